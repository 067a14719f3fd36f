// Stack-based SVO traversal, one thread per pixel, after a beam prepass that
// gives each tile of pixels a safe distance to start from. The traversal is
// the twin of src/trace/svo.rs: change both together. Prefixed with
// common.wgsl.
//
// The loop body is straight-line code choosing between "push" and "advance"
// with select(): on SIMD hardware, and above all on CPU-emulated GPUs, both
// sides of a divergent branch run anyway, and the bookkeeping of branches
// costs more than the selects.

@group(0) @binding(BINDING_BEAM_DISTANCE) var<storage, read_write> beam_distance: array<f32>;
// The tiles the beam prepass found something in; `main` runs on these only
// (an indirect dispatch), after the floor kernel has drawn every pixel as
// sky. CPU-emulated GPUs run a branch that any lane takes on every lane,
// masked, so an empty tile in the trace kernel cost about what a traced one
// did. `count` is zeroed before every SVO frame (`TracePass::encode`).
struct TracedTiles {
    count: atomic<u32>,
    // x | y << 16 of each tile, in no particular order.
    list: array<u32>,
}
@group(0) @binding(BINDING_TRACED) var<storage, read_write> traced: TracedTiles;
// The indirect dispatch arguments of `main`, written by `tile_dispatch`; in a
// group of its own, since a dispatch may not read its own arguments buffer
// as storage.
@group(1) @binding(BINDING_DISPATCH_ARGS) var<storage, read_write> dispatch_args: array<u32, 3>;

// Side of the square tile of pixels that shares one beam: set from
// `BEAM_TILE` in src/gpu/trace_pass.rs, which also sizes the beam buffer.
override BEAM_TILE: u32;
// Level of detail compiled in (`--lod` above 0): without it the walk has no
// footprint test at all, so an exact frame costs what it did before.
override LOD: bool = false;
// The beam stops at nodes this small (4³ voxels): finer levels cost more
// prepass steps than they save.
const BEAM_LEVEL: u32 = 2u;
// No solid cell in the tile's frustum.
const BEAM_NONE: f32 = 3.0e38;
const BEAM_MAX_STEPS: u32 = 16384u;

fn octant_offset(o: u32) -> vec3<i32> {
    return vec3<i32>(i32(o & 1u), i32((o >> 1u) & 1u), i32((o >> 2u) & 1u));
}

// One octree in the pool: the scene's one model, or an instance's model.
struct Tree {
    root: u32,
    depth: u32,
    // Its first node slot, and the word its first brick is at, in `pool`.
    node_base: u32,
    brick_base: u32,
    // `iteration_bound` of its depth: no valid ray takes this many.
    max_iterations: u32,
}

// The tree of a scene of one model.
fn scene_tree() -> Tree {
    return Tree(u.root, u.depth, 0u, u.brick_base, u.max_iterations);
}

// Child word of a node (level >= 2) or voxel value of a brick (level 1),
// with a single load: each load site in the loop costs a scalar loop over
// the SIMD lanes on CPU-emulated GPUs.
fn child_word(tree: Tree, word: u32, level: u32, octant: u32) -> u32 {
    let slot = word & ~POINTER_BIT;
    let brick = level == 1u;
    let loaded = pool[select((tree.node_base + slot) * NODE_WORDS + octant, tree.brick_base + slot * 2u + (octant >> 2u), brick)];
    return select(loaded, (loaded >> (8u * (octant & 3u))) & 0xffu, brick);
}

// The child cell of node (`mn`, level) that holds the ray point at t: per
// axis, whether the ray has crossed the mid-plane (the rule of `crossed`).
fn child_cell(r: Ray, mn: vec3<i32>, level: u32, t: f32, entry_axis: u32) -> vec3<i32> {
    let half = 1 << (level - 1u);
    let t_mid = (vec3<f32>(mn + vec3<i32>(half)) - r.o) * r.inv;
    let tie_counts = vec3<u32>(0u, 1u, 2u) <= vec3<u32>(entry_axis);
    let crossed = select(t_mid < vec3<f32>(t), t_mid <= vec3<f32>(t), tie_counts);
    let upper = crossed == (r.d > vec3<f32>(0.0));
    return mn + select(vec3<i32>(0), vec3<i32>(half), upper);
}

