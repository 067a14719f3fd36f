//! Clicks on the panels when frames are slow.
//!
//! egui times a press and its release by the frames that take them in
//! (egui-winit stamps a frame's input when the frame starts), and a press
//! held longer than `max_click_duration` is no click. A frame that lasts
//! long (lavapipe compiling a kernel, or running one pass of the denoiser
//! over a large view) between the press and the release lengthens the click
//! by up to that frame, so a quick click across it was lost. The limit is
//! raised by the last frame's length: a click held as briefly as ever still
//! counts, and a long press with quick frames is still none.

/// egui's own limit (its default), in seconds.
const CLICK_SECONDS: f64 = 0.8;

/// Sets egui's click limit for the frame `raw` starts: [`CLICK_SECONDS`]
/// plus the time since the previous frame's input.
pub(super) fn allow_for_frame_length(ctx: &egui::Context, raw: &egui::RawInput) {
    let Some(now) = raw.time else { return };
    let frame = (now - ctx.input(|i| i.time)).max(0.0);
    ctx.options_mut(|o| o.input_options.max_click_duration = CLICK_SECONDS + frame);
}

#[cfg(test)]
mod tests {
    use super::*;

    const AT: egui::Pos2 = egui::pos2(30.0, 20.0);

    fn button(pressed: Option<bool>) -> egui::Event {
        match pressed {
            Some(pressed) => egui::Event::PointerButton {
                pos: AT,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::NONE,
            },
            None => egui::Event::PointerMoved(AT),
        }
    }

    /// Frames at the given times, each with its pointer event (`None` a
    /// move to the button); whether the button drawn under it was clicked.
    fn clicked(frames: &[(f64, Option<bool>)], allow: bool) -> bool {
        let ctx = egui::Context::default();
        let mut clicked = false;
        for &(time, event) in frames {
            let raw = egui::RawInput { time: Some(time), events: vec![button(event)], ..Default::default() };
            if allow {
                allow_for_frame_length(&ctx, &raw);
            }
            let mut output = ctx.run_ui(raw, |ui| {
                egui::CentralPanel::default().show(ui, |ui| clicked |= ui.button("Denoise").clicked());
            });
            output.textures_delta.clear();
        }
        clicked
    }

    #[test]
    fn a_quick_click_across_a_slow_frame_still_counts() {
        // Pressed during one frame, released 0.1 s later during a frame of
        // 1.2 s: egui sees a press of 1.2 s.
        let frames = [(0.0, None), (0.05, None), (0.1, Some(true)), (1.3, Some(false)), (1.35, None)];
        assert!(!clicked(&frames, false), "egui's default limit should drop this click");
        assert!(clicked(&frames, true));
    }

    #[test]
    fn a_long_press_over_quick_frames_is_still_no_click() {
        let mut frames: Vec<(f64, Option<bool>)> = vec![(0.0, None), (0.05, Some(true))];
        frames.extend((2..30).map(|i| (0.05 * f64::from(i), None)));
        frames.push((1.5, Some(false)));
        assert!(!clicked(&frames, true));
        let quick = [(0.0, None), (0.05, Some(true)), (0.1, None), (0.15, Some(false))];
        assert!(clicked(&quick, true));
    }
}
