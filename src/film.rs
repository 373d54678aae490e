//! What a render produces: a linear float image and honest statistics.

use std::time::Duration;

use crate::color::{quantize_unorm8, srgb_encode};

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
}

impl RenderStats {
    /// Rays traced per second of wall time.
    pub fn rays_per_second(&self) -> f64 {
        let seconds = self.elapsed.as_secs_f64();
        if seconds > 0.0 {
            self.rays_traced as f64 / seconds
        } else {
            0.0
        }
    }
}

/// A callback told how many image rows are done out of how many, as a render proceeds.
pub type ProgressFn<'a> = &'a (dyn Fn(u32, u32) + Sync);

/// A finished render: the linear image and its statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// The linear float image.
    pub image: LinearImage,
    /// Ray count and time.
    pub stats: RenderStats,
}
