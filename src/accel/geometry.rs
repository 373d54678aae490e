//! The primitive lists both tracers intersect, and [`SceneGeometry`], which holds them
//! with the BVH over them.

use glam::{DVec2, DVec3, DVec4};

use super::bvh::{Aabb32, BuildMethod, Bvh};
use super::instance::{Instance, InstancedMesh, mesh_groups};
use crate::scene::{
    AlphaMode, Image, Material, Mesh, PolygonPlane, Scene, Shape, polygon_plane, project_to_plane,
};

pub use crate::scene::outline::MAX_POLYGON_VERTICES;

/// Most infinite planes a GPU scene may have: every ray tests every plane, so their
/// count bounds the work of one traversal step.
pub const MAX_PLANES: usize = 1024;

/// The kind of a primitive, stored in the top three bits of a [`PrimRef`]. The order
/// (spheres, planes, polygons, triangles) decides exact ties between kinds: a polygon
/// lying in a plane, such as the bottom of a box standing on the floor, loses to the
/// plane, as it did before the BVH on both backends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PrimKind {
    /// An entry of [`SceneGeometry::spheres`].
    Sphere = 0,
    /// An entry of [`SceneGeometry::planes`] (never in the BVH).
    Plane = 1,
    /// An entry of [`SceneGeometry::polygons`].
    Polygon = 2,
    /// An entry of [`SceneGeometry::triangles`].
    Triangle = 3,
    /// An entry of [`SceneGeometry::instances`]: a placement of an instanced mesh,
    /// which the traversal enters (never a hit itself; see [`super::instance`]).
    Instance = 4,
}

/// A primitive named by its kind and its index in that kind's list: `kind << 29 |
/// index`. It is also the tie-break key: of two hits at exactly the same distance, the
/// smaller `PrimRef` wins (on both backends).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, bytemuck::Pod, bytemuck::Zeroable,
)]
#[repr(transparent)]
pub struct PrimRef(pub u32);

impl PrimRef {
    /// Bits of a [`PrimRef`] that hold the index.
    pub const INDEX_BITS: u32 = 29;
    /// Largest index a [`PrimRef`] can hold (one less than 2^29).
    pub const MAX_INDEX: u32 = (1 << Self::INDEX_BITS) - 1;

    /// The reference to entry `index` of `kind`'s list (`index` at most
    /// [`PrimRef::MAX_INDEX`]).
    pub fn new(kind: PrimKind, index: u32) -> Self {
        debug_assert!(index <= Self::MAX_INDEX);
        Self(((kind as u32) << Self::INDEX_BITS) | (index & Self::MAX_INDEX))
    }

    /// The primitive's kind.
    pub fn kind(self) -> PrimKind {
        match self.0 >> Self::INDEX_BITS {
            0 => PrimKind::Sphere,
            1 => PrimKind::Plane,
            2 => PrimKind::Polygon,
            3 => PrimKind::Triangle,
            _ => PrimKind::Instance,
        }
    }

    /// The index in its kind's list.
    pub fn index(self) -> usize {
        (self.0 & Self::MAX_INDEX) as usize
    }
}

/// A sphere, with the anchor both tracers intersect it relative to
/// ([`crate::scene::sphere_anchor`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereShape {
    /// Centre.
    pub center: DVec3,
    /// Radius (> 0).
    pub radius: f64,
    /// The sphere's point nearest the world origin.
    pub anchor: DVec3,
    /// The unit outward normal at `anchor`.
    pub anchor_normal: DVec3,
    /// Material index.
    pub material: u32,
}

/// An infinite plane `normal · p = offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneShape {
    /// Unit normal.
    pub normal: DVec3,
    /// Signed distance from the origin along `normal`.
    pub offset: f64,
    /// Material index.
    pub material: u32,
}

/// A planar polygon of at most [`MAX_POLYGON_VERTICES`] vertices with its plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonShape {
    /// Its plane and projection axis, computed once ([`polygon_plane`]).
    pub plane: PolygonPlane,
    /// Its vertices in order.
    pub vertices: Vec<DVec3>,
    /// Material index.
    pub material: u32,
}

/// A triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleShape {
    /// Corners; the geometric normal is `(v1-v0)×(v2-v0)`, normalized.
    pub vertices: [DVec3; 3],
    /// Material index.
    pub material: u32,
    /// Index into [`SceneGeometry::triangle_attributes`] for a mesh triangle with
    /// vertex normals or texture coordinates.
    pub attributes: Option<u32>,
}

