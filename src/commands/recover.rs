//! `octovox recover FILE -o OUT [--force]`: the window's crash-recovery
//! journal beside FILE, replayed headless, saved as OUT. All or nothing: a
//! journal that does not parse, belongs to another file or fails on a line
//! is reported and left in place, and OUT is not written.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};

pub fn run(file: &Path, output: &Path, force: bool) -> anyhow::Result<ExitCode> {
    check_output(output, OutputKind::Scene, &[file], force)?;
    let scene = octovox::journal::recover(file)?;
    let options = WriteOptions { overwrite_read_only: force };
    octovox::io::save_scene(output, &scene, options).with_context(|| format!("saving {}", output.display()))?;
    let journal = octovox::journal::journal_path(file);
    say!(
        "recovered {} voxels into {}; the journal {} is left in place",
        scene.tree.solid_voxels(),
        output.display(),
        journal.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
