//! Importers for model files made by other tools: Wavefront OBJ with its MTL material
//! libraries, and glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`).
//!
//! An importer reads a file into an [`ImportedModel`]: renderer-independent meshes,
//! materials already mapped onto our [`Material`] models, the textures they use, lights
//! and the file's camera, everything in world space and in our units. How each file
//! format's fields map onto ours is tabulated in `docs/models.md`.
//!
//! A mesh that a glTF file places under several nodes is stored once, with one
//! transform per placement ([`ImportedMesh::instances`]), so that a renderer can instance
//! it; [`ImportedModel::world_triangles`] flattens the instances into world-space
//! triangles for a renderer that cannot. [`ImportedModel::camera_or_default`] and
//! [`ImportedModel::lights_or_default`] frame a model that brings no camera or lights of
//! its own ([`default_camera`], [`default_lights`]).
//!
//! Every failure is a [`SceneError`] naming the file, the place (the 1-based line and
//! column in OBJ and MTL files) and the element (mesh, primitive, node, material,
//! texture); the importers never panic on bad input. Problems that do not stop the model
//! from rendering (skipped degenerate triangles, ignored features) are collected in
//! [`ImportedModel::warnings`].
//!
//! ```no_run
//! use gpu_render::scene::import::import_model;
//!
//! let model = import_model("scenes/models/vase.gltf".as_ref())?;
//! for warning in &model.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! let camera = model.camera_or_default(4.0 / 3.0);
//! let triangles: Vec<_> = model.world_triangles().collect();
//! println!("{} triangles seen from {:?}", triangles.len(), camera.eye);
//! # Ok::<(), gpu_render::scene::SceneError>(())
//! ```

mod accessor;
mod framing;
mod gltf;
mod mesh;
mod obj;
mod place;
mod tangents;
mod texture;

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec2, DVec3};

pub use self::framing::{DEFAULT_FOV_Y_DEGREES, default_camera, default_lights};
pub use self::gltf::{LUMENS_PER_WATT, import_gltf, import_gltf_with, parse_gltf};
use self::mesh::Budget;
pub use self::obj::{DEFAULT_OBJ_ALBEDO, import_obj, import_obj_with, parse_obj};
pub use self::place::{MODEL_BACKGROUND, ModelPlacement, is_model_path};
use super::{Camera, Image, Light, Material, SceneError, TextureTransform};

/// Largest model file (OBJ, MTL, glTF, GLB or external glTF buffer) accepted, in bytes
/// (512 MiB); a larger one is refused before it is read.
pub const MAX_MODEL_FILE_BYTES: u64 = 512 * 1024 * 1024;
/// Largest accepted number of vertices over all meshes of a model (each stored once,
/// however often it is instanced).
pub const MAX_MODEL_VERTICES: usize = 16 * 1024 * 1024;
/// Largest accepted number of triangles over all meshes of a model (each stored once).
pub const MAX_MODEL_TRIANGLES: usize = 16 * 1024 * 1024;
/// Largest accepted number of mesh placements (glTF nodes with a mesh, summed over the
/// meshes' primitives).
pub const MAX_MODEL_INSTANCES: usize = 1024 * 1024;
/// Largest accepted number of texels over all the textures of a model (2^27: 2 GiB of
/// linear RGBA `f32`). Each texture is also limited to
/// [`MAX_IMAGE_SIDE`](crate::scene::MAX_IMAGE_SIDE) texels a side.
pub const MAX_MODEL_TEXELS: u64 = 1 << 27;

/// A model read from a file: meshes, materials, textures, lights and camera, all in world
/// space and our units.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedModel {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// The geometry. Each mesh has one material; a glTF mesh of several primitives
    /// becomes one [`ImportedMesh`] per primitive.
    pub meshes: Vec<ImportedMesh>,
    /// The materials, indexed by [`ImportedMesh::material`]. Never empty when there is a
    /// mesh: geometry without a material gets a default one (white-ish Lambert).
    pub materials: Vec<ImportedMaterial>,
    /// The textures, indexed by [`TextureRef::image`], in linear RGBA `f32` (colour
    /// textures are linearised from sRGB on load; data textures hold the file's values).
    pub images: Vec<Image>,
    /// The model's own lights (glTF `KHR_lights_punctual`), in our units (see
    /// [`LUMENS_PER_WATT`]). Empty when the file has none; see
    /// [`ImportedModel::lights_or_default`].
    pub lights: Vec<Light>,
    /// The model's own camera (the first glTF perspective camera placed by a node).
    pub camera: Option<ImportedCamera>,
    /// Problems that did not stop the import, each naming the file and the element.
    pub warnings: Vec<String>,
}