/// The per-vertex shading attributes of a mesh triangle, in world space and in the
/// order of its [`TriangleShape::vertices`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleAttributes {
    /// Unit vertex normals (smooth shading), if the mesh has them.
    pub normals: Option<[DVec3; 3]>,
    /// Vertex texture coordinates, if the mesh has them.
    pub uvs: Option<[DVec2; 3]>,
    /// The second set of vertex texture coordinates, if the mesh has it.
    pub uvs1: Option<[DVec2; 3]>,
    /// Linear RGBA vertex colours, if the mesh has them.
    pub colors: Option<[DVec4; 3]>,
    /// Unit tangents with the bitangent's handedness in `w`, if the mesh has them.
    pub tangents: Option<[DVec4; 3]>,
}

impl TriangleAttributes {
    /// The attributes of the triangle of `mesh` whose corners are `order`, without
    /// normals; `None` when the mesh has none of them.
    pub fn of_corners(
        mesh: &Mesh,
        order: [usize; 3],
        normals: Option<[DVec3; 3]>,
        transform: Option<&glam::DMat3>,
    ) -> Option<Self> {
        let attributes = Self {
            tangents: mesh.tangents.as_ref().map(|t| {
                order.map(|i| transform.map_or(t[i], |m| super::instance::world_tangent(m, t[i])))
            }),
            normals,
            uvs: mesh.uvs.as_ref().map(|uvs| order.map(|i| uvs[i])),
            uvs1: mesh.uvs1.as_ref().map(|uvs| order.map(|i| uvs[i])),
            colors: mesh.colors.as_ref().map(|colors| order.map(|i| colors[i])),
        };
        (attributes.normals.is_some()
            || attributes.uvs.is_some()
            || attributes.uvs1.is_some()
            || attributes.colors.is_some()
            || attributes.tangents.is_some())
        .then_some(attributes)
    }
}

/// What the CPU traversal needs to find the coverage of a material whose alpha
/// matters ([`AlphaMode::Mask`] with a positive cutoff, or [`AlphaMode::Blend`]): the
/// material and its albedo texture, whose alpha channel is the texture's part of the
/// surface's alpha.
#[derive(Debug, Clone, PartialEq)]
pub struct AlphaMask {
    /// The material (its alpha factor, texture coordinates and wrap modes).
    pub material: Material,
    /// Its alpha mode: a mask whose cutoff is above 0, or blending.
    pub mode: AlphaMode,
    /// The albedo texture, if any.
    pub texture: Option<Image>,
}

/// The alpha masks of `materials` (indexed alike; `None` for an opaque material and
/// for a mask whose cutoff is 0, which keeps every point), their textures from
/// `images`.
pub fn alpha_masks(materials: &[Material], images: &[Image]) -> Vec<Option<AlphaMask>> {
    materials
        .iter()
        .map(|material| {
            material.uses_alpha().then(|| AlphaMask {
                material: *material,
                mode: material.alpha_mode,
                texture: material
                    .albedo_texture
                    .and_then(|i| images.get(i as usize).cloned()),
            })
        })
        .collect()
}

/// A scene's primitives by kind and the BVH over the bounded ones: what both tracers
/// intersect.
#[derive(Debug, Clone)]
pub struct SceneGeometry {
    /// Spheres, in scene order.
    pub spheres: Vec<SphereShape>,
    /// Planes, in scene order.
    pub planes: Vec<PlaneShape>,
    /// Polygons of at most [`MAX_POLYGON_VERTICES`] vertices, in scene order.
    pub polygons: Vec<PolygonShape>,
    /// Triangles: the scene's own in scene order, then those of the polygons that had
    /// more than [`MAX_POLYGON_VERTICES`] vertices, then those of the meshes placed
    /// once, in world space. Meshes placed more than once are in `instanced_meshes`.
    pub triangles: Vec<TriangleShape>,
    /// Shading attributes of the mesh triangles that have any.
    pub triangle_attributes: Vec<TriangleAttributes>,
    /// Meshes placed more than once (the same geometry in one or more [`Mesh`]es),
    /// each stored once in its own space with its own BVH.
    pub instanced_meshes: Vec<InstancedMesh>,
    /// The placements of `instanced_meshes`, which the BVH holds as
    /// [`PrimKind::Instance`] primitives.
    pub instances: Vec<Instance>,
    /// Mesh triangles left out because they have no area (in world space for meshes
    /// placed once, per placement; in their own space for instanced meshes, once).
    pub degenerate_triangles: usize,
    /// How many of the scene's polygons were triangulated.
    pub triangulated_polygons: usize,
    /// Length scale of the self-intersection offset's near-origin branch
    /// ([`ray_offset_scale`]).
    pub offset_scale: f64,
    /// The hierarchy over spheres, polygons and triangles.
    pub bvh: Bvh,
    /// The alpha mask of each material, indexed by material (empty: none masks; see
    /// [`alpha_masks`]): the traversal skips a candidate hit whose alpha is below its
    /// material's cutoff.
    pub alpha_masks: Vec<Option<AlphaMask>>,
}

