//! `octovox import MESH.obj -o OUT.vox [--size N] [--up y|z] [--color I]`:
//! voxelize a closed mesh, solid inside, and save it as .vox or .ovx.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use glam::IVec3;
use octovox::io::atomic::WriteOptions;
use octovox::io::mesh::voxelize_obj_with;
use octovox::io::output::{OutputKind, check_output};
use octovox::scene::{Palette, Scene};

use crate::cli::ImportArgs;

pub fn run(args: &ImportArgs) -> anyhow::Result<ExitCode> {
    check_output(&args.output, OutputKind::Scene, &[&args.mesh], args.force)?;
    let start = Instant::now();
    let tree = super::progress_bar::with_bar("voxelizing", |progress| {
        voxelize_obj_with(&args.mesh, args.size, args.up, args.color, progress)
    })?;
    let voxelized = start.elapsed();
    let (lo, hi) = tree.solid_bounds().unwrap_or_default();
    let d = hi - lo + IVec3::ONE;
    let scene = Scene::new(Palette::default(), tree);
    let options = WriteOptions::forced(args.force);
    octovox::io::save_scene(&args.output, &scene, options)
        .with_context(|| format!("saving {}", args.output.display()))?;
    if args.stats {
        let stats = super::bench_scale::ImportStats {
            voxels: scene.solid_voxels(),
            seconds: start.elapsed().as_secs_f64(),
            peak_bytes: super::bench_scale::peak_resident_bytes(),
        };
        say!("{}", serde_json::to_string(&stats)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    say!(
        "{}: {} solid voxels in {}×{}×{} (voxelized in {:.2} s), wrote {}",
        args.mesh.display(),
        scene.solid_voxels(),
        d.x,
        d.y,
        d.z,
        voxelized.as_secs_f64(),
        args.output.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
