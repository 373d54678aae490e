//! [`Renderer`]: the one public face of the GPU backend, in the shape of vello's and
//! glyphon's renderers. The application owns the instance, adapter, device, queue,
//! encoder and frame; the renderer is built for one device and takes the device (and
//! queue where it submits) in every call.
//!
//! - Set-up and scenes, here: [`Renderer::new`], the device needs
//!   ([`Renderer::required_limits`], [`Renderer::optional_features`]),
//!   [`Renderer::upload`] (a [`GpuScene`]: buffers, images and the trace pipelines
//!   specialised to it), [`Renderer::set_camera`], [`Renderer::create_film`].
//! - The frame loop (`frame_loop`): [`Renderer::encode_samples`] records samples into a
//!   [`super::Film`] without blocking, [`Renderer::encode_display`] and
//!   [`Renderer::draw`] show it; `docs/embedding.md` walks through it.
//! - Whole images and tiles (`blocking`): [`Renderer::render`],
//!   [`Renderer::render_region`], [`Renderer::render_to_texture`] and
//!   [`Renderer::trace_into`] trace every sample and wait, for programs (the CLI,
//!   tests) that want an image rather than a frame loop. The CLI and the viewer run
//!   through these same calls.

use std::time::{Duration, Instant};

use super::denoiser::DenoisePipelines;
use super::draw::DrawPipelines;
use super::film::Film;
use super::gpu_scene::GpuScene;
use super::limits::{check_limits, required_limits};
use super::pipelines::{Pipelines, TracePipelines};
use super::scene_buffers::{HardwarePlan, UploadOptions, hardware_plan, upload_scene};
use super::wavefront::{Schedule, default_schedule, iteration_budget_for, warm_up};
use super::{RenderError, ShaderFeatures, Traversal};
use crate::accel::{BuildMethod, SceneGeometry};
use crate::scene::{Camera, Scene, view_problem};

mod blocking;
mod denoising;
mod frame_loop;

pub use blocking::{RenderedImage, TraceRegion, image_tiles};
pub use frame_loop::{BufferWrites, FilmImage};

