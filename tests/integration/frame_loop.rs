//! The frame-loop API (`gpu::Renderer`): device limits, progressive accumulation,
//! camera moves and the draw into a colour attachment.
//!
//! Progressive accumulation and camera moves are compared with the one-shot renders
//! bit for bit: a film's pixel sums its samples in the same order however they were
//! split into calls (`src/gpu/film.rs`), and the camera's constants are the ones a
//! fresh upload computes. The CPU comparison uses the tolerance of `gpu_vs_cpu.rs`
//! (`|gpu - cpu| <= 1e-3 + 5e-3·|cpu|`, at most 0.5% of the pixels outside it: f32
//! against f64), and writes both images and a difference image under
//! `target/test-output/` on failure.

use std::sync::Mutex;

use crate::support::compare::{Tolerance, assert_images_match};
use gpu_render::film::LinearImage;
use gpu_render::gpu::{
    BufferWrites, Film, GpuScene, HeadlessGpu, RenderError, Renderer, RendererOptions, Schedule,
};
use gpu_render::low_level::gpu::layout::FrameUniforms;
use gpu_render::scene::{Camera, LightingSpace, RenderOverrides, Scene};

const CPU_TOLERANCE: Tolerance = Tolerance {
    absolute: 1e-3,
    relative: 5e-3,
    outlier_fraction: 0.005,
};

/// A shipped scene shrunk to `width` pixels with `spp` samples per pixel.
fn scene(name: &str, width: u32, spp: u32) -> Scene {
    crate::support::scenes::reduced(
        crate::support::scenes::shipped(name),
        width,
        RenderOverrides {
            samples_per_pixel: Some(spp),
            ..RenderOverrides::default()
        },
    )
}

fn renderer(gpu: &HeadlessGpu, options: RendererOptions) -> Renderer {
    Renderer::new(&gpu.device, options).unwrap_or_else(|e| panic!("Renderer::new: {e}"))
}

/// Submits `encoder` and waits for it (the map callbacks of the film's readbacks run
/// in the wait).
fn submit_and_wait(gpu: &HeadlessGpu, encoder: wgpu::CommandEncoder) {
    let index = gpu.queue.submit([encoder.finish()]);
    gpu.device
        .poll(wgpu::PollType::Wait {
            submission_index: Some(index),
            timeout: None,
        })
        .unwrap_or_else(|e| panic!("poll: {e}"));
}

/// Asserts that two images are identical bit for bit, naming the first difference.
fn assert_identical(label: &str, expected: &LinearImage, actual: &LinearImage) {
    assert_eq!(
        (expected.width, expected.height),
        (actual.width, actual.height),
        "{label}: sizes differ"
    );
    let first = expected
        .pixels
        .iter()
        .zip(&actual.pixels)
        .position(|(e, a)| e.map(f32::to_bits) != a.map(f32::to_bits));
    if let Some(i) = first {
        // Write both for inspection; the assertion below fails anyway.
        let _ = assert_images_match(
            label,
            expected,
            actual,
            Tolerance {
                absolute: 0.0,
                relative: 0.0,
                outlier_fraction: 0.0,
            },
        );
        panic!(
            "{label}: pixel {i} differs: expected {:?}, got {:?}",
            expected.pixels[i], actual.pixels[i]
        );
    }
}

#[test]
fn a_device_with_default_limits_gets_a_typed_error_and_required_limits_work() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let request = |limits: wgpu::Limits| {
        pollster::block_on(gpu.adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("limits test"),
            required_limits: limits,
            ..Default::default()
        }))
        .unwrap_or_else(|e| panic!("request_device: {e}"))
    };
    for (name, limits) in [
        ("default", wgpu::Limits::default()),
        ("downlevel", wgpu::Limits::downlevel_defaults()),
    ] {
        let (device, _queue) = request(limits);
        // The default uncaptured-error handler panics: reaching the match at all shows
        // no pipeline was built outside an error scope.
        match Renderer::new(&device, RendererOptions::default()) {
            Err(RenderError::Limit {
                limit,
                needed,
                available,
            }) => {
                assert_eq!(limit, "max_storage_buffers_per_shader_stage", "{name}");
                assert_eq!(
                    available,
                    u64::from(device.limits().max_storage_buffers_per_shader_stage)
                );
                assert!(needed > available, "{name}: needed {needed}");
            }
            Err(other) => panic!("{name}: expected RenderError::Limit, got {other}"),
            Ok(_) => panic!("{name}: a renderer was built on a device that is too small"),
        }
    }
    let (device, queue) = request(Renderer::required_limits(&gpu.adapter.limits()));
    let renderer = Renderer::new(&device, RendererOptions::default())
        .unwrap_or_else(|e| panic!("Renderer::new with required_limits: {e}"));
    let scene = scene("minimal.toml", 32, 2);
    let gpu_scene = renderer
        .upload(&device, &queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let mut film = renderer
        .create_film(&device, &gpu_scene, 32, scene.render.height)
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let image = renderer
        .render_to_image(&device, &queue, &gpu_scene, &mut film)
        .unwrap_or_else(|e| panic!("render_to_image: {e}"));
    assert_eq!(image.samples, 2);
    assert!(image.rays_traced >= u64::from(32 * scene.render.height) * 2);
}

