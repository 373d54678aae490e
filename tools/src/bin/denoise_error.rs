//! Measures the denoisers (issue 29): relative MSE against a converged reference at 1,
//! 4, 16 and 64 samples per pixel, raw, built-in filter and (built with the `oidn`
//! feature) Intel Open Image Denoise, on the CPU reference (the GPU filter equals the
//! built-in one per pixel: `tests/integration/denoise.rs`); and each denoiser's time
//! per 1920x1080 frame: the built-in GPU filter where a GPU is present, OIDN on the
//! CPU.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin denoise_error -- [SCENE] [WIDTH] [REFERENCE_SPP]
//! cargo run --release -p gpu-render-tools --features oidn --bin denoise_error -- ...  # + OIDN (OIDN_DIR)
//! ```
//!
//! SCENE is a scene file or a model file (.obj, .gltf, .glb, with its own camera and
//! lights or the defaults, as `gpu-render MODEL` renders it), path traced whatever its
//! integrator. Defaults: `scenes/cornell-box.toml`, 128 pixels wide (same aspect), a
//! 2,048-sample reference. The reference draws its path's random numbers
//! from sample index 2²⁰ on, so that they are not those of the images it judges; its
//! own relative MSE against the exact image (from its estimated variance) is printed
//! beside. Relative MSE: the mean over pixels and channels of `(x - r)² / (r² + 0.01)`
//! (Rousselle, Knaus and Zwicker 2012, as SVGF's evaluation uses it), which keeps dark
//! pixels from dominating. With `DENOISE_ERROR_WORST` set it also prints, for each spp,
//! the eight pixels of largest denoised error with their guides (how the albedo edge
//! stop's need was found). OIDN's time per 1920x1080 frame is measured on the 1-spp
//! image and its passes tiled to that size (its network's cost does not depend on the
//! content), median of 3 after one warm-up run.

use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Instant;

use glam::DVec3;
use gpu_render::cpu::PreparedScene;
use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions};
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::path::path_radiance;
use gpu_render::low_level::denoise::GuidePasses;
use gpu_render::low_level::denoise::{DenoiseSettings, denoise};
use gpu_render::scene::{Integrator, RenderOverrides, RenderSettings, Scene, load_scene};

/// Where the reference's sample indices start.
const REFERENCE_SAMPLE_OFFSET: u32 = 1 << 20;

/// The ε of the relative MSE's denominator.
const EPSILON: f64 = 0.01;

/// Per pixel: the mean radiance over the scene's samples (path indices from
/// `first_sample` on) and the variance of that mean.
fn render_reference(prepared: &PreparedScene, first_sample: u32) -> Vec<(DVec3, DVec3)> {
    let settings = prepared.settings;
    let (width, height, spp) = (settings.width, settings.height, settings.samples_per_pixel);
    let next_row = AtomicU32::new(0);
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let mut rows: Vec<(u32, Vec<(DVec3, DVec3)>)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let y = next_row.fetch_add(1, Ordering::Relaxed);
                        if y >= height {
                            break done;
                        }
                        let row = (0..width)
                            .map(|x| {
                                let (mut sum, mut squares) = (DVec3::ZERO, DVec3::ZERO);
                                for index in 0..spp {
                                    let (dx, dy) = prepared.samples.offset(x, y, index);
                                    let direction = prepared.camera.ray_direction(
                                        f64::from(x) + dx,
                                        f64::from(y) + dy,
                                        width,
                                        height,
                                    );
                                    let primary = Ray {
                                        origin: prepared.camera.eye,
                                        direction,
                                    };
                                    let (radiance, _) = path_radiance(
                                        prepared,
                                        primary,
                                        y * width + x,
                                        first_sample + index,
                                    );
                                    sum += radiance;
                                    squares += radiance * radiance;
                                }
                                let n = f64::from(spp);
                                let mean = sum / n;
                                let variance = (squares / n - mean * mean).max(DVec3::ZERO);
                                (mean, variance / n)
                            })
                            .collect();
                        done.push((y, row));
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_default())
            .collect()
    });
    rows.sort_by_key(|(y, _)| *y);
    rows.into_iter().flat_map(|(_, row)| row).collect()
}

/// The relative MSE of `image` against `reference`.
fn relative_mse(image: &[[f32; 3]], reference: &[(DVec3, DVec3)]) -> f64 {
    let mut sum = 0.0;
    for (pixel, (r, _)) in image.iter().zip(reference) {
        for c in 0..3 {
            let (x, r) = (f64::from(pixel[c]), r[c]);
            sum += (x - r) * (x - r) / (r * r + EPSILON);
        }
    }
    sum / (3 * image.len()) as f64
}

