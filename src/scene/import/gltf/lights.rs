//! `KHR_lights_punctual`: glTF's point, spot and directional lights in our radiometric
//! units.

use ::gltf::khr_lights_punctual::Kind;
use glam::{DMat4, DVec3};

use super::importer::{Importer, describe};
use crate::echo::short;
use crate::scene::{Light, MAX_RADIANCE, SceneError};

/// Luminous efficacy used to turn `KHR_lights_punctual`'s photometric intensities into
/// our radiometric ones, in lm/W: 683, the peak of the photopic curve at 555 nm (the
/// definition of the candela, SI Brochure §2.3.1). A point or spot light of `I` cd
/// becomes `I / 683` W/sr, a directional light of `E` lux becomes `E / 683` W/m², each
/// times the light's linear `color`. This treats every light as if all its power were at
/// 555 nm, the convention of Blender's glTF exporter in its "Standard" lighting mode.
pub const LUMENS_PER_WATT: f64 = 683.0;

impl Importer<'_> {
    /// Converts a `KHR_lights_punctual` light into our units (see [`LUMENS_PER_WATT`]).
    pub(super) fn light(
        &mut self,
        light: &::gltf::khr_lights_punctual::Light<'_>,
        node: &str,
        world: DMat4,
    ) -> Result<(), SceneError> {
        let name = describe("light", light.index(), light.name());
        let intensity = f64::from(light.intensity());
        let color = DVec3::from_array(light.color().map(f64::from));
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(self.fail(format!(
                "{name}: intensity {intensity} is negative or not finite"
            )));
        }
        if !color
            .to_array()
            .into_iter()
            .all(|c| (0.0..=1.0).contains(&c))
        {
            return Err(self.fail(format!("{name}: color {color} must lie in [0, 1]")));
        }
        if light.range().is_some() {
            self.warn(format!(
                "{name}: range is ignored (our lights fall off with the inverse square to any distance)"
            ));
        }
        let strength = color * intensity / LUMENS_PER_WATT;
        if strength.max_element() > MAX_RADIANCE {
            return Err(self.fail(format!(
                "{name}: intensity {} is {} W after conversion, above the {} accepted (the GPU \
                 sums light in 32-bit floats)",
                short(intensity),
                short(strength.max_element()),
                short(MAX_RADIANCE)
            )));
        }
        let position = world.transform_point3(DVec3::ZERO);
        let point = Light::Point {
            position,
            intensity: strength,
        };
        let converted = match light.kind() {
            Kind::Point => point,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                // §KHR_lights_punctual: 0 ≤ inner < outer ≤ π/2 (defaults 0 and π/4).
                let (inner, outer) = (f64::from(inner_cone_angle), f64::from(outer_cone_angle));
                let right_angle = std::f64::consts::FRAC_PI_2;
                // π/2 given in f32 lies a little above it in f64.
                let ordered = (0.0..right_angle).contains(&inner)
                    && outer > inner
                    && outer <= right_angle + 1e-6;
                if !ordered {
                    return Err(self.fail(format!(
                        "{name} on {node}: spot innerConeAngle {} and outerConeAngle {} must satisfy 0 <= inner < outer <= pi/2",
                        short(inner_cone_angle),
                        short(outer_cone_angle)
                    )));
                }
                // Spot lights shine along the node's local -z, as directional ones.
                let direction = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                if direction == DVec3::ZERO {
                    self.warn(format!(
                        "{name} on {node}: its transform leaves no direction (singular); ignored"
                    ));
                    return Ok(());
                }
                Light::Spot {
                    position,
                    direction,
                    intensity: strength,
                    cos_inner: inner.cos(),
                    cos_outer: outer.min(right_angle).cos().max(0.0),
                }
            }
            Kind::Directional => {
                // §KHR_lights_punctual: directional lights shine along the node's local -z.
                let direction = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                if direction == DVec3::ZERO {
                    self.warn(format!(
                        "{name} on {node}: its transform leaves no direction (singular); ignored"
                    ));
                    return Ok(());
                }
                Light::Directional {
                    direction,
                    irradiance: strength,
                }
            }
        };
        self.model.lights.push(converted);
        Ok(())
    }
}
