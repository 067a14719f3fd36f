//! Box selection in the window. In select mode (B) a left drag selects the
//! box between the voxels under the press and the release; a drag that
//! starts on a face of the selected box (the face is its handle) moves that
//! face by the voxel steps the drag covers on screen. Ctrl+C / Ctrl+X /
//! Ctrl+V, Delete, Escape and the arrow keys act on it. Everything ends as
//! an editor line (`select`, `copy`, `paste`, `move`…), as a script would.

use glam::{DVec3, IVec3, Vec3};

use octovox::camera::Camera;
use octovox::edit::selection::Region;
use octovox::script::{Line, ObjectLine};

use super::gesture::{Gesture, SelectDrag};
use super::session::Session;
use super::state::Mode;
use super::{Nudge, StrokePhase};

impl Session {
    pub(super) fn select_drag(&mut self, phase: StrokePhase, x: f64, y: f64) {
        match phase {
            StrokePhase::Begin => {
                let drag = match self.handle_at(x, y) {
                    Some(normal) => Some(SelectDrag::Face { normal, start: (x, y) }),
                    None => {
                        let pick = self.pick_or_ground_or_say(x, y, "no voxel or ground there to select from");
                        pick.map(|p| SelectDrag::NewBox(p.cell()))
                    }
                };
                self.gesture = drag.map_or(Gesture::Idle, |drag| Gesture::Select { drag, preview: None });
                self.update_select_preview(x, y);
            }
            StrokePhase::Move => self.update_select_preview(x, y),
            StrokePhase::End => {
                let region = self.dragged_box(x, y);
                self.gesture = Gesture::Idle;
                if let Some(r) = region {
                    self.act(Line::Select(Some((r.min, r.max))), "select");
                }
            }
            StrokePhase::Click => {}
        }
    }

    /// The box to show as the selection: the one being dragged, else the
    /// selected one.
    pub(super) fn shown_selection(&self) -> Option<Region> {
        self.gesture.select_preview().or(self.doc.editor.selection)
    }

    fn update_select_preview(&mut self, x: f64, y: f64) {
        let dragged = self.dragged_box(x, y);
        if let Gesture::Select { preview, .. } = &mut self.gesture {
            *preview = dragged;
        }
    }

    /// The box the drag so far would select.
    fn dragged_box(&self, x: f64, y: f64) -> Option<Region> {
        let Gesture::Select { drag, .. } = self.gesture else { return None };
        match drag {
            SelectDrag::NewBox(from) => {
                let to = self.pick_or_ground(x, y).ok().flatten().map_or(from, |pick| pick.cell());
                Region::new(from, to).ok()
            }
            SelectDrag::Face { normal, start } => {
                let region = self.doc.editor.selection?;
                let (lo, hi) = box_corners(&region, self.doc.editor.scene.origin());
                let face = (lo + hi) * 0.5 + normal.as_vec3() * (hi - lo) * 0.5;
                let steps = self.screen_steps(face, normal, start, (x, y))?;
                super::drag::moved_face(&region, normal, steps)
            }
        }
    }

    /// The outward normal of the selected box's face under window pixel
    /// (x, y), if the pointer is on the box.
    fn handle_at(&self, x: f64, y: f64) -> Option<IVec3> {
        let region = self.doc.editor.selection?;
        let (w, h) = self.window_size();
        let origin = self.doc.editor.scene.origin();
        let (eye, dir) = self.state.camera.basis(w, h, origin).ray_through(x as f32, y as f32);
        let (lo, hi) = box_corners(&region, origin);
        entry_face(eye, dir, lo, hi)
    }

    /// Edit ▸ Paste: the block's min corner in the cell in front of the
    /// face under the cursor.
    pub(super) fn paste_at_cursor(&mut self) {
        let Some((x, y)) = self.pointer.cursor else { return };
        if let Some(pick) = self.pick_or_ground_or_say(x, y, "no face or ground under the cursor to paste on") {
            self.act(Line::Paste(pick.voxel + pick.normal), "paste");
        }
    }

    /// An arrow key: `move` the selection one voxel along the world axis
    /// nearest to that direction as the camera sees it.
    pub(super) fn nudge(&mut self, nudge: Nudge) {
        let step = nudge_step(&self.state.camera, nudge);
        if self.state.mode == Mode::Object {
            return self.act(Line::Object(ObjectLine::Move(step)), "object");
        }
        if self.doc.editor.selection.is_none() {
            self.ui.info("nothing is selected: B, then drag a box");
            return;
        }
        self.act(Line::Move(step), "move");
    }
}