/// How a [`Renderer`] is built. Every field but `surface_format` only trades speed,
/// memory or waiting: the image does not depend on them.
#[derive(Debug, Clone)]
pub struct RendererOptions {
    /// The colour format of the attachments [`Renderer::draw`] renders into (for
    /// example the swapchain's `Bgra8UnormSrgb`); `None` builds no draw pipeline.
    pub surface_format: Option<wgpu::TextureFormat>,
    /// How the trace kernels are dispatched; `None`: the adapter's default
    /// ([`super::default_schedule`]).
    pub schedule: Option<Schedule>,
    /// Path slots (invocations per dispatch) per film or trace; `None`: the adapter's
    /// default ([`super::default_slot_count`]).
    pub slot_count: Option<u32>,
    /// Loop iterations per invocation and dispatch (at least 1); `None`: the adapter's
    /// ([`super::iteration_budget_for`]). Smaller budgets split the same work into
    /// more dispatches.
    pub iteration_budget: Option<u32>,
    /// Most rounds of the trace kernels one [`Renderer::encode_samples`] records:
    /// bounds the GPU time one call adds to a frame.
    pub max_rounds_per_call: u32,
    /// Bounds every wait of the blocking calls (one submission of trace rounds, the
    /// display pass, one readback); past it [`RenderError::Timeout`] is reported
    /// instead of waiting on. `None`: waits are unbounded (each submission's work is
    /// bounded by design, and a real device that hangs is reset by its driver and
    /// reported lost).
    pub poll_timeout: Option<Duration>,
    /// With `true`, [`Renderer::render`] and [`Renderer::render_region`] also return
    /// each pixel's noise estimate ([`RenderedImage::noise`]): the trace keeps every
    /// pixel's sample sum and luminance m2 (16 bytes per pixel of the tile) and reads
    /// them back. Films always keep them.
    pub noise_estimate: bool,
    /// With `true`, uploaded scenes' trace modules can record the auxiliary passes of
    /// the camera rays' first hits (`shaders/aov.wgsl` and its CPU twin set out the
    /// conventions: albedo, shading normal, depth); [`Renderer::render`] and
    /// [`Renderer::render_region`] then return them ([`RenderedImage::aov`]; 32 more
    /// bytes per pixel of the tile), and films keep them beside their sums
    /// ([`Renderer::read_aov`], the denoiser's guides).
    pub aov: bool,
    /// Trace shaders specialised to each scene's features (`true`, faster to run and
    /// to compile) or the general shader.
    pub specialise: bool,
    /// On CPU devices, bind the records of scenes small enough as uniform buffers
    /// (see [`ShaderFeatures::uniform_records`]) and read the BVH nodes of larger
    /// ones from a texture (see [`ShaderFeatures::node_texture`]) (`true`, faster
    /// there), or always read the records from storage buffers.
    pub uniform_records: bool,
    /// Where the device has subgroup operations, let the fused kernel's traversals
    /// give way to lanes whose rays finished (see [`ShaderFeatures::refill_lanes`]).
    /// `false` by default: on lavapipe the kernel without it traced meshes 10-15%
    /// faster and the unrolled showcase 5% faster (`BENCHMARKS.md`, "Lane refill
    /// off by default"); GPUs' default schedule, the wavefront, never gives way.
    pub refill_lanes: bool,
    /// Where the device has subgroup operations, let the fused kernel's Whitted
    /// samples start in lockstep across a subgroup (see
    /// [`ShaderFeatures::lockstep_samples`]). `true` by default: on lavapipe it traced
    /// the bunny 20% faster and the showcase 9% (`BENCHMARKS.md`, "Samples in
    /// lockstep"); the image is the same either way.
    pub lockstep_samples: bool,
    /// On CPU devices, test the primitives of scenes small enough unrolled instead of
    /// walking their BVH (`true`, faster there; see [`ShaderFeatures::unrolled`]).
    pub unrolled: bool,
    /// How the scene's triangles are found: the software walk of the wide BVH, or
    /// the device's ray queries ([`ShaderFeatures::hardware_traversal`]), which need
    /// a device created with [`wgpu::Features::EXPERIMENTAL_RAY_QUERY`] and, as wgpu
    /// requires of that feature, its experimental features enabled
    /// ([`super::ray_query_features`] says what to request; [`super::HeadlessGpu`] and
    /// the viewer request it where the adapter offers it). [`Traversal::Auto`] (the default)
    /// takes the hardware path where it exists and pays; the image differs only where
    /// the hardware's triangle test and ours differ (`docs/model.md`, "Hardware
    /// traversal").
    pub traversal: Traversal,
    /// For tests of the safety net: every traversal leaves its loop early without
    /// reaching an exit, as when a driver cuts loops (llvmpipe before Mesa 25:
    /// [`super::driver_loop_limit`]), so that the kernels report it and every trace
    /// fails with [`RenderError::TraceIncomplete`] instead of returning a short image.
    pub simulate_loop_cut: bool,
    /// A driver cache of compiled pipelines (`wgpu::Device::create_pipeline_cache`, on
    /// devices with [`wgpu::Features::PIPELINE_CACHE`]) that every pipeline of the
    /// renderer is built through: created from the data an earlier run saved
    /// ([`wgpu::PipelineCache::get_data`]), it spares recompiling the kernels. The
    /// application owns the cache and saves its data; `None` builds without one.
    pub pipeline_cache: Option<wgpu::PipelineCache>,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self {
            surface_format: None,
            schedule: None,
            slot_count: None,
            iteration_budget: None,
            max_rounds_per_call: 64,
            poll_timeout: None,
            noise_estimate: false,
            aov: false,
            specialise: true,
            uniform_records: true,
            refill_lanes: false,
            lockstep_samples: true,
            unrolled: true,
            traversal: Traversal::Auto,
            simulate_loop_cut: false,
            pipeline_cache: None,
        }
    }
}

/// The renderer, built for one device: the bind group layouts, the display pipeline,
/// the draw pipelines (with a surface format) and a cache of trace pipelines, which
/// [`Renderer::upload`] builds for each scene's features.
///
/// A frame loop (the application owns the device, the encoder and the frame):
///
/// ```no_run
/// use gpu_render::gpu::{Renderer, RendererOptions};
/// # fn frame_loop(adapter: &wgpu::Adapter, scene: &gpu_render::scene::Scene,
/// #               mut camera_for_frame: impl FnMut(u32) -> Option<gpu_render::scene::Camera>)
/// #               -> Result<(), Box<dyn std::error::Error>> {
/// let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
///     required_limits: Renderer::required_limits(&adapter.limits()),
///     required_features: Renderer::optional_features(adapter.features()),
///     ..Default::default()
/// }))?;
/// let renderer = Renderer::new(&device, RendererOptions::default())?;
/// let mut gpu_scene = renderer.upload(&device, &queue, scene)?;
/// let mut film = renderer.create_film(&device, &gpu_scene, 640, 360)?;
/// for frame in 0..100 {
///     if let Some(camera) = camera_for_frame(frame) {
///         renderer.set_camera(&mut gpu_scene, &camera)?; // the film restarts by itself
///     }
///     let mut encoder = device.create_command_encoder(&Default::default());
///     renderer.encode_samples(&device, &queue, &mut encoder, &gpu_scene, &mut film, 1)?;
///     // ... renderer.draw(&mut render_pass, &gpu_scene, &film) into the swapchain ...
///     queue.submit([encoder.finish()]);
/// }
/// # Ok(())
/// # }
/// ```
///
/// A whole image, blocking:
///
/// ```no_run
/// use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions};
/// # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::RenderError> {
/// let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
/// let renderer = Renderer::new(&gpu.device, RendererOptions::default())?;
/// let progress = |done: u32, total: u32| eprintln!("{done}/{total} rows");
/// let out = renderer.render(&gpu.device, &gpu.queue, scene, Some(&progress))?;
/// assert_eq!(out.display_rgba8.len(), out.image.pixels.len() * 4);
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct Renderer {
    pipelines: Pipelines,
    /// The denoiser's kernels, with [`RendererOptions::aov`].
    denoise: Option<DenoisePipelines>,
    draw: Option<DrawPipelines>,
    options: RendererOptions,
    schedule: Schedule,
    iteration_budget: u32,
}

