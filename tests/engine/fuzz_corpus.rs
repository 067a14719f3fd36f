//! Replays the fuzz corpus (tests/fuzz/corpus/<target>/) through the same
//! checks the fuzz targets run, so what fuzzing found stays fixed.

use std::path::PathBuf;

#[path = "../fuzz/checks.rs"]
mod checks;

/// Every file of one target's corpus; at least `min` of them.
fn corpus(target: &str, min: usize) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus").join(target);
    let mut files: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| {
            let path = entry.expect("corpus entry").path();
            let bytes = std::fs::read(&path).expect("corpus file");
            (path, bytes)
        })
        .collect();
    files.sort();
    assert!(files.len() >= min, "{} holds {} inputs", dir.display(), files.len());
    files
}

fn replay(target: &str, min: usize, check: fn(&[u8])) {
    let files = corpus(target, min);
    for (path, bytes) in &files {
        // Name the input that fails.
        let outcome = std::panic::catch_unwind(|| check(bytes));
        assert!(outcome.is_ok(), "{} fails its check", path.display());
    }
    println!("{target}: {} corpus inputs replayed", files.len());
}

#[test]
fn vox_corpus() {
    replay("vox", 10, checks::vox);
}

#[test]
fn obj_corpus() {
    replay("obj", 10, checks::obj);
}

#[test]
fn script_corpus() {
    replay("script", 10, checks::script);
}

#[test]
fn journal_corpus() {
    replay("journal", 10, checks::journal);
}

#[test]
fn ovx_corpus() {
    replay("ovx", 10, checks::ovx);
}
