//! Edits as plain data, the undo/redo history, and everything that builds
//! edits: brushes and clicks, mirror planes, lines, fills, extrudes and box
//! selections.
//!
//! The mouse, the panels, replay scripts and undo all produce an [`Edit`];
//! applying one is the single path from "the user wants this" to changed
//! octree slots (which the node pool then flushes to the GPU) or a changed
//! palette entry. This room builds on `scene` and knows no editor, script
//! or window.

pub mod brush;
pub mod extrude;
pub mod fill;
pub mod mirror;
pub mod selection;

use std::collections::VecDeque;

use crate::scene::objects::{GraphChange, Model};
use crate::scene::{EditError, Material, ObjectRefusal, Op, Patch, Scene, Shape};

/// One change to the scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Edit {
    /// Apply a brush shape with an operation.
    Brush { shape: Shape, op: Op },
    /// Empty the box `min..=max` (a selection's delete, cut or move): in a
    /// scene of objects, in every object it covers (see
    /// [`Edit::resolved_all`]), not only one.
    Clear { min: glam::IVec3, max: glam::IVec3 },
    /// A brush in object `object`'s model (what a brush becomes in a scene
    /// of objects: see [`Edit::resolved`]).
    InObject { object: usize, shape: Shape, op: Op },
    /// A brush in object `object`'s model cells (as its .vox numbers them).
    InModel { object: usize, shape: Shape, op: Op },
    /// Put back cells saved by an earlier edit (what undo sends).
    Restore(Patch),
    /// Put back cells of model `model` (what undo sends for `InObject`).
    RestoreModel { model: usize, patch: Patch },
    /// A change to the scene graph of a scene of objects: hide, show,
    /// move, turn, name, duplicate or delete objects, name or hide layers.
    Graph(Box<GraphChange>),
    /// Store one more model (a copy an object is about to place).
    AddModel(Box<Model>),
    /// Take the last model back out (the undo of `AddModel`).
    PopModel,
    /// Give a palette entry (1..=255) a colour and a material: every voxel of
    /// that index changes look at once.
    Palette { index: u8, color: [u8; 4], material: Box<Material> },
}

impl Edit {
    /// The edit as it applies to `scene`: in a scene of objects a brush goes
    /// into the model of the object [`Objects::target_at`] names at the
    /// brush's centre, fixed now so that a redo lands where the edit did.
    ///
    /// [`Objects::target_at`]: crate::scene::objects::Objects::target_at
    pub fn resolved(self, scene: &Scene) -> Edit {
        match (self, scene.objects()) {
            (Edit::Brush { shape, op }, Some(objects)) => {
                let (lo, hi) = shape.bounds();
                match objects.target_at(lo + (hi - lo) / 2) {
                    Some(object) => Edit::InObject { object, shape, op },
                    None => Edit::Brush { shape, op },
                }
            }
            (edit, _) => edit,
        }
    }

    /// The edits it becomes in `scene`: a [`Edit::Clear`] in a scene of
    /// objects empties the box in each shown object holding voxels there
    /// (issue 48, item 10: a delete around two objects emptied one), and is
    /// refused as a whole when one of them is locked; in a scene of one
    /// model it is a box brush. Any other edit is [`Edit::resolved`].
    ///
    /// # Errors
    /// A locked object with voxels in the box.
    pub fn resolved_all(self, scene: &Scene) -> Result<Vec<Edit>, EditError> {
        let Edit::Clear { min, max } = self else { return Ok(vec![self.resolved(scene)]) };
        let shape = Shape::Box { min, max };
        let Some(objects) = scene.objects() else { return Ok(vec![Edit::Brush { shape, op: Op::Remove }]) };
        let covered: Vec<usize> = (0..objects.list().len()).filter(|&i| objects.holds_voxels_in(i, min, max)).collect();
        if let Some(&locked) = covered.iter().find(|&&i| objects.locked(i)) {
            return Err(ObjectRefusal::LockedInBox(locked).into());
        }
        Ok(covered.into_iter().map(|object| Edit::InObject { object, shape, op: Op::Remove }).collect())
    }

