// BVH traversal, resumable and bounded. CPU twin: src/cpu/traverse.rs (same nodes,
// same rules: planes first, then the tree nearest child first; at equal distance the
// smaller primitive reference wins, so the result does not depend on the visit order).
//
// MAX_TRAVERSAL_STACK, the child word constants and MAX_POLYGON_VERTICES come from
// the Rust constants (the module `limits`, src/gpu/shaders.rs). Every step is charged
// to the invocation's budget (budget.wgsl).
//
// The traversal runs in steps (`traverse`): where no leaf is open a node step (a pop,
// a visit of a wide node that descends into the child it enters first, or both), then
// where a leaf is open (still, or just reached) its next primitive's test, so that a
// lane never waits for the others to finish a phase of their own.
// Its state between steps and between dispatches is its TraceRay.

// Unrolled scenes: a scene of a few primitives (src/gpu/cpu_device/unrolled.rs says which) gets
// no tree walk at all. The host writes unrolled_closest_hit (the module
// `unrolled_scene`), one call of the helpers of unrolled.wgsl per primitive with its
// record index (and a polygon's vertices) as literals, so every record is read at a
// constant offset: llvmpipe loads such a record once for all lanes, where a per-lane
// index costs a load per lane and component, and the primitive's kind is known at
// compile time. The nearest hit, ties to the smaller
// reference, is the tree's (which only skips primitives whose boxes the ray misses),
// so the image is the same; glass.toml traced 34% faster (BENCHMARKS.md, "Unrolled
// scenes"). Its work is bounded by the scene: at most
// MAX_UNROLLED_PRIMITIVES records, charged to `iterations` like the tree's tests.

#import limits
#import types
#import records
#import bindings
#import budget
#import intersect
#import instance
//#if UNROLLED
#import unrolled_scene
//#endif
//#if ALPHA
#import coverage
//#endif
//#if HARDWARE_TRAVERSAL
#import ray_query
//#endif

// Direction components smaller than this are replaced by it (with their sign; -0
// counts as positive) before the slab test divides by them: a ray parallel to a slab
// gets huge but finite distances, never the NaN of 0·∞.
const MIN_DIRECTION_COMPONENT: f32 = 1e-20;

// 1 + 2γ₃ for f32 (γₙ = nε/(1 - nε), ε = 2^-24), which rounds to 1 + 3·2^-23: the far
// slab distance is enlarged by it so that rounding never loses a box the ray enters
// (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013).
const FAR_SLAB_SCALE: f32 = 1.0000003576;

// The entry distance child_entries gives a child the ray misses: larger than any it
// enters, so that sorting puts the missed last.
const MISSED_CHILD: f32 = 3.40282347e38;

// What `traverse` did: finished the traversal, stopped because the budget is
// spent (or the loop was cut), or gave way to lanes whose rays have finished.
const TRAVERSAL_FINISHED: u32 = 0u;
const TRAVERSAL_SUSPENDED: u32 = 1u;
const TRAVERSAL_GAVE_WAY: u32 = 2u;

//#if REFILL_LANES
// A traversal that may give way does so once at most 1/REFILL_FRACTION of the lanes of
// its subgroup that began the call together still traverse: the others' rays have
// finished, and they idle until the last one's does. Giving way lets them shade and
// start their next rays while the stragglers resume in the next pass of the fused
// kernel's loop: Aila and Laine's "replacing terminated rays" ("Understanding the
// Efficiency of Ray Traversal on GPUs", HPG 2009, section 4). Each give-way costs the
// shading step of the lanes that finished, run with fewer lanes, so giving way early
// costs more than it wins: on lavapipe (8 lanes) with the Whitted integrator,
// glass.toml traced 1.077 s without it, 1.098 s giving way at 1/2, 1.569 s at 3/4,
// 0.979 s at 1/3 and 0.986 s at 1/5; the 1920x1080 showcase 5.953 s without, 4.753 s
// at 1/3 (BENCHMARKS.md, "Replacing finished rays"). The kernel has changed since
// (fused node and primitive steps, nodes in a texture, fewer slots): on it lavapipe
// traced meshes 10-15% faster without giving way, so the renderer leaves it off
// unless asked (RendererOptions::refill_lanes; BENCHMARKS.md, "Lane refill off by
// default").
const REFILL_FRACTION: u32 = 3u;
//#endif

