//! The editor: the scene, its undo history, the tool state (brush, colour,
//! mirror planes), the box selection and the clipboard, and what every
//! script line that edits or reads them means. `octovox replay` and the
//! window both drive one `Editor`, so a line means one thing in both; what
//! a host does around it (files, cameras, pixels, the GPU) stays the host's.

use glam::IVec3;

use crate::edit::brush::Brush;
use crate::edit::mirror::Mirror;
use crate::edit::selection::{self, Block, Region};
use crate::edit::{Edit, History};
use crate::scene::objects::Objects;
use crate::scene::transform::CellMap;
use crate::scene::{EditError, Op, Palette, Scene};
use crate::script::{AnimLine, Line, ObjectLine, ObjectRef, PaletteLine};
use crate::settings::PathSettings;

/// Why a line could not run. A refused line changes nothing.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EditorError {
    #[error(transparent)]
    Edit(#[from] EditError),
    #[error("nothing is selected: select a box first")]
    NothingSelected,
    #[error("nothing to paste: copy or cut a selection first")]
    NothingToPaste,
    #[error("no voxel at {0} to pick a colour from")]
    NothingToPick(IVec3),
    #[error("nothing to {0}")]
    NoSteps(&'static str),
    #[error("only {available} step(s) to {what}, not {wanted}")]
    TooFewSteps { what: &'static str, available: usize, wanted: u32 },
    #[error("there is no palette preset '{0}'")]
    NoPreset(String),
    /// An `object` or `layer` line that names nothing, or more than one thing.
    #[error("{0}")]
    Object(String),
}

/// What brush edits use: the brush, the colour and the mirror planes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tools {
    pub brush: Brush,
    /// Palette index of Attach, Paint, lines and fills (1..=255).
    pub color: u8,
    pub mirror: Mirror,
}

impl Default for Tools {
    fn default() -> Tools {
        Tools { brush: Brush::Voxel, color: 1, mirror: Mirror::default() }
    }
}

/// What a line did, for the host to follow up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Tool state, selection or clipboard changed; the voxels did not.
    State,
    /// The voxels or the palette changed: the host flushes the pool.
    Changed,
    /// A new scene is in place: the host uploads it whole.
    Replaced,
    /// An expectation: whether it held, what it wanted and what it found.
    Checked { ok: bool, expected: String, got: String },
    /// Not the editor's line (files, camera, pixels): the host runs it.
    Host,
}

/// The scene and everything the user edits it with.
#[derive(Default)]
pub struct Editor {
    pub scene: Scene,
    pub history: History,
    pub tools: Tools,
    /// The selected box, if any.
    pub selection: Option<Region>,
    clipboard: Option<Block>,
    /// Clicks that hit no voxel land on the ground, the plane y = 0
    /// (`ground on|off`; on for a scene that starts empty).
    pub ground: bool,
}

impl Editor {
    /// Puts `scene` in place with an empty history and no selection; the
    /// tools and the clipboard stay (pasting between documents works). The
    /// next flush uploads all of it (what it was flushed to before, if
    /// anything, is not this editor's GPU buffer).
    pub fn set_scene(&mut self, mut scene: Scene) {
        scene.forget_uploads();
        self.scene = scene;
        self.history.clear();
        self.selection = None;
        self.ground = self.scene.solid_voxels() == 0 && self.scene.objects().is_none();
    }

    /// The world height of the ground plane drawn under the scene: y = 0
    /// where clicks build on the ground, none where they do not.
    pub fn ground_plane(&self) -> Option<i32> {
        self.ground.then_some(0)
    }

    pub fn clipboard(&self) -> Option<&Block> {
        self.clipboard.as_ref()
    }

