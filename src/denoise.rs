//! The built-in denoiser: an edge-avoiding à-trous wavelet filter (Dammertz, Sewtz,
//! Hanika and Lensch, "Edge-Avoiding À-Trous Wavelet Transform for fast Global
//! Illumination Filtering", HPG 2010) guided by the auxiliary passes (albedo, normal,
//! depth) and by each pixel's variance, as spatiotemporal variance-guided filtering
//! weighs it (Schied et al., "Spatiotemporal Variance-Guided Filtering", HPG 2017,
//! section 4.4, without the temporal part), on albedo-demodulated radiance.
//!
//! This is the CPU twin of the GPU filter: both work in `f32`, in the same order, so
//! that their images agree per pixel.

use crate::color::luminance;

// Intel Open Image Denoise, loaded at run time (feature `oidn`): the alternative to
// this module's filter, guided by the same albedo and normal passes. Documented by its
// own `//!` (an outer doc here would make its links resolve from this module).
#[cfg(feature = "oidn")]
#[path = "oidn.rs"]
pub mod oidn;

/// The auxiliary passes of a render that guide the filter, `width × height` each,
/// row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct GuidePasses {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// First-hit albedo (after textures) in [0, 1]; black where the camera ray escapes.
    pub albedo: Vec<[f32; 3]>,
    /// First-hit shading normal, unit length (world space); zero where the ray escapes.
    pub normal: Vec<[f32; 3]>,
    /// Distance along the camera ray to the first hit; 0 where the ray escapes.
    pub depth: Vec<f32>,
}

/// How strongly each guide stops the filter across an edge (the σ of SVGF's edge
/// stopping functions, section 4.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DenoiseSettings {
    /// Passes of the à-trous filter; pass `i` samples every `2^i`-th pixel, so 5
    /// passes reach 2 · 2^4 + ... = 62 pixels out (Dammertz et al. use 5).
    pub iterations: u32,
    /// Exponent of the normals' cosine (SVGF: 128).
    pub sigma_normal: f32,
    /// Depth difference, relative to the larger of the two depths and per pixel of the
    /// pass's tap spacing, that weighs `e^-1`.
    pub sigma_depth: f32,
    /// Luminance difference, in standard deviations of the pixel's noise, that weighs
    /// `e^-1` (SVGF: 4).
    pub sigma_luminance: f32,
    /// Albedo difference (the mean of the channels' absolute differences) that weighs
    /// `e^-1`. SVGF has no albedo stop, only demodulation; without it an emitter
    /// (albedo 0, no noise) and the wall around it (same normal and depth) blurred
    /// into each other on the Cornell box (`BENCHMARKS.md`, "Denoiser").
    pub sigma_albedo: f32,
}

impl Default for DenoiseSettings {
    fn default() -> Self {
        Self {
            iterations: 5,
            sigma_normal: 128.0,
            sigma_depth: 0.1,
            sigma_luminance: 4.0,
            sigma_albedo: 0.1,
        }
    }
}

