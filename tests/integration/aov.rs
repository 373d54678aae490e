//! The auxiliary passes (`src/cpu/aov.rs`, `shaders/aov.wgsl`): first-hit albedo,
//! shading normal and depth, averaged over each pixel's samples.
//!
//! - Closed forms on the CPU reference: a Lambert plane facing the camera gives its
//!   albedo and its normal in every pixel, and the depth of the pixel centre's ray,
//!   `d · |(ndc_x · aspect · tan, ndc_y · tan, 1)|` for a camera at distance `d`; a
//!   planar-mapped texture of 2x2-texel blocks gives the block's texel wherever the
//!   bilinear lookup stays inside a block.
//! - The GPU's passes equal the CPU's per pixel (f32 against f64, the twin tolerance),
//!   on those planes and on shipped scenes with mirrors, glass, meshes and the path
//!   integrator; a progressive film's passes equal a one-shot render's bit for bit;
//!   recording them leaves the image bit-identical.

use glam::{DVec2, DVec3};
use gpu_render::gpu::{HeadlessGpu, RendererOptions};
use gpu_render::low_level::denoise::GuidePasses;
use gpu_render::scene::{
    Camera, Environment, Image, Light, Material, RenderOverrides, RenderSettings, Scene, Shape,
    TextureMapping,
};

/// Per-channel tolerance of GPU against CPU: f32 sums against f64 (as the twin tests).
const ABSOLUTE: f32 = 1e-3;
const RELATIVE: f32 = 5e-3;
/// Pixels allowed outside it: samples grazing an edge land on either side.
const OUTLIERS: f64 = 0.005;

/// Camera distance from the plane z = 0, and its vertical field of view.
const DISTANCE: f64 = 4.0;
const FOV_Y_DEGREES: f64 = 50.0;

/// A plane z = 0 of `material` filling the view of a camera on the z axis.
fn plane_scene(material: Material, images: Vec<Image>, samples: u32) -> Scene {
    Scene {
        render: RenderSettings {
            width: 40,
            height: 30,
            samples_per_pixel: samples,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.0, 0.0, DISTANCE),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: FOV_Y_DEGREES,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        material_names: vec!["plane".into()],
        materials: vec![material],
        lights: vec![Light::Directional {
            direction: DVec3::new(0.0, 0.0, -1.0),
            irradiance: DVec3::ONE,
        }],
        shapes: vec![Shape::Plane {
            normal: DVec3::Z,
            offset: 0.0,
            material: 0,
        }],
        meshes: vec![],
        images,
    }
}

/// The distance along the ray through the centre of pixel (x, y) to the plane z = 0.
fn centre_ray_depth(scene: &Scene, x: u32, y: u32) -> f64 {
    let (w, h) = (
        f64::from(scene.render.width),
        f64::from(scene.render.height),
    );
    let tan = (FOV_Y_DEGREES.to_radians() / 2.0).tan();
    let ndc_x = 2.0 * (f64::from(x) + 0.5) / w - 1.0;
    let ndc_y = 1.0 - 2.0 * (f64::from(y) + 0.5) / h;
    DISTANCE * DVec3::new(ndc_x * (w / h) * tan, ndc_y * tan, 1.0).length()
}

/// Asserts that every pixel of `passes` has albedo `albedo`, normal +z and, with
/// `depth_at`, that depth.
fn assert_plane_passes(
    label: &str,
    passes: &GuidePasses,
    albedo: [f32; 3],
    depth_at: Option<&dyn Fn(u32, u32) -> f64>,
) {
    for (i, (a, n)) in passes.albedo.iter().zip(&passes.normal).enumerate() {
        for c in 0..3 {
            assert!(
                (a[c] - albedo[c]).abs() < 1e-6,
                "{label} pixel {i}: albedo {a:?}"
            );
        }
        assert!(
            (n[0].abs() + n[1].abs() + (n[2] - 1.0).abs()) < 1e-6,
            "{label} pixel {i}: normal {n:?}"
        );
        if let Some(depth_at) = depth_at {
            let (x, y) = (i as u32 % passes.width, i as u32 / passes.width);
            let expected = depth_at(x, y);
            assert!(
                (f64::from(passes.depth[i]) - expected).abs() < 1e-5 * expected,
                "{label} pixel ({x}, {y}): depth {} for {expected}",
                passes.depth[i]
            );
        }
    }
}

