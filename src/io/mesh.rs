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

use glam::{IVec3, UVec3, Vec2, Vec3};
use rayon::prelude::*;

use crate::io::progress::Progress;
use crate::scene::build::{BLOCK_LEVEL, Block, BlockBuilder, VoxelSource};
use crate::scene::{BuildError, Octree};

/// Longest side of an imported mesh when no size is asked for.
pub const DEFAULT_MESH_SIZE: u32 = 256;
/// Largest `size`. The voxelizer streams tiles of columns, so memory
/// follows the surface; the memory budget has the last word.
pub const MAX_MESH_SIZE: u32 = 8192;
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
    #[error(
        "{}: the mesh is {extent:e} units wide, {distance:e} from the origin: {why} for {size} voxels across it \
         (32-bit floats cannot place them); scale or move it in its file",
        path.display()
    )]
    Unplaceable { path: PathBuf, extent: f32, distance: f32, size: u32, why: &'static str },
    #[error("voxel size {0} is outside 1..={MAX_MESH_SIZE}")]
    Size(u32),
    #[error("{}: {source}", path.display())]
    Build { path: PathBuf, source: BuildError },
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
    let (models, _materials) = parsed.map_err(|panicked| reason(panicked.0))?.map_err(|e| match bad_line(bytes) {
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

/// Loads and voxelizes an .obj file into an octree, streaming: the longest
/// side becomes `size` voxels, all of palette index `color`.
pub fn voxelize_obj(path: &Path, size: u32, up: UpAxis, color: u8) -> Result<Octree, MeshError> {
    voxelize_obj_with(path, size, up, color, &Progress::default())
}

/// [`voxelize_obj`], counting the tiles of columns done in `progress`.
pub fn voxelize_obj_with(
    path: &Path,
    size: u32,
    up: UpAxis,
    color: u8,
    progress: &Progress,
) -> Result<Octree, MeshError> {
    if !(1..=MAX_MESH_SIZE).contains(&size) {
        return Err(MeshError::Size(size));
    }
    let triangles = load_obj_triangles(path, up)?;
    check_placeable(&triangles, size).map_err(|(extent, distance, why)| MeshError::Unplaceable {
        path: path.to_path_buf(),
        extent,
        distance,
        size,
        why,
    })?;
    crate::budget::check(
        || format!("voxelizing {} at {size} voxels", path.display()),
        voxelize_bytes(&triangles, size),
    )
    .map_err(|source| MeshError::OverBudget { path: path.to_path_buf(), source })?;
    let tree = voxelize(&triangles, size, color, progress)
        .map_err(|e| MeshError::Build { path: path.to_path_buf(), source: e })?;
    if tree.solid_voxels() == 0 {
        return Err(MeshError::NothingInside { path: path.to_path_buf(), size });
    }
    Ok(tree)
}

/// Whether f32 can place `size` voxels across the mesh: its extent must be
/// a normal number whose scale to voxels is finite, and a voxel must be
/// wider than a unit in the last place of the coordinates (a mesh of side
/// 1 at 1e30 has all its vertices at one float). Else (extent, distance, why).
fn check_placeable(triangles: &[[Vec3; 3]], size: u32) -> Result<(), (f32, f32, &'static str)> {
    let (lo, hi) = bounds(triangles);
    let extent = (hi - lo).max_element();
    let distance = lo.abs().max(hi.abs()).max_element();
    let voxel = extent / size as f32;
    if !extent.is_normal() || !voxel.is_normal() || !(size as f32 / extent).is_finite() {
        return Err((extent, distance, "too small"));
    }
    if voxel <= distance * f32::EPSILON {
        return Err((extent, distance, "too far from the origin for its size"));
    }
    Ok(())
}

/// The min and max corners of the triangles' vertices.
fn bounds(triangles: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    let lo = triangles.iter().flatten().copied().fold(Vec3::INFINITY, Vec3::min);
    let hi = triangles.iter().flatten().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
    (lo, hi)
}

/// Where the voxels go: the mesh's min corner, voxels per mesh unit, and
/// the block size in voxels.
#[derive(Clone, Copy)]
struct Placement {
    lo: Vec3,
    scale: f32,
    dims: UVec3,
}

fn placement(triangles: &[[Vec3; 3]], size: u32) -> Placement {
    let (lo, hi) = bounds(triangles);
    let scale = size as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let dims = ((hi - lo) * scale).ceil().as_uvec3().clamp(UVec3::ONE, UVec3::splat(size));
    Placement { lo, scale, dims }
}

/// Peak memory of [`voxelize`]: the triangles' tile lists, per thread a few
/// tiles of columns (a list of crossings and one of runs per column), and
/// the pool, estimated from the crossings (at most one per column under each
/// triangle's footprint; each a surface voxel, at most 24 bytes of bricks,
/// nodes and run apiece).
pub fn voxelize_bytes(triangles: &[[Vec3; 3]], size: u32) -> u64 {
    let place = placement(triangles, size);
    let crossings: u64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|p| (p - place.lo) * place.scale);
            let span = |u: f32, v: f32, w: f32| (u.max(v).max(w).ceil() - u.min(v).min(w).floor()) as u64 + 1;
            span(a.x, b.x, c.x) * span(a.z, b.z, c.z)
        })
        .sum();
    let tile = u64::from(TILE) * u64::from(TILE) * 2 * std::mem::size_of::<Vec<f32>>() as u64;
    let threads = rayon::current_num_threads() as u64;
    triangles.len() as u64 * 16 + 4 * threads * tile + crossings * 24
}

