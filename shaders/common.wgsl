// Shared by trace_svo.wgsl and trace_grid.wgsl: uniforms, bindings, rays,
// the plane-crossing rule, hit records and shading. The CPU twins live in
// src/trace/mod.rs and src/trace/render.rs.

// Twin of `FrameUniforms` in src/gpu/trace_pass.rs.
struct FrameUniforms {
    eye: vec3<f32>,
    root: u32,
    forward: vec3<f32>,
    depth: u32,
    right: vec3<f32>,
    view: u32,
    up: vec3<f32>,
    width: u32,
    grid_min: vec3<i32>,
    height: u32,
    grid_dims: vec3<u32>,
    highlight_on: u32,
    highlight_min: vec3<i32>,
    // 1: write a hit record per pixel (tests and benchmarks read them; the
    // window does not, and they cost a scattered 16-byte store per pixel).
    hit_records: u32,
    highlight_max: vec3<i32>,
    // Word index of the first brick in `pool` (nodes come first).
    brick_base: u32,
    // No valid ray takes this many iterations (src/trace/mod.rs,
    // `iteration_bound`); one that does is reported as a give-up.
    max_iterations: u32,
    // Level of detail: a camera ray stops at a node whose cell is at most
    // this many voxels wide per unit of t (the `--lod` pixels' footprint);
    // 0 = exact. See `Footprint` in src/trace/mod.rs.
    lod_per_t: f32,
    // 1: an orthographic view, whose rays start across the image plane
    // (`eye` its centre) and all run along `forward` (`RayBasis::ortho`).
    ortho: u32,
    // Level of detail of orthographic rays: the footprint at every t.
    lod_at_start: f32,
    // The ground grid (`GroundGrid`), tree-local: lines `ground_step` apart
    // on the plane y = ground_y over x0..x1, z0..z1; drawn when ground_on.
    ground_on: u32,
    ground_step: u32,
    ground_y: i32,
    ground_x0: i32,
    ground_x1: i32,
    ground_z0: i32,
    ground_z1: i32,
    // Nodes of the instance tree in `instances` (0: the pool holds one
    // model, traced from `root`). See src/scene/instances.rs.
    instance_nodes: u32,
    // 1: rays land on the ground plane y = plane_y (`ground_landing`).
    plane_on: u32,
    plane_y: i32,
    _pad0: u32,
    _pad1: u32,
}

// Read-only storage, not uniform: see `constants_entry` in src/gpu/trace_pass.rs.
@group(0) @binding(BINDING_FRAME_CONSTANTS) var<storage, read> frame_constants: FrameUniforms;
// The invocation's copy of the frame constants, read once by `load_constants`
// at the start of every entry point. CPU-emulated GPUs (lavapipe of Mesa 22)
// read a storage buffer lane by lane, even where every lane reads the same
// word: a read in the traversal loop cost a scalar loop per iteration.
var<private> u: FrameUniforms;

fn load_constants() {
    u = frame_constants;
}
// Nodes (NODE_WORDS words each) and then bricks (2 words each) of the node pool.
@group(0) @binding(BINDING_POOL) var<storage, read> pool: array<u32>;
// The instance tree's nodes, then the instance records (src/scene/instances.rs),
// read four words at a time: each load site costs a scalar loop over the
// lanes on CPU-emulated GPUs.
@group(0) @binding(BINDING_INSTANCES) var<storage, read> instances: array<vec4<u32>>;
@group(0) @binding(BINDING_PALETTE) var<storage, read> palette: array<u32>;
@group(0) @binding(BINDING_GRID) var<storage, read> grid: array<u32>;
@group(0) @binding(BINDING_OUT_COLOR) var out_color: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(BINDING_HIT_RECORDS) var<storage, read_write> hit_records: array<vec4<u32>>;

// Sun shadows are compiled in only when the scene and settings ask for them.
override SHADOWS: bool = true;

// NO_AXIS, MIN_DIRECTION, POINTER_BIT, SUN_DIR, GAVE_UP_COLOR,
// GAVE_UP_RECORD and the VIEW_* codes come from their Rust definitions,
// prepended by src/gpu/prelude.rs.

struct Ray {
    o: vec3<f32>,
    d: vec3<f32>,
    inv: vec3<f32>,
}

struct Hit {
    value: u32,
    voxel: vec3<i32>,
    normal_code: u32, // 0 none, 1..6 = +x -x +y -y +z -z
    level: u32,
    iterations: u32,
    // The ray's t on entering the voxel, and whether a voxel was found (it
    // may be empty when the ray walks through a medium: see trace_svo).
    t: f32,
    found: bool,
    // The instance hit (NO_INSTANCE: a scene of one model).
    instance: u32,
    // A freely turned object's face (`TurnedFace` in src/trace/mod.rs):
    // `voxel` then holds the hit cell's turned centre, `normal_code` is the
    // nearest axis, and these the face's normal and the centre of the cell
    // in front of it.
    turned: bool,
    turned_normal: vec3<f32>,
    outside: vec3<f32>,
}

