//! The stack-based SVO traversal on the CPU. `shaders/trace_svo.wgsl` is a
//! line-for-line twin: change both together.
//!
//! Per ray: descend into the child containing the current point, step to the
//! next sibling across the nearest exit plane (by t, never by nudging the
//! position), pop when the step leaves the node. The stack holds the node
//! word and the octant taken at every level.

use glam::{IVec3, Vec3};

use super::{Hit, MAX_ITERATIONS, NO_AXIS, Ray, argmin};
use crate::gpu_pool::{is_pointer, slot_of};
use crate::scene::octree::{MAX_DEPTH, Octree, octant_offset};

const STACK: usize = MAX_DEPTH as usize + 1;

/// The first solid voxel along `ray` (tree-local coordinates).
pub fn trace(tree: &Octree, ray: &Ray) -> Hit {
    let depth = tree.depth();
    let size = (1u32 << depth) as f32;
    let (t_enter, t_exit, entry_axis) = ray.slab(Vec3::ZERO, Vec3::splat(size));
    if t_enter > t_exit || t_exit < 0.0 {
        return Hit::default();
    }
    let mut t = t_enter.max(0.0);
    // NO_AXIS: the ray starts inside the root, so no face was entered yet.
    let mut axis = if t_enter >= 0.0 { entry_axis } else { NO_AXIS };
    let root = tree.root_word();
    if !is_pointer(root) {
        return hit_cell(ray, root as u8, IVec3::ZERO, depth, t, axis, 1);
    }
    let mut words = [0u32; STACK];
    let mut octants = [0usize; STACK];
    let mut level = depth;
    let mut node_min = IVec3::ZERO;
    words[level as usize] = root;
    let mut octant = first_octant(ray, node_min, level, t, axis);
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let half = 1 << (level - 1);
        let child_min = node_min + octant_offset(octant) * half;
        let word = child_word(tree, words[level as usize], level, octant);
        if is_pointer(word) {
            octants[level as usize] = octant;
            level -= 1;
            words[level as usize] = word;
            node_min = child_min;
            octant = first_octant(ray, node_min, level, t, axis);
            continue;
        }
        if word != 0 {
            return hit_cell(ray, word as u8, child_min, level - 1, t, axis, iterations);
        }
        // Empty child: leave it through its nearest exit plane.
        let far = child_min.as_vec3() + Vec3::select(ray.dir.cmpgt(Vec3::ZERO), Vec3::splat(half as f32), Vec3::ZERO);
        let exits = (far - ray.origin) * ray.inv;
        let a = argmin(exits);
        t = exits[a];
        axis = a;
        let bit = 1 << a;
        loop {
            let leaving = if ray.dir[a] > 0.0 { octant & bit != 0 } else { octant & bit == 0 };
            if !leaving {
                octant ^= bit;
                break;
            }
            if level == depth {
                return Hit { iterations, ..Hit::default() };
            }
            level += 1;
            octant = octants[level as usize];
            node_min -= octant_offset(octant) * (1 << (level - 1));
        }
    }
    Hit { iterations, ..Hit::default() }
}

/// Child word of a node (level ≥ 2) or voxel value of a brick (level 1).
fn child_word(tree: &Octree, word: u32, level: u32, octant: usize) -> u32 {
    if level == 1 {
        u32::from(tree.pool().bricks.get(slot_of(word))[octant])
    } else {
        tree.pool().nodes.get(slot_of(word))[octant]
    }
}

/// Octant of the node (`min`, level) holding the ray point at `t`: per axis,
/// whether the ray has crossed the mid-plane (by [`Ray::crossed`]).
fn first_octant(ray: &Ray, min: IVec3, level: u32, t: f32, entry_axis: usize) -> usize {
    let mid = (min + IVec3::splat(1 << (level - 1))).as_vec3();
    let mut octant = 0;
    for a in 0..3 {
        let crossed = ray.crossed(a, mid[a], t, entry_axis);
        let upper = if ray.dir[a] > 0.0 { crossed } else { !crossed };
        octant |= usize::from(upper) << a;
    }
    octant
}

/// The hit inside a uniform cell: the voxel of the cell where the ray is at
/// `t`, on the entered face.
fn hit_cell(ray: &Ray, value: u8, min: IVec3, level: u32, t: f32, axis: usize, iterations: u32) -> Hit {
    if value == 0 {
        return Hit { iterations, ..Hit::default() };
    }
    let max = min + IVec3::splat((1 << level) - 1);
    let mut voxel = IVec3::ZERO;
    for b in 0..3 {
        voxel[b] = if b == axis {
            if ray.dir[b] > 0.0 { min[b] } else { max[b] }
        } else {
            ray.voxel_on_axis(b, t, axis).clamp(min[b], max[b])
        };
    }
    let normal = if axis == NO_AXIS { IVec3::ZERO } else { ray.entry_normal(axis) };
    Hit { value, voxel, normal, cell_level: level, iterations }
}
