//! A scene uploaded to one device: its buffers (primitives, BVH, materials, lights; the
//! records every traversal step reads in uniform buffers where `super::cpu_device::uniform_records`
//! says), its image array and its trace constants.

use super::RenderError;
use super::area_lights::{EMITTER_NONE, FLAG_PATH, GpuEmitter, emitter_records};
use super::cpu_device::uniform_records::UniformRecords;
use super::cpu_device::unrolled::{self, UnrolledPrimitives};
use super::cpu_device::{node_texture, uniform_records};
use super::environment::environment_buffer;
use super::features::ShaderFeatures;
use super::layout::FrameUniforms;
use super::pipelines::binding;
use super::ray_query::{
    Acceleration, Traversal, build_acceleration, fits_hardware, wants_hardware,
};
use super::readback::{Caught, capture};
use super::upload::{
    InstanceLayout, SceneRecords, frame_uniforms, image_array_levels, image_array_size,
    image_layer, image_layer_level,
};
use crate::accel::{
    BrdfMapCdfs, BuildMethod, Bvh, BvhStats, EnvironmentLight, MAX_PLANES, SceneGeometry,
};
use crate::scene::{Integrator, Scene};
use crate::texture::mip_levels;

/// The storage buffers of an uploaded scene.
#[derive(Debug)]
pub(crate) struct SceneBuffers {
    pub spheres: wgpu::Buffer,
    pub planes: wgpu::Buffer,
    pub polygons: wgpu::Buffer,
    pub polygon_points: wgpu::Buffer,
    pub triangles: wgpu::Buffer,
    pub materials: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub bvh_nodes: wgpu::Buffer,
    pub bvh_prims: wgpu::Buffer,
    pub triangle_attributes: wgpu::Buffer,
    /// The path integrator's emitters (one padding record for Whitted scenes).
    pub emitters: wgpu::Buffer,
    /// The environment map and its sampling tables (a header alone without a map).
    pub environment: wgpu::Buffer,
}

/// A scene's buffers and constants on one device (what [`super::GpuScene`] holds
/// besides its pipelines and camera).
#[derive(Debug)]
pub(crate) struct DeviceScene {
    pub(crate) frame: FrameUniforms,
    pub(crate) stack_size: u32,
    pub(crate) features: ShaderFeatures,
    pub(crate) encode_srgb: bool,
    pub(crate) buffers: SceneBuffers,
    /// Albedo textures and BRDF maps, one layer each (see [`super::upload::image_layers`]).
    pub(crate) images: wgpu::TextureView,
    /// The BVH nodes as texels ([`ShaderFeatures::node_texture`]), else the
    /// renderer's one-texel placeholder.
    pub(crate) node_texels: wgpu::TextureView,
    /// The acceleration structures of the hardware traversal
    /// ([`ShaderFeatures::hardware_traversal`]), if it is used.
    pub(crate) acceleration: Option<Acceleration>,
    bvh: BvhStats,
    scene_bytes: u64,
    image_bytes: u64,
}

impl DeviceScene {
    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.frame.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.frame.height
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.frame.samples_per_pixel
    }

    /// Capacity of each path's bounce stack.
    pub fn stack_size(&self) -> u32 {
        self.stack_size
    }

    /// The shader features the trace pipelines for this scene contain.
    pub fn features(&self) -> ShaderFeatures {
        self.features
    }

    /// Whether the display pass should apply the sRGB curve for this scene (false in
    /// naive gamma mode).
    pub fn display_encodes_srgb(&self) -> bool {
        self.encode_srgb
    }

    /// The trace constants for the whole image (the scheduler sets region, samples,
    /// slots and budget per trace).
    pub fn frame_uniforms(&self) -> &FrameUniforms {
        &self.frame
    }

    /// How the BVH the GPU walks was built: the scene's, or with the hardware
    /// traversal the analytic shapes' alone (the driver builds the triangles'
    /// structures, whose figures wgpu does not give).
    pub fn bvh_stats(&self) -> &BvhStats {
        &self.bvh
    }

    /// Bytes of the scene's buffers on the device (primitives, BVH, materials,
    /// lights, and the BVH nodes' texture where there is one; not the images or the
    /// per-trace slots).
    pub fn scene_bytes(&self) -> u64 {
        self.scene_bytes
    }

    /// Bytes of the scene's image array on the device (albedo textures and BRDF
    /// maps, `Rgba32Float`, at least one 1×1 layer).
    pub fn image_bytes(&self) -> u64 {
        self.image_bytes
    }
}

