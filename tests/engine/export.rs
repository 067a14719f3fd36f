//! `octovox export`: greedy meshes that are small, closed and outward, read
//! back from the files themselves (not through the code that wrote them).

use crate::common;

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

pub(crate) fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().unwrap()
}

pub(crate) fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// Positions and triangles (0-based) of an .obj's `v` and `f` lines.
pub(crate) fn read_obj(path: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"v") => positions.push([1, 2, 3].map(|i| words[i].parse().unwrap())),
            Some(&"f") => {
                assert_eq!(words.len(), 4, "not a triangle: {line}");
                triangles.push([1, 2, 3].map(|i| words[i].parse::<usize>().unwrap() - 1));
            }
            _ => {}
        }
    }
    (positions, triangles)
}

/// Positions, colours and triangles of a binary little-endian .ply.
pub(crate) struct Ply {
    pub positions: Vec<[f64; 3]>,
    pub colors: Vec<[u8; 3]>,
    pub triangles: Vec<[usize; 3]>,
    /// Each face's `object` property, when the header declares one.
    pub objects: Vec<u32>,
}

pub(crate) fn read_ply(path: &Path) -> Ply {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let count = |element: &str| -> usize {
        let line = header.lines().find(|l| l.starts_with(&format!("element {element} "))).unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let mut at = end;
    let mut take = |n: usize| {
        let slice = &bytes[at..at + n];
        at += n;
        slice.to_vec()
    };
    let f32_of = |b: Vec<u8>| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let mut positions = Vec::new();
    let mut colors = Vec::new();
    for _ in 0..nv {
        positions.push([f32_of(take(4)), f32_of(take(4)), f32_of(take(4))]);
        let c = take(3);
        colors.push([c[0], c[1], c[2]]);
    }
    let with_objects = header.contains("property list uchar uint vertex_indices\nproperty uint object\n");
    let mut triangles = Vec::new();
    let mut objects = Vec::new();
    for _ in 0..nf {
        assert_eq!(take(1)[0], 3);
        let index = |b: Vec<u8>| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        triangles.push([index(take(4)), index(take(4)), index(take(4))]);
        if with_objects {
            objects.push(index(take(4)) as u32);
        }
    }
    assert_eq!(at, bytes.len(), "trailing bytes");
    Ply { positions, colors, triangles, objects }
}

/// A .glb read back: its JSON, and the positions and triangles of all its
/// primitives together.
pub(crate) struct Glb {
    pub json: serde_json::Value,
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[usize; 3]>,
    /// Each mesh's triangles (indices into `positions`), in mesh order.
    pub mesh_triangles: Vec<Vec<[usize; 3]>>,
    pub bin: Vec<u8>,
}

impl Glb {
    /// The floats of accessor `index` (tightly packed), component by component.
    pub fn floats(&self, index: usize) -> Vec<f64> {
        let accessor = &self.json["accessors"][index];
        let view = &self.json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(accessor["componentType"], 5126, "floats");
        let width = match accessor["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            other => panic!("accessor type {other}"),
        };
        let start = (view["byteOffset"].as_u64().unwrap_or(0) + accessor["byteOffset"].as_u64().unwrap_or(0)) as usize;
        let count = accessor["count"].as_u64().unwrap() as usize * width;
        let bytes = &self.bin[start..start + 4 * count];
        bytes.chunks_exact(4).map(|w| f64::from(f32::from_le_bytes(w.try_into().unwrap()))).collect()
    }
}

pub(crate) fn read_glb(path: &Path) -> Glb {
    let bytes = std::fs::read(path).unwrap();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!((&bytes[..4], word(4), word(8)), (&b"glTF"[..], 2, bytes.len()), "GLB header");
    let json_length = word(12);
    assert_eq!((&bytes[16..20], json_length % 4), (&b"JSON"[..], 0), "JSON chunk");
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    let bin_at = 20 + json_length;
    let bin_length = word(bin_at);
    assert_eq!((&bytes[bin_at + 4..bin_at + 8], bin_length % 4), (&b"BIN\0"[..], 0), "BIN chunk");
    assert_eq!(bin_at + 8 + bin_length, bytes.len(), "trailing bytes");
    let bin = &bytes[bin_at + 8..];
    assert!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize <= bin.len());
    // An accessor's numbers, tightly packed 4-byte floats or unsigned ints.
    let accessor = |index: &serde_json::Value| -> Vec<f64> {
        let accessor = &json["accessors"][index.as_u64().unwrap() as usize];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let components = match accessor["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC3" => 3,
            other => panic!("accessor type {other}"),
        };
        assert!(view["byteStride"].is_null() || view["byteStride"] == 4 * components, "{view}");
        let start = (view["byteOffset"].as_u64().unwrap_or(0) + accessor["byteOffset"].as_u64().unwrap_or(0)) as usize;
        let count = accessor["count"].as_u64().unwrap() as usize * components;
        let words = bin[start..start + 4 * count].chunks_exact(4).map(|w| w.try_into().unwrap());
        match accessor["componentType"].as_u64().unwrap() {
            5126 => words.map(|w| f64::from(f32::from_le_bytes(w))).collect(),
            5125 => words.map(|w| f64::from(u32::from_le_bytes(w))).collect(),
            other => panic!("component type {other}"),
        }
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut mesh_triangles = Vec::new();
    for mesh in json["meshes"].as_array().unwrap() {
        let first = triangles.len();
        for primitive in mesh["primitives"].as_array().unwrap() {
            assert_eq!(primitive["mode"], 4, "triangles");
            let base = positions.len();
            positions
                .extend(accessor(&primitive["attributes"]["POSITION"]).chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
            let indices = accessor(&primitive["indices"]);
            triangles.extend(indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| base + t[k] as usize)));
        }
        mesh_triangles.push(triangles[first..].to_vec());
    }
    let bin = bin.to_vec();
    Glb { json, positions, triangles, mesh_triangles, bin }
}

