//! The validated, in-memory scene: what both backends render.
//!
//! Everything here has been checked by [`crate::scene::load_scene`] (finite numbers,
//! positive sizes, resolved material names, planar polygons, ...), so the tracers can
//! trust it. Positions are in scene units (any length unit, used consistently), colours
//! are linear RGB, and the CPU reference works on these `f64` values directly while the
//! GPU backend rounds them to `f32` on upload.

use std::path::PathBuf;

use glam::{DMat4, DVec2, DVec3};

/// A complete scene: image settings, camera, environment, materials, lights and shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Output size, sampling and recursion limits.
    pub render: RenderSettings,
    /// The pinhole camera.
    pub camera: Camera,
    /// Radiance seen by rays that escape the scene, and the Whitted ambient term.
    pub environment: Environment,
    /// Materials, indexed by [`Shape::material`].
    pub materials: Vec<Material>,
    /// The names the scene file gave the materials, parallel to `materials`.
    pub material_names: Vec<String>,
    /// Light sources; each shading point casts one shadow ray per light.
    pub lights: Vec<Light>,
    /// Geometry.
    pub shapes: Vec<Shape>,
    /// Triangle meshes with per-vertex normals and texture coordinates, each placed
    /// one or more times (models from OBJ or glTF files).
    pub meshes: Vec<Mesh>,
    /// Images (albedo textures and tabulated BRDF maps), indexed by
    /// [`Material::albedo_texture`] and [`Material::brdf_map`].
    pub images: Vec<Image>,
}

/// An indexed triangle mesh and the places it stands in the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Where it came from (a model file's mesh or primitive), for messages.
    pub name: String,
    /// Vertex positions in the mesh's own space.
    pub positions: Vec<DVec3>,
    /// Unit vertex normals, parallel to `positions`, for smooth shading.
    pub normals: Option<Vec<DVec3>>,
    /// Texture coordinates, parallel to `positions` (`v` down, as image rows run).
    pub uvs: Option<Vec<DVec2>>,
    /// A second set of texture coordinates (glTF's `TEXCOORD_1`), parallel to
    /// `positions`, for the textures whose [`TextureTransform::set`] is 1.
    pub uvs1: Option<Vec<DVec2>>,
    /// Linear RGBA vertex colours in [0, 1], parallel to `positions` (glTF's `COLOR_0`,
    /// OBJ's `v x y z r g b` with alpha 1): the colour multiplies the albedo, the alpha
    /// the material's alpha where its alpha mode reads alpha (glTF 2.0 §3.7.2.1,
    /// §3.9.4; [`AlphaMode`]).
    pub colors: Option<Vec<glam::DVec4>>,
    /// Unit tangents (`xyz`) with the bitangent's handedness (`w`, ±1), parallel to
    /// `positions`, for normal maps: glTF's `TANGENT`, or MikkTSpace's from the
    /// normals and texture coordinates; the bitangent is `w · (normal × tangent)`.
    pub tangents: Option<Vec<glam::DVec4>>,
    /// Triangles as three vertex indices, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Mesh-to-world transforms, one per placement (finite and invertible).
    pub instances: Vec<DMat4>,
}

/// An image loaded from a file, in linear RGBA `f32` (8-bit sRGB files are linearised
/// on load with the exact sRGB curve; float files are taken as linear).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// Width in texels (at least 1).
    pub width: u32,
    /// Height in texels (at least 1).
    pub height: u32,
    /// `width × height` texels, row-major, top row first.
    pub texels: Vec<[f32; 4]>,
}

impl Image {
    /// The texel at column `x`, row `y` (both in range).
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texels[(y * self.width + x) as usize]
    }
}

/// How the image is sampled and how deep rays recurse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels (at least 1).
    pub width: u32,
    /// Image height in pixels (at least 1).
    pub height: u32,
    /// Stratified samples per pixel, averaged with a box filter (at least 1).
    pub samples_per_pixel: u32,
    /// Largest number of reflection/refraction bounces after the primary ray
    /// (0 = ray casting with direct lighting only).
    pub max_depth: u32,
    /// Capacity of the explicit bounce stack. `max_depth + 1` entries always suffice;
    /// with fewer, a branch that finds the stack full is dropped (its energy is lost)
    /// on both backends alike.
    pub stack_size: u32,
    /// Whether lighting is done correctly in linear space or, for the lecture's
    /// comparison, naively on sRGB-encoded values.
    pub lighting_space: LightingSpace,
    /// Ray-weight cutoff in [0, 1]: a reflected or refracted branch whose accumulated
    /// weight (largest channel) is not above it is not traced. 0 traces every branch
    /// that carries any light; larger values trade accuracy for speed.
    pub min_ray_weight: f64,
    /// The light-transport algorithm.
    pub integrator: Integrator,
    /// How surface textures are filtered (`[render] texture_filtering`).
    pub texture_filtering: TextureFiltering,
}

/// The most trilinear probes an anisotropic lookup takes along a footprint's long
/// axis ([`crate::texture::texel_footprint`]): 16, the largest anisotropy of common
/// GPU samplers (`maxSamplerAnisotropy`, Vulkan 1.3 §33.1; wgpu's `anisotropy_clamp`
/// ≤ 16).
pub const MAX_TEXTURE_PROBES: u32 = 16;

