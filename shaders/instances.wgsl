// Two-level tracing: a scene of objects is a tree of boxes over instance
// records, each placing a model's octree by a signed permutation and an
// integer offset (src/scene/instances.rs writes both). The twin of
// src/trace/instanced.rs: change both together. Prefixed with common.wgsl
// and trace_svo.wgsl.

// Compiled in for a scene drawn as instances only: the other kernels have
// no instance walk at all (on lavapipe its mere presence, untaken, made
// them 1.8x slower).
override INSTANCES: bool = false;

// A t past every node's entry: the node is not entered.
const NO_ENTRY: f32 = 3.0e38;

// An instance: its model's tree, and model cell m[j] = ±s[src[j]] + offset[j]
// of scene cell s (minus where `negative[j]`); or where `turned`, model
// point m = rows · s + t of scene point s (`Turned` in src/scene/instances.rs).
struct Instance {
    tree: Tree,
    src: vec3<u32>,
    negative: vec3<bool>,
    offset: vec3<i32>,
    turned: bool,
    rows: mat3x3<f32>,
    t: vec3<f32>,
    // The model's solid box, tree-local (`Turned::solid`); lo > hi: none.
    solid_lo: vec3<f32>,
    solid_hi: vec3<f32>,
}

fn load_instance(index: u32) -> Instance {
    let at = (u.instance_nodes * BVH_NODE_WORDS + index * INSTANCE_WORDS) / 4u;
    let a = instances[at];
    let b = instances[at + 1u];
    let axes = (a.w & ~TURNED_BIT) >> 8u;
    var inst: Instance;
    inst.tree = Tree(a.x, a.w & 0xffu, a.y, a.z, b.x);
    inst.src = vec3<u32>(axes & 3u, (axes >> 2u) & 3u, (axes >> 4u) & 3u);
    inst.negative = (vec3<u32>(axes) & vec3<u32>(64u, 128u, 256u)) != vec3<u32>(0u);
    inst.offset = bitcast<vec3<i32>>(b.yzw);
    inst.turned = (a.w & TURNED_BIT) != 0u;
    if (inst.turned) {
        inst.t = bitcast<vec3<f32>>(b.yzw);
        // The rows as the columns of a matrix: `v * rows` is rows · v.
        let r0 = instances[at + 2u];
        let r1 = instances[at + 3u];
        let r2 = instances[at + 4u];
        inst.rows = mat3x3<f32>(bitcast<vec3<f32>>(r0.xyz), bitcast<vec3<f32>>(r1.xyz), bitcast<vec3<f32>>(r2.xyz));
        // Each row's fourth word: one axis of the solid box, lo | hi << 16.
        let box_words = vec3<u32>(r0.w, r1.w, r2.w);
        inst.solid_lo = vec3<f32>(box_words & vec3<u32>(0xffffu)) - vec3<f32>(SOLID_BOX_SLACK);
        inst.solid_hi = vec3<f32>(box_words >> vec3<u32>(16u)) + vec3<f32>(1.0 + SOLID_BOX_SLACK);
    }
    return inst;
}

// A turned instance's scene point of model point `m` (`Turned::scene_point`:
// the rows are orthogonal, so their transpose undoes them).
fn turned_scene_point(inst: Instance, m: vec3<f32>) -> vec3<f32> {
    return inst.rows * (m - inst.t);
}

// A node of the tree of boxes (its words: src/scene/instances.rs).
struct BoxNode {
    lo: vec3<f32>,
    hi: vec3<f32>,
    // The node after its subtree, and its instance + 1 (0: an inner node)
    // with EMPTY_BIT where nothing below it is drawn.
    skip: u32,
    leaf: u32,
}

fn load_node(i: u32) -> BoxNode {
    let at = i * (BVH_NODE_WORDS / 4u);
    let a = instances[at];
    let b = instances[at + 1u];
    let lo = bitcast<vec3<i32>>(a.xyz);
    let hi = bitcast<vec3<i32>>(vec3<u32>(a.w, b.x, b.y));
    return BoxNode(vec3<f32>(lo), vec3<f32>(hi), b.z, b.w);
}

// The ray in the model's tree-local frame: the same t reaches the same point.
fn model_ray(inst: Instance, r: Ray) -> Ray {
    if (inst.turned) {
        return make_ray(r.o * inst.rows + inst.t, r.d * inst.rows);
    }
    let s = select(vec3<f32>(1.0), vec3<f32>(-1.0), inst.negative);
    let o = vec3<f32>(r.o[inst.src.x], r.o[inst.src.y], r.o[inst.src.z]);
    let d = vec3<f32>(r.d[inst.src.x], r.d[inst.src.y], r.d[inst.src.z]);
    let inv = vec3<f32>(r.inv[inst.src.x], r.inv[inst.src.y], r.inv[inst.src.z]);
    return Ray(s * o + vec3<f32>(inst.offset), s * d, s * inv);
}

