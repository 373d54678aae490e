//! The GPU-against-CPU check the twin tests share: render one scene on both backends,
//! compare per pixel in linear float (`super::compare`, which writes both images and a
//! difference under `target/test-output/` on failure), and compare the rays each
//! counted.

use gpu_render::film::RenderStats;
use gpu_render::gpu::{HeadlessGpu, Renderer};
use gpu_render::scene::Scene;

use super::compare::{Comparison, Tolerance, assert_images_match};

/// The GPU-against-CPU tolerance of the twin tests: a channel passes within `1e-3 +
/// 5e-3·|cpu|` (f32 against f64), and 0.5% of the pixels may fail it (a sample that
/// grazes an edge, or a branch taken the other way within rounding, lands on either
/// side).
pub const TWIN_TOLERANCE: Tolerance = Tolerance {
    absolute: 1e-3,
    relative: 5e-3,
    outlier_fraction: 0.005,
};

/// Both backends count the rays they trace; their counts must agree within `fraction`
/// of the CPU's.
pub fn assert_ray_counts_agree(label: &str, cpu: &RenderStats, gpu: &RenderStats, fraction: f64) {
    let (c, g) = (cpu.rays_traced as f64, gpu.rays_traced as f64);
    assert!(
        (c - g).abs() <= fraction * c,
        "{label}: ray counts differ: CPU {c}, GPU {g}"
    );
}

/// Renders `scene` with the CPU reference and with `renderer`, asserts that every GPU
/// pixel is finite, that the images agree within `tolerance` and that the ray counts
/// agree within 1%; prints what it measured and returns it.
pub fn assert_backends_agree(
    gpu: &HeadlessGpu,
    renderer: &Renderer,
    label: &str,
    scene: &Scene,
    tolerance: Tolerance,
) -> Comparison {
    let cpu = gpu_render::cpu::render(scene, None);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
    assert!(
        gpu_image
            .image
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite())),
        "{label}: the GPU image has non-finite pixels"
    );
    let comparison = assert_images_match(label, &cpu.image, &gpu_image.image, tolerance);
    eprintln!(
        "{label}: {} of {} pixels outside tolerance, max |Δ| {:.2e}, RMSE {:.2e}; rays CPU {}, \
         GPU {}",
        comparison.outliers,
        comparison.pixels,
        comparison.max_abs_error,
        comparison.rmse,
        cpu.stats.rays_traced,
        gpu_image.stats.rays_traced
    );
    assert_ray_counts_agree(label, &cpu.stats, &gpu_image.stats, 0.01);
    comparison
}
