//! The pinhole camera (with an optional thin lens) and the pixel sample pattern, shared
//! by both backends. The GPU twin is `shaders/camera.wgsl` (`sample_offset`,
//! `lens_sample`, `camera_ray`, `ray_direction` as `camera_ray_direction`); the hash is
//! [`crate::sample::pcg_hash`].

use glam::{DVec2, DVec3};

use crate::sample::{pcg_hash, sample_concentric_disk, unit_from_hash};
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
    /// An orthographic camera's half view height in scene units
    /// ([`Camera::orthographic_half_height`]); `None` for a pinhole camera.
    pub orthographic_half_height: Option<f64>,
    /// Radius of the thin lens ([`crate::scene::ThinLens`]); 0 for a pinhole.
    pub lens_radius: f64,
    /// Distance from the eye to the plane in focus along `forward` (unused without a
    /// lens).
    pub focus_distance: f64,
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
            orthographic_half_height: camera.orthographic_half_height,
            lens_radius: camera.lens.map_or(0.0, |lens| lens.aperture_radius),
            focus_distance: camera.lens.map_or(0.0, |lens| {
                lens.focus_distance_for(camera.eye, camera.look_at)
            }),
        }
    }

    /// The origin and unit direction of camera ray through image position (`x`, `y`)
    /// (as [`CameraFrame::ray_direction`] measures it), the lens point chosen by
    /// `lens` in [0, 1)² ([`lens_sample`]). A pinhole's ray is
    /// ([`CameraFrame::ray_origin`], [`CameraFrame::ray_direction`]). Through a thin
    /// lens (pbrt-v4 §5.2.3) the ray starts at the lens point
    /// `eye + r·(right·d.x + up·d.y)`, `d` the concentric disk map of `lens`
    /// ([`sample_concentric_disk`]), and passes through the point where the pinhole
    /// ray meets the plane in focus, `eye + p·focus / (p·forward)` for the pinhole
    /// direction `p`.
    pub fn camera_ray(
        &self,
        x: f64,
        y: f64,
        width: u32,
        height: u32,
        lens: DVec2,
    ) -> (DVec3, DVec3) {
        let direction = self.ray_direction(x, y, width, height);
        let origin = self.ray_origin(x, y, width, height);
        if self.lens_radius <= 0.0 {
            return (origin, direction);
        }
        let focus = self.eye + direction * (self.focus_distance / direction.dot(self.forward));
        let disk = sample_concentric_disk(lens) * self.lens_radius;
        let origin = self.eye + self.right * disk.x + self.up * disk.y;
        (origin, (focus - origin).normalize())
    }

    /// The unit direction of the ray through image position (`x`, `y`) in pixels,
    /// measured from the top-left corner of the image (pixel centres at `i + 0.5`):
    /// the view direction itself for an orthographic camera.
    pub fn ray_direction(&self, x: f64, y: f64, width: u32, height: u32) -> DVec3 {
        if self.orthographic_half_height.is_some() {
            return self.forward;
        }
        let ndc_x = 2.0 * x / f64::from(width) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / f64::from(height);
        (self.forward
            + self.right * (ndc_x * self.aspect * self.tan_half_fov_y)
            + self.up * (ndc_y * self.tan_half_fov_y))
            .normalize()
    }

    /// The ray cone of a camera ray of an image `height` pixels high rendered with
    /// `samples_per_pixel` samples, for the texture level of detail: its width at the
    /// ray's origin and its spread, the growth of its width per unit distance,
    /// `2·tan(α/2)` with the pixel's spread angle `α = atan(2·tan(fov_y/2) / height)`
    /// (Akenine-Möller et al., "Texture Level of Detail Strategies for Real-Time Ray
    /// Tracing", Ray Tracing Gems ch. 20, 2019, eq. 30; "Improved Shader and Texture
    /// Level of Detail Using Ray Cones", JCGT 10(1), 2021, §3), both scaled by
    /// [`cone_sample_scale`]: the pixel's samples already average over it, so each
    /// filters only its share. A pinhole's cone starts at width 0; an orthographic
    /// camera's rays are parallel: width one pixel's height in scene units (scaled),
    /// spread 0. A thin lens is taken as its pinhole (its defocus is not part of the
    /// footprint: the cone is right at the plane in focus and too narrow elsewhere).
    pub fn pixel_cone(&self, height: u32, samples_per_pixel: u32) -> PixelCone {
        let height = f64::from(height.max(1));
        let scale = cone_sample_scale(samples_per_pixel);
        match self.orthographic_half_height {
            Some(half_height) => PixelCone {
                width: 2.0 * half_height / height * scale,
                spread: 0.0,
            },
            None => {
                let alpha = (2.0 * self.tan_half_fov_y / height).atan();
                PixelCone {
                    width: 0.0,
                    spread: 2.0 * (0.5 * alpha).tan() * scale,
                }
            }
        }
    }

    /// Where the ray through image position (`x`, `y`) starts: the eye for a pinhole
    /// camera; for an orthographic one the point of the view plane through the eye
    /// that the position maps to, `eye + right·(ndc_x·aspect·h) + up·(ndc_y·h)` with
    /// `h` the half height (glTF 2.0 §3.10.3, the orthographic projection).
    pub fn ray_origin(&self, x: f64, y: f64, width: u32, height: u32) -> DVec3 {
        let Some(half_height) = self.orthographic_half_height else {
            return self.eye;
        };
        let ndc_x = 2.0 * x / f64::from(width) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / f64::from(height);
        self.eye
            + self.right * (ndc_x * self.aspect * half_height)
            + self.up * (ndc_y * half_height)
    }
}

