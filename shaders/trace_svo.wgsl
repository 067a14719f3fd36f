// Stack-based SVO traversal, one thread per pixel. Line-for-line twin of
// src/trace/svo.rs: change both together. Prefixed with common.wgsl.

fn octant_offset(o: u32) -> vec3<i32> {
    return vec3<i32>(i32(o & 1u), i32((o >> 1u) & 1u), i32((o >> 2u) & 1u));
}

// Child word of a node (level >= 2) or voxel value of a brick (level 1).
fn child_word(word: u32, level: u32, octant: u32) -> u32 {
    let slot = word & ~POINTER_BIT;
    if (level == 1u) {
        let packed = bricks[slot * 2u + (octant >> 2u)];
        return (packed >> (8u * (octant & 3u))) & 0xffu;
    }
    return nodes[slot * 8u + octant];
}

fn first_octant(r: Ray, mn: vec3<i32>, level: u32, t: f32, entry_axis: u32) -> u32 {
    let mid = vec3<f32>(mn + vec3<i32>(1 << (level - 1u)));
    var octant = 0u;
    for (var a = 0u; a < 3u; a++) {
        let c = crossed(r, a, mid[a], t, entry_axis);
        let upper = select(!c, c, r.d[a] > 0.0);
        octant |= select(0u, 1u, upper) << a;
    }
    return octant;
}

fn trace_svo(r: Ray) -> Hit {
    var miss: Hit;
    let depth = u.depth;
    let size = f32(1u << depth);
    let s = slab(r, vec3<f32>(0.0), vec3<f32>(size));
    if (s.t_enter > s.t_exit || s.t_exit < 0.0) {
        return miss;
    }
    var t = max(s.t_enter, 0.0);
    var axis = select(NO_AXIS, s.axis, s.t_enter >= 0.0);
    if ((u.root & POINTER_BIT) == 0u) {
        return hit_cell(r, u.root, vec3<i32>(0), depth, t, axis, 1u);
    }
    var words: array<u32, 21>;
    var octants: array<u32, 21>;
    var level = depth;
    var node_min = vec3<i32>(0);
    words[level] = u.root;
    var octant = first_octant(r, node_min, level, t, axis);
    var iterations = 0u;
    loop {
        if (iterations >= MAX_ITERATIONS) {
            break;
        }
        iterations += 1u;
        let half = 1 << (level - 1u);
        let child_min = node_min + octant_offset(octant) * half;
        let word = child_word(words[level], level, octant);
        if ((word & POINTER_BIT) != 0u) {
            octants[level] = octant;
            level -= 1u;
            words[level] = word;
            node_min = child_min;
            octant = first_octant(r, node_min, level, t, axis);
            continue;
        }
        if (word != 0u) {
            return hit_cell(r, word, child_min, level - 1u, t, axis, iterations);
        }
        // Empty child: leave it through its nearest exit plane.
        let far = vec3<f32>(child_min) + select(vec3<f32>(0.0), vec3<f32>(f32(half)), r.d > vec3<f32>(0.0));
        let exits = (far - r.o) * r.inv;
        let a = argmin3(exits);
        t = exits[a];
        axis = a;
        let bit = 1u << a;
        var left_root = false;
        loop {
            let leaving = select((octant & bit) == 0u, (octant & bit) != 0u, r.d[a] > 0.0);
            if (!leaving) {
                octant ^= bit;
                break;
            }
            if (level == depth) {
                left_root = true;
                break;
            }
            level += 1u;
            octant = octants[level];
            node_min -= octant_offset(octant) * (1 << (level - 1u));
        }
        if (left_root) {
            break;
        }
    }
    miss.iterations = iterations;
    return miss;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= u.width || gid.y >= u.height) {
        return;
    }
    let r = pixel_ray(gid.xy);
    let hit = trace_svo(r);
    var in_shadow = false;
    if (SHADOWS && u.view == 0u && hit.value != 0u && hit.normal_code != 0u) {
        in_shadow = trace_svo(shadow_ray(hit)).value != 0u;
    }
    write_pixel(gid.xy, hit, r.d, in_shadow);
}
