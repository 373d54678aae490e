//! glTF emissive textures (glTF 2.0 §3.9.3: emission = emissiveFactor × texel) on both
//! backends and both integrators. A glTF quad light whose emissive texture is black on
//! its left half and white on its right: the camera sees the pattern; a Lambert floor
//! lit by it alone gets the irradiance of the bright half only (Lambert's formula for a
//! polygon), so next-event estimation looks the texture up at each sampled point; the
//! light-selection weight of a textured emitter is its emission times the texture's
//! mean; and the GPU matches the CPU reference per pixel, Whitted and path.

use base64::Engine;
use glam::DVec3;
use gpu_render::low_level::accel::{AreaLights, SceneGeometry};
use gpu_render::low_level::camera::CameraFrame;
use gpu_render::scene::import::{ModelPlacement, import_gltf};
use gpu_render::scene::{
    Camera, Environment, Image, Integrator, Light, Material, MaterialKind, RenderSettings, Scene,
    Shape, TextureMapping,
};

use crate::support::compare::Tolerance;

/// The light: a 1.2 × 0.9 rectangle at height 1.2 facing down, `u` running along x
/// from its left edge (x = −0.4) to its right (x = 0.8), `v` along z.
const CORNERS: [[f32; 3]; 4] = [
    [-0.4, 1.2, -0.3],
    [0.8, 1.2, -0.3],
    [0.8, 1.2, 0.6],
    [-0.4, 1.2, 0.6],
];
/// Where the texture turns from black to white: u = ½.
const EDGE_X: f64 = 0.2;
/// The glTF emissive strength (the white half's radiance).
const STRENGTH: f64 = 3.0;
/// Texels across: the bilinear ramp between the halves is one texel (1.2/256 scene
/// units) wide and symmetric about u = ½, so it changes the floor's irradiance by a
/// second-order amount only.
const TEXELS: u32 = 256;

/// A PNG file's bytes.
fn png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    let image = image::RgbaImage::from_raw(width, height, raw).expect("texel count");
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut bytes, image::ImageFormat::Png)
        .expect("encode png");
    bytes.into_inner()
}

