//! [`Film`]: the running mean of a progressive render, and the path slots that add
//! samples to it, with what the host knows of their progress.
//!
//! Samples are added in *passes*: one pass traces samples `first..end` of every pixel,
//! starting each pixel from the sum the previous passes left in the accumulation
//! buffer, and writes the pixel's mean over `end` samples. A pass takes as many rounds
//! of the trace kernels as its pixels need, which only the GPU knows; so every
//! [`super::Renderer::encode_samples`] records a few rounds and a copy of the pass's
//! counters, which wgpu maps once the GPU has run them (the callback fires inside the
//! application's next `queue.submit` or `device.poll`). Until the host has seen a pass
//! complete, further calls record more rounds of the same pass and queue the samples
//! they are asked for; the next pass takes all queued samples at once. The sum of a
//! pixel is therefore built in the same order, sample by sample, however the samples
//! are split into calls and passes, and equals a one-shot render's bit for bit.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use super::denoiser::DenoiseTargets;
use super::gpu_scene::GpuScene;
use super::layout::GpuCounters;
use super::limits::{check_binding_bytes, check_film_size};
use super::pipelines::LINEAR_FORMAT;
use super::readback::{Caught, capture, create_texture};
use super::wavefront::{AOV_BYTES_PER_PIXEL, SUM_BYTES_PER_PIXEL, SlotBuffers, check_errors};
use super::{RenderError, Renderer};

/// Readback buffers a film keeps (made with it); with all of them in flight, a call
/// records no counter copy (a later one will).
const MAX_READBACKS: usize = 8;

/// The counters of one pass as a mapped readback found them.
#[derive(Debug, Clone, Copy)]
struct Report {
    generation: u64,
    pass: u64,
    /// Rounds recorded for the pass up to and including the copy.
    rounds: u64,
    counters: GpuCounters,
}

/// A readback buffer and whether its mapping is still pending.
#[derive(Debug)]
struct Readback {
    buffer: wgpu::Buffer,
    busy: Arc<AtomicBool>,
}

impl Readback {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render film counters"),
                size: size_of::<GpuCounters>() as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
            busy: Arc::new(AtomicBool::new(false)),
        }
    }
}

/// The pass in progress, as far as the host knows.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pass {
    pub id: u64,
    pub first: u32,
    pub end: u32,
    pub rounds: u64,
}

/// The running mean of a progressive render of one image size: an `Rgba32Float`
/// texture of the mean radiance, the per-pixel sample sums, and the path slots that
/// add samples. Created by [`super::Renderer::create_film`]; samples are added by
/// [`super::Renderer::encode_samples`].
#[derive(Debug)]
pub struct Film {
    width: u32,
    height: u32,
    pub(crate) texture: wgpu::Texture,
    pub(crate) view: wgpu::TextureView,
    pub(crate) slots: SlotBuffers,
    pub(crate) slot_count: u32,
    pub(crate) stack_size: u32,
    requested_slots: Option<u32>,
    /// Whether the film keeps the auxiliary passes beside its sums.
    pub(crate) aov: bool,
    /// The denoiser's buffers and image, made by its first use.
    pub(crate) denoise: Option<DenoiseTargets>,
    /// The trace bind group and the scene it was built for.
    pub(crate) binding: Option<(u64, wgpu::BindGroup)>,
    /// `draw`'s bind group of the mean texture.
    pub(crate) draw_binding: Option<wgpu::BindGroup>,
    /// Increased by every reset: reports of older passes are ignored.
    generation: u64,
    /// The scene and camera version the film accumulates.
    pub(crate) source: Option<(u64, u64)>,
    completed: u32,
    requested: u32,
    pub(crate) pass: Option<Pass>,
    next_pass: u64,
    rounds_per_sample: Option<f64>,
    rays: u64,
    passes: u32,
    readbacks: Vec<Readback>,
    reports: Arc<Mutex<Vec<Report>>>,
}