/// The share of a pixel's footprint each of its `samples_per_pixel` samples filters
/// textures over: `max(1/8, 1/√n)`, the scale pbrt gives its camera rays' differentials
/// (Pharr, Jakob and Humphreys, "Physically Based Rendering", 3rd ed., §7.2: the
/// `ScaleDifferentials` call of `SamplerIntegrator::Render`; 4th ed., §5.1, with the
/// floor of 1/8). `n` samples stratified over the pixel each cover about `1/n` of
/// its area, so a full pixel's cone per sample would blur the texture twice, by the
/// samples' average and by the lookup.
pub fn cone_sample_scale(samples_per_pixel: u32) -> f64 {
    (1.0 / f64::from(samples_per_pixel.max(1)).sqrt()).max(0.125)
}

/// A camera ray's cone ([`CameraFrame::pixel_cone`]): at distance `t` from the ray's
/// origin it is `width + spread·t` wide.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PixelCone {
    /// The width at the ray's origin, in scene units.
    pub width: f64,
    /// The growth of the width per unit distance along the ray, `2·tan(α/2)`.
    pub spread: f64,
}

/// The second coordinate of Sobol's sequence in base 2 as 32 fraction bits: the XOR of
/// the direction numbers `v_k` of the set bits `k` of `index`, `v_0 = 2⁻¹` and `v_k =
/// v_{k−1} ⊕ (v_{k−1} >> 1)` (the primitive polynomial `x + 1`: the generator matrix
/// is Pascal's triangle mod 2). With the van der Corput first coordinate
/// (`index.reverse_bits()`) it makes the (0,2)-sequence: every aligned block of `2^k`
/// points is a (0,k,2)-net, one point in each of the `2^k` equal dyadic boxes of every
/// shape (Sobol, "On the distribution of points in a cube", USSR Comp. Math. 1967;
/// Niederreiter 1992, §4). Twin of `sobol_second` in `shaders/camera.wgsl`.
pub fn sobol_second(index: u32) -> u32 {
    let (mut bits, mut direction, mut rest) = (0u32, 0x8000_0000u32, index);
    while rest != 0 {
        if rest & 1 == 1 {
            bits ^= direction;
        }
        direction ^= direction >> 1;
        rest >>= 1;
    }
    bits
}

/// A nested uniform (Owen) scramble of the 32 fraction bits `bits` seeded by `seed`:
/// each bit is flipped by a hash of the bits above it, so that every dyadic interval
/// maps onto one of the same length: a (0,k,2)-net stays one, and every point becomes
/// uniform on [0, 1). The hash is Laine and Karras's, on the reversed bits, with the
/// constants of Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020,
/// listing 3 (`nested_uniform_scramble`). Twin of `owen_scramble`.
pub fn owen_scramble(bits: u32, seed: u32) -> u32 {
    let mut x = bits.reverse_bits().wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x.reverse_bits()
}