    /// Carries out one line. `Err` is a line that could not run (a refused
    /// edit changes nothing).
    pub fn run(&mut self, command: &Line) -> Result<Outcome, EditorError> {
        // Frames played since the last line are composed before it reads the scene.
        self.scene.catch_up()?;
        let tools = self.tools;
        if command.ends_stroke() {
            self.history.end_stroke();
        }
        let changed = match command {
            Line::Stroke(true) => self.set(|e| e.history.begin_stroke()),
            Line::Stroke(false) => self.set(|e| e.history.end_stroke()),
            Line::New | Line::Demo(_) => {
                self.set_scene(built_scene(command).unwrap_or_default());
                return Ok(Outcome::Replaced);
            }
            Line::Brush(brush) => self.set(|e| e.tools.brush = *brush),
            Line::Ground(on) => self.set(|e| e.ground = *on),
            Line::Color(c) => self.set(|e| e.tools.color = *c),
            Line::Mirror(plane) => self.set(|e| e.tools.mirror.apply_line(*plane)),
            Line::Pick(p) => {
                let color = picked_color(&self.scene, *p)?;
                self.set(|e| e.tools.color = color)
            }
            Line::Place(p) => self.apply_mirrored(vec![brush_edit(&tools, *p, Op::Place(tools.color))])?,
            Line::Remove(p) => self.apply_mirrored(vec![brush_edit(&tools, *p, Op::Remove)])?,
            Line::Paint(p) => self.apply_mirrored(vec![brush_edit(&tools, *p, Op::Paint(tools.color))])?,
            Line::Segment(a, b) => {
                let edits = crate::edit::brush::line_edits(&tools.brush, tools.color, *a, *b)?;
                self.apply_mirrored(edits)?
            }
            // Fills and extrudes are not mirrored: their regions follow the
            // colours and faces, not the brush.
            Line::Fill(p) => {
                let edits = crate::edit::fill::fill_edits(self.scene.drawn(), *p, tools.color)?;
                self.commit(edits)?
            }
            Line::Extrude(p, normal, layers) => {
                let edits = crate::edit::extrude::extrude_edits(self.scene.drawn(), *p, *normal, *layers)?;
                self.commit(edits)?
            }
            Line::Rgb(..) | Line::Material(..) => match palette_edit(command, &self.scene.palette) {
                Some(edit) => self.commit(vec![edit])?,
                None => false,
            },
            Line::Palette(PaletteLine::Set { first, colors }) => {
                self.commit(palette_colors(&self.scene.palette, *first, colors))?
            }
            Line::Palette(PaletteLine::Preset(name)) => {
                let colors =
                    crate::io::palette_file::preset(name).ok_or_else(|| EditorError::NoPreset(name.clone()))?;
                self.commit(palette_colors(&self.scene.palette, 1, &colors))?
            }
            Line::ExpectPalette(index, want) => {
                let [r, g, b, _] = self.scene.palette.color(*index);
                let got = format!("{r} {g} {b}");
                return Ok(checked(
                    [r, g, b] == *want,
                    format!("palette {index} = {} {} {}", want[0], want[1], want[2]),
                    got,
                ));
            }
            Line::Undo(n) => self.repeat(*n, true)?,
            Line::Redo(n) => self.repeat(*n, false)?,
            Line::Select(None) => self.set(|e| e.selection = None),
            Line::Select(Some((a, b))) => {
                let region = Region::new(*a, *b)?;
                self.set(|e| e.selection = Some(region))
            }
            Line::Copy => {
                let block = selection::copy(self.scene.drawn(), self.selected()?)?;
                self.set(|e| e.clipboard = Some(block))
            }
            Line::Cut => {
                let region = self.selected()?;
                let block = selection::copy(self.scene.drawn(), region)?;
                let changed = self.commit(vec![region.clear_edit()])?;
                self.clipboard = Some(block);
                changed
            }
            Line::Delete => self.commit(vec![self.selected()?.clear_edit()])?,
            Line::Paste(at) => {
                let block = self.clipboard.as_ref().ok_or(EditorError::NothingToPaste)?;
                let region = block.region_at(*at).inside_world()?;
                let changed = self.commit(block.place_edits(*at))?;
                self.selection = Some(region);
                changed
            }
            Line::Move(by) => self.move_selection(*by)?,
            Line::Rotate(axis) => self.turn_selection(*axis, false)?,
            Line::Flip(axis) => self.turn_selection(*axis, true)?,
            Line::ExpectVoxel(p, want) => {
                let got = self.scene.voxel(*p);
                return Ok(checked(got == *want, format!("voxel {p} = {want}"), got));
            }
            Line::ExpectCount(want) => {
                let got = self.scene.solid_voxels();
                return Ok(checked(got == *want, format!("{want} voxels"), got));
            }
            Line::ExpectEffects(want) => {
                let (ok, got) = effects_match(&self.scene, want);
                return Ok(checked(ok, format!("effects [{}]", want.join(" ")), format!("[{}]", got.join(" "))));
            }
            Line::Object(line) => self.object_line(line)?,
            Line::Layer(id, line) => match line.attribute() {
                None => {
                    self.scene.set_new_layer(*id)?;
                    true
                }
                Some((key, value)) => {
                    let change = self.objects()?.layer_with(*id, key, value.as_deref())?;
                    self.commit(vec![Edit::Graph(Box::new(change))])?
                }
            },
            Line::ExpectObjects(want) => {
                let got = self.scene.objects().map_or(1, |o| o.list().len());
                return Ok(checked(got == *want, format!("{want} objects"), got));
            }
            Line::Frame(frame) => self.show_frame(*frame, false)?,
            Line::Anim(line) => {
                let objects = self.animated()?;
                let mut animation = objects.graph.as_ref().map(|g| g.animation).unwrap_or_default();
                match *line {
                    AnimLine::Range(first, last) => animation.range = Some((first, last)),
                    AnimLine::Fps(fps) => animation.fps = Some(fps),
                    AnimLine::Loop(on) => animation.looping = Some(on),
                }
                let change = objects.with_animation(animation)?;
                self.commit(vec![Edit::Graph(Box::new(change))])?
            }
            Line::ExpectFrame(want) => {
                let got = self.scene.objects().map_or(0, |o| o.frame);
                return Ok(checked(got == *want as usize, format!("frame {want}"), got));
            }
            Line::ExpectModels(want) => {
                let got = self.scene.objects().map_or(1, |o| o.models.len());
                return Ok(checked(got == *want, format!("{want} models"), got));
            }
            Line::Load(_)
            | Line::Palette(PaletteLine::Load(_) | PaletteLine::Save(_))
            | Line::Camera { .. }
            | Line::Projection(_)
            | Line::Viewport(..)
            | Line::Click { .. }
            | Line::Save(_)
            | Line::Render(_)
            | Line::ExpectWritten(_)
            | Line::ExpectImage(..) => return Ok(Outcome::Host),
        };
        Ok(if changed { Outcome::Changed } else { Outcome::State })
    }

