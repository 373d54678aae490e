// The path-tracing integrator (`integrator = "path"`): the WGSL twin of
// src/cpu/path.rs (path_radiance) and of its samplers, src/sample.rs, documented
// in docs/path-tracing.md. It runs in the wavefront engine of wavefront.wgsl, one
// bounce per shading step, when frame.flags has FLAG_PATH:
//
// - a miss adds the background, or the environment map's radiance weighted by multiple
//   importance sampling against its next-event estimation (environment.wgsl);
// - at a hit (path_closest_hit) the path adds the emission it finds (weighted by
//   multiple importance sampling against next-event estimation), picks one event of
//   the material, and decides its continuation at once: the next ray (BRDF-sampled,
//   or the mirror or refracted one), after Russian roulette, goes on the slot's bounce
//   stack, which the path integrator uses for that one entry. Every random number is
//   counter-based (random_number), so drawing them early changes nothing;
// - for the base BRDF it then gathers direct light as Whitted does, one shadow ray per
//   point or directional light (PHASE_NEXT_LIGHT, PHASE_SHADOW), each contribution
//   added on its own, and last one shadow ray towards a point sampled on one emitter
//   or a direction sampled from the environment map (PHASE_EMITTER), whose sample is drawn again from the same numbers when the ray
//   comes back, so that nothing but the phase is kept between the two steps;
// - PHASE_POP then pops the continuation, or ends the sample when there is none.
//
// The path therefore draws the CPU's numbers for the CPU's decisions, in the CPU's
// order of sums: the images agree per pixel within f32 rounding (tests/integration/path_gpu.rs).

#import types
#import path_types
#import bindings
#import records
#import math
#import color
#import sample
#import medium
#import intersect
#import texture
#import bxdf
#import slot
#import area_lights
#import trace
//#if ALPHA
#import coverage
//#endif
//#if ENVIRONMENT_MAP
#import environment
//#endif
//#if TABULATED
#import tabulated
//#endif

// Bounces after which Russian roulette may end a path. Twin of ROULETTE_DEPTH.
const ROULETTE_DEPTH: u32 = 3u;
// The least survival probability of Russian roulette. Twin of MIN_SURVIVAL.
const MIN_SURVIVAL: f32 = 0.05;
// Random dimensions a path uses per bounce: the event (0), the BRDF lobe (1), the
// BRDF direction (2, 3), the light (4: the environment map or an emitter), the point
// on the emitter or the map's direction (5, 6) and roulette (7);
// dimensions 0 and 1 of a sample are its position in the pixel. Twin of
// DIMENSIONS_PER_BOUNCE.
const DIMENSIONS_PER_BOUNCE: u32 = 8u;
// PathState.brdf_pdf of a ray that no BRDF sample made (a camera ray, or one after a
// perfectly specular event): its emission is not weighted.
const NO_BRDF_PDF: f32 = -1.0;

//#if ALPHA
// The dimension of a bounce whose hash (blend_seed) seeds its rays' stochastic
// transparency: roulette's, which uses its top bits directly, while the draws hash it
// again with each surface (blend_number). Twin of BLEND_DIMENSION.
const BLEND_DIMENSION: u32 = 7u;

// The stochastic transparency seed of the rays of the path's current bounce. Twin of
// the `blend` of path_radiance's loop.
fn path_blend_seed(path: ptr<function, PathState>) -> u32 {
    let xy = image_position(path);
    let dimension = 2u + (*path).depth * DIMENSIONS_PER_BOUNCE + BLEND_DIMENSION;
    return blend_seed(xy.y * frame.width + xy.x, (*path).sample, dimension);
}
//#endif

// Random number `k` of the path's current bounce: dimension 2 + 8·depth + k of its
// sample, for its image pixel (y·width + x).
fn path_random(path: ptr<function, PathState>, k: u32) -> f32 {
    let xy = image_position(path);
    let dimension = 2u + (*path).depth * DIMENSIONS_PER_BOUNCE + k;
    return random_number(xy.y * frame.width + xy.x, (*path).sample, dimension);
}

// The probability that next-event estimation picks the environment rather than an
// area light: 0 without a map. Twin of environment_selection (src/cpu/path.rs).
fn environment_selection() -> f32 {
    //#if ENVIRONMENT_MAP
    return environment.header.selection;
    //#else
    return 0.0;
    //#endif
}

