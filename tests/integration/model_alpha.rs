//! glTF's alpha coverage (issue 28; glTF 2.0 §3.9.4 "Alpha Coverage"): a material in
//! `MASK` mode is fully opaque where its alpha (the base colour factor's alpha times the
//! base colour texture's texel alpha and the vertex colour's alpha) is greater than or
//! equal to its cutoff, and does
//! not exist for any ray where it is below: camera rays see what lies behind, shadow
//! rays pass, the AOV pass records what is behind. A material in `BLEND` mode stops the
//! fraction alpha of the light (docs/models.md, "Alpha coverage"): Whitted shows
//! `alpha·surface + (1 − alpha)·behind` and its shadow rays carry `1 − alpha`, the path
//! tracer passes the surface with probability `1 − alpha` and converges to the same.
//! Each scene is checked against what the specification says lands where (probes of
//! the CPU image), then rendered on the GPU and compared per pixel with the CPU
//! reference, Whitted and path traced.

use glam::{DMat4, DVec3};
use gpu_render::film::LinearImage as Film;
use gpu_render::scene::{
    AlphaMode, Environment, Image, Integrator, Light, Material, Mesh, RenderSettings, Scene,
    TextureMapping, TextureWrap,
};

use crate::support::quads::{
    EYE_Z, HEIGHT, WIDTH, assert_colour, assert_colour_within, at, camera, colour, pixel_at_uv,
    pixel_of, quad,
};
use crate::support::twins::{TWIN_TOLERANCE, assert_backends_agree};

/// The backdrop's plane, behind the quads (`crate::support::quads`).
const BACKDROP_Z: f64 = -1.0;

/// The backdrop's albedo, and the masked surfaces' (white).
const GREEN: DVec3 = DVec3::new(0.1, 0.8, 0.1);

/// The glTF default cutoff.
const CUTOFF: f64 = 0.5;

/// The pixel that sees the backdrop's point `(x, y, BACKDROP_Z)` (past z = 0).
fn pixel_of_backdrop(x: f64, y: f64) -> (u32, u32) {
    let scale = EYE_Z / (EYE_Z - BACKDROP_Z);
    pixel_of(x * scale, y * scale)
}

/// A green backdrop at z = BACKDROP_Z filling the view.
fn backdrop(material: u32) -> Mesh {
    let mut mesh = quad(
        material,
        vec![DMat4::from_translation(DVec3::new(0.0, 0.0, BACKDROP_Z))],
    );
    mesh.positions
        .iter_mut()
        .for_each(|p| *p *= DVec3::new(5.5, 2.0, 1.0));
    mesh.name = "backdrop".into();
    mesh
}

