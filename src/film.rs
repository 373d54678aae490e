//! What a render produces: a linear float image, its noise estimate and honest
//! statistics; and the measure of an image's error against a reference.

use std::time::Duration;

use glam::DVec3;

use crate::color::{luminance, quantize_unorm8, srgb_encode};
use crate::noise::NoiseEstimate;

/// A linear-light RGBA image in 32-bit float, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels of linear RGB radiance and alpha 1.
    pub pixels: Vec<[f32; 4]>,
}

impl LinearImage {
    /// A black image of the given size.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![[0.0, 0.0, 0.0, 1.0]; width as usize * height as usize],
        }
    }

    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Encodes to 8-bit RGBA with the exact sRGB curve (`encode = true`) or by
    /// clamping only (`encode = false`, for naive gamma-space renders), matching the
    /// GPU's display pass.
    pub fn to_display_rgba8(&self, encode: bool) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(self.pixels.len() * 4);
        for p in &self.pixels {
            for &c in &p[..3] {
                let v = if encode {
                    srgb_encode(f64::from(c))
                } else {
                    f64::from(c)
                };
                bytes.push(quantize_unorm8(v));
            }
            bytes.push(255);
        }
        bytes
    }
}

/// Counts and timings of one render.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RenderStats {
    /// Rays actually traced: primary, shadow, reflected and refracted, each counted
    /// once when it is intersected with the scene.
    pub rays_traced: u64,
    /// Wall time of the render (tracing only, without scene loading or file output).
    pub elapsed: Duration,
    /// GPU time of the trace passes, measured with timestamp queries: for each
    /// submitted chunk, from the start of its first trace pass to the end of its last,
    /// summed over the chunks. `None` where the device lacks
    /// [`wgpu::Features::TIMESTAMP_QUERY`], for the CPU reference, and where the
    /// timestamps could not be trusted (see [`crate::gpu::Renderer::render`]).
    pub gpu_time: Option<Duration>,
}

/// Where a trace time came from; see [`RenderStats::trace_time`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TimingSource {
    /// GPU timestamp queries around the trace passes ([`RenderStats::gpu_time`]).
    GpuTimestamps,
    /// Host wall-clock time around the tracing ([`RenderStats::elapsed`]).
    WallClock,
}

impl std::fmt::Display for TimingSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TimingSource::GpuTimestamps => "GPU timestamps",
            TimingSource::WallClock => "wall clock",
        })
    }
}

impl RenderStats {
    /// Rays traced per second of wall time ([`RenderStats::elapsed`]).
    pub fn rays_per_second(&self) -> f64 {
        per_second(self.rays_traced, self.elapsed.as_secs_f64())
    }

    /// The best measure of the tracing time: [`RenderStats::gpu_time`] where it was
    /// measured, else the wall time [`RenderStats::elapsed`], and which one it is.
    pub fn trace_time(&self) -> (Duration, TimingSource) {
        match self.gpu_time {
            Some(gpu) => (gpu, TimingSource::GpuTimestamps),
            None => (self.elapsed, TimingSource::WallClock),
        }
    }

    /// [`RenderStats::trace_time`] in seconds.
    pub fn trace_seconds(&self) -> (f64, TimingSource) {
        let (time, source) = self.trace_time();
        (time.as_secs_f64(), source)
    }

    /// Rays traced per second of [`RenderStats::trace_time`], and which time that is.
    pub fn trace_rays_per_second(&self) -> (f64, TimingSource) {
        let (seconds, source) = self.trace_seconds();
        (per_second(self.rays_traced, seconds), source)
    }
}

/// `count / seconds`, or 0 for a zero time.
fn per_second(count: u64, seconds: f64) -> f64 {
    if seconds > 0.0 {
        count as f64 / seconds
    } else {
        0.0
    }
}

/// A callback told how many image rows are done out of how many, as a render proceeds.
pub type ProgressFn<'a> = &'a (dyn Fn(u32, u32) + Sync);

/// A finished render: the linear image, its noise estimate and its statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// The linear float image.
    pub image: LinearImage,
    /// Each pixel's standard error, from the spread of its samples, where asked for
    /// ([`crate::cpu::render_with_noise`]).
    pub noise: Option<NoiseEstimate>,
    /// Ray count and times.
    pub stats: RenderStats,
}

// Here rather than in src/noise.rs: a film holds its noise estimate, so the estimate
// stays below the film and knows no images.
impl NoiseEstimate {
    /// The standard errors as a grey linear image (R = G = B = the standard error,
    /// alpha 1), for writing as EXR.
    pub fn standard_error_image(&self) -> LinearImage {
        LinearImage {
            width: self.width,
            height: self.height,
            pixels: self
                .standard_error
                .iter()
                .map(|&se| [se, se, se, 1.0])
                .collect(),
        }
    }
}

/// Relative RMSE of `image`'s luminance against `reference`'s:
/// `√(mean over pixels (Y − Y_ref)²) / mean over pixels Y_ref`, with `Y` the
/// [`luminance`] of a pixel. The error measure of the tradeoff's time-to-1%
/// figures (`docs/quality.md`), and the one [`NoiseEstimate::relative_error`]
/// predicts. Infinite for a black reference.
pub fn relative_rmse(reference: &LinearImage, image: &LinearImage) -> f64 {
    let luminance = |p: &[f32; 4]| {
        luminance(DVec3::new(
            f64::from(p[0]),
            f64::from(p[1]),
            f64::from(p[2]),
        ))
    };
    let mut squares = 0.0;
    let mut total = 0.0;
    for (r, x) in reference.pixels.iter().zip(&image.pixels) {
        let (r, x) = (luminance(r), luminance(x));
        squares += (x - r) * (x - r);
        total += r;
    }
    let count = reference.pixels.len().max(1) as f64;
    let mean = total / count;
    if mean > 0.0 {
        (squares / count).sqrt() / mean
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_rmse_of_a_uniform_offset() {
        let mut reference = LinearImage::new(4, 2);
        reference
            .pixels
            .iter_mut()
            .for_each(|p| *p = [2.0, 2.0, 2.0, 1.0]);
        let mut image = reference.clone();
        image.pixels.iter_mut().for_each(|p| p[0] = 2.2);
        // Red off by 0.2 in every pixel: luminance off by 0.2126 · 0.2, mean 2.
        let expected = 0.2126 * 0.2 / 2.0;
        assert!((relative_rmse(&reference, &image) - expected).abs() < 1e-6);
        assert_eq!(relative_rmse(&reference, &reference), 0.0);
    }
}
