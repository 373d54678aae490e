//! End-to-end plumbing of the GPU backend, independent of what the trace shader
//! computes: submissions of rounds, readback of a width whose rows need padding, the
//! ray counters, the low-level API and its error paths, and the independence of the
//! image from slots, budgets and regions.

use std::sync::Mutex;
use std::time::Duration;

use glam::DVec3;
use gpu_render::gpu::RendererOptions;
use gpu_render::gpu::{RenderError, Schedule, TraceRegion, read_texture};
use gpu_render::scene::{
    Camera, Environment, Light, LightingSpace, Material, RenderOverrides, RenderSettings, Scene,
    Shape,
};

// 37 columns: 37 * 16 and 37 * 4 bytes are not multiples of 256, so both readbacks
// strip row padding. 37 * 61 * 1024 samples take many rounds and submissions.
const WIDTH: u32 = 37;
const HEIGHT: u32 = 61;
const SPP: u32 = 1024;

fn scene(samples_per_pixel: u32) -> Scene {
    Scene {
        render: RenderSettings {
            width: WIDTH,
            height: HEIGHT,
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
        environment: Environment {
            background: DVec3::new(0.2, 0.3, 0.5),
            ambient: DVec3::ZERO,
            map: None,
        },
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

#[test]
fn render_reads_back_counts_rays_and_reports_progress() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    // A small budget, so that the render takes several submissions.
    let renderer = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            iteration_budget: Some(64),
            ..RendererOptions::default()
        },
    );
    let scene = scene(SPP);

    let reported = Mutex::new(Vec::new());
    let progress = |done: u32, total: u32| reported.lock().unwrap().push((done, total));
    let out = renderer
        .render(&gpu.device, &gpu.queue, &scene, Some(&progress))
        .expect("render succeeds");

    let reported = reported.into_inner().unwrap();
    assert!(
        reported.len() > 1,
        "progress after each submission: {reported:?}"
    );
    assert!(
        reported.windows(2).all(|w| w[0].0 <= w[1].0),
        "{reported:?}"
    );
    assert_eq!(reported.last(), Some(&(HEIGHT, HEIGHT)));

    assert_eq!((out.image.width, out.image.height), (WIDTH, HEIGHT));
    assert_eq!(out.image.pixels.len(), (WIDTH * HEIGHT) as usize);
    for (i, p) in out.image.pixels.iter().enumerate() {
        assert!(p.iter().all(|c| c.is_finite()), "pixel {i} = {p:?}");
        assert_eq!(p[3], 1.0, "alpha of pixel {i}");
    }
    // The display image is the CPU encoding of the linear one, up to f32 rounding.
    let cpu_display = out.image.to_display_rgba8(true);
    assert_eq!(out.display_rgba8.len(), cpu_display.len());
    for (g, c) in out.display_rgba8.iter().zip(&cpu_display) {
        assert!(g.abs_diff(*c) <= 1);
    }
    // Camera rays plus at least one shadow ray for every pixel sample that sees the
    // lit sphere or floor; the CPU reference counts exactly the same rays.
    let cpu = gpu_render::cpu::render(&scene, None);
    assert_eq!(out.stats.rays_traced, cpu.stats.rays_traced);
    let primary = u64::from(WIDTH) * u64::from(HEIGHT) * u64::from(SPP);
    assert!(out.stats.rays_traced > primary);
    assert!(out.stats.elapsed > Duration::ZERO);
    eprintln!(
        "{}x{} at {SPP} spp: {} rays in {:?} ({:.1} Mrays/s)",
        WIDTH,
        HEIGHT,
        out.stats.rays_traced,
        out.stats.elapsed,
        out.stats.rays_per_second() / 1e6
    );
}

