//! Environment maps on the CPU reference: the closed form of a Lambert sphere under a
//! uniform sky, the map as the background of both integrators, and the scene file's
//! `[environment] map` with its bad inputs (a missing or malformed file, NaN, infinite
//! or negative texels, a black map, contradictory fields), each a clear error naming
//! the file and the problem, or documented behaviour.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use gpu_render::scene::{
    Camera, Environment, EnvironmentMap, Image, Integrator, LoadOptions, Material, RenderSettings,
    Scene, Shape, load_scene, load_scene_with,
};

/// A `width × height` map of one colour.
fn uniform_map(width: u32, height: u32, value: f32) -> Image {
    Image {
        path: "uniform.exr".into(),
        width,
        height,
        texels: vec![[value, value, value, 1.0]; (width * height) as usize],
    }
}

/// A Lambert sphere of albedo `rho` (radius 1 at the origin) under `map`, seen from
/// (0, 0, 4) on a 16 × 16 image at 256 samples per pixel.
fn sphere_under(map: EnvironmentMap, rho: f64, integrator: Integrator, max_depth: u32) -> Scene {
    Scene {
        render: RenderSettings {
            width: 16,
            height: 16,
            samples_per_pixel: 256,
            max_depth,
            stack_size: max_depth + 1,
            integrator,
            ..RenderSettings::default()
        },
        camera: Camera {
            eye: DVec3::new(0.0, 0.0, 4.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            orthographic_half_height: None,
            lens: None,
        },
        environment: Environment {
            map: Some(Arc::new(map)),
            ..Environment::default()
        },
        material_names: vec!["sphere".into()],
        materials: vec![Material::lambert(DVec3::splat(rho))],
        lights: vec![],
        shapes: vec![Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
            material: 0,
        }],
        meshes: vec![],
        images: vec![],
    }
}

/// Whether the camera ray through image point (`x`, `y`) (pixels, y down) of
/// [`sphere_under`]'s 16 × 16 view hits the unit sphere.
fn ray_hits_sphere(x: f64, y: f64) -> bool {
    let tan_half = 20f64.to_radians().tan();
    let (px, py) = (
        (2.0 * x / 16.0 - 1.0) * tan_half,
        (1.0 - 2.0 * y / 16.0) * tan_half,
    );
    let d = DVec3::new(px, py, -1.0).normalize();
    let o = DVec3::new(0.0, 0.0, 4.0);
    // |o + t d|² = 1 has a real root.
    let b = o.dot(d);
    b * b - (o.length_squared() - 1.0) > 0.0
}

/// The pixels wholly on the sphere and wholly off it (their four corners agree).
fn classify_pixels() -> (Vec<usize>, Vec<usize>) {
    let (mut on, mut off) = (vec![], vec![]);
    for y in 0..16 {
        for x in 0..16 {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(dx, dy)| ray_hits_sphere(f64::from(x) + dx, f64::from(y) + dy));
            if corners.iter().all(|&c| c) {
                on.push((y * 16 + x) as usize);
            } else if corners.iter().all(|&c| !c) {
                off.push((y * 16 + x) as usize);
            }
        }
    }
    (on, off)
}

/// A convex Lambert surface under a uniform environment of radiance L sees the sky
/// over its whole hemisphere: irradiance π L, outgoing radiance ρ L, whatever the
/// point, with one bounce or many (no light returns to a convex shape), by next-event
/// estimation alone (`max_depth = 0`) or combined with BRDF sampling; the background
/// is L. The map is rotated and scaled (L = 0.8 · 1.5) to exercise both.
#[test]
fn a_lambert_sphere_under_a_uniform_sky_converges_to_rho_times_l() {
    let (on, off) = classify_pixels();
    assert!(
        on.len() > 20 && off.len() > 100,
        "{} {}",
        on.len(),
        off.len()
    );
    let radiance = 0.8 * 1.5;
    for (rho, max_depth) in [(0.6, 5), (0.6, 0), (0.9, 3)] {
        let map = EnvironmentMap {
            image: uniform_map(32, 16, 0.8),
            rotation_degrees: 30.0,
            scale: DVec3::splat(1.5),
        };
        let scene = sphere_under(map, rho, Integrator::Path, max_depth);
        let image = gpu_render::cpu::render(&scene, None).image;
        let values: Vec<f64> = on.iter().map(|&i| f64::from(image.pixels[i][1])).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let error = (variance / n).sqrt();
        let expected = rho * radiance;
        let label = format!("rho {rho}, max_depth {max_depth}");
        assert!(
            error <= 0.01 * expected,
            "{label}: too noisy to test: standard error {error} of {mean}"
        );
        assert!(
            (mean - expected).abs() <= 4.0 * error,
            "{label}: mean {mean} against ρL = {expected} (standard error {error})"
        );
        for &i in &off {
            let p = image.pixels[i];
            for c in &p[..3] {
                assert!(
                    (f64::from(*c) - radiance).abs() <= 1e-6,
                    "{label}: background pixel {i} is {c}, not L = {radiance}"
                );
            }
        }
    }
}

