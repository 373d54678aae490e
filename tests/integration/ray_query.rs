//! Hardware traversal (issue 30, item 2): the triangles found by the device's ray
//! queries in acceleration structures (`src/gpu/ray_query.rs`,
//! `shaders/ray_query.wgsl`), the analytic shapes by the software walk of their own
//! tree. lavapipe (Mesa 25) emulates ray queries in software, so these tests run in CI.
//!
//! - Images: scenes with world-space triangles, instanced meshes (translated, rotated,
//!   scaled, mirrored), spheres, polygons and planes, Whitted and path traced, alpha
//!   masked and blended, rendered with `Traversal::Hardware` agree per pixel with the
//!   CPU reference and with the GPU's software traversal within the twin tolerance
//!   (`TWIN_TOLERANCE`: a channel within `1e-3 + 5e-3·|expected|`, 0.5% of the pixels
//!   may fail: the hardware's triangle test is not ours, so a ray that grazes an edge
//!   may take the neighbouring triangle, and its distance differs by a few ulps), and
//!   their ray counts within 1%.
//! - A device without ray queries: `Traversal::Hardware` is an error naming
//!   `EXPERIMENTAL_RAY_QUERY`, `Auto` renders with the software walk.
//! - A scene beyond the structures' limits: `Hardware` is refused naming the limit.
//! - A scene without triangles, and a degenerate tree (many identical triangles),
//!   trace on the hardware path as on the software one.

use glam::DVec3;
use gpu_render::gpu::{
    HeadlessGpu, RenderError, Renderer, RendererOptions, Traversal, hardware_traversal_available,
};
use gpu_render::scene::{AlphaMode, Integrator, RenderOverrides, Scene, Shape};

use crate::support::compare::assert_images_match;
use crate::support::geometry::blob;
use crate::support::scenes::{reduced, shipped};
use crate::support::twins::{TWIN_TOLERANCE, assert_backends_agree, assert_ray_counts_agree};

/// A device with ray queries, or `None` off CI where the driver has none.
///
/// # Panics
///
/// In CI (`CI` set), when the device has no ray queries: the lavapipe the project
/// installs (Mesa 25.0.7) has them, so the hardware path must be tested there.
pub(crate) fn ray_query_gpu() -> Option<HeadlessGpu> {
    let gpu = crate::support::gpu::headless_gpu()?;
    if hardware_traversal_available(&gpu.device) {
        return Some(gpu);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "CI is set but the device ({}) has no ray queries: install the lavapipe of \
         scripts/lib.sh (Mesa 25)",
        gpu.adapter_info().name
    );
    eprintln!("note: skipping the hardware traversal test, the device has no ray queries");
    None
}

/// The default options but `traversal`.
fn options(traversal: Traversal) -> RendererOptions {
    RendererOptions {
        traversal,
        ..RendererOptions::default()
    }
}

fn renderer(gpu: &HeadlessGpu, traversal: Traversal) -> Renderer {
    crate::support::gpu::renderer_with(gpu, options(traversal))
}

/// Renders `scene` with the hardware traversal and asserts that it took it, that it
/// agrees with the CPU reference and with the software traversal (images within the
/// twin tolerance, ray counts within 1%).
fn hardware_agrees(gpu: &HeadlessGpu, label: &str, scene: &Scene) {
    let hardware = renderer(gpu, Traversal::Hardware);
    let uploaded = hardware
        .upload(&gpu.device, &gpu.queue, scene)
        .unwrap_or_else(|e| panic!("{label}: upload failed: {e}"));
    assert!(
        uploaded.features().hardware_traversal,
        "{label}: Traversal::Hardware must trace with ray queries"
    );
    assert_backends_agree(
        gpu,
        &hardware,
        &format!("{label}-hardware-vs-cpu"),
        scene,
        TWIN_TOLERANCE,
    );
    let software = renderer(gpu, Traversal::Software);
    let soft = software
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("{label}: software render failed: {e}"));
    let hard = hardware
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("{label}: hardware render failed: {e}"));
    let comparison = assert_images_match(
        &format!("{label}-hardware-vs-software"),
        &soft.image,
        &hard.image,
        TWIN_TOLERANCE,
    );
    eprintln!(
        "{label}: hardware against software traversal: {} of {} pixels outside, max |Δ| \
         {:.2e}; rays {} and {}",
        comparison.outliers,
        comparison.pixels,
        comparison.max_abs_error,
        soft.stats.rays_traced,
        hard.stats.rays_traced
    );
    assert_ray_counts_agree(label, &soft.stats, &hard.stats, 0.01);
}

