//! MTL material libraries (Alias|Wavefront Advanced Visualizer manual, appendix B2):
//! each line checked here (errors name the library, line and column), then parsed by
//! `tobj`, and each material mapped onto ours (the table in `docs/models.md`).

use std::collections::{HashMap, HashSet};
use std::io::{Cursor, ErrorKind};
use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use super::normal_map::{BumpImage, bump_multiplier, classify};
use super::scalar_maps::{
    ScalarChannel, coverage_size, metallic_roughness, metallic_roughness_size, with_coverage,
};
use super::{DEFAULT_OBJ_ALBEDO, Notes, at, decode_text, finite, is_integer, strip_comment, words};
use crate::echo::{echo, echo_path, short, short3};
use crate::input::{InputError, read_input};
use crate::scene::import::gltf::MAX_TEXTURE_TRANSFORM;
use crate::scene::import::mesh::Budget;
use crate::scene::import::texture::{Encoding, Textures};
use crate::scene::import::{ImportedMaterial, MAX_MODEL_FILE_BYTES, TextureRef, WrapMode, error};
use crate::scene::{AlphaMode, MAX_RADIANCE, Material, MaterialKind, SceneError, TextureTransform};

/// Index of refraction assumed for glass (`illum` 4, 6, 7, 9) and coats (`illum` 3, 5, 8)
/// whose material gives no usable `Ni`.
const DEFAULT_IOR: f64 = 1.5;
/// Blinn-Phong exponent assumed when `Ns` is absent (as tinyobjloader does).
const DEFAULT_NS: f64 = 1.0;
/// Largest accepted Blinn-Phong exponent (the scene format's limit).
const MAX_SHININESS: f64 = 1e6;

/// A material of an MTL library with what `tobj` does not keep: where it was defined.
pub(super) struct SourceMaterial {
    material: tobj::Material,
    /// The library file.
    library: PathBuf,
    /// The line of its `newmtl`.
    line: usize,
    /// The line of the OBJ file's `mtllib` that named the library.
    pub(super) mtllib_line: usize,
    /// `map_Kd` line and column, when it has one.
    map_kd_at: Option<(usize, usize)>,
    /// `map_Ke` line and column, when it has one.
    map_ke_at: Option<(usize, usize)>,
    /// `map_d` line and column, when it has one.
    map_d_at: Option<(usize, usize)>,
    /// `norm` line and column, when it has one.
    norm_at: Option<(usize, usize)>,
    /// `bump` (or `map_Bump`, `map_bump`) line and column, when it has one.
    bump_at: Option<(usize, usize)>,
    /// `map_Pr` line and column, when it has one.
    map_pr_at: Option<(usize, usize)>,
    /// `map_Pm` line and column, when it has one.
    map_pm_at: Option<(usize, usize)>,
}

/// The material libraries an OBJ file names.
#[derive(Default)]
pub(super) struct Libraries {
    /// Every material, libraries in `mtllib` order, materials in file order.
    pub(super) materials: Vec<SourceMaterial>,
    /// Material name → index; of two materials of one name the later one wins.
    pub(super) index: HashMap<String, usize>,
    /// Whether a library could not be read (a warning said so).
    pub(super) any_missing: bool,
}

