//! What an export writes, before any format: each model's mesh once, and
//! the parts that place them. A file of one model is one part, `voxels`, at
//! its place. A scene of objects is a part per visible object, named by its
//! path of named transforms, placed by its exact cell map (or a freely
//! turned one by its rigid map, as it is traced), and sharing its model's
//! mesh with every other placement of that model (a reference).

use std::collections::HashMap;

use glam::{DMat3, DQuat, DVec3, IVec3};

use super::greedy::{VoxelMesh, mesh_within_budget};
use super::{ExportError, check_scale};
use crate::scene::Scene;
use crate::scene::graph::Node;
use crate::scene::objects::Objects;
use crate::scene::transform::Placing;

/// The meshes and the parts that place them.
pub struct Exported {
    pub meshes: Vec<NamedMesh>,
    pub parts: Vec<Part>,
    /// The scene has objects (a file of one model writes exactly what it
    /// always wrote: no object names, no groups).
    pub objects: bool,
    /// Frames a second of the animation the parts' motions play.
    pub fps: u32,
}

pub struct NamedMesh {
    pub name: String,
    pub mesh: VoxelMesh,
}

/// One placement of a mesh.
pub struct Part {
    /// The groups above it, outermost first (the named transforms above
    /// its own), and its own name.
    pub groups: Vec<String>,
    pub name: String,
    pub mesh: usize,
    pub place: Place,
    /// Where it is at each frame of the document's range, when it moves.
    pub motion: Option<Motion>,
}

/// An object's places over the frames of the document's range: at every
/// frame where its place changes and the frame before, so that a sampler
/// gives its place at every frame exactly.
pub struct Motion {
    /// Frames counted from the range's first, and the place at each.
    pub samples: Vec<(u32, Place)>,
    /// Its own keys are all `step` (held until the next), else moving on.
    pub step: bool,
}

/// Most frames of an animation an export samples.
pub const MAX_EXPORT_FRAMES: u32 = 4096;

impl Part {
    /// Its groups and name joined by `/`, as `info --objects` prints them,
    /// on one line (the text formats name it in a line of their own).
    pub fn path(&self) -> String {
        let mut path = self.groups.join("/");
        if !path.is_empty() {
            path.push('/');
        }
        (path + &self.name).replace(['\n', '\r'], " ")
    }
}

/// How a mesh's vertices (in half voxels) land in the world (y up): by a
/// signed permutation and an offset, exactly, or for a freely turned object
/// by its rigid map (`world = m · p + t`, in half voxels), compared bit for
/// bit.
#[derive(Clone, Copy, Debug)]
pub enum Place {
    Cells([(usize, i32, i32); 3]),
    Turned { m: DMat3, t: DVec3 },
}

impl PartialEq for Place {
    fn eq(&self, other: &Place) -> bool {
        match (self, other) {
            (Place::Cells(a), Place::Cells(b)) => a == b,
            (Place::Turned { m: a, t: s }, Place::Turned { m: b, t: u }) => {
                a.to_cols_array().map(f64::to_bits) == b.to_cols_array().map(f64::to_bits)
                    && s.to_array().map(f64::to_bits) == u.to_array().map(f64::to_bits)
            }
            _ => false,
        }
    }
}

impl Place {
    pub const IDENTITY: Place = Place::Cells([(0, 1, 0), (1, 1, 0), (2, 1, 0)]);

    fn of_placing(placing: &Placing) -> Place {
        match placing {
            Placing::Cells(map) => Place::Cells(map.half_voxel_rows()),
            Placing::Turned(map) => {
                let (m, at) = map.to_world();
                Place::Turned { m, t: at * 2.0 }
            }
        }
    }

    /// Whether it is a free turn's.
    pub fn is_turned(&self) -> bool {
        matches!(self, Place::Turned { .. })
    }

    /// The linear part as a matrix.
    fn linear(&self) -> DMat3 {
        match *self {
            Place::Cells(rows) => {
                let mut columns = [DVec3::ZERO; 3];
                for (row, (axis, sign, _)) in rows.into_iter().enumerate() {
                    columns[axis][row] = f64::from(sign);
                }
                DMat3::from_cols(columns[0], columns[1], columns[2])
            }
            Place::Turned { m, .. } => m,
        }
    }

    /// The translation, in half voxels.
    fn offset(&self) -> DVec3 {
        match *self {
            Place::Cells(rows) => DVec3::from_array(rows.map(|(_, _, offset)| f64::from(offset))),
            Place::Turned { t, .. } => t,
        }
    }