#[test]
fn instanced_meshes_with_analytic_shapes_render_as_the_cpu_and_the_software_walk_do() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    // A plane and a mirror sphere (the analytic tree), a blob placed four times
    // (translated, rotated, scaled, mirrored), a point and a directional light.
    let scene = crate::instancing::instanced_scene(48, &blob(12, 16));
    hardware_agrees(&gpu, "ray-query-instances", &scene);
}

#[test]
fn shipped_mesh_and_polygon_scenes_render_as_the_cpu_does() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    // OBJ and glTF models (world-space triangles) beside spheres and polygons.
    let models = reduced(
        shipped("models.toml"),
        48,
        RenderOverrides {
            samples_per_pixel: Some(1),
            ..RenderOverrides::default()
        },
    );
    hardware_agrees(&gpu, "ray-query-models", &models);
    // Path traced: the Cornell box's polygons and its emitter through the analytic
    // tree, a few samples.
    let cornell = reduced(
        shipped("cornell-box.toml"),
        32,
        RenderOverrides {
            samples_per_pixel: Some(2),
            ..RenderOverrides::default()
        },
    );
    assert_eq!(cornell.render.integrator, Integrator::Path);
    let hardware = renderer(&gpu, Traversal::Hardware);
    assert_backends_agree(
        &gpu,
        &hardware,
        "ray-query-cornell-path",
        &cornell,
        TWIN_TOLERANCE,
    );
}

#[test]
fn alpha_masked_and_blended_triangles_are_candidates_the_shader_decides() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    let mask = crate::model_alpha::checker_scene(AlphaMode::Mask { cutoff: 0.5 });
    hardware_agrees(&gpu, "ray-query-alpha-mask", &mask);
    let blend = crate::model_alpha::checker_scene(AlphaMode::Blend);
    hardware_agrees(&gpu, "ray-query-alpha-blend", &blend);
    // Shadow rays through a cut-out leaf, Whitted and path traced (stochastic
    // transparency's draws name the hit as the software walk does).
    let shadow = crate::model_alpha::shadow_scene();
    hardware_agrees(&gpu, "ray-query-alpha-shadow", &shadow);
    hardware_agrees(
        &gpu,
        "ray-query-alpha-shadow-path",
        &crate::model_alpha::path_traced(&shadow, 2),
    );
}

/// A grey scene of `shapes` seen from +z, lit by one point light.
fn shapes_scene(shapes: Vec<Shape>) -> Scene {
    let mut scene = crate::instancing::instanced_scene(48, &blob(4, 4));
    scene.meshes.clear();
    scene.shapes = shapes;
    scene
}

#[test]
fn a_scene_without_triangles_and_a_degenerate_tree_trace_on_the_hardware_path() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    // Spheres and a plane only: an empty top-level structure.
    let analytic = shapes_scene(vec![
        Shape::Sphere {
            center: DVec3::new(0.0, 0.0, 0.0),
            radius: 1.0,
            material: 1,
        },
        Shape::Plane {
            normal: DVec3::Y,
            offset: -1.2,
            material: 0,
        },
    ]);
    hardware_agrees(&gpu, "ray-query-no-triangles", &analytic);
    // 20,000 copies of one triangle: a tree of identical boxes, ties everywhere
    // (which copy is hit may differ; the image may not).
    let triangle = Shape::Triangle {
        vertices: [
            DVec3::new(-1.5, -1.0, 0.0),
            DVec3::new(1.5, -1.0, 0.0),
            DVec3::new(0.0, 1.5, 0.0),
        ],
        material: 2,
    };
    hardware_agrees(
        &gpu,
        "ray-query-identical-triangles",
        &shapes_scene(vec![triangle; 20_000]),
    );
}

