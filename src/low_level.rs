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
