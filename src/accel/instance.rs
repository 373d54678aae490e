//! Instancing: a mesh placed more than once is stored once, in its own space, with a
//! bottom-level BVH of its own, and each placement is an [`Instance`]: an affine
//! transform pair and a material, standing in the scene's BVH as one primitive of kind
//! [`PrimKind::Instance`] bounded by its world box (a two-level BVH).
//!
//! Both tracers transform a ray that reaches an instance into the mesh's space
//! (`world_to_object`, the direction not renormalised, so that the ray parameter `t`
//! is the same in both spaces and hits of different instances compare directly), run
//! the same watertight triangle test there, and transform the hit back: the hit record
//! is made from the triangle moved to world space exactly as a flattened placement
//! would store it (corners 1 and 2 swapped under a mirroring transform, normals through
//! the inverse transpose), so an instanced mesh shades as the flattened one does.

use std::collections::HashMap;
use std::hash::{DefaultHasher, Hasher};

use glam::{DAffine3, DMat3, DMat4, DVec3, DVec4};

use super::bvh::{Aabb32, BuildMethod, Bvh};
use super::geometry::{PrimKind, PrimRef, TriangleAttributes, TriangleShape};
use crate::scene::Mesh;

/// Which placement of which mesh a surface belongs to: `None` for the scene's own
/// (flattened) primitives, `Some(i)` for entry `i` of [`super::SceneGeometry::instances`].
pub type InstanceId = Option<u32>;

/// A surface a ray can hit: a primitive and, for an instanced mesh's triangle (then an
/// index into its [`InstancedMesh::triangles`]), the instance it was hit in.
///
/// It is also the tie-break key of both tracers: of two hits at exactly the same
/// distance the smaller key wins, ordered by instance first (the scene's own
/// primitives, `None`, after every instance), then by primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HitKey {
    /// The primitive (for an instance: a [`PrimKind::Triangle`] of its mesh).
    pub prim: PrimRef,
    /// The instance, if any.
    pub instance: InstanceId,
}

impl HitKey {
    /// The key of one of the scene's own primitives.
    pub fn world(prim: PrimRef) -> Self {
        Self {
            prim,
            instance: None,
        }
    }

    /// `(instance or u32::MAX, prim)`: the order both tracers compare.
    fn order(&self) -> (u32, PrimRef) {
        (self.instance.unwrap_or(u32::MAX), self.prim)
    }
}

impl PartialOrd for HitKey {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for HitKey {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.order().cmp(&other.order())
    }
}

/// A mesh stored once for all its placements: its triangles in its own space, their
/// shading attributes, and the bottom-level BVH over them.
#[derive(Debug, Clone)]
pub struct InstancedMesh {
    /// The scene mesh it came from (the first of identical ones), for messages.
    pub name: String,
    /// Triangles in the mesh's own space, in mesh order (those without area left out);
    /// `material` is the first placement's (each instance has its own).
    pub triangles: Vec<TriangleShape>,
    /// Object-space shading attributes, indexed by [`TriangleShape::attributes`].
    pub triangle_attributes: Vec<TriangleAttributes>,
    /// The hierarchy over `triangles` ([`PrimKind::Triangle`] references into them).
    pub bvh: Bvh,
}

/// One placement of an [`InstancedMesh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Index into [`super::SceneGeometry::instanced_meshes`].
    pub mesh: u32,
    /// Mesh-to-world transform (affine, invertible).
    pub object_to_world: DAffine3,
    /// Its inverse.
    pub world_to_object: DAffine3,
    /// The inverse transpose of the linear part: how normals go to world space.
    pub normal_matrix: DMat3,
    /// Whether the transform mirrors (negative determinant): the winding of its
    /// triangles is reversed in world space, as a flattened placement stores it.
    pub mirrored: bool,
    /// Material index of every triangle of this placement.
    pub material: u32,
    /// The world box: around the mesh's [`InstancedMesh::hull_points`] moved to world
    /// space (as tight as the transformed vertices near the root of the mesh's tree,
    /// and never smaller than the transformed mesh).
    pub bounds: Aabb32,
}

