//! # gpu-render
//!
//! A Whitted-style, physically based ray tracer whose tracing runs in WGSL compute
//! shaders through wgpu, with a plain CPU reference tracer that implements the same
//! model and serves as the test oracle.
//!
//! - [`scene`]: the scene model and the TOML scene-file format.
//! - [`accel`]: the primitives both tracers intersect and the BVH over them.
//! - [`camera`], [`color`], [`film`]: the pinhole camera and sample pattern, the sRGB
//!   curve, and the image a render produces.
//! - [`cpu`]: the reference tracer (f64).
//! - [`gpu`]: the wgpu backend, built from the caller's `Device` and `Queue`.
//! - [`noise`]: the per-pixel noise estimate (standard error of each pixel's mean).
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
pub mod tiles;
#[cfg(feature = "cli")]
pub mod tradeoff;
