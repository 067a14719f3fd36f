//! Binary little-endian .ply with vertex colours. A vertex has one colour,
//! so each colour's triangles get their own copies of the vertices they use.

use std::collections::HashMap;

use super::VoxelMesh;
use crate::scene::Palette;

pub fn ply(mesh: &VoxelMesh, palette: &Palette, scale: f32) -> Vec<u8> {
    // (position, colour) → vertex of the file.
    let mut index: HashMap<(u32, u8), u32> = HashMap::new();
    let mut vertices: Vec<(u32, u8)> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len());
    for (triangle, color) in &mesh.triangles {
        faces.push(triangle.map(|v| {
            *index.entry((v, *color)).or_insert_with(|| {
                vertices.push((v, *color));
                u32::try_from(vertices.len() - 1).unwrap_or(u32::MAX)
            })
        }));
    }
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment exported by octovox: greedy-meshed voxels, y up\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    let mut bytes = header.into_bytes();
    for (v, color) in &vertices {
        for c in mesh.position(*v) {
            bytes.extend((c * scale).to_le_bytes());
        }
        bytes.extend(&palette.color(*color)[..3]);
    }
    for face in &faces {
        bytes.push(3);
        for v in face {
            bytes.extend(v.to_le_bytes());
        }
    }
    bytes
}
