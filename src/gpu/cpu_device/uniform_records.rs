//! Binding the scene records every traversal step reads as uniform buffers, on CPU
//! devices.
//!
//! llvmpipe (Mesa 25.0) loads an element of a storage buffer whose index differs from
//! lane to lane of a SIMD vector one lane at a time, each lane behind a branch on its
//! execution mask and another on the buffer's bounds (`emit_load_mem` in gallivm's
//! `lp_bld_nir_soa.c`); an element of a uniform buffer it gathers without branches. The
//! BVH nodes and primitive references, planes, spheres, polygons and their points,
//! triangles, materials and lights are read at every traversal and shading step, so
//! where each of them fits in one uniform binding ([`UNIFORM_RECORD_BYTES`]) and the
//! device is a CPU, they are bound as uniform arrays
//! of a fixed length (the binding padded to it), which makes the trace of
//! `scenes/showcase.toml` about 28% shorter on lavapipe (BENCHMARKS.md, "Uniform
//! records"). On GPUs, uniform (constant) memory serialises lanes that read different
//! addresses, so those keep storage buffers.
//!
//! The WGSL declarations of these bindings are composed here ([`declarations`]) rather
//! than written in `shaders/bindings.wgsl`, as the module `records` of the composer
//! (`crate::gpu::shaders`), since their address space and array type are what differs; the
//! code that reads them is the same.

use std::mem::size_of;

use crate::accel::WideNode;
use crate::gpu::features::ShaderFeatures;
use crate::gpu::layout::{GpuLight, GpuMaterial, GpuPlane, GpuPolygon, GpuSphere, GpuTriangle};
use crate::gpu::pipelines::binding;
use crate::gpu::upload::SceneRecords;

/// The bytes of each uniform record binding: the least `maxUniformBufferRange` Vulkan
/// guarantees is 16 KiB, lavapipe's is 64 KiB; [`fits`] checks the device's.
pub const UNIFORM_RECORD_BYTES: u64 = 65536;

/// One record array that may be bound as a uniform buffer.
struct RecordBinding {
    binding: u32,
    name: &'static str,
    wgsl_type: &'static str,
    stride: usize,
    /// The scene's records of this binding.
    length: fn(&SceneRecords) -> usize,
}

/// The record arrays bound as uniform buffers, in binding order (besides the packed
/// ones, [`PACKED`]). The planes too: every ray reads them all in the same order, but
/// llvmpipe does not see that the index is the same in every lane and loaded a storage
/// plane lane by lane (`glass.toml` took 8% less CPU time with uniform planes,
/// BENCHMARKS.md "Uniform records").
const RECORDS: [RecordBinding; 7] = [
    RecordBinding {
        binding: binding::PLANES,
        name: "planes",
        wgsl_type: "Plane",
        stride: size_of::<GpuPlane>(),
        length: |r| r.planes.len(),
    },
    RecordBinding {
        binding: binding::SPHERES,
        name: "spheres",
        wgsl_type: "Sphere",
        stride: size_of::<GpuSphere>(),
        length: |r| r.spheres.len(),
    },
    RecordBinding {
        binding: binding::POLYGONS,
        name: "polygons",
        wgsl_type: "Polygon",
        stride: size_of::<GpuPolygon>(),
        length: |r| r.polygons.len(),
    },
    RecordBinding {
        binding: binding::TRIANGLES,
        name: "triangles",
        wgsl_type: "Triangle",
        stride: size_of::<GpuTriangle>(),
        length: |r| r.triangles.len(),
    },
    RecordBinding {
        binding: binding::MATERIALS,
        name: "materials",
        wgsl_type: "Material",
        stride: size_of::<GpuMaterial>(),
        length: |r| r.materials.len(),
    },
    RecordBinding {
        binding: binding::LIGHTS,
        name: "lights",
        wgsl_type: "Light",
        stride: size_of::<GpuLight>(),
        length: |r| r.lights.len(),
    },
    RecordBinding {
        binding: binding::BVH_NODES,
        name: "bvh_nodes",
        wgsl_type: "WideNode",
        stride: size_of::<WideNode>(),
        length: |r| r.bvh_nodes.len(),
    },
];

