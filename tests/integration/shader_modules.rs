//! The WGSL modules of `shaders/` declare what they use: each imports exactly the
//! modules whose declarations it names (no fewer, which composing it alone would hide
//! when another import brings them, and no more), and the import graph has no cycle.
//! That each module composed alone validates is tested beside the composer
//! (`src/gpu/shaders.rs`).

use std::collections::{BTreeMap, BTreeSet};

use gpu_render::gpu::ShaderFeatures;
use gpu_render::gpu::shaders::{HOST_MODULES, SHADER_MODULES, host_module, imports};
use gpu_render::gpu::unrolled::UnrolledPrimitives;

/// `source` without its `//` comments (the feature directives among them).
fn code_of(source: &str) -> String {
    source
        .lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The names a module declares at module scope: functions, structs, constants,
/// overrides, aliases and global variables, each written at the start of a line.
fn declarations(source: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in code_of(source).lines() {
        // Attributes first (`@group(0) @binding(1) var<storage> ...`).
        let mut rest = line;
        while let Some(after) = rest.strip_prefix('@') {
            rest = after
                .find(' ')
                .map_or("", |space| after[space..].trim_start());
        }
        for keyword in ["fn ", "struct ", "const ", "override ", "alias ", "var "] {
            if let Some(after) = rest.strip_prefix(keyword) {
                names.insert(identifier_at(after).to_string());
            }
        }
        if let Some(after) = rest.strip_prefix("var<") {
            let after = &after[after.find('>').map_or(after.len(), |i| i + 1)..];
            names.insert(identifier_at(after.trim_start()).to_string());
        }
    }
    names
}

fn identifier_at(text: &str) -> &str {
    let end = text
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(text.len());
    &text[..end]
}

/// The identifiers a module's code names: not member accesses (`a.name`), nor the
/// names that members, parameters and typed locals declare (`name: T`).
fn references(source: &str) -> BTreeSet<String> {
    let code = code_of(source);
    let mut names = BTreeSet::new();
    let mut previous = ' ';
    let mut chars = code.char_indices().peekable();
    while let Some((start, c)) = chars.next() {
        if c.is_ascii_alphabetic() || c == '_' {
            let mut end = start + c.len_utf8();
            while let Some(&(i, next)) = chars.peek() {
                if !(next.is_ascii_alphanumeric() || next == '_') {
                    break;
                }
                end = i + next.len_utf8();
                chars.next();
            }
            let declares = code[end..].trim_start().starts_with(':');
            if previous != '.' && !declares {
                names.insert(code[start..end].to_string());
            }
            previous = 'a';
        } else if !c.is_whitespace() {
            previous = c;
        }
    }
    names
}

/// Every module's text, the host's for `features` included.
fn module_texts(features: &ShaderFeatures) -> BTreeMap<String, String> {
    let mut texts: BTreeMap<String, String> = SHADER_MODULES
        .iter()
        .map(|m| (m.name.to_string(), m.source.to_string()))
        .collect();
    for name in HOST_MODULES {
        if let Some(text) = host_module(name, features) {
            texts.insert(name.to_string(), text);
        }
    }
    texts
}

/// The feature sets of the checks: every feature, none, each alone and each left out,
/// and the host's choices (uniform records, lanes that give way, an unrolled scene).
fn feature_sets() -> Vec<ShaderFeatures> {
    let none = ShaderFeatures {
        spheres: false,
        planes: false,
        polygons: false,
        triangles: false,
        refraction: false,
        blinn_phong: false,
        cook_torrance: false,
        oren_nayar: false,
        tabulated: false,
        pbr: false,
        textures: false,
        mesh_attributes: false,
        instances: false,
        path: false,
        environment_map: false,
        uniform_records: false,
        refill_lanes: false,
        unrolled: None,
    };
    type Toggle = fn(&mut ShaderFeatures, bool);
    let toggles: [Toggle; 15] = [
        |f, v| f.spheres = v,
        |f, v| f.planes = v,
        |f, v| f.polygons = v,
        |f, v| f.triangles = v,
        |f, v| f.refraction = v,
        |f, v| f.blinn_phong = v,
        |f, v| f.cook_torrance = v,
        |f, v| f.oren_nayar = v,
        |f, v| f.tabulated = v,
        |f, v| f.pbr = v,
        |f, v| f.textures = v,
        |f, v| f.mesh_attributes = v,
        |f, v| f.instances = v,
        |f, v| f.path = v,
        |f, v| f.environment_map = v,
    ];
    let unrolled = UnrolledPrimitives::for_scene(&[0], 1, &[]);
    assert!(unrolled.is_some(), "a sphere and a plane are unrolled");
    let mut sets = vec![
        ShaderFeatures::ALL,
        none,
        ShaderFeatures {
            uniform_records: true,
            refill_lanes: true,
            unrolled,
            ..ShaderFeatures::ALL
        },
    ];
    for toggle in toggles {
        let mut alone = none;
        toggle(&mut alone, true);
        let mut without = ShaderFeatures::ALL;
        toggle(&mut without, false);
        sets.extend([alone, without]);
    }
    sets
}

/// For each module, the modules it imports and the modules that declare the names it
/// uses, with `features` deciding every `//#if` block.
fn imports_and_uses(
    features: &ShaderFeatures,
) -> BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)> {
    let texts: BTreeMap<String, String> = module_texts(features)
        .into_iter()
        .map(|(name, text)| {
            let specialised = gpu_render::gpu::features::specialise(&text, features)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            (name, specialised)
        })
        .collect();
    let mut declared_by: BTreeMap<String, String> = BTreeMap::new();
    for (name, text) in &texts {
        for declared in declarations(text) {
            if let Some(other) = declared_by.insert(declared.clone(), name.clone()) {
                panic!("`{declared}` is declared by both {other} and {name}");
            }
        }
    }
    texts
        .iter()
        .map(|(name, text)| {
            let imported: BTreeSet<String> = imports(text, features)
                .unwrap_or_else(|e| panic!("{name}: {e}"))
                .into_iter()
                .collect();
            let used: BTreeSet<String> = references(text)
                .iter()
                .filter_map(|r| declared_by.get(r))
                .filter(|module| *module != name)
                .cloned()
                .collect();
            (name.clone(), (imported, used))
        })
        .collect()
}

