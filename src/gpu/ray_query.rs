//! Hardware traversal: the scene's triangles found by the device's ray queries
//! (`shaders/ray_query.wgsl`) in acceleration structures built here, where the device
//! has [`wgpu::Features::EXPERIMENTAL_RAY_QUERY`] and [`Traversal`] asks for it.
//!
//! The structures: one bottom-level structure over the scene's own triangles (world
//! space, in [`SceneGeometry::triangles`] order), one per instanced mesh (its own
//! space), each built straight from the triangle buffer the software walk reads (a
//! triangle record is three 16-byte slots, each a vertex followed by a word, so the
//! buffer is a non-indexed `Float32x3` vertex buffer of stride 16 and a hit's
//! `primitive_index` is the triangle's index in its range); and one top-level
//! structure of their placements, whose 24-bit instance data names a hit as the
//! software walk does: [`WORLD_TRIANGLES`] for the scene's own, the node index of the
//! instance's records for a placement ([`super::upload::InstanceLayout::record`]). The
//! analytic shapes (spheres, polygons, planes), which wgpu's structures do not hold,
//! keep a software tree of their own ([`SceneGeometry::analytic_bvh`]).

use glam::DAffine3;

use super::RenderError;
use super::pipelines::TRACE_STORAGE_BUFFERS;
use super::readback::{Caught, capture};
use super::upload::InstanceLayout;
use crate::accel::SceneGeometry;

/// How the GPU finds the scene's triangles ([`super::RendererOptions::traversal`],
/// `--traversal`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Traversal {
    /// The hardware path where the device offers ray queries and is not a CPU
    /// emulation (lavapipe emulates them in software, slower than our own walk:
    /// `BENCHMARKS.md`, "Hardware traversal"), the scene has triangles and fits the
    /// device's acceleration-structure limits; the software path elsewhere.
    #[default]
    Auto,
    /// Always the software walk of the wide BVH (`shaders/traverse.wgsl`).
    Software,
    /// Always ray queries for the triangles; an error where the device has no ray
    /// queries ([`RenderError::MissingFeature`]) or the scene exceeds its limits
    /// ([`RenderError::SceneTooLarge`]).
    Hardware,
}

/// The top-level instance data of the structure holding the scene's own triangles
/// (`WORLD_TRIANGLES` in `shaders/ray_query.wgsl`): the largest 24-bit value, which no
/// instance record's node index may take.
pub const WORLD_TRIANGLES: u32 = 0x00ff_ffff;

/// The feature the hardware path needs, as messages name it.
pub(crate) const RAY_QUERY_FEATURE: &str = "EXPERIMENTAL_RAY_QUERY";

/// What to add to a device request for the hardware traversal, where the adapter
/// (of features `adapter_features`) offers ray queries: the feature, and wgpu's
/// opt-in to its experimental features, which ray queries still are (without it the
/// request fails). Nothing elsewhere.
///
/// ```
/// let (features, _experimental) =
///     gpu_render::gpu::ray_query_features(wgpu::Features::EXPERIMENTAL_RAY_QUERY);
/// assert_eq!(features, wgpu::Features::EXPERIMENTAL_RAY_QUERY);
/// assert!(gpu_render::gpu::ray_query_features(wgpu::Features::empty()).0.is_empty());
/// ```
pub fn ray_query_features(
    adapter_features: wgpu::Features,
) -> (wgpu::Features, wgpu::ExperimentalFeatures) {
    let features = adapter_features & wgpu::Features::EXPERIMENTAL_RAY_QUERY;
    if features.is_empty() {
        return (features, wgpu::ExperimentalFeatures::disabled());
    }
    // SAFETY: wgpu's experimental features may have bugs an application must accept;
    // gpu-render uses only ray queries, and checks their images against the software
    // traversal and the CPU reference (tests/integration/ray_query.rs).
    (features, unsafe { wgpu::ExperimentalFeatures::enabled() })
}

/// Whether `device` can run the hardware traversal: it was created with
/// [`wgpu::Features::EXPERIMENTAL_RAY_QUERY`] and binds an acceleration structure
/// beside the trace kernels' buffers.
pub fn hardware_traversal_available(device: &wgpu::Device) -> bool {
    missing_requirement(device).is_none()
}

/// Why `device` cannot run the hardware traversal, if it cannot: no ray queries, or
/// a limit that leaves no room to bind the scene's acceleration structure.
fn missing_requirement(device: &wgpu::Device) -> Option<RenderError> {
    let missing = |feature, hint| {
        Some(RenderError::MissingFeature {
            what: "hardware traversal",
            feature,
            hint,
        })
    };
    if !device
        .features()
        .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
    {
        return missing(
            RAY_QUERY_FEATURE,
            "; use --traversal software or auto, or create the device with \
             Features::EXPERIMENTAL_RAY_QUERY and experimental features enabled where \
             the adapter offers it",
        );
    }
    let limits = device.limits();
    let room = " (an acceleration structure beside the trace kernels' buffers)";
    if limits.max_acceleration_structures_per_shader_stage < 1 {
        return missing("max_acceleration_structures_per_shader_stage", room);
    }
    // The trace kernels' storage buffers, their uniform buffer and the structure.
    if limits.max_buffers_and_acceleration_structures_per_shader_stage < TRACE_STORAGE_BUFFERS + 2 {
        return missing(
            "max_buffers_and_acceleration_structures_per_shader_stage",
            room,
        );
    }
    None
}

