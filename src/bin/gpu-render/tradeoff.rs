//! `gpu-render tradeoff SCENE`: time against error for the speed/accuracy knobs.

use std::time::Duration;

use anyhow::{Context, Result};
use gpu_render::film::TimingSource;
use gpu_render::film::relative_rmse;
use gpu_render::low_level::tradeoff::{
    ErrorAxis, Knobs, Measurement, default_sweep, integrator_name, mean_flip, pareto_front,
    plot_png, rmse, sweep, time_to_error, to_csv,
};
use gpu_render::scene::{Integrator, RenderOverrides, RenderSettings, Scene};

use crate::args::TradeoffArgs;
use crate::backend::{Backend, Frame, GpuOptions};
use crate::progress::Progress;

/// The relative error whose time the summary reports (`docs/quality.md`).
const TARGET_ERROR: f64 = 0.01;

/// Renders each integrator's reference, sweeps the knobs and writes the table, CSV
/// and plots.
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
    // Its settings are the file's own: the sweep sets them.
    let loaded = crate::loading::load_any(
        &args.scene,
        &crate::loading::LoadArgs {
            settings: &crate::args::SettingsArgs::default(),
            sandbox: args.sandbox,
            quiet: false,
            max_memory: None,
        },
    )?;
    let crate::loading::Loaded { scene, inputs, .. } = loaded;
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
    let mut integrators: Vec<Integrator> = Vec::new();
    for integrator in args.integrators.iter().map(|&i| Integrator::from(i)) {
        if !integrators.contains(&integrator) {
            integrators.push(integrator);
        }
    }
    if integrators.is_empty() {
        integrators.push(scene.render.integrator);
    }
    // Each integrator's reference, checked before anything is written.
    let mut series = Vec::new();
    for &integrator in &integrators {
        let knobs = Knobs {
            integrator,
            samples_per_pixel: match integrator {
                Integrator::Whitted => args.reference_spp,
                Integrator::Path => args.path_reference_spp,
            },
            max_depth: args.reference_depth,
            min_ray_weight: 0.0,
        };
        series.push((
            knobs,
            with_knobs(&scene, knobs)?,
            sweep_of(args, integrator),
        ));
    }
    let mut outputs = vec![
        "tradeoff.csv".to_owned(),
        "tradeoff.png".to_owned(),
        "tradeoff-relative.png".to_owned(),
    ];
    outputs.extend(
        integrators
            .iter()
            .map(|&i| format!("reference-{}.png", integrator_name(i))),
    );
    for name in &outputs {
        let path = args.out_dir.join(name);
        crate::loading::check_inputs_survive(&path, &args.scene, &scene, &inputs)?;
    }
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("cannot create {}", args.out_dir.display()))?;
    // The images' checks probe the folder for the CSV too (whose extension
    // check_output_path, an image check, refuses).
    for name in outputs.iter().filter(|name| name.ends_with(".png")) {
        gpu_render::output::check_output_path(&args.out_dir.join(name))?;
    }
    let options = GpuOptions {
        noise: true,
        ..GpuOptions::default()
    };
    let backend = Backend::open(args.backend, None, &scene, &options, false)?;

    let mut measurements = Vec::new();
    let mut timing = None;
    let mut summaries = Vec::new();
    for (reference_knobs, reference_scene, sweep) in series {
        let name = integrator_name(reference_knobs.integrator);
        let progress = Progress::new(format!("rendering the {name} reference"), true);
        let reference = backend.render(&reference_scene, &|done, total| {
            progress.update(done, total)
        })?;
        progress.finish();
        let reference_path = args.out_dir.join(format!("reference-{name}.png"));
        gpu_render::output::write_image(
            &reference_path,
            &reference.image,
            &reference.display_rgba8,
        )?;
        let reference_noise = reference
            .noise
            .as_ref()
            .and_then(|noise| noise.relative_error());
        eprintln!(
            "{name} reference: {} spp, depth {}, estimated noise {}",
            reference_knobs.samples_per_pixel,
            reference_knobs.max_depth,
            percent(reference_noise)
        );
        // Every render on this backend is timed the same way: GPU timestamps where
        // the device has them (as the reference render shows), wall time otherwise.
        let (_, source) = reference.stats.trace_time();
        timing.get_or_insert(source);
        // The first render at each stack size compiles its pipeline: keep that out of
        // the timings.
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
        eprintln!(
            "{} {name} settings at {}x{} on {}; time = {}, best of {}",
            sweep.len(),
            scene.render.width,
            scene.render.height,
            backend.describe(),
            timing_name(source),
            args.repeats
        );
        print_header();
        for knobs in sweep {
            let measurement = measure(&backend, &scene, knobs, &reference, args.repeats)?;
            print_row(&measurement, "");
            measurements.push(measurement);
        }
        // The reference's own noise moves the errors of settings with more than a
        // sixteenth of its samples by more than about 3%: the fit leaves them out.
        let max_spp = reference_knobs.samples_per_pixel / 16;
        summaries.push((
            name,
            time_to_error(
                &measurements,
                reference_knobs.integrator,
                TARGET_ERROR,
                max_spp,
            ),
        ));
    }
    let front = pareto_front(&measurements);
    println!("\nPareto fronts of time and FLIP (fastest first):");
    print_header();
    for &index in &front {
        print_row(&measurements[index], "*");
    }
    println!(
        "\nTime to {}% relative luminance RMSE against each integrator's reference:",
        TARGET_ERROR * 100.0
    );
    for (name, time) in &summaries {
        match time {
            Some(t) => println!(
                "{name:>8}: {:.3} s, {:.1} spp ({}; error ∝ spp^{:.2})",
                t.seconds,
                t.samples_per_pixel,
                if t.measured {
                    "interpolated between measured settings"
                } else {
                    "extrapolated along the fit"
                },
                t.exponent
            ),
            None => println!("{name:>8}: no fit (too few settings below the reference's spp/16)"),
        }
    }

    let csv_path = args.out_dir.join("tradeoff.csv");
    gpu_render::output::write_text(&csv_path, &to_csv(&measurements, &front))?;
    let scene_name = args
        .scene
        .file_name()
        .map_or_else(|| "scene".into(), |n| n.to_string_lossy());
    for (file, axis) in [
        ("tradeoff.png", ErrorAxis::Flip),
        ("tradeoff-relative.png", ErrorAxis::RelativeError),
    ] {
        let title = format!(
            "{scene_name} at {}x{}: time vs error ({})",
            scene.render.width,
            scene.render.height,
            backend.describe()
        );
        plot_png(
            &args.out_dir.join(file),
            &title,
            &measurements,
            &front,
            axis,
        )?;
    }
    eprintln!(
        "wrote {}, tradeoff.png, tradeoff-relative.png and the references in {}",
        csv_path.display(),
        args.out_dir.display()
    );
    Ok(())
}