/// Columns per side of a tile: the cubes of one tile share its columns.
const TILE: u32 = 1 << BLOCK_LEVEL;

/// Fills the inside of `triangles` (see the module comment) into an octree,
/// one tile of TILE × TILE columns at a time (both cores), so that memory
/// follows the surface and the pool rather than the volume. `size` must be
/// at least 1; `triangles` must not be empty.
///
/// # Errors
/// A mesh wider than the largest octree.
pub fn voxelize(triangles: &[[Vec3; 3]], size: u32, color: u8, progress: &Progress) -> Result<Octree, BuildError> {
    let place = placement(triangles, size);
    let mut builder = BlockBuilder::new(IVec3::ZERO, place.dims)?;
    let block_level = builder.block_level;
    let tiles = builder.cubes_across(place.dims);
    let bins = bin_triangles(triangles, place, block_level, tiles);
    // A few tiles per thread at a time: their cubes go into the tree before
    // the next ones are filled.
    let batch = 4 * rayon::current_num_threads();
    let all: Vec<(u32, u32)> = (0..tiles.z).flat_map(|z| (0..tiles.x).map(move |x| (x, z))).collect();
    progress.start(all.len() as u64);
    for chunk in all.chunks(batch) {
        let built: Vec<Vec<(UVec3, Block)>> = chunk
            .par_iter()
            .map(|&(tx, tz)| {
                let which = &bins[(tz * tiles.x + tx) as usize];
                Columns::of_tile(triangles, which, place, (tx, tz), block_level, color).blocks(tiles.y, block_level)
            })
            .collect();
        for (coord, block) in built.into_iter().flatten() {
            builder.add(coord, block);
        }
        progress.advance(chunk.len() as u64);
    }
    Ok(builder.finish())
}

/// The dense reference of [`voxelize`]: the same columns over the whole
/// block at once (tests compare the two).
pub fn voxelize_dense(triangles: &[[Vec3; 3]], size: u32, color: u8) -> DenseVoxels {
    let place = placement(triangles, size);
    let all: Vec<u32> = (0..triangles.len() as u32).collect();
    let columns = Columns::of(triangles, &all, place, ((0, 0), (place.dims.x, place.dims.z)), color);
    DenseVoxels { dims: place.dims, data: columns.fill() }
}

/// For each tile of columns, the triangles whose footprint reaches it, in
/// mesh order (so each column sees its crossings in the same order as a
/// whole-block pass would).
fn bin_triangles(triangles: &[[Vec3; 3]], place: Placement, block_level: u32, tiles: UVec3) -> Vec<Vec<u32>> {
    let mut bins = vec![Vec::new(); (tiles.x * tiles.z) as usize];
    for (i, triangle) in triangles.iter().enumerate() {
        let Some((xs, zs)) = projected(triangle, place).and_then(|(v, _)| column_ranges(v, place.dims)) else {
            continue;
        };
        for tz in (zs.start() >> block_level)..=(zs.end() >> block_level) {
            for tx in (xs.start() >> block_level)..=(xs.end() >> block_level) {
                bins[(tz * tiles.x + tx) as usize].push(i as u32);
            }
        }
    }
    bins
}