/// The sample pattern of one render: [`sample_offset`] for its image width and
/// sample count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SamplePattern {
    /// Image width (the pixel index is `y · width + x`).
    pub width: u32,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
}

impl SamplePattern {
    /// The pattern of a render with `settings`.
    pub fn new(settings: &RenderSettings) -> Self {
        Self {
            width: settings.width,
            samples_per_pixel: settings.samples_per_pixel,
        }
    }

    /// [`sample_offset`] of sample `index` of pixel (`px`, `py`).
    pub fn offset(&self, px: u32, py: u32, index: u32) -> (f64, f64) {
        if self.samples_per_pixel <= 1 {
            return (0.5, 0.5);
        }
        let pixel_index = py.wrapping_mul(self.width).wrapping_add(px);
        let seed_x = pcg_hash(pixel_index);
        let seed_y = pcg_hash(seed_x);
        (
            unit_from_hash(owen_scramble(index.reverse_bits(), seed_x)),
            unit_from_hash(owen_scramble(sobol_second(index), seed_y)),
        )
    }
}

/// The hash of sample `index` of pixel `pixel_index` that seeds its lens point
/// ([`lens_sample`]). The samples of the pattern (`index < spp`) hash `pixel_index ·
/// spp + index`, one number per sample of the image. A progressive render's later
/// rounds (`index ≥ spp`, round `r = index / spp`) hash that first-round seed again
/// mixed with the round, so that they repeat neither their own first round's lens
/// points nor a neighbour's (`pixel_index · spp + index` would be the next pixel's).
pub fn sample_seed(pixel_index: u32, spp: u32, index: u32) -> u32 {
    let round = index / spp;
    let first = pcg_hash(pixel_index.wrapping_mul(spp).wrapping_add(index % spp));
    if round == 0 {
        first
    } else {
        pcg_hash(first ^ pcg_hash(round))
    }
}

/// The point of the unit square that picks the lens point of sample `index` of pixel
/// `pixel_index` ([`CameraFrame::camera_ray`]): a hash of the sample's seed
/// ([`sample_seed`]) salted apart from other uses of it, so that the lens point and
/// the image position vary independently. Both backends pick the same points.
pub fn lens_sample(pixel_index: u32, spp: u32, index: u32) -> DVec2 {
    let seed = pcg_hash(sample_seed(pixel_index, spp.max(1), index) ^ LENS_SALT);
    DVec2::new(unit_from_hash(seed), unit_from_hash(pcg_hash(seed)))
}

/// XORed into a sample's seed for its lens point ([`lens_sample`]): the 32-bit
/// golden ratio, any constant that separates the two streams would do.
pub const LENS_SALT: u32 = 0x9e37_79b9;

