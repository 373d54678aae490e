//! The blocking conveniences built on the stages of [`GpuRenderer`]: whole renders
//! and regions traced in tiles of at most the device's texture size, with the display
//! pass and readback ([`GpuRenderer::render`], [`GpuRenderer::render_region`]), and a
//! trace into one caller texture ([`GpuRenderer::render_to_texture`]). The CLI and
//! the tests use these; an application's frame loop uses [`super::super::Renderer`].

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use super::{GpuRenderer, TraceRegion, create_texture};
use crate::film::{LinearImage, ProgressFn, RenderStats};
use crate::gpu::GpuError;
use crate::gpu::pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT};
use crate::gpu::readback::{read_texture, submit_and_wait};
use crate::gpu::scene_buffers::PreparedScene;
use crate::gpu::shaders::WORKGROUP_SIZE;
use crate::noise::NoiseEstimate;
use crate::scene::Scene;

/// The result of [`GpuRenderer::render`], and of [`GpuRenderer::render_region`] (whose
/// images are the region's).
#[derive(Debug, Clone, PartialEq)]
pub struct GpuRendered {
    /// The linear radiance image, as traced.
    pub image: LinearImage,
    /// The display pass's output: `width × height` RGBA8 pixels, row-major, top row
    /// first, sRGB-encoded unless the scene is in naive gamma mode.
    pub display_rgba8: Vec<u8>,
    /// Rays traced, the wall time of tracing and, where the device has timestamp
    /// queries, its GPU time.
    pub stats: RenderStats,
    /// Each pixel's noise estimate, with [`GpuRenderer::with_noise_estimate`].
    pub noise: Option<NoiseEstimate>,
}

/// The tiles [`GpuRenderer::render`] traces an image of `width × height` in: one tile
/// when the image fits `max_dimension` (the device's `max_texture_dimension_2d`), else a
/// grid of tiles of at most `max_dimension` on a side, in row-major order, covering
/// every pixel once. Each tile's `target_origin` is its own top-left pixel: it is traced
/// into a texture of its own size and stitched into the image on readback.
pub fn image_tiles(width: u32, height: u32, max_dimension: u32) -> Vec<TraceRegion> {
    let step = max_dimension.max(1);
    let mut tiles = Vec::new();
    let mut y = 0;
    while y < height {
        let rows = y..height.min(y.saturating_add(step));
        let mut x = 0;
        while x < width {
            let columns = x..width.min(x.saturating_add(step));
            tiles.push(TraceRegion {
                target_origin: (columns.start, rows.start),
                columns: columns.clone(),
                rows: rows.clone(),
            });
            x = columns.end;
        }
        y = rows.end;
    }
    tiles
}

