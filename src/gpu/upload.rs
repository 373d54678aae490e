//! Pure conversion of a validated [`Scene`] into the records the shaders read.
//!
//! Nothing here touches wgpu, so it is unit-tested on any machine. Call it with the
//! scene as the tracers shade it ([`Scene::in_lighting_space`]); the renderer does.

use glam::{DVec2, DVec3, DVec4};

use super::layout::{
    DISTRIBUTION_BECKMANN, DISTRIBUTION_GGX, FLAG_ANISOTROPIC_TEXTURES, FLAG_ORTHOGRAPHIC,
    FLAG_TEXTURE_FILTERING, FRESNEL_EXACT, FRESNEL_SCHLICK, FrameUniforms, GpuLight, GpuMaterial,
    GpuPlane, GpuPolygon, GpuSphere, GpuTriangle, GpuTriangleAttributes, LIGHT_DIRECTIONAL,
    LIGHT_POINT, LIGHT_SPOT, MAPPING_PLANAR, MAPPING_SPHERICAL, MAPPING_UV, MATERIAL_BLINN_PHONG,
    MATERIAL_COOK_TORRANCE, MATERIAL_DIELECTRIC, MATERIAL_EMISSIVE, MATERIAL_LAMBERT,
    MATERIAL_MIRROR, MATERIAL_OREN_NAYAR, MATERIAL_PBR, MATERIAL_TABULATED, NO_ATTRIBUTES,
    NO_IMAGE, UV_SLOT_ALBEDO, UV_SLOT_EMISSION, UV_SLOT_METALLIC_ROUGHNESS, UV_SLOT_NORMAL,
    WRAP_CLAMP_TO_EDGE, WRAP_MIRRORED_REPEAT, WRAP_REPEAT,
};
use crate::accel::{
    BrdfMapCdf, BrdfMapCdfs, Bvh, Instance, PolygonShape, PrimKind, PrimRef, SceneGeometry,
    TriangleAttributes, TriangleShape, WideNode,
};
use crate::camera::{CameraFrame, PixelCone};
use crate::scene::{
    AlphaMode, FresnelModel, Image, Light, Material, MaterialKind, MediumStack,
    MicrofacetDistribution, Scene, TextureFiltering, TextureMapping, TextureWrap, project_to_plane,
};

/// Every record list of a scene, ready for upload. The lists hold exactly the scene's
/// items (possibly none); [`SceneRecords::padded`] adds the padding record WGSL needs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneRecords {
    /// Spheres, in [`SceneGeometry::spheres`] order.
    pub spheres: Vec<GpuSphere>,
    /// Planes, in [`SceneGeometry::planes`] order.
    pub planes: Vec<GpuPlane>,
    /// Polygons, in [`SceneGeometry::polygons`] order; their vertices are in
    /// `polygon_points`.
    pub polygons: Vec<GpuPolygon>,
    /// The vertices of all polygons, concatenated, each as the two coordinates of its
    /// polygon's inside-test projection ([`crate::scene::project_to_plane`] by the
    /// plane's dropped axis): all the inside test reads, in half the bytes.
    pub polygon_points: Vec<[f32; 2]>,
    /// Triangles, in [`SceneGeometry::triangles`] order, then each instanced mesh's
    /// (in its own space, once).
    pub triangles: Vec<GpuTriangle>,
    /// Mesh triangles' vertex normals and texture coordinates, in
    /// [`SceneGeometry::triangle_attributes`] order, then each instanced mesh's.
    pub triangle_attributes: Vec<GpuTriangleAttributes>,
    /// Materials, indexed by the shapes' `material`.
    pub materials: Vec<GpuMaterial>,
    /// Lights, in scene order.
    pub lights: Vec<GpuLight>,
    /// The wide BVH nodes, as both tracers read them (the scene's tree from node 0),
    /// then each instanced mesh's tree, then [`INSTANCE_RECORD_NODES`] records per
    /// instance ([`instance_records`]).
    pub bvh_nodes: Vec<WideNode>,
    /// The BVH's primitive references (`PrimRef` values), leaf by leaf: the scene's
    /// tree's (an instance named by the node index of its records), then each
    /// instanced mesh's (its triangles by their index in `triangles`).
    pub bvh_prims: Vec<u32>,
}

impl SceneRecords {
    /// Converts the materials and lights of `scene` (already in lighting space) and
    /// the primitives and BVH of its `geometry`.
    pub fn new(scene: &Scene, geometry: &SceneGeometry) -> Self {
        Self::with_scene_tree(scene, geometry, &geometry.bvh)
    }

    /// [`SceneRecords::new`] with `scene_tree` in place of the geometry's own tree as
    /// the scene's tree (node 0 on): for the hardware traversal, the tree of the
    /// analytic shapes alone ([`SceneGeometry::analytic_bvh`]). The instanced meshes'
    /// trees and the instances' records follow it as always.
    pub fn with_scene_tree(scene: &Scene, geometry: &SceneGeometry, scene_tree: &Bvh) -> Self {
        let shift_uvs = may_shift_uvs(scene);
        let mut records = Self {
            spheres: geometry
                .spheres
                .iter()
                .map(|s| GpuSphere {
                    anchor: vec3(s.anchor),
                    radius: s.radius as f32,
                    normal: vec3(s.anchor_normal),
                    material: s.material,
                })
                .collect(),
            planes: geometry
                .planes
                .iter()
                .map(|p| GpuPlane {
                    normal: vec3(p.normal),
                    offset: p.offset as f32,
                    material: p.material,
                    _pad0: 0,
                    _pad1: 0,
                    _pad2: 0,
                })
                .collect(),
            triangles: geometry
                .triangles
                .iter()
                .map(|t| triangle_record(t, 0))
                .collect(),
            triangle_attributes: geometry
                .triangle_attributes
                .iter()
                .map(|a| triangle_attributes_record(a, shift_uvs))
                .collect(),
            bvh_nodes: scene_tree.wide.clone(),
            bvh_prims: scene_tree.prims.iter().map(|p| p.0).collect(),
            ..Self::default()
        };
        records.append_instances(geometry, shift_uvs);
        for polygon in &geometry.polygons {
            let first_vertex = records.polygon_points.len();
            records
                .polygon_points
                .extend(polygon.vertices.iter().map(|v| {
                    let (u, w) = project_to_plane(*v, polygon.plane.dropped_axis);
                    [u as f32, w as f32]
                }));
            records.polygons.push(polygon_record(polygon, first_vertex));
        }
        records.materials = scene
            .materials
            .iter()
            .map(|m| material_record(m, &scene.images))
            .collect();
        records.lights = scene.lights.iter().map(light_record).collect();
        records
    }

