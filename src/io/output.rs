//! Which outputs a command may write: never one of its inputs, never over an
//! existing document (.vox, .obj, .ovr, .ply, .glb, .mtl, or any palette
//! file) unless the user said `--force`, and only in the format the file's
//! extension names.

use std::path::{Path, PathBuf};

/// What a command writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// A rendered image: `.png`.
    Image,
    /// A rendered animation in one file: `.gif`.
    Animation,
    /// A scene: `.vox` or `.ovx`.
    Scene,
    /// A replay script (`--record`): any name, `.ovr` by convention.
    Script,
    /// An exported mesh: `.obj`, `.ply` or `.glb`.
    Mesh,
    /// The materials of an exported .obj: `.mtl`.
    Materials,
    /// A palette: `.png`, `.hex` or `.gpl`.
    Palette,
}

impl OutputKind {
    /// The extensions it may have; empty for any.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            OutputKind::Image => &["png"],
            OutputKind::Animation => &["gif"],
            OutputKind::Scene => &["vox", "ovx"],
            OutputKind::Script => &[],
            OutputKind::Mesh => &["obj", "ply", "glb"],
            OutputKind::Materials => &["mtl"],
            OutputKind::Palette => &["png", "hex", "gpl"],
        }
    }
}

/// Extensions of the files users make by hand or with other tools (meshes
/// and their materials included); an existing one is only replaced with
/// `--force`.
const DOCUMENT_EXTENSIONS: [&str; 7] = ["vox", "ovx", "obj", "ovr", "ply", "glb", "mtl"];

/// Why an output was refused.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum OutputError {
    #[error("{} is an input of this command; refusing to overwrite it (--force overwrites)", path.display())]
    IsInput { path: PathBuf },
    #[error("{} already exists; refusing to replace it (--force replaces it)", path.display())]
    Exists { path: PathBuf },
    #[error("{} {}, but this command writes {expected} files", path.display(), named(found))]
    WrongExtension { path: PathBuf, found: String, expected: String },
}

/// What an output's extension makes of it, for [`OutputError::WrongExtension`].
fn named(extension: &str) -> String {
    if extension.is_empty() {
        "has no file extension (a folder?)".to_string()
    } else {
        format!("names a .{extension} file")
    }
}

/// Checks that `output` may be written by a command that read `inputs`.
///
/// # Errors
/// [`OutputError::WrongExtension`] always; the others unless `force`.
pub fn check_output(output: &Path, kind: OutputKind, inputs: &[&Path], force: bool) -> Result<(), OutputError> {
    let extension = extension_of(output);
    let allowed = kind.extensions();
    if !allowed.is_empty() && !allowed.contains(&extension.as_str()) {
        let mut names: Vec<String> = allowed.iter().map(|e| format!(".{e}")).collect();
        let last = names.pop().unwrap_or_default();
        let expected = if names.is_empty() { last } else { format!("{} or {last}", names.join(", ")) };
        return Err(OutputError::WrongExtension { path: output.to_path_buf(), found: extension, expected });
    }
    if force {
        return Ok(());
    }
    if inputs.iter().any(|input| same_file(input, output)) {
        return Err(OutputError::IsInput { path: output.to_path_buf() });
    }
    // A palette file is a document whatever its extension: a `.png` render
    // may be replaced, a `.png` palette someone made may not.
    if output.exists() && (DOCUMENT_EXTENSIONS.contains(&extension.as_str()) || kind == OutputKind::Palette) {
        return Err(OutputError::Exists { path: output.to_path_buf() });
    }
    Ok(())
}

/// Lower-case extension, or "" when there is none.
fn extension_of(path: &Path) -> String {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default()
}

/// True when both paths name one existing file (through links and `..`).
#[cfg(not(target_arch = "wasm32"))]
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Whether `a` and `b` name the same file: in the browser the page's
/// files have one name each.
#[cfg(target_arch = "wasm32")]
pub fn same_file(a: &Path, b: &Path) -> bool {
    a == b && crate::io::input::is_file(a)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn inputs_and_documents_are_protected() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model.vox");
        std::fs::write(&model, b"VOX ").unwrap();
        let png = dir.path().join("a.png");
        std::fs::write(&png, b"png").unwrap();
        let err = check_output(&model, OutputKind::Scene, &[&model], false).unwrap_err();
        assert!(matches!(err, OutputError::IsInput { .. }), "{err}");
        let err = check_output(&model, OutputKind::Image, &[], false).unwrap_err();
        assert!(matches!(err, OutputError::WrongExtension { .. }), "{err}");
        assert!(matches!(check_output(&model, OutputKind::Scene, &[], false), Err(OutputError::Exists { .. })));
        assert_eq!(check_output(&model, OutputKind::Scene, &[&model], true), Ok(()));
        // An existing image is an ordinary output; a new .vox too.
        assert_eq!(check_output(&png, OutputKind::Image, &[&model], false), Ok(()));
        assert_eq!(check_output(&dir.path().join("new.vox"), OutputKind::Scene, &[&model], false), Ok(()));
        // The format comes from the extension, in any case.
        assert_eq!(check_output(&dir.path().join("X.PNG"), OutputKind::Image, &[], false), Ok(()));
        assert!(check_output(&dir.path().join("x.jpg"), OutputKind::Image, &[], true).is_err());
        // Issue 48, item 6: `palette save` replaced an existing palette
        // (the one the run loaded, too) without --force.
        for name in ["p.gpl", "p.hex", "p.png"] {
            let palette = dir.path().join(name);
            assert_eq!(check_output(&palette, OutputKind::Palette, &[], false), Ok(()));
            std::fs::write(&palette, b"x").unwrap();
            assert!(matches!(check_output(&palette, OutputKind::Palette, &[], false), Err(OutputError::Exists { .. })));
            assert_eq!(check_output(&palette, OutputKind::Palette, &[], true), Ok(()));
        }
        // A folder (or any name without an extension) is named as such.
        let err = check_output(dir.path(), OutputKind::Mesh, &[], false).unwrap_err();
        assert!(err.to_string().contains("has no file extension (a folder?), but this command writes"), "{err}");
    }
}
