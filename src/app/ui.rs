//! The egui panels. They read the plain editor state, bind its knobs (tool,
//! brush, colour, render settings) directly, and return [`Command`]s for
//! everything that acts (edits, files, camera moves).
//!
//! Layout: a menu bar on top and a tool panel on the left, both drawn *over*
//! the traced image, which always fills the whole window. So window pixel
//! (x, y) is trace pixel (x, y) at render scale 1, whatever the panels do.

use std::path::{Path, PathBuf};

use egui::{Color32, Sense, Stroke, Vec2};

use octovox::scene::{Material, MaterialKind, Octree, Palette};
use octovox::settings::{EffectsChoice, Shading, Sky, TraceMode, View};

use super::command::{Choice, Command, Pending};
use super::state::{BrushKind, EditorState, Pick, Tool};
use glam::{IVec3, Vec3};

/// Width of the left panel in points.
pub const PANEL_WIDTH: f32 = 236.0;

/// Numbers the stats panel shows.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Frames per second over recent continuously drawn frames.
    pub fps: f64,
    /// Wall time of the last frame function, milliseconds.
    pub frame_ms: f64,
    /// Trace pass time: GPU timestamps when available, else wall time.
    pub trace_ms: f64,
    /// Wall time of acquire, blit, egui, submit and present, milliseconds.
    pub present_ms: f64,
    /// Render scale of the last frame (lower while the camera moves).
    pub scale: f32,
    /// Whether the camera moved since the frame before.
    pub moving: bool,
    /// Bytes the last edit (or undo/redo) wrote to the GPU.
    pub last_edit_bytes: u64,
    /// Byte ranges of the last edit.
    pub last_edit_ranges: usize,
    /// The path tracer's last frame, when it drew it.
    pub path: Option<octovox::gpu::PathFrame>,
}

/// Read-only facts the panels show.
pub struct Info<'a> {
    pub palette: &'a Palette,
    pub tree: &'a Octree,
    pub stats: &'a Stats,
    pub adapter: &'a str,
    pub timestamps: bool,
    /// File being loaded, seconds since it started, and the fraction done
    /// where the loader reports one (.obj tiles, .ovx bytes).
    pub loading: Option<(&'a Path, f64, Option<f32>)>,
    pub can_undo: bool,
    pub can_redo: bool,
    /// Undo steps, their bytes, and the history's budget.
    pub history: (usize, usize, usize),
    /// The last measurement of the quality presets, if any.
    pub presets: Option<&'a [super::presets::Measured]>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogKind {
    Open,
    SaveAs,
    Export,
}

/// UI-only state: open dialogs, the prompt, the message line.
#[derive(Debug, Default)]
pub struct UiState {
    pub dialog: Option<(DialogKind, String)>,
    /// An action waiting for the unsaved-changes prompt.
    pub pending: Option<Pending>,
    pub prompt_open: bool,
    /// A read-only file the user is asked about overwriting.
    pub read_only: Option<PathBuf>,
    /// A crash-recovery journal found beside the document just opened.
    pub recover: Option<PathBuf>,
    /// Last message for the user, and whether it is an error.
    pub message: Option<(String, bool)>,
}

impl UiState {
    pub fn error(&mut self, text: impl Into<String>) {
        let text = text.into();
        log::warn!("{text}");
        self.message = Some((text, true));
    }

    pub fn info(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), false));
    }
}

fn rgba(palette: &Palette, index: u8) -> Color32 {
    let [r, g, b, _] = palette.color(index);
    Color32::from_rgb(r, g, b)
}

/// Draws every panel; returns what the user asked for.
pub fn show(ui: &mut egui::Ui, state: &mut EditorState, ui_state: &mut UiState, info: &Info) -> Vec<Command> {
    let mut out = Vec::new();
    egui::Panel::top("menu").show(ui, |ui| menu_bar(ui, info, ui_state, &mut out));
    egui::Panel::left("tools").resizable(false).exact_size(PANEL_WIDTH).show(ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            tools(ui, state);
            mirror(ui, state);
            ui.separator();
            palette(ui, state, info.palette);
            material_editor(ui, state.color, info.palette, &mut out);
            ui.separator();
            render(ui, state);
            quality(ui, info.presets, &mut out);
            ui.separator();
            stats(ui, info);
        });
    });
    dialog(ui.ctx(), ui_state, &mut out);
    prompt(ui.ctx(), ui_state, &mut out);
    read_only_prompt(ui.ctx(), ui_state, &mut out);
    recover_prompt(ui.ctx(), ui_state, &mut out);
    out
}