/// Runs the Khronos glTF validator (`tests/gltf/validate.js`) on `files`
/// and prints its report; fails on any error or warning, and when Node.js
/// or the validator is missing.
/// `octovox export` of the .vox `bytes` to a .glb in a new folder, which
/// the Khronos validator passes; what the .glb holds.
pub(crate) fn exported_glb(bytes: &[u8]) -> Glb {
    let dir = tempfile::tempdir().unwrap();
    let (vox, glb) = (dir.path().join("scene.vox"), dir.path().join("scene.glb"));
    std::fs::write(&vox, bytes).unwrap();
    let out = octovox(&["export", vox.to_str().unwrap(), "-o", glb.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    validate_gltf(&[&glb]);
    read_glb(&glb)
}

pub(crate) fn validate_gltf(files: &[&Path]) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf/validate.js");
    let out = Command::new("node").arg(script).args(files).output().unwrap_or_else(|err| {
        panic!(
            "cannot run node ({err}); the glTF test needs Node.js and the Khronos validator: \
             apt-get install -y nodejs npm && npm ci --prefix tests/gltf"
        )
    });
    let report = text(&out);
    println!("{report}");
    assert!(out.status.success(), "glTF validation failed ({}):\n{report}", out.status);
}

/// A palette byte as the linear value of a glTF colour factor.
fn linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Every directed edge between two positions has as many reverse edges
/// (closed and consistently oriented); returns the signed volume.
pub(crate) fn closed_volume(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> f64 {
    let key = |i: usize| positions[i].map(|c| (c * 2.0).round() as i64);
    let mut edges: HashMap<([i64; 3], [i64; 3]), i64> = HashMap::new();
    let mut volume = 0.0;
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            *edges.entry((a, b)).or_default() += 1;
            *edges.entry((b, a)).or_default() -= 1;
        }
        let [a, b, c] = t.map(|i| positions[i]);
        let cross = [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]];
        volume += (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0;
    }
    let open: Vec<_> = edges.iter().filter(|(_, n)| **n != 0).take(3).collect();
    assert!(open.is_empty(), "open or flipped edges, e.g. {open:?}");
    volume
}

/// The test sculpture saved as a .vox in `dir`.
fn sculpture_file(dir: &Path) -> (std::path::PathBuf, u64) {
    let tree = common::sculpture();
    let path = dir.join("sculpture.vox");
    let scene = octovox::scene::Scene::new(Default::default(), tree);
    octovox::io::save_scene(&path, &scene, Default::default()).unwrap();
    (path, scene.solid_voxels())
}

