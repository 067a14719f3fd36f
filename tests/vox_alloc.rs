//! Hostile headers must not make the loader allocate what they claim, and a
//! brush in a scene of objects takes what its surface needs, not a list of
//! the voxels it covers.
//!
//! This test binary counts heap bytes with a wrapping global allocator; its
//! tests take `MEASURING` in turn, so nothing else allocates while one
//! measures.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report
#![expect(unsafe_code, reason = "a GlobalAlloc that forwards to System needs unsafe impl")]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use octovox::io::vox::load_vox;

struct PeakCounter;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to `System`; the counters are
// only bookkeeping.
unsafe impl GlobalAlloc for PeakCounter {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: PeakCounter = PeakCounter;

/// Held by the test that measures.
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Peak heap growth, in bytes, while `f` runs.
fn peak_while(f: impl FnOnce()) -> usize {
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    f();
    PEAK.load(Ordering::Relaxed).saturating_sub(before)
}

fn words(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn vox_file(chunks: &[(&[u8; 4], Vec<u8>)]) -> Vec<u8> {
    let mut children = Vec::new();
    for (id, content) in chunks {
        children.extend(*id);
        children.extend(words(&[u32::try_from(content.len()).expect("small"), 0]));
        children.extend(content);
    }
    let mut bytes = b"VOX ".to_vec();
    bytes.extend(words(&[150]));
    bytes.extend(b"MAIN");
    bytes.extend(words(&[0, u32::try_from(children.len()).expect("small")]));
    bytes.extend(children);
    bytes
}

/// Peak heap growth, in bytes, while loading `bytes` (which must fail).
fn peak_while_failing(bytes: &[u8]) -> usize {
    peak_while(|| assert!(load_vox(bytes, 0).is_err()))
}

#[test]
fn hostile_headers_allocate_almost_nothing() {
    let _measuring = MEASURING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let one_voxel = words(&[1]).into_iter().chain([0, 0, 0, 1]).collect::<Vec<u8>>();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("SIZE 2^31", vox_file(&[(b"SIZE", words(&[1 << 31, 1 << 31, 1 << 31])), (b"XYZI", one_voxel)])),
        ("XYZI claiming 2^31 voxels", vox_file(&[(b"SIZE", words(&[8, 8, 8])), (b"XYZI", words(&[1 << 31, 0, 0]))])),
        ("nGRP claiming 2^30 children", vox_file(&[(b"nGRP", words(&[0, 0, 1 << 30, 1, 2]))])),
        ("dictionary claiming 2^31 entries", vox_file(&[(b"MATL", words(&[1, 1 << 31, 4, 0]))])),
    ];
    for (name, bytes) in cases {
        let peak = peak_while_failing(&bytes);
        assert!(peak < 64 * 1024, "{name}: peak heap growth {peak} bytes");
    }
}

/// Runs script lines on `editor`, panicking at the first refused one.
fn run(editor: &mut octovox::editor::Editor, text: &str) {
    let script = octovox::script::parse_script(std::path::Path::new("t.ovr"), text).unwrap();
    for line in &script.lines {
        editor.run(&line.command).unwrap();
    }
}

/// Issue 48, item 7: a 255³ box in a new object of a scene of objects took
/// 646 MB (every voxel it composed, listed), where the same brush in a
/// scene of one model writes a few uniform cells; a 2048³ box asked for
/// 8 GB and aborted. Composing now copies the model's uniform cells.
#[test]
fn a_brush_in_a_scene_of_objects_takes_what_its_surface_needs() {
    let _measuring = MEASURING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let groups = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/format/test_groups.vox");
    let objects_scene = octovox::io::load_scene(&groups, 0).unwrap();
    for side in [255, 2048] {
        let brush = format!("brush box {side} {side} {side}\nplace 3000 {} 0", side / 2 + 40);
        // The same voxels as one model, in an octree of the same root (so
        // the box is as aligned to its cells).
        let mut one_model = octovox::editor::Editor::default();
        let drawn = objects_scene.drawn().clone();
        one_model.set_scene(octovox::scene::Scene::new(objects_scene.palette.clone(), drawn));
        let alone = peak_while(|| run(&mut one_model, &brush));
        let mut editor = octovox::editor::Editor::default();
        editor.set_scene(objects_scene.clone());
        run(&mut editor, "object new slab");
        let peak = peak_while(|| run(&mut editor, &brush));
        eprintln!("box {side}: peak heap {peak} bytes in a scene of objects, {alone} in a scene of one model");
        assert_eq!(editor.scene.solid_voxels(), objects_scene.solid_voxels() + (side as u64).pow(3));
        // Two octrees change (the model's and the drawn one): about twice
        // the one model's, where the list of voxels took 40 (255³) to 140
        // times (2048³) as much.
        assert!(peak < 3 * alone + (16 << 20), "box {side}: {peak} bytes in a scene of objects ({alone} alone)");
    }
}
