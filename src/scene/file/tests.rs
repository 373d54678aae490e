//! Happy paths of the scene-file parser.

use std::path::Path;

use glam::DVec3;

use super::{LoadOptions, parse_scene, parse_scene_with};
use crate::scene::{
    Light, LightingSpace, Material, MaterialKind, RenderSettings, Scene, SceneWarning, Shape,
};

const CAMERA: &str = "[camera]\neye = [0, 1, 5]\nlook_at = [0, 0.5, 0]\n";

fn parse(text: &str) -> Scene {
    match parse_scene(text, Path::new("test.toml")) {
        Ok(scene) => scene,
        Err(e) => panic!("unexpected error: {e}"),
    }
}

#[test]
fn defaults_are_applied() {
    let scene = parse(CAMERA);
    assert_eq!(
        scene.render,
        RenderSettings {
            width: 640,
            height: 480,
            samples_per_pixel: 1,
            max_depth: 5,
            stack_size: 6,
            lighting_space: LightingSpace::Linear,
            min_ray_weight: 0.0,
            integrator: crate::scene::Integrator::Whitted,
            texture_filtering: crate::scene::TextureFiltering::Anisotropic,
        }
    );
    assert_eq!(scene.camera.up, DVec3::Y);
    assert_eq!(scene.camera.fov_y_degrees, 45.0);
    assert_eq!(scene.environment.background, DVec3::ZERO);
    assert_eq!(scene.environment.ambient, DVec3::ZERO);
    assert!(scene.materials.is_empty() && scene.lights.is_empty() && scene.shapes.is_empty());
}

#[test]
fn stack_size_follows_max_depth_unless_given() {
    let scene = parse(&format!(
        "[render]\nmax_depth = 9\nlighting = \"naive_gamma\"\n{CAMERA}"
    ));
    assert_eq!(scene.render.stack_size, 10);
    assert_eq!(scene.render.lighting_space, LightingSpace::NaiveGamma);
    let scene = parse(&format!(
        "[render]\nmax_depth = 9\nstack_size = 3\n{CAMERA}"
    ));
    assert_eq!(scene.render.stack_size, 3);
}

#[test]
fn grey_shorthand_and_rgb_colours() {
    let scene = parse(&format!(
        "{CAMERA}[environment]\nbackground = 0.25\nambient = [0.1, 0.2, 0.3]\n\
         [materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n"
    ));
    assert_eq!(scene.environment.background, DVec3::splat(0.25));
    assert_eq!(scene.environment.ambient, DVec3::new(0.1, 0.2, 0.3));
    assert_eq!(scene.materials[0], Material::lambert(DVec3::splat(0.5)));
}

#[test]
fn light_strength_times_colour() {
    let scene = parse(&format!(
        "{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = 50\n\
         color = [1, 0.5, 0]\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0, -2, 0]\nirradiance = 2\n"
    ));
    assert_eq!(
        scene.lights,
        vec![
            Light::Point {
                position: DVec3::new(0.0, 4.0, 0.0),
                intensity: DVec3::new(50.0, 25.0, 0.0),
            },
            Light::Directional {
                direction: DVec3::NEG_Y,
                irradiance: DVec3::splat(2.0),
            },
        ]
    );
}

#[test]
fn plane_normal_is_normalized_and_offset_computed() {
    let scene = parse(&format!(
        "{CAMERA}[materials.m]\ntype = \"mirror\"\n\
         [[objects]]\ntype = \"plane\"\npoint = [0, -1, 3]\nnormal = [0, 5, 0]\nmaterial = \"m\"\n"
    ));
    assert_eq!(
        scene.shapes,
        vec![Shape::Plane {
            normal: DVec3::Y,
            offset: -1.0,
            material: 0
        }]
    );
    assert_eq!(scene.materials[0].reflectance, DVec3::ONE);
}

