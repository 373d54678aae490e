//! Writing rendered images to disk (being written).

use std::path::Path;

use crate::film::LinearImage;

/// A failure to write an output image.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct OutputError {
    /// The output file.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

/// Writes `image` to `path`, choosing the format from the extension: `.png` gets the
/// 8-bit display image `display_rgba8`, `.exr` and `.hdr` the linear float image.
pub fn write_image(
    path: &Path,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<(), OutputError> {
    let _ = (image, display_rgba8);
    Err(OutputError {
        path: path.display().to_string(),
        message: "not written yet".into(),
    })
}
