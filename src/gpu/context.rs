//! A headless wgpu context for apps and tests that do not bring their own device.

use std::sync::{Arc, Mutex, PoisonError};

use super::RenderError;

/// Which adapter [`HeadlessGpu::new`] should open.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum AdapterChoice {
    /// wgpu's choice with [`wgpu::PowerPreference::HighPerformance`].
    #[default]
    Default,
    /// The adapter at this position in [`list_adapters`].
    Index(usize),
    /// The first adapter whose name contains this text (case-insensitive).
    NameContains(String),
}

/// The backends to try first: `WGPU_BACKEND` if set (for example `vulkan` or `gl`),
/// otherwise the native modern APIs. GL is left out here so that machines offering
/// both Vulkan and EGL (lavapipe and llvmpipe, say) pick deterministically.
fn primary_backends() -> wgpu::Backends {
    wgpu::Backends::from_env()
        .unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12)
}

fn instance_for(backends: wgpu::Backends) -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = backends;
    wgpu::Instance::new(desc)
}

/// An instance with its adapters: the primary backends, or GL when those offer none
/// (and `WGPU_BACKEND` did not pin the choice).
fn instance_with_adapters() -> (wgpu::Instance, Vec<wgpu::Adapter>) {
    let backends = primary_backends();
    let instance = instance_for(backends);
    let adapters = pollster::block_on(instance.enumerate_adapters(backends));
    if !adapters.is_empty() || wgpu::Backends::from_env().is_some() {
        return (instance, adapters);
    }
    let gl = instance_for(wgpu::Backends::GL);
    let adapters = pollster::block_on(gl.enumerate_adapters(wgpu::Backends::GL));
    (gl, adapters)
}

/// Every adapter [`HeadlessGpu::new`] could open, in the order [`AdapterChoice::Index`]
/// counts them.
///
/// ```no_run
/// for (i, info) in gpu_render::gpu::list_adapters().iter().enumerate() {
///     println!("{i}: {} ({:?})", info.name, info.backend);
/// }
/// ```
pub fn list_adapters() -> Vec<wgpu::AdapterInfo> {
    let (_instance, adapters) = instance_with_adapters();
    adapters.iter().map(wgpu::Adapter::get_info).collect()
}

/// [`list_adapters`] with the features each adapter offers (for `gpu-render --adapter
/// list`, which names the ones the tracer uses or could use).
pub fn list_adapters_with_features() -> Vec<(wgpu::AdapterInfo, wgpu::Features)> {
    let (_instance, adapters) = instance_with_adapters();
    adapters
        .iter()
        .map(|adapter| (adapter.get_info(), adapter.features()))
        .collect()
}

/// `adapters` numbered as [`AdapterChoice::Index`] counts them, for error messages:
/// `available: 0: NAME (BACKEND), ...`, or `no adapters found`.
pub fn adapter_listing(adapters: &[wgpu::Adapter]) -> String {
    let list: Vec<String> = adapters
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let info = a.get_info();
            format!("{i}: {} ({:?})", info.name, info.backend)
        })
        .collect();
    if list.is_empty() {
        "no adapters found".to_string()
    } else {
        format!("available: {}", list.join(", "))
    }
}

/// The adapter of `adapters` that `choice` names: by index, or the first whose name
/// contains the text (case-insensitive); [`AdapterChoice::Default`] takes the first.
/// A window's program passes the adapters that can present to its surface.
///
/// Errors: [`RenderError::NoAdapter`] naming the choice and listing `adapters`.
pub fn select_adapter(
    adapters: &[wgpu::Adapter],
    choice: &AdapterChoice,
) -> Result<wgpu::Adapter, RenderError> {
    let found = match choice {
        AdapterChoice::Default => adapters.first(),
        AdapterChoice::Index(i) => adapters.get(*i),
        AdapterChoice::NameContains(text) => {
            let wanted = text.to_lowercase();
            adapters
                .iter()
                .find(|a| a.get_info().name.to_lowercase().contains(&wanted))
        }
    };
    found.cloned().ok_or_else(|| {
        let asked = match choice {
            AdapterChoice::Default => "no adapter".to_string(),
            AdapterChoice::Index(i) => format!("no adapter with index {i}"),
            AdapterChoice::NameContains(text) => format!("no adapter name contains {text:?}"),
        };
        RenderError::NoAdapter {
            requested: asked,
            available: adapter_listing(adapters),
        }
    })
}

