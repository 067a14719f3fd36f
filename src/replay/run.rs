//! Running scripts: the [`Editor`] carries out every line that edits or
//! reads the scene (the window drives the same one); the runner adds files,
//! the camera, pixels and the pool flush, to the GPU when there is one.

use std::path::{Path, PathBuf};

use glam::IVec3;

use super::{Command, Line, Script};
use crate::camera::Camera;
use crate::editor::{Editor, Outcome};
use crate::gpu::Renderer;
use crate::io::atomic::WriteOptions;
use crate::io::output::{OutputKind, check_output};
use crate::io::png::{differing_fraction, load_png, save_png};
use crate::settings::RenderSettings;
use crate::tool::click_target;
use crate::trace::render::render_scene_cpu;
use crate::trace::svo;

/// Where renders and pool flushes go.
pub enum RunnerMode {
    /// Headless GPU: flushes are real `write_buffer` calls, renders use WGSL.
    Gpu(Box<Renderer>),
    /// No GPU: flushes are counted only, renders use the CPU tracer.
    Cpu,
}

/// An expectation that did not hold, or a line that could not run.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub file: PathBuf,
    pub line: usize,
    pub expected: String,
    pub got: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: expected {}, got {}", self.file.display(), self.line, self.expected, self.got)
    }
}

/// Expectations passed and failures of one script.
#[derive(Clone, Debug, Default)]
pub struct ScriptReport {
    pub passed: usize,
    pub failures: Vec<Failure>,
}

/// The state a script drives: the editor, the camera and the viewport.
pub struct Runner {
    pub editor: Editor,
    pub camera: Camera,
    pub viewport: (u32, u32),
    pub settings: RenderSettings,
    /// Bytes the pool flush after the last edit line wrote.
    pub last_written: Option<u64>,
    last_render: Option<image::RgbaImage>,
    mode: RunnerMode,
    /// Write missing or different reference images instead of failing.
    pub update_images: bool,
    /// Let `save` and `render` replace inputs and existing documents.
    pub force: bool,
    /// Files this run read (scripts, loaded scenes): never written over.
    inputs: Vec<PathBuf>,
    /// Files this run wrote: a later line may write them again.
    written: Vec<PathBuf>,
}

/// What one line did, for callers that show progress.
#[derive(Debug, PartialEq)]
pub enum StepResult {
    Done,
    Passed,
    Failed { expected: String, got: String },
}

impl Runner {
    pub fn new(mode: RunnerMode) -> Runner {
        Runner {
            editor: Editor::default(),
            camera: Camera::default(),
            viewport: (640, 480),
            settings: RenderSettings::default(),
            last_written: None,
            last_render: None,
            mode,
            update_images: false,
            force: false,
            inputs: Vec::new(),
            written: Vec::new(),
        }
    }

    /// Gives back the renderer, to reuse it for the next script.
    pub fn into_mode(self) -> RunnerMode {
        self.mode
    }

    /// Runs every line; an error stops the script and counts as a failure.
    pub fn run(&mut self, script: &Script) -> ScriptReport {
        let base = script.path.parent().unwrap_or(Path::new(".")).to_path_buf();
        self.inputs.push(script.path.clone());
        let mut report = ScriptReport::default();
        for line in &script.lines {
            let fail =
                |expected: String, got: String| Failure { file: script.path.clone(), line: line.number, expected, got };
            match self.step(&base, line) {
                Ok(StepResult::Done) => {}
                Ok(StepResult::Passed) => report.passed += 1,
                Ok(StepResult::Failed { expected, got }) => report.failures.push(fail(expected, got)),
                Err(message) => {
                    report.failures.push(fail(format!("'{}' to run", line.command), format!("error: {message}")));
                    break;
                }
            }
        }
        report
    }

    /// Runs one line. `Err` is an error that stops the script.
    pub fn step(&mut self, base: &Path, line: &Line) -> Result<StepResult, String> {
        self.run_command(base, &line.command)
    }

    fn run_command(&mut self, base: &Path, command: &Command) -> Result<StepResult, String> {
        match self.editor.run(command)? {
            Outcome::State => {}
            Outcome::Changed => self.last_written = Some(self.flush()),
            Outcome::Replaced => self.scene_replaced(),
            Outcome::Checked { ok, expected, got } => return Ok(check(ok, expected, || got)),
            Outcome::Host => return self.host_step(base, command),
        }
        Ok(StepResult::Done)
    }

