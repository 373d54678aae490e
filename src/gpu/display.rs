//! The display pass: linear radiance to 8-bit display values, with the exact sRGB
//! curve (`shaders/display.wgsl`).

use wgpu::util::DeviceExt;

use super::GpuError;
use super::layout::DisplayUniforms;
use super::pipelines::{DISPLAY_FORMAT, LINEAR_FORMAT, Pipelines};
use super::readback::{Caught, capture};
use super::shaders::WORKGROUP_SIZE;

/// Checks that `view`'s texture has `format`, `usage` and at least `width × height`.
pub(crate) fn check_texture(
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