/// One mesh with a single material, in its own (object) space, stored once however often
/// it is placed.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedMesh {
    /// Where it came from, for messages: the OBJ object/group name, or the glTF mesh
    /// name (or index) and primitive index.
    pub name: String,
    /// Vertex positions in object space (all finite).
    pub positions: Vec<DVec3>,
    /// Per-vertex normals in object space, unit length, parallel to `positions`, when the
    /// file gives them for every vertex.
    pub normals: Option<Vec<DVec3>>,
    /// Per-vertex texture coordinates (glTF `TEXCOORD_0`, OBJ `vt`), parallel to
    /// `positions`, when the file gives them for every vertex. `v` grows downwards
    /// (glTF's convention and our textures'; OBJ's upward `v` is flipped to `1 - v` on
    /// import), so `(0, 0)` is the first texel of the image's top row.
    pub uvs: Option<Vec<DVec2>>,
    /// A second set of texture coordinates (glTF `TEXCOORD_1`, read when a texture of
    /// the mesh's material asks for it), like `uvs`.
    pub uvs1: Option<Vec<DVec2>>,
    /// Linear RGBA vertex colours in [0, 1] (glTF `COLOR_0`, OBJ `v x y z r g b` with
    /// alpha 1), parallel to `positions`: the colour multiplies the material's albedo,
    /// the alpha its alpha.
    pub colors: Option<Vec<glam::DVec4>>,
    /// Unit tangents with the bitangent's handedness in `w` (±1), parallel to
    /// `positions`, for a normal map: glTF `TANGENT`, or MikkTSpace's.
    pub tangents: Option<Vec<glam::DVec4>>,
    /// Triangles as indices into `positions`, counter-clockwise seen from the front (the
    /// side the right-hand-rule normal points to). Degenerate triangles were dropped.
    pub triangles: Vec<[u32; 3]>,
    /// Index into [`ImportedModel::materials`].
    pub material: u32,
    /// Object-to-world transforms, one per placement of the mesh (at least one; OBJ
    /// meshes have exactly the identity). Each is finite and invertible.
    pub instances: Vec<DMat4>,
}

/// A material mapped onto our models, with the textures it uses.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedMaterial {
    /// The file's name for it (or `material N` / `default`).
    pub name: String,
    /// The material as our renderers understand it; every value is within the ranges the
    /// scene format accepts (`docs/scene-format.md`). Its `albedo_texture` is `None`:
    /// textures are referenced by the fields below and indexed into
    /// [`ImportedModel::images`], and they are addressed by the meshes' UVs, not by one of
    /// the scene format's [`TextureMapping`](crate::scene::TextureMapping)s.
    pub material: Material,
    /// A colour texture multiplying `material.diffuse` (the Lambert/Blinn-Phong albedo or
    /// the PBR base colour), as glTF's `baseColorTexture` and MTL's `map_Kd`.
    pub base_color_texture: Option<TextureRef>,
    /// glTF's `metallicRoughnessTexture`: a data texture whose green channel multiplies
    /// `material.roughness` and blue channel multiplies `material.metallic`.
    pub metallic_roughness_texture: Option<TextureRef>,
    /// glTF's `emissiveTexture`: a colour texture multiplying `material.emission`.
    pub emissive_texture: Option<TextureRef>,
    /// glTF's `normalTexture`: a tangent-space normal map (linear data), with its
    /// `scale` in `material.normal_scale`.
    pub normal_texture: Option<TextureRef>,
}

/// A material's use of a texture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureRef {
    /// Index into [`ImportedModel::images`].
    pub image: u32,
    /// How `u` outside [0, 1] wraps (glTF sampler `wrapS`; MTL `-clamp`).
    pub wrap_u: WrapMode,
    /// How `v` outside [0, 1] wraps (glTF sampler `wrapT`; MTL `-clamp`).
    pub wrap_v: WrapMode,
    /// Which texture coordinate set it reads (glTF `texCoord`, 0 or 1) and how they
    /// are transformed (`KHR_texture_transform`); the identity on set 0 for OBJ.
    pub transform: TextureTransform,
}

