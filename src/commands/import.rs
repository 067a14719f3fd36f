//! `octovox import MESH.obj -o OUT.vox [--size N] [--up y|z] [--color I]`:
//! voxelize a closed mesh, solid inside, and save it as .vox.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use octovox::io::mesh::voxelize_obj;
use octovox::scene::Scene;

use crate::cli::ImportArgs;

pub fn run(args: &ImportArgs) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
    let dense = voxelize_obj(&args.mesh, args.size, args.up, args.color)?;
    let voxelized = start.elapsed();
    let scene = Scene::from_dense(&dense).with_context(|| format!("building {}", args.mesh.display()))?;
    octovox::io::save_scene(&args.output, &scene).with_context(|| format!("saving {}", args.output.display()))?;
    let d = dense.dims;
    println!(
        "{}: {} solid voxels in {}×{}×{} (voxelized in {:.2} s), wrote {}",
        args.mesh.display(),
        scene.tree.solid_voxels(),
        d.x,
        d.y,
        d.z,
        voxelized.as_secs_f64(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
