// The Whitted tracer as a wavefront of path states: each slot of `paths` owns one
// pixel at a time and walks its samples' ray trees with the CPU reference's stack
// discipline (src/cpu/trace.rs: same bounce stack, same order of every sum), but one
// ray at a time, in two small kernels that the host dispatches in turns (Laine,
// Karras and Aila, "Megakernels Considered Harmful: Wavefront Path Tracing on GPUs",
// HPG 2013):
//
// - `shade_paths` consumes the slot's finished trace (shades a hit, pushes the
//   reflected and refracted rays, adds a light's contribution) and advances the path
//   to its next ray: the next light's shadow ray, the next ray on the bounce stack,
//   the next sample's camera ray, or the next pixel, which it takes from a shared
//   counter;
// - `trace_rays` runs that ray's BVH traversal (shaders/traverse.wgsl).
//
// No invocation's work grows with the scene's depth, lights, samples or size: each
// runs one traversal or one shading step and its cheap bookkeeping, within
// frame.iteration_budget loop iterations, and resumes in the next dispatch where it
// stopped. A slot's pixel gets every sample and every ray from that slot alone, so
// its sums happen in one fixed order: the image does not depend on how many slots,
// dispatches or budgets it took.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
// binding 1: `spheres`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 2: `planes`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 3: `polygons`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 4: `polygon_points`, each polygon vertex projected for the inside test (the
// plane's dropped axis removed), read by polygon_point(i); declared by
// src/gpu/uniform_records.rs.
// binding 5: `triangles`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 6: `materials`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 7: `lights`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
@group(0) @binding(8) var linear_output: texture_storage_2d<rgba32float, write>;
@group(0) @binding(9) var<storage, read_write> counters: Counters;
// Each finished pixel's sample sum in xyz and its luminance m2 in w (shaders/noise.wgsl)
// when frame.flags has FLAG_STORE_SUM, and the sums a pixel starts from when
// frame.first_sample > 0: progressive rendering.
@group(0) @binding(10) var<storage, read_write> accumulation: array<vec4<f32>>;
// binding 11: `images` (shaders/texture.wgsl).
// binding 12: `bvh_nodes`, a storage or a uniform array, declared by src/gpu/uniform_records.rs.
// binding 13: `bvh_prims`, read by prim_ref(i); declared by src/gpu/uniform_records.rs.
@group(0) @binding(14) var<storage, read_write> paths: array<PathState>;
// Each slot's bounce stack of frame.stack_size entries (interleaved across slots).
@group(0) @binding(15) var<storage, read_write> ray_stack: array<StackEntry>;
@group(0) @binding(16) var<storage, read_write> traces: array<TraceRay>;
// Each slot's traversal stack of MAX_BVH_DEPTH entries (interleaved across slots).
@group(0) @binding(17) var<storage, read_write> traversal_stack: array<u32>;
// Vertex normals and texture coordinates of mesh triangles (Triangle.attributes).
@group(0) @binding(18) var<storage, read> triangle_attributes: array<TriangleAttributes>;

// Squared point-light distances below the smallest normal f32 (2^-126) contribute
// nothing: I / r² would be infinite or NaN. Twin of MIN_LIGHT_DISTANCE_SQUARED.
const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1.17549435e-38;
// The least cosine to the geometric surface a bent secondary ray keeps. Twin of
// MIN_SECONDARY_COSINE (src/cpu/trace.rs).
const MIN_SECONDARY_COSINE: f32 = 1e-3;

// Branches whose weight is not above the smallest normal f32 are not traced, whatever
// the cutoff. Twin of MIN_BRANCH_WEIGHT.
const MIN_BRANCH_WEIGHT: f32 = 1.17549435e-38;

// The dielectrics a ray is inside, outermost first (the per-path medium stack; the
// rule is documented on the CPU twin, MediumStack in src/scene/medium.rs): a refracted
// ray entering a dielectric pushes its index, one leaving pops; reflected rays keep
// the stack. Entries past `depth` are unused; deeper nesting than 4 keeps counting.
struct MediumStack {
    iors: vec4<f32>,
    depth: u32,
}

