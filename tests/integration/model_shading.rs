//! What glTF and OBJ files ask of the shading, on both backends (issue 28): vertex
//! colours (glTF `COLOR_0`, OBJ `v x y z r g b`) multiplying the albedo, and texture
//! coordinates made per texture (`KHR_texture_transform`'s offset, rotation and scale,
//! and `texCoord` choosing `TEXCOORD_1`). Each scene is checked against what the
//! specification says lands where (probes of the CPU image), then rendered on the GPU
//! and compared per pixel with the CPU reference.

use glam::{DMat4, DVec2, DVec3};
use gpu_render::film::LinearImage as Film;
use gpu_render::scene::{
    Environment, Image, Light, Material, Mesh, RenderSettings, Scene, TextureMapping,
    TextureTransform,
};

use crate::support::quads::{
    EYE_Z, FOV_Y_DEGREES, HEIGHT, WIDTH, assert_colour, assert_colour_within, at, camera, colour,
    pixel_at_uv, pixel_of, quad,
};
use crate::support::twins::{TWIN_TOLERANCE, assert_backends_agree};

/// A scene of `meshes` under a light along −z of irradiance π: a white Lambert surface
/// facing it has radiance 1, so a pixel shows its albedo.
fn scene(materials: Vec<Material>, meshes: Vec<Mesh>, images: Vec<Image>) -> Scene {
    Scene {
        render: RenderSettings {
            width: WIDTH,
            height: HEIGHT,
            samples_per_pixel: 1,
            ..RenderSettings::default()
        },
        camera: camera(),
        environment: Environment::default(),
        material_names: (0..materials.len()).map(|i| format!("m{i}")).collect(),
        materials,
        lights: vec![Light::Directional {
            direction: DVec3::new(0.0, 0.0, -1.0),
            irradiance: DVec3::splat(std::f64::consts::PI),
        }],
        shapes: vec![],
        meshes,
        images,
    }
}

fn gpu_agrees(label: &str, scene: &Scene) {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer(&gpu);
    assert_backends_agree(&gpu, &renderer, label, scene, TWIN_TOLERANCE);
}

/// Red on the quad's left edge, blue on its right: at `u` the albedo is
/// `(1 - u, 0, u)`.
const LEFT: DVec3 = DVec3::X;
const RIGHT: DVec3 = DVec3::Z;

#[test]
fn a_vertex_colour_gradient_renders_the_gradient_on_both_backends() {
    let mut plain = quad(0, vec![at(-3.0)]);
    plain.colors = Some([LEFT, RIGHT, RIGHT, LEFT].map(|c| c.extend(1.0)).to_vec());
    // Placed twice, the second time mirrored left to right (an instanced mesh, corners
    // 1 and 2 swapped): its gradient runs the other way.
    let mut placed = plain.clone();
    placed.instances = vec![
        at(-1.0),
        at(1.0) * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
    ];
    // The colour multiplies a textured base colour: a grey texture of 0.5.
    let mut textured = plain.clone();
    textured.material = 1;
    textured.instances = vec![at(3.0)];
    let grey = Image {
        path: "<grey>".into(),
        width: 1,
        height: 1,
        texels: vec![[0.5, 0.5, 0.5, 1.0]],
    };
    let scene = scene(
        vec![
            Material::lambert(DVec3::ONE),
            Material {
                albedo_texture: Some(0),
                texture_mapping: TextureMapping::Uv,
                ..Material::lambert(DVec3::ONE)
            },
        ],
        vec![plain, placed, textured],
        vec![grey],
    );
    let cpu = gpu_render::cpu::render(&scene, None);
    // A pixel spans 0.0275 of u: its centre is within that of the probe.
    let within = 0.03;
    for u in [0.1, 0.25, 0.5, 0.75, 0.9] {
        let gradient = LEFT * (1.0 - u) + RIGHT * u;
        for centre in [-3.0, -1.0] {
            let pixel = pixel_at_uv(centre, u, 0.5);
            assert_colour_within("gradient", &cpu.image, pixel, gradient, within);
        }
        let mirrored = LEFT * u + RIGHT * (1.0 - u);
        let pixel = pixel_at_uv(1.0, u, 0.5);
        assert_colour_within("mirrored", &cpu.image, pixel, mirrored, within);
        let pixel = pixel_at_uv(3.0, u, 0.5);
        assert_colour_within("textured", &cpu.image, pixel, gradient * 0.5, within);
    }
    gpu_agrees("vertex-colours", &scene);
}