/// A wgpu instance, adapter, device and queue without any window.
///
/// The device is created with the adapter's own limits (not [`wgpu::Limits::default`]),
/// so large storage buffers and image sizes the hardware supports are usable, and with
/// the features of `gpu::limits::optional_features` where the adapter offers them
/// (timestamp queries, so that renders report GPU time, and subgroup operations).
pub struct HeadlessGpu {
    /// The instance the adapter came from.
    pub instance: wgpu::Instance,
    /// The chosen adapter.
    pub adapter: wgpu::Adapter,
    /// The device; pass it to [`super::Renderer::new`] and its methods.
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
    lost: Arc<Mutex<Option<String>>>,
}

impl std::fmt::Debug for HeadlessGpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeadlessGpu")
            .field("adapter", &self.adapter.get_info())
            .field("lost", &self.lost_reason())
            .finish_non_exhaustive()
    }
}

impl HeadlessGpu {
    /// Opens the adapter `choice` names and creates a device with its full limits.
    ///
    /// Errors: [`RenderError::NoAdapter`] when nothing matches (the message lists what
    /// exists), [`RenderError::RequestDevice`] when the adapter refuses the device.
    ///
    /// ```no_run
    /// use gpu_render::gpu::{AdapterChoice, HeadlessGpu};
    /// let gpu = HeadlessGpu::new(&AdapterChoice::NameContains("llvmpipe".into()))?;
    /// println!("rendering on {}", gpu.adapter_info().name);
    /// # Ok::<(), gpu_render::gpu::RenderError>(())
    /// ```
    pub fn new(choice: &AdapterChoice) -> Result<Self, RenderError> {
        let (instance, adapters) = instance_with_adapters();
        let adapter = match choice {
            AdapterChoice::Default => {
                let options = wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    ..Default::default()
                };
                match pollster::block_on(instance.request_adapter(&options)) {
                    Ok(adapter) => adapter,
                    // request_adapter may decline where enumeration found something
                    // (for example only a CPU adapter): take the first one then.
                    Err(e) => adapters
                        .first()
                        .cloned()
                        .ok_or_else(|| RenderError::NoAdapter {
                            requested: e.to_string(),
                            available: adapter_listing(&adapters),
                        })?,
                }
            }
            _ => select_adapter(&adapters, choice)?,
        };
        // Timestamp queries and subgroup operations, where the adapter offers them;
        // ray queries too (the hardware traversal), which wgpu offers only as an
        // experimental feature: it is enabled where they are requested.
        let (ray_query, experimental_features) =
            super::ray_query::ray_query_features(adapter.features());
        let required_features = super::limits::optional_features(adapter.features()) | ray_query;
        let desc = wgpu::DeviceDescriptor {
            label: Some("gpu-render headless device"),
            required_features,
            required_limits: adapter.limits(),
            experimental_features,
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(RenderError::RequestDevice)?;
        // Record the reason if the device is lost, so callers can tell a reset from
        // other failures (see `lost_reason`).
        let lost = Arc::new(Mutex::new(None));
        let sink = Arc::clone(&lost);
        device.set_device_lost_callback(move |reason, message| {
            *sink.lock().unwrap_or_else(PoisonError::into_inner) =
                Some(format!("{reason:?}: {message}"));
        });
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            lost,
        })
    }

    /// Name, backend, device type and driver of the adapter, for summaries.
    pub fn adapter_info(&self) -> wgpu::AdapterInfo {
        self.adapter.get_info()
    }

    /// Why the device was lost, if it was (`None` while it is healthy).
    pub fn lost_reason(&self) -> Option<String> {
        self.lost
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}
