//! `octovox bench scale`: Nefertiti voxelized at growing heights, each
//! through the product's own paths: `octovox import` as a child process (so
//! its peak resident memory is its own), then in this process the .ovx
//! load, the .vox save, a frame, and a radius-64 sphere edit with its
//! upload.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::Context;
use glam::IVec3;
use serde::{Deserialize, Serialize};

use super::bench::{header, median};
use octovox::camera::Camera;
use octovox::gpu::Renderer;
use octovox::io::atomic::WriteOptions;
use octovox::scene::{Op, Shape};
use octovox::settings::RenderSettings;

/// What `octovox import --stats` prints.
#[derive(Serialize, Deserialize)]
pub struct ImportStats {
    pub voxels: u64,
    pub seconds: f64,
    /// The process's peak resident memory (VmHWM), when the system says.
    pub peak_bytes: Option<u64>,
}

/// The peak resident memory of this process so far (`VmHWM` of
/// /proc/self/status), or `None` where there is no such file.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib * 1024)
}

/// The .vox save of a row: seconds, or why .vox cannot hold it (written
/// to the JSON as `{"Ok": s}` or `{"Err": why}`).
#[derive(Serialize)]
enum VoxSave {
    Ok(f64),
    Err(String),
}

#[derive(Serialize)]
struct ScaleRow {
    height: u32,
    voxels: u64,
    import_s: f64,
    import_peak_mb: Option<f64>,
    pool_mb: f64,
    bytes_per_voxel: f64,
    ovx_mb: f64,
    ovx_load_s: f64,
    /// Seconds, or why .vox cannot hold it.
    vox_save: VoxSave,
    frame_ms: f64,
    edit_ms: f64,
}

const FRAME: (u32, u32) = (1280, 720);

pub fn bench_scale(quick: bool) -> anyhow::Result<(String, String)> {
    let heights: &[u32] = if quick { &[64, 128] } else { &[512, 1024, 2048, 4096] };
    let mesh = super::bench::assets().join("meshes/nefertiti.obj");
    let dir = tempfile::tempdir().context("a scratch folder")?;
    let mut renderer = Renderer::headless().context("bench scale needs a GPU (lavapipe works)")?;
    let mut rows = Vec::new();
    for &height in heights {
        rows.push(measure(&mut renderer, &mesh, dir.path(), height)?);
    }
    Ok((markdown(&rows, &renderer.gpu.adapter_name), serde_json::to_string_pretty(&rows)?))
}

fn measure(renderer: &mut Renderer, mesh: &Path, dir: &Path, height: u32) -> anyhow::Result<ScaleRow> {
    let ovx = dir.join(format!("nefertiti{height}.ovx"));
    let import = import(mesh, &ovx, height)?;
    let start = Instant::now();
    let mut scene = octovox::io::ovx::load_ovx(&ovx, &Default::default())?;
    let ovx_load_s = start.elapsed().as_secs_f64();
    let pool = scene.drawn_pool_bytes();
    let start = Instant::now();
    let vox_save = octovox::io::save_scene(&dir.join("saved.vox"), &scene, WriteOptions::default())
        .map_or_else(|e| VoxSave::Err(e.to_string()), |()| VoxSave::Ok(start.elapsed().as_secs_f64()));
    let _ = std::fs::remove_file(dir.join("saved.vox"));
    renderer.sync(&mut scene);
    let (lo, hi) = scene.solid_bounds().context("empty import")?;
    let camera = Camera::framing(lo, hi, 50.0);
    let settings = RenderSettings::default();
    renderer.render(&scene, &camera, FRAME, &settings, None)?;
    let frames: anyhow::Result<Vec<f64>> =
        (0..3).map(|_| Ok(renderer.render(&scene, &camera, FRAME, &settings, None)?)).collect();
    // A sphere on the statue's front: half of it cuts in, half adds.
    let centre = IVec3::new((lo.x + hi.x) / 2, (lo.y + hi.y) / 2, hi.z);
    let start = Instant::now();
    scene.apply_brush(&Shape::Sphere { center: centre, radius: 64 }, Op::Place(2))?;
    renderer.sync(&mut scene);
    let edit_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(ScaleRow {
        height,
        voxels: import.voxels,
        import_s: import.seconds,
        import_peak_mb: import.peak_bytes.map(|b| b as f64 / 1e6),
        pool_mb: pool as f64 / 1e6,
        bytes_per_voxel: pool as f64 / import.voxels.max(1) as f64,
        ovx_mb: std::fs::metadata(&ovx)?.len() as f64 / 1e6,
        ovx_load_s,
        vox_save,
        frame_ms: median(frames?),
        edit_ms,
    })
}

/// `octovox import --stats` in a child process: its time and its own peak.
fn import(mesh: &Path, out: &Path, height: u32) -> anyhow::Result<ImportStats> {
    let exe = std::env::current_exe().context("the octovox binary")?;
    let output = Command::new(exe)
        .arg("import")
        .arg(mesh)
        .arg("-o")
        .arg(out)
        .args(["--size", &height.to_string(), "--up", "z", "--force", "--stats"])
        .output()?;
    if !output.status.success() {
        anyhow::bail!("import at {height} failed: {}", String::from_utf8_lossy(&output.stderr));
    }
    serde_json::from_slice(&output.stdout).context("import --stats prints JSON")
}

fn markdown(rows: &[ScaleRow], adapter: &str) -> String {
    let mut md = header("Scale: Nefertiti from 512 to 4096 voxels tall");
    md += &format!(
        "`meshes/nefertiti.obj` imported with `--up z` at each height. *Import*: `octovox import --stats` as a child process (voxelize, build, write the .ovx), its wall time and its own peak resident memory (VmHWM). Then in one process: the .ovx read back, saved as .vox (refused past the 2^26 voxels a .vox can be read back with), a {}×{} preview frame on **{adapter}** (median of 3 after one, camera framing the statue), and a radius-64 sphere placed on its front plus the upload of what it changed.\n\n",
        FRAME.0, FRAME.1
    );
    md += "| height | solid voxels | import s | import peak MB | pool MB | pool B / voxel | .ovx MB | .ovx load s | .vox save s | frame ms | r = 64 edit + upload ms |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        let save = match &r.vox_save {
            VoxSave::Ok(s) => format!("{s:.2}"),
            VoxSave::Err(_) => "refused (> 2^26 voxels)".into(),
        };
        md += &format!(
            "| {} | {} | {:.2} | {} | {:.1} | {:.3} | {:.1} | {:.2} | {save} | {:.1} | {:.1} |\n",
            r.height,
            r.voxels,
            r.import_s,
            r.import_peak_mb.map_or("-".into(), |m| format!("{m:.0}")),
            r.pool_mb,
            r.bytes_per_voxel,
            r.ovx_mb,
            r.ovx_load_s,
            r.frame_ms,
            r.edit_ms
        );
    }
    md
}
