//! Wavefront .obj meshes, voxelized solid.
//!
//! The mesh is scaled so that its longest side spans `size` voxels, and every
//! voxel whose centre lies inside the surface is filled: for each vertical
//! column of voxel centres, the heights where the column crosses a triangle
//! are collected, sorted, and the voxels between the 1st and 2nd, 3rd and 4th
//! … crossings are solid (the even-odd rule). Closed meshes give solids;
//! a column through a hole has an odd count, and its last crossing is
//! dropped rather than filling to the top.

use std::io::BufReader;
use std::path::{Path, PathBuf};

use glam::{UVec3, Vec2, Vec3};
use rayon::prelude::*;

/// Longest side of an imported mesh when no size is asked for.
pub const DEFAULT_MESH_SIZE: u32 = 256;
/// Largest `size`: at most 1024³ bytes of dense voxels.
pub const MAX_MESH_SIZE: u32 = 1024;
/// Palette index of imported meshes (white in the default palette).
pub const MESH_COLOR: u8 = 1;
/// Largest .obj file read.
pub const MAX_OBJ_BYTES: u64 = 1 << 30;

/// Which mesh axis points up (octovox is y up).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum UpAxis {
    /// The usual .obj convention.
    #[default]
    Y,
    /// Many scans and CAD exports: (x, y, z) becomes octovox (x, z, −y).
    Z,
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: crate::io::input::InputError },
    #[error("{}: not a readable .obj mesh ({reason})", path.display())]
    Parse { path: PathBuf, reason: String },
    #[error("{}: the mesh has no triangles", path.display())]
    Empty { path: PathBuf },
    #[error("{}:{line}: {reason}", path.display())]
    BadVertex { path: PathBuf, line: usize, reason: String },
    #[error("{}: {source}", path.display())]
    OverBudget { path: PathBuf, source: crate::budget::OverBudget },
    #[error("{}: face index {index} refers past the {vertices} vertices", path.display())]
    BadIndex { path: PathBuf, index: u32, vertices: usize },
    #[error("{}: at {size} voxels the mesh encloses no voxel centre (is it closed?)", path.display())]
    NothingInside { path: PathBuf, size: u32 },
    #[error("voxel size {0} is outside 1..={MAX_MESH_SIZE}")]
    Size(u32),
}

/// A dense block of voxels, indexed `x + dims.x * (y + dims.y * z)` (the
/// layout of `Octree::from_dense`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DenseVoxels {
    pub dims: UVec3,
    pub data: Vec<u8>,
}

impl DenseVoxels {
    pub fn solid_count(&self) -> usize {
        self.data.iter().filter(|&&v| v != 0).count()
    }
}

/// Reads an .obj file's triangles, in octovox axes.
pub fn load_obj_triangles(path: &Path, up: UpAxis) -> Result<Vec<[Vec3; 3]>, MeshError> {
    let bytes = crate::io::input::read_limited(path, MAX_OBJ_BYTES)
        .map_err(|source| MeshError::Io { path: path.to_path_buf(), source })?;
    parse_obj(&bytes, path, up)
}

/// The triangles of .obj text, in octovox axes; `path` names it in errors.
pub fn parse_obj(bytes: &[u8], path: &Path, up: UpAxis) -> Result<Vec<[Vec3; 3]>, MeshError> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    // Materials are not used: never open the .mtl files a mesh names.
    let parsed = super::guard::catch_quietly(|| {
        tobj::load_obj_buf(&mut BufReader::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
    });
    let reason = |r: String| MeshError::Parse { path: path.to_path_buf(), reason: r };
    let (models, _materials) = parsed.map_err(reason)?.map_err(|e| match bad_line(bytes) {
        Some((line, text)) => MeshError::BadVertex { path: path.to_path_buf(), line, reason: text },
        None => reason(e.to_string()),
    })?;
    let mut triangles = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let vertices = mesh.positions.len() / 3;
        let vertex = |i: u32| -> Result<Vec3, MeshError> {
            let i = i as usize;
            if i >= vertices {
                return Err(MeshError::BadIndex { path: path.to_path_buf(), index: i as u32, vertices });
            }
            let p = Vec3::from_slice(&mesh.positions[3 * i..3 * i + 3]);
            Ok(match up {
                UpAxis::Y => p,
                UpAxis::Z => Vec3::new(p.x, p.z, -p.y),
            })
        };
        for face in mesh.indices.chunks_exact(3) {
            triangles.push([vertex(face[0])?, vertex(face[1])?, vertex(face[2])?]);
        }
    }
    if triangles.is_empty() {
        return Err(MeshError::Empty { path: path.to_path_buf() });
    }
    let (lo, hi) = bounds(&triangles);
    let all_finite = triangles.iter().flatten().all(|p| p.is_finite());
    if !all_finite || !(hi - lo).is_finite() {
        let (line, reason) = largest_vertex(bytes);
        return Err(MeshError::BadVertex { path: path.to_path_buf(), line, reason });
    }
    Ok(triangles)
}

