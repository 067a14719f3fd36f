//! The egui panels. They read the plain editor state, bind its knobs (tool,
//! brush, colour, render settings) directly, and return [`AppCommand`]s for
//! everything that acts (edits, files, camera moves).
//!
//! Layout: a menu bar on top, a tool panel on the left and, for a scene of
//! objects, the Outliner on the right, all drawn *over* the traced image,
//! which always fills the whole window. So window pixel (x, y) is trace
//! pixel (x, y) at render scale 1, whatever the panels do.

use std::path::{Path, PathBuf};

use egui::{Color32, Sense, Stroke, Vec2};

use octovox::scene::objects::Objects;
use octovox::scene::{Material, MaterialKind, Palette, Scene};
use octovox::settings::{EffectsChoice, Shading, Sky, TraceMode, View};

use super::browser::Answer;
use super::command::{AppCommand, Choice, Pending};
use super::state::{BrushKind, EditorState, Mode, Pick, Tool};
use glam::{IVec3, Vec3};
use octovox::edit::brush::Brush;
use octovox::edit::selection::Region;
use octovox::editor::Tools;

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
    /// Its parts, and the panels' layout and tessellation, milliseconds.
    pub acquire_ms: f64,
    pub draw_ms: f64,
    pub submit_ms: f64,
    pub panels_ms: f64,
    /// Render scale of the last frame (lower while the camera moves).
    pub scale: f32,
    /// Whether the camera moved since the frame before.
    pub moving: bool,
    /// Bytes the last edit (or undo/redo) of this scene wrote to the GPU;
    /// `None` before its first.
    pub last_edit_bytes: Option<u64>,
    /// Byte ranges of the last edit.
    pub last_edit_ranges: usize,
    /// The path tracer's last frame, when it drew it.
    pub path: Option<octovox::gpu::PathFrame>,
    /// The path-traced image's estimated noise at the last sample
    /// (`Renderer::noise_estimate`).
    pub noise: Option<f32>,
}

/// What the panels read out: the last frame's numbers, the ones on
/// screen, and what the last measurement of the quality presets found.
#[derive(Default)]
pub struct Readouts {
    pub stats: Stats,
    pub shown_stats: ShownStats,
    pub presets_measured: Option<Vec<super::presets::Measured>>,
}

/// How often the Stats panel takes new numbers.
const STATS_REFRESH: std::time::Duration = std::time::Duration::from_millis(250);

/// The numbers the Stats panel shows, taken four times a second: digits
/// that change every frame cannot be read, and they would make the panels
/// (kept on the GPU while unchanged, `EguiLayers`) be drawn again every
/// frame.
#[derive(Default)]
pub struct ShownStats {
    stats: Stats,
    taken: Option<web_time::Instant>,
}

impl ShownStats {
    /// The numbers to show: `current` when the last were taken long enough
    /// ago, else those, with a frame asked for when they are due.
    pub fn take(&mut self, ctx: &egui::Context, current: &Stats) -> &Stats {
        let age = self.taken.map_or(STATS_REFRESH, |at| at.elapsed());
        if age >= STATS_REFRESH {
            self.stats = current.clone();
            self.taken = Some(web_time::Instant::now());
        } else {
            ctx.request_repaint_after(STATS_REFRESH - age);
        }
        &self.stats
    }
}

/// Read-only facts the panels show.
pub struct Info<'a> {
    pub palette: &'a Palette,
    pub scene: &'a Scene,
    /// Where the line being dragged starts.
    pub line_start: Option<IVec3>,
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
    pub selection: Option<Region>,
    pub has_clipboard: bool,
    /// File ▸ Open recent, newest first.
    pub recent: Vec<PathBuf>,
    /// The faces an extrude would move (voxels, normal) and its layers so far.
    pub extrude: Option<(&'a [IVec3], IVec3, i32)>,
    /// What a fill would recolour (bounds and count; `None` inside: too large).
    pub fill: Option<Option<((IVec3, IVec3), usize)>>,
    /// The box a paste would fill.
    pub paste: Option<Region>,
    /// The colour the eyedropper would pick.
    pub eyedropper: Option<u8>,
    /// The objects and layers of a scene of several objects.
    pub objects: Option<&'a Objects>,
    /// Clicks that hit no voxel land on the ground (`ground on|off`).
    pub ground: bool,
}

/// How long an info message (`saved …`, `copied 6 voxels`) stays.
pub const INFO_LIFETIME: std::time::Duration = std::time::Duration::from_secs(4);

/// UI-only state: open dialogs, the prompt, the message line.
#[derive(Debug, Default)]
pub struct UiState {
    /// The file browser inside the window, where no native dialog shows.
    pub dialog: Option<super::browser::Browser>,
    /// An action waiting for the unsaved-changes prompt.
    pub pending: Option<Pending>,
    pub prompt_open: bool,
    /// A file the user is asked about replacing: a read-only one, or an
    /// existing file other than the document's own (a Save As onto it).
    pub replace: Option<Replace>,
    /// A crash-recovery journal found beside the document just opened, and
    /// why applying it needs a second thought (its document changed since).
    pub recover: Option<(PathBuf, Option<String>)>,
    /// The Outliner's and Layers panel's own state.
    pub outliner: super::outliner::OutlinerState,
    /// The timeline's: playing, the easing of new keys.
    pub playback: super::timeline::Playback,
    /// The open scene's edits are not journaled, and why: shown until a
    /// journal starts again.
    pub journal_warning: Option<String>,
    /// Last message for the user, whether it is an error, and when it came.
    pub message: Option<(String, bool, web_time::Instant)>,
}

/// A file a save would replace, which the user is asked about first.
#[derive(Clone, Debug)]
pub struct Replace {
    pub path: PathBuf,
    /// It is read-only (else: it exists and is not the document's own).
    pub read_only: bool,
}

