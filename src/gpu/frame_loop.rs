//! [`Renderer`]: the frame-loop API for applications that embed the tracer in their
//! own wgpu program, in the shape of vello's and glyphon's renderers. The application
//! owns the instance, adapter, device, queue, encoder and frame; the renderer uploads
//! a scene once ([`Renderer::upload`]), changes its camera on the host
//! ([`Renderer::set_camera`]), records samples into a [`Film`] without blocking
//! ([`Renderer::encode_samples`]) and shows the film in a storage texture
//! ([`Renderer::encode_display`]) or inside the application's render pass
//! ([`Renderer::draw`]). `docs/embedding.md` walks through it.

use super::draw::DrawPipelines;
use super::film::Film;
use super::gpu_scene::GpuScene;
use super::layout::FLAG_STORE_SUM;
use super::limits::{check_limits, required_limits};
use super::pipelines::{DISPLAY_FORMAT, Pipelines};
use super::readback::{read_texture, wait};
use super::renderer::create_texture;
use super::scene_buffers::{UploadOptions, upload_scene};
use super::shaders::{SLOT_WORKGROUP_SIZE, WORKGROUP_SIZE};
use super::wavefront::{Schedule, default_schedule, encode_rounds, iteration_budget_for};
use super::{GpuError, RenderError};
use crate::accel::SceneGeometry;
use crate::film::LinearImage;
use crate::noise::NoiseEstimate;
use crate::scene::{Camera, Scene, view_problem};

/// Where [`Renderer::encode_samples`] writes the few bytes a trace pass needs: a
/// [`wgpu::Queue`], or in tests a wrapper that records each write and forwards it.
pub trait BufferWrites {
    /// Schedules writing `data` into `buffer` at `offset` (as
    /// [`wgpu::Queue::write_buffer`]: before the next submission's commands).
    fn write_buffer(&self, buffer: &wgpu::Buffer, offset: wgpu::BufferAddress, data: &[u8]);
}

impl BufferWrites for wgpu::Queue {
    fn write_buffer(&self, buffer: &wgpu::Buffer, offset: wgpu::BufferAddress, data: &[u8]) {
        wgpu::Queue::write_buffer(self, buffer, offset, data);
    }
}

/// How a [`Renderer`] is built.
#[derive(Debug, Clone, PartialEq)]
pub struct RendererOptions {
    /// The colour format of the attachments [`Renderer::draw`] renders into (for
    /// example the swapchain's `Bgra8UnormSrgb`); `None` builds no draw pipeline.
    pub surface_format: Option<wgpu::TextureFormat>,
    /// How the trace kernels are dispatched; `None`: the adapter's default
    /// ([`super::default_schedule`]). The image does not depend on it.
    pub schedule: Option<Schedule>,
    /// Path slots per film; `None`: the adapter's default
    /// ([`super::default_slot_count`]). The image does not depend on it.
    pub slot_count: Option<u32>,
    /// Loop iterations per invocation and dispatch; `None`: the adapter's
    /// ([`super::iteration_budget_for`]). The image does not depend on it.
    pub iteration_budget: Option<u32>,
    /// Most rounds of the trace kernels one [`Renderer::encode_samples`] records:
    /// bounds the GPU time one call adds to a frame.
    pub max_rounds_per_call: u32,
    /// Trace shaders specialised to each scene's features (`true`, faster) or the
    /// general shader.
    pub specialise: bool,
    /// On CPU devices, bind the records of scenes small enough as uniform buffers
    /// (`true`, faster there) or always as storage buffers. The image does not depend
    /// on it.
    pub uniform_records: bool,
    /// Where the device has subgroup operations, let the fused kernel's traversals
    /// give way to lanes whose rays finished (`true`, faster on lavapipe; see
    /// [`super::ShaderFeatures::refill_lanes`]). The image does not depend on it.
    pub refill_lanes: bool,
    /// On CPU devices, test the primitives of scenes small enough unrolled instead of
    /// walking their BVH (`true`, faster there; see [`super::ShaderFeatures::unrolled`]).
    /// The image does not depend on it.
    pub unrolled: bool,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self {
            surface_format: None,
            schedule: None,
            slot_count: None,
            iteration_budget: None,
            max_rounds_per_call: 64,
            specialise: true,
            uniform_records: true,
            refill_lanes: true,
            unrolled: true,
        }
    }
}

