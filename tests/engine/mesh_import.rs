//! Mesh voxelization: solids come out filled and to scale, the shared meshes
//! import, bad .obj files get clear errors (never a panic), and `octovox
//! import` writes a .vox that reads back the same.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{IVec3, UVec3};
use octovox::io::mesh::{DenseVoxels, MeshError, UpAxis, load_obj_triangles, voxelize, voxelize_dense, voxelize_obj};
use octovox::scene::Octree;

/// The dense reference voxelization, after checking that the streaming one
/// (what `import` and the window use) gives exactly its voxels.
fn voxelized(path: &Path, size: u32, up: UpAxis, color: u8) -> DenseVoxels {
    let dense = voxelize_dense(&load_obj_triangles(path, up).unwrap(), size, color);
    let streamed = voxelize_obj(path, size, up, color).unwrap();
    let reference = Octree::from_dense(dense.dims, IVec3::ZERO, &dense.data).unwrap();
    assert_eq!(streamed.voxels(), reference.voxels(), "{} at {size}", path.display());
    assert_eq!((streamed.origin(), streamed.depth()), (reference.origin(), reference.depth()));
    streamed.check_invariants().unwrap();
    dense
}

fn write_obj(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// An axis-aligned box from (0,0,0) to `size`: 8 vertices, 12 triangles.
fn box_obj(size: [f32; 3]) -> String {
    let mut text = String::new();
    for i in 0..8 {
        let corner = [i & 1, (i >> 1) & 1, (i >> 2) & 1];
        text += &format!(
            "v {} {} {}\n",
            corner[0] as f32 * size[0],
            corner[1] as f32 * size[1],
            corner[2] as f32 * size[2]
        );
    }
    // Quads by their corner indices (1-based), split into triangles.
    for [a, b, c, d] in [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]] {
        text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
    }
    text
}

fn cube_obj(s: f32) -> String {
    box_obj([s; 3])
}

/// A closed UV sphere of radius 1.
fn sphere_obj(rings: usize, segments: usize) -> String {
    let mut text = String::from("v 0 1 0\n");
    for r in 1..rings {
        let phi = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let theta = 2.0 * PI * s as f32 / segments as f32;
            text += &format!("v {} {} {}\n", phi.sin() * theta.cos(), phi.cos(), phi.sin() * theta.sin());
        }
    }
    text += "v 0 -1 0\n";
    let ring = |r: usize, s: usize| 2 + (r - 1) * segments + s % segments;
    let bottom = 2 + (rings - 1) * segments;
    for s in 0..segments {
        text += &format!("f 1 {} {}\n", ring(1, s + 1), ring(1, s));
        text += &format!("f {bottom} {} {}\n", ring(rings - 1, s), ring(rings - 1, s + 1));
        for r in 1..rings - 1 {
            let (a, b, c, d) = (ring(r, s), ring(r, s + 1), ring(r + 1, s + 1), ring(r + 1, s));
            text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    text
}

#[test]
fn a_cube_fills_its_whole_block() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_obj(dir.path(), "cube.obj", &cube_obj(3.0));
    let dense = voxelized(&path, 8, UpAxis::Y, 7);
    assert_eq!(dense.dims, UVec3::splat(8));
    assert_eq!(dense.solid_count(), 512);
    assert!(dense.data.iter().all(|&v| v == 7));
}

#[test]
fn a_sphere_has_the_volume_of_a_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_obj(dir.path(), "sphere.obj", &sphere_obj(48, 96));
    let dense = voxelized(&path, 48, UpAxis::Y, 1);
    assert_eq!(dense.dims, UVec3::splat(48));
    let expected = 4.0 / 3.0 * PI * 24f32.powi(3);
    let ratio = dense.solid_count() as f32 / expected;
    assert!((0.97..1.01).contains(&ratio), "{} voxels, {ratio:.4} of a ball", dense.solid_count());
    // Solid, not a shell: the centre column is filled from bottom to top.
    let at = |x: u32, y: u32, z: u32| dense.data[(x + 48 * (y + 48 * z)) as usize];
    assert!((2..46).all(|y| at(24, y, 24) == 1));
    assert_eq!(at(0, 0, 0), 0);
}

#[test]
fn an_open_mesh_does_not_leak_to_the_top() {
    // A closed 4³ cube, and beside it a box without its top face: columns
    // through the open box cross it once, and must not fill up to the top.
    let closed = cube_obj(4.0);
    let open: String = cube_obj(4.0)
        .lines()
        .filter(|l| !l.starts_with("f 3 7") && !l.starts_with("f 3 8"))
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f32> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                format!("v {} {} {}\n", c[0] + 6.0, c[1], c[2])
            }
            None => {
                let i: Vec<usize> = l[2..].split(' ').map(|x| x.parse::<usize>().unwrap() + 8).collect();
                format!("f {} {} {}\n", i[0], i[1], i[2])
            }
        })
        .collect();
    assert_eq!(open.lines().filter(|l| l.starts_with("f ")).count(), 10);
    let dir = tempfile::tempdir().unwrap();
    let path = write_obj(dir.path(), "open.obj", &(closed + &open));
    let dense = voxelized(&path, 10, UpAxis::Y, 1);
    assert_eq!(dense.dims, UVec3::new(10, 4, 4));
    assert_eq!(dense.solid_count(), 64);
}

