//! The program's cache of compiled GPU pipelines, kept between runs in the user's cache
//! folder, so that a second render of a scene (or of another scene with the same
//! features) does not compile its kernels again where the driver keeps compiled code
//! in its pipeline cache (`wgpu::Features::PIPELINE_CACHE`, Vulkan).
//!
//! The folder is `$GPU_RENDER_CACHE_DIR`, else `$XDG_CACHE_HOME/gpu-render`, else
//! `~/.cache/gpu-render`; `GPU_RENDER_CACHE_DIR=off` keeps no cache. One file per
//! adapter (`wgpu::util::pipeline_cache_key`: the backend, vendor and device), written
//! atomically; a file that does not load is replaced, never trusted blindly (wgpu
//! checks its header against the adapter and starts empty otherwise).

use std::path::{Path, PathBuf};

/// The largest cache file read (a full set of kernel variants is a few MiB).
const MAX_CACHE_BYTES: u64 = 256 * 1024 * 1024;

/// A pipeline cache opened from (and saved to) a file.
pub struct PipelineCacheFile {
    path: PathBuf,
    cache: wgpu::PipelineCache,
    /// The data as loaded, to save only what changed.
    loaded: Option<Vec<u8>>,
}

impl PipelineCacheFile {
    /// The cache of `device` (made from `adapter`) from its file, if the device has
    /// pipeline caches and a cache folder is known (and not turned off).
    pub fn open(device: &wgpu::Device, adapter: &wgpu::AdapterInfo) -> Option<Self> {
        if !device.features().contains(wgpu::Features::PIPELINE_CACHE) {
            return None;
        }
        let key = wgpu::util::pipeline_cache_key(adapter)?;
        let path = cache_dir()?.join(format!("{key}.bin"));
        let loaded = gpu_render::low_level::input::read_input(&path, MAX_CACHE_BYTES).ok();
        // SAFETY: the data is what `PipelineCache::get_data` returned in an earlier run
        // for this adapter key, written by `save` below into the user's own cache
        // folder, as `create_pipeline_cache` requires. wgpu validates its header
        // (magic, version, backend, adapter key, size) and, with `fallback`, starts an
        // empty cache for data it cannot use.
        let cache = unsafe {
            device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("gpu-render pipeline cache"),
                data: loaded.as_deref(),
                fallback: true,
            })
        };
        Some(Self {
            path,
            cache,
            loaded,
        })
    }

    /// The cache, for [`gpu_render::gpu::RendererOptions::pipeline_cache`].
    pub fn cache(&self) -> wgpu::PipelineCache {
        self.cache.clone()
    }

    /// Writes the cache's data back to its file if it changed. Best effort: a cache
    /// that cannot be saved is reported (unless `quiet`) and the render stands.
    pub fn save(&self, quiet: bool) {
        let Some(data) = self.cache.get_data() else {
            return;
        };
        if self.loaded.as_deref() == Some(data.as_slice()) {
            return;
        }
        let written = self
            .path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .map_err(|e| e.to_string())
            .and_then(|()| {
                gpu_render::output::write_bytes(&self.path, &data).map_err(|e| e.to_string())
            });
        if let Err(e) = written
            && !quiet
        {
            eprintln!(
                "note: could not save the GPU pipeline cache {}: {e}",
                self.path.display()
            );
        }
    }
}

/// The cache folder, or `None` where none is known or `GPU_RENDER_CACHE_DIR` is `off`.
fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("GPU_RENDER_CACHE_DIR") {
        Some(dir) if dir == "off" || dir.is_empty() => None,
        Some(dir) => Some(PathBuf::from(dir)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .filter(|dir| Path::new(dir).is_absolute())
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".cache")))
            .map(|dir| dir.join("gpu-render")),
    }
}
