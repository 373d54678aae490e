//! Reading image files for albedo textures and tabulated BRDF maps.

use std::io::Cursor;
use std::path::Path;
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

/// Reads the image at `path` into linear RGBA `f32`: 8- and 16-bit files (PNG) are
/// taken as sRGB-encoded and linearised with the exact sRGB curve (IEC 61966-2-1);
/// 32-bit float files (OpenEXR, Radiance HDR) are taken as linear. Fails with a
/// message (without the path, which the caller names) when the file is missing,
/// unreadable, not a regular file (a FIFO or a device would block or never end:
/// judged on the opened file, [`crate::input`]), not an image, empty or larger than
/// [`MAX_IMAGE_SIDE`], or holds a non-finite value. Texels outside [0, 1] are kept as
/// they are: a scene's materials check their range.
pub fn load_image(path: &Path) -> Result<Image, ImageError> {
    let bytes =
        read_input(path, MAX_IMAGE_FILE_BYTES).map_err(|e| ImageError::Read(Arc::new(e)))?;
    decode_image(path, &bytes)
}

/// [`load_image`] for the file `file` that a sandboxed scene in folder `dir` names:
/// opened beneath `dir` so that no symbolic link, nor a swap of one while the file is
/// opened, reaches outside it ([`crate::input::open_confined`]). The image's path is
/// `dir/file`.
pub fn load_confined_image(dir: &Path, file: &Path) -> Result<Image, ImageError> {
    let bytes = read_confined(dir, file, MAX_IMAGE_FILE_BYTES)
        .map_err(|e| ImageError::Read(Arc::new(e)))?;
    decode_image(&dir.join(file), &bytes)
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
    let texels: Vec<[f32; 4]> = match &decoded {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            decoded.to_rgba32f().pixels().map(|p| p.0).collect()
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => decoded
            .to_rgba16()
            .pixels()
            .map(|p| {
                let c = |v: u16| srgb_decode(f64::from(v) / 65535.0) as f32;
                [c(p.0[0]), c(p.0[1]), c(p.0[2]), f32::from(p.0[3]) / 65535.0]
            })
            .collect(),
        _ => {
            let table: Vec<f32> = (0..=255u8)
                .map(|v| srgb_decode(f64::from(v) / 255.0) as f32)
                .collect();
            decoded
                .to_rgba8()
                .pixels()
                .map(|p| {
                    let c = |v: u8| table[usize::from(v)];
                    [c(p.0[0]), c(p.0[1]), c(p.0[2]), f32::from(p.0[3]) / 255.0]
                })
                .collect()
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
