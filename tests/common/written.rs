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
    let mut scenes = vec![
        SceneNode::Transform { attributes: dict(&[]), frames: vec![], child: 1, layer_id: u32::MAX },
        SceneNode::Group { attributes: dict(&[]), children: (0..count).map(|k| 2 + 2 * k).collect() },
    ];
    for k in 0..count {
        let (x, y) = ((k % 20) as i32 * 16, (k / 20) as i32 * 16);
        let key = |f: u32, dx: i32| Frame::new(dict(&[("_f", f.to_string()), ("_t", format!("{} {y} 0", x + dx))]));
        let mut attributes = vec![("_name", format!("cow {k}"))];
        if k % 3 == 0 {
            attributes.push(("_loop", "1".to_owned()));
        }
        scenes.push(SceneNode::Transform {
            attributes: dict(&attributes),
            frames: vec![key(0, 0), key(6 + k % 5, 3 + (k % 7) as i32), key(20, 0)],
            child: 3 + 2 * k,
            layer_id: 0,
        });
        scenes.push(SceneNode::Shape {
            attributes: dict(&[]),
            models: vec![ShapeModel { model_id: 0, attributes: dict(&[]) }],
        });
    }
    DotVoxData {
        version: 200,
        index_map: Vec::new(),
        models: vec![model(6, 30)],
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: Vec::new(),
        scenes,
        layers: vec![Layer { attributes: dict(&[("_name", "0".into())]) }],
    }
}
