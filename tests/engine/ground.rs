//! Issue 47, item 8: the ground plane under a scene takes its shadow.
//! Checked against geometry the test works out itself: which pixels see
//! the ground, and which ground cells the sun cannot reach past the model.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use glam::{DVec3, IVec3};
use octovox::camera::Camera;
use octovox::scene::{Octree, Op, Palette, Scene, Shape};
use octovox::settings::{RenderSettings, SUN_DIR};
use octovox::trace::render::render_scene_cpu;

/// A table: a 16 × 2 × 16 top held up at y = 8 by one leg from the ground.
const BOXES: [(IVec3, IVec3); 2] =
    [(IVec3::new(0, 8, 0), IVec3::new(15, 9, 15)), (IVec3::new(7, 0, 7), IVec3::new(8, 7, 8))];

fn table() -> Scene {
    let mut tree = Octree::default();
    for (min, max) in BOXES {
        tree.apply_brush(&Shape::Box { min, max }, Op::Place(1)).unwrap();
    }
    let mut palette = Palette::default();
    palette.colors[1] = [200, 80, 60, 255];
    Scene::new(palette, tree)
}

/// The entry t of a ray into the box `lo..hi` (corners), if it meets it
/// at t > 0 (slabs, in f64).
fn meets(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> Option<f64> {
    let (t0, t1) = ((lo - o) / d, (hi - o) / d);
    let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
    (near <= far && far > 0.0).then_some(near.max(0.0))
}

/// The entry t of a ray into a box of cells.
fn enters(o: DVec3, d: DVec3, (lo, hi): (IVec3, IVec3)) -> Option<f64> {
    meets(o, d, lo.as_dvec3(), hi.as_dvec3() + DVec3::ONE)
}

/// Whether a ray meets or misses every box with `margin` to spare: the
/// same answer for the boxes shrunk and grown by it (rays that graze an
/// edge are left out, where rounding may decide).
fn clear_of_edges(o: DVec3, d: DVec3, margin: f64) -> bool {
    BOXES.iter().all(|&(lo, hi)| {
        let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3() + DVec3::ONE);
        meets(o, d, lo + margin, hi - margin).is_some() == meets(o, d, lo - margin, hi + margin).is_some()
    })
}

#[test]
fn the_ground_under_a_model_is_dark_where_the_model_hides_the_sun() {
    let scene = table();
    let camera =
        Camera { eye: DVec3::new(-14.0, 30.0, 34.0), target: DVec3::new(4.0, 0.0, 4.0), fov_y_deg: 60.0, ortho: None };
    let size = (160, 120);
    let settings = RenderSettings { ground: Some(0), ..RenderSettings::default() };
    let image = render_scene_cpu(&scene, None, &camera, size, &settings);
    let basis = camera.basis(size.0, size.1, IVec3::ZERO);
    let sun = DVec3::from(SUN_DIR.map(f64::from));
    let (mut lit, mut shadowed) = (Vec::new(), Vec::new());
    for y in 0..size.1 {
        for x in 0..size.0 {
            let (o, d) = basis.ray(x, y);
            let (o, d) = (o.as_dvec3(), d.as_dvec3());
            let t = -o.y / d.y;
            if d.y >= 0.0 || BOXES.iter().any(|&b| enters(o, d, b).is_some_and(|e| e < t)) {
                continue;
            }
            // The ground cell's shadow ray leaves its top face's centre.
            let g = o + d * t;
            let from = DVec3::new(g.x.floor() + 0.5, 0.5, g.z.floor() + 0.5);
            let near_cell_edge = (g.x - g.x.round()).abs() < 0.05 || (g.z - g.z.round()).abs() < 0.05;
            if near_cell_edge || !clear_of_edges(o, d, 0.05) || !clear_of_edges(from, sun, 0.05) {
                continue;
            }
            let grey = image.get_pixel(x, y).0[..3].iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0;
            let blocked = BOXES.iter().any(|&b| enters(from, sun, b).is_some());
            if blocked { shadowed.push(grey) } else { lit.push(grey) }
        }
    }
    assert!(lit.len() > 500 && shadowed.len() > 100, "{} lit and {} shadowed ground pixels", lit.len(), shadowed.len());
    let darkest_lit = lit.iter().copied().fold(f64::MAX, f64::min);
    let brightest_shadow = shadowed.iter().copied().fold(0.0, f64::max);
    println!("lit ground {darkest_lit}.., shadowed ..{brightest_shadow}");
    assert!(brightest_shadow < 0.6 * darkest_lit, "shadowed ground up to {brightest_shadow}, lit from {darkest_lit}");
    // Without the ground those pixels are sky.
    let sky = render_scene_cpu(&scene, None, &camera, size, &RenderSettings::default());
    assert_ne!(sky, image);
}

/// A click goes where the picture shows: with the ground on (drawn at
/// y = 0), a voxel below the plane is hidden by it, and the pixel over it
/// picks the ground, not the voxel (the review of issue 47's ground found
/// clicks acting on hidden voxels).
#[test]
fn a_click_on_the_drawn_ground_picks_the_ground_not_a_voxel_under_it() {
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Box { min: IVec3::new(-20, -6, -20), max: IVec3::new(20, -3, 20) }, Op::Place(1)).unwrap();
    let scene = Scene::new(Palette::default(), tree);
    let camera = Camera { eye: DVec3::new(3.0, 30.0, 40.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None };
    let (size, centre) = ((64, 48), (32, 24));
    let hidden = octovox::trace::pick::pick_with_ground(&scene, &camera, size, centre, false).unwrap().unwrap();
    assert!(hidden.value == 1 && hidden.voxel.y == -3, "{hidden:?}");
    let shown = octovox::trace::pick::pick_with_ground(&scene, &camera, size, centre, true).unwrap().unwrap();
    assert_eq!((shown.value, shown.voxel.y, shown.normal), (0, -1, IVec3::Y), "{shown:?}");
}
