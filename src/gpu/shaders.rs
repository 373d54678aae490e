//! The WGSL sources and their composition. Each file of `shaders/` is one module that
//! names the modules it uses in `#import NAME` lines (vello's convention); the
//! composer (`src/gpu/shaders/composer.rs`) joins a module with everything it
//! imports, each module once and after its imports, and refuses an import cycle. Each
//! module is specialised to the scene's features first ([`super::features`]), so an
//! import inside an `//#if` block is followed only where the block is kept.
//!
//! Besides the files, three modules are written by the host: `limits` (the Rust
//! constants `MAX_POLYGON_VERTICES`, `MAX_TRAVERSAL_STACK` and the wide tree's
//! child-word constants), `records` (the bindings of
//! the scene records, storage or uniform arrays: `super::cpu_device::uniform_records`) and, for
//! an unrolled scene, `unrolled_scene` (its `unrolled_closest_hit`: [`super::cpu_device::unrolled`]).
//!
//! Each module twins the Rust file of the same name (`shaders/intersect.wgsl` and
//! `src/cpu/intersect.rs`, `shaders/color.wgsl` and `src/color.rs`): the same
//! functions under the same names, which `tests/integration/shader_modules.rs` holds
//! them to.

mod composer;

use std::borrow::Cow;

pub use composer::ComposeError;

use super::features::ShaderFeatures;

/// One WGSL source file of `shaders/`, embedded at compile time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderModule {
    /// Its name, the file's stem (`shaders/{name}.wgsl`), by which others import it.
    pub name: &'static str,
    /// Its text.
    pub source: &'static str,
}

macro_rules! shader_modules {
    ($($name:literal),* $(,)?) => {
        [$(ShaderModule {
            name: $name,
            source: include_str!(concat!("../../shaders/", $name, ".wgsl")),
        }),*]
    };
}

/// Every module of `shaders/`, the lower ones first.
pub const SHADER_MODULES: [ShaderModule; 31] = shader_modules![
    "types",
    "path_types",
    "math",
    "bindings",
    "budget",
    "color",
    "sample",
    "medium",
    "camera",
    "noise",
    "texture",
    "bxdf",
    "instance",
    "intersect",
    "coverage",
    "ray_query",
    "unrolled",
    "traverse",
    "environment",
    "brdf_map_cdf",
    "tabulated",
    "area_lights",
    "slot",
    "trace",
    "path",
    "aov",
    "wavefront",
    "display",
    "draw",
    "bxdf_eval",
    "denoise",
];

/// The modules the host writes (see the module's documentation).
pub const HOST_MODULES: [&str; 3] = ["limits", "records", "unrolled_scene"];

/// The text of the module of `shaders/` called `name`.
pub fn shader_module(name: &str) -> Option<&'static str> {
    SHADER_MODULES
        .iter()
        .find(|module| module.name == name)
        .map(|module| module.source)
}

/// The text of the host's module `name` for a trace module with `features` (`None`
/// for other names, and for `unrolled_scene` without an unrolled scene).
pub fn host_module(name: &str, features: &ShaderFeatures) -> Option<String> {
    match name {
        "limits" => Some(format!(
            "const MAX_POLYGON_VERTICES: u32 = {}u;\n\
             const MAX_TRAVERSAL_STACK: u32 = {}u;\nconst EMPTY_CHILD: u32 = {}u;\n\
             const CHILD_COUNT_SHIFT: u32 = {}u;\nconst CHILD_INDEX_MASK: u32 = {}u;\n",
            crate::accel::MAX_POLYGON_VERTICES,
            crate::accel::MAX_TRAVERSAL_STACK,
            crate::accel::EMPTY_CHILD,
            crate::accel::CHILD_COUNT_SHIFT,
            crate::accel::CHILD_INDEX_MASK,
        )),
        "records" => Some(format!(
            "#import types\n{}",
            super::cpu_device::uniform_records::declarations(
                super::cpu_device::uniform_records::UniformRecords::of(features)
            )
        )),
        "unrolled_scene" => features.unrolled.as_ref().map(|unrolled| unrolled.wgsl()),
        _ => None,
    }
}

/// The module `name`, a file's or the host's, composed with everything it imports and
/// specialised to `features`.
///
/// Errors: [`ComposeError`] for a missing module, an import cycle or malformed
/// directives.
pub fn compose(name: &str, features: &ShaderFeatures) -> Result<String, ComposeError> {
    let lookup = |module: &str| lookup(module, features);
    let source = lookup(name).ok_or_else(|| ComposeError::MissingModule {
        module: name.to_string(),
        importer: None,
    })?;
    composer::compose(name, &source, &lookup, features)
}

/// A WGSL source of the caller's (a test's kernel) composed with the modules its
/// `#import` lines name, specialised to `features`.
///
/// Errors: [`ComposeError`] for a missing module, an import cycle or malformed
/// directives.
pub fn compose_source(source: &str, features: &ShaderFeatures) -> Result<String, ComposeError> {
    let lookup = |module: &str| lookup(module, features);
    composer::compose("<source>", source, &lookup, features)
}

/// The modules a WGSL source imports, in the order of its `#import` lines, with
/// `features` deciding its `//#if` blocks.
///
/// Errors: [`ComposeError`] for malformed directives or imports.
pub fn imports(source: &str, features: &ShaderFeatures) -> Result<Vec<String>, ComposeError> {
    composer::imports_of("<source>", source, features)
}

