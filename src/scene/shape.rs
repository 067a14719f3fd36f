//! Brush shapes and operations, and how a shape overlaps an octree cell.

use glam::IVec3;

/// Largest sphere radius and box side a brush accepts (keeps edits bounded).
pub const MAX_BRUSH_EXTENT: i32 = 4096;

/// The cells a brush covers, in world voxel coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// One voxel.
    Voxel(IVec3),
    /// Voxels whose offset (dx, dy, dz) from `center` has dx² + dy² + dz² ≤ radius².
    Sphere { center: IVec3, radius: i32 },
    /// Voxels in `min..=max` on every axis.
    Box { min: IVec3, max: IVec3 },
}

/// What a brush does to the cells it covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// Fill every covered cell with this palette index (overwriting).
    Place(u8),
    /// Empty every covered cell.
    Remove,
    /// Recolour only the covered cells that are solid.
    Paint(u8),
}

/// How a shape overlaps an axis-aligned cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    Outside,
    Partial,
    Inside,
}

/// Why a brush shape is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ShapeError {
    #[error("sphere radius {0} is outside 0..={MAX_BRUSH_EXTENT}")]
    Radius(i32),
    #[error("box min {min} is above its max {max}")]
    Inverted { min: IVec3, max: IVec3 },
    #[error("box {min}..{max} is wider than {MAX_BRUSH_EXTENT}")]
    TooWide { min: IVec3, max: IVec3 },
}

impl Shape {
    /// A box of `size` cells centred on `center` the way the replay language
    /// defines it: `center - size / 2 ..= center - size / 2 + size - 1`.
    pub fn centered_box(center: IVec3, size: IVec3) -> Shape {
        let min = center - size / 2;
        Shape::Box { min, max: min + size - IVec3::ONE }
    }

    /// Inclusive bounding box of the covered cells.
    pub fn bounds(&self) -> (IVec3, IVec3) {
        match *self {
            Shape::Voxel(p) => (p, p),
            Shape::Sphere { center, radius } => (center - IVec3::splat(radius), center + IVec3::splat(radius)),
            Shape::Box { min, max } => (min, max),
        }
    }

    pub fn contains(&self, p: IVec3) -> bool {
        match *self {
            Shape::Voxel(q) => p == q,
            Shape::Sphere { center, radius } => dist2(p - center) <= i64::from(radius).pow(2),
            Shape::Box { min, max } => p.cmpge(min).all() && p.cmple(max).all(),
        }
    }

    /// Overlap with the cell of `size` voxels per side whose min corner is `min`.
    pub fn overlap(&self, min: IVec3, size: i32) -> Overlap {
        let max = min + IVec3::splat(size - 1);
        match *self {
            Shape::Voxel(p) => box_overlap(p, p, min, max),
            Shape::Box { min: lo, max: hi } => box_overlap(lo, hi, min, max),
            Shape::Sphere { center, radius } => {
                let r2 = i64::from(radius).pow(2);
                let nearest = center.clamp(min, max);
                if dist2(nearest - center) > r2 {
                    return Overlap::Outside;
                }
                let far = (min - center).abs().max((max - center).abs());
                if dist2(far) <= r2 { Overlap::Inside } else { Overlap::Partial }
            }
        }
    }

    /// Checks the size limits; returns a message naming the problem.
    /// About how many voxels lie on the shape's surface: what an edit's new
    /// bricks and nodes grow with (its inside becomes a few uniform cells).
    pub fn surface_voxels(&self) -> u64 {
        match *self {
            Shape::Voxel(_) => 1,
            Shape::Sphere { radius, .. } => {
                let r = f64::from(radius.max(0)) + 1.0;
                (4.0 * std::f64::consts::PI * r * r) as u64
            }
            Shape::Box { min, max } => {
                let [a, b, c] =
                    (max - min + IVec3::ONE).as_i64vec3().max(glam::I64Vec3::ONE).to_array().map(|v| v as u64);
                2 * (a * b + b * c + c * a)
            }
        }
    }

    pub fn validate(&self) -> Result<(), ShapeError> {
        match *self {
            Shape::Voxel(_) => Ok(()),
            Shape::Sphere { radius, .. } if !(0..=MAX_BRUSH_EXTENT).contains(&radius) => {
                Err(ShapeError::Radius(radius))
            }
            Shape::Box { min, max } if (max - min).cmplt(IVec3::ZERO).any() => Err(ShapeError::Inverted { min, max }),
            Shape::Box { min, max } if (max - min).max_element() >= MAX_BRUSH_EXTENT => {
                Err(ShapeError::TooWide { min, max })
            }
            _ => Ok(()),
        }
    }
}

fn dist2(d: IVec3) -> i64 {
    let d = d.as_i64vec3();
    d.x * d.x + d.y * d.y + d.z * d.z
}

fn box_overlap(lo: IVec3, hi: IVec3, min: IVec3, max: IVec3) -> Overlap {
    if hi.cmplt(min).any() || lo.cmpgt(max).any() {
        Overlap::Outside
    } else if lo.cmple(min).all() && hi.cmpge(max).all() {
        Overlap::Inside
    } else {
        Overlap::Partial
    }
}

impl Op {
    /// The value a covered voxel holding `old` ends up with.
    pub fn apply(self, old: u8) -> u8 {
        match self {
            Op::Place(v) => v,
            Op::Remove => 0,
            Op::Paint(v) if old != 0 => v,
            Op::Paint(_) => old,
        }
    }

    /// The palette index the op writes, if any (0 is not a valid colour).
    pub fn color(self) -> Option<u8> {
        match self {
            Op::Place(v) | Op::Paint(v) => Some(v),
            Op::Remove => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Overlap must agree with `contains` over every voxel of the cell.
    #[test]
    fn overlap_matches_contains() {
        let shapes = [
            Shape::Sphere { center: IVec3::new(3, -2, 5), radius: 4 },
            Shape::Sphere { center: IVec3::ZERO, radius: 0 },
            Shape::Box { min: IVec3::new(-3, 0, 1), max: IVec3::new(2, 7, 1) },
            Shape::Voxel(IVec3::new(1, 1, 1)),
        ];
        for shape in shapes {
            for size in [1i32, 2, 4, 8] {
                for z in (-8..8).step_by(size as usize) {
                    for y in (-8..8).step_by(size as usize) {
                        for x in (-8..8).step_by(size as usize) {
                            let min = IVec3::new(x, y, z);
                            let inside = (0..size.pow(3))
                                .filter(|i| {
                                    let o = IVec3::new(i % size, (i / size) % size, i / size / size);
                                    shape.contains(min + o)
                                })
                                .count() as i32;
                            let expected = match inside {
                                0 => Overlap::Outside,
                                n if n == size.pow(3) => Overlap::Inside,
                                _ => Overlap::Partial,
                            };
                            assert_eq!(shape.overlap(min, size), expected, "{shape:?} at {min} size {size}");
                        }
                    }
                }
            }
        }
    }
}
