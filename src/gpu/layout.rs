//! The `#[repr(C)]` records uploaded to the GPU, twins of the structs in
//! `shaders/types.wgsl`. `tests/integration/layout.rs` checks with naga's layouter that every size
//! and field offset agrees. WGSL `vec3<f32>` is 16-byte aligned with size 12, so every
//! `[f32; 3]` here is followed by a 4-byte scalar that fills its last lane.

use bytemuck::{Pod, Zeroable};

/// The constants of one trace (`FrameUniforms` in WGSL), bound as a uniform buffer:
/// the camera and scene settings, and which region of the image, which sample range
/// and how many slots the trace covers.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Camera position.
    pub eye: [f32; 3],
    /// Tangent of half the vertical field of view; with [`FLAG_ORTHOGRAPHIC`], half
    /// the view's height in scene units.
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
    /// Samples per pixel of the whole render.
    pub samples_per_pixel: u32,
    /// Whitted ambient radiance.
    pub ambient: [f32; 3],
    /// Largest bounce depth after the primary ray.
    pub max_depth: u32,
    /// Indices of refraction of the dielectrics around the camera, outermost first
    /// (unused entries 1).
    pub camera_medium_iors: [f32; 4],
    /// How many dielectrics contain the camera (`Scene::camera_medium`).
    pub camera_medium_depth: u32,
    /// Number of infinite planes.
    pub plane_count: u32,
    /// Number of BVH nodes (0: no bounded primitive).
    pub node_count: u32,
    /// Number of lights.
    pub light_count: u32,
    /// First image column of the traced region.
    pub region_x: u32,
    /// First image row of the traced region.
    pub region_y: u32,
    /// Columns of the traced region.
    pub region_width: u32,
    /// Rows of the traced region.
    pub region_height: u32,
    /// Image column stored at texel x = 0 of the target texture.
    pub target_x: u32,
    /// Image row stored at texel y = 0 of the target texture.
    pub target_y: u32,
    /// First sample index this trace adds to each pixel.
    pub first_sample: u32,
    /// One past the last sample index this trace adds; the written mean divides by it.
    pub end_sample: u32,
    /// Number of path slots (invocations per dispatch).
    pub slot_count: u32,
    /// Entries of each slot's bounce stack (the scene's `stack_size`).
    pub stack_size: u32,
    /// Most loop iterations one invocation runs per dispatch (see `docs/model.md`,
    /// "Bounded work").
    pub iteration_budget: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// Length scale of the self-intersection offset's near-origin branch (see
    /// [`crate::accel::ray_offset_scale`]).
    pub offset_scale: f32,
    /// Branches whose weight is not above this are not traced.
    pub min_ray_weight: f32,
    /// Region pixels below this go to slots in a fixed order, the rest from the shared
    /// counter ([`static_pixels_for`]; set where a trace starts).
    pub static_pixels: u32,
    /// Radius of the camera's thin lens ([`crate::camera::CameraFrame::lens_radius`]);
    /// 0 for a pinhole.
    pub lens_radius: f32,
    /// Distance from the eye to the plane in focus along `forward` (with a lens).
    pub focus_distance: f32,
    /// A camera ray's cone width at its origin
    /// ([`crate::camera::CameraFrame::pixel_cone`]); 0 without texture filtering.
    pub cone_width: f32,
    /// A camera ray's cone width growth per unit distance, `2·tan(α/2)`
    /// ([`crate::camera::CameraFrame::pixel_cone`]); 0 without texture filtering.
    pub cone_spread: f32,
    /// Padding to the record's 16-byte alignment.
    pub _pad: u32,
}

/// Most rounds of pixels handed out in a fixed order ([`static_pixels_for`]).
pub const STATIC_ROUNDS: u64 = 4;

