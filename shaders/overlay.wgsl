// What the editor draws over a pixel's colour: the selection's (or the
// brush's) tint and the ground grid's lines, each by the share of the
// pixel's samples that showed it (0 or 1 in the preview). Shared by the
// preview (common.wgsl), the path tracer's raw output (path.wgsl) and the
// denoised one (denoise.wgsl); put in front of every shader by
// `with_prelude`, after the constants it uses.
fn overlaid(rgb: vec3<f32>, tint: f32, grid: f32) -> vec3<f32> {
    return mix(mix(rgb, HIGHLIGHT_TINT, HIGHLIGHT_MIX * tint), vec3<f32>(1.0), GRID_MIX * grid);
}
