//! Wavefront OBJ and MTL (Wavefront's "Object Files" and "Material Library Files"
//! specifications, Alias|Wavefront Advanced Visualizer manual, appendices B1 and B2),
//! read through the `tobj` crate.
//!
//! Every line is first checked here, so that each error names its file, line and column
//! and so that `tobj` only ever sees well-formed lines (it has no line numbers of its own
//! and panics on some malformed ones). `tobj` then groups the faces into objects, fans
//! them into triangles and unifies the position/texture/normal indices.

mod mtl;

use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap};
use std::io::Cursor;
use std::path::Path;

use glam::{DVec2, DVec3};

use self::mtl::{Libraries, map_material};
use super::mesh::{Budget, RawMesh, finish_mesh};
use super::texture::Textures;
use super::{
    ImportedMaterial, ImportedModel, MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES, error, read_file,
};
use crate::scene::{Material, SceneError};

/// Diffuse albedo of a material whose MTL gives no `Kd` (and of geometry with no
/// material at all); 1 when a `map_Kd` texture supplies the colour.
pub const DEFAULT_OBJ_ALBEDO: f64 = 0.8;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_know_their_columns() {
        assert_eq!(words("  v 1\t2"), vec![(3, "v"), (5, "1"), (7, "2")]);
    }
}
