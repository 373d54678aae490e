//! Imported models as the importer tests look at them.

use glam::{DVec3, DVec4};
use gpu_render::scene::Scene;
use gpu_render::scene::import::{ImportedMaterial, ImportedModel};

/// `model` as a 32 x 24 scene (its lights, or the default ones) seen from `eye`
/// towards `look_at`.
pub fn small_scene(model: &ImportedModel, eye: DVec3, look_at: DVec3) -> Scene {
    let mut scene = model.into_scene(gpu_render::scene::RenderSettings {
        width: 32,
        height: 24,
        ..Default::default()
    });
    scene.camera.eye = eye;
    scene.camera.look_at = look_at;
    scene
}

/// Asserts that `tangents` exist and each is `expected` (direction and handedness)
/// within 1e-6.
pub fn assert_tangents(tangents: Option<&Vec<DVec4>>, expected: DVec4) {
    for tangent in tangents.expect("tangents") {
        assert!(
            (*tangent - expected).length() < 1e-6,
            "{tangent} against {expected}"
        );
    }
}

/// The material of `model` named `name`; panics naming it when there is none.
pub fn material_named<'a>(model: &'a ImportedModel, name: &str) -> &'a ImportedMaterial {
    model
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}
