//! Choosing where to trace (GPU or CPU reference) and rendering a scene there.

use std::io::Write;

use anyhow::{Context, Result, bail};
use gpu_render::cpu;
use gpu_render::film::{LinearImage, ProgressFn, RenderStats, Rendered};
use gpu_render::gpu::{self, AdapterChoice, HeadlessGpu, Renderer, RendererOptions, TraceRegion};
use gpu_render::low_level::denoise::{self, DenoiseSettings, GuidePasses};
use gpu_render::low_level::noise::NoiseEstimate;
use gpu_render::scene::Scene;
use gpu_render::tiles::PixelWindow;

use crate::args::{AdapterArg, BackendArg, DenoiserArg};
use crate::pipeline_cache::PipelineCacheFile;

/// The denoiser `--denoise` chose, ready to run.
pub enum Denoiser {
    /// The built-in à-trous filter (GPU, or its CPU twin).
    Builtin,
    /// Intel Open Image Denoise, loaded.
    #[cfg(feature = "oidn")]
    Oidn(denoise::oidn::Oidn),
}

impl Denoiser {
    /// Readies the denoiser `arg` names: loads OIDN (where `OIDN_DIR` says, see
    /// `gpu_render::low_level::denoise::oidn`) for `oidn`, or says that this build
    /// has no OIDN.
    pub fn open(arg: DenoiserArg) -> Result<Self> {
        match arg {
            DenoiserArg::Builtin => Ok(Self::Builtin),
            #[cfg(feature = "oidn")]
            DenoiserArg::Oidn => Ok(Self::Oidn(
                denoise::oidn::Oidn::load().context("--denoise oidn")?,
            )),
            #[cfg(not(feature = "oidn"))]
            DenoiserArg::Oidn => bail!(
                "--denoise oidn: this gpu-render was built without the `oidn` feature (Intel \
                 Open Image Denoise); rebuild it with `cargo build --release --features oidn` \
                 (README, \"Intel Open Image Denoise\"), or use --denoise builtin"
            ),
        }
    }

    /// Whether the render must estimate each pixel's noise for this denoiser (the
    /// built-in filter weighs by it; OIDN does not use it).
    pub fn needs_noise(&self) -> bool {
        matches!(self, Self::Builtin)
    }
}

/// A render as the command line needs it: both images and the statistics.
pub struct Frame {
    /// The linear image.
    pub image: LinearImage,
    /// The 8-bit display image, RGBA.
    pub display_rgba8: Vec<u8>,
    /// Ray count and tracing time.
    pub stats: RenderStats,
    /// Each pixel's noise estimate, where the backend was opened with
    /// [`GpuOptions::noise`].
    pub noise: Option<NoiseEstimate>,
    /// The auxiliary passes, where the backend was opened with [`GpuOptions::aov`]
    /// (whole renders only).
    pub aov: Option<GuidePasses>,
    /// How long the GPU spent compiling the scene's kernels (zero when they were
    /// cached); `None` on the CPU reference.
    pub compile: Option<std::time::Duration>,
    /// Whether the GPU found the triangles by ray query (`--traversal`).
    pub hardware_traversal: bool,
}

impl Frame {
    /// A CPU render of `scene` with its display image encoded as the scene says.
    fn from_cpu(rendered: Rendered, scene: &Scene) -> Self {
        let display_rgba8 = rendered
            .image
            .to_display_rgba8(scene.display_encodes_srgb());
        Self {
            image: rendered.image,
            display_rgba8,
            stats: rendered.stats,
            noise: rendered.noise,
            aov: None,
            compile: None,
            hardware_traversal: false,
        }
    }
}

/// The GPU renderer's options from the command line.
#[derive(Debug, Clone, Copy, Default)]
pub struct GpuOptions {
    /// `--iteration-budget`.
    pub iteration_budget: Option<u32>,
    /// `--gpu-timeout`.
    pub timeout: Option<std::time::Duration>,
    /// Estimate each pixel's noise (`--standard-error`); on either backend.
    pub noise: bool,
    /// Record the auxiliary passes (`--aov`, `--denoise`); on either backend.
    pub aov: bool,
    /// `--traversal`.
    pub traversal: gpu::Traversal,
}

