//! Property-based fuzzing of the scene parser (proptest): whatever the text, `parse_scene`
//! returns (never panics) within a second, and a scene it accepts renders a finite image
//! on the CPU at 8 × 6 pixels, one sample per pixel.
//!
//! Inputs are the shipped scenes mutated (spliced tokens, numbers replaced by NaN,
//! infinities, huge, tiny and denormal values, deletions) or truncated, and random
//! TOML-like documents built from the format's own keys. Every input that ever failed is
//! kept in `tests/fixtures/fuzz-regressions/` and replayed by
//! `regression_corpus_parses_and_renders`.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::Config;

/// Longest a parse may take (it takes microseconds; this catches runaway loops).
const PARSE_BUDGET: Duration = Duration::from_secs(1);

/// Parses `text`; if it is accepted, renders it small on the CPU. Panics (a test
/// failure) if the parser panics or is slow, or the image has a NaN or infinity.
fn check_scene_text(text: &str) {
    let started = Instant::now();
    let parsed =
        std::panic::catch_unwind(|| gpu_render::scene::parse_scene(text, Path::new("<fuzz>")));
    let elapsed = started.elapsed();
    let parsed = match parsed {
        Ok(parsed) => parsed,
        Err(_) => panic!("parse_scene panicked on:\n{text}"),
    };
    assert!(
        elapsed < PARSE_BUDGET,
        "parse_scene took {elapsed:?} on:\n{text}"
    );
    let Ok(mut scene) = parsed else { return };
    scene.render.width = 8;
    scene.render.height = 6;
    scene.render.samples_per_pixel = 1;
    let rendered = gpu_render::cpu::render(&scene, None);
    assert!(
        rendered
            .image
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite())),
        "non-finite pixel rendering:\n{text}"
    );
}

fn shipped_scenes() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("readable scene"))
        .collect()
}

/// Number spellings at the edges of f64 and f32, and some that TOML rejects.
const NUMBERS: &[&str] = &[
    "nan",
    "+nan",
    "-nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1.8e308",
    "1e-320",
    "5e-324",
    "1e-45",
    "1e-40",
    "3.4028236e38",
    "1e39",
    "-0.0",
    "0",
    "0.0",
    "1",
    "-1",
    "1e6",
    "1e-6",
    "65536",
    "4294967296",
    "18446744073709551616",
    "-9223372036854775809",
    "0x10",
    "1_000",
    "1e",
    ".5",
    "[]",
    "[nan, nan, nan]",
    "[0, 0, 0]",
    "[1e308, 1e308, 1e308]",
    "[1e-320, 0, 0]",
    "\"\"",
    "true",
];

/// Keys, section headers and fragments of the scene format.
const TOKENS: &[&str] = &[
    "[render]",
    "[camera]",
    "[environment]",
    "[[lights]]",
    "[[objects]]",
    "[materials.m]",
    "width",
    "height",
    "samples_per_pixel",
    "max_depth",
    "stack_size",
    "lighting",
    "eye",
    "look_at",
    "up",
    "fov_y_degrees",
    "background",
    "ambient",
    "type",
    "albedo",
    "diffuse",
    "specular",
    "shininess",
    "reflectance",
    "ior",
    "transmittance",
    "coat_ior",
    "emission",
    "position",
    "intensity",
    "color",
    "direction",
    "irradiance",
    "center",
    "radius",
    "normal",
    "point",
    "vertices",
    "material",
    "\"m\"",
    "\"sphere\"",
    "\"plane\"",
    "\"polygon\"",
    "\"triangle\"",
    "\"point\"",
    "\"directional\"",
    "\"lambert\"",
    "\"blinn-phong\"",
    "\"mirror\"",
    "\"dielectric\"",
    "\"emissive\"",
    "=",
    "\n",
    " ",
    "[",
    "]",
    ",",
    "#",
    "\"",
    "'",
    "{",
    "}",
    ".",
];

/// One edit of a scene text.
#[derive(Debug, Clone)]
enum Edit {
    /// Replace the number-like run of characters at this fraction of the text.
    Number(f64, usize),
    /// Insert a token here.
    Insert(f64, usize),
    /// Delete this many bytes here.
    Delete(f64, usize),
}

fn edit_strategy() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0.0..1.0f64, 0..NUMBERS.len()).prop_map(|(at, n)| Edit::Number(at, n)),
        (0.0..1.0f64, 0..TOKENS.len()).prop_map(|(at, n)| Edit::Insert(at, n)),
        (0.0..1.0f64, 1..40usize).prop_map(|(at, n)| Edit::Delete(at, n)),
    ]
}

