//! The built-in denoiser on the GPU ([`crate::denoise`]'s twin, `shaders/denoise.wgsl`):
//! a film denoised into its display image in the frame loop, its accumulated samples
//! untouched ([`Renderer::encode_denoise`], [`Renderer::encode_denoised_display`]),
//! and an image with its guides denoised in one blocking call
//! ([`Renderer::denoise_image`]).

use super::Renderer;
use super::frame_loop::BufferWrites;
use crate::denoise::{DenoiseSettings, GuidePasses};
use crate::film::LinearImage;
use crate::gpu::RenderError;
use crate::gpu::denoiser::{DenoiseInput, DenoiseTargets, encode_filter};
use crate::gpu::film::Film;
use crate::gpu::gpu_scene::GpuScene;
use crate::gpu::readback::{read_texture, wait};

impl Renderer {
    /// Records the denoiser over `film` into `encoder`: its mean radiance, filtered as
    /// [`crate::denoise::denoise`] does, guided by the film's auxiliary passes and the
    /// variance of each pixel's mean (from its noise estimate), into the film's
    /// denoised image ([`Film::denoised_texture`]). Reads the film's texture and sums
    /// and writes neither: the accumulation goes on unchanged. Writes the filter's
    /// few uniform bytes through `queue`; creates the denoiser's buffers on the first
    /// call for a film (and after [`Film::resize`]) and a bind group per step.
    /// Settings of more than [`crate::gpu::MAX_DENOISE_ITERATIONS`] passes run that
    /// many.
    ///
    /// Errors: [`RenderError::NoAov`] for a film made by a renderer without
    /// [`super::RendererOptions::aov`]; [`RenderError::OutOfMemory`] if the buffers
    /// cannot be made.
    pub fn encode_denoise(
        &self,
        device: &wgpu::Device,
        queue: &(impl BufferWrites + ?Sized),
        encoder: &mut wgpu::CommandEncoder,
        film: &mut Film,
        settings: &DenoiseSettings,
    ) -> Result<(), RenderError> {
        let Some(pipelines) = &self.denoise else {
            return Err(RenderError::NoAov);
        };
        if !film.aov {
            return Err(RenderError::NoAov);
        }
        if film.denoise.is_none() {
            film.denoise = Some(DenoiseTargets::new(
                device,
                film.width(),
                film.height(),
                self.draw_layout(),
            )?);
        }
        let Some(targets) = &film.denoise else {
            return Ok(());
        };
        encode_filter(
            device,
            queue,
            encoder,
            pipelines,
            targets,
            settings,
            DenoiseInput::Film {
                mean: &film.view,
                sums: &film.slots.accumulation,
            },
        );
        Ok(())
    }

    /// [`Renderer::encode_denoise`], then the display pass of the denoised image into
    /// `target` (as [`Renderer::encode_display`] shows the film): what a viewer shows
    /// with its denoiser on.
    ///
    /// Errors: as [`Renderer::encode_denoise`] and [`Renderer::encode_display`].
    #[allow(clippy::too_many_arguments)]
    pub fn encode_denoised_display(
        &self,
        device: &wgpu::Device,
        queue: &(impl BufferWrites + ?Sized),
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        film: &mut Film,
        settings: &DenoiseSettings,
        target: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.encode_denoise(device, queue, encoder, film, settings)?;
        let Some(targets) = &film.denoise else {
            return Err(RenderError::NoAov);
        };
        self.encode_display_texture(
            device,
            encoder,
            &targets.output_view,
            target,
            scene.display_encodes_srgb(),
        )
    }

