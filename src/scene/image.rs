//! Reading image files for albedo textures and tabulated BRDF maps.

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use image::{DynamicImage, ImageFormat, ImageReader};

use super::Image;
use crate::color::srgb_decode;
use crate::input::{InputError, read_confined, read_input};

/// Why an image file was refused. The messages are the reason alone, without the
/// image's path, which the caller names with the image's role ("the texture wood.png
/// does not load: {reason}").
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ImageError {
    /// The file could not be opened or read ([`crate::input`]'s rules).
    #[error("cannot read the file: {0}")]
    Read(#[source] Arc<InputError>),
    /// The bytes are not an image the decoder reads (or its format cannot be told).
    #[error("not a readable image: {0}")]
    Decode(#[source] Arc<image::ImageError>),
    /// The format of the bytes could not be guessed.
    #[error("cannot read the file: {0}")]
    Guess(#[source] Arc<std::io::Error>),
    /// The image has no texels.
    #[error("the image is empty ({width}x{height})")]
    Empty {
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
    },
    /// A side is larger than [`MAX_IMAGE_SIDE`].
    #[error(
        "the image is {width}x{height}, larger than the {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE} accepted"
    )]
    TooLarge {
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
    },
    /// The decoded texels do not match the size the header declares.
    #[error(
        "the image decodes to {decoded_width}x{decoded_height}, not the {width}x{height} its header declares"
    )]
    SizeMismatch {
        /// The width the header declares.
        width: u32,
        /// The height the header declares.
        height: u32,
        /// The width decoded.
        decoded_width: u32,
        /// The height decoded.
        decoded_height: u32,
    },
    /// A texel holds an infinite or NaN value.
    #[error("texel ({x}, {y}) is not a finite number")]
    NotFinite {
        /// Its column.
        x: u32,
        /// Its row.
        y: u32,
    },
}

/// Largest accepted image width or height in texels. Every image of a scene shares one
/// GPU texture array whose layers are as large as the largest image, so this bounds
/// each layer at 64 MiB of RGBA `f32`.
pub const MAX_IMAGE_SIDE: u32 = 2048;

/// Largest accepted image file in bytes: a [`MAX_IMAGE_SIDE`]² RGBA `f32` OpenEXR
/// file without compression is 64 MiB, so this leaves room for any real encoding.
pub const MAX_IMAGE_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// Bytes a decoded image holds for each texel: linear RGBA `f32`.
pub const DECODED_BYTES_PER_TEXEL: u64 = 16;

/// The most bytes decoding holds for each texel besides the file's own bytes: the
/// decoder's image (at most RGB(A) `f32`, 16 bytes, while a 3-channel image is widened
/// to 4: 12 + 16) and the linear texels made from it (16). An upper bound, used to
/// refuse an image before it is decoded ([`EncodedImage::decoding_peak_bytes`]).
pub const DECODING_BYTES_PER_TEXEL: u64 = 44;

/// An image file read but not decoded: its bytes and the size its header declares
/// (checked as [`load_image`] checks it), so that a caller can count the memory the
/// image will take before it takes it.
#[derive(Debug, Clone)]
pub struct EncodedImage {
    path: PathBuf,
    bytes: Vec<u8>,
    width: u32,
    height: u32,
}

impl EncodedImage {
    /// Reads the image file at `path` and its header ([`crate::input`]'s rules).
    pub fn read(path: &Path) -> Result<Self, ImageError> {
        let bytes =
            read_input(path, MAX_IMAGE_FILE_BYTES).map_err(|e| ImageError::Read(Arc::new(e)))?;
        Self::from_bytes(path, bytes)
    }

