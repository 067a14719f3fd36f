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

use crate::replay::{Runner, RunnerMode};
use crate::scene::Scene;
use crate::script::{Line, Script};

/// The journal of `document`: `.NAME.octovox-journal.ovr` beside it.
pub fn journal_path(document: &Path) -> PathBuf {
    let name = document.file_name().map_or_else(|| "untitled".into(), |n| n.to_string_lossy().into_owned());
    document.with_file_name(format!(".{name}.octovox-journal.ovr"))
}

/// The journal file names end so; `octovox recover` takes one directly.
const JOURNAL_SUFFIX: &str = ".octovox-journal.ovr";

/// The document whose journal `journal` is ([`journal_path`] backwards);
/// `None` for an untitled scene's journal or another file.
pub fn document_of(journal: &Path) -> Option<PathBuf> {
    let name = journal.file_name()?.to_string_lossy().into_owned();
    let document = name.strip_prefix('.')?.strip_suffix(JOURNAL_SUFFIX)?;
    (untitled_session(&name).is_none() && !document.is_empty()).then(|| journal.with_file_name(document))
}

/// Whether `path` names a journal (rather than a document).
pub fn is_journal(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n.to_string_lossy().ends_with(JOURNAL_SUFFIX))
}

/// The journal of the untitled scene of the session with process id `pid`:
/// `.untitled-PID.octovox-journal.ovr` in `dir`.
pub fn untitled_journal_path(dir: &Path, pid: u32) -> PathBuf {
    dir.join(format!(".untitled-{pid}{JOURNAL_SUFFIX}"))
}

/// This session's number in the names of its untitled journals: the
/// process id on the desktop; in the browser, where a page has none, a
/// random number drawn once per page.
#[cfg(not(target_arch = "wasm32"))]
pub fn session_id() -> u32 {
    std::process::id()
}

#[cfg(target_arch = "wasm32")]
pub fn session_id() -> u32 {
    thread_local! {
        static ID: u32 = {
            let mut bytes = [0u8; 4];
            // Without randomness, two pages share a name: the later one's
            // journal replaces the earlier's, which it would have offered.
            let _ = getrandom::fill(&mut bytes);
            u32::from_le_bytes(bytes)
        };
    }
    ID.with(|id| *id)
}

/// The process id in an untitled journal's name.
fn untitled_session(name: &str) -> Option<u32> {
    name.strip_prefix(".untitled-")?.strip_suffix(JOURNAL_SUFFIX)?.parse().ok()
}

/// Untitled journals among the page's files of pages gone (a page's
/// journals outlive it in the browser's storage), newest name last.
#[cfg(target_arch = "wasm32")]
pub fn orphaned_untitled(dir: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = crate::io::page_files::list(dir)
        .into_iter()
        .filter(|path| {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            untitled_session(&name).is_some_and(|id| id != session_id())
        })
        .collect();
    found.sort();
    found
}

/// Untitled journals in `dir` of sessions no longer running (no
/// `/proc/PID`), newest first.
#[cfg(not(target_arch = "wasm32"))]
pub fn orphaned_untitled(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut found: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            untitled_session(&name)
                .is_some_and(|pid| pid != session_id() && !Path::new("/proc").join(pid.to_string()).exists())
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
    crate::io::input::is_file(&path).then_some(path)
}

/// Removes a journal and its snapshot: its edits were saved, recovered
/// into another journal, or discarded. Either may be missing.
pub fn discard(journal: &Path) {
    for path in [snapshot_path(journal), journal.to_path_buf()] {
        #[cfg(not(target_arch = "wasm32"))]
        let _ = std::fs::remove_file(path);
        #[cfg(target_arch = "wasm32")]
        let _ = crate::io::page_files::remove(&path);
    }
}

/// What a journal noted of a file when it started: the file its `load`
/// line loads, as the window read it. Recovery compares the file as it is
/// now by its hash; size and time only make the message readable.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileStamp {
    pub size: u64,
    /// Modification time, in seconds since the Unix epoch (0: unknown).
    pub modified: u64,
    pub sha256: String,
}

