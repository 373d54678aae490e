//! [`RenderError`]: the one error type of the frame-loop API ([`super::Renderer`]).

use thiserror::Error;

use super::GpuError;
use crate::scene::Camera;

/// Everything the frame-loop API ([`super::Renderer`], [`super::GpuScene`],
/// [`super::Film`]) can report. Non-exhaustive: match the variants you handle and keep
/// a catch-all arm.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The device was created with a smaller limit than the renderer, a scene or a film
    /// needs. Request [`super::Renderer::required_limits`] when creating the device.
    #[error(
        "the device's `{limit}` is {available}, but gpu-render needs {needed} \
         (request Renderer::required_limits(&adapter.limits()) when creating the device)"
    )]
    Limit {
        /// The field of [`wgpu::Limits`] that is too small.
        limit: &'static str,
        /// What gpu-render needs.
        needed: u64,
        /// What the device has.
        available: u64,
    },
    /// The scene cannot be uploaded: invalid render settings, or more primitives,
    /// images or bytes than the device holds.
    #[error("the scene cannot be uploaded: {0}")]
    Scene(#[source] GpuError),
    /// A camera with an undefined view (eye on the look-at point, a zero or parallel
    /// up vector) or a field of view outside (0, 180) degrees.
    #[error("invalid camera {0:?}")]
    InvalidCamera(Camera),
    /// A target texture whose format the operation cannot write.
    #[error("the target texture is {found:?}, this operation writes {expected:?}")]
    TargetFormat {
        /// The format the operation writes.
        expected: wgpu::TextureFormat,
        /// The target's format.
        found: wgpu::TextureFormat,
    },
    /// A target texture without a usage the operation needs.
    #[error("the target texture needs usage {needed:?}, it has {found:?}")]
    TargetUsage {
        /// The usage needed.
        needed: wgpu::TextureUsages,
        /// The target's usages.
        found: wgpu::TextureUsages,
    },
    /// A target texture of another size than the film.
    #[error("the target texture is {target:?} pixels, the film {film:?}")]
    TargetSize {
        /// The film's width and height.
        film: (u32, u32),
        /// The target's width and height.
        target: (u32, u32),
    },
    /// [`super::Renderer::draw`] on a renderer built without a `surface_format`.
    #[error("draw needs RendererOptions::surface_format")]
    NoSurfaceFormat,
    /// A film whose bounce stacks are smaller than the scene's `stack_size` (create a
    /// film for that scene).
    #[error("the film's bounce stacks hold {film} entries, the scene needs {scene}")]
    FilmStack {
        /// The film's stack capacity.
        film: u32,
        /// The scene's stack size.
        scene: u32,
    },
    /// wgpu reported an error (validation, out of memory, internal) while creating a
    /// pipeline or resource.
    #[error("wgpu error: {0}")]
    Wgpu(#[source] GpuError),
    /// The device was lost, or a blocking convenience's wait for it failed.
    #[error("the GPU device was lost: {0}")]
    DeviceLost(#[source] GpuError),
    /// Reading a film back failed (a blocking convenience).
    #[error("reading back from the GPU failed: {0}")]
    Readback(#[source] GpuError),
    /// The trace kernels reported work they could not finish (a loop cut short by the
    /// driver, an overflowing traversal stack): the film would be wrong.
    #[error("the GPU trace did not complete: {0}")]
    TraceIncomplete(#[source] GpuError),
}

impl From<GpuError> for RenderError {
    /// Sorts an error of the blocking layer into the frame loop's variants.
    fn from(error: GpuError) -> Self {
        match error {
            GpuError::DeviceLimit { .. } => RenderError::Scene(error),
            GpuError::TraceIncomplete(_) => RenderError::TraceIncomplete(error),
            GpuError::DeviceLost(_) => RenderError::DeviceLost(error),
            GpuError::Readback(_) => RenderError::Readback(error),
            other => RenderError::Wgpu(other),
        }
    }
}
