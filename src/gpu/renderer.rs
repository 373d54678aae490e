//! [`GpuRenderer`]: pipelines, scene upload, chunked dispatch and readback.
//!
//! The renderer owns no device: it is built from the caller's [`wgpu::Device`] and
//! every method takes the device (and queue where it submits), so an app can embed
//! the tracer in its own frame. Two levels:
//!
//! - high level: [`GpuRenderer::render`] (textures, chunked tracing, display pass,
//!   readback, statistics) and [`GpuRenderer::render_to_texture`];
//! - low level: [`GpuRenderer::prepare`] uploads a scene, [`GpuRenderer::encode_trace`]
//!   and [`GpuRenderer::encode_display`] record passes into the caller's encoder.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use wgpu::util::DeviceExt;

use super::GpuError;
use super::features::ShaderFeatures;
use super::layout::{DisplayUniforms, FrameUniforms};
use super::readback::{
    Caught, align_up, capture, map_read, read_buffer, read_texture, submit_and_wait,
};
use super::shaders::{
    DISPLAY_ENTRY_POINT, TRACE_ENTRY_POINT, WORKGROUP_SIZE, display_shader_source,
    trace_shader_source,
};
use super::upload::{SceneRecords, frame_uniforms, image_layers};
use crate::film::{LinearImage, ProgressFn, RenderStats};
use crate::scene::Scene;

/// Most pixel samples (`rows × width × samples_per_pixel`) traced by one submission
/// of [`GpuRenderer::render`]. Each chunk is submitted and waited for on its own, so
/// no single dispatch runs long enough to trip an OS GPU watchdog (about 2 s on
/// Windows), and progress can be reported between chunks. 2^21 samples take well under
/// a second on lavapipe for moderate scenes. A single row wider than this is still
/// traced as one chunk.
pub const MAX_CHUNK_SAMPLES: u64 = 1 << 21;

/// Default bound on one wait for the GPU; see [`GpuRenderer::with_poll_timeout`].
pub const DEFAULT_POLL_TIMEOUT: Duration = Duration::from_secs(120);

/// Format of the linear radiance texture the trace pass writes.
pub const LINEAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the display texture (sRGB encoding is done in the shader because
/// `Rgba8UnormSrgb` cannot be a storage texture).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The GPU tracer's pipelines, built for one device.
///
/// ```no_run
/// use gpu_render::gpu::{AdapterChoice, GpuRenderer, HeadlessGpu};
/// # fn demo(scene: &gpu_render::scene::Scene) -> Result<(), gpu_render::gpu::GpuError> {
/// let gpu = HeadlessGpu::new(&AdapterChoice::Default)?;
/// let renderer = GpuRenderer::new(&gpu.device)?;
/// let progress = |done: u32, total: u32| eprintln!("{done}/{total} rows");
/// let out = renderer.render(&gpu.device, &gpu.queue, scene, Some(&progress))?;
/// assert_eq!(out.display_rgba8.len(), out.image.pixels.len() * 4);
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct GpuRenderer {
    trace_bind_group_layout: wgpu::BindGroupLayout,
    trace_pipeline_layout: wgpu::PipelineLayout,
    display_bind_group_layout: wgpu::BindGroupLayout,
    display_pipeline: wgpu::ComputePipeline,
    /// Trace pipelines by bounce-stack size and shader features, built on first use:
    /// both are compiled into the module, and most runs need only one.
    trace_pipelines: Mutex<HashMap<(u32, ShaderFeatures), wgpu::ComputePipeline>>,
    poll_timeout: Duration,
    /// Whether trace modules are specialised to each scene's features (the default)
    /// or always contain every feature.
    specialise: bool,
}

/// A scene uploaded to one device: the storage buffers, the per-row ray counters and
/// the frame constants, ready for [`GpuRenderer::encode_trace`].
///
/// The ray counters accumulate over every trace recorded with this scene; clear them
/// with [`GpuRenderer::encode_clear_ray_counts`] before re-rendering.
#[derive(Debug)]
pub struct PreparedScene {
    frame: FrameUniforms,
    stack_size: u32,
    features: ShaderFeatures,
    encode_srgb: bool,
    spheres: wgpu::Buffer,
    planes: wgpu::Buffer,
    polygons: wgpu::Buffer,
    polygon_vertices: wgpu::Buffer,
    triangles: wgpu::Buffer,
    materials: wgpu::Buffer,
    lights: wgpu::Buffer,
    ray_counts: wgpu::Buffer,
    /// Running sums of one sample dispatch to the next, for up to `accumulation_rows`.
    accumulation: wgpu::Buffer,
    /// Albedo textures and BRDF maps, one layer each (see [`image_layers`]).
    images: wgpu::TextureView,
}

impl PreparedScene {
    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.frame.width
    }

    /// Image height in pixels (also the number of ray counters).
    pub fn height(&self) -> u32 {
        self.frame.height
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.frame.samples_per_pixel
    }

    /// Bounce-stack capacity, which selects the trace pipeline.
    pub fn stack_size(&self) -> u32 {
        self.stack_size
    }

    /// The shader features the trace pipeline for this scene contains.
    pub fn features(&self) -> ShaderFeatures {
        self.features
    }

    /// Whether the display pass should apply the sRGB curve for this scene (false in
    /// naive gamma mode).
    pub fn display_encodes_srgb(&self) -> bool {
        self.encode_srgb
    }

    /// The frame constants for the whole image (`row_offset` 0, `row_count` height).
    pub fn frame_uniforms(&self) -> &FrameUniforms {
        &self.frame
    }

    /// The ray counters: one `u32` per image row (`STORAGE | COPY_SRC | COPY_DST`).
    pub fn ray_count_buffer(&self) -> &wgpu::Buffer {
        &self.ray_counts
    }
}

