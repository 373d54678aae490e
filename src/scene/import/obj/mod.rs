//! Wavefront OBJ (Wavefront's "Object Files" specification, Alias|Wavefront Advanced
//! Visualizer manual, appendix B1) with its MTL material libraries ([`mtl`]), read as
//! tinyobjloader and assimp read them.
//!
//! Every line is read here, so that each error names its file, line and column: vertex
//! data, faces (cut into triangles by [`face`]: fans for convex faces, ear clipping
//! for the others), objects, groups and material changes. The faces are collected into
//! one mesh per object (or group) name and material, each with its own vertices: one
//! per distinct position/texture/normal index triple it uses. Everything is a single
//! pass over the lines with hash lookups, so the time is linear in the file however
//! many groups, objects or material changes it has. The libraries are read once the
//! whole file is, so that a material is found by its name wherever its `mtllib` stands.
//!
//! The readers other programs use decide what is lenient: an inline `#` comment, a
//! missing library or texture, an empty `usemtl`, normal indices in a file without
//! `vn`, and a number followed by junk (`3.1+e2`) are warnings, never errors.

mod face;
mod mtl;
mod normal_map;
mod scalar_maps;

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::{DVec2, DVec3};

use self::face::{Cut, FaceCutter};
use self::mtl::{Libraries, map_material};
use super::mesh::{Budget, RawMesh, finish_mesh, memory_cap_message};
use super::texture::Textures;
use super::{
    ImportOptions, ImportedMaterial, ImportedModel, MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES, error,
    read_file,
};
use crate::echo::{echo, short};
use crate::scene::{Material, SceneError};

/// Diffuse albedo of a material whose MTL gives no `Kd` (and of geometry with no
/// material at all); 1 when a `map_Kd` texture supplies the colour.
pub const DEFAULT_OBJ_ALBEDO: f64 = 0.8;

/// A corner's missing texture coordinate or normal index.
const NONE: u32 = u32::MAX;

/// The name of faces before any `o` or `g` (and of an `o` or `g` without a name), as
/// tobj names them.
const UNNAMED: &str = "unnamed_object";
/// Lines between two checks of the memory an OBJ file's arrays hold (and two progress
/// reports).
const CHECK_EVERY_LINES: usize = 1 << 16;

/// How many kinds of unsupported statement are named one by one in the warnings; the
/// rest are counted together.
const MAX_NAMED_STATEMENTS: usize = 16;

/// Reads the OBJ file at `path` with the MTL libraries it names (relative to its
/// directory) and their `map_Kd` and `map_Ke` textures (relative to each library's
/// directory).
///
/// Fails, naming the file, line and column, on a missing or unreadable OBJ file, a
/// malformed line, a non-finite position, a face index out of range, a malformed MTL
/// line or a texture file that exists but does not decode, and, naming the file, on a
/// file that has no triangles to render. A material library or texture that is missing
/// is a warning (the default material, or the material without the texture, is used);
/// degenerate triangles are skipped and counted in a warning.
pub fn import_obj(path: &Path) -> Result<ImportedModel, SceneError> {
    import_obj_with(path, &ImportOptions::default())
}

/// [`import_obj`] with `options`: the file is counted against
/// [`ImportOptions::max_bytes`] by its size before it is read, the arrays it makes as
/// they grow, and the textures by their headers before they are decoded; the reading
/// reports its progress.
pub fn import_obj_with(
    path: &Path,
    options: &ImportOptions<'_>,
) -> Result<ImportedModel, SceneError> {
    let mut budget = Budget::new(options.max_bytes);
    let bytes = read_file(path, path, "the model file", &mut budget)?;
    parse_obj_within(&bytes, path, budget, options.progress)
}

/// Reads OBJ text from `bytes` (UTF-8, or UTF-16 with a byte-order mark); `path` names
/// the file in messages and its directory is where the material libraries are looked
/// up.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<ImportedModel, SceneError> {
    parse_obj_within(bytes, path, Budget::default(), None)
}