impl GpuRenderer {
    /// Renders `scene` completely: uploads it, traces it (in tiles of at most the
    /// device's `max_texture_dimension_2d` on a side, each into a texture of its own),
    /// runs the display pass and reads back both images; `progress(rows_done, height)`
    /// follows the finished pixels (in rows' worth). `stats.elapsed` covers the trace
    /// submissions only.
    ///
    /// Errors: see [`GpuRenderer::prepare`] and [`GpuRenderer::trace_into`];
    /// [`GpuError::Readback`].
    pub fn render(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<GpuRendered, GpuError> {
        let prepared = self.prepare(device, queue, scene)?;
        self.render_prepared(device, queue, &prepared, progress)
    }

    /// [`GpuRenderer::render`] for a scene already uploaded: the region of the whole
    /// image ([`GpuRenderer::render_region`]).
    pub fn render_prepared(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<GpuRendered, GpuError> {
        let whole = TraceRegion::whole(prepared.width(), prepared.height());
        self.render_region(device, queue, prepared, &whole, progress)
    }

    /// Renders only the pixels of `region` of a scene already uploaded: traces them in
    /// tiles of at most the device's limits (each into textures of its own), runs the
    /// display pass and reads both images back. The result is the
    /// region's: `image` is `columns × rows` pixels whose (0, 0) is the region's first
    /// pixel, and `region.target_origin` is not used. Each pixel is bit-identical to
    /// the same pixel of a whole render (`docs/model.md`, "Bounded work"), so regions
    /// rendered apart, even in other processes, assemble into the whole image.
    /// `progress(rows_done, region_rows)` follows the finished pixels in rows' worth.
    ///
    /// ```no_run
    /// use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu, TraceRegion};
    /// # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::GpuError> {
    /// let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
    /// let renderer = GpuRenderer::new(&gpu.device)?;
    /// let prepared = renderer.prepare(&gpu.device, &gpu.queue, scene)?;
    /// // The bottom half of the image.
    /// let region = TraceRegion {
    ///     columns: 0..prepared.width(),
    ///     rows: prepared.height() / 2..prepared.height(),
    ///     target_origin: (0, 0),
    /// };
    /// let half = renderer.render_region(&gpu.device, &gpu.queue, &prepared, &region, None)?;
    /// assert_eq!(half.image.height, prepared.height() - prepared.height() / 2);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// Errors: [`GpuError::Validation`] for a region that is empty or lies outside
    /// the image; see [`GpuRenderer::prepare`] and [`GpuRenderer::trace_into`];
    /// [`GpuError::Readback`].
    pub fn render_region(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        region: &TraceRegion,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<GpuRendered, GpuError> {
        let (width, height) = region.size();
        if width == 0
            || height == 0
            || region.columns.end > prepared.width()
            || region.rows.end > prepared.height()
        {
            return Err(GpuError::Validation(format!(
                "region columns {:?}, rows {:?} is empty or lies outside the {}x{} image",
                region.columns,
                region.rows,
                prepared.width(),
                prepared.height()
            )));
        }
        let limits = device.limits();
        // A tile must fit one texture and one display dispatch's workgroup count.
        let mut tile_limit = limits.max_texture_dimension_2d.min(
            limits
                .max_compute_workgroups_per_dimension
                .saturating_mul(WORKGROUP_SIZE),
        );
        if self.noise_estimate {
            // And the noise estimate's sums, 16 bytes per pixel, one storage binding.
            let binding = limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size);
            let side = ((binding / 16) as f64).sqrt() as u32;
            tile_limit = tile_limit.min(side.max(1));
        }
        let (x0, y0) = (region.columns.start, region.rows.start);
        let tiles = image_tiles(width, height, tile_limit)
            .into_iter()
            .map(|tile| TraceRegion {
                columns: tile.columns.start + x0..tile.columns.end + x0,
                rows: tile.rows.start + y0..tile.rows.end + y0,
                target_origin: (tile.columns.start + x0, tile.rows.start + y0),
            });
        let mut pixels = vec![[0.0f32; 4]; width as usize * height as usize];
        let mut display_rgba8 = vec![0u8; width as usize * height as usize * 4];
        let finished = AtomicU64::new(0);
        let report = |new: u64| {
            let done = finished.fetch_add(new, Ordering::Relaxed) + new;
            if let Some(progress) = progress {
                progress((done / u64::from(width)) as u32, height);
            }
        };
        let mut stats = RenderStats::default();
        let mut gpu_time = Some(Duration::ZERO);
        let mut noise = self.noise_estimate.then(|| NoiseEstimate {
            width,
            height,
            samples: prepared.samples_per_pixel(),
            mean_luminance: vec![0.0; width as usize * height as usize],
            standard_error: vec![0.0; width as usize * height as usize],
        });
        for tile in tiles {
            let traced = self.render_tile(device, queue, prepared, &tile, &report)?;
            stats.rays_traced += traced.stats.rays_traced;
            stats.elapsed += traced.stats.elapsed;
            gpu_time = gpu_time.zip(traced.stats.gpu_time).map(|(a, b)| a + b);
            let tile_width = traced.image.width as usize;
            for (row, y) in tile.rows.clone().enumerate() {
                let start = (y - y0) as usize * width as usize + (tile.columns.start - x0) as usize;
                pixels[start..start + tile_width].copy_from_slice(
                    &traced.image.pixels[row * tile_width..(row + 1) * tile_width],
                );
                display_rgba8[start * 4..(start + tile_width) * 4].copy_from_slice(
                    &traced.display_rgba8[row * tile_width * 4..(row + 1) * tile_width * 4],
                );
                if let (Some(whole), Some(part)) = (&mut noise, &traced.noise) {
                    let (to, from) = (
                        start..start + tile_width,
                        row * tile_width..(row + 1) * tile_width,
                    );
                    whole.mean_luminance[to.clone()]
                        .copy_from_slice(&part.mean_luminance[from.clone()]);
                    whole.standard_error[to].copy_from_slice(&part.standard_error[from]);
                }
            }
        }
        stats.gpu_time = gpu_time;
        Ok(GpuRendered {
            image: LinearImage {
                width,
                height,
                pixels,
            },
            display_rgba8,
            stats,
            noise,
        })
    }

    /// Traces one `tile` (which fits the device's limits) into textures of its own
    /// size, runs the display pass and reads both back; `report(new_pixels)` is told
    /// the pixels finished since its last call.
    fn render_tile(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        tile: &TraceRegion,
        report: &dyn Fn(u64),
    ) -> Result<GpuRendered, GpuError> {
        let (tile_width, tile_height) = tile.size();
        let linear = create_texture(
            device,
            "gpu-render linear image",
            tile_width,
            tile_height,
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        )?;
        let display = create_texture(
            device,
            "gpu-render display image",
            tile_width,
            tile_height,
            DISPLAY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        )?;
        let linear_view = linear.create_view(&wgpu::TextureViewDescriptor::default());
        let display_view = display.create_view(&wgpu::TextureViewDescriptor::default());
        let last = AtomicU64::new(0);
        let tile_progress = |done: u64, _: u64| {
            let before = last.swap(done, Ordering::Relaxed);
            report(done - before);
        };
        let (stats, noise) = self.trace_region_into(
            device,
            queue,
            prepared,
            &linear_view,
            tile,
            Some(&tile_progress),
            self.noise_estimate,
        )?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render display pass"),
        });
        self.encode_display(
            device,
            &mut encoder,
            &linear_view,
            &display_view,
            prepared.display_encodes_srgb(),
        )?;
        submit_and_wait(device, queue, encoder, "display pass", self.poll_timeout)?;
        let linear_bytes = read_texture(device, queue, &linear, 16, self.poll_timeout)?;
        let display_rgba8 = read_texture(device, queue, &display, 4, self.poll_timeout)?;
        Ok(GpuRendered {
            image: LinearImage {
                width: tile_width,
                height: tile_height,
                // pod_collect_to_vec copies, so the byte vector's alignment does not
                // matter.
                pixels: bytemuck::pod_collect_to_vec(&linear_bytes),
            },
            display_rgba8,
            stats,
            noise,
        })
    }