impl Libraries {
    /// Reads the libraries of the OBJ file `obj` named by its `mtllib` statements (the
    /// text after the keyword, and the line), relative to `directory`, each file once.
    /// A library that does not exist is a warning, one per statement, its materials
    /// replaced by the default one (as tinyobjloader and assimp do); one that exists but
    /// cannot be read (a FIFO, a device, too large), or has a malformed line, is an
    /// error naming the library, line and column.
    pub(super) fn load(
        statements: &[(String, usize)],
        directory: &Path,
        obj: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<Self, SceneError> {
        let mut libraries = Self::default();
        let mut read = HashSet::new();
        for (text, line) in statements {
            let mut unread: Vec<(String, String)> = Vec::new();
            for name in library_names(text, directory) {
                let mut file = directory.join(&name);
                if !file.exists() && name.contains('\\') {
                    file = directory.join(name.replace('\\', "/"));
                }
                if !read.insert(file.clone()) {
                    continue;
                }
                let message = |e: InputError| {
                    format!("cannot read the material library {}: {e}", echo_path(&file))
                };
                match read_input(&file, MAX_MODEL_FILE_BYTES) {
                    Ok(bytes) => libraries.parse(&file, &bytes, *line, warnings)?,
                    Err(InputError::Io(e)) if e.kind() == ErrorKind::NotFound => {
                        unread.push((name, message(InputError::Io(e))));
                    }
                    // A FIFO, a device or a huge file is not a library that went missing
                    // but one that must not be read (src/input.rs).
                    Err(e) => {
                        return Err(at(
                            obj,
                            *line,
                            1,
                            format!("mtllib {}: {}", echo(&name), message(e)),
                        ));
                    }
                }
            }
            if let Some((name, message)) = unread.first() {
                libraries.any_missing = true;
                let others = match unread.len() - 1 {
                    0 => String::new(),
                    _ => format!(
                        " (nor can {}, named on the same line)",
                        unread[1..]
                            .iter()
                            .map(|(name, _)| echo(name).to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                };
                warnings.push(format!(
                    "{}:{line}: mtllib {}: {message}{others}; the materials it would define are replaced by the default material",
                    obj.display(),
                    echo(name)
                ));
            }
        }
        Ok(libraries)
    }

    /// Checks and parses one library's text, named on line `mtllib_line` of the OBJ file.
    fn parse(
        &mut self,
        library: &Path,
        bytes: &[u8],
        mtllib_line: usize,
        warnings: &mut Vec<String>,
    ) -> Result<(), SceneError> {
        let text = decode_text(bytes, library, warnings);
        let mut notes = Notes::default();
        let (clean, lines) = scan_mtl(&text, library, &mut notes)?;
        notes.report(library, warnings);
        let (materials, _) =
            tobj::load_mtl_buf(&mut Cursor::new(clean.as_bytes())).map_err(|e| {
                error(
                    library,
                    format!("the material library could not be read: {e}"),
                )
            })?;
        for (
            material,
            MtlLines {
                line,
                map_kd_at,
                map_ke_at,
                map_d_at,
                norm_at,
                bump_at,
                map_pr_at,
                map_pm_at,
            },
        ) in materials.into_iter().zip(lines)
        {
            self.index
                .insert(material.name.clone(), self.materials.len());
            self.materials.push(SourceMaterial {
                material,
                library: library.to_path_buf(),
                line,
                mtllib_line,
                map_kd_at,
                map_ke_at,
                map_d_at,
                norm_at,
                bump_at,
                map_pr_at,
                map_pm_at,
            });
        }
        Ok(())
    }
}

/// The file names a `mtllib` statement gives: the whole text when a file has that name
/// (names with spaces are common; tobj reads them so), otherwise its words, `\ ` within
/// a word standing for a space (several libraries on one line, as the specification
/// and tinyobjloader read it).
fn library_names(text: &str, directory: &Path) -> Vec<String> {
    if !text.contains(char::is_whitespace) || directory.join(text).is_file() {
        return vec![text.to_string()];
    }
    let mut names = Vec::new();
    let mut name = String::new();
    let mut characters = text.chars().peekable();
    while let Some(c) = characters.next() {
        if c == '\\' && characters.peek().is_some_and(|next| next.is_whitespace()) {
            name.extend(characters.next());
        } else if c.is_whitespace() {
            if !name.is_empty() {
                names.push(std::mem::take(&mut name));
            }
        } else {
            name.push(c);
        }
    }
    if !name.is_empty() {
        names.push(name);
    }
    names
}

/// Colour keywords of MTL (1 or 3 numbers).
const MTL_COLOURS: &[&str] = &["Ka", "Kd", "Ks", "Ke", "Tf"];
/// Scalar keywords of MTL and of its PBR extension.
const MTL_SCALARS: &[&str] = &[
    "Ns",
    "Ni",
    "d",
    "Tr",
    "Pr",
    "Pm",
    "Ps",
    "Pc",
    "Pcr",
    "aniso",
    "anisor",
    "sharpness",
];

/// Where a material of an MTL library is defined: the line of its `newmtl`, and the line
/// and column of its `map_Kd`, `map_Ke` and `map_d`, when it has them.
struct MtlLines {
    line: usize,
    map_kd_at: Option<(usize, usize)>,
    map_ke_at: Option<(usize, usize)>,
    map_d_at: Option<(usize, usize)>,
    norm_at: Option<(usize, usize)>,
    bump_at: Option<(usize, usize)>,
    map_pr_at: Option<(usize, usize)>,
    map_pm_at: Option<(usize, usize)>,
}

/// Checks every line of an MTL library and returns the text for `tobj` (colours with one
/// number spelled out as three, unsupported forms blanked) and, per material in order,
/// where it is defined.
fn scan_mtl(
    text: &str,
    path: &Path,
    notes: &mut Notes,
) -> Result<(String, Vec<MtlLines>), SceneError> {
    let mut clean = String::with_capacity(text.len());
    let mut lines = Vec::new();
    let mut nameless = false;
    for (index, line) in text.lines().enumerate() {
        let n = index + 1;
        let line = strip_comment(line);
        let words = words(line);
        let Some(&(column, keyword)) = words.first() else {
            clean.push('\n');
            continue;
        };
        let values = &words[1..];
        let mut kept = line.trim().to_string();
        if keyword == "newmtl" {
            // A material no `usemtl` can name (tobj refuses it): skipped to the next.
            nameless = values.is_empty();
            if nameless {
                notes.nameless_materials.note(|| n);
            }
        }
        if nameless {
            clean.push('\n');
            continue;
        }
        if keyword == "newmtl" {
            lines.push(MtlLines {
                line: n,
                map_kd_at: None,
                map_ke_at: None,
                map_d_at: None,
                norm_at: None,
                bump_at: None,
                map_pr_at: None,
                map_pm_at: None,
            });
        } else if MTL_COLOURS.contains(&keyword) {
            if values
                .first()
                .is_some_and(|w| w.1 == "spectral" || w.1 == "xyz")
            {
                // Spectral and CIE XYZ colours are not supported: dropped.
                kept.clear();
            } else {
                if values.len() != 1 && values.len() != 3 {
                    return Err(at(
                        path,
                        n,
                        column,
                        format!(
                            "`{keyword}` takes r g b (or one grey value), got {} numbers",
                            values.len()
                        ),
                    ));
                }
                let mut rgb = [0.0; 3];
                for (c, word) in values.iter().enumerate() {
                    rgb[c] = finite(path, n, *word, keyword, notes)?;
                }
                if values.len() == 1 {
                    rgb = [rgb[0]; 3];
                }
                kept = format!("{keyword} {:?} {:?} {:?}", rgb[0], rgb[1], rgb[2]);
            }
        } else if MTL_SCALARS.contains(&keyword) {
            // `d -halo 0.5`: the halo form is read as a plain dissolve.
            let values: Vec<_> = values.iter().filter(|w| w.1 != "-halo").collect();
            if values.len() != 1 {
                return Err(at(
                    path,
                    n,
                    column,
                    format!("`{keyword}` takes one number, got {}", values.len()),
                ));
            }
            let value = finite(path, n, *values[0], keyword, notes)?;
            kept = format!("{keyword} {value:?}");
        } else if keyword == "illum" {
            let [word] = values else {
                return Err(at(path, n, column, "`illum` takes one number (0 to 10)"));
            };
            let illum: Option<i64> = match word.1.parse() {
                Ok(illum) => Some(illum),
                // An integer of more digits than an i64 holds: no model either.
                Err(_) if is_integer(word.1) => None,
                Err(_) => {
                    return Err(at(
                        path,
                        n,
                        word.0,
                        format!("illum: `{}` is not an integer", echo(word.1)),
                    ));
                }
            };
            if !illum.is_some_and(|illum| (0..=10).contains(&illum)) {
                return Err(at(
                    path,
                    n,
                    word.0,
                    format!(
                        "illum {} is not an illumination model (0 to 10)",
                        echo(word.1)
                    ),
                ));
            }
        } else if keyword.starts_with("map_")
            || matches!(keyword, "bump" | "disp" | "decal" | "refl" | "norm")
        {
            if values.is_empty() {
                return Err(at(
                    path,
                    n,
                    column,
                    format!("`{}` needs a file name", echo(keyword)),
                ));
            }
            if matches!(
                keyword,
                "map_Kd"
                    | "map_Ke"
                    | "map_d"
                    | "norm"
                    | "bump"
                    | "map_Bump"
                    | "map_bump"
                    | "map_Pr"
                    | "map_Pm"
            ) {
                match lines.last_mut() {
                    Some(last) if keyword == "map_Kd" => last.map_kd_at = Some((n, column)),
                    Some(last) if keyword == "map_Ke" => last.map_ke_at = Some((n, column)),
                    Some(last) if keyword == "map_d" => last.map_d_at = Some((n, column)),
                    Some(last) if keyword == "norm" => last.norm_at = Some((n, column)),
                    Some(last) if keyword == "map_Pr" => last.map_pr_at = Some((n, column)),
                    Some(last) if keyword == "map_Pm" => last.map_pm_at = Some((n, column)),
                    Some(last) => last.bump_at = Some((n, column)),
                    None => kept.clear(),
                }
            }
        }
        if lines.is_empty() {
            // Before the first `newmtl`: belongs to no material.
            kept.clear();
        }
        clean.push_str(&kept);
        clean.push('\n');
    }
    Ok((clean, lines))
}

/// A number from a material's keys that `tobj` keeps as text (checked by [`scan_mtl`]).
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

/// Maps one MTL material onto ours (the table in `docs/models.md`).
pub(super) fn map_material(
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
    let colour = |c: Option<[f64; 3]>| c.map(|[r, g, b]| DVec3::new(r, g, b));

    // A texture statement (`map_Kd`, `map_Ke`, `map_d`, `norm`, `bump`, `map_Pr`,
    // `map_Pm`) at `at`, loaded relative to the library's directory, with the argument of
    // the option the caller reads (the scalar maps' `-imfchan`, the normal map's `-bm`).
    let mut load_texture = |key: &str,
                            spec: Option<&String>,
                            at_line: Option<(usize, usize)>,
                            encoding: Encoding|
     -> Result<Option<(TextureRef, Option<String>)>, SceneError> {
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
            warn(format!(
                "{key} {}: a scale or offset must be finite and at most {} in size; the texture is placed without it",
                echo(&text),
                short(MAX_TEXTURE_TRANSFORM)
            ));
            TextureTransform::IDENTITY
        });
        if !ignored.is_empty() {
            warn(format!(
                "{key} options {} are not supported; ignored",
                echo(&ignored.join(" "))
            ));
        }
        let directory = source.library.parent().unwrap_or(Path::new(""));
        let mut file_path = directory.join(&file);
        if !file_path.exists() && file.contains('\\') {
            file_path = directory.join(file.replace('\\', "/"));
        }
        if !file_path.exists() {
            // Exporters write absolute paths of the author's machine, and models are
            // shared without their textures: the geometry is still worth seeing.
            warn(format!(
                "{key}: the texture {} does not exist; the material is used without it",
                echo_path(&file_path)
            ));
            return Ok(None);
        }
        let image = textures.file(&file_path, encoding, budget).map_err(|e| {
            at(
                &source.library,
                line,
                column,
                format!("material '{}': {key}: {e}", echo(&m.name)),
            )
        })?;
        let texture = TextureRef {
            image,
            wrap_u: wrap,
            wrap_v: wrap,
            transform,
        };
        Ok(Some((texture, argument)))
    };
    let mut base_color_texture = load_texture(
        "map_Kd",
        m.diffuse_texture.as_ref(),
        source.map_kd_at,
        Encoding::Color,
    )?
    .map(|(texture, _)| texture);
    let emissive_texture = load_texture(
        "map_Ke",
        m.unknown_param.get("map_Ke"),
        source.map_ke_at,
        Encoding::Color,
    )?
    .map(|(texture, _)| texture);
    // A scalar texture: the file's values, not linearised.
    let dissolve_texture = load_texture(
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
    let normal_texture = load_texture(normal_key, normal_spec, normal_at, Encoding::Data)?;
    // The PBR extension's scalar maps.
    let roughness_map = load_texture(
        "map_Pr",
        m.unknown_param.get("map_Pr"),
        source.map_pr_at,
        Encoding::Data,
    )?;
    let metallic_map = load_texture(
        "map_Pm",
        m.unknown_param.get("map_Pm"),
        source.map_pm_at,
        Encoding::Data,
    )?;
    // The channel a scalar map's -imfchan names, `fallback` without one (or, with a
    // warning, with one MTL does not define).
    let mut channel =
        |map: &Option<(TextureRef, Option<String>)>, key: &str, fallback: ScalarChannel| {
            let Some(letter) = map.as_ref().and_then(|(_, letter)| letter.as_deref()) else {
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
        };
    let coverage_channel = channel(&dissolve_texture, "map_d", ScalarChannel::Auto);
    let rough_channel = channel(&roughness_map, "map_Pr", ScalarChannel::Luminance);
    let metal_channel = channel(&metallic_map, "map_Pm", ScalarChannel::Luminance);
    let dissolve_texture = dissolve_texture.map(|(texture, _)| texture);
    let (rough, metal) = (
        roughness_map.map(|(texture, _)| texture),
        metallic_map.map(|(texture, _)| texture),
    );
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
    if norm.is_some() && m.normal_texture.is_some() {
        warn("bump is ignored: norm gives the normal map".into());
    }
    // The normal map where its image is one, and its strength (`-bm`).
    let (normal_texture, normal_scale) = match normal_texture {
        Some((texture, multiplier)) => {
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
                            "{normal_key} -bm {} is not a finite number; the normal map's strength is 1",
                            echo(text)
                        ));
                        1.0
                    }),
                };
                (Some(texture), scale)
            } else {
                warn(format!(
                    "{normal_key}: the image {} {why}; ignored",
                    echo_path(&image.path)
                ));
                (None, 1.0)
            }
        }
        None => (None, 1.0),
    };

    let default_albedo = if base_color_texture.is_some() {
        1.0
    } else {
        DEFAULT_OBJ_ALBEDO
    };
    let mut kd = colour(m.diffuse).unwrap_or(DVec3::splat(default_albedo));
    let mut ks = colour(m.specular).unwrap_or(DVec3::ZERO);
    let ke = colour(m.emissive).unwrap_or(DVec3::ZERO);
    let ns = m.shininess.unwrap_or(DEFAULT_NS);
    let ni = m.optical_density;
    let dissolve = m
        .dissolve
        .or_else(|| extra(m, "Tr").map(|tr| 1.0 - tr))
        .unwrap_or(1.0);
    let tf = extra_colour(m, "Tf");
    let (pr, pm) = (extra(m, "Pr"), extra(m, "Pm"));
    let illum = m.illumination_model.unwrap_or(2);

    let unit = |name: &str, c: DVec3, warn: &mut dyn FnMut(String)| {
        let clamped = c.clamp(DVec3::ZERO, DVec3::ONE);
        if clamped != c {
            warn(format!("{name} {} is outside [0, 1]; clamped", short3(c)));
        }
        clamped
    };
    let emission = ke.clamp(DVec3::ZERO, DVec3::splat(MAX_RADIANCE));
    if emission != ke {
        warn(format!(
            "Ke {} is negative or above the 1e30 the GPU can sum in 32-bit floats; clamped",
            short3(ke)
        ));
    }
    let ior_or_default = |warn: &mut dyn FnMut(String), what: &str| match ni {
        Some(ni) if ni > 0.0 => ni,
        Some(ni) => {
            warn(format!(
                "Ni {} is not positive; {what} uses {DEFAULT_IOR}",
                short(ni)
            ));
            DEFAULT_IOR
        }
        None => DEFAULT_IOR,
    };

    let mut material = if matches!(illum, 4 | 6 | 7 | 9) {
        let ior = ior_or_default(&mut warn, "the glass");
        let transmittance = unit("Tf", tf.unwrap_or(DVec3::ONE), &mut warn);
        Material {
            ior,
            transmittance,
            emission,
            ..Material::blank(MaterialKind::Dielectric)
        }
    } else if pr.is_some()
        || pm.is_some()
        || m.unknown_param.contains_key("map_Pr")
        || m.unknown_param.contains_key("map_Pm")
    {
        if matches!(illum, 3 | 5 | 8) {
            warn(format!(
                "illum {illum} (coat) is ignored: Pr/Pm make it a metal/roughness material"
            ));
        }
        let clamp01 = |name: &str, v: f64, warn: &mut dyn FnMut(String)| {
            if !(0.0..=1.0).contains(&v) {
                warn(format!("{name} {} is outside [0, 1]; clamped", short(v)));
            }
            v.clamp(0.0, 1.0)
        };
        Material {
            diffuse: unit("Kd", kd, &mut warn),
            metallic: clamp01("Pm", pm.unwrap_or(0.0), &mut warn),
            roughness: clamp01("Pr", pr.unwrap_or(1.0), &mut warn),
            emission,
            ..Material::blank(MaterialKind::Pbr)
        }
    } else {
        kd = unit("Kd", kd, &mut warn);
        ks = unit("Ks", ks, &mut warn);
        if matches!(illum, 0 | 1) {
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
        let coat_ior = if matches!(illum, 3 | 5 | 8) {
            let ior = ior_or_default(&mut warn, "the coat");
            if ior < 1.0 {
                warn(format!(
                    "Ni {} is below 1; the coat uses {DEFAULT_IOR}",
                    short(ior)
                ));
                DEFAULT_IOR
            } else {
                ior
            }
        } else {
            0.0
        };
        if ks == DVec3::ZERO {
            Material {
                coat_ior,
                emission,
                ..Material::lambert(kd)
            }
        } else {
            let shininess = if (0.0..=MAX_SHININESS).contains(&ns) {
                ns
            } else {
                warn(format!(
                    "Ns {} is outside [0, {}]; clamped",
                    short(ns),
                    short(MAX_SHININESS)
                ));
                ns.clamp(0.0, MAX_SHININESS)
            };
            Material {
                diffuse: kd,
                specular: ks,
                shininess,
                coat_ior,
                emission,
                ..Material::blank(MaterialKind::BlinnPhong)
            }
        }
    };
    // `d` (or `1 − Tr`) as coverage, as tinyobjloader (`dissolve`) and assimp
    // (`AI_MATKEY_OPACITY`) read it and viewers blend by it: glTF's BLEND with that
    // alpha. Glass needs none: it transmits by its own model.
    if dissolve < 1.0 && material.kind != MaterialKind::Dielectric {
        if dissolve < 0.0 {
            warn(format!("d {} is below 0; read as 0", short(dissolve)));
        }
        material.alpha_mode = AlphaMode::Blend;
        material.alpha = dissolve.max(0.0);
    }
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
    if normal_texture.is_some() {
        material.normal_scale = normal_scale;
    }
    // map_Pr and map_Pm as one metallic/roughness texture (made once per pair).
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
    Ok(ImportedMaterial {
        name: m.name.clone(),
        material,
        base_color_texture,
        metallic_roughness_texture,
        emissive_texture,
        normal_texture,
    })
}