/// [`parse_obj`] counting what it builds against `budget`, reporting progress.
fn parse_obj_within(
    bytes: &[u8],
    path: &Path,
    mut budget: Budget,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> Result<ImportedModel, SceneError> {
    let mut model = ImportedModel::empty(path);
    let text = decode_text(bytes, path, &mut model.warnings);
    if let Cow::Owned(decoded) = &text {
        budget
            .charge_bytes(decoded.len() as u64, "its text decoded")
            .map_err(|e| e.at(path))?;
    }
    let mut notes = Notes::default();
    let reader = ObjReader::new(path, budget.bytes_left(), progress);
    let mut file = reader.read(&text, &mut notes)?;
    notes.report(path, &mut model.warnings);
    let directory = path.parent().unwrap_or(Path::new(""));
    let libraries = Libraries::load(&file.libraries, directory, path, &mut model.warnings)?;
    check_material_uses(&file.used_materials, &libraries, path, &mut model.warnings);

    let mut textures = Textures::default();
    for source in &libraries.materials {
        let imported = map_material(source, &mut textures, &mut budget, &mut model.warnings)?;
        model.materials.push(imported);
    }
    let mut default_material = None;
    for group in std::mem::take(&mut file.groups) {
        let found = group
            .material
            .as_ref()
            .and_then(|name| libraries.index.get(name));
        let material = match found {
            Some(&index) => index as u32,
            None => *default_material.get_or_insert_with(|| {
                model.materials.push(ImportedMaterial {
                    name: "default".into(),
                    material: Material::lambert(DVec3::splat(DEFAULT_OBJ_ALBEDO)),
                    base_color_texture: None,
                    metallic_roughness_texture: None,
                    emissive_texture: None,
                    normal_texture: None,
                });
                model.materials.len() as u32 - 1
            }),
        };
        let name = format!(
            "object '{}' (material '{}')",
            echo(&group.object),
            echo(&model.materials[material as usize].name)
        );
        budget
            .charge_mesh(group.vertices.len(), group.triangles.len())
            .map_err(|e| e.at(path))?;
        let mut raw = group.into_raw_mesh(&file);
        if model.materials[material as usize].normal_texture.is_some() {
            // A normal map needs tangents: MikkTSpace's, from the normals and texture
            // coordinates (glTF 2.0 §3.7.2.1 asks for them; OBJ has no tangents).
            match raw
                .uvs
                .as_deref()
                .and_then(|uvs| super::tangents::with_mikktspace_tangents(&raw, uvs))
            {
                Some(with_tangents) => raw = with_tangents,
                None => model.warnings.push(format!(
                    "{}: {name}: its material's normal map needs tangents, made from every vertex's normal (vn) and texture coordinates (vt), which it lacks; the normal map is not applied",
                    path.display()
                )),
            }
        }
        if let Some(mesh) = finish_mesh(name, path, raw, material, &mut model.warnings)
            .map_err(|e| error(path, e))?
        {
            model.meshes.push(mesh);
        }
    }
    if model.meshes.is_empty() {
        return Err(error(path, file.why_no_triangles()));
    }
    model.images = textures.images;
    Ok(model)
}

/// The text of an OBJ or MTL file: UTF-16 when it starts with a UTF-16 byte-order
/// mark (as assimp reads it), otherwise UTF-8 without its byte-order mark (which would
/// hide the first line's keyword), invalid bytes replaced with a warning.
fn decode_text<'a>(bytes: &'a [u8], path: &Path, warnings: &mut Vec<String>) -> Cow<'a, str> {
    let utf16 = |rest: &[u8], unit: fn([u8; 2]) -> u16| {
        let units = rest.chunks_exact(2).map(|pair| unit([pair[0], pair[1]]));
        let text: String = char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect();
        Cow::Owned(text)
    };
    match bytes {
        [0xFE, 0xFF, rest @ ..] => return utf16(rest, u16::from_be_bytes),
        [0xFF, 0xFE, rest @ ..] => return utf16(rest, u16::from_le_bytes),
        _ => {}
    }
    let text = String::from_utf8_lossy(bytes);
    if matches!(text, Cow::Owned(_)) {
        warnings.push(format!(
            "{}: not valid UTF-8; the invalid bytes were replaced",
            path.display()
        ));
    }
    match text {
        Cow::Borrowed(text) => Cow::Borrowed(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Cow::Owned(text) => match text.strip_prefix('\u{feff}') {
            Some(rest) => Cow::Owned(rest.to_string()),
            None => Cow::Owned(text),
        },
    }
}

/// Warns about `usemtl` names that no library defines (unless a library could not be
/// read: its materials are the likely ones, and its warning says so) and about a
/// `usemtl` before the `mtllib` that defines its material (found anyway, by name, as
/// assimp finds it; tinyobjloader and tobj would use their default material).
fn check_material_uses(
    used: &[(String, usize)],
    libraries: &Libraries,
    path: &Path,
    warnings: &mut Vec<String>,
) {
    let undefined: Vec<&(String, usize)> = used
        .iter()
        .filter(|(name, _)| !libraries.index.contains_key(name))
        .collect();
    if let Some((name, line)) = undefined.first().filter(|_| !libraries.any_missing) {
        let others = match undefined.len() - 1 {
            0 => String::new(),
            more => format!(
                " (nor {more} other name{} used later: {})",
                plural(more),
                list(undefined[1..].iter().map(|(name, _)| name.as_str()))
            ),
        };
        warnings.push(format!(
            "{}:{line}: usemtl {}: no material library defines it{others}; the default material is used",
            path.display(),
            echo(name)
        ));
    }
    let early: Vec<(&str, usize, usize)> = used
        .iter()
        .filter_map(|(name, line)| {
            let material = &libraries.materials[*libraries.index.get(name)?];
            (material.mtllib_line > *line).then_some((name.as_str(), *line, material.mtllib_line))
        })
        .collect();
    if let Some(&(name, line, mtllib_line)) = early.first() {
        let others = match early.len() - 1 {
            0 => String::new(),
            more => format!(" (and {more} more material{})", plural(more)),
        };
        warnings.push(format!(
            "{}:{line}: usemtl {} comes before the mtllib on line {mtllib_line} that defines it{others}; it is used, but other readers may show their default material",
            path.display(),
            echo(name)
        ));
    }
}