    /// Reads the file `file` that a sandboxed scene in folder `dir` names: opened
    /// beneath `dir` so that no symbolic link, nor a swap of one while the file is
    /// opened, reaches outside it ([`crate::input::open_confined`]). The image's path
    /// is `dir/file`.
    pub fn read_confined(dir: &Path, file: &Path) -> Result<Self, ImageError> {
        let bytes = read_confined(dir, file, MAX_IMAGE_FILE_BYTES)
            .map_err(|e| ImageError::Read(Arc::new(e)))?;
        Self::from_bytes(&dir.join(file), bytes)
    }

    /// The image file `bytes`, read from or named `path`, with its header checked.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, ImageError> {
        let (width, height) = image_dimensions(path, &bytes)?;
        Ok(Self {
            path: path.to_path_buf(),
            bytes,
            width,
            height,
        })
    }

    /// The width and height its header declares.
    pub fn dimensions(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The bytes the decoded image holds ([`DECODED_BYTES_PER_TEXEL`] a texel).
    pub fn decoded_bytes(&self) -> u64 {
        texel_count(self.width, self.height) * DECODED_BYTES_PER_TEXEL
    }

    /// The most bytes held while it is decoded: the file's bytes and
    /// [`DECODING_BYTES_PER_TEXEL`] a texel.
    pub fn decoding_peak_bytes(&self) -> u64 {
        self.decoded_bytes()
            + decoding_transient_bytes(self.bytes.len() as u64, self.width, self.height)
    }

    /// Decodes it as [`load_image`] does.
    pub fn decode(self) -> Result<Image, ImageError> {
        decode_image(&self.path, &self.bytes)
    }
}

fn texel_count(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height)
}

/// The bytes decoding an image file of `file_bytes` bytes and `width × height` texels
/// holds for a moment beside the decoded image it keeps: the file and the decoder's
/// image ([`DECODING_BYTES_PER_TEXEL`] less [`DECODED_BYTES_PER_TEXEL`] a texel).
pub fn decoding_transient_bytes(file_bytes: u64, width: u32, height: u32) -> u64 {
    file_bytes + texel_count(width, height) * (DECODING_BYTES_PER_TEXEL - DECODED_BYTES_PER_TEXEL)
}

/// Reads the image at `path` into linear RGBA `f32`: 8- and 16-bit files (PNG) are
/// taken as sRGB-encoded and linearised with the exact sRGB curve (IEC 61966-2-1);
/// 32-bit float files (OpenEXR, Radiance HDR) are taken as linear. Fails with a
/// message (without the path, which the caller names) when the file is missing,
/// unreadable, not a regular file (a FIFO or a device would block or never end:
/// judged on the opened file, [`crate::input`]), not an image, empty or larger than
/// [`MAX_IMAGE_SIDE`], or holds a non-finite value. Texels outside [0, 1] are kept as
/// they are: a scene's materials check their range.
pub fn load_image(path: &Path) -> Result<Image, ImageError> {
    EncodedImage::read(path)?.decode()
}

/// [`load_image`] for the file `file` that a sandboxed scene in folder `dir` names
/// ([`EncodedImage::read_confined`]). The image's path is `dir/file`.
pub fn load_confined_image(dir: &Path, file: &Path) -> Result<Image, ImageError> {
    EncodedImage::read_confined(dir, file)?.decode()
}

/// The width and height the image file `bytes` (read from or named `path`) declares in
/// its header, checked as [`load_image`] checks them, without decoding its texels: for
/// callers that count the memory an image will take before it is decoded.
pub fn image_dimensions(path: &Path, bytes: &[u8]) -> Result<(u32, u32), ImageError> {
    let bytes = radiance_header(bytes);
    let dimensions = image_reader(path, &bytes)?
        .into_dimensions()
        .map_err(|e| ImageError::Decode(Arc::new(e)))?;
    check_dimensions(dimensions)?;
    Ok(dimensions)
}

/// A reader of the image file `bytes`, its format from the bytes or else from `path`'s
/// extension.
fn image_reader<'b>(
    path: &Path,
    bytes: &'b [u8],
) -> Result<ImageReader<Cursor<&'b [u8]>>, ImageError> {
    let mut reader = ImageReader::new(Cursor::new(bytes));
    if let Ok(format) = ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    reader
        .with_guessed_format()
        .map_err(|e| ImageError::Guess(Arc::new(e)))
}