/// How surface textures are looked up (`[render] texture_filtering`,
/// docs/scene-format.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TextureFiltering {
    /// Bilinear at level 0, whatever the distance (aliases far away).
    None,
    /// Trilinear between mip-map levels at the footprint of a ray cone, isotropic: one
    /// probe at the level of the footprint's long axis ([`crate::texture::texture_lod`]).
    Trilinear,
    /// Trilinear probes along the long axis of a ray cone's footprint, each at the
    /// level of its share of it ([`crate::texture::texel_footprint`]): sharp at grazing
    /// angles where `Trilinear` blurs across the view.
    #[default]
    Anisotropic,
}

impl TextureFiltering {
    /// Whether textures have mip-map chains and are looked up at a ray cone's
    /// footprint.
    pub fn filters(self) -> bool {
        self != Self::None
    }

    /// The most trilinear probes one lookup takes
    /// ([`crate::texture::ConeFootprint::max_probes`]).
    pub fn max_probes(self) -> u32 {
        match self {
            Self::None | Self::Trilinear => 1,
            Self::Anisotropic => MAX_TEXTURE_PROBES,
        }
    }
}

impl Default for RenderSettings {
    /// The scene-file defaults: 640x480, 1 sample, depth 5, a sufficient stack, linear
    /// lighting, no weight cutoff.
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 1,
            max_depth: 5,
            stack_size: Self::sufficient_stack_size(5),
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: Integrator::Whitted,
            texture_filtering: TextureFiltering::Anisotropic,
        }
    }
}

impl RenderSettings {
    /// The stack size that guarantees no branch is ever dropped for `max_depth`.
    pub fn sufficient_stack_size(max_depth: u32) -> u32 {
        // Saturating: an absurd depth is reported by `check`, not by an overflow panic.
        max_depth.saturating_add(1)
    }
}

/// How radiance along a camera ray is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Whitted's recursive ray tracing: direct light by one shadow ray per light,
    /// perfect mirror and refraction branches, a flat ambient term.
    #[default]
    Whitted,
    /// Unbiased Monte Carlo path tracing: emissive shapes are lights, next-event
    /// estimation with multiple importance sampling, importance-sampled BRDFs, Russian
    /// roulette (docs/path-tracing.md). On both backends.
    Path,
}

/// Where shading arithmetic happens (see the lecture's "Gamma space vs linear space").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LightingSpace {
    /// Colours are linear, lighting is linear, one sRGB encode at the end. Correct.
    #[default]
    Linear,
    /// Colours are taken as the sRGB-encoded values an artist would pick, lighting is
    /// done on them directly and the result is written without the final encode.
    /// Wrong on purpose, to reproduce the lecture's comparison.
    NaiveGamma,
}

/// Largest half view height of an orthographic camera accepted, in scene units
/// ([`Camera::orthographic_half_height`]).
pub const MAX_ORTHOGRAPHIC_HALF_HEIGHT: f64 = 1e15;

/// A pinhole camera, or an orthographic one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Centre of projection.
    pub eye: DVec3,
    /// A point the camera looks at (distinct from `eye`).
    pub look_at: DVec3,
    /// Approximate up direction (non-zero, not parallel to the view direction).
    pub up: DVec3,
    /// Full vertical field of view in degrees, in (0, 180) (unused by an
    /// orthographic camera).
    pub fov_y_degrees: f64,
    /// For an orthographic camera (glTF's `orthographic` projection), half the height
    /// of the view in scene units (finite, > 0, at most
    /// [`MAX_ORTHOGRAPHIC_HALF_HEIGHT`]; glTF's `ymag`): its rays are parallel,
    /// along the view direction, from points of the plane through `eye` facing it,
    /// `half_height` above and below `eye` and the image's aspect times that either
    /// side. `None`: a pinhole camera of `fov_y_degrees`.
    pub orthographic_half_height: Option<f64>,
    /// A thin lens at the eye of a pinhole camera, for depth of field; `None`: a
    /// pinhole, everything in focus. Not with an orthographic camera.
    pub lens: Option<ThinLens>,
}

/// A thin lens of radius `aperture_radius` centred on the eye, facing the view
/// direction, focused on the plane `focus_distance` along it (pbrt-v4's
/// `PerspectiveCamera` with `lensradius` and `focaldistance`, Pharr, Jakob and
/// Humphreys, *Physically Based Rendering*, 4th ed., §5.2.3): each camera ray starts
/// at a point of the lens, uniform in area, and passes through the point of the focal
/// plane that the pinhole ray through its image position meets, so points on that
/// plane are sharp and others blur with their distance from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinLens {
    /// Radius of the aperture in scene units (finite, > 0).
    pub aperture_radius: f64,
    /// Distance from the eye to the plane in focus, along the view direction (finite,
    /// > 0); `None`: the distance to `look_at`, which a camera path moves with it.
    pub focus_distance: Option<f64>,
}

