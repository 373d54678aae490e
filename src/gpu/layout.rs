//! The `#[repr(C)]` records uploaded to the GPU, twins of the structs in
//! `shaders/types.wgsl`. `tests/layout.rs` checks with naga's layouter that every size
//! and field offset agrees. WGSL `vec3<f32>` is 16-byte aligned with size 12, so every
//! `[f32; 3]` here is followed by a 4-byte scalar that fills its last lane.

use bytemuck::{Pod, Zeroable};

/// Per-frame constants (`FrameUniforms` in WGSL), bound as a uniform buffer.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Camera position.
    pub eye: [f32; 3],
    /// Tangent of half the vertical field of view.
    pub tan_half_fov_y: f32,
    /// Unit view direction.
    pub forward: [f32; 3],
    /// Image width divided by height.
    pub aspect: f32,
    /// Unit camera right vector.
    pub right: [f32; 3],
    /// Image width in pixels.
    pub width: u32,
    /// Unit camera up vector (orthogonal to `forward` and `right`).
    pub up: [f32; 3],
    /// Image height in pixels.
    pub height: u32,
    /// Radiance of rays that escape.
    pub background: [f32; 3],
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    /// Whitted ambient radiance.
    pub ambient: [f32; 3],
    /// Largest bounce depth after the primary ray.
    pub max_depth: u32,
    /// Number of spheres in the sphere buffer (the buffer may hold a padding record).
    pub sphere_count: u32,
    /// Number of planes.
    pub plane_count: u32,
    /// Number of polygons.
    pub polygon_count: u32,
    /// Number of triangles.
    pub triangle_count: u32,
    /// Number of lights.
    pub light_count: u32,
    /// First image row this dispatch traces (dispatches are split into row chunks).
    pub row_offset: u32,
    /// Number of rows this dispatch traces.
    pub row_count: u32,
    /// First image column this dispatch traces (images wider than the device's
    /// texture limit are traced in tiles).
    pub column_offset: u32,
    /// Number of columns this dispatch traces.
    pub column_count: u32,
    /// Image column stored at texel x = 0 of the target texture (the tile's left edge).
    pub target_x: u32,
    /// Image row stored at texel y = 0 of the target texture (the tile's top edge).
    pub target_y: u32,
    /// Length scale of the self-intersection offset's near-origin branch (see
    /// `crate::cpu::intersect::ray_offset_scale`).
    pub offset_scale: f32,
    /// Branches whose weight is not above this are not traced.
    pub min_ray_weight: f32,
    /// The sample this dispatch traces in every pixel: one dispatch per sample index
    /// (see `docs/model.md`, "One sample per dispatch").
    pub sample_index: u32,
    /// Pixel rows the accumulation buffer holds (the dispatch's rows fit in it).
    pub accumulation_rows: u32,
    /// How many dielectrics contain the camera (`Scene::camera_medium`).
    pub camera_medium_depth: u32,
    /// Their indices of refraction, outermost first (unused entries 1).
    pub camera_medium_iors: [f32; 4],
}

/// A sphere (`Sphere` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuSphere {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Material index.
    pub material: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// An infinite plane `normal · p = offset` (`Plane` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuPlane {
    /// Unit normal.
    pub normal: [f32; 3],
    /// Plane offset along the normal.
    pub offset: f32,
    /// Material index.
    pub material: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// A planar polygon whose vertices live in the polygon-vertex buffer (`Polygon` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuPolygon {
    /// Unit normal of the polygon's plane.
    pub normal: [f32; 3],
    /// Plane offset along the normal.
    pub offset: f32,
    /// Index of the first vertex in the polygon-vertex buffer.
    pub first_vertex: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// The axis (0 = x, 1 = y, 2 = z) dropped when projecting for the inside test.
    pub dropped_axis: u32,
    /// Material index.
    pub material: u32,
}

/// A triangle (`Triangle` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTriangle {
    /// First corner.
    pub v0: [f32; 3],
    /// Material index.
    pub material: u32,
    /// Second corner.
    pub v1: [f32; 3],
    /// Padding.
    pub _pad1: u32,
    /// Third corner.
    pub v2: [f32; 3],
    /// Padding.
    pub _pad2: u32,
}

