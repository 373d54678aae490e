//! Instancing (issue 9): a mesh placed more than once is stored once and traced through
//! its placements' transforms (src/accel/instance.rs).
//!
//! - The CPU renders an instanced scene (translated, rotated, non-uniformly scaled and
//!   mirrored placements of one smooth, UV-mapped mesh, two materials) like the same
//!   scene flattened by hand into world-space meshes. Tolerance: a channel passes when
//!   `|Δ| <= 1e-5 + 1e-5·|flat|`, with 0.1% of the pixels allowed to fail: both are f64,
//!   but the instanced triangle test runs in object space, so a sample exactly on a
//!   silhouette or shadow edge may fall on the other side.
//! - The GPU renders it like the CPU within the tolerance of `tests/integration/gpu_vs_cpu.rs`, and
//!   like its own flattened render.
//! - The traversal equals the brute force over every instance's every triangle.
//! - Path tracing: emissive meshes placed twice are flattened (and render as before);
//!   geometry built from parts instances them and the CPU's lights hold every copy.
//! - Memory: the GPU scene records of 100 placements are those of one plus about 100
//!   instance records.

use crate::support::compare::{Tolerance, assert_images_match};
use crate::support::geometry::{SplitMix, blob};
use glam::{DMat3, DMat4, DVec3};
use gpu_render::low_level::accel::SceneGeometry;
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::traverse::{
    TraversalCounts, closest_hit_brute_force, closest_hit_counted, occluded,
};
use gpu_render::low_level::gpu::upload::SceneRecords;
use gpu_render::scene::import::ModelPlacement;
use gpu_render::scene::{
    Camera, Environment, Integrator, Light, Material, MaterialKind, Mesh, RenderSettings, Scene,
    Shape,
};

/// CPU instanced against CPU flattened (see the module comment).
const FLAT_TOLERANCE: Tolerance = Tolerance {
    absolute: 1e-5,
    relative: 1e-5,
    outlier_fraction: 0.001,
};

/// GPU against CPU: the tolerance of `tests/integration/gpu_vs_cpu.rs`.
const GPU_TOLERANCE: Tolerance = crate::support::twins::TWIN_TOLERANCE;

/// The placements: translated, rotated, non-uniformly scaled, mirrored (with a
/// rotation, so that the mirror shows), each with its material.
fn placements() -> Vec<(DMat4, u32)> {
    let trs = ModelPlacement::trs;
    vec![
        (trs(DVec3::new(-2.2, 0.0, 0.0), DVec3::ZERO, DVec3::ONE), 1),
        (
            trs(
                DVec3::new(0.0, 0.2, 0.0),
                DVec3::new(20.0, 40.0, 0.0),
                DVec3::new(1.3, 0.6, 0.9),
            ),
            2,
        ),
        (
            trs(
                DVec3::new(2.2, 0.0, 0.0),
                DVec3::new(0.0, 30.0, 0.0),
                DVec3::new(-1.0, 1.0, 1.0),
            ),
            1,
        ),
        (
            trs(
                DVec3::new(0.0, 0.0, -2.5),
                DVec3::new(0.0, 0.0, 15.0),
                DVec3::new(0.7, 1.4, -0.8),
            ),
            3,
        ),
    ]
}

fn materials() -> Vec<Material> {
    let phong = Material {
        specular: DVec3::splat(0.4),
        shininess: 40.0,
        ..Material::lambert(DVec3::new(0.2, 0.5, 0.8))
    };
    let phong = Material {
        kind: MaterialKind::BlinnPhong,
        ..phong
    };
    let mirror = Material {
        reflectance: DVec3::splat(0.8),
        ..Material::blank(MaterialKind::Mirror)
    };
    vec![
        Material::lambert(DVec3::splat(0.6)),
        Material::lambert(DVec3::new(0.8, 0.3, 0.2)),
        phong,
        mirror,
    ]
}