impl SceneGeometry {
    /// The geometry of a validated `scene`, with a BVH built by [`BuildMethod::Sah`].
    pub fn new(scene: &Scene) -> Self {
        Self::with_method(scene, BuildMethod::Sah)
    }

    /// The geometry of `scene` with a BVH built by `method`; every mesh placed more
    /// than once is instanced, emissive or not (next-event estimation samples each
    /// instance's triangles, [`super::AreaLights`]).
    pub fn with_method(scene: &Scene, method: BuildMethod) -> Self {
        let mut geometry = Self::without_scene_tree(scene, method);
        geometry.build_scene_tree(method);
        geometry
    }

    /// The geometry of `scene` as [`SceneGeometry::with_method`] makes it but for the
    /// hierarchy over the whole scene: `bvh` stays empty (the instanced meshes get
    /// theirs) until [`SceneGeometry::build_scene_tree`]. For the GPU's hardware
    /// traversal, which walks a tree of the analytic shapes alone
    /// ([`SceneGeometry::analytic_bvh`]) and leaves the triangles to the driver's
    /// structures: a million triangles' tree takes about 0.16 s to build on 2 cores.
    pub fn without_scene_tree(scene: &Scene, method: BuildMethod) -> Self {
        let mut geometry = Self::without_tree(&scene.shapes, &scene.meshes, method);
        let masks = alpha_masks(&scene.materials, &scene.images);
        if masks.iter().any(Option::is_some) {
            geometry.alpha_masks = masks;
        }
        geometry
    }

    /// Builds `bvh`, the hierarchy over every bounded primitive (spheres, polygons,
    /// triangles, instances), by `method`.
    pub fn build_scene_tree(&mut self, method: BuildMethod) {
        let bounds = self.bounded_primitives();
        self.bvh = Bvh::build(&bounds, method);
    }

    /// The geometry of `shapes` (validated, as in a [`Scene`]) with a BVH built by
    /// `method`.
    pub fn from_shapes(shapes: &[Shape], method: BuildMethod) -> Self {
        Self::from_parts(shapes, &[], method)
    }

    /// The geometry of `shapes` and `meshes` (validated, as in a [`Scene`]) with a BVH
    /// built by `method`; every mesh placed more than once is instanced.
    pub fn from_parts(shapes: &[Shape], meshes: &[Mesh], method: BuildMethod) -> Self {
        let mut geometry = Self::without_tree(shapes, meshes, method);
        geometry.build_scene_tree(method);
        geometry
    }

