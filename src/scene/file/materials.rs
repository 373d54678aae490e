//! `[materials.NAME]` tables.

use std::path::Path;

use glam::DVec3;
use toml::Spanned;

use super::LoadOptions;
use super::budget::{LoadBudget, load_scene_image};
use super::check::{ColourRange, Item, Source};
use super::paths::confined_path;
use super::raw::RawMaterial;
use crate::echo::{echo, echo_path, short, short3};
use crate::scene::{
    FresnelModel, Image, Material, MaterialKind, MicrofacetDistribution, SceneError, TextureMapping,
};

/// Largest accepted Blinn-Phong exponent.
const MAX_SHININESS: f64 = 1e6;

const LAMBERT_FIELDS: &[&str] = &[
    "albedo",
    "coat_ior",
    "emission",
    "albedo_texture",
    "texture_mapping",
    "texture_scale",
];
const BLINN_PHONG_FIELDS: &[&str] = &["diffuse", "specular", "shininess", "coat_ior", "emission"];
const MIRROR_FIELDS: &[&str] = &["reflectance", "emission"];
const DIELECTRIC_FIELDS: &[&str] = &["ior", "transmittance", "emission"];
const EMISSIVE_FIELDS: &[&str] = &["radiance"];
const COOK_TORRANCE_FIELDS: &[&str] = &[
    "roughness",
    "distribution",
    "fresnel",
    "conductor",
    "eta",
    "k",
    "ior",
    "diffuse",
    "albedo_texture",
    "texture_mapping",
    "texture_scale",
    "emission",
];
const OREN_NAYAR_FIELDS: &[&str] = &[
    "albedo",
    "sigma_degrees",
    "albedo_texture",
    "texture_mapping",
    "texture_scale",
    "emission",
];
const PBR_FIELDS: &[&str] = &[
    "base_color",
    "metallic",
    "roughness",
    "albedo_texture",
    "texture_mapping",
    "texture_scale",
    "emission",
];
const TABULATED_FIELDS: &[&str] = &["brdf_map", "emission"];
const KINDS: &str =
    "lambert, blinn_phong, mirror, dielectric, emissive, cook_torrance, oren_nayar, pbr, tabulated";

/// A conductor's complex index of refraction `(eta, k)` at the R, G and B wavelengths.
///
/// The values are the RGB table of the LabPBR Material Standard ("hardcoded metals",
/// <https://shaderlabs.org/wiki/LabPBR_Material_Standard>), measured `n` and `k` at
/// red, green and blue wavelengths (refractiveindex.info data); their normal-incidence
/// reflectances agree with Real-Time Rendering, 4th ed., Table 9.2 (see
/// `tests/integration/bxdf_plausibility.rs`).
pub const CONDUCTOR_PRESETS: &[(&str, [f64; 3], [f64; 3])] = &[
    ("gold", [0.18299, 0.42108, 1.3734], [3.4242, 2.3459, 1.7704]),
    (
        "silver",
        [0.15943, 0.14512, 0.13547],
        [3.9291, 3.1900, 2.3808],
    ),
    (
        "copper",
        [0.27105, 0.67693, 1.3164],
        [3.6092, 2.6248, 2.2921],
    ),
    (
        "aluminium",
        [1.3456, 0.96521, 0.61722],
        [7.4746, 6.3995, 5.3031],
    ),
];

/// Most distinct image files one scene may load: each may be 2048x2048 RGBA `f32`
/// (64 MiB), and the GPU holds them all as layers of one texture array.
pub const MAX_SCENE_IMAGES: usize = 16;

/// What a material uses an image for; the same file used both ways is loaded twice,
/// because only an albedo texture is clamped to [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ImageRole {
    /// `albedo_texture`: a reflectance in [0, 1] (larger texels are clamped).
    Albedo,
    /// `brdf_map`: π·f, any value >= 0.
    BrdfMap,
}

/// The images a scene's materials load, and where relative paths start.
pub struct ImageTable<'a> {
    /// The directory of the scene file.
    base: &'a Path,
    /// Confinement, and who hears about clamped texels.
    options: &'a LoadOptions<'a>,
    /// Images loaded so far, indexed by `Material::albedo_texture` / `brdf_map`, with
    /// what each is used for.
    images: Vec<(Image, ImageRole)>,
    /// The memory the load holds so far (the environment map's first), against the cap.
    budget: &'a mut LoadBudget,
}