/// An opened backend, ready to render any number of scenes.
pub enum Backend {
    /// The wgpu tracer on an opened device.
    Gpu {
        /// Instance, adapter, device and queue.
        gpu: Box<HeadlessGpu>,
        /// The renderer built for the device.
        renderer: Box<Renderer>,
        /// The adapter's name, for the summary.
        adapter_name: String,
        /// The pipeline cache kept between runs, where the device has one.
        pipeline_cache: Option<PipelineCacheFile>,
    },
    /// The CPU reference tracer.
    Cpu {
        /// Why `--backend auto` chose it, for the summary (`None` when asked for).
        reason: Option<String>,
        /// Whether renders estimate each pixel's noise.
        noise: bool,
        /// Whether whole renders record the auxiliary passes.
        aov: bool,
    },
}

impl Backend {
    /// Opens the backend `choice` asks for. With `auto` and no usable adapter, prints
    /// a one-line note (unless `quiet`) and falls back to the CPU. An explicit
    /// `--adapter` demands a GPU (except with `cpu`, which the caller refuses earlier).
    pub fn open(
        choice: BackendArg,
        adapter: Option<&AdapterArg>,
        scene: &Scene,
        options: &GpuOptions,
        quiet: bool,
    ) -> Result<Self> {
        let adapter_choice = match adapter {
            None => AdapterChoice::Default,
            Some(AdapterArg::Index(index)) => AdapterChoice::Index(*index),
            Some(AdapterArg::Name(name)) => AdapterChoice::NameContains(name.clone()),
            Some(AdapterArg::List) => bail!("--adapter list does not select an adapter"),
        };
        match choice {
            BackendArg::Cpu => Ok(Backend::Cpu {
                reason: None,
                noise: options.noise,
                aov: options.aov,
            }),
            BackendArg::Gpu => Self::open_gpu(&adapter_choice, options),
            BackendArg::Auto if adapter.is_some() => Self::open_gpu(&adapter_choice, options),
            BackendArg::Auto => match HeadlessGpu::new(&adapter_choice) {
                Ok(gpu) => match auto_rule(&gpu.adapter_info(), scene) {
                    Some(reason) => Ok(Backend::Cpu {
                        reason: Some(reason),
                        noise: options.noise,
                        aov: options.aov,
                    }),
                    None => Self::with_device(gpu, options),
                },
                Err(e) => {
                    if !quiet {
                        eprintln!("no GPU adapter found ({e}); rendering on the CPU reference");
                    }
                    Ok(Backend::Cpu {
                        reason: Some("no GPU adapter".into()),
                        noise: options.noise,
                        aov: options.aov,
                    })
                }
            },
        }
    }

    fn open_gpu(choice: &AdapterChoice, options: &GpuOptions) -> Result<Self> {
        let gpu = HeadlessGpu::new(choice).with_context(|| match choice {
            AdapterChoice::Default => {
                "cannot open a GPU (use --backend cpu to render on the CPU)".to_owned()
            }
            AdapterChoice::Index(i) => format!("cannot open GPU adapter {i} (see --adapter list)"),
            AdapterChoice::NameContains(name) => {
                format!("cannot open a GPU adapter named like {name:?} (see --adapter list)")
            }
        })?;
        Self::with_device(gpu, options)
    }

    fn with_device(gpu: HeadlessGpu, options: &GpuOptions) -> Result<Self> {
        let adapter_name = gpu.adapter_info().name;
        let pipeline_cache = PipelineCacheFile::open(&gpu.device, &gpu.adapter_info());
        let options = RendererOptions {
            iteration_budget: options.iteration_budget,
            poll_timeout: options.timeout,
            noise_estimate: options.noise,
            aov: options.aov,
            traversal: options.traversal,
            pipeline_cache: pipeline_cache.as_ref().map(PipelineCacheFile::cache),
            ..RendererOptions::default()
        };
        let renderer = Renderer::new(&gpu.device, options)
            .with_context(|| format!("cannot set up the GPU tracer on {adapter_name}"))?;
        Ok(Backend::Gpu {
            gpu: Box::new(gpu),
            renderer: Box::new(renderer),
            adapter_name,
            pipeline_cache,
        })
    }

