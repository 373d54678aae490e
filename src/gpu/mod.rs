//! The wgpu backend (being written).
//!
//! - [`upload`]: pure conversion of a [`crate::scene::Scene`] into the GPU records.
//! - [`shaders`]: composition of the WGSL sources.
//! - [`layout`]: the `#[repr(C)]` records shared with `shaders/types.wgsl`.

mod error;
pub mod layout;
pub mod shaders;
pub mod upload;

pub use error::GpuError;