/// Renders `scene` progressively in calls of `splits` samples, waiting after each call
/// when `wait_between` (so that each call is a pass of its own) or not at all, then
/// finishing; returns the film and its image.
fn progressive(
    gpu: &HeadlessGpu,
    renderer: &Renderer,
    gpu_scene: &GpuScene,
    splits: &[u32],
    wait_between: bool,
) -> (Film, LinearImage) {
    let mut film = renderer
        .create_film(
            &gpu.device,
            gpu_scene,
            gpu_scene.width(),
            gpu_scene.height(),
        )
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    for &n in splits {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer
            .encode_samples(
                &gpu.device,
                &gpu.queue,
                &mut encoder,
                gpu_scene,
                &mut film,
                n,
            )
            .unwrap_or_else(|e| panic!("encode_samples: {e}"));
        if wait_between {
            submit_and_wait(gpu, encoder);
            renderer
                .finish(&gpu.device, &gpu.queue, gpu_scene, &mut film)
                .unwrap_or_else(|e| panic!("finish: {e}"));
        } else {
            gpu.queue.submit([encoder.finish()]);
        }
    }
    renderer
        .finish(&gpu.device, &gpu.queue, gpu_scene, &mut film)
        .unwrap_or_else(|e| panic!("finish: {e}"));
    let image = renderer
        .read_film(&gpu.device, &gpu.queue, gpu_scene, &film)
        .unwrap_or_else(|e| panic!("read_film: {e}"));
    (film, image.image)
}

#[test]
fn progressive_samples_equal_a_one_shot_render_and_the_cpu_reference() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let old = crate::support::gpu::renderer(&gpu);
    let renderer = renderer(&gpu, RendererOptions::default());
    for name in ["showcase.toml", "glass.toml"] {
        let scene = scene(name, 64, 8);
        let one_shot = old
            .render(&gpu.device, &gpu.queue, &scene, None)
            .unwrap_or_else(|e| panic!("{name}: one-shot render: {e}"));
        let gpu_scene = renderer
            .upload(&gpu.device, &gpu.queue, &scene)
            .unwrap_or_else(|e| panic!("{name}: upload: {e}"));
        let label = name.trim_end_matches(".toml");

        // Three passes of 1, 3 and 4 samples: sample indices continue across calls.
        let (film, image) = progressive(&gpu, &renderer, &gpu_scene, &[1, 3, 4], true);
        assert_eq!(film.passes(), 3, "{name}: each waited call is one pass");
        assert_eq!(film.samples(), 8);
        assert!(film.is_complete());
        assert_identical(
            &format!("frame-loop-{label}-passes"),
            &one_shot.image,
            &image,
        );
        // Rays: the same paths, so the same count as the one-shot render.
        assert_eq!(film.rays_traced(), one_shot.stats.rays_traced, "{name}");

        // Calls submitted without waiting: samples queue into fewer passes, and the
        // image is still the same.
        let (film, image) = progressive(&gpu, &renderer, &gpu_scene, &[2, 1, 1, 4], false);
        assert_eq!(film.samples(), 8);
        assert!((1..=4).contains(&film.passes()), "{}", film.passes());
        assert_identical(
            &format!("frame-loop-{label}-queued"),
            &one_shot.image,
            &image,
        );

        let cpu = gpu_render::cpu::render(&scene, None);
        let comparison = assert_images_match(
            &format!("frame-loop-{label}-cpu"),
            &cpu.image,
            &image,
            CPU_TOLERANCE,
        );
        eprintln!(
            "{label}: {} of {} pixels outside tolerance, max |Δ| {:.2e}, RMSE {:.2e}",
            comparison.outliers, comparison.pixels, comparison.max_abs_error, comparison.rmse
        );
    }
}

/// A queue wrapper that records every write and forwards it.
struct RecordingQueue<'a> {
    queue: &'a wgpu::Queue,
    writes: Mutex<Vec<(wgpu::Buffer, u64, usize)>>,
}

