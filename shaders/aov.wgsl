// The auxiliary passes (AOVs) from the camera rays' first hits: albedo (the specular
// tint of perfect specular surfaces), the shading normal facing the ray, and the
// distance along the ray. Twin of src/cpu/aov.rs, where the conventions are set out.
// The sums over a pixel's samples live in `accumulation` after the region's sample
// sums, two vec4 per pixel: (albedo, depth) and (normal, samples counted), the count
// telling a reader of a pass still in flight how many samples each pixel has.

#import types
#import bindings
#import trace

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

// The first hit of a camera ray as the passes see it: the shading's `surface`
// (resolve_surface: its textures looked up at the footprint of the ray's cone, its
// shading normal) at distance `t`. Twin of first_hit_aov.
fn first_hit_aov(surface: Surface, t: f32) -> FirstHitAov {
    return FirstHitAov(aov_albedo(surface.material), surface.n, t);
}

// Starts region pixel `pixel`'s sums of the passes at zero (its first sample).
fn clear_pixel_aov(pixel: u32) {
    let at = aov_index(pixel);
    accumulation[at] = vec4<f32>(0.0);
    accumulation[at + 1u] = vec4<f32>(0.0);
}

// Counts a camera ray that escaped in region pixel `pixel`'s sums: the sample adds
// nothing to the passes but is one of them.
fn add_missed_aov(pixel: u32) {
    accumulation[aov_index(pixel) + 1u].w += 1.0;
}

// Adds the first hit of a camera ray, the shading's `surface` at distance `t`, to
// region pixel `pixel`'s sums: trace_pixel_aov's sum, one sample at a time, in sample
// order. A single-sided back face the camera ray passes through adds nothing: the ray
// traced again from beyond it adds the sample (first_hit_aov's loop on the CPU), so
// the caller calls this only for the surface it shades.
fn add_first_hit_aov(pixel: u32, surface: Surface, t: f32) {
    let at = aov_index(pixel);
    let first = first_hit_aov(surface, t);
    accumulation[at] += vec4<f32>(first.albedo, first.depth);
    accumulation[at + 1u] += vec4<f32>(first.normal, 1.0);
}
