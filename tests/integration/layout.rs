//! The WGSL records in `shaders/types.wgsl` and their `#[repr(C)]` twins in
//! `src/gpu/layout.rs` must agree byte for byte; naga's layouter computes the WGSL
//! side. Also checks that the composed shaders parse and validate.

use std::collections::BTreeMap;
use std::mem::{offset_of, size_of};

use gpu_render::gpu::ShaderFeatures;
use gpu_render::low_level::accel::{PrimKind, PrimRef, WideNode};
use gpu_render::low_level::gpu::area_lights::{
    EMITTER_NONE, EMITTER_SPHERE, EMITTER_TRIANGLE, EMITTER_TWO_SIDED_TRIANGLE, FLAG_PATH,
    GpuEmitter, PHASE_EMITTER, PHASE_START_EMITTER,
};
use gpu_render::low_level::gpu::environment::GpuEnvironmentHeader;
use gpu_render::low_level::gpu::layout::*;
use gpu_render::low_level::gpu::shaders::{
    bxdf_eval_shader_source, display_shader_source, shader_module, trace_shader_source,
};

/// The shared records: types.wgsl and the path integrator's path_types.wgsl.
fn shared_types_wgsl() -> String {
    let module = |name| shader_module(name).unwrap_or_else(|| panic!("shaders/{name}.wgsl"));
    format!("{}\n{}", module("types"), module("path_types"))
}

/// Rust twin of one WGSL struct: size and (member name, offset) pairs.
type Twin = (usize, Vec<(&'static str, usize)>);

macro_rules! twin {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        (size_of::<$ty>(), vec![$((stringify!($field), offset_of!($ty, $field))),*])
    };
}

fn rust_twins() -> BTreeMap<&'static str, Twin> {
    BTreeMap::from([
        (
            "FrameUniforms",
            twin!(FrameUniforms {
                eye,
                tan_half_fov_y,
                forward,
                aspect,
                right,
                width,
                up,
                height,
                background,
                samples_per_pixel,
                ambient,
                max_depth,
                camera_medium_iors,
                camera_medium_depth,
                plane_count,
                node_count,
                light_count,
                region_x,
                region_y,
                region_width,
                region_height,
                target_x,
                target_y,
                first_sample,
                end_sample,
                slot_count,
                stack_size,
                iteration_budget,
                flags,
                offset_scale,
                min_ray_weight,
                static_pixels,
                lens_radius,
                focus_distance,
                cone_width,
                cone_spread,
                _pad,
            }),
        ),
        (
            "Sphere",
            twin!(GpuSphere {
                anchor,
                radius,
                normal,
                material
            }),
        ),
        (
            "Plane",
            twin!(GpuPlane {
                normal,
                offset,
                material,
                _pad0,
                _pad1,
                _pad2
            }),
        ),
        (
            "Polygon",
            twin!(GpuPolygon {
                normal,
                offset,
                first_vertex,
                vertex_count,
                dropped_axis,
                material
            }),
        ),
        (
            "Triangle",
            twin!(GpuTriangle {
                v0,
                material,
                v1,
                attributes,
                v2,
                _pad2
            }),
        ),
        (
            "Material",
            twin!(GpuMaterial {
                diffuse,
                shininess,
                specular,
                ior,
                reflectance,
                kind,
                transmittance,
                coat_ior,
                emission,
                roughness,
                eta,
                metallic,
                k,
                sigma,
                distribution,
                fresnel,
                conductor,
                texture_mapping,
                texture_layer,
                texture_width,
                texture_height,
                texture_scale,
                brdf_map_layer,
                brdf_map_size,
                texture_wrap_u,
                texture_wrap_v,
                metallic_roughness_layer,
                metallic_roughness_width,
                metallic_roughness_height,
                metallic_roughness_wrap,
                two_sided,
                emission_layer,
                emission_width,
                emission_height,
                emission_wrap,
                uv_sets,
                cull_back_faces,
                normal_layer,
                uv_rows,
                normal_width,
                normal_height,
                normal_wrap,
                normal_scale,
                alpha_cutoff,
                alpha,
                alpha_blend,
                _pad1,
            }),
        ),
        (
            "Light",
            twin!(GpuLight {
                position_or_direction,
                kind,
                power,
                cos_inner,
                spot_direction,
                cos_outer
            }),
        ),
        (
            "DisplayUniforms",
            twin!(DisplayUniforms { encode_srgb, _pad }),
        ),
        (
            "DenoiseUniforms",
            twin!(DenoiseUniforms {
                width,
                height,
                step,
                _pad,
                sigma_normal,
                sigma_depth,
                sigma_luminance,
                sigma_albedo,
            }),
        ),
        (
            "WideNode",
            twin!(WideNode {
                origin,
                exponents,
                low,
                spare_low,
                high,
                spare_high,
                children
            }),
        ),
        (
            "TraceRay",
            twin!(GpuTraceRay {
                origin,
                t_max,
                direction,
                status,
                best_t,
                best_prim,
                stack_len,
                node,
                cursor,
                leaf_end,
                any_hit,
                best_instance,
                instance,
                stack_base,
                world_cursor,
                world_leaf_end,
                blend_seed,
                transmittance,
                _pad0,
                _pad1
            }),
        ),
        (
            "PathState",
            twin!(GpuPathState {
                pixel,
                sample,
                phase,
                stack_len,
                pixel_sum,
                rays,
                radiance,
                light,
                origin,
                depth,
                direction,
                medium_depth,
                weight,
                material,
                medium_iors,
                shadow_origin,
                base,
                normal,
                roughness,
                albedo,
                metallic,
                direct,
                brdf_pdf,
                emission,
                luminance_m2,
                held,
                held_top,
                image_x,
                image_y,
                pass_throughs,
                cone_width,
                _pad0,
                _pad1,
                _pad2
            }),
        ),
        (
            "TriangleAttributes",
            twin!(GpuTriangleAttributes {
                n0,
                has_normals,
                n1,
                has_uvs,
                n2,
                has_colors,
                uv01,
                uv2,
                has_uvs1,
                has_tangents,
                uv1_01,
                uv1_2,
                _pad1,
                c0,
                c1,
                c2,
                t0,
                t1,
                t2
            }),
        ),
        (
            "StackEntry",
            twin!(GpuStackEntry {
                origin,
                depth,
                direction,
                medium_depth,
                weight,
                cone_width,
                medium_iors
            }),
        ),
        (
            "Emitter",
            twin!(GpuEmitter {
                v0,
                kind,
                v1,
                prim,
                v2,
                cdf,
                normal,
                selection,
                radiance,
                area_density,
                instance,
                _pad0,
                _pad1,
                _pad2
            }),
        ),
        (
            "EnvironmentHeader",
            twin!(GpuEnvironmentHeader {
                scale,
                width,
                rotation,
                height,
                selection,
                integral,
                _pad
            }),
        ),
        (
            "Counters",
            twin!(GpuCounters {
                next_pixel,
                pixels_done,
                rays_low,
                rays_high,
                errors,
                _pad
            }),
        ),
    ])
}

