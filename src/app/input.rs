//! Mouse and keyboard: turns input events that egui did not consume into
//! [`AppCommand`]s, and remembers what is held (buttons, fly keys, modifiers).
//! Both shells feed it: the desktop window its winit events
//! ([`InputEvent::from_winit`]), the browser page egui's (`web::input`),
//! named with winit's key and button names.

use std::collections::HashSet;

use glam::DVec3;
use winit::event::{ElementState, MouseButton};
#[cfg(not(target_arch = "wasm32"))]
use winit::event::{MouseScrollDelta, WindowEvent};
use winit::keyboard::{KeyCode, ModifiersState};

use super::command::{AppCommand, StrokePhase};
use super::session::Pointer;
use super::state::Tool;

/// A right press becomes an orbit once the pointer moved this far (pixels);
/// released before that, it is a click.
const CLICK_SLOP_PIXELS: f64 = 4.0;
/// Pixels per wheel "line" for touchpads that report pixels.
#[cfg(not(target_arch = "wasm32"))]
const PIXELS_PER_LINE: f64 = 40.0;

/// One key going down or up, as [`Input::on_key`] needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyInput {
    pub code: KeyCode,
    pub state: ElementState,
    pub repeat: bool,
    /// Sent by the shell, not typed: see [`Input::on_key`].
    pub synthetic: bool,
}

/// One input event, whichever shell saw it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InputEvent {
    Modifiers(ModifiersState),
    FocusLost,
    CursorLeft,
    /// The pointer, in physical pixels of the view.
    CursorMoved {
        x: f64,
        y: f64,
    },
    Button {
        button: MouseButton,
        pressed: bool,
    },
    /// Wheel steps ("lines"), up positive.
    Wheel {
        steps: f64,
    },
    Key(KeyInput),
}

#[cfg(not(target_arch = "wasm32"))]
impl InputEvent {
    /// The desktop window's event, where it is one the input reads.
    pub fn from_winit(event: &WindowEvent) -> Option<InputEvent> {
        Some(match event {
            WindowEvent::ModifiersChanged(m) => InputEvent::Modifiers(m.state()),
            WindowEvent::Focused(false) => InputEvent::FocusLost,
            WindowEvent::CursorLeft { .. } => InputEvent::CursorLeft,
            WindowEvent::CursorMoved { position, .. } => InputEvent::CursorMoved { x: position.x, y: position.y },
            WindowEvent::MouseInput { state, button, .. } => {
                InputEvent::Button { button: *button, pressed: *state == ElementState::Pressed }
            }
            WindowEvent::MouseWheel { delta, .. } => InputEvent::Wheel {
                steps: match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(*y),
                    MouseScrollDelta::PixelDelta(p) => p.y / PIXELS_PER_LINE,
                },
            },
            WindowEvent::KeyboardInput { event, is_synthetic, .. } => {
                let winit::keyboard::PhysicalKey::Code(code) = event.physical_key else { return None };
                InputEvent::Key(KeyInput { code, state: event.state, repeat: event.repeat, synthetic: *is_synthetic })
            }
            _ => return None,
        })
    }
}

#[derive(Debug, Default)]
pub struct Input {
    cursor: Option<(f64, f64)>,
    left: bool,
    middle: bool,
    /// Where the right button went down, and whether it has moved since.
    right: Option<((f64, f64), bool)>,
    keys: HashSet<KeyCode>,
    modifiers: ModifiersState,
}

impl Input {
    /// The pointer in physical window pixels, if it is in the window.
    pub fn cursor(&self) -> Option<(f64, f64)> {
        self.cursor
    }

    /// The pointer and the modifiers, as the session reads them: Ctrl held
    /// (a left drag from a face extrudes it), Shift (a click with Paint
    /// fills), Alt (a click picks a colour).
    pub fn pointer(&self) -> Pointer {
        Pointer {
            cursor: self.cursor,
            ctrl: self.modifiers.control_key(),
            shift: self.modifiers.shift_key(),
            alt: self.modifiers.alt_key(),
        }
    }

