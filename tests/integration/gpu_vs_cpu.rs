//! Every scene shipped in `scenes/` rendered on the GPU (lavapipe in CI) and on the CPU
//! reference, compared per pixel in linear float.
//!
//! Tolerance: a channel passes when `|gpu - cpu| <= 1e-3 + 5e-3·|cpu|`: the GPU works in
//! f32 and the reference in f64, and a refracted ray that has crossed a few interfaces
//! lands a little elsewhere (measured on lavapipe: RMSE below 5e-4 on every scene, most
//! pixels within 1e-5). At most 0.5% of the pixels may fail: those are samples that
//! graze a silhouette, a shadow boundary or the critical angle and fall on the other side
//! in the other precision. Scenes are rendered 200 pixels wide with 2 samples per pixel
//! to keep the CPU reference fast.

use crate::support::twins::assert_ray_counts_agree;

use crate::support::compare::{Tolerance, assert_images_match};
use gpu_render::scene::{LightingSpace, RenderOverrides, Scene, load_scene};

const TOLERANCE: Tolerance = crate::support::twins::TWIN_TOLERANCE;

fn reduced(scene: Scene, lighting_space: LightingSpace) -> Scene {
    let overrides = RenderOverrides {
        samples_per_pixel: Some(2),
        lighting_space: Some(lighting_space),
        // Path-traced scenes (the Cornell box, the caustic) are compared as Whitted
        // renders here; the path integrator's twin has tests/integration/path_gpu.rs.
        integrator: Some(gpu_render::scene::Integrator::Whitted),
        ..RenderOverrides::default()
    };
    crate::support::scenes::reduced(scene, 200, overrides)
}

#[test]
fn gpu_matches_cpu_reference_on_every_shipped_scene() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    for path in crate::support::scenes::shipped_scenes() {
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
        let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let spaces: &[LightingSpace] = if name == "linear-vs-gamma" {
            &[LightingSpace::Linear, LightingSpace::NaiveGamma]
        } else {
            &[LightingSpace::Linear]
        };
        for &space in spaces {
            let scene = reduced(scene.clone(), space);
            let cpu = gpu_render::cpu::render(&scene, None);
            let gpu_image = renderer
                .render(&gpu.device, &gpu.queue, &scene, None)
                .unwrap_or_else(|e| panic!("{name}: GPU render failed: {e}"));
            assert!(
                gpu_image
                    .image
                    .pixels
                    .iter()
                    .all(|p| p.iter().all(|c| c.is_finite())),
                "{name}: the GPU image has non-finite pixels"
            );
            let label = format!("{name}-{space:?}").to_lowercase();
            let comparison = assert_images_match(&label, &cpu.image, &gpu_image.image, TOLERANCE);
            eprintln!(
                "{label}: {} of {} pixels outside tolerance, max |Δ| {:.2e}, RMSE {:.2e}",
                comparison.outliers, comparison.pixels, comparison.max_abs_error, comparison.rmse
            );
            // Edge samples may branch differently in f32 and f64: allow 1%.
            assert_ray_counts_agree(&label, &cpu.stats, &gpu_image.stats, 0.01);
        }
    }
}

#[test]
fn ray_weight_cutoff_traces_fewer_rays_alike_on_both_backends() {
    let full = reduced(
        crate::support::scenes::shipped("glass.toml"),
        LightingSpace::Linear,
    );
    let mut cut = full.clone();
    cut.render.min_ray_weight = 0.2;
    let cpu_full = gpu_render::cpu::render(&full, None);
    let cpu_cut = gpu_render::cpu::render(&cut, None);
    assert!(
        cpu_cut.stats.rays_traced < cpu_full.stats.rays_traced * 9 / 10,
        "a 0.2 cutoff should skip the weak Fresnel reflections: {} vs {} rays",
        cpu_cut.stats.rays_traced,
        cpu_full.stats.rays_traced
    );
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let gpu_cut = renderer
        .render(&gpu.device, &gpu.queue, &cut, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match("glass-cutoff", &cpu_cut.image, &gpu_cut.image, TOLERANCE);
    assert_ray_counts_agree("glass-cutoff", &cpu_cut.stats, &gpu_cut.stats, 0.01);
}

/// Many samples of deep glass paths per pixel: lavapipe ends all loops of an
/// invocation after 65535 iterations in total, which once silently dropped rays here
/// (the GPU now traces one sample per dispatch). Ray counts must agree closely.
#[test]
fn many_deep_samples_per_pixel_lose_no_rays() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let mut scene = crate::support::scenes::shipped("showcase.toml");
    scene.render = scene
        .render
        .with_overrides(&RenderOverrides {
            width: Some(64),
            height: Some(36),
            samples_per_pixel: Some(64),
            max_depth: Some(10),
            ..RenderOverrides::default()
        })
        .expect("valid overrides");
    let cpu = gpu_render::cpu::render(&scene, None);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match("showcase-64spp", &cpu.image, &gpu_image.image, TOLERANCE);
    assert_ray_counts_agree("showcase-64spp", &cpu.stats, &gpu_image.stats, 1e-3);
}