impl ThinLens {
    /// What makes the lens unusable, if anything: an aperture or focus distance that is
    /// not finite and positive.
    pub fn problem(&self) -> Option<&'static str> {
        let usable = |v: f64| v.is_finite() && v > 0.0;
        if !usable(self.aperture_radius) {
            return Some("aperture_radius must be finite and > 0 (leave it out for a pinhole)");
        }
        if self.focus_distance.is_some_and(|d| !usable(d)) {
            return Some("focus_distance must be finite and > 0");
        }
        None
    }

    /// The distance in focus for a camera at `eye` looking at `look_at`.
    pub fn focus_distance_for(&self, eye: DVec3, look_at: DVec3) -> f64 {
        self.focus_distance
            .unwrap_or_else(|| (look_at - eye).length())
    }
}

/// Light that does not come from a light source.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Environment {
    /// Radiance (W/(sr·m²) per channel) carried by rays that hit nothing, when there
    /// is no [`Environment::map`].
    pub background: DVec3,
    /// An environment map: the radiance of rays that hit nothing by direction (it
    /// replaces `background`), and a light the path integrator samples.
    pub map: Option<std::sync::Arc<super::EnvironmentMap>>,
    /// Constant ambient radiance added as `albedo * ambient` at every diffuse hit:
    /// the classic Whitted ambient term. Default 0 (physically based).
    pub ambient: DVec3,
}

/// The reflection model a material uses for direct lighting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaterialKind {
    /// Lambertian diffuse: `f = albedo / π`.
    Lambert,
    /// Normalized Blinn-Phong: `f = kd/π + ks·(n+8)/(8π)·cos^n θ_h`.
    BlinnPhong,
    /// Perfect specular reflection weighted by a reflectance colour.
    Mirror,
    /// Smooth dielectric interface: Fresnel-weighted reflection and refraction.
    Dielectric,
    /// Pure emitter: adds its emission, reflects nothing.
    Emissive,
    /// Cook-Torrance microfacet reflection (GGX or Beckmann, height-correlated Smith,
    /// conductor or dielectric Fresnel) over an optional Fresnel-weighted diffuse base.
    CookTorrance,
    /// Oren-Nayar rough diffuse reflection (the qualitative model of the 1994 paper).
    OrenNayar,
    /// A tabulated, isotropic BRDF `f(θi, θr)` read from an image.
    Tabulated,
    /// The glTF 2.0 metal/roughness model (glTF specification, Appendix B).
    Pbr,
}

/// The normal distribution of a microfacet material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MicrofacetDistribution {
    /// Trowbridge-Reitz (GGX).
    #[default]
    Ggx,
    /// Beckmann.
    Beckmann,
}

/// Which Fresnel reflectance a microfacet material uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FresnelModel {
    /// The exact Fresnel equations (dielectric or conductor).
    #[default]
    Exact,
    /// Schlick's approximation `F0 + (1 - F0)(1 - cos θ)^5` with `F0` from the exact
    /// equations at normal incidence.
    Schlick,
}

/// How a hit point is mapped to texture coordinates (see `docs/materials.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TextureMapping {
    /// Projection onto the tangent frame of the geometric normal, scaled by
    /// [`Material::texture_scale`] (for planes and polygons).
    #[default]
    Planar,
    /// Longitude/latitude of the geometric normal (for spheres).
    Spherical,
    /// The texture coordinates of a mesh's vertices, interpolated across each triangle
    /// (shapes without them read `(0, 0)`).
    Uv,
}

/// What a texture lookup does outside [0, 1] on one axis (glTF's sampler wrap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TextureWrap {
    /// Repeat the image.
    #[default]
    Repeat,
    /// Repeat it mirrored every other time.
    MirroredRepeat,
    /// Extend the edge texels.
    ClampToEdge,
}

/// How a texture's coordinates are made from a hit's texture coordinates: which set
/// of the mesh's it reads and the affine map applied to them (glTF's `texCoord` and
/// `KHR_texture_transform`). Planar and spherical mappings are transformed too, but
/// always read their one set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureTransform {
    /// The texture coordinate set of a UV-mapped texture: 0 ([`Mesh::uvs`]) or 1
    /// ([`Mesh::uvs1`]).
    pub set: u32,
    /// The affine map `(u, v) ↦ (rows[0]·(u, v, 1), rows[1]·(u, v, 1))`, finite.
    pub rows: [DVec3; 2],
}

impl TextureTransform {
    /// Set 0, untransformed.
    pub const IDENTITY: Self = Self {
        set: 0,
        rows: [DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)],
    };

    /// The transform of `KHR_texture_transform`: `T · R · S`, the scale first, then the
    /// rotation by `rotation` radians (counter-clockwise in UV space, which is clockwise
    /// on the image since `v` runs down), then the offset; the extension's matrix
    /// `R = [[cos, sin], [-sin, cos]]`.
    pub fn offset_rotation_scale(set: u32, offset: DVec2, rotation: f64, scale: DVec2) -> Self {
        let (sin, cos) = rotation.sin_cos();
        Self {
            set,
            rows: [
                DVec3::new(cos * scale.x, sin * scale.y, offset.x),
                DVec3::new(-sin * scale.x, cos * scale.y, offset.y),
            ],
        }
    }

    /// Whether the map moves coordinates in any way but by an offset: then whole
    /// repeats of the untransformed coordinates are not whole repeats of the texture.
    pub fn is_linear_identity(&self) -> bool {
        self.rows[0].truncate() == glam::DVec2::X && self.rows[1].truncate() == glam::DVec2::Y
    }

    /// The transformed coordinates of `uv`.
    pub fn apply(&self, uv: DVec2) -> DVec2 {
        let p = uv.extend(1.0);
        DVec2::new(self.rows[0].dot(p), self.rows[1].dot(p))
    }
}