/// How texture coordinates outside [0, 1] are brought back into the image (glTF 2.0
/// §3.8.4.3, the OpenGL wrap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WrapMode {
    /// The image repeats (`REPEAT`, glTF's default and MTL's).
    #[default]
    Repeat,
    /// Coordinates are clamped to the edge texels (`CLAMP_TO_EDGE`, MTL `-clamp on`).
    ClampToEdge,
    /// The image repeats, every other copy mirrored (`MIRRORED_REPEAT`).
    MirroredRepeat,
}

/// A camera found in a model file.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedCamera {
    /// The file's name for it (or `camera N`).
    pub name: String,
    /// The pinhole camera in world space.
    pub camera: Camera,
    /// Width over height the file asks for (glTF `aspectRatio`), when it says.
    pub aspect_ratio: Option<f64>,
}

/// One triangle of a model in world space: a mesh triangle under one of its instance
/// transforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldTriangle {
    /// The corners in world space, counter-clockwise seen from the front.
    pub vertices: [DVec3; 3],
    /// The corners' unit normals in world space (transformed by the inverse transpose),
    /// when the mesh has normals.
    pub normals: Option<[DVec3; 3]>,
    /// The corners' texture coordinates, when the mesh has them.
    pub uvs: Option<[DVec2; 3]>,
    /// Index into [`ImportedModel::materials`].
    pub material: u32,
}

impl WorldTriangle {
    /// Whether the triangle has (nearly) no area relative to its longest edge, by the
    /// scene format's rule for triangles: such a triangle (a mesh triangle squashed by a
    /// transform, or one whose coordinates lost their size in `f64`) should be skipped.
    pub fn is_degenerate(&self) -> bool {
        mesh::is_degenerate(self.vertices)
    }
}

impl ImportedModel {
    /// An empty model read from `path`.
    fn empty(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            meshes: Vec::new(),
            materials: Vec::new(),
            images: Vec::new(),
            lights: Vec::new(),
            camera: None,
            warnings: Vec::new(),
        }
    }

    /// The number of triangles in world space: each mesh's triangles times its instances
    /// (what [`ImportedModel::world_triangles`] yields). Check it against a renderer's
    /// limit before flattening.
    pub fn world_triangle_count(&self) -> u64 {
        self.meshes
            .iter()
            .map(|m| m.triangles.len() as u64 * m.instances.len() as u64)
            .sum()
    }

    /// Every triangle of every instance in world space, mesh by mesh, instance by
    /// instance, in file order. Lazy: nothing is allocated for the whole model.
    pub fn world_triangles(&self) -> impl Iterator<Item = WorldTriangle> + '_ {
        self.meshes.iter().flat_map(|mesh| {
            mesh.instances.iter().flat_map(move |transform| {
                let normal_matrix = transform.inverse().transpose();
                mesh.triangles.iter().map(move |&[a, b, c]| {
                    let corners = [a as usize, b as usize, c as usize];
                    WorldTriangle {
                        vertices: corners.map(|i| transform.transform_point3(mesh.positions[i])),
                        normals: mesh.normals.as_ref().map(|normals| {
                            corners.map(|i| {
                                normal_matrix
                                    .transform_vector3(normals[i])
                                    .normalize_or_zero()
                            })
                        }),
                        uvs: mesh.uvs.as_ref().map(|uvs| corners.map(|i| uvs[i])),
                        material: mesh.material,
                    }
                })
            })
        })
    }

    /// The axis-aligned box `(min, max)` around the model in world space, or `None` for a
    /// model without triangles. Conservative for rotated instances: each instance
    /// contributes the transformed corners of its mesh's own box.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let mut bounds: Option<(DVec3, DVec3)> = None;
        for mesh in &self.meshes {
            let Some((low, high)) = mesh::local_bounds(mesh) else {
                continue;
            };
            for transform in &mesh.instances {
                for corner in 0..8 {
                    let pick = |bit: u32, l: f64, h: f64| if corner & bit == 0 { l } else { h };
                    let local = DVec3::new(
                        pick(1, low.x, high.x),
                        pick(2, low.y, high.y),
                        pick(4, low.z, high.z),
                    );
                    let world = transform.transform_point3(local);
                    bounds = Some(match bounds {
                        None => (world, world),
                        Some((min, max)) => (min.min(world), max.max(world)),
                    });
                }
            }
        }
        bounds
    }

    /// The model's own camera, or [`default_camera`] framing its bounds for an image of
    /// `aspect` (width over height); a model without triangles is looked at from
    /// `(0, 0, 5)`.
    pub fn camera_or_default(&self, aspect: f64) -> Camera {
        match &self.camera {
            Some(camera) => camera.camera,
            None => default_camera(self.bounds(), aspect),
        }
    }

    /// The model's own lights, or the [`default_lights`] rig when it has none.
    pub fn lights_or_default(&self) -> Vec<Light> {
        if self.lights.is_empty() {
            default_lights()
        } else {
            self.lights.clone()
        }
    }
}