/// An 8 × 8 texture of four uniform quadrants, so that a lookup inside one returns its
/// colour exactly.
fn quadrants() -> Image {
    let mut texels = Vec::new();
    for y in 0..8 {
        for x in 0..8 {
            let c = QUADRANTS[usize::from(y >= 4) * 2 + usize::from(x >= 4)];
            texels.push([c.x as f32, c.y as f32, c.z as f32, 1.0]);
        }
    }
    Image {
        path: "<quadrants>".into(),
        width: 8,
        height: 8,
        texels,
    }
}

/// The quadrants' colours: top left, top right, bottom left, bottom right.
const QUADRANTS: [DVec3; 4] = [
    DVec3::new(0.9, 0.1, 0.1),
    DVec3::new(0.1, 0.8, 0.1),
    DVec3::new(0.1, 0.1, 0.7),
    DVec3::new(0.6, 0.6, 0.1),
];
const TOP_LEFT: DVec3 = QUADRANTS[0];
const TOP_RIGHT: DVec3 = QUADRANTS[1];
const BOTTOM_LEFT: DVec3 = QUADRANTS[2];
const BOTTOM_RIGHT: DVec3 = QUADRANTS[3];

fn textured(transform: TextureTransform) -> Material {
    Material {
        albedo_texture: Some(0),
        texture_mapping: TextureMapping::Uv,
        texture_transform: transform,
        ..Material::lambert(DVec3::ONE)
    }
}

#[test]
fn a_transformed_texture_lands_where_the_transform_says() {
    let transform = |set, offset: [f64; 2], degrees: f64, scale: [f64; 2]| {
        TextureTransform::offset_rotation_scale(
            set,
            DVec2::from(offset),
            degrees.to_radians(),
            DVec2::from(scale),
        )
    };
    let materials = vec![
        textured(TextureTransform::IDENTITY),
        // Half a repeat to the right: the quad's left half shows the image's right.
        textured(transform(0, [0.5, 0.0], 0.0, [1.0, 1.0])),
        // 90° (KHR_texture_transform: u' = v, v' = -u): the image turned a quarter.
        textured(transform(0, [0.0, 0.0], 90.0, [1.0, 1.0])),
        // Set 1 (offset by half a repeat on both axes from set 0), scaled by 2.
        textured(transform(1, [0.0, 0.0], 0.0, [2.0, 2.0])),
    ];
    let meshes = (0..4)
        .map(|i| {
            let mut mesh = quad(i, vec![at(-3.0 + 2.0 * f64::from(i))]);
            let uvs = mesh.uvs.clone().expect("uvs");
            mesh.uvs1 = Some(uvs.iter().map(|uv| *uv + DVec2::splat(0.5)).collect());
            mesh
        })
        .collect();
    let scene = scene(materials, meshes, vec![quadrants()]);
    let cpu = gpu_render::cpu::render(&scene, None);
    let probes = [
        // Untransformed: the image as it is (which also checks the probes' mapping).
        (-3.0, [0.25, 0.25], TOP_LEFT),
        (-3.0, [0.75, 0.25], TOP_RIGHT),
        (-3.0, [0.25, 0.75], BOTTOM_LEFT),
        (-3.0, [0.75, 0.75], BOTTOM_RIGHT),
        // Offset: u + 0.5.
        (-1.0, [0.25, 0.25], TOP_RIGHT),
        (-1.0, [0.75, 0.75], BOTTOM_LEFT),
        // Rotated: (0.25, 0.25) → (0.25, -0.25) ≡ (0.25, 0.75); (0.75, 0.25) → (0.25,
        // -0.75) ≡ (0.25, 0.25); (0.25, 0.75) → (0.75, 0.75).
        (1.0, [0.25, 0.25], BOTTOM_LEFT),
        (1.0, [0.75, 0.25], TOP_LEFT),
        (1.0, [0.25, 0.75], BOTTOM_RIGHT),
        // Set 1 scaled: (0.1, 0.1) → set 1 (0.6, 0.6) → (1.2, 1.2) ≡ (0.2, 0.2); (0.3,
        // 0.1) → (0.8, 0.6) → (1.6, 1.2) ≡ (0.6, 0.2).
        (3.0, [0.1, 0.1], TOP_LEFT),
        (3.0, [0.3, 0.1], TOP_RIGHT),
        (3.0, [0.1, 0.3], BOTTOM_LEFT),
    ];
    for (centre, [u, v], expected) in probes {
        assert_colour(
            &format!("quad at {centre}, uv ({u}, {v})"),
            &cpu.image,
            pixel_at_uv(centre, u, v),
            expected,
        );
    }
    gpu_agrees("texture-transforms", &scene);
}

