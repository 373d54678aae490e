//! The lecture's three rules of a physically plausible BRDF, checked on a tabulated
//! BRDF map (`gpu-render brdf-check FILE`):
//!
//! - positivity: `f(ωi, ωr) ≥ 0`;
//! - energy conservation: `∫ f(ωi, ωr) cos θr dωr ≤ 1` for every `ωi`;
//! - Helmholtz reciprocity: `f(ωi, ωr) = f(ωr, ωi)`.
//!
//! The map is read as the renderer reads it ([`crate::texture::sample_brdf_map`]):
//! isotropic, so `∫ f cos θr dωr = 2π ∫₀^{π/2} f(θi, θr) cos θr sin θr dθr`.

use std::f64::consts::{FRAC_PI_2, PI};

use crate::scene::Image;
use crate::texture::sample_brdf_map;

/// Steps of the midpoint rule over `θr` in the energy integral. With a bilinear map
/// the integrand is smooth between grid lines; 4096 steps integrate a constant map
/// (a white Lambertian, exactly 1) to within 1e-7.
pub const ENERGY_STEPS: usize = 4096;
/// Allowed excess of the directional albedo over 1 (integration error).
pub const ENERGY_TOLERANCE: f64 = 1e-4;
/// Allowed `|f(a, b) - f(b, a)|`, relative to the map's largest value.
pub const RECIPROCITY_TOLERANCE: f64 = 1e-3;

/// The worst case of one rule: its size and where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Worst {
    /// Positivity: the smallest `f` (1/sr). Energy: the largest directional albedo.
    /// Reciprocity: the largest `|f(θi, θr) - f(θr, θi)|` (1/sr).
    pub value: f64,
    /// Angle of incidence in degrees.
    pub theta_i_degrees: f64,
    /// Angle of reflection in degrees (energy: not applicable, 0).
    pub theta_r_degrees: f64,
    /// Colour channel (0 = R, 1 = G, 2 = B).
    pub channel: usize,
    /// Whether this rule holds.
    pub holds: bool,
}

/// The result of [`check_brdf_map`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrdfMapReport {
    /// Positivity.
    pub positivity: Worst,
    /// Energy conservation.
    pub energy: Worst,
    /// Helmholtz reciprocity.
    pub reciprocity: Worst,
}

impl BrdfMapReport {
    /// Whether all three rules hold.
    pub fn plausible(&self) -> bool {
        self.positivity.holds && self.energy.holds && self.reciprocity.holds
    }
}

fn grid_angle_degrees(index: u32, size: u32) -> f64 {
    f64::from(index) / f64::from(size - 1) * 90.0
}

/// An image that cannot be a BRDF map: not square, or smaller than 2×2.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("a BRDF map must be square and at least 2x2 (θi across, θr down), got {width}x{height}")]
pub struct NotABrdfMap {
    /// The image's width.
    pub width: u32,
    /// The image's height.
    pub height: u32,
}

/// Checks a square BRDF map (at least 2×2, texel `(x, y)` = `π·f` at
/// `θi = x/(N-1)·90°`, `θr = y/(N-1)·90°`) against the three rules.
///
/// Errors: [`NotABrdfMap`] when the map is not square or smaller than 2×2.
pub fn check_brdf_map(map: &Image) -> Result<BrdfMapReport, NotABrdfMap> {
    if map.width != map.height || map.width < 2 {
        return Err(NotABrdfMap {
            width: map.width,
            height: map.height,
        });
    }
    let n = map.width;
    let mut positivity = Worst {
        value: f64::INFINITY,
        theta_i_degrees: 0.0,
        theta_r_degrees: 0.0,
        channel: 0,
        holds: true,
    };
    let mut reciprocity = Worst {
        value: 0.0,
        ..positivity
    };
    let mut largest: f64 = 0.0;
    for y in 0..n {
        for x in 0..n {
            let t = map.texel(x, y);
            let mirrored = map.texel(y, x);
            for c in 0..3 {
                let f = f64::from(t[c]) / PI;
                largest = largest.max(f.abs());
                if f < positivity.value {
                    positivity = Worst {
                        value: f,
                        theta_i_degrees: grid_angle_degrees(x, n),
                        theta_r_degrees: grid_angle_degrees(y, n),
                        channel: c,
                        holds: true,
                    };
                }
                let asymmetry = (f - f64::from(mirrored[c]) / PI).abs();
                if asymmetry > reciprocity.value {
                    reciprocity = Worst {
                        value: asymmetry,
                        theta_i_degrees: grid_angle_degrees(x, n),
                        theta_r_degrees: grid_angle_degrees(y, n),
                        channel: c,
                        holds: true,
                    };
                }
            }
        }
    }
    positivity.holds = positivity.value >= 0.0;
    reciprocity.holds = reciprocity.value <= RECIPROCITY_TOLERANCE * largest;

    // The albedo is linear in θi between grid columns (bilinear map), so its largest
    // value is at a column.
    let mut energy = Worst {
        value: f64::NEG_INFINITY,
        ..positivity
    };
    let step = FRAC_PI_2 / ENERGY_STEPS as f64;
    for x in 0..n {
        let theta_i = f64::from(x) / f64::from(n - 1) * FRAC_PI_2;
        let mut albedo = glam::DVec3::ZERO;
        for s in 0..ENERGY_STEPS {
            let theta_r = (s as f64 + 0.5) * step;
            albedo += sample_brdf_map(map, theta_i, theta_r) * (theta_r.cos() * theta_r.sin());
        }
        albedo *= 2.0 * PI * step;
        for (c, a) in albedo.to_array().into_iter().enumerate() {
            if a > energy.value {
                energy = Worst {
                    value: a,
                    theta_i_degrees: theta_i.to_degrees(),
                    theta_r_degrees: 0.0,
                    channel: c,
                    holds: true,
                };
            }
        }
    }
    energy.holds = energy.value <= 1.0 + ENERGY_TOLERANCE;
    Ok(BrdfMapReport {
        positivity,
        energy,
        reciprocity,
    })
}
