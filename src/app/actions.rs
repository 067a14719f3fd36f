//! The one table of keyboard actions: each command with its shortcut, its
//! label and its menu. The key handler, the menu bar and the key table in
//! `docs/window.md` (checked by a test) all read it.

use glam::IVec3;
use winit::keyboard::KeyCode;

use super::command::{AppCommand, Nudge};
use super::state::Tool;
use octovox::script::ObjectLine;

/// One action: what it does, the key that does it and where its menu is.
pub struct Action {
    pub label: &'static str,
    pub key: KeyCode,
    pub ctrl: bool,
    pub shift: bool,
    /// The menu that lists it (`None`: keyboard only, or a second key of
    /// an action a menu already lists).
    pub menu: Option<&'static str>,
    pub command: AppCommand,
}

const fn key(label: &'static str, key: KeyCode, menu: Option<&'static str>, command: AppCommand) -> Action {
    Action { label, key, ctrl: false, shift: false, menu, command }
}

const fn ctrl(label: &'static str, key: KeyCode, menu: Option<&'static str>, command: AppCommand) -> Action {
    Action { label, key, ctrl: true, shift: false, menu, command }
}

const fn ctrl_shift(label: &'static str, key: KeyCode, menu: Option<&'static str>, command: AppCommand) -> Action {
    Action { label, key, ctrl: true, shift: true, menu, command }
}

const fn turn(label: &'static str, code: KeyCode, axis: usize, flip: bool) -> Action {
    Action { label, key: code, ctrl: false, shift: flip, menu: EDIT, command: AppCommand::Turn { axis, flip } }
}

const fn nudge(label: &'static str, code: KeyCode, direction: Nudge) -> Action {
    key(label, code, None, AppCommand::Nudge(direction))
}

const FILE: Option<&str> = Some("File");
const EDIT: Option<&str> = Some("Edit");
const TOOLS: Option<&str> = Some("Tools");
const VIEW: Option<&str> = Some("View");
const OBJECT: Option<&str> = Some("Object");
const ANIMATION: Option<&str> = Some("Animation");

const fn object(label: &'static str, code: KeyCode, line: ObjectLine) -> Action {
    Action { label, key: code, ctrl: true, shift: false, menu: OBJECT, command: AppCommand::Object(line) }
}

