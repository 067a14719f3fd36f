//! `octovox info` on the shared assets, through the real binary.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::Value;

/// `../shared/assets/vox` beside the project root.
fn asset(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox").join(relative)
}

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().expect("run octovox")
}

/// Runs `octovox info --json` on an asset and parses what it prints.
fn info_json(relative: &str, extra: &[&str]) -> Value {
    let path = asset(relative);
    let path = path.to_str().expect("UTF-8 asset path");
    let output = octovox(&[&["info", path, "--json"], extra].concat());
    assert!(output.status.success(), "octovox info {relative} failed: {}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_slice(&output.stdout).expect("info --json prints JSON")
}

fn extent(info: &Value) -> [i64; 3] {
    let axis = |i: usize| info["extent"][i].as_i64().expect("extent is [x, y, z]");
    [axis(0), axis(1), axis(2)]
}

#[test]
fn torus64_matches_the_report() {
    let info = info_json("seed/torus64.vox", &[]);
    assert_eq!(info["voxels"], 41_032);
    assert_eq!(extent(&info), [64, 18, 64]);
    assert_eq!(info["models"], 1);
}

/// Six 79×85×125 models placed by nTRN translations. The report gives the
/// bounds as 158×125×255; the voxels themselves span 254 along z.
#[test]
fn teapot256_places_six_models() {
    let info = info_json("seed/teapot256.vox", &[]);
    assert_eq!(info["voxels"], 101_683);
    assert_eq!(info["models"], 6);
    assert_eq!(extent(&info), [158, 125, 254]);
}

/// 15 models under nested groups; some shapes are placed by several
/// transforms, so 19 placements.
#[test]
fn test_groups_walks_nested_groups() {
    let info = info_json("format/test_groups.vox", &[]);
    assert_eq!(info["voxels"], 1_754);
    assert_eq!(info["models"], 19);
}

/// Issue 47, item 5: `info --json` lists each object with its name path,
/// layer, hidden flag and model: all 19 objects of test_groups.vox are on
/// layer 0, which is why hiding the other seven layers hides nothing.
#[test]
fn json_lists_every_object_with_its_path_layer_and_model() {
    let info = info_json("format/test_groups.vox", &[]);
    let objects = info["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 19);
    for (index, object) in objects.iter().enumerate() {
        assert_eq!(object["index"], index);
        assert_eq!(object["layer"], 0, "{object}");
        assert_eq!(object["hidden"], false);
        assert!(object["model"].as_u64().unwrap() < 15, "{object}");
        assert!(object["bounds"].is_array(), "{object}");
    }
    let paths: Vec<&str> = objects.iter().map(|o| o["path"].as_str().unwrap()).collect();
    assert_eq!((paths[0], paths[15]), ("characters", "text"), "{paths:?}");
    let one = info_json("magicavoxel/chr_knight.vox", &[]);
    assert_eq!(
        one["objects"],
        serde_json::json!([{"index": 0, "path": "", "model": 0, "layer": null,
        "hidden": false, "bounds": [one["min"], one["max"]]}])
    );
}

#[test]
fn axes_version_200_with_groups() {
    let info = info_json("format/axes.vox", &[]);
    assert_eq!(info["voxels"], 12_452);
    assert_eq!(info["models"], 10);
}

#[test]
fn trex_loads_one_animation_frame() {
    let info = info_json("magicavoxel/T-Rex.vox", &[]);
    assert_eq!(info["voxels"], 1_272);
    assert_eq!(info["models"], 1);
    // Frame 2 is the third model of the file (1,287 voxels).
    assert_eq!(info_json("magicavoxel/T-Rex.vox", &["--frame", "2"])["voxels"], 1_287);
}

#[test]
fn json_has_every_documented_key() {
    let info = info_json("format/metal-material.vox", &[]);
    for key in ["voxels", "extent", "min", "max", "models", "materials", "palette_entries"] {
        assert!(info.get(key).is_some(), "missing key {key} in {info}");
    }
    assert_eq!(info["materials"], serde_json::json!({ "metal": 1 }));
    assert_eq!(info["palette_entries"], 1);
    // max − min + 1 = extent on every axis.
    for axis in 0..3 {
        let span = info["max"][axis].as_i64().unwrap_or(0) - info["min"][axis].as_i64().unwrap_or(0);
        assert_eq!(span + 1, extent(&info)[axis]);
    }
}

#[test]
fn human_output_is_aligned_lines() {
    let path = asset("seed/torus64.vox");
    let output = octovox(&["info", path.to_str().expect("UTF-8 asset path")]);
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).expect("UTF-8 output");
    assert!(text.contains("voxels           41032"), "{text}");
    assert!(text.contains("extent           64 x 18 x 64"), "{text}");
}

#[test]
fn not_a_vox_exits_nonzero_with_the_reason() {
    let path = asset("format/not_a.vox");
    let output = octovox(&["info", path.to_str().expect("UTF-8 asset path"), "--json"]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("not a .vox file (missing 'VOX ' magic)"), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
    assert!(output.stdout.is_empty());
}

#[test]
fn missing_file_and_bad_frame_are_errors() {
    let output = octovox(&["info", "/nonexistent/x.vox"]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("cannot read /nonexistent/x.vox"));

    let path = asset("magicavoxel/T-Rex.vox");
    let output = octovox(&["info", path.to_str().expect("UTF-8 asset path"), "--frame", "8"]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("frame 8 requested but file has 8 models"), "stderr: {stderr}");
}

#[test]
fn convert_writes_a_file_that_loads_the_same() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("teapot.vox");
    let input = asset("seed/teapot256.vox");
    let output =
        octovox(&["convert", input.to_str().expect("UTF-8 asset path"), out.to_str().expect("UTF-8 temp path")]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let before = info_json("seed/teapot256.vox", &[]);
    let after = octovox(&["info", out.to_str().expect("UTF-8 temp path"), "--json"]);
    let after: Value = serde_json::from_slice(&after.stdout).expect("JSON");
    for key in ["voxels", "extent", "min", "max", "palette_entries", "materials"] {
        assert_eq!(before[key], after[key], "{key}");
    }
}

/// A MATL with values octovox cannot use as they are (out of range, not a
/// number, an unknown type) loads, clamps them, never yields NaN, and
/// `info` says what it did.
#[test]
fn odd_material_values_are_clamped_and_reported() {
    use octovox::scene::{Material, MaterialKind, Palette};
    let mut palette = Palette::default();
    let mut metal = Material::new(MaterialKind::Metal);
    metal.params.insert("_rough".into(), "nan".into());
    metal.params.insert("_metal".into(), "7".into());
    metal.params.insert("_ri".into(), "1.33".into());
    palette.materials[5] = metal;
    let mut odd = Material::new(MaterialKind::Diffuse);
    odd.params.insert("_flux".into(), "-2".into());
    palette.materials[6] = odd;
    let mut bytes = octovox::io::vox::encode_vox(&palette, &[(glam::IVec3::ZERO, 5), (glam::IVec3::ONE, 6)]).unwrap();
    // An unknown type, written the way MagicaVoxel writes `_blend`.
    let at = bytes.windows(8).position(|w| w == b"_diffuse").unwrap();
    bytes[at..at + 8].copy_from_slice(b"_blendxx");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.vox");
    std::fs::write(&path, &bytes).unwrap();

    let model = octovox::io::vox::load_vox_file(&path, 0).unwrap();
    let metal = model.palette.material(5);
    assert_eq!((metal.roughness(), metal.metalness(), metal.ior()), (0.1, 1.0, 1.33));
    assert_eq!(model.palette.material(6).kind, MaterialKind::Diffuse);
    assert_eq!(model.palette.material(6).flux(), 0.0);
    let out =
        std::process::Command::new(env!("CARGO_BIN_EXE_octovox")).args(["info", "--json"]).arg(&path).output().unwrap();
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let warnings = info["warnings"].to_string();
    for expected in [
        "material 5: _rough 'nan' is not a number, read as 0.1",
        "material 5: _metal '7' is outside 0..=1, read as 1",
        "material 6: type '_blendxx' is not one octovox renders; treated as diffuse",
        "material 6: _flux '-2' is outside 0..=4, read as 0",
    ] {
        assert!(warnings.contains(expected), "missing '{expected}' in {warnings}");
    }
}