#[test]
fn materials_are_sorted_by_name_and_referenced_by_index() {
    let scene = parse(&format!(
        "{CAMERA}[materials.zinc]\ntype = \"mirror\"\nreflectance = 0.9\n\
         [materials.air]\ntype = \"dielectric\"\nior = 1.5\n\
         [materials.lamp]\ntype = \"emissive\"\nradiance = [4, 3, 2]\n\
         [materials.paint]\ntype = \"blinn_phong\"\ndiffuse = 0.5\nspecular = 0.5\n\
         shininess = 20\ncoat_ior = 1.5\nemission = 0.1\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"zinc\"\n\
         [[objects]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n\
         material = \"air\"\n\
         [[objects]]\ntype = \"polygon\"\n\
         vertices = [[0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 0.5, 0], [0, 2, 0]]\n\
         material = \"paint\"\n"
    ));
    assert_eq!(scene.material_names, ["air", "lamp", "paint", "zinc"]);
    let kinds: Vec<MaterialKind> = scene.materials.iter().map(|m| m.kind).collect();
    assert_eq!(
        kinds,
        [
            MaterialKind::Dielectric,
            MaterialKind::Emissive,
            MaterialKind::BlinnPhong,
            MaterialKind::Mirror
        ]
    );
    assert_eq!(scene.materials[0].ior, 1.5);
    assert_eq!(scene.materials[0].transmittance, DVec3::ONE);
    assert_eq!(scene.materials[1].emission, DVec3::new(4.0, 3.0, 2.0));
    assert_eq!(scene.materials[2].coat_ior, 1.5);
    assert_eq!(scene.materials[2].shininess, 20.0);
    assert_eq!(scene.materials[2].emission, DVec3::splat(0.1));
    let indices: Vec<u32> = scene.shapes.iter().map(Shape::material).collect();
    assert_eq!(indices, [3, 0, 2]);
    match &scene.shapes[2] {
        Shape::Polygon { vertices, .. } => assert_eq!(vertices.len(), 5),
        other => panic!("expected a polygon, got {other:?}"),
    }
}

#[test]
fn minimal_scene_file_loads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/minimal.toml");
    let scene = match super::load_scene(&path) {
        Ok(scene) => scene,
        Err(e) => panic!("{e}"),
    };
    assert_eq!((scene.render.width, scene.render.height), (320, 240));
    assert_eq!(scene.render.samples_per_pixel, 1);
    assert_eq!(scene.materials, [Material::lambert(DVec3::splat(0.7))]);
    assert_eq!(scene.environment.background, DVec3::ZERO);
    assert_eq!(scene.lights.len(), 1);
    assert!(matches!(
        scene.shapes[..],
        [Shape::Sphere {
            radius: 1.0,
            material: 0,
            ..
        }]
    ));
}

#[test]
fn documented_example_parses() {
    let doc = include_str!("../../../docs/scene-format.md");
    let Some((_, after)) = doc.split_once("## Complete example\n\n```toml\n") else {
        panic!("docs/scene-format.md lost its example");
    };
    let Some((example, _)) = after.split_once("```") else {
        panic!("unterminated example");
    };
    let scene = parse(example);
    assert_eq!(scene.materials.len(), 5);
    assert_eq!(scene.lights.len(), 2);
    assert_eq!(scene.shapes.len(), 5);
}

const ANIMATION: &str = "[animation]\nfps = 4\ninterpolation = \"catmull_rom\"\n\
    [[animation.keyframes]]\ntime = 0\neye = [0, 1, 5]\nlook_at = [0, 0, 0]\n\
    [[animation.keyframes]]\ntime = 1.5\neye = [5, 1, 0]\nlook_at = [0, 0.5, 0]\n";