    /// Applies the edit; returns the edit that undoes it. A refused edit
    /// changes nothing.
    pub fn apply(&self, scene: &mut Scene) -> Result<Edit, EditError> {
        match self {
            Edit::Clear { min, max } => {
                Ok(Edit::Restore(scene.apply_brush(&Shape::Box { min: *min, max: *max }, Op::Remove)?))
            }
            // In a scene of objects the drawn tree follows the models: a brush
            // must go into one (see `Edit::resolved`); the scene refuses it.
            Edit::Brush { shape, op } => Ok(Edit::Restore(scene.apply_brush(shape, *op)?)),
            Edit::Restore(patch) => Ok(Edit::Restore(scene.apply_patch(patch)?)),
            Edit::InObject { object, shape, op } => {
                let (model, patch) = scene.apply_in_object(*object, shape, *op)?;
                Ok(Edit::RestoreModel { model, patch })
            }
            Edit::InModel { object, shape, op } => {
                let (model, patch) = scene.apply_in_model(*object, shape, *op)?;
                Ok(Edit::RestoreModel { model, patch })
            }
            Edit::RestoreModel { model, patch } => {
                Ok(Edit::RestoreModel { model: *model, patch: scene.apply_model_patch(*model, patch)? })
            }
            Edit::Graph(change) => Ok(Edit::Graph(Box::new(scene.apply_graph_change(change)?))),
            Edit::AddModel(model) => {
                scene.push_model((**model).clone())?;
                Ok(Edit::PopModel)
            }
            Edit::PopModel => Ok(Edit::AddModel(Box::new(scene.pop_model()?))),
            Edit::Palette { index, color, material } => {
                if *index == 0 {
                    return Err(EditError::ZeroColor);
                }
                let i = usize::from(*index);
                let palette = &mut scene.palette;
                let old_color = std::mem::replace(&mut palette.colors[i], *color);
                let old_material = std::mem::replace(&mut palette.materials[i], (**material).clone());
                scene.touch();
                Ok(Edit::Palette { index: *index, color: old_color, material: Box::new(old_material) })
            }
        }
    }

    /// Peak bytes applying it may take: a brush as `Octree::apply_brush`
    /// estimates it (24 bytes per voxel of its surface), a restore twice its
    /// saved cells (they and the cells it replaces), plus the edit and its
    /// undo record themselves.
    pub fn estimated_bytes(&self) -> u64 {
        let own = 2 * std::mem::size_of::<Edit>() as u64;
        own.saturating_add(match self {
            Edit::Brush { shape, .. } | Edit::InObject { shape, .. } | Edit::InModel { shape, .. } => {
                shape.surface_voxels().saturating_mul(crate::scene::apply::EDIT_BYTES_PER_SURFACE_VOXEL)
            }
            Edit::Clear { min, max } => Shape::Box { min: *min, max: *max }
                .surface_voxels()
                .saturating_mul(crate::scene::apply::EDIT_BYTES_PER_SURFACE_VOXEL),
            Edit::Restore(patch) | Edit::RestoreModel { patch, .. } => 2 * patch.heap_bytes() as u64,
            Edit::AddModel(model) => 2 * model.tree.pool().live_bytes(),
            // The nodes it replaces and their undo copies, and the placements
            // walked again (composing goes cell by cell: see `Objects`).
            Edit::Graph(change) => change.estimated_bytes(),
            Edit::Palette { .. } | Edit::PopModel => 0,
        })
    }
}

/// One undo step: a single edit or a whole mouse stroke.
#[derive(Clone, Debug, Default)]
struct Step {
    edits: Vec<Edit>,
    inverses: Vec<Edit>,
    /// The state it leads to ([`History::state_id`]); 0 until recorded.
    id: u64,
}

impl Step {
    /// Memory its undo data holds.
    fn bytes(&self) -> usize {
        self.inverses.iter().map(edit_bytes).sum()
    }
}

/// Undo and redo stacks. Unlimited, except that the oldest steps are dropped
/// once the undo data passes `memory_limit_bytes`.
#[derive(Clone, Debug)]
pub struct History {
    done: VecDeque<Step>,
    /// Undo data held by `done` (kept as a running total, not re-summed).
    done_bytes: usize,
    undone: Vec<Step>,
    stroke: Option<Step>,
    pub memory_limit_bytes: usize,
    /// The last step id given out, and the state under the oldest step
    /// kept (the id of the last one dropped for memory, else 0).
    last_id: u64,
    floor_id: u64,
}