/// A scene of `meshes` lit by a Whitted ambient term of 1 and no light: a Lambert
/// surface's pixel shows its albedo, whatever shadows there would be. The path
/// integrator is lit by the background instead.
fn ambient_scene(materials: Vec<Material>, meshes: Vec<Mesh>, images: Vec<Image>) -> Scene {
    Scene {
        render: RenderSettings {
            width: WIDTH,
            height: HEIGHT,
            samples_per_pixel: 1,
            ..RenderSettings::default()
        },
        camera: camera(),
        environment: Environment {
            background: DVec3::splat(0.5),
            map: None,
            ambient: DVec3::ONE,
        },
        material_names: (0..materials.len()).map(|i| format!("m{i}")).collect(),
        materials,
        lights: vec![],
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

pub(crate) fn path_traced(scene: &Scene, samples: u32) -> Scene {
    let mut path = scene.clone();
    path.render.integrator = Integrator::Path;
    path.render.samples_per_pixel = samples;
    path
}

/// A white texture of 4 × 4 texels whose alpha is a checkerboard: 1 where `x + y` is
/// even, 0 where it is odd.
fn checker() -> Image {
    let texels = (0..16)
        .map(|i| {
            let (x, y) = (i % 4, i / 4);
            [1.0, 1.0, 1.0, if (x + y) % 2 == 0 { 1.0 } else { 0.0 }]
        })
        .collect();
    Image {
        path: "<checker>".into(),
        width: 4,
        height: 4,
        texels,
    }
}

/// A white Lambert material masked by texture 0's alpha at `cutoff`.
fn masked(cutoff: f64) -> Material {
    Material {
        albedo_texture: Some(0),
        texture_mapping: TextureMapping::Uv,
        alpha_mode: AlphaMode::Mask { cutoff },
        ..Material::lambert(DVec3::ONE)
    }
}

/// Checkered quads in front of the backdrop: one mesh placed twice (x = -1 and 1, an
/// instanced mesh) and one placed once (x = -3, world-space triangles).
pub(crate) fn checker_scene(mode: AlphaMode) -> Scene {
    let mut once = quad(0, vec![DMat4::IDENTITY]);
    once.positions.iter_mut().for_each(|p| p.x -= 3.0);
    ambient_scene(
        vec![
            Material {
                alpha_mode: mode,
                ..masked(CUTOFF)
            },
            Material::lambert(GREEN),
        ],
        vec![quad(0, vec![at(-1.0), at(1.0)]), once, backdrop(1)],
        vec![checker()],
    )
}

#[test]
fn a_masked_checker_shows_the_backdrop_exactly_where_alpha_is_below_the_cutoff() {
    let scene = checker_scene(AlphaMode::Mask { cutoff: CUTOFF });
    let cpu = gpu_render::cpu::render(&scene, None);
    let prepared = gpu_render::cpu::PreparedScene::new(&scene);
    for centre in [-3.0, -1.0, 1.0] {
        for (x, y) in (0..4).flat_map(|y| (0..4).map(move |x| (x, y))) {
            let (u, v) = ((f64::from(x) + 0.5) / 4.0, (f64::from(y) + 0.5) / 4.0);
            let pixel = pixel_at_uv(centre, u, v);
            let opaque = (x + y) % 2 == 0;
            let label = format!("quad at {centre}, texel ({x}, {y})");
            assert_colour(
                &label,
                &cpu.image,
                pixel,
                if opaque { DVec3::ONE } else { GREEN },
            );
            // The AOV pass's first hit is the quad, or the backdrop behind it.
            let aov = gpu_render::low_level::cpu::aov::trace_pixel_aov(&prepared, pixel.0, pixel.1);
            let on_quad = DVec3::new(centre - 0.9 + 1.8 * u, 0.9 - 1.8 * v, 0.0);
            let depth_beyond_quad = aov.depth > on_quad.distance(camera().eye) + 0.5;
            assert_eq!(
                depth_beyond_quad, !opaque,
                "{label}: AOV depth {}",
                aov.depth
            );
        }
    }
    gpu_agrees("alpha-mask-checker-whitted", &scene);
    gpu_agrees("alpha-mask-checker-path", &path_traced(&scene, 2));

    // Opaque, the same material shows white everywhere: alpha is ignored.
    let opaque = gpu_render::cpu::render(&checker_scene(AlphaMode::Opaque), None);
    assert_colour(
        "opaque",
        &opaque.image,
        pixel_at_uv(1.0, 0.375, 0.125),
        DVec3::ONE,
    );
}

/// Quads placed as [`checker_scene`]'s, untextured, white, with alpha 1 at their left
/// corners' vertex colours and 0 at their right ones' (glTF's `COLOR_0`, a factor of
/// the base colour's alpha, glTF 2.0 §3.7.2.1, §3.9.4): their alpha is `1 − u`.
fn vertex_alpha_scene(mode: AlphaMode) -> Scene {
    let opaque_left = |mut mesh: Mesh| {
        let alphas = [1.0, 0.0, 0.0, 1.0];
        mesh.colors = Some(alphas.map(|a| DVec3::ONE.extend(a)).to_vec());
        mesh
    };
    let mut once = opaque_left(quad(0, vec![DMat4::IDENTITY]));
    once.positions.iter_mut().for_each(|p| p.x -= 3.0);
    ambient_scene(
        vec![
            Material {
                alpha_mode: mode,
                ..Material::lambert(DVec3::ONE)
            },
            Material::lambert(GREEN),
        ],
        vec![
            opaque_left(quad(0, vec![at(-1.0), at(1.0)])),
            once,
            backdrop(1),
        ],
        vec![],
    )
}

#[test]
fn vertex_colour_alpha_multiplies_the_coverage() {
    // Masked at 0.5: the left half (alpha above 0.5) is there, the right half is not.
    let masked = vertex_alpha_scene(AlphaMode::Mask { cutoff: CUTOFF });
    let cpu = gpu_render::cpu::render(&masked, None);
    for centre in [-3.0, -1.0, 1.0] {
        for (u, expected) in [(0.2, DVec3::ONE), (0.8, GREEN)] {
            let label = format!("mask: quad at {centre}, u = {u}");
            assert_colour(&label, &cpu.image, pixel_at_uv(centre, u, 0.5), expected);
        }
    }
    gpu_agrees("vertex-alpha-mask-whitted", &masked);
    gpu_agrees("vertex-alpha-mask-path", &path_traced(&masked, 2));

    // Blended: alpha 1 − u of the white quad over the green backdrop.
    let blended = vertex_alpha_scene(AlphaMode::Blend);
    let cpu = gpu_render::cpu::render(&blended, None);
    for centre in [-3.0, -1.0, 1.0] {
        for u in [0.25, 0.5, 0.75] {
            let pixel = pixel_at_uv(centre, u, 0.5);
            let expected = DVec3::ONE * (1.0 - u) + GREEN * u;
            // A pixel spans 0.05 scene units, 0.028 of `u`: its colour is within 0.03.
            let label = format!("blend: quad at {centre}, u = {u}");
            assert_colour_within(&label, &cpu.image, pixel, expected, 0.03);
        }
    }
    gpu_agrees("vertex-alpha-blend-whitted", &blended);

    // Opaque, the vertex alpha is ignored as the material's is (§3.9.4).
    let opaque = gpu_render::cpu::render(&vertex_alpha_scene(AlphaMode::Opaque), None);
    assert_colour(
        "opaque",
        &opaque.image,
        pixel_at_uv(1.0, 0.8, 0.5),
        DVec3::ONE,
    );
}

/// A half-size quad whose left half is opaque and right half cut out (a 2 × 1 texture
/// of alpha 1 and 0, clamped: the bilinear alpha crosses 0.5 at x = 0), in front of
/// the backdrop, lit by a directional light slanted towards +x whose shadows on the
/// backdrop lie 0.5 to the right of what casts them.
pub(crate) fn shadow_scene() -> Scene {
    let mut leaf = quad(0, vec![DMat4::IDENTITY]);
    leaf.positions.iter_mut().for_each(|p| *p *= 0.5);
    let half = Image {
        path: "<half>".into(),
        width: 2,
        height: 1,
        texels: vec![[1.0, 1.0, 1.0, 1.0], [1.0, 1.0, 1.0, 0.0]],
    };
    let mut scene = ambient_scene(
        vec![
            Material {
                texture_wrap: [TextureWrap::ClampToEdge; 2],
                ..masked(CUTOFF)
            },
            Material::lambert(GREEN),
        ],
        vec![leaf, backdrop(1)],
        vec![half],
    );
    scene.environment.ambient = DVec3::ZERO;
    scene.environment.background = DVec3::ZERO;
    scene.lights = vec![Light::Directional {
        direction: DVec3::new(0.5, 0.0, -1.0).normalize(),
        irradiance: DVec3::splat(std::f64::consts::PI),
    }];
    scene
}

#[test]
fn a_masked_leaf_casts_a_shadow_shaped_like_its_opaque_part() {
    let scene = shadow_scene();
    let cpu = gpu_render::cpu::render(&scene, None);
    let lit = 2.0 / 5f64.sqrt(); // cos θ of the slanted light on a surface facing +z
    // The opaque half covers x in [-0.45, 0]: its shadow on the backdrop x in [0.05,
    // 0.5]; the cut-out half's would be x in [0.5, 0.95], which is lit.
    assert_colour(
        "the backdrop where only the cut-out half would shadow it",
        &cpu.image,
        pixel_of_backdrop(0.7, 0.0),
        GREEN * lit,
    );
    // Seen through the cut-out half, in the opaque half's shadow.
    assert_colour(
        "the opaque half's shadow, seen through the cut-out half",
        &cpu.image,
        pixel_of_backdrop(0.3, 0.0),
        DVec3::ZERO,
    );
    assert_colour(
        "the opaque half",
        &cpu.image,
        pixel_of(-0.2, 0.0),
        DVec3::ONE * lit,
    );
    gpu_agrees("alpha-mask-shadow-whitted", &scene);
    gpu_agrees("alpha-mask-shadow-path", &path_traced(&scene, 2));
}

#[test]
fn alpha_exactly_at_the_cutoff_is_opaque() {
    // Every value is exact in f32, so both backends compare the same numbers.
    let above = CUTOFF + 2f64.powi(-20);
    let half_alpha = Image {
        path: "<half alpha>".into(),
        width: 1,
        height: 1,
        texels: vec![[1.0, 1.0, 1.0, 0.5]],
    };
    let factor = |alpha: f64, cutoff: f64| Material {
        alpha,
        alpha_mode: AlphaMode::Mask { cutoff },
        ..Material::lambert(DVec3::ONE)
    };
    let materials = vec![
        // The factor alone at the cutoff: opaque.
        factor(0.5, CUTOFF),
        // Just below the cutoff: cut out.
        factor(0.5, above),
        // factor 0.5 × texel alpha 0.5 = 0.25 at a cutoff of 0.25: opaque.
        Material {
            alpha: 0.5,
            alpha_mode: AlphaMode::Mask { cutoff: 0.25 },
            ..masked(0.25)
        },
        // Opaque ignores alpha, even 0.
        Material {
            alpha: 0.0,
            ..Material::lambert(DVec3::ONE)
        },
        Material::lambert(GREEN),
    ];
    let meshes = vec![
        quad(0, vec![at(-3.0)]),
        quad(1, vec![at(-1.0)]),
        quad(2, vec![at(1.0)]),
        quad(3, vec![at(3.0)]),
        backdrop(4),
    ];
    let scene = ambient_scene(materials, meshes, vec![half_alpha]);
    let cpu = gpu_render::cpu::render(&scene, None);
    for (centre, expected) in [
        (-3.0, DVec3::ONE),
        (-1.0, GREEN),
        (1.0, DVec3::ONE),
        (3.0, DVec3::ONE),
    ] {
        assert_colour(
            &format!("quad at {centre}"),
            &cpu.image,
            pixel_of(centre, 0.0),
            expected,
        );
    }
    gpu_agrees("alpha-mask-cutoff", &scene);
}

/// The alpha of the blended quads.
const QUARTER: f64 = 0.25;

/// A white quad at x = 0 blended at alpha 0.25 (`material`'s kind and colours kept)
/// in front of the backdrop (`backdrop`).
fn blend_scene(material: Material, backdrop_material: Material) -> Scene {
    ambient_scene(
        vec![
            Material {
                alpha: QUARTER,
                alpha_mode: AlphaMode::Blend,
                ..material
            },
            backdrop_material,
        ],
        vec![quad(0, vec![DMat4::IDENTITY]), backdrop(1)],
        vec![],
    )
}

/// The mean colour of the pixels that see the square of side `side` centred at
/// `(x, y, 0)`.
fn mean_colour(film: &Film, (x, y): (f64, f64), side: f64) -> DVec3 {
    let (x0, y0) = pixel_of(x - side / 2.0, y + side / 2.0);
    let (x1, y1) = pixel_of(x + side / 2.0, y - side / 2.0);
    let mut sum = DVec3::ZERO;
    for row in y0..y1 {
        for column in x0..x1 {
            sum += colour(film, (column, row));
        }
    }
    sum / f64::from((x1 - x0) * (y1 - y0))
}

#[test]
fn blend_at_a_quarter_shows_a_quarter_of_the_surface_over_three_quarters_of_the_backdrop() {
    // Lit by the ambient term only (Whitted): the quad's radiance is 1, the
    // backdrop's its albedo.
    let ambient = blend_scene(Material::lambert(DVec3::ONE), Material::lambert(GREEN));
    let cpu = gpu_render::cpu::render(&ambient, None);
    let blended = DVec3::ONE * QUARTER + GREEN * (1.0 - QUARTER);
    assert_colour("ambient", &cpu.image, pixel_of(0.0, 0.0), blended);
    assert_colour("beside", &cpu.image, pixel_of(2.0, 0.0), GREEN);
    gpu_agrees("alpha-blend-ambient-whitted", &ambient);

    // Lit by a light along −z (irradiance π) instead: the backdrop behind the quad
    // gets the three quarters of the light the quad lets through (its shadow ray's
    // transmittance), the quad all of it.
    let mut lit = ambient.clone();
    lit.environment.ambient = DVec3::ZERO;
    lit.environment.background = DVec3::ZERO;
    lit.lights = vec![Light::Directional {
        direction: DVec3::NEG_Z,
        irradiance: DVec3::splat(std::f64::consts::PI),
    }];
    let cpu = gpu_render::cpu::render(&lit, None);
    let shadowed = DVec3::ONE * QUARTER + GREEN * (1.0 - QUARTER) * (1.0 - QUARTER);
    assert_colour("lit", &cpu.image, pixel_of(0.0, 0.0), shadowed);
    assert_colour("lit beside", &cpu.image, pixel_of(2.0, 0.0), GREEN);
    gpu_agrees("alpha-blend-lit-whitted", &lit);
    gpu_agrees("alpha-blend-lit-path", &path_traced(&lit, 4));
}

#[test]
fn the_path_tracer_s_stochastic_blend_converges_to_the_whitted_blend() {
    // Emitters, so that both integrators see the same radiance: the quad's 1, the
    // backdrop's green, nothing reflected.
    let emitter = |emission: DVec3| Material {
        emission,
        ..Material::blank(gpu_render::scene::MaterialKind::Emissive)
    };
    let mut scene = blend_scene(emitter(DVec3::ONE), emitter(GREEN));
    scene.environment = Environment::default();
    let expected = DVec3::ONE * QUARTER + GREEN * (1.0 - QUARTER);
    let whitted = gpu_render::cpu::render(&scene, None);
    assert_colour("whitted", &whitted.image, pixel_of(0.0, 0.0), expected);
    let path = path_traced(&scene, 64);
    let cpu = gpu_render::cpu::render(&path, None);
    // A 1 × 1 square: about 400 pixels of 64 samples, each hitting the quad with
    // probability 1/4; the mean's standard error is below 0.003.
    let mean = mean_colour(&cpu.image, (0.0, 0.0), 1.0);
    assert!(
        (mean - expected).abs().max_element() < 0.015,
        "path traced {mean}, expected {expected}"
    );
    // Every sample sees exactly one of the two: no pixel is brighter than the quad.
    assert!(
        cpu.image.pixels.iter().all(|p| p[0] <= 1.0 + 1e-6),
        "a pixel brighter than both surfaces"
    );
    gpu_agrees("alpha-blend-emitters-path", &path_traced(&scene, 8));
}

/// The corpus's ClearCoatTest (Khronos sample, `../shared/realworld`, read in place):
/// its `Partial_Coating` material is `BLEND` with a base colour texture whose alpha
/// varies, so it imports blended without a warning, its alpha read from the texture;
/// rendered, the texture's transparent parts let what lies behind the surface show, so
/// the image differs from the same scene with the material opaque, and only there.
#[test]
fn the_corpus_clear_coat_test_s_partial_coating_renders_blended() {
    let Some(model) =
        crate::corpus::corpus_model("assimp/test/models/glTF2/ClearCoat-glTF/ClearCoatTest.gltf")
    else {
        return;
    };
    assert!(
        model.warnings.iter().all(|w| !w.contains("alphaMode")),
        "{:?}",
        model.warnings
    );
    let coating = model
        .materials
        .iter()
        .find(|m| m.name.contains("Partial_Coating"))
        .expect("the Partial_Coating material");
    assert_eq!(coating.material.alpha_mode, AlphaMode::Blend);
    let texture = coating.base_color_texture.expect("its base colour texture");
    let alphas: Vec<f32> = model.images[texture.image as usize]
        .texels
        .iter()
        .map(|t| t[3])
        .collect();
    assert!(
        alphas.iter().any(|&a| a < 0.5) && alphas.iter().any(|&a| a > 0.5),
        "the texture's alpha varies"
    );
    let scene = model.into_scene(RenderSettings {
        width: 96,
        height: 72,
        ..RenderSettings::default()
    });
    let blended = gpu_render::cpu::render(&scene, None);
    let mut opaque_scene = scene.clone();
    for material in &mut opaque_scene.materials {
        material.alpha_mode = AlphaMode::Opaque;
    }
    let opaque = gpu_render::cpu::render(&opaque_scene, None);
    assert!(
        blended
            .image
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite())),
        "finite"
    );
    let differing = blended
        .image
        .pixels
        .iter()
        .zip(&opaque.image.pixels)
        .filter(|(a, b)| a != b)
        .count();
    eprintln!(
        "ClearCoatTest: {differing} of {} pixels differ from the opaque render",
        blended.image.pixels.len()
    );
    assert!(differing > 0, "the blend changes nothing");
    assert!(
        differing < blended.image.pixels.len() / 4,
        "{differing} pixels differ: more than the coated samples cover"
    );
}

