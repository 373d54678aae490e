//! The mapping of one MTL material onto ours ([`map_material`]; the table in
//! `docs/models.md`): its numbers ([`Factors`]), the model its illumination model and
//! the PBR extension choose (glass, metal/roughness, Lambert or Blinn-Phong with an
//! optional coat), its dissolve as coverage, and its texture maps ([`super::maps`],
//! [`super::derived_textures`]).

use glam::DVec3;

use super::SourceMaterial;
use super::derived_textures::{coverage_in_base_color, metallic_roughness_texture};
use super::maps::load_maps;
use crate::echo::{echo, short, short3};
use crate::scene::import::ImportedMaterial;
use crate::scene::import::mesh::Budget;
use crate::scene::import::obj::DEFAULT_OBJ_ALBEDO;
use crate::scene::import::texture::Textures;
use crate::scene::{AlphaMode, MAX_RADIANCE, Material, MaterialKind, SceneError};

/// Index of refraction assumed for glass (`illum` 4, 6, 7, 9) and coats (`illum` 3, 5, 8)
/// whose material gives no usable `Ni`.
const DEFAULT_IOR: f64 = 1.5;
/// Blinn-Phong exponent assumed when `Ns` is absent (as tinyobjloader does).
const DEFAULT_NS: f64 = 1.0;
/// Largest accepted Blinn-Phong exponent (the scene format's limit).
const MAX_SHININESS: f64 = 1e6;

