//! `octovox export`: greedy meshes that are small, closed and outward, read
//! back from the files themselves (not through the code that wrote them).
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

mod common;

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().unwrap()
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// Positions and triangles (0-based) of an .obj's `v` and `f` lines.
fn read_obj(path: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"v") => positions.push([1, 2, 3].map(|i| words[i].parse().unwrap())),
            Some(&"f") => {
                assert_eq!(words.len(), 4, "not a triangle: {line}");
                triangles.push([1, 2, 3].map(|i| words[i].parse::<usize>().unwrap() - 1));
            }
            _ => {}
        }
    }
    (positions, triangles)
}

/// Positions, colours and triangles of a binary little-endian .ply.
struct Ply {
    positions: Vec<[f64; 3]>,
    colors: Vec<[u8; 3]>,
    triangles: Vec<[usize; 3]>,
}

fn read_ply(path: &Path) -> Ply {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let count = |element: &str| -> usize {
        let line = header.lines().find(|l| l.starts_with(&format!("element {element} "))).unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let mut at = end;
    let mut take = |n: usize| {
        let slice = &bytes[at..at + n];
        at += n;
        slice.to_vec()
    };
    let f32_of = |b: Vec<u8>| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let mut positions = Vec::new();
    let mut colors = Vec::new();
    for _ in 0..nv {
        positions.push([f32_of(take(4)), f32_of(take(4)), f32_of(take(4))]);
        let c = take(3);
        colors.push([c[0], c[1], c[2]]);
    }
    let mut triangles = Vec::new();
    for _ in 0..nf {
        assert_eq!(take(1)[0], 3);
        let index = |b: Vec<u8>| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        triangles.push([index(take(4)), index(take(4)), index(take(4))]);
    }
    assert_eq!(at, bytes.len(), "trailing bytes");
    Ply { positions, colors, triangles }
}

/// Every directed edge between two positions has as many reverse edges
/// (closed and consistently oriented); returns the signed volume.
fn closed_volume(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> f64 {
    let key = |i: usize| positions[i].map(|c| (c * 2.0).round() as i64);
    let mut edges: HashMap<([i64; 3], [i64; 3]), i64> = HashMap::new();
    let mut volume = 0.0;
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            *edges.entry((a, b)).or_default() += 1;
            *edges.entry((b, a)).or_default() -= 1;
        }
        let [a, b, c] = t.map(|i| positions[i]);
        let cross = [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]];
        volume += (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0;
    }
    let open: Vec<_> = edges.iter().filter(|(_, n)| **n != 0).take(3).collect();
    assert!(open.is_empty(), "open or flipped edges, e.g. {open:?}");
    volume
}

/// The test sculpture saved as a .vox in `dir`.
fn sculpture_file(dir: &Path) -> (std::path::PathBuf, u64) {
    let tree = common::sculpture();
    let path = dir.join("sculpture.vox");
    let scene = octovox::scene::Scene { palette: Default::default(), tree };
    octovox::io::save_scene(&path, &scene, Default::default()).unwrap();
    (path, scene.tree.solid_voxels())
}

#[test]
fn a_box_is_twelve_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("box.ovr");
    std::fs::write(&script, "new\ncolor 7\nbrush box 5 3 4\nplace 0 0 0\nsave box.vox\n").unwrap();
    assert!(octovox(&["replay", "--cpu", script.to_str().unwrap()]).status.success());
    let obj = dir.path().join("box.obj");
    let out = octovox(&["export", dir.path().join("box.vox").to_str().unwrap(), "-o", obj.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let (positions, triangles) = read_obj(&obj);
    assert_eq!((positions.len(), triangles.len()), (8, 12));
    assert_eq!(closed_volume(&positions, &triangles).round() as i64, 5 * 3 * 4);
    let mtl = std::fs::read_to_string(dir.path().join("box.mtl")).unwrap();
    assert!(mtl.contains("newmtl palette_7"), "{mtl}");
}

#[test]
fn obj_and_ply_exports_are_closed_outward_and_hold_the_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let (vox, voxels) = sculpture_file(dir.path());
    let (obj, ply) = (dir.path().join("s.obj"), dir.path().join("s.ply"));
    for (out, scale) in [(&obj, "1"), (&ply, "0.5")] {
        let done = octovox(&["export", vox.to_str().unwrap(), "-o", out.to_str().unwrap(), "--scale", scale]);
        assert!(done.status.success(), "{}", text(&done));
    }
    let (positions, triangles) = read_obj(&obj);
    assert_eq!(closed_volume(&positions, &triangles).round() as u64, voxels);
    let Ply { positions, colors, triangles } = read_ply(&ply);
    // Half a unit per voxel: an eighth of the volume.
    assert_eq!((closed_volume(&positions, &triangles) * 8.0).round() as u64, voxels);
    let palette = octovox::scene::Palette::default();
    let used: std::collections::BTreeSet<[u8; 3]> = colors.into_iter().collect();
    for index in [3u8, 17, 80, 200, 255] {
        let c = palette.color(index);
        assert!(used.contains(&[c[0], c[1], c[2]]), "colour of palette index {index} missing");
    }
}

#[test]
fn greedy_meshing_beats_one_quad_per_face() {
    let tree = common::sculpture();
    let mesh = octovox::io::export::greedy::mesh(&tree);
    let naive = mesh.exposed_faces * 2;
    assert!((mesh.triangles.len() as u64) * 2 < naive, "{} triangles, naive {naive}", mesh.triangles.len());
}

#[test]
fn bad_export_targets_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (vox, _) = sculpture_file(dir.path());
    let v = vox.to_str().unwrap();
    let refused = |args: &[&str], needle: &str| {
        let out = octovox(args);
        assert!(!out.status.success() && text(&out).contains(needle), "{args:?}: {}", text(&out));
    };
    refused(&["export", v, "-o", v], "writes .obj, .ply or .glb files");
    refused(&["export", v, "-o", dir.path().join("x.stl").to_str().unwrap()], "writes .obj, .ply or .glb files");
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    refused(&["export", v, "-o", folder.to_str().unwrap(), "--force"], "is a folder");
    for name in ["mine.ply", "mine.glb"] {
        let existing = dir.path().join(name);
        std::fs::write(&existing, b"my mesh").unwrap();
        refused(&["export", v, "-o", existing.to_str().unwrap()], "already exists");
        assert_eq!(std::fs::read(&existing).unwrap(), b"my mesh");
    }
    let mtl = dir.path().join("other.mtl");
    std::fs::write(&mtl, b"my materials").unwrap();
    refused(&["export", v, "-o", dir.path().join("other.obj").to_str().unwrap()], "other.mtl already exists");
}
