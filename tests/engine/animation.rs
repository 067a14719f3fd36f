//! Scenes that move (issue 49, item 1): what octovox draws at a frame is
//! what an independent composition in this test puts there. The test
//! reads the files with `dot_vox`, samples the keys as `ogt_vox` does
//! (written out again here: sorted keys, `_loop`, translations in f32
//! rounded toward zero, rotations and models held) and places every voxel
//! by its centre through the chain of transforms in f64. Load → save keeps
//! every key, range and loop flag, compared through `dot_vox` and the raw
//! chunks.

use std::collections::BTreeMap;

use dot_vox::{DotVoxData, Frame, Layer, SceneNode, ShapeModel};
use glam::IVec3;
use octovox::editor::Editor;

use super::vox_scene::{append_chunks, assets, dict, kept_chunks, load, model, raw_chunks, run, saved};
use crate::common::written::herd;

type Cells = BTreeMap<(i32, i32, i32), u8>;
/// A transform as the test applies it: rotation matrix, translation.
type Placing = ([[f64; 3]; 3], [f64; 3]);

/// A key's frame (`_f`, 0 where missing).
fn frame_of(attributes: &dot_vox::Dict) -> u32 {
    attributes.get("_f").map_or(0, |f| f.parse().unwrap())
}

/// `frame` as a node with keys at `frames` (sorted) shows it: the index
/// into `frames` of the earlier key, and the later one with how far along.
fn sample(frames: &[u32], looping: bool, frame: u32) -> (usize, Option<(usize, f32)>) {
    let (first, last) = (frames[0], *frames.last().unwrap());
    let period = u64::from(last - first) + 1;
    let frame = match (looping, frame >= first) {
        (false, _) => frame,
        (true, true) => (u64::from(first) + u64::from(frame - first) % period) as u32,
        (true, false) => (u64::from(last) - u64::from(first - frame - 1) % period) as u32,
    };
    if frame <= first {
        return (0, None);
    }
    if frame >= last {
        return (frames.len() - 1, None);
    }
    let k = frames.iter().rposition(|&f| f <= frame).unwrap();
    (k, Some((k + 1, (frame - frames[k]) as f32 / (frames[k + 1] - frames[k]) as f32)))
}

/// A rotation byte as a matrix: row `i` has a ±1 in the column its two
/// bits (rows 0 and 1) or the one left (row 2) name, negative where bit
/// 4 + i is set.
fn rotation(byte: u8) -> [[f64; 3]; 3] {
    let (a, b) = ((byte & 3) as usize, ((byte >> 2) & 3) as usize);
    let mut m = [[0.0; 3]; 3];
    for (row, column) in [a, b, 3 - a - b].into_iter().enumerate() {
        m[row][column] = if byte & (1 << (4 + row)) != 0 { -1.0 } else { 1.0 };
    }
    m
}

/// A transform node's transform at `frame`: rotation matrix and translation.
fn transform_at(node: &SceneNode, frame: u32) -> Placing {
    let SceneNode::Transform { attributes, frames, .. } = node else { panic!("not a transform") };
    if frames.is_empty() {
        return (rotation(4), [0.0; 3]);
    }
    let mut keys: Vec<&Frame> = frames.iter().collect();
    keys.sort_by_key(|k| frame_of(&k.attributes));
    let times: Vec<u32> = keys.iter().map(|k| frame_of(&k.attributes)).collect();
    let looping = attributes.get("_loop").is_some_and(|l| l == "1");
    let translation = |k: usize| -> [i32; 3] {
        let t = keys[k].attributes.get("_t").map_or("0 0 0".to_owned(), Clone::clone);
        let v: Vec<i32> = t.split_whitespace().map(|p| p.parse().unwrap()).collect();
        [v[0], v[1], v[2]]
    };
    let (from, next) = sample(&times, looping, frame);
    let r = keys[from].attributes.get("_r").map_or(4, |r| r.parse().unwrap());
    let mut t = translation(from).map(f64::from);
    if let Some((to, s)) = next {
        let (a, b) = (translation(from), translation(to));
        t = [0, 1, 2].map(|i| f64::from((b[i] as f32 * s + a[i] as f32 * (1.0 - s)) as i32));
    }
    (rotation(r), t)
}

