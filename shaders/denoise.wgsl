// The denoiser: an edge-avoiding à-trous wavelet filter over the path
// tracer's accumulation, and the noise estimate. Twin of
// src/trace/denoise.rs (the CPU reference, whose comment explains the
// filter): the same taps in the same order, so change both together.
// Prefixed with the shared constants only.
//
// Three entry points, dispatched in turn by src/gpu/denoise_pass.rs:
// `prepare` (demodulated light and its variance, and each workgroup's sum of
// the displayed variance), `atrous` (DENOISE_ITERATIONS times, ping-ponging
// between two light buffers) and `finish` (light times albedo, to the
// display texture).

// Twin of `DenoiseUniforms` in src/gpu/layout.rs.
struct DenoiseUniforms {
    eye: vec3<f32>,
    width: u32,
    forward: vec3<f32>,
    height: u32,
    at_start: f32,
    per_t: f32,
    // Pixels between the taps of this `atrous` dispatch.
    step: u32,
    // 1: `prepare` writes the light (the filter follows); 0: only the noise
    // estimate's sums.
    light: u32,
}

@group(0) @binding(BINDING_DENOISE_CONSTANTS) var<storage, read> constants: DenoiseUniforms;
var<private> du: DenoiseUniforms;
// Three vec4 per pixel (shaders/path.wgsl): sum and count, sum of
// squares, sum of the first hits' albedo.
@group(0) @binding(BINDING_ACCUM) var<storage, read> accum: array<vec4<f32>>;
@group(0) @binding(BINDING_GUIDES) var<storage, read> guides: array<vec4<u32>>;
// Demodulated light and the variance of its luminance, per pixel.
@group(0) @binding(BINDING_LIGHT_IN) var<storage, read> light_in: array<vec4<f32>>;
@group(0) @binding(BINDING_LIGHT_OUT) var<storage, read_write> light_out: array<vec4<f32>>;
@group(0) @binding(BINDING_OUT_COLOR) var out_color: texture_storage_2d<rgba8unorm, write>;
// One sum of displayed variance per `prepare` workgroup.
@group(0) @binding(BINDING_PARTIALS) var<storage, read_write> partials: array<f32>;

fn code_of(i: u32) -> u32 {
    return guides[i].w;
}

fn point_of(i: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(guides[i].xyz);
}

fn is_filtered(code: u32) -> bool {
    return (code & GUIDE_FILTERED) != 0u;
}

fn sign_not_zero(v: f32) -> f32 {
    return select(1.0, -1.0, v < 0.0);
}

// The face's unit normal: its axis, or a freely turned face's own from
// its octahedral coordinates (twin of `Guide::normal`).
fn normal_of(code: u32) -> vec3<f32> {
    let axis_code = code & 7u;
    if ((code & GUIDE_TURNED) == 0u) {
        let on_axis = vec3<u32>(0u, 1u, 2u) == vec3<u32>((axis_code - 1u) / 2u);
        return select(vec3<f32>(0.0), vec3<f32>(select(-1.0, 1.0, axis_code % 2u == 1u)), on_axis);
    }
    let bits = code >> GUIDE_NORMAL_SHIFT;
    let uv = vec2<f32>(vec2<u32>(bits & 0xfffu, (bits >> 12u) & 0xfffu)) / GUIDE_NORMAL_STEPS * 2.0 - 1.0;
    let z = 1.0 - abs(uv.x) - abs(uv.y);
    var xy = uv;
    if (z < 0.0) {
        xy = vec2<f32>((1.0 - abs(uv.y)) * sign_not_zero(uv.x), (1.0 - abs(uv.x)) * sign_not_zero(uv.y));
    }
    return normalize(vec3<f32>(xy, z));
}

// Facing the same way: the same nearest axis (a test at every tap, kept to
// one comparison; the plane test reads a turned face's own normal).
fn same_surface(p: u32, q: u32) -> bool {
    return is_filtered(q) && (q & 7u) == (p & 7u);
}

fn count_of(i: u32) -> f32 {
    return accum[3u * i].w;
}

fn mean_of(i: u32) -> vec3<f32> {
    return accum[3u * i].rgb / max(count_of(i), 1.0);
}

// Twin of `Sums::albedo`.
fn albedo_of(i: u32) -> vec3<f32> {
    return max(accum[3u * i + 2u].rgb / max(count_of(i), 1.0), vec3<f32>(MIN_ALBEDO));
}

// Twin of `Sums::variance_of_mean`.
fn variance_of_mean(i: u32) -> vec3<f32> {
    let n = count_of(i);
    if (n < 2.0) {
        return vec3<f32>(0.0);
    }
    let mean = accum[3u * i].rgb / n;
    return max((accum[3u * i + 1u].rgb / n - mean * mean) / (n - 1.0), vec3<f32>(0.0));
}

// Twin of `displayed_variance`.
fn displayed_variance(i: u32) -> f32 {
    let shown = select(vec3<f32>(0.0), vec3<f32>(1.0), mean_of(i) < vec3<f32>(1.0));
    let v = variance_of_mean(i) * shown;
    return v.x + v.y + v.z;
}

fn pixel_index(x: i32, y: i32) -> u32 {
    return u32(y) * du.width + u32(x);
}

fn inside(x: i32, y: i32) -> bool {
    return x >= 0 && y >= 0 && x < i32(du.width) && y < i32(du.height);
}

fn demodulated(i: u32) -> vec3<f32> {
    return mean_of(i) / albedo_of(i);
}