struct Slab {
    t_enter: f32,
    t_exit: f32,
    axis: u32,
}

fn clamp_component(d: f32) -> f32 {
    if (abs(d) < MIN_DIRECTION) {
        return select(-MIN_DIRECTION, MIN_DIRECTION, d >= 0.0);
    }
    return d;
}

fn make_ray(o: vec3<f32>, d_in: vec3<f32>) -> Ray {
    let d = vec3<f32>(clamp_component(d_in.x), clamp_component(d_in.y), clamp_component(d_in.z));
    return Ray(o, d, vec3<f32>(1.0) / d);
}

// The ray through a point of the image given in pixels (pixel (x, y) spans
// x..x + 1, y..y + 1); twin of `RayBasis::ray_through`.
fn image_ray(p: vec2<f32>) -> Ray {
    let ndc_x = 2.0 * p.x / f32(u.width) - 1.0;
    let ndc_y = 1.0 - 2.0 * p.y / f32(u.height);
    let offset = u.right * ndc_x + u.up * ndc_y;
    if (u.ortho != 0u) {
        return make_ray(u.eye + offset, u.forward);
    }
    return make_ray(u.eye, u.forward + offset);
}

fn pixel_ray(px: vec2<u32>) -> Ray {
    return image_ray(vec2<f32>(px) + vec2<f32>(0.5));
}

// The level-of-detail footprint of camera rays (`Footprint::of_pixels`).
fn camera_footprint() -> vec2<f32> {
    return vec2<f32>(u.lod_at_start, u.lod_per_t);
}

fn plane_t(r: Ray, axis: u32, coord: f32) -> f32 {
    return (coord - r.o[axis]) * r.inv[axis];
}

// Entry axis among ties is the last one crossed (x, y, z order).
fn slab(r: Ray, mn: vec3<f32>, mx: vec3<f32>) -> Slab {
    let t0 = (mn - r.o) * r.inv;
    let t1 = (mx - r.o) * r.inv;
    let near = min(t0, t1);
    let far = max(t0, t1);
    var axis = 0u;
    if (near.z >= near.x && near.z >= near.y) {
        axis = 2u;
    } else if (near.y >= near.x) {
        axis = 1u;
    }
    return Slab(max(max(near.x, near.y), near.z), min(min(far.x, far.y), far.z), axis);
}

// Smallest component; ties go to x, then y.
fn argmin3(t: vec3<f32>) -> u32 {
    if (t.x <= t.y && t.x <= t.z) {
        return 0u;
    }
    if (t.y <= t.z) {
        return 1u;
    }
    return 2u;
}

// The voxel where the ray is at t, on every axis at once: `Ray::voxel_on_axis`
// of src/trace/mod.rs in vector form, with the same plane-crossing rule
// (`Ray::crossed`: planes crossed at the same t count in x, y, z order) (dynamic vector indexing is slow on some
// drivers, so the shaders avoid it on hot paths).
fn voxel_at(r: Ray, t: f32, entry_axis: u32) -> vec3<i32> {
    let p = r.o + r.d * t;
    let positive = r.d > vec3<f32>(0.0);
    let k = vec3<i32>(select(ceil(p) - vec3<f32>(1.0), floor(p), positive));
    let tie_counts = vec3<u32>(0u, 1u, 2u) <= vec3<u32>(entry_axis);
    let t_k = (vec3<f32>(k) - r.o) * r.inv;
    let t_k1 = (vec3<f32>(k + vec3<i32>(1)) - r.o) * r.inv;
    let crossed_k = select(t_k < vec3<f32>(t), t_k <= vec3<f32>(t), tie_counts);
    let crossed_k1 = select(t_k1 < vec3<f32>(t), t_k1 <= vec3<f32>(t), tie_counts);
    // Moving up, voxel k is entered through plane k; moving down, through k + 1.
    let up = select(select(vec3<i32>(0), vec3<i32>(1), crossed_k1), vec3<i32>(-1), !crossed_k);
    let down = select(select(vec3<i32>(0), vec3<i32>(-1), crossed_k), vec3<i32>(1), !crossed_k1);
    return k + select(down, up, positive);
}

