//! What an OBJ file holds once its lines are read ([`ObjFile`]): the vertex data, and
//! the faces grouped by object (or group) name and material ([`FaceGroup`]), each group
//! with its own vertices, before they are made into meshes.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::notes::plural;
use super::syntax::NONE;
use crate::scene::import::mesh::RawMesh;

/// What an OBJ file holds, read but not yet made into meshes.
pub(super) struct ObjFile {
    /// Vertex positions (`v`).
    pub(super) positions: Vec<DVec3>,
    /// Vertex colours (`v x y z r g b`), parallel to `positions` from the first
    /// coloured vertex on (white for those before it and those without); empty when no
    /// vertex has one.
    pub(super) colors: Vec<DVec3>,
    /// Texture coordinates, `v` already flipped to grow downwards (ours and glTF's
    /// convention: OBJ's row 0 of the image is at `v` = 1).
    pub(super) texcoords: Vec<DVec2>,
    /// Vertex normals (`vn`).
    pub(super) normals: Vec<DVec3>,
    /// The faces by object (or group) name and material, in order of first use.
    pub(super) groups: Vec<FaceGroup>,
    /// Each `mtllib` statement: the text after the keyword and its line.
    pub(super) libraries: Vec<(String, usize)>,
    /// Each material name `usemtl` gives, with the first line giving it, in that order.
    pub(super) used_materials: Vec<(String, usize)>,
    /// `f` statements read (with fewer than three corners too).
    pub(super) faces: usize,
    /// `l` and `p` statements.
    pub(super) lines_and_points: usize,
    /// Statements of any known kind.
    pub(super) statements: usize,
    /// Lines with anything but a comment.
    pub(super) nonblank_lines: usize,
}

impl ObjFile {
    /// Why a file gave no mesh: the message of its error.
    pub(super) fn why_no_triangles(&self) -> String {
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
pub(super) struct FaceGroup {
    /// The `o` or `g` name.
    pub(super) object: String,
    /// The `usemtl` name (`None` before any `usemtl`, or after an empty one).
    pub(super) material: Option<String>,
    /// The mesh's vertices: each distinct (position, texture coordinate, normal) index
    /// triple its faces use, 0-based, [`NONE`] for an absent index.
    pub(super) vertices: Vec<[u32; 3]>,
    /// Index triple → its vertex.
    pub(super) lookup: HashMap<[u32; 3], u32>,
    /// Triangles as indices into `vertices`.
    pub(super) triangles: Vec<[u32; 3]>,
}

impl FaceGroup {
    /// The vertex of `corner`, added on first use.
    pub(super) fn vertex(&mut self, corner: [u32; 3]) -> u32 {
        let vertices = &mut self.vertices;
        *self.lookup.entry(corner).or_insert_with(|| {
            vertices.push(corner);
            (vertices.len() - 1) as u32
        })
    }

    /// The group's geometry for the checks of
    /// [`finish_mesh`](crate::scene::import::mesh::finish_mesh): an attribute that only
    /// some vertices have is passed short, which drops it with a warning.
    pub(super) fn into_raw_mesh(self, file: &ObjFile) -> RawMesh {
        /// The values of attribute `slot` (1 texture coordinates, 2 normals) of the
        /// vertices that have one, `None` when none has.
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
