//! What each fuzz target checks for one input. The fuzz targets
//! (`tests/fuzz/fuzz_targets/`) and the corpus replay that CI runs
//! (`tests/engine/fuzz_corpus.rs`) include this one file, so both check the same.
//!
//! A check panics when octovox misbehaves: a panic escaping the library, an
//! accepted input whose result breaks an invariant, or a script line that
//! does not survive printing and parsing again.

use std::path::Path;

/// Largest mesh edge the obj check voxelizes at: enough to run every step.
const OBJ_VOXELS: u32 = 24;

/// A .vox file: loading never panics; what loads builds a valid octree,
/// and saving it gives a file that loads back with the same voxels.
pub fn vox(data: &[u8]) {
    let Ok(model) = octovox::io::vox::load_vox(data, 0) else { return };
    let Ok(scene) = octovox::scene::Scene::from_model(&model) else { return };
    if let Err(broken) = scene.drawn().check_invariants() {
        panic!("a loaded scene built a broken octree: {broken}");
    }
    if scene.solid_voxels() > 1 << 20 {
        return; // a valid but large scene: saving it again proves nothing more
    }
    let bytes = octovox::io::vox::encode_vox(&scene.palette, &model.voxels).expect("a loaded scene saves");
    let again = octovox::io::vox::load_vox(&bytes, 0).expect("a saved scene loads");
    // The loader sorts by position (x, then y, then z).
    let mut expected = scene.voxels();
    expected.sort_by_key(|(p, _)| (p.x, p.y, p.z));
    assert_eq!(again.voxels, expected, "the voxels changed in a save and load");
}

/// An .obj file: parsing never panics; what parses voxelizes, streamed,
/// into the dense reference's voxel count.
pub fn obj(data: &[u8]) {
    let path = Path::new("fuzz.obj");
    let Ok(triangles) = octovox::io::mesh::parse_obj(data, path, octovox::io::mesh::UpAxis::Y) else { return };
    let dense = octovox::io::mesh::voxelize_dense(&triangles, OBJ_VOXELS, 1);
    let dims = dense.dims;
    assert!(dims.max_element() <= OBJ_VOXELS && dims.min_element() >= 1, "block {dims}");
    assert_eq!(dense.data.len() as u64, dims.as_u64vec3().element_product());
    let tree =
        octovox::io::mesh::voxelize(&triangles, OBJ_VOXELS, 1, &Default::default()).expect("a small block builds");
    assert_eq!(tree.solid_voxels(), dense.solid_count() as u64, "streamed and dense voxel counts differ");
}

/// A script: parsing never panics, and every parsed line prints as text
/// that parses to the same command (what `--record` relies on).
pub fn script(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(script) = octovox::script::parse_script(Path::new("fuzz.ovr"), text) else { return };
    for line in &script.lines {
        let printed = line.command.to_string();
        let again = octovox::script::parse_script(Path::new("fuzz.ovr"), &printed)
            .unwrap_or_else(|e| panic!("'{printed}' does not parse again: {e:?}"));
        assert_eq!(again.lines.len(), 1, "'{printed}'");
        assert_eq!(again.lines[0].command, line.command, "'{printed}'");
    }
}

/// The folder of the journal check's document, the same for every process
/// so that the corpus can name it: `load /tmp/octovox-fuzz-journal/doc.vox`.
pub const JOURNAL_DOCUMENT: &str = "/tmp/octovox-fuzz-journal/doc.vox";

/// A folder of this process's own (fuzz jobs run side by side).
fn own_dir(what: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("octovox-fuzz-{what}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a folder for the check");
    dir
}

/// A crash journal: reading it never panics, and a journal read as good
/// only edits: no line that writes a file (`save`, `render`) and one scene
/// line at most (`load`, `new`, `demo`), with and without its document.
pub fn journal(data: &[u8]) {
    use octovox::script::Line;
    static DOCUMENT: std::sync::Once = std::sync::Once::new();
    let document = Path::new(JOURNAL_DOCUMENT);
    DOCUMENT.call_once(|| {
        std::fs::create_dir_all(document.parent().expect("a folder")).expect("the document's folder");
        let mut scene = octovox::scene::Scene::default();
        let shape = octovox::scene::Shape::Box { min: glam::IVec3::ZERO, max: glam::IVec3::new(1, 2, 1) };
        scene.apply_brush(&shape, octovox::scene::Op::Place(3)).expect("a small box");
        // Every process writes the same bytes; the write is atomic.
        let options = octovox::io::atomic::WriteOptions::forced(true);
        octovox::io::save_scene(document, &scene, options).expect("the journal's document saves");
    });
    let journal = own_dir("journal").join(".doc.vox.octovox-journal.ovr");
    std::fs::write(&journal, data).expect("the journal is written");
    for owner in [Some(document), None] {
        let Ok(script) = octovox::journal::read(&journal, owner, Default::default()) else { continue };
        let writes = script.lines.iter().find(|l| matches!(l.command, Line::Save(_) | Line::Render(_)));
        assert!(writes.is_none(), "a journal read as good writes a file: '{}'", writes.map(|l| &l.command).unwrap());
        let scenes = script.lines.iter().filter(|l| matches!(l.command, Line::Load(_) | Line::New | Line::Demo(_)));
        assert!(scenes.count() <= 1, "a journal read as good makes more than one scene");
    }
}

/// Bytes an .ovx decoder may produce for an input of `input` bytes: a step
/// of its chunked reading, and a generous compression ratio.
const OVX_DECODED_PER_INPUT_BYTE: u64 = 1024;

/// An .ovx file: decoding never panics, never decompresses far more than
/// the input could honestly hold, and what loads saves and loads back the same.
pub fn ovx(data: &[u8]) {
    let progress = octovox::io::progress::Progress::default();
    let loaded = octovox::io::ovx::decode_ovx(data, &progress);
    let (decoded, _) = progress.get();
    let allowed = (2 << 20) + OVX_DECODED_PER_INPUT_BYTE * data.len() as u64;
    assert!(decoded <= allowed, "{} input bytes decoded to {decoded}", data.len());
    let Ok(scene) = loaded else { return };
    if let Err(broken) = scene.drawn().check_invariants() {
        panic!("a loaded .ovx is a broken octree: {broken}");
    }
    let path = own_dir("ovx").join("again.ovx");
    octovox::io::ovx::save_ovx(&path, &scene, octovox::io::atomic::WriteOptions::forced(true))
        .expect("a loaded .ovx saves");
    let again = octovox::io::ovx::load_ovx(&path, &Default::default()).expect("a saved .ovx loads");
    // Cells, not voxels: a tiny file can hold one uniform 2^20-wide cube.
    let cells = |tree: &octovox::scene::Octree| {
        let mut cells = Vec::new();
        tree.for_each_solid_cell(|min, size, value| cells.push((min, size, value)));
        cells
    };
    assert_eq!(cells(again.drawn()), cells(scene.drawn()), "the voxels changed in a save and load");
    assert_eq!(again.counts(), scene.counts());
    assert_eq!((again.origin(), again.drawn().depth()), (scene.origin(), scene.drawn().depth()));
    assert_eq!(again.palette, scene.palette, "the palette or materials changed in a save and load");
}
