//! The timeline under the view, for a scene of objects: a bar to scrub the
//! frames with the picked object's keys on it, play and pause, the range,
//! the speed and the loop, and keying the picked object at the frame shown.
//!
//! Every change is a script line (`frame N`, `anim …`, `object key …`,
//! `object unkey`), run like any other: recorded, journaled, undone where it
//! is an edit. Only the frames shown while playing or scrubbing go by
//! [`AppCommand::ShowFrame`], which the recording and the journal skip; the
//! frame where playing or scrubbing stops is a `frame N` line, so an edit
//! made there replays where it was made.

use web_time::Instant;

use egui::{Color32, Sense, Stroke, Vec2};

use super::command::AppCommand;
use super::session::Session;
use octovox::scene::anim::{Ease, MAX_FPS, key_frame};
use octovox::scene::graph::NodeKind;
use octovox::scene::objects::Objects;
use octovox::script::{AnimLine, Line, ObjectLine, ObjectRef};

/// Height of the timeline panel in points.
pub const TIMELINE_HEIGHT: f32 = 56.0;
/// Width of the frame number's label: `frame 4294967295` fits.
const FRAME_LABEL_WIDTH: f32 = 110.0;

/// The timeline's own state: playing or not, the easing of new keys, and
/// values being edited.
#[derive(Debug, Default)]
pub struct Playback {
    /// Playing since when, from which frame.
    playing: Option<(Instant, u32)>,
    /// The easing the Key button keys with.
    pub ease: Ease,
    /// The frame the bar is being dragged to (shown, not yet a line).
    scrubbing: Option<u32>,
}

impl Playback {
    pub fn playing(&self) -> bool {
        self.playing.is_some()
    }

    /// Stops playing, where it is (a new scene starts still).
    pub fn stop(&mut self) {
        self.playing = None;
        self.scrubbing = None;
    }

    /// Starts playing from `shown`, or stops (the frame it stopped at is
    /// then run as a `frame N` line by [`show`]).
    pub fn toggle(&mut self, shown: u32) {
        self.playing = match self.playing {
            Some(_) => None,
            None => Some((Instant::now(), shown)),
        };
    }
}

/// The frame playing shows `elapsed` seconds after it started at `from`,
/// `fps` frames a second through `first..=last`: wrapping to the first when
/// `looping`, else holding the last; and whether it goes on.
pub fn frame_after(from: u32, elapsed: f64, (first, last): (u32, u32), fps: u32, looping: bool) -> (u32, bool) {
    let from = u64::from(from.clamp(first, last));
    let steps = (elapsed.max(0.0) * f64::from(fps)).floor() as u64;
    let (first, last) = (u64::from(first), u64::from(last));
    let reached = from.saturating_add(steps);
    if reached <= last {
        return (reached as u32, true);
    }
    if !looping {
        return (last as u32, false);
    }
    let period = last - first + 1;
    ((first + (reached - first) % period) as u32, true)
}

/// The object the key buttons act on and whose keys show: the picked one,
/// or the only one.
fn keyed_object(objects: &Objects) -> Option<usize> {
    objects.selected.or((objects.list().len() == 1).then_some(0))
}

/// The frames of object `index`'s keys.
fn key_frames(objects: &Objects, index: usize) -> Vec<u32> {
    let Ok(node) = objects.transform_node(index) else { return Vec::new() };
    let NodeKind::Transform { frames, .. } = &node.kind else { return Vec::new() };
    frames.iter().filter_map(|k| key_frame(k, node.id).ok()).collect()
}

/// Draws the timeline at the bottom of the window; returns what it asks for.
pub fn show(ui: &mut egui::Ui, objects: &Objects, playback: &mut Playback, out: &mut Vec<AppCommand>) {
    let shown = u32::try_from(objects.frame).unwrap_or(u32::MAX);
    let (first, last) = objects.frame_range();
    let settings = objects.graph.as_ref().map(|g| g.animation).unwrap_or_default();
    advance(ui.ctx(), playback, shown, (first, last), settings.fps(), settings.looping(), out);
    egui::Panel::bottom("timeline").resizable(false).exact_size(TIMELINE_HEIGHT).show(ui, |ui| {
        ui.horizontal(|ui| {
            let label = if playback.playing() { "⏸ Pause" } else { "▶ Play" };
            if ui.button(label).on_hover_text("Space").clicked() {
                out.extend(toggle(playback, shown).map(|line| AppCommand::Lines(vec![line])));
            }
            // A fixed width: the bar after it does not shift as the digits change.
            let label = egui::Label::new(format!("frame {}", playback.scrubbing.unwrap_or(shown)));
            ui.add_sized([FRAME_LABEL_WIDTH, 18.0], label);
            let keyed = keyed_object(objects);
            let keys = keyed.map_or(Vec::new(), |i| key_frames(objects, i));
            scrub_bar(ui, playback, shown, (first, last), &keys, out);
        });
        ui.horizontal(|ui| {
            range_and_speed(ui, (first, last), settings.fps(), settings.looping(), out);
            ui.separator();
            key_buttons(ui, objects, playback, shown, out);
        });
    });
}