#[test]
fn wgsl_structs_match_rust_twins() {
    let module = naga::front::wgsl::parse_str(&shared_types_wgsl()).expect("types.wgsl parses");
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).expect("layouts compute");
    let twins = rust_twins();
    let mut seen = Vec::new();
    // Collect every mismatch before failing, so one run shows the whole picture.
    let mut mismatches = Vec::new();
    for (handle, ty) in module.types.iter() {
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            continue;
        };
        let name = ty.name.as_deref().unwrap_or("<unnamed>");
        seen.push(name.to_string());
        let Some((rust_size, rust_fields)) = twins.get(name) else {
            mismatches.push(format!("WGSL struct {name} has no Rust twin in this test"));
            continue;
        };
        let wgsl_size = layouter[handle].size as usize;
        if wgsl_size != *rust_size || *span as usize != *rust_size {
            mismatches.push(format!(
                "{name}: WGSL size {wgsl_size} (span {span}), Rust size {rust_size}"
            ));
        }
        // Padding members (named `_...`) may be spelled differently on the two sides
        // (`_pad: [u32; 3]` in Rust, three scalars in WGSL): only the offsets of the
        // meaningful members and the total size must agree.
        let wgsl_fields: Vec<(String, usize)> = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .filter(|(n, _)| !n.starts_with('_'))
            .collect();
        let rust_fields: Vec<(String, usize)> = rust_fields
            .iter()
            .filter(|(n, _)| !n.starts_with('_'))
            .map(|(n, o)| (n.to_string(), *o))
            .collect();
        if wgsl_fields != rust_fields {
            mismatches.push(format!(
                "{name}: WGSL members {wgsl_fields:?}, Rust fields {rust_fields:?}"
            ));
        }
    }
    seen.sort();
    let expected: Vec<String> = twins.keys().map(|k| k.to_string()).collect();
    for missing in expected.iter().filter(|e| !seen.contains(e)) {
        mismatches.push(format!("Rust twin {missing} has no WGSL struct"));
    }
    assert!(
        mismatches.is_empty(),
        "WGSL/Rust layout mismatches:\n  {}",
        mismatches.join("\n  ")
    );
}