/// The B3-spline taps of the à-trous kernel (Dammertz et al., section 3).
const KERNEL: [f32; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

/// Smallest albedo a pixel is demodulated by; darker albedos are kept as they are (an
/// escaped ray, a black surface) and filtered as radiance.
const MIN_ALBEDO: f32 = 1e-3;

/// Variances above this (a pixel of fewer than two samples has an infinite one, see
/// [`crate::noise::standard_error`]) are taken as this, which stops nothing: the
/// filter then follows the geometry alone.
pub const MAX_VARIANCE: f32 = 1e30;

/// Denoises `radiance` (`width × height` linear RGB pixels) guided by `guides` and
/// each pixel's `variance` (of its mean's luminance, the square of the noise
/// estimate's standard error). Returns the filtered radiance; pixels whose variance
/// is 0 (converged) keep their value unless their neighbours agree with them.
///
/// ```
/// use gpu_render::low_level::denoise::{GuidePasses, DenoiseSettings, denoise};
/// let guides = GuidePasses {
///     width: 2, height: 1,
///     albedo: vec![[0.5; 3]; 2], normal: vec![[0.0, 0.0, 1.0]; 2], depth: vec![1.0; 2],
/// };
/// let out = denoise(&[[0.2; 3], [0.4; 3]], &[0.01, 0.01], &guides, &DenoiseSettings::default());
/// assert!((out[0][0] - out[1][0]).abs() < 0.2);
/// ```
///
/// # Panics
///
/// If the buffers do not all hold `width × height` pixels.
pub fn denoise(
    radiance: &[[f32; 3]],
    variance: &[f32],
    guides: &GuidePasses,
    settings: &DenoiseSettings,
) -> Vec<[f32; 3]> {
    let pixels = guides.width as usize * guides.height as usize;
    assert!(
        radiance.len() == pixels
            && variance.len() == pixels
            && guides.albedo.len() == pixels
            && guides.normal.len() == pixels
            && guides.depth.len() == pixels,
        "every buffer must hold {pixels} pixels"
    );
    let mut signal: Vec<[f32; 3]> = radiance
        .iter()
        .zip(&guides.albedo)
        .map(|(&c, &a)| demodulate(c, a))
        .collect();
    let mut var: Vec<f32> = variance
        .iter()
        .zip(&guides.albedo)
        .map(|(&v, &a)| v.min(MAX_VARIANCE) / demodulation_scale(a).powi(2))
        .collect();
    for iteration in 0..settings.iterations {
        let step = 1i32 << iteration;
        let (next, next_var) = atrous_pass(&signal, &var, guides, settings, step);
        signal = next;
        var = next_var;
    }
    signal
        .iter()
        .zip(&guides.albedo)
        .map(|(&c, &a)| remodulate(c, a))
        .collect()
}

/// The factor a pixel's radiance is divided by: its albedo's mean, or 1 for albedos
/// too dark to divide by.
fn demodulation_scale(albedo: [f32; 3]) -> f32 {
    let mean = (albedo[0] + albedo[1] + albedo[2]) / 3.0;
    if mean > MIN_ALBEDO { mean } else { 1.0 }
}

/// Radiance divided by its albedo, per channel where the channel is bright enough.
fn demodulate(radiance: [f32; 3], albedo: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|c| {
        if albedo[c] > MIN_ALBEDO {
            radiance[c] / albedo[c]
        } else {
            radiance[c]
        }
    })
}

/// The inverse of [`demodulate`].
fn remodulate(signal: [f32; 3], albedo: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|c| {
        if albedo[c] > MIN_ALBEDO {
            signal[c] * albedo[c]
        } else {
            signal[c]
        }
    })
}

/// One pass of the filter with taps `step` pixels apart: each pixel's weighted mean of
/// its 5x5 taps, and the variance of that mean (Σ w² var / (Σ w)², SVGF eq. 7).
fn atrous_pass(
    signal: &[[f32; 3]],
    variance: &[f32],
    guides: &GuidePasses,
    settings: &DenoiseSettings,
    step: i32,
) -> (Vec<[f32; 3]>, Vec<f32>) {
    let (width, height) = (guides.width as i32, guides.height as i32);
    let mut out = vec![[0.0f32; 3]; signal.len()];
    let mut out_var = vec![0.0f32; signal.len()];
    for y in 0..height {
        for x in 0..width {
            let p = (y * width + x) as usize;
            let l_p = luminance_f32(signal[p]);
            // The luminance edge stop scales with the pixel's noise, blurred over its
            // 3x3 neighbourhood so that a single noisy estimate does not decide it.
            let sigma_l =
                settings.sigma_luminance * blurred_variance(variance, x, y, width, height).sqrt();
            let mut sum = [0.0f32; 3];
            let mut sum_var = 0.0f32;
            let mut weights = 0.0f32;
            for (j, ky) in KERNEL.iter().enumerate() {
                let qy = y + (j as i32 - 2) * step;
                if qy < 0 || qy >= height {
                    continue;
                }
                for (i, kx) in KERNEL.iter().enumerate() {
                    let qx = x + (i as i32 - 2) * step;
                    if qx < 0 || qx >= width {
                        continue;
                    }
                    let q = (qy * width + qx) as usize;
                    let w = kx
                        * ky
                        * edge_weight(p, q, l_p, signal[q], sigma_l, guides, settings, step);
                    for c in 0..3 {
                        sum[c] += w * signal[q][c];
                    }
                    sum_var += w * w * variance[q];
                    weights += w;
                }
            }
            // The centre tap has weight 3/8 · 3/8 · 1 > 0, so `weights` is positive.
            out[p] = sum.map(|s| s / weights);
            out_var[p] = sum_var / (weights * weights);
        }
    }
    (out, out_var)
}

