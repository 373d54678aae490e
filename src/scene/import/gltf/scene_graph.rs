//! The scene graph: the default scene's node trees walked parents first, each node's
//! transform composed with its parents', placing meshes, cameras and lights.

use glam::{DMat4, DQuat, DVec3};

use super::importer::{Importer, describe, quote_list};
use super::instancing::GPU_INSTANCING;
use crate::scene::SceneError;

/// How far a node matrix's last row may stray from `0 0 0 1` and still count as affine:
/// rounding in a writer's arithmetic, far below anything a renderer would show.
const AFFINE_TOLERANCE: f64 = 1e-6;

/// A node's `matrix` or translation/rotation/scale as a matrix, exactly from its `f32`s.
///
/// glTF 2.0 §3.5.3 gives a node's transform as either a matrix or TRS properties, and
/// requires a matrix to decompose into TRS. So a matrix given together with TRS
/// properties that are not the identity is an error (readers disagree on which
/// applies), as is a projective matrix (last row not `0 0 0 1`, which an affine
/// transform would silently drop). A sheared matrix is applied as it is.
fn local_transform(node: &::gltf::json::Node) -> Result<DMat4, String> {
    if let Some(matrix) = node.matrix {
        let mut trs = Vec::new();
        if node.translation.is_some_and(|t| t != [0.0; 3]) {
            trs.push("translation");
        }
        if node.rotation.is_some_and(|r| r.0 != [0.0, 0.0, 0.0, 1.0]) {
            trs.push("rotation");
        }
        if node.scale.is_some_and(|s| s != [1.0; 3]) {
            trs.push("scale");
        }
        if !trs.is_empty() {
            return Err(format!(
                "it has both a matrix and {} (glTF 2.0 §3.5.3: a node's transform is a matrix or translation/rotation/scale, not both); which applies is ambiguous",
                trs.join(", ")
            ));
        }
        let matrix = DMat4::from_cols_array(&matrix.map(f64::from));
        if !matrix.is_finite() {
            return Err("its matrix has a component that is not finite".into());
        }
        let last_row = matrix.row(3);
        if (last_row - glam::DVec4::W).abs().max_element() > AFFINE_TOLERANCE {
            return Err(format!(
                "its matrix's last row is {last_row}, not [0, 0, 0, 1]: a projective transform, which glTF 2.0 §3.5.3 does not allow (a node's matrix must decompose into translation, rotation and scale)"
            ));
        }
        // Within the tolerance, the last row is rounding: it is made exact.
        return Ok(DMat4::from_cols(
            matrix.x_axis.truncate().extend(0.0),
            matrix.y_axis.truncate().extend(0.0),
            matrix.z_axis.truncate().extend(0.0),
            matrix.w_axis.truncate().extend(1.0),
        ));
    }
    let [x, y, z, w] = node
        .rotation
        .map_or([0.0, 0.0, 0.0, 1.0], |r| r.0)
        .map(f64::from);
    let rotation = DQuat::from_xyzw(x, y, z, w);
    let length = rotation.length();
    if !length.is_finite() || length == 0.0 {
        return Err(format!(
            "its rotation quaternion {rotation} is not a rotation"
        ));
    }
    let translation = DVec3::from_array(node.translation.unwrap_or([0.0; 3]).map(f64::from));
    let scale = DVec3::from_array(node.scale.unwrap_or([1.0; 3]).map(f64::from));
    if !translation.is_finite() || !scale.is_finite() {
        return Err("its translation or scale has a component that is not finite".into());
    }
    Ok(DMat4::from_scale_rotation_translation(
        scale,
        rotation / length,
        translation,
    ))
}

