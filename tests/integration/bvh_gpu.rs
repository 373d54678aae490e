//! The WGSL traversal of the BVH (`shaders/traverse.wgsl`) returns exactly what a WGSL
//! brute-force loop over every primitive returns (same distance bits, same primitive),
//! for random rays, shadow rays and rays aimed at shared mesh edges, also when every
//! traversal is suspended and resumed after each step; and it agrees with the CPU
//! twin up to the f32/f64 difference of grazing rays. The hardware traversal (ray
//! queries for the triangles) finds the software walk's hits ray by ray, up to what
//! the driver's own triangle test decides (edges, exact ties, a few ulps).

use crate::support::geometry::{
    blob, mixed_shapes, random_rays, rays_through_mesh_edges, small_polygons,
};
use glam::{DMat4, DQuat, DVec3};
use gpu_render::gpu::ShaderFeatures;
use gpu_render::low_level::accel::{BuildMethod, SceneGeometry};
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::traverse::closest_hit_brute_force;
use gpu_render::low_level::gpu::layout::{FrameUniforms, GpuCounters};
use gpu_render::low_level::gpu::ray_query::build_acceleration;
use gpu_render::low_level::gpu::shaders::compose_source;
use gpu_render::low_level::gpu::upload::{InstanceLayout, SceneRecords, frame_uniforms};
use gpu_render::scene::{Camera, Environment, Material, RenderSettings, Scene, Shape};
use wgpu::util::DeviceExt;

/// Two kernels over a list of rays (`origin, t_max; direction, any_hit`): the BVH
/// traversal, resumed until it finishes, and the brute force with the same tie rule.
/// Each writes `(bits of best_t, best_prim)`.
const KERNELS: &str = r"
#import types
#import bindings
#import records
#import budget
#import intersect
#import traverse

@group(0) @binding(23) var<storage, read> test_rays: array<vec4<f32>>;
@group(0) @binding(24) var<storage, read_write> results: array<vec2<u32>>;

fn test_trace(slot: u32) -> TraceRay {
    let a = test_rays[2u * slot];
    let b = test_rays[2u * slot + 1u];
    return TraceRay(a.xyz, a.w, b.xyz, TRACE_PENDING, a.w, NO_PRIM, 0u, NO_NODE, 0u, 0u,
                    u32(b.w), NO_INSTANCE, NO_INSTANCE, 0u, 0u, 0u, NO_BLEND_SEED, 1.0, 0u, 0u);
}

@compute @workgroup_size(64)
fn traverse_rays(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if slot >= frame.slot_count {
        return;
    }
    var trace = test_trace(slot);
    loop {
        iterations = 0u;
        if traverse(slot, &trace, false) == TRAVERSAL_FINISHED {
            break;
        }
    }
    results[slot] = vec2<u32>(bitcast<u32>(trace.best_t), trace.best_prim);
}

fn brute_force_consider(prim: u32, ray: Ray, best: ptr<function, vec2<u32>>) {
    let t = intersect_prim(prim, ray, shear_ray(ray),
                           limit_for(prim, NO_INSTANCE, bitcast<f32>((*best).x), (*best).y, NO_INSTANCE));
    if t != NO_HIT {
        *best = vec2<u32>(bitcast<u32>(t), prim);
    }
}

@compute @workgroup_size(64)
fn brute_force_rays(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if slot >= frame.slot_count {
        return;
    }
    let trace = test_trace(slot);
    let ray = Ray(trace.origin, trace.direction);
    var best = vec2<u32>(bitcast<u32>(trace.t_max), NO_PRIM);
    for (var i = 0u; i < arrayLength(&spheres); i += 1u) {
        brute_force_consider((PRIM_SPHERE << PRIM_KIND_SHIFT) | i, ray, &best);
    }
    for (var i = 0u; i < frame.plane_count; i += 1u) {
        brute_force_consider((PRIM_PLANE << PRIM_KIND_SHIFT) | i, ray, &best);
    }
    for (var i = 0u; i < arrayLength(&polygons); i += 1u) {
        brute_force_consider((PRIM_POLYGON << PRIM_KIND_SHIFT) | i, ray, &best);
    }
    for (var i = 0u; i < arrayLength(&triangles); i += 1u) {
        brute_force_consider((PRIM_TRIANGLE << PRIM_KIND_SHIFT) | i, ray, &best);
    }
    results[slot] = best;
}
";