// The largest charge of one step of the traversal loop (a polygon test charges its
// vertices besides the step).
//#if POLYGONS
const MAX_STEP_COST: u32 = 1u + MAX_POLYGON_VERTICES;
//#else
const MAX_STEP_COST: u32 = 1u;
//#endif

// `1 / d` per component, a component smaller than MIN_DIRECTION_COMPONENT in
// magnitude replaced by it with its sign first. Twin of inverse_direction.
fn inverse_direction(d: vec3<f32>) -> vec3<f32> {
    let tiny = select(vec3<f32>(MIN_DIRECTION_COMPONENT), vec3<f32>(-MIN_DIRECTION_COMPONENT),
                      d < vec3<f32>(0.0));
    return 1.0 / select(d, tiny, abs(d) < vec3<f32>(MIN_DIRECTION_COMPONENT));
}

// A ray prepared for the slab tests. Twin of SlabRay.
struct SlabRay {
    origin: vec3<f32>,
    inverse_direction: vec3<f32>,
}

// Twin of SlabRay::new.
fn slab_ray(ray: Ray) -> SlabRay {
    return SlabRay(ray.origin, inverse_direction(ray.direction));
}

// The four bytes of `word`, byte i in component i.
fn unpack_bytes(word: u32) -> vec4<u32> {
    return (vec4<u32>(word) >> vec4<u32>(0u, 8u, 16u, 24u)) & vec4<u32>(0xffu);
}

// The four children's bounds on one axis: origin + q * 2^e, whose product is exact in
// f32, so that the sum rounds once, fused or not (accel::wide). Twin of dequantize.
fn dequantize(origin: f32, biased_exponent: u32, quantized: u32) -> vec4<f32> {
    let step = bitcast<f32>(biased_exponent << 23u);
    return vec4<f32>(origin) + vec4<f32>(unpack_bytes(quantized)) * step;
}

// The four slab distances of one axis (the slab test of Kay and Kajiya).
fn slab_axis(origin: f32, inverse_direction: f32, bound: vec4<f32>) -> vec4<f32> {
    return (bound - vec4<f32>(origin)) * inverse_direction;
}

// The distances at which the ray enters node `index`'s four children's boxes, for each
// that it enters in [0, t_max] (with Ize's far distance) and is not empty, else
// MISSED_CHILD. Twin of SlabRay::enter on WideNode::child_box.
fn child_entries(slab: SlabRay, node: WideNode, t_max: f32) -> vec4<f32> {
    let e = unpack_bytes(node.exponents);
    let lo_x = slab_axis(slab.origin.x, slab.inverse_direction.x, dequantize(node.origin.x, e.x, node.low.x));
    let hi_x = slab_axis(slab.origin.x, slab.inverse_direction.x, dequantize(node.origin.x, e.x, node.high.x));
    let lo_y = slab_axis(slab.origin.y, slab.inverse_direction.y, dequantize(node.origin.y, e.y, node.low.y));
    let hi_y = slab_axis(slab.origin.y, slab.inverse_direction.y, dequantize(node.origin.y, e.y, node.high.y));
    let lo_z = slab_axis(slab.origin.z, slab.inverse_direction.z, dequantize(node.origin.z, e.z, node.low.z));
    let hi_z = slab_axis(slab.origin.z, slab.inverse_direction.z, dequantize(node.origin.z, e.z, node.high.z));
    let near = max(max(max(min(lo_x, hi_x), min(lo_y, hi_y)), min(lo_z, hi_z)), vec4<f32>(0.0));
    let far = min(min(min(max(lo_x, hi_x), max(lo_y, hi_y)), max(lo_z, hi_z)), vec4<f32>(t_max))
        * FAR_SLAB_SCALE;
    let entered = (near <= far) & (node.children != vec4<u32>(EMPTY_CHILD));
    return select(vec4<f32>(MISSED_CHILD), near, entered);
}

