//! The wgpu backend (being written).
//!
//! - [`upload`]: pure conversion of a [`crate::scene::Scene`] into the GPU records.
//! - [`layout`]: the `#[repr(C)]` records shared with `shaders/types.wgsl`.

mod error;
pub mod layout;
pub mod upload;

pub use error::GpuError;