impl Default for History {
    fn default() -> History {
        History {
            done: VecDeque::new(),
            done_bytes: 0,
            undone: Vec::new(),
            stroke: None,
            memory_limit_bytes: 2 << 30,
            last_id: 0,
            floor_id: 0,
        }
    }
}

impl History {
    /// Applies an edit and records it (into the open stroke, if any).
    pub fn apply(&mut self, scene: &mut Scene, edit: Edit) -> Result<(), EditError> {
        self.apply_group(scene, vec![edit])
    }

    /// Applies several edits as one undo step (a fill), or as part of the
    /// open stroke. If one is refused, those before it are undone: the
    /// scene is as it was and the error is returned.
    pub fn apply_group(&mut self, scene: &mut Scene, edits: Vec<Edit>) -> Result<(), EditError> {
        // The whole step against the budget before any of it (an extrude
        // of a million faces is a million brushes, each under the budget).
        if edits.len() > 1 {
            let bytes = edits.iter().map(Edit::estimated_bytes).fold(0, u64::saturating_add);
            crate::budget::check(|| format!("a step of {} edits", edits.len()), bytes)?;
        }
        let mut step = Step::default();
        for edit in edits {
            let applied = edit.resolved_all(scene).and_then(|resolved| {
                for edit in resolved {
                    let inverse = edit.apply(scene)?;
                    step.edits.push(edit);
                    step.inverses.push(inverse);
                }
                Ok(())
            });
            if let Err(err) = applied {
                for inverse in step.inverses.iter().rev() {
                    // Undoing what was just done cannot need more room than doing it.
                    let _ = inverse.apply(scene);
                }
                return Err(err);
            }
        }
        if step.edits.is_empty() {
            return Ok(());
        }
        self.undone.clear();
        match &mut self.stroke {
            Some(stroke) => {
                stroke.edits.extend(step.edits);
                stroke.inverses.extend(step.inverses);
            }
            None => self.push(step),
        }
        Ok(())
    }

    /// Starts grouping edits into one undo step (a mouse drag).
    pub fn begin_stroke(&mut self) {
        self.end_stroke();
        self.stroke = Some(Step::default());
    }

    /// Whether a stroke is open: edits go into one step until it closes.
    pub fn stroke_open(&self) -> bool {
        self.stroke.is_some()
    }

    /// Closes the open stroke; an empty stroke leaves no step.
    pub fn end_stroke(&mut self) {
        if let Some(stroke) = self.stroke.take().filter(|s| !s.edits.is_empty()) {
            self.push(stroke);
        }
    }

    fn push(&mut self, mut step: Step) {
        if step.id == 0 {
            self.last_id += 1;
            step.id = self.last_id;
        }
        self.done_bytes += step.bytes();
        self.done.push_back(step);
        while self.done_bytes > self.memory_limit_bytes && self.done.len() > 1 {
            if let Some(oldest) = self.done.pop_front() {
                self.done_bytes -= oldest.bytes();
                self.floor_id = oldest.id;
            }
        }
    }

    /// Names the state the steps have led to: equal ids, equal scenes. A
    /// window compares it with the id it saved at, so undoing back to the
    /// saved state is not an unsaved change (and a redo back past it is).
    /// An open stroke with edits is a state of its own, never saved.
    pub fn state_id(&self) -> u64 {
        if self.stroke.as_ref().is_some_and(|s| !s.edits.is_empty()) {
            return u64::MAX;
        }
        self.done.back().map_or(self.floor_id, |step| step.id)
    }

    /// Undoes the last step; false when there is none.
    pub fn undo(&mut self, scene: &mut Scene) -> Result<bool, EditError> {
        self.end_stroke();
        let Some(mut step) = self.done.pop_back() else { return Ok(false) };
        self.done_bytes -= step.bytes();
        for inverse in step.inverses.iter().rev() {
            inverse.apply(scene)?;
        }
        step.inverses.clear();
        self.undone.push(step);
        Ok(true)
    }

