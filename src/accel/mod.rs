//! Scene geometry as both tracers intersect it: the primitives in flat lists by kind,
//! with their per-shape constants computed once, and a bounding volume hierarchy over
//! the bounded ones.
//!
//! Built once per scene on the host ([`SceneGeometry::new`]) and shared by the CPU
//! reference, which traverses it in `f64`, and the GPU backend, which uploads the same
//! nodes and primitive lists and traverses them in WGSL. Both follow the same rules
//! (`docs/model.md`, "Acceleration structure"):
//!
//! - the nearest hit wins; at exactly equal distances the smaller [`PrimRef`] wins, so
//!   the result does not depend on the order in which the tree is visited, and a
//!   traversal returns exactly what a brute-force loop over every primitive returns;
//! - node boxes are `f32`, rounded outwards and padded so that they contain both the
//!   `f64` primitive (CPU) and its `f32` rounding (GPU);
//! - planes are unbounded and stay a short list tested before the tree.
//!
//! - [`geometry`]: the primitive lists and [`SceneGeometry`];
//! - [`bvh`]: the tree, its `f32` node records and its two builders;
//! - [`wide`]: the same tree collapsed into the compressed 4-wide nodes both tracers
//!   walk;
//! - [`instance`]: meshes placed more than once, stored once with a BVH of their own
//!   and entered through their placements' transforms (a two-level BVH).
//!
//! Also built once on the host for both backends: [`area_lights`], the emitters the
//! path integrator samples, and [`brdf_map_cdf`], the inverse-CDF tables of tabulated
//! BRDF maps.

pub mod area_lights;
pub mod brdf_map_cdf;
pub mod bvh;
pub mod environment;
pub mod geometry;
pub mod instance;
pub mod wide;

pub use area_lights::{AreaLights, EmitterEntry, EmitterEntryShape};
pub use brdf_map_cdf::{BrdfMapCdf, BrdfMapCdfs};
pub use bvh::{BuildMethod, Bvh, BvhNode, BvhStats, MAX_BVH_DEPTH, MAX_LEAF_PRIMITIVES};
pub use environment::{Distribution1D, ENVIRONMENT_SELECTION, EnvironmentLight, EnvironmentSample};
pub use geometry::{
    AlphaMask, MAX_PLANES, MAX_POLYGON_VERTICES, PlaneShape, PolygonShape, PrimKind, PrimRef,
    SceneGeometry, SphereShape, TriangleAttributes, TriangleShape, alpha_masks, ray_offset_scale,
};
pub use instance::{HitKey, Instance, InstanceId, InstancedMesh};
pub use wide::{
    CHILD_COUNT_SHIFT, CHILD_INDEX_MASK, EMPTY_CHILD, MAX_TRAVERSAL_STACK, MAX_WIDE_DEPTH, WIDTH,
    WideChild, WideNode,
};