/// The result of [`Renderer::render_to_image`]: the film's mean radiance and its
/// display values.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmImage {
    /// The mean radiance, linear.
    pub image: LinearImage,
    /// `width × height` RGBA8 display values (the scene's sRGB rule applied), row-major,
    /// top row first.
    pub display_rgba8: Vec<u8>,
    /// Samples per pixel in the image.
    pub samples: u32,
    /// Rays traced for it.
    pub rays_traced: u64,
}

/// The frame-loop renderer, built for one device: the bind group layouts and every
/// pipeline but the trace kernels, which [`Renderer::upload`] builds for each scene.
///
/// A frame loop (the application owns the device, the encoder and the frame):
///
/// ```no_run
/// use gpu_render::gpu::{Renderer, RendererOptions};
/// # fn frame_loop(adapter: &wgpu::Adapter, scene: &gpu_render::scene::Scene,
/// #               mut camera_for_frame: impl FnMut(u32) -> Option<gpu_render::scene::Camera>)
/// #               -> Result<(), Box<dyn std::error::Error>> {
/// let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
///     required_limits: Renderer::required_limits(&adapter.limits()),
///     required_features: Renderer::optional_features(adapter.features()),
///     ..Default::default()
/// }))?;
/// let renderer = Renderer::new(&device, RendererOptions::default())?;
/// let mut gpu_scene = renderer.upload(&device, &queue, scene)?;
/// let mut film = renderer.create_film(&device, &gpu_scene, 640, 360)?;
/// for frame in 0..100 {
///     if let Some(camera) = camera_for_frame(frame) {
///         renderer.set_camera(&mut gpu_scene, &camera)?; // the film restarts by itself
///     }
///     let mut encoder = device.create_command_encoder(&Default::default());
///     renderer.encode_samples(&device, &queue, &mut encoder, &gpu_scene, &mut film, 1)?;
///     // ... renderer.draw(&mut render_pass, &gpu_scene, &film) into the swapchain ...
///     queue.submit([encoder.finish()]);
/// }
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct Renderer {
    pipelines: Pipelines,
    draw: Option<DrawPipelines>,
    options: RendererOptions,
    schedule: Schedule,
    iteration_budget: u32,
}

impl Renderer {
    /// Checks `device`'s limits, then builds the layouts, the display pipeline and,
    /// with [`RendererOptions::surface_format`], the draw pipelines.
    ///
    /// Errors: [`RenderError::Limit`] naming the first limit the device has too little
    /// of (a device made with `wgpu::Limits::default()` binds 8 storage buffers per
    /// stage, the trace kernels 16): request [`Renderer::required_limits`].
    /// [`RenderError::Wgpu`] if a pipeline fails to build.
    pub fn new(device: &wgpu::Device, options: RendererOptions) -> Result<Self, RenderError> {
        check_limits(&device.limits())?;
        let pipelines = Pipelines::new(device).map_err(RenderError::Wgpu)?;
        let draw = options
            .surface_format
            .map(|format| DrawPipelines::new(device, format))
            .transpose()
            .map_err(RenderError::Wgpu)?;
        let adapter = device.adapter_info();
        Ok(Self {
            pipelines,
            draw,
            schedule: options
                .schedule
                .unwrap_or_else(|| default_schedule(&adapter)),
            iteration_budget: options
                .iteration_budget
                .unwrap_or_else(|| iteration_budget_for(&adapter))
                .max(1),
            options,
        })
    }

    /// The limits to request when creating a device for the renderer:
    /// `adapter_limits` raised to the renderer's minimums ([`super::limits`]).
    pub fn required_limits(adapter_limits: &wgpu::Limits) -> wgpu::Limits {
        required_limits(adapter_limits)
    }

    /// The features to request when creating a device for the renderer, where the
    /// adapter has them ([`super::limits::optional_features`]): the renderer runs
    /// without them, only slower.
    pub fn optional_features(adapter_features: wgpu::Features) -> wgpu::Features {
        super::limits::optional_features(adapter_features)
    }

    /// The options the renderer was built with.
    pub fn options(&self) -> &RendererOptions {
        &self.options
    }

