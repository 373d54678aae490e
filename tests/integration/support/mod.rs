//! Helpers shared by the integration tests.

pub mod compare;
pub mod geometry;
pub mod gpu;
pub mod models;
pub mod pipeline;
pub mod process;
pub mod quads;
pub mod reference;
pub mod scenes;
pub mod twins;

/// The repository's root: the manifest folder of the integration tests, or its parent
/// when these helpers are built into the tools crate (`tools/`, whose fuzz programs
/// include them).
pub fn repo_root() -> &'static std::path::Path {
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    match manifest.parent() {
        Some(parent) if manifest.ends_with("tools") => parent,
        _ => manifest,
    }
}