/// How [`upload_scene`] may specialise a scene's trace module.
#[derive(Debug, Clone, Copy)]
pub(crate) struct UploadOptions {
    /// Only the features the scene uses ([`ShaderFeatures::for_scene`]), else all.
    pub specialise: bool,
    /// Records in uniform buffers where the device prefers them and they fit, else
    /// the BVH nodes in a texture where it prefers that and they fit.
    pub allow_uniform_records: bool,
    /// Traversals that give way, where the device has subgroup operations.
    pub allow_refill_lanes: bool,
    /// Whitted samples that start in lockstep, where the device has subgroup
    /// operations.
    pub allow_lockstep_samples: bool,
    /// A small scene's closest-hit test unrolled, where the device prefers it
    /// ([`super::unrolled`]).
    pub allow_unrolled: bool,
    /// The module records the auxiliary passes ([`ShaderFeatures::aov`]; the general
    /// module always can).
    pub aov: bool,
}

/// The hardware traversal's software part: the tree of the analytic shapes and where
/// the instances' records go after it ([`hardware_plan`]).
pub(crate) type HardwarePlan = (Bvh, InstanceLayout);

/// The hardware traversal's plan for `geometry` on `device` where `traversal` takes
/// it: the tree of the analytic shapes the software walk keeps (the structures hold
/// the triangles and instances) and where the instances' records go after it; `None`
/// for the software walk of the scene's tree.
///
/// Errors: as [`wants_hardware`] and [`fits_hardware`], for [`Traversal::Hardware`].
pub(crate) fn hardware_plan(
    traversal: Traversal,
    device: &wgpu::Device,
    geometry: &SceneGeometry,
) -> Result<Option<HardwarePlan>, RenderError> {
    if !wants_hardware(traversal, device, geometry)? {
        return Ok(None);
    }
    let tree = geometry.analytic_bvh(BuildMethod::Sah);
    let layout = InstanceLayout::with_scene_nodes(geometry, tree.wide.len());
    Ok(fits_hardware(traversal, geometry, &layout, &device.limits())?.then_some((tree, layout)))
}