/// An image-sized 2D texture of `format` and `usage`.
fn image_texture(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: WIDTH,
            height: HEIGHT,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn linear_target(device: &wgpu::Device) -> wgpu::Texture {
    image_texture(
        device,
        "smoke linear",
        wgpu::TextureFormat::Rgba32Float,
        wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
    )
}

/// The image is the same bit for bit whether it is traced whole or as three
/// regions into one target, with one slot or many, with either schedule, with or
/// without lanes giving way to finished ones, and with an
/// iteration budget so small that every traversal is suspended and resumed many times.
#[test]
fn regions_slots_and_budgets_do_not_change_the_image() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let renderer = crate::support::gpu::renderer(&gpu);
    let scene = scene(4);
    let timeout = Some(Duration::from_secs(60));

    // Reference: the high-level call into a caller-owned texture.
    let reference = linear_target(device);
    let stats = renderer
        .render_to_texture(
            device,
            queue,
            &scene,
            &reference.create_view(&Default::default()),
            None,
        )
        .expect("render_to_texture succeeds");
    let reference =
        read_texture(device, queue, &reference, 16, timeout).expect("reference reads back");

    // Three uneven bands of rows, each traced into its place in one target.
    let prepared = renderer.upload(device, queue, &scene).expect("prepare");
    // The reference does not give way to finished lanes (off by default); the
    // "lane refill" variant below does wherever the device can (lavapipe can).
    assert!(!prepared.features().refill_lanes);
    let subgroups = device.features().contains(wgpu::Features::SUBGROUP);
    // Samples start in lockstep by default wherever the device can; the "samples not
    // in lockstep" variant below turns it off.
    assert_eq!(prepared.features().lockstep_samples, subgroups);
    if gpu.adapter.get_info().name.contains("llvmpipe") {
        assert!(subgroups, "lavapipe offers subgroup operations");
    }
    let target = linear_target(device);
    let view = target.create_view(&Default::default());
    let mut rays = 0;
    for rows in [0..5, 5..40, 40..HEIGHT] {
        let region = TraceRegion {
            columns: 0..WIDTH,
            rows,
            target_origin: (0, 0),
        };
        rays += renderer
            .trace_into(device, queue, &prepared, &view, &region, None)
            .expect("trace_into")
            .rays_traced;
    }
    let banded = read_texture(device, queue, &target, 16, timeout).expect("reads back");
    assert_eq!(banded, reference, "regions must not change the image");
    assert_eq!(rays, stats.rays_traced, "same rays either way");

    // One slot, and a budget of 3 iterations per dispatch.
    for (label, variant) in [
        (
            "one slot",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    slot_count: Some(1),
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "budget 3",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    iteration_budget: Some(3),
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "lane refill",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    refill_lanes: true,
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "samples not in lockstep",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    lockstep_samples: false,
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "wavefront schedule",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Wavefront),
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "fused schedule, budget 3",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Fused),
                    iteration_budget: Some(3),
                    ..RendererOptions::default()
                },
            ),
        ),
        // The smallest budgets: a budget of 1 once made no progress at all in the
        // fused kernel (its shading step spent the one iteration on nothing).
        (
            "fused schedule, budget 1, lane refill",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Fused),
                    iteration_budget: Some(1),
                    refill_lanes: true,
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "fused schedule, budget 2, lane refill",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Fused),
                    iteration_budget: Some(2),
                    refill_lanes: true,
                    ..RendererOptions::default()
                },
            ),
        ),
        (
            "wavefront schedule, budget 1",
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Wavefront),
                    iteration_budget: Some(1),
                    ..RendererOptions::default()
                },
            ),
        ),
    ] {
        if label.contains("lane refill") {
            let features = variant
                .upload(device, queue, &scene)
                .expect("prepare")
                .features();
            assert_eq!(
                features.refill_lanes, subgroups,
                "{label} gives way where it can"
            );
        }
        let target = linear_target(device);
        let view = target.create_view(&Default::default());
        let traced = variant
            .render_to_texture(device, queue, &scene, &view, None)
            .expect("render_to_texture");
        let image = read_texture(device, queue, &target, 16, timeout).expect("reads back");
        assert_eq!(image, reference, "{label} must not change the image");
        assert_eq!(traced.rays_traced, stats.rays_traced, "{label}: same rays");
    }
}

