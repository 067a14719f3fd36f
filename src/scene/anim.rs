//! Time in a scene graph: what a transform or a shape node shows at a frame.
//!
//! Keys are sampled as `ogt_vox` samples them (`sample_keyframe_transform`,
//! `ogt_vox_sample_anim_model`), so that a frame shows what MagicaVoxel
//! and the readers built on `ogt_vox` show:
//!
//! - keys are taken in the order of their frames (`_f`, 0 where missing);
//! - before the first key a node shows the first, after the last the last;
//! - with `_loop` set on the node, a frame outside the keys wraps into
//!   `first..=last` (one period is `last − first + 1` frames);
//! - between two keys a translation moves linearly, each coordinate rounded
//!   toward zero as `ogt_vox` rounds it (`(int32_t)` of a `float`), and a
//!   rotation and a shape's model stay the earlier key's.
//!
//! octovox adds one key of its own, [`EASE_KEY`], which other readers
//! ignore: `step` holds the key's translation until the next key, `smooth`
//! eases in and out (smoothstep); without it a key is `linear`.

use super::graph::{Attributes, GraphError, is_set};
use super::transform::Pose;

/// The keyframe attribute octovox keeps a key's easing in.
pub const EASE_KEY: &str = "_ov_ease";

/// How a translation goes from a key to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ease {
    /// Held until the next key.
    Step,
    /// Straight on, as MagicaVoxel moves it.
    #[default]
    Linear,
    /// Slow out of the key and into the next (smoothstep).
    Smooth,
}

impl Ease {
    pub const ALL: [Ease; 3] = [Ease::Step, Ease::Linear, Ease::Smooth];

    pub fn name(self) -> &'static str {
        match self {
            Ease::Step => "step",
            Ease::Linear => "linear",
            Ease::Smooth => "smooth",
        }
    }

    pub fn from_name(name: &str) -> Option<Ease> {
        Ease::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The key's easing: its [`EASE_KEY`], linear without one.
    pub fn of(key: &Attributes, node: u32) -> Result<Ease, GraphError> {
        match key.get(EASE_KEY) {
            None => Ok(Ease::Linear),
            Some(text) => Ease::from_name(text.trim())
                .ok_or_else(|| GraphError::Bad(format!("node {node} has an unknown easing {EASE_KEY}={text:?}"))),
        }
    }

    /// Writes it into a key (linear, the default, as no attribute).
    pub fn write(self, key: &mut Attributes) {
        match self {
            Ease::Linear => key.remove(EASE_KEY),
            other => key.insert(EASE_KEY.to_owned(), other.name().to_owned()),
        };
    }

    /// The fraction of the way to the next key at fraction `t` of the time.
    fn shaped(self, t: f32) -> f32 {
        match self {
            Ease::Step => 0.0,
            Ease::Linear => t,
            Ease::Smooth => t * t * (3.0 - 2.0 * t),
        }
    }
}

/// A key's frame: its `_f`, 0 where it has none.
pub fn key_frame(key: &Attributes, node: u32) -> Result<u32, GraphError> {
    match key.get("_f") {
        None => Ok(0),
        Some(text) => text
            .trim()
            .parse::<u32>()
            .map_err(|_| GraphError::Bad(format!("node {node} has a malformed frame index _f={text:?}"))),
    }
}

/// The keys' (frame, index) in the order of their frames (file order among
/// equal frames).
pub fn keys_in_time<'a>(
    keys: impl Iterator<Item = &'a Attributes>,
    node: u32,
) -> Result<Vec<(u32, usize)>, GraphError> {
    let mut timed =
        keys.enumerate().map(|(k, key)| Ok((key_frame(key, node)?, k))).collect::<Result<Vec<_>, GraphError>>()?;
    timed.sort_by_key(|&(frame, _)| frame);
    Ok(timed)
}

/// `frame` wrapped into `first..=last`, as `ogt_vox`'s
/// `compute_looped_frame_index` wraps it (frames before `first` too).
pub fn looped(first: u32, last: u32, frame: u32) -> u32 {
    let period = u64::from(last - first) + 1;
    let wrapped = if frame >= first {
        u64::from(first) + u64::from(frame - first) % period
    } else {
        u64::from(last) - u64::from(first - frame - 1) % period
    };
    u32::try_from(wrapped).expect("within first..=last")
}