/// The pixels of a region of `pixels` pixels that `frame`'s trace hands out in a fixed
/// order (`FrameUniforms::static_pixels`): slot `s` takes pixels `s`, `s + slots`,
/// `s + 2·slots`, ... below this count, so that the lanes of one SIMD vector
/// (neighbouring slots) start on neighbouring pixels and take the same branches.
/// At most [`STATIC_ROUNDS`] rounds, and never the last whole one: later, lanes
/// drift a round apart and a fixed order no longer keeps them together (every round
/// in it made the 1920x1080 showcase 13% slower on lavapipe), so the rest goes through
/// the shared counter to the slots that finish first, which also balances the end of
/// the trace. None for the path integrator, whose paths scatter after the first
/// bounce anyway: there the fixed order measured 3-5% slower. The order changes no
/// pixel: each slot traces a pixel alone, in the same order (`BENCHMARKS.md`, "Pixel
/// order", for the figures).
pub fn static_pixels_for(frame: &FrameUniforms, pixels: u64) -> u32 {
    if frame.flags & super::area_lights::FLAG_PATH != 0 {
        return 0;
    }
    let slots = u64::from(frame.slot_count.max(1));
    let rounds = (pixels / slots).saturating_sub(1).min(STATIC_ROUNDS);
    (rounds * slots).min(u64::from(u32::MAX)) as u32
}

/// `FrameUniforms.flags`: store each finished pixel's sample sum and luminance m2
/// (its noise estimate, [`crate::noise`]) in the accumulation buffer.
pub const FLAG_STORE_SUM: u32 = 1;
/// `FrameUniforms.flags`, for tests: traversals leave their loop without reaching an
/// exit, as a driver that cuts loops makes them do.
pub const FLAG_SIMULATE_LOOP_CUT: u32 = 2;
/// `FrameUniforms::flags`: also sum each pixel's auxiliary passes (albedo and depth,
/// normal: two `vec4<f32>` per pixel, `shaders/aov.wgsl`) in the accumulation buffer,
/// after the sample sums; only modules with [`super::ShaderFeatures::aov`] do.
pub const FLAG_AOV: u32 = 8;
/// `FrameUniforms.flags`: the camera is orthographic, and `tan_half_fov_y` holds half
/// the view's height in scene units ([`crate::camera::CameraFrame::ray_origin`]).
pub const FLAG_ORTHOGRAPHIC: u32 = 16;
/// `FrameUniforms.flags`: textures are filtered (`[render] texture_filtering =
/// "trilinear"` or `"anisotropic"`): the host then fills `cone_width` and
/// `cone_spread` of each frame's camera (the shaders read only those, which are 0
/// without filtering).
pub const FLAG_TEXTURE_FILTERING: u32 = 32;
/// `FrameUniforms.flags`: texture lookups take up to
/// [`crate::scene::MAX_TEXTURE_PROBES`] probes along the footprint's long axis
/// (`texture_filtering = "anisotropic"`), else one.
pub const FLAG_ANISOTROPIC_TEXTURES: u32 = 64;

/// One traversal of one ray, resumable (`TraceRay` in WGSL). Only the shaders read and
/// write it; the host zeroes it (`TRACE_IDLE`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTraceRay {
    /// Ray origin.
    pub origin: [f32; 3],
    /// Exclusive distance limit.
    pub t_max: f32,
    /// Unit direction.
    pub direction: [f32; 3],
    /// `TRACE_*` state.
    pub status: u32,
    /// Distance of the best hit so far (`t_max` without one).
    pub best_t: f32,
    /// The best hit's primitive reference, or `u32::MAX`.
    pub best_prim: u32,
    /// Entries on the slot's traversal stack.
    pub stack_len: u32,
    /// Node to visit next, or `u32::MAX`.
    pub node: u32,
    /// Next primitive of the current leaf.
    pub cursor: u32,
    /// One past the current leaf's last primitive.
    pub leaf_end: u32,
    /// 1 for a shadow ray (the first hit ends it).
    pub any_hit: u32,
    /// The best hit's instance (the node index of its record), or `u32::MAX` for the
    /// scene's own primitives.
    pub best_instance: u32,
    /// The instance whose mesh is being traversed (its record's node index), or
    /// `u32::MAX` in the scene's own tree.
    pub instance: u32,
    /// Stack depth at which the current instance's traversal began.
    pub stack_base: u32,
    /// Inside an instance: the next primitive of the scene tree's leaf that named it.
    pub world_cursor: u32,
    /// Inside an instance: one past that leaf's last primitive.
    pub world_leaf_end: u32,
    /// The seed of stochastic transparency (the path integrator's rays,
    /// [`crate::cpu::coverage::BlendRule::Stochastic`]), or [`NO_BLEND_SEED`]:
    /// blended surfaces are then hit by a closest-hit trace and transmit light
    /// through an any-hit one.
    pub blend_seed: u32,
    /// With [`NO_BLEND_SEED`], the product of `1 − alpha` of the blended surfaces an
    /// any-hit trace passed.
    pub transmittance: f32,
    /// Padding to the record's 16-byte alignment.
    pub _pad0: u32,
    /// Padding to the record's 16-byte alignment.
    pub _pad1: u32,
}