/// Uploads `scene` (as loaded: it is converted to its lighting space here) with its
/// `geometry` (built from the lighting-space-independent shapes). With
/// `allow_uniform_records`, a scene whose records fit is bound with uniform records
/// where the device prefers them (see `super::cpu_device::uniform_records`). With
/// `allow_refill_lanes`, the trace module gives way to finished lanes
/// ([`ShaderFeatures::refill_lanes`]) where the device has subgroup operations, and
/// with `allow_lockstep_samples` its Whitted samples start in lockstep there
/// ([`ShaderFeatures::lockstep_samples`]). With
/// `allow_unrolled`, a small scene's closest-hit test is unrolled
/// ([`ShaderFeatures::unrolled`]) where the device prefers it.
/// `analytic` is the hardware traversal's plan ([`hardware_plan`]), `None` for the
/// software walk of `geometry`'s tree.
pub(crate) fn upload_scene(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    geometry: &SceneGeometry,
    options: UploadOptions,
    analytic: Option<HardwarePlan>,
    node_texels_placeholder: &wgpu::TextureView,
) -> Result<DeviceScene, RenderError> {
    let UploadOptions {
        specialise,
        allow_uniform_records,
        allow_refill_lanes,
        allow_lockstep_samples,
        allow_unrolled,
        aov,
    } = options;
    scene.render.check().map_err(RenderError::InvalidSettings)?;
    if geometry.planes.len() > MAX_PLANES {
        return Err(RenderError::SceneTooLarge {
            what: "infinite planes (every ray tests every plane; use polygons)".into(),
            value: geometry.planes.len() as u64,
            limit: MAX_PLANES as u64,
        });
    }
    let shaded = scene.in_lighting_space();
    let scene_features = ShaderFeatures::for_scene(scene);
    let hardware = analytic.is_some();
    // Geometry made without its tree (Renderer::upload, for the hardware path) that
    // the software walk traced would find nothing: a bug, not a user's error.
    debug_assert!(
        hardware
            || !geometry.bvh.prims.is_empty()
            || (geometry.spheres.is_empty()
                && geometry.polygons.is_empty()
                && geometry.triangles.is_empty()
                && geometry.instances.is_empty()),
        "the software walk needs the scene's tree"
    );
    let limits = device.limits();
    let records = match &analytic {
        Some((tree, _)) => SceneRecords::with_scene_tree(&shaded, geometry, tree),
        None => SceneRecords::new(&shaded, geometry),
    };
    let path = scene.render.integrator == Integrator::Path;
    let mut frame = frame_uniforms(&shaded, geometry);
    if let Some((tree, _)) = &analytic {
        frame.node_count = u32::try_from(tree.wide.len()).unwrap_or(u32::MAX);
    }
    let emitters = if path {
        // The integrator is a flag of the trace: every trace of the scene keeps it.
        frame.flags |= FLAG_PATH;
        frame.stack_size = frame.stack_size.max(1);
        // Instances named where the records put them: after the tree the GPU walks.
        let layout = match &analytic {
            Some((_, layout)) => layout.clone(),
            None => InstanceLayout::new(geometry),
        };
        emitter_records(geometry, &layout, &shaded.materials, &shaded.images)
    } else {
        vec![GpuEmitter::NONE]
    };
    // The map's distribution, shared with the CPU reference (`crate::cpu::PreparedScene`).
    let environment = environment_buffer(
        shaded
            .environment
            .map
            .clone()
            .map(|map| {
                let has_area_lights = path && emitters[0].kind != EMITTER_NONE;
                EnvironmentLight::new(map, has_area_lights)
            })
            .as_ref(),
    );
    let max_binding = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    let padded = records.padded();
    // The hardware traversal's triangle buffer is the structures' vertex buffer: a
    // storage buffer.
    let cpu_records =
        allow_uniform_records && !hardware && uniform_records::preferred(&device.adapter_info());
    let uniform_records = cpu_records && uniform_records::fits(&padded, &limits);
    // Too large for uniform arrays: the nodes in a texture and the small records
    // uniform, where they fit.
    let node_texture = cpu_records
        && !uniform_records
        && node_texture::fits(padded.bvh_nodes.len(), &limits)
        && uniform_records::small_records_fit(&padded, &limits);
    let record_bindings = UniformRecords::of(&ShaderFeatures {
        uniform_records,
        node_texture,
        ..ShaderFeatures::ALL
    });
    let mut scene_bytes = 0;
    let mut upload =
        |what: &str, binding: u32, bytes: &[u8]| -> Result<wgpu::Buffer, RenderError> {
            // A uniform record array is bound whole: its buffer has the array's length.
            let uniform_bytes = record_bindings
                .binds_uniform(binding)
                .then(|| uniform_records::padded_bytes(binding))
                .flatten();
            let size = uniform_bytes.unwrap_or(bytes.len() as u64);
            // A uniform record array fits its binding (`uniform_records::fits`,
            // `uniform_records::small_records_fit`).
            if uniform_bytes.is_none() && size > max_binding {
                return Err(RenderError::SceneTooLarge {
                    what: format!("{what} buffer bytes"),
                    value: size,
                    limit: max_binding,
                });
            }
            scene_bytes += size;
            let buffer = capture(device, what, Caught::Resource, || {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(what),
                    size,
                    usage: if uniform_bytes.is_some() {
                        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST
                    } else if hardware && binding == binding::TRIANGLES {
                        wgpu::BufferUsages::STORAGE
                            | wgpu::BufferUsages::COPY_DST
                            | wgpu::BufferUsages::BLAS_INPUT
                    } else {
                        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST
                    },
                    mapped_at_creation: false,
                })
            })?;
            // write_buffer stages through the queue: no mapped_at_creation, whose mapping
            // would panic if the allocation had failed.
            queue.write_buffer(&buffer, 0, bytes);
            Ok(buffer)
        };
    let buffers = SceneBuffers {
        spheres: upload(
            "sphere",
            binding::SPHERES,
            bytemuck::cast_slice(&padded.spheres),
        )?,
        planes: upload(
            "plane",
            binding::PLANES,
            bytemuck::cast_slice(&padded.planes),
        )?,
        polygons: upload(
            "polygon",
            binding::POLYGONS,
            bytemuck::cast_slice(&padded.polygons),
        )?,
        polygon_points: upload(
            "polygon point",
            binding::POLYGON_POINTS,
            bytemuck::cast_slice(&padded.polygon_points),
        )?,
        triangles: upload(
            "triangle",
            binding::TRIANGLES,
            bytemuck::cast_slice(&padded.triangles),
        )?,
        materials: upload(
            "material",
            binding::MATERIALS,
            bytemuck::cast_slice(&padded.materials),
        )?,
        lights: upload(
            "light",
            binding::LIGHTS,
            bytemuck::cast_slice(&padded.lights),
        )?,
        bvh_nodes: upload(
            "BVH node",
            binding::BVH_NODES,
            bytemuck::cast_slice(&padded.bvh_nodes),
        )?,
        bvh_prims: upload(
            "BVH primitive",
            binding::BVH_PRIMS,
            bytemuck::cast_slice(&padded.bvh_prims),
        )?,
        triangle_attributes: upload(
            "triangle attribute",
            binding::TRIANGLE_ATTRIBUTES,
            bytemuck::cast_slice(&padded.triangle_attributes),
        )?,
        emitters: upload(
            "emitter",
            binding::EMITTERS,
            bytemuck::cast_slice(&emitters),
        )?,
        environment: upload("environment map", binding::ENVIRONMENT, &environment)?,
    };
    let unrolled = if allow_unrolled
        && !hardware
        && unrolled::preferred(&device.adapter_info())
        && geometry.instances.is_empty()
        && geometry.instanced_meshes.is_empty()
        // The unrolled test has no alpha coverage.
        && !scene_features.alpha
    {
        UnrolledPrimitives::for_scene(&records.bvh_prims, records.planes.len(), &records.polygons)
    } else {
        None
    };
    let acceleration = match &analytic {
        Some((_, layout)) => Some(build_acceleration(
            device,
            queue,
            &buffers.triangles,
            geometry,
            layout,
            !scene_features.alpha,
        )?),
        None => None,
    };
    let (images, image_bytes) = upload_images(device, queue, &shaded, &limits)?;
    let node_texels = if node_texture {
        let (view, bytes) = node_texture::upload(device, queue, &padded.bvh_nodes)?;
        scene_bytes += bytes;
        view
    } else {
        node_texels_placeholder.clone()
    };
    Ok(DeviceScene {
        frame,
        // A path keeps its one continuation on the bounce stack.
        stack_size: if path {
            scene.render.stack_size.max(1)
        } else {
            scene.render.stack_size
        },
        features: ShaderFeatures {
            uniform_records,
            node_texture,
            refill_lanes: allow_refill_lanes
                && device.features().contains(wgpu::Features::SUBGROUP),
            lockstep_samples: allow_lockstep_samples
                && device.features().contains(wgpu::Features::SUBGROUP),
            unrolled,
            hardware_traversal: hardware,
            aov: aov || !specialise,
            ..if specialise {
                scene_features
            } else {
                // The general module, with the alpha test only where it is needed.
                ShaderFeatures {
                    alpha: scene_features.alpha,
                    ..ShaderFeatures::ALL
                }
            }
        },
        encode_srgb: scene.display_encodes_srgb(),
        buffers,
        images,
        node_texels,
        acceleration,
        bvh: match &analytic {
            Some((tree, _)) => tree.stats,
            None => geometry.bvh.stats,
        },
        scene_bytes,
        image_bytes,
    })
}