/// The emission and metallic/roughness textures follow their own transforms too: the
/// same quads with the quadrant texture as emission and a rough-metal map, on both
/// backends (path integrator: emission seen and sampled).
#[test]
fn every_texture_of_a_material_follows_its_own_transform_on_both_backends() {
    let transform = TextureTransform::offset_rotation_scale(
        1,
        DVec2::new(0.25, 0.5),
        0.7,
        DVec2::new(1.5, 0.75),
    );
    let material = Material {
        kind: gpu_render::scene::MaterialKind::Pbr,
        diffuse: DVec3::splat(0.8),
        metallic: 1.0,
        roughness: 1.0,
        emission: DVec3::splat(0.5),
        texture_mapping: TextureMapping::Uv,
        metallic_roughness_texture: Some(0),
        metallic_roughness_transform: transform,
        emission_texture: Some(0),
        emission_transform: TextureTransform {
            set: 0,
            ..transform
        },
        ..Material::blank(gpu_render::scene::MaterialKind::Pbr)
    };
    let mut mesh = quad(0, vec![at(-1.0), at(1.0)]);
    let uvs = mesh.uvs.clone().expect("uvs");
    mesh.uvs1 = Some(uvs.iter().map(|uv| DVec2::new(uv.y, uv.x)).collect());
    let mut scene = scene(vec![material], vec![mesh], vec![quadrants()]);
    scene.lights.push(Light::Point {
        position: DVec3::new(0.5, 1.0, 3.0),
        intensity: DVec3::splat(20.0),
    });
    scene.render.width = WIDTH / 2;
    scene.render.height = HEIGHT / 2;
    gpu_agrees("transformed-pbr-whitted", &scene);
    scene.render.integrator = gpu_render::scene::Integrator::Path;
    scene.render.samples_per_pixel = 2;
    gpu_agrees("transformed-pbr-path", &scene);
}

/// The corpus's vertex-coloured box (FBX2glTF's `BoxVertexColors.glb`, whose base
/// colour is white): rendered as its colours say, not white.
#[test]
fn the_corpus_vertex_coloured_box_renders_in_colour() {
    let Some(model) =
        crate::corpus::corpus_model("gltf-transform/packages/core/test/in/BoxVertexColors.glb")
    else {
        return;
    };
    assert!(model.meshes.iter().all(|m| m.colors.is_some()));
    let scene = model.into_scene(RenderSettings {
        width: 48,
        height: 36,
        ..RenderSettings::default()
    });
    let cpu = gpu_render::cpu::render(&scene, None);
    // Chroma: how far a pixel's channels are apart. A white box lit by white lights has
    // none; the coloured one has plenty.
    let coloured = cpu
        .image
        .pixels
        .iter()
        .filter(|p| {
            let (low, high) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            high > 0.05 && high - low > 0.5 * high
        })
        .count();
    assert!(
        coloured > cpu.image.pixels.len() / 10,
        "only {coloured} of {} pixels are coloured",
        cpu.image.pixels.len()
    );
    gpu_agrees("box-vertex-colors", &scene);
}

/// A red quad turned away from the camera (its back face towards it) in front of a
/// green backdrop, lit from the camera's side at a slant: with `cull_back_faces`
/// (glTF's `doubleSided: false`) the camera sees the backdrop through it, lit where the
/// quad's shadow does not fall, and the quad still casts its shadow; without, it sees
/// the quad's back face.
fn back_face_scene(cull_back_faces: bool) -> Scene {
    let mut away = quad(0, vec![DMat4::from_rotation_y(std::f64::consts::PI)]);
    away.positions.iter_mut().for_each(|p| *p *= 0.5);
    let backdrop = Mesh {
        positions: quad(1, vec![]).positions.iter().map(|p| *p * 2.0).collect(),
        ..quad(1, vec![DMat4::from_translation(DVec3::new(0.0, 0.0, -1.0))])
    };
    let mut scene = scene(
        vec![
            Material {
                cull_back_faces,
                ..Material::lambert(DVec3::new(0.8, 0.1, 0.1))
            },
            Material::lambert(DVec3::new(0.1, 0.8, 0.1)),
        ],
        vec![away, backdrop],
        vec![],
    );
    // Slanted towards +x: the quad's shadow on the backdrop lies 0.5 to the right.
    scene.lights = vec![Light::Directional {
        direction: DVec3::new(0.5, 0.0, -1.0).normalize(),
        irradiance: DVec3::splat(std::f64::consts::PI),
    }];
    scene.render.width = WIDTH / 2;
    scene
}