impl Session {
    /// Object mode: a press picks the object it hits (no edit), and a drag
    /// from it moves it over the ground's axes, one undo step.
    pub(super) fn object_click(&mut self, phase: StrokePhase, x: f64, y: f64) {
        if phase == StrokePhase::Begin
            && let Some(centre) = self.ring_at(x, y)
        {
            let last = super::drag::screen_angle(centre, (x, y));
            return self.begin_stroke(Gesture::Ring { centre, last, dragged: 0.0, turned: 0 });
        }
        match phase {
            StrokePhase::Begin | StrokePhase::Click => {
                let Ok(Some(pick)) = self.pick_at(x, y) else { return };
                match self.doc.editor.object_line_for(&pick) {
                    Some(line) => self.act(line, "object"),
                    None if self.doc.editor.scene.objects().is_none() => {
                        return self.ui.info("the scene is one model: no objects to pick");
                    }
                    None => {}
                }
                if phase == StrokePhase::Begin {
                    self.begin_stroke(Gesture::ObjectDrag { at: pick.voxel, start: (x, y), moved: IVec3::ZERO });
                }
            }
            StrokePhase::Move if matches!(self.gesture, Gesture::Ring { .. }) => self.drag_ring(x, y),
            StrokePhase::Move => self.drag_object(x, y),
            StrokePhase::End => self.close_strokes(),
        }
    }

    /// The rotation ring around the picked object, in window pixels (the
    /// one `ui::draw_selection` draws in points): its centre and radius.
    pub(super) fn ring(&self) -> Option<(glam::DVec2, f64)> {
        let objects = self.doc.editor.scene.pickable_objects()?;
        let (lo, hi) = objects.selected.and_then(|i| objects.world_box(i))?;
        let origin = self.doc.editor.scene.origin();
        super::drag::ring(&self.view_basis(), lo - origin, hi - origin, self.view.scale_factor)
    }

    /// The ring's centre, where window pixel (x, y) is on the ring.
    fn ring_at(&self, x: f64, y: f64) -> Option<glam::DVec2> {
        let (centre, radius) = self.ring()?;
        let off = ((glam::DVec2::new(x, y) - centre).length() - radius).abs();
        (off <= super::drag::RING_GRAB * self.view.scale_factor).then_some(centre)
    }

    /// Turns the picked object about the ring's axis (the Turn row's, y
    /// unless Shift+X or Shift+Z chose another) by the whole degrees the
    /// pointer has gone round the ring since the press: counter-clockwise
    /// on screen is counter-clockwise seen from the axis' positive side
    /// (from its negative side when the eye is there).
    fn drag_ring(&mut self, x: f64, y: f64) {
        let Gesture::Ring { centre, last, dragged, turned } = self.gesture else { return };
        let angle = super::drag::screen_angle(centre, (x, y));
        let dragged = dragged + super::drag::wrapped(angle - last);
        let axis = self.ui.outliner.turn.axis;
        let objects = self.doc.editor.scene.pickable_objects();
        let middle = objects
            .and_then(|o| o.selected.and_then(|i| o.world_box(i)))
            .map(|(lo, hi)| f64::from(lo[axis] + hi[axis] + 1) * 0.5);
        let sign = if super::drag::seen_from_below(&self.state.camera, axis, middle) { -1.0 } else { 1.0 };
        let target = (sign * dragged).round() as i64;
        if let Gesture::Ring { last, dragged: so_far, .. } = &mut self.gesture {
            (*last, *so_far) = (angle, dragged);
        }
        if target == turned {
            return;
        }
        let turn = ObjectLine::Turn { axis, degrees: octovox::script::Degrees((target - turned) as f64) };
        if let Err(err) = self.run_line(&Line::Object(turn)) {
            return self.ui.error(format!("object refused: {err}"));
        }
        if let Gesture::Ring { turned, .. } = &mut self.gesture {
            *turned = target;
        }
    }

    /// Moves the dragged object to where the pointer has dragged its point:
    /// whole voxels along x and z, as they look on screen.
    fn drag_object(&mut self, x: f64, y: f64) {
        let Gesture::ObjectDrag { at, start, moved } = self.gesture else { return };
        let Some(steps) = self.ground_steps(at, start, (x, y)) else { return };
        if steps == moved {
            return;
        }
        if let Err(err) = self.run_line(&Line::Object(ObjectLine::Move(steps - moved))) {
            return self.ui.error(format!("object refused: {err}"));
        }
        if let Gesture::ObjectDrag { moved, .. } = &mut self.gesture {
            *moved = steps;
        }
    }

