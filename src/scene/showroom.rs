//! The built-in showroom: a polished metal floor, a glass pane, a lamp, a
//! gold sphere and a red one, between two walls open to the sky. It shows
//! every effect of the path tracer (`octovox render --demo showroom --spp 64`).

use glam::IVec3;

use super::{Material, MaterialKind, Octree, Op, Palette, Scene, Shape};

const FLOOR: u8 = 1;
const WALL: u8 = 2;
const RED_WALL: u8 = 3;
const GLASS: u8 = 4;
const LAMP: u8 = 5;
const RED: u8 = 6;
const GOLD: u8 = 7;
const STONE: u8 = 8;

fn material(kind: MaterialKind, params: &[(&str, &str)]) -> Material {
    let mut m = Material::new(kind);
    for (key, value) in params {
        m.params.insert((*key).to_string(), (*value).to_string());
    }
    m
}

fn showroom_palette() -> Palette {
    let mut palette = Palette::default();
    let colors: [(u8, [u8; 3]); 8] = [
        (FLOOR, [190, 192, 200]),
        (WALL, [232, 228, 220]),
        (RED_WALL, [190, 70, 60]),
        (GLASS, [200, 235, 245]),
        (LAMP, [255, 214, 150]),
        (RED, [210, 50, 40]),
        (GOLD, [240, 190, 80]),
        (STONE, [110, 110, 118]),
    ];
    for (index, [r, g, b]) in colors {
        palette.colors[usize::from(index)] = [r, g, b, 255];
    }
    let m = &mut palette.materials;
    m[usize::from(FLOOR)] = material(MaterialKind::Metal, &[("_metal", "1"), ("_rough", "0.35")]);
    m[usize::from(GLASS)] = material(MaterialKind::Glass, &[("_ri", "1.5"), ("_trans", "1"), ("_rough", "0")]);
    m[usize::from(LAMP)] = material(MaterialKind::Emit, &[("_emit", "1"), ("_flux", "1")]);
    m[usize::from(GOLD)] = material(MaterialKind::Metal, &[("_metal", "1"), ("_rough", "0.2")]);
    palette
}

/// The showroom scene.
pub fn showroom_scene() -> Scene {
    let mut tree = Octree::default();
    let edits = [
        (Shape::Box { min: IVec3::new(0, -1, 0), max: IVec3::new(63, 0, 63) }, FLOOR),
        (Shape::Box { min: IVec3::new(0, 1, 0), max: IVec3::new(63, 28, 1) }, WALL),
        (Shape::Box { min: IVec3::new(0, 1, 2), max: IVec3::new(1, 28, 63) }, RED_WALL),
        (Shape::Box { min: IVec3::new(22, 1, 30), max: IVec3::new(46, 20, 31) }, GLASS),
        (Shape::Sphere { center: IVec3::new(30, 8, 16), radius: 7 }, RED),
        (Shape::Sphere { center: IVec3::new(44, 6, 46), radius: 5 }, GOLD),
        (Shape::Box { min: IVec3::new(12, 1, 44), max: IVec3::new(13, 12, 45) }, STONE),
        (Shape::Box { min: IVec3::new(10, 13, 42), max: IVec3::new(15, 16, 47) }, LAMP),
    ];
    for (shape, color) in edits {
        // The shapes are fixed and well inside the world limits.
        let _ = tree.apply_brush(&shape, Op::Place(color));
    }
    Scene::new(showroom_palette(), tree)
}

/// A camera inside the interior, looking at the table from a corner.
pub fn interior_camera() -> crate::camera::Camera {
    use glam::DVec3;
    crate::camera::Camera {
        eye: DVec3::new(36.0, 18.0, 36.0),
        target: DVec3::new(10.0, 4.0, 10.0),
        fov_y_deg: 60.0,
        ortho: None,
    }
}

/// A closed room lit only by three lamps: a wooden floor, white walls, a
/// table and a stool. No sunlight or sky reaches inside.
pub fn interior_scene() -> Scene {
    let mut palette = showroom_palette();
    palette.colors[usize::from(FLOOR)] = [150, 105, 70, 255];
    palette.materials[usize::from(FLOOR)] = Material::default();
    let mut tree = Octree::default();
    let edits = [
        (Shape::Box { min: IVec3::new(-1, -1, -1), max: IVec3::new(40, 24, 40) }, Op::Place(WALL)),
        (Shape::Box { min: IVec3::new(0, 0, 0), max: IVec3::new(39, 23, 39) }, Op::Remove),
        (Shape::Box { min: IVec3::new(-1, -1, -1), max: IVec3::new(40, -1, 40) }, Op::Paint(FLOOR)),
        (Shape::Box { min: IVec3::new(-1, 0, 0), max: IVec3::new(-1, 23, 39) }, Op::Paint(RED_WALL)),
        (Shape::Box { min: IVec3::new(12, 8, 12), max: IVec3::new(27, 9, 27) }, Op::Place(STONE)),
        (Shape::Box { min: IVec3::new(13, 0, 13), max: IVec3::new(14, 7, 14) }, Op::Place(STONE)),
        (Shape::Box { min: IVec3::new(25, 0, 25), max: IVec3::new(26, 7, 26) }, Op::Place(STONE)),
        (Shape::Sphere { center: IVec3::new(30, 3, 8), radius: 3 }, Op::Place(RED)),
        (Shape::Box { min: IVec3::new(18, 22, 18), max: IVec3::new(21, 23, 21) }, Op::Place(LAMP)),
        (Shape::Box { min: IVec3::new(4, 10, 34), max: IVec3::new(5, 11, 35) }, Op::Place(LAMP)),
        (Shape::Box { min: IVec3::new(18, 10, 18), max: IVec3::new(19, 11, 19) }, Op::Place(LAMP)),
    ];
    for (shape, op) in edits {
        // The shapes are fixed and well inside the world limits.
        let _ = tree.apply_brush(&shape, op);
    }
    Scene::new(palette, tree)
}