#[test]
fn camera_rays_pass_through_single_sided_back_faces_which_still_cast_shadows() {
    let lit = 1.0 / 5f64.sqrt() * 2.0; // cos θ of the slanted light on a surface facing +z
    // The quad covers x in [-0.45, 0.45]; its shadow on the backdrop x in [0.05, 0.95].
    let through = pixel_of(-0.3, 0.0);
    let shadow = pixel_of(0.7, 0.0);
    let culled = back_face_scene(true);
    let cpu = gpu_render::cpu::render(&culled, None);
    let backdrop = DVec3::new(0.1, 0.8, 0.1) * lit;
    // The image is half as wide: the same angles, a quarter of the columns fewer on
    // the left.
    let half = |(x, y): (u32, u32)| (x - WIDTH / 4, y);
    let (through, shadow) = (half(through), half(shadow));
    assert_colour_within("through", &cpu.image, through, backdrop, 1e-3);
    assert_colour_within("shadow", &cpu.image, shadow, DVec3::ZERO, 1e-6);
    gpu_agrees("single-sided-whitted", &culled);
    let mut path = culled.clone();
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.samples_per_pixel = 2;
    gpu_agrees("single-sided-path", &path);

    // Double-sided: the quad's back face, lit.
    let shown = gpu_render::cpu::render(&back_face_scene(false), None);
    assert_colour_within(
        "back face",
        &shown.image,
        through,
        DVec3::new(0.8, 0.1, 0.1) * lit,
        1e-3,
    );
}

/// Khronos' TextureSettingsTest: its single-sided row shows a red X on the back face
/// of a single-sided quad, which a viewer that culls back faces never shows.
#[test]
fn the_texture_settings_test_shows_no_red_x() {
    let Some(model) = crate::corpus::corpus_model(
        "draco/testdata/KhronosSampleModels/TextureSettingsTest/glTF/TextureSettingsTest.gltf",
    ) else {
        return;
    };
    let scene = model.into_scene(RenderSettings {
        width: 160,
        height: 120,
        // Level 0: at this size the X's thin strokes are minified, and filtered
        // lookups mix them with their neighbours below the probe's saturation.
        texture_filtering: gpu_render::scene::TextureFiltering::None,
        ..RenderSettings::default()
    });
    let red = |image: &Film| {
        image
            .pixels
            .iter()
            .filter(|p| p[0] > 0.3 && p[1] < 0.25 * p[0] && p[2] < 0.25 * p[0])
            .count()
    };
    let cpu = gpu_render::cpu::render(&scene, None);
    assert_eq!(red(&cpu.image), 0, "red pixels in the single-sided row");
    // Shown on both faces (as before doubleSided was honoured), the X is there: the
    // probe sees it.
    let mut both = scene.clone();
    both.materials
        .iter_mut()
        .for_each(|m| m.cull_back_faces = false);
    let shown = gpu_render::cpu::render(&both, None);
    assert!(red(&shown.image) > 0, "no red pixels");
    gpu_agrees("texture-settings-test", &scene);
}

