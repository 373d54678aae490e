//! A minimal headless embedding of the frame-loop API: the application owns the
//! instance, adapter, device, queue and encoders; gpu-render uploads the scene once,
//! adds one sample per pixel per "frame" to a film without blocking, and the
//! application reads the finished film back and saves it.
//!
//! The gpu-render-specific part is the 12 lines between the `gpu-render:` markers
//! below, plus the `required_limits` and `required_features` lines of the device
//! request: 14 lines.
//!
//! ```sh
//! cargo run --release --example embed_headless -- scenes/minimal.toml embedded.png
//! ```

use anyhow::{Context, Result};
use gpu_render::{Renderer, RendererOptions};

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let scene_path = args.next().unwrap_or_else(|| "scenes/minimal.toml".into());
    let output = args.next().unwrap_or_else(|| "embedded.png".into());

    // The application's own device: gpu-render never creates one behind its back.
    let mut instance_desc = wgpu::InstanceDescriptor::new_without_display_handle();
    instance_desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    let instance = wgpu::Instance::new(instance_desc);
    let adapter =
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .context("no GPU adapter")?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: Renderer::required_limits(&adapter.limits()),
        required_features: Renderer::optional_features(adapter.features()),
        ..Default::default()
    }))?;

    // gpu-render: from here
    let scene = gpu_render::load_scene(scene_path.as_ref())?;
    let renderer = Renderer::new(&device, RendererOptions::default())?;
    let gpu_scene = renderer.upload(&device, &queue, &scene)?;
    let (width, height) = (gpu_scene.width(), gpu_scene.height());
    let mut film = renderer.create_film(&device, &gpu_scene, width, height)?;
    for _frame in 0..gpu_scene.samples_per_pixel() {
        let mut encoder = device.create_command_encoder(&Default::default());
        renderer.encode_samples(&device, &queue, &mut encoder, &gpu_scene, &mut film, 1)?;
        queue.submit([encoder.finish()]);
    }
    renderer.finish(&device, &queue, &gpu_scene, &mut film)?;
    let shown = renderer.read_film(&device, &queue, &gpu_scene, &film)?;
    // gpu-render: to here

    image::RgbaImage::from_raw(width, height, shown.display_rgba8)
        .context("readback size")?
        .save(&output)
        .with_context(|| format!("cannot write {output}"))?;
    println!(
        "wrote {output} ({width}x{height}, {} samples per pixel in {} passes)",
        shown.samples,
        film.passes()
    );
    Ok(())
}
