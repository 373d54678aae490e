// Alpha coverage (glTF 2.0 §3.9.4, `alphaMode` MASK and BLEND): what fraction of
// light a candidate hit stops, and whether it stops a trace. Both traversals use it:
// the software walk's primitive tests (traverse.wgsl, `consider`) and the hardware
// ray queries' candidate loop (ray_query.wgsl). The whole module is compiled only
// with ALPHA. CPU twins: src/cpu/traverse.rs.

//#if ALPHA
#import types
#import records
#import intersect
#import instance
#import texture
#import sample

// The fraction of light the hit of the surface (`prim`, `instance`) at parameter `t`
// along the world-space `ray` stops (its coverage): 1 for an opaque material; for a
// mask (glTF 2.0 §3.9.4: opaque where alpha >= alphaCutoff) 1 where its alpha
// (shading_alpha, at the hit record's point and texture coordinates) reaches the
// cutoff and 0 where it is below, so the point does not exist for any ray; for a
// blended material its alpha. Twin of hit_coverage.
fn hit_coverage(prim: u32, instance: u32, ray: Ray, t: f32) -> f32 {
    let hit = hit_record_keyed(prim, instance, ray, t);
    let material = materials[hit.material];
    if !(material.alpha_cutoff > 0.0) && material.alpha_blend == 0u {
        return 1.0;
    }
    let alpha = shading_alpha(material, hit.position, hit.normal, hit.uv, hit.uv1, hit.color.a);
    if material.alpha_blend != 0u {
        return alpha;
    }
    return select(1.0, 0.0, alpha < material.alpha_cutoff);
}

// The uniform number in [0, 1) that decides whether a stochastic trace of seed `seed`
// passes the blended surface (`prim`, `instance`), named as the CPU names it: an
// instanced triangle by its index in its mesh and the instance's index. Twin of
// blend_number.
fn blend_number(seed: u32, prim: u32, instance: u32) -> f32 {
    var key_prim = prim;
    var key_instance = NO_INSTANCE;
    //#if INSTANCES
    if instance != NO_INSTANCE {
        let placed = load_instance(instance);
        key_prim = (PRIM_TRIANGLE << PRIM_KIND_SHIFT) | (prim_index(prim) - placed.first_triangle);
        key_instance = placed.index;
    }
    //#endif
    return unit_from_hash(pcg_hash(seed ^ pcg_hash(key_prim ^ pcg_hash(key_instance))));
}

// The stochastic transparency seed of the rays of sample `sample` of image pixel
// `pixel` at the bounce whose dimension `dimension` is given: random_number's hash,
// unreduced (NO_BLEND_SEED made 0). Twin of blend_seed.
fn blend_seed(pixel: u32, sample: u32, dimension: u32) -> u32 {
    let seed = pcg_hash(pcg_hash(pcg_hash(pixel) ^ sample) ^ dimension);
    return select(seed, 0u, seed == NO_BLEND_SEED);
}

// Whether a candidate hit of coverage `coverage` (hit_coverage) stops `trace`: never at
// coverage 0 (or NaN), always at 1; between, a trace with a blend seed when its draw
// (blend_number) falls below the coverage, an any-hit trace without one never (its
// transmittance is multiplied by 1 - coverage), a closest-hit one always. Twin of
// stops_ray.
fn stops_ray(trace: ptr<function, TraceRay>, prim: u32, instance: u32, coverage: f32) -> bool {
    if !(coverage > 0.0) {
        return false;
    }
    if coverage >= 1.0 {
        return true;
    }
    if (*trace).blend_seed != NO_BLEND_SEED {
        return blend_number((*trace).blend_seed, prim, instance) < coverage;
    }
    if (*trace).any_hit == 0u {
        return true;
    }
    (*trace).transmittance *= 1.0 - coverage;
    return false;
}
//#endif