/// An array of 4- or 8-byte elements, which a uniform array holds packed four or two
/// to a `vec4` (its array stride must be 16 bytes), read through an accessor function
/// that both declarations define.
struct PackedBinding {
    binding: u32,
    name: &'static str,
    /// The storage array's element type.
    element: &'static str,
    /// The uniform array's element type, a `vec4`.
    packed: &'static str,
    /// Elements per `vec4`.
    per_vec4: usize,
    /// The accessor: `fn {accessor}(i: u32) -> {element}`.
    accessor: &'static str,
    /// The accessor's body for the packed array, reading element `i`.
    packed_read: &'static str,
    /// The scene's elements of this binding.
    length: fn(&SceneRecords) -> usize,
}

/// The primitive references (4 bytes) and the polygons' projected points (8 bytes).
const PACKED: [PackedBinding; 2] = [
    PackedBinding {
        binding: binding::POLYGON_POINTS,
        name: "polygon_points",
        element: "vec2<f32>",
        packed: "vec4<f32>",
        per_vec4: 2,
        accessor: "polygon_point",
        packed_read: "let c = (i & 1u) * 2u; return vec2<f32>(polygon_points[i >> 1u][c], polygon_points[i >> 1u][c + 1u]);",
        length: |r| r.polygon_points.len(),
    },
    PackedBinding {
        binding: binding::BVH_PRIMS,
        name: "bvh_prims",
        element: "u32",
        packed: "vec4<u32>",
        per_vec4: 4,
        accessor: "prim_ref",
        packed_read: "return bvh_prims[i >> 2u][i & 3u];",
        length: |r| r.bvh_prims.len(),
    },
];

/// The uniform buffers the trace kernels bind in one stage with uniform records: the
/// frame's and one per record array.
pub(crate) const UNIFORM_BUFFERS: u32 = 1 + (RECORDS.len() + PACKED.len()) as u32;

/// The record arrays that scenes too large for uniform records still bind as uniform
/// arrays where they fit, beside their BVH nodes in a texture
/// ([`UniformRecords::Small`]): the planes every ray tests, and the materials and
/// lights every shading step reads, which real scenes have few of. The bunny of
/// `scenes/bench/bunny.toml` traced 11% faster with them uniform (BENCHMARKS.md,
/// "Small records in uniform buffers, nodes in a storage texture").
const SMALL_RECORDS: [u32; 3] = [binding::PLANES, binding::MATERIALS, binding::LIGHTS];

/// The uniform buffers the trace kernels bind in one stage with
/// [`UniformRecords::Small`]: the frame's and the small records'.
pub(crate) const SMALL_UNIFORM_BUFFERS: u32 = 1 + SMALL_RECORDS.len() as u32;

/// Which record bindings a trace module and its layout bind as uniform arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum UniformRecords {
    /// None: every record array is a storage buffer.
    None,
    /// Every record array ([`is_uniform_record`]): a small scene on a CPU device
    /// ([`crate::gpu::ShaderFeatures::uniform_records`]).
    All,
    /// The small record arrays ([`SMALL_RECORDS`]), the others storage buffers and the
    /// BVH nodes in a texture: a larger scene on a CPU device
    /// ([`crate::gpu::ShaderFeatures::node_texture`]).
    Small,
}

impl UniformRecords {
    /// The record bindings of a module with `features`.
    pub(crate) fn of(features: &ShaderFeatures) -> Self {
        if features.uniform_records {
            Self::All
        } else if features.node_texture {
            Self::Small
        } else {
            Self::None
        }
    }

    /// Whether record binding `binding` is a uniform array.
    pub(crate) fn binds_uniform(self, binding: u32) -> bool {
        match self {
            Self::None => false,
            Self::All => is_uniform_record(binding),
            Self::Small => SMALL_RECORDS.contains(&binding),
        }
    }
}

/// Whether a device with `limits` can bind the records as uniform buffers at all
/// (the trace layout with uniform records is built only then).
pub(crate) fn device_allows(limits: &wgpu::Limits) -> bool {
    limits.max_uniform_buffer_binding_size >= UNIFORM_RECORD_BYTES
        && limits.max_uniform_buffers_per_shader_stage >= UNIFORM_BUFFERS
}