impl Default for TextureTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// How a material's alpha (coverage) is used: glTF 2.0's `alphaMode` (§3.9.4, "Alpha
/// Coverage"). The alpha of a surface point is [`Material::alpha`] times the albedo
/// texture's texel alpha (the same lookup as the albedo's, bilinear on the image's own
/// alpha channel).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is fully opaque everywhere (glTF's `OPAQUE`).
    #[default]
    Opaque,
    /// glTF's `MASK`: the surface is fully opaque where its alpha is greater than or
    /// equal to `cutoff`, and does not exist for any ray (camera, reflected, refracted,
    /// path and shadow rays, the AOV pass) where it is below: both tracers skip such
    /// a candidate hit inside the traversal and look on for the next one.
    Mask {
        /// glTF's `alphaCutoff` (default 0.5), finite and not negative; 0 keeps
        /// every point.
        cutoff: f64,
    },
    /// glTF's `BLEND`: alpha is the fraction of light the surface stops (its
    /// coverage), `1 − alpha` passes through it unchanged and unbent. The Whitted
    /// integrator weights the hit's shading by alpha and continues the ray through
    /// the surface with weight `1 − alpha` (a branch like a dielectric's transmitted
    /// one, one bounce deeper); its shadow rays carry a transmittance of `1 − alpha`
    /// per surface they cross. The path integrator makes the choice stochastically
    /// (stochastic transparency, as Cycles and pbrt-v4 do): every ray, camera,
    /// bounce or shadow, passes each crossing with probability `1 − alpha`, decided
    /// inside the traversal by a hash of the ray's sample and the primitive (see
    /// `docs/models.md`).
    Blend,
}