/// Sample slightly off the column centre so that no sample lies exactly on
/// a shared edge or vertex, where it would count for two triangles or none.
const JITTER: Vec2 = Vec2::new(0.5 + 1.37e-3, 0.5 + 2.91e-3);

/// The triangle in voxel units, and its 2D (x, z) area; `None` edge-on.
fn projected(triangle: &[Vec3; 3], place: Placement) -> Option<([Vec3; 3], f32)> {
    let [a, b, c] = triangle.map(|p| (p - place.lo) * place.scale);
    let area = cross(Vec2::new(b.x - a.x, b.z - a.z), Vec2::new(c.x - a.x, c.z - a.z));
    (area != 0.0).then_some(([a, b, c], area))
}

/// The columns (x and z ranges) under a triangle's footprint (its vertices
/// in voxel units, from [`projected`]), or `None` when no column centre can
/// cross it.
fn column_ranges(
    [a, b, c]: [Vec3; 3],
    dims: UVec3,
) -> Option<(std::ops::RangeInclusive<u32>, std::ops::RangeInclusive<u32>)> {
    let min = Vec2::new(a.x.min(b.x).min(c.x), a.z.min(b.z).min(c.z)) - JITTER;
    let max = Vec2::new(a.x.max(b.x).max(c.x), a.z.max(b.z).max(c.z)) - JITTER;
    let (x0, x1) = (min.x.ceil().max(0.0), max.x.floor().min(dims.x as f32 - 1.0));
    let (z0, z1) = (min.y.ceil().max(0.0), max.y.floor().min(dims.z as f32 - 1.0));
    (x0 <= x1 && z0 <= z1).then_some(((x0 as u32)..=(x1 as u32), (z0 as u32)..=(z1 as u32)))
}

/// A rectangle of columns as solid runs: for each column (x, z), the y
/// ranges of voxels inside, in order. Both voxelizers fill from these.
struct Columns {
    /// First column (x, z) and the rectangle's size in columns.
    min: (u32, u32),
    size: (u32, u32),
    height: u32,
    color: u8,
    runs: Vec<Vec<std::ops::Range<u32>>>,
}

impl Columns {
    /// The columns of tile (tx, tz).
    fn of_tile(
        triangles: &[[Vec3; 3]],
        which: &[u32],
        place: Placement,
        tile: (u32, u32),
        level: u32,
        color: u8,
    ) -> Columns {
        let min = (tile.0 << level, tile.1 << level);
        let size = ((place.dims.x - min.0).min(1 << level), (place.dims.z - min.1).min(1 << level));
        Columns::of(triangles, which, place, (min, size), color)
    }