    /// The world position of a vertex at `p`, both in half voxels (exact
    /// whole numbers but through a free turn).
    pub fn apply_x2(&self, p: IVec3) -> DVec3 {
        match *self {
            Place::Cells(rows) => {
                IVec3::from_array(rows.map(|(axis, sign, offset)| sign * p[axis] + offset)).as_dvec3()
            }
            Place::Turned { m, t } => m * p.as_dvec3() + t,
        }
    }

    /// Whether the map mirrors (its determinant is −1): a mesh placed by it
    /// must wind its triangles the other way to stay outward. (glTF does
    /// this itself from the node's matrix.)
    pub fn mirrors(&self) -> bool {
        self.linear().determinant() < 0.0
    }

    /// A triangle's corners in the order that keeps it outward once placed.
    pub fn wind(&self, [a, b, c]: [u32; 3]) -> [u32; 3] {
        if self.mirrors() { [a, c, b] } else { [a, b, c] }
    }

    /// The map as translation, rotation (a unit quaternion) and scale, as
    /// glTF animates them: a map that mirrors is a turn after a mirror of x
    /// (scale −1 on x).
    pub fn trs(&self, scale: f32) -> ([f32; 3], [f32; 4], [f32; 3]) {
        let flip = if self.mirrors() { -1.0 } else { 1.0 };
        let linear = self.linear();
        let turn = DMat3::from_cols(linear.x_axis * flip, linear.y_axis, linear.z_axis);
        let rotation = DQuat::from_mat3(&turn).normalize().as_quat();
        let translation = (self.offset() * 0.5 * f64::from(scale)).as_vec3();
        (translation.to_array(), rotation.to_array(), [flip as f32, 1.0, 1.0])
    }

    /// The map as a column-major 4×4 matrix on coordinates scaled by
    /// `scale` (glTF's `matrix`); `None` for the identity.
    pub fn matrix(&self, scale: f32) -> Option<[f32; 16]> {
        if *self == Place::IDENTITY {
            return None;
        }
        let mut m = glam::Mat4::from_mat3(self.linear().as_mat3()).to_cols_array();
        m[12..15].copy_from_slice(&(self.offset() * 0.5 * f64::from(scale)).as_vec3().to_array());
        Some(m)
    }
}

impl Exported {
    /// Meshes `scene`: the one drawn octree, or each model an object shows;
    /// with `animated`, each moving object's motion too.
    ///
    /// # Errors
    /// A scale that no vertex coordinate survives, the memory budget, an
    /// animation longer than [`MAX_EXPORT_FRAMES`].
    pub fn of(scene: &Scene, scale: f32, animated: bool) -> Result<Exported, ExportError> {
        check_scale(scene.drawn(), scale)?;
        let Some(objects) = scene.objects() else {
            let mesh = NamedMesh { name: "voxels".into(), mesh: mesh_within_budget(scene.drawn())? };
            let part =
                Part { groups: Vec::new(), name: "voxels".into(), mesh: 0, place: Place::IDENTITY, motion: None };
            return Ok(Exported { meshes: vec![mesh], parts: vec![part], objects: false, fps: 0 });
        };
        let mut meshes = Vec::new();
        let mut mesh_of_model: HashMap<usize, usize> = HashMap::new();
        let mut parts = Vec::new();
        let mut motions = if animated { motions(objects)? } else { HashMap::new() };
        for (index, object) in objects.list().iter().enumerate() {
            if object.hidden {
                continue;
            }
            let model = object.placement.model;
            let mesh = match mesh_of_model.get(&model) {
                Some(&mesh) => mesh,
                None => {
                    let tree = &objects.models[model].tree;
                    check_scale(tree, scale)?;
                    meshes.push(NamedMesh { name: format!("model {model}"), mesh: mesh_within_budget(tree)? });
                    mesh_of_model.insert(model, meshes.len() - 1);
                    meshes.len() - 1
                }
            };
            let (groups, name) = names(objects, index);
            let motion = motions.remove(&index);
            parts.push(Part { groups, name, mesh, place: Place::of_placing(&objects.map(index)), motion });
        }
        let fps = objects.graph.as_ref().map_or(crate::scene::anim::DEFAULT_FPS, |g| g.animation.fps());
        Ok(Exported { meshes, parts, objects: true, fps })
    }

    /// Palette indices any mesh uses, in order.
    pub fn colors(&self) -> std::collections::BTreeSet<u8> {
        self.meshes.iter().flat_map(|m| m.mesh.triangles.iter().map(|(_, c)| *c)).collect()
    }

    /// Triangles and vertices written, and the triangles of one quad per
    /// face, over every part.
    pub fn counts(&self) -> (usize, usize, u64) {
        self.parts.iter().fold((0, 0, 0), |(t, v, n), part| {
            let mesh = &self.meshes[part.mesh].mesh;
            (t + mesh.triangles.len(), v + mesh.positions_x2.len(), n + mesh.exposed_faces * 2)
        })
    }
}