// The ray a traversal walks with, in the space of the tree it is in (the scene's, or
// an instanced mesh's), prepared once for the slab and the triangle tests.
struct TraversalRay {
    ray: Ray,
    slab: SlabRay,
    sheared: ShearedRay,
}

fn traversal_ray(ray: Ray) -> TraversalRay {
    return TraversalRay(ray, slab_ray(ray), shear_ray(ray));
}

//#if INSTANCES
// `ray` in an instance's mesh space: origin and direction through world_to_object, the
// direction not renormalised, so that a point keeps its ray parameter and hits in
// different instances compare by distance. CPU twin: object_ray.
fn object_ray(instance: Instance, ray: Ray) -> Ray {
    let o = ray.origin;
    let d = ray.direction;
    return Ray(instance.w2o_x * o.x + instance.w2o_y * o.y + instance.w2o_z * o.z + instance.w2o_t,
               instance.w2o_x * d.x + instance.w2o_y * d.y + instance.w2o_z * d.z);
}
//#endif

// The ray a call of `traverse` starts with: the scene's, or for a traversal suspended
// inside an instance the object-space ray, recomputed from the instance's record.
fn resumed_ray(trace: ptr<function, TraceRay>) -> TraversalRay {
    let world_ray = Ray((*trace).origin, (*trace).direction);
    //#if INSTANCES
    if (*trace).status == TRACE_RUNNING && (*trace).instance != NO_INSTANCE {
        return traversal_ray(object_ray(load_instance((*trace).instance), world_ray));
    }
    //#endif
    return traversal_ray(world_ray);
}

// Tests primitive `prim` of the tree being walked against the best hit so far with the
// tie rule (limit_for), and keeps it if it is nearer and stops the trace (stops_ray of
// its hit_coverage). Twin of Query::consider.
fn consider(trace: ptr<function, TraceRay>, prim: u32, ray: TraversalRay) {
    let instance = (*trace).instance;
    let limit = limit_for(prim, instance, (*trace).best_t, (*trace).best_prim, (*trace).best_instance);
    let t = intersect_prim(prim, ray.ray, ray.sheared, limit);
    //#if ALPHA
    if t != NO_HIT
        && !stops_ray(trace, prim, instance, hit_coverage(prim, instance, Ray((*trace).origin, (*trace).direction), t)) {
        return;
    }
    //#endif
    if t != NO_HIT {
        (*trace).best_t = t;
        (*trace).best_prim = prim;
        (*trace).best_instance = instance;
    }
}

// Goes to the child a child word names: an inner node becomes the current node; a
// leaf's primitives become the range [cursor, leaf_end) (the node stays NO_NODE), so
// that the node on the saved state is never a leaf. Twin of WideChild::from_word.
fn enter_child(trace: ptr<function, TraceRay>, word: u32) {
    let count = word >> CHILD_COUNT_SHIFT;
    if count > 0u {
        (*trace).cursor = word & CHILD_INDEX_MASK;
        (*trace).leaf_end = (*trace).cursor + count;
        (*trace).node = NO_NODE;
    } else {
        (*trace).node = word & CHILD_INDEX_MASK;
    }
}

//#if PLANES
// Tests every plane: planes are unbounded, so every ray tests them all, before the
// tree.
fn test_planes(trace: ptr<function, TraceRay>, ray: TraversalRay) {
    var i = 0u;
    loop {
        if i >= frame.plane_count {
            break;
        }
        iterations += 1u;
        consider(trace, (PRIM_PLANE << PRIM_KIND_SHIFT) | i, ray);
        i += 1u;
    }
    if i < frame.plane_count {
        atomicOr(&counters.errors, ERROR_LOOP_CUT);
    }
}
//#endif

