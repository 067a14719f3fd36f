//! The browser build in headless Chromium with WebGPU (docs/web.md):
//! `drive.mjs` plays each scenario on `target/web` (made by `bash
//! web/build`, which `.ci/test` runs first) with real mouse clicks and keys
//! and leaves the console, screenshots and downloads; the checks here read
//! them: against the desktop window's picture, and with dot_vox (not
//! octovox's loader) for the files the page saved.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

#[path = "../common/mod.rs"]
mod common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The camera of the scenarios that compare pictures (drive.mjs says the same).
const CAMERA: &str = "96,70,110:32,8,32";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Plays `scenario` (with `given`, a file for the page) and returns the
/// folder of what it left.
fn drive(scenario: &str, given: Option<&Path>) -> tempfile::TempDir {
    let wasm = root().join("target/web/octovox_bg.wasm");
    assert!(wasm.is_file(), "{} is missing: run `bash web/build` first (.ci/test does)", wasm.display());
    let modules = root().join("tests/web/node_modules/puppeteer-core");
    assert!(modules.is_dir(), "puppeteer-core is missing: npm ci --prefix tests/web (.ci/test does)");
    let out = tempfile::tempdir().unwrap();
    let mut command = Command::new("node");
    command.arg(root().join("tests/web/drive.mjs")).arg(scenario).arg(out.path());
    if let Some(given) = given {
        command.arg(given);
    }
    let run = command.output().expect("cannot run node");
    assert!(
        run.status.success(),
        "{scenario}: {}\n{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

/// The page's console, as (type, text).
fn console(out: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(out.join("console.json")).unwrap();
    let messages: Vec<serde_json::Value> = serde_json::from_str(&text).unwrap();
    messages
        .iter()
        .map(|m| (m["type"].as_str().unwrap_or("").to_string(), m["text"].as_str().unwrap_or("").to_string()))
        .collect()
}

fn assert_no_errors(out: &Path) {
    let errors: Vec<_> = console(out).into_iter().filter(|(kind, _)| kind == "error" || kind == "pageerror").collect();
    assert!(errors.is_empty(), "console errors: {errors:#?}");
}

/// A file's voxels in world cells with their colours, read with dot_vox:
/// each model placed by the translations above it (MagicaVoxel centres a
/// model of size s on its translation: cell v lands on t + v − ⌊s/2⌋).
fn world_voxels(path: &Path) -> BTreeSet<([i32; 3], u8)> {
    let data = dot_vox::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = BTreeSet::new();
    if data.scenes.is_empty() {
        for model in &data.models {
            out.extend(model.voxels.iter().map(|v| ([i32::from(v.x), i32::from(v.y), i32::from(v.z)], v.i)));
        }
        return out;
    }
    place(&data, 0, [0, 0, 0], &mut out);
    out
}

fn place(data: &dot_vox::DotVoxData, node: u32, at: [i32; 3], out: &mut BTreeSet<([i32; 3], u8)>) {
    match &data.scenes[node as usize] {
        dot_vox::SceneNode::Transform { frames, child, .. } => {
            let frame = &frames[0];
            assert!(frame.attributes.get("_r").is_none_or(|r| r == "4"), "a rotated model: {frame:?}");
            let t: Vec<i32> = frame
                .attributes
                .get("_t")
                .map_or_else(|| vec![0, 0, 0], |t| t.split(' ').map(|w| w.parse().unwrap()).collect());
            place(data, *child, [at[0] + t[0], at[1] + t[1], at[2] + t[2]], out);
        }
        dot_vox::SceneNode::Group { children, .. } => {
            for child in children {
                place(data, *child, at, out);
            }
        }
        dot_vox::SceneNode::Shape { models, .. } => {
            for shape in models {
                let model = &data.models[shape.model_id as usize];
                let half = [model.size.x as i32 / 2, model.size.y as i32 / 2, model.size.z as i32 / 2];
                out.extend(model.voxels.iter().map(|v| {
                    let cell = [i32::from(v.x), i32::from(v.y), i32::from(v.z)];
                    ([at[0] + cell[0] - half[0], at[1] + cell[1] - half[1], at[2] + cell[2] - half[2]], v.i)
                }));
            }
        }
    }
}

/// `after` holds what `before` holds and exactly one voxel more.
fn assert_one_voxel_added(before: &Path, after: &Path) {
    let (before, after) = (world_voxels(before), world_voxels(after));
    let added: Vec<_> = after.difference(&before).collect();
    let removed: Vec<_> = before.difference(&after).collect();
    assert_eq!((added.len(), removed.len()), (1, 0), "added {added:?}, removed {removed:?}");
}

/// A copy of the shared asset `name` (vox/magicavoxel), for the page.
fn asset_copy(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let given = dir.path().join(name);
    std::fs::copy(root().join("../shared/assets/vox/magicavoxel").join(name), &given).unwrap();
    (dir, given)
}

/// The page starts without a console error and draws the demo scene as
/// the desktop window draws it from the same camera: SwiftShader's WebGPU
/// in Chromium beside lavapipe's Vulkan under Xvfb, the same session and
/// renderer code. Compared over the scene right of the side panel.
#[test]
fn the_page_draws_the_demo_scene_as_the_desktop_window_does() {
    use common::window::{open_ready, screenshot_x, start_xvfb, xdotool};
    let out = drive("start", None);
    assert_no_errors(out.path());
    let page = image::open(out.path().join("start.png")).unwrap().to_rgb8();
    common::window::require_window_tools();
    let (_xvfb, display) = start_xvfb();
    let args: Vec<String> =
        ["--shading", "preview", "--camera", CAMERA, "--size", "1280x720"].iter().map(|a| (*a).to_string()).collect();
    let (_app, _lines, window) = open_ready(&display, out.path(), &args);
    // The pointer on the menu bar, as in the page: no hover highlight.
    xdotool(&display, &["mousemove", "--window", &window, "640", "10"]);
    std::thread::sleep(std::time::Duration::from_millis(800));
    let native = screenshot_x(&display, &out.path().join("window.png"));
    let (x0, y0, x1, y1) = (300, 130, 1150, 690);
    let (mut sum, mut far, mut n, mut levels) = (0.0, 0u32, 0u32, BTreeSet::new());
    for y in y0..y1 {
        for x in x0..x1 {
            let (a, b) = (page.get_pixel(x, y), native.get_pixel(x, y));
            let d = (0..3).map(|c| (i32::from(a[c]) - i32::from(b[c])).abs()).max().unwrap();
            sum += f64::from(d);
            far += u32::from(d > 8);
            n += 1;
            levels.insert(a[1] / 16);
        }
    }
    let mean = sum / f64::from(n);
    let far_share = f64::from(far) / f64::from(n);
    assert!(levels.len() >= 8, "the page's view is nearly flat ({} green levels): blank?", levels.len());
    // Stated tolerance (docs/web.md): mean difference under 1 level of 255,
    // under 0.5 % of the pixels off by more than 8.
    assert!(mean < 1.0 && far_share < 0.005, "page vs window: mean {mean:.3}, {far_share:.5} of pixels off by > 8");
}

/// A real click places a voxel, a right click erases one, Ctrl+Z takes
/// the erase back: the page's Save then holds the scene it saved before
/// plus the one placed voxel.
#[test]
fn clicks_place_and_erase_and_ctrl_z_undoes() {
    let out = drive("edit", None);
    assert_no_errors(out.path());
    assert_one_voxel_added(&out.path().join("before.vox"), &out.path().join("after.vox"));
    let (placed, shown) =
        (image::open(out.path().join("placed.png")).unwrap(), image::open(out.path().join("before.png")).unwrap());
    assert_ne!(placed.as_bytes(), shown.as_bytes(), "the placed voxel shows");
}

/// A .vox given to the page's file picker opens, and Save As writes the
/// same voxels.
#[test]
fn a_vox_from_the_file_picker_opens_and_saves_the_same_voxels() {
    let (_dir, given) = asset_copy("chr_knight.vox");
    let out = drive("open", Some(&given));
    assert_no_errors(out.path());
    assert_eq!(world_voxels(&out.path().join("copy.vox")), world_voxels(&given));
}

/// `?open=URL` opens a model shared as a link.
#[test]
fn a_model_shared_as_a_link_opens() {
    let (_dir, given) = asset_copy("teapot.vox");
    let out = drive("link", Some(&given));
    assert_no_errors(out.path());
    assert_eq!(world_voxels(&out.path().join("linked.vox")), world_voxels(&given));
}

/// A replay script played in the page (File ▸ Play script…) gives the
/// voxels `octovox replay` gives on the same script: its own `save` line
/// writes the file, a download in the page.
#[test]
fn a_script_played_in_the_page_gives_what_octovox_replay_gives() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = std::fs::read_to_string(root().join("tests/replays/house.ovr")).unwrap();
    text.push_str("save house.vox\n");
    let script = dir.path().join("house.ovr");
    std::fs::write(&script, text).unwrap();
    let out = drive("replay", Some(&script));
    assert_no_errors(out.path());
    let page_lines: Vec<String> = console(out.path()).into_iter().map(|(_, text)| text).collect();
    assert!(page_lines.iter().any(|l| l.ends_with(" 0 failed") && l.starts_with("replay: ")), "{page_lines:#?}");
    let native = Command::new(env!("CARGO_BIN_EXE_octovox")).arg("replay").arg(&script).output().unwrap();
    assert!(native.status.success(), "{}", String::from_utf8_lossy(&native.stderr));
    let (page, replayed) = (world_voxels(&out.path().join("house.vox")), world_voxels(&dir.path().join("house.vox")));
    assert_eq!(page.len(), 727, "the house's own count (tests/replays/house.ovr)");
    assert_eq!(page, replayed);
}

/// A reload after an edit offers it back (the journal kept in the
/// browser's storage), and Recover gives the scene with the edit: the
/// demo scene an earlier page saved, plus the one voxel the click placed.
#[test]
fn a_reload_after_edits_offers_them_back() {
    let out = drive("recover", None);
    assert_no_errors(out.path());
    assert_one_voxel_added(&out.path().join("before.vox"), &out.path().join("recovered.vox"));
}

/// An edit of an opened (then saved) file, a reload: the page says the
/// edits are kept, and opening the file again offers them back.
#[test]
fn a_files_edits_come_back_when_it_is_opened_after_a_reload() {
    let (_dir, given) = asset_copy("chr_knight.vox");
    let out = drive("reopen", Some(&given));
    assert_no_errors(out.path());
    assert_one_voxel_added(&out.path().join("before.vox"), &out.path().join("recovered.vox"));
}

/// A browser without WebGPU gets a message in the page that says so and
/// what to do, not a blank canvas.
#[test]
fn a_browser_without_webgpu_is_told_so() {
    let out = drive("nogpu", None);
    let shown = std::fs::read_to_string(out.path().join("status.txt")).unwrap();
    assert!(shown.contains("no WebGPU") && shown.contains("desktop build"), "the page shows {shown:?}");
}

/// File ▸ Open recent after a reload, by real clicks on the menu, opens
/// the file from the browser's storage: the same voxels.
#[test]
fn open_recent_after_a_reload_opens_the_kept_file() {
    let (_dir, given) = asset_copy("chr_knight.vox");
    let out = drive("recent", Some(&given));
    assert_no_errors(out.path());
    assert_eq!(world_voxels(&out.path().join("reopened.vox")), world_voxels(&given));
}

/// File ▸ Export mesh… in the page downloads the .glb `octovox export`
/// writes for the same file, byte for byte, and the Khronos validator
/// passes it.
#[test]
fn an_export_from_the_page_is_the_native_export() {
    let (dir, given) = asset_copy("chr_knight.vox");
    let out = drive("export", Some(&given));
    assert_no_errors(out.path());
    let native = dir.path().join("native.glb");
    let export = Command::new(env!("CARGO_BIN_EXE_octovox")).arg("export").arg(&given).arg("-o").arg(&native).output();
    let export = export.unwrap();
    assert!(export.status.success(), "{}", String::from_utf8_lossy(&export.stderr));
    let page = out.path().join("model.glb");
    assert!(
        std::fs::read(&page).unwrap() == std::fs::read(&native).unwrap(),
        "the page's .glb differs from octovox export's"
    );
    let validator = Command::new("node").arg(root().join("tests/gltf/validate.js")).arg(&page).output().unwrap();
    assert!(
        validator.status.success(),
        "{}{}",
        String::from_utf8_lossy(&validator.stdout),
        String::from_utf8_lossy(&validator.stderr)
    );
}