/// Starts or stops playing; a stop leaves the frame shown as a line to run.
pub fn toggle(playback: &mut Playback, shown: u32) -> Option<Line> {
    let stopping = playback.playing();
    playback.toggle(shown);
    stopping.then_some(Line::Frame(shown))
}

/// The frame `by` frames from `shown` within the range, wrapping.
pub fn stepped(objects: &Objects, shown: u32, by: i32) -> u32 {
    let (first, last) = objects.frame_range();
    let period = i64::from(last - first) + 1;
    let at = i64::from(shown.clamp(first, last)) - i64::from(first) + i64::from(by);
    (i64::from(first) + at.rem_euclid(period)) as u32
}

/// The lines that key (or unkey) the object the timeline keys, picking it
/// first where it is not picked; `None` where there is no such object.
pub fn key_lines(objects: &Objects, line: ObjectLine) -> Option<Vec<Line>> {
    let index = keyed_object(objects)?;
    let mut lines = Vec::new();
    if objects.selected != Some(index) {
        lines.push(Line::Object(ObjectLine::Pick(ObjectRef::Index(index))));
    }
    lines.push(Line::Object(line));
    Some(lines)
}

/// While playing: the frame due now, and the next repaint.
fn advance(
    ctx: &egui::Context,
    playback: &mut Playback,
    shown: u32,
    range: (u32, u32),
    fps: u32,
    looping: bool,
    out: &mut Vec<AppCommand>,
) {
    let Some((since, from)) = playback.playing else { return };
    let (due, going) = frame_after(from, since.elapsed().as_secs_f64(), range, fps, looping);
    if due != shown {
        out.push(AppCommand::ShowFrame(due));
    }
    if going {
        ctx.request_repaint_after(std::time::Duration::from_secs_f64(0.5 / f64::from(fps)));
    } else {
        playback.playing = None;
        out.push(AppCommand::Lines(vec![Line::Frame(due)]));
    }
}

/// The bar of frames `first..=last`: the keys as marks, the frame shown as
/// a line; a click or a drag shows the frame under the pointer.
fn scrub_bar(
    ui: &mut egui::Ui,
    playback: &mut Playback,
    shown: u32,
    (first, last): (u32, u32),
    keys: &[u32],
    out: &mut Vec<AppCommand>,
) {
    let width = ui.available_width().max(40.0);
    let (rect, response) = ui.allocate_exact_size(Vec2::new(width, 18.0), Sense::click_and_drag());
    let span = f64::from(last - first).max(1.0);
    let x_of = |frame: u32| rect.left() + ((f64::from(frame.saturating_sub(first)) / span) as f32) * rect.width();
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect.shrink2(Vec2::new(0.0, 6.0)), 2.0, ui.visuals().widgets.inactive.bg_fill);
    for &key in keys.iter().filter(|&&k| (first..=last).contains(&k)) {
        let c = egui::pos2(x_of(key), rect.center().y);
        let diamond =
            vec![c + Vec2::new(0.0, -5.0), c + Vec2::new(5.0, 0.0), c + Vec2::new(0.0, 5.0), c + Vec2::new(-5.0, 0.0)];
        painter.add(egui::Shape::convex_polygon(diamond, Color32::from_rgb(240, 200, 60), Stroke::NONE));
    }
    let at = playback.scrubbing.unwrap_or(shown);
    painter.vline(x_of(at.clamp(first, last)), rect.y_range(), Stroke::new(2.0, Color32::from_rgb(90, 170, 255)));
    let pointed = response.interact_pointer_pos().map(|p| {
        let t = f64::from(((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0));
        first.saturating_add((t * span).round() as u32).min(last)
    });
    if let Some(frame) = pointed.filter(|_| response.dragged() || response.clicked()) {
        playback.playing = None;
        if frame != at {
            out.push(AppCommand::ShowFrame(frame));
        }
        playback.scrubbing = Some(frame);
    }
    if (response.drag_stopped() || response.clicked())
        && let Some(frame) = playback.scrubbing.take()
    {
        out.push(AppCommand::Lines(vec![Line::Frame(frame)]));
    }
}

