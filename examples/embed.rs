//! How a wgpu application embeds gpu-render's frame loop: it keeps its own instance,
//! adapter, device, queue, textures and command encoders; gpu-render records into
//! them. Each "frame" adds one sample per pixel to a film, runs the display pass into
//! the application's `Rgba8Unorm` storage texture and draws the film into the
//! application's `Bgra8UnormSrgb` colour target (a swapchain stand-in) inside the
//! application's own render pass. At the end the storage texture is saved.
//!
//! ```sh
//! cargo run --release --example embed -- scenes/minimal.toml embedded.png
//! ```

use anyhow::{Context, Result};
use gpu_render::gpu::read_texture;
use gpu_render::{Renderer, RendererOptions, load_scene};

/// The application's swapchain format.
const SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Bgra8UnormSrgb;

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let scene_path = args.next().unwrap_or_else(|| "scenes/minimal.toml".into());
    let output = args.next().unwrap_or_else(|| "embedded.png".into());
    let scene = load_scene(scene_path.as_ref())?;

    // The application's own device, with the limits gpu-render needs.
    let mut instance_desc = wgpu::InstanceDescriptor::new_without_display_handle();
    instance_desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    let instance = wgpu::Instance::new(instance_desc);
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .context("no GPU adapter")?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("application device"),
        required_limits: Renderer::required_limits(&adapter.limits()),
        required_features: Renderer::optional_features(adapter.features()),
        ..Default::default()
    }))?;

    // The application's own textures: a storage texture for the display pass and a
    // colour target of the swapchain's format.
    let (width, height) = (scene.render.width, scene.render.height);
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    use wgpu::TextureUsages as U;
    let display = texture(
        "application display target",
        wgpu::TextureFormat::Rgba8Unorm,
        U::STORAGE_BINDING | U::COPY_SRC,
    );
    let surface = texture(
        "application colour target",
        SURFACE_FORMAT,
        U::RENDER_ATTACHMENT,
    );
    let display_view = display.create_view(&Default::default());
    let surface_view = surface.create_view(&Default::default());

    let renderer = Renderer::new(
        &device,
        RendererOptions {
            surface_format: Some(SURFACE_FORMAT),
            ..RendererOptions::default()
        },
    )?;
    let gpu_scene = renderer.upload(&device, &queue, &scene)?;
    let mut film = renderer.create_film(&device, &gpu_scene, width, height)?;
    let mut frames = 0;
    // The frame loop: one sample per pixel per frame until the scene's samples are in
    // (a viewer would go on, or restart after set_camera).
    while frames < gpu_scene.samples_per_pixel() || !film.is_complete() {
        let samples = u32::from(frames < gpu_scene.samples_per_pixel());
        let mut encoder = device.create_command_encoder(&Default::default());
        renderer.encode_samples(
            &device,
            &queue,
            &mut encoder,
            &gpu_scene,
            &mut film,
            samples,
        )?;
        renderer.encode_display(&device, &mut encoder, &gpu_scene, &film, &display_view)?;
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("application frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &surface_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations::default(),
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            renderer.draw(&mut pass, &gpu_scene, &film)?;
            // ... the application's own drawing (UI, overlays) goes here ...
        }
        queue.submit([encoder.finish()]);
        // A windowed application presents here, and the swapchain paces the loop; the
        // next submit runs the film's progress callbacks. Headless, a wait for the
        // frame stands in for the pacing.
        device.poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout: None,
        })?;
        frames += 1;
    }
    println!(
        "{frames} frames, {} samples per pixel in {} passes",
        film.samples(),
        film.passes()
    );

    // The display pass of the last frame ran after the film's last samples.
    let rgba8 = read_texture(&device, &queue, &display, 4, None)?;
    image::RgbaImage::from_raw(width, height, rgba8)
        .context("readback size")?
        .save(&output)
        .with_context(|| format!("cannot write {output}"))?;
    println!("wrote {output} ({width}x{height})");
    Ok(())
}