/// The model a shape shows at `frame`.
fn model_at(node: &SceneNode, frame: u32) -> usize {
    let SceneNode::Shape { attributes, models } = node else { panic!("not a shape") };
    let mut keys: Vec<&ShapeModel> = models.iter().collect();
    keys.sort_by_key(|m| frame_of(&m.attributes));
    let times: Vec<u32> = keys.iter().map(|m| frame_of(&m.attributes)).collect();
    let looping = attributes.get("_loop").is_some_and(|l| l == "1");
    keys[sample(&times, looping, frame).0].model_id as usize
}

/// Every voxel of `data` at `frame`, in octovox's world axes (MagicaVoxel
/// x, z, −y), walked from node 0 in file order, the later winning.
fn composed(data: &DotVoxData, frame: u32) -> Cells {
    let mut cells = Cells::new();
    let mut stack: Vec<(u32, Vec<Placing>)> = vec![(0, Vec::new())];
    while let Some((id, chain)) = stack.pop() {
        match &data.scenes[id as usize] {
            node @ SceneNode::Transform { child, .. } => {
                let mut chain = chain.clone();
                chain.push(transform_at(node, frame));
                stack.push((*child, chain));
            }
            SceneNode::Group { children, .. } => {
                stack.extend(children.iter().rev().map(|&c| (c, chain.clone())));
            }
            node @ SceneNode::Shape { .. } => {
                let model = &data.models[model_at(node, frame)];
                let pivot = [model.size.x / 2, model.size.y / 2, model.size.z / 2].map(f64::from);
                for v in &model.voxels {
                    // The voxel's centre in model space, then each transform from the innermost.
                    let mut p = [v.x, v.y, v.z].map(f64::from);
                    p = [0, 1, 2].map(|i| p[i] - pivot[i] + 0.5);
                    for (r, t) in chain.iter().rev() {
                        p = [0, 1, 2].map(|i| r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + t[i]);
                    }
                    let [x, y, z] = p.map(|c| c.floor() as i32);
                    cells.insert((x, z, -y), v.i + 1);
                }
            }
        }
    }
    cells
}

fn drawn(editor: &Editor) -> Cells {
    editor.scene.voxels().into_iter().map(|(p, c)| ((p.x, p.y, p.z), c)).collect()
}

/// A cart (a group keyed from x 0 to 20 over frames 0..10, looping) with
/// a wheel that moves, turns and shows three models in turn (its shape
/// loops over frames 0, 4, 8), a rider that stands still in the cart, and
/// a post outside that rises between frames 2 and 12.
fn cart() -> DotVoxData {
    let transform = |name: &str, keys: Vec<Vec<(&str, String)>>, looping: bool, child: u32| {
        let mut attributes = vec![("_name", name.to_owned())];
        if looping {
            attributes.push(("_loop", "1".to_owned()));
        }
        SceneNode::Transform {
            attributes: dict(&attributes),
            frames: keys.iter().map(|k| Frame::new(dict(k))).collect(),
            child,
            layer_id: 0,
        }
    };
    let key = |f: u32, t: &str| vec![("_f", f.to_string()), ("_t", t.to_owned())];
    let mut turned = key(5, "0 0 6");
    turned.push(("_r", "17".to_owned()));
    let shown = |m: u32, f: u32| ShapeModel { model_id: m, attributes: dict(&[("_f", f.to_string())]) };
    DotVoxData {
        version: 200,
        index_map: Vec::new(),
        models: vec![model(5, 10), model(4, 20), model(6, 30)],
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: Vec::new(),
        scenes: vec![
            SceneNode::Transform { attributes: dict(&[]), frames: vec![], child: 1, layer_id: u32::MAX },
            SceneNode::Group { attributes: dict(&[]), children: vec![2, 6] },
            transform("cart", vec![key(0, "0 0 0"), key(10, "20 0 0")], true, 3),
            SceneNode::Group { attributes: dict(&[]), children: vec![4, 8] },
            transform("wheel", vec![key(0, "0 0 0"), turned, key(10, "0 0 0")], false, 5),
            SceneNode::Shape {
                attributes: dict(&[("_loop", "1".to_owned())]),
                models: vec![shown(0, 0), shown(1, 4), shown(2, 8)],
            },
            transform("post", vec![key(12, "-30 5 9"), key(2, "-30 5 0")], false, 7),
            SceneNode::Shape { attributes: dict(&[]), models: vec![ShapeModel { model_id: 2, attributes: dict(&[]) }] },
            transform("rider", vec![vec![("_t", "3 -9 4".to_owned())]], false, 9),
            SceneNode::Shape { attributes: dict(&[]), models: vec![ShapeModel { model_id: 1, attributes: dict(&[]) }] },
        ],
        layers: vec![Layer { attributes: dict(&[("_name", "0".into())]) }],
    }
}

