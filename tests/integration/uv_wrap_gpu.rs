//! Mesh texture coordinates and glTF's wrap modes on both backends: three quads whose
//! UVs run from -1.25 to 2.25 (so every mode repeats, mirrors or clamps the image
//! several times across them), one per mode and a fourth mixing modes per axis,
//! rendered on the GPU and on the CPU reference and compared per pixel; and the CPU's
//! `wrap_index` against each mode's definition (glTF 2.0 §5.26, OpenGL's wrap rules);
//! and metallic/roughness textures (glTF 2.0 §3.9.2) the same way.

use crate::support::compare::{Tolerance, assert_images_match};
use glam::{DMat4, DVec2, DVec3};
use gpu_render::low_level::texture::wrap_index;
use gpu_render::scene::{
    Camera, Environment, Image, Light, Material, Mesh, RenderSettings, Scene, TextureMapping,
    TextureWrap,
};

/// The shipped scenes' tolerance (tests/integration/gpu_vs_cpu.rs): f32 against f64, with 0.5% of
/// the pixels (quad edges) allowed to land on either side.
const TOLERANCE: Tolerance = Tolerance {
    absolute: 1e-3,
    relative: 5e-3,
    outlier_fraction: 0.005,
};

/// A 4 × 3 texture of distinct colours, so that each wrap mode's pattern differs.
fn texture() -> Image {
    let mut texels = Vec::new();
    for y in 0..3 {
        for x in 0..4 {
            texels.push([
                0.1 + 0.25 * x as f32,
                0.1 + 0.4 * y as f32,
                0.9 - 0.2 * (x + y) as f32 / 2.0,
                1.0,
            ]);
        }
    }
    Image {
        path: "<test texture>".into(),
        width: 4,
        height: 3,
        texels,
    }
}

fn quad(material: u32, x: f64) -> Mesh {
    Mesh {
        name: format!("quad at {x}"),
        positions: vec![
            DVec3::new(-0.9, -0.9, 0.0),
            DVec3::new(0.9, -0.9, 0.0),
            DVec3::new(0.9, 0.9, 0.0),
            DVec3::new(-0.9, 0.9, 0.0),
        ],
        normals: None,
        uvs: Some(vec![
            DVec2::new(-1.25, 2.25),
            DVec2::new(2.25, 2.25),
            DVec2::new(2.25, -1.25),
            DVec2::new(-1.25, -1.25),
        ]),
        uvs1: None,
        colors: None,
        tangents: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        material,
        instances: vec![DMat4::from_translation(DVec3::new(x, 0.0, 0.0))],
    }
}

fn scene() -> Scene {
    use TextureWrap::{ClampToEdge, MirroredRepeat, Repeat};
    let modes = [
        [Repeat, Repeat],
        [MirroredRepeat, MirroredRepeat],
        [ClampToEdge, ClampToEdge],
        [MirroredRepeat, ClampToEdge],
    ];
    let materials: Vec<Material> = modes
        .iter()
        .map(|&wrap| Material {
            albedo_texture: Some(0),
            texture_mapping: TextureMapping::Uv,
            texture_wrap: wrap,
            ..Material::lambert(DVec3::ONE)
        })
        .collect();
    Scene {
        render: RenderSettings {
            width: 160,
            height: 48,
            samples_per_pixel: 2,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.0, 0.0, 7.5),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 18.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        material_names: modes.iter().map(|m| format!("{m:?}")).collect(),
        materials,
        lights: vec![Light::Directional {
            direction: DVec3::new(0.0, 0.0, -1.0),
            irradiance: DVec3::splat(3.0),
        }],
        shapes: vec![],
        meshes: (0..4).map(|i| quad(i, -3.0 + 2.0 * f64::from(i))).collect(),
        images: vec![texture()],
    }
}

#[test]
fn uv_textures_wrap_alike_on_both_backends() {
    let scene = scene();
    let cpu = gpu_render::cpu::render(&scene, None);
    // The quads show several distinct colours each: the texture is really sampled.
    let mut colours: Vec<[u32; 3]> = cpu
        .image
        .pixels
        .iter()
        .map(|p| [0, 1, 2].map(|c| (p[c] * 64.0) as u32))
        .collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(
        colours.len() > 12,
        "only {} colours in the image",
        colours.len()
    );
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match("uv-wrap", &cpu.image, &gpu_image.image, TOLERANCE);
}

/// Texture coordinates offset by 1e5 and by 1e7 repeats (an even number, so that
/// repeating and mirroring modes show the pattern they show at the origin, clamping
/// the edge texel): the GPU keeps the fraction that `f32` would lose at that size
/// (`gpu::upload::uvs_near_origin`) and renders what the CPU reference renders in
/// `f64`.
#[test]
fn far_texture_coordinates_keep_their_precision_on_the_gpu() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let near = scene();
    for offset in [1e5, 1e7] {
        let mut far = near.clone();
        for mesh in &mut far.meshes {
            for uv in mesh.uvs.iter_mut().flatten() {
                *uv += DVec2::splat(offset);
            }
        }
        let cpu = gpu_render::cpu::render(&far, None);
        let gpu_image = renderer
            .render(&gpu.device, &gpu.queue, &far, None)
            .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
        assert_images_match(
            &format!("uv-far-{offset:e}"),
            &cpu.image,
            &gpu_image.image,
            TOLERANCE,
        );
    }
}