/// Where `frame` falls among keys sorted by frame: the earlier key, and the
/// later one with the fraction of the time between them that has passed
/// (`None` before the first key, after the last, or on a key).
fn bracket(timed: &[(u32, usize)], looping: bool, frame: u32) -> (usize, Option<(usize, f32)>) {
    let (first, last) = (timed[0].0, timed[timed.len() - 1].0);
    let frame = if looping { looped(first, last, frame) } else { frame };
    if frame <= first {
        return (timed[0].1, None);
    }
    if frame >= last {
        return (timed[timed.len() - 1].1, None);
    }
    // The last key at or before `frame`; there is a later one (frame < last).
    let at = timed.partition_point(|&(f, _)| f <= frame) - 1;
    let (from, to) = (timed[at], timed[at + 1]);
    // As ogt_vox: the frame distances as floats, then their quotient.
    let t = (frame - from.0) as f32 / (to.0 - from.0) as f32;
    (from.1, Some((to.1, t)))
}

/// The pose a transform node's keys give at `frame` (the identity for a
/// node without keys): translations move linearly as `ogt_vox` moves them;
/// rotations hold the earlier key as in `ogt_vox`, unless a key turns
/// freely (`_ov_turn`), then they turn by slerp (see [`Pose::toward`]).
pub fn sample_transform(
    keys: &[Attributes],
    node_attributes: &Attributes,
    frame: u32,
    node: u32,
) -> Result<Pose, GraphError> {
    if keys.is_empty() {
        return Ok(Pose::IDENTITY);
    }
    let timed = keys_in_time(keys.iter(), node)?;
    let (from, next) = bracket(&timed, is_set(node_attributes, "_loop"), frame);
    let held = super::graph::parse_pose(&keys[from], node)?;
    let Some((to, t)) = next else { return Ok(held) };
    let toward = super::graph::parse_pose(&keys[to], node)?;
    let s = Ease::of(&keys[from], node)?.shaped(t);
    let mut translation = held.transform.translation;
    for (axis, out) in translation.iter_mut().enumerate() {
        // f32 and a cast that rounds toward zero, as ogt_vox computes it
        // (exact up to 2^24; farther translations round as ogt_vox's do).
        let (a, b) = (held.transform.translation[axis] as f32, toward.transform.translation[axis] as f32);
        *out = i64::from((b * s + a * (1.0 - s)) as i32);
    }
    Ok(held.toward(&toward, f64::from(s), translation))
}

/// Which key of a shape node's models shows at `frame` (`None` for a shape
/// without models): the earlier key's, never a blend.
pub fn sample_model(
    models: &[(u32, Attributes)],
    node_attributes: &Attributes,
    frame: u32,
    node: u32,
) -> Result<Option<usize>, GraphError> {
    if models.is_empty() {
        return Ok(None);
    }
    let timed = keys_in_time(models.iter().map(|m| &m.1), node)?;
    Ok(Some(bracket(&timed, is_set(node_attributes, "_loop"), frame).0))
}

/// The index of the key at exactly `frame`, if there is one: the one a
/// frame shows where several share it (the last in file order, as
/// [`keys_in_time`] orders them).
pub fn key_at(keys: &[Attributes], frame: u32, node: u32) -> Result<Option<usize>, GraphError> {
    let timed = keys_in_time(keys.iter(), node)?;
    Ok(timed.iter().rev().find(|&&(f, _)| f == frame).map(|&(_, k)| k))
}

/// Whether a transform node moves: keys at more than one frame.
pub fn is_animated(keys: &[Attributes], node: u32) -> Result<bool, GraphError> {
    let timed = keys_in_time(keys.iter(), node)?;
    Ok(timed.first().map(|f| f.0) != timed.last().map(|l| l.0))
}

/// Frames a second where a document does not say.
pub const DEFAULT_FPS: u32 = 12;
/// Most frames a second a document may ask for.
pub const MAX_FPS: u32 = 240;

/// The META chunk's key for the range MagicaVoxel plays (since 0.99.7.2),
/// and octovox's own keys beside it for the speed and whether playing loops.
const RANGE_KEY: &str = "_anim_range";
const FPS_KEY: &str = "_ov_fps";
const LOOP_KEY: &str = "_ov_loop";

