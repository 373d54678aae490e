//! `gpu-render tradeoff SCENE`: time against error for the speed/accuracy knobs.

use std::time::Duration;

use anyhow::{Context, Result};
use gpu_render::film::TimingSource;
use gpu_render::scene::{RenderOverrides, RenderSettings, Scene};
use gpu_render::tradeoff::{
    Knobs, Measurement, default_sweep, mean_flip, pareto_front, plot_png, rmse, to_csv,
};

use crate::args::TradeoffArgs;
use crate::backend::{Backend, Frame, GpuOptions};
use crate::progress::Progress;

/// The files written into `--out-dir`.
const OUTPUT_FILES: [&str; 3] = ["reference.png", "tradeoff.csv", "tradeoff.png"];

/// Renders the reference, sweeps the knobs and writes the table, CSV and plot.
///
/// Everything that can be checked (the flags, by clap; the scene; the settings; the
/// output folder) is checked before the folder is created or a ray is traced.
pub fn run(args: &TradeoffArgs) -> Result<()> {
    if args.out_dir.exists() && !args.out_dir.is_dir() {
        anyhow::bail!(
            "{}: --out-dir must be a directory, and this is a file",
            args.out_dir.display()
        );
    }
    let scene = crate::load(&args.scene, args.sandbox, false)?.scene;
    let height = (u64::from(scene.render.height) * u64::from(args.width)
        / u64::from(scene.render.width))
    .max(1) as u32;
    let base = scene
        .render
        .with_overrides(&RenderOverrides {
            width: Some(args.width),
            height: Some(height),
            ..RenderOverrides::default()
        })
        .map_err(|message| anyhow::anyhow!("invalid --width {}: {message}", args.width))?;
    let scene = Scene {
        render: base,
        ..scene
    };
    let reference_knobs = Knobs {
        samples_per_pixel: args.reference_spp,
        max_depth: args.reference_depth,
        min_ray_weight: 0.0,
    };
    let reference_scene = with_knobs(&scene, reference_knobs)?;
    for name in OUTPUT_FILES {
        let path = args.out_dir.join(name);
        let inputs = std::iter::once((args.scene.as_path(), "scene file"))
            .chain(scene.images.iter().map(|i| (i.path.as_path(), "image")));
        gpu_render::output::check_not_an_input(&path, inputs)?;
    }
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("cannot create {}", args.out_dir.display()))?;
    for name in OUTPUT_FILES {
        gpu_render::output::check_output_path(&args.out_dir.join(name))?;
    }
    let backend = Backend::open(args.backend, None, &scene, &GpuOptions::default(), false)?;

    let progress = Progress::new("rendering the reference", true);
    let reference = backend.render(&reference_scene, &|done, total| {
        progress.update(done, total)
    })?;
    progress.finish();
    let reference_path = args.out_dir.join("reference.png");
    gpu_render::output::write_image(&reference_path, &reference.image, &reference.display_rgba8)?;

    let sweep = default_sweep();
    // The first render at each stack size compiles its pipeline: keep that out of the
    // timings.
    let mut warmed = Vec::new();
    for knobs in &sweep {
        if !warmed.contains(&knobs.max_depth) {
            let warm = Knobs {
                samples_per_pixel: 1,
                ..*knobs
            };
            backend.render(&with_knobs(&scene, warm)?, &|_, _| {})?;
            warmed.push(knobs.max_depth);
        }
    }

    // Every render on this backend is timed the same way: GPU timestamps where the
    // device has them (as the reference render shows), wall time otherwise.
    let (_, source) = reference.stats.trace_time();
    let timing = match source {
        TimingSource::GpuTimestamps => "GPU timestamps of the trace passes",
        TimingSource::WallClock => "wall time of the trace pass (no GPU timestamps)",
    };
    eprintln!(
        "{} settings at {}x{} on {}; time = {timing}, best of {}",
        sweep.len(),
        scene.render.width,
        scene.render.height,
        backend.describe(),
        args.repeats
    );
    println!(
        "{:>4} {:>5} {:>6} {:>10} {:>10} {:>11} {:>9}",
        "spp", "depth", "cutoff", "time (ms)", "Mrays", "RMSE", "FLIP"
    );
    let mut measurements = Vec::with_capacity(sweep.len());
    for knobs in sweep {
        let measurement = measure(&backend, &scene, knobs, &reference, args.repeats)?;
        print_row(&measurement, "");
        measurements.push(measurement);
    }
    let front = pareto_front(&measurements);
    println!("\nPareto front (fastest first):");
    for &index in &front {
        print_row(&measurements[index], "*");
    }

    let csv_path = args.out_dir.join("tradeoff.csv");
    gpu_render::output::write_text(&csv_path, &to_csv(&measurements, &front))?;
    let plot_path = args.out_dir.join("tradeoff.png");
    let title = format!(
        "{} at {}x{}: time vs error ({})",
        args.scene
            .file_name()
            .map_or_else(|| "scene".into(), |n| n.to_string_lossy()),
        scene.render.width,
        scene.render.height,
        backend.describe()
    );
    plot_png(&plot_path, &title, &measurements, &front)?;
    eprintln!(
        "wrote {}, {} and {}",
        csv_path.display(),
        plot_path.display(),
        reference_path.display()
    );
    Ok(())
}

/// `scene` with the knobs applied (and a stack deep enough for the depth).
fn with_knobs(scene: &Scene, knobs: Knobs) -> Result<Scene> {
    let render = scene
        .render
        .with_overrides(&RenderOverrides {
            samples_per_pixel: Some(knobs.samples_per_pixel),
            max_depth: Some(knobs.max_depth),
            stack_size: Some(RenderSettings::sufficient_stack_size(knobs.max_depth)),
            min_ray_weight: Some(knobs.min_ray_weight),
            ..RenderOverrides::default()
        })
        .map_err(anyhow::Error::msg)?;
    Ok(Scene {
        render,
        ..scene.clone()
    })
}

/// Renders `knobs` `repeats` times, keeps the fastest trace time (GPU timestamps where
/// measured, else wall time), and measures its error.
fn measure(
    backend: &Backend,
    scene: &Scene,
    knobs: Knobs,
    reference: &Frame,
    repeats: u32,
) -> Result<Measurement> {
    let scene = with_knobs(scene, knobs)?;
    let mut fastest = Duration::MAX;
    let mut frame = None;
    for _ in 0..repeats {
        let rendered = backend.render(&scene, &|_, _| {})?;
        fastest = fastest.min(rendered.stats.trace_time().0);
        frame = Some(rendered);
    }
    let frame = frame.context("no render was made")?;
    Ok(Measurement {
        knobs,
        seconds: fastest.as_secs_f64(),
        rays: frame.stats.rays_traced,
        rmse: rmse(&reference.image, &frame.image),
        flip: mean_flip(
            &reference.display_rgba8,
            &frame.display_rgba8,
            scene.render.width,
            scene.render.height,
        ),
    })
}

fn print_row(m: &Measurement, mark: &str) {
    println!(
        "{:>4} {:>5} {:>6} {:>10.1} {:>10.2} {:>11.3e} {:>9.4} {mark}",
        m.knobs.samples_per_pixel,
        m.knobs.max_depth,
        m.knobs.min_ray_weight,
        m.seconds * 1e3,
        m.rays as f64 / 1e6,
        m.rmse,
        m.flip
    );
}
