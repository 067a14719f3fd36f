//! Property tests of the CPU octree, its edits, undo data and the node pool's
//! dirty ranges.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::collections::HashMap;

use glam::IVec3;
use octovox::edit::{Edit, History};
use octovox::gpu_pool::Upload;
use octovox::scene::octree::decode_from_bytes;
use octovox::scene::{Octree, Op, Palette, Scene, Shape};
use proptest::prelude::*;

/// A byte-for-byte copy of the GPU buffers, updated only through flushed ranges.
#[derive(Default)]
struct Mirror {
    nodes: Vec<u8>,
    bricks: Vec<u8>,
}

impl Mirror {
    fn apply(&mut self, tree: &Octree, upload: &Upload) {
        let pool = tree.pool();
        for (buf, region, ranges) in [
            (&mut self.nodes, &upload.nodes, upload.nodes.ranges(&pool.nodes).collect::<Vec<_>>()),
            (&mut self.bricks, &upload.bricks, upload.bricks.ranges(&pool.bricks).collect::<Vec<_>>()),
        ] {
            if let Some(bytes) = region.grow_to_bytes() {
                // A new buffer holds a copy of the old one; the rest is garbage.
                buf.resize(bytes as usize, 0xAB);
            }
            for (offset, bytes) in ranges {
                buf[offset as usize..offset as usize + bytes.len()].copy_from_slice(bytes);
            }
        }
    }
}

fn arb_shape() -> impl Strategy<Value = Shape> {
    let pos = || (-40i32..40, -40i32..40, -40i32..40).prop_map(|(x, y, z)| IVec3::new(x, y, z));
    prop_oneof![
        pos().prop_map(Shape::Voxel),
        (pos(), 0i32..9).prop_map(|(center, radius)| Shape::Sphere { center, radius }),
        (pos(), (1i32..12, 1i32..12, 1i32..12))
            .prop_map(|(min, (x, y, z))| Shape::Box { min, max: min + IVec3::new(x, y, z) - IVec3::ONE }),
    ]
}

fn arb_op() -> impl Strategy<Value = Op> {
    prop_oneof![(1u8..=255).prop_map(Op::Place), Just(Op::Remove), (1u8..=255).prop_map(Op::Paint)]
}

fn apply_reference(reference: &mut HashMap<IVec3, u8>, shape: &Shape, op: Op) {
    let (lo, hi) = shape.bounds();
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let p = IVec3::new(x, y, z);
                if shape.contains(p) {
                    let old = reference.get(&p).copied().unwrap_or(0);
                    match op.apply(old) {
                        0 => reference.remove(&p),
                        v => reference.insert(p, v),
                    };
                }
            }
        }
    }
}