/// [`GpuTraceRay::blend_seed`] of a trace without stochastic transparency. A seed
/// that happens to equal it is taken as none; the path integrator's seeds are hashes
/// ([`crate::cpu::coverage::blend_seed`]), so its traces avoid it by changing it to 0
/// (`blend_seed` in `shaders/path.wgsl` and `src/cpu/traverse.rs`).
pub const NO_BLEND_SEED: u32 = u32::MAX;

/// The state of one slot's path tree between dispatches (`PathState` in WGSL). Only
/// the shaders read and write it; the host zeroes it (`PHASE_FIRST_PIXEL`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuPathState {
    /// Region pixel the slot works on.
    pub pixel: u32,
    /// Current sample index.
    pub sample: u32,
    /// `PHASE_*` of the path.
    pub phase: u32,
    /// Entries on the slot's bounce stack.
    pub stack_len: u32,
    /// Sum of the pixel's finished samples.
    pub pixel_sum: [f32; 3],
    /// Rays traced for the pixel so far.
    pub rays: u32,
    /// Radiance of the current sample so far.
    pub radiance: [f32; 3],
    /// Index of the light being gathered.
    pub light: u32,
    /// Origin of the ray being shaded.
    pub origin: [f32; 3],
    /// Its bounce depth.
    pub depth: u32,
    /// Its direction.
    pub direction: [f32; 3],
    /// How many dielectrics it is inside.
    pub medium_depth: u32,
    /// Its path weight.
    pub weight: [f32; 3],
    /// Material of the hit being lit.
    pub material: u32,
    /// Indices of refraction of the dielectrics it is inside.
    pub medium_iors: [f32; 4],
    /// Origin of the hit's shadow rays.
    pub shadow_origin: [f32; 3],
    /// Weight of the hit's base BRDF (1 - coat reflectance).
    pub base: f32,
    /// Shading normal (facing the incoming ray).
    pub normal: [f32; 3],
    /// Perceptual roughness at the hit (metallic/roughness texture applied).
    pub roughness: f32,
    /// Albedo at the hit (texture applied).
    pub albedo: [f32; 3],
    /// Metalness at the hit (metallic/roughness texture applied).
    pub metallic: f32,
    /// Direct light gathered so far (ambient included); with the path integrator,
    /// the weight of the hit's base-BRDF event.
    pub direct: [f32; 3],
    /// Path integrator: the density of the BRDF sample that made the current ray
    /// (negative when none did).
    pub brdf_pdf: f32,
    /// Whitted: the emission of the hit being lit (emission texture applied), added
    /// with its direct light.
    pub emission: [f32; 3],
    /// Welford's sum of squared deviations of the pixel's sample luminances so far
    /// ([`crate::noise::luminance_m2_step`]).
    pub luminance_m2: f32,
    /// The bounce stack's top entry while `held_top` is not 0 (it is then not in the
    /// slot's bounce stack buffer).
    pub held: GpuStackEntry,
    /// Whether `held` is the stack's top.
    pub held_top: u32,
    /// Image column of `pixel`.
    pub image_x: u32,
    /// Image row of `pixel`.
    pub image_y: u32,
    /// Back faces the current sample's camera ray has passed through (at most
    /// [`crate::cpu::intersect::MAX_PASS_THROUGHS`]).
    pub pass_throughs: u32,
    /// The ray cone's width at `origin`, the current ray's (texture level of detail).
    pub cone_width: f32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// One pending ray on a slot's bounce stack (`StackEntry` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuStackEntry {
    /// Ray origin.
    pub origin: [f32; 3],
    /// Bounce depth.
    pub depth: u32,
    /// Ray direction.
    pub direction: [f32; 3],
    /// How many dielectrics the ray is inside.
    pub medium_depth: u32,
    /// Path weight.
    pub weight: [f32; 3],
    /// The ray cone's width at `origin` (texture level of detail; its spread is the
    /// camera's, `FrameUniforms::cone_spread`).
    pub cone_width: f32,
    /// Indices of refraction of the dielectrics it is inside.
    pub medium_iors: [f32; 4],
}