// The probability that the base BRDF's sampler picks its specular lobe (the lobes mixed
// in proportion to their weights). Twin of specular_lobe_probability.
fn specular_lobe_probability(material: Material) -> f32 {
    var p = 0.0;
    //#if BLINN_PHONG
    if material.kind == MATERIAL_BLINN_PHONG {
        let d = luminance(material.diffuse);
        let s = luminance(material.specular);
        if d + s > 0.0 {
            p = s / (d + s);
        }
    }
    //#endif
    //#if COOK_TORRANCE
    if material.kind == MATERIAL_COOK_TORRANCE {
        p = select(1.0, 0.5, max_component(material.diffuse) > 0.0);
    }
    //#endif
    //#if PBR
    if material.kind == MATERIAL_PBR {
        p = 0.5 + 0.5 * material.metallic;
    }
    //#endif
    return p;
}

// A half vector of the material's specular lobe in the local frame (`wo` local). Twin
// of sample_half_vector.
fn sample_half_vector(material: Material, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    var h = vec3<f32>(0.0, 0.0, 1.0);
    //#if BLINN_PHONG
    if material.kind == MATERIAL_BLINN_PHONG {
        h = sample_blinn_phong_half(material.shininess, u);
    }
    //#endif
    //#if COOK_TORRANCE || PBR
    if material.kind == MATERIAL_COOK_TORRANCE || material.kind == MATERIAL_PBR {
        let alpha = microfacet_alpha(material.roughness);
        //#if COOK_TORRANCE
        if material.kind == MATERIAL_COOK_TORRANCE && material.distribution == DISTRIBUTION_BECKMANN {
            h = sample_beckmann_normal(alpha, u);
        } else {
        //#endif
            h = sample_ggx_visible_normal(wo, alpha, u);
        //#if COOK_TORRANCE
        }
        //#endif
    }
    //#endif
    return h;
}

// The density of sample_half_vector at `h`. Twin of pdf_half_vector.
fn pdf_half_vector(material: Material, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    var pdf = 0.0;
    //#if BLINN_PHONG
    if material.kind == MATERIAL_BLINN_PHONG {
        pdf = pdf_blinn_phong_half(h, material.shininess);
    }
    //#endif
    //#if COOK_TORRANCE || PBR
    if material.kind == MATERIAL_COOK_TORRANCE || material.kind == MATERIAL_PBR {
        let alpha = microfacet_alpha(material.roughness);
        //#if COOK_TORRANCE
        if material.kind == MATERIAL_COOK_TORRANCE && material.distribution == DISTRIBUTION_BECKMANN {
            pdf = pdf_beckmann_normal(h, alpha);
        } else {
        //#endif
            pdf = pdf_ggx_visible_normal(wo, h, alpha);
        //#if COOK_TORRANCE
        }
        //#endif
    }
    //#endif
    return pdf;
}