/// Whether a device with `limits` can bind the small records as uniform buffers (the
/// trace layout of [`UniformRecords::Small`] is built only then).
pub(crate) fn device_allows_small(limits: &wgpu::Limits) -> bool {
    limits.max_uniform_buffer_binding_size >= UNIFORM_RECORD_BYTES
        && limits.max_uniform_buffers_per_shader_stage >= SMALL_UNIFORM_BUFFERS
}

/// How many records of `stride` bytes one uniform binding holds.
const fn capacity(stride: usize) -> usize {
    UNIFORM_RECORD_BYTES as usize / stride
}

/// The `vec4`s of one packed uniform binding.
const PACKED_VEC4S: usize = UNIFORM_RECORD_BYTES as usize / 16;

/// Whether `binding` is one of the record bindings that [`declarations`] makes
/// uniform.
pub(crate) fn is_uniform_record(binding: u32) -> bool {
    RECORDS.iter().any(|r| r.binding == binding) || PACKED.iter().any(|p| p.binding == binding)
}

/// The bytes the buffer of record binding `binding` is padded to when it is bound as
/// a uniform array (its capacity times its stride), or `None` for other bindings.
pub(crate) fn padded_bytes(binding: u32) -> Option<u64> {
    RECORDS
        .iter()
        .find(|r| r.binding == binding)
        .map(|r| (capacity(r.stride) * r.stride) as u64)
        .or_else(|| {
            PACKED
                .iter()
                .any(|p| p.binding == binding)
                .then_some(UNIFORM_RECORD_BYTES)
        })
}

/// The WGSL declarations of the record bindings: storage arrays, or where `records`
/// binds them uniform, uniform arrays of their capacity; the accessors of the packed
/// ones, `polygon_point(i)` and `prim_ref(i)`; and `load_wide_node(i)`, which reads
/// the node from `bvh_nodes`, or with [`UniformRecords::Small`] from the texture of
/// `super::node_texture`.
pub(crate) fn declarations(records: UniformRecords) -> String {
    let node_reader = if records == UniformRecords::Small {
        super::node_texture::wgsl()
    } else {
        "fn load_wide_node(i: u32) -> WideNode { return bvh_nodes[i]; }\n".to_string()
    };
    let packed = PACKED.iter().map(|p| {
        if records.binds_uniform(p.binding) {
            format!(
                "@group(0) @binding({}) var<uniform> {}: array<{}, {}>;\n\
                 fn {}(i: u32) -> {} {{ {} }}\n",
                p.binding, p.name, p.packed, PACKED_VEC4S, p.accessor, p.element, p.packed_read
            )
        } else {
            format!(
                "@group(0) @binding({}) var<storage, read> {}: array<{}>;\n\
                 fn {}(i: u32) -> {} {{ return {}[i]; }}\n",
                p.binding, p.name, p.element, p.accessor, p.element, p.name
            )
        }
    });
    RECORDS
        .iter()
        .map(|r| {
            if records.binds_uniform(r.binding) {
                format!(
                    "@group(0) @binding({}) var<uniform> {}: array<{}, {}>;\n",
                    r.binding,
                    r.name,
                    r.wgsl_type,
                    capacity(r.stride)
                )
            } else {
                format!(
                    "@group(0) @binding({}) var<storage, read> {}: array<{}>;\n",
                    r.binding, r.name, r.wgsl_type
                )
            }
        })
        .chain(packed)
        .chain(std::iter::once(node_reader))
        .collect()
}

/// Whether every record array of `records` fits in its uniform binding on a device
/// with `limits`.
pub(crate) fn fits(records: &SceneRecords, limits: &wgpu::Limits) -> bool {
    device_allows(limits)
        && RECORDS
            .iter()
            .all(|r| (r.length)(records) <= capacity(r.stride))
        && PACKED
            .iter()
            .all(|p| (p.length)(records) <= PACKED_VEC4S * p.per_vec4)
}

/// Whether the small record arrays of `records` ([`SMALL_RECORDS`]) fit their uniform
/// bindings on a device with `limits`.
pub(crate) fn small_records_fit(records: &SceneRecords, limits: &wgpu::Limits) -> bool {
    device_allows_small(limits)
        && RECORDS
            .iter()
            .filter(|r| SMALL_RECORDS.contains(&r.binding))
            .all(|r| (r.length)(records) <= capacity(r.stride))
}

