//! The side panel stays put: choosing the Sphere or the Box brush, or a
//! material kind with fewer sliders, moves no palette swatch and nothing
//! below (issue 27: a Sphere click pushed the palette down 23 px, so a
//! click meant for red picked another colour). Screenshots before and
//! after, compared pixel by pixel over the palette.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::time::Duration;

use common::window::*;

/// Where the brush buttons are in an 800×600 window (egui lays the panel
/// out the same on every machine: its fonts are built in).
const SPHERE: (u32, u32) = (92, 125);
const BOX: (u32, u32) = (148, 125);
/// The palette's swatches and the colour line below them.
const PALETTE: (u32, u32, u32, u32) = (8, 270, 228, 500);

fn palette_pixels(shot: &image::RgbImage) -> Vec<[u8; 3]> {
    let (x0, y0, x1, y1) = PALETTE;
    (y0..y1).flat_map(|y| (x0..x1).map(move |x| shot.get_pixel(x, y).0)).collect()
}

#[test]
fn choosing_a_brush_moves_no_palette_swatch() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    // The demo scene: MagicaVoxel's default palette, 255 distinct swatches.
    let args = ["--size".to_owned(), format!("{WIDTH}x{HEIGHT}")];
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    // Past the path tracer's first samples and filters (whose first frames
    // compile the denoiser's kernels on lavapipe).
    lines.wait_for("noise: ", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    let shot = |name: &str| resting_shot(&display, &window, dir.path(), &format!("panel-{name}"));
    let voxel = shot("voxel");
    let swatches = palette_pixels(&voxel);
    let distinct: std::collections::HashSet<[u8; 3]> = swatches.iter().copied().collect();
    assert!(distinct.len() > 100, "the palette area shows the swatches ({} colours)", distinct.len());
    for (name, (x, y)) in [("sphere", SPHERE), ("box", BOX)] {
        xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
        std::thread::sleep(Duration::from_millis(400));
        xdotool(&display, &["mousedown", "1"]);
        std::thread::sleep(Duration::from_millis(100));
        xdotool(&display, &["mouseup", "1"]);
        // The frame that shows the click may come after a path-traced one
        // (a band, or a stage of the denoiser): look for up to 10 s.
        let mut after = shot(name);
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        while after.get_pixel(x, y) == voxel.get_pixel(x, y) && std::time::Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(200));
            after = shot(name);
        }
        assert_ne!(after.get_pixel(x, y), voxel.get_pixel(x, y), "the {name} button is selected");
        let moved = palette_pixels(&after).iter().zip(&swatches).filter(|(a, b)| a != b).count();
        assert_eq!(moved, 0, "choosing {name} changed {moved} pixels of the palette");
    }
}
