//! The path integrator of the CPU reference (src/cpu/path.rs) against closed forms:
//! the white furnace (a closed emissive Lambert sphere around the camera converges to
//! E·Σρᵏ), a spherical and a square area light over a Lambert floor (the irradiance of
//! a sphere, π L sin² α, and Lambert's formula for a polygon), one-sided emission, and
//! agreement with the Whitted tracer where both compute the same thing (direct light
//! from point lights). Statistical checks allow 4 standard errors of the mean,
//! estimated from the pixels, and require that error to be small, so that they can
//! fail.

use glam::DVec3;
use gpu_render::scene::{
    Camera, Environment, Integrator, Light, Material, MaterialKind, RenderSettings, Scene, Shape,
};

fn scene(shapes: Vec<Shape>, materials: Vec<Material>, camera: Camera) -> Scene {
    Scene {
        render: RenderSettings {
            width: 8,
            height: 8,
            samples_per_pixel: 64,
            max_depth: 64,
            stack_size: 65,
            integrator: Integrator::Path,
            ..RenderSettings::default()
        },
        camera,
        environment: Environment::default(),
        material_names: (0..materials.len()).map(|i| format!("m{i}")).collect(),
        materials,
        lights: vec![],
        shapes,
        meshes: vec![],
        images: vec![],
    }
}

/// Mean and standard error of the mean of the pixels' green channel.
fn pixel_statistics(scene: &Scene) -> (f64, f64) {
    let image = gpu_render::cpu::render(scene, None).image;
    let values: Vec<f64> = image.pixels.iter().map(|p| f64::from(p[1])).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

fn assert_converges(label: &str, scene: &Scene, expected: f64, max_relative_error: f64) {
    let (mean, standard_error) = pixel_statistics(scene);
    assert!(
        standard_error <= max_relative_error * expected,
        "{label}: the estimate is too noisy to test: standard error {standard_error} of {mean}"
    );
    assert!(
        (mean - expected).abs() <= 4.0 * standard_error + 1e-9 * expected,
        "{label}: mean {mean} against the closed form {expected} (standard error \
         {standard_error})"
    );
}

fn emissive(radiance: f64) -> Material {
    Material {
        emission: DVec3::splat(radiance),
        ..Material::blank(MaterialKind::Emissive)
    }
}

/// Inside a closed sphere of albedo ρ and emission E every path sees E at each bounce:
/// L = E (1 − ρ^(d+1)) / (1 − ρ) for d bounces, whatever the direction sampling, the
/// roulette or the (absent) next-event estimation from inside.
#[test]
fn the_white_furnace_converges_to_the_geometric_series() {
    let camera = Camera {
        eye: DVec3::new(0.1, -0.2, 0.05),
        look_at: DVec3::new(1.0, 0.3, 0.0),
        up: DVec3::Y,
        fov_y_degrees: 90.0,
        orthographic_half_height: None,
        lens: None,
    };
    for (rho, depth) in [(0.0, 64), (0.5, 64), (0.8, 64), (0.8, 3)] {
        let furnace = Material {
            emission: DVec3::splat(1.5),
            ..Material::lambert(DVec3::splat(rho))
        };
        let mut s = scene(
            vec![Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
                material: 0,
            }],
            vec![furnace],
            camera,
        );
        s.render.max_depth = depth;
        s.render.samples_per_pixel = 512;
        let expected = 1.5 * (1.0 - rho.powi(depth as i32 + 1)) / (1.0 - rho);
        let tolerance = if rho == 0.0 { 1e-12 } else { 0.01 };
        assert_converges(
            &format!("ρ = {rho}, depth {depth}"),
            &s,
            expected,
            tolerance,
        );
    }
}

/// A camera that sees a small patch of the floor y = 0 around the origin from the
/// side (a 0.1° field of view, so that the irradiance varies over it by less than
/// 1e-5).
fn floor_camera() -> Camera {
    Camera {
        eye: DVec3::new(3.0, 1.5, 0.5),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        fov_y_degrees: 0.1,
        orthographic_half_height: None,
        lens: None,
    }
}

fn floor(material: u32) -> Shape {
    Shape::Plane {
        normal: DVec3::Y,
        offset: 0.0,
        material,
    }
}