/// `""` for one, `"s"` for any other count.
fn plural(count: usize) -> &'static str {
    if count == 1 { "" } else { "s" }
}

/// The first few of `names` ([`echo`]ed), comma-separated, with `…` when there are
/// more.
fn list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    const SHOWN: usize = 5;
    let names: Vec<&str> = names.collect();
    let shown: Vec<String> = names[..names.len().min(SHOWN)]
        .iter()
        .map(|name| echo(name).to_string())
        .collect();
    let mut text = shown.join(", ");
    if names.len() > SHOWN {
        text.push_str(", …");
    }
    text
}

/// What an OBJ file holds, read but not yet made into meshes.
struct ObjFile {
    positions: Vec<DVec3>,
    /// Vertex colours (`v x y z r g b`), parallel to `positions` from the first
    /// coloured vertex on (white for those before it and those without); empty when no
    /// vertex has one.
    colors: Vec<DVec3>,
    /// Texture coordinates, `v` already flipped to grow downwards (ours and glTF's
    /// convention: OBJ's row 0 of the image is at `v` = 1).
    texcoords: Vec<DVec2>,
    normals: Vec<DVec3>,
    /// The faces by object (or group) name and material, in order of first use.
    groups: Vec<FaceGroup>,
    /// Each `mtllib` statement: the text after the keyword and its line.
    libraries: Vec<(String, usize)>,
    /// Each material name `usemtl` gives, with the first line giving it, in that order.
    used_materials: Vec<(String, usize)>,
    /// `f` statements read (with fewer than three corners too).
    faces: usize,
    /// `l` and `p` statements.
    lines_and_points: usize,
    /// Statements of any known kind.
    statements: usize,
    /// Lines with anything but a comment.
    nonblank_lines: usize,
}

impl ObjFile {
    /// Why a file gave no mesh: the message of its error.
    fn why_no_triangles(&self) -> String {
        let why = if self.faces == 1 {
            "its only face is degenerate (no area) or has fewer than 3 corners".to_string()
        } else if self.faces > 1 {
            format!(
                "all {} faces are degenerate (no area) or have fewer than 3 corners",
                self.faces
            )
        } else if self.lines_and_points > 0 {
            format!(
                "it has no faces, only lines and points ({} `l` and `p` statement{}), which are not rendered",
                self.lines_and_points,
                plural(self.lines_and_points)
            )
        } else if self.nonblank_lines == 0 {
            "the file is empty (or holds only comments)".to_string()
        } else if self.statements == 0 {
            "no OBJ statement was recognised in it: is it a text file in UTF-8 (or UTF-16 with a byte-order mark)?".to_string()
        } else {
            "it has no faces (`f`)".to_string()
        };
        format!("no triangles to render: {why}")
    }
}

/// The faces of one object (or group) name and material.
struct FaceGroup {
    object: String,
    /// The `usemtl` name (`None` before any `usemtl`, or after an empty one).
    material: Option<String>,
    /// The mesh's vertices: each distinct (position, texture coordinate, normal) index
    /// triple its faces use, 0-based, [`NONE`] for an absent index.
    vertices: Vec<[u32; 3]>,
    /// Index triple → its vertex.
    lookup: HashMap<[u32; 3], u32>,
    /// Triangles as indices into `vertices`.
    triangles: Vec<[u32; 3]>,
}

impl FaceGroup {
    /// The vertex of `corner`, added on first use.
    fn vertex(&mut self, corner: [u32; 3]) -> u32 {
        let vertices = &mut self.vertices;
        *self.lookup.entry(corner).or_insert_with(|| {
            vertices.push(corner);
            (vertices.len() - 1) as u32
        })
    }