/// The shared counters of one trace (`Counters` in WGSL), read back after each
/// submission.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuCounters {
    /// Region pixels handed out from the shared counter, counted from
    /// `FrameUniforms::static_pixels` (may pass the region's size).
    pub next_pixel: u32,
    /// Region pixels finished.
    pub pixels_done: u32,
    /// Rays traced, low word.
    pub rays_low: u32,
    /// Rays traced, high word.
    pub rays_high: u32,
    /// `ERROR_*` bits.
    pub errors: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

impl GpuCounters {
    /// Rays traced, as one number.
    pub fn rays(&self) -> u64 {
        (u64::from(self.rays_high) << 32) | u64::from(self.rays_low)
    }
}

/// `Counters.errors` bit: a loop ended without reaching its exit (the driver cut it).
pub const ERROR_LOOP_CUT: u32 = 1;
/// `Counters.errors` bit: a traversal needed more stack than `MAX_TRAVERSAL_STACK`.
pub const ERROR_TRAVERSAL_STACK: u32 = 2;

/// A sphere (`Sphere` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuSphere {
    /// The sphere's point nearest the world origin (`crate::scene::sphere_anchor`).
    pub anchor: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// The unit outward normal at `anchor`.
    pub normal: [f32; 3],
    /// Material index.
    pub material: u32,
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
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
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
    /// Index of its vertex normals and texture coordinates in the triangle attribute
    /// buffer, or [`NO_ATTRIBUTES`].
    pub attributes: u32,
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
    /// How the albedo texture wraps along `u`: one of the `WRAP_*` constants.
    pub texture_wrap_u: u32,
    /// How the albedo texture wraps along `v`: one of the `WRAP_*` constants.
    pub texture_wrap_v: u32,
    /// Layer of the metallic/roughness texture in the image array, or [`NO_IMAGE`].
    pub metallic_roughness_layer: u32,
    /// Width of the metallic/roughness texture in texels.
    pub metallic_roughness_width: u32,
    /// Height of the metallic/roughness texture in texels.
    pub metallic_roughness_height: u32,
    /// Its wrap modes: the `WRAP_*` code along `u` in bits 0-7, along `v` in bits 8-15.
    pub metallic_roughness_wrap: u32,
    /// 1 when flat shapes of this material emit from both sides (path integrator).
    pub two_sided: u32,
    /// Layer of the emission texture in the image array, or [`NO_IMAGE`].
    pub emission_layer: u32,
    /// Width of the emission texture in texels.
    pub emission_width: u32,
    /// Height of the emission texture in texels.
    pub emission_height: u32,
    /// Its wrap modes: the `WRAP_*` code along `u` in bits 0-7, along `v` in bits 8-15.
    pub emission_wrap: u32,
    /// The texture coordinate set (0 or 1) each texture reads: the albedo texture's in
    /// bit 0, the metallic/roughness texture's in bit 1, the emission texture's in bit 2
    /// (`UV_SLOT_*`).
    pub uv_sets: u32,
    /// 1 when camera rays pass through the back faces of flat shapes of this material
    /// (glTF `doubleSided: false`).
    pub cull_back_faces: u32,
    /// Layer of the normal map in the image array, or [`NO_IMAGE`].
    pub normal_layer: u32,
    /// The affine maps of the textures' coordinates, two rows each: texture `s`
    /// (`UV_SLOT_*`) maps `(u, v)` to `(rows[2s]·(u, v, 1), rows[2s+1]·(u, v, 1))`
    /// (the last lane unused); see [`crate::scene::TextureTransform`].
    pub uv_rows: [[f32; 4]; 8],
    /// Width of the normal map in texels.
    pub normal_width: u32,
    /// Height of the normal map in texels.
    pub normal_height: u32,
    /// Its wrap modes: the `WRAP_*` code along `u` in bits 0-7, along `v` in bits 8-15.
    pub normal_wrap: u32,
    /// glTF's `normalTexture.scale`.
    pub normal_scale: f32,
    /// The alpha mask's cutoff: points whose alpha is below it do not exist for any
    /// ray ([`crate::scene::AlphaMode::Mask`]); 0 for an opaque or blended material.
    pub alpha_cutoff: f32,
    /// The alpha factor ([`crate::scene::Material::alpha`]), multiplying the albedo
    /// texture's texel alpha.
    pub alpha: f32,
    /// 1 for a blended material ([`crate::scene::AlphaMode::Blend`]), whose alpha is
    /// the fraction of light it stops.
    pub alpha_blend: u32,
    /// Padding to the record's 16-byte alignment.
    pub _pad1: u32,
}

