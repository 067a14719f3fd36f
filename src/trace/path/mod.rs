//! The path tracer's CPU reference, twin of `shaders/path.wgsl`: the same
//! sampling, the same random numbers ([`rng`]), the same order of draws, so
//! `render --cpu --spp N` and the GPU agree up to rounding.
//!
//! Per sample: a jittered camera ray, then up to `bounces` scattering events
//! (diffuse, metal, glass), with next-event estimation toward the sun (a
//! cone of [`SUN_ANGULAR_RADIUS`]) and toward emissive voxels at diffuse
//! events. A light reached by a ray after a diffuse event is not added again
//! (the estimate already holds it); after a specular event it is.
//! Continuation rays start exactly on the hit face's plane, where the
//! traversal's tie rule puts them in the voxel on the side they go to: no
//! epsilon offsets.

pub mod lights;
pub mod materials;
pub mod rng;

use std::f32::consts::PI;

use glam::{IVec3, Vec3};
use rayon::prelude::*;

use self::lights::Emitter;
use self::materials::{Effects, GpuMaterial, MATERIAL_EMIT, MATERIAL_GLASS, MATERIAL_METAL};
use self::rng::Rng;
use super::Footprint;
use super::denoise::{Guide, Sums};
use super::ground::{self, GROUND_ALBEDO, Landing};
use super::instanced::Traced;
use super::render::GAVE_UP_COLOR;
use super::svo::Crossing;
use super::{Hit, Ray, argmin};
use crate::camera::{Camera, RayBasis};
use crate::scene::Scene;
use crate::settings::{EffectsChoice, PathSettings, SUN_DIR};

/// Angular radius of the sun (radians): soft shadows of a few voxels.
pub const SUN_ANGULAR_RADIUS: f32 = 0.05;
/// Irradiance of the sun on a surface facing it.
pub const SUN_IRRADIANCE: f32 = 1.8;
/// Largest radiance one sample may add to a pixel: fireflies are clamped,
/// and NaN or infinity never reach the accumulation.
pub const MAX_SAMPLE_RADIANCE: f32 = 32.0;
/// Most passes through glass surfaces in one path (they do not count as
/// bounces, so that clear glass does not darken what lies behind it).
pub const MAX_TRANSMISSIONS: u32 = 16;
/// How far a ray leaving a freely turned face starts off it, relative to
/// the point's largest coordinate (at least 1). A turned face lies on no
/// plane of the grid: the hit point is on it only to rounding, and a ray
/// started there could find the cell it just left (a bounce stopped dead,
/// glass left where it was entered). Unturned faces need none: their hit
/// point lies on the face's plane exactly.
pub const TURNED_LIFT: f32 = 1.0 / 65536.0;

/// The ground's entry in [`PathScene`]'s material and albedo tables, after
/// the palette's 256 (the shaders get it from `crate::gpu::prelude`).
pub const GROUND_SURFACE: usize = 256;

/// Cosine of the sun's angular radius.
pub fn sun_cos() -> f32 {
    SUN_ANGULAR_RADIUS.cos()
}

/// Radiance of the sun's disk.
pub fn sun_radiance() -> f32 {
    SUN_IRRADIANCE / (2.0 * PI * (1.0 - sun_cos()))
}

/// The effect set of a frame: the scene's, or all of them.
pub fn effects_for(scene: &Scene, settings: &PathSettings) -> Effects {
    let sky = settings.sky != crate::settings::Sky::Black;
    match settings.effects {
        EffectsChoice::Auto => Effects::of_scene(scene.counts(), &scene.palette, settings.sun, sky),
        EffectsChoice::All => Effects::ALL,
    }
}

/// A scene prepared for path tracing.
pub struct PathScene<'a> {
    pub traced: Traced<'a>,
    /// Every palette entry's, then the ground's ([`GROUND_SURFACE`]).
    pub materials: Vec<GpuMaterial>,
    pub albedo: Vec<Vec3>,
    /// The tree-local height of the ground plane, if there is one.
    pub ground: Option<i32>,
    pub lights: Vec<Emitter>,
    pub effects: Effects,
    pub settings: PathSettings,
}