// Starts a pending traversal: with HARDWARE_TRAVERSAL the triangles by ray query,
// then the planes, then the root of the tree; for an unrolled scene, every primitive
// at once. Returns the steps it took.
fn start_traversal(trace: ptr<function, TraceRay>, ray: TraversalRay) -> u32 {
    (*trace).node = NO_NODE;
    (*trace).cursor = 0u;
    (*trace).leaf_end = 0u;
    (*trace).stack_len = 0u;
    (*trace).instance = NO_INSTANCE;
    (*trace).stack_base = 0u;
    (*trace).status = TRACE_RUNNING;
    //#if UNROLLED
    // A small scene's every primitive, planes included, in straight-line code with
    // constant record indices (see "Unrolled scenes" above): the traversal finds
    // nothing left to visit.
    var best_t = (*trace).best_t;
    var best_prim = (*trace).best_prim;
    unrolled_closest_hit(ray.ray, ray.sheared, &best_t, &best_prim);
    (*trace).best_t = best_t;
    (*trace).best_prim = best_prim;
    // The traversal's one step (so that a simulated loop cut still cuts it).
    return 1u;
    //#else
    //#if HARDWARE_TRAVERSAL
    // The triangles by ray query, run to its end in this step (ray_query.wgsl); the
    // tree below then holds only the analytic shapes.
    hardware_triangles(trace);
    //#endif
    //#if PLANES
    test_planes(trace, ray);
    //#endif
    // The root is visited as any node (its children's boxes are tested there).
    if frame.node_count > 0u {
        (*trace).node = 0u;
    }
    return 0u;
    //#endif
}

// Whether the traversal is over: an any-hit trace (a shadow ray) has a hit, or nothing
// is left to visit (no open leaf, current node, stacked node or instance). Twin of
// Query::done and of the end of Query::walk.
fn traversal_done(trace: TraceRay) -> bool {
    return (trace.any_hit != 0u && trace.best_prim != NO_PRIM)
        || (trace.cursor >= trace.leaf_end && trace.node == NO_NODE && trace.stack_len == 0u
            && trace.instance == NO_INSTANCE);
}

//#if INSTANCES
// Enters instance `record`, named by a leaf of the scene's tree: saves the leaf's
// position, moves the ray to the mesh's space and continues in the mesh's tree, on the
// same stack above the depth it entered at (stack_base). Twin of
// Query::enter_instance.
fn enter_instance(trace: ptr<function, TraceRay>, record: u32, world_ray: Ray) -> TraversalRay {
    let placed = load_instance(record);
    (*trace).world_cursor = (*trace).cursor;
    (*trace).world_leaf_end = (*trace).leaf_end;
    (*trace).cursor = 0u;
    (*trace).leaf_end = 0u;
    (*trace).instance = record;
    (*trace).stack_base = (*trace).stack_len;
    (*trace).node = placed.root;
    return traversal_ray(object_ray(placed, world_ray));
}

// Leaves the instance whose tree is done: back to the scene's ray and leaf.
fn leave_instance(trace: ptr<function, TraceRay>, world_ray: Ray) -> TraversalRay {
    (*trace).instance = NO_INSTANCE;
    (*trace).stack_base = 0u;
    (*trace).cursor = (*trace).world_cursor;
    (*trace).leaf_end = (*trace).world_leaf_end;
    return traversal_ray(world_ray);
}
//#endif

// Tests the open leaf's next primitive, or enters the instance it names.
fn next_leaf_prim(trace: ptr<function, TraceRay>, ray: ptr<function, TraversalRay>, world_ray: Ray) {
    let prim = prim_ref((*trace).cursor);
    (*trace).cursor += 1u;
    //#if INSTANCES
    if prim_kind(prim) == PRIM_INSTANCE {
        *ray = enter_instance(trace, prim_index(prim), world_ray);
        return;
    }
    //#endif
    consider(trace, prim, *ray);
}

