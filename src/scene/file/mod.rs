//! The TOML scene-file format (see `docs/scene-format.md`): reading, parsing into the
//! raw serde structures of [`raw`], and validating into a [`Scene`].
//!
//! Every failure is a [`SceneError`] naming the file, the 1-based line:column where
//! the offending item (or, for syntax and type errors, the offending token) begins,
//! and the problem.

mod check;
mod lights;
mod materials;
mod objects;
mod raw;
mod settings;

use std::io::Read;
use std::path::Path;

use self::check::Source;
pub use self::materials::CONDUCTOR_PRESETS;
use self::objects::MaterialTable;
use self::raw::RawScene;
use super::{Scene, SceneError};

/// Largest scene file accepted, in bytes (64 MiB).
pub const MAX_SCENE_FILE_BYTES: u64 = 64 * 1024 * 1024;
/// Largest accepted number of objects plus polygon and triangle vertices.
pub const MAX_SCENE_ELEMENTS: usize = 1_000_000;

/// Reads and validates the scene file at `path`.
///
/// Fails without reading when `path` is a directory or larger than
/// `MAX_SCENE_FILE_BYTES` (64 MiB); an OS error (missing file, no permission) is named.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = read_scene_file(path)?;
    parse_scene(&text, path)
}

/// Parses and validates scene text; `path` is only used in error messages.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let source = Source { path, text };
    if text.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(source.error(None, too_large_message(text.len() as u64)));
    }
    let raw: RawScene = toml::from_str(text).map_err(|e| toml_error(&source, &e))?;
    check_element_count(&source, &raw)?;
    build_scene(&source, raw)
}

fn read_scene_file(path: &Path) -> Result<String, SceneError> {
    let fail = |message: String| SceneError {
        path: path.to_path_buf(),
        location: None,
        message,
    };
    let metadata =
        std::fs::metadata(path).map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    if metadata.is_dir() {
        return Err(fail("cannot read the scene file: it is a directory".into()));
    }
    if metadata.len() > MAX_SCENE_FILE_BYTES {
        return Err(fail(too_large_message(metadata.len())));
    }
    let file =
        std::fs::File::open(path).map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(fail(too_large_message(bytes.len() as u64)));
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "cannot read the scene file: it is not valid UTF-8 (at byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

fn too_large_message(bytes: u64) -> String {
    format!(
        "the scene file is {bytes} bytes, more than the {MAX_SCENE_FILE_BYTES} (64 MiB) accepted"
    )
}

/// A TOML syntax or type error, located at its span, with the key path it concerns.
fn toml_error(source: &Source<'_>, error: &toml::de::Error) -> SceneError {
    let location = error.span().map(|span| source.location(span.start));
    let message = match toml_error_keys(error) {
        Some(keys) => format!("{keys}: {}", error.message()),
        None => error.message().to_owned(),
    };
    source.error(location, message)
}

/// The dotted key path (`objects.radius`) a toml error concerns, if it says.
///
/// toml shows the keys only in its `Display` and only when it has no input to quote,
/// so this renders a copy without input and picks the trailing "in `...`" line.
fn toml_error_keys(error: &toml::de::Error) -> Option<String> {
    let mut bare = error.clone();
    bare.set_input(None);
    let rendered = bare.to_string();
    let last = rendered.trim_end().lines().last()?;
    let keys = last.strip_prefix("in `")?.strip_suffix('`')?;
    (!keys.is_empty() && rendered.trim_end() != error.message().trim_end())
        .then(|| format!("`{keys}`"))
}

/// Guards against absurd input: too many objects and vertices to be a sane scene.
fn check_element_count(source: &Source<'_>, raw: &RawScene) -> Result<(), SceneError> {
    let vertices: usize = raw
        .objects
        .iter()
        .map(|o| o.get_ref().vertices.as_ref().map_or(0, Vec::len))
        .sum();
    let total = raw.objects.len() + vertices;
    if total > MAX_SCENE_ELEMENTS {
        return Err(source.error(
            None,
            format!(
                "the scene has {} objects and {vertices} polygon/triangle vertices, \
                 {total} in total, more than the {MAX_SCENE_ELEMENTS} accepted",
                raw.objects.len()
            ),
        ));
    }
    Ok(())
}

/// Validates every table and item, in file order within each section.
fn build_scene(source: &Source<'_>, raw: RawScene) -> Result<Scene, SceneError> {
    let render = settings::render(source, raw.render)?;
    let camera = settings::camera(source, raw.camera)?;
    let environment = settings::environment(source, raw.environment)?;
    let mut material_names = Vec::with_capacity(raw.materials.len());
    let mut materials = Vec::with_capacity(raw.materials.len());
    let mut images = materials::ImageTable {
        base: source.path.parent().unwrap_or(std::path::Path::new("")),
        images: Vec::new(),
    };
    for (name, material) in raw.materials {
        materials.push(materials::material(source, &name, material, &mut images)?);
        material_names.push(name);
    }
    let lights = raw
        .lights
        .into_iter()
        .enumerate()
        .map(|(i, light)| lights::light(source, i, light))
        .collect::<Result<_, _>>()?;
    let table = MaterialTable::new(&material_names);
    let shapes = raw
        .objects
        .into_iter()
        .enumerate()
        .map(|(i, object)| objects::object(source, &table, i, object))
        .collect::<Result<_, _>>()?;
    Ok(Scene {
        render,
        camera,
        environment,
        materials,
        material_names,
        lights,
        shapes,
        images: images.images,
    })
}

#[cfg(test)]
mod tests;
