//! Scenes the tests write with `dot_vox` (not octovox's saver): small
//! models, dictionaries, and a herd of moving references.

use dot_vox::{DotVoxData, Frame, Layer, Model, SceneNode, ShapeModel, Size, Voxel};

/// A cube-ish model with a marked corner, so that rotations show.
pub fn model(size: u32, color: u8) -> Model {
    let mut voxels = Vec::new();
    for x in 0..size as u8 {
        for y in 0..size as u8 {
            voxels.push(Voxel { x, y, z: 0, i: color });
        }
    }
    voxels.push(Voxel { x: 0, y: 0, z: 1, i: color + 1 });
    Model { size: Size { x: size, y: size, z: 2 }, voxels }
}

pub fn dict(pairs: &[(&str, String)]) -> dot_vox::Dict {
    pairs.iter().map(|(k, v)| ((*k).to_owned(), v.clone())).collect()
}

/// A herd: `count` references of one model on a grid, each keyed to walk
/// along x and back (some step, some loop), enough that the scene is drawn
/// as instances.
pub fn herd(count: u32) -> DotVoxData {
    let objects = (0..count).map(|k| {
        let (x, y) = ((k % 20) as i32 * 16, (k / 20) as i32 * 16);
        let key = |f: u32, dx: i32| Frame::new(dict(&[("_f", f.to_string()), ("_t", format!("{} {y} 0", x + dx))]));
        let mut attributes = vec![("_name", format!("cow {k}"))];
        if k % 3 == 0 {
            attributes.push(("_loop", "1".to_owned()));
        }
        (dict(&attributes), vec![key(0, 0), key(6 + k % 5, 3 + (k % 7) as i32), key(20, 0)])
    });
    placements_of(model(6, 30), objects.collect())
}

/// A scene of one model placed once per object under one group: each
/// object's transform attributes and keys, in order.
fn placements_of(model: Model, objects: Vec<(dot_vox::Dict, Vec<Frame>)>) -> DotVoxData {
    let count = objects.len() as u32;
    let mut scenes = vec![
        SceneNode::Transform { attributes: dict(&[]), frames: vec![], child: 1, layer_id: u32::MAX },
        SceneNode::Group { attributes: dict(&[]), children: (0..count).map(|k| 2 + 2 * k).collect() },
    ];
    for (k, (attributes, frames)) in (0..count).zip(objects) {
        scenes.push(SceneNode::Transform { attributes, frames, child: 3 + 2 * k, layer_id: 0 });
        scenes.push(SceneNode::Shape {
            attributes: dict(&[]),
            models: vec![ShapeModel { model_id: 0, attributes: dict(&[]) }],
        });
    }
    DotVoxData {
        version: 200,
        index_map: Vec::new(),
        models: vec![model],
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: Vec::new(),
        scenes,
        layers: vec![Layer { attributes: dict(&[("_name", "0".into())]) }],
    }
}

/// `count` objects of one 6 × 5 × 4 block (a colour per layer, a notch cut
/// into one corner) on a grid 14 apart, each turned by a random unit
/// quaternion `_ov_turn` (beside `_r` 4, no quarter turn) drawn from `seed`.
pub fn turned_herd(count: u32, seed: u64) -> DotVoxData {
    let mut voxels = Vec::new();
    for x in 0..6u8 {
        for y in 0..5u8 {
            for z in 0..4u8 {
                if !(x < 2 && y < 2 && z > 1) {
                    voxels.push(Voxel { x, y, z, i: 20 + 16 * z + (x + y) % 3 });
                }
            }
        }
    }
    let mut state = seed;
    let mut uniform = move || {
        // SplitMix64: a fixed, seedable stream.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let objects = (0..count).map(|k| {
        let (x, y) = ((k % 10) as i32 * 14, (k / 10) as i32 * 14);
        // A uniform random rotation (Shoemake's subgroup algorithm).
        let (u1, u2, u3) = (uniform(), uniform() * std::f64::consts::TAU, uniform() * std::f64::consts::TAU);
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let q = [a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos()];
        let key = dict(&[
            ("_t", format!("{x} {y} {}", (k % 3) as i32 * 5)),
            ("_ov_turn", format!("{} {} {} {}", q[0], q[1], q[2], q[3])),
        ]);
        (dict(&[("_name", format!("turned {k}"))]), vec![Frame::new(key)])
    });
    placements_of(Model { size: Size { x: 6, y: 5, z: 4 }, voxels }, objects.collect())
}