/// Whether a scene whose records [`fits`] binds them as uniform arrays on the device
/// `info` describes: on CPU devices only (see the module's documentation).
pub(crate) fn preferred(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_uniform_record_has_a_16_byte_stride_and_fits_whole() {
        for r in &RECORDS {
            assert_eq!(r.stride % 16, 0, "{}", r.name);
            assert!(capacity(r.stride) > 0, "{}", r.name);
            assert!(padded_bytes(r.binding).unwrap_or(0) <= UNIFORM_RECORD_BYTES);
        }
        assert!(is_uniform_record(binding::PLANES));
        assert!(padded_bytes(binding::PATHS).is_none());
        assert!(!is_uniform_record(binding::PATHS));
        // Every plane a scene may have fits.
        assert!(capacity(size_of::<crate::gpu::layout::GpuPlane>()) >= crate::accel::MAX_PLANES);
        assert_eq!(padded_bytes(binding::BVH_PRIMS), Some(UNIFORM_RECORD_BYTES));
    }

    #[test]
    fn declarations_give_the_address_space_and_the_capacity() {
        assert!(
            declarations(UniformRecords::None).contains(
                "@group(0) @binding(12) var<storage, read> bvh_nodes: array<WideNode>;\n"
            )
        );
        assert!(
            declarations(UniformRecords::All).contains(
                "@group(0) @binding(12) var<uniform> bvh_nodes: array<WideNode, 1024>;\n"
            )
        );
        // The small records uniform, the rest storage, beside the node texture.
        let small = declarations(UniformRecords::Small);
        assert!(small.contains("@group(0) @binding(6) var<uniform> materials: array<Material, "));
        assert!(small.contains("@group(0) @binding(7) var<uniform> lights: array<Light, "));
        assert!(small.contains("@group(0) @binding(2) var<uniform> planes: array<Plane, "));
        assert!(
            small
                .contains("@group(0) @binding(5) var<storage, read> triangles: array<Triangle>;\n")
        );
        assert!(
            small.contains(
                "@group(0) @binding(12) var<storage, read> bvh_nodes: array<WideNode>;\n"
            )
        );
    }

    #[test]
    fn small_records_fit_where_the_device_and_their_counts_allow() {
        let limits = wgpu::Limits {
            max_uniform_buffer_binding_size: UNIFORM_RECORD_BYTES,
            max_uniform_buffers_per_shader_stage: SMALL_UNIFORM_BUFFERS,
            ..wgpu::Limits::default()
        };
        let mut records = SceneRecords {
            triangles: vec![bytemuck::Zeroable::zeroed(); 100_000],
            ..SceneRecords::default()
        };
        assert!(!fits(&records, &limits));
        assert!(small_records_fit(&records, &limits));
        let materials = capacity(size_of::<GpuMaterial>());
        records.materials = vec![bytemuck::Zeroable::zeroed(); materials];
        assert!(small_records_fit(&records, &limits));
        records.materials.push(bytemuck::Zeroable::zeroed());
        assert!(!small_records_fit(&records, &limits));
        records.materials.clear();
        let few = wgpu::Limits {
            max_uniform_buffers_per_shader_stage: SMALL_UNIFORM_BUFFERS - 1,
            ..limits
        };
        assert!(!small_records_fit(&records, &few));
    }

    #[test]
    fn declarations_name_each_record_binding_once() {
        for records in [
            UniformRecords::None,
            UniformRecords::All,
            UniformRecords::Small,
        ] {
            let text = declarations(records);
            let bindings = RECORDS.iter().map(|r| r.binding);
            for binding in bindings.chain(PACKED.iter().map(|p| p.binding)) {
                assert_eq!(text.matches(&format!("@binding({binding}) ")).count(), 1);
            }
            assert!(text.contains("fn prim_ref(i: u32) -> u32 {"));
            assert!(text.contains("fn polygon_point(i: u32) -> vec2<f32> {"));
            assert_eq!(
                text.matches("fn load_wide_node(i: u32) -> WideNode {")
                    .count(),
                1
            );
            assert_eq!(
                text.contains("var node_texels: texture_storage_2d<rgba32uint, read>"),
                records == UniformRecords::Small
            );
        }
    }
}
