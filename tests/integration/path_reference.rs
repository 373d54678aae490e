//! The path integrator against an independent renderer: the Cornell box
//! (`scenes/cornell-box.toml`) at 32 × 32 pixels, rendered by Mitsuba 3's path tracer
//! with 65,536 samples per pixel (`scripts/mitsuba/path_reference.py`, the reference
//! committed as `tests/fixtures/mitsuba/cornell-box-32.exr`), and here with 1,024.
//!
//! The tolerance is statistical, per pixel and channel: the difference over its
//! standard error, `z = (ours − reference) / sqrt(s²/n + s²/n_ref)` with `s²` the
//! sample variance of our pixel's samples (the reference's error taken as that of the
//! same variance at its sample count). A correct integrator gives z of about unit
//! spread: at most 0.5% of the values may have |z| > 4 (a normal variable exceeds 4
//! once in 16,000). Against bias, each channel's image mean must agree within 4 of its
//! standard error (the pixels are independent, so the variances add) and within 0.5%.

use std::path::Path;

use gpu_render::low_level::cpu::trace::PreparedScene;
use gpu_render::scene::load_scene;

const SIZE: u32 = 32;
const SAMPLES: u32 = 1024;
const REFERENCE_SAMPLES: f64 = 65_536.0;

#[test]
fn the_cornell_box_agrees_with_mitsuba_within_its_statistical_error() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scene = load_scene(&root.join("scenes/cornell-box.toml")).expect("scene");
    scene.render.width = SIZE;
    scene.render.height = SIZE;
    scene.render.samples_per_pixel = SAMPLES;
    let prepared = PreparedScene::new(&scene);
    let ours = crate::support::reference::render_with_variance(&prepared, SIZE, SIZE, SAMPLES);
    let reference = image::open(root.join("tests/fixtures/mitsuba/cornell-box-32.exr"))
        .expect("the Mitsuba reference")
        .to_rgb32f();
    assert_eq!(reference.dimensions(), (SIZE, SIZE));

    let mut gathered = crate::support::reference::ReferenceComparison::default();
    for (i, (mean, variance)) in ours.iter().enumerate() {
        let r = reference.get_pixel(i as u32 % SIZE, i as u32 / SIZE);
        for c in 0..3 {
            let expected = f64::from(r[c]);
            let error = (variance[c] / f64::from(SAMPLES) + variance[c] / REFERENCE_SAMPLES).sqrt();
            gathered.our_total[c] += mean[c];
            gathered.reference_total[c] += expected;
            gathered.total_variance[c] += error * error;
            if error > 0.0 {
                gathered.z_values.push((mean[c] - expected) / error);
            } else {
                // A pixel without variance (the lamp seen directly) must agree exactly,
                // to f32.
                assert!(
                    (mean[c] - expected).abs() <= 1e-5 * expected.max(1.0),
                    "pixel {i} channel {c}: {} against {expected} with no variance",
                    mean[c]
                );
            }
        }
    }
    gathered.assert_agrees();
}
