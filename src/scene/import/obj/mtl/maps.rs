//! The texture statements of an MTL material loaded ([`load_maps`]): `map_Kd`, `map_Ke`,
//! `map_d`, the normal map (`norm`, else `bump`), and the PBR extension's `map_Pr` and
//! `map_Pm`, each relative to its library's directory, with the options read (the
//! scalar maps' `-imfchan` channel, the normal map's `-bm` strength) and warnings for
//! the statements and options that are not supported.

use std::path::Path;

use super::SourceMaterial;
use super::texture_options::{scale_and_offset, texture_options};
use crate::echo::{echo, echo_path, short};
use crate::scene::import::TextureRef;
use crate::scene::import::gltf::MAX_TEXTURE_TRANSFORM;
use crate::scene::import::mesh::Budget;
use crate::scene::import::obj::normal_map::{BumpImage, bump_multiplier, classify};
use crate::scene::import::obj::scalar_maps::ScalarChannel;
use crate::scene::import::obj::syntax::at;
use crate::scene::import::texture::{Encoding, Textures};
use crate::scene::{SceneError, TextureTransform};

/// A loaded texture statement: the texture, and the argument of the option its caller
/// reads (the scalar maps' `-imfchan`, the normal map's `-bm`), when it has one.
type Loaded = (TextureRef, Option<String>);

/// The textures of an MTL material, loaded, with how each is read.
pub(super) struct Maps {
    /// `map_Kd`: the albedo.
    pub(super) base_color: Option<TextureRef>,
    /// `map_Ke`: the emission.
    pub(super) emissive: Option<TextureRef>,
    /// `map_d`: coverage.
    pub(super) dissolve: Option<TextureRef>,
    /// The channel of `map_d` that holds the coverage.
    pub(super) coverage_channel: ScalarChannel,
    /// `norm` (or `bump`) where its image is a tangent-space normal map.
    pub(super) normal: Option<TextureRef>,
    /// The normal map's strength (`-bm`; 1 without one).
    pub(super) normal_scale: f64,
    /// `map_Pr`: roughness.
    pub(super) roughness: Option<TextureRef>,
    /// The channel of `map_Pr` that holds the roughness.
    pub(super) roughness_channel: ScalarChannel,
    /// `map_Pm`: metalness.
    pub(super) metallic: Option<TextureRef>,
    /// The channel of `map_Pm` that holds the metalness.
    pub(super) metallic_channel: ScalarChannel,
}

/// Loads the texture statements of `source` into `textures` (counted against
/// `budget`), reads their options, and warns (through `warn`) about what is not
/// supported: texture statements other than those loaded, and a `bump` beside a
/// `norm`. A texture file that is missing is a warning; one that exists but does not
/// decode is an error naming the library, line and column.
pub(super) fn load_maps(
    source: &SourceMaterial,
    textures: &mut Textures,
    budget: &mut Budget,
    warn: &mut dyn FnMut(String),
) -> Result<Maps, SceneError> {
    let m = &source.material;
    let mut loader = TextureLoader {
        source,
        textures,
        budget,
        warn,
    };
    let base_color = loader
        .load(
            "map_Kd",
            m.diffuse_texture.as_ref(),
            source.map_kd_at,
            Encoding::Color,
        )?
        .map(|(texture, _)| texture);
    let emissive = loader
        .load(
            "map_Ke",
            m.unknown_param.get("map_Ke"),
            source.map_ke_at,
            Encoding::Color,
        )?
        .map(|(texture, _)| texture);
    // A scalar texture: the file's values, not linearised.
    let dissolve = loader.load(
        "map_d",
        m.dissolve_texture.as_ref(),
        source.map_d_at,
        Encoding::Data,
    )?;
    // A normal map: `norm`, else `bump` (`map_Bump`) where its image is one.
    let norm = m.unknown_param.get("norm");
    let (normal_key, normal_spec, normal_at) = match norm {
        Some(spec) => ("norm", Some(spec), source.norm_at),
        None => ("bump", m.normal_texture.as_ref(), source.bump_at),
    };
    let normal = loader.load(normal_key, normal_spec, normal_at, Encoding::Data)?;
    // The PBR extension's scalar maps.
    let roughness = loader.load(
        "map_Pr",
        m.unknown_param.get("map_Pr"),
        source.map_pr_at,
        Encoding::Data,
    )?;
    let metallic = loader.load(
        "map_Pm",
        m.unknown_param.get("map_Pm"),
        source.map_pm_at,
        Encoding::Data,
    )?;
    let coverage_channel = channel(dissolve.as_ref(), "map_d", ScalarChannel::Auto, warn);
    let roughness_channel = channel(roughness.as_ref(), "map_Pr", ScalarChannel::Luminance, warn);
    let metallic_channel = channel(metallic.as_ref(), "map_Pm", ScalarChannel::Luminance, warn);
    warn_unsupported(m, warn);
    let (normal, normal_scale) = normal_map(normal, normal_key, textures, warn);
    Ok(Maps {
        base_color,
        emissive,
        dissolve: dissolve.map(|(texture, _)| texture),
        coverage_channel,
        normal,
        normal_scale,
        roughness: roughness.map(|(texture, _)| texture),
        roughness_channel,
        metallic: metallic.map(|(texture, _)| texture),
        metallic_channel,
    })
}

