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
//!   `draw`, and [`limits`] (what the renderer needs of a device).
//! - [`shaders`]: composition of the WGSL sources, specialised by [`features`];
//!   [`upload`]: pure conversion of a [`crate::scene::Scene`] into the GPU records,
//!   [`layout`] their `#[repr(C)]` twins of `shaders/types.wgsl`.
//! - For CPU devices (lavapipe), strategies that only pay there: `uniform_records`
//!   (the scene records in uniform buffers), [`unrolled`] (small scenes' closest-hit
//!   test without the tree), and lanes that give way to finished ones
//!   ([`ShaderFeatures::refill_lanes`]).
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

pub mod area_lights;
pub mod context;
mod denoiser;
mod display;
mod draw;
pub mod environment;
mod error;
pub mod features;
mod film;
mod gpu_scene;
pub mod layout;
pub mod limits;
mod pipelines;
mod readback;
pub mod renderer;
mod scene_buffers;
pub mod shaders;
mod uniform_records;
pub mod unrolled;
pub mod upload;
mod wavefront;

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
pub use readback::read_texture;
pub use renderer::{
    BufferWrites, FilmImage, RenderedImage, Renderer, RendererOptions, TraceRegion, image_tiles,
};
pub use wavefront::{
    LLVMPIPE_LOOP_LIMIT, Schedule, TARGET_SUBMISSION, default_schedule, default_slot_count,
    driver_loop_limit, iteration_budget_for,
};
