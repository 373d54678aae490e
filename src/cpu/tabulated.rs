//! Importance sampling of tabulated BRDF maps by inverse CDF: the path integrator's
//! sampler for `tabulated` materials (issue 11), twin of `shaders/tabulated.wgsl`
//! (same function names, the same `f32` tables).
//!
//! A map is `f(θi, θr)`, independent of azimuth, bilinear on a corner-aligned grid of
//! `N` angles per axis (`docs/materials.md`). For the outgoing direction `wo` at
//! `θr = θ_y + fy·Δ` (between rows `y` and `y + 1`, `Δ = π/2 / (N−1)`, `fy` the
//! bilinear lookup's weight), the map's sampler
//!
//! 1. picks row `y` with probability `1 − w` and row `y + 1` with probability `w`, the
//!    position of `cos θr` between the rows' cosines (close to the bilinear lookup's
//!    weight `fy`; see `brdf_map_rows` for why not `fy` itself);
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
//! `p_map(ωi) = ((1 − w) P_y(b) + w P_{y+1}(b)) · cos θi / (π ΔS_b)`,
//!
//! exact for the sampler above. The path integrator mixes it with the cosine sampler,
//! chosen with probability [`TABULATED_COSINE_PROBABILITY`]: the mixture's density is
//! positive wherever `cos θi > 0`, even in bands whose probability rounds to zero in the
//! `f32` table, so the estimator stays unbiased for any map.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::accel::BrdfMapCdf;
use crate::accel::brdf_map_cdf::band_projected_solid_angle;
use crate::sample::{pdf_cosine_hemisphere, sample_cosine_hemisphere};

/// The probability with which the sampler of a tabulated BRDF draws from the cosine
/// distribution instead of the map's (a defensive mixture; see the module's
/// documentation).
pub const TABULATED_COSINE_PROBABILITY: f64 = 0.1;

/// `θ_b = b/(n−1)·π/2`, the angle of texel `b` of an `n`-texel axis, and its cosine.
fn grid_angle(b: u32, n: u32) -> (f64, f64) {
    let theta = f64::from(b) * (FRAC_PI_2 / f64::from(n - 1));
    (theta, theta.cos())
}

/// The cell `b` (`θ_b ≤ θ < θ_{b+1}`, `b ≤ n − 2`) of an `n`-texel axis holding the
/// angle of cosine `z ∈ [0, 1]`: guessed from `acos z`, then checked against the
/// cosines of the cell's ends, so that an approximate `acos` (as GPUs have) moves no
/// direction across an edge: what is left is the rounding of `z` and of the cosines.
fn brdf_map_cell(n: u32, z: f64) -> u32 {
    let last = f64::from(n - 1);
    let theta = z.acos();
    let mut cell = ((theta / FRAC_PI_2).clamp(0.0, 1.0) * last)
        .floor()
        .min(last - 1.0) as u32;
    if cell > 0 && z > grid_angle(cell, n).1 {
        cell -= 1;
    } else if cell + 2 < n && z <= grid_angle(cell + 1, n).1 {
        cell += 1;
    }
    cell
}

/// The two rows of an `n`-row table the sampler mixes for the outgoing cosine `cos_o`:
/// the first, `y` (`θ_y ≤ θr < θ_{y+1}`), and the weight `w` of the second, the
/// position of `cos θr` between the rows' cosines, `w = (cos θ_y − cos θr) / (cos θ_y −
/// cos θ_{y+1})`. It is close to the bilinear lookup's weight (linear in `θr`) and,
/// unlike that, needs no `acos`, whose approximation on GPUs would move the row
/// choice's threshold; the density uses the same `w`, so the sampler stays exact.
fn brdf_map_rows(n: u32, cos_o: f64) -> (u32, f64) {
    let z = cos_o.clamp(0.0, 1.0);
    let y = brdf_map_cell(n, z);
    // cos θ_y − cos θ_{y+1} = 2 sin((θ_y + θ_{y+1})/2) sin(Δ/2), without cancellation.
    let half_step = 0.5 * (FRAC_PI_2 / f64::from(n - 1));
    let width = 2.0 * (f64::from(2 * y + 1) * half_step).sin() * half_step.sin();
    (y, ((grid_angle(y, n).1 - z) / width).clamp(0.0, 1.0))
}

/// A local incident direction (`z` the normal) from the map's own sampler (steps 1 to
/// 3 of the module's documentation) for the outgoing cosine `cos_o`: `u_row` chooses
/// the row, `u.x` the band and the position in it, `u.y` the azimuth.
pub fn sample_brdf_map_direction(cdf: &BrdfMapCdf, cos_o: f64, u_row: f64, u: DVec2) -> DVec3 {
    let n = cdf.size();
    let (y0, w) = brdf_map_rows(n, cos_o);
    let row = if u_row < 1.0 - w { y0 } else { y0 + 1 };
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
    let (theta_b, cos_b) = grid_angle(lo, n);
    let ds = band_projected_solid_angle(lo, n);
    let sin_squared = theta_b.sin() * theta_b.sin() + t * ds;
    let cos_squared = cos_b * cos_b - t * ds;
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
    let band = brdf_map_cell(n, wi.z.min(1.0));
    let (y0, w) = brdf_map_rows(n, cos_o);
    let band_probability =
        |row: u32| f64::from(cdf.value(band + 1, row)) - f64::from(cdf.value(band, row));
    let probability = (1.0 - w) * band_probability(y0) + w * band_probability(y0 + 1);
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
