//! Tangents for normal maps where a glTF primitive has none: MikkTSpace (Mikkelsen,
//! "Simulation of Wrinkled Surfaces Revisited", 2008), which glTF 2.0 §3.7.2.1
//! prescribes ("client implementations SHOULD calculate tangents using default
//! MikkTSpace algorithms with the specified vertex positions, normals, and texture
//! coordinates associated with the normal texture"), through the `mikktspace` crate.

use std::collections::HashMap;

use glam::{DVec2, DVec3, DVec4};

use super::mesh::RawMesh;
use crate::scene::TextureTransform;

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
pub(super) fn with_mikktspace_tangents(raw: &RawMesh, uvs: &[DVec2]) -> Option<RawMesh> {
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

/// `raw` flat-shaded, as glTF 2.0 §3.7.2.1 asks of a primitive without `NORMAL`
/// ("client implementations MUST calculate flat normals and the provided tangents (if
/// present) MUST be ignored"): every triangle its own three vertices, each with the
/// triangle's winding normal (zero for a degenerate one, which `finish_mesh` skips),
/// its other attributes copied, no tangents. `None` where an index is out of range
/// (`finish_mesh` reports it).
pub(super) fn with_flat_normals(raw: &RawMesh) -> Option<RawMesh> {
    let count = raw.positions.len();
    if raw.triangles.iter().flatten().any(|&i| i as usize >= count) {
        return None;
    }
    let corners: Vec<usize> = raw
        .triangles
        .iter()
        .flatten()
        .map(|&i| i as usize)
        .collect();
    let normals = raw
        .triangles
        .iter()
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| raw.positions[i as usize]);
            [(b - a).cross(c - a).normalize_or_zero(); 3]
        })
        .collect();
    let pick = |values: &[DVec3]| corners.iter().map(|&i| values[i]).collect::<Vec<_>>();
    let pick2 = |values: &[DVec2]| corners.iter().map(|&i| values[i]).collect::<Vec<_>>();
    let short = |len: usize| len != count;
    Some(RawMesh {
        positions: pick(&raw.positions),
        normals: Some(normals),
        uvs: raw.uvs.as_deref().filter(|v| !short(v.len())).map(pick2),
        uvs1: raw.uvs1.as_deref().filter(|v| !short(v.len())).map(pick2),
        colors: raw
            .colors
            .as_deref()
            .filter(|v| !short(v.len()))
            .map(|values| corners.iter().map(|&i| values[i]).collect()),
        tangents: None,
        triangles: (0..raw.triangles.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect(),
    })
}