// Octant of a cell of size 2^(level-1) within its node: one coordinate bit
// per axis. The cell's coordinates hold its octant at every level above, so
// the traversal keeps no octant stack.
fn octant_of(cell: vec3<i32>, level: u32) -> u32 {
    let b = (vec3<u32>(cell) >> vec3<u32>(level - 1u)) & vec3<u32>(1u);
    return b.x | (b.y << 1u) | (b.z << 2u);
}

// `argmin3` without branches.
fn argmin3_select(t: vec3<f32>) -> u32 {
    return select(select(2u, 1u, t.y <= t.z), 0u, t.x <= t.y && t.x <= t.z);
}

// Whether a node cell `size` voxels wide, entered at t, is below the
// footprint `lod` (voxels at t = 0, voxels per unit of t): twin of
// `Footprint::covers` in src/trace/mod.rs.
fn below_footprint(lod: vec2<f32>, size: u32, t: f32) -> bool {
    return f32(size) <= lod.x + lod.y * t;
}

// The first voxel along `r`, at or after `t_min`, whose value is not
// `medium`: the first solid voxel for rays in empty space (medium 0), the
// way out for rays inside glass. With a footprint `lod` (zero: exact), a
// node cell below it is hit as a solid cell of its summary's palette index.
// Twin of `walk` in src/trace/svo.rs.
fn trace_svo(tree: Tree, r: Ray, t_min: f32, medium: u32, lod: vec2<f32>) -> Hit {
    var miss: Hit;
    let depth = tree.depth;
    let size = f32(1u << depth);
    let s = slab(r, vec3<f32>(0.0), vec3<f32>(size));
    // t_exit = 0: the ray starts on the root's face and heads out.
    if (s.t_enter > s.t_exit || s.t_exit <= max(t_min, 0.0)) {
        return miss;
    }
    var t = max(s.t_enter, 0.0);
    // NO_AXIS: the ray starts inside the root, so no face was entered yet.
    var axis = select(NO_AXIS, s.axis, s.t_enter >= 0.0);
    if (t_min > t) {
        t = t_min;
        axis = NO_AXIS;
    }
    if ((tree.root & POINTER_BIT) == 0u) {
        if (tree.root == medium) {
            miss.iterations = 1u;
            return miss;
        }
        return hit_cell(r, tree.root, vec3<i32>(0), depth, t, axis, 1u);
    }
    let positive = r.d > vec3<f32>(0.0);
    let far_side = select(vec3<i32>(0), vec3<i32>(1), positive);
    let below = select(vec3<i32>(-1), vec3<i32>(0), positive);
    var level = depth;
    var node = tree.root;
    // The stack: node words one, two and three levels up, `cached` of them
    // valid. A pop past them restarts from the root (see below); a per-thread
    // array would be slower, very much so on CPU-emulated GPUs.
    var up1 = 0u;
    var up2 = 0u;
    var up3 = 0u;
    var cached = 0u;
    // After a restart the cell is already known down to this node level, so
    // the descent follows its coordinate bits instead of the ray.
    var known = depth;
    var cell = child_cell(r, vec3<i32>(0), level, t, axis);
    var iterations = 0u;
    var value = 0u;
    var found = false;
    // The node word a footprint stopped at (0: none).
    var summarized = 0u;
    loop {
        if (iterations >= tree.max_iterations) {
            break;
        }
        iterations += 1u;
        let word = child_word(tree, node, level, octant_of(cell, level));
        let push = (word & POINTER_BIT) != 0u;
        // Only a node cell the ray newly enters (not an ancestor walked down
        // again after a restart) may stop it; bricks never do.
        let stop = LOD && push && level >= 3u && level - 1u < known && below_footprint(lod, 1u << (level - 1u), t);
        if ((!push && word != medium) || stop) {
            value = word;
            summarized = select(0u, word, stop);
            found = true;
            break;
        }
        // Push: the child cell of the new node holding the ray point.
        let child_level = level - 1u;
        let pushed_cell = select(cell, child_cell(r, cell, max(child_level, 1u), t, axis), child_level < known);
        // Advance: leave the empty cell through its nearest exit plane. The
        // highest coordinate bit that changes is the octant bit of the
        // smallest node holding both cells: that is where the step pops to.
        let half = 1 << (level - 1u);
        let exits = (vec3<f32>(cell + far_side * half) - r.o) * r.inv;
        let a = argmin3_select(exits);
        let next = cell + select(vec3<i32>(0), far_side * half + below, vec3<u32>(0u, 1u, 2u) == vec3<u32>(a));
        let changed = vec3<u32>(cell ^ next);
        let new_level = firstLeadingBit(changed.x | changed.y | changed.z) + 1u;
        if (!push && new_level > depth) {
            break;
        }
        let climbed = new_level - level;
        // Popping past the cached ancestors restarts at the root and descends
        // again along the cell's coordinate bits.
        let restart = climbed > cached;
        let popped = select(select(select(node, up3, climbed == 3u), up2, climbed == 2u), up1, climbed == 1u);
        let popped_up1 = select(select(up1, up3, climbed == 2u), up2, climbed == 1u);
        let popped_up2 = select(up2, up3, climbed == 1u);
        let parent = node;
        t = select(min(min(exits.x, exits.y), exits.z), t, push);
        axis = select(a, axis, push);
        cell = select(next & vec3<i32>(~((1 << (new_level - 1u)) - 1)), pushed_cell, vec3<bool>(push));
        known = select(new_level, min(known, child_level), push);
        node = select(select(popped, tree.root, restart), word, push);
        up3 = select(up3, up2, push);
        up2 = select(popped_up2, up1, push);
        up1 = select(popped_up1, parent, push);
        level = select(select(new_level, depth, restart), child_level, push);
        cached = select(select(cached - climbed, 0u, restart), min(cached + 1u, 3u), push);
    }
    if (!found) {
        miss.iterations = iterations;
        return miss;
    }
    if (LOD && summarized != 0u) {
        value = pool[(tree.node_base + (summarized & ~POINTER_BIT)) * NODE_WORDS + LOD_WORD] & 0xffu;
    }
    return hit_cell(r, value, cell, level - 1u, t, axis, iterations);
}

