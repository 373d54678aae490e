//! Bind group layouts and compute pipelines: the trace kernels, specialised to each
//! scene's features and cached, and the display pass.

use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

use super::RenderError;
use super::cpu_device::node_texture;
use super::cpu_device::uniform_records::{
    SMALL_UNIFORM_BUFFERS, UNIFORM_BUFFERS, UniformRecords, device_allows, device_allows_small,
};
use super::features::ShaderFeatures;
use super::ray_query::{RAY_QUERY_FEATURE, hardware_traversal_available};
use super::readback::{Caught, capture};
use super::shaders::{
    DISPLAY_ENTRY_POINT, FUSED_ENTRY_POINT, SHADE_ENTRY_POINT, TRACE_ENTRY_POINT,
    display_shader_source, trace_shader_source,
};
use super::wavefront::Schedule;

/// Format of the linear radiance texture the trace writes.
pub const LINEAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the display texture (sRGB encoding is done in the shader because
/// `Rgba8UnormSrgb` cannot be a storage texture).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Bindings of the trace module (`shaders/trace.wgsl`): 0 uniforms; 1–7 spheres,
/// planes, polygons, polygon points, triangles, materials, lights; 8 the linear
/// output; 9 counters; 10 accumulation; 11 images; 12–13 BVH nodes and primitives;
/// 14–17 path states, bounce stacks, traces, traversal stacks; 18 mesh triangles'
/// vertex normals and texture coordinates; 19 the path integrator's emitters; 20 the
/// environment map and its sampling tables; 21 the hardware traversal's top-level
/// acceleration structure (only in its layout); 22 the BVH nodes as texels (read only
/// by modules with [`ShaderFeatures::node_texture`], bound in every layout).
pub(crate) mod binding {
    pub const FRAME: u32 = 0;
    pub const SPHERES: u32 = 1;
    pub const PLANES: u32 = 2;
    pub const POLYGONS: u32 = 3;
    pub const POLYGON_POINTS: u32 = 4;
    pub const TRIANGLES: u32 = 5;
    pub const MATERIALS: u32 = 6;
    pub const LIGHTS: u32 = 7;
    pub const LINEAR_OUTPUT: u32 = 8;
    pub const COUNTERS: u32 = 9;
    pub const ACCUMULATION: u32 = 10;
    pub const IMAGES: u32 = 11;
    pub const BVH_NODES: u32 = 12;
    pub const BVH_PRIMS: u32 = 13;
    pub const PATHS: u32 = 14;
    pub const RAY_STACK: u32 = 15;
    pub const TRACES: u32 = 16;
    pub const TRAVERSAL_STACK: u32 = 17;
    pub const TRIANGLE_ATTRIBUTES: u32 = 18;
    pub const EMITTERS: u32 = 19;
    pub const ENVIRONMENT: u32 = 20;
    pub const SCENE_TLAS: u32 = 21;
    pub const NODE_TEXELS: u32 = 22;
}

/// Storage buffers the trace kernels bind in one stage.
pub const TRACE_STORAGE_BUFFERS: u32 = 18;

/// The kernels of one trace module for one schedule: only the entry points the
/// schedule dispatches are built, since drivers compile each pipeline (real ones at
/// creation, lavapipe at its first dispatch) and a kernel never dispatched is compile
/// time for nothing.
#[derive(Debug, Clone)]
pub enum TracePipelines {
    /// `trace_paths`, shading and traversal in one loop ([`Schedule::Fused`]).
    Fused(wgpu::ComputePipeline),
    /// `shade_paths` and `trace_rays`, dispatched in turn ([`Schedule::Wavefront`]).
    Wavefront {
        /// `shade_paths`.
        shade: wgpu::ComputePipeline,
        /// `trace_rays`.
        trace: wgpu::ComputePipeline,
    },
}

impl TracePipelines {
    /// The schedule these kernels run.
    pub fn schedule(&self) -> Schedule {
        match self {
            TracePipelines::Fused(_) => Schedule::Fused,
            TracePipelines::Wavefront { .. } => Schedule::Wavefront,
        }
    }

    /// The kernels of one round, in dispatch order.
    pub(crate) fn round(&self) -> Vec<&wgpu::ComputePipeline> {
        self.named_round()
            .into_iter()
            .map(|(_, pipeline)| pipeline)
            .collect()
    }

    /// The kernels of one round with their entry points' names, in dispatch order.
    pub(crate) fn named_round(&self) -> Vec<(&'static str, &wgpu::ComputePipeline)> {
        match self {
            TracePipelines::Fused(fused) => vec![(FUSED_ENTRY_POINT, fused)],
            TracePipelines::Wavefront { shade, trace } => {
                vec![(SHADE_ENTRY_POINT, shade), (TRACE_ENTRY_POINT, trace)]
            }
        }
    }
}

/// The bind group and pipeline layout of the trace modules of one kind of record
/// binding ([`UniformRecords`]: see [`ShaderFeatures::uniform_records`] and
/// [`ShaderFeatures::node_texture`]), with or without the hardware traversal's
/// acceleration structure ([`ShaderFeatures::hardware_traversal`]).
#[derive(Debug)]
struct TraceLayout {
    bind_group: wgpu::BindGroupLayout,
    pipeline: wgpu::PipelineLayout,
}

impl TraceLayout {
    fn new(
        device: &wgpu::Device,
        records: UniformRecords,
        acceleration_structure: bool,
    ) -> Result<Self, RenderError> {
        use binding::*;
        // The records every traversal step reads: storage or uniform arrays.
        let record = |binding: u32| {
            if records.binds_uniform(binding) {
                uniform_entry(binding)
            } else {
                storage_entry(binding, true)
            }
        };
        // Explicit layouts: an automatic layout would drop bindings a shader leaves
        // unused, and the bind groups would no longer match it.
        let mut entries = vec![
            uniform_entry(FRAME),
            record(SPHERES),
            record(PLANES),
            record(POLYGONS),
            record(POLYGON_POINTS),
            record(TRIANGLES),
            record(MATERIALS),
            record(LIGHTS),
            storage_texture_entry(LINEAR_OUTPUT, LINEAR_FORMAT),
            storage_entry(COUNTERS, false),
            storage_entry(ACCUMULATION, false),
            float_texture_entry(IMAGES, wgpu::TextureViewDimension::D2Array),
            record(BVH_NODES),
            record(BVH_PRIMS),
            storage_entry(PATHS, false),
            storage_entry(RAY_STACK, false),
            storage_entry(TRACES, false),
            storage_entry(TRAVERSAL_STACK, false),
            storage_entry(TRIANGLE_ATTRIBUTES, true),
            storage_entry(EMITTERS, true),
            storage_entry(ENVIRONMENT, true),
            compute_entry(
                NODE_TEXELS,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::ReadOnly,
                    format: node_texture::NODE_TEXEL_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            ),
        ];
        if acceleration_structure {
            entries.push(compute_entry(
                SCENE_TLAS,
                wgpu::BindingType::AccelerationStructure {
                    vertex_return: false,
                },
            ));
        }
        let bind_group = capture(device, "trace bind group layout", Caught::Resource, || {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(match (records, acceleration_structure) {
                    (UniformRecords::All, _) => "gpu-render trace bindings (uniform records)",
                    (UniformRecords::Small, _) => {
                        "gpu-render trace bindings (small uniform records, node texture)"
                    }
                    (UniformRecords::None, true) => {
                        "gpu-render trace bindings (acceleration structure)"
                    }
                    (UniformRecords::None, false) => "gpu-render trace bindings",
                }),
                entries: &entries,
            })
        })?;
        let pipeline = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu-render trace layout"),
            bind_group_layouts: &[Some(&bind_group)],
            immediate_size: 0,
        });
        Ok(Self {
            bind_group,
            pipeline,
        })
    }
}