//#if REFRACTION
// The index of refraction `level` dielectrics deep (0 = air, index 1).
fn medium_ior_at(medium: MediumStack, level: u32) -> f32 {
    if level == 0u {
        return 1.0;
    }
    // Entry min(level, 4) - 1, picked with selects rather than a dynamic index.
    let i = min(level, 4u) - 1u;
    let v = medium.iors;
    return select(select(select(v.x, v.y, i == 1u), v.z, i == 2u), v.w, i == 3u);
}
//#endif

//#if REFRACTION
// The index on the outside of a dielectric surface: the current medium when entering,
// else the enclosing one.
fn medium_outside_ior(medium: MediumStack, entering: bool) -> f32 {
    if entering {
        return medium_ior_at(medium, medium.depth);
    }
    return medium_ior_at(medium, max(medium.depth, 1u) - 1u);
}
//#endif

//#if REFRACTION
// The stack of the refracted ray: `ior` pushed when entering, else popped.
fn medium_after_refraction(medium: MediumStack, entering: bool, ior: f32) -> MediumStack {
    var next = medium;
    if entering {
        // Entry `depth` (if below 4) becomes `ior`, set with a select rather than a
        // dynamic index.
        next.iors = select(next.iors, vec4<f32>(ior), vec4<u32>(0u, 1u, 2u, 3u) == vec4<u32>(next.depth));
        next.depth += 1u;
    } else if next.depth > 0u {
        next.depth -= 1u;
    }
    return next;
}
//#endif

// Whether every component is finite, read from the exponent bits so that no
// fast-math assumption of the shader compiler can fold the test away. The guard on
// every contribution; twin of finite_radiance.
fn finite_radiance(c: vec3<f32>) -> bool {
    let exponent = bitcast<vec3<u32>>(c) & vec3<u32>(0x7f800000u);
    return all(exponent != vec3<u32>(0x7f800000u));
}

fn max_component(c: vec3<f32>) -> f32 {
    return max(c.x, max(c.y, c.z));
}

// Adds `weight × radiance` to the sample's radiance if it is finite.
fn add_contribution(path: ptr<function, PathState>, contribution: vec3<f32>) {
    if finite_radiance(contribution) {
        (*path).radiance += contribution;
    }
}

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
                      0u, 0u, u32(any_hit), NO_INSTANCE, NO_INSTANCE, 0u, 0u, 0u);
}

// What a light does at a shading point: the direction to it, its distance, the
// irradiance it delivers on a surface facing it, and cos θi; `lit` is false when it
// contributes nothing and casts no shadow ray (behind the surface, or a point light
// at zero distance). Twin of the geometry part of direct_light.
struct LightSample {
    wi: vec3<f32>,
    distance: f32,
    irradiance: vec3<f32>,
    cos_i: f32,
    lit: bool,
}

// `n` is the shading normal (facing the incoming ray): a light lights the point when it
// is above `n` and its shadow ray, from the lifted point, reaches it. CPU twin:
// direct_light.
fn sample_light(light: Light, origin: vec3<f32>, n: vec3<f32>) -> LightSample {
    var sample = LightSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, false);
    if light.kind == LIGHT_POINT {
        let to_light = light.position_or_direction - origin;
        let distance_squared = dot(to_light, to_light);
        if !(distance_squared >= MIN_LIGHT_DISTANCE_SQUARED) {
            return sample;
        }
        sample.distance = sqrt(distance_squared);
        sample.wi = to_light / sample.distance;
        // Inverse-square law: E = I / r² on a surface facing the light.
        sample.irradiance = light.power / distance_squared;
    } else {
        sample.wi = -light.position_or_direction;
        sample.distance = bitcast<f32>(0x7f800000u); // +infinity
        sample.irradiance = light.power;
    }
    sample.cos_i = clamp(dot(n, sample.wi), -1.0, 1.0);
    sample.lit = sample.cos_i > 0.0;
    return sample;
}