fn beam_tiles() -> vec2<u32> {
    return (vec2<u32>(u.width, u.height) + vec2<u32>(BEAM_TILE - 1u)) / BEAM_TILE;
}

// Direction through a point of the image plane given in pixels (corners at
// whole numbers); `pixel_ray` uses pixel centres.
fn image_direction(p: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(2.0 * p.x / f32(u.width) - 1.0, 1.0 - 2.0 * p.y / f32(u.height));
    return u.forward + u.right * ndc.x + u.up * ndc.y;
}

// Is the box (lo, hi) wholly outside the half-space n·(p - eye) >= 0?
fn beyond(n: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    return dot(n, select(lo, hi, n >= vec3<f32>(0.0)) - u.eye) < 0.0;
}

fn inward(n: vec3<f32>, center: vec3<f32>) -> vec3<f32> {
    return select(-n, n, dot(n, center) >= 0.0);
}

// Beam prepass, one thread per tile: the distance from the eye to the
// nearest non-empty node of BEAM_LEVEL (or uniform solid node) inside the
// pyramid of the tile's corner rays. Every pixel ray of the tile lies in
// that pyramid, so none can meet a solid voxel closer than this distance.
// A depth-first search, near children first, pruned by the best distance so
// far; its stack is the child taken at every level, 3 bits a level.
fn beam_search(tile: vec2<u32>) -> f32 {
    let p0 = vec2<f32>(tile * BEAM_TILE);
    let p1 = vec2<f32>(min((tile + vec2<u32>(1u)) * BEAM_TILE, vec2<u32>(u.width, u.height)));
    let c00 = image_direction(p0);
    let c10 = image_direction(vec2<f32>(p1.x, p0.y));
    let c11 = image_direction(p1);
    let c01 = image_direction(vec2<f32>(p0.x, p1.y));
    let center = image_direction((p0 + p1) * 0.5);
    let n0 = inward(cross(c00, c10), center);
    let n1 = inward(cross(c10, c11), center);
    let n2 = inward(cross(c11, c01), center);
    let n3 = inward(cross(c01, c00), center);
    var best = BEAM_NONE;
    let depth = u.depth;
    if (INSTANCES && u.instance_nodes != 0u) {
        // An orthographic view of objects: every ray starts at its origin.
        let anything = (load_node(0u).leaf & EMPTY_BIT) == 0u;
        return select(select(BEAM_NONE, 0.0, anything), beam_instances(n0, n1, n2, n3), u.ortho == 0u);
    }
    // Too small to search, or an orthographic view (parallel rays: no
    // pyramid about the eye): every ray starts at its origin.
    if (u.ortho != 0u || (u.root & POINTER_BIT) == 0u || depth <= BEAM_LEVEL) {
        return select(0.0, BEAM_NONE, u.root == 0u);
    }
    var node = u.root;
    var level = depth;
    var mn = vec3<i32>(0);
    var next = 0u;
    var path_low = 0u;
    var path_high = 0u;
    var steps = 0u;
    loop {
        if (steps >= BEAM_MAX_STEPS) {
            // Out of budget: start those rays from the eye.
            best = 0.0;
            break;
        }
        steps += 1u;
        if (next == 8u) {
            // This node is done: back to its parent's next child.
            if (level == depth) {
                break;
            }
            level += 1u;
            let shift = 3u * ((level - 1u) % 10u);
            let saved = select(path_high, path_low, level <= 10u);
            next = ((saved >> shift) & 7u) + 1u;
            mn = mn & vec3<i32>(~((1 << level) - 1));
            node = u.root;
            for (var l = depth; l > level; l--) {
                node = pool[(node & ~POINTER_BIT) * NODE_WORDS + octant_of(mn, l)];
            }
            continue;
        }
        let half = 1 << (level - 1u);
        let near_side = u.eye >= vec3<f32>(mn + vec3<i32>(half));
        let near = select(0u, 1u, near_side.x) | select(0u, 2u, near_side.y) | select(0u, 4u, near_side.z);
        let o = near ^ next;
        let child = pool[(node & ~POINTER_BIT) * NODE_WORDS + o];
        let child_min = mn + octant_offset(o) * half;
        next += 1u;
        if (child == 0u) {
            continue;
        }
        // Half a voxel of slack against rounding in the plane tests.
        let lo = vec3<f32>(child_min) - vec3<f32>(0.5);
        let hi = vec3<f32>(child_min + vec3<i32>(half)) + vec3<f32>(0.5);
        let distance = length(max(max(lo - u.eye, u.eye - hi), vec3<f32>(0.0)));
        if (beyond(n0, lo, hi) || beyond(n1, lo, hi) || beyond(n2, lo, hi) || beyond(n3, lo, hi) || distance >= best) {
            continue;
        }
        // A node cell that some ray of the tile may stop at under the level
        // of detail counts as solid: no ray's t there exceeds the distance to
        // the box's farthest corner (|d| >= 1).
        let far_corner = length(max(abs(lo - u.eye), abs(hi - u.eye)));
        let summarized = LOD && below_footprint(vec2<f32>(0.0, u.lod_per_t), u32(half), far_corner);
        if ((child & POINTER_BIT) == 0u || level - 1u <= BEAM_LEVEL || summarized) {
            best = distance;
            continue;
        }
        // Descend, remembering which child this was.
        let shift = 3u * ((level - 1u) % 10u);
        let entry = (next - 1u) << shift;
        if (level <= 10u) {
            path_low = (path_low & ~(7u << shift)) | entry;
        } else {
            path_high = (path_high & ~(7u << shift)) | entry;
        }
        node = child;
        level -= 1u;
        mn = child_min;
        next = 0u;
    }
    return best;
}

