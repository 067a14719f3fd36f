//! load → encode → load keeps voxels, palette and materials; axes keep their
//! directions (no mirroring) both when loading and when saving.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use glam::IVec3;
use octovox::io::vox::{encode_vox, load_vox, load_vox_file, save_vox};
use octovox::scene::{Material, MaterialKind, Palette, VoxelModel};

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox")
}

/// Every `.vox` under the shared assets except the deliberately broken one.
fn asset_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut dirs = vec![assets()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("read asset dir") {
            let path = entry.expect("dir entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "vox") && path.file_name().is_some_and(|n| n != "not_a.vox")
            {
                files.push(path);
            }
        }
    }
    files.sort();
    assert!(files.len() >= 14, "expected the shared assets, found {files:?}");
    files
}

fn voxel_set(model: &VoxelModel) -> BTreeSet<([i32; 3], u8)> {
    model.voxels.iter().map(|&(p, i)| (p.to_array(), i)).collect()
}

fn assert_round_trip(name: &str, model: &VoxelModel) -> VoxelModel {
    let bytes = encode_vox(&model.palette, &model.voxels).expect("encode");
    let again = load_vox(&bytes, 0).expect("reload what we wrote");
    assert_eq!(again.voxels.len(), model.voxels.len(), "{name}: voxel count");
    assert!(voxel_set(&again) == voxel_set(model), "{name}: voxels differ");
    assert_eq!(again.palette.colors, model.palette.colors, "{name}: colours");
    assert_eq!(again.palette.materials, model.palette.materials, "{name}: materials");
    again
}

#[test]
fn every_shared_asset_round_trips() {
    for path in asset_files() {
        let model = load_vox_file(&path, 0).expect("load asset");
        assert_round_trip(&path.display().to_string(), &model);
    }
}

#[test]
fn every_trex_frame_round_trips() {
    let path = assets().join("magicavoxel/T-Rex.vox");
    for frame in 0..8 {
        let model = load_vox_file(&path, frame).expect("load frame");
        assert_round_trip(&format!("T-Rex frame {frame}"), &model);
    }
}

/// Materials survive: kinds and every parameter, including MATT-derived ones.
#[test]
fn materials_are_read_from_matl_and_matt() {
    let metal = load_vox_file(&assets().join("format/metal-material.vox"), 0).expect("load");
    let m = metal.palette.material(85);
    assert_eq!(m.kind, MaterialKind::Metal);
    assert_eq!(m.params.get("_rough").map(String::as_str), Some("0.252632"));
    assert_eq!(metal.palette.material(249).kind, MaterialKind::Glass);

    // T-Rex has only old MATT chunks: diffuse, weight 1, roughness/specular/IOR.
    let trex = load_vox_file(&assets().join("magicavoxel/T-Rex.vox"), 0).expect("load");
    let m = trex.palette.material(1);
    assert_eq!(m.kind, MaterialKind::Diffuse);
    assert_eq!(m.params.get("_weight").map(String::as_str), Some("1"));
    assert!(m.params.contains_key("_rough") && m.params.contains_key("_ior"), "{m:?}");
}

fn synthetic_palette() -> Palette {
    let mut palette = Palette::default();
    palette.colors[255] = [1, 2, 3, 4];
    palette.colors[0] = [9, 8, 7, 6];
    let mut glass = Material::new(MaterialKind::Glass);
    glass.params.insert("_ior".to_owned(), "0.5".to_owned());
    glass.params.insert("_unknown_key".to_owned(), "kept verbatim".to_owned());
    palette.materials[255] = glass;
    palette.materials[7] = Material::new(MaterialKind::Emit);
    // Index 0 is written as MATL 256, MagicaVoxel's number for it.
    palette.materials[0] = Material::new(MaterialKind::Metal);
    palette
}

/// Palette index 255 (dot_vox's `i` = 254) and a scene 701 voxels wide, which
/// must be cut into several ≤ 256³ models.
#[test]
fn index_255_and_wide_scenes_round_trip() {
    let voxels = vec![
        (IVec3::new(-300, 0, 0), 255),
        (IVec3::new(400, 0, 0), 1),
        (IVec3::new(0, -1000, 5), 7),
        (IVec3::new(0, 0, 700), 255),
        (IVec3::new(255, 255, 255), 2),
        (IVec3::new(256, 256, 256), 3),
    ];
    let model = VoxelModel { palette: synthetic_palette(), voxels, models: 1, ..VoxelModel::default() };
    let again = assert_round_trip("synthetic", &model);
    assert!(again.models >= 4, "expected a split into several models, got {}", again.models);
    assert_eq!(again.palette.colors[255], [1, 2, 3, 4]);
    assert_eq!(again.palette.material(255).params["_unknown_key"], "kept verbatim");
}