/// The range, speed and loop, each an `anim` line when changed (a drag
/// when it ends: one undo step, not one a pixel).
fn range_and_speed(ui: &mut egui::Ui, (first, last): (u32, u32), fps: u32, looping: bool, out: &mut Vec<AppCommand>) {
    let settled = |r: &egui::Response| (r.changed() && !r.dragged()) || r.drag_stopped();
    let (mut a, mut b, mut speed) = (first, last, fps);
    ui.label("range");
    let ra = ui.add(egui::DragValue::new(&mut a).range(0..=last));
    let rb = ui.add(egui::DragValue::new(&mut b).range(first..=u32::MAX));
    if settled(&ra) || settled(&rb) {
        out.push(AppCommand::Lines(vec![Line::Anim(AnimLine::Range(a.min(b), b.max(a)))]));
    }
    let rs = ui.add(egui::DragValue::new(&mut speed).range(1..=MAX_FPS).suffix(" fps"));
    if settled(&rs) {
        out.push(AppCommand::Lines(vec![Line::Anim(AnimLine::Fps(speed))]));
    }
    let mut on = looping;
    if ui.checkbox(&mut on, "loop").changed() {
        out.push(AppCommand::Lines(vec![Line::Anim(AnimLine::Loop(on))]));
    }
}

/// Key and Unkey at the frame shown, for the picked object (or the only
/// one), with the easing toward the next key.
fn key_buttons(ui: &mut egui::Ui, objects: &Objects, playback: &mut Playback, shown: u32, out: &mut Vec<AppCommand>) {
    let Some(index) = keyed_object(objects) else {
        ui.label("pick an object to key it");
        return;
    };
    let pick = |line: ObjectLine| AppCommand::Lines(key_lines(objects, line).unwrap_or_default());
    egui::ComboBox::from_id_salt("ease").selected_text(playback.ease.name()).show_ui(ui, |ui| {
        for ease in Ease::ALL {
            ui.selectable_value(&mut playback.ease, ease, ease.name());
        }
    });
    if ui.button("Key").on_hover_text("K: key the object at this frame").clicked() {
        out.push(pick(ObjectLine::Key(playback.ease)));
    }
    let has_key = key_frames(objects, index).contains(&shown);
    if ui.add_enabled(has_key, egui::Button::new("Unkey")).on_hover_text("Shift+K").clicked() {
        out.push(pick(ObjectLine::Unkey));
    }
}

impl Session {
    /// Shows frame `frame` while playing or scrubbing: the editor's `frame
    /// N`, uploaded and drawn, but not recorded or journaled (`timeline`).
    pub(super) fn show_frame(&mut self, frame: u32) {
        match self.doc.editor.play_frame(frame) {
            Ok(_) => {
                let upload = self.upload();
                self.readouts.stats.last_edit_bytes = Some(upload.bytes);
                self.readouts.stats.last_edit_ranges = upload.ranges;
                self.request_redraw();
            }
            Err(err) => self.ui.error(format!("frame {frame} refused: {err}")),
        }
    }

    /// Space, comma, period, K and Shift+K: play or pause, step a frame,
    /// key or unkey the object the timeline keys.
    pub(super) fn timeline_key(&mut self, command: &AppCommand) {
        let Some(objects) = self.doc.editor.scene.objects() else {
            return self.ui.info("this scene is one model: it has no animation");
        };
        let shown = u32::try_from(objects.frame).unwrap_or(u32::MAX);
        let lines = match *command {
            AppCommand::TogglePlay => toggle(&mut self.ui.playback, shown).into_iter().collect(),
            AppCommand::StepFrame(by) => vec![octovox::script::Line::Frame(stepped(objects, shown, by))],
            AppCommand::Key(on) => {
                let line = if on {
                    octovox::script::ObjectLine::Key(self.ui.playback.ease)
                } else {
                    octovox::script::ObjectLine::Unkey
                };
                match key_lines(objects, line) {
                    Some(lines) => lines,
                    None => return self.ui.info("pick an object to key it"),
                }
            }
            _ => Vec::new(),
        };
        for line in lines {
            let word = line.word();
            self.act(line, word);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn playing_steps_through_the_range_and_wraps_or_stops() {
        assert_eq!(frame_after(0, 0.0, (0, 30), 12, true), (0, true));
        assert_eq!(frame_after(0, 1.0, (0, 30), 12, true), (12, true));
        assert_eq!(frame_after(25, 1.0, (0, 30), 12, true), (6, true), "37 wraps to 6 in 31 frames");
        assert_eq!(frame_after(25, 1.0, (0, 30), 12, false), (30, false));
        assert_eq!(frame_after(50, 0.0, (0, 30), 12, true), (30, true), "a frame past the range starts at its end");
        assert_eq!(frame_after(5, 1e12, (5, 5), 240, true), (5, true));
        assert!(frame_after(0, 1e30, (0, u32::MAX), 240, true).1, "no overflow");
    }
}
