//! Tangents for normal maps where a glTF primitive has none: MikkTSpace (Mikkelsen,
//! "Simulation of Wrinkled Surfaces Revisited", 2008), which glTF 2.0 §3.7.2.1
//! prescribes ("client implementations SHOULD calculate tangents using default
//! MikkTSpace algorithms with the specified vertex positions, normals, and texture
//! coordinates associated with the normal texture"), through the `mikktspace` crate.

use std::collections::HashMap;

use glam::{DVec2, DVec3, DVec4};

use super::mesh::RawMesh;

/// The geometry `mikktspace` reads, corner by corner, and the tangents it writes.
struct Corners<'a> {
    positions: &'a [DVec3],
    normals: &'a [DVec3],
    uvs: &'a [DVec2],
    triangles: &'a [[u32; 3]],
    /// One per corner (`3 · face + corner`).
    tangents: Vec<[f32; 4]>,
}

impl Corners<'_> {
    fn vertex(&self, face: usize, corner: usize) -> usize {
        self.triangles[face][corner] as usize
    }
}

impl mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, corner: usize) -> [f32; 3] {
        self.positions[self.vertex(face, corner)]
            .as_vec3()
            .to_array()
    }

    fn normal(&self, face: usize, corner: usize) -> [f32; 3] {
        self.normals[self.vertex(face, corner)].as_vec3().to_array()
    }

    /// `v` flipped: glTF's runs down the image, but its normal maps' green channel
    /// points up it (glTF 2.0 §3.9.3, "+Y is up"), and MikkTSpace's bitangent runs
    /// along increasing `v`; Blender's exporter and three.js flip it the same way.
    fn tex_coord(&self, face: usize, corner: usize) -> [f32; 2] {
        let uv = self.uvs[self.vertex(face, corner)];
        [uv.x as f32, (1.0 - uv.y) as f32]
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, corner: usize) {
        self.tangents[3 * face + corner] = tangent;
    }
}

/// `raw` with MikkTSpace tangents from its normals and the texture coordinates `uvs`
/// (the set its normal map reads), parallel to them. Corners of one vertex that get
/// different tangents (across a UV seam or a mirror line) become vertices of their own,
/// every attribute copied. `None` when `raw` has no normals or the generator fails.
pub(super) fn with_mikktspace_tangents(raw: RawMesh, uvs: &[DVec2]) -> Option<RawMesh> {
    let normals = raw.normals.as_ref()?;
    if normals.len() != raw.positions.len()
        || uvs.len() != raw.positions.len()
        || raw
            .triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= raw.positions.len())
    {
        return None;
    }
    let mut corners = Corners {
        positions: &raw.positions,
        normals,
        uvs,
        triangles: &raw.triangles,
        tangents: vec![[0.0; 4]; 3 * raw.triangles.len()],
    };
    if !mikktspace::generate_tangents(&mut corners) {
        return None;
    }
    let tangents = corners.tangents;
    // Each (vertex, tangent) pair once.
    let mut index: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut source: Vec<usize> = Vec::new();
    let mut vertex_tangents: Vec<DVec4> = Vec::new();
    let triangles: Vec<[u32; 3]> = raw
        .triangles
        .iter()
        .enumerate()
        .map(|(face, triangle)| {
            std::array::from_fn(|corner| {
                let tangent = tangents[3 * face + corner];
                let key = (triangle[corner], tangent.map(f32::to_bits));
                *index.entry(key).or_insert_with(|| {
                    source.push(triangle[corner] as usize);
                    vertex_tangents.push(DVec4::from_array(tangent.map(f64::from)));
                    (source.len() - 1) as u32
                })
            })
        })
        .collect();
    let pick = |values: &[DVec3]| source.iter().map(|&i| values[i]).collect::<Vec<_>>();
    let pick2 = |values: &[DVec2]| source.iter().map(|&i| values[i]).collect::<Vec<_>>();
    Some(RawMesh {
        positions: pick(&raw.positions),
        normals: raw.normals.as_deref().map(pick),
        uvs: raw.uvs.as_deref().map(pick2),
        uvs1: raw.uvs1.as_deref().map(pick2),
        colors: raw
            .colors
            .as_deref()
            .map(|values| source.iter().map(|&i| values[i]).collect()),
        tangents: Some(vertex_tangents),
        triangles,
    })
}
