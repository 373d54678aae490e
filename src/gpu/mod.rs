//! The wgpu backend: tracing in WGSL compute shaders, driven from the host here.
//!
//! - [`Renderer`] (`renderer`): the one renderer, built from the caller's `Device`
//!   with [`RendererOptions`]; [`Renderer::upload`] makes a [`GpuScene`]; the frame
//!   loop records samples into a [`Film`] and shows it (`docs/embedding.md`); whole
//!   images and tiles are [`Renderer::render`], [`Renderer::render_region`] and
//!   [`Renderer::trace_into`]. Its one error type is [`RenderError`].
//! - [`HeadlessGpu`] (`context`): an instance, adapter, device and queue for programs
//!   and tests that do not bring their own device.
//! - The stages: `scene_buffers` (a scene uploaded to the device), `wavefront` (the
//!   path slots and the schedule of the trace kernels), `pipelines`, `display`,
//!   `draw`, `limits` (what the renderer needs of a device) and `ray_query` (the
//!   hardware traversal's acceleration structures, [`Traversal`]).
//! - `shaders`: composition of the WGSL sources, specialised by `features`;
//!   `upload`: pure conversion of a [`crate::scene::Scene`] into the GPU records,
//!   `layout` their `#[repr(C)]` twins of `shaders/types.wgsl` (these four public as
//!   [`crate::low_level::gpu`]).
//! - `cpu_device`: for CPU devices (lavapipe), the strategies that only pay there:
//!   the scene records in uniform buffers, small scenes' closest-hit test without the
//!   tree, and the BVH nodes of larger scenes in a texture. (Lanes that give way to
//!   finished ones, [`ShaderFeatures::refill_lanes`], are off unless asked for;
//!   Whitted samples that start in lockstep across a subgroup,
//!   [`ShaderFeatures::lockstep_samples`], are on wherever the device has subgroup
//!   operations.)
//!
//! ```no_run
//! use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions};
//! # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::RenderError> {
//! let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
//! let renderer = Renderer::new(&gpu.device, RendererOptions::default())?;
//! let rendered = renderer.render(&gpu.device, &gpu.queue, scene, None)?;
//! println!("{} rays", rendered.stats.rays_traced);
//! # Ok(())
//! # }
//! ```

pub(crate) mod area_lights;
mod context;
pub(crate) mod cpu_device;
mod denoiser;
mod display;
mod draw;
pub(crate) mod environment;
mod error;
pub(crate) mod features;
mod film;
mod gpu_scene;
pub(crate) mod layout;
mod limits;
mod pipelines;
pub(crate) mod ray_query;
mod readback;
mod renderer;
mod scene_buffers;
pub(crate) mod shaders;
pub(crate) mod upload;
mod wavefront;

/// The denoiser's settings and the auxiliary passes that guide it, which the frame
/// loop's denoising calls take and return (the filter itself: `low_level::denoise`).
pub use crate::denoise::{DenoiseSettings, GuidePasses};
pub use context::{
    AdapterChoice, HeadlessGpu, adapter_listing, list_adapters, list_adapters_with_features,
    select_adapter,
};
pub use denoiser::MAX_DENOISE_ITERATIONS;
pub use error::{RenderError, TraceFailure};
pub use features::ShaderFeatures;
pub use film::Film;
pub use gpu_scene::GpuScene;
pub use pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT, TRACE_STORAGE_BUFFERS, TracePipelines};
pub use ray_query::{Traversal, hardware_traversal_available, ray_query_features};
pub use readback::read_texture;
pub use renderer::{
    BufferWrites, FilmImage, RenderedImage, Renderer, RendererOptions, TraceRegion, image_tiles,
};
pub use wavefront::{
    CPU_SLOTS_PER_THREAD, KernelCompile, LLVMPIPE_LOOP_LIMIT, Schedule, TARGET_SUBMISSION,
    default_schedule, default_slot_count, driver_loop_limit, iteration_budget_for,
};
