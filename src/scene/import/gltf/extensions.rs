//! The glTF extensions this importer reads or refuses: the list it supports, the message
//! for a file that requires others (with what to do about compression), and
//! `KHR_texture_transform` as its JSON gives it.

/// The extensions this importer understands; a file that requires any other is refused.
pub(super) const SUPPORTED_EXTENSIONS: &[&str] = &[
    "EXT_mesh_gpu_instancing",
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];
/// `KHR_mesh_quantization`, which widens the component types of vertex attributes.
pub(super) const MESH_QUANTIZATION: &str = "KHR_mesh_quantization";

/// Draco mesh compression (`KHR_draco_mesh_compression`), which is not decoded here.
pub(super) const DRACO: &str = "KHR_draco_mesh_compression";
/// meshoptimizer's buffer compression, as a vendor extension and as ratified by Khronos;
/// not decoded here.
pub(super) const MESHOPT: &[&str] = &["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// The message for a file that requires the `unsupported` extensions (at least one):
/// all of them at once, and for a compression what to do about it.
pub(super) fn unsupported_extensions(unsupported: &[&str]) -> String {
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

/// A texture's `KHR_texture_transform` as its JSON gives it (checked by
/// [`Importer::transform`](super::importer::Importer::transform)).
#[derive(Debug, Clone, Copy)]
pub(super) struct TransformExtension {
    pub(super) offset: [f32; 2],
    pub(super) rotation: f32,
    pub(super) scale: [f32; 2],
    /// The texture coordinate set that overrides the texture's `texCoord`.
    pub(super) tex_coord: Option<u32>,
}

impl TransformExtension {
    /// Reads the extension's object where gltf 1.4 leaves it unparsed (on a
    /// `normalTexture`, whose extensions it keeps as JSON).
    pub(super) fn from_json(value: &::gltf::json::Value) -> Result<Self, String> {
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
