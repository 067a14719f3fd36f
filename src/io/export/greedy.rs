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

use std::collections::{HashMap, HashSet};

use glam::{IVec3, UVec3};

use crate::scene::Octree;

/// Triangles with one palette index each, over shared vertices. Positions
/// are in half voxels (a fan's centre can lie on a half), world axes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VoxelMesh {
    pub positions_x2: Vec<IVec3>,
    /// (vertex indices counter-clockwise from outside, palette index).
    pub triangles: Vec<([u32; 3], u8)>,
    /// Faces before merging: two triangles each in a one-quad-per-face export.
    pub exposed_faces: u64,
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

/// Bytes [`mesh`] needs for the dense copy of `tree` (for the memory budget).
pub fn dense_bytes(tree: &Octree) -> u64 {
    tree.solid_bounds().map_or(0, |(lo, hi)| (hi - lo + IVec3::ONE).as_u64vec3().element_product())
}

/// The greedy mesh of `tree`'s solid voxels.
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
mod tests {
    use super::*;
    use crate::scene::{Op, Shape};

    #[test]
    fn a_box_is_twelve_triangles() {
        let mut tree = Octree::default();
        tree.apply_brush(&Shape::Box { min: IVec3::new(-2, 0, 1), max: IVec3::new(4, 3, 9) }, Op::Place(5)).ok();
        let mesh = mesh(&tree);
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.positions_x2.len(), 8);
        assert_eq!(mesh.exposed_faces, 2 * (7 * 4 + 4 * 9 + 9 * 7));
    }
}
