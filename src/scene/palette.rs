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

    /// Parses a `_type` value; unknown names (e.g. `_blend`) fall back to diffuse.
    pub fn from_vox_name(name: &str) -> MaterialKind {
        match name {
            "_metal" => MaterialKind::Metal,
            "_glass" => MaterialKind::Glass,
            "_emit" => MaterialKind::Emit,
            "_media" | "_cloud" => MaterialKind::Media,
            _ => MaterialKind::Diffuse,
        }
    }
}

/// One palette entry's material: the kind plus MagicaVoxel's MATL parameters.
///
/// Parameters are kept as the key/value strings of the MATL dictionary
/// (`_rough`, `_metal`, `_ior`, `_trans`, `_emit`, `_flux`, …) so that a
/// load → save → load round trip keeps every one, including keys octovox does
/// not interpret; typed accessors read the ones the renderer uses.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Material {
    pub kind: MaterialKind,
    /// MATL dictionary without `_type` (the kind holds that).
    pub params: BTreeMap<String, String>,
}

impl Material {
    pub fn new(kind: MaterialKind) -> Material {
        Material { kind, params: BTreeMap::new() }
    }

    fn param(&self, key: &str) -> Option<f32> {
        self.params.get(key).and_then(|v| v.trim().parse().ok())
    }

    pub fn roughness(&self) -> f32 {
        self.param("_rough").unwrap_or(0.1)
    }
    pub fn metalness(&self) -> f32 {
        self.param("_metal").unwrap_or(0.0)
    }
    pub fn ior(&self) -> f32 {
        self.param("_ior").map_or(1.5, |ior| if ior < 1.0 { ior + 1.0 } else { ior })
    }
    pub fn transparency(&self) -> f32 {
        self.param("_trans").unwrap_or(0.0)
    }
    pub fn emission(&self) -> f32 {
        self.param("_emit").unwrap_or(0.0)
    }
    pub fn flux(&self) -> f32 {
        self.param("_flux").unwrap_or(0.0)
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