impl FileStamp {
    /// The stamp of `path` as it is now.
    ///
    /// # Errors
    /// The file cannot be read, or is not a regular file: a FIFO would be
    /// drained by the hash before the loader could read it.
    pub fn of(path: &Path) -> std::io::Result<FileStamp> {
        FileStamp::with_hash(path, None)
    }

    /// [`FileStamp::of`], with the file's SHA-256 when the caller knows it
    /// already (a save just hashed what it wrote) rather than reading it again.
    ///
    /// # Errors
    /// As [`FileStamp::of`].
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_hash(path: &Path, sha256: Option<String>) -> std::io::Result<FileStamp> {
        let meta = std::fs::metadata(path)?;
        if !meta.is_file() {
            let text = format!("{} is not a regular file", path.display());
            return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, text));
        }
        let modified = meta.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
        let sha256 = match sha256 {
            Some(known) => known,
            None => crate::io::atomic::sha256_of(path)?,
        };
        Ok(FileStamp { size: meta.len(), modified: modified.map_or(0, |d| d.as_secs()), sha256 })
    }

    /// [`FileStamp::of`] of one of the browser page's files (its time unknown).
    ///
    /// # Errors
    /// The page holds no such file.
    #[cfg(target_arch = "wasm32")]
    pub fn with_hash(path: &Path, sha256: Option<String>) -> std::io::Result<FileStamp> {
        let bytes = crate::io::page_files::read_existing(path)?;
        let sha256 = sha256.unwrap_or_else(|| crate::io::atomic::sha256_of_bytes(&bytes));
        Ok(FileStamp { size: bytes.len() as u64, modified: 0, sha256 })
    }

    /// The journal's note of the file it edits: `source size=N modified=S sha256=HEX`.
    pub fn note(&self) -> String {
        format!("source size={} modified={} sha256={}", self.size, self.modified, self.sha256)
    }

    fn parse(words: &[String]) -> Option<FileStamp> {
        let value = |key: &str| words.iter().find_map(|w| w.strip_prefix(key)?.strip_prefix('='));
        Some(FileStamp {
            size: value("size")?.parse().ok()?,
            modified: value("modified")?.parse().ok()?,
            sha256: value("sha256")?.to_owned(),
        })
    }
}

impl std::fmt::Display for FileStamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let short = self.sha256.get(..12).unwrap_or(&self.sha256);
        write!(f, "{} bytes, modified at {} s after 1970, SHA-256 {short}…", self.size, self.modified)
    }
}

/// The journal's note written just before a save replaces `path` with a
/// file of hash `sha256`: if a kill comes between that save's rename and
/// the journal's removal, recovery finds the journal's edits in `path`.
pub fn saved_note(sha256: &str, path: &Path) -> String {
    format!("saved sha256={sha256} {}", crate::script::quoted(path))
}

/// The notes (`#@ …` lines) of a journal's text.
#[derive(Default)]
struct Notes {
    /// The file the `load` line loads, as it was when the journal started.
    source: Option<FileStamp>,
    /// The last save the journal saw begin: its line, hash and file.
    saved: Option<(usize, String, PathBuf)>,
}

impl Notes {
    fn read(text: &str) -> Notes {
        let mut notes = Notes::default();
        for (number, line) in (1..).zip(text.lines()) {
            let Some(words) = line.strip_prefix("#@").and_then(|rest| crate::script::split_words(rest).ok()) else {
                continue;
            };
            match words.first().map(String::as_str) {
                Some("source") if notes.source.is_none() => notes.source = FileStamp::parse(&words[1..]),
                Some("saved") => {
                    if let [_, hash, path] = words.as_slice()
                        && let Some(hash) = hash.strip_prefix("sha256=")
                    {
                        notes.saved = Some((number, hash.to_owned(), PathBuf::from(path)));
                    }
                }
                _ => {}
            }
        }
        notes
    }
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
    #[error(
        "journal {} is live: another octovox window is editing with it and holds its lock; nothing was applied",
        path.display()
    )]
    Live { path: PathBuf },
    #[error(
        "journal {} is stale: a save put all its edits in {} (the file still holds that save); nothing to recover",
        path.display(),
        saved_to.display()
    )]
    Saved { path: PathBuf, saved_to: PathBuf },
    #[error(
        "journal {} was started on {} as it was then ({then}); it is now {now}: its edits were made on other \
         content, so nothing was applied",
        path.display(),
        document.display()
    )]
    Changed { path: PathBuf, document: PathBuf, then: FileStamp, now: String },
}