/// Khronos' UnlitTest (`KHR_materials_unlit`, required): its README asks for two boxes
/// of flat orange and blue, "with no shading", under any lights. At one sample per
/// pixel every pixel is the background or exactly one of the two base colours.
#[test]
fn the_unlit_test_shows_two_flat_boxes() {
    let Some(model) = crate::corpus::corpus_model(
        "draco/testdata/KhronosSampleModels/UnlitTest/glTF/UnlitTest.gltf",
    ) else {
        return;
    };
    let scene = model.into_scene(RenderSettings {
        width: 160,
        height: 100,
        samples_per_pixel: 1,
        ..RenderSettings::default()
    });
    assert!(!scene.lights.is_empty(), "lit, so that shading would show");
    let image = gpu_render::cpu::render(&scene, None).image;
    let background = scene.environment.background.as_vec3();
    let orange = glam::Vec3::new(1.0, 0.217_637_64, 0.0);
    let blue = glam::Vec3::new(0.0, 0.217_637_64, 1.0);
    let (mut on_orange, mut on_blue) = (0, 0);
    for p in &image.pixels {
        let c = glam::Vec3::new(p[0], p[1], p[2]);
        if (c - orange).abs().max_element() < 1e-6 {
            on_orange += 1;
        } else if (c - blue).abs().max_element() < 1e-6 {
            on_blue += 1;
        } else {
            assert!(
                (c - background).abs().max_element() < 1e-6,
                "a shaded pixel {c} (neither box colour nor the background {background})"
            );
        }
    }
    assert!(
        on_orange > 500 && on_blue > 500,
        "{on_orange} orange and {on_blue} blue pixels"
    );
    gpu_agrees("unlit-test", &scene);
}

/// A spot light 2 above a white floor, pointing down, its cones 0.2 and 0.4 rad
/// (`KHR_lights_punctual`'s spot), of intensity π W/sr: the floor's radiance is
/// `h / d³` times the cone's attenuation.
fn spot_scene() -> Scene {
    let mut floor = quad(0, vec![]);
    floor.positions.iter_mut().for_each(|p| *p *= 4.0);
    floor.instances = vec![DMat4::IDENTITY];
    let mut scene = scene(vec![Material::lambert(DVec3::ONE)], vec![floor], vec![]);
    scene.lights = vec![Light::Spot {
        position: DVec3::new(0.0, 0.0, SPOT_HEIGHT),
        direction: DVec3::NEG_Z,
        intensity: DVec3::splat(std::f64::consts::PI),
        cos_inner: INNER.cos(),
        cos_outer: OUTER.cos(),
    }];
    scene
}

const SPOT_HEIGHT: f64 = 2.0;
const INNER: f64 = 0.2;
const OUTER: f64 = 0.4;

#[test]
fn a_spot_light_s_cone_edges_land_where_its_angles_say() {
    let scene = spot_scene();
    let cpu = gpu_render::cpu::render(&scene, None);
    let row = HEIGHT / 2;
    let half_width =
        EYE_Z * (FOV_Y_DEGREES.to_radians() / 2.0).tan() * f64::from(WIDTH) / f64::from(HEIGHT);
    let x_of =
        |column: u32| ((f64::from(column) + 0.5) / f64::from(WIDTH) * 2.0 - 1.0) * half_width;
    let pixel_size = 2.0 * half_width / f64::from(WIDTH);
    // The outer edge: the last lit pixel right of the centre is where the outer cone
    // meets the floor, h·tan(outer), within the pixel and its sample's jitter.
    let last_lit = (WIDTH / 2..WIDTH)
        .take_while(|&c| colour(&cpu.image, (c, row)).x > 0.0)
        .last()
        .expect("the centre is lit");
    let edge = SPOT_HEIGHT * OUTER.tan();
    assert!(
        (x_of(last_lit) - edge).abs() < 1.5 * pixel_size,
        "the light ends at x = {}, the outer cone at {edge}",
        x_of(last_lit)
    );
    // Inside the inner cone the full inverse-square light; halfway between the cones
    // (in angle) the reference implementation's ((cos θ − cos o)/(cos i − cos o))².
    let radiance = |x: f64, attenuation: f64| {
        let d = (x * x + SPOT_HEIGHT * SPOT_HEIGHT).sqrt();
        SPOT_HEIGHT / d.powi(3) * attenuation
    };
    let inside = pixel_of(0.5 * SPOT_HEIGHT * INNER.tan(), 0.0);
    let expected = radiance(x_of(inside.0), 1.0);
    assert_colour_within(
        "inner cone",
        &cpu.image,
        inside,
        DVec3::splat(expected),
        0.01 * expected,
    );
    let middle = (INNER + OUTER) / 2.0;
    let halfway = pixel_of(SPOT_HEIGHT * middle.tan(), 0.0);
    let cosine = SPOT_HEIGHT / (x_of(halfway.0).powi(2) + SPOT_HEIGHT.powi(2)).sqrt();
    let t = (cosine - OUTER.cos()) / (INNER.cos() - OUTER.cos());
    let expected = radiance(x_of(halfway.0), t * t);
    // The attenuation changes by about 6% across a pixel here.
    assert_colour_within(
        "between the cones",
        &cpu.image,
        halfway,
        DVec3::splat(expected),
        0.06 * expected,
    );
    gpu_agrees("spot-whitted", &scene);
    let mut path = scene.clone();
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.samples_per_pixel = 2;
    gpu_agrees("spot-path", &path);
}

