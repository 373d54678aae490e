//! A material's textures: its images (from a buffer view, a data URI or a file), its
//! sampler's wrap modes, its texture coordinate set and `KHR_texture_transform`.

use ::gltf::texture::WrappingMode;
use glam::DVec2;

use super::buffers::{data_uri, uri_file};
use super::extensions::TransformExtension;
use super::importer::{Importer, describe};
use crate::echo::short;
use crate::scene::import::accessor::view_bytes;
use crate::scene::import::texture::Encoding;
use crate::scene::import::{TextureRef, WrapMode, error};
use crate::scene::{SceneError, TextureTransform};

/// Largest offset or scale (in size) of a `KHR_texture_transform` (or an MTL texture's
/// `-o` and `-s`) accepted: beyond it an `f32` texture coordinate keeps less than 1/16
/// of a repeat.
pub(in crate::scene::import) const MAX_TEXTURE_TRANSFORM: f64 = 1e6;

impl Importer<'_> {
    /// Loads the image of a material's texture and keeps its sampler's wrap modes, its
    /// texture coordinate set and `KHR_texture_transform` ([`Importer::transform`]).
    pub(super) fn texture(
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
    pub(super) fn texture_of(
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
    pub(super) fn transform(
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
}
