//! The command line: what `gpu-render` accepts, as clap derive types.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use gpu_render::low_level::quality::QualityPreset;
use gpu_render::output::AuxPass;
use gpu_render::scene::{
    Integrator, LightingSpace, MAX_DEPTH_LIMIT, MAX_IMAGE_DIMENSION, MAX_SAMPLES_PER_PIXEL,
    RenderOverrides, SettingsError,
};
use gpu_render::tiles::PixelWindow;

use crate::memory::DEFAULT_MAX_MEMORY_GIB;

const AFTER_HELP: &str = "\
Output formats (chosen by the extension of --output):
  .png   8-bit sRGB display image
  .exr   linear 32-bit float RGBA (OpenEXR)
  .hdr   linear RGB (Radiance RGBE)

Examples:
  gpu-render scenes/showcase.toml -o showcase.png
  gpu-render scene.toml -o scene.exr --spp 64 --max-depth 8
  gpu-render scene.toml -o gamma.png --compare-gamma --backend cpu
  gpu-render scene.toml -o draft.png --quality draft
  gpu-render scene.toml --tile 2/4 -o tile-{tile}.exr
  gpu-render merge tile-*.exr -o scene.png
  gpu-render animated.toml --frame 12 -o frame-{frame}.png
  gpu-render estimate scene.toml --tiles 4
  gpu-render tradeoff scenes/showcase.toml --out-dir tradeoff
  gpu-render brdf-check scenes/brdf/plausible.png
  gpu-render view scenes/showcase.toml
  gpu-render --adapter list

Tiles, frames and the recipes for Slurm, Kubernetes and GNU parallel:
docs/distributed.md";

/// Renders a scene file with the GPU ray tracer (or its CPU reference).
#[derive(Debug, Parser)]
#[command(
    name = "gpu-render",
    version,
    about,
    long_about = "Renders a TOML scene file with a Whitted-style, physically based ray \
                  tracer that runs in WGSL compute shaders through wgpu, or with the CPU \
                  reference tracer.",
    override_usage = "gpu-render [OPTIONS] SCENE --output <PATH>\n       gpu-render merge TILE.exr... --output <PATH>\n       gpu-render estimate SCENE [OPTIONS]\n       gpu-render tradeoff SCENE [OPTIONS]\n       gpu-render brdf-check FILE\n       gpu-render view SCENE [OPTIONS]\n       gpu-render --adapter list",
    after_help = AFTER_HELP,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    /// A tool other than rendering (rendering is the default).
    #[command(subcommand)]
    pub command: Option<Command>,

    /// What to render and how.
    #[command(flatten)]
    pub render: RenderArgs,
}

/// Subcommands. Rendering needs none: `gpu-render SCENE -o OUT`.
///
/// Tools such as `brdf-check FILE` go here as variants.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Measure the speed/accuracy trade: render a converged reference, sweep samples
    /// per pixel, maximum depth and the ray-weight cutoff, and report each setting's
    /// time and error (linear RMSE and FLIP) with the Pareto front, as a table, a CSV
    /// and a PNG plot.
    Tradeoff(TradeoffArgs),

    /// Assemble the EXR tiles of `--tile` or `--crop` renders into the whole image,
    /// after checking that they cover it exactly once and come from the same scene,
    /// frame, settings and backend. The result is byte for byte the whole render's.
    Merge(MergeArgs),

    /// Print the expected time of each tile (and frame) on the chosen backend, from a
    /// short calibration render at a fraction of the pixels.
    Estimate(EstimateArgs),

    /// Open a window showing the scene rendered progressively on the GPU: orbit
    /// (left drag), pan (right or middle drag), zoom (wheel), S saves the image,
    /// Esc or Q quits; the scene file is reloaded when it changes. See docs/viewer.md.
    #[cfg(feature = "viewer")]
    View(ViewArgs),

    /// Reports whether a tabulated BRDF map (a square image, θi across, θr down,
    /// texels holding π·f) is physically plausible: positivity, energy conservation
    /// and Helmholtz reciprocity, with the worst violation of each. Exits with status 1
    /// when it is not.
    BrdfCheck {
        /// The map: an 8-bit sRGB PNG (linearised) or a float OpenEXR (linear).
        #[arg(value_name = "FILE")]
        file: PathBuf,
    },
}

/// The arguments of `gpu-render tradeoff`.
#[derive(Debug, Args)]
pub struct TradeoffArgs {
    /// The scene file (TOML), or a model file (OBJ, glTF, GLB) framed as a scene of its own.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,

    /// Directory for tradeoff.csv, tradeoff.png and reference.png (created if missing).
    #[arg(long, value_name = "DIR", default_value = "tradeoff")]
    pub out_dir: PathBuf,

