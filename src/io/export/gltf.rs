//! glTF 2.0 binary (.glb): a mesh per model with a primitive per palette
//! index used, each with a metallic-roughness material made from the palette
//! colour and its MATL entry as the path tracer reads it (`docs/export.md`
//! has the table). A scene of objects is a node per visible object under
//! nodes for its groups, placed by its exact transform; the placements of
//! one model share its mesh.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use glam::IVec3;
use serde_json::{Map, Value, json};

use super::VoxelMesh;
use super::parts::{Exported, Motion};
use crate::scene::Palette;
use crate::trace::path::materials::{MATERIAL_EMIT, MATERIAL_GLASS, MATERIAL_METAL, gpu_material};

// Codes from the glTF 2.0 specification (accessor.componentType,
// bufferView.target, mesh.primitive.mode).
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;

/// The .glb of `exported`, one unit (metre) per voxel times `scale`; `None`
/// when it would pass the 4 GiB a .glb can hold (its lengths are 32-bit).
pub fn glb(exported: &Exported, palette: &Palette, scale: f32) -> Option<Vec<u8>> {
    let mut buffers = Buffers::default();
    let mut extensions_used = BTreeSet::new();
    let mut material_of = HashMap::new();
    let mut materials = Vec::new();
    for color in exported.colors() {
        material_of.insert(color, materials.len());
        materials.push(material(palette, color, &mut extensions_used));
    }
    // glTF allows no empty mesh: a mesh without triangles has no index.
    let mut meshes = Vec::new();
    let mut gltf_mesh = Vec::new();
    for named in &exported.meshes {
        let primitives = buffers.primitives(&named.mesh, scale, &material_of);
        gltf_mesh.push((!primitives.is_empty()).then_some(meshes.len()));
        if !primitives.is_empty() {
            meshes.push(json!({"name": named.name, "primitives": primitives}));
        }
    }
    let (mut nodes, mut roots, moving) = nodes(exported, &gltf_mesh, scale);
    let animation = buffers.animation(&moving, exported.fps, scale);
    // A scene needs a node (every object hidden): one without a mesh.
    if nodes.is_empty() {
        (nodes, roots) = (vec![json!({"name": "voxels"})], vec![0]);
    }

    let mut root = Map::new();
    root.insert("asset".into(), json!({"version": "2.0", "generator": "octovox"}));
    root.insert("scene".into(), json!(0));
    root.insert("scenes".into(), json!([{"nodes": roots}]));
    // An empty scene is a node without a mesh: glTF allows no empty mesh,
    // array or buffer.
    if !meshes.is_empty() {
        root.insert("meshes".into(), Value::Array(meshes));
        root.insert("materials".into(), Value::Array(materials));
    }
    if !buffers.accessors.is_empty() {
        root.insert("accessors".into(), Value::Array(buffers.accessors));
        root.insert("bufferViews".into(), Value::Array(buffers.views));
        root.insert("buffers".into(), json!([{"byteLength": buffers.bin.len()}]));
    }
    root.insert("nodes".into(), Value::Array(nodes));
    if let Some(animation) = animation {
        root.insert("animations".into(), json!([animation]));
    }
    if !extensions_used.is_empty() {
        root.insert("extensionsUsed".into(), json!(extensions_used));
    }
    container(Value::Object(root).to_string().as_bytes(), &buffers.bin)
}