/// The first `v` or `f` line that does not parse, with the reason, to name
/// the place of an error that the parser reports without one.
fn bad_line(bytes: &[u8]) -> Option<(usize, String)> {
    let text = String::from_utf8_lossy(bytes);
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let problem = match words.next() {
            Some("v") => {
                let coords: Vec<&str> = words.take(3).collect();
                match coords.iter().find(|c| c.parse::<f32>().is_err()) {
                    Some(bad) => Some(format!("vertex coordinate '{bad}' is not a number")),
                    None if coords.len() < 3 => Some("a vertex needs three coordinates".to_owned()),
                    None => None,
                }
            }
            Some("f") => words
                .map(|w| w.split('/').next().unwrap_or(""))
                .find(|index| index.parse::<i64>().map_or(true, |i| i == 0))
                .map(|bad| format!("face vertex index '{bad}' is not a non-zero whole number")),
            _ => None,
        };
        if let Some(problem) = problem {
            return Some((index + 1, problem));
        }
    }
    None
}

/// The line of the vertex with the largest coordinate, and why it is a
/// problem: the mesh's extent overflows 32-bit floats (or a coordinate is
/// not finite to begin with).
fn largest_vertex(bytes: &[u8]) -> (usize, String) {
    let text = String::from_utf8_lossy(bytes);
    let mut worst = (0, 0.0f64, String::new());
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        for word in words.take(3) {
            // Not a number, or past f32: as bad as a coordinate gets.
            let value = word.parse::<f64>().map(f64::abs).ok().filter(|v| *v <= f64::from(f32::MAX));
            let value = value.unwrap_or(f64::INFINITY);
            if worst.0 == 0 || value > worst.1 {
                worst = (index + 1, value, word.to_owned());
            }
        }
    }
    let (line, value, word) = worst;
    let reason = if value.is_finite() {
        format!("vertex coordinate {word} is so large that the mesh's size overflows 32-bit floats")
    } else {
        format!("vertex coordinate {word} is not a finite 32-bit number")
    };
    (line, reason)
}

/// Loads and voxelizes an .obj file: the longest side becomes `size` voxels,
/// all of palette index `color`.
pub fn voxelize_obj(path: &Path, size: u32, up: UpAxis, color: u8) -> Result<DenseVoxels, MeshError> {
    if !(1..=MAX_MESH_SIZE).contains(&size) {
        return Err(MeshError::Size(size));
    }
    let triangles = load_obj_triangles(path, up)?;
    crate::budget::check(
        || format!("voxelizing {} at {size} voxels", path.display()),
        voxelize_bytes(&triangles, size),
    )
    .map_err(|source| MeshError::OverBudget { path: path.to_path_buf(), source })?;
    let dense = voxelize(&triangles, size, color);
    if dense.solid_count() == 0 {
        return Err(MeshError::NothingInside { path: path.to_path_buf(), size });
    }
    Ok(dense)
}

/// The min and max corners of the triangles' vertices.
fn bounds(triangles: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    let lo = triangles.iter().flatten().copied().fold(Vec3::INFINITY, Vec3::min);
    let hi = triangles.iter().flatten().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
    (lo, hi)
}

/// The scale and the block size in voxels of `triangles` at `size`.
fn placement(triangles: &[[Vec3; 3]], size: u32) -> (Vec3, f32, UVec3) {
    let (lo, hi) = bounds(triangles);
    let scale = size as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let dims = ((hi - lo) * scale).ceil().as_uvec3().clamp(UVec3::ONE, UVec3::splat(size));
    (lo, scale, dims)
}

