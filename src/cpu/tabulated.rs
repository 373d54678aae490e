//! Importance sampling of tabulated BRDF maps by inverse CDF: the path integrator's
//! sampler for `tabulated` materials (issue 11), twin of `shaders/tabulated.wgsl`
//! (same function names, the same `f32` tables).
//!
//! A map is `f(θi, θr)`, independent of azimuth, bilinear on a corner-aligned grid of
//! `N` angles per axis (`docs/materials.md`). For the outgoing direction `wo` at
//! `θr = θ_y + fy·Δ` (between rows `y` and `y + 1`, `Δ = π/2 / (N−1)`), the map's
//! sampler
//!
//! 1. picks row `y` with probability `1 − fy` and row `y + 1` with probability `fy`,
//!    as the bilinear lookup weights them;
//! 2. picks a band `θi ∈ [θ_b, θ_{b+1}]` from that row's piecewise-constant
//!    distribution ([`crate::accel::BrdfMapCdf`], weights `f̄ · cos θ` integrated over
//!    the band) by binary search of its cumulative table (pbrt-v4 §A.4.2, "Piecewise-
//!    Constant 1D Functions");
//! 3. draws `sin² θi` uniformly over the band, so that inside it the density in solid
//!    angle is proportional to `cos θi` (Malley's method restricted to a ring: `∫ cos θ
//!    dω = π d(sin² θ)`), and the azimuth uniformly.
//!
//! Its density per steradian is therefore, with `P_r(b)` the probability of band `b`
//! in row `r` and `ΔS_b = sin² θ_{b+1} − sin² θ_b`,
//!
//! `p_map(ωi) = ((1 − fy) P_y(b) + fy P_{y+1}(b)) · cos θi / (π ΔS_b)`,
//!
//! exact for the sampler above. The path integrator mixes it with the cosine sampler,
//! chosen with probability [`TABULATED_COSINE_PROBABILITY`]: the mixture's density is
//! positive wherever `cos θi > 0`, even in bands whose probability rounds to zero in the
//! `f32` table, so the estimator stays unbiased for any map.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use super::sample::{pdf_cosine_hemisphere, sample_cosine_hemisphere};
use crate::accel::BrdfMapCdf;
use crate::accel::brdf_map_cdf::band_projected_solid_angle;

/// The probability with which the sampler of a tabulated BRDF draws from the cosine
/// distribution instead of the map's (a defensive mixture; see the module's
/// documentation).
pub const TABULATED_COSINE_PROBABILITY: f64 = 0.1;

/// The two rows of an `n`-row table that the bilinear lookup mixes at the outgoing
/// cosine `cos_o`, and the weight `fy` of the second, as `sample_brdf_map` computes
/// them (`θr = acos(cos_o)`, clamped to the grid).
fn brdf_map_rows(n: u32, cos_o: f64) -> (u32, f64) {
    let last = f64::from(n - 1);
    let theta_r = cos_o.clamp(-1.0, 1.0).acos();
    let y = (theta_r / FRAC_PI_2).clamp(0.0, 1.0) * last;
    let y0 = y.floor().min(last - 1.0);
    (y0 as u32, y - y0)
}

/// A local incident direction (`z` the normal) from the map's own sampler (steps 1 to
/// 3 of the module's documentation) for the outgoing cosine `cos_o`: `u_row` chooses
/// the row, `u.x` the band and the position in it, `u.y` the azimuth.
pub fn sample_brdf_map_direction(cdf: &BrdfMapCdf, cos_o: f64, u_row: f64, u: DVec2) -> DVec3 {
    let n = cdf.size();
    let (y0, fy) = brdf_map_rows(n, cos_o);
    let row = if u_row < 1.0 - fy { y0 } else { y0 + 1 };
    // The band b with cdf[b] <= u.x < cdf[b + 1]: cdf[0] = 0 and cdf[n − 1] = 1 bound
    // it, so the band found has a positive probability.
    let (mut lo, mut hi) = (0u32, n - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if f64::from(cdf.value(mid, row)) <= u.x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (c0, c1) = (
        f64::from(cdf.value(lo, row)),
        f64::from(cdf.value(lo + 1, row)),
    );
    let t = (u.x - c0) / (c1 - c0);
    // sin² θ and cos² θ each from its own end of the band, without cancellation.
    let theta_b = f64::from(lo) * (FRAC_PI_2 / f64::from(n - 1));
    let ds = band_projected_solid_angle(lo, n);
    let sin_squared = theta_b.sin() * theta_b.sin() + t * ds;
    let cos_squared = theta_b.cos() * theta_b.cos() - t * ds;
    let (sin_theta, cos_theta) = (sin_squared.max(0.0).sqrt(), cos_squared.max(0.0).sqrt());
    let phi = 2.0 * PI * u.y;
    DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// The density per steradian of [`sample_brdf_map_direction`] producing the local
/// direction `wi` for the outgoing cosine `cos_o` (0 below the surface).
pub fn pdf_brdf_map_direction(cdf: &BrdfMapCdf, cos_o: f64, wi: DVec3) -> f64 {
    if wi.z <= 0.0 {
        return 0.0;
    }
    let n = cdf.size();
    let last = f64::from(n - 1);
    let theta_i = wi.z.min(1.0).acos();
    let band = ((theta_i / FRAC_PI_2).clamp(0.0, 1.0) * last)
        .floor()
        .min(last - 1.0) as u32;
    let (y0, fy) = brdf_map_rows(n, cos_o);
    let band_probability =
        |row: u32| f64::from(cdf.value(band + 1, row)) - f64::from(cdf.value(band, row));
    let probability = (1.0 - fy) * band_probability(y0) + fy * band_probability(y0 + 1);
    probability * wi.z / (PI * band_projected_solid_angle(band, n))
}

/// A local incident direction for a tabulated BRDF seen from the local `wo`: the cosine
/// sampler when `u_lobe < TABULATED_COSINE_PROBABILITY`, else the map's, its row chosen
/// by `u_lobe` rescaled to `[0, 1)`.
pub fn sample_tabulated(cdf: &BrdfMapCdf, wo: DVec3, u_lobe: f64, u: DVec2) -> DVec3 {
    if u_lobe < TABULATED_COSINE_PROBABILITY {
        sample_cosine_hemisphere(u)
    } else {
        let u_row = (u_lobe - TABULATED_COSINE_PROBABILITY) / (1.0 - TABULATED_COSINE_PROBABILITY);
        sample_brdf_map_direction(cdf, wo.z, u_row, u)
    }
}

/// The density per steradian of [`sample_tabulated`] producing the local `wi`: the
/// mixture of the cosine density and [`pdf_brdf_map_direction`].
pub fn pdf_tabulated(cdf: &BrdfMapCdf, wo: DVec3, wi: DVec3) -> f64 {
    TABULATED_COSINE_PROBABILITY * pdf_cosine_hemisphere(wi)
        + (1.0 - TABULATED_COSINE_PROBABILITY) * pdf_brdf_map_direction(cdf, wo.z, wi)
}
