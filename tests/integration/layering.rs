//! The library's modules depend only downward (`src/lib.rs` names the layers): the
//! model and the math both tracers share know no tracer, `accel` knows neither tracer,
//! the CPU reference and the GPU backend know nothing of each other, and no two
//! modules use each other. Read from the sources: every `crate::NAME` outside a
//! comment is a use of the top-level module `NAME`. Inside each folder, the files (and
//! subfolders) use each other only in the cycles issue 51 lists, which may shrink but
//! not grow: `crate::`, `super::` and `self::` paths resolved to the folder's members.

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
    let cycles = cycles(&module_uses());
    assert!(cycles.is_empty(), "modules that use each other: {cycles:?}");
}

/// Each folder's cycles of files that use each other which are known and listed in
/// issue 51 ("import circles inside folders"), as the folder's module path and the
/// sorted members of the cycle's strongly connected component. The test fails on any
/// other cycle, and on a listed one that is gone (so that the list only shrinks).
const KNOWN_FOLDER_CYCLES: &[(&str, &[&str])] = &[
    ("accel", &["bvh", "geometry", "instance", "wide"]),
    ("cpu", &["path", "trace"]),
    ("gpu", &["area_lights", "layout", "upload"]),
    (
        "gpu",
        &[
            "cpu_device",
            "features",
            "pipelines",
            "ray_query",
            "scene_buffers",
            "shaders",
            "wavefront",
        ],
    ),
    ("gpu", &["denoiser", "film", "renderer"]),
];

/// The module path of a source file under `src/` (`scene/import/gltf/mod.rs` →
/// `scene::import::gltf`).
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("a file under src/");
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.strip_suffix(".rs").unwrap_or(&last).to_string();
    if stem != "mod" && stem != "lib" {
        parts.push(stem);
    }
    parts
}

/// The module paths a file's code names: `crate::a::b`, `super::x` (as many `super`s
/// as written), `self::y`, and the first names inside a group (`super::{a, b::c}`),
/// resolved against the file's own module path `at` (a `mod.rs` is its folder's
/// module, so its `super` is the folder's parent).
fn named_paths(code: &str, at: &[String]) -> Vec<Vec<String>> {
    let ident = |s: &str| -> usize {
        s.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(s.len())
    };
    let mut found = Vec::new();
    let mut rest = code;
    while let Some(start) = rest.find(['c', 's']) {
        let text = &rest[start..];
        let boundary = rest[..start]
            .chars()
            .last()
            .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'));
        let mut base: Option<Vec<String>> = None;
        let mut tail = text;
        if boundary {
            if let Some(after) = text.strip_prefix("crate::") {
                base = Some(Vec::new());
                tail = after;
            } else if text.starts_with("super::") || text.starts_with("self::") {
                let mut module = at.to_vec();
                while let Some(after) = tail.strip_prefix("super::") {
                    module.pop();
                    tail = after;
                }
                if let Some(after) = tail.strip_prefix("self::") {
                    tail = after;
                }
                base = Some(module);
            }
        }
        let Some(mut path) = base else {
            rest = &rest[start + 1..];
            continue;
        };
        // The named segments, then a group's first names.
        loop {
            let length = ident(tail);
            if length == 0 {
                break;
            }
            path.push(tail[..length].to_string());
            tail = &tail[length..];
            match tail.strip_prefix("::") {
                Some(after) => tail = after,
                None => break,
            }
        }
        if let Some(group) = tail.strip_prefix('{') {
            let mut depth = 0;
            let mut item_start = true;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if item_start && depth == 0 && !c.is_whitespace() => {
                        let length = ident(&group[i..]);
                        if length > 0 {
                            let mut item = path.clone();
                            item.push(group[i..i + length].to_string());
                            found.push(item);
                        }
                        item_start = false;
                    }
                    _ => {}
                }
            }
        }
        found.push(path);
        rest = &rest[start + 1..];
    }
    found
}

