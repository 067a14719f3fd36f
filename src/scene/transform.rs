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

use glam::{DMat3, DQuat, DVec3, IVec3};

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
    /// The placement by signed permutations: exact, and what MagicaVoxel
    /// shows (a free turn's nearest quarter turns).
    pub transform: Transform,
    /// Whether model space is centred on the pivot `size / 2` (scene-graph
    /// files) or is the model's own grid (files without a scene graph).
    pub centred: bool,
    /// The whole placement where a transform on the way down turns freely
    /// (`_ov_turn`): what octovox draws then.
    pub turned: Option<Rigid>,
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

// ----- free turns ---------------------------------------------------------------
//
// MagicaVoxel turns only by the 48 signed permutations. octovox keeps a turn
// by any angle as a unit quaternion `_ov_turn` beside a keyframe's `_r`: the
// keyframe's rotation is `turn · R(_r)`, where `_r` is the signed permutation
// nearest the whole rotation (of the same handedness), so that a reader that
// ignores `_ov_turn` shows the nearest quarter turns. A placement with no
// free turn on its way down stays on the exact integer path ([`CellMap`]);
// one with a free turn is a rigid map of points ([`Rigid`], [`TurnedMap`]).

/// A free turn: a unit quaternion in MagicaVoxel axes, compared bit for
/// bit (a turn read from a file is the one written).
#[derive(Clone, Copy, Debug)]
pub struct Turn(pub DQuat);

impl PartialEq for Turn {
    fn eq(&self, other: &Turn) -> bool {
        self.0.to_array().map(f64::to_bits) == other.0.to_array().map(f64::to_bits)
    }
}

impl Eq for Turn {}

/// Turns closer to none than this many radians are none: what the float
/// arithmetic of composing whole quarter turns leaves (1e-16 or so), far
/// below the smallest turn anyone asks for (1e-7 rad is kept).
const NO_TURN_RAD: f64 = 1e-12;

impl Rotation {
    /// The matrix of this signed permutation (row `i` has `sign[i]` in
    /// column `axis[i]`).
    pub fn matrix(self) -> DMat3 {
        let mut cols = [DVec3::ZERO; 3];
        for row in 0..3 {
            cols[self.axis[row]][row] = self.sign[row] as f64;
        }
        DMat3::from_cols(cols[0], cols[1], cols[2])
    }

    /// Whether it is a turn (determinant +1), not a mirror image.
    pub fn proper(self) -> bool {
        self.matrix().determinant() > 0.0
    }

    /// The signed permutation nearest the orthogonal matrix `m` among those
    /// of its handedness: the largest `trace(Pᵀ · m)`.
    pub fn nearest(m: DMat3) -> Rotation {
        let proper = m.determinant() > 0.0;
        let score = |r: &Rotation| (0..3).map(|row| r.sign[row] as f64 * m.col(r.axis[row])[row]).sum::<f64>();
        (0..=127u8)
            .filter_map(Rotation::from_byte)
            .filter(|r| r.proper() == proper)
            .max_by(|a, b| score(a).total_cmp(&score(b)))
            .unwrap_or(Rotation::IDENTITY)
    }
}

/// A keyframe's transform, or one sampled between keyframes: the signed
/// permutation and translation MagicaVoxel reads (`_r`, `_t`) and octovox's
/// free turn on top (`_ov_turn`): the rotation is `turn · transform.rotation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pose {
    pub transform: Transform,
    pub turn: Option<Turn>,
}

impl Pose {
    pub const IDENTITY: Pose = Pose { transform: Transform::IDENTITY, turn: None };

    /// The whole rotation.
    pub fn matrix(&self) -> DMat3 {
        let r = self.transform.rotation.matrix();
        self.turn.map_or(r, |turn| DMat3::from_quat(turn.0) * r)
    }

    /// The pose of the orthogonal matrix `m` and `translation`: the nearest
    /// signed permutation of its handedness, and the turn left over (none
    /// where it is no turn).
    pub fn of_matrix(m: DMat3, translation: [i64; 3]) -> Pose {
        let rotation = Rotation::nearest(m);
        // m = q · R, so q = m · Rᵀ: a turn, as m and R have one handedness.
        let rest = DQuat::from_mat3(&(m * rotation.matrix().transpose())).normalize();
        // The angle from the vector part: acos(w) cannot tell turns below 1e-8.
        let angle = 2.0 * rest.xyz().length().atan2(rest.w.abs());
        let turn = (angle >= NO_TURN_RAD).then_some(Turn(rest));
        Pose { transform: Transform { rotation, translation }, turn }
    }