/// Whitted's tracer sees the map as the background, interpolated bilinearly between
/// texel centres as Mitsuba's `envmap` does (here a map whose column 0 differs from the
/// rest, unrotated: the camera looks along −z, u = 0, between the last column's centre
/// at u = 7/8 and the first's at u = 1/8). No light reaches the sphere but the ambient
/// term, which stays as it is.
#[test]
fn whitted_sees_the_map_as_the_background() {
    let columns = [2.0, 0.5, 0.5, 0.5];
    let mut image = uniform_map(4, 2, 0.0);
    for (i, texel) in image.texels.iter_mut().enumerate() {
        let value = columns[i % 4] as f32;
        *texel = [value, value, value, 1.0];
    }
    let map = EnvironmentMap {
        image,
        rotation_degrees: 0.0,
        scale: DVec3::ONE,
    };
    let mut scene = sphere_under(map, 0.5, Integrator::Whitted, 2);
    // One sample: through each pixel's centre.
    scene.render.samples_per_pixel = 1;
    scene.environment.ambient = DVec3::splat(0.2);
    let rendered = gpu_render::cpu::render(&scene, None).image;
    let pixel = |x: usize, y: usize| f64::from(rendered.pixels[y * 16 + x][1]);
    // The map along each corner pixel's centre ray, interpolated here from the
    // columns: x = frac(u − 1/8)·4 between columns ⌊x⌋ and ⌊x⌋ + 1 (wrapping).
    let frame = gpu_render::low_level::camera::CameraFrame::new(&scene.camera, 16, 16);
    let expected = |px: f64, py: f64| {
        let d = frame.ray_direction(px, py, 16, 16);
        let u = d.x.atan2(-d.z) / (2.0 * std::f64::consts::PI);
        let shifted = u - 0.125;
        let x = (shifted - shifted.floor()) * 4.0;
        let (i, t) = (x.floor() as usize % 4, x - x.floor());
        columns[i] * (1.0 - t) + columns[(i + 1) % 4] * t
    };
    // Top-left corner: left of −z (u just below 1); top-right: right of it (u just
    // above 0); both between column 3 and column 0, nearer the middle than either.
    for (x, y) in [(0usize, 0usize), (15, 0)] {
        let want = expected(x as f64 + 0.5, y as f64 + 0.5);
        assert!(want > 0.6 && want < 1.9, "corner ({x}, {y}) expects {want}");
        assert!(
            (pixel(x, y) - want).abs() < 1e-6,
            "({x}, {y}): {} for {want}",
            pixel(x, y)
        );
    }
    assert!(
        pixel(15, 0) > pixel(0, 0),
        "the right corner is nearer column 0"
    );
    // The sphere's centre: albedo × ambient only.
    assert!((pixel(8, 8) - 0.1).abs() < 1e-6, "{}", pixel(8, 8));
}

/// A black map lights nothing and is never sampled: no division by its zero
/// integral, no NaN; the image is black (documented in docs/scene-format.md).
#[test]
fn a_black_map_renders_black_without_nan() {
    let map = EnvironmentMap {
        image: uniform_map(8, 4, 0.0),
        rotation_degrees: 0.0,
        scale: DVec3::ONE,
    };
    let scene = sphere_under(map, 0.8, Integrator::Path, 4);
    let image = gpu_render::cpu::render(&scene, None).image;
    assert!(
        image
            .pixels
            .iter()
            .all(|p| p[..3].iter().all(|&c| c == 0.0))
    );
}

