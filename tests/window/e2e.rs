//! End to end: the real `octovox` binary in a real window on its own Xvfb
//! display, driven with the real mouse and keyboard through `xdotool`.
//!
//! The test opens a copy of `torus64.vox` with a fixed camera and window size,
//! computes on the CPU (`Camera::basis` + `svo::trace`, the app's own picking
//! path) a window pixel that hits a voxel face, clicks it (Attach), saves with
//! Ctrl+S and checks the file gained exactly the voxel in front of that face;
//! then erases it the same way and checks the file is back to the original.
//! Along the way it screenshots the X screen (model and panel visible), takes
//! the app's own F12 screenshot, and checks from the app's stdout that each
//! click wrote at most 1 KiB to the GPU.
//!
//! The pixel mapping holds because the app traces the whole window at render
//! scale 1 and draws its egui panels *over* the image (docs/window.md).
//!
//! Needs `Xvfb`, `xdotool`, `xwd` and ImageMagick's `convert`
//! (`apt-get install -y mesa-vulkan-drivers xvfb xdotool x11-apps imagemagick`).

// A test: a failed unwrap is a failed test, with its message.
#![allow(clippy::unwrap_used)]

use crate::common;

use std::collections::HashSet;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

use common::window::*;
use glam::IVec3;
use octovox::camera::Camera;
use octovox::scene::{Op, Shape};
use octovox::trace::{Ray, svo};