/// The nodes: one per part (with its mesh and, unless it is the identity,
/// its matrix; a part that moves has its place at the frame shown as
/// translation, rotation and scale, which an animation can drive) under
/// one per group on its path, in the order first met; the indices of the
/// scene's root nodes; and each moving part's node with its motion.
fn nodes<'a>(
    exported: &'a Exported,
    gltf_mesh: &[Option<usize>],
    scale: f32,
) -> (Vec<Value>, Vec<usize>, Vec<(usize, &'a Motion)>) {
    let mut moving = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    let mut roots = Vec::new();
    let mut group_nodes: HashMap<Vec<String>, usize> = HashMap::new();
    for part in &exported.parts {
        let mut parent = None;
        for depth in 1..=part.groups.len() {
            let key = part.groups[..depth].to_vec();
            let node = match group_nodes.get(&key) {
                Some(&node) => node,
                None => {
                    nodes.push(json!({"name": key[depth - 1], "children": []}));
                    let node = nodes.len() - 1;
                    attach(&mut nodes, &mut roots, parent, node);
                    group_nodes.insert(key, node);
                    node
                }
            };
            parent = Some(node);
        }
        let mut node = json!({"name": part.name});
        if let Some(mesh) = gltf_mesh[part.mesh] {
            node["mesh"] = json!(mesh);
        }
        match &part.motion {
            Some(motion) => {
                let (translation, rotation, scaling) = part.place.trs(scale);
                node["translation"] = json!(translation);
                node["rotation"] = json!(rotation);
                node["scale"] = json!(scaling);
                moving.push((nodes.len(), motion));
            }
            None => {
                if let Some(matrix) = part.place.matrix(scale) {
                    node["matrix"] = json!(matrix);
                }
            }
        }
        nodes.push(node);
        let node = nodes.len() - 1;
        attach(&mut nodes, &mut roots, parent, node);
    }
    (nodes, roots, moving)
}

/// Makes node `child` a child of `parent`, or a root of the scene.
fn attach(nodes: &mut [Value], roots: &mut Vec<usize>, parent: Option<usize>, child: usize) {
    match parent.and_then(|parent| nodes[parent]["children"].as_array_mut()) {
        Some(children) => children.push(json!(child)),
        None => roots.push(child),
    }
}

/// The binary buffer and the views and accessors into it.
#[derive(Default)]
struct Buffers {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffers {
    /// A primitive per palette index `mesh` uses, its data appended.
    fn primitives(&mut self, mesh: &VoxelMesh, scale: f32, material_of: &HashMap<u8, usize>) -> Vec<Value> {
        let mut by_color: BTreeMap<u8, Vec<[u32; 3]>> = BTreeMap::new();
        for (triangle, color) in &mesh.triangles {
            by_color.entry(*color).or_default().push(*triangle);
        }
        let mut primitives = Vec::new();
        for (color, triangles) in &by_color {
            let part = Part::of(mesh, triangles, scale);
            let first = self.accessors.len();
            // The validator requires the bounds of POSITION, and checks them
            // against the data: both are the same f32 values.
            let lo = part.positions.iter().fold([f32::INFINITY; 3], |lo, p| [0, 1, 2].map(|k| lo[k].min(p[k])));
            let hi = part.positions.iter().fold([f32::NEG_INFINITY; 3], |hi, p| [0, 1, 2].map(|k| hi[k].max(p[k])));
            let count = part.positions.len();
            let view = self.push_view(le_floats(&part.positions), ARRAY_BUFFER);
            self.accessors.push(json!({
                "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC3", "min": lo, "max": hi
            }));
            let view = self.push_view(le_floats(&part.normals), ARRAY_BUFFER);
            self.accessors.push(json!({"bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC3"}));
            let view = self.push_view(part.indices.iter().map(|i| i.to_le_bytes()), ELEMENT_ARRAY_BUFFER);
            let count = part.indices.len();
            self.accessors
                .push(json!({"bufferView": view, "componentType": UNSIGNED_INT, "count": count, "type": "SCALAR"}));
            primitives.push(json!({
                "attributes": {"POSITION": first, "NORMAL": first + 1},
                "indices": first + 2,
                "material": material_of.get(color).copied().unwrap_or(0),
                "mode": TRIANGLES,
            }));
        }
        primitives
    }

    /// Appends `words` (little-endian, as glTF stores numbers) as a buffer
    /// view of its own; returns the view's index.
    fn push_view(&mut self, words: impl Iterator<Item = [u8; 4]>, target: u32) -> usize {
        let index = self.push_data(words);
        self.views[index]["target"] = json!(target);
        index
    }

    /// The same, for data no vertex stage reads (animation samplers).
    fn push_data(&mut self, words: impl Iterator<Item = [u8; 4]>) -> usize {
        let offset = self.bin.len();
        self.bin.extend(words.flatten());
        let length = self.bin.len() - offset;
        self.views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": length}));
        self.views.len() - 1
    }

    /// An accessor of floats, `kind` ("SCALAR", "VEC3", "VEC4") wide each.
    fn float_accessor(&mut self, values: &[f32], width: usize, kind: &str, bounds: bool) -> usize {
        let view = self.push_data(values.iter().map(|v| v.to_le_bytes()));
        let mut accessor =
            json!({"bufferView": view, "componentType": FLOAT, "count": values.len() / width, "type": kind});
        if bounds {
            let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            accessor["min"] = json!([lo]);
            accessor["max"] = json!([hi]);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// One animation driving every moving node: its translation (STEP where
    /// its keys hold, else LINEAR), its rotation (LINEAR where it turns
    /// freely between keys that do not hold, else STEP: quarter turns are
    /// held between keys) and its scale (STEP); `None` when nothing moves.
    fn animation(&mut self, moving: &[(usize, &Motion)], fps: u32, scale: f32) -> Option<Value> {
        let (mut samplers, mut channels) = (Vec::new(), Vec::new());
        for &(node, motion) in moving {
            let times: Vec<f32> = motion.samples.iter().map(|(frame, _)| *frame as f32 / fps.max(1) as f32).collect();
            let input = self.float_accessor(&times, 1, "SCALAR", true);
            let trs: Vec<_> = motion.samples.iter().map(|(_, place)| place.trs(scale)).collect();
            let translation: Vec<f32> = trs.iter().flat_map(|t| t.0).collect();
            let scaling: Vec<f32> = trs.iter().flat_map(|t| t.2).collect();
            let step = if motion.step { "STEP" } else { "LINEAR" };
            // Free turns slerp between keys, as glTF's LINEAR rotation does
            // (each sample on the near side of the last: the short way).
            let slerped = !motion.step && motion.samples.iter().any(|(_, place)| place.is_turned());
            let mut last = glam::Vec4::W;
            let rotation: Vec<f32> = trs
                .iter()
                .flat_map(|t| {
                    let q = glam::Vec4::from_array(t.1);
                    last = if slerped && q.dot(last) < 0.0 { -q } else { q };
                    last.to_array()
                })
                .collect();
            let mut channel = |path: &str, values: &[f32], width: usize, kind: &str, interpolation: &str| {
                let output = self.float_accessor(values, width, kind, false);
                samplers.push(json!({"input": input, "output": output, "interpolation": interpolation}));
                channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": path}}));
            };
            // All three, even where one holds over the range: the node's own
            // values are those of the frame exported, which may lie outside it.
            channel("translation", &translation, 3, "VEC3", step);
            channel("rotation", &rotation, 4, "VEC4", if slerped { "LINEAR" } else { "STEP" });
            channel("scale", &scaling, 3, "VEC3", "STEP");
        }
        (!channels.is_empty()).then(|| json!({"name": "animation", "samplers": samplers, "channels": channels}))
    }
}

/// One primitive's vertices: a copy of a mesh vertex per face direction
/// that uses it, so that each copy has its face's flat normal.
#[derive(Default)]
struct Part {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
}

impl Part {
    fn of(mesh: &VoxelMesh, triangles: &[[u32; 3]], scale: f32) -> Part {
        let mut part = Part::default();
        let mut index: HashMap<(u32, IVec3), u32> = HashMap::new();
        for triangle in triangles {
            let [a, b, c] = triangle.map(|v| mesh.positions_x2[v as usize].as_i64vec3());
            // Every triangle lies in an axis-aligned face (none is degenerate), so
            // the signs of its normal are the unit normal. In i64: the
            // product of two coordinates can pass i32.
            let normal = (b - a).cross(c - a).signum().as_ivec3();
            for v in *triangle {
                let i = *index.entry((v, normal)).or_insert_with(|| {
                    part.positions.push(mesh.position(v).map(|c| c * scale));
                    part.normals.push(normal.as_vec3().to_array());
                    u32::try_from(part.positions.len() - 1).unwrap_or(u32::MAX)
                });
                part.indices.push(i);
            }
        }
        part
    }
}

fn le_floats(vectors: &[[f32; 3]]) -> impl Iterator<Item = [u8; 4]> {
    vectors.as_flattened().iter().map(|c| c.to_le_bytes())
}

/// The material of palette entry `index`; adds the extensions it uses to
/// `extensions_used`. The kind and emission come from [`gpu_material`], so
/// media and emitters without emission are diffuse here as in the render.
fn material(palette: &Palette, index: u8, extensions_used: &mut BTreeSet<String>) -> Value {
    let [r, g, b, _] = palette.color(index).map(srgb_to_linear);
    let matl = gpu_material(palette, index);
    // A diffuse voxel is Lambertian: fully rough, not metal.
    let (metallic, roughness) = match matl.kind {
        MATERIAL_METAL => (matl.metalness, matl.roughness),
        MATERIAL_GLASS => (0.0, matl.roughness),
        _ => (0.0, 1.0),
    };
    let mut material = json!({
        "name": format!("palette_{index}"),
        "pbrMetallicRoughness": {"baseColorFactor": [r, g, b, 1.0], "metallicFactor": metallic, "roughnessFactor": roughness},
    });
    let mut extensions = Map::new();
    if matl.kind == MATERIAL_GLASS {
        // Transmission keeps alphaMode OPAQUE (the default): the surface is
        // see-through by refraction, not blended.
        extensions.insert("KHR_materials_transmission".into(), json!({"transmissionFactor": matl.transparency}));
        extensions.insert("KHR_materials_ior".into(), json!({"ior": matl.ior}));
    }
    if matl.kind == MATERIAL_EMIT {
        // emissiveFactor stops at 1; the extension multiplies it past that.
        material["emissiveFactor"] = json!([r, g, b].map(|c| c * matl.emission.min(1.0)));
        if matl.emission > 1.0 {
            extensions.insert("KHR_materials_emissive_strength".into(), json!({"emissiveStrength": matl.emission}));
        }
    }
    if !extensions.is_empty() {
        extensions_used.extend(extensions.keys().cloned());
        material["extensions"] = Value::Object(extensions);
    }
    material
}

/// A palette byte, sRGB-encoded as MagicaVoxel and the colour picker show
/// it, as the linear value glTF's colour factors hold (a viewer encodes it
/// back, so it shows the palette colour). Computed in f64 and rounded
/// once: `f32::powf` differs by an ulp between the desktop's libm and the
/// browser build's, and the same file must export the same bytes on both.
fn srgb_to_linear(byte: u8) -> f32 {
    let c = f64::from(byte) / 255.0;
    let linear = if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    linear as f32
}

/// The GLB container: a 12-byte header, the JSON chunk padded with spaces
/// and the binary chunk (left out when empty) padded with zeros, each to
/// 4 bytes. `None` when a length passes 32 bits.
fn container(json: &[u8], bin: &[u8]) -> Option<Vec<u8>> {
    let json_length = u32::try_from(json.len().next_multiple_of(4)).ok()?;
    let bin_length = u32::try_from(bin.len().next_multiple_of(4)).ok()?;
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin_length };
    let total = 12u32.checked_add(8 + json_length)?.checked_add(bin_chunk)?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(total.to_le_bytes());
    let mut chunk = |kind: &[u8; 4], data: &[u8], length: u32, pad: u8| {
        out.extend(length.to_le_bytes());
        out.extend(kind);
        out.extend(data);
        out.resize(out.len() + length as usize - data.len(), pad);
    };
    chunk(b"JSON", json, json_length, b' ');
    if !bin.is_empty() {
        chunk(b"BIN\0", bin, bin_length, 0);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_ends_and_middle() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert_eq!(srgb_to_linear(255), 1.0);
        assert!((srgb_to_linear(188) - 0.5).abs() < 0.005);
    }

    #[test]
    fn chunks_are_aligned_and_padded() {
        let glb = container(b"{}", &[1, 2, 3, 4, 5]).unwrap();
        assert_eq!(glb.len(), 12 + 8 + 4 + 8 + 8);
        assert_eq!(&glb[8..12], &(glb.len() as u32).to_le_bytes());
        assert_eq!(&glb[12..24], b"\x04\0\0\0JSON{}  ");
        assert_eq!(&glb[24..40], b"\x08\0\0\0BIN\0\x01\x02\x03\x04\x05\0\0\0");
    }
}