/// How a model is imported ([`import_model_with`]): a cap on the memory the import
/// may take, and a progress hook for long reads.
#[derive(Clone, Copy, Default)]
pub struct ImportOptions<'a> {
    /// The most bytes the import may hold at once: the file and its buffers as read,
    /// the meshes' arrays as they are built (64 bytes a vertex, 12 a triangle) and the
    /// textures as decoded (16 bytes a texel). Checked before each large allocation
    /// (a file by its size before it is read, a texture by its header before it is
    /// decoded) and as an OBJ file's arrays grow, so that a model too large is refused
    /// before it takes the memory. `None`: only the fixed limits
    /// ([`MAX_MODEL_VERTICES`], ...).
    pub max_bytes: Option<u64>,
    /// Called as the model file is read, with the bytes read so far and the file's size
    /// (at most every mebibyte).
    pub progress: Option<&'a (dyn Fn(u64, u64) + Sync)>,
}

impl std::fmt::Debug for ImportOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ImportOptions")
            .field("max_bytes", &self.max_bytes)
            .field("progress", &self.progress.is_some())
            .finish()
    }
}

/// Reads the model at `path`, choosing the importer by the file extension
/// (case-insensitive): `.obj` ([`import_obj`]), `.gltf` or `.glb` ([`import_gltf`]).
pub fn import_model(path: &Path) -> Result<ImportedModel, SceneError> {
    import_model_with(path, &ImportOptions::default())
}

/// [`import_model`] with `options`: a memory cap and a progress hook.
pub fn import_model_with(
    path: &Path,
    options: &ImportOptions<'_>,
) -> Result<ImportedModel, SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("obj") => import_obj_with(path, options),
        Some("gltf" | "glb") => import_gltf_with(path, options),
        _ => Err(SceneError::unsupported(
            path,
            None,
            "not a model file this program reads: the name must end in .obj, .gltf or .glb",
        )),
    }
}

/// An error about `path` with no line.
fn error(path: &Path, message: impl Into<String>) -> SceneError {
    SceneError::invalid(path, None, message)
}

/// Reads a whole file (a model, a material library or a buffer), refusing anything
/// but a regular file (judged on the opened file: a FIFO or a device behind any name
/// is refused at once) and files larger than [`MAX_MODEL_FILE_BYTES`] or than what
/// `budget` has left (checked by the file's size before it is read). `what` names the
/// file's role in the message ("the model file", "the material library lib.mtl",
/// ...); errors are reported against `report` (the model being imported).
fn read_file(
    path: &Path,
    report: &Path,
    what: &str,
    budget: &mut Budget,
) -> Result<Vec<u8>, SceneError> {
    let fail = |e: crate::input::InputError| error(report, format!("cannot read {what}: {e}"));
    let file = crate::input::open_input(path).map_err(fail)?;
    let length = file
        .metadata()
        .map_err(|e| fail(crate::input::InputError::Io(e)))?
        .len();
    budget
        .charge_bytes(length, &format!("{what} ({length} bytes)"))
        .map_err(|e| e.at(report))?;
    crate::input::read_opened(file, MAX_MODEL_FILE_BYTES).map_err(fail)
}