    /// For every column (x, z) of voxel centres in the rectangle, the
    /// heights (in voxels) at which it crosses one of the `which` triangles,
    /// sorted; the voxels whose centre y + 0.5 lies between the 1st and 2nd,
    /// 3rd and 4th, … are inside (even-odd).
    fn of(
        triangles: &[[Vec3; 3]],
        which: &[u32],
        place: Placement,
        (min, size): ((u32, u32), (u32, u32)),
        color: u8,
    ) -> Columns {
        let mut heights = vec![Vec::new(); size.0 as usize * size.1 as usize];
        for &i in which {
            let Some(([a, b, c], area)) = projected(&triangles[i as usize], place) else { continue };
            let Some((xs, zs)) = column_ranges([a, b, c], place.dims) else { continue };
            let (a2, b2, c2) = (Vec2::new(a.x, a.z), Vec2::new(b.x, b.z), Vec2::new(c.x, c.z));
            let (x0, x1) = ((*xs.start()).max(min.0), (*xs.end()).min(min.0 + size.0 - 1));
            let (z0, z1) = ((*zs.start()).max(min.1), (*zs.end()).min(min.1 + size.1 - 1));
            for z in z0..=z1 {
                for x in x0..=x1 {
                    let p = Vec2::new(x as f32, z as f32) + JITTER;
                    // Barycentric weights; all of one sign when p is inside.
                    let (wa, wb, wc) =
                        (cross(b2 - p, c2 - p) / area, cross(c2 - p, a2 - p) / area, cross(a2 - p, b2 - p) / area);
                    if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                        let column = (z - min.1) as usize * size.0 as usize + (x - min.0) as usize;
                        heights[column].push(wa * a.y + wb * b.y + wc * c.y);
                    }
                }
            }
        }
        let height = place.dims.y;
        let runs = heights
            .into_par_iter()
            .map(|mut ys| {
                ys.sort_by(f32::total_cmp);
                let mut runs: Vec<std::ops::Range<u32>> = Vec::new();
                for pair in ys.chunks_exact(2) {
                    let first = ((pair[0] - 0.5).ceil().max(0.0) as u32).min(height);
                    let end = ((pair[1] - 0.5).ceil().max(0.0) as u32).min(height);
                    match runs.last_mut() {
                        // Touching runs are one (a run's cover test needs it).
                        Some(last) if last.end >= first => last.end = last.end.max(end),
                        _ if first < end => runs.push(first..end),
                        _ => {}
                    }
                }
                runs
            })
            .collect();
        Columns { min, size, height, color, runs }
    }

    fn column(&self, x: i32, z: i32) -> Option<&[std::ops::Range<u32>]> {
        let inside = x >= 0 && z >= 0 && (x as u32) < self.size.0 && (z as u32) < self.size.1;
        inside.then(|| self.runs[z as usize * self.size.0 as usize + x as usize].as_slice())
    }

    /// The rectangle as dense voxels, indexed `x + w * (y + height * z)`.
    fn fill(&self) -> Vec<u8> {
        let (w, d) = (self.size.0 as usize, self.size.1 as usize);
        let plane = w * self.height as usize;
        let mut data = vec![0u8; plane * d];
        data.par_chunks_mut(plane).enumerate().for_each(|(z, slice)| {
            for x in 0..w {
                for run in &self.runs[z * w + x] {
                    for y in run.clone() {
                        slice[x + w * y as usize] = self.color;
                    }
                }
            }
        });
        data
    }

    /// The tile's column of cubes, each with its cube coordinate.
    fn blocks(&self, cubes: u32, level: u32) -> Vec<(UVec3, Block)> {
        let tile = UVec3::new(self.min.0 >> level, 0, self.min.1 >> level);
        (0..cubes).map(|y| (tile + UVec3::Y * y, BlockBuilder::build_block(self, UVec3::Y * y, level))).collect()
    }
}

/// How a column meets the heights `lo..hi`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cover {
    Empty,
    Full,
    Part,
}

fn cover(runs: &[std::ops::Range<u32>], lo: u32, hi: u32) -> Cover {
    // The first run that ends above lo.
    let i = runs.partition_point(|r| r.end <= lo);
    match runs.get(i) {
        Some(r) if r.start <= lo && r.end >= hi => Cover::Full,
        Some(r) if r.start < hi => Cover::Part,
        _ => Cover::Empty,
    }
}

impl VoxelSource for Columns {
    fn at(&self, p: IVec3) -> u8 {
        let Some(runs) = self.column(p.x, p.z) else { return 0 };
        let y = p.y as u32;
        if p.y >= 0 && cover(runs, y, y + 1) == Cover::Full { self.color } else { 0 }
    }

    /// Uniform when every column of the cube is wholly inside or wholly
    /// outside it: a look at each column's runs, no voxel visited.
    fn uniform(&self, min: IVec3, size: i32) -> Option<u8> {
        let (lo, hi) = (min.y.max(0) as u32, (min.y + size).max(0) as u32);
        let mut seen: Option<Cover> = None;
        for z in min.z..min.z + size {
            for x in min.x..min.x + size {
                let here = self.column(x, z).map_or(Cover::Empty, |runs| cover(runs, lo, hi));
                if here == Cover::Part || seen.is_some_and(|s| s != here) {
                    return None;
                }
                seen = Some(here);
            }
        }
        Some(if seen == Some(Cover::Full) { self.color } else { 0 })
    }
}

fn cross(u: Vec2, v: Vec2) -> f32 {
    u.x * v.y - u.y * v.x
}
