//! The display pass: linear radiance to 8-bit display values, with the exact sRGB
//! curve (`shaders/display.wgsl`).

use wgpu::util::DeviceExt;

use super::RenderError;
use super::layout::DisplayUniforms;
use super::pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT, Pipelines};
use super::readback::{Caught, capture};
use super::shaders::WORKGROUP_SIZE;

/// How a texture's size must relate to the image it is used with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TextureSize {
    /// The image's size exactly (a film's display target).
    Exact,
    /// At least the image's size (a trace target may hold more).
    AtLeast,
}

/// Checks that `view`'s texture (the operation's `role` texture) has `format`,
/// `usage` and the size `image` asks, as `size` says.
pub(crate) fn check_texture(
    view: &wgpu::TextureView,
    role: &'static str,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    image: (u32, u32),
    size: TextureSize,
) -> Result<(), RenderError> {
    let texture = view.texture();
    if texture.format() != format {
        return Err(RenderError::TargetFormat {
            role,
            expected: format,
            found: texture.format(),
        });
    }
    if !texture.usage().contains(usage) {
        return Err(RenderError::TargetUsage {
            role,
            needed: usage,
            found: texture.usage(),
        });
    }
    let target = (texture.width(), texture.height());
    let fits = match size {
        TextureSize::Exact => target == image,
        TextureSize::AtLeast => target.0 >= image.0 && target.1 >= image.1,
    };
    if !fits {
        return Err(RenderError::TargetSize {
            role,
            film: image,
            target,
        });
    }
    Ok(())
}

/// Records the display pass into `encoder`: reads `linear` (an `Rgba32Float` texture
/// with `TEXTURE_BINDING`), applies the exact sRGB curve if `encode_srgb` (else
/// clamps only), quantises to 8 bits and writes `display` (an `Rgba8Unorm` texture
/// with `STORAGE_BINDING` of the same size).
pub(crate) fn encode_display(
    pipelines: &Pipelines,
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    linear: &wgpu::TextureView,
    display: &wgpu::TextureView,
    encode_srgb: bool,
) -> Result<(), RenderError> {
    let (width, height) = (linear.texture().width(), linear.texture().height());
    check_texture(
        linear,
        "display input",
        LINEAR_FORMAT,
        wgpu::TextureUsages::TEXTURE_BINDING,
        (width, height),
        TextureSize::Exact,
    )?;
    check_texture(
        display,
        "display output",
        DISPLAY_FORMAT,
        wgpu::TextureUsages::STORAGE_BINDING,
        (width, height),
        TextureSize::Exact,
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
            layout: &pipelines.display_bind_group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
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
    pass.set_pipeline(&pipelines.display);
    pass.set_bind_group(0, &bind_group, &[]);
    pass.dispatch_workgroups(
        width.div_ceil(WORKGROUP_SIZE),
        height.div_ceil(WORKGROUP_SIZE),
        1,
    );
    Ok(())
}
