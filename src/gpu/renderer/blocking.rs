//! Whole images and tiles, blocking: every sample of a region traced into a caller's
//! texture ([`Renderer::trace_into`]), whole renders and regions traced in tiles of at
//! most the device's texture size with the display pass and readback
//! ([`Renderer::render`], [`Renderer::render_region`]), and a trace into one caller
//! texture ([`Renderer::render_to_texture`]). The CLI, the tests and programs that
//! want an image rather than a frame loop use these.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use super::Renderer;
use crate::denoise::GuidePasses;
use crate::film::{LinearImage, ProgressFn, RenderStats};
use crate::gpu::RenderError;
use crate::gpu::display::{TextureSize, check_texture, encode_display};
use crate::gpu::gpu_scene::GpuScene;
use crate::gpu::pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT};
use crate::gpu::readback::{create_texture, read_texture, submit_and_wait};
use crate::gpu::shaders::WORKGROUP_SIZE;
use crate::gpu::wavefront::{SlotBuffers, trace_region};
use crate::noise::NoiseEstimate;
use crate::scene::Scene;

/// A rectangle of image pixels traced into one target texture, and where it lands
/// there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TraceRegion {
    /// Image columns traced.
    pub columns: Range<u32>,
    /// Image rows traced.
    pub rows: Range<u32>,
    /// The image pixel stored at texel (0, 0) of the target.
    pub target_origin: (u32, u32),
}

impl TraceRegion {
    /// The whole image of `width × height`, stored at the target's origin.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            columns: 0..width,
            rows: 0..height,
            target_origin: (0, 0),
        }
    }

    fn size(&self) -> (u32, u32) {
        (
            self.columns.end.saturating_sub(self.columns.start),
            self.rows.end.saturating_sub(self.rows.start),
        )
    }

    /// [`RenderError::InvalidRegion`] for this region of a `width × height` image.
    fn invalid(&self, width: u32, height: u32) -> RenderError {
        RenderError::InvalidRegion {
            columns: self.columns.clone(),
            rows: self.rows.clone(),
            origin: self.target_origin,
            width,
            height,
        }
    }
}

/// The result of [`Renderer::render`], and of [`Renderer::render_region`] (whose
/// images are the region's).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedImage {
    /// The linear radiance image, as traced.
    pub image: LinearImage,
    /// The display pass's output: `width × height` RGBA8 pixels, row-major, top row
    /// first, sRGB-encoded unless the scene is in naive gamma mode.
    pub display_rgba8: Vec<u8>,
    /// Rays traced, the wall time of tracing and, where the device has timestamp
    /// queries, its GPU time.
    pub stats: RenderStats,
    /// Each pixel's noise estimate, with [`super::RendererOptions::noise_estimate`].
    pub noise: Option<NoiseEstimate>,
    /// The auxiliary passes (first-hit albedo, shading normal, depth; averaged over
    /// each pixel's samples), with [`super::RendererOptions::aov`].
    pub aov: Option<GuidePasses>,
}

/// The tiles [`Renderer::render`] traces an image of `width × height` in: one tile
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

