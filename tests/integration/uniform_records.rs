//! On CPU devices, a scene whose records fit is bound with its BVH nodes, spheres,
//! polygons, triangles, materials and lights in uniform buffers
//! (`src/gpu/cpu_device/uniform_records.rs`), and a larger one reads its BVH nodes
//! from a texture (`src/gpu/cpu_device/node_texture.rs`): the same pixels and the same
//! rays as with storage buffers, and scenes too large for uniform buffers keep
//! storage buffers for their records.

use glam::DVec3;
use gpu_render::gpu::Renderer;
use gpu_render::gpu::RendererOptions;
use gpu_render::scene::{Light, RenderOverrides, Scene};

/// Whether the test device is a CPU (lavapipe), where uniform records are preferred.
fn cpu_device(gpu: &gpu_render::gpu::HeadlessGpu) -> bool {
    gpu.adapter_info().device_type == wgpu::DeviceType::Cpu
}

/// A renderer that keeps every record in storage buffers.
fn storage_renderer(gpu: &gpu_render::gpu::HeadlessGpu) -> Renderer {
    Renderer::new(
        &gpu.device,
        RendererOptions {
            uniform_records: false,
            ..RendererOptions::default()
        },
    )
    .expect("renderer")
}

#[test]
fn shipped_scenes_render_the_same_with_uniform_and_storage_records() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let uniform = crate::support::gpu::renderer(&gpu);
    let storage = storage_renderer(&gpu);
    let mut uniform_scenes = 0;
    // Whitted with polygons, triangles and glass; the path integrator; meshes and
    // textures; tabulated BRDFs; an environment map.
    let names = [
        "showcase.toml",
        "cornell-box.toml",
        "models.toml",
        "tabulated.toml",
        "env-materials.toml",
    ];
    for path in names {
        let scene = crate::support::scenes::reduced(
            crate::support::scenes::shipped(path),
            64,
            RenderOverrides::default(),
        );
        let prepared = uniform
            .upload(&gpu.device, &gpu.queue, &scene)
            .expect("prepare");
        let stored = storage
            .upload(&gpu.device, &gpu.queue, &scene)
            .expect("prepare");
        assert!(!stored.features().uniform_records && !stored.features().node_texture);
        if !cpu_device(&gpu) {
            // Real GPUs keep storage buffers: nothing to compare.
            assert!(!prepared.features().uniform_records && !prepared.features().node_texture);
            continue;
        }
        // One or the other where the records do not fit uniform buffers.
        assert!(prepared.features().uniform_records != prepared.features().node_texture);
        uniform_scenes += usize::from(prepared.features().uniform_records);
        // The same code reading the same values; only where they are bound differs.
        let what = format!("{path}, uniform and storage records");
        crate::support::gpu::assert_renders_identical(&gpu, &uniform, &storage, &scene, &what);
    }
    if cpu_device(&gpu) {
        // These scenes are small: most of them take uniform records.
        assert!(
            uniform_scenes >= 4,
            "{uniform_scenes} scenes had uniform records"
        );
    }
}

/// The showcase with `lights` point lights added.
fn with_point_lights(lights: usize) -> Scene {
    let mut scene = crate::support::scenes::shipped("showcase.toml");
    for i in 0..lights {
        scene.lights.push(Light::Point {
            position: DVec3::new(i as f64 * 1e-3, 5.0, 0.0),
            intensity: DVec3::splat(1e-3),
        });
    }
    scene
}

#[test]
fn records_beyond_one_uniform_binding_stay_in_storage_buffers() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let base = crate::support::scenes::shipped("showcase.toml")
        .lights
        .len();
    // 64 KiB of 32-byte light records hold 2,048 lights.
    let capacity = 65536 / std::mem::size_of::<gpu_render::low_level::gpu::layout::GpuLight>();
    let fits = renderer
        .upload(&gpu.device, &gpu.queue, &with_point_lights(capacity - base))
        .expect("prepare");
    assert_eq!(fits.features().uniform_records, cpu_device(&gpu));
    let beyond = renderer
        .upload(
            &gpu.device,
            &gpu.queue,
            &with_point_lights(capacity - base + 1),
        )
        .expect("prepare");
    assert!(!beyond.features().uniform_records);
    // Its lights do not fit their binding beside a node texture either
    // (`UniformRecords::Small`), so every record stays in storage, its nodes too.
    assert!(!beyond.features().node_texture);
    assert!(!fits.features().node_texture);
}

#[test]
fn a_scene_too_large_for_uniform_records_reads_its_nodes_from_a_texture_with_the_same_pixels() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let texture = crate::support::gpu::renderer(&gpu);
    let storage = storage_renderer(&gpu);
    let mut scene = crate::support::scenes::reduced(
        crate::support::scenes::shipped("showcase.toml"),
        48,
        RenderOverrides::default(),
    );
    // 9,400 triangles: beyond the 1,365 of one uniform binding, and thousands of nodes.
    scene.meshes.push(gpu_render::scene::Mesh {
        instances: vec![glam::DMat4::IDENTITY],
        ..crate::support::geometry::blob(60, 80)
    });
    let prepared = texture
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("prepare");
    assert!(!prepared.features().uniform_records);
    assert_eq!(prepared.features().node_texture, cpu_device(&gpu));
    let stored = storage
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("prepare");
    assert!(!stored.features().node_texture);
    // The same walk reading the same nodes; only where they are bound differs.
    crate::support::gpu::assert_renders_identical(
        &gpu,
        &texture,
        &storage,
        &scene,
        "the showcase and a blob, nodes from the texture and from storage",
    );
}