/// A device for `gpu`'s adapter with the renderer's limits and `features`, and
/// `limits` changed by `adjust`.
fn device_with(
    gpu: &HeadlessGpu,
    features: wgpu::Features,
    adjust: impl FnOnce(&mut wgpu::Limits),
) -> (wgpu::Device, wgpu::Queue) {
    let mut limits = Renderer::required_limits(&gpu.adapter.limits());
    adjust(&mut limits);
    let (_, experimental_features) = gpu_render::gpu::ray_query_features(features);
    pollster::block_on(gpu.adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("ray query test device"),
        required_features: features,
        required_limits: limits,
        experimental_features,
        ..Default::default()
    }))
    .expect("the adapter gives a device")
}

#[test]
fn without_ray_queries_hardware_is_an_error_and_auto_takes_the_software_walk() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (device, queue) = device_with(
        &gpu,
        Renderer::optional_features(gpu.adapter.features()),
        |_| {},
    );
    assert!(!hardware_traversal_available(&device));
    let scene = crate::instancing::instanced_scene(32, &blob(6, 8));
    let hardware = Renderer::new(&device, options(Traversal::Hardware)).expect("renderer");
    let error = hardware
        .upload(&device, &queue, &scene)
        .expect_err("Traversal::Hardware without ray queries must fail");
    assert!(
        matches!(error, RenderError::MissingFeature { .. }),
        "{error:?}"
    );
    let message = error.to_string();
    assert!(
        message.contains("EXPERIMENTAL_RAY_QUERY") && message.contains("hardware traversal"),
        "{message}"
    );
    let auto = Renderer::new(&device, options(Traversal::Auto)).expect("renderer");
    let uploaded = auto
        .upload(&device, &queue, &scene)
        .expect("Traversal::Auto renders without ray queries");
    assert!(!uploaded.features().hardware_traversal);
    let rendered = auto
        .render(&device, &queue, &scene, None)
        .expect("the software walk renders");
    assert!(rendered.stats.rays_traced > 0);
}

#[test]
fn a_scene_beyond_the_structures_limits_is_refused_naming_the_limit() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    // Bottom-level structures of at most 30 vertices: ten triangles.
    let (device, queue) = device_with(
        &gpu,
        Renderer::optional_features(gpu.adapter.features())
            | wgpu::Features::EXPERIMENTAL_RAY_QUERY,
        |limits| limits.max_blas_primitive_count = 30,
    );
    assert!(hardware_traversal_available(&device));
    let scene = crate::instancing::instanced_scene(32, &blob(6, 8));
    let hardware = Renderer::new(&device, options(Traversal::Hardware)).expect("renderer");
    let error = hardware
        .upload(&device, &queue, &scene)
        .expect_err("a mesh beyond max_blas_primitive_count must be refused");
    let message = error.to_string();
    assert!(
        matches!(error, RenderError::SceneTooLarge { .. })
            && message.contains("bottom-level acceleration structure")
            && message.contains("30"),
        "{message}"
    );
    // A lone small triangle fits, and renders.
    let small = shapes_scene(vec![Shape::Triangle {
        vertices: [DVec3::new(-1.0, -1.0, 0.0), DVec3::X, DVec3::Y],
        material: 1,
    }]);
    let rendered = hardware
        .render(&device, &queue, &small, None)
        .expect("a scene within the limits renders");
    assert!(rendered.stats.rays_traced > 0);
}

