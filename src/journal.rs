//! Crash recovery: while a document has unsaved edits, the window appends
//! every edit to a journal beside it (a replay script, flushed per line, by
//! the same [`Recorder`](crate::replay::Recorder) as `--record`), and
//! removes it when the document is saved or the edits are discarded. A
//! journal still there when the document is opened again means a crash:
//! the window offers to replay it, and `octovox recover` does so headless.
//! `docs/recovery.md` describes it.

use std::path::{Path, PathBuf};

use crate::replay::{Command, Runner, RunnerMode, Script, load_script};
use crate::scene::Scene;

/// The journal of `document`: `.NAME.octovox-journal.ovr` beside it.
pub fn journal_path(document: &Path) -> PathBuf {
    let name = document.file_name().map_or_else(|| "untitled".into(), |n| n.to_string_lossy().into_owned());
    document.with_file_name(format!(".{name}.octovox-journal.ovr"))
}

/// The journal of `document` if one was left behind.
pub fn find(document: &Path) -> Option<PathBuf> {
    let path = journal_path(document);
    path.is_file().then_some(path)
}

/// Why a journal could not be applied. The journal is never changed.
#[derive(Debug, thiserror::Error)]
pub enum RecoverError {
    #[error("{} has no journal: there is nothing to recover", .0.display())]
    NoJournal(PathBuf),
    #[error("journal {}: {}", path.display(), errors.join("; "))]
    Unreadable { path: PathBuf, errors: Vec<String> },
    #[error("journal {} belongs to {}, not to {}", path.display(), owner, document.display())]
    Foreign { path: PathBuf, owner: String, document: PathBuf },
    #[error("journal {}: {message}; nothing was applied", path.display())]
    Failed { path: PathBuf, message: String },
}

/// Reads a journal and checks that it starts by loading `document`.
///
/// # Errors
/// A journal that does not parse, or one written for another file.
pub fn read(journal: &Path, document: &Path) -> Result<Script, RecoverError> {
    let script = load_script(journal).map_err(|errors| RecoverError::Unreadable {
        path: journal.to_path_buf(),
        errors: errors.iter().map(ToString::to_string).collect(),
    })?;
    let document_id = std::fs::canonicalize(document).unwrap_or_else(|_| document.to_path_buf());
    let first_load = script.lines.iter().find(|l| !matches!(l.command, Command::Viewport(..)));
    match first_load.map(|l| &l.command) {
        Some(Command::Load(owner)) if std::fs::canonicalize(owner).is_ok_and(|p| p == document_id) => Ok(script),
        other => Err(RecoverError::Foreign {
            path: journal.to_path_buf(),
            owner: other.map_or_else(|| "nothing".into(), ToString::to_string),
            document: document.to_path_buf(),
        }),
    }
}

/// The document as it was after the journal's last edit: the journal
/// replayed, headless, on the CPU. All or nothing.
///
/// # Errors
/// As [`read`], or a line that does not apply.
pub fn recover(document: &Path) -> Result<Scene, RecoverError> {
    let journal = find(document).ok_or_else(|| RecoverError::NoJournal(document.to_path_buf()))?;
    let script = read(&journal, document)?;
    let mut runner = Runner::new(RunnerMode::Cpu);
    let report = runner.run(&script);
    if let Some(failure) = report.failures.first() {
        return Err(RecoverError::Failed { path: journal, message: failure.to_string() });
    }
    Ok(runner.editor.scene)
}