/// Decodes the image file `bytes` (read from `path`, or embedded in a model and named
/// `path`) as [`load_image`] does. The format comes from the bytes, or where they do
/// not tell, from `path`'s extension.
pub fn decode_image(path: &Path, bytes: &[u8]) -> Result<Image, ImageError> {
    let (width, height) = image_dimensions(path, bytes)?;
    let bytes = radiance_header(bytes);
    let decoded = image_reader(path, &bytes)?
        .decode()
        .map_err(|e| ImageError::Decode(Arc::new(e)))?;
    if (decoded.width(), decoded.height()) != (width, height) {
        return Err(ImageError::SizeMismatch {
            width,
            height,
            decoded_width: decoded.width(),
            decoded_height: decoded.height(),
        });
    }
    let (width, height) = (decoded.width(), decoded.height());
    // Each conversion consumes the decoder's image, so that at most it and one
    // converted copy are held at once (DECODING_BYTES_PER_TEXEL).
    let texels: Vec<[f32; 4]> = match decoded {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            let values = decoded.into_rgba32f().into_raw();
            match bytemuck::allocation::try_cast_vec(values) {
                Ok(texels) => texels,
                Err((_, values)) => values
                    .chunks_exact(4)
                    .map(|t| [t[0], t[1], t[2], t[3]])
                    .collect(),
            }
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => decoded
            .into_rgba16()
            .pixels()
            .map(|p| {
                let c = |v: u16| srgb_decode(f64::from(v) / 65535.0) as f32;
                [c(p.0[0]), c(p.0[1]), c(p.0[2]), f32::from(p.0[3]) / 65535.0]
            })
            .collect(),
        decoded => {
            let table: Vec<f32> = (0..=255u8)
                .map(|v| srgb_decode(f64::from(v) / 255.0) as f32)
                .collect();
            let c = |v: u8| table[usize::from(v)];
            match decoded {
                DynamicImage::ImageRgb8(rgb) => rgb
                    .pixels()
                    .map(|p| [c(p.0[0]), c(p.0[1]), c(p.0[2]), 1.0])
                    .collect(),
                decoded => decoded
                    .into_rgba8()
                    .pixels()
                    .map(|p| [c(p.0[0]), c(p.0[1]), c(p.0[2]), f32::from(p.0[3]) / 255.0])
                    .collect(),
            }
        }
    };
    if let Some(index) = texels.iter().position(|t| t.iter().any(|c| !c.is_finite())) {
        let (x, y) = (index as u32 % width, index as u32 / width);
        return Err(ImageError::NotFinite { x, y });
    }
    Ok(Image {
        path: path.to_path_buf(),
        width,
        height,
        texels,
    })
}

/// A Radiance HDR file whose first line is `#?RGBE` (as Mitsuba and other programs
/// write it) with that line spelled `#?RADIANCE`, the only one the decoder takes: both
/// name the same format (Greg Ward, "Real Pixels", Graphics Gems II, and the Radiance
/// reference, where the program name after `#?` is free). Other bytes as they are.
fn radiance_header(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    const RGBE: &[u8] = b"#?RGBE\n";
    match bytes.strip_prefix(RGBE) {
        Some(rest) => {
            let mut fixed = b"#?RADIANCE\n".to_vec();
            fixed.extend_from_slice(rest);
            std::borrow::Cow::Owned(fixed)
        }
        None => std::borrow::Cow::Borrowed(bytes),
    }
}

fn check_dimensions((width, height): (u32, u32)) -> Result<(), ImageError> {
    if width == 0 || height == 0 {
        return Err(ImageError::Empty { width, height });
    }
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(ImageError::TooLarge { width, height });
    }
    Ok(())
}