    /// The pose `frac` of the way from `self` to `to` (`frac` eased
    /// already): the rotation by slerp where either has a free turn and both
    /// have one handedness, else held; the translation as given.
    pub fn toward(&self, to: &Pose, frac: f64, translation: [i64; 3]) -> Pose {
        let (a, b) = (self.matrix(), to.matrix());
        let proper = a.determinant() > 0.0;
        if (self.turn.is_none() && to.turn.is_none()) || proper != (b.determinant() > 0.0) {
            return Pose { transform: Transform { translation, ..self.transform }, turn: self.turn };
        }
        // A mirror image is −1 times a turn: slerp the turns, mirror back.
        let sign = if proper { 1.0 } else { -1.0 };
        let (qa, qb) = (DQuat::from_mat3(&(a * sign)), DQuat::from_mat3(&(b * sign)));
        let m = DMat3::from_quat(qa.slerp(qb, frac).normalize()) * sign;
        Pose::of_matrix(m, translation)
    }
}

/// A rigid map of MagicaVoxel points: `p ↦ m · p + t` (`m` orthogonal),
/// compared bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct Rigid {
    pub m: DMat3,
    pub t: DVec3,
}

impl PartialEq for Rigid {
    fn eq(&self, other: &Rigid) -> bool {
        self.m.to_cols_array().map(f64::to_bits) == other.m.to_cols_array().map(f64::to_bits)
            && self.t.to_array().map(f64::to_bits) == other.t.to_array().map(f64::to_bits)
    }
}

impl Eq for Rigid {}

impl Rigid {
    pub fn of_transform(transform: Transform) -> Rigid {
        Rigid { m: transform.rotation.matrix(), t: DVec3::from_array(transform.translation.map(|c| c as f64)) }
    }

    pub fn of_pose(pose: &Pose) -> Rigid {
        Rigid { m: pose.matrix(), ..Rigid::of_transform(pose.transform) }
    }

    /// The map that applies `child` first, then `self`.
    pub fn compose(self, child: Rigid) -> Rigid {
        Rigid { m: self.m * child.m, t: self.m * child.t + self.t }
    }
}

/// Octovox's world axes from MagicaVoxel's on points: (x, y, z) → (x, z,
/// 1 − y), the linear part here and the 1 in [`TurnedMap::new`]. On cells
/// this is [`Placement::cell_map`]'s axis change: MagicaVoxel cell y (the
/// points y..y + 1) is world cell z = −y (the points −y..−y + 1).
fn world_axes() -> DMat3 {
    DMat3::from_cols(DVec3::X, DVec3::NEG_Z, DVec3::Y)
}

/// A freely turned placement on cells: model grid point `x` is world point
/// `a · x + shift + frac`. A model cell is drawn in the world cells whose
/// centres its turned cube holds, so the map between cells goes by cell
/// centres. The translation's whole part `shift` is taken off in integers
/// before any rounding: an object far out lands on the cells it lands on
/// near the origin, moved, and float error stays that of its own size.
#[derive(Clone, Copy, Debug)]
pub struct TurnedMap {
    a: DMat3,
    shift: IVec3,
    frac: DVec3,
}

impl PartialEq for TurnedMap {
    fn eq(&self, other: &TurnedMap) -> bool {
        self.key() == other.key()
    }
}

impl Eq for TurnedMap {}

impl std::hash::Hash for TurnedMap {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.key().hash(state);
    }
}

impl TurnedMap {
    /// The map of a model of `size` placed by `rigid` about its pivot
    /// (`centred`) or from its grid's corner.
    pub fn new(rigid: Rigid, size: [u32; 3], centred: bool) -> TurnedMap {
        let pivot = DVec3::from_array(size.map(|s| if centred { f64::from(s / 2) } else { 0.0 }));
        let c = world_axes();
        // The translation's whole part exactly (whole numbers from `_t`,
        // unless a group above turns freely), then what the turn of the
        // pivot adds.
        let shift = c * rigid.t + DVec3::Z;
        let whole = shift.round();
        let frac = shift - whole - c * (rigid.m * pivot);
        TurnedMap { a: c * rigid.m, shift: whole.as_ivec3(), frac }
    }