/// A material. One flat record for all kinds (fields a kind does not use are zero),
/// which is exactly what the GPU receives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Which model shades this material.
    pub kind: MaterialKind,
    /// Diffuse albedo `kd` in [0, 1] (Lambert, Blinn-Phong).
    pub diffuse: DVec3,
    /// Specular colour `ks` in [0, 1] of the Blinn-Phong lobe.
    pub specular: DVec3,
    /// Blinn-Phong exponent `n` (≥ 0).
    pub shininess: f64,
    /// Mirror reflectance colour (Mirror).
    pub reflectance: DVec3,
    /// Index of refraction of the dielectric (Dielectric), > 0.
    pub ior: f64,
    /// Colour filter applied to refracted light (Dielectric).
    pub transmittance: DVec3,
    /// Index of refraction of a clear coat over a Lambert or Blinn-Phong base; 0 = no
    /// coat. With a coat, a Fresnel-weighted mirror reflection `F` is added and the
    /// base is scaled by `1 - F`.
    pub coat_ior: f64,
    /// Emitted radiance, added wherever a ray hits the surface.
    pub emission: DVec3,
    /// Perceptual roughness in [0, 1] (Cook-Torrance, PBR); the distribution's
    /// `alpha = max(roughness², MIN_ALPHA)`.
    pub roughness: f64,
    /// Microfacet normal distribution (Cook-Torrance; PBR is always GGX).
    pub distribution: MicrofacetDistribution,
    /// Exact or Schlick Fresnel (Cook-Torrance).
    pub fresnel: FresnelModel,
    /// Whether the Cook-Torrance Fresnel is a conductor's (`eta`, `k`) rather than a
    /// dielectric's (`ior`).
    pub conductor: bool,
    /// Real part of a conductor's complex index of refraction, per channel.
    pub eta: DVec3,
    /// Imaginary part (extinction coefficient) of a conductor's index, per channel.
    pub k: DVec3,
    /// glTF metalness in [0, 1] (PBR).
    pub metallic: f64,
    /// Oren-Nayar roughness: standard deviation of the facet slope angle, in radians.
    pub sigma: f64,
    /// Index into [`Scene::images`] of a texture multiplying `diffuse`, if any.
    pub albedo_texture: Option<u32>,
    /// How hit points map to texture coordinates.
    pub texture_mapping: TextureMapping,
    /// Scene units per texture repeat of the planar mapping (> 0).
    pub texture_scale: f64,
    /// Wrap modes of the albedo texture along `u` and `v`.
    pub texture_wrap: [TextureWrap; 2],
    /// The coordinates of the albedo texture.
    pub texture_transform: TextureTransform,
    /// Index into [`Scene::images`] of the tabulated BRDF (Tabulated).
    pub brdf_map: Option<u32>,
    /// Index into [`Scene::images`] of a texture of linear data whose green channel
    /// multiplies `roughness` and blue channel `metallic` (glTF 2.0's
    /// `metallicRoughnessTexture`, §3.9.2), looked up with the albedo texture's
    /// coordinates (`texture_mapping`), if any (PBR).
    pub metallic_roughness_texture: Option<u32>,
    /// Wrap modes of the metallic/roughness texture along `u` and `v`.
    pub metallic_roughness_wrap: [TextureWrap; 2],
    /// The coordinates of the metallic/roughness texture.
    pub metallic_roughness_transform: TextureTransform,
    /// Index into [`Scene::images`] of a colour texture multiplying `emission`
    /// (glTF's `emissiveTexture`, OBJ's `map_Ke`), looked up with the albedo
    /// texture's coordinates (`texture_mapping`) wherever emission is evaluated,
    /// if any.
    pub emission_texture: Option<u32>,
    /// Wrap modes of the emission texture along `u` and `v`.
    pub emission_wrap: [TextureWrap; 2],
    /// The coordinates of the emission texture.
    pub emission_transform: TextureTransform,
    /// Index into [`Scene::images`] of a tangent-space normal map (linear data, glTF's
    /// `normalTexture`): where a mesh has tangents, the shading normal becomes
    /// `normalize(T·x + B·y + N·z)` with `(x, y, z) = (2·texel − 1)·(scale, scale, 1)`.
    pub normal_texture: Option<u32>,
    /// Wrap modes of the normal map along `u` and `v`.
    pub normal_wrap: [TextureWrap; 2],
    /// The coordinates of the normal map.
    pub normal_transform: TextureTransform,
    /// glTF's `normalTexture.scale`: the map's x and y are multiplied by it (finite).
    pub normal_scale: f64,
    /// Whether flat shapes (polygons, triangles, meshes) of this material emit
    /// `emission` from both sides; by default only from the side their normal points
    /// to (spheres always emit on both). The path integrator's rule: Whitted shows
    /// emission on either side.
    pub two_sided: bool,
    /// Whether camera rays pass through the back faces of flat shapes (polygons,
    /// triangles, meshes) of this material: glTF's `doubleSided: false` (glTF 2.0
    /// §3.9.5, back-face culling). Secondary and shadow rays see both faces, so that a
    /// single-sided surface still reflects, refracts (a closed glass mesh) and casts
    /// shadows as a rasteriser's shadow map would. Default false: both faces show.
    pub cull_back_faces: bool,
    /// How alpha is used: opaque, masked or blended (see [`AlphaMode`]).
    pub alpha_mode: AlphaMode,
    /// The alpha factor in [0, 1] (glTF's `baseColorFactor`'s fourth component),
    /// multiplying the albedo texture's texel alpha; unused by [`AlphaMode::Opaque`].
    pub alpha: f64,
}

impl Material {
    /// A material of `kind` with every parameter zero except transmittance, `eta`,
    /// `texture_scale` and `alpha` (1), GGX and exact Fresnel, no images, opaque.
    pub fn blank(kind: MaterialKind) -> Self {
        Self {
            kind,
            diffuse: DVec3::ZERO,
            specular: DVec3::ZERO,
            shininess: 0.0,
            reflectance: DVec3::ZERO,
            ior: 1.0,
            transmittance: DVec3::ONE,
            coat_ior: 0.0,
            emission: DVec3::ZERO,
            roughness: 0.0,
            distribution: MicrofacetDistribution::Ggx,
            fresnel: FresnelModel::Exact,
            conductor: false,
            eta: DVec3::ONE,
            k: DVec3::ZERO,
            metallic: 0.0,
            sigma: 0.0,
            albedo_texture: None,
            texture_mapping: TextureMapping::Planar,
            texture_scale: 1.0,
            texture_wrap: [TextureWrap::Repeat; 2],
            texture_transform: TextureTransform::IDENTITY,
            brdf_map: None,
            metallic_roughness_texture: None,
            metallic_roughness_wrap: [TextureWrap::Repeat; 2],
            metallic_roughness_transform: TextureTransform::IDENTITY,
            emission_texture: None,
            emission_wrap: [TextureWrap::Repeat; 2],
            emission_transform: TextureTransform::IDENTITY,
            normal_texture: None,
            normal_wrap: [TextureWrap::Repeat; 2],
            normal_transform: TextureTransform::IDENTITY,
            normal_scale: 1.0,
            two_sided: false,
            cull_back_faces: false,
            alpha_mode: AlphaMode::Opaque,
            alpha: 1.0,
        }
    }

    /// Whether the material's alpha matters to the tracers: a mask whose cutoff is
    /// above 0 (a cutoff of 0 keeps every point), or blending.
    pub fn uses_alpha(&self) -> bool {
        match self.alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask { cutoff } => cutoff > 0.0,
            AlphaMode::Blend => true,
        }
    }

    /// A Lambertian material of the given albedo.
    pub fn lambert(albedo: DVec3) -> Self {
        Self {
            diffuse: albedo,
            ..Self::blank(MaterialKind::Lambert)
        }
    }
}