    /// The index of the object `which` names: by index in walk order, or by
    /// its name or the path of names down to it. A scene of one model is
    /// object 0.
    fn object_named(&self, which: &ObjectRef) -> Result<usize, EditorError> {
        let Some(objects) = self.scene.objects() else {
            return match which {
                ObjectRef::Index(0) => Ok(0),
                _ => Err(EditorError::Object("the scene is one model: object 0 is all there is".to_owned())),
            };
        };
        let list = objects.list();
        match which {
            ObjectRef::Index(n) if *n < list.len() => Ok(*n),
            ObjectRef::Index(n) => Err(EditorError::Object(format!(
                "there is no object {n}: the scene has {} (0 to {})",
                list.len(),
                list.len().saturating_sub(1)
            ))),
            ObjectRef::Name(name) => {
                let own = |path: &str| path.rsplit('/').next().unwrap_or("").to_owned();
                let named = |i: usize| {
                    let path = objects.path(i);
                    path == *name || own(&path) == *name
                };
                let found: Vec<usize> = (0..list.len()).filter(|&i| named(i)).collect();
                match found.as_slice() {
                    [one] => Ok(*one),
                    [] => Err(EditorError::Object(format!("no object is named '{name}'"))),
                    many => {
                        let candidates: Vec<String> =
                            many.iter().take(8).map(|&i| format!("{i} ({})", objects.path(i))).collect();
                        Err(EditorError::Object(format!(
                            "{} objects are named '{name}': {}{}; name one by index or by its path",
                            many.len(),
                            candidates.join(", "),
                            if many.len() > 8 { ", …" } else { "" }
                        )))
                    }
                }
            }
        }
    }

    /// The `object N` line that picks the object drawn at `voxel`, when that
    /// is not the picked one already (what a click runs before its edit).
    /// A scene of one object has none to pick: its edits go to it.
    pub fn object_line_at(&self, voxel: IVec3) -> Option<Line> {
        self.pick_line(|objects| objects.owner_at(voxel))
    }

    /// The `object N` line a click on `picked` runs before its edit: the
    /// turned object whose model cell it hit, or the object drawn at its
    /// voxel ([`Editor::object_line_at`]).
    pub fn object_line_for(&self, picked: &crate::trace::pick::Picked) -> Option<Line> {
        match picked.model {
            Some(model) => self.pick_line(|_| Some(model.object)),
            None => self.object_line_at(picked.voxel),
        }
    }

