//! Binary little-endian .ply with vertex colours. A vertex has one colour,
//! so each colour's triangles get their own copies of the vertices they use.
//! A scene of objects places each visible object in the world and tells
//! their faces apart: a face property `object` (its index in the header's
//! `comment object K PATH` lines), as .ply has no groups.

use std::collections::HashMap;
use std::fmt::Write as _;

use super::parts::Exported;
use crate::scene::Palette;

pub fn ply(exported: &Exported, palette: &Palette, scale: f32) -> Vec<u8> {
    // (part, mesh vertex, colour) → vertex of the file.
    let mut index: HashMap<(usize, u32, u8), u32> = HashMap::new();
    let mut vertices: Vec<(usize, u32, u8)> = Vec::new();
    let mut faces: Vec<([u32; 3], u32)> = Vec::new();
    for (p, part) in exported.parts.iter().enumerate() {
        for (triangle, color) in &exported.meshes[part.mesh].mesh.triangles {
            let face = part.place.wind(*triangle).map(|v| {
                *index.entry((p, v, *color)).or_insert_with(|| {
                    vertices.push((p, v, *color));
                    u32::try_from(vertices.len() - 1).unwrap_or(u32::MAX)
                })
            });
            faces.push((face, u32::try_from(p).unwrap_or(u32::MAX)));
        }
    }
    let mut bytes = header(exported, vertices.len(), faces.len()).into_bytes();
    for &(p, v, color) in &vertices {
        let part = &exported.parts[p];
        let at = part.place.apply_x2(exported.meshes[part.mesh].mesh.positions_x2[v as usize]);
        for c in at.to_array() {
            bytes.extend(((c * 0.5 * f64::from(scale)) as f32).to_le_bytes());
        }
        bytes.extend(&palette.color(color)[..3]);
    }
    for (face, part) in &faces {
        bytes.push(3);
        for v in face {
            bytes.extend(v.to_le_bytes());
        }
        if exported.objects {
            bytes.extend(part.to_le_bytes());
        }
    }
    bytes
}

fn header(exported: &Exported, vertices: usize, faces: usize) -> String {
    let mut header =
        String::from("ply\nformat binary_little_endian 1.0\ncomment exported by octovox: greedy-meshed voxels, y up\n");
    // Writing to a String cannot fail.
    if exported.objects {
        for (k, part) in exported.parts.iter().enumerate() {
            let _ = writeln!(header, "comment object {k} {}", part.path());
        }
    }
    let _ = write!(
        header,
        "element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {faces}\nproperty list uchar uint vertex_indices\n"
    );
    if exported.objects {
        header.push_str("property uint object\n");
    }
    header.push_str("end_header\n");
    header
}