    /// The group's geometry for the checks of [`finish_mesh`]: an attribute that only
    /// some vertices have is passed short, which drops it with a warning.
    fn into_raw_mesh(self, file: &ObjFile) -> RawMesh {
        fn attribute<T: Copy>(vertices: &[[u32; 3]], slot: usize, values: &[T]) -> Option<Vec<T>> {
            let present: Vec<T> = vertices
                .iter()
                .filter(|corner| corner[slot] != NONE)
                .map(|corner| values[corner[slot] as usize])
                .collect();
            (!present.is_empty()).then_some(present)
        }
        RawMesh {
            positions: self
                .vertices
                .iter()
                .map(|corner| file.positions[corner[0] as usize])
                .collect(),
            normals: attribute(&self.vertices, 2, &file.normals),
            uvs: attribute(&self.vertices, 1, &file.texcoords),
            uvs1: None,
            tangents: None,
            colors: (!file.colors.is_empty()).then(|| {
                self.vertices
                    .iter()
                    .map(|corner| file.colors[corner[0] as usize].extend(1.0))
                    .collect()
            }),
            triangles: self.triangles,
        }
    }
}

/// Problems that do not stop the import, each kind reported once per file, at its
/// first place and with how often it occurs, however many lines have it.
#[derive(Default)]
struct Notes {
    /// Words read by their leading number: line, column, the word, the number.
    partial_numbers: Counted<(usize, usize, String, f64)>,
    short_faces: Counted<usize>,
    fanned_faces: Counted<usize>,
    normals_without_vn: Counted<usize>,
    empty_usemtl: Counted<usize>,
    empty_mtllib: Counted<usize>,
    /// MTL `newmtl` statements without a name.
    nameless_materials: Counted<usize>,
    /// Statements that are not read, by keyword: the first line, in order of first use
    /// (at most [`MAX_NAMED_STATEMENTS`]).
    ignored: Vec<(String, usize)>,
    ignored_kinds: HashSet<String>,
    /// Lines with further kinds of unsupported statement, and the first of them.
    ignored_others: Counted<usize>,
}

/// The first occurrence of something and how many there are.
struct Counted<T> {
    first: Option<T>,
    count: usize,
}

impl<T> Default for Counted<T> {
    fn default() -> Self {
        Self {
            first: None,
            count: 0,
        }
    }
}

impl<T> Counted<T> {
    fn note(&mut self, first: impl FnOnce() -> T) {
        if self.first.is_none() {
            self.first = Some(first());
        }
        self.count += 1;
    }
}

impl Notes {
    fn ignore(&mut self, keyword: &str, line: usize) {
        if self.ignored_kinds.contains(keyword) {
            return;
        }
        if self.ignored_kinds.len() < MAX_NAMED_STATEMENTS {
            self.ignored_kinds.insert(keyword.to_string());
            self.ignored.push((keyword.to_string(), line));
        } else {
            self.ignored_others.note(|| line);
        }
    }

    /// Adds one warning per kind of problem noted to `warnings`.
    fn report(self, path: &Path, warnings: &mut Vec<String>) {
        let file = path.display();
        let times = |count: usize| match count {
            1 => String::new(),
            _ => format!(" ({count} times)"),
        };
        if let Some((line, column, word, value)) = self.partial_numbers.first {
            let more = match self.partial_numbers.count - 1 {
                0 => String::new(),
                more => format!(" ({more} more such number{})", plural(more)),
            };
            warnings.push(format!(
                "{file}:{line}:{column}: `{}` is read as {}, the number it starts with, as tinyobjloader and assimp read it{more}",
                echo(&word),
                short(value)
            ));
        }
        if let Some(line) = self.short_faces.first {
            let count = self.short_faces.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} of fewer than 3 vertices skipped",
                plural(count)
            ));
        }
        if let Some(line) = self.fanned_faces.first {
            let count = self.fanned_faces.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} could not be ear-clipped (the outline crosses itself in the face's plane); fanned from the first corner, so triangles may overlap",
                plural(count)
            ));
        }
        if let Some(line) = self.normals_without_vn.first {
            let count = self.normals_without_vn.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} give normal indices, but no `vn` is defined before them; the indices are ignored (flat shading)",
                plural(count)
            ));
        }
        if let Some(line) = self.empty_usemtl.first {
            warnings.push(format!(
                "{file}:{line}: `usemtl` without a material name{}; the default material is used",
                times(self.empty_usemtl.count)
            ));
        }
        if let Some(line) = self.empty_mtllib.first {
            warnings.push(format!(
                "{file}:{line}: `mtllib` without a file name{}; ignored",
                times(self.empty_mtllib.count)
            ));
        }
        if let Some(line) = self.nameless_materials.first {
            warnings.push(format!(
                "{file}:{line}: `newmtl` without a material name{}; the material is skipped",
                times(self.nameless_materials.count)
            ));
        }
        for (keyword, line) in &self.ignored {
            let what = match keyword.as_str() {
                "l" => "lines are not rendered",
                "p" => "points are not rendered",
                "cstype" | "curv" | "curv2" | "surf" | "deg" | "bmat" | "step" | "parm"
                | "trim" | "hole" | "scrv" | "sp" | "end" => {
                    "free-form curves and surfaces are not supported"
                }
                _ => "not supported",
            };
            warnings.push(format!(
                "{file}:{line}: `{}`: {what}; ignored (here and on any later line)",
                echo(keyword)
            ));
        }
        if let Some(line) = self.ignored_others.first {
            let count = self.ignored_others.count;
            warnings.push(format!(
                "{file}:{line}: {count} more line{} of other unknown statements ignored",
                plural(count)
            ));
        }
    }
}