    /// The `object N` line that picks the object `owner` names, unless it
    /// is picked already or locked (or the scene has no objects to pick).
    fn pick_line(&self, owner: impl FnOnce(&Objects) -> Option<usize>) -> Option<Line> {
        let objects = self.scene.pickable_objects()?;
        let owner = owner(objects).filter(|&i| objects.selected != Some(i) && !objects.locked(i))?;
        Some(Line::Object(ObjectLine::Pick(ObjectRef::Index(owner))))
    }

    /// The objects of a scene of several, or why an `object`/`layer` line
    /// cannot change anything.
    fn objects(&self) -> Result<&Objects, EditorError> {
        self.scene.objects().ok_or_else(|| {
            EditorError::Object("the scene is one model: it has no objects or layers to change".to_owned())
        })
    }

    /// Shows frame `frame` while it plays (the window's timeline): as the
    /// `frame N` line, but a scene drawn as instances composes its octree
    /// only when the next line runs (`Scene::show_frame`), so a played frame
    /// writes instance words and nothing else. Whether the picture changed.
    pub fn play_frame(&mut self, frame: u32) -> Result<bool, EditorError> {
        self.show_frame(frame, true)
    }

    /// Shows frame `frame`, composed at once or (`deferred`) as
    /// [`Editor::play_frame`] does; whether the picture changed.
    fn show_frame(&mut self, frame: u32, deferred: bool) -> Result<bool, EditorError> {
        let objects = self.animated()?;
        let frame = frame as usize;
        if objects.frame == frame {
            return Ok(false);
        }
        if objects.graph.is_none() && frame >= objects.models.len() {
            return Err(EditorError::Object(format!(
                "frame {frame}: this file of animation frames has {} (0 to {})",
                objects.models.len(),
                objects.models.len() - 1
            )));
        }
        match deferred {
            true => self.scene.show_frame(frame)?,
            false => self.scene.set_frame(frame)?,
        }
        Ok(true)
    }

    /// The objects of a scene that has time, or why `frame` and `anim`
    /// lines mean nothing in it.
    fn animated(&self) -> Result<&Objects, EditorError> {
        self.scene.objects().ok_or_else(|| {
            EditorError::Object(
                "the scene is one model, which has no animation: `frame` and `anim` need a scene of objects".to_owned(),
            )
        })
    }

    /// The object the `object …` lines change.
    fn picked_object(&self) -> Result<usize, EditorError> {
        self.objects()?.selected.ok_or_else(|| {
            EditorError::Object("no object is picked: pick one first (object N or object NAME)".to_owned())
        })
    }

    /// An `object` line: picking is tool state; every other line is one
    /// undo step on the picked object, which stays picked (a new or
    /// duplicated one is picked; a deleted one leaves none).
    fn object_line(&mut self, line: &ObjectLine) -> Result<bool, EditorError> {
        let (edits, picks) = match line {
            ObjectLine::Pick(which) => {
                let index = self.object_named(which)?;
                self.scene.select_object(Some(index));
                return Ok(false);
            }
            ObjectLine::New(name) => {
                let (model, change, id) = self.objects()?.created(name)?;
                (vec![Edit::AddModel(Box::new(model)), Edit::Graph(Box::new(change))], Picks::Transform(id))
            }
            line => self.picked_object_edits(line)?,
        };
        let changed = self.commit(edits)?;
        if let Some(objects) = self.scene.objects() {
            let selected = match picks {
                Picks::Same => objects.selected,
                Picks::None => None,
                Picks::Transform(id) => objects.index_of_transform(id),
            };
            self.scene.select_object(selected);
        }
        Ok(changed)
    }

