//! Loading a model's textures, each file once, through [`load_image`].

use std::collections::HashMap;
use std::path::Path;

use super::mesh::Budget;
use crate::color::srgb_encode;
use crate::input::read_input;
use crate::scene::{
    Image, MAX_IMAGE_FILE_BYTES, decode_image, decoding_transient_bytes, image_dimensions,
};

/// How a texture's values are meant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Encoding {
    /// Colours, sRGB-encoded in 8- and 16-bit files and linearised on load (base colour,
    /// emission).
    Color,
    /// Numbers (glTF's metallic-roughness texture): the file's values, not linearised.
    Data,
}

/// The textures loaded so far, shared by the materials that name the same source.
#[derive(Default)]
pub(super) struct Textures {
    pub images: Vec<Image>,
    loaded: HashMap<(String, Encoding), u32>,
}

impl Textures {
    /// The index of the texture read from the file `path`, loading it on first use.
    /// Fails with a message naming the file (the caller names the material).
    pub fn file(
        &mut self,
        path: &Path,
        encoding: Encoding,
        budget: &mut Budget,
    ) -> Result<u32, String> {
        let key = (path.display().to_string(), encoding);
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let fail = |e: String| format!("the texture {} does not load: {e}", path.display());
        let bytes = read_input(path, MAX_IMAGE_FILE_BYTES)
            .map_err(|e| fail(format!("cannot read the file: {e}")))?;
        self.decode(key, path, &bytes, encoding, budget)
            .map_err(|e| e.message(fail))
    }

    /// The index of the texture decoded from `bytes` (an image embedded in the model),
    /// called `name` in messages and in [`Image::path`].
    pub fn bytes(
        &mut self,
        bytes: &[u8],
        name: &str,
        encoding: Encoding,
        budget: &mut Budget,
    ) -> Result<u32, String> {
        let key = (name.to_string(), encoding);
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        let fail = |e: String| format!("the texture {name} does not load: {e}");
        self.decode(key, Path::new(name), bytes, encoding, budget)
            .map_err(|e| e.message(fail))
    }

    /// The index of an image made from loaded ones by `make` (a colour texture with a
    /// dissolve texture's coverage), made once per `key`, after charging its `width ×
    /// height` texels to `budget`.
    pub fn derived(
        &mut self,
        key: String,
        (width, height): (u32, u32),
        make: impl FnOnce(&[Image]) -> Image,
        budget: &mut Budget,
    ) -> Result<u32, String> {
        // A NUL cannot start a path, so no file's key meets a derived one.
        let key = (format!("\0derived {key}"), Encoding::Color);
        if let Some(&index) = self.loaded.get(&key) {
            return Ok(index);
        }
        budget.charge_texels(width, height).map_err(String::from)?;
        let image = make(&self.images);
        let index = self.images.len() as u32;
        self.images.push(image);
        self.loaded.insert(key, index);
        Ok(index)
    }

    /// Decodes the image file `bytes` (read from or named `path`) and adds it, after
    /// charging its texels to `budget` from its header, before its texels are
    /// allocated.
    fn decode(
        &mut self,
        key: (String, Encoding),
        path: &Path,
        bytes: &[u8],
        encoding: Encoding,
        budget: &mut Budget,
    ) -> Result<u32, TextureFailure> {
        let (width, height) =
            image_dimensions(path, bytes).map_err(|e| TextureFailure::Decode(e.to_string()))?;
        budget
            .charge_texels(width, height)
            .map_err(|e| TextureFailure::Budget(e.into()))?;
        // Decoding holds the file and the decoder's image beside the texels it keeps.
        let transient = decoding_transient_bytes(bytes.len() as u64, width, height);
        budget
            .check_transient(transient, "its textures while one is decoded")
            .map_err(|e| TextureFailure::Budget(e.into()))?;
        let mut image =
            decode_image(path, bytes).map_err(|e| TextureFailure::Decode(e.to_string()))?;
        if encoding == Encoding::Data {
            // `load_image` linearised the 8/16-bit values as sRGB; glTF images are PNG or
            // JPEG (glTF 2.0 §3.8.3), never float, so encoding again restores the
            // file's values (to f32 rounding).
            for texel in &mut image.texels {
                for channel in &mut texel[..3] {
                    *channel = srgb_encode(f64::from(*channel)) as f32;
                }
            }
        }
        let index = self.images.len() as u32;
        self.images.push(image);
        self.loaded.insert(key, index);
        Ok(index)
    }
}

/// Why a texture was not added.
enum TextureFailure {
    /// The file does not decode (the caller names the texture).
    Decode(String),
    /// The model's budget refuses its texels (a message of its own).
    Budget(String),
}

impl TextureFailure {
    /// The message: a decoding failure through `name_it`, the budget's as it is.
    fn message(self, name_it: impl FnOnce(String) -> String) -> String {
        match self {
            TextureFailure::Decode(why) => name_it(why),
            TextureFailure::Budget(why) => why,
        }
    }
}
