// BVH traversal, resumable and bounded. CPU twin: src/cpu/traverse.rs (same nodes,
// same rules: planes first, then the tree nearest child first; at equal distance the
// smaller primitive reference wins, so the result does not depend on the visit order).
//
// MAX_BVH_DEPTH and MAX_POLYGON_VERTICES come from the Rust constants (the module
// `limits`, src/gpu/shaders.rs). Every step is charged to the invocation's budget
// (budget.wgsl).


// Unrolled scenes: a scene of a few primitives (src/gpu/unrolled.rs says which) gets
// no tree walk at all. The host writes unrolled_closest_hit (the module
// `unrolled_scene`), one call of the helpers of unrolled.wgsl per primitive with its record index (and a polygon's vertices) as literals, so
// every record is read at a constant offset: llvmpipe loads such a record once for all
// lanes, where a per-lane index costs a load per lane and component, and the
// primitive's kind is known at compile time. The nearest hit, ties to the smaller
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

// Direction components smaller than this are replaced by it (with their sign; -0
// counts as positive) before the slab test divides by them: a ray parallel to a slab
// gets huge but finite distances, never the NaN of 0·∞.
const MIN_DIRECTION_COMPONENT: f32 = 1e-20;

// 1 + 2γ₃ for f32 (γₙ = nε/(1 - nε), ε = 2^-24), which rounds to 1 + 3·2^-23: the far
// slab distance is enlarged by it so that rounding never loses a box the ray enters
// (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013).
const FAR_SLAB_SCALE: f32 = 1.0000003576;

// What advance_traversal did: finished the traversal, stopped because the budget is
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
// at 1/3 (BENCHMARKS.md, "Replacing finished rays").
const REFILL_FRACTION: u32 = 3u;
//#endif

// The largest charge of one step of the traversal loop (a polygon test charges its
// vertices besides the step).
//#if POLYGONS
const MAX_STEP_COST: u32 = 1u + MAX_POLYGON_VERTICES;
//#else
const MAX_STEP_COST: u32 = 1u;
//#endif

fn inverse_direction(d: vec3<f32>) -> vec3<f32> {
    let tiny = select(vec3<f32>(MIN_DIRECTION_COMPONENT), vec3<f32>(-MIN_DIRECTION_COMPONENT),
                      d < vec3<f32>(0.0));
    return 1.0 / select(d, tiny, abs(d) < vec3<f32>(MIN_DIRECTION_COMPONENT));
}