#[test]
fn click_attach_save_erase_save_in_a_real_window() {
    for tool in ["Xvfb", "xdotool", "xwd", "convert"] {
        require_tool(tool);
    }
    let started = Instant::now();
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/torus64.vox");
    assert!(source.is_file(), "missing test model {}", source.display());
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("torus.vox");
    common::copy_writable(&source, &file);

    // The CPU reference decides where to click and what must happen.
    let original = octovox::io::load_scene(&file, 0).unwrap();
    let original_voxels: HashSet<IVec3> = original.voxels().into_iter().map(|(p, _)| p).collect();
    let (lo, hi) = original.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    let (x, y, hit_voxel, normal) = stable_pixel(original.drawn(), &camera, |_, _| true);
    let placed = hit_voxel + normal;
    assert!(!original_voxels.contains(&placed));
    eprintln!("click at ({x}, {y}): hits {hit_voxel} through face {normal}; attach goes to {placed}");

    let (_xvfb, display) = start_xvfb();
    let args = document_args(&file, &camera, &[]);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);

    let window = find_window(&display, &mut app, &stderr_path);
    let ready = lines.wait_for("octovox: ready", Duration::from_secs(90));
    assert_eq!(ready, format!("octovox: ready {WIDTH}x{HEIGHT}"), "the window must have the requested size");
    // Without a window manager nothing focuses the window; keys go to the focus.
    xdotool(&display, &["windowfocus", "--sync", &window]);

    // The screen shows the model (not one flat colour) and the egui panel.
    let shot = screenshot_x(&display, &dir.path().join("screen.png"));
    let (_, view_variance) = grey_stats(&shot, FREE_X, FREE_Y, WIDTH, HEIGHT);
    assert!(view_variance > 100.0, "the traced view looks flat (variance {view_variance:.1})");
    let (panel_mean, _) = grey_stats(&shot, 4, 300, 200, 340);
    let (sky_mean, _) = grey_stats(&shot, WIDTH - 40, FREE_Y, WIDTH - 4, FREE_Y + 40);
    assert!(
        panel_mean < 80.0 && sky_mean > 120.0,
        "no dark egui panel over the bright sky: panel {panel_mean:.0}, sky {sky_mean:.0}"
    );

    // Attach one voxel in front of the clicked face, save, check the file.
    // A read-only file is not replaced: Ctrl+S asks, Escape cancels.
    let before = std::fs::read(&file).unwrap();
    set_read_only(&file, true);
    let bytes = click(&display, &window, &mut lines, x, y);
    assert!(bytes <= 1024, "a one-voxel click wrote {bytes} bytes to the GPU");
    xdotool(&display, &["key", "ctrl+s"]);
    let asked = lines.wait_for("asking:", Duration::from_secs(30));
    assert!(asked.ends_with("torus.vox is read-only"), "{asked}");
    assert_eq!(std::fs::read(&file).unwrap(), before, "a read-only file was overwritten without asking");
    xdotool(&display, &["key", "Escape"]);
    set_read_only(&file, false);
    save(&display, &mut lines, &file);
    let after_attach = voxel_set(&file);
    let added: Vec<&IVec3> = after_attach.difference(&original_voxels).collect();
    let removed: Vec<&IVec3> = original_voxels.difference(&after_attach).collect();
    assert_eq!((added, removed), (vec![&placed], vec![]), "Attach must add exactly the voxel at hit + normal");

    // The same pixel now hits the new voxel (the ray passed through its cell).
    let edited = octovox::io::load_scene(&file, 0).unwrap();
    let basis = camera.basis(WIDTH, HEIGHT, edited.origin());
    let (o, d) = basis.ray(x, y);
    let again = svo::trace(edited.drawn(), &Ray::new(o, d));
    assert_eq!(again.voxel + edited.origin(), placed);

    // Erase it with the R tool, save, and the file is the original again.
    // The panels are kept between frames while they do not change
    // (EguiLayers): the key must still light the Erase button up.
    let tools_before = screenshot_x(&display, &dir.path().join("tools-before.png"));
    xdotool(&display, &["key", "r"]);
    std::thread::sleep(Duration::from_millis(700));
    let tools_after = screenshot_x(&display, &dir.path().join("tools-after.png"));
    let changed = pixels_changed(&tools_before, &tools_after, 0..230, 50..72);
    assert!(changed > 200, "the tool buttons did not follow the R key ({changed} pixels changed)");
    let bytes = click(&display, &window, &mut lines, x, y);
    assert!(bytes <= 1024, "a one-voxel erase wrote {bytes} bytes to the GPU");
    save(&display, &mut lines, &file);
    assert_eq!(voxel_set(&file), original_voxels, "Erase must remove exactly the placed voxel");

    // A drag is a stroke: several edits, one undo step. It ends on a pixel
    // that (after the first attach) still hits another voxel of the same face
    // layer, so the stroke must place there too.
    let (x, y, top_voxel, _) = stable_pixel(original.drawn(), &camera, |v, n| n == IVec3::Y && v.y == hi.y);
    let mut stroked = original.drawn().clone();
    let first = octovox::scene::Shape::Voxel(top_voxel + IVec3::Y);
    stroked.apply_brush(&first, octovox::scene::Op::Place(1)).unwrap();
    let (ex, ey) = same_layer_pixel(&stroked, &camera, (x, y), top_voxel, IVec3::Y);
    eprintln!("stroke from ({x}, {y}) to ({ex}, {ey})");
    xdotool(&display, &["key", "t"]);
    drag(&display, &window, (x, y), (ex, ey));
    let before = lines.seen.len();
    xdotool(&display, &["key", "ctrl+z"]);
    let undo = lines.wait_for("undo:", Duration::from_secs(30));
    let stroke_edits = lines.seen[before..].iter().filter(|l| l.starts_with("edit:")).count();
    eprintln!("stroke: {stroke_edits} edits, undone by one `{undo}`");
    assert!(stroke_edits >= 2, "dragging along the face made {stroke_edits} edits");
    save(&display, &mut lines, &file);
    assert_eq!(voxel_set(&file), original_voxels, "one Ctrl+Z must undo the whole stroke");

    // The app's own screenshot (F12) lands in saves/ and is not flat.
    xdotool(&display, &["key", "F12"]);
    let line = lines.wait_for("screenshot:", Duration::from_secs(30));
    let png = dir.path().join(line.trim_start_matches("screenshot:").trim());
    let own = image::open(&png).expect("the app's screenshot is a PNG").to_rgb8();
    assert_eq!(own.dimensions(), (WIDTH, HEIGHT));
    assert!(grey_stats(&own, FREE_X, FREE_Y, WIDTH, HEIGHT).1 > 100.0, "the app's screenshot is flat");

    // Ctrl+Q quits without a prompt: everything was saved.
    xdotool(&display, &["key", "ctrl+q"]);
    let status = wait_for_exit(&mut app, Duration::from_secs(30), "Ctrl+Q");
    assert!(status.success(), "octovox exited with {status}");
    for line in lines.seen.iter().filter(|l| l.starts_with("edit:")) {
        let n: u64 = line.split_whitespace().nth(1).and_then(|n| n.parse().ok()).unwrap();
        assert!(n <= 1024, "{line}");
    }
    eprintln!("window test took {:.1} s", started.elapsed().as_secs_f64());
}