// Twin of `Ray::voxel_in_box`: the voxel of the box lo..=hi where the ray is
// at t, having entered it on `entry_axis` (that axis: the entered face).
fn voxel_in_box(r: Ray, lo: vec3<i32>, hi: vec3<i32>, t: f32, entry_axis: u32) -> vec3<i32> {
    let on_face = select(hi, lo, r.d > vec3<f32>(0.0));
    let is_entry = vec3<u32>(0u, 1u, 2u) == vec3<u32>(entry_axis);
    return select(clamp(voxel_at(r, t, entry_axis), lo, hi), on_face, is_entry);
}

fn entry_normal_code(r: Ray, axis: u32) -> u32 {
    if (axis == NO_AXIS) {
        return 0u;
    }
    // Entering through the min face means the normal points to -axis.
    return 1u + 2u * axis + select(0u, 1u, r.d[axis] > 0.0);
}

// The crossing into a uniform cell: the voxel where the ray is at t.
fn hit_cell(r: Ray, value: u32, mn: vec3<i32>, level: u32, t: f32, axis: u32, iterations: u32) -> Hit {
    var hit: Hit;
    hit.instance = NO_INSTANCE;
    hit.iterations = iterations;
    hit.voxel = voxel_in_box(r, mn, mn + vec3<i32>((1 << level) - 1), t, axis);
    hit.value = value;
    hit.normal_code = entry_normal_code(r, axis);
    hit.level = level;
    hit.t = t;
    hit.found = true;
    return hit;
}

fn normal_vector(code: u32) -> vec3<f32> {
    let on_axis = vec3<u32>(0u, 1u, 2u) == vec3<u32>((code - 1u) / 2u);
    let valid = code != 0u && code <= 6u;
    return select(vec3<f32>(0.0), vec3<f32>(select(-1.0, 1.0, code % 2u == 1u)), on_axis & vec3<bool>(valid));
}

// Twin of `ground::landing` in src/trace/ground.rs: the ground cell a ray
// coming down from above the plane lands on before `hit` (a voxel counts as
// behind the plane when its cell lies below it), as a hit on that cell's top
// face of the surface GROUND_SURFACE; else `hit`. Shaded views only; a ray
// that gave up stays one.
fn ground_landing(r: Ray, hit: Hit) -> Hit {
    let found = hit.found || hit.value != 0u;
    let plane = f32(u.plane_y);
    let gave_up_here = !found && hit.iterations >= u.max_iterations;
    if (u.plane_on == 0u || u.view != VIEW_SHADED || gave_up_here || r.d.y >= 0.0 || r.o.y <= plane) {
        return hit;
    }
    if (found && hit.voxel.y >= u.plane_y) {
        return hit;
    }
    let t = plane_t(r, 1u, plane);
    let p = r.o + r.d * t;
    var ground: Hit;
    ground.value = GROUND_SURFACE;
    ground.voxel = vec3<i32>(i32(floor(p.x)), u.plane_y - 1, i32(floor(p.z)));
    ground.normal_code = 3u;
    ground.iterations = hit.iterations;
    ground.t = t;
    ground.found = true;
    ground.instance = NO_INSTANCE;
    return ground;
}

// A surface's colour: its palette entry's, or the ground's.
fn surface_albedo(value: u32) -> vec3<f32> {
    return select(unpack4x8unorm(palette[min(value, 255u)]).rgb, GROUND_ALBEDO, value == GROUND_SURFACE);
}

// The face's normal as shading sees it (twin of `Hit::shading_normal`).
fn hit_normal(hit: Hit) -> vec3<f32> {
    return select(normal_vector(hit.normal_code), hit.turned_normal, hit.turned);
}

// The shadow ray starts in the empty voxel in front of the entered face.
fn shadow_ray(hit: Hit) -> Ray {
    let o = vec3<f32>(hit.voxel) + normal_vector(hit.normal_code) + vec3<f32>(0.5);
    return make_ray(select(o, hit.outside, hit.turned), SUN_DIR);
}

fn sky_color(d: vec3<f32>) -> vec3<f32> {
    let up = clamp(normalize(d).y * 0.5 + 0.5, 0.0, 1.0);
    return mix(vec3<f32>(0.86, 0.89, 0.95), vec3<f32>(0.32, 0.5, 0.82), up);
}

// Blue → cyan → green → yellow → red over [0, 1]. Written without a local
// array: those live in per-thread memory on CPU-emulated GPUs.
fn heat(x_in: f32) -> vec3<f32> {
    let x = clamp(x_in, 0.0, 1.0) * 4.0;
    let i = min(floor(x), 3.0);
    let f = x - i;
    let s0 = vec3<f32>(0.05, 0.05, 0.45);
    let s1 = vec3<f32>(0.0, 0.6, 0.9);
    let s2 = vec3<f32>(0.1, 0.8, 0.2);
    let s3 = vec3<f32>(0.95, 0.9, 0.1);
    let s4 = vec3<f32>(0.9, 0.1, 0.05);
    let lo = select(select(select(s3, s2, i < 2.5), s1, i < 1.5), s0, i < 0.5);
    let hi = select(select(select(s4, s3, i < 2.5), s2, i < 1.5), s1, i < 0.5);
    return mix(lo, hi, f);
}

