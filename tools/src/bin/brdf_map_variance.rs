//! Measures how much inverse-CDF sampling of tabulated BRDF maps reduces noise in the
//! path integrator: per-pixel RMSE against a converged reference at equal samples per
//! pixel, the maps' inverse-CDF sampler against the cosine sampler they used before, on
//! `scenes/tabulated.toml` (CPU reference).
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin brdf_map_variance -- [WIDTH] [SPP] [REFERENCE_SPP]
//! ```
//!
//! Defaults: 160 pixels wide (same aspect), 16 samples per pixel, a 2,048-sample
//! reference. The reference uses the inverse-CDF sampler with sample indices from
//! 2²⁰ on, so that its random numbers are not those of the images it judges; its own
//! noise (the RMSE it would show against the exact image) is printed beside. The
//! cosine sampler is what `sample_brdf` falls back to for a tabulated material without
//! a table, so the example takes the tables away from the prepared scene to get it.
//! RMSE is over every channel of every pixel, of the pixels whose camera ray (through
//! the pixel's centre) first hits a tabulated material, and of those of each map.

use std::path::Path;
use std::sync::atomic::{AtomicU32, Ordering};

use glam::DVec3;
use gpu_render::cpu::PreparedScene;
use gpu_render::low_level::accel::BrdfMapCdfs;
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::path::path_radiance;
use gpu_render::low_level::cpu::traverse::intersect_scene;
use gpu_render::scene::{Integrator, MaterialKind, RenderOverrides, Scene, load_scene};

/// Where the reference's sample indices start.
const REFERENCE_SAMPLE_OFFSET: u32 = 1 << 20;

/// Per pixel: the mean radiance over `spp` samples from `first_sample` on, and the
/// variance of that mean.
fn render(prepared: &PreparedScene, first_sample: u32) -> Vec<(DVec3, DVec3)> {
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

/// The material the camera ray through the centre of each pixel first hits, if any.
fn primary_materials(prepared: &PreparedScene) -> Vec<Option<u32>> {
    let (width, height) = (prepared.settings.width, prepared.settings.height);
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let direction = prepared.camera.ray_direction(
                f64::from(x) + 0.5,
                f64::from(y) + 0.5,
                width,
                height,
            );
            let ray = Ray {
                origin: prepared.camera.eye,
                direction,
            };
            intersect_scene(&prepared.geometry, &ray, f64::INFINITY).map(|hit| hit.material)
        })
        .collect()
}

/// RMSE of `image` against `reference` over every channel of the pixels `mask` keeps.
fn rmse(image: &[(DVec3, DVec3)], reference: &[(DVec3, DVec3)], mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for ((a, b), &keep) in image.iter().zip(reference).zip(mask) {
        if keep {
            let d = a.0 - b.0;
            sum += d.length_squared();
            count += 3;
        }
    }
    (sum / count as f64).sqrt()
}

/// The RMSE the reference's own noise adds, over the pixels `mask` keeps.
fn reference_noise(reference: &[(DVec3, DVec3)], mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for (pixel, &keep) in reference.iter().zip(mask) {
        if keep {
            sum += pixel.1.x + pixel.1.y + pixel.1.z;
            count += 3;
        }
    }
    (sum / count as f64).sqrt()
}

fn scene_with(scene: &Scene, width: u32, spp: u32) -> Result<Scene, String> {
    let height = (u64::from(scene.render.height) * u64::from(width) / u64::from(scene.render.width))
        .max(1) as u32;
    let overrides = RenderOverrides {
        width: Some(width),
        height: Some(height),
        samples_per_pixel: Some(spp),
        integrator: Some(Integrator::Path),
        ..RenderOverrides::default()
    };
    Ok(Scene {
        render: scene
            .render
            .with_overrides(&overrides)
            .map_err(|e| e.to_string())?,
        ..scene.clone()
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse::<u32>().map_err(|e| format!("`{a}`: {e}")))
        .collect::<Result<_, _>>()?;
    let width = args.first().copied().unwrap_or(160).max(1);
    let spp = args.get(1).copied().unwrap_or(16).max(1);
    let reference_spp = args.get(2).copied().unwrap_or(2048).max(1);
    let file = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join("scenes/tabulated.toml");
    let scene = load_scene(&file)?;

    let reference_scene = scene_with(&scene, width, reference_spp)?;
    let reference = render(
        &PreparedScene::new(&reference_scene),
        REFERENCE_SAMPLE_OFFSET,
    );
    let test_scene = scene_with(&scene, width, spp)?;
    let inverse_cdf = PreparedScene::new(&test_scene);
    let mut cosine = inverse_cdf.clone();
    cosine.brdf_map_cdfs = BrdfMapCdfs::default();
    let primary = primary_materials(&inverse_cdf);
    let is_map = |m: &Option<u32>| {
        m.is_some_and(|m| test_scene.materials[m as usize].kind == MaterialKind::Tabulated)
    };
    let mut masks = vec![
        ("all".to_string(), vec![true; reference.len()]),
        (
            "tabulated".to_string(),
            primary.iter().map(is_map).collect(),
        ),
    ];
    for (index, material) in test_scene.materials.iter().enumerate() {
        if material.kind == MaterialKind::Tabulated {
            let mask: Vec<bool> = primary.iter().map(|m| *m == Some(index as u32)).collect();
            masks.push((format!("`{}`", test_scene.material_names[index]), mask));
        }
    }
    let with_cdf = render(&inverse_cdf, 0);
    let with_cosine = render(&cosine, 0);

    let (w, h) = (test_scene.render.width, test_scene.render.height);
    println!("scenes/tabulated.toml, {w}x{h}, {spp} spp against a {reference_spp}-spp reference");
    println!(
        "| pixels (count) | cosine RMSE | inverse-CDF RMSE | RMSE ratio | variance ratio | reference noise |"
    );
    println!("|---|---|---|---|---|---|");
    for (label, mask) in &masks {
        let (a, b) = (
            rmse(&with_cosine, &reference, mask),
            rmse(&with_cdf, &reference, mask),
        );
        let count = mask.iter().filter(|&&m| m).count();
        println!(
            "| {label} ({count}) | {a:.4e} | {b:.4e} | {:.2} | {:.1} | {:.1e} |",
            a / b,
            (a / b) * (a / b),
            reference_noise(&reference, mask)
        );
    }
    Ok(())
}