/// The result of [`GpuRenderer::render`].
#[derive(Debug, Clone, PartialEq)]
pub struct GpuRendered {
    /// The linear radiance image, as traced.
    pub image: LinearImage,
    /// The display pass's output: `width × height` RGBA8 pixels, row-major, top row
    /// first, sRGB-encoded unless the scene is in naive gamma mode.
    pub display_rgba8: Vec<u8>,
    /// Rays traced (summed from the per-row counters), the wall time of tracing and,
    /// where the device has timestamp queries, its GPU time.
    pub stats: RenderStats,
}

fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

fn storage_texture_entry(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
    )
}

fn buffer_binding(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// Checks that `view`'s texture has `format`, `usage` and at least `width × height`.
fn check_texture(
    view: &wgpu::TextureView,
    role: &str,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    width: u32,
    height: u32,
) -> Result<(), GpuError> {
    let texture = view.texture();
    if texture.format() != format {
        return Err(GpuError::Validation(format!(
            "{role} texture must be {format:?}, got {:?}",
            texture.format()
        )));
    }
    if !texture.usage().contains(usage) {
        return Err(GpuError::Validation(format!(
            "{role} texture needs usage {usage:?}, has {:?}",
            texture.usage()
        )));
    }
    if texture.width() < width || texture.height() < height {
        return Err(GpuError::Validation(format!(
            "{role} texture is {}x{}, the image is {width}x{height}",
            texture.width(),
            texture.height()
        )));
    }
    Ok(())
}

/// The row ranges [`GpuRenderer::render`] dispatches for an image of `width × height`
/// with `samples_per_pixel`: consecutive, covering every row once, each at most
/// [`MAX_CHUNK_SAMPLES`] samples (or one row, if a row alone is more).
pub fn row_chunks(width: u32, height: u32, samples_per_pixel: u32) -> Vec<Range<u32>> {
    let samples_per_row = (u64::from(width) * u64::from(samples_per_pixel)).max(1);
    let rows_per_chunk = (MAX_CHUNK_SAMPLES / samples_per_row).clamp(1, u64::from(u32::MAX));
    let rows_per_chunk = rows_per_chunk as u32;
    let mut chunks = Vec::new();
    let mut start = 0;
    while start < height {
        let end = start.saturating_add(rows_per_chunk).min(height);
        chunks.push(start..end);
        start = end;
    }
    chunks
}

impl GpuRenderer {
    /// Builds the bind group layouts and the display pipeline on `device`. Trace
    /// pipelines are built on first use for each stack size.
    ///
    /// Errors: [`GpuError::Shader`] if the display shader fails to compile.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        // Explicit layouts: an automatic layout would drop bindings a shader leaves
        // unused, and the bind groups below would no longer match it.
        let trace_bind_group_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("gpu-render trace bindings"),
                entries: &[
                    uniform_entry(0),
                    storage_entry(1, true),
                    storage_entry(2, true),
                    storage_entry(3, true),
                    storage_entry(4, true),
                    storage_entry(5, true),
                    storage_entry(6, true),
                    storage_entry(7, true),
                    storage_texture_entry(8, LINEAR_FORMAT),
                    storage_entry(9, false),
                    storage_entry(10, false),
                    compute_entry(
                        11,
                        wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                    ),
                ],
            });
        let trace_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("gpu-render trace layout"),
                bind_group_layouts: &[Some(&trace_bind_group_layout)],
                immediate_size: 0,
            });
        let display_bind_group_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("gpu-render display bindings"),
                entries: &[
                    uniform_entry(0),
                    compute_entry(
                        1,
                        wgpu::BindingType::Texture {
                            // Rgba32Float is not filterable without an extra feature;
                            // the pass only uses textureLoad.
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                    ),
                    storage_texture_entry(2, DISPLAY_FORMAT),
                ],
            });
        let display_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("gpu-render display layout"),
                bind_group_layouts: &[Some(&display_bind_group_layout)],
                immediate_size: 0,
            });
        let display_pipeline = build_pipeline(
            device,
            "display",
            display_shader_source(),
            &display_pipeline_layout,
            DISPLAY_ENTRY_POINT,
        )?;
        Ok(Self {
            trace_bind_group_layout,
            trace_pipeline_layout,
            display_bind_group_layout,
            display_pipeline,
            trace_pipelines: Mutex::new(HashMap::new()),
            poll_timeout: DEFAULT_POLL_TIMEOUT,
            specialise: true,
        })
    }

    /// Sets the longest this renderer waits for one submission (one chunk, the display
    /// pass, one readback) before reporting [`GpuError::DeviceLost`] instead of hanging.
    /// Default: [`DEFAULT_POLL_TIMEOUT`].
    pub fn with_poll_timeout(mut self, timeout: Duration) -> Self {
        self.poll_timeout = timeout;
        self
    }

    /// With `false`, every trace module contains every feature (the general shader)
    /// instead of only what each scene uses. For measurements and tests; the default,
    /// `true`, is faster to run and to compile.
    pub fn with_specialisation(mut self, specialise: bool) -> Self {
        self.specialise = specialise;
        self
    }

    /// The trace pipeline for `stack_size` and `features`, built and cached on first
    /// use. Prepared scenes carry their features ([`PreparedScene::features`]).
    ///
    /// Errors: [`GpuError::Shader`] if the composed trace shader does not compile.
    pub fn trace_pipeline(
        &self,
        device: &wgpu::Device,
        stack_size: u32,
        features: &ShaderFeatures,
    ) -> Result<wgpu::ComputePipeline, GpuError> {
        let mut cache = self
            .trace_pipelines
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        if let Some(pipeline) = cache.get(&(stack_size, *features)) {
            return Ok(pipeline.clone());
        }
        let source = trace_shader_source(stack_size, features).map_err(GpuError::Shader)?;
        let pipeline = build_pipeline(
            device,
            &format!("trace (stack size {stack_size}, {})", features.label()),
            source,
            &self.trace_pipeline_layout,
            TRACE_ENTRY_POINT,
        )?;
        cache.insert((stack_size, *features), pipeline.clone());
        Ok(pipeline)
    }

    /// How many trace pipelines have been built and cached so far.
    pub fn cached_pipeline_count(&self) -> usize {
        self.trace_pipelines
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .len()
    }

    /// Uploads `scene` (converted with [`Scene::in_lighting_space`] here, so pass the
    /// scene as loaded) and allocates its per-row ray counters.
    ///
    /// Errors: [`GpuError::DeviceLimit`] if the image or a buffer exceeds the device's
    /// limits, [`GpuError::OutOfMemory`] if an allocation fails,
    /// [`GpuError::Validation`] if the render settings are out of range.
    pub fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
    ) -> Result<PreparedScene, GpuError> {
        scene.render.check().map_err(GpuError::Validation)?;
        let scene = scene.in_lighting_space();
        let records = SceneRecords::from_scene(&scene);
        let frame = frame_uniforms(&scene, &records);
        let limits = device.limits();
        let over = |what: &str, value: u64, limit: u64| {
            if value > limit {
                Err(GpuError::DeviceLimit {
                    what: what.to_string(),
                    value,
                    limit,
                })
            } else {
                Ok(())
            }
        };
        // The image may exceed max_texture_dimension_2d: render() then traces it in
        // tiles (see `image_tiles`). What one dispatch covers is checked against the
        // workgroup-count limit in encode_trace_region.

        let padded = records.padded();
        let max_binding = limits.max_storage_buffer_binding_size;
        let max_buffer = limits.max_buffer_size;
        let upload = |what: &str, bytes: &[u8]| -> Result<wgpu::Buffer, GpuError> {
            let size = bytes.len() as u64;
            over(
                &format!("{what} buffer bytes"),
                size,
                max_binding.min(max_buffer),
            )?;
            let buffer = capture(device, what, Caught::Resource, || {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(what),
                    size,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })?;
            // write_buffer stages through the queue: no mapped_at_creation, whose
            // mapping would panic if the allocation had failed.
            queue.write_buffer(&buffer, 0, bytes);
            Ok(buffer)
        };
        let spheres = upload("sphere", bytemuck::cast_slice(&padded.spheres))?;
        let planes = upload("plane", bytemuck::cast_slice(&padded.planes))?;
        let polygons = upload("polygon", bytemuck::cast_slice(&padded.polygons))?;
        let polygon_vertices = upload(
            "polygon vertex",
            bytemuck::cast_slice(&padded.polygon_vertices),
        )?;
        let triangles = upload("triangle", bytemuck::cast_slice(&padded.triangles))?;
        let materials = upload("material", bytemuck::cast_slice(&padded.materials))?;
        let lights = upload("light", bytemuck::cast_slice(&padded.lights))?;
        let ray_count_bytes = u64::from(frame.height) * 4;
        over(
            "ray counter buffer bytes",
            ray_count_bytes,
            max_binding.min(max_buffer),
        )?;
        let ray_counts = capture(device, "ray counters", Caught::Resource, || {
            // wgpu zero-initialises new buffers, so the counters start at 0.
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render ray counters"),
                size: ray_count_bytes,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        })?;
        // Radiance sums for as many rows as one storage binding holds; larger row
        // ranges are traced in bands of that many rows.
        let row_bytes = u64::from(frame.width) * 16;
        let accumulation_rows = (max_binding.min(max_buffer) / row_bytes)
            .min(u64::from(frame.height))
            .max(1) as u32;
        let accumulation = capture(device, "accumulation", Caught::Resource, || {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render accumulation"),
                size: row_bytes * u64::from(accumulation_rows),
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        })?;
        let frame = FrameUniforms {
            accumulation_rows,
            ..frame
        };
        let images = upload_images(device, queue, &scene, &limits)?;
        Ok(PreparedScene {
            frame,
            accumulation,
            stack_size: scene.render.stack_size,
            features: if self.specialise {
                ShaderFeatures::for_scene(&scene)
            } else {
                ShaderFeatures::ALL
            },
            encode_srgb: scene.display_encodes_srgb(),
            spheres,
            planes,
            polygons,
            polygon_vertices,
            triangles,
            materials,
            lights,
            ray_counts,
            images,
        })
    }

    /// Records the trace of image rows `rows` into `encoder`, writing linear radiance
    /// into `target` and adding to the prepared scene's ray counters: one dispatch per
    /// sample index (each adds one sample of every pixel to a running sum; the last
    /// writes the mean), in bands of rows that fit the accumulation buffer.
    ///
    /// `target` must view an [`LINEAR_FORMAT`] (`Rgba32Float`) texture with
    /// `STORAGE_BINDING` usage, at least as large as the image. Each call creates a
    /// small uniform buffer per dispatch holding the frame constants with its
    /// `row_offset`/`row_count`/`sample_index`, initialised at creation: unlike `Queue::write_buffer`
    /// (which lands before the whole submission), this lets several chunks be recorded
    /// into one encoder. wgpu keeps the buffer alive until the work completes. An empty
    /// range records nothing.
    ///
    /// Errors: [`GpuError::Validation`] for an out-of-range `rows` or an unsuitable
    /// target, [`GpuError::Shader`] if the trace pipeline cannot be built. Validation of
    /// the recorded pass itself happens when the caller finishes the encoder.
    ///
    /// ```no_run
    /// # fn demo(gpu: &gpu_render::gpu::HeadlessGpu, scene: &gpu_render::scene::Scene)
    /// # -> Result<(), gpu_render::gpu::GpuError> {
    /// # let (device, queue) = (&gpu.device, &gpu.queue);
    /// let renderer = gpu_render::gpu::GpuRenderer::new(device)?;
    /// let prepared = renderer.prepare(device, queue, scene)?;
    /// let texture = device.create_texture(&wgpu::TextureDescriptor {
    ///     label: Some("linear"),
    ///     size: wgpu::Extent3d { width: prepared.width(), height: prepared.height(), depth_or_array_layers: 1 },
    ///     mip_level_count: 1,
    ///     sample_count: 1,
    ///     dimension: wgpu::TextureDimension::D2,
    ///     format: wgpu::TextureFormat::Rgba32Float,
    ///     usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
    ///     view_formats: &[],
    /// });
    /// let view = texture.create_view(&Default::default());
    /// let mut encoder = device.create_command_encoder(&Default::default());
    /// renderer.encode_trace(device, &mut encoder, &prepared, &view, 0..prepared.height())?;
    /// queue.submit([encoder.finish()]);
    /// # Ok(())
    /// # }
    /// ```
    pub fn encode_trace(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        rows: Range<u32>,
    ) -> Result<(), GpuError> {
        let region = TraceRegion {
            columns: 0..prepared.width(),
            rows,
            target_origin: (0, 0),
        };
        self.encode_trace_region(device, encoder, prepared, target, &region)
    }

    /// Records one trace dispatch of the image pixels in `region` into `encoder`,
    /// writing each pixel (x, y) to texel (x, y) − `region.target_origin` of `target`,
    /// which must be large enough for that. This is how images larger than the device's
    /// texture limit are traced, one tile-sized target at a time. Like
    /// [`GpuRenderer::encode_trace`], it writes no timestamps: time the caller's own
    /// passes or submissions if needed.
    ///
    /// Errors: as [`GpuRenderer::encode_trace`], and [`GpuError::DeviceLimit`] when the
    /// region needs more workgroups than `max_compute_workgroups_per_dimension`.
    pub fn encode_trace_region(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
    ) -> Result<(), GpuError> {
        self.encode_timed_trace_region(device, encoder, prepared, target, region, None)
            .map(|_| ())
    }

    /// [`GpuRenderer::encode_trace_region`], and with `timestamps` writes a timestamp
    /// at the beginning of the first trace pass it records and at the end of the last.
    /// Returns how many passes it recorded (none for an empty region, and then no
    /// timestamps are written).
    fn encode_timed_trace_region(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        timestamps: Option<ChunkTimestamps<'_>>,
    ) -> Result<u64, GpuError> {
        let TraceRegion {
            columns,
            rows,
            target_origin: (origin_x, origin_y),
        } = region.clone();
        if rows.start > rows.end || rows.end > prepared.height() {
            return Err(GpuError::Validation(format!(
                "row range {rows:?} is outside the image's {} rows",
                prepared.height()
            )));
        }
        if columns.start > columns.end || columns.end > prepared.width() {
            return Err(GpuError::Validation(format!(
                "column range {columns:?} is outside the image's {} columns",
                prepared.width()
            )));
        }
        if origin_x > columns.start || origin_y > rows.start {
            return Err(GpuError::Validation(format!(
                "target origin ({origin_x}, {origin_y}) lies after the region's first pixel \
                 ({}, {})",
                columns.start, rows.start
            )));
        }
        if rows.is_empty() || columns.is_empty() {
            return Ok(0);
        }
        check_texture(
            target,
            "trace target",
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
            columns.end - origin_x,
            rows.end - origin_y,
        )?;
        let max_groups = device.limits().max_compute_workgroups_per_dimension;
        let groups_x = (columns.end - columns.start).div_ceil(WORKGROUP_SIZE);
        let groups_y = (rows.end - rows.start).div_ceil(WORKGROUP_SIZE);
        for (what, groups) in [("columns", groups_x), ("rows", groups_y)] {
            if groups > max_groups {
                return Err(GpuError::DeviceLimit {
                    what: format!("workgroups for the {what} of one trace dispatch"),
                    value: u64::from(groups),
                    limit: u64::from(max_groups),
                });
            }
        }
        let pipeline = self.trace_pipeline(device, prepared.stack_size, &prepared.features)?;
        let band_rows = prepared.frame.accumulation_rows.max(1);
        let samples = prepared.samples_per_pixel();
        let mut passes = 0;
        let mut band_start = rows.start;
        while band_start < rows.end {
            let band_end = rows.end.min(band_start.saturating_add(band_rows));
            for sample_index in 0..samples {
                let dispatch = FrameUniforms {
                    row_offset: band_start,
                    row_count: band_end - band_start,
                    column_offset: columns.start,
                    column_count: columns.end - columns.start,
                    target_x: origin_x,
                    target_y: origin_y,
                    sample_index,
                    ..prepared.frame
                };
                let first = band_start == rows.start && sample_index == 0;
                let last = band_end == rows.end && sample_index + 1 == samples;
                // Only the chunk's first and last pass write (wgpu rejects a pass
                // timestamp write with neither index).
                let timestamp_writes = timestamps.filter(|_| first || last).map(|chunk| {
                    wgpu::ComputePassTimestampWrites {
                        query_set: chunk.query_set,
                        beginning_of_pass_write_index: first.then_some(chunk.begin),
                        end_of_pass_write_index: last.then_some(chunk.begin + 1),
                    }
                });
                self.encode_trace_dispatch(
                    device,
                    encoder,
                    prepared,
                    target,
                    &pipeline,
                    &dispatch,
                    timestamp_writes,
                )?;
                passes += 1;
            }
            band_start = band_end;
        }
        Ok(passes)
    }

    /// Records one dispatch of the trace pass: one sample of every pixel in the region
    /// `dispatch` names, writing the timestamps `timestamp_writes` asks for.
    #[allow(clippy::too_many_arguments)]
    fn encode_trace_dispatch(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        pipeline: &wgpu::ComputePipeline,
        dispatch: &FrameUniforms,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> Result<(), GpuError> {
        let bind_group = capture(device, "trace bind group", Caught::Resource, || {
            let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("gpu-render dispatch uniforms"),
                contents: bytemuck::bytes_of(dispatch),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gpu-render trace bind group"),
                layout: &self.trace_bind_group_layout,
                entries: &[
                    buffer_binding(0, &uniforms),
                    buffer_binding(1, &prepared.spheres),
                    buffer_binding(2, &prepared.planes),
                    buffer_binding(3, &prepared.polygons),
                    buffer_binding(4, &prepared.polygon_vertices),
                    buffer_binding(5, &prepared.triangles),
                    buffer_binding(6, &prepared.materials),
                    buffer_binding(7, &prepared.lights),
                    wgpu::BindGroupEntry {
                        binding: 8,
                        resource: wgpu::BindingResource::TextureView(target),
                    },
                    buffer_binding(9, &prepared.ray_counts),
                    buffer_binding(10, &prepared.accumulation),
                    wgpu::BindGroupEntry {
                        binding: 11,
                        resource: wgpu::BindingResource::TextureView(&prepared.images),
                    },
                ],
            })
        })?;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gpu-render trace"),
            timestamp_writes,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(
            dispatch.column_count.div_ceil(WORKGROUP_SIZE),
            dispatch.row_count.div_ceil(WORKGROUP_SIZE),
            1,
        );
        Ok(())
    }

    /// Records a clear of the prepared scene's ray counters into `encoder`.
    pub fn encode_clear_ray_counts(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedScene,
    ) {
        encoder.clear_buffer(&prepared.ray_counts, 0, None);
    }

    /// Reads the prepared scene's ray counters (after the traces that fill them have
    /// been submitted) and returns their sum. Each row's counter is a `u32` that wraps
    /// past 2^32 rays in one row; the sum is taken in `u64`.
    pub fn read_ray_count(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
    ) -> Result<u64, GpuError> {
        let bytes = read_buffer(
            device,
            queue,
            &prepared.ray_counts,
            u64::from(prepared.height()) * 4,
            self.poll_timeout,
        )?;
        Ok(bytes
            .chunks_exact(4)
            .map(|c| u64::from(u32::from_ne_bytes([c[0], c[1], c[2], c[3]])))
            .sum())
    }

    /// Records the display pass into `encoder`: reads `linear` (an `Rgba32Float`
    /// texture with `TEXTURE_BINDING`), applies the exact sRGB curve if `encode_srgb`
    /// (else clamps only), quantises to 8 bits and writes `display` (an `Rgba8Unorm`
    /// texture with `STORAGE_BINDING` of the same size).
    ///
    /// Errors: [`GpuError::Validation`] for unsuitable textures.
    pub fn encode_display(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        linear: &wgpu::TextureView,
        display: &wgpu::TextureView,
        encode_srgb: bool,
    ) -> Result<(), GpuError> {
        let (width, height) = (linear.texture().width(), linear.texture().height());
        check_texture(
            linear,
            "display input",
            LINEAR_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
            width,
            height,
        )?;
        check_texture(
            display,
            "display output",
            DISPLAY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
            width,
            height,
        )?;
        let uniforms = DisplayUniforms {
            encode_srgb: u32::from(encode_srgb),
            _pad: [0; 3],
        };
        let bind_group = capture(device, "display bind group", Caught::Resource, || {
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("gpu-render display uniforms"),
                contents: bytemuck::bytes_of(&uniforms),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gpu-render display bind group"),
                layout: &self.display_bind_group_layout,
                entries: &[
                    buffer_binding(0, &buffer),
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(linear),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(display),
                    },
                ],
            })
        })?;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gpu-render display"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.display_pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(
            width.div_ceil(WORKGROUP_SIZE),
            height.div_ceil(WORKGROUP_SIZE),
            1,
        );
        Ok(())
    }

    /// Renders `scene` completely: traces it in row chunks (see [`MAX_CHUNK_SAMPLES`]),
    /// each submitted and waited for, calling `progress(rows_done, height)` after each;
    /// an image wider or taller than the device's `max_texture_dimension_2d` is traced
    /// in tiles ([`image_tiles`]), each into a texture of its own, display-encoded and
    /// read back into its place (`rows_done` then counts finished pixels / width);
    /// runs the display pass; reads back both images and the ray counters.
    /// `stats.elapsed` covers the tracing submissions only (not upload, display pass or
    /// readback); the trace pipeline is built before the clock starts.
    ///
    /// Where `device` has [`wgpu::Features::TIMESTAMP_QUERY`] (which
    /// [`super::HeadlessGpu`] requests when the adapter offers it), `stats.gpu_time` is
    /// the GPU's own time of the trace passes: each chunk writes a timestamp at the
    /// beginning of its first pass and at the end of its last, into query sets of up to
    /// [`wgpu::QUERY_SET_MAX_QUERIES`] (as many as the chunks need), resolved and read
    /// back once after the last chunk; the tick differences, times
    /// [`wgpu::Queue::get_timestamp_period`], are summed over chunks. It is `None` on
    /// other devices, and where the timestamps cannot be trusted (one went backwards, or
    /// the period is not a positive number).
    ///
    /// Errors: see [`GpuRenderer::prepare`]; [`GpuError::DeviceLost`] if the device
    /// fails or a chunk exceeds the poll timeout; [`GpuError::Readback`].
    pub fn render(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<GpuRendered, GpuError> {
        let prepared = self.prepare(device, queue, scene)?;
        let (width, height) = (prepared.width(), prepared.height());
        let limits = device.limits();
        // A tile must fit one texture and one dispatch's workgroup count.
        let tile_limit = limits.max_texture_dimension_2d.min(
            limits
                .max_compute_workgroups_per_dimension
                .saturating_mul(WORKGROUP_SIZE),
        );
        let tiles = image_tiles(width, height, tile_limit);
        let mut pixels = vec![[0.0f32; 4]; width as usize * height as usize];
        let mut display_rgba8 = vec![0u8; width as usize * height as usize * 4];
        // Progress is reported in image rows: pixels finished / width, so that a tiled
        // image reports like an untiled one.
        let pixels_done = std::sync::atomic::AtomicU64::new(0);
        let report = |pixels: u64| {
            let done = pixels_done.fetch_add(pixels, std::sync::atomic::Ordering::Relaxed) + pixels;
            if let Some(progress) = progress {
                progress((done / u64::from(width)) as u32, height);
            }
        };
        let mut timer = TraceTimer::for_device(device);
        let mut elapsed = Duration::ZERO;
        for tile in &tiles {
            let (tile_width, tile_height) = (
                tile.columns.end - tile.columns.start,
                tile.rows.end - tile.rows.start,
            );
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

            elapsed += self.trace_region_chunks(
                device,
                queue,
                &prepared,
                &linear_view,
                tile,
                &report,
                timer.as_mut(),
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
            let display_bytes = read_texture(device, queue, &display, 4, self.poll_timeout)?;
            // pod_collect_to_vec copies, so the byte vector's alignment does not matter.
            let tile_pixels: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&linear_bytes);
            let tile_width = tile_width as usize;
            for (row, y) in tile.rows.clone().enumerate() {
                let start = y as usize * width as usize + tile.columns.start as usize;
                pixels[start..start + tile_width]
                    .copy_from_slice(&tile_pixels[row * tile_width..(row + 1) * tile_width]);
                display_rgba8[start * 4..(start + tile_width) * 4].copy_from_slice(
                    &display_bytes[row * tile_width * 4..(row + 1) * tile_width * 4],
                );
            }
        }
        let gpu_time = match timer {
            Some(timer) => timer.read(device, queue, self.poll_timeout)?,
            None => None,
        };
        let stats = RenderStats {
            rays_traced: self.read_ray_count(device, queue, &prepared)?,
            elapsed,
            gpu_time,
        };
        Ok(GpuRendered {
            image: LinearImage {
                width,
                height,
                pixels,
            },
            display_rgba8,
            stats,
        })
    }

    /// Traces `scene` into the caller's `target` (an `Rgba32Float` texture with
    /// `STORAGE_BINDING`, at least image-sized), chunked and timed like
    /// [`GpuRenderer::render`], without the display pass or image readback. Returns the
    /// ray count and trace time (with GPU time as [`GpuRenderer::render`] describes).
    ///
    /// Errors: as [`GpuRenderer::render`], and [`GpuError::DeviceLimit`] for an image
    /// larger than `max_texture_dimension_2d`, which no single target can hold (use
    /// [`GpuRenderer::render`], which tiles, or [`GpuRenderer::encode_trace_region`]).
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
        let whole = TraceRegion {
            columns: 0..prepared.width(),
            rows: 0..prepared.height(),
            target_origin: (0, 0),
        };
        let rows_done = std::sync::atomic::AtomicU32::new(0);
        let width = u64::from(prepared.width());
        let row_report = |pixels: u64| {
            let rows = (pixels / width) as u32;
            let done = rows_done.fetch_add(rows, std::sync::atomic::Ordering::Relaxed) + rows;
            if let Some(progress) = progress {
                progress(done, prepared.height());
            }
        };
        let mut timer = TraceTimer::for_device(device);
        let elapsed = self.trace_region_chunks(
            device,
            queue,
            &prepared,
            target,
            &whole,
            &row_report,
            timer.as_mut(),
        )?;
        let gpu_time = match timer {
            Some(timer) => timer.read(device, queue, self.poll_timeout)?,
            None => None,
        };
        Ok(RenderStats {
            rays_traced: self.read_ray_count(device, queue, &prepared)?,
            elapsed,
            gpu_time,
        })
    }

    /// Traces the rows of `region` in chunks (see [`row_chunks`], split further to stay
    /// within `max_compute_workgroups_per_dimension`), one submission and
    /// wait each, calling `report(pixels)` after each chunk with the pixels it traced;
    /// returns the wall time spent tracing. With a `timer`, each chunk's first and last
    /// trace pass write a pair of timestamps into it (read later with
    /// [`TraceTimer::read`]).
    #[allow(clippy::too_many_arguments)]
    fn trace_region_chunks(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &PreparedScene,
        target: &wgpu::TextureView,
        region: &TraceRegion,
        report: &dyn Fn(u64),
        mut timer: Option<&mut TraceTimer>,
    ) -> Result<Duration, GpuError> {
        // Compile before timing: shader and pipeline creation is not tracing.
        self.trace_pipeline(device, prepared.stack_size, &prepared.features)?;
        let start = Instant::now();
        let region_width = region.columns.end - region.columns.start;
        // Rows per dispatch are also bounded by the workgroup-count limit.
        let max_rows = device
            .limits()
            .max_compute_workgroups_per_dimension
            .saturating_mul(WORKGROUP_SIZE)
            .max(1);
        let chunks: Vec<Range<u32>> = row_chunks(
            region_width,
            region.rows.end - region.rows.start,
            prepared.samples_per_pixel(),
        )
        .into_iter()
        .flat_map(|chunk| {
            chunk
                .clone()
                .step_by(max_rows as usize)
                .map(move |start| start..chunk.end.min(start.saturating_add(max_rows)))
        })
        .collect();
        // Query sets are created up front, outside the chunk loop's submissions.
        if let Some(timer) = timer.as_deref_mut() {
            timer.reserve(device, chunks.len())?;
        }
        for chunk in chunks {
            let rows = region.rows.start + chunk.start..region.rows.start + chunk.end;
            let pixels = u64::from(rows.end - rows.start) * u64::from(region_width);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gpu-render trace chunk"),
            });
            let chunk_region = TraceRegion {
                rows,
                ..region.clone()
            };
            let slot = timer.as_deref().and_then(TraceTimer::next_slot);
            let timed = slot.is_some();
            let passes = self.encode_timed_trace_region(
                device,
                &mut encoder,
                prepared,
                target,
                &chunk_region,
                slot,
            )?;
            submit_and_wait(device, queue, encoder, "trace chunk", self.poll_timeout)?;
            if let Some(timer) = timer.as_deref_mut() {
                timer.record(timed, passes > 0);
            }
            report(pixels);
        }
        Ok(start.elapsed())
    }
}

