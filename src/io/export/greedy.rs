//! Greedy meshing: the visible faces of a voxel scene as few triangles.
//!
//! For each axis and direction, each layer of faces (a solid voxel whose
//! neighbour across the face is empty) is merged into rectangles of one
//! colour, row by row: a solid box becomes six rectangles, twelve triangles.
//! Merged rectangles meet smaller ones in T-junctions, which would leave
//! cracks; every rectangle edge is therefore split at the corners of the
//! rectangles that touch it, and a rectangle with such split points becomes
//! a fan around its centre. The result is watertight: every directed edge
//! has its reverse, and the triangles wind counter-clockwise seen from
//! outside (their signed volume is the voxel count).
//!
//! The cost follows the surface, not the volume: the faces are read from the
//! octree's maximal uniform cells (a solid cell of side `s` has six `s × s`
//! faces, each hidden or shown by the few cells across it), and a layer of
//! faces is held as runs along its rows, so a solid 1024³ box is one cell,
//! six neighbour look-ups and 6 × 1024 runs, where a dense copy of its
//! bounding box was a gigabyte.

use std::collections::{BTreeMap, HashMap, HashSet};

use glam::IVec3;

use crate::budget::OverBudget;
use crate::scene::Octree;

/// Bytes of memory counted per run of visible faces along a row (a face of
/// side `s` adds `s` runs before runs of one colour join): the run (16),
/// its place in the sorted rows (12), and at most one rectangle with its
/// triangles and vertices (the rest) when no two runs merge.
pub const RUN_BYTES: u64 = 64;

/// Triangles with one palette index each, over shared vertices. Positions
/// are in half voxels (a fan's centre can lie on a half), world axes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VoxelMesh {
    pub positions_x2: Vec<IVec3>,
    /// (vertex indices counter-clockwise from outside, palette index).
    pub triangles: Vec<([u32; 3], u8)>,
    /// Faces before merging: two triangles each in a one-quad-per-face export.
    pub exposed_faces: u64,
    /// Octree cells the mesher read: the maximal solid cells and the cells
    /// looked up across their faces. It follows the surface: a solid box
    /// aligned to the tree is one cell and six look-ups, whatever its size.
    pub cells_visited: u64,
    /// Runs of visible faces along rows, before runs of one colour join
    /// (what [`RUN_BYTES`] counts against the memory budget).
    pub face_runs: u64,
}

impl VoxelMesh {
    /// A vertex position in voxels.
    pub fn position(&self, index: u32) -> [f32; 3] {
        (self.positions_x2[index as usize].as_vec3() * 0.5).to_array()
    }
}

/// One merged rectangle: its four corners counter-clockwise from outside.
struct Quad {
    corners: [IVec3; 4],
    color: u8,
}

/// Visible faces of one colour, side by side along a row: `start..end`
/// along the layer's `u` axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Run {
    start: i32,
    end: i32,
    color: u8,
}

/// The layers of visible faces by (axis, 0 for +axis and 1 for −axis, the
/// plane's coordinate along the axis), in the order the dense mesher made
/// its rectangles; each holds its runs as (row along `v`, run).
type Layers = BTreeMap<(usize, u8, i32), Vec<(i32, Run)>>;

/// The two axes of a layer facing along `axis`: `(u, v, axis)` is cyclic
/// and right-handed, `u × v = +axis`.
fn layer_axes(axis: usize) -> (usize, usize) {
    ((axis + 1) % 3, (axis + 2) % 3)
}

/// The greedy mesh of `tree`'s solid voxels.
pub fn mesh(tree: &Octree) -> VoxelMesh {
    mesh_within(tree, u64::MAX).unwrap_or_default()
}

/// [`mesh`], refused once its faces pass the memory budget
/// ([`RUN_BYTES`] per run of visible faces, counted as they are read).
///
/// # Errors
/// [`OverBudget`] with the estimate at that point; nothing more is read.
pub fn mesh_within_budget(tree: &Octree) -> Result<VoxelMesh, OverBudget> {
    mesh_within(tree, crate::budget::budget_bytes())
}