impl Instance {
    /// The instance of `mesh` under `transform` (finite and invertible, as validated
    /// meshes' instances are) with `material`; `hull_points` are the mesh's
    /// [`InstancedMesh::hull_points`] (at least one), whose convex hull contains it.
    pub fn new(mesh: u32, transform: &DMat4, material: u32, hull_points: &[DVec3]) -> Self {
        let object_to_world = DAffine3::from_mat4(*transform);
        let world_to_object = object_to_world.inverse();
        let linear = object_to_world.matrix3;
        // An affine map keeps convex hulls: the box around the moved points holds the
        // moved mesh.
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for p in hull_points {
            let p = object_to_world.transform_point3(*p);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Self {
            mesh,
            object_to_world,
            world_to_object,
            normal_matrix: linear.inverse().transpose(),
            mirrored: linear.determinant() < 0.0,
            material,
            bounds: Aabb32::around(lo, hi),
        }
    }

    /// The corner order of a triangle of this instance in world space: corners 1 and
    /// 2 swapped when the transform mirrors, which keeps the winding normal facing out.
    pub fn corner_order(&self) -> [usize; 3] {
        if self.mirrored { [0, 2, 1] } else { [0, 1, 2] }
    }

    /// Triangle `index` of `mesh` moved to world space as a flattened placement stores
    /// it (corner order of [`Instance::corner_order`], this instance's material), with
    /// its world-space attributes (normals through the normal matrix, normalised; one
    /// that vanishes becomes the triangle's facing).
    pub fn world_triangle(
        &self,
        mesh: &InstancedMesh,
        index: usize,
    ) -> (TriangleShape, Option<TriangleAttributes>) {
        let triangle = &mesh.triangles[index];
        let order = self.corner_order();
        let vertices = order.map(|k| self.object_to_world.transform_point3(triangle.vertices[k]));
        let facing = (vertices[1] - vertices[0])
            .cross(vertices[2] - vertices[0])
            .normalize_or_zero();
        let attributes = triangle.attributes.map(|a| {
            let object = &mesh.triangle_attributes[a as usize];
            TriangleAttributes {
                normals: object
                    .normals
                    .map(|n| order.map(|k| (self.normal_matrix * n[k]).normalize_or(facing))),
                uvs: object.uvs.map(|uv| order.map(|k| uv[k])),
                uvs1: object.uvs1.map(|uv| order.map(|k| uv[k])),
                colors: object.colors.map(|c| order.map(|k| c[k])),
                tangents: object
                    .tangents
                    .map(|t| order.map(|k| world_tangent(&self.object_to_world.matrix3, t[k]))),
            }
        });
        (
            TriangleShape {
                vertices,
                material: self.material,
                attributes: triangle.attributes,
            },
            attributes,
        )
    }
}

/// The most nodes of a mesh's tree whose boxes stand for their subtrees in
/// [`InstancedMesh::hull_points`].
pub const MAX_HULL_NODES: usize = 512;

impl InstancedMesh {
    /// Points whose convex hull contains every triangle of the mesh, from which each
    /// instance's world box is made: the tree is opened level by level from the root
    /// while at most [`MAX_HULL_NODES`] nodes stand, and each standing node gives the
    /// vertices of its triangles if it is a leaf, else its box's eight corners. A
    /// rotated instance's box is then about as tight as the box of its moved vertices
    /// (the eight corners of the mesh's root box, moved, make a box up to √3 times as
    /// wide under rotation), at a cost per instance that does not grow with the mesh.
    pub fn hull_points(&self) -> Vec<DVec3> {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return Vec::new();
        }
        let mut standing = vec![0usize];
        loop {
            let inner = standing.iter().filter(|&&i| !nodes[i].is_leaf()).count();
            if inner == 0 || standing.len() + inner > MAX_HULL_NODES {
                break;
            }
            standing = standing
                .iter()
                .flat_map(|&i| {
                    let node = &nodes[i];
                    let first = node.first as usize;
                    if node.is_leaf() {
                        [i, usize::MAX]
                    } else {
                        [first, first + 1]
                    }
                })
                .filter(|&i| i != usize::MAX)
                .collect();
        }
        let mut points = Vec::new();
        for i in standing {
            let node = &nodes[i];
            if node.is_leaf() {
                let prims = &self.bvh.prims[node.first as usize..][..node.count as usize];
                for prim in prims {
                    points.extend_from_slice(&self.triangles[prim.index()].vertices);
                }
            } else {
                for corner in 0..8 {
                    let pick = |axis: usize| {
                        f64::from(if (corner >> axis) & 1 == 1 {
                            node.max[axis]
                        } else {
                            node.min[axis]
                        })
                    };
                    points.push(DVec3::new(pick(0), pick(1), pick(2)));
                }
            }
        }
        points
    }

