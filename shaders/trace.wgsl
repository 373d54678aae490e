// The Whitted integrator's shading, twin of src/cpu/trace.rs (shade_hit, direct_light
// and trace_radiance's sums, in its order): one ray's hit or miss at a time, in the
// steps of the wavefront (wavefront.wgsl), its branches pushed on the slot's bounce
// stack (slot.wgsl).

#import types
#import bindings
#import records
#import medium
//#if ENVIRONMENT_MAP
#import environment
//#endif
#import intersect
#import texture
#import bxdf
#import slot

// Squared point-light distances below the smallest normal f32 (2^-126) contribute
// nothing: I / r² would be infinite or NaN. Twin of MIN_LIGHT_DISTANCE_SQUARED.
const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1.17549435e-38;
// The least cosine to the geometric surface a bent secondary ray keeps. Twin of
// MIN_SECONDARY_COSINE (src/cpu/trace.rs).
const MIN_SECONDARY_COSINE: f32 = 1e-3;
// The largest height above the geometric surface valid_reflection_normal asks of a
// mirror reflection. Twin of MIN_REFLECTION_HEIGHT (src/cpu/trace.rs).
const MIN_REFLECTION_HEIGHT: f32 = 0.01;

// Whether every component is finite, read from the exponent bits so that no
// fast-math assumption of the shader compiler can fold the test away. The guard on
// every contribution; twin of finite_radiance.
fn finite_radiance(c: vec3<f32>) -> bool {
    let exponent = bitcast<vec3<u32>>(c) & vec3<u32>(0x7f800000u);
    return all(exponent != vec3<u32>(0x7f800000u));
}

// Adds `weight × radiance` to the sample's radiance if it is finite.
fn add_contribution(path: ptr<function, PathState>, contribution: vec3<f32>) {
    if finite_radiance(contribution) {
        (*path).radiance += contribution;
    }
}

