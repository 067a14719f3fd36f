//! egui's output on the window, in two parts. The panels are drawn into a
//! layer of the window's size that is kept across frames and drawn again
//! only when what they show changes; the scene overlays (brush outline,
//! selection box, previews, hints), which move with the camera, are drawn
//! onto every frame, under the panels.
//!
//! Why: on lavapipe the panels' ~6,000 small triangles took 15–17 ms of
//! every frame at 1280×720, more than the trace of a moving camera, though
//! they rarely change while the camera moves. The kept layer is laid over
//! the frame only where the panels drew (a fullscreen draw blended over the
//! whole window took 5 ms there).

use std::hash::{Hash, Hasher};

use egui::epaint::{ClippedPrimitive, Primitive};
use octovox::gpu::blit_pass::color_pass;
use octovox::gpu::{BlitMode, BlitPass, GpuContext, GpuError};

pub struct EguiLayers {
    /// Draws the panels into `layer`.
    panels: egui_wgpu::Renderer,
    /// Draws the scene overlays onto the frame.
    overlays: egui_wgpu::Renderer,
    /// Lays `layer` over the frame.
    composite: BlitPass,
    format: wgpu::TextureFormat,
    layer: Option<Layer>,
    /// Textures freed once a frame that no longer uses them was submitted.
    to_free: Vec<egui::TextureId>,
}

/// The panels as last drawn.
struct Layer {
    view: wgpu::TextureView,
    size: [u32; 2],
    /// `fingerprint` of what it holds; `None`: must be drawn.
    drawn: Option<u64>,
    /// Where the panels drew: disjoint pixel rectangles (x, y, width, height).
    areas: Vec<[u32; 4]>,
}

impl EguiLayers {
    pub fn new(gpu: &GpuContext, format: wgpu::TextureFormat) -> Result<EguiLayers, GpuError> {
        let renderer = || egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        Ok(EguiLayers {
            panels: renderer(),
            overlays: renderer(),
            composite: BlitPass::new(gpu, format, BlitMode::Over)?,
            format,
            layer: None,
            to_free: Vec::new(),
        })
    }

    /// Uploads egui's new textures to both renderers, before the swapchain
    /// image is acquired (a skipped frame loses nothing); frees come after
    /// the next submitted frame (`free_textures`).
    pub fn set_textures(&mut self, gpu: &GpuContext, delta: &mut egui::TexturesDelta) {
        for (id, images) in delta.set.drain() {
            for image in &images {
                self.panels.update_texture(&gpu.device, &gpu.queue, id, image);
                self.overlays.update_texture(&gpu.device, &gpu.queue, id, image);
            }
            // A changed font atlas can change the panels' glyphs under the same vertices.
            if let Some(layer) = &mut self.layer {
                layer.drawn = None;
            }
        }
        self.to_free.extend(delta.free.drain());
    }

    pub fn free_textures(&mut self) {
        for id in self.to_free.drain(..) {
            self.panels.free_texture(&id);
            self.overlays.free_texture(&id);
        }
    }