    /// Width of every render in pixels; the height keeps the scene's aspect ratio.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 320,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_IMAGE_DIMENSION>
    )]
    pub width: u32,

    /// Samples per pixel of the converged reference.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 256,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_SAMPLES_PER_PIXEL>
    )]
    pub reference_spp: u32,

    /// Maximum depth of the converged reference.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 16,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<0, MAX_DEPTH_LIMIT>
    )]
    pub reference_depth: u32,

    /// Samples per pixel of the path integrator's converged reference.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1024,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_SAMPLES_PER_PIXEL>
    )]
    pub path_reference_spp: u32,

    /// The integrators to sweep, each a series of its own against its own converged
    /// reference, on one chart [default: the scene's].
    #[arg(long, value_enum, value_name = "LIST", value_delimiter = ',')]
    pub integrators: Vec<IntegratorArg>,

    /// Samples per pixel to sweep, instead of each integrator's default list.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_SAMPLES_PER_PIXEL>
    )]
    pub spp: Vec<u32>,

    /// Maximum depths to sweep, instead of each integrator's default list.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_parser = parse_in_range::<0, MAX_DEPTH_LIMIT>
    )]
    pub depths: Vec<u32>,

    /// Timed runs per setting; the fastest counts.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 2,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, 1000>
    )]
    pub repeats: u32,

    /// Where to trace (see the render options).
    #[arg(long, value_enum, default_value_t = BackendArg::Auto)]
    pub backend: BackendArg,

    /// Confine the files the scene names to its folder (see the render options).
    #[arg(long)]
    pub sandbox: bool,
}

