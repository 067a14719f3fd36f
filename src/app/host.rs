//! What the one script interpreter (`octovox::replay::step`) asks of the
//! session as its host: the editor, loading and saving files, the camera
//! and viewport, picks, renders, and the bytes the last edit wrote. The
//! session runs its lines and follows them up (`Session::run_line`).

use std::path::Path;

use glam::DVec3;

use octovox::camera::Camera;
use octovox::editor::Editor;
use octovox::io::atomic::WriteOptions;
use octovox::io::output::{OutputKind, check_output};
use octovox::replay::{Host, HostError};
use octovox::settings::RenderSettings;
use octovox::trace::pick;

use super::session::Session;

impl Session {
    /// The rule every command that writes follows: the kind's extension,
    /// never an input (the played script, the open document).
    fn check_write(&self, path: &Path, kind: OutputKind) -> Result<(), HostError> {
        let inputs: Vec<&Path> = self.doc.player.iter().map(|p| p.path()).chain(self.state.path.as_deref()).collect();
        Ok(check_output(path, kind, &inputs, false)?)
    }

    /// `render PATH` in the window: the image `octovox replay` makes (the
    /// script's viewport, the default settings), by the session's renderer.
    fn render_for_script(&mut self, path: &Path) -> Result<image::RgbaImage, HostError> {
        self.check_write(path, OutputKind::Image)?;
        let renderer = self.renderer.as_mut().ok_or(HostError::NoGpuYet)?;
        let viewport = self.doc.player.as_ref().map_or(octovox::replay::DEFAULT_VIEWPORT, |p| p.viewport);
        let settings = RenderSettings { ground: self.doc.editor.ground_plane(), ..RenderSettings::default() };
        renderer.render(&self.doc.editor.scene, &self.state.camera, viewport, &settings, None)?;
        let image = renderer.read_image()?;
        octovox::io::png::save_png(&image, path, WriteOptions::default())?;
        report!("screenshot: {}", path.display());
        self.request_redraw();
        Ok(image)
    }
}

impl Host for Session {
    fn editor(&mut self) -> &mut Editor {
        &mut self.doc.editor
    }

    /// Read in the background, as File ▸ Open does; the player waits for it.
    fn load(&mut self, path: &Path) -> Result<(), HostError> {
        self.start_loading(path.to_path_buf());
        Ok(())
    }

    fn set_camera(&mut self, eye: DVec3, target: DVec3, fov_y_deg: Option<f32>) {
        let fov_y_deg = fov_y_deg.unwrap_or(self.state.camera.fov_y_deg);
        self.state.camera = Camera { eye, target, fov_y_deg, ..self.state.camera };
        self.request_redraw();
    }

    fn set_projection(&mut self, ortho: Option<f32>) {
        self.state.camera.ortho = ortho;
        self.request_redraw();
    }

    /// The size of the script's renders; clicks name pixels of the window.
    fn set_viewport(&mut self, width: u32, height: u32) {
        if let Some(player) = &mut self.doc.player {
            player.viewport = (width, height);
        }
    }

    fn pick(&mut self, x: u32, y: u32) -> Result<Option<pick::Picked>, pick::GaveUp> {
        self.pick_or_ground(f64::from(x) + 0.5, f64::from(y) + 0.5)
    }

    fn save(&mut self, path: &Path) -> Result<(), HostError> {
        if self.save_document(path, WriteOptions::default()) { Ok(()) } else { Err(HostError::NotSaved(path.into())) }
    }

    fn render(&mut self, path: &Path) -> Result<(), HostError> {
        let image = self.render_for_script(path)?;
        if let Some(player) = &mut self.doc.player {
            player.last_render = Some(image);
        }
        Ok(())
    }

    fn save_palette(&mut self, path: &Path) -> Result<(), HostError> {
        self.check_write(path, OutputKind::Palette)?;
        octovox::io::palette_file::save(&self.doc.editor.scene.palette, path)?;
        report!("palette saved: {}", path.display());
        Ok(())
    }

    fn last_render(&self) -> Option<&image::RgbaImage> {
        self.doc.player.as_ref()?.last_render.as_ref()
    }

    fn last_written(&self) -> Option<u64> {
        self.readouts.stats.last_edit_bytes
    }
}
