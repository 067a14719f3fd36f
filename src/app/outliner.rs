//! The panel on the right of a scene of objects: the Outliner (the tree of
//! groups and objects, in walk order) and the Layers panel. Everything a
//! row does is an `object` or `layer` script line, so it is an undo step,
//! journaled and recorded like the same line typed in a script.

use std::collections::HashSet;

use egui::{Color32, Sense, Stroke};

use octovox::scene::graph::OutlineRow;
use octovox::scene::objects::Objects;
use octovox::script::{LayerLine, Line, ObjectLine, ObjectRef};

use super::command::AppCommand;

/// Width of the right panel in points.
pub const OUTLINER_WIDTH: f32 = 280.0;

/// The picked object's colour: its box in the view, the Outliner's drop line.
pub const PICKED: Color32 = Color32::from_rgb(255, 190, 60);

/// Most rows the Outliner lists (a scene may place 10⁵ objects).
const MAX_ROWS: usize = 500;

/// Indentation of one group level, and the deepest level indented (a
/// scene may nest 10⁵ groups).
const INDENT: f32 = 12.0;
const MAX_INDENT_LEVELS: u32 = 8;

/// What the panel remembers between frames.
#[derive(Debug, Default)]
pub struct OutlinerState {
    /// The name field: the object it was filled from, and the text (Enter
    /// renames the object to it).
    pub rename: (Option<usize>, String),
    /// The objects marked with + to merge into the picked one.
    pub merge: Vec<usize>,
    /// A layer colour being picked: set when the pointer lets go (one
    /// `layer N color` line, one undo step, per pick).
    pub layer_color: Option<(u32, [u8; 3])>,
    /// A layer being renamed (a double click on its name) and the text.
    pub layer_name: Option<(u32, String)>,
    /// Groups folded shut, by their transform node.
    pub collapsed: HashSet<u32>,
    /// The object whose row is being dragged.
    pub dragging: Option<usize>,
    pub turn: TurnInput,
}

/// The Turn row: an axis (0, 1, 2 = x, y, z) and an angle in degrees.
#[derive(Debug)]
pub struct TurnInput {
    pub axis: usize,
    pub degrees: f64,
}

impl Default for TurnInput {
    fn default() -> TurnInput {
        TurnInput { axis: 1, degrees: 15.0 }
    }
}

/// Draws the panel; what the user asked for goes to `out`.
pub fn show(ui: &mut egui::Ui, objects: &Objects, state: &mut OutlinerState, out: &mut Vec<AppCommand>) {
    egui::Panel::right("outliner").resizable(false).exact_size(OUTLINER_WIDTH).show(ui, |ui| {
        egui::ScrollArea::vertical().id_salt("scene panel").show(ui, |ui| {
            let models = objects.models.len();
            ui.strong(format!("Outliner ({} objects, {models} models)", objects.list().len()));
            rename_row(ui, objects, &mut state.rename, out);
            merge_row(ui, objects, &mut state.merge, out);
            ui.separator();
            egui::ScrollArea::vertical().id_salt("outliner").max_height(360.0).show(ui, |ui| {
                tree(ui, objects, state, out);
            });
            ui.separator();
            layers(ui, objects, state, out);
            ui.separator();
            turn_row(ui, objects, &mut state.turn, out);
        });
    });
}