    /// Records the overlays onto `target`, the panels into their layer when
    /// they changed, and the layer over `target`. Returns the command
    /// buffers egui's paint callbacks asked for (to submit first).
    pub fn encode(
        &mut self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        panels: &[ClippedPrimitive],
        overlays: &[ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> Vec<wgpu::CommandBuffer> {
        let mut buffers = self.overlays.update_buffers(&gpu.device, &gpu.queue, encoder, overlays, screen);
        if !overlays.is_empty() {
            let mut pass = color_pass(encoder, target, wgpu::LoadOp::Load, "egui scene overlays");
            self.overlays.render(&mut pass, overlays, screen);
        }
        let fingerprint = fingerprint(panels, screen);
        let mut layer = self.take_layer(&gpu.device, screen.size_in_pixels);
        if fingerprint.is_none() || layer.drawn != fingerprint {
            buffers.extend(self.panels.update_buffers(&gpu.device, &gpu.queue, encoder, panels, screen));
            let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
            let mut pass = color_pass(encoder, &layer.view, clear, "egui panels");
            self.panels.render(&mut pass, panels, screen);
            layer.drawn = fingerprint;
            layer.areas = disjoint(&drawn_areas(panels, screen));
        }
        self.composite.prepare(&gpu.device, &layer.view);
        self.composite.encode(encoder, target, Some(&layer.areas));
        self.layer = Some(layer);
        buffers
    }

    /// The layer, made again (empty) when the window's size changed.
    fn take_layer(&mut self, device: &wgpu::Device, size: [u32; 2]) -> Layer {
        if let Some(layer) = self.layer.take().filter(|layer| layer.size == size) {
            return layer;
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("egui panels layer"),
            size: wgpu::Extent3d { width: size[0].max(1), height: size[1].max(1), depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Layer { view, size, drawn: None, areas: Vec::new() }
    }
}

/// The pixel rectangles (x0, y0, x1, y1) the primitives may draw in: each
/// mesh's bounds within its clip rectangle, rounded outward, on the screen.
fn drawn_areas(primitives: &[ClippedPrimitive], screen: &egui_wgpu::ScreenDescriptor) -> Vec<[u32; 4]> {
    let [width, height] = screen.size_in_pixels;
    let ppp = screen.pixels_per_point;
    let pixels = |v: f32, limit: u32| (v.max(0.0) as u32).min(limit);
    primitives
        .iter()
        .filter_map(|ClippedPrimitive { clip_rect, primitive }| {
            let Primitive::Mesh(mesh) = primitive else { return Some([0, 0, width, height]) };
            let r = mesh.calc_bounds().intersect(*clip_rect);
            let area = [
                pixels((r.min.x * ppp).floor(), width),
                pixels((r.min.y * ppp).floor(), height),
                pixels((r.max.x * ppp).ceil(), width),
                pixels((r.max.y * ppp).ceil(), height),
            ];
            (area[0] < area[2] && area[1] < area[3]).then_some(area)
        })
        .collect()
}

/// The union of rectangles (x0, y0, x1, y1) as disjoint rectangles (x, y,
/// width, height): per horizontal band between their edges, the merged
/// runs across it. A pixel blended twice would be drawn wrong.
fn disjoint(rects: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let mut edges: Vec<u32> = rects.iter().flat_map(|r| [r[1], r[3]]).collect();
    edges.sort_unstable();
    edges.dedup();
    let mut out = Vec::new();
    for band in edges.windows(2) {
        let (y0, y1) = (band[0], band[1]);
        let mut runs: Vec<(u32, u32)> =
            rects.iter().filter(|r| r[1] <= y0 && r[3] >= y1).map(|r| (r[0], r[2])).collect();
        runs.sort_unstable();
        let mut merged: Vec<(u32, u32)> = Vec::new();
        for (x0, x1) in runs {
            match merged.last_mut() {
                Some(last) if x0 <= last.1 => last.1 = last.1.max(x1),
                _ => merged.push((x0, x1)),
            }
        }
        out.extend(merged.into_iter().map(|(x0, x1)| [x0, y0, x1 - x0, y1 - y0]));
    }
    out
}

/// A hash of everything that decides the panels' pixels (given the same
/// textures): the screen, and each primitive's clip rectangle, texture,
/// vertices and indices. `None` for a paint callback, which cannot be
/// compared and is drawn every frame.
fn fingerprint(primitives: &[ClippedPrimitive], screen: &egui_wgpu::ScreenDescriptor) -> Option<u64> {
    let mut hasher = std::hash::DefaultHasher::new();
    screen.size_in_pixels.hash(&mut hasher);
    screen.pixels_per_point.to_bits().hash(&mut hasher);
    for ClippedPrimitive { clip_rect, primitive } in primitives {
        let Primitive::Mesh(mesh) = primitive else { return None };
        for value in [clip_rect.min.x, clip_rect.min.y, clip_rect.max.x, clip_rect.max.y] {
            value.to_bits().hash(&mut hasher);
        }
        mesh.texture_id.hash(&mut hasher);
        hasher.write(bytemuck::cast_slice(&mesh.vertices));
        hasher.write(bytemuck::cast_slice(&mesh.indices));
    }
    Some(hasher.finish())
}

#[cfg(test)]
mod tests {
    use egui::epaint::{Mesh, Vertex};
    use egui::{Color32, Pos2, Rect, TextureId};

    use super::*;

    fn quad(color: Color32) -> ClippedPrimitive {
        let mut mesh = Mesh::with_texture(TextureId::Managed(0));
        for (x, y) in [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)] {
            mesh.vertices.push(Vertex { pos: Pos2::new(x, y), uv: Pos2::ZERO, color });
        }
        mesh.indices = vec![0, 1, 2, 0, 2, 3];
        ClippedPrimitive {
            clip_rect: Rect::from_min_max(Pos2::ZERO, Pos2::new(100.0, 100.0)),
            primitive: Primitive::Mesh(mesh),
        }
    }

    #[test]
    fn disjoint_areas_cover_the_union_once() {
        let rects = [[0, 0, 40, 5], [0, 5, 10, 30], [2, 8, 8, 20], [5, 0, 15, 12], [30, 20, 35, 25], [12, 25, 20, 30]];
        let areas = disjoint(&rects);
        for y in 0..32 {
            for x in 0..42 {
                let inside = rects.iter().any(|r| x >= r[0] && x < r[2] && y >= r[1] && y < r[3]);
                let covers = areas.iter().filter(|a| x >= a[0] && x < a[0] + a[2] && y >= a[1] && y < a[1] + a[3]);
                assert_eq!(covers.count(), usize::from(inside), "pixel {x},{y}");
            }
        }
        assert!(disjoint(&[]).is_empty());
    }

    #[test]
    fn the_fingerprint_changes_with_anything_drawn_and_only_then() {
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: [100, 100], pixels_per_point: 1.0 };
        let base = fingerprint(&[quad(Color32::WHITE)], &screen);
        assert_eq!(base, fingerprint(&[quad(Color32::WHITE)], &screen));
        assert_ne!(base, fingerprint(&[quad(Color32::RED)], &screen), "a colour");
        let mut moved = quad(Color32::WHITE);
        if let Primitive::Mesh(mesh) = &mut moved.primitive {
            mesh.vertices[2].pos.x += 0.5;
        }
        assert_ne!(base, fingerprint(&[moved], &screen), "a vertex");
        let mut clipped = quad(Color32::WHITE);
        clipped.clip_rect.max.x = 50.0;
        assert_ne!(base, fingerprint(&[clipped], &screen), "a clip rectangle");
        let bigger = egui_wgpu::ScreenDescriptor { size_in_pixels: [200, 100], pixels_per_point: 1.0 };
        assert_ne!(base, fingerprint(&[quad(Color32::WHITE)], &bigger), "the screen");
        assert_ne!(base, fingerprint(&[quad(Color32::WHITE), quad(Color32::WHITE)], &screen), "a second mesh");
    }
}
