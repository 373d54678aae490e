//! On CPU devices, a scene of at most `MAX_UNROLLED_PRIMITIVES` primitives tests them
//! in straight-line code instead of walking its BVH (`src/gpu/cpu_device/unrolled.rs`): the same
//! pixels and the same rays as the tree's walk, on shipped scenes and on one with
//! every kind of primitive (a polygon of more than four vertices among them); larger
//! scenes keep the tree.

use std::path::Path;

use gpu_render::gpu::Renderer;
use gpu_render::gpu::RendererOptions;
use gpu_render::low_level::gpu::cpu_device::unrolled::MAX_UNROLLED_PRIMITIVES;
use gpu_render::scene::{RenderOverrides, Scene, parse_scene};

/// Spheres, planes, a triangle, a quad and a hexagon, in glass, a mirror and Lambert
/// surfaces, lit by a point light and the sun.
const EVERY_KIND: &str = r#"
[render]
width = 48
height = 36
samples_per_pixel = 2
max_depth = 12

[camera]
eye = [0.0, 1.5, 6.0]
look_at = [0.0, 0.6, 0.0]
fov_y_degrees = 50.0

[environment]
background = [0.3, 0.35, 0.45]

[materials.white]
type = "lambert"
albedo = 0.7

[materials.glass]
type = "dielectric"
ior = 1.5

[materials.mirror]
type = "mirror"

[[lights]]
type = "point"
position = [2.0, 5.0, 3.0]
intensity = 40.0

[[lights]]
type = "directional"
direction = [-0.3, -1.0, -0.2]
irradiance = 1.5

[[objects]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "white"

[[objects]]
type = "plane"
point = [0.0, 0.0, -3.0]
normal = [0.0, 0.0, 1.0]
material = "white"

[[objects]]
type = "sphere"
center = [-1.2, 0.7, 0.0]
radius = 0.7
material = "glass"

[[objects]]
type = "sphere"
center = [0.9, 0.5, 0.6]
radius = 0.5
material = "mirror"

[[objects]]
type = "triangle"
vertices = [[-2.5, 0.0, -1.0], [-0.5, 0.0, -1.5], [-1.5, 2.0, -1.2]]
material = "white"

[[objects]]
type = "polygon"
vertices = [[0.5, 0.0, -1.0], [2.0, 0.0, -1.0], [2.0, 1.5, -1.0], [0.5, 1.5, -1.0]]
material = "glass"

[[objects]]
type = "polygon"
vertices = [[-0.5, 0.01, 1.0], [0.0, 0.01, 0.6], [0.6, 0.01, 0.8], [0.7, 0.01, 1.4], [0.2, 0.01, 1.8], [-0.4, 0.01, 1.5]]
material = "mirror"
"#;

/// Whether the test device is a CPU (lavapipe), where unrolled scenes are preferred.
fn cpu_device(gpu: &gpu_render::gpu::HeadlessGpu) -> bool {
    gpu.adapter_info().device_type == wgpu::DeviceType::Cpu
}

fn every_kind() -> Scene {
    parse_scene(EVERY_KIND, Path::new("every-kind.toml")).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn small_scenes_render_the_same_unrolled_and_through_the_tree() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let unrolled = crate::support::gpu::renderer(&gpu);
    let tree = Renderer::new(
        &gpu.device,
        RendererOptions {
            unrolled: false,
            ..RendererOptions::default()
        },
    )
    .expect("renderer");
    let mut scenes = vec![("every kind of primitive".to_string(), every_kind())];
    for name in ["glass.toml", "direct-light.toml", "caustic-whitted.toml"] {
        let scene = crate::support::scenes::reduced(
            crate::support::scenes::shipped(name),
            64,
            RenderOverrides::default(),
        );
        scenes.push((name.to_string(), scene));
    }
    // glass.toml's deep refraction chains, where a tree walk and the unrolled test
    // would part first if they disagreed on a grazing hit.
    let deep = crate::support::scenes::reduced(
        crate::support::scenes::shipped("glass.toml"),
        48,
        RenderOverrides {
            max_depth: Some(64),
            ..RenderOverrides::default()
        },
    );
    scenes.push(("glass.toml at depth 64".to_string(), deep));
    for (what, scene) in &scenes {
        let prepared = unrolled
            .upload(&gpu.device, &gpu.queue, scene)
            .expect("prepare");
        assert!(
            tree.upload(&gpu.device, &gpu.queue, scene)
                .expect("prepare")
                .features()
                .unrolled
                .is_none(),
            "{what}: the switch keeps the tree"
        );
        if !cpu_device(&gpu) {
            // Real GPUs walk the tree: nothing to compare.
            assert!(prepared.features().unrolled.is_none(), "{what}");
            continue;
        }
        let tests = prepared
            .features()
            .unrolled
            .unwrap_or_else(|| panic!("{what}: small enough to unroll"));
        assert!(!tests.tests().is_empty(), "{what}");
        crate::support::gpu::assert_renders_identical(
            &gpu,
            &unrolled,
            &tree,
            scene,
            &format!("{what}, unrolled and through the tree"),
        );
    }
}

#[test]
fn scenes_past_the_limit_walk_the_tree() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let mut scene = every_kind();
    let count = |scene: &Scene| {
        gpu_render::low_level::accel::SceneGeometry::new(scene).bounded_count() + 2 // two planes
    };
    assert!(count(&scene) <= MAX_UNROLLED_PRIMITIVES);
    let sphere = scene.shapes[2].clone();
    while count(&scene) <= MAX_UNROLLED_PRIMITIVES {
        scene.shapes.push(sphere.clone());
    }
    let prepared = renderer
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("prepare");
    assert!(prepared.features().unrolled.is_none());
}
