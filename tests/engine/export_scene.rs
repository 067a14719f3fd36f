//! `octovox export` of a scene of objects: a glTF node per visible object
//! under nodes for its groups, the placements of one model sharing its
//! mesh; an `o` per object in .obj and an `object` face property in .ply.
//! The files are read back by readers in the test, and every face is
//! checked against the voxels octovox's flat loader composes.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use super::export::{Glb, Ply, closed_volume, octovox, read_glb, read_ply, text, validate_gltf};
use super::vox_scene::{assets, written_scene};

/// The world cells the flat loader composes from the visible objects.
fn solid_cells(bytes: &[u8]) -> HashSet<[i64; 3]> {
    let scene = octovox::io::vox::load_vox(bytes, 0).unwrap();
    scene.voxels.iter().map(|(p, _)| [p.x, p.y, p.z].map(i64::from)).collect()
}

/// Every triangle lies on a face of a solid cell and faces out of it: the
/// point a quarter voxel behind its centroid is in a solid cell.
pub(crate) fn faces_lie_on_solid_cells(
    label: &str,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    solid: &HashSet<[i64; 3]>,
) {
    assert!(!triangles.is_empty(), "{label}: no triangles");
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i]);
        let (u, v) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
        let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        let axis = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).unwrap();
        let mut inside = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
        inside[axis] -= 0.25 * n[axis].signum();
        let cell = inside.map(|c| c.floor() as i64);
        assert!(solid.contains(&cell), "{label}: a face at {inside:?} has no solid cell {cell:?} behind it");
    }
}

/// An `o` of an .obj: its name and triangles (0-based into the file's positions).
type ObjObject = (String, Vec<[usize; 3]>);

/// The .obj's positions and its objects in file order.
fn read_obj_objects(path: &Path) -> (Vec<[f64; 3]>, Vec<ObjObject>) {
    let mut positions = Vec::new();
    let mut objects: Vec<ObjObject> = Vec::new();
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first() {
            Some(&"o") => objects.push((line[2..].to_owned(), Vec::new())),
            Some(&"v") => positions.push([1, 2, 3].map(|i| words[i].parse().unwrap())),
            Some(&"f") => {
                let triangle = [1, 2, 3].map(|i| words[i].parse::<usize>().unwrap() - 1);
                objects.last_mut().expect("a face before any `o`").1.push(triangle);
            }
            _ => {}
        }
    }
    (positions, objects)
}

/// Each node's matrix (column-major, the identity when absent) times its
/// parents', for the nodes with a mesh: (node name, mesh, world matrix).
pub(crate) fn placed_meshes(json: &serde_json::Value) -> Vec<(String, usize, [f64; 16])> {
    let nodes = json["nodes"].as_array().unwrap();
    let matrix = |node: &serde_json::Value| -> [f64; 16] {
        match node["matrix"].as_array() {
            Some(m) => std::array::from_fn(|i| m[i].as_f64().unwrap()),
            None => trs_matrix(node),
        }
    };
    let times = |a: &[f64; 16], b: &[f64; 16]| -> [f64; 16] {
        std::array::from_fn(|i| (0..4).map(|k| a[k * 4 + i % 4] * b[(i / 4) * 4 + k]).sum())
    };
    let mut out = Vec::new();
    let mut stack: Vec<(usize, [f64; 16])> = json["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| (n.as_u64().unwrap() as usize, std::array::from_fn(|i| if i % 5 == 0 { 1.0 } else { 0.0 })))
        .collect();
    while let Some((index, parent)) = stack.pop() {
        let node = &nodes[index];
        let world = times(&parent, &matrix(node));
        if let Some(mesh) = node["mesh"].as_u64() {
            out.push((node["name"].as_str().unwrap().to_owned(), mesh as usize, world));
        }
        for child in node["children"].as_array().into_iter().flatten() {
            stack.push((child.as_u64().unwrap() as usize, world));
        }
    }
    out
}

/// A node's translation, rotation and scale (a moving object's) as the
/// column-major matrix T · R · S; the identity for a node without them.
fn trs_matrix(node: &serde_json::Value) -> [f64; 16] {
    let read = |key: &str, default: &[f64]| -> Vec<f64> {
        node[key].as_array().map_or(default.to_vec(), |a| a.iter().map(|v| v.as_f64().unwrap()).collect())
    };
    let (t, q, s) = (read("translation", &[0.0; 3]), read("rotation", &[0.0, 0.0, 0.0, 1.0]), read("scale", &[1.0; 3]));
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    // The rotation matrix of a unit quaternion, row by row.
    let r = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ];
    let mut m = [0.0; 16];
    for column in 0..3 {
        for row in 0..3 {
            m[column * 4 + row] = r[row][column] * s[column];
        }
        m[12 + column] = t[column];
    }
    m[15] = 1.0;
    m
}