fn mesh_within(tree: &Octree, budget_bytes: u64) -> Result<VoxelMesh, OverBudget> {
    let mut mesh = VoxelMesh::default();
    let layers = visible_faces(tree, budget_bytes, &mut mesh)?;
    let mut quads = Vec::new();
    for ((axis, direction, plane), runs) in layers {
        let positive = direction == 0;
        let (u, v) = layer_axes(axis);
        for (row, run, height) in rectangles(runs) {
            let corner = |a: i32, b: i32| {
                let mut p = IVec3::ZERO;
                p[axis] = plane;
                p[u] = run.start + a;
                p[v] = row + b;
                p
            };
            let width = run.end - run.start;
            let ccw = [corner(0, 0), corner(width, 0), corner(width, height), corner(0, height)];
            let corners = if positive { ccw } else { [ccw[0], ccw[3], ccw[2], ccw[1]] };
            quads.push(Quad { corners, color: run.color });
        }
    }
    let triangulated = triangulate(&quads);
    mesh.positions_x2 = triangulated.positions_x2;
    mesh.triangles = triangulated.triangles;
    Ok(mesh)
}

/// The visible faces of every maximal solid cell, as runs per layer and
/// row; counts the faces, the cells read and the runs in `mesh`.
fn visible_faces(tree: &Octree, budget_bytes: u64, mesh: &mut VoxelMesh) -> Result<Layers, OverBudget> {
    let mut layers = Layers::new();
    let mut over = None;
    tree.for_each_solid_cell(|min, side, color| {
        if over.is_some() {
            return;
        }
        mesh.cells_visited += 1;
        for axis in 0..3 {
            let (u, v) = layer_axes(axis);
            for positive in [true, false] {
                // The layer of voxels across the face, and the face's plane.
                let (across, plane) =
                    if positive { (min[axis] + side, min[axis] + side) } else { (min[axis] - 1, min[axis]) };
                let runs = layers.entry((axis, u8::from(!positive), plane)).or_default();
                let square = Square { axis, across, u0: min[u], v0: min[v], side };
                shown_parts(tree, square, &mut mesh.cells_visited, &mut |u0, v0, part| {
                    mesh.exposed_faces += (part as u64).pow(2);
                    mesh.face_runs += part as u64;
                    runs.extend((v0..v0 + part).map(|row| (row, Run { start: u0, end: u0 + part, color })));
                });
            }
        }
        let needed = mesh.face_runs.saturating_mul(RUN_BYTES);
        if needed > budget_bytes {
            over = Some(OverBudget {
                what: format!("meshing {} or more runs of visible faces", mesh.face_runs),
                needed,
                budget: budget_bytes,
            });
        }
    });
    over.map_or(Ok(layers), Err)
}

/// A square of faces of one cell, aligned to its side: its corner
/// (`u0`, `v0`) and `side` in the layer facing along `axis`, and the
/// coordinate of the voxels across it.
#[derive(Clone, Copy)]
struct Square {
    axis: usize,
    across: i32,
    u0: i32,
    v0: i32,
    side: i32,
}

/// Calls `show(u0, v0, side)` for the aligned parts of `square` whose
/// neighbours across are empty: a uniform cell across that covers the
/// square decides it whole, else its four quarters are looked at. Octree
/// cells are aligned to their size, so the cell holding a part's corner
/// covers the part when it is at least as large.
fn shown_parts(tree: &Octree, square: Square, visited: &mut u64, show: &mut impl FnMut(i32, i32, i32)) {
    let (u, v) = layer_axes(square.axis);
    let mut p = IVec3::ZERO;
    p[square.axis] = square.across;
    p[u] = square.u0;
    p[v] = square.v0;
    *visited += 1;
    match tree.uniform_cell(p) {
        // Outside the root: the square lies past the root's face, all empty.
        None => show(square.u0, square.v0, square.side),
        Some((_, level, value)) if 1i64 << level >= i64::from(square.side) => {
            if value == 0 {
                show(square.u0, square.v0, square.side);
            }
        }
        Some(_) => {
            // A cell smaller than the square: the square's side is ≥ 2.
            let half = square.side / 2;
            for (du, dv) in [(0, 0), (half, 0), (0, half), (half, half)] {
                let part = Square { u0: square.u0 + du, v0: square.v0 + dv, side: half, ..square };
                shown_parts(tree, part, visited, show);
            }
        }
    }
}

