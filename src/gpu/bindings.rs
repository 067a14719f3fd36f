//! The binding number of every variable the shaders bind, by the
//! variable's name: the one source for the passes' layouts and bind groups
//! and for the WGSL, where the prelude writes each as a `const`
//! (`BINDING_POOL` for `POOL`, the binding of `pool`) that `@binding(...)`
//! names. A module that
//! concatenates files (the path module holds the trace module's variables)
//! can therefore never bind two variables to one number, and the layout
//! test checks every bound variable of every module against [`ALL`].

macro_rules! bindings {
    ($($name:ident = $number:literal, $variable:literal;)*) => {
        $(
            #[doc = concat!("`", $variable, "`")]
            pub const $name: u32 = $number;
        )*
        /// Every bound variable's name, its constant's name (the WGSL's is
        /// `BINDING_` and it) and its binding number.
        pub const ALL: &[(&str, &str, u32)] = &[$(($variable, stringify!($name), $number)),*];
    };
}

bindings! {
    // Group 0 of the trace and path modules (`shaders/common.wgsl`,
    // `trace_svo.wgsl`, `path.wgsl`).
    FRAME_CONSTANTS = 0, "frame_constants";
    POOL = 1, "pool";
    INSTANCES = 2, "instances";
    PALETTE = 3, "palette";
    GRID = 4, "grid";
    OUT_COLOR = 5, "out_color";
    HIT_RECORDS = 6, "hit_records";
    BEAM_DISTANCE = 7, "beam_distance";
    PATH_CONSTANTS = 8, "path_constants";
    MATERIALS = 9, "materials";
    EMITTERS = 10, "emitters";
    ACCUM = 11, "accum";
    GUIDES = 12, "guides";
    TRACED = 13, "traced";
    // The denoiser's own (it reads `accum` and `guides` and writes
    // `out_color` under the path module's numbers).
    DENOISE_CONSTANTS = 14, "constants";
    LIGHT_IN = 15, "light_in";
    LIGHT_OUT = 16, "light_out";
    PARTIALS = 17, "partials";
    // The blit.
    SOURCE = 18, "source";
    SOURCE_SAMPLER = 19, "source_sampler";
    // Group 1 of the trace module: the indirect dispatch's arguments.
    DISPATCH_ARGS = 0, "dispatch_args";
}