//#if MESH_ATTRIBUTES
// The normal a hit is shaded with: the shading normal `ns`, tilted towards the viewer
// where the ray would arrive behind it, normalize(ns + (c_min - wo·ns)·wo) (continuous,
// so no facet edge shows; Veach's thesis, 1997, §5.3, on shading normals). CPU twin:
// shading_frame_normal.
fn shading_frame_normal(direction: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>) -> vec3<f32> {
    if all(ns == ng) {
        return ng;
    }
    let wo = -direction;
    let cosine = dot(wo, ns);
    if cosine >= MIN_SECONDARY_COSINE {
        return ns;
    }
    return normalize(ns + wo * (MIN_SECONDARY_COSINE - cosine));
}

// A secondary direction computed about a shading normal, kept on the side of the
// geometric surface `side` points to, at a cosine of at least MIN_SECONDARY_COSINE: the
// bent reflection of Keller et al., "The Iray Light Transport Simulation and Rendering
// System" (2017). CPU twin: keep_on_side.
fn keep_on_side(d: vec3<f32>, side: vec3<f32>) -> vec3<f32> {
    let cosine = dot(d, side);
    if cosine >= MIN_SECONDARY_COSINE {
        return d;
    }
    return normalize(d + side * (MIN_SECONDARY_COSINE - cosine));
}
//#endif

