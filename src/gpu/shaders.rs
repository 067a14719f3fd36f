//! Which WGSL files make which shader module: the one list the passes
//! build their modules from, and the layout test reads (`layout.rs`).

use super::prelude::with_prelude;

const COMMON: &str = include_str!("../../shaders/common.wgsl");
const SVO: &str = include_str!("../../shaders/trace_svo.wgsl");
const INSTANCES: &str = include_str!("../../shaders/instances.wgsl");
const GRID: &str = include_str!("../../shaders/trace_grid.wgsl");
const FLOOR: &str = include_str!("../../shaders/floor.wgsl");
const PATH: &str = include_str!("../../shaders/path.wgsl");
const DENOISE: &str = include_str!("../../shaders/denoise.wgsl");
const BLIT: &str = include_str!("../../shaders/blit.wgsl");

/// A shader module octovox compiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Module {
    /// The preview's octree and instance walk (`TracePass`).
    TraceSvo,
    /// The dense grid's DDA baseline (`TracePass`).
    TraceGrid,
    /// Everything a frame does but the traversal (`TracePass`).
    Floor,
    /// The path tracer (`PathPass`).
    Path,
    /// The à-trous filter (`DenoisePass`).
    Denoise,
    /// The image onto the window (`BlitPass`).
    Blit,
}

impl Module {
    pub const ALL: [Module; 6] =
        [Module::TraceSvo, Module::TraceGrid, Module::Floor, Module::Path, Module::Denoise, Module::Blit];

    /// The label its shader carries (the file of its entry points).
    pub fn label(self) -> &'static str {
        match self {
            Module::TraceSvo => "trace_svo.wgsl",
            Module::TraceGrid => "trace_grid.wgsl",
            Module::Floor => "floor.wgsl",
            Module::Path => "path.wgsl",
            Module::Denoise => "denoise.wgsl",
            Module::Blit => "blit.wgsl",
        }
    }

    /// Its WGSL: the shared constants and overlay prelude (where it has
    /// one), then its files in order.
    pub fn source(self) -> String {
        match self {
            Module::TraceSvo => with_prelude(&[COMMON, SVO, INSTANCES]),
            Module::TraceGrid => with_prelude(&[COMMON, GRID]),
            Module::Floor => with_prelude(&[COMMON, FLOOR]),
            Module::Path => with_prelude(&[COMMON, SVO, INSTANCES, PATH]),
            Module::Denoise => with_prelude(&[DENOISE]),
            Module::Blit => with_prelude(&[BLIT]),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use std::mem::{offset_of, size_of};

    use super::Module;
    use crate::gpu::layout::{DenoiseUniforms, FrameUniforms, PathUniforms};
    use crate::trace::path::lights::Emitter;
    use crate::trace::path::materials::GpuMaterial;
    use wgpu::naga;

    /// A Rust struct that a WGSL struct of the same name in `module` must
    /// match byte for byte: its size and each member's offset.
    struct Twin {
        module: Module,
        wgsl: &'static str,
        size: usize,
        offsets: Vec<(&'static str, usize)>,
    }

    macro_rules! twin {
        ($module:expr, $wgsl:literal, $ty:ty, [$($field:ident),* $(,)?]) => {
            Twin {
                module: $module,
                wgsl: $wgsl,
                size: size_of::<$ty>(),
                offsets: vec![$((stringify!($field), offset_of!($ty, $field))),*],
            }
        };
    }

    fn twins() -> Vec<Twin> {
        vec![
            twin!(
                Module::TraceSvo,
                "FrameUniforms",
                FrameUniforms,
                [
                    eye,
                    root,
                    forward,
                    depth,
                    right,
                    view,
                    up,
                    width,
                    grid_min,
                    height,
                    grid_dims,
                    highlight_on,
                    highlight_min,
                    hit_records,
                    highlight_max,
                    brick_base,
                    max_iterations,
                    lod_per_t,
                    ortho,
                    lod_at_start,
                    ground_on,
                    ground_step,
                    ground_y,
                    ground_x0,
                    ground_x1,
                    ground_z0,
                    ground_z1,
                    instance_nodes,
                    plane_on,
                    plane_y,
                ]
            ),
            twin!(
                Module::Path,
                "PathUniforms",
                PathUniforms,
                [
                    sky_horizon,
                    sample_index,
                    sky_zenith,
                    bounces,
                    shadow_samples,
                    emitter_count,
                    first_row,
                    end_row,
                    first_sample,
                ]
            ),
            twin!(
                Module::Denoise,
                "DenoiseUniforms",
                DenoiseUniforms,
                [eye, width, forward, height, at_start, per_t, step, light,]
            ),
            twin!(Module::Path, "Material", GpuMaterial, [kind, roughness, metalness, ior, transparency, emission]),
            twin!(Module::Path, "Emitter", Emitter, [min, size, cdf, index, instance]),
        ]
    }

    /// The members of struct `name` in `module`'s WGSL, as naga lays them
    /// out (name, offset), and its size.
    fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
        let (_, ty) = module.types.iter().find(|(_, ty)| ty.name.as_deref() == Some(name)).unwrap();
        let naga::TypeInner::Struct { members, span } = &ty.inner else { panic!("{name} is not a struct") };
        (members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(), *span)
    }

    /// Issue 46, item 4: `FrameUniforms` had no size or offset check (only
    /// `PathUniforms` had one). Every struct the passes bind is parsed from
    /// the WGSL the GPU compiles, and its size and every member's offset
    /// must equal the Rust twin's; a WGSL member the twin lacks fails too
    /// (`_pad…` members excepted: the twin pads as it likes).
    #[test]
    fn every_bound_struct_matches_its_rust_twin_byte_for_byte() {
        for twin in twins() {
            let source = twin.module.source();
            let module =
                naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}: {e}", twin.module.label()));
            let (members, span) = wgsl_layout(&module, twin.wgsl);
            assert_eq!(span as usize, twin.size, "{}: WGSL size {span}, Rust {}", twin.wgsl, twin.size);
            for (name, offset) in members.iter().filter(|(name, _)| !name.starts_with("_pad")) {
                let rust = twin.offsets.iter().find(|(field, _)| field == name).map(|(_, at)| *at);
                assert_eq!(rust, Some(*offset as usize), "{}.{name}: WGSL offset {offset}, Rust {rust:?}", twin.wgsl);
            }
        }
    }

    /// Issue 46, item 4: the path module concatenated trace_svo.wgsl
    /// (binding 12: `traced`) and path.wgsl (binding 12: `guides`), and
    /// binding numbers were literals on both sides. Every bound variable of
    /// every module now has the number `bindings::ALL` gives its name (the
    /// passes bind by the same constants), and no module binds two
    /// variables to one slot.
    #[test]
    fn every_bound_variable_has_its_number_from_the_one_table() {
        use crate::gpu::bindings::ALL;
        for module in Module::ALL {
            let parsed = naga::front::wgsl::parse_str(&module.source()).unwrap_or_else(|e| panic!("{module:?}: {e}"));
            let mut seen = std::collections::HashMap::new();
            for (_, var) in parsed.global_variables.iter() {
                let (Some(binding), Some(name)) = (&var.binding, &var.name) else { continue };
                let number = ALL.iter().find(|(variable, ..)| variable == name).map(|(.., number)| *number);
                assert_eq!(number, Some(binding.binding), "{module:?}: `{name}` is bound at {binding:?}");
                if let Some(other) = seen.insert((binding.group, binding.binding), name.clone()) {
                    panic!("{module:?}: `{other}` and `{name}` share {binding:?}");
                }
            }
        }
    }
}
