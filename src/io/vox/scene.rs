//! Scene-graph traversal: which model goes where, with which rotation.
//!
//! MagicaVoxel (and opengametools' `ogt_vox.h`, which reads it) places a model
//! by a transform `world = R · p + t` applied to *model-space geometry*, where
//! model space has its origin at the pivot `floor(size / 2)`. `R` is a signed
//! permutation matrix (the `_r` byte, rows as stored), `t` the `_t`
//! translation, and transforms compose child first: `ogt_vox` flattens an
//! instance with `transform_multiply(instance, group)`, i.e. `G · I`.
//!
//! A voxel is the unit cube `[v, v + 1)`. In model space it is
//! `[v − pivot, v − pivot + 1)`; after `R` and `t` it is again a unit cube, and
//! the voxel's scene position is that cube's minimum corner. Row by row, with
//! `R[i]` picking axis `j` with sign `s`:
//!
//! ```text
//! scene[i] = t[i] + (v[j] − pivot[j])        if s = +1
//! scene[i] = t[i] − (v[j] − pivot[j]) − 1    if s = −1
//! ```
//!
//! (equivalently `floor(R · (v − pivot + ½) + t)`). This is exact integer
//! arithmetic, so every voxel lands on the cell MagicaVoxel draws it in.

use std::collections::HashMap;

use dot_vox::{Dict, SceneNode};

use super::{MAX_INSTANCES, MAX_NODE_VISITS, MAX_VOXELS, VoxError};

/// A signed permutation matrix: row `i` has `sign[i]` in column `axis[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Rotation {
    axis: [usize; 3],
    sign: [i64; 3],
}

impl Rotation {
    pub(super) const IDENTITY: Rotation = Rotation {
        axis: [0, 1, 2],
        sign: [1, 1, 1],
    };

    /// Decodes MagicaVoxel's `_r` byte; `None` when the two stored column
    /// indices are out of range or equal.
    pub(super) fn from_byte(byte: u8) -> Option<Rotation> {
        let first = usize::from(byte & 3);
        let second = usize::from((byte >> 2) & 3);
        if first > 2 || second > 2 || first == second {
            return None;
        }
        let sign = |bit: u8| if byte & (1 << bit) == 0 { 1 } else { -1 };
        Some(Rotation {
            axis: [first, second, 3 - first - second],
            sign: [sign(4), sign(5), sign(6)],
        })
    }

    /// `self · other`: apply `other` first.
    fn times(self, other: Rotation) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for row in 0..3 {
            let picked = self.axis[row];
            out.axis[row] = other.axis[picked];
            out.sign[row] = self.sign[row] * other.sign[picked];
        }
        out
    }

    fn apply(self, v: [i64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|row| self.sign[row] * v[self.axis[row]])
    }
}

/// A rigid transform of the MagicaVoxel scene: `p ↦ rotation · p + translation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Transform {
    pub rotation: Rotation,
    pub translation: [i64; 3],
}

impl Transform {
    pub(super) const IDENTITY: Transform = Transform {
        rotation: Rotation::IDENTITY,
        translation: [0, 0, 0],
    };

    /// The transform that applies `child` first, then `self`.
    fn compose(self, child: Transform) -> Transform {
        let moved = self.rotation.apply(child.translation);
        Transform {
            rotation: self.rotation.times(child.rotation),
            translation: [0, 1, 2].map(|i| moved[i] + self.translation[i]),
        }
    }
}

/// One model placed in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Placement {
    /// Index into the file's models.
    pub model: usize,
    pub transform: Transform,
    /// Whether model space is centred on the pivot `size / 2` (scene-graph
    /// files) or is the model's own grid (files without a scene graph).
    pub centred: bool,
}

impl Placement {
    /// Scene position (MagicaVoxel axes) of the voxel at `v` in a model of
    /// `size`, by the unit-cube rule in the module documentation.
    pub(super) fn place(&self, v: [u8; 3], size: [u32; 3]) -> [i64; 3] {
        let local = [0, 1, 2].map(|axis| {
            let pivot = if self.centred {
                i64::from(size[axis] / 2)
            } else {
                0
            };
            i64::from(v[axis]) - pivot
        });
        let Transform {
            rotation,
            translation,
        } = self.transform;
        [0, 1, 2].map(|row| {
            let along = local[rotation.axis[row]];
            let offset = if rotation.sign[row] > 0 {
                along
            } else {
                -along - 1
            };
            translation[row] + offset
        })
    }
}