fn base_scene(width: u32, meshes: Vec<Mesh>) -> Scene {
    let materials = materials();
    Scene {
        render: RenderSettings {
            width,
            height: width * 3 / 4,
            samples_per_pixel: 1,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.5, 2.5, 7.5),
            look_at: DVec3::new(0.0, 0.0, -0.5),
            up: DVec3::Y,
            fov_y_degrees: 45.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment {
            background: DVec3::new(0.1, 0.12, 0.15),
            ambient: DVec3::splat(0.05),
            map: None,
        },
        material_names: (0..materials.len()).map(|i| format!("m{i}")).collect(),
        materials,
        lights: vec![
            Light::Point {
                position: DVec3::new(-3.0, 5.0, 4.0),
                intensity: DVec3::splat(30.0),
            },
            Light::Directional {
                direction: DVec3::new(0.3, -1.0, -0.4).normalize(),
                irradiance: DVec3::splat(0.6),
            },
        ],
        shapes: vec![
            Shape::Plane {
                normal: DVec3::Y,
                offset: -1.2,
                material: 0,
            },
            Shape::Sphere {
                center: DVec3::new(1.2, -0.7, 1.5),
                radius: 0.5,
                material: 3,
            },
        ],
        meshes,
        images: vec![],
    }
}

/// The scene with the mesh placed as [`placements`] says: one scene mesh per
/// material, sharing the geometry (as two `[[objects]]` of one file would).
pub(crate) fn instanced_scene(width: u32, mesh: &Mesh) -> Scene {
    let mut meshes: Vec<Mesh> = Vec::new();
    for (transform, material) in placements() {
        match meshes.iter_mut().find(|m| m.material == material) {
            Some(m) => m.instances.push(transform),
            None => meshes.push(Mesh {
                material,
                instances: vec![transform],
                ..mesh.clone()
            }),
        }
    }
    base_scene(width, meshes)
}

/// The same scene flattened by hand: every placement a mesh of its own in world space
/// (positions moved, normals through the inverse transpose, winding reversed where the
/// transform mirrors), placed once at the identity.
fn flattened_scene(width: u32, mesh: &Mesh) -> Scene {
    let meshes = placements()
        .into_iter()
        .map(|(transform, material)| {
            let linear = DMat3::from_mat4(transform);
            let normal_matrix = linear.inverse().transpose();
            let mirrored = linear.determinant() < 0.0;
            Mesh {
                positions: mesh
                    .positions
                    .iter()
                    .map(|p| transform.transform_point3(*p))
                    .collect(),
                normals: mesh
                    .normals
                    .as_ref()
                    .map(|n| n.iter().map(|n| (normal_matrix * *n).normalize()).collect()),
                triangles: mesh
                    .triangles
                    .iter()
                    .map(|&[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] })
                    .collect(),
                material,
                instances: vec![DMat4::IDENTITY],
                ..mesh.clone()
            }
        })
        .collect();
    base_scene(width, meshes)
}

#[test]
fn the_instanced_scene_is_stored_once() {
    let mesh = blob(12, 16);
    let geometry = SceneGeometry::new(&instanced_scene(64, &mesh));
    assert_eq!(geometry.instanced_meshes.len(), 1);
    assert_eq!(geometry.instances.len(), placements().len());
    assert!(geometry.triangles.is_empty());
    let stored = geometry.instanced_meshes[0].triangles.len();
    assert_eq!(stored, mesh.triangles.len());
    assert_eq!(geometry.instanced_triangle_count(), 4 * stored);
    let mirrored: Vec<bool> = geometry.instances.iter().map(|i| i.mirrored).collect();
    // Grouped by scene mesh: material 1's two placements first.
    assert_eq!(mirrored, [false, true, false, true]);
    let flat = SceneGeometry::new(&flattened_scene(64, &mesh));
    assert!(flat.instances.is_empty());
    assert_eq!(flat.triangles.len(), 4 * stored);
}

