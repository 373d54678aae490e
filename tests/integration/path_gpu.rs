//! The path integrator's GPU twin (`shaders/path.wgsl`) against the CPU reference
//! (`src/cpu/path.rs`), per pixel in linear float.
//!
//! Both backends draw the same counter-based random numbers for the same decisions, so
//! a GPU pixel is the CPU pixel up to f32 rounding, not merely the same estimate:
//! a channel passes when `|gpu - cpu| <= 1e-3 + 5e-3·|cpu|`, the tolerance of
//! `tests/integration/gpu_vs_cpu.rs`. A pixel may still fail where one of its paths takes another
//! branch in f32 than in f64 (a ray grazing an edge, an event or roulette number within
//! rounding of its threshold), and from then on draws other numbers: at most
//! 0.5% of the pixels (`crate::support::twins::TWIN_TOLERANCE`) may (measured on lavapipe, 2026-12-01: none does on any
//! of these scenes; the largest difference is 2.1e-3, on a bright Cornell box pixel,
//! RMSE at most 2.7e-5). On failure both images and their difference are
//! written under `target/test-output/`.
//!
//! Also: the ray counts agree, a tiny iteration budget (many resumed dispatches) gives
//! the bit-identical image, and a loop the driver cuts is an error.

use crate::support::compare::Tolerance;
use glam::DVec3;
use gpu_render::gpu::{RenderError, Renderer, RendererOptions, Schedule, TraceFailure};
use gpu_render::scene::{
    Camera, Environment, Integrator, Material, MaterialKind, RenderOverrides, RenderSettings,
    Scene, Shape,
};

const TOLERANCE: Tolerance = crate::support::twins::TWIN_TOLERANCE;

/// A shipped scene, path-traced, `width` pixels wide with `samples` per pixel.
fn shipped(name: &str, width: u32, samples: u32) -> Scene {
    let overrides = RenderOverrides {
        samples_per_pixel: Some(samples),
        integrator: Some(Integrator::Path),
        ..RenderOverrides::default()
    };
    crate::support::scenes::reduced(crate::support::scenes::shipped(name), width, overrides)
}

/// Renders `scene` on both backends and compares them.
fn compare(gpu: &gpu_render::gpu::HeadlessGpu, renderer: &Renderer, label: &str, scene: &Scene) {
    crate::support::twins::assert_backends_agree(gpu, renderer, label, scene, TOLERANCE);
}

/// A closed emissive sphere around the camera with `material` inside: the white
/// furnace of `tests/integration/path_tracing.rs`, where every path sees the emission at every
/// bounce and no next-event estimation applies from inside.
fn furnace(material: Material, max_depth: u32) -> Scene {
    Scene {
        render: RenderSettings {
            width: 24,
            height: 16,
            samples_per_pixel: 16,
            max_depth,
            stack_size: 4,
            integrator: Integrator::Path,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.1, -0.2, 0.05),
            look_at: DVec3::new(1.0, 0.3, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 90.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        material_names: vec!["furnace".into()],
        materials: vec![material],
        lights: vec![],
        shapes: vec![Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
            material: 0,
        }],
        meshes: vec![],
        images: vec![],
    }
}

#[test]
fn gpu_path_tracing_matches_the_cpu_on_the_cornell_box() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "path-cornell-box",
        &shipped("cornell-box.toml", 48, 8),
    );
    // The lamp made two-sided lights the ceiling above it too: brighter overall, and
    // the same on both backends.
    let one_sided = shipped("cornell-box.toml", 48, 8);
    let mut two_sided = one_sided.clone();
    for material in &mut two_sided.materials {
        if material.emission != glam::DVec3::ZERO {
            material.two_sided = true;
        }
    }
    let total = |scene: &Scene| -> f64 {
        gpu_render::cpu::render(scene, None)
            .image
            .pixels
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum()
    };
    assert!(
        total(&two_sided) > total(&one_sided) * 1.001,
        "the lamp's back lights nothing"
    );
    compare(&gpu, &renderer, "path-cornell-box-two-sided", &two_sided);
}

#[test]
fn gpu_path_tracing_matches_the_cpu_on_the_caustic() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "path-caustic",
        &shipped("caustic.toml", 64, 8),
    );
}

/// The showcase's glossy models (Blinn-Phong, Cook-Torrance, glTF PBR, Oren-Nayar)
/// exercise every BRDF sampler and its density.
#[test]
fn gpu_path_tracing_matches_the_cpu_on_the_showcase_materials() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "path-showcase",
        &shipped("showcase.toml", 64, 4),
    );
}

/// Smooth and textured meshes (shading normals, the shadow terminator, bent
/// continuations) and every material model, tabulated BRDFs included.
#[test]
fn gpu_path_tracing_matches_the_cpu_on_meshes_and_every_material() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "path-models",
        &shipped("models.toml", 48, 2),
    );
    compare(
        &gpu,
        &renderer,
        "path-materials",
        &shipped("materials.toml", 48, 2),
    );
}

