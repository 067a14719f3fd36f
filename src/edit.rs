//! Edits as plain data, and the undo/redo history.
//!
//! The mouse, replay scripts and undo all produce an [`Edit`]; applying one is
//! the single path from "the user wants this" to changed octree slots (which
//! the node pool then flushes to the GPU).

use std::collections::VecDeque;

use crate::scene::{EditError, Octree, Op, Patch, Shape};

/// One change to the scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Edit {
    /// Apply a brush shape with an operation.
    Brush { shape: Shape, op: Op },
    /// Put back cells saved by an earlier edit (what undo sends).
    Restore(Patch),
}

impl Edit {
    /// Applies the edit; returns the edit that undoes it.
    pub fn apply(&self, tree: &mut Octree) -> Result<Edit, EditError> {
        let patch = match self {
            Edit::Brush { shape, op } => tree.apply_brush(shape, *op)?,
            Edit::Restore(patch) => tree.apply_patch(patch)?,
        };
        Ok(Edit::Restore(patch))
    }
}

/// One undo step: a single edit or a whole mouse stroke.
#[derive(Clone, Debug, Default)]
struct Step {
    edits: Vec<Edit>,
    inverses: Vec<Edit>,
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
}

impl Default for History {
    fn default() -> History {
        History { done: VecDeque::new(), done_bytes: 0, undone: Vec::new(), stroke: None, memory_limit_bytes: 2 << 30 }
    }
}

impl History {
    /// Applies an edit and records it (into the open stroke, if any).
    pub fn apply(&mut self, tree: &mut Octree, edit: Edit) -> Result<(), EditError> {
        let inverse = edit.apply(tree)?;
        self.undone.clear();
        match &mut self.stroke {
            Some(stroke) => {
                stroke.edits.push(edit);
                stroke.inverses.push(inverse);
            }
            None => self.push(Step { edits: vec![edit], inverses: vec![inverse] }),
        }
        Ok(())
    }

    /// Starts grouping edits into one undo step (a mouse drag).
    pub fn begin_stroke(&mut self) {
        self.end_stroke();
        self.stroke = Some(Step::default());
    }

    /// Closes the open stroke; an empty stroke leaves no step.
    pub fn end_stroke(&mut self) {
        if let Some(stroke) = self.stroke.take().filter(|s| !s.edits.is_empty()) {
            self.push(stroke);
        }
    }

    fn push(&mut self, step: Step) {
        self.done_bytes += step.bytes();
        self.done.push_back(step);
        while self.done_bytes > self.memory_limit_bytes && self.done.len() > 1 {
            if let Some(oldest) = self.done.pop_front() {
                self.done_bytes -= oldest.bytes();
            }
        }
    }

    /// Undoes the last step; false when there is none.
    pub fn undo(&mut self, tree: &mut Octree) -> Result<bool, EditError> {
        self.end_stroke();
        let Some(mut step) = self.done.pop_back() else { return Ok(false) };
        self.done_bytes -= step.bytes();
        for inverse in step.inverses.iter().rev() {
            inverse.apply(tree)?;
        }
        step.inverses.clear();
        self.undone.push(step);
        Ok(true)
    }

    /// Re-applies the last undone step; false when there is none.
    pub fn redo(&mut self, tree: &mut Octree) -> Result<bool, EditError> {
        self.end_stroke();
        let Some(mut step) = self.undone.pop() else { return Ok(false) };
        for edit in &step.edits {
            step.inverses.push(edit.apply(tree)?);
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

    /// Forgets everything (a new scene was loaded).
    pub fn clear(&mut self) {
        self.done.clear();
        self.done_bytes = 0;
        self.undone.clear();
        self.stroke = None;
    }
}

fn edit_bytes(edit: &Edit) -> usize {
    match edit {
        Edit::Brush { .. } => std::mem::size_of::<Edit>(),
        Edit::Restore(patch) => patch.heap_bytes(),
    }
}
