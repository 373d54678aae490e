//! The host side of the GPU denoiser (`shaders/denoise.wgsl`, twin of
//! [`crate::denoise`]): its pipelines, the buffers of one image size, and the steps
//! recorded: the input (a film's mean, variance and passes, or an uploaded image),
//! demodulation, the à-trous passes ping-ponging between two signal buffers, and
//! remodulation into the denoised image.

use super::RenderError;
use super::layout::DenoiseUniforms;
use super::pipelines::{LINEAR_FORMAT, build_pipelines};
use super::readback::{Caught, capture, create_texture};
use super::renderer::BufferWrites;
use super::shaders::{WORKGROUP_SIZE, denoise_shader_source};
use crate::denoise::DenoiseSettings;

/// Most à-trous passes the GPU filter runs (taps up to 2^11 pixels apart); settings
/// with more run this many.
pub const MAX_DENOISE_ITERATIONS: u32 = 12;

/// Bytes between the uniform records of the steps (a multiple of every device's
/// `min_uniform_buffer_offset_alignment`, at most 256).
const UNIFORM_STRIDE: u64 = 256;

/// The denoiser's bind group layout and its four kernels.
#[derive(Debug)]
pub(crate) struct DenoisePipelines {
    layout: wgpu::BindGroupLayout,
    prepare_film: wgpu::ComputePipeline,
    demodulate: wgpu::ComputePipeline,
    atrous: wgpu::ComputePipeline,
    remodulate: wgpu::ComputePipeline,
    /// Bound where a step reads no film: a 1x1 texture and a 16-byte buffer.
    no_film: (wgpu::TextureView, wgpu::Buffer),
}

impl DenoisePipelines {
    pub fn new(
        device: &wgpu::Device,
        cache: Option<&wgpu::PipelineCache>,
    ) -> Result<Self, RenderError> {
        let entry = |binding: u32, ty: wgpu::BindingType| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let buffer = |ty: wgpu::BufferBindingType| wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let storage = |read_only| buffer(wgpu::BufferBindingType::Storage { read_only });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gpu-render denoise bindings"),
            entries: &[
                entry(0, buffer(wgpu::BufferBindingType::Uniform)),
                entry(
                    1,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(2, storage(true)),
                entry(3, storage(false)),
                entry(4, storage(true)),
                entry(5, storage(false)),
                entry(
                    6,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: LINEAR_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu-render denoise layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let mut built = build_pipelines(
            device,
            "denoise",
            denoise_shader_source(),
            &pipeline_layout,
            &[
                "prepare_film_signal",
                "demodulate_signal",
                "atrous_pass",
                "remodulate_signal",
            ],
            cache,
        )?;
        let texture = create_texture(
            device,
            "gpu-render denoise no film",
            1,
            1,
            LINEAR_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        let no_film = (
            texture.create_view(&wgpu::TextureViewDescriptor::default()),
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render denoise no film sums"),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
        );
        Ok(Self {
            layout,
            remodulate: built.remove(3),
            atrous: built.remove(2),
            demodulate: built.remove(1),
            prepare_film: built.remove(0),
            no_film,
        })
    }
}

/// The buffers of the denoiser for one image size: the steps' uniforms, the guides,
/// two signal buffers and the denoised image.
#[derive(Debug)]
pub(crate) struct DenoiseTargets {
    pub width: u32,
    pub height: u32,
    uniforms: wgpu::Buffer,
    pub guides: wgpu::Buffer,
    pub signals: [wgpu::Buffer; 2],
    pub output: wgpu::Texture,
    pub output_view: wgpu::TextureView,
    /// `draw`'s bind group of the denoised image, with a draw layout.
    pub draw_binding: Option<wgpu::BindGroup>,
}

impl DenoiseTargets {
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        draw_layout: Option<&wgpu::BindGroupLayout>,
    ) -> Result<Self, RenderError> {
        let pixels = u64::from(width) * u64::from(height);
        let output = create_texture(
            device,
            "gpu-render denoised image",
            width,
            height,
            LINEAR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        )?;
        let storage = |label: &str, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let output_view = output.create_view(&wgpu::TextureViewDescriptor::default());
        let draw_binding = draw_layout.map(|layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("gpu-render denoised draw bind group"),
                layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&output_view),
                }],
            })
        });
        capture(device, "denoise buffers", Caught::Resource, || Self {
            width,
            height,
            uniforms: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render denoise uniforms"),
                size: UNIFORM_STRIDE * u64::from(MAX_DENOISE_ITERATIONS),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            guides: storage("gpu-render denoise guides", pixels * 32),
            signals: [
                storage("gpu-render denoise signal A", pixels * 16),
                storage("gpu-render denoise signal B", pixels * 16),
            ],
            output_view,
            output,
            draw_binding,
        })
    }
}

