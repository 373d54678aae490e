//! The wide BVH nodes as the texels of a read-only storage texture, on CPU devices,
//! for scenes whose records do not fit uniform buffers (`super::uniform_records`).
//!
//! llvmpipe (Mesa 25.0) reads a storage-buffer element whose index differs from lane
//! to lane one lane at a time, each lane behind a branch on its execution mask and
//! each component behind another on the buffer's bounds (`emit_load_mem` in gallivm's
//! `lp_bld_nir_soa.c`). A texel load it gathers without branches: one 16-byte texel
//! per lane, its coordinates checked as a vector. A node visit reads a 64-byte node,
//! four texels here. With a sampled texture (`texture_2d<u32>`) the bunny of
//! `scenes/bench/bunny.toml` (69,451 triangles) traced 8% faster on lavapipe than
//! from storage; a storage texture (`texture_storage_2d<rgba32uint, read>`) is faster
//! still, the bunny 15% and the million-triangle terrain 16%: lavapipe's image load
//! is a 48-instruction function, its sampled texel fetch 156, which looks up the mip
//! level's size and offset lane by lane although there is one level (BENCHMARKS.md,
//! "The compressed 4-wide BVH" and "Small records in uniform buffers, nodes in a
//! storage texture"). The triangles did not gain from a sampled texture (three texels
//! each, slower than their storage reads), so only the nodes go to the texture; the
//! storage buffer of nodes stays bound too, for the instance records it holds
//! (`shaders/instance.wgsl`).
//!
//! Layout: node `i`'s four 16-byte quarters, in their [`WideNode`] order, are the
//! texels `(4 · (i mod NODES_PER_ROW) + k, i / NODES_PER_ROW)`, `k = 0..4`, of an
//! [`NODE_TEXEL_FORMAT`] texture [`ROW_TEXELS`] wide (read by `load_wide_node` of
//! [`wgsl`]).

use crate::accel::WideNode;
use crate::gpu::RenderError;
use crate::gpu::pipelines::binding;
use crate::gpu::readback::{Caught, capture};

/// Nodes in one texture row.
pub const NODES_PER_ROW: u32 = 1024;

/// The texture's format: a texel holds four of a node's words.
pub const NODE_TEXEL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// Texels of one node: its 64 bytes as four [`NODE_TEXEL_FORMAT`] texels.
pub const TEXELS_PER_NODE: u32 = 4;

/// The texture's width in texels (within the 8,192 every WebGPU device allows).
pub const ROW_TEXELS: u32 = NODES_PER_ROW * TEXELS_PER_NODE;

/// The WGSL declaration of the texture (`binding::NODE_TEXELS` in
/// `src/gpu/pipelines.rs`) and of `load_wide_node(i)`, which reads node `i` from it,
/// written from this module's constants.
pub(crate) fn wgsl() -> String {
    format!(
        "@group(0) @binding({binding}) var node_texels: texture_storage_2d<rgba32uint, read>;\n\
         fn load_wide_node(i: u32) -> WideNode {{\n\
             let at = vec2<i32>(i32((i % {NODES_PER_ROW}u) * {TEXELS_PER_NODE}u), i32(i / {NODES_PER_ROW}u));\n\
             let a = textureLoad(node_texels, at);\n\
             let b = textureLoad(node_texels, at + vec2<i32>(1, 0));\n\
             let c = textureLoad(node_texels, at + vec2<i32>(2, 0));\n\
             let d = textureLoad(node_texels, at + vec2<i32>(3, 0));\n\
             return WideNode(bitcast<vec3<f32>>(a.xyz), a.w, b.xyz, b.w, c.xyz, c.w, d);\n\
         }}\n",
        binding = binding::NODE_TEXELS,
    )
}

/// The texture's rows for `nodes` nodes (at least one).
fn rows(nodes: usize) -> u64 {
    (nodes as u64).div_ceil(u64::from(NODES_PER_ROW)).max(1)
}

/// Whether `nodes` nodes fit a texture on a device with `limits`.
pub(crate) fn fits(nodes: usize, limits: &wgpu::Limits) -> bool {
    let side = u64::from(limits.max_texture_dimension_2d);
    u64::from(ROW_TEXELS) <= side && rows(nodes) <= side
}