/// The arguments of `gpu-render merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The tiles (EXR files written with --tile or --crop), in any order.
    #[arg(value_name = "TILE.exr", required = true, num_args = 1..)]
    pub tiles: Vec<PathBuf>,

    /// The whole image; its extension picks the format (.png, .exr or .hdr).
    #[arg(short, long, value_name = "PATH")]
    pub output: PathBuf,

    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The arguments of `gpu-render estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// The scene file (TOML), or a model file (.obj, .gltf, .glb) framed as the render
    /// command frames it.
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,

    /// Estimate each of this many tiles (the split of --tile).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_IMAGE_DIMENSION>
    )]
    pub tiles: u32,

    /// Estimate this frame of the scene's animation [default: the still camera, or for
    /// an animated scene up to 5 frames spread over it].
    #[arg(long, value_name = "K", allow_negative_numbers = true, value_parser = parse_whole)]
    pub frame: Option<u32>,

    /// Pixels of the calibration render, a scaled-down copy of the image (at least
    /// one row per tile); the whole image if it has fewer.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 16_384,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, 134_217_728>
    )]
    pub calibration_pixels: u32,

    /// Image size, samples, depth and lighting, over the scene's.
    #[command(flatten)]
    pub settings: SettingsArgs,

    /// Where and how to trace.
    #[command(flatten)]
    pub device: DeviceArgs,

    /// Confine the files the scene names to its folder (see the render options).
    #[arg(long)]
    pub sandbox: bool,
}

/// The arguments of `gpu-render view`.
#[cfg(feature = "viewer")]
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// The scene file (TOML), or a model file (.obj, .gltf, .glb).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,

    /// Samples per pixel added each frame.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_SAMPLES_PER_PIXEL>
    )]
    pub samples_per_frame: u32,

    /// Stop adding samples once a pixel has this many (the window then only redraws
    /// on a change).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 4096,
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, MAX_SAMPLES_PER_PIXEL>
    )]
    pub max_samples: u32,

    /// Render this many frames, finish their samples, show the result and exit (with
    /// the frame rate on stderr).
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, 1_000_000>
    )]
    pub frames: Option<u32>,

    /// With --frames: write what the window shows at the end to this PNG.
    #[arg(long, value_name = "PATH", requires = "frames")]
    pub screenshot: Option<PathBuf>,

    /// Image size (the window's first size), samples, depth and lighting, over the
    /// scene's. The scene's samples per pixel sets the stratified pattern: after that
    /// many samples the window shows exactly the one-shot render.
    #[command(flatten)]
    pub settings: SettingsArgs,

    /// Confine the files the scene names to its folder (see the render options).
    #[arg(long)]
    pub sandbox: bool,

    /// Trace a film this fraction of the window's size and draw it scaled up (nearest
    /// texel): 0.5 traces a quarter of the pixels, for a faster preview.
    #[arg(
        long,
        value_name = "F",
        default_value_t = 1.0,
        allow_hyphen_values = true,
        value_parser = parse_view_scale
    )]
    pub scale: f64,

    /// Show the film denoised by the built-in à-trous filter (guided by the first-hit
    /// albedo, normal and depth the trace then records, and the noise estimate); the
    /// D key switches between the denoised and the raw film. The samples accumulate
    /// the same either way.
    #[arg(long)]
    pub denoise: bool,

    /// The GPU adapter to show the window with: an index from the list the viewer
    /// prints when this does not match, or part of an adapter's name.
    #[arg(long, value_name = "INDEX|NAME", value_parser = parse_view_adapter)]
    pub adapter: Option<AdapterArg>,

    /// Print nothing but errors and the --frames summary.
    #[arg(short, long)]
    pub quiet: bool,
}

#[cfg(feature = "viewer")]
/// `--scale`: a fraction in (0, 1].
fn parse_view_scale(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|e| format!("expected a number in (0, 1], got `{text}`: {e}"))?;
    if value > 0.0 && value <= 1.0 {
        Ok(value)
    } else {
        Err(format!("must be in (0, 1], got {text}"))
    }
}

#[cfg(feature = "viewer")]
/// The viewer's `--adapter`: an index or a name (`list` belongs to the render command).
fn parse_view_adapter(text: &str) -> Result<AdapterArg, String> {
    match parse_adapter(text)? {
        AdapterArg::List => Err(
            "`gpu-render --adapter list` lists the adapters; the viewer \
                                 takes an index or part of a name"
                .into(),
        ),
        choice => Ok(choice),
    }
}

/// `--tile I/N`: tile `index` of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileArg {
    /// 0-based.
    pub index: u32,
    /// At least 1, above `index`.
    pub count: u32,
}

/// `I/N` with `0 <= I < N`.
fn parse_tile(text: &str) -> Result<TileArg, String> {
    let usage = || format!("must be I/N, tile I (0-based) of N, like 0/4, got `{text}`");
    let (index, count) = text.split_once('/').ok_or_else(usage)?;
    let number = |part: &str| {
        let part = part.trim();
        (!part.is_empty() && part.bytes().all(|b| b.is_ascii_digit()))
            .then(|| part.parse::<u32>().ok())
            .flatten()
            .ok_or_else(usage)
    };
    let (index, count) = (number(index)?, number(count)?);
    if count == 0 || index >= count {
        return Err(format!(
            "tile {index} of {count}: the index must be below the count (0 to N-1), got `{text}`"
        ));
    }
    Ok(TileArg { index, count })
}

/// A comma-separated list of auxiliary pass names (`albedo,normal,depth`), each once,
/// in the order given.
fn parse_aov_list(text: &str) -> Result<AovList, String> {
    let known = || {
        AuxPass::ALL
            .iter()
            .map(|pass| pass.name())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut passes = Vec::new();
    for name in text.split(',').map(str::trim) {
        let Some(pass) = AuxPass::from_name(name) else {
            return Err(format!(
                "unknown pass `{}`: the passes are {} (comma-separated)",
                gpu_render::low_level::echo::echo(name),
                known()
            ));
        };
        if passes.contains(&pass) {
            return Err(format!("the pass `{name}` is named twice"));
        }
        passes.push(pass);
    }
    Ok(AovList(passes))
}

/// The passes `--aov` names, in its order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AovList(pub Vec<AuxPass>);

/// `x0,y0,x1,y1` with `x0 < x1`, `y0 < y1` (checked against the image later).
fn parse_crop(text: &str) -> Result<PixelWindow, String> {
    let usage = || format!("must be x0,y0,x1,y1 (whole pixels, x1 and y1 excluded), got `{text}`");
    let values: Vec<u32> = text
        .split(',')
        .map(|part| {
            let part = part.trim();
            (!part.is_empty() && part.bytes().all(|b| b.is_ascii_digit()))
                .then(|| part.parse::<u32>().ok())
                .flatten()
                .ok_or_else(usage)
        })
        .collect::<Result<_, _>>()?;
    let [x0, y0, x1, y1] = values[..] else {
        return Err(usage());
    };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!(
            "the window {x0},{y0},{x1},{y1} is empty: x0 < x1 and y0 < y1 are needed"
        ));
    }
    Ok(PixelWindow {
        columns: x0..x1,
        rows: y0..y1,
    })
}

/// The arguments of a render.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The scene file (TOML), or a model file (.obj, .gltf, .glb) to render on its own.
    #[arg(value_name = "SCENE", required_unless_present = "adapter")]
    pub scene: Option<PathBuf>,

    /// The image to write; its extension picks the format (.png, .exr or .hdr).
    #[arg(short, long, value_name = "PATH", required_unless_present = "adapter")]
    pub output: Option<PathBuf>,

    /// Image size, samples, depth and lighting, over the scene's.
    #[command(flatten)]
    pub settings: SettingsArgs,

    /// Render twice, in linear and in naive gamma space, and write both side by side
    /// (linear on the left) into a .png.
    #[arg(long, conflicts_with = "lighting", help_heading = "Render settings")]
    pub compare_gamma: bool,

    /// Also write each pixel's standard error (of its mean luminance, estimated from
    /// the spread of its samples) as a grey linear EXR, and print the estimated noise
    /// left in the summary. `{frame}` and `{tile}` expand as in the output name.
    #[arg(long, value_name = "PATH.exr", conflicts_with = "compare_gamma")]
    pub standard_error: Option<PathBuf>,

    /// Also write the auxiliary passes of the camera rays' first hits as layers of the
    /// output EXR (give an .exr output): `albedo` (channels albedo.R/G/B, after
    /// textures; mirrors and glass give their tint), `normal` (normal.X/Y/Z, world
    /// space) and `depth` (depth.Z, distance along the camera ray, 0 where it
    /// escapes), each averaged over the pixel's samples.
    #[arg(
        long,
        value_name = "NAME,...",
        value_parser = parse_aov_list,
        conflicts_with = "compare_gamma"
    )]
    pub aov: Option<AovList>,

    /// Denoise the image: `builtin` (the default, plain `--denoise`) with the
    /// edge-avoiding à-trous filter, guided by the first-hit albedo, normal and depth
    /// and by each pixel's noise estimate (on the backend that renders); `oidn` with
    /// Intel Open Image Denoise (a build with the `oidn` feature, and the library
    /// where OIDN_DIR names it, README "Intel Open Image Denoise"), guided by the
    /// albedo and normal, on the CPU. For the path integrator: Whitted images have no
    /// noise to remove, and are refused.
    #[arg(
        long,
        value_name = "DENOISER",
        num_args = 0..=1,
        default_missing_value = "builtin",
        conflicts_with = "compare_gamma"
    )]
    pub denoise: Option<DenoiserArg>,

    /// Where and how to trace.
    #[command(flatten)]
    pub device: DeviceArgs,

    /// Render only tile I of N (0-based): the band of rows from I·H/N to (I+1)·H/N
    /// (rounded down), every column. Writes a linear EXR tile (give an .exr output)
    /// that records its window, for `gpu-render merge`. `{tile}` in the output name
    /// becomes I, zero-padded to the digits of N - 1.
    #[arg(
        long,
        value_name = "I/N",
        allow_hyphen_values = true,
        value_parser = parse_tile,
        conflicts_with = "crop",
        help_heading = "Pieces"
    )]
    pub tile: Option<TileArg>,

    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 (0,0 is the top-left pixel).
    /// Writes a linear EXR tile like --tile.
    #[arg(
        long,
        value_name = "X0,Y0,X1,Y1",
        allow_hyphen_values = true,
        value_parser = parse_crop,
        help_heading = "Pieces"
    )]
    pub crop: Option<PixelWindow>,

    /// Render frame K (0-based) of the scene's [animation] camera path instead of its
    /// [camera]. `{frame}` in the output name becomes K, zero-padded to at least 4
    /// digits (more when the animation has more frames).
    #[arg(
        long,
        value_name = "K",
        allow_negative_numbers = true,
        value_parser = parse_whole,
        help_heading = "Pieces"
    )]
    pub frame: Option<u32>,

    /// Confine the files the scene names (textures, BRDF maps) to the scene file's
    /// folder: refuse absolute paths, `..` and links out of it. Without it a scene
    /// file is trusted like a program: it may name any file you can read.
    #[arg(long)]
    pub sandbox: bool,

    /// Refuse, before rendering, a render whose estimated peak memory is above this
    /// many GiB (see docs/reliability.md for the estimate per backend and format).
    #[arg(
        long,
        value_name = "GIB",
        default_value_t = DEFAULT_MAX_MEMORY_GIB,
        allow_hyphen_values = true,
        value_parser = parse_gib
    )]
    pub max_memory: f64,

    /// Print nothing but errors: no progress, warnings, notes or summary.
    #[arg(short, long)]
    pub quiet: bool,
}

/// A positive, finite number of seconds.
fn parse_seconds(text: &str) -> Result<std::time::Duration, String> {
    let seconds: f64 = text
        .parse()
        .map_err(|_| format!("must be a number of seconds, got {text:?}"))?;
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(format!("must be a positive number of seconds, got {text}"));
    }
    std::time::Duration::try_from_secs_f64(seconds).map_err(|e| format!("{text}: {e}"))
}

/// The render settings that override the scene's.
#[derive(Debug, Clone, Default, Args)]
pub struct SettingsArgs {
    /// Image width in pixels [default: the scene's].
    #[arg(
        long,
        value_name = "N",
        help_heading = "Render settings",
        allow_negative_numbers = true,
        value_parser = parse_positive
    )]
    pub width: Option<u32>,

    /// Image height in pixels [default: the scene's].
    #[arg(
        long,
        value_name = "N",
        help_heading = "Render settings",
        allow_negative_numbers = true,
        value_parser = parse_positive
    )]
    pub height: Option<u32>,

    /// Samples per pixel [default: the scene's].
    #[arg(
        long,
        value_name = "N",
        help_heading = "Render settings",
        allow_negative_numbers = true,
        value_parser = parse_positive
    )]
    pub spp: Option<u32>,

    /// Maximum reflection/refraction bounces; the bounce stack grows to fit unless
    /// --stack-size is given [default: the scene's].
    #[arg(
        long,
        value_name = "N",
        help_heading = "Render settings",
        allow_negative_numbers = true,
        value_parser = parse_whole
    )]
    pub max_depth: Option<u32>,

    /// Bounce-stack capacity; smaller than max depth + 1 drops deep branches
    /// [default: the scene's].
    #[arg(
        long,
        value_name = "N",
        help_heading = "Render settings",
        allow_negative_numbers = true,
        value_parser = parse_positive
    )]
    pub stack_size: Option<u32>,

    /// A measured speed/accuracy preset (samples, depth, cutoff); explicit --spp,
    /// --max-depth and --min-ray-weight win over it. See docs/quality.md.
    #[arg(
        long,
        value_enum,
        value_name = "PRESET",
        help_heading = "Render settings"
    )]
    pub quality: Option<QualityArg>,

    /// Do not trace reflected/refracted branches whose weight is at most this, in
    /// [0, 1]: faster, slightly darker glass and mirrors [default: the scene's, or 0].
    #[arg(
        long,
        value_name = "W",
        help_heading = "Render settings",
        allow_hyphen_values = true
    )]
    pub min_ray_weight: Option<f64>,

    /// Shade in linear space (correct) or naively on gamma-encoded colours
    /// [default: the scene's].
    #[arg(
        long,
        value_enum,
        value_name = "SPACE",
        help_heading = "Render settings"
    )]
    pub lighting: Option<LightingArg>,
    /// Light transport: Whitted ray tracing or Monte Carlo path tracing [default: the
    /// scene's, else whitted].
    #[arg(
        long,
        value_enum,
        value_name = "INTEGRATOR",
        help_heading = "Render settings"
    )]
    pub integrator: Option<IntegratorArg>,
}

/// Where and how to trace.
#[derive(Debug, Args)]
pub struct DeviceArgs {
    /// Where to trace: the GPU if one is found (auto), the GPU only, or the CPU
    /// reference tracer.
    #[arg(
        long,
        value_enum,
        default_value_t = BackendArg::Auto,
        help_heading = "Device"
    )]
    pub backend: BackendArg,

    /// `list` prints the GPU adapters and exits; an index from that list or part of
    /// an adapter's name selects one.
    #[arg(long, value_name = "list|INDEX|NAME", value_parser = parse_adapter, help_heading = "Device")]
    pub adapter: Option<AdapterArg>,

    /// GPU only: the most loop iterations one shader invocation runs per dispatch
    /// [default: the adapter's; on llvmpipe its loop limit over its SIMD lanes]. The
    /// image does not depend on it.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        value_parser = parse_in_range::<1, { u32::MAX }>,
        help_heading = "Device"
    )]
    pub iteration_budget: Option<u32>,

    /// GPU only: give up with an error when one wait for the GPU takes longer than
    /// this many seconds [default: wait as long as it takes; each submission's work is
    /// bounded, and a hung device is reported lost by its driver].
    #[arg(
        long,
        value_name = "SECONDS",
        allow_hyphen_values = true,
        value_parser = parse_seconds,
        help_heading = "Device"
    )]
    pub gpu_timeout: Option<std::time::Duration>,

    /// GPU only: how the triangles are found: the device's ray queries where it has
    /// them and is a real GPU (auto), always ray queries (an error without them), or
    /// always the software walk of the BVH. The summary says when ray queries ran.
    #[arg(
        long,
        value_enum,
        default_value_t = TraversalArg::Auto,
        help_heading = "Device"
    )]
    pub traversal: TraversalArg,
}

impl SettingsArgs {
    /// The command-line settings that override the scene file's.
    pub fn overrides(&self) -> RenderOverrides {
        let preset = self
            .quality
            .map(|quality| QualityPreset::from(quality).overrides())
            .unwrap_or_default();
        // An explicit depth without an explicit stack size lets the stack grow to fit.
        let preset_stack = if self.max_depth.is_some() {
            None
        } else {
            preset.stack_size
        };
        RenderOverrides {
            width: self.width,
            height: self.height,
            samples_per_pixel: self.spp.or(preset.samples_per_pixel),
            max_depth: self.max_depth.or(preset.max_depth),
            stack_size: self.stack_size.or(preset_stack),
            lighting_space: self.lighting.map(LightingSpace::from),
            min_ray_weight: self.min_ray_weight.or(preset.min_ray_weight),
            integrator: self.integrator.map(Integrator::from),
        }
    }

    /// The flag that sets the render setting `error` is about, with the value given,
    /// if the user gave that flag (`"--width 0"`).
    pub fn flag_for_setting(&self, error: &SettingsError) -> Option<String> {
        let text = |value: Option<u32>| value.map(|v| v.to_string());
        let (flag, value) = match error {
            SettingsError::Dimension { name: "width", .. } => ("--width", text(self.width)),
            SettingsError::Dimension { name: "height", .. } => ("--height", text(self.height)),
            SettingsError::SamplesPerPixel(_) => ("--spp", text(self.spp)),
            SettingsError::MaxDepth(_) => ("--max-depth", text(self.max_depth)),
            SettingsError::StackSize(_) => ("--stack-size", text(self.stack_size)),
            SettingsError::MinRayWeight(_) => (
                "--min-ray-weight",
                self.min_ray_weight.map(|w| w.to_string()),
            ),
            _ => return None,
        };
        value.map(|value| format!("{flag} {value}"))
    }
}

/// `--quality` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum QualityArg {
    /// 1 sample, depth 4, cutoff 0.05.
    Draft,
    /// 4 samples, depth 4.
    Preview,
    /// 16 samples, depth 8.
    Final,
}

impl From<QualityArg> for QualityPreset {
    fn from(arg: QualityArg) -> Self {
        match arg {
            QualityArg::Draft => QualityPreset::Draft,
            QualityArg::Preview => QualityPreset::Preview,
            QualityArg::Final => QualityPreset::Final,
        }
    }
}

/// `--lighting` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LightingArg {
    /// Correct: light in linear space, encode to sRGB once at the end.
    Linear,
    /// The classic mistake: light on sRGB-encoded colours, no final encode.
    NaiveGamma,
}

/// `--integrator` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum IntegratorArg {
    /// Whitted ray tracing: shadow rays, mirror and refraction branches, ambient.
    Whitted,
    /// Path tracing: area lights, indirect light, caustics.
    Path,
}

impl From<IntegratorArg> for Integrator {
    fn from(arg: IntegratorArg) -> Self {
        match arg {
            IntegratorArg::Whitted => Integrator::Whitted,
            IntegratorArg::Path => Integrator::Path,
        }
    }
}

impl From<LightingArg> for LightingSpace {
    fn from(arg: LightingArg) -> Self {
        match arg {
            LightingArg::Linear => LightingSpace::Linear,
            LightingArg::NaiveGamma => LightingSpace::NaiveGamma,
        }
    }
}

/// `--denoise`: which denoiser.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DenoiserArg {
    /// The built-in edge-avoiding à-trous filter (GPU, or its CPU twin).
    Builtin,
    /// Intel Open Image Denoise (feature `oidn`; the library loaded at run time).
    Oidn,
}

/// `--backend` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// The GPU if an adapter is found, otherwise the CPU reference tracer.
    Auto,
    /// The GPU; fail if there is none.
    Gpu,
    /// The CPU reference tracer.
    Cpu,
}

impl DeviceArgs {
    /// Refuses the GPU's flags with `--backend cpu`, which has no use for them: the
    /// adapter, the traversal, the iteration budget and the GPU timeout are all
    /// refused alike rather than some silently ignored.
    pub fn check_for_backend(&self) -> Result<(), String> {
        if self.backend != BackendArg::Cpu {
            return Ok(());
        }
        let flag = if self.adapter.is_some() {
            Some(("--adapter", "selects a GPU adapter"))
        } else if self.traversal != TraversalArg::Auto {
            Some(("--traversal", "chooses how the GPU finds triangles"))
        } else if self.iteration_budget.is_some() {
            Some(("--iteration-budget", "bounds the GPU kernels' loops"))
        } else if self.gpu_timeout.is_some() {
            Some(("--gpu-timeout", "bounds the GPU's submissions"))
        } else {
            None
        };
        match flag {
            Some((flag, what)) => Err(format!(
                "{flag} {what}; it cannot be used with --backend cpu"
            )),
            None => Ok(()),
        }
    }
}

/// `--traversal` values ([`gpu_render::gpu::Traversal`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TraversalArg {
    /// Ray queries where the device has them and is not a CPU emulation.
    Auto,
    /// The software walk of the BVH.
    Software,
    /// The device's ray queries; fail if it has none.
    Hardware,
}

impl From<TraversalArg> for gpu_render::gpu::Traversal {
    fn from(arg: TraversalArg) -> Self {
        match arg {
            TraversalArg::Auto => Self::Auto,
            TraversalArg::Software => Self::Software,
            TraversalArg::Hardware => Self::Hardware,
        }
    }
}

/// `--adapter` values.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AdapterArg {
    /// Print the adapters and exit.
    List,
    /// The adapter at this index of the list.
    Index(usize),
    /// The first adapter whose name contains this text.
    Name(String),
}

/// A count that must be at least 1: the range is checked later, against the scene's
/// other settings, but a negative or non-numeric value is refused here.
fn parse_positive(text: &str) -> Result<u32, String> {
    parse_count(text, "a positive integer (1 or more)")
}

/// A count that may be 0.
fn parse_whole(text: &str) -> Result<u32, String> {
    parse_count(text, "a whole number (0 or more)")
}

fn parse_count(text: &str, what: &str) -> Result<u32, String> {
    let digits = text.trim();
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("must be {what}, got `{text}`"));
    }
    digits
        .parse()
        .map_err(|_| format!("must be {what} no larger than {}, got {text}", u32::MAX))
}

/// A count within `LOW..=HIGH`.
fn parse_in_range<const LOW: u32, const HIGH: u32>(text: &str) -> Result<u32, String> {
    let value = parse_count(text, "a whole number")?;
    if value < LOW && HIGH == u32::MAX {
        return Err(format!("must be at least {LOW}, got {value}"));
    }
    if !(LOW..=HIGH).contains(&value) {
        return Err(format!("must be between {LOW} and {HIGH}, got {value}"));
    }
    Ok(value)
}

/// A memory size in GiB, more than 0.
fn parse_gib(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(gib) if gib.is_finite() && gib > 0.0 => Ok(gib),
        _ => Err(format!(
            "must be a number of GiB above 0 (e.g. 4 or 0.5), got `{text}`"
        )),
    }
}

fn parse_adapter(text: &str) -> Result<AdapterArg, String> {
    let text = text.trim();
    if text.is_empty() {
        return Err("expected `list`, an adapter index or part of an adapter name".into());
    }
    if text.eq_ignore_ascii_case("list") {
        return Ok(AdapterArg::List);
    }
    if text.bytes().all(|b| b.is_ascii_digit()) {
        return text
            .parse()
            .map(AdapterArg::Index)
            .map_err(|e| format!("adapter index {text}: {e}"));
    }
    Ok(AdapterArg::Name(text.to_owned()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn adapter_values() {
        assert_eq!(parse_adapter("list"), Ok(AdapterArg::List));
        assert_eq!(parse_adapter("2"), Ok(AdapterArg::Index(2)));
        assert_eq!(
            parse_adapter("NVIDIA"),
            Ok(AdapterArg::Name("NVIDIA".into()))
        );
        assert!(parse_adapter(" ").is_err());
    }

    #[test]
    fn names_the_flag_behind_a_settings_message() {
        let cli = Cli::try_parse_from(["gpu-render", "s.toml", "-o", "o.png", "--spp", "0"])
            .expect("parses");
        let settings = &cli.render.settings;
        assert_eq!(
            settings
                .flag_for_setting(&SettingsError::SamplesPerPixel(0))
                .as_deref(),
            Some("--spp 0")
        );
        let width = SettingsError::Dimension {
            name: "width",
            value: 0,
        };
        assert_eq!(settings.flag_for_setting(&width), None);
    }

    #[test]
    fn counts_say_what_they_must_be() {
        assert_eq!(parse_positive("12"), Ok(12));
        assert_eq!(parse_positive("0"), Ok(0));
        let negative = parse_positive("-1").expect_err("negative");
        assert!(
            negative.contains("positive integer") && negative.contains("-1"),
            "{negative}"
        );
        assert!(parse_positive("1.5").is_err());
        assert!(parse_positive("99999999999").is_err());
        assert!(
            parse_whole("-3")
                .expect_err("negative")
                .contains("whole number")
        );
        assert_eq!(parse_in_range::<1, 10>("10"), Ok(10));
        assert!(parse_in_range::<1, 10>("0").is_err());
        assert!(parse_gib("0").is_err() && parse_gib("nan").is_err());
        assert_eq!(parse_gib("0.5"), Ok(0.5));
    }

    #[test]
    fn a_negative_width_reaches_the_value_parser() {
        let err = Cli::try_parse_from(["gpu-render", "s.toml", "-o", "o.png", "--width", "-1"])
            .expect_err("refused");
        let shown = err.to_string();
        assert!(
            shown.contains("--width") && shown.contains("positive integer"),
            "{shown}"
        );
        let err = Cli::try_parse_from(["gpu-render", "tradeoff", "s.toml", "--repeats", "0"])
            .expect_err("refused");
        assert!(err.to_string().contains("--repeats"), "{err}");
    }

    /// Every option that takes a number, a tile or a window, with a value of `-1`: the
    /// value parser sees it (and says what the value must be), where clap alone would
    /// take `-1` for a flag and answer "unexpected argument".
    #[test]
    fn a_negative_value_reaches_every_value_parser() {
        let command = Cli::command();
        // What each command needs besides the option, so that only the option fails.
        let mut commands: Vec<(Vec<&str>, &clap::Command)> =
            vec![(vec!["s.toml", "-o", "o.exr"], &command)];
        for sub in command.get_subcommands() {
            let needs = match sub.get_name() {
                "merge" => vec!["t.exr", "-o", "o.png"],
                _ => vec!["s.toml"],
            };
            commands.push((needs, sub));
        }
        let mut checked = Vec::new();
        for (needs, command) in commands {
            for option in command.get_arguments() {
                let Some(long) = option.get_long() else {
                    continue;
                };
                let takes_a_value = option.get_action().takes_values();
                let value_name = option
                    .get_value_names()
                    .and_then(|names| names.first())
                    .map(|name| name.as_str())
                    .unwrap_or("");
                // Paths, names and lists of words are not numbers.
                let not_numeric = option.get_value_parser().possible_values().is_some()
                    || value_name.contains("PATH")
                    || value_name.contains("DIR")
                    || value_name.contains("NAME");
                if !takes_a_value || not_numeric {
                    continue;
                }
                let flag = format!("--{long}");
                let mut argv = vec!["gpu-render"];
                if command.get_name() != "gpu-render" {
                    argv.push(command.get_name());
                }
                argv.extend(&needs);
                argv.extend([flag.as_str(), "-1"]);
                let values = option.get_num_args().map_or(1, |n| n.min_values());
                argv.extend(std::iter::repeat_n("-1", values.saturating_sub(1)));
                match Cli::try_parse_from(&argv) {
                    // A value checked later, against the scene (--min-ray-weight).
                    Ok(_) => {}
                    Err(err) => {
                        assert_eq!(
                            err.kind(),
                            clap::error::ErrorKind::ValueValidation,
                            "{argv:?}: {err}"
                        );
                        assert!(err.to_string().contains(&flag), "{argv:?}: {err}");
                    }
                }
                checked.push(format!("{} {flag}", command.get_name()));
            }
        }
        for expected in [
            "gpu-render --tile",
            "gpu-render --crop",
            "gpu-render --max-memory",
            "gpu-render --frame",
            "gpu-render --iteration-budget",
            "gpu-render --gpu-timeout",
            "gpu-render --width",
            "estimate --tiles",
            "estimate --calibration-pixels",
            "tradeoff --repeats",
        ] {
            assert!(
                checked.iter().any(|c| c == expected),
                "{expected} not checked: {checked:?}"
            );
        }
        let err = Cli::try_parse_from(["gpu-render", "s.toml", "-o", "t.exr", "--tile", "-1/4"])
            .expect_err("refused");
        assert!(err.to_string().contains("must be I/N"), "{err}");
        let err =
            Cli::try_parse_from(["gpu-render", "s.toml", "-o", "o.png", "--max-memory", "-1"])
                .expect_err("refused");
        assert!(err.to_string().contains("must be a number of GiB"), "{err}");
    }

    #[test]
    fn tiles_and_crops_parse_or_say_what_they_must_be() {
        assert_eq!(parse_tile("2/4"), Ok(TileArg { index: 2, count: 4 }));
        for bad in ["4/4", "0/0", "1", "-1/4", "a/b", "1/2/3", "/4"] {
            let err = parse_tile(bad).expect_err(bad);
            assert!(err.contains(bad), "{err}");
        }
        assert_eq!(
            parse_crop("0, 10,64,20"),
            Ok(PixelWindow {
                columns: 0..64,
                rows: 10..20
            })
        );
        for bad in [
            "1,2,3",
            "0,0,0,5",
            "4,0,2,5",
            "0,0,1,1,1",
            "0,0,x,1",
            "-1,0,2,2",
        ] {
            let err = parse_crop(bad).expect_err(bad);
            assert!(err.contains(bad), "{err}");
        }
        let cli = Cli::try_parse_from([
            "gpu-render",
            "s.toml",
            "-o",
            "t.exr",
            "--tile",
            "0/2",
            "--crop",
            "0,0,1,1",
        ]);
        assert!(cli.is_err(), "--tile and --crop together");
    }

    #[test]
    fn adapter_list_needs_no_scene() {
        let cli = Cli::try_parse_from(["gpu-render", "--adapter", "list"]).expect("parses");
        assert_eq!(cli.render.device.adapter, Some(AdapterArg::List));
        assert!(Cli::try_parse_from(["gpu-render", "s.toml"]).is_err());
        assert!(Cli::try_parse_from(["gpu-render", "-o", "x.png"]).is_err());
    }

    #[test]
    fn quality_presets_yield_to_explicit_flags() {
        let parse = |extra: &[&str]| {
            let mut argv = vec!["gpu-render", "s.toml", "-o", "o.png"];
            argv.extend_from_slice(extra);
            Cli::try_parse_from(argv)
                .expect("parses")
                .render
                .settings
                .overrides()
        };
        let draft = parse(&["--quality", "draft"]);
        assert_eq!(draft.samples_per_pixel, Some(1));
        assert_eq!(draft.min_ray_weight, Some(0.05));
        let tuned = parse(&["--quality", "final", "--spp", "3", "--max-depth", "12"]);
        assert_eq!(tuned.samples_per_pixel, Some(3));
        assert_eq!(tuned.max_depth, Some(12));
        // The stack grows with the explicit depth instead of keeping the preset's.
        assert_eq!(tuned.stack_size, None);
        assert_eq!(parse(&[]).samples_per_pixel, None);
    }
}
