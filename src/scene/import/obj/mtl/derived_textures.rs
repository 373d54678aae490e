//! The textures an MTL material's scalar maps derive, made once per pair of images
//! (the texels: [`scalar_maps`](crate::scene::import::obj::scalar_maps)): `map_d`'s
//! coverage put into the alpha of the albedo texture ([`coverage_in_base_color`]), and
//! `map_Pr` and `map_Pm` made one metallic/roughness texture
//! ([`metallic_roughness_texture`]).

use super::SourceMaterial;
use super::maps::Maps;
use crate::echo::echo;
use crate::scene::import::TextureRef;
use crate::scene::import::mesh::Budget;
use crate::scene::import::obj::scalar_maps::{
    coverage_size, metallic_roughness, metallic_roughness_size, with_coverage,
};
use crate::scene::import::obj::syntax::at;
use crate::scene::import::texture::Textures;
use crate::scene::{AlphaMode, Material, MaterialKind, SceneError};

/// The albedo texture of `material` with `map_d` as coverage in its alpha, as
/// tinyobjloader and assimp read it (made once per pair of images; `maps.base_color`
/// itself without a `map_d`), `material` blended by it. Ignored on glass, as `d` is.
pub(super) fn coverage_in_base_color(
    material: &mut Material,
    maps: &Maps,
    source: &SourceMaterial,
    textures: &mut Textures,
    budget: &mut Budget,
    warn: &mut dyn FnMut(String),
) -> Result<Option<TextureRef>, SceneError> {
    let m = &source.material;
    let mut base_color_texture = maps.base_color;
    let (dissolve_texture, coverage_channel) = (maps.dissolve, maps.coverage_channel);
    // `map_d` as coverage too, in the albedo texture's alpha (made once per pair of
    // images); ignored on glass as `d` is.
    if let Some(mask) = dissolve_texture {
        if material.kind == MaterialKind::Dielectric {
            warn("map_d is ignored on glass (illum 4, 6, 7, 9), as d is".into());
        } else {
            if base_color_texture.is_some_and(|b| b.transform != mask.transform) {
                warn(
                    "map_d's -s or -o differ from map_Kd's; its coverage is placed as map_Kd is"
                        .into(),
                );
            }
            let base = base_color_texture.map(|t| t.image);
            let size = coverage_size(
                base.map(|i| &textures.images[i as usize]),
                &textures.images[mask.image as usize],
            );
            let key = format!("{base:?} {} {coverage_channel:?}", mask.image);
            let image = textures
                .derived(
                    key,
                    size,
                    |images| {
                        with_coverage(
                            base.map(|i| &images[i as usize]),
                            &images[mask.image as usize],
                            coverage_channel,
                        )
                    },
                    budget,
                )
                .map_err(|e| {
                    let (line, column) = source.map_d_at.unwrap_or((source.line, 1));
                    at(
                        &source.library,
                        line,
                        column,
                        format!("material '{}': map_d: {e}", echo(&m.name)),
                    )
                })?;
            base_color_texture = Some(TextureRef {
                image,
                ..base_color_texture.unwrap_or(mask)
            });
            material.alpha_mode = AlphaMode::Blend;
        }
    }
    Ok(base_color_texture)
}

/// `map_Pr` and `map_Pm` as one metallic/roughness texture (made once per pair of
/// images), read by metal/roughness materials only; a map replaces its factor in
/// `material`.
pub(super) fn metallic_roughness_texture(
    material: &mut Material,
    maps: &Maps,
    source: &SourceMaterial,
    textures: &mut Textures,
    budget: &mut Budget,
    warn: &mut dyn FnMut(String),
) -> Result<Option<TextureRef>, SceneError> {
    let m = &source.material;
    let (rough, metal) = (maps.roughness, maps.metallic);
    let (rough_channel, metal_channel) = (maps.roughness_channel, maps.metallic_channel);
    let mut metallic_roughness_texture = None;
    if (rough.is_some() || metal.is_some()) && material.kind != MaterialKind::Pbr {
        warn(
            "map_Pr and map_Pm are read by metal/roughness materials only; ignored on glass".into(),
        );
    } else if let (Some(placed), Some(size)) = (
        rough.or(metal),
        metallic_roughness_size(
            rough.map(|t| &textures.images[t.image as usize]),
            metal.map(|t| &textures.images[t.image as usize]),
        ),
    ) {
        if let (Some(r), Some(m)) = (rough, metal)
            && (r.transform != m.transform || r.wrap_u != m.wrap_u)
        {
            warn(
                "map_Pm's -s, -o or -clamp differ from map_Pr's; it is placed as map_Pr is".into(),
            );
        }
        let key = format!(
            "{:?} {rough_channel:?} {:?} {metal_channel:?}",
            rough.map(|t| t.image),
            metal.map(|t| t.image)
        );
        let image = textures
            .derived(
                key,
                size,
                |images| {
                    let map = |t: Option<TextureRef>, c| t.map(|t| (&images[t.image as usize], c));
                    metallic_roughness(map(rough, rough_channel), map(metal, metal_channel))
                        .expect("one of the two maps")
                },
                budget,
            )
            .map_err(|e| {
                let (line, column) = source
                    .map_pr_at
                    .or(source.map_pm_at)
                    .unwrap_or((source.line, 1));
                at(
                    &source.library,
                    line,
                    column,
                    format!("material '{}': map_Pr/map_Pm: {e}", echo(&m.name)),
                )
            })?;
        metallic_roughness_texture = Some(TextureRef { image, ..placed });
        // A map replaces its factor, as Blender's importer reads it (it links the map
        // in the factor's place).
        if rough.is_some() {
            material.roughness = 1.0;
        }
        if metal.is_some() {
            material.metallic = 1.0;
        }
    }
    Ok(metallic_roughness_texture)
}