impl UiState {
    /// Whether a dialog or prompt waits for an answer over the view.
    pub fn modal_open(&self) -> bool {
        self.dialog.is_some() || self.prompt_open || self.replace.is_some() || self.recover.is_some()
    }

    pub fn error(&mut self, text: impl Into<String>) {
        let text = text.into();
        log::warn!("{text}");
        self.message = Some((text, true, web_time::Instant::now()));
    }

    /// A message that says what just happened: it goes after
    /// [`INFO_LIFETIME`], or at the next change (`saved …` no longer holds
    /// once the scene is edited again).
    pub fn info(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), false, web_time::Instant::now()));
    }

    /// The scene changed: a message about what was before goes. Errors stay
    /// until dismissed or replaced.
    pub fn change_made(&mut self) {
        self.message = self.message.take().filter(|(_, is_error, _)| *is_error);
    }

    /// The message to show `now`, if any: an info message past its lifetime
    /// is dropped.
    pub fn current_message(&mut self, now: web_time::Instant) -> Option<(&str, bool, std::time::Duration)> {
        let expired = |(_, is_error, at): &(String, bool, web_time::Instant)| {
            !is_error && now.saturating_duration_since(*at) >= INFO_LIFETIME
        };
        if self.message.as_ref().is_some_and(expired) {
            self.message = None;
        }
        let (text, is_error, at) = self.message.as_ref()?;
        Some((text, *is_error, INFO_LIFETIME.saturating_sub(now.saturating_duration_since(*at))))
    }
}

fn rgba(palette: &Palette, index: u8) -> Color32 {
    let [r, g, b, _] = palette.color(index);
    Color32::from_rgb(r, g, b)
}

/// Draws every panel; returns what the user asked for.
pub fn show(
    ui: &mut egui::Ui,
    state: &mut EditorState,
    tools: &Tools,
    ui_state: &mut UiState,
    info: &Info,
) -> Vec<AppCommand> {
    let mut out = Vec::new();
    egui::Panel::top("menu").show(ui, |ui| menu_bar(ui, info, ui_state, &mut out));
    if let Some(objects) = info.scene.objects() {
        super::timeline::show(ui, objects, &mut ui_state.playback, &mut out);
    }
    if let Some(objects) = info.objects {
        super::outliner::show(ui, objects, &mut ui_state.outliner, &mut out);
    }
    egui::Panel::left("tools").resizable(false).exact_size(PANEL_WIDTH).show(ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            tool_panel(ui, state, tools, &mut out);
            mirror(ui, tools, &mut out);
            ground(ui, state, info.ground, &mut out);
            ui.separator();
            palette(ui, tools, info.palette, &mut out);
            material_editor(ui, tools.color, info.palette, &mut out);
            ui.separator();
            // Sections below the palette collapse; none above it changes height.
            egui::CollapsingHeader::new("Render").default_open(true).show(ui, |ui| {
                render(ui, state, info.stats);
                quality(ui, info.presets, &mut out);
            });
            egui::CollapsingHeader::new("Stats").default_open(true).show(ui, |ui| stats(ui, info));
        });
    });
    let right = if info.objects.is_some() { super::outliner::OUTLINER_WIDTH } else { 0.0 };
    super::gizmo::show(ui.ctx(), &state.camera, right, &mut out);
    dialog(ui.ctx(), ui_state, &mut out);
    prompt(ui.ctx(), ui_state, &mut out);
    replace_prompt(ui.ctx(), ui_state, &mut out);
    recover_prompt(ui.ctx(), ui_state, &mut out);
    out
}

