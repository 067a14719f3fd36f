// The progressive path tracer: one sample per pixel per dispatch, added to
// an accumulation buffer; the display texture gets the mean. Twin of
// src/trace/path/mod.rs (the CPU reference): the same draws from the same
// counter-based random numbers, in the same order, so change both
// together. Prefixed with common.wgsl, trace_svo.wgsl and
// instances.wgsl.
//
// The effects are override constants: a kernel built for a scene of diffuse
// voxels has no metal, glass or emitter code at all.

override SUN: bool = true;
override SKY: bool = true;
override EMIT: bool = true;
override METAL: bool = true;
override GLASS: bool = true;

const PI: f32 = 3.14159265358979;

// Twin of `PathUniforms` in src/gpu/layout.rs.
struct PathUniforms {
    sky_horizon: vec3<f32>,
    // Index of this frame's sample: 0 restarts the accumulation.
    sample_index: u32,
    sky_zenith: vec3<f32>,
    bounces: u32,
    shadow_samples: u32,
    emitter_count: u32,
    // This dispatch traces the rows first_row..end_row (a band of the
    // image; the window spreads a sample over several frames on slow
    // adapters).
    first_row: u32,
    end_row: u32,
    // Added to sample_index in the random sequences: the seed's first sample.
    first_sample: u32,
}

// Twin of `GpuMaterial` in src/trace/path/materials.rs.
struct Material {
    kind: u32,
    roughness: f32,
    metalness: f32,
    ior: f32,
    transparency: f32,
    emission: f32,
    _pad0: f32,
    _pad1: f32,
}

// Twin of `Emitter` in src/trace/path/lights.rs.
struct Emitter {
    min: vec3<i32>,
    size: u32,
    cdf: f32,
    index: u32,
    // The freely turned object whose model cell this is, or NO_INSTANCE.
    instance: u32,
    _pad: u32,
}

@group(0) @binding(BINDING_PATH_CONSTANTS) var<storage, read> path_constants: PathUniforms;
// Read once per invocation, like `u` (common.wgsl, `load_constants`).
var<private> pu: PathUniforms;
@group(0) @binding(BINDING_MATERIALS) var<storage, read> materials: array<Material>;
@group(0) @binding(BINDING_EMITTERS) var<storage, read> emitters: array<Emitter>;
// Three vec4 per pixel: the sum of the samples and their count, the sum of
// their squares (the denoiser's variance and the noise estimate), and the
// sum of their first hits' `demodulation_albedo`.
@group(0) @binding(BINDING_ACCUM) var<storage, read_write> accum: array<vec4<f32>>;
// The denoiser's guide per pixel (twin of `Guide` in src/trace/denoise.rs):
// the point where the centre ray enters a face, as bits, then the code.
@group(0) @binding(BINDING_GUIDES) var<storage, read_write> guides: array<vec4<u32>>;

// The first hit's `demodulation_albedo` of the path being traced.
var<private> first_albedo: vec3<f32>;
// 1 when the sample's first hit is a highlighted voxel (the selection).
var<private> first_tint: f32;
// The t of the camera ray's first voxel (NO_VOXEL_T for none): what hides the ground grid.
var<private> first_t: f32;

// Whether the denoiser leaves a pixel whose first hit is of `kind` to its
// samples (twin of `PathScene::left_to_samples`).
fn left_to_samples(kind: u32) -> bool {
    return (EMIT && kind == MATERIAL_EMIT) || (GLASS && kind == MATERIAL_GLASS) || (METAL && kind == MATERIAL_METAL);
}

// Twin of `PathScene::demodulation_albedo`.
fn demodulation_albedo(value: u32) -> vec3<f32> {
    return select(surface_albedo(value), vec3<f32>(1.0), left_to_samples(material_of(value).kind));
}

// ---- random numbers (twin of src/trace/path/rng.rs) ----

fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

var<private> rng_state: u32;

fn rng_init(pixel: u32, sample: u32) {
    rng_state = pcg(pixel ^ pcg(sample + 0x9e3779b9u));
}

fn rng_next() -> f32 {
    rng_state = pcg(rng_state);
    return f32(rng_state >> 8u) * (1.0 / 16777216.0);
}

