//! The path integrator under an environment map against an independent renderer: the
//! Lambert scene `tests/fixtures/mitsuba/env-lambert.toml` (three spheres on a floor
//! under the shipped sky, turned by 30°) at 48 × 27 pixels, rendered by Mitsuba 3.6.4's
//! path tracer with its `envmap` emitter at 65,536 samples per pixel
//! (`scripts/mitsuba/environment_reference.py`, the reference committed as
//! `tests/fixtures/mitsuba/env-lambert-48.exr`), and here with 1,024.
//!
//! The tolerance is that of `tests/integration/path_reference.rs`, per pixel and channel: `z =
//! (ours − reference) / sqrt(s²/n + s²/n_ref)` with `s²` our pixel's sample variance;
//! at most 0.5% of the values may have |z| > 4, and each channel's image mean must
//! agree within 4 of its standard error and within 0.5%. Both renderers look the map up
//! bilinearly with Mitsuba's texel convention, so the map goes to Mitsuba as it is and
//! no model difference is allowed for (until the lookups were bilinear here, the
//! script enlarged the map 8 times and the sky seen directly needed a 0.2% allowance).
//! The sky seen directly, smooth across a pixel, leaves our estimate almost no
//! variance, so there `b =` [`ROUNDING`] times the reference is added to σ in
//! quadrature (Mitsuba's `f32` film: measured at most 0.023% apart on the rows of pure
//! sky), and a value without variance must agree within `b`. The measured figures are
//! in docs/path-tracing.md and BENCHMARKS.md.

use std::path::Path;

use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::low_level::cpu::trace::PreparedScene;
use gpu_render::low_level::cpu::traverse::intersect_scene;
use gpu_render::scene::load_scene;

const WIDTH: u32 = 48;
const HEIGHT: u32 = 27;
const SAMPLES: u32 = 1024;
const REFERENCE_SAMPLES: f64 = 65_536.0;
/// The relative difference allowed, in quadrature, on the sky seen directly, which
/// only rounding (Mitsuba's `f32` film) separates from the reference: measured at most
/// 2.3e-4 on the rows of pure sky.
const ROUNDING: f64 = 5e-4;

#[test]
fn an_environment_lit_scene_agrees_with_mitsuba_within_its_statistical_error() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scene =
        load_scene(&root.join("tests/fixtures/mitsuba/env-lambert.toml")).expect("scene");
    scene.render.width = WIDTH;
    scene.render.height = HEIGHT;
    scene.render.samples_per_pixel = SAMPLES;
    let prepared = PreparedScene::new(&scene);
    let ours = crate::support::reference::render_with_variance(&prepared, WIDTH, HEIGHT, SAMPLES);
    // Whether each pixel's centre ray escapes: the background seen directly.
    let escapes = |i: u32| {
        let (x, y) = (f64::from(i % WIDTH) + 0.5, f64::from(i / WIDTH) + 0.5);
        let ray = Ray {
            origin: prepared.camera.eye,
            direction: prepared.camera.ray_direction(x, y, WIDTH, HEIGHT),
        };
        intersect_scene(&prepared.geometry, &ray, f64::INFINITY).is_none()
    };
    let reference = image::open(root.join("tests/fixtures/mitsuba/env-lambert-48.exr"))
        .expect("the Mitsuba reference")
        .to_rgb32f();
    assert_eq!(reference.dimensions(), (WIDTH, HEIGHT));

    let mut gathered = crate::support::reference::ReferenceComparison::default();
    let mut background_values = 0;
    for (i, (mean, variance)) in ours.iter().enumerate() {
        let r = reference.get_pixel(i as u32 % WIDTH, i as u32 / WIDTH);
        let background = escapes(i as u32);
        background_values += usize::from(background) * 3;
        for c in 0..3 {
            let expected = f64::from(r[c]);
            let statistical = variance[c] / f64::from(SAMPLES) + variance[c] / REFERENCE_SAMPLES;
            gathered.our_total[c] += mean[c];
            gathered.reference_total[c] += expected;
            gathered.total_variance[c] += statistical;
            let b = if background { ROUNDING * expected } else { 0.0 };
            if statistical > 0.0 {
                gathered
                    .z_values
                    .push((mean[c] - expected) / (statistical + b * b).sqrt());
            } else {
                assert!(
                    background && (mean[c] - expected).abs() <= b,
                    "pixel {i} channel {c}: {} against {expected} with no variance",
                    mean[c]
                );
            }
        }
    }
    assert!(
        background_values > 300,
        "{background_values} background values"
    );
    gathered.assert_agrees();
}
