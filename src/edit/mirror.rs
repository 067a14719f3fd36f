//! Mirror editing: brush edits also applied mirrored across planes
//! `x = C`, `y = C`, `z = C` (C a whole or half number, so both even and odd
//! widths have a centre), several axes at once, all in one undo step.

use glam::IVec3;

use crate::edit::Edit;
use crate::scene::Shape;

/// The planes in force: per axis, twice the plane's coordinate (exact for
/// halves), or `None`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mirror {
    pub planes: [Option<i32>; 3],
}

impl Mirror {
    /// The plane coordinate on `axis` as a number (`None` when off).
    pub fn plane(&self, axis: usize) -> Option<f64> {
        self.planes[axis].map(|twice| f64::from(twice) / 2.0)
    }

    /// Sets the plane on `axis` to `c` (rounded to the nearest half).
    pub fn set(&mut self, axis: usize, c: Option<f64>) {
        self.planes[axis] = c.map(|c| (c * 2.0).round() as i32);
    }

    /// Carries out a `mirror` script line: one plane on, or (`None`) all off.
    pub fn apply_line(&mut self, plane: Option<(usize, f64)>) {
        match plane {
            Some((axis, c)) => self.set(axis, Some(c)),
            None => *self = Mirror::default(),
        }
    }

    /// `edit` and its mirror images across every plane in force (2^planes
    /// edits, the same one once); other edits as they are.
    pub fn edits(&self, edit: Edit) -> Vec<Edit> {
        let Edit::Brush { shape, op } = edit else { return vec![edit] };
        let mut shapes = vec![shape];
        for (axis, twice) in self.planes.iter().enumerate() {
            let Some(twice) = *twice else { continue };
            let images: Vec<Shape> = shapes.iter().map(|s| mirror_shape(*s, axis, twice)).collect();
            for image in images {
                if !shapes.contains(&image) {
                    shapes.push(image);
                }
            }
        }
        shapes.into_iter().map(|shape| Edit::Brush { shape, op }).collect()
    }
}

/// The voxel coordinate mirrored across the plane at `twice / 2`: voxel p
/// spans p..p + 1, so its image spans twice − p − 1..twice − p.
fn mirror_coord(p: i32, twice: i32) -> i32 {
    twice - p - 1
}

fn mirror_point(mut p: IVec3, axis: usize, twice: i32) -> IVec3 {
    p[axis] = mirror_coord(p[axis], twice);
    p
}

fn mirror_shape(shape: Shape, axis: usize, twice: i32) -> Shape {
    match shape {
        Shape::Voxel(p) => Shape::Voxel(mirror_point(p, axis, twice)),
        // A sphere is symmetric about its centre voxel.
        Shape::Sphere { center, radius } => Shape::Sphere { center: mirror_point(center, axis, twice), radius },
        Shape::Box { min, max } => {
            let (a, b) = (mirror_point(min, axis, twice), mirror_point(max, axis, twice));
            Shape::Box { min: a.min(b), max: a.max(b) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Op;

    #[test]
    fn half_and_whole_planes_mirror_odd_and_even_widths() {
        let mut mirror = Mirror::default();
        mirror.set(0, Some(0.5));
        // x = 0.5 is the centre of voxel 0: voxel 0 is its own image.
        let place = |p| Edit::Brush { shape: Shape::Voxel(p), op: Op::Place(3) };
        assert_eq!(mirror.edits(place(IVec3::ZERO)).len(), 1);
        assert_eq!(mirror.edits(place(IVec3::new(3, 1, 2)))[1], place(IVec3::new(-3, 1, 2)));
        mirror.set(0, Some(4.0));
        assert_eq!(mirror.edits(place(IVec3::new(3, 0, 0)))[1], place(IVec3::new(4, 0, 0)));
        mirror.set(2, Some(0.0));
        let all = mirror.edits(place(IVec3::new(1, 0, 5)));
        assert_eq!(all.len(), 4);
        assert!(all.contains(&place(IVec3::new(6, 0, -6))));
        let b =
            Edit::Brush { shape: Shape::Box { min: IVec3::new(1, 0, 0), max: IVec3::new(2, 1, 1) }, op: Op::Remove };
        let Edit::Brush { shape, .. } = mirror.edits(b)[1] else { panic!() };
        assert_eq!(shape, Shape::Box { min: IVec3::new(5, 0, 0), max: IVec3::new(6, 1, 1) });
    }
}