fn scene_of(shapes: Vec<Shape>) -> Scene {
    Scene {
        render: RenderSettings::default(),
        camera: Camera {
            eye: DVec3::new(0.0, 0.0, 10.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        materials: vec![Material::lambert(DVec3::splat(0.5))],
        material_names: vec!["grey".into()],
        lights: vec![],
        shapes,
        meshes: vec![],
        images: vec![],
    }
}

/// One ray's result: the hit distance's bits and primitive.
type GpuHit = [u32; 2];

/// How [`run_kernel`]'s traversal finds the triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Walk {
    /// The software walk of the scene's wide BVH.
    Software,
    /// The device's ray queries in acceleration structures (`HARDWARE_TRAVERSAL`),
    /// the software walk over a tree of the analytic shapes alone.
    Hardware,
}

/// Runs `entry` over `rays` (each with its limit and any-hit flag) on the GPU.
fn run_kernel(
    gpu: &gpu_render::gpu::HeadlessGpu,
    geometry: &SceneGeometry,
    scene: &Scene,
    rays: &[(Ray, f32, bool)],
    entry: &str,
    budget: u32,
    walk: Walk,
) -> Vec<GpuHit> {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let hardware = walk == Walk::Hardware;
    let features = ShaderFeatures {
        hardware_traversal: hardware,
        ..ShaderFeatures::ALL
    };
    let source = compose_source(KERNELS, &features).expect("the kernels compose");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("traversal test"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    // The hardware path walks a tree of the analytic shapes alone (as the renderer's
    // upload does).
    let analytic = hardware.then(|| geometry.analytic_bvh(BuildMethod::Sah));
    let records = match &analytic {
        Some(tree) => SceneRecords::with_scene_tree(scene, geometry, tree),
        None => SceneRecords::new(scene, geometry),
    }
    .padded();
    let mut frame = FrameUniforms {
        slot_count: rays.len() as u32,
        iteration_budget: budget,
        ..frame_uniforms(scene, geometry)
    };
    if let Some(tree) = &analytic {
        frame.node_count = tree.wide.len() as u32;
    }
    let storage = |contents: &[u8], usage: wgpu::BufferUsages| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents,
            usage: wgpu::BufferUsages::STORAGE | usage,
        })
    };
    let none = wgpu::BufferUsages::empty();
    let ray_words: Vec<[f32; 4]> = rays
        .iter()
        .flat_map(|(ray, t_max, any_hit)| {
            let o = ray.origin.as_vec3();
            let d = ray.direction.as_vec3();
            [
                [o.x, o.y, o.z, *t_max],
                [d.x, d.y, d.z, f32::from(u8::from(*any_hit))],
            ]
        })
        .collect();
    let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::bytes_of(&frame),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let buffers = [
        (1, storage(bytemuck::cast_slice(&records.spheres), none)),
        (2, storage(bytemuck::cast_slice(&records.planes), none)),
        (3, storage(bytemuck::cast_slice(&records.polygons), none)),
        (
            4,
            storage(bytemuck::cast_slice(&records.polygon_points), none),
        ),
        (
            5,
            storage(
                bytemuck::cast_slice(&records.triangles),
                if hardware {
                    wgpu::BufferUsages::BLAS_INPUT
                } else {
                    none
                },
            ),
        ),
        (
            9,
            storage(
                bytemuck::bytes_of(&<GpuCounters as bytemuck::Zeroable>::zeroed()),
                wgpu::BufferUsages::COPY_SRC,
            ),
        ),
        (12, storage(bytemuck::cast_slice(&records.bvh_nodes), none)),
        (13, storage(bytemuck::cast_slice(&records.bvh_prims), none)),
        (
            17,
            storage(
                &vec![
                    0u8;
                    rays.len() * gpu_render::low_level::accel::MAX_TRAVERSAL_STACK as usize * 8
                ],
                none,
            ),
        ),
        (23, storage(bytemuck::cast_slice(&ray_words), none)),
        (
            24,
            storage(&vec![0u8; rays.len() * 8], wgpu::BufferUsages::COPY_SRC),
        ),
    ];
    let acceleration = analytic.as_ref().map(|tree| {
        let layout = InstanceLayout::with_scene_nodes(geometry, tree.wide.len());
        let triangles = &buffers
            .iter()
            .find(|(binding, _)| *binding == 5)
            .expect("the triangle buffer")
            .1;
        build_acceleration(device, queue, triangles, geometry, &layout, true)
            .unwrap_or_else(|e| panic!("the acceleration structures build: {e}"))
    });
    // The automatic layout keeps only what the entry point uses.
    let layout = pipeline.get_bind_group_layout(0);
    let used: Vec<u32> = match entry {
        "traverse_rays" => vec![0, 1, 2, 3, 4, 5, 9, 12, 13, 17, 23, 24],
        _ => vec![0, 1, 2, 3, 4, 5, 23, 24],
    };
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: uniforms.as_entire_binding(),
    }];
    if let Some(acceleration) = &acceleration {
        entries.push(wgpu::BindGroupEntry {
            binding: 21,
            resource: wgpu::BindingResource::AccelerationStructure(&acceleration.tlas),
        });
    }
    for (binding, buffer) in &buffers {
        if used.contains(binding) {
            entries.push(wgpu::BindGroupEntry {
                binding: *binding,
                resource: buffer.as_entire_binding(),
            });
        }
    }
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &entries,
    });
    let results = &buffers.last().expect("results").1;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: rays.len() as u64 * 8,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(results, 0, &readback, 0, rays.len() as u64 * 8);
    queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("maps"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("device polls");
    let bytes = readback
        .slice(..)
        .get_mapped_range()
        .expect("mapped")
        .to_vec();
    bytemuck::pod_collect_to_vec(&bytes)
}