// The traced tiles are dispatched in rows of ROW_TILES tiles (a dispatch is
// at most 65535 workgroups per axis; ROW_TILES comes from
// src/gpu/trace_pass.rs, which sizes the list). NO_TILE pads the last row.
const NO_TILE: u32 = 0xffffffffu;

@compute @workgroup_size(8, 8)
fn beam(@builtin(global_invocation_id) gid: vec3<u32>) {
    load_constants();
    let tiles = beam_tiles();
    if (gid.x >= tiles.x || gid.y >= tiles.y) {
        return;
    }
    let best = beam_search(gid.xy);
    beam_distance[gid.y * tiles.x + gid.x] = best;
    // With a ground, rays that meet no voxel still land on it.
    if (best < BEAM_NONE || u.plane_on != 0u) {
        traced.list[atomicAdd(&traced.count, 1u)] = gid.x | (gid.y << 16u);
    }
}

// 8×8 workgroups per tile (BEAM_TILE is a multiple of 8).
fn tile_groups() -> u32 {
    return (BEAM_TILE / 8u) * (BEAM_TILE / 8u);
}

// The indirect dispatch arguments of `main`: rows of ROW_TILES tiles, the
// last one padded with NO_TILE.
@compute @workgroup_size(1)
fn tile_dispatch() {
    let count = atomicLoad(&traced.count);
    let rows = (count + ROW_TILES - 1u) / ROW_TILES;
    for (var k = count; k < rows * ROW_TILES; k++) {
        traced.list[k] = NO_TILE;
    }
    dispatch_args[0] = tile_groups() * ROW_TILES;
    dispatch_args[1] = rows;
    dispatch_args[2] = 1u;
}

