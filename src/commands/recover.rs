//! `octovox recover FILE -o OUT [--force]`: the window's crash-recovery
//! journal beside FILE (or FILE itself when it is a journal, as an untitled
//! scene's is), replayed headless, saved as OUT. All or nothing: a journal
//! that does not parse, belongs to another file or fails on a line is
//! reported and left in place, and OUT is not written.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};

pub fn run(file: &Path, output: &Path, force: bool) -> anyhow::Result<ExitCode> {
    check_output(output, OutputKind::Scene, &[file], force)?;
    let (scene, journal) = if octovox::journal::is_journal(file) {
        (octovox::journal::recover_from(file, None)?, file.to_path_buf())
    } else {
        (octovox::journal::recover(file)?, octovox::journal::journal_path(file))
    };
    let options = WriteOptions { overwrite_read_only: force };
    octovox::io::save_scene(output, &scene, options).with_context(|| format!("saving {}", output.display()))?;
    say!(
        "recovered {} voxels into {}; the journal {} is left in place",
        scene.tree.solid_voxels(),
        output.display(),
        journal.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