fn menu_bar(ui: &mut egui::Ui, info: &Info, ui_state: &mut UiState, out: &mut Vec<AppCommand>) {
    egui::MenuBar::new().ui(ui, |ui| {
        for (menu, actions) in super::actions::menus() {
            ui.menu_button(menu, |ui| {
                for action in actions {
                    let text = format!("{}   {}", action.label, super::actions::shortcut_text(action));
                    if ui.add_enabled(available(&action.command, info), egui::Button::new(text)).clicked() {
                        out.push(action.command.clone());
                    }
                    if action.command == AppCommand::AskOpen {
                        recent_menu(ui, info, out);
                    }
                }
            });
        }
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

/// File ▸ Open recent.
fn recent_menu(ui: &mut egui::Ui, info: &Info, out: &mut Vec<AppCommand>) {
    ui.add_enabled_ui(!info.recent.is_empty(), |ui| {
        ui.menu_button("Open recent", |ui| {
            for path in &info.recent {
                if ui.button(path.display().to_string()).clicked() {
                    out.push(AppCommand::Open(path.clone()));
                }
            }
        });
    });
}

/// Whether a menu entry can act now (greyed out otherwise).
fn available(command: &AppCommand, info: &Info) -> bool {
    match command {
        AppCommand::Undo => info.can_undo,
        AppCommand::Redo => info.can_redo,
        AppCommand::Copy | AppCommand::Cut | AppCommand::DeleteSelection | AppCommand::SelectNone => {
            info.selection.is_some()
        }
        AppCommand::PasteAtCursor => info.has_clipboard,
        AppCommand::Object(_) => info.objects.is_some_and(|o| o.selected.is_some()),
        _ => true,
    }
}

/// The ground (`ground on|off`) and the side of the working volume drawn on it.
fn ground(ui: &mut egui::Ui, state: &mut EditorState, on: bool, out: &mut Vec<AppCommand>) {
    ui.horizontal(|ui| {
        let mut shown = on;
        let tip = "clicks on empty space build on the ground at y = 0 (ground on|off)";
        if ui.checkbox(&mut shown, "Ground").on_hover_text(tip).changed() {
            out.push(AppCommand::Lines(vec![octovox::script::Line::Ground(shown)]));
        }
        ui.label("volume");
        let range = super::state::VOLUME_RANGE;
        ui.add_enabled(on, egui::DragValue::new(&mut state.volume).range(range).suffix("³"))
            .on_hover_text("the working volume outlined on the ground");
    });
}

/// Mirror planes: a checkbox and the plane's coordinate per axis. A change
/// runs as `mirror` lines: `mirror off`, then the planes on.
fn mirror(ui: &mut egui::Ui, tools: &Tools, out: &mut Vec<AppCommand>) {
    use octovox::script::Line;
    let mut mirror = tools.mirror;
    ui.horizontal(|ui| {
        ui.label("Mirror");
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            let mut on = mirror.planes[axis].is_some();
            let mut c = mirror.plane(axis).unwrap_or(0.0);
            ui.checkbox(&mut on, name);
            if on {
                ui.add(egui::DragValue::new(&mut c).speed(0.5).fixed_decimals(1));
            }
            mirror.set(axis, on.then_some(c));
        }
    });
    if mirror != tools.mirror {
        let planes = (0..3).filter_map(|axis| mirror.plane(axis).map(|c| Line::Mirror(Some((axis, c)))));
        out.push(AppCommand::Lines(std::iter::once(Line::Mirror(None)).chain(planes).collect()));
    }
}

fn tool_panel(ui: &mut egui::Ui, state: &mut EditorState, tools: &Tools, commands: &mut Vec<AppCommand>) {
    ui.heading("Tool");
    ui.horizontal(|ui| {
        for tool in Tool::ALL {
            if ui.selectable_label(state.lit_tool() == Some(tool), tool_label(tool)).clicked() {
                commands.push(AppCommand::SetTool(tool));
            }
        }
    });
    ui.horizontal(|ui| {
        let line = ui.selectable_label(state.mode == Mode::Line, "Line (L)");
        if line.on_hover_text("press, drag and release: the brush along a line").clicked() {
            commands.push(AppCommand::ToggleLine);
        }
        let select = ui.selectable_label(state.mode == Mode::Select, "Select (B)");
        let hint = "drag a box; drag a face of it to resize; Ctrl+C/X/V, Delete, arrows move it";
        if select.on_hover_text(hint).clicked() {
            commands.push(AppCommand::ToggleSelect);
        }
        let object = ui.selectable_label(state.mode == Mode::Object, "Object (Tab)");
        let hint = "click an object to pick it; drag it, or arrows and PageUp/PageDown, to move it; X/Y/Z turn it, Delete deletes it";
        if object.on_hover_text(hint).clicked() {
            commands.push(AppCommand::ToggleObject);
        }
    });
    // A change runs as a `brush` line.
    let mut brush = tools.brush;
    ui.label("Brush");
    ui.horizontal(|ui| {
        for (kind, label) in [(BrushKind::Voxel, "Voxel"), (BrushKind::Sphere, "Sphere"), (BrushKind::Box, "Box")] {
            if ui.selectable_label(BrushKind::of(tools.brush) == kind, label).clicked() {
                brush = state.brush_of(kind);
            }
        }
    });
    // One row whatever the brush, so nothing below it moves: the slider
    // shows the brush in force (a script may have set it) and remembers its
    // size for the next switch; a voxel has none.
    match &mut brush {
        Brush::Voxel => {
            ui.add_enabled(false, egui::Slider::new(&mut 1, 1..=1).text("size"));
        }
        Brush::Sphere(radius) => {
            ui.add(egui::Slider::new(radius, 0..=32).text("radius"));
            state.sphere_radius = *radius;
        }
        Brush::Box(size) => {
            let mut side = size.max_element();
            let uneven = size.min_element() != side;
            let tip = if uneven {
                format!("{} × {} × {} (a script's box)", size.x, size.y, size.z)
            } else {
                side.to_string()
            };
            if ui.add(egui::Slider::new(&mut side, 1..=64).text("size")).on_hover_text(tip).changed() || !uneven {
                *size = IVec3::splat(side);
            }
            state.box_size = side;
        }
    }
    ui.small("left: apply · Ctrl+drag a face: extrude · right-drag: orbit · right-click: erase (Attach) · middle: pan · wheel: zoom · WASDQE + right: fly · F: frame");
    if brush != tools.brush {
        commands.push(AppCommand::Lines(vec![octovox::script::Line::Brush(brush)]));
    }
}

fn palette(ui: &mut egui::Ui, tools: &Tools, palette: &Palette, out: &mut Vec<AppCommand>) {
    use octovox::script::{Line, PaletteLine};
    ui.heading("Palette");
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("palette presets").selected_text("Preset").width(90.0).show_ui(ui, |ui| {
            for (name, _) in octovox::io::palette_file::PRESETS {
                if ui.selectable_label(false, name).on_hover_text(format!("palette preset {name}")).clicked() {
                    out.push(AppCommand::Lines(vec![Line::Palette(PaletteLine::Preset(name.to_owned()))]));
                }
            }
        });
        if ui.button("Load…").on_hover_text("a MagicaVoxel .png, Lospec .hex or GIMP .gpl palette").clicked() {
            out.push(AppCommand::AskPalette { save: false });
        }
        if ui.button("Save…").on_hover_text("as .png (256×1), .hex or .gpl").clicked() {
            out.push(AppCommand::AskPalette { save: true });
        }
    });
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
    let selected = cell_rect(tools.color);
    painter.rect_stroke(selected, 0.0, Stroke::new(2.0, Color32::WHITE), egui::StrokeKind::Inside);
    let index_at = |pos: egui::Pos2| {
        let offset = (pos - rect.min) / cell;
        let (column, row) = (offset.x.floor() as i32, offset.y.floor() as i32);
        ((0..16).contains(&column) && (0..16).contains(&row)).then(|| (row * 16 + column) as u8)
    };
    if response.clicked()
        && let Some(index) = response.interact_pointer_pos().and_then(index_at).filter(|i| *i != 0)
    {
        out.push(AppCommand::Lines(vec![Line::Color(index)]));
    }
    if let Some(index) = response.hover_pos().and_then(index_at) {
        response.on_hover_text(format!("{index}"));
    }
    let material = palette.material(tools.color);
    let [r, g, b, _] = palette.color(tools.color);
    // One line whatever the entry holds (its parameters are the sliders
    // below, their MATL keys in the sliders' tooltips).
    ui.label(format!(
        "colour {} · #{r:02x}{g:02x}{b:02x} · {}",
        tools.color,
        material.kind.vox_name().trim_start_matches('_')
    ));
}