#[test]
fn cpu_renders_the_instanced_scene_like_the_flattened_one() {
    let mesh = blob(24, 32);
    let instanced = gpu_render::cpu::render(&instanced_scene(160, &mesh), None);
    let flat = gpu_render::cpu::render(&flattened_scene(160, &mesh), None);
    let comparison = assert_images_match(
        "instancing-cpu-vs-flattened",
        &flat.image,
        &instanced.image,
        FLAT_TOLERANCE,
    );
    eprintln!(
        "instanced vs flattened (CPU): {} of {} pixels outside, max |Δ| {:.2e}",
        comparison.outliers, comparison.pixels, comparison.max_abs_error
    );
    assert_eq!(instanced.stats.rays_traced, flat.stats.rays_traced);
}

#[test]
fn gpu_renders_the_instanced_scene_like_the_cpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let mesh = blob(24, 32);
    let scene = instanced_scene(160, &mesh);
    let cpu = gpu_render::cpu::render(&scene, None);
    let rendered = renderer
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    let comparison = assert_images_match(
        "instancing-gpu-vs-cpu",
        &cpu.image,
        &rendered.image,
        GPU_TOLERANCE,
    );
    eprintln!(
        "instanced GPU vs CPU: {} of {} pixels outside, max |Δ| {:.2e}, RMSE {:.2e}",
        comparison.outliers, comparison.pixels, comparison.max_abs_error, comparison.rmse
    );
    let flat = renderer
        .render(&gpu.device, &gpu.queue, &flattened_scene(160, &mesh), None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match(
        "instancing-gpu-vs-gpu-flattened",
        &flat.image,
        &rendered.image,
        GPU_TOLERANCE,
    );
}

/// Random rays from around the scene towards it.
fn rays(count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix(seed);
    (0..count)
        .map(|_| {
            let origin = rng.point(6.0);
            let target = rng.point(2.5);
            Ray {
                origin,
                direction: (target - origin).normalize(),
            }
        })
        .collect()
}

#[test]
fn traversal_equals_the_brute_force_over_every_instance() {
    let mesh = blob(10, 14);
    let mut scene = instanced_scene(64, &mesh);
    // Many overlapping placements too, so that instances tie and nest in the tree.
    scene.meshes[0]
        .instances
        .extend((0..12).map(|i| DMat4::from_rotation_y(0.5 * i as f64)));
    let geometry = SceneGeometry::new(&scene);
    assert!(geometry.instances.len() > 12);
    let mut hits = 0;
    for ray in rays(3000, 7) {
        let mut counts = TraversalCounts::default();
        let expected = closest_hit_brute_force(&geometry, &ray, f64::INFINITY);
        let actual = closest_hit_counted(&geometry, &ray, f64::INFINITY, &mut counts);
        assert_eq!(actual, expected, "{ray:?}");
        hits += usize::from(expected.is_some_and(|(_, key)| key.instance.is_some()));
        for limit in [0.5, 3.0, 8.0] {
            let blocked = closest_hit_brute_force(&geometry, &ray, limit).is_some();
            assert_eq!(
                occluded(&geometry, &ray, limit),
                blocked,
                "{ray:?} to {limit}"
            );
        }
    }
    assert!(hits > 300, "only {hits} rays hit an instance");
}

#[test]
fn hits_on_mirrored_and_scaled_instances_face_out() {
    let mesh = blob(16, 24);
    let scene = instanced_scene(64, &mesh);
    let geometry = SceneGeometry::new(&scene);
    let mut checked = [0usize; 4];
    for ray in rays(4000, 3) {
        let Some(hit) =
            gpu_render::low_level::cpu::traverse::intersect_scene(&geometry, &ray, f64::INFINITY)
        else {
            continue;
        };
        let Some(i) = hit.instance else { continue };
        let instance = &geometry.instances[i as usize];
        // The blob is star-shaped about its centre: its winding normal points away
        // from it, in world space too, mirrored or not.
        let centre = instance.object_to_world.translation;
        assert!(hit.normal.dot(hit.position - centre) > 0.0, "{ray:?}");
        assert!(hit.shading_normal.dot(hit.normal) > 0.0);
        assert_eq!(hit.material, instance.material);
        checked[i as usize] += 1;
    }
    assert!(checked.iter().all(|&n| n > 20), "{checked:?}");
}