/// Every ray as a closest-hit query, then again as a shadow ray (any hit) to distance 3.
fn closest_and_shadow_queries(rays: &[Ray]) -> Vec<(Ray, f32, bool)> {
    let closest = rays.iter().map(|r| (*r, f32::INFINITY, false));
    closest
        .chain(rays.iter().map(|r| (*r, 3.0, true)))
        .collect()
}

/// Checks the traversal on `rays`; with `watertight`, every closest-hit ray must hit.
fn check(
    gpu: &gpu_render::gpu::HeadlessGpu,
    shapes: Vec<Shape>,
    rays: Vec<Ray>,
    name: &str,
    watertight: bool,
) {
    let scene = scene_of(shapes);
    let geometry = SceneGeometry::with_method(&scene, BuildMethod::Sah);
    let queries = closest_and_shadow_queries(&rays);
    let budget = gpu_render::gpu::iteration_budget_for(&gpu.adapter_info());
    let traversed = run_kernel(
        gpu,
        &geometry,
        &scene,
        &queries,
        "traverse_rays",
        budget,
        Walk::Software,
    );
    let brute = run_kernel(
        gpu,
        &geometry,
        &scene,
        &queries,
        "brute_force_rays",
        budget,
        Walk::Software,
    );
    // A budget of 1: every traversal is suspended after each step and resumed.
    let resumed = run_kernel(
        gpu,
        &geometry,
        &scene,
        &queries,
        "traverse_rays",
        1,
        Walk::Software,
    );
    let mut hits = 0;
    for (i, (query, any_hit)) in queries.iter().map(|q| (q, q.2)).enumerate() {
        if any_hit {
            // A shadow query reports some hit before its limit, not necessarily the
            // nearest: only whether it is occluded must agree.
            let blocked = |r: &GpuHit| r[1] != u32::MAX;
            assert_eq!(
                blocked(&traversed[i]),
                blocked(&brute[i]),
                "{name}: shadow {query:?}"
            );
            assert_eq!(
                blocked(&resumed[i]),
                blocked(&brute[i]),
                "{name}: resumed shadow"
            );
        } else {
            assert_eq!(traversed[i], brute[i], "{name}: ray {i} {query:?}");
            assert_eq!(resumed[i], brute[i], "{name}: resumed ray {i}");
            hits += usize::from(brute[i][1] != u32::MAX);
        }
    }
    assert!(hits > 0, "{name}: the rays must hit something");
    if watertight {
        assert_eq!(hits, rays.len(), "{name}: rays slipped between triangles");
    }
    // The CPU twin in f64 finds the same hit distance (within f32 rounding) for almost
    // every ray; on a shared edge the two triangles tie, and f32 and f64 may break the
    // tie differently, so the primitive itself is not compared.
    let mut differ = 0;
    for (i, ray) in rays.iter().enumerate() {
        let cpu = closest_hit_brute_force(&geometry, ray, f64::INFINITY).map(|(t, _)| t);
        let gpu = (traversed[i][1] != u32::MAX).then(|| f64::from(f32::from_bits(traversed[i][0])));
        let same = match (cpu, gpu) {
            (Some(c), Some(g)) => (c - g).abs() <= 1e-4 * c.abs().max(1.0),
            (None, None) => true,
            _ => false,
        };
        differ += usize::from(!same);
    }
    let fraction = differ as f64 / rays.len() as f64;
    eprintln!(
        "{name}: {hits} hits of {} rays; GPU and CPU differ on {differ}",
        rays.len()
    );
    assert!(
        fraction < 0.002,
        "{name}: {differ} of {} rays differ from the CPU",
        rays.len()
    );
}

