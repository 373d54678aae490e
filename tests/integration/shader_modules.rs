//! The WGSL modules of `shaders/` declare what they use: each imports exactly the
//! modules whose declarations it names (no fewer, which composing it alone would hide
//! when another import brings them, and no more), the import graph has no cycle, and
//! every WGSL function has a Rust twin of the same name in the Rust file of the same
//! name, but for the short list below. That each module composed alone validates is
//! tested beside the composer (`src/gpu/shaders.rs`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use gpu_render::gpu::ShaderFeatures;
use gpu_render::low_level::gpu::cpu_device::unrolled::UnrolledPrimitives;
use gpu_render::low_level::gpu::shaders::{
    HOST_MODULES, SHADER_MODULES, host_module, imports, shader_module,
};

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
        alpha: false,
        aov: false,
        uniform_records: false,
        node_texture: false,
        refill_lanes: false,
        lockstep_samples: false,
        unrolled: None,
        hardware_traversal: false,
    };
    type Toggle = fn(&mut ShaderFeatures, bool);
    let toggles: [Toggle; 17] = [
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
        |f, v| f.alpha = v,
        |f, v| f.aov = v,
    ];
    let unrolled = UnrolledPrimitives::for_scene(&[0], 1, &[]);
    assert!(unrolled.is_some(), "a sphere and a plane are unrolled");
    let mut sets = vec![
        ShaderFeatures::ALL,
        // Every feature: the general module of a scene with alpha coverage.
        ShaderFeatures {
            alpha: true,
            ..ShaderFeatures::ALL
        },
        none,
        ShaderFeatures {
            uniform_records: true,
            refill_lanes: true,
            lockstep_samples: true,
            unrolled,
            ..ShaderFeatures::ALL
        },
        // The hardware traversal, with and without alpha coverage.
        ShaderFeatures {
            hardware_traversal: true,
            ..ShaderFeatures::ALL
        },
        ShaderFeatures {
            hardware_traversal: true,
            alpha: true,
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
            let specialised = gpu_render::low_level::gpu::features::specialise(&text, features)
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
    let every = ShaderFeatures {
        alpha: true,
        hardware_traversal: true,
        ..ShaderFeatures::ALL
    };
    let mut problems = Vec::new();
    for features in feature_sets() {
        for (name, (imported, used)) in imports_and_uses(&features) {
            let missing: Vec<_> = used.difference(&imported).collect();
            if !missing.is_empty() {
                problems.push(format!("{name} uses {missing:?} without importing them"));
            }
            // Every import is used where every feature is on (the general module
            // with alpha coverage); with fewer, an import may serve only code the
            // features leave out.
            if features == every {
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

/// WGSL functions without a Rust function of the same name in the Rust file of the
/// same name, and why: (module, functions or `*` for the whole module, reason). Keep it
/// short: a new function gets a twin, or a reason as good as these.
const WITHOUT_RUST_TWIN: &[(&str, &[&str], &str)] = &[
    (
        "texture",
        &["material_texels", "slot_image"],
        "a hit's four texture lookups gathered in one loop over the slots, so that \
         lavapipe, which inlines every call, compiles the filtered lookup once per call \
         site; the CPU reference makes the same lookups where it uses them \
         (shading_material, mapped_normal in src/texture.rs)",
    ),
    (
        "wavefront",
        &["*"],
        "the trace kernels and their schedule of slots, phases and dispatches: the CPU \
         traces a pixel's rays in one loop (src/cpu/trace.rs); the host is \
         src/gpu/wavefront.rs",
    ),
    (
        "slot",
        &["*"],
        "a slot's bounce stack, trace record and pixel kept between dispatches: the CPU \
         keeps them in the locals of its loop",
    ),
    (
        "unrolled",
        &["*"],
        "the unrolled primitive tests of small scenes on lavapipe, a GPU-only strategy \
         (src/gpu/cpu_device/unrolled.rs writes the calls)",
    ),
    (
        "ray_query",
        &["*"],
        "the hardware traversal's ray queries, a GPU-only path (src/gpu/ray_query.rs \
         builds its structures); the CPU reference and the software walk are what \
         tests/integration/ray_query.rs compares it with",
    ),
    (
        "draw",
        &["*"],
        "the raster pass that draws a film into the caller's attachment (src/gpu/draw.rs)",
    ),
    (
        "bxdf_eval",
        &["*"],
        "the test kernel of tests/integration/bxdf_gpu_twin.rs",
    ),
    (
        "math",
        &["*"],
        "what std and glam give the CPU: f64::is_nan, max_element, normalize_or_zero, \
         indexing a vector by a number",
    ),
    (
        "traverse",
        &[
            "traversal_ray",
            "resumed_ray",
            "start_traversal",
            "test_planes",
            "traversal_done",
            "next_leaf_prim",
            "leave_instance",
            "enter_child",
            "traversal_stack_index",
            "store_stacked",
            "push_child",
            "spill_window",
            "pop_child",
            "visit_wide_node",
            "node_step",
        ],
        "the steps of the resumable, budgeted traversal, whose state lives in a TraceRay \
         and the slot's stack: the CPU walks a tree in one call (Query::walk) and \
         recurses into instances",
    ),
    (
        "traverse",
        &["unpack_bytes", "dequantize", "slab_axis", "sort_pair"],
        "the vector arithmetic of child_entries and the sort of visit_wide_node: the CPU \
         decodes a child's box in WideNode::child_box (src/accel/wide.rs, whose dequantize \
         is the same f32 sum) and sorts a slice in Query::walk",
    ),
    (
        "trace",
        &[
            "consume_miss",
            "consume_closest_hit",
            "consume_shadow_ray",
            "finish_lights",
        ],
        "shade_hit and direct_light cut at each shadow ray into the wavefront's steps",
    ),
    (
        "trace",
        &["resolve_surface"],
        "the part of shade_hit and of path_radiance's bounce that both integrators share          (the hit's textures, normals and Fresnel weights), gathered in one function so          that lavapipe, which inlines every call, compiles it once in the shading kernel          (issue 50: the general shading kernel 50 s -> 40 s)",
    ),
    (
        "path",
        &[
            "path_random",
            "path_emitter_sample",
            "path_continue",
            "path_miss",
            "path_closest_hit",
            "path_start_emitter",
            "path_consume_emitter",
            "path_blend_seed",
        ],
        "path_radiance's loop body cut at each shadow ray into the wavefront's steps, \
         with the path's random numbers and state in its slot",
    ),
    (
        "aov",
        &[
            "aov_mode",
            "aov_index",
            "clear_pixel_aov",
            "add_missed_aov",
            "add_first_hit_aov",
        ],
        "the passes' sums kept in the accumulation buffer between a slot's samples: the \
         CPU sums them in the locals of trace_pixel_aov",
    ),
    (
        "denoise",
        &[
            "tap_index",
            "prepare_film_signal",
            "demodulate_signal",
            "remodulate_signal",
        ],
        "the kernels of the steps src/denoise.rs runs in one call over whole images \
         (denoise's loops), and a film's sums read as its input",
    ),
    (
        "intersect",
        &["prim_kind", "prim_index"],
        "PrimRef::kind and PrimRef::index (src/accel/geometry.rs), on the bit layout \
         whose constants types.wgsl holds",
    ),
    (
        "intersect",
        &["inside_polygon_points"],
        "point_in_polygon's even-odd loop over the vertices projected at upload \
         (polygon_points); the CPU projects them as it goes",
    ),
    (
        "intersect",
        &["world_attributes"],
        "the attributes half of Instance::world_triangle, which the GPU reads apart \
         from the corners",
    ),
    (
        "instance",
        &["load_instance", "instance_point", "instance_normal"],
        "a placement unpacked from the bvh_nodes records src/gpu/upload.rs packs it in, \
         and its transforms: glam's DAffine3 and normal matrix on the CPU",
    ),
    (
        "environment",
        &[
            "environment_present",
            "environment_texel_radiance",
            "environment_function_offset",
            "environment_conditional_offset",
            "environment_marginal_offset",
        ],
        "reads of the one buffer src/gpu/environment.rs packs the map, its sampling \
         function and its CDFs in; the CPU holds an Option of the map and its \
         distributions",
    ),
    (
        "area_lights",
        &["emitter_count", "emitter_before"],
        "the emitter records as the GPU holds them (one EMITTER_NONE record for none) \
         and their order for the binary search: a Vec and partition_point on the CPU",
    ),
];

/// The Rust files under `src/`.
fn rust_files(path: &Path) -> Vec<PathBuf> {
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

/// `CamelCase` as `snake_case`, a digit run a word of its own (`Distribution1D`:
/// `distribution_1d`).
fn snake_case(name: &str) -> String {
    let mut snake = String::new();
    let mut previous: Option<char> = None;
    for c in name.chars() {
        if let Some(p) = previous {
            let new_word = (c.is_ascii_uppercase() && p.is_ascii_lowercase())
                || (c.is_ascii_digit() && p.is_ascii_alphabetic());
            if new_word {
                snake.push('_');
            }
        }
        snake.push(c.to_ascii_lowercase());
        previous = Some(c);
    }
    snake
}

/// The names under which a WGSL function may twin the Rust file `text`: its
/// functions, the names it re-exports (`pub use path::name;`), and each method `m` of
/// a type `T` as `t_m` (and `T::new` as `t`), since WGSL has neither methods nor
/// namespaces.
fn rust_names(text: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    let mut impl_type: Option<String> = None;
    // Tests are no twins: they follow the code, at the end of the file.
    let code_end = text.find("#[cfg(test)]").unwrap_or(text.len());
    for line in text[..code_end].lines() {
        let code = line.split("//").next().unwrap_or("");
        if let Some(rest) = code.strip_prefix("impl") {
            // `impl<T> Trait for Type {` or `impl Type {`: the type is the last word.
            let head = rest.split('{').next().unwrap_or("");
            let head = head.rsplit(" for ").next().unwrap_or(head);
            impl_type = head
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .rfind(|w| w.starts_with(|c: char| c.is_ascii_uppercase()))
                .map(snake_case);
        } else if code.starts_with('}') {
            impl_type = None;
        }
        if let Some(at) = code.find("fn ") {
            let before = &code[..at];
            if before.is_empty() || before.ends_with(' ') || before.ends_with('(') {
                let name = identifier_at(&code[at + 3..]).to_string();
                if let (Some(t), true) = (&impl_type, line.starts_with("    ")) {
                    names.insert(format!("{t}_{name}"));
                    if name == "new" {
                        names.insert(t.clone());
                    }
                }
                names.insert(name);
            }
        }
        if let Some(rest) = code.trim().strip_prefix("pub use ") {
            for word in rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
                names.insert(word.to_string());
            }
        }
    }
    names
}

/// The names under which a function of the module `name` has a Rust twin in
/// `rust_files`: those of its Rust files of the same name.
fn twin_names(name: &str, rust_files: &[PathBuf]) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for file in rust_files
        .iter()
        .filter(|f| f.file_stem().is_some_and(|s| s == name))
    {
        names.extend(rust_names(
            &std::fs::read_to_string(file).expect("a source"),
        ));
    }
    names
}

/// Whether `function` of the module `module` is among `names`, as it is or without the
/// module's name as its prefix (`environment_to_local`: `EnvironmentMap::to_local`).
fn has_twin(module: &str, function: &str, names: &BTreeSet<String>) -> bool {
    names.contains(function)
        || function
            .strip_prefix(&format!("{module}_"))
            .is_some_and(|rest| names.contains(rest))
}

/// The functions declared in `source`.
fn functions(source: &str) -> Vec<String> {
    declarations(source)
        .into_iter()
        .filter(|name| code_of(source).contains(&format!("fn {name}(")))
        .collect()
}

/// Whether the list excuses `function` of module `module`.
fn allowed(module: &str, function: &str) -> bool {
    WITHOUT_RUST_TWIN.iter().any(|(m, functions, _)| {
        *m == module && functions.iter().any(|f| *f == "*" || *f == function)
    })
}

/// The functions of the module `name` (text `source`) without a twin in `rust_files`
/// that the list does not excuse.
fn functions_without_twin(name: &str, source: &str, rust_files: &[PathBuf]) -> Vec<String> {
    let names = twin_names(name, rust_files);
    functions(source)
        .into_iter()
        .filter(|function| !has_twin(name, function, &names) && !allowed(name, function))
        .collect()
}

#[test]
fn every_wgsl_function_has_a_rust_twin_of_the_same_name() {
    let files = rust_files(&crate::support::repo_root().join("src"));
    let missing: Vec<String> = SHADER_MODULES
        .iter()
        .flat_map(|module| {
            functions_without_twin(module.name, module.source, &files)
                .into_iter()
                .map(move |function| format!("shaders/{}.wgsl: {function}", module.name))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "WGSL functions without a Rust twin of the same name in a Rust file of the \
         module's name (rename one side, or move it to the file of the right name):\n  {}",
        missing.join("\n  ")
    );
    // A new function is found: `luminance` has its twin in src/color.rs, `glitter`
    // none.
    let added = "fn luminance(c: vec3<f32>) -> f32 { return c.x; }\nfn glitter() {}\n";
    assert_eq!(functions_without_twin("color", added, &files), ["glitter"]);
}

/// Every function on the list exists and has no twin, so that the list only shrinks.
#[test]
fn the_list_of_functions_without_a_twin_is_current() {
    let files = rust_files(&crate::support::repo_root().join("src"));
    for (module, listed, reason) in WITHOUT_RUST_TWIN {
        assert!(!reason.is_empty(), "{module}: no reason");
        let source = shader_module(module).unwrap_or_else(|| panic!("no module {module}"));
        let declared = functions(source);
        let names = twin_names(module, &files);
        for function in listed.iter().filter(|f| **f != "*") {
            assert!(
                declared.iter().any(|d| d == function),
                "{module}::{function} is on the list but is no WGSL function"
            );
            assert!(
                !has_twin(module, function, &names),
                "{module}::{function} has a Rust twin: take it off the list"
            );
        }
    }
}