/// Every layout and pipeline the renderer uses on one device.
#[derive(Debug)]
pub(crate) struct Pipelines {
    /// With storage records.
    storage_layout: TraceLayout,
    /// With uniform records, where the device binds enough uniform buffers
    /// (`uniform_records::device_allows`).
    uniform_layout: Option<TraceLayout>,
    /// With the small records uniform and the BVH nodes in a texture, where the
    /// device binds enough uniform buffers (`uniform_records::device_allows_small`).
    node_texture_layout: Option<TraceLayout>,
    /// With storage records and the hardware traversal's acceleration structure,
    /// where the device has ray queries
    /// ([`super::ray_query::hardware_traversal_available`]).
    hardware_layout: Option<TraceLayout>,
    pub display_bind_group_layout: wgpu::BindGroupLayout,
    pub display: wgpu::ComputePipeline,
    /// Trace pipelines by feature set and schedule, built on first use.
    trace: Mutex<HashMap<(ShaderFeatures, Schedule), TracePipelines>>,
    /// The driver's cache of compiled pipelines every pipeline goes through, if any.
    cache: Option<wgpu::PipelineCache>,
    /// The one-texel texture bound where a scene's BVH nodes are not in a texture
    /// (every trace layout has the binding), one for all the device's scenes.
    pub node_texels_placeholder: wgpu::TextureView,
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

fn float_texture_entry(
    binding: u32,
    dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::Texture {
            // Rgba32Float is not filterable without an extra feature; the shaders
            // only use textureLoad.
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: dimension,
            multisampled: false,
        },
    )
}