/// Where one chunk writes its two timestamps: `begin` at the start of its first trace
/// pass, `begin + 1` at the end of its last.
#[derive(Debug, Clone, Copy)]
struct ChunkTimestamps<'a> {
    query_set: &'a wgpu::QuerySet,
    begin: u32,
}

/// One timestamp query set of a [`TraceTimer`] and how many of its queries are taken.
#[derive(Debug)]
struct TimerSet {
    query_set: wgpu::QuerySet,
    capacity: u32,
    used: u32,
}

/// GPU timestamps around the trace passes of one render: a pair of queries per chunk,
/// in as many query sets of up to [`wgpu::QUERY_SET_MAX_QUERIES`] as the chunks need,
/// resolved and read back once after the last chunk ([`TraceTimer::read`]).
#[derive(Debug)]
struct TraceTimer {
    sets: Vec<TimerSet>,
    /// A chunk was traced without timestamps, so their sum would not cover the trace.
    incomplete: bool,
}

impl TraceTimer {
    /// A timer for `device` if it has [`wgpu::Features::TIMESTAMP_QUERY`], else `None`.
    fn for_device(device: &wgpu::Device) -> Option<Self> {
        device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| Self {
                sets: Vec::new(),
                incomplete: false,
            })
    }

    /// Creates query sets until `chunks` more pairs of queries are free.
    fn reserve(&mut self, device: &wgpu::Device, chunks: usize) -> Result<(), GpuError> {
        let free: u64 = self
            .sets
            .iter()
            .map(|set| u64::from((set.capacity - set.used) / 2))
            .sum();
        let mut needed = (chunks as u64).saturating_sub(free);
        while needed > 0 {
            let capacity = needed
                .saturating_mul(2)
                .min(u64::from(wgpu::QUERY_SET_MAX_QUERIES)) as u32;
            let query_set = capture(device, "timestamp query set", Caught::Resource, || {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("gpu-render trace timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: capacity,
                })
            })?;
            self.sets.push(TimerSet {
                query_set,
                capacity,
                used: 0,
            });
            needed -= u64::from(capacity / 2);
        }
        Ok(())
    }

    /// The set and first query of the next free pair, if any.
    fn free_pair(&self) -> Option<(usize, u32)> {
        self.sets
            .iter()
            .position(|set| set.capacity - set.used >= 2)
            .map(|index| (index, self.sets[index].used))
    }

    /// Where the next chunk should write its timestamps (`None` if nothing was
    /// reserved for it).
    fn next_slot(&self) -> Option<ChunkTimestamps<'_>> {
        self.free_pair().map(|(index, begin)| ChunkTimestamps {
            query_set: &self.sets[index].query_set,
            begin,
        })
    }

    /// Records that a chunk was submitted: with its timestamps (`timed`, from
    /// [`TraceTimer::next_slot`]) or without, and whether it `traced` any pass (a chunk
    /// with no pass writes no timestamps and needs none).
    fn record(&mut self, timed: bool, traced: bool) {
        if !traced {
            return;
        }
        match self.free_pair() {
            Some((index, _)) if timed => self.sets[index].used += 2,
            _ => self.incomplete = true,
        }
    }

    /// Resolves and reads every recorded timestamp (one submission and one map, after
    /// all chunks) and returns the sum over chunks of last-pass end minus first-pass
    /// start, times the queue's timestamp period. `None` when a chunk went untimed, a
    /// timestamp went backwards (a counter wrapped) or the period is unusable.
    fn read(
        self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        timeout: Duration,
    ) -> Result<Option<Duration>, GpuError> {
        if self.incomplete {
            return Ok(None);
        }
        // Nanoseconds per timestamp tick.
        let period_ns = f64::from(queue.get_timestamp_period());
        if !(period_ns.is_finite() && period_ns > 0.0) {
            return Ok(None);
        }
        // Each set resolves at an offset aligned as resolve_query_set requires.
        let mut offsets = Vec::with_capacity(self.sets.len());
        let mut size = 0;
        for set in &self.sets {
            offsets.push(size);
            size = align_up(
                size + u64::from(set.used) * u64::from(wgpu::QUERY_SIZE),
                wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT,
            );
        }
        if size == 0 {
            return Ok(Some(Duration::ZERO));
        }
        let (resolve, staging) = capture(device, "timestamp buffers", Caught::Resource, || {
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render timestamp readback"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            (resolve, staging)
        })?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render timestamp resolve"),
        });
        for (set, &offset) in self.sets.iter().zip(&offsets) {
            if set.used > 0 {
                encoder.resolve_query_set(&set.query_set, 0..set.used, &resolve, offset);
            }
        }
        encoder.copy_buffer_to_buffer(&resolve, 0, &staging, 0, size);
        submit_and_wait(device, queue, encoder, "timestamp resolve", timeout)?;
        let bytes = map_read(device, &staging, size, timeout)?;
        let tick = |index: u64| -> Option<u64> {
            let start = usize::try_from(index * u64::from(wgpu::QUERY_SIZE)).ok()?;
            let raw = bytes.get(start..start + 8)?;
            Some(u64::from_ne_bytes(raw.try_into().ok()?))
        };
        let mut ticks = 0u128;
        for (set, &offset) in self.sets.iter().zip(&offsets) {
            let first = offset / u64::from(wgpu::QUERY_SIZE);
            for pair in 0..u64::from(set.used / 2) {
                let (Some(begin), Some(end)) = (tick(first + 2 * pair), tick(first + 2 * pair + 1))
                else {
                    return Err(GpuError::Readback(
                        "timestamp readback is shorter than the queries".into(),
                    ));
                };
                let Some(chunk) = end.checked_sub(begin) else {
                    return Ok(None);
                };
                ticks += u128::from(chunk);
            }
        }
        Ok(Duration::try_from_secs_f64(ticks as f64 * period_ns * 1e-9).ok())
    }
}