// Where a sample falls in its pixel: the R2 sequence shifted per pixel
// (twin of `pixel_offset` in src/trace/path/rng.rs, which says why).
fn pixel_offset(pixel: u32, sample: u32) -> vec2<f32> {
    let shift_x = pcg(pixel ^ R2_SHIFT_SEED);
    let shift_y = pcg(shift_x);
    let x = shift_x + sample * R2_STEP_X;
    let y = shift_y + sample * R2_STEP_Y;
    return vec2<f32>(f32(x >> 8u), f32(y >> 8u)) * (1.0 / 16777216.0);
}

// ---- directions ----

// An orthonormal basis around a unit vector (Duff et al., 2017).
fn around(n: vec3<f32>, cos_theta: f32, phi: f32) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = vec3<f32>(b, sign + n.y * n.y * a, -n.y);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    return (t * cos(phi) + bt * sin(phi)) * sin_theta + n * cos_theta;
}

fn cosine_direction(n: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    return around(n, sqrt(1.0 - u1), 2.0 * PI * u2);
}

fn cone_direction(axis: vec3<f32>, cos_max: f32, u1: f32, u2: f32) -> vec3<f32> {
    return around(axis, 1.0 - u1 * (1.0 - cos_max), 2.0 * PI * u2);
}

fn ggx_half_vector(n: vec3<f32>, alpha: f32, u1: f32, u2: f32) -> vec3<f32> {
    let cos2 = (1.0 - u1) / (1.0 + (alpha * alpha - 1.0) * u1);
    return around(n, sqrt(max(cos2, 0.0)), 2.0 * PI * u2);
}

fn reflect_about(d: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return d - 2.0 * dot(d, n) * n;
}