// Where word `word` (0: the child word, 1: its entry distance's bits) of level
// `level` of slot `slot`'s traversal stack lives: levels are interleaved across slots,
// so the lanes of one vector touch neighbouring words.
fn traversal_stack_index(slot: u32, level: u32, word: u32) -> u32 {
    return (2u * level + word) * frame.slot_count + slot;
}

// A child waiting on the traversal stack: its word and the distance at which the ray
// enters its box.
struct StackedChild {
    word: u32,
    entry: f32,
}

// The stack's top STACK_WINDOW children are kept in registers (StackWindow), the
// newest in component 0, and only the levels below them in traversal_stack: a child
// pushed and popped while fewer than STACK_WINDOW others were pushed above it never
// goes through memory. llvmpipe keeps a vector's components in registers of their
// own, so shifting the window is register renaming, where a storage access costs a
// branch per lane.
const STACK_WINDOW: u32 = 4u;

struct StackWindow {
    words: vec4<u32>,
    entries: vec4<f32>,
    // Children in the window: the top `len` levels of the stack.
    len: u32,
}

// Writes `child` to level `level` of slot `slot`'s stack.
fn store_stacked(slot: u32, level: u32, child: StackedChild) {
    traversal_stack[traversal_stack_index(slot, level, 0u)] = child.word;
    traversal_stack[traversal_stack_index(slot, level, 1u)] = bitcast<u32>(child.entry);
}

// Pushes `child` on the window; a full window first sends its oldest child to memory.
fn push_child(slot: u32, trace: ptr<function, TraceRay>, window: ptr<function, StackWindow>, child: StackedChild) {
    if (*trace).stack_len >= MAX_TRAVERSAL_STACK {
        atomicOr(&counters.errors, ERROR_TRAVERSAL_STACK);
        return;
    }
    if (*window).len == STACK_WINDOW {
        store_stacked(slot, (*trace).stack_len - STACK_WINDOW,
                      StackedChild((*window).words.w, (*window).entries.w));
        (*window).len -= 1u;
    }
    (*window).words = vec4<u32>(child.word, (*window).words.xyz);
    (*window).entries = vec4<f32>(child.entry, (*window).entries.xyz);
    (*window).len += 1u;
    (*trace).stack_len += 1u;
}

// Writes the window's children to their levels in memory (before a suspended call
// returns; `stack_len` is the stack's whole depth) and empties it. Unrolled: a loop
// would count towards llvmpipe's loop limit (budget.wgsl).
fn spill_window(slot: u32, stack_len: u32, window: ptr<function, StackWindow>) {
    let w = *window;
    if w.len > 0u {
        store_stacked(slot, stack_len - 1u, StackedChild(w.words.x, w.entries.x));
    }
    if w.len > 1u {
        store_stacked(slot, stack_len - 2u, StackedChild(w.words.y, w.entries.y));
    }
    if w.len > 2u {
        store_stacked(slot, stack_len - 3u, StackedChild(w.words.z, w.entries.z));
    }
    if w.len > 3u {
        store_stacked(slot, stack_len - 4u, StackedChild(w.words.w, w.entries.w));
    }
    (*window).len = 0u;
}

// Pops the stack's top child and goes to it if the ray enters its box no farther
// than the best hit (times Ize's factor, as the slab test's far distance): a child
// pushed earlier may lie beyond a hit found since. Twin of the pop in Query::walk.
fn pop_child(slot: u32, trace: ptr<function, TraceRay>, window: ptr<function, StackWindow>) {
    (*trace).stack_len -= 1u;
    var child = StackedChild((*window).words.x, (*window).entries.x);
    if (*window).len == 0u {
        child = StackedChild(
            traversal_stack[traversal_stack_index(slot, (*trace).stack_len, 0u)],
            bitcast<f32>(traversal_stack[traversal_stack_index(slot, (*trace).stack_len, 1u)]));
    } else {
        (*window).words = vec4<u32>((*window).words.yzw, EMPTY_CHILD);
        (*window).entries = vec4<f32>((*window).entries.yzw, 0.0);
        (*window).len -= 1u;
    }
    if child.entry <= (*trace).best_t * FAR_SLAB_SCALE {
        enter_child(trace, child.word);
    }
}