fn menu_bar(ui: &mut egui::Ui, info: &Info, ui_state: &mut UiState, out: &mut Vec<Command>) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            if ui.button("New          Ctrl+N").clicked() {
                out.push(Command::New);
            }
            if ui.button("Open…        Ctrl+O").clicked() {
                out.push(Command::AskOpen);
            }
            if ui.button("Save         Ctrl+S").clicked() {
                out.push(Command::Save);
            }
            if ui.button("Save As…     Ctrl+Shift+S").clicked() {
                out.push(Command::AskSaveAs);
            }
            if ui.button("Export mesh…").clicked() {
                out.push(Command::AskExport);
            }
            if ui.button("Screenshot   F12").clicked() {
                out.push(Command::Screenshot);
            }
            ui.separator();
            if ui.button("Quit         Ctrl+Q").clicked() {
                out.push(Command::Quit);
            }
        });
        ui.menu_button("Edit", |ui| {
            if ui.add_enabled(info.can_undo, egui::Button::new("Undo   Ctrl+Z")).clicked() {
                out.push(Command::Undo);
            }
            if ui.add_enabled(info.can_redo, egui::Button::new("Redo   Ctrl+Shift+Z / Ctrl+Y")).clicked() {
                out.push(Command::Redo);
            }
        });
        ui.menu_button("View", |ui| {
            if ui.button("Frame model   F").clicked() {
                out.push(Command::FrameModel);
            }
        });
        if let Some((path, seconds, fraction)) = info.loading {
            match fraction {
                Some(f) => {
                    ui.add(egui::ProgressBar::new(f).desired_width(120.0).show_percentage());
                }
                None => {
                    ui.spinner();
                }
            }
            ui.label(format!("loading {} … {seconds:.1} s", path.display()));
        }
        message(ui, ui_state);
    });
}

/// Mirror planes: a checkbox and the plane's coordinate per axis.
fn mirror(ui: &mut egui::Ui, state: &mut EditorState) {
    ui.horizontal(|ui| {
        ui.label("Mirror");
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            let mut on = state.mirror.planes[axis].is_some();
            let mut c = state.mirror.plane(axis).unwrap_or(0.0);
            ui.checkbox(&mut on, name);
            if on {
                ui.add(egui::DragValue::new(&mut c).speed(0.5).fixed_decimals(1));
            }
            state.mirror.set(axis, on.then_some(c));
        }
    });
}

fn tools(ui: &mut egui::Ui, state: &mut EditorState) {
    ui.heading("Tool");
    ui.horizontal(|ui| {
        for tool in Tool::ALL {
            ui.selectable_value(&mut state.tool, tool, tool_label(tool));
        }
    });
    if ui
        .toggle_value(&mut state.line_mode, "Line (L)")
        .on_hover_text("press, drag and release: the brush along a line")
        .changed()
    {
        state.line_start = None;
    }
    ui.label("Brush");
    ui.horizontal(|ui| {
        ui.selectable_value(&mut state.brush_kind, BrushKind::Voxel, "Voxel");
        ui.selectable_value(&mut state.brush_kind, BrushKind::Sphere, "Sphere");
        ui.selectable_value(&mut state.brush_kind, BrushKind::Box, "Box");
    });
    match state.brush_kind {
        BrushKind::Voxel => {}
        BrushKind::Sphere => {
            ui.add(egui::Slider::new(&mut state.sphere_radius, 0..=32).text("radius"));
        }
        BrushKind::Box => {
            ui.add(egui::Slider::new(&mut state.box_size, 1..=64).text("size"));
        }
    }
    ui.small("left: apply · Ctrl+drag a face: extrude · right-drag: orbit · right-click: erase (Attach) · middle: pan · wheel: zoom · WASDQE + right: fly · F: frame");
}