#[test]
fn path_tracing_samples_emissive_instances() {
    // Two emissive placements of one small mesh above a Lambert floor: instanced and
    // flattened give the same converged image (same sampler, same emitters).
    let mut mesh = blob(6, 8);
    mesh.normals = None;
    mesh.uvs = None;
    let light = Material {
        emission: DVec3::splat(4.0),
        ..Material::blank(MaterialKind::Emissive)
    };
    let make = |meshes: Vec<Mesh>| {
        let mut scene = base_scene(24, meshes);
        scene.materials.push(light);
        scene.material_names.push("light".into());
        scene.lights.clear();
        scene.shapes.truncate(1);
        scene.render.integrator = Integrator::Path;
        scene.render.samples_per_pixel = 16;
        scene.render.max_depth = 3;
        scene.render.stack_size = RenderSettings::sufficient_stack_size(3);
        scene
    };
    let emitter = 4;
    let transforms = [
        DMat4::from_scale_rotation_translation(
            DVec3::new(0.5, 0.2, 0.5),
            glam::DQuat::IDENTITY,
            DVec3::new(-1.0, 1.5, 0.0),
        ),
        DMat4::from_scale_rotation_translation(
            DVec3::new(-0.4, 0.3, 0.4),
            glam::DQuat::IDENTITY,
            DVec3::new(1.2, 1.0, -1.0),
        ),
    ];
    let instanced = make(vec![Mesh {
        material: emitter,
        instances: transforms.to_vec(),
        ..mesh.clone()
    }]);
    // Emissive meshes placed twice are instanced too, and the lights hold every
    // placement's triangles.
    let parts = SceneGeometry::new(&instanced);
    assert_eq!(parts.instances.len(), 2);
    assert!(parts.triangles.is_empty(), "nothing flattened");
    let lights = gpu_render::low_level::accel::AreaLights::new(
        &parts,
        &instanced.materials,
        &instanced.images,
    );
    assert_eq!(lights.entries().len(), 2 * mesh.triangles.len());
    let flat = make(
        transforms
            .iter()
            .map(|t| {
                let mirrored = DMat3::from_mat4(*t).determinant() < 0.0;
                Mesh {
                    positions: mesh
                        .positions
                        .iter()
                        .map(|p| t.transform_point3(*p))
                        .collect(),
                    triangles: mesh
                        .triangles
                        .iter()
                        .map(|&[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] })
                        .collect(),
                    material: emitter,
                    instances: vec![DMat4::IDENTITY],
                    ..mesh.clone()
                }
            })
            .collect(),
    );
    let a = gpu_render::cpu::render(&instanced, None).image;
    let b = gpu_render::cpu::render(&flat, None).image;
    let lit = a.pixels.iter().filter(|p| p[1] > 0.0 && p[1] < 3.9).count();
    assert!(lit > a.pixels.len() / 4, "the floor must be lit: {lit}");
    // A path whose sample lands exactly on an edge may branch differently: 2%.
    let tolerance = Tolerance {
        outlier_fraction: 0.02,
        ..FLAT_TOLERANCE
    };
    assert_images_match("instancing-path-emitters", &b, &a, tolerance);

    // The GPU samples the instances' triangles as the CPU does: same emitter records
    // (named by the GPU's triangle and instance record indices), same images.
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, &instanced, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match(
        "instancing-path-emitters-gpu",
        &a,
        &gpu_image.image,
        // A path whose sample lands exactly on an edge may branch differently: 2%.
        Tolerance {
            outlier_fraction: 0.02,
            ..GPU_TOLERANCE
        },
    );
}

/// Bytes of every record list the GPU receives for `scene`.
fn record_bytes(scene: &Scene) -> usize {
    let records = SceneRecords::new(scene, &SceneGeometry::new(scene)).padded();
    std::mem::size_of_val(records.spheres.as_slice())
        + std::mem::size_of_val(records.planes.as_slice())
        + std::mem::size_of_val(records.polygons.as_slice())
        + std::mem::size_of_val(records.polygon_points.as_slice())
        + std::mem::size_of_val(records.triangles.as_slice())
        + std::mem::size_of_val(records.triangle_attributes.as_slice())
        + std::mem::size_of_val(records.materials.as_slice())
        + std::mem::size_of_val(records.lights.as_slice())
        + std::mem::size_of_val(records.bvh_nodes.as_slice())
        + std::mem::size_of_val(records.bvh_prims.as_slice())
}