// A direction for the base BRDF at a point of shading normal `n` seen from `wo`
// (world): a tabulated BRDF by its map's inverse CDF (shaders/tabulated.wgsl), else the
// specular lobe with its probability, else the cosine sampler. Twin of sample_brdf.
fn sample_brdf(material: Material, n: vec3<f32>, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> vec3<f32> {
    let basis = shading_frame(n);
    let wo_local = shading_frame_to_local(basis, wo);
    //#if TABULATED
    if material.kind == MATERIAL_TABULATED && material.brdf_map_layer != NO_IMAGE {
        return shading_frame_to_world(basis, sample_tabulated(material.brdf_map_layer,
                                                      material.brdf_map_size, wo_local, u_lobe, u));
    }
    //#endif
    var local = sample_cosine_hemisphere(u);
    if u_lobe < specular_lobe_probability(material) {
        local = reflect_about(wo_local, sample_half_vector(material, wo_local, u));
    }
    return shading_frame_to_world(basis, local);
}

// The density per steradian of sample_brdf producing `wi`: the mixture of its lobes'.
// Twin of pdf_brdf.
fn pdf_brdf(material: Material, n: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let basis = shading_frame(n);
    let wo_local = shading_frame_to_local(basis, wo);
    let wi_local = shading_frame_to_local(basis, wi);
    //#if TABULATED
    if material.kind == MATERIAL_TABULATED && material.brdf_map_layer != NO_IMAGE {
        return pdf_tabulated(material.brdf_map_layer, material.brdf_map_size, wo_local, wi_local);
    }
    //#endif
    let p_specular = specular_lobe_probability(material);
    var pdf = (1.0 - p_specular) * pdf_cosine_hemisphere(wi_local);
    if p_specular > 0.0 {
        let h = normalize_or_zero(wo_local + wi_local);
        if h.z > 0.0 {
            pdf += p_specular * reflected_pdf(pdf_half_vector(material, wo_local, h), dot(wo_local, h));
        }
    }
    return pdf;
}

// The density per steradian with which next-event estimation from `point` samples the
// direction towards `hit`, made in instance `instance` (0 if `hit` is on no sampled
// emitter): a sphere's cone
// density times its selection probability, a flat emitter's selection / area per unit
// area converted to solid angle. Twin of AreaLights::pdf.
fn emitter_pdf(point: vec3<f32>, hit: Hit, instance: u32) -> f32 {
    let index = area_lights_first_piece(hit.prim, instance);
    if index == NO_PRIM {
        return 0.0;
    }
    let emitter = emitters[index];
    //#if SPHERES
    if emitter.kind == EMITTER_SPHERE {
        let w = normalize_or_zero(hit.position - point);
        return emitter.selection * pdf_sphere_cone(point, emitter.v0, emitter.v1.x, w);
    }
    //#endif
    return area_to_solid_angle_pdf(emitter.area_density, point, hit.position, emitter.normal);
}

// Whether emission of the shape hit is seen from the side the ray arrives on: flat
// shapes emit on the side of their normal, or on both for a two_sided material;
// spheres on both. Twin of emits_towards.
fn emits_towards(hit: Hit, direction: vec3<f32>, two_sided: bool) -> bool {
    return two_sided || prim_kind(hit.prim) == PRIM_SPHERE || dot(direction, hit.normal) < 0.0;
}

// Next-event estimation's sample of one light from the path's shadow origin: the
// environment with its selection probability (dimension 4 below it), else an emitter
// chosen by power with the rest of dimension 4's range; a direction towards a point
// on it (dimensions 5, 6), its density per steradian, selection included, and the
// radiance arriving along it; not found when it contributes nothing and casts no ray
// (inside a sphere, behind a one-sided emitter, below the shading normal, a pole of
// the map). Twin of the choice in path_radiance and of the sampling parts of
// sample_emitter and sample_environment.
struct EmitterSample {
    wi: vec3<f32>,
    pdf: f32,
    radiance: vec3<f32>,
    // The emitter record, or ENVIRONMENT_EMITTER.
    emitter: u32,
    found: bool,
}

// EmitterSample.emitter of a sample of the environment map.
const ENVIRONMENT_EMITTER: u32 = 0xffffffffu;

fn path_emitter_sample(path: ptr<function, PathState>) -> EmitterSample {
    var sample = EmitterSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0u, false);
    let origin = (*path).shadow_origin;
    let u_light = path_random(path, 4u);
    let u = vec2<f32>(path_random(path, 5u), path_random(path, 6u));
    let p_environment = environment_selection();
    //#if ENVIRONMENT_MAP
    if u_light < p_environment {
        let drawn = environment_sample(u);
        if !drawn.found {
            return sample;
        }
        sample.emitter = ENVIRONMENT_EMITTER;
        sample.wi = drawn.wi;
        sample.pdf = drawn.pdf * p_environment;
        sample.radiance = drawn.radiance;
        sample.found = sample.pdf > 0.0 && dot((*path).normal, sample.wi) > 0.0;
        return sample;
    }
    //#endif
    let count = emitter_count();
    if count == 0u {
        return sample;
    }
    sample.emitter = area_lights_choose((u_light - p_environment) / (1.0 - p_environment), count);
    let emitter = emitters[sample.emitter];
    sample.radiance = emitter.radiance;
    if emitter.kind == EMITTER_SPHERE {
        //#if SPHERES
        let cone = sample_sphere_cone(origin, emitter.v0, emitter.v1.x, u);
        if !cone.found {
            return sample;
        }
        sample.wi = cone.wi;
        sample.pdf = cone.pdf * (emitter.selection * (1.0 - p_environment));
        //#else
        return sample;
        //#endif
    } else {
        let b = sample_triangle_barycentrics(u);
        let point = emitter.v0 * b.x + emitter.v1 * b.y + emitter.v2 * b.z;
        let to_light = point - origin;
        if emitter.kind != EMITTER_TWO_SIDED_TRIANGLE && dot(to_light, emitter.normal) >= 0.0 {
            // The back of a one-sided emitter.
            return sample;
        }
        sample.pdf = area_to_solid_angle_pdf(emitter.area_density * (1.0 - p_environment), origin,
                                             point, emitter.normal);
        sample.wi = normalize_or_zero(to_light);
    }
    let cos_i = dot((*path).normal, sample.wi);
    sample.found = sample.pdf > 0.0 && cos_i > 0.0 && any(sample.wi != vec3<f32>(0.0));
    return sample;
}

