// Records shared by the tracing and display passes. Each struct is the twin of the
// `#[repr(C)]` struct of the same name (with a `Gpu` prefix) in src/gpu/layout.rs;
// tests/layout.rs checks sizes and offsets with naga's layouter.

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
    sphere_count: u32,
    plane_count: u32,
    polygon_count: u32,
    triangle_count: u32,
    light_count: u32,
    row_offset: u32,
    row_count: u32,
    column_offset: u32,
    column_count: u32,
    target_x: u32,
    target_y: u32,
    offset_scale: f32,
    min_ray_weight: f32,
    sample_index: u32,
    accumulation_rows: u32,
    camera_medium_depth: u32,
    camera_medium_iors: vec4<f32>,
}

struct Sphere {
    center: vec3<f32>,
    radius: f32,
    material: u32,
    // Not vec3<u32>: that is 16-byte aligned and would grow the struct to 48 bytes.
    _pad: array<u32, 3>,
}

// The plane normal · p = offset.
struct Plane {
    normal: vec3<f32>,
    offset: f32,
    material: u32,
    // Not vec3<u32>: that is 16-byte aligned and would grow the struct to 48 bytes.
    _pad: array<u32, 3>,
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
    _pad1: u32,
    v2: vec3<f32>,
    _pad2: u32,
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
    // Scalars, not vec2<u32>/vec3<u32>, so the padding never changes the alignment.
    _pad0: u32,
    _pad1: u32,
}

const LIGHT_POINT: u32 = 0u;
const LIGHT_DIRECTIONAL: u32 = 1u;

struct Light {
    position_or_direction: vec3<f32>,
    kind: u32,
    power: vec3<f32>,
    _pad: u32,
}

struct DisplayUniforms {
    encode_srgb: u32,
    // Three scalars, not vec3<u32> (16-byte aligned, 32-byte struct) nor array<u32, 3>
    // (invalid in the uniform address space, which needs a 16-byte array stride).
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}
