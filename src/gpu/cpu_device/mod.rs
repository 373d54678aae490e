//! The strategies the tracer takes on CPU devices (Mesa's lavapipe and llvmpipe) only,
//! kept apart so that the path a real GPU takes reads without them. Each was measured
//! on lavapipe (`BENCHMARKS.md`) and is chosen at upload from the adapter's device type:
//!
//! - `uniform_records`: the scene records every traversal step reads bound as
//!   uniform arrays instead of storage buffers (llvmpipe gathers uniform elements
//!   without a branch per lane);
//! - `node_texture`: for scenes too large for that, the wide BVH nodes as the texels
//!   of a texture (llvmpipe gathers texels without a branch per lane either);
//! - [`unrolled`]: the closest-hit test of a scene of a few primitives as straight-line
//!   WGSL instead of a walk of the BVH.
//!
//! A fourth, refilling finished lanes inside the trace kernel
//! ([`crate::gpu::ShaderFeatures::refill_lanes`]), is a shader feature that needs
//! subgroup operations (`gpu::limits`); it is off unless asked for
//! ([`crate::gpu::RendererOptions::refill_lanes`]), since lavapipe now traces faster
//! without it.

pub(crate) mod node_texture;
pub(crate) mod uniform_records;
pub mod unrolled;
