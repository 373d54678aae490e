//! The scene: its in-memory model and the TOML scene-file format that fills it
//! (documented field by field in `docs/scene-format.md`).

mod error;
mod file;
mod model;

pub use error::SceneError;
pub use file::{load_scene, parse_scene};
pub use model::*;