/// The char boundary nearest below `fraction` of `text`'s length.
fn boundary(text: &str, fraction: f64) -> usize {
    let mut at = ((text.len() as f64) * fraction) as usize;
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn apply(text: &mut String, edit: &Edit) {
    match *edit {
        Edit::Number(fraction, n) => {
            // The number (or word) under the position: a run of [0-9a-z.+-_].
            let at = boundary(text, fraction);
            let is_part = |c: char| c.is_ascii_alphanumeric() || "+-._".contains(c);
            let start = text[..at]
                .char_indices()
                .rev()
                .take_while(|&(_, c)| is_part(c))
                .last()
                .map_or(at, |(i, _)| i);
            let end = text[at..]
                .char_indices()
                .find(|&(_, c)| !is_part(c))
                .map_or(text.len(), |(i, _)| at + i);
            text.replace_range(start..end, NUMBERS[n]);
        }
        Edit::Insert(fraction, n) => {
            let at = boundary(text, fraction);
            text.insert_str(at, TOKENS[n]);
        }
        Edit::Delete(fraction, n) => {
            let start = boundary(text, fraction);
            let mut end = (start + n).min(text.len());
            while !text.is_char_boundary(end) {
                end += 1;
            }
            text.replace_range(start..end, "");
        }
    }
}

/// A random TOML-like document: sections of `key = value` lines drawn from the format's
/// own vocabulary, values from [`NUMBERS`] or tokens.
fn toml_ish() -> impl Strategy<Value = String> {
    let line = (0..TOKENS.len(), 0..NUMBERS.len() + TOKENS.len()).prop_map(|(k, v)| {
        let value = NUMBERS
            .get(v)
            .copied()
            .unwrap_or_else(|| TOKENS[v - NUMBERS.len()]);
        format!(
            "{} = {value}\n",
            TOKENS[k].trim_matches(|c| c == '[' || c == ']')
        )
    });
    let section = (0..6usize, prop::collection::vec(line, 0..8))
        .prop_map(|(h, lines)| format!("{}\n{}", TOKENS[h], lines.concat()));
    prop::collection::vec(section, 0..8).prop_map(|sections| sections.concat())
}

fn config() -> Config {
    Config {
        cases: 192,
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_shipped_scenes_never_panic(
        scene in 0..4usize,
        edits in prop::collection::vec(edit_strategy(), 1..6),
    ) {
        let scenes = shipped_scenes();
        let mut text = scenes[scene % scenes.len()].clone();
        for edit in &edits {
            apply(&mut text, edit);
        }
        check_scene_text(&text);
    }

    #[test]
    fn truncated_shipped_scenes_never_panic(scene in 0..4usize, fraction in 0.0..1.0f64) {
        let scenes = shipped_scenes();
        let text = &scenes[scene % scenes.len()];
        check_scene_text(&text[..boundary(text, fraction)]);
    }

    #[test]
    fn random_toml_like_documents_never_panic(text in toml_ish()) {
        check_scene_text(&text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        check_scene_text(&text);
    }
}

/// Every scene text that ever failed, replayed.
#[test]
fn regression_corpus_parses_and_renders() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fuzz-regressions");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&dir).expect("tests/fixtures/fuzz-regressions/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).expect("readable");
            check_scene_text(&text);
            replayed += 1;
        }
    }
    assert!(replayed > 0, "the corpus in {} is empty", dir.display());
}

/// The unmutated scenes the fuzzers start from parse and render through the same
/// check, so that the render half of `check_scene_text` is exercised, not vacuous.
#[test]
fn seed_scenes_parse_and_render_through_the_check() {
    let mut rendered = 0;
    for text in shipped_scenes() {
        // Scenes with image or model files (textures, BRDF maps, environment maps,
        // models) cannot resolve them from `<fuzz>`; the rest must parse.
        if text.contains("albedo_texture")
            || text.contains("brdf_map")
            || text.contains("map = \"")
            || text.contains("type = \"model\"")
        {
            continue;
        }
        assert!(
            gpu_render::scene::parse_scene(&text, Path::new("<fuzz>")).is_ok(),
            "a seed scene does not parse:\n{text}"
        );
        check_scene_text(&text);
        rendered += 1;
    }
    assert!(rendered >= 3, "only {rendered} seed scenes rendered");
}