    /// Fly direction (right, up, forward) while the right button is held.
    pub fn fly_direction(&self) -> Option<DVec3> {
        self.right?;
        let axis = |plus: KeyCode, minus: KeyCode| {
            f64::from(u8::from(self.keys.contains(&plus))) - f64::from(u8::from(self.keys.contains(&minus)))
        };
        let dir = DVec3::new(
            axis(KeyCode::KeyD, KeyCode::KeyA),
            axis(KeyCode::KeyE, KeyCode::KeyQ),
            axis(KeyCode::KeyW, KeyCode::KeyS),
        );
        (dir != DVec3::ZERO).then_some(dir)
    }

    /// Handles one event. `consumed` is egui's verdict: a consumed press
    /// starts nothing, but releases and motion are always tracked so that no
    /// button stays stuck. `extruding`: a Ctrl+drag extrude is under way
    /// (the window's gesture), so motion and the release go to it.
    pub fn on_event(&mut self, event: &InputEvent, consumed: bool, tool: Tool, extruding: bool) -> Vec<AppCommand> {
        let mut out = Vec::new();
        match event {
            InputEvent::Modifiers(m) => self.modifiers = *m,
            InputEvent::FocusLost => {
                self.keys.clear();
                if self.left {
                    self.left = false;
                    if let Some((x, y)) = self.cursor {
                        out.push(AppCommand::PointerEdit { phase: StrokePhase::End, tool, x, y });
                    }
                }
                self.middle = false;
                self.right = None;
            }
            InputEvent::CursorLeft => self.cursor = None,
            &InputEvent::CursorMoved { x, y } => {
                if let Some((px, py)) = self.cursor {
                    let (dx, dy) = (x - px, y - py);
                    if let Some((start, moved)) = &mut self.right {
                        if !*moved && ((x - start.0).powi(2) + (y - start.1).powi(2)).sqrt() > CLICK_SLOP_PIXELS {
                            *moved = true;
                            // Catch up with the motion made inside the slop.
                            out.push(AppCommand::Orbit { dx: x - start.0, dy: y - start.1 });
                        } else if *moved {
                            out.push(AppCommand::Orbit { dx, dy });
                        }
                    } else if self.middle {
                        out.push(AppCommand::Pan { dx, dy });
                    }
                }
                self.cursor = Some((x, y));
                if self.left {
                    out.push(AppCommand::PointerEdit { phase: StrokePhase::Move, tool, x, y });
                }
                if extruding {
                    out.push(AppCommand::ExtrudeDrag { phase: StrokePhase::Move, x, y });
                }
            }
            &InputEvent::Button { button, pressed } => {
                let at = self.cursor;
                match (button, pressed) {
                    // Shift+click with Paint: flood fill.
                    (MouseButton::Left, true) if !consumed && self.modifiers.shift_key() && tool == Tool::Paint => {
                        if let Some((x, y)) = at {
                            out.push(AppCommand::FillAt { x, y });
                        }
                    }
                    // Ctrl+drag from a face: extrude.
                    (MouseButton::Left, true) if !consumed && self.modifiers.control_key() => {
                        if let Some((x, y)) = at {
                            out.push(AppCommand::ExtrudeDrag { phase: StrokePhase::Begin, x, y });
                        }
                    }
                    (MouseButton::Left, false) if extruding => {
                        let (x, y) = at.unwrap_or_default();
                        out.push(AppCommand::ExtrudeDrag { phase: StrokePhase::End, x, y });
                    }
                    // Alt+click: the eyedropper.
                    (MouseButton::Left, true) if !consumed && self.modifiers.alt_key() => {
                        if let Some((x, y)) = at {
                            out.push(AppCommand::PickColor { x, y });
                        }
                    }
                    (MouseButton::Left, true) if !consumed && !self.left => {
                        if let Some((x, y)) = at {
                            self.left = true;
                            out.push(AppCommand::PointerEdit { phase: StrokePhase::Begin, tool, x, y });
                        }
                    }
                    (MouseButton::Left, false) if self.left => {
                        self.left = false;
                        let (x, y) = at.unwrap_or_default();
                        out.push(AppCommand::PointerEdit { phase: StrokePhase::End, tool, x, y });
                    }
                    (MouseButton::Right, true) if !consumed => {
                        if let Some(p) = at {
                            self.right = Some((p, false));
                        }
                    }
                    (MouseButton::Right, false) => {
                        // A right click without drag erases while Attach is active.
                        if let (Some((_, false)), Some((x, y)), Tool::Attach) = (self.right, at, tool) {
                            out.push(AppCommand::PointerEdit { phase: StrokePhase::Click, tool: Tool::Erase, x, y });
                        }
                        self.right = None;
                    }
                    (MouseButton::Middle, true) if !consumed => self.middle = true,
                    (MouseButton::Middle, false) => self.middle = false,
                    _ => {}
                }
            }
            &InputEvent::Wheel { steps } if !consumed => out.push(AppCommand::Zoom { steps, at: self.cursor }),
            InputEvent::Wheel { .. } => {}
            &InputEvent::Key(key) => {
                log::debug!("key {key:?} consumed={consumed} modifiers={:?}", self.modifiers);
                out.extend(self.on_key(key, consumed));
            }
        }
        out
    }