    /// [`SceneGeometry::from_parts`] with `bvh` left empty.
    fn without_tree(shapes: &[Shape], meshes: &[Mesh], method: BuildMethod) -> Self {
        let mut geometry = Self {
            spheres: Vec::new(),
            planes: Vec::new(),
            polygons: Vec::new(),
            triangles: Vec::new(),
            triangle_attributes: Vec::new(),
            instanced_meshes: Vec::new(),
            instances: Vec::new(),
            degenerate_triangles: 0,
            triangulated_polygons: 0,
            offset_scale: 1.0,
            bvh: Bvh::default(),
            alpha_masks: Vec::new(),
        };
        let mut large_polygons = Vec::new();
        for shape in shapes {
            match shape {
                Shape::Sphere {
                    center,
                    radius,
                    material,
                } => {
                    let (anchor, anchor_normal) = crate::scene::sphere_anchor(*center, *radius);
                    geometry.spheres.push(SphereShape {
                        center: *center,
                        radius: *radius,
                        anchor,
                        anchor_normal,
                        material: *material,
                    });
                }
                Shape::Plane {
                    normal,
                    offset,
                    material,
                } => geometry.planes.push(PlaneShape {
                    normal: *normal,
                    offset: *offset,
                    material: *material,
                }),
                Shape::Polygon { vertices, material } => {
                    // Validation rejects degenerate polygons; one that slips through
                    // gets a zero normal and is never hit.
                    let plane = polygon_plane(vertices).unwrap_or(PolygonPlane {
                        normal: DVec3::ZERO,
                        offset: 0.0,
                        dropped_axis: 2,
                    });
                    if vertices.len() > MAX_POLYGON_VERTICES {
                        large_polygons.push((plane, vertices, *material));
                    } else {
                        geometry.polygons.push(PolygonShape {
                            plane,
                            vertices: vertices.clone(),
                            material: *material,
                        });
                    }
                }
                Shape::Triangle { vertices, material } => geometry.triangles.push(TriangleShape {
                    vertices: *vertices,
                    material: *material,
                    attributes: None,
                }),
            }
        }
        geometry.triangulated_polygons = large_polygons.len();
        for (plane, vertices, material) in large_polygons {
            triangulate_polygon(&plane, vertices, material, &mut geometry.triangles);
        }
        geometry.add_meshes(meshes, method);
        geometry.offset_scale = geometry.ray_offset_scale();
        geometry
    }

    /// A hierarchy over the analytic shapes alone (spheres and polygons), built by
    /// `method`: what the software walk traverses where the device's ray queries find
    /// the triangles and instances (the GPU's hardware traversal).
    pub fn analytic_bvh(&self, method: BuildMethod) -> Bvh {
        let analytic: Vec<_> = self
            .bounded_primitives()
            .into_iter()
            .filter(|(prim, _)| matches!(prim.kind(), PrimKind::Sphere | PrimKind::Polygon))
            .collect();
        Bvh::build(&analytic, method)
    }

    /// Every bounded primitive with its conservative `f32` box, spheres first, then
    /// polygons, then triangles.
    fn bounded_primitives(&self) -> Vec<(PrimRef, Aabb32)> {
        let index = |i: usize| u32::try_from(i).unwrap_or(PrimRef::MAX_INDEX);
        let spheres = self.spheres.iter().enumerate().map(|(i, s)| {
            let r = DVec3::splat(s.radius);
            // The f32 sphere the GPU intersects (through its f32 anchor, with its f32
            // normal and radius), widened by both roundings.
            let r32 = f64::from(s.radius as f32);
            let c32 = s.anchor.as_vec3().as_dvec3() - s.anchor_normal.as_vec3().as_dvec3() * r32;
            let r32 = DVec3::splat(r32 * (1.0 + 4.0 * f64::from(f32::EPSILON)));
            let lo = (s.center - r).min(c32 - r32);
            let hi = (s.center + r).max(c32 + r32);
            (
                PrimRef::new(PrimKind::Sphere, index(i)),
                Aabb32::around(lo, hi),
            )
        });
        let polygons = self.polygons.iter().enumerate().map(|(i, p)| {
            (
                PrimRef::new(PrimKind::Polygon, index(i)),
                Aabb32::around_points(&p.vertices),
            )
        });
        let triangles = self.triangles.iter().enumerate().map(|(i, t)| {
            (
                PrimRef::new(PrimKind::Triangle, index(i)),
                Aabb32::around_points(&t.vertices),
            )
        });
        let instances = self
            .instances
            .iter()
            .enumerate()
            .map(|(i, instance)| (PrimRef::new(PrimKind::Instance, index(i)), instance.bounds));
        spheres
            .chain(polygons)
            .chain(triangles)
            .chain(instances)
            .collect()
    }