// The radiance a ray escaping along the unit `direction` sees: the map's texel times
// its scale, or the constant background. Twin of background_radiance
// (src/cpu/trace.rs).
fn background_radiance(direction: vec3<f32>) -> vec3<f32> {
    //#if ENVIRONMENT_MAP
    if environment_present() {
        return environment_radiance(direction);
    }
    //#endif
    return frame.background;
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
// The fraction of a spot light's intensity towards a point in direction -wi: 1 inside
// the inner cone, 0 outside the outer one, t² between them with t = (cos θ -
// cos_outer) / max(cos_inner - cos_outer, 0.001) (KHR_lights_punctual's reference
// implementation). CPU twin: spot_attenuation.
fn spot_attenuation(direction: vec3<f32>, wi: vec3<f32>, cos_inner: f32, cos_outer: f32) -> f32 {
    let scale = 1.0 / max(cos_inner - cos_outer, 0.001);
    let t = clamp((dot(direction, -wi) - cos_outer) * scale, 0.0, 1.0);
    return t * t;
}

fn sample_light(light: Light, origin: vec3<f32>, n: vec3<f32>) -> LightSample {
    var sample = LightSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, false);
    if light.kind == LIGHT_POINT || light.kind == LIGHT_SPOT {
        let to_light = light.position_or_direction - origin;
        let distance_squared = dot(to_light, to_light);
        if !(distance_squared >= MIN_LIGHT_DISTANCE_SQUARED) {
            return sample;
        }
        sample.distance = sqrt(distance_squared);
        sample.wi = to_light / sample.distance;
        // Inverse-square law: E = I / r² on a surface facing the light.
        sample.irradiance = light.power / distance_squared;
        if light.kind == LIGHT_SPOT {
            let attenuation = spot_attenuation(light.spot_direction, sample.wi, light.cos_inner, light.cos_outer);
            // Outside the outer cone: no light and no shadow ray.
            if !(attenuation > 0.0) {
                return sample;
            }
            sample.irradiance *= attenuation;
        }
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
// so no facet edge shows; Veach's thesis, 1997, §5.3, on shading normals), then turned
// towards `ng` until its mirror reflection leaves the surface (valid_reflection_normal).
// CPU twin: shading_frame_normal.
fn shading_frame_normal(direction: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>) -> vec3<f32> {
    if all(ns == ng) {
        return ng;
    }
    let wo = -direction;
    let cosine = dot(wo, ns);
    var n = ns;
    if cosine < MIN_SECONDARY_COSINE {
        n = normalize(ns + wo * (MIN_SECONDARY_COSINE - cosine));
    }
    return valid_reflection_normal(wo, ng, n);
}

// `n` turned towards `ng` (the side `wo` arrives from) by the least angle for which the
// mirror reflection of `wo` about it rises to a height h = min(0.9·wo·ng,
// MIN_REFLECTION_HEIGHT) above the surface: in the plane of ng and n, with x the unit
// part of n across ng, n' = sin θ·x + cos θ·ng reflects wo to ρ·cos(2θ - α) (ρ = |(a, b)|,
// α = atan2(a, b), a = wo·x, b = wo·ng), so θ = (α + acos(h/ρ))/2, at most n's own angle.
// Blender Cycles' valid specular reflection (ensure_valid_specular_reflection,
// intern/cycles/kernel/closure/bsdf_util.h), solved directly. CPU twin:
// valid_reflection_normal.
fn valid_reflection_normal(wo: vec3<f32>, ng: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let b = dot(wo, ng);
    let height = min(0.9 * b, MIN_REFLECTION_HEIGHT);
    let reflected = 2.0 * dot(n, wo) * n - wo;
    if dot(reflected, ng) >= height {
        return n;
    }
    let across = n - dot(n, ng) * ng;
    let length_across = length(across);
    if !(length_across > 0.0) {
        return ng;
    }
    let x = across / length_across;
    let a = dot(wo, x);
    let rho = sqrt(a * a + b * b);
    let theta_n = atan2(length_across, dot(n, ng));
    let theta = clamp(0.5 * (atan2(a, b) + acos(clamp(height / rho, -1.0, 1.0))), 0.0, theta_n);
    return sin(theta) * x + cos(theta) * ng;
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

//#if ALPHA
// The alpha of a blended `material` at `hit` (shading_alpha), clamped to [0, 1]: the
// fraction of light the surface stops. CPU twin: blend_alpha.
fn blend_alpha(material: Material, hit: Hit) -> f32 {
    return clamp(shading_alpha(material, hit.position, hit.normal, hit.uv, hit.uv1, hit.color.a), 0.0, 1.0);
}
//#endif

// What both integrators shade a closest hit with, resolved once per hit so that the
// hit record, the texture lookups, the normal map and the Fresnel weights are one
// call site each in the shading kernel (lavapipe inlines every call, so each call
// site is compiled again): the hit, its material with the textures applied, the
// cone's width there, the side the ray arrives on, the shading normal, the lifted
// point shadow rays start from, the medium and the surface's response.
struct Surface {
    hit: Hit,
    material: Material,
    cone_width: f32,
    entering: bool,
    ng: vec3<f32>,
    n: vec3<f32>,
    lifted: vec3<f32>,
    medium: MediumStack,
    outside_ior: f32,
    response: SurfaceResponse,
}

// The surface of `hit` on `ray`, reached by a cone `cone_width` wide there, inside
// `medium`. The shared part of shade_hit and of path_radiance's bounce (src/cpu).
fn resolve_surface(hit: Hit, ray: Ray, cone_width: f32, medium: MediumStack) -> Surface {
    let footprint = cone_footprint(cone_width, ray.direction, hit.normal, hit.uv_density, hit.uv_axis);
    let texels = material_texels(materials[hit.material], hit.position, hit.normal, hit.uv, hit.uv1, footprint);
    let material = shading_material(materials[hit.material], hit.color.rgb, texels);
    let entering = dot(ray.direction, hit.normal) < 0.0;
    // Shading happens on the side the ray came from.
    let ng = select(-hit.normal, hit.normal, entering);
    //#if REFRACTION
    let outside_ior = medium_outside_ior(medium, entering);
    //#else
    // Without dielectrics every ray travels in air.
    let outside_ior = 1.0;
    //#endif
    //#if MESH_ATTRIBUTES
    let mapped = mapped_normal(materials[hit.material], hit.normal, hit.shading_normal, hit.tangent, texels[UV_SLOT_NORMAL]);
    let ns = select(-mapped, mapped, entering);
    let n = shading_frame_normal(ray.direction, ng, ns);
    let lifted = shadow_terminator_point(hit, ng);
    //#else
    let n = ng;
    let lifted = hit.position;
    //#endif
    let response = surface_response(material, ray.direction, n, entering, outside_ior);
    return Surface(hit, material, cone_width, entering, ng, n, lifted, medium, outside_ior, response);
}

// Shades a miss of the path's current ray: adds the background
// (background_radiance: the environment map or the constant).
fn consume_miss(path: ptr<function, PathState>) {
    add_contribution(path, (*path).weight * background_radiance((*path).direction));
    (*path).phase = PHASE_POP;
}

// Shades the hit of the path's current ray, as shade_hit and trace_radiance do on the
// CPU: a hit pushes the refracted, then the
// reflected branch, and either adds its emission at once or, for a surface with a base
// BRDF, starts gathering its lights (PHASE_NEXT_LIGHT), the ambient term first.
fn consume_closest_hit(slot: u32, path: ptr<function, PathState>, surface: Surface) {
    let ray = Ray((*path).origin, (*path).direction);
    let hit = surface.hit;
    let cone_width = surface.cone_width;
    let material = surface.material;
    let ng = surface.ng;
    let n = surface.n;
    let medium = surface.medium;
    let entering = surface.entering;
    //#if ALPHA
    // A blended surface stops the fraction alpha of the light: its shading and
    // branches are weighted by alpha, and the ray goes on through it, unbent, with
    // weight 1 - alpha (one bounce deeper, pushed first so it is traced last).
    if materials[hit.material].alpha_blend != 0u {
        let alpha = blend_alpha(materials[hit.material], hit);
        if alpha < 1.0 && (*path).depth < frame.max_depth {
            let beyond = select(-hit.normal, hit.normal, dot(ray.direction, hit.normal) > 0.0);
            push_branch(slot, path, StackEntry(
                offset_ray_origin(hit.position, beyond, frame.offset_scale), (*path).depth + 1u,
                ray.direction, medium.depth, (*path).weight * (1.0 - alpha), cone_width, medium.iors));
        }
        (*path).weight *= alpha;
    }
    //#endif
    var response = surface.response;
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
            (*path).weight * response.transmit, cone_width, inside.iors));
        //#endif
        push_branch(slot, path, StackEntry(
            offset_ray_origin(hit.position, ng, frame.offset_scale), (*path).depth + 1u,
            reflected, medium.depth,
            (*path).weight * response.reflect, cone_width, medium.iors));
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
        (*path).shadow_origin = offset_ray_origin(surface.lifted, ng, frame.offset_scale);
        (*path).light = 0u;
        (*path).phase = PHASE_NEXT_LIGHT;
    } else {
        add_contribution(path, (*path).weight * material.emission);
        (*path).phase = PHASE_POP;
    }
}

