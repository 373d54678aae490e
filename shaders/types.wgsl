// Records shared by the tracing and display passes. Each struct is the twin of the
// `#[repr(C)]` struct of the same name (with a `Gpu` prefix) in src/gpu/layout.rs;
// tests/integration/layout.rs checks sizes and offsets with naga's layouter.

struct FrameUniforms {
    eye: vec3<f32>,
    tan_half_fov_y: f32,
    forward: vec3<f32>,
    aspect: f32,
    right: vec3<f32>,
    width: u32,
    up: vec3<f32>,
    height: u32,
    background: vec3<f32>,
    samples_per_pixel: u32,
    ambient: vec3<f32>,
    max_depth: u32,
    camera_medium_iors: vec4<f32>,
    camera_medium_depth: u32,
    plane_count: u32,
    node_count: u32,
    light_count: u32,
    region_x: u32,
    region_y: u32,
    region_width: u32,
    region_height: u32,
    target_x: u32,
    target_y: u32,
    first_sample: u32,
    end_sample: u32,
    slot_count: u32,
    stack_size: u32,
    iteration_budget: u32,
    flags: u32,
    offset_scale: f32,
    min_ray_weight: f32,
    static_pixels: u32,
    // The camera's thin lens (camera_ray): its radius, 0 for a pinhole, and the
    // distance of the plane in focus along `forward`.
    lens_radius: f32,
    focus_distance: f32,
    // A camera ray's ray cone (Akenine-Möller et al., JCGT 10(1), 2021): its width at
    // the origin and its width growth per unit distance, 2·tan(α/2) (CPU twin:
    // CameraFrame::pixel_cone); both 0 without texture filtering.
    cone_width: f32,
    cone_spread: f32,
    _pad: u32,
}

// FrameUniforms.flags: also store each finished pixel's sample sum and luminance m2 in
// `accumulation`.
const FLAG_STORE_SUM: u32 = 1u;
// FrameUniforms.flags, for tests: traversals leave their loop early without reaching
// an exit, as a driver that cuts loops makes them do.
const FLAG_SIMULATE_LOOP_CUT: u32 = 2u;
// FrameUniforms.flags: also sum each pixel's auxiliary passes (aov.wgsl) in
// `accumulation`, after the sample sums (bit 4 is path_types.wgsl's FLAG_PATH).
const FLAG_AOV: u32 = 8u;

// Uniforms of one step of the denoiser (denoise.wgsl): the image size, the tap
// spacing of an à-trous pass, and the edge-stopping settings (DenoiseSettings).
struct DenoiseUniforms {
    width: u32,
    height: u32,
    step: u32,
    _pad: u32,
    sigma_normal: f32,
    sigma_depth: f32,
    sigma_luminance: f32,
    sigma_albedo: f32,
}
// FrameUniforms.flags: the camera is orthographic; tan_half_fov_y holds half the view's
// height in scene units (camera_ray_origin).
const FLAG_ORTHOGRAPHIC: u32 = 16u;
// FrameUniforms.flags: textures are filtered; the host fills cone_width and
// cone_spread (the shaders read only those).
const FLAG_TEXTURE_FILTERING: u32 = 32u;
// FrameUniforms.flags: texture lookups take up to MAX_TEXTURE_PROBES probes along the
// footprint's long axis (texture_filtering = "anisotropic"), else one.
const FLAG_ANISOTROPIC_TEXTURES: u32 = 64u;

// A sphere through its anchor (its point nearest the origin) with the outward normal
// there: see src/scene/sphere.rs.
struct Sphere {
    anchor: vec3<f32>,
    radius: f32,
    normal: vec3<f32>,
    material: u32,
}

