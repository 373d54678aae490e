//! How a wgpu application embeds gpu-render: it keeps its own instance, adapter,
//! device, queue, textures and command encoder, and asks the renderer only to record
//! passes into that encoder.
//!
//! ```sh
//! cargo run --release --example embed -- scenes/minimal.toml embedded.png
//! ```

use anyhow::{Context, Result};
use gpu_render::gpu::{DISPLAY_FORMAT, LINEAR_FORMAT};
use gpu_render::gpu::{GpuRenderer, read_texture};
use gpu_render::scene::load_scene;

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let scene_path = args.next().unwrap_or_else(|| "scenes/minimal.toml".into());
    let output = args.next().unwrap_or_else(|| "embedded.png".into());
    let scene = load_scene(scene_path.as_ref())?;

    // The application's own device: gpu-render never creates one behind its back.
    let mut instance_desc = wgpu::InstanceDescriptor::new_without_display_handle();
    instance_desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    let instance = wgpu::Instance::new(instance_desc);
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .context("no GPU adapter")?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("application device"),
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;

    // The application's own textures: a linear float target and a display target.
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
    let linear = texture(
        "application linear target",
        LINEAR_FORMAT,
        U::STORAGE_BINDING | U::TEXTURE_BINDING,
    );
    let display = texture(
        "application display target",
        DISPLAY_FORMAT,
        U::STORAGE_BINDING | U::COPY_SRC,
    );
    let linear_view = linear.create_view(&Default::default());
    let display_view = display.create_view(&Default::default());

    // gpu-render traces into the application's texture, then records its display
    // pass into the application's encoder; the application decides when to submit.
    let renderer = GpuRenderer::new(&device)?;
    let prepared = renderer.prepare(&device, &queue, &scene)?;
    let region = gpu_render::gpu::TraceRegion::whole(width, height);
    renderer.trace_into(&device, &queue, &prepared, &linear_view, &region, None)?;
    let mut encoder = device.create_command_encoder(&Default::default());
    renderer.encode_display(
        &device,
        &mut encoder,
        &linear_view,
        &display_view,
        prepared.display_encodes_srgb(),
    )?;
    queue.submit([encoder.finish()]);

    let rgba8 = read_texture(
        &device,
        &queue,
        &display,
        4,
        Some(std::time::Duration::from_secs(120)),
    )?;
    image::RgbaImage::from_raw(width, height, rgba8)
        .context("readback size")?
        .save(&output)
        .with_context(|| format!("cannot write {output}"))?;
    println!("wrote {output} ({width}x{height})");
    Ok(())
}