    /// Saves the GPU's pipeline cache for the next run, if it has one and it changed.
    pub fn save_pipeline_cache(&self, quiet: bool) {
        if let Backend::Gpu {
            pipeline_cache: Some(cache),
            ..
        } = self
        {
            cache.save(quiet);
        }
    }

    /// A short description for the summary: `GPU (name)` or `CPU reference`, with
    /// the reason when `--backend auto` chose the CPU.
    pub fn describe(&self) -> String {
        match self {
            Backend::Gpu { adapter_name, .. } => format!("GPU ({adapter_name})"),
            Backend::Cpu { reason: None, .. } => "CPU reference".to_owned(),
            Backend::Cpu {
                reason: Some(reason),
                ..
            } => format!("CPU reference (auto: {reason})"),
        }
    }

    /// `gpu` or `cpu`, as a tile records it.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Backend::Gpu { .. } => "gpu",
            Backend::Cpu { .. } => "cpu",
        }
    }

    /// The adapter's name, or `CPU reference`, as a tile records it.
    pub fn device_name(&self) -> String {
        match self {
            Backend::Gpu { adapter_name, .. } => adapter_name.clone(),
            Backend::Cpu { .. } => "CPU reference".to_owned(),
        }
    }

    /// Renders the pixels of `window` of `scene` (a frame the window's size),
    /// reporting the window's rows done to `progress`.
    pub fn render_region(
        &self,
        scene: &Scene,
        window: &PixelWindow,
        progress: ProgressFn<'_>,
    ) -> Result<Frame> {
        match self {
            Backend::Gpu { gpu, renderer, .. } => {
                let uploaded = renderer
                    .upload(&gpu.device, &gpu.queue, scene)
                    .context("cannot upload the scene to the GPU")?;
                let region = TraceRegion {
                    columns: window.columns.clone(),
                    rows: window.rows.clone(),
                    target_origin: (window.columns.start, window.rows.start),
                };
                let rendered = renderer
                    .render_region(&gpu.device, &gpu.queue, &uploaded, &region, Some(progress))
                    .context("GPU render failed")?;
                Ok(Frame {
                    image: rendered.image,
                    display_rgba8: rendered.display_rgba8,
                    stats: rendered.stats,
                    noise: rendered.noise,
                    aov: None,
                    compile: Some(uploaded.compile_time()),
                    hardware_traversal: uploaded.features().hardware_traversal,
                })
            }
            Backend::Cpu { noise, .. } => {
                let render = if *noise {
                    cpu::render_region_with_noise
                } else {
                    cpu::render_region
                };
                let rendered = render(
                    scene,
                    window.columns.clone(),
                    window.rows.clone(),
                    Some(progress),
                )?;
                Ok(Frame::from_cpu(rendered, scene))
            }
        }
    }

    /// The image of `frame` (rendered with the auxiliary passes, and the noise
    /// estimate for the built-in filter) denoised by `denoiser`: the built-in filter
    /// on the GPU where `frame` was rendered there, OIDN on the CPU.
    pub fn denoise(&self, frame: &Frame, denoiser: &Denoiser) -> Result<LinearImage> {
        let Some(guides) = &frame.aov else {
            bail!("the backend returned no auxiliary passes to denoise with");
        };
        let radiance = || -> Vec<[f32; 3]> {
            frame
                .image
                .pixels
                .iter()
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        };
        let image = |denoised: Vec<[f32; 3]>| LinearImage {
            width: frame.image.width,
            height: frame.image.height,
            pixels: denoised.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
        };
        match denoiser {
            Denoiser::Builtin => {}
            #[cfg(feature = "oidn")]
            Denoiser::Oidn(oidn) => {
                let denoised = oidn
                    .denoise(&radiance(), guides, &denoise::oidn::OidnSettings::default())
                    .context("--denoise oidn")?;
                return Ok(image(denoised));
            }
        }
        let Some(noise) = &frame.noise else {
            bail!("the backend returned no noise estimate to denoise with");
        };
        let variance: Vec<f32> = noise.standard_error.iter().map(|se| se * se).collect();
        let settings = DenoiseSettings::default();
        match self {
            Backend::Gpu { gpu, renderer, .. } => renderer
                .denoise_image(
                    &gpu.device,
                    &gpu.queue,
                    &frame.image,
                    &variance,
                    guides,
                    &settings,
                )
                .context("GPU denoising failed"),
            Backend::Cpu { .. } => Ok(image(denoise::denoise(
                &radiance(),
                &variance,
                guides,
                &settings,
            ))),
        }
    }

    /// Renders `scene`, reporting rows done to `progress`.
    pub fn render(&self, scene: &Scene, progress: ProgressFn<'_>) -> Result<Frame> {
        match self {
            Backend::Gpu { gpu, renderer, .. } => {
                let uploaded = renderer
                    .upload(&gpu.device, &gpu.queue, scene)
                    .context("cannot upload the scene to the GPU")?;
                let whole = TraceRegion::whole(uploaded.width(), uploaded.height());
                let rendered = renderer
                    .render_region(&gpu.device, &gpu.queue, &uploaded, &whole, Some(progress))
                    .context("GPU render failed")?;
                Ok(Frame {
                    image: rendered.image,
                    display_rgba8: rendered.display_rgba8,
                    stats: rendered.stats,
                    noise: rendered.noise,
                    aov: rendered.aov,
                    compile: Some(uploaded.compile_time()),
                    hardware_traversal: uploaded.features().hardware_traversal,
                })
            }
            Backend::Cpu { noise, aov, .. } => {
                let rendered = if *noise {
                    cpu::render_with_noise(scene, Some(progress))
                } else {
                    cpu::render(scene, Some(progress))
                };
                let mut frame = Frame::from_cpu(rendered, scene);
                frame.aov = aov.then(|| cpu::render_aovs(scene));
                Ok(frame)
            }
        }
    }
}