#[test]
fn a_hundred_copies_cost_one_copy_and_a_hundred_instance_records() {
    let mesh = blob(64, 96);
    let grid = |copies: usize| -> Vec<DMat4> {
        (0..copies)
            .map(|i| {
                let (x, z) = ((i % 10) as f64, (i / 10) as f64);
                DMat4::from_translation(DVec3::new(2.0 * x, 0.0, -2.0 * z))
            })
            .collect()
    };
    let scene = |copies: usize| {
        base_scene(
            64,
            vec![Mesh {
                instances: grid(copies),
                ..mesh.clone()
            }],
        )
    };
    let one = record_bytes(&scene(1));
    let hundred = record_bytes(&scene(100));
    // Per instance: its four node records, its reference, and its share of the scene
    // tree's nodes (fewer than two nodes per primitive).
    let per_instance = 4 * 32 + 4 + 2 * 32;
    eprintln!(
        "{} triangles: 1 copy {one} bytes, 100 copies {hundred} bytes ({:.3}x)",
        mesh.triangles.len(),
        hundred as f64 / one as f64
    );
    assert!(
        hundred <= one + 100 * per_instance + one / 50,
        "100 copies take {hundred} bytes, one {one}"
    );
    assert!((hundred as f64) < 1.1 * one as f64);
    // On the device, when there is one: the uploaded storage buffers agree.
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let uploaded = |copies: usize| {
        renderer
            .upload(&gpu.device, &gpu.queue, &scene(copies))
            .unwrap_or_else(|e| panic!("upload failed: {e}"))
            .scene_bytes() as usize
    };
    let (one, hundred) = (uploaded(1), uploaded(100));
    assert!(
        hundred <= one + 100 * per_instance + one / 50,
        "on the device 100 copies take {hundred} bytes, one {one}"
    );
}

/// A mesh whose material emits is instanced like any other: its copies cost the GPU
/// scene bytes of one placement and an instance record each, plus, for the path
/// integrator, one emitter record (96 bytes) per triangle and copy (next-event
/// estimation samples each placement's triangles in world space). Prints the figures
/// that docs/models.md quotes.
#[test]
fn emissive_copies_are_instanced_with_an_emitter_record_per_triangle_and_copy() {
    let mesh = blob(64, 96);
    let lamp = Material {
        emission: DVec3::splat(2.0),
        ..Material::lambert(DVec3::splat(0.5))
    };
    let scene = |copies: usize| {
        let mut s = base_scene(
            64,
            vec![Mesh {
                instances: (0..copies)
                    .map(|i| DMat4::from_translation(DVec3::new(2.0 * i as f64, 0.0, 0.0)))
                    .collect(),
                material: 0,
                ..mesh.clone()
            }],
        );
        s.materials[0] = lamp;
        s
    };
    let (one, ten) = (record_bytes(&scene(1)), record_bytes(&scene(10)));
    let triangles = mesh.triangles.len();
    let geometry = SceneGeometry::new(&scene(10));
    let emitters = gpu_render::low_level::gpu::area_lights::emitter_records(
        &geometry,
        &gpu_render::low_level::gpu::upload::InstanceLayout::new(&geometry),
        &scene(10).materials,
        &[],
    );
    eprintln!(
        "{triangles} emissive triangles: 1 copy {one} bytes, 10 copies {ten} bytes ({:.3}x), \
         {} emitter records ({} bytes)",
        ten as f64 / one as f64,
        emitters.len(),
        std::mem::size_of_val(emitters.as_slice())
    );
    assert_eq!(SceneGeometry::new(&scene(10)).instances.len(), 10);
    assert!(
        (ten as f64) < 1.1 * one as f64,
        "10 copies take {ten} bytes, one {one}"
    );
    assert_eq!(emitters.len(), 10 * triangles);
}