/// An orthographic camera (glTF's `orthographic` projection) looking down the z axis
/// at two quads of the same size, one at z = 0 and one 5 further away: the far one
/// looks exactly as large (parallel rays), and the view spans `2·ymag` in height.
#[test]
fn an_orthographic_camera_shows_parallel_edges_and_ymag_as_the_half_height() {
    let half_height = 1.5;
    let mut scene = scene(
        vec![
            Material::lambert(DVec3::ONE),
            Material::lambert(DVec3::splat(0.5)),
        ],
        vec![
            quad(0, vec![at(-1.2)]),
            quad(1, vec![DMat4::from_translation(DVec3::new(1.2, 0.0, -5.0))]),
        ],
        vec![],
    );
    scene.camera.orthographic_half_height = Some(half_height);
    scene.render.width = 96;
    scene.render.height = 48;
    let cpu = gpu_render::cpu::render(&scene, None);
    // Each quad's rows and columns of lit pixels: 1.8 units of the 3 the height spans,
    // both the same, whatever the distance (under perspective the far one would be
    // 7.5/12.5 as large).
    let extent = |value: f32| {
        let lit =
            |x: u32, y: u32| (cpu.image.pixels[(y * 96 + x) as usize][0] - value).abs() < 1e-3;
        let columns = (0..96).filter(|&x| (0..48).any(|y| lit(x, y))).count();
        let rows = (0..48).filter(|&y| (0..96).any(|x| lit(x, y))).count();
        (columns, rows)
    };
    let pixels = 1.8 / (2.0 * half_height) * 48.0;
    for (value, name) in [(1.0, "near"), (0.5, "far")] {
        let (columns, rows) = extent(value);
        assert!(
            (columns as f64 - pixels).abs() <= 1.0 && (rows as f64 - pixels).abs() <= 1.0,
            "{name} quad: {columns} x {rows} pixels, expected {pixels} x {pixels}"
        );
    }
    gpu_agrees("orthographic-whitted", &scene);
    let mut path = scene.clone();
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.samples_per_pixel = 2;
    gpu_agrees("orthographic-path", &path);
}

/// A 1 × 1 normal map whose one texel is the tangent-space normal `n` (encoded as
/// `(n + 1) / 2`, linear data).
fn normal_map(n: DVec3) -> Image {
    let texel = (n + DVec3::ONE) / 2.0;
    Image {
        path: "<normal map>".into(),
        width: 1,
        height: 1,
        texels: vec![[texel.x as f32, texel.y as f32, texel.z as f32, 1.0]],
    }
}

/// Three quads facing +z, tangent +x: normal-mapped 30° towards +x, flat, and mapped
/// 30° towards −x (the mirror twin), lit at a grazing angle from +x.
fn normal_mapped_scene() -> Scene {
    let tilt = 30f64.to_radians();
    let mapped = |image: u32| Material {
        normal_texture: Some(image),
        texture_mapping: TextureMapping::Uv,
        ..Material::lambert(DVec3::splat(0.8))
    };
    let meshes = (0..3)
        .map(|i| {
            let mut mesh = quad(i, vec![at(-3.0 + 2.0 * f64::from(i))]);
            mesh.tangents = Some(vec![glam::DVec4::new(1.0, 0.0, 0.0, 1.0); 4]);
            mesh
        })
        .collect();
    let mut scene = scene(
        vec![mapped(0), Material::lambert(DVec3::splat(0.8)), mapped(1)],
        meshes,
        vec![
            normal_map(DVec3::new(tilt.sin(), 0.0, tilt.cos())),
            normal_map(DVec3::new(-tilt.sin(), 0.0, tilt.cos())),
        ],
    );
    scene.lights = vec![Light::Directional {
        direction: -GRAZING,
        irradiance: DVec3::splat(std::f64::consts::PI),
    }];
    scene
}

