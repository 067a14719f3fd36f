//! Palette colours and per-index materials (MagicaVoxel's RGBA and MATL chunks).

use std::collections::BTreeMap;

/// Rendering model of a palette entry, as MagicaVoxel's `_type` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    #[default]
    Diffuse,
    Metal,
    Glass,
    Emit,
    /// Volumetric media (`_media`, MagicaVoxel's cloud material).
    Media,
}

impl MaterialKind {
    pub const ALL: [MaterialKind; 5] =
        [MaterialKind::Diffuse, MaterialKind::Metal, MaterialKind::Glass, MaterialKind::Emit, MaterialKind::Media];

    /// The `_type` string MagicaVoxel writes for this kind.
    pub fn vox_name(self) -> &'static str {
        match self {
            MaterialKind::Diffuse => "_diffuse",
            MaterialKind::Metal => "_metal",
            MaterialKind::Glass => "_glass",
            MaterialKind::Emit => "_emit",
            MaterialKind::Media => "_media",
        }
    }

    /// Parses a `_type` value; `None` for a name octovox does not render
    /// (e.g. `_blend`), which loaders treat as diffuse with a warning.
    pub fn from_vox_name(name: &str) -> Option<MaterialKind> {
        match name {
            "_diffuse" => Some(MaterialKind::Diffuse),
            "_metal" => Some(MaterialKind::Metal),
            "_glass" => Some(MaterialKind::Glass),
            "_emit" => Some(MaterialKind::Emit),
            "_media" | "_cloud" => Some(MaterialKind::Media),
            _ => None,
        }
    }
}

/// The MATL keys octovox reads as numbers: (key, range MagicaVoxel's UI
/// allows, value when absent). `_ior` is the refractive index minus one;
/// `_ri`, where present, is the index itself.
const NUMERIC_PARAMS: [(&str, std::ops::RangeInclusive<f32>, f32); 11] = [
    ("_rough", 0.0..=1.0, 0.1),
    ("_metal", 0.0..=1.0, 0.0),
    ("_sp", 0.0..=2.0, 0.5),
    ("_ior", 0.0..=2.0, 0.5),
    ("_ri", 1.0..=3.0, 1.5),
    ("_trans", 0.0..=1.0, 0.0),
    ("_alpha", 0.0..=1.0, 0.0),
    ("_emit", 0.0..=1.0, 0.0),
    ("_flux", 0.0..=4.0, 0.0),
    ("_ldr", 0.0..=1.0, 0.0),
    ("_d", 0.0..=1.0, 0.0),
];

/// The range MagicaVoxel's UI allows a numeric MATL parameter (scripts and
/// the window refuse values outside it; files keep theirs, and rendering
/// clamps them).
pub fn param_range(key: &str) -> Option<std::ops::RangeInclusive<f32>> {
    NUMERIC_PARAMS.iter().find(|(k, _, _)| *k == key).map(|(_, range, _)| range.clone())
}

/// Whether `key` is a MATL parameter octovox reads as a number.
pub fn is_numeric_key(key: &str) -> bool {
    NUMERIC_PARAMS.iter().any(|(k, _, _)| *k == key)
}

/// One palette entry's material: the kind plus MagicaVoxel's MATL parameters.
///
/// Parameters are kept as the key/value strings of the MATL dictionary
/// (`_rough`, `_metal`, `_ior`, `_trans`, `_emit`, `_flux`, …) so that a
/// load → save → load round trip keeps every one, including keys octovox does
/// not interpret; typed accessors read the ones the renderer uses.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Material {
    pub kind: MaterialKind,
    /// MATL dictionary without `_type` (the kind holds that).
    pub params: BTreeMap<String, String>,
}

impl Material {
    pub fn new(kind: MaterialKind) -> Material {
        Material { kind, params: BTreeMap::new() }
    }

    /// A numeric parameter, clamped into its range; its default when it is
    /// absent or not a finite number. Never NaN.
    fn param(&self, key: &str) -> f32 {
        let Some((_, range, default)) = NUMERIC_PARAMS.iter().find(|(k, _, _)| *k == key) else { return 0.0 };
        match self.params.get(key).map(|v| v.trim().parse::<f32>()) {
            Some(Ok(v)) if v.is_finite() => v.clamp(*range.start(), *range.end()),
            _ => *default,
        }
    }