// Twin of one pixel of `prepare`.
fn prepared(px: vec2<i32>) -> vec4<f32> {
    let i = pixel_index(px.x, px.y);
    let p = code_of(i);
    if (!is_filtered(p)) {
        return vec4<f32>(mean_of(i), 0.0);
    }
    var variance: f32;
    if (u32(count_of(i)) < SPATIAL_VARIANCE_BELOW) {
        var m1 = 0.0;
        var m2 = 0.0;
        var n = 0.0;
        for (var dy = -1; dy <= 1; dy += 1) {
            for (var dx = -1; dx <= 1; dx += 1) {
                let q = px + vec2<i32>(dx, dy);
                if (inside(q.x, q.y) && same_surface(p, code_of(pixel_index(q.x, q.y)))) {
                    let l = dot(demodulated(pixel_index(q.x, q.y)), LUMINANCE);
                    m1 += l;
                    m2 += l * l;
                    n += 1.0;
                }
            }
        }
        variance = max(m2 / n - (m1 / n) * (m1 / n), 0.0);
    } else {
        let w = LUMINANCE / albedo_of(i);
        let v = variance_of_mean(i) * w * w;
        variance = v.x + v.y + v.z;
    }
    return vec4<f32>(demodulated(i), variance);
}

var<workgroup> scratch: array<f32, 64>;

@compute @workgroup_size(8, 8)
fn prepare(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    du = constants;
    var shown = 0.0;
    if (gid.x < du.width && gid.y < du.height) {
        let px = vec2<i32>(gid.xy);
        shown = displayed_variance(pixel_index(px.x, px.y));
        if (du.light != 0u) {
            light_out[pixel_index(px.x, px.y)] = prepared(px);
        }
    }
    scratch[local] = shown;
    workgroupBarrier();
    for (var half = 32u; half > 0u; half >>= 1u) {
        if (local < half) {
            scratch[local] += scratch[local + half];
        }
        workgroupBarrier();
    }
    if (local == 0u) {
        partials[group.y * groups.x + group.x] = scratch[0];
    }
}

// Twin of `kernel`.
fn kernel(d: i32) -> f32 {
    return select(KERNEL_SIDE, KERNEL_CENTRE, d == 0);
}

// Twin of `blurred_variance`.
fn blurred_variance(px: vec2<i32>, p: u32) -> f32 {
    var sum = 0.0;
    var weight = 0.0;
    for (var dy = -1; dy <= 1; dy += 1) {
        for (var dx = -1; dx <= 1; dx += 1) {
            let q = px + vec2<i32>(dx, dy);
            if (inside(q.x, q.y)) {
                let j = pixel_index(q.x, q.y);
                if (same_surface(p, code_of(j))) {
                    let k = kernel(dx) * kernel(dy);
                    sum += k * light_in[j].w;
                    weight += k;
                }
            }
        }
    }
    return sum / weight;
}

@compute @workgroup_size(8, 8)
fn atrous(@builtin(global_invocation_id) gid: vec3<u32>) {
    du = constants;
    if (gid.x >= du.width || gid.y >= du.height) {
        return;
    }
    let px = vec2<i32>(gid.xy);
    let i = pixel_index(px.x, px.y);
    let p = code_of(i);
    if (!is_filtered(p)) {
        light_out[i] = light_in[i];
        return;
    }
    var variance_p = light_in[i].w;
    if (du.step == 1u) {
        variance_p = blurred_variance(px, p);
    }
    let luminance = dot(light_in[i].rgb, LUMINANCE);
    let point = point_of(i);
    let normal = normal_of(p);
    let pixel_width = du.at_start + du.per_t * max(dot(point - du.eye, du.forward), 0.0);
    let step = i32(du.step);
    let plane_scale = SIGMA_PLANE * pixel_width * f32(step);
    var rgb = vec3<f32>(0.0);
    var variance = 0.0;
    var weight = 0.0;
    for (var dy = -1; dy <= 1; dy += 1) {
        for (var dx = -1; dx <= 1; dx += 1) {
            let q = px + vec2<i32>(dx, dy) * step;
            if (!inside(q.x, q.y)) {
                continue;
            }
            let j = pixel_index(q.x, q.y);
            if (!same_surface(p, code_of(j))) {
                continue;
            }
            let off_plane = abs(dot(normal, point_of(j) - point));
            let distance = sqrt(f32(dx * dx + dy * dy));
            let w_plane = exp(-off_plane / (plane_scale * distance + 1e-6));
            let sigma = SIGMA_LIGHT * sqrt(variance_p + light_in[j].w) + 1e-6;
            let w_light = exp(-abs(dot(light_in[j].rgb, LUMINANCE) - luminance) / sigma);
            let w = kernel(dx) * kernel(dy) * w_plane * w_light;
            rgb += w * light_in[j].rgb;
            variance += w * w * light_in[j].w;
            weight += w;
        }
    }
    light_out[i] = vec4<f32>(rgb / weight, variance / (weight * weight));
}

@compute @workgroup_size(8, 8)
fn finish(@builtin(global_invocation_id) gid: vec3<u32>) {
    du = constants;
    if (gid.x >= du.width || gid.y >= du.height) {
        return;
    }
    let i = pixel_index(i32(gid.x), i32(gid.y));
    let p = code_of(i);
    let rgb = select(mean_of(i), light_in[i].rgb * albedo_of(i), is_filtered(p));
    // The tint and the grid by the shares of samples that showed them,
    // counted beside the albedo and squares sums (see `path` in path.wgsl).
    let n = max(count_of(i), 1.0);
    let shown = overlaid(rgb, accum[3u * i + 2u].w / n, accum[3u * i + 1u].w / n);
    textureStore(out_color, vec2<i32>(gid.xy), vec4<f32>(shown, 1.0));
}
