//! GPU test helpers: a headless device that is optional on developer machines and
//! mandatory in CI.

use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu};

/// A headless GPU, or `None` (with a note on stderr) when this machine has no adapter.
///
/// # Panics
///
/// When the `CI` environment variable is set and no device can be created: GPU tests
/// must fail in CI, never pass by skipping.
pub fn headless_gpu() -> Option<HeadlessGpu> {
    match HeadlessGpu::new(&AdapterChoice::Default) {
        Ok(gpu) => Some(gpu),
        Err(e) if std::env::var_os("CI").is_some() => panic!(
            "\n\n*** CI is set but no GPU device could be created: {e}\n\
             *** GPU tests must not be skipped in CI; install a Vulkan driver \
             (e.g. mesa-vulkan-drivers for lavapipe).\n\n"
        ),
        Err(e) => {
            eprintln!("note: skipping GPU test, no GPU device: {e}");
            None
        }
    }
}

/// A renderer for `gpu`'s device.
///
/// # Panics
///
/// If the renderer cannot be built (its shaders fail to compile): a test failure.
pub fn renderer(gpu: &HeadlessGpu) -> GpuRenderer {
    GpuRenderer::new(&gpu.device).unwrap_or_else(|e| panic!("GpuRenderer::new failed: {e}"))
}