/// Asserts that two sets of passes agree per pixel within the twin tolerance; returns
/// the largest difference.
fn assert_passes_match(label: &str, cpu: &GuidePasses, gpu: &GuidePasses) -> f32 {
    assert_eq!((cpu.width, cpu.height), (gpu.width, gpu.height), "{label}");
    let close = |a: f32, b: f32| (a - b).abs() <= ABSOLUTE + RELATIVE * a.abs();
    let mut outliers = 0;
    let mut largest = 0.0f32;
    for i in 0..cpu.depth.len() {
        let pairs = (0..3)
            .map(|c| (cpu.albedo[i][c], gpu.albedo[i][c]))
            .chain((0..3).map(|c| (cpu.normal[i][c], gpu.normal[i][c])))
            .chain([(cpu.depth[i], gpu.depth[i])]);
        let mut ok = true;
        for (a, b) in pairs {
            assert!(b.is_finite(), "{label} pixel {i}: GPU value {b}");
            ok &= close(a, b);
            largest = largest.max((a - b).abs());
        }
        if !ok {
            outliers += 1;
        }
    }
    let allowed = (OUTLIERS * cpu.depth.len() as f64).floor() as usize;
    eprintln!(
        "{label}: {outliers} of {} pixels outside tolerance, largest difference {largest:.2e}",
        cpu.depth.len()
    );
    assert!(
        outliers <= allowed,
        "{label}: {outliers} pixels differ (allowed {allowed})"
    );
    largest
}

/// The GPU's passes of `scene`, rendered by a renderer with AOVs.
fn gpu_passes(gpu: &HeadlessGpu, scene: &Scene) -> GuidePasses {
    let renderer = crate::support::gpu::renderer_with(
        gpu,
        RendererOptions {
            aov: true,
            ..RendererOptions::default()
        },
    );
    renderer
        .render(&gpu.device, &gpu.queue, scene, None)
        .unwrap_or_else(|e| panic!("GPU render failed: {e}"))
        .aov
        .expect("asked for")
}

#[test]
fn a_lambert_planes_passes_are_its_albedo_its_normal_and_the_ray_distance() {
    let albedo = DVec3::new(0.2, 0.5, 0.8);
    // One sample: the pixel centre's ray, whose depth has a closed form.
    let scene = plane_scene(Material::lambert(albedo), vec![], 1);
    let cpu = gpu_render::low_level::cpu::aov::render_aovs(&scene);
    let expected = albedo.as_vec3().to_array();
    let depth = |x, y| centre_ray_depth(&scene, x, y);
    assert_plane_passes("CPU", &cpu, expected, Some(&depth));
    // Several jittered samples: albedo and normal do not move.
    let jittered = plane_scene(Material::lambert(albedo), vec![], 5);
    assert_plane_passes(
        "CPU 5 spp",
        &gpu_render::low_level::cpu::aov::render_aovs(&jittered),
        expected,
        None,
    );
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let gpu_aov = gpu_passes(&gpu, &scene);
    assert_plane_passes("GPU", &gpu_aov, expected, None);
    assert_passes_match("plane", &cpu, &gpu_aov);
    assert_passes_match(
        "plane 5 spp",
        &gpu_render::low_level::cpu::aov::render_aovs(&jittered),
        &gpu_passes(&gpu, &jittered),
    );
}

/// An 8x8 texture of 2x2-texel blocks, each block its own colour.
fn block_texture() -> Image {
    let colour = |bx: u32, by: u32| [0.1 + 0.25 * bx as f32, 0.9 - 0.2 * by as f32, 0.3, 1.0];
    let texels = (0..64u32).map(|i| colour(i % 8 / 2, i / 8 / 2)).collect();
    Image {
        path: "<block texture>".into(),
        width: 8,
        height: 8,
        texels,
    }
}

