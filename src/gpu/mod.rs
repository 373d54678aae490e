//! The wgpu backend: tracing in WGSL compute shaders, driven from the host here.
//!
//! - [`context`]: a headless instance/adapter/device/queue ([`HeadlessGpu`]) for apps
//!   and tests that do not bring their own device.
//! - [`renderer`]: [`GpuRenderer`], built from the caller's `Device`; a high-level
//!   [`GpuRenderer::render`] and low-level `prepare`/`encode_trace`/`encode_display`
//!   for apps that own their frame.
//! - [`upload`]: pure conversion of a [`crate::scene::Scene`] into the GPU records.
//! - [`shaders`]: composition of the WGSL sources, specialised by [`features`].
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

pub mod context;
mod error;
pub mod features;
pub mod layout;
mod readback;
pub mod renderer;
pub mod shaders;
pub mod upload;

pub use context::{AdapterChoice, HeadlessGpu, list_adapters};
pub use error::GpuError;
pub use features::ShaderFeatures;
pub use readback::read_texture;
pub use renderer::{GpuRendered, GpuRenderer, PreparedScene, TraceRegion, image_tiles};