impl<'a> ImageTable<'a> {
    /// An empty table for a scene file in directory `base`, its images charged to
    /// `budget`.
    pub fn new(base: &'a Path, options: &'a LoadOptions<'a>, budget: &'a mut LoadBudget) -> Self {
        Self {
            base,
            options,
            images: Vec::new(),
            budget,
        }
    }

    /// The bytes the cap leaves for the rest of the load, if there is a cap.
    pub fn bytes_left(&self) -> Option<u64> {
        self.budget.left()
    }

    /// The images, in index order.
    pub fn into_images(self) -> Vec<Image> {
        self.images.into_iter().map(|(image, _)| image).collect()
    }

    /// The index of `file` (relative to the scene file) in the table, loading it on
    /// first use: materials naming the same file for the same role share one image.
    fn index_of(
        &mut self,
        item: &Item<'_>,
        field: &str,
        file: &str,
        role: ImageRole,
    ) -> Result<u32, SceneError> {
        let path = if self.options.sandbox {
            confined_path(self.base, file).map_err(|e| item.fail(format_args!("{field} {e}")))?
        } else {
            self.base.join(file)
        };
        if let Some(index) = self
            .images
            .iter()
            .position(|(image, r)| image.path == path && *r == role)
        {
            return Ok(index as u32);
        }
        if self.images.len() >= MAX_SCENE_IMAGES {
            return Err(item.fail(format_args!(
                "{field} `{}`: a scene may use at most {MAX_SCENE_IMAGES} different image files",
                echo_path(Path::new(file))
            )));
        }
        let fail = |message: String| {
            item.fail(format_args!(
                "{field} `{}` ({}): {message}",
                echo_path(Path::new(file)),
                echo_path(&path)
            ))
        };
        let mut image = load_scene_image(
            item,
            field,
            (file, &path),
            self.base,
            self.options,
            self.budget,
        )?;
        if let Some(((x, y), channel, value)) = negative_texel(&image) {
            let why = match role {
                ImageRole::Albedo => "a reflectance cannot be negative",
                ImageRole::BrdfMap => "a BRDF (π·f) cannot be negative",
            };
            return Err(fail(format!(
                "texel ({x}, {y}) has {channel} = {}; texels must be >= 0 ({why})",
                short(value)
            )));
        }
        if role == ImageRole::Albedo
            && let Some(clamped) = clamp_albedo(&mut image)
            && let Some(warn) = self.options.warning
        {
            warn(&item.warning(format_args!(
                "{field} `{}` ({}): {} texels have a channel above 1 (largest {} at \
                 ({}, {})); clamped to 1, as a surface reflects at most the light it receives",
                echo_path(Path::new(file)),
                echo_path(&path),
                clamped.count,
                short(clamped.largest),
                clamped.at.0,
                clamped.at.1
            )));
        }
        self.images.push((image, role));
        Ok(self.images.len() as u32 - 1)
    }
}

/// The first texel with a negative colour channel: its position, channel and value.
/// Alpha is not used by any material and is not checked.
fn negative_texel(image: &Image) -> Option<((u32, u32), &'static str, f32)> {
    image.texels.iter().enumerate().find_map(|(i, texel)| {
        let (channel, value) = ["r", "g", "b"]
            .into_iter()
            .zip(texel.iter().copied())
            .find(|&(_, v)| v < 0.0)?;
        let i = i as u32;
        Some(((i % image.width, i / image.width), channel, value))
    })
}

/// What [`clamp_albedo`] changed.
struct Clamped {
    /// Texels with a channel above 1.
    count: usize,
    /// The largest channel value found.
    largest: f32,
    /// Where it was.
    at: (u32, u32),
}

/// Clamps every colour channel above 1 to 1; `None` when none was.
fn clamp_albedo(image: &mut Image) -> Option<Clamped> {
    let mut clamped: Option<Clamped> = None;
    let width = image.width;
    for (i, texel) in image.texels.iter_mut().enumerate() {
        let largest = texel[..3].iter().copied().fold(f32::MIN, f32::max);
        if largest <= 1.0 {
            continue;
        }
        let i = i as u32;
        let entry = clamped.get_or_insert(Clamped {
            count: 0,
            largest,
            at: (i % width, i / width),
        });
        entry.count += 1;
        if largest > entry.largest {
            entry.largest = largest;
            entry.at = (i % width, i / width);
        }
        for channel in &mut texel[..3] {
            *channel = channel.min(1.0);
        }
    }
    clamped
}

