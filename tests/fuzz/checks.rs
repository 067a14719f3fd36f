//! What each fuzz target checks for one input. The fuzz targets
//! (`tests/fuzz/fuzz_targets/`) and the corpus replay that CI runs
//! (`tests/fuzz_corpus.rs`) include this one file, so both check the same.
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
    if let Err(broken) = scene.tree.check_invariants() {
        panic!("a loaded scene built a broken octree: {broken}");
    }
    if scene.tree.solid_voxels() > 1 << 20 {
        return; // a valid but large scene: saving it again proves nothing more
    }
    let bytes = octovox::io::vox::encode_vox(&scene.palette, &model.voxels).expect("a loaded scene saves");
    let again = octovox::io::vox::load_vox(&bytes, 0).expect("a saved scene loads");
    // The loader sorts by position (x, then y, then z).
    let mut expected = scene.tree.voxels();
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
    let Ok(script) = octovox::replay::parse_script(Path::new("fuzz.ovr"), text) else { return };
    for line in &script.lines {
        let printed = line.command.to_string();
        let again = octovox::replay::parse_script(Path::new("fuzz.ovr"), &printed)
            .unwrap_or_else(|e| panic!("'{printed}' does not parse again: {e:?}"));
        assert_eq!(again.lines.len(), 1, "'{printed}'");
        assert_eq!(again.lines[0].command, line.command, "'{printed}'");
    }
}
