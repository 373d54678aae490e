//! Checks shared by the importers: finite vertices, triangle indices in range, degenerate
//! triangles, unit normals, and the model-wide size limits.

use std::path::Path;

use glam::{DVec2, DVec3};

use crate::echo::{short, short3};
use crate::scene::SceneError;

use super::{
    ImportedMesh, MAX_MODEL_INSTANCES, MAX_MODEL_TEXELS, MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES,
};

/// A vertex colour as messages quote it: each channel in at most about 24 characters
/// ([`short`]), so that 1e38 is not spelt out in 39 digits.
fn short4(color: glam::DVec4) -> String {
    format!(
        "[{}, {}, {}, {}]",
        short(color.x),
        short(color.y),
        short(color.z),
        short(color.w)
    )
}

/// Twice the area, relative to the squared longest edge, below which a triangle counts
/// as degenerate: the scene format's rule (`src/scene/file/objects.rs`).
const DEGENERACY_TOLERANCE: f64 = 1e-12;

/// Whether a triangle has (nearly) no area relative to its longest edge, or a coordinate
/// that is not finite.
pub(super) fn is_degenerate([a, b, c]: [DVec3; 3]) -> bool {
    let longest = (b - a)
        .length_squared()
        .max((c - b).length_squared())
        .max((a - c).length_squared());
    let twice_area = (b - a).cross(c - a).length();
    // Written so that NaN counts as degenerate.
    twice_area.partial_cmp(&(DEGENERACY_TOLERANCE * longest)) != Some(std::cmp::Ordering::Greater)
}

/// The box around a mesh's positions in its own space.
pub(super) fn local_bounds(mesh: &ImportedMesh) -> Option<(DVec3, DVec3)> {
    let first = *mesh.positions.first()?;
    Some(
        mesh.positions
            .iter()
            .fold((first, first), |(low, high), p| (low.min(*p), high.max(*p))),
    )
}

/// Geometry as read from a file, before the checks.
pub(super) struct RawMesh {
    pub positions: Vec<DVec3>,
    pub normals: Option<Vec<DVec3>>,
    pub uvs: Option<Vec<DVec2>>,
    pub uvs1: Option<Vec<DVec2>>,
    pub colors: Option<Vec<glam::DVec4>>,
    pub tangents: Option<Vec<glam::DVec4>>,
    pub triangles: Vec<[u32; 3]>,
}