fn bytes_of(data: &DotVoxData) -> Vec<u8> {
    let mut bytes = Vec::new();
    data.write_vox(&mut bytes).unwrap();
    bytes
}

/// Checks the picture at `frames` against the independent composition,
/// through `frame N` in the editor and through a load at that frame.
fn assert_frames_match(name: &str, bytes: &[u8], frames: &[u32]) {
    let data = dot_vox::load_bytes(bytes).unwrap();
    let mut editor = Editor::default();
    editor.set_scene(load(bytes));
    for &frame in frames {
        run(&mut editor, &format!("frame {frame}\nexpect frame {frame}")).unwrap();
        let want = composed(&data, frame);
        assert!(!want.is_empty());
        assert!(drawn(&editor) == want, "{name}, frame {frame}: drawn differs from the composition");
        let loaded = octovox::io::vox::load_vox_scene(bytes, frame as usize).unwrap().0;
        let at_load: Cells = loaded.voxels().into_iter().map(|(p, c)| ((p.x, p.y, p.z), c)).collect();
        assert!(at_load == want, "{name}, loaded at frame {frame}: differs from the composition");
    }
}

/// animation.vox (MagicaVoxel 0.99.7.1): keys at 0, 9 and 30, looping.
/// Between keys the object moves; frame 31 wraps to 0 and 45 to 14.
#[test]
fn animation_vox_draws_at_every_frame_what_its_keys_say() {
    let bytes = std::fs::read(assets().join("anim/animation.vox")).unwrap();
    assert_frames_match("animation.vox", &bytes, &[0, 1, 4, 8, 9, 10, 20, 29, 30, 31, 45, 1000]);
    let data = dot_vox::load_bytes(&bytes).unwrap();
    // The frames differ: the object does move.
    assert_ne!(composed(&data, 4), composed(&data, 0));
    assert_eq!(composed(&data, 45), composed(&data, 14), "a loop of 31 frames");
}

/// Keys on nested groups, a turn, models per frame and loops on both.
#[test]
fn nested_keys_turns_and_models_per_frame_compose_as_written() {
    let bytes = bytes_of(&cart());
    assert_frames_match("cart", &bytes, &[0, 1, 2, 3, 4, 5, 7, 8, 9, 10, 11, 12, 13, 17, 25, 1 << 31]);
    let data = cart();
    assert_ne!(composed(&data, 3), composed(&data, 4), "the wheel shows its second model from frame 4");
}

/// The transform keys of the node named `name` in a saved file, as
/// `dot_vox` reads them: (frame, translation, easing).
fn keys_of(bytes: &[u8], name: &str) -> Vec<(u32, String, Option<String>)> {
    let data = dot_vox::load_bytes(bytes).unwrap();
    let node = data.scenes.iter().find(
        |n| matches!(n, SceneNode::Transform { attributes, .. } if attributes.get("_name").is_some_and(|n| n == name)),
    );
    let Some(SceneNode::Transform { frames, .. }) = node else { panic!("no transform {name}") };
    let mut keys: Vec<_> = frames
        .iter()
        .map(|f| (frame_of(&f.attributes), f.attributes["_t"].clone(), f.attributes.get("_ov_ease").cloned()))
        .collect();
    keys.sort();
    keys
}

