//! Putting an imported model into a [`Scene`]: its meshes (with their vertex normals
//! and texture coordinates), its materials and the textures they use, under a
//! placement transform; or a whole scene around a model file rendered on its own.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DQuat, DVec3, EulerRot};

use super::{ImportedModel, TextureRef, WrapMode};
use crate::scene::{
    Environment, Material, Mesh, RenderSettings, Scene, TextureMapping, TextureWrap,
};

/// Where and how a model stands in a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelPlacement {
    /// Model-to-scene transform, applied after the model's own node transforms
    /// (finite and invertible).
    pub transform: DMat4,
    /// A scene material (an index into [`Scene::materials`]) that replaces every
    /// material of the model, or `None` to keep the model's own.
    pub material: Option<u32>,
    /// Whether the meshes keep their vertex normals (smooth shading); `false` shades
    /// every triangle flat with its geometric normal, as if the file had none.
    pub smooth: bool,
}

impl ModelPlacement {
    /// The model as it is, with its own materials.
    pub const IDENTITY: Self = Self {
        transform: DMat4::IDENTITY,
        material: None,
        smooth: true,
    };

    /// The transform `T · R · S` of a scene file's `translate`, `rotate` (degrees about
    /// x, then y, then z, each about the fixed scene axes) and `scale` (per axis).
    pub fn trs(translate: DVec3, rotate_degrees: DVec3, scale: DVec3) -> DMat4 {
        let r = rotate_degrees * (std::f64::consts::PI / 180.0);
        // Extrinsic x, y, z is intrinsic z, y, x: R = Rz · Ry · Rx.
        let rotation = DQuat::from_euler(EulerRot::ZYX, r.z, r.y, r.x);
        DMat4::from_scale_rotation_translation(scale, rotation, translate)
    }
}

/// The scene format's wrap mode for an importer's.
fn texture_wrap(mode: WrapMode) -> TextureWrap {
    match mode {
        WrapMode::Repeat => TextureWrap::Repeat,
        WrapMode::MirroredRepeat => TextureWrap::MirroredRepeat,
        WrapMode::ClampToEdge => TextureWrap::ClampToEdge,
    }
}

impl ImportedModel {
    /// Adds the model to `scene` under `placement`: one [`Mesh`] per imported mesh
    /// (instances composed with the placement), its materials (named
    /// `<file stem>/<material>`) unless the placement overrides them, and the base
    /// colour, metallic/roughness and emission textures they use (UV-mapped, with the
    /// file's wrap modes). [`ImportedModel::add_placements_to_scene`] with one
    /// placement.
    pub fn add_to_scene(&self, scene: &mut Scene, placement: &ModelPlacement) {
        self.add_placements_to_scene(scene, std::slice::from_ref(placement));
    }

    /// Adds the model to `scene` under every one of `placements`, holding its geometry
    /// once per distinct (material override, `smooth`) pair rather than once per
    /// placement: each imported mesh becomes one [`Mesh`] per such pair, whose
    /// instances are those of the file composed with each of its placements' transforms
    /// (in placement order), so that a model file placed many times costs the host
    /// memory of one copy (the GPU and the BVH hold it once in any case, as an
    /// instanced mesh). The model's materials (named `<file stem>/<material>`) and the
    /// textures they use join the scene once, for the placements that keep them.
    pub fn add_placements_to_scene(&self, scene: &mut Scene, placements: &[ModelPlacement]) {
        let stem = self
            .path
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
        let material_base = scene.materials.len() as u32;
        if placements.iter().any(|p| p.material.is_none()) {
            self.add_materials(scene, &stem);
        }
        // The distinct (material override, smooth) pairs, in order of first use, each
        // with its placements' transforms; by hash, so that many placements with many
        // overrides are grouped in linear time.
        type Kind = (Option<u32>, bool);
        let mut kinds: Vec<(Kind, Vec<DMat4>)> = Vec::new();
        let mut kind_of: HashMap<Kind, usize> = HashMap::new();
        for p in placements {
            let kind = *kind_of.entry((p.material, p.smooth)).or_insert_with(|| {
                kinds.push(((p.material, p.smooth), Vec::new()));
                kinds.len() - 1
            });
            kinds[kind].1.push(p.transform);
        }
        for ((material, smooth), transforms) in kinds {
            for mesh in &self.meshes {
                scene.meshes.push(Mesh {
                    name: format!("{stem}/{}", mesh.name),
                    positions: mesh.positions.clone(),
                    normals: if smooth { mesh.normals.clone() } else { None },
                    uvs: mesh.uvs.clone(),
                    uvs1: mesh.uvs1.clone(),
                    colors: mesh.colors.clone(),
                    tangents: mesh.tangents.clone(),
                    triangles: mesh.triangles.clone(),
                    material: material.unwrap_or(material_base + mesh.material),
                    instances: transforms
                        .iter()
                        .flat_map(|t| mesh.instances.iter().map(move |m| *t * *m))
                        .collect(),
                });
            }
        }
    }

