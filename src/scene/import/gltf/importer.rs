//! The state of one glTF import and how it reports: warnings prefixed with the file,
//! errors naming it, and elements described by index and name.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use ::gltf::Document;

use crate::scene::SceneError;
use crate::scene::TextureTransform;
use crate::scene::import::mesh::Budget;
use crate::scene::import::texture::Textures;
use crate::scene::import::{ImportedModel, error};

/// Most validation problems quoted in one error message.
pub(super) const QUOTED_PROBLEMS: usize = 5;

/// The state of one import.
pub(super) struct Importer<'a> {
    pub(super) path: &'a Path,
    pub(super) directory: PathBuf,
    pub(super) document: &'a Document,
    pub(super) buffers: Vec<Vec<u8>>,
    pub(super) model: ImportedModel,
    pub(super) budget: Budget,
    pub(super) textures: Textures,
    /// glTF material index (`None`: the default material) → index in the model and
    /// whether a texture of it reads `TEXCOORD_1`.
    pub(super) materials: HashMap<Option<usize>, MaterialUse>,
    /// Warnings already given once per file.
    pub(super) warned: BTreeSet<&'static str>,
    /// The primitives skipped for being points or lines (`mesh N, primitive P: MODE`).
    pub(super) not_triangles: Vec<String>,
    /// How many primitives of triangles were read.
    pub(super) triangle_primitives: usize,
    /// The primitives with vertex colour sets beyond `COLOR_0`, which are not read
    /// (`mesh N, primitive P: COLOR_1`).
    pub(super) vertex_colors: Vec<String>,
}

/// `what N ('name')`, or `what N` for an unnamed element.
pub(super) fn describe(what: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) if !name.is_empty() => format!("{what} {index} ('{name}')"),
        _ => format!("{what} {index}"),
    }
}

impl Importer<'_> {
    pub(super) fn warn(&mut self, message: String) {
        self.model
            .warnings
            .push(format!("{}: {message}", self.path.display()));
    }

    /// Warns about `message` once per file, keyed by `key`.
    pub(super) fn warn_once(&mut self, key: &'static str, message: String) {
        if self.warned.insert(key) {
            self.warn(message);
        }
    }

    pub(super) fn fail(&self, message: impl Into<String>) -> SceneError {
        error(self.path, message)
    }
}

/// What a primitive's reading depends on in its material.
#[derive(Debug, Clone, Copy)]
pub(super) struct MaterialUse {
    /// Index in the model's materials.
    pub(super) index: u32,
    /// Whether a texture reads `TEXCOORD_1`.
    pub(super) uses_set1: bool,
    /// The coordinates of its normal map (set and `KHR_texture_transform`), if it has
    /// one: the primitive then needs tangents, for the map's axes.
    pub(super) normal_map: Option<TextureTransform>,
}

/// The first [`QUOTED_PROBLEMS`] of `items`, joined by `separator`, and how many more
/// there are.
pub(super) fn quote_list(items: &[String], separator: &str) -> String {
    let shown = items.len().min(QUOTED_PROBLEMS);
    let mut list = items[..shown].join(separator);
    if items.len() > shown {
        list += &format!(" and {} more", items.len() - shown);
    }
    list
}
