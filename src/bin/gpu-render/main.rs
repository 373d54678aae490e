//! `gpu-render SCENE -o OUT`: renders a scene file, or a model file (OBJ, glTF, GLB)
//! on its own, to an image.
//!
//! Cheap checks (output format and directory, command-line settings, the scene file)
//! all happen before a device is opened or a ray traced. Errors are printed as
//! `error: ...` with their causes and exit with status 1; usage errors are clap's
//! (status 2). Ctrl-C, SIGTERM and SIGHUP stop it cleanly with status 130 (see
//! `signals.rs`).

mod args;
mod backend;
mod compare;
mod estimate;
mod loading;
mod memory;
mod merge;
mod naming;
mod pipeline_cache;
mod progress;
mod signals;
mod summary;
mod tradeoff;
#[cfg(feature = "viewer")]
mod view;

use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use clap::{CommandFactory, Parser, error::ErrorKind};
use gpu_render::output::{self, HDR_MAX, OutputFormat, Written};
use gpu_render::scene::{self, Integrator, LightingSpace, RenderSettings, Scene};
use gpu_render::tiles::{Fingerprint, PixelWindow, Tile, TileInfo, tile_window};

use crate::args::{AdapterArg, AovList, Cli, DenoiserArg, RenderArgs, SettingsArgs};
use crate::backend::{Backend, Denoiser, Frame, GpuOptions};
use crate::loading::{LoadArgs, Loaded};
use crate::memory::{BackendKind, Estimate};
use crate::progress::Progress;
use crate::summary::Summary;
use gpu_render::low_level::input::InputFile;

/// The programs of the `gpu-render-tools` crate, which users reach for as subcommands
/// (`gpu-render bench SCENE`).
const TOOLS: &[&str] = &[
    "bench",
    "embed_bench",
    "fuzz_campaign",
    "fuzz_probe",
    "fuzz_replay",
    "load_probe",
    "loop_probe",
];

fn main() -> ExitCode {
    if let Some(first) = std::env::args().nth(1)
        && TOOLS.contains(&first.as_str())
        && !Path::new(&first).exists()
    {
        eprintln!(
            "error: `{first}` is not a subcommand of gpu-render but a program of the tools \
             crate: cargo run --release -p gpu-render-tools --bin {first} -- ARGS"
        );
        return ExitCode::from(2);
    }
    let cli = Cli::parse();
    if let Err(error) = signals::install() {
        eprintln!("error: {}", describe_error(&error));
        return ExitCode::FAILURE;
    }
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {}", describe_error(&error));
            ExitCode::FAILURE
        }
    }
}

