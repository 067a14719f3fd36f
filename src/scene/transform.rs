//! Placing a model voxel in the MagicaVoxel scene.
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

use glam::IVec3;

use super::Shape;

/// A signed permutation matrix: row `i` has `sign[i]` in column `axis[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rotation {
    axis: [usize; 3],
    sign: [i64; 3],
}

impl Rotation {
    pub const IDENTITY: Rotation = Rotation { axis: [0, 1, 2], sign: [1, 1, 1] };

    /// Decodes MagicaVoxel's `_r` byte; `None` when the two stored column
    /// indices are out of range or equal.
    pub fn from_byte(byte: u8) -> Option<Rotation> {
        let first = usize::from(byte & 3);
        let second = usize::from((byte >> 2) & 3);
        if first > 2 || second > 2 || first == second {
            return None;
        }
        let sign = |bit: u8| if byte & (1 << bit) == 0 { 1 } else { -1 };
        Some(Rotation { axis: [first, second, 3 - first - second], sign: [sign(4), sign(5), sign(6)] })
    }

    /// `self · other`: apply `other` first.
    pub fn times(self, other: Rotation) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for row in 0..3 {
            let picked = self.axis[row];
            out.axis[row] = other.axis[picked];
            out.sign[row] = self.sign[row] * other.sign[picked];
        }
        out
    }

    pub fn apply(self, v: [i64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|row| self.sign[row] * v[self.axis[row]])
    }

    /// The inverse rotation (the transpose of a signed permutation).
    pub fn inverse(self) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for row in 0..3 {
            out.axis[self.axis[row]] = row;
            out.sign[self.axis[row]] = self.sign[row];
        }
        out
    }
}

/// A rigid transform of the MagicaVoxel scene: `p ↦ rotation · p + translation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Transform {
    pub rotation: Rotation,
    pub translation: [i64; 3],
}

impl Transform {
    pub const IDENTITY: Transform = Transform { rotation: Rotation::IDENTITY, translation: [0, 0, 0] };

    /// The transform that undoes this one.
    pub fn inverse(self) -> Transform {
        let rotation = self.rotation.inverse();
        let back = rotation.apply(self.translation);
        Transform { rotation, translation: back.map(|c| -c) }
    }

    /// The transform that applies `child` first, then `self`.
    pub fn compose(self, child: Transform) -> Transform {
        let moved = self.rotation.apply(child.translation);
        Transform {
            rotation: self.rotation.times(child.rotation),
            translation: [0, 1, 2].map(|i| moved[i] + self.translation[i]),
        }
    }
}

/// One model placed in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
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
    pub fn place(&self, v: [u8; 3], size: [u32; 3]) -> [i64; 3] {
        let local = [0, 1, 2].map(|axis| {
            let pivot = if self.centred { i64::from(size[axis] / 2) } else { 0 };
            i64::from(v[axis]) - pivot
        });
        let Transform { rotation, translation } = self.transform;
        [0, 1, 2].map(|row| {
            let along = local[rotation.axis[row]];
            let offset = if rotation.sign[row] > 0 { along } else { -along - 1 };
            translation[row] + offset
        })
    }
}

impl Rotation {
    /// MagicaVoxel's `_r` byte for this rotation (the inverse of [`Rotation::from_byte`]).
    pub fn to_byte(self) -> u8 {
        let signs = (0..3).map(|row| u8::from(self.sign[row] < 0) << (4 + row)).sum::<u8>();
        (self.axis[0] as u8) | ((self.axis[1] as u8) << 2) | signs
    }

    /// A quarter turn counter-clockwise seen from the positive end of MagicaVoxel axis `axis` (0, 1, 2 = x, y, z).
    pub fn quarter_turn(axis: usize) -> Rotation {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        // a → b and b → −a: row b reads +a, row a reads −b.
        let mut rotation = Rotation::IDENTITY;
        rotation.axis[b] = a;
        rotation.axis[a] = b;
        rotation.sign[a] = -1;
        rotation
    }
}

impl Placement {
    /// The map from model cells to octovox world cells (y up) that [`Placement::place`] and the axis change
    /// (x, y, z) → (x, z, −y) make together; `None` when an offset leaves the 32-bit range.
    pub fn cell_map(&self, size: [u32; 3]) -> Option<CellMap> {
        let Transform { rotation, translation } = self.transform;
        let row = |r: usize| {
            let a = rotation.axis[r];
            let s = rotation.sign[r];
            let pivot = if self.centred { i64::from(size[a] / 2) } else { 0 };
            let offset = translation[r] - s * pivot - i64::from(s < 0);
            (a, s, offset)
        };
        let [x, y, z] = [row(0), row(1), row(2)];
        let rows = [x, z, (y.0, -y.1, -y.2)];
        let offset = [0, 1, 2].map(|i| i32::try_from(rows[i].2).ok());
        Some(CellMap {
            axis: rows.map(|r| r.0),
            sign: rows.map(|r| r.1 as i32),
            offset: IVec3::new(offset[0]?, offset[1]?, offset[2]?),
        })
    }
}

/// A signed permutation of cells plus an integer offset: world cell `w[i] = sign[i] · v[axis[i]] + offset[i]`.
/// It maps cell centres by an isometry, so a sphere of cells maps to a sphere and a box to a box, exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellMap {
    axis: [usize; 3],
    sign: [i32; 3],
    offset: IVec3,
}

impl CellMap {
    pub const IDENTITY: CellMap = CellMap { axis: [0, 1, 2], sign: [1, 1, 1], offset: IVec3::ZERO };

