//! `octovox replay`'s host: the [`Runner`] runs scripts through
//! [`super::step`] with files, a camera, pixels and the pool flush (to the
//! GPU when there is one) of its own.

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::step::{Host, HostError, StepError, StepResult, step};
use crate::camera::Camera;
use crate::editor::{Editor, Outcome};
use crate::gpu::Renderer;
use crate::io::atomic::WriteOptions;
use crate::io::output::{OutputKind, check_output};
use crate::io::png::save_png;
use crate::script::{NumberedLine, Script};
use crate::settings::RenderSettings;
use crate::trace::pick;
use crate::trace::render::render_scene_cpu;

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

impl Runner {
    pub fn new(mode: RunnerMode) -> Runner {
        Runner {
            editor: Editor::default(),
            camera: Camera::default(),
            viewport: super::DEFAULT_VIEWPORT,
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
                Ok(StepResult::Done | StepResult::Ran(_)) => {}
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
    ///
    /// # Errors
    /// As [`step`].
    pub fn step(&mut self, base: &Path, line: &NumberedLine) -> Result<StepResult, StepError> {
        let result = step(self, base, &line.command)?;
        if let StepResult::Ran(ran) = &result {
            match ran.outcome {
                Outcome::Changed => self.last_written = Some(self.flush()),
                Outcome::Replaced => self.scene_replaced(),
                _ => {}
            }
        }
        Ok(result)
    }

    /// The rule of every command that writes (`crate::io::output`); a file
    /// this run wrote itself may be written again.
    fn check_output(&self, path: &Path, kind: OutputKind) -> Result<(), HostError> {
        let ours = self.written.iter().any(|w| w == path);
        let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        Ok(check_output(path, kind, &inputs, self.force || ours)?)
    }

    /// After a new scene: nothing was written by an edit yet; all of it goes up.
    fn scene_replaced(&mut self) {
        self.last_written = None;
        self.flush();
    }

    /// Sends the pool's dirty ranges; returns the bytes written.
    fn flush(&mut self) -> u64 {
        match &mut self.mode {
            RunnerMode::Gpu(renderer) => renderer.sync(&mut self.editor.scene).bytes,
            RunnerMode::Cpu => self.editor.scene.take_uploads().byte_count(),
        }
    }

    fn render_image(&mut self) -> Result<image::RgbaImage, HostError> {
        // The ground plane where the window draws one (`ground on`).
        let settings = RenderSettings { ground: self.editor.ground_plane(), ..self.settings };
        match &mut self.mode {
            RunnerMode::Gpu(renderer) => {
                renderer.render(&self.editor.scene, &self.camera, self.viewport, &settings, None)?;
                Ok(renderer.read_image()?)
            }
            RunnerMode::Cpu => Ok(render_scene_cpu(&self.editor.scene, None, &self.camera, self.viewport, &settings)),
        }
    }
}

impl Host for Runner {
    fn editor(&mut self) -> &mut Editor {
        &mut self.editor
    }

    fn load(&mut self, path: &Path) -> Result<(), HostError> {
        self.editor.set_scene(crate::io::load_scene(path, 0)?);
        self.scene_replaced();
        self.inputs.push(path.to_path_buf());
        Ok(())
    }

    fn set_camera(&mut self, eye: DVec3, target: DVec3, fov_y_deg: Option<f32>) {
        self.camera = Camera { eye, target, fov_y_deg: fov_y_deg.unwrap_or(self.camera.fov_y_deg), ..self.camera };
    }

    fn set_projection(&mut self, ortho: Option<f32>) {
        self.camera.ortho = ortho;
    }

    fn set_viewport(&mut self, width: u32, height: u32) {
        self.viewport = (width, height);
    }

    fn pick(&mut self, x: u32, y: u32) -> Result<Option<pick::Picked>, pick::GaveUp> {
        let (scene, ground) = (&self.editor.scene, self.editor.ground);
        pick::pick_with_ground(scene, &self.camera, self.viewport, (x, y), ground)
    }

    fn save(&mut self, path: &Path) -> Result<(), HostError> {
        self.check_output(path, OutputKind::Scene)?;
        crate::io::save_scene(path, &self.editor.scene, WriteOptions::forced(self.force))?;
        self.written.push(path.to_path_buf());
        Ok(())
    }

    fn render(&mut self, path: &Path) -> Result<(), HostError> {
        self.check_output(path, OutputKind::Image)?;
        let image = self.render_image()?;
        save_png(&image, path, WriteOptions::forced(self.force))?;
        self.written.push(path.to_path_buf());
        self.last_render = Some(image);
        Ok(())
    }

    fn save_palette(&mut self, path: &Path) -> Result<(), HostError> {
        self.check_output(path, OutputKind::Palette)?;
        crate::io::palette_file::save(&self.editor.scene.palette, path)?;
        self.written.push(path.to_path_buf());
        Ok(())
    }

    fn last_render(&self) -> Option<&image::RgbaImage> {
        self.last_render.as_ref()
    }

    fn last_written(&self) -> Option<u64> {
        self.last_written
    }

    fn update_images(&self) -> bool {
        self.update_images
    }
}