    /// The bind group layout of the draw pipelines, if any.
    pub(crate) fn draw_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.draw.as_ref().map(|draw| &draw.layout)
    }

    /// Builds `scene`'s geometry and BVH, uploads its buffers and images, and builds
    /// the trace pipelines specialised to it (so that no encoding call compiles
    /// anything). Pass the scene as loaded: it is converted to its lighting space
    /// here.
    ///
    /// Errors: [`RenderError::Scene`] for invalid render settings or a scene larger
    /// than the device holds; [`RenderError::Wgpu`] if an allocation or pipeline
    /// fails.
    pub fn upload(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
    ) -> Result<GpuScene, RenderError> {
        let geometry = SceneGeometry::new(scene);
        let prepared = upload_scene(
            device,
            queue,
            scene,
            &geometry,
            UploadOptions {
                specialise: self.options.specialise,
                allow_uniform_records: self.options.uniform_records,
                allow_refill_lanes: self.options.refill_lanes,
                allow_unrolled: self.options.unrolled,
            },
        )
        .map_err(|e| match e {
            GpuError::Validation(_) | GpuError::DeviceLimit { .. } => RenderError::Scene(e),
            other => RenderError::Wgpu(other),
        })?;
        let pipelines = self
            .pipelines
            .trace(device, &prepared.features)
            .map_err(RenderError::Wgpu)?;
        Ok(GpuScene::new(
            device,
            prepared,
            pipelines,
            scene.camera,
            scene.dielectric_spheres(),
        ))
    }

    /// Moves `scene`'s camera. Writes nothing to the device: the next trace pass of
    /// each film writes the camera with the pass's other constants (one 192-byte
    /// uniform record), and a film accumulating the old camera restarts at sample 0 in
    /// its next [`Renderer::encode_samples`]. No scene buffer is touched.
    ///
    /// Errors: [`RenderError::InvalidCamera`] for an undefined view or a field of view
    /// outside (0, 180) degrees (the scene keeps its camera).
    pub fn set_camera(&self, scene: &mut GpuScene, camera: &Camera) -> Result<(), RenderError> {
        let fov_ok = camera.fov_y_degrees > 0.0 && camera.fov_y_degrees < 180.0;
        if !fov_ok || view_problem(camera.eye, camera.look_at, camera.up).is_some() {
            return Err(RenderError::InvalidCamera(*camera));
        }
        if scene.camera != *camera {
            scene.camera = *camera;
            scene.camera_version += 1;
        }
        Ok(())
    }

    /// Creates a film of `width × height` pixels for `scene` (and any other scene
    /// whose `stack_size` is at most `scene`'s), with its path slots.
    ///
    /// Errors: [`RenderError::Limit`] for a film the device cannot hold (texture side,
    /// bytes of the per-pixel sums); [`RenderError::Wgpu`] if an allocation fails.
    pub fn create_film(
        &self,
        device: &wgpu::Device,
        scene: &GpuScene,
        width: u32,
        height: u32,
    ) -> Result<Film, RenderError> {
        let mut film = Film::new(
            device,
            self.draw_layout(),
            self.options.slot_count,
            scene.prepared.stack_size,
            width,
            height,
        )?;
        let bind_group = film
            .slots
            .bind_group(
                device,
                self.pipelines
                    .trace_bind_group_layout(&scene.prepared.features),
                &scene.prepared,
                &film.view,
            )
            .map_err(RenderError::Wgpu)?;
        film.binding = Some((scene.id, bind_group));
        Ok(film)
    }

    /// Adds `samples` samples per pixel to `film`'s running mean of `scene` (sample
    /// indices continue where the film's last samples ended, so the mean after any
    /// split of N samples into calls equals a one-shot render of N samples). Records
    /// into `encoder` and returns at once: no wait, no poll, no error scope.
    ///
    /// Each call records at most [`RendererOptions::max_rounds_per_call`] rounds of
    /// the trace kernels and a copy of the pass's counters, which wgpu maps when the
    /// GPU has run them (inside the application's next `queue.submit` or
    /// `device.poll`). A pass covers every sample queued when it starts; until the
    /// host has seen it complete, calls record more rounds of it and queue their
    /// samples for the next pass ([`Film::samples`], [`Film::requested_samples`]).
    /// `samples = 0` only moves the pass in progress on. The only write through
    /// `queue` is the film's 192-byte trace constants when a pass starts. Every
    /// encoder given here must be submitted, in order.
    ///
    /// A film whose scene or camera changed since its last samples restarts at
    /// sample 0. The film's trace bind group is made again (without an error scope)
    /// only when the film is used with another scene than the last, or after
    /// [`Film::resize`]; nothing else is created here.
    ///
    /// Errors: [`RenderError::FilmStack`] for a scene with deeper bounce stacks than
    /// the film's; [`RenderError::TraceIncomplete`] when an earlier pass's counters
    /// report a loop the driver cut short (the film is reset).
    pub fn encode_samples(
        &self,
        device: &wgpu::Device,
        queue: &(impl BufferWrites + ?Sized),
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        film: &mut Film,
        samples: u32,
    ) -> Result<(), RenderError> {
        film.check_scene(scene)?;
        let source = (scene.id, scene.camera_version);
        if film.source != Some(source) {
            film.reset();
            film.source = Some(source);
        }
        if film.binding.as_ref().map(|(id, _)| *id) != Some(scene.id) {
            // Built without an error scope (which would block): the layout and every
            // resource are the renderer's own, made to match.
            let bind_group = film.slots.bind_group_unchecked(
                device,
                self.pipelines
                    .trace_bind_group_layout(&scene.prepared.features),
                &scene.prepared,
                &film.view,
            );
            film.binding = Some((scene.id, bind_group));
        }
        film.collect_progress()?;
        film.queue_samples(samples);
        if let Some(pass) = film.start_pass() {
            let frame = super::layout::FrameUniforms {
                first_sample: pass.first,
                end_sample: pass.end,
                slot_count: film.slot_count,
                iteration_budget: self.iteration_budget,
                // The scene's own flags (its integrator) kept.
                flags: FLAG_STORE_SUM | scene.prepared.frame.flags,
                ..scene.frame_for(film.width(), film.height())
            };
            let pixels = u64::from(film.width()) * u64::from(film.height());
            let frame = super::layout::FrameUniforms {
                static_pixels: super::layout::static_pixels_for(&frame, pixels),
                ..frame
            };
            queue.write_buffer(&film.slots.uniforms, 0, bytemuck::bytes_of(&frame));
            // Zeroed slots start at PHASE_FIRST_PIXEL with no trace pending.
            encoder.clear_buffer(&film.slots.paths, 0, None);
            encoder.clear_buffer(&film.slots.traces, 0, None);
            encoder.clear_buffer(&film.slots.counters, 0, None);
        }
        let rounds = film.rounds_to_record(self.options.max_rounds_per_call.max(1));
        if rounds == 0 {
            return Ok(());
        }
        if let Some((_, bind_group)) = &film.binding {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("gpu-render film samples"),
                timestamp_writes: None,
            });
            encode_rounds(
                &mut pass,
                &scene.pipelines,
                self.schedule,
                bind_group,
                film.slot_count.div_ceil(SLOT_WORKGROUP_SIZE),
                rounds,
            );
        }
        film.add_rounds(rounds);
        film.record_readback(encoder);
        Ok(())
    }

    /// Records the display pass of `film` into `encoder`: the scene's sRGB rule
    /// (exact curve, or clamping only in naive gamma mode), quantised to 8 bits, into
    /// `target`, an `Rgba8Unorm` texture with `STORAGE_BINDING` of the film's size.
    /// Records only; creates one bind group.
    ///
    /// Errors: [`RenderError::TargetFormat`], [`RenderError::TargetUsage`],
    /// [`RenderError::TargetSize`] for an unsuitable target.
    pub fn encode_display(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        film: &Film,
        target: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        let texture = target.texture();
        if texture.format() != DISPLAY_FORMAT {
            return Err(RenderError::TargetFormat {
                expected: DISPLAY_FORMAT,
                found: texture.format(),
            });
        }
        if !texture
            .usage()
            .contains(wgpu::TextureUsages::STORAGE_BINDING)
        {
            return Err(RenderError::TargetUsage {
                needed: wgpu::TextureUsages::STORAGE_BINDING,
                found: texture.usage(),
            });
        }
        if (texture.width(), texture.height()) != (film.width(), film.height()) {
            return Err(RenderError::TargetSize {
                film: (film.width(), film.height()),
                target: (texture.width(), texture.height()),
            });
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gpu-render film display bind group"),
            layout: &self.pipelines.display_bind_group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: scene.display_uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&film.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(target),
                },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gpu-render film display"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipelines.display);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(
            film.width().div_ceil(WORKGROUP_SIZE),
            film.height().div_ceil(WORKGROUP_SIZE),
            1,
        );
        Ok(())
    }

    /// Draws `film` into the caller's render pass (whose colour attachment has the
    /// [`RendererOptions::surface_format`]): one triangle over the pass's viewport,
    /// which the film fills, each pixel showing the film texel under its centre (a
    /// viewport of the film's size shows film pixel (x, y) at viewport pixel (x, y);
    /// a larger one scales the film up by nearest texel). The sRGB curve is
    /// applied exactly once: by the shader for a linear-unorm attachment, by the
    /// attachment for an `*Srgb` one (naive-gamma scenes are decoded first, so that
    /// their display values come out unchanged). Records only; binds the film's bind
    /// group made at its creation.
    ///
    /// Errors: [`RenderError::NoSurfaceFormat`] for a renderer built without one.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &GpuScene,
        film: &Film,
    ) -> Result<(), RenderError> {
        let (Some(draw), Some(bind_group)) = (&self.draw, &film.draw_binding) else {
            return Err(RenderError::NoSurfaceFormat);
        };
        pass.set_pipeline(draw.pipeline(scene.display_encodes_srgb()));
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// Blocks until every sample asked of `film` is in it: records and submits more
    /// rounds and waits for them, as often as it takes.
    ///
    /// Errors: as [`Renderer::encode_samples`]; [`RenderError::DeviceLost`] if a wait
    /// fails.
    pub fn finish(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &mut Film,
    ) -> Result<(), RenderError> {
        loop {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gpu-render finish film"),
            });
            self.encode_samples(device, queue, &mut encoder, scene, film, 0)?;
            let submission = queue.submit([encoder.finish()]);
            wait(device, submission, None)?;
            // The wait ran the map callbacks: the reports are in.
            film.collect_progress()?;
            if film.is_complete() {
                return Ok(());
            }
        }
    }

    /// The blocking convenience: resets `film`, adds the scene's samples per pixel,
    /// waits for them, runs the display pass and reads both images back.
    ///
    /// Errors: as [`Renderer::finish`]; [`RenderError::Readback`] or
    /// [`RenderError::DeviceLost`] if the readback fails.
    pub fn render_to_image(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &mut Film,
    ) -> Result<FilmImage, RenderError> {
        film.reset();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render render to image"),
        });
        self.encode_samples(
            device,
            queue,
            &mut encoder,
            scene,
            film,
            scene.samples_per_pixel(),
        )?;
        queue.submit([encoder.finish()]);
        self.finish(device, queue, scene, film)?;
        self.read_film(device, queue, scene, film)
    }

    /// Reads `film` back as it is now (blocking): the mean radiance and the display
    /// pass's values.
    ///
    /// Errors: [`RenderError::Readback`] or [`RenderError::DeviceLost`].
    pub fn read_film(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &Film,
    ) -> Result<FilmImage, RenderError> {
        let (width, height) = (film.width(), film.height());
        let display = create_texture(
            device,
            "gpu-render film display image",
            width,
            height,
            DISPLAY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        )?;
        let view = display.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render film display"),
        });
        self.encode_display(device, &mut encoder, scene, film, &view)?;
        let submission = queue.submit([encoder.finish()]);
        wait(device, submission, None)?;
        let linear = read_texture(device, queue, &film.texture, 16, None)?;
        let display_rgba8 = read_texture(device, queue, &display, 4, None)?;
        Ok(FilmImage {
            image: LinearImage {
                width,
                height,
                pixels: bytemuck::pod_collect_to_vec(&linear),
            },
            display_rgba8,
            samples: film.samples(),
            rays_traced: film.rays_traced(),
        })
    }

    /// Waits for every sample asked of `film` ([`Renderer::finish`]) and reads its
    /// noise estimate back (blocking): each pixel's standard error from the spread of
    /// its [`Film::samples`] samples, kept beside the sample sums in the film's
    /// accumulation buffer (16 bytes per pixel, whatever the sample count). The
    /// summary [`NoiseEstimate::relative_error`] says how much noise remains.
    ///
    /// ```no_run
    /// # use gpu_render::gpu::{Film, GpuScene, Renderer};
    /// # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, renderer: &Renderer,
    /// #         scene: &GpuScene, film: &mut Film) -> Result<(), gpu_render::gpu::RenderError> {
    /// let noise = renderer.read_noise(device, queue, scene, film)?;
    /// if let Some(relative) = noise.relative_error() {
    ///     println!("{} spp, about {:.2}% noise left", noise.samples, relative * 100.0);
    /// }
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// Errors: as [`Renderer::finish`]; [`RenderError::Readback`] or
    /// [`RenderError::DeviceLost`] if the readback fails.
    pub fn read_noise(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &mut Film,
    ) -> Result<NoiseEstimate, RenderError> {
        self.finish(device, queue, scene, film)?;
        Ok(film.slots.read_noise(
            device,
            queue,
            (film.width(), film.height()),
            film.samples(),
            None,
        )?)
    }
}