/// A module of `shaders/` or of the host by its name.
fn lookup(name: &str, features: &ShaderFeatures) -> Option<Cow<'static, str>> {
    shader_module(name)
        .map(Cow::Borrowed)
        .or_else(|| host_module(name, features).map(Cow::Owned))
}

/// The shipped module `name` composed with every feature on: the display, draw and
/// BRDF test kernels, whose modules have no feature directives but those of the
/// modules they share with the trace kernels.
fn compose_shipped(name: &str) -> String {
    compose(name, &ShaderFeatures::ALL).unwrap_or_else(|error| {
        panic!("the shipped modules compose (tests/integration/shader_modules.rs): {error}")
    })
}

/// Entry point of the BRDF test kernel.
pub const BXDF_EVAL_ENTRY_POINT: &str = "eval_brdfs";
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

/// The complete trace module specialised to `features` (see `gpu::features`):
/// `shaders/wavefront.wgsl`, the trace kernels, with everything it imports, the
/// record bindings storage or uniform arrays as `features.uniform_records` says, and
/// for an unrolled scene its `unrolled_closest_hit` ([`super::cpu_device::unrolled`]).
///
/// Errors: [`ComposeError`] if the sources' feature directives or imports are
/// malformed (bugs in our own sources, which the tests catch).
///
/// ```
/// use gpu_render::gpu::ShaderFeatures;
/// let src = gpu_render::low_level::gpu::shaders::trace_shader_source(&ShaderFeatures::ALL).unwrap();
/// assert!(src.contains("const MAX_TRAVERSAL_STACK: u32 = 96u;\n"));
/// assert!(src.contains("fn refract_direction"));
/// assert!(src.contains("fn shade_paths") && src.contains("fn trace_rays"));
/// ```
pub fn trace_shader_source(features: &ShaderFeatures) -> Result<String, ComposeError> {
    compose("wavefront", features)
}

/// The BRDF test kernel, `shaders/bxdf_eval.wgsl`, which evaluates
/// [`crate::cpu::bxdf::eval_brdf`]'s twin on a list of (material, n, wi, wo) cases so
/// that tests can compare it with the CPU.
///
/// ```
/// let src = gpu_render::low_level::gpu::shaders::bxdf_eval_shader_source();
/// assert!(src.contains("fn eval_brdfs"));
/// ```
pub fn bxdf_eval_shader_source() -> String {
    compose_shipped("bxdf_eval")
}

/// The complete display module, `shaders/display.wgsl` and its imports.
///
/// ```
/// let src = gpu_render::low_level::gpu::shaders::display_shader_source();
/// assert!(src.contains("fn encode_display"));
/// ```
pub fn display_shader_source() -> String {
    compose_shipped("display")
}

/// The denoiser, `shaders/denoise.wgsl` and its imports.
///
/// ```
/// let src = gpu_render::low_level::gpu::shaders::denoise_shader_source();
/// assert!(src.contains("fn atrous_pass"));
/// ```
pub fn denoise_shader_source() -> String {
    compose_shipped("denoise")
}

/// The draw shader, `shaders/draw.wgsl` and its imports.
pub fn draw_shader_source() -> String {
    compose_shipped("draw")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses and validates `source` with every capability the trace kernels may use.
    fn validate(name: &str, source: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{name} does not parse:\n{}", e.emit_to_string(source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name} does not validate:\n{}", e.emit_to_string(source)));
        module
    }

    /// Each module, composed alone with every feature, is valid WGSL: it imports every
    /// module whose names it uses (naga refuses an unknown identifier).
    #[test]
    fn every_module_composed_alone_validates() {
        for module in SHADER_MODULES {
            let source = compose(module.name, &ShaderFeatures::ALL)
                .unwrap_or_else(|e| panic!("{}: {e}", module.name));
            validate(module.name, &source);
        }
        for name in ["limits", "records"] {
            validate(name, &compose(name, &ShaderFeatures::ALL).expect(name));
        }
    }

    /// The trace module of the hardware traversal begins with the ray-query
    /// extension's directive, and validates where ray queries are a capability, with
    /// and without alpha coverage's candidate loop.
    #[test]
    fn the_hardware_traversal_module_enables_ray_queries_and_validates() {
        for alpha in [false, true] {
            let features = ShaderFeatures {
                hardware_traversal: true,
                alpha,
                ..ShaderFeatures::ALL
            };
            let source = trace_shader_source(&features).expect("composes");
            assert!(source.starts_with("enable wgpu_ray_query;\n"));
            assert_eq!(source.matches("enable wgpu_ray_query;").count(), 1);
            assert!(source.contains("fn hardware_triangles("));
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("does not parse:\n{}", e.emit_to_string(&source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::RAY_QUERY,
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("does not validate:\n{}", e.emit_to_string(&source)));
        }
        let software = trace_shader_source(&ShaderFeatures::ALL).expect("composes");
        assert!(!software.contains("wgpu_ray_query") && !software.contains("hardware_triangles"));
    }

    #[test]
    fn every_module_is_emitted_once_after_its_imports() {
        let source = trace_shader_source(&ShaderFeatures::ALL).expect("composes");
        let types = source.find("struct FrameUniforms {").expect("types");
        let bindings = source
            .find("var<uniform> frame: FrameUniforms")
            .expect("bindings");
        let kernels = source.find("fn trace_paths(").expect("wavefront");
        assert!(types < bindings && bindings < kernels);
        assert_eq!(source.matches("struct FrameUniforms {").count(), 1);
        assert!(!source.contains("#import"));
    }
}
