// Copies the trace output onto the swapchain image: one triangle that covers
// the whole target, sampling the (possibly smaller, render-scaled) texture.
// Used by src/gpu/blit_pass.rs.

@group(0) @binding(0) var source: texture_2d<f32>;
@group(0) @binding(1) var source_sampler: sampler;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// Vertices (-1,-1), (3,-1), (-1,3): a triangle whose inside is the screen.
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    let x = f32((index << 1u) & 2u);
    let y = f32(index & 2u);
    var out: VertexOut;
    out.position = vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
    // uv (0,0) is the top-left texel, as in the trace output.
    out.uv = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // The trace output already holds display (sRGB-encoded) values and the
    // swapchain is a non-sRGB format, so the bytes pass through unchanged.
    return vec4<f32>(textureSample(source, source_sampler, in.uv).rgb, 1.0);
}
