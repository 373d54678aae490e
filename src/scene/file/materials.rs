//! `[materials.NAME]` tables.

use glam::DVec3;
use toml::Spanned;

use super::check::{ColourRange, Item, Source};
use super::raw::RawMaterial;
use crate::scene::{Material, MaterialKind, SceneError};

/// Largest accepted Blinn-Phong exponent.
const MAX_SHININESS: f64 = 1e6;

const LAMBERT_FIELDS: &[&str] = &["albedo", "coat_ior", "emission"];
const BLINN_PHONG_FIELDS: &[&str] = &["diffuse", "specular", "shininess", "coat_ior", "emission"];
const MIRROR_FIELDS: &[&str] = &["reflectance", "emission"];
const DIELECTRIC_FIELDS: &[&str] = &["ior", "transmittance", "emission"];
const EMISSIVE_FIELDS: &[&str] = &["radiance"];
const KINDS: &str = "lambert, blinn_phong, mirror, dielectric, emissive";

/// One material, checked and turned into the flat model record.
pub fn material(
    source: &Source<'_>,
    name: &str,
    raw: Spanned<RawMaterial>,
) -> Result<Material, SceneError> {
    let span = raw.span();
    let raw = raw.into_inner();
    let untyped = source.item(format!("materials.{name}"), Some(span.clone()));
    let kind = untyped.require("type", raw.kind.clone())?;
    let item = source.item(format!("materials.{name} ({kind})"), Some(span));
    let given = raw.given_fields();
    match kind.as_str() {
        "lambert" => {
            item.only_fields(&kind, LAMBERT_FIELDS, &given)?;
            lambert(&item, &raw)
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
        other => Err(untyped.fail(format_args!(
            "unknown material type `{other}` (expected one of: {KINDS})"
        ))),
    }
}

fn lambert(item: &Item<'_>, raw: &RawMaterial) -> Result<Material, SceneError> {
    let albedo = item.require("albedo", raw.albedo)?;
    Ok(Material {
        diffuse: item.colour("albedo", albedo, ColourRange::Fraction)?,
        coat_ior: coat_ior(item, raw.coat_ior)?,
        emission: emission(item, raw)?,
        ..Material::blank(MaterialKind::Lambert)
    })
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
            "shininess must be at most {MAX_SHININESS:e}, got {shininess}"
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
        return Err(item.fail(format_args!("ior must be > 0, got {ior}")));
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
            "coat_ior must be >= 1 (1 is an invisible coat; leave it out for none), got {value}"
        )));
    }
    Ok(value)
}

fn emission(item: &Item<'_>, raw: &RawMaterial) -> Result<DVec3, SceneError> {
    item.colour_or("emission", raw.emission, ColourRange::Radiance, DVec3::ZERO)
}
