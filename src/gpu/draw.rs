//! The draw of a film into the caller's render pass (`shaders/draw.wgsl`): a
//! fullscreen-triangle render pipeline for the colour format given in
//! [`super::RendererOptions::surface_format`], one per sRGB rule.

use super::RenderError;
use super::readback::{Caught, capture};
use super::shaders::draw_shader_source;

/// What the fragment shader does to a film value before the attachment stores it
/// (`DRAW_MODE` in `shaders/draw.wgsl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum DrawMode {
    /// Clamp only.
    Clamp = 0,
    /// Apply the exact sRGB curve.
    Encode = 1,
    /// Apply the inverse curve (the attachment encodes again).
    Decode = 2,
}

impl DrawMode {
    /// The mode that shows a scene whose display values are sRGB-encoded radiance
    /// (`encodes_srgb`) or already display values, on an attachment that does
    /// (`target_srgb`) or does not encode what it stores: the curve is applied exactly
    /// once, by the shader or by the attachment.
    pub fn new(encodes_srgb: bool, target_srgb: bool) -> Self {
        match (encodes_srgb, target_srgb) {
            (true, true) | (false, false) => DrawMode::Clamp,
            (true, false) => DrawMode::Encode,
            (false, true) => DrawMode::Decode,
        }
    }
}

/// The draw pipelines for one colour format.
#[derive(Debug)]
pub(crate) struct DrawPipelines {
    pub layout: wgpu::BindGroupLayout,
    /// For scenes whose display values are sRGB-encoded radiance, and for the others.
    linear_scene: wgpu::RenderPipeline,
    display_scene: wgpu::RenderPipeline,
}

impl DrawPipelines {
    /// Builds both pipelines for `format` inside error scopes.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<Self, RenderError> {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gpu-render draw bindings"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu-render draw layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let target_srgb = format.is_srgb();
        let (linear_scene, display_scene) = capture(device, "draw shader", Caught::Shader, || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("gpu-render draw"),
                source: wgpu::ShaderSource::Wgsl(draw_shader_source().into()),
            });
            let pipeline = |mode: DrawMode| {
                let constants = [("DRAW_MODE", f64::from(mode as u32))];
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("gpu-render draw"),
                    layout: Some(&pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("fullscreen_triangle"),
                        compilation_options: wgpu::PipelineCompilationOptions::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: None,
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("draw_film"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants: &constants,
                            ..Default::default()
                        },
                        targets: &[Some(wgpu::ColorTargetState {
                            format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
            (
                pipeline(DrawMode::new(true, target_srgb)),
                pipeline(DrawMode::new(false, target_srgb)),
            )
        })?;
        Ok(Self {
            layout,
            linear_scene,
            display_scene,
        })
    }

    /// The pipeline for a scene with the sRGB rule `encodes_srgb`.
    pub fn pipeline(&self, encodes_srgb: bool) -> &wgpu::RenderPipeline {
        if encodes_srgb {
            &self.linear_scene
        } else {
            &self.display_scene
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_is_applied_once() {
        assert_eq!(DrawMode::new(true, true), DrawMode::Clamp);
        assert_eq!(DrawMode::new(true, false), DrawMode::Encode);
        assert_eq!(DrawMode::new(false, false), DrawMode::Clamp);
        assert_eq!(DrawMode::new(false, true), DrawMode::Decode);
    }
}