/// Maps one MTL material onto ours (the table in `docs/models.md`).
pub(in crate::scene::import::obj) fn map_material(
    source: &SourceMaterial,
    textures: &mut Textures,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<ImportedMaterial, SceneError> {
    let m = &source.material;
    let place = format!(
        "{}:{}: material '{}'",
        source.library.display(),
        source.line,
        echo(&m.name)
    );
    let mut warn = |message: String| warnings.push(format!("{place}: {message}"));
    let maps = load_maps(source, textures, budget, &mut warn)?;
    let factors = Factors::read(m, maps.base_color.is_some());
    let mut material = shading_model(m, &factors, &mut warn);
    apply_dissolve(&mut material, factors.dissolve, &mut warn);
    let base_color_texture =
        coverage_in_base_color(&mut material, &maps, source, textures, budget, &mut warn)?;
    if maps.normal.is_some() {
        material.normal_scale = maps.normal_scale;
    }
    let metallic_roughness_texture =
        metallic_roughness_texture(&mut material, &maps, source, textures, budget, &mut warn)?;
    Ok(ImportedMaterial {
        name: m.name.clone(),
        material,
        base_color_texture,
        metallic_roughness_texture,
        emissive_texture: maps.emissive,
        normal_texture: maps.normal,
    })
}

/// The numbers of an MTL material, with MTL's (and tinyobjloader's) defaults where they
/// are absent.
struct Factors {
    /// `Kd`; [`DEFAULT_OBJ_ALBEDO`] when absent, 1 when a `map_Kd` gives the colour.
    kd: DVec3,
    /// `Ks`; 0 when absent.
    ks: DVec3,
    /// `Ke`; 0 when absent.
    ke: DVec3,
    /// `Ns`; [`DEFAULT_NS`] when absent.
    ns: f64,
    /// `Ni`.
    ni: Option<f64>,
    /// `d`, or `1 − Tr`; 1 when neither is given.
    dissolve: f64,
    /// `Tf`.
    tf: Option<DVec3>,
    /// `Pr` (the PBR extension's roughness).
    pr: Option<f64>,
    /// `Pm` (the PBR extension's metalness).
    pm: Option<f64>,
    /// `illum`; 2 when absent.
    illum: u8,
}

impl Factors {
    /// The numbers of `m`; `textured` when a `map_Kd` texture supplies its colour.
    fn read(m: &tobj::Material, textured: bool) -> Self {
        let colour = |c: Option<[f64; 3]>| c.map(|[r, g, b]| DVec3::new(r, g, b));
        let default_albedo = if textured { 1.0 } else { DEFAULT_OBJ_ALBEDO };
        Self {
            kd: colour(m.diffuse).unwrap_or(DVec3::splat(default_albedo)),
            ks: colour(m.specular).unwrap_or(DVec3::ZERO),
            ke: colour(m.emissive).unwrap_or(DVec3::ZERO),
            ns: m.shininess.unwrap_or(DEFAULT_NS),
            ni: m.optical_density,
            dissolve: m
                .dissolve
                .or_else(|| extra(m, "Tr").map(|tr| 1.0 - tr))
                .unwrap_or(1.0),
            tf: extra_colour(m, "Tf"),
            pr: extra(m, "Pr"),
            pm: extra(m, "Pm"),
            illum: m.illumination_model.unwrap_or(2),
        }
    }
}

/// A number from a material's keys that `tobj` keeps as text (checked by
/// [`scan_mtl`](super::scan::scan_mtl)).
fn extra(material: &tobj::Material, key: &str) -> Option<f64> {
    material.unknown_param.get(key)?.parse().ok()
}

/// A colour from a material's keys that `tobj` keeps as text.
fn extra_colour(material: &tobj::Material, key: &str) -> Option<DVec3> {
    let values: Vec<f64> = material
        .unknown_param
        .get(key)?
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    match values.as_slice() {
        [r, g, b] => Some(DVec3::new(*r, *g, *b)),
        _ => None,
    }
}

/// Our material for `m` with its numbers `f`, as its illumination model and the PBR
/// extension choose: glass for `illum` 4, 6, 7 and 9, metal/roughness where `Pr`, `Pm`,
/// `map_Pr` or `map_Pm` is present, otherwise Lambert or Blinn-Phong (coated for
/// `illum` 3, 5 and 8). Values out of range are clamped with a warning.
fn shading_model(m: &tobj::Material, f: &Factors, warn: &mut dyn FnMut(String)) -> Material {
    let ke = f.ke;
    let emission = ke.clamp(DVec3::ZERO, DVec3::splat(MAX_RADIANCE));
    if emission != ke {
        warn(format!(
            "Ke {} is negative or above the 1e30 the GPU can sum in 32-bit floats; clamped",
            short3(ke)
        ));
    }
    if matches!(f.illum, 4 | 6 | 7 | 9) {
        glass(f, emission, warn)
    } else if f.pr.is_some()
        || f.pm.is_some()
        || m.unknown_param.contains_key("map_Pr")
        || m.unknown_param.contains_key("map_Pm")
    {
        metal_roughness(f, emission, warn)
    } else {
        blinn_phong(f, emission, warn)
    }
}

/// A glass (`illum` 4, 6, 7, 9): `Ni` its index of refraction, `Tf` its transmittance.
fn glass(f: &Factors, emission: DVec3, warn: &mut dyn FnMut(String)) -> Material {
    let ior = ior_or_default(f.ni, "the glass", warn);
    let transmittance = unit("Tf", f.tf.unwrap_or(DVec3::ONE), warn);
    Material {
        ior,
        transmittance,
        emission,
        ..Material::blank(MaterialKind::Dielectric)
    }
}

/// A metal/roughness material (the PBR extension): `Kd` its base colour, `Pm` its
/// metalness (0 if absent), `Pr` its roughness (1 if absent). A coat's `illum` is
/// ignored with a warning.
fn metal_roughness(f: &Factors, emission: DVec3, warn: &mut dyn FnMut(String)) -> Material {
    let illum = f.illum;
    if matches!(illum, 3 | 5 | 8) {
        warn(format!(
            "illum {illum} (coat) is ignored: Pr/Pm make it a metal/roughness material"
        ));
    }
    Material {
        diffuse: unit("Kd", f.kd, warn),
        metallic: clamp01("Pm", f.pm.unwrap_or(0.0), warn),
        roughness: clamp01("Pr", f.pr.unwrap_or(1.0), warn),
        emission,
        ..Material::blank(MaterialKind::Pbr)
    }
}

/// A Lambert material, or Blinn-Phong where it has a specular colour (`Ks`, none for
/// `illum` 0 and 1), coated for `illum` 3, 5 and 8; `Kd` and `Ks` scaled down together
/// where their sum would reflect more light than the surface receives.
fn blinn_phong(f: &Factors, emission: DVec3, warn: &mut dyn FnMut(String)) -> Material {
    let mut kd = unit("Kd", f.kd, warn);
    let mut ks = unit("Ks", f.ks, warn);
    if matches!(f.illum, 0 | 1) {
        ks = DVec3::ZERO;
    }
    let sum = (kd + ks).max_element();
    if sum > 1.0 {
        warn(format!(
            "Kd + Ks reaches {} in a channel; both are scaled by 1/{} so that the surface does not reflect more light than it receives",
            short(sum),
            short(sum)
        ));
        kd /= sum;
        ks /= sum;
    }
    let coat_ior = coat_ior(f, warn);
    if ks == DVec3::ZERO {
        Material {
            coat_ior,
            emission,
            ..Material::lambert(kd)
        }
    } else {
        Material {
            diffuse: kd,
            specular: ks,
            shininess: shininess(f.ns, warn),
            coat_ior,
            emission,
            ..Material::blank(MaterialKind::BlinnPhong)
        }
    }
}

/// The index of refraction of the coat of `illum` 3, 5 and 8 (`Ni`, [`DEFAULT_IOR`]
/// where it is not at least 1), 0 (no coat) for the other models.
fn coat_ior(f: &Factors, warn: &mut dyn FnMut(String)) -> f64 {
    if !matches!(f.illum, 3 | 5 | 8) {
        return 0.0;
    }
    let ior = ior_or_default(f.ni, "the coat", warn);
    if ior < 1.0 {
        warn(format!(
            "Ni {} is below 1; the coat uses {DEFAULT_IOR}",
            short(ior)
        ));
        DEFAULT_IOR
    } else {
        ior
    }
}

/// The Blinn-Phong exponent `ns`, clamped to [0, [`MAX_SHININESS`]] with a warning.
fn shininess(ns: f64, warn: &mut dyn FnMut(String)) -> f64 {
    if (0.0..=MAX_SHININESS).contains(&ns) {
        ns
    } else {
        warn(format!(
            "Ns {} is outside [0, {}]; clamped",
            short(ns),
            short(MAX_SHININESS)
        ));
        ns.clamp(0.0, MAX_SHININESS)
    }
}

/// `Ni` (`ni`) where it is positive, else [`DEFAULT_IOR`] (with a warning naming `what`
/// uses it where `Ni` is given).
fn ior_or_default(ni: Option<f64>, what: &str, warn: &mut dyn FnMut(String)) -> f64 {
    match ni {
        Some(ni) if ni > 0.0 => ni,
        Some(ni) => {
            warn(format!(
                "Ni {} is not positive; {what} uses {DEFAULT_IOR}",
                short(ni)
            ));
            DEFAULT_IOR
        }
        None => DEFAULT_IOR,
    }
}

/// The colour `c` of statement `name`, clamped to [0, 1] with a warning.
fn unit(name: &str, c: DVec3, warn: &mut dyn FnMut(String)) -> DVec3 {
    let clamped = c.clamp(DVec3::ZERO, DVec3::ONE);
    if clamped != c {
        warn(format!("{name} {} is outside [0, 1]; clamped", short3(c)));
    }
    clamped
}

/// The number `v` of statement `name`, clamped to [0, 1] with a warning.
fn clamp01(name: &str, v: f64, warn: &mut dyn FnMut(String)) -> f64 {
    if !(0.0..=1.0).contains(&v) {
        warn(format!("{name} {} is outside [0, 1]; clamped", short(v)));
    }
    v.clamp(0.0, 1.0)
}

/// `d` (or `1 − Tr`), `dissolve`, as coverage, as tinyobjloader (`dissolve`) and assimp
/// (`AI_MATKEY_OPACITY`) read it and viewers blend by it: glTF's BLEND with that alpha.
/// Glass needs none: it transmits by its own model.
fn apply_dissolve(material: &mut Material, dissolve: f64, warn: &mut dyn FnMut(String)) {
    if dissolve < 1.0 && material.kind != MaterialKind::Dielectric {
        if dissolve < 0.0 {
            warn(format!("d {} is below 0; read as 0", short(dissolve)));
        }
        material.alpha_mode = AlphaMode::Blend;
        material.alpha = dissolve.max(0.0);
    }
}