/// A rectangle of image pixels traced by one dispatch, and where it lands in the
/// target texture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TraceRegion {
    /// Image columns traced.
    pub columns: Range<u32>,
    /// Image rows traced.
    pub rows: Range<u32>,
    /// The image pixel stored at texel (0, 0) of the target.
    pub target_origin: (u32, u32),
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

/// Creates a shader module and a compute pipeline inside error scopes, so that WGSL or
/// pipeline errors come back as [`GpuError::Shader`] instead of panicking.
fn build_pipeline(
    device: &wgpu::Device,
    name: &str,
    source: String,
    layout: &wgpu::PipelineLayout,
    entry_point: &str,
) -> Result<wgpu::ComputePipeline, GpuError> {
    capture(device, &format!("{name} shader"), Caught::Shader, || {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(name),
            layout: Some(layout),
            module: &module,
            entry_point: Some(entry_point),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        })
    })
}

/// Uploads the scene's images as one `Rgba32Float` 2D array texture (one layer per
/// image, see [`image_layers`]) and returns its view.
fn upload_images(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    limits: &wgpu::Limits,
) -> Result<wgpu::TextureView, GpuError> {
    let (width, height, layers, texels) = image_layers(&scene.images);
    if layers > limits.max_texture_array_layers {
        return Err(GpuError::DeviceLimit {
            what: "images (texture array layers)".to_string(),
            value: u64::from(layers),
            limit: u64::from(limits.max_texture_array_layers),
        });
    }
    let size = wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: layers,
    };
    let texture = capture(device, "image array", Caught::Resource, || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gpu-render images"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    })?;
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * 16),
            rows_per_image: Some(height),
        },
        size,
    );
    Ok(texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    }))
}

/// Creates a 2D texture inside error scopes (allocation failure becomes
/// [`GpuError::OutOfMemory`]).
fn create_texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Result<wgpu::Texture, GpuError> {
    capture(device, label, Caught::Resource, || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_cover_rows_once_within_budget() {
        for &(w, h, spp) in &[(37, 19, 1), (1920, 1080, 16), (4000, 3, 1024), (1, 1, 1)] {
            let chunks = row_chunks(w, h, spp);
            assert_eq!(chunks.first().map(|c| c.start), Some(0));
            assert_eq!(chunks.last().map(|c| c.end), Some(h));
            for pair in chunks.windows(2) {
                assert_eq!(pair[0].end, pair[1].start);
            }
            for c in &chunks {
                let samples = u64::from(c.end - c.start) * u64::from(w) * u64::from(spp);
                assert!(c.end > c.start);
                assert!(samples <= MAX_CHUNK_SAMPLES || c.end - c.start == 1);
            }
        }
        // 1920 x 16 spp = 30720 samples per row: 68 rows per chunk.
        assert_eq!(row_chunks(1920, 1080, 16)[0], 0..68);
        assert!(row_chunks(1, 0, 1).is_empty());
    }

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