    /// The mesh stored once: its triangles with area in object space (the others are
    /// counted into `degenerate`), their attributes, and the BVH over them.
    pub fn new(mesh: &Mesh, method: BuildMethod, degenerate: &mut usize) -> Self {
        let mut stored = Self {
            name: mesh.name.clone(),
            triangles: Vec::with_capacity(mesh.triangles.len()),
            triangle_attributes: Vec::new(),
            bvh: Bvh::default(),
        };
        for corners in &mesh.triangles {
            let order = corners.map(|i| i as usize);
            let vertices = order.map(|i| mesh.positions[i]);
            let area = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
            if !(area.length_squared() > 0.0 && area.is_finite()) {
                *degenerate += 1;
                continue;
            }
            let normals = mesh
                .normals
                .as_ref()
                .map(|normals| order.map(|i| normals[i]));
            let attributes =
                TriangleAttributes::of_corners(mesh, order, normals, None).map(|attributes| {
                    stored.triangle_attributes.push(attributes);
                    (stored.triangle_attributes.len() - 1) as u32
                });
            stored.triangles.push(TriangleShape {
                vertices,
                material: mesh.material,
                attributes,
            });
        }
        let bounds: Vec<(PrimRef, Aabb32)> = stored
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let index = u32::try_from(i).unwrap_or(PrimRef::MAX_INDEX);
                (
                    PrimRef::new(PrimKind::Triangle, index),
                    Aabb32::around_points(&t.vertices),
                )
            })
            .collect();
        stored.bvh = Bvh::build(&bounds, method);
        stored
    }
}

/// A tangent (`w`: the bitangent's handedness) moved by the linear part `linear` of an
/// object-to-world transform: the direction through it, renormalised (zero where it
/// vanishes, which disables the normal map there), the handedness flipped under a
/// mirroring transform, whose normal matrix turns `normal × tangent` around. Twin of
/// `world_tangent` in `shaders/instance.wgsl`.
pub fn world_tangent(linear: &glam::DMat3, tangent: DVec4) -> DVec4 {
    let direction = (*linear * tangent.truncate()).normalize_or_zero();
    let w = if linear.determinant() < 0.0 {
        -tangent.w
    } else {
        tangent.w
    };
    direction.extend(w)
}

/// Whether two meshes have the same geometry and attributes (the same file's same
/// mesh, placed twice): they may then share one [`InstancedMesh`].
fn same_geometry(a: &Mesh, b: &Mesh) -> bool {
    a.triangles == b.triangles
        && a.positions == b.positions
        && a.normals == b.normals
        && a.uvs == b.uvs
        && a.uvs1 == b.uvs1
        && a.colors == b.colors
        && a.tangents == b.tangents
}