/// Tabulated BRDF maps sampled by their inverse-CDF tables (in the alpha channel of
/// the maps' layers on the GPU, from the same host-built `f32` values as the CPU's): a
/// glossy map, a grazing one and a near-Lambertian one (`scenes/tabulated.toml`).
#[test]
fn gpu_path_tracing_matches_the_cpu_on_brdf_maps() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    compare(
        &gpu,
        &renderer,
        "path-tabulated",
        &shipped("tabulated.toml", 64, 8),
    );
}

#[test]
fn gpu_path_tracing_matches_the_cpu_in_furnaces() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let lambert = Material {
        emission: DVec3::splat(1.5),
        ..Material::lambert(DVec3::splat(0.8))
    };
    let conductor = Material {
        emission: DVec3::splat(0.5),
        roughness: 0.5,
        conductor: true,
        eta: DVec3::ONE,
        k: DVec3::splat(1e6),
        fresnel: gpu_render::scene::FresnelModel::Schlick,
        ..Material::blank(MaterialKind::CookTorrance)
    };
    for (label, material, depth) in [
        ("path-furnace-lambert-64", lambert, 64),
        ("path-furnace-lambert-3", lambert, 3),
        ("path-furnace-ggx-8", conductor, 8),
    ] {
        compare(&gpu, &renderer, label, &furnace(material, depth));
    }
}

/// With a budget of 1 or 3 loop iterations per dispatch every bounce, light and traversal
/// resumes across many dispatches: the image and ray count are bit-identical to those
/// of the default budget, on both schedules. A loop the driver cuts is an error, never
/// an image with paths missing.
#[test]
fn the_budget_bounds_path_tracing_and_a_cut_loop_is_an_error() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let scene = shipped("cornell-box.toml", 16, 4);
    let reference = crate::support::gpu::renderer(&gpu)
        .render(&gpu.device, &gpu.queue, &scene, None)
        .expect("GPU render");
    for schedule in [Schedule::Fused, Schedule::Wavefront] {
        // 1 is the smallest budget the CLI accepts; it once never finished (fused).
        for budget in [1, 3] {
            let tiny = crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(schedule),
                    iteration_budget: Some(budget),
                    ..RendererOptions::default()
                },
            )
            .render(&gpu.device, &gpu.queue, &scene, None)
            .expect("GPU render with a tiny budget");
            assert_eq!(
                tiny.image.pixels, reference.image.pixels,
                "{schedule:?}, budget {budget}: the image must not change"
            );
            assert_eq!(
                tiny.stats.rays_traced, reference.stats.rays_traced,
                "{schedule:?}, budget {budget}: same rays"
            );
        }
        let cut = Renderer::new(
            &gpu.device,
            RendererOptions {
                schedule: Some(schedule),
                simulate_loop_cut: true,
                ..RendererOptions::default()
            },
        )
        .expect("renderer")
        .render(&gpu.device, &gpu.queue, &scene, None);
        match cut {
            Err(RenderError::TraceIncomplete(failure)) => {
                assert_eq!(failure, TraceFailure::LoopCut, "{schedule:?}");
                assert!(
                    failure.to_string().contains("cut short"),
                    "{schedule:?}: {failure}"
                );
            }
            other => panic!("{schedule:?}: expected TraceIncomplete, got {other:?}"),
        }
    }
}

/// The frame loop (the viewer's engine) accumulates path-traced samples in passes
/// whose sample indices continue, drawing the same numbers: three passes of 1, 3 and 4
/// samples give the bit-identical image and ray count of a one-shot render.
#[test]
fn progressive_path_tracing_equals_a_one_shot_render() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let scene = shipped("cornell-box.toml", 32, 8);
    let one_shot = crate::support::gpu::renderer(&gpu)
        .render(&gpu.device, &gpu.queue, &scene, None)
        .expect("one-shot render");
    let renderer = Renderer::new(&gpu.device, RendererOptions::default()).expect("renderer");
    let gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("upload");
    let mut film = renderer
        .create_film(
            &gpu.device,
            &gpu_scene,
            gpu_scene.width(),
            gpu_scene.height(),
        )
        .expect("film");
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
            .expect("encode_samples");
        let index = gpu.queue.submit([encoder.finish()]);
        gpu.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            })
            .expect("poll");
        renderer
            .finish(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
            .expect("finish");
    }
    assert_eq!(film.samples(), 8);
    let image = renderer
        .read_film(&gpu.device, &gpu.queue, &gpu_scene, &film)
        .expect("read_film");
    assert_eq!(
        image.image.pixels, one_shot.image.pixels,
        "progressive passes must give the one-shot image"
    );
    assert_eq!(film.rays_traced(), one_shot.stats.rays_traced);
}

