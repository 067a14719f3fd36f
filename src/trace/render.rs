//! Whole images on the CPU: trace every pixel (rows in parallel) and shade
//! the hits the same way `shaders/common.wgsl` does.

use glam::{IVec3, Vec3};
use rayon::prelude::*;

use super::grid::{self, DenseGrid};
use super::ground::{self, Landing};
use super::instanced::Traced;
use super::{Footprint, Hit, Ray};
use crate::camera::{Camera, RayBasis};
use crate::scene::{Palette, Scene};
use crate::settings::{RenderSettings, SUN_DIR, View};

/// The structure a CPU render walks.
pub enum Tracer<'a> {
    Svo(Traced<'a>),
    Grid(&'a DenseGrid),
}

impl Tracer<'_> {
    /// The first hit along `ray`; the grid is always exact.
    pub fn trace(&self, ray: &Ray, footprint: Footprint) -> Hit {
        match self {
            Tracer::Svo(traced) => traced.trace(ray, footprint),
            Tracer::Grid(grid) => grid::trace(grid, ray),
        }
    }
}

/// Hit records of every pixel, row-major from the top-left.
pub fn trace_image(tracer: &Tracer, basis: &RayBasis, footprint: Footprint) -> Vec<Hit> {
    (0..basis.height)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..basis.width).map(move |x| {
                let (origin, dir) = basis.ray(x, y);
                tracer.trace(&Ray::new(origin, dir), footprint)
            })
        })
        .collect()
}

/// Colours hit records into RGBA8 pixels. `shadow` says, per pixel, whether
/// the sun is blocked (all false when shadows are off); `grounds`, where the
/// pixel's ray lands on the ground instead (empty without a ground, which
/// only the shaded view draws).
pub fn shade_image(
    hits: &[Hit],
    grounds: &[Option<Landing>],
    basis: &RayBasis,
    palette: &Palette,
    view: View,
    shadow: &[bool],
) -> Vec<[u8; 4]> {
    hits.par_iter()
        .enumerate()
        .map(|(i, hit)| {
            let x = i as u32 % basis.width;
            let y = i as u32 / basis.width;
            let dir = basis.ray(x, y).1;
            let in_shadow = shadow.get(i).copied().unwrap_or(false);
            match grounds.get(i) {
                Some(Some(_)) => display_rgba(ground::shaded(in_shadow)),
                _ => shade(hit, dir, palette, view, in_shadow),
            }
        })
        .collect()
}

/// Where each pixel's ray lands on the ground at tree-local height `y`
/// before the voxel it hit ([`ground::landing`]); a ray that gave up lands
/// nowhere (it stays magenta).
pub fn ground_landings(hits: &[Hit], basis: &RayBasis, y: i32) -> Vec<Option<Landing>> {
    hits.par_iter()
        .enumerate()
        .map(|(i, hit)| {
            let (origin, dir) = basis.ray(i as u32 % basis.width, i as u32 / basis.width);
            let found = if hit.is_hit() { Some(hit.voxel) } else { None };
            if hit.gave_up() { None } else { ground::landing(&Ray::new(origin, dir), y, found) }
        })
        .collect()
}

/// The ray toward the sun from a hit: it starts at the centre of the empty
/// voxel in front of the entered face, so it never starts inside the surface
/// (shadows are per face, which suits voxels). Mirrors `shadow_origin` in WGSL.
pub fn shadow_ray(hit: &Hit) -> Option<Ray> {
    if let Some(face) = hit.turned.filter(|_| hit.is_hit()) {
        return Some(Ray::new(face.outside, Vec3::from(SUN_DIR)));
    }
    (hit.is_hit() && hit.normal != IVec3::ZERO).then(|| sun_ray_from(hit.voxel + hit.normal))
}

/// The ray toward the sun from the centre of the empty `cell` in front of a
/// lit face (a voxel's, or the ground's top face, whose cell is the one
/// above the landing's).
fn sun_ray_from(cell: IVec3) -> Ray {
    Ray::new(cell.as_vec3() + Vec3::splat(0.5), Vec3::from(SUN_DIR))
}

/// A shaded cell's depth along the view axis (the hit voxel's, or the ground
/// cell's): the camera ray's t there, near enough, from integers alone so
/// the GPU (`main` in `shaders/trace_svo.wgsl`) agrees.
pub fn cell_depth(cell: IVec3, basis: &RayBasis) -> f32 {
    (cell.as_vec3() + Vec3::splat(0.5) - basis.eye).dot(basis.forward)
}

/// Colour of a ray that ran out of iterations before it hit or left the
/// scene (the shaders get it from `crate::gpu::prelude`): magenta, so a
/// give-up never looks like sky.
pub const GAVE_UP_COLOR: Vec3 = Vec3::new(1.0, 0.0, 1.0);