/// A light source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// An isotropic point light. Irradiance at distance `r` facing it is `I / r²`.
    Point {
        /// Position in scene units.
        position: DVec3,
        /// Radiant intensity per channel in W/sr (scalar intensity times colour).
        intensity: DVec3,
    },
    /// A point light whose intensity falls off towards the edge of a cone
    /// (`KHR_lights_punctual`'s spot light): full inside the inner cone, none outside
    /// the outer one, and between them the square of `(cos θ − cos_outer) / (cos_inner
    /// − cos_outer)` (the extension's reference implementation, smooth at both edges),
    /// θ being the angle from `direction` ([`crate::cpu::trace::spot_attenuation`]).
    Spot {
        /// Position in scene units.
        position: DVec3,
        /// Unit direction the cone points along (from the light into the scene).
        direction: DVec3,
        /// Radiant intensity per channel in W/sr along the cone's axis.
        intensity: DVec3,
        /// Cosine of the inner cone's half-angle, in (`cos_outer`, 1].
        cos_inner: f64,
        /// Cosine of the outer cone's half-angle, in [0, 1).
        cos_outer: f64,
    },
    /// A light at infinity (the sun).
    Directional {
        /// Unit direction in which the light travels (from the light into the scene).
        direction: DVec3,
        /// Irradiance per channel in W/m² on a surface facing the light.
        irradiance: DVec3,
    },
}

/// A geometric primitive with its material index.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius (> 0).
        radius: f64,
        /// Index into [`Scene::materials`].
        material: u32,
    },
    /// An infinite plane `normal · p = offset`.
    Plane {
        /// Unit normal.
        normal: DVec3,
        /// Signed distance of the plane from the origin along `normal`.
        offset: f64,
        /// Index into [`Scene::materials`].
        material: u32,
    },
    /// A planar polygon (convex or concave, ≥ 3 vertices), intersected as in the lecture:
    /// the plane first, then an even-odd inside test on the projected polygon.
    Polygon {
        /// Vertices in order, all on one plane.
        vertices: Vec<DVec3>,
        /// Index into [`Scene::materials`].
        material: u32,
    },
    /// A triangle.
    Triangle {
        /// The three corners; the geometric normal is `(v1-v0)×(v2-v0)`, normalized.
        vertices: [DVec3; 3],
        /// Index into [`Scene::materials`].
        material: u32,
    },
}

impl Shape {
    /// The shape's kind as the scene format writes it: `sphere`, `plane`, `polygon` or
    /// `triangle`.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Plane { .. } => "plane",
            Shape::Polygon { .. } => "polygon",
            Shape::Triangle { .. } => "triangle",
        }
    }

    /// The material index of this shape.
    pub fn material(&self) -> u32 {
        match self {
            Shape::Sphere { material, .. }
            | Shape::Plane { material, .. }
            | Shape::Polygon { material, .. }
            | Shape::Triangle { material, .. } => *material,
        }
    }
}

/// Largest accepted image width or height in pixels (a device may allow less; the GPU
/// backend checks its own limit).
pub const MAX_IMAGE_DIMENSION: u32 = 32_768;
/// Largest accepted number of pixels in one image (2^27: 2 GiB of linear RGBA f32).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 27;
/// Largest accepted samples per pixel.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 65_536;
/// Largest accepted bounce depth.
pub const MAX_DEPTH_LIMIT: u32 = 64;
/// Largest accepted bounce-stack capacity.
pub const MAX_STACK_SIZE: u32 = 128;
/// Largest accepted radiance (emission, background, ambient, environment texels times
/// their scale) and light strength (point intensity, directional irradiance, colour
/// included), per channel. The GPU sums samples and bounces in `f32`: at this value
/// [`MAX_SAMPLES_PER_PIXEL`] samples sum to 6.6e34, which leaves a factor of 5,000 for
/// bounces and path weights below the largest `f32` (3.4e38), where a 1e38 environment
/// at 4 samples per pixel overflowed.
pub const MAX_RADIANCE: f64 = 1e30;

/// Settings a user may override on the command line, on top of the scene file.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RenderOverrides {
    /// Image width in pixels.
    pub width: Option<u32>,
    /// Image height in pixels.
    pub height: Option<u32>,
    /// Samples per pixel.
    pub samples_per_pixel: Option<u32>,
    /// Maximum bounce depth. Without an explicit stack size, the stack grows with it.
    pub max_depth: Option<u32>,
    /// Bounce-stack capacity.
    pub stack_size: Option<u32>,
    /// Lighting space.
    pub lighting_space: Option<LightingSpace>,
    /// Ray-weight cutoff.
    pub min_ray_weight: Option<f64>,
    /// Light-transport algorithm.
    pub integrator: Option<Integrator>,
}

