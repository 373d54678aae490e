// Records and constants of the path-tracing integrator (shaders/path.wgsl). Each
// struct is the twin of the `#[repr(C)]` struct of the same name (with a `Gpu` prefix)
// in src/gpu/area_lights.rs; tests/integration/layout.rs checks sizes and offsets with naga's
// layouter.

// FrameUniforms.flags: trace with the path integrator (`integrator = "path"`) instead
// of Whitted's; only modules with the PATH feature have its code.
const FLAG_PATH: u32 = 4u;

// PathState.phase of the path integrator: the shadow ray towards a point sampled on an
// emitter is being traced (next-event estimation of the area lights).
const PHASE_EMITTER: u32 = 8u;

// PathState.phase of the path integrator: the lights are done and the emitter sample
// of next-event estimation is to be drawn and its shadow ray started (in the shading
// step's one call of path_emitter_sample, which consuming that ray shares).
const PHASE_START_EMITTER: u32 = 11u;

// Emitter.kind.
// A sphere, sampled by the cone of directions it subtends.
const EMITTER_SPHERE: u32 = 0u;
// A triangle (of a triangle, a mesh or a polygon), sampled uniformly by area.
const EMITTER_TRIANGLE: u32 = 1u;
// The padding record of a scene without emitters.
const EMITTER_NONE: u32 = 2u;
// A triangle of a two_sided material: it emits from its back too.
const EMITTER_TWO_SIDED_TRIANGLE: u32 = 3u;

// One emitter of the AreaLights distribution (twin of src/cpu/path.rs): its shape,
// the primitive a ray hits on it, its radiance, and its share of the selection by
// power. Records are in the CPU's order, which is ascending PrimRef order (spheres,
// polygons, triangles, each by index; the triangles of a polygon next to each other),
// so the first record of a primitive is found by binary search.
struct Emitter {
    // Sphere: its centre; triangle: its first vertex.
    v0: vec3<f32>,
    kind: u32,
    // Sphere: (radius, 0, 0); triangle: its second vertex.
    v1: vec3<f32>,
    // The PrimRef a ray hits on it.
    prim: u32,
    // Triangle: its third vertex.
    v2: vec3<f32>,
    // Cumulative selection probability up to and including this emitter (CPU:
    // AreaLights::cdf / total); the last is 1.
    cdf: f32,
    // Triangle: the unit normal of its emitting side.
    normal: vec3<f32>,
    // Probability that next-event estimation picks it.
    selection: f32,
    radiance: vec3<f32>,
    // Triangle: selection / area, its density per unit area.
    area_density: f32,
    // The instance a ray hits it in, or NO_INSTANCE for the scene's own primitives.
    instance: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// The header of the environment buffer (binding 20, shaders/environment.wgsl): the
// map's size, rotation, scale and sampling constants, followed by its f32 data (twin
// of GpuEnvironmentHeader in src/gpu/environment.rs, which documents the data's
// order). A width of 0 means the scene has no map.
struct EnvironmentHeader {
    scale: vec3<f32>,
    width: u32,
    // (cos α, sin α) of the rotation α about +y.
    rotation: vec2<f32>,
    height: u32,
    // The probability that next-event estimation picks the environment.
    selection: f32,
    // ∫ f over the unit square (the marginal distribution's integral); 0 when black.
    integral: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}