/// The scene's meshes grouped by identical geometry ([`Mesh::positions`], normals,
/// texture coordinates and triangles), in the order of their first members; each
/// group lists indices into `meshes`. A hash of each mesh's whole geometry (its bits)
/// decides which pairs are compared in full, so that the time is linear in the
/// meshes' total size however many meshes there are (a file of 200,000 OBJ groups
/// makes 200,000 meshes: comparing each with every group before it took minutes).
pub fn mesh_groups(meshes: &[Mesh]) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    // Geometry hash -> the groups whose geometry has it (one, but for collisions).
    let mut by_hash: HashMap<u64, Vec<usize>> = HashMap::with_capacity(meshes.len());
    for (i, mesh) in meshes.iter().enumerate() {
        let candidates = by_hash.entry(geometry_hash(mesh)).or_default();
        let found = candidates
            .iter()
            .copied()
            .find(|&g| same_geometry(&meshes[groups[g][0]], mesh));
        match found {
            Some(g) => groups[g].push(i),
            None => {
                candidates.push(groups.len());
                groups.push(vec![i]);
            }
        }
    }
    groups
}

/// A hash of everything [`same_geometry`] compares, by bits (meshes it finds equal
/// hash equally but for signed zeros, which only costs the sharing).
fn geometry_hash(mesh: &Mesh) -> u64 {
    let mut hasher = DefaultHasher::new();
    hasher.write(bytemuck::cast_slice(&mesh.positions));
    hasher.write(bytemuck::cast_slice(&mesh.triangles));
    // The presence of each attribute is hashed too: `None` and an empty list differ.
    match &mesh.normals {
        Some(normals) => {
            hasher.write_u8(1);
            hasher.write(bytemuck::cast_slice(normals));
        }
        None => hasher.write_u8(0),
    }
    match &mesh.uvs {
        Some(uvs) => {
            hasher.write_u8(1);
            hasher.write(bytemuck::cast_slice(uvs));
        }
        None => hasher.write_u8(0),
    }
    hasher.finish()
}