/// Checks `raw` and makes it a mesh named `name`, read from `file`. Fails (with a message
/// naming the mesh, which the caller reports against the file) on a non-finite position
/// or an index out of range; drops normals or UVs that are not usable and skips
/// degenerate triangles, saying so in `warnings`. Returns `None` (with a warning) when no
/// triangle is left.
pub(super) fn finish_mesh(
    name: String,
    file: &std::path::Path,
    raw: RawMesh,
    material: u32,
    warnings: &mut Vec<String>,
) -> Result<Option<ImportedMesh>, String> {
    let RawMesh {
        positions,
        normals,
        uvs,
        uvs1,
        colors,
        tangents,
        triangles,
    } = raw;
    let mut warn = |message: String| warnings.push(format!("{}: {message}", file.display()));
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            "{name}: vertex {i} has a position that is not a finite number ({})",
            positions[i]
        ));
    }
    let count = positions.len();
    let normals = normals.and_then(|normals| {
        if normals.len() != count {
            warn(format!(
                "{name}: {} normals for {count} vertices; the normals are ignored",
                normals.len()
            ));
            return None;
        }
        let unit: Vec<DVec3> = normals.iter().map(|n| n.normalize_or_zero()).collect();
        match unit.iter().position(|n| *n == DVec3::ZERO) {
            Some(i) => {
                warn(format!(
                    "{name}: the normal of vertex {i} is zero or not finite ({}); the normals are ignored",
                    short3(normals[i])
                ));
                None
            }
            None => Some(unit),
        }
    });
    let mut check_uvs = |uvs: Option<Vec<DVec2>>, what: &str| {
        uvs.and_then(|uvs| {
            if uvs.len() != count {
                warn(format!(
                    "{name}: {} {what} for {count} vertices; the {what} are ignored",
                    uvs.len()
                ));
                return None;
            }
            match uvs.iter().position(|uv| !uv.is_finite()) {
                Some(i) => {
                    warn(format!(
                        "{name}: the {what} of vertex {i} are not finite ({}); the {what} are ignored",
                        uvs[i]
                    ));
                    None
                }
                None => Some(uvs),
            }
        })
    };
    let uvs = check_uvs(uvs, "texture coordinates");
    let uvs1 = check_uvs(uvs1, "second texture coordinates");
    let colors = colors.and_then(|colors| {
        if colors.len() != count {
            warn(format!(
                "{name}: {} vertex colours for {count} vertices; the vertex colours are ignored",
                colors.len()
            ));
            return None;
        }
        if let Some(i) = colors.iter().position(|c| c.is_nan()) {
            warn(format!(
                "{name}: the colour of vertex {i} is not a number ({}); the vertex colours are ignored",
                short4(colors[i])
            ));
            return None;
        }
        // Colours are reflectances: outside [0, 1] a surface would reflect more light
        // than it receives (or less than none).
        let outside = colors
            .iter()
            .filter(|c| c.min_element() < 0.0 || c.max_element() > 1.0)
            .count();
        if outside > 0 {
            warn(format!(
                "{name}: {outside} vertex colour{} outside [0, 1] (the first at vertex {}: {}); clamped",
                if outside == 1 { "" } else { "s" },
                colors
                    .iter()
                    .position(|c| c.min_element() < 0.0 || c.max_element() > 1.0)
                    .unwrap_or(0),
                short4(
                    colors
                        .iter()
                        .find(|c| c.min_element() < 0.0 || c.max_element() > 1.0)
                        .copied()
                        .unwrap_or_default()
                ),
            ));
        }
        Some(
            colors
                .into_iter()
                .map(|c| c.clamp(glam::DVec4::ZERO, glam::DVec4::ONE))
                .collect(),
        )
    });
    let tangents = tangents.and_then(|tangents| {
        if tangents.len() != count {
            warn(format!(
                "{name}: {} tangents for {count} vertices; the tangents are ignored (the normal map with them)",
                tangents.len()
            ));
            return None;
        }
        // Unit xyz and w = ±1 (glTF 2.0 §3.7.2.1); a zero or non-finite tangent
        // leaves its vertex without a normal map rather than the whole mesh.
        let usable = |t: &glam::DVec4| t.is_finite() && t.truncate().length_squared() > 0.0;
        let bad = tangents.iter().filter(|t| !usable(t)).count();
        if bad > 0 {
            warn(format!(
                "{name}: {bad} tangent{} zero or not finite; the normal map is not applied there",
                if bad == 1 { " is" } else { "s are" }
            ));
        }
        Some(
            tangents
                .into_iter()
                .map(|t| {
                    if usable(&t) {
                        let w = if t.w < 0.0 { -1.0 } else { 1.0 };
                        t.truncate().normalize_or_zero().extend(w)
                    } else {
                        glam::DVec4::ZERO
                    }
                })
                .collect(),
        )
    });
    let total = triangles.len();
    let mut kept = Vec::with_capacity(total);
    for (t, triangle) in triangles.into_iter().enumerate() {
        if let Some(&index) = triangle.iter().find(|&&i| i as usize >= count) {
            return Err(format!(
                "{name}: triangle {t} refers to vertex {index}, but there are only {count} vertices"
            ));
        }
        if !is_degenerate(triangle.map(|i| positions[i as usize])) {
            kept.push(triangle);
        }
    }
    let skipped = total - kept.len();
    if kept.is_empty() {
        warn(if total == 0 {
            format!("{name}: no triangles; skipped")
        } else {
            format!("{name}: all {total} triangles are degenerate; skipped")
        });
        return Ok(None);
    }
    if skipped > 0 {
        warn(format!(
            "{name}: skipped {skipped} degenerate triangle{} (of {total}): (nearly) no area",
            if skipped == 1 { "" } else { "s" }
        ));
    }
    Ok(Some(ImportedMesh {
        name,
        positions,
        normals,
        uvs,
        uvs1,
        colors,
        tangents,
        triangles: kept,
        material,
        instances: vec![glam::DMat4::IDENTITY],
    }))
}

