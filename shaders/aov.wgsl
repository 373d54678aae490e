// The auxiliary passes (AOVs) from the camera rays' first hits: albedo (the specular
// tint of perfect specular surfaces), the shading normal facing the ray, and the
// distance along the ray. Twin of src/cpu/aov.rs, where the conventions are set out.
// The sums over a pixel's samples live in `accumulation` after the region's sample
// sums, two vec4 per pixel: (albedo, depth) and (normal, samples counted), the count
// telling a reader of a pass still in flight how many samples each pixel has.

#import types
#import bindings
#import records
#import intersect
#import texture
//#if MESH_ATTRIBUTES
#import trace
//#endif

// Whether this trace records the auxiliary passes.
fn aov_mode() -> bool {
    return (frame.flags & FLAG_AOV) != 0u;
}

// Where region pixel `pixel`'s sums of the passes start in `accumulation`.
fn aov_index(pixel: u32) -> u32 {
    return frame.region_width * frame.region_height + 2u * pixel;
}

// The albedo pass's value for a material (textures applied): a mirror's reflectance,
// a dielectric's transmittance, else the diffuse albedo; clamped to [0, 1]. Twin of
// aov_albedo.
fn aov_albedo(material: Material) -> vec3<f32> {
    var albedo = material.diffuse;
    if material.kind == MATERIAL_MIRROR {
        albedo = material.reflectance;
    } else if material.kind == MATERIAL_DIELECTRIC {
        albedo = material.transmittance;
    }
    return clamp(albedo, vec3<f32>(0.0), vec3<f32>(1.0));
}

// What the first hit of a camera ray contributes to the passes.
struct FirstHitAov {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    depth: f32,
}

// The first hit `trace` found for the camera ray `ray` as the passes see it (the ray
// hit something), its textures looked up at the footprint of the ray's cone,
// `cone_width` wide at its origin. Twin of first_hit_aov.
fn first_hit_aov(ray: Ray, trace: TraceRay, cone_width: f32) -> FirstHitAov {
    let hit = hit_record_keyed(trace.best_prim, trace.best_instance, ray, trace.best_t);
    let footprint = cone_footprint(cone_width + frame.cone_spread * hit.t, ray.direction, hit.normal, hit.uv_density, hit.uv_axis);
    let texels = material_texels(materials[hit.material], hit.position, hit.normal, hit.uv, hit.uv1, footprint);
    let material = shading_material(materials[hit.material], hit.color.rgb, texels);
    let entering = dot(ray.direction, hit.normal) < 0.0;
    let ng = select(-hit.normal, hit.normal, entering);
    //#if MESH_ATTRIBUTES
    let mapped = mapped_normal(materials[hit.material], hit.normal, hit.shading_normal, hit.tangent, texels[UV_SLOT_NORMAL]);
    let ns = select(-mapped, mapped, entering);
    let n = shading_frame_normal(ray.direction, ng, ns);
    //#else
    let n = ng;
    //#endif
    return FirstHitAov(aov_albedo(material), n, trace.best_t);
}

// Starts region pixel `pixel`'s sums of the passes at zero (its first sample).
fn clear_pixel_aov(pixel: u32) {
    let at = aov_index(pixel);
    accumulation[at] = vec4<f32>(0.0);
    accumulation[at + 1u] = vec4<f32>(0.0);
}

// Adds the first hit of the camera ray from `origin` along `direction`, found by
// `trace`, to region pixel `pixel`'s sums (an escaped ray adds nothing):
// trace_pixel_aov's sum, one sample at a time, in sample order. `pass_throughs` back
// faces have been passed already; the ray's cone is `cone_width` wide at `origin`.
fn add_first_hit_aov(pixel: u32, origin: vec3<f32>, direction: vec3<f32>, trace: TraceRay, pass_throughs: u32, cone_width: f32) {
    let at = aov_index(pixel);
    if trace.best_prim == NO_PRIM {
        accumulation[at + 1u].w += 1.0;
        return;
    }
    // A single-sided back face the camera ray passes through: the ray traced again
    // from beyond it adds the sample (first_hit_aov's loop on the CPU).
    let passed = hit_record_keyed(trace.best_prim, trace.best_instance, Ray(origin, direction), trace.best_t);
    if pass_throughs < MAX_PASS_THROUGHS
        && culls_back_face(materials[passed.material].cull_back_faces != 0u, 0u, direction, passed.normal) {
        return;
    }
    let first = first_hit_aov(Ray(origin, direction), trace, cone_width);
    accumulation[at] += vec4<f32>(first.albedo, first.depth);
    accumulation[at + 1u] += vec4<f32>(first.normal, 1.0);
}