#[test]
fn constants_match() {
    let module = naga::front::wgsl::parse_str(&shared_types_wgsl()).expect("types.wgsl parses");
    let rust = BTreeMap::from([
        ("MATERIAL_LAMBERT", MATERIAL_LAMBERT),
        ("MATERIAL_BLINN_PHONG", MATERIAL_BLINN_PHONG),
        ("MATERIAL_MIRROR", MATERIAL_MIRROR),
        ("MATERIAL_DIELECTRIC", MATERIAL_DIELECTRIC),
        ("MATERIAL_EMISSIVE", MATERIAL_EMISSIVE),
        ("MATERIAL_COOK_TORRANCE", MATERIAL_COOK_TORRANCE),
        ("MATERIAL_OREN_NAYAR", MATERIAL_OREN_NAYAR),
        ("MATERIAL_TABULATED", MATERIAL_TABULATED),
        ("MATERIAL_PBR", MATERIAL_PBR),
        ("DISTRIBUTION_GGX", DISTRIBUTION_GGX),
        ("DISTRIBUTION_BECKMANN", DISTRIBUTION_BECKMANN),
        ("FRESNEL_EXACT", FRESNEL_EXACT),
        ("FRESNEL_SCHLICK", FRESNEL_SCHLICK),
        ("MAPPING_PLANAR", MAPPING_PLANAR),
        ("MAPPING_SPHERICAL", MAPPING_SPHERICAL),
        ("MAPPING_UV", MAPPING_UV),
        ("WRAP_REPEAT", WRAP_REPEAT),
        ("WRAP_MIRRORED_REPEAT", WRAP_MIRRORED_REPEAT),
        ("WRAP_CLAMP_TO_EDGE", WRAP_CLAMP_TO_EDGE),
        ("NO_ATTRIBUTES", NO_ATTRIBUTES),
        ("NO_IMAGE", NO_IMAGE),
        ("NO_BLEND_SEED", NO_BLEND_SEED),
        ("LIGHT_POINT", LIGHT_POINT),
        ("LIGHT_DIRECTIONAL", LIGHT_DIRECTIONAL),
        ("LIGHT_SPOT", LIGHT_SPOT),
        ("FLAG_STORE_SUM", FLAG_STORE_SUM),
        ("FLAG_SIMULATE_LOOP_CUT", FLAG_SIMULATE_LOOP_CUT),
        ("ERROR_LOOP_CUT", ERROR_LOOP_CUT),
        ("ERROR_TRAVERSAL_STACK", ERROR_TRAVERSAL_STACK),
        (
            "MAX_PASS_THROUGHS",
            gpu_render::low_level::cpu::intersect::MAX_PASS_THROUGHS,
        ),
        ("PRIM_KIND_SHIFT", PrimRef::INDEX_BITS),
        ("PRIM_INDEX_MASK", PrimRef::MAX_INDEX),
        ("PRIM_SPHERE", PrimKind::Sphere as u32),
        ("PRIM_PLANE", PrimKind::Plane as u32),
        ("PRIM_POLYGON", PrimKind::Polygon as u32),
        ("PRIM_TRIANGLE", PrimKind::Triangle as u32),
        ("FLAG_PATH", FLAG_PATH),
        ("PHASE_EMITTER", PHASE_EMITTER),
        ("PHASE_START_EMITTER", PHASE_START_EMITTER),
        ("EMITTER_SPHERE", EMITTER_SPHERE),
        ("EMITTER_TRIANGLE", EMITTER_TRIANGLE),
        ("EMITTER_NONE", EMITTER_NONE),
        ("EMITTER_TWO_SIDED_TRIANGLE", EMITTER_TWO_SIDED_TRIANGLE),
    ]);
    let mut found = 0;
    for (_, constant) in module.constants.iter() {
        let Some(name) = constant.name.as_deref() else {
            continue;
        };
        let Some(&value) = rust.get(name) else {
            continue;
        };
        let expr = &module.global_expressions[constant.init];
        assert_eq!(
            *expr,
            naga::Expression::Literal(naga::Literal::U32(value)),
            "{name}"
        );
        found += 1;
    }
    assert_eq!(found, rust.len());
}

fn validate(name: &str, source: &str) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name} does not parse:\n{}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name} does not validate:\n{}", e.emit_to_string(source)));
}

#[test]
fn composed_trace_shader_validates() {
    let source = trace_shader_source(&ShaderFeatures::ALL).expect("directives");
    validate("trace shader", &source);
    let module = naga::front::wgsl::parse_str(&source).expect("parsed above");
    for name in ["shade_paths", "trace_rays"] {
        let entry = module
            .entry_points
            .iter()
            .find(|e| e.name == name)
            .unwrap_or_else(|| panic!("entry point {name}"));
        assert_eq!(entry.stage, naga::ShaderStage::Compute);
        assert_eq!(
            entry.workgroup_size,
            [
                gpu_render::low_level::gpu::shaders::SLOT_WORKGROUP_SIZE,
                1,
                1
            ]
        );
    }
}