impl Film {
    pub(crate) fn new(
        device: &wgpu::Device,
        draw_layout: Option<&wgpu::BindGroupLayout>,
        requested_slots: Option<u32>,
        stack_size: u32,
        aov: bool,
        width: u32,
        height: u32,
    ) -> Result<Self, RenderError> {
        let limits = device.limits();
        check_film_size(&limits, width.max(1), height.max(1))?;
        let pixels = u64::from(width.max(1)) * u64::from(height.max(1));
        let per_pixel = SUM_BYTES_PER_PIXEL + u64::from(aov) * AOV_BYTES_PER_PIXEL;
        check_binding_bytes(&limits, pixels * per_pixel)?;
        let slot_count = SlotBuffers::slot_count(device, requested_slots, pixels, stack_size);
        let slots = SlotBuffers::new(device, slot_count, stack_size, pixels, aov)?;
        let texture = create_texture(
            device,
            "gpu-render film",
            width.max(1),
            height.max(1),
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        )?;
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let draw_binding = draw_layout.map(|layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gpu-render film draw bind group"),
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                }],
            })
        });
        Ok(Self {
            width: width.max(1),
            height: height.max(1),
            texture,
            view,
            slots,
            slot_count,
            stack_size,
            requested_slots,
            aov,
            denoise: None,
            binding: None,
            draw_binding,
            generation: 0,
            source: None,
            completed: 0,
            requested: 0,
            pass: None,
            next_pass: 0,
            rounds_per_sample: None,
            rays: 0,
            passes: 0,
            readbacks: capture(device, "film readbacks", Caught::Resource, || {
                (0..MAX_READBACKS).map(|_| Readback::new(device)).collect()
            })?,
            reports: Arc::new(Mutex::new(Vec::new())),
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The mean radiance image (`Rgba32Float`, `TEXTURE_BINDING | COPY_SRC`), for
    /// applications that sample or copy it themselves. Pixels the pass in progress has
    /// not reached yet still hold the previous mean.
    pub fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// A view of [`Film::texture`].
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Whether the film keeps the auxiliary passes (albedo, normal, depth) beside its
    /// sums: made by a renderer with [`super::RendererOptions::aov`]; they are
    /// recorded for scenes uploaded by one.
    pub fn keeps_aov(&self) -> bool {
        self.aov
    }

    /// The film's denoised image (`Rgba32Float`, `TEXTURE_BINDING | COPY_SRC`) as
    /// [`super::Renderer::encode_denoise`] last wrote it; `None` before its first
    /// call.
    pub fn denoised_texture(&self) -> Option<&wgpu::Texture> {
        self.denoise.as_ref().map(|targets| &targets.output)
    }

    /// Samples per pixel the host knows to be in the film (the GPU may be ahead).
    pub fn samples(&self) -> u32 {
        self.completed
    }

    /// Samples per pixel asked for since the last reset: [`Film::samples`] plus those
    /// in the pass in progress and those queued for the next.
    pub fn requested_samples(&self) -> u32 {
        self.requested
    }

    /// Whether every sample asked for is known to be in the film.
    pub fn is_complete(&self) -> bool {
        self.completed == self.requested && self.pass.is_none()
    }

    /// Passes completed since the last reset (each took every sample queued when it
    /// started).
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Rays traced by the completed passes since the last reset.
    pub fn rays_traced(&self) -> u64 {
        self.rays
    }

    /// Drops every sample: the next [`super::Renderer::encode_samples`] starts again
    /// at sample 0. Records nothing; the texture keeps the old mean until the first
    /// new pass overwrites each pixel. [`super::Renderer::encode_samples`] resets a
    /// film by itself when the scene's camera has changed.
    pub fn reset(&mut self) {
        self.generation += 1;
        self.completed = 0;
        self.requested = 0;
        self.pass = None;
        self.rays = 0;
        self.passes = 0;
        self.source = None;
    }

    /// Resizes the film to `width × height` (recreating its texture, sums and slots)
    /// and resets it. The views of the old texture stay valid but are no longer
    /// written.
    ///
    /// Errors: [`RenderError::Limit`] for a size the device cannot hold.
    pub fn resize(
        &mut self,
        device: &wgpu::Device,
        renderer: &Renderer,
        width: u32,
        height: u32,
    ) -> Result<(), RenderError> {
        let fresh = Film::new(
            device,
            renderer.draw_layout(),
            self.requested_slots,
            self.stack_size,
            self.aov,
            width,
            height,
        )?;
        let generation = self.generation;
        *self = fresh;
        // Reports of the old film's passes must not count in the new one.
        self.generation = generation;
        self.reset();
        Ok(())
    }

    /// Reads the counters the GPU has reported since the last call (their map
    /// callbacks run inside the application's `queue.submit` or `device.poll`) and
    /// moves [`Film::samples`] on: a pass whose every pixel is done is complete.
    /// [`super::Renderer::encode_samples`] calls it first; call it to check progress
    /// between frames. Never blocks.
    ///
    /// Errors: [`RenderError::TraceIncomplete`] if the kernels flagged an error (the
    /// pass is dropped and the film reset).
    pub fn collect_progress(&mut self) -> Result<(), RenderError> {
        let reports: Vec<Report> =
            std::mem::take(&mut *self.reports.lock().unwrap_or_else(PoisonError::into_inner));
        let pixels = u64::from(self.width) * u64::from(self.height);
        for report in reports {
            let Some(pass) = self.pass else { break };
            if report.generation != self.generation || report.pass != pass.id {
                continue;
            }
            if let Err(e) = check_errors(report.counters.errors) {
                self.reset();
                return Err(e);
            }
            if u64::from(report.counters.pixels_done) >= pixels {
                let samples = f64::from(pass.end - pass.first);
                self.rounds_per_sample = Some(report.rounds as f64 / samples);
                self.completed = pass.end;
                self.rays += report.counters.rays();
                self.passes += 1;
                self.pass = None;
            }
        }
        Ok(())
    }

    /// Queues `samples` more samples per pixel.
    pub(crate) fn queue_samples(&mut self, samples: u32) {
        self.requested = self.requested.saturating_add(samples);
    }

    /// Starts a pass of every queued sample if none is in progress and some are
    /// queued; returns it.
    pub(crate) fn start_pass(&mut self) -> Option<Pass> {
        if self.pass.is_some() || self.requested == self.completed {
            return None;
        }
        let pass = Pass {
            id: self.next_pass,
            first: self.completed,
            end: self.requested,
            rounds: 0,
        };
        self.next_pass += 1;
        self.pass = Some(pass);
        Some(pass)
    }

    /// How many rounds to record now for the pass in progress: what the last
    /// completed pass needed per sample (a quarter more, at least 1), less what is
    /// already recorded; once that is spent, a quarter of it again, so that a pass
    /// that needs more is still finished in a few frames.
    pub(crate) fn rounds_to_record(&self, max_rounds: u32) -> u32 {
        let Some(pass) = self.pass else { return 0 };
        let samples = f64::from(pass.end - pass.first);
        let estimate = self
            .rounds_per_sample
            .map_or(4.0 * samples, |per_sample| per_sample * samples * 1.25)
            .ceil()
            .max(1.0) as u64;
        let rounds = if pass.rounds < estimate {
            estimate - pass.rounds
        } else {
            (pass.rounds / 4).max(1)
        };
        rounds.clamp(1, u64::from(max_rounds)) as u32
    }

    /// Notes `rounds` more rounds recorded for the pass in progress.
    pub(crate) fn add_rounds(&mut self, rounds: u32) {
        if let Some(pass) = &mut self.pass {
            pass.rounds += u64::from(rounds);
        }
    }

    /// Records a copy of the counters into a free readback buffer, mapped when the
    /// encoder's command buffer has run; the callback files a report. Records nothing
    /// if all [`MAX_READBACKS`] are in flight.
    pub(crate) fn record_readback(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let Some(pass) = self.pass else { return };
        let size = size_of::<GpuCounters>() as u64;
        let Some(index) = self
            .readbacks
            .iter()
            .position(|r| !r.busy.load(Ordering::Acquire))
        else {
            return;
        };
        let readback = &self.readbacks[index];
        readback.busy.store(true, Ordering::Release);
        encoder.copy_buffer_to_buffer(&self.slots.counters, 0, &readback.buffer, 0, size);
        let buffer = readback.buffer.clone();
        let busy = Arc::clone(&readback.busy);
        let reports = Arc::clone(&self.reports);
        let (generation, rounds) = (self.generation, pass.rounds);
        encoder.map_buffer_on_submit(&readback.buffer, wgpu::MapMode::Read, .., move |result| {
            if result.is_ok() {
                let counters = buffer
                    .get_mapped_range(..)
                    .ok()
                    .map(|bytes| bytemuck::pod_read_unaligned::<GpuCounters>(&bytes));
                buffer.unmap();
                if let Some(counters) = counters {
                    reports
                        .lock()
                        .unwrap_or_else(PoisonError::into_inner)
                        .push(Report {
                            generation,
                            pass: pass.id,
                            rounds,
                            counters,
                        });
                }
            }
            busy.store(false, Ordering::Release);
        });
    }

    /// Whether a film of this one's stack capacity can trace `scene`.
    pub(crate) fn check_scene(&self, scene: &GpuScene) -> Result<(), RenderError> {
        if scene.prepared.stack_size > self.stack_size {
            return Err(RenderError::FilmStack {
                film: self.stack_size,
                scene: scene.prepared.stack_size,
            });
        }
        Ok(())
    }
}