impl PathScene<'_> {
    pub fn new<'a>(scene: &'a Scene, settings: &PathSettings) -> PathScene<'a> {
        let palette = &scene.palette;
        let effects = effects_for(scene, settings);
        let lights = if effects.emit { lights::emitters(scene) } else { Vec::new() };
        let mut materials = materials::material_table(palette);
        let mut albedo: Vec<Vec3> = (0..=255u8).map(|i| materials::albedo(palette, i)).collect();
        materials.push(GpuMaterial::default());
        albedo.push(Vec3::from(GROUND_ALBEDO));
        PathScene {
            traced: Traced::of(scene),
            materials,
            albedo,
            ground: settings.ground.map(|y| y - scene.origin().y),
            lights,
            effects,
            settings: *settings,
        }
    }

    /// One sample of pixel (x, y): the radiance, finite and clamped.
    pub fn sample(&self, basis: &RayBasis, x: u32, y: u32, sample: u32) -> Vec3 {
        self.sample_with_albedo(basis, x, y, sample).0
    }

    /// One sample of pixel (x, y) and the colour the denoiser divides its
    /// light by: the first hit's albedo ([`PathScene::demodulation_albedo`]).
    pub fn sample_with_albedo(&self, basis: &RayBasis, x: u32, y: u32, sample: u32) -> (Vec3, Vec3) {
        let pixel = y * basis.width + x;
        // Where this sample is in the seed's random sequences.
        let sequence_index = self.settings.first_sample().wrapping_add(sample);
        let mut rng = Rng::new(pixel, sequence_index);
        let (jx, jy) = rng::pixel_offset(pixel, sequence_index);
        let (origin, dir) = basis.ray_through(x as f32 + jx, y as f32 + jy);
        let mut albedo = Vec3::ONE;
        let radiance = clamp_sample(self.radiance(Ray::new(origin, dir), &mut rng, &mut albedo));
        (radiance, albedo)
    }

    /// Whether the denoiser leaves a pixel whose first hit is of `kind` to
    /// its samples: a lamp, glass or metal (of the effects simulated).
    fn left_to_samples(&self, kind: u32) -> bool {
        let effects = self.effects;
        (effects.emit && kind == MATERIAL_EMIT)
            || (effects.glass && kind == MATERIAL_GLASS)
            || (effects.metal && kind == MATERIAL_METAL)
    }

    /// The colour a first hit on `value` contributes to the pixel's mean
    /// albedo: its own, or white where the pixel is left to its samples.
    /// Twin of `demodulation_albedo` in `shaders/path.wgsl`.
    fn demodulation_albedo(&self, surface: usize) -> Vec3 {
        let kind = self.materials[surface].kind;
        if self.left_to_samples(kind) { Vec3::ONE } else { self.albedo[surface] }
    }

    /// Where `ray` lands on the ground before the voxel it found, if it does.
    fn landing(&self, ray: &Ray, c: &Crossing) -> Option<Landing> {
        let found = c.found.then_some(c.hit.voxel);
        ground::landing(ray, self.ground?, found).filter(|_| !c.hit.gave_up)
    }

    /// The surface a ray meets: where, its normal, and its entry of the
    /// material and albedo tables (the voxel's value, or [`GROUND_SURFACE`],
    /// as the GPU's hit has it); `None` when it meets nothing or starts
    /// inside a solid voxel.
    fn surface(&self, ray: &Ray, c: &Crossing) -> Option<(Vec3, Vec3, usize)> {
        if let Some(land) = self.landing(ray, c) {
            return Some((land.point(ray), Vec3::Y, GROUND_SURFACE));
        }
        (c.found && c.hit.normal != IVec3::ZERO)
            .then(|| (surface_point(ray, c), c.hit.shading_normal(), usize::from(c.hit.value)))
    }

    /// The denoiser's guide of pixel (x, y): the first hit of its centre
    /// ray. Twin of `write_guide` in `shaders/path.wgsl`.
    pub fn guide(&self, basis: &RayBasis, x: u32, y: u32) -> Guide {
        let (origin, dir) = basis.ray(x, y);
        let ray = Ray::new(origin, dir);
        let c = self.cross(&ray, 0, None);
        match self.surface(&ray, &c) {
            Some((p, n, surface)) if !self.left_to_samples(self.materials[surface].kind) => {
                // The ground in front of a turned face is no turned face.
                Guide::filtered(p, n, c.hit.turned.is_some() && surface != GROUND_SURFACE)
            }
            _ => Guide::LEFT,
        }
    }

    /// The radiance along a camera ray; `first_albedo` gets the first hit's
    /// [`PathScene::demodulation_albedo`] (left as it is on a miss).
    fn radiance(&self, mut ray: Ray, rng: &mut Rng, first_albedo: &mut Vec3) -> Vec3 {
        let mut radiance = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        let mut medium = 0u8;
        // The instance whose glass the ray is in.
        let mut inside = None;
        let mut lights_counted = false;
        let (mut bounces, mut transmissions) = (0, 0);
        let mut first = true;
        loop {
            let c = self.cross(&ray, medium, inside);
            if c.hit.gave_up {
                return radiance + beta * GAVE_UP_COLOR;
            }
            let Some((p, n, surface)) = self.surface(&ray, &c) else {
                if c.found {
                    // The ray started inside a solid voxel: nothing to see.
                    return radiance;
                }
                return radiance + beta * self.environment(ray.dir, lights_counted);
            };
            // The ground in front of a turned face is no turned face (the
            // shader's landed hit is the ground's alone).
            let lift = if surface == GROUND_SURFACE { 0.0 } else { lift_of(&c, p) };
            let d = ray.dir.normalize();
            let material = self.materials[surface];
            if first {
                *first_albedo = self.demodulation_albedo(surface);
                first = false;
            }
            let glass = |index: usize| self.materials[index].kind == MATERIAL_GLASS;
            let dir;
            // Leaving glass (into empty space or other glass), or entering it.
            let leaving = self.effects.glass && medium != 0 && (surface == 0 || glass(surface));
            if !leaving && self.effects.emit && material.kind == MATERIAL_EMIT {
                // Counted by light sampling, unless no list of lights
                // (too many) sampled it.
                if !lights_counted || self.lights.is_empty() {
                    radiance += beta * self.albedo[surface] * material.emission;
                }
                return radiance;
            }
            if leaving
                || (self.effects.glass && material.kind == MATERIAL_GLASS && rng.uniform() < material.transparency)
            {
                transmissions += 1;
                // A glass face is a voxel's (the ground is none): its value.
                let Some((next, to)) = self.interface(d, n, medium, c.hit.value, rng) else { return radiance };
                // Into other glass (or out of it): the instance of the face crossed.
                if to.0 != medium {
                    inside = c.instance;
                }
                (dir, medium) = (next, to.0);
                beta *= to.1;
                lights_counted = false;
            } else if bounces == self.settings.bounces {
                return radiance;
            } else if self.effects.metal && material.kind == MATERIAL_METAL {
                bounces += 1;
                let albedo = self.albedo[surface];
                let p_spec = 0.5 + 0.5 * material.metalness;
                if rng.uniform() < p_spec {
                    let lobe = Lobe::glossy(-d, albedo, &material);
                    // Lights are sampled for a rough lobe; a sharp one finds
                    // them by reflection.
                    let sampled = lobe.alpha >= MIN_SAMPLED_ALPHA;
                    if sampled {
                        radiance += beta * self.direct(leave(p, n, lift, n), n, &lobe, rng) / p_spec;
                    }
                    let Some((next, weight)) = metal_lobe(d, n, albedo, &material, rng) else { return radiance };
                    dir = next;
                    beta *= weight / p_spec;
                    lights_counted = sampled;
                } else {
                    let albedo = albedo * (1.0 - material.metalness) / (1.0 - p_spec);
                    radiance += beta * albedo * self.direct(leave(p, n, lift, n), n, &Lobe::DIFFUSE, rng);
                    dir = cosine_direction(n, rng.uniform(), rng.uniform());
                    beta *= albedo;
                    lights_counted = true;
                }
            } else {
                bounces += 1;
                let albedo = self.albedo[surface];
                radiance += beta * albedo * self.direct(leave(p, n, lift, n), n, &Lobe::DIFFUSE, rng);
                dir = cosine_direction(n, rng.uniform(), rng.uniform());
                beta *= albedo;
                lights_counted = true;
            }
            if transmissions > MAX_TRANSMISSIONS {
                return radiance;
            }
            ray = Ray::new(leave(p, n, lift, dir), dir);
        }
    }

    /// The next voxel that is not the medium, the glass of instance
    /// `inside` (see [`Traced::trace_through`]).
    fn cross(&self, ray: &Ray, medium: u8, inside: Option<u32>) -> Crossing {
        self.traced.trace_through(ray, medium, inside, Footprint::EXACT)
    }

    /// A glass surface between `medium` and `value` (0: empty space):
    /// Fresnel reflection or refraction about a normal roughened by the
    /// glass's GGX roughness. Returns the new direction and the medium it
    /// travels in with the colour it is tinted by, or `None` when a rough
    /// normal sends it to the wrong side.
    fn interface(&self, d: Vec3, n: Vec3, medium: u8, value: u8, rng: &mut Rng) -> Option<(Vec3, (u8, Vec3))> {
        let glass = if medium != 0 { medium } else { value };
        let material = self.materials[usize::from(glass)];
        let ior = |index: u8| if index == 0 { 1.0 } else { self.materials[usize::from(index)].ior };
        let alpha = material.roughness * material.roughness;
        let (u1, u2) = (rng.uniform(), rng.uniform());
        let mut h = if alpha > 1e-4 { ggx_half_vector(n, alpha, u1, u2) } else { n };
        if h.dot(d) >= 0.0 {
            h = n;
        }
        let eta = ior(medium) / ior(value);
        let cos_i = -d.dot(h);
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
        let fresnel = if sin2_t >= 1.0 { 1.0 } else { fresnel_dielectric(cos_i, (1.0 - sin2_t).sqrt(), eta) };
        if rng.uniform() < fresnel {
            let dir = reflect(d, h);
            return (dir.dot(n) > 0.0).then_some((dir, (medium, Vec3::ONE)));
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let dir = eta * d + (eta * cos_i - cos_t) * h;
        // Entering glass tints by its colour; leaving does not.
        let tint = if value != 0 { self.albedo[usize::from(value)] } else { Vec3::ONE };
        (dir.dot(n) < 0.0).then_some((dir, (value, tint)))
    }

    /// Light reflected at `p` by `lobe` toward the path (for the diffuse
    /// lobe, before the albedo): the sun's cone and one emissive voxel face,
    /// each with a shadow ray.
    fn direct(&self, p: Vec3, n: Vec3, lobe: &Lobe, rng: &mut Rng) -> Vec3 {
        let mut light = Vec3::ZERO;
        if self.effects.sun {
            let samples = self.settings.shadow_samples.max(1);
            let mut sum = Vec3::ZERO;
            for _ in 0..samples {
                let l = cone_direction(Vec3::from(SUN_DIR), sun_cos(), rng.uniform(), rng.uniform());
                let cos = n.dot(l);
                if cos > 0.0 && !self.cross(&Ray::new(p, l), 0, None).found {
                    sum += SUN_IRRADIANCE * cos * lobe.eval(n, l);
                }
            }
            light += sum / samples as f32;
        }
        if self.effects.emit && !self.lights.is_empty() {
            light += self.emitter_light(p, n, lobe, rng);
        }
        light
    }

    /// One sample of an emissive cell: a cell picked by power, one of its
    /// faces that faces `p`, a point on it. A turned lamp's cell is
    /// sampled in its model's frame (a rigid map: the same distances).
    fn emitter_light(&self, p: Vec3, n: Vec3, lobe: &Lobe, rng: &mut Rng) -> Vec3 {
        let (u0, u1, u2, u3) = (rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
        let i = lights::pick(&self.lights, u0);
        let light = self.lights[i];
        let turned = self.traced.turned(light.instance);
        let at = turned.map_or(p, |t| t.model_point(p));
        let Some((q, face_axis, faces)) = emitter_point(&light, at, u1, u2, u3) else { return Vec3::ZERO };
        let w = q - at;
        let dist2 = w.length_squared();
        let towards = w / dist2.sqrt();
        let l = turned.map_or(towards, |t| t.scene_dir(towards));
        let cos_s = n.dot(l);
        let cos_l = towards[face_axis].abs();
        if cos_s <= 0.0 || dist2 <= 0.0 {
            return Vec3::ZERO;
        }
        let c = self.cross(&Ray::new(p, l), 0, None);
        let reached = match turned {
            None => c.found && lights::contains(&light, c.hit.voxel),
            Some(_) => {
                let same = c.instance == Some(light.instance) && u32::from(c.hit.value) == light.index;
                c.found && same && lights::holds_point(&light, at + towards * c.t)
            }
        };
        if !reached {
            return Vec3::ZERO;
        }
        let size = light.size as f32;
        let pdf = lights::pick_probability(&self.lights, i) / (faces as f32 * size * size);
        let index = light.index as usize;
        let radiance = self.albedo[index] * self.materials[index].emission;
        radiance * lobe.eval(n, l) * (cos_s * cos_l / (dist2 * pdf))
    }

    /// What a ray that leaves the scene sees: the sky, and the sun's disk
    /// unless a diffuse event already sampled it.
    fn environment(&self, dir: Vec3, lights_counted: bool) -> Vec3 {
        let d = dir.normalize();
        let mut radiance = Vec3::ZERO;
        if self.effects.sky {
            let (horizon, zenith) = self.settings.sky.colors();
            radiance += Vec3::from(horizon).lerp(Vec3::from(zenith), (d.y * 0.5 + 0.5).clamp(0.0, 1.0));
        }
        if self.effects.sun && !lights_counted && d.dot(Vec3::from(SUN_DIR)) >= sun_cos() {
            radiance += Vec3::splat(sun_radiance());
        }
        radiance
    }
}

/// Lights are sampled at a metal's specular lobe from this GGX alpha up
/// (roughness 0.1); sharper lobes find them by reflection alone.
pub const MIN_SAMPLED_ALPHA: f32 = 0.01;

/// The reflectance a light sample is weighted by: Lambert's 1/π (the albedo
/// applied by the caller), or a metal's GGX lobe seen from `v`.
struct Lobe {
    glossy: bool,
    alpha: f32,
    f0: Vec3,
    v: Vec3,
}

impl Lobe {
    const DIFFUSE: Lobe = Lobe { glossy: false, alpha: 1.0, f0: Vec3::ZERO, v: Vec3::ZERO };

    fn glossy(v: Vec3, albedo: Vec3, material: &GpuMaterial) -> Lobe {
        let f0 = Vec3::splat(0.04).lerp(albedo, material.metalness);
        Lobe { glossy: true, alpha: material.roughness * material.roughness, f0, v }
    }

    /// The BRDF for light arriving from `l`.
    fn eval(&self, n: Vec3, l: Vec3) -> Vec3 {
        if !self.glossy {
            return Vec3::splat(1.0 / PI);
        }
        let h = (self.v + l).normalize();
        let (cos_v, cos_l, cos_h) = (n.dot(self.v), n.dot(l), n.dot(h));
        if cos_v <= 0.0 || cos_l <= 0.0 {
            return Vec3::ZERO;
        }
        let a2 = self.alpha * self.alpha;
        let k = cos_h * cos_h * (a2 - 1.0) + 1.0;
        let ggx = a2 / (PI * k * k);
        let g = smith_g1(cos_v, self.alpha) * smith_g1(cos_l, self.alpha);
        let x = 1.0 - self.v.dot(h).max(0.0);
        let fresnel = self.f0 + (Vec3::ONE - self.f0) * (x * x * x * x * x);
        fresnel * (ggx * g / (4.0 * cos_v * cos_l))
    }
}

/// A point on a face of the emissive cell that faces `p`: the point, the
/// face's axis and how many faces face `p`; `None` if none does.
fn emitter_point(light: &Emitter, p: Vec3, u1: f32, u2: f32, u3: f32) -> Option<(Vec3, usize, u32)> {
    let lo = IVec3::from(light.min).as_vec3();
    let hi = lo + Vec3::splat(light.size as f32);
    let below = p.cmplt(lo);
    let above = p.cmpgt(hi);
    let faces = (0..3).filter(|a| below.test(*a) || above.test(*a)).count() as u32;
    if faces == 0 {
        return None;
    }
    let pick = ((u1 * faces as f32) as u32).min(faces - 1);
    let axis = (0..3).filter(|a| below.test(*a) || above.test(*a)).nth(pick as usize)?;
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut q = Vec3::ZERO;
    q[axis] = if below.test(axis) { lo[axis] } else { hi[axis] };
    q[b] = lo[b] + u2 * (hi[b] - lo[b]);
    q[c] = lo[c] + u3 * (hi[c] - lo[c]);
    Some((q, axis, faces))
}

/// How far a ray leaving the face `c` found, at `p`, starts off it:
/// [`TURNED_LIFT`] of the point's size on a turned face, none on any
/// other. Twin of `lift_of` in `shaders/path.wgsl`.
fn lift_of(c: &Crossing, p: Vec3) -> f32 {
    if c.hit.turned.is_some() { TURNED_LIFT * p.abs().max_element().max(1.0) } else { 0.0 }
}

/// Where a ray in direction `dir` leaving the face at `p` (normal `n`)
/// starts: `lift` off the face, on the side `dir` goes to.
fn leave(p: Vec3, n: Vec3, lift: f32, dir: Vec3) -> Vec3 {
    p + n * if dir.dot(n) >= 0.0 { lift } else { -lift }
}

/// The point where a ray enters the voxel it found: on the entered face's
/// plane exactly, inside the face.
pub fn surface_point(ray: &Ray, c: &Crossing) -> Vec3 {
    let hit: &Hit = &c.hit;
    if hit.turned.is_some() {
        // A turned face lies on no plane of the grid.
        return ray.origin + ray.dir * c.t;
    }
    let lo = hit.voxel.as_vec3();
    let mut p = (ray.origin + ray.dir * c.t).clamp(lo, lo + Vec3::ONE);
    let axis = argmin(-hit.normal.abs().as_vec3());
    p[axis] = lo[axis] + if hit.normal[axis] > 0 { 1.0 } else { 0.0 };
    p
}

/// Finite, non-negative, at most [`MAX_SAMPLE_RADIANCE`] per channel.
pub fn clamp_sample(v: Vec3) -> Vec3 {
    if !v.is_finite() {
        return Vec3::ZERO;
    }
    v.clamp(Vec3::ZERO, Vec3::splat(MAX_SAMPLE_RADIANCE))
}

/// An orthonormal basis around a unit vector (Duff et al., 2017).
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

fn around(n: Vec3, cos_theta: f32, phi: f32) -> Vec3 {
    let (t, b) = basis(n);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    (t * phi.cos() + b * phi.sin()) * sin_theta + n * cos_theta
}

/// Cosine-weighted direction about `n`.
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    around(n, (1.0 - u1).sqrt(), 2.0 * PI * u2)
}

