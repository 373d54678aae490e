// Hardware traversal: the scene's triangles, its own and its instanced meshes', found
// by the device's ray queries (wgpu's ray-query WGSL extension, whose `enable`
// directive the composer puts before the module: src/gpu/shaders/composer.rs) in
// the acceleration structures of src/gpu/ray_query.rs: one bottom-level structure
// over the scene's own triangles, one per instanced mesh, and a top-level one of
// their placements. The analytic shapes (spheres, polygons, planes) keep the
// software walk of traverse.wgsl over a tree of their own, which starts with the
// hardware's hit as its best (start_traversal), so that the nearer hit wins and an
// exact tie between a triangle and an analytic shape goes to the smaller key as
// everywhere (limit_for).
//
// Vulkan's ray queries (VK_KHR_ray_query; WGSL: wgpu's ray-query extension, naga's
// `RayDesc` and `RayIntersection`): `rayQueryProceed` runs the traversal until it
// ends or meets a candidate it cannot decide alone (a triangle of non-opaque
// geometry), which the shader confirms or not. Opaque geometry (scenes without
// ALPHA) reports no candidates: the driver keeps the nearest hit. With ALPHA, every
// triangle is a candidate, and the loop below applies the software walk's rules to
// it: coverage (coverage.wgsl) and the tie rule, so that ties between triangles are
// settled as the software walk settles them.

//#if HARDWARE_TRAVERSAL
#import types
#import budget
#import intersect
#import instance
//#if ALPHA
#import coverage
//#endif

@group(0) @binding(21) var scene_tlas: acceleration_structure;

// The top-level instance data (24 bits) of the structure that holds the scene's own
// triangles; the instanced meshes' placements carry the node index of their records
// (src/gpu/ray_query.rs, WORLD_TRIANGLES).
const WORLD_TRIANGLES: u32 = 0xffffffu;

// The names the software walk gives the triangle `primitive_index` of the structure
// whose instance data is `instance_data`: its reference in `triangles` (x) and the
// node index of its instance's records, or NO_INSTANCE (y).
fn hardware_surface(instance_data: u32, primitive_index: u32) -> vec2<u32> {
    if instance_data == WORLD_TRIANGLES {
        return vec2<u32>((PRIM_TRIANGLE << PRIM_KIND_SHIFT) | primitive_index, NO_INSTANCE);
    }
    //#if INSTANCES
    let first = load_instance(instance_data).first_triangle;
    return vec2<u32>((PRIM_TRIANGLE << PRIM_KIND_SHIFT) | (first + primitive_index), instance_data);
    //#else
    // A scene without instances places only its own triangles.
    return vec2<u32>(NO_PRIM, NO_INSTANCE);
    //#endif
}

// The ray query's largest distance for a trace whose hits must lie below `best_t`:
// the software tests keep t < best_t, a ray query t <= t_max, so the f32 below a
// positive finite best_t.
fn ray_query_t_max(best_t: f32) -> f32 {
    if best_t > 0.0 && best_t < bitcast<f32>(0x7f800000u) {
        return bitcast<f32>(bitcast<u32>(best_t) - 1u);
    }
    return best_t;
}

// Finds `trace`'s nearest triangle hit below its best distance with a ray query (for
// an any-hit trace, a shadow ray, any one), and keeps it as the best hit. Charges
// the budget a step for the query and one per candidate.
fn hardware_triangles(trace: ptr<function, TraceRay>) {
    var flags = RAY_FLAG_NONE;
    if (*trace).any_hit != 0u {
        flags = RAY_FLAG_TERMINATE_ON_FIRST_HIT;
    }
    var query: ray_query;
    rayQueryInitialize(&query, scene_tlas,
        RayDesc(flags, 0xffu, 0.0, ray_query_t_max((*trace).best_t), (*trace).origin, (*trace).direction));
    iterations += 1u;
    //#if ALPHA
    let world_ray = Ray((*trace).origin, (*trace).direction);
    while rayQueryProceed(&query) {
        iterations += 1u;
        let candidate = rayQueryGetCandidateIntersection(&query);
        let surface = hardware_surface(candidate.instance_custom_data, candidate.primitive_index);
        let limit = limit_for(surface.x, surface.y, (*trace).best_t, (*trace).best_prim, (*trace).best_instance);
        if !(candidate.t < limit)
            || !stops_ray(trace, surface.x, surface.y, hit_coverage(surface.x, surface.y, world_ray, candidate.t)) {
            continue;
        }
        (*trace).best_t = candidate.t;
        (*trace).best_prim = surface.x;
        (*trace).best_instance = surface.y;
        rayQueryConfirmIntersection(&query);
    }
    //#else
    // Opaque geometry: the traversal runs to its end in one call.
    while rayQueryProceed(&query) {
        iterations += 1u;
    }
    let hit = rayQueryGetCommittedIntersection(&query);
    // Fields of a committed intersection are read only when there is one.
    if hit.kind == RAY_QUERY_INTERSECTION_TRIANGLE {
        let surface = hardware_surface(hit.instance_custom_data, hit.primitive_index);
        (*trace).best_t = hit.t;
        (*trace).best_prim = surface.x;
        (*trace).best_instance = surface.y;
    }
    //#endif
}
//#endif