/// The edge-stopping weight of tap `q` for pixel `p` (SVGF eq. 3-6): normals, depth
/// and luminance, and albedo; 1 for the pixel itself, so that every pixel keeps a weight however
/// its guides stop the others. The normals' cosine is taken between their directions:
/// a pixel's mean normal is shorter than 1 where its samples see several surfaces.
#[allow(clippy::too_many_arguments)]
fn edge_weight(
    p: usize,
    q: usize,
    l_p: f32,
    signal_q: [f32; 3],
    sigma_l: f32,
    guides: &GuidePasses,
    settings: &DenoiseSettings,
    step: i32,
) -> f32 {
    if p == q {
        return 1.0;
    }
    let (n_p, n_q) = (unit_normal(guides.normal[p]), unit_normal(guides.normal[q]));
    let cosine = (n_p[0] * n_q[0] + n_p[1] * n_q[1] + n_p[2] * n_q[2]).max(0.0);
    // Escaped rays have no normal: they filter only with each other.
    let both_escaped = guides.depth[p] <= 0.0 && guides.depth[q] <= 0.0;
    let w_normal = if both_escaped {
        1.0
    } else {
        cosine.powf(settings.sigma_normal)
    };
    let (z_p, z_q) = (guides.depth[p], guides.depth[q]);
    let scale = settings.sigma_depth * z_p.max(z_q).max(1e-6) * step as f32;
    let w_depth = (-(z_p - z_q).abs() / scale).exp();
    let l_q = luminance_f32(signal_q);
    let w_luminance = (-(l_p - l_q).abs() / (sigma_l + 1e-10)).exp();
    let (a_p, a_q) = (guides.albedo[p], guides.albedo[q]);
    let albedo_difference =
        ((a_p[0] - a_q[0]).abs() + (a_p[1] - a_q[1]).abs() + (a_p[2] - a_q[2]).abs()) / 3.0;
    let w_albedo = (-albedo_difference / settings.sigma_albedo).exp();
    w_normal * w_depth * w_luminance * w_albedo
}

/// `n` scaled to unit length, or zero for a zero normal.
fn unit_normal(n: [f32; 3]) -> [f32; 3] {
    let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if length > 0.0 {
        n.map(|c| c / length)
    } else {
        [0.0; 3]
    }
}

/// The variance of pixel (x, y) blurred by a 3x3 Gaussian (SVGF section 4.4).
fn blurred_variance(variance: &[f32], x: i32, y: i32, width: i32, height: i32) -> f32 {
    const GAUSS: [f32; 3] = [0.25, 0.5, 0.25];
    let mut sum = 0.0f32;
    let mut weights = 0.0f32;
    for (j, gy) in GAUSS.iter().enumerate() {
        let qy = y + j as i32 - 1;
        if qy < 0 || qy >= height {
            continue;
        }
        for (i, gx) in GAUSS.iter().enumerate() {
            let qx = x + i as i32 - 1;
            if qx < 0 || qx >= width {
                continue;
            }
            let w = gx * gy;
            sum += w * variance[(qy * width + qx) as usize];
            weights += w;
        }
    }
    sum / weights
}

