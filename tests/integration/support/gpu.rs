//! GPU test helpers: a headless device that is optional on developer machines and
//! mandatory in CI.

use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions};

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

/// A renderer for `gpu`'s device with the default options.
///
/// # Panics
///
/// If the renderer cannot be built (its shaders fail to compile): a test failure.
pub fn renderer(gpu: &HeadlessGpu) -> Renderer {
    renderer_with(gpu, RendererOptions::default())
}

/// A renderer for `gpu`'s device with `options`.
///
/// # Panics
///
/// If the renderer cannot be built: a test failure.
pub fn renderer_with(gpu: &HeadlessGpu, options: RendererOptions) -> Renderer {
    Renderer::new(&gpu.device, options).unwrap_or_else(|e| panic!("Renderer::new failed: {e}"))
}

/// Renders `scene` with `a` and with `b` on `gpu` and asserts the same pixels bit for
/// bit and the same ray count: for settings that change how the work is done, never
/// its result. `what` names the scene and the pair in a failure.
pub fn assert_renders_identical(
    gpu: &HeadlessGpu,
    a: &Renderer,
    b: &Renderer,
    scene: &gpu_render::scene::Scene,
    what: &str,
) {
    let first = a
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("{what}, first render: {e}"));
    let second = b
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("{what}, second render: {e}"));
    let worst = super::compare::max_channel_difference(&first.image, &second.image);
    assert_eq!(worst, 0.0, "{what}: max |Δ| {worst}");
    assert_eq!(
        first.stats.rays_traced, second.stats.rays_traced,
        "{what}: rays"
    );
}