/// `object key` keys the frame shown with what it shows, `object unkey`
/// takes it out, a move at a frame between keys keys that frame; each is
/// one undo step, and the saved file holds the keys `dot_vox` reads back.
#[test]
fn keys_are_set_moved_and_taken_out_at_the_frame_shown() {
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes_of(&cart())));
    // The post rises from z 0 (frame 2) to 9 (frame 12): at frame 7 it is at 4.
    run(&mut editor, "object post\nframe 7\nobject key smooth").unwrap();
    let keyed = saved(&editor.scene);
    assert_eq!(
        keys_of(&keyed, "post"),
        [(2, "-30 5 0".into(), None), (7, "-30 5 4".into(), Some("smooth".into())), (12, "-30 5 9".into(), None)]
    );
    assert_frames_match("keyed post", &keyed, &[2, 5, 7, 12]);
    run(&mut editor, "frame 9\nobject move 0 1 0").unwrap();
    // Frame 9 between the keys 7 (z 4, smooth) and 12 (z 9): smoothstep(0.4)
    // = 0.352, 4 + 5·0.352 = 5.76 → 5; one up is 6.
    let moved = saved(&editor.scene);
    assert_eq!(keys_of(&moved, "post")[2], (9, "-30 5 6".into(), None));
    assert_frames_match("moved post", &moved, &[9, 12]);
    run(&mut editor, "undo\nexpect frame 9").unwrap();
    assert_eq!(keys_of(&saved(&editor.scene), "post").len(), 3);
    run(&mut editor, "frame 7\nobject unkey").unwrap();
    assert_eq!(keys_of(&saved(&editor.scene), "post"), keys_of(&bytes_of(&cart()), "post"));
    let refused = run(&mut editor, "object unkey").unwrap_err().to_string();
    assert!(refused.contains("no key at frame 7"), "{refused}");
    // The rider does not move: a move changes its one key, at every frame.
    run(&mut editor, "object rider\nframe 5\nobject move 1 0 0").unwrap();
    assert_eq!(keys_of(&saved(&editor.scene), "rider"), [(0, "4 -9 4".into(), None)]);
    let last = run(&mut editor, "object unkey").unwrap_err().to_string();
    assert!(last.contains("no key at frame 5"), "{last}");
    run(&mut editor, "frame 0\nobject key step").unwrap();
    let only = run(&mut editor, "object unkey").unwrap_err().to_string();
    assert!(only.contains("only key"), "{only}");
}

/// The playback settings live in the META chunk: MagicaVoxel's
/// `_anim_range`, octovox's `_ov_fps` and `_ov_loop`; a META chunk read
/// and not changed is written back byte for byte, with its other keys.
#[test]
fn the_range_speed_and_loop_are_kept_in_the_meta_chunk() {
    let mut meta = Vec::new();
    let entries = [("_anim_range", "2 20"), ("_later", "kept")];
    meta.extend_from_slice(&(entries.len() as u32).to_le_bytes());
    for (key, value) in entries {
        for text in [key, value] {
            meta.extend_from_slice(&(text.len() as u32).to_le_bytes());
            meta.extend_from_slice(text.as_bytes());
        }
    }
    let mut bytes = bytes_of(&cart());
    append_chunks(&mut bytes, &[(*b"META", meta.clone())]);
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes));
    assert_eq!(editor.scene.objects().unwrap().frame_range(), (2, 20));
    assert_eq!(kept_chunks(&saved(&editor.scene)), kept_chunks(&bytes), "unchanged: as read");
    run(&mut editor, "anim fps 24\nanim loop off\nanim range 0 40").unwrap();
    let changed = saved(&editor.scene);
    let metas: Vec<Vec<u8>> = raw_chunks(&changed).into_iter().filter(|(id, _)| id == b"META").map(|c| c.1).collect();
    assert_eq!(metas.len(), 1);
    let written: Vec<(String, String)> =
        [("_anim_range", "0 40"), ("_later", "kept"), ("_ov_fps", "24"), ("_ov_loop", "0")]
            .map(|(k, v)| (k.to_owned(), v.to_owned()))
            .into();
    assert_eq!(dict_entries(&metas[0]), written);
    assert_eq!(load(&changed).objects().unwrap().frame_range(), (0, 40));
    run(&mut editor, "undo 3").unwrap();
    assert_eq!(kept_chunks(&saved(&editor.scene)), kept_chunks(&bytes), "undone: as read again");
    // Without a META chunk the range spans the keys; setting one adds it.
    let mut plain = Editor::default();
    plain.set_scene(load(&bytes_of(&cart())));
    assert_eq!(plain.scene.objects().unwrap().frame_range(), (0, 12));
    run(&mut plain, "anim fps 30").unwrap();
    assert_eq!(raw_chunks(&saved(&plain.scene)).iter().filter(|(id, _)| id == b"META").count(), 1);
}