impl Importer<'_> {
    /// Walks the scene's node trees, parents before children, composing transforms, and
    /// imports the meshes, lights and camera they place.
    pub(super) fn import(&mut self) -> Result<(), SceneError> {
        let document = self.document;
        let scene = document
            .default_scene()
            .or_else(|| document.scenes().next());
        let roots: Vec<::gltf::Node<'_>> = match &scene {
            Some(scene) => {
                if document.scenes().len() > 1 {
                    self.warn(format!(
                        "the file has {} scenes; only {} is imported",
                        document.scenes().len(),
                        describe("scene", scene.index(), scene.name())
                    ));
                }
                scene.nodes().collect()
            }
            None => {
                // No scene: every node that is nobody's child is a root.
                let mut child = vec![false; document.nodes().len()];
                for node in document.nodes() {
                    for c in node.children() {
                        child[c.index()] = true;
                    }
                }
                document.nodes().filter(|n| !child[n.index()]).collect()
            }
        };
        if document.animations().len() > 0 {
            self.warn("animations are ignored: the nodes' static transforms are imported".into());
        }
        let mut visited = vec![false; document.nodes().len()];
        let mut placements: Vec<Vec<DMat4>> = vec![Vec::new(); document.meshes().len()];
        let mut stack: Vec<(::gltf::Node<'_>, DMat4)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        while let Some((node, parent)) = stack.pop() {
            let name = describe("node", node.index(), node.name());
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(self.fail(format!(
                    "{name} is reached twice: it has two parents or is its own ancestor (glTF nodes form trees, §3.5.2)"
                )));
            }
            let local = local_transform(&document.as_json().nodes[node.index()])
                .map_err(|e| self.fail(format!("{name}: {e}")))?;
            let world = parent * local;
            if !world.is_finite() {
                return Err(self.fail(format!(
                    "{name}: its transform composed with its parents' is not finite"
                )));
            }
            if let Some(mesh) = node.mesh() {
                let placed = self.mesh_placements(&node, &name, world)?;
                placements[mesh.index()].extend(placed);
            } else if node.extension_value(GPU_INSTANCING).is_some() {
                self.warn(format!(
                    "{name}: {GPU_INSTANCING} on a node without a mesh, which the extension gives no meaning; ignored"
                ));
            }
            if let Some(camera) = node.camera() {
                self.camera(&camera, &name, world)?;
            }
            if let Some(light) = node.light() {
                self.light(&light, &name, world)?;
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world));
            }
        }
        for mesh in document.meshes() {
            let instances = std::mem::take(&mut placements[mesh.index()]);
            if !instances.is_empty() {
                self.mesh(&mesh, instances)?;
            }
        }
        if !self.vertex_colors.is_empty() {
            // COLOR_0 multiplies the base colour (glTF 2.0 §3.9.2); further sets have no
            // meaning the specification gives.
            self.warn(format!(
                "only COLOR_0 multiplies the base colour; further vertex colour sets are ignored ({})",
                quote_list(&self.vertex_colors, "; ")
            ));
        }
        if self.not_triangles.is_empty() {
            return Ok(());
        }
        let count = self.not_triangles.len();
        let list = quote_list(&self.not_triangles, "; ");
        if self.model.meshes.is_empty() {
            return Err(self.fail(format!(
                "no triangles: the primitives it places are points or lines, which are not rendered ({list}){}",
                if self.triangle_primitives > 0 {
                    ", and the triangles of the others are all degenerate"
                } else {
                    ""
                }
            )));
        }
        self.warn(format!(
            "skipped {count} primitive{} of points or lines, which are not rendered: {list}",
            if count == 1 { "" } else { "s" }
        ));
        Ok(())
    }

    /// Where `node` (described by `name`, at `world`) places its mesh: at its world
    /// transform, or at each of its `EXT_mesh_gpu_instancing` instances composed after
    /// it. Singular placements (a scale of 0) are left out with a warning.
    fn mesh_placements(
        &mut self,
        node: &::gltf::Node<'_>,
        name: &str,
        world: DMat4,
    ) -> Result<Vec<DMat4>, SceneError> {
        if node.skin().is_some() {
            self.warn_once(
                "skin",
                "skins are ignored: skinned meshes are placed by their nodes' transforms in the bind pose".into(),
            );
        }
        let singular = |m: &DMat4| m.determinant() == 0.0 || !m.inverse().is_finite();
        let Some(instances) = self.gpu_instances(node, name)? else {
            if singular(&world) {
                self.warn(format!(
                    "{name}: its transform is singular (a scale of 0?); its mesh is not placed"
                ));
                return Ok(Vec::new());
            }
            return Ok(vec![world]);
        };
        let total = instances.len();
        let placed: Vec<DMat4> = instances
            .into_iter()
            .map(|instance| world * instance)
            .filter(|m| m.is_finite() && !singular(m))
            .collect();
        if placed.len() < total {
            self.warn(format!(
                "{name}: {} of its {total} {GPU_INSTANCING} instances have a singular or unbounded transform (a scale of 0?); they are not placed",
                total - placed.len()
            ));
        }
        Ok(placed)
    }
}
