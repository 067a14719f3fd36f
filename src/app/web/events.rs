//! The page's input, as egui's web runner hands it over, turned into the
//! events the one input table reads (`input::InputEvent`): positions from
//! points to the canvas's physical pixels, keys and buttons by winit's names.

use winit::event::{ElementState, MouseButton};
use winit::keyboard::{KeyCode, ModifiersState};

use super::super::input::{InputEvent, KeyInput};

/// Pixels per wheel "line" for wheels that report points.
const POINTS_PER_LINE: f64 = 40.0;

/// The input events one egui event makes (none for what the input table
/// does not read: text, copy and paste, touches, zoom gestures).
pub fn translate(event: &egui::Event, pixels_per_point: f32) -> Vec<InputEvent> {
    let px = |p: egui::Pos2| InputEvent::CursorMoved {
        x: f64::from(p.x * pixels_per_point),
        y: f64::from(p.y * pixels_per_point),
    };
    match event {
        egui::Event::PointerMoved(at) => vec![px(*at)],
        egui::Event::PointerGone => vec![InputEvent::CursorLeft],
        egui::Event::WindowFocused(false) => vec![InputEvent::FocusLost],
        egui::Event::PointerButton { pos, button, pressed, modifiers } => {
            let Some(button) = mouse_button(*button) else { return Vec::new() };
            vec![
                InputEvent::Modifiers(modifiers_state(*modifiers)),
                px(*pos),
                InputEvent::Button { button, pressed: *pressed },
            ]
        }
        egui::Event::MouseWheel { unit, delta, modifiers, .. } => {
            let steps = match unit {
                egui::MouseWheelUnit::Line | egui::MouseWheelUnit::Page => f64::from(delta.y),
                egui::MouseWheelUnit::Point => f64::from(delta.y) / POINTS_PER_LINE,
            };
            vec![InputEvent::Modifiers(modifiers_state(*modifiers)), InputEvent::Wheel { steps }]
        }
        egui::Event::Key { key, physical_key, pressed, repeat, modifiers } => {
            let Some(code) = key_code(physical_key.unwrap_or(*key)) else {
                return vec![InputEvent::Modifiers(modifiers_state(*modifiers))];
            };
            let state = if *pressed { ElementState::Pressed } else { ElementState::Released };
            vec![
                InputEvent::Modifiers(modifiers_state(*modifiers)),
                InputEvent::Key(KeyInput { code, state, repeat: *repeat, synthetic: false }),
            ]
        }
        _ => Vec::new(),
    }
}

fn mouse_button(button: egui::PointerButton) -> Option<MouseButton> {
    Some(match button {
        egui::PointerButton::Primary => MouseButton::Left,
        egui::PointerButton::Secondary => MouseButton::Right,
        egui::PointerButton::Middle => MouseButton::Middle,
        egui::PointerButton::Extra1 | egui::PointerButton::Extra2 => return None,
    })
}

fn modifiers_state(m: egui::Modifiers) -> ModifiersState {
    let mut state = ModifiersState::empty();
    state.set(ModifiersState::CONTROL, m.ctrl);
    state.set(ModifiersState::SHIFT, m.shift);
    state.set(ModifiersState::ALT, m.alt);
    state.set(ModifiersState::SUPER, m.mac_cmd);
    state
}

/// The physical key of an egui key: every key of the shortcut table
/// (`actions`). The browser does not tell the number row from the keypad
/// here, so the digits 1, 3, 5 and 7 are the keypad's view keys.
fn key_code(key: egui::Key) -> Option<KeyCode> {
    use egui::Key as K;
    let letters = [
        (K::A, KeyCode::KeyA),
        (K::B, KeyCode::KeyB),
        (K::C, KeyCode::KeyC),
        (K::D, KeyCode::KeyD),
        (K::E, KeyCode::KeyE),
        (K::F, KeyCode::KeyF),
        (K::G, KeyCode::KeyG),
        (K::H, KeyCode::KeyH),
        (K::I, KeyCode::KeyI),
        (K::J, KeyCode::KeyJ),
        (K::K, KeyCode::KeyK),
        (K::L, KeyCode::KeyL),
        (K::M, KeyCode::KeyM),
        (K::N, KeyCode::KeyN),
        (K::O, KeyCode::KeyO),
        (K::P, KeyCode::KeyP),
        (K::Q, KeyCode::KeyQ),
        (K::R, KeyCode::KeyR),
        (K::S, KeyCode::KeyS),
        (K::T, KeyCode::KeyT),
        (K::U, KeyCode::KeyU),
        (K::V, KeyCode::KeyV),
        (K::W, KeyCode::KeyW),
        (K::X, KeyCode::KeyX),
        (K::Y, KeyCode::KeyY),
        (K::Z, KeyCode::KeyZ),
    ];
    let others = [
        (K::ArrowDown, KeyCode::ArrowDown),
        (K::ArrowLeft, KeyCode::ArrowLeft),
        (K::ArrowRight, KeyCode::ArrowRight),
        (K::ArrowUp, KeyCode::ArrowUp),
        (K::Comma, KeyCode::Comma),
        (K::Period, KeyCode::Period),
        (K::Delete, KeyCode::Delete),
        (K::Escape, KeyCode::Escape),
        (K::Space, KeyCode::Space),
        (K::Tab, KeyCode::Tab),
        (K::PageDown, KeyCode::PageDown),
        (K::PageUp, KeyCode::PageUp),
        (K::F12, KeyCode::F12),
        (K::Num1, KeyCode::Numpad1),
        (K::Num3, KeyCode::Numpad3),
        (K::Num5, KeyCode::Numpad5),
        (K::Num7, KeyCode::Numpad7),
    ];
    letters.into_iter().chain(others).find(|(k, _)| *k == key).map(|(_, code)| code)
}
