// The trace kernels, a wavefront of path states: each slot of `paths` owns one
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
// - `trace_rays` runs that ray's BVH traversal (traverse.wgsl).
//
// No invocation's work grows with the scene's depth, lights, samples or size: each
// runs one traversal or one shading step and its cheap bookkeeping, within
// frame.iteration_budget loop iterations, and resumes in the next dispatch where it
// stopped. A slot's pixel gets every sample and every ray from that slot alone, so
// its sums happen in one fixed order: the image does not depend on how many slots,
// dispatches or budgets it took.
//
// Each step hands the hit or shadow ray it consumes to the integrator of the trace:
// Whitted's (trace.wgsl) or, with FLAG_PATH, the path integrator (path.wgsl).

#import types
#import path_types
#import bindings
#import records
#import budget
#import color
#import camera
#import noise
#import intersect
#import medium
#import traverse
#import slot
#import trace
//#if PATH
#import path
//#endif
//#if AOV
#import aov
//#endif

// Gives a trace of the path integrator the stochastic transparency seed of the path's
// current bounce (path_blend_seed); the Whitted integrator's traces keep none.
fn seed_blend(path: ptr<function, PathState>, trace: ptr<function, TraceRay>) {
    //#if ALPHA
    //#if PATH
    if path_mode() {
        (*trace).blend_seed = path_blend_seed(path);
    }
    //#endif
    //#endif
}

// Shades the finished closest-hit trace of the path's current ray with the trace's
// integrator.
fn consume_closest_trace(slot: u32, path: ptr<function, PathState>, trace: TraceRay) {
    //#if AOV
    // Depth 0 is the camera ray: every branch and bounce is one deeper.
    let first_hit = aov_mode() && (*path).depth == 0u;
    //#endif
    if trace.best_prim == NO_PRIM {
        //#if AOV
        if first_hit {
            add_missed_aov((*path).pixel);
        }
        //#endif
        //#if PATH
        if path_mode() {
            path_miss(path);
            return;
        }
        //#endif
        consume_miss(path);
        return;
    }
    let ray = Ray((*path).origin, (*path).direction);
    let hit = hit_record_keyed(trace.best_prim, trace.best_instance, ray, trace.best_t);
    // Every ray spawned here starts as wide as the cone is here and keeps the spread
    // (PreparedScene::cone_width_at; the specular bounces of JCGT 10(1), 2021, §3,
    // without the curvature term).
    let cone_width = (*path).cone_width + frame.cone_spread * hit.t;
    if (*path).pass_throughs < MAX_PASS_THROUGHS
        && culls_back_face(materials[hit.material].cull_back_faces != 0u, (*path).depth, ray.direction, hit.normal) {
        (*path).origin = offset_ray_origin(hit.position, hit.normal, frame.offset_scale);
        (*path).cone_width = cone_width;
        (*path).phase = PHASE_PASS_THROUGH;
        return;
    }
    let surface = resolve_surface(hit, ray, cone_width, MediumStack((*path).medium_iors, (*path).medium_depth));
    //#if AOV
    if first_hit {
        add_first_hit_aov((*path).pixel, surface, trace.best_t);
    }
    //#endif
    //#if PATH
    if path_mode() {
        // From here on the path's cone_width is the cone's width at the hit, where
        // every ray spawned here starts.
        (*path).cone_width = cone_width;
        path_closest_hit(path, trace, surface);
        return;
    }
    //#endif
    consume_closest_hit(slot, path, surface);
}

// Starts the shadow ray of the next light that faces the shading point and returns
// true; after the last light, adds the hit's emission plus its direct light times the
// base weight and moves on to the bounce stack (false).
fn next_light(path: ptr<function, PathState>, trace: ptr<function, TraceRay>) -> bool {
    if (*path).light >= frame.light_count {
        //#if PATH
        if path_mode() {
            // The path integrator's next-event estimation of an emitter comes last
            // (shade_step draws its sample).
            (*path).phase = PHASE_START_EMITTER;
            return false;
        }
        //#endif
        finish_lights(path);
        return false;
    }
    let sample = sample_light(lights[(*path).light], (*path).shadow_origin, (*path).normal);
    if !sample.lit {
        (*path).light += 1u;
        return false;
    }
    (*path).rays += 1u;
    start_trace(trace, (*path).shadow_origin, sample.wi, sample.distance, true);
    seed_blend(path, trace);
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
    (*path).cone_width = entry.cone_width;
    (*path).rays += 1u;
    start_trace(trace, entry.origin, entry.direction, bitcast<f32>(0x7f800000u), false);
    seed_blend(path, trace);
    (*path).phase = PHASE_CLOSEST;
    return true;
}

// Starts the camera ray of the path's current sample (Owen-scrambled Sobol, box
// filter), inside the dielectrics around the camera.
fn start_sample(path: ptr<function, PathState>, trace: ptr<function, TraceRay>) {
    let xy = image_position(path);
    let offset = sample_offset(xy.x, xy.y, (*path).sample);
    let camera = camera_ray(xy.x, xy.y, (*path).sample, offset);
    let direction = camera.direction;
    let origin = camera.origin;
    (*path).radiance = vec3<f32>(0.0);
    (*path).origin = origin;
    (*path).direction = direction;
    (*path).weight = vec3<f32>(1.0);
    (*path).depth = 0u;
    (*path).medium_depth = frame.camera_medium_depth;
    (*path).medium_iors = frame.camera_medium_iors;
    (*path).stack_len = 0u;
    (*path).held_top = 0u;
    (*path).pass_throughs = 0u;
    (*path).cone_width = frame.cone_width;
    (*path).rays += 1u;
    start_trace(trace, origin, direction, bitcast<f32>(0x7f800000u), false);
    seed_blend(path, trace);
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
                                             luminance((*path).radiance), (*path).sample);
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
    //#if AOV
    if aov_mode() && frame.first_sample == 0u {
        clear_pixel_aov(pixel);
    }
    //#endif
    (*path).phase = PHASE_START_SAMPLE;
}