/// The selected entry's colour, material kind and the parameters the path
/// tracer reads; every change is an edit (undoable, saved in RGBA/MATL).
fn material_editor(ui: &mut egui::Ui, index: u8, palette: &Palette, out: &mut Vec<AppCommand>) {
    let [r, g, b, _] = palette.color(index);
    let mut rgb = [r, g, b];
    let old = palette.material(index);
    let mut material = old.clone();
    let mut changed = false;
    ui.horizontal(|ui| {
        // A palette colour is opaque: RGB and hex, no alpha or blending.
        changed |= ui.color_edit_button_srgb(&mut rgb).on_hover_text("rgb INDEX R G B").changed();
        changed |= hex_field(ui, index, &mut rgb);
        egui::ComboBox::from_id_salt("material kind")
            .width(70.0)
            .selected_text(material.kind.vox_name().trim_start_matches('_'))
            .show_ui(ui, |ui| {
                for kind in MaterialKind::ALL {
                    let label = kind.vox_name().trim_start_matches('_');
                    if ui.selectable_label(material.kind == kind, label).clicked() && material.kind != kind {
                        material = material.switched_to(kind);
                        changed = true;
                    }
                }
            });
    });
    // Three rows whatever the kind, so the panel below does not move: the
    // rows a kind does not use are disabled.
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
    for row in 0..MATERIAL_ROWS {
        let Some((key, label, range)) = sliders.get(row) else {
            ui.add_enabled(false, egui::Slider::new(&mut 0.0, 0.0..=1.0).show_value(false).text("—"));
            continue;
        };
        let mut value = material_value(&material, key);
        let slider = egui::Slider::new(&mut value, range.clone()).text(*label);
        if ui.add(slider).on_hover_text(format!("MATL key {key}")).changed() {
            material.params.insert((*key).to_string(), format!("{value:.3}"));
            if *key == "_ri" {
                // MagicaVoxel writes the index minus one as `_ior` beside `_ri`.
                material.params.insert("_ior".to_string(), format!("{:.3}", value - 1.0));
            }
            changed = true;
        }
    }
    if changed {
        let color = [rgb[0], rgb[1], rgb[2], 255];
        let edit = octovox::edit::Edit::Palette { index, color, material: Box::new(material) };
        let dragging = ui.ctx().input(|i| i.pointer.any_down());
        out.push(AppCommand::EditPalette { edit, dragging });
    }
}

/// Slider rows the material editor always shows (glass uses all three).
const MATERIAL_ROWS: usize = 3;

