//! Screenshots (F12) and `--bench-frames`: the two things that read frames
//! back or time them. Kept out of the frame function so it stays readable.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use winit::event_loop::ActiveEventLoop;

use octovox::gpu::GpuContext;
use octovox::gpu::readback::{padded_row_bytes, read_buffer, staging_buffer};

use super::super::SAVES_DIR;
use super::{App, Gfx};

/// The window's image copied for a screenshot: buffer, width, height, and
/// whether its bytes are BGRA.
pub(super) type WindowCopy = (wgpu::Buffer, u32, u32, bool);

impl App {
    /// Writes the traced view (and, where the swapchain allows copies, the
    /// whole window with its panels) as PNGs under `saves/`.
    pub(super) fn save_screenshot(&mut self, window_copy: Option<WindowCopy>) {
        let Some(renderer) = &self.session.renderer else { return };
        let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_millis());
        if let Err(err) = std::fs::create_dir_all(SAVES_DIR) {
            log::warn!("cannot create {SAVES_DIR}: {err}");
        }
        let view_path = Path::new(SAVES_DIR).join(format!("octovox-{stamp}.png"));
        let base = view_path.with_extension("");
        let result = renderer.read_image().map_err(anyhow::Error::from).and_then(|image| {
            octovox::io::png::save_png(&image, &view_path, Default::default()).map_err(anyhow::Error::from)
        });
        match result {
            Ok(()) => report!("screenshot: {}", view_path.display()),
            Err(err) => {
                self.session.ui.error(format!("screenshot failed: {err:#}"));
                return;
            }
        }
        if let Some((buffer, width, height, bgra)) = window_copy {
            let window_path = PathBuf::from(format!("{}-window.png", base.display()));
            let result = read_buffer(&renderer.gpu, &buffer).map_err(anyhow::Error::from).and_then(|bytes| {
                let row = (width * 4) as usize;
                let mut pixels: Vec<u8> =
                    bytes.chunks(padded_row_bytes(width) as usize).flat_map(|r| &r[..row]).copied().collect();
                if bgra {
                    pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
                }
                pixels.chunks_exact_mut(4).for_each(|p| p[3] = 255);
                let image =
                    image::RgbaImage::from_raw(width, height, pixels).context("frame readback has the wrong size")?;
                octovox::io::png::save_png(&image, &window_path, Default::default()).map_err(anyhow::Error::from)
            });
            match result {
                Ok(()) => report!("screenshot: {}", window_path.display()),
                Err(err) => self.session.ui.error(format!("window screenshot failed: {err:#}")),
            }
        }
        self.session.ui.info(format!("screenshot saved to {}", view_path.display()));
    }

    pub(super) fn bench_step(&mut self, event_loop: &ActiveEventLoop) {
        if !self.frames.ready {
            return;
        }
        let Some(bench) = &mut self.frames.bench else { return };
        if let Some(line) = bench.frame(&self.session) {
            report!("{line}");
            self.frames.bench = None;
            event_loop.exit();
        }
    }
}

/// Copies the swapchain image into a mappable buffer (read after submit).
pub(super) fn copy_frame(
    gfx: &Gfx,
    gpu: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
) -> WindowCopy {
    let (width, height) = (texture.width(), texture.height());
    let padded = padded_row_bytes(width);
    let buffer = staging_buffer(&gpu.device, "window screenshot", u64::from(padded) * u64::from(height));
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    let bgra = matches!(gfx.config.format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
    (buffer, width, height, bgra)
}
