//! Mesh texture coordinates and glTF's wrap modes on both backends: three quads whose
//! UVs run from -1.25 to 2.25 (so every mode repeats, mirrors or clamps the image
//! several times across them), one per mode and a fourth mixing modes per axis,
//! rendered on the GPU and on the CPU reference and compared per pixel; and the CPU's
//! `wrap_index` against each mode's definition (glTF 2.0 §5.26, OpenGL's wrap rules).

mod common;

use common::compare::{Tolerance, assert_images_match};
use glam::{DMat4, DVec2, DVec3};
use gpu_render::cpu::texture::wrap_index;
use gpu_render::scene::{
    Camera, Environment, Image, Light, Material, Mesh, RenderSettings, Scene, TextureMapping,
    TextureWrap,
};

/// The shipped scenes' tolerance (tests/gpu_vs_cpu.rs): f32 against f64, with 0.5% of
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
    let Some(gpu) = common::gpu::headless_gpu() else {
        return;
    };
    let renderer = common::gpu::renderer(&gpu);
    let gpu_image = renderer
        .render(&gpu.device, &gpu.queue, &scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"));
    assert_images_match("uv-wrap", &cpu.image, &gpu_image.image, TOLERANCE);
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