fn palette(ui: &mut egui::Ui, state: &mut EditorState, palette: &Palette) {
    ui.heading("Palette");
    // One 16×16 block painted by hand: 256 widgets would be slow and loose.
    let cell = ((ui.available_width() - 4.0) / 16.0).floor().clamp(8.0, 16.0);
    let (rect, response) = ui.allocate_exact_size(Vec2::splat(cell * 16.0), Sense::click());
    let cell_rect = |index: u8| {
        let (row, column) = (f32::from(index / 16), f32::from(index % 16));
        egui::Rect::from_min_size(rect.min + Vec2::new(column, row) * cell, Vec2::splat(cell)).shrink(0.5)
    };
    let painter = ui.painter_at(rect);
    for index in 0..=255u8 {
        let r = cell_rect(index);
        if index == 0 {
            // Index 0 is "empty", not a colour.
            painter.line_segment([r.left_bottom(), r.right_top()], Stroke::new(1.0, Color32::GRAY));
        } else {
            painter.rect_filled(r, 0.0, rgba(palette, index));
        }
    }
    let selected = cell_rect(state.color);
    painter.rect_stroke(selected, 0.0, Stroke::new(2.0, Color32::WHITE), egui::StrokeKind::Inside);
    let index_at = |pos: egui::Pos2| {
        let offset = (pos - rect.min) / cell;
        let (column, row) = (offset.x.floor() as i32, offset.y.floor() as i32);
        ((0..16).contains(&column) && (0..16).contains(&row)).then(|| (row * 16 + column) as u8)
    };
    if response.clicked()
        && let Some(index) = response.interact_pointer_pos().and_then(index_at).filter(|i| *i != 0)
    {
        state.color = index;
    }
    if let Some(index) = response.hover_pos().and_then(index_at) {
        response.on_hover_text(format!("{index}"));
    }
    let material = palette.material(state.color);
    let [r, g, b, _] = palette.color(state.color);
    ui.label(format!(
        "colour {} · #{r:02x}{g:02x}{b:02x} · {}",
        state.color,
        material.kind.vox_name().trim_start_matches('_')
    ));
    let params: Vec<String> =
        material.params.iter().filter(|(k, _)| k.as_str() != "_type").map(|(k, v)| format!("{k}={v}")).collect();
    if !params.is_empty() {
        ui.small(params.join(" "));
    }
}

/// The selected entry's colour, material kind and the parameters the path
/// tracer reads; every change is an edit (undoable, saved in RGBA/MATL).
fn material_editor(ui: &mut egui::Ui, index: u8, palette: &Palette, out: &mut Vec<Command>) {
    let old_color = palette.color(index);
    let old = palette.material(index);
    let mut color = Color32::from_rgba_unmultiplied(old_color[0], old_color[1], old_color[2], old_color[3]);
    let mut material = old.clone();
    let mut changed = false;
    ui.horizontal(|ui| {
        changed |= ui.color_edit_button_srgba(&mut color).changed();
        egui::ComboBox::from_id_salt("material kind")
            .selected_text(material.kind.vox_name().trim_start_matches('_'))
            .show_ui(ui, |ui| {
                for kind in MaterialKind::ALL {
                    let label = kind.vox_name().trim_start_matches('_');
                    changed |= ui.selectable_value(&mut material.kind, kind, label).changed();
                }
            });
    });
    let sliders: &[(&str, &str, std::ops::RangeInclusive<f32>)] = match material.kind {
        MaterialKind::Metal => &[("_rough", "roughness", 0.0..=1.0), ("_metal", "metalness", 0.0..=1.0)],
        MaterialKind::Glass => &[
            ("_rough", "roughness", 0.0..=1.0),
            ("_ri", "refractive index", 1.0..=3.0),
            ("_trans", "transparency", 0.0..=1.0),
        ],
        MaterialKind::Emit => &[("_emit", "emission", 0.0..=1.0), ("_flux", "power", 0.0..=4.0)],
        MaterialKind::Diffuse | MaterialKind::Media => &[],
    };
    for (key, label, range) in sliders {
        let mut value = material_value(&material, key);
        if ui.add(egui::Slider::new(&mut value, range.clone()).text(*label)).changed() {
            material.params.insert((*key).to_string(), format!("{value:.3}"));
            if *key == "_ri" {
                // MagicaVoxel writes the index minus one as `_ior` beside `_ri`.
                material.params.insert("_ior".to_string(), format!("{:.3}", value - 1.0));
            }
            changed = true;
        }
    }
    if changed {
        let edit =
            octovox::edit::Edit::Palette { index, color: color.to_srgba_unmultiplied(), material: Box::new(material) };
        let dragging = ui.ctx().input(|i| i.pointer.any_down());
        out.push(Command::EditPalette { edit, dragging });
    }
}

/// The value the renderer uses for a MATL key (clamped, defaulted).
fn material_value(material: &Material, key: &str) -> f32 {
    match key {
        "_rough" => material.roughness(),
        "_metal" => material.metalness(),
        "_ri" => material.ior(),
        "_trans" => material.transparency(),
        "_emit" => material.emission(),
        _ => material.flux(),
    }
}