/// A dictionary's entries, read byte by byte: a count, then length-prefixed
/// keys and values.
fn dict_entries(content: &[u8]) -> Vec<(String, String)> {
    let word = |at: usize| u32::from_le_bytes(content[at..at + 4].try_into().unwrap()) as usize;
    let mut at = 4;
    let mut text = || {
        let len = word(at);
        let out = String::from_utf8(content[at + 4..at + 4 + len].to_vec()).unwrap();
        at += 4 + len;
        out
    };
    (0..word(0)).map(|_| (text(), text())).collect()
}

/// Keys far in time, many keys, and keys that cannot be read: a correct
/// picture or a clear refusal, never a panic.
#[test]
fn far_many_and_broken_keys() {
    let keyed = |keys: Vec<Vec<(&str, String)>>| {
        let mut data = cart();
        data.scenes[6] = SceneNode::Transform {
            attributes: dict(&[("_name", "post".to_owned())]),
            frames: keys.iter().map(|k| Frame::new(dict(k))).collect(),
            child: 7,
            layer_id: 0,
        };
        bytes_of(&data)
    };
    let key = |f: u64, t: &str| vec![("_f", f.to_string()), ("_t", t.to_owned())];
    let far = keyed(vec![key(0, "0 0 0"), key(1 << 31, "1000 0 0")]);
    assert_frames_match("far keys", &far, &[0, 1 << 30, u32::MAX]);
    let many = keyed((0..100_000u64).map(|f| key(2 * f, &format!("{} 0 0", f % 1000))).collect());
    assert_frames_match("100,000 keys", &many, &[0, 1001, 99_999, 150_001]);
    for (bad, why) in [
        (keyed(vec![key(1 << 32, "0 0 0")]), "_f"),
        (keyed(vec![vec![("_f", "x".into()), ("_t", "0 0 0".into())]]), "_f"),
        (keyed(vec![key(0, "NaN 0 0")]), "_t"),
        (keyed(vec![key(0, "inf 0 0")]), "_t"),
        (keyed(vec![key(0, "0 0 0"), vec![("_f", "4".into()), ("_r", "255".into())]]), "_r"),
    ] {
        let err = octovox::io::vox::load_vox_scene(&bad, 0).map(|_| ()).unwrap_err().to_string();
        assert!(err.contains(why), "{why}: {err}");
    }
    let mut editor = Editor::default();
    let one_model = run(&mut editor, "new\nframe 3").unwrap_err().to_string();
    assert!(one_model.contains("no animation"), "{one_model}");
}

/// A scene drawn at another frame edits the model every frame shows.
#[test]
fn an_edit_at_any_frame_edits_the_model_every_frame_shows() {
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes_of(&cart())));
    run(&mut editor, "frame 12\nobject post").unwrap();
    let cells = drawn(&editor);
    let (&(x, y, z), _) = cells.iter().max_by_key(|(p, _)| p.1).unwrap();
    run(&mut editor, &format!("color 5\nplace {x} {} {z}\nframe 2", y + 1)).unwrap();
    let models = &editor.scene.objects().unwrap().models;
    assert_eq!(models[2].tree.solid_voxels(), 37 + 1, "the post's model (6×6 and a corner) grew by one");
    // At frame 2 the post is 9 lower, and the new voxel with it.
    assert_eq!(editor.scene.voxel(IVec3::new(x, y + 1 - 9, z)), 5);
}

/// `info --frame N` reads the scene at frame N and says its time.
#[test]
fn info_follows_the_frame_and_says_the_range() {
    let file = assets().join("anim/animation.vox");
    let info = |frame: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_octovox"))
            .args(["info", file.to_str().unwrap(), "--json", "--frame", frame])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (at0, at9) = (info("0"), info("9"));
    assert_eq!(at9["animation"], serde_json::json!({"frame": 9, "range": [0, 30], "fps": 12, "loop": true}));
    // Key 9 is 43 voxels along MagicaVoxel −x and 60 along +y (world −z) from key 0.
    let min = |v: &serde_json::Value, axis: usize| v["min"][axis].as_i64().unwrap();
    assert_eq!((min(&at9, 0) - min(&at0, 0), min(&at9, 2) - min(&at0, 2)), (-43, -60));
}