#[test]
fn saving_an_empty_scene_loads_back_empty() {
    let bytes = encode_vox(&Palette::default(), &[]).expect("encode");
    assert!(load_vox(&bytes, 0).expect("load").voxels.is_empty());
}

#[test]
fn index_zero_cannot_be_saved() {
    let err = encode_vox(&Palette::default(), &[(IVec3::ZERO, 0)]).expect_err("index 0");
    assert!(err.to_string().contains("palette index 0"), "{err}");
}

/// A tripod with arms of lengths 5 (+x), 3 (+y, up) and 2 (+z), one palette
/// index per arm. Mirroring any axis or swapping two would move an arm.
fn tripod() -> Vec<(IVec3, u8)> {
    let mut voxels = vec![(IVec3::ZERO, 1)];
    voxels.extend((1..=5).map(|i| (IVec3::new(i, 0, 0), 2)));
    voxels.extend((1..=3).map(|i| (IVec3::new(0, i, 0), 3)));
    voxels.extend((1..=2).map(|i| (IVec3::new(0, 0, i), 4)));
    voxels
}

#[test]
fn tripod_keeps_its_arms_through_save_and_load() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("tripod.vox");
    save_vox(&path, &Palette::default(), &tripod()).expect("save");
    let loaded = load_vox_file(&path, 0).expect("load");
    let expected: BTreeSet<_> = tripod().iter().map(|&(p, i)| (p.to_array(), i)).collect();
    assert!(voxel_set(&loaded) == expected, "arms moved: {:?}", loaded.voxels);
}

/// In the saved file (read with dot_vox itself, MagicaVoxel's z-up axes) the
/// world-up arm must run along +z and the world +z arm along −y: the
/// right-handed change of axes, not a mirror.
#[test]
fn saved_tripod_stands_upright_in_magicavoxel_axes() {
    let bytes = encode_vox(&Palette::default(), &tripod()).expect("encode");
    let data = dot_vox::load_bytes(&bytes).expect("dot_vox reads our file");
    assert_eq!(data.models.len(), 1);
    let model = &data.models[0];
    let origin = model.voxels.iter().find(|v| v.i + 1 == 1).expect("origin voxel");
    let arm = |index: u8| -> Vec<[i32; 3]> {
        let mut offsets: Vec<[i32; 3]> = model
            .voxels
            .iter()
            .filter(|v| v.i + 1 == index)
            .map(|v| {
                [
                    i32::from(v.x) - i32::from(origin.x),
                    i32::from(v.y) - i32::from(origin.y),
                    i32::from(v.z) - i32::from(origin.z),
                ]
            })
            .collect();
        offsets.sort_unstable();
        offsets
    };
    assert_eq!(arm(2), (1..=5).map(|i| [i, 0, 0]).collect::<Vec<_>>(), "world +x → vox +x");
    assert_eq!(arm(3), (1..=3).map(|i| [0, 0, i]).collect::<Vec<_>>(), "world +y → vox +z");
    assert_eq!(arm(4), vec![[0, -2, 0], [0, -1, 0]], "world +z → vox −y");
}

/// axes.vox (dot_vox's test file) is a coordinate gizmo: three copies of a
/// model stacked along each MagicaVoxel axis, one colour per axis — index 217
/// along +x (group at x = 173), 239 along +y (group at y = 188), 229 along +z
/// (group at z = 131, MagicaVoxel's up). Loaded, the +z arm must point up
/// (world +y), the +y arm away from the viewer (world −z), +x stay +x.
#[test]
fn axes_asset_arms_point_the_right_way() {
    let model = load_vox_file(&assets().join("format/axes.vox"), 0).expect("load axes.vox");
    let mut sums: BTreeMap<u8, ([i64; 3], i64)> = BTreeMap::new();
    for &(p, index) in &model.voxels {
        let entry = sums.entry(index).or_insert(([0; 3], 0));
        for axis in 0..3 {
            entry.0[axis] += i64::from(p[axis]);
        }
        entry.1 += 1;
    }
    let centroid = |index: u8| {
        let (sum, n) = sums[&index];
        sum.map(|s| s / n)
    };
    let [x_arm, y_arm, z_arm] = [centroid(217), centroid(239), centroid(229)];
    assert!(x_arm[0] > 150 && x_arm[2].abs() < 10, "x arm at {x_arm:?}");
    assert!(y_arm[2] < -150 && y_arm[0].abs() < 10, "MagicaVoxel y arm at {y_arm:?}");
    assert!(z_arm[1] > 100 && z_arm[0].abs() < 10 && z_arm[2].abs() < 10, "z arm at {z_arm:?}");
}