/// The offset inside pixel (`px`, `py`) of sample `index`, in [0, 1)². One sample goes
/// through the pixel centre (as in the lecture). With `n > 1` samples, sample `i` is
/// point `i` of Sobol's (0,2)-sequence (van der Corput's radical inverse, then
/// [`sobol_second`]), each coordinate Owen-scrambled ([`owen_scramble`]) by a hash of
/// the pixel: for `n = 2^k` the pixel's samples are a (0,k,2)-net (exactly one in every
/// column and every row of `n`, one in every cell of a `√n × √n` grid, and in every
/// other dyadic box of area `1/n`), any `n` samples lie in distinct columns and rows of
/// the next power of two, every sample is uniform over the pixel (so the box-filter
/// mean is unbiased), and a progressive render's later samples go on with the same
/// sequence, so each further aligned block of `2^k` is a net too and together they
/// make finer ones. pbrt-v4's default sampler is the same construction
/// (`ZSobolSampler`; Pharr, Jakob and Humphreys, 4th ed., §8.7). Integer arithmetic
/// and the same 24 bits of each coordinate on both backends: identical positions.
pub fn sample_offset(px: u32, py: u32, index: u32, settings: &RenderSettings) -> (f64, f64) {
    SamplePattern::new(settings).offset(px, py, index)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(width: u32, samples_per_pixel: u32) -> RenderSettings {
        RenderSettings {
            width,
            samples_per_pixel,
            ..RenderSettings::default()
        }
    }

    #[test]
    fn a_pixel_cone_spreads_by_a_pixel_per_unit_distance() {
        let camera = Camera {
            eye: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Y,
            fov_y_degrees: 60.0,
            orthographic_half_height: None,
            lens: None,
        };
        let frame = CameraFrame::new(&camera, 1920, 1080);
        let cone = frame.pixel_cone(1080, 1);
        assert_eq!(cone.width, 0.0);
        // A pixel's height at unit distance, 2·tan(30°)/1080, to first order in α.
        let pixel = 2.0 * (30f64).to_radians().tan() / 1080.0;
        assert!((cone.spread / pixel - 1.0).abs() < 1e-6, "{cone:?}");
        // Exactly 2·tan(α/2) with tan α = 2·tan(fov/2)/height: 1 for 90° over 2 rows.
        let wide = CameraFrame::new(
            &Camera {
                fov_y_degrees: 90.0,
                ..camera
            },
            2,
            2,
        );
        let expected = 2.0 * (std::f64::consts::FRAC_PI_8).tan();
        assert!((wide.pixel_cone(2, 1).spread - expected).abs() < 1e-12);
        // n samples per pixel filter 1/√n of it each, down to an eighth.
        assert!((wide.pixel_cone(2, 4).spread - expected / 2.0).abs() < 1e-12);
        assert!((wide.pixel_cone(2, 1024).spread - expected / 8.0).abs() < 1e-12);
        // Orthographic rays are parallel, a pixel's height apart.
        let orthographic = CameraFrame::new(
            &Camera {
                orthographic_half_height: Some(3.0),
                ..camera
            },
            640,
            480,
        );
        let cone = orthographic.pixel_cone(480, 1);
        assert_eq!((cone.width, cone.spread), (6.0 / 480.0, 0.0));
    }

    /// Whether `points` (in [0, 1)²) hold exactly one point in each of the `2^k` dyadic
    /// boxes of every shape `2^-a × 2^-(k-a)`, `2^k` being their number.
    fn is_net(points: &[(f64, f64)]) -> bool {
        let n = points.len();
        let k = n.trailing_zeros();
        (0..=k).all(|a| {
            let (columns, rows) = (1usize << a, 1usize << (k - a));
            let mut hits = vec![0u32; n];
            for &(x, y) in points {
                let cell = (y * rows as f64) as usize * columns + (x * columns as f64) as usize;
                hits[cell] += 1;
            }
            hits.iter().all(|&h| h == 1)
        })
    }

    #[test]
    fn the_sobol_sequence_is_the_published_one() {
        // Unscrambled: (0, 0), (1/2, 1/2), (1/4, 3/4), (3/4, 1/4), (1/8, 5/8),
        // (5/8, 1/8), (3/8, 3/8), (7/8, 7/8) (Sobol 1967; Joe and Kuo's table).
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, y) in expected.into_iter().enumerate() {
            assert_eq!(
                f64::from(sobol_second(i as u32)) / 2f64.powi(32),
                y,
                "i={i}"
            );
        }
        let points: Vec<(f64, f64)> = (0..1024u32)
            .map(|i| {
                let unit = |bits: u32| f64::from(bits) / 2f64.powi(32);
                (unit(i.reverse_bits()), unit(sobol_second(i)))
            })
            .collect();
        for k in 0..=10 {
            assert!(is_net(&points[..1 << k]), "first {} points", 1 << k);
        }
    }

    #[test]
    fn owen_scrambling_maps_dyadic_intervals_onto_dyadic_intervals() {
        // The top k bits of the result depend on the top k bits of the input only, and
        // the scramble is a bijection (of 16-bit prefixes here).
        for seed in [0u32, 1, 0xdead_beef, pcg_hash(7)] {
            let mut seen = vec![false; 1 << 16];
            for top in 0..(1u32 << 16) {
                let a = owen_scramble(top << 16, seed);
                let b = owen_scramble((top << 16) | pcg_hash(top) >> 16, seed);
                assert_eq!(a >> 16, b >> 16, "seed {seed} prefix {top}");
                assert!(!std::mem::replace(&mut seen[(a >> 16) as usize], true));
            }
        }
    }

    #[test]
    fn powers_of_two_fill_every_dyadic_box_and_other_counts_distinct_strata() {
        for n in 2..=300u32 {
            let strata = n.next_power_of_two();
            for (px, py) in [(0, 0), (7, 3), (639, 479)] {
                let points: Vec<(f64, f64)> = (0..n)
                    .map(|i| sample_offset(px, py, i, &settings(640, n)))
                    .collect();
                assert!(
                    points
                        .iter()
                        .all(|&(x, y)| (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y))
                );
                if n.is_power_of_two() {
                    assert!(is_net(&points), "n={n} pixel ({px}, {py}): {points:?}");
                }
                // Any count: no two samples share a column or a row of the next power of
                // two (a prefix of a net).
                let mut columns = vec![0u32; strata as usize];
                let mut rows = vec![0u32; strata as usize];
                for &(x, y) in &points {
                    columns[(x * f64::from(strata)) as usize] += 1;
                    rows[(y * f64::from(strata)) as usize] += 1;
                }
                assert!(columns.iter().chain(&rows).all(|&h| h <= 1), "n={n}");
            }
        }
    }

    #[test]
    fn every_sample_is_uniform_over_the_pixel() {
        // Owen scrambling makes each sample uniform on the pixel, so the box-filter mean
        // is unbiased for every count: over 65,536 pixels, the mean of sample i's
        // offset is 1/2 and its variance 1/12, within 5 standard errors.
        let pixels = 65_536u32;
        for (n, index) in [(3, 2), (5, 4), (32, 17), (100, 99)] {
            let pattern = SamplePattern::new(&settings(256, n));
            let (mut sum, mut square) = (DVec2::ZERO, DVec2::ZERO);
            for p in 0..pixels {
                let (x, y) = pattern.offset(p % 256, p / 256, index);
                let v = DVec2::new(x, y);
                sum += v;
                square += v * v;
            }
            let mean = sum / f64::from(pixels);
            let variance = square / f64::from(pixels) - mean * mean;
            let error = 5.0 * (1.0f64 / 12.0 / f64::from(pixels)).sqrt();
            assert!((mean - 0.5).abs().max_element() < error, "n={n}: {mean:?}");
            assert!((variance - 1.0 / 12.0).abs().max_element() < 0.002, "n={n}");
        }
    }

    #[test]
    fn pixels_get_different_patterns() {
        let a: Vec<_> = (0..16)
            .map(|i| sample_offset(0, 0, i, &settings(64, 16)))
            .collect();
        let b: Vec<_> = (0..16)
            .map(|i| sample_offset(1, 0, i, &settings(64, 16)))
            .collect();
        assert_ne!(a, b);
        assert_eq!(sample_offset(3, 4, 0, &settings(64, 1)), (0.5, 0.5));
    }

    #[test]
    fn centre_ray_looks_forward() {
        let camera = Camera {
            eye: DVec3::ZERO,
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_y_degrees: 90.0,
            orthographic_half_height: None,
            lens: None,
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
    fn later_rounds_go_on_with_the_sequence() {
        // A progressive render's rounds past the pattern: each round of a power of two
        // is a net of its own, unlike the rounds before it, and the rounds together
        // make a finer net (4 rounds of 4: one of 16).
        for (px, py) in [(0, 0), (9, 2)] {
            let points: Vec<(f64, f64)> = (0..16)
                .map(|i| sample_offset(px, py, i, &settings(64, 4)))
                .collect();
            assert!(is_net(&points));
            for round in points.chunks(4) {
                assert!(is_net(round));
            }
            assert_ne!(points[..4], points[4..8]);
        }
        // The lens point's seed: the first round is the pattern's own sample index.
        assert_eq!(sample_seed(7, 16, 3), pcg_hash(7 * 16 + 3));
        assert_ne!(sample_seed(7, 16, 19), sample_seed(7, 16, 3));
        assert_ne!(sample_seed(7, 16, 19), sample_seed(8, 16, 3));
    }
}
