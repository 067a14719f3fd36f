//! Loading: pre-pass, guarded `dot_vox` parse, scene placement, axis change.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use dot_vox::DotVoxData;
use glam::IVec3;

use super::scene;
use super::transform::{Placement, Transform};
use super::validate::{self, Layout};
use super::{MAX_FILE_BYTES, VoxError};
use crate::io::guard::catch_quietly;
use crate::io::input::{InputError, read_limited};
use crate::scene::{Material, MaterialKind, Palette, Voxel, VoxelModel};

/// Reads and loads the `.vox` file at `path`; see [`load_vox`].
///
/// # Errors
/// [`VoxError::Read`] (naming the path) when the file cannot be read,
/// [`VoxError::FileTooLarge`] beyond [`MAX_FILE_BYTES`], else as [`load_vox`].
pub fn load_vox_file(path: &Path, frame: usize) -> Result<VoxelModel, VoxError> {
    let bytes = read_limited(path, MAX_FILE_BYTES).map_err(|e| match e {
        InputError::Io(source) => VoxError::Read { path: path.to_owned(), source },
        InputError::NotRegular => VoxError::NotRegular { path: path.to_owned() },
        InputError::TooLarge { .. } => VoxError::FileTooLarge { path: path.to_owned() },
    })?;
    load_vox(&bytes, frame)
}

/// Loads a MagicaVoxel `.vox` file held in memory.
///
/// Files with a scene graph (nTRN/nGRP/nSHP) are placed by walking it from
/// node 0 (hidden nodes and layers included, as `ogt_vox` does); `frame`
/// picks the keyframe where transforms or shapes are animated (`_f`). Files
/// without one hold either one model or animation frames (several models,
/// PACK), of which model `frame` is loaded as is, in its own grid.
/// Positions are in octovox world axes (y up): scene (x, y, z) → (x, z, −y).
/// Voxels are sorted by position; where two placements overlap, the later one
/// in the scene graph wins.
///
/// # Errors
/// Any malformed or hostile input gives a [`VoxError`] naming the problem;
/// nothing in the file can make this panic or allocate much more than the
/// scene it describes (at most [`super::MAX_VOXELS`] voxels).
pub fn load_vox(bytes: &[u8], frame: usize) -> Result<VoxelModel, VoxError> {
    let layout = validate::check(bytes)?;
    let data = parse_guarded(bytes)?;
    cross_check(&layout, &data)?;
    let placements = if data.scenes.is_empty() {
        frame_placement(data.models.len(), frame)?
    } else {
        scene::placements(&data.scenes, &layout.node_ids, &layout.model_voxels, frame)?
    };
    let voxels = place_voxels(&data, &layout, &placements)?;
    let mut warnings = layout.warnings.clone();
    let palette = palette_of(&data, &layout, &mut warnings);
    Ok(VoxelModel { palette, voxels, models: placements.len(), stored_models: data.models.len(), warnings })
}

/// Runs `dot_vox::load_bytes`, turning a panic into [`VoxError::ParserPanic`].
///
/// The pre-pass should leave `dot_vox` nothing to panic on; this is the
/// second line of defence.
fn parse_guarded(bytes: &[u8]) -> Result<DotVoxData, VoxError> {
    match catch_quietly(|| dot_vox::load_bytes(bytes)) {
        Ok(parsed) => parsed.map_err(VoxError::Parser),
        Err(message) => Err(VoxError::ParserPanic(message)),
    }
}

/// `dot_vox` must have seen the same models and nodes as the pre-pass, or
/// model and node indices would not line up.
fn cross_check(layout: &Layout, data: &DotVoxData) -> Result<(), VoxError> {
    let model_counts: Vec<usize> = data.models.iter().map(|m| m.voxels.len()).collect();
    if model_counts != layout.model_voxels {
        return Err(VoxError::Inconsistent(format!(
            "dot_vox read {} models, the pre-pass {}",
            model_counts.len(),
            layout.model_voxels.len()
        )));
    }
    if data.scenes.len() != layout.node_ids.len() {
        return Err(VoxError::Inconsistent(format!(
            "dot_vox read {} scene nodes, the pre-pass {}",
            data.scenes.len(),
            layout.node_ids.len()
        )));
    }
    if data.version != layout.version {
        return Err(VoxError::Inconsistent("dot_vox read another version".to_owned()));
    }
    Ok(())
}

