// Draws a texture onto the swapchain image with one triangle that covers the
// whole target: the trace output (possibly smaller, render-scaled), or a
// layer of the target's size over it. Used by src/gpu/blit_pass.rs.

@group(0) @binding(BINDING_SOURCE) var source: texture_2d<f32>;
@group(0) @binding(BINDING_SOURCE_SAMPLER) var source_sampler: sampler;

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

// A layer of the target's size, premultiplied alpha, texel for pixel (the
// pipeline blends it over the target).
@fragment
fn fs_over(in: VertexOut) -> @location(0) vec4<f32> {
    return textureLoad(source, vec2<i32>(in.position.xy), 0);
}
