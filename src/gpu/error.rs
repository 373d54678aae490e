//! The error type of the GPU backend.

use thiserror::Error;

/// Everything that can go wrong on the GPU side. Invalid WGSL, exceeded device limits,
/// allocation failures and lost devices all become values of this type rather than
/// panics, so a front end can report them and, for example, fall back to the CPU.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter matched the request (the message says what was asked for and what
    /// was found).
    #[error("no suitable GPU adapter: {0}")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a GPU device: {0}")]
    RequestDevice(String),
    /// A shader module or pipeline failed to compile or validate.
    #[error("shader or pipeline creation failed: {0}")]
    Shader(String),
    /// wgpu rejected a command or resource (for example a caller's texture with the
    /// wrong format or usage passed to a low-level `encode_*` call).
    #[error("GPU validation error: {0}")]
    Validation(String),
    /// The scene needs more than the device allows.
    #[error("{what} is {value}, more than this device's limit of {limit}")]
    DeviceLimit {
        /// What exceeded the limit (for example "image width" or "sphere buffer bytes").
        what: String,
        /// The value the scene needs.
        value: u64,
        /// The device's limit.
        limit: u64,
    },
    /// A buffer or texture allocation failed.
    #[error("GPU out of memory: {0}")]
    OutOfMemory(String),
    /// The device was lost (driver reset, watchdog, hang past the poll timeout).
    #[error("GPU device lost: {0}")]
    DeviceLost(String),
    /// The trace kernels reported work they could not finish (a loop cut short by the
    /// driver): the image would be wrong, so none is returned.
    #[error("the GPU trace did not complete: {0}")]
    TraceIncomplete(String),
    /// Reading results back from the GPU failed.
    #[error("reading back from the GPU failed: {0}")]
    Readback(String),
}