/// A document's playback settings, as its META chunk says them; `None`
/// where it says nothing (the range then spans the keys, the speed is
/// [`DEFAULT_FPS`] and playing loops).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Animation {
    pub range: Option<(u32, u32)>,
    pub fps: Option<u32>,
    pub looping: Option<bool>,
}

impl Animation {
    /// The settings a META chunk's dictionary holds, and a sentence for each
    /// value that cannot be read (which is then left out).
    pub fn from_meta(meta: &Attributes) -> (Animation, Vec<String>) {
        let mut warnings = Vec::new();
        let mut bad = |key: &str, text: &str| {
            warnings.push(format!("META {key}={text:?} is not understood: ignored"));
        };
        let range = meta.get(RANGE_KEY).and_then(|text| {
            let parts: Vec<Option<u32>> = text.split_whitespace().map(|p| p.parse().ok()).collect();
            let range = match parts[..] {
                [Some(a), Some(b)] if a <= b => Some((a, b)),
                _ => None,
            };
            if range.is_none() {
                bad(RANGE_KEY, text);
            }
            range
        });
        let fps = meta.get(FPS_KEY).and_then(|text| {
            let fps = text.trim().parse().ok().filter(|f| (1..=MAX_FPS).contains(f));
            if fps.is_none() {
                bad(FPS_KEY, text);
            }
            fps
        });
        let looping = meta.get(LOOP_KEY).and_then(|text| match text.trim() {
            "0" => Some(false),
            "1" => Some(true),
            _ => {
                bad(LOOP_KEY, text);
                None
            }
        });
        (Animation { range, fps, looping }, warnings)
    }

    /// Writes the settings into a META dictionary, keeping its other keys.
    pub fn write_meta(&self, meta: &mut Attributes) {
        let mut set = |key: &str, value: Option<String>| match value {
            Some(value) => meta.insert(key.to_owned(), value),
            None => meta.remove(key),
        };
        set(RANGE_KEY, self.range.map(|(a, b)| format!("{a} {b}")));
        set(FPS_KEY, self.fps.map(|f| f.to_string()));
        set(LOOP_KEY, self.looping.map(|l| u8::from(l).to_string()));
    }

    pub fn fps(&self) -> u32 {
        self.fps.unwrap_or(DEFAULT_FPS)
    }

    pub fn looping(&self) -> bool {
        self.looping.unwrap_or(true)
    }
}