#[test]
fn the_shared_meshes_import_upright_and_solid() {
    let nefertiti = common::assets().join("meshes/nefertiti.obj");
    let dense = voxelized(&nefertiti, 128, UpAxis::Z, 1);
    // The bust stands: its height (mesh z) is the longest side, now y.
    assert_eq!(dense.dims.y, 128);
    assert!(dense.dims.x < 128 && dense.dims.z < 128, "{:?}", dense.dims);
    let filled = dense.solid_count() as f64 / dense.data.len() as f64;
    assert!((0.2..0.35).contains(&filled), "{filled}");
    let bunny = common::assets().join("meshes/stanford-bunny.obj");
    let dense = voxelized(&bunny, 64, UpAxis::Y, 1);
    assert_eq!(dense.dims.max_element(), 64);
    assert!(dense.solid_count() > 64 * 64 * 64 / 10, "{}", dense.solid_count());
}

#[test]
fn bad_meshes_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str); 6] = [
        ("garbage.obj", "\u{0}\u{1}\u{2} this is not a mesh\nf x y z\n", ":2: face vertex index 'x'"),
        ("empty.obj", "", "no triangles"),
        ("points.obj", "v 0 0 0\nv 1 0 0\n", "no triangles"),
        ("nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", ":2: vertex coordinate nan is not a finite"),
        ("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", "out of bounds"),
        ("flat.obj", "v 0 0 0\nv 1e38 0 0\nv 0 -1e38 0\nf 1 2 3\n", "encloses no voxel"),
    ];
    for (name, text, message) in cases {
        let path = write_obj(dir.path(), name, text);
        let shown = voxelize_obj(&path, 16, UpAxis::Y, 1).unwrap_err().to_string();
        assert!(shown.contains(name) && shown.contains(message), "{name}: {shown}");
    }
    let missing = dir.path().join("missing.obj");
    assert!(matches!(voxelize_obj(&missing, 16, UpAxis::Y, 1), Err(MeshError::Io { .. })));
    let cube = write_obj(dir.path(), "cube.obj", &cube_obj(1.0));
    for size in [0, 9000] {
        let e = voxelize_obj(&cube, size, UpAxis::Y, 1).unwrap_err();
        assert!(e.to_string().contains(&size.to_string()), "{e}");
    }
}

#[test]
fn import_writes_a_vox_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(dir.path(), "slab.obj", &box_obj([30.0, 2.0, 3.0]));
    let vox = dir.path().join("slab.vox");
    let bin = env!("CARGO_BIN_EXE_octovox");
    let out =
        Command::new(bin).args(["import"]).arg(&obj).arg("-o").arg(&vox).args(["--size", "300"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Wider than one .vox model (256): saved as several, read back whole.
    let model = octovox::io::vox::load_vox_file(&vox, 0).unwrap();
    assert_eq!(model.voxels.len(), 300 * 20 * 30);
    // The window and `render` open .obj files directly too.
    let scene = octovox::io::load_scene(&obj, 0).unwrap();
    assert_eq!(scene.solid_voxels(), 256 * 17 * 26);

    // Saving never writes .vox bytes over a mesh.
    let e = octovox::io::save_scene(&obj, &scene, Default::default()).unwrap_err();
    assert!(e.to_string().contains("saved as .vox"), "{e}");
    assert!(std::fs::read_to_string(&obj).unwrap().starts_with("v "));

    let bad = write_obj(dir.path(), "bad.obj", "v 0 0 0\nf 1 2 3\n");
    let out = Command::new(bin).args(["import"]).arg(&bad).arg("-o").arg(dir.path().join("bad.vox")).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.obj") && !err.contains("panicked"), "{err}");
}

/// The streaming voxelizer, tile by tile, gives exactly the dense one's
/// voxels, at sizes that cut tiles and cubes in every way (the shared
/// meshes, 1 to 3 tiles of 64 columns a side, and one past a power of two).
#[test]
fn streaming_equals_dense_on_the_shared_meshes() {
    let nefertiti = common::assets().join("meshes/nefertiti.obj");
    let bunny = common::assets().join("meshes/stanford-bunny.obj");
    for size in [63, 64, 65, 130, 200] {
        voxelized(&nefertiti, size, UpAxis::Z, 3);
        voxelized(&bunny, size, UpAxis::Y, 5);
    }
    let triangles = load_obj_triangles(&nefertiti, UpAxis::Z).unwrap();
    assert_eq!(
        voxelize(&triangles, 1, 1, &Default::default()).unwrap().solid_voxels(),
        voxelize_dense(&triangles, 1, 1).solid_count() as u64
    );
}