/// The motion of every object that moves over the document's range (see
/// [`Motion`]), by object index.
fn motions(objects: &Objects) -> Result<HashMap<usize, Motion>, ExportError> {
    let (first, last) = objects.frame_range();
    if first == last || objects.graph.is_none() {
        return Ok(HashMap::new());
    }
    if last - first >= MAX_EXPORT_FRAMES {
        return Err(ExportError::TooManyFrames { frames: u64::from(last - first) + 1, most: MAX_EXPORT_FRAMES });
    }
    let mut places: Vec<Vec<Place>> = vec![Vec::new(); objects.list().len()];
    for frame in first..=last {
        let maps = objects.maps_at(frame as usize).map_err(|e| ExportError::Frame { frame, reason: e.to_string() })?;
        for (row, map) in places.iter_mut().zip(&maps) {
            row.push(Place::of_placing(map));
        }
    }
    let mut motions = HashMap::new();
    for (index, row) in places.into_iter().enumerate() {
        if row.windows(2).all(|w| w[0] == w[1]) {
            continue;
        }
        let kept =
            (0..row.len()).filter(|&k| k == 0 || row[k] != row[k - 1] || row.get(k + 1).is_some_and(|n| *n != row[k]));
        let samples = kept.map(|k| (k as u32, row[k])).collect();
        motions.insert(index, Motion { samples, step: own_keys_step(objects, index) });
    }
    Ok(motions)
}

/// Whether every key of object `index`'s own transform is held (`step`).
fn own_keys_step(objects: &Objects, index: usize) -> bool {
    use crate::scene::anim::Ease;
    use crate::scene::graph::NodeKind;
    let Ok(node) = objects.transform_node(index) else { return false };
    let NodeKind::Transform { frames, .. } = &node.kind else { return false };
    !frames.is_empty() && frames.iter().all(|k| Ease::of(k, node.id) == Ok(Ease::Step))
}

/// Object `index`'s groups and name: its path of named transforms, of which
/// the last is its own when its transform is named; `object N` otherwise.
fn names(objects: &Objects, index: usize) -> (Vec<String>, String) {
    let path = objects.path(index);
    let mut groups: Vec<String> = path.split('/').filter(|s| !s.is_empty()).map(str::to_owned).collect();
    let own = objects.transform_node(index).ok().and_then(Node::name);
    match own {
        Some(own) if groups.last().is_some_and(|last| last == own) => {
            groups.pop();
            (groups, own.to_owned())
        }
        _ => (groups, format!("object {index}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The matrix takes each cube's corners where the cell map takes the
    /// cell: for every one of the 48 turns and mirrors.
    #[test]
    fn the_place_of_a_cell_map_moves_cubes_as_cells() {
        use crate::scene::transform::{Placement, Rotation, Transform};
        for byte in 0..=u8::MAX {
            let Some(rotation) = Rotation::from_byte(byte) else { continue };
            let transform = Transform { rotation, translation: [5, -3, 7] };
            let placement = Placement { model: 0, transform, centred: true, turned: None };
            let map = placement.cell_map([4, 6, 3]).unwrap();
            let place = Place::of_placing(&Placing::Cells(map));
            let m = place.matrix(1.0).unwrap_or([1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.]);
            let det =
                glam::Mat3::from_cols_slice(&[m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]]).determinant();
            assert_eq!(place.mirrors(), det < 0.0, "rotation byte {byte}");
            for v in [IVec3::new(0, 0, 0), IVec3::new(3, 5, 2), IVec3::new(1, 4, 0)] {
                let cell = map.apply(v);
                let corners: Vec<IVec3> = (0..8)
                    .map(|k| place.apply_x2(2 * v + 2 * IVec3::new(k & 1, (k >> 1) & 1, k >> 2)).as_ivec3())
                    .collect();
                let lo = corners.iter().copied().reduce(IVec3::min).unwrap();
                let hi = corners.iter().copied().reduce(IVec3::max).unwrap();
                assert_eq!((lo, hi), (2 * cell, 2 * cell + 2), "rotation byte {byte}, cell {v}");
                // The matrix does what apply_x2 does.
                let p = (2 * v + IVec3::ONE).as_vec3() * 0.5;
                let q = [0, 1, 2].map(|r| m[r] * p.x + m[4 + r] * p.y + m[8 + r] * p.z + m[12 + r]);
                assert_eq!(q, (cell.as_vec3() + 0.5).to_array(), "rotation byte {byte}, cell {v}");
            }
        }
    }
}
