//! The validated, in-memory scene: what both backends render.
//!
//! Everything here has been checked by [`crate::scene::load_scene`] (finite numbers,
//! positive sizes, resolved material names, planar polygons, ...), so the tracers can
//! trust it. Positions are in scene units (any length unit, used consistently), colours
//! are linear RGB, and the CPU reference works on these `f64` values directly while the
//! GPU backend rounds them to `f32` on upload.

use glam::DVec3;

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
}

/// How the image is sampled and how deep rays recurse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
}

impl RenderSettings {
    /// The stack size that guarantees no branch is ever dropped for `max_depth`.
    pub fn sufficient_stack_size(max_depth: u32) -> u32 {
        max_depth + 1
    }
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

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Centre of projection.
    pub eye: DVec3,
    /// A point the camera looks at (distinct from `eye`).
    pub look_at: DVec3,
    /// Approximate up direction (non-zero, not parallel to the view direction).
    pub up: DVec3,
    /// Full vertical field of view in degrees, in (0, 180).
    pub fov_y_degrees: f64,
}

/// Light that does not come from a light source.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Environment {
    /// Radiance (W/(sr·m²) per channel) carried by rays that hit nothing.
    pub background: DVec3,
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
}

impl Material {
    /// A material of `kind` with every parameter zero except transmittance = 1.
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
