//! The trace shader is specialised to each scene: what a scene does not use is not in
//! the compiled module, and leaving it out changes no pixel.

use std::collections::BTreeSet;

use gpu_render::gpu::RendererOptions;
use gpu_render::gpu::{Renderer, ShaderFeatures};
use gpu_render::low_level::gpu::shaders::trace_shader_source;
use gpu_render::scene::{RenderOverrides, Scene, load_scene};

use crate::support::scenes::shipped as scene;

/// The names of the functions in the naga module built for `features`, validated with
/// the capabilities a device without optional features has (subgroup operations only
/// for a module with `refill_lanes`, which needs them).
fn function_names(features: &ShaderFeatures) -> BTreeSet<String> {
    let source = trace_shader_source(features).expect("well-formed directives");
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    let mut validator = if features.refill_lanes || features.lockstep_samples {
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::SUBGROUP,
        );
        validator
            .subgroup_stages(naga::valid::ShaderStages::COMPUTE)
            .subgroup_operations(
                naga::valid::SubgroupOperationSet::ARITHMETIC
                    | naga::valid::SubgroupOperationSet::VOTE,
            );
        validator
    } else {
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
    };
    validator
        .validate(&module)
        .unwrap_or_else(|e| panic!("{:?}: {}", features, e.emit_to_string(&source)));
    module
        .functions
        .iter()
        .filter_map(|(_, f)| f.name.clone())
        .collect()
}

const REFRACTION_CODE: [&str; 3] = [
    "refract_direction",
    "medium_after_refraction",
    "medium_outside_ior",
];

#[test]
fn a_scene_without_dielectrics_gets_no_refraction_code() {
    let diffuse = scene("linear-vs-gamma.toml");
    let features = ShaderFeatures::for_scene(&diffuse);
    assert!(!features.refraction);
    let names = function_names(&features);
    for function in REFRACTION_CODE {
        assert!(!names.contains(function), "{function} is in the module");
    }
    // Nor code for the shapes and models it does not use.
    for function in [
        "intersect_triangle",
        "point_in_polygon",
        "brdf_cook_torrance",
        "brdf_oren_nayar",
        "brdf_pbr",
        "sample_texture",
    ] {
        assert!(!names.contains(function), "{function} is in the module");
    }
    assert!(names.contains("intersect_sphere") && names.contains("brdf_blinn_phong"));

    let glass = ShaderFeatures::for_scene(&scene("showcase.toml"));
    assert!(glass.refraction);
    let names = function_names(&glass);
    for function in REFRACTION_CODE {
        assert!(names.contains(function), "{function} is missing");
    }
}

/// A scene without an environment map gets none of its code (the constant background
/// and a zero selection remain); the shipped environment-lit scene gets it.
#[test]
fn only_a_scene_with_an_environment_map_gets_its_code() {
    const ENVIRONMENT_CODE: [&str; 4] = [
        "environment_sample",
        "environment_pdf",
        "environment_radiance",
        "distribution_1d_sample",
    ];
    let cornell = ShaderFeatures::for_scene(&scene("cornell-box.toml"));
    assert!(cornell.path && !cornell.environment_map);
    let names = function_names(&cornell);
    for function in ENVIRONMENT_CODE {
        assert!(!names.contains(function), "{function} is in the module");
    }
    assert!(names.contains("background_radiance") && names.contains("environment_selection"));
    let lit = ShaderFeatures::for_scene(&scene("env-materials.toml"));
    assert!(lit.environment_map);
    let names = function_names(&lit);
    for function in ENVIRONMENT_CODE {
        assert!(names.contains(function), "{function} is missing");
    }
}

/// Only a module with `refill_lanes` or `lockstep_samples` uses subgroup operations
/// (a device without wgpu::Features::SUBGROUP could not build the others otherwise),
/// and it validates.
#[test]
fn only_modules_that_ask_for_them_use_subgroup_operations() {
    for features in [
        ShaderFeatures::ALL,
        ShaderFeatures::for_scene(&scene("showcase.toml")),
        ShaderFeatures::for_scene(&scene("cornell-box.toml")),
    ] {
        assert!(
            !features.refill_lanes && !features.lockstep_samples,
            "chosen from the device, not the scene"
        );
        let without = trace_shader_source(&features).expect("well-formed directives");
        assert!(!without.contains("subgroupAdd(") && !without.contains("subgroupAll("));
        let refill = ShaderFeatures {
            refill_lanes: true,
            ..features
        };
        assert_eq!(function_names(&refill), function_names(&features));
        let with = trace_shader_source(&refill).expect("well-formed directives");
        assert!(with.contains("subgroupAdd(1u)"));
        assert!(!with.contains("subgroupAll("));
        let lockstep = ShaderFeatures {
            lockstep_samples: true,
            ..features
        };
        assert_eq!(function_names(&lockstep), function_names(&features));
        let with = trace_shader_source(&lockstep).expect("well-formed directives");
        assert!(with.contains("subgroupAll(path.phase == PHASE_START_SAMPLE)"));
        assert!(!with.contains("subgroupAdd("));
    }
}

