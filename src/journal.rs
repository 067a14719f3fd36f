//! Crash recovery: while a document has unsaved edits, the window appends
//! every edit to a journal beside it (a replay script, flushed per line, by
//! the same [`Recorder`](crate::replay::Recorder) as `--record`), and
//! removes it when the document is saved or the edits are discarded. A
//! journal still there when the document is opened again means a crash:
//! the window offers to replay it, and `octovox recover` does so headless.
//! A scene without a file (the demo, a new scene, an imported mesh) is
//! journaled in `saves/` under the session's process id; the next window
//! started without a file offers the journal of a session that is gone.
//! `docs/recovery.md` describes it.

use std::path::{Path, PathBuf};

use crate::replay::{Command, Runner, RunnerMode, Script, load_script};
use crate::scene::Scene;

/// The journal of `document`: `.NAME.octovox-journal.ovr` beside it.
pub fn journal_path(document: &Path) -> PathBuf {
    let name = document.file_name().map_or_else(|| "untitled".into(), |n| n.to_string_lossy().into_owned());
    document.with_file_name(format!(".{name}.octovox-journal.ovr"))
}

/// The journal file names end so; `octovox recover` takes one directly.
const JOURNAL_SUFFIX: &str = ".octovox-journal.ovr";

/// Whether `path` names a journal (rather than a document).
pub fn is_journal(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n.to_string_lossy().ends_with(JOURNAL_SUFFIX))
}

/// The journal of the untitled scene of the session with process id `pid`:
/// `.untitled-PID.octovox-journal.ovr` in `dir`.
pub fn untitled_journal_path(dir: &Path, pid: u32) -> PathBuf {
    dir.join(format!(".untitled-{pid}{JOURNAL_SUFFIX}"))
}

/// Untitled journals in `dir` of sessions no longer running (no
/// `/proc/PID`), newest first.
pub fn orphaned_untitled(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut found: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            let pid = name.strip_prefix(".untitled-").and_then(|rest| rest.strip_suffix(JOURNAL_SUFFIX));
            pid.and_then(|p| p.parse::<u32>().ok())
                .is_some_and(|pid| pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists())
        })
        .filter_map(|entry| Some((entry.metadata().ok()?.modified().ok()?, entry.path())))
        .collect();
    found.sort_by_key(|(modified, _)| std::cmp::Reverse(*modified));
    found.into_iter().map(|(_, path)| path).collect()
}

/// The snapshot a journal may start from (`load` of it as its first line):
/// the journal's path with `.ovx` for `.ovr`. The window writes one when a
/// change cannot be journaled as a line; it goes with its journal.
pub fn snapshot_path(journal: &Path) -> PathBuf {
    journal.with_extension("ovx")
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

/// Reads a journal. Its first scene line must load `document` (or the
/// journal's own snapshot) when one is given (the journal found beside
/// it); a journal named directly (an untitled one) must start with a scene
/// line (`load`, `new`, `demo`).
///
/// # Errors
/// A journal that does not parse, or one written for another file.
pub fn read(journal: &Path, document: Option<&Path>) -> Result<Script, RecoverError> {
    let script = load_script(journal).map_err(|errors| RecoverError::Unreadable {
        path: journal.to_path_buf(),
        errors: errors.iter().map(ToString::to_string).collect(),
    })?;
    let first = script.lines.iter().find(|l| !matches!(l.command, Command::Viewport(..))).map(|l| &l.command);
    let owned = match (first, document) {
        (Some(Command::Load(owner)), Some(document)) => {
            let id = |p: &Path| std::fs::canonicalize(p).ok();
            let owner = id(owner);
            owner.is_some() && (owner == id(document) || owner == id(&snapshot_path(journal)))
        }
        (Some(Command::Load(_) | Command::New | Command::Demo(_)), None) => true,
        _ => false,
    };
    // A journal only edits: one that writes files (planted, or damaged) is refused.
    if let Some(line) = script.lines.iter().find(|l| matches!(l.command, Command::Save(_) | Command::Render(_))) {
        return Err(RecoverError::Failed {
            path: journal.to_path_buf(),
            message: format!("line {} writes a file ('{}'), which no journal does", line.number, line.command),
        });
    }
    if owned {
        return Ok(script);
    }
    let owner = first.map_or_else(|| "nothing".into(), ToString::to_string);
    Err(match document {
        Some(document) => {
            RecoverError::Foreign { path: journal.to_path_buf(), owner, document: document.to_path_buf() }
        }
        None => RecoverError::Failed {
            path: journal.to_path_buf(),
            message: format!("it starts with '{owner}', not with the scene it edits (load, new or demo)"),
        },
    })
}

/// The scene as it was after the journal's last edit: the journal
/// replayed, headless, on the CPU. All or nothing.
///
/// # Errors
/// As [`read`], or a line that does not apply.
pub fn recover_from(journal: &Path, document: Option<&Path>) -> Result<Scene, RecoverError> {
    let script = read(journal, document)?;
    let mut runner = Runner::new(RunnerMode::Cpu);
    let report = runner.run(&script);
    if let Some(failure) = report.failures.first() {
        return Err(RecoverError::Failed { path: journal.to_path_buf(), message: failure.to_string() });
    }
    Ok(runner.editor.scene)
}

/// The document as it was after its journal's last edit.
///
/// # Errors
/// No journal beside it, or as [`recover_from`].
pub fn recover(document: &Path) -> Result<Scene, RecoverError> {
    let journal = find(document).ok_or_else(|| RecoverError::NoJournal(document.to_path_buf()))?;
    recover_from(&journal, Some(document))
}
