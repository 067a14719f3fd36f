//! The stack-based SVO traversal on the CPU. `shaders/trace_svo.wgsl` is a
//! line-for-line twin: change both together.
//!
//! Per ray: descend into the child containing the current point, step to the
//! next sibling across the nearest exit plane (by t, never by nudging the
//! position), pop when the step leaves the node. The stack holds the octant
//! taken at every level (see `OctantPath`).

use glam::{IVec3, Vec3};

use super::{Hit, MAX_ITERATIONS, NO_AXIS, Ray, argmin};
use crate::camera::Camera;
use crate::gpu_pool::{is_pointer, slot_of};
use crate::scene::octree::{MAX_DEPTH, Octree, octant_offset};

// The octant path holds 20 levels of 3 bits in two words.
const _: () = assert!(MAX_DEPTH <= 20);

/// The voxel and face under pixel (x, y) of a `size` view, with the voxel in
/// world coordinates: the one CPU pick that the window's mouse and replay's
/// `click` share.
pub fn pick(tree: &Octree, camera: &Camera, size: (u32, u32), x: u32, y: u32) -> Option<Hit> {
    let basis = camera.basis(size.0, size.1, tree.origin());
    let (origin, dir) = basis.ray(x, y);
    let hit = trace(tree, &Ray::new(origin, dir));
    hit.is_hit().then(|| Hit { voxel: hit.voxel + tree.origin(), ..hit })
}

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
    // The stack: the octant taken at every level, 3 bits a level, in two
    // words (registers on a GPU, unlike an array). The node words above the
    // current one are not kept: after a pop they are fetched again from the
    // root along the octant path, which is cheaper on GPUs (and far cheaper on
    // CPU-emulated ones) than a per-thread array.
    let mut path = OctantPath::default();
    let mut level = depth;
    let mut node = root;
    let mut node_min = IVec3::ZERO;
    let mut octant = first_octant(ray, node_min, level, t, axis);
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let half = 1 << (level - 1);
        let child_min = node_min + octant_offset(octant) * half;
        let word = child_word(tree, node, level, octant);
        if is_pointer(word) {
            path.set(level, octant);
            level -= 1;
            node = word;
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
        let start_level = level;
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
            octant = path.get(level);
            node_min -= octant_offset(octant) * (1 << (level - 1));
        }
        if level != start_level {
            node = refetch(tree, root, depth, level, &path);
        }
    }
    Hit { iterations, ..Hit::default() }
}

/// Octants taken at levels 1..=20, 3 bits each (`octant_path_*` in WGSL).
#[derive(Default, Clone, Copy)]
struct OctantPath {
    low: u32,
    high: u32,
}

impl OctantPath {
    fn get(&self, level: u32) -> usize {
        let i = level - 1;
        (if i < 10 { self.low >> (3 * i) } else { self.high >> (3 * (i - 10)) } & 7) as usize
    }

    fn set(&mut self, level: u32, octant: usize) {
        let i = level - 1;
        let (word, shift) = if i < 10 { (&mut self.low, 3 * i) } else { (&mut self.high, 3 * (i - 10)) };
        *word = (*word & !(7 << shift)) | (octant as u32) << shift;
    }
}

/// The node word at `level` on the current path, fetched from the root.
fn refetch(tree: &Octree, root: u32, depth: u32, level: u32, path: &OctantPath) -> u32 {
    let mut word = root;
    let mut l = depth;
    while l > level {
        word = child_word(tree, word, l, path.get(l));
        l -= 1;
    }
    word
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