/// A sphere of radiance L and radius r at height d over a Lambert floor of albedo ρ:
/// E = π L (r/d)² at the point below it, so the floor's radiance is ρ L (r/d)². Found
/// by next-event estimation alone (depth 0) and by it and BRDF sampling combined
/// (depth 2, MIS).
#[test]
fn a_sphere_light_lights_the_floor_as_its_solid_angle_says() {
    let (radiance, radius, height, rho) = (4.0, 0.5, 2.0, 0.6);
    for depth in [0, 2] {
        let mut s = scene(
            vec![
                floor(0),
                Shape::Sphere {
                    center: DVec3::new(0.0, height, 0.0),
                    radius,
                    material: 1,
                },
            ],
            vec![Material::lambert(DVec3::splat(rho)), emissive(radiance)],
            floor_camera(),
        );
        s.render.max_depth = depth;
        s.render.samples_per_pixel = 256;
        let expected = rho * radiance * (radius / height).powi(2);
        assert_converges(&format!("depth {depth}"), &s, expected, 0.01);
    }
}

/// Irradiance at the origin, normal +y, from a polygon of radiance `radiance` seen
/// through its front: Lambert's formula E = (L/2) Σ θᵢ (n · uᵢ), with θᵢ the angle the
/// edge (vᵢ, vᵢ₊₁) subtends and uᵢ the unit normal of the plane through the point and
/// that edge (Arvo, "Applications of Irradiance Tensors", SIGGRAPH 1995, eq. 1).
fn polygon_irradiance(vertices: &[DVec3], radiance: f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let (a, b) = (
            vertices[i].normalize(),
            vertices[(i + 1) % vertices.len()].normalize(),
        );
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * a.cross(b).normalize().dot(DVec3::Y);
    }
    (radiance / 2.0 * sum).abs()
}

/// A square light facing down over the floor, off centre: its irradiance by Lambert's
/// formula; turned to face up, it lights nothing (one-sided emission), unless its
/// material is `two_sided`.
#[test]
fn a_square_light_lights_the_floor_as_lamberts_formula_says_and_only_from_its_front() {
    let (radiance, rho) = (3.0, 0.5);
    // Wound clockwise seen from below: the normal (right-hand rule) points down.
    let down = vec![
        DVec3::new(-0.4, 1.2, -0.3),
        DVec3::new(0.8, 1.2, -0.3),
        DVec3::new(0.8, 1.2, 0.6),
        DVec3::new(-0.4, 1.2, 0.6),
    ];
    let normal = (down[1] - down[0]).cross(down[2] - down[0]);
    assert!(normal.y < 0.0, "the square faces down");
    let expected = rho / std::f64::consts::PI * polygon_irradiance(&down, radiance);
    for depth in [0, 2] {
        let mut s = scene(
            vec![
                floor(0),
                Shape::Polygon {
                    vertices: down.clone(),
                    material: 1,
                },
            ],
            vec![Material::lambert(DVec3::splat(rho)), emissive(radiance)],
            floor_camera(),
        );
        s.render.max_depth = depth;
        s.render.samples_per_pixel = 256;
        assert_converges(&format!("facing down, depth {depth}"), &s, expected, 0.01);
    }
    let up: Vec<DVec3> = down.iter().rev().copied().collect();
    let s = scene(
        vec![
            floor(0),
            Shape::Polygon {
                vertices: up,
                material: 1,
            },
        ],
        vec![Material::lambert(DVec3::splat(rho)), emissive(radiance)],
        floor_camera(),
    );
    let (mean, _) = pixel_statistics(&s);
    assert_eq!(mean, 0.0, "a light facing away lit the floor");

    // A two_sided material emits from the back as well: facing up, the square lights
    // the floor as it did facing down.
    let up: Vec<DVec3> = down.iter().rev().copied().collect();
    for depth in [0, 2] {
        let mut s = scene(
            vec![
                floor(0),
                Shape::Polygon {
                    vertices: up.clone(),
                    material: 1,
                },
            ],
            vec![
                Material::lambert(DVec3::splat(rho)),
                Material {
                    two_sided: true,
                    ..emissive(radiance)
                },
            ],
            floor_camera(),
        );
        s.render.max_depth = depth;
        s.render.samples_per_pixel = 256;
        assert_converges(&format!("two-sided, depth {depth}"), &s, expected, 0.01);
    }
}

