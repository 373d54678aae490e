//! The library's modules depend only downward (`src/lib.rs` names the layers): the
//! model and the math both tracers share know no tracer, `accel` knows neither tracer,
//! the CPU reference and the GPU backend know nothing of each other, and no two
//! modules use each other. Read from the sources: every `crate::NAME` outside a
//! comment is a use of the top-level module `NAME`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The layer below both tracers (and `accel`), which may use none of them.
const SHARED: [&str; 8] = [
    "scene", "input", "color", "sample", "texture", "camera", "noise", "film",
];
/// The two tracers.
const TRACERS: [&str; 2] = ["cpu", "gpu"];

/// Each top-level module of `src/` (a file or a folder; not the programs of
/// `src/bin`) and the other top-level modules its code uses.
fn module_uses() -> BTreeMap<String, BTreeSet<String>> {
    let src = crate::support::repo_root().join("src");
    let mut uses = BTreeMap::new();
    for entry in std::fs::read_dir(&src).expect("src/") {
        let path = entry.expect("entry").path();
        let Some(name) = path.file_stem().and_then(|n| n.to_str()) else {
            continue;
        };
        if name == "lib" || name == "bin" {
            continue;
        }
        let mut used = BTreeSet::new();
        for file in rust_files(&path) {
            let text = std::fs::read_to_string(&file).expect("a source file");
            for line in text.lines() {
                let code = line.split("//").next().unwrap_or("");
                for (at, _) in code.match_indices("crate::") {
                    let rest = &code[at + "crate::".len()..];
                    let end = rest
                        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                        .unwrap_or(rest.len());
                    if end > 0 && &rest[..end] != name {
                        used.insert(rest[..end].to_string());
                    }
                }
            }
        }
        uses.insert(name.to_string(), used);
    }
    uses
}

fn rust_files(path: &Path) -> Vec<std::path::PathBuf> {
    if path.is_dir() {
        let mut files = Vec::new();
        for entry in std::fs::read_dir(path).expect("a folder") {
            files.extend(rust_files(&entry.expect("entry").path()));
        }
        files
    } else if path.extension().is_some_and(|e| e == "rs") {
        vec![path.to_path_buf()]
    } else {
        Vec::new()
    }
}

#[test]
fn the_shared_layer_and_accel_use_no_tracer_and_the_tracers_not_each_other() {
    let uses = module_uses();
    for module in SHARED.iter().chain(["accel"].iter()) {
        let used = &uses[*module];
        for upper in TRACERS.iter().chain(["accel"].iter()) {
            assert!(!used.contains(*upper), "{module} uses {upper}: {used:?}");
        }
    }
    assert!(!uses["cpu"].contains("gpu"), "cpu uses gpu");
    assert!(!uses["gpu"].contains("cpu"), "gpu uses cpu");
}

#[test]
fn no_two_modules_use_each_other() {
    let uses = module_uses();
    // Depth-first search for a path back to where it started.
    fn cycle_from(
        uses: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        let current = path.last().cloned().unwrap_or_default();
        for next in uses.get(&current).into_iter().flatten() {
            if let Some(start) = path.iter().position(|m| m == next) {
                let mut cycle = path[start..].to_vec();
                cycle.push(next.clone());
                return Some(cycle);
            }
            if done.contains(next) {
                continue;
            }
            path.push(next.clone());
            if let Some(cycle) = cycle_from(uses, path, done) {
                return Some(cycle);
            }
            path.pop();
        }
        done.insert(current);
        None
    }
    let mut done = BTreeSet::new();
    for module in uses.keys() {
        if let Some(cycle) = cycle_from(&uses, &mut vec![module.clone()], &mut done) {
            panic!("modules use each other: {}", cycle.join(" -> "));
        }
    }
}