fn render(ui: &mut egui::Ui, state: &mut EditorState) {
    ui.heading("Render");
    let settings = &mut state.settings;
    egui::ComboBox::from_id_salt("view").selected_text(format!("{:?}", settings.view)).show_ui(ui, |ui| {
        for view in View::ALL {
            ui.selectable_value(&mut settings.view, view, format!("{view:?}"));
        }
    });
    ui.horizontal(|ui| {
        ui.label("--mode");
        ui.radio_value(&mut settings.mode, TraceMode::Svo, "svo");
        ui.radio_value(&mut settings.mode, TraceMode::Grid, "grid (DDA)");
    });
    ui.checkbox(&mut settings.shadows, "Sun shadows");
    // The knobs carry their command-line names, as in `bench quality`;
    // shorter sliders leave the panel room for them.
    ui.spacing_mut().slider_width = 64.0;
    ui.add(egui::Slider::new(&mut settings.render_scale, 0.25..=1.0).text("--render-scale"));
    ui.add(egui::Slider::new(&mut settings.lod, 0.0..=16.0).step_by(0.5).text("--lod (px)")).on_hover_text(
        "level of detail: the preview stops at octree cells narrower than this many pixels \
         and draws them as one solid cell (0 = exact; the path tracer is always exact)",
    );
    ui.add(egui::Slider::new(&mut state.frame_target_ms, 10.0..=100.0).text("ms target"))
        .on_hover_text("frame time to hold while the camera moves: the render scale drops as far as needed");
    path_tracing(ui, state);
}

/// Presets from draft to reference, with what each costs here and the error
/// it buys once measured.
fn quality(ui: &mut egui::Ui, measured: Option<&[super::presets::Measured]>, out: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        ui.label("Quality");
        if ui.button("Measure").on_hover_text("time and error (FLIP) of each preset from this camera").clicked() {
            out.push(Command::MeasurePresets);
        }
    });
    egui::Grid::new("presets").num_columns(3).show(ui, |ui| {
        for (i, preset) in super::presets::PRESETS.iter().enumerate() {
            if ui.small_button(preset.name).clicked() {
                out.push(Command::ApplyPreset(i));
            }
            match measured.and_then(|m| m.get(i)) {
                Some(m) => {
                    ui.label(format!("{:.0} ms", m.ms));
                    ui.label(format!("FLIP {:.3}", m.flip));
                }
                None => {
                    ui.label("");
                    ui.label("");
                }
            }
            ui.end_row();
        }
    });
}

fn path_tracing(ui: &mut egui::Ui, state: &mut EditorState) {
    egui::ComboBox::from_id_salt("shading").selected_text(state.shading.label()).show_ui(ui, |ui| {
        for shading in Shading::ALL {
            ui.selectable_value(&mut state.shading, shading, shading.label());
        }
    });
    if state.shading == Shading::Preview {
        return;
    }
    let path = &mut state.path_settings;
    ui.add(egui::Slider::new(&mut path.bounces, 0..=16).text("--bounces"));
    ui.add(egui::Slider::new(&mut path.shadow_samples, 1..=16).text("--shadow-samples"));
    ui.add(egui::Slider::new(&mut state.sample_target, 1..=4096).logarithmic(true).text("--spp"));
    ui.horizontal(|ui| {
        ui.checkbox(&mut path.sun, "Sun");
        egui::ComboBox::from_id_salt("sky").selected_text(format!("sky: {:?}", path.sky)).show_ui(ui, |ui| {
            for sky in [Sky::Gradient, Sky::White, Sky::Black] {
                ui.selectable_value(&mut path.sky, sky, format!("{sky:?}"));
            }
        });
    });
    ui.horizontal(|ui| {
        ui.radio_value(&mut path.effects, EffectsChoice::Auto, "effects: auto");
        ui.radio_value(&mut path.effects, EffectsChoice::All, "all");
    });
}