/// The rows of groups and objects; a group's arrow folds it, an object's
/// name dragged onto another object's row puts it before or after that one
/// (`object before|after N`), in that one's group.
fn tree(ui: &mut egui::Ui, objects: &Objects, state: &mut OutlinerState, out: &mut Vec<AppCommand>) {
    let list = objects.list();
    state.merge.retain(|&i| i < list.len() && objects.selected != Some(i));
    state.dragging = state.dragging.filter(|&i| i < list.len());
    // Object rows drawn, where, for a drop.
    let mut targets: Vec<(usize, egui::Rect)> = Vec::new();
    let mut folded_below: Option<u32> = None;
    let mut rows = 0;
    for row in objects.outline() {
        let depth = match row {
            OutlineRow::Group { depth, .. } | OutlineRow::Object { depth, .. } => *depth,
        };
        if folded_below.is_some_and(|d| depth > d) {
            continue;
        }
        folded_below = None;
        if rows == MAX_ROWS {
            ui.label(format!("… and more ({} objects; object N picks any)", list.len()));
            break;
        }
        rows += 1;
        match row {
            OutlineRow::Group { transform, hidden, .. } => {
                let name = objects.group_name(*transform);
                let open = !state.collapsed.contains(transform);
                ui.horizontal(|ui| {
                    indent(ui, depth);
                    let arrow = ui.add(egui::Button::new(if open { "⏷" } else { "⏵" }).frame(false));
                    if arrow.on_hover_text(if open { "fold" } else { "unfold" }).clicked()
                        && !state.collapsed.remove(transform)
                    {
                        state.collapsed.insert(*transform);
                    }
                    let text = if name.is_empty() { "(group)" } else { name };
                    let text = egui::RichText::new(text).strong();
                    ui.label(if *hidden { text.weak() } else { text });
                });
                if !open {
                    folded_below = Some(depth);
                }
            }
            OutlineRow::Object { index, .. } => {
                let rect = ui
                    .horizontal(|ui| {
                        indent(ui, depth);
                        object_row(ui, objects, *index, state, out);
                    })
                    .response
                    .rect;
                targets.push((*index, rect));
            }
        }
    }
    drop_target(ui, &targets, state, out);
}

fn indent(ui: &mut egui::Ui, depth: u32) {
    ui.add_space(INDENT * depth.min(MAX_INDENT_LEVELS) as f32);
}

/// One object's row: the eye, the lock, the merge mark, and the name that
/// picks the object when clicked and moves it when dragged.
fn object_row(
    ui: &mut egui::Ui,
    objects: &Objects,
    index: usize,
    state: &mut OutlinerState,
    out: &mut Vec<AppCommand>,
) {
    let object = &objects.list()[index];
    let pick = Line::Object(ObjectLine::Pick(ObjectRef::Index(index)));
    let mut shown = !object.own_hidden;
    if ui.checkbox(&mut shown, "").on_hover_text("show or hide").changed() {
        out.push(AppCommand::Lines(vec![pick.clone(), Line::Object(ObjectLine::Hide(!shown))]));
    }
    let mut locked = objects.locked(index);
    let icon = if locked { "🔒" } else { "🔓" };
    let lock = ui.toggle_value(&mut locked, icon);
    if lock.on_hover_text("lock: no edits, moves or picks by a click").changed() {
        out.push(AppCommand::Lines(vec![pick.clone(), Line::Object(ObjectLine::Lock(locked))]));
    }
    layer_choice(ui, objects, index, &pick, out);
    let marked = state.merge.contains(&index);
    let can_mark = objects.selected.is_some_and(|p| p != index);
    let mark = ui.add_enabled(can_mark, egui::Button::new(if marked { "−" } else { "+" }).small());
    if mark.on_hover_text("mark to merge into the picked object").clicked() {
        toggle(&mut state.merge, index);
    }
    let own = objects.transform_node(index).ok().and_then(octovox::scene::graph::Node::name);
    let name = own.unwrap_or("(unnamed)");
    let label = format!("{index} {name}");
    let text = if object.hidden { egui::RichText::new(label).weak() } else { egui::RichText::new(label) };
    let text = if marked { text.underline() } else { text };
    let row = ui.selectable_label(objects.selected == Some(index), text).interact(Sense::drag());
    let path = objects.path(index);
    let path = if path.is_empty() { "(unnamed)" } else { &path };
    let row = row.on_hover_text(format!("{path} · model {} · drag to move it", object.placement.model));
    if row.clicked() {
        out.push(AppCommand::Lines(vec![pick]));
    }
    if row.drag_started() {
        state.dragging = Some(index);
    }
}

/// The layer an object is on, as MagicaVoxel's outliner shows it, and a
/// menu of the layers that puts it on another (`object layer N`): what a
/// layer's eye hides is then on screen.
fn layer_choice(ui: &mut egui::Ui, objects: &Objects, index: usize, pick: &Line, out: &mut Vec<AppCommand>) {
    let layers = objects.layer_list();
    if layers.is_empty() {
        return;
    }
    let current = objects.list()[index].layer;
    let label = current.map_or("L–".to_owned(), |id| format!("L{id}"));
    // A menu button as wide as its label, so the row keeps room for the name.
    let response = ui.menu_button(label, |ui| {
        for layer in layers {
            let name = layer.name();
            let id = layer.id.to_string();
            let text = if name.is_empty() || name == id { id } else { format!("{id} {name}") };
            if ui.selectable_label(current == Some(layer.id), text).clicked() && current != Some(layer.id) {
                out.push(AppCommand::Lines(vec![pick.clone(), Line::Object(ObjectLine::Layer(layer.id))]));
                ui.close();
            }
        }
    });
    let name = current.and_then(|id| layers.iter().find(|l| l.id == id)).map_or("none", |l| l.name());
    response.response.on_hover_text(format!("on layer {name}: its eye below hides it; click to move it"));
}