    /// Re-applies the last undone step; false when there is none.
    pub fn redo(&mut self, scene: &mut Scene) -> Result<bool, EditError> {
        self.end_stroke();
        let Some(mut step) = self.undone.pop() else { return Ok(false) };
        for edit in &step.edits {
            step.inverses.push(edit.apply(scene)?);
        }
        self.push(step);
        Ok(true)
    }

    pub fn can_undo(&self) -> bool {
        !self.done.is_empty() || self.stroke.as_ref().is_some_and(|s| !s.edits.is_empty())
    }

    pub fn can_redo(&self) -> bool {
        !self.undone.is_empty()
    }

    /// Steps that undo and redo can take now (an open stroke counts as one).
    pub fn steps(&self) -> (usize, usize) {
        let stroke = self.stroke.as_ref().is_some_and(|s| !s.edits.is_empty());
        (self.done.len() + usize::from(stroke), self.undone.len())
    }

    /// Undo steps kept and the memory their undo data holds (what the
    /// budget `memory_limit_bytes` is checked against).
    pub fn usage(&self) -> (usize, usize) {
        (self.done.len(), self.done_bytes)
    }

    /// Forgets everything (a new scene was loaded).
    pub fn clear(&mut self) {
        self.done.clear();
        self.done_bytes = 0;
        self.undone.clear();
        self.stroke = None;
        // A fresh floor: the state now is none that an id named before.
        self.last_id += 1;
        self.floor_id = self.last_id;
    }
}

fn edit_bytes(edit: &Edit) -> usize {
    match edit {
        Edit::Brush { .. } | Edit::Clear { .. } | Edit::InObject { .. } | Edit::InModel { .. } | Edit::PopModel => {
            std::mem::size_of::<Edit>()
        }
        Edit::Graph(change) => change.heap_bytes(),
        Edit::AddModel(model) => usize::try_from(model.tree.pool().live_bytes()).unwrap_or(usize::MAX),
        Edit::Restore(patch) | Edit::RestoreModel { patch, .. } => patch.heap_bytes(),
        Edit::Palette { material, .. } => {
            std::mem::size_of::<Edit>() + material.params.iter().map(|(k, v)| k.len() + v.len() + 48).sum::<usize>()
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use glam::IVec3;

    fn place(history: &mut History, scene: &mut Scene, at: i32) {
        history.apply(scene, Edit::Brush { shape: Shape::Voxel(IVec3::new(at, 0, 0)), op: Op::Place(3) }).unwrap();
    }

    /// Issue 47, item 7: undoing back to the saved state still asked to
    /// save. The state id names where the steps have led: undo back to it
    /// gives the same id, a new edit after an undo another one, and an open
    /// stroke with edits is never a saved state.
    #[test]
    fn the_state_id_comes_back_with_undo_and_never_repeats_for_new_edits() {
        let (mut history, mut scene) = (History::default(), Scene::default());
        history.clear();
        let loaded = history.state_id();
        place(&mut history, &mut scene, 0);
        let saved = history.state_id();
        assert_ne!(saved, loaded);
        place(&mut history, &mut scene, 1);
        assert_ne!(history.state_id(), saved);
        history.undo(&mut scene).unwrap();
        assert_eq!(history.state_id(), saved, "undo back to the saved state");
        history.undo(&mut scene).unwrap();
        assert_eq!(history.state_id(), loaded);
        history.redo(&mut scene).unwrap();
        assert_eq!(history.state_id(), saved, "redo to it");
        place(&mut history, &mut scene, 2);
        let other = history.state_id();
        history.undo(&mut scene).unwrap();
        place(&mut history, &mut scene, 5);
        assert!(![loaded, saved, other].contains(&history.state_id()), "a new edit is a new state");
        history.begin_stroke();
        place(&mut history, &mut scene, 7);
        assert_eq!(history.state_id(), u64::MAX);
        history.end_stroke();
        assert_ne!(history.state_id(), u64::MAX);
        history.clear();
        assert!(![loaded, saved, other].contains(&history.state_id()), "a new scene is none of the old states");
    }
}