/// A `#rrggbb` field for the entry's colour: what is typed counts once it
/// parses (on Enter or when the field loses focus). Whether it changed `rgb`.
fn hex_field(ui: &mut egui::Ui, index: u8, rgb: &mut [u8; 3]) -> bool {
    let id = egui::Id::unique(("palette hex", index));
    let shown = format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
    let mut text = ui.data_mut(|d| d.get_temp::<String>(id)).unwrap_or_else(|| shown.clone());
    let field = ui.add(egui::TextEdit::singleline(&mut text).desired_width(72.0)).on_hover_text("hex RRGGBB");
    if field.has_focus() {
        ui.data_mut(|d| d.insert_temp(id, text.clone()));
    } else {
        ui.data_mut(|d| d.remove::<String>(id));
    }
    if field.lost_focus()
        && let Some(parsed) = octovox::io::palette_file::parse_hex(text.trim())
    {
        let changed = parsed != *rgb;
        *rgb = parsed;
        return changed;
    }
    false
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

fn render(ui: &mut egui::Ui, state: &mut EditorState, stats: &Stats) {
    let settings = &mut state.settings;
    egui::ComboBox::from_id_salt("view").selected_text(format!("{:?}", settings.view)).show_ui(ui, |ui| {
        for view in View::ALL {
            ui.selectable_value(&mut settings.view, view, format!("{view:?}"));
        }
    });
    ui.horizontal(|ui| {
        ui.label("Tracer").on_hover_text("--mode");
        ui.radio_value(&mut settings.mode, TraceMode::Svo, "octree");
        ui.radio_value(&mut settings.mode, TraceMode::Grid, "grid (DDA)");
    });
    ui.checkbox(&mut settings.shadows, "Sun shadows").on_hover_text("--no-shadows turns them off");
    // Plain labels; the command-line flag (the name `bench quality` uses)
    // in each tooltip. Shorter sliders leave the panel room for them.
    ui.spacing_mut().slider_width = 64.0;
    ui.add(egui::Slider::new(&mut settings.render_scale, 0.25..=1.0).text("Render scale"))
        .on_hover_text("--render-scale: the fraction of the window's pixels traced per axis");
    ui.add(egui::Slider::new(&mut settings.lod, 0.0..=16.0).step_by(0.5).text("Detail (px)")).on_hover_text(
        "--lod, level of detail: the preview stops at octree cells narrower than this many pixels \
         and draws them as one solid cell (0 = exact; the path tracer is always exact)",
    );
    ui.add(egui::Slider::new(&mut state.frame_target_ms, 10.0..=100.0).text("Frame (ms)")).on_hover_text(
        "frame target: the frame time to hold while the camera moves (the render scale drops as far as needed)",
    );
    path_tracing(ui, state, stats);
}

/// Presets from draft to reference, with what each costs here and the error
/// it buys once measured.
fn quality(ui: &mut egui::Ui, measured: Option<&[super::presets::Measured]>, out: &mut Vec<AppCommand>) {
    ui.horizontal(|ui| {
        ui.label("Quality");
        if ui.button("Measure").on_hover_text("time and error (FLIP) of each preset from this camera").clicked() {
            out.push(AppCommand::MeasurePresets);
        }
    });
    egui::Grid::new("presets").num_columns(3).show(ui, |ui| {
        ui.label("");
        ui.label("ms");
        ui.label("FLIP").on_hover_text("the error against the reference preset, from this camera");
        ui.end_row();
        for (i, preset) in super::presets::PRESETS.iter().enumerate() {
            if ui.small_button(preset.name).clicked() {
                out.push(AppCommand::ApplyPreset(i));
            }
            match measured.and_then(|m| m.get(i)) {
                Some(m) => {
                    ui.label(format!("{:.0}", m.ms));
                    ui.label(format!("{:.3}", m.flip));
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

fn path_tracing(ui: &mut egui::Ui, state: &mut EditorState, stats: &Stats) {
    egui::ComboBox::from_id_salt("shading").selected_text(state.shading.label()).show_ui(ui, |ui| {
        for shading in Shading::ALL {
            ui.selectable_value(&mut state.shading, shading, shading.label());
        }
    });
    // Disabled, not removed, in preview shading: the rows below stay put.
    ui.add_enabled_ui(state.shading != Shading::Preview, |ui| {
        path_knobs(ui, state);
        ui.checkbox(&mut state.denoise, "Denoise").on_hover_text(
            "--denoise: the accumulation filtered by its first hits (colour, face, depth) \
             and its variance; off: the raw samples",
        );
        // Two lines' room whatever the text says, so nothing below moves
        // when it changes (issue 47, item 2: a wrapped line pushed the
        // preset buttons down 15 px under the pointer).
        let height = 2.0 * ui.text_style_height(&egui::TextStyle::Body) + ui.spacing().item_spacing.y;
        let (rect, _) = ui.allocate_exact_size(egui::vec2(ui.available_width(), height), Sense::hover());
        ui.scope_builder(egui::UiBuilder::new().max_rect(rect), |ui| {
            ui.add(egui::Label::new(noise_text(stats, state.sample_target)).wrap()).on_hover_text(
                "the raw samples' estimated noise: the RMS standard error of the displayed pixels \
                 (render --target-error stops on it)",
            );
        });
    });
}

/// The noise line of the Render panel: "≈ 1.8 % noise, ~4 s to 1 %".
pub fn noise_text(stats: &Stats, sample_target: u32) -> String {
    const GOAL: f32 = 0.01;
    let (Some(path), Some(noise)) = (stats.path, stats.noise) else {
        return "noise: measured from the second sample".into();
    };
    let percent = format!("≈ {:.1} % noise", 100.0 * noise);
    if noise <= GOAL {
        return format!("{percent}, below 1 %");
    }
    // The standard error falls as 1/√samples.
    let needed = (path.samples as f32 * (noise / GOAL).powi(2)).ceil() as u32;
    if needed > sample_target {
        return format!("{percent}; 1 % needs ~{needed} samples (target {sample_target})");
    }
    let seconds = f64::from(needed - path.samples) * stats.trace_ms / 1e3;
    format!("{percent}, ~{seconds:.0} s to 1 %")
}

fn path_knobs(ui: &mut egui::Ui, state: &mut EditorState) {
    let path = &mut state.path_settings;
    ui.add(egui::Slider::new(&mut path.bounces, 0..=16).text("Bounces")).on_hover_text("--bounces");
    ui.add(egui::Slider::new(&mut path.shadow_samples, 1..=16).text("Shadow rays"))
        .on_hover_text("--shadow-samples: shadow rays toward the sun and the emitters per hit");
    ui.add(egui::Slider::new(&mut state.sample_target, 1..=4096).logarithmic(true).text("Samples/px"))
        .on_hover_text("--spp: samples per pixel; the path tracer stops there while the camera rests");
    ui.horizontal(|ui| {
        ui.checkbox(&mut path.sun, "Sun");
        egui::ComboBox::from_id_salt("sky").selected_text(format!("sky: {:?}", path.sky)).show_ui(ui, |ui| {
            for sky in [Sky::Gradient, Sky::White, Sky::Black] {
                ui.selectable_value(&mut path.sky, sky, format!("{sky:?}"));
            }
        });
    });
    ui.horizontal(|ui| {
        ui.radio_value(&mut path.effects, EffectsChoice::Auto, "effects: the scene's")
            .on_hover_text("--effects auto: the kernel compiled for the effects the scene holds");
        ui.radio_value(&mut path.effects, EffectsChoice::All, "all").on_hover_text("--effects all");
    });
}

fn stats(ui: &mut egui::Ui, info: &Info) {
    let s = info.stats;
    let tree = info.scene.drawn();
    let pool = tree.pool();
    let trace = if info.timestamps { "GPU" } else { "wall" };
    // Two columns that share the panel: a long value wraps in its own.
    let column = (ui.available_width() - ui.spacing().item_spacing.x) / 2.0;
    egui::Grid::new("stats").num_columns(2).max_col_width(column).show(ui, |ui| {
        // Values wrap within the panel rather than run past its edge.
        let mut row = |name: &str, value: String| {
            ui.label(name);
            ui.add(egui::Label::new(value).wrap());
            ui.end_row();
        };
        row("fps", format!("{:.1}", s.fps));
        row("frame", format!("{:.2} ms", s.frame_ms));
        row("trace", format!("{:.2} ms ({trace})", s.trace_ms));
        row("present", format!("{:.2} ms", s.present_ms));
        row("  acq · draw · sub", format!("{:.1} · {:.1} · {:.1} ms", s.acquire_ms, s.draw_ms, s.submit_ms));
        row("panels", format!("{:.2} ms", s.panels_ms));
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
        match s.last_edit_bytes {
            Some(bytes) => row("last edit", format!("{bytes} bytes, {} ranges", s.last_edit_ranges)),
            None => row("last edit", "none".to_string()),
        }
        row("uploaded", format!("{} bytes total", pool.stats.total_bytes));
        let (steps, bytes, limit) = info.history;
        let human = |b: usize| octovox::budget::human(b as u64);
        row("undo", format!("{steps} steps, {} of {} (oldest dropped past it)", human(bytes), human(limit)));
        row("adapter", info.adapter.to_string());
    });
}

/// The last message (errors in red), on the menu bar where it is always seen.
fn message(ui: &mut egui::Ui, ui_state: &mut UiState) {
    if let Some(warning) = &ui_state.journal_warning {
        ui.separator();
        ui.colored_label(Color32::from_rgb(255, 170, 60), format!("⚠ {warning}"));
    }
    let mut clear = false;
    if let Some((text, is_error, left)) = ui_state.current_message(web_time::Instant::now()) {
        ui.separator();
        let color = if is_error { Color32::from_rgb(255, 110, 100) } else { Color32::LIGHT_GREEN };
        ui.colored_label(color, text);
        clear = ui.small_button("×").on_hover_text("dismiss").clicked();
        if !is_error {
            // A frame when it goes, though nothing else moves.
            ui.ctx().request_repaint_after(left);
        }
    }
    if clear {
        ui_state.message = None;
    }
}

fn dialog(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<AppCommand>) {
    let Some(browser) = &mut ui_state.dialog else { return };
    match browser.show(ctx) {
        Answer::Waiting => return,
        Answer::Chosen(path) => out.push(browser.kind().command(path)),
        Answer::Cancelled => {}
    }
    ui_state.dialog = None;
}

fn prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<AppCommand>) {
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
                out.push(AppCommand::Resolve(Choice::Save));
            }
            if ui.button("Discard").clicked() {
                out.push(AppCommand::Resolve(Choice::Discard));
            }
            if ui.button("Cancel").clicked() {
                out.push(AppCommand::Resolve(Choice::Cancel));
            }
        });
    });
}

/// Offers to apply a crash-recovery journal found beside the document;
/// one started on other content than the document holds now is offered
/// only with that said, as "Apply anyway".
fn recover_prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<AppCommand>) {
    let Some((journal, doubt)) = ui_state.recover.clone() else { return };
    egui::Modal::new(egui::Id::unique("recover")).show(ctx, |ui| {
        ui.heading("Recover unsaved edits?");
        ui.label(format!("A session that ended without saving left its edits in {}. Apply them?", journal.display()));
        if let Some(doubt) = &doubt {
            ui.colored_label(Color32::from_rgb(255, 110, 100), doubt);
        }
        ui.horizontal(|ui| {
            let apply = if doubt.is_some() { "Apply anyway" } else { "Recover" };
            // Enter recovers (where no doubt was raised): the default answer.
            let enter = doubt.is_none() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui.button(format!("{apply}{}", if doubt.is_none() { " (Enter)" } else { "" })).clicked() || enter {
                ui_state.recover = None;
                let checks = octovox::journal::Checks { allow_changed_source: doubt.is_some() };
                out.push(AppCommand::RecoverJournal(journal.clone(), checks));
            }
            if ui.button("Discard").clicked() {
                ui_state.recover = None;
                out.push(AppCommand::DiscardJournal(journal.clone()));
            }
        });
    });
}