/// The UV scene with metal/roughness materials whose roughness and metalness come from
/// the texture's green and blue channels (glTF's `metallicRoughnessTexture`), under a
/// point light that makes the highlights depend on the roughness.
fn metallic_roughness_scene(texture: Option<u32>) -> Scene {
    let mut scene = scene();
    for material in &mut scene.materials {
        let wrap = material.texture_wrap;
        *material = Material {
            kind: gpu_render::scene::MaterialKind::Pbr,
            diffuse: DVec3::new(0.8, 0.6, 0.4),
            metallic: 1.0,
            roughness: 1.0,
            texture_mapping: TextureMapping::Uv,
            metallic_roughness_texture: texture,
            metallic_roughness_wrap: wrap,
            ..Material::blank(gpu_render::scene::MaterialKind::Pbr)
        };
    }
    scene.lights.push(Light::Point {
        position: DVec3::new(0.5, 1.0, 3.0),
        intensity: DVec3::splat(20.0),
    });
    scene
}

#[test]
fn metallic_roughness_textures_shade_alike_on_both_backends() {
    let scene = metallic_roughness_scene(Some(0));
    let cpu = gpu_render::cpu::render(&scene, None);
    let untextured = gpu_render::cpu::render(&metallic_roughness_scene(None), None);
    let changed = cpu
        .image
        .pixels
        .iter()
        .zip(&untextured.image.pixels)
        .filter(|(a, b)| (0..3).any(|c| (a[c] - b[c]).abs() > 1e-3))
        .count();
    assert!(
        changed * 4 > cpu.image.pixels.len(),
        "the texture changes only {changed} pixels"
    );

    // Green scales the roughness and blue the metalness: a constant texel of
    // (_, 0.5, 0.25) is the untextured material with those factors.
    let mut constant = metallic_roughness_scene(Some(0));
    constant.images[0].texels = vec![[0.9, 0.5, 0.25, 1.0]; 12];
    let mut factors = metallic_roughness_scene(None);
    for material in &mut factors.materials {
        material.roughness = 0.5;
        material.metallic = 0.25;
    }
    let a = gpu_render::cpu::render(&constant, None);
    let b = gpu_render::cpu::render(&factors, None);
    for (p, q) in a.image.pixels.iter().zip(&b.image.pixels) {
        for c in 0..3 {
            assert!(
                (p[c] - q[c]).abs() <= 1e-6 * q[c].abs().max(1.0),
                "{p:?} vs {q:?}"
            );
        }
    }

    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match(
        "metallic-roughness",
        &cpu.image,
        &gpu_image.image,
        TOLERANCE,
    );

    // The path integrator's twin reads the textured material at its shadow rays too.
    let mut path = metallic_roughness_scene(Some(0));
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.max_depth = 3;
    let cpu_path = gpu_render::cpu::render(&path, None);
    let gpu_path = renderer
        .render(&gpu.device, &gpu.queue, &path, None)
        .unwrap_or_else(|e| panic!("GPU path render failed: {e}"));
    assert_images_match(
        "metallic-roughness-path",
        &cpu_path.image,
        &gpu_path.image,
        TOLERANCE,
    );
}

#[test]
fn wrap_index_follows_each_modes_definition() {
    let n = 4;
    for i in -20i32..20 {
        let x = f64::from(i);
        let repeat = i.rem_euclid(n as i32) as u32;
        assert_eq!(wrap_index(x, n, TextureWrap::Repeat), repeat, "repeat {i}");
        // Mirrored: 0 1 2 3 3 2 1 0 0 1 ... (period 2n, the second half reversed).
        let j = i.rem_euclid(2 * n as i32) as u32;
        let mirrored = if j < n { j } else { 2 * n - 1 - j };
        assert_eq!(
            wrap_index(x, n, TextureWrap::MirroredRepeat),
            mirrored,
            "mirrored {i}"
        );
        let clamped = i.clamp(0, n as i32 - 1) as u32;
        assert_eq!(
            wrap_index(x, n, TextureWrap::ClampToEdge),
            clamped,
            "clamp {i}"
        );
    }
    // Huge coordinates stay in range instead of saturating an integer conversion.
    for x in [1e30, -1e30, f64::MAX, f64::MIN] {
        for mode in [
            TextureWrap::Repeat,
            TextureWrap::MirroredRepeat,
            TextureWrap::ClampToEdge,
        ] {
            assert!(wrap_index(x, n, mode) < n, "{mode:?} at {x}");
        }
    }
}
