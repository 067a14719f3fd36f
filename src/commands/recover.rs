//! `octovox recover FILE -o OUT [--force]`: the window's crash-recovery
//! journal beside FILE (or FILE itself when it is a journal, as an untitled
//! scene's is), replayed headless, saved as OUT. All or nothing: a journal
//! that does not parse, belongs to another file, fails on a line, is held
//! by a running window, was started on other content than FILE holds now,
//! or whose edits a finished save already holds is reported and left in
//! place, and OUT is not written.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::journal::Checks;

pub fn run(file: &Path, output: &Path, force: bool) -> anyhow::Result<ExitCode> {
    check_output(output, OutputKind::Scene, &[file], force)?;
    let (scene, journal) = if octovox::journal::is_journal(file) {
        (octovox::journal::recover_from(file, None, Checks::default())?, file.to_path_buf())
    } else {
        (octovox::journal::recover(file, Checks::default())?, octovox::journal::journal_path(file))
    };
    let options = WriteOptions::forced(force);
    octovox::io::save_scene(output, &scene, options).with_context(|| format!("saving {}", output.display()))?;
    say!(
        "recovered {} voxels into {}; the journal {} is left in place",
        scene.solid_voxels(),
        output.display(),
        journal.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
