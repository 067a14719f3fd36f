//! Criterion benchmarks of the octree: build from a voxel list and from a
//! dense array, and edit latency (apply + flush). `octovox bench` prints the
//! same quantities as tables for docs/bench/.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::IVec3;
use octovox::scene::{Octree, Op, Shape};

fn teapot_voxels() -> Vec<(IVec3, u8)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/teapot256.vox");
    octovox::io::vox::load_vox_file(&path, 0).expect("teapot256.vox in ../shared/assets").voxels
}

fn build(c: &mut Criterion) {
    let voxels = teapot_voxels();
    c.bench_function("build teapot256 from list", |b| b.iter(|| Octree::from_voxels(black_box(&voxels))));
    let dims = glam::UVec3::splat(128);
    let dense: Vec<u8> = (0..128 * 128 * 128)
        .map(|i: i32| {
            let p = IVec3::new(i % 128, (i / 128) % 128, i / 16384) - IVec3::splat(64);
            u8::from(p.length_squared() < 60 * 60)
        })
        .collect();
    c.bench_function("build 128³ ball from dense", |b| {
        b.iter(|| Octree::from_dense(dims, IVec3::ZERO, black_box(&dense)))
    });
}

fn edit(c: &mut Criterion) {
    let mut tree = Octree::from_voxels(&teapot_voxels()).expect("teapot fits");
    tree.pool_mut().flush();
    let at = (-200..200).map(|x| IVec3::new(x, 0, 0)).find(|p| tree.get(*p) != 0).expect("a wall voxel");
    for (name, shape) in [
        ("edit one voxel + flush", Shape::Voxel(at)),
        ("edit sphere r=8 + flush", Shape::Sphere { center: at, radius: 8 }),
    ] {
        let mut remove = true;
        c.bench_function(name, |b| {
            b.iter(|| {
                let op = if remove { Op::Remove } else { Op::Place(2) };
                remove = !remove;
                let undo = tree.apply_brush(&shape, op);
                black_box((undo, tree.pool_mut().flush().byte_count()))
            })
        });
    }
}

criterion_group!(benches, build, edit);
criterion_main!(benches);
