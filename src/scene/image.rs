//! Reading image files for albedo textures and tabulated BRDF maps.

use std::path::Path;

use image::{DynamicImage, ImageReader};

use super::Image;
use crate::color::srgb_decode;

/// Largest accepted image width or height in texels. Every image of a scene shares one
/// GPU texture array whose layers are as large as the largest image, so this bounds
/// each layer at 64 MiB of RGBA `f32`.
pub const MAX_IMAGE_SIDE: u32 = 2048;

/// Reads the image at `path` into linear RGBA `f32`: 8- and 16-bit files (PNG) are
/// taken as sRGB-encoded and linearised with the exact sRGB curve (IEC 61966-2-1);
/// 32-bit float files (OpenEXR, Radiance HDR) are taken as linear. Fails with a
/// message (without the path, which the caller names) when the file is missing,
/// unreadable, not a regular file (a FIFO or a device would block or never end), not
/// an image, empty or larger than [`MAX_IMAGE_SIDE`], or holds a non-finite value.
/// Texels outside [0, 1] are kept as they are: a scene's materials check their range.
pub fn load_image(path: &Path) -> Result<Image, String> {
    let metadata = std::fs::metadata(path).map_err(|e| format!("cannot read the file: {e}"))?;
    if let Some(kind) = not_a_regular_file(&metadata) {
        return Err(format!(
            "cannot read the file: it is {kind}, not a regular file"
        ));
    }
    let reader = ImageReader::open(path)
        .map_err(|e| format!("cannot read the file: {e}"))?
        .with_guessed_format()
        .map_err(|e| format!("cannot read the file: {e}"))?;
    let dimensions = reader
        .into_dimensions()
        .map_err(|e| format!("not a readable image: {e}"))?;
    check_dimensions(dimensions)?;
    let decoded = ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| format!("cannot read the file: {e}"))?
        .decode()
        .map_err(|e| format!("not a readable image: {e}"))?;
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
        return Err(format!("texel ({x}, {y}) is not a finite number"));
    }
    Ok(Image {
        path: path.to_path_buf(),
        width,
        height,
        texels,
    })
}

/// What a file that is not a regular file is ("a directory", "a FIFO", "a device",
/// "a socket"), or `None` for a regular file. Symbolic links are followed by the
/// caller's `metadata`.
pub(crate) fn not_a_regular_file(metadata: &std::fs::Metadata) -> Option<&'static str> {
    if metadata.is_file() {
        return None;
    }
    if metadata.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_fifo() {
            return Some("a FIFO");
        }
        if kind.is_char_device() || kind.is_block_device() {
            return Some("a device");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    Some("a special file")
}

fn check_dimensions((width, height): (u32, u32)) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is empty ({width}x{height})"));
    }
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(format!(
            "the image is {width}x{height}, larger than the {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE} accepted"
        ));
    }
    Ok(())
}
