//! The TOML scene-file format (see `docs/scene-format.md`): reading, parsing into the
//! raw serde structures of [`raw`], and validating into a [`Scene`].
//!
//! Every failure is a [`SceneError`] naming the file, the 1-based line:column where
//! the offending item (or, for syntax and type errors, the offending token) begins,
//! and the problem.

mod animation;
mod budget;
mod check;
mod lights;
mod materials;
mod objects;
mod paths;
mod raw;
mod settings;
mod structure;

use std::io::Read;
use std::path::Path;

use self::check::Source;
pub use self::materials::CONDUCTOR_PRESETS;
use self::objects::MaterialTable;
pub use self::paths::{SandboxError, confined_path};
use self::raw::RawScene;
pub(crate) use self::settings::view_problem;
use super::{CameraPath, Scene, SceneError, SceneWarning};
use crate::echo::{echo, short};
use crate::input::InputError;

/// Largest scene file accepted, in bytes (64 MiB).
pub const MAX_SCENE_FILE_BYTES: u64 = 64 * 1024 * 1024;
/// Largest accepted number of objects plus polygon and triangle vertices.
pub const MAX_SCENE_ELEMENTS: usize = 1_000_000;
/// Largest accepted number of TOML values (tables, arrays, numbers, strings), counted
/// before parsing as the `=`, `,`, `[` and `{` outside strings and comments (an upper
/// bound). Loading needs about 375 bytes per counted value at its peak (measured:
/// 742k spheres, 6.7M counted, 2.5 GB), so this bounds it at about 3 GB; the largest
/// legitimate files (64 MiB of spheres, or the 1,000,000-element limit in triangles,
/// 4.2M counted) are below it, while 64 MiB of `[],` counts 44.7 million.
pub const MAX_SCENE_VALUES: u64 = 8_000_000;

/// How a scene file is loaded: whether the files it names are confined to its folder,
/// and who hears about progress and warnings. The default confines nothing and is
/// silent, as [`load_scene`] is.
#[derive(Clone, Copy, Default)]
pub struct LoadOptions<'a> {
    /// Confine the files the scene names (albedo textures, BRDF maps, the environment
    /// map) to the scene
    /// file's folder: refuse absolute paths, `..` and links that lead out of it (see
    /// [`confined_path`]). Without it a scene file is trusted input, like a program:
    /// it may name any file the user can read.
    pub sandbox: bool,
    /// Told what the loader is doing as it goes, for a progress display. Called often
    /// (for every item), so it should be cheap.
    pub progress: Option<&'a (dyn Fn(LoadProgress) + Sync)>,
    /// Told about each suspicious input that was accepted, and what was done about it
    /// (an albedo texel above 1, clamped to 1).
    pub warning: Option<&'a (dyn Fn(&SceneWarning) + Sync)>,
    /// The most bytes the load may hold: the images the scene names (the environment
    /// map, albedo textures, BRDF maps), each counted from its header before it is
    /// decoded, together with what decoding it holds for a moment; and each model file
    /// it places, within what the images leave
    /// ([`crate::scene::import::ImportOptions::max_bytes`]). A scene too large is
    /// refused before it takes the memory. `None`: the fixed limits only.
    pub max_bytes: Option<u64>,
}

impl std::fmt::Debug for LoadOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadOptions")
            .field("sandbox", &self.sandbox)
            .field("progress", &self.progress.is_some())
            .field("warning", &self.warning.is_some())
            .field("max_bytes", &self.max_bytes)
            .finish()
    }
}

/// What the loader is doing, for [`LoadOptions::progress`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LoadProgress {
    /// Reading the file, `bytes` long.
    Reading {
        /// The file's size.
        bytes: u64,
    },
    /// Parsing `bytes` of TOML (one step; the longest for a large file).
    Parsing {
        /// The text's size.
        bytes: u64,
    },
    /// Reading a model file (one placed by the scene, or the model rendered on its
    /// own): `done` of its `total` bytes.
    Importing {
        /// Bytes read so far.
        done: u64,
        /// The file's bytes.
        total: u64,
    },
    /// Checking the items (materials, lights, objects): `done` of `total`.
    Checking {
        /// Items checked so far.
        done: u64,
        /// All items.
        total: u64,
    },
}