#[test]
fn a_textured_albedo_pass_is_the_texel() {
    let texture = block_texture();
    let diffuse = DVec3::new(1.0, 0.8, 0.5);
    let material = Material {
        albedo_texture: Some(0),
        texture_mapping: TextureMapping::Planar,
        texture_scale: 1.5,
        ..Material::lambert(diffuse)
    };
    let mut scene = plane_scene(material, vec![texture.clone()], 1);
    // Level 0: the blocks are 2 × 2 texels, so a bilinear lookup inside one is its
    // texel; the far pixels' filtered lookups would mix blocks at level 1 (whose
    // texel centres are the blocks' centres).
    scene.render.texture_filtering = gpu_render::scene::TextureFiltering::None;
    let cpu = gpu_render::low_level::cpu::aov::render_aovs(&scene);
    // Pixels whose lookup lies inside a block (between its four texel centres, with a
    // margin) show that block's texel times the diffuse factor.
    let mut checked = 0;
    let mut colours = Vec::new();
    for y in 0..scene.render.height {
        for x in 0..scene.render.width {
            let t = centre_ray_depth(&scene, x, y);
            let direction = {
                let tan = (FOV_Y_DEGREES.to_radians() / 2.0).tan();
                let (w, h) = (
                    f64::from(scene.render.width),
                    f64::from(scene.render.height),
                );
                let ndc_x = 2.0 * (f64::from(x) + 0.5) / w - 1.0;
                let ndc_y = 1.0 - 2.0 * (f64::from(y) + 0.5) / h;
                DVec3::new(ndc_x * (w / h) * tan, ndc_y * tan, -1.0).normalize()
            };
            let point = scene.camera.eye + direction * t;
            let (u, v) = gpu_render::low_level::texture::texture_coordinates(
                &scene.materials[0],
                &scene.materials[0].texture_transform,
                point,
                DVec3::Z,
                [DVec2::ZERO; 2],
            );
            let (tx, ty) = (u * 8.0 - 0.5, v * 8.0 - 0.5);
            let inside = |p: f64| (0.05..=0.95).contains(&p.rem_euclid(2.0));
            if !(inside(tx) && inside(ty)) {
                continue;
            }
            let (bx, by) = (
                (tx / 2.0).floor().rem_euclid(4.0) as u32,
                (ty / 2.0).floor().rem_euclid(4.0) as u32,
            );
            let texel = texture.texels[(by * 2 * 8 + bx * 2) as usize];
            let i = (y * scene.render.width + x) as usize;
            for c in 0..3 {
                let expected = texel[c] * diffuse[c] as f32;
                assert!(
                    (cpu.albedo[i][c] - expected).abs() < 1e-5,
                    "pixel ({x}, {y}): {:?} for texel {texel:?}",
                    cpu.albedo[i]
                );
            }
            colours.push((bx, by));
            checked += 1;
        }
    }
    colours.sort_unstable();
    colours.dedup();
    assert!(
        checked > 100 && colours.len() >= 12,
        "{checked} pixels, {} blocks",
        colours.len()
    );
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    assert_passes_match("textured plane", &cpu, &gpu_passes(&gpu, &scene));
}

#[test]
fn the_gpu_passes_equal_the_cpu_passes_on_shipped_scenes() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    // Mirrors, glass (the specular tint), a textured floor, and the path integrator.
    for (name, width) in [
        ("showcase.toml", 64),
        ("materials.toml", 64),
        ("cornell-box.toml", 48),
    ] {
        let scene = crate::support::scenes::reduced(
            crate::support::scenes::shipped(name),
            width,
            RenderOverrides {
                samples_per_pixel: Some(3),
                ..RenderOverrides::default()
            },
        );
        let cpu = gpu_render::low_level::cpu::aov::render_aovs(&scene);
        assert!(
            cpu.depth.iter().any(|&d| d > 0.0),
            "{name}: the camera sees something"
        );
        assert_passes_match(name, &cpu, &gpu_passes(&gpu, &scene));
    }
}