/// [`GpuMaterial::uv_rows`] and [`GpuMaterial::uv_sets`]: the albedo texture.
pub const UV_SLOT_ALBEDO: u32 = 0;
/// [`GpuMaterial::uv_rows`] and [`GpuMaterial::uv_sets`]: the metallic/roughness
/// texture.
pub const UV_SLOT_METALLIC_ROUGHNESS: u32 = 1;
/// [`GpuMaterial::uv_rows`] and [`GpuMaterial::uv_sets`]: the emission texture.
pub const UV_SLOT_EMISSION: u32 = 2;
/// [`GpuMaterial::uv_rows`] and [`GpuMaterial::uv_sets`]: the normal map.
pub const UV_SLOT_NORMAL: u32 = 3;

/// The shading attributes of one mesh triangle (`TriangleAttributes` in WGSL): vertex
/// normals and texture coordinates in the order of the triangle's corners; see
/// [`crate::accel::TriangleAttributes`].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTriangleAttributes {
    /// Unit normal at the first corner.
    pub n0: [f32; 3],
    /// 1 when the normals are given (smooth shading), else 0 (the shader then uses the
    /// geometric normal).
    pub has_normals: u32,
    /// Unit normal at the second corner.
    pub n1: [f32; 3],
    /// 1 when the texture coordinates are given, else 0 (`(0, 0)` is used).
    pub has_uvs: u32,
    /// Unit normal at the third corner.
    pub n2: [f32; 3],
    /// 1 when the vertex colours are given, else 0 (white is used).
    pub has_colors: u32,
    /// Texture coordinates of the first and second corners.
    pub uv01: [f32; 4],
    /// Texture coordinates of the third corner.
    pub uv2: [f32; 2],
    /// 1 when the second set of texture coordinates is given, else 0 (`(0, 0)`).
    pub has_uvs1: u32,
    /// 1 when tangents are given (normal maps), else 0.
    pub has_tangents: u32,
    /// Second-set texture coordinates of the first and second corners.
    pub uv1_01: [f32; 4],
    /// Second-set texture coordinates of the third corner.
    pub uv1_2: [f32; 2],
    /// Padding.
    pub _pad1: [u32; 2],
    /// Linear RGBA colour at the first corner.
    pub c0: [f32; 4],
    /// Linear RGBA colour at the second corner.
    pub c1: [f32; 4],
    /// Linear RGBA colour at the third corner.
    pub c2: [f32; 4],
    /// Unit tangent and bitangent handedness at the first corner.
    pub t0: [f32; 4],
    /// Unit tangent and bitangent handedness at the second corner.
    pub t1: [f32; 4],
    /// Unit tangent and bitangent handedness at the third corner.
    pub t2: [f32; 4],
}

