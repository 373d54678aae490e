//! Environment maps: an equirectangular (latitude-longitude) image of the radiance
//! arriving from every direction at infinity, rotated about +y and scaled. The
//! background escaping rays see, and a light the path integrator samples
//! (`crate::accel::EnvironmentLight`).
//!
//! The mapping from a direction to image coordinates is Mitsuba 3's `envmap` (so that
//! `scripts/mitsuba/environment_reference.py` needs no transform but the rotation):
//! with `d = (x, y, z)` the unit direction in the map's own frame (the world direction
//! turned by −`rotation` about +y),
//!
//! - `u = atan2(x, −z) / 2π`, wrapped into `[0, 1)`: `u = 0` (and 1) looks along −z,
//!   `u = 1/4` along +x, `u = 1/2` along +z, `u = 3/4` along −x;
//! - `v = acos(y) / π`: `v = 0` is straight up (+y, the image's top row), `v = 1`
//!   straight down;
//!
//! and back, `θ = π v`, `φ = 2π u`, `d = (sin φ sin θ, cos θ, −cos φ sin θ)`. A direction
//! sees the texel (`⌊u·width⌋`, `⌊v·height⌋`) (nearest, no filtering: the radiance is
//! piecewise constant, exactly the density the sampler draws from).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::Image;

/// An environment map: the image, its rotation and its radiance scale.
#[derive(Clone, PartialEq)]
pub struct EnvironmentMap {
    /// The equirectangular image, linear radiance (W/(sr·m²)) per texel, every
    /// channel finite and at least 0 (checked on load).
    pub image: Image,
    /// Rotation of the map about +y in degrees, right-handed (counter-clockwise seen
    /// from above): the map's −z direction (`u = 0`) turns towards −x for 90°. Finite.
    pub rotation_degrees: f64,
    /// Radiance multiplier per channel (finite, at least 0).
    pub scale: DVec3,
}

/// The map without its texels (and without its file's path, which fingerprints must
/// not see; `crate::tiles` hashes the texels' bytes).
impl std::fmt::Debug for EnvironmentMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvironmentMap")
            .field("width", &self.image.width)
            .field("height", &self.image.height)
            .field("rotation_degrees", &self.rotation_degrees)
            .field("scale", &self.scale)
            .finish_non_exhaustive()
    }
}

impl EnvironmentMap {
    /// `(cos α, sin α)` of the rotation α.
    pub fn rotation_cos_sin(&self) -> DVec2 {
        let a = self.rotation_degrees.to_radians();
        DVec2::new(a.cos(), a.sin())
    }

    /// The world direction `d` in the map's frame: turned by −α about +y.
    pub fn to_local(&self, d: DVec3) -> DVec3 {
        let cs = self.rotation_cos_sin();
        DVec3::new(cs.x * d.x - cs.y * d.z, d.y, cs.y * d.x + cs.x * d.z)
    }

    /// A direction of the map's frame in the world: turned by α about +y.
    pub fn to_world(&self, d: DVec3) -> DVec3 {
        let cs = self.rotation_cos_sin();
        DVec3::new(cs.x * d.x + cs.y * d.z, d.y, -cs.y * d.x + cs.x * d.z)
    }

    /// The texel a world direction sees.
    pub fn texel_of(&self, direction: DVec3) -> (u32, u32) {
        let uv = direction_to_uv(self.to_local(direction));
        texel_at(uv, self.image.width, self.image.height)
    }

    /// The radiance arriving along `-direction`, i.e. seen looking along the world
    /// direction `direction` (unit): the texel times the scale.
    pub fn radiance(&self, direction: DVec3) -> DVec3 {
        let (x, y) = self.texel_of(direction);
        let t = self.image.texel(x, y);
        DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2])) * self.scale
    }
}

/// `(u, v)` of a unit direction in the map's frame (see the module's documentation).
pub fn direction_to_uv(d: DVec3) -> DVec2 {
    let mut u = d.x.atan2(-d.z) * (0.5 / PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = d.y.clamp(-1.0, 1.0).acos() * (1.0 / PI);
    DVec2::new(u, v)
}

/// The unit direction in the map's frame of `(u, v)`.
pub fn uv_to_direction(uv: DVec2) -> DVec3 {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * uv.x;
    let s = theta.sin();
    DVec3::new(phi.sin() * s, theta.cos(), -phi.cos() * s)
}

/// The texel `(⌊u·width⌋, ⌊v·height⌋)`, clamped into the image.
pub fn texel_at(uv: DVec2, width: u32, height: u32) -> (u32, u32) {
    let x = ((uv.x * f64::from(width)) as u32).min(width - 1);
    let y = ((uv.y * f64::from(height)) as u32).min(height - 1);
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mapping_follows_mitsubas_envmap() {
        let close = |a: DVec2, b: DVec2| (a - b).length() < 1e-12;
        assert!(close(direction_to_uv(DVec3::NEG_Z), DVec2::new(0.0, 0.5)));
        assert!(close(direction_to_uv(DVec3::X), DVec2::new(0.25, 0.5)));
        assert!(close(direction_to_uv(DVec3::Z), DVec2::new(0.5, 0.5)));
        assert!(close(direction_to_uv(DVec3::NEG_X), DVec2::new(0.75, 0.5)));
        assert!(direction_to_uv(DVec3::Y).y.abs() < 1e-12);
        assert!((direction_to_uv(DVec3::NEG_Y).y - 1.0).abs() < 1e-12);
        for (u, v) in [(0.1, 0.2), (0.6, 0.9), (0.33, 0.5), (0.99, 0.01)] {
            let uv = DVec2::new(u, v);
            assert!(close(direction_to_uv(uv_to_direction(uv)), uv), "{uv}");
        }
    }

    #[test]
    fn rotation_turns_minus_z_towards_minus_x() {
        let map = EnvironmentMap {
            image: Image {
                path: "sky.hdr".into(),
                width: 1,
                height: 1,
                texels: vec![[1.0; 4]],
            },
            rotation_degrees: 90.0,
            scale: DVec3::ONE,
        };
        assert!(map.to_world(DVec3::NEG_Z).distance(DVec3::NEG_X) < 1e-12);
        let d = DVec3::new(0.3, -0.5, 0.81).normalize();
        assert!(map.to_local(map.to_world(d)).distance(d) < 1e-12);
    }
}