    /// Traces `scene` into the caller's `target` (an `Rgba32Float` texture with
    /// `STORAGE_BINDING`, at least image-sized), without the display pass or image
    /// readback; returns the ray count and trace time.
    ///
    /// Errors: as [`GpuRenderer::render`], and [`GpuError::DeviceLimit`] for an image
    /// larger than `max_texture_dimension_2d`, which no single target can hold (use
    /// [`GpuRenderer::render`], which tiles, or [`GpuRenderer::trace_into`]).
    pub fn render_to_texture(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        target: &wgpu::TextureView,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<RenderStats, GpuError> {
        let prepared = self.prepare(device, queue, scene)?;
        let max_dimension = device.limits().max_texture_dimension_2d;
        for (what, value) in [
            ("image width (one target texture)", prepared.width()),
            ("image height (one target texture)", prepared.height()),
        ] {
            if value > max_dimension {
                return Err(GpuError::DeviceLimit {
                    what: what.to_string(),
                    value: u64::from(value),
                    limit: u64::from(max_dimension),
                });
            }
        }
        let (width, height) = (prepared.width(), prepared.height());
        let rows = |done: u64, _: u64| {
            if let Some(progress) = progress {
                progress((done / u64::from(width)) as u32, height);
            }
        };
        self.trace_into(
            device,
            queue,
            &prepared,
            target,
            &TraceRegion::whole(width, height),
            Some(&rows),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_every_pixel_once_within_the_limit() {
        assert_eq!(image_tiles(100, 50, 16384).len(), 1);
        for &(w, h, max) in &[(16500, 3, 16384), (40, 33, 16), (17, 17, 17), (1, 1, 1)] {
            let tiles = image_tiles(w, h, max);
            let mut covered = vec![0u8; (w * h) as usize];
            for tile in &tiles {
                assert!(tile.columns.end - tile.columns.start <= max);
                assert!(tile.rows.end - tile.rows.start <= max);
                assert_eq!(tile.target_origin, (tile.columns.start, tile.rows.start));
                for y in tile.rows.clone() {
                    for x in tile.columns.clone() {
                        covered[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1), "{w}x{h} max {max}");
        }
        assert_eq!(image_tiles(16500, 3, 16384).len(), 2);
    }
}