/// A glossy floor of `material` under a uniform sky, with a small emissive sphere and
/// a point light above it whose reflections are the lobe's peak: the scene of the
/// near-mirror bias (issue 26), where the GPU's `f32` `1 - cos²θh` cancelled and made
/// the GGX lobe 1.9% brighter than the CPU's at roughness 0.
fn glossy_floor(material: Material) -> Scene {
    Scene {
        render: RenderSettings {
            width: 32,
            height: 24,
            samples_per_pixel: 4,
            max_depth: 4,
            integrator: Integrator::Path,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.0, 1.0, 4.0),
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment {
            background: DVec3::splat(0.4),
            ..Environment::default()
        },
        material_names: vec!["floor".into(), "lamp".into()],
        materials: vec![
            material,
            Material {
                emission: DVec3::splat(20.0),
                ..Material::lambert(DVec3::ZERO)
            },
        ],
        lights: vec![gpu_render::scene::Light::Point {
            position: DVec3::new(1.0, 2.0, -3.0),
            intensity: DVec3::splat(30.0),
        }],
        shapes: vec![
            Shape::Plane {
                normal: DVec3::Y,
                offset: 0.0,
                material: 0,
            },
            Shape::Sphere {
                center: DVec3::new(-0.8, 1.2, -2.0),
                radius: 0.3,
                material: 1,
            },
        ],
        meshes: vec![],
        images: vec![],
    }
}

/// The microfacet models agree across the whole roughness range, the near-mirror end
/// included (roughness 0 clamps to α = 10⁻³, D's peak 3·10⁵): PBR metal, Cook-Torrance
/// GGX and Beckmann conductors, each at eleven roughnesses from 0 to 1.
#[test]
fn gpu_path_tracing_matches_the_cpu_across_the_roughness_range() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let gold = DVec3::new(1.0, 0.78, 0.34);
    for roughness in [0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.85, 1.0] {
        let pbr = Material {
            roughness,
            metallic: 1.0,
            ..Material {
                diffuse: gold,
                ..Material::blank(MaterialKind::Pbr)
            }
        };
        let conductor = |distribution| Material {
            roughness,
            conductor: true,
            eta: DVec3::new(0.18, 0.42, 1.37),
            k: DVec3::new(3.42, 2.35, 1.77),
            distribution,
            ..Material::blank(MaterialKind::CookTorrance)
        };
        for (kind, material) in [
            ("pbr", pbr),
            (
                "ggx",
                conductor(gpu_render::scene::MicrofacetDistribution::Ggx),
            ),
            (
                "beckmann",
                conductor(gpu_render::scene::MicrofacetDistribution::Beckmann),
            ),
        ] {
            let label = format!("path-roughness-{kind}-{roughness}");
            compare(&gpu, &renderer, &label, &glossy_floor(material));
        }
    }
}

/// At the largest radiance and light strength the loader accepts
/// ([`gpu_render::scene::MAX_RADIANCE`], 1e30) the GPU's f32 sums of samples and
/// bounces do not overflow: an emitter, a background, a point light and an environment
/// map of that strength render as on the CPU (a 1e38 map at 4 samples per pixel had 79%
/// of its pixels wrong before such values were refused, issue 26).
#[test]
fn gpu_path_tracing_matches_the_cpu_at_the_largest_accepted_radiance() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let strongest = gpu_render::scene::MAX_RADIANCE;
    let mut scene = glossy_floor(Material::lambert(DVec3::splat(0.5)));
    scene.materials[1].emission = DVec3::splat(strongest);
    scene.environment.background = DVec3::new(strongest, 0.5 * strongest, 0.25);
    scene.lights = vec![gpu_render::scene::Light::Point {
        position: DVec3::new(1.0, 2.0, -3.0),
        intensity: DVec3::splat(strongest),
    }];
    compare(&gpu, &renderer, "path-radiance-1e30", &scene);

    // A map whose brightest texel times the scale is the limit.
    let (width, height) = (8, 4);
    let texels = (0..width * height)
        .map(|i| {
            let v = (i % 7 + 1) as f32 / 7.0;
            [v, 1.0 - 0.5 * v, 0.5, 1.0]
        })
        .collect();
    let image = gpu_render::scene::Image {
        path: "sky.hdr".into(),
        width,
        height,
        texels,
    };
    scene.environment.background = DVec3::ZERO;
    scene.environment.map = Some(std::sync::Arc::new(gpu_render::scene::EnvironmentMap {
        image,
        rotation_degrees: 30.0,
        scale: DVec3::splat(strongest),
    }));
    compare(&gpu, &renderer, "path-environment-1e30", &scene);
}
