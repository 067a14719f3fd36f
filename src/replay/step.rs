//! The one interpreter of script lines. [`step`] gives every line to the
//! [`Editor`] first; what the editor leaves (files, the camera, pixels) is
//! the host's, through the [`Host`] trait, which `octovox replay` (the
//! headless [`super::Runner`]) and the window both implement. So a line
//! means one thing wherever it runs, and this is the only place the host
//! lines are matched. An editor line comes back as [`StepResult::Ran`]
//! for the host to follow up (the pool flush, the recording, the journal)
//! once `step` has returned: the engine never calls back into a host for
//! an edit.

use std::path::Path;

use glam::DVec3;

use crate::edit::selection::Region;
use crate::editor::{Editor, EditorError, Outcome};
use crate::io::png::{differing_fraction, load_png, save_png};
use crate::script::{Line, PaletteLine, click_command};
use crate::trace::pick;

/// The size of renders (and of the pixels `click` names headless) before a
/// `viewport` line.
pub const DEFAULT_VIEWPORT: (u32, u32) = (640, 480);

/// What a host does around the editor: files, the camera, the viewport
/// and pixels.
pub trait Host {
    fn editor(&mut self) -> &mut Editor;

    /// `load PATH`: the file's scene goes into the editor (the window reads
    /// it in the background; the next line waits for it).
    ///
    /// # Errors
    /// The file cannot be read.
    fn load(&mut self, path: &Path) -> Result<(), HostError>;

    /// `camera`: `None` keeps the field of view; the projection stays.
    fn set_camera(&mut self, eye: DVec3, target: DVec3, fov_y_deg: Option<f32>);

    /// `ortho HEIGHT` (`Some`) or `perspective`.
    fn set_projection(&mut self, ortho: Option<f32>);

    /// `viewport W H`: the size of renders and of the pixels `click` names.
    fn set_viewport(&mut self, width: u32, height: u32);

    /// The world voxel, face normal and value under a pixel (what the mouse
    /// picks); value 0: the ground (`Editor::ground`), no voxel.
    ///
    /// # Errors
    /// The traversal gave up.
    fn pick(&mut self, x: u32, y: u32) -> Result<Option<pick::Picked>, pick::GaveUp>;

    /// `save PATH`.
    ///
    /// # Errors
    /// The file cannot be written (or may not be).
    fn save(&mut self, path: &Path) -> Result<(), HostError>;

    /// `render PATH`: the view at the viewport's size with the default
    /// render settings, as `octovox replay` makes it; kept for `expect image`.
    ///
    /// # Errors
    /// The render failed or the file cannot be written.
    fn render(&mut self, path: &Path) -> Result<(), HostError>;

    /// `palette save PATH`: the palette, under the rule every command that
    /// writes follows (`crate::io::output`).
    ///
    /// # Errors
    /// The file may not or cannot be written.
    fn save_palette(&mut self, path: &Path) -> Result<(), HostError>;

    /// The image of the last `render`.
    fn last_render(&self) -> Option<&image::RgbaImage>;

    /// Bytes the pool flush after the last edit line wrote; `None` before
    /// any edit of this scene.
    fn last_written(&self) -> Option<u64>;

    /// Write missing or different reference images instead of failing.
    fn update_images(&self) -> bool {
        false
    }
}

/// What one line did.
#[derive(Debug, PartialEq)]
pub enum StepResult {
    /// An editor line changed the tool state, the voxels or the scene: the
    /// host follows it up.
    Ran(Ran),
    /// A host line was carried out.
    Done,
    Passed,
    Failed {
        expected: String,
        got: String,
    },
}

/// An editor line that ran: the line (a `click` gives the edit it became),
/// what it changed, and the selection from before it (a journal that the
/// line starts begins with that).
#[derive(Debug, PartialEq)]
pub struct Ran {
    pub line: Line,
    pub outcome: Outcome,
    pub selection: Option<Region>,
    /// The `object N` line a click ran first, when the voxel it hit is
    /// another object's (a recording or journal writes it before `line`).
    pub picked: Option<Line>,
}