/// Whether another process holds `journal`'s lock (a window editing with it).
/// A page holds no lock: its journals are the tab's own.
#[cfg(target_arch = "wasm32")]
pub fn is_live(_journal: &Path) -> bool {
    false
}

/// Whether another process holds `journal`'s lock (a window editing with it).
#[cfg(not(target_arch = "wasm32"))]
pub fn is_live(journal: &Path) -> bool {
    std::fs::File::open(journal).is_ok_and(|file| matches!(file.try_lock(), Err(std::fs::TryLockError::WouldBlock)))
}

/// What [`read`] checks beyond the journal's own lines.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Checks {
    /// Apply the journal even though the file it loads changed since it
    /// started (the window asks the user first).
    pub allow_changed_source: bool,
}

/// Reads a journal. It must make its scene once, on its first line: `load`
/// of `document` (or of the journal's own snapshot) when one is given (the
/// journal found beside it); a journal named directly (an untitled one)
/// may also start with `new` or `demo`. The file it loads must be as the
/// journal noted it when it started, unless `checks` allows otherwise; a
/// journal whose edits a finished save holds, or that a running window
/// holds, is refused.
///
/// # Errors
/// A journal that does not parse, is written for another file, is live,
/// stale, or was started on other content than its file holds now.
pub fn read(journal: &Path, document: Option<&Path>, checks: Checks) -> Result<Script, RecoverError> {
    if is_live(journal) {
        return Err(RecoverError::Live { path: journal.to_path_buf() });
    }
    let unreadable = |errors: Vec<String>| RecoverError::Unreadable { path: journal.to_path_buf(), errors };
    let bytes = crate::io::input::read_limited(journal, crate::script::MAX_SCRIPT_BYTES)
        .map_err(|e| unreadable(vec![format!("cannot read it: {e}")]))?;
    let text = String::from_utf8(bytes).map_err(|_| unreadable(vec!["it is not UTF-8 text".into()]))?;
    let script = crate::script::parse_script(journal, &text)
        .map_err(|errors| unreadable(errors.iter().map(ToString::to_string).collect()))?;
    let first = check_lines(journal, &script, document)?;
    let notes = Notes::read(&text);
    if let Some((line, hash, saved_to)) = notes.saved
        && script.lines.last().is_none_or(|last| last.number < line)
        && crate::io::atomic::sha256_of(&saved_to).is_ok_and(|now| now == hash)
    {
        return Err(RecoverError::Saved { path: journal.to_path_buf(), saved_to });
    }
    if let (Some(then), Line::Load(source)) = (notes.source, first)
        && !checks.allow_changed_source
    {
        let now = FileStamp::of(source);
        if !now.as_ref().is_ok_and(|now| now.sha256 == then.sha256) {
            let now = now.map_or_else(|err| format!("unreadable ({err})"), |now| now.to_string());
            return Err(RecoverError::Changed { path: journal.to_path_buf(), document: source.clone(), then, now });
        }
    }
    Ok(script)
}

