//! The wgpu backend: tracing in WGSL compute shaders, driven from the host here.
//!
//! - The frame loop, for applications that own their device and frame
//!   (`docs/embedding.md`): [`Renderer`] (`frame_loop`), [`GpuScene`] (`gpu_scene`),
//!   [`Film`] (`film`), the draw pipeline (`draw`), the device [`limits`] it checks,
//!   and its error type [`RenderError`] (`render_error`).
//! - [`context`]: a headless instance/adapter/device/queue ([`HeadlessGpu`]) for apps
//!   and tests that do not bring their own device.
//! - [`renderer`]: [`GpuRenderer`], built from the caller's `Device`; a high-level
//!   [`GpuRenderer::render`] and `prepare`/`trace_into`/`encode_display` for apps that
//!   own their textures and frame.
//! - `scene_buffers`: a scene uploaded to the device ([`PreparedScene`]).
//! - `wavefront`: the path slots and the schedule of the two trace kernels.
//! - `pipelines`, `display`: the pipelines and the display pass.
//! - [`upload`]: pure conversion of a [`crate::scene::Scene`] into the GPU records.
//! - [`shaders`]: composition of the WGSL sources, specialised by [`features`];
//!   `uniform_records`: the scene records CPU devices read from uniform buffers;
//!   [`unrolled`]: small scenes' closest-hit test without the tree.
//! - [`layout`]: the `#[repr(C)]` records shared with `shaders/types.wgsl`.
//!
//! ```no_run
//! use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu};
//! # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::GpuError> {
//! let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
//! let renderer = GpuRenderer::new(&gpu.device)?;
//! let rendered = renderer.render(&gpu.device, &gpu.queue, scene, None)?;
//! println!("{} rays", rendered.stats.rays_traced);
//! # Ok(())
//! # }
//! ```

pub mod area_lights;
pub mod context;
mod display;
mod draw;
pub mod environment;
mod error;
pub mod features;
mod film;
mod frame_loop;
mod gpu_scene;
pub mod layout;
pub mod limits;
mod pipelines;
mod readback;
mod render_error;
pub mod renderer;
mod scene_buffers;
pub mod shaders;
mod uniform_records;
pub mod unrolled;
pub mod upload;
mod wavefront;

pub use context::{AdapterChoice, HeadlessGpu, adapter_listing, list_adapters, select_adapter};
pub use error::GpuError;
pub use features::ShaderFeatures;
pub use film::Film;
pub use frame_loop::{BufferWrites, FilmImage, Renderer, RendererOptions};
pub use gpu_scene::GpuScene;
pub use pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT, TRACE_STORAGE_BUFFERS, TracePipelines};
pub use readback::read_texture;
pub use render_error::RenderError;
pub use renderer::{GpuRendered, GpuRenderer, TraceRegion, image_tiles};
pub use scene_buffers::PreparedScene;
pub use wavefront::{
    LLVMPIPE_LOOP_LIMIT, Schedule, TARGET_SUBMISSION, default_schedule, default_slot_count,
    driver_loop_limit, iteration_budget_for,
};
