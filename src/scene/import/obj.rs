//! Wavefront OBJ and MTL (Wavefront's "Object Files" and "Material Library Files"
//! specifications, Alias|Wavefront Advanced Visualizer manual, appendices B1 and B2),
//! read through the `tobj` crate.
//!
//! Every line is first checked here, so that each error names its file, line and column
//! and so that `tobj` only ever sees well-formed lines (it has no line numbers of its own
//! and panics on some malformed ones). `tobj` then groups the faces into objects, fans
//! them into triangles and unifies the position/texture/normal indices.

use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap};
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use super::mesh::{Budget, RawMesh, finish_mesh};
use super::texture::{Encoding, Textures};
use super::{
    ImportedMaterial, ImportedModel, MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES, TextureRef, WrapMode,
    error, read_file,
};
use crate::scene::{Material, MaterialKind, SceneError};

/// Diffuse albedo of a material whose MTL gives no `Kd` (and of geometry with no
/// material at all); 1 when a `map_Kd` texture supplies the colour.
pub const DEFAULT_OBJ_ALBEDO: f64 = 0.8;
/// Index of refraction assumed for glass (`illum` 4, 6, 7, 9) and coats (`illum` 3, 5, 8)
/// whose material gives no usable `Ni`.
const DEFAULT_IOR: f64 = 1.5;
/// Blinn-Phong exponent assumed when `Ns` is absent (as tinyobjloader does).
const DEFAULT_NS: f64 = 1.0;
/// Largest accepted Blinn-Phong exponent (the scene format's limit).
const MAX_SHININESS: f64 = 1e6;

/// Reads the OBJ file at `path` with the MTL libraries it names (relative to its
/// directory) and their `map_Kd` textures (relative to each library's directory).
///
/// Fails, naming the file, line and column, on a missing or unreadable file, a
/// malformed line, a non-finite position, a face index out of range, a missing material
/// library or a texture that does not load. Degenerate triangles are skipped and counted
/// in a warning.
pub fn import_obj(path: &Path) -> Result<ImportedModel, SceneError> {
    let bytes = read_file(path, path, "the model file")?;
    parse_obj(&bytes, path)
}

/// Reads OBJ text from `bytes`; `path` names the file in messages and its directory is
/// where the material libraries are looked up.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<ImportedModel, SceneError> {
    let mut model = ImportedModel::empty(path);
    let text = String::from_utf8_lossy(bytes);
    if std::str::from_utf8(bytes).is_err() {
        model.warnings.push(format!(
            "{}: not valid UTF-8; the invalid bytes were replaced",
            path.display()
        ));
    }
    // A byte-order mark would hide the first line's keyword.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let scan = scan_obj(text, path, &mut model.warnings)?;
    let directory = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let libraries = RefCell::new(Libraries::default());
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) =
        tobj::load_obj_buf(&mut Cursor::new(scan.text.as_bytes()), &options, |name| {
            libraries.borrow_mut().load(&directory, name, path, &scan)
        })
        .map_err(|e| error(path, format!("the OBJ file could not be read: {e}")))?;
    let libraries = libraries.into_inner();
    if let Some(failure) = libraries.failure {
        return Err(failure);
    }
    for (name, line) in &scan.used_materials {
        if !libraries.index.contains_key(name) {
            model.warnings.push(format!(
                "{}:{line}: usemtl {name}: no material library defines it; the default material is used",
                path.display()
            ));
        }
    }

    let mut budget = Budget::default();
    let mut textures = Textures::default();
    for source in &libraries.materials {
        let imported = map_material(source, &mut textures, &mut budget, &mut model.warnings)?;
        model.materials.push(imported);
    }
    let mut default_material = None;
    for obj in models {
        let mesh = obj.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = match mesh.material_id {
            Some(id) if id < model.materials.len() => id as u32,
            _ => *default_material.get_or_insert_with(|| {
                model.materials.push(ImportedMaterial {
                    name: "default".into(),
                    material: Material::lambert(DVec3::splat(DEFAULT_OBJ_ALBEDO)),
                    base_color_texture: None,
                    metallic_roughness_texture: None,
                    emissive_texture: None,
                });
                model.materials.len() as u32 - 1
            }),
        };
        let name = format!(
            "object '{}' (material '{}')",
            obj.name, model.materials[material as usize].name
        );
        let vertices = mesh.positions.len() / 3;
        budget
            .charge_mesh(vertices, mesh.indices.len() / 3)
            .map_err(|e| error(path, e))?;
        let raw = RawMesh {
            positions: mesh
                .positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2]))
                .collect(),
            normals: (!mesh.normals.is_empty()).then(|| {
                mesh.normals
                    .chunks_exact(3)
                    .map(|n| DVec3::new(n[0], n[1], n[2]))
                    .collect()
            }),
            // OBJ's v grows upwards (row 0 of the image at v = 1); ours downwards.
            uvs: (!mesh.texcoords.is_empty()).then(|| {
                mesh.texcoords
                    .chunks_exact(2)
                    .map(|t| DVec2::new(t[0], 1.0 - t[1]))
                    .collect()
            }),
            triangles: mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        };
        if let Some(mesh) = finish_mesh(name, path, raw, material, &mut model.warnings)
            .map_err(|e| error(path, e))?
        {
            model.meshes.push(mesh);
        }
    }
    model.images = textures.images;
    Ok(model)
}

