//! The glTF document before its content is read: glTF 1.0 files recognised and refused
//! with how to convert them, parse errors with their JSON line and column, and the
//! `gltf` crate's validation run with our own checks first.

use std::path::Path;

use ::gltf::Document;
use ::gltf::json::validation::Checked;

use super::extensions::DRACO;
use super::importer::{QUOTED_PROBLEMS, quote_list};
use crate::scene::SceneError;
use crate::scene::import::error;

/// Why `bytes` is a binary glTF 1.0 file (a GLB container of version 1, the
/// `KHR_binary_glTF` extension of glTF 1.0), if it is one.
pub(super) fn gltf1_binary(bytes: &[u8]) -> Option<String> {
    let version = bytes.strip_prefix(b"glTF")?.get(..4)?;
    (u32::from_le_bytes([version[0], version[1], version[2], version[3]]) == 1)
        .then(|| "a GLB container of version 1, glTF 1.0's KHR_binary_glTF".to_string())
}

/// Why the JSON `bytes` are a glTF 1.0 document, if they are one: `asset.version` "1.x",
/// or (1.0 files often leave `version` out) top-level properties that glTF 1.0 made
/// objects keyed by id and glTF 2.0 made arrays.
pub(super) fn gltf1_json(bytes: &[u8]) -> Option<String> {
    let value: ::gltf::json::Value = ::gltf::json::deserialize::from_slice(bytes).ok()?;
    let root = value.as_object()?;
    if let Some(version) = root
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(|v| v.as_str())
        .filter(|v| v.starts_with("1."))
    {
        return Some(format!("asset.version is \"{version}\""));
    }
    ["accessors", "meshes", "nodes", "buffers", "bufferViews"]
        .into_iter()
        .find(|key| root.get(*key).is_some_and(|v| v.is_object()))
        .map(|key| format!("its {key} are an object keyed by id, glTF 1.0's layout"))
}

/// The error for a glTF 1.0 file, `why` saying how it was recognised.
pub(super) fn gltf1_error(path: &Path, why: String) -> SceneError {
    SceneError::unsupported(
        path,
        None,
        format!(
            "the file is glTF 1.0 ({why}); only glTF 2.0 is read: convert it first, e.g. with gltf-pipeline (`gltf-pipeline -i IN -o OUT`), which updates glTF 1.0 to 2.0"
        ),
    )
}

/// The error for a file the `gltf` crate cannot parse, with the JSON line and column
/// where it knows them.
pub(super) fn parse_error(path: &Path, e: ::gltf::Error) -> SceneError {
    match e {
        ::gltf::Error::Deserialize(json) if json.line() > 0 => {
            let (line, column) = (json.line(), json.column());
            let text = json.to_string();
            let suffix = format!(" at line {line} column {column}");
            SceneError::syntax(
                path,
                Some((line, column.max(1))),
                format!(
                    "not a valid glTF file: {}",
                    text.strip_suffix(&suffix).unwrap_or(&text)
                ),
            )
        }
        ::gltf::Error::Binary(binary) => SceneError::syntax(
            path,
            None,
            format!("not a valid GLB file (truncated or corrupt): {binary}"),
        ),
        other => SceneError::syntax(path, None, format!("not a valid glTF file: {other}")),
    }
}

/// Runs the `gltf` crate's validation (references in range, required properties present,
/// enumerations valid), which its accessors rely on.
pub(super) fn validate(document: &Document, path: &Path) -> Result<(), SceneError> {
    use ::gltf::json::validation::Validate;
    let root = document.as_json();
    // gltf-json 1.4's validation indexes the accessors with POSITION's index unchecked
    // (`primitive_validate_hook`), so that index is checked here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(::gltf::Semantic::Positions));
            if let Some(index) = position
                && index.value() >= root.accessors.len()
            {
                return Err(error(
                    path,
                    format!(
                        "not a valid glTF file: meshes[{m}].primitives[{p}].attributes[\"POSITION\"] refers to accessor {}, but there are {} accessors",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    // A file that uses Draco without requiring it must keep uncompressed copies of its
    // meshes (KHR_draco_mesh_compression, "Conformance"); without them its accessors
    // hold no data, and it is Draco that is missing, not just a bufferView.
    if root.extensions_used.iter().any(|e| e == DRACO) {
        let empty: Vec<String> = root
            .accessors
            .iter()
            .enumerate()
            .filter(|(_, a)| a.buffer_view.is_none() && a.sparse.is_none())
            .map(|(i, _)| i.to_string())
            .collect();
        if !empty.is_empty() {
            return Err(error(
                path,
                format!(
                    "the file's meshes are Draco-compressed ({DRACO}) without uncompressed copies (accessor{} {} {} no bufferView), and Draco mesh compression is not supported: decompress the file first, e.g. with `gltf-transform cp IN OUT` (glTF Transform decodes Draco on reading)",
                    if empty.len() == 1 { "" } else { "s" },
                    quote_list(&empty, ", "),
                    if empty.len() == 1 { "has" } else { "have" },
                ),
            ));
        }
    }
    let mut problems = Vec::new();
    root.validate(root, ::gltf::json::Path::new, &mut |where_, what| {
        let where_ = where_();
        // POSITION's min and max are required (§3.7.2.1) but only serve to bound the
        // mesh without reading it; some exporters leave them out or get them wrong, and
        // the positions are read (and checked) anyway. Required extensions were judged
        // against what this importer reads, not what the crate knows.
        //
        // Attributes whose names start with `_` are the application's own (§3.7.2.1),
        // which gltf-json without its `extras` feature calls invalid (and names
        // "<invalid semantic name>", like any name it does not know); they are not read.
        if !where_.as_str().contains(r#"["POSITION"].m"#)
            && !where_.as_str().starts_with("extensionsRequired")
            && !where_
                .as_str()
                .contains(r#".attributes["<invalid semantic name>"]"#)
        {
            problems.push(format!("{where_}: {what}"));
        }
    });
    if problems.is_empty() {
        return Ok(());
    }
    let more = problems.len().saturating_sub(QUOTED_PROBLEMS);
    problems.truncate(QUOTED_PROBLEMS);
    Err(error(
        path,
        format!(
            "not a valid glTF file: {}{}",
            problems.join("; "),
            if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            }
        ),
    ))
}
