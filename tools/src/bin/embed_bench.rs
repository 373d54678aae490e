//! The cost of a camera move in the frame loop (`Renderer::set_camera`, then the next
//! `encode_samples`, which starts a pass and writes its trace constants) against a
//! full re-upload of the scene with the new camera (what moving the camera cost
//! before: `Renderer::prepare` builds the geometry and BVH and uploads every buffer
//! and image), in alternating runs, medians printed. Bytes are counted as written:
//! the frame loop's through a `BufferWrites` wrapper, the re-upload's as the scene's
//! buffer and image bytes.
//!
//! ```sh
//! cargo run --release -p gpu-render-tools --bin embed_bench -- scenes/showcase.toml --runs 15
//! ```

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use gpu_render::gpu::{AdapterChoice, BufferWrites, HeadlessGpu, Renderer, RendererOptions};
use gpu_render::scene::{Camera, load_scene};

/// Counts the bytes written through it and forwards them.
struct CountingQueue<'a> {
    queue: &'a wgpu::Queue,
    bytes: AtomicU64,
}

impl BufferWrites for CountingQueue<'_> {
    fn write_buffer(&self, buffer: &wgpu::Buffer, offset: u64, data: &[u8]) {
        self.bytes.fetch_add(data.len() as u64, Ordering::Relaxed);
        self.queue.write_buffer(buffer, offset, data);
    }
}

fn median(mut values: Vec<Duration>) -> Duration {
    values.sort();
    values[values.len() / 2]
}

/// Blocks until the queue is idle.
fn wait_idle(gpu: &HeadlessGpu) -> Result<()> {
    gpu.device.poll(wgpu::PollType::Wait {
        submission_index: None,
        timeout: None,
    })?;
    Ok(())
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "scenes/showcase.toml".into());
    let (mut runs, mut frames) = (15usize, 0u32);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--runs" => runs = args.next().context("--runs N")?.parse()?,
            "--frames" => frames = args.next().context("--frames N")?.parse()?,
            other => anyhow::bail!("unknown argument {other}"),
        }
    }
    let scene = load_scene(path.as_ref())?;
    let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
    let renderer = Renderer::new(&gpu.device, RendererOptions::default())?;
    let old = Renderer::new(&gpu.device, RendererOptions::default())?;
    let mut gpu_scene = renderer.upload(&gpu.device, &gpu.queue, &scene)?;
    // A small film: only the pass start's host cost and bytes are measured, not the
    // tracing.
    let mut film = renderer.create_film(&gpu.device, &gpu_scene, 64, 36)?;
    let counting = CountingQueue {
        queue: &gpu.queue,
        bytes: AtomicU64::new(0),
    };
    let camera_at = |i: usize| Camera {
        eye: scene.camera.eye + glam::DVec3::new(0.01 * (i % 7) as f64, 0.0, 0.0),
        ..scene.camera
    };

    let (mut set_camera, mut frame_loop, mut reupload) = (Vec::new(), Vec::new(), Vec::new());
    let (mut frame_loop_bytes, mut reupload_bytes) = (0, 0);
    for run in 0..runs {
        // The frame loop: move the camera, record the next frame's samples, submit.
        let moved = camera_at(run + 1);
        counting.bytes.store(0, Ordering::Relaxed);
        let start = Instant::now();
        renderer.set_camera(&mut gpu_scene, &moved)?;
        set_camera.push(start.elapsed());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.encode_samples(
            &gpu.device,
            &counting,
            &mut encoder,
            &gpu_scene,
            &mut film,
            1,
        )?;
        gpu.queue.submit([encoder.finish()]);
        frame_loop.push(start.elapsed());
        frame_loop_bytes = counting.bytes.load(Ordering::Relaxed);
        wait_idle(&gpu)?;

        // The re-upload: the scene with the new camera, uploaded again, until the
        // queue has taken every byte.
        let moved_scene = gpu_render::scene::Scene {
            camera: moved,
            ..scene.clone()
        };
        let start = Instant::now();
        let prepared = old.upload(&gpu.device, &gpu.queue, &moved_scene)?;
        gpu.queue.submit([]);
        wait_idle(&gpu)?;
        reupload.push(start.elapsed());
        reupload_bytes = prepared.scene_bytes() + prepared.image_bytes();
    }
    let adapter = gpu.adapter_info();
    println!(
        "{path} on {} ({:?}, {}), {runs} alternating runs",
        adapter.name, adapter.backend, adapter.driver_info
    );
    println!(
        "set_camera alone:                           median {:>10.6} ms, 0 bytes written",
        median(set_camera).as_secs_f64() * 1e3
    );
    println!(
        "set_camera + next encode_samples + submit: median {:>10.3} ms, {frame_loop_bytes} bytes written",
        median(frame_loop).as_secs_f64() * 1e3
    );
    println!(
        "full re-upload (Renderer::prepare):     median {:>10.3} ms, {reupload_bytes} bytes written",
        median(reupload).as_secs_f64() * 1e3
    );
    if frames > 0 {
        frame_loop_rate(&gpu, &renderer, &gpu_scene, frames)?;
    }
    Ok(())
}

/// Runs `frames` frames of the frame loop on a film of the scene's size, one sample
/// per pixel asked per frame, each frame waited for (as a swapchain would pace it),
/// and prints the median frame time and the samples per pixel completed per second.
fn frame_loop_rate(
    gpu: &HeadlessGpu,
    renderer: &Renderer,
    gpu_scene: &gpu_render::gpu::GpuScene,
    frames: u32,
) -> Result<()> {
    let (width, height) = (gpu_scene.width(), gpu_scene.height());
    let mut film = renderer.create_film(&gpu.device, gpu_scene, width, height)?;
    // Warm-up: lavapipe compiles the pipeline at its first dispatch.
    renderer.render_to_image(&gpu.device, &gpu.queue, gpu_scene, &mut film)?;
    film.reset();
    let mut times = Vec::new();
    let start = Instant::now();
    for _ in 0..frames {
        let frame = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.encode_samples(
            &gpu.device,
            &gpu.queue,
            &mut encoder,
            gpu_scene,
            &mut film,
            1,
        )?;
        gpu.queue.submit([encoder.finish()]);
        wait_idle(gpu)?;
        times.push(frame.elapsed());
    }
    let elapsed = start.elapsed();
    film.collect_progress()?;
    println!(
        "frame loop at {width}x{height}, 1 sample per frame asked: median frame {:.1} ms \
         ({:.2} frames/s), {} samples per pixel completed in {:.2} s ({:.2} spp/s, {} passes)",
        median(times).as_secs_f64() * 1e3,
        f64::from(frames) / elapsed.as_secs_f64(),
        film.samples(),
        elapsed.as_secs_f64(),
        f64::from(film.samples()) / elapsed.as_secs_f64(),
        film.passes()
    );
    Ok(())
}