/// The rule of `--backend auto` for the adapter wgpu prefers and `scene`, from the
/// figures in `BENCHMARKS.md` ("--backend auto"): a real GPU is always used, and so is
/// a CPU device (lavapipe, llvmpipe, WARP: software on the same cores as the CPU
/// reference) whose loops have no limit (llvmpipe from Mesa 25,
/// `gpu::driver_loop_limit`): its trace measured faster than the CPU reference's on
/// every scene measured, Whitted and path-traced, with and without meshes (the bunny
/// 2.4x, the million-triangle terrain 2.6x, `models.toml` 1.2x, a textured glTF truck
/// 1.9x, the path-traced Cornell box walking its tree 1.4x and unrolled 2.3x, a
/// path-traced bunny 1.7x). Older Mesa measured slower on every scene, so there the
/// CPU reference is used. On any device, a scene with a sphere that only the CPU
/// reference's f64 places precisely enough (`scene::sphere_precision`: a small sphere
/// far from the origin seen from close by), or another shape, light or camera beyond
/// the GPU's f32, renders on the CPU. Returns why the CPU reference is chosen instead,
/// if it is.
pub fn auto_rule(adapter: &wgpu::AdapterInfo, scene: &Scene) -> Option<String> {
    if let Some(radius) = sphere_only_the_cpu_places(scene) {
        return Some(format!(
            "a sphere of radius {radius:e} is beyond the GPU's f32 precision here but not \
             the CPU reference's f64 (see the load warning); --backend gpu uses the GPU anyway"
        ));
    }
    let aim = gpu_render::scene::camera_pixel_precision(&scene.camera, scene.render.height);
    if aim > gpu_render::scene::CAMERA_PRECISION_LIMIT {
        return Some(format!(
            "the field of view of {:e}° over {} pixels is beyond the GPU's f32 ray \
             directions ({aim:.1e} of a pixel) but not the CPU reference's f64; --backend gpu \
             uses the GPU anyway",
            scene.camera.fov_y_degrees, scene.render.height
        ));
    }
    if let Some((light, shape, distance)) = gpu_render::scene::light_beyond_the_gpu(scene) {
        return Some(format!(
            "point light {light} is {distance:e} from shape {shape}, where its irradiance is \
             beyond the GPU's f32 but not the CPU reference's f64; --backend gpu uses the GPU \
             anyway"
        ));
    }
    if let Some(beyond) = gpu_render::scene::flat_shape_beyond_the_gpu(scene) {
        return Some(format!(
            "{} is beyond the GPU's f32 precision or range here (placed to {:.1e} units at \
             {:.1e} from the camera) but not the CPU reference's f64; --backend gpu uses the \
             GPU anyway",
            beyond.what, beyond.precision.gpu, beyond.precision.distance
        ));
    }
    if adapter.device_type != wgpu::DeviceType::Cpu || gpu::driver_loop_limit(adapter).is_none() {
        return None;
    }
    Some(format!(
        "the only adapter, {}, is a CPU device whose driver version measured slower than \
         the CPU reference on every scene (BENCHMARKS.md); --backend gpu uses it anyway",
        adapter.name
    ))
}