/// Where the filter's input comes from.
pub(crate) enum DenoiseInput<'a> {
    /// A film's mean texture and its sums (with the passes' sums after them).
    Film {
        mean: &'a wgpu::TextureView,
        sums: &'a wgpu::Buffer,
    },
    /// Already written: the radiance and variance in `signals[0]`, the guides in
    /// `guides`.
    Uploaded,
}

/// Records the whole filter into `encoder`: the input, demodulation, the passes of
/// `settings` (at most [`MAX_DENOISE_ITERATIONS`]) and remodulation into
/// `targets.output`; writes the steps' uniforms through `queue`.
pub(crate) fn encode_filter(
    device: &wgpu::Device,
    queue: &(impl BufferWrites + ?Sized),
    encoder: &mut wgpu::CommandEncoder,
    pipelines: &DenoisePipelines,
    targets: &DenoiseTargets,
    settings: &DenoiseSettings,
    input: DenoiseInput<'_>,
) {
    let iterations = settings.iterations.min(MAX_DENOISE_ITERATIONS);
    for slot in 0..iterations.max(1) {
        let uniforms = DenoiseUniforms {
            width: targets.width,
            height: targets.height,
            step: 1 << slot,
            _pad: 0,
            sigma_normal: settings.sigma_normal,
            sigma_depth: settings.sigma_depth,
            sigma_luminance: settings.sigma_luminance,
            sigma_albedo: settings.sigma_albedo,
        };
        queue.write_buffer(
            &targets.uniforms,
            UNIFORM_STRIDE * u64::from(slot),
            bytemuck::bytes_of(&uniforms),
        );
    }
    let from_film = matches!(input, DenoiseInput::Film { .. });
    let (mean, sums) = match input {
        DenoiseInput::Film { mean, sums } => (mean, sums),
        DenoiseInput::Uploaded => (&pipelines.no_film.0, &pipelines.no_film.1),
    };
    let bind_group = |slot: u32, from: usize, to: usize| {
        fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gpu-render denoise bind group"),
            layout: &pipelines.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &targets.uniforms,
                        offset: UNIFORM_STRIDE * u64::from(slot),
                        size: wgpu::BufferSize::new(size_of::<DenoiseUniforms>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(mean),
                },
                buffer(2, sums),
                buffer(3, &targets.guides),
                buffer(4, &targets.signals[from]),
                buffer(5, &targets.signals[to]),
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&targets.output_view),
                },
            ],
        })
    };
    let mut steps: Vec<(&wgpu::ComputePipeline, wgpu::BindGroup)> = Vec::new();
    if from_film {
        steps.push((&pipelines.prepare_film, bind_group(0, 1, 0)));
    }
    steps.push((&pipelines.demodulate, bind_group(0, 0, 1)));
    let mut current = 1;
    for slot in 0..iterations {
        steps.push((&pipelines.atrous, bind_group(slot, current, 1 - current)));
        current = 1 - current;
    }
    steps.push((&pipelines.remodulate, bind_group(0, current, 1 - current)));
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("gpu-render denoise"),
        timestamp_writes: None,
    });
    for (pipeline, bind_group) in &steps {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(
            targets.width.div_ceil(WORKGROUP_SIZE),
            targets.height.div_ceil(WORKGROUP_SIZE),
            1,
        );
    }
}
