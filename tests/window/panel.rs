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
        // The pointer stays on the button until the app has run a pass over
        // the click: egui tests a release against the pointer's latest
        // place, so a move away in the same (slow, path-traced) frame lost it.
        std::thread::sleep(Duration::from_millis(1500));
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

/// The Render panel's presets after eight wheel notches down the panel of
/// an 800×600 window (the sections above them keep their heights), and the
/// strip of the panel they sit in.
const PRESETS: [(&str, u32); 5] =
    [("draft", 415), ("preview", 438), ("path: quick", 461), ("path: good", 484), ("reference", 507)];
const PRESET_STRIP: (u32, u32, u32, u32) = (20, 400, 200, 520);

/// Issue 47, item 2: a quick click on a preset did nothing, and after a
/// preset switch a noise line wrapped and pushed the presets down 15 px, so
/// the spot that meant "good" meant "reference". Every preset takes an
/// instant move and a quick click (press and release at once), and after
/// every switch the presets are where they were, pixel for pixel.
#[test]
fn every_preset_takes_a_quick_click_and_none_moves() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--size".to_owned(), format!("{WIDTH}x{HEIGHT}")];
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    lines.wait_for("noise: ", Duration::from_secs(90));
    xdotool(&display, &["mousemove", "--window", &window, "200", "300"]);
    std::thread::sleep(Duration::from_millis(300));
    for _ in 0..8 {
        xdotool(&display, &["click", "5"]);
        std::thread::sleep(Duration::from_millis(100));
    }
    let strip = |shot: &image::RgbImage| {
        let (x0, y0, x1, y1) = PRESET_STRIP;
        (y0..y1).flat_map(|y| (x0..x1).map(move |x| shot.get_pixel(x, y).0)).collect::<Vec<_>>()
    };
    let before = strip(&resting_shot(&display, &window, dir.path(), "presets-before"));
    for (name, y) in PRESETS {
        xdotool(&display, &["mousemove", "--window", &window, "48", &y.to_string(), "click", "1"]);
        let applied = lines.wait_for("preset:", Duration::from_secs(20));
        assert_eq!(applied, format!("preset: {name}"), "a quick click on {name}");
        let after = strip(&resting_shot(&display, &window, dir.path(), &format!("presets-{name}")));
        let moved = after.iter().zip(&before).filter(|(a, b)| a != b).count();
        assert_eq!(moved, 0, "after {name}, {moved} pixels of the presets changed");
    }
}
