//! # gpu-render
//!
//! A Whitted-style, physically based ray tracer whose tracing runs in WGSL compute
//! shaders through wgpu, with a plain CPU reference tracer that implements the same
//! model and serves as the test oracle.
//!
//! The modules form layers, each using only those below it
//! (`tests/integration/layering.rs` checks the arrows):
//!
//! 1. the model and the math both tracers share: [`scene`], the scene model and the
//!    TOML scene-file format; [`color`], luminance and the sRGB curve; [`sample`], the
//!    hash and the sample warps; [`texture`], texture coordinates and lookups;
//!    [`camera`], the pinhole camera and the sample pattern; [`noise`], the per-pixel
//!    noise estimate (standard error of each pixel's mean); [`film`], the image a
//!    render produces;
//! 2. [`accel`]: the primitives both tracers intersect, the BVH over them, and the
//!    lights' distributions (emitters, the environment map, tabulated BRDF maps);
//! 3. the two tracers, apart from each other: [`cpu`], the reference tracer (f64), and
//!    [`gpu`], the wgpu backend, built from the caller's `Device` and `Queue`, whose
//!    WGSL modules (`shaders/`) twin the files of the layers above of the same name.
//!
//! Beside the layers, using them:
//!
//! - [`denoise`]: the edge-avoiding à-trous denoiser guided by albedo, normal, depth
//!   and variance (CPU twin of the GPU filter, `shaders/denoise.wgsl`); the guides are
//!   the auxiliary passes of `cpu::aov` and of the GPU's `shaders/aov.wgsl`.
//! - [`echo`]: text and numbers read from files, as messages quote them (control
//!   characters escaped, long text cut, numbers short).
//! - [`input`]: opening the files a render reads (regular files only, confined in a
//!   sandbox without a race).
//! - [`output`]: writing PNG, EXR and HDR files atomically.
//! - `plausibility` (with the default `cli` feature): the lecture's three rules checked
//!   on a tabulated BRDF map, for `gpu-render brdf-check`.
//! - `quality` (with `cli`): the named presets chosen from the measured front.
//! - [`tiles`]: windows of an image rendered apart, their EXR tile files and merging
//!   them into the whole image.
//! - `tradeoff` (with the default `cli` feature): measuring time against error for the
//!   speed/accuracy knobs.

#![warn(missing_docs)]

pub mod accel;
pub mod camera;
pub mod color;
pub mod cpu;
pub mod denoise;
pub mod echo;
pub mod film;
pub mod gpu;
pub mod input;
pub mod noise;
pub mod output;
#[cfg(feature = "cli")]
pub mod plausibility;
#[cfg(feature = "cli")]
pub mod quality;
pub mod sample;
pub mod scene;
pub mod texture;
pub mod tiles;
#[cfg(feature = "cli")]
pub mod tradeoff;