    /// Adds `meshes`: those whose geometry is placed once as world-space triangles
    /// ([`SceneGeometry::add_mesh`]), the others stored once as an [`InstancedMesh`]
    /// with one [`Instance`] per placement (of every mesh sharing that geometry, each
    /// with its mesh's material).
    fn add_meshes(&mut self, meshes: &[Mesh], method: BuildMethod) {
        for group in mesh_groups(meshes) {
            let placements: usize = group.iter().map(|&i| meshes[i].instances.len()).sum();
            if placements <= 1 {
                group.iter().for_each(|&i| self.add_mesh(&meshes[i]));
                continue;
            }
            let stored =
                InstancedMesh::new(&meshes[group[0]], method, &mut self.degenerate_triangles);
            let hull = stored.hull_points();
            if hull.is_empty() {
                // Every triangle degenerate: nothing to place.
                continue;
            }
            let mesh_index = self.instanced_meshes.len() as u32;
            for &i in &group {
                for transform in &meshes[i].instances {
                    self.instances.push(Instance::new(
                        mesh_index,
                        transform,
                        meshes[i].material,
                        &hull,
                    ));
                }
            }
            self.instanced_meshes.push(stored);
        }
    }

    /// Adds every instance of `mesh` as world-space triangles. A transform that
    /// mirrors (negative determinant) would reverse the winding, and with it the
    /// geometric normal: two corners are swapped back. Normals go through the inverse
    /// transpose. Triangles without area in world space are left out and counted.
    fn add_mesh(&mut self, mesh: &Mesh) {
        for transform in &mesh.instances {
            let linear = glam::DMat3::from_mat4(*transform);
            let normal_matrix = linear.inverse().transpose();
            let mirrored = linear.determinant() < 0.0;
            for corners in &mesh.triangles {
                let mut order = corners.map(|i| i as usize);
                if mirrored {
                    order.swap(1, 2);
                }
                let vertices = order.map(|i| transform.transform_point3(mesh.positions[i]));
                let area = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
                if !(area.length_squared() > 0.0 && area.is_finite()) {
                    self.degenerate_triangles += 1;
                    continue;
                }
                let facing = area.normalize();
                let normals = mesh.normals.as_ref().map(|normals| {
                    order.map(|i| (normal_matrix * normals[i]).normalize_or(facing))
                });
                let attributes =
                    TriangleAttributes::of_corners(mesh, order, normals, Some(&linear)).map(
                        |attributes| {
                            self.triangle_attributes.push(attributes);
                            (self.triangle_attributes.len() - 1) as u32
                        },
                    );
                self.triangles.push(TriangleShape {
                    vertices,
                    material: mesh.material,
                    attributes,
                });
            }
        }
    }

    /// The length scale of the ray offset's near-origin branch ([`ray_offset_scale`])
    /// over every primitive of this geometry.
    fn ray_offset_scale(&self) -> f64 {
        let mut extent = 0.0f64;
        let mut include = |v: DVec3| extent = extent.max(v.abs().max_element());
        self.spheres
            .iter()
            .for_each(|s| include(s.center.abs() + DVec3::splat(s.radius)));
        self.planes
            .iter()
            .for_each(|p| include(DVec3::splat(p.offset)));
        self.polygons
            .iter()
            .for_each(|p| p.vertices.iter().copied().for_each(&mut include));
        self.triangles
            .iter()
            .for_each(|t| t.vertices.iter().copied().for_each(&mut include));
        // An instance by its world box: a little larger than its triangles' extent.
        self.instances.iter().for_each(|i| {
            include(DVec3::from_array(i.bounds.min.map(f64::from)));
            include(DVec3::from_array(i.bounds.max.map(f64::from)));
        });
        if extent > 0.0 && extent < 1.0 {
            extent
        } else {
            1.0
        }
    }

    /// The material of primitive `prim`.
    pub fn material(&self, prim: PrimRef) -> u32 {
        match prim.kind() {
            PrimKind::Sphere => self.spheres[prim.index()].material,
            PrimKind::Polygon => self.polygons[prim.index()].material,
            PrimKind::Triangle => self.triangles[prim.index()].material,
            PrimKind::Plane => self.planes[prim.index()].material,
            PrimKind::Instance => self.instances[prim.index()].material,
        }
    }

    /// The alpha mask of material `material`, if it has one.
    pub fn alpha_mask(&self, material: u32) -> Option<&AlphaMask> {
        self.alpha_masks.get(material as usize)?.as_ref()
    }

    /// The number of bounded primitives (those in the BVH, instances counted once).
    pub fn bounded_count(&self) -> usize {
        self.spheres.len() + self.polygons.len() + self.triangles.len() + self.instances.len()
    }