pub(crate) fn apply(m: &[f64; 16], p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
}

fn determinant(m: &[f64; 16]) -> f64 {
    m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2])
}

/// Exports `vox` to .glb, .obj and .ply in `dir`.
fn export_all(dir: &Path, vox: &Path) -> [std::path::PathBuf; 3] {
    let outputs = ["scene.glb", "scene.obj", "scene.ply"].map(|name| dir.join(name));
    for out in &outputs {
        let done = octovox(&["export", vox.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert!(done.status.success(), "{}", text(&done));
    }
    outputs
}

/// Sixty objects of three models turned every way, some hidden and one
/// layer hidden: each visible object is a node of its own name whose mesh,
/// placed by the node's matrix, lies on the composed voxels with the
/// model's volume; references share one mesh; .obj and .ply agree.
#[test]
fn a_scene_exports_an_object_per_visible_object_and_a_mesh_per_model() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = written_scene(60);
    let vox = dir.path().join("forest.vox");
    std::fs::write(&vox, &bytes).unwrap();
    let solid = solid_cells(&bytes);
    // Objects k on layer k % 3 (layer 2 hidden) of model k % 3, hidden when k % 11 == 5.
    let visible: Vec<usize> = (0..60).filter(|k| k % 3 != 2 && k % 11 != 5).collect();
    let model_voxels = |k: usize| [26.0, 17.0][k % 3];
    let [glb, obj, ply] = export_all(dir.path(), &vox);

    validate_gltf(&[&glb]);
    let Glb { json, positions, mesh_triangles, .. } = read_glb(&glb);
    assert_eq!(json["meshes"].as_array().unwrap().len(), 2, "two models are shown: two meshes");
    let placed = placed_meshes(&json);
    let names: BTreeMap<String, usize> = placed.iter().map(|(name, mesh, _)| (name.clone(), *mesh)).collect();
    let expected: BTreeMap<String, usize> = visible.iter().map(|k| (format!("tree {k}"), k % 3)).collect();
    assert_eq!(names.keys().collect::<Vec<_>>(), expected.keys().collect::<Vec<_>>(), "the visible objects");
    let mut mirrored = 0;
    for (name, mesh, world) in &placed {
        let k: usize = name["tree ".len()..].parse().unwrap();
        let moved: Vec<[f64; 3]> = positions.iter().map(|p| apply(world, *p)).collect();
        let det = determinant(world);
        mirrored += usize::from(det < 0.0);
        // glTF winds a mirrored node's triangles the other way itself.
        let triangles: Vec<[usize; 3]> =
            mesh_triangles[*mesh].iter().map(|&[a, b, c]| if det < 0.0 { [a, c, b] } else { [a, b, c] }).collect();
        assert_eq!(closed_volume(&moved, &triangles).round(), model_voxels(k), "{name}");
        faces_lie_on_solid_cells(name, &moved, &triangles, &solid);
    }
    assert!(mirrored > 5, "the 48 rotations include mirrors; {mirrored} were");

    let (positions, objects) = read_obj_objects(&obj);
    let names: Vec<&str> = objects.iter().map(|(name, _)| name.as_str()).collect();
    let expected: Vec<String> = visible.iter().map(|k| format!("tree {k}")).collect();
    assert_eq!(names, expected, "one `o` per visible object, in walk order");
    for ((name, triangles), k) in objects.iter().zip(&visible) {
        assert_eq!(closed_volume(&positions, triangles).round(), model_voxels(*k), "{name}");
        faces_lie_on_solid_cells(name, &positions, triangles, &solid);
    }

    let header = String::from_utf8_lossy(&std::fs::read(&ply).unwrap()[..4000]).into_owned();
    let Ply { positions, triangles, objects, .. } = read_ply(&ply);
    for (i, k) in visible.iter().enumerate() {
        assert!(header.contains(&format!("comment object {i} tree {k}\n")), "object {i} in\n{header}");
        let mine: Vec<[usize; 3]> =
            triangles.iter().zip(&objects).filter(|(_, o)| **o as usize == i).map(|(t, _)| *t).collect();
        assert_eq!(closed_volume(&positions, &mine).round(), model_voxels(*k), "tree {k}");
        faces_lie_on_solid_cells(&format!("tree {k}"), &positions, &mine, &solid);
    }
}

/// MagicaVoxel's test_groups.vox: its groups are nodes holding their
/// objects, and its references share their model's mesh.
#[test]
fn groups_become_glb_nodes_and_references_share_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let vox = assets().join("format/test_groups.vox");
    let solid = solid_cells(&std::fs::read(&vox).unwrap());
    let [glb, obj, _] = export_all(dir.path(), &vox);
    validate_gltf(&[&glb]);
    let Glb { json, positions, mesh_triangles, .. } = read_glb(&glb);
    let nodes = json["nodes"].as_array().unwrap();
    let children = |name: &str| {
        let group = nodes.iter().find(|n| n["name"] == name).unwrap_or_else(|| panic!("no node {name}"));
        group["children"].as_array().unwrap().len()
    };
    assert_eq!((children("characters"), children("text")), (4, 15));
    assert_eq!(json["scenes"][0]["nodes"].as_array().unwrap().len(), 2, "the two groups are the roots");
    // 19 objects of 15 models: one mesh per model.
    assert_eq!(json["meshes"].as_array().unwrap().len(), 15);
    let placed = placed_meshes(&json);
    assert_eq!(placed.len(), 19);
    for (name, mesh, world) in &placed {
        let moved: Vec<[f64; 3]> = positions.iter().map(|p| apply(world, *p)).collect();
        faces_lie_on_solid_cells(name, &moved, &mesh_triangles[*mesh], &solid);
    }
    let (_, objects) = read_obj_objects(&obj);
    let names: Vec<&str> = objects.iter().map(|(name, _)| name.as_str()).collect();
    assert_eq!(names[..2], ["characters/object 0", "characters/object 1"]);
    assert_eq!(names[18], "text/object 18");
}

/// A scene whose objects are all hidden exports a valid, empty .glb: one
/// node without a mesh (glTF allows no empty scene).
#[test]
fn a_scene_with_every_object_hidden_exports_a_valid_empty_glb() {
    let dir = tempfile::tempdir().unwrap();
    let source = assets().join("format/test_groups.vox");
    let mut script = format!("load {}\n", source.display());
    for i in 0..19 {
        script.push_str(&format!("object {i}\nobject hide\n"));
    }
    script.push_str("save hidden.vox\n");
    let path = dir.path().join("hide.ovr");
    std::fs::write(&path, script).unwrap();
    let ran = octovox(&["replay", "--cpu", path.to_str().unwrap()]);
    assert!(ran.status.success(), "{}", text(&ran));
    let glb = dir.path().join("hidden.glb");
    let done = octovox(&["export", dir.path().join("hidden.vox").to_str().unwrap(), "-o", glb.to_str().unwrap()]);
    assert!(done.status.success(), "{}", text(&done));
    validate_gltf(&[&glb]);
    let bytes = std::fs::read(&glb).unwrap();
    let json_length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    assert_eq!(json["nodes"].as_array().unwrap().len(), 1);
    assert!(json["meshes"].is_null());
}