// The pixel of this invocation in its workgroup's traced tile, and the tile's
// index in the beam buffer; or none (x = NO_TILE) past the list or the
// image. Divisions by constants only: integer division is a scalar loop over
// the lanes on CPU-emulated GPUs.
fn traced_pixel(wid: vec3<u32>, lid: vec3<u32>) -> vec3<u32> {
    let none = vec3<u32>(NO_TILE);
    let packed = traced.list[wid.y * ROW_TILES + wid.x / tile_groups()];
    if (packed == NO_TILE) {
        return none;
    }
    let tile = vec2<u32>(packed & 0xffffu, packed >> 16u);
    let block = wid.x % tile_groups();
    let side = BEAM_TILE / 8u;
    let corner = tile * BEAM_TILE + vec2<u32>(block % side, block / side) * 8u;
    let px = corner + lid.xy;
    let inside = px.x < u.width && px.y < u.height;
    return select(none, vec3<u32>(px, tile.y * beam_tiles().x + tile.x), inside);
}

// Traces the pixels of the tiles the beam found something in, each ray
// starting one voxel before its tile's beam distance (t measures distance in
// units of |d|).
@compute @workgroup_size(8, 8)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    load_constants();
    let pixel = traced_pixel(wid, lid);
    if (pixel.x == NO_TILE) {
        return;
    }
    let px = pixel.xy;
    let r = pixel_ray(px);
    let distance = beam_distance[pixel.z];
    let t_start = max(distance - 1.0, 0.0) / length(r.d);
    let hit = ground_landing(r, trace_scene(r, t_start, 0u, NO_INSTANCE, camera_footprint()));
    var in_shadow = false;
    if (SHADOWS && u.view == VIEW_SHADED && hit.value != 0u && hit.normal_code != 0u) {
        // The shadow ray keeps the footprint the camera ray had at the hit
        // cell's depth (`cell_depth` in src/trace/render.rs).
        let depth = dot(vec3<f32>(hit.voxel) + vec3<f32>(0.5) - u.eye, u.forward);
        let footprint = u.lod_at_start + u.lod_per_t * depth;
        in_shadow = trace_scene(shadow_ray(hit), 0.0, 0u, NO_INSTANCE, vec2<f32>(footprint, 0.0)).value != 0u;
    }
    write_pixel(px, hit, r.d, in_shadow);
}