#[test]
fn gpu_traversal_equals_gpu_brute_force_and_the_cpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    check(
        &gpu,
        mixed_shapes(0x5eed),
        random_rays(4000, 11),
        "random",
        false,
    );
    let (shapes, rays) = rays_through_mesh_edges();
    check(&gpu, shapes, rays, "mesh edges", true);
}

/// Triangles and quads, convex and concave, given as polygons take the GPU's loop-free
/// inside test: rays aimed in, around and near the edges of each find the same hits by
/// traversal and by brute force, and their distances agree with the f64 CPU twin.
#[test]
fn small_polygons_agree_with_the_cpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let (shapes, rays) = small_polygons(0x9a11);
    check(&gpu, shapes, rays, "small polygons", false);
}

/// The shapes of `mixed_shapes(0x1a57)` and a blob placed five times: translated,
/// rotated, scaled, mirrored (two levels of BVH).
fn instanced_scene() -> Scene {
    let mut scene = scene_of(mixed_shapes(0x1a57));
    let place = |scale: DVec3, angle: f64, at: DVec3| {
        DMat4::from_scale_rotation_translation(scale, DQuat::from_rotation_y(angle), at)
    };
    scene.meshes = vec![gpu_render::scene::Mesh {
        material: 0,
        instances: vec![
            place(DVec3::ONE, 0.0, DVec3::new(-2.0, 0.0, 0.0)),
            place(DVec3::new(1.5, 0.5, 1.0), 0.7, DVec3::new(2.0, 1.0, 0.5)),
            place(DVec3::new(-1.0, 1.0, 1.2), 1.1, DVec3::new(0.0, -2.0, 2.0)),
            place(DVec3::new(0.8, -1.3, 0.8), 2.0, DVec3::new(0.5, 2.5, -2.5)),
            place(DVec3::splat(2.0), 0.3, DVec3::new(-1.0, 0.5, -1.0)),
        ],
        ..blob(10, 14)
    }];
    scene
}