impl BufferWrites for RecordingQueue<'_> {
    fn write_buffer(&self, buffer: &wgpu::Buffer, offset: u64, data: &[u8]) {
        self.writes
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push((buffer.clone(), offset, data.len()));
        self.queue.write_buffer(buffer, offset, data);
    }
}

#[test]
fn a_camera_move_uploads_only_the_trace_constants_and_equals_a_fresh_upload() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = renderer(&gpu, RendererOptions::default());
    let scene = scene("showcase.toml", 48, 4);
    let mut gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let mut film = renderer
        .create_film(
            &gpu.device,
            &gpu_scene,
            gpu_scene.width(),
            gpu_scene.height(),
        )
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let before = renderer
        .render_to_image(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
        .unwrap_or_else(|e| panic!("render_to_image: {e}"));

    // The move also puts a thin lens on the camera: the lens travels in the trace
    // constants like the rest of the camera.
    let moved = Camera {
        eye: scene.camera.eye + glam::DVec3::new(0.7, 0.4, -0.3),
        fov_y_degrees: scene.camera.fov_y_degrees * 0.9,
        orthographic_half_height: None,
        lens: Some(gpu_render::scene::ThinLens {
            aperture_radius: 0.15,
            focus_distance: None,
        }),
        ..scene.camera
    };
    renderer
        .set_camera(&mut gpu_scene, &moved)
        .unwrap_or_else(|e| panic!("set_camera: {e}"));
    assert_eq!(gpu_scene.camera(), &moved);

    // Every write of the frames after the move goes through the recorder.
    let recorder = RecordingQueue {
        queue: &gpu.queue,
        writes: Mutex::new(Vec::new()),
    };
    let mut frames = 0;
    let mut samples = gpu_scene.samples_per_pixel();
    loop {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer
            .encode_samples(
                &gpu.device,
                &recorder,
                &mut encoder,
                &gpu_scene,
                &mut film,
                samples,
            )
            .unwrap_or_else(|e| panic!("encode_samples: {e}"));
        samples = 0;
        let done = film.is_complete();
        submit_and_wait(&gpu, encoder);
        if done {
            break;
        }
        frames += 1;
        assert!(frames < 10_000, "the film never completed");
    }
    assert_eq!(film.samples(), gpu_scene.samples_per_pixel());
    let writes = recorder
        .writes
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    // One pass: one write of the 208-byte trace constants into a uniform buffer, and
    // nothing into any storage buffer (the scene's buffers are all storage buffers).
    assert_eq!(writes.len(), 1, "writes after the camera move: {writes:?}");
    let (buffer, offset, bytes) = &writes[0];
    assert_eq!((*offset, *bytes), (0, size_of::<FrameUniforms>()));
    assert_eq!(size_of::<FrameUniforms>(), 208);
    assert!(buffer.usage().contains(wgpu::BufferUsages::UNIFORM));
    assert!(!buffer.usage().contains(wgpu::BufferUsages::STORAGE));
    assert_eq!(film.passes(), 1);

    let after = renderer
        .read_film(&gpu.device, &gpu.queue, &gpu_scene, &film)
        .unwrap_or_else(|e| panic!("read_film: {e}"));
    assert_ne!(after.image, before.image, "the camera move changed nothing");
    let fresh_scene = Scene {
        camera: moved,
        ..scene.clone()
    };
    let fresh = renderer
        .upload(&gpu.device, &gpu.queue, &fresh_scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let mut fresh_film = renderer
        .create_film(&gpu.device, &fresh, fresh.width(), fresh.height())
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let expected = renderer
        .render_to_image(&gpu.device, &gpu.queue, &fresh, &mut fresh_film)
        .unwrap_or_else(|e| panic!("render_to_image: {e}"));
    assert_identical("frame-loop-set-camera", &expected.image, &after.image);
    assert_eq!(after.display_rgba8, expected.display_rgba8);

    // An undefined view is refused and the scene keeps its camera.
    let bad = Camera {
        look_at: moved.eye,
        ..moved
    };
    assert!(matches!(
        renderer.set_camera(&mut gpu_scene, &bad),
        Err(RenderError::InvalidCamera(_))
    ));
    // So are a lens without an aperture and a lens on an orthographic camera.
    let no_aperture = Camera {
        lens: Some(gpu_render::scene::ThinLens {
            aperture_radius: 0.0,
            focus_distance: None,
        }),
        ..moved
    };
    let orthographic_lens = Camera {
        orthographic_half_height: Some(1.0),
        ..moved
    };
    for bad in [no_aperture, orthographic_lens] {
        assert!(matches!(
            renderer.set_camera(&mut gpu_scene, &bad),
            Err(RenderError::InvalidCamera(_))
        ));
    }
    assert_eq!(gpu_scene.camera(), &moved);
}

/// Draws `film` into a fresh `format` attachment `scale` times its size and reads it
/// back as RGBA8.
fn draw_into(
    gpu: &HeadlessGpu,
    renderer: &Renderer,
    gpu_scene: &GpuScene,
    film: &Film,
    format: wgpu::TextureFormat,
    scale: u32,
) -> Vec<u8> {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("draw target"),
        size: wgpu::Extent3d {
            width: film.width() * scale,
            height: film.height() * scale,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("application pass"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::RED),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        renderer
            .draw(&mut pass, gpu_scene, film)
            .unwrap_or_else(|e| panic!("draw: {e}"));
    }
    submit_and_wait(gpu, encoder);
    gpu_render::gpu::read_texture(&gpu.device, &gpu.queue, &texture, 4, None)
        .unwrap_or_else(|e| panic!("read_texture: {e}"))
}

#[test]
fn draw_scales_the_film_up_to_fill_the_viewport() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let renderer = renderer(
        &gpu,
        RendererOptions {
            surface_format: Some(format),
            ..RendererOptions::default()
        },
    );
    let scene = scene("minimal.toml", 24, 1);
    let gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let (width, height) = (gpu_scene.width(), gpu_scene.height());
    let mut film = renderer
        .create_film(&gpu.device, &gpu_scene, width, height)
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    renderer
        .render_to_image(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
        .unwrap_or_else(|e| panic!("render_to_image: {e}"));
    let one = draw_into(&gpu, &renderer, &gpu_scene, &film, format, 1);
    let scale = 3;
    let scaled = draw_into(&gpu, &renderer, &gpu_scene, &film, format, scale);
    assert_eq!(scaled.len(), one.len() * (scale * scale) as usize);
    // Every framebuffer pixel shows the film texel under its centre: a block of
    // scale × scale pixels per texel, exactly its value.
    let mut wrong = 0;
    for y in 0..height * scale {
        for x in 0..width * scale {
            let big = ((y * width * scale + x) * 4) as usize;
            let small = (((y / scale) * width + x / scale) * 4) as usize;
            if scaled[big..big + 4] != one[small..small + 4] {
                wrong += 1;
            }
        }
    }
    assert_eq!(
        wrong, 0,
        "{wrong} pixels of the 3x draw differ from their texel"
    );
    // The image is not uniform, so the comparison tests the mapping.
    assert!(one.chunks(4).any(|p| p != &one[0..4]));
}

#[test]
fn draw_applies_the_scenes_srgb_rule_once_on_any_attachment() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    for space in [LightingSpace::Linear, LightingSpace::NaiveGamma] {
        let scene = crate::support::scenes::reduced(
            crate::support::scenes::shipped("linear-vs-gamma.toml"),
            40,
            RenderOverrides {
                samples_per_pixel: Some(2),
                lighting_space: Some(space),
                ..RenderOverrides::default()
            },
        );
        for format in [
            wgpu::TextureFormat::Rgba8UnormSrgb,
            wgpu::TextureFormat::Rgba8Unorm,
        ] {
            let renderer = renderer(
                &gpu,
                RendererOptions {
                    surface_format: Some(format),
                    ..RendererOptions::default()
                },
            );
            let gpu_scene = renderer
                .upload(&gpu.device, &gpu.queue, &scene)
                .unwrap_or_else(|e| panic!("upload: {e}"));
            let mut film = renderer
                .create_film(
                    &gpu.device,
                    &gpu_scene,
                    gpu_scene.width(),
                    gpu_scene.height(),
                )
                .unwrap_or_else(|e| panic!("create_film: {e}"));
            let shown = renderer
                .render_to_image(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
                .unwrap_or_else(|e| panic!("render_to_image: {e}"));
            let drawn = draw_into(&gpu, &renderer, &gpu_scene, &film, format, 1);
            assert_eq!(drawn.len(), shown.display_rgba8.len());
            // The attachment's own encoding may round differently from the display
            // pass's exact quantisation: one level at most.
            let worst = drawn
                .iter()
                .zip(&shown.display_rgba8)
                .map(|(a, b)| a.abs_diff(*b))
                .max()
                .unwrap_or(0);
            assert!(
                worst <= 1,
                "{space:?} into {format:?}: drawn values differ from the display pass by \
                 up to {worst} levels"
            );
        }
    }
    // A renderer without a surface format refuses to draw (nothing is recorded).
    let renderer = renderer(&gpu, RendererOptions::default());
    let scene = scene("minimal.toml", 16, 1);
    let gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let film = renderer
        .create_film(&gpu.device, &gpu_scene, 16, 16)
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: 16,
            height: 16,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: None,
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations::default(),
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    assert!(matches!(
        renderer.draw(&mut pass, &gpu_scene, &film),
        Err(RenderError::NoSurfaceFormat)
    ));
}

#[test]
fn both_schedules_and_resized_films_equal_one_shot_renders() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let old = crate::support::gpu::renderer(&gpu);
    let scene = scene("glass.toml", 48, 4);
    let one_shot = old
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("one-shot render: {e}"));
    for schedule in [Schedule::Wavefront, Schedule::Fused] {
        let renderer = renderer(
            &gpu,
            RendererOptions {
                schedule: Some(schedule),
                ..RendererOptions::default()
            },
        );
        let gpu_scene = renderer
            .upload(&gpu.device, &gpu.queue, &scene)
            .unwrap_or_else(|e| panic!("upload: {e}"));
        let (mut film, image) = progressive(&gpu, &renderer, &gpu_scene, &[1, 3], true);
        assert_eq!(film.passes(), 2);
        assert_identical(
            &format!("frame-loop-{schedule:?}").to_lowercase(),
            &one_shot.image,
            &image,
        );

        // A resized film renders the image of the scene at that size.
        let small = crate::support::scenes::reduced(scene.clone(), 30, RenderOverrides::default());
        film.resize(&gpu.device, &renderer, 30, small.render.height)
            .unwrap_or_else(|e| panic!("resize: {e}"));
        assert_eq!(film.samples(), 0);
        let resized = renderer
            .render_to_image(&gpu.device, &gpu.queue, &gpu_scene, &mut film)
            .unwrap_or_else(|e| panic!("render_to_image: {e}"));
        let expected = old
            .render(&gpu.device, &gpu.queue, &small, None)
            .unwrap_or_else(|e| panic!("one-shot render: {e}"));
        assert_identical("frame-loop-resized", &expected.image, &resized.image);
    }
}

