//! Times a scene on the GPU backend and on the CPU reference, alternating the two so
//! that both see the same machine load, and prints medians.
//!
//! ```sh
//! cargo run --release --example bench -- scenes/showcase.toml --width 1920 --height 1080 --runs 3
//! ```
//!
//! "trace" is the tracing work alone (`RenderStats::elapsed`: GPU submissions of the
//! trace pass, or the CPU threads); "total" adds the display pass and readback on the
//! GPU. Rays are counted by the tracers as they trace them, not estimated.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Parser;
use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu};
use gpu_render::scene::{RenderOverrides, load_scene};

#[derive(Parser)]
struct Args {
    /// Scene file.
    scene: PathBuf,
    /// Image width override.
    #[arg(long)]
    width: Option<u32>,
    /// Image height override.
    #[arg(long)]
    height: Option<u32>,
    /// Samples-per-pixel override.
    #[arg(long)]
    spp: Option<u32>,
    /// Timed runs per backend (after one warm-up run of each).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Skip the CPU reference.
    #[arg(long)]
    gpu_only: bool,
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut scene = load_scene(&args.scene)?;
    scene.render = scene
        .render
        .with_overrides(&RenderOverrides {
            width: args.width,
            height: args.height,
            samples_per_pixel: args.spp,
            ..RenderOverrides::default()
        })
        .map_err(anyhow::Error::msg)?;
    let gpu = HeadlessGpu::new(&AdapterChoice::Default).context("no GPU adapter")?;
    let renderer = GpuRenderer::new(&gpu.device)?;
    let info = gpu.adapter_info();
    println!(
        "scene {} at {}x{}, {} spp, max depth {}; adapter: {} ({:?}); CPU threads: {}",
        args.scene.display(),
        scene.render.width,
        scene.render.height,
        scene.render.samples_per_pixel,
        scene.render.max_depth,
        info.name,
        info.backend,
        std::thread::available_parallelism().map_or(1, usize::from)
    );
    // Warm-up: the first dispatch compiles the pipeline (lavapipe runs LLVM then).
    renderer.render(&gpu.device, &gpu.queue, &scene, None)?;
    if !args.gpu_only {
        gpu_render::cpu::render(&scene, None);
    }
    let (mut gpu_trace, mut gpu_total, mut cpu_trace) = (vec![], vec![], vec![]);
    let (mut gpu_rays, mut cpu_rays) = (0, 0);
    for _ in 0..args.runs {
        let started = Instant::now();
        let rendered = renderer.render(&gpu.device, &gpu.queue, &scene, None)?;
        gpu_total.push(started.elapsed().as_secs_f64());
        gpu_trace.push(rendered.stats.elapsed.as_secs_f64());
        gpu_rays = rendered.stats.rays_traced;
        if !args.gpu_only {
            let rendered = gpu_render::cpu::render(&scene, None);
            cpu_trace.push(rendered.stats.elapsed.as_secs_f64());
            cpu_rays = rendered.stats.rays_traced;
        }
    }
    let report = |name: &str, trace: f64, total: Option<f64>, rays: u64| {
        let total = total.map_or(String::new(), |t| format!(", total {:.3} s", t));
        println!(
            "{name}: trace {:.3} s{total}; {rays} rays; {:.1} Mrays/s",
            trace,
            rays as f64 / trace / 1e6
        );
    };
    report(
        "GPU",
        median(gpu_trace.clone()),
        Some(median(gpu_total)),
        gpu_rays,
    );
    if !args.gpu_only {
        report("CPU reference", median(cpu_trace.clone()), None, cpu_rays);
        println!(
            "median GPU/CPU trace-time ratio: {:.2} ({} runs each, alternating)",
            median(gpu_trace) / median(cpu_trace),
            args.runs
        );
    }
    Ok(())
}