// Whether a turned instance's model ray misses its solid box, or enters
// it past `until` (twin of `Turned::misses_solid`; an instance with no box
// is walked).
fn misses_solid(inst: Instance, mr: Ray, until: f32) -> bool {
    if (!inst.turned || any(inst.solid_lo > inst.solid_hi)) {
        return false;
    }
    let s = slab(mr, inst.solid_lo, inst.solid_hi);
    return !(s.t_enter <= s.t_exit && s.t_exit >= 0.0 && s.t_enter <= until);
}

// The code of the axis nearest `n` (twin of `nearest_axis`).
fn nearest_axis_code(n: vec3<f32>) -> u32 {
    let a = abs(n);
    var axis = 2u;
    if (a.x >= a.y && a.x >= a.z) {
        axis = 0u;
    } else if (a.y >= a.z) {
        axis = 1u;
    }
    return 1u + 2u * axis + select(0u, 1u, n[axis] < 0.0);
}

// A hit in a turned model's frame, in the scene's (twin of `turned_hit` in
// src/trace/instanced.rs).
fn turned_hit(inst: Instance, h: Hit) -> Hit {
    var out = h;
    out.voxel = vec3<i32>(floor(turned_scene_point(inst, vec3<f32>(h.voxel) + vec3<f32>(0.5))));
    if (h.normal_code != 0u) {
        let n = normal_vector(h.normal_code);
        out.turned = true;
        out.turned_normal = inst.rows * n;
        out.normal_code = nearest_axis_code(out.turned_normal);
        out.outside = turned_scene_point(inst, vec3<f32>(h.voxel) + n + vec3<f32>(0.5));
    }
    return out;
}

// A hit in the model's frame, in the scene's.
fn scene_hit(inst: Instance, index: u32, h: Hit) -> Hit {
    if (inst.turned) {
        var out = turned_hit(inst, h);
        out.instance = index;
        return out;
    }
    var out = h;
    let d = h.voxel - inst.offset;
    // Cell m spans m..m + 1: mirrored, its low corner is the image of m + 1.
    let m = select(d, -d - vec3<i32>(1), inst.negative);
    out.voxel[inst.src.x] = m.x;
    out.voxel[inst.src.y] = m.y;
    out.voxel[inst.src.z] = m.z;
    if (h.normal_code != 0u) {
        let axis = (h.normal_code - 1u) / 2u;
        // Odd codes are the positive normals.
        let negative_normal = (h.normal_code % 2u == 0u) != inst.negative[axis];
        out.normal_code = 1u + 2u * inst.src[axis] + select(0u, 1u, negative_normal);
    }
    out.instance = index;
    return out;
}

// A ray inside glass that leaves the tree's cube crosses into empty space
// at the cube's face (twin of `root_exit` in src/trace/svo.rs).
fn root_exit(r: Ray, depth: u32, iterations: u32) -> Hit {
    let size = f32(1u << depth);
    let far = (select(vec3<f32>(0.0), vec3<f32>(size), r.d > vec3<f32>(0.0)) - r.o) * r.inv;
    let axis = argmin3(far);
    let t = max(far[axis], 0.0);
    let p = r.o + r.d * t;
    var hit: Hit;
    hit.voxel = vec3<i32>(floor(p));
    hit.voxel[axis] = select(-1, i32(1u << depth), r.d[axis] > 0.0);
    hit.normal_code = 1u + 2u * axis + select(0u, 1u, r.d[axis] > 0.0);
    hit.iterations = iterations;
    hit.t = t;
    hit.found = true;
    hit.instance = NO_INSTANCE;
    return hit;
}

// The first voxel of `tree` along `r` that is not `medium`; a ray inside
// glass that finds none leaves the glass at the tree's face (twin of `cross`).
fn cross_tree(tree: Tree, r: Ray, t_min: f32, medium: u32, lod: vec2<f32>) -> Hit {
    let hit = trace_svo(tree, r, t_min, medium, lod);
    if (hit.found || medium == 0u || hit.iterations >= tree.max_iterations) {
        return hit;
    }
    return root_exit(r, tree.depth, hit.iterations);
}

// Within TIE_T of each other two hits are at one distance.
fn tie_limit(t: f32) -> f32 {
    return t + TIE_T * max(t, 1.0);
}

// Whether a hit at t in instance `index` wins over `best`: it is nearer, or
// at its distance and of a later object (as composing gives).
fn wins(t: f32, index: u32, best: Hit) -> bool {
    return !best.found || t < best.t - TIE_T * max(best.t, 1.0) || (t <= tie_limit(best.t) && index > best.instance);
}

// Farthest t a node may be entered at and still hold a winning hit.
fn reach(best: Hit) -> f32 {
    return select(NO_ENTRY, tie_limit(best.t), best.found);
}