/// Towards the grazing light: from +x, 11° above the quads' plane.
const GRAZING: DVec3 = DVec3::new(0.980_580_675_690_920_2, 0.0, 0.196_116_135_138_184_04);

#[test]
fn a_normal_mapped_quad_tilted_toward_a_grazing_light_is_brighter_than_its_mirror_twin() {
    let scene = normal_mapped_scene();
    let cpu = gpu_render::cpu::render(&scene, None);
    let tilt = 30f64.to_radians();
    let value = |centre: f64| colour(&cpu.image, pixel_at_uv(centre, 0.5, 0.5)).x;
    let (toward, flat, away) = (value(-3.0), value(-1.0), value(1.0));
    // Lambert under irradiance π: 0.8 · cos between the (mapped) normal and the light.
    let expected = |n: DVec3| 0.8 * n.dot(GRAZING).max(0.0);
    assert!(
        (toward - expected(DVec3::new(tilt.sin(), 0.0, tilt.cos()))).abs() < 1e-3,
        "{toward}"
    );
    assert!((flat - expected(DVec3::Z)).abs() < 1e-3, "{flat}");
    assert!(toward > 3.0 * flat && flat > away, "{toward} {flat} {away}");
    assert_eq!(away, 0.0, "turned away from the light");
    gpu_agrees("normal-map-whitted", &scene);
    let mut path = scene.clone();
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.samples_per_pixel = 2;
    gpu_agrees("normal-map-path", &path);
    // Instanced and mirrored placements move the tangents (and flip their handedness).
    let mut placed = scene.clone();
    placed.meshes[0].instances = vec![
        at(-3.0),
        at(1.0) * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
    ];
    placed.meshes.truncate(2);
    let cpu = gpu_render::cpu::render(&placed, None);
    // Mirrored, the map's +x tilt points to −x: away from the light.
    assert_eq!(colour(&cpu.image, pixel_at_uv(1.0, 0.5, 0.5)).x, 0.0);
    gpu_agrees("normal-map-instanced", &placed);
}

/// 300 red single-sided quads, each turned away from the camera, stacked in front of
/// the green backdrop under an ambient light: a camera ray passes through the first
/// `MAX_PASS_THROUGHS` back faces and shows the next as a front (a mutated model once
/// made both tracers pass through back faces without end), on both backends alike.
#[test]
fn a_camera_ray_passes_through_at_most_max_pass_throughs_back_faces_on_both_backends() {
    use gpu_render::low_level::cpu::intersect::MAX_PASS_THROUGHS;
    const LAYERS: u32 = 300;
    let red = DVec3::new(0.8, 0.1, 0.1);
    let green = DVec3::new(0.1, 0.8, 0.1);
    let layers = quad(
        0,
        (0..LAYERS)
            .map(|i| {
                DMat4::from_translation(DVec3::new(0.0, 0.0, -0.002 * f64::from(i)))
                    * DMat4::from_rotation_y(std::f64::consts::PI)
            })
            .collect(),
    );
    let backdrop = Mesh {
        positions: quad(1, vec![]).positions.iter().map(|p| *p * 2.0).collect(),
        ..quad(1, vec![DMat4::from_translation(DVec3::new(0.0, 0.0, -1.0))])
    };
    let mut scene = scene(
        vec![
            Material {
                cull_back_faces: true,
                ..Material::lambert(red)
            },
            Material::lambert(green),
        ],
        vec![layers, backdrop],
        vec![],
    );
    scene.environment.ambient = DVec3::ONE;
    scene.lights.clear();
    let centre = pixel_of(0.0, 0.0);
    const { assert!(LAYERS > MAX_PASS_THROUGHS) };
    let cpu = gpu_render::cpu::render(&scene, None);
    assert_colour_within("the layer after the bound", &cpu.image, centre, red, 1e-3);
    assert_colour_within(
        "the backdrop beside the layers",
        &cpu.image,
        pixel_of(1.5, 0.0),
        green,
        1e-3,
    );
    gpu_agrees("pass-through-bound-whitted", &scene);
    let mut path = scene.clone();
    path.render.integrator = gpu_render::scene::Integrator::Path;
    path.render.samples_per_pixel = 2;
    gpu_agrees("pass-through-bound-path", &path);
}