/// While a row is dragged, the line where it would go; when it is let go
/// over another object's row, the lines that move it there.
fn drop_target(
    ui: &mut egui::Ui,
    targets: &[(usize, egui::Rect)],
    state: &mut OutlinerState,
    out: &mut Vec<AppCommand>,
) {
    let Some(dragged) = state.dragging else { return };
    let (pointer, down) = ui.input(|i| (i.pointer.interact_pos(), i.pointer.any_down()));
    let over = pointer.and_then(|p| {
        targets.iter().find(|(_, r)| r.y_range().contains(p.y) && r.x_range().contains(p.x)).map(|&(i, r)| (i, r, p))
    });
    let place = over.filter(|&(i, ..)| i != dragged).map(|(i, r, p)| (i, r, p.y > r.center().y));
    if let Some((_, rect, after)) = place {
        let y = if after { rect.bottom() } else { rect.top() };
        let stroke = Stroke::new(2.0, PICKED);
        ui.painter().hline(rect.x_range(), y, stroke);
    }
    if down {
        return;
    }
    state.dragging = None;
    if let Some((target, _, after)) = place {
        out.push(AppCommand::Lines(vec![
            Line::Object(ObjectLine::Pick(ObjectRef::Index(dragged))),
            Line::Object(ObjectLine::Regroup(ObjectRef::Index(target), after)),
        ]));
    }
}

/// Puts `index` in `set`, or takes it out.
fn toggle(set: &mut Vec<usize>, index: usize) {
    match set.iter().position(|&i| i == index) {
        Some(at) => {
            set.remove(at);
        }
        None => set.push(index),
    }
}

/// Turns the picked object by a typed angle about a world axis (`object
/// turn x|y|z DEGREES`, one undo step): any angle, where X, Y and Z in the
/// view turn by quarters. Always there, disabled with no object picked.
fn turn_row(ui: &mut egui::Ui, objects: &Objects, turn: &mut TurnInput, out: &mut Vec<AppCommand>) {
    ui.horizontal(|ui| {
        ui.add_enabled_ui(objects.selected.is_some(), |ui| {
            let button =
                ui.button("Turn").on_hover_text("object turn x|y|z DEGREES: counter-clockwise, about the pivot");
            egui::ComboBox::from_id_salt("turn axis").width(36.0).selected_text(["x", "y", "z"][turn.axis]).show_ui(
                ui,
                |ui| {
                    for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
                        ui.selectable_value(&mut turn.axis, axis, name);
                    }
                },
            );
            ui.add(egui::DragValue::new(&mut turn.degrees).speed(1.0).range(-360.0..=360.0).suffix("°"));
            if let (true, Some(index)) = (button.clicked(), objects.selected) {
                out.push(AppCommand::Lines(vec![
                    Line::Object(ObjectLine::Pick(ObjectRef::Index(index))),
                    Line::Object(ObjectLine::Turn { axis: turn.axis, degrees: octovox::script::Degrees(turn.degrees) }),
                ]));
            }
        });
    });
}

/// The button that merges the objects marked with + into the picked one
/// (`object merge N…`, one undo step). Always there, so that the rows
/// below stay put.
fn merge_row(ui: &mut egui::Ui, objects: &Objects, merge: &mut Vec<usize>, out: &mut Vec<AppCommand>) {
    ui.horizontal(|ui| {
        let ready = objects.selected.is_some() && !merge.is_empty();
        let button = ui.add_enabled(ready, egui::Button::new(format!("Merge {} marked", merge.len())));
        if button.on_hover_text("+ marks objects to merge into the picked one").clicked() {
            let others = merge.drain(..).map(ObjectRef::Index).collect();
            out.push(AppCommand::Lines(vec![Line::Object(ObjectLine::Merge(others))]));
        }
        if ui.add_enabled(!merge.is_empty(), egui::Button::new("Clear")).clicked() {
            merge.clear();
        }
    });
}