    /// The edits an `object` line makes of the picked object, and what is
    /// picked after them.
    fn picked_object_edits(&self, line: &ObjectLine) -> Result<(Vec<Edit>, Picks), EditorError> {
        // A click's edit in a scene of one object goes to it, picked or not.
        let only = self.objects()?.list().len() == 1;
        let index = match line {
            ObjectLine::Cell { .. } if only => self.objects()?.selected.unwrap_or(0),
            _ => self.picked_object()?,
        };
        let objects = self.objects()?;
        let graph = |change| vec![Edit::Graph(Box::new(change))];
        Ok(match line {
            ObjectLine::Move(by) => (graph(objects.moved(index, *by)?), Picks::Same),
            ObjectLine::Rotate(axis) => (graph(objects.rotated(index, *axis, 1)?), Picks::Same),
            ObjectLine::Turn { axis, degrees } => (graph(objects.turned(index, *axis, degrees.0)?), Picks::Same),
            ObjectLine::Hide(hidden) => {
                (graph(objects.with_attribute(index, "_hidden", hidden.then_some("1"))?), Picks::Same)
            }
            ObjectLine::Rename(name) => (graph(objects.with_attribute(index, "_name", Some(name))?), Picks::Same),
            ObjectLine::Lock(locked) => {
                (graph(objects.with_attribute(index, "_lock", locked.then_some("1"))?), Picks::Same)
            }
            ObjectLine::Layer(layer) => (graph(objects.on_layer(index, *layer)?), Picks::Same),
            ObjectLine::Key(ease) => (graph(objects.keyed(index, *ease)?), Picks::Same),
            ObjectLine::Unkey => (graph(objects.unkeyed(index)?), Picks::Same),
            ObjectLine::Cell { tool, at } => {
                let op = crate::edit::brush::tool_op(*tool, self.tools.color);
                (vec![Edit::InModel { object: index, shape: self.tools.brush.shape_at(*at), op }], Picks::Same)
            }
            ObjectLine::Delete => (graph(objects.deleted(index)?), Picks::None),
            ObjectLine::Duplicate { reference: true } => {
                let (change, id) = objects.duplicated(index, None)?;
                (graph(change), Picks::Transform(id))
            }
            ObjectLine::Duplicate { reference: false } => {
                let (copy, model) = objects.model_copy(index);
                let (change, id) = objects.duplicated(index, Some(model))?;
                (vec![Edit::AddModel(Box::new(copy)), Edit::Graph(Box::new(change))], Picks::Transform(id))
            }
            ObjectLine::Unique => {
                let (copy, model) = objects.model_copy(index);
                let change = objects.made_unique(index, model)?;
                (vec![Edit::AddModel(Box::new(copy)), Edit::Graph(Box::new(change))], Picks::Same)
            }
            ObjectLine::Regroup(target, after) => {
                let target = self.object_named(target)?;
                let own = objects.transform_node(index)?.id;
                (graph(objects.regrouped(index, target, *after)?), Picks::Transform(own))
            }
            ObjectLine::Merge(others) => {
                let others = others.iter().map(|o| self.object_named(o)).collect::<Result<Vec<_>, _>>()?;
                let (model, change) = objects.merged(index, &others)?;
                let own = objects.transform_node(index)?.id;
                (vec![Edit::AddModel(Box::new(model)), Edit::Graph(Box::new(change))], Picks::Transform(own))
            }
            ObjectLine::Pick(_) | ObjectLine::New(_) => (Vec::new(), Picks::Same),
        })
    }

    /// A change of tool state, selection or clipboard: never an edit.
    fn set(&mut self, change: impl FnOnce(&mut Editor)) -> bool {
        change(self);
        false
    }

    /// The selected box, or why a line that needs one cannot run.
    fn selected(&self) -> Result<Region, EditorError> {
        self.selection.ok_or(EditorError::NothingSelected)
    }

    /// `move`: the selected voxels leave their box and land `by` away, as
    /// one undo step; the selection follows. Refused as a whole when the
    /// new place is outside the world. Whether the voxels changed.
    fn move_selection(&mut self, by: IVec3) -> Result<bool, EditorError> {
        let region = self.selected()?;
        self.relocate_selection(region, region.shifted(by), &CellMap::IDENTITY)
    }

    /// `rotate` (`flip`): the selected voxels leave their box and land
    /// turned (mirrored) in the turned box about the same centre, as one
    /// undo step; the selection follows. Whether the voxels changed.
    fn turn_selection(&mut self, axis: usize, flip: bool) -> Result<bool, EditorError> {
        let region = self.selected()?;
        let (turned, map) = region.turned(axis, flip);
        self.relocate_selection(region, turned, &map)
    }