// Records the path's continuation (origin, direction, throughput after the event,
// medium) as its bounce stack's held top (hold_top: it never goes through memory)
// unless Russian roulette ends it: after ROULETTE_DEPTH bounces it survives with
// probability clamp(max channel, MIN_SURVIVAL, 1) (dimension 7) and is divided by it.
// A throughput that is not finite ends the path. Twin of the end of path_radiance's loop.
fn path_continue(path: ptr<function, PathState>, origin: vec3<f32>, direction: vec3<f32>, throughput: vec3<f32>, medium: MediumStack) {
    // The continuation starts as wide as the cone is at the hit (path_closest_hit
    // keeps that width in cone_width) and keeps the spread.
    let depth = (*path).depth + 1u;
    var weight = throughput;
    if depth >= ROULETTE_DEPTH {
        let survival = clamp(max_component(weight), MIN_SURVIVAL, 1.0);
        if path_random(path, 7u) >= survival {
            return;
        }
        weight = weight / survival;
    }
    if !finite_radiance(weight) {
        return;
    }
    hold_top(path, StackEntry(origin, depth, direction, medium.depth, weight, (*path).cone_width, medium.iors));
    (*path).stack_len = 1u;
}

// Shades a miss of the path's current ray, the end of path_radiance's bounce: adds the
// background, the environment weighted against next-event estimation where that
// could have found it, and goes on to PHASE_POP.
fn path_miss(path: ptr<function, PathState>) {
    var background = frame.background;
    //#if ENVIRONMENT_MAP
    if environment_present() {
        // The environment, weighted against next-event estimation where that could
        // have found it.
        var weight = 1.0;
        if (*path).depth > 0u && (*path).brdf_pdf > 0.0 {
            weight = power_heuristic((*path).brdf_pdf,
                                     environment.header.selection * environment_pdf((*path).direction));
        }
        background = environment_radiance((*path).direction) * weight;
    }
    //#endif
    add_contribution(path, (*path).weight * background);
    (*path).phase = PHASE_POP;
}

// Shades the hit of the path's current ray, `surface` (resolve_surface), one bounce of
// path_radiance: adds its emission (MIS-weighted after a BRDF sample), picks an event
// in proportion to its weight (dimension 0) and records the continuation; for the
// base BRDF it samples the next direction (dimensions 1-3) and starts gathering direct
// light (PHASE_NEXT_LIGHT), else it goes on to PHASE_POP.
fn path_closest_hit(path: ptr<function, PathState>, trace: TraceRay, surface: Surface) {
    let ray = Ray((*path).origin, (*path).direction);
    let hit = surface.hit;
    let material = surface.material;
    // Emission, weighted against next-event estimation where that could have found it;
    // shadow_origin still holds the previous hit's, where that estimation sampled from.
    if max_component(material.emission) > 0.0 && emits_towards(hit, ray.direction, material.two_sided != 0u) {
        var weight = 1.0;
        if (*path).depth > 0u && (*path).brdf_pdf > 0.0 {
            weight = power_heuristic((*path).brdf_pdf,
                                     (1.0 - environment_selection()) * emitter_pdf((*path).shadow_origin, hit, trace.best_instance));
        }
        add_contribution(path, (*path).weight * material.emission * weight);
    }
    let entering = surface.entering;
    let ng = surface.ng;
    let n = surface.n;
    let lifted = surface.lifted;
    let medium = surface.medium;
    let wo = -ray.direction;
    let response = surface.response;
    // The events and their weights; a path whose weights are NaN also ends.
    var base = 0.0;
    if has_base_brdf(material.kind) {
        base = response.base;
    }
    let reflect_weight = luminance(response.reflect);
    let transmit_weight = luminance(response.transmit);
    let total = base + reflect_weight + transmit_weight;
    (*path).phase = PHASE_POP;
    if !(total > 0.0) {
        return;
    }
    let u_event = path_random(path, 0u) * total;
    let continues = (*path).depth < frame.max_depth;
    if u_event < base {
        let event_weight = (*path).weight * (response.base / (base / total));
        // The lighting state of the hit; `direct` holds the event's weight.
        (*path).direct = event_weight;
        (*path).albedo = material.diffuse;
        (*path).roughness = material.roughness;
        (*path).metallic = material.metallic;
        (*path).material = hit.material;
        (*path).normal = n;
        (*path).shadow_origin = offset_ray_origin(lifted, ng, frame.offset_scale);
        (*path).light = 0u;
        (*path).phase = PHASE_NEXT_LIGHT;
        (*path).brdf_pdf = NO_BRDF_PDF;
        if continues {
            let wi = sample_brdf(material, n, wo, path_random(path, 1u),
                                 vec2<f32>(path_random(path, 2u), path_random(path, 3u)));
            let pdf = pdf_brdf(material, n, wo, wi);
            let cos_i = dot(n, wi);
            if pdf > 0.0 && cos_i > 0.0 && dot(ng, wi) > 0.0 {
                let f = eval_brdf(material, n, wi, wo);
                (*path).brdf_pdf = pdf;
                path_continue(path, offset_ray_origin(hit.position, ng, frame.offset_scale),
                              wi, event_weight * f * (cos_i / pdf), medium);
            }
        }
        return;
    }
    if !continues {
        return;
    }
    var weight = response.transmit / (transmit_weight / total);
    var direction = response.transmit_direction;
    var side = -ng;
    var next_medium = medium;
    if u_event < base + reflect_weight {
        weight = response.reflect / (reflect_weight / total);
        direction = normalize(reflect_direction(ray.direction, n));
        side = ng;
    } else {
        //#if REFRACTION
        next_medium = medium_after_refraction(medium, entering, material.ior);
        //#endif
    }
    //#if MESH_ATTRIBUTES
    if any(n != ng) {
        direction = keep_on_side(direction, side);
    }
    //#endif
    (*path).brdf_pdf = NO_BRDF_PDF;
    path_continue(path, offset_ray_origin(hit.position, side, frame.offset_scale),
                  direction, (*path).weight * weight, next_medium);
}

