// The report's baseline: Amanatides-Woo DDA over the dense grid, one thread
// per pixel. Twin of src/trace/grid.rs. Prefixed with common.wgsl.

fn grid_at(p: vec3<i32>) -> u32 {
    let rel = p - u.grid_min;
    if (any(rel < vec3<i32>(0)) || any(vec3<u32>(rel) >= u.grid_dims)) {
        return 0u;
    }
    let i = u32(rel.x) + u.grid_dims.x * (u32(rel.y) + u.grid_dims.y * u32(rel.z));
    return (grid[i >> 2u] >> (8u * (i & 3u))) & 0xffu;
}

fn trace_grid(r: Ray) -> Hit {
    var miss: Hit;
    if (any(u.grid_dims == vec3<u32>(0u))) {
        return miss;
    }
    let lo = u.grid_min;
    let hi = u.grid_min + vec3<i32>(u.grid_dims) - vec3<i32>(1);
    let s = slab(r, vec3<f32>(lo), vec3<f32>(hi + vec3<i32>(1)));
    if (s.t_enter > s.t_exit || s.t_exit <= 0.0) {
        return miss;
    }
    let t = max(s.t_enter, 0.0);
    var axis = select(NO_AXIS, s.axis, s.t_enter >= 0.0);
    var voxel = voxel_in_box(r, lo, hi, t, axis);
    let step = select(vec3<i32>(-1), vec3<i32>(1), r.d > vec3<f32>(0.0));
    let far_offset = select(vec3<f32>(0.0), vec3<f32>(1.0), r.d > vec3<f32>(0.0));
    var iterations = 0u;
    loop {
        if (iterations >= u.max_iterations) {
            break;
        }
        iterations += 1u;
        let value = grid_at(voxel);
        if (value != 0u) {
            var hit: Hit;
            hit.value = value;
            hit.voxel = voxel;
            hit.normal_code = entry_normal_code(r, axis);
            hit.iterations = iterations;
            return hit;
        }
        let exits = (vec3<f32>(voxel) + far_offset - r.o) * r.inv;
        let a = argmin3(exits);
        voxel[a] += step[a];
        axis = a;
        if (voxel[a] < lo[a] || voxel[a] > hi[a]) {
            break;
        }
    }
    miss.iterations = iterations;
    return miss;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    load_constants();
    if (gid.x >= u.width || gid.y >= u.height) {
        return;
    }
    let r = pixel_ray(gid.xy);
    let hit = ground_landing(r, trace_grid(r));
    var in_shadow = false;
    if (SHADOWS && u.view == VIEW_SHADED && hit.value != 0u && hit.normal_code != 0u) {
        in_shadow = trace_grid(shadow_ray(hit)).value != 0u;
    }
    write_pixel(gid.xy, hit, r.d, in_shadow);
}