/// Peak memory of [`voxelize`]: the dense block (twice, for the octree
/// built from it), the column lists, and at most one crossing per column
/// under each triangle's footprint.
pub fn voxelize_bytes(triangles: &[[Vec3; 3]], size: u32) -> u64 {
    let (lo, scale, dims) = placement(triangles, size);
    let columns = u64::from(dims.x) * u64::from(dims.z);
    let crossings: u64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|p| (p - lo) * scale);
            let span = |u: f32, v: f32, w: f32| (u.max(v).max(w).ceil() - u.min(v).min(w).floor()) as u64 + 1;
            span(a.x, b.x, c.x) * span(a.z, b.z, c.z)
        })
        .sum();
    2 * u64::from(dims.x) * u64::from(dims.y) * u64::from(dims.z)
        + columns * std::mem::size_of::<Vec<f32>>() as u64
        // A list that grows by doubling may hold twice what it uses.
        + crossings * 8
}

/// Fills the inside of `triangles` (see the module comment). `size` must be
/// at least 1; `triangles` must not be empty.
pub fn voxelize(triangles: &[[Vec3; 3]], size: u32, color: u8) -> DenseVoxels {
    let (lo, scale, dims) = placement(triangles, size);
    let mut columns = crossings(triangles, lo, scale, dims);
    columns.par_iter_mut().for_each(|ys| ys.sort_by(f32::total_cmp));
    let mut data = vec![0u8; dims.x as usize * dims.y as usize * dims.z as usize];
    let plane = dims.x as usize * dims.y as usize;
    // One z slice per task: each owns its part of `data`.
    data.par_chunks_mut(plane).enumerate().for_each(|(z, slice)| {
        for x in 0..dims.x as usize {
            for pair in columns[z * dims.x as usize + x].chunks_exact(2) {
                // Voxels whose centre y + 0.5 lies in [pair[0], pair[1]).
                let first = (pair[0] - 0.5).ceil().max(0.0) as usize;
                let end = ((pair[1] - 0.5).ceil().max(0.0) as usize).min(dims.y as usize);
                for y in first..end {
                    slice[x + dims.x as usize * y] = color;
                }
            }
        }
    });
    DenseVoxels { dims, data }
}

/// For every column (x, z) of voxel centres, the heights (in voxels) at
/// which it crosses a triangle.
fn crossings(triangles: &[[Vec3; 3]], lo: Vec3, scale: f32, dims: UVec3) -> Vec<Vec<f32>> {
    let mut columns = vec![Vec::new(); dims.x as usize * dims.z as usize];
    // Sample slightly off the centre so that no sample lies exactly on a
    // shared edge or vertex, where it would count for two triangles or none.
    let jitter = Vec2::new(0.5 + 1.37e-3, 0.5 + 2.91e-3);
    for triangle in triangles {
        let [a, b, c] = triangle.map(|p| (p - lo) * scale);
        let (a2, b2, c2) = (Vec2::new(a.x, a.z), Vec2::new(b.x, b.z), Vec2::new(c.x, c.z));
        let area = cross(b2 - a2, c2 - a2);
        if area == 0.0 {
            continue; // edge-on: no column crosses it
        }
        let min = a2.min(b2).min(c2) - jitter;
        let max = a2.max(b2).max(c2) - jitter;
        let x_range = (min.x.ceil().max(0.0) as u32)..=(max.x.floor().min(dims.x as f32 - 1.0) as u32);
        let z_range = (min.y.ceil().max(0.0) as u32)..=(max.y.floor().min(dims.z as f32 - 1.0) as u32);
        for z in z_range {
            for x in x_range.clone() {
                let p = Vec2::new(x as f32, z as f32) + jitter;
                // Barycentric weights; all of one sign when p is inside.
                let (wa, wb, wc) =
                    (cross(b2 - p, c2 - p) / area, cross(c2 - p, a2 - p) / area, cross(a2 - p, b2 - p) / area);
                if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                    columns[z as usize * dims.x as usize + x as usize].push(wa * a.y + wb * b.y + wc * c.y);
                }
            }
        }
    }
    columns
}

fn cross(u: Vec2, v: Vec2) -> f32 {
    u.x * v.y - u.y * v.x
}