/// The state of reading an OBJ file line by line.
struct ObjReader<'p> {
    path: &'p Path,
    file: ObjFile,
    /// The current `o`/`g` name and `usemtl` material.
    object: String,
    material: Option<String>,
    /// The group of the current name and material, once a face has asked for it.
    current: Option<usize>,
    /// (name, material) → its group in `file.groups`.
    group_of: HashMap<(String, Option<String>), usize>,
    /// Material names already in `file.used_materials`.
    used: HashSet<String>,
    /// Triangles so far, against [`MAX_MODEL_TRIANGLES`].
    triangles: usize,
    cutter: FaceCutter,
    /// Buffers reused from face to face.
    corners: Vec<[u32; 3]>,
    points: Vec<DVec3>,
    cut: Vec<[u32; 3]>,
    /// The most bytes the arrays may hold ([`super::ImportOptions::max_bytes`] less the
    /// file).
    max_bytes: Option<u64>,
    progress: Option<&'p (dyn Fn(u64, u64) + Sync)>,
}

impl<'p> ObjReader<'p> {
    /// A reader of the file at `path` that may hold at most `max_bytes` more (none:
    /// the fixed limits only) and reports its progress to `progress`.
    fn new(
        path: &'p Path,
        max_bytes: Option<u64>,
        progress: Option<&'p (dyn Fn(u64, u64) + Sync)>,
    ) -> Self {
        Self {
            path,
            max_bytes,
            progress,
            file: ObjFile {
                positions: Vec::new(),
                colors: Vec::new(),
                texcoords: Vec::new(),
                normals: Vec::new(),
                groups: Vec::new(),
                libraries: Vec::new(),
                used_materials: Vec::new(),
                faces: 0,
                lines_and_points: 0,
                statements: 0,
                nonblank_lines: 0,
            },
            object: UNNAMED.to_string(),
            material: None,
            current: None,
            group_of: HashMap::new(),
            used: HashSet::new(),
            triangles: 0,
            cutter: FaceCutter::default(),
            corners: Vec::new(),
            points: Vec::new(),
            cut: Vec::new(),
        }
    }

    /// Reads every line of `text`, checking the memory its arrays hold and reporting
    /// progress every [`CHECK_EVERY_LINES`] lines.
    fn read(mut self, text: &str, notes: &mut Notes) -> Result<ObjFile, SceneError> {
        let total = text.len() as u64;
        let (mut done, mut lines) = (0u64, 0);
        for line in text.lines() {
            lines += 1;
            self.statement(lines, strip_comment(line), notes)?;
            done += line.len() as u64 + 1;
            if lines % CHECK_EVERY_LINES == 0 {
                self.check_memory(lines)?;
                if let Some(progress) = self.progress {
                    progress(done.min(total), total);
                }
            }
        }
        self.check_memory(lines)?;
        if let Some(progress) = self.progress {
            progress(total, total);
        }
        Ok(self.file)
    }

    /// Refuses the file once the arrays read so far hold more than the cap allows
    /// (line `n` names where).
    fn check_memory(&self, n: usize) -> Result<(), SceneError> {
        let Some(max) = self.max_bytes else {
            return Ok(());
        };
        let file = &self.file;
        let groups: (u64, u64) = file.groups.iter().fold((0, 0), |(v, t), group| {
            (
                v + group.vertices.len() as u64,
                t + group.triangles.len() as u64,
            )
        });
        // A group's vertex is its index triple and its lookup entry (about 48 bytes
        // with the table's overhead); a triangle three indices.
        let held = file.positions.len() as u64 * 24
            + file.normals.len() as u64 * 24
            + file.texcoords.len() as u64 * 16
            + groups.0 * 48
            + groups.1 * 12;
        if held > max {
            return Err(SceneError::too_large(
                self.path,
                None,
                format!(
                    "by line {n}: {}",
                    memory_cap_message(held, max, "the arrays read so far")
                ),
            ));
        }
        Ok(())
    }