#[test]
fn an_animation_defines_a_camera_path() {
    let file = super::parse_scene_file(
        &format!("{CAMERA}{ANIMATION}"),
        Path::new("test.toml"),
        &super::LoadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let Some(path) = file.camera_path else {
        panic!("no camera path");
    };
    assert_eq!(path.interpolation, crate::scene::Interpolation::CatmullRom);
    // 1.5 s at 4 fps: frames 0 to 6.
    assert_eq!(path.frame_count, 7);
    assert_eq!(path.keys[1].eye, DVec3::new(5.0, 1.0, 0.0));
    let last = path.frame_camera(&file.scene.camera, 6);
    assert_eq!(
        (last.eye, last.look_at),
        (path.keys[1].eye, path.keys[1].look_at)
    );
    // The still camera is the [camera] table's.
    assert_eq!(file.scene.camera.eye, DVec3::new(0.0, 1.0, 5.0));
    let frames = parse(&format!(
        "{CAMERA}[animation]\nfps = 24\nframes = 3\n\
        [[animation.keyframes]]\ntime = 2\neye = [1, 1, 1]\nlook_at = [0, 0, 0]\n"
    ));
    assert_eq!(frames.camera.eye, DVec3::new(0.0, 1.0, 5.0));
}

#[test]
fn animation_errors_are_located() {
    let fail = |animation: &str| {
        parse_scene(&format!("{CAMERA}{animation}"), Path::new("test.toml"))
            .map(|_| ())
            .expect_err(animation)
            .to_string()
    };
    let message = fail(&ANIMATION.replace("time = 1.5", "time = 0"));
    assert!(
        message.starts_with("test.toml:11:1: animation.keyframes[1]: time 0 is not after"),
        "{message}"
    );
    let message = fail(&ANIMATION.replace("fps = 4", "fps = 0"));
    assert!(
        message.starts_with("test.toml:4:1: animation: fps must be > 0"),
        "{message}"
    );
    let message = fail(&ANIMATION.replace("catmull_rom", "bezier"));
    assert!(
        message.contains("\"linear\" or \"catmull_rom\""),
        "{message}"
    );
    let message = fail("[animation]\nfps = 24\n");
    assert!(
        message.contains("at least one [[animation.keyframes]]"),
        "{message}"
    );
    let message = fail(&ANIMATION.replace("look_at = [0, 0.5, 0]", "look_at = [5, 1, 0]"));
    assert!(
        message.contains("keyframes[1]: eye and look_at are the same"),
        "{message}"
    );
    // A straight path through the look-at point: fine at both keys, not at frame 2.
    let through = "[animation]\nfps = 2\n\
        [[animation.keyframes]]\ntime = 0\neye = [0, 0, -2]\nlook_at = [0, 0, 0]\n\
        [[animation.keyframes]]\ntime = 2\neye = [0, 0, 2]\nlook_at = [0, 0, 0]\n";
    let message = fail(through);
    assert!(
        message.contains("animation: at frame 2 (t = 1 s): eye and look_at are the same point"),
        "{message}"
    );
    let message = fail(&ANIMATION.replace("fps = 4", "fps = 4\nframes = 0"));
    assert!(
        message.contains("frames must be between 1 and"),
        "{message}"
    );
    let message = fail(&ANIMATION.replace("time = 1.5\n", "time = 1.5\nfov = 3\n"));
    assert!(message.contains("unknown field `fov`"), "{message}");
}

/// The warnings `text` loads with.
fn warnings(text: &str) -> Vec<SceneWarning> {
    let collected = std::sync::Mutex::new(Vec::new());
    let hook = |w: &SceneWarning| collected.lock().expect("lock").push(w.clone());
    let options = LoadOptions {
        warning: Some(&hook),
        ..LoadOptions::default()
    };
    parse_scene_with(text, Path::new("s.toml"), &options).expect("the scene loads");
    collected.into_inner().expect("lock")
}

fn sphere_scene(center: &str, radius: &str) -> String {
    format!(
        "[camera]\neye = [0, 3, 4]\nlook_at = [0, 0, 0]\n\
         [materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n\
         [[objects]]\ntype = \"plane\"\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\nmaterial = \"m\"\n\
         [[objects]]\ntype = \"sphere\"\ncenter = {center}\nradius = {radius}\nmaterial = \"m\"\n"
    )
}

#[test]
fn a_sphere_beyond_both_precisions_is_warned_about_with_its_figures() {
    let found = warnings(&sphere_scene("[0, -1e20, 0]", "1e20"));
    assert_eq!(found.len(), 1, "{found:?}");
    let warning = &found[0];
    assert_eq!(warning.location, Some((12, 1)), "{warning}");
    let message = &warning.message;
    for part in [
        "objects[1] (sphere)",
        "radius 1e20",
        "at 3.000e0 from the camera",
        "2.2e4 units on the CPU reference",
        "neither backend",
    ] {
        assert!(message.contains(part), "{part:?} missing from: {message}");
    }
}

#[test]
fn a_sphere_only_f64_places_is_warned_about_for_the_gpu() {
    let text = sphere_scene("[1000000, 0, 0]", "1").replace(
        "eye = [0, 3, 4]\nlook_at = [0, 0, 0]",
        "eye = [1000000, 0, 6]\nlook_at = [1000000, 0, 0]",
    );
    let found = warnings(&text);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].message.contains("the GPU cannot place it")
            && found[0].message.contains("--backend auto"),
        "{}",
        found[0]
    );
}

