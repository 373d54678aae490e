//! Meshes and their primitives: positions, normals, the texture coordinates a material
//! reads, vertex colours and triangles (lists, strips and fans), and tangents for normal
//! maps (given or MikkTSpace's).

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::json::validation::Checked;
use ::gltf::mesh::Mode;
use glam::{DMat4, DVec2, DVec3};

use super::attributes::{NORMAL_TYPES, POSITION_TYPES};
use super::importer::{Importer, MaterialUse, describe};
use crate::scene::import::accessor::{Expect, Normalized, read};
use crate::scene::import::mesh::{RawMesh, finish_mesh};
use crate::scene::import::tangents;
use crate::scene::import::{ImportedMesh, MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES};
use crate::scene::{MaterialKind, SceneError, TextureTransform};

impl Importer<'_> {
    /// Imports each primitive of `mesh` as one mesh placed at `instances`.
    pub(super) fn mesh(
        &mut self,
        mesh: &::gltf::Mesh<'_>,
        instances: Vec<DMat4>,
    ) -> Result<(), SceneError> {
        let mesh_name = describe("mesh", mesh.index(), mesh.name());
        if mesh.primitives().any(|p| p.morph_targets().len() > 0) {
            self.warn_once(
                "morph",
                "morph targets are ignored: meshes are imported in their base shape".into(),
            );
        }
        for primitive in mesh.primitives() {
            let name = format!("{mesh_name}, primitive {}", primitive.index());
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                // Points and lines have no area for a ray to hit; a file may well mix
                // them with surfaces (guides, wireframes), so only they are left out.
                self.not_triangles
                    .push(format!("{name}: {}", mode_name(mode)));
                continue;
            }
            self.triangle_primitives += 1;
            // The material first: it decides which texture coordinates to read.
            let uses = self.material(primitive.material().index())?;
            let material = uses.index;
            // The JSON's keys, not `Primitive::attributes`, which unwraps each key.
            let json = &self.document.as_json().meshes[mesh.index()].primitives[primitive.index()];
            let colors: Vec<String> = json
                .attributes
                .keys()
                .filter_map(|semantic| match semantic {
                    Checked::Valid(::gltf::Semantic::Colors(set)) if *set > 0 => {
                        Some(format!("COLOR_{set}"))
                    }
                    _ => None,
                })
                .collect();
            if !colors.is_empty() {
                self.vertex_colors
                    .push(format!("{name}: {}", colors.join(", ")));
            }
            let raw = self
                .primitive(&primitive, &name, uses)
                .map_err(|e| self.fail(format!("{name}: {e}")))?;
            self.budget
                .charge_instances(instances.len())
                .map_err(|e| e.at(self.path))?;
            if let Some(imported) =
                finish_mesh(name, self.path, raw, material, &mut self.model.warnings)
                    .map_err(|e| self.fail(e))?
            {
                self.model.meshes.push(ImportedMesh {
                    instances: instances.clone(),
                    ..imported
                });
            }
        }
        Ok(())
    }

    /// Reads one primitive's positions, normals, texture coordinates (`TEXCOORD_0`, and
    /// `TEXCOORD_1` when `uses_set1`: a texture of its material reads it), vertex
    /// colours (`COLOR_0`) and triangles (its mode is one of the three of triangles),
    /// with tangents where its material has a normal map; `name` (mesh and primitive)
    /// is for warnings, the caller prefixes it to errors.
    pub(super) fn primitive(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        uses: MaterialUse,
    ) -> Result<RawMesh, String> {
        let positions_accessor = primitive
            .get(&::gltf::Semantic::Positions)
            .ok_or("it has no POSITION attribute")?;
        let count = positions_accessor.count();
        self.charge_primitive(primitive, count)?;
        let positions = vec3(read(
            &positions_accessor,
            &Expect {
                name: "POSITION",
                dimensions: Dimensions::Vec3,
                types: POSITION_TYPES,
                normalized: Normalized::Either,
            },
            &self.buffers,
        )?);
        self.check_quantization(&positions_accessor, name, "POSITION", false);
        self.check_declared_bounds(&positions_accessor, name, &positions);
        let normals = self.normals(primitive, name, count)?;
        let uvs = self.texcoords(primitive, name, 0, count)?;
        let uvs1 = if uses.uses_set1 {
            self.second_texcoords(primitive, name, count, &uvs)?
        } else {
            None
        };
        let colors = self.colors(primitive, name, count);
        // Emissive materials come from KHR_materials_unlit alone here; their colour is
        // the emission, which vertex colours do not multiply.
        let unlit =
            self.model.materials[uses.index as usize].material.kind == MaterialKind::Emissive;
        if unlit && colors.is_some() {
            self.warn(format!(
                "{name}: COLOR_0 does not multiply the colour of its unlit material; ignored"
            ));
        }
        let triangles = self.primitive_triangles(primitive, name, count)?;
        let raw = RawMesh {
            positions,
            normals,
            uvs,
            uvs1,
            colors,
            tangents: None,
            triangles,
        };
        match uses.normal_map {
            Some(normal_map) => self.with_normal_map_tangents(raw, primitive, name, &normal_map),
            None => Ok(raw),
        }
    }

    /// Refuses a primitive of `count` vertices whose vertex or triangle count is beyond
    /// the limits, and charges it to the import's budget.
    fn charge_primitive(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        count: usize,
    ) -> Result<(), String> {
        if count > MAX_MODEL_VERTICES {
            return Err(format!(
                "{count} vertices, more than the {MAX_MODEL_VERTICES} accepted"
            ));
        }
        let index_count = primitive.indices().map_or(count, |a| a.count());
        let triangle_count = match primitive.mode() {
            Mode::Triangles => index_count / 3,
            _ => index_count.saturating_sub(2),
        };
        if triangle_count > MAX_MODEL_TRIANGLES {
            return Err(format!(
                "{triangle_count} triangles, more than the {MAX_MODEL_TRIANGLES} accepted"
            ));
        }
        self.budget
            .charge_mesh(count, triangle_count)
            .map_err(String::from)
    }

    /// Reads `NORMAL` of `primitive` (of `count` vertices), if it has it.
    fn normals(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Result<Option<Vec<DVec3>>, String> {
        let Some(accessor) = primitive.get(&::gltf::Semantic::Normals) else {
            return Ok(None);
        };
        if accessor.count() != count {
            return Err(format!(
                "NORMAL has {} elements but POSITION has {count}",
                accessor.count()
            ));
        }
        let normals = vec3(read(
            &accessor,
            &Expect {
                name: "NORMAL",
                dimensions: Dimensions::Vec3,
                types: NORMAL_TYPES,
                normalized: Normalized::Always,
            },
            &self.buffers,
        )?);
        self.check_quantization(&accessor, name, "NORMAL", false);
        Ok(Some(normals))
    }

    /// Reads `TEXCOORD_1`, which a texture of the primitive's material reads; without
    /// it, the first set `uvs` stands in, with a warning.
    fn second_texcoords(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
        uvs: &Option<Vec<DVec2>>,
    ) -> Result<Option<Vec<DVec2>>, String> {
        if let Some(uvs1) = self.texcoords(primitive, name, 1, count)? {
            return Ok(Some(uvs1));
        }
        // A texture that names a set the primitive lacks is invalid (glTF 2.0 §5.30,
        // textureInfo.texCoord); the first set is the likeliest intent.
        self.warn(format!(
            "{name}: its material's textures use TEXCOORD_1, which it does not have; {}",
            if uvs.is_some() {
                "TEXCOORD_0 is used"
            } else {
                "it has no texture coordinates"
            }
        ));
        Ok(uvs.clone())
    }

    /// The triangles of `primitive` (of `count` vertices): its indices, or its vertices
    /// in order, as a list, strip or fan; a list's incomplete last triangle is dropped
    /// with a warning.
    fn primitive_triangles(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Result<Vec<[u32; 3]>, String> {
        let mode = primitive.mode();
        let indices: Vec<u32> = match primitive.indices() {
            Some(accessor) => read(
                &accessor,
                &Expect {
                    name: "indices",
                    dimensions: Dimensions::Scalar,
                    types: &[DataType::U8, DataType::U16, DataType::U32],
                    normalized: Normalized::Never,
                },
                &self.buffers,
            )?
            .into_iter()
            .map(|i| i as u32)
            .collect(),
            None => (0..count as u32).collect(),
        };
        if mode == Mode::Triangles && !indices.len().is_multiple_of(3) {
            self.warn(format!(
                "{name}: a triangle list of {} indices (not a multiple of 3): the last {} ignored",
                indices.len(),
                indices.len() % 3
            ));
        }
        Ok(triangles(mode, &indices))
    }

    /// The tangents a normal map read at `normal_map`'s coordinates needs: the
    /// primitive's `TANGENT` turned to follow the map's transform, or MikkTSpace's from
    /// the normals (flat ones where the primitive has none) and the map's coordinates.
    /// Where neither can be had, the mesh is returned without them, with a warning: its
    /// normal map is not applied.
    fn with_normal_map_tangents(
        &mut self,
        raw: RawMesh,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        normal_map: &TextureTransform,
    ) -> Result<RawMesh, String> {
        let given = self.tangents(primitive, name, raw.positions.len())?;
        let mut raw = RawMesh {
            tangents: given,
            ..raw
        };
        if raw.normals.is_none() {
            // glTF 2.0 §3.7.2.1: without NORMAL, flat normals (and TANGENT ignored),
            // from which MikkTSpace makes the normal map's tangents below.
            self.budget
                .charge_mesh(3 * raw.triangles.len(), 0)
                .map_err(String::from)?;
            if let Some(flat) = tangents::with_flat_normals(&raw) {
                raw = flat;
            }
        }
        if let Some(given) = raw.tangents.as_mut() {
            // TANGENT runs along the mesh's coordinates, the map's axes along the
            // transformed ones.
            if let Some(normals) = &raw.normals {
                tangents::follow_texture_transform(given, normals, normal_map);
            }
            return Ok(raw);
        }
        // No TANGENT: MikkTSpace's, from the normals and the normal map's coordinates as
        // the map reads them (`KHR_texture_transform` applied).
        let map_uvs = if normal_map.set == 1 {
            &raw.uvs1
        } else {
            &raw.uvs
        };
        let map_uvs = map_uvs.as_ref().map(|uvs| {
            uvs.iter()
                .map(|&uv| normal_map.apply(uv))
                .collect::<Vec<_>>()
        });
        let generated = match (&raw.normals, &map_uvs) {
            (Some(_), Some(map_uvs)) => tangents::with_mikktspace_tangents(&raw, map_uvs),
            _ => None,
        };
        match generated {
            Some(with_tangents) => Ok(with_tangents),
            None => {
                self.warn(format!(
                    "{name}: its material's normalTexture needs tangents, and without TANGENT they are generated from NORMAL and the normal map's texture coordinates, which {}; the normal map is not applied",
                    if raw.normals.is_none() || map_uvs.is_none() {
                        "it lacks"
                    } else {
                        "do not give any"
                    }
                ));
                Ok(raw)
            }
        }
    }
}

/// Points from a flat list of coordinates, three by three.
fn vec3(values: Vec<f64>) -> Vec<DVec3> {
    values
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect()
}

/// A primitive mode by its name and number in glTF 2.0 §5.24 (`mesh.primitive.mode`).
pub(super) fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS (0)",
        Mode::Lines => "LINES (1)",
        Mode::LineLoop => "LINE_LOOP (2)",
        Mode::LineStrip => "LINE_STRIP (3)",
        Mode::Triangles => "TRIANGLES (4)",
        Mode::TriangleStrip => "TRIANGLE_STRIP (5)",
        Mode::TriangleFan => "TRIANGLE_FAN (6)",
    }
}

/// Triangles from a primitive's index list (glTF 2.0 §3.7.2.1): a list, a strip
/// (triangle `i` is `(i, i+1, i+2)` for even `i` and `(i, i+2, i+1)` for odd `i`, which
/// keeps the winding) or a fan (`(i+1, i+2, 0)`).
pub(super) fn triangles(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => indices
            .windows(3)
            .enumerate()
            .map(|(i, w)| {
                if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[0], w[2], w[1]]
                }
            })
            .collect(),
        Mode::TriangleFan => match indices.split_first() {
            Some((&first, rest)) => rest.windows(2).map(|w| [w[0], w[1], first]).collect(),
            None => Vec::new(),
        },
        _ => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_the_winding() {
        assert_eq!(
            triangles(Mode::TriangleStrip, &[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &[0, 1, 2, 3]),
            vec![[1, 2, 0], [2, 3, 0]]
        );
        assert_eq!(triangles(Mode::TriangleFan, &[]), Vec::<[u32; 3]>::new());
        assert_eq!(triangles(Mode::Triangles, &[0, 1, 2, 3]), vec![[0, 1, 2]]);
    }
}