/// Bytes an imported vertex may hold: its position and normal (`DVec3`, 24 bytes
/// each) and texture coordinates (`DVec2`, 16 bytes). Vertex colours and a second set
/// of texture coordinates, which few meshes have, are not counted.
pub(super) const BYTES_PER_VERTEX: u64 = 64;
/// Bytes of an imported triangle (three `u32` indices).
pub(super) const BYTES_PER_TRIANGLE: u64 = 12;

/// The model-wide totals, checked against the limits as the importers go: the fixed
/// limits on counts, and the caller's cap on the bytes the import holds
/// ([`super::ImportOptions::max_bytes`]).
#[derive(Debug, Default)]
pub(super) struct Budget {
    vertices: usize,
    triangles: usize,
    instances: usize,
    texels: u64,
    bytes: u64,
    max_bytes: Option<u64>,
}

/// A model beyond the import's limits: a fixed count limit or the memory cap
/// (`--max-memory`); the message says which, and by how much.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub(super) struct LimitExceeded(pub String);

impl LimitExceeded {
    /// The [`SceneError::TooLarge`] of the model `path`.
    pub fn at(self, path: &Path) -> SceneError {
        SceneError::too_large(path, None, self.0)
    }
}

impl From<LimitExceeded> for String {
    fn from(limit: LimitExceeded) -> Self {
        limit.0
    }
}

impl Budget {
    /// A budget capped at `max_bytes` (none: the fixed count limits only).
    pub fn new(max_bytes: Option<u64>) -> Self {
        Self {
            max_bytes,
            ..Self::default()
        }
    }

    /// The bytes the budget still allows, if it is capped.
    pub fn bytes_left(&self) -> Option<u64> {
        self.max_bytes.map(|max| max.saturating_sub(self.bytes))
    }

    /// Counts `bytes` more held by the import (`what` names them in the message), before
    /// they are allocated where the caller can.
    pub fn charge_bytes(&mut self, bytes: u64, what: &str) -> Result<(), LimitExceeded> {
        self.bytes = self.bytes.saturating_add(bytes);
        match self.max_bytes {
            Some(max) if self.bytes > max => {
                Err(LimitExceeded(memory_cap_message(self.bytes, max, what)))
            }
            _ => Ok(()),
        }
    }

    /// Counts a mesh of `vertices` vertices and `triangles` triangles (before it is read,
    /// so that an absurd count is refused without allocating).
    pub fn charge_mesh(&mut self, vertices: usize, triangles: usize) -> Result<(), LimitExceeded> {
        self.charge_bytes(
            (vertices as u64).saturating_mul(BYTES_PER_VERTEX)
                + (triangles as u64).saturating_mul(BYTES_PER_TRIANGLE),
            "its meshes",
        )?;
        self.vertices = self.vertices.saturating_add(vertices);
        self.triangles = self.triangles.saturating_add(triangles);
        if self.vertices > MAX_MODEL_VERTICES {
            return Err(LimitExceeded(format!(
                "the model has more than {MAX_MODEL_VERTICES} vertices, more than accepted"
            )));
        }
        if self.triangles > MAX_MODEL_TRIANGLES {
            return Err(LimitExceeded(format!(
                "the model has more than {MAX_MODEL_TRIANGLES} triangles, more than accepted"
            )));
        }
        Ok(())
    }