/// A line that could not run: the script stops there.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    #[error(transparent)]
    Editor(#[from] EditorError),
    #[error(transparent)]
    Host(#[from] HostError),
    #[error("'{0}' needs {1} line before it")]
    NeedsEarlier(&'static str, &'static str),
    #[error("'{0}' is not a line octovox replay runs")]
    NotAHostLine(String),
}

/// A host's failure: files and the GPU.
#[derive(Debug, thiserror::Error)]
pub enum HostError {
    #[error(transparent)]
    Load(#[from] crate::io::LoadError),
    #[error(transparent)]
    Save(#[from] crate::io::SaveError),
    #[error(transparent)]
    Output(#[from] crate::io::output::OutputError),
    #[error(transparent)]
    Png(#[from] crate::io::png::PngError),
    #[error(transparent)]
    Palette(#[from] crate::io::palette_file::PaletteFileError),
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    #[error("{reference} ({hint})")]
    Reference { reference: crate::io::png::PngError, hint: &'static str },
    /// The window's device is not there yet.
    #[error("no GPU device yet")]
    NoGpuYet,
    /// The window could not save (it says why on its message line).
    #[error("could not save {0}")]
    NotSaved(std::path::PathBuf),
}

/// Carries out one line for `host`; relative paths are taken from `base`
/// (the script's folder).
///
/// # Errors
/// A line that could not run; a refused edit changes nothing.
pub fn step(host: &mut impl Host, base: &Path, line: &Line) -> Result<StepResult, StepError> {
    let selection = host.editor().selection;
    let outcome = host.editor().run(line)?;
    match outcome {
        Outcome::Checked { ok, expected, got } => Ok(check(ok, expected, || got)),
        Outcome::Host => host_line(host, base, line),
        outcome => Ok(StepResult::Ran(Ran { line: line.clone(), outcome, selection, picked: None })),
    }
}

/// The lines that are the host's own: files, the camera and pixels.
fn host_line(host: &mut impl Host, base: &Path, line: &Line) -> Result<StepResult, StepError> {
    match line {
        Line::Load(path) => host.load(&base.join(path))?,
        Line::Camera { eye, target, fov } => host.set_camera(*eye, *target, *fov),
        Line::Viewport(w, h) => host.set_viewport(*w, *h),
        Line::Projection(ortho) => host.set_projection(*ortho),
        Line::Click { x, y, tool } => {
            let expected = format!("pixel ({x}, {y}) to hit a voxel");
            let hit = match host.pick(*x, *y) {
                Ok(Some(hit)) if hit.value != 0 || *tool == crate::edit::brush::Tool::Attach => hit,
                Ok(Some(_)) => return Ok(StepResult::Failed { expected, got: "the ground (attach only)".into() }),
                Ok(None) => return Ok(StepResult::Failed { expected, got: "no voxel under it".into() }),
                Err(gave_up) => return Ok(StepResult::Failed { expected, got: gave_up.to_string() }),
            };
            // The object it hits is picked; then the place, remove or paint
            // of the cell it picks, as the mouse does.
            let picked = host.editor().object_line_for(&hit);
            if let Some(line) = &picked {
                host.editor().run(line)?;
            }
            return Ok(match step(host, base, &click_command(*tool, &hit))? {
                StepResult::Ran(ran) => StepResult::Ran(Ran { picked, ..ran }),
                other => other,
            });
        }
        // The file's colours become the `palette set` line a recording or
        // journal keeps (it needs no file at recovery).
        Line::Palette(PaletteLine::Load(path)) => {
            let mut colors = crate::io::palette_file::read_colors(&base.join(path)).map_err(HostError::from)?;
            colors.truncate(255);
            return step(host, base, &Line::Palette(PaletteLine::Set { first: 1, colors }));
        }
        Line::Palette(PaletteLine::Save(path)) => {
            // An unknown format is named as a palette's, before the rule of outputs.
            crate::io::palette_file::PaletteFormat::of(path).map_err(HostError::from)?;
            host.save_palette(&base.join(path))?;
        }
        Line::Save(path) => host.save(&base.join(path))?,
        Line::Render(path) => host.render(&base.join(path))?,
        Line::ExpectWritten(limit) => {
            let got = host.last_written().ok_or(StepError::NeedsEarlier("expect written", "an edit"))?;
            return Ok(check(got <= *limit, format!("at most {limit} bytes written"), || format!("{got} bytes")));
        }
        Line::ExpectImage(path, tolerance) => return expect_image(host, &base.join(path), *tolerance),
        // `Editor::run` answers every other line.
        _ => return Err(StepError::NotAHostLine(line.to_string())),
    }
    Ok(StepResult::Done)
}

fn expect_image(host: &mut impl Host, path: &Path, tolerance: f64) -> Result<StepResult, StepError> {
    let image = host.last_render().ok_or(StepError::NeedsEarlier("expect image", "a render"))?;
    if host.update_images() {
        save_png(image, path, crate::io::atomic::WriteOptions::default()).map_err(HostError::from)?;
        return Ok(StepResult::Passed);
    }
    let reference = load_png(path)
        .map_err(|reference| HostError::Reference { reference, hint: "OCTOVOX_UPDATE_IMAGES=1 writes it" })?;
    let fraction = differing_fraction(image, &reference);
    Ok(check(fraction <= tolerance, format!("at most {tolerance} of pixels differing from {}", path.display()), || {
        format!("{fraction:.5}")
    }))
}

fn check(ok: bool, expected: String, got: impl FnOnce() -> String) -> StepResult {
    if ok { StepResult::Passed } else { StepResult::Failed { expected, got: got() } }
}