/// The settings to sweep for `integrator`: its default sweep, or the grid of
/// `--spp` and `--depths` (each defaulting to the integrator's own list).
fn sweep_of(args: &TradeoffArgs, integrator: Integrator) -> Vec<Knobs> {
    let defaults = default_sweep(integrator);
    let distinct = |values: Vec<u32>| {
        let mut values = values;
        values.sort_unstable();
        values.dedup();
        values
    };
    if args.spp.is_empty() && args.depths.is_empty() {
        return defaults;
    }
    let samples = if args.spp.is_empty() {
        distinct(defaults.iter().map(|k| k.samples_per_pixel).collect())
    } else {
        distinct(args.spp.clone())
    };
    let depths = if args.depths.is_empty() {
        distinct(defaults.iter().map(|k| k.max_depth).collect())
    } else {
        distinct(args.depths.clone())
    };
    let mut cutoffs: Vec<f64> = Vec::new();
    for k in &defaults {
        if !cutoffs.contains(&k.min_ray_weight) {
            cutoffs.push(k.min_ray_weight);
        }
    }
    sweep(integrator, &samples, &depths, &cutoffs)
}

fn timing_name(source: TimingSource) -> &'static str {
    match source {
        TimingSource::GpuTimestamps => "GPU timestamps of the trace passes",
        TimingSource::WallClock => "wall time of the trace pass (no GPU timestamps)",
    }
}

/// A relative error as a percentage, or `unknown`.
fn percent(relative: Option<f64>) -> String {
    relative.map_or_else(|| "unknown".to_owned(), |r| format!("{:.3}%", r * 100.0))
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
            integrator: Some(knobs.integrator),
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
        relative_error: relative_rmse(&reference.image, &frame.image),
        estimated_error: frame.noise.as_ref().and_then(|n| n.relative_error()),
        flip: mean_flip(
            &reference.display_rgba8,
            &frame.display_rgba8,
            scene.render.width,
            scene.render.height,
        ),
    })
}

fn print_header() {
    println!(
        "{:>8} {:>4} {:>5} {:>6} {:>10} {:>10} {:>11} {:>9} {:>9} {:>9}",
        "", "spp", "depth", "cutoff", "time (ms)", "Mrays", "RMSE", "rel. err", "estimate", "FLIP"
    );
}

fn print_row(m: &Measurement, mark: &str) {
    println!(
        "{:>8} {:>4} {:>5} {:>6} {:>10.1} {:>10.2} {:>11.3e} {:>9.4} {:>9} {:>9.4} {mark}",
        integrator_name(m.knobs.integrator),
        m.knobs.samples_per_pixel,
        m.knobs.max_depth,
        m.knobs.min_ray_weight,
        m.seconds * 1e3,
        m.rays as f64 / 1e6,
        m.rmse,
        m.relative_error,
        m.estimated_error
            .map_or_else(|| "-".to_owned(), |e| format!("{e:.4}")),
        m.flip
    );
}