/// The words of the texture that holds `nodes`: whole rows, the last padded with
/// zeros.
pub(crate) fn texel_words(nodes: &[WideNode]) -> Vec<u32> {
    let mut words: Vec<u32> = bytemuck::cast_slice(nodes).to_vec();
    let row_words = ROW_TEXELS as usize * 4;
    words.resize(rows(nodes.len()) as usize * row_words, 0);
    words
}

/// Uploads `nodes` as the texture [`wgsl`] reads (the caller checked [`fits`]), and
/// its bytes.
pub(crate) fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    nodes: &[WideNode],
) -> Result<(wgpu::TextureView, u64), RenderError> {
    let words = texel_words(nodes);
    let size = wgpu::Extent3d {
        width: ROW_TEXELS,
        height: rows(nodes.len()) as u32,
        depth_or_array_layers: 1,
    };
    let texture = capture(device, "BVH node texture", Caught::Resource, || {
        device.create_texture(&descriptor("gpu-render BVH nodes", size))
    })?;
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&words),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(ROW_TEXELS * 16),
            rows_per_image: Some(size.height),
        },
        size,
    );
    let bytes = std::mem::size_of_val(words.as_slice()) as u64;
    Ok((texture.create_view(&Default::default()), bytes))
}

/// A one-texel texture for the binding where a scene's nodes are not in a texture
/// (every trace layout has the binding; such a module does not declare it).
pub(crate) fn placeholder(device: &wgpu::Device) -> wgpu::TextureView {
    let size = wgpu::Extent3d {
        width: 1,
        height: 1,
        depth_or_array_layers: 1,
    };
    device
        .create_texture(&descriptor("gpu-render BVH node texture placeholder", size))
        .create_view(&Default::default())
}

fn descriptor(label: &str, size: wgpu::Extent3d) -> wgpu::TextureDescriptor<'_> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: NODE_TEXEL_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::WideChild;
    use crate::accel::bvh::Aabb32;

    fn node(n: u32) -> WideNode {
        let bounds = Aabb32 {
            min: [n as f32, 0.0, -1.0],
            max: [n as f32 + 1.0, 2.0, 3.0],
        };
        WideNode::new(bounds, &[(WideChild::Node(n), bounds)])
    }

    /// The texel the WGSL's `load_wide_node` reads as quarter `k` of node `i`: its
    /// four words.
    fn quarter(words: &[u32], i: u32, k: u32) -> [u32; 4] {
        let (x, y) = ((i % 1024) * 4 + k, i / 1024);
        let at = ((y * ROW_TEXELS + x) * 4) as usize;
        [words[at], words[at + 1], words[at + 2], words[at + 3]]
    }

    #[test]
    fn every_node_is_read_back_whole_from_the_texels_the_shader_reads() {
        let wgsl = wgsl();
        assert!(wgsl.contains(
            "@group(0) @binding(22) var node_texels: texture_storage_2d<rgba32uint, read>;"
        ));
        assert!(wgsl.contains("(i % 1024u) * 4u), i32(i / 1024u)"));
        assert_eq!(NODES_PER_ROW, 1024);
        let nodes: Vec<WideNode> = (0..2500).map(node).collect();
        let words = texel_words(&nodes);
        assert_eq!(words.len(), 3 * ROW_TEXELS as usize * 4);
        for (i, expected) in nodes.iter().enumerate() {
            let read: Vec<u32> = (0..TEXELS_PER_NODE)
                .flat_map(|k| quarter(&words, i as u32, k))
                .collect();
            assert_eq!(
                read.as_slice(),
                bytemuck::cast_slice::<_, u32>(&[*expected])
            );
        }
    }

    #[test]
    fn the_texture_fits_within_the_device_side() {
        let limits = wgpu::Limits::default();
        let side = limits.max_texture_dimension_2d as usize;
        assert!(fits(1, &limits));
        assert!(fits(side * NODES_PER_ROW as usize, &limits));
        assert!(!fits(side * NODES_PER_ROW as usize + 1, &limits));
        let narrow = wgpu::Limits {
            max_texture_dimension_2d: ROW_TEXELS - 1,
            ..limits
        };
        assert!(!fits(1, &narrow));
    }
}
