//! [`RenderError`]: the one error type of the GPU backend.

use std::ops::Range;
use std::time::Duration;

use thiserror::Error;

use crate::scene::Camera;

/// Everything the GPU backend ([`super::Renderer`], [`super::GpuScene`],
/// [`super::Film`], [`super::HeadlessGpu`]) can report. Invalid WGSL, exceeded device
/// limits, allocation failures and lost devices all become values of this type rather
/// than panics, so that a front end can report them and, for example, fall back to the
/// CPU reference. wgpu's own errors are kept as each variant's `source`.
///
/// Non-exhaustive: match the variants you handle and keep a catch-all arm.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RenderError {
    /// No adapter matched the request.
    #[error("no suitable GPU adapter: {requested}; {available}")]
    NoAdapter {
        /// What was asked for ("no adapter named like \"nvidia\"", or wgpu's reason).
        requested: String,
        /// The adapters there are, as [`super::adapter_listing`] lists them.
        available: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a GPU device: {0}")]
    RequestDevice(#[source] wgpu::RequestDeviceError),
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
    /// The scene (or the image asked of it) needs more than the device can hold
    /// whatever it is asked for: more planes than the kernels test, buffers larger
    /// than a binding, more images than texture layers.
    #[error("{what} is {value}, more than this device's limit of {limit}")]
    SceneTooLarge {
        /// What exceeded the limit ("infinite planes", "triangles buffer bytes", ...).
        what: String,
        /// The value the scene needs.
        value: u64,
        /// The device's limit.
        limit: u64,
    },
    /// A traversal was asked of a device that cannot run it:
    /// [`super::Traversal::Hardware`] on a device without
    /// [`wgpu::Features::EXPERIMENTAL_RAY_QUERY`] (or without room to bind an
    /// acceleration structure).
    #[error("{what} needs the device feature {feature}, which this device does not have{hint}")]
    MissingFeature {
        /// What needed it ("hardware traversal").
        what: &'static str,
        /// The `wgpu::Features` flag or limit.
        feature: &'static str,
        /// What to do about it (empty, or a sentence beginning with "; ").
        hint: &'static str,
    },
    /// The scene's render settings are out of range
    /// ([`crate::scene::RenderSettings::check`]).
    #[error("invalid render settings: {0}")]
    InvalidSettings(#[source] crate::scene::SettingsError),
    /// A camera with an undefined view (eye on the look-at point, a zero or parallel
    /// up vector) or a field of view outside (0, 180) degrees.
    #[error("invalid camera {0:?}")]
    InvalidCamera(Camera),
    /// A region of pixels that is empty or lies outside the image, or whose target
    /// origin lies after its first pixel.
    #[error(
        "region columns {columns:?}, rows {rows:?} (stored from {origin:?}) is empty or \
         lies outside the {width}x{height} image"
    )]
    InvalidRegion {
        /// The region's image columns.
        columns: Range<u32>,
        /// The region's image rows.
        rows: Range<u32>,
        /// The image pixel the target's texel (0, 0) holds.
        origin: (u32, u32),
        /// The image's width.
        width: u32,
        /// The image's height.
        height: u32,
    },
    /// A texture whose format the operation cannot read or write.
    #[error("the {role} texture is {found:?}, this operation needs {expected:?}")]
    TargetFormat {
        /// Which texture ("target", "display input", ...).
        role: &'static str,
        /// The format the operation needs.
        expected: wgpu::TextureFormat,
        /// The texture's format.
        found: wgpu::TextureFormat,
    },
    /// A texture without a usage the operation needs.
    #[error("the {role} texture needs usage {needed:?}, it has {found:?}")]
    TargetUsage {
        /// Which texture.
        role: &'static str,
        /// The usage needed.
        needed: wgpu::TextureUsages,
        /// The texture's usages.
        found: wgpu::TextureUsages,
    },
    /// A texture of another size than the film or image it is used with.
    #[error("the {role} texture is {target:?} pixels, the image {film:?}")]
    TargetSize {
        /// Which texture.
        role: &'static str,
        /// The film's or image's width and height.
        film: (u32, u32),
        /// The texture's width and height.
        target: (u32, u32),
    },
    /// [`super::Renderer::draw`] on a renderer built without a `surface_format`.
    #[error("draw needs RendererOptions::surface_format")]
    NoSurfaceFormat,
    /// The auxiliary passes (or the denoiser they guide) asked of a film or scene made
    /// by a renderer without [`super::RendererOptions::aov`].
    #[error(
        "the auxiliary passes need RendererOptions::aov for the renderer that made the film \
         and uploaded the scene"
    )]
    NoAov,
    /// A film whose bounce stacks are smaller than the scene's `stack_size` (create a
    /// film for that scene).
    #[error("the film's bounce stacks hold {film} entries, the scene needs {scene}")]
    FilmStack {
        /// The film's stack capacity.
        film: u32,
        /// The scene's stack size.
        scene: u32,
    },
    /// The WGSL of a module could not be composed (a malformed feature directive in
    /// the sources: a bug, never the scene's fault).
    #[error("the {module} shader source could not be composed: {message}")]
    ShaderSource {
        /// The module ("trace (...)", "display").
        module: String,
        /// What is wrong.
        message: String,
    },
    /// wgpu rejected a shader module or pipeline.
    #[error("shader or pipeline creation failed: {what}: {source}")]
    Shader {
        /// The module or pipeline.
        what: String,
        /// wgpu's error.
        source: wgpu::Error,
    },
    /// An allocation failed.
    #[error("GPU out of memory: {what}: {source}")]
    OutOfMemory {
        /// What was being allocated.
        what: String,
        /// wgpu's error.
        source: wgpu::Error,
    },
    /// wgpu rejected a resource or command (validation or internal error).
    #[error("wgpu rejected {what}: {source}")]
    Wgpu {
        /// What was being created or submitted.
        what: String,
        /// wgpu's error.
        source: wgpu::Error,
    },
    /// A wait for the GPU took longer than the renderer's
    /// [`super::RendererOptions::poll_timeout`]: the dispatch hung or was killed by a
    /// watchdog.
    #[error("the GPU did not finish within {0:?} (the renderer's poll timeout)")]
    Timeout(Duration),
    /// The device was lost (driver reset, watchdog, a failure while waiting).
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    /// Reading results back from the GPU failed.
    #[error("reading back from the GPU failed: {what}")]
    Readback {
        /// What failed ("map failed: ...").
        what: String,
        /// wgpu's error, where it gave one.
        source: Option<wgpu::BufferAsyncError>,
    },
    /// The trace kernels reported work they could not finish: the image would be
    /// wrong, so none is returned.
    #[error("the GPU trace did not complete: {0}")]
    TraceIncomplete(TraceFailure),
}

/// Why the trace kernels could not finish ([`RenderError::TraceIncomplete`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum TraceFailure {
    /// A shader loop was cut short by the driver (llvmpipe before Mesa 25 ends every
    /// loop of an invocation after 65,535 iterations).
    #[error(
        "a shader loop was cut short by the driver before it finished (llvmpipe ends \
         every loop of an invocation after 65,535 iterations); the image would miss \
         rays, so none is returned. Lower the iteration budget \
         (RendererOptions::iteration_budget, or the CLI's --iteration-budget) or \
         render on the CPU reference"
    )]
    LoopCut,
    /// A BVH traversal needed more stack entries than the kernels hold.
    #[error(
        "a BVH traversal needed more than {max_depth} stack entries; the image would \
         miss hits, so none is returned (a bug: the builders bound the depth)"
    )]
    TraversalStack {
        /// The kernels' stack depth.
        max_depth: u32,
    },
}