/// Turns `tangents` (`TANGENT`'s, along the mesh's own texture coordinates) into the
/// axes of a normal map read through `transform` (`KHR_texture_transform`), at vertices
/// of unit-length `normals`. The map's `x` and `y` run along increasing `u'` and
/// decreasing `v'` of the transformed coordinates `(u', v') = L·(u, v) + offset`; with
/// the given frame `T = ∂P/∂x`, `B = w·(N × T) = ∂P/∂y` (glTF 2.0 §3.7.2.1) and `L` in
/// image axes, `L_img = F·L·F` with `F = diag(1, −1)`, the chain rule gives
/// `(∂P/∂x', ∂P/∂y') = (T, B)·L_img⁻¹`. The new tangent is `∂P/∂x'` made orthogonal to
/// `N` and normalized, its handedness the sign of `(N × T')·∂P/∂y'`: exact for a
/// rotation, a uniform scale and any mirror, which keep the axes orthogonal (the frame
/// stays orthonormal, as MikkTSpace's does, under the rest). A transform that is an
/// offset only leaves them as they are; so does a singular one (a zero scale: the map
/// then reads one texel, whatever the frame).
pub(super) fn follow_texture_transform(
    tangents: &mut [DVec4],
    normals: &[DVec3],
    transform: &TextureTransform,
) {
    if transform.is_linear_identity() {
        return;
    }
    let [r0, r1] = transform.rows;
    let determinant = r0.x * r1.y - r0.y * r1.x;
    if determinant == 0.0 || !determinant.is_finite() {
        return;
    }
    for (tangent, &normal) in tangents.iter_mut().zip(normals) {
        let along = tangent.truncate();
        let bitangent = normal.cross(along) * if tangent.w < 0.0 { -1.0 } else { 1.0 };
        // Columns of L_img⁻¹ = [[r11, r01], [r10, r00]] / det.
        let x_axis = (along * r1.y + bitangent * r1.x) / determinant;
        let y_axis = (along * r0.y + bitangent * r0.x) / determinant;
        let in_plane = x_axis - normal * normal.dot(x_axis);
        let length = in_plane.length();
        if !(length > 0.0 && length.is_finite()) {
            continue;
        }
        let turned = in_plane / length;
        let handedness = if normal.cross(turned).dot(y_axis) < 0.0 {
            -1.0
        } else {
            1.0
        };
        *tangent = turned.extend(handedness);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: DVec3 = DVec3::Z;

    fn followed(tangent: DVec4, transform: TextureTransform) -> DVec4 {
        let mut tangents = [tangent];
        follow_texture_transform(&mut tangents, &[N], &transform);
        tangents[0]
    }

    fn assert_close(a: DVec4, b: DVec4) {
        assert!((a - b).abs().max_element() < 1e-12, "{a} against {b}");
    }

    #[test]
    fn flat_normals_split_the_vertices_of_a_fold() {
        // Two triangles folded along their shared edge (x = 0..1 at y = z = 0).
        let raw = RawMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, -1.0)],
            normals: None,
            uvs: Some(vec![DVec2::ZERO, DVec2::X, DVec2::Y, DVec2::ONE]),
            uvs1: None,
            colors: None,
            tangents: Some(vec![DVec4::X; 4]),
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        };
        let flat = with_flat_normals(&raw).expect("in range");
        assert_eq!(flat.positions.len(), 6);
        assert_eq!(flat.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        let normals = flat.normals.expect("normals");
        assert_eq!(&normals[..3], &[DVec3::Z; 3]);
        assert_eq!(&normals[3..], &[DVec3::NEG_Y; 3]);
        assert_eq!(flat.uvs.expect("uvs")[5], DVec2::ONE);
        assert!(flat.tangents.is_none(), "TANGENT without NORMAL is ignored");
        let broken = RawMesh {
            triangles: vec![[0, 1, 9]],
            ..raw
        };
        assert!(with_flat_normals(&broken).is_none());
    }

    #[test]
    fn a_quarter_turn_turns_the_frame_the_other_way() {
        // u' = v, v' = −u: the map's x (increasing u') runs along increasing v, which is
        // −B (B points up the image, against v); its y (decreasing v') along +u, +T.
        let quarter = TextureTransform::offset_rotation_scale(
            0,
            DVec2::ZERO,
            std::f64::consts::FRAC_PI_2,
            DVec2::ONE,
        );
        let t = DVec4::new(1.0, 0.0, 0.0, 1.0);
        assert_close(followed(t, quarter), DVec4::new(0.0, -1.0, 0.0, 1.0));
        // A left-handed frame (B = −y): the map's x along −B = +y.
        let mirrored = DVec4::new(1.0, 0.0, 0.0, -1.0);
        assert_close(followed(mirrored, quarter), DVec4::new(0.0, 1.0, 0.0, -1.0));
    }

    #[test]
    fn a_mirroring_scale_flips_the_handedness_only() {
        // SheenCloth's scale [30, −30]: the map's x still along T, its y against B.
        let scale =
            TextureTransform::offset_rotation_scale(0, DVec2::ZERO, 0.0, DVec2::new(30.0, -30.0));
        let t = DVec4::new(0.0, 1.0, 0.0, 1.0);
        assert_close(followed(t, scale), DVec4::new(0.0, 1.0, 0.0, -1.0));
    }

    #[test]
    fn offsets_and_singular_maps_leave_the_frame_alone() {
        let t = DVec4::new(0.6, 0.8, 0.0, -1.0);
        let offset =
            TextureTransform::offset_rotation_scale(1, DVec2::new(0.25, 3.0), 0.0, DVec2::ONE);
        assert_eq!(followed(t, offset), t);
        let flat =
            TextureTransform::offset_rotation_scale(0, DVec2::ZERO, 0.3, DVec2::new(0.0, 1.0));
        assert_eq!(followed(t, flat), t);
    }

    #[test]
    fn any_rotation_turns_the_frame_by_its_angle() {
        // A rotation by θ of the coordinates turns the map's axes by −θ on the surface
        // (the image turns clockwise under a counter-clockwise turn of the coordinates
        // and v runs down): here T = +x, B = +y, so T' = (cos θ, −sin θ).
        for k in 0..16 {
            let theta = f64::from(k) * 0.4 - 3.0;
            let rotation =
                TextureTransform::offset_rotation_scale(0, DVec2::ZERO, theta, DVec2::splat(2.5));
            let t = followed(DVec4::new(1.0, 0.0, 0.0, 1.0), rotation);
            assert_close(t, DVec4::new(theta.cos(), -theta.sin(), 0.0, 1.0));
        }
    }
}