/// The rectangles of one layer's runs as (row, run, height), in the order
/// and shape a row-major scan of a dense mask gives them: each as wide as
/// its first row's run, then as tall as the rows below hold the same run
/// (which it then takes out of them).
fn rectangles(mut runs: Vec<(i32, Run)>) -> Vec<(i32, Run, i32)> {
    runs.sort_unstable_by_key(|(row, run)| (*row, run.start));
    // Rows of maximal runs: touching runs of one colour join.
    let mut rows: Vec<(i32, Vec<Run>)> = Vec::new();
    for (row, run) in runs {
        match rows.last_mut() {
            Some((last_row, list)) if *last_row == row => match list.last_mut() {
                Some(last) if last.end == run.start && last.color == run.color => last.end = run.end,
                _ => list.push(run),
            },
            _ => rows.push((row, vec![run])),
        }
    }
    let mut out = Vec::new();
    for k in 0..rows.len() {
        let (row, list) = (rows[k].0, std::mem::take(&mut rows[k].1));
        for run in list {
            let mut height = 1;
            while let Some((below_row, below)) = rows.get_mut(k + height as usize)
                && *below_row == row + height
            {
                // The run of the row below that holds `run.start`: runs are
                // maximal, so it holds all of `run` only if it is as wide.
                let at = below.partition_point(|r| r.end <= run.start);
                let Some(&under) = below.get(at) else { break };
                if under.start > run.start || under.end < run.end || under.color != run.color {
                    break;
                }
                let left = Run { end: run.start, ..under };
                let right = Run { start: run.end, ..under };
                below.splice(at..=at, [left, right].into_iter().filter(|r| r.start < r.end));
                height += 1;
            }
            out.push((row, run, height));
        }
    }
    out
}

