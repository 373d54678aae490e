//! glTF 2.0 (Khronos, "glTF 2.0 Specification", 2021), as `.gltf` JSON with external or
//! embedded (data URI) buffers or as binary `.glb`, read through the `gltf` crate (its
//! JSON model and validation; buffers, accessors and images are read here, with every
//! range checked).

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use ::gltf::Document;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::camera::Projection;
use ::gltf::json::validation::Checked;
use ::gltf::khr_lights_punctual::Kind;
use ::gltf::mesh::Mode;
use ::gltf::texture::WrappingMode;
use base64::Engine;
use glam::{DMat4, DQuat, DVec2, DVec3, DVec4};

use super::accessor::{Expect, Normalized, read, view_bytes};
use super::mesh::{Budget, RawMesh, finish_mesh};
use super::texture::{Encoding, Textures};
use super::{
    ImportOptions, ImportedCamera, ImportedMaterial, ImportedMesh, ImportedModel,
    MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES, TextureRef, WrapMode, error, read_file,
};
use crate::echo::{short, short3};
use crate::scene::{
    AlphaMode, Camera, Light, MAX_ORTHOGRAPHIC_HALF_HEIGHT, MAX_RADIANCE, Material, MaterialKind,
    SceneError, TextureTransform,
};

/// Luminous efficacy used to turn `KHR_lights_punctual`'s photometric intensities into
/// our radiometric ones, in lm/W: 683, the peak of the photopic curve at 555 nm (the
/// definition of the candela, SI Brochure §2.3.1). A point or spot light of `I` cd
/// becomes `I / 683` W/sr, a directional light of `E` lux becomes `E / 683` W/m², each
/// times the light's linear `color`. This treats every light as if all its power were at
/// 555 nm, the convention of Blender's glTF exporter in its "Standard" lighting mode.
pub const LUMENS_PER_WATT: f64 = 683.0;

/// The extensions this importer understands; a file that requires any other is refused.
const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];
/// `KHR_mesh_quantization`, which widens the component types of vertex attributes.
const MESH_QUANTIZATION: &str = "KHR_mesh_quantization";
/// Component types of `POSITION`: `FLOAT` (glTF 2.0 §3.7.2.1), and under
/// `KHR_mesh_quantization` (its table "Extending Mesh Attributes") signed and unsigned
/// bytes and shorts, normalized or not.
const POSITION_TYPES: &[DataType] = &[
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];
/// Component types of `NORMAL`: `FLOAT`, and under `KHR_mesh_quantization` normalized
/// signed bytes and shorts.
const NORMAL_TYPES: &[DataType] = &[DataType::F32, DataType::I8, DataType::I16];
/// Component types of `TEXCOORD_n`: `FLOAT` and normalized unsigned bytes and shorts
/// (glTF 2.0 §3.7.2.1), and under `KHR_mesh_quantization` also signed ones and both
/// not normalized.
const TEXCOORD_TYPES: &[DataType] = &[
    DataType::F32,
    DataType::I8,
    DataType::U8,
    DataType::I16,
    DataType::U16,
];
/// Largest offset or scale (in size) of a `KHR_texture_transform` (or an MTL texture's
/// `-o` and `-s`) accepted: beyond it an `f32` texture coordinate keeps less than 1/16
/// of a repeat.
pub(super) const MAX_TEXTURE_TRANSFORM: f64 = 1e6;
/// Component types of `COLOR_0`: `FLOAT` and normalized unsigned bytes and shorts
/// (glTF 2.0 §3.7.2.1).
const COLOR_TYPES: &[DataType] = &[DataType::F32, DataType::U8, DataType::U16];
/// Index of refraction of `KHR_materials_ior`'s default (and of glass without it).
const DEFAULT_IOR: f64 = 1.5;
/// glTF's `alphaCutoff` where a `MASK` material gives none (glTF 2.0 §3.9.4).
const DEFAULT_ALPHA_CUTOFF: f32 = 0.5;
/// Most validation problems quoted in one error message.
const QUOTED_PROBLEMS: usize = 5;

/// Reads the glTF 2.0 file at `path`: JSON (`.gltf`, with buffers and images in
/// external files relative to it or embedded as data URIs) or binary (`.glb`), told
/// apart by content.
///
/// Fails, naming the file and the element (buffer, accessor, mesh and primitive, node,
/// material, texture, camera, light), on a missing, truncated or malformed file, a
/// glTF 1.0 file, extensions it requires that are not supported (all named at once;
/// Draco and meshopt compression with how to decompress), a file whose primitives are
/// all points or lines, an index or range out of bounds, a non-finite position or
/// transform, a node matrix that is projective or given beside translation, rotation or
/// scale, a texture that does not load, or a model beyond the size limits.
pub fn import_gltf(path: &Path) -> Result<ImportedModel, SceneError> {
    import_gltf_with(path, &ImportOptions::default())
}

/// [`import_gltf`] with `options`: the file, its buffers, meshes and textures are
/// counted against [`ImportOptions::max_bytes`] before they are allocated.
pub fn import_gltf_with(
    path: &Path,
    options: &ImportOptions<'_>,
) -> Result<ImportedModel, SceneError> {
    let mut budget = Budget::new(options.max_bytes);
    let bytes = read_file(path, path, "the model file", &mut budget)?;
    if let Some(progress) = options.progress {
        progress(bytes.len() as u64, bytes.len() as u64);
    }
    parse_gltf_within(&bytes, path, budget)
}

/// Reads glTF or GLB from `bytes`; `path` names the file in messages and its directory
/// is where external buffers and images are looked up.
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<ImportedModel, SceneError> {
    parse_gltf_within(bytes, path, Budget::default())
}