#[test]
fn each_module_imports_exactly_the_modules_whose_names_it_uses() {
    let mut problems = Vec::new();
    for features in feature_sets() {
        for (name, (imported, used)) in imports_and_uses(&features) {
            let missing: Vec<_> = used.difference(&imported).collect();
            if !missing.is_empty() {
                problems.push(format!("{name} uses {missing:?} without importing them"));
            }
            // Every import is used where every feature is on; with fewer, an import
            // may serve only code the features leave out.
            if features == ShaderFeatures::ALL {
                let unused: Vec<_> = imported.difference(&used).collect();
                if !unused.is_empty() {
                    problems.push(format!("{name} imports {unused:?} but uses none of it"));
                }
            }
        }
        if problems.len() > 20 {
            break;
        }
    }
    problems.dedup();
    assert!(problems.is_empty(), "\n{}", problems.join("\n"));
}

/// The first import cycle of `graph` (`a -> b -> a`), if any.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        let current = path.last().cloned().unwrap_or_default();
        for next in graph.get(&current).into_iter().flatten() {
            if let Some(start) = path.iter().position(|m| m == next) {
                let mut cycle = path[start..].to_vec();
                cycle.push(next.clone());
                return Some(cycle);
            }
            if !done.contains(next) {
                path.push(next.clone());
                if let Some(cycle) = visit(graph, path, done) {
                    return Some(cycle);
                }
                path.pop();
            }
        }
        done.insert(current);
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|start| visit(graph, &mut vec![start.clone()], &mut done))
}

/// Each module's imports as written, whatever its `//#if` blocks decide.
fn import_graph() -> BTreeMap<String, BTreeSet<String>> {
    let unrolled = ShaderFeatures {
        unrolled: UnrolledPrimitives::for_scene(&[0], 1, &[]),
        ..ShaderFeatures::ALL
    };
    module_texts(&unrolled)
        .into_iter()
        .map(|(name, text)| {
            let imported = text
                .lines()
                .filter_map(|line| line.trim().strip_prefix("#import "))
                .map(|module| module.trim().to_string())
                .collect();
            (name, imported)
        })
        .collect()
}

#[test]
fn the_import_graph_has_no_cycle() {
    let graph = import_graph();
    if let Some(cycle) = find_cycle(&graph) {
        panic!("shader modules import each other: {}", cycle.join(" -> "));
    }
    // The search finds a cycle where there is one.
    let mut with_cycle = graph.clone();
    with_cycle
        .get_mut("types")
        .expect("types")
        .insert("wavefront".into());
    let cycle = find_cycle(&with_cycle).expect("a cycle through types");
    assert_eq!(cycle.first(), cycle.last());
    assert!(cycle.contains(&"types".to_string()) && cycle.contains(&"wavefront".to_string()));
}
