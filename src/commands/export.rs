//! `octovox export FILE -o OUT.obj|OUT.ply|OUT.glb [--scale S] [--frame N] [--force]`.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::atomic::WriteOptions;

pub fn run(file: &Path, output: &Path, scale: f32, frame: usize, force: bool) -> anyhow::Result<ExitCode> {
    octovox::io::export::check_outputs(output, &[file], force)?;
    let scene = octovox::io::load_scene(file, frame).with_context(|| format!("loading {}", file.display()))?;
    let options = WriteOptions::forced(force);
    let stats = octovox::io::export::export_mesh(output, &scene, scale, options)?;
    say!(
        "wrote {}: {} triangles, {} vertices ({} triangles as one quad per face)",
        stats.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(" and "),
        stats.triangles,
        stats.vertices,
        stats.naive_triangles
    )?;
    Ok(ExitCode::SUCCESS)
}
