//! `octovox convert IN.vox OUT.vox [--frame N] [--force]`: load, then save
//! through octovox's scene model (the octree), one model at a time.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};

/// Loads `input` (frame `frame`) and saves it to `output`, replacing it
/// atomically; an existing .vox or the input itself only with `force`.
pub fn run(input: &Path, output: &Path, frame: usize, force: bool) -> anyhow::Result<ExitCode> {
    check_output(output, OutputKind::Scene, &[input], force)?;
    let scene =
        super::progress_bar::with_bar("loading", |progress| octovox::io::load_scene_with(input, frame, progress))
            .with_context(|| format!("loading {}", input.display()))?;
    let options = WriteOptions::forced(force);
    octovox::io::save_scene(output, &scene, options).with_context(|| format!("saving {}", output.display()))?;
    say!("wrote {} voxels to {}", scene.solid_voxels(), output.display())?;
    if let Some(note) = octovox::io::magicavoxel_note(output, &scene) {
        say!("note: {note}")?;
    }
    Ok(ExitCode::SUCCESS)
}