impl LoadOptions<'_> {
    fn report(&self, progress: LoadProgress) {
        if let Some(hook) = self.progress {
            hook(progress);
        }
    }
}

/// Reads and validates the scene file at `path`.
///
/// Fails without reading when `path` is not a regular file (a directory, a FIFO, a
/// device) or larger than `MAX_SCENE_FILE_BYTES` (64 MiB); an OS error (missing file,
/// no permission) is named.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with(path, &LoadOptions::default())
}

/// [`load_scene`] with options: a sandbox, a progress hook and a warning hook.
pub fn load_scene_with(path: &Path, options: &LoadOptions<'_>) -> Result<Scene, SceneError> {
    load_scene_file(path, options).map(|file| file.scene)
}

/// What a scene file defines: the scene (with the `[camera]` table's camera) and,
/// if it has an `[animation]` table, its camera path.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneFile {
    /// The scene, as [`load_scene`] returns it.
    pub scene: Scene,
    /// The camera path of `[animation]`, if there is one; render frame `k` with
    /// [`CameraPath::frame_camera`].
    pub camera_path: Option<CameraPath>,
}

/// [`load_scene_with`], keeping the camera path of an `[animation]` table.
pub fn load_scene_file(path: &Path, options: &LoadOptions<'_>) -> Result<SceneFile, SceneError> {
    let text = read_scene_file(path, options)?;
    parse_scene_file(&text, path, options)
}

/// Parses and validates scene text; `path` is only used in error messages and to
/// resolve the image files the scene names.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, SceneError> {
    parse_scene_with(text, path, &LoadOptions::default())
}

/// [`parse_scene`] with options: a sandbox, a progress hook and a warning hook.
pub fn parse_scene_with(
    text: &str,
    path: &Path,
    options: &LoadOptions<'_>,
) -> Result<Scene, SceneError> {
    parse_scene_file(text, path, options).map(|file| file.scene)
}

/// [`parse_scene_with`], keeping the camera path of an `[animation]` table.
pub fn parse_scene_file(
    text: &str,
    path: &Path,
    options: &LoadOptions<'_>,
) -> Result<SceneFile, SceneError> {
    let source = Source { path, text };
    if text.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(source.error(None, too_large_message(text.len() as u64)));
    }
    let structure = structure::scan(text);
    if structure.values > MAX_SCENE_VALUES {
        return Err(source.error(
            None,
            format!(
                "the scene file holds up to {} values (every `=`, `,`, `[` and `{{` outside \
                 strings and comments starts one), more than the {MAX_SCENE_VALUES} accepted: \
                 the TOML parser keeps every value in memory (200 to 400 bytes each, so \
                 several GB for this file)",
                structure.values
            ),
        ));
    }
    options.report(LoadProgress::Parsing {
        bytes: text.len() as u64,
    });
    let raw: RawScene = toml::from_str(text).map_err(|e| toml_error(&source, &structure, &e))?;
    check_element_count(&source, &raw)?;
    build_scene(&source, raw, options)
}

