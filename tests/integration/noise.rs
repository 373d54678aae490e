//! The per-pixel noise estimate (`src/noise.rs`, `shaders/noise.wgsl`).
//!
//! - On the CPU reference, the estimated standard error matches the spread of
//!   independent pixel means: with a field of view of a thousandth of a degree every
//!   pixel of a path-traced Cornell box sees the same point of the back wall and draws
//!   its own random numbers, so the pixels are independent renders of one pixel, and
//!   the variance of their means must equal the mean of their estimated squared
//!   standard errors within four standard errors of the empirical variance (computed
//!   from the data's fourth moment).
//! - The GPU's estimate equals the CPU's per pixel (both draw the same samples): in a
//!   one-shot render and in a progressive film whose samples arrive in passes, within
//!   `1e-6 + 1e-3·se` (f32 sums and Welford steps against f64; measured on lavapipe,
//!   2026-12-01: no pixel outside it, the largest difference 2.4e-7 on 48x48 Cornell
//!   boxes at 8 spp, whose standard errors are 1e-3 to 1), with the outlier fraction of
//!   `tests/integration/path_gpu.rs` for paths that branch differently in f32.

use gpu_render::gpu::{Renderer, RendererOptions};
use gpu_render::low_level::noise::NoiseEstimate;
use gpu_render::scene::{Integrator, RenderOverrides, Scene};

/// The largest fraction of pixels allowed outside the tolerance (as `tests/integration/path_gpu.rs`).
const OUTLIERS: f64 = 0.005;

/// The Cornell box at `width` pixels and `samples` spp, with the given integrator.
fn cornell(width: u32, samples: u32, integrator: Integrator) -> Scene {
    crate::support::scenes::reduced(
        crate::support::scenes::shipped("cornell-box.toml"),
        width,
        RenderOverrides {
            samples_per_pixel: Some(samples),
            integrator: Some(integrator),
            ..RenderOverrides::default()
        },
    )
}

#[test]
fn cpu_estimate_matches_the_spread_of_independent_pixel_means() {
    // Two samples per pixel, so that a wrong n/(n − 1) would be a factor of 2.
    let mut scene = cornell(48, 2, Integrator::Path);
    scene.camera.fov_y_degrees = 1e-3;
    let rendered = gpu_render::cpu::render_with_noise(&scene, None);
    let noise = rendered.noise.as_ref().expect("asked for");
    assert_eq!(noise.samples, 2);
    let n = noise.mean_luminance.len() as f64;
    let means: Vec<f64> = noise.mean_luminance.iter().map(|&y| f64::from(y)).collect();
    let mean = means.iter().sum::<f64>() / n;
    let deviations: Vec<f64> = means.iter().map(|y| y - mean).collect();
    let variance = deviations.iter().map(|d| d * d).sum::<f64>() / (n - 1.0);
    let fourth = deviations.iter().map(|d| d.powi(4)).sum::<f64>() / n;
    // The sampling variance of a sample variance: (m4 − σ⁴ (n − 3)/(n − 1)) / n.
    let variance_error = ((fourth - variance * variance * (n - 3.0) / (n - 1.0)) / n).sqrt();
    let estimated = noise
        .standard_error
        .iter()
        .map(|&se| f64::from(se) * f64::from(se))
        .sum::<f64>()
        / n;
    eprintln!(
        "variance of {n} pixel means {variance:.4e} ± {variance_error:.1e}; mean estimated \
         se² {estimated:.4e}; mean luminance {mean:.4}"
    );
    assert!(variance > 0.0, "the pixels must differ");
    assert!(
        (estimated - variance).abs() <= 4.0 * variance_error,
        "estimated se² {estimated:.4e} vs the spread of the means {variance:.4e} \
         (± {variance_error:.1e})"
    );
    // Enough pixels that an estimate off by n/(n − 1) = 2 would be caught.
    assert!(variance_error < 0.1 * variance, "too few pixels to tell");
    let relative = noise.relative_error().expect("an estimate");
    assert!((relative - estimated.sqrt() / mean).abs() < 1e-9);
}

