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
//! and back, `θ = π v`, `φ = 2π u`, `d = (sin φ sin θ, cos θ, −cos φ sin θ)`.
//!
//! A direction sees the map interpolated bilinearly with Mitsuba's texel convention
//! ([`Bilinear`]): column `i`'s centre at `u = (i + ½)/width`, wrapping around in `u`
//! (the last column blends into the first), and row `j` at `v = j/(height − 1)`, so
//! the first and last rows are the poles' values. The path integrator's sampler draws
//! from piecewise-constant cells (`⌊u·width⌋`, `⌊v·height⌋`, [`texel_at`]) whose
//! weights cover every texel that blends into them (`crate::accel::EnvironmentLight`).

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
    /// direction `direction` (unit): the map interpolated at its `(u, v)`
    /// ([`EnvironmentMap::radiance_at`]).
    pub fn radiance(&self, direction: DVec3) -> DVec3 {
        self.radiance_at(direction_to_uv(self.to_local(direction)))
    }

    /// The radiance at map coordinates `uv`: the four texels [`Bilinear`] picks,
    /// weighted, times the scale (Mitsuba 3's `envmap` `eval_spectrum`).
    pub fn radiance_at(&self, uv: DVec2) -> DVec3 {
        let b = Bilinear::at(uv, self.image.width, self.image.height);
        let texel = |x: u32, y: u32| {
            let t = self.image.texel(x, y);
            DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]))
        };
        let top = texel(b.x0, b.y0) * (1.0 - b.wx) + texel(b.x1, b.y0) * b.wx;
        let bottom = texel(b.x0, b.y1) * (1.0 - b.wx) + texel(b.x1, b.y1) * b.wx;
        (top * (1.0 - b.wy) + bottom * b.wy) * self.scale
    }
}

/// The texels and weights of a bilinear lookup of a `width × height` map at `uv`,
/// with Mitsuba 3's `envmap` convention (its `eval_spectrum`, which pads the image
/// with a copy of its first column): `x = frac(u − ½/width)·width`, so column `i`'s
/// centre is at `u = (i + ½)/width` and columns wrap around; `y = v·(height − 1)`, so
/// row `j` lies at `v = j/(height − 1)`, the first row at the top pole and the last at
/// the bottom one. A map one row high has that row everywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bilinear {
    /// The left column.
    pub x0: u32,
    /// The right column (`x0 + 1`, or 0 after the last).
    pub x1: u32,
    /// The upper row.
    pub y0: u32,
    /// The lower row (`y0 + 1`, or `y0` for a map one row high).
    pub y1: u32,
    /// The right column's weight, in [0, 1].
    pub wx: f64,
    /// The lower row's weight, in [0, 1].
    pub wy: f64,
}

impl Bilinear {
    /// The lookup at `uv` (`u` any value, wrapped; `v` in [0, 1]).
    pub fn at(uv: DVec2, width: u32, height: u32) -> Self {
        let w = f64::from(width);
        let shifted = uv.x - 0.5 / w;
        let x = (shifted - shifted.floor()) * w;
        let x0 = (x as u32).min(width - 1);
        let x1 = if x0 + 1 == width { 0 } else { x0 + 1 };
        let wx = (x - f64::from(x0)).clamp(0.0, 1.0);
        if height < 2 {
            return Self {
                x0,
                x1,
                y0: 0,
                y1: 0,
                wx,
                wy: 0.0,
            };
        }
        let y = uv.y.clamp(0.0, 1.0) * f64::from(height - 1);
        let y0 = (y as u32).min(height - 2);
        Self {
            x0,
            x1,
            y0,
            y1: y0 + 1,
            wx,
            wy: (y - f64::from(y0)).clamp(0.0, 1.0),
        }
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

    fn map(width: u32, height: u32, values: &[f32]) -> EnvironmentMap {
        EnvironmentMap {
            image: Image {
                path: "map.exr".into(),
                width,
                height,
                texels: values.iter().map(|&v| [v, v, v, 1.0]).collect(),
            },
            rotation_degrees: 0.0,
            scale: DVec3::ONE,
        }
    }

    #[test]
    fn lookups_interpolate_between_texel_centres_as_mitsuba_does() {
        // 4 columns, 3 rows: column i's centre at u = (i + 0.5)/4, row j at v = j/2.
        let values: Vec<f32> = (0..12).map(|i| i as f32).collect();
        let m = map(4, 3, &values);
        let at = |u: f64, v: f64| m.radiance_at(DVec2::new(u, v)).x;
        for j in 0..3 {
            for i in 0..4 {
                let centre = at((f64::from(i) + 0.5) / 4.0, f64::from(j) / 2.0);
                assert!(
                    (centre - f64::from(j * 4 + i)).abs() < 1e-12,
                    "({i}, {j}): {centre}"
                );
            }
        }
        // Halfway between columns 1 and 2 of row 0, and between rows 0 and 1.
        assert!((at(0.5, 0.0) - 1.5).abs() < 1e-12);
        assert!((at(0.375, 0.25) - 3.0).abs() < 1e-12);
        // Columns wrap: at u = 0 (and 1), halfway between the last column and the first.
        assert!((at(0.0, 0.0) - 1.5).abs() < 1e-12);
        assert!((at(1.0, 0.0) - 1.5).abs() < 1e-12);
        // The poles are the first and last rows.
        assert!((at(0.125, 1.0) - 8.0).abs() < 1e-12);
        // One row: that row at every v.
        let strip = map(2, 1, &[2.0, 4.0]);
        assert!((strip.radiance_at(DVec2::new(0.25, 0.9)).x - 2.0).abs() < 1e-12);
    }

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
