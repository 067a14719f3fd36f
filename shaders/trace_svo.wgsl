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

// Per axis: has the ray crossed the mid-plane (the rule of `crossed`, in
// vector form: no dynamic vector indexing, which is slow on some drivers)?
fn first_octant(r: Ray, mn: vec3<i32>, level: u32, t: f32, entry_axis: u32) -> u32 {
    let mid = vec3<f32>(mn + vec3<i32>(1 << (level - 1u)));
    let t_mid = (mid - r.o) * r.inv;
    let tie_counts = vec3<u32>(0u, 1u, 2u) <= vec3<u32>(entry_axis);
    let c = select(t_mid < vec3<f32>(t), t_mid <= vec3<f32>(t), tie_counts);
    let upper = select(!c, c, r.d > vec3<f32>(0.0));
    return select(0u, 1u, upper.x) | select(0u, 2u, upper.y) | select(0u, 4u, upper.z);
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
    // The stack: the octant taken at every level, 3 bits a level, in two
    // registers. Node words above the current one are fetched again from the
    // root after a pop (no per-thread array: those are slow, very slow on
    // CPU-emulated GPUs like lavapipe).
    var path_low = 0u;
    var path_high = 0u;
    var level = depth;
    var node = u.root;
    // Node words one, two and three levels up; `cached` of them are valid.
    var up1 = 0u;
    var up2 = 0u;
    var up3 = 0u;
    var cached = 0u;
    var node_min = vec3<i32>(0);
    var octant = first_octant(r, node_min, level, t, axis);
    var iterations = 0u;
    loop {
        if (iterations >= MAX_ITERATIONS) {
            break;
        }
        iterations += 1u;
        let half = 1 << (level - 1u);
        let child_min = node_min + octant_offset(octant) * half;
        let word = child_word(node, level, octant);
        if ((word & POINTER_BIT) != 0u) {
            let i = level - 1u;
            if (i < 10u) {
                path_low = (path_low & ~(7u << (3u * i))) | (octant << (3u * i));
            } else {
                path_high = (path_high & ~(7u << (3u * (i - 10u)))) | (octant << (3u * (i - 10u)));
            }
            level -= 1u;
            // Keep the last three ancestors in registers (a short stack).
            up3 = up2;
            up2 = up1;
            up1 = node;
            cached = min(cached + 1u, 3u);
            node = word;
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
        t = min(min(exits.x, exits.y), exits.z);
        axis = a;
        let bit = 1u << a;
        let positive = r.d > vec3<f32>(0.0);
        let forward = select(select(positive.z, positive.y, a == 1u), positive.x, a == 0u);
        let start_level = level;
        var left_root = false;
        loop {
            let leaving = select((octant & bit) == 0u, (octant & bit) != 0u, forward);
            if (!leaving) {
                octant ^= bit;
                break;
            }
            if (level == depth) {
                left_root = true;
                break;
            }
            level += 1u;
            octant = path_octant(path_low, path_high, level);
            node_min -= octant_offset(octant) * (1 << (level - 1u));
        }
        if (left_root) {
            break;
        }
        let climbed = level - start_level;
        if (climbed == 0u) {
            continue;
        }
        if (climbed <= cached) {
            // The new node is an ancestor still held in registers.
            if (climbed == 1u) {
                node = up1;
                up1 = up2;
                up2 = up3;
            } else if (climbed == 2u) {
                node = up2;
                up1 = up3;
            } else {
                node = up3;
            }
            cached -= climbed;
        } else {
            // Deeper pop: fetch the node word again from the root along the path.
            node = u.root;
            for (var l = depth; l > level; l--) {
                node = child_word(node, l, path_octant(path_low, path_high, l));
            }
            cached = 0u;
        }
    }
    miss.iterations = iterations;
    return miss;
}

fn path_octant(low: u32, high: u32, level: u32) -> u32 {
    let i = level - 1u;
    if (i < 10u) {
        return (low >> (3u * i)) & 7u;
    }
    return (high >> (3u * (i - 10u))) & 7u;
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