/// Triangles of the rectangles, with every edge split at the corners of
/// the rectangles that touch it (no T-junctions, so no cracks).
fn triangulate(quads: &[Quad]) -> VoxelMesh {
    let corners: HashSet<IVec3> = quads.iter().flat_map(|q| q.corners).collect();
    let mut mesh = VoxelMesh::default();
    let mut index: HashMap<IVec3, u32> = HashMap::new();
    let mut vertex = |p_x2: IVec3, mesh: &mut VoxelMesh| {
        *index.entry(p_x2).or_insert_with(|| {
            mesh.positions_x2.push(p_x2);
            u32::try_from(mesh.positions_x2.len() - 1).unwrap_or(u32::MAX)
        })
    };
    for quad in quads {
        let mut outline = Vec::with_capacity(4);
        for k in 0..4 {
            let (a, b) = (quad.corners[k], quad.corners[(k + 1) % 4]);
            outline.push(a);
            let along = (b - a).signum();
            let length = (b - a).abs().max_element();
            outline.extend((1..length).map(|t| a + along * t).filter(|p| corners.contains(p)));
        }
        let ids: Vec<u32> = outline.iter().map(|p| vertex(*p * 2, &mut mesh)).collect();
        if ids.len() == 4 {
            mesh.triangles.push(([ids[0], ids[1], ids[2]], quad.color));
            mesh.triangles.push(([ids[0], ids[2], ids[3]], quad.color));
        } else {
            // The centre lies strictly inside, so no fan triangle is flat.
            let center = vertex(quad.corners[0] + quad.corners[2], &mut mesh);
            for k in 0..ids.len() {
                mesh.triangles.push(([center, ids[k], ids[(k + 1) % ids.len()]], quad.color));
            }
        }
    }
    mesh
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::scene::{Op, Shape};

    /// The mesher before it followed the surface: a dense copy of the
    /// bounding box, each layer's faces as a mask. The reference that the
    /// sparse mesher must match rectangle for rectangle.
    mod dense {
        use super::super::{Quad, VoxelMesh, triangulate};
        use crate::scene::Octree;
        use glam::{IVec3, UVec3};

        pub fn mesh(tree: &Octree) -> VoxelMesh {
            let Some(dense) = Dense::of(tree) else { return VoxelMesh::default() };
            let mut quads = Vec::new();
            let mut exposed_faces = 0;
            for axis in 0..3 {
                for positive in [true, false] {
                    exposed_faces += merge_faces(&dense, axis, positive, &mut quads);
                }
            }
            let mut mesh = triangulate(&quads);
            mesh.exposed_faces = exposed_faces;
            mesh
        }

        /// The voxels of the scene's bounding box, dense.
        struct Dense {
            lo: IVec3,
            dims: UVec3,
            data: Vec<u8>,
        }

        impl Dense {
            fn of(tree: &Octree) -> Option<Dense> {
                let (lo, hi) = tree.solid_bounds()?;
                let dims = (hi - lo + IVec3::ONE).as_uvec3();
                let mut dense = Dense { lo, dims, data: vec![0; dims.as_u64vec3().element_product() as usize] };
                tree.for_each_solid_cell(|min, size, value| {
                    for z in 0..size {
                        for y in 0..size {
                            for x in 0..size {
                                let i = dense.index(min + IVec3::new(x, y, z) - lo);
                                dense.data[i] = value;
                            }
                        }
                    }
                });
                Some(dense)
            }

            fn index(&self, p: IVec3) -> usize {
                p.x as usize + self.dims.x as usize * (p.y as usize + self.dims.y as usize * p.z as usize)
            }

            /// Value at `p` (box-local); 0 outside.
            fn at(&self, p: IVec3) -> u8 {
                if p.cmplt(IVec3::ZERO).any() || p.cmpge(self.dims.as_ivec3()).any() {
                    return 0;
                }
                self.data[self.index(p)]
            }
        }

        /// Merges the faces that look along `±axis` into rectangles; returns how
        /// many faces there were.
        fn merge_faces(dense: &Dense, axis: usize, positive: bool, quads: &mut Vec<Quad>) -> u64 {
            // (u, v, axis) is a cyclic, right-handed order: u × v = +axis.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let dims = dense.dims.as_ivec3();
            let (nu, nv) = (dims[u] as usize, dims[v] as usize);
            let mut step = IVec3::ZERO;
            step[axis] = if positive { 1 } else { -1 };
            let mut faces = 0;
            let mut mask = vec![0u8; nu * nv];
            for layer in 0..dims[axis] {
                for j in 0..nv {
                    for i in 0..nu {
                        let mut p = IVec3::ZERO;
                        (p[axis], p[u], p[v]) = (layer, i as i32, j as i32);
                        let value = dense.at(p);
                        let visible = value != 0 && dense.at(p + step) == 0;
                        mask[i + nu * j] = if visible { value } else { 0 };
                        faces += u64::from(visible);
                    }
                }
                let plane = layer + i32::from(positive);
                for (i, j, w, h, color) in rectangles(&mut mask, nu, nv) {
                    let corner = |a: usize, b: usize| {
                        let mut p = dense.lo;
                        p[axis] += plane;
                        p[u] += (i + a) as i32;
                        p[v] += (j + b) as i32;
                        p
                    };
                    let ccw = [corner(0, 0), corner(w, 0), corner(w, h), corner(0, h)];
                    let corners = if positive { ccw } else { [ccw[0], ccw[3], ccw[2], ccw[1]] };
                    quads.push(Quad { corners, color });
                }
            }
            faces
        }

        /// Takes rectangles of one value out of `mask` (row-major, `nu` wide): each
        /// as wide as its first row's run, then as tall as the rows below match.
        fn rectangles(mask: &mut [u8], nu: usize, nv: usize) -> Vec<(usize, usize, usize, usize, u8)> {
            let mut out = Vec::new();
            for j in 0..nv {
                let mut i = 0;
                while i < nu {
                    let color = mask[i + nu * j];
                    if color == 0 {
                        i += 1;
                        continue;
                    }
                    let w = (i..nu).take_while(|&x| mask[x + nu * j] == color).count();
                    let h = (j..nv).take_while(|&y| (i..i + w).all(|x| mask[x + nu * y] == color)).count();
                    for y in j..j + h {
                        mask[i + nu * y..i + w + nu * y].fill(0);
                    }
                    out.push((i, j, w, h, color));
                    i += w;
                }
            }
            out
        }
    }

    fn boxed(min: IVec3, max: IVec3) -> Octree {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min, max }, Op::Place(5)).unwrap();
        tree
    }

    #[test]
    fn a_box_is_twelve_triangles() {
        let mesh = mesh(&boxed(IVec3::new(-2, 0, 1), IVec3::new(4, 3, 9)));
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.positions_x2.len(), 8);
        assert_eq!(mesh.exposed_faces, 2 * (7 * 4 + 4 * 9 + 9 * 7));
    }

    /// The same rectangles, vertices and triangles, in the same order, as
    /// the dense mesher on scenes with holes, colours, T-junctions and
    /// cells of every size.
    #[test]
    fn the_sparse_mesher_matches_the_dense_one() {
        let mut scenes = vec![
            crate::scene::demo::BuiltIn::Showroom.scene().drawn().clone(),
            boxed(IVec3::new(-2, 0, 1), IVec3::new(4, 3, 9)),
            boxed(IVec3::new(0, 0, 0), IVec3::new(31, 31, 31)),
        ];
        let mut carved = boxed(IVec3::new(-9, -3, -5), IVec3::new(20, 17, 12));
        for (i, (center, radius)) in
            [(IVec3::new(3, 9, 4), 6), (IVec3::new(-9, 0, 0), 4), (IVec3::new(15, 15, 9), 5)].into_iter().enumerate()
        {
            let op = if i == 1 { Op::Place(9) } else { Op::Remove };
            carved.apply_brush(&Shape::Sphere { center, radius }, op).unwrap();
        }
        carved.apply_brush(&Shape::Box { min: IVec3::new(0, 0, 0), max: IVec3::new(7, 2, 3) }, Op::Place(77)).unwrap();
        scenes.push(carved);
        for (k, tree) in scenes.iter().enumerate() {
            let (sparse, reference) = (mesh(tree), dense::mesh(tree));
            assert_eq!(sparse.exposed_faces, reference.exposed_faces, "scene {k}");
            assert_eq!(sparse.positions_x2, reference.positions_x2, "scene {k}");
            assert_eq!(sparse.triangles, reference.triangles, "scene {k}");
        }
    }

    /// Issue 24, item 14: the cells read follow the surface. A box aligned
    /// to the tree is one cell whatever its size; a box off the grid has
    /// faces of small cells, and its count grows with its area (×4 per
    /// doubling), not its volume (×8). Before, the mesher filled a dense
    /// copy of the whole bounding box (a 1024³ box: a gigabyte).
    #[test]
    fn the_cells_read_follow_the_surface() {
        let aligned = mesh(&boxed(IVec3::ZERO, IVec3::splat(1023)));
        assert_eq!((aligned.triangles.len(), aligned.positions_x2.len()), (12, 8));
        assert_eq!(aligned.exposed_faces, 6 * 1024 * 1024);
        assert_eq!(aligned.cells_visited, 1 + 6, "one cell and a look-up across each face");
        assert_eq!(aligned.face_runs, 6 * 1024, "one run per row of each face");
        let visits = |side: i32| {
            let mesh = mesh(&boxed(IVec3::ONE, IVec3::splat(side)));
            assert_eq!(mesh.triangles.len(), 12);
            mesh.cells_visited
        };
        let (small, large) = (visits(40), visits(80));
        let area = 6 * 80 * 80;
        assert!(large <= 12 * area, "{large} cells read for a surface of {area} faces");
        assert!(large * 10 <= small * 45, "×{:.2} cells read for twice the side", large as f64 / small as f64);
    }

    /// The numbers of docs/bench/export.md, the dense mesher on a solid
    /// 1024³ box (`OCTOVOX_MESH_BENCH=dense`, else the sparse one); run
    /// under `/usr/bin/time -v` in a release build.
    #[test]
    #[ignore = "a measurement: cargo test --release --lib -- --ignored mesh_a_solid_1024_box"]
    fn mesh_a_solid_1024_box() {
        let tree = boxed(IVec3::ZERO, IVec3::splat(1023));
        let started = web_time::Instant::now();
        let dense = std::env::var("OCTOVOX_MESH_BENCH").is_ok_and(|v| v == "dense");
        let mesh = if dense { dense::mesh(&tree) } else { mesh(&tree) };
        println!(
            "{} triangles in {:?} ({})",
            mesh.triangles.len(),
            started.elapsed(),
            if dense { "dense" } else { "sparse" }
        );
        assert_eq!(mesh.triangles.len(), 12);
    }

    #[test]
    fn a_mesh_past_the_budget_is_refused_while_its_faces_are_read() {
        let tree = boxed(IVec3::ZERO, IVec3::splat(1023));
        let over = mesh_within(&tree, 1000).unwrap_err();
        assert!(over.what.contains("runs of visible faces"), "{over}");
        assert!(mesh_within(&tree, 6 * 1024 * RUN_BYTES).is_ok());
    }
}