/// The journal's own lines: one scene line, first, that makes the scene
/// the journal edits, and no line that writes a file. Returns the scene line.
fn check_lines<'a>(journal: &Path, script: &'a Script, document: Option<&Path>) -> Result<&'a Line, RecoverError> {
    let failed = |message: String| RecoverError::Failed { path: journal.to_path_buf(), message };
    let is_scene = |c: &Line| matches!(c, Line::Load(_) | Line::New | Line::Demo(_));
    let first = script.lines.iter().find(|l| !matches!(l.command, Line::Viewport(..))).map(|l| &l.command);
    // A journal only edits: one that writes files (planted, or damaged) is refused.
    if let Some(line) = script.lines.iter().find(|l| matches!(l.command, Line::Save(_) | Line::Render(_))) {
        return Err(failed(format!("line {} writes a file ('{}'), which no journal does", line.number, line.command)));
    }
    // It makes its scene once: a second scene line would edit another file.
    if let Some(line) = script.lines.iter().filter(|l| is_scene(&l.command)).nth(1) {
        return Err(failed(format!(
            "line {} makes a second scene ('{}'): a journal makes its scene once, on its first line",
            line.number, line.command
        )));
    }
    let owned = match (first, document) {
        (Some(Line::Load(owner)), Some(document)) => {
            use crate::io::output::same_file;
            same_file(owner, document) || same_file(owner, &snapshot_path(journal))
        }
        (Some(first), None) => is_scene(first),
        _ => false,
    };
    match first {
        Some(first) if owned => Ok(first),
        _ => {
            let owner = first.map_or_else(|| "nothing".into(), ToString::to_string);
            Err(match document {
                Some(document) => {
                    RecoverError::Foreign { path: journal.to_path_buf(), owner, document: document.to_path_buf() }
                }
                None => failed(format!("it starts with '{owner}', not with the scene it edits (load, new or demo)")),
            })
        }
    }
}

