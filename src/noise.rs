//! The per-pixel noise estimate of a render: how far each pixel's mean luminance may
//! still be from its converged value, from the spread of the pixel's own samples.
//!
//! Both backends keep, per pixel and next to the sample sum, Welford's running sum of
//! squared deviations `M2` of the samples' luminance (B. P. Welford, "Note on a Method
//! for Calculating Corrected Sums of Squares and Products", Technometrics 4(3), 1962;
//! Knuth, TAOCP vol. 2, 3rd ed., §4.2.2, eq. 15–16), updated in the same step that adds
//! the sample to the sum: [`luminance_m2_step`] here and its twin of the same name in
//! `shaders/noise.wgsl`. That is one number per pixel whatever the sample count, so
//! the GPU keeps it in the unused fourth float of the accumulation buffer.
//!
//! After `n ≥ 2` samples the unbiased sample variance of a pixel's luminance is
//! `s² = M2 / (n − 1)` and the standard error of its mean is `s / √n` (the mean of `n`
//! independent samples; our stratified samples are not quite independent, which only
//! makes the true error smaller). [`NoiseEstimate::relative_error`] summarises the
//! image: `√(mean over pixels of se²) / mean over pixels of the mean luminance`, the
//! expected relative RMSE of the luminance image against its converged value
//! (`E[(Ȳ − μ)²] = σ²/n`).

use glam::DVec3;

use crate::color::luminance;

/// Welford's update of a pixel's `m2` for its sample number `index` (0-based) of
/// luminance `luminance`: `sum_before` is the radiance sum of the samples before it,
/// `sum_after` the sum with it. The running means are taken from the sums, which the
/// backends keep anyway: `M2 += (y − mean_before)(y − mean_after)` (Welford 1962).
pub fn luminance_m2_step(
    m2: f64,
    sum_before: DVec3,
    sum_after: DVec3,
    luminance: f64,
    index: u32,
) -> f64 {
    let mean_before = if index == 0 {
        0.0
    } else {
        crate::color::luminance(sum_before) / f64::from(index)
    };
    let mean_after = crate::color::luminance(sum_after) / (f64::from(index) + 1.0);
    m2 + (luminance - mean_before) * (luminance - mean_after)
}

/// The standard error of the mean luminance of a pixel from its `m2` after `samples`
/// samples: `√(M2 / (n (n − 1)))`; infinite (unknown) below two samples or for a
/// non-finite `m2`. Rounding can leave a tiny negative `m2` where every sample is
/// equal: it counts as 0.
pub fn standard_error(m2: f64, samples: u32) -> f64 {
    if samples < 2 || !m2.is_finite() {
        return f64::INFINITY;
    }
    let n = f64::from(samples);
    (m2.max(0.0) / (n * (n - 1.0))).sqrt()
}

/// The noise estimate of a render: per pixel, its mean luminance and the standard
/// error of that mean, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseEstimate {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel the estimate is over.
    pub samples: u32,
    /// `width * height` mean luminances ([`luminance`] of the mean radiance).
    pub mean_luminance: Vec<f32>,
    /// `width * height` standard errors of the mean luminance ([`standard_error`]);
    /// infinite below two samples.
    pub standard_error: Vec<f32>,
}

impl NoiseEstimate {
    /// The estimate from each pixel's radiance sum and luminance `m2` after `samples`
    /// samples, row-major.
    pub fn from_sums(
        width: u32,
        height: u32,
        samples: u32,
        sums: impl IntoIterator<Item = (DVec3, f64)>,
    ) -> Self {
        let n = f64::from(samples.max(1));
        let (mean_luminance, standard_error) = sums
            .into_iter()
            .map(|(sum, m2)| {
                (
                    (luminance(sum) / n) as f32,
                    self::standard_error(m2, samples) as f32,
                )
            })
            .unzip();
        Self {
            width,
            height,
            samples,
            mean_luminance,
            standard_error,
        }
    }

    /// The standard error of pixel (`x`, `y`).
    pub fn pixel_standard_error(&self, x: u32, y: u32) -> f32 {
        self.standard_error[y as usize * self.width as usize + x as usize]
    }

    /// The estimated relative error of the image: `√(mean se²) / mean(mean
    /// luminance)`, the expected relative RMSE of its luminance against the converged
    /// image. `None` below two samples, for a black image, or where a pixel's
    /// estimate is not finite.
    pub fn relative_error(&self) -> Option<f64> {
        let count = self.standard_error.len().max(1) as f64;
        let mean_square = self
            .standard_error
            .iter()
            .map(|&se| f64::from(se) * f64::from(se))
            .sum::<f64>()
            / count;
        let mean = self
            .mean_luminance
            .iter()
            .map(|&y| f64::from(y))
            .sum::<f64>()
            / count;
        let relative = mean_square.sqrt() / mean;
        (relative.is_finite() && mean > 0.0).then_some(relative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Welford's M2 over a known list equals the two-pass sum of squared deviations.
    #[test]
    fn welford_steps_match_the_two_pass_formula() {
        let values = [0.0, 1.0, 4.0, 0.5, 2.5, 1.0, 0.0, 3.0];
        let mut sum = DVec3::ZERO;
        let mut m2 = 0.0;
        for (i, &v) in values.iter().enumerate() {
            let rgb = DVec3::splat(v);
            let before = sum;
            sum += rgb;
            m2 = luminance_m2_step(m2, before, sum, luminance(rgb), i as u32);
        }
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let two_pass: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
        assert!(
            (m2 - two_pass).abs() < 1e-12 * two_pass,
            "{m2} vs {two_pass}"
        );
        let n = values.len() as f64;
        let se = standard_error(m2, values.len() as u32);
        assert!((se - (two_pass / (n - 1.0) / n).sqrt()).abs() < 1e-12);
    }

    // Grey's own luminance, once part of this test, is tested with `luminance` in
    // src/color.rs.
    #[test]
    fn one_sample_and_a_non_finite_m2_are_unknown() {
        assert!(standard_error(1.0, 1).is_infinite());
        assert!(standard_error(f64::NAN, 8).is_infinite());
        assert_eq!(standard_error(-1e-20, 8), 0.0);
        let estimate = NoiseEstimate::from_sums(1, 1, 1, [(DVec3::ONE, 0.0)]);
        assert_eq!(estimate.relative_error(), None);
    }
}
