//! What the CPU tracers walk: the one model's octree, or a scene of
//! objects as instances (two-level tracing). The reference for
//! `shaders/instances.wgsl`: the same ray transforms, the same walk over the
//! tree of instance boxes and the same rule for ties, so change both
//! together.

use glam::IVec3;

use super::svo::{self, Crossing};
use super::{Footprint, Hit, Ray};
use crate::scene::Scene;
use crate::scene::instances::{Instance, InstanceTable, TIE_T};
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
    /// The scene's one model, or its objects placed in its local frame
    /// (cells from `scene.origin()`).
    pub fn of(scene: &'a Scene) -> Traced<'a> {
        match scene.objects() {
            None => Traced::Tree(scene.drawn()),
            Some(objects) => Traced::Objects {
                table: InstanceTable::build(objects, scene.origin()),
                models: &objects.models,
                bound: super::iteration_bound(scene.drawn().depth()),
            },
        }
    }

    /// The first solid voxel along `ray` under `footprint`.
    pub fn trace(&self, ray: &Ray, footprint: Footprint) -> Hit {
        self.trace_through(ray, 0, None, footprint).hit
    }

    /// The first voxel along `ray` that is not `medium`, where `inside` is
    /// the instance whose glass the ray is in: every other object is
    /// crossed as empty space. A ray in glass that finds none leaves it at
    /// its tree's face. Twin of `trace_scene` in `shaders/instances.wgsl`.
    pub fn trace_through(&self, ray: &Ray, medium: u8, inside: Option<u32>, footprint: Footprint) -> Crossing {
        let (table, models, bound) = match self {
            Traced::Tree(tree) => return svo::cross(tree, ray, medium, footprint),
            Traced::Objects { table, models, bound } => (table, models, *bound),
        };
        let mut best: Option<Crossing> = None;
        let (mut iterations, mut gave_up) = (0u32, false);
        let mut i = 0;
        while i < table.nodes.len() {
            let node = table.nodes[i];
            let enter = node.bounds.is_some_and(|(lo, hi)| {
                let (t_enter, t_exit, _) = ray.slab(lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
                let reach = best.map_or(f32::MAX, |b| tie_limit(b.t));
                t_enter <= t_exit && t_exit > 0.0 && t_enter <= reach
            });
            if let (true, Some(index)) = (enter, node.leaf) {
                let instance = &table.instances[index as usize];
                let tree = &models[instance.model].tree;
                let m = if inside == Some(index) { medium } else { 0 };
                let c = svo::cross(tree, &model_ray(instance, ray), m, footprint);
                iterations = iterations.saturating_add(c.hit.iterations);
                gave_up |= c.hit.gave_up;
                if c.found && best.is_none_or(|b| c.t <= tie_limit(b.t)) {
                    best = Some(scene_crossing(instance, index, c));
                }
            }
            i = if enter && node.leaf.is_none() { i + 1 } else { node.skip as usize };
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

/// The ray in the model's tree-local frame: the same t reaches the same point.
fn model_ray(instance: &Instance, ray: &Ray) -> Ray {
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
    let hit = Hit { voxel: instance.cell_to_scene(c.hit.voxel), normal: instance.dir_to_scene(c.hit.normal), ..c.hit };
    Crossing { hit, instance: Some(index), ..c }
}