/// The node's place at `time` by the animation's samplers, as the column-
/// major matrix T · R · S (a sampler holds its last sample at or before
/// `time`: the samples are at every frame where the place changes).
pub(crate) fn sampled_node(glb: &super::export::Glb, node: usize, time: f64) -> serde_json::Value {
    let mut out = glb.json["nodes"][node].clone();
    let animation = &glb.json["animations"][0];
    for channel in animation["channels"].as_array().unwrap() {
        if channel["target"]["node"] != node {
            continue;
        }
        let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
        let times = glb.floats(sampler["input"].as_u64().unwrap() as usize);
        let values = glb.floats(sampler["output"].as_u64().unwrap() as usize);
        let width = values.len() / times.len();
        let at = times.iter().rposition(|&t| t <= time + 1e-6).unwrap();
        out[channel["target"]["path"].as_str().unwrap()] = serde_json::json!(values[at * width..(at + 1) * width]);
    }
    out.as_object_mut().unwrap().remove("matrix");
    out
}

/// `export` of a moving scene writes a glTF animation that the Khronos
/// validator passes, whose samplers put every moving object's mesh, at
/// every frame checked, on the cells the independent composition fills.
#[test]
fn the_glb_export_animates_what_moves_and_passes_the_validator() {
    let read = super::export::exported_glb(&bytes_of(&cart()));
    let animation = &read.json["animations"][0];
    let named = |name: &str| read.json["nodes"].as_array().unwrap().iter().position(|n| n["name"] == name).unwrap();
    let driven: std::collections::BTreeSet<(u64, String)> = animation["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["target"]["node"].as_u64().unwrap(), c["target"]["path"].as_str().unwrap().to_owned()))
        .collect();
    // The wheel moves and turns (a quarter about z between frames 5 and 10);
    // the rider moves with the cart; the post rises.
    for (name, path) in
        [("wheel", "translation"), ("wheel", "rotation"), ("rider", "translation"), ("post", "translation")]
    {
        assert!(driven.contains(&(named(name) as u64, path.to_owned())), "{name} {path}: {driven:?}");
    }
    let data = cart();
    // The wheel's shape shows model 0 at frames 0..3 and, looping every 9,
    // 9..12; at 4..8 it shows models glTF cannot switch to (its nodes move,
    // its meshes do not), so there only the rider and the post are checked.
    for frame in [0u32, 3, 5, 7, 9, 10, 12] {
        let wheel_shown = !(4..=8).contains(&frame);
        let solid: std::collections::HashSet<[i64; 3]> =
            composed(&data, frame).keys().map(|&(x, y, z)| [x, y, z].map(i64::from)).collect();
        let mut json = read.json.clone();
        for name in ["wheel", "rider", "post"] {
            json["nodes"][named(name)] = sampled_node(&read, named(name), f64::from(frame) / 12.0);
        }
        for (name, mesh, matrix) in super::export_scene::placed_meshes(&json) {
            if name == "wheel" && !wheel_shown {
                continue;
            }
            let positions: Vec<[f64; 3]> =
                read.positions.iter().map(|&p| super::export_scene::apply(&matrix, p)).collect();
            let label = format!("{name} at frame {frame}");
            super::export_scene::faces_lie_on_solid_cells(&label, &positions, &read.mesh_triangles[mesh], &solid);
        }
    }
}

/// `object turn AXIS DEGREES` by whole quarter turns is `object rotate`
/// (−90 undoes 90, 450 is 90), on the exact path (free angles: `turns.rs`).
#[test]
fn object_turn_by_quarter_turns_is_a_rotate() {
    let scene = || {
        let mut editor = Editor::default();
        editor.set_scene(load(&bytes_of(&cart())));
        run(&mut editor, "object rider").unwrap();
        editor
    };
    let original = drawn(&scene());
    let (mut turned, mut rotated, mut round) = (scene(), scene(), scene());
    run(&mut turned, "object turn z 90").unwrap();
    run(&mut rotated, "object rotate z").unwrap();
    run(&mut round, "object turn z 450\nobject turn z -90").unwrap();
    assert_ne!(drawn(&turned), original);
    assert!(drawn(&turned) == drawn(&rotated), "a 90° turn is a quarter rotate");
    assert!(drawn(&round) == original, "450° then −90° is a whole turn");
}

/// Frames played in a scene drawn as instances leave the CPU's octree
/// behind (only the instance words go to the GPU); the next line composes
/// it, and it then holds what an independent composition of the frame puts
/// there.
#[test]
fn played_frames_are_composed_before_the_next_line_reads_the_scene() {
    let data = herd(200);
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes_of(&data)));
    assert!(editor.scene.instanced().is_some(), "the herd is drawn as instances");
    for frame in [1, 2, 5, 9, 13] {
        editor.play_frame(frame).unwrap();
    }
    assert!(editor.scene.objects().unwrap().is_behind(), "played frames are not composed yet");
    run(&mut editor, "expect frame 13").unwrap();
    assert!(drawn(&editor) == composed(&data, 13), "composed when the next line ran");
    // A move after playing lands where the frame shows the object.
    editor.play_frame(7).unwrap();
    run(&mut editor, "object 4\nobject move 0 5 0").unwrap();
    let moved = octovox::io::vox::load_vox_scene(&saved(&editor.scene), 7).unwrap().0;
    let cells = |scene: &octovox::scene::Scene| -> Cells {
        scene.voxels().into_iter().map(|(p, c)| ((p.x, p.y, p.z), c)).collect()
    };
    assert!(cells(&moved) == drawn(&editor), "saved and drawn agree at frame 7");
    assert!(cells(&moved) != composed(&data, 7), "the move changed the frame");
}