    /// The whole voxels along x and z that a drag from `start` to `end`
    /// covers at the world voxel `at`: the drag in the screen's directions
    /// of those two axes there. (A move can grow the tree and move its
    /// origin, hence world coordinates until here.)
    fn ground_steps(&self, at: IVec3, start: (f64, f64), end: (f64, f64)) -> Option<IVec3> {
        super::drag::ground_steps(&self.view_basis(), at - self.doc.editor.scene.origin(), start, end)
    }
}

/// The box's corners in tree-local coordinates (what camera rays use).
fn box_corners(region: &Region, origin: IVec3) -> (Vec3, Vec3) {
    ((region.min - origin).as_vec3(), (region.max + IVec3::ONE - origin).as_vec3())
}

/// Where the ray from `eye` along `dir` enters the box `lo..hi`: the
/// outward normal of the face it crosses; `None` if it misses, or starts
/// inside.
fn entry_face(eye: Vec3, dir: Vec3, lo: Vec3, hi: Vec3) -> Option<IVec3> {
    let (mut near, mut far, mut normal) = (f32::NEG_INFINITY, f32::INFINITY, IVec3::ZERO);
    for axis in 0..3 {
        if dir[axis] == 0.0 {
            if eye[axis] < lo[axis] || eye[axis] > hi[axis] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo[axis] - eye[axis]) / dir[axis], (hi[axis] - eye[axis]) / dir[axis]);
        let mut outward = IVec3::ZERO;
        outward[axis] = if t0 < t1 { -1 } else { 1 };
        if t0.min(t1) > near {
            (near, normal) = (t0.min(t1), outward);
        }
        far = far.min(t0.max(t1));
    }
    (near > 0.0 && near <= far).then_some(normal)
}

/// One voxel along the world axis nearest to `nudge` as the camera sees
/// it: left/right and away/near on the ground (x or z), up/down along y.
fn nudge_step(camera: &Camera, nudge: Nudge) -> IVec3 {
    let forward = DVec3::new(camera.target.x - camera.eye.x, 0.0, camera.target.z - camera.eye.z);
    let right = forward.cross(DVec3::Y);
    let ground = |v: DVec3| {
        if v.x.abs() >= v.z.abs() {
            IVec3::new(v.x.signum() as i32, 0, 0)
        } else {
            IVec3::new(0, 0, v.z.signum() as i32)
        }
    };
    match nudge {
        Nudge::Right => ground(right),
        Nudge::Left => -ground(right),
        Nudge::Away => ground(forward),
        Nudge::Near => -ground(forward),
        Nudge::Up => IVec3::Y,
        Nudge::Down => IVec3::NEG_Y,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_enters_the_face_it_crosses_first() {
        let (lo, hi) = (Vec3::ZERO, Vec3::splat(4.0));
        let down = entry_face(Vec3::new(2.0, 10.0, 2.0), Vec3::new(0.1, -1.0, 0.0), lo, hi);
        assert_eq!(down, Some(IVec3::Y));
        assert_eq!(entry_face(Vec3::new(-5.0, 1.0, 1.0), Vec3::X, lo, hi), Some(IVec3::NEG_X));
        assert_eq!(entry_face(Vec3::new(-5.0, 9.0, 1.0), Vec3::X, lo, hi), None);
        assert_eq!(entry_face(Vec3::splat(2.0), Vec3::X, lo, hi), None, "from inside");
    }

    #[test]
    fn arrows_follow_the_camera() {
        let from_front = Camera { eye: DVec3::new(0.0, 5.0, 20.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None };
        assert_eq!(nudge_step(&from_front, Nudge::Right), IVec3::X);
        assert_eq!(nudge_step(&from_front, Nudge::Away), IVec3::NEG_Z);
        let from_side = Camera { eye: DVec3::new(20.0, 5.0, 1.0), target: DVec3::ZERO, fov_y_deg: 50.0, ortho: None };
        assert_eq!(nudge_step(&from_side, Nudge::Right), IVec3::NEG_Z);
        assert_eq!(nudge_step(&from_side, Nudge::Near), IVec3::X);
        assert_eq!(nudge_step(&from_side, Nudge::Down), IVec3::NEG_Y);
    }
}
