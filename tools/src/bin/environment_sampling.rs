//! What importance sampling of an environment map buys: renders a path-traced scene
//! with a map twice on the CPU reference at the same samples per pixel, with the map's
//! next-event estimation (the default: luminance-proportional directions, MIS with
//! the BRDF) and without it (its selection probability set to 0, so only BRDF-sampled
//! escapes find the map, with weight 1), and prints each one's mean per-pixel variance
//! of the luminance, its time, and the variance ratio (the factor in samples the
//! sampler saves). Figures in BENCHMARKS.md.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin environment_sampling -- tests/fixtures/mitsuba/env-lambert.toml 64
//! ```

use std::time::Instant;

use glam::DVec3;
use gpu_render::low_level::color::luminance;
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::path::path_radiance;
use gpu_render::low_level::cpu::trace::PreparedScene;

/// Mean over the pixels of the sample variance of the luminance, and the seconds taken.
fn mean_variance(scene: &PreparedScene, samples: u32) -> (f64, f64) {
    let (width, height) = (scene.settings.width, scene.settings.height);
    let start = Instant::now();
    let mut total = 0.0;
    for p in 0..width * height {
        let (x, y) = (p % width, p / width);
        let (mut sum, mut squares) = (0.0, 0.0);
        for s in 0..samples {
            let (dx, dy) = scene.samples.offset(x, y, s);
            let direction =
                scene
                    .camera
                    .ray_direction(f64::from(x) + dx, f64::from(y) + dy, width, height);
            let ray = Ray {
                origin: scene.camera.eye,
                direction,
            };
            let (radiance, _): (DVec3, u64) = path_radiance(scene, ray, p, s);
            let l = luminance(radiance);
            sum += l;
            squares += l * l;
        }
        let n = f64::from(samples);
        let mean = sum / n;
        total += (squares / n - mean * mean) * n / (n - 1.0);
    }
    (
        total / f64::from(width * height),
        start.elapsed().as_secs_f64(),
    )
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or_else(|| anyhow::anyhow!("usage: environment_sampling SCENE.toml [SPP]"))?;
    let samples: u32 = args.next().map_or(Ok(64), |s| s.parse())?;
    anyhow::ensure!(samples >= 2, "need at least 2 samples per pixel");
    let scene = gpu_render::scene::load_scene(std::path::Path::new(&path))?;
    let sampled = PreparedScene::new(&scene);
    anyhow::ensure!(
        sampled.environment.is_some(),
        "{path} has no environment map"
    );
    let mut unsampled = sampled.clone();
    if let Some(environment) = &mut unsampled.environment {
        environment.selection = 0.0;
    }
    let (with, with_time) = mean_variance(&sampled, samples);
    let (without, without_time) = mean_variance(&unsampled, samples);
    println!(
        "{path}, {}x{}, {samples} spp: mean pixel variance {with:.4e} with the map sampled \
         ({with_time:.2} s), {without:.4e} by BRDF sampling alone ({without_time:.2} s): \
         {:.2}x less variance",
        scene.render.width,
        scene.render.height,
        without / with
    );
    Ok(())
}
