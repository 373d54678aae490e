//! Conformance over a corpus of real model files written by other tools: every `.obj`,
//! `.gltf` and `.glb` under `../shared/realworld` (relative to the repository root;
//! `README.md` there gives each file's origin and purpose) is imported with
//! [`import_model`] and, when it imports, rendered on the CPU reference tracer at 16x12
//! with one sample per pixel. Each file's outcome is compared with the committed table
//! `tests/fixtures/corpus/expected.tsv`:
//!
//! - `renders`, the number of world-space triangles and the number of warnings, or
//! - `refused` and a short, stable reason (the class of the error, without paths or
//!   numbers: `unsupported required extension KHR_draco_mesh_compression`, `no
//!   triangles`, ...); every such reason is a limitation listed in `docs/models.md`.
//!
//! Any difference, a file that newly renders as much as one newly refused, fails the
//! test with a list of every changed file. When a change is intended, rewrite the table
//! and commit it with the change:
//!
//! ```text
//! GPU_RENDER_BLESS=1 cargo test --test integration corpus::
//! ```
//!
//! `GPU_RENDER_CORPUS=DIR` reads the corpus from `DIR` instead. Where the corpus is
//! absent (it is not part of the repository) the test says so and passes, unless
//! `GPU_RENDER_REQUIRE_CORPUS` is set. `GPU_RENDER_CORPUS_VERBOSE=1` prints every
//! file's full error message and warnings.

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use gpu_render::scene::RenderSettings;
use gpu_render::scene::import::import_model;

/// The committed table, relative to the crate root.
const EXPECTED: &str = "tests/fixtures/corpus/expected.tsv";

/// Image size of the smoke render: enough rays to reach the model, few enough that the
/// whole corpus renders in seconds.
const WIDTH: u32 = 16;
const HEIGHT: u32 = 12;

/// The corpus folder: `GPU_RENDER_CORPUS`, else `../shared/realworld`.
pub(crate) fn corpus_root() -> PathBuf {
    match std::env::var_os("GPU_RENDER_CORPUS") {
        Some(dir) => PathBuf::from(dir),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld"),
    }
}

/// The corpus file at `relative` (to [`corpus_root`]) imported, for tests that judge
/// one model as its own README says; `None`, with a notice, where the corpus is absent,
/// unless `GPU_RENDER_REQUIRE_CORPUS` is set (then a failure, as for the conformance
/// test).
pub(crate) fn corpus_model(relative: &str) -> Option<gpu_render::scene::import::ImportedModel> {
    model_in_place(&corpus_root().join(relative), relative)
}

/// The Khronos sample model at `relative` (to `../shared/khronos-sample-assets`)
/// imported, as [`corpus_model`] imports a corpus file (absent: skipped with a notice,
/// or a failure under `GPU_RENDER_REQUIRE_CORPUS`).
pub(crate) fn khronos_sample_model(
    relative: &str,
) -> Option<gpu_render::scene::import::ImportedModel> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/khronos-sample-assets");
    model_in_place(&root.join(relative), relative)
}

/// The model file at `path` imported (`relative` names it in messages), read in place.
fn model_in_place(path: &Path, relative: &str) -> Option<gpu_render::scene::import::ImportedModel> {
    if !path.exists() {
        let notice = format!("{} is absent", path.display());
        assert!(!flag("GPU_RENDER_REQUIRE_CORPUS"), "{notice}");
        eprintln!("note: {notice}; skipped");
        return None;
    }
    Some(import_model(path).unwrap_or_else(|e| panic!("{relative}: {e}")))
}

fn flag(name: &str) -> bool {
    std::env::var_os(name).is_some_and(|v| !v.is_empty() && v != "0")
}

/// Every model file under `root`, as paths relative to it with `/` separators, sorted.
fn model_files(root: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut folders = vec![root.to_path_buf()];
    while let Some(folder) = folders.pop() {
        let entries = std::fs::read_dir(&folder)
            .unwrap_or_else(|e| panic!("cannot list {}: {e}", folder.display()));
        for entry in entries {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                folders.push(path);
            } else if gpu_render::scene::import::is_model_path(&path) {
                let relative = path.strip_prefix(root).expect("under the root");
                let parts: Vec<String> = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                found.push(parts.join("/"));
            }
        }
    }
    found.sort();
    found
}

