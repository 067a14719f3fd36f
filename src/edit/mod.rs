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
mod history;
pub mod mirror;
pub mod selection;

pub use history::History;

use crate::scene::{EditError, Material, Op, Patch, Scene, Shape};

/// One change to the scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Edit {
    /// Apply a brush shape with an operation.
    Brush { shape: Shape, op: Op },
    /// Put back cells saved by an earlier edit (what undo sends).
    Restore(Patch),
    /// Give a palette entry (1..=255) a colour and a material: every voxel of
    /// that index changes look at once.
    Palette { index: u8, color: [u8; 4], material: Box<Material> },
}

impl Edit {
    /// Applies the edit; returns the edit that undoes it. A refused edit
    /// changes nothing.
    pub fn apply(&self, scene: &mut Scene) -> Result<Edit, EditError> {
        match self {
            Edit::Brush { shape, op } => Ok(Edit::Restore(scene.tree.apply_brush(shape, *op)?)),
            Edit::Restore(patch) => Ok(Edit::Restore(scene.tree.apply_patch(patch)?)),
            Edit::Palette { index, color, material } => {
                if *index == 0 {
                    return Err(EditError::ZeroColor);
                }
                let i = usize::from(*index);
                let palette = &mut scene.palette;
                let old_color = std::mem::replace(&mut palette.colors[i], *color);
                let old_material = std::mem::replace(&mut palette.materials[i], (**material).clone());
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
            Edit::Brush { shape, .. } => {
                shape.surface_voxels().saturating_mul(crate::scene::apply::EDIT_BYTES_PER_SURFACE_VOXEL)
            }
            Edit::Restore(patch) => 2 * patch.heap_bytes() as u64,
            Edit::Palette { .. } => 0,
        })
    }

    /// Whether applying it changes the palette (which then goes to the GPU).
    pub fn changes_palette(&self) -> bool {
        matches!(self, Edit::Palette { .. })
    }
}
