//! The kinds of file the window asks for (open, save as, export, palettes):
//! their titles, the extensions they list and what a chosen path does. The
//! native dialog and the in-window browser both take one.

use std::path::PathBuf;

use super::command::AppCommand;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogKind {
    Open,
    SaveAs,
    Export,
    LoadPalette,
    SavePalette,
    PlayScript,
}

impl DialogKind {
    /// Whether it picks an existing file (rather than a name to write).
    pub fn opens(self) -> bool {
        matches!(self, DialogKind::Open | DialogKind::LoadPalette | DialogKind::PlayScript)
    }

    pub fn title(self) -> &'static str {
        match self {
            DialogKind::Open => "Open .vox, .ovx or .obj",
            DialogKind::SaveAs => "Save as .vox or .ovx",
            DialogKind::Export => "Export a mesh (.obj, .ply or .glb)",
            DialogKind::LoadPalette => "Load a palette (.png, .hex or .gpl)",
            DialogKind::SavePalette => "Save the palette as .png, .hex or .gpl",
            DialogKind::PlayScript => "Play a replay script (.ovr)",
        }
    }

    /// The extensions it lists.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            DialogKind::Open => &["vox", "ovx", "obj"],
            DialogKind::SaveAs => &["vox", "ovx"],
            DialogKind::Export => &["obj", "ply", "glb"],
            DialogKind::LoadPalette | DialogKind::SavePalette => &["png", "hex", "gpl"],
            DialogKind::PlayScript => &["ovr"],
        }
    }

    /// What the chosen path does.
    pub fn command(self, path: PathBuf) -> AppCommand {
        use octovox::script::{Line, PaletteLine};
        match self {
            DialogKind::Open => AppCommand::Open(path),
            DialogKind::SaveAs => AppCommand::SaveAs(path),
            DialogKind::Export => AppCommand::Export(path),
            DialogKind::LoadPalette => AppCommand::Lines(vec![Line::Palette(PaletteLine::Load(path))]),
            DialogKind::SavePalette => AppCommand::Lines(vec![Line::Palette(PaletteLine::Save(path))]),
            DialogKind::PlayScript => AppCommand::PlayScript(path),
        }
    }
}
