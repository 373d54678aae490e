//! `[[lights]]` entries.

use glam::DVec3;
use toml::Spanned;

use super::check::{ColourRange, Item, Source};
use super::raw::RawLight;
use crate::echo::{echo, short};
use crate::scene::{Light, MAX_RADIANCE, SceneError};

const POINT_FIELDS: &[&str] = &["position", "intensity", "color"];
const DIRECTIONAL_FIELDS: &[&str] = &["direction", "irradiance", "color"];

/// Light `index` (0-based, in file order), checked.
pub fn light(
    source: &Source<'_>,
    index: usize,
    raw: Spanned<RawLight>,
) -> Result<Light, SceneError> {
    let span = raw.span();
    let raw = raw.into_inner();
    let untyped = source.item(format!("lights[{index}]"), Some(span.clone()));
    let kind = untyped.require("type", raw.kind.clone())?;
    let item = source.item(format!("lights[{index}] ({kind})"), Some(span));
    let given = raw.given_fields();
    match kind.as_str() {
        "point" => {
            item.only_fields(&kind, POINT_FIELDS, &given)?;
            point(&item, &raw)
        }
        "directional" => {
            item.only_fields(&kind, DIRECTIONAL_FIELDS, &given)?;
            directional(&item, &raw)
        }
        other => Err(untyped.fail(format_args!(
            "unknown light type `{}` (expected one of: point, directional)",
            echo(other)
        ))),
    }
}

fn point(item: &Item<'_>, raw: &RawLight) -> Result<Light, SceneError> {
    let position = item.vector("position", item.require("position", raw.position)?)?;
    let intensity = item.non_negative("intensity", item.require("intensity", raw.intensity)?)?;
    Ok(Light::Point {
        position,
        intensity: strength(item, "intensity", intensity * color(item, raw)?)?,
    })
}

fn directional(item: &Item<'_>, raw: &RawLight) -> Result<Light, SceneError> {
    let direction = item.vector("direction", item.require("direction", raw.direction)?)?;
    let Some(direction) = direction.try_normalize() else {
        return Err(item.fail("direction is the zero vector"));
    };
    let irradiance =
        item.non_negative("irradiance", item.require("irradiance", raw.irradiance)?)?;
    Ok(Light::Directional {
        direction,
        irradiance: strength(item, "irradiance", irradiance * color(item, raw)?)?,
    })
}

/// A light's strength times its colour, refused above [`MAX_RADIANCE`] per channel.
fn strength(item: &Item<'_>, field: &str, value: DVec3) -> Result<DVec3, SceneError> {
    let largest = value.max_element();
    if largest > MAX_RADIANCE {
        return Err(item.fail(format_args!(
            "{field} times color reaches {}, above the {} accepted (the GPU sums light \
             in 32-bit floats)",
            short(largest),
            short(MAX_RADIANCE)
        )));
    }
    Ok(value)
}

fn color(item: &Item<'_>, raw: &RawLight) -> Result<DVec3, SceneError> {
    item.colour_or("color", raw.color, ColourRange::Radiance, DVec3::ONE)
}