fn stats(ui: &mut egui::Ui, info: &Info) {
    ui.heading("Stats");
    let s = info.stats;
    let tree = info.tree;
    let pool = tree.pool();
    let trace = if info.timestamps { "GPU" } else { "wall" };
    egui::Grid::new("stats").num_columns(2).show(ui, |ui| {
        let mut row = |name: &str, value: String| {
            ui.label(name);
            ui.label(value);
            ui.end_row();
        };
        row("fps", format!("{:.1}", s.fps));
        row("frame", format!("{:.2} ms", s.frame_ms));
        row("trace", format!("{:.2} ms ({trace})", s.trace_ms));
        row("present", format!("{:.2} ms", s.present_ms));
        row("scale", format!("{:.2}{}", s.scale, if s.moving { " (moving)" } else { "" }));
        if let Some(path) = &s.path {
            let effects = path.effects.names();
            let compiling = if path.kernel == path.effects { "" } else { " (compiling; all run)" };
            row(
                "effects",
                format!("{}{compiling}", if effects.is_empty() { "none".into() } else { effects.join(" ") }),
            );
            row("samples", format!("{}", path.samples));
            row("per sample", format!("{:.2} ms", s.trace_ms));
        }
        row("voxels", format!("{}", tree.solid_voxels()));
        row("nodes", format!("{} + {} bricks", tree.node_count(), tree.brick_count()));
        row("pool", format!("{} bytes", pool.live_bytes()));
        row("last edit", format!("{} bytes, {} ranges", s.last_edit_bytes, s.last_edit_ranges));
        row("uploaded", format!("{} bytes total", pool.stats.total_bytes));
        let (steps, bytes, limit) = info.history;
        let human = |b: usize| octovox::budget::human(b as u64);
        row("undo", format!("{steps} steps, {} of {} (oldest dropped past it)", human(bytes), human(limit)));
        row("adapter", info.adapter.to_string());
    });
}

/// The last message (errors in red), on the menu bar where it is always seen.
fn message(ui: &mut egui::Ui, ui_state: &mut UiState) {
    let mut clear = false;
    if let Some((text, is_error)) = &ui_state.message {
        ui.separator();
        let color = if *is_error { Color32::from_rgb(255, 110, 100) } else { Color32::LIGHT_GREEN };
        ui.colored_label(color, text);
        clear = ui.small_button("×").on_hover_text("dismiss").clicked();
    }
    if clear {
        ui_state.message = None;
    }
}

/// Files in the current folder and in `saves/` for a path dialog: .vox,
/// .ovx and .obj to open, .vox or .ovx to save over.
fn nearby_files(kind: DialogKind) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = [Path::new("."), Path::new("saves")]
        .iter()
        .filter_map(|dir| std::fs::read_dir(dir).ok())
        .flatten()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            let scene = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("vox")) || octovox::io::is_ovx_path(p);
            match kind {
                DialogKind::Open => scene || octovox::io::is_mesh_path(p),
                DialogKind::SaveAs => scene,
                DialogKind::Export => octovox::io::export::MeshFormat::of(p).is_some(),
            }
        })
        .collect();
    files.sort();
    files
}

fn dialog(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<Command>) {
    let Some((kind, path)) = &mut ui_state.dialog else { return };
    let title = match kind {
        DialogKind::Open => "Open .vox, .ovx or .obj",
        DialogKind::SaveAs => "Save as .vox or .ovx",
        DialogKind::Export => "Export a mesh (.obj, .ply or .glb)",
    };
    let mut close = false;
    egui::Window::new(title).collapsible(false).resizable(false).show(ctx, |ui| {
        ui.label("Path:");
        let field = ui.text_edit_singleline(path);
        let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        // Typing goes to the path at once (nothing else has focus while the dialog is up).
        if !entered && ui.memory(|m| m.focused().is_none()) {
            field.request_focus();
        }
        for file in nearby_files(*kind).into_iter().take(12) {
            if ui.link(file.display().to_string()).clicked() {
                *path = file.display().to_string();
            }
        }
        ui.horizontal(|ui| {
            let verb = match kind {
                DialogKind::Open => "Open",
                DialogKind::SaveAs => "Save",
                DialogKind::Export => "Export",
            };
            let ok = ui.button(verb).clicked();
            if (ok || entered) && !path.trim().is_empty() {
                let chosen = PathBuf::from(path.trim());
                out.push(match kind {
                    DialogKind::Open => Command::Open(chosen),
                    DialogKind::SaveAs => Command::SaveAs(chosen),
                    DialogKind::Export => Command::Export(chosen),
                });
                close = true;
            }
            if ui.button("Cancel").clicked() {
                close = true;
            }
        });
    });
    if close {
        ui_state.dialog = None;
    }
}

