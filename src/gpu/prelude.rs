//! The constants Rust and WGSL share, written as WGSL from their Rust
//! definitions and put in front of the shaders: one source, no copies kept
//! in step by hand.

use std::fmt::Write as _;

use super::layout::{FLOOR_ROW, GRID_MIX, HIGHLIGHT_MIX, HIGHLIGHT_TINT, ROW_TILES};
use crate::gpu_pool::{LOD_WORD, NODE_WORDS, POINTER_BIT};
use crate::scene::instances::{
    BVH_NODE_WORDS, BVH_STACK, EMPTY_BIT, INSTANCE_WORDS, NO_INSTANCE, SOLID_BOX_SLACK, TIE_T, TURNED_BIT,
};
use crate::settings::{SUN_DIR, View};
use crate::trace::denoise;
use crate::trace::path::{self, materials};
use crate::trace::render::GAVE_UP_COLOR;
use crate::trace::{GAVE_UP_RECORD, MIN_DIRECTION, NO_AXIS};

/// WGSL `const` declarations of every shared constant.
pub fn shared_constants() -> String {
    let vec3 = |v: [f32; 3]| format!("vec3<f32>({:?}, {:?}, {:?})", v[0], v[1], v[2]);
    let mut wgsl = String::from("// Generated from the Rust constants by src/gpu/prelude.rs.\n");
    let mut line = |name: &str, ty: &str, value: String| {
        // Writing to a String cannot fail.
        let _ = writeln!(wgsl, "const {name}: {ty} = {value};");
    };
    line("GAVE_UP_RECORD", "u32", format!("{GAVE_UP_RECORD:#x}u"));
    line("NO_AXIS", "u32", format!("{NO_AXIS}u"));
    line("MIN_DIRECTION", "f32", format!("{MIN_DIRECTION:?}"));
    line("POINTER_BIT", "u32", format!("{POINTER_BIT:#x}u"));
    line("NODE_WORDS", "u32", format!("{NODE_WORDS}u"));
    line("LOD_WORD", "u32", format!("{LOD_WORD}u"));
    line("BVH_NODE_WORDS", "u32", format!("{BVH_NODE_WORDS}u"));
    line("BVH_STACK", "u32", format!("{BVH_STACK}u"));
    line("EMPTY_BIT", "u32", format!("{EMPTY_BIT:#x}u"));
    line("INSTANCE_WORDS", "u32", format!("{INSTANCE_WORDS}u"));
    line("NO_INSTANCE", "u32", format!("{NO_INSTANCE:#x}u"));
    line("TIE_T", "f32", format!("{TIE_T:?}"));
    line("TURNED_BIT", "u32", format!("{TURNED_BIT:#x}u"));
    line("SOLID_BOX_SLACK", "f32", format!("{SOLID_BOX_SLACK:?}"));
    line("ROW_TILES", "u32", format!("{ROW_TILES}u"));
    line("FLOOR_ROW", "u32", format!("{FLOOR_ROW}u"));
    line("HIGHLIGHT_TINT", "vec3<f32>", vec3(HIGHLIGHT_TINT));
    line("HIGHLIGHT_MIX", "f32", format!("{HIGHLIGHT_MIX:?}"));
    line("GRID_MIX", "f32", format!("{GRID_MIX:?}"));
    line("SUN_DIR", "vec3<f32>", vec3(SUN_DIR));
    line("GAVE_UP_COLOR", "vec3<f32>", vec3(GAVE_UP_COLOR.to_array()));
    line("SUN_COS", "f32", format!("{:?}", path::sun_cos()));
    line("SUN_IRRADIANCE", "f32", format!("{:?}", path::SUN_IRRADIANCE));
    line("SUN_RADIANCE", "f32", format!("{:?}", path::sun_radiance()));
    line("GROUND_ALBEDO", "vec3<f32>", vec3(crate::trace::ground::GROUND_ALBEDO));
    line("GROUND_SURFACE", "u32", format!("{}u", path::GROUND_SURFACE));
    line("MAX_SAMPLE_RADIANCE", "f32", format!("{:?}", path::MAX_SAMPLE_RADIANCE));
    line("R2_STEP_X", "u32", format!("{}u", path::rng::R2_STEP[0]));
    line("R2_STEP_Y", "u32", format!("{}u", path::rng::R2_STEP[1]));
    line("R2_SHIFT_SEED", "u32", format!("{:#x}u", path::rng::R2_SHIFT_SEED));
    line("MAX_TRANSMISSIONS", "u32", format!("{}u", path::MAX_TRANSMISSIONS));
    line("TURNED_LIFT", "f32", format!("{:?}", path::TURNED_LIFT));
    line("TURNED_EMITTER_SLACK", "f32", format!("{:?}", path::lights::TURNED_EMITTER_SLACK));
    line("MIN_SAMPLED_ALPHA", "f32", format!("{:?}", path::MIN_SAMPLED_ALPHA));
    line("MATERIAL_DIFFUSE", "u32", format!("{}u", materials::MATERIAL_DIFFUSE));
    line("MATERIAL_METAL", "u32", format!("{}u", materials::MATERIAL_METAL));
    line("MATERIAL_GLASS", "u32", format!("{}u", materials::MATERIAL_GLASS));
    line("MATERIAL_EMIT", "u32", format!("{}u", materials::MATERIAL_EMIT));
    line("GUIDE_FILTERED", "u32", format!("{:#x}u", denoise::GUIDE_FILTERED));
    line("GUIDE_NORMAL_SHIFT", "u32", format!("{}u", denoise::GUIDE_NORMAL_SHIFT));
    line("GUIDE_NORMAL_STEPS", "f32", format!("{:?}", denoise::GUIDE_NORMAL_STEPS as f32));
    line("GUIDE_TURNED", "u32", format!("{:#x}u", denoise::GUIDE_TURNED));
    line("DENOISE_ITERATIONS", "u32", format!("{}u", denoise::ITERATIONS));
    line("SIGMA_LIGHT", "f32", format!("{:?}", denoise::SIGMA_LIGHT));
    line("SIGMA_PLANE", "f32", format!("{:?}", denoise::SIGMA_PLANE));
    line("SPATIAL_VARIANCE_BELOW", "u32", format!("{}u", denoise::SPATIAL_VARIANCE_BELOW));
    line("MIN_ALBEDO", "f32", format!("{:?}", denoise::MIN_ALBEDO));
    line("LUMINANCE", "vec3<f32>", vec3(denoise::LUMINANCE.to_array()));
    line("KERNEL_CENTRE", "f32", format!("{:?}", denoise::KERNEL_CENTRE));
    line("KERNEL_SIDE", "f32", format!("{:?}", denoise::KERNEL_SIDE));
    for (_, name, binding) in super::bindings::ALL {
        line(&format!("BINDING_{name}"), "u32", format!("{binding}u"));
    }
    for view in View::ALL {
        line(view.wgsl_name(), "u32", format!("{}u", view.code()));
    }
    wgsl
}

/// The overlay mix over a pixel (`overlaid`), which uses the constants.
const OVERLAY_WGSL: &str = include_str!("../../shaders/overlay.wgsl");

/// A shader's source with the shared constants and the overlay mix in front.
pub fn with_prelude(parts: &[&str]) -> String {
    let mut source = shared_constants();
    source.push('\n');
    source.push_str(OVERLAY_WGSL);
    for part in parts {
        source.push('\n');
        source.push_str(part);
    }
    source
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_are_written_as_wgsl() {
        let wgsl = shared_constants();
        assert!(wgsl.contains("const GAVE_UP_RECORD: u32 = 0xffffu;"), "{wgsl}");
        assert!(wgsl.contains("const POINTER_BIT: u32 = 0x80000000u;"), "{wgsl}");
        assert!(wgsl.contains("const MIN_DIRECTION: f32 = 1.1920929e-7;"), "{wgsl}");
        assert!(wgsl.contains("const VIEW_NORMALS: u32 = 3u;"), "{wgsl}");
    }
}