fn check_all(tree: &Octree, reference: &HashMap<IVec3, u8>, mirror: &Mirror) {
    tree.check_invariants().unwrap();
    assert_eq!(tree.solid_voxels(), reference.len() as u64);
    let lo = IVec3::splat(-52);
    let hi = IVec3::splat(52);
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let p = IVec3::new(x, y, z);
                let want = reference.get(&p).copied().unwrap_or(0);
                assert_eq!(tree.get(p), want, "octree at {p}");
                let gpu =
                    decode_from_bytes(&mirror.nodes, &mirror.bricks, tree.root_word(), tree.origin(), tree.depth(), p);
                assert_eq!(gpu, want, "mirror buffer at {p}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random mixed edits match a HashMap, keep the collapse invariant, and a
    /// mirror fed only by dirty ranges decodes to the same voxels.
    #[test]
    fn edits_match_reference_and_mirror(
        edits in prop::collection::vec((arb_shape(), arb_op()), 1..24),
        start_small in any::<bool>(),
    ) {
        let mut tree = if start_small { Octree::empty(IVec3::new(3, 3, 3), 2) } else { Octree::default() };
        let mut reference = HashMap::new();
        let mut mirror = Mirror::default();
        for (shape, op) in &edits {
            tree.apply_brush(shape, *op).unwrap();
            apply_reference(&mut reference, shape, *op);
            let upload = tree.pool_mut().flush();
            mirror.apply(&tree, &upload);
        }
        check_all(&tree, &reference, &mirror);
    }

    /// Undoing every edit restores the voxels and the node count; redoing
    /// brings the edited scene back; freed slots get reused.
    #[test]
    fn undo_redo_round_trip(edits in prop::collection::vec((arb_shape(), arb_op()), 1..16)) {
        let base: Vec<(IVec3, u8)> = (0..300)
            .map(|i| (IVec3::new(i % 17 - 8, (i / 17) % 5, i % 13 - 6), (i % 7 + 1) as u8))
            .collect();
        let mut scene = Scene::new(Default::default(), Octree::from_voxels(&base).unwrap());
        let before = scene.voxels();
        let (nodes, bricks) = (scene.drawn().node_count(), scene.drawn().brick_count());
        let mut history = History::default();
        for (shape, op) in &edits {
            history.apply(&mut scene, Edit::Brush { shape: *shape, op: *op }).unwrap();
        }
        let after = scene.voxels();
        let after_counts = (scene.drawn().node_count(), scene.drawn().brick_count());
        while history.undo(&mut scene).unwrap() {}
        scene.drawn().check_invariants().unwrap();
        prop_assert_eq!(sorted(scene.voxels()), sorted(before));
        prop_assert_eq!((scene.drawn().node_count(), scene.drawn().brick_count()), (nodes, bricks));
        while history.redo(&mut scene).unwrap() {}
        scene.drawn().check_invariants().unwrap();
        prop_assert_eq!(sorted(scene.voxels()), sorted(after));
        prop_assert_eq!((scene.drawn().node_count(), scene.drawn().brick_count()), after_counts);
    }
}

fn sorted(mut v: Vec<(IVec3, u8)>) -> Vec<(IVec3, u8)> {
    v.sort_by_key(|(p, _)| (p.x, p.y, p.z));
    v
}

#[test]
fn build_from_list_and_dense_agree() {
    let dims = glam::UVec3::new(37, 21, 45);
    let mut dense = vec![0u8; (dims.x * dims.y * dims.z) as usize];
    let mut list = Vec::new();
    for z in 0..dims.z as i32 {
        for y in 0..dims.y as i32 {
            for x in 0..dims.x as i32 {
                let v = if (x - 18).pow(2) + (y - 10).pow(2) * 3 + (z - 22).pow(2) < 300 {
                    ((x / 4 + z / 8) % 3 + 1) as u8
                } else {
                    0
                };
                dense[(x + 37 * (y + 21 * z)) as usize] = v;
                if v != 0 {
                    list.push((IVec3::new(x, y, z) + IVec3::new(-5, 7, 100), v));
                }
            }
        }
    }
    let a = Octree::from_voxels(&list).unwrap();
    let b = Octree::from_dense(dims, IVec3::new(-5, 7, 100), &dense).unwrap();
    a.check_invariants().unwrap();
    b.check_invariants().unwrap();
    assert_eq!(a.solid_voxels(), list.len() as u64);
    assert_eq!(sorted(a.voxels()), sorted(list.clone()));
    assert_eq!(sorted(b.voxels()), sorted(list));
}

#[test]
fn duplicate_positions_keep_the_last_value() {
    let p = IVec3::new(1, 2, 3);
    let tree = Octree::from_voxels(&[(p, 4), (IVec3::ZERO, 1), (p, 9)]).unwrap();
    assert_eq!(tree.get(p), 9);
    assert_eq!(tree.solid_voxels(), 2);
}

#[test]
fn edits_far_outside_grow_the_root_and_undo_shrinks_it() {
    let mut scene = Scene::new(Default::default(), Octree::from_voxels(&[(IVec3::ZERO, 5)]).unwrap());
    let (origin, depth) = (scene.origin(), scene.drawn().depth());
    let mut history = History::default();
    let far = IVec3::new(-3000, 40, 9000);
    history.apply(&mut scene, Edit::Brush { shape: Shape::Voxel(far), op: Op::Place(7) }).unwrap();
    assert_eq!(scene.voxel(far), 7);
    assert_eq!(scene.voxel(IVec3::ZERO), 5);
    assert!(scene.drawn().depth() > depth);
    history.undo(&mut scene).unwrap();
    assert_eq!((scene.origin(), scene.drawn().depth()), (origin, depth));
    assert_eq!(scene.voxel(far), 0);
    scene.drawn().check_invariants().unwrap();
}

#[test]
fn bad_edits_are_refused_without_change() {
    let mut scene = Scene::new(Default::default(), Octree::from_voxels(&[(IVec3::ZERO, 5)]).unwrap());
    let huge = Edit::Brush { shape: Shape::Voxel(IVec3::new(1 << 30, 0, 0)), op: Op::Place(1) };
    assert!(huge.apply(&mut scene).is_err());
    let zero = Edit::Brush { shape: Shape::Voxel(IVec3::ONE), op: Op::Place(0) };
    assert!(zero.apply(&mut scene).is_err());
    let radius = Edit::Brush { shape: Shape::Sphere { center: IVec3::ZERO, radius: 1_000_000_000 }, op: Op::Remove };
    assert!(radius.apply(&mut scene).unwrap_err().to_string().contains("radius"));
    let palette_zero = Edit::Palette { index: 0, color: [1, 2, 3, 255], material: Box::default() };
    assert!(palette_zero.apply(&mut scene).is_err());
    assert_eq!(scene.voxels(), vec![(IVec3::ZERO, 5)]);
    assert_eq!(scene.palette, Palette::default());
}

/// Edits on the report's teapot write bytes for the slots they touch, not
/// for the tree: one voxel ≤ 1 KiB, a radius-8 sphere a small fraction.
#[test]
fn teapot_edits_write_only_what_they_touch() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/teapot256.vox");
    let model = octovox::io::vox::load_vox_file(&path, 0).unwrap();
    let mut tree = Octree::from_voxels(&model.voxels).unwrap();
    let whole = tree.pool_mut().flush().byte_count();
    assert_eq!(whole, tree.pool().live_bytes());
    let wall = (-200..200).map(|x| IVec3::new(x, 0, 0)).find(|p| tree.get(*p) != 0).unwrap();
    for (shape, limit) in [
        (Shape::Voxel(wall), 1024),
        (Shape::Voxel(wall + IVec3::new(-1, 0, 0)), 1024),
        (Shape::Sphere { center: wall, radius: 8 }, whole / 100),
    ] {
        for op in [Op::Remove, Op::Place(3), Op::Paint(4)] {
            tree.apply_brush(&shape, op).unwrap();
            let written = tree.pool_mut().flush().byte_count();
            assert!(written <= limit, "{shape:?} {op:?} wrote {written} bytes of {whole}");
        }
    }
}

/// Level-of-detail summaries follow edits: the root's representative index
/// is the one covering most, repainting the model changes it, and undo
/// restores it.
#[test]
fn summaries_follow_edits_and_undo() {
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(15, 7, 15) }, Op::Place(3)).unwrap();
    tree.apply_brush(&Shape::Voxel(IVec3::new(0, 12, 0)), Op::Place(9)).unwrap();
    let root = |tree: &Octree| tree.summary(tree.root_word(), tree.depth());
    assert_eq!(root(&tree).index, 3);
    assert_eq!(root(&tree).coverage, 128, "half the 16³ root is solid (rounded up)");
    let patch = tree.apply_brush(&Shape::Box { min: IVec3::ZERO, max: IVec3::new(15, 7, 15) }, Op::Paint(7)).unwrap();
    assert_eq!(root(&tree).index, 7);
    tree.check_invariants().unwrap();
    tree.apply_patch(&patch).unwrap();
    assert_eq!(root(&tree).index, 3);
    tree.check_invariants().unwrap();
}