/// The Layers panel: each layer's eye, colour, whether new objects go on
/// it, and its name.
fn layers(ui: &mut egui::Ui, objects: &Objects, state: &mut OutlinerState, out: &mut Vec<AppCommand>) {
    let picking = &mut state.layer_color;
    let layers = objects.layer_list();
    let Some(active) = objects.layer_for_new() else { return };
    ui.strong(format!("Layers ({})", layers.len()));
    for layer in layers {
        ui.horizontal(|ui| {
            let mut shown = !layer.hidden();
            if ui.checkbox(&mut shown, "").on_hover_text("show or hide").changed() {
                out.push(AppCommand::Lines(vec![Line::Layer(layer.id, LayerLine::Hide(!shown))]));
            }
            let mut color = picking.filter(|(id, _)| *id == layer.id).map_or(layer.color(), |(_, c)| c);
            if ui.color_edit_button_srgb(&mut color).on_hover_text("colour").changed() {
                *picking = Some((layer.id, color));
            }
            let new_here = ui.radio(active == layer.id, "").on_hover_text("new objects go on this layer");
            if new_here.clicked() && active != layer.id {
                out.push(AppCommand::Lines(vec![Line::Layer(layer.id, LayerLine::Active)]));
            }
            layer_name(ui, layer, &mut state.layer_name, out);
        });
    }
    // A pick is set once the pointer lets go, so a drag is one undo step.
    if let Some((id, color)) = *picking
        && !ui.input(|i| i.pointer.any_down())
    {
        *picking = None;
        let current = layers.iter().find(|l| l.id == id).map(|l| l.color());
        if current.is_some_and(|c| c != color) {
            out.push(AppCommand::Lines(vec![Line::Layer(id, LayerLine::Color(color))]));
        }
    }
}

/// A layer's name; a double click edits it, Enter renames the layer
/// (`layer N NAME`, one undo step), Escape or a click elsewhere keeps it.
fn layer_name(
    ui: &mut egui::Ui,
    layer: &octovox::scene::graph::Layer,
    editing: &mut Option<(u32, String)>,
    out: &mut Vec<AppCommand>,
) {
    if let Some((_, text)) = editing.as_mut().filter(|(id, _)| *id == layer.id) {
        let field = ui.add(egui::TextEdit::singleline(text).desired_width(110.0));
        if !field.has_focus() && !field.lost_focus() {
            field.request_focus();
        }
        if field.lost_focus() {
            let name = text.trim().to_owned();
            if ui.input(|i| i.key_pressed(egui::Key::Enter)) && !name.is_empty() && name != layer.name() {
                out.push(AppCommand::Lines(vec![Line::Layer(layer.id, LayerLine::Name(name))]));
            }
            *editing = None;
        }
        return;
    }
    let name = if layer.name().is_empty() { format!("layer {}", layer.id) } else { layer.name().to_owned() };
    let label = ui.add(egui::Label::new(name).sense(Sense::click()));
    if label.on_hover_text(format!("layer {} · double click to rename", layer.id)).double_clicked() {
        *editing = Some((layer.id, layer.name().to_owned()));
    }
}

/// The picked object's name, editable: Enter renames it (`object rename`,
/// an undo step). Always there, disabled with no object picked, so that
/// the rows below stay put.
fn rename_row(ui: &mut egui::Ui, objects: &Objects, rename: &mut (Option<usize>, String), out: &mut Vec<AppCommand>) {
    let picked = objects.selected;
    if rename.0 != picked {
        let own = picked.and_then(|i| objects.transform_node(i).ok()).and_then(octovox::scene::graph::Node::name);
        *rename = (picked, own.unwrap_or_default().to_owned());
    }
    ui.horizontal(|ui| {
        ui.label("Name");
        ui.add_enabled_ui(picked.is_some(), |ui| {
            let field = ui.add(egui::TextEdit::singleline(&mut rename.1).desired_width(150.0));
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if let (true, Some(index)) = (entered && !rename.1.trim().is_empty(), picked) {
                out.push(AppCommand::Lines(vec![
                    Line::Object(ObjectLine::Pick(ObjectRef::Index(index))),
                    Line::Object(ObjectLine::Rename(rename.1.trim().to_owned())),
                ]));
            }
            field.on_hover_text("object rename NAME (Enter)");
        });
    });
}