/// A file that takes seconds to arrive (a FIFO fed later) loads on the
/// background thread: the window keeps drawing and answering the mouse, and
/// the scene appears when the bytes do.
#[test]
fn slow_load_keeps_the_window_live() {
    for tool in ["Xvfb", "xdotool", "xwd", "convert", "mkfifo"] {
        require_tool(tool);
    }
    let teapot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/teapot256.vox");
    assert!(teapot.is_file(), "missing test model {}", teapot.display());
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("slow.vox");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());

    let (_xvfb, display) = start_xvfb();
    let args = ["--size", "640x480", "--render-scale", "0.5", "--no-shadows"].map(String::from);
    let (mut app, mut lines, window) = open_ready(&display, dir.path(), &args);

    // Open the FIFO through the Open dialog: the reader blocks until we write.
    xdotool(&display, &["key", "ctrl+o"]);
    answer_browser(&display, &window, &mut lines, (640, 480), &dir.path().join("slow.vox"));
    std::thread::sleep(Duration::from_millis(1500));
    // What the app said before and as the load began.
    let _ = lines.rx.try_iter().count();

    // While the load hangs, an orbit still changes the picture.
    let before = screenshot_x(&display, &dir.path().join("before.png"));
    xdotool(&display, &["mousemove", "--window", &window, "420", "240"]);
    xdotool(&display, &["mousedown", "3"]);
    for _ in 0..6 {
        xdotool(&display, &["mousemove_relative", "--", "20", "5"]);
        std::thread::sleep(Duration::from_millis(100));
    }
    xdotool(&display, &["mouseup", "3"]);
    std::thread::sleep(Duration::from_millis(1500));
    let after = screenshot_x(&display, &dir.path().join("after.png"));
    let changed = pixels_changed(&before, &after, 260..640, 40..480);
    assert!(changed > 5000, "the view did not follow the mouse during the load ({changed} pixels changed)");
    // Only previews while it loads (a path-traced sample can take seconds
    // on lavapipe, and the closed dialog stayed on screen that long): no
    // samples were added after the load's first 1.5 s, the orbit's rest included.
    let since: Vec<String> = lines.rx.try_iter().collect();
    assert!(!since.iter().any(|l| l.starts_with("loaded:")), "the load finished too early");
    assert!(!since.iter().any(|l| l.starts_with("noise:")), "path samples during the load: {since:?}");

    // Now the bytes arrive and the teapot replaces the demo.
    std::fs::write(&fifo, std::fs::read(&teapot).unwrap()).unwrap();
    let loaded = lines.wait_for("loaded:", Duration::from_secs(60));
    assert!(loaded.contains("(101683 voxels"), "{loaded}");
    xdotool(&display, &["key", "ctrl+q"]);
    let deadline = Instant::now() + Duration::from_secs(30);
    while app.0.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "octovox did not quit on Ctrl+Q");
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn set_read_only(file: &std::path::Path, read_only: bool) {
    use std::os::unix::fs::PermissionsExt;
    let mode = if read_only { 0o444 } else { 0o644 };
    std::fs::set_permissions(file, std::fs::Permissions::from_mode(mode)).unwrap();
}

/// A window wider than wgpu's default texture limit (8192) panicked inside
/// wgpu; now the device asks for the adapter's limit and the surface is
/// clamped to it, so the window opens and draws.
#[test]
fn a_window_wider_than_8192_pixels_opens_and_draws() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args =
        ["--size", "8193x300", "--render-scale", "0.25", "--no-shadows", "--bench-frames", "3"].map(String::from);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    let status = wait_for_exit(&mut app, Duration::from_secs(90), "the end of its benchmark frames");
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    assert!(status.success() && !stderr.contains("panicked"), "{status}: {stderr}");
}