// Orders two (entry, word) pairs of the sort in visit_wide_node.
fn sort_pair(entries: ptr<function, vec4<f32>>, words: ptr<function, vec4<u32>>, i: u32, j: u32) {
    let swap = (*entries)[j] < (*entries)[i];
    let ti = (*entries)[i];
    let wi = (*words)[i];
    (*entries)[i] = select(ti, (*entries)[j], swap);
    (*entries)[j] = select((*entries)[j], ti, swap);
    (*words)[i] = select(wi, (*words)[j], swap);
    (*words)[j] = select((*words)[j], wi, swap);
}

// Visits the current wide node: tests its four children's boxes, goes to the child the
// ray enters nearest, and stacks the others it enters, the farthest deepest. Twin of
// the node visit in Query::walk.
fn visit_wide_node(slot: u32, trace: ptr<function, TraceRay>, window: ptr<function, StackWindow>, slab: SlabRay) {
    let node = load_wide_node((*trace).node);
    var entries = child_entries(slab, node, (*trace).best_t);
    var words = select(node.children, vec4<u32>(EMPTY_CHILD), entries == vec4<f32>(MISSED_CHILD));
    // A sorting network of four (Knuth, TAOCP vol. 3, §5.3.4): the nearest first.
    sort_pair(&entries, &words, 0u, 1u);
    sort_pair(&entries, &words, 2u, 3u);
    sort_pair(&entries, &words, 0u, 2u);
    sort_pair(&entries, &words, 1u, 3u);
    sort_pair(&entries, &words, 1u, 2u);
    if words[3] != EMPTY_CHILD {
        push_child(slot, trace, window, StackedChild(words[3], entries[3]));
    }
    if words[2] != EMPTY_CHILD {
        push_child(slot, trace, window, StackedChild(words[2], entries[2]));
    }
    if words[1] != EMPTY_CHILD {
        push_child(slot, trace, window, StackedChild(words[1], entries[1]));
    }
    (*trace).node = NO_NODE;
    if words[0] != EMPTY_CHILD {
        enter_child(trace, words[0]);
    }
}

// One node step: a pop when no node is current, then a visit of the current node
// (the one just popped, or the one a visit entered before); a leaf either reaches is
// opened in the same step.
fn node_step(slot: u32, trace: ptr<function, TraceRay>, window: ptr<function, StackWindow>, slab: SlabRay) {
    if (*trace).node == NO_NODE {
        pop_child(slot, trace, window);
    }
    if (*trace).node != NO_NODE {
        visit_wide_node(slot, trace, window, slab);
    }
}