/// The `-s` (scale) and `-o` (origin offset) options of a texture statement, taken out
/// of `options` (its unsupported ones, as [`texture_options`] lists them), as the map
/// of the texture's coordinates that tinyobjloader reads and three.js's MTLLoader
/// applies (`repeat` and `offset`: `uv · s + o`), in our coordinates, whose `v` runs
/// down (`v = 1 − v_obj`): scale `(s_u, s_v)`, offset `(o_u, 1 − s_v − o_v)`. Missing
/// values are MTL's defaults (scale 1, offset 0); the third (`w`) is ignored. `Err`
/// with the option's text where a value is not a finite number of at most
/// [`MAX_TEXTURE_TRANSFORM`] in size.
fn scale_and_offset(options: &mut Vec<String>) -> Result<TextureTransform, String> {
    let mut scale = DVec2::ONE;
    let mut offset = DVec2::ZERO;
    let mut problem = None;
    options.retain(|option| {
        let mut words = option.split_whitespace();
        let target = match words.next() {
            Some("-s") => &mut scale,
            Some("-o") => &mut offset,
            _ => return true,
        };
        for (axis, word) in words.take(2).enumerate() {
            match word.parse::<f64>() {
                Ok(v) if v.is_finite() && v.abs() <= MAX_TEXTURE_TRANSFORM => target[axis] = v,
                _ => problem = Some(option.clone()),
            }
        }
        false
    });
    if let Some(option) = problem {
        return Err(option);
    }
    let offset = DVec2::new(offset.x, 1.0 - scale.y - offset.y);
    Ok(TextureTransform::offset_rotation_scale(
        0, offset, 0.0, scale,
    ))
}