impl Pipelines {
    /// Builds the layouts and the display pipeline (trace pipelines come on demand),
    /// every pipeline through `cache` if given (a driver's cache of compiled code,
    /// [`super::RendererOptions::pipeline_cache`]).
    pub fn new(
        device: &wgpu::Device,
        cache: Option<wgpu::PipelineCache>,
    ) -> Result<Self, RenderError> {
        let storage_layout = TraceLayout::new(device, UniformRecords::None, false)?;
        let uniform_layout = if device_allows(&device.limits()) {
            Some(TraceLayout::new(device, UniformRecords::All, false)?)
        } else {
            None
        };
        let node_texture_layout = if device_allows_small(&device.limits()) {
            Some(TraceLayout::new(device, UniformRecords::Small, false)?)
        } else {
            None
        };
        let hardware_layout = if hardware_traversal_available(device) {
            Some(TraceLayout::new(device, UniformRecords::None, true)?)
        } else {
            None
        };
        let display_bind_group_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("gpu-render display bindings"),
                entries: &[
                    uniform_entry(0),
                    float_texture_entry(1, wgpu::TextureViewDimension::D2),
                    storage_texture_entry(2, DISPLAY_FORMAT),
                ],
            });
        let display_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("gpu-render display layout"),
                bind_group_layouts: &[Some(&display_bind_group_layout)],
                immediate_size: 0,
            });
        let display = build_pipelines(
            device,
            "display",
            display_shader_source(),
            &display_pipeline_layout,
            &[DISPLAY_ENTRY_POINT],
            cache.as_ref(),
        )?
        .remove(0);
        Ok(Self {
            storage_layout,
            uniform_layout,
            node_texture_layout,
            hardware_layout,
            display_bind_group_layout,
            display,
            trace: Mutex::new(HashMap::new()),
            cache,
            node_texels_placeholder: node_texture::placeholder(device),
        })
    }

    /// The trace pipelines of `schedule` for `features`, built and cached on first use.
    pub fn trace(
        &self,
        device: &wgpu::Device,
        features: &ShaderFeatures,
        schedule: Schedule,
    ) -> Result<TracePipelines, RenderError> {
        let mut cache = self.trace.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(pipelines) = cache.get(&(*features, schedule)) {
            return Ok(pipelines.clone());
        }
        let layout = self.trace_layout(device, features)?;
        let label = format!("trace ({})", features.label());
        let source = trace_shader_source(features).map_err(|error| RenderError::ShaderSource {
            module: label.clone(),
            message: error.to_string(),
        })?;
        let entry_points: &[&str] = match schedule {
            Schedule::Fused => &[FUSED_ENTRY_POINT],
            Schedule::Wavefront => &[SHADE_ENTRY_POINT, TRACE_ENTRY_POINT],
        };
        let mut built = build_pipelines(
            device,
            &label,
            source,
            &layout.pipeline,
            entry_points,
            self.cache.as_ref(),
        )?;
        let pipelines = match schedule {
            Schedule::Fused => TracePipelines::Fused(built.remove(0)),
            Schedule::Wavefront => TracePipelines::Wavefront {
                trace: built.remove(1),
                shade: built.remove(0),
            },
        };
        cache.insert((*features, schedule), pipelines.clone());
        Ok(pipelines)
    }

    /// Whether the trace pipelines of `schedule` for `features` are built and cached
    /// already.
    pub(crate) fn has_trace(&self, features: &ShaderFeatures, schedule: Schedule) -> bool {
        self.trace
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .contains_key(&(*features, schedule))
    }

    /// The layouts of the trace modules for `features` (their record bindings are
    /// storage or uniform buffers).
    ///
    /// Errors: [`RenderError::Limit`] for uniform records (all or the small ones) on a
    /// device that binds too few uniform buffers, [`RenderError::MissingFeature`] for
    /// the hardware traversal
    /// on a device without ray queries (an upload never chooses them there).
    fn trace_layout(
        &self,
        device: &wgpu::Device,
        features: &ShaderFeatures,
    ) -> Result<&TraceLayout, RenderError> {
        if features.hardware_traversal {
            return self
                .hardware_layout
                .as_ref()
                .ok_or(RenderError::MissingFeature {
                    what: "hardware traversal",
                    feature: RAY_QUERY_FEATURE,
                    hint: "",
                });
        }
        let (layout, needed) = match UniformRecords::of(features) {
            UniformRecords::None => return Ok(&self.storage_layout),
            UniformRecords::All => (&self.uniform_layout, UNIFORM_BUFFERS),
            UniformRecords::Small => (&self.node_texture_layout, SMALL_UNIFORM_BUFFERS),
        };
        layout.as_ref().ok_or_else(|| RenderError::Limit {
            limit: "max_uniform_buffers_per_shader_stage",
            needed: u64::from(needed),
            available: u64::from(device.limits().max_uniform_buffers_per_shader_stage),
        })
    }

    /// The bind group layout of the trace modules for a prepared scene's `features`
    /// (uploads choose uniform records, all or the small ones, only where the device
    /// has their layout).
    pub fn trace_bind_group_layout(&self, features: &ShaderFeatures) -> &wgpu::BindGroupLayout {
        let layout = if features.hardware_traversal {
            self.hardware_layout.as_ref()
        } else {
            match UniformRecords::of(features) {
                UniformRecords::None => None,
                UniformRecords::All => self.uniform_layout.as_ref(),
                UniformRecords::Small => self.node_texture_layout.as_ref(),
            }
        };
        &layout.unwrap_or(&self.storage_layout).bind_group
    }

    /// How many trace modules have been built so far.
    pub fn cached_trace_count(&self) -> usize {
        self.trace
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .len()
    }
}

/// Creates one shader module and a compute pipeline per entry point inside error
/// scopes, so that WGSL or pipeline errors come back as [`RenderError::Shader`] instead of
/// panicking.
pub(crate) fn build_pipelines(
    device: &wgpu::Device,
    name: &str,
    source: String,
    layout: &wgpu::PipelineLayout,
    entry_points: &[&str],
    cache: Option<&wgpu::PipelineCache>,
) -> Result<Vec<wgpu::ComputePipeline>, RenderError> {
    capture(device, &format!("{name} shader"), Caught::Shader, || {
        let desc = wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        };
        let module = device.create_shader_module(desc);
        entry_points
            .iter()
            .map(|entry_point| {
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(&format!("{name}: {entry_point}")),
                    layout: Some(layout),
                    module: &module,
                    entry_point: Some(entry_point),
                    compilation_options: wgpu::PipelineCompilationOptions::default(),
                    cache,
                })
            })
            .collect()
    })
}