/// Walks the scene graph from node 0 and returns every shape placement.
///
/// `node_ids[k]` is the id of `nodes[k]`; `model_voxels[m]` the voxel count of
/// model `m`, used to refuse scenes over [`MAX_VOXELS`] before building them.
/// `frame` picks the keyframe of animated transforms and shapes (`_f`).
pub(super) fn placements(
    nodes: &[SceneNode],
    node_ids: &[u32],
    model_voxels: &[usize],
    frame: usize,
) -> Result<Vec<Placement>, VoxError> {
    let index_of = index_nodes(node_ids)?;
    let lookup = |id: u32, parent: Option<u32>| {
        index_of.get(&id).copied().ok_or_else(|| {
            VoxError::BadSceneGraph(match parent {
                Some(parent) => format!("node {parent} refers to missing node {id}"),
                None => "there is no root node 0".to_owned(),
            })
        })
    };

    enum Step {
        Enter {
            id: u32,
            parent: Option<u32>,
            transform: Transform,
        },
        Leave {
            index: usize,
        },
    }
    let mut on_path = vec![false; nodes.len()];
    let mut stack = vec![Step::Enter {
        id: 0,
        parent: None,
        transform: Transform::IDENTITY,
    }];
    let mut visits = 0usize;
    let mut voxels = 0usize;
    let mut out = Vec::new();
    while let Some(step) = stack.pop() {
        let (id, parent, transform) = match step {
            Step::Leave { index } => {
                on_path[index] = false;
                continue;
            }
            Step::Enter {
                id,
                parent,
                transform,
            } => (id, parent, transform),
        };
        let index = lookup(id, parent)?;
        if on_path[index] {
            return Err(VoxError::SceneCycle(id));
        }
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(VoxError::BadSceneGraph(format!(
                "more than {MAX_NODE_VISITS} node visits (nodes shared along too many paths)"
            )));
        }
        on_path[index] = true;
        stack.push(Step::Leave { index });
        match &nodes[index] {
            SceneNode::Transform { frames, child, .. } => {
                let picked = pick_keyframe(frames.iter().map(|f| &f.attributes), frame, id)?;
                let local = match picked {
                    Some(k) => parse_transform(&frames[k].attributes, id)?,
                    None => Transform::IDENTITY,
                };
                let transform = transform.compose(local);
                stack.push(Step::Enter {
                    id: *child,
                    parent: Some(id),
                    transform,
                });
            }
            SceneNode::Group { children, .. } => {
                // Reversed so that children are visited in file order.
                for &child in children.iter().rev() {
                    stack.push(Step::Enter {
                        id: child,
                        parent: Some(id),
                        transform,
                    });
                }
            }
            SceneNode::Shape { models, .. } => {
                let picked = pick_keyframe(models.iter().map(|m| &m.attributes), frame, id)?;
                let Some(k) = picked else { continue };
                let model = usize::try_from(models[k].model_id).unwrap_or(usize::MAX);
                let count = model_voxels.get(model).copied().ok_or_else(|| {
                    VoxError::BadSceneGraph(format!(
                        "shape node {id} uses model {model} but the file has {} models",
                        model_voxels.len()
                    ))
                })?;
                voxels = voxels.saturating_add(count);
                if voxels > MAX_VOXELS {
                    return Err(VoxError::TooManyVoxels {
                        limit: MAX_VOXELS,
                        found: voxels,
                    });
                }
                if out.len() >= MAX_INSTANCES {
                    return Err(VoxError::BadSceneGraph(format!(
                        "more than {MAX_INSTANCES} model placements"
                    )));
                }
                out.push(Placement {
                    model,
                    transform,
                    centred: true,
                });
            }
        }
    }
    Ok(out)
}

fn index_nodes(node_ids: &[u32]) -> Result<HashMap<u32, usize>, VoxError> {
    let mut index_of = HashMap::with_capacity(node_ids.len());
    for (index, &id) in node_ids.iter().enumerate() {
        if index_of.insert(id, index).is_some() {
            return Err(VoxError::BadSceneGraph(format!(
                "node id {id} is used twice"
            )));
        }
    }
    Ok(index_of)
}

/// Index of the keyframe shown at `frame`: the last one whose `_f` is at
/// most `frame` (a missing `_f` counts as 0), else the first; `None` when
/// there are none. MagicaVoxel interpolates translations between keyframes;
/// octovox snaps to the earlier one.
fn pick_keyframe<'a>(
    keyframes: impl Iterator<Item = &'a Dict>,
    frame: usize,
    node: u32,
) -> Result<Option<usize>, VoxError> {
    let mut best: Option<(usize, usize)> = None;
    let mut any = false;
    for (k, attributes) in keyframes.enumerate() {
        any = true;
        let at = match attributes.get("_f") {
            None => 0,
            Some(text) => text.trim().parse::<usize>().map_err(|_| {
                VoxError::BadSceneGraph(format!(
                    "node {node} has a malformed frame index _f={text:?}"
                ))
            })?,
        };
        if at <= frame && best.is_none_or(|(best_at, _)| at > best_at) {
            best = Some((at, k));
        }
    }
    Ok(best.map(|(_, k)| k).or(any.then_some(0)))
}

