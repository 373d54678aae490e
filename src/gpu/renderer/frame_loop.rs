//! The frame loop of [`Renderer`]: samples recorded into a [`Film`] without blocking
//! ([`Renderer::encode_samples`]), the film shown in a storage texture
//! ([`Renderer::encode_display`]) or inside the application's render pass
//! ([`Renderer::draw`]), and the blocking conveniences built on them (finishing a film,
//! reading it back). `docs/embedding.md` walks through it.

use super::Renderer;
use crate::denoise::GuidePasses;
use crate::film::LinearImage;
use crate::gpu::RenderError;
use crate::gpu::display::{TextureSize, check_texture};
use crate::gpu::film::Film;
use crate::gpu::gpu_scene::GpuScene;
use crate::gpu::layout::{FLAG_AOV, FLAG_STORE_SUM};
use crate::gpu::pipelines::DISPLAY_FORMAT;
use crate::gpu::readback::{create_texture, read_texture, wait};
use crate::gpu::shaders::{SLOT_WORKGROUP_SIZE, WORKGROUP_SIZE};
use crate::gpu::wavefront::encode_rounds;
use crate::noise::NoiseEstimate;

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

impl Renderer {
    /// Adds `samples` samples per pixel to `film`'s running mean of `scene` (sample
    /// indices continue where the film's last samples ended, so the mean after any
    /// split of N samples into calls equals a one-shot render of N samples). Records
    /// into `encoder` and returns at once: no wait, no poll, no error scope.
    ///
    /// Each call records at most [`RendererOptions::max_rounds_per_call`](crate::gpu::RendererOptions::max_rounds_per_call) rounds of
    /// the trace kernels and a copy of the pass's counters, which wgpu maps when the
    /// GPU has run them (inside the application's next `queue.submit` or
    /// `device.poll`). A pass covers every sample queued when it starts; until the
    /// host has seen it complete, calls record more rounds of it and queue their
    /// samples for the next pass ([`Film::samples`], [`Film::requested_samples`]).
    /// `samples = 0` only moves the pass in progress on. The only write through
    /// `queue` is the film's 208-byte trace constants when a pass starts. Every
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
            let frame = crate::gpu::layout::FrameUniforms {
                first_sample: pass.first,
                end_sample: pass.end,
                slot_count: film.slot_count,
                iteration_budget: self.iteration_budget,
                // The scene's own flags (its integrator) kept.
                flags: FLAG_STORE_SUM
                    | scene.prepared.frame.flags
                    | if film.aov && scene.prepared.features.aov {
                        FLAG_AOV
                    } else {
                        0
                    },
                ..scene.frame_for(film.width(), film.height())
            };
            let pixels = u64::from(film.width()) * u64::from(film.height());
            let frame = crate::gpu::layout::FrameUniforms {
                static_pixels: crate::gpu::layout::static_pixels_for(&frame, pixels),
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
        check_texture(
            target,
            "display target",
            DISPLAY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
            (film.width(), film.height()),
            TextureSize::Exact,
        )?;
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
    /// [`RendererOptions::surface_format`](crate::gpu::RendererOptions::surface_format)): one triangle over the pass's viewport,
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
        film.slots.read_noise(
            device,
            queue,
            (film.width(), film.height()),
            film.samples(),
            None,
        )
    }

    /// Waits for every sample asked of `film` ([`Renderer::finish`]) and reads its
    /// auxiliary passes back (blocking): the mean over its [`Film::samples`] samples
    /// of the camera rays' first-hit albedo, shading normal and depth
    /// (`shaders/aov.wgsl`), the guides of the denoiser.
    ///
    /// Errors: [`RenderError::NoAov`] for a film or scene made without
    /// [`super::RendererOptions::aov`]; as [`Renderer::finish`];
    /// [`RenderError::Readback`] or [`RenderError::DeviceLost`] if the readback fails.
    pub fn read_aov(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &mut Film,
    ) -> Result<GuidePasses, RenderError> {
        if !(film.aov && scene.prepared.features.aov) {
            return Err(RenderError::NoAov);
        }
        self.finish(device, queue, scene, film)?;
        film.slots.read_aov(
            device,
            queue,
            (film.width(), film.height()),
            film.samples(),
            None,
        )
    }
}
