//! The kinds of file the window asks for (open, save as, export, palettes):
//! their titles, the extensions they list and what a chosen path does. The
//! native dialog and the in-window browser both take one.

use std::path::PathBuf;

use super::command::Command;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogKind {
    Open,
    SaveAs,
    Export,
    LoadPalette,
    SavePalette,
}

impl DialogKind {
    /// Whether it picks an existing file (rather than a name to write).
    pub fn opens(self) -> bool {
        matches!(self, DialogKind::Open | DialogKind::LoadPalette)
    }

    pub fn title(self) -> &'static str {
        match self {
            DialogKind::Open => "Open .vox, .ovx or .obj",
            DialogKind::SaveAs => "Save as .vox or .ovx",
            DialogKind::Export => "Export a mesh (.obj, .ply or .glb)",
            DialogKind::LoadPalette => "Load a palette (.png, .hex or .gpl)",
            DialogKind::SavePalette => "Save the palette as .png, .hex or .gpl",
        }
    }

    /// The extensions it lists.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            DialogKind::Open => &["vox", "ovx", "obj"],
            DialogKind::SaveAs => &["vox", "ovx"],
            DialogKind::Export => &["obj", "ply", "glb"],
            DialogKind::LoadPalette | DialogKind::SavePalette => &["png", "hex", "gpl"],
        }
    }

    /// What the chosen path does.
    pub fn command(self, path: PathBuf) -> Command {
        use octovox::script::{Command as Line, PaletteLine};
        match self {
            DialogKind::Open => Command::Open(path),
            DialogKind::SaveAs => Command::SaveAs(path),
            DialogKind::Export => Command::Export(path),
            DialogKind::LoadPalette => Command::Lines(vec![Line::Palette(PaletteLine::Load(path))]),
            DialogKind::SavePalette => Command::Lines(vec![Line::Palette(PaletteLine::Save(path))]),
        }
    }
}