    fn key(&self) -> [u64; 15] {
        let mut key = [0; 15];
        let values = self.a.to_cols_array().into_iter().chain(self.frac.to_array());
        for (k, v) in key.iter_mut().zip(values) {
            *k = v.to_bits();
        }
        for (k, v) in key[12..].iter_mut().zip(self.shift.to_array()) {
            *k = u64::from(v as u32);
        }
        key
    }

    /// The world point of model grid point `x`, less the whole shift.
    fn world_unshifted(&self, x: DVec3) -> DVec3 {
        self.a * x + self.frac
    }

    /// The model grid point of world point `shift + u`.
    fn model_unshifted(&self, u: DVec3) -> DVec3 {
        self.a.transpose() * (u - self.frac)
    }

    /// World cell `w` less the shift, in exact integers.
    fn unshifted(&self, w: IVec3) -> DVec3 {
        (w.as_i64vec3() - self.shift.as_i64vec3()).as_dvec3()
    }

    /// The world cell holding model cell `v`'s centre.
    pub fn apply(&self, v: IVec3) -> IVec3 {
        self.world_unshifted(v.as_dvec3() + DVec3::splat(0.5)).floor().as_ivec3().saturating_add(self.shift)
    }

    /// The model cell whose turned cube holds world cell `w`'s centre.
    pub fn invert(&self, w: IVec3) -> IVec3 {
        self.model_unshifted(self.unshifted(w) + DVec3::splat(0.5)).floor().as_ivec3()
    }

    /// The world cells whose centres the turned cubes of model cells
    /// `lo..=hi` may hold (the box around the turned box).
    pub fn apply_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        let (min, max) = self.turned_points(lo, hi);
        // A centre c in min..=max: c − ½ is a whole number there. Widened
        // by TIE_SLACK: a centre on the box's face to rounding may go to a
        // model cell inside (`invert` rounds the other way round), and a
        // region composed again must hold it.
        // Saturated: a box past the 32-bit range is refused by the world's limit after.
        let (lo, hi) = ((min - 0.5 - TIE_SLACK).ceil().as_ivec3(), (max - 0.5 + TIE_SLACK).floor().as_ivec3());
        (lo.saturating_add(self.shift), hi.saturating_add(self.shift))
    }

    /// The world cells the turned cubes of the model cells in `blocks`
    /// (inclusive boxes: a model's hull) reach into: the cells around
    /// their turned boxes of points, which an exact tracer's box must hold
    /// (wider than [`TurnedMap::apply_box`]).
    pub fn cover_blocks(&self, blocks: &[(IVec3, IVec3)]) -> (IVec3, IVec3) {
        let spread = DMat3::from_cols(self.a.x_axis.abs(), self.a.y_axis.abs(), self.a.z_axis.abs());
        let (min, max) = blocks.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(min, max), &(lo, hi)| {
            // A box of points c ± h turns to a box around a·c ± |a|·h.
            let (a, b) = (lo.as_dvec3(), (hi + IVec3::ONE).as_dvec3());
            let centre = self.world_unshifted((a + b) * 0.5);
            let half = spread * ((b - a) * 0.5);
            (min.min(centre - half), max.max(centre + half))
        });
        let (lo, hi) = (min.floor().as_ivec3(), max.ceil().as_ivec3() - IVec3::ONE);
        (lo.saturating_add(self.shift), hi.saturating_add(self.shift))
    }

    /// The box of points (less the whole shift) around the turned cubes of
    /// model cells `lo..=hi`.
    fn turned_points(&self, lo: IVec3, hi: IVec3) -> (DVec3, DVec3) {
        image_box(|x| self.world_unshifted(x), lo.as_dvec3(), (hi + IVec3::ONE).as_dvec3())
    }

    /// The map from model grid points to world points: world point
    /// `a · x + at` of model grid point `x`.
    pub fn to_world(&self) -> (DMat3, DVec3) {
        (self.a, self.shift.as_dvec3() + self.frac)
    }

    /// The map from world points to model grid points, in parts: model
    /// point `x = m · (w − shift) + c` of world point `w`, with `m`
    /// orthogonal and `shift` the translation's whole part (kept out of
    /// the floats, so the tracers subtract it before they round).
    pub fn to_model(&self) -> (DMat3, IVec3, DVec3) {
        let m = self.a.transpose();
        (m, self.shift, -(m * self.frac))
    }

    /// The model cells [`TurnedMap::invert`] gives for the world cells
    /// `lo..=hi`: those holding their centres' preimages.
    pub fn invert_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        let half = DVec3::splat(0.5);
        let (a, b) = (self.unshifted(lo) + half, self.unshifted(hi) + half);
        let (min, max) = image_box(|u| self.model_unshifted(u), a, b);
        // Widened as `apply_box` is: a centre's preimage on a face to
        // rounding may fall in the cell beyond.
        ((min - TIE_SLACK).floor().as_ivec3(), (max + TIE_SLACK).floor().as_ivec3())
    }
}