/// What the line check found: the text handed to `tobj` (every line kept or blanked, so
/// the numbering stays), and where the material libraries and materials are named.
struct ObjScan {
    text: String,
    /// `mtllib` argument → line naming it.
    libraries: HashMap<String, usize>,
    /// `usemtl` name → first line using it.
    used_materials: Vec<(String, usize)>,
}

/// The words of a line with their 1-based columns (in characters).
fn words(line: &str) -> Vec<(usize, &str)> {
    let mut words = Vec::new();
    let mut start = None;
    let mut column = 0;
    let mut start_column = 0;
    for (offset, c) in line.char_indices() {
        column += 1;
        match (c.is_whitespace(), start) {
            (false, None) => {
                start = Some(offset);
                start_column = column;
            }
            (true, Some(s)) => {
                words.push((start_column, &line[s..offset]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        words.push((start_column, &line[s..]));
    }
    words
}

/// An error at `line`:`column` of `path`.
fn at(path: &Path, line: usize, column: usize, message: impl Into<String>) -> SceneError {
    SceneError {
        path: path.to_path_buf(),
        location: Some((line, column)),
        message: message.into(),
    }
}

/// Parses `word` as a number, failing with a message that names `what`.
fn number(
    path: &Path,
    line: usize,
    (column, word): (usize, &str),
    what: &str,
) -> Result<f64, SceneError> {
    word.parse::<f64>().map_err(|_| {
        at(
            path,
            line,
            column,
            format!("{what}: `{word}` is not a number"),
        )
    })
}

/// Parses `word` as a finite number.
fn finite(path: &Path, line: usize, word: (usize, &str), what: &str) -> Result<f64, SceneError> {
    let value = number(path, line, word, what)?;
    if !value.is_finite() {
        return Err(at(
            path,
            line,
            word.0,
            format!("{what} is not a finite number ({})", word.1),
        ));
    }
    Ok(value)
}

/// Checks every line of an OBJ file; see [`ObjScan`].
fn scan_obj(text: &str, path: &Path, warnings: &mut Vec<String>) -> Result<ObjScan, SceneError> {
    let mut scan = ObjScan {
        text: String::with_capacity(text.len()),
        libraries: HashMap::new(),
        used_materials: Vec::new(),
    };
    let mut seen_materials = BTreeSet::new();
    let (mut positions, mut texcoords, mut normals) = (0usize, 0usize, 0usize);
    let mut triangles = 0usize;
    let mut ignored: Vec<(&str, usize)> = Vec::new();
    let mut short_faces = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let number_of_line = index + 1;
        let n = number_of_line;
        let words = words(line);
        let keep = match words.first().map(|w| w.1) {
            None => false,
            Some(keyword) if keyword.starts_with('#') => false,
            Some("v") => {
                let values = &words[1..];
                if !matches!(values.len(), 3 | 4 | 6) {
                    return Err(at(
                        path,
                        n,
                        words[0].0,
                        format!(
                            "`v` takes x y z (and optionally w, or r g b), got {} numbers",
                            values.len()
                        ),
                    ));
                }
                for (axis, word) in ["x", "y", "z"].iter().zip(values) {
                    finite(path, n, *word, &format!("position {axis}"))?;
                }
                if values.len() == 4 {
                    let w = finite(path, n, values[3], "position w")?;
                    if w == 0.0 {
                        return Err(at(path, n, values[3].0, "position w is 0"));
                    }
                }
                for word in values.iter().skip(3) {
                    number(path, n, *word, "vertex colour")?;
                }
                positions += 1;
                true
            }
            Some("vt") => {
                let values = &words[1..];
                if !(1..=3).contains(&values.len()) {
                    return Err(at(
                        path,
                        n,
                        words[0].0,
                        format!("`vt` takes u (v (w)), got {} numbers", values.len()),
                    ));
                }
                let u = number(path, n, values[0], "texture coordinate u")?;
                let v = match values.get(1) {
                    Some(word) => number(path, n, *word, "texture coordinate v")?,
                    None => 0.0,
                };
                if let Some(word) = values.get(2) {
                    number(path, n, *word, "texture coordinate w")?;
                }
                texcoords += 1;
                // tobj needs both u and v; a missing v is 0 (the specification's default).
                scan.text.push_str(&format!("vt {u:?} {v:?}\n"));
                continue;
            }
            Some("vn") => {
                let values = &words[1..];
                if values.len() != 3 {
                    return Err(at(
                        path,
                        n,
                        words[0].0,
                        format!("`vn` takes i j k, got {} numbers", values.len()),
                    ));
                }
                for word in values {
                    number(path, n, *word, "normal")?;
                }
                normals += 1;
                true
            }
            Some("f") => {
                let corners = &words[1..];
                for (k, corner) in corners.iter().enumerate() {
                    check_corner(path, n, k + 1, *corner, [positions, texcoords, normals])?;
                }
                if corners.len() < 3 {
                    short_faces.push(n);
                    false
                } else {
                    triangles = triangles.saturating_add(corners.len() - 2);
                    true
                }
            }
            Some("o" | "g") => true,
            Some("usemtl") => {
                let name = line.trim_start()[6..].trim();
                if name.is_empty() {
                    return Err(at(path, n, words[0].0, "`usemtl` needs a material name"));
                }
                if seen_materials.insert(name.to_string()) {
                    scan.used_materials.push((name.to_string(), n));
                }
                // tobj takes the name after the first space.
                scan.text.push_str(&format!("usemtl {name}\n"));
                continue;
            }
            Some("mtllib") => {
                // As tobj reads it: the rest of the line is one file name (names with
                // spaces are common, several names on one line are not).
                let rest = line.trim_start()[6..].trim();
                if rest.is_empty() {
                    return Err(at(path, n, words[0].0, "`mtllib` needs a file name"));
                }
                scan.libraries.entry(rest.to_string()).or_insert(n);
                scan.text.push_str(&format!("mtllib {rest}\n"));
                continue;
            }
            Some("s" | "l" | "p") => {
                if words[0].1 != "s" {
                    ignored.push((words[0].1, n));
                }
                false
            }
            Some(keyword) => {
                ignored.push((keyword, n));
                false
            }
        };
        if keep {
            scan.text.push_str(line.trim());
        }
        scan.text.push('\n');
    }
    if positions > MAX_MODEL_VERTICES {
        return Err(error(
            path,
            format!("{positions} vertex positions, more than the {MAX_MODEL_VERTICES} accepted"),
        ));
    }
    if triangles > MAX_MODEL_TRIANGLES {
        return Err(error(
            path,
            format!("{triangles} triangles, more than the {MAX_MODEL_TRIANGLES} accepted"),
        ));
    }
    if let Some(first) = short_faces.first() {
        warnings.push(format!(
            "{}:{first}: {} face{} of fewer than 3 vertices skipped",
            path.display(),
            short_faces.len(),
            if short_faces.len() == 1 { "" } else { "s" }
        ));
    }
    let mut reported = BTreeSet::new();
    for (keyword, line) in ignored {
        if reported.insert(keyword) {
            let what = match keyword {
                "l" => "lines are not rendered",
                "p" => "points are not rendered",
                "cstype" | "curv" | "curv2" | "surf" | "deg" | "bmat" | "step" | "parm"
                | "trim" | "hole" | "scrv" | "sp" | "end" => {
                    "free-form curves and surfaces are not supported"
                }
                _ => "not supported",
            };
            warnings.push(format!(
                "{}:{line}: `{keyword}`: {what}; ignored (here and on any later line)",
                path.display()
            ));
        }
    }
    Ok(scan)
}

/// Checks face corner number `k` (`v`, `v/vt`, `v//vn` or `v/vt/vn`) against the
/// counts of positions, texture coordinates and normals defined so far.
fn check_corner(
    path: &Path,
    line: usize,
    k: usize,
    (column, word): (usize, &str),
    defined: [usize; 3],
) -> Result<(), SceneError> {
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 {
        return Err(at(
            path,
            line,
            column,
            format!("face corner {k} `{word}` has more than three indices (v/vt/vn)"),
        ));
    }
    let kinds = ["position", "texture coordinate", "normal"];
    for (slot, part) in parts.iter().enumerate() {
        if part.is_empty() {
            if slot == 0 {
                return Err(at(
                    path,
                    line,
                    column,
                    format!("face corner {k} `{word}` has no position index"),
                ));
            }
            continue;
        }
        let kind = kinds[slot];
        let fail = |message: String| at(path, line, column, format!("face corner {k}: {message}"));
        let index: i64 = part
            .parse()
            .map_err(|_| fail(format!("the {kind} index `{part}` is not an integer")))?;
        let count = defined[slot];
        let in_range = match index {
            0 => return Err(fail(format!("the {kind} index is 0 (OBJ counts from 1)"))),
            i if i > 0 => (i as u64) <= count as u64,
            i => i.unsigned_abs() <= count as u64,
        };
        if !in_range {
            return Err(fail(format!(
                "the {kind} index {index} is out of range: {count} {kind}{} defined before this line",
                if count == 1 { " is" } else { "s are" }
            )));
        }
    }
    Ok(())
}

/// A material of an MTL library with what `tobj` does not keep: where it was defined.
struct SourceMaterial {
    material: tobj::Material,
    /// The library file.
    library: PathBuf,
    /// The line of its `newmtl`.
    line: usize,
    /// `map_Kd` line and column, when it has one.
    map_kd_at: Option<(usize, usize)>,
    /// `map_Ke` line and column, when it has one.
    map_ke_at: Option<(usize, usize)>,
}

/// The material libraries loaded while `tobj` reads the OBJ file.
#[derive(Default)]
struct Libraries {
    /// Every material, in library order (the index `tobj` gives meshes).
    materials: Vec<SourceMaterial>,
    /// Material name → index, as `tobj` resolves `usemtl`.
    index: HashMap<String, usize>,
    /// The first error, reported once `tobj` returns.
    failure: Option<SceneError>,
}

impl Libraries {
    /// Loads the library `name` (as written after `mtllib`) for `tobj`; on failure keeps
    /// the error to report and gives `tobj` an empty library.
    fn load(
        &mut self,
        directory: &Path,
        name: &Path,
        obj: &Path,
        scan: &ObjScan,
    ) -> tobj::MTLLoadResult {
        if self.failure.is_some() {
            return Err(tobj::LoadError::GenericFailure);
        }
        let line = scan
            .libraries
            .get(name.to_string_lossy().as_ref())
            .copied()
            .unwrap_or(1);
        let library = directory.join(name);
        let result = read_file(
            &library,
            obj,
            &format!("the material library {}", library.display()),
        )
        .map_err(|e| {
            at(
                obj,
                line,
                1,
                format!("mtllib {}: {}", name.display(), e.message),
            )
        })
        .and_then(|bytes| self.parse(&library, &bytes));
        match result {
            Ok(loaded) => Ok(loaded),
            Err(e) => {
                self.failure = Some(e);
                Err(tobj::LoadError::GenericFailure)
            }
        }
    }

    /// Checks and parses one library's text. Its materials are kept here too, with the
    /// indices `tobj` gives them (libraries in `mtllib` order, materials in file order).
    fn parse(
        &mut self,
        library: &Path,
        bytes: &[u8],
    ) -> Result<(Vec<tobj::Material>, HashMap<String, usize>), SceneError> {
        let text = String::from_utf8_lossy(bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let (clean, lines) = scan_mtl(text, library)?;
        let (materials, names) =
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
            },
        ) in materials.iter().cloned().zip(lines)
        {
            self.index
                .insert(material.name.clone(), self.materials.len());
            self.materials.push(SourceMaterial {
                material,
                library: library.to_path_buf(),
                line,
                map_kd_at,
                map_ke_at,
            });
        }
        Ok((materials, names))
    }
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
/// and column of its `map_Kd` and `map_Ke`, when it has them.
struct MtlLines {
    line: usize,
    map_kd_at: Option<(usize, usize)>,
    map_ke_at: Option<(usize, usize)>,
}

/// Checks every line of an MTL library and returns the text for `tobj` (colours with one
/// number spelled out as three, unsupported forms blanked) and, per material in order,
/// where it is defined.
fn scan_mtl(text: &str, path: &Path) -> Result<(String, Vec<MtlLines>), SceneError> {
    let mut clean = String::with_capacity(text.len());
    let mut lines = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let n = index + 1;
        let words = words(line);
        let Some(&(column, keyword)) = words.first() else {
            clean.push('\n');
            continue;
        };
        let values = &words[1..];
        let mut kept = line.trim().to_string();
        if keyword.starts_with('#') {
            kept.clear();
        } else if keyword == "newmtl" {
            if values.is_empty() {
                return Err(at(path, n, column, "`newmtl` needs a material name"));
            }
            lines.push(MtlLines {
                line: n,
                map_kd_at: None,
                map_ke_at: None,
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
                    rgb[c] = finite(path, n, *word, keyword)?;
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
            let value = finite(path, n, *values[0], keyword)?;
            kept = format!("{keyword} {value:?}");
        } else if keyword == "illum" {
            let [word] = values else {
                return Err(at(path, n, column, "`illum` takes one number (0 to 10)"));
            };
            let illum: i64 = word.1.parse().map_err(|_| {
                at(
                    path,
                    n,
                    word.0,
                    format!("illum: `{}` is not an integer", word.1),
                )
            })?;
            if !(0..=10).contains(&illum) {
                return Err(at(
                    path,
                    n,
                    word.0,
                    format!("illum {illum} is not an illumination model (0 to 10)"),
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
                    format!("`{keyword}` needs a file name"),
                ));
            }
            if keyword == "map_Kd" || keyword == "map_Ke" {
                match lines.last_mut() {
                    Some(last) if keyword == "map_Kd" => last.map_kd_at = Some((n, column)),
                    Some(last) => last.map_ke_at = Some((n, column)),
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
fn map_material(
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
        m.name
    );
    let mut warn = |message: String| warnings.push(format!("{place}: {message}"));
    let colour = |c: Option<[f64; 3]>| c.map(|[r, g, b]| DVec3::new(r, g, b));

    // A colour texture statement (`map_Kd`, `map_Ke`) at `at`, loaded relative to the
    // library's directory.
    let mut colour_texture = |key: &str,
                              spec: Option<&String>,
                              at_line: Option<(usize, usize)>|
     -> Result<Option<TextureRef>, SceneError> {
        let (Some(spec), Some((line, column))) = (spec, at_line) else {
            return Ok(None);
        };
        let (file, wrap, ignored) = texture_options(spec);
        if !ignored.is_empty() {
            warn(format!(
                "{key} options {} are not supported; ignored",
                ignored.join(" ")
            ));
        }
        let directory = source.library.parent().unwrap_or(Path::new(""));
        let mut file_path = directory.join(&file);
        if !file_path.exists() && file.contains('\\') {
            file_path = directory.join(file.replace('\\', "/"));
        }
        let image = textures
            .file(&file_path, Encoding::Color, budget)
            .map_err(|e| {
                at(
                    &source.library,
                    line,
                    column,
                    format!("material '{}': {key}: {e}", m.name),
                )
            })?;
        Ok(Some(TextureRef {
            image,
            wrap_u: wrap,
            wrap_v: wrap,
        }))
    };
    let base_color_texture =
        colour_texture("map_Kd", m.diffuse_texture.as_ref(), source.map_kd_at)?;
    let emissive_texture =
        colour_texture("map_Ke", m.unknown_param.get("map_Ke"), source.map_ke_at)?;
    for (key, present) in [
        ("map_Ks", m.specular_texture.is_some()),
        ("map_Ka", m.ambient_texture.is_some()),
        ("map_Ns", m.shininess_texture.is_some()),
        ("map_d", m.dissolve_texture.is_some()),
        ("bump", m.normal_texture.is_some()),
    ] {
        if present {
            warn(format!("{key} is not supported; ignored"));
        }
    }
    let mut others: Vec<&String> = m
        .unknown_param
        .keys()
        .filter(|k| {
            (k.starts_with("map_") && k.as_str() != "map_Ke")
                || matches!(k.as_str(), "disp" | "decal" | "refl" | "norm")
        })
        .collect();
    others.sort();
    for key in others {
        warn(format!("{key} is not supported; ignored"));
    }

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
            warn(format!("{name} {c} is outside [0, 1]; clamped"));
        }
        clamped
    };
    let emission = ke.max(DVec3::ZERO);
    if emission != ke {
        warn(format!("Ke {ke} is negative; clamped to 0"));
    }
    let ior_or_default = |warn: &mut dyn FnMut(String), what: &str| match ni {
        Some(ni) if ni > 0.0 => ni,
        Some(ni) => {
            warn(format!(
                "Ni {ni} is not positive; {what} uses {DEFAULT_IOR}"
            ));
            DEFAULT_IOR
        }
        None => DEFAULT_IOR,
    };

    let material = if matches!(illum, 4 | 6 | 7 | 9) {
        let ior = ior_or_default(&mut warn, "the glass");
        let transmittance = unit("Tf", tf.unwrap_or(DVec3::ONE), &mut warn);
        Material {
            ior,
            transmittance,
            emission,
            ..Material::blank(MaterialKind::Dielectric)
        }
    } else if pr.is_some() || pm.is_some() {
        if matches!(illum, 3 | 5 | 8) {
            warn(format!(
                "illum {illum} (coat) is ignored: Pr/Pm make it a metal/roughness material"
            ));
        }
        let clamp01 = |name: &str, v: f64, warn: &mut dyn FnMut(String)| {
            if !(0.0..=1.0).contains(&v) {
                warn(format!("{name} {v} is outside [0, 1]; clamped"));
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
                "Kd + Ks reaches {sum} in a channel; both are scaled by 1/{sum} so that the surface does not reflect more light than it receives"
            ));
            kd /= sum;
            ks /= sum;
        }
        let coat_ior = if matches!(illum, 3 | 5 | 8) {
            let ior = ior_or_default(&mut warn, "the coat");
            if ior < 1.0 {
                warn(format!("Ni {ior} is below 1; the coat uses {DEFAULT_IOR}"));
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
                warn(format!("Ns {ns} is outside [0, {MAX_SHININESS}]; clamped"));
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
    if dissolve < 1.0 && material.kind != MaterialKind::Dielectric {
        warn(format!(
            "d {dissolve} (partial transparency) is not supported; the material is opaque"
        ));
    }
    Ok(ImportedMaterial {
        name: m.name.clone(),
        material,
        base_color_texture,
        metallic_roughness_texture: None,
        emissive_texture,
    })
}

/// Splits a texture statement (`-clamp on -s 2 2 file name.png`) into the file name, the
/// wrap mode (`-clamp on` clamps) and the options that are not supported.
fn texture_options(spec: &str) -> (String, WrapMode, Vec<String>) {
    /// Options and how many arguments each takes at most (all but the last are numbers).
    const OPTIONS: &[(&str, usize)] = &[
        ("-blendu", 1),
        ("-blendv", 1),
        ("-bm", 1),
        ("-boost", 1),
        ("-cc", 1),
        ("-clamp", 1),
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
    let mut i = 0;
    while i < words.len() {
        let Some(&(option, most)) = OPTIONS.iter().find(|(o, _)| *o == words[i]) else {
            break;
        };
        let mut taken = 0;
        while taken < most
            && i + 1 + taken < words.len() - 1
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
    (words[i.min(words.len())..].join(" "), wrap, ignored)
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
            texture_options("-bm 0.5 b.png"),
            (
                "b.png".into(),
                WrapMode::Repeat,
                vec!["-bm 0.5".to_string()]
            )
        );
    }

    #[test]
    fn words_know_their_columns() {
        assert_eq!(words("  v 1\t2"), vec![(3, "v"), (5, "1"), (7, "2")]);
    }
}