/// Asks before a save replaces a read-only file.
fn replace_prompt(ctx: &egui::Context, ui_state: &mut UiState, out: &mut Vec<AppCommand>) {
    let Some(Replace { path, read_only }) = ui_state.replace.clone() else { return };
    let modal = egui::Modal::new(egui::Id::unique("replace")).show(ctx, |ui| {
        ui.heading(if read_only { "Read-only file" } else { "Replace the file?" });
        let what = if read_only { "is read-only" } else { "already exists" };
        ui.label(format!("{} {what}. Replace it?", path.display()));
        ui.horizontal(|ui| {
            if ui.button("Replace").clicked() {
                ui_state.replace = None;
                out.push(AppCommand::SaveOver(path.clone()));
            }
            if ui.button("Cancel").clicked() {
                ui_state.replace = None;
                // What waited for the save (a Quit, an Open) waits no more.
                ui_state.pending = None;
            }
        });
    });
    // Escape or a click outside cancels, as Cancel does.
    if modal.should_close() {
        ui_state.replace = None;
        ui_state.pending = None;
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

/// The layer of everything drawn over the scene (outlines, previews, hints).
fn scene_layer() -> egui::LayerId {
    egui::LayerId::new(egui::Order::Background, egui::Id::unique("scene overlays"))
}

fn scene_painter(ctx: &egui::Context) -> egui::Painter {
    ctx.layer_painter(scene_layer())
}

/// Takes this frame's scene overlays out of egui's output, at the end of the
/// frame's UI pass: they move with the camera, so the window draws them on
/// every frame under the panels, which it keeps while they do not change
/// (`EguiLayers`).
pub fn take_scene_overlays(ctx: &egui::Context) -> Vec<egui::epaint::ClippedShape> {
    ctx.graphics_mut(|layers| {
        let Some(list) = layers.get_mut(scene_layer()) else { return Vec::new() };
        let shapes: Vec<_> = list.all_entries().cloned().collect();
        // A paint list cannot be emptied from outside; no-ops tessellate to nothing.
        for i in 0..shapes.len() {
            list.reset_shape(egui::layers::ShapeIdx(i));
        }
        shapes
    })
}

/// Outlines the cells the brush would touch (projected with the trace
/// camera), so the preview also shows Attach's target cells, which are empty
/// and so cannot be tinted by the shader.
pub fn draw_brush_outline(ui: &egui::Ui, state: &EditorState, tools: &Tools, pick: &Pick, info: &Info) {
    use octovox::scene::Shape;
    let (lo, hi) = state.preview_box(tools, pick, info.line_start);
    let color = match state.tool {
        Tool::Attach => egui::Color32::from_rgb(120, 255, 140),
        Tool::Erase => egui::Color32::from_rgb(255, 100, 90),
        Tool::Paint => egui::Color32::from_rgb(255, 220, 90),
    };
    // A sphere is outlined as a sphere, a box (or a line's span) as a box.
    let shape = state.preview_shape(tools, pick, info.line_start).unwrap_or(Shape::Box { min: lo, max: hi });
    // With mirror planes on, where the images of the edit land too.
    let brush = octovox::edit::Edit::Brush { shape, op: octovox::scene::Op::Remove };
    for image in tools.mirror.edits(brush) {
        match image {
            octovox::edit::Edit::Brush { shape: Shape::Sphere { center, radius }, .. } => {
                outline_sphere(ui, state, info, center, radius, color);
            }
            octovox::edit::Edit::Brush { shape, .. } => outline_box(ui, state, info, shape.bounds(), color, false),
            _ => {}
        }
    }
}

/// The silhouette of the sphere of cells within `radius` of `center`'s
/// centre: a circle about it, facing the camera, and its equator.
fn outline_sphere(ui: &egui::Ui, state: &EditorState, info: &Info, center: IVec3, radius: i32, color: Color32) {
    let screen = ui.ctx().content_rect();
    let basis =
        state.camera.basis(screen.width().max(1.0) as u32, screen.height().max(1.0) as u32, info.scene.origin());
    let middle = (center - info.scene.origin()).as_vec3() + Vec3::splat(0.5);
    let (_, right, up) = state.camera.axes();
    let r = radius as f32 + 0.5;
    let ring = |a: Vec3, b: Vec3| -> Option<Vec<egui::Pos2>> {
        (0..=48)
            .map(|i| {
                let angle = i as f32 / 48.0 * std::f32::consts::TAU;
                let p = middle + (a * angle.cos() + b * angle.sin()) * r;
                basis.project(p).map(|(x, y)| egui::pos2(x, y))
            })
            .collect()
    };
    let painter = scene_painter(ui.ctx());
    if let Some(points) = ring(right.as_vec3(), up.as_vec3()) {
        painter.add(egui::Shape::line(points, Stroke::new(1.5, color)));
    }
    if let Some(points) = ring(Vec3::X, Vec3::Z) {
        painter.add(egui::Shape::line(points, Stroke::new(1.0, color.gamma_multiply(0.6))));
    }
}

/// The fill, paste and eyedropper previews: an outline where the action
/// lands, and a line of text beside the cursor saying what it does.
pub fn draw_action_previews(ui: &egui::Ui, state: &EditorState, info: &Info) {
    let yellow = Color32::from_rgb(255, 220, 90);
    let (hint, swatch) = match (info.fill, info.paste, info.eyedropper) {
        (Some(Some((bounds, voxels))), _, _) => {
            outline_box(ui, state, info, bounds, yellow, false);
            (format!("fill: {voxels} voxels"), None)
        }
        (Some(None), _, _) => ("fill: the region is too large".to_string(), None),
        (_, Some(region), _) => {
            outline_box(ui, state, info, (region.min, region.max), Color32::from_rgb(255, 160, 60), false);
            ("Ctrl+V pastes here".to_string(), None)
        }
        (_, _, Some(index)) => (format!("pick colour {index}"), Some(rgba(info.palette, index))),
        _ => return,
    };
    let Some(at) = ui.ctx().pointer_hover_pos() else { return };
    let painter = scene_painter(ui.ctx());
    let mut text_at = at + Vec2::new(16.0, 12.0);
    if let Some(color) = swatch {
        painter.rect_filled(egui::Rect::from_min_size(text_at, Vec2::splat(14.0)), 2.0, color);
        text_at.x += 18.0;
    }
    painter.text(text_at, egui::Align2::LEFT_TOP, hint, egui::FontId::proportional(13.0), Color32::WHITE);
}

/// Most faces the extrude preview draws (a larger region shows its first ones).
const MAX_PREVIEW_FACES: usize = 20_000;

/// The faces an extrude would move, drawn where the drag puts them:
/// `layers` voxels out along `normal` (in, when negative; green out, red in).
pub fn draw_extrude(ui: &egui::Ui, state: &EditorState, info: &Info, voxels: &[IVec3], normal: IVec3, layers: i32) {
    let screen = ui.ctx().content_rect();
    let basis =
        state.camera.basis(screen.width().max(1.0) as u32, screen.height().max(1.0) as u32, info.scene.origin());
    let origin = info.scene.origin().as_vec3();
    let n = normal.as_vec3();
    // The two axes of the face's plane, half a voxel each.
    let (u, v) = match normal.abs() {
        IVec3 { x: 1, .. } => (Vec3::Y * 0.5, Vec3::Z * 0.5),
        IVec3 { y: 1, .. } => (Vec3::Z * 0.5, Vec3::X * 0.5),
        _ => (Vec3::X * 0.5, Vec3::Y * 0.5),
    };
    let color = if layers < 0 { Color32::from_rgb(255, 100, 90) } else { Color32::from_rgb(120, 255, 140) };
    let painter = scene_painter(ui.ctx());
    for voxel in voxels.iter().take(MAX_PREVIEW_FACES) {
        let center = voxel.as_vec3() - origin + Vec3::splat(0.5) + n * (0.5 + layers as f32);
        let corners = [center - u - v, center + u - v, center + u + v, center - u + v];
        let points: Option<Vec<egui::Pos2>> =
            corners.iter().map(|c| basis.project(*c).map(|(x, y)| egui::pos2(x, y))).collect();
        if let Some(points) = points {
            painter.add(egui::Shape::convex_polygon(points, color.gamma_multiply(0.35), Stroke::new(1.0, color)));
        }
    }
}

/// The working volume's outline over the image: where a first click in an
/// empty scene builds. (The ground's grid is traced with the voxels,
/// `EditorState::ground_grid`, so that they hide it.)
pub fn draw_ground(ui: &egui::Ui, state: &EditorState, info: &Info) {
    if !info.ground {
        return;
    }
    outline_box(ui, state, info, state.working_volume(), Color32::from_white_alpha(40), false);
}

/// Outlines the selected box (or the one being dragged); in select mode
/// with a dot on each face, the handle that resizes it. In object mode the
/// ring around the picked object, which turns it about `ring_axis`.
pub fn draw_selection(ui: &egui::Ui, state: &EditorState, info: &Info, ring_axis: usize) {
    if let Some(objects) = info.objects
        && let Some(bounds) = objects.selected.and_then(|i| objects.world_box(i))
    {
        outline_box(ui, state, info, bounds, super::outliner::PICKED, false);
        if state.mode == Mode::Object {
            draw_ring(ui, state, info, bounds, ring_axis);
        }
    }
    if let Some(region) = info.selection {
        outline_box(
            ui,
            state,
            info,
            (region.min, region.max),
            egui::Color32::from_rgb(90, 220, 255),
            state.mode == Mode::Select,
        );
    }
}

/// Object mode: the rotation ring around the picked object's box, which a
/// drag turns about world axis `axis` (`Session::ring`, the same circle in
/// window pixels), named at its top.
fn draw_ring(ui: &egui::Ui, state: &EditorState, info: &Info, (lo, hi): (IVec3, IVec3), axis: usize) {
    let screen = ui.ctx().content_rect();
    let basis =
        state.camera.basis(screen.width().max(1.0) as u32, screen.height().max(1.0) as u32, info.scene.origin());
    let origin = info.scene.origin();
    if let Some((centre, radius)) = super::drag::ring(&basis, lo - origin, hi - origin, 1.0) {
        let centre = egui::pos2(centre.x as f32, centre.y as f32);
        let color = super::outliner::PICKED.gamma_multiply(0.8);
        let painter = scene_painter(ui.ctx());
        painter.circle_stroke(centre, radius as f32, Stroke::new(2.0, color));
        let top = centre - egui::vec2(0.0, radius as f32 + 4.0);
        let name = ["about x", "about y", "about z"][axis];
        let font = egui::FontId::proportional(14.0);
        painter.text(top, egui::Align2::CENTER_BOTTOM, name, font, super::outliner::PICKED);
    }
}

/// Draws the edges of the cells `lo..=hi` over the image, and the centres
/// of its faces when `handles`.
fn outline_box(
    ui: &egui::Ui,
    state: &EditorState,
    info: &Info,
    (lo, hi): (IVec3, IVec3),
    color: Color32,
    handles: bool,
) {
    let screen = ui.ctx().content_rect();
    let (w, h) = (screen.width().max(1.0), screen.height().max(1.0));
    let basis = state.camera.basis(w as u32, h as u32, info.scene.origin());
    let origin = info.scene.origin().as_vec3();
    let project = |p: Vec3| basis.project(p - origin).map(|(x, y)| egui::pos2(x, y));
    let (a, b) = (lo.as_vec3(), (hi + IVec3::ONE).as_vec3());
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { a.x } else { b.x },
            if i & 2 == 0 { a.y } else { b.y },
            if i & 4 == 0 { a.z } else { b.z },
        )
    };
    let painter = scene_painter(ui.ctx());
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
    if handles {
        let center = (a + b) * 0.5;
        for normal in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
            if let Some(p) = project(center + normal * (b - a) * 0.5) {
                painter.circle_filled(p, 4.0, color);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;
    use web_time::Instant;

    /// Issue 27, bug 4: "saved …" and "copied 6 voxels" stayed on screen
    /// long after they described anything.
    #[test]
    fn info_messages_go_with_time_or_the_next_change_and_errors_stay() {
        let mut ui = UiState::default();
        let now = Instant::now();
        ui.info("saved a.vox");
        assert_eq!(ui.current_message(now).map(|m| m.0), Some("saved a.vox"));
        assert!(ui.current_message(now + INFO_LIFETIME + Duration::from_millis(1)).is_none(), "gone after its time");
        ui.info("copied 6 voxels");
        ui.change_made();
        assert!(ui.current_message(now).is_none(), "gone at the next change");
        ui.error("save failed: disk full");
        ui.change_made();
        let later = now + INFO_LIFETIME * 10;
        assert_eq!(ui.current_message(later).map(|m| (m.0, m.1)), Some(("save failed: disk full", true)));
    }
}