/// Every keyboard action, in menu order.
pub static ACTIONS: [Action; 55] = [
    ctrl("New", KeyCode::KeyN, FILE, AppCommand::New),
    ctrl("Open…", KeyCode::KeyO, FILE, AppCommand::AskOpen),
    ctrl("Save", KeyCode::KeyS, FILE, AppCommand::Save),
    ctrl_shift("Save As…", KeyCode::KeyS, FILE, AppCommand::AskSaveAs),
    ctrl("Export mesh…", KeyCode::KeyE, FILE, AppCommand::AskExport),
    ctrl_shift("Play script…", KeyCode::KeyP, FILE, AppCommand::AskPlayScript),
    key("Screenshot", KeyCode::F12, FILE, AppCommand::Screenshot),
    ctrl("Quit", KeyCode::KeyQ, FILE, AppCommand::Quit),
    ctrl("Undo", KeyCode::KeyZ, EDIT, AppCommand::Undo),
    ctrl_shift("Redo", KeyCode::KeyZ, EDIT, AppCommand::Redo),
    ctrl("Redo", KeyCode::KeyY, None, AppCommand::Redo),
    ctrl("Copy selection", KeyCode::KeyC, EDIT, AppCommand::Copy),
    ctrl("Cut selection", KeyCode::KeyX, EDIT, AppCommand::Cut),
    ctrl("Paste on the face under the cursor", KeyCode::KeyV, EDIT, AppCommand::PasteAtCursor),
    key("Delete selection", KeyCode::Delete, EDIT, AppCommand::DeleteSelection),
    key("Select none", KeyCode::Escape, EDIT, AppCommand::SelectNone),
    turn("Turn selection about x", KeyCode::KeyX, 0, false),
    turn("Turn selection about y", KeyCode::KeyY, 1, false),
    turn("Turn selection about z", KeyCode::KeyZ, 2, false),
    turn("Flip selection along x", KeyCode::KeyX, 0, true),
    turn("Flip selection along y", KeyCode::KeyY, 1, true),
    turn("Flip selection along z", KeyCode::KeyZ, 2, true),
    key("Attach tool", KeyCode::KeyT, TOOLS, AppCommand::SetTool(Tool::Attach)),
    key("Erase tool", KeyCode::KeyR, TOOLS, AppCommand::SetTool(Tool::Erase)),
    key("Paint tool", KeyCode::KeyG, TOOLS, AppCommand::SetTool(Tool::Paint)),
    key("Line mode", KeyCode::KeyL, TOOLS, AppCommand::ToggleLine),
    key("Box select mode", KeyCode::KeyB, TOOLS, AppCommand::ToggleSelect),
    key("Object mode", KeyCode::Tab, OBJECT, AppCommand::ToggleObject),
    object("Duplicate object", KeyCode::KeyD, ObjectLine::Duplicate { reference: false }),
    Action {
        label: "Duplicate object as a reference",
        key: KeyCode::KeyD,
        ctrl: false,
        shift: true,
        menu: OBJECT,
        command: AppCommand::Object(ObjectLine::Duplicate { reference: true }),
    },
    object("Make object unique", KeyCode::KeyU, ObjectLine::Unique),
    object("Turn object about y", KeyCode::KeyR, ObjectLine::Rotate(1)),
    object("Hide object", KeyCode::KeyH, ObjectLine::Hide(true)),
    object("Delete object", KeyCode::Delete, ObjectLine::Delete),
    key("Play or pause", KeyCode::Space, ANIMATION, AppCommand::TogglePlay),
    key("Frame before", KeyCode::Comma, ANIMATION, AppCommand::StepFrame(-1)),
    key("Frame after", KeyCode::Period, ANIMATION, AppCommand::StepFrame(1)),
    key("Key object at this frame", KeyCode::KeyK, ANIMATION, AppCommand::Key(true)),
    Action {
        label: "Take the object's key out",
        key: KeyCode::KeyK,
        ctrl: false,
        shift: true,
        menu: ANIMATION,
        command: AppCommand::Key(false),
    },
    key("Frame model", KeyCode::KeyF, VIEW, AppCommand::FrameModel),
    Action {
        label: "Frame selection",
        key: KeyCode::KeyF,
        ctrl: false,
        shift: true,
        menu: VIEW,
        command: AppCommand::FrameSelection,
    },
    key("Orthographic or perspective", KeyCode::KeyO, VIEW, AppCommand::ToggleProjection),
    key("Orthographic or perspective", KeyCode::Numpad5, None, AppCommand::ToggleProjection),
    key("Front view", KeyCode::Numpad1, VIEW, AppCommand::ViewFrom(IVec3::Z)),
    ctrl("Back view", KeyCode::Numpad1, VIEW, AppCommand::ViewFrom(IVec3::NEG_Z)),
    key("Right view", KeyCode::Numpad3, VIEW, AppCommand::ViewFrom(IVec3::X)),
    ctrl("Left view", KeyCode::Numpad3, VIEW, AppCommand::ViewFrom(IVec3::NEG_X)),
    key("Top view", KeyCode::Numpad7, VIEW, AppCommand::ViewFrom(IVec3::Y)),
    ctrl("Bottom view", KeyCode::Numpad7, VIEW, AppCommand::ViewFrom(IVec3::NEG_Y)),
    nudge("Move selection left", KeyCode::ArrowLeft, Nudge::Left),
    nudge("Move selection right", KeyCode::ArrowRight, Nudge::Right),
    nudge("Move selection away", KeyCode::ArrowUp, Nudge::Away),
    nudge("Move selection nearer", KeyCode::ArrowDown, Nudge::Near),
    nudge("Move selection up", KeyCode::PageUp, Nudge::Up),
    nudge("Move selection down", KeyCode::PageDown, Nudge::Down),
];

