//! `octovox convert IN.vox OUT.vox [--frame N]`: load, then save through
//! octovox's scene model.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::vox::{load_vox_file, save_vox};

/// Loads `input` (frame `frame`) and saves it to `output`, replacing it atomically.
pub fn run(input: &Path, output: &Path, frame: usize) -> anyhow::Result<ExitCode> {
    let model = load_vox_file(input, frame).with_context(|| format!("loading {}", input.display()))?;
    save_vox(output, &model.palette, &model.voxels).with_context(|| format!("saving {}", output.display()))?;
    println!("wrote {} voxels to {}", model.voxels.len(), output.display());
    Ok(ExitCode::SUCCESS)
}