    /// [`Renderer::draw`] of the film's denoised image as [`Renderer::encode_denoise`]
    /// last recorded it (the film itself before the first call): what a viewer draws
    /// with its denoiser on. Records only.
    ///
    /// Errors: [`RenderError::NoSurfaceFormat`] for a renderer built without one.
    pub fn draw_denoised(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &GpuScene,
        film: &Film,
    ) -> Result<(), RenderError> {
        let (Some(draw), Some(bind_group)) = (
            &self.draw,
            film.denoise
                .as_ref()
                .and_then(|targets| targets.draw_binding.as_ref()),
        ) else {
            return self.draw(pass, scene, film);
        };
        pass.set_pipeline(draw.pipeline(scene.display_encodes_srgb()));
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// Waits for every sample asked of `film` ([`Renderer::finish`]), denoises it
    /// ([`Renderer::encode_denoise`]) and reads the denoised image back (blocking).
    ///
    /// Errors: as [`Renderer::encode_denoise`] and [`Renderer::finish`];
    /// [`RenderError::Readback`] or [`RenderError::DeviceLost`].
    pub fn read_denoised(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        film: &mut Film,
        settings: &DenoiseSettings,
    ) -> Result<LinearImage, RenderError> {
        self.finish(device, queue, scene, film)?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render denoise film"),
        });
        self.encode_denoise(device, queue, &mut encoder, film, settings)?;
        let submission = queue.submit([encoder.finish()]);
        wait(device, submission, self.options().poll_timeout)?;
        let Some(targets) = &film.denoise else {
            return Err(RenderError::NoAov);
        };
        read_linear(device, queue, targets, self.options().poll_timeout)
    }

    /// Denoises `image` on the GPU (blocking): [`crate::denoise::denoise`] of its
    /// radiance with `variance` (of each pixel's mean luminance) and `guides`, as the
    /// frame loop's filter runs it. The alpha channel of the result is 1.
    ///
    /// Errors: [`RenderError::NoAov`] on a renderer without
    /// [`super::RendererOptions::aov`]; [`RenderError::OutOfMemory`],
    /// [`RenderError::Readback`] or [`RenderError::DeviceLost`].
    ///
    /// # Panics
    ///
    /// If `variance` or `guides` do not hold the image's pixels.
    pub fn denoise_image(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        image: &LinearImage,
        variance: &[f32],
        guides: &GuidePasses,
        settings: &DenoiseSettings,
    ) -> Result<LinearImage, RenderError> {
        let Some(pipelines) = &self.denoise else {
            return Err(RenderError::NoAov);
        };
        let pixels = image.pixels.len();
        assert!(
            variance.len() == pixels
                && (guides.width, guides.height) == (image.width, image.height)
                && guides.albedo.len() == pixels
                && guides.normal.len() == pixels
                && guides.depth.len() == pixels,
            "the image, its variance and its guides differ in size"
        );
        let targets = DenoiseTargets::new(device, image.width, image.height, None)?;
        let signal: Vec<[f32; 4]> = image
            .pixels
            .iter()
            .zip(variance)
            .map(|(p, &v)| [p[0], p[1], p[2], v])
            .collect();
        let guide_records: Vec<[f32; 4]> = (0..pixels)
            .flat_map(|i| {
                let (a, n) = (guides.albedo[i], guides.normal[i]);
                [[a[0], a[1], a[2], guides.depth[i]], [n[0], n[1], n[2], 0.0]]
            })
            .collect();
        queue.write_buffer(&targets.signals[0], 0, bytemuck::cast_slice(&signal));
        queue.write_buffer(&targets.guides, 0, bytemuck::cast_slice(&guide_records));
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render denoise image"),
        });
        encode_filter(
            device,
            queue,
            &mut encoder,
            pipelines,
            &targets,
            settings,
            DenoiseInput::Uploaded,
        );
        let submission = queue.submit([encoder.finish()]);
        wait(device, submission, self.options().poll_timeout)?;
        read_linear(device, queue, &targets, self.options().poll_timeout)
    }
}

/// Reads the denoised image of `targets` back.
fn read_linear(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    targets: &DenoiseTargets,
    timeout: Option<std::time::Duration>,
) -> Result<LinearImage, RenderError> {
    let bytes = read_texture(device, queue, &targets.output, 16, timeout)?;
    Ok(LinearImage {
        width: targets.width,
        height: targets.height,
        pixels: bytemuck::pod_collect_to_vec(&bytes),
    })
}