/// The reason class of an import error: what kind of problem it is, without the file,
/// the element's name or index, or counts, so that the table stays stable when only
/// those change.
fn refusal_reason(message: &str) -> String {
    /// Known problems, by a phrase of their message, and their class.
    const CLASSES: &[(&str, &str)] = &[
        ("no triangles", "no triangles"),
        ("not a finite number", "non-finite position"),
        ("is out of range", "index out of range"),
        ("refers to vertex", "index out of range"),
        ("index is 0", "index 0"),
        ("is reached twice", "node reached twice"),
        ("cannot read", "missing or unreadable file"),
        ("does not load", "texture does not load"),
    ];
    let word_after = |phrase: &str| {
        let at = message.find(phrase)? + phrase.len();
        message[at..]
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .find(|w| !w.is_empty())
    };
    if let Some(extension) = word_after("requires the extension ") {
        return format!("unsupported required extension {extension}");
    }
    if let Some(mode) = word_after("its mode is ") {
        return format!("primitive mode {mode}");
    }
    for (phrase, class) in CLASSES {
        if message.contains(phrase) {
            return (*class).to_string();
        }
    }
    // Unclassified: the first clause, numbers as N.
    let clause = message.split(['(', ';']).next().unwrap_or(message);
    clause
        .split_whitespace()
        .take(10)
        .map(|w| {
            if w.chars().any(|c| c.is_ascii_digit()) {
                "N"
            } else {
                w
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Imports and renders the file at `path`; the table's row for it (without the file).
fn outcome(path: &Path, verbose: bool) -> String {
    let model = match import_model(path) {
        Ok(model) => model,
        Err(e) => {
            if verbose {
                eprintln!("{e}");
            }
            return format!("refused\t{}", refusal_reason(e.message()));
        }
    };
    if verbose {
        for warning in &model.warnings {
            eprintln!("  warning: {warning}");
        }
    }
    let render = RenderSettings {
        width: WIDTH,
        height: HEIGHT,
        ..RenderSettings::default()
    };
    let image = gpu_render::cpu::render(&model.into_scene(render), None).image;
    if image.pixels.iter().flatten().any(|c| !c.is_finite()) {
        return "renders a non-finite image".into();
    }
    format!(
        "renders\t{} triangles\t{} warnings",
        model.world_triangle_count(),
        model.warnings.len()
    )
}

fn parse_table(text: &str) -> BTreeMap<String, String> {
    text.lines()
        .filter(|line| !line.is_empty() && !line.starts_with('#'))
        .map(|line| match line.split_once('\t') {
            Some((file, outcome)) => (file.to_string(), outcome.to_string()),
            None => (line.to_string(), String::new()),
        })
        .collect()
}

#[test]
fn every_corpus_file_imports_or_is_refused_as_the_table_says() {
    let root = corpus_root();
    if !root.is_dir() {
        let notice = format!(
            "the model corpus is not at {} (set GPU_RENDER_CORPUS to its folder)",
            root.display()
        );
        assert!(!flag("GPU_RENDER_REQUIRE_CORPUS"), "{notice}");
        eprintln!("note: {notice}; the conformance test is skipped");
        return;
    }
    let verbose = flag("GPU_RENDER_CORPUS_VERBOSE");
    let files = model_files(&root);
    assert!(!files.is_empty(), "no model files under {}", root.display());
    let mut actual = BTreeMap::new();
    for file in &files {
        if verbose {
            eprintln!("{file}");
        }
        let path = root.join(file);
        let row = catch_unwind(AssertUnwindSafe(|| outcome(&path, verbose)))
            .unwrap_or_else(|_| "panics".to_string());
        actual.insert(file.clone(), row);
    }

    let expected_path = Path::new(env!("CARGO_MANIFEST_DIR")).join(EXPECTED);
    if flag("GPU_RENDER_BLESS") {
        let mut text = String::from(
            "# Outcome of every model file of the corpus (tests/integration/corpus.rs): \
             file, then `renders`, triangles, warnings or `refused`, reason.\n\
             # Rewritten by GPU_RENDER_BLESS=1 cargo test --test integration corpus::\n",
        );
        for (file, row) in &actual {
            text.push_str(&format!("{file}\t{row}\n"));
        }
        std::fs::create_dir_all(expected_path.parent().expect("has a folder"))
            .expect("create the fixture folder");
        std::fs::write(&expected_path, text).expect("write the table");
        eprintln!("wrote {}", expected_path.display());
        return;
    }
    let expected_text = std::fs::read_to_string(&expected_path).unwrap_or_else(|e| {
        panic!(
            "cannot read {}: {e}; create it with GPU_RENDER_BLESS=1",
            expected_path.display()
        )
    });
    let expected = parse_table(&expected_text);
    let mut changes = Vec::new();
    for (file, row) in &actual {
        match expected.get(file) {
            None => changes.push(format!("  new      {file}\n           now: {row}")),
            Some(before) if before != row => changes.push(format!(
                "  changed  {file}\n           was: {before}\n           now: {row}"
            )),
            Some(_) => {}
        }
    }
    for (file, before) in &expected {
        if !actual.contains_key(file) {
            changes.push(format!("  gone     {file}\n           was: {before}"));
        }
    }
    assert!(
        changes.is_empty(),
        "{} of {} corpus files differ from {EXPECTED}:\n{}\n\
         If the change is intended, run GPU_RENDER_BLESS=1 cargo test --test integration corpus:: and commit the table.",
        changes.len(),
        actual.len(),
        changes.join("\n")
    );
}
