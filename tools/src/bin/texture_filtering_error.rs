//! Measures texture filtering (issue 28 item 3): the RMSE (linear float, over pixels
//! and channels) of a scene rendered at its samples per pixel with `texture_filtering
//! = "anisotropic"`, `"trilinear"` and `"none"`, against an unfiltered reference of
//! many samples per pixel (the pixel's box-filtered integral the filter approximates),
//! on the CPU reference and, where there is an adapter, the GPU; and each render's
//! time, the median of `RUNS` runs, the modes alternating.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin texture_filtering_error -- \
//!     [SCENE] [REFERENCE_SPP] [RUNS]
//! ```
//!
//! Defaults: `scenes/bench/horizon-checker.toml`, 1,024 reference samples, 3 runs.

use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use gpu_render::film::LinearImage;
use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions};
use gpu_render::low_level::tradeoff::rmse;
use gpu_render::scene::{Scene, TextureFiltering, load_scene};

/// `scene` with `filtering`.
fn with_filtering(scene: &Scene, filtering: TextureFiltering) -> Scene {
    let mut scene = scene.clone();
    scene.render.texture_filtering = filtering;
    scene
}

/// The median of `times`.
fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

/// The filtering modes measured, the unfiltered one last (the ratios' denominator).
const MODES: [(TextureFiltering, &str); 3] = [
    (TextureFiltering::Anisotropic, "anisotropic"),
    (TextureFiltering::Trilinear, "trilinear"),
    (TextureFiltering::None, "none"),
];

/// Renders the scene in every mode of [`MODES`] `runs` times each, alternating, with
/// `render`; prints their RMSE against `reference`, their ratio to the unfiltered
/// RMSE and their median times (and, with `TEXTURE_FILTERING_BANDS` set, the RMSE
/// of eight bands of rows, top to bottom).
fn measure(
    label: &str,
    scenes: &[Scene],
    reference: &LinearImage,
    runs: usize,
    mut render: impl FnMut(&Scene) -> Result<LinearImage>,
) -> Result<()> {
    let mut times = vec![Vec::new(); scenes.len()];
    let mut images = vec![None; scenes.len()];
    for _ in 0..runs {
        for (i, scene) in scenes.iter().enumerate() {
            let start = Instant::now();
            let image = render(scene)?;
            times[i].push(start.elapsed());
            images[i] = Some(image);
        }
    }
    let images: Vec<LinearImage> = images
        .into_iter()
        .map(|i| i.context("no run"))
        .collect::<Result<_>>()?;
    let errors: Vec<f64> = images.iter().map(|i| rmse(i, reference)).collect();
    let unfiltered = errors[errors.len() - 1];
    println!("{label}:");
    for (((_, name), error), times) in MODES.iter().zip(&errors).zip(times) {
        println!(
            "  {name:<12} RMSE {error:.5}  ratio {:.3}  median {:.2?}",
            error / unfiltered,
            median(times)
        );
    }
    if std::env::var_os("TEXTURE_FILTERING_BANDS").is_some() {
        let band = |image: &LinearImage, b: usize| {
            let rows = image.height as usize / 8;
            let span = b * rows * image.width as usize..(b + 1) * rows * image.width as usize;
            let part = |i: &LinearImage| LinearImage {
                width: i.width,
                height: rows as u32,
                pixels: i.pixels[span.clone()].to_vec(),
            };
            rmse(&part(image), &part(reference))
        };
        for b in 0..8 {
            let row: Vec<String> = MODES
                .iter()
                .zip(&images)
                .map(|((_, name), image)| format!("{name} {:.5}", band(image, b)))
                .collect();
            println!("  band {b}: {}", row.join("  "));
        }
    }
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .map_or("scenes/bench/horizon-checker.toml", String::as_str);
    let reference_spp: u32 = args.get(1).map_or(Ok(1024), |s| s.parse())?;
    let runs: usize = args.get(2).map_or(Ok(3), |s| s.parse())?;
    let scene = load_scene(path.as_ref()).with_context(|| format!("loading {path}"))?;
    let scenes: Vec<Scene> = MODES
        .iter()
        .map(|(mode, _)| with_filtering(&scene, *mode))
        .collect();
    let mut reference_scene = with_filtering(&scene, TextureFiltering::None);
    reference_scene.render.samples_per_pixel = reference_spp;
    let start = Instant::now();
    let reference = gpu_render::cpu::render(&reference_scene, None).image;
    println!(
        "{path}: {}x{} at {} spp against an unfiltered {reference_spp}-spp CPU reference \
         ({:.1?}); medians of {runs} alternating runs",
        scene.render.width,
        scene.render.height,
        scene.render.samples_per_pixel,
        start.elapsed()
    );
    measure("CPU", &scenes, &reference, runs, |s| {
        Ok(gpu_render::cpu::render(s, None).image)
    })?;
    match HeadlessGpu::new(&AdapterChoice::Default) {
        Ok(gpu) => {
            let renderer = Renderer::new(&gpu.device, RendererOptions::default())?;
            let label = format!("GPU ({})", gpu.adapter.get_info().name);
            measure(&label, &scenes, &reference, runs, |s| {
                Ok(renderer.render(&gpu.device, &gpu.queue, s, None)?.image)
            })?;
        }
        Err(e) => println!("GPU: none ({e})"),
    }
    Ok(())
}
