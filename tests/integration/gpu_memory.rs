//! The GPU memory a render allocates does not depend on its samples per pixel: the
//! path slots, the traversal stacks and the scene's buffers are sized by the slot
//! count, the bounce stack and the scene, never by the samples (issue 8: 65,536 spp
//! of a 2x2 image used to allocate 1.29 GB, a buffer and bind group per sample).

use std::sync::Mutex;

use glam::DVec3;
use gpu_render::gpu::RendererOptions;
use gpu_render::scene::{
    Camera, Environment, Light, LightingSpace, Material, RenderSettings, Scene, Shape,
};

fn scene(samples_per_pixel: u32) -> Scene {
    Scene {
        render: RenderSettings {
            width: 2,
            height: 2,
            samples_per_pixel,
            max_depth: 2,
            stack_size: 3,
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: gpu_render::scene::Integrator::Whitted,
            texture_filtering: gpu_render::scene::TextureFiltering::Trilinear,
        },
        camera: Camera {
            eye: DVec3::new(0.0, 1.0, 4.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        materials: vec![Material::lambert(DVec3::splat(0.6))],
        material_names: vec!["grey".into()],
        lights: vec![Light::Point {
            position: DVec3::new(2.0, 4.0, 3.0),
            intensity: DVec3::splat(20.0),
        }],
        shapes: vec![
            Shape::Sphere {
                center: DVec3::new(0.0, 0.5, 0.0),
                radius: 0.5,
                material: 0,
            },
            Shape::Plane {
                normal: DVec3::Y,
                offset: 0.0,
                material: 0,
            },
        ],
        meshes: vec![],
        images: vec![],
    }
}

/// The most bytes the device's allocator held while `samples` samples per pixel were
/// traced, read after every submission through the progress callback.
/// With `noise`, the render also keeps and reads back each pixel's noise estimate.
fn peak_allocated(gpu: &gpu_render::gpu::HeadlessGpu, samples: u32, noise: bool) -> Option<u64> {
    // A small budget, so that even the short render takes several submissions.
    let renderer = crate::support::gpu::renderer_with(
        gpu,
        RendererOptions {
            iteration_budget: Some(256),
            noise_estimate: noise,
            ..RendererOptions::default()
        },
    );
    let peak = Mutex::new(None);
    let progress = |_: u32, _: u32| {
        if let Some(report) = gpu.device.generate_allocator_report() {
            let mut peak = peak.lock().unwrap();
            *peak = Some(peak.unwrap_or(0).max(report.total_allocated_bytes));
        }
    };
    renderer
        .render(&gpu.device, &gpu.queue, &scene(samples), Some(&progress))
        .expect("render");
    peak.into_inner().unwrap()
}

#[test]
fn gpu_memory_does_not_grow_with_samples() {
    assert_memory_does_not_grow_with_samples(false);
}

/// The noise estimate's sums are one `vec4` per pixel, whatever the samples.
#[test]
fn gpu_memory_of_the_noise_estimate_does_not_grow_with_samples() {
    assert_memory_does_not_grow_with_samples(true);
}

fn assert_memory_does_not_grow_with_samples(noise: bool) {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let Some(few) = peak_allocated(&gpu, 4, noise) else {
        // Only Vulkan, DX12 and Metal report their allocations; CI runs on Vulkan.
        assert!(
            std::env::var_os("CI").is_none(),
            "{} gives no allocator report",
            gpu.adapter_info().name
        );
        eprintln!("note: no allocator report on {}", gpu.adapter_info().name);
        return;
    };
    let many = peak_allocated(&gpu, 16_384, noise).expect("a report, as before");
    eprintln!("noise {noise}: peak allocated: {few} bytes at 4 spp, {many} bytes at 16384 spp");
    assert!(few > 0);
    // 4096 times the samples: within 64 KiB (the queue's staging chunks for the
    // uniforms come and go), where the old engine's buffer per sample grew to 1.29 GB.
    assert!(
        many.abs_diff(few) <= 64 << 10,
        "memory must not depend on the samples per pixel: {few} vs {many} bytes"
    );
}