/// Parses a keyframe's `_r` rotation byte and `_t` translation.
fn parse_transform(attributes: &Dict, node: u32) -> Result<Transform, VoxError> {
    let rotation = match attributes.get("_r") {
        None => Rotation::IDENTITY,
        Some(text) => text
            .trim()
            .parse::<u8>()
            .ok()
            .and_then(Rotation::from_byte)
            .ok_or_else(|| {
                VoxError::BadSceneGraph(format!("node {node} has an invalid rotation _r={text:?}"))
            })?,
    };
    let translation = match attributes.get("_t") {
        None => [0, 0, 0],
        Some(text) => parse_translation(text).ok_or_else(|| {
            VoxError::BadSceneGraph(format!(
                "node {node} has a malformed translation _t={text:?}"
            ))
        })?,
    };
    Ok(Transform {
        rotation,
        translation,
    })
}

fn parse_translation(text: &str) -> Option<[i64; 3]> {
    let mut parts = text
        .split_ascii_whitespace()
        .map(|p| p.parse::<i32>().ok().map(i64::from));
    let t = [parts.next()??, parts.next()??, parts.next()??];
    parts.next().is_none().then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `_r` = 4 is the identity (row 0 → x, row 1 → y).
    #[test]
    fn rotation_byte_four_is_identity() {
        assert_eq!(Rotation::from_byte(4), Some(Rotation::IDENTITY));
        assert_eq!(Rotation::from_byte(0), None);
        assert_eq!(Rotation::from_byte(3), None);
    }

    /// Composition matches plain matrix products on all 48 signed permutations.
    #[test]
    fn composition_matches_matrix_product() {
        let all: Vec<Rotation> = (0..=127u8).filter_map(Rotation::from_byte).collect();
        assert_eq!(all.len(), 48);
        let probe = [1, 10, 100];
        for &a in &all {
            for &b in &all {
                assert_eq!(a.times(b).apply(probe), a.apply(b.apply(probe)));
            }
        }
    }

    /// A 3-wide model mirrored in x covers the mirror image of its cells:
    /// unrotated it spans x in [-1, 1], mirrored [-1, 1] too, with voxel 0 at +1.
    #[test]
    fn flipped_axis_maps_cells_not_corners() {
        let flip_x = Rotation {
            axis: [0, 1, 2],
            sign: [-1, 1, 1],
        };
        let placement = Placement {
            model: 0,
            transform: Transform {
                rotation: flip_x,
                translation: [0, 0, 0],
            },
            centred: true,
        };
        let size = [3, 1, 1];
        assert_eq!(placement.place([0, 0, 0], size), [0, 0, 0]);
        assert_eq!(placement.place([2, 0, 0], size), [-2, 0, 0]);
        // Even edges: 4 wide spans [-2, 1] both ways.
        let size = [4, 1, 1];
        assert_eq!(placement.place([0, 0, 0], size), [1, 0, 0]);
        assert_eq!(placement.place([3, 0, 0], size), [-2, 0, 0]);
    }

    /// A quarter turn about z (x → y, y → −x) of a 2×3 footprint centred at
    /// (1, 1): cell centres (v + ½ − pivot) rotate exactly.
    #[test]
    fn quarter_turn_rotates_cell_centres() {
        // Rows: world x = −v.y, world y = v.x, world z = v.z.
        let quarter = Rotation {
            axis: [1, 0, 2],
            sign: [-1, 1, 1],
        };
        let placement = Placement {
            model: 0,
            transform: Transform {
                rotation: quarter,
                translation: [10, 20, 30],
            },
            centred: true,
        };
        let size = [2, 3, 1];
        for x in 0..2u8 {
            for y in 0..3u8 {
                let centre = [f64::from(x) + 0.5 - 1.0, f64::from(y) + 0.5 - 1.0];
                let rotated = [-centre[1] + 10.0, centre[0] + 20.0];
                let expected = [rotated[0].floor(), rotated[1].floor()].map(|c| c as i64);
                let got = placement.place([x, y, 0], size);
                assert_eq!([got[0], got[1]], expected, "voxel ({x}, {y})");
            }
        }
    }

    #[test]
    fn translation_parsing_is_strict() {
        assert_eq!(parse_translation("1 -2  3"), Some([1, -2, 3]));
        assert_eq!(parse_translation("1 2"), None);
        assert_eq!(parse_translation("1 2 3 4"), None);
        assert_eq!(parse_translation("1 2 x"), None);
    }
}