/// What loading the textures of one material needs: the material, the textures loaded
/// so far, the memory budget, and where its warnings go.
struct TextureLoader<'a> {
    /// The material, with its library and where its statements are.
    source: &'a SourceMaterial,
    /// Every texture of the model, each file loaded once.
    textures: &'a mut Textures,
    /// The memory the import may still use.
    budget: &'a mut Budget,
    /// Takes a warning about the material.
    warn: &'a mut dyn FnMut(String),
}

impl TextureLoader<'_> {
    /// A texture statement (`map_Kd`, `map_Ke`, `map_d`, `norm`, `bump`, `map_Pr`,
    /// `map_Pm`: `key`, its text `spec`) at `at_line`, loaded relative to the library's
    /// directory, with the argument of the option the caller reads (the scalar maps'
    /// `-imfchan`, the normal map's `-bm`). `None` without the statement, or with a
    /// warning where its file does not exist.
    fn load(
        &mut self,
        key: &str,
        spec: Option<&String>,
        at_line: Option<(usize, usize)>,
        encoding: Encoding,
    ) -> Result<Option<Loaded>, SceneError> {
        let (Some(spec), Some((line, column))) = (spec, at_line) else {
            return Ok(None);
        };
        let (file, wrap, mut ignored) = texture_options(spec);
        let handled = match key {
            "map_d" | "map_Pr" | "map_Pm" => "-imfchan ",
            "norm" | "bump" => "-bm ",
            _ => "",
        };
        let mut argument = None;
        if !handled.is_empty() {
            ignored.retain(|option| match option.strip_prefix(handled) {
                Some(value) => {
                    argument = Some(value.to_string());
                    false
                }
                None => true,
            });
        }
        let transform = scale_and_offset(&mut ignored).unwrap_or_else(|text| {
            (self.warn)(format!(
                "{key} {}: a scale or offset must be finite and at most {} in size; the texture is placed without it",
                echo(&text),
                short(MAX_TEXTURE_TRANSFORM)
            ));
            TextureTransform::IDENTITY
        });
        if !ignored.is_empty() {
            (self.warn)(format!(
                "{key} options {} are not supported; ignored",
                echo(&ignored.join(" "))
            ));
        }
        let source = self.source;
        let directory = source.library.parent().unwrap_or(Path::new(""));
        let mut file_path = directory.join(&file);
        if !file_path.exists() && file.contains('\\') {
            file_path = directory.join(file.replace('\\', "/"));
        }
        if !file_path.exists() {
            // Exporters write absolute paths of the author's machine, and models are
            // shared without their textures: the geometry is still worth seeing.
            (self.warn)(format!(
                "{key}: the texture {} does not exist; the material is used without it",
                echo_path(&file_path)
            ));
            return Ok(None);
        }
        let image = self
            .textures
            .file(&file_path, encoding, self.budget)
            .map_err(|e| {
                at(
                    &source.library,
                    line,
                    column,
                    format!("material '{}': {key}: {e}", echo(&source.material.name)),
                )
            })?;
        let texture = TextureRef {
            image,
            wrap_u: wrap,
            wrap_v: wrap,
            transform,
        };
        Ok(Some((texture, argument)))
    }
}

