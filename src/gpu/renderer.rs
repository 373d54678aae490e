//! [`GpuRenderer`]: the public face of the GPU backend, built from the caller's device.
//!
//! - [`GpuRenderer::prepare`] uploads a scene ([`PreparedScene`]);
//! - [`GpuRenderer::trace_into`] traces one region of it into the caller's
//!   `Rgba32Float` texture, blocking until every pixel is done;
//! - [`GpuRenderer::encode_display`] records the sRGB display pass into the caller's
//!   encoder;
//! - the conveniences [`GpuRenderer::render`] (tiles, display pass, readback),
//!   [`GpuRenderer::render_region`] (the same for a window of the image) and
//!   [`GpuRenderer::render_to_texture`] are built on these.
//!
//! The conveniences live in `renderer/blocking.rs`; the stages they are built on
//! (upload, trace, display) here.
//!
//! The renderer owns no device: every method takes the device (and queue where it
//! submits), so an app can embed the tracer in its own program.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use super::GpuError;
use super::display::{check_texture, encode_display};
use super::features::ShaderFeatures;
use super::pipelines::{LINEAR_FORMAT, Pipelines, TRACE_STORAGE_BUFFERS, TracePipelines};
use super::readback::{Caught, capture};
use super::scene_buffers::{PreparedScene, UploadOptions, upload_scene};
use super::wavefront::{
    Schedule, SlotBuffers, default_schedule, iteration_budget_for, trace_region,
};
use crate::accel::SceneGeometry;
use crate::film::RenderStats;
use crate::noise::NoiseEstimate;
use crate::scene::Scene;

mod blocking;
pub use blocking::{GpuRendered, image_tiles};

/// The GPU tracer's pipelines and options, built for one device.
///
/// ```no_run
/// use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu};
/// # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::GpuError> {
/// let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
/// let renderer = GpuRenderer::new(&gpu.device)?;
/// let progress = |done: u32, total: u32| eprintln!("{done}/{total} rows");
/// let out = renderer.render(&gpu.device, &gpu.queue, scene, Some(&progress))?;
/// assert_eq!(out.display_rgba8.len(), out.image.pixels.len() * 4);
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct GpuRenderer {
    pipelines: Pipelines,
    poll_timeout: Option<Duration>,
    specialise: bool,
    uniform_records: bool,
    refill_lanes: bool,
    unrolled: bool,
    iteration_budget: Option<u32>,
    slot_count: Option<u32>,
    schedule: Option<Schedule>,
    simulate_loop_cut: bool,
    noise_estimate: bool,
}

/// A rectangle of image pixels traced into one target texture, and where it lands
/// there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TraceRegion {
    /// Image columns traced.
    pub columns: Range<u32>,
    /// Image rows traced.
    pub rows: Range<u32>,
    /// The image pixel stored at texel (0, 0) of the target.
    pub target_origin: (u32, u32),
}

impl TraceRegion {
    /// The whole image of `width × height`, stored at the target's origin.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            columns: 0..width,
            rows: 0..height,
            target_origin: (0, 0),
        }
    }

    fn size(&self) -> (u32, u32) {
        (
            self.columns.end.saturating_sub(self.columns.start),
            self.rows.end.saturating_sub(self.rows.start),
        )
    }
}