    /// Appends the instanced meshes (triangles, attributes, trees with their node and
    /// primitive indices shifted to where they land) and the instances' records, and
    /// renames the scene tree's instance references to their records' node index.
    fn append_instances(&mut self, geometry: &SceneGeometry, shift_uvs: bool) {
        if geometry.instances.is_empty() {
            return;
        }
        let index = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        // The scene tree's references come first; the meshes' follow.
        let scene_prims = self.bvh_prims.len();
        let mut roots = Vec::with_capacity(geometry.instanced_meshes.len());
        for mesh in &geometry.instanced_meshes {
            let first_triangle = index(self.triangles.len());
            let first_attributes = index(self.triangle_attributes.len());
            self.triangles.extend(
                mesh.triangles
                    .iter()
                    .map(|t| triangle_record(t, first_attributes)),
            );
            self.triangle_attributes.extend(
                mesh.triangle_attributes
                    .iter()
                    .map(|a| triangle_attributes_record(a, shift_uvs)),
            );
            let first_node = index(self.bvh_nodes.len());
            let first_prim = index(self.bvh_prims.len());
            roots.push((first_node, first_triangle));
            self.bvh_nodes.extend(
                mesh.bvh
                    .wide
                    .iter()
                    .map(|n| n.shifted(first_node, first_prim)),
            );
            self.bvh_prims.extend(
                mesh.bvh
                    .prims
                    .iter()
                    .map(|p| PrimRef::new(PrimKind::Triangle, first_triangle + p.index() as u32).0),
            );
        }
        let first_record = self.bvh_nodes.len();
        for (i, instance) in geometry.instances.iter().enumerate() {
            let (root, first_triangle) = roots[instance.mesh as usize];
            self.bvh_nodes
                .extend(instance_records(instance, root, index(i), first_triangle));
        }
        let record = |i: usize| index(first_record + INSTANCE_RECORD_NODES * i);
        for prim in &mut self.bvh_prims[..scene_prims] {
            let p = PrimRef(*prim);
            if p.kind() == PrimKind::Instance {
                *prim = PrimRef::new(PrimKind::Instance, record(p.index())).0;
            }
        }
    }

    /// The same lists with one zeroed record in place of each empty list: WGSL has no
    /// zero-sized storage buffers, and the real counts travel in [`FrameUniforms`]
    /// (or, for the BVH, in an empty tree's node count of 0).
    pub fn padded(&self) -> Self {
        Self {
            spheres: pad(&self.spheres),
            planes: pad(&self.planes),
            polygons: pad(&self.polygons),
            polygon_points: pad(&self.polygon_points),
            triangles: pad(&self.triangles),
            triangle_attributes: pad(&self.triangle_attributes),
            materials: pad(&self.materials),
            lights: pad(&self.lights),
            bvh_nodes: pad(&self.bvh_nodes),
            bvh_prims: pad(&self.bvh_prims),
        }
    }
}

/// Where the instanced meshes land in the GPU's buffers, as
/// [`SceneRecords::new`] lays them out: after the scene's own triangles and tree, each
/// mesh's triangles and tree in turn, then [`INSTANCE_RECORD_NODES`] node records per
/// instance.
#[derive(Debug, Clone)]
pub struct InstanceLayout {
    /// Per instanced mesh: the index of its first triangle in the triangle buffer.
    first_triangle: Vec<u32>,
    /// The node index of the first instance's records.
    first_record: u32,
}

impl InstanceLayout {
    /// The layout of `geometry`'s instanced meshes and instances.
    pub fn new(geometry: &SceneGeometry) -> Self {
        Self::with_scene_nodes(geometry, geometry.bvh.wide.len())
    }

    /// The layout of `geometry`'s instanced meshes and instances after a scene tree of
    /// `scene_nodes` wide nodes ([`SceneRecords::with_scene_tree`]).
    pub fn with_scene_nodes(geometry: &SceneGeometry, scene_nodes: usize) -> Self {
        let index = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        let mut triangles = geometry.triangles.len();
        let mut nodes = scene_nodes;
        let mut first_triangle = Vec::with_capacity(geometry.instanced_meshes.len());
        for mesh in &geometry.instanced_meshes {
            first_triangle.push(index(triangles));
            triangles += mesh.triangles.len();
            nodes += mesh.bvh.wide.len();
        }
        Self {
            first_triangle,
            first_record: index(nodes),
        }
    }

    /// The index in the triangle buffer of instanced mesh `mesh`'s first triangle.
    pub fn first_triangle(&self, mesh: usize) -> u32 {
        self.first_triangle[mesh]
    }

    /// The node index of instance `instance`'s records.
    pub fn record(&self, instance: u32) -> u32 {
        self.first_record
            .saturating_add((INSTANCE_RECORD_NODES as u32).saturating_mul(instance))
    }

    /// The names a GPU hit on triangle `triangle` of instance `instance`'s mesh
    /// carries: its `PrimRef` in the triangle buffer and the node index of the
    /// instance's records.
    pub fn surface(&self, geometry: &SceneGeometry, instance: u32, triangle: usize) -> (u32, u32) {
        let mesh = geometry.instances[instance as usize].mesh as usize;
        let prim = self.first_triangle[mesh] + triangle as u32;
        (
            PrimRef::new(PrimKind::Triangle, prim).0,
            self.record(instance),
        )
    }
}

/// Node records per instance in [`SceneRecords::bvh_nodes`].
pub const INSTANCE_RECORD_NODES: usize = 2;