fn read_scene_file(path: &Path, options: &LoadOptions<'_>) -> Result<String, SceneError> {
    const WHAT: &str = "cannot read the scene file";
    let read = |e: InputError| SceneError::read(path, WHAT, e);
    // Opened, then judged on what was opened: a FIFO is refused without waiting for a
    // writer, and nothing can be swapped in between the check and the read.
    let file = crate::input::open_input(path).map_err(read)?;
    let length = file.metadata().map_err(|e| read(InputError::Io(e)))?.len();
    if length > MAX_SCENE_FILE_BYTES {
        return Err(SceneError::too_large(path, None, too_large_message(length)));
    }
    options.report(LoadProgress::Reading { bytes: length });
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| read(InputError::Io(e)))?;
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(SceneError::too_large(
            path,
            None,
            too_large_message(bytes.len() as u64),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        SceneError::syntax(
            path,
            None,
            format!(
                "{WHAT}: it is not valid UTF-8 (at byte {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

fn too_large_message(bytes: u64) -> String {
    format!(
        "the scene file is {bytes} bytes, more than the {MAX_SCENE_FILE_BYTES} (64 MiB) accepted"
    )
}

/// A TOML syntax or type error, located at its span, with the key path it concerns.
/// The parser's bare "duplicate key" gets the key's name, and its "recursion limit"
/// (a dotted key of too many parts, which it reports without a place) gets the place
/// and the number of parts of the longest key.
fn toml_error(
    source: &Source<'_>,
    structure: &structure::Structure,
    error: &toml::de::Error,
) -> SceneError {
    let span = error.span();
    let mut location = span.clone().map(|span| source.location(span.start));
    let mut message = match toml_error_keys(error) {
        Some(keys) => format!("{keys}: {}", error.message()),
        None => error.message().to_owned(),
    };
    if error.message() == "duplicate key"
        && let Some(span) = span
    {
        message = duplicate_key_message(source.text, span);
    } else if error.message() == "recursion limit"
        && location.is_none()
        && let Some((start, parts)) = structure.longest_key
    {
        location = Some(source.location(start));
        message = format!(
            "recursion limit: a dotted key has {parts} parts (`{}…`); the TOML parser accepts at most 80",
            source.text[start..].chars().take(24).collect::<String>()
        );
    }
    SceneError::syntax(source.path, location, message)
}

/// "duplicate key `eye`" or, for a table header, "duplicate table `[materials.a]`".
fn duplicate_key_message(text: &str, span: std::ops::Range<usize>) -> String {
    let key = text.get(span.clone()).unwrap_or("?");
    let line_start = text[..span.start.min(text.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    let line = text[line_start..line_end].trim();
    if line.starts_with('[') {
        let header = line.split('#').next().unwrap_or(line).trim();
        format!(
            "duplicate table `{}` (each table may be defined once; use [[...]] for a list)",
            echo(header)
        )
    } else {
        format!(
            "duplicate key `{}` (each key may be given once per table)",
            echo(key)
        )
    }
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
        return Err(SceneError::too_large(
            source.path,
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
fn build_scene(
    source: &Source<'_>,
    raw: RawScene,
    options: &LoadOptions<'_>,
) -> Result<SceneFile, SceneError> {
    let render = settings::render(source, raw.render)?;
    let camera = settings::camera(source, raw.camera)?;
    let camera_path = animation::animation(source, raw.animation, &camera)?;
    let aim = crate::scene::camera_pixel_precision(&camera, render.height);
    if let Some(warn) = options.warning
        && aim > crate::scene::CAMERA_PRECISION_LIMIT
    {
        warn(&source.item("camera".into(), None).warning(format_args!(
            "fov_y_degrees = {} over {} pixels: the GPU aims its rays (f32) to {aim:.1e} of a \
             pixel, more than {:e}; --backend auto renders this scene on the CPU reference, \
             or widen the view",
            short(camera.fov_y_degrees),
            render.height,
            crate::scene::CAMERA_PRECISION_LIMIT
        )));
    }
    let mut budget = budget::LoadBudget::new(options.max_bytes);
    let environment = settings::environment(
        source,
        raw.environment,
        source.path.parent().unwrap_or(std::path::Path::new("")),
        options,
        &mut budget,
    )?;
    let total = (raw.materials.len() + raw.lights.len() + raw.objects.len()) as u64;
    let mut done = 0;
    let mut checked = || {
        done += 1;
        options.report(LoadProgress::Checking { done, total });
    };
    let mut material_names = Vec::with_capacity(raw.materials.len());
    let mut materials = Vec::with_capacity(raw.materials.len());
    let mut images = materials::ImageTable::new(
        source.path.parent().unwrap_or(std::path::Path::new("")),
        options,
        &mut budget,
    );
    for (name, material) in raw.materials {
        materials.push(materials::material(source, &name, material, &mut images)?);
        material_names.push(name);
        checked();
    }
    let light_spans: Vec<_> = raw.lights.iter().map(|l| l.span()).collect();
    let lights = raw
        .lights
        .into_iter()
        .enumerate()
        .map(|(i, light)| {
            checked();
            lights::light(source, i, light)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let table = MaterialTable::new(&material_names, &materials);
    let base = source.path.parent().unwrap_or(std::path::Path::new(""));
    let mut shapes = Vec::with_capacity(raw.objects.len());
    // Each shape's object index and span, for the warnings that judge shapes together.
    let mut shape_items = Vec::with_capacity(raw.objects.len());
    let mut models = Vec::new();
    let mut model_cache = objects::ModelCache::new();
    // Each model may hold what the images left of the cap.
    let model_options = LoadOptions {
        max_bytes: images.bytes_left(),
        ..*options
    };
    for (i, object) in raw.objects.into_iter().enumerate() {
        checked();
        if object.get_ref().kind.as_deref() == Some("model") {
            models.push(objects::model(
                source,
                &table,
                i,
                object,
                base,
                &model_options,
                &mut model_cache,
            )?);
        } else {
            let span = object.span();
            let shape = objects::object(source, &table, i, object)?;
            if let Some(warn) = options.warning
                && let Some(message) = objects::precision_warning(&shape, camera.eye)
            {
                warn(
                    &source
                        .item(
                            format!("objects[{i}] ({})", shape.kind_name()),
                            Some(span.clone()),
                        )
                        .warning(message),
                );
            }
            shapes.push(shape);
            shape_items.push((i, span));
        }
    }
    if let Some(warn) = options.warning {
        let extent = objects::scene_extent(&shapes, &lights, camera.eye);
        for (k, shape) in shapes.iter().enumerate() {
            let (i, span) = &shape_items[k];
            let item = || source.item(format!("objects[{i}] (sphere)"), Some(span.clone()));
            if let Some(message) = objects::far_wall_warning(shape, camera.eye, extent) {
                warn(&item().warning(message));
            }
            for (other, (j, _)) in shapes.iter().zip(&shape_items).skip(k + 1) {
                let name = format!("objects[{j}]");
                if let Some(message) = objects::coincident_warning(shape, other, &name, camera.eye)
                {
                    warn(&item().warning(message));
                }
            }
        }
    }
    let mut scene = Scene {
        render,
        camera,
        environment,
        materials,
        material_names,
        lights,
        shapes,
        meshes: vec![],
        images: images.into_images(),
    };
    // Each model file once, with all its placements (in file order of first use): its
    // geometry is held once per distinct material override.
    let mut done = vec![false; models.len()];
    for first in 0..models.len() {
        if done[first] {
            continue;
        }
        let model = &models[first].model;
        let placements: Vec<_> = (first..models.len())
            .filter(|&k| std::rc::Rc::ptr_eq(&models[k].model, model))
            .inspect(|&k| done[k] = true)
            .map(|k| models[k].placement)
            .collect();
        model.add_placements_to_scene(&mut scene, &placements);
    }
    if let Some(warn) = options.warning
        && let Some((light, shape, distance)) = crate::scene::light_beyond_the_gpu(&scene)
    {
        warn(
            &source
                .item(
                    format!("lights[{light}] (point)"),
                    light_spans.get(light).cloned(),
                )
                .warning(format_args!(
                    "{distance:.1e} from objects[{}], its irradiance there is beyond the \
                     GPU's 32-bit floats (I/r² above 2e37), where the GPU shows 0; \
                     --backend auto renders this scene on the CPU reference, or move the \
                     light",
                    shape_items.get(shape).map_or(shape, |(i, _)| *i)
                )),
        );
    }
    if let Some(warn) = options.warning
        && !scene.meshes.is_empty()
        && let Some(beyond) =
            crate::scene::mesh_triangle_beyond_the_gpu(&scene.meshes, scene.camera.eye)
        && let Some(message) = objects::precision_message(
            "a triangle",
            &beyond.precision,
            "split it into smaller triangles",
        )
    {
        warn(&source.item(beyond.what, None).warning(message));
    }
    Ok(SceneFile { scene, camera_path })
}

#[cfg(test)]
mod tests;