    /// Counts `count` more placements of meshes.
    pub fn charge_instances(&mut self, count: usize) -> Result<(), LimitExceeded> {
        self.instances = self.instances.saturating_add(count);
        if self.instances > MAX_MODEL_INSTANCES {
            return Err(LimitExceeded(format!(
                "the model places meshes more than {MAX_MODEL_INSTANCES} times, more than accepted"
            )));
        }
        Ok(())
    }

    /// Refuses `bytes` held for a moment (a texture's decoding, beside what it keeps)
    /// when they do not fit in what the cap leaves; counts nothing.
    pub fn check_transient(&self, bytes: u64, what: &str) -> Result<(), LimitExceeded> {
        match self.max_bytes {
            Some(max) if self.bytes.saturating_add(bytes) > max => Err(LimitExceeded(
                memory_cap_message(self.bytes.saturating_add(bytes), max, what),
            )),
            _ => Ok(()),
        }
    }

    /// Counts a texture of `width × height` texels.
    pub fn charge_texels(&mut self, width: u32, height: u32) -> Result<(), LimitExceeded> {
        let texels = u64::from(width) * u64::from(height);
        self.charge_bytes(
            texels.saturating_mul(crate::scene::DECODED_BYTES_PER_TEXEL),
            "its textures",
        )?;
        self.texels = self
            .texels
            .saturating_add(u64::from(width) * u64::from(height));
        if self.texels > MAX_MODEL_TEXELS {
            return Err(LimitExceeded(format!(
                "the model's textures hold more than {MAX_MODEL_TEXELS} texels, more than accepted"
            )));
        }
        Ok(())
    }
}

/// The message for an import that needs `bytes` with `what`, more than the cap `max`.
pub(super) fn memory_cap_message(bytes: u64, max: u64, what: &str) -> String {
    format!(
        "reading the model with {what} needs at least {} of memory, more than the {} \
         allowed (--max-memory); raise the cap if the machine has the memory",
        crate::echo::bytes(bytes),
        crate::echo::bytes(max)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> RawMesh {
        RawMesh {
            positions,
            normals: None,
            uvs: None,
            uvs1: None,
            colors: None,
            tangents: None,
            triangles,
        }
    }

    #[test]
    fn degenerate_triangles_are_skipped_and_counted() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X * 2.0];
        let mut warnings = Vec::new();
        let mesh = finish_mesh(
            "m".into(),
            std::path::Path::new("f"),
            raw(p, vec![[0, 1, 2], [0, 1, 3], [2, 2, 1]]),
            0,
            &mut warnings,
        )
        .expect("valid")
        .expect("one triangle left");
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("skipped 2 degenerate triangles (of 3)"));
    }

    #[test]
    fn an_index_out_of_range_is_an_error() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        let e = finish_mesh(
            "m".into(),
            std::path::Path::new("f"),
            raw(p, vec![[0, 1, 3]]),
            0,
            &mut Vec::new(),
        )
        .expect_err("index 3 of 3 vertices");
        assert!(e.contains("triangle 0 refers to vertex 3"), "{e}");
    }

    #[test]
    fn a_nan_position_is_an_error() {
        let p = vec![DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Y];
        let e = finish_mesh(
            "m".into(),
            std::path::Path::new("f"),
            raw(p, vec![[0, 1, 2]]),
            0,
            &mut Vec::new(),
        )
        .expect_err("NaN");
        assert!(e.contains("vertex 1"), "{e}");
    }

    #[test]
    fn zero_normals_are_dropped_with_a_warning() {
        let mut mesh = raw(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        mesh.normals = Some(vec![DVec3::Z, DVec3::ZERO, DVec3::Z * 3.0]);
        let mut warnings = Vec::new();
        let mesh = finish_mesh(
            "m".into(),
            std::path::Path::new("f"),
            mesh,
            0,
            &mut warnings,
        )
        .expect("valid")
        .expect("kept");
        assert!(mesh.normals.is_none());
        assert!(warnings[0].contains("vertex 1"), "{warnings:?}");
    }
}