#[test]
fn unsuitable_targets_and_films_get_typed_errors() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = renderer(&gpu, RendererOptions::default());
    let scene = scene("minimal.toml", 16, 1);
    let gpu_scene = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let film = renderer
        .create_film(&gpu.device, &gpu_scene, 16, 12)
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let target = |format, usage, width| {
        gpu.device
            .create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width,
                    height: 12,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    use wgpu::TextureFormat as F;
    use wgpu::TextureUsages as U;
    let display = |view: &wgpu::TextureView| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.encode_display(&gpu.device, &mut encoder, &gpu_scene, &film, view)
    };
    assert!(matches!(
        display(&target(F::Rgba16Float, U::STORAGE_BINDING, 16)),
        Err(RenderError::TargetFormat {
            expected: F::Rgba8Unorm,
            found: F::Rgba16Float,
            ..
        })
    ));
    assert!(matches!(
        display(&target(F::Rgba8Unorm, U::TEXTURE_BINDING, 16)),
        Err(RenderError::TargetUsage { .. })
    ));
    assert!(matches!(
        display(&target(F::Rgba8Unorm, U::STORAGE_BINDING, 20)),
        Err(RenderError::TargetSize {
            film: (16, 12),
            target: (20, 12),
            ..
        })
    ));
    assert!(display(&target(F::Rgba8Unorm, U::STORAGE_BINDING, 16)).is_ok());

    // A film sized past the device's textures names the limit.
    let side = gpu.device.limits().max_texture_dimension_2d + 1;
    assert!(matches!(
        renderer.create_film(&gpu.device, &gpu_scene, side, 1),
        Err(RenderError::Limit {
            limit: "max_texture_dimension_2d",
            ..
        })
    ));

    // A film made for shallow bounce stacks refuses a scene with deeper ones.
    let deep = Scene {
        render: gpu_render::scene::RenderSettings {
            stack_size: scene.render.stack_size + 4,
            ..scene.render
        },
        ..scene.clone()
    };
    let deep_scene = renderer
        .upload(&gpu.device, &gpu.queue, &deep)
        .unwrap_or_else(|e| panic!("upload: {e}"));
    let mut shallow = renderer
        .create_film(&gpu.device, &gpu_scene, 16, 12)
        .unwrap_or_else(|e| panic!("create_film: {e}"));
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    assert!(matches!(
        renderer.encode_samples(
            &gpu.device,
            &gpu.queue,
            &mut encoder,
            &deep_scene,
            &mut shallow,
            1
        ),
        Err(RenderError::FilmStack { .. })
    ));
}