/// Instanced meshes (a two-level BVH): the traversal, whole and suspended after every
/// step (also inside an instance's tree), finds the same hits, and their distances
/// agree with the CPU brute force over every instance's every triangle. (The WGSL
/// brute force above knows no instances.)
#[test]
fn gpu_traversal_through_instances_resumes_and_agrees_with_the_cpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let scene = instanced_scene();
    let geometry = SceneGeometry::with_method(&scene, BuildMethod::Sah);
    assert_eq!(geometry.instances.len(), 5);
    let rays = random_rays(4000, 23);
    let queries = closest_and_shadow_queries(&rays);
    let budget = gpu_render::gpu::iteration_budget_for(&gpu.adapter_info());
    let traversed = run_kernel(
        &gpu,
        &geometry,
        &scene,
        &queries,
        "traverse_rays",
        budget,
        Walk::Software,
    );
    let resumed = run_kernel(
        &gpu,
        &geometry,
        &scene,
        &queries,
        "traverse_rays",
        1,
        Walk::Software,
    );
    assert_eq!(traversed, resumed, "suspending and resuming changes a hit");
    let (mut differ, mut on_instances) = (0, 0);
    for (i, ray) in rays.iter().enumerate() {
        let cpu = closest_hit_brute_force(&geometry, ray, f64::INFINITY);
        on_instances += usize::from(cpu.is_some_and(|(_, key)| key.instance.is_some()));
        let gpu_t =
            (traversed[i][1] != u32::MAX).then(|| f64::from(f32::from_bits(traversed[i][0])));
        let same = match (cpu.map(|(t, _)| t), gpu_t) {
            (Some(c), Some(g)) => (c - g).abs() <= 1e-4 * c.abs().max(1.0),
            (None, None) => true,
            _ => false,
        };
        differ += usize::from(!same);
        // Shadow rays: occluded within 3 on both (up to the same grazing cases).
        let blocked = closest_hit_brute_force(&geometry, ray, 3.0).is_some();
        differ += usize::from(blocked != (traversed[rays.len() + i][1] != u32::MAX));
    }
    eprintln!(
        "instances: {on_instances} of {} rays hit an instance; GPU and CPU differ on {differ}",
        rays.len()
    );
    assert!(
        on_instances > 200,
        "only {on_instances} rays hit an instance"
    );
    assert!(
        (differ as f64) < 0.002 * rays.len() as f64,
        "{differ} of {} rays differ from the CPU",
        rays.len()
    );
}

/// How two traversals' answers to the same closest-hit rays compare.
#[derive(Debug, Default)]
struct Agreement {
    /// The same primitive at the same distance, bit for bit.
    identical: usize,
    /// The same primitive, the distance a few ulps apart (the driver's triangle test
    /// is not ours).
    ulps_apart: usize,
    /// Another triangle with the same corners (a deliberate exact tie): the driver
    /// keeps either of two triangles at the same distance.
    coincident: usize,
    /// Another triangle at the same distance (within the tolerance) that is not the
    /// same triangle: the ray meets the two where they touch (a shared edge), and the
    /// driver's triangle test, not ours, decides.
    edge: usize,
    /// A software hit the hardware misses: a ray that slips between triangles where
    /// they meet (the driver's triangle test need not be watertight).
    missed: usize,
    /// Anything else: a hardware hit the software walk misses, another primitive that
    /// is not a triangle at the same distance, or distances beyond the tolerance.
    different: usize,
}

/// Whether a GPU primitive key names a triangle: its kind, the bits from
/// `PRIM_KIND_SHIFT` (29), is `PRIM_TRIANGLE` (3) (`shaders/types.wgsl`).
fn is_triangle(prim: u32) -> bool {
    prim != u32::MAX && prim >> 29 == 3
}

/// Compares `hardware` with `software` ray by ray; distances agree within `1e-5`
/// relative (a few hundred f32 ulps: the two triangle tests round differently).
fn agreement(geometry: &SceneGeometry, software: &[GpuHit], hardware: &[GpuHit]) -> Agreement {
    let corners = |prim: u32| {
        let index = (prim & 0x1fff_ffff) as usize;
        geometry.triangles.get(index).map(|t| {
            let mut v = t.vertices.map(|p| p.to_array().map(f64::to_bits));
            v.sort_unstable();
            v
        })
    };
    let mut a = Agreement::default();
    for (s, h) in software.iter().zip(hardware) {
        let (ts, th) = (f32::from_bits(s[0]), f32::from_bits(h[0]));
        let close = (ts - th).abs() <= 1e-5 * ts.abs().max(1.0);
        if s == h {
            a.identical += 1;
        } else if s[1] == h[1] && close {
            a.ulps_apart += 1;
        } else if is_triangle(s[1]) && is_triangle(h[1]) && close {
            if corners(s[1]).is_some() && corners(s[1]) == corners(h[1]) {
                a.coincident += 1;
            } else {
                a.edge += 1;
            }
        } else if s[1] != u32::MAX && h[1] == u32::MAX {
            a.missed += 1;
        } else {
            a.different += 1;
        }
    }
    a
}