    /// Reads the statement on line `n` (its comment already cut off).
    fn statement(&mut self, n: usize, line: &str, notes: &mut Notes) -> Result<(), SceneError> {
        let path = self.path;
        let words = words(line);
        let Some(&(column, keyword)) = words.first() else {
            return Ok(());
        };
        let values = &words[1..];
        // The rest of the line, for names that may hold spaces.
        let rest = || line.trim_start()[keyword.len()..].trim();
        self.file.nonblank_lines += 1;
        self.file.statements += 1;
        match keyword {
            "v" => {
                if !matches!(values.len(), 3 | 4 | 6) {
                    return Err(at(
                        path,
                        n,
                        column,
                        format!(
                            "`v` takes x y z (and optionally w, or r g b), got {} numbers",
                            values.len()
                        ),
                    ));
                }
                let mut position = [0.0; 3];
                for (what, (value, word)) in ["position x", "position y", "position z"]
                    .iter()
                    .zip(position.iter_mut().zip(values))
                {
                    *value = finite(path, n, *word, what, notes)?;
                }
                // `w` weighs rational curves' control points; a polygon's vertex is
                // where x y z say (tinyobjloader and assimp ignore it too).
                if values.len() == 4 {
                    number(path, n, values[3], "position w", notes)?;
                }
                let mut color = None;
                if values.len() == 6 {
                    let mut rgb = [0.0; 3];
                    for (value, word) in rgb.iter_mut().zip(&values[3..]) {
                        *value = finite(path, n, *word, "vertex colour", notes)?;
                    }
                    color = Some(DVec3::from(rgb));
                }
                if self.file.positions.len() == MAX_MODEL_VERTICES {
                    return Err(at(
                        path,
                        n,
                        column,
                        format!(
                            "more than {MAX_MODEL_VERTICES} vertex positions, more than accepted"
                        ),
                    ));
                }
                self.file.positions.push(DVec3::from(position));
                // Vertices without a colour among coloured ones are white, as
                // tinyobjloader reads them.
                if color.is_some() || !self.file.colors.is_empty() {
                    let vertex = self.file.positions.len() - 1;
                    self.file.colors.resize(vertex, DVec3::ONE);
                    self.file.colors.push(color.unwrap_or(DVec3::ONE));
                }
            }
            "vt" => {
                if !(1..=3).contains(&values.len()) {
                    return Err(at(
                        path,
                        n,
                        column,
                        format!("`vt` takes u (v (w)), got {} numbers", values.len()),
                    ));
                }
                let u = number(path, n, values[0], "texture coordinate u", notes)?;
                // A missing v is 0 (the specification's default); w is for 3D textures.
                let v = match values.get(1) {
                    Some(word) => number(path, n, *word, "texture coordinate v", notes)?,
                    None => 0.0,
                };
                if let Some(word) = values.get(2) {
                    number(path, n, *word, "texture coordinate w", notes)?;
                }
                self.file.texcoords.push(DVec2::new(u, 1.0 - v));
            }
            "vn" => {
                if values.len() != 3 {
                    return Err(at(
                        path,
                        n,
                        column,
                        format!("`vn` takes i j k, got {} numbers", values.len()),
                    ));
                }
                let mut normal = [0.0; 3];
                for (value, word) in normal.iter_mut().zip(values) {
                    *value = number(path, n, *word, "normal", notes)?;
                }
                self.file.normals.push(DVec3::from(normal));
            }
            "f" => self.face(n, column, values, notes)?,
            "o" | "g" => {
                let name = rest();
                self.object = if name.is_empty() { UNNAMED } else { name }.to_string();
                self.current = None;
            }
            "usemtl" => {
                let name = rest();
                if name.is_empty() {
                    notes.empty_usemtl.note(|| n);
                    self.material = None;
                } else {
                    if self.used.insert(name.to_string()) {
                        self.file.used_materials.push((name.to_string(), n));
                    }
                    self.material = Some(name.to_string());
                }
                self.current = None;
            }
            "mtllib" => {
                let names = rest();
                if names.is_empty() {
                    notes.empty_mtllib.note(|| n);
                } else {
                    self.file.libraries.push((names.to_string(), n));
                }
            }
            // Smoothing groups: the normals come from `vn`.
            "s" => {}
            "l" | "p" => {
                self.file.lines_and_points += 1;
                notes.ignore(keyword, n);
            }
            _ => {
                self.file.statements -= 1;
                notes.ignore(keyword, n);
            }
        }
        Ok(())
    }