/// `scene` at `width` pixels wide and `spp` samples per pixel, path traced.
fn at(scene: &Scene, width: u32, spp: u32) -> Scene {
    let height = (u64::from(scene.render.height) * u64::from(width) / u64::from(scene.render.width))
        .max(1) as u32;
    let render = scene
        .render
        .with_overrides(&RenderOverrides {
            width: Some(width),
            height: Some(height),
            samples_per_pixel: Some(spp),
            integrator: Some(Integrator::Path),
            ..RenderOverrides::default()
        })
        .expect("valid overrides");
    Scene {
        render,
        ..scene.clone()
    }
}

/// `radiance` and `guides` repeated to fill `width × height` (for timing only).
#[cfg_attr(not(feature = "oidn"), allow(dead_code))]
fn tiled(
    radiance: &[[f32; 3]],
    guides: &GuidePasses,
    width: u32,
    height: u32,
) -> (Vec<[f32; 3]>, GuidePasses) {
    let index = |x: u32, y: u32| ((y % guides.height) * guides.width + x % guides.width) as usize;
    let mut out = GuidePasses {
        width,
        height,
        albedo: Vec::new(),
        normal: Vec::new(),
        depth: Vec::new(),
    };
    let mut colour = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let i = index(x, y);
            colour.push(radiance[i]);
            out.albedo.push(guides.albedo[i]);
            out.normal.push(guides.normal[i]);
            out.depth.push(guides.depth[i]);
        }
    }
    (colour, out)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .map_or("scenes/cornell-box.toml", String::as_str);
    let width: u32 = args.get(1).map_or(Ok(128), |a| a.parse())?;
    let reference_spp: u32 = args.get(2).map_or(Ok(2048), |a| a.parse())?;
    let scene_path = std::path::Path::new(path);
    let scene = if gpu_render::scene::import::is_model_path(scene_path) {
        gpu_render::scene::import::import_model(scene_path)?.into_scene(RenderSettings::default())
    } else {
        load_scene(scene_path)?
    };
    #[cfg(feature = "oidn")]
    let oidn = gpu_render::low_level::denoise::oidn::Oidn::load()?;
    #[cfg(feature = "oidn")]
    let oidn_settings = gpu_render::low_level::denoise::oidn::OidnSettings::default();
    #[cfg(feature = "oidn")]
    println!("OIDN {} from {}", oidn.version(), oidn.path().display());

    let started = Instant::now();
    let reference_scene = at(&scene, width, reference_spp);
    let reference = render_reference(
        &PreparedScene::new(&reference_scene),
        REFERENCE_SAMPLE_OFFSET,
    );
    let own_error = reference
        .iter()
        .map(|(r, variance)| {
            (0..3)
                .map(|c| variance[c] / (r[c] * r[c] + EPSILON))
                .sum::<f64>()
        })
        .sum::<f64>()
        / (3 * reference.len()) as f64;
    println!(
        "{path}, {}x{}, reference {reference_spp} spp in {:.0} s (its own relative MSE about \
         {own_error:.2e})",
        reference_scene.render.width,
        reference_scene.render.height,
        started.elapsed().as_secs_f64()
    );
    println!(
        "| spp | raw relMSE | built-in relMSE | OIDN relMSE | built-in time (CPU, one thread) \
         | OIDN time (CPU) |"
    );
    println!("|---|---|---|---|---|---|");
    let settings = DenoiseSettings::default();
    // The 1-spp image and its passes, for OIDN's full-HD timing.
    let mut one_spp: Option<(Vec<[f32; 3]>, GuidePasses)> = None;
    for spp in [1, 4, 16, 64] {
        let scene = at(&scene, width, spp);
        let rendered = gpu_render::cpu::render_with_noise(&scene, None);
        let guides = gpu_render::low_level::cpu::aov::render_aovs(&scene);
        let noise = rendered.noise.expect("asked for");
        let variance: Vec<f32> = noise.standard_error.iter().map(|se| se * se).collect();
        let raw: Vec<[f32; 3]> = rendered
            .image
            .pixels
            .iter()
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        let timer = Instant::now();
        let denoised = denoise(&raw, &variance, &guides, &settings);
        let time = timer.elapsed();
        if std::env::var_os("DENOISE_ERROR_WORST").is_some() {
            let mut worst: Vec<(f64, usize)> = denoised
                .iter()
                .zip(&reference)
                .map(|(d, (r, _))| {
                    (0..3)
                        .map(|c| (f64::from(d[c]) - r[c]).powi(2) / (r[c] * r[c] + EPSILON))
                        .sum::<f64>()
                })
                .enumerate()
                .map(|(i, e)| (e, i))
                .collect();
            worst.sort_by(|a, b| b.0.total_cmp(&a.0));
            for &(e, i) in &worst[..8] {
                eprintln!(
                    "  pixel ({}, {}) error {e:.3}: raw {:?} denoised {:?} reference {:?} albedo {:?} depth {} variance {}",
                    i as u32 % scene.render.width,
                    i as u32 / scene.render.width,
                    raw[i],
                    denoised[i],
                    reference[i].0,
                    guides.albedo[i],
                    guides.depth[i],
                    variance[i]
                );
            }
        }
        #[cfg(feature = "oidn")]
        let (oidn_error, oidn_time) = {
            let timer = Instant::now();
            let denoised = oidn.denoise(&raw, &guides, &oidn_settings)?;
            let time = timer.elapsed();
            (
                format!("{:.4e}", relative_mse(&denoised, &reference)),
                format!("{:.3} s", time.as_secs_f64()),
            )
        };
        #[cfg(not(feature = "oidn"))]
        let (oidn_error, oidn_time) = ("(no oidn feature)", "");
        println!(
            "| {spp} | {:.4e} | {:.4e} | {oidn_error} | {:.3} s | {oidn_time} |",
            relative_mse(&raw, &reference),
            relative_mse(&denoised, &reference),
            time.as_secs_f64()
        );
        if spp == 1 {
            one_spp = Some((raw, guides));
        }
    }

    #[cfg(feature = "oidn")]
    if let Some((raw, guides)) = &one_spp {
        let (radiance, guides) = tiled(raw, guides, 1920, 1080);
        let mut times = Vec::new();
        for _ in 0..4 {
            let timer = Instant::now();
            oidn.denoise(&radiance, &guides, &oidn_settings)?;
            times.push(timer.elapsed().as_secs_f64());
        }
        let mut steady = times[1..].to_vec();
        steady.sort_by(f64::total_cmp);
        println!(
            "OIDN (CPU, {} threads), 1920x1080: median {:.3} s per frame (first {:.3} s)",
            std::thread::available_parallelism().map_or(1, usize::from),
            steady[steady.len() / 2],
            times[0]
        );
    }
    #[cfg(not(feature = "oidn"))]
    let _ = one_spp;

    // The GPU filter's time per 1920x1080 frame: a film of one sample of the scene,
    // denoised five times (the filter only, no readback).
    let Ok(gpu) = HeadlessGpu::new(&AdapterChoice::Default) else {
        println!("no GPU: no GPU timing");
        return Ok(());
    };
    let renderer = Renderer::new(
        &gpu.device,
        RendererOptions {
            aov: true,
            ..RendererOptions::default()
        },
    )?;
    let mut frame_scene = at(&scene, 1920, 1);
    frame_scene.render.height = 1080;
    let uploaded = renderer.upload(&gpu.device, &gpu.queue, &frame_scene)?;
    let mut film = renderer.create_film(&gpu.device, &uploaded, 1920, 1080)?;
    renderer.render_to_image(&gpu.device, &gpu.queue, &uploaded, &mut film)?;
    let mut times = Vec::new();
    for _ in 0..6 {
        let timer = Instant::now();
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        renderer.encode_denoise(&gpu.device, &gpu.queue, &mut encoder, &mut film, &settings)?;
        let submission = gpu.queue.submit([encoder.finish()]);
        gpu.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(submission),
                timeout: None,
            })
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        times.push(timer.elapsed().as_secs_f64());
    }
    // The first run makes the film's buffers and compiles nothing (the pipelines are
    // built with the renderer) but lavapipe compiles at the first dispatch: drop it.
    let mut steady = times[1..].to_vec();
    steady.sort_by(f64::total_cmp);
    println!(
        "GPU filter ({}), 1920x1080, {} passes: median {:.3} s per frame (first {:.3} s)",
        gpu.adapter_info().name,
        settings.iterations,
        steady[steady.len() / 2],
        times[0]
    );
    Ok(())
}
