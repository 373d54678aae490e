//! What a render produces: a linear float image and honest statistics.

use std::time::Duration;

use crate::color::{quantize_unorm8, srgb_encode};
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