impl Renderer {
    /// Renders `scene` completely: uploads it ([`Renderer::upload`]), traces it (in
    /// tiles of at most the device's `max_texture_dimension_2d` on a side, each into a
    /// texture of its own), runs the display pass and reads back both images;
    /// `progress(rows_done, height)` follows the finished pixels (in rows' worth).
    /// `stats.elapsed` covers the trace submissions only.
    ///
    /// Errors: see [`Renderer::upload`] and [`Renderer::trace_into`];
    /// [`RenderError::Readback`].
    pub fn render(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<RenderedImage, RenderError> {
        let uploaded = self.upload(device, queue, scene)?;
        let whole = TraceRegion::whole(uploaded.width(), uploaded.height());
        self.render_region(device, queue, &uploaded, &whole, progress)
    }

    /// Renders only the pixels of `region` of a scene already uploaded: traces them in
    /// tiles of at most the device's limits (each into textures of its own), runs the
    /// display pass and reads both images back. The result is the region's: `image`
    /// is `columns × rows` pixels whose (0, 0) is the region's first pixel, and
    /// `region.target_origin` is not used. Each pixel is bit-identical to the same
    /// pixel of a whole render (`docs/model.md`, "Bounded work"), so regions rendered
    /// apart, even in other processes, assemble into the whole image.
    /// `progress(rows_done, region_rows)` follows the finished pixels in rows' worth.
    ///
    /// ```no_run
    /// use gpu_render::gpu::{AdapterChoice, HeadlessGpu, Renderer, RendererOptions, TraceRegion};
    /// # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::RenderError> {
    /// let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
    /// let renderer = Renderer::new(&gpu.device, RendererOptions::default())?;
    /// let uploaded = renderer.upload(&gpu.device, &gpu.queue, scene)?;
    /// // The bottom half of the image.
    /// let region = TraceRegion {
    ///     columns: 0..uploaded.width(),
    ///     rows: uploaded.height() / 2..uploaded.height(),
    ///     target_origin: (0, 0),
    /// };
    /// let half = renderer.render_region(&gpu.device, &gpu.queue, &uploaded, &region, None)?;
    /// assert_eq!(half.image.height, uploaded.height() - uploaded.height() / 2);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// Errors: [`RenderError::InvalidRegion`] for a region that is empty or lies
    /// outside the image; see [`Renderer::trace_into`]; [`RenderError::Readback`].
    pub fn render_region(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        region: &TraceRegion,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<RenderedImage, RenderError> {
        let (width, height) = region.size();
        if width == 0
            || height == 0
            || region.columns.end > scene.width()
            || region.rows.end > scene.height()
        {
            return Err(region.invalid(scene.width(), scene.height()));
        }
        let limits = device.limits();
        // A tile must fit one texture and one display dispatch's workgroup count.
        let mut tile_limit = limits.max_texture_dimension_2d.min(
            limits
                .max_compute_workgroups_per_dimension
                .saturating_mul(WORKGROUP_SIZE),
        );
        let noise_estimate = self.options().noise_estimate;
        let aov = self.options().aov && scene.prepared.features.aov;
        if noise_estimate || aov {
            // And the noise estimate's sums, 16 bytes per pixel, and the auxiliary
            // passes', 32 more: one storage binding.
            let binding = limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size);
            let per_pixel = 16 + if aov { 32 } else { 0 };
            let side = ((binding / per_pixel) as f64).sqrt() as u32;
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
        let mut noise = noise_estimate.then(|| NoiseEstimate {
            width,
            height,
            samples: scene.samples_per_pixel(),
            mean_luminance: vec![0.0; width as usize * height as usize],
            standard_error: vec![0.0; width as usize * height as usize],
        });
        let mut passes = aov.then(|| GuidePasses {
            width,
            height,
            albedo: vec![[0.0; 3]; width as usize * height as usize],
            normal: vec![[0.0; 3]; width as usize * height as usize],
            depth: vec![0.0; width as usize * height as usize],
        });
        for tile in tiles {
            let traced = self.render_tile(device, queue, scene, &tile, &report)?;
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
                if let (Some(whole), Some(part)) = (&mut passes, &traced.aov) {
                    let (to, from) = (
                        start..start + tile_width,
                        row * tile_width..(row + 1) * tile_width,
                    );
                    whole.albedo[to.clone()].copy_from_slice(&part.albedo[from.clone()]);
                    whole.normal[to.clone()].copy_from_slice(&part.normal[from.clone()]);
                    whole.depth[to].copy_from_slice(&part.depth[from]);
                }
            }
        }
        stats.gpu_time = gpu_time;
        Ok(RenderedImage {
            image: LinearImage {
                width,
                height,
                pixels,
            },
            display_rgba8,
            stats,
            noise,
            aov: passes,
        })
    }

    /// Traces one `tile` (which fits the device's limits) into textures of its own
    /// size, runs the display pass and reads both back; `report(new_pixels)` is told
    /// the pixels finished since its last call.
    fn render_tile(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        tile: &TraceRegion,
        report: &dyn Fn(u64),
    ) -> Result<RenderedImage, RenderError> {
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
        let (stats, noise, aov) = self.trace_region_into(
            device,
            queue,
            scene,
            &linear_view,
            tile,
            Some(&tile_progress),
            self.options().noise_estimate,
            self.options().aov,
        )?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render display pass"),
        });
        self.encode_display_texture(
            device,
            &mut encoder,
            &linear_view,
            &display_view,
            scene.display_encodes_srgb(),
        )?;
        let timeout = self.options().poll_timeout;
        submit_and_wait(device, queue, encoder, "display pass", timeout)?;
        let linear_bytes = read_texture(device, queue, &linear, 16, timeout)?;
        let display_rgba8 = read_texture(device, queue, &display, 4, timeout)?;
        Ok(RenderedImage {
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
            aov,
        })
    }

    /// Uploads `scene` and traces it into the caller's `target` (an `Rgba32Float`
    /// texture with `STORAGE_BINDING`, at least image-sized), without the display pass
    /// or image readback; returns the ray count and trace time.
    ///
    /// Errors: as [`Renderer::render`], and [`RenderError::SceneTooLarge`] for an image
    /// larger than `max_texture_dimension_2d`, which no single target can hold (use
    /// [`Renderer::render`], which tiles, or [`Renderer::trace_into`]).
    pub fn render_to_texture(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        target: &wgpu::TextureView,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<RenderStats, RenderError> {
        let uploaded = self.upload(device, queue, scene)?;
        let max_dimension = device.limits().max_texture_dimension_2d;
        for (what, value) in [
            ("image width (one target texture)", uploaded.width()),
            ("image height (one target texture)", uploaded.height()),
        ] {
            if value > max_dimension {
                return Err(RenderError::SceneTooLarge {
                    what: what.to_string(),
                    value: u64::from(value),
                    limit: u64::from(max_dimension),
                });
            }
        }
        let (width, height) = (uploaded.width(), uploaded.height());
        let rows = |done: u64, _: u64| {
            if let Some(progress) = progress {
                progress((done / u64::from(width)) as u32, height);
            }
        };
        self.trace_into(
            device,
            queue,
            &uploaded,
            target,
            &TraceRegion::whole(width, height),
            Some(&rows),
        )
    }

    /// Traces the pixels of `region` of `scene` into `target` (an `Rgba32Float`
    /// texture with `STORAGE_BINDING`, holding at least the region from
    /// `region.target_origin` on), every sample of every pixel, blocking until done.
    /// `progress(pixels_done, region_pixels)` is called after each submission.
    ///
    /// Errors: [`RenderError::InvalidRegion`] for a region outside the image;
    /// [`RenderError::TargetFormat`], [`RenderError::TargetUsage`] or
    /// [`RenderError::TargetSize`] for an unsuitable target;
    /// [`RenderError::TraceIncomplete`] if the kernels report a loop the driver cut
    /// short (the image is then not returned); [`RenderError::Timeout`] past the
    /// renderer's poll timeout; [`RenderError::DeviceLost`].
    pub fn trace_into(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        progress: Option<&dyn Fn(u64, u64)>,
    ) -> Result<RenderStats, RenderError> {
        self.trace_region_into(device, queue, scene, target, region, progress, false, false)
            .map(|(stats, _, _)| stats)
    }

    /// [`Renderer::trace_into`], and with `noise` the region's noise estimate, with
    /// `aov` its auxiliary passes (where the scene's module records them).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn trace_region_into(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        progress: Option<&dyn Fn(u64, u64)>,
        noise: bool,
        aov: bool,
    ) -> Result<(RenderStats, Option<NoiseEstimate>, Option<GuidePasses>), RenderError> {
        let aov = aov && scene.prepared.features.aov;
        let (width, height) = region.size();
        let (origin_x, origin_y) = region.target_origin;
        if region.columns.end > scene.width()
            || region.rows.end > scene.height()
            || origin_x > region.columns.start
            || origin_y > region.rows.start
        {
            return Err(region.invalid(scene.width(), scene.height()));
        }
        let pixels = u64::from(width) * u64::from(height);
        if pixels == 0 {
            return Ok((RenderStats::default(), None, None));
        }
        check_texture(
            target,
            "trace target",
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
            (region.columns.end - origin_x, region.rows.end - origin_y),
            TextureSize::AtLeast,
        )?;
        let prepared = &scene.prepared;
        let slot_count = SlotBuffers::slot_count(
            device,
            self.options().slot_count,
            pixels,
            prepared.stack_size,
        );
        // The sums are kept only for the noise estimate (16 bytes per region pixel) and
        // the auxiliary passes (32 more).
        let sums = if noise || aov { pixels } else { 0 };
        let slots = SlotBuffers::new(device, slot_count, prepared.stack_size, sums, aov)?;
        let bind_group = slots.bind_group(
            device,
            self.pipelines.trace_bind_group_layout(&prepared.features),
            prepared,
            target,
        )?;
        // The camera of the upload, or where `set_camera` moved it since.
        let base = if scene.camera_version == 0 {
            prepared.frame
        } else {
            scene.frame_for(scene.width(), scene.height())
        };
        let frame = crate::gpu::layout::FrameUniforms {
            region_x: region.columns.start,
            region_y: region.rows.start,
            region_width: width,
            region_height: height,
            target_x: origin_x,
            target_y: origin_y,
            first_sample: 0,
            end_sample: prepared.samples_per_pixel(),
            slot_count,
            iteration_budget: self.iteration_budget(),
            // The scene's own flags (its integrator) and the test switch.
            flags: prepared.frame.flags
                | if self.options().simulate_loop_cut {
                    crate::gpu::layout::FLAG_SIMULATE_LOOP_CUT
                } else {
                    0
                }
                | if noise {
                    crate::gpu::layout::FLAG_STORE_SUM
                } else {
                    0
                }
                | if aov { crate::gpu::layout::FLAG_AOV } else { 0 },
            ..base
        };
        let done = AtomicU64::new(0);
        let report = |new: u64| {
            let total = done.fetch_add(new, Ordering::Relaxed) + new;
            if let Some(progress) = progress {
                progress(total, pixels);
            }
        };
        let timeout = self.options().poll_timeout;
        let outcome = trace_region(
            device,
            queue,
            &scene.pipelines,
            &slots,
            &bind_group,
            &frame,
            timeout,
            &report,
        )?;
        let stats = RenderStats {
            rays_traced: outcome.rays,
            elapsed: outcome.elapsed,
            gpu_time: outcome.gpu_time,
        };
        let estimate = if noise {
            Some(slots.read_noise(
                device,
                queue,
                (width, height),
                prepared.samples_per_pixel(),
                timeout,
            )?)
        } else {
            None
        };
        let passes = if aov {
            Some(slots.read_aov(
                device,
                queue,
                (width, height),
                prepared.samples_per_pixel(),
                timeout,
            )?)
        } else {
            None
        };
        Ok((stats, estimate, passes))
    }

    /// Records the display pass over any pair of textures into `encoder`: reads
    /// `linear` (an `Rgba32Float` texture with `TEXTURE_BINDING`), applies the exact
    /// sRGB curve if `encode_srgb` (else clamps only; take it from
    /// [`GpuScene::display_encodes_srgb`]), quantises to 8 bits and writes `display`
    /// (an `Rgba8Unorm` texture with `STORAGE_BINDING` of the same size). A film's
    /// display is [`Renderer::encode_display`].
    ///
    /// Errors: [`RenderError::TargetFormat`], [`RenderError::TargetUsage`] or
    /// [`RenderError::TargetSize`] for unsuitable textures.
    pub fn encode_display_texture(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        linear: &wgpu::TextureView,
        display: &wgpu::TextureView,
        encode_srgb: bool,
    ) -> Result<(), RenderError> {
        encode_display(
            &self.pipelines,
            device,
            encoder,
            linear,
            display,
            encode_srgb,
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
