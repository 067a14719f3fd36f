//! The built-in demo scene: rolling terrain with grass, dirt, stone, sand
//! and water, a few shapes and a tree — generated in code, deterministic.

use glam::IVec3;

use super::{Octree, Op, Palette, Scene, Shape};

/// Palette indices of the demo's colours.
mod colors {
    pub const GRASS: u8 = 1;
    pub const DIRT: u8 = 2;
    pub const STONE: u8 = 3;
    pub const SAND: u8 = 4;
    pub const WATER: u8 = 5;
    pub const TRUNK: u8 = 6;
    pub const LEAVES: u8 = 7;
    pub const RED: u8 = 8;
    pub const GOLD: u8 = 9;
    pub const WHITE: u8 = 10;
    pub const BLUE: u8 = 11;
}

const SIZE: i32 = 128;
const WATER_LEVEL: i32 = 9;

fn demo_palette() -> Palette {
    let mut palette = Palette::default();
    let custom: [(u8, [u8; 3]); 11] = [
        (colors::GRASS, [96, 168, 72]),
        (colors::DIRT, [134, 96, 67]),
        (colors::STONE, [128, 128, 136]),
        (colors::SAND, [219, 202, 148]),
        (colors::WATER, [64, 120, 200]),
        (colors::TRUNK, [102, 72, 48]),
        (colors::LEAVES, [58, 130, 60]),
        (colors::RED, [200, 60, 50]),
        (colors::GOLD, [230, 180, 40]),
        (colors::WHITE, [235, 235, 228]),
        (colors::BLUE, [70, 90, 190]),
    ];
    for (index, [r, g, b]) in custom {
        palette.colors[usize::from(index)] = [r, g, b, 255];
    }
    palette
}

/// Terrain height at a column: a few octaves of smooth waves.
fn height(x: i32, z: i32) -> i32 {
    let (x, z) = (x as f32, z as f32);
    let h = 12.0
        + 6.0 * (x * 0.045).sin() * (z * 0.038).cos()
        + 3.5 * (x * 0.11 + 1.3).sin() * (z * 0.09 + 0.4).sin()
        + 1.5 * ((x + z) * 0.23).sin();
    h.round() as i32
}

fn terrain() -> Vec<(IVec3, u8)> {
    let mut voxels = Vec::new();
    for z in 0..SIZE {
        for x in 0..SIZE {
            let top = height(x, z);
            for y in 0..=top.max(WATER_LEVEL) {
                let value = if y > top {
                    colors::WATER
                } else if y == top && top <= WATER_LEVEL + 1 {
                    colors::SAND
                } else if y == top {
                    colors::GRASS
                } else if y + 3 >= top {
                    colors::DIRT
                } else {
                    colors::STONE
                };
                voxels.push((IVec3::new(x, y, z), value));
            }
        }
    }
    voxels
}

/// Shapes placed with the same brushes the user has.
fn decorate(tree: &mut Octree) {
    let ground = |x: i32, z: i32| height(x, z).max(WATER_LEVEL);
    let mut place = |shape: Shape, op: Op| {
        // The shapes are fixed and inside the world limits.
        let _ = tree.apply_brush(&shape, op);
    };
    // A red sphere with a golden cap, and a white arch.
    let (sx, sz) = (40, 84);
    let sy = ground(sx, sz) + 9;
    place(Shape::Sphere { center: IVec3::new(sx, sy, sz), radius: 9 }, Op::Place(colors::RED));
    place(
        Shape::Box { min: IVec3::new(sx - 10, sy + 4, sz - 10), max: IVec3::new(sx + 10, sy + 10, sz + 10) },
        Op::Paint(colors::GOLD),
    );
    let (ax, az) = (80, 40);
    let ay = ground(ax, az);
    place(
        Shape::Box { min: IVec3::new(ax - 12, ay, az - 3), max: IVec3::new(ax + 12, ay + 22, az + 3) },
        Op::Place(colors::WHITE),
    );
    place(Shape::Box { min: IVec3::new(ax - 7, ay, az - 4), max: IVec3::new(ax + 7, ay + 15, az + 4) }, Op::Remove);
    // A blue tower with windows.
    let (tx, tz) = (96, 96);
    let ty = ground(tx, tz);
    place(
        Shape::Box { min: IVec3::new(tx - 5, ty, tz - 5), max: IVec3::new(tx + 5, ty + 34, tz + 5) },
        Op::Place(colors::BLUE),
    );
    for level in 0..4 {
        let y = ty + 6 + level * 8;
        place(Shape::Box { min: IVec3::new(tx - 6, y, tz - 1), max: IVec3::new(tx + 6, y + 3, tz + 1) }, Op::Remove);
    }
    // A tree.
    let (rx, rz) = (24, 30);
    let ry = ground(rx, rz);
    place(
        Shape::Box { min: IVec3::new(rx - 1, ry, rz - 1), max: IVec3::new(rx + 1, ry + 14, rz + 1) },
        Op::Place(colors::TRUNK),
    );
    place(Shape::Sphere { center: IVec3::new(rx, ry + 18, rz), radius: 7 }, Op::Place(colors::LEAVES));
}

/// The scene `octovox` opens without a file.
pub fn demo_scene() -> Scene {
    // The terrain list is bounded (128² columns) and well inside the limits.
    let mut tree = Octree::from_voxels(&terrain()).unwrap_or_default();
    decorate(&mut tree);
    Scene::new(demo_palette(), tree)
}

/// The scenes built in, for `--demo` and replay's `demo`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum BuiltIn {
    /// Rolling terrain with a few shapes (the default).
    #[default]
    Terrain,
    /// A metal floor, a glass pane, a lamp: every effect of the path tracer.
    Showroom,
    /// A closed room lit by lamps only.
    Interior,
}

impl BuiltIn {
    pub fn scene(self) -> Scene {
        match self {
            BuiltIn::Terrain => demo_scene(),
            BuiltIn::Showroom => super::showroom::showroom_scene(),
            BuiltIn::Interior => super::showroom::interior_scene(),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            BuiltIn::Terrain => "terrain",
            BuiltIn::Showroom => "showroom",
            BuiltIn::Interior => "interior",
        }
    }
}