/// The scene as it was after the journal's last edit: the journal
/// replayed, headless, on the CPU. All or nothing.
///
/// # Errors
/// As [`read`], or a line that does not apply.
pub fn recover_from(journal: &Path, document: Option<&Path>, checks: Checks) -> Result<Scene, RecoverError> {
    let script = read(journal, document, checks)?;
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
pub fn recover(document: &Path, checks: Checks) -> Result<Scene, RecoverError> {
    let journal = find(document).ok_or_else(|| RecoverError::NoJournal(document.to_path_buf()))?;
    recover_from(&journal, Some(document), checks)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // in tests a panic is the failure report

    use super::*;

    /// A document of one voxel and its journal path, in a fresh folder.
    fn document() -> (tempfile::TempDir, PathBuf, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let document = dir.path().join("doc.vox");
        let mut scene = Scene::default();
        scene.apply_brush(&crate::scene::Shape::Voxel(glam::IVec3::ZERO), crate::scene::Op::Place(3)).unwrap();
        crate::io::save_scene(&document, &scene, Default::default()).unwrap();
        let journal = journal_path(&document);
        (dir, std::fs::canonicalize(&document).unwrap(), journal)
    }

    fn journal_text(document: &Path, notes: &str, edits: &str) -> String {
        format!("# test journal\n{notes}load {}\n{edits}", crate::script::quoted(document))
    }

    #[test]
    fn a_journal_loads_its_document_once_and_first() {
        let (dir, document, journal) = document();
        let other = dir.path().join("other.vox");
        std::fs::copy(&document, &other).unwrap();
        let second = format!("place 0 1 0\nload {}\nplace 0 2 0\n", other.display());
        std::fs::write(&journal, journal_text(&document, "", &second)).unwrap();
        let err = recover(&document, Checks::default()).unwrap_err().to_string();
        assert!(err.contains("line 4 makes a second scene") && err.contains("nothing was applied"), "{err}");
        std::fs::write(&journal, format!("new\n{}", journal_text(&document, "", "place 0 1 0\n"))).unwrap();
        assert!(recover(&document, Checks::default()).is_err(), "a scene line before the load is refused too");
        std::fs::write(&journal, journal_text(&document, "", "place 0 1 0\n")).unwrap();
        assert_eq!(recover(&document, Checks::default()).unwrap().solid_voxels(), 2);
    }

    #[test]
    fn a_journal_started_on_other_content_is_refused_unless_allowed() {
        let (_dir, document, journal) = document();
        let stamp = FileStamp::of(&document).unwrap();
        let text = journal_text(&document, &format!("#@ {}\n", stamp.note()), "place 0 1 0\n");
        std::fs::write(&journal, &text).unwrap();
        assert_eq!(recover(&document, Checks::default()).unwrap().solid_voxels(), 2, "the same content");
        // Another program rewrites the document after the journal started.
        let mut scene = crate::io::load_scene(&document, 0).unwrap();
        scene.apply_brush(&crate::scene::Shape::Voxel(glam::IVec3::X), crate::scene::Op::Place(4)).unwrap();
        crate::io::save_scene(&document, &scene, Default::default()).unwrap();
        let err = recover(&document, Checks::default()).unwrap_err();
        assert!(matches!(err, RecoverError::Changed { .. }), "{err}");
        let message = err.to_string();
        assert!(message.contains(&format!("{} bytes", stamp.size)) && message.contains("nothing was applied"));
        let checks = Checks { allow_changed_source: true };
        assert_eq!(recover(&document, checks).unwrap().solid_voxels(), 3, "applied when the user says so");
        assert_eq!(std::fs::read_to_string(&journal).unwrap(), text, "the journal is left as it was");
    }

    #[test]
    fn a_journal_whose_save_finished_is_stale() {
        let (_dir, document, journal) = document();
        let stamp = FileStamp::of(&document).unwrap();
        // The save noted itself, then renamed its file over the document.
        let mut scene = crate::io::load_scene(&document, 0).unwrap();
        scene.apply_brush(&crate::scene::Shape::Voxel(glam::IVec3::Y), crate::scene::Op::Place(3)).unwrap();
        crate::io::save_scene(&document, &scene, Default::default()).unwrap();
        let saved = crate::io::atomic::sha256_of(&document).unwrap();
        let edits = format!("place 0 1 0\n#@ {}\n", saved_note(&saved, &document));
        std::fs::write(&journal, journal_text(&document, &format!("#@ {}\n", stamp.note()), &edits)).unwrap();
        let err = recover(&document, Checks::default()).unwrap_err();
        assert!(matches!(err, RecoverError::Saved { .. }), "{err}");
        // A save that did not finish (the file is not what it noted) changes nothing.
        let mut unfinished = saved.clone();
        unfinished.replace_range(..1, if saved.starts_with('0') { "1" } else { "0" });
        let edits = format!("place 0 1 0\n#@ {}\n", saved_note(&unfinished, &document));
        std::fs::write(&journal, journal_text(&document, "", &edits)).unwrap();
        assert_eq!(recover(&document, Checks::default()).unwrap().solid_voxels(), 2);
    }

    #[test]
    fn a_journal_a_window_holds_is_live() {
        let (_dir, document, journal) = document();
        let mut recorder = crate::replay::Recorder::journal(&journal, "test").unwrap();
        recorder.scene(Line::Load(document.clone())).unwrap();
        assert!(is_live(&journal));
        let err = recover(&document, Checks::default()).unwrap_err();
        assert!(matches!(err, RecoverError::Live { .. }), "{err}");
        let again = crate::replay::Recorder::journal(&journal, "second window").map(|_| ()).unwrap_err();
        assert_eq!(again.kind(), std::io::ErrorKind::WouldBlock);
        assert!(std::fs::read_to_string(&journal).unwrap().contains("# test\nload"), "left as the first wrote it");
        drop(recorder);
        assert!(!is_live(&journal));
        assert!(recover(&document, Checks::default()).is_ok());
    }

    #[test]
    fn a_documents_journal_names_its_document_and_an_untitled_one_none() {
        let document = Path::new("models/chr_knight.vox");
        assert_eq!(document_of(&journal_path(document)), Some(document.to_path_buf()));
        assert_eq!(document_of(&untitled_journal_path(Path::new("saves"), 42)), None);
        assert_eq!(document_of(Path::new("models/chr_knight.vox")), None);
    }
}