fn prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<Command>) {
    if !ui_state.prompt_open {
        return;
    }
    let what = match &ui_state.pending {
        Some(Pending::New) => "starting a new scene",
        Some(Pending::Open(_)) => "opening another file",
        Some(Pending::Quit) => "quitting",
        None => "continuing",
    };
    egui::Modal::new(egui::Id::unique("unsaved")).show(ctx, |ui| {
        ui.heading("Unsaved changes");
        ui.label(format!("Save the changes before {what}?"));
        ui.horizontal(|ui| {
            if ui.button("Save").clicked() {
                out.push(Command::Resolve(Choice::Save));
            }
            if ui.button("Discard").clicked() {
                out.push(Command::Resolve(Choice::Discard));
            }
            if ui.button("Cancel").clicked() {
                out.push(Command::Resolve(Choice::Cancel));
            }
        });
    });
}

/// Offers to apply a crash-recovery journal found beside the document.
fn recover_prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<Command>) {
    let Some(journal) = ui_state.recover.clone() else { return };
    egui::Modal::new(egui::Id::unique("recover")).show(ctx, |ui| {
        ui.heading("Recover unsaved edits?");
        ui.label(format!(
            "A session that ended without saving left its edits in {}. Apply them to the document?",
            journal.display()
        ));
        ui.horizontal(|ui| {
            if ui.button("Recover").clicked() {
                ui_state.recover = None;
                out.push(Command::RecoverJournal);
            }
            if ui.button("Discard").clicked() {
                ui_state.recover = None;
                out.push(Command::DiscardJournal);
            }
        });
    });
}

/// Asks before a save replaces a read-only file.
fn read_only_prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<Command>) {
    let Some(path) = ui_state.read_only.clone() else { return };
    let modal = egui::Modal::new(egui::Id::unique("read-only")).show(ctx, |ui| {
        ui.heading("Read-only file");
        ui.label(format!("{} is read-only. Overwrite it?", path.display()));
        ui.horizontal(|ui| {
            if ui.button("Overwrite").clicked() {
                ui_state.read_only = None;
                out.push(Command::SaveOver(path.clone()));
            }
            if ui.button("Cancel").clicked() {
                ui_state.read_only = None;
            }
        });
    });
    // Escape or a click outside cancels, as Cancel does.
    if modal.should_close() {
        ui_state.read_only = None;
    }
}

/// Button text of a tool, with its MagicaVoxel key.
fn tool_label(tool: Tool) -> &'static str {
    match tool {
        Tool::Attach => "Attach (T)",
        Tool::Erase => "Erase (R)",
        Tool::Paint => "Paint (G)",
    }
}

/// Outlines the cells the brush would touch (projected with the trace
/// camera), so the preview also shows Attach's target cells, which are empty
/// and so cannot be tinted by the shader.
pub fn draw_brush_outline(ui: &egui::Ui, state: &EditorState, pick: &Pick, info: &Info) {
    let (lo, hi) = state.preview_box(pick);
    let screen = ui.ctx().content_rect();
    let (w, h) = (screen.width().max(1.0), screen.height().max(1.0));
    let basis = state.camera.basis(w as u32, h as u32, info.tree.origin());
    let origin = info.tree.origin().as_vec3();
    let project = |p: Vec3| -> Option<egui::Pos2> {
        let d = p - origin - basis.eye;
        let depth = d.dot(basis.forward);
        if depth <= 0.05 {
            return None;
        }
        let nx = d.dot(basis.right) / basis.right.length_squared() / depth;
        let ny = d.dot(basis.up) / basis.up.length_squared() / depth;
        Some(egui::pos2((nx + 1.0) * 0.5 * w, (1.0 - ny) * 0.5 * h))
    };
    let (a, b) = (lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { a.x } else { b.x },
            if i & 2 == 0 { a.y } else { b.y },
            if i & 4 == 0 { a.z } else { b.z },
        )
    };
    let painter =
        ui.ctx().layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::unique("brush outline")));
    let color = match state.tool {
        Tool::Attach => egui::Color32::from_rgb(120, 255, 140),
        Tool::Erase => egui::Color32::from_rgb(255, 100, 90),
        Tool::Paint => egui::Color32::from_rgb(255, 220, 90),
    };
    for i in 0..8usize {
        for bit in [1usize, 2, 4] {
            let j = i | bit;
            if j == i {
                continue;
            }
            if let (Some(p), Some(q)) = (project(corner(i)), project(corner(j))) {
                painter.line_segment([p, q], egui::Stroke::new(1.5, color));
            }
        }
    }
}