/// Splits a texture statement (`-clamp on -s 2 2 file name.png`) into the file name, the
/// wrap mode (`-clamp on` clamps) and the options that are not supported.
pub(super) fn texture_options(spec: &str) -> (String, WrapMode, Vec<String>) {
    /// Options and how many arguments each takes at most (all but the last are numbers).
    const OPTIONS: &[(&str, usize)] = &[
        ("-blendu", 1),
        ("-blendv", 1),
        ("-bm", 1),
        ("-boost", 1),
        ("-cc", 1),
        ("-clamp", 1),
        ("-colorspace", 1),
        ("-imfchan", 1),
        ("-mm", 2),
        ("-o", 3),
        ("-s", 3),
        ("-t", 3),
        ("-texres", 1),
        ("-type", 1),
    ];
    let words: Vec<&str> = spec.split_whitespace().collect();
    let mut wrap = WrapMode::Repeat;
    if words.is_empty() {
        return (String::new(), wrap, Vec::new());
    }
    let mut ignored = Vec::new();
    // The options from word `i` on, each with at most its count of arguments (all but
    // the last numbers), none past `end`: returns the word after them.
    let mut options = |mut i: usize, end: usize| {
        while i < end {
            let Some(&(option, most)) = OPTIONS.iter().find(|(o, _)| *o == words[i]) else {
                break;
            };
            let mut taken = 0;
            while taken < most
                && i + 1 + taken < end
                && (taken == 0 || words[i + 1 + taken].parse::<f64>().is_ok())
            {
                taken += 1;
            }
            let arguments = &words[i + 1..i + 1 + taken];
            if option == "-clamp" {
                if arguments.first() == Some(&"on") {
                    wrap = WrapMode::ClampToEdge;
                }
            } else {
                ignored.push(
                    format!("{option} {}", arguments.join(" "))
                        .trim()
                        .to_string(),
                );
            }
            i += 1 + taken;
        }
        i
    };
    // Options before the file name (its last word kept for it), the file name (spaces
    // and all) up to the next option word, and options after it, which
    // tinyobjloader reads too (its issue 85: `bump.jpg -bm 1.5`).
    let first = options(0, words.len() - 1);
    let is_option = |word: &str| OPTIONS.iter().any(|(o, _)| *o == word);
    let last = (first + 1..words.len())
        .find(|&j| is_option(words[j]))
        .unwrap_or(words.len());
    let stop = options(last, words.len());
    if stop < words.len() {
        ignored.push(words[stop..].join(" "));
    }
    // The file name as written between its first and last word (runs of spaces kept).
    let offset = |word: &str| word.as_ptr() as usize - spec.as_ptr() as usize;
    let file = match words.get(first..last) {
        Some([start, .., end]) => &spec[offset(start)..offset(end) + end.len()],
        Some([only]) => only,
        _ => "",
    };
    (file.to_string(), wrap, ignored)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_options_are_split_from_the_file_name() {
        assert_eq!(
            texture_options("wood grain.png"),
            ("wood grain.png".into(), WrapMode::Repeat, vec![])
        );
        assert_eq!(
            texture_options("-clamp on -s 2 2 1 a.png"),
            (
                "a.png".into(),
                WrapMode::ClampToEdge,
                vec!["-s 2 2 1".to_string()]
            )
        );
        assert_eq!(
            texture_options("-imfchan r bumpmap2.jpg -bm 1.5"),
            (
                "bumpmap2.jpg".into(),
                WrapMode::Repeat,
                vec!["-imfchan r".to_string(), "-bm 1.5".to_string()]
            )
        );
        assert_eq!(
            texture_options("-o 1 two  spaces.png"),
            (
                "two  spaces.png".into(),
                WrapMode::Repeat,
                vec!["-o 1".to_string()]
            )
        );
        assert_eq!(
            texture_options("-clamp on"),
            ("on".into(), WrapMode::Repeat, vec![])
        );
        assert_eq!(
            texture_options("this dissolve texture has spaces.jpg -clamp on"),
            (
                "this dissolve texture has spaces.jpg".into(),
                WrapMode::ClampToEdge,
                vec![]
            )
        );
        assert_eq!(
            texture_options("-bm 0.5 b.png"),
            (
                "b.png".into(),
                WrapMode::Repeat,
                vec!["-bm 0.5".to_string()]
            )
        );
    }
}