impl GpuRenderer {
    /// Builds the bind group layouts and the display pipeline on `device`; trace
    /// pipelines are built on first use for each feature set.
    ///
    /// Errors: [`GpuError::DeviceLimit`] if the device binds fewer storage buffers per
    /// shader stage than the trace kernels need ([`GpuRenderer::required_limits`]),
    /// [`GpuError::Shader`] if the display shader fails to compile.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        let limits = device.limits();
        if limits.max_storage_buffers_per_shader_stage < TRACE_STORAGE_BUFFERS {
            return Err(GpuError::DeviceLimit {
                what: "storage buffers per shader stage the trace kernels bind (request \
                       GpuRenderer::required_limits when creating the device)"
                    .into(),
                value: u64::from(TRACE_STORAGE_BUFFERS),
                limit: u64::from(limits.max_storage_buffers_per_shader_stage),
            });
        }
        Ok(Self {
            pipelines: Pipelines::new(device)?,
            poll_timeout: None,
            specialise: true,
            uniform_records: true,
            refill_lanes: true,
            unrolled: true,
            iteration_budget: None,
            slot_count: None,
            schedule: None,
            simulate_loop_cut: false,
            noise_estimate: false,
        })
    }

    /// The limits a device needs for this renderer: `adapter_limits` (what the adapter
    /// offers, so large scenes and images fit) raised to the minimums of
    /// [`super::limits::required_limits`] (the storage buffers per shader stage the
    /// trace kernels bind among them).
    pub fn required_limits(adapter_limits: &wgpu::Limits) -> wgpu::Limits {
        super::limits::required_limits(adapter_limits)
    }

    /// The features to request when creating a device for this renderer, where the
    /// adapter has them ([`super::limits::optional_features`]).
    pub fn optional_features(adapter_features: wgpu::Features) -> wgpu::Features {
        super::limits::optional_features(adapter_features)
    }

    /// Bounds every wait for the GPU (one submission of trace rounds, the display
    /// pass, one readback) by `timeout`, after which [`GpuError::DeviceLost`] is
    /// reported instead of waiting on. By default waits are unbounded: each
    /// submission's work is bounded by design, and a real device that hangs is reset
    /// by its driver and reported lost.
    pub fn with_poll_timeout(mut self, timeout: Duration) -> Self {
        self.poll_timeout = Some(timeout);
        self
    }

    /// With `false`, every trace module contains every feature (the general shader)
    /// instead of only what each scene uses. For measurements and tests; the default,
    /// `true`, is faster to run and to compile.
    pub fn with_specialisation(mut self, specialise: bool) -> Self {
        self.specialise = specialise;
        self
    }

    /// With `false`, scenes keep their records in storage buffers on every device,
    /// instead of uniform buffers where they fit on CPU devices (see
    /// [`ShaderFeatures::uniform_records`]). For measurements and tests; the image is
    /// the same.
    pub fn with_uniform_records(mut self, uniform_records: bool) -> Self {
        self.uniform_records = uniform_records;
        self
    }

    /// With `false`, the fused kernel's traversals never give way to lanes whose rays
    /// finished, even where the device has subgroup operations (see
    /// [`ShaderFeatures::refill_lanes`]). For measurements and tests; the image is the
    /// same.
    pub fn with_refill_lanes(mut self, refill_lanes: bool) -> Self {
        self.refill_lanes = refill_lanes;
        self
    }

    /// With `false`, small scenes are traced through their BVH like any other, instead
    /// of with their closest-hit test unrolled on CPU devices (see
    /// [`ShaderFeatures::unrolled`]). For measurements and tests; the image is the same.
    pub fn with_unrolled_primitives(mut self, unrolled: bool) -> Self {
        self.unrolled = unrolled;
        self
    }

    /// Sets the most loop iterations one invocation runs per dispatch (at least 1),
    /// instead of the adapter's ([`super::iteration_budget_for`]). Smaller budgets only
    /// split the same work into more dispatches: the image does not change.
    pub fn with_iteration_budget(mut self, budget: u32) -> Self {
        self.iteration_budget = Some(budget.max(1));
        self
    }

    /// Sets the number of path slots (invocations per dispatch) of each trace instead
    /// of the adapter's default ([`super::default_slot_count`]). The image does not
    /// depend on it.
    pub fn with_slot_count(mut self, slots: u32) -> Self {
        self.slot_count = Some(slots.max(1));
        self
    }

    /// Sets how the trace kernels are dispatched instead of the adapter's default
    /// ([`super::default_schedule`]). The image does not depend on it.
    pub fn with_schedule(mut self, schedule: Schedule) -> Self {
        self.schedule = Some(schedule);
        self
    }

    /// For tests of the safety net: with `true`, every traversal leaves its loop early
    /// without reaching an exit, as when a driver cuts loops (llvmpipe before Mesa 25:
    /// [`super::driver_loop_limit`]), so that the kernels report it and every render
    /// fails with [`GpuError::TraceIncomplete`] instead of returning a short image.
    pub fn with_simulated_loop_cut(mut self, simulate: bool) -> Self {
        self.simulate_loop_cut = simulate;
        self
    }

    /// With `true`, [`GpuRenderer::render`] and [`GpuRenderer::render_region`] also
    /// return each pixel's noise estimate ([`GpuRendered::noise`]): the trace keeps
    /// every pixel's sample sum and luminance m2 in an accumulation buffer of 16 bytes
    /// per pixel of the tile (whatever the sample count) and reads it back. The image
    /// does not change.
    pub fn with_noise_estimate(mut self, estimate: bool) -> Self {
        self.noise_estimate = estimate;
        self
    }

    /// The schedule this renderer uses on `device`.
    pub fn schedule(&self, device: &wgpu::Device) -> Schedule {
        self.schedule
            .unwrap_or_else(|| default_schedule(&device.adapter_info()))
    }

    /// The iteration budget this renderer uses on `device`.
    pub fn iteration_budget(&self, device: &wgpu::Device) -> u32 {
        self.iteration_budget
            .unwrap_or_else(|| iteration_budget_for(&device.adapter_info()))
    }

    /// The trace pipelines for `features`, built and cached on first use (prepared
    /// scenes carry their features: [`PreparedScene::features`]).
    ///
    /// Errors: [`GpuError::Shader`] if the composed trace shader does not compile.
    pub fn trace_pipelines(
        &self,
        device: &wgpu::Device,
        features: &ShaderFeatures,
    ) -> Result<TracePipelines, GpuError> {
        self.pipelines.trace(device, features)
    }

    /// How many trace modules have been built and cached so far.
    pub fn cached_pipeline_count(&self) -> usize {
        self.pipelines.cached_trace_count()
    }

    /// Builds `scene`'s geometry and BVH and uploads it (converted with
    /// [`Scene::in_lighting_space`] here, so pass the scene as loaded).
    ///
    /// Errors: [`GpuError::DeviceLimit`] if a buffer exceeds the device's limits,
    /// [`GpuError::OutOfMemory`] if an allocation fails, [`GpuError::Validation`] if
    /// the render settings are out of range.
    pub fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
    ) -> Result<PreparedScene, GpuError> {
        self.prepare_with_geometry(device, queue, scene, &SceneGeometry::new(scene))
    }

    /// [`GpuRenderer::prepare`] with geometry already built from `scene` (for example
    /// the one the CPU reference traces, so that both use the same tree).
    pub fn prepare_with_geometry(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        geometry: &SceneGeometry,
    ) -> Result<PreparedScene, GpuError> {
        upload_scene(
            device,
            queue,
            scene,
            geometry,
            UploadOptions {
                specialise: self.specialise,
                allow_uniform_records: self.uniform_records,
                allow_refill_lanes: self.refill_lanes,
                allow_unrolled: self.unrolled,
            },
        )
    }

    /// Traces the pixels of `region` of `prepared` into `target` (an `Rgba32Float`
    /// texture with `STORAGE_BINDING`, holding at least the region from
    /// `region.target_origin` on), every sample of every pixel, blocking until done.
    /// `progress(pixels_done, region_pixels)` is called after each submission.
    ///
    /// Errors: [`GpuError::Validation`] for a region outside the image or an unsuitable
    /// target; [`GpuError::TraceIncomplete`] if the kernels report a loop the driver
    /// cut short (the image is then not returned); [`GpuError::DeviceLost`];
    /// [`GpuError::Shader`] if the pipelines cannot be built.
    pub fn trace_into(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        progress: Option<&dyn Fn(u64, u64)>,
    ) -> Result<RenderStats, GpuError> {
        self.trace_region_into(device, queue, prepared, target, region, progress, false)
            .map(|(stats, _)| stats)
    }

    /// [`GpuRenderer::trace_into`], and with `noise` the region's noise estimate.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn trace_region_into(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        progress: Option<&dyn Fn(u64, u64)>,
        noise: bool,
    ) -> Result<(RenderStats, Option<NoiseEstimate>), GpuError> {
        let (width, height) = region.size();
        if region.columns.end > prepared.width() || region.rows.end > prepared.height() {
            return Err(GpuError::Validation(format!(
                "region {:?} x {:?} lies outside the {}x{} image",
                region.columns,
                region.rows,
                prepared.width(),
                prepared.height()
            )));
        }
        let (origin_x, origin_y) = region.target_origin;
        if origin_x > region.columns.start || origin_y > region.rows.start {
            return Err(GpuError::Validation(format!(
                "target origin ({origin_x}, {origin_y}) lies after the region's first pixel \
                 ({}, {})",
                region.columns.start, region.rows.start
            )));
        }
        let pixels = u64::from(width) * u64::from(height);
        if pixels == 0 {
            return Ok((RenderStats::default(), None));
        }
        check_texture(
            target,
            "trace target",
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
            region.columns.end - origin_x,
            region.rows.end - origin_y,
        )?;
        // Compile before the clock starts: pipeline creation is not tracing.
        let pipelines = self.trace_pipelines(device, &prepared.features)?;
        let slot_count =
            SlotBuffers::slot_count(device, self.slot_count, pixels, prepared.stack_size);
        // The sums are kept only for the noise estimate (16 bytes per region pixel).
        let sums = if noise { pixels } else { 0 };
        let slots = SlotBuffers::new(device, slot_count, prepared.stack_size, sums)?;
        let bind_group = slots.bind_group(
            device,
            self.pipelines.trace_bind_group_layout(&prepared.features),
            prepared,
            target,
        )?;
        let frame = super::layout::FrameUniforms {
            region_x: region.columns.start,
            region_y: region.rows.start,
            region_width: width,
            region_height: height,
            target_x: origin_x,
            target_y: origin_y,
            first_sample: 0,
            end_sample: prepared.samples_per_pixel(),
            slot_count,
            iteration_budget: self.iteration_budget(device),
            // The scene's own flags (its integrator) and the test switch.
            flags: prepared.frame.flags
                | if self.simulate_loop_cut {
                    super::layout::FLAG_SIMULATE_LOOP_CUT
                } else {
                    0
                }
                | if noise {
                    super::layout::FLAG_STORE_SUM
                } else {
                    0
                },
            ..prepared.frame
        };
        let done = AtomicU64::new(0);
        let report = |new: u64| {
            let total = done.fetch_add(new, Ordering::Relaxed) + new;
            if let Some(progress) = progress {
                progress(total, pixels);
            }
        };
        let outcome = trace_region(
            device,
            queue,
            &pipelines,
            self.schedule(device),
            &slots,
            &bind_group,
            &frame,
            self.poll_timeout,
            &report,
        )?;
        let stats = RenderStats {
            rays_traced: outcome.rays,
            elapsed: outcome.elapsed,
            gpu_time: outcome.gpu_time,
        };
        let estimate = if noise {
            Some(slots.read_noise(
                device,
                queue,
                (width, height),
                prepared.samples_per_pixel(),
                self.poll_timeout,
            )?)
        } else {
            None
        };
        Ok((stats, estimate))
    }

    /// Records the display pass into `encoder`: reads `linear` (an `Rgba32Float`
    /// texture with `TEXTURE_BINDING`), applies the exact sRGB curve if `encode_srgb`
    /// (else clamps only; take it from [`PreparedScene::display_encodes_srgb`]),
    /// quantises to 8 bits and writes `display` (an `Rgba8Unorm` texture with
    /// `STORAGE_BINDING` of the same size).
    ///
    /// Errors: [`GpuError::Validation`] for unsuitable textures.
    pub fn encode_display(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        linear: &wgpu::TextureView,
        display: &wgpu::TextureView,
        encode_srgb: bool,
    ) -> Result<(), GpuError> {
        encode_display(
            &self.pipelines,
            device,
            encoder,
            linear,
            display,
            encode_srgb,
        )
    }
}

/// Creates a 2D texture inside error scopes (allocation failure becomes
/// [`GpuError::OutOfMemory`]).
pub(crate) fn create_texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Result<wgpu::Texture, GpuError> {
    capture(device, label, Caught::Resource, || {
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
    })
}
