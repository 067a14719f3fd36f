//! Editing tools and brushes: how a click on a voxel face becomes an
//! [`Edit`]. The window and the replay `click` command both use this.

use glam::IVec3;

use crate::edit::Edit;
use crate::scene::octree::{MAX_DEPTH, WORLD_LIMIT};
use crate::scene::{EditError, Op, Shape};

/// What a click does (MagicaVoxel's names and keys: T, R, G).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tool {
    /// Place voxels on the face that was clicked.
    #[default]
    Attach,
    /// Remove the clicked voxels.
    Erase,
    /// Recolour the clicked voxels.
    Paint,
}

impl Tool {
    pub const ALL: [Tool; 3] = [Tool::Attach, Tool::Erase, Tool::Paint];

    /// The word the replay language uses.
    pub fn name(self) -> &'static str {
        match self {
            Tool::Attach => "attach",
            Tool::Erase => "erase",
            Tool::Paint => "paint",
        }
    }

    pub fn from_name(name: &str) -> Option<Tool> {
        Tool::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// The brush shape, centred on the cell a click picks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Brush {
    #[default]
    Voxel,
    /// Cells with dx² + dy² + dz² ≤ r².
    Sphere(i32),
    /// `size` cells per axis, from `center - size / 2`.
    Box(IVec3),
}

impl Brush {
    /// How far the brush reaches from its centre along an axis.
    pub fn reach(&self) -> i32 {
        match *self {
            Brush::Voxel => 0,
            Brush::Sphere(radius) => radius.max(0),
            Brush::Box(size) => size.max_element().max(1) / 2,
        }
    }

    pub fn shape_at(&self, center: IVec3) -> Shape {
        match *self {
            Brush::Voxel => Shape::Voxel(center),
            Brush::Sphere(radius) => Shape::Sphere { center, radius },
            Brush::Box(size) => Shape::centered_box(center, size),
        }
    }
}

/// The cell a click with `tool` acts on, given the picked voxel and the
/// normal of the face hit: Attach works in front of the face.
pub fn click_target(tool: Tool, voxel: IVec3, normal: IVec3) -> IVec3 {
    match tool {
        Tool::Attach => voxel + normal,
        Tool::Erase | Tool::Paint => voxel,
    }
}

/// The operation a tool performs with a colour.
pub fn tool_op(tool: Tool, color: u8) -> Op {
    match tool {
        Tool::Attach => Op::Place(color),
        Tool::Erase => Op::Remove,
        Tool::Paint => Op::Paint(color),
    }
}

/// The edit of a click on (world) `voxel` through the face with `normal`.
pub fn click_edit(tool: Tool, brush: &Brush, color: u8, voxel: IVec3, normal: IVec3) -> (IVec3, Edit) {
    let center = click_target(tool, voxel, normal);
    (center, Edit::Brush { shape: brush.shape_at(center), op: tool_op(tool, color) })
}

/// The cells of a 3D line from `a` to `b`, both ends included: one per step
/// along the longest axis (max(|Δx|, |Δy|, |Δz|) + 1 cells), the others
/// rounded to the nearest cell (halves up).
pub fn line_points(a: IVec3, b: IVec3) -> Vec<IVec3> {
    let d = (b - a).as_i64vec3();
    let n = d.abs().max_element();
    if n == 0 {
        return vec![a];
    }
    (0..=n)
        .map(|i| {
            let offset = (d * 2 * i + glam::I64Vec3::splat(n)).div_euclid(glam::I64Vec3::splat(2 * n));
            a + offset.as_ivec3()
        })
        .collect()
}

/// The edits of a line: the brush placed with `color` at every cell of it.
/// Its extent and memory are checked before any cell is built (a line
/// across the whole coordinate range is 33 million cells).
///
/// # Errors
/// The line and brush reach past the coordinate limit, are wider than the
/// world, or their edits' estimate is over the memory budget.
pub fn line_edits(brush: &Brush, color: u8, a: IVec3, b: IVec3) -> Result<Vec<Edit>, EditError> {
    let (lo_a, hi_a) = brush.shape_at(a).bounds();
    let (lo_b, hi_b) = brush.shape_at(b).bounds();
    let (min, max) = (lo_a.min(lo_b), hi_a.max(hi_b));
    if min.min_element() <= -WORLD_LIMIT || max.max_element() >= WORLD_LIMIT {
        return Err(EditError::OutsideWorld { min, max });
    }
    if (max.as_i64vec3() - min.as_i64vec3()).max_element() >= 1 << MAX_DEPTH {
        return Err(EditError::TooWide { min, max });
    }
    let cells = (b.as_i64vec3() - a.as_i64vec3()).abs().max_element().unsigned_abs() + 1;
    let each = Edit::Brush { shape: brush.shape_at(a), op: Op::Place(color) }.estimated_bytes();
    crate::budget::check(|| format!("a line of {cells} brushes"), cells.saturating_mul(each))?;
    let edits = line_points(a, b).into_iter().map(|p| Edit::Brush { shape: brush.shape_at(p), op: Op::Place(color) });
    Ok(edits.collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_has_one_cell_per_step_of_its_longest_axis() {
        assert_eq!(line_points(IVec3::ZERO, IVec3::new(3, 0, 0)).len(), 4);
        let diagonal = line_points(IVec3::new(1, 1, 1), IVec3::new(-2, -2, -2));
        assert_eq!(diagonal, (0..4).map(|i| IVec3::splat(1 - i)).collect::<Vec<_>>());
        let general = line_points(IVec3::ZERO, IVec3::new(7, -3, 2));
        assert_eq!(general.len(), 8);
        assert_eq!((general[0], general[7]), (IVec3::ZERO, IVec3::new(7, -3, 2)));
        // 26-connected: each cell touches the next.
        assert!(general.windows(2).all(|w| (w[1] - w[0]).abs().max_element() == 1));
    }
}
