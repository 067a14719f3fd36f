//! Clicks meant for the panels and dialogs never reach the scene, and a
//! Save As never replaces another file without asking (issue 47, item 1;
//! issue 48, item 5).
//!
//! egui says whether a press is its own from the hover of the last frame:
//! a pointer moved onto a button and pressed before the next frame (what
//! `xdotool mousemove … click 1` does, and a quick hand does) reached the
//! scene behind the button, and the stray voxels went into the file and
//! the journal. Here every click is such an instant move and press, from a
//! spot over the model.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::time::Duration;

use common::window::*;

/// Left-panel controls of an 800×600 window (egui lays the panel out the
/// same on every machine: its fonts are built in), in the order clicked:
/// brushes, tools, a mirror plane on and off, the ground on and off, two
/// swatches, then the modes, each on and off.
const PANEL: [(&str, u32, u32); 21] = [
    ("Sphere", 92, 125),
    ("Voxel", 32, 125),
    ("Box", 148, 125),
    ("Sphere", 92, 125),
    ("Erase", 122, 61),
    ("Paint", 195, 61),
    ("Attach", 43, 61),
    ("Mirror x", 60, 204),
    ("Mirror x", 60, 204),
    ("Ground", 15, 227),
    ("Ground", 15, 227),
    ("swatch 1", 18, 304),
    ("swatch 2", 30, 304),
    ("Line", 37, 84),
    ("Line", 37, 84),
    ("Select", 108, 84),
    ("Select", 108, 84),
    ("Object", 195, 84),
    ("Object", 195, 84),
    ("Attach", 43, 61),
    ("Voxel", 32, 125),
];

/// Moves the pointer onto the model and lets a frame see it there, then
/// moves to `(x, y)` and clicks at once.
fn instant_click(display: &str, window: &str, over_model: (u32, u32), x: u32, y: u32) {
    let (mx, my) = (over_model.0.to_string(), over_model.1.to_string());
    xdotool(display, &["mousemove", "--window", window, &mx, &my]);
    std::thread::sleep(Duration::from_millis(400));
    xdotool(display, &["mousemove", "--window", window, &x.to_string(), &y.to_string(), "click", "1"]);
    std::thread::sleep(Duration::from_millis(300));
}

#[test]
fn an_instant_click_on_a_panel_or_a_dialog_edits_nothing() {
    let (dir, file, original, camera) = torus_document();
    let (_xvfb, display) = start_xvfb();
    let args = document_args(&file, &camera, &[]);
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &args);
    let (x, y, _, _) = stable_pixel(original.drawn(), &camera, |_, _| true);
    for (name, bx, by) in PANEL {
        instant_click(&display, &window, (x, y), bx, by);
        assert!(
            !lines.seen.iter().any(|l| l.starts_with("edit:")),
            "a click on {name} edited the scene: {:?}",
            lines.seen
        );
    }
    // And the other way: from the panel straight onto the model, a click
    // edits (it was lost: egui still said the pointer was its own).
    let (px, py) = (PANEL[0].1, PANEL[0].2);
    instant_click(&display, &window, (px, py), x, y);
    lines.wait_for("edit:", Duration::from_secs(20));
    xdotool(&display, &["key", "ctrl+z"]);
    lines.wait_for("undo:", Duration::from_secs(20));
    lines.seen.retain(|l| !l.starts_with("edit:"));
    // The Save As browser's name field, over the model.
    xdotool(&display, &["key", "ctrl+shift+s"]);
    wait_for_browser(&mut lines);
    instant_click(&display, &window, (WIDTH - 40, HEIGHT - 40), WIDTH / 2 - 30, HEIGHT / 2 + 20 + 105);
    xdotool(&display, &["key", "Escape"]);
    std::thread::sleep(Duration::from_millis(500));
    // Whatever lines came late: none is an edit, and the file and the
    // journal hold nothing new.
    let _ = lines.try_wait_for("edit:", Duration::from_secs(2));
    assert!(!lines.seen.iter().any(|l| l.starts_with("edit:")), "{:?}", lines.seen);
    save(&display, &mut lines, &file);
    let voxels: std::collections::HashSet<glam::IVec3> = original.voxels().into_iter().map(|(p, _)| p).collect();
    assert_eq!(voxel_set(&file), voxels, "the saved file holds the voxels it had");
}

/// Save As onto an existing file asks first: Escape keeps the file as it
/// was; Replace (Tab, Return: the modal's first button) replaces it.
#[test]
fn save_as_asks_before_replacing_another_file() {
    let (dir, file, original, camera) = torus_document();
    let other = dir.path().join("other.vox");
    std::fs::write(&other, b"not really a model, but someone's file").unwrap();
    let before = std::fs::read(&other).unwrap();
    let (_xvfb, display) = start_xvfb();
    let (_app, mut lines, window) = open_ready(&display, dir.path(), &document_args(&file, &camera, &[]));
    for answer in ["Escape", "Replace"] {
        xdotool(&display, &["key", "ctrl+shift+s"]);
        answer_browser(&display, &window, &mut lines, (WIDTH, HEIGHT), &other);
        let asked = lines.wait_for("asking:", Duration::from_secs(30));
        assert!(asked.ends_with("other.vox exists"), "{asked}");
        std::thread::sleep(Duration::from_millis(500));
        assert_eq!(std::fs::read(&other).unwrap(), before, "replaced without asking");
        if answer == "Escape" {
            xdotool(&display, &["key", "Escape"]);
            std::thread::sleep(Duration::from_millis(500));
        } else {
            xdotool(&display, &["key", "Tab"]);
            std::thread::sleep(Duration::from_millis(300));
            xdotool(&display, &["key", "Return"]);
            let saved = lines.wait_for("saved:", Duration::from_secs(30));
            assert!(saved.ends_with("other.vox"), "{saved}");
        }
    }
    assert_eq!(voxel_set(&other).len() as u64, original.solid_voxels(), "Replace wrote the scene");
    // The document is now other.vox: Ctrl+S saves over it without asking.
    save(&display, &mut lines, &other);
}