/// A move at a frame past a looping object's keys keys the frame its loop
/// shows there, so the loop keeps its length (a review found the key added
/// past the last, which lengthened the loop of every frame).
#[test]
fn a_move_outside_a_loop_keys_the_frame_the_loop_shows() {
    let data = herd(3);
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes_of(&data)));
    // Cow 0 loops over keys 0, 6 and 20: frame 25 shows frame 4.
    run(&mut editor, "frame 25\nobject 0\nobject move 0 2 0").unwrap();
    let frames: Vec<u32> = keys_of(&saved(&editor.scene), "cow 0").iter().map(|k| k.0).collect();
    assert_eq!(frames, [0, 4, 6, 20]);
    assert!(drawn(&editor) != composed(&data, 25), "the cow moved");
    // (The other cows do not loop: only cow 0's place is compared.)
    let cow = |editor: &Editor| editor.scene.objects().unwrap().world_box(0);
    run(&mut editor, "frame 4").unwrap();
    let at4 = cow(&editor);
    run(&mut editor, "frame 25").unwrap();
    assert_eq!(cow(&editor), at4, "frame 25 still shows frame 4");
}

/// While frames play (the CPU's octree not composed yet), a pick sees the
/// frame shown: it walks the objects as placed there, as the GPU draws
/// them. A camera looking straight down on the top cell of a column that
/// the shown frame fills and frame 0 does not fill as high picks that cell.
#[test]
fn a_pick_while_playing_sees_the_frame_shown() {
    let data = herd(200);
    let mut editor = Editor::default();
    editor.set_scene(load(&bytes_of(&data)));
    editor.play_frame(13).unwrap();
    assert!(editor.scene.objects().unwrap().is_behind(), "played, not composed");
    let (now, then) = (composed(&data, 13), composed(&data, 0));
    let top = |cells: &Cells, x: i32, z: i32| cells.keys().filter(|c| c.0 == x && c.2 == z).map(|c| c.1).max();
    let &(x, y, z) = now
        .keys()
        .find(|&&(x, y, z)| top(&now, x, z) == Some(y) && top(&then, x, z).is_none_or(|t| t < y))
        .expect("a column the herd fills higher at frame 13 than at frame 0");
    let centre = glam::DVec3::new(f64::from(x) + 0.5, f64::from(y) + 0.5, f64::from(z) + 0.5);
    let camera = octovox::camera::Camera {
        eye: centre + glam::DVec3::new(0.0, 40.0, 0.0),
        target: centre,
        fov_y_deg: 20.0,
        ortho: None,
    };
    let picked = octovox::trace::pick::pick(&editor.scene, &camera, (101, 101), 50, 50).unwrap();
    assert_eq!(picked.map(|p| p.voxel), Some(IVec3::new(x, y, z)), "the top cell of frame 13's column");
}