impl RenderSettings {
    /// Applies `overrides` and checks the result, returning a description of the first
    /// setting out of range.
    pub fn with_overrides(mut self, overrides: &RenderOverrides) -> Result<Self, SettingsError> {
        if let Some(width) = overrides.width {
            self.width = width;
        }
        if let Some(height) = overrides.height {
            self.height = height;
        }
        if let Some(spp) = overrides.samples_per_pixel {
            self.samples_per_pixel = spp;
        }
        if let Some(depth) = overrides.max_depth {
            self.max_depth = depth;
            if overrides.stack_size.is_none() {
                self.stack_size = self.stack_size.max(Self::sufficient_stack_size(depth));
            }
        }
        if let Some(stack) = overrides.stack_size {
            self.stack_size = stack;
        }
        if let Some(space) = overrides.lighting_space {
            self.lighting_space = space;
        }
        if let Some(cutoff) = overrides.min_ray_weight {
            self.min_ray_weight = cutoff;
        }
        if let Some(integrator) = overrides.integrator {
            self.integrator = integrator;
        }
        self.check()?;
        Ok(self)
    }

    /// Checks every setting against the accepted ranges.
    pub fn check(&self) -> Result<(), SettingsError> {
        for (name, value) in [("width", self.width), ("height", self.height)] {
            if value == 0 || value > MAX_IMAGE_DIMENSION {
                return Err(SettingsError::Dimension { name, value });
            }
        }
        let pixels = u64::from(self.width) * u64::from(self.height);
        if pixels > MAX_IMAGE_PIXELS {
            return Err(SettingsError::Pixels {
                width: self.width,
                height: self.height,
            });
        }
        if self.samples_per_pixel == 0 || self.samples_per_pixel > MAX_SAMPLES_PER_PIXEL {
            return Err(SettingsError::SamplesPerPixel(self.samples_per_pixel));
        }
        if self.max_depth > MAX_DEPTH_LIMIT {
            return Err(SettingsError::MaxDepth(self.max_depth));
        }
        if !(0.0..=1.0).contains(&self.min_ray_weight) {
            return Err(SettingsError::MinRayWeight(self.min_ray_weight));
        }
        if self.stack_size == 0 || self.stack_size > MAX_STACK_SIZE {
            return Err(SettingsError::StackSize(self.stack_size));
        }
        Ok(())
    }
}

/// A render setting out of its accepted range ([`RenderSettings::check`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SettingsError {
    /// The width or height is 0 or above [`MAX_IMAGE_DIMENSION`].
    #[error("{name} must be between 1 and {MAX_IMAGE_DIMENSION} pixels, got {value}")]
    Dimension {
        /// "width" or "height".
        name: &'static str,
        /// The value given.
        value: u32,
    },
    /// The image has more than [`MAX_IMAGE_PIXELS`] pixels.
    #[error(
        "{width}x{height} is {} pixels, more than the {MAX_IMAGE_PIXELS} accepted",
        u64::from(*.width) * u64::from(*.height)
    )]
    Pixels {
        /// The width.
        width: u32,
        /// The height.
        height: u32,
    },
    /// The samples per pixel are 0 or above [`MAX_SAMPLES_PER_PIXEL`].
    #[error("samples_per_pixel must be between 1 and {MAX_SAMPLES_PER_PIXEL}, got {0}")]
    SamplesPerPixel(u32),
    /// The depth is above [`MAX_DEPTH_LIMIT`].
    #[error("max_depth must be at most {MAX_DEPTH_LIMIT}, got {0}")]
    MaxDepth(u32),
    /// The ray-weight cutoff is outside [0, 1].
    #[error("min_ray_weight must be between 0 and 1, got {}", crate::echo::short(*.0))]
    MinRayWeight(f64),
    /// The stack size is 0 or above [`MAX_STACK_SIZE`].
    #[error("stack_size must be between 1 and {MAX_STACK_SIZE}, got {0}")]
    StackSize(u32),
}

impl Scene {
    /// The image files the scene was built from, each with what it is ("image" for
    /// textures and BRDF maps, "environment map"): the inputs besides the scene file
    /// that a render must never write over.
    pub fn image_files(&self) -> impl Iterator<Item = (&std::path::Path, &'static str)> {
        let images = self
            .images
            .iter()
            .map(|image| (image.path.as_path(), "image"));
        let environment = self
            .environment
            .map
            .iter()
            .map(|map| (map.image.path.as_path(), "environment map"));
        images.chain(environment)
    }