#[test]
fn a_box_is_twelve_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("box.ovr");
    std::fs::write(&script, "new\ncolor 7\nbrush box 5 3 4\nplace 0 0 0\nsave box.vox\n").unwrap();
    assert!(octovox(&["replay", "--cpu", script.to_str().unwrap()]).status.success());
    let obj = dir.path().join("box.obj");
    let out = octovox(&["export", dir.path().join("box.vox").to_str().unwrap(), "-o", obj.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let (positions, triangles) = read_obj(&obj);
    assert_eq!((positions.len(), triangles.len()), (8, 12));
    assert_eq!(closed_volume(&positions, &triangles).round() as i64, 5 * 3 * 4);
    let mtl = std::fs::read_to_string(dir.path().join("box.mtl")).unwrap();
    assert!(mtl.contains("newmtl palette_7"), "{mtl}");
    let glb = dir.path().join("box.glb");
    let out = octovox(&["export", dir.path().join("box.vox").to_str().unwrap(), "-o", glb.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let Glb { json, positions, triangles, .. } = read_glb(&glb);
    // A corner per face that meets there: each copy has its face's normal.
    assert_eq!((positions.len(), triangles.len()), (24, 12));
    assert_eq!(closed_volume(&positions, &triangles).round() as i64, 5 * 3 * 4);
    assert_eq!(json["materials"].as_array().unwrap().len(), 1);
    assert_eq!(json["materials"][0]["name"], "palette_7");
}

#[test]
fn obj_ply_and_glb_exports_are_closed_outward_and_hold_the_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let (vox, voxels) = sculpture_file(dir.path());
    let (obj, ply, glb) = (dir.path().join("s.obj"), dir.path().join("s.ply"), dir.path().join("s.glb"));
    for (out, scale) in [(&obj, "1"), (&ply, "0.5"), (&glb, "2")] {
        let done = octovox(&["export", vox.to_str().unwrap(), "-o", out.to_str().unwrap(), "--scale", scale]);
        assert!(done.status.success(), "{}", text(&done));
    }
    let (positions, triangles) = read_obj(&obj);
    assert_eq!(closed_volume(&positions, &triangles).round() as u64, voxels);
    let Ply { positions, colors, triangles, .. } = read_ply(&ply);
    // Half a unit per voxel: an eighth of the volume.
    assert_eq!((closed_volume(&positions, &triangles) * 8.0).round() as u64, voxels);
    let palette = octovox::scene::Palette::default();
    let used: std::collections::BTreeSet<[u8; 3]> = colors.into_iter().collect();
    for index in [3u8, 17, 80, 200, 255] {
        let c = palette.color(index);
        assert!(used.contains(&[c[0], c[1], c[2]]), "colour of palette index {index} missing");
    }
    let Glb { json, positions, triangles, .. } = read_glb(&glb);
    // Two units per voxel: eight times the volume.
    assert_eq!((closed_volume(&positions, &triangles) / 8.0).round() as u64, voxels);
    // One diffuse material per palette index, its colour made linear.
    let materials = json["materials"].as_array().unwrap();
    assert_eq!(materials.len(), json["meshes"][0]["primitives"].as_array().unwrap().len());
    for index in [3u8, 17, 80, 200, 255] {
        let material = materials.iter().find(|m| m["name"] == format!("palette_{index}")).unwrap();
        let pbr = &material["pbrMetallicRoughness"];
        let factor: Vec<f64> = pbr["baseColorFactor"].as_array().unwrap().iter().map(|c| c.as_f64().unwrap()).collect();
        let c = palette.color(index);
        for (k, expected) in [linear(c[0]), linear(c[1]), linear(c[2]), 1.0].into_iter().enumerate() {
            assert!((factor[k] - expected).abs() < 1e-6, "palette_{index}: {factor:?}");
        }
        assert_eq!((pbr["metallicFactor"].as_f64(), pbr["roughnessFactor"].as_f64()), (Some(0.0), Some(1.0)));
    }
    validate_gltf(&[&glb]);
}

#[test]
fn glb_materials_follow_matl_and_pass_the_khronos_validator() {
    use octovox::scene::MaterialKind;
    let dir = tempfile::tempdir().unwrap();
    let scene = octovox::scene::showroom::showroom_scene();
    let vox = dir.path().join("showroom.vox");
    octovox::io::save_scene(&vox, &scene, Default::default()).unwrap();
    let glb = dir.path().join("showroom.glb");
    let out = octovox(&["export", vox.to_str().unwrap(), "-o", glb.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let Glb { json, positions, triangles, .. } = read_glb(&glb);
    assert_eq!(closed_volume(&positions, &triangles).round() as u64, scene.solid_voxels());
    let close = |value: &serde_json::Value, expected: f32| {
        value.as_f64().is_some_and(|v| (v - f64::from(expected)).abs() < 1e-6)
    };
    let mut kinds = std::collections::BTreeSet::new();
    for material in json["materials"].as_array().unwrap() {
        let index: u8 = material["name"].as_str().unwrap().strip_prefix("palette_").unwrap().parse().unwrap();
        let matl = scene.palette.material(index);
        let (pbr, extensions) = (&material["pbrMetallicRoughness"], &material["extensions"]);
        match matl.kind {
            MaterialKind::Metal => {
                assert!(close(&pbr["metallicFactor"], matl.metalness()), "{material}");
                assert!(close(&pbr["roughnessFactor"], matl.roughness()), "{material}");
            }
            MaterialKind::Glass => {
                let transmission = &extensions["KHR_materials_transmission"]["transmissionFactor"];
                assert!(close(transmission, matl.transparency()), "{material}");
                assert!(close(&extensions["KHR_materials_ior"]["ior"], matl.ior()), "{material}");
                assert!(material["alphaMode"].is_null() || material["alphaMode"] == "OPAQUE", "{material}");
            }
            MaterialKind::Emit => {
                // The path tracer's radiance: _emit · 2^_flux · EMIT_SCALE.
                let strength = matl.emission() * matl.flux().exp2() * octovox::trace::path::materials::EMIT_SCALE;
                assert!(strength > 1.0);
                let factor = &material["emissiveFactor"];
                let c = scene.palette.color(index);
                assert!((0..3).all(|k| close(&factor[k], linear(c[k]) as f32)), "{material}");
                assert!(close(&extensions["KHR_materials_emissive_strength"]["emissiveStrength"], strength));
            }
            MaterialKind::Diffuse | MaterialKind::Media => {
                assert!(extensions.is_null() && material["emissiveFactor"].is_null(), "{material}");
            }
        }
        kinds.insert(matl.kind);
    }
    assert!([MaterialKind::Metal, MaterialKind::Glass, MaterialKind::Emit].iter().all(|k| kinds.contains(k)));
    let used: Vec<&str> = json["extensionsUsed"].as_array().unwrap().iter().map(|e| e.as_str().unwrap()).collect();
    assert_eq!(
        used,
        ["KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_transmission"],
        "sorted, each once"
    );
    assert!(json["extensionsRequired"].is_null(), "a viewer without them still shows the colours");
    // An empty scene is a valid file too: a node without a mesh.
    let empty = dir.path().join("empty.vox");
    let nothing = octovox::scene::Scene::new(Default::default(), Default::default());
    octovox::io::save_scene(&empty, &nothing, Default::default()).unwrap();
    let empty_glb = dir.path().join("empty.glb");
    let out = octovox(&["export", empty.to_str().unwrap(), "-o", empty_glb.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    validate_gltf(&[&glb, &empty_glb]);
}

#[test]
fn greedy_meshing_beats_one_quad_per_face() {
    let tree = common::sculpture();
    let mesh = octovox::io::export::greedy::mesh(&tree);
    let naive = mesh.exposed_faces * 2;
    assert!((mesh.triangles.len() as u64) * 2 < naive, "{} triangles, naive {naive}", mesh.triangles.len());
}

#[test]
fn bad_export_targets_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (vox, _) = sculpture_file(dir.path());
    let v = vox.to_str().unwrap();
    let refused = |args: &[&str], needle: &str| {
        let out = octovox(args);
        assert!(!out.status.success() && text(&out).contains(needle), "{args:?}: {}", text(&out));
    };
    refused(&["export", v, "-o", v], "writes .obj, .ply or .glb files");
    refused(&["export", v, "-o", dir.path().join("x.stl").to_str().unwrap()], "writes .obj, .ply or .glb files");
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    refused(&["export", v, "-o", folder.to_str().unwrap(), "--force"], "is a folder");
    for name in ["mine.ply", "mine.glb"] {
        let existing = dir.path().join(name);
        std::fs::write(&existing, b"my mesh").unwrap();
        refused(&["export", v, "-o", existing.to_str().unwrap()], "already exists");
        assert_eq!(std::fs::read(&existing).unwrap(), b"my mesh");
    }
    let mtl = dir.path().join("other.mtl");
    std::fs::write(&mtl, b"my materials").unwrap();
    refused(&["export", v, "-o", dir.path().join("other.obj").to_str().unwrap()], "other.mtl already exists");
}

/// Issue 24, item 9: a scale that makes a vertex coordinate infinite or
/// denormal (or zero) is refused, naming the scale and the range this scene
/// allows, and nothing is written; before, `--scale 3e38` wrote `inf`
/// vertices and `--scale 1e-45` collapsed them, both with exit 0.
#[test]
fn scales_past_what_a_float_holds_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("box.ovr");
    std::fs::write(&script, "new\ncolor 7\nbrush box 5 3 4\nplace 0 0 0\nsave box.vox\n").unwrap();
    assert!(octovox(&["replay", "--cpu", script.to_str().unwrap()]).status.success());
    let vox = dir.path().join("box.vox");
    for name in ["big.obj", "big.ply", "big.glb"] {
        let out_path = dir.path().join(name);
        for scale in ["3e38", "1e-45", "1e-39"] {
            let out = octovox(&["export", vox.to_str().unwrap(), "-o", out_path.to_str().unwrap(), "--scale", scale]);
            assert!(!out.status.success(), "{name} --scale {scale}: {}", text(&out));
            assert!(text(&out).contains(&format!("--scale {scale} puts")), "{}", text(&out));
            assert!(text(&out).contains("this scene allows --scale 2.3509887e-38 to "), "{}", text(&out));
            assert!(!out_path.exists() && !dir.path().join("big.mtl").exists(), "{name}: something was written");
        }
    }
    // The ends of the range work, and every coordinate is finite.
    for scale in ["1e30", "3e-38"] {
        let obj = dir.path().join(format!("ok{scale}.obj"));
        let out = octovox(&["export", vox.to_str().unwrap(), "-o", obj.to_str().unwrap(), "--scale", scale]);
        assert!(out.status.success(), "{}", text(&out));
        let (positions, _) = read_obj(&obj);
        assert!(positions.iter().flatten().all(|c| c.is_finite()), "{positions:?}");
        let nonzero: Vec<f64> = positions.iter().flatten().copied().filter(|c| *c != 0.0).collect();
        assert!(nonzero.iter().all(|c| (*c as f32).is_normal()), "{positions:?}");
        assert!(!nonzero.is_empty());
    }
}

/// Issue 24, item 19: when the .obj cannot be written after its .mtl was,
/// the export removes the .mtl it created, so the rerun is not refused; a
/// file that was there before is never removed.
#[test]
fn a_failed_export_leaves_no_partial_files() {
    let dir = tempfile::tempdir().unwrap();
    let (vox, _) = sculpture_file(dir.path());
    let v = vox.to_str().unwrap();
    // The .obj refused by the atomic writer: a link to a device, a folder.
    let full = dir.path().join("full.obj");
    std::os::unix::fs::symlink("/dev/full", &full).unwrap();
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    for (obj, needle) in [(&full, "not a regular file"), (&folder, "is a folder")] {
        let out = octovox(&["export", v, "-o", obj.to_str().unwrap(), "--force"]);
        assert!(!out.status.success() && text(&out).contains(needle), "{}", text(&out));
        assert!(!obj.with_extension("mtl").exists(), "{}: the .mtl was left behind", obj.display());
    }
    assert!(std::fs::symlink_metadata(&full).unwrap().file_type().is_symlink(), "the link stays");
    assert!(folder.is_dir(), "the folder stays");
    // The rerun, once the cause is gone, is not refused by a stale .mtl.
    std::fs::remove_file(&full).unwrap();
    let out = octovox(&["export", v, "-o", full.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(full.is_file() && full.with_extension("mtl").is_file());
    // An .mtl that existed before the failed export is not removed.
    let mine = dir.path().join("mine.obj");
    std::os::unix::fs::symlink("/dev/full", &mine).unwrap();
    std::fs::write(mine.with_extension("mtl"), b"my materials").unwrap();
    let out = octovox(&["export", v, "-o", mine.to_str().unwrap(), "--force"]);
    assert!(!out.status.success(), "{}", text(&out));
    assert!(mine.with_extension("mtl").is_file(), "an existing .mtl was removed");
}