// One shading step of a slot: consumes its finished traversal (if any), then moves
// the path on through the cheap phases in their natural order (the lights that cast
// no ray, the end of the hit, the bounce stack, the end of the sample or pixel, the
// next pixel, the next camera ray) until a new traversal starts, the slot runs out of
// pixels, or the budget is spent (the path then stays in its phase and the next step
// continues there). Straight-line code, so that each phase's code runs once per step
// on SIMD devices that execute every branch (llvmpipe). Without `may_start` a path
// that reaches its next sample waits there (see trace_paths, LOCKSTEP_SAMPLES).
fn shade_step(slot: u32, path: ptr<function, PathState>, trace: ptr<function, TraceRay>,
              may_start: bool) {
    //#if PATH
    // The finished emitter shadow ray, consumed below with the step's emitter sample.
    var emitter_trace = *trace;
    var consume_emitter = false;
    //#endif
    if (*trace).status == TRACE_DONE {
        (*trace).status = TRACE_IDLE;
        if (*path).phase == PHASE_CLOSEST {
            consume_closest_trace(slot, path, *trace);
        } else if (*path).phase == PHASE_SHADOW {
            consume_shadow_ray(path, *trace);
        }
        //#if PATH
        if (*path).phase == PHASE_EMITTER {
            consume_emitter = true;
            emitter_trace = *trace;
        }
        //#endif
    }
    if (*path).phase == PHASE_PASS_THROUGH {
        // The camera ray again, from beyond the back face it passed (culls_back_face).
        (*path).pass_throughs += 1u;
        (*path).rays += 1u;
        start_trace(trace, (*path).origin, (*path).direction, bitcast<f32>(0x7f800000u), false);
        seed_blend(path, trace);
        (*path).phase = PHASE_CLOSEST;
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
    //#if PATH
    // Next-event estimation's emitter sample, drawn at one call site for the step that
    // starts its shadow ray and the step that consumes it (the same numbers give the
    // same sample; a step does one or the other, never both).
    if consume_emitter || (*path).phase == PHASE_START_EMITTER {
        let sample = path_emitter_sample(path);
        if consume_emitter {
            path_consume_emitter(path, emitter_trace, sample);
        } else {
            path_start_emitter(path, trace, sample);
        }
    }
    //#endif
    if (*path).phase == PHASE_POP {
        _ = pop_ray(slot, path, trace);
    }
    if (*path).phase == PHASE_END_SAMPLE {
        end_sample(path);
    }
    if (*path).phase == PHASE_FETCH_PIXEL || (*path).phase == PHASE_FIRST_PIXEL {
        fetch_pixel(slot, path);
    }
    if (*path).phase == PHASE_START_SAMPLE && may_start {
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
    shade_step(slot, &path, &trace, true);
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
    if traverse(slot, &trace, false) == TRAVERSAL_FINISHED {
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
    //#if LOCKSTEP_SAMPLES
    // Whitted samples start in lockstep: a lane whose sample is done waits until every
    // lane of its subgroup still here is done with theirs, and they start their next
    // samples (or pixels) together. So the rays that a vector traverses at once are
    // all camera rays or all shadow rays of the same light, from neighbouring pixels,
    // and walk the same nodes; before, lanes whose pixels take fewer rays per sample
    // (the background's one against a lit hit's two) drifted into other phases and
    // other pixels, and a vector walked the union of unrelated rays' nodes. Waiting
    // costs little on SIMD devices, where an iteration costs the same for one lane as
    // for all of them (traverse.wgsl), and a Whitted pixel's samples take nearly the
    // same rays. On lavapipe it traced the bunny 20% faster, the million-triangle
    // terrain 15%, models.toml 20%, glass.toml 32% and the showcase 9%
    // (BENCHMARKS.md, "Samples in lockstep"). Not for the path integrator: its paths
    // end at random depths, so lanes wait for the longest, and a path-traced Cornell
    // box took 30% longer in lockstep.
    let lockstep = (frame.flags & FLAG_PATH) == 0u;
    //#endif
    var exited = false;
    loop {
        if trace_in_flight(trace) {
            let outcome = traverse(slot, &trace, give_way);
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
        var may_start = true;
        //#if LOCKSTEP_SAMPLES
        // The vote is over the lanes still in the loop (those whose budget is spent
        // have left, and vote again in the next dispatch).
        if lockstep {
            may_start = subgroupAll(path.phase == PHASE_START_SAMPLE);
        }
        //#endif
        // A lane whose traversal gave way resumes it in the next pass.
        if !trace_in_flight(trace) {
            iterations += 1u;
            shade_step(slot, &path, &trace, may_start);
        }
    }
    if !exited {
        atomicOr(&counters.errors, ERROR_LOOP_CUT);
    }
    paths[slot] = path;
    traces[slot] = trace;
}
