//! What the path tracer knows of each palette entry, and which effects a
//! scene calls for.
//!
//! The table is uploaded as it is (`GpuMaterial` is the twin of `Material`
//! in `shaders/path.wgsl`); the material codes reach WGSL through the
//! prelude. The effect set decides which code the kernel is compiled with.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::scene::{MaterialKind, Palette, VoxelCounts};

/// Material codes, shared with the shaders.
pub const MATERIAL_DIFFUSE: u32 = 0;
pub const MATERIAL_METAL: u32 = 1;
pub const MATERIAL_GLASS: u32 = 2;
pub const MATERIAL_EMIT: u32 = 3;

/// Radiance of an emissive voxel per unit of `_emit` at `_flux` 0: the
/// colour times `_emit · 2^_flux · EMIT_SCALE`. MagicaVoxel does not publish
/// its scale; this one lights a room from a lamp of a few voxels.
pub const EMIT_SCALE: f32 = 8.0;

/// One palette entry as the kernel reads it (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    pub kind: u32,
    pub roughness: f32,
    pub metalness: f32,
    pub ior: f32,
    pub transparency: f32,
    /// Radiance multiplier of the palette colour (0 unless emissive).
    pub emission: f32,
    pub _pad: [f32; 2],
}

/// The kernel's view of a palette entry. Media (clouds) render as diffuse:
/// see `docs/rendering.md`. An emitter with zero emission is diffuse.
pub fn gpu_material(palette: &Palette, index: u8) -> GpuMaterial {
    let material = palette.material(index);
    let emission = material.emission() * material.flux().exp2() * EMIT_SCALE;
    let kind = match material.kind {
        MaterialKind::Metal => MATERIAL_METAL,
        MaterialKind::Glass => MATERIAL_GLASS,
        MaterialKind::Emit if emission > 0.0 => MATERIAL_EMIT,
        _ => MATERIAL_DIFFUSE,
    };
    GpuMaterial {
        kind,
        roughness: material.roughness(),
        metalness: material.metalness(),
        ior: material.ior(),
        transparency: material.transparency(),
        emission: if kind == MATERIAL_EMIT { emission } else { 0.0 },
        _pad: [0.0; 2],
    }
}

/// The table of all 256 entries.
pub fn material_table(palette: &Palette) -> Vec<GpuMaterial> {
    (0..=255u8).map(|i| gpu_material(palette, i)).collect()
}

/// A palette colour as linear albedo in 0..=1.
pub fn albedo(palette: &Palette, index: u8) -> Vec3 {
    let c = palette.color(index);
    Vec3::new(f32::from(c[0]), f32::from(c[1]), f32::from(c[2])) / 255.0
}

/// The effects a path-traced frame simulates. Each is an override constant
/// of the kernel: an effect that is off has no code in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Effects {
    /// Sunlight: next-event estimation toward a sun of finite size.
    pub sun: bool,
    /// Light from the sky dome.
    pub sky: bool,
    /// Emissive voxels (and sampling them as lights).
    pub emit: bool,
    /// Metal: a GGX specular lobe.
    pub metal: bool,
    /// Glass: refraction and Fresnel reflection.
    pub glass: bool,
}

impl Effects {
    pub const ALL: Effects = Effects { sun: true, sky: true, emit: true, metal: true, glass: true };

    /// What a scene calls for: the materials of the voxels present, and the
    /// lights the user has on.
    pub fn of_scene(counts: &VoxelCounts, palette: &Palette, sun: bool, sky: bool) -> Effects {
        let mut effects = Effects { sun, sky, ..Effects::default() };
        for index in counts.present() {
            match gpu_material(palette, index).kind {
                MATERIAL_METAL => effects.metal = true,
                MATERIAL_GLASS => effects.glass = true,
                MATERIAL_EMIT => effects.emit = true,
                _ => {}
            }
        }
        effects
    }

    /// The names of the effects that are on, in a fixed order.
    pub fn names(&self) -> Vec<&'static str> {
        [("sun", self.sun), ("sky", self.sky), ("emit", self.emit), ("metal", self.metal), ("glass", self.glass)]
            .into_iter()
            .filter_map(|(name, on)| on.then_some(name))
            .collect()
    }

    /// The kernel's override constants.
    pub fn constants(&self) -> [(&'static str, f64); 5] {
        let flag = |on: bool| if on { 1.0 } else { 0.0 };
        [
            ("SUN", flag(self.sun)),
            ("SKY", flag(self.sky)),
            ("EMIT", flag(self.emit)),
            ("METAL", flag(self.metal)),
            ("GLASS", flag(self.glass)),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Octree};
    use glam::IVec3;

    #[test]
    fn effects_follow_the_materials_present() {
        let mut palette = Palette::default();
        palette.materials[3] = Material::new(MaterialKind::Glass);
        let mut emit = Material::new(MaterialKind::Emit);
        emit.params.insert("_emit".into(), "0.5".into());
        palette.materials[4] = emit;
        let tree = Octree::from_voxels(&[(IVec3::ZERO, 1), (IVec3::ONE, 3)]).unwrap();
        let effects = Effects::of_scene(tree.counts(), &palette, true, false);
        assert_eq!(effects.names(), ["sun", "glass"]);
        let tree = Octree::from_voxels(&[(IVec3::ZERO, 4)]).unwrap();
        assert_eq!(Effects::of_scene(tree.counts(), &palette, false, true).names(), ["sky", "emit"]);
    }

    #[test]
    fn an_emitter_without_emission_is_diffuse() {
        let mut palette = Palette::default();
        palette.materials[9] = Material::new(MaterialKind::Emit);
        assert_eq!(gpu_material(&palette, 9).kind, MATERIAL_DIFFUSE);
        palette.materials[9].params.insert("_emit".into(), "1".into());
        palette.materials[9].params.insert("_flux".into(), "2".into());
        let m = gpu_material(&palette, 9);
        assert_eq!((m.kind, m.emission), (MATERIAL_EMIT, 4.0 * EMIT_SCALE));
    }
}