/// One pixel's colour; mirrors `shade` in `shaders/common.wgsl`.
pub fn shade(hit: &Hit, dir: Vec3, palette: &Palette, view: View, in_shadow: bool) -> [u8; 4] {
    let rgb = match view {
        View::Shaded if hit.is_hit() => {
            let c = palette.color(hit.value);
            let albedo = Vec3::new(f32::from(c[0]), f32::from(c[1]), f32::from(c[2])) / 255.0;
            let n = hit.shading_normal();
            let lambert = n.dot(Vec3::from(SUN_DIR)).max(0.0);
            let sun = if in_shadow { 0.0 } else { lambert };
            let sky = if hit.normal == IVec3::ZERO { 0.0 } else { 0.5 + 0.5 * n.y };
            albedo * (0.25 + 0.15 * sky + 0.6 * sun)
        }
        View::Shaded if hit.gave_up() => GAVE_UP_COLOR,
        View::Shaded => sky_color(dir),
        View::Iterations => heat(hit.iterations as f32 / 160.0),
        View::Depth if hit.is_hit() => heat((hit.cell_level as f32 + 1.0) / 8.0),
        View::Depth => Vec3::ZERO,
        View::Normals if hit.is_hit() => hit.shading_normal() * 0.5 + Vec3::splat(0.5),
        View::Normals => Vec3::ZERO,
    };
    display_rgba(rgb)
}

/// A colour as the display shows it: each channel clamped to 0..=1 and
/// rounded to a byte (no tone mapping; the path tracer's radiance too).
pub fn display_rgba(rgb: Vec3) -> [u8; 4] {
    let to_byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    [to_byte(rgb.x), to_byte(rgb.y), to_byte(rgb.z), 255]
}

/// Background: horizon to zenith by the ray's elevation.
pub fn sky_color(dir: Vec3) -> Vec3 {
    let up = (dir.normalize_or_zero().y * 0.5 + 0.5).clamp(0.0, 1.0);
    Vec3::new(0.86, 0.89, 0.95).lerp(Vec3::new(0.32, 0.5, 0.82), up)
}

/// Blue → cyan → green → yellow → red for 0..=1.
pub fn heat(x: f32) -> Vec3 {
    let x = x.clamp(0.0, 1.0) * 4.0;
    let stops = [
        Vec3::new(0.05, 0.05, 0.45),
        Vec3::new(0.0, 0.6, 0.9),
        Vec3::new(0.1, 0.8, 0.2),
        Vec3::new(0.95, 0.9, 0.1),
        Vec3::new(0.9, 0.1, 0.05),
    ];
    let i = (x.floor() as usize).min(3);
    stops[i].lerp(stops[i + 1], x - i as f32)
}

/// A whole image on the CPU: the reference for `render --cpu` and replay's
/// `--cpu` mode. `grid` selects the DDA baseline instead of the SVO.
pub fn render_scene_cpu(
    scene: &Scene,
    grid: Option<&DenseGrid>,
    camera: &Camera,
    size: (u32, u32),
    settings: &RenderSettings,
) -> image::RgbaImage {
    let tracer = match grid {
        Some(grid) => Tracer::Grid(grid),
        None => Tracer::Svo(Traced::of(scene)),
    };
    let basis = camera.basis(size.0, size.1, scene.origin());
    let footprint = Footprint::of_pixels(&basis, settings.lod);
    let hits = trace_image(&tracer, &basis, footprint);
    let gave_up = hits.iter().filter(|hit| hit.gave_up()).count();
    if gave_up > 0 {
        log::warn!(
            "{gave_up} of {} rays ran out of iterations before they hit or left the scene \
             (a traversal bug: no valid ray should); they are drawn magenta, not as sky",
            hits.len()
        );
    }
    let grounds = match settings.ground {
        Some(y) if settings.view == View::Shaded => ground_landings(&hits, &basis, y - scene.origin().y),
        _ => Vec::new(),
    };
    let shadows: Vec<bool> = if settings.shadows {
        // A shadow ray keeps the footprint its camera ray had at the hit.
        (0..hits.len())
            .into_par_iter()
            .map(|i| {
                let ray = match grounds.get(i) {
                    Some(Some(landing)) => Some((sun_ray_from(landing.cell + IVec3::Y), landing.cell)),
                    _ => shadow_ray(&hits[i]).map(|ray| (ray, hits[i].voxel)),
                };
                ray.is_some_and(|(ray, cell)| tracer.trace(&ray, footprint.at(cell_depth(cell, &basis))).is_hit())
            })
            .collect()
    } else {
        Vec::new()
    };
    let bytes: Vec<u8> =
        shade_image(&hits, &grounds, &basis, &scene.palette, settings.view, &shadows).into_iter().flatten().collect();
    // shade_image yields exactly width * height pixels, so this cannot fail.
    image::RgbaImage::from_raw(basis.width, basis.height, bytes).unwrap_or_default()
}
