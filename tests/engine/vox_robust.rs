//! Malformed and hostile `.vox` input: always an error naming the problem,
//! never a panic, a hang or a huge allocation.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::path::PathBuf;
use std::sync::LazyLock;
use std::time::{Duration, Instant};

use octovox::io::vox::{VoxError, load_vox, load_vox_file};
use proptest::prelude::*;

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox")
}

fn read_asset(relative: &str) -> Vec<u8> {
    std::fs::read(assets().join(relative)).expect("read asset")
}

// --- building files by hand -------------------------------------------------

fn chunk(id: &[u8; 4], content: &[u8]) -> Vec<u8> {
    let mut bytes = id.to_vec();
    bytes.extend(u32::try_from(content.len()).expect("small chunk").to_le_bytes());
    bytes.extend(0u32.to_le_bytes());
    bytes.extend(content);
    bytes
}

fn vox_file(children: &[Vec<u8>]) -> Vec<u8> {
    let children = children.concat();
    let mut bytes = b"VOX ".to_vec();
    bytes.extend(150u32.to_le_bytes());
    bytes.extend(b"MAIN");
    bytes.extend(0u32.to_le_bytes());
    bytes.extend(u32::try_from(children.len()).expect("small file").to_le_bytes());
    bytes.extend(children);
    bytes
}