/// [`parse_gltf`] counting what it reads against `budget`.
fn parse_gltf_within(
    bytes: &[u8],
    path: &Path,
    budget: Budget,
) -> Result<ImportedModel, SceneError> {
    // glTF JSON must not start with a byte-order mark (§3.2), but some writers add one.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if bytes.is_empty() {
        return Err(error(path, "not a valid glTF file: the file is empty"));
    }
    if let Some(why) = gltf1_binary(bytes) {
        return Err(gltf1_error(path, why));
    }
    let gltf = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        // A glTF 1.0 file fails to parse as 2.0 (its top-level arrays were objects);
        // say what it is rather than where the 2.0 parser stopped.
        match gltf1_json(bytes) {
            Some(why) => gltf1_error(path, why),
            None => parse_error(path, e),
        }
    })?;
    let version = &gltf.as_json().asset.version;
    if version.starts_with("1.") {
        return Err(gltf1_error(path, format!("asset.version is \"{version}\"")));
    }
    if !version.starts_with("2.") {
        return Err(error(
            path,
            format!("glTF version {version} is not supported (only 2.x)"),
        ));
    }
    let unsupported: Vec<&str> = gltf
        .extensions_required()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if !unsupported.is_empty() {
        return Err(error(path, unsupported_extensions(&unsupported)));
    }
    validate(&gltf.document, path)?;
    let mut importer = Importer {
        path,
        directory: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        document: &gltf.document,
        buffers: Vec::new(),
        model: ImportedModel::empty(path),
        budget,
        textures: Textures::default(),
        materials: HashMap::new(),
        warned: BTreeSet::new(),
        not_triangles: Vec::new(),
        triangle_primitives: 0,
        vertex_colors: Vec::new(),
    };
    for extension in gltf.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&extension) {
            importer.warn(format!(
                "uses the extension {extension}, which is not supported; what it adds is ignored"
            ));
        }
    }
    importer.buffers = load_buffers(
        &gltf.document,
        gltf.blob.as_deref(),
        path,
        &importer.directory,
        &mut importer.budget,
    )?;
    importer.import()?;
    let mut model = importer.model;
    model.images = importer.textures.images;
    Ok(model)
}

