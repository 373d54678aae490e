//! The pinhole camera and the pixel sample pattern, shared by both backends.
//! The GPU twin is `shaders/sampling.wgsl` (`camera_ray`, `sample_offset`, `pcg_hash`).

use glam::DVec3;

use crate::scene::{Camera, RenderSettings};

/// An orthonormal camera basis with the projection constants, ready to generate rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraFrame {
    /// Centre of projection.
    pub eye: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit right vector.
    pub right: DVec3,
    /// Unit up vector, orthogonal to `forward` and `right`.
    pub up: DVec3,
    /// `tan(fov_y / 2)`.
    pub tan_half_fov_y: f64,
    /// Width over height.
    pub aspect: f64,
}

impl CameraFrame {
    /// Builds the basis of a validated camera for an image of `width × height`.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.look_at - camera.eye).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        Self {
            eye: camera.eye,
            forward,
            right,
            up,
            tan_half_fov_y: (camera.fov_y_degrees.to_radians() * 0.5).tan(),
            aspect: f64::from(width) / f64::from(height),
        }
    }

    /// The unit direction of the ray through image position (`x`, `y`) in pixels,
    /// measured from the top-left corner of the image (pixel centres at `i + 0.5`).
    pub fn ray_direction(&self, x: f64, y: f64, width: u32, height: u32) -> DVec3 {
        let ndc_x = 2.0 * x / f64::from(width) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / f64::from(height);
        (self.forward
            + self.right * (ndc_x * self.aspect * self.tan_half_fov_y)
            + self.up * (ndc_y * self.tan_half_fov_y))
            .normalize()
    }
}

/// PCG hash of one 32-bit word (Jarzynski and Olano, "Hash Functions for GPU
/// Rendering", JCGT 2020): the same bits on CPU and GPU.
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A uniform number in [0, 1) from the top 24 bits of a hash: exact in `f32`.
pub fn unit_from_hash(hash: u32) -> f64 {
    f64::from(hash >> 8) * (1.0 / 16_777_216.0)
}

/// Number of stratum columns and rows for `samples_per_pixel` samples: a grid of
/// `ceil(sqrt(n))` columns and as many rows as needed.
pub fn strata_grid(samples_per_pixel: u32) -> (u32, u32) {
    let mut columns = (f64::from(samples_per_pixel)).sqrt() as u32;
    if columns * columns < samples_per_pixel {
        columns += 1;
    }
    let rows = samples_per_pixel.div_ceil(columns);
    (columns, rows)
}

/// The offset inside pixel (`px`, `py`) of sample `index`, in [0, 1)². One sample goes
/// through the pixel centre (as in the lecture); more are jittered stratified: sample
/// `i` lies in cell (`i mod columns`, `i div columns`) of the [`strata_grid`], jittered
/// by a hash of the pixel and sample index, so both backends pick identical positions.
pub fn sample_offset(px: u32, py: u32, index: u32, settings: &RenderSettings) -> (f64, f64) {
    let spp = settings.samples_per_pixel;
    if spp <= 1 {
        return (0.5, 0.5);
    }
    let (columns, rows) = strata_grid(spp);
    let pixel_index = py.wrapping_mul(settings.width).wrapping_add(px);
    let seed = pcg_hash(pixel_index.wrapping_mul(spp).wrapping_add(index));
    let jitter_x = unit_from_hash(seed);
    let jitter_y = unit_from_hash(pcg_hash(seed));
    (
        (f64::from(index % columns) + jitter_x) / f64::from(columns),
        (f64::from(index / columns) + jitter_y) / f64::from(rows),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_cover_every_sample() {
        for n in 1..200 {
            let (c, r) = strata_grid(n);
            assert!(c * r >= n && c * (r - 1) < n, "n={n} c={c} r={r}");
        }
    }

    #[test]
    fn centre_ray_looks_forward() {
        let camera = Camera {
            eye: DVec3::ZERO,
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_y_degrees: 90.0,
        };
        let frame = CameraFrame::new(&camera, 200, 100);
        let d = frame.ray_direction(100.0, 50.0, 200, 100);
        assert!((d - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        // The top edge of a 90° field of view is 45° up.
        let top = frame.ray_direction(100.0, 0.0, 200, 100);
        assert!((top.y - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        // The right edge spans aspect * tan(45°) = 2.
        let right = frame.ray_direction(200.0, 50.0, 200, 100);
        assert!((right.x / -right.z - 2.0).abs() < 1e-12);
    }

    #[test]
    fn pcg_hash_matches_reference_values() {
        // Values computed by hand from the published algorithm.
        let state = 747_796_405u32.wrapping_add(2_891_336_453);
        let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
        assert_eq!(pcg_hash(1), (word >> 22) ^ word);
        assert_ne!(pcg_hash(0), pcg_hash(1));
    }
}
