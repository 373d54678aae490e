//! Whole-pipeline fuzzing (proptest): valid but hostile scene files (see
//! `tests/integration/support/pipeline.rs` for what is generated) must parse, render on the CPU
//! reference and on the GPU (lavapipe in CI) without a panic, give finite pixels, and
//! agree per pixel in linear float within `|gpu - cpu| <= 1e-3 + 5e-3·|cpu|`, at most 2
//! pixels of an image (at most 12 × 10) outside it: the rule of `tests/integration/gpu_vs_cpu.rs`
//! with the edge outliers counted in pixels.
//!
//! CI runs a bounded number of cases from a fixed seed; `FUZZ_PIPELINE_CASES` and
//! `FUZZ_PIPELINE_SEED` change both, and `tools/src/bin/fuzz_campaign.rs` runs long
//! campaigns and records them in `docs/fuzzing.md`. Every fixed find is kept in
//! `tests/fixtures/pipeline-regressions/` and replayed here; the finds that are limits
//! of `f32` are kept in `tests/fixtures/pipeline-f32-limits/`, checked to get their load
//! warning.

use std::path::Path;

use crate::support::compare::{assert_images_match, output_dir};
use crate::support::pipeline::{Failed, PipelineChecker, TOLERANCE};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

/// Cases a plain `cargo test` runs (a few milliseconds each in the test profile on
/// lavapipe: the images are tiny). From this seed the first 200 pass; later ones hit
/// the finds of `docs/fuzzing.md` (the 250th, `ci-seed12-ground-sphere-far-wall`, is an
/// `f32` limit the loader warns about, found with the pixel sample pattern before
/// Sobol's).
const CI_CASES: u32 = 200;
/// The seed a plain `cargo test` uses, so that CI is reproducible.
const CI_SEED: u64 = 12;

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name} must be a whole number, got {v:?}"))
        })
        .unwrap_or(default)
}

/// A deterministic proptest RNG from a 64-bit seed.
fn rng(seed: u64) -> TestRng {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}

/// Writes the failing scene (and, with both images, the usual comparison images) under
/// `target/test-output/` and panics with where they are.
fn report_failure(name: &str, text: &str, failed: &Failed) -> ! {
    let dir = output_dir();
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("{name}.toml"));
    let written = std::fs::write(&path, text).map_or_else(
        |e| format!("(not written: {e})"),
        |()| path.display().to_string(),
    );
    if let Some((cpu, gpu)) = &failed.images {
        // Panics with the image paths when the images differ; otherwise fall through.
        let strict = crate::support::compare::Tolerance {
            outlier_fraction: crate::support::pipeline::OUTLIER_PIXELS as f64
                / cpu.pixels.len().max(1) as f64,
            ..TOLERANCE
        };
        let _ = std::panic::catch_unwind(|| assert_images_match(name, cpu, gpu, strict));
    }
    panic!(
        "{name}: {}\nscene: {written} (add it to tests/fixtures/pipeline-regressions/)\n{text}",
        failed.reason
    );
}

#[test]
fn random_hostile_scenes_render_alike_on_both_backends() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let checker = PipelineChecker::new(gpu);
    let cases = env_number("FUZZ_PIPELINE_CASES", u64::from(CI_CASES)) as u32;
    let seed = env_number("FUZZ_PIPELINE_SEED", CI_SEED);
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 256,
        ..Config::default()
    };
    fuzz(&checker, config, seed, "fuzz-pipeline-failure", |_| {});
}

/// Runs random scenes from `seed` through `checker` under `config`; on a failure,
/// minimises it, checks the minimal case again for its own images and reason, and
/// reports it under `name`. `visit` sees each case before it is checked.
fn fuzz(checker: &PipelineChecker, config: Config, seed: u64, name: &str, visit: impl Fn(&str)) {
    let mut runner = TestRunner::new_with_rng(config, rng(seed));
    let outcome = runner.run(&crate::support::pipeline::scene_text(), |text| {
        visit(&text);
        checker
            .check(&text)
            .map(|_| ())
            .map_err(|failed| TestCaseError::fail(failed.reason))
    });
    if let Err(error) = outcome {
        let minimal = match &error {
            proptest::test_runner::TestError::Fail(_, text) => text.clone(),
            other => panic!("the fuzzer stopped: {other}"),
        };
        let failed = checker.check(&minimal).err().unwrap_or_else(|| Failed {
            reason: format!("{error} (passed when checked again)"),
            images: None,
        });
        report_failure(name, &minimal, &failed);
    }
}

/// Cases with their primitives unrolled (`gpu_render::low_level::gpu::cpu_device::unrolled`, on CPU devices):
/// fewer, as each compiles a module of its own. Most are unrolled (at most seven
/// objects; the larger polygons' triangles may pass the limit).
const UNROLLED_CASES: u32 = 8;

/// The same check with the primitives of each case tested unrolled rather than through
/// the tree, from another seed.
#[test]
fn random_hostile_scenes_render_alike_unrolled() {
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let cpu_device = gpu.adapter_info().device_type == wgpu::DeviceType::Cpu;
    let checker = PipelineChecker::unrolled(gpu);
    let config = Config {
        cases: UNROLLED_CASES,
        failure_persistence: None,
        max_shrink_iters: 64,
        ..Config::default()
    };
    let unrolled = std::cell::Cell::new(0);
    fuzz(
        &checker,
        config,
        CI_SEED + 1,
        "fuzz-pipeline-unrolled-failure",
        |text| unrolled.set(unrolled.get() + usize::from(checker.unrolls(text))),
    );
    if cpu_device {
        assert!(
            unrolled.get() * 2 >= UNROLLED_CASES as usize,
            "only {} of {UNROLLED_CASES} cases were unrolled",
            unrolled.get()
        );
    }
}