    /// The triangles the instances stand for: what flattening them would store.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.instanced_meshes[i.mesh as usize].triangles.len())
            .sum()
    }
}

/// The length scale of the ray offset's near-origin branch for `scene`
/// (`offset_ray_origin` in `src/cpu/intersect.rs` and `shaders/intersect.wgsl`): the
/// largest absolute coordinate of its geometry (sphere centres ± radii, plane offsets,
/// vertices, mesh triangles where they stand), capped at 1.
///
/// Wächter and Binder's constants (`1/32` for "near the origin", `1/65536` for the
/// absolute offset there) assume a scene of about unit size. In a scene 10^-4 across
/// that absolute offset would be 15% of the scene, so both constants are multiplied by
/// this scale, which makes the offset, like every other length, scale with the scene.
/// Larger scenes keep the published constants (scale 1): there the ulp branch covers
/// every coordinate beyond 1/32, and a larger near-origin offset would lift rays off a
/// small object lying near the origin of a large world. [`SceneGeometry::offset_scale`]
/// holds it for a built geometry.
pub fn ray_offset_scale(scene: &Scene) -> f64 {
    SceneGeometry::new(scene).offset_scale
}

/// Triangulates a planar polygon (ear clipping, mapbox's earcut, in the projection that
/// drops the plane's dominant axis) and appends its triangles, each wound so that its
/// normal agrees with the polygon's.
fn triangulate_polygon(
    plane: &PolygonPlane,
    vertices: &[DVec3],
    material: u32,
    out: &mut Vec<TriangleShape>,
) {
    let projected: Vec<[f64; 2]> = vertices
        .iter()
        .map(|v| {
            let (u, w) = project_to_plane(*v, plane.dropped_axis);
            [u, w]
        })
        .collect();
    let mut indices: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(projected.iter().copied(), &[] as &[u32], &mut indices);
    for corner in indices.chunks_exact(3) {
        let mut tri = [
            vertices[corner[0] as usize],
            vertices[corner[1] as usize],
            vertices[corner[2] as usize],
        ];
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        if normal.dot(plane.normal) < 0.0 {
            tri.swap(1, 2);
        }
        out.push(TriangleShape {
            vertices: tri,
            material,
            attributes: None,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prim_refs_round_trip_and_order_by_kind() {
        for kind in [
            PrimKind::Sphere,
            PrimKind::Polygon,
            PrimKind::Triangle,
            PrimKind::Plane,
            PrimKind::Instance,
        ] {
            for index in [0, 1, 12345, PrimRef::MAX_INDEX] {
                let prim = PrimRef::new(kind, index);
                assert_eq!(prim.kind(), kind);
                assert_eq!(prim.index(), index as usize);
            }
        }
        assert!(
            PrimRef::new(PrimKind::Sphere, PrimRef::MAX_INDEX) < PrimRef::new(PrimKind::Plane, 0)
        );
        assert!(
            PrimRef::new(PrimKind::Plane, PrimRef::MAX_INDEX) < PrimRef::new(PrimKind::Polygon, 0)
        );
    }

    #[test]
    fn large_polygons_become_triangles_of_the_same_area_and_side() {
        // A regular 100-gon of radius 1 in the plane y = 2, counter-clockwise seen from +y.
        let n = 100;
        let vertices: Vec<DVec3> = (0..n)
            .map(|i| {
                let a = -(i as f64) / n as f64 * std::f64::consts::TAU;
                DVec3::new(a.cos(), 2.0, a.sin())
            })
            .collect();
        let plane = polygon_plane(&vertices).expect("planar");
        let shapes = vec![Shape::Polygon {
            vertices,
            material: 0,
        }];
        let geometry = SceneGeometry::from_shapes(&shapes, BuildMethod::Sah);
        assert!(geometry.polygons.is_empty());
        assert_eq!(geometry.triangulated_polygons, 1);
        assert_eq!(geometry.triangles.len(), n - 2);
        let mut area = 0.0;
        for t in &geometry.triangles {
            let cross = (t.vertices[1] - t.vertices[0]).cross(t.vertices[2] - t.vertices[0]);
            assert!(cross.dot(plane.normal) > 0.0);
            area += cross.length() / 2.0;
        }
        let expected = 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin();
        assert!((area - expected).abs() < 1e-9, "{area} vs {expected}");
    }
}