/// Without a scene graph, `frame` selects one model, placed as stored.
fn frame_placement(models: usize, frame: usize) -> Result<Vec<Placement>, VoxError> {
    if models == 0 && frame == 0 {
        return Ok(Vec::new());
    }
    if frame >= models {
        return Err(VoxError::FrameOutOfRange { requested: frame, models });
    }
    Ok(vec![Placement { model: frame, transform: Transform::IDENTITY, centred: false }])
}

/// Peak bytes per voxel of a load and the octree build after it: the list
/// (16), its sort, and the build's Morton keys (16 each).
const BYTES_PER_LOADED_VOXEL: u64 = 48;

/// Every placed voxel in world axes, sorted by position, overlaps resolved.
fn place_voxels(data: &DotVoxData, layout: &Layout, placements: &[Placement]) -> Result<Vec<Voxel>, VoxError> {
    let empty: HashSet<(usize, usize)> = layout.zero_index_voxels.iter().copied().collect();
    let total: usize = placements.iter().map(|p| layout.model_voxels[p.model]).sum();
    crate::budget::check(|| format!("loading {total} voxels"), total as u64 * BYTES_PER_LOADED_VOXEL)?;
    let mut voxels = Vec::with_capacity(total);
    for placement in placements {
        let model = &data.models[placement.model];
        let size = [model.size.x, model.size.y, model.size.z];
        for (ordinal, v) in model.voxels.iter().enumerate() {
            if !empty.is_empty() && empty.contains(&(placement.model, ordinal)) {
                continue;
            }
            let [x, y, z] = placement.place([v.x, v.y, v.z], size);
            let world = to_world([x, z, -y]).ok_or_else(|| {
                VoxError::BadSceneGraph(format!(
                    "a voxel of model {} lands at ({x}, {y}, {z}), outside the 32-bit range",
                    placement.model
                ))
            })?;
            // `dot_vox` stores the file's index minus one; 0 was skipped above.
            voxels.push((world, v.i.saturating_add(1)));
        }
    }
    sort_and_dedup(&mut voxels);
    Ok(voxels)
}

fn to_world(p: [i64; 3]) -> Option<IVec3> {
    Some(IVec3::new(p[0].try_into().ok()?, p[1].try_into().ok()?, p[2].try_into().ok()?))
}

/// Sorts by position (x, then y, then z) and keeps the last of equal positions.
pub(super) fn sort_and_dedup(voxels: &mut Vec<Voxel>) {
    voxels.sort_by_key(|(p, _)| (p.x, p.y, p.z));
    voxels.dedup_by(|later, kept| {
        let same = later.0 == kept.0;
        if same {
            kept.1 = later.1;
        }
        same
    });
}

/// Colours from RGBA (or MagicaVoxel's default), materials from MATT then
/// MATL; problems with the materials go to `warnings`.
fn palette_of(data: &DotVoxData, layout: &Layout, warnings: &mut Vec<String>) -> Palette {
    let mut palette = Palette::default_magicavoxel();
    for (entry, color) in data.palette.iter().take(256).enumerate() {
        // Entry k of the RGBA chunk is palette index k + 1; the last is index 0.
        palette.colors[(entry + 1) % 256] = (*color).into();
    }
    let mut materials = vec![Material::default(); 256];
    for (&index, material) in &layout.matt {
        materials[usize::from(index)] = material.clone();
    }
    for matl in &data.materials {
        // MagicaVoxel numbers materials 1..=256, where 256 is palette index 0.
        let index = usize::from(matl.id.to_le_bytes()[0]);
        materials[index] = material_from_properties(index, &matl.properties, warnings);
    }
    palette.materials = materials;
    palette
}

/// A MATL's material; what it holds that octovox cannot use as it is goes
/// to `warnings`, naming the palette index.
fn material_from_properties(index: usize, properties: &dot_vox::Dict, warnings: &mut Vec<String>) -> Material {
    let kind = match properties.get("_type") {
        None => MaterialKind::Diffuse,
        Some(name) => MaterialKind::from_vox_name(name).unwrap_or_else(|| {
            warnings.push(format!("material {index}: type '{name}' is not one octovox renders; treated as diffuse"));
            MaterialKind::Diffuse
        }),
    };
    let params: BTreeMap<String, String> = properties
        .iter()
        .filter(|(key, _)| key.as_str() != "_type")
        .map(|(key, value)| (key.clone(), value.clone()))
        .collect();
    let material = Material { kind, params };
    warnings.extend(material.problems().into_iter().map(|p| format!("material {index}: {p}")));
    material
}