/// At rest the window path traces: the showroom's effect set is compiled,
/// the samples accumulate to the target, and the picture is not flat.
#[test]
fn the_window_path_traces_the_showroom_at_rest() {
    for tool in ["Xvfb", "xdotool", "import"] {
        require_tool(tool);
    }
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--demo", "showroom", "--size", "480x320", "--samples", "6"].map(String::from);
    let (_app, mut lines, _stderr) = spawn_app(&display, dir.path(), &args);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    let line = lines.wait_for("path: 6 samples", Duration::from_secs(120));
    assert!(line.contains("effects [sun sky emit metal glass]"), "{line}");
    let shot = screenshot_x(&display, &dir.path().join("path.png"));
    let (mean, variance) = grey_stats(&shot, 300, 60, 470, 300);
    assert!(variance > 100.0 && mean > 20.0, "a flat or black path-traced view: mean {mean}, variance {variance}");
}

/// At rest the window reports the raw samples' noise estimate at 2, 4, 8
/// and 16 samples: it falls while the camera rests, and the view it shows
/// (denoised, the default) is not flat.
#[test]
fn the_noise_estimate_falls_while_the_camera_rests() {
    for tool in ["Xvfb", "xdotool", "import"] {
        require_tool(tool);
    }
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--demo", "showroom", "--size", "480x320", "--samples", "16"].map(String::from);
    let (_app, mut lines, _stderr) = spawn_app(&display, dir.path(), &args);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    let mut estimates = Vec::new();
    for samples in [2, 4, 8, 16] {
        let line = lines.wait_for("noise: ", Duration::from_secs(120));
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(words.get(3), Some(&samples.to_string().as_str()), "{line}");
        estimates.push(words[1].parse::<f64>().unwrap());
    }
    lines.wait_for("path: 16 samples", Duration::from_secs(60));
    assert!(estimates.windows(2).all(|w| w[1] < w[0]), "the estimate did not fall: {estimates:?}");
    // Not the √8 of well-behaved noise: two samples of the showroom's lamps,
    // metal and glass rarely catch the bright paths that 16 do, so the
    // first estimates are low (1.58 on lavapipe).
    let ratio = estimates[0] / estimates[3];
    assert!((1.3..4.5).contains(&ratio), "2 to 16 samples divided the estimate by {ratio}");
    let shot = screenshot_x(&display, &dir.path().join("denoised.png"));
    let (mean, variance) = grey_stats(&shot, 300, 60, 470, 300);
    assert!(variance > 100.0 && mean > 20.0, "a flat or black denoised view: mean {mean}, variance {variance}");
}

/// Alt+click is the eyedropper: the colour of the voxel under the cursor
/// (found here by the CPU tracer) becomes the current colour, and the next
/// attach uses it, as the saved file shows.
#[test]
fn alt_click_picks_a_colour_and_shift_click_paint_fills_with_it() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("two.vox");
    let mut scene = octovox::scene::Scene::default();
    let box_of = |x0: i32, color: u8| {
        (Shape::Box { min: IVec3::new(x0, 0, 0), max: IVec3::new(x0 + 7, 7, 7) }, Op::Place(color))
    };
    for (shape, op) in [box_of(0, 12), box_of(8, 77)] {
        scene.apply_brush(&shape, op).unwrap();
    }
    octovox::io::save_scene(&file, &scene, Default::default()).unwrap();
    let camera = Camera {
        eye: glam::DVec3::new(8.0, 14.0, 30.0),
        target: glam::DVec3::new(8.0, 4.0, 4.0),
        fov_y_deg: 50.0,
        ortho: None,
    };
    let (x, y, voxel, normal) = stable_pixel(scene.drawn(), &camera, |v, n| scene.voxel(v) == 77 && n == IVec3::Z);
    let args = document_args(&file, &camera, &["--shading", "preview"]);
    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    xdotool(&display, &["keydown", "alt", "click", "1", "keyup", "alt"]);
    assert_eq!(lines.wait_for("picked colour", Duration::from_secs(30)), "picked colour 77");
    click(&display, &window, &mut lines, x, y);
    save(&display, &mut lines, &file);
    let saved = octovox::io::load_scene(&file, 0).unwrap();
    assert_eq!(saved.voxel(voxel + normal), 77, "the attached voxel has the picked colour");

    // Shift+click with Paint floods the 77 region (the attached voxel
    // included) with the colour picked from the other box: all is 12 then.
    let (x12, y12, _, _) = stable_pixel(scene.drawn(), &camera, |v, n| scene.voxel(v) == 12 && n == IVec3::Z);
    xdotool(&display, &["mousemove", "--window", &window, &x12.to_string(), &y12.to_string()]);
    xdotool(&display, &["keydown", "alt", "click", "1", "keyup", "alt"]);
    assert_eq!(lines.wait_for("picked colour", Duration::from_secs(30)), "picked colour 12");
    xdotool(&display, &["key", "g"]);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    xdotool(&display, &["keydown", "shift", "click", "1", "keyup", "shift"]);
    lines.wait_for("fill:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let filled = octovox::io::load_scene(&file, 0).unwrap();
    assert_eq!(filled.solid_voxels(), 1025);
    assert!(filled.voxels().iter().all(|(_, c)| *c == 12), "the 77 region was filled with 12");
}