// Adds the current light's f(wi, wo)·E·cos θi if its shadow ray was unblocked, and
// moves on to the next light: Whitted's into the hit's direct light, times the
// transmittance of the blended surfaces the shadow ray passed; the path integrator's
// into the sample's radiance times the event's weight (held in `direct`). One
// function for both integrators, so that the BRDF is evaluated at one call site.
fn consume_shadow_ray(path: ptr<function, PathState>, trace: TraceRay) {
    var visible = trace.best_prim == NO_PRIM && trace.transmittance > 0.0;
    var transmittance = trace.transmittance;
    //#if PATH
    let path_integrator = path_mode();
    if path_integrator {
        visible = trace.best_prim == NO_PRIM;
        transmittance = 1.0;
    }
    //#endif
    if visible {
        let sample = sample_light(lights[(*path).light], (*path).shadow_origin, (*path).normal);
        let material = lit_material(path);
        let lit = eval_brdf(material, (*path).normal, sample.wi, -(*path).direction)
            * sample.irradiance * (sample.cos_i * transmittance);
        //#if PATH
        if path_integrator {
            add_contribution(path, (*path).direct * lit);
        } else {
            (*path).direct += lit;
        }
        //#else
        (*path).direct += lit;
        //#endif
    }
    (*path).light += 1u;
    (*path).phase = PHASE_NEXT_LIGHT;
}

// After the last light: adds the hit's emission plus its direct light times the base
// weight, and moves on to the bounce stack.
fn finish_lights(path: ptr<function, PathState>) {
    add_contribution(path, (*path).weight * ((*path).emission + (*path).direct * (*path).base));
    (*path).phase = PHASE_POP;
}