    /// Reads the face on line `n` (`values` are its corners) into the current group.
    fn face(
        &mut self,
        n: usize,
        column: usize,
        values: &[(usize, &str)],
        notes: &mut Notes,
    ) -> Result<(), SceneError> {
        self.file.faces += 1;
        let defined = [
            self.file.positions.len(),
            self.file.texcoords.len(),
            self.file.normals.len(),
        ];
        let mut dropped_normals = false;
        self.corners.clear();
        for (k, word) in values.iter().enumerate() {
            let corner = corner(self.path, n, k + 1, *word, defined, &mut dropped_normals)?;
            self.corners.push(corner);
        }
        if dropped_normals {
            notes.normals_without_vn.note(|| n);
        }
        if values.len() < 3 {
            notes.short_faces.note(|| n);
            return Ok(());
        }
        self.triangles += values.len() - 2;
        if self.triangles > MAX_MODEL_TRIANGLES {
            return Err(at(
                self.path,
                n,
                column,
                format!("more than {MAX_MODEL_TRIANGLES} triangles, more than accepted"),
            ));
        }
        self.points.clear();
        let positions = &self.file.positions;
        self.points
            .extend(self.corners.iter().map(|c| positions[c[0] as usize]));
        self.cut.clear();
        if self.cutter.cut(&self.points, &mut self.cut) == Cut::FanAfterEarsFailed {
            notes.fanned_faces.note(|| n);
        }
        let group = self.group();
        let group = &mut self.file.groups[group];
        for triangle in &self.cut {
            let vertices = triangle.map(|k| group.vertex(self.corners[k as usize]));
            group.triangles.push(vertices);
        }
        Ok(())
    }

    /// The group of the current name and material, made on first use.
    fn group(&mut self) -> usize {
        if let Some(group) = self.current {
            return group;
        }
        let key = (self.object.clone(), self.material.clone());
        let groups = &mut self.file.groups;
        let group = *self.group_of.entry(key).or_insert_with(|| {
            groups.push(FaceGroup {
                object: self.object.clone(),
                material: self.material.clone(),
                vertices: Vec::new(),
                lookup: HashMap::new(),
                triangles: Vec::new(),
            });
            groups.len() - 1
        });
        self.current = Some(group);
        group
    }
}

/// `line` without its comment: a `#` that starts a word starts a comment running to the
/// end of the line (inline comments are common, though the specification only has
/// whole-line ones); a `#` inside a word (`mat#1`) is part of it.
fn strip_comment(line: &str) -> &str {
    let mut after_space = true;
    for (offset, c) in line.char_indices() {
        if c == '#' && after_space {
            return &line[..offset];
        }
        after_space = c.is_whitespace();
    }
    line
}

/// Reads face corner number `k` (`v`, `v/vt`, `v//vn` or `v/vt/vn`, each index from 1,
/// or negative counting back from the last defined) as 0-based indices, against the
/// counts of positions, texture coordinates and normals defined before the line.
/// Normal indices in a file with no `vn` before the face are dropped (as tinyobjloader
/// does), setting `dropped_normals`.
fn corner(
    path: &Path,
    line: usize,
    k: usize,
    (column, word): (usize, &str),
    defined: [usize; 3],
    dropped_normals: &mut bool,
) -> Result<[u32; 3], SceneError> {
    if word.split('/').count() > 3 {
        return Err(at(
            path,
            line,
            column,
            format!(
                "face corner {k} `{}` has more than three indices (v/vt/vn)",
                echo(word)
            ),
        ));
    }
    let kinds = ["position", "texture coordinate", "normal"];
    let mut corner = [NONE; 3];
    for (slot, part) in word.split('/').enumerate() {
        if part.is_empty() {
            if slot == 0 {
                return Err(at(
                    path,
                    line,
                    column,
                    format!("face corner {k} `{}` has no position index", echo(word)),
                ));
            }
            continue;
        }
        let kind = kinds[slot];
        let fail = |message: String| at(path, line, column, format!("face corner {k}: {message}"));
        // `None`: an integer beyond any index (more digits than an i64 holds).
        let index: Option<i64> = match part.parse() {
            Ok(index) => Some(index),
            Err(_) if is_integer(part) => None,
            Err(_) => {
                return Err(fail(format!(
                    "the {kind} index `{}` is not an integer",
                    echo(part)
                )));
            }
        };
        if index == Some(0) {
            return Err(fail(format!("the {kind} index is 0 (OBJ counts from 1)")));
        }
        let count = defined[slot];
        if slot == 2 && count == 0 {
            *dropped_normals = true;
            continue;
        }
        let resolved = index.and_then(|index| {
            if index > 0 {
                index.unsigned_abs().checked_sub(1)
            } else {
                (count as u64).checked_sub(index.unsigned_abs())
            }
        });
        match resolved {
            Some(resolved) if resolved < count as u64 => corner[slot] = resolved as u32,
            _ => {
                return Err(fail(format!(
                    "the {kind} index {} is out of range: {count} {kind}{} defined before this line",
                    echo(part),
                    if count == 1 { " is" } else { "s are" }
                )));
            }
        }
    }
    Ok(corner)
}

/// Whether `word` is an integer in decimal, of any size: an optional sign and digits.
fn is_integer(word: &str) -> bool {
    let digits = word.strip_prefix(['+', '-']).unwrap_or(word);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
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
    SceneError::invalid(path, Some((line, column)), message)
}

