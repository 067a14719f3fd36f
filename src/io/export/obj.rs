//! Wavefront .obj text and its .mtl: one material per palette index used.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::VoxelMesh;
use crate::scene::Palette;

/// The .obj: vertices, then the triangles grouped by material (1-based).
pub fn obj(mesh: &VoxelMesh, scale: f32, mtl_name: &str) -> Vec<u8> {
    let mut text = String::from("# exported by octovox: greedy-meshed voxels, one unit per voxel × scale, y up\n");
    // Writing to a String cannot fail.
    let _ = writeln!(text, "mtllib {mtl_name}");
    for i in 0..mesh.positions_x2.len() {
        let [x, y, z] = mesh.position(i as u32).map(|c| c * scale);
        let _ = writeln!(text, "v {x} {y} {z}");
    }
    let colors: BTreeSet<u8> = mesh.triangles.iter().map(|(_, c)| *c).collect();
    for color in colors {
        let _ = writeln!(text, "usemtl palette_{color}");
        for (t, _) in mesh.triangles.iter().filter(|(_, c)| *c == color) {
            let _ = writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    text.into_bytes()
}

/// The .mtl: a diffuse colour per palette index the mesh uses.
pub fn mtl(mesh: &VoxelMesh, palette: &Palette) -> Vec<u8> {
    let mut text = String::from("# exported by octovox: one material per palette colour\n");
    let colors: BTreeSet<u8> = mesh.triangles.iter().map(|(_, c)| *c).collect();
    for color in colors {
        let [r, g, b, _] = palette.color(color).map(|c| f32::from(c) / 255.0);
        let _ = writeln!(text, "newmtl palette_{color}\nKd {r} {g} {b}\n");
    }
    text.into_bytes()
}