/// Every scene that ever failed, replayed through the same check.
#[test]
fn regression_corpus_renders_alike_on_both_backends() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pipeline-regressions");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .expect("tests/fixtures/pipeline-regressions/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    assert!(
        !paths.is_empty(),
        "the corpus in {} is empty",
        dir.display()
    );
    let Some(gpu) = crate::support::gpu::headless_gpu() else {
        return;
    };
    let checker = PipelineChecker::new(gpu);
    for path in &paths {
        let text = std::fs::read_to_string(path).expect("readable");
        let name = format!(
            "pipeline-regression-{}",
            path.file_stem().and_then(|s| s.to_str()).unwrap_or("case")
        );
        match checker.check(&text) {
            Ok(passed) => eprintln!(
                "{name}: {} of {} pixels outside tolerance, max |Δ| {:.2e}",
                passed.comparison.outliers, passed.pixels, passed.comparison.max_abs_error
            ),
            Err(failed) => report_failure(&name, &text, &failed),
        }
    }
}

/// The finds that are limits of `f32` rather than bugs (`tests/fixtures/pipeline-f32-limits/`,
/// docs/fuzzing.md, groups 5 and 6) still differ between the backends, and the loader
/// says why at the object concerned: a sphere around the camera whose far side the GPU
/// places to more than 1e-2 of the scene, or two ground spheres closer near the camera
/// than the GPU can place them. No shipped scene gets either warning.
#[test]
fn finds_beyond_f32_are_warned_about_at_load() {
    use gpu_render::scene::{LoadOptions, SceneWarning, parse_scene_with};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let warnings_of = |path: &Path| {
        let text = std::fs::read_to_string(path).expect("readable");
        let warnings = std::sync::Mutex::new(Vec::new());
        let warn = |w: &SceneWarning| warnings.lock().expect("lock").push(w.to_string());
        let options = LoadOptions {
            warning: Some(&warn),
            ..Default::default()
        };
        parse_scene_with(&text, path, &options).expect("the scene loads");
        (text, warnings.into_inner().expect("lock"))
    };
    let limits = |w: &String| {
        w.contains("(sphere): radius")
            && (w.contains("on its far side") || w.contains("is in front"))
    };
    let gpu = crate::support::gpu::headless_gpu();
    let checker = gpu.map(PipelineChecker::new);
    let mut finds: Vec<_> = std::fs::read_dir(root.join("tests/fixtures/pipeline-f32-limits"))
        .expect("tests/fixtures/pipeline-f32-limits/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    finds.sort();
    assert!(finds.len() >= 4, "{finds:?}");
    for path in &finds {
        let (text, warnings) = warnings_of(path);
        assert!(
            warnings.iter().any(limits),
            "{}: no f32-limit warning: {warnings:?}",
            path.display()
        );
        // Still a difference: when the GPU agrees, the scene belongs in the regression
        // corpus (where it may keep its warning).
        if let Some(checker) = &checker {
            assert!(
                checker.check(&text).is_err(),
                "{} now renders alike on both backends: move it to \
                 tests/fixtures/pipeline-regressions/",
                path.display()
            );
        }
    }
    let mut scenes: Vec<_> = std::fs::read_dir(root.join("scenes"))
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(!scenes.is_empty());
    for path in scenes {
        let (_, warnings) = warnings_of(&path);
        assert!(
            !warnings.iter().any(limits),
            "{}: {warnings:?}",
            path.display()
        );
    }
}

/// The generator makes what `tests/integration/support/pipeline.rs` says, and every scene it makes
/// is accepted by the loader: otherwise the fuzzer would test less than it claims.
#[test]
fn generated_scenes_parse_and_are_hostile() {
    let mut runner = TestRunner::new_with_rng(Config::default(), rng(CI_SEED));
    let strategy = crate::support::pipeline::scene_text();
    let (mut many_vertices, mut many_lights, mut deep, mut shells, mut huge) = (0, 0, 0, 0, 0);
    let cases = 300;
    for _ in 0..cases {
        let text = strategy
            .new_tree(&mut runner)
            .expect("a scene is generated")
            .current();
        let scene = gpu_render::scene::parse_scene(&text, Path::new("<fuzz>"))
            .unwrap_or_else(|e| panic!("a generated scene does not parse: {e}\n{text}"));
        many_vertices += usize::from(scene.shapes.iter().any(
            |s| matches!(s, gpu_render::scene::Shape::Polygon { vertices, .. } if vertices.len() >= 100),
        ));
        many_lights += usize::from(scene.lights.len() >= 20);
        deep += usize::from(scene.render.max_depth >= 60);
        let spheres = |min_radius: f64| {
            scene
                .shapes
                .iter()
                .filter(|s| {
                    matches!(s, gpu_render::scene::Shape::Sphere { radius, .. } if *radius >= min_radius)
                })
                .count()
        };
        shells += usize::from(spheres(0.0) >= 5);
        let scale: f64 = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# scale "))
            .and_then(|s| s.parse().ok())
            .expect("the first line names the scale");
        huge += usize::from(spheres(999.0 * scale) >= 1);
    }
    for (what, count) in [
        ("a polygon of 100 or more vertices", many_vertices),
        ("20 or more lights", many_lights),
        ("a depth of 60 or more", deep),
        ("5 or more spheres (nested shells)", shells),
        ("a ground sphere of radius 1e3 or 1e4", huge),
    ] {
        assert!(
            count >= cases / 50,
            "only {count} of {cases} generated scenes have {what}"
        );
    }
}