/// The first acceleration-structure limit of `limits` that `geometry` exceeds, as the
/// error [`Traversal::Hardware`] reports (with `layout`, where its instances' records
/// land).
fn exceeded_limit(
    geometry: &SceneGeometry,
    layout: &InstanceLayout,
    limits: &wgpu::Limits,
) -> Option<RenderError> {
    let too_large = |what: &str, value: u64, limit: u64| {
        (value > limit).then(|| RenderError::SceneTooLarge {
            what: what.to_string(),
            value,
            limit,
        })
    };
    // wgpu checks a bottom-level structure's vertex count against the primitive limit.
    let largest_mesh = geometry
        .instanced_meshes
        .iter()
        .map(|mesh| mesh.triangles.len())
        .chain([geometry.triangles.len()])
        .max()
        .unwrap_or(0) as u64;
    let structures = u64::from(!geometry.triangles.is_empty()) + geometry.instances.len() as u64;
    let last_record = match geometry.instances.len() {
        0 => 0,
        n => u64::from(layout.record((n - 1) as u32)),
    };
    too_large(
        "vertices of one bottom-level acceleration structure (3 per triangle)",
        3 * largest_mesh,
        u64::from(limits.max_blas_primitive_count),
    )
    .or_else(|| {
        too_large(
            "placements in the top-level acceleration structure",
            structures,
            u64::from(limits.max_tlas_instance_count),
        )
    })
    .or_else(|| {
        too_large(
            "the node index of the last instance's records (24-bit instance data)",
            last_record,
            u64::from(WORLD_TRIANGLES - 1),
        )
    })
}

/// Whether `traversal` takes the hardware path for `geometry` on `device`, before
/// its limits are checked ([`fits_hardware`]).
///
/// Errors: with [`Traversal::Hardware`], [`RenderError::MissingFeature`] on a device
/// without ray queries or without room to bind a structure.
pub(crate) fn wants_hardware(
    traversal: Traversal,
    device: &wgpu::Device,
    geometry: &SceneGeometry,
) -> Result<bool, RenderError> {
    match traversal {
        Traversal::Software => Ok(false),
        Traversal::Auto => Ok(hardware_traversal_available(device)
            && device.adapter_info().device_type != wgpu::DeviceType::Cpu
            && (!geometry.triangles.is_empty() || !geometry.instances.is_empty())),
        Traversal::Hardware => match missing_requirement(device) {
            Some(error) => Err(error),
            None => Ok(true),
        },
    }
}

/// Whether `geometry`, its instances' records laid out as `layout`, fits `limits`'
/// acceleration structures: [`Traversal::Auto`] takes the software path where it does
/// not.
///
/// Errors: with [`Traversal::Hardware`], [`RenderError::SceneTooLarge`] naming the
/// first limit exceeded.
pub(crate) fn fits_hardware(
    traversal: Traversal,
    geometry: &SceneGeometry,
    layout: &InstanceLayout,
    limits: &wgpu::Limits,
) -> Result<bool, RenderError> {
    match exceeded_limit(geometry, layout, limits) {
        None => Ok(true),
        Some(error) if traversal == Traversal::Hardware => Err(error),
        Some(_) => Ok(false),
    }
}

/// A scene's acceleration structures on the device: the top-level one the trace
/// kernels bind, and the bottom-level ones it places (kept alive with it).
#[derive(Debug)]
pub struct Acceleration {
    /// The top-level structure (`scene_tlas` in `shaders/ray_query.wgsl`).
    pub tlas: wgpu::Tlas,
    /// The scene's own triangles' structure, then each instanced mesh's.
    _bottom: Vec<wgpu::Blas>,
}

/// The rows of `transform` as a top-level placement takes them (row-major 3×4).
pub fn placement_rows(transform: &DAffine3) -> [f32; 12] {
    let m = transform.matrix3;
    let t = transform.translation;
    let row = |r: usize| {
        [
            m.x_axis[r] as f32,
            m.y_axis[r] as f32,
            m.z_axis[r] as f32,
            t[r] as f32,
        ]
    };
    let [a, b, c] = [row(0), row(1), row(2)];
    [
        a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], c[0], c[1], c[2], c[3],
    ]
}

/// One bottom-level structure to build: `triangles` triangles from `first_triangle`
/// of the triangle buffer.
struct BottomLevel {
    first_triangle: u32,
    triangles: u32,
}