/// Parses `word` as a number, failing with a message that names `what`. A word that
/// starts with a number and goes on with something else (`3.1+e2`) is read as that
/// number, as C's `strtod` (and so tinyobjloader and assimp) read it, with a note.
fn number(
    path: &Path,
    line: usize,
    (column, word): (usize, &str),
    what: &str,
    notes: &mut Notes,
) -> Result<f64, SceneError> {
    if let Ok(value) = word.parse::<f64>() {
        return Ok(value);
    }
    match word[..number_prefix(word)].parse::<f64>() {
        Ok(value) => {
            notes
                .partial_numbers
                .note(|| (line, column, word.to_string(), value));
            Ok(value)
        }
        Err(_) => Err(at(
            path,
            line,
            column,
            format!("{what}: `{}` is not a number", echo(word)),
        )),
    }
}

/// The length of the longest start of `word` that is a decimal number: an optional
/// sign, digits with at most one point (at least one digit), and an exponent when it
/// has digits.
fn number_prefix(word: &str) -> usize {
    let bytes = word.as_bytes();
    let digits_from = |mut i: usize| {
        while bytes.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    let start = usize::from(matches!(bytes.first(), Some(b'+' | b'-')));
    let mut end = digits_from(start);
    let mut digits = end - start;
    if bytes.get(end) == Some(&b'.') {
        let fraction = digits_from(end + 1);
        digits += fraction - end - 1;
        end = fraction;
    }
    if digits == 0 {
        return 0;
    }
    if matches!(bytes.get(end), Some(b'e' | b'E')) {
        let sign = end + 1 + usize::from(matches!(bytes.get(end + 1), Some(b'+' | b'-')));
        let exponent = digits_from(sign);
        if exponent > sign {
            end = exponent;
        }
    }
    end
}

/// Parses `word` as a finite number.
fn finite(
    path: &Path,
    line: usize,
    word: (usize, &str),
    what: &str,
    notes: &mut Notes,
) -> Result<f64, SceneError> {
    let value = number(path, line, word, what, notes)?;
    if !value.is_finite() {
        return Err(at(
            path,
            line,
            word.0,
            format!("{what} is not a finite number ({})", echo(word.1)),
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An OBJ of `vertices` positions and one triangle.
    fn many_vertices(vertices: usize) -> String {
        let mut text = String::with_capacity(vertices * 20);
        for i in 0..vertices {
            text.push_str(&format!("v {i} {} 0.25\n", (i * i) % 7));
        }
        text.push_str("f 1 2 3\n");
        text
    }

    #[test]
    fn a_capped_import_is_refused_while_its_arrays_grow_past_the_cap() {
        let text = many_vertices(400_000);
        let path = Path::new("big.obj");
        // Unbounded, it imports.
        assert!(parse_obj(text.as_bytes(), path).is_ok());
        // 2 MiB for the arrays: positions of 24 bytes reach it by about line 87,000,
        // and the check every 65,536 lines refuses at the first check past it.
        let cap = 2 << 20;
        let err = parse_obj_within(text.as_bytes(), path, Budget::new(Some(cap)), None)
            .expect_err("over the cap")
            .to_string();
        assert!(
            err.contains("by line 131072") && err.contains("--max-memory"),
            "{err}"
        );
        // The progress hook hears about every checked stretch and the end.
        let heard = std::sync::Mutex::new(Vec::new());
        let hook = |done: u64, total: u64| heard.lock().expect("lock").push((done, total));
        parse_obj_within(text.as_bytes(), path, Budget::default(), Some(&hook)).expect("imports");
        let heard = heard.into_inner().expect("lock");
        assert_eq!(heard.len(), 400_001 / CHECK_EVERY_LINES + 1, "{heard:?}");
        assert_eq!(heard.last(), Some(&(text.len() as u64, text.len() as u64)));
        assert!(heard.windows(2).all(|pair| pair[0].0 < pair[1].0));
    }

    #[test]
    fn words_know_their_columns() {
        assert_eq!(words("  v 1\t2"), vec![(3, "v"), (5, "1"), (7, "2")]);
    }

    #[test]
    fn comments_start_at_a_hash_that_starts_a_word() {
        assert_eq!(strip_comment("v 1 2 3 # corner"), "v 1 2 3 ");
        assert_eq!(strip_comment("# whole line"), "");
        assert_eq!(strip_comment("usemtl mat#1"), "usemtl mat#1");
        assert_eq!(strip_comment("v 1 2 3\t#tab"), "v 1 2 3\t");
    }

    #[test]
    fn numbers_followed_by_junk_are_read_by_their_start() {
        for (word, length) in [
            ("3.1+e2", 3),
            ("3.1-e2", 3),
            ("1e+2", 4),
            ("2.e", 2),
            ("-.5x", 3),
            ("+", 0),
            (".", 0),
            ("e5", 0),
            ("12abc", 2),
        ] {
            assert_eq!(number_prefix(word), length, "{word}");
        }
    }
}