    /// The scene as the tracers shade it. In [`LightingSpace::Linear`] that is the scene
    /// itself. In [`LightingSpace::NaiveGamma`] every colour (albedos, reflectances,
    /// transmittances, emission, background and ambient radiance) is replaced by its
    /// sRGB-encoded value, the number an artist picking colours on screen would type,
    /// so that shading happens on gamma-encoded values as in the lecture's wrong
    /// example. Light intensities are physical quantities and stay as they are, as do
    /// images (textures, BRDF maps and the environment map).
    ///
    /// Borrowed in [`LightingSpace::Linear`]: no copy of the images is made.
    pub fn in_lighting_space(&self) -> std::borrow::Cow<'_, Scene> {
        if self.render.lighting_space == LightingSpace::NaiveGamma {
            let mut scene = self.clone();
            let encode = |c: DVec3| {
                DVec3::new(
                    crate::color::srgb_encode_extended(c.x),
                    crate::color::srgb_encode_extended(c.y),
                    crate::color::srgb_encode_extended(c.z),
                )
            };
            for m in &mut scene.materials {
                m.diffuse = encode(m.diffuse);
                m.specular = encode(m.specular);
                m.reflectance = encode(m.reflectance);
                m.transmittance = encode(m.transmittance);
                m.emission = encode(m.emission);
            }
            scene.environment.background = encode(scene.environment.background);
            scene.environment.ambient = encode(scene.environment.ambient);
            return std::borrow::Cow::Owned(scene);
        }
        std::borrow::Cow::Borrowed(self)
    }

    /// The indices of refraction of the dielectric spheres that contain the camera,
    /// outermost (largest) first: the medium the camera rays start in. Other closed
    /// dielectric shapes (polygon or triangle meshes) around the camera are not
    /// detected; rays then start in air.
    pub fn camera_medium(&self) -> Vec<f64> {
        media_around(self.camera.eye, &self.dielectric_spheres())
    }

    /// The spheres of dielectric material: the only shapes that can contain the
    /// camera ([`Scene::camera_medium`], [`media_around`]).
    pub fn dielectric_spheres(&self) -> Vec<DielectricSphere> {
        self.shapes
            .iter()
            .filter_map(|shape| match shape {
                Shape::Sphere {
                    center,
                    radius,
                    material,
                } => {
                    let material = self.materials.get(*material as usize)?;
                    (material.kind == MaterialKind::Dielectric).then_some(DielectricSphere {
                        center: *center,
                        radius: *radius,
                        ior: material.ior,
                    })
                }
                _ => None,
            })
            .collect()
    }

    /// Whether the display pass applies the sRGB curve (false in naive gamma mode,
    /// whose values are already "display" values).
    pub fn display_encodes_srgb(&self) -> bool {
        self.render.lighting_space == LightingSpace::Linear
    }
}

/// A sphere of dielectric material, as far as the camera's medium is concerned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricSphere {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
    /// Index of refraction of its material.
    pub ior: f64,
}

/// The indices of refraction of the dielectric spheres that contain `eye`, outermost
/// (largest) first: the medium stack camera rays start with. Nested spheres are
/// assumed not to intersect.
pub fn media_around(eye: DVec3, spheres: &[DielectricSphere]) -> Vec<f64> {
    let mut around: Vec<(f64, f64)> = spheres
        .iter()
        .filter(|s| {
            // Inside, decided relative to the anchor: a centre 1e20 away would leave
            // |eye - c| without the digits that say.
            let (anchor, normal) = super::sphere_anchor(s.center, s.radius);
            super::sphere_level(eye, anchor, normal, s.radius) < 0.0
        })
        .map(|s| (s.radius, s.ior))
        .collect();
    around.sort_by(|a, b| b.0.total_cmp(&a.0));
    around.into_iter().map(|(_, ior)| ior).collect()
}

/// The plane of a polygon and the axis dropped to project it for the inside test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonPlane {
    /// Unit normal (Newell's method; follows the vertex winding by the right-hand rule).
    pub normal: DVec3,
    /// `normal · p` for every point `p` of the plane.
    pub offset: f64,
    /// Index (0 = x, 1 = y, 2 = z) of the largest normal component: dropping that
    /// coordinate projects the polygon onto a coordinate plane with the least distortion.
    pub dropped_axis: u32,
}

/// The plane of a polygon by Newell's method (Sutherland, Sproull and Schumacker 1974;
/// see also Christer Ericson, "Real-Time Collision Detection", §12.3.1), robust for
/// concave polygons and nearly collinear vertices. Returns `None` when the polygon is
/// degenerate (zero area).
pub fn polygon_plane(vertices: &[DVec3]) -> Option<PolygonPlane> {
    let mut normal = DVec3::ZERO;
    let mut centroid = DVec3::ZERO;
    for (i, current) in vertices.iter().enumerate() {
        let next = vertices[(i + 1) % vertices.len()];
        normal.x += (current.y - next.y) * (current.z + next.z);
        normal.y += (current.z - next.z) * (current.x + next.x);
        normal.z += (current.x - next.x) * (current.y + next.y);
        centroid += *current;
    }
    let length = normal.length();
    if vertices.len() < 3 || length.is_nan() || length <= 0.0 || length.is_infinite() {
        return None;
    }
    let normal = normal / length;
    centroid /= vertices.len() as f64;
    let magnitude = normal.abs();
    let dropped_axis = if magnitude.x >= magnitude.y && magnitude.x >= magnitude.z {
        0
    } else if magnitude.y >= magnitude.z {
        1
    } else {
        2
    };
    Some(PolygonPlane {
        normal,
        offset: normal.dot(centroid),
        dropped_axis,
    })
}

/// The two coordinates of `point` that remain when `dropped_axis` (0 = x, 1 = y,
/// 2 = z) is removed: the projection of a polygon's inside test
/// ([`PolygonPlane::dropped_axis`]).
pub fn project_to_plane(point: DVec3, dropped_axis: u32) -> (f64, f64) {
    match dropped_axis {
        0 => (point.y, point.z),
        1 => (point.z, point.x),
        _ => (point.x, point.y),
    }
}