/// A light (`Light` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// Point and spot light: position. Directional light: unit direction of travel.
    pub position_or_direction: [f32; 3],
    /// One of the `LIGHT_*` constants.
    pub kind: u32,
    /// Point and spot light: intensity in W/sr. Directional light: irradiance in W/m².
    pub power: [f32; 3],
    /// Spot light: cosine of the inner cone's half-angle (else 0).
    pub cos_inner: f32,
    /// Spot light: the unit axis of its cone (else zero).
    pub spot_direction: [f32; 3],
    /// Spot light: cosine of the outer cone's half-angle (else 0).
    pub cos_outer: f32,
}

/// Uniforms of one step of the denoiser (`DenoiseUniforms` in WGSL,
/// `shaders/denoise.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct DenoiseUniforms {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Tap spacing of an à-trous pass, `2^iteration` pixels.
    pub step: u32,
    /// Padding.
    pub _pad: u32,
    /// [`crate::denoise::DenoiseSettings::sigma_normal`].
    pub sigma_normal: f32,
    /// [`crate::denoise::DenoiseSettings::sigma_depth`].
    pub sigma_depth: f32,
    /// [`crate::denoise::DenoiseSettings::sigma_luminance`].
    pub sigma_luminance: f32,
    /// [`crate::denoise::DenoiseSettings::sigma_albedo`].
    pub sigma_albedo: f32,
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
/// `texture_mapping`: the mesh's interpolated texture coordinates.
pub const MAPPING_UV: u32 = 2;
/// `texture_wrap_u`/`_v`: the image repeats.
pub const WRAP_REPEAT: u32 = 0;
/// `texture_wrap_u`/`_v`: the image repeats, mirrored every other time.
pub const WRAP_MIRRORED_REPEAT: u32 = 1;
/// `texture_wrap_u`/`_v`: the edge texels extend.
pub const WRAP_CLAMP_TO_EDGE: u32 = 2;
/// [`GpuTriangle::attributes`] of a triangle without vertex attributes.
pub const NO_ATTRIBUTES: u32 = u32::MAX;
/// `texture_layer` / `brdf_map_layer` value meaning "no image".
pub const NO_IMAGE: u32 = u32::MAX;
/// The instance of the scene's own primitives in a hit or an emitter record
/// (`NO_INSTANCE` in WGSL).
pub const NO_INSTANCE: u32 = u32::MAX;
/// `Light.kind` value for a point light.
pub const LIGHT_POINT: u32 = 0;
/// `Light.kind` value for a directional light.
pub const LIGHT_DIRECTIONAL: u32 = 1;
/// `Light.kind` value for a spot light.
pub const LIGHT_SPOT: u32 = 2;

#[cfg(test)]
mod tests {
    use super::{FrameUniforms, static_pixels_for};
    use crate::gpu::area_lights::FLAG_PATH;
    use bytemuck::Zeroable;

    fn frame(slots: u32, flags: u32) -> FrameUniforms {
        FrameUniforms {
            slot_count: slots,
            flags,
            ..FrameUniforms::zeroed()
        }
    }

    #[test]
    fn the_first_whole_rounds_but_the_last_are_handed_out_in_order() {
        assert_eq!(static_pixels_for(&frame(100, 0), 500), 400);
        assert_eq!(static_pixels_for(&frame(100, 0), 599), 400);
        // At most STATIC_ROUNDS rounds.
        assert_eq!(static_pixels_for(&frame(100, 0), 10_000), 400);
        assert_eq!(static_pixels_for(&frame(100, 0), 199), 0);
        assert_eq!(static_pixels_for(&frame(100, 0), 50), 0);
        assert_eq!(static_pixels_for(&frame(1 << 31, 0), 1 << 40), u32::MAX);
    }

    #[test]
    fn the_path_integrator_takes_every_pixel_from_the_counter() {
        assert_eq!(static_pixels_for(&frame(100, FLAG_PATH), 1000), 0);
    }
}
