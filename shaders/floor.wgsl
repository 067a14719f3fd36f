// The floor of a frame on this adapter: everything the trace pass does per
// pixel except the traversal (the pixel's ray, shading a miss, one store),
// a thread per pixel. `octovox bench render` reports each model's SVO time
// as a multiple of it. An SVO frame runs it first as its sky: the trace then
// draws over the tiles the beam prepass lists (trace_svo.wgsl).

// Workgroups are rows of FLOOR_ROW pixels, not 8×8 squares, so that two
// threads rarely write one cache line of the output (src/gpu/trace_pass.rs).
@compute @workgroup_size(FLOOR_ROW, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    load_constants();
    if (gid.x >= u.width || gid.y >= u.height) {
        return;
    }
    let r = pixel_ray(gid.xy);
    var miss: Hit;
    write_pixel(gid.xy, miss, r.d, false);
}