// Starts the shadow ray towards the emitter `sample` (path_emitter_sample of the path's
// shadow origin), or moves on to the continuation when there is none.
fn path_start_emitter(path: ptr<function, PathState>, trace: ptr<function, TraceRay>, sample: EmitterSample) {
    if !sample.found {
        (*path).phase = PHASE_POP;
        return;
    }
    (*path).rays += 1u;
    // The environment's sample is visible when its ray hits nothing: any hit will do.
    start_trace(trace, (*path).shadow_origin, sample.wi, bitcast<f32>(0x7f800000u),
                sample.emitter == ENVIRONMENT_EMITTER);
    //#if ALPHA
    (*trace).blend_seed = path_blend_seed(path);
    //#endif
    (*path).phase = PHASE_EMITTER;
}

// The emitter sample is visible when the first thing its ray meets is that emitter
// (its emitting side faces the ray: the sample was drawn only there), the environment's
// when its ray meets nothing; then it adds f·L·cos θ / pdf (L times the emission
// texture at the shadow ray's hit, when the emitter has one), times the event's
// weight, weighted by the power heuristic against the BRDF sampler when the path goes
// on. `sample` is the one the ray was started towards, drawn again from the same
// numbers (the shading step's one call of path_emitter_sample). Twin of sample_emitter and
// sample_environment.
fn path_consume_emitter(path: ptr<function, PathState>, trace: TraceRay, sample: EmitterSample) {
    var visible = trace.best_prim == NO_PRIM;
    if sample.emitter != ENVIRONMENT_EMITTER {
        let emitter = emitters[sample.emitter];
        visible = trace.best_prim == emitter.prim && trace.best_instance == emitter.instance;
    }
    if sample.found && visible {
        let material = lit_material(path);
        let n = (*path).normal;
        let wo = -(*path).direction;
        let f = eval_brdf(material, n, sample.wi, wo);
        var weight = 1.0;
        if (*path).depth < frame.max_depth {
            weight = power_heuristic(sample.pdf, pdf_brdf(material, n, wo, sample.wi));
        }
        let cos_i = dot(n, sample.wi);
        var radiance = sample.radiance;
        //#if TEXTURES
        // A textured emitter's radiance at the point the shadow ray reaches (the
        // sampled point), looked up at that hit's texture coordinates.
        if sample.emitter != ENVIRONMENT_EMITTER {
            let light_hit = hit_record_keyed(trace.best_prim, trace.best_instance,
                                          Ray((*path).shadow_origin, sample.wi), trace.best_t);
            let light_material = materials[light_hit.material];
            if light_material.emission_layer != NO_IMAGE {
                // At the footprint there of the path's cone, cone_width wide at the
                // hit the shadow ray leaves.
                let light_footprint = cone_footprint((*path).cone_width + frame.cone_spread * light_hit.t,
                                                     sample.wi, light_hit.normal, light_hit.uv_density,
                                                     light_hit.uv_axis);
                radiance = shading_emission(light_material, light_hit.position, light_hit.normal, light_hit.uv,
                                            light_hit.uv1, light_footprint);
            }
        }
        //#endif
        add_contribution(path, (*path).direct * (f * radiance * (cos_i * weight / sample.pdf)));
    }
    (*path).phase = PHASE_POP;
}
