// The emitters of the path integrator's next-event estimation as the GPU reads them:
// the records of the AreaLights distribution, in the CPU's order. CPU twin:
// src/accel/area_lights.rs (AreaLights); the records are written by
// src/gpu/area_lights.rs.

#import types
#import path_types

// The emitters of the AreaLights distribution (src/gpu/area_lights.rs), in the CPU's
// order; one EMITTER_NONE record when the scene has none.
@group(0) @binding(19) var<storage, read> emitters: array<Emitter>;

// How many emitters the scene has (the padding record of none is EMITTER_NONE).
fn emitter_count() -> u32 {
    if emitters[0].kind == EMITTER_NONE {
        return 0u;
    }
    return arrayLength(&emitters);
}

// The emitter chosen by u ∈ [0, 1): the first whose cumulative probability exceeds u,
// at most the last (partition_point(c <= u·total)); binary search, at most 32 steps.
// Twin of AreaLights::choose.
fn area_lights_choose(u: f32, count: u32) -> u32 {
    var low = 0u;
    var high = count;
    for (var step = 0u; step < 32u && low < high; step += 1u) {
        let middle = (low + high) / 2u;
        if emitters[middle].cdf <= u {
            low = middle + 1u;
        } else {
            high = middle;
        }
    }
    return min(low, count - 1u);
}

// Whether emitter record `index` comes before the surface (instance, prim) in the
// records' order: ascending instance (NO_INSTANCE, the scene's own, last), then prim.
fn emitter_before(index: u32, prim: u32, instance: u32) -> bool {
    let e = emitters[index];
    return e.instance < instance || (e.instance == instance && e.prim < prim);
}

// The first emitter record of primitive `prim` in instance `instance` (NO_INSTANCE for
// the scene's own), or NO_PRIM when it is no sampled emitter; binary search over the
// records' ascending (instance, prim). Twin of AreaLights::first_piece.
fn area_lights_first_piece(prim: u32, instance: u32) -> u32 {
    let count = emitter_count();
    var low = 0u;
    var high = count;
    for (var step = 0u; step < 32u && low < high; step += 1u) {
        let middle = (low + high) / 2u;
        if emitter_before(middle, prim, instance) {
            low = middle + 1u;
        } else {
            high = middle;
        }
    }
    if low < count && emitters[low].prim == prim && emitters[low].instance == instance {
        return low;
    }
    return NO_PRIM;
}
