//! Wavefront .obj text and its .mtl: one material per palette index used.
//! A scene of objects writes each visible object as an `o` of its own,
//! named by its path, its vertices placed in the world.

use std::fmt::Write as _;

use super::parts::{Exported, Part};
use crate::scene::Palette;

/// The .obj: per part, its vertices, then its triangles grouped by
/// material (indices 1-based, counted over the whole file).
pub fn obj(exported: &Exported, scale: f32, mtl_name: &str) -> Vec<u8> {
    let mut text = String::from("# exported by octovox: greedy-meshed voxels, one unit per voxel × scale, y up\n");
    // Writing to a String cannot fail.
    let _ = writeln!(text, "mtllib {mtl_name}");
    let mut first = 1;
    for part in &exported.parts {
        if exported.objects {
            let _ = writeln!(text, "o {}", part.path());
        }
        first += write_part(&mut text, exported, part, scale, first);
    }
    text.into_bytes()
}

/// Writes one part's `v`, `usemtl` and `f` lines, its vertices numbered
/// from `first`; returns how many vertices it wrote.
fn write_part(text: &mut String, exported: &Exported, part: &Part, scale: f32, first: usize) -> usize {
    let mesh = &exported.meshes[part.mesh].mesh;
    for &p in &mesh.positions_x2 {
        let [x, y, z] = part.place.apply_x2(p).to_array().map(|c| (c * 0.5 * f64::from(scale)) as f32);
        let _ = writeln!(text, "v {x} {y} {z}");
    }
    let colors: std::collections::BTreeSet<u8> = mesh.triangles.iter().map(|(_, c)| *c).collect();
    for color in colors {
        let _ = writeln!(text, "usemtl palette_{color}");
        for (t, _) in mesh.triangles.iter().filter(|(_, c)| *c == color) {
            let [a, b, c] = part.place.wind(*t).map(|v| v as usize + first);
            let _ = writeln!(text, "f {a} {b} {c}");
        }
    }
    mesh.positions_x2.len()
}

/// The .mtl: a diffuse colour per palette index the meshes use.
pub fn mtl(exported: &Exported, palette: &Palette) -> Vec<u8> {
    let mut text = String::from("# exported by octovox: one material per palette colour\n");
    for color in exported.colors() {
        let [r, g, b, _] = palette.color(color).map(|c| f32::from(c) / 255.0);
        let _ = writeln!(text, "newmtl palette_{color}\nKd {r} {g} {b}\n");
    }
    text.into_bytes()
}