/// Draco mesh compression (`KHR_draco_mesh_compression`), which is not decoded here.
const DRACO: &str = "KHR_draco_mesh_compression";
/// meshoptimizer's buffer compression, as a vendor extension and as ratified by Khronos;
/// not decoded here.
const MESHOPT: &[&str] = &["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// The message for a file that requires the `unsupported` extensions (at least one):
/// all of them at once, and for a compression what to do about it.
fn unsupported_extensions(unsupported: &[&str]) -> String {
    let list = unsupported.join(", ");
    let supported = SUPPORTED_EXTENSIONS.join(", ");
    let mut message = if let [_] = unsupported {
        format!(
            "the file requires the extension {list}, which is not supported (supported: {supported})"
        )
    } else {
        format!(
            "the file requires {} extensions that are not supported: {list} (supported: {supported})",
            unsupported.len()
        )
    };
    for &extension in unsupported {
        if extension == DRACO {
            message += &format!(
                ". Its meshes are Draco-compressed ({extension}), and Draco mesh compression is not supported: decompress the file first, e.g. with `gltf-transform cp IN OUT` (glTF Transform decodes Draco on reading)"
            );
        } else if MESHOPT.contains(&extension) {
            message += &format!(
                ". Its buffers are meshopt-compressed ({extension}), and meshopt compression is not supported: decompress the file first, e.g. with `gltfpack -i IN -o OUT` (gltfpack compresses only when given -c)"
            );
        }
    }
    message
}

/// Why `bytes` is a binary glTF 1.0 file (a GLB container of version 1, the
/// `KHR_binary_glTF` extension of glTF 1.0), if it is one.
fn gltf1_binary(bytes: &[u8]) -> Option<String> {
    let version = bytes.strip_prefix(b"glTF")?.get(..4)?;
    (u32::from_le_bytes([version[0], version[1], version[2], version[3]]) == 1)
        .then(|| "a GLB container of version 1, glTF 1.0's KHR_binary_glTF".to_string())
}

/// Why the JSON `bytes` are a glTF 1.0 document, if they are one: `asset.version` "1.x",
/// or (1.0 files often leave `version` out) top-level properties that glTF 1.0 made
/// objects keyed by id and glTF 2.0 made arrays.
fn gltf1_json(bytes: &[u8]) -> Option<String> {
    let value: ::gltf::json::Value = ::gltf::json::deserialize::from_slice(bytes).ok()?;
    let root = value.as_object()?;
    if let Some(version) = root
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(|v| v.as_str())
        .filter(|v| v.starts_with("1."))
    {
        return Some(format!("asset.version is \"{version}\""));
    }
    ["accessors", "meshes", "nodes", "buffers", "bufferViews"]
        .into_iter()
        .find(|key| root.get(*key).is_some_and(|v| v.is_object()))
        .map(|key| format!("its {key} are an object keyed by id, glTF 1.0's layout"))
}

/// The error for a glTF 1.0 file, `why` saying how it was recognised.
fn gltf1_error(path: &Path, why: String) -> SceneError {
    SceneError::unsupported(
        path,
        None,
        format!(
            "the file is glTF 1.0 ({why}); only glTF 2.0 is read: convert it first, e.g. with gltf-pipeline (`gltf-pipeline -i IN -o OUT`), which updates glTF 1.0 to 2.0"
        ),
    )
}

/// The error for a file the `gltf` crate cannot parse, with the JSON line and column
/// where it knows them.
fn parse_error(path: &Path, e: ::gltf::Error) -> SceneError {
    match e {
        ::gltf::Error::Deserialize(json) if json.line() > 0 => {
            let (line, column) = (json.line(), json.column());
            let text = json.to_string();
            let suffix = format!(" at line {line} column {column}");
            SceneError::syntax(
                path,
                Some((line, column.max(1))),
                format!(
                    "not a valid glTF file: {}",
                    text.strip_suffix(&suffix).unwrap_or(&text)
                ),
            )
        }
        ::gltf::Error::Binary(binary) => SceneError::syntax(
            path,
            None,
            format!("not a valid GLB file (truncated or corrupt): {binary}"),
        ),
        other => SceneError::syntax(path, None, format!("not a valid glTF file: {other}")),
    }
}

/// Runs the `gltf` crate's validation (references in range, required properties present,
/// enumerations valid), which its accessors rely on.
fn validate(document: &Document, path: &Path) -> Result<(), SceneError> {
    use ::gltf::json::validation::Validate;
    let root = document.as_json();
    // gltf-json 1.4's validation indexes the accessors with POSITION's index unchecked
    // (`primitive_validate_hook`), so that index is checked here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(::gltf::Semantic::Positions));
            if let Some(index) = position
                && index.value() >= root.accessors.len()
            {
                return Err(error(
                    path,
                    format!(
                        "not a valid glTF file: meshes[{m}].primitives[{p}].attributes[\"POSITION\"] refers to accessor {}, but there are {} accessors",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    // A file that uses Draco without requiring it must keep uncompressed copies of its
    // meshes (KHR_draco_mesh_compression, "Conformance"); without them its accessors
    // hold no data, and it is Draco that is missing, not just a bufferView.
    if root.extensions_used.iter().any(|e| e == DRACO) {
        let empty: Vec<String> = root
            .accessors
            .iter()
            .enumerate()
            .filter(|(_, a)| a.buffer_view.is_none() && a.sparse.is_none())
            .map(|(i, _)| i.to_string())
            .collect();
        if !empty.is_empty() {
            return Err(error(
                path,
                format!(
                    "the file's meshes are Draco-compressed ({DRACO}) without uncompressed copies (accessor{} {} {} no bufferView), and Draco mesh compression is not supported: decompress the file first, e.g. with `gltf-transform cp IN OUT` (glTF Transform decodes Draco on reading)",
                    if empty.len() == 1 { "" } else { "s" },
                    quote_list(&empty, ", "),
                    if empty.len() == 1 { "has" } else { "have" },
                ),
            ));
        }
    }
    let mut problems = Vec::new();
    root.validate(root, ::gltf::json::Path::new, &mut |where_, what| {
        let where_ = where_();
        // POSITION's min and max are required (§3.7.2.1) but only serve to bound the
        // mesh without reading it; some exporters leave them out or get them wrong, and
        // the positions are read (and checked) anyway. Required extensions were judged
        // against what this importer reads, not what the crate knows.
        //
        // Attributes whose names start with `_` are the application's own (§3.7.2.1),
        // which gltf-json without its `extras` feature calls invalid (and names
        // "<invalid semantic name>", like any name it does not know); they are not read.
        if !where_.as_str().contains(r#"["POSITION"].m"#)
            && !where_.as_str().starts_with("extensionsRequired")
            && !where_
                .as_str()
                .contains(r#".attributes["<invalid semantic name>"]"#)
        {
            problems.push(format!("{where_}: {what}"));
        }
    });
    if problems.is_empty() {
        return Ok(());
    }
    let more = problems.len().saturating_sub(QUOTED_PROBLEMS);
    problems.truncate(QUOTED_PROBLEMS);
    Err(error(
        path,
        format!(
            "not a valid glTF file: {}{}",
            problems.join("; "),
            if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            }
        ),
    ))
}

/// The first [`QUOTED_PROBLEMS`] of `items`, joined by `separator`, and how many more
/// there are.
fn quote_list(items: &[String], separator: &str) -> String {
    let shown = items.len().min(QUOTED_PROBLEMS);
    let mut list = items[..shown].join(separator);
    if items.len() > shown {
        list += &format!(" and {} more", items.len() - shown);
    }
    list
}

/// A data URI's bytes (RFC 2397), base64 or percent-encoded.
fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((header, data)) = rest.split_once(',') else {
        return Some(Err("the data URI has no ',' before its data".into()));
    };
    Some(if header.ends_with(";base64") {
        let engine = base64::engine::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        engine
            .decode(data.trim())
            .map_err(|e| format!("the data URI is not valid base64: {e}"))
    } else {
        Ok(percent_decode(data))
    })
}

/// Undoes URI percent-encoding (`%20` → space); malformed escapes stay as they are.
fn percent_decode(text: &str) -> Vec<u8> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    out
}

/// The file a relative URI names, or why it names none.
fn uri_file(directory: &Path, uri: &str) -> Result<PathBuf, String> {
    let scheme = uri.split_once(':').map(|(s, _)| s);
    if scheme.is_some_and(|s| {
        s.len() > 1
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    }) {
        return Err(format!(
            "the URI {uri} is neither a relative file path nor a data URI (nothing is fetched from the network)"
        ));
    }
    let decoded = String::from_utf8_lossy(&percent_decode(uri)).into_owned();
    Ok(directory.join(decoded))
}

/// Loads every buffer: the GLB binary chunk, a data URI or a file relative to the model.
fn load_buffers(
    document: &Document,
    blob: Option<&[u8]>,
    path: &Path,
    directory: &Path,
    budget: &mut Budget,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let name = match buffer.name() {
            Some(name) => format!("buffer {} ('{name}')", buffer.index()),
            None => format!("buffer {}", buffer.index()),
        };
        let fail = |message: String| error(path, format!("{name}: {message}"));
        let data = match buffer.source() {
            ::gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    fail("refers to the GLB binary chunk, but the file has none".into())
                })?
                .to_vec(),
            ::gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(decoded) => {
                    let bytes = decoded.map_err(fail)?;
                    budget
                        .charge_bytes(bytes.len() as u64, &name)
                        .map_err(|e| e.at(path))?;
                    bytes
                }
                None => {
                    let file = uri_file(directory, uri).map_err(fail)?;
                    read_file(&file, path, &format!("{name} {}", file.display()), budget)?
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(fail(format!(
                "holds {} bytes, fewer than its byteLength {} (truncated?)",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The state of one import.
struct Importer<'a> {
    path: &'a Path,
    directory: PathBuf,
    document: &'a Document,
    buffers: Vec<Vec<u8>>,
    model: ImportedModel,
    budget: Budget,
    textures: Textures,
    /// glTF material index (`None`: the default material) → index in the model and
    /// whether a texture of it reads `TEXCOORD_1`.
    materials: HashMap<Option<usize>, MaterialUse>,
    /// Warnings already given once per file.
    warned: BTreeSet<&'static str>,
    /// The primitives skipped for being points or lines (`mesh N, primitive P: MODE`).
    not_triangles: Vec<String>,
    /// How many primitives of triangles were read.
    triangle_primitives: usize,
    /// The primitives with vertex colour sets beyond `COLOR_0`, which are not read
    /// (`mesh N, primitive P: COLOR_1`).
    vertex_colors: Vec<String>,
}

/// What a primitive's reading depends on in its material.
#[derive(Debug, Clone, Copy)]
struct MaterialUse {
    /// Index in the model's materials.
    index: u32,
    /// Whether a texture reads `TEXCOORD_1`.
    uses_set1: bool,
    /// The coordinates of its normal map (set and `KHR_texture_transform`), if it has
    /// one: the primitive then needs tangents, for the map's axes.
    normal_map: Option<TextureTransform>,
}

/// A texture's `KHR_texture_transform` as its JSON gives it (checked by
/// [`Importer::transform`]).
#[derive(Debug, Clone, Copy)]
struct TransformExtension {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
    /// The texture coordinate set that overrides the texture's `texCoord`.
    tex_coord: Option<u32>,
}

impl TransformExtension {
    /// Reads the extension's object where gltf 1.4 leaves it unparsed (on a
    /// `normalTexture`, whose extensions it keeps as JSON).
    fn from_json(value: &::gltf::json::Value) -> Result<Self, String> {
        let json: ::gltf::json::extensions::texture::TextureTransform =
            ::gltf::json::deserialize::from_value(value.clone()).map_err(|e| e.to_string())?;
        Ok(Self {
            offset: json.offset.0,
            rotation: json.rotation.0,
            scale: json.scale.0,
            tex_coord: json.tex_coord,
        })
    }
}

/// `what N ('name')`, or `what N` for an unnamed element.
fn describe(what: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) if !name.is_empty() => format!("{what} {index} ('{name}')"),
        _ => format!("{what} {index}"),
    }
}

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
    fn warn(&mut self, message: String) {
        self.model
            .warnings
            .push(format!("{}: {message}", self.path.display()));
    }

    /// Warns about `message` once per file, keyed by `key`.
    fn warn_once(&mut self, key: &'static str, message: String) {
        if self.warned.insert(key) {
            self.warn(message);
        }
    }

    fn fail(&self, message: impl Into<String>) -> SceneError {
        error(self.path, message)
    }

    /// Walks the scene's node trees, parents before children, composing transforms, and
    /// imports the meshes, lights and camera they place.
    fn import(&mut self) -> Result<(), SceneError> {
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
                if node.skin().is_some() {
                    self.warn_once(
                        "skin",
                        "skins are ignored: skinned meshes are placed by their nodes' transforms in the bind pose".into(),
                    );
                }
                let determinant = world.determinant();
                if determinant == 0.0 || !world.inverse().is_finite() {
                    self.warn(format!(
                        "{name}: its transform is singular (a scale of 0?); its mesh is not placed"
                    ));
                } else {
                    placements[mesh.index()].push(world);
                }
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

    /// Imports each primitive of `mesh` as one mesh placed at `instances`.
    fn mesh(&mut self, mesh: &::gltf::Mesh<'_>, instances: Vec<DMat4>) -> Result<(), SceneError> {
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
    /// colours (`COLOR_0`) and triangles (its mode is one of the three of triangles);
    /// `name` (mesh and primitive) is for warnings, the caller prefixes it to errors.
    fn primitive(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        uses: MaterialUse,
    ) -> Result<RawMesh, String> {
        let uses_set1 = uses.uses_set1;
        let mode = primitive.mode();
        let positions_accessor = primitive
            .get(&::gltf::Semantic::Positions)
            .ok_or("it has no POSITION attribute")?;
        let count = positions_accessor.count();
        if count > MAX_MODEL_VERTICES {
            return Err(format!(
                "{count} vertices, more than the {MAX_MODEL_VERTICES} accepted"
            ));
        }
        let index_count = primitive.indices().map_or(count, |a| a.count());
        let triangle_count = match mode {
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
            .map_err(String::from)?;
        let vec3 = |values: Vec<f64>| -> Vec<DVec3> {
            values
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect()
        };
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
        let same_count = |accessor: &::gltf::Accessor<'_>, name: &str| {
            if accessor.count() == count {
                Ok(())
            } else {
                Err(format!(
                    "{name} has {} elements but POSITION has {count}",
                    accessor.count()
                ))
            }
        };
        let normals = match primitive.get(&::gltf::Semantic::Normals) {
            Some(accessor) => {
                same_count(&accessor, "NORMAL")?;
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
                Some(normals)
            }
            None => None,
        };
        let uvs = self.texcoords(primitive, name, 0, count)?;
        let uvs1 = if uses_set1 {
            match self.texcoords(primitive, name, 1, count)? {
                Some(uvs1) => Some(uvs1),
                None => {
                    // A texture that names a set the primitive lacks is invalid (glTF 2.0
                    // §5.30, textureInfo.texCoord); the first set is the likeliest intent.
                    self.warn(format!(
                        "{name}: its material's textures use TEXCOORD_1, which it does not have; {}",
                        if uvs.is_some() {
                            "TEXCOORD_0 is used"
                        } else {
                            "it has no texture coordinates"
                        }
                    ));
                    uvs.clone()
                }
            }
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
        let triangles = triangles(mode, &indices);
        if mode == Mode::Triangles && !indices.len().is_multiple_of(3) {
            self.warn(format!(
                "{name}: a triangle list of {} indices (not a multiple of 3): the last {} ignored",
                indices.len(),
                indices.len() % 3
            ));
        }
        let Some(normal_map) = uses.normal_map else {
            return Ok(RawMesh {
                positions,
                normals,
                uvs,
                uvs1,
                colors,
                tangents: None,
                triangles,
            });
        };
        let tangents = self.tangents(primitive, name, count)?;
        let mut raw = RawMesh {
            positions,
            normals,
            uvs,
            uvs1,
            colors,
            tangents,
            triangles,
        };
        if raw.normals.is_none() {
            // glTF 2.0 §3.7.2.1: without NORMAL, flat normals (and TANGENT ignored),
            // from which MikkTSpace makes the normal map's tangents below.
            self.budget
                .charge_mesh(3 * raw.triangles.len(), 0)
                .map_err(String::from)?;
            if let Some(flat) = super::tangents::with_flat_normals(&raw) {
                raw = flat;
            }
        }
        if let Some(given) = raw.tangents.as_mut() {
            // TANGENT runs along the mesh's coordinates, the map's axes along the
            // transformed ones.
            if let Some(normals) = &raw.normals {
                super::tangents::follow_texture_transform(given, normals, &normal_map);
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
            (Some(_), Some(map_uvs)) => super::tangents::with_mikktspace_tangents(&raw, map_uvs),
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

    /// Reads `TANGENT` of `primitive` (of `count` vertices), if it has it: `VEC4` of
    /// floats, or under `KHR_mesh_quantization` normalized signed bytes or shorts.
    fn tangents(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Result<Option<Vec<glam::DVec4>>, String> {
        let Some(accessor) = primitive.get(&::gltf::Semantic::Tangents) else {
            return Ok(None);
        };
        if accessor.count() != count {
            return Err(format!(
                "TANGENT has {} elements but POSITION has {count}",
                accessor.count()
            ));
        }
        let values = read(
            &accessor,
            &Expect {
                name: "TANGENT",
                dimensions: Dimensions::Vec4,
                types: NORMAL_TYPES,
                normalized: Normalized::Always,
            },
            &self.buffers,
        )?;
        self.check_quantization(&accessor, name, "TANGENT", false);
        Ok(Some(
            values
                .chunks_exact(4)
                .map(|c| glam::DVec4::new(c[0], c[1], c[2], c[3]))
                .collect(),
        ))
    }

    /// Reads `TEXCOORD_{set}` of `primitive` (of `count` vertices), if it has it.
    fn texcoords(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        set: u32,
        count: usize,
    ) -> Result<Option<Vec<DVec2>>, String> {
        let Some(accessor) = primitive.get(&::gltf::Semantic::TexCoords(set)) else {
            return Ok(None);
        };
        let uv_name = format!("TEXCOORD_{set}");
        if accessor.count() != count {
            return Err(format!(
                "{uv_name} has {} elements but POSITION has {count}",
                accessor.count()
            ));
        }
        let values = read(
            &accessor,
            &Expect {
                name: &uv_name,
                dimensions: Dimensions::Vec2,
                types: TEXCOORD_TYPES,
                normalized: Normalized::Either,
            },
            &self.buffers,
        )?;
        self.check_quantization(&accessor, name, &uv_name, true);
        Ok(Some(
            values
                .chunks_exact(2)
                .map(|c| DVec2::new(c[0], c[1]))
                .collect(),
        ))
    }

    /// Reads `COLOR_0` of `primitive` (of `count` vertices), if it has it: `VEC3` or
    /// `VEC4` of floats or normalized unsigned bytes or shorts (glTF 2.0 §3.7.2.1),
    /// `VEC3` with alpha 1. An accessor that breaks these rules is left out with a
    /// warning: the model still renders, in its materials' colours.
    fn colors(
        &mut self,
        primitive: &::gltf::Primitive<'_>,
        name: &str,
        count: usize,
    ) -> Option<Vec<DVec4>> {
        let accessor = primitive.get(&::gltf::Semantic::Colors(0))?;
        let dimensions = accessor.dimensions();
        let read_colors = || -> Result<Vec<f64>, String> {
            if accessor.count() != count {
                return Err(format!(
                    "COLOR_0 has {} elements but POSITION has {count}",
                    accessor.count()
                ));
            }
            if !matches!(dimensions, Dimensions::Vec3 | Dimensions::Vec4) {
                return Err(format!(
                    "COLOR_0 (accessor {}) holds {dimensions:?} elements, expected Vec3 or Vec4",
                    accessor.index()
                ));
            }
            read(
                &accessor,
                &Expect {
                    name: "COLOR_0",
                    dimensions,
                    types: COLOR_TYPES,
                    normalized: Normalized::Always,
                },
                &self.buffers,
            )
        };
        let values = match read_colors() {
            Ok(values) => values,
            Err(e) => {
                self.warn(format!("{name}: {e}; the vertex colours are ignored"));
                return None;
            }
        };
        let components = dimensions.multiplicity();
        Some(
            values
                .chunks_exact(components)
                .map(|c| DVec4::new(c[0], c[1], c[2], c.get(3).copied().unwrap_or(1.0)))
                .collect(),
        )
    }

    /// Warns when positions lie outside the `min` and `max` their accessor declares, as
    /// the glTF validator does (ACCESSOR_MIN_MISMATCH, ACCESSOR_MAX_MISMATCH): the
    /// declared bounds are wrong or the positions are damaged. The model is framed by
    /// the positions read, never by the declaration. A position within a relative
    /// 1e-5 of the declared box (the JSON numbers' rounding) is inside.
    fn check_declared_bounds(
        &mut self,
        accessor: &::gltf::Accessor<'_>,
        primitive: &str,
        positions: &[DVec3],
    ) {
        let declared = |value: Option<::gltf::json::Value>| -> Option<DVec3> {
            let array = value?;
            let array = array.as_array()?;
            let component = |i: usize| array.get(i)?.as_f64();
            Some(DVec3::new(component(0)?, component(1)?, component(2)?))
        };
        let (Some(min), Some(max)) = (declared(accessor.min()), declared(accessor.max())) else {
            return;
        };
        let slack = (max - min).abs().max_element().max(1.0) * 1e-5;
        let outside = |p: &DVec3| {
            (0..3).any(|axis| !(p[axis] >= min[axis] - slack && p[axis] <= max[axis] + slack))
        };
        let count = positions.iter().filter(|p| outside(p)).count();
        let Some((first, at)) = positions.iter().enumerate().find(|(_, p)| outside(p)) else {
            return;
        };
        self.warn(format!(
            "{primitive}: POSITION (accessor {}) has {count} of {} vertices outside the min {} \
             and max {} it declares (the first, vertex {first}, at {}); the bounds are wrong or \
             the positions damaged, and the model is framed by the positions as read",
            accessor.index(),
            positions.len(),
            short3(min),
            short3(max),
            short3(*at)
        ));
    }

    /// Warns (once per file) when `accessor` holds one of the component types that only
    /// `KHR_mesh_quantization` allows but the file does not list the extension in
    /// `extensionsUsed` (glTF 2.0 §3.12: an extension a file uses must be listed). The
    /// values are unambiguous either way, so they are read.
    fn check_quantization(
        &mut self,
        accessor: &::gltf::Accessor<'_>,
        primitive: &str,
        attribute: &str,
        texcoord: bool,
    ) {
        let data_type = accessor.data_type();
        let core = data_type == DataType::F32
            || (texcoord
                && accessor.normalized()
                && matches!(data_type, DataType::U8 | DataType::U16));
        if !core
            && !self
                .document
                .extensions_used()
                .any(|e| e == MESH_QUANTIZATION)
        {
            self.warn_once(
                "quantization",
                format!(
                    "{primitive}: {attribute} (accessor {}) holds {}{data_type:?} components, which only {MESH_QUANTIZATION} allows, but the file does not list that extension in extensionsUsed; read anyway",
                    accessor.index(),
                    if accessor.normalized() { "normalized " } else { "" }
                ),
            );
        }
    }

    /// The model's index of glTF material `index` (`None`: the default material, glTF
    /// 2.0 §3.9.6), mapping it on first use.
    fn material(&mut self, index: Option<usize>) -> Result<MaterialUse, SceneError> {
        if let Some(&known) = self.materials.get(&index) {
            return Ok(known);
        }
        let (imported, uses_set1, normal_map) =
            match index.and_then(|i| self.document.materials().nth(i)) {
                Some(material) => self.map_material(&material)?,
                None => (
                    ImportedMaterial {
                        name: "default".into(),
                        // glTF's default material: white, fully metallic and rough... which is
                        // black under Whitted lighting; a white dielectric PBR is what viewers show.
                        material: Material {
                            diffuse: DVec3::ONE,
                            metallic: 0.0,
                            roughness: 1.0,
                            // The default material is single-sided (§3.9.6).
                            cull_back_faces: true,
                            ..Material::blank(MaterialKind::Pbr)
                        },
                        base_color_texture: None,
                        metallic_roughness_texture: None,
                        emissive_texture: None,
                        normal_texture: None,
                    },
                    false,
                    None,
                ),
            };
        let ours = self.model.materials.len() as u32;
        self.model.materials.push(imported);
        let uses = MaterialUse {
            index: ours,
            uses_set1,
            normal_map,
        };
        self.materials.insert(index, uses);
        Ok(uses)
    }

    /// Maps a glTF metallic-roughness material onto ours (the table in `docs/models.md`),
    /// with whether one of its textures reads `TEXCOORD_1` and the coordinates of its
    /// normal map, if any.
    fn map_material(
        &mut self,
        material: &::gltf::Material<'_>,
    ) -> Result<(ImportedMaterial, bool, Option<TextureTransform>), SceneError> {
        let name = describe("material", material.index().unwrap_or(0), material.name());
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha] = pbr.base_color_factor().map(f64::from);
        let base = DVec3::new(r, g, b);
        let metallic = f64::from(pbr.metallic_factor());
        let roughness = f64::from(pbr.roughness_factor());
        let strength = f64::from(material.emissive_strength().unwrap_or(1.0));
        let emissive = DVec3::from_array(material.emissive_factor().map(f64::from));
        let in_unit = |v: f64| (0.0..=1.0).contains(&v);
        if !base.to_array().into_iter().all(in_unit)
            || !in_unit(alpha)
            || !in_unit(metallic)
            || !in_unit(roughness)
        {
            return Err(self.fail(format!(
                "{name}: baseColorFactor {base} (alpha {alpha}), metallicFactor {metallic} and roughnessFactor {roughness} must lie in [0, 1]"
            )));
        }
        if !(emissive.to_array().into_iter().all(in_unit)
            && strength.is_finite()
            && strength >= 0.0)
        {
            return Err(self.fail(format!(
                "{name}: emissiveFactor {emissive} must lie in [0, 1] and emissiveStrength {strength} be finite and not negative"
            )));
        }
        // glTF 2.0 §3.9.4 "Alpha Coverage": MASK makes the surface opaque where the base
        // colour's alpha is >= alphaCutoff (default 0.5) and absent elsewhere; BLEND
        // makes alpha its coverage; OPAQUE ignores alpha.
        let alpha_mode = match material.alpha_mode() {
            ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            ::gltf::material::AlphaMode::Mask => {
                let cutoff = f64::from(material.alpha_cutoff().unwrap_or(DEFAULT_ALPHA_CUTOFF));
                let cutoff = if cutoff.is_finite() && cutoff >= 0.0 {
                    if cutoff > 1.0 {
                        // Alpha lies in [0, 1]: no point reaches the cutoff.
                        self.warn(format!(
                            "{name}: alphaCutoff {} is above 1, the largest alpha, so the material's every point is cut away and it is invisible",
                            short(cutoff)
                        ));
                    }
                    cutoff
                } else {
                    self.warn(format!(
                        "{name}: alphaCutoff {cutoff} must be finite and not negative; {DEFAULT_ALPHA_CUTOFF} is used"
                    ));
                    f64::from(DEFAULT_ALPHA_CUTOFF)
                };
                AlphaMode::Mask { cutoff }
            }
            ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        // occlusionTexture is left out without a warning: baked ambient occlusion is a
        // rasteriser's stand-in for the shadowing of indirect light (glTF 2.0 §3.9.3),
        // which a path tracer computes; applying it too would darken creases twice.
        let mut emission = emissive * strength;
        if emission.max_element() > MAX_RADIANCE {
            self.warn(format!(
                "{name}: emission {} is above the {} the GPU can sum in 32-bit floats; clamped",
                short(emission.max_element()),
                short(MAX_RADIANCE)
            ));
            emission = emission.min(DVec3::splat(MAX_RADIANCE));
        }
        let transmission = material
            .transmission()
            .map_or(0.0, |t| f64::from(t.transmission_factor()));
        let ior = material.ior().map(f64::from);
        let ours = if material.unlit() {
            // KHR_materials_unlit: the base colour, unshaded. An emitter of that radiance
            // that reflects nothing shows it exactly (Whitted); the path integrator also
            // lets it light its surroundings, which an unlit surface does not do.
            self.warn(format!(
                "{name}: KHR_materials_unlit: read as an emitter of its base colour that reflects nothing; under the path integrator it also lights its surroundings"
            ));
            Material {
                emission: base,
                ..Material::blank(MaterialKind::Emissive)
            }
        } else if transmission > 0.0 && metallic < 1.0 {
            let ior = match ior {
                Some(ior) if ior.is_finite() && ior >= 1.0 => ior,
                Some(ior) => {
                    self.warn(format!(
                        "{name}: ior {ior} is not supported; {DEFAULT_IOR} is used"
                    ));
                    DEFAULT_IOR
                }
                None => DEFAULT_IOR,
            };
            if metallic > 0.0 || roughness > 0.0 {
                self.warn(format!(
                    "{name}: a transmissive material is imported as smooth glass; metallicFactor {metallic} and roughnessFactor {roughness} are ignored"
                ));
            }
            if material
                .transmission()
                .is_some_and(|t| t.transmission_texture().is_some())
            {
                self.warn(format!(
                    "{name}: transmissionTexture is not supported; ignored"
                ));
            }
            Material {
                ior,
                transmittance: (base * transmission.clamp(0.0, 1.0)).clamp(DVec3::ZERO, DVec3::ONE),
                emission,
                ..Material::blank(MaterialKind::Dielectric)
            }
        } else {
            if ior.is_some_and(|ior| ior != DEFAULT_IOR) {
                self.warn(format!(
                    "{name}: ior is only used for transmissive, non-metallic materials (the metal/roughness model's F0 is 0.04); ignored"
                ));
            }
            Material {
                diffuse: base,
                metallic,
                roughness,
                emission,
                ..Material::blank(MaterialKind::Pbr)
            }
        };
        // glTF's doubleSided lights both sides of a surface: an emitter emits from both.
        // Without it, camera rays cull the back faces (glTF 2.0 §3.9.5).
        let ours = Material {
            two_sided: material.double_sided() && ours.emission != DVec3::ZERO,
            cull_back_faces: !material.double_sided(),
            alpha_mode,
            alpha,
            ..ours
        };
        let base_color_texture = match pbr.base_color_texture() {
            Some(info) => Some(self.texture(&info, Encoding::Color, &name, "baseColorTexture")?),
            None => None,
        };
        let metallic_roughness_texture = match pbr.metallic_roughness_texture() {
            Some(info) => {
                Some(self.texture(&info, Encoding::Data, &name, "metallicRoughnessTexture")?)
            }
            None => None,
        };
        let emissive_texture = match material.emissive_texture() {
            // An unlit material's colour is its base colour, texture included.
            _ if material.unlit() => base_color_texture,
            Some(info) => Some(self.texture(&info, Encoding::Color, &name, "emissiveTexture")?),
            None => None,
        };
        let (normal_texture, normal_scale) = match material.normal_texture() {
            Some(normal) => {
                let scale = f64::from(normal.scale());
                if !scale.is_finite() {
                    return Err(
                        self.fail(format!("{name}: normalTexture scale {scale} is not finite"))
                    );
                }
                let extension = match normal.extension_value("KHR_texture_transform") {
                    Some(value) => Some(TransformExtension::from_json(value).map_err(|e| {
                        self.fail(format!("{name}: normalTexture: KHR_texture_transform: {e}"))
                    })?),
                    None => None,
                };
                let transform =
                    self.transform(normal.tex_coord(), extension, &name, "normalTexture")?;
                let texture = self.texture_of(
                    normal.texture(),
                    transform,
                    Encoding::Data,
                    &name,
                    "normalTexture",
                )?;
                (Some(texture), scale)
            }
            None => (None, 1.0),
        };
        let ours = Material {
            normal_scale,
            ..ours
        };
        let uses_set1 = [
            &base_color_texture,
            &metallic_roughness_texture,
            &emissive_texture,
            &normal_texture,
        ]
        .iter()
        .any(|t| t.is_some_and(|t| t.transform.set == 1));
        let imported = ImportedMaterial {
            name: material.name().map_or_else(|| name.clone(), str::to_string),
            material: ours,
            base_color_texture,
            metallic_roughness_texture,
            emissive_texture,
            normal_texture,
        };
        Ok((imported, uses_set1, normal_texture.map(|t| t.transform)))
    }

    /// Loads the image of a material's texture and keeps its sampler's wrap modes, its
    /// texture coordinate set and `KHR_texture_transform` ([`Importer::transform`]).
    fn texture(
        &mut self,
        info: &::gltf::texture::Info<'_>,
        encoding: Encoding,
        material: &str,
        slot: &str,
    ) -> Result<TextureRef, SceneError> {
        let extension = info
            .texture_transform()
            .map(|extension| TransformExtension {
                offset: extension.offset(),
                rotation: extension.rotation(),
                scale: extension.scale(),
                tex_coord: extension.tex_coord(),
            });
        let transform = self.transform(info.tex_coord(), extension, material, slot)?;
        self.texture_of(info.texture(), transform, encoding, material, slot)
    }

    /// Loads the image of `texture` and keeps its sampler's wrap modes, with the
    /// coordinates `transform` describes.
    fn texture_of(
        &mut self,
        texture: ::gltf::texture::Texture<'_>,
        transform: TextureTransform,
        encoding: Encoding,
        material: &str,
        slot: &str,
    ) -> Result<TextureRef, SceneError> {
        let image = texture.source();
        let image_name = describe("image", image.index(), image.name());
        let fail = |e: String| error(self.path, format!("{material}: {slot}: {image_name}: {e}"));
        let label = format!("{}#{image_name}", self.path.display());
        // The image's JSON, not `Image::source`, which unwraps a missing `uri` or (for a
        // buffer view) `mimeType` (gltf 1.4).
        let json = &self.document.as_json().images[image.index()];
        let index = match (&json.buffer_view, &json.uri) {
            (Some(view), _) => {
                let view =
                    self.document.views().nth(view.value()).ok_or_else(|| {
                        fail(format!("bufferView {} does not exist", view.value()))
                    })?;
                let bytes = view_bytes(&view, &self.buffers).map_err(fail)?.to_vec();
                self.textures
                    .bytes(&bytes, &label, encoding, &mut self.budget)
                    .map_err(fail)?
            }
            (None, Some(uri)) => match data_uri(uri) {
                Some(decoded) => {
                    let bytes = decoded.map_err(fail)?;
                    self.textures
                        .bytes(&bytes, &label, encoding, &mut self.budget)
                        .map_err(fail)?
                }
                None => {
                    let file = uri_file(&self.directory, uri).map_err(fail)?;
                    self.textures
                        .file(&file, encoding, &mut self.budget)
                        .map_err(fail)?
                }
            },
            (None, None) => return Err(fail("it has neither a uri nor a bufferView".into())),
        };
        let sampler = texture.sampler();
        let wrap = |mode: WrappingMode| match mode {
            WrappingMode::Repeat => WrapMode::Repeat,
            WrappingMode::ClampToEdge => WrapMode::ClampToEdge,
            WrappingMode::MirroredRepeat => WrapMode::MirroredRepeat,
        };
        Ok(TextureRef {
            image: index,
            wrap_u: wrap(sampler.wrap_s()),
            wrap_v: wrap(sampler.wrap_t()),
            transform,
        })
    }

    /// The texture coordinate set of a texture (its `texCoord`, or the one its
    /// `KHR_texture_transform` overrides it with) and the extension's offset, rotation
    /// and scale as one map ([`TextureTransform::offset_rotation_scale`]). A set beyond 1
    /// is read as `TEXCOORD_0`, with a warning (no texture of the Khronos samples asks
    /// for one). A transform with a value that is not finite, or an offset or scale
    /// beyond [`MAX_TEXTURE_TRANSFORM`] in size (where `f32` coordinates on the GPU keep
    /// no fraction of a texel), is an error.
    fn transform(
        &mut self,
        tex_coord: u32,
        extension: Option<TransformExtension>,
        material: &str,
        slot: &str,
    ) -> Result<TextureTransform, SceneError> {
        let mut set = tex_coord;
        let mut transform = TextureTransform::IDENTITY;
        if let Some(extension) = extension {
            set = extension.tex_coord.unwrap_or(set);
            let offset = DVec2::from_array(extension.offset.map(f64::from));
            let rotation = f64::from(extension.rotation);
            let scale = DVec2::from_array(extension.scale.map(f64::from));
            let in_range =
                |v: DVec2| v.is_finite() && v.abs().max_element() <= MAX_TEXTURE_TRANSFORM;
            if !(in_range(offset) && in_range(scale) && rotation.is_finite()) {
                return Err(self.fail(format!(
                    "{material}: {slot}: KHR_texture_transform offset {offset}, rotation {rotation} and scale {scale} must be finite, the offset and scale at most {} in size",
                    short(MAX_TEXTURE_TRANSFORM)
                )));
            }
            transform = TextureTransform::offset_rotation_scale(0, offset, rotation, scale);
        }
        if set > 1 {
            self.warn(format!(
                "{material}: {slot} uses TEXCOORD_{set}, but only TEXCOORD_0 and TEXCOORD_1 are read; TEXCOORD_0 is used"
            ));
            set = 0;
        }
        transform.set = set;
        Ok(transform)
    }

    /// Keeps the first perspective camera placed by a node.
    fn camera(
        &mut self,
        camera: &::gltf::Camera<'_>,
        node: &str,
        world: DMat4,
    ) -> Result<(), SceneError> {
        let name = describe("camera", camera.index(), camera.name());
        if self.model.camera.is_some() {
            self.warn(format!(
                "{name} on {node}: only the first camera is imported; ignored"
            ));
            return Ok(());
        }
        // A perspective camera's vertical field of view, or an orthographic one's half
        // height (in its node's space; the node's scale applies) and xmag/ymag.
        let (fov_y_degrees, orthographic, aspect_ratio) = match camera.projection() {
            Projection::Perspective(perspective) => {
                let yfov = f64::from(perspective.yfov());
                if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
                    return Err(self.fail(format!("{name}: yfov {yfov} rad is not in (0, π)")));
                }
                let aspect_ratio = perspective.aspect_ratio().map(f64::from);
                if aspect_ratio.is_some_and(|a| !(a.is_finite() && a > 0.0)) {
                    return Err(self.fail(format!(
                        "{name}: aspectRatio {} is not positive",
                        aspect_ratio.unwrap_or_default()
                    )));
                }
                (yfov.to_degrees(), None, aspect_ratio)
            }
            Projection::Orthographic(orthographic) => {
                // glTF 2.0 §5.13: xmag and ymag must not be zero and should not be
                // negative; a negative one is taken by its size.
                let (xmag, ymag) = (
                    f64::from(orthographic.xmag()).abs(),
                    f64::from(orthographic.ymag()).abs(),
                );
                let y_scale = world.transform_vector3(DVec3::Y).length();
                let half_height = ymag * y_scale;
                let usable = |v: f64| v.is_finite() && v > 0.0 && v <= MAX_ORTHOGRAPHIC_HALF_HEIGHT;
                if !(usable(xmag) && usable(half_height)) {
                    // The half height the view gets is ymag times the node's scale along
                    // its y axis: say both, so that a scale of 0 is seen for what it is.
                    return Err(self.fail(format!(
                        "{name} on {node}: orthographic xmag {} and ymag {} times the node's y scale {} (a half height of {}) must be positive, finite and at most {}",
                        short(orthographic.xmag()),
                        short(orthographic.ymag()),
                        short(y_scale),
                        short(half_height),
                        short(MAX_ORTHOGRAPHIC_HALF_HEIGHT)
                    )));
                }
                (
                    super::DEFAULT_FOV_Y_DEGREES,
                    Some(half_height),
                    Some(xmag / ymag),
                )
            }
        };
        // glTF 2.0 §3.10.1: the camera looks along its local -z with +y up.
        let eye = world.transform_point3(DVec3::ZERO);
        let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
        let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
        if forward == DVec3::ZERO || up == DVec3::ZERO || forward.cross(up).length() < 1e-6 {
            self.warn(format!(
                "{name} on {node}: its transform leaves no view direction and up (singular or sheared); ignored"
            ));
            return Ok(());
        }
        self.model.camera = Some(ImportedCamera {
            name: camera.name().map_or_else(|| name.clone(), str::to_string),
            camera: Camera {
                eye,
                look_at: eye + forward,
                up,
                fov_y_degrees,
                orthographic_half_height: orthographic,
                lens: None,
            },
            aspect_ratio,
        });
        Ok(())
    }

    /// Converts a `KHR_lights_punctual` light into our units (see [`LUMENS_PER_WATT`]).
    fn light(
        &mut self,
        light: &::gltf::khr_lights_punctual::Light<'_>,
        node: &str,
        world: DMat4,
    ) -> Result<(), SceneError> {
        let name = describe("light", light.index(), light.name());
        let intensity = f64::from(light.intensity());
        let color = DVec3::from_array(light.color().map(f64::from));
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(self.fail(format!(
                "{name}: intensity {intensity} is negative or not finite"
            )));
        }
        if !color
            .to_array()
            .into_iter()
            .all(|c| (0.0..=1.0).contains(&c))
        {
            return Err(self.fail(format!("{name}: color {color} must lie in [0, 1]")));
        }
        if light.range().is_some() {
            self.warn(format!(
                "{name}: range is ignored (our lights fall off with the inverse square to any distance)"
            ));
        }
        let strength = color * intensity / LUMENS_PER_WATT;
        if strength.max_element() > MAX_RADIANCE {
            return Err(self.fail(format!(
                "{name}: intensity {} is {} W after conversion, above the {} accepted (the GPU \
                 sums light in 32-bit floats)",
                short(intensity),
                short(strength.max_element()),
                short(MAX_RADIANCE)
            )));
        }
        let position = world.transform_point3(DVec3::ZERO);
        let point = Light::Point {
            position,
            intensity: strength,
        };
        let converted = match light.kind() {
            Kind::Point => point,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                // §KHR_lights_punctual: 0 ≤ inner < outer ≤ π/2 (defaults 0 and π/4).
                let (inner, outer) = (f64::from(inner_cone_angle), f64::from(outer_cone_angle));
                let right_angle = std::f64::consts::FRAC_PI_2;
                // π/2 given in f32 lies a little above it in f64.
                let ordered = (0.0..right_angle).contains(&inner)
                    && outer > inner
                    && outer <= right_angle + 1e-6;
                if !ordered {
                    return Err(self.fail(format!(
                        "{name} on {node}: spot innerConeAngle {} and outerConeAngle {} must satisfy 0 <= inner < outer <= pi/2",
                        short(inner_cone_angle),
                        short(outer_cone_angle)
                    )));
                }
                // Spot lights shine along the node's local -z, as directional ones.
                let direction = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                if direction == DVec3::ZERO {
                    self.warn(format!(
                        "{name} on {node}: its transform leaves no direction (singular); ignored"
                    ));
                    return Ok(());
                }
                Light::Spot {
                    position,
                    direction,
                    intensity: strength,
                    cos_inner: inner.cos(),
                    cos_outer: outer.min(right_angle).cos().max(0.0),
                }
            }
            Kind::Directional => {
                // §KHR_lights_punctual: directional lights shine along the node's local -z.
                let direction = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                if direction == DVec3::ZERO {
                    self.warn(format!(
                        "{name} on {node}: its transform leaves no direction (singular); ignored"
                    ));
                    return Ok(());
                }
                Light::Directional {
                    direction,
                    irradiance: strength,
                }
            }
        };
        self.model.lights.push(converted);
        Ok(())
    }
}

/// A primitive mode by its name and number in glTF 2.0 §5.24 (`mesh.primitive.mode`).
fn mode_name(mode: Mode) -> &'static str {
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
fn triangles(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
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

    #[test]
    fn data_uris_and_percent_escapes_decode() {
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAEC").map(Result::ok),
            Some(Some(vec![0, 1, 2]))
        );
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAE").map(Result::ok),
            Some(Some(vec![0, 1]))
        );
        assert!(data_uri("data:;base64,!!").is_some_and(|r| r.is_err()));
        assert!(data_uri("buffer.bin").is_none());
        assert_eq!(percent_decode("my%20file.bin"), b"my file.bin");
        assert_eq!(percent_decode("100%"), b"100%");
        assert_eq!(percent_decode("%4"), b"%4");
    }

    #[test]
    fn only_relative_uris_name_files() {
        let dir = Path::new("models");
        assert_eq!(
            uri_file(dir, "tex%201.png"),
            Ok(PathBuf::from("models/tex 1.png"))
        );
        assert!(uri_file(dir, "https://example.com/a.bin").is_err());
        assert!(uri_file(dir, "file:///etc/passwd").is_err());
    }
}
