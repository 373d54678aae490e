//! The scene file as written: serde structures mirroring the TOML, before any checking.
//!
//! Items whose fields depend on their `type` (materials, lights, objects) are flat
//! structures with every field optional, so that the validator can say exactly which
//! field a given type is missing or does not take. Items are wrapped in
//! [`toml::Spanned`] so errors can point at where each one begins.

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use toml::Spanned;

/// A 3-vector as written: `[x, y, z]`.
pub type RawVec3 = [f64; 3];

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    /// `[render]`, optional.
    pub render: Option<Spanned<RawRender>>,
    /// `[camera]`, required (checked by the validator for a clearer message).
    pub camera: Option<Spanned<RawCamera>>,
    /// `[environment]`, optional.
    pub environment: Option<Spanned<RawEnvironment>>,
    /// `[materials.NAME]` tables, sorted by name.
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<RawMaterial>>,
    /// `[[lights]]`, in file order.
    #[serde(default)]
    pub lights: Vec<Spanned<RawLight>>,
    /// `[[objects]]`, in file order.
    #[serde(default)]
    pub objects: Vec<Spanned<RawObject>>,
    /// `[animation]`, optional: a camera path.
    pub animation: Option<Spanned<RawAnimation>>,
}

/// `[animation]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAnimation {
    pub fps: Option<f64>,
    pub frames: Option<u32>,
    pub interpolation: Option<String>,
    #[serde(default)]
    pub keyframes: Vec<Spanned<RawKeyframe>>,
}

/// `[[animation.keyframes]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawKeyframe {
    pub time: Option<f64>,
    pub eye: Option<RawVec3>,
    pub look_at: Option<RawVec3>,
}

/// `[render]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRender {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples_per_pixel: Option<u32>,
    pub max_depth: Option<u32>,
    pub stack_size: Option<u32>,
    pub lighting: Option<RawLighting>,
    pub min_ray_weight: Option<f64>,
    pub integrator: Option<RawIntegrator>,
    pub texture_filtering: Option<RawTextureFiltering>,
}

/// `render.texture_filtering`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RawTextureFiltering {
    None,
    Trilinear,
    Anisotropic,
}

/// `render.integrator`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RawIntegrator {
    Whitted,
    Path,
}

/// `render.lighting`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RawLighting {
    Linear,
    NaiveGamma,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCamera {
    pub eye: Option<RawVec3>,
    pub look_at: Option<RawVec3>,
    pub up: Option<RawVec3>,
    pub fov_y_degrees: Option<f64>,
    pub orthographic_half_height: Option<f64>,
    pub aperture_radius: Option<f64>,
    pub focus_distance: Option<f64>,
}

/// `[environment]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEnvironment {
    pub background: Option<RawColor>,
    pub ambient: Option<RawColor>,
    pub map: Option<String>,
    pub rotation: Option<f64>,
    pub scale: Option<RawColor>,
}

/// `[materials.NAME]`: the union of every material type's fields.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMaterial {
    #[serde(rename = "type")]
    pub kind: Option<String>,
    pub albedo: Option<RawColor>,
    pub diffuse: Option<RawColor>,
    pub specular: Option<RawColor>,
    pub shininess: Option<f64>,
    pub reflectance: Option<RawColor>,
    pub ior: Option<f64>,
    pub transmittance: Option<RawColor>,
    pub radiance: Option<RawColor>,
    pub coat_ior: Option<f64>,
    pub emission: Option<RawColor>,
    pub roughness: Option<f64>,
    pub distribution: Option<String>,
    pub fresnel: Option<String>,
    pub conductor: Option<String>,
    pub eta: Option<RawColor>,
    pub k: Option<RawColor>,
    pub base_color: Option<RawColor>,
    pub metallic: Option<f64>,
    pub sigma_degrees: Option<f64>,
    pub albedo_texture: Option<String>,
    pub texture_mapping: Option<String>,
    pub texture_scale: Option<f64>,
    pub brdf_map: Option<String>,
    pub two_sided: Option<bool>,
}

