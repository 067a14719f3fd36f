//! A procedural stand-in for the report's Pietà: a solid sculpture about
//! 510×484×333 voxels holding over 10 million solid voxels, made of blended
//! ellipsoids with a wavy surface. Deterministic, built as a dense array.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

/// Bounds of the report's Pietà (x, y up, z).
pub const DIMS: UVec3 = UVec3::new(510, 484, 333);

/// (centre, semi-axes) of the blobs, in voxels.
const BLOBS: [(Vec3, Vec3); 5] = [
    (Vec3::new(255.0, 30.0, 166.0), Vec3::new(245.0, 30.0, 155.0)), // plinth
    (Vec3::new(215.0, 200.0, 160.0), Vec3::new(95.0, 125.0, 85.0)), // seated body
    (Vec3::new(215.0, 360.0, 150.0), Vec3::new(50.0, 60.0, 50.0)),  // head
    (Vec3::new(300.0, 95.0, 195.0), Vec3::new(205.0, 38.0, 50.0)),  // lying figure
    (Vec3::new(215.0, 430.0, 150.0), Vec3::new(70.0, 40.0, 60.0)),  // veil
];

fn solid(p: Vec3) -> bool {
    let wave = 0.06 * (p.x * 0.071).sin() * (p.y * 0.053 + 1.0).sin() * (p.z * 0.067 + 2.0).sin()
        + 0.03 * (p.x * 0.19 + p.y * 0.23).sin()
        + 0.025 * (p.x * 0.41 + p.z * 0.37).sin() * (p.y * 0.29).sin();
    BLOBS.iter().any(|(c, s)| ((p - *c) / *s).length_squared() < 1.0 + wave)
}

/// The sculpture as a dense array indexed `x + DIMS.x * (y + DIMS.y * z)`,
/// palette index 1 for stone and 2 for the veil's darker band.
pub fn sculpture_dense() -> Vec<u8> {
    let (nx, ny) = (DIMS.x as usize, DIMS.y as usize);
    let mut data = vec![0u8; nx * ny * DIMS.z as usize];
    data.par_chunks_mut(nx * ny).enumerate().for_each(|(z, slab)| {
        for y in 0..ny {
            for x in 0..nx {
                let p = Vec3::new(x as f32 + 0.5, y as f32 + 0.5, z as f32 + 0.5);
                if solid(p) {
                    slab[x + nx * y] = if y > 400 { 2 } else { 1 };
                }
            }
        }
    });
    data
}