// The t the ray enters a node's box at, or NO_ENTRY: it misses the box,
// nothing is drawn below it, or it lies past `until`.
fn entry_t(node: BoxNode, r: Ray, t_min: f32, until: f32) -> f32 {
    let s = slab(r, node.lo, node.hi);
    let meets = s.t_enter <= s.t_exit && s.t_exit > max(t_min, 0.0) && s.t_enter <= until;
    return select(NO_ENTRY, s.t_enter, meets && (node.leaf & EMPTY_BIT) == 0u);
}

// The first voxel along `r` that is not the medium, in a scene of one model
// or of objects. `medium` is the glass the ray is in (0: none) and `inside`
// the instance of that glass; every other object is crossed as empty space.
// The tree of boxes is walked nearer child first, the farther one on a
// stack, and a node entered past the nearest hit so far is skipped whole.
// Twin of `Traced::trace_through` in src/trace/instanced.rs.
fn trace_scene(r: Ray, t_min: f32, medium: u32, inside: u32, lod: vec2<f32>) -> Hit {
    if (!INSTANCES || u.instance_nodes == 0u) {
        return cross_tree(scene_tree(), r, t_min, medium, lod);
    }
    var best: Hit;
    best.instance = NO_INSTANCE;
    var iterations = 0u;
    var gave_up = false;
    var stack_node: array<u32, BVH_STACK>;
    var stack_t: array<f32, BVH_STACK>;
    var top = 0u;
    var i = 0u;
    var node = load_node(0u);
    var t_i = entry_t(node, r, t_min, NO_ENTRY);
    loop {
        if (t_i < NO_ENTRY) {
            let leaf = node.leaf;
            if (leaf == 0u) {
                // Both children, the nearer first: the left one follows its
                // parent, the right one follows the left one's subtree.
                let left = load_node(i + 1u);
                let right_index = left.skip;
                let right = load_node(right_index);
                let until = reach(best);
                let t_left = entry_t(left, r, t_min, until);
                let t_right = entry_t(right, r, t_min, until);
                let left_first = t_left <= t_right;
                if (max(t_left, t_right) < NO_ENTRY) {
                    stack_node[top] = select(i + 1u, right_index, left_first);
                    stack_t[top] = max(t_left, t_right);
                    top += 1u;
                }
                i = select(right_index, i + 1u, left_first);
                node = right;
                if (left_first) {
                    node = left;
                }
                t_i = min(t_left, t_right);
                continue;
            }
            let index = leaf - 1u;
            let inst = load_instance(index);
            let mr = model_ray(inst, r);
            // A turned object's solid box, tighter than its scene box;
            // glass the ray is in is left at its tree's face: walked.
            if (index == inside || !misses_solid(inst, mr, reach(best))) {
                let h = cross_tree(inst.tree, mr, t_min, select(0u, medium, index == inside), lod);
                iterations += h.iterations;
                gave_up = gave_up || (!h.found && h.iterations >= inst.tree.max_iterations);
                if (h.found && wins(h.t, index, best)) {
                    best = scene_hit(inst, index, h);
                }
            }
        }
        // The next node on the stack still within reach, if any.
        t_i = NO_ENTRY;
        loop {
            if (top == 0u) {
                break;
            }
            top -= 1u;
            if (stack_t[top] <= reach(best)) {
                i = stack_node[top];
                node = load_node(i);
                t_i = stack_t[top];
                break;
            }
        }
        if (t_i >= NO_ENTRY) {
            break;
        }
    }
    if (gave_up) {
        var miss: Hit;
        miss.iterations = u.max_iterations;
        return miss;
    }
    best.iterations = min(iterations, u.max_iterations - 1u);
    return best;
}

// The beam prepass of a scene of objects: the distance from the eye to the
// nearest instance box inside the tile's pyramid (planes n0..n3), or
// BEAM_NONE. Every ray of the tile that meets a voxel meets it in a box.
fn beam_instances(n0: vec3<f32>, n1: vec3<f32>, n2: vec3<f32>, n3: vec3<f32>) -> f32 {
    var best = BEAM_NONE;
    var i = 0u;
    loop {
        if (i >= u.instance_nodes) {
            break;
        }
        let node = load_node(i);
        var descend = false;
        if ((node.leaf & EMPTY_BIT) == 0u) {
            // Half a voxel of slack against rounding in the plane tests.
            let lo = node.lo - vec3<f32>(0.5);
            let hi = node.hi + vec3<f32>(0.5);
            let distance = length(max(max(lo - u.eye, u.eye - hi), vec3<f32>(0.0)));
            let outside = beyond(n0, lo, hi) || beyond(n1, lo, hi) || beyond(n2, lo, hi) || beyond(n3, lo, hi);
            if (!outside && distance < best) {
                descend = node.leaf == 0u;
                best = select(distance, best, descend);
            }
        }
        i = select(node.skip, i + 1u, descend);
    }
    return best;
}
