//! Renders with a per-pixel variance estimate, for comparisons with an independent
//! renderer's reference image (tests/integration/path_reference.rs, tests/integration/environment_reference.rs).

use glam::DVec3;
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::path::path_radiance;
use gpu_render::low_level::cpu::trace::PreparedScene;

/// Per pixel (row-major): the mean and the sample variance of `samples` path-traced
/// samples of `scene` (`width × height` pixels), on every core.
pub fn render_with_variance(
    scene: &PreparedScene,
    width: u32,
    height: u32,
    samples: u32,
) -> Vec<(DVec3, DVec3)> {
    let pixels: Vec<u32> = (0..width * height).collect();
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let chunk = pixels.len().div_ceil(threads);
    std::thread::scope(|scope| {
        let handles: Vec<_> = pixels
            .chunks(chunk)
            .map(|part| {
                scope.spawn(move || {
                    part.iter()
                        .map(|&p| {
                            let (x, y) = (p % width, p / width);
                            let (mut sum, mut squares) = (DVec3::ZERO, DVec3::ZERO);
                            for s in 0..samples {
                                let (dx, dy) = scene.samples.offset(x, y, s);
                                let direction = scene.camera.ray_direction(
                                    f64::from(x) + dx,
                                    f64::from(y) + dy,
                                    width,
                                    height,
                                );
                                let ray = Ray {
                                    origin: scene.camera.eye,
                                    direction,
                                };
                                let (radiance, _) = path_radiance(scene, ray, p, s);
                                sum += radiance;
                                squares += radiance * radiance;
                            }
                            let n = f64::from(samples);
                            let mean = sum / n;
                            let variance = (squares / n - mean * mean) * (n / (n - 1.0));
                            (mean, variance.max(DVec3::ZERO))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("render thread"))
            .collect()
    })
}

/// What a comparison with an independent reference gathered over the pixel values:
/// each value's z score, and per channel the two image sums and the variance of their
/// difference.
#[derive(Debug, Default)]
pub struct ReferenceComparison {
    /// `(ours − reference) / σ` of every value with a variance.
    pub z_values: Vec<f64>,
    /// Our image's sum per channel.
    pub our_total: DVec3,
    /// The reference's sum per channel.
    pub reference_total: DVec3,
    /// The variance of `our_total − reference_total` per channel.
    pub total_variance: DVec3,
}

impl ReferenceComparison {
    /// Asserts the stated agreement with the reference: at most 0.5% of the values
    /// beyond 4 standard errors, and each channel's image sum within 4 standard
    /// errors and 0.5% of the reference's. Prints the figures.
    pub fn assert_agrees(&self) {
        let n = self.z_values.len() as f64;
        let outliers = self.z_values.iter().filter(|z| z.abs() > 4.0).count();
        let difference = self.our_total - self.reference_total;
        let standard_error = DVec3::new(
            self.total_variance.x.sqrt(),
            self.total_variance.y.sqrt(),
            self.total_variance.z.sqrt(),
        );
        let relative = difference / self.reference_total;
        eprintln!(
            "{} values: {outliers} with |z| > 4; image means differ by {relative:.5} \
             (relative), {:.2} standard errors",
            self.z_values.len(),
            (difference / standard_error).abs().max_element()
        );
        assert!(
            outliers as f64 <= 0.005 * n,
            "{outliers} of {n} pixel values differ from the reference by more than 4 \
             standard errors"
        );
        for c in 0..3 {
            assert!(
                difference[c].abs() <= 4.0 * standard_error[c],
                "channel {c}: biased against the reference: the image sums differ by {} \
                 with a standard error of {}",
                difference[c],
                standard_error[c]
            );
            assert!(
                relative[c].abs() <= 0.005,
                "channel {c}: the image mean differs from the reference's by {:.3}%",
                100.0 * relative[c]
            );
        }
    }
}