/// One material, checked and turned into the flat model record.
pub fn material(
    source: &Source<'_>,
    name: &str,
    raw: Spanned<RawMaterial>,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    let span = raw.span();
    let raw = raw.into_inner();
    let name = echo(name);
    let untyped = source.item(format!("materials.{name}"), Some(span.clone()));
    let kind = untyped.require("type", raw.kind.clone())?;
    let item = source.item(format!("materials.{name} ({})", echo(&kind)), Some(span));
    let given = raw.given_fields();
    let mut material = match kind.as_str() {
        "lambert" => {
            item.only_fields(&kind, LAMBERT_FIELDS, &given)?;
            lambert(&item, &raw, images)
        }
        "blinn_phong" => {
            item.only_fields(&kind, BLINN_PHONG_FIELDS, &given)?;
            blinn_phong(&item, &raw)
        }
        "mirror" => {
            item.only_fields(&kind, MIRROR_FIELDS, &given)?;
            mirror(&item, &raw)
        }
        "dielectric" => {
            item.only_fields(&kind, DIELECTRIC_FIELDS, &given)?;
            dielectric(&item, &raw)
        }
        "emissive" => {
            item.only_fields(&kind, EMISSIVE_FIELDS, &given)?;
            emissive(&item, &raw)
        }
        "cook_torrance" => {
            item.only_fields(&kind, COOK_TORRANCE_FIELDS, &given)?;
            cook_torrance(&item, &raw, images)
        }
        "oren_nayar" => {
            item.only_fields(&kind, OREN_NAYAR_FIELDS, &given)?;
            oren_nayar(&item, &raw, images)
        }
        "pbr" => {
            item.only_fields(&kind, PBR_FIELDS, &given)?;
            pbr(&item, &raw, images)
        }
        "tabulated" => {
            item.only_fields(&kind, TABULATED_FIELDS, &given)?;
            tabulated(&item, &raw, images)
        }
        other => Err(untyped.fail(format_args!(
            "unknown material type `{}` (expected one of: {KINDS})",
            echo(other)
        ))),
    }?;
    if let Some(two_sided) = raw.two_sided {
        if two_sided && material.emission == DVec3::ZERO {
            return Err(item.fail(format_args!(
                "two_sided = true applies to emission, and this material emits nothing \
                 (give it `emission`, or `radiance` for an emissive one)"
            )));
        }
        material.two_sided = two_sided;
    }
    Ok(material)
}

fn lambert(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    let material = Material {
        diffuse: albedo(item, "albedo", raw.albedo, raw)?,
        coat_ior: coat_ior(item, raw.coat_ior)?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Lambert)
    };
    texture(item, raw, images, material)
}

/// A colour that a texture multiplies: required without `albedo_texture`, 1 with one.
fn albedo(
    item: &Item<'_>,
    field: &str,
    value: Option<super::raw::RawColor>,
    raw: &RawMaterial,
) -> Result<DVec3, SceneError> {
    match (value, raw.albedo_texture.is_some()) {
        (Some(colour), _) => item.colour(field, colour, ColourRange::Fraction),
        (None, true) => Ok(DVec3::ONE),
        (None, false) => Err(item.fail(format_args!(
            "missing required field `{field}` (or `albedo_texture`)"
        ))),
    }
}

/// Roughness in [0, 1].
fn roughness(item: &Item<'_>, value: f64) -> Result<f64, SceneError> {
    let value = item.number("roughness", value)?;
    if !(0.0..=1.0).contains(&value) {
        return Err(item.fail(format_args!(
            "roughness must be in [0, 1], got {}",
            short(value)
        )));
    }
    Ok(value)
}

