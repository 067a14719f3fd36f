//! Native file dialogs, the window's own file browser and the recent-files
//! list in the real window. A stand-in `zenity` on PATH (rfd's dialog where
//! no desktop portal is) answers Open and Save As with paths; one that gives
//! up at once sends the window to its file browser, whose recent folders
//! and name field are clicked with the mouse.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::path::Path;
use std::time::Duration;

use common::window::*;
use glam::IVec3;
use octovox::scene::{Op, Scene, Shape};

/// The second recent-folder button (`work`, after `sub`) in a 640×480
/// window: the row starts at the browser's left edge.
const RECENT_WORK: (u32, u32) = (268, 45);

fn save_box(path: &Path, max: IVec3) -> u64 {
    let mut scene = Scene::default();
    scene.apply_brush(&Shape::Box { min: IVec3::ZERO, max }, Op::Place(12)).unwrap();
    octovox::io::save_scene(path, &scene, Default::default()).unwrap();
    scene.solid_voxels()
}

#[test]
fn open_and_save_as_go_through_the_native_dialog_or_the_browser() {
    require_window_tools();
    let dir = tempfile::tempdir().unwrap();
    // Folders of fixed names: the recent-folder buttons have known widths.
    let root = std::fs::canonicalize(dir.path()).unwrap().join("work");
    std::fs::create_dir_all(root.join("sub")).unwrap();
    let (a, b, c, d) = (root.join("a.vox"), root.join("b.vox"), root.join("sub/c.vox"), root.join("d.vox"));
    save_box(&a, IVec3::new(7, 0, 7));
    let b_count = save_box(&b, IVec3::new(3, 3, 3));
    save_box(&d, IVec3::new(1, 1, 1));
    // The stand-in dialog: "picks" b.vox to open and c.vox to save as,
    // logs its arguments, and gives up at once while `fail` exists.
    let bin = root.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let script = format!(
        "#!/bin/sh\necho \"$@\" >> {log}\n[ -e {fail} ] && exit 1\n\
         case \"$*\" in *--save*) echo {c} ;; *) echo {b} ;; esac\n",
        log = root.join("zenity.log").display(),
        fail = root.join("fail").display(),
        c = c.display(),
        b = b.display(),
    );
    let zenity = bin.join("zenity");
    std::fs::write(&zenity, script).unwrap();
    std::fs::set_permissions(&zenity, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());

    let (_xvfb, display) = start_xvfb();
    let args = [a.display().to_string(), "--size".into(), "640x480".into()];
    let (_app, mut lines, window) = open_ready_with(&display, &root, &args, &[("PATH", &path)]);

    xdotool(&display, &["key", "ctrl+o"]);
    lines.wait_for("file dialog: native", Duration::from_secs(30));
    let loaded = lines.wait_for("loaded:", Duration::from_secs(30));
    assert!(loaded.contains("b.vox") && loaded.contains(&format!("({b_count} voxels")), "{loaded}");
    xdotool(&display, &["key", "ctrl+shift+s"]);
    let saved = lines.wait_for("saved:", Duration::from_secs(30));
    assert!(saved.ends_with("c.vox"), "{saved}");
    assert_eq!(octovox::io::load_scene(&c, 0).unwrap().solid_voxels(), b_count);
    let log = std::fs::read_to_string(root.join("zenity.log")).unwrap();
    assert!(log.contains("--file-selection") && log.contains("--save"), "{log}");

    // A dialog that never shows: the browser asks instead. It starts in
    // the folder of the document (sub/, where c.vox was saved); the second
    // recent folder (work/, of b.vox) takes it to d.vox's, where its name
    // alone opens it.
    std::fs::write(root.join("fail"), "").unwrap();
    xdotool(&display, &["key", "ctrl+o"]);
    lines.wait_for("file dialog: none showed", Duration::from_secs(30));
    wait_for_browser(&mut lines);
    let before = screenshot_x(&display, &root.join("browser-sub.png"));
    let (x, y) = RECENT_WORK;
    xdotool(&display, &["mousemove", "--window", &window, &x.to_string(), &y.to_string()]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(&display, &["click", "1"]);
    std::thread::sleep(Duration::from_millis(700));
    let after = screenshot_x(&display, &root.join("browser-work.png"));
    // The browser's folder line and file list (the scene behind keeps
    // changing while its samples accumulate).
    let listing = |shot: &image::RgbImage| image::imageops::crop_imm(shot, 100, 150, 440, 190).to_image();
    assert_ne!(listing(&after), listing(&before), "the browser shows another folder");
    type_in_browser(&display, &window, (640, 480), Path::new("d.vox"));
    assert!(lines.wait_for("loaded:", Duration::from_secs(30)).contains("d.vox"));

    // Newest first: d (opened), c (saved as), b (opened), a (the first file).
    let recent = std::fs::read_to_string(root.join("config/octovox/recent.txt")).unwrap();
    let listed: Vec<&str> = recent.lines().collect();
    let want: Vec<String> = [&d, &c, &b, &a].iter().map(|p| p.display().to_string()).collect();
    assert_eq!(listed, want);
}