fn fresnel_dielectric(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

fn smith_g1(c: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    return 2.0 * c / (c + sqrt(a2 + (1.0 - a2) * c * c));
}

// ---- the scene ----

// A surface's material: its palette entry's, or the ground's (diffuse,
// as `PathScene` has it).
fn material_of(index: u32) -> Material {
    if (index == GROUND_SURFACE) {
        return Material(MATERIAL_DIFFUSE, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    }
    return materials[index];
}

fn is_glass(index: u32) -> bool {
    return material_of(index).kind == MATERIAL_GLASS;
}

fn ior_of(index: u32) -> f32 {
    return select(materials[index].ior, 1.0, index == 0u);
}

// The point where the ray enters the voxel it found: on the entered face's
// plane exactly (twin of `surface_point`).
fn surface_point(r: Ray, hit: Hit) -> vec3<f32> {
    if (hit.turned) {
        // A turned face lies on no plane of the grid.
        return r.o + r.d * hit.t;
    }
    let lo = vec3<f32>(hit.voxel);
    var p = clamp(r.o + r.d * hit.t, lo, lo + vec3<f32>(1.0));
    let axis = (hit.normal_code - 1u) / 2u;
    p[axis] = lo[axis] + select(0.0, 1.0, hit.normal_code % 2u == 1u);
    return p;
}

// How far a ray leaving the face `hit` starts off it (twin of `lift_of` in
// src/trace/path/mod.rs): TURNED_LIFT of the point's size on a turned face.
fn lift_of(hit: Hit, p: vec3<f32>) -> f32 {
    let a = abs(p);
    return select(0.0, TURNED_LIFT * max(max(max(a.x, a.y), a.z), 1.0), hit.turned);
}

// Where a ray in direction `dir` leaving the face at `p` (normal `n`)
// starts: `lift` off the face, on the side `dir` goes to (twin of `leave`).
fn leave(p: vec3<f32>, n: vec3<f32>, lift: f32, dir: vec3<f32>) -> vec3<f32> {
    return p + n * select(-lift, lift, dot(dir, n) >= 0.0);
}

fn environment(dir: vec3<f32>, lights_counted: bool) -> vec3<f32> {
    let d = normalize(dir);
    var radiance = vec3<f32>(0.0);
    if (SKY) {
        radiance += mix(pu.sky_horizon, pu.sky_zenith, clamp(d.y * 0.5 + 0.5, 0.0, 1.0));
    }
    if (SUN && !lights_counted && dot(d, SUN_DIR) >= SUN_COS) {
        radiance += vec3<f32>(SUN_RADIANCE);
    }
    return radiance;
}

// ---- lights ----

fn pick_emitter(u0: f32) -> u32 {
    let count = pu.emitter_count;
    let target_cdf = u0 * emitters[count - 1u].cdf;
    var lo = 0u;
    var hi = count - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (emitters[mid].cdf <= target_cdf) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The reflectance a light sample is weighted by (twin of `Lobe`).
struct Lobe {
    glossy: bool,
    alpha: f32,
    f0: vec3<f32>,
    v: vec3<f32>,
}

fn diffuse_lobe() -> Lobe {
    return Lobe(false, 1.0, vec3<f32>(0.0), vec3<f32>(0.0));
}

fn glossy_lobe(v: vec3<f32>, albedo: vec3<f32>, m: Material) -> Lobe {
    return Lobe(true, m.roughness * m.roughness, mix(vec3<f32>(0.04), albedo, m.metalness), v);
}

fn lobe_eval(lobe: Lobe, n: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    if (!lobe.glossy) {
        return vec3<f32>(1.0 / PI);
    }
    let h = normalize(lobe.v + l);
    let cos_v = dot(n, lobe.v);
    let cos_l = dot(n, l);
    let cos_h = dot(n, h);
    if (cos_v <= 0.0 || cos_l <= 0.0) {
        return vec3<f32>(0.0);
    }
    let a2 = lobe.alpha * lobe.alpha;
    let k = cos_h * cos_h * (a2 - 1.0) + 1.0;
    let ggx = a2 / (PI * k * k);
    let g = smith_g1(cos_v, lobe.alpha) * smith_g1(cos_l, lobe.alpha);
    let x = 1.0 - max(dot(lobe.v, h), 0.0);
    let fresnel = lobe.f0 + (vec3<f32>(1.0) - lobe.f0) * (x * x * x * x * x);
    return fresnel * (ggx * g / (4.0 * cos_v * cos_l));
}

// One sample of an emissive cell: a cell picked by power, one of its faces
// that faces p, a point on it. A turned lamp's cell is sampled in its
// model's frame (a rigid map: the same distances). Twin of `emitter_light`.
fn emitter_light(p: vec3<f32>, n: vec3<f32>, lobe: Lobe) -> vec3<f32> {
    let u0 = rng_next();
    let u1 = rng_next();
    let u2 = rng_next();
    let u3 = rng_next();
    let i = pick_emitter(u0);
    let e = emitters[i];
    let turned = e.instance != NO_INSTANCE;
    var inst: Instance;
    var at = p;
    if (turned) {
        inst = load_instance(e.instance);
        at = p * inst.rows + inst.t;
    }
    let lo = vec3<f32>(e.min);
    let hi = lo + vec3<f32>(f32(e.size));
    let below = at < lo;
    let above = at > hi;
    let facing = below | above;
    let faces = u32(facing.x) + u32(facing.y) + u32(facing.z);
    if (faces == 0u) {
        return vec3<f32>(0.0);
    }
    let pick = min(u32(u1 * f32(faces)), faces - 1u);
    // The pick-th facing axis.
    var axis = 0u;
    var seen = 0u;
    for (var a = 0u; a < 3u; a++) {
        if (facing[a]) {
            if (seen == pick) {
                axis = a;
            }
            seen += 1u;
        }
    }
    let b = (axis + 1u) % 3u;
    let c = (axis + 2u) % 3u;
    var q = vec3<f32>(0.0);
    q[axis] = select(hi[axis], lo[axis], below[axis]);
    q[b] = lo[b] + u2 * (hi[b] - lo[b]);
    q[c] = lo[c] + u3 * (hi[c] - lo[c]);
    let w = q - at;
    let dist2 = dot(w, w);
    let towards = w / sqrt(dist2);
    var l = towards;
    if (turned) {
        l = inst.rows * towards;
    }
    let cos_s = dot(n, l);
    let cos_l = abs(towards[axis]);
    if (cos_s <= 0.0 || dist2 <= 0.0) {
        return vec3<f32>(0.0);
    }
    let shadow = trace_scene(make_ray(p, l), 0.0, 0u, NO_INSTANCE, vec2<f32>(0.0));
    var reached = false;
    if (turned) {
        // The hit in the model's frame, in the sampled cell (twin of `holds_point`).
        let m = at + towards * shadow.t;
        let slack = vec3<f32>(TURNED_EMITTER_SLACK);
        let same = shadow.instance == e.instance && shadow.value == e.index;
        reached = shadow.found && same && all(m >= lo - slack) && all(m <= hi + slack);
    } else {
        let rel = shadow.voxel - e.min;
        reached = shadow.found && all(rel >= vec3<i32>(0)) && all(rel < vec3<i32>(i32(e.size)));
    }
    if (!reached) {
        return vec3<f32>(0.0);
    }
    let before = select(emitters[max(i, 1u) - 1u].cdf, 0.0, i == 0u);
    let size = f32(e.size);
    let pdf = (e.cdf - before) / emitters[pu.emitter_count - 1u].cdf / (f32(faces) * size * size);
    let radiance = surface_albedo(e.index) * materials[e.index].emission;
    return radiance * lobe_eval(lobe, n, l) * (cos_s * cos_l / (dist2 * pdf));
}

// Light reflected at p by `lobe` toward the path (twin of `direct`).
fn direct(p: vec3<f32>, n: vec3<f32>, lobe: Lobe) -> vec3<f32> {
    var light = vec3<f32>(0.0);
    if (SUN) {
        let samples = max(pu.shadow_samples, 1u);
        var sum = vec3<f32>(0.0);
        for (var k = 0u; k < samples; k++) {
            let u1 = rng_next();
            let u2 = rng_next();
            let l = cone_direction(SUN_DIR, SUN_COS, u1, u2);
            let c = dot(n, l);
            if (c > 0.0 && !trace_scene(make_ray(p, l), 0.0, 0u, NO_INSTANCE, vec2<f32>(0.0)).found) {
                sum += SUN_IRRADIANCE * c * lobe_eval(lobe, n, l);
            }
        }
        light += sum / f32(samples);
    }
    if (EMIT && pu.emitter_count > 0u) {
        light += emitter_light(p, n, lobe);
    }
    return light;
}

// ---- scattering ----

// Result of a scattering event: the new direction and the throughput
// factor, or no continuation.
struct Scatter {
    dir: vec3<f32>,
    weight: vec3<f32>,
    medium: u32,
    ok: bool,
}

fn glass_interface(d: vec3<f32>, n: vec3<f32>, medium: u32, value: u32) -> Scatter {
    var s: Scatter;
    let glass = select(value, medium, medium != 0u);
    let m = materials[glass];
    let alpha = m.roughness * m.roughness;
    let u1 = rng_next();
    let u2 = rng_next();
    var h = select(n, ggx_half_vector(n, alpha, u1, u2), alpha > 1e-4);
    if (dot(h, d) >= 0.0) {
        h = n;
    }
    let eta = ior_of(medium) / ior_of(value);
    let cos_i = -dot(d, h);
    let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    var fresnel = 1.0;
    if (sin2_t < 1.0) {
        fresnel = fresnel_dielectric(cos_i, sqrt(1.0 - sin2_t), eta);
    }
    if (rng_next() < fresnel) {
        s.dir = reflect_about(d, h);
        s.weight = vec3<f32>(1.0);
        s.medium = medium;
        s.ok = dot(s.dir, n) > 0.0;
        return s;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    s.dir = eta * d + (eta * cos_i - cos_t) * h;
    s.weight = select(vec3<f32>(1.0), surface_albedo(value), value != 0u);
    s.medium = value;
    s.ok = dot(s.dir, n) < 0.0;
    return s;
}

fn metal_lobe(d: vec3<f32>, n: vec3<f32>, albedo: vec3<f32>, m: Material) -> Scatter {
    var s: Scatter;
    let alpha = m.roughness * m.roughness;
    let u1 = rng_next();
    let u2 = rng_next();
    let smooth_surface = alpha <= 1e-4;
    let h = select(ggx_half_vector(n, alpha, u1, u2), n, smooth_surface);
    s.dir = reflect_about(d, h);
    let cos_v = -dot(d, n);
    let cos_l = dot(s.dir, n);
    let cos_h = dot(h, n);
    let cos_vh = -dot(d, h);
    s.ok = cos_l > 0.0 && cos_vh > 0.0;
    let f0 = mix(vec3<f32>(0.04), albedo, m.metalness);
    let x = 1.0 - cos_vh;
    let fresnel = f0 + (vec3<f32>(1.0) - f0) * (x * x * x * x * x);
    if (smooth_surface) {
        s.weight = fresnel;
    } else {
        let g = smith_g1(cos_v, alpha) * smith_g1(cos_l, alpha);
        s.weight = fresnel * (g * cos_vh / max(cos_v * cos_h, 1e-6));
    }
    return s;
}

// One path from the camera ray `ray_in` (twin of `PathScene::radiance`).
fn radiance(ray_in: Ray) -> vec3<f32> {
    var ray = ray_in;
    var radiance = vec3<f32>(0.0);
    var beta = vec3<f32>(1.0);
    var medium = 0u;
    // The instance whose glass the ray is in.
    var inside = NO_INSTANCE;
    var lights_counted = false;
    var bounces = 0u;
    var transmissions = 0u;
    var first = true;
    loop {
        let hit = ground_landing(ray, trace_scene(ray, 0.0, medium, inside, vec2<f32>(0.0)));
        if (first) {
            first_t = select(NO_VOXEL_T, hit.t, hit.found && hit.value != 0u && hit.value != GROUND_SURFACE);
        }
        if (hit.iterations >= u.max_iterations && !hit.found) {
            return radiance + beta * GAVE_UP_COLOR;
        }
        if (!hit.found) {
            return radiance + beta * environment(ray.d, lights_counted);
        }
        if (hit.normal_code == 0u) {
            return radiance;
        }
        let p = surface_point(ray, hit);
        let n = hit_normal(hit);
        let lift = lift_of(hit, p);
        let p_out = leave(p, n, lift, n);
        let d = normalize(ray.d);
        let value = hit.value;
        let m = material_of(value);
        if (first) {
            first_albedo = demodulation_albedo(value);
            first_tint = select(0.0, 1.0, u.highlight_on != 0u && in_highlight(hit));
            first = false;
        }
        var dir: vec3<f32>;
        // Leaving glass (into empty space or other glass), or entering it.
        let leaving = GLASS && medium != 0u && (value == 0u || is_glass(value));
        if (!leaving && EMIT && m.kind == MATERIAL_EMIT) {
            // Counted by light sampling, unless no list of lights (too
            // many) sampled it.
            if (!lights_counted || pu.emitter_count == 0u) {
                radiance += beta * surface_albedo(value) * m.emission;
            }
            return radiance;
        }
        if (leaving || (GLASS && m.kind == MATERIAL_GLASS && rng_next() < m.transparency)) {
            transmissions += 1u;
            let s = glass_interface(d, n, medium, value);
            if (!s.ok) {
                return radiance;
            }
            dir = s.dir;
            // Into other glass (or out of it): the instance of the face crossed.
            inside = select(inside, hit.instance, s.medium != medium);
            medium = s.medium;
            beta *= s.weight;
            lights_counted = false;
        } else if (bounces == pu.bounces) {
            return radiance;
        } else if (METAL && m.kind == MATERIAL_METAL) {
            bounces += 1u;
            let albedo = surface_albedo(value);
            let p_spec = 0.5 + 0.5 * m.metalness;
            if (rng_next() < p_spec) {
                let lobe = glossy_lobe(-d, albedo, m);
                let sampled = lobe.alpha >= MIN_SAMPLED_ALPHA;
                if (sampled) {
                    radiance += beta * direct(p_out, n, lobe) / p_spec;
                }
                let s = metal_lobe(d, n, albedo, m);
                if (!s.ok) {
                    return radiance;
                }
                dir = s.dir;
                beta *= s.weight / p_spec;
                lights_counted = sampled;
            } else {
                let diffuse = albedo * (1.0 - m.metalness) / (1.0 - p_spec);
                radiance += beta * diffuse * direct(p_out, n, diffuse_lobe());
                let u1 = rng_next();
                let u2 = rng_next();
                dir = cosine_direction(n, u1, u2);
                beta *= diffuse;
                lights_counted = true;
            }
        } else {
            bounces += 1u;
            let albedo = surface_albedo(value);
            radiance += beta * albedo * direct(p_out, n, diffuse_lobe());
            let u1 = rng_next();
            let u2 = rng_next();
            dir = cosine_direction(n, u1, u2);
            beta *= albedo;
            lights_counted = true;
        }
        if (transmissions > MAX_TRANSMISSIONS) {
            return radiance;
        }
        ray = make_ray(leave(p, n, lift, dir), dir);
    }
    return radiance;
}

// Finite, non-negative, at most MAX_SAMPLE_RADIANCE per channel.
fn clamp_sample(v: vec3<f32>) -> vec3<f32> {
    let finite = all(abs(v) < vec3<f32>(3.0e38)) && all(v == v);
    return select(vec3<f32>(0.0), clamp(v, vec3<f32>(0.0), vec3<f32>(MAX_SAMPLE_RADIANCE)), finite);
}

// The guide of a pixel: the first hit of its centre ray, if the denoiser
// may filter it (twin of `PathScene::guide`).
fn write_guide(px: vec2<u32>, pixel: u32) {
    let r = pixel_ray(px);
    let hit = ground_landing(r, trace_scene(r, 0.0, 0u, NO_INSTANCE, vec2<f32>(0.0)));
    var guide = vec4<u32>(0u);
    if (hit.found && hit.normal_code != 0u && !left_to_samples(material_of(hit.value).kind)) {
        // The nearest axis, and a turned face's own normal.
        var code = GUIDE_FILTERED | hit.normal_code;
        if (hit.turned) {
            code |= GUIDE_TURNED | (pack_normal(hit.turned_normal) << GUIDE_NORMAL_SHIFT);
        }
        guide = vec4<u32>(bitcast<vec3<u32>>(surface_point(r, hit)), code);
    }
    guides[pixel] = guide;
}

// -1 for a negative number, else 1.
fn sign_not_zero(v: f32) -> f32 {
    return select(1.0, -1.0, v < 0.0);
}

// A unit normal's octahedral coordinates, GUIDE_NORMAL_STEPS steps each,
// in 24 bits (twin of `pack_normal` in src/trace/denoise.rs).
fn pack_normal(normal: vec3<f32>) -> u32 {
    let n = normal / (abs(normal.x) + abs(normal.y) + abs(normal.z));
    var uv = n.xy;
    if (n.z < 0.0) {
        uv = vec2<f32>((1.0 - abs(n.y)) * sign_not_zero(n.x), (1.0 - abs(n.x)) * sign_not_zero(n.y));
    }
    let steps = vec2<u32>(floor((uv + 1.0) * 0.5 * GUIDE_NORMAL_STEPS + 0.5));
    return steps.x | (steps.y << 12u);
}

@compute @workgroup_size(8, 8)
fn path(@builtin(global_invocation_id) gid: vec3<u32>) {
    load_constants();
    pu = path_constants;
    let px = vec2<u32>(gid.x, gid.y + pu.first_row);
    if (px.x >= u.width || px.y >= pu.end_row) {
        return;
    }
    let pixel = px.y * u.width + px.x;
    let sequence_index = pu.first_sample + pu.sample_index;
    rng_init(pixel, sequence_index);
    let r = image_ray(vec2<f32>(px) + pixel_offset(pixel, sequence_index));
    first_albedo = vec3<f32>(1.0);
    first_tint = 0.0;
    first_t = NO_VOXEL_T;
    let sample = clamp_sample(radiance(r));
    let first = pu.sample_index == 0u;
    let at = 3u * pixel;
    let sum = select(accum[at].rgb, vec3<f32>(0.0), first) + sample;
    // Beside the squares: how many samples crossed a ground grid line.
    let squares = select(accum[at + 1u], vec4<f32>(0.0), first) + vec4<f32>(sample * sample, ground_line(r, first_t));
    let albedo = select(accum[at + 2u], vec4<f32>(0.0), first) + vec4<f32>(first_albedo, first_tint);
    let n = f32(pu.sample_index + 1u);
    accum[at] = vec4<f32>(sum, n);
    accum[at + 1u] = squares;
    accum[at + 2u] = albedo;
    // The tint and the grid by the shares of samples that showed them.
    textureStore(out_color, vec2<i32>(px), vec4<f32>(overlaid(sum / n, albedo.w / n, squares.w / n), 1.0));
    if (first) {
        write_guide(px, pixel);
    }
}