/// A mirrored stroke: with `mirror x 8` (the floor's middle) in force (set
/// by a replayed script line), a real drag across the floor attaches the
/// voxels it passes over and their images across the plane, and one Ctrl+Z
/// takes the whole stroke away.
#[test]
fn a_mirrored_stroke_places_both_sides_and_undoes_in_one_step() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (file, scene, camera) = floor_scene(dir.path());
    let script = dir.path().join("mirror.ovr");
    std::fs::write(&script, "mirror x 8\n").unwrap();
    // A floor voxel left of the plane, hit from above, and another of the
    // same layer a little away from it: the stroke goes from one to the other.
    let (x, y, voxel, normal) = stable_pixel(scene.drawn(), &camera, |v, n| n == IVec3::Y && v.x < 6);
    let (ex, ey) = same_layer_pixel(scene.drawn(), &camera, (x, y), voxel, normal);
    let placed = voxel + normal;
    let image = |p: IVec3| IVec3::new(15 - p.x, p.y, p.z);
    let args = document_args(&file, &camera, &["--shading", "preview", "--replay", &script.display().to_string()]);
    let (_xvfb, display) = start_xvfb();
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("replay:", Duration::from_secs(90));
    xdotool(&display, &["windowfocus", "--sync", &window]);
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["mousedown", "1"]);
    lines.wait_for("edit:", Duration::from_secs(30));
    for i in 1..=4 {
        let (px, py) = (x as i32 + (ex as i32 - x as i32) * i / 4, y as i32 + (ey as i32 - y as i32) * i / 4);
        xdotool(&display, &["mousemove", "--window", &window, &px.to_string(), &py.to_string()]);
        std::thread::sleep(Duration::from_millis(150));
    }
    xdotool(&display, &["mouseup", "1"]);
    save(&display, &mut lines, &file);
    let saved = octovox::io::load_scene(&file, 0).unwrap();
    let added: Vec<IVec3> = saved.voxels().into_iter().map(|(p, _)| p).filter(|p| p.y == 1).collect();
    assert!(added.contains(&placed) && added.contains(&image(placed)), "{placed} and its image: {added:?}");
    assert!(added.len() >= 4, "the stroke passed over at least two cells: {added:?}");
    assert!(added.iter().all(|p| added.contains(&image(*p))), "every voxel has its image: {added:?}");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(octovox::io::load_scene(&file, 0).unwrap().solid_voxels(), 256, "one undo took the stroke away");
}