fn in_highlight(hit: Hit) -> bool {
    let voxel = hit.value != 0u && hit.value != GROUND_SURFACE;
    return voxel && all(hit.voxel >= u.highlight_min) && all(hit.voxel <= u.highlight_max);
}

// A ray that ran out of iterations before it hit or left the tree.
fn gave_up(hit: Hit) -> bool {
    return hit.value == 0u && hit.iterations >= u.max_iterations;
}

// Twin of `shade` in src/trace/render.rs.
fn shade(hit: Hit, d: vec3<f32>, in_shadow: bool) -> vec3<f32> {
    let n = hit_normal(hit);
    switch (u.view) {
        case VIEW_ITERATIONS: {
            return heat(f32(hit.iterations) / 160.0);
        }
        case VIEW_DEPTH: {
            return select(vec3<f32>(0.0), heat((f32(hit.level) + 1.0) / 8.0), hit.value != 0u);
        }
        case VIEW_NORMALS: {
            return select(vec3<f32>(0.0), n * 0.5 + vec3<f32>(0.5), hit.value != 0u);
        }
        default: {
            if (hit.value == 0u) {
                return select(sky_color(d), GAVE_UP_COLOR, gave_up(hit));
            }
            let albedo = surface_albedo(hit.value);
            let lambert = max(dot(n, SUN_DIR), 0.0);
            let sun = select(lambert, 0.0, in_shadow);
            let sky = select(0.5 + 0.5 * n.y, 0.0, hit.normal_code == 0u);
            return albedo * (0.25 + 0.15 * sky + 0.6 * sun);
        }
    }
}

// The t of a ray that hits no voxel: the ground grid shows up to it.
const NO_VOXEL_T: f32 = 3.0e38;

// How much of a one-pixel-wide ground grid line the ray `r` crosses before
// t = `until` (where it first hits a voxel): 0 or 1, as a line is either
// under the pixel's centre or not. Voxels in front of the ground hide it.
fn ground_line(r: Ray, until: f32) -> f32 {
    if (u.ground_on == 0u) {
        return 0.0;
    }
    let t = plane_t(r, 1u, f32(u.ground_y));
    if (!(t > 0.0) || t >= until) {
        return 0.0;
    }
    let p = r.o + r.d * t;
    let lo = vec2<f32>(f32(u.ground_x0), f32(u.ground_z0));
    let hi = vec2<f32>(f32(u.ground_x1), f32(u.ground_z1));
    if (any(p.xz < lo) || any(p.xz > hi)) {
        return 0.0;
    }
    // A pixel's width on the ground's distance: the image plane's pixel
    // scaled by t (perspective) or not (orthographic).
    let pixel = 2.0 * length(u.up) / f32(u.height) * select(t, 1.0, u.ortho != 0u);
    let step = f32(u.ground_step);
    let off = abs(fract((p.xz - lo) / step + vec2<f32>(0.5)) - vec2<f32>(0.5)) * step;
    return select(0.0, 1.0, any(off < vec2<f32>(0.5 * pixel)));
}

fn write_pixel(px: vec2<u32>, hit: Hit, d: vec3<f32>, in_shadow: bool) {
    var rgb = shade(hit, d, in_shadow);
    if (u.ground_on != 0u) {
        let until = select(NO_VOXEL_T, hit.t, hit.value != 0u && hit.value != GROUND_SURFACE);
        rgb = overlaid(rgb, 0.0, ground_line(pixel_ray(px), until));
    }
    // Uniform branches: skipped as a whole when off.
    if (u.highlight_on != 0u) {
        if (in_highlight(hit)) {
            rgb = overlaid(rgb, 1.0, 0.0);
        }
    }
    textureStore(out_color, vec2<i32>(px), vec4<f32>(rgb, 1.0));
    if (u.hit_records == 0u) {
        return;
    }
    let iterations = select(min(hit.iterations, GAVE_UP_RECORD - 1u), GAVE_UP_RECORD, gave_up(hit));
    // The ground records as no voxel (value 0) with its cell and normal.
    let info = (hit.value & 0xffu) | (hit.normal_code << 8u) | (min(hit.level, 31u) << 11u) | (iterations << 16u);
    hit_records[px.y * u.width + px.x] = vec4<u32>(bitcast<u32>(hit.voxel.x), bitcast<u32>(hit.voxel.y), bitcast<u32>(hit.voxel.z), info);
}