    /// The voxels of `region` leave it and land in `target`, each cell taken
    /// through `map` (cells relative to each box's min corner), as one undo
    /// step; `target` becomes the selection. Refused as a whole when
    /// `target` is outside the world. Whether the voxels changed.
    fn relocate_selection(&mut self, region: Region, target: Region, map: &CellMap) -> Result<bool, EditorError> {
        let target = target.inside_world()?;
        let block = selection::copy(self.scene.drawn(), region)?.mapped(map, target.size());
        let mut edits = vec![region.clear_edit()];
        edits.extend(block.place_edits(target.min));
        let changed = self.commit(edits)?;
        self.selection = Some(target);
        Ok(changed)
    }

    /// Brush edits and their mirror images as one undo step (or part of the
    /// open stroke); whether there was any.
    ///
    /// # Errors
    /// A refused edit; then nothing changed.
    fn apply_mirrored(&mut self, edits: Vec<Edit>) -> Result<bool, EditError> {
        let edits = edits.into_iter().flat_map(|e| self.tools.mirror.edits(e)).collect();
        self.commit(edits)
    }

    /// Edits as one undo step (or part of the open stroke); whether there
    /// was any (no edits make no step).
    ///
    /// # Errors
    /// A refused edit; then nothing changed.
    fn commit(&mut self, edits: Vec<Edit>) -> Result<bool, EditError> {
        let any = !edits.is_empty();
        self.history.apply_group(&mut self.scene, edits)?;
        Ok(any)
    }

    /// `undo N` / `redo N`: all N steps, or (fewer there) none.
    fn repeat(&mut self, n: u32, undo: bool) -> Result<bool, EditorError> {
        let (undoable, redoable) = self.history.steps();
        let (what, available) = if undo { ("undo", undoable) } else { ("redo", redoable) };
        if available == 0 {
            return Err(EditorError::NoSteps(what));
        }
        if usize::try_from(n).map_or(true, |n| n > available) {
            return Err(EditorError::TooFewSteps { what, available, wanted: n });
        }
        for _ in 0..n {
            let scene = &mut self.scene;
            if undo { self.history.undo(scene) } else { self.history.redo(scene) }?;
        }
        Ok(true)
    }
}

/// Which object an `object` line leaves picked.
enum Picks {
    Same,
    None,
    /// The one its new transform node places.
    Transform(u32),
}

/// The scene a `new` or `demo` line makes; `None` for other lines.
fn built_scene(command: &Line) -> Option<Scene> {
    match command {
        Line::New => Some(Scene::default()),
        Line::Demo(built_in) => Some(built_in.scene()),
        _ => None,
    }
}

/// The edit a palette line (`rgb`, `material`) makes on `palette`; `None`
/// for other lines.
fn palette_edit(command: &Line, palette: &Palette) -> Option<Edit> {
    let (index, color, material) = match command {
        Line::Rgb(index, [r, g, b]) => (*index, [*r, *g, *b, 255], palette.material(*index).clone()),
        Line::Material(index, material) => (*index, palette.color(*index), (**material).clone()),
        _ => return None,
    };
    Some(Edit::Palette { index, color, material: Box::new(material) })
}

/// The edits that give palette entries `first..` the colours `colors`
/// (opaque), each keeping its material; entries already so make none.
fn palette_colors(palette: &Palette, first: u8, colors: &[[u8; 3]]) -> Vec<Edit> {
    (first..=255)
        .zip(colors)
        .map(|(index, &[r, g, b])| (index, [r, g, b, 255]))
        .filter(|&(index, color)| palette.color(index) != color)
        .map(|(index, color)| Edit::Palette { index, color, material: Box::new(palette.material(index).clone()) })
        .collect()
}

/// `pick X Y Z`: the colour of the voxel there, or why there is none.
fn picked_color(scene: &Scene, at: IVec3) -> Result<u8, EditorError> {
    match scene.voxel(at) {
        0 => Err(EditorError::NothingToPick(at)),
        value => Ok(value),
    }
}

/// `expect effects`: whether the effect set the scene calls for (with the
/// default path settings, so a script means one thing in every host) is
/// exactly `want` (in any order), and the set's names.
fn effects_match(scene: &Scene, want: &[String]) -> (bool, Vec<&'static str>) {
    let names = crate::trace::path::effects_for(scene, &PathSettings::default()).names();
    let mut got = names.clone();
    let mut expected: Vec<&str> = want.iter().map(String::as_str).collect();
    got.sort_unstable();
    expected.sort_unstable();
    (got == expected, names)
}