/// Line mode (L): a real press-drag-release across the floor places one
/// voxel per step of the longest axis, both ends included, touching each
/// other; one Ctrl+Z takes the line away.
#[test]
fn a_dragged_line_in_line_mode() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (file, scene, camera) = floor_scene(dir.path());
    let (xa, ya, va, na) = stable_pixel(scene.drawn(), &camera, |v, n| n == IVec3::Y && v.x < 4);
    let (xb, yb, vb, nb) = stable_pixel(scene.drawn(), &camera, |v, n| n == IVec3::Y && v.x > 11);
    let (a, b) = (va + na, vb + nb);
    let args = document_args(&file, &camera, &["--shading", "preview"]);
    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    xdotool(&display, &["key", "l"]);
    xdotool(&display, &["mousemove", "--window", &window, &xa.to_string(), &ya.to_string()]);
    xdotool(&display, &["mousedown", "1"]);
    for i in 1..=4 {
        let (x, y) = (xa as i32 + (xb as i32 - xa as i32) * i / 4, ya as i32 + (yb as i32 - ya as i32) * i / 4);
        xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
        std::thread::sleep(Duration::from_millis(100));
    }
    xdotool(&display, &["mouseup", "1"]);
    lines.wait_for("line:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    let saved = octovox::io::load_scene(&file, 0).unwrap();
    let added: Vec<IVec3> = saved.voxels().into_iter().map(|(p, _)| p).filter(|p| p.y == 1).collect();
    let steps = (b - a).abs().max_element();
    assert_eq!(added.len() as i32, steps + 1, "{a} to {b}: {added:?}");
    assert!(added.contains(&a) && added.contains(&b), "both ends: {added:?}");
    let touching = added.iter().all(|p| added.iter().any(|q| q != p && (*q - *p).abs().max_element() == 1));
    assert!(touching, "the cells touch: {added:?}");
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(30));
    save(&display, &mut lines, &file);
    assert_eq!(octovox::io::load_scene(&file, 0).unwrap().solid_voxels(), 256, "one undo took the line away");
}

/// A 16×16 floor of colour 20 saved as `floor.vox` in `dir`, and a camera
/// looking down at it from the front.
fn floor_scene(dir: &std::path::Path) -> (PathBuf, octovox::scene::Scene, Camera) {
    let file = dir.join("floor.vox");
    let mut scene = octovox::scene::Scene::default();
    scene.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(15, 0, 15) }, Op::Place(20)).unwrap();
    octovox::io::save_scene(&file, &scene, Default::default()).unwrap();
    let camera = Camera {
        eye: glam::DVec3::new(8.0, 20.0, 24.0),
        target: glam::DVec3::new(8.0, 0.0, 8.0),
        fov_y_deg: 50.0,
        ortho: None,
    };
    (file, scene, camera)
}

/// How many pixels of the rectangle `xs` × `ys` differ between two screenshots.
fn pixels_changed(
    before: &image::RgbImage,
    after: &image::RgbImage,
    xs: std::ops::Range<u32>,
    ys: std::ops::Range<u32>,
) -> usize {
    xs.flat_map(|x| ys.clone().map(move |y| (x, y)))
        .filter(|&(x, y)| before.get_pixel(x, y) != after.get_pixel(x, y))
        .count()
}

/// Issue 27, bug 2: once the side panel was at the end of its scroll range,
/// egui let the wheel go and the 3D view zoomed. Fast notches over the
/// panel, past both ends, must leave every pixel of the view as it was.
#[test]
fn the_wheel_over_the_panel_never_zooms_the_view() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let args = ["--size", "800x600", "--spp", "1"].map(String::from);
    let (mut app, mut lines, stderr_path) = spawn_app(&display, dir.path(), &args);
    let window = find_window(&display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(&display, &["mousemove", "--window", &window, "100", "400"]);
    // The path tracer at rest, its one sample done: the view is still.
    lines.wait_for("path: 1 samples", Duration::from_secs(60));
    std::thread::sleep(Duration::from_millis(500));
    let before = screenshot_x(&display, &dir.path().join("before.png"));
    // Down past the panel's end, then up past its top: 5 (down) and 4 (up).
    for button in ["5", "4"] {
        xdotool(&display, &["click", "--repeat", "40", "--delay", "1", button]);
        std::thread::sleep(Duration::from_millis(300));
    }
    xdotool(&display, &["mousemove", "--window", &window, "100", "420"]);
    std::thread::sleep(Duration::from_millis(800));
    let after = screenshot_x(&display, &dir.path().join("after.png"));
    let (panel, width, height) = (300, before.width().min(800), before.height().min(600));
    let changed = pixels_changed(&before, &after, panel..width, 40..height);
    assert_eq!(changed, 0, "the 3D view changed under a wheel over the panel");
    app.0.kill().unwrap();
}
