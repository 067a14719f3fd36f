//! What the CPU tracers walk: the one model's octree, or a scene of
//! objects as instances (two-level tracing). The reference for
//! `shaders/instances.wgsl`: the same ray transforms, the same walk over the
//! tree of instance boxes and the same rule for ties, so change both
//! together.

use glam::{IVec3, Vec3};

use super::svo::{self, Crossing};
use super::{Footprint, Hit, Ray, TurnedFace, nearest_axis};
use crate::scene::Scene;
use crate::scene::instances::{BVH_STACK, Instance, InstanceTable, TIE_T, Turned};
use crate::scene::objects::Model;
use crate::scene::octree::Octree;

/// A scene as the tracers walk it.
pub enum Traced<'a> {
    Tree(&'a Octree),
    /// `bound`: where a give-up is reported, the GPU's `max_iterations`
    /// (that of the composed tree's depth).
    Objects {
        table: InstanceTable,
        models: &'a [Model],
        bound: u32,
    },
}

impl<'a> Traced<'a> {
    /// The scene's drawn octree, or its objects as instances in its local
    /// frame (cells from `scene.origin()`), as the GPU draws it
    /// ([`Scene::instanced`]).
    pub fn of(scene: &'a Scene) -> Traced<'a> {
        match scene.instanced() {
            None => Traced::Tree(scene.drawn()),
            Some(objects) => Traced::Objects {
                table: InstanceTable::build(objects, scene.origin()),
                models: &objects.models,
                bound: super::iteration_bound(scene.drawn().depth()),
            },
        }
    }

    /// The free turn of instance `instance` (none for [`NO_INSTANCE`], an
    /// instance placed by cells, or a scene of one model).
    pub fn turned(&self, instance: u32) -> Option<&Turned> {
        match self {
            Traced::Tree(_) => None,
            Traced::Objects { table, .. } => table.instances.get(instance as usize)?.turned.as_ref(),
        }
    }

    /// The first solid voxel along `ray` under `footprint`.
    pub fn trace(&self, ray: &Ray, footprint: Footprint) -> Hit {
        self.trace_through(ray, 0, None, footprint).hit
    }

    /// The first voxel along `ray` that is not `medium`, where `inside` is
    /// the instance whose glass the ray is in: every other object is
    /// crossed as empty space. A ray in glass that finds none leaves it at
    /// its tree's face. The tree of boxes is walked nearer child first, and
    /// a node entered past the nearest hit so far is skipped. Twin of
    /// `trace_scene` in `shaders/instances.wgsl`.
    pub fn trace_through(&self, ray: &Ray, medium: u8, inside: Option<u32>, footprint: Footprint) -> Crossing {
        let (table, models, bound) = match self {
            Traced::Tree(tree) => return svo::cross(tree, ray, medium, footprint),
            Traced::Objects { table, models, bound } => (table, models, *bound),
        };
        let mut best: Option<Crossing> = None;
        let (mut iterations, mut gave_up) = (0u32, false);
        // The farther children still to visit, with their entry t.
        let mut stack = [(0usize, 0f32); BVH_STACK];
        let mut top = 0;
        let mut next = entry_t(table, 0, ray, f32::MAX).map(|t| (0, t));
        while let Some((i, _)) = next {
            let node = table.nodes[i];
            if let Some(index) = node.leaf {
                let instance = &table.instances[index as usize];
                let tree = &models[instance.model].tree;
                let m = if inside == Some(index) { medium } else { 0 };
                let model_ray = model_ray(instance, ray);
                // A turned object's solid box, tighter than its scene box;
                // glass the ray is in is left at its tree's face: walked.
                let misses =
                    inside != Some(index) && instance.turned.is_some_and(|t| t.misses_solid(&model_ray, reach(best)));
                if !misses {
                    let c = svo::cross(tree, &model_ray, m, footprint);
                    iterations = iterations.saturating_add(c.hit.iterations);
                    gave_up |= c.hit.gave_up;
                    if c.found && wins(c.t, index, best) {
                        best = Some(scene_crossing(instance, index, c));
                    }
                }
            } else {
                // The right child is the node after the left one's subtree;
                // the nearer goes first, the left one at equal t, as on the GPU.
                let (left, right) = (i + 1, table.nodes[i + 1].skip as usize);
                let until = reach(best);
                let (t_left, t_right) = (entry_t(table, left, ray, until), entry_t(table, right, ray, until));
                let left_first = t_left.unwrap_or(f32::MAX) <= t_right.unwrap_or(f32::MAX);
                let (near, far) =
                    if left_first { ((left, t_left), (right, t_right)) } else { ((right, t_right), (left, t_left)) };
                // A farther child that is entered means a nearer one is too.
                if let Some(t_far) = far.1 {
                    stack[top] = (far.0, t_far);
                    top += 1;
                }
                if let Some(t_near) = near.1 {
                    next = Some((near.0, t_near));
                    continue;
                }
            }
            next = None;
            while top > 0 {
                top -= 1;
                if stack[top].1 <= reach(best) {
                    next = Some(stack[top]);
                    break;
                }
            }
        }
        if gave_up {
            return Crossing { hit: Hit::miss(bound, bound), ..Crossing::default() };
        }
        let mut out = best.unwrap_or_default();
        out.hit.iterations = iterations.min(bound - 1);
        out
    }
}

/// Within [`TIE_T`] of each other two hits are at one distance.
fn tie_limit(t: f32) -> f32 {
    t + TIE_T * t.max(1.0)
}

/// Whether a hit at `t` in instance `index` wins over `best`: it is nearer,
/// or at its distance and of a later object (as composing gives).
fn wins(t: f32, index: u32, best: Option<Crossing>) -> bool {
    best.is_none_or(|b| {
        let later = b.instance.is_none_or(|i| index > i);
        t < b.t - TIE_T * b.t.max(1.0) || (t <= tie_limit(b.t) && later)
    })
}

/// Farthest t a node may be entered at and still hold a winning hit.
fn reach(best: Option<Crossing>) -> f32 {
    best.map_or(f32::MAX, |b| tie_limit(b.t))
}

/// The t the ray enters node `i`'s box at, unless it misses the box,
/// nothing is drawn below it, or it lies past `until`.
fn entry_t(table: &InstanceTable, i: usize, ray: &Ray, until: f32) -> Option<f32> {
    let (lo, hi) = table.nodes[i].bounds?;
    let (t_enter, t_exit, _) = ray.slab(lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
    (t_enter <= t_exit && t_exit > 0.0 && t_enter <= until).then_some(t_enter)
}

/// The ray in the model's tree-local frame: the same t reaches the same point.
fn model_ray(instance: &Instance, ray: &Ray) -> Ray {
    if let Some(turned) = &instance.turned {
        return Ray::new(turned.model_point(ray.origin), turned.model_dir(ray.dir));
    }
    let mut out = *ray;
    for j in 0..3 {
        let (src, sign) = (instance.src[j], instance.sign[j] as f32);
        out.origin[j] = sign * ray.origin[src] + instance.offset[j] as f32;
        out.dir[j] = sign * ray.dir[src];
        out.inv[j] = sign * ray.inv[src];
    }
    out
}

/// A crossing in the model's frame, in the scene's.
fn scene_crossing(instance: &Instance, index: u32, c: Crossing) -> Crossing {
    let hit = match &instance.turned {
        Some(turned) => turned_hit(turned, c.hit),
        None => {
            Hit { voxel: instance.cell_to_scene(c.hit.voxel), normal: instance.dir_to_scene(c.hit.normal), ..c.hit }
        }
    };
    Crossing { hit, instance: Some(index), ..c }
}

/// A hit in a turned model's frame, in the scene's: the cell holding the
/// hit cell's centre, the axis nearest the face's normal, and the face.
/// Twin of `turned_hit` in shaders/instances.wgsl.
fn turned_hit(turned: &Turned, hit: Hit) -> Hit {
    let centre = |cell: IVec3| turned.scene_point(cell.as_vec3() + Vec3::splat(0.5));
    let voxel = centre(hit.voxel).floor().as_ivec3();
    if hit.normal == IVec3::ZERO {
        return Hit { voxel, ..hit };
    }
    let normal = turned.scene_dir(hit.normal.as_vec3());
    let face = TurnedFace { normal, outside: centre(hit.voxel + hit.normal), cell: hit.voxel, cell_normal: hit.normal };
    Hit { voxel, normal: nearest_axis(normal), turned: Some(face), ..hit }
}