/// Whether `meshes` place some geometry more than once, so that the geometry built
/// from them has instances.
pub fn has_instances(meshes: &[Mesh]) -> bool {
    mesh_groups(meshes).iter().any(|group| {
        group
            .iter()
            .map(|&i| meshes[i].instances.len())
            .sum::<usize>()
            > 1
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(instances: Vec<DMat4>) -> Mesh {
        Mesh {
            name: "quad".into(),
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            normals: Some(vec![DVec3::Z; 4]),
            uvs: None,
            uvs1: None,
            colors: None,
            tangents: None,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            material: 0,
            instances,
        }
    }

    #[test]
    fn identical_meshes_group_and_count_placements() {
        let a = quad(vec![DMat4::IDENTITY]);
        let mut b = quad(vec![DMat4::from_translation(DVec3::X)]);
        b.material = 3;
        let mut c = quad(vec![DMat4::IDENTITY]);
        c.positions[2].x = 2.0;
        let meshes = [a.clone(), b, c];
        assert_eq!(mesh_groups(&meshes), vec![vec![0, 1], vec![2]]);
        assert!(has_instances(&meshes));
        assert!(!has_instances(&meshes[2..]));
        assert!(has_instances(&[quad(vec![DMat4::IDENTITY; 2])]));
    }

    #[test]
    fn meshes_alike_but_for_an_inner_vertex_or_an_attribute_stay_apart() {
        // Same sizes, same first and last vertex: only the full comparison tells them apart.
        let a = quad(vec![DMat4::IDENTITY]);
        let mut inner = a.clone();
        inner.positions[1].y = 0.5;
        let mut no_normals = a.clone();
        no_normals.normals = None;
        let mut empty_uvs = no_normals.clone();
        empty_uvs.uvs = Some(vec![]);
        let meshes = [a.clone(), inner, no_normals, empty_uvs, a];
        assert_eq!(
            mesh_groups(&meshes),
            vec![vec![0, 4], vec![1], vec![2], vec![3]]
        );
    }

    #[test]
    fn hit_keys_order_instances_before_the_scenes_own_primitives() {
        let t = |i| PrimRef::new(PrimKind::Triangle, i);
        let world = HitKey::world(t(0));
        let first = HitKey {
            prim: t(9),
            instance: Some(0),
        };
        let second = HitKey {
            prim: t(1),
            instance: Some(1),
        };
        assert!(first < second && second < world);
    }

    #[test]
    fn a_mirrored_instance_keeps_the_winding_normal_and_transforms_normals() {
        let mut degenerate = 0;
        let mesh = InstancedMesh::new(&quad(vec![]), BuildMethod::Sah, &mut degenerate);
        assert_eq!(degenerate, 0);
        let mirror = DMat4::from_scale(DVec3::new(-2.0, 1.0, 1.0));
        let instance = Instance::new(0, &mirror, 5, &mesh.hull_points());
        assert!(instance.mirrored);
        let (triangle, attributes) = instance.world_triangle(&mesh, 0);
        assert_eq!(triangle.material, 5);
        let [a, b, c] = triangle.vertices;
        assert_eq!(
            [a, b, c],
            [DVec3::ZERO, DVec3::new(-2.0, 1.0, 0.0), -2.0 * DVec3::X]
        );
        let normal = (b - a).cross(c - a).normalize();
        assert!((normal - DVec3::Z).length() < 1e-15, "{normal}");
        let normals = attributes.and_then(|a| a.normals).expect("normals");
        assert!(normals.iter().all(|n| (*n - DVec3::Z).length() < 1e-15));
        assert!(instance.bounds.min[0] <= -2.0 && instance.bounds.max[0] >= 0.0);
    }

    /// A ring of triangles around the z axis (a round mesh, whose box a rotation about
    /// z leaves unchanged) tipped 45° about x and turned 45° about z: the instance's box is
    /// the box of its moved vertices (within the f32 padding), and holds every one of
    /// them, where the moved corners of the mesh's box would be √2 wider along y.
    #[test]
    fn instance_boxes_are_as_tight_as_their_moved_vertices() {
        let n = 400;
        let mut positions = vec![DVec3::ZERO];
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        let triangles = (0..n as u32)
            .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
            .collect();
        let disc = Mesh {
            name: "disc".into(),
            positions: positions.clone(),
            normals: None,
            uvs: None,
            uvs1: None,
            colors: None,
            tangents: None,
            triangles,
            material: 0,
            instances: vec![],
        };
        let mut degenerate = 0;
        let mesh = InstancedMesh::new(&disc, BuildMethod::Sah, &mut degenerate);
        let hull = mesh.hull_points();
        let transform = DMat4::from_rotation_z(std::f64::consts::FRAC_PI_4)
            * DMat4::from_rotation_x(std::f64::consts::FRAC_PI_4)
            * DMat4::from_scale(DVec3::new(2.0, 2.0, 1.0));
        let instance = Instance::new(0, &transform, 0, &hull);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &positions {
            let q = transform.transform_point3(*p);
            (lo, hi) = (lo.min(q), hi.max(q));
            for axis in 0..3 {
                assert!(
                    f64::from(instance.bounds.min[axis]) <= q[axis]
                        && q[axis] <= f64::from(instance.bounds.max[axis]),
                    "{q} outside the box"
                );
            }
        }
        let root = mesh.bvh.root_bounds().expect("a tree");
        let corners = Instance::new(0, &transform, 0, &corner_points(root));
        for axis in 0..3 {
            let width = f64::from(instance.bounds.max[axis] - instance.bounds.min[axis]);
            let tight = hi[axis] - lo[axis];
            assert!(
                width <= tight * (1.0 + 1e-4) + 1e-5,
                "axis {axis}: box {width} wide for vertices {tight} wide"
            );
            let loose = f64::from(corners.bounds.max[axis] - corners.bounds.min[axis]);
            assert!(width <= loose, "axis {axis}");
        }
        let loose_y = f64::from(corners.bounds.max[1] - corners.bounds.min[1]);
        assert!(
            loose_y > 1.3 * (hi.y - lo.y),
            "the corners' box is tight too: the test cannot tell"
        );
    }

    /// The eight corners of a box.
    fn corner_points(b: Aabb32) -> Vec<DVec3> {
        (0..8)
            .map(|c: usize| {
                let pick = |axis: usize| {
                    f64::from(if (c >> axis) & 1 == 1 {
                        b.max[axis]
                    } else {
                        b.min[axis]
                    })
                };
                DVec3::new(pick(0), pick(1), pick(2))
            })
            .collect()
    }
}