/// How far (in voxels) a cell centre may lie outside a turned box and
/// still be counted in: more than the rounding of the map's f64 arithmetic
/// on a model's size, far less than any real distance between centres.
const TIE_SLACK: f64 = 1e-9;

/// The box around the image under `f` of the box of points `a..=b`.
fn image_box(f: impl Fn(DVec3) -> DVec3, a: DVec3, b: DVec3) -> (DVec3, DVec3) {
    let corners = (0..8).map(|k| DVec3::new([a.x, b.x][k & 1], [a.y, b.y][(k >> 1) & 1], [a.z, b.z][k >> 2]));
    corners.map(f).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), p| (l.min(p), h.max(p)))
}

/// How an object's model cells land on world cells: exactly by a signed
/// permutation and an offset, or by a free turn through cell centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Placing {
    Cells(CellMap),
    Turned(TurnedMap),
}

impl Placing {
    /// The exact map, where the placement has no free turn.
    pub fn cells(&self) -> Option<&CellMap> {
        match self {
            Placing::Cells(map) => Some(map),
            Placing::Turned(_) => None,
        }
    }

    pub fn apply(&self, v: IVec3) -> IVec3 {
        match self {
            Placing::Cells(map) => map.apply(v),
            Placing::Turned(map) => map.apply(v),
        }
    }

    pub fn invert(&self, w: IVec3) -> IVec3 {
        match self {
            Placing::Cells(map) => map.invert(w),
            Placing::Turned(map) => map.invert(w),
        }
    }

    pub fn apply_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        match self {
            Placing::Cells(map) => map.apply_box(lo, hi),
            Placing::Turned(map) => map.apply_box(lo, hi),
        }
    }

    pub fn invert_box(&self, lo: IVec3, hi: IVec3) -> (IVec3, IVec3) {
        match self {
            Placing::Cells(map) => map.invert_box(lo, hi),
            Placing::Turned(map) => map.invert_box(lo, hi),
        }
    }

    /// The model cells a world brush shape covers, as a shape of the same
    /// kind. Through a free turn a box becomes the box of the model's own
    /// axes around the cells it reaches (a turned box is no box of cells).
    pub fn invert_shape(&self, shape: &Shape) -> Shape {
        match (self, *shape) {
            (Placing::Cells(map), _) => map.invert_shape(shape),
            (Placing::Turned(map), Shape::Voxel(p)) => Shape::Voxel(map.invert(p)),
            (Placing::Turned(map), Shape::Sphere { center, radius }) => {
                Shape::Sphere { center: map.invert(center), radius }
            }
            (Placing::Turned(map), Shape::Box { min, max }) => {
                let (min, max) = map.invert_box(min, max);
                Shape::Box { min, max }
            }
        }
    }
}

impl Placement {
    /// How this placement puts a model of `size` on world cells; `None`
    /// where an exact offset leaves the 32-bit range.
    pub fn placing(&self, size: [u32; 3]) -> Option<Placing> {
        match self.turned {
            Some(rigid) => Some(Placing::Turned(TurnedMap::new(rigid, size, self.centred))),
            None => self.cell_map(size).map(Placing::Cells),
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
            let placement = Placement {
                model: 0,
                transform: Transform { rotation, translation: [7, -3, 11] },
                centred: true,
                turned: None,
            };
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
        let placement = Placement {
            model: 0,
            transform: Transform { rotation: flip_x, translation: [0, 0, 0] },
            centred: true,
            turned: None,
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
        let quarter = Rotation { axis: [1, 0, 2], sign: [-1, 1, 1] };
        let placement = Placement {
            model: 0,
            transform: Transform { rotation: quarter, translation: [10, 20, 30] },
            centred: true,
            turned: None,
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
