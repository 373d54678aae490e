//! The scene: its in-memory model and the TOML scene-file format that fills it
//! (documented field by field in `docs/scene-format.md`).

mod error;
mod file;
mod image;
pub mod import;
mod model;

pub use error::SceneError;
pub use file::{CONDUCTOR_PRESETS, load_scene, parse_scene};
pub use image::{MAX_IMAGE_SIDE, load_image};
pub use model::*;
