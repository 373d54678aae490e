//! Composition of the WGSL sources. WGSL has no `#include`, so the modules are
//! concatenated in dependency order; every source file is embedded at compile time.
//! Optional code is kept or dropped by [`specialise`] (see [`super::features`]).

mod compose;

use std::borrow::Cow;

pub use compose::ComposeError;

use super::features::{ShaderFeatures, specialise};

/// The shared records (`FrameUniforms`, `Sphere`, ...), twins of [`super::layout`].
pub const TYPES_WGSL: &str = include_str!("../../shaders/types.wgsl");
/// The exact sRGB curve, twin of [`crate::color::srgb_encode`].
pub const COLOR_WGSL: &str = include_str!("../../shaders/color.wgsl");
/// The display pass (`encode_display`).
pub const DISPLAY_WGSL: &str = include_str!("../../shaders/display.wgsl");
/// `shaders/draw.wgsl`: the fullscreen-triangle draw of a film into a colour attachment.
pub const DRAW_WGSL: &str = include_str!("../../shaders/draw.wgsl");
/// Camera rays and the sample pattern, twin of [`crate::camera`].
pub const SAMPLING_WGSL: &str = include_str!("../../shaders/sampling.wgsl");
/// Ray/shape intersection.
pub const INTERSECT_WGSL: &str = include_str!("../../shaders/intersect.wgsl");
/// Texture coordinates and bilinear lookups (the `images` binding), twin of
/// [`crate::texture`].
pub const TEXTURE_WGSL: &str = include_str!("../../shaders/texture.wgsl");
/// Materials.
pub const BXDF_WGSL: &str = include_str!("../../shaders/bxdf.wgsl");
/// The BRDF test kernel (`eval_brdfs`), composed by [`bxdf_eval_shader_source`].
pub const BXDF_EVAL_WGSL: &str = include_str!("../../shaders/bxdf_eval.wgsl");
/// Entry point of the BRDF test kernel.
pub const BXDF_EVAL_ENTRY_POINT: &str = "eval_brdfs";
/// The resumable BVH traversal, twin of [`crate::cpu::traverse`].
pub const TRAVERSE_WGSL: &str = include_str!("../../shaders/traverse.wgsl");
/// The wavefront kernels (`shade_paths`, `trace_rays`) and their bindings.
pub const TRACE_WGSL: &str = include_str!("../../shaders/trace.wgsl");
/// `shaders/noise.wgsl`: the per-pixel noise estimate's running sums (twin of
/// [`crate::noise`]).
pub const NOISE_WGSL: &str = include_str!("../../shaders/noise.wgsl");
/// The path integrator's records and constants (`Emitter`, `FLAG_PATH`), twins of
/// [`super::area_lights`].
pub const PATH_TYPES_WGSL: &str = include_str!("../../shaders/path_types.wgsl");
/// The environment map (`ENVIRONMENT_MAP` feature): its radiance by direction and its
/// sampler, twins of [`crate::scene::EnvironmentMap`] and
/// [`crate::accel::EnvironmentLight`].
pub const ENVIRONMENT_WGSL: &str = include_str!("../../shaders/environment.wgsl");
/// The path integrator (`PATH` feature), twin of [`crate::cpu::path`] and its samplers.
pub const PATH_WGSL: &str = include_str!("../../shaders/path.wgsl");
/// The inverse-CDF sampler of tabulated BRDF maps (`PATH` and `TABULATED` features),
/// twin of [`crate::cpu::tabulated`].
pub const TABULATED_WGSL: &str = include_str!("../../shaders/tabulated.wgsl");

/// Entry point of the shading kernel of the trace module.
pub const SHADE_ENTRY_POINT: &str = "shade_paths";
/// Entry point of the traversal kernel of the trace module.
pub const TRACE_ENTRY_POINT: &str = "trace_rays";
/// Entry point of the fused kernel of the trace module (shading and traversal in one
/// loop).
pub const FUSED_ENTRY_POINT: &str = "trace_paths";
/// Invocations per workgroup of the trace kernels, `@workgroup_size(256, 1, 1)`.
pub const SLOT_WORKGROUP_SIZE: u32 = 256;
/// Entry point of the display module.
pub const DISPLAY_ENTRY_POINT: &str = "encode_display";
/// Workgroup size (x and y) of the display pass, `@workgroup_size(8, 8, 1)`.
pub const WORKGROUP_SIZE: u32 = 8;