/// Uploads the scene's images as one `Rgba32Float` 2D array texture (one layer per
/// image, see [`super::upload::image_layers`]), with its mip chain where the scene
/// filters textures ([`image_layer_level`]), and returns its view and its bytes (every
/// level's).
///
/// One layer at a time: its level 0 and its mip chain are made, written and submitted
/// before the next, so that the host holds one layer's copies (and wgpu one layer's
/// staging) at a time, not the whole array's twice (`docs/reliability.md`, "Memory").
fn upload_images(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    limits: &wgpu::Limits,
) -> Result<(wgpu::TextureView, u64), RenderError> {
    let cdfs = BrdfMapCdfs::new(&scene.images, &scene.materials);
    let (width, height, layers) = image_array_size(&scene.images);
    if layers > limits.max_texture_array_layers {
        return Err(RenderError::SceneTooLarge {
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
    // With texture filtering, the array's mip chain: level k of every image in level k
    // of its layer (the CPU reference's PreparedScene::image_levels).
    let filters = scene.render.texture_filtering.filters();
    let extra_levels = if filters {
        image_array_levels(width, height)
    } else {
        0
    };
    let texture = capture(device, "image array", Caught::Resource, || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gpu-render images"),
            size,
            mip_level_count: 1 + extra_levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    })?;
    let write_layer = |layer: u32, level: u32, w: u32, h: u32, texels: &[[f32; 4]]| {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: level,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 16),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        std::mem::size_of_val(texels) as u64
    };
    let mut bytes = 0;
    if scene.images.is_empty() {
        // One 1x1 zero layer (WGSL needs a bound texture), which has no levels beyond 0.
        bytes += write_layer(0, 0, width, height, &[[0.0; 4]]);
    }
    for (layer, image) in scene.images.iter().enumerate() {
        let layer_texels = image_layer(image, cdfs.of_image(layer), width, height);
        bytes += write_layer(layer as u32, 0, width, height, &layer_texels);
        drop(layer_texels);
        if filters {
            let chain = mip_levels(image);
            for k in 1..=extra_levels {
                let (w, h, texels) = image_layer_level(&chain, k, width, height);
                bytes += write_layer(layer as u32, k, w, h, &texels);
            }
        }
        // The staging copies of this layer go to the device now, not with the next.
        queue.submit([]);
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    Ok((view, bytes))
}
