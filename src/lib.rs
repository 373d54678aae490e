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
//!
//! Public at the top are the model ([`scene`]), the two tracers ([`cpu`], [`gpu`]),
//! the image they make ([`film`]), writing it ([`output`]) and rendering it in tiles
//! ([`tiles`]); the shared math, [`accel`] and the helpers are public under
//! [`low_level`].
//!
//! What an embedding application needs is re-exported here, at the top
//! (`docs/embedding.md`): [`Renderer`] and [`RendererOptions`] with the caller's
//! `Device` and `Queue`, the [`Film`] it accumulates into, scene loading
//! ([`load_scene`], [`Scene`]), the images it reads back ([`LinearImage`]) and one
//! error type per layer ([`SceneError`], [`RenderError`], [`OutputError`]).

#![warn(missing_docs)]

pub use film::{LinearImage, RenderStats};
pub use gpu::{Film, HeadlessGpu, RenderError, Renderer, RendererOptions};
pub use output::OutputError;
pub use scene::{LoadOptions, Scene, SceneError, SceneWarning, load_scene, load_scene_with};

pub mod cpu;
pub mod film;
pub mod gpu;
pub mod low_level;
pub mod output;
pub mod scene;
pub mod tiles;

// The internals keep their crate paths (`crate::color`, `crate::accel`, ...), which
// the layering test reads; their public path is under `low_level`.
pub(crate) use low_level::{accel, camera, color, denoise, echo, input, noise, sample, texture};
