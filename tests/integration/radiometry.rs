//! Analytic radiometry: a camera inside a Lambert sphere of albedo ρ and radius r, with
//! a point light of intensity I at its centre, sees radiance ρ·I/(π·r²) in every pixel
//! (irradiance I/r² at normal incidence times the BRDF ρ/π), up to the self-intersection
//! offset of the shadow ray. Checked on both backends.

use glam::DVec3;
use gpu_render::scene::{
    Camera, Environment, Light, LightingSpace, Material, RenderSettings, Scene, Shape,
};

fn furnace_scene(albedo: f64, radius: f64, intensity: f64) -> Scene {
    Scene {
        render: RenderSettings {
            width: 24,
            height: 16,
            samples_per_pixel: 4,
            max_depth: 0,
            stack_size: 1,
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: gpu_render::scene::Integrator::Whitted,
            texture_filtering: gpu_render::scene::TextureFiltering::Trilinear,
        },
        camera: Camera {
            eye: DVec3::new(0.1, -0.2, 0.05) * radius,
            look_at: DVec3::new(1.0, 0.3, -0.4) * radius,
            up: DVec3::Y,
            fov_y_degrees: 100.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment::default(),
        materials: vec![Material::lambert(DVec3::splat(albedo))],
        material_names: vec!["inside".into()],
        lights: vec![Light::Point {
            position: DVec3::ZERO,
            intensity: DVec3::new(intensity, 0.5 * intensity, 0.25 * intensity),
        }],
        shapes: vec![Shape::Sphere {
            center: DVec3::ZERO,
            radius,
            material: 0,
        }],
        meshes: vec![],
        images: vec![],
    }
}

fn expected_radiance(albedo: f64, radius: f64, intensity: f64) -> [f64; 3] {
    let l = albedo * intensity / (std::f64::consts::PI * radius * radius);
    [l, 0.5 * l, 0.25 * l]
}

#[test]
fn cpu_sees_rho_i_over_pi_r_squared_everywhere() {
    for (albedo, radius, intensity) in [(0.5, 1.0, std::f64::consts::PI), (0.8, 3.0, 40.0)] {
        let scene = furnace_scene(albedo, radius, intensity);
        let rendered = gpu_render::cpu::render(&scene, None);
        let expected = expected_radiance(albedo, radius, intensity);
        for pixel in &rendered.image.pixels {
            for c in 0..3 {
                let relative = (f64::from(pixel[c]) - expected[c]).abs() / expected[c];
                // The shadow ray, and with it the light's distance, starts at the hit
                // point moved inwards by the self-intersection offset, 256 f32 ulps of
                // each coordinate on both backends (offset_ray_origin): r shrinks by at
                // most 256·2^-23 of itself, so r² by twice that; then f64 arithmetic
                // rounded once to f32.
                let offset = 2.0 * 256.0 * f64::from(f32::EPSILON);
                assert!(relative < offset + 1e-6, "{pixel:?} vs {expected:?}");
            }
        }
        // One camera ray and one shadow ray per sample.
        assert_eq!(rendered.stats.rays_traced, 24 * 16 * 4 * 2);
    }
}

#[test]
fn gpu_sees_rho_i_over_pi_r_squared_everywhere() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    for (albedo, radius, intensity) in [(0.5, 1.0, std::f64::consts::PI), (0.8, 3.0, 40.0)] {
        let scene = furnace_scene(albedo, radius, intensity);
        let rendered = renderer
            .render(&gpu.device, &gpu.queue, &scene, None)
            .expect("GPU render");
        let expected = expected_radiance(albedo, radius, intensity);
        for pixel in &rendered.image.pixels {
            for c in 0..3 {
                let relative = (f64::from(pixel[c]) - expected[c]).abs() / expected[c];
                // f32 throughout: a hit point off by a few ulps changes r² slightly.
                assert!(relative < 1e-4, "{pixel:?} vs {expected:?}");
            }
        }
        assert_eq!(rendered.stats.rays_traced, 24 * 16 * 4 * 2);
    }
}