#[test]
fn modules_with_uniform_records_validate_and_differ_only_in_their_bindings() {
    for features in [
        ShaderFeatures::ALL,
        ShaderFeatures::for_scene(&scene("showcase.toml")),
    ] {
        let uniform = ShaderFeatures {
            uniform_records: true,
            ..features
        };
        assert_eq!(function_names(&uniform), function_names(&features));
        let source = trace_shader_source(&uniform).expect("well-formed directives");
        assert!(source.contains("var<uniform> bvh_nodes: array<WideNode, 1024>;"));
        assert!(!source.contains("var<storage, read> bvh_nodes"));
    }
}

#[test]
fn every_feature_alone_and_every_feature_left_out_validates() {
    let none = ShaderFeatures {
        spheres: false,
        planes: false,
        polygons: false,
        triangles: false,
        refraction: false,
        blinn_phong: false,
        cook_torrance: false,
        oren_nayar: false,
        tabulated: false,
        pbr: false,
        textures: false,
        mesh_attributes: false,
        instances: false,
        path: false,
        environment_map: false,
        alpha: false,
        aov: false,
        uniform_records: false,
        node_texture: false,
        refill_lanes: false,
        lockstep_samples: false,
        unrolled: None,
        hardware_traversal: false,
    };
    type Toggle = fn(&mut ShaderFeatures, bool);
    let toggles: [Toggle; 17] = [
        |f, v| f.spheres = v,
        |f, v| f.planes = v,
        |f, v| f.polygons = v,
        |f, v| f.triangles = v,
        |f, v| f.refraction = v,
        |f, v| f.blinn_phong = v,
        |f, v| f.cook_torrance = v,
        |f, v| f.oren_nayar = v,
        |f, v| f.tabulated = v,
        |f, v| f.pbr = v,
        |f, v| f.textures = v,
        |f, v| f.mesh_attributes = v,
        |f, v| f.instances = v,
        |f, v| f.path = v,
        |f, v| f.environment_map = v,
        |f, v| f.alpha = v,
        |f, v| f.aov = v,
    ];
    // Every toggle on: the general module leaves the alpha test out.
    let every = ShaderFeatures {
        alpha: true,
        ..ShaderFeatures::ALL
    };
    let all = function_names(&every).len();
    let bare = function_names(&none).len();
    assert!(
        bare < all,
        "the bare module should be smaller: {bare} vs {all}"
    );
    for toggle in toggles {
        let mut alone = none;
        toggle(&mut alone, true);
        function_names(&alone);
        let mut without = every;
        toggle(&mut without, false);
        function_names(&without);
        let source_length = |f: &ShaderFeatures| {
            trace_shader_source(f)
                .expect("well-formed directives")
                .len()
        };
        assert!(
            source_length(&without) < source_length(&every),
            "leaving out a feature should remove code: {without:?}"
        );
    }
}

fn reduced(scene: Scene) -> Scene {
    let overrides = RenderOverrides {
        samples_per_pixel: Some(2),
        // Path-traced scenes are compared as Whitted renders here; the path
        // integrator's twin has tests/integration/path_gpu.rs.
        integrator: Some(gpu_render::scene::Integrator::Whitted),
        ..RenderOverrides::default()
    };
    crate::support::scenes::reduced(scene, 96, overrides)
}

#[test]
fn specialised_and_general_modules_render_the_same_pixels() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let specialised = crate::support::gpu::renderer(&gpu);
    let general = Renderer::new(
        &gpu.device,
        RendererOptions {
            specialise: false,
            ..RendererOptions::default()
        },
    )
    .expect("renderer");
    for path in crate::support::scenes::shipped_scenes() {
        let scene = reduced(load_scene(&path).unwrap_or_else(|e| panic!("{e}")));
        let a = specialised
            .render(&gpu.device, &gpu.queue, &scene, None)
            .expect("specialised render");
        let b = general
            .render(&gpu.device, &gpu.queue, &scene, None)
            .expect("general render");
        let worst = crate::support::compare::max_channel_difference(&a.image, &b.image);
        // The same arithmetic in the same order; only code the scene never runs differs.
        assert!(worst <= 1e-6, "{}: max |Δ| {worst}", path.display());
        assert_eq!(
            a.stats.rays_traced,
            b.stats.rays_traced,
            "{}",
            path.display()
        );
    }
}

#[test]
fn pipelines_are_cached_by_feature_set() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let showcase = reduced(scene("showcase.toml"));
    let diffuse = reduced(scene("linear-vs-gamma.toml"));
    let render = |s: &Scene| {
        renderer
            .render(&gpu.device, &gpu.queue, s, None)
            .expect("render");
    };
    render(&showcase);
    render(&showcase);
    assert_eq!(renderer.cached_pipeline_count(), 1);
    render(&diffuse);
    assert_eq!(renderer.cached_pipeline_count(), 2);
    render(&showcase);
    render(&diffuse);
    assert_eq!(renderer.cached_pipeline_count(), 2);
}