/// The radius of the first sphere that the GPU cannot place precisely enough seen from
/// the camera while the CPU reference can ([`gpu_render::scene::sphere_precision`]).
fn sphere_only_the_cpu_places(scene: &Scene) -> Option<f64> {
    scene.shapes.iter().find_map(|shape| match shape {
        gpu_render::scene::Shape::Sphere { center, radius, .. } => {
            let precision = gpu_render::scene::sphere_precision(*center, *radius, scene.camera.eye);
            (precision.gpu_hopeless() && !precision.cpu_hopeless()).then_some(*radius)
        }
        _ => None,
    })
}

/// The adapter features the tracer uses where they exist (timestamps for GPU time,
/// subgroups) or that decide what it could use (ray queries for hardware traversal, a
/// driver pipeline cache), as `--adapter list` names them.
const LISTED_FEATURES: [(&str, wgpu::Features); 4] = [
    ("SUBGROUP", wgpu::Features::SUBGROUP),
    ("TIMESTAMP_QUERY", wgpu::Features::TIMESTAMP_QUERY),
    (
        "EXPERIMENTAL_RAY_QUERY",
        wgpu::Features::EXPERIMENTAL_RAY_QUERY,
    ),
    ("PIPELINE_CACHE", wgpu::Features::PIPELINE_CACHE),
];

/// One line of `--adapter list`: `0: NAME (vulkan, DiscreteGpu, driver NVIDIA
/// 570.1; SUBGROUP yes, TIMESTAMP_QUERY yes, EXPERIMENTAL_RAY_QUERY no, PIPELINE_CACHE
/// yes)`.
fn adapter_line(index: usize, info: &wgpu::AdapterInfo, features: wgpu::Features) -> String {
    let driver = [info.driver.trim(), info.driver_info.trim()]
        .into_iter()
        .filter(|part| !part.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    let driver = if driver.is_empty() {
        String::new()
    } else {
        format!(", driver {driver}")
    };
    let listed = LISTED_FEATURES
        .iter()
        .map(|(name, feature)| {
            let offered = if features.contains(*feature) {
                "yes"
            } else {
                "no"
            };
            format!("{name} {offered}")
        })
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "{index}: {} ({}, {:?}{driver}; {listed})",
        info.name, info.backend, info.device_type
    )
}

/// Prints the GPU adapters wgpu can see, one a line, on stdout, with their drivers
/// and the features of [`LISTED_FEATURES`].
pub fn print_adapters() -> Result<()> {
    let adapters = gpu::list_adapters_with_features();
    let mut out = std::io::stdout().lock();
    let result = if adapters.is_empty() {
        writeln!(out, "no GPU adapters found")
    } else {
        adapters
            .iter()
            .enumerate()
            .try_for_each(|(index, (info, features))| {
                writeln!(out, "{}", adapter_line(index, info, *features))
            })
    };
    match result.and_then(|()| out.flush()) {
        // `gpu-render --adapter list | head -1` is fine.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other.context("cannot write the adapter list to stdout"),
    }
}

#[cfg(test)]
mod tests {
    use super::{adapter_line, auto_rule};