#[test]
fn the_cli_says_when_ray_queries_found_the_triangles() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    let cpu_device = gpu.adapter_info().device_type == wgpu::DeviceType::Cpu;
    drop(gpu);
    let dir = crate::support::compare::output_dir().join("ray-query-cli");
    std::fs::create_dir_all(&dir).expect("output dir");
    let model = crate::support::repo_root().join("scenes/models/torus.obj");
    let run = |traversal: &str| {
        let output = dir.join(format!("{traversal}.png"));
        let run = crate::support::process::gpu_render(&[
            model.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
            "--backend".as_ref(),
            "gpu".as_ref(),
            "--traversal".as_ref(),
            traversal.as_ref(),
            "--width".as_ref(),
            "24".as_ref(),
            "--height".as_ref(),
            "16".as_ref(),
            "--spp".as_ref(),
            "1".as_ref(),
        ]);
        assert_eq!(run.status, Some(0), "{traversal}: {}", run.stderr);
        run.stderr
    };
    let hardware = run("hardware");
    assert!(hardware.contains("triangles by ray query"), "{hardware}");
    let software = run("software");
    assert!(!software.contains("ray query"), "{software}");
    // On a CPU device (lavapipe) auto keeps the software walk, on a real GPU it takes
    // the ray queries.
    let auto = run("auto");
    assert_eq!(
        auto.contains("triangles by ray query"),
        !cpu_device,
        "{auto}"
    );
}

/// Path traced with emissive instanced meshes: next-event estimation samples the
/// instances' triangles, whose emitter records must name the instances' records where
/// the hardware path lays them out (after the analytic shapes' tree, not the scene's).
#[test]
fn emissive_instances_are_sampled_as_the_hardware_path_names_them() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    let mut scene = crate::instancing::instanced_scene(40, &blob(8, 12));
    for mesh in &scene.meshes {
        scene.materials[mesh.material as usize].emission = DVec3::new(2.0, 1.5, 1.0);
    }
    // Small spheres behind the camera: the scene's tree (spheres and instances) and
    // the analytic shapes' tree (spheres alone) get different node counts.
    let eye = scene.camera.eye;
    let material = scene.meshes[0].material;
    scene.shapes.extend((0..24).map(|i| Shape::Sphere {
        center: eye + DVec3::new(f64::from(i % 6) - 2.5, f64::from(i / 6) - 1.5, 3.0),
        radius: 0.1,
        material,
    }));
    scene.render.integrator = Integrator::Path;
    scene.render.samples_per_pixel = 4;
    scene.render.max_depth = 3;
    let geometry = gpu_render::low_level::accel::SceneGeometry::new(&scene);
    let analytic = geometry.analytic_bvh(gpu_render::low_level::accel::BuildMethod::Sah);
    assert_ne!(geometry.bvh.wide.len(), analytic.wide.len());
    hardware_agrees(&gpu, "ray-query-emissive-instances", &scene);
}

/// The hardware path builds no software tree over the triangles (the driver's
/// structures hold them): the upload's tree is the analytic shapes' alone, and the
/// scene's buffers hold no node or reference of a triangle.
#[test]
fn the_hardware_path_builds_no_tree_over_the_triangles() {
    let Some(gpu) = ray_query_gpu() else {
        return;
    };
    let mut scene = crate::instancing::instanced_scene(32, &blob(24, 32));
    // One placement of the blob: world-space triangles, the scene tree's bulk.
    scene.meshes.truncate(1);
    scene.meshes[0].instances.truncate(1);
    let geometry = gpu_render::low_level::accel::SceneGeometry::new(&scene);
    let analytic = geometry.analytic_bvh(gpu_render::low_level::accel::BuildMethod::Sah);
    assert!(geometry.triangles.len() > 1000 && geometry.instances.is_empty());
    let upload = |traversal| {
        renderer(&gpu, traversal)
            .upload(&gpu.device, &gpu.queue, &scene)
            .unwrap_or_else(|e| panic!("{traversal:?}: {e}"))
    };
    let (hardware, software) = (upload(Traversal::Hardware), upload(Traversal::Software));
    assert_eq!(hardware.bvh_stats().nodes, analytic.stats.nodes);
    assert_eq!(software.bvh_stats().nodes, geometry.bvh.stats.nodes);
    assert!(analytic.stats.nodes * 10 < geometry.bvh.stats.nodes);
    assert!(
        hardware.scene_bytes() < software.scene_bytes(),
        "{} against {} bytes",
        hardware.scene_bytes(),
        software.scene_bytes()
    );
    hardware_agrees(&gpu, "ray-query-world-triangles", &scene);
}
