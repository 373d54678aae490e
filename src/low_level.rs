//! The library's advanced internals, for tools, tests and embedders that need more
//! than the frame-loop API at the crate's top: the shared math both tracers use, the
//! acceleration structures, the denoiser, the file-input and message helpers, and the
//! command line's measuring modules. Their paths may change between versions; what the
//! top of the crate re-exports is the stable surface (`docs/embedding.md`).
//!
//! The files stay where the layers put them (`src/lib.rs` names the layers); only
//! their public path is here.

#[path = "accel/mod.rs"]
pub mod accel;
#[path = "camera.rs"]
pub mod camera;
#[path = "color.rs"]
pub mod color;
#[path = "denoise.rs"]
pub mod denoise;
#[path = "echo.rs"]
pub mod echo;
#[path = "input.rs"]
pub mod input;
#[path = "noise.rs"]
pub mod noise;
#[cfg(feature = "cli")]
#[path = "plausibility.rs"]
pub mod plausibility;
#[cfg(feature = "cli")]
#[path = "quality.rs"]
pub mod quality;
#[path = "sample.rs"]
pub mod sample;
#[path = "texture.rs"]
pub mod texture;
#[cfg(feature = "cli")]
#[path = "tradeoff.rs"]
pub mod tradeoff;

/// The CPU reference tracer's internals: its ray and hit records and intersection
/// tests, the BVH queries, the BxDFs, the two integrators' steps and the auxiliary
/// passes. Whole renders are [`crate::cpu`].
pub mod cpu {
    /// The first-hit albedo, normal and depth passes.
    pub mod aov {
        pub use crate::cpu::aov::*;
    }
    /// Alpha coverage: what a candidate hit stops, and whether it stops a query.
    pub mod coverage {
        pub use crate::cpu::coverage::*;
    }
    /// The BxDFs: evaluation, sampling and densities.
    pub mod bxdf {
        pub use crate::cpu::bxdf::*;
    }
    /// Rays, hits and the intersection tests of each primitive.
    pub mod intersect {
        pub use crate::cpu::intersect::*;
    }
    /// The path integrator.
    pub mod path {
        pub use crate::cpu::path::*;
    }
    /// Tabulated BRDF maps.
    pub mod tabulated {
        pub use crate::cpu::tabulated::*;
    }
    /// The Whitted integrator and the prepared scene.
    pub mod trace {
        pub use crate::cpu::trace::*;
    }
    /// The scene queries over the BVH.
    pub mod traverse {
        pub use crate::cpu::traverse::*;
    }
}

/// The GPU backend's internals: the `#[repr(C)]` records and their upload, the WGSL
/// composition and specialisation, the emitter and environment records, and the
/// strategies for CPU devices. The frame-loop API is [`crate::gpu`].
pub mod gpu {
    /// The GPU records, `#[repr(C)]` twins of `shaders/types.wgsl`.
    pub mod layout {
        pub use crate::gpu::layout::*;
    }
    /// Pure conversion of a scene into the GPU records.
    pub mod upload {
        pub use crate::gpu::upload::*;
    }
    /// Composition of the WGSL modules.
    pub mod shaders {
        pub use crate::gpu::shaders::*;
    }
    /// The shader features a scene needs, and specialising sources to them.
    pub mod features {
        pub use crate::gpu::features::*;
    }
    /// The emitter records of the path integrator's area lights.
    pub mod area_lights {
        pub use crate::gpu::area_lights::*;
    }
    /// The environment map's records.
    pub mod environment {
        pub use crate::gpu::environment::*;
    }
    /// The strategies the tracer takes on CPU devices only.
    pub mod cpu_device {
        pub use crate::gpu::cpu_device::unrolled;
    }
    /// The hardware traversal's acceleration structures.
    pub mod ray_query {
        pub use crate::gpu::ray_query::{Acceleration, build_acceleration};
    }
}
