//! glTF 2.0 (Khronos, "glTF 2.0 Specification", 2021), as `.gltf` JSON with external or
//! embedded (data URI) buffers or as binary `.glb`, read through the `gltf` crate (its
//! JSON model and validation; buffers, accessors and images are read here, with every
//! range checked). One file per concept: the document and its validation, buffers, the
//! scene graph, geometry and vertex attributes, materials and textures, cameras, lights
//! and extensions, each an `impl` of the one [`Importer`] state.

mod attributes;
mod buffers;
mod cameras;
mod document;
mod extensions;
mod geometry;
mod importer;
mod instancing;
mod lights;
mod materials;
mod scene_graph;
mod textures;

use std::collections::{BTreeSet, HashMap};
use std::path::Path;

use crate::scene::SceneError;
use crate::scene::import::mesh::Budget;
use crate::scene::import::texture::Textures;
use crate::scene::import::{ImportOptions, ImportedModel, error, read_file};
use buffers::load_buffers;
use document::{gltf1_binary, gltf1_error, gltf1_json, parse_error, validate};
use extensions::{SUPPORTED_EXTENSIONS, unsupported_extensions};
use importer::Importer;

pub use lights::LUMENS_PER_WATT;
pub(super) use textures::MAX_TEXTURE_TRANSFORM;

/// Reads the glTF 2.0 file at `path`: JSON (`.gltf`, with buffers and images in
/// external files relative to it or embedded as data URIs) or binary (`.glb`), told
/// apart by content.
///
/// Fails, naming the file and the element (buffer, accessor, mesh and primitive, node,
/// material, texture, camera, light), on a missing, truncated or malformed file, a
/// glTF 1.0 file, extensions it requires that are not supported (all named at once;
/// Draco and meshopt compression with how to decompress), a file whose primitives are
/// all points or lines, an index or range out of bounds, a non-finite position or
/// transform, a node matrix that is projective or given beside translation, rotation or
/// scale, a texture that does not load, or a model beyond the size limits.
pub fn import_gltf(path: &Path) -> Result<ImportedModel, SceneError> {
    import_gltf_with(path, &ImportOptions::default())
}

/// [`import_gltf`] with `options`: the file, its buffers, meshes and textures are
/// counted against [`ImportOptions::max_bytes`] before they are allocated.
pub fn import_gltf_with(
    path: &Path,
    options: &ImportOptions<'_>,
) -> Result<ImportedModel, SceneError> {
    let mut budget = Budget::new(options.max_bytes);
    let bytes = read_file(path, path, "the model file", &mut budget)?;
    if let Some(progress) = options.progress {
        progress(bytes.len() as u64, bytes.len() as u64);
    }
    parse_gltf_within(&bytes, path, budget)
}

/// Reads glTF or GLB from `bytes`; `path` names the file in messages and its directory
/// is where external buffers and images are looked up.
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<ImportedModel, SceneError> {
    parse_gltf_within(bytes, path, Budget::default())
}

/// [`parse_gltf`] counting what it reads against `budget`.
fn parse_gltf_within(
    bytes: &[u8],
    path: &Path,
    budget: Budget,
) -> Result<ImportedModel, SceneError> {
    // glTF JSON must not start with a byte-order mark (§3.2), but some writers add one.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if bytes.is_empty() {
        return Err(error(path, "not a valid glTF file: the file is empty"));
    }
    if let Some(why) = gltf1_binary(bytes) {
        return Err(gltf1_error(path, why));
    }
    let gltf = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        // A glTF 1.0 file fails to parse as 2.0 (its top-level arrays were objects);
        // say what it is rather than where the 2.0 parser stopped.
        match gltf1_json(bytes) {
            Some(why) => gltf1_error(path, why),
            None => parse_error(path, e),
        }
    })?;
    let version = &gltf.as_json().asset.version;
    if version.starts_with("1.") {
        return Err(gltf1_error(path, format!("asset.version is \"{version}\"")));
    }
    if !version.starts_with("2.") {
        return Err(error(
            path,
            format!("glTF version {version} is not supported (only 2.x)"),
        ));
    }
    let unsupported: Vec<&str> = gltf
        .extensions_required()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !unsupported.is_empty() {
        return Err(error(path, unsupported_extensions(&unsupported)));
    }
    validate(&gltf.document, path)?;
    let mut importer = Importer {
        path,
        directory: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        document: &gltf.document,
        buffers: Vec::new(),
        model: ImportedModel::empty(path),
        budget,
        textures: Textures::default(),
        materials: HashMap::new(),
        warned: BTreeSet::new(),
        not_triangles: Vec::new(),
        triangle_primitives: 0,
        vertex_colors: Vec::new(),
    };
    for extension in gltf.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&extension) {
            importer.warn(format!(
                "uses the extension {extension}, which is not supported; what it adds is ignored"
            ));
        }
    }
    importer.buffers = load_buffers(
        &gltf.document,
        gltf.blob.as_deref(),
        path,
        &importer.directory,
        &mut importer.budget,
    )?;
    importer.import()?;
    let mut model = importer.model;
    model.images = importer.textures.images;
    Ok(model)
}