impl Action {
    /// Held down, the key repeats the action (nudging); others fire once.
    pub fn repeats(&self) -> bool {
        matches!(self.command, AppCommand::Nudge(_))
    }
}

/// The action a key press does, if any.
pub fn for_key(code: KeyCode, ctrl: bool, shift: bool, repeat: bool) -> Option<&'static Action> {
    ACTIONS.iter().find(|a| a.key == code && a.ctrl == ctrl && a.shift == shift && (a.repeats() || !repeat))
}

/// The menus, in order, with their actions.
pub fn menus() -> Vec<(&'static str, Vec<&'static Action>)> {
    let mut menus: Vec<(&'static str, Vec<&'static Action>)> = Vec::new();
    for action in &ACTIONS {
        let Some(menu) = action.menu else { continue };
        match menus.iter_mut().find(|(name, _)| *name == menu) {
            Some((_, actions)) => actions.push(action),
            None => menus.push((menu, vec![action])),
        }
    }
    menus
}

/// "Ctrl+Shift+S" and the like.
pub fn shortcut_text(action: &Action) -> String {
    let name = match action.key {
        KeyCode::Delete => "Delete".to_string(),
        KeyCode::Escape => "Escape".to_string(),
        KeyCode::ArrowLeft => "←".to_string(),
        KeyCode::ArrowRight => "→".to_string(),
        KeyCode::ArrowUp => "↑".to_string(),
        KeyCode::ArrowDown => "↓".to_string(),
        KeyCode::PageUp => "Page Up".to_string(),
        KeyCode::PageDown => "Page Down".to_string(),
        // KeyA … KeyZ, F1 … F12.
        code => format!("{code:?}").trim_start_matches("Key").to_string(),
    };
    let ctrl = if action.ctrl { "Ctrl+" } else { "" };
    let shift = if action.shift { "Shift+" } else { "" };
    format!("{ctrl}{shift}{name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key table of `docs/window.md`.
    fn markdown_table() -> String {
        let mut text = String::from("| key | action | menu |\n|---|---|---|\n");
        for action in &ACTIONS {
            let menu = action.menu.unwrap_or("");
            text.push_str(&format!("| {} | {} | {menu} |\n", shortcut_text(action), action.label));
        }
        text
    }

    #[test]
    fn no_two_actions_share_a_key() {
        for (i, a) in ACTIONS.iter().enumerate() {
            for b in &ACTIONS[i + 1..] {
                assert!((a.key, a.ctrl, a.shift) != (b.key, b.ctrl, b.shift), "{} and {}", a.label, b.label);
            }
        }
    }

    /// The docs' key table is this table; `OCTOVOX_UPDATE_DOCS=1` rewrites it.
    #[test]
    fn the_docs_list_every_action() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/window.md");
        let docs = std::fs::read_to_string(&path).unwrap();
        let (begin, end) = ("<!-- keys:begin -->\n", "<!-- keys:end -->");
        let start = docs.find(begin).expect("docs/window.md has no keys:begin marker") + begin.len();
        let stop = docs.find(end).expect("docs/window.md has no keys:end marker");
        let table = markdown_table();
        if std::env::var_os("OCTOVOX_UPDATE_DOCS").is_some() {
            std::fs::write(&path, format!("{}{table}{}", &docs[..start], &docs[stop..])).unwrap();
        } else {
            assert_eq!(
                docs[start..stop],
                table,
                "docs/window.md's key table is stale: OCTOVOX_UPDATE_DOCS=1 cargo test"
            );
        }
    }
}
