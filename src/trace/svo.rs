//! The stack-based SVO traversal on the CPU, the reference for
//! `shaders/trace_svo.wgsl`: the same steps and the same plane-crossing rule,
//! so change both together.
//!
//! Per ray: descend into the child holding the current point, step to the
//! next cell across the nearest exit plane (by t, never by nudging the
//! position), and pop to the smallest node holding both cells. The cell's
//! integer coordinates carry the octant taken at every level, so the pop
//! target is the highest coordinate bit the step changes. The GPU keeps
//! three ancestors in registers and restarts from the root past them, and
//! starts each ray at its tile's beam distance; here a plain array of node
//! words serves, and rays start at the eye.

use glam::{IVec3, Vec3};

use super::{Footprint, Hit, NO_AXIS, Ray, argmin, iteration_bound};
use crate::gpu_pool::{is_pointer, slot_of};
use crate::scene::octree::{MAX_DEPTH, Octree};

// The GPU beam's octant path holds 20 levels of 3 bits in two words.
const _: () = assert!(MAX_DEPTH <= 20);

/// The first solid voxel along `ray` (tree-local coordinates).
pub fn trace(tree: &Octree, ray: &Ray) -> Hit {
    walk(tree, ray, 0, Footprint::EXACT).hit
}

/// Where a ray leaves its medium: the first voxel whose value differs from
/// the medium's, and the ray's t on entering it. Inside glass the medium is
/// the glass's palette index, and the voxel found may be empty (value 0).
#[derive(Clone, Copy, Debug, Default)]
pub struct Crossing {
    pub hit: Hit,
    pub t: f32,
    /// Whether such a voxel lies inside the tree (a miss otherwise).
    pub found: bool,
    /// The instance it is in, in a scene of objects (`crate::trace::instanced`).
    pub instance: Option<u32>,
}

/// The first voxel along `ray` whose value is not `medium` (0 for rays in
/// empty space): the traversal of [`trace`] with "solid" read as "not the
/// medium".
pub fn trace_through(tree: &Octree, ray: &Ray, medium: u8) -> Crossing {
    walk(tree, ray, medium, Footprint::EXACT)
}

/// [`trace_through`] under `footprint`, where a ray inside glass (`medium`
/// not 0) that finds no other voxel leaves the glass at the root's face.
pub fn cross(tree: &Octree, ray: &Ray, medium: u8, footprint: Footprint) -> Crossing {
    let c = walk(tree, ray, medium, footprint);
    if c.found || c.hit.gave_up || medium == 0 {
        return c;
    }
    root_exit(ray, tree.size() as f32, c.hit.iterations)
}

/// Where a ray inside glass leaves the root cube: the empty cell beyond the
/// face it crosses (twin of `root_exit` in `shaders/instances.wgsl`).
fn root_exit(ray: &Ray, size: f32, iterations: u32) -> Crossing {
    let far = (Vec3::select(ray.dir.cmpgt(Vec3::ZERO), Vec3::splat(size), Vec3::ZERO) - ray.origin) * ray.inv;
    let axis = argmin(far);
    let t = far[axis].max(0.0);
    let p = ray.origin + ray.dir * t;
    let mut voxel = p.floor().as_ivec3();
    let mut normal = IVec3::ZERO;
    normal[axis] = if ray.dir[axis] > 0.0 { -1 } else { 1 };
    voxel[axis] = if ray.dir[axis] > 0.0 { size as i32 } else { -1 };
    Crossing { hit: Hit { voxel, normal, iterations, ..Hit::default() }, t, found: true, instance: None }
}