/// A material (`Material` in WGSL); see [`crate::scene::Material`] for the meaning.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Diffuse albedo.
    pub diffuse: [f32; 3],
    /// Blinn-Phong exponent.
    pub shininess: f32,
    /// Blinn-Phong specular colour.
    pub specular: [f32; 3],
    /// Dielectric index of refraction.
    pub ior: f32,
    /// Mirror reflectance.
    pub reflectance: [f32; 3],
    /// One of the `MATERIAL_*` constants.
    pub kind: u32,
    /// Dielectric transmittance filter.
    pub transmittance: [f32; 3],
    /// Clear-coat index of refraction (0 = none).
    pub coat_ior: f32,
    /// Emitted radiance.
    pub emission: [f32; 3],
    /// Perceptual roughness (Cook-Torrance, PBR).
    pub roughness: f32,
    /// Conductor index of refraction, real part.
    pub eta: [f32; 3],
    /// PBR metalness.
    pub metallic: f32,
    /// Conductor index of refraction, imaginary part.
    pub k: [f32; 3],
    /// Oren-Nayar slope deviation in radians.
    pub sigma: f32,
    /// One of the `DISTRIBUTION_*` constants.
    pub distribution: u32,
    /// One of the `FRESNEL_*` constants.
    pub fresnel: u32,
    /// 1 for a conductor's Fresnel (`eta`, `k`), 0 for a dielectric's (`ior`).
    pub conductor: u32,
    /// One of the `MAPPING_*` constants.
    pub texture_mapping: u32,
    /// Layer of the albedo texture in the image array, or [`NO_IMAGE`].
    pub texture_layer: u32,
    /// Width of the albedo texture in texels.
    pub texture_width: u32,
    /// Height of the albedo texture in texels.
    pub texture_height: u32,
    /// Scene units per repeat of the planar mapping.
    pub texture_scale: f32,
    /// Layer of the BRDF map in the image array, or [`NO_IMAGE`].
    pub brdf_map_layer: u32,
    /// Side of the (square) BRDF map in texels.
    pub brdf_map_size: u32,
    /// Padding (scalars: a `vec3<u32>` would be 16-byte aligned in WGSL).
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
}

/// A light (`Light` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// Point light: position. Directional light: unit direction of travel.
    pub position_or_direction: [f32; 3],
    /// One of the `LIGHT_*` constants.
    pub kind: u32,
    /// Point light: intensity in W/sr. Directional light: irradiance in W/m².
    pub power: [f32; 3],
    /// Padding.
    pub _pad: u32,
}

/// Uniforms of the display pass (`DisplayUniforms` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct DisplayUniforms {
    /// 1: apply the sRGB transfer curve; 0: write the values unchanged (naive gamma mode).
    pub encode_srgb: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// `Material.kind` value for Lambert.
pub const MATERIAL_LAMBERT: u32 = 0;
/// `Material.kind` value for Blinn-Phong.
pub const MATERIAL_BLINN_PHONG: u32 = 1;
/// `Material.kind` value for a mirror.
pub const MATERIAL_MIRROR: u32 = 2;
/// `Material.kind` value for a dielectric.
pub const MATERIAL_DIELECTRIC: u32 = 3;
/// `Material.kind` value for a pure emitter.
pub const MATERIAL_EMISSIVE: u32 = 4;
/// `Material.kind` value for Cook-Torrance.
pub const MATERIAL_COOK_TORRANCE: u32 = 5;
/// `Material.kind` value for Oren-Nayar.
pub const MATERIAL_OREN_NAYAR: u32 = 6;
/// `Material.kind` value for a tabulated BRDF map.
pub const MATERIAL_TABULATED: u32 = 7;
/// `Material.kind` value for glTF metal/roughness PBR.
pub const MATERIAL_PBR: u32 = 8;
/// `Material.distribution` value for GGX.
pub const DISTRIBUTION_GGX: u32 = 0;
/// `Material.distribution` value for Beckmann.
pub const DISTRIBUTION_BECKMANN: u32 = 1;
/// `Material.fresnel` value for the exact equations.
pub const FRESNEL_EXACT: u32 = 0;
/// `Material.fresnel` value for Schlick's approximation.
pub const FRESNEL_SCHLICK: u32 = 1;
/// `Material.texture_mapping` value for the planar mapping.
pub const MAPPING_PLANAR: u32 = 0;
/// `Material.texture_mapping` value for the spherical mapping.
pub const MAPPING_SPHERICAL: u32 = 1;
/// `texture_layer` / `brdf_map_layer` value meaning "no image".
pub const NO_IMAGE: u32 = u32::MAX;
/// `Light.kind` value for a point light.
pub const LIGHT_POINT: u32 = 0;
/// `Light.kind` value for a directional light.
pub const LIGHT_DIRECTIONAL: u32 = 1;
