//! `octovox info FILE [--json] [--objects] [--frame N]`: what a .vox or
//! .ovx file holds.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::vox::{VoxMeta, load_vox_scene_file};
use octovox::scene::{MaterialKind, Scene};

/// Widest world MagicaVoxel opens, in voxels per axis.
const MAGICAVOXEL_WORLD: i64 = 2048;

/// Loads `file` and prints its summary, as JSON when `json` is set.
pub fn run(file: &Path, json: bool, objects: bool, frame: usize) -> anyhow::Result<ExitCode> {
    let loading = || format!("loading {}", file.display());
    let (scene, meta) = if octovox::io::is_ovx_path(file) {
        let scene = octovox::io::ovx::load_ovx(file, &Default::default()).with_context(loading)?;
        (scene, VoxMeta { models: 1, stored_models: 1, warnings: Vec::new() })
    } else {
        load_vox_scene_file(file, frame).with_context(loading)?
    };
    let mut summary = Summary::of(&scene, meta);
    if summary.extent().iter().any(|e| *e > MAGICAVOXEL_WORLD) {
        let [x, y, z] = summary.extent();
        summary.warnings.push(format!(
            "the world is {x} x {y} x {z} voxels: MagicaVoxel opens worlds up to {MAGICAVOXEL_WORLD} across"
        ));
    }
    if json {
        let mut value = summary.to_json(file);
        value["objects"] = object_json(&scene);
        say!("{}", serde_json::to_string_pretty(&value)?)?;
    } else if objects {
        std::io::Write::write_all(&mut std::io::stdout().lock(), object_lines(&scene).as_bytes())?;
    } else {
        std::io::Write::write_all(&mut std::io::stdout().lock(), summary.to_text(file).as_bytes())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// `info --objects`: one line per object in walk order (a scene of one
/// model is object 0).
fn object_lines(scene: &Scene) -> String {
    let corner = |p: glam::IVec3| format!("{} {} {}", p.x, p.y, p.z);
    let Some(objects) = scene.objects() else {
        let bounds =
            scene.solid_bounds().map_or("-".to_owned(), |(lo, hi)| format!("{} .. {}", corner(lo), corner(hi)));
        return format!("0\t-\tmodel 0\tlayer -\tshown\t{bounds}\n");
    };
    let mut out = String::new();
    for (index, object) in objects.list().iter().enumerate() {
        let bounds =
            objects.world_box(index).map_or("-".to_owned(), |(lo, hi)| format!("{} .. {}", corner(lo), corner(hi)));
        let path = objects.path(index);
        let name = if path.is_empty() { "-" } else { &path };
        let layer = object.layer.map_or("-".to_owned(), |l| l.to_string());
        let shown = if object.hidden { "hidden" } else { "shown" };
        out += &format!("{index}\t{name}\tmodel {}\tlayer {layer}\t{shown}\t{bounds}\n", object.placement.model);
    }
    out
}

/// `info --json`'s objects, in walk order: index, name path, model, layer,
/// whether hidden (itself, above, or by its layer) and world box (a scene
/// of one model is object 0).
fn object_json(scene: &Scene) -> serde_json::Value {
    let bounds = |b: Option<(glam::IVec3, glam::IVec3)>| b.map(|(lo, hi)| [lo.to_array(), hi.to_array()]);
    let Some(objects) = scene.objects() else {
        let one = serde_json::json!({"index": 0, "path": "", "model": 0, "layer": null, "hidden": false,
            "bounds": bounds(scene.solid_bounds())});
        return serde_json::Value::Array(vec![one]);
    };
    let rows = objects.list().iter().enumerate().map(|(index, object)| {
        serde_json::json!({
            "index": index,
            "path": objects.path(index),
            "model": object.placement.model,
            "layer": object.layer,
            "hidden": object.hidden,
            "bounds": bounds(objects.world_box(index)),
        })
    });
    serde_json::Value::Array(rows.collect())
}

/// The numbers `info` reports.
struct Summary {
    models: usize,
    stored_models: usize,
    /// (id, name, hidden) of every layer.
    layers: Vec<(u32, String, bool)>,
    groups: usize,
    /// Bytes of the node pools of every stored model (the drawn tree's for a scene of one model).
    pool_bytes: u64,
    warnings: Vec<String>,
    voxels: u64,
    /// Inclusive corners in world axes (y up); `None` for an empty scene.
    bounds: Option<([i32; 3], [i32; 3])>,
    palette_entries: usize,
    /// Kind → number of used palette entries of that kind.
    materials: BTreeMap<MaterialKind, usize>,
    /// A scene of objects' time: the frame shown, the frames it plays, how
    /// fast, whether playing loops.
    animation: Option<Animation>,
}

/// What `info` says of a scene's time.
struct Animation {
    frame: usize,
    range: (u32, u32),
    fps: u32,
    looping: bool,
}

impl Summary {
    /// A scene as loaded (streamed from a .vox, or an .ovx's pool).
    fn of(scene: &Scene, meta: VoxMeta) -> Summary {
        let used: Vec<u8> = scene.counts().present().collect();
        let mut materials = BTreeMap::new();
        for &index in &used {
            *materials.entry(scene.palette.material(index).kind).or_insert(0) += 1;
        }
        let objects = scene.objects();
        Summary {
            models: meta.models,
            stored_models: meta.stored_models,
            layers: objects.map_or_else(Vec::new, |o| o.layers()),
            groups: objects.map_or(0, |o| o.group_count()),
            pool_bytes: objects.map_or(scene.drawn_pool_bytes(), |o| o.pool_bytes()),
            warnings: meta.warnings,
            voxels: scene.solid_voxels(),
            bounds: scene.solid_bounds().map(|(lo, hi)| (lo.to_array(), hi.to_array())),
            palette_entries: used.len(),
            materials,
            animation: objects.map(|o| {
                let settings = o.graph.as_ref().map(|g| g.animation).unwrap_or_default();
                Animation { frame: o.frame, range: o.frame_range(), fps: settings.fps(), looping: settings.looping() }
            }),
        }
    }

    /// max − min + 1 per axis, zero when empty.
    fn extent(&self) -> [i64; 3] {
        self.bounds.map_or([0; 3], |(lo, hi)| [0, 1, 2].map(|i| i64::from(hi[i]) - i64::from(lo[i]) + 1))
    }

    fn material_names(&self) -> impl Iterator<Item = (&'static str, usize)> + '_ {
        self.materials.iter().map(|(kind, &count)| (kind.vox_name().trim_start_matches('_'), count))
    }

    fn to_json(&self, file: &Path) -> serde_json::Value {
        let materials: serde_json::Map<String, serde_json::Value> =
            self.material_names().map(|(name, count)| (name.to_owned(), count.into())).collect();
        serde_json::json!({
            "file": file.display().to_string(),
            "models": self.models,
            "stored_models": self.stored_models,
            "layers": self.layers.iter().map(|(id, name, hidden)| serde_json::json!({"id": id, "name": name, "hidden": hidden})).collect::<Vec<_>>(),
            "groups": self.groups,
            "pool_bytes": self.pool_bytes,
            "warnings": self.warnings,
            "voxels": self.voxels,
            "extent": self.extent(),
            "min": self.bounds.map(|(lo, _)| lo),
            "max": self.bounds.map(|(_, hi)| hi),
            "palette_entries": self.palette_entries,
            "materials": materials,
            "animation": self.animation.as_ref().map(|a| serde_json::json!({
                "frame": a.frame, "range": [a.range.0, a.range.1], "fps": a.fps, "loop": a.looping,
            })),
        })
    }

    fn to_text(&self, file: &Path) -> String {
        let [ex, ey, ez] = self.extent();
        let corner = |c: Option<[i32; 3]>| c.map_or("-".to_owned(), |[x, y, z]| format!("{x} {y} {z}"));
        let materials: Vec<String> = self.material_names().map(|(name, count)| format!("{name} {count}")).collect();
        let rows = [
            ("file", file.display().to_string()),
            ("models", self.models.to_string()),
            ("stored models", self.stored_models.to_string()),
            ("layers", self.layers.len().to_string()),
            ("groups", self.groups.to_string()),
            ("pool bytes", self.pool_bytes.to_string()),
            ("voxels", self.voxels.to_string()),
            ("extent", format!("{ex} x {ey} x {ez}  (x, y up, z)")),
            ("min", corner(self.bounds.map(|(lo, _)| lo))),
            ("max", corner(self.bounds.map(|(_, hi)| hi))),
            ("palette entries", self.palette_entries.to_string()),
            ("materials", if materials.is_empty() { "-".to_owned() } else { materials.join(", ") }),
        ];
        let animation = self.animation.as_ref().map(|a| {
            let looping = if a.looping { "looping" } else { "once" };
            ("animation", format!("frame {} of {}..{}, {} a second, {looping}", a.frame, a.range.0, a.range.1, a.fps))
        });
        let warnings = self.warnings.iter().map(|w| ("warning", w.clone()));
        rows.into_iter().chain(animation).chain(warnings).map(|(key, value)| format!("{key:<16} {value}\n")).collect()
    }
}