/// The [`INSTANCE_RECORD_NODES`] node records that hold `instance` for the shaders
/// (`load_instance` in `shaders/instance.wgsl`), whose mesh's tree has its root at
/// node `root`: the columns of `object_to_world` (the images of x, y and z, then the
/// translation) in the first record's `origin`, `low`, `high` and `children[0..3]`
/// (as `f32` bits), those of `world_to_object` in the second's; the first record's
/// `exponents`, `spare_low`, `spare_high` and `children[3]` hold the root, the
/// material, whether the transform mirrors and the instance's index in
/// [`SceneGeometry::instances`], the second's `exponents` its mesh's first triangle in
/// the triangle buffer (the index and first triangle name a hit as the CPU does, for
/// stochastic transparency's hash). The normal matrix is the transpose of
/// `world_to_object`'s linear part and is not stored.
pub fn instance_records(
    instance: &Instance,
    root: u32,
    index: u32,
    first_triangle: u32,
) -> [WideNode; INSTANCE_RECORD_NODES] {
    let bits = |v: DVec3| vec3(v).map(f32::to_bits);
    let record = |columns: [DVec3; 4], words: [u32; 4]| {
        let t = bits(columns[3]);
        WideNode {
            origin: vec3(columns[0]),
            exponents: words[0],
            low: bits(columns[1]),
            spare_low: words[1],
            high: bits(columns[2]),
            spare_high: words[2],
            children: [t[0], t[1], t[2], words[3]],
        }
    };
    let o2w = &instance.object_to_world;
    let w2o = &instance.world_to_object;
    [
        record(
            [
                o2w.matrix3.x_axis,
                o2w.matrix3.y_axis,
                o2w.matrix3.z_axis,
                o2w.translation,
            ],
            [root, instance.material, u32::from(instance.mirrored), index],
        ),
        record(
            [
                w2o.matrix3.x_axis,
                w2o.matrix3.y_axis,
                w2o.matrix3.z_axis,
                w2o.translation,
            ],
            [first_triangle, 0, 0, 0],
        ),
    ]
}

/// The record of a triangle whose attributes index is shifted by `first_attributes`.
fn triangle_record(t: &TriangleShape, first_attributes: u32) -> GpuTriangle {
    GpuTriangle {
        v0: vec3(t.vertices[0]),
        material: t.material,
        v1: vec3(t.vertices[1]),
        attributes: t.attributes.map_or(NO_ATTRIBUTES, |a| a + first_attributes),
        v2: vec3(t.vertices[2]),
        _pad2: 0,
    }
}

/// `items`, or a single zeroed record if it is empty.
pub fn pad<T: bytemuck::Zeroable + Clone>(items: &[T]) -> Vec<T> {
    if items.is_empty() {
        vec![T::zeroed()]
    } else {
        items.to_vec()
    }
}

