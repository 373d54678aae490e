//! glTF materials mapped onto ours: the metal/roughness model, alpha coverage,
//! emission (`KHR_materials_emissive_strength`), glass (`KHR_materials_transmission`,
//! `KHR_materials_ior`), `KHR_materials_unlit` and the normal map.

use glam::DVec3;

use super::extensions::TransformExtension;
use super::importer::{Importer, MaterialUse, describe};
use crate::echo::short;
use crate::scene::import::texture::Encoding;
use crate::scene::import::{ImportedMaterial, TextureRef};
use crate::scene::{AlphaMode, MAX_RADIANCE, Material, MaterialKind, SceneError, TextureTransform};

/// Index of refraction of `KHR_materials_ior`'s default (and of glass without it).
const DEFAULT_IOR: f64 = 1.5;
/// glTF's `alphaCutoff` where a `MASK` material gives none (glTF 2.0 §3.9.4).
const DEFAULT_ALPHA_CUTOFF: f32 = 0.5;

impl Importer<'_> {
    /// The model's index of glTF material `index` (`None`: the default material, glTF
    /// 2.0 §3.9.6), mapping it on first use.
    pub(super) fn material(&mut self, index: Option<usize>) -> Result<MaterialUse, SceneError> {
        if let Some(&known) = self.materials.get(&index) {
            return Ok(known);
        }
        let (imported, uses_set1, normal_map) =
            match index.and_then(|i| self.document.materials().nth(i)) {
                Some(material) => self.map_material(&material)?,
                None => (
                    ImportedMaterial {
                        name: "default".into(),
                        // glTF's default material: white, fully metallic and rough... which is
                        // black under Whitted lighting; a white dielectric PBR is what viewers show.
                        material: Material {
                            diffuse: DVec3::ONE,
                            metallic: 0.0,
                            roughness: 1.0,
                            // The default material is single-sided (§3.9.6).
                            cull_back_faces: true,
                            ..Material::blank(MaterialKind::Pbr)
                        },
                        base_color_texture: None,
                        metallic_roughness_texture: None,
                        emissive_texture: None,
                        normal_texture: None,
                    },
                    false,
                    None,
                ),
            };
        let ours = self.model.materials.len() as u32;
        self.model.materials.push(imported);
        let uses = MaterialUse {
            index: ours,
            uses_set1,
            normal_map,
        };
        self.materials.insert(index, uses);
        Ok(uses)
    }

    /// Maps a glTF metallic-roughness material onto ours (the table in `docs/models.md`),
    /// with whether one of its textures reads `TEXCOORD_1` and the coordinates of its
    /// normal map, if any.
    pub(super) fn map_material(
        &mut self,
        material: &::gltf::Material<'_>,
    ) -> Result<(ImportedMaterial, bool, Option<TextureTransform>), SceneError> {
        let name = describe("material", material.index().unwrap_or(0), material.name());
        let factors = self.factors(material, &name)?;
        let alpha_mode = self.alpha_mode(material, &name);
        // occlusionTexture is left out without a warning: baked ambient occlusion is a
        // rasteriser's stand-in for the shadowing of indirect light (glTF 2.0 §3.9.3),
        // which a path tracer computes; applying it too would darken creases twice.
        let emission = self.clamped_emission(factors.emissive * factors.strength, &name);
        let ours = self.material_model(material, &name, &factors, emission);
        // glTF's doubleSided lights both sides of a surface: an emitter emits from both.
        // Without it, camera rays cull the back faces (glTF 2.0 §3.9.5).
        let ours = Material {
            two_sided: material.double_sided() && ours.emission != DVec3::ZERO,
            cull_back_faces: !material.double_sided(),
            alpha_mode,
            alpha: factors.alpha,
            ..ours
        };
        let textures = self.material_textures(material, &name)?;
        let ours = Material {
            normal_scale: textures.normal_scale,
            ..ours
        };
        let uses_set1 = [
            &textures.base_color,
            &textures.metallic_roughness,
            &textures.emissive,
            &textures.normal,
        ]
        .iter()
        .any(|t| t.is_some_and(|t| t.transform.set == 1));
        let imported = ImportedMaterial {
            name: material.name().map_or_else(|| name.clone(), str::to_string),
            material: ours,
            base_color_texture: textures.base_color,
            metallic_roughness_texture: textures.metallic_roughness,
            emissive_texture: textures.emissive,
            normal_texture: textures.normal,
        };
        Ok((imported, uses_set1, textures.normal.map(|t| t.transform)))
    }

    /// The material's factors, each checked: base colour, alpha, metalness and
    /// roughness in [0, 1], the emissive factor in [0, 1] and its strength
    /// (`KHR_materials_emissive_strength`) finite and not negative.
    fn factors(&self, material: &::gltf::Material<'_>, name: &str) -> Result<Factors, SceneError> {
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha] = pbr.base_color_factor().map(f64::from);
        let base = DVec3::new(r, g, b);
        let metallic = f64::from(pbr.metallic_factor());
        let roughness = f64::from(pbr.roughness_factor());
        let strength = f64::from(material.emissive_strength().unwrap_or(1.0));
        let emissive = DVec3::from_array(material.emissive_factor().map(f64::from));
        let in_unit = |v: f64| (0.0..=1.0).contains(&v);
        if !base.to_array().into_iter().all(in_unit)
            || !in_unit(alpha)
            || !in_unit(metallic)
            || !in_unit(roughness)
        {
            return Err(self.fail(format!(
                "{name}: baseColorFactor {base} (alpha {alpha}), metallicFactor {metallic} and roughnessFactor {roughness} must lie in [0, 1]"
            )));
        }
        if !(emissive.to_array().into_iter().all(in_unit)
            && strength.is_finite()
            && strength >= 0.0)
        {
            return Err(self.fail(format!(
                "{name}: emissiveFactor {emissive} must lie in [0, 1] and emissiveStrength {strength} be finite and not negative"
            )));
        }
        Ok(Factors {
            base,
            alpha,
            metallic,
            roughness,
            emissive,
            strength,
        })
    }

    /// The material's alpha coverage, its cutoff checked (glTF 2.0 §3.9.4).
    fn alpha_mode(&mut self, material: &::gltf::Material<'_>, name: &str) -> AlphaMode {
        // glTF 2.0 §3.9.4 "Alpha Coverage": MASK makes the surface opaque where the base
        // colour's alpha is >= alphaCutoff (default 0.5) and absent elsewhere; BLEND
        // makes alpha its coverage; OPAQUE ignores alpha.
        match material.alpha_mode() {
            ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            ::gltf::material::AlphaMode::Mask => {
                let cutoff = f64::from(material.alpha_cutoff().unwrap_or(DEFAULT_ALPHA_CUTOFF));
                let cutoff = if cutoff.is_finite() && cutoff >= 0.0 {
                    if cutoff > 1.0 {
                        // Alpha lies in [0, 1]: no point reaches the cutoff.
                        self.warn(format!(
                            "{name}: alphaCutoff {} is above 1, the largest alpha, so the material's every point is cut away and it is invisible",
                            short(cutoff)
                        ));
                    }
                    cutoff
                } else {
                    self.warn(format!(
                        "{name}: alphaCutoff {cutoff} must be finite and not negative; {DEFAULT_ALPHA_CUTOFF} is used"
                    ));
                    f64::from(DEFAULT_ALPHA_CUTOFF)
                };
                AlphaMode::Mask { cutoff }
            }
            ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        }
    }

    /// `emission` clamped to what the GPU sums in 32-bit floats, with a warning.
    fn clamped_emission(&mut self, emission: DVec3, name: &str) -> DVec3 {
        if emission.max_element() > MAX_RADIANCE {
            self.warn(format!(
                "{name}: emission {} is above the {} the GPU can sum in 32-bit floats; clamped",
                short(emission.max_element()),
                short(MAX_RADIANCE)
            ));
            return emission.min(DVec3::splat(MAX_RADIANCE));
        }
        emission
    }

    /// Our model of the material: an emitter for `KHR_materials_unlit`, smooth glass
    /// for a transmissive non-metal (`KHR_materials_transmission`, its `ior` from
    /// `KHR_materials_ior`), else the metal/roughness BRDF.
    fn material_model(
        &mut self,
        material: &::gltf::Material<'_>,
        name: &str,
        factors: &Factors,
        emission: DVec3,
    ) -> Material {
        let Factors {
            base,
            metallic,
            roughness,
            ..
        } = *factors;
        let transmission = material
            .transmission()
            .map_or(0.0, |t| f64::from(t.transmission_factor()));
        let ior = material.ior().map(f64::from);
        if material.unlit() {
            // KHR_materials_unlit: the base colour, unshaded. An emitter of that radiance
            // that reflects nothing shows it exactly (Whitted); the path integrator also
            // lets it light its surroundings, which an unlit surface does not do.
            self.warn(format!(
                "{name}: KHR_materials_unlit: read as an emitter of its base colour that reflects nothing; under the path integrator it also lights its surroundings"
            ));
            Material {
                emission: base,
                ..Material::blank(MaterialKind::Emissive)
            }
        } else if transmission > 0.0 && metallic < 1.0 {
            let ior = match ior {
                Some(ior) if ior.is_finite() && ior >= 1.0 => ior,
                Some(ior) => {
                    self.warn(format!(
                        "{name}: ior {ior} is not supported; {DEFAULT_IOR} is used"
                    ));
                    DEFAULT_IOR
                }
                None => DEFAULT_IOR,
            };
            if metallic > 0.0 || roughness > 0.0 {
                self.warn(format!(
                    "{name}: a transmissive material is imported as smooth glass; metallicFactor {metallic} and roughnessFactor {roughness} are ignored"
                ));
            }
            if material
                .transmission()
                .is_some_and(|t| t.transmission_texture().is_some())
            {
                self.warn(format!(
                    "{name}: transmissionTexture is not supported; ignored"
                ));
            }
            Material {
                ior,
                transmittance: (base * transmission.clamp(0.0, 1.0)).clamp(DVec3::ZERO, DVec3::ONE),
                emission,
                ..Material::blank(MaterialKind::Dielectric)
            }
        } else {
            if ior.is_some_and(|ior| ior != DEFAULT_IOR) {
                self.warn(format!(
                    "{name}: ior is only used for transmissive, non-metallic materials (the metal/roughness model's F0 is 0.04); ignored"
                ));
            }
            Material {
                diffuse: base,
                metallic,
                roughness,
                emission,
                ..Material::blank(MaterialKind::Pbr)
            }
        }
    }

    /// The material's textures (base colour, metal/roughness, emissive, normal map) and
    /// its normal map's scale.
    fn material_textures(
        &mut self,
        material: &::gltf::Material<'_>,
        name: &str,
    ) -> Result<MaterialTextures, SceneError> {
        let pbr = material.pbr_metallic_roughness();
        let base_color_texture = match pbr.base_color_texture() {
            Some(info) => Some(self.texture(&info, Encoding::Color, name, "baseColorTexture")?),
            None => None,
        };
        let metallic_roughness_texture = match pbr.metallic_roughness_texture() {
            Some(info) => {
                Some(self.texture(&info, Encoding::Data, name, "metallicRoughnessTexture")?)
            }
            None => None,
        };
        let emissive_texture = match material.emissive_texture() {
            // An unlit material's colour is its base colour, texture included.
            _ if material.unlit() => base_color_texture,
            Some(info) => Some(self.texture(&info, Encoding::Color, name, "emissiveTexture")?),
            None => None,
        };
        let (normal_texture, normal_scale) = match material.normal_texture() {
            Some(normal) => {
                let scale = f64::from(normal.scale());
                if !scale.is_finite() {
                    return Err(
                        self.fail(format!("{name}: normalTexture scale {scale} is not finite"))
                    );
                }
                let extension = match normal.extension_value("KHR_texture_transform") {
                    Some(value) => Some(TransformExtension::from_json(value).map_err(|e| {
                        self.fail(format!("{name}: normalTexture: KHR_texture_transform: {e}"))
                    })?),
                    None => None,
                };
                let transform =
                    self.transform(normal.tex_coord(), extension, name, "normalTexture")?;
                let texture = self.texture_of(
                    normal.texture(),
                    transform,
                    Encoding::Data,
                    name,
                    "normalTexture",
                )?;
                (Some(texture), scale)
            }
            None => (None, 1.0),
        };
        Ok(MaterialTextures {
            base_color: base_color_texture,
            metallic_roughness: metallic_roughness_texture,
            emissive: emissive_texture,
            normal: normal_texture,
            normal_scale,
        })
    }
}

/// A glTF material's factors, checked ([`Importer::factors`]).
#[derive(Debug, Clone, Copy)]
struct Factors {
    /// `baseColorFactor`'s colour.
    base: DVec3,
    /// `baseColorFactor`'s alpha.
    alpha: f64,
    /// `metallicFactor`.
    metallic: f64,
    /// `roughnessFactor`.
    roughness: f64,
    /// `emissiveFactor`.
    emissive: DVec3,
    /// `KHR_materials_emissive_strength`'s `emissiveStrength` (1 without it).
    strength: f64,
}

/// A glTF material's textures as loaded ([`Importer::material_textures`]).
#[derive(Debug, Clone, Copy)]
struct MaterialTextures {
    /// `baseColorTexture`.
    base_color: Option<TextureRef>,
    /// `metallicRoughnessTexture`.
    metallic_roughness: Option<TextureRef>,
    /// `emissiveTexture` (an unlit material's base colour texture).
    emissive: Option<TextureRef>,
    /// `normalTexture`.
    normal: Option<TextureRef>,
    /// `normalTexture`'s `scale` (1 without a normal map).
    normal_scale: f64,
}