/// Builds `geometry`'s acceleration structures from `triangles` (the uploaded
/// triangle buffer, created with [`wgpu::BufferUsages::BLAS_INPUT`]) and submits the
/// build. With `opaque`, the geometry is opaque (the driver keeps the nearest hit by
/// itself); without, every triangle is a candidate the shader decides
/// (`shaders/ray_query.wgsl`, for alpha coverage), reported once.
///
/// Errors: [`RenderError::OutOfMemory`] or [`RenderError::Wgpu`] if wgpu refuses a
/// structure or its build.
pub fn build_acceleration(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    triangles: &wgpu::Buffer,
    geometry: &SceneGeometry,
    layout: &InstanceLayout,
    opaque: bool,
) -> Result<Acceleration, RenderError> {
    let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut levels = Vec::new();
    if !geometry.triangles.is_empty() {
        levels.push(BottomLevel {
            first_triangle: 0,
            triangles: count(geometry.triangles.len()),
        });
    }
    for (mesh, instanced) in geometry.instanced_meshes.iter().enumerate() {
        levels.push(BottomLevel {
            first_triangle: layout.first_triangle(mesh),
            triangles: count(instanced.triangles.len()),
        });
    }
    let flags = if opaque {
        wgpu::AccelerationStructureGeometryFlags::OPAQUE
    } else {
        wgpu::AccelerationStructureGeometryFlags::NO_DUPLICATE_ANY_HIT_INVOCATION
    };
    let sizes: Vec<wgpu::BlasTriangleGeometrySizeDescriptor> = levels
        .iter()
        .map(|level| wgpu::BlasTriangleGeometrySizeDescriptor {
            vertex_format: wgpu::VertexFormat::Float32x3,
            vertex_count: level.triangles.saturating_mul(3),
            index_format: None,
            index_count: None,
            flags,
        })
        .collect();
    let structure = wgpu::CreateBlasDescriptor {
        label: Some("gpu-render triangles (bottom level)"),
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    };
    let bottom = capture(
        device,
        "bottom-level acceleration structures",
        Caught::Resource,
        || {
            sizes
                .iter()
                .map(|size| {
                    device.create_blas(
                        &structure,
                        wgpu::BlasGeometrySizeDescriptors::Triangles {
                            descriptors: vec![size.clone()],
                        },
                    )
                })
                .collect::<Vec<_>>()
        },
    )?;
    let world = usize::from(!geometry.triangles.is_empty());
    let placements = world + geometry.instances.len();
    let mut tlas = capture(
        device,
        "top-level acceleration structure",
        Caught::Resource,
        || {
            device.create_tlas(&wgpu::CreateTlasDescriptor {
                label: Some("gpu-render placements (top level)"),
                // At least one slot: a scene without triangles binds an empty structure.
                max_instances: count(placements.max(1)),
                flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                update_mode: wgpu::AccelerationStructureUpdateMode::Build,
            })
        },
    )?;
    if world == 1 {
        tlas[0] = Some(wgpu::TlasInstance::new(
            &bottom[0],
            placement_rows(&DAffine3::IDENTITY),
            WORLD_TRIANGLES,
            0xff,
        ));
    }
    for (i, instance) in geometry.instances.iter().enumerate() {
        tlas[world + i] = Some(wgpu::TlasInstance::new(
            &bottom[world + instance.mesh as usize],
            placement_rows(&instance.object_to_world),
            layout.record(count(i)),
            0xff,
        ));
    }
    capture(
        device,
        "acceleration structure build",
        Caught::Resource,
        || {
            let entries: Vec<wgpu::BlasBuildEntry> = levels
                .iter()
                .zip(&sizes)
                .zip(&bottom)
                .map(|((level, size), blas)| wgpu::BlasBuildEntry {
                    blas,
                    geometry: wgpu::BlasGeometries::TriangleGeometries(vec![
                        wgpu::BlasTriangleGeometry {
                            size,
                            vertex_buffer: triangles,
                            first_vertex: level.first_triangle.saturating_mul(3),
                            // A triangle record's three 16-byte slots begin with its vertices.
                            vertex_stride: 16,
                            index_buffer: None,
                            first_index: None,
                            transform_buffer: None,
                            transform_buffer_offset: None,
                        },
                    ]),
                })
                .collect();
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gpu-render acceleration structure build"),
            });
            encoder.build_acceleration_structures(entries.iter(), std::iter::once(&tlas));
            queue.submit([encoder.finish()]);
        },
    )?;
    Ok(Acceleration {
        tlas,
        _bottom: bottom,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat3, DVec3};

    #[test]
    fn placement_rows_are_the_rows_of_the_affine_map() {
        let transform = DAffine3 {
            matrix3: DMat3::from_cols(
                DVec3::new(1.0, 2.0, 3.0),
                DVec3::new(4.0, 5.0, 6.0),
                DVec3::new(7.0, 8.0, 9.0),
            ),
            translation: DVec3::new(10.0, 11.0, 12.0),
        };
        assert_eq!(
            placement_rows(&transform),
            [
                1.0, 4.0, 7.0, 10.0, 2.0, 5.0, 8.0, 11.0, 3.0, 6.0, 9.0, 12.0
            ]
        );
    }
}