    /// Adds the model's materials to `scene` (named `<stem>/<material>`, in the
    /// model's order) with the images their textures use, each image once.
    fn add_materials(&self, scene: &mut Scene, stem: &str) {
        let mut image_index = vec![None; self.images.len()];
        let mut scene_image = |scene: &mut Scene, image: u32| {
            *image_index[image as usize].get_or_insert_with(|| {
                scene.images.push(self.images[image as usize].clone());
                scene.images.len() as u32 - 1
            })
        };
        for imported in &self.materials {
            let mut material: Material = imported.material;
            if let Some(TextureRef {
                image,
                wrap_u,
                wrap_v,
                transform,
            }) = imported.base_color_texture
            {
                material.texture_transform = transform;
                material.albedo_texture = Some(scene_image(scene, image));
                material.texture_mapping = TextureMapping::Uv;
                material.texture_wrap = [texture_wrap(wrap_u), texture_wrap(wrap_v)];
            }
            if let Some(TextureRef {
                image,
                wrap_u,
                wrap_v,
                transform,
            }) = imported.metallic_roughness_texture
            {
                material.metallic_roughness_transform = transform;
                material.metallic_roughness_texture = Some(scene_image(scene, image));
                material.texture_mapping = TextureMapping::Uv;
                material.metallic_roughness_wrap = [texture_wrap(wrap_u), texture_wrap(wrap_v)];
            }
            if let Some(TextureRef {
                image,
                wrap_u,
                wrap_v,
                transform,
            }) = imported.emissive_texture
            {
                material.emission_transform = transform;
                material.emission_texture = Some(scene_image(scene, image));
                material.texture_mapping = TextureMapping::Uv;
                material.emission_wrap = [texture_wrap(wrap_u), texture_wrap(wrap_v)];
            }
            if let Some(TextureRef {
                image,
                wrap_u,
                wrap_v,
                transform,
            }) = imported.normal_texture
            {
                material.normal_transform = transform;
                material.normal_texture = Some(scene_image(scene, image));
                material.texture_mapping = TextureMapping::Uv;
                material.normal_wrap = [texture_wrap(wrap_u), texture_wrap(wrap_v)];
            }
            scene.materials.push(material);
            scene
                .material_names
                .push(format!("{stem}/{}", imported.name));
        }
    }

    /// A scene of this model alone, as the command line renders a model file: the
    /// model's own camera (or [`super::default_camera`] framing it, for `render`'s
    /// aspect ratio), its own lights (or [`super::default_lights`]), a dark grey
    /// background, and the given render settings.
    pub fn into_scene(&self, render: RenderSettings) -> Scene {
        let aspect = f64::from(render.width) / f64::from(render.height);
        let mut scene = Scene {
            render,
            camera: self.camera_or_default(aspect),
            environment: Environment {
                background: DVec3::splat(MODEL_BACKGROUND),
                ambient: DVec3::ZERO,
                map: None,
            },
            materials: Vec::new(),
            material_names: Vec::new(),
            lights: self.lights_or_default(),
            shapes: Vec::new(),
            meshes: Vec::new(),
            images: Vec::new(),
        };
        self.add_to_scene(&mut scene, &ModelPlacement::IDENTITY);
        scene
    }
}

/// Background radiance of a model rendered on its own (dark grey, so that black parts
/// of the model stand out).
pub const MODEL_BACKGROUND: f64 = 0.05;

/// Whether `path` names a model file ([`super::import_model`] reads it) rather than a
/// scene file, by its extension.
pub fn is_model_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .is_some_and(|e| matches!(e.as_str(), "obj" | "gltf" | "glb"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trs_applies_scale_then_rotation_then_translation() {
        let m = ModelPlacement::trs(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(0.0, 90.0, 0.0),
            DVec3::splat(2.0),
        );
        // x → scaled 2x → rotated 90° about y to -z → translated.
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 2.0, 1.0)).length() < 1e-12, "{p}");
    }

    #[test]
    fn rotations_are_about_fixed_axes_x_first() {
        let m = ModelPlacement::trs(DVec3::ZERO, DVec3::new(90.0, 90.0, 0.0), DVec3::ONE);
        // y → (about x) z → (about y) x.
        let p = m.transform_point3(DVec3::Y);
        assert!((p - DVec3::X).length() < 1e-12, "{p}");
    }
}