/// The AOV pass sees what the image's camera ray stops at: on a mask, what lies behind
/// the cut-out parts; on a blended surface, the surface for the Whitted integrator and
/// the path integrator's stochastic choice for it, the same on both backends.
#[test]
fn the_aov_pass_sees_what_the_camera_ray_stops_at_on_both_backends() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let renderer = crate::support::gpu::renderer_with(
        &gpu,
        gpu_render::gpu::RendererOptions {
            aov: true,
            ..gpu_render::gpu::RendererOptions::default()
        },
    );
    let blend = blend_scene(Material::lambert(DVec3::ONE), Material::lambert(GREEN));
    for (label, scene) in [
        ("mask", checker_scene(AlphaMode::Mask { cutoff: CUTOFF })),
        ("blend-whitted", blend.clone()),
        ("blend-path", path_traced(&blend, 4)),
    ] {
        let cpu = gpu_render::low_level::cpu::aov::render_aovs(&scene);
        let gpu_aov = renderer
            .render(&gpu.device, &gpu.queue, &scene, None)
            .unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"))
            .aov
            .expect("asked for");
        let outliers = cpu
            .depth
            .iter()
            .zip(&gpu_aov.depth)
            .filter(|(a, b)| (*a - *b).abs() > 1e-3 + 1e-4 * a.abs())
            .count();
        eprintln!(
            "AOV {label}: {outliers} of {} depths differ",
            cpu.depth.len()
        );
        assert!(
            outliers <= cpu.depth.len() / 200,
            "AOV {label}: {outliers} depths differ"
        );
    }
}