/// `error` and its causes on one line, `message: cause: cause`, each cause said once:
/// a cause whose words the line holds already (the library's messages quote the
/// reason they wrap, and expose it as their source too) is left out.
pub fn describe_error(error: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

fn run(cli: Cli) -> Result<()> {
    if let Some(command) = cli.command {
        return match command {
            args::Command::Tradeoff(args) => tradeoff::run(&args),
            args::Command::Merge(args) => merge::run(&args),
            args::Command::Estimate(args) => estimate::run(&args),
            args::Command::BrdfCheck { file } => brdf_check(&file),
            #[cfg(feature = "viewer")]
            args::Command::View(args) => view::run(&args),
        };
    }
    let args = cli.render;
    if args.device.adapter == Some(AdapterArg::List) {
        return backend::print_adapters();
    }
    let (Some(scene_path), Some(output_path)) = (args.scene.as_deref(), args.output.as_deref())
    else {
        Cli::command()
            .error(
                ErrorKind::MissingRequiredArgument,
                "a render needs a SCENE and --output <PATH>; only `--adapter list` runs without them",
            )
            .exit()
    };
    render(&args, scene_path, output_path)
}

/// `gpu-render brdf-check FILE`: prints the worst case of each plausibility rule and
/// fails when one is broken.
fn brdf_check(file: &Path) -> Result<()> {
    use gpu_render::low_level::plausibility::{
        ENERGY_TOLERANCE, RECIPROCITY_TOLERANCE, Worst, check_brdf_map,
    };
    let map = scene::load_image(file).map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let report = check_brdf_map(&map).map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let channel = |w: &Worst| ["R", "G", "B"][w.channel];
    let verdict = |w: &Worst| if w.holds { "ok" } else { "VIOLATED" };
    let p = &report.positivity;
    println!(
        "positivity:   {:8}  smallest f = {:.6} /sr at θi = {:.1}°, θr = {:.1}° ({})",
        verdict(p),
        p.value,
        p.theta_i_degrees,
        p.theta_r_degrees,
        channel(p)
    );
    let e = &report.energy;
    println!(
        "energy:       {:8}  largest ∫ f cos θr dω = {:.6} at θi = {:.1}° ({}; allowed 1 + {ENERGY_TOLERANCE:e})",
        verdict(e),
        e.value,
        e.theta_i_degrees,
        channel(e)
    );
    let r = &report.reciprocity;
    println!(
        "reciprocity:  {:8}  largest |f(θi,θr) - f(θr,θi)| = {:.6} /sr at θi = {:.1}°, θr = {:.1}° ({}; allowed {RECIPROCITY_TOLERANCE:e} × max f)",
        verdict(r),
        r.value,
        r.theta_i_degrees,
        r.theta_r_degrees,
        channel(r)
    );
    if !report.plausible() {
        bail!(
            "{}: the BRDF map is not physically plausible",
            file.display()
        );
    }
    println!("{}: physically plausible", file.display());
    Ok(())
}

/// Validates everything cheap, then renders and writes the image (or, with `--tile`
/// or `--crop`, the tile).
fn render(args: &RenderArgs, scene_path: &Path, output_pattern: &Path) -> Result<()> {
    let piece = args.tile.is_some() || args.crop.is_some();
    let format = OutputFormat::from_path(output_pattern)?;
    if piece && format != OutputFormat::Exr {
        bail!(
            "{}: --tile and --crop write a linear EXR tile that records its window (for `gpu-render merge`), so the output must be an .exr",
            output_pattern.display()
        );
    }
    if args.compare_gamma && format != OutputFormat::Png {
        bail!(
            "{}: --compare-gamma writes a side-by-side 8-bit display image, so the output must be a .png",
            output_pattern.display()
        );
    }
    if args.aov.is_some() && format != OutputFormat::Exr {
        bail!(
            "{}: --aov writes the passes as layers of an OpenEXR file, so the output must be an .exr (PNG and Radiance HDR hold no layers)",
            output_pattern.display()
        );
    }
    if args.denoise.is_some() && piece {
        bail!("--denoise filters a whole image; it cannot be used with --tile or --crop");
    }
    // Before the scene is read: a build without OIDN, or a library that is not there,
    // fails at once rather than after the render.
    let denoiser = args.denoise.map(Denoiser::open).transpose()?;
    if args.aov.is_some() && piece {
        bail!(
            "--aov writes layers of a whole image's EXR; it cannot be used with --tile or --crop"
        );
    }
    if args.compare_gamma && piece {
        bail!("--compare-gamma renders two whole images side by side; it cannot be a tile");
    }
    args.device
        .check_for_backend()
        .map_err(anyhow::Error::msg)?;
    let tile = args.tile.map(|t| (t.index, t.count));
    // Without a {frame}, every check of the output happens before the scene is read.
    let named_by_frame = naming::contains(output_pattern, naming::FRAME);
    if !named_by_frame {
        let output_path = naming::expand(output_pattern, None, tile)?;
        output::check_output_path(&output_path)?;
        output::check_not_an_input(&output_path, [(scene_path, "scene file")])?;
    } else if args.frame.is_none() {
        naming::expand(output_pattern, None, tile)?;
    }
    // Values out of range whatever the scene says (`--width 0`) fail before loading it.
    apply_overrides(&args.settings, minimal_settings(), None)?;
    // A model is refused while it is read once it would hold more than --max-memory.
    let cap = Some((args.max_memory * f64::from(1u32 << 30)) as u64);

    let loaded = loading::load_any(
        scene_path,
        &LoadArgs {
            settings: &args.settings,
            sandbox: args.sandbox,
            quiet: args.quiet,
            max_memory: cap,
        },
    )?;
    let Loaded {
        mut scene,
        camera_path,
        inputs,
    } = loaded;
    let frame = match args.frame {
        None => None,
        Some(frame) => {
            let Some(path) = &camera_path else {
                bail!(
                    "{}: --frame {frame}: the scene has no [animation] camera path",
                    scene_path.display()
                );
            };
            if frame >= path.frame_count {
                bail!(
                    "{}: --frame {frame}: the animation has {} frames (0 to {})",
                    scene_path.display(),
                    path.frame_count,
                    path.frame_count - 1
                );
            }
            scene.camera = path.frame_camera(&scene.camera, frame);
            Some((frame, path.frame_count))
        }
    };
    let output_path = naming::expand(output_pattern, frame, tile)?;
    if named_by_frame {
        output::check_output_path(&output_path)?;
    }
    let standard_error_path = args
        .standard_error
        .as_deref()
        .map(|pattern| {
            standard_error_path(
                pattern,
                frame,
                tile,
                &output_path,
                scene_path,
                &scene,
                &inputs,
            )
        })
        .transpose()?;
    loading::check_inputs_survive(&output_path, scene_path, &scene, &inputs)?;
    if args.denoise.is_some() && scene.render.integrator == Integrator::Whitted {
        bail!(
            "{}: --denoise removes the noise of path tracing, and the scene uses the Whitted integrator, whose images have none; render with integrator = \"path\" (or --integrator path), or without --denoise",
            scene_path.display()
        );
    }
    let window = piece_window(args, &scene.render)?;

    let gpu_options = GpuOptions {
        iteration_budget: args.device.iteration_budget,
        timeout: args.device.gpu_timeout,
        noise: standard_error_path.is_some()
            || denoiser.as_ref().is_some_and(Denoiser::needs_noise),
        aov: args.aov.is_some() || denoiser.is_some(),
        traversal: args.device.traversal.into(),
    };
    let backend = Backend::open(
        args.device.backend,
        args.device.adapter.as_ref(),
        &scene,
        &gpu_options,
        args.quiet,
    )?;
    let estimate = check_memory(
        &scene,
        &backend,
        format,
        args.compare_gamma,
        window.as_ref(),
        gpu_options.noise,
        gpu_options.aov,
        args.denoise == Some(DenoiserArg::Oidn),
        args.max_memory,
    )?;
    let piece_name = window.as_ref().map(|window| match args.tile {
        Some(t) => format!("tile {}/{} ({window})", t.index, t.count),
        None => format!("crop {window}"),
    });
    let started = Instant::now();
    let rendered = if args.compare_gamma {
        let linear = render_pass(&backend, &scene, Some(LightingSpace::Linear), args.quiet)?;
        let naive = render_pass(
            &backend,
            &scene,
            Some(LightingSpace::NaiveGamma),
            args.quiet,
        )?;
        compare::side_by_side(&linear, &naive)?
    } else if let Some(window) = &window {
        let progress = Progress::new(
            format!("rendering {}", piece_name.as_deref().unwrap_or("")),
            !args.quiet,
        );
        let report = |done: u32, total: u32| progress.update(done, total);
        let rendered = backend.render_region(&scene, window, &report);
        progress.finish();
        rendered?
    } else {
        render_pass(&backend, &scene, None, args.quiet)?
    };
    let mut rendered = rendered;
    if let Some(denoiser) = &denoiser {
        let denoised = backend.denoise(&rendered, denoiser)?;
        rendered.display_rgba8 = denoised.to_display_rgba8(scene.display_encodes_srgb());
        rendered.image = denoised;
    }
    let wall = started.elapsed();
    backend.save_pipeline_cache(args.quiet);

    let written = match &window {
        Some(window) => {
            let tile = Tile {
                info: TileInfo {
                    image_width: scene.render.width,
                    image_height: scene.render.height,
                    window: window.clone(),
                    tile,
                    frame: frame.map(|(k, _)| k),
                    fingerprint: Fingerprint::of(&scene),
                    settings: gpu_render::tiles::describe_settings(&scene.render),
                    // Ray queries and the software walk agree within docs/model.md's
                    // stated difference, not bit for bit: the merge keeps them apart.
                    backend: if rendered.hardware_traversal {
                        format!("{}-ray-query", backend.kind_name())
                    } else {
                        backend.kind_name().to_owned()
                    },
                    device: backend.device_name(),
                    scene_name: scene_path
                        .file_name()
                        .map(|name| name.to_string_lossy().into_owned())
                        .unwrap_or_default(),
                    version: env!("CARGO_PKG_VERSION").to_owned(),
                },
                image: rendered.image,
                display_rgba8: rendered.display_rgba8,
            };
            gpu_render::tiles::write_tile(&output_path, &tile)?;
            Written::default()
        }
        None => match (&args.aov, &rendered.aov) {
            (Some(AovList(passes)), Some(aov)) => {
                output::write_exr_with_passes(&output_path, &rendered.image, aov, passes)?;
                Written::default()
            }
            (Some(_), None) => bail!("the backend returned no auxiliary passes"),
            (None, _) => {
                output::write_image(&output_path, &rendered.image, &rendered.display_rgba8)?
            }
        },
    };
    if let Some(path) = &standard_error_path {
        let noise = rendered
            .noise
            .as_ref()
            .context("the backend returned no noise estimate")?;
        output::write_image(path, &noise.standard_error_image(), &[])?;
    }

    if !args.quiet {
        warn_clamped(&output_path, written);
        let summary = Summary {
            settings: &scene.render,
            passes: if args.compare_gamma { 2 } else { 1 },
            piece: piece_name.as_deref(),
            frame: frame.map(|(k, _)| k),
            backend: &if rendered.hardware_traversal
                && gpu_render::gpu::ShaderFeatures::for_scene(&scene).triangles
            {
                format!("{}, triangles by ray query", backend.describe())
            } else {
                backend.describe()
            },
            wall,
            compile: rendered.compile,
            stats: rendered.stats,
            output: &output_path,
            // The raw image's noise, shown only where asked for (--standard-error):
            // --denoise takes it too, and its image has less.
            noise: rendered
                .noise
                .as_ref()
                .filter(|_| standard_error_path.is_some()),
            memory: memory::peak_resident_bytes().map(|peak| (peak, estimate.total)),
        };
        eprintln!("{summary}");
    }
    Ok(())
}

/// The window `--tile` or `--crop` asks for, checked against the image; `None` for
/// the whole image.
fn piece_window(args: &RenderArgs, settings: &RenderSettings) -> Result<Option<PixelWindow>> {
    let (width, height) = (settings.width, settings.height);
    if let Some(tile) = args.tile {
        return tile_window(tile.index, tile.count, width, height)
            .map(Some)
            .map_err(|e| anyhow!("--tile {}/{}: {e}", tile.index, tile.count));
    }
    match &args.crop {
        Some(crop) if !crop.fits(width, height) => bail!(
            "--crop {},{},{},{}: the window {crop} does not lie inside the {width}x{height} image",
            crop.columns.start,
            crop.rows.start,
            crop.columns.end,
            crop.rows.end
        ),
        crop => Ok(crop.clone()),
    }
}

/// The path `--standard-error` names for this render (`{frame}` and `{tile}`
/// expanded): an `.exr` that is neither the image written nor an input.
fn standard_error_path(
    pattern: &Path,
    frame: Option<(u32, u32)>,
    tile: Option<(u32, u32)>,
    output_path: &Path,
    scene_path: &Path,
    scene: &Scene,
    inputs: &[InputFile],
) -> Result<PathBuf> {
    let path = naming::expand(pattern, frame, tile)?;
    if output::check_output_path(&path)? != OutputFormat::Exr {
        bail!(
            "{}: --standard-error writes a linear float image, so it must be an .exr",
            path.display()
        );
    }
    output::check_distinct_outputs(&[(output_path, "image (-o)"), (&path, "--standard-error")])?;
    loading::check_inputs_survive(&path, scene_path, scene, inputs)?;
    Ok(path)
}

/// Refuses, before rendering, a render whose estimated peak memory is above the cap.
#[allow(clippy::too_many_arguments)]
fn check_memory(
    scene: &Scene,
    backend: &Backend,
    format: OutputFormat,
    compare_gamma: bool,
    window: Option<&PixelWindow>,
    noise: bool,
    aov: bool,
    oidn: bool,
    max_memory_gib: f64,
) -> Result<Estimate> {
    let kind = match backend {
        Backend::Gpu { .. } => BackendKind::Gpu,
        Backend::Cpu { .. } => BackendKind::Cpu,
    };
    let mut estimate = match window {
        Some(window) => Estimate::for_tile(scene, kind, window.pixels()),
        None => Estimate::new(scene, kind, format, compare_gamma),
    };
    if noise {
        estimate = estimate.with_noise_estimate(kind);
    }
    if aov {
        estimate = estimate.with_aov();
    }
    if oidn {
        estimate = estimate.with_oidn();
    }
    let cap = max_memory_gib * f64::from(1u32 << 30);
    if estimate.total as f64 > cap {
        let s = &scene.render;
        bail!(
            "rendering {}x{}{} to {format} on the {} would need about {estimate}, more than \
             the {max_memory_gib} GiB allowed; render smaller, or raise --max-memory if the \
             machine has the memory",
            s.width,
            s.height,
            if compare_gamma {
                " twice (--compare-gamma)"
            } else {
                ""
            },
            backend.describe()
        );
    }
    Ok(estimate)
}

/// Warns when the format could not hold every pixel and clamped some.
pub fn warn_clamped(output_path: &Path, written: Written) {
    if written.clamped_pixels > 0 {
        eprintln!(
            "warning: {}: {} pixels had radiance above {HDR_MAX:e}, the largest a Radiance \
             HDR file holds, and were clamped to it; write .exr to keep them",
            output_path.display(),
            written.clamped_pixels
        );
    }
}

/// Renders `scene`, in `lighting` space if given, with progress on stderr.
fn render_pass(
    backend: &Backend,
    scene: &Scene,
    lighting: Option<LightingSpace>,
    quiet: bool,
) -> Result<Frame> {
    let label = match lighting {
        None => "rendering",
        Some(LightingSpace::Linear) => "rendering (linear)",
        Some(LightingSpace::NaiveGamma) => "rendering (naive gamma)",
    };
    let scene = match lighting {
        Some(space) if space != scene.render.lighting_space => {
            let mut changed = scene.clone();
            changed.render.lighting_space = space;
            Cow::Owned(changed)
        }
        _ => Cow::Borrowed(scene),
    };
    let progress = Progress::new(label, !quiet);
    let report = |done: u32, total: u32| progress.update(done, total);
    let frame = backend.render(&scene, &report);
    progress.finish();
    frame
}

/// The smallest valid settings, to range-check the command-line values on their own.
pub fn minimal_settings() -> RenderSettings {
    RenderSettings {
        width: 1,
        height: 1,
        samples_per_pixel: 1,
        max_depth: 0,
        stack_size: 1,
        lighting_space: LightingSpace::Linear,
        min_ray_weight: 0.0,
        integrator: gpu_render::scene::Integrator::Whitted,
        texture_filtering: gpu_render::scene::TextureFiltering::None,
    }
}

/// Applies the command-line overrides to `base`, naming the offending flag on error.
pub fn apply_overrides(
    args: &SettingsArgs,
    base: RenderSettings,
    scene_path: Option<&Path>,
) -> Result<RenderSettings> {
    base.with_overrides(&args.overrides())
        .map_err(|message| match args.flag_for_setting(&message) {
            Some(flag) => anyhow!("invalid {flag}: {message}"),
            None => match scene_path {
                Some(path) => anyhow!(
                    "{}: the render settings with the command-line overrides are invalid: {message}",
                    path.display()
                ),
                None => anyhow!("invalid command-line render settings: {message}"),
            },
        })
}