fn brush_edit(tools: &Tools, at: IVec3, op: Op) -> Edit {
    Edit::Brush { shape: tools.brush.shape_at(at), op }
}

fn checked(ok: bool, expected: String, got: impl ToString) -> Outcome {
    Outcome::Checked { ok, expected, got: got.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(editor: &mut Editor, line: &str) -> Result<Outcome, EditorError> {
        let script = crate::script::parse_script(std::path::Path::new("t.ovr"), line).unwrap();
        editor.run(&script.lines[0].command)
    }

    #[test]
    fn a_refused_paste_leaves_scene_selection_and_history_alone() {
        let mut editor = Editor::default();
        for line in ["place 0 0 0", "place 1 0 0", "select 0 0 0 1 0 0", "copy"] {
            run(&mut editor, line).unwrap();
        }
        let limit = crate::scene::octree::WORLD_LIMIT - 1;
        let err = run(&mut editor, &format!("paste {limit} 0 0")).unwrap_err().to_string();
        assert!(err.contains("outside the world"), "{err}");
        assert_eq!(editor.scene.solid_voxels(), 2);
        assert_eq!(editor.selection, Some(Region { min: IVec3::ZERO, max: IVec3::X }));
        assert_eq!(editor.history.usage().0, 2);
        assert!(run(&mut editor, &format!("move {limit} 0 0")).is_err());
        assert_eq!((editor.scene.voxel(IVec3::ZERO), editor.scene.voxel(IVec3::X)), (1, 1));
    }

    /// Issue 27, bug 1: a scene recovered from a journal (replayed on the
    /// CPU, whose runner flushed the pool as it went) uploaded 0 bytes in
    /// the window, which went on showing the scene from before recovery.
    #[test]
    fn a_scene_put_in_place_is_uploaded_whole() {
        let mut replayed = Editor::default();
        for line in ["new", "brush sphere 6", "place 0 0 0", "place 9 0 0"] {
            run(&mut replayed, line).unwrap();
        }
        // A flush elsewhere (the CPU runner counts its flushes so).
        let _ = replayed.scene.take_uploads();
        let live = replayed.scene.drawn_pool_bytes();
        let mut window = Editor::default();
        window.set_scene(replayed.scene);
        let upload = window.scene.take_uploads();
        assert!(upload.byte_count() >= live, "{} of {live} bytes uploaded", upload.byte_count());
    }

    #[test]
    fn lines_that_need_a_selection_or_clipboard_say_so() {
        let mut editor = Editor::default();
        for line in ["copy", "cut", "delete", "move 1 0 0"] {
            assert!(run(&mut editor, line).unwrap_err().to_string().contains("nothing is selected"), "{line}");
        }
        assert!(run(&mut editor, "paste 0 0 0").unwrap_err().to_string().contains("nothing to paste"));
    }

    #[test]
    fn an_empty_block_makes_no_step_and_stays_inside_the_world() {
        let mut editor = Editor::default();
        for line in ["place 0 0 0", "select 5 5 5 6 6 6", "copy"] {
            run(&mut editor, line).unwrap();
        }
        assert_eq!(run(&mut editor, "paste 10 0 0"), Ok(Outcome::State), "nothing to place: no step");
        assert_eq!(editor.history.steps(), (1, 0));
        let far = crate::scene::octree::WORLD_LIMIT - 1;
        assert!(run(&mut editor, &format!("move {far} 0 0")).unwrap_err().to_string().contains("outside the world"));
        assert_eq!(editor.selection, Some(Region { min: IVec3::new(10, 0, 0), max: IVec3::new(11, 1, 1) }));
    }

    /// Every solid voxel of the editor's scene with its colour, in one order.
    fn voxels(editor: &Editor) -> Vec<(IVec3, u8)> {
        let mut out = editor.scene.voxels();
        out.sort_by_key(|(p, _)| (p.x, p.y, p.z));
        out
    }

    /// An uneven shape in a 5×3×2 box (sizes that differ by odd counts).
    fn uneven(editor: &mut Editor) {
        for (i, line) in ["place 0 0 0", "place 1 0 0", "place 4 0 0", "place 4 2 1", "place 0 1 1"].iter().enumerate()
        {
            run(editor, &format!("color {}", i + 1)).unwrap();
            run(editor, line).unwrap();
        }
        run(editor, "select 0 0 0 4 2 1").unwrap();
    }

    #[test]
    fn two_quarter_turns_are_two_flips_and_four_come_back() {
        for axis in ["x", "y", "z"] {
            let (mut turned, mut flipped) = (Editor::default(), Editor::default());
            uneven(&mut turned);
            uneven(&mut flipped);
            let start = (voxels(&turned), turned.selection);
            run(&mut turned, &format!("rotate {axis}")).unwrap();
            assert_ne!(voxels(&turned), start.0, "about {axis}");
            run(&mut turned, &format!("rotate {axis}")).unwrap();
            let others: Vec<&str> = ["x", "y", "z"].into_iter().filter(|a| *a != axis).collect();
            for other in others {
                run(&mut flipped, &format!("flip {other}")).unwrap();
            }
            assert_eq!(voxels(&turned), voxels(&flipped), "a half turn about {axis}");
            assert_eq!(turned.selection, flipped.selection);
            run(&mut turned, &format!("rotate {axis}")).unwrap();
            run(&mut turned, &format!("rotate {axis}")).unwrap();
            assert_eq!((voxels(&turned), turned.selection), start, "four turns about {axis}");
            assert_eq!(turned.history.steps().0, 5 + 4, "each turn is one undo step");
            run(&mut turned, "undo 4").unwrap();
            assert_eq!((voxels(&turned), turned.selection.is_some()), (start.0, true));
        }
    }

    #[test]
    fn a_turn_swaps_the_box_sizes_about_its_centre() {
        let mut editor = Editor::default();
        uneven(&mut editor);
        // About y a 5×3×2 box becomes 2×3×5: x moves in by 2 (half of 3,
        // away from zero), z out by 2.
        run(&mut editor, "rotate y").unwrap();
        assert_eq!(editor.selection, Some(Region { min: IVec3::new(2, 0, -2), max: IVec3::new(3, 2, 2) }));
        // Counter-clockwise seen from +y: +x turns to −z, +z to +x.
        assert_eq!(editor.scene.voxel(IVec3::new(2, 0, 2)), 1, "(0, 0, 0) went to the far +z end");
        assert_eq!(editor.scene.voxel(IVec3::new(2, 0, -2)), 3, "(4, 0, 0) went to the −z end");
        assert_eq!(editor.scene.voxel(IVec3::new(3, 2, -2)), 4, "(4, 2, 1) went +x of it");
        assert_eq!(editor.scene.solid_voxels(), 5);
    }

    #[test]
    fn a_turn_needs_a_selection_and_a_refused_one_changes_nothing() {
        let mut editor = Editor::default();
        assert!(run(&mut editor, "rotate y").unwrap_err().to_string().contains("nothing is selected"));
        // A column 8 high at the world's +x edge turned about z lies 8 wide
        // about its centre: 3 cells past the edge.
        let edge = crate::scene::octree::WORLD_LIMIT - 2;
        for line in ["brush box 1 8 1".to_owned(), format!("place {edge} 4 0"), format!("select {edge} 0 0 {edge} 7 0")]
        {
            run(&mut editor, &line).unwrap();
        }
        let column = |e: &Editor| (0..8).filter(|&y| e.scene.voxel(IVec3::new(edge, y, 0)) != 0).count();
        let before = (column(&editor), editor.scene.solid_voxels(), editor.selection, editor.history.steps());
        assert_eq!(before.0, 8);
        let err = run(&mut editor, "rotate z").unwrap_err().to_string();
        assert!(err.contains("outside the world"), "{err}");
        assert_eq!((column(&editor), editor.scene.solid_voxels(), editor.selection, editor.history.steps()), before);
    }

    #[test]
    fn undo_n_takes_all_n_steps_or_none() {
        let mut editor = Editor::default();
        for line in ["place 0 0 0", "place 1 0 0"] {
            run(&mut editor, line).unwrap();
        }
        assert!(run(&mut editor, "undo 3").unwrap_err().to_string().contains("only 2 step(s) to undo"));
        assert_eq!(editor.scene.solid_voxels(), 2, "nothing was undone");
        assert_eq!(run(&mut editor, "undo 2"), Ok(Outcome::Changed));
        assert_eq!(editor.scene.solid_voxels(), 0);
    }
}