fn vec3(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// The record of one polygon whose vertices start at `first_vertex` in the vertex list,
/// with the plane computed once for both tracers ([`PolygonShape::plane`]).
pub fn polygon_record(polygon: &PolygonShape, first_vertex: usize) -> GpuPolygon {
    GpuPolygon {
        normal: vec3(polygon.plane.normal),
        offset: polygon.plane.offset as f32,
        first_vertex: u32::try_from(first_vertex).unwrap_or(u32::MAX),
        vertex_count: u32::try_from(polygon.vertices.len()).unwrap_or(u32::MAX),
        dropped_axis: polygon.plane.dropped_axis,
        material: polygon.material,
    }
}

/// The `MATERIAL_*` constant of a material kind.
pub fn material_kind_code(kind: MaterialKind) -> u32 {
    match kind {
        MaterialKind::Lambert => MATERIAL_LAMBERT,
        MaterialKind::BlinnPhong => MATERIAL_BLINN_PHONG,
        MaterialKind::Mirror => MATERIAL_MIRROR,
        MaterialKind::Dielectric => MATERIAL_DIELECTRIC,
        MaterialKind::Emissive => MATERIAL_EMISSIVE,
        MaterialKind::CookTorrance => MATERIAL_COOK_TORRANCE,
        MaterialKind::OrenNayar => MATERIAL_OREN_NAYAR,
        MaterialKind::Tabulated => MATERIAL_TABULATED,
        MaterialKind::Pbr => MATERIAL_PBR,
    }
}

/// The record of one material; `images` are the scene's, whose index is the layer in
/// the image array ([`image_layers`]).
pub fn material_record(material: &Material, images: &[Image]) -> GpuMaterial {
    let image =
        |index: Option<u32>| match index.and_then(|i| images.get(i as usize).map(|m| (i, m))) {
            Some((i, m)) => (i, m.width, m.height),
            None => (NO_IMAGE, 0, 0),
        };
    let (texture_layer, texture_width, texture_height) = image(material.albedo_texture);
    let (brdf_map_layer, brdf_map_size, _) = image(material.brdf_map);
    let (metallic_roughness_layer, metallic_roughness_width, metallic_roughness_height) =
        image(material.metallic_roughness_texture);
    let (emission_layer, emission_width, emission_height) = image(material.emission_texture);
    let (normal_layer, normal_width, normal_height) = image(material.normal_texture);
    GpuMaterial {
        diffuse: vec3(material.diffuse),
        shininess: material.shininess as f32,
        specular: vec3(material.specular),
        ior: material.ior as f32,
        reflectance: vec3(material.reflectance),
        kind: material_kind_code(material.kind),
        transmittance: vec3(material.transmittance),
        coat_ior: material.coat_ior as f32,
        emission: vec3(material.emission),
        roughness: material.roughness as f32,
        eta: vec3(material.eta),
        metallic: material.metallic as f32,
        k: vec3(material.k),
        sigma: material.sigma as f32,
        distribution: match material.distribution {
            MicrofacetDistribution::Ggx => DISTRIBUTION_GGX,
            MicrofacetDistribution::Beckmann => DISTRIBUTION_BECKMANN,
        },
        fresnel: match material.fresnel {
            FresnelModel::Exact => FRESNEL_EXACT,
            FresnelModel::Schlick => FRESNEL_SCHLICK,
        },
        conductor: u32::from(material.conductor),
        texture_mapping: match material.texture_mapping {
            TextureMapping::Planar => MAPPING_PLANAR,
            TextureMapping::Spherical => MAPPING_SPHERICAL,
            TextureMapping::Uv => MAPPING_UV,
        },
        texture_layer,
        texture_width,
        texture_height,
        texture_scale: material.texture_scale as f32,
        brdf_map_layer,
        brdf_map_size,
        texture_wrap_u: wrap_code(material.texture_wrap[0]),
        texture_wrap_v: wrap_code(material.texture_wrap[1]),
        metallic_roughness_layer,
        metallic_roughness_width,
        metallic_roughness_height,
        metallic_roughness_wrap: wrap_code(material.metallic_roughness_wrap[0])
            | wrap_code(material.metallic_roughness_wrap[1]) << 8,
        two_sided: u32::from(material.two_sided),
        emission_layer,
        emission_width,
        emission_height,
        emission_wrap: wrap_code(material.emission_wrap[0])
            | wrap_code(material.emission_wrap[1]) << 8,
        uv_sets: [
            (UV_SLOT_ALBEDO, &material.texture_transform),
            (
                UV_SLOT_METALLIC_ROUGHNESS,
                &material.metallic_roughness_transform,
            ),
            (UV_SLOT_EMISSION, &material.emission_transform),
            (UV_SLOT_NORMAL, &material.normal_transform),
        ]
        .iter()
        .fold(0, |sets, &(slot, t)| sets | u32::from(t.set == 1) << slot),
        cull_back_faces: u32::from(material.cull_back_faces),
        normal_layer,
        uv_rows: [
            &material.texture_transform,
            &material.metallic_roughness_transform,
            &material.emission_transform,
            &material.normal_transform,
        ]
        .map(|t| {
            t.rows
                .map(|row| [row.x as f32, row.y as f32, row.z as f32, 0.0])
        })
        .concat()
        .try_into()
        .unwrap_or_default(),
        normal_width,
        normal_height,
        normal_wrap: wrap_code(material.normal_wrap[0]) | wrap_code(material.normal_wrap[1]) << 8,
        normal_scale: material.normal_scale as f32,
        alpha_cutoff: match material.alpha_mode {
            AlphaMode::Mask { cutoff } => cutoff as f32,
            AlphaMode::Opaque | AlphaMode::Blend => 0.0,
        },
        alpha: material.alpha as f32,
        alpha_blend: u32::from(material.alpha_mode == AlphaMode::Blend),
        _pad1: 0,
    }
}

/// Whether the texture coordinates of `scene`'s meshes may be moved by whole repeats
/// ([`uvs_near_origin`]): not when a material maps its texture coordinates by more
/// than an offset (`KHR_texture_transform`'s rotation or scale), under which whole
/// repeats of the coordinates are not whole repeats of the texture. Such a mesh keeps
/// its coordinates as they are, in `f32`.
pub fn may_shift_uvs(scene: &Scene) -> bool {
    scene.materials.iter().all(|m| {
        [
            &m.texture_transform,
            &m.metallic_roughness_transform,
            &m.emission_transform,
            &m.normal_transform,
        ]
        .iter()
        .all(|t| t.is_linear_identity())
    })
}

/// A triangle's texture coordinates moved, on each axis, by a whole even number of
/// texture repeats towards the origin, where the triangle lies wholly beyond 2 (or
/// wholly below −1): in `f32` a coordinate near 1e5 keeps only 1/128 of a repeat (16%
/// of the pixels of a textured quad were wrong at that offset). An even shift leaves
/// every wrap mode's lookup as it was (repeat and mirrored repeat are periodic in 2,
/// glTF 2.0 §5.26), and the shifted coordinates stay beyond 1 (or below 0), so
/// clamping gives the same edge texel. The CPU reference keeps the coordinates as
/// they are, in `f64`, which holds them.
pub fn uvs_near_origin(uvs: [DVec2; 3]) -> [DVec2; 3] {
    let shift = |values: [f64; 3]| {
        let (low, high) = (
            values.iter().copied().fold(f64::INFINITY, f64::min),
            values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        if low >= 2.0 {
            2.0 * (low / 2.0).floor() - 2.0
        } else if high <= -1.0 {
            2.0 * (high / 2.0).ceil() + 2.0
        } else {
            0.0
        }
    };
    let offset = DVec2::new(shift(uvs.map(|uv| uv.x)), shift(uvs.map(|uv| uv.y)));
    uvs.map(|uv| uv - offset)
}

/// The `WRAP_*` code of a wrap mode.
fn wrap_code(wrap: TextureWrap) -> u32 {
    match wrap {
        TextureWrap::Repeat => WRAP_REPEAT,
        TextureWrap::MirroredRepeat => WRAP_MIRRORED_REPEAT,
        TextureWrap::ClampToEdge => WRAP_CLAMP_TO_EDGE,
    }
}

/// The record of one mesh triangle's shading attributes (zeros where absent), its
/// texture coordinates moved near the origin ([`uvs_near_origin`]) so that `f32`
/// keeps their fraction, where `shift_uvs` ([`may_shift_uvs`]).
pub fn triangle_attributes_record(
    attributes: &TriangleAttributes,
    shift_uvs: bool,
) -> GpuTriangleAttributes {
    let normals = attributes.normals.unwrap_or([DVec3::ZERO; 3]);
    let near = |uvs: Option<[DVec2; 3]>| {
        let uvs = uvs.unwrap_or_default();
        if shift_uvs { uvs_near_origin(uvs) } else { uvs }
    };
    let uvs = near(attributes.uvs);
    let uvs1 = near(attributes.uvs1);
    let colors = attributes
        .colors
        .unwrap_or([DVec4::ONE; 3])
        .map(|c| c.as_vec4().to_array());
    let tangents = attributes
        .tangents
        .unwrap_or_default()
        .map(|t| t.as_vec4().to_array());
    GpuTriangleAttributes {
        n0: vec3(normals[0]),
        has_normals: u32::from(attributes.normals.is_some()),
        n1: vec3(normals[1]),
        has_uvs: u32::from(attributes.uvs.is_some()),
        n2: vec3(normals[2]),
        has_colors: u32::from(attributes.colors.is_some()),
        uv01: [
            uvs[0].x as f32,
            uvs[0].y as f32,
            uvs[1].x as f32,
            uvs[1].y as f32,
        ],
        uv2: [uvs[2].x as f32, uvs[2].y as f32],
        has_uvs1: u32::from(attributes.uvs1.is_some()),
        has_tangents: u32::from(attributes.tangents.is_some()),
        uv1_01: [
            uvs1[0].x as f32,
            uvs1[0].y as f32,
            uvs1[1].x as f32,
            uvs1[1].y as f32,
        ],
        uv1_2: [uvs1[2].x as f32, uvs1[2].y as f32],
        _pad1: [0; 2],
        c0: colors[0],
        c1: colors[1],
        c2: colors[2],
        t0: tangents[0],
        t1: tangents[1],
        t2: tangents[2],
    }
}

/// The scene's images as the layers of one `Rgba32Float` texture array: every layer is
/// as large as the largest image, each image in its layer's top-left corner (the
/// shaders only read texels inside the image's own width and height), the rest zero.
/// The alpha channel of a BRDF map's layer holds its inverse-CDF table from `cdfs`
/// (texel `(x, y)` = [`crate::accel::BrdfMapCdf::value`]`(x, y)`), which the path
/// integrator samples the map by; otherwise only an albedo texture's alpha coverage
/// reads an image's alpha ([`crate::scene::AlphaMode`]).
/// Returns `(width, height, layers, texels)` with texels layer by layer, row-major; a
/// scene without images gets one 1×1 zero layer (WGSL needs a bound texture).
pub fn image_layers(images: &[Image], cdfs: &BrdfMapCdfs) -> (u32, u32, u32, Vec<[f32; 4]>) {
    let (width, height, layers) = image_array_size(images);
    let mut texels = Vec::with_capacity(width as usize * height as usize * layers as usize);
    for (layer, image) in images.iter().enumerate() {
        texels.extend(image_layer(image, cdfs.of_image(layer), width, height));
    }
    texels.resize(width as usize * height as usize * layers as usize, [0.0; 4]);
    (width, height, layers, texels)
}

/// The size of the scene's image array ([`image_layers`]): the largest width, the
/// largest height and the number of layers (at least 1 each).
pub fn image_array_size(images: &[Image]) -> (u32, u32, u32) {
    let width = images.iter().map(|i| i.width).max().unwrap_or(1);
    let height = images.iter().map(|i| i.height).max().unwrap_or(1);
    (width, height, images.len().max(1) as u32)
}

/// One layer of [`image_layers`]: `image` in the top-left corner of `width × height`
/// texels, the rest zero, its alpha replaced by the inverse-CDF table `cdf` where the
/// image is a BRDF map the path integrator samples.
pub fn image_layer(
    image: &Image,
    cdf: Option<&BrdfMapCdf>,
    width: u32,
    height: u32,
) -> Vec<[f32; 4]> {
    let mut texels = vec![[0.0; 4]; width as usize * height as usize];
    for y in 0..image.height.min(height) as usize {
        let row = &image.texels[y * image.width as usize..][..image.width.min(width) as usize];
        let start = y * width as usize;
        texels[start..start + row.len()].copy_from_slice(row);
        if let Some(cdf) = cdf {
            for (x, texel) in texels[start..start + row.len()].iter_mut().enumerate() {
                texel[3] = cdf.value(x as u32, y as u32);
            }
        }
    }
    texels
}

/// The number of mip levels beyond 0 of an image array whose level 0 is `width ×
/// height`: `⌊log2(max(width, height))⌋`.
pub fn image_array_levels(width: u32, height: u32) -> u32 {
    width.max(height).max(1).ilog2()
}

/// One layer of level `k` (at least 1) of the image array's mip chain (level 0 is
/// [`image_layers`]): the level is `max(1, width >> k) × max(1, height >> k)` texels
/// (the array's level size, wgpu's) and holds level `k` of the image's chain `chain`
/// ([`crate::texture::mip_levels`], whose level sizes are the same shifts of the
/// image's own size, so it fits) in its top-left corner, the rest zero; where the
/// image's chain is shorter than the array's, its last level (the shaders clamp each
/// image's level of detail to its own chain). `width` and `height` are the array's
/// level 0 size. Returns `(width, height, texels)`.
pub fn image_layer_level(
    chain: &[Image],
    k: u32,
    width: u32,
    height: u32,
) -> (u32, u32, Vec<[f32; 4]>) {
    let (w, h) = ((width >> k).max(1), (height >> k).max(1));
    let mut texels = vec![[0.0; 4]; w as usize * h as usize];
    if let Some(image) = chain.get(k as usize - 1).or(chain.last()) {
        for y in 0..image.height.min(h) as usize {
            let row = &image.texels[y * image.width as usize..][..image.width.min(w) as usize];
            let start = y * w as usize;
            texels[start..start + row.len()].copy_from_slice(row);
        }
    }
    (w, h, texels)
}

/// The record of one light.
pub fn light_record(light: &Light) -> GpuLight {
    let record = |position_or_direction: DVec3, kind: u32, power: DVec3| GpuLight {
        position_or_direction: vec3(position_or_direction),
        kind,
        power: vec3(power),
        cos_inner: 0.0,
        spot_direction: [0.0; 3],
        cos_outer: 0.0,
    };
    match light {
        Light::Point {
            position,
            intensity,
        } => record(*position, LIGHT_POINT, *intensity),
        Light::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        } => GpuLight {
            cos_inner: *cos_inner as f32,
            spot_direction: vec3(*direction),
            cos_outer: *cos_outer as f32,
            ..record(*position, LIGHT_SPOT, *intensity)
        },
        Light::Directional {
            direction,
            irradiance,
        } => record(*direction, LIGHT_DIRECTIONAL, *irradiance),
    }
}

/// `FrameUniforms::tan_half_fov_y` and the `FrameUniforms::flags` bit of `camera`'s
/// projection: `tan(fov_y / 2)` and 0 for a pinhole camera, the half view height and
/// [`FLAG_ORTHOGRAPHIC`] for an orthographic one.
pub fn projection_uniforms(camera: &CameraFrame) -> (f64, u32) {
    match camera.orthographic_half_height {
        Some(half_height) => (half_height, FLAG_ORTHOGRAPHIC),
        None => (camera.tan_half_fov_y, 0),
    }
}

/// The constants of a trace of `scene` (in lighting space) with `geometry`, covering
/// the whole image and all its samples with no slots yet: the scheduler fills in the
/// region, sample range, slot count and budget of each trace.
pub fn frame_uniforms(scene: &Scene, geometry: &SceneGeometry) -> FrameUniforms {
    let settings = &scene.render;
    let camera = CameraFrame::new(&scene.camera, settings.width, settings.height);
    let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    // The same stack the CPU reference starts its camera rays with.
    let camera_medium = MediumStack::from_outermost_first(&scene.camera_medium());
    let (tan_half_fov_y, projection_flag) = projection_uniforms(&camera);
    // The camera's ray cone where textures are filtered, else none (level 0): the
    // CPU reference's PreparedScene::cone.
    let (cone, filtering_flag) = match settings.texture_filtering {
        TextureFiltering::None => (PixelCone::default(), 0),
        TextureFiltering::Trilinear => (
            camera.pixel_cone(settings.height, settings.samples_per_pixel),
            FLAG_TEXTURE_FILTERING,
        ),
        TextureFiltering::Anisotropic => (
            camera.pixel_cone(settings.height, settings.samples_per_pixel),
            FLAG_TEXTURE_FILTERING | FLAG_ANISOTROPIC_TEXTURES,
        ),
    };
    FrameUniforms {
        eye: vec3(camera.eye),
        tan_half_fov_y: tan_half_fov_y as f32,
        forward: vec3(camera.forward),
        aspect: camera.aspect as f32,
        right: vec3(camera.right),
        width: settings.width,
        up: vec3(camera.up),
        height: settings.height,
        background: vec3(scene.environment.background),
        samples_per_pixel: settings.samples_per_pixel,
        ambient: vec3(scene.environment.ambient),
        max_depth: settings.max_depth,
        camera_medium_iors: camera_medium.iors.map(|ior| ior as f32),
        camera_medium_depth: camera_medium.depth,
        plane_count: count(geometry.planes.len()),
        node_count: count(geometry.bvh.wide.len()),
        light_count: count(scene.lights.len()),
        region_x: 0,
        region_y: 0,
        region_width: settings.width,
        region_height: settings.height,
        target_x: 0,
        target_y: 0,
        first_sample: 0,
        end_sample: settings.samples_per_pixel,
        slot_count: 0,
        stack_size: settings.stack_size,
        iteration_budget: u32::MAX,
        flags: projection_flag | filtering_flag,
        offset_scale: geometry.offset_scale as f32,
        min_ray_weight: settings.min_ray_weight as f32,
        static_pixels: 0,
        lens_radius: camera.lens_radius as f32,
        focus_distance: camera.focus_distance as f32,
        cone_width: cone.width as f32,
        cone_spread: cone.spread as f32,
        _pad: 0,
    }
}

#[cfg(test)]
mod tests {
    use bytemuck::Zeroable;

    use super::*;
    use crate::accel::WideChild;
    use crate::scene::{Camera, Environment, LightingSpace, RenderSettings, Shape};

    fn scene(shapes: Vec<Shape>, lights: Vec<Light>) -> Scene {
        Scene {
            render: RenderSettings {
                width: 40,
                height: 20,
                samples_per_pixel: 4,
                max_depth: 3,
                stack_size: 4,
                lighting_space: LightingSpace::Linear,
                min_ray_weight: 0.0,
                integrator: crate::scene::Integrator::Whitted,
                texture_filtering: crate::scene::TextureFiltering::Trilinear,
            },
            camera: Camera {
                eye: DVec3::new(0.0, 0.0, 5.0),
                look_at: DVec3::ZERO,
                up: DVec3::Y,
                fov_y_degrees: 60.0,
                orthographic_half_height: None,
                lens: None,
            },
            environment: Environment {
                background: DVec3::new(0.1, 0.2, 0.3),
                ambient: DVec3::ZERO,
                map: None,
            },
            materials: vec![Material::lambert(DVec3::splat(0.5))],
            material_names: vec!["grey".into()],
            lights,
            shapes,
            meshes: vec![],
            images: vec![],
        }
    }

    fn polygon(vertices: &[DVec3], material: u32) -> PolygonShape {
        PolygonShape {
            plane: crate::scene::polygon_plane(vertices).unwrap_or(crate::scene::PolygonPlane {
                normal: DVec3::ZERO,
                offset: 0.0,
                dropped_axis: 2,
            }),
            vertices: vertices.to_vec(),
            material,
        }
    }

    #[test]
    fn polygon_in_xz_plane_drops_y() {
        // Counter-clockwise seen from +y: normal +y.
        let square = vec![
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 1.0),
            DVec3::new(1.0, 2.0, 1.0),
            DVec3::new(1.0, 2.0, 0.0),
        ];
        let rec = polygon_record(&polygon(&square, 3), 7);
        assert_eq!(rec.normal, [0.0, 1.0, 0.0]);
        assert_eq!(rec.offset, 2.0);
        assert_eq!(rec.dropped_axis, 1);
        assert_eq!(
            (rec.first_vertex, rec.vertex_count, rec.material),
            (7, 4, 3)
        );
    }

    #[test]
    fn concave_polygon_normal_and_axis() {
        // An L shape in a tilted plane mostly facing +x (x = 0.1 z + 1).
        let pts = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let l: Vec<DVec3> = pts
            .iter()
            .map(|&(y, z)| DVec3::new(0.1 * z + 1.0, y, z))
            .collect();
        let rec = polygon_record(&polygon(&l, 0), 0);
        let n = DVec3::new(
            f64::from(rec.normal[0]),
            f64::from(rec.normal[1]),
            f64::from(rec.normal[2]),
        );
        let expected = DVec3::new(1.0, 0.0, -0.1).normalize();
        assert!((n - expected).length() < 1e-6, "{n}");
        assert_eq!(rec.dropped_axis, 0);
        for v in &l {
            assert!((n.dot(*v) - f64::from(rec.offset)).abs() < 1e-5);
        }
    }

    #[test]
    fn polygon_record_drops_the_largest_normal_axis() {
        let tilted = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(1.0, 0.3, 1.0),
            DVec3::new(0.0, 0.2, 1.0),
        ];
        let record = polygon_record(&polygon(&tilted, 2), 4);
        assert_eq!(record.dropped_axis, 1);
        assert_eq!(
            (record.first_vertex, record.vertex_count, record.material),
            (4, 4, 2)
        );
        let degenerate = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert_eq!(polygon_record(&polygon(&degenerate, 0), 0).normal, [0.0; 3]);
    }

    #[test]
    fn empty_lists_get_one_padding_record_and_counts_stay_zero() {
        let s = scene(vec![], vec![]);
        let geometry = SceneGeometry::new(&s);
        let records = SceneRecords::new(&s, &geometry);
        assert!(records.spheres.is_empty() && records.lights.is_empty());
        let padded = records.padded();
        assert_eq!(padded.spheres, vec![GpuSphere::zeroed()]);
        assert_eq!(padded.planes.len(), 1);
        assert_eq!(padded.polygons.len(), 1);
        assert_eq!(padded.polygon_points, vec![[0.0; 2]]);
        assert_eq!(padded.triangles.len(), 1);
        assert_eq!(padded.lights.len(), 1);
        assert_eq!(padded.bvh_nodes.len(), 1);
        assert_eq!(padded.bvh_prims.len(), 1);
        assert_eq!(padded.materials.len(), 1, "the scene's one material");
        let frame = frame_uniforms(&s, &geometry);
        assert_eq!(
            (frame.plane_count, frame.node_count, frame.light_count),
            (0, 0, 0)
        );
    }

    #[test]
    fn shapes_lights_and_frame_are_converted() {
        let tri = [DVec3::X, DVec3::Y, DVec3::Z];
        let square = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let s = scene(
            vec![
                Shape::Sphere {
                    center: DVec3::new(1.0, 2.0, 3.0),
                    radius: 0.5,
                    material: 0,
                },
                Shape::Polygon {
                    vertices: square.clone(),
                    material: 0,
                },
                Shape::Triangle {
                    vertices: tri,
                    material: 0,
                },
                Shape::Polygon {
                    vertices: square[..3].to_vec(),
                    material: 0,
                },
                Shape::Plane {
                    normal: DVec3::Y,
                    offset: -1.0,
                    material: 0,
                },
            ],
            vec![
                Light::Point {
                    position: DVec3::new(0.0, 5.0, 0.0),
                    intensity: DVec3::splat(10.0),
                },
                Light::Directional {
                    direction: DVec3::NEG_Y,
                    irradiance: DVec3::ONE,
                },
            ],
        );
        let geometry = SceneGeometry::new(&s);
        let r = SceneRecords::new(&s, &geometry);
        // The anchor: the sphere's point nearest the origin, 0.5 from (1, 2, 3) towards it.
        let towards_origin = -DVec3::new(1.0, 2.0, 3.0).normalize();
        let anchor = DVec3::new(1.0, 2.0, 3.0) + towards_origin * 0.5;
        assert_eq!(r.spheres[0].anchor, anchor.as_vec3().to_array());
        assert_eq!(r.spheres[0].normal, towards_origin.as_vec3().to_array());
        assert_eq!(r.spheres[0].radius, 0.5);
        assert_eq!(r.planes[0].offset, -1.0);
        assert_eq!(r.polygons.len(), 2);
        assert_eq!(
            (r.polygons[1].first_vertex, r.polygons[1].vertex_count),
            (4, 3)
        );
        assert_eq!(r.polygon_points.len(), 7);
        // The square's plane is z = 0: its points are (x, y).
        assert_eq!(r.polygon_points[5], [1.0, 0.0]);
        assert_eq!(r.polygon_points[2], [1.0, 1.0]);
        assert_eq!(r.polygons[0].dropped_axis, 2);
        assert_eq!(r.triangles[0].v2, [0.0, 0.0, 1.0]);
        assert_eq!(r.lights[0].kind, LIGHT_POINT);
        assert_eq!(r.lights[1].kind, LIGHT_DIRECTIONAL);
        assert_eq!(r.lights[1].position_or_direction, [0.0, -1.0, 0.0]);
        assert_eq!(r.materials[0].kind, MATERIAL_LAMBERT);
        // Four bounded primitives: the tree's leaves reference each once.
        let mut referenced = r.bvh_prims.clone();
        referenced.sort_unstable();
        assert_eq!(referenced.len(), 4);
        assert_eq!(r.bvh_nodes.len(), geometry.bvh.wide.len());
        let f = frame_uniforms(&s, &geometry);
        assert_eq!(
            (f.width, f.height, f.samples_per_pixel, f.max_depth),
            (40, 20, 4, 3)
        );
        assert_eq!((f.plane_count, f.light_count), (1, 2));
        assert_eq!(f.node_count as usize, geometry.bvh.wide.len());
        assert_eq!((f.region_width, f.region_height, f.end_sample), (40, 20, 4));
        assert_eq!(f.aspect, 2.0);
        assert_eq!(f.forward, [0.0, 0.0, -1.0]);
        assert_eq!(f.background, [0.1, 0.2, 0.3]);
    }

    /// A BRDF map's layer carries its inverse-CDF table in alpha, every other image its
    /// own texels; the colour channels are the images'.
    #[test]
    fn brdf_map_layers_carry_their_inverse_cdf_in_alpha() {
        let image = |width: u32, height: u32, value: f32| Image {
            path: "test".into(),
            width,
            height,
            texels: (0..width * height)
                .map(|i| [value * i as f32, value, value, 1.0])
                .collect(),
        };
        let images = [image(4, 2, 0.5), image(3, 3, 0.25)];
        let map = Material {
            brdf_map: Some(1),
            ..Material::blank(MaterialKind::Tabulated)
        };
        let cdfs = BrdfMapCdfs::new(&images, &[map]);
        let table = cdfs.of_image(1).expect("the map's table");
        let (width, height, layers, texels) = image_layers(&images, &cdfs);
        assert_eq!((width, height, layers), (4, 3, 2));
        let texel = |layer: usize, x: usize, y: usize| texels[(layer * 3 + y) * 4 + x];
        assert_eq!(texel(0, 3, 1), images[0].texel(3, 1));
        for y in 0..3 {
            for x in 0..3 {
                let t = texel(1, x, y);
                assert_eq!(&t[..3], &images[1].texel(x as u32, y as u32)[..3]);
                assert_eq!(t[3], table.value(x as u32, y as u32));
            }
        }
        assert_eq!(texel(1, 2, 2)[3], 1.0);
        assert!(texel(1, 1, 0)[3] > 0.0 && texel(1, 1, 0)[3] < 1.0);
    }

    #[test]
    fn material_kinds_map_to_constants() {
        for (kind, code) in [
            (MaterialKind::Lambert, MATERIAL_LAMBERT),
            (MaterialKind::BlinnPhong, MATERIAL_BLINN_PHONG),
            (MaterialKind::Mirror, MATERIAL_MIRROR),
            (MaterialKind::Dielectric, MATERIAL_DIELECTRIC),
            (MaterialKind::Emissive, MATERIAL_EMISSIVE),
        ] {
            let mut m = Material::blank(kind);
            m.ior = 1.5;
            m.emission = DVec3::new(1.0, 2.0, 3.0);
            let rec = material_record(&m, &[]);
            assert_eq!(rec.kind, code);
            assert_eq!(rec.ior, 1.5);
            assert_eq!(rec.emission, [1.0, 2.0, 3.0]);
            assert_eq!(rec.transmittance, [1.0; 3]);
        }
    }

    #[test]
    fn instances_become_node_records_and_shifted_trees() {
        let mut s = scene(vec![], vec![]);
        s.materials.push(Material::lambert(DVec3::splat(0.9)));
        let mesh = crate::scene::Mesh {
            name: "tri".into(),
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            normals: Some(vec![DVec3::Z; 3]),
            uvs: None,
            uvs1: None,
            colors: None,
            tangents: None,
            triangles: vec![[0, 1, 2]],
            material: 1,
            instances: vec![
                glam::DMat4::from_translation(DVec3::new(3.0, 0.0, 0.0)),
                glam::DMat4::from_scale(DVec3::new(-1.0, 2.0, 1.0)),
            ],
        };
        s.meshes.push(mesh);
        let geometry = SceneGeometry::new(&s);
        assert_eq!(geometry.instances.len(), 2);
        let r = SceneRecords::new(&s, &geometry);
        // The mesh's one triangle and its attributes, once.
        assert_eq!((r.triangles.len(), r.triangle_attributes.len()), (1, 1));
        assert_eq!(r.triangles[0].attributes, 0);
        let world_nodes = geometry.bvh.wide.len();
        let mesh_nodes = geometry.instanced_meshes[0].bvh.wide.len();
        assert_eq!(
            r.bvh_nodes.len(),
            world_nodes + mesh_nodes + 2 * INSTANCE_RECORD_NODES
        );
        // The mesh's leaf names the triangle at its place in the triangle list.
        let WideChild::Leaf { first, .. } = r.bvh_nodes[world_nodes].child(0) else {
            panic!("the mesh's root holds its leaf");
        };
        let prim = PrimRef(r.bvh_prims[first as usize]);
        assert_eq!((prim.kind(), prim.index()), (PrimKind::Triangle, 0));
        // The scene's tree names each instance by its records' node index.
        let mut records: Vec<usize> = r.bvh_prims[..geometry.bvh.prims.len()]
            .iter()
            .map(|&p| PrimRef(p))
            .filter(|p| p.kind() == PrimKind::Instance)
            .map(PrimRef::index)
            .collect();
        records.sort_unstable();
        let first = world_nodes + mesh_nodes;
        assert_eq!(records, [first, first + INSTANCE_RECORD_NODES]);
        let second = &r.bvh_nodes[first + INSTANCE_RECORD_NODES..];
        assert_eq!(
            second[0].exponents as usize, world_nodes,
            "the mesh tree's root"
        );
        assert_eq!(second[0].spare_low, 1, "the material");
        assert_eq!(second[0].spare_high, 1, "mirrored");
        assert_eq!(
            second[0].origin,
            [-1.0, 0.0, 0.0],
            "object_to_world's x column"
        );
        assert_eq!(
            second[1].low.map(f32::from_bits),
            [0.0, 0.5, 0.0],
            "world_to_object's y column"
        );
    }

    #[test]
    fn far_texture_coordinates_move_by_even_repeats_and_keep_their_side() {
        let v = |x: f64, y: f64| DVec2::new(x, y);
        // Near the origin nothing moves.
        let near = [v(-0.5, 0.2), v(1.5, 1.9), v(0.0, -0.9)];
        assert_eq!(uvs_near_origin(near), near);
        for offset in [1e5, 1e7, 3.5, -1e5, -2.25] {
            let far = [
                v(offset, offset),
                v(offset + 0.5, offset),
                v(offset, offset + 0.25),
            ];
            let moved = uvs_near_origin(far);
            for (a, b) in far.iter().zip(&moved) {
                let shift = *a - *b;
                // A whole even number of repeats...
                assert_eq!(shift.x % 2.0, 0.0, "{offset}: {shift}");
                assert_eq!(shift.y % 2.0, 0.0, "{offset}: {shift}");
                // ... to within a few repeats of the origin, on the same side of [0, 1].
                assert!(b.x.abs() < 5.0 && b.y.abs() < 5.0, "{offset}: {b}");
                assert_eq!(a.x > 1.0, b.x > 1.0, "{offset}");
                assert_eq!(a.x < 0.0, b.x < 0.0, "{offset}");
            }
        }
    }
}