/// chr_knight.vox (no scene graph) is loaded in its own grid: the file's
/// z = 0 layer (the knight's feet, on the ground in MagicaVoxel) becomes the
/// lowest world y and the file's top layer the highest; MagicaVoxel's y
/// becomes −z.
#[test]
fn knight_feet_are_below_its_head() {
    let path = assets().join("magicavoxel/chr_knight.vox");
    let data = dot_vox::load_bytes(&std::fs::read(&path).expect("read")).expect("dot_vox");
    let raw = &data.models[0].voxels;
    let model = load_vox_file(Path::new(&path), 0).expect("load");
    let lowest_z = raw.iter().map(|v| v.z).min().expect("voxels");
    let highest_z = raw.iter().map(|v| v.z).max().expect("voxels");
    let (lo, hi) = model.bounds().expect("voxels");
    assert_eq!(lo.y, i32::from(lowest_z));
    assert_eq!(hi.y, i32::from(highest_z));
    let raw_set: BTreeSet<[i32; 3]> = raw.iter().map(|v| [i32::from(v.x), i32::from(v.z), -i32::from(v.y)]).collect();
    let loaded: BTreeSet<[i32; 3]> = model.voxels.iter().map(|(p, _)| p.to_array()).collect();
    assert!(raw_set == loaded, "world = (x, z, −y) of the stored voxels");
}

/// A save that fails leaves the previous file as it was and no temporary
/// file behind; one that succeeds replaces it.
#[test]
fn saving_is_atomic() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("scene.vox");
    save_vox(&path, &Palette::default(), &tripod()).expect("first save");
    let before = std::fs::read(&path).expect("read");

    let bad = [(IVec3::ZERO, 1), (IVec3::ONE, 0)];
    assert!(save_vox(&path, &Palette::default(), &bad).is_err());
    assert_eq!(std::fs::read(&path).expect("read"), before, "a failed save changed the file");

    let single = [(IVec3::new(3, 4, 5), 9)];
    save_vox(&path, &Palette::default(), &single).expect("second save");
    let loaded = load_vox_file(&path, 0).expect("load");
    assert_eq!(loaded.voxels, single.to_vec());

    // Renaming onto a directory fails after the bytes were written.
    let blocked = dir.path().join("blocked.vox");
    std::fs::create_dir(&blocked).expect("mkdir");
    let err = save_vox(&blocked, &Palette::default(), &single).expect_err("target is a directory");
    assert!(err.to_string().contains("blocked.vox"), "{err}");

    let names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "leftover files: {names:?}");
}

#[cfg(unix)]
#[test]
fn saved_files_are_world_readable() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("scene.vox");
    save_vox(&path, &Palette::default(), &tripod()).expect("save");
    let mode = std::fs::metadata(&path).expect("stat").permissions().mode();
    assert_eq!(mode & 0o777, 0o644);
}

/// Loading model by model into the octree gives exactly the voxels, palette
/// and materials of the whole-list load, on every shared model (scene
/// graphs, instancing, overlapping placements, animation frames).
#[test]
fn a_streamed_load_equals_the_whole_list_load() {
    for path in asset_files() {
        let bytes = std::fs::read(&path).unwrap();
        let Ok(model) = load_vox(&bytes, 0) else { continue };
        let reference = octovox::scene::Scene::from_model(&model).unwrap();
        let (streamed, meta) = octovox::io::vox::load_vox_scene(&bytes, 0).unwrap();
        let name = path.display();
        assert_eq!(streamed.voxels(), reference.voxels(), "{name}");
        assert_eq!((streamed.origin(), streamed.drawn().depth()), (reference.origin(), reference.drawn().depth()));
        assert_eq!(streamed.palette, reference.palette, "{name}");
        assert_eq!(
            (meta.models, meta.stored_models, &meta.warnings),
            (model.models, model.stored_models, &model.warnings)
        );
        streamed.drawn().check_invariants().unwrap();
    }
}