// The plane normal · p = offset.
struct Plane {
    normal: vec3<f32>,
    offset: f32,
    material: u32,
    // Not vec3<u32>, which is 16-byte aligned and would grow the struct to 48 bytes, nor
    // array<u32, 3>, whose 4-byte stride a uniform array of planes may not hold.
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct Polygon {
    normal: vec3<f32>,
    offset: f32,
    first_vertex: u32,
    vertex_count: u32,
    dropped_axis: u32,
    material: u32,
}

struct Triangle {
    v0: vec3<f32>,
    material: u32,
    v1: vec3<f32>,
    // Index into triangle_attributes, or NO_ATTRIBUTES.
    attributes: u32,
    v2: vec3<f32>,
    _pad2: u32,
}

const NO_ATTRIBUTES: u32 = 0xffffffffu;

// Vertex normals, texture coordinates (two sets) and colours of a mesh triangle,
// corner by corner.
struct TriangleAttributes {
    n0: vec3<f32>,
    has_normals: u32,
    n1: vec3<f32>,
    has_uvs: u32,
    n2: vec3<f32>,
    has_colors: u32,
    uv01: vec4<f32>,
    uv2: vec2<f32>,
    has_uvs1: u32,
    has_tangents: u32,
    uv1_01: vec4<f32>,
    uv1_2: vec2<f32>,
    _pad1: vec2<u32>,
    // Linear RGBA vertex colours.
    c0: vec4<f32>,
    c1: vec4<f32>,
    c2: vec4<f32>,
    // Unit tangents, the bitangent's handedness in w (normal maps).
    t0: vec4<f32>,
    t1: vec4<f32>,
    t2: vec4<f32>,
}

const MATERIAL_LAMBERT: u32 = 0u;
const MATERIAL_BLINN_PHONG: u32 = 1u;
const MATERIAL_MIRROR: u32 = 2u;
const MATERIAL_DIELECTRIC: u32 = 3u;
const MATERIAL_EMISSIVE: u32 = 4u;
const MATERIAL_COOK_TORRANCE: u32 = 5u;
const MATERIAL_OREN_NAYAR: u32 = 6u;
const MATERIAL_TABULATED: u32 = 7u;
const MATERIAL_PBR: u32 = 8u;
const DISTRIBUTION_GGX: u32 = 0u;
const DISTRIBUTION_BECKMANN: u32 = 1u;
const FRESNEL_EXACT: u32 = 0u;
const FRESNEL_SCHLICK: u32 = 1u;
const MAPPING_PLANAR: u32 = 0u;
const MAPPING_SPHERICAL: u32 = 1u;
const MAPPING_UV: u32 = 2u;
const WRAP_REPEAT: u32 = 0u;
const WRAP_MIRRORED_REPEAT: u32 = 1u;
const WRAP_CLAMP_TO_EDGE: u32 = 2u;
const NO_IMAGE: u32 = 0xffffffffu;

struct Material {
    diffuse: vec3<f32>,
    shininess: f32,
    specular: vec3<f32>,
    ior: f32,
    reflectance: vec3<f32>,
    kind: u32,
    transmittance: vec3<f32>,
    coat_ior: f32,
    emission: vec3<f32>,
    roughness: f32,
    eta: vec3<f32>,
    metallic: f32,
    k: vec3<f32>,
    sigma: f32,
    distribution: u32,
    fresnel: u32,
    conductor: u32,
    texture_mapping: u32,
    texture_layer: u32,
    texture_width: u32,
    texture_height: u32,
    texture_scale: f32,
    brdf_map_layer: u32,
    brdf_map_size: u32,
    // WRAP_* modes of the albedo texture; scalars, not a vec2<u32>, whose 8-byte
    // alignment would move them.
    texture_wrap_u: u32,
    texture_wrap_v: u32,
    // The metallic/roughness texture (green: roughness, blue: metallic), or NO_IMAGE;
    // its wrap modes as u in bits 0-7 and v in bits 8-15.
    metallic_roughness_layer: u32,
    metallic_roughness_width: u32,
    metallic_roughness_height: u32,
    metallic_roughness_wrap: u32,
    // 1 when flat shapes of this material emit from both sides (path integrator).
    two_sided: u32,
    // The emission texture (a colour multiplying `emission`), or NO_IMAGE; its wrap
    // modes as u in bits 0-7 and v in bits 8-15.
    emission_layer: u32,
    emission_width: u32,
    emission_height: u32,
    emission_wrap: u32,
    // The texture coordinate set (0 or 1) of each texture: bit UV_SLOT_* set for 1.
    uv_sets: u32,
    // 1 when camera rays pass through the back faces of flat shapes of this material.
    cull_back_faces: u32,
    // The tangent-space normal map (linear data), or NO_IMAGE.
    normal_layer: u32,
    // The affine maps of the textures' coordinates: texture s (UV_SLOT_*) maps uv to
    // (dot(uv_rows[2s].xyz, (uv, 1)), dot(uv_rows[2s+1].xyz, (uv, 1))).
    uv_rows: array<vec4<f32>, 8>,
    normal_width: u32,
    normal_height: u32,
    // Wrap modes as u in bits 0-7 and v in bits 8-15.
    normal_wrap: u32,
    normal_scale: f32,
    // The alpha mask's cutoff (points whose alpha is below it do not exist for any
    // ray), 0 for an opaque material; the alpha factor multiplying the albedo
    // texture's texel alpha.
    alpha_cutoff: f32,
    alpha: f32,
    // 1 for a blended material, whose alpha is the fraction of light it stops.
    alpha_blend: u32,
    _pad1: u32,
}

const UV_SLOT_ALBEDO: u32 = 0u;
const UV_SLOT_METALLIC_ROUGHNESS: u32 = 1u;
const UV_SLOT_EMISSION: u32 = 2u;
const UV_SLOT_NORMAL: u32 = 3u;

const LIGHT_POINT: u32 = 0u;
const LIGHT_DIRECTIONAL: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;

struct Light {
    position_or_direction: vec3<f32>,
    kind: u32,
    power: vec3<f32>,
    // A spot light's cone: the cosines of its inner and outer half-angles.
    cos_inner: f32,
    // A spot light's unit axis (the direction it shines along).
    spot_direction: vec3<f32>,
    cos_outer: f32,
}

// One node of the compressed 4-wide BVH (twin of `accel::WideNode`, which explains
// the quantization): byte i of low[a] and high[a] holds child i's quantized bounds on
// axis a, decoded as origin[a] + q * 2^e with byte a of `exponents` the biased e;
// children holds the children's words: EMPTY_CHILD, an inner node's index (count 0),
// or a leaf's first primitive in bvh_prims with its count above CHILD_COUNT_SHIFT.
struct WideNode {
    origin: vec3<f32>,
    exponents: u32,
    low: vec3<u32>,
    spare_low: u32,
    high: vec3<u32>,
    spare_high: u32,
    children: vec4<u32>,
}

// A primitive reference (twin of `accel::PrimRef`): kind << 29 | index in its list;
// with the instance, the tie-break key (the smaller (instance, prim) wins at equal
// distance; the scene's own primitives have instance NO_INSTANCE).
const PRIM_KIND_SHIFT: u32 = 29u;
const PRIM_INDEX_MASK: u32 = 0x1fffffffu;
const PRIM_SPHERE: u32 = 0u;
const PRIM_PLANE: u32 = 1u;
const PRIM_POLYGON: u32 = 2u;
const PRIM_TRIANGLE: u32 = 3u;
// A placement of an instanced mesh; its index is the node index of its record in
// bvh_nodes (see load_instance in shaders/instance.wgsl).
const PRIM_INSTANCE: u32 = 4u;
const NO_PRIM: u32 = 0xffffffffu;
const NO_INSTANCE: u32 = 0xffffffffu;
const NO_NODE: u32 = 0xffffffffu;

// TraceRay.status
const TRACE_IDLE: u32 = 0u;
const TRACE_PENDING: u32 = 1u;
const TRACE_RUNNING: u32 = 2u;
const TRACE_DONE: u32 = 3u;

// One traversal of one ray through the scene, resumable: the ray, its distance
// limit, the best hit so far and where the traversal stands (the current node, the
// next primitive of the current leaf, and the depth of the slot's traversal stack;
// inside an instanced mesh, the instance, the stack depth it began at and the scene
// leaf to go back to).
struct TraceRay {
    origin: vec3<f32>,
    t_max: f32,
    direction: vec3<f32>,
    status: u32,
    best_t: f32,
    best_prim: u32,
    stack_len: u32,
    node: u32,
    cursor: u32,
    leaf_end: u32,
    any_hit: u32,
    best_instance: u32,
    instance: u32,
    stack_base: u32,
    world_cursor: u32,
    world_leaf_end: u32,
    // Stochastic transparency's seed (the path integrator's rays), or NO_BLEND_SEED:
    // blended surfaces are then hit by a closest-hit trace and multiply an any-hit
    // trace's transmittance by 1 - alpha.
    blend_seed: u32,
    transmittance: f32,
    _pad0: u32,
    _pad1: u32,
}

// TraceRay.blend_seed of a trace without stochastic transparency.
const NO_BLEND_SEED: u32 = 0xffffffffu;

// PathState.phase: what a path does next (see shaders/wavefront.wgsl).
// A zeroed slot, before its first pixel.
const PHASE_FIRST_PIXEL: u32 = 0u;
const PHASE_CLOSEST: u32 = 1u;
const PHASE_SHADOW: u32 = 2u;
const PHASE_NEXT_LIGHT: u32 = 3u;
const PHASE_POP: u32 = 4u;
const PHASE_END_SAMPLE: u32 = 5u;
const PHASE_START_SAMPLE: u32 = 6u;
const PHASE_IDLE: u32 = 7u;
// A slot whose pixel is done (PHASE_EMITTER is 8).
const PHASE_FETCH_PIXEL: u32 = 9u;
// A camera ray met the back face of a single-sided material: it goes on from just
// beyond it (culls_back_face).
const PHASE_PASS_THROUGH: u32 = 10u;
// The most back faces one camera ray passes through; the next is shaded as a front.
// CPU twin: MAX_PASS_THROUGHS (a mutated model made a camera ray pass through back
// faces without end).
const MAX_PASS_THROUGHS: u32 = 256u;

// The state of one slot's path tree between dispatches: its pixel and sample, the
// sums, the ray being shaded (origin, direction, weight, depth, medium) and, while its
// lights are being gathered, the shading point's lighting state.
struct PathState {
    pixel: u32,
    sample: u32,
    phase: u32,
    stack_len: u32,
    pixel_sum: vec3<f32>,
    rays: u32,
    radiance: vec3<f32>,
    light: u32,
    origin: vec3<f32>,
    depth: u32,
    direction: vec3<f32>,
    medium_depth: u32,
    weight: vec3<f32>,
    material: u32,
    medium_iors: vec4<f32>,
    shadow_origin: vec3<f32>,
    base: f32,
    normal: vec3<f32>,
    // The hit's roughness, albedo and metalness with its textures applied (the shadow
    // rays' BRDF evaluations read the rest of the material from its record).
    roughness: f32,
    albedo: vec3<f32>,
    metallic: f32,
    direct: vec3<f32>,
    // Path integrator: the density of the BRDF sample that made the current ray, or
    // NO_BRDF_PDF (shaders/path.wgsl).
    brdf_pdf: f32,
    // Whitted: the emission of the hit being lit (emission texture applied), added with
    // its direct light after the last light.
    emission: vec3<f32>,
    // Welford's sum of squared deviations of the pixel's sample luminances so far
    // (shaders/noise.wgsl).
    luminance_m2: f32,
    // The bounce stack's top entry, kept here instead of in ray_stack while
    // held_top != 0: a branch pushed and popped before another push (the reflected ray
    // of a dielectric or mirror, the path integrator's continuation) never goes through
    // memory (push_branch, pop_ray).
    held: StackEntry,
    held_top: u32,
    // The image column and row of `pixel`, worked out once per pixel (fetch_pixel):
    // llvmpipe divides integers one lane at a time.
    image_x: u32,
    image_y: u32,
    // Back faces the current sample's camera ray has passed through (PHASE_PASS_THROUGH,
    // at most MAX_PASS_THROUGHS).
    pass_throughs: u32,
    // The current ray's cone width at its origin (texture level of detail; its spread
    // is frame.cone_spread).
    cone_width: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One pending reflected or refracted ray on a slot's bounce stack.
struct StackEntry {
    origin: vec3<f32>,
    depth: u32,
    direction: vec3<f32>,
    medium_depth: u32,
    weight: vec3<f32>,
    // The ray cone's width at `origin` (its spread is frame.cone_spread).
    cone_width: f32,
    medium_iors: vec4<f32>,
}

// Counters.errors bits.
// A loop ended without reaching its exit: the driver cut it (llvmpipe's loop limit).
const ERROR_LOOP_CUT: u32 = 1u;
// A traversal needed more than MAX_TRAVERSAL_STACK stack entries.
const ERROR_TRAVERSAL_STACK: u32 = 2u;

// Shared counters of one trace: pixels handed out and finished, rays traced (64 bits
// as two words) and error bits.
struct Counters {
    next_pixel: atomic<u32>,
    pixels_done: atomic<u32>,
    rays_low: atomic<u32>,
    rays_high: atomic<u32>,
    errors: atomic<u32>,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct DisplayUniforms {
    encode_srgb: u32,
    // Three scalars, not vec3<u32> (16-byte aligned, 32-byte struct) nor array<u32, 3>
    // (invalid in the uniform address space, which needs a 16-byte array stride).
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}