// The distance at which the ray enters node `index`'s box, if it does so in
// [0, t_max], else NO_HIT (the slab test of Kay and Kajiya, with Ize's far distance).
fn slab_enter(index: u32, origin: vec3<f32>, inverse: vec3<f32>, t_max: f32) -> f32 {
    let node = bvh_nodes[index];
    let lo = (node.min - origin) * inverse;
    let hi = (node.max - origin) * inverse;
    let near_axes = min(lo, hi);
    let far_axes = max(lo, hi);
    let near = max(max(max(near_axes.x, near_axes.y), near_axes.z), 0.0);
    let far = min(min(min(far_axes.x, far_axes.y), far_axes.z), t_max) * FAR_SLAB_SCALE;
    return select(NO_HIT, near, near <= far);
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

// Opens node `*node` if it is a leaf: its primitives become the range [*cursor,
// *leaf_end) and *node becomes NO_NODE (the traversal loop descends only through inner
// nodes). Called on every node a traversal reaches, in the step that reaches it.
fn open_if_leaf(node: ptr<function, u32>, cursor: ptr<function, u32>, leaf_end: ptr<function, u32>) {
    let count = bvh_nodes[*node].count;
    if count > 0u {
        *cursor = bvh_nodes[*node].first;
        *leaf_end = *cursor + count;
        *node = NO_NODE;
    }
}

// Where level `level` of slot `slot`'s traversal stack lives: levels are interleaved
// across slots, so the lanes of one vector touch neighbouring words.
fn traversal_stack_index(slot: u32, level: u32) -> u32 {
    return level * frame.slot_count + slot;
}

// Runs `trace`'s traversal until it finishes (TRAVERSAL_FINISHED), the iteration
// budget is spent (TRAVERSAL_SUSPENDED) or, where `give_way` and the module has
// REFILL_LANES, few lanes of its subgroup still traverse (TRAVERSAL_GAVE_WAY); in the
// last two the state is saved in `trace` and the slot's traversal stack. For an any-hit
// trace (a shadow ray) the first hit ends it; best_prim != NO_PRIM then means occluded.
//
// Instances (a two-level BVH, src/accel/instance.rs): a leaf primitive of kind
// PRIM_INSTANCE is entered as one step: the leaf's position is saved, the ray moves to
// the mesh's space (object_ray) and the traversal continues in the mesh's tree, on the
// same stack above the depth it entered at (stack_base); when that tree is done, one
// more step moves the ray back and resumes the leaf. A suspended traversal inside an
// instance recomputes the object-space ray from its record when it resumes.
fn advance_traversal(slot: u32, trace: ptr<function, TraceRay>, give_way: bool) -> u32 {
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
    var ray = world_ray;
    var inverse = inverse_direction(ray.direction);
    var sheared = shear_ray(ray);
    let any_hit = (*trace).any_hit != 0u;
    var best_t = (*trace).best_t;
    var best_prim = (*trace).best_prim;
    var best_instance = (*trace).best_instance;
    var node = (*trace).node;
    var cursor = (*trace).cursor;
    var leaf_end = (*trace).leaf_end;
    var stack_len = (*trace).stack_len;
    var instance = (*trace).instance;
    var stack_base = (*trace).stack_base;
    var world_cursor = (*trace).world_cursor;
    var world_leaf_end = (*trace).world_leaf_end;
    //#if INSTANCES
    if (*trace).status == TRACE_RUNNING && instance != NO_INSTANCE {
        ray = object_ray(load_instance(instance), world_ray);
        inverse = inverse_direction(ray.direction);
        sheared = shear_ray(ray);
    }
    //#endif
    // At least one step per call, so that any budget makes progress.
    var steps = 0u;
    if (*trace).status == TRACE_PENDING {
        node = NO_NODE;
        cursor = 0u;
        leaf_end = 0u;
        stack_len = 0u;
        instance = NO_INSTANCE;
        stack_base = 0u;
        //#if UNROLLED
        // A small scene's every primitive, planes included, in straight-line code with
        // constant record indices (unrolled_closest_hit, written by the host; see
        // "Unrolled scenes" above): the loop below finds nothing left to visit.
        unrolled_closest_hit(ray, sheared, &best_t, &best_prim);
        // The traversal's one step (so that a simulated loop cut still cuts it).
        steps = 1u;
        //#else
        //#if PLANES
        // Planes are unbounded: every ray tests every plane, before the tree.
        var i = 0u;
        loop {
            if i >= frame.plane_count {
                break;
            }
            iterations += 1u;
            let prim = (PRIM_PLANE << PRIM_KIND_SHIFT) | i;
            let t = intersect_prim(prim, ray, sheared,
                                   limit_for(prim, NO_INSTANCE, best_t, best_prim, best_instance));
            if t != NO_HIT {
                best_t = t;
                best_prim = prim;
                best_instance = NO_INSTANCE;
            }
            i += 1u;
        }
        if i < frame.plane_count {
            atomicOr(&counters.errors, ERROR_LOOP_CUT);
        }
        //#endif
        if frame.node_count > 0u && slab_enter(0u, ray.origin, inverse, best_t) != NO_HIT {
            node = 0u;
            open_if_leaf(&node, &cursor, &leaf_end);
        }
        //#endif
        (*trace).status = TRACE_RUNNING;
    }
    var finished = false;
    var exited = false;
    // The top of the traversal stack while it is not in traversal_stack (NO_NODE when
    // level stack_len - 1, if any, is in memory): a node pushed and popped with no push
    // between never goes through memory. Written back before a suspended call returns.
    var held = NO_NODE;
    // One loop whose every step is either a primitive test (while the lane has a leaf
    // open) or a node step (pop, or visit an inner node and open the child it descends
    // into if that is a leaf), so that a lane never waits for the others to finish a
    // phase: on llvmpipe this measured 2-4% faster than "while-while" (Aila and Laine,
    // "Understanding the Efficiency of Ray Traversal on GPUs", HPG 2009: a descent loop,
    // then a leaf loop), where lanes that reached a leaf wait for the rest
    // (BENCHMARKS.md, "Uniform records"). Node records on the saved state are never
    // leaves: a leaf is opened in the step that reaches it.
    loop {
        // The test switch: a driver that cuts the loop after its first step (even
        // one that would have ended it).
        if steps > 0u && (frame.flags & FLAG_SIMULATE_LOOP_CUT) != 0u {
            break;
        }
        if (any_hit && best_prim != NO_PRIM)
            || (cursor >= leaf_end && node == NO_NODE && stack_len == 0u && instance == NO_INSTANCE) {
            finished = true;
            exited = true;
            break;
        }
        if steps > 0u && iterations + MAX_STEP_COST > frame.iteration_budget {
            exited = true;
            break;
        }
        //#if REFILL_LANES
        // The lanes still here vote (subgroupAdd over the active lanes); the test is
        // the same for all of them, so they leave together. The exit is charged, as it
        // costs the loop's last iteration.
        if give_way && steps > 0u && REFILL_FRACTION * subgroupAdd(1u) <= traversing {
            iterations += 1u;
            gave_way = true;
            exited = true;
            break;
        }
        //#endif
        steps += 1u;
        iterations += 1u;
        if cursor < leaf_end {
            // Test the leaf's next primitive.
            let prim = prim_ref(cursor);
            cursor += 1u;
            var entered = false;
            //#if INSTANCES
            if prim_kind(prim) == PRIM_INSTANCE {
                // Enter the instance: its mesh's tree, with the ray in the mesh's space.
                entered = true;
                let record = prim_index(prim);
                let placed = load_instance(record);
                world_cursor = cursor;
                world_leaf_end = leaf_end;
                cursor = 0u;
                leaf_end = 0u;
                instance = record;
                stack_base = stack_len;
                ray = object_ray(placed, world_ray);
                inverse = inverse_direction(ray.direction);
                sheared = shear_ray(ray);
                node = NO_NODE;
                if slab_enter(placed.root, ray.origin, inverse, best_t) != NO_HIT {
                    node = placed.root;
                    open_if_leaf(&node, &cursor, &leaf_end);
                }
            }
            //#endif
            if !entered {
                let t = intersect_prim(prim, ray, sheared,
                                       limit_for(prim, instance, best_t, best_prim, best_instance));
                if t != NO_HIT {
                    best_t = t;
                    best_prim = prim;
                    best_instance = instance;
                }
            }
            continue;
        }
        //#if INSTANCES
        if node == NO_NODE && stack_len == stack_base {
            // The instance's tree is done: back to the scene's ray and leaf.
            instance = NO_INSTANCE;
            stack_base = 0u;
            ray = world_ray;
            inverse = inverse_direction(ray.direction);
            sheared = shear_ray(ray);
            cursor = world_cursor;
            leaf_end = world_leaf_end;
            continue;
        }
        //#endif
        if node == NO_NODE {
            // Pop; a node pushed earlier may lie beyond a hit found since.
            stack_len -= 1u;
            var candidate = held;
            if held == NO_NODE {
                candidate = traversal_stack[traversal_stack_index(slot, stack_len)];
            }
            held = NO_NODE;
            if slab_enter(candidate, ray.origin, inverse, best_t) != NO_HIT {
                node = candidate;
            }
        } else {
            let a = bvh_nodes[node].first;
            let b = a + 1u;
            let enter_a = slab_enter(a, ray.origin, inverse, best_t);
            let enter_b = slab_enter(b, ray.origin, inverse, best_t);
            if enter_a != NO_HIT && enter_b != NO_HIT {
                // Nearest child first; the other waits on the stack.
                var near = a;
                var far = b;
                if enter_b < enter_a {
                    near = b;
                    far = a;
                }
                if stack_len < MAX_BVH_DEPTH {
                    if held != NO_NODE {
                        traversal_stack[traversal_stack_index(slot, stack_len - 1u)] = held;
                    }
                    held = far;
                    stack_len += 1u;
                } else {
                    atomicOr(&counters.errors, ERROR_TRAVERSAL_STACK);
                }
                node = near;
            } else if enter_a != NO_HIT {
                node = a;
            } else if enter_b != NO_HIT {
                node = b;
            } else {
                node = NO_NODE;
            }
        }
        if node != NO_NODE {
            open_if_leaf(&node, &cursor, &leaf_end);
        }
    }
    if !exited {
        atomicOr(&counters.errors, ERROR_LOOP_CUT);
    }
    if !finished && held != NO_NODE {
        traversal_stack[traversal_stack_index(slot, stack_len - 1u)] = held;
    }
    (*trace).best_t = best_t;
    (*trace).best_prim = best_prim;
    (*trace).best_instance = best_instance;
    (*trace).node = node;
    (*trace).cursor = cursor;
    (*trace).leaf_end = leaf_end;
    (*trace).stack_len = stack_len;
    (*trace).instance = instance;
    (*trace).stack_base = stack_base;
    (*trace).world_cursor = world_cursor;
    (*trace).world_leaf_end = world_leaf_end;
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
