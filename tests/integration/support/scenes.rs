//! The shipped scenes, loaded and shrunk for tests.

use std::path::PathBuf;

use gpu_render::scene::{RenderOverrides, Scene, load_scene};

/// Every `scenes/*.toml`, sorted.
pub fn shipped_scenes() -> Vec<PathBuf> {
    let dir = super::repo_root().join("scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .map(|entry| entry.expect("readable entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(
        scenes.len() >= 3,
        "expected the shipped scenes in {}",
        dir.display()
    );
    scenes
}

/// `scenes/NAME`, loaded (panics with the scene error otherwise).
pub fn shipped(name: &str) -> Scene {
    let path = super::repo_root().join("scenes").join(name);
    load_scene(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// `scene` at `width` pixels wide (same aspect) with `overrides` on top.
pub fn reduced(scene: Scene, width: u32, overrides: RenderOverrides) -> Scene {
    let height = (u64::from(scene.render.height) * u64::from(width) / u64::from(scene.render.width))
        .max(1) as u32;
    let render = scene
        .render
        .with_overrides(&RenderOverrides {
            width: Some(width),
            height: Some(height),
            ..overrides
        })
        .expect("valid overrides");
    Scene { render, ..scene }
}