    /// The lines that are the runner's own: files, the camera and pixels.
    fn host_step(&mut self, base: &Path, command: &Command) -> Result<StepResult, String> {
        let resolve = |p: &Path| base.join(p);
        let scene = &self.editor.scene;
        match command {
            Command::Load(path) => {
                let path = resolve(path);
                self.editor.set_scene(crate::io::load_scene(&path, 0).map_err(|e| e.to_string())?);
                self.scene_replaced();
                self.inputs.push(path);
            }
            Command::Camera { eye, target, fov } => {
                self.camera = Camera { eye: *eye, target: *target, fov_y_deg: fov.unwrap_or(self.camera.fov_y_deg) };
            }
            Command::Viewport(w, h) => self.viewport = (*w, *h),
            Command::Click { x, y, tool } => {
                let expected = format!("pixel ({x}, {y}) to hit a voxel");
                let (voxel, normal) = match self.pick(*x, *y) {
                    Ok(Some(hit)) => hit,
                    Ok(None) => return Ok(StepResult::Failed { expected, got: "no voxel under it".into() }),
                    Err(gave_up) => return Ok(StepResult::Failed { expected, got: gave_up.to_string() }),
                };
                // The place, remove or paint of the cell it picks, as in the window.
                let center = click_target(*tool, voxel, normal);
                return self.run_command(base, &super::edit_command(*tool, center));
            }
            Command::Save(path) => {
                let path = resolve(path);
                self.check_output(&path, OutputKind::Scene)?;
                let options = WriteOptions::forced(self.force);
                crate::io::save_scene(&path, scene, options).map_err(|e| e.to_string())?;
                self.written.push(path);
            }
            Command::Render(path) => {
                let path = resolve(path);
                self.check_output(&path, OutputKind::Image)?;
                let image = self.render()?;
                save_png(&image, &path, WriteOptions::forced(self.force)).map_err(|e| e.to_string())?;
                self.written.push(path);
                self.last_render = Some(image);
            }
            Command::ExpectWritten(limit) => {
                let got = self.last_written.ok_or("'expect written' needs an edit line before it")?;
                return Ok(check(got <= *limit, format!("at most {limit} bytes written"), || format!("{got} bytes")));
            }
            Command::ExpectImage(path, tolerance) => return self.expect_image(&resolve(path), *tolerance),
            Command::ExpectEffects(want) => {
                let (ok, got) = super::effects_match(scene, &crate::settings::PathSettings::default(), want);
                return Ok(check(ok, format!("effects [{}]", want.join(" ")), || format!("[{}]", got.join(" "))));
            }
            other => return Err(format!("'{other}' is not a line octovox replay runs")),
        }
        Ok(StepResult::Done)
    }

    /// The rule of every command that writes (`crate::io::output`); a file
    /// this run wrote itself may be written again.
    fn check_output(&self, path: &Path, kind: OutputKind) -> Result<(), String> {
        let ours = self.written.iter().any(|w| w == path);
        let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        check_output(path, kind, &inputs, self.force || ours).map_err(|e| e.to_string())
    }

    /// After a new scene: nothing was written by an edit yet; all of it goes up.
    fn scene_replaced(&mut self) {
        self.last_written = None;
        self.flush();
    }

    /// The world voxel and face normal under a pixel (what the mouse picks).
    pub fn pick(&self, x: u32, y: u32) -> Result<Option<(IVec3, IVec3)>, svo::GaveUp> {
        Ok(svo::pick(&self.editor.scene.tree, &self.camera, self.viewport, x, y)?.map(|hit| (hit.voxel, hit.normal)))
    }

    /// Sends the pool's dirty ranges; returns the bytes written.
    fn flush(&mut self) -> u64 {
        match &mut self.mode {
            RunnerMode::Gpu(renderer) => renderer.sync(&mut self.editor.scene.tree, &self.editor.scene.palette).bytes,
            RunnerMode::Cpu => self.editor.scene.tree.pool_mut().flush().byte_count(),
        }
    }

    fn render(&mut self) -> Result<image::RgbaImage, String> {
        match &mut self.mode {
            RunnerMode::Gpu(renderer) => {
                renderer
                    .render(&self.editor.scene.tree, &self.camera, self.viewport, &self.settings, None)
                    .map_err(|e| e.to_string())?;
                renderer.read_image().map_err(|e| e.to_string())
            }
            RunnerMode::Cpu => {
                Ok(render_scene_cpu(&self.editor.scene, None, &self.camera, self.viewport, &self.settings))
            }
        }
    }

    fn expect_image(&mut self, path: &Path, tolerance: f64) -> Result<StepResult, String> {
        let image = self.last_render.as_ref().ok_or("'expect image' needs a render line before it")?;
        if self.update_images {
            save_png(image, path, WriteOptions::default()).map_err(|e| e.to_string())?;
            return Ok(StepResult::Passed);
        }
        let reference = load_png(path).map_err(|e| format!("{e} (OCTOVOX_UPDATE_IMAGES=1 writes it)"))?;
        let fraction = differing_fraction(image, &reference);
        Ok(check(
            fraction <= tolerance,
            format!("at most {tolerance} of pixels differing from {}", path.display()),
            || format!("{fraction:.5}"),
        ))
    }
}

fn check(ok: bool, expected: String, got: impl FnOnce() -> String) -> StepResult {
    if ok { StepResult::Passed } else { StepResult::Failed { expected, got: got() } }
}