    fn adapter(name: &str, device_type: wgpu::DeviceType) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: name.into(),
            ..wgpu::AdapterInfo::new(device_type, wgpu::Backend::Vulkan)
        }
    }

    fn scene(text: &str) -> gpu_render::scene::Scene {
        gpu_render::scene::parse_scene(text, std::path::Path::new("<test>")).expect("scene")
    }

    #[test]
    fn auto_prefers_the_cpu_where_only_it_can_place_a_sphere() {
        let materials = "[materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n";
        // A unit sphere a million units out seen from 5 units: f32 places it to 0.12.
        let far = scene(&format!(
            "[camera]\neye = [1000000, 0, 6]\nlook_at = [1000000, 0, 0]\n{materials}\
             [[objects]]\ntype = \"sphere\"\ncenter = [1000000, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
        ));
        let h200 = adapter("NVIDIA H200", wgpu::DeviceType::DiscreteGpu);
        let reason = auto_rule(&h200, &far).expect("the CPU places it");
        assert!(
            reason.contains("radius 1e0") && reason.contains("f32"),
            "{reason}"
        );
        // A ground sphere of radius 1000 and a hopeless one (both backends) stay on the GPU.
        for (centre, radius) in [("-1000", "1000"), ("-1e20", "1e20")] {
            let ground = scene(&format!(
                "[camera]\neye = [0, 3, 4]\nlook_at = [0, 0, 0]\n{materials}\
                 [[objects]]\ntype = \"sphere\"\ncenter = [0, {centre}, 0]\nradius = {radius}\nmaterial = \"m\"\n"
            ));
            assert_eq!(auto_rule(&h200, &ground), None, "radius {radius}");
        }
    }

    #[test]
    fn auto_uses_real_gpus_and_cpu_devices_only_where_they_measured_faster() {
        let camera = "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n";
        let sphere =
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
        let spheres = scene(&format!(
            "{camera}[materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n{sphere}"
        ));
        let mut mesh = spheres.clone();
        mesh.meshes.push(gpu_render::scene::Mesh {
            name: "one triangle".into(),
            positions: vec![glam::DVec3::ZERO, glam::DVec3::X, glam::DVec3::Y],
            normals: None,
            uvs: None,
            uvs1: None,
            colors: None,
            tangents: None,
            triangles: vec![[0, 1, 2]],
            material: 0,
            instances: vec![glam::DMat4::IDENTITY],
        });
        let path = scene(&format!(
            "[render]\nintegrator = \"path\"\n{camera}[materials.m]\ntype = \"lambert\"\n\
             albedo = 0.5\n{sphere}"
        ));
        let mut large_path = path.clone();
        large_path
            .shapes
            .extend(std::iter::repeat_n(path.shapes[0].clone(), 100));
        large_path.meshes = mesh.meshes.clone();
        let scenes = [&spheres, &mesh, &path, &large_path];
        let lavapipe = |mesa: &str| wgpu::AdapterInfo {
            driver: "llvmpipe".into(),
            driver_info: format!("Mesa {mesa} (LLVM 15.0.6)"),
            ..adapter("llvmpipe (LLVM 15.0.6, 256 bits)", wgpu::DeviceType::Cpu)
        };
        let new = lavapipe("25.0.7");
        let old = lavapipe("22.3.6");
        for (i, scene) in scenes.into_iter().enumerate() {
            assert_eq!(auto_rule(&new, scene), None, "scene {i} on Mesa 25");
            let reason = auto_rule(&old, scene).expect("old llvmpipe is not used");
            assert!(
                reason.contains("llvmpipe") && reason.contains("every scene"),
                "{reason}"
            );
            for kind in [
                wgpu::DeviceType::DiscreteGpu,
                wgpu::DeviceType::IntegratedGpu,
                wgpu::DeviceType::VirtualGpu,
            ] {
                assert_eq!(
                    auto_rule(&adapter("NVIDIA H200", kind), scene),
                    None,
                    "scene {i}, {kind:?}"
                );
            }
        }
    }

    #[test]
    fn adapter_line_names_driver_and_features() {
        let info = wgpu::AdapterInfo {
            name: "NVIDIA H200".into(),
            driver: "NVIDIA".into(),
            driver_info: "570.133.20".into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Vulkan)
        };
        let features = wgpu::Features::SUBGROUP | wgpu::Features::TIMESTAMP_QUERY;
        assert_eq!(
            adapter_line(0, &info, features),
            "0: NVIDIA H200 (vulkan, DiscreteGpu, driver NVIDIA 570.133.20; SUBGROUP yes, \
             TIMESTAMP_QUERY yes, EXPERIMENTAL_RAY_QUERY no, PIPELINE_CACHE no)"
        );
        let bare = wgpu::AdapterInfo {
            name: "Some GPU".into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::Other, wgpu::Backend::Gl)
        };
        assert!(
            adapter_line(3, &bare, wgpu::Features::empty())
                .starts_with("3: Some GPU (gl, Other; SUBGROUP no,")
        );
    }
}