/// Lanes that give way to finished ones resume where they stopped: shipped Whitted
/// scenes (polygons and glass, meshes and instances, deep refraction) render the same
/// pixels from the same rays with and without it.
#[test]
fn giving_way_to_finished_lanes_does_not_change_the_image() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let refill = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            schedule: Some(Schedule::Fused),
            refill_lanes: true,
            ..RendererOptions::default()
        },
    );
    let plain = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            schedule: Some(Schedule::Fused),
            ..RendererOptions::default()
        },
    );
    for path in ["showcase.toml", "glass.toml", "models.toml"] {
        let scene = crate::support::scenes::reduced(
            crate::support::scenes::shipped(path),
            96,
            RenderOverrides {
                max_depth: Some(16),
                ..RenderOverrides::default()
            },
        );
        let what = format!("{path}, lanes refilled and not");
        crate::support::gpu::assert_renders_identical(&gpu, &refill, &plain, &scene, &what);
    }
}

/// Samples that start in lockstep across a subgroup wait for one another, within and
/// across dispatches, but trace the same rays: shipped Whitted scenes (polygons and
/// glass, meshes and instances, deep refraction) and a path-traced one (which does
/// not wait) render the same pixels from the same rays with and without it, with the
/// default budget and with a budget of 3 iterations per dispatch.
#[test]
fn samples_in_lockstep_do_not_change_the_image() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let subgroups = gpu.device.features().contains(wgpu::Features::SUBGROUP);
    for budget in [None, Some(3)] {
        let renderer = |lockstep_samples| {
            crate::support::gpu::renderer_with(
                &gpu,
                RendererOptions {
                    schedule: Some(Schedule::Fused),
                    iteration_budget: budget,
                    lockstep_samples,
                    ..RendererOptions::default()
                },
            )
        };
        let lockstep = renderer(true);
        let free = renderer(false);
        for path in [
            "showcase.toml",
            "glass.toml",
            "models.toml",
            "cornell-box.toml",
        ] {
            let scene = crate::support::scenes::reduced(
                crate::support::scenes::shipped(path),
                64,
                RenderOverrides {
                    samples_per_pixel: Some(4),
                    max_depth: Some(16),
                    ..RenderOverrides::default()
                },
            );
            let features = lockstep
                .upload(&gpu.device, &gpu.queue, &scene)
                .expect("prepare")
                .features();
            assert_eq!(features.lockstep_samples, subgroups, "{path}: where it can");
            let what = format!("{path}, budget {budget:?}, samples in lockstep and not");
            crate::support::gpu::assert_renders_identical(&gpu, &lockstep, &free, &scene, &what);
        }
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let renderer = crate::support::gpu::renderer(&gpu);

    let mut bad = scene(1);
    bad.render.stack_size = 0;
    assert!(matches!(
        renderer.upload(device, queue, &bad),
        Err(RenderError::InvalidSettings(_))
    ));

    // An image wider than one texture can be: `render` tiles it (tests/integration/extremes.rs),
    // `render_to_texture`, which has a single target, refuses it clearly.
    let too_wide = device.limits().max_texture_dimension_2d.checked_add(1);
    if let Some(width) = too_wide.filter(|&w| w <= gpu_render::scene::MAX_IMAGE_DIMENSION) {
        let mut wide = scene(1);
        wide.render.width = width;
        let target = linear_target(device);
        let view = target.create_view(&Default::default());
        match renderer.render_to_texture(device, queue, &wide, &view, None) {
            Err(RenderError::SceneTooLarge { value, limit, .. }) => {
                assert_eq!((value, limit), (u64::from(width), u64::from(width - 1)));
            }
            other => panic!("expected DeviceLimit, got {other:?}"),
        }
    }

    let prepared = renderer.upload(device, queue, &scene(1)).expect("prepare");
    let target = linear_target(device);
    let view = target.create_view(&Default::default());
    let outside = TraceRegion {
        columns: 0..WIDTH,
        rows: 0..HEIGHT + 1,
        target_origin: (0, 0),
    };
    assert!(matches!(
        renderer.trace_into(device, queue, &prepared, &view, &outside, None),
        Err(RenderError::InvalidRegion { .. })
    ));
    let wrong_format = image_texture(
        device,
        "wrong format",
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::STORAGE_BINDING,
    );
    let result = renderer.trace_into(
        device,
        queue,
        &prepared,
        &wrong_format.create_view(&Default::default()),
        &TraceRegion::whole(WIDTH, HEIGHT),
        None,
    );
    assert!(
        matches!(
            result,
            Err(RenderError::TargetFormat {
                role: "trace target",
                ..
            })
        ),
        "{result:?}"
    );
}