#[test]
fn ordinary_and_ground_spheres_load_without_a_warning() {
    for (center, radius) in [
        ("[0, 0.5, 0]", "0.5"),
        ("[0, -1000, 0]", "1000"),
        ("[3, -1e10, 2]", "1e10"),
        ("[0, 0, -1e4]", "1"),
    ] {
        let found = warnings(&sphere_scene(center, radius));
        assert!(found.is_empty(), "{center} {radius}: {found:?}");
    }
}

#[test]
fn two_sided_emission_is_read_and_needs_emission() {
    let scene = parse(&format!(
        "{CAMERA}[materials.lamp]\ntype = \"emissive\"\nradiance = [2, 2, 2]\ntwo_sided = true\n\
         [materials.glow]\ntype = \"lambert\"\nalbedo = [0.5, 0.5, 0.5]\nemission = [1, 0, 0]\n\
         [materials.plain]\ntype = \"lambert\"\nalbedo = [0.5, 0.5, 0.5]\ntwo_sided = false\n"
    ));
    let by_name = |name: &str| {
        let index = scene
            .material_names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no material {name}"));
        scene.materials[index]
    };
    assert!(by_name("lamp").two_sided);
    assert!(!by_name("glow").two_sided, "one-sided by default");
    assert!(!by_name("plain").two_sided);

    let text = format!(
        "{CAMERA}[materials.dull]\ntype = \"lambert\"\nalbedo = [0.5, 0.5, 0.5]\ntwo_sided = true\n"
    );
    let error = match parse_scene(&text, Path::new("test.toml")) {
        Ok(_) => panic!("two_sided without emission was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        error.contains("materials.dull")
            && error.contains("two_sided")
            && error.contains("test.toml"),
        "{error}"
    );
}

/// A point light so near a surface that `I/r²` is beyond f32 there (the GPU shows 0,
/// the CPU 1.85e38) is warned about at the light; the same light a unit away is not.
#[test]
fn a_point_light_whose_irradiance_is_beyond_f32_is_warned_about() {
    let scene = |z: &str| {
        format!(
            "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
             [materials.m]\ntype = \"lambert\"\nalbedo = 1\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 0, {z}]\nintensity = 1e30\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
        )
    };
    let found = warnings(&scene("1.000072"));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].location, Some((7, 1)), "{}", found[0]);
    for part in [
        "lights[0] (point)",
        "7.2e-5 from objects[0]",
        "--backend auto",
    ] {
        assert!(
            found[0].message.contains(part),
            "{part:?} missing from {}",
            found[0]
        );
    }
    assert!(warnings(&scene("2")).is_empty());
}