/// Scene files have spot lights and orthographic cameras too: `type = "spot"` with
/// cone half-angles in degrees (glTF's defaults 0 and 45 when left out) loads as the
/// model's spot light, and `orthographic_half_height` as an orthographic camera; a
/// scene written so renders the same image as the model built by hand
/// (`spot_scene`). Cones out of order, a camera with both a field of view and a half
/// height, and a half height of 0 are located errors.
#[test]
fn scene_files_write_spot_lights_and_orthographic_cameras() {
    use gpu_render::scene::{SceneError, parse_scene};
    let text = |light: &str, camera: &str| {
        format!(
            "[render]\nwidth = {WIDTH}\nheight = {HEIGHT}\nsamples_per_pixel = 1\n\
             [camera]\neye = [0, 0, {EYE_Z}]\nlook_at = [0, 0, 0]\n{camera}\n\
             [materials.white]\ntype = \"lambert\"\nalbedo = 1\n\
             [[lights]]\n{light}\n\
             [[objects]]\ntype = \"polygon\"\nmaterial = \"white\"\n\
             vertices = [[-3.6, -3.6, 0], [3.6, -3.6, 0], [3.6, 3.6, 0], [-3.6, 3.6, 0]]\n"
        )
    };
    let spot = format!(
        "type = \"spot\"\nposition = [0, 0, {SPOT_HEIGHT}]\ndirection = [0, 0, -3]\n\
         intensity = {}\ninner_cone_degrees = {}\nouter_cone_degrees = {}",
        std::f64::consts::PI,
        INNER.to_degrees(),
        OUTER.to_degrees()
    );
    let written = parse_scene(
        &text(&spot, &format!("fov_y_degrees = {FOV_Y_DEGREES}")),
        "spot.toml".as_ref(),
    )
    .expect("the spot scene loads");
    let Light::Spot {
        direction,
        cos_inner,
        cos_outer,
        ..
    } = written.lights[0]
    else {
        panic!("a spot light, got {:?}", written.lights[0]);
    };
    assert_eq!(direction, DVec3::NEG_Z);
    assert!((cos_inner - INNER.cos()).abs() < 1e-12 && (cos_outer - OUTER.cos()).abs() < 1e-12);
    let by_hand = gpu_render::cpu::render(&spot_scene(), None);
    let from_file = gpu_render::cpu::render(&written, None);
    let centre = pixel_of(0.0, 0.0);
    let edge = pixel_of(SPOT_HEIGHT * ((INNER + OUTER) / 2.0).tan(), 0.0);
    for pixel in [centre, edge] {
        assert_colour_within(
            "the file's spot light",
            &from_file.image,
            pixel,
            colour(&by_hand.image, pixel),
            1e-6,
        );
    }

    let defaults = parse_scene(
        &text(
            "type = \"spot\"\nposition = [0, 0, 2]\ndirection = [0, 0, -1]\nintensity = 1",
            "",
        ),
        "spot.toml".as_ref(),
    )
    .expect("defaults");
    assert!(matches!(
        defaults.lights[0],
        Light::Spot { cos_inner, cos_outer, .. }
            if cos_inner == 1.0 && (cos_outer - std::f64::consts::FRAC_PI_4.cos()).abs() < 1e-12
    ));

    let orthographic = parse_scene(
        &text(&spot, "orthographic_half_height = 1.5"),
        "ortho.toml".as_ref(),
    )
    .expect("the orthographic scene loads");
    assert_eq!(orthographic.camera.orthographic_half_height, Some(1.5));

    let refused = |light: &str, camera: &str, needle: &str| {
        let err = parse_scene(&text(light, camera), "bad.toml".as_ref()).expect_err(needle);
        assert!(
            matches!(
                err,
                SceneError::Invalid {
                    location: Some(_),
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains(needle), "{needle:?} not in {err}");
    };
    refused(
        "type = \"spot\"\nposition = [0, 0, 2]\ndirection = [0, 0, -1]\nintensity = 1\n\
         inner_cone_degrees = 30\nouter_cone_degrees = 20",
        "",
        "0 <= inner < outer <= 90",
    );
    refused(
        &spot,
        "fov_y_degrees = 30\northographic_half_height = 1",
        "exclude each other",
    );
    refused(
        &spot,
        "orthographic_half_height = 0",
        "orthographic_half_height must be in",
    );
}