fn cook_torrance(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    let roughness = roughness(item, item.require("roughness", raw.roughness)?)?;
    let distribution = match raw.distribution.as_deref() {
        None | Some("ggx") => MicrofacetDistribution::Ggx,
        Some("beckmann") => MicrofacetDistribution::Beckmann,
        Some(other) => {
            return Err(item.fail(format_args!(
                "unknown distribution `{}` (expected ggx or beckmann)",
                echo(other)
            )));
        }
    };
    let fresnel = match raw.fresnel.as_deref() {
        None | Some("exact") => FresnelModel::Exact,
        Some("schlick") => FresnelModel::Schlick,
        Some(other) => {
            return Err(item.fail(format_args!(
                "unknown fresnel `{}` (expected exact or schlick)",
                echo(other)
            )));
        }
    };
    let mut material = Material {
        roughness,
        distribution,
        fresnel,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::CookTorrance)
    };
    let explicit = raw.eta.is_some() || raw.k.is_some();
    match (&raw.conductor, explicit, raw.ior) {
        (Some(name), false, None) => {
            let Some((_, eta, k)) = CONDUCTOR_PRESETS.iter().find(|(n, _, _)| n == name) else {
                let names: Vec<&str> = CONDUCTOR_PRESETS.iter().map(|p| p.0).collect();
                return Err(item.fail(format_args!(
                    "unknown conductor `{}` (expected one of: {})",
                    echo(name),
                    names.join(", ")
                )));
            };
            material.conductor = true;
            material.eta = DVec3::from_array(*eta);
            material.k = DVec3::from_array(*k);
        }
        (None, true, None) => {
            let eta = item.require("eta", raw.eta)?;
            let k = item.require("k", raw.k)?;
            material.conductor = true;
            material.eta = item.colour("eta", eta, ColourRange::Radiance)?;
            material.k = item.colour("k", k, ColourRange::Radiance)?;
            if material.eta.min_element() <= 0.0 {
                return Err(item.fail(format_args!(
                    "every channel of eta must be > 0, got {}",
                    short3(material.eta)
                )));
            }
        }
        (None, false, Some(ior)) => {
            let ior = item.number("ior", ior)?;
            if ior <= 0.0 {
                return Err(item.fail(format_args!("ior must be > 0, got {}", short(ior))));
            }
            material.ior = ior;
            material.diffuse = match raw.diffuse {
                Some(colour) => item.colour("diffuse", colour, ColourRange::Fraction)?,
                None if raw.albedo_texture.is_some() => DVec3::ONE,
                None => DVec3::ZERO,
            };
            return texture(item, raw, images, material);
        }
        _ => {
            return Err(item.fail(
                "give exactly one Fresnel source: `conductor` (a preset), `eta` and `k` \
                 (a conductor), or `ior` (a dielectric)",
            ));
        }
    }
    if raw.diffuse.is_some() || raw.albedo_texture.is_some() {
        return Err(
            item.fail("a conductor has no diffuse base: `diffuse` and `albedo_texture` need `ior`")
        );
    }
    Ok(material)
}

fn oren_nayar(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    let sigma = item.non_negative(
        "sigma_degrees",
        item.require("sigma_degrees", raw.sigma_degrees)?,
    )?;
    if sigma > 90.0 {
        return Err(item.fail(format_args!(
            "sigma_degrees must be in [0, 90], got {}",
            short(sigma)
        )));
    }
    let material = Material {
        diffuse: albedo(item, "albedo", raw.albedo, raw)?,
        sigma: sigma.to_radians(),
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::OrenNayar)
    };
    texture(item, raw, images, material)
}

fn pbr(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    // glTF 2.0 defaults: metallicFactor = roughnessFactor = 1.
    let metallic = item.non_negative("metallic", raw.metallic.unwrap_or(1.0))?;
    if metallic > 1.0 {
        return Err(item.fail(format_args!(
            "metallic must be in [0, 1], got {}",
            short(metallic)
        )));
    }
    let material = Material {
        diffuse: albedo(item, "base_color", raw.base_color, raw)?,
        metallic,
        roughness: roughness(item, raw.roughness.unwrap_or(1.0))?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Pbr)
    };
    texture(item, raw, images, material)
}

fn tabulated(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
) -> Result<Material, SceneError> {
    let file = item.require("brdf_map", raw.brdf_map.as_deref())?;
    let index = images.index_of(item, "brdf_map", file, ImageRole::BrdfMap)?;
    let image = &images.images[index as usize].0;
    if image.width != image.height || image.width < 2 {
        return Err(item.fail(format_args!(
            "brdf_map `{}` ({}): the map must be square and at least 2x2 (θi across, \
             θr down), got {}x{}",
            echo_path(Path::new(file)),
            echo_path(&image.path),
            image.width,
            image.height
        )));
    }
    Ok(Material {
        brdf_map: Some(index),
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Tabulated)
    })
}