/// The traversal itself. Twin of `trace_svo` in `shaders/trace_svo.wgsl`.
fn walk(tree: &Octree, ray: &Ray, medium: u8, footprint: Footprint) -> Crossing {
    let depth = tree.depth();
    let size = (1u32 << depth) as f32;
    let (t_enter, t_exit, entry_axis) = ray.slab(Vec3::ZERO, Vec3::splat(size));
    // t_exit = 0: the ray starts on the root's face and heads out (a path
    // leaving a voxel on the root's face), so it meets nothing.
    if t_enter > t_exit || t_exit <= 0.0 {
        return Crossing::default();
    }
    let mut t = t_enter.max(0.0);
    // NO_AXIS: the ray starts inside the root, so no face was entered yet.
    let mut axis = if t_enter >= 0.0 { entry_axis } else { NO_AXIS };
    let root = tree.root_word();
    if !is_pointer(root) {
        if root == u32::from(medium) {
            return Crossing { hit: Hit { iterations: 1, ..Hit::default() }, ..Crossing::default() };
        }
        return hit_cell(ray, root as u8, IVec3::ZERO, depth, t, axis, 1);
    }
    // The stack: the node word at every level of the current path.
    let mut nodes = [0u32; MAX_DEPTH as usize + 1];
    let mut level = depth;
    nodes[level as usize] = root;
    // The child cell the ray is in: min corner, size 2^(level - 1).
    let mut cell = child_cell(ray, IVec3::ZERO, level, t, axis);
    let bound = iteration_bound(depth);
    let mut iterations = 0;
    while iterations < bound {
        iterations += 1;
        let word = child_word(tree, nodes[level as usize], level, octant_of(cell, level));
        if is_pointer(word) {
            // A node cell (bricks never stop) below the footprint.
            if level >= 3 && footprint.covers(1 << (level - 1), t) {
                let index = tree.summary(word, level - 1).index;
                return hit_cell(ray, index, cell, level - 1, t, axis, iterations);
            }
            level -= 1;
            nodes[level as usize] = word;
            cell = child_cell(ray, cell, level, t, axis);
            continue;
        }
        if word != u32::from(medium) {
            return hit_cell(ray, word as u8, cell, level - 1, t, axis, iterations);
        }
        // A cell of the medium: leave it through its nearest exit plane.
        let half = 1 << (level - 1);
        let positive = ray.dir.cmpgt(Vec3::ZERO);
        let far = cell + IVec3::select(positive, IVec3::splat(half), IVec3::ZERO);
        let exits = (far.as_vec3() - ray.origin) * ray.inv;
        let a = argmin(exits);
        t = exits[a];
        axis = a;
        let mut next = cell;
        next[a] += if positive.test(a) { half } else { -1 };
        // The highest changed coordinate bit is the octant bit of the
        // smallest node holding both cells.
        let new_level = u32::BITS - ((cell[a] ^ next[a]) as u32).leading_zeros();
        if new_level > depth {
            break;
        }
        level = new_level;
        cell = next & IVec3::splat(!((1 << (level - 1)) - 1));
    }
    Crossing { hit: Hit::miss(iterations, bound), ..Crossing::default() }
}

/// Octant of a cell of size 2^(level - 1) within its node: one coordinate
/// bit per axis.
fn octant_of(cell: IVec3, level: u32) -> usize {
    let b = (cell >> (level - 1) as i32) & IVec3::ONE;
    (b.x | (b.y << 1) | (b.z << 2)) as usize
}

/// Child word of a node (level ≥ 2) or voxel value of a brick (level 1).
fn child_word(tree: &Octree, word: u32, level: u32, octant: usize) -> u32 {
    if level == 1 {
        u32::from(tree.pool().bricks.get(slot_of(word))[octant])
    } else {
        tree.pool().nodes.get(slot_of(word)).children[octant]
    }
}

/// The child cell of node (`min`, level) that holds the ray point at `t`:
/// per axis, whether the ray has crossed the mid-plane (by [`Ray::crossed`]).
fn child_cell(ray: &Ray, min: IVec3, level: u32, t: f32, entry_axis: usize) -> IVec3 {
    let half = 1 << (level - 1);
    let mut cell = min;
    for a in 0..3 {
        let crossed = ray.crossed(a, (min[a] + half) as f32, t, entry_axis);
        if crossed == (ray.dir[a] > 0.0) {
            cell[a] += half;
        }
    }
    cell
}

/// The crossing into a uniform cell: the voxel of the cell where the ray is
/// at `t`, on the entered face.
fn hit_cell(ray: &Ray, value: u8, min: IVec3, level: u32, t: f32, axis: usize, iterations: u32) -> Crossing {
    let voxel = ray.voxel_in_box(min, min + IVec3::splat((1 << level) - 1), t, axis);
    let normal = if axis == NO_AXIS { IVec3::ZERO } else { ray.entry_normal(axis) };
    let hit = Hit { value, voxel, normal, cell_level: level, iterations, gave_up: false, turned: None };
    Crossing { hit, t, found: true, instance: None }
}