    /// The quarter turn counter-clockwise seen from the positive end of
    /// `axis` (0, 1, 2 = x, y, z) that takes the box of cells `0..size` onto
    /// the box `0..size'` of the turned size (the other two sizes swapped).
    pub fn quarter_turn_in(axis: usize, size: IVec3) -> CellMap {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        // a → b and b → −a, then back into the box.
        let mut map = CellMap::IDENTITY;
        map.axis[b] = a;
        map.axis[a] = b;
        map.sign[a] = -1;
        map.offset[a] = size[b] - 1;
        map
    }

    /// The mirror image along `axis` that takes the box of cells `0..size` onto itself.
    pub fn flip_in(axis: usize, size: IVec3) -> CellMap {
        let mut map = CellMap::IDENTITY;
        map.sign[axis] = -1;
        map.offset[axis] = size[axis] - 1;
        map
    }

    /// The same map on points measured in half voxels (cell `v` is the
    /// cube from `2v` to `2v + 2`): row `i` is `(axis, sign, offset)` with
    /// `w[i] = sign · p[axis] + offset`. A mirrored axis moves the cube's
    /// low corner, hence its offset's extra cell.
    pub fn half_voxel_rows(&self) -> [(usize, i32, i32); 3] {
        [0, 1, 2].map(|i| {
            let corner = if self.sign[i] < 0 { 2 } else { 0 };
            (self.axis[i], self.sign[i], self.offset[i].wrapping_mul(2).wrapping_add(corner))
        })
    }

    /// Row `i` of the map on cells: `(axis, sign, offset)` with
    /// `w[i] = sign · v[axis] + offset`.
    pub fn rows(&self) -> [(usize, i32, i32); 3] {
        [0, 1, 2].map(|i| (self.axis[i], self.sign[i], self.offset[i]))
    }

    /// The world cell of model cell `v`.
    pub fn apply(&self, v: IVec3) -> IVec3 {
        IVec3::from_array([0, 1, 2].map(|i| self.sign[i].wrapping_mul(v[self.axis[i]]).wrapping_add(self.offset[i])))
    }

    /// The model cell at world cell `w`.
    pub fn invert(&self, w: IVec3) -> IVec3 {
        let mut v = [0; 3];
        for i in 0..3 {
            v[self.axis[i]] = self.sign[i].wrapping_mul(w[i].wrapping_sub(self.offset[i]));
        }
        IVec3::from_array(v)
    }

    /// The image of the inclusive box `lo..=hi` of model cells.
    pub fn apply_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        let (a, b) = (self.apply(lo), self.apply(hi));
        (a.min(b), a.max(b))
    }

    /// The model cells of the inclusive world box `lo..=hi`.
    pub fn invert_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        let (a, b) = (self.invert(lo), self.invert(hi));
        (a.min(b), a.max(b))
    }

    /// The model cells a world brush shape covers, as a shape of the same kind.
    pub fn invert_shape(&self, shape: &Shape) -> Shape {
        match *shape {
            Shape::Voxel(p) => Shape::Voxel(self.invert(p)),
            Shape::Sphere { center, radius } => Shape::Sphere { center: self.invert(center), radius },
            Shape::Box { min, max } => {
                let (min, max) = self.invert_box(min, max);
                Shape::Box { min, max }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_bytes_round_trip_and_quarter_turns_cycle() {
        for byte in (0..=127u8).filter(|b| Rotation::from_byte(*b).is_some()) {
            assert_eq!(Rotation::from_byte(byte).map(Rotation::to_byte), Some(byte));
        }
        // About z: x → y → −x.
        assert_eq!(Rotation::quarter_turn(2).apply([1, 0, 0]), [0, 1, 0]);
        assert_eq!(Rotation::quarter_turn(2).apply([0, 1, 0]), [-1, 0, 0]);
        for axis in 0..3 {
            let turn = Rotation::quarter_turn(axis);
            let full = turn.times(turn).times(turn).times(turn);
            assert_eq!(full, Rotation::IDENTITY);
            assert_eq!(turn.times(turn.inverse()), Rotation::IDENTITY);
        }
    }

    /// The cell map agrees with `place` and the axis change on every cell of a small model, for all 48
    /// rotations, and inverts exactly.
    #[test]
    fn cell_maps_agree_with_placement_and_invert() {
        let size = [3, 4, 5];
        for byte in (0..=127u8).filter(|b| Rotation::from_byte(*b).is_some()) {
            let rotation = Rotation::from_byte(byte).unwrap();
            let placement =
                Placement { model: 0, transform: Transform { rotation, translation: [7, -3, 11] }, centred: true };
            let map = placement.cell_map(size).unwrap();
            for v in [[0u8, 0, 0], [2, 3, 4], [1, 2, 0]] {
                let [x, y, z] = placement.place(v, size);
                let world = IVec3::new(x as i32, z as i32, -y as i32);
                let model = IVec3::new(v[0].into(), v[1].into(), v[2].into());
                assert_eq!(map.apply(model), world, "rotation {byte}");
                assert_eq!(map.invert(world), model);
            }
        }
    }

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

    /// Mirroring x maps each voxel's cube, not its corner: a 3-wide model
    /// (pivot 1) covers [-1, 2) unrotated and (-2, 1] mirrored, so voxel 0
    /// lands at 0 and voxel 2 at -2; a 4-wide one covers [-2, 2) both ways.
    #[test]
    fn flipped_axis_maps_cells_not_corners() {
        let flip_x = Rotation { axis: [0, 1, 2], sign: [-1, 1, 1] };
        let placement =
            Placement { model: 0, transform: Transform { rotation: flip_x, translation: [0, 0, 0] }, centred: true };
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
        let quarter = Rotation { axis: [1, 0, 2], sign: [-1, 1, 1] };
        let placement = Placement {
            model: 0,
            transform: Transform { rotation: quarter, translation: [10, 20, 30] },
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
}
