//! The TOML scene-file format (placeholder; being written).

use std::path::Path;

use super::{Scene, SceneError};

/// Reads and validates the scene file at `path`.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        path: path.to_path_buf(),
        location: None,
        message: format!("cannot read the scene file: {e}"),
    })?;
    parse_scene(&text, path)
}

/// Parses and validates scene text; `path` is only used in error messages.
pub fn parse_scene(_text: &str, path: &Path) -> Result<Scene, SceneError> {
    Err(SceneError {
        path: path.to_path_buf(),
        location: None,
        message: "scene parsing is not written yet".into(),
    })
}
