//! The environment map as a light, shared by both backends: the distribution by which
//! next-event estimation samples directions of an [`EnvironmentMap`], and the
//! probability with which it picks the map rather than an area light. The CPU
//! reference samples it (`src/cpu/path.rs`); the GPU uploads its tables
//! (`src/gpu/environment.rs`) and samples them with the same numbers
//! (`shaders/environment.wgsl`).
//!
//! The distribution is pbrt's 2D piecewise-constant one (pbrt-v4's
//! `PiecewiseConstant2D`, Pharr, Jakob and Humphreys, *Physically Based Rendering*, 4th
//! ed., §A.5; pbrt-v3 §13.6.7 and §14.2.4 for its use on a latitude-longitude map): a
//! marginal distribution over the rows and one conditional distribution per row over
//! its cells (`⌊u·width⌋`, `⌊v·height⌋`), of the function `f(x, y) = max luminance ·
//! sin θ_y`, `θ_y = π (y + ½) / height` the row's polar angle, the maximum taken over
//! the texels (times the scale) that the map's bilinear lookup blends anywhere in the
//! cell ([`cell_texels`]): so the density is positive wherever the radiance is, and
//! next-event estimation alone finds all the light. Weighting by `sin θ` makes the
//! density follow the radiance per solid angle: a point `(u, v)` drawn with density
//! `p(u, v) = f / ∫f` has the direction density `p(ω) = p(u, v) / (2π² sin θ)` (the
//! Jacobian of `(u, v) ↦ ω`, `dω = 2π² sin θ du dv`).

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::color::luminance;
use crate::scene::{EnvironmentMap, direction_to_uv, texel_at, uv_to_direction};

/// The probability with which next-event estimation picks the environment when the
/// scene also has area lights (both backends; docs/path-tracing.md).
pub const ENVIRONMENT_SELECTION: f64 = 0.5;

/// A 1D piecewise-constant distribution on `[0, 1)` of `n` cells (pbrt-v4's
/// `PiecewiseConstant1D`): `cdf[i] = Σ_{j<i} func[j] / (n · integral)`, `cdf[0] = 0`,
/// `cdf[n] = 1`; uniform when the function is zero everywhere.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    /// The function's value per cell (at least 0).
    pub func: Vec<f64>,
    /// `n + 1` cumulative values.
    pub cdf: Vec<f64>,
    /// `∫₀¹ f = Σ func / n`.
    pub integral: f64,
}

impl Distribution1D {
    /// The distribution of `func` (non-empty, every value finite and at least 0).
    pub fn new(func: Vec<f64>) -> Self {
        let n = func.len();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        for (i, f) in func.iter().enumerate() {
            cdf.push(cdf[i] + f / n as f64);
        }
        let integral = cdf[n];
        if integral > 0.0 {
            for c in &mut cdf {
                *c /= integral;
            }
        } else {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f64 / n as f64;
            }
        }
        cdf[n] = 1.0;
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// The cell `u ∈ [0, 1)` falls in, the largest `i < n` with `cdf[i] <= u`, and the
    /// point `(i + du) / n` of `[0, 1)` it maps to, `du` its position within the cell.
    pub fn sample(&self, u: f64) -> (usize, f64) {
        let n = self.func.len();
        let cell = self
            .cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1);
        let width = self.cdf[cell + 1] - self.cdf[cell];
        let mut du = u - self.cdf[cell];
        if width > 0.0 {
            du /= width;
        }
        (cell, (cell as f64 + du.clamp(0.0, 1.0)) / n as f64)
    }
}

/// One direction drawn from the environment: the unit world direction, its density
/// per steradian (the environment's selection not included) and the radiance
/// arriving along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvironmentSample {
    /// Unit direction, world space, towards the environment.
    pub wi: DVec3,
    /// Density per steradian.
    pub pdf: f64,
    /// Radiance of the texel sampled (scale included).
    pub radiance: DVec3,
}

/// An environment map with its sampling distribution and selection probability.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentLight {
    /// The map.
    pub map: Arc<EnvironmentMap>,
    /// Per row, the distribution over its texels of `f(x, y)`.
    pub conditional: Vec<Distribution1D>,
    /// The distribution over the rows of their integrals.
    pub marginal: Distribution1D,
    /// The probability that next-event estimation picks the environment: 0 for a
    /// black map (nothing to sample), 1 without area lights, else
    /// [`ENVIRONMENT_SELECTION`].
    pub selection: f64,
}