#[test]
fn composed_display_shader_validates() {
    let source = display_shader_source();
    validate("display shader", &source);
    let module = naga::front::wgsl::parse_str(&source).expect("parsed above");
    let entry = module
        .entry_points
        .iter()
        .find(|e| e.name == "encode_display")
        .expect("entry point encode_display");
    assert_eq!(entry.workgroup_size, [8, 8, 1]);
}

#[test]
fn composed_bxdf_eval_shader_validates() {
    validate("bxdf eval shader", &bxdf_eval_shader_source());
}

/// The value of `const NAME: f32 = VALUE;` in a WGSL source.
fn wgsl_f32_const(source: &str, name: &str) -> f32 {
    let prefix = format!("const {name}: f32 = ");
    let line = source
        .lines()
        .find(|l| l.starts_with(&prefix))
        .unwrap_or_else(|| panic!("no `{prefix}` in the shader"));
    line[prefix.len()..]
        .trim_end_matches(';')
        .parse()
        .unwrap_or_else(|e| panic!("{line}: {e}"))
}

/// Numeric constants written in the WGSL by hand equal their Rust twins in f32.
#[test]
fn wgsl_constants_equal_their_rust_twins() {
    let module = |name| shader_module(name).unwrap_or_else(|| panic!("shaders/{name}.wgsl"));
    let trace = module("trace");
    for (name, rust) in [
        (
            "MIN_LIGHT_DISTANCE_SQUARED",
            gpu_render::low_level::cpu::trace::MIN_LIGHT_DISTANCE_SQUARED,
        ),
        (
            "MIN_SECONDARY_COSINE",
            gpu_render::low_level::cpu::trace::MIN_SECONDARY_COSINE,
        ),
        (
            "MIN_REFLECTION_HEIGHT",
            gpu_render::low_level::cpu::trace::MIN_REFLECTION_HEIGHT,
        ),
    ] {
        assert_eq!(wgsl_f32_const(trace, name), rust as f32, "{name}");
    }
    let path = module("path");
    assert_eq!(
        wgsl_f32_const(path, "MIN_SURVIVAL"),
        gpu_render::low_level::cpu::path::MIN_SURVIVAL as f32
    );
    assert_eq!(
        wgsl_f32_const(module("tabulated"), "TABULATED_COSINE_PROBABILITY"),
        gpu_render::low_level::cpu::tabulated::TABULATED_COSINE_PROBABILITY as f32
    );
    let roulette = format!(
        "const ROULETTE_DEPTH: u32 = {}u;",
        gpu_render::low_level::cpu::path::ROULETTE_DEPTH
    );
    assert!(path.lines().any(|l| l == roulette), "{roulette}");
    assert_eq!(
        wgsl_f32_const(module("texture"), "PROBE_SPAN"),
        gpu_render::low_level::texture::PROBE_SPAN as f32
    );
    let probes = format!(
        "const MAX_TEXTURE_PROBES: u32 = {}u;",
        gpu_render::scene::MAX_TEXTURE_PROBES
    );
    assert!(module("texture").lines().any(|l| l == probes), "{probes}");
    let [r, g, b] = gpu_render::low_level::color::LUMINANCE_WEIGHTS.map(|w| w as f32);
    let weights = format!("const LUMINANCE_WEIGHTS: vec3<f32> = vec3<f32>({r:?}, {g:?}, {b:?});");
    assert!(module("color").lines().any(|l| l == weights), "{weights}");
}

#[test]
fn composed_draw_shader_validates() {
    let source = gpu_render::low_level::gpu::shaders::draw_shader_source();
    validate("draw shader", &source);
    let module = naga::front::wgsl::parse_str(&source).expect("parsed above");
    for (name, stage) in [
        ("fullscreen_triangle", naga::ShaderStage::Vertex),
        ("draw_film", naga::ShaderStage::Fragment),
    ] {
        let entry = module
            .entry_points
            .iter()
            .find(|e| e.name == name)
            .unwrap_or_else(|| panic!("entry point {name}"));
        assert_eq!(entry.stage, stage, "{name}");
    }
    // The mode the host sets (src/gpu/draw.rs) is an override constant of that name.
    assert!(
        module
            .overrides
            .iter()
            .any(|(_, o)| o.name.as_deref() == Some("DRAW_MODE")),
        "DRAW_MODE override"
    );
}