/// The optional albedo texture and its mapping.
fn texture(
    item: &Item<'_>,
    raw: &RawMaterial,
    images: &mut ImageTable<'_>,
    mut material: Material,
) -> Result<Material, SceneError> {
    let Some(file) = raw.albedo_texture.as_deref() else {
        if raw.texture_mapping.is_some() || raw.texture_scale.is_some() {
            return Err(item.fail("texture_mapping and texture_scale need an albedo_texture"));
        }
        return Ok(material);
    };
    material.texture_mapping = match raw.texture_mapping.as_deref() {
        None | Some("planar") => TextureMapping::Planar,
        Some("spherical") => TextureMapping::Spherical,
        Some(other) => {
            return Err(item.fail(format_args!(
                "unknown texture_mapping `{}` (expected planar or spherical)",
                echo(other)
            )));
        }
    };
    if let Some(scale) = raw.texture_scale {
        let scale = item.number("texture_scale", scale)?;
        if scale <= 0.0 {
            return Err(item.fail(format_args!(
                "texture_scale must be > 0, got {}",
                short(scale)
            )));
        }
        material.texture_scale = scale;
    }
    material.albedo_texture =
        Some(images.index_of(item, "albedo_texture", file, ImageRole::Albedo)?);
    Ok(material)
}

fn blinn_phong(item: &Item<'_>, raw: &RawMaterial) -> Result<Material, SceneError> {
    let diffuse = item.colour(
        "diffuse",
        item.require("diffuse", raw.diffuse)?,
        ColourRange::Fraction,
    )?;
    let specular = item.colour(
        "specular",
        item.require("specular", raw.specular)?,
        ColourRange::Fraction,
    )?;
    check_energy(item, diffuse, specular)?;
    let shininess = item.non_negative("shininess", item.require("shininess", raw.shininess)?)?;
    if shininess > MAX_SHININESS {
        return Err(item.fail(format_args!(
            "shininess must be at most {MAX_SHININESS:e}, got {}",
            short(shininess)
        )));
    }
    Ok(Material {
        diffuse,
        specular,
        shininess,
        coat_ior: coat_ior(item, raw.coat_ior)?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::BlinnPhong)
    })
}

/// Blinn-Phong reflects at most all incoming light: `diffuse + specular <= 1` per channel.
fn check_energy(item: &Item<'_>, diffuse: DVec3, specular: DVec3) -> Result<(), SceneError> {
    let sum = diffuse + specular;
    for (channel, total) in ["r", "g", "b"].iter().zip(sum.to_array()) {
        if total > 1.0 {
            return Err(item.fail(format_args!(
                "diffuse.{channel} + specular.{channel} = {total} exceeds 1; \
                 the material would reflect more light than it receives"
            )));
        }
    }
    Ok(())
}

fn mirror(item: &Item<'_>, raw: &RawMaterial) -> Result<Material, SceneError> {
    Ok(Material {
        reflectance: item.colour_or(
            "reflectance",
            raw.reflectance,
            ColourRange::Fraction,
            DVec3::ONE,
        )?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Mirror)
    })
}

fn dielectric(item: &Item<'_>, raw: &RawMaterial) -> Result<Material, SceneError> {
    let ior = item.number("ior", item.require("ior", raw.ior)?)?;
    if ior <= 0.0 {
        return Err(item.fail(format_args!("ior must be > 0, got {}", short(ior))));
    }
    Ok(Material {
        ior,
        transmittance: item.colour_or(
            "transmittance",
            raw.transmittance,
            ColourRange::Fraction,
            DVec3::ONE,
        )?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Dielectric)
    })
}

fn emissive(item: &Item<'_>, raw: &RawMaterial) -> Result<Material, SceneError> {
    let radiance = item.require("radiance", raw.radiance)?;
    Ok(Material {
        emission: item.colour("radiance", radiance, ColourRange::Radiance)?,
        ..Material::blank(MaterialKind::Emissive)
    })
}

/// The optional clear-coat index: absent means no coat (0); given, it must be >= 1.
fn coat_ior(item: &Item<'_>, value: Option<f64>) -> Result<f64, SceneError> {
    let Some(value) = value else { return Ok(0.0) };
    let value = item.number("coat_ior", value)?;
    if value < 1.0 {
        return Err(item.fail(format_args!(
            "coat_ior must be >= 1 (1 is an invisible coat; leave it out for none), got {}",
            short(value)
        )));
    }
    Ok(value)
}

fn emission(item: &Item<'_>, raw: &RawMaterial) -> Result<DVec3, SceneError> {
    item.colour_or("emission", raw.emission, ColourRange::Radiance, DVec3::ZERO)
}