impl Renderer {
    /// Checks `device`'s limits, then builds the layouts, the display pipeline and,
    /// with [`RendererOptions::surface_format`], the draw pipelines.
    ///
    /// Errors: [`RenderError::Limit`] naming the first limit the device has too little
    /// of (a device made with `wgpu::Limits::default()` binds 8 storage buffers per
    /// stage, the trace kernels 16): request [`Renderer::required_limits`].
    /// [`RenderError::Shader`] if a pipeline fails to build.
    pub fn new(device: &wgpu::Device, options: RendererOptions) -> Result<Self, RenderError> {
        check_limits(&device.limits())?;
        let pipelines = Pipelines::new(device, options.pipeline_cache.clone())?;
        let draw = options
            .surface_format
            .map(|format| DrawPipelines::new(device, format))
            .transpose()?;
        let denoise = options
            .aov
            .then(|| DenoisePipelines::new(device, options.pipeline_cache.as_ref()))
            .transpose()?;
        let adapter = device.adapter_info();
        Ok(Self {
            pipelines,
            denoise,
            draw,
            schedule: options
                .schedule
                .unwrap_or_else(|| default_schedule(&adapter)),
            iteration_budget: options
                .iteration_budget
                .unwrap_or_else(|| iteration_budget_for(&adapter))
                .max(1),
            options,
        })
    }

    /// The limits to request when creating a device for the renderer:
    /// `adapter_limits` raised to the renderer's minimums (`gpu::limits`).
    pub fn required_limits(adapter_limits: &wgpu::Limits) -> wgpu::Limits {
        required_limits(adapter_limits)
    }

    /// The features to request when creating a device for the renderer, where the
    /// adapter has them (`gpu::limits::optional_features`): the renderer runs
    /// without them, only slower.
    pub fn optional_features(adapter_features: wgpu::Features) -> wgpu::Features {
        super::limits::optional_features(adapter_features)
    }

    /// The options the renderer was built with.
    pub fn options(&self) -> &RendererOptions {
        &self.options
    }

    /// How the trace kernels are dispatched on this renderer's device.
    pub fn schedule(&self) -> Schedule {
        self.schedule
    }

    /// The loop iterations per invocation and dispatch on this renderer's device.
    pub fn iteration_budget(&self) -> u32 {
        self.iteration_budget
    }

    /// How many trace modules have been built and cached so far (each distinct set of
    /// scene features compiles one).
    pub fn cached_pipeline_count(&self) -> usize {
        self.pipelines.cached_trace_count()
    }

    /// The trace pipelines of this renderer's schedule for `features`, built and
    /// cached on first use (uploaded scenes carry their features:
    /// [`GpuScene::features`]). For measurements of the compile time;
    /// [`Renderer::upload`] builds what a scene needs.
    ///
    /// Errors: [`RenderError::Shader`] if the composed trace shader does not compile.
    pub fn trace_pipelines(
        &self,
        device: &wgpu::Device,
        features: &ShaderFeatures,
    ) -> Result<TracePipelines, RenderError> {
        self.pipelines.trace(device, features, self.schedule)
    }