/// Asserts that two estimates agree pixel by pixel and in their summary.
fn assert_estimates_match(label: &str, cpu: &NoiseEstimate, gpu: &NoiseEstimate) {
    assert_eq!((cpu.width, cpu.height), (gpu.width, gpu.height), "{label}");
    assert_eq!(cpu.samples, gpu.samples, "{label}");
    let mut outliers = 0;
    let mut largest = 0.0f32;
    for (c, g) in cpu.standard_error.iter().zip(&gpu.standard_error) {
        let difference = (c - g).abs();
        largest = largest.max(difference);
        if difference.is_nan() || difference > 1e-6 + 1e-3 * c {
            outliers += 1;
        }
    }
    let pixels = cpu.standard_error.len();
    eprintln!(
        "{label}: {outliers} of {pixels} standard errors outside tolerance, largest \
         difference {largest:.2e}; relative error CPU {:?}, GPU {:?}",
        cpu.relative_error(),
        gpu.relative_error()
    );
    assert!(
        outliers as f64 <= OUTLIERS * pixels as f64,
        "{label}: {outliers} of {pixels} pixels' standard errors differ"
    );
    let (c, g) = (
        cpu.relative_error().expect("a CPU estimate"),
        gpu.relative_error().expect("a GPU estimate"),
    );
    assert!((c - g).abs() <= 1e-4 * c, "{label}: {c} vs {g}");
}

#[test]
fn gpu_estimates_equal_the_cpu_reference_per_pixel() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            noise_estimate: true,
            ..RendererOptions::default()
        },
    );
    for (label, scene) in [
        ("path-traced Cornell box", cornell(48, 8, Integrator::Path)),
        ("Whitted Cornell box", cornell(48, 8, Integrator::Whitted)),
    ] {
        let cpu = gpu_render::cpu::render_with_noise(&scene, None);
        let rendered = renderer
            .render(&gpu.device, &gpu.queue, &scene, None)
            .unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let noise = rendered.noise.expect("asked for");
        assert_estimates_match(label, cpu.noise.as_ref().expect("asked for"), &noise);
    }
    // Without the option nothing is kept or read, on either backend.
    let small = cornell(8, 2, Integrator::Path);
    let plain = crate::support::gpu::renderer(&gpu)
        .render(&gpu.device, &gpu.queue, &small, None)
        .expect("render");
    assert!(plain.noise.is_none());
    assert!(gpu_render::cpu::render(&small, None).noise.is_none());
}

#[test]
fn a_progressive_film_estimates_what_a_one_shot_cpu_render_does() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = Renderer::new(&gpu.device, RendererOptions::default())
        .unwrap_or_else(|e| panic!("Renderer::new: {e}"));
    let scene = cornell(48, 8, Integrator::Path);
    let gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let mut film = renderer
        .create_film(
            &gpu.device,
            &gpu_scene,
            scene.render.width,
            scene.render.height,
        )
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    // Three passes: each later one starts from the sums and m2 the last left.
    for samples in [1, 3, 4] {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer
            .encode_samples(
                &gpu.device,
                &gpu.queue,
                &mut encoder,
                &gpu_scene,
                &mut film,
                samples,
            )
            .unwrap_or_else(|e| panic!("encode_samples: {e}"));
        gpu.queue.submit([encoder.finish()]);
        renderer
            .finish(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
            .unwrap_or_else(|e| panic!("finish: {e}"));
    }
    let noise = renderer
        .read_noise(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
        .unwrap_or_else(|e| panic!("read_noise: {e}"));
    assert_eq!(noise.samples, 8);
    let cpu = gpu_render::cpu::render_with_noise(&scene, None);
    assert_estimates_match(
        "progressive film",
        cpu.noise.as_ref().expect("asked for"),
        &noise,
    );
}