/// Uniform direction in the cone about `axis` of half-angle cosine `cos_max`.
pub fn cone_direction(axis: Vec3, cos_max: f32, u1: f32, u2: f32) -> Vec3 {
    around(axis, 1.0 - u1 * (1.0 - cos_max), 2.0 * PI * u2)
}

/// A microfacet normal drawn from the GGX distribution D(h)·(n·h).
fn ggx_half_vector(n: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    let cos2 = (1.0 - u1) / (1.0 + (alpha * alpha - 1.0) * u1);
    around(n, cos2.max(0.0).sqrt(), 2.0 * PI * u2)
}

fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// Unpolarised Fresnel reflectance of a dielectric surface, `eta` = n_i/n_t.
fn fresnel_dielectric(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Smith's masking term for GGX.
fn smith_g1(cos: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    2.0 * cos / (cos + (a2 + (1.0 - a2) * cos * cos).sqrt())
}

/// The specular lobe of a metal: a mirror at roughness 0, GGX above it,
/// tinted by the colour as far as `_metal` says (Schlick's Fresnel from
/// F0 = mix(0.04, colour, metalness)). Returns the direction and weight.
fn metal_lobe(d: Vec3, n: Vec3, albedo: Vec3, material: &GpuMaterial, rng: &mut Rng) -> Option<(Vec3, Vec3)> {
    let alpha = material.roughness * material.roughness;
    let (u1, u2) = (rng.uniform(), rng.uniform());
    let smooth = alpha <= 1e-4;
    let h = if smooth { n } else { ggx_half_vector(n, alpha, u1, u2) };
    let dir = reflect(d, h);
    let (cos_v, cos_l, cos_h) = (-d.dot(n), dir.dot(n), h.dot(n));
    let cos_vh = -d.dot(h);
    if cos_l <= 0.0 || cos_vh <= 0.0 {
        return None;
    }
    let f0 = Vec3::splat(0.04).lerp(albedo, material.metalness);
    let x = 1.0 - cos_vh;
    let fresnel = f0 + (Vec3::ONE - f0) * (x * x * x * x * x);
    if smooth {
        return Some((dir, fresnel));
    }
    let g = smith_g1(cos_v, alpha) * smith_g1(cos_l, alpha);
    Some((dir, fresnel * (g * cos_vh / (cos_v * cos_h).max(1e-6))))
}

/// What the CPU reference rendered.
pub struct CpuRender {
    /// The mean radiance of every pixel, row-major.
    pub pixels: Vec<Vec3>,
    /// The sums the means come from, for the denoiser and the noise estimate.
    pub sums: Vec<Sums>,
    /// The denoiser's guide of every pixel.
    pub guides: Vec<Guide>,
    pub effects: Effects,
    /// Emissive cells sampled as lights.
    pub lights: usize,
}

/// The mean radiance of `spp` samples of every pixel: the CPU reference for
/// path-traced frames (`render --cpu --spp N`).
pub fn render_cpu(scene: &Scene, camera: &Camera, size: (u32, u32), settings: &PathSettings, spp: u32) -> CpuRender {
    let basis = camera.basis(size.0, size.1, scene.origin());
    let scene = PathScene::new(scene, settings);
    let (sums, guides): (Vec<Sums>, Vec<Guide>) = (0..basis.height)
        .into_par_iter()
        .flat_map_iter(|y| {
            let scene = &scene;
            (0..basis.width).map(move |x| {
                let mut sums = Sums { count: spp, ..Sums::default() };
                for s in 0..spp {
                    let (v, albedo) = scene.sample_with_albedo(&basis, x, y, s);
                    sums.sum += v;
                    sums.squares += v * v;
                    sums.albedo += albedo;
                }
                (sums, scene.guide(&basis, x, y))
            })
        })
        .unzip();
    let pixels = sums.iter().map(Sums::mean).collect();
    CpuRender { pixels, sums, guides, effects: scene.effects, lights: scene.lights.len() }
}

/// Radiance to display bytes: clamped to 0..=1, as the preview's colours.
pub fn to_image(pixels: &[Vec3], width: u32, height: u32) -> image::RgbaImage {
    let bytes = pixels.iter().flat_map(|p| super::render::display_rgba(*p)).collect();
    image::RgbaImage::from_raw(width, height, bytes).unwrap_or_default()
}