// Shades the hit (or miss) of the path's current ray, as shade_hit and trace_radiance
// do on the CPU: a miss adds the background (background_radiance: the environment map
// or the constant); a hit pushes the refracted, then the
// reflected branch, and either adds its emission at once or, for a surface with a base
// BRDF, starts gathering its lights (PHASE_NEXT_LIGHT), the ambient term first.
fn consume_closest_hit(slot: u32, path: ptr<function, PathState>, trace: TraceRay) {
    //#if PATH
    if path_mode() {
        path_closest_hit(path, trace);
        return;
    }
    //#endif
    let ray = Ray((*path).origin, (*path).direction);
    if trace.best_prim == NO_PRIM {
        add_contribution(path, (*path).weight * background_radiance(ray.direction));
        (*path).phase = PHASE_POP;
        return;
    }
    let hit = hit_record_in(trace.best_prim, trace.best_instance, ray, trace.best_t);
    let material = shading_material(materials[hit.material], hit.position, hit.normal, hit.uv);
    let entering = dot(ray.direction, hit.normal) < 0.0;
    // Shading happens on the side the ray came from.
    let ng = select(-hit.normal, hit.normal, entering);
    let medium = MediumStack((*path).medium_iors, (*path).medium_depth);
    //#if REFRACTION
    let outside_ior = medium_outside_ior(medium, entering);
    //#else
    // Without dielectrics every ray travels in air.
    let outside_ior = 1.0;
    //#endif
    //#if MESH_ATTRIBUTES
    let ns = select(-hit.shading_normal, hit.shading_normal, entering);
    let n = shading_frame_normal(ray.direction, ng, ns);
    let lifted = shadow_terminator_point(hit, ng);
    //#else
    let n = ng;
    let lifted = hit.position;
    //#endif
    var response = surface_response(material, ray.direction, n, entering, outside_ior);
    var reflected = normalize(reflect_direction(ray.direction, n));
    //#if MESH_ATTRIBUTES
    if any(n != ng) {
        reflected = keep_on_side(reflected, ng);
        response.transmit_direction = keep_on_side(response.transmit_direction, -ng);
    }
    //#endif
    if (*path).depth < frame.max_depth {
        // Refraction is pushed first so that reflection is traced first.
        //#if REFRACTION
        let inside = medium_after_refraction(medium, entering, material.ior);
        push_branch(slot, path, StackEntry(
            offset_ray_origin(hit.position, -ng, frame.offset_scale), (*path).depth + 1u,
            response.transmit_direction, inside.depth,
            (*path).weight * response.transmit, 0u, inside.iors));
        //#endif
        push_branch(slot, path, StackEntry(
            offset_ray_origin(hit.position, ng, frame.offset_scale), (*path).depth + 1u,
            reflected, medium.depth,
            (*path).weight * response.reflect, 0u, medium.iors));
    }
    if has_base_brdf(material.kind) && response.base > 0.0 {
        (*path).direct = material.diffuse * frame.ambient;
        (*path).albedo = material.diffuse;
        (*path).roughness = material.roughness;
        (*path).metallic = material.metallic;
        (*path).emission = material.emission;
        (*path).material = hit.material;
        (*path).normal = n;
        (*path).base = response.base;
        (*path).shadow_origin = offset_ray_origin(lifted, ng, frame.offset_scale);
        (*path).light = 0u;
        (*path).phase = PHASE_NEXT_LIGHT;
    } else {
        add_contribution(path, (*path).weight * material.emission);
        (*path).phase = PHASE_POP;
    }
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

// Adds the current light's f(wi, wo)·E·cos θi if its shadow ray was unblocked, and
// moves on to the next light.
fn consume_shadow_ray(path: ptr<function, PathState>, trace: TraceRay) {
    //#if PATH
    if path_mode() {
        path_consume_shadow_ray(path, trace);
        return;
    }
    //#endif
    if trace.best_prim == NO_PRIM {
        let sample = sample_light(lights[(*path).light], (*path).shadow_origin, (*path).normal);
        let material = lit_material(path);
        (*path).direct += eval_brdf(material, (*path).normal, sample.wi, -(*path).direction)
            * sample.irradiance * sample.cos_i;
    }
    (*path).light += 1u;
    (*path).phase = PHASE_NEXT_LIGHT;
}

// Starts the shadow ray of the next light that faces the shading point and returns
// true; after the last light, adds the hit's emission plus its direct light times the
// base weight and moves on to the bounce stack (false).
fn next_light(path: ptr<function, PathState>, trace: ptr<function, TraceRay>) -> bool {
    if (*path).light >= frame.light_count {
        //#if PATH
        if path_mode() {
            // The path integrator's next-event estimation of an emitter comes last.
            return path_start_emitter(path, trace);
        }
        //#endif
        add_contribution(path, (*path).weight * ((*path).emission + (*path).direct * (*path).base));
        (*path).phase = PHASE_POP;
        return false;
    }
    let sample = sample_light(lights[(*path).light], (*path).shadow_origin, (*path).normal);
    if !sample.lit {
        (*path).light += 1u;
        return false;
    }
    (*path).rays += 1u;
    start_trace(trace, (*path).shadow_origin, sample.wi, sample.distance, true);
    (*path).phase = PHASE_SHADOW;
    return true;
}

// Pops the next ray of the bounce stack and starts its traversal (true), or ends the
// sample when the stack is empty (false).
fn pop_ray(slot: u32, path: ptr<function, PathState>, trace: ptr<function, TraceRay>) -> bool {
    if (*path).stack_len == 0u {
        (*path).phase = PHASE_END_SAMPLE;
        return false;
    }
    (*path).stack_len -= 1u;
    var entry = (*path).held;
    if (*path).held_top == 0u {
        entry = ray_stack[ray_stack_index(slot, (*path).stack_len)];
    }
    (*path).held_top = 0u;
    (*path).origin = entry.origin;
    (*path).direction = entry.direction;
    (*path).weight = entry.weight;
    (*path).depth = entry.depth;
    (*path).medium_depth = entry.medium_depth;
    (*path).medium_iors = entry.medium_iors;
    (*path).rays += 1u;
    start_trace(trace, entry.origin, entry.direction, bitcast<f32>(0x7f800000u), false);
    (*path).phase = PHASE_CLOSEST;
    return true;
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

// Starts the camera ray of the path's current sample (jittered stratified, box
// filter), inside the dielectrics around the camera.
fn start_sample(path: ptr<function, PathState>, trace: ptr<function, TraceRay>) {
    let xy = image_position(path);
    let offset = sample_offset(xy.x, xy.y, (*path).sample);
    let direction = camera_ray_direction(f32(xy.x) + offset.x, f32(xy.y) + offset.y);
    (*path).radiance = vec3<f32>(0.0);
    (*path).origin = frame.eye;
    (*path).direction = direction;
    (*path).weight = vec3<f32>(1.0);
    (*path).depth = 0u;
    (*path).medium_depth = frame.camera_medium_depth;
    (*path).medium_iors = frame.camera_medium_iors;
    (*path).stack_len = 0u;
    (*path).held_top = 0u;
    (*path).rays += 1u;
    start_trace(trace, frame.eye, direction, bitcast<f32>(0x7f800000u), false);
    (*path).phase = PHASE_CLOSEST;
}

// Adds the finished sample to the pixel's sum and its luminance to the pixel's m2
// (the noise estimate); after the last sample of the range,
// writes the pixel (the mean over frame.end_sample samples, black if not finite),
// counts its rays and moves on to the next pixel.
fn end_sample(path: ptr<function, PathState>) {
    let before = (*path).pixel_sum;
    (*path).pixel_sum += (*path).radiance;
    (*path).luminance_m2 = luminance_m2_step((*path).luminance_m2, before, (*path).pixel_sum,
                                             sample_luminance((*path).radiance), (*path).sample);
    (*path).sample += 1u;
    if (*path).sample < frame.end_sample {
        (*path).phase = PHASE_START_SAMPLE;
        return;
    }
    var mean = (*path).pixel_sum / f32(frame.end_sample);
    // The sum of finite contributions may still overflow: the pixel is then black.
    if !finite_radiance(mean) {
        mean = vec3<f32>(0.0);
    }
    if (frame.flags & FLAG_STORE_SUM) != 0u {
        accumulation[(*path).pixel] = vec4<f32>((*path).pixel_sum, (*path).luminance_m2);
    }
    let xy = image_position(path);
    textureStore(linear_output, vec2<u32>(xy.x - frame.target_x, xy.y - frame.target_y),
                 vec4<f32>(mean, 1.0));
    // 64-bit ray count as two words: carry when the low word wraps.
    let low = atomicAdd(&counters.rays_low, (*path).rays);
    if low + (*path).rays < low {
        atomicAdd(&counters.rays_high, 1u);
    }
    atomicAdd(&counters.pixels_done, 1u);
    (*path).phase = PHASE_FETCH_PIXEL;
}

// Takes the slot's next pixel of the region, or goes idle: slot s takes pixels s,
// s + slot_count, s + 2·slot_count, ... below frame.static_pixels (the first few
// rounds), so that neighbouring lanes start on neighbouring pixels, and the rest from
// the shared counter, so that the slots that finish first take the next pixels
// (static_pixels_for in src/gpu/layout.rs).
fn fetch_pixel(slot: u32, path: ptr<function, PathState>) {
    var pixel = (*path).pixel + frame.slot_count;
    if (*path).phase == PHASE_FIRST_PIXEL {
        pixel = slot;
    }
    if pixel >= frame.static_pixels {
        pixel = frame.static_pixels + atomicAdd(&counters.next_pixel, 1u);
    }
    if pixel >= frame.region_width * frame.region_height {
        (*path).phase = PHASE_IDLE;
        return;
    }
    (*path).pixel = pixel;
    let xy = pixel_position(pixel);
    (*path).image_x = xy.x;
    (*path).image_y = xy.y;
    (*path).sample = frame.first_sample;
    (*path).rays = 0u;
    (*path).pixel_sum = vec3<f32>(0.0);
    (*path).luminance_m2 = 0.0;
    if frame.first_sample > 0u {
        let sums = accumulation[pixel];
        (*path).pixel_sum = sums.xyz;
        (*path).luminance_m2 = sums.w;
    }
    (*path).phase = PHASE_START_SAMPLE;
}

// One shading step of a slot: consumes its finished traversal (if any), then moves
// the path on through the cheap phases in their natural order (the lights that cast
// no ray, the end of the hit, the bounce stack, the end of the sample or pixel, the
// next pixel, the next camera ray) until a new traversal starts, the slot runs out of
// pixels, or the budget is spent (the path then stays in its phase and the next step
// continues there). Straight-line code, so that each phase's code runs once per step
// on SIMD devices that execute every branch (llvmpipe).
fn shade_step(slot: u32, path: ptr<function, PathState>, trace: ptr<function, TraceRay>) {
    if (*trace).status == TRACE_DONE {
        (*trace).status = TRACE_IDLE;
        if (*path).phase == PHASE_CLOSEST {
            consume_closest_hit(slot, path, *trace);
        } else if (*path).phase == PHASE_SHADOW {
            consume_shadow_ray(path, *trace);
        }
        //#if PATH
        if (*path).phase == PHASE_EMITTER {
            path_consume_emitter(path, *trace);
        }
        //#endif
    }
    if (*path).phase == PHASE_NEXT_LIGHT {
        // Lights behind the surface cast no ray: skip them here. At least one light
        // per step, so that any budget makes progress: the step itself was charged an
        // iteration, and a budget of 1 would otherwise spend it on nothing, forever.
        var exited = false;
        var lights = 0u;
        loop {
            if (lights > 0u && iterations >= frame.iteration_budget)
                || (*path).phase != PHASE_NEXT_LIGHT {
                exited = true;
                break;
            }
            lights += 1u;
            iterations += 1u;
            if next_light(path, trace) {
                exited = true;
                break;
            }
        }
        if !exited {
            atomicOr(&counters.errors, ERROR_LOOP_CUT);
        }
    }
    if (*path).phase == PHASE_POP {
        _ = pop_ray(slot, path, trace);
    }
    if (*path).phase == PHASE_END_SAMPLE {
        end_sample(path);
    }
    if (*path).phase == PHASE_FETCH_PIXEL || (*path).phase == PHASE_FIRST_PIXEL {
        fetch_pixel(slot, path);
    }
    if (*path).phase == PHASE_START_SAMPLE {
        start_sample(path, trace);
    }
}

// The wavefront schedule's shading kernel: one shading step per slot.
@compute @workgroup_size(256, 1, 1)
fn shade_paths(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if slot >= frame.slot_count {
        return;
    }
    var path = paths[slot];
    if path.phase == PHASE_IDLE {
        return;
    }
    var trace = traces[slot];
    if trace_in_flight(trace) {
        return;
    }
    iterations = 0u;
    shade_step(slot, &path, &trace);
    paths[slot] = path;
    traces[slot] = trace;
}

// The wavefront schedule's traversal kernel: one traversal (or its part within the
// budget) per slot.
@compute @workgroup_size(256, 1, 1)
fn trace_rays(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if slot >= frame.slot_count {
        return;
    }
    var trace = traces[slot];
    if !trace_in_flight(trace) {
        return;
    }
    iterations = 0u;
    if advance_traversal(slot, &trace, false) == TRAVERSAL_FINISHED {
        trace.status = TRACE_DONE;
    }
    traces[slot] = trace;
}

// The fused schedule's only kernel: each slot alternates traversals and shading steps
// until its budget is spent or it runs out of pixels, keeping its state in registers
// between rays. The same functions in the same order as the wavefront schedule, so
// the image is the same.
@compute @workgroup_size(256, 1, 1)
fn trace_paths(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if slot >= frame.slot_count {
        return;
    }
    var path = paths[slot];
    if path.phase == PHASE_IDLE {
        return;
    }
    var trace = traces[slot];
    iterations = 0u;
    // Whitted traversals give way to finished lanes (REFILL_LANES); the path
    // integrator's do not, as its heavier shading step made that 3-4% slower on a
    // Cornell box (BENCHMARKS.md, "Replacing finished rays").
    let give_way = (frame.flags & FLAG_PATH) == 0u;
    var exited = false;
    loop {
        if trace_in_flight(trace) {
            let outcome = advance_traversal(slot, &trace, give_way);
            if outcome == TRAVERSAL_SUSPENDED {
                exited = true;
                break;
            }
            if outcome == TRAVERSAL_FINISHED {
                trace.status = TRACE_DONE;
            }
        }
        if path.phase == PHASE_IDLE || iterations >= frame.iteration_budget {
            exited = true;
            break;
        }
        // A lane whose traversal gave way resumes it in the next pass.
        if !trace_in_flight(trace) {
            iterations += 1u;
            shade_step(slot, &path, &trace);
        }
    }
    if !exited {
        atomicOr(&counters.errors, ERROR_LOOP_CUT);
    }
    paths[slot] = path;
    traces[slot] = trace;
}