/// A folder of its own under the target directory for this test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("environment-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// A scene file in `dir` whose `[environment]` table has `environment`.
fn scene_with(dir: &Path, environment: &str) -> PathBuf {
    let path = dir.join("scene.toml");
    let text = format!(
        "[render]\nwidth = 4\nheight = 4\nintegrator = \"path\"\n\
         [camera]\neye = [0, 0, 4]\nlook_at = [0, 0, 0]\n\
         [environment]\n{environment}\n"
    );
    std::fs::write(&path, text).expect("scene file");
    path
}

/// Writes a 2 × 1 OpenEXR map whose second texel's red channel is `value`.
fn write_exr(path: &Path, value: f32) {
    let image = image::Rgba32FImage::from_raw(2, 1, vec![1.0, 1.0, 1.0, 1.0, value, 1.0, 1.0, 1.0])
        .expect("2 × 1 texels");
    image.save(path).expect("EXR written");
}

fn load_error(path: &Path) -> String {
    match load_scene(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_map_is_read_relative_to_the_scene_file_with_rotation_and_scale() {
    let dir = scratch("good");
    write_exr(&dir.join("sky.exr"), 3.0);
    let scene = load_scene(&scene_with(
        &dir,
        "map = \"sky.exr\"\nrotation = 45\nscale = [1, 2, 3]\nambient = 0.1",
    ))
    .expect("the scene loads");
    let map = scene.environment.map.expect("a map");
    assert_eq!((map.image.width, map.image.height), (2, 1));
    assert_eq!(map.image.texels[1][0], 3.0);
    assert_eq!(map.rotation_degrees, 45.0);
    assert_eq!(map.scale, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(scene.environment.ambient, DVec3::splat(0.1));
    // The shipped scene's map.
    let shipped =
        load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/env-materials.toml"))
            .expect("scenes/env-materials.toml loads");
    let sky = shipped.environment.map.expect("a map");
    assert_eq!((sky.image.width, sky.image.height), (256, 128));
}

#[test]
fn bad_maps_are_clear_errors_naming_the_file_and_the_problem() {
    let dir = scratch("bad");
    let missing = load_error(&scene_with(&dir, "map = \"nowhere.hdr\""));
    assert!(
        missing.contains("environment")
            && missing.contains("nowhere.hdr")
            && missing.contains("cannot read"),
        "{missing}"
    );
    std::fs::write(dir.join("text.hdr"), "not an image").expect("written");
    let malformed = load_error(&scene_with(&dir, "map = \"text.hdr\""));
    assert!(
        malformed.contains("text.hdr") && malformed.contains("not a readable image"),
        "{malformed}"
    );
    for (name, value, problem) in [
        ("nan.exr", f32::NAN, "not a finite number"),
        ("inf.exr", f32::INFINITY, "not a finite number"),
        ("negative.exr", -0.5, "texels must be >= 0"),
    ] {
        write_exr(&dir.join(name), value);
        let message = load_error(&scene_with(&dir, &format!("map = \"{name}\"")));
        assert!(
            message.contains(name) && message.contains("texel (1, 0)") && message.contains(problem),
            "{name}: {message}"
        );
    }
    write_exr(&dir.join("ok.exr"), 1.0);
    // Finite texels and a scale whose product is beyond what the GPU can sum (1e30).
    write_exr(&dir.join("big.exr"), 100.0);
    for (fields, problem) in [
        (
            "map = \"ok.exr\"\nbackground = 1",
            "either background or map",
        ),
        ("map = \"ok.exr\"\nrotation = nan", "rotation is NaN"),
        ("map = \"ok.exr\"\nscale = -1", "scale must be >= 0"),
        ("map = \"big.exr\"\nscale = 1e37", "at most 1e30"),
        (
            "map = \"big.exr\"\nscale = 1e29",
            "reaches 1e31, above the 1e30 accepted",
        ),
        ("rotation = 10", "there is no map"),
    ] {
        let message = load_error(&scene_with(&dir, fields));
        assert!(message.contains(problem), "{fields}: {message}");
    }
    // A sandbox confines the map to the scene's folder.
    let outside = scene_with(&dir, "map = \"../environment-bad/ok.exr\"");
    let options = LoadOptions {
        sandbox: true,
        ..LoadOptions::default()
    };
    let confined = match load_scene_with(&outside, &options) {
        Ok(_) => panic!("a map outside the folder loaded in a sandbox"),
        Err(e) => e.to_string(),
    };
    assert!(confined.contains("map"), "{confined}");
    assert!(
        load_scene(&outside).is_ok(),
        "without a sandbox the path is trusted"
    );
}
