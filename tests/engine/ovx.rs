//! The native .ovx file through the real binary: `convert` both ways with
//! .vox, `info`, `render`, and the errors of damaged files and budgets.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().expect("run octovox")
}

fn ok(args: &[&str]) -> String {
    let output = octovox(args);
    assert!(output.status.success(), "octovox {args:?}: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn refused(args: &[&str]) -> String {
    let output = octovox(args);
    assert!(!output.status.success(), "octovox {args:?} succeeded");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn info(path: &Path) -> serde_json::Value {
    serde_json::from_str(&ok(&["info", s(path), "--json"])).unwrap()
}

/// Models with scene graphs, materials and several models, .vox → .ovx →
/// .vox: the same voxels, palette entries and materials throughout.
#[test]
fn vox_to_ovx_and_back_keeps_every_voxel() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["magicavoxel/monu9.vox", "format/metal-material.vox", "seed/teapot256.vox"] {
        let vox = common::assets().join("vox").join(name);
        let (ovx, back) = (dir.path().join("a.ovx"), dir.path().join("b.vox"));
        ok(&["convert", s(&vox), s(&ovx), "--force"]);
        ok(&["convert", s(&ovx), s(&back), "--force"]);
        let (a, b, c) = (info(&vox), info(&ovx), info(&back));
        for key in ["voxels", "extent", "min", "max", "palette_entries", "materials"] {
            assert_eq!(a[key], b[key], "{name}: {key} of the .ovx");
            assert_eq!(a[key], c[key], "{name}: {key} after the round trip");
        }
        let original = octovox::io::load_scene(&vox, 0).unwrap();
        let round = octovox::io::load_scene(&back, 0).unwrap();
        assert_eq!(original.voxels(), round.voxels(), "{name}");
        assert_eq!(original.palette.materials, round.palette.materials, "{name}");
    }
}

#[test]
fn an_ovx_renders_like_its_vox() {
    let dir = tempfile::tempdir().unwrap();
    let vox = common::assets().join("vox/magicavoxel/chr_knight.vox");
    let ovx = dir.path().join("knight.ovx");
    ok(&["convert", s(&vox), s(&ovx)]);
    let images: Vec<PathBuf> = ["from-vox.png", "from-ovx.png"].iter().map(|n| dir.path().join(n)).collect();
    ok(&["render", s(&vox), "-o", s(&images[0]), "--size", "160x120", "--cpu"]);
    ok(&["render", s(&ovx), "-o", s(&images[1]), "--size", "160x120", "--cpu"]);
    let (a, b) = (image::open(&images[0]).unwrap(), image::open(&images[1]).unwrap());
    assert_eq!(a.as_bytes(), b.as_bytes());
}

/// A cut file, another version, a flipped byte: each says what it is, exits
/// non-zero, and a failed convert leaves its output as it was.
#[test]
fn damaged_files_are_refused_with_their_own_message() {
    let dir = tempfile::tempdir().unwrap();
    let vox = common::assets().join("vox/seed/torus64.vox");
    let good = dir.path().join("good.ovx");
    ok(&["convert", s(&vox), s(&good)]);
    let bytes = std::fs::read(&good).unwrap();
    let bad = dir.path().join("bad.ovx");
    let out = dir.path().join("out.vox");
    std::fs::write(&out, b"keep me").unwrap();
    let mut version = bytes.clone();
    version[8] = 2;
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 2] ^= 1;
    for (damaged, expected) in [
        (bytes[..bytes.len() / 2].to_vec(), "truncated"),
        (version, "unsupported .ovx version 2"),
        (flipped, "checksum mismatch"),
        (b"not an octree at all".to_vec(), "not an .ovx file"),
    ] {
        std::fs::write(&bad, &damaged).unwrap();
        assert!(refused(&["info", s(&bad)]).contains(expected), "info: {expected}");
        assert!(refused(&["convert", s(&bad), s(&out), "--force"]).contains(expected), "convert: {expected}");
        assert_eq!(std::fs::read(&out).unwrap(), b"keep me");
    }
    let message = refused(&["--memory-budget", "4K", "info", s(&good)]);
    assert!(message.contains("budget (--memory-budget raises it)"), "{message}");
}