/// For each folder of `src/` (by module path), the uses between its members: each
/// `.rs` file but `mod.rs` and each subfolder, named by its module name, and the
/// members of the same folder its code names (a subfolder's files count for it).
fn folder_uses() -> BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> {
    let src = crate::support::repo_root().join("src");
    let mut folders: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    let mut members: BTreeMap<Vec<String>, BTreeSet<String>> = BTreeMap::new();
    let files: Vec<_> = rust_files(&src)
        .into_iter()
        .filter(|f| !f.starts_with(src.join("bin")))
        .collect();
    for file in &files {
        let module = module_path(&src, file);
        for depth in 0..module.len() {
            members
                .entry(module[..depth].to_vec())
                .or_default()
                .insert(module[depth].clone());
        }
    }
    for file in &files {
        let module = module_path(&src, file);
        let text = std::fs::read_to_string(file).expect("a source file");
        // Inline test modules (`#[cfg(test)] mod tests`, at the end of a file) name
        // their own file's items through `super`: they are left out.
        let text = match text.find("#[cfg(test)]\nmod tests") {
            Some(end) => &text[..end],
            None => &text[..],
        };
        let code: String = text
            .lines()
            .map(|line| line.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        // A file `a/b.rs` is module `a::b`, whose `super` is `a`; a `mod.rs` is its
        // folder's module `a`, whose `super` is a's parent.
        for named in named_paths(&code, &module) {
            for depth in 0..module.len() {
                let folder = &module[..depth];
                if named.len() > depth
                    && named[..depth] == *folder
                    && named[depth] != module[depth]
                    && members
                        .get(folder)
                        .is_some_and(|m| m.contains(&named[depth]))
                {
                    folders
                        .entry(folder.to_vec())
                        .or_default()
                        .entry(module[depth].clone())
                        .or_default()
                        .insert(named[depth].clone());
                }
            }
        }
    }
    folders
}

/// The strongly connected components of more than one member: the members that reach
/// each other (by search from each; `src/` and its folders have a few dozen members
/// at most).
fn cycles(uses: &BTreeMap<String, BTreeSet<String>>) -> Vec<BTreeSet<String>> {
    let nodes: Vec<&String> = uses
        .keys()
        .chain(uses.values().flatten())
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let reaches = |from: &String| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(node) = stack.pop() {
            for next in uses.get(&node).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<&String, BTreeSet<String>> =
        nodes.iter().map(|n| (*n, reaches(n))).collect();
    let mut components: Vec<BTreeSet<String>> = Vec::new();
    for node in &nodes {
        if components.iter().any(|c| c.contains(*node)) {
            continue;
        }
        let component: BTreeSet<String> = nodes
            .iter()
            .filter(|other| reach[*node].contains(**other) && reach[**other].contains(*node))
            .map(|other| (*other).clone())
            .collect();
        if component.len() > 1 {
            components.push(component);
        }
    }
    components
}

#[test]
fn no_two_files_of_a_folder_use_each_other_but_the_known_cycles() {
    let mut found = BTreeSet::new();
    for (folder, uses) in folder_uses() {
        for component in cycles(&uses) {
            let members: Vec<String> = component.into_iter().collect();
            found.insert((folder.join("::"), members));
        }
    }
    let known: BTreeSet<(String, Vec<String>)> = KNOWN_FOLDER_CYCLES
        .iter()
        .map(|(folder, members)| {
            (
                folder.to_string(),
                members.iter().map(|m| m.to_string()).collect(),
            )
        })
        .collect();
    let new: Vec<_> = found.difference(&known).collect();
    let gone: Vec<_> = known.difference(&found).collect();
    assert!(
        new.is_empty() && gone.is_empty(),
        "files of a folder that use each other, not listed in KNOWN_FOLDER_CYCLES: {new:?}; \
         listed but gone (remove them): {gone:?}"
    );
}