impl EnvironmentLight {
    /// The light of `map`, in a scene with area lights or without.
    pub fn new(map: Arc<EnvironmentMap>, has_area_lights: bool) -> Self {
        let (w, h) = (map.image.width, map.image.height);
        let texel_luminance: Vec<f64> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let t = map.image.texel(x, y);
                let c = DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
                luminance(c * map.scale)
            })
            .collect();
        let conditional: Vec<Distribution1D> = (0..h)
            .map(|y| {
                let sin_theta = (PI * (f64::from(y) + 0.5) / f64::from(h)).sin();
                let row = (0..w)
                    .map(|x| {
                        let (columns, rows) = cell_texels(x, y, w, h);
                        let brightest = rows
                            .flat_map(|r| columns.map(|c| (r * w + c) as usize))
                            .map(|i| texel_luminance[i])
                            .fold(0.0, f64::max);
                        let f = brightest * sin_theta;
                        if f.is_finite() { f.max(0.0) } else { 0.0 }
                    })
                    .collect();
                Distribution1D::new(row)
            })
            .collect();
        let marginal = Distribution1D::new(conditional.iter().map(|c| c.integral).collect());
        // The function's values are finite and at least 0, so the integral is never NaN.
        let selection = if marginal.integral <= 0.0 {
            0.0
        } else if has_area_lights {
            ENVIRONMENT_SELECTION
        } else {
            1.0
        };
        Self {
            map,
            conditional,
            marginal,
            selection,
        }
    }

    /// A direction drawn from `u ∈ [0, 1)²` (the row by `u.y`, the texel in it by
    /// `u.x`), or `None` at a pole or for a black map.
    pub fn sample(&self, u: DVec2) -> Option<EnvironmentSample> {
        if self.marginal.integral <= 0.0 {
            return None;
        }
        let (row, v) = self.marginal.sample(u.y);
        let (column, u) = self.conditional[row].sample(u.x);
        let pdf_uv = self.conditional[row].func[column] / self.marginal.integral;
        let sin_theta = (PI * v).sin();
        if !(sin_theta > 0.0 && pdf_uv > 0.0) {
            return None;
        }
        let radiance = self.map.radiance_at(DVec2::new(u, v));
        Some(EnvironmentSample {
            wi: self.map.to_world(uv_to_direction(DVec2::new(u, v))),
            pdf: pdf_uv / (2.0 * PI * PI * sin_theta),
            radiance,
        })
    }

    /// The density per steradian of [`EnvironmentLight::sample`] at the unit world
    /// direction `wi` (the selection not included).
    pub fn pdf(&self, wi: DVec3) -> f64 {
        if self.marginal.integral <= 0.0 {
            return 0.0;
        }
        let local = self.map.to_local(wi);
        let sin_theta = (1.0 - local.y * local.y).max(0.0).sqrt();
        if sin_theta == 0.0 {
            return 0.0;
        }
        let (x, y) = texel_at(
            direction_to_uv(local),
            self.map.image.width,
            self.map.image.height,
        );
        let f = self.conditional[y as usize].func[x as usize];
        f / self.marginal.integral / (2.0 * PI * PI * sin_theta)
    }
}

/// The columns and rows of the texels that the map's bilinear lookup
/// ([`crate::scene::Bilinear`]) blends somewhere in sampling cell (`x`, `y`) of a
/// `width × height` map: columns `x − 1`, `x`, `x + 1` (wrapping around; the cell spans
/// half a texel either side of column `x`'s centre), and the rows whose span
/// `v·(height − 1)` over the cell's `v` reaches, a row either side included.
pub fn cell_texels(
    x: u32,
    y: u32,
    width: u32,
    height: u32,
) -> ([u32; 3], std::ops::RangeInclusive<u32>) {
    let columns = [(x + width - 1) % width, x, (x + 1) % width];
    if height < 2 {
        return (columns, 0..=0);
    }
    let to_row = |v: f64| v * f64::from(height - 1);
    let top = to_row(f64::from(y) / f64::from(height)).floor() as u32;
    let bottom = to_row(f64::from(y + 1) / f64::from(height)).floor() as u32 + 1;
    (columns, top.min(height - 2)..=bottom.min(height - 1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Image;

    #[test]
    fn a_black_map_is_never_sampled_and_has_density_zero() {
        let map = EnvironmentMap {
            image: Image {
                path: "black.hdr".into(),
                width: 4,
                height: 2,
                texels: vec![[0.0, 0.0, 0.0, 1.0]; 8],
            },
            rotation_degrees: 0.0,
            scale: DVec3::ONE,
        };
        let light = EnvironmentLight::new(Arc::new(map), false);
        assert_eq!(light.selection, 0.0);
        assert_eq!(light.sample(DVec2::new(0.3, 0.7)), None);
        assert_eq!(light.pdf(DVec3::X), 0.0);
        // Its tables are uniform, not NaN.
        assert!(light.marginal.cdf.iter().all(|c| c.is_finite()));
    }

    #[test]
    fn the_density_is_positive_wherever_the_interpolated_radiance_is() {
        // One lit texel in a dark map, at every position of a 5 × 4 and a 3 × 1 map:
        // its bilinear footprint reaches into neighbouring cells, which must be
        // sampled too.
        for (w, h) in [(5u32, 4u32), (3, 1), (1, 3)] {
            for lit in 0..w * h {
                let mut texels = vec![[0.0, 0.0, 0.0, 1.0]; (w * h) as usize];
                texels[lit as usize] = [1.0, 1.0, 1.0, 1.0];
                let map = EnvironmentMap {
                    image: Image {
                        path: "dot.exr".into(),
                        width: w,
                        height: h,
                        texels,
                    },
                    rotation_degrees: 0.0,
                    scale: DVec3::ONE,
                };
                let light = EnvironmentLight::new(Arc::new(map), false);
                for i in 0..97 {
                    for j in 1..60 {
                        let uv = DVec2::new(f64::from(i) / 97.0, f64::from(j) / 60.0);
                        if light.map.radiance_at(uv).x > 0.0 {
                            let wi = light.map.to_world(uv_to_direction(uv));
                            assert!(
                                light.pdf(wi) > 0.0,
                                "{w}x{h}, texel {lit} lit: radiance at {uv} but density 0"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn cells_are_found_by_their_cumulative_values() {
        let d = Distribution1D::new(vec![1.0, 0.0, 3.0]);
        assert_eq!(d.cdf, vec![0.0, 0.25, 0.25, 1.0]);
        assert_eq!(d.sample(0.1).0, 0);
        assert_eq!(d.sample(0.25).0, 2);
        let (cell, x) = d.sample(0.625);
        assert_eq!(cell, 2);
        assert!((x - 2.5 / 3.0).abs() < 1e-12);
    }
}
