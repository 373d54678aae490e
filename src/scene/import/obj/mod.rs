//! Wavefront OBJ (Wavefront's "Object Files" specification, Alias|Wavefront Advanced
//! Visualizer manual, appendix B1) with its MTL material libraries ([`mtl`]), read as
//! tinyobjloader and assimp read them.
//!
//! Every line is read by this module ([`reader`]), so that each error names its file,
//! line and column: vertex data, faces (cut into triangles by [`face`]: fans for convex
//! faces, ear clipping for the others), objects, groups and material changes. The faces
//! are collected into one mesh per object (or group) name and material, each with its
//! own vertices: one per distinct position/texture/normal index triple it uses.
//! Everything is a single pass over the lines with hash lookups, so the time is linear
//! in the file however many groups, objects or material changes it has. The libraries
//! are read once the whole file is, so that a material is found by its name wherever
//! its `mtllib` stands.
//!
//! The readers other programs use decide what is lenient: an inline `#` comment, a
//! missing library or texture, an empty `usemtl`, normal indices in a file without
//! `vn`, and a number followed by junk (`3.1+e2`) are warnings, never errors.
//!
//! This module holds the import's entry points and its top-level flow; the parts are:
//! [`syntax`] (words, numbers, comments and face corners of OBJ and MTL lines),
//! [`reader`] (the OBJ statements, line by line, into the [`contents`] of the file),
//! [`notes`] (the warnings counted while reading), [`mtl`] (the material libraries
//! and their mapping onto our materials), and [`material_uses`] (the `usemtl` names
//! checked against the libraries).

mod contents;
mod face;
mod material_uses;
mod mtl;
mod normal_map;
mod notes;
mod reader;
mod scalar_maps;
mod syntax;

use std::borrow::Cow;
use std::path::Path;

use glam::DVec3;

use self::material_uses::check_material_uses;
use self::mtl::{Libraries, map_material};
use self::notes::Notes;
use self::reader::ObjReader;
use self::syntax::decode_text;
use super::mesh::{Budget, finish_mesh};
use super::texture::Textures;
use super::{ImportOptions, ImportedMaterial, ImportedModel, error, read_file};
use crate::echo::echo;
use crate::scene::{Material, SceneError};

/// Diffuse albedo of a material whose MTL gives no `Kd` (and of geometry with no
/// material at all); 1 when a `map_Kd` texture supplies the colour.
pub const DEFAULT_OBJ_ALBEDO: f64 = 0.8;

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

#[cfg(test)]
mod tests {
    use super::reader::CHECK_EVERY_LINES;
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
}