/// With point lights only and no bounces, both integrators compute direct light by
/// the same shadow rays: the images are equal.
#[test]
fn with_point_lights_and_no_bounces_path_tracing_is_whitted() {
    let mut s = scene(
        vec![
            floor(0),
            Shape::Sphere {
                center: DVec3::new(0.0, 0.5, 0.0),
                radius: 0.5,
                material: 1,
            },
        ],
        vec![
            Material::lambert(DVec3::splat(0.6)),
            Material::lambert(DVec3::new(0.8, 0.3, 0.2)),
        ],
        Camera {
            eye: DVec3::new(0.0, 1.5, 4.0),
            look_at: DVec3::new(0.0, 0.4, 0.0),
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            orthographic_half_height: None,
            lens: None,
        },
    );
    s.lights = vec![
        Light::Point {
            position: DVec3::new(2.0, 3.0, 2.0),
            intensity: DVec3::splat(8.0),
        },
        Light::Directional {
            direction: DVec3::new(-0.3, -1.0, -0.2),
            irradiance: DVec3::splat(0.7),
        },
    ];
    s.render.width = 32;
    s.render.height = 24;
    s.render.samples_per_pixel = 4;
    s.render.max_depth = 0;
    let path = gpu_render::cpu::render(&s, None).image;
    s.render.integrator = Integrator::Whitted;
    let whitted = gpu_render::cpu::render(&s, None).image;
    assert!(path.pixels.iter().any(|p| p[0] > 0.0));
    assert_eq!(path.pixels, whitted.pixels);
}

/// `∫ f(wi, n) cos θi dωi` at normal incidence (the directional albedo seen along the
/// normal), by the midpoint rule on a fine grid.
fn normal_incidence_albedo(material: &Material) -> f64 {
    let (nt, np) = (400, 200);
    let (dt, dp) = (
        std::f64::consts::FRAC_PI_2 / nt as f64,
        2.0 * std::f64::consts::PI / np as f64,
    );
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        for j in 0..np {
            let phi = (j as f64 + 0.5) * dp;
            let wi = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let f =
                gpu_render::low_level::cpu::bxdf::eval_brdf(material, &[], DVec3::Z, wi, DVec3::Z);
            sum += f.y * wi.z * theta.sin() * dt * dp;
        }
    }
    sum
}

/// The furnace with a white GGX conductor (Fresnel 1 at every angle): a single-scattering
/// microfacet model loses the light that its facets would reflect more than once, and
/// no more. With the camera at the centre every camera ray meets the sphere at normal
/// incidence, so one bounce gives exactly L = E (1 + A(0)), A(0) the directional albedo
/// at normal incidence (< 1, by quadrature); and every depth stays below E (d + 1).
#[test]
fn the_white_furnace_of_a_ggx_conductor_loses_only_what_single_scattering_loses() {
    let camera = Camera {
        eye: DVec3::ZERO,
        look_at: DVec3::new(1.0, 0.2, 0.3),
        up: DVec3::Y,
        fov_y_degrees: 90.0,
        orthographic_half_height: None,
        lens: None,
    };
    for roughness in [0.3, 0.7, 1.0] {
        let conductor = Material {
            roughness,
            conductor: true,
            eta: DVec3::ONE,
            k: DVec3::splat(1e6),
            fresnel: gpu_render::scene::FresnelModel::Schlick,
            emission: DVec3::splat(1.0),
            ..Material::blank(MaterialKind::CookTorrance)
        };
        let albedo = normal_incidence_albedo(&conductor);
        // Checked independently: 0.99, 0.70 and 0.31 for alpha 0.09, 0.49 and 1 (a
        // NumPy quadrature of the same formulas); at alpha = 1 D(h) = 1/pi, and every
        // facet tilted more than 45 degrees reflects below the horizon.
        assert!(
            albedo < 1.0 && albedo > 0.25,
            "roughness {roughness}: A(0) = {albedo}"
        );
        let mut s = scene(
            vec![Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
                material: 0,
            }],
            vec![conductor],
            camera,
        );
        s.render.max_depth = 1;
        s.render.samples_per_pixel = 1024;
        assert_converges(
            &format!("GGX roughness {roughness}, one bounce"),
            &s,
            1.0 + albedo,
            0.01,
        );
        s.render.max_depth = 8;
        s.render.samples_per_pixel = 64;
        let (mean, _) = pixel_statistics(&s);
        assert!(
            mean < 9.0 && mean > 1.0 + albedo,
            "roughness {roughness}, 8 bounces: {mean}"
        );
    }
}
