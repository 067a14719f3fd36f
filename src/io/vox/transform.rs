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

/// A signed permutation matrix: row `i` has `sign[i]` in column `axis[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Rotation {
    axis: [usize; 3],
    sign: [i64; 3],
}

impl Rotation {
    pub(super) const IDENTITY: Rotation = Rotation { axis: [0, 1, 2], sign: [1, 1, 1] };

    /// Decodes MagicaVoxel's `_r` byte; `None` when the two stored column
    /// indices are out of range or equal.
    pub(super) fn from_byte(byte: u8) -> Option<Rotation> {
        let first = usize::from(byte & 3);
        let second = usize::from((byte >> 2) & 3);
        if first > 2 || second > 2 || first == second {
            return None;
        }
        let sign = |bit: u8| if byte & (1 << bit) == 0 { 1 } else { -1 };
        Some(Rotation { axis: [first, second, 3 - first - second], sign: [sign(4), sign(5), sign(6)] })
    }

    /// `self · other`: apply `other` first.
    pub(super) fn times(self, other: Rotation) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for row in 0..3 {
            let picked = self.axis[row];
            out.axis[row] = other.axis[picked];
            out.sign[row] = self.sign[row] * other.sign[picked];
        }
        out
    }

    pub(super) fn apply(self, v: [i64; 3]) -> [i64; 3] {
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
    pub(super) const IDENTITY: Transform = Transform { rotation: Rotation::IDENTITY, translation: [0, 0, 0] };

    /// The transform that applies `child` first, then `self`.
    pub(super) fn compose(self, child: Transform) -> Transform {
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