    /// A key went down or up. A synthetic press (winit sends one for every
    /// key held when the window gains focus) counts as held but fires no
    /// shortcut: the real press, when the key was pressed just as the focus
    /// came, follows it, and a toggle would fire twice.
    fn on_key(&mut self, key: KeyInput, consumed: bool) -> Option<AppCommand> {
        if key.state == ElementState::Released {
            self.keys.remove(&key.code);
            return None;
        }
        if consumed {
            return None;
        }
        self.keys.insert(key.code);
        if key.synthetic {
            return None;
        }
        self.shortcut(key.code, key.repeat)
    }

    /// Keyboard shortcuts (physical keys, so they work on any layout), from
    /// the one table of actions.
    fn shortcut(&self, code: KeyCode, repeat: bool) -> Option<AppCommand> {
        let action = super::actions::for_key(code, self.modifiers.control_key(), self.modifiers.shift_key(), repeat)?;
        // While the right button is held, WASDQE fly, and F is not "frame".
        if action.command == AppCommand::FrameModel && self.right.is_some() {
            return None;
        }
        Some(action.command.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(code: KeyCode, synthetic: bool) -> KeyInput {
        KeyInput { code, state: ElementState::Pressed, repeat: false, synthetic }
    }

    #[test]
    fn a_key_held_as_the_focus_comes_toggles_once() {
        let mut input = Input::default();
        // The focus arrives while B is down: winit's synthetic press, then the real one.
        assert_eq!(input.on_key(press(KeyCode::KeyB, true), false), None);
        assert_eq!(input.on_key(press(KeyCode::KeyB, false), false), Some(AppCommand::ToggleSelect));
        let release = KeyInput { state: ElementState::Released, ..press(KeyCode::KeyB, false) };
        assert_eq!(input.on_key(release, false), None);
    }

    #[test]
    fn a_synthetic_press_still_counts_as_held() {
        let mut input = Input { right: Some(((0.0, 0.0), true)), ..Input::default() };
        assert_eq!(input.on_key(press(KeyCode::KeyW, true), false), None);
        assert_eq!(input.fly_direction(), Some(DVec3::Z));
    }

    #[test]
    fn a_press_egui_consumed_fires_nothing() {
        let mut input = Input::default();
        assert_eq!(input.on_key(press(KeyCode::KeyB, false), true), None);
    }
}