/// The glTF document of the quad light: positions, UVs, indices and the PNG in one
/// embedded buffer; emissiveFactor 1 × KHR_materials_emissive_strength `STRENGTH`,
/// a black base colour, and a clamping sampler.
fn quad_light_gltf() -> String {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8]| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            bin.len(),
            bytes.len()
        ));
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    let f32s =
        |values: &[f32]| -> Vec<u8> { values.iter().flat_map(|v| v.to_le_bytes()).collect() };
    let positions: Vec<f32> = CORNERS.iter().flatten().copied().collect();
    let uvs: Vec<f32> = CORNERS
        .iter()
        .flat_map(|c| [(c[0] + 0.4) / 1.2, (c[2] + 0.3) / 0.9])
        .collect();
    // (p1 − p0) × (p2 − p0) points down: the quad faces the floor.
    let indices: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let texels: Vec<[u8; 4]> = (0..TEXELS * 2)
        .map(|i| {
            if i % TEXELS < TEXELS / 2 {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            }
        })
        .collect();
    let p = view(&mut bin, &f32s(&positions));
    let t = view(&mut bin, &f32s(&uvs));
    let i = view(&mut bin, &indices);
    let image = view(&mut bin, &png(TEXELS, 2, &texels));
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{"asset":{{"version":"2.0"}},
  "extensionsUsed":["KHR_materials_emissive_strength"],
  "scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
  "meshes":[{{"name":"light","primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
  "materials":[{{"name":"panel","pbrMetallicRoughness":{{"baseColorFactor":[0,0,0,1],"metallicFactor":0,"roughnessFactor":1}},
     "emissiveFactor":[1,1,1],"emissiveTexture":{{"index":0}},
     "extensions":{{"KHR_materials_emissive_strength":{{"emissiveStrength":{STRENGTH}}}}}}}],
  "samplers":[{{"wrapS":33071,"wrapT":33071}}],
  "textures":[{{"source":0,"sampler":0}}],
  "images":[{{"bufferView":{image},"mimeType":"image/png"}}],
  "bufferViews":[{views}],
  "accessors":[
     {{"bufferView":{p},"componentType":5126,"count":4,"type":"VEC3","min":[-0.4,1.2,-0.3],"max":[0.8,1.2,0.6]}},
     {{"bufferView":{t},"componentType":5126,"count":4,"type":"VEC2"}},
     {{"bufferView":{i},"componentType":5123,"count":6,"type":"SCALAR"}}],
  "buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}]}}"#,
        views = views.join(","),
        len = bin.len(),
    )
}

/// A scene of the quad light (made a pure emitter, so that nothing but its emission
/// lights the floor) over a Lambert floor of albedo `rho` when `floor`.
fn scene(camera: Camera, floor: Option<f64>, integrator: Integrator) -> Scene {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("light.gltf");
    std::fs::write(&path, quad_light_gltf()).expect("write the glTF");
    let model = import_gltf(&path).unwrap_or_else(|e| panic!("import failed: {e}"));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let mut scene = Scene {
        render: RenderSettings {
            width: 8,
            height: 8,
            samples_per_pixel: 64,
            max_depth: 2,
            integrator,
            ..RenderSettings::default()
        },
        camera,
        environment: Environment::default(),
        materials: vec![],
        material_names: vec![],
        lights: vec![],
        shapes: vec![],
        meshes: vec![],
        images: vec![],
    };
    if let Some(rho) = floor {
        scene.materials.push(Material::lambert(DVec3::splat(rho)));
        scene.material_names.push("floor".into());
        scene.shapes.push(Shape::Plane {
            normal: DVec3::Y,
            offset: 0.0,
            material: 0,
        });
    }
    model.add_to_scene(&mut scene, &ModelPlacement::IDENTITY);
    let light = scene.materials.last_mut().expect("the light's material");
    assert_eq!(light.emission, DVec3::splat(STRENGTH));
    assert!(light.emission_texture.is_some(), "the texture is placed");
    assert_eq!(light.texture_mapping, TextureMapping::Uv);
    light.kind = MaterialKind::Emissive;
    scene
}

/// The light seen from below: every pixel whose centre ray meets the quad away from
/// the texture's edge shows black left of it and `STRENGTH` right of it.
#[test]
fn the_camera_sees_the_emissive_texture() {
    let camera = Camera {
        eye: DVec3::new(0.2, 0.2, 0.15),
        look_at: DVec3::new(0.2, 1.2, 0.15),
        up: DVec3::Z,
        fov_y_degrees: 40.0,
        orthographic_half_height: None,
        lens: None,
    };
    for integrator in [Integrator::Whitted, Integrator::Path] {
        let mut s = scene(camera, None, integrator);
        (s.render.width, s.render.height, s.render.samples_per_pixel) = (32, 32, 1);
        let image = gpu_render::cpu::render(&s, None).image;
        let frame = CameraFrame::new(&camera, 32, 32);
        let (mut dark, mut bright) = (0, 0);
        for y in 0..32 {
            for x in 0..32 {
                let d = frame.ray_direction(f64::from(x) + 0.5, f64::from(y) + 0.5, 32, 32);
                let t = (1.2 - camera.eye.y) / d.y;
                let hit = camera.eye + d * t;
                // A pixel's footprint on the quad is about 0.04 wide.
                if (hit.x - EDGE_X).abs() < 0.06 {
                    continue;
                }
                let expected = if hit.x > EDGE_X { STRENGTH } else { 0.0 };
                let value = image.pixels[(y * 32 + x) as usize];
                for c in 0..3 {
                    assert!(
                        (f64::from(value[c]) - expected).abs() < 1e-5,
                        "{integrator:?}: pixel ({x}, {y}) at x = {:.3} shows {value:?}, \
                         expected {expected}",
                        hit.x
                    );
                }
                if expected > 0.0 {
                    bright += 1;
                } else {
                    dark += 1;
                }
            }
        }
        assert!(dark > 300 && bright > 300, "{dark} dark, {bright} bright");
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

/// A camera that sees a small patch of the floor around the origin (a 0.1° field of
/// view: the irradiance varies over it by less than 1e-5).
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

/// The floor below the light gets the irradiance of the bright half alone, by
/// next-event estimation alone (depth 0) and combined with BRDF sampling (depth 2, MIS):
/// within 4 standard errors of the mean, estimated from the pixels. The whole quad's
/// irradiance (what a renderer ignoring the texture would give) is far from it.
#[test]
fn a_floor_lit_by_the_texture_gets_the_bright_half_s_irradiance() {
    let rho = 0.5;
    let corner = |x: f64, z: f64| DVec3::new(x, 1.2, z);
    let bright = [
        corner(EDGE_X, -0.3),
        corner(0.8, -0.3),
        corner(0.8, 0.6),
        corner(EDGE_X, 0.6),
    ];
    let whole = [
        corner(-0.4, -0.3),
        corner(0.8, -0.3),
        corner(0.8, 0.6),
        corner(-0.4, 0.6),
    ];
    let expected = rho / std::f64::consts::PI * polygon_irradiance(&bright, STRENGTH);
    let untextured = rho / std::f64::consts::PI * polygon_irradiance(&whole, STRENGTH);
    assert!(
        untextured > 1.5 * expected,
        "{untextured} vs {expected}: the test could not tell"
    );
    for depth in [0, 2] {
        let mut s = scene(floor_camera(), Some(rho), Integrator::Path);
        s.render.max_depth = depth;
        s.render.samples_per_pixel = 256;
        let image = gpu_render::cpu::render(&s, None).image;
        let values: Vec<f64> = image.pixels.iter().map(|p| f64::from(p[1])).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let standard_error = (variance / n).sqrt();
        assert!(
            standard_error <= 0.01 * expected,
            "depth {depth}: too noisy to test: standard error {standard_error} of {mean}"
        );
        assert!(
            (mean - expected).abs() <= 4.0 * standard_error,
            "depth {depth}: floor radiance {mean} against the bright half's {expected} \
             (standard error {standard_error}; the whole quad would give {untextured})"
        );
    }
}

/// Two emitting triangles of equal area and emission, one with a texture of mean 0.25:
/// next-event estimation picks them with probabilities 0.2 and 0.8.
#[test]
fn a_textured_emitter_is_chosen_by_its_texture_s_mean() {
    let triangle = |x: f64, material: u32| Shape::Triangle {
        vertices: [
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x + 1.0, 0.0, 0.0),
            DVec3::new(x, 1.0, 0.0),
        ],
        material,
    };
    let lamp = Material {
        emission: DVec3::splat(2.0),
        ..Material::blank(MaterialKind::Emissive)
    };
    let textured = Material {
        emission_texture: Some(0),
        texture_mapping: TextureMapping::Uv,
        ..lamp
    };
    // Texels 0 and 0.5 (mean 0.25) in every channel.
    let image = Image {
        path: "<test texture>".into(),
        width: 2,
        height: 1,
        texels: vec![[0.0, 0.0, 0.0, 1.0], [0.5, 0.5, 0.5, 1.0]],
    };
    let s = Scene {
        shapes: vec![triangle(0.0, 0), triangle(2.0, 1)],
        materials: vec![textured, lamp],
        material_names: vec!["textured".into(), "lamp".into()],
        images: vec![image],
        meshes: vec![],
        ..scene(floor_camera(), None, Integrator::Path)
    };
    let geometry = SceneGeometry::new(&s);
    let entries = AreaLights::new(&geometry, &s.materials, &s.images).entries();
    let mut selections: Vec<f64> = entries.iter().map(|e| e.selection).collect();
    selections.sort_by(f64::total_cmp);
    assert_eq!(selections.len(), 2);
    assert!((selections[0] - 0.2).abs() < 1e-12, "{selections:?}");
    assert!((selections[1] - 0.8).abs() < 1e-12, "{selections:?}");
}

/// The shipped scenes' tolerance (tests/integration/gpu_vs_cpu.rs): f32 against f64, with 0.5% of
/// the pixels (the quad's edges and the texture's) allowed to land on either side.
const TOLERANCE: Tolerance = crate::support::twins::TWIN_TOLERANCE;

/// The GPU renders the textured light and the floor it lights as the CPU reference
/// does, per pixel, with both integrators (Whitted with a directional light, so that the
/// floor is lit; path with the light alone, two bounces).
#[test]
fn emissive_textures_render_alike_on_both_backends() {
    let camera = Camera {
        eye: DVec3::new(0.2, 0.6, 3.0),
        look_at: DVec3::new(0.2, 0.6, 0.0),
        up: DVec3::Y,
        fov_y_degrees: 50.0,
        orthographic_half_height: None,
        lens: None,
    };
    let mut whitted = scene(camera, Some(0.5), Integrator::Whitted);
    whitted.lights.push(Light::Directional {
        direction: DVec3::new(0.3, -1.0, -0.2).normalize(),
        irradiance: DVec3::splat(1.0),
    });
    let mut path = scene(camera, Some(0.5), Integrator::Path);
    for s in [&mut whitted, &mut path] {
        (s.render.width, s.render.height, s.render.samples_per_pixel) = (64, 48, 4);
    }
    // The camera sees the light's underside: some pixels show each half.
    let cpu = gpu_render::cpu::render(&whitted, None).image;
    let shows = |value: f32| {
        cpu.pixels
            .iter()
            .filter(|p| (p[1] - value).abs() < 1e-4)
            .count()
    };
    assert!(shows(STRENGTH as f32) > 20, "the bright half is not seen");
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    for (label, s) in [
        ("emissive-texture-whitted", &whitted),
        ("emissive-texture-path", &path),
    ] {
        crate::support::twins::assert_backends_agree(&gpu, &renderer, label, s, TOLERANCE);
    }
}
