// One slot of the wavefront (wavefront.wgsl) between dispatches: the bounce stack of
// its path (the reflected and refracted rays still to trace), the traversal its ray
// is in, and the pixel it works on. The CPU reference keeps the same stack in its own
// loop (src/cpu/trace.rs, trace_radiance).

#import types
#import bindings
#import records
#import math
//#if PATH
#import path_types
//#endif

// Branches whose weight is not above the smallest normal f32 are not traced, whatever
// the cutoff. Twin of MIN_BRANCH_WEIGHT.
const MIN_BRANCH_WEIGHT: f32 = 1.17549435e-38;

// Where entry `level` of slot `slot`'s bounce stack lives (interleaved across slots).
fn ray_stack_index(slot: u32, level: u32) -> u32 {
    return level * frame.slot_count + slot;
}

// Pushes a branch if it carries more than the weight cutoff and the stack has room;
// otherwise the branch is dropped (both backends alike). The new top is held in the
// path state; the one it covers moves to its place in ray_stack.
fn push_branch(slot: u32, path: ptr<function, PathState>, entry: StackEntry) {
    let cutoff = max(frame.min_ray_weight, MIN_BRANCH_WEIGHT);
    if max_component(entry.weight) > cutoff && (*path).stack_len < frame.stack_size {
        if (*path).held_top != 0u {
            ray_stack[ray_stack_index(slot, (*path).stack_len - 1u)] = (*path).held;
        }
        hold_top(path, entry);
        (*path).stack_len += 1u;
    }
}

// Makes `entry` the held top of the bounce stack (its level is stack_len - 1 once the
// caller has counted it).
fn hold_top(path: ptr<function, PathState>, entry: StackEntry) {
    (*path).held = entry;
    (*path).held_top = 1u;
}

// Whether `trace` has a traversal to run or resume.
fn trace_in_flight(trace: TraceRay) -> bool {
    return trace.status == TRACE_PENDING || trace.status == TRACE_RUNNING;
}

// Sets up the traversal of a ray: the nearest hit in (0, t_max), or with `any_hit`
// whether anything lies there.
fn start_trace(trace: ptr<function, TraceRay>, origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) {
    *trace = TraceRay(origin, t_max, direction, TRACE_PENDING, t_max, NO_PRIM, 0u, NO_NODE,
                      0u, 0u, u32(any_hit), NO_INSTANCE, NO_INSTANCE, 0u, 0u, 0u,
                      NO_BLEND_SEED, 1.0, 0u, 0u);
}

// The image pixel of region pixel `pixel`.
fn pixel_position(pixel: u32) -> vec2<u32> {
    return vec2<u32>(frame.region_x + pixel % frame.region_width,
                     frame.region_y + pixel / frame.region_width);
}

// The image pixel the path works on (pixel_position of its region pixel, kept by
// fetch_pixel).
fn image_position(path: ptr<function, PathState>) -> vec2<u32> {
    return vec2<u32>((*path).image_x, (*path).image_y);
}

// The material of the hit the path is lighting, as shading_material made it: its
// record with the textured albedo, roughness and metalness kept in the path state.
fn lit_material(path: ptr<function, PathState>) -> Material {
    var material = materials[(*path).material];
    material.diffuse = (*path).albedo;
    material.roughness = (*path).roughness;
    material.metallic = (*path).metallic;
    return material;
}

//#if PATH
// Whether this trace uses the path integrator.
fn path_mode() -> bool {
    return (frame.flags & FLAG_PATH) != 0u;
}
//#endif