/// The frames between the first and the last key of every node of
/// `graph` (`None` for a graph without keys past frame 0).
pub fn keyed_range(graph: &super::graph::SceneGraph) -> Result<Option<(u32, u32)>, GraphError> {
    use super::graph::NodeKind;
    let mut range: Option<(u32, u32)> = None;
    for node in &graph.nodes {
        let frames: Vec<u32> = match &node.kind {
            NodeKind::Transform { frames, .. } => {
                frames.iter().map(|k| key_frame(k, node.id)).collect::<Result<_, _>>()?
            }
            NodeKind::Shape { models } => models.iter().map(|m| key_frame(&m.1, node.id)).collect::<Result<_, _>>()?,
            NodeKind::Group { .. } => Vec::new(),
        };
        for f in frames {
            range = Some(range.map_or((f, f), |(a, b)| (a.min(f), b.max(f))));
        }
    }
    Ok(range.filter(|&(a, b)| (a, b) != (0, 0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::transform::Rotation;

    fn key(frame: u32, t: [i32; 3], r: Option<u8>) -> Attributes {
        let mut key = Attributes::new();
        key.insert("_f".into(), frame.to_string());
        key.insert("_t".into(), format!("{} {} {}", t[0], t[1], t[2]));
        if let Some(r) = r {
            key.insert("_r".into(), r.to_string());
        }
        key
    }

    fn at(keys: &[Attributes], looping: bool, frame: u32) -> crate::scene::transform::Transform {
        let mut node = Attributes::new();
        if looping {
            node.insert("_loop".into(), "1".into());
        }
        sample_transform(keys, &node, frame, 7).unwrap().transform
    }

    /// animation.vox's three keys (0, 9, 30): held before and after,
    /// linear between, each coordinate rounded toward zero.
    #[test]
    fn translations_interpolate_and_round_toward_zero() {
        let keys = [key(0, [14, -29, 20], None), key(9, [-29, 31, 20], None), key(30, [-131, -29, 20], None)];
        assert_eq!(at(&keys, false, 0).translation, [14, -29, 20]);
        // 14 + (−43)·4/9 = −5.11 → −5; −29 + 60·4/9 = −2.33 → −2.
        assert_eq!(at(&keys, false, 4).translation, [-5, -2, 20]);
        assert_eq!(at(&keys, false, 9).translation, [-29, 31, 20]);
        // −29 − 102·11/21 = −82.43 → −82; 31 − 60·11/21 = −0.43 → 0.
        assert_eq!(at(&keys, false, 20).translation, [-82, 0, 20]);
        assert_eq!(at(&keys, false, 31).translation, [-131, -29, 20], "held after the last key");
        // Looping: the period is 31 frames, so 31 shows frame 0 and 35 frame 4.
        assert_eq!(at(&keys, true, 31).translation, [14, -29, 20]);
        assert_eq!(at(&keys, true, 35), at(&keys, false, 4));
    }

    #[test]
    fn rotations_and_models_hold_the_earlier_key() {
        let turned = Rotation::from_byte(1 | (2 << 2)).unwrap();
        let keys = [key(0, [0, 0, 0], None), key(10, [10, 0, 0], Some(1 | (2 << 2)))];
        assert_eq!(at(&keys, false, 9).rotation, Rotation::IDENTITY);
        assert_eq!(at(&keys, false, 10).rotation, turned);
        let models: Vec<(u32, Attributes)> = [(0, 3), (1, 6), (2, 9)].map(|(m, f)| (m, key(f, [0, 0, 0], None))).into();
        let shown = |frame| sample_model(&models, &Attributes::new(), frame, 1).unwrap();
        assert_eq!([0, 3, 5, 6, 8, 9, 100].map(shown), [0, 0, 0, 1, 1, 2, 2].map(Some));
    }

    #[test]
    fn loops_wrap_frames_before_and_after_the_keys() {
        assert_eq!([5, 6, 7, 8, 9, 4, 3, 0].map(|f| looped(5, 8, f)), [5, 6, 7, 8, 5, 8, 7, 8]);
        assert_eq!(looped(0, 0, u32::MAX), 0);
        assert_eq!(looped(0, u32::MAX, u32::MAX), u32::MAX);
        // One whole period (2^31 frames) before the first key shows the first.
        assert_eq!(looped(1 << 31, u32::MAX, 0), 1 << 31);
    }

    #[test]
    fn easing_shapes_the_way_between_keys() {
        let mut keys = [key(0, [0, 0, 0], None), key(10, [100, 0, 0], None)];
        Ease::Step.write(&mut keys[0]);
        assert_eq!(at(&keys, false, 9).translation[0], 0);
        Ease::Smooth.write(&mut keys[0]);
        // smoothstep(0.2) = 0.104.
        assert_eq!(at(&keys, false, 2).translation[0], 10);
        assert_eq!(at(&keys, false, 5).translation[0], 50);
        Ease::Linear.write(&mut keys[0]);
        assert!(!keys[0].contains_key(EASE_KEY));
        keys[0].insert(EASE_KEY.into(), "bouncy".into());
        assert!(sample_transform(&keys, &Attributes::new(), 3, 4).is_err());
    }

    /// Two keys at one frame: the frame shows the later in file order, and
    /// that is the key a move there changes (a review found the first).
    #[test]
    fn of_keys_sharing_a_frame_the_shown_one_is_changed() {
        let keys =
            [key(0, [0, 0, 0], None), key(5, [1, 0, 0], None), key(5, [2, 0, 0], None), key(10, [3, 0, 0], None)];
        assert_eq!(at(&keys, false, 5).translation[0], 2);
        assert_eq!(key_at(&keys, 5, 7).unwrap(), Some(2));
        assert_eq!(key_at(&keys, 6, 7).unwrap(), None);
    }

    /// Keys far apart in time (2^31) and keys out of order.
    #[test]
    fn far_and_unordered_keys() {
        let keys = [key(1 << 31, [1000, 0, 0], None), key(0, [0, 0, 0], None)];
        assert_eq!(at(&keys, false, 1 << 30).translation[0], 500);
        assert_eq!(at(&keys, false, u32::MAX).translation[0], 1000);
        let mut bad = key(0, [0, 0, 0], None);
        bad.insert("_f".into(), "4294967296".into());
        assert!(sample_transform(&[bad], &Attributes::new(), 0, 1).is_err());
    }
}