/// The complete trace module specialised to `features` (see [`super::features`]): the
/// constants shared with the Rust side (`MAX_BVH_DEPTH`, `MAX_POLYGON_VERTICES`), the
/// record bindings (storage or uniform arrays, as `features.uniform_records` says), then
/// types, path types, sampling, intersect, texture, bxdf, environment, traverse, noise,
/// trace, path and the tabulated BRDF sampler, then for an unrolled scene its
/// `unrolled_closest_hit` ([`super::unrolled`]).
///
/// Errors: [`ComposeError`] if the sources' feature directives are malformed.
///
/// ```
/// use gpu_render::gpu::ShaderFeatures;
/// let src = gpu_render::gpu::shaders::trace_shader_source(&ShaderFeatures::ALL).unwrap();
/// assert!(src.starts_with("const MAX_BVH_DEPTH: u32 = 64u;\n"));
/// assert!(src.contains("fn refract_direction"));
/// assert!(src.contains("fn shade_paths") && src.contains("fn trace_rays"));
/// ```
pub fn trace_shader_source(features: &ShaderFeatures) -> Result<String, ComposeError> {
    let parts = [
        ("types", TYPES_WGSL),
        ("path_types", PATH_TYPES_WGSL),
        ("sampling", SAMPLING_WGSL),
        ("intersect", INTERSECT_WGSL),
        ("texture", TEXTURE_WGSL),
        ("bxdf", BXDF_WGSL),
        ("environment", ENVIRONMENT_WGSL),
        ("traverse", TRAVERSE_WGSL),
        ("noise", NOISE_WGSL),
        ("trace", TRACE_WGSL),
        ("path", PATH_WGSL),
        ("tabulated", TABULATED_WGSL),
    ];
    let mut source = format!(
        "const MAX_BVH_DEPTH: u32 = {}u;\nconst MAX_POLYGON_VERTICES: u32 = {}u;\n",
        crate::accel::MAX_BVH_DEPTH,
        crate::accel::MAX_POLYGON_VERTICES
    );
    source.push_str(&super::uniform_records::declarations(
        features.uniform_records,
    ));
    for (module, part) in parts {
        source.push_str(
            &specialise(part, features).map_err(|source| ComposeError::Directive {
                module: module.to_string(),
                source,
            })?,
        );
    }
    if let Some(unrolled) = &features.unrolled {
        source.push_str(&unrolled.wgsl());
    }
    Ok(source)
}

/// The BRDF test kernel: types, texture, bxdf and `shaders/bxdf_eval.wgsl`, which
/// evaluates [`crate::cpu::bxdf::eval_brdf`]'s twin on a list of (material, n, wi, wo)
/// cases so that tests can compare it with the CPU.
///
/// ```
/// let src = gpu_render::gpu::shaders::bxdf_eval_shader_source();
/// assert!(src.contains("fn eval_brdfs"));
/// ```
pub fn bxdf_eval_shader_source() -> String {
    let mut source = String::new();
    for part in [TYPES_WGSL, TEXTURE_WGSL, BXDF_WGSL, BXDF_EVAL_WGSL] {
        // Every feature is on: the directives are only stripped, which cannot fail
        // for our own sources (the layout tests check that it does not).
        source.push_str(&specialise(part, &ShaderFeatures::ALL).unwrap_or_default());
    }
    source
}

/// The complete display module: types, colour and display.
///
/// ```
/// let src = gpu_render::gpu::shaders::display_shader_source();
/// assert!(src.contains("fn encode_display"));
/// ```
pub fn display_shader_source() -> String {
    let mut source = String::new();
    for part in [TYPES_WGSL, COLOR_WGSL, DISPLAY_WGSL] {
        source.push_str(part);
        if !part.ends_with('\n') {
            source.push('\n');
        }
    }
    source
}

/// The draw shader (`shaders/draw.wgsl` after `shaders/color.wgsl`).
pub fn draw_shader_source() -> String {
    let mut source = String::new();
    for part in [COLOR_WGSL, DRAW_WGSL] {
        source.push_str(part);
        if !part.ends_with('\n') {
            source.push('\n');
        }
    }
    source
}

/// A WGSL source of the caller's (a test's kernel) composed with the modules its
/// `#import` lines name, specialised to `features`.
///
/// Errors: [`ComposeError`] for a missing module, an import cycle or malformed
/// directives.
pub fn compose_source(source: &str, features: &ShaderFeatures) -> Result<String, ComposeError> {
    compose::compose("<source>", source, &shipped_module, features)
}

/// The source of the module of `shaders/` called `name`.
fn shipped_module(name: &str) -> Option<Cow<'static, str>> {
    let sources = [
        ("types", TYPES_WGSL),
        ("path_types", PATH_TYPES_WGSL),
        ("sampling", SAMPLING_WGSL),
        ("intersect", INTERSECT_WGSL),
        ("texture", TEXTURE_WGSL),
        ("bxdf", BXDF_WGSL),
        ("environment", ENVIRONMENT_WGSL),
        ("traverse", TRAVERSE_WGSL),
        ("noise", NOISE_WGSL),
        ("trace", TRACE_WGSL),
        ("path", PATH_WGSL),
        ("tabulated", TABULATED_WGSL),
    ];
    sources
        .iter()
        .find(|(module, _)| *module == name)
        .map(|(_, source)| Cow::Borrowed(*source))
}

/// The modules a WGSL source imports, in the order of its `#import` lines, with
/// `features` deciding its `//#if` blocks.
///
/// Errors: [`ComposeError`] for malformed directives or imports.
pub fn imports(source: &str, features: &ShaderFeatures) -> Result<Vec<String>, ComposeError> {
    compose::imports_of("<source>", source, features)
}
