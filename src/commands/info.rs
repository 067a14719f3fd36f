//! `octovox info FILE [--json] [--frame N]`: what a .vox or .ovx file holds.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context;
use octovox::io::vox::{VoxMeta, load_vox_scene_file};
use octovox::scene::{MaterialKind, Scene};

/// Widest world MagicaVoxel opens, in voxels per axis.
const MAGICAVOXEL_WORLD: i64 = 2048;

/// Loads `file` and prints its summary, as JSON when `json` is set.
pub fn run(file: &Path, json: bool, frame: usize) -> anyhow::Result<ExitCode> {
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
        say!("{}", serde_json::to_string_pretty(&summary.to_json(file))?)?;
    } else {
        std::io::Write::write_all(&mut std::io::stdout().lock(), summary.to_text(file).as_bytes())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// The numbers `info` reports.
struct Summary {
    models: usize,
    stored_models: usize,
    warnings: Vec<String>,
    voxels: u64,
    /// Inclusive corners in world axes (y up); `None` for an empty scene.
    bounds: Option<([i32; 3], [i32; 3])>,
    palette_entries: usize,
    /// Kind → number of used palette entries of that kind.
    materials: BTreeMap<MaterialKind, usize>,
}

impl Summary {
    /// A scene as loaded (streamed from a .vox, or an .ovx's pool).
    fn of(scene: &Scene, meta: VoxMeta) -> Summary {
        let used: Vec<u8> = scene.tree.counts().present().collect();
        let mut materials = BTreeMap::new();
        for &index in &used {
            *materials.entry(scene.palette.material(index).kind).or_insert(0) += 1;
        }
        Summary {
            models: meta.models,
            stored_models: meta.stored_models,
            warnings: meta.warnings,
            voxels: scene.tree.solid_voxels(),
            bounds: scene.tree.solid_bounds().map(|(lo, hi)| (lo.to_array(), hi.to_array())),
            palette_entries: used.len(),
            materials,
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
            "warnings": self.warnings,
            "voxels": self.voxels,
            "extent": self.extent(),
            "min": self.bounds.map(|(lo, _)| lo),
            "max": self.bounds.map(|(_, hi)| hi),
            "palette_entries": self.palette_entries,
            "materials": materials,
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
            ("voxels", self.voxels.to_string()),
            ("extent", format!("{ex} x {ey} x {ez}  (x, y up, z)")),
            ("min", corner(self.bounds.map(|(lo, _)| lo))),
            ("max", corner(self.bounds.map(|(_, hi)| hi))),
            ("palette entries", self.palette_entries.to_string()),
            ("materials", if materials.is_empty() { "-".to_owned() } else { materials.join(", ") }),
        ];
        let warnings = self.warnings.iter().map(|w| ("warning", w.clone()));
        rows.into_iter().chain(warnings).map(|(key, value)| format!("{key:<16} {value}\n")).collect()
    }
}
