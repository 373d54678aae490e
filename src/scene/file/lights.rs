//! `[[lights]]` entries.

use glam::DVec3;
use toml::Spanned;

use super::check::{ColourRange, Item, Source};
use super::raw::RawLight;
use crate::echo::{echo, short};
use crate::scene::{Light, MAX_RADIANCE, SceneError};

const POINT_FIELDS: &[&str] = &["position", "intensity", "color"];
const DIRECTIONAL_FIELDS: &[&str] = &["direction", "irradiance", "color"];
const SPOT_FIELDS: &[&str] = &[
    "position",
    "direction",
    "intensity",
    "color",
    "inner_cone_degrees",
    "outer_cone_degrees",
];
/// The cone half-angles a spot light takes when not given: glTF's
/// `KHR_lights_punctual` defaults (0 and π/4).
const DEFAULT_INNER_CONE_DEGREES: f64 = 0.0;
const DEFAULT_OUTER_CONE_DEGREES: f64 = 45.0;

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
        "spot" => {
            item.only_fields(&kind, SPOT_FIELDS, &given)?;
            spot(&item, &raw)
        }
        other => Err(untyped.fail(format_args!(
            "unknown light type `{}` (expected one of: point, directional, spot)",
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

/// A spot light: a point light whose intensity is full within the inner cone about
/// `direction`, falls off smoothly to 0 at the outer cone, and is 0 beyond it
/// (`KHR_lights_punctual`'s spot, whose cone rules it keeps: 0 <= inner < outer <= 90
/// degrees, half-angles from the axis).
fn spot(item: &Item<'_>, raw: &RawLight) -> Result<Light, SceneError> {
    let position = item.vector("position", item.require("position", raw.position)?)?;
    let direction = item.vector("direction", item.require("direction", raw.direction)?)?;
    let Some(direction) = direction.try_normalize() else {
        return Err(item.fail("direction is the zero vector"));
    };
    let intensity = item.non_negative("intensity", item.require("intensity", raw.intensity)?)?;
    let inner = item.number(
        "inner_cone_degrees",
        raw.inner_cone_degrees.unwrap_or(DEFAULT_INNER_CONE_DEGREES),
    )?;
    let outer = item.number(
        "outer_cone_degrees",
        raw.outer_cone_degrees.unwrap_or(DEFAULT_OUTER_CONE_DEGREES),
    )?;
    if !((0.0..90.0).contains(&inner) && outer > inner && outer <= 90.0) {
        return Err(item.fail(format_args!(
            "inner_cone_degrees {} and outer_cone_degrees {} must satisfy \
             0 <= inner < outer <= 90 (half-angles from the direction)",
            short(inner),
            short(outer)
        )));
    }
    Ok(Light::Spot {
        position,
        direction,
        intensity: strength(item, "intensity", intensity * color(item, raw)?)?,
        cos_inner: inner.to_radians().cos(),
        cos_outer: outer.to_radians().cos().max(0.0),
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