/// Luminance in `f32` with the project's one set of weights.
fn luminance_f32(c: [f32; 3]) -> f32 {
    luminance(glam::DVec3::new(
        f64::from(c[0]),
        f64::from(c[1]),
        f64::from(c[2]),
    )) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat_guides(width: u32, height: u32) -> GuidePasses {
        let n = (width * height) as usize;
        GuidePasses {
            width,
            height,
            albedo: vec![[0.5; 3]; n],
            normal: vec![[0.0, 0.0, 1.0]; n],
            depth: vec![2.0; n],
        }
    }

    /// A fixed pseudo-random sequence in [0, 1) (a multiplicative hash).
    fn noise(i: usize) -> f32 {
        let h = (i as u32 ^ 0x9e37_79b9)
            .wrapping_mul(0x85eb_ca6b)
            .rotate_left(13);
        let h = h.wrapping_mul(0xc2b2_ae35);
        (h >> 8) as f32 / (1u32 << 24) as f32
    }

    #[test]
    fn a_converged_image_passes_through_unchanged() {
        let guides = flat_guides(16, 12);
        let image: Vec<[f32; 3]> = (0..192).map(|i| [0.1 + 0.004 * i as f32; 3]).collect();
        let out = denoise(&image, &[0.0; 192], &guides, &DenoiseSettings::default());
        for (a, b) in image.iter().zip(&out) {
            assert!(
                (a[0] - b[0]).abs() <= 1e-3 * a[0].max(1.0),
                "{a:?} -> {b:?}"
            );
        }
    }

    #[test]
    fn a_noisy_constant_image_converges_to_the_constant() {
        let guides = flat_guides(32, 32);
        let n = 32 * 32;
        // Mean 0.25, noise ±0.2 (a uniform spread of variance 0.2²/3).
        let image: Vec<[f32; 3]> = (0..n).map(|i| [0.25 + 0.4 * (noise(i) - 0.5); 3]).collect();
        let variance = vec![0.4 * 0.4 / 12.0; n];
        let out = denoise(&image, &variance, &guides, &DenoiseSettings::default());
        let error = |img: &[[f32; 3]]| {
            (img.iter().map(|p| (p[0] - 0.25).powi(2)).sum::<f32>() / n as f32).sqrt()
        };
        assert!(
            error(&out) < error(&image) / 5.0,
            "rms error {} -> {}",
            error(&image),
            error(&out)
        );
    }

    #[test]
    fn no_blur_across_an_albedo_or_a_depth_edge() {
        let (w, h) = (24u32, 8u32);
        let n = (w * h) as usize;
        // A checker of albedo 0.1 and 0.9 under uniform light 1: radiance = albedo,
        // with a little noise.
        let mut guides = flat_guides(w, h);
        let mut image = Vec::with_capacity(n);
        for i in 0..n {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let a = if (x / 4 + y / 4) % 2 == 0 { 0.1 } else { 0.9 };
            guides.albedo[i] = [a; 3];
            image.push([a * (1.0 + 0.1 * (noise(i) - 0.5)); 3]);
        }
        let variance = vec![0.01 / 12.0; n];
        let out = denoise(&image, &variance, &guides, &DenoiseSettings::default());
        for (i, (pixel, albedo)) in out.iter().zip(&guides.albedo).enumerate() {
            let a = albedo[0];
            assert!(
                (pixel[0] - a).abs() < 0.05 * a + 0.01,
                "pixel {i}: {} for albedo {a}",
                pixel[0]
            );
        }
        // A depth edge: the left half at depth 1 in light 1, the right half at depth
        // 10 in light 0.2; the two never mix.
        let mut guides = flat_guides(w, h);
        let mut image = Vec::with_capacity(n);
        for i in 0..n {
            let left = (i as u32 % w) < w / 2;
            guides.depth[i] = if left { 1.0 } else { 10.0 };
            guides.albedo[i] = [1.0; 3];
            let light = if left { 1.0 } else { 0.2 };
            image.push([light * (1.0 + 0.1 * (noise(i) - 0.5)); 3]);
        }
        let out = denoise(&image, &variance, &guides, &DenoiseSettings::default());
        for (i, pixel) in out.iter().enumerate() {
            let left = (i as u32 % w) < w / 2;
            let light = if left { 1.0 } else { 0.2 };
            assert!(
                (pixel[0] - light).abs() < 0.06 * light,
                "pixel {i}: {} for {light}",
                pixel[0]
            );
        }
    }

    #[test]
    fn an_emitter_does_not_bleed_into_the_wall_around_it() {
        // The Cornell box's light in its ceiling: the same normal and depth, the light
        // of albedo 0 and radiance 17 without noise, the ceiling of albedo 0.73 and
        // radiance 0.1 with noise, its edge pixels' variance large.
        let (w, h) = (24u32, 8u32);
        let n = (w * h) as usize;
        let mut guides = flat_guides(w, h);
        let mut image = Vec::with_capacity(n);
        let mut variance = Vec::with_capacity(n);
        for i in 0..n {
            let x = i as u32 % w;
            let light = x < w / 2;
            guides.albedo[i] = if light { [0.0; 3] } else { [0.73; 3] };
            image.push(if light {
                [17.0; 3]
            } else {
                [0.1 * (1.0 + (noise(i) - 0.5)); 3]
            });
            variance.push(if light {
                0.0
            } else if x == w / 2 {
                10.0
            } else {
                1e-3
            });
        }
        let out = denoise(&image, &variance, &guides, &DenoiseSettings::default());
        for (i, pixel) in out.iter().enumerate() {
            let light = (i as u32 % w) < w / 2;
            if light {
                assert!(
                    (pixel[0] - 17.0).abs() < 0.2,
                    "light pixel {i}: {}",
                    pixel[0]
                );
            } else {
                assert!(pixel[0] < 0.2, "wall pixel {i}: {}", pixel[0]);
            }
        }
    }
}