// Runs `trace`'s traversal until it finishes (TRAVERSAL_FINISHED), the iteration
// budget is spent (TRAVERSAL_SUSPENDED) or, where `give_way` and the module has
// REFILL_LANES, few lanes of its subgroup still traverse (TRAVERSAL_GAVE_WAY); in the
// last two the state is saved in `trace` and the slot's traversal stack. For an any-hit
// trace (a shadow ray) the first hit ends it; best_prim != NO_PRIM then means occluded.
// Twin of traverse (without its budget: the CPU never suspends a traversal).
//
// Instances (a two-level BVH, src/accel/instance.rs): a leaf primitive of kind
// PRIM_INSTANCE is entered as one step (enter_instance); when the mesh's tree is done,
// one more step moves the ray back and resumes the leaf (leave_instance).
//
// One loop whose every step is a node step where no leaf is open (a pop, a visit, or
// a pop and the visit of the node popped), then a primitive test where a leaf is
// open (the one the node step opened, or one still open): the operations of the walk
// in their order, as few iterations as there are node visits and primitive tests.
// llvmpipe (Mesa 25.0's gallivm) runs both sides of every `if` for the whole vector,
// its lanes masked ("gallivm doesn't generally jump when exec_mask is 0",
// lp_bld_nir_soa.c): an iteration costs its pop, its visit and its primitive test
// whichever each lane needs, and fewer iterations cost less. With the step that did
// one of the three, the bunny's trace took 10% longer at 32 spp (20% at 256) and the
// million-triangle terrain's 15% (BENCHMARKS.md, "The compressed 4-wide BVH"). Such
// a loop measured 2-4% faster on llvmpipe than "while-while" (Aila and Laine,
// "Understanding the Efficiency of Ray Traversal on GPUs", HPG 2009: a descent loop,
// then a leaf loop), where lanes that reached a leaf wait for the rest (BENCHMARKS.md,
// "Uniform records").
fn traverse(slot: u32, trace: ptr<function, TraceRay>, give_way: bool) -> u32 {
    //#if REFILL_LANES
    // The lanes of this subgroup that run this call together (counted only where they
    // may give way).
    var traversing = 0u;
    if give_way {
        traversing = subgroupAdd(1u);
    }
    var gave_way = false;
    //#endif
    let world_ray = Ray((*trace).origin, (*trace).direction);
    var ray = resumed_ray(trace);
    // At least one step per call, so that any budget makes progress.
    var steps = 0u;
    if (*trace).status == TRACE_PENDING {
        steps = start_traversal(trace, ray);
    }
    var finished = false;
    var exited = false;
    // The stack's top (see StackWindow), written back before a suspended call
    // returns.
    var window = StackWindow(vec4<u32>(EMPTY_CHILD), vec4<f32>(0.0), 0u);
    loop {
        // The test switch: a driver that cuts the loop after its first step (even
        // one that would have ended it).
        if steps > 0u && (frame.flags & FLAG_SIMULATE_LOOP_CUT) != 0u {
            break;
        }
        if traversal_done(*trace) {
            finished = true;
            exited = true;
            break;
        }
        if steps > 0u && iterations + MAX_STEP_COST > frame.iteration_budget {
            exited = true;
            break;
        }
        //#if REFILL_LANES
        // The lanes still here vote (subgroupAdd over the active lanes) every fourth
        // step: llvmpipe adds the lanes up one by one, which cost 3-5% of the bunny's
        // trace when they voted at every step (BENCHMARKS.md, "The compressed 4-wide
        // BVH"). `steps` is the same in every lane still here (they began the loop
        // together), so the test is the same for all of them and they leave together.
        // The exit is charged, as it costs the loop's last iteration.
        if give_way && steps > 0u && (steps & 3u) == 0u && REFILL_FRACTION * subgroupAdd(1u) <= traversing {
            iterations += 1u;
            gave_way = true;
            exited = true;
            break;
        }
        //#endif
        steps += 1u;
        iterations += 1u;
        // The node step where no leaf is open, then the open leaf's next primitive.
        if (*trace).cursor >= (*trace).leaf_end {
            //#if INSTANCES
            if (*trace).node == NO_NODE && (*trace).stack_len == (*trace).stack_base {
                ray = leave_instance(trace, world_ray);
                continue;
            }
            //#endif
            node_step(slot, trace, &window, ray.slab);
        }
        if (*trace).cursor < (*trace).leaf_end {
            next_leaf_prim(trace, &ray, world_ray);
        }
    }
    if !exited {
        atomicOr(&counters.errors, ERROR_LOOP_CUT);
    }
    if !finished {
        spill_window(slot, (*trace).stack_len, &window);
    }
    if finished {
        return TRAVERSAL_FINISHED;
    }
    //#if REFILL_LANES
    if gave_way {
        return TRAVERSAL_GAVE_WAY;
    }
    //#endif
    return TRAVERSAL_SUSPENDED;
}