#[test]
fn timestamp_queries_time_the_trace_passes() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let info = gpu.adapter_info();
    if !gpu
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY)
    {
        // lavapipe offers timestamp queries, so CI (which runs on it) must time with them.
        assert!(
            std::env::var_os("CI").is_none() || !info.name.contains("llvmpipe"),
            "CI on {} must have TIMESTAMP_QUERY",
            info.name
        );
        eprintln!(
            "note: skipping the GPU timestamp test, {} lacks TIMESTAMP_QUERY",
            info.name
        );
        return;
    }
    let renderer = crate::support::gpu::renderer(&gpu);
    let out = renderer
        .render(&gpu.device, &gpu.queue, &scene(SPP), None)
        .expect("render succeeds");
    let slack = Duration::from_millis(50);
    let gpu_time = out
        .stats
        .gpu_time
        .expect("a device with timestamps reports GPU time");
    assert!(
        gpu_time > Duration::ZERO && gpu_time <= out.stats.elapsed + slack,
        "GPU time {gpu_time:?}, wall time {:?}",
        out.stats.elapsed
    );
    assert_eq!(
        out.stats.trace_time(),
        (gpu_time, gpu_render::film::TimingSource::GpuTimestamps)
    );
    eprintln!(
        "trace on {}: GPU timestamps {gpu_time:?}, wall {:?}",
        info.name, out.stats.elapsed
    );

    // render_to_texture times its submissions the same way.
    let target = linear_target(&gpu.device);
    let view = target.create_view(&Default::default());
    let stats = renderer
        .render_to_texture(&gpu.device, &gpu.queue, &scene(4), &view, None)
        .expect("render_to_texture succeeds");
    let gpu_time = stats.gpu_time.expect("render_to_texture reports GPU time");
    assert!(gpu_time > Duration::ZERO && gpu_time <= stats.elapsed + slack);
}

/// A device that does not finish in time (a hung or lost GPU) is reported as a lost
/// device with a clear message, not waited on forever. A 1 ns limit stands in for the
/// hang: no real dispatch finishes that fast.
#[test]
fn a_stalled_device_is_an_error_not_a_hang() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            poll_timeout: Some(Duration::from_nanos(1)),
            ..RendererOptions::default()
        },
    );
    let started = std::time::Instant::now();
    match renderer.render(&gpu.device, &gpu.queue, &scene(256), None) {
        Err(error @ RenderError::Timeout(limit)) => {
            assert_eq!(limit, Duration::from_nanos(1));
            assert!(error.to_string().contains("did not finish"), "{error}");
        }
        Err(other) => panic!("expected a timeout, got {other}"),
        Ok(_) => panic!("a 1 ns limit cannot be met by a 256-sample render"),
    }
    assert!(
        started.elapsed() < Duration::from_secs(60),
        "the error took {:?}",
        started.elapsed()
    );
}
