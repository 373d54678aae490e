//! Renders with a per-pixel variance estimate, for comparisons with an independent
//! renderer's reference image (tests/path_reference.rs, tests/environment_reference.rs).

use glam::DVec3;
use gpu_render::cpu::intersect::Ray;
use gpu_render::cpu::path::path_radiance;
use gpu_render::cpu::trace::PreparedScene;

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