    pub fn roughness(&self) -> f32 {
        self.param("_rough")
    }
    pub fn metalness(&self) -> f32 {
        self.param("_metal")
    }
    /// The refractive index: `_ri` where present, else from `_ior`, which
    /// MATL stores as the index minus one (old MATT chunks store the index
    /// itself, 1 or more).
    pub fn ior(&self) -> f32 {
        if self.params.get("_ri").is_some_and(|v| v.trim().parse::<f32>().is_ok_and(f32::is_finite)) {
            return self.param("_ri");
        }
        let ior = self.param("_ior");
        if ior < 1.0 { ior + 1.0 } else { ior }
    }
    /// `_trans`, else the older `_alpha`; a glass entry with neither is
    /// clear (what its kind promises), any other kind opaque.
    pub fn transparency(&self) -> f32 {
        let valid = |key: &str| self.params.get(key).is_some_and(|v| v.trim().parse::<f32>().is_ok_and(f32::is_finite));
        if valid("_trans") {
            self.param("_trans")
        } else if valid("_alpha") {
            self.param("_alpha")
        } else if self.kind == MaterialKind::Glass {
            1.0
        } else {
            0.0
        }
    }
    /// This material as `kind`, its parameters kept; an emitter whose
    /// emission is 0 gets 1, so that choosing "emit" changes what is seen
    /// (the panel's kind menu).
    pub fn switched_to(&self, kind: MaterialKind) -> Material {
        let mut material = Material { kind, params: self.params.clone() };
        if kind == MaterialKind::Emit && material.emission() == 0.0 {
            material.params.insert("_emit".to_string(), "1".to_string());
        }
        material
    }

    pub fn emission(&self) -> f32 {
        self.param("_emit")
    }
    pub fn flux(&self) -> f32 {
        self.param("_flux")
    }

    /// The numeric parameters that are not numbers or lie outside their
    /// range, each as "key 'value' …, read as X" (what the accessors use).
    pub fn problems(&self) -> Vec<String> {
        NUMERIC_PARAMS
            .iter()
            .filter_map(|(key, range, default)| {
                let text = self.params.get(*key)?;
                match text.trim().parse::<f32>() {
                    Ok(v) if v.is_finite() && range.contains(&v) => None,
                    Ok(v) if v.is_finite() => Some(format!(
                        "{key} '{text}' is outside {}..={}, read as {}",
                        range.start(),
                        range.end(),
                        self.param(key)
                    )),
                    _ => Some(format!("{key} '{text}' is not a number, read as {default}")),
                }
            })
            .collect()
    }
}

/// 256 RGBA colours and their materials. Index 0 means "empty" in voxel data;
/// its colour is kept only so files round-trip.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    pub colors: [[u8; 4]; 256],
    pub materials: Vec<Material>,
}

impl Default for Palette {
    fn default() -> Palette {
        Palette::default_magicavoxel()
    }
}

impl Palette {
    /// MagicaVoxel's default palette (the one a file without RGBA uses).
    pub fn default_magicavoxel() -> Palette {
        let mut colors = [[0u8; 4]; 256];
        for (i, c) in dot_vox::DEFAULT_PALETTE.iter().enumerate() {
            // Entry i of an RGBA chunk is colour index i + 1; the last entry
            // lands on index 0, which no voxel uses.
            colors[(i + 1) % 256] = [c.r, c.g, c.b, c.a];
        }
        Palette { colors, materials: vec![Material::default(); 256] }
    }

    pub fn color(&self, index: u8) -> [u8; 4] {
        self.colors[usize::from(index)]
    }

    pub fn material(&self, index: u8) -> &Material {
        &self.materials[usize::from(index)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(kind: MaterialKind, params: &[(&str, &str)]) -> Material {
        let mut m = Material::new(kind);
        m.params.extend(params.iter().map(|(k, v)| ((*k).to_string(), (*v).to_string())));
        m
    }

    /// Issue 27, bug 7: "emit" started at emission 0, so choosing it
    /// changed nothing on screen.
    #[test]
    fn switching_to_emit_gives_a_visible_emission() {
        let emitter = with(MaterialKind::Diffuse, &[("_rough", "0.3")]).switched_to(MaterialKind::Emit);
        assert_eq!((emitter.kind, emitter.emission(), emitter.roughness()), (MaterialKind::Emit, 1.0, 0.3));
        let dim = with(MaterialKind::Metal, &[("_emit", "0.25")]).switched_to(MaterialKind::Emit);
        assert_eq!(dim.emission(), 0.25, "a set emission is kept");
        assert_eq!(emitter.switched_to(MaterialKind::Glass).kind, MaterialKind::Glass);
    }

    #[test]
    fn transparency_comes_from_trans_then_alpha() {
        assert_eq!(with(MaterialKind::Glass, &[("_trans", "0.3"), ("_alpha", "0.8")]).transparency(), 0.3);
        assert_eq!(with(MaterialKind::Glass, &[("_alpha", "0.8")]).transparency(), 0.8);
        assert_eq!(with(MaterialKind::Glass, &[("_trans", "nan")]).transparency(), 1.0);
        assert_eq!(with(MaterialKind::Glass, &[]).transparency(), 1.0);
        assert_eq!(with(MaterialKind::Diffuse, &[]).transparency(), 0.0);
        assert_eq!(with(MaterialKind::Glass, &[("_trans", "7")]).transparency(), 1.0);
    }
}