/// The channel a scalar map's `-imfchan` names (the map of statement `key`), `fallback`
/// without one (or, with a warning, with one MTL does not define).
fn channel(
    map: Option<&Loaded>,
    key: &str,
    fallback: ScalarChannel,
    warn: &mut dyn FnMut(String),
) -> ScalarChannel {
    let Some(letter) = map.and_then(|(_, letter)| letter.as_deref()) else {
        return fallback;
    };
    ScalarChannel::from_imfchan(letter).unwrap_or_else(|| {
        warn(format!(
            "{key} -imfchan {} is not supported (r, g, b, m or l are); {} is read",
            echo(letter),
            match fallback {
                ScalarChannel::Auto => "its alpha, or else its luminance,",
                _ => "its luminance",
            }
        ));
        fallback
    })
}

/// Warns about the texture statements of `m` that are not read (`map_Ks`, `map_Ka`,
/// `map_Ns`, `disp`, `decal`, `refl` and other `map_` keywords), and about a `bump`
/// that a `norm` overrides.
fn warn_unsupported(m: &tobj::Material, warn: &mut dyn FnMut(String)) {
    for (key, present) in [
        ("map_Ks", m.specular_texture.is_some()),
        ("map_Ka", m.ambient_texture.is_some()),
        ("map_Ns", m.shininess_texture.is_some()),
    ] {
        if present {
            warn(format!("{key} is not supported; ignored"));
        }
    }
    let mut others: Vec<&String> = m
        .unknown_param
        .keys()
        .filter(|k| {
            (k.starts_with("map_") && !matches!(k.as_str(), "map_Ke" | "map_Pr" | "map_Pm"))
                || matches!(k.as_str(), "disp" | "decal" | "refl")
        })
        .collect();
    others.sort();
    for key in others {
        warn(format!("{} is not supported; ignored", echo(key)));
    }
    if m.unknown_param.contains_key("norm") && m.normal_texture.is_some() {
        warn("bump is ignored: norm gives the normal map".into());
    }
}

/// The normal map of statement `key` where its image is one, and its strength (`-bm`);
/// where the image is not a tangent-space normal map, none (with a warning) and 1.
fn normal_map(
    loaded: Option<Loaded>,
    key: &str,
    textures: &Textures,
    warn: &mut dyn FnMut(String),
) -> (Option<TextureRef>, f64) {
    let Some((texture, multiplier)) = loaded else {
        return (None, 1.0);
    };
    let image = &textures.images[texture.image as usize];
    let why = match classify(image) {
        BumpImage::NormalMap => "",
        BumpImage::HeightMap => {
            "is grey, a height map: bump mapping is not supported (tangent-space normal maps are)"
        }
        BumpImage::Unclear => {
            "is not a tangent-space normal map (its blue channel, the normal's z, averages below one half)"
        }
    };
    if why.is_empty() {
        let scale = match multiplier.as_deref() {
            None => 1.0,
            Some(text) => bump_multiplier(text).unwrap_or_else(|| {
                warn(format!(
                    "{key} -bm {} is not a finite number; the normal map's strength is 1",
                    echo(text)
                ));
                1.0
            }),
        };
        (Some(texture), scale)
    } else {
        warn(format!(
            "{key}: the image {} {why}; ignored",
            echo_path(&image.path)
        ));
        (None, 1.0)
    }
}
