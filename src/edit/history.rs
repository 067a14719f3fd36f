//! The undo/redo history: steps of edits and the edits that undo them.

use std::collections::VecDeque;

use super::Edit;
use crate::scene::{EditError, Scene};

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
    pub fn apply(&mut self, scene: &mut Scene, edit: Edit) -> Result<(), EditError> {
        let inverse = edit.apply(scene)?;
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
            match edit.apply(scene) {
                Ok(inverse) => {
                    step.edits.push(edit);
                    step.inverses.push(inverse);
                }
                Err(err) => {
                    for inverse in step.inverses.iter().rev() {
                        // Undoing what was just done cannot need more room than doing it.
                        let _ = inverse.apply(scene);
                    }
                    return Err(err);
                }
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
    }
}

fn edit_bytes(edit: &Edit) -> usize {
    match edit {
        Edit::Brush { .. } => std::mem::size_of::<Edit>(),
        Edit::Restore(patch) => patch.heap_bytes(),
        Edit::Palette { material, .. } => {
            std::mem::size_of::<Edit>() + material.params.iter().map(|(k, v)| k.len() + v.len() + 48).sum::<usize>()
        }
    }
}