impl RawMaterial {
    /// Names of the fields present, apart from `type`.
    pub fn given_fields(&self) -> Vec<&'static str> {
        given([
            ("albedo", self.albedo.is_some()),
            ("diffuse", self.diffuse.is_some()),
            ("specular", self.specular.is_some()),
            ("shininess", self.shininess.is_some()),
            ("reflectance", self.reflectance.is_some()),
            ("ior", self.ior.is_some()),
            ("transmittance", self.transmittance.is_some()),
            ("radiance", self.radiance.is_some()),
            ("coat_ior", self.coat_ior.is_some()),
            ("emission", self.emission.is_some()),
            ("roughness", self.roughness.is_some()),
            ("distribution", self.distribution.is_some()),
            ("fresnel", self.fresnel.is_some()),
            ("conductor", self.conductor.is_some()),
            ("eta", self.eta.is_some()),
            ("k", self.k.is_some()),
            ("base_color", self.base_color.is_some()),
            ("metallic", self.metallic.is_some()),
            ("sigma_degrees", self.sigma_degrees.is_some()),
            ("albedo_texture", self.albedo_texture.is_some()),
            ("texture_mapping", self.texture_mapping.is_some()),
            ("texture_scale", self.texture_scale.is_some()),
            ("brdf_map", self.brdf_map.is_some()),
        ])
    }
}

/// `[[lights]]`: the union of every light type's fields.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLight {
    #[serde(rename = "type")]
    pub kind: Option<String>,
    pub position: Option<RawVec3>,
    pub intensity: Option<f64>,
    pub direction: Option<RawVec3>,
    pub irradiance: Option<f64>,
    pub color: Option<RawColor>,
    pub inner_cone_degrees: Option<f64>,
    pub outer_cone_degrees: Option<f64>,
}

impl RawLight {
    /// Names of the fields present, apart from `type`.
    pub fn given_fields(&self) -> Vec<&'static str> {
        given([
            ("position", self.position.is_some()),
            ("intensity", self.intensity.is_some()),
            ("direction", self.direction.is_some()),
            ("irradiance", self.irradiance.is_some()),
            ("color", self.color.is_some()),
            ("inner_cone_degrees", self.inner_cone_degrees.is_some()),
            ("outer_cone_degrees", self.outer_cone_degrees.is_some()),
        ])
    }
}

/// `[[objects]]`: the union of every shape type's fields.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObject {
    #[serde(rename = "type")]
    pub kind: Option<String>,
    pub center: Option<RawVec3>,
    pub radius: Option<f64>,
    pub point: Option<RawVec3>,
    pub normal: Option<RawVec3>,
    pub vertices: Option<Vec<RawVec3>>,
    pub material: Option<String>,
    /// A model object's file (OBJ, glTF or GLB), relative to the scene file.
    pub file: Option<String>,
    /// A model's translation.
    pub translate: Option<RawVec3>,
    /// A model's rotation in degrees about x, y, z.
    pub rotate: Option<RawVec3>,
    /// A model's scale: one number (uniform) or one per axis (the colour syntax).
    pub scale: Option<RawColor>,
    /// Whether a model shades with its vertex normals (default true).
    pub smooth: Option<bool>,
}

impl RawObject {
    /// Names of the fields present, apart from `type`.
    pub fn given_fields(&self) -> Vec<&'static str> {
        given([
            ("center", self.center.is_some()),
            ("radius", self.radius.is_some()),
            ("point", self.point.is_some()),
            ("normal", self.normal.is_some()),
            ("vertices", self.vertices.is_some()),
            ("material", self.material.is_some()),
            ("file", self.file.is_some()),
            ("translate", self.translate.is_some()),
            ("rotate", self.rotate.is_some()),
            ("scale", self.scale.is_some()),
            ("smooth", self.smooth.is_some()),
        ])
    }
}

fn given<const N: usize>(fields: [(&'static str, bool); N]) -> Vec<&'static str> {
    fields
        .into_iter()
        .filter_map(|(name, present)| present.then_some(name))
        .collect()
}

/// A colour as written: one number (grey) or `[r, g, b]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RawColor {
    /// `0.5` means `[0.5, 0.5, 0.5]`.
    Grey(f64),
    /// `[r, g, b]`.
    Rgb([f64; 3]),
}

impl<'de> Deserialize<'de> for RawColor {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ColorVisitor)
    }
}

struct ColorVisitor;

impl<'de> Visitor<'de> for ColorVisitor {
    type Value = RawColor;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a colour: a number (grey) or an [r, g, b] array of numbers")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawColor, E> {
        Ok(RawColor::Grey(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawColor, E> {
        Ok(RawColor::Grey(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawColor, E> {
        Ok(RawColor::Grey(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawColor, A::Error> {
        let mut rgb = [0.0; 3];
        for (i, channel) in rgb.iter_mut().enumerate() {
            *channel = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(i, &self))?;
        }
        let mut len = 3;
        while seq.next_element::<de::IgnoredAny>()?.is_some() {
            len += 1;
        }
        if len != 3 {
            return Err(de::Error::invalid_length(len, &self));
        }
        Ok(RawColor::Rgb(rgb))
    }
}
