//! The environment map on the GPU (`shaders/environment.wgsl`, the miss and
//! next-event code of `shaders/path.wgsl` and `shaders/trace.wgsl`) against the CPU
//! reference, per pixel in linear float, on the shipped environment-lit scene with
//! both integrators, with an area light beside the map (the light choice between the
//! two), with a rotated, tinted map, and with a black map (never sampled).
//!
//! Both backends draw the same numbers for the same decisions, so a GPU pixel is the
//! CPU pixel up to f32 rounding: a channel passes when `|gpu - cpu| <= 1e-3 +
//! 5e-3·|cpu|` (the tolerance of `tests/integration/path_gpu.rs`), and at most [`OUTLIERS`] of
//! the pixels may fail it (a path that takes another branch in f32: a texel or CDF
//! boundary within rounding, a grazing ray). Measured on lavapipe (2026-12-01): 2 or 3
//! of 2,304 pixels per image, every one a sky pixel seen directly whose one camera
//! sample falls in the neighbouring texel row in f32 (the map is looked up per texel,
//! so the pixel moves by a quarter or an eighth of the step between two rows: at most
//! 1.2e-2); RMSE 1.3e-4 to 2.3e-4; ray counts equal. On failure both images and their
//! difference are written under `target/test-output/`.

use std::sync::Arc;

use crate::support::compare::Tolerance;
use glam::DVec3;
use gpu_render::gpu::{HeadlessGpu, Renderer};
use gpu_render::scene::{Integrator, Material, MaterialKind, RenderOverrides, Scene, Shape};

const TOLERANCE: Tolerance = crate::support::twins::TWIN_TOLERANCE;

/// `scenes/env-materials.toml` with `integrator`, `width` pixels wide, `samples` per
/// pixel.
fn env_materials(integrator: Integrator, width: u32, samples: u32) -> Scene {
    let overrides = RenderOverrides {
        samples_per_pixel: Some(samples),
        integrator: Some(integrator),
        ..RenderOverrides::default()
    };
    crate::support::scenes::reduced(
        crate::support::scenes::shipped("env-materials.toml"),
        width,
        overrides,
    )
}

fn compare(gpu: &HeadlessGpu, renderer: &Renderer, label: &str, scene: &Scene) {
    crate::support::twins::assert_backends_agree(gpu, renderer, label, scene, TOLERANCE);
}

#[test]
fn gpu_environment_lighting_matches_the_cpu_with_both_integrators() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "env-materials-path",
        &env_materials(Integrator::Path, 64, 8),
    );
    compare(
        &gpu,
        &renderer,
        "env-materials-whitted",
        &env_materials(Integrator::Whitted, 64, 4),
    );
}

#[test]
fn gpu_environment_lighting_matches_the_cpu_beside_an_area_light_and_rotated() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    // An emissive sphere over the spheres: next-event estimation now picks the map
    // or the lamp, each with probability 1/2.
    let mut lamp = env_materials(Integrator::Path, 64, 8);
    lamp.materials.push(Material {
        emission: DVec3::splat(6.0),
        ..Material::blank(MaterialKind::Emissive)
    });
    lamp.material_names.push("lamp".into());
    lamp.shapes.push(Shape::Sphere {
        center: DVec3::new(0.5, 2.6, 1.0),
        radius: 0.3,
        material: (lamp.materials.len() - 1) as u32,
    });
    compare(&gpu, &renderer, "env-materials-lamp", &lamp);
    // The map turned by 73° and tinted: the sun moves, both backends alike.
    let mut turned = env_materials(Integrator::Path, 64, 8);
    let map = turned
        .environment
        .map
        .as_mut()
        .expect("the scene has a map");
    let map = Arc::make_mut(map);
    map.rotation_degrees = 73.0;
    map.scale = DVec3::new(1.3, 0.9, 0.7);
    compare(&gpu, &renderer, "env-materials-rotated", &turned);
    // A black map beside the lamp: never sampled (its selection is 0), no NaN.
    let mut black = lamp.clone();
    let map = black.environment.map.as_mut().expect("the scene has a map");
    for texel in &mut Arc::make_mut(map).image.texels {
        *texel = [0.0, 0.0, 0.0, 1.0];
    }
    compare(&gpu, &renderer, "env-materials-black-map", &black);
}