/// The hardware traversal (issue 30): ray queries for the triangles, the software walk
/// for the analytic shapes, against the software walk of the whole scene, ray by ray:
/// random rays through spheres, polygons, planes and triangles, rays aimed exactly at
/// a mesh's shared edges and vertices, and random rays through instanced meshes
/// (translated, rotated, scaled, mirrored). Every closest-hit ray finds the same
/// primitive, bit for bit or a few ulps apart (the driver's triangle test is not
/// ours), except where two triangles tie on an edge, which the driver settles itself
/// (docs/model.md, "Hardware traversal"); no ray aimed at an edge slips between its
/// triangles; shadow rays (any hit within 3) agree on occlusion.
#[test]
fn hardware_traversal_finds_the_hits_of_the_software_walk() {
    let Some(gpu) = crate::ray_query::ray_query_gpu() else {
        return;
    };
    let (edge_shapes, edge_rays) = rays_through_mesh_edges();
    let cases = [
        (
            "random",
            scene_of(mixed_shapes(0x5eed)),
            random_rays(4000, 11),
        ),
        ("mesh edges", scene_of(edge_shapes), edge_rays),
        ("instances", instanced_scene(), random_rays(4000, 23)),
    ];
    let budget = gpu_render::gpu::iteration_budget_for(&gpu.adapter_info());
    for (name, scene, rays) in cases {
        let geometry = SceneGeometry::with_method(&scene, BuildMethod::Sah);
        let queries = closest_and_shadow_queries(&rays);
        let run = |walk| {
            run_kernel(
                &gpu,
                &geometry,
                &scene,
                &queries,
                "traverse_rays",
                budget,
                walk,
            )
        };
        let software = run(Walk::Software);
        let hardware = run(Walk::Hardware);
        let n = rays.len();
        let closest = agreement(&geometry, &software[..n], &hardware[..n]);
        let hits = software[..n].iter().filter(|h| h[1] != u32::MAX).count();
        let blocked = |r: &GpuHit| r[1] != u32::MAX;
        let shadows_differ = software[n..]
            .iter()
            .zip(&hardware[n..])
            .filter(|(s, h)| blocked(s) != blocked(h))
            .count();
        eprintln!(
            "{name}: {n} rays, {hits} hits: {closest:?}; shadow rays differ on {shadows_differ}"
        );
        assert!(hits > n / 10, "{name}: only {hits} of {n} rays hit");
        assert_eq!(closest.different, 0, "{name}: {closest:?}");
        // A shadow ray differs only where its closest-hit twin slipped through.
        assert!(shadows_differ <= closest.missed, "{name}: shadow rays");
        if name == "mesh edges" {
            // lavapipe 25.0.7's triangle test lets a few rays aimed exactly at a
            // vertex through (measured: 18 of 8,928, at three vertices of the UV
            // sphere, each shared by six triangles); the software walk lets none
            // through (bvh_gpu's other tests). Above a third of a percent is a bug.
            assert!(
                closest.missed * 300 < n,
                "{name}: {} of {n} rays slipped between triangles",
                closest.missed
            );
        } else {
            assert_eq!(closest.missed, 0, "{name}: {closest:?}");
            // Random rays seldom meet an edge: nearly all agree bit for bit, by ulps,
            // or on the two coincident triangles of `mixed_shapes`.
            assert!(
                closest.edge * 500 < n,
                "{name}: {} of {n} rays take a neighbouring triangle",
                closest.edge
            );
        }
    }
}