    /// The bind group layout of the draw pipelines, if any.
    pub(crate) fn draw_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.draw.as_ref().map(|draw| &draw.layout)
    }

    /// Builds `scene`'s geometry and BVH, uploads its buffers and images, and builds
    /// the trace pipelines specialised to it, dispatching each once over no work so
    /// that drivers which compile at the first dispatch compile now: no later call
    /// compiles anything ([`GpuScene::compile_time`] says how long that took). Pass the scene
    /// as loaded: it is converted to its lighting space here.
    ///
    /// Errors: [`RenderError::InvalidSettings`] for invalid render settings,
    /// [`RenderError::SceneTooLarge`] for a scene larger than the device holds,
    /// [`RenderError::OutOfMemory`] or [`RenderError::Shader`] if an allocation or
    /// pipeline fails.
    pub fn upload(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
    ) -> Result<GpuScene, RenderError> {
        // The hardware traversal walks a tree of the analytic shapes alone: the
        // scene's tree (over every triangle) is built only for the software walk.
        let mut geometry = SceneGeometry::without_scene_tree(scene, BuildMethod::Sah);
        let plan = hardware_plan(self.options.traversal, device, &geometry)?;
        if plan.is_none() {
            geometry.build_scene_tree(BuildMethod::Sah);
        }
        self.upload_planned(device, queue, scene, &geometry, plan)
    }

    /// [`Renderer::upload`] with geometry already built from `scene` (for example the
    /// one the CPU reference traces, so that both use the same tree).
    pub fn upload_with_geometry(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        geometry: &SceneGeometry,
    ) -> Result<GpuScene, RenderError> {
        let plan = hardware_plan(self.options.traversal, device, geometry)?;
        self.upload_planned(device, queue, scene, geometry, plan)
    }

    /// The uploads of [`Renderer::upload`] and [`Renderer::upload_with_geometry`],
    /// with the traversal planned ([`hardware_plan`]).
    fn upload_planned(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        geometry: &SceneGeometry,
        plan: Option<HardwarePlan>,
    ) -> Result<GpuScene, RenderError> {
        let prepared = upload_scene(
            device,
            queue,
            scene,
            geometry,
            UploadOptions {
                specialise: self.options.specialise,
                allow_uniform_records: self.options.uniform_records,
                allow_refill_lanes: self.options.refill_lanes,
                allow_lockstep_samples: self.options.lockstep_samples,
                allow_unrolled: self.options.unrolled,
                aov: self.options.aov,
            },
            plan,
            &self.pipelines.node_texels_placeholder,
        )?;
        let cached = self.pipelines.has_trace(&prepared.features, self.schedule);
        let started = Instant::now();
        let pipelines = self
            .pipelines
            .trace(device, &prepared.features, self.schedule)?;
        let mut kernels = Vec::new();
        if !cached {
            let layout = self.pipelines.trace_bind_group_layout(&prepared.features);
            kernels = warm_up(
                device,
                queue,
                &pipelines,
                layout,
                &prepared,
                self.options.poll_timeout,
            )?;
        }
        let compile_time = started.elapsed();
        let mut scene = GpuScene::new(
            device,
            prepared,
            pipelines,
            compile_time,
            scene.camera,
            scene.dielectric_spheres(),
        );
        scene.kernel_compiles = kernels;
        Ok(scene)
    }

    /// Moves `scene`'s camera. Writes nothing to the device: the next trace pass of
    /// each film (or the next blocking trace) writes the camera with the pass's other
    /// constants (one 208-byte uniform record), and a film accumulating the old camera
    /// restarts at sample 0 in its next [`Renderer::encode_samples`]. No scene buffer
    /// is touched.
    ///
    /// Errors: [`RenderError::InvalidCamera`] for an undefined view, a field of view
    /// outside (0, 180) degrees, or a thin lens with an aperture or focus distance that
    /// is not finite and positive or on an orthographic camera (the scene keeps its
    /// camera).
    pub fn set_camera(&self, scene: &mut GpuScene, camera: &Camera) -> Result<(), RenderError> {
        let fov_ok = camera.fov_y_degrees > 0.0 && camera.fov_y_degrees < 180.0;
        let lens_ok = camera.lens.is_none_or(|lens| {
            lens.problem().is_none() && camera.orthographic_half_height.is_none()
        });
        if !fov_ok || !lens_ok || view_problem(camera.eye, camera.look_at, camera.up).is_some() {
            return Err(RenderError::InvalidCamera(*camera));
        }
        if scene.camera != *camera {
            scene.camera = *camera;
            scene.camera_version += 1;
        }
        Ok(())
    }

    /// Creates a film of `width × height` pixels for `scene` (and any other scene
    /// whose `stack_size` is at most `scene`'s), with its path slots.
    ///
    /// Errors: [`RenderError::Limit`] for a film the device cannot hold (texture side,
    /// bytes of the per-pixel sums); [`RenderError::OutOfMemory`] if an allocation
    /// fails.
    pub fn create_film(
        &self,
        device: &wgpu::Device,
        scene: &GpuScene,
        width: u32,
        height: u32,
    ) -> Result<Film, RenderError> {
        let mut film = Film::new(
            device,
            self.draw_layout(),
            self.options.slot_count,
            scene.prepared.stack_size,
            self.options.aov,
            width,
            height,
        )?;
        let bind_group = film.slots.bind_group(
            device,
            self.pipelines
                .trace_bind_group_layout(&scene.prepared.features),
            &scene.prepared,
            &film.view,
        )?;
        film.binding = Some((scene.id, bind_group));
        Ok(film)
    }
}