fn words(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn size(x: u32, y: u32, z: u32) -> Vec<u8> {
    chunk(b"SIZE", &words(&[x, y, z]))
}

fn xyzi(count: u32, voxels: &[[u8; 4]]) -> Vec<u8> {
    let mut content = count.to_le_bytes().to_vec();
    content.extend(voxels.iter().flatten());
    chunk(b"XYZI", &content)
}

fn dict(entries: &[(&str, &str)]) -> Vec<u8> {
    let mut bytes = words(&[u32::try_from(entries.len()).expect("small dict")]);
    for (key, value) in entries {
        for text in [key, value] {
            bytes.extend(words(&[u32::try_from(text.len()).expect("short")]));
            bytes.extend(text.as_bytes());
        }
    }
    bytes
}

fn transform(id: u32, child: u32, frame: &[(&str, &str)]) -> Vec<u8> {
    let mut content = words(&[id]);
    content.extend(dict(&[]));
    content.extend(words(&[child, u32::MAX, 0, 1]));
    content.extend(dict(frame));
    chunk(b"nTRN", &content)
}

fn animated_transform(id: u32, child: u32, frames: &[&[(&str, &str)]]) -> Vec<u8> {
    let mut content = words(&[id]);
    content.extend(dict(&[]));
    let count = u32::try_from(frames.len()).expect("few frames");
    content.extend(words(&[child, u32::MAX, 0, count]));
    for frame in frames {
        content.extend(dict(frame));
    }
    chunk(b"nTRN", &content)
}

fn group(id: u32, children: &[u32]) -> Vec<u8> {
    let mut content = words(&[id]);
    content.extend(dict(&[]));
    content.extend(words(&[u32::try_from(children.len()).expect("few")]));
    content.extend(words(children));
    chunk(b"nGRP", &content)
}

fn shape(id: u32, model: u32) -> Vec<u8> {
    let mut content = words(&[id]);
    content.extend(dict(&[]));
    content.extend(words(&[1, model]));
    content.extend(dict(&[]));
    chunk(b"nSHP", &content)
}

fn one_voxel_model() -> Vec<Vec<u8>> {
    vec![size(1, 1, 1), xyzi(1, &[[0, 0, 0, 1]])]
}

fn load_err(bytes: &[u8]) -> VoxError {
    match load_vox(bytes, 0) {
        Ok(model) => panic!("expected an error, loaded {} voxels", model.voxels.len()),
        Err(err) => err,
    }
}

fn assert_err_contains(bytes: &[u8], needle: &str) {
    let message = load_err(bytes).to_string();
    assert!(message.contains(needle), "message {message:?} lacks {needle:?}");
}

// --- the cases --------------------------------------------------------------

#[test]
fn hand_built_files_load() {
    let plain = vox_file(&one_voxel_model());
    assert_eq!(load_vox(&plain, 0).expect("plain").voxels.len(), 1);
    let mut scene = one_voxel_model();
    scene.extend([transform(0, 1, &[]), group(1, &[2]), transform(2, 3, &[("_t", "5 6 7")])]);
    scene.push(shape(3, 0));
    let model = load_vox(&vox_file(&scene), 0).expect("scene");
    // Scene (5, 6, 7) → world (5, 7, −6).
    assert_eq!(model.voxels[0].0.to_array(), [5, 7, -6]);
}

/// Issue 24, item 8: a model translated past ±2^24 loaded, rendered and
/// converted (docs/limits.md says it is refused at load), and edits there
/// reported wrapped coordinates. Both ends of the limit, and just inside it.
#[test]
fn voxels_past_the_coordinate_limit_are_refused_at_load() {
    let placed_at = |t: &str| {
        let mut scene = one_voxel_model();
        scene.extend([transform(0, 1, &[]), group(1, &[2]), transform(2, 3, &[("_t", t)])]);
        scene.push(shape(3, 0));
        load_vox(&vox_file(&scene), 0)
    };
    for t in ["16777216 0 0", "0 0 -16777216", "0 -20000000 0", "2000000000 0 0"] {
        let message = placed_at(t).map(|m| m.voxels.len()).unwrap_err().to_string();
        assert!(message.contains("past the coordinate limit ±16777216"), "{t}: {message}");
    }
    assert_eq!(placed_at("16777215 0 -16777215").unwrap().voxels[0].0.to_array(), [16777215, -16777215, -0]);
}

/// `--frame` samples the keys as MagicaVoxel and `ogt_vox` do: linear
/// between keys, rounded toward zero (before issue 49 it snapped to the
/// earlier key: 0 at frame 4 and 10 at frame 7).
#[test]
fn keyframes_follow_the_requested_frame() {
    let mut chunks = one_voxel_model();
    chunks.push(animated_transform(
        0,
        1,
        &[&[("_t", "0 0 0")], &[("_f", "5"), ("_t", "10 0 0")], &[("_f", "8"), ("_t", "20 0 0")]],
    ));
    chunks.push(shape(1, 0));
    let bytes = vox_file(&chunks);
    for (frame, x) in [(0, 0), (4, 8), (5, 10), (7, 16), (8, 20), (100, 20)] {
        let model = load_vox(&bytes, frame).expect("animated scene");
        assert_eq!(model.voxels[0].0.x, x, "frame {frame}");
    }
}

/// 8,192 placements of a full 256×256 layer would be 2^29 voxels, twice
/// `MAX_VOXELS`: refused before any voxel is placed.
#[test]
fn the_voxel_cap_is_checked_before_building() {
    let layer: Vec<[u8; 4]> = (0..=255u8).flat_map(|x| (0..=255u8).map(move |y| [x, y, 0, 1])).collect();
    let mut chunks = vec![size(256, 256, 1), xyzi(65_536, &layer)];
    chunks.push(transform(0, 1, &[]));
    // Thirteen levels of groups with two children each: 2^13 shapes.
    for level in 0..13 {
        chunks.push(group(1 + 2 * level, &[2 + 2 * level, 2 + 2 * level]));
        chunks.push(transform(2 + 2 * level, 3 + 2 * level, &[]));
    }
    chunks.push(shape(27, 0));
    let start = Instant::now();
    let err = load_err(&vox_file(&chunks));
    assert!(matches!(err, VoxError::TooManyVoxels { .. }), "{err:?}");
    assert!(start.elapsed() < Duration::from_secs(2), "took {:?}", start.elapsed());
}

#[test]
fn not_a_vox_says_so() {
    let err = load_vox_file(&assets().join("format/not_a.vox"), 0).expect_err("not a .vox");
    assert!(matches!(err, VoxError::NotVox), "{err:?}");
    assert_eq!(err.to_string(), "not a .vox file (missing 'VOX ' magic)");
}

#[test]
fn every_truncation_of_the_knight_is_an_error() {
    let bytes = read_asset("magicavoxel/chr_knight.vox");
    for len in 0..bytes.len() {
        assert!(load_vox(&bytes[..len], 0).is_err(), "prefix of {len} bytes loaded");
    }
    assert!(load_vox(&bytes, 0).is_ok());
}

/// Hostile sizes and counts fail fast. (`vox_alloc.rs` checks that they
/// also allocate almost nothing.)
#[test]
fn huge_claims_fail_fast() {
    let start = Instant::now();
    let big_size = vox_file(&[size(1 << 31, 1, 1), xyzi(1, &[[0, 0, 0, 1]])]);
    assert_err_contains(&big_size, "gives model size 2147483648x1x1");
    let big_count = vox_file(&[size(8, 8, 8), xyzi(1 << 31, &[[0, 0, 0, 1]; 10])]);
    assert_err_contains(&big_count, "claims 2147483648 voxels but holds 40 bytes");
    let mut huge_chunk = vox_file(&one_voxel_model());
    huge_chunk[24..28].copy_from_slice(&u32::MAX.to_le_bytes()); // SIZE's content size
    assert_err_contains(&huge_chunk, "claims 4294967295 content bytes");
    assert!(start.elapsed() < Duration::from_secs(1), "took {:?}", start.elapsed());
}

#[test]
fn voxels_outside_their_model_are_rejected() {
    let bytes = vox_file(&[size(2, 2, 2), xyzi(1, &[[0, 5, 0, 1]])]);
    assert_err_contains(&bytes, "outside the model size 2x2x2");
}

#[test]
fn scene_graph_cycles_are_errors() {
    let mut chunks = one_voxel_model();
    chunks.extend([transform(0, 1, &[]), group(1, &[2]), transform(2, 1, &[])]);
    let err = load_err(&vox_file(&chunks));
    assert!(matches!(err, VoxError::SceneCycle(_)), "{err:?}");
    assert!(err.to_string().starts_with("scene graph cycle at node"), "{err}");

    let mut self_loop = one_voxel_model();
    self_loop.push(transform(0, 0, &[]));
    assert_eq!(load_err(&vox_file(&self_loop)).to_string(), "scene graph cycle at node 0");
}

/// A node shared by two parents is an instance, not a cycle (test_groups.vox
/// does this); but sharing that doubles at every level must hit a limit.
#[test]
fn shared_nodes_are_fine_but_exponential_sharing_is_capped() {
    let mut shared = one_voxel_model();
    shared.extend([transform(0, 1, &[]), group(1, &[2, 3])]);
    shared.extend([transform(2, 4, &[("_t", "0 0 0")]), transform(3, 4, &[("_t", "9 0 0")])]);
    shared.push(shape(4, 0));
    assert_eq!(load_vox(&vox_file(&shared), 0).expect("shared shape").voxels.len(), 2);

    // 40 levels of groups whose two children are the same next group: 2^40 paths.
    let mut bomb = one_voxel_model();
    bomb.push(transform(0, 1, &[]));
    for level in 0..40 {
        bomb.push(group(1 + level, &[2 + level, 2 + level]));
    }
    bomb.push(group(41, &[]));
    let start = Instant::now();
    assert_err_contains(&vox_file(&bomb), "node visits");
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

#[test]
fn bad_references_are_errors() {
    let mut missing = one_voxel_model();
    missing.push(transform(0, 7, &[]));
    assert_err_contains(&vox_file(&missing), "node 0 refers to missing node 7");

    let mut bad_model = one_voxel_model();
    bad_model.extend([transform(0, 1, &[]), shape(1, 3)]);
    assert_err_contains(&vox_file(&bad_model), "uses model 3 but the file has 1 models");

    let mut no_root = one_voxel_model();
    no_root.push(shape(5, 0));
    assert_err_contains(&vox_file(&no_root), "no root node 0");
}

/// dot_vox's own `Frame::orientation` panics ("Invalid Rotation") on these.
#[test]
fn invalid_rotations_are_errors_not_panics() {
    for rotation in ["0", "3", "15", "300", "x"] {
        let mut chunks = one_voxel_model();
        chunks.extend([transform(0, 1, &[("_r", rotation)]), shape(1, 0)]);
        assert_err_contains(&vox_file(&chunks), "invalid rotation");
    }
}

/// dot_vox recurses into the children of any chunk: 100,000 nested chunk
/// headers (1.2 MB) overflow its stack, which aborts the process.
#[test]
fn nested_chunks_are_rejected_before_dot_vox_recurses() {
    let depth = 100_000u32;
    let mut nested = Vec::new();
    for level in 0..=depth {
        nested.extend(b"ABCD");
        nested.extend(words(&[0, 12 * (depth - level)]));
    }
    let mut bytes = vox_file(&[]);
    bytes[16..20].copy_from_slice(&u32::try_from(nested.len()).expect("fits").to_le_bytes());
    bytes.extend(nested);
    assert_err_contains(&bytes, "only MAIN may have children");
}

#[test]
fn other_structural_errors_name_the_chunk() {
    let bad_id = vox_file(&[size(1, 1, 1), chunk(b"\xffAB\x00", &[]), xyzi(1, &[[0; 4]])]);
    assert_err_contains(&bad_id, "has an id that is not ASCII text");
    let orphan = vox_file(&[xyzi(1, &[[0, 0, 0, 1]])]);
    assert_err_contains(&orphan, "chunk XYZI at byte 20 comes before any SIZE chunk");
    let palette = vox_file(&[chunk(b"RGBA", &[0; 12])]);
    assert_err_contains(&palette, "has 12 bytes; a palette has 1024");
    let mut stray = vox_file(&[size(1, 1, 1), vec![0; 5]]);
    stray.extend([0; 7]); // bytes after MAIN are ignored, as dot_vox does
    assert_err_contains(&stray, "chunk MAIN at byte 8 ends with 5 stray bytes at byte 44");
    let mut version = vox_file(&[]);
    version[4] = 151;
    assert_err_contains(&version, "unsupported .vox version 151");
    // MATL 1 with one property whose key is the single byte 0xff.
    let matl = [words(&[1, 1, 1]), vec![0xff], words(&[0])].concat();
    let bad_utf8 = vox_file(&[chunk(b"MATL", &matl)]);
    assert_err_contains(&bad_utf8, "not UTF-8");
}

/// A voxel stored with colour index 0 is empty (as in ogt_vox), not index 1.
#[test]
fn stored_index_zero_is_empty() {
    let bytes = vox_file(&[size(2, 1, 1), xyzi(2, &[[0, 0, 0, 0], [1, 0, 0, 200]])]);
    let model = load_vox(&bytes, 0).expect("load");
    assert_eq!(model.voxels.len(), 1);
    assert_eq!(model.voxels[0].1, 200);
}

// --- fuzzing the shared assets ----------------------------------------------

static SAMPLES: LazyLock<Vec<Vec<u8>>> = LazyLock::new(|| {
    let mut files: Vec<PathBuf> = ["seed", "format", "magicavoxel"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(assets().join(dir)).expect("asset dir"))
        .map(|entry| entry.expect("dir entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "vox"))
        .collect();
    files.sort();
    files.iter().map(|path| std::fs::read(path).expect("read asset")).collect()
});

/// Where a flip lands: anywhere, or within the first 2 KiB, where the headers,
/// scene graph and small chunks of most files live.
fn flip_position(bytes: &[u8], at: prop::sample::Index, near_start: bool) -> usize {
    let span = if near_start { bytes.len().min(2048) } else { bytes.len() };
    at.index(span)
}

proptest! {
    // A full load of the largest asset takes ~25 ms with the test profile
    // (most cases fail much earlier): a few seconds per property.
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    /// With `patch_main`, MAIN's children size is cut to match, so the
    /// pre-pass reaches the chunk that was cut instead of stopping at MAIN.
    #[test]
    fn truncated_assets_never_panic(
        file in any::<prop::sample::Index>(),
        cut in any::<prop::sample::Index>(),
        patch_main in any::<bool>(),
    ) {
        let mut bytes = file.get(&SAMPLES)[..].to_vec();
        bytes.truncate(cut.index(bytes.len()));
        if patch_main && bytes.len() >= 20 {
            let children = u32::try_from(bytes.len() - 20).expect("small asset");
            bytes[16..20].copy_from_slice(&children.to_le_bytes());
        }
        let _ = load_vox(&bytes, 0);
    }

    #[test]
    fn flipped_assets_never_panic(
        file in any::<prop::sample::Index>(),
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<bool>(), 1u8..=255), 1..=8),
        frame in prop_oneof![3 => Just(0usize), 1 => 1usize..3],
    ) {
        let mut bytes = file.get(&SAMPLES).clone();
        for (at, near_start, mask) in flips {
            let position = flip_position(&bytes, at, near_start);
            bytes[position] ^= mask;
        }
        if let Ok(model) = load_vox(&bytes, frame) {
            prop_assert!(model.voxels.len() <= octovox::io::vox::MAX_VOXELS);
        }
    }
}