#[test]
fn recording_the_passes_leaves_the_image_bit_identical_and_a_film_keeps_them() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let scene = crate::support::scenes::reduced(
        crate::support::scenes::shipped("cornell-box.toml"),
        32,
        RenderOverrides {
            samples_per_pixel: Some(4),
            ..RenderOverrides::default()
        },
    );
    let plain = crate::support::gpu::renderer(&gpu);
    let with_aov = crate::support::gpu::renderer_with(
        &gpu,
        RendererOptions {
            aov: true,
            ..RendererOptions::default()
        },
    );
    crate::support::gpu::assert_renders_identical(&gpu, &plain, &with_aov, &scene, "AOVs on");
    let one_shot = with_aov
        .render(&gpu.device, &gpu.queue, &scene, None)
        .expect("renders");
    assert!(
        plain
            .render(&gpu.device, &gpu.queue, &scene, None)
            .expect("renders")
            .aov
            .is_none()
    );
    // A film of the same samples, added in three calls of 1, 1 and 2.
    let uploaded = with_aov
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("uploads");
    let mut film = with_aov
        .create_film(
            &gpu.device,
            &uploaded,
            scene.render.width,
            scene.render.height,
        )
        .expect("film");
    assert!(film.keeps_aov());
    for samples in [1, 1, 2] {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        with_aov
            .encode_samples(
                &gpu.device,
                &gpu.queue,
                &mut encoder,
                &uploaded,
                &mut film,
                samples,
            )
            .expect("encodes");
        gpu.queue.submit([encoder.finish()]);
        with_aov
            .finish(&gpu.device, &gpu.queue, &uploaded, &mut film)
            .expect("finishes");
    }
    let progressive = with_aov
        .read_aov(&gpu.device, &gpu.queue, &uploaded, &mut film)
        .expect("reads");
    assert_eq!(film.samples(), 4);
    assert_eq!(Some(progressive), one_shot.aov, "film against one-shot");
    // A film of a renderer without AOVs says so.
    let plain_scene = plain
        .upload(&gpu.device, &gpu.queue, &scene)
        .expect("uploads");
    let mut plain_film = plain
        .create_film(&gpu.device, &plain_scene, 8, 8)
        .expect("film");
    assert!(matches!(
        plain.read_aov(&gpu.device, &gpu.queue, &plain_scene, &mut plain_film),
        Err(gpu_render::gpu::RenderError::NoAov)
    ));
}

/// The passes follow the camera rays of every projection: an orthographic camera's
/// rays start on its view plane and a thin lens's at its lens points, on both
/// backends (the CPU's passes once started every ray at the eye, which an orthographic
/// camera's GPU passes did not).
#[test]
fn the_gpu_passes_equal_the_cpu_passes_through_a_thin_lens_and_an_orthographic_camera() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let base = crate::support::scenes::reduced(
        crate::support::scenes::shipped("showcase.toml"),
        64,
        RenderOverrides {
            samples_per_pixel: Some(3),
            ..RenderOverrides::default()
        },
    );
    let mut orthographic = base.clone();
    orthographic.camera.orthographic_half_height = Some(2.0);
    let mut lens = base.clone();
    lens.camera.lens = Some(gpu_render::scene::ThinLens {
        aperture_radius: 0.3,
        focus_distance: Some(3.0),
    });
    for (label, scene) in [("orthographic", orthographic), ("thin-lens", lens)] {
        let cpu = gpu_render::low_level::cpu::aov::render_aovs(&scene);
        // Through the eye the depth of the pinhole's rays: a different image.
        let pinhole = gpu_render::low_level::cpu::aov::render_aovs(&base);
        assert_ne!(
            cpu.depth, pinhole.depth,
            "{label}: the camera changed nothing"
        );
        assert_passes_match(label, &cpu, &gpu_passes(&gpu, &scene));
    }
}
