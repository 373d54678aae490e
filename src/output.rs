//! Writing rendered images to disk, atomically.
//!
//! The format follows the file extension: `.png` gets the 8-bit sRGB display image,
//! `.exr` the linear image as 32-bit float RGBA and `.hdr` the linear image as Radiance
//! RGBE. Every file is first written to a temporary file beside the target, flushed and
//! synced, then renamed over the target, so a failed write never leaves a truncated or
//! half-written file where the old one was, and no temporary file stays behind.

use std::fmt;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use image::{DynamicImage, ImageFormat, Rgb32FImage, Rgba32FImage, RgbaImage};

use crate::film::LinearImage;

/// An image file format the renderer writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// 8-bit RGBA PNG of the display image (sRGB encoded, or naive gamma values).
    Png,
    /// OpenEXR, linear 32-bit float RGBA.
    Exr,
    /// Radiance HDR (RGBE), linear RGB.
    Hdr,
}

impl OutputFormat {
    /// Every supported format, in the order they are listed in messages.
    pub const ALL: [OutputFormat; 3] = [OutputFormat::Png, OutputFormat::Exr, OutputFormat::Hdr];

    /// The format named by the extension of `path` (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            Some("hdr") => Ok(OutputFormat::Hdr),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
                extension: path.extension().map(|e| e.to_string_lossy().into_owned()),
            }),
        }
    }

    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Png => "png",
            OutputFormat::Exr => "exr",
            OutputFormat::Hdr => "hdr",
        }
    }

    /// Whether the format stores the linear float image rather than the display image.
    pub fn is_linear(self) -> bool {
        !matches!(self, OutputFormat::Png)
    }

    fn image_format(self) -> ImageFormat {
        match self {
            OutputFormat::Png => ImageFormat::Png,
            OutputFormat::Exr => ImageFormat::OpenExr,
            OutputFormat::Hdr => ImageFormat::Hdr,
        }
    }
}

impl fmt::Display for OutputFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            OutputFormat::Png => "PNG",
            OutputFormat::Exr => "OpenEXR",
            OutputFormat::Hdr => "Radiance HDR",
        })
    }
}

/// A failure to write an output image. Every message starts with the output path.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension names no supported format.
    #[error(
        "{}: unsupported output format {}; use .png (8-bit sRGB), .exr (linear float) or .hdr (linear Radiance)",
        .path.display(),
        describe_extension(.extension)
    )]
    UnknownFormat {
        /// The output file.
        path: PathBuf,
        /// Its extension, if it has one.
        extension: Option<String>,
    },
    /// The directory the file would go into does not exist or is not a directory.
    #[error("{}: the output directory {} does not exist", .path.display(), .dir.display())]
    MissingDirectory {
        /// The output file.
        path: PathBuf,
        /// Its parent directory.
        dir: PathBuf,
    },
    /// The output path names an existing directory.
    #[error("{}: is a directory; give a file name ending in .png, .exr or .hdr", .path.display())]
    IsDirectory {
        /// The output path.
        path: PathBuf,
    },
    /// The image and the buffers handed to the writer disagree in size.
    #[error("{}: cannot write the image: {message}", .path.display())]
    BadImage {
        /// The output file.
        path: PathBuf,
        /// Which buffer has the wrong size.
        message: String,
    },
    /// Encoding the image failed.
    #[error("{}: cannot encode the image as {format}: {source}", .path.display())]
    Encode {
        /// The output file.
        path: PathBuf,
        /// The format being written.
        format: OutputFormat,
        /// The encoder's error.
        source: image::ImageError,
    },
    /// Creating, writing, syncing or renaming the file failed.
    #[error("{}: cannot {action}: {source}", .path.display())]
    Io {
        /// The output file.
        path: PathBuf,
        /// What was being done ("create a temporary file in /dir", ...).
        action: String,
        /// The operating system's error.
        source: io::Error,
    },
}

fn describe_extension(extension: &Option<String>) -> String {
    match extension {
        Some(e) => format!("\".{e}\""),
        None => "(no extension)".to_owned(),
    }
}

/// The directory a file at `path` is written into (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

/// Checks, before any rendering, that `path` can take an image: its extension names a
/// supported format and its directory exists. Returns the format.
pub fn check_output_path(path: &Path) -> Result<OutputFormat, OutputError> {
    if path.is_dir() {
        return Err(OutputError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let format = OutputFormat::from_path(path)?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    Ok(format)
}

/// Writes `image` to `path`, choosing the format from the extension: `.png` gets the
/// 8-bit display image `display_rgba8` (`width * height * 4` bytes, top row first),
/// `.exr` and `.hdr` the linear float image.
///
/// The write is atomic: the file is written to a temporary file in the same directory
/// and renamed over `path` only once it is complete and synced. On any error an
/// existing file at `path` is left untouched and the temporary file is removed.
pub fn write_image(
    path: &Path,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<(), OutputError> {
    let format = OutputFormat::from_path(path)?;
    let encoded = to_dynamic_image(path, format, image, display_rgba8)?;
    write_atomically(path, |writer| {
        encoded
            .write_to(writer, format.image_format())
            .map_err(|source| OutputError::Encode {
                path: path.to_path_buf(),
                format,
                source,
            })
    })
}

/// Writes an 8-bit RGBA image (a plot, say) to the PNG file `path`, atomically.
pub fn write_png_rgba8(
    path: &Path,
    width: u32,
    height: u32,
    rgba8: Vec<u8>,
) -> Result<(), OutputError> {
    let image = RgbaImage::from_raw(width, height, rgba8).ok_or_else(|| OutputError::BadImage {
        path: path.to_path_buf(),
        message: format!("the buffer does not hold a {width}x{height} RGBA8 image"),
    })?;
    write_atomically(path, |writer| {
        image
            .write_to(writer, ImageFormat::Png)
            .map_err(|source| OutputError::Encode {
                path: path.to_path_buf(),
                format: OutputFormat::Png,
                source,
            })
    })
}

/// Writes `text` to `path` atomically (a CSV table, say).
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomically(path, |writer| {
        writer
            .write_all(text.as_bytes())
            .map_err(|source| OutputError::Io {
                path: path.to_path_buf(),
                action: "write the file".to_owned(),
                source,
            })
    })
}

/// Converts the render to the pixel layout `format` stores, checking buffer sizes.
fn to_dynamic_image(
    path: &Path,
    format: OutputFormat,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<DynamicImage, OutputError> {
    let bad = |message: String| OutputError::BadImage {
        path: path.to_path_buf(),
        message,
    };
    let (width, height) = (image.width, image.height);
    let pixels = width as usize * height as usize;
    if width == 0 || height == 0 {
        return Err(bad(format!("the image is empty ({width}x{height})")));
    }
    match format {
        OutputFormat::Png => {
            let expected = pixels * 4;
            if display_rgba8.len() != expected {
                return Err(bad(format!(
                    "the display buffer has {} bytes, but a {width}x{height} RGBA8 image needs {expected}",
                    display_rgba8.len()
                )));
            }
            RgbaImage::from_raw(width, height, display_rgba8.to_vec())
                .map(DynamicImage::ImageRgba8)
                .ok_or_else(|| bad("the display buffer does not fit the image size".into()))
        }
        OutputFormat::Exr | OutputFormat::Hdr => {
            if image.pixels.len() != pixels {
                return Err(bad(format!(
                    "the linear image has {} pixels, but {width}x{height} needs {pixels}",
                    image.pixels.len()
                )));
            }
            let converted = if format == OutputFormat::Exr {
                let data = image.pixels.iter().flatten().copied().collect();
                Rgba32FImage::from_raw(width, height, data).map(DynamicImage::ImageRgba32F)
            } else {
                let data = image
                    .pixels
                    .iter()
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect();
                Rgb32FImage::from_raw(width, height, data).map(DynamicImage::ImageRgb32F)
            };
            converted.ok_or_else(|| bad("the linear image does not fit the image size".into()))
        }
    }
}

/// Runs `encode` on a temporary file beside `path`, syncs it and renames it over `path`.
/// The temporary file is deleted on every error path (by `NamedTempFile`'s drop).
fn write_atomically(
    path: &Path,
    encode: impl FnOnce(&mut BufWriter<&mut std::fs::File>) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    let io_error = |action: String| {
        let path = path.to_path_buf();
        move |source: io::Error| OutputError::Io {
            path,
            action,
            source,
        }
    };
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".gpu-render-").suffix(".tmp");
    #[cfg(unix)]
    {
        // Like an ordinary new file: rw for everyone, narrowed by the umask.
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut temp = builder.tempfile_in(dir).map_err(io_error(format!(
        "create a temporary file in {}",
        dir.display()
    )))?;
    {
        let mut writer = BufWriter::new(temp.as_file_mut());
        encode(&mut writer)?;
        writer
            .flush()
            .map_err(io_error("write the file".to_owned()))?;
    }
    temp.as_file()
        .sync_all()
        .map_err(io_error("sync the file to disk".to_owned()))?;
    temp.persist(path)
        .map_err(|e| io_error("move the finished file into place".to_owned())(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(width: u32, height: u32) -> LinearImage {
        let mut image = LinearImage::new(width, height);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            let t = i as f32 / (width * height) as f32;
            *p = [t * 3.7, 0.125 + t, 1.0 / (1.0 + i as f32), 1.0];
        }
        image
    }

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("read test dir")
            .map(|e| e.expect("dir entry").path())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn format_from_extension() {
        assert_eq!(
            OutputFormat::from_path(Path::new("a.png")).ok(),
            Some(OutputFormat::Png)
        );
        assert_eq!(
            OutputFormat::from_path(Path::new("a.PNG")).ok(),
            Some(OutputFormat::Png)
        );
        assert_eq!(
            OutputFormat::from_path(Path::new("d/a.exr")).ok(),
            Some(OutputFormat::Exr)
        );
        assert_eq!(
            OutputFormat::from_path(Path::new("a.hdr")).ok(),
            Some(OutputFormat::Hdr)
        );
        for bad in ["a.jpg", "a", "a.png.bak", ".png"] {
            let err = OutputFormat::from_path(Path::new(bad)).expect_err(bad);
            let message = err.to_string();
            assert!(message.starts_with(bad), "{message}");
            assert!(message.contains("unsupported output format"), "{message}");
        }
    }

    #[test]
    fn png_round_trip() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.png");
        let image = gradient(5, 3);
        let display = image.to_display_rgba8(true);
        write_image(&path, &image, &display).expect("write png");
        let read = image::open(&path).expect("open png").to_rgba8();
        assert_eq!(read.dimensions(), (5, 3));
        assert_eq!(read.into_raw(), display);
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.exr");
        let image = gradient(4, 3);
        write_image(&path, &image, &[]).expect("write exr");
        let read = image::open(&path).expect("open exr").to_rgba32f();
        assert_eq!(read.dimensions(), (4, 3));
        let expected: Vec<f32> = image.pixels.iter().flatten().copied().collect();
        assert_eq!(read.into_raw(), expected);
    }

    #[test]
    fn hdr_round_trip_within_rgbe_precision() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.hdr");
        let image = gradient(6, 2);
        write_image(&path, &image, &[]).expect("write hdr");
        let read = image::open(&path).expect("open hdr").to_rgb32f();
        assert_eq!(read.dimensions(), (6, 2));
        for (got, want) in read.pixels().zip(&image.pixels) {
            let scale = want[..3].iter().fold(0.0f32, |m, &c| m.max(c));
            for c in 0..3 {
                // RGBE keeps 8 mantissa bits relative to the largest channel.
                assert!(
                    (got.0[c] - want[c]).abs() <= scale / 128.0,
                    "{:?} vs {:?}",
                    got.0,
                    want
                );
            }
        }
    }

    #[test]
    fn unknown_extension_is_an_error_naming_the_path() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.jpg");
        let image = gradient(2, 2);
        let err = write_image(&path, &image, &image.to_display_rgba8(true)).expect_err("jpg");
        assert!(matches!(err, OutputError::UnknownFormat { .. }));
        assert!(err.to_string().contains("out.jpg"), "{err}");
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn check_output_path_wants_an_existing_directory() {
        let dir = tempfile::tempdir().expect("tempdir");
        let ok = dir.path().join("x.exr");
        assert_eq!(check_output_path(&ok).ok(), Some(OutputFormat::Exr));
        assert_eq!(
            check_output_path(Path::new("bare.png")).ok(),
            Some(OutputFormat::Png)
        );
        let taken = dir.path().join("taken.png");
        std::fs::create_dir(&taken).expect("mkdir");
        let err = check_output_path(&taken).expect_err("directory");
        assert!(matches!(err, OutputError::IsDirectory { .. }), "{err}");
        let missing = dir.path().join("nope").join("x.png");
        let err = check_output_path(&missing).expect_err("missing dir");
        assert!(matches!(err, OutputError::MissingDirectory { .. }));
        assert!(err.to_string().contains("nope"), "{err}");
    }

    #[test]
    fn failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("keep.png");
        let old = b"previous contents, not even a PNG".to_vec();
        std::fs::write(&path, &old).expect("seed file");
        let image = gradient(4, 4);

        // Display buffer of the wrong length.
        let err = write_image(&path, &image, &[0u8; 7]).expect_err("short buffer");
        assert!(matches!(err, OutputError::BadImage { .. }), "{err}");
        assert!(err.to_string().contains("keep.png"), "{err}");
        assert_eq!(std::fs::read(&path).expect("read back"), old);

        // Linear image whose pixel count disagrees with its size.
        let exr = dir.path().join("keep.exr");
        std::fs::write(&exr, &old).expect("seed exr");
        let mut broken = gradient(4, 4);
        broken.pixels.pop();
        assert!(write_image(&exr, &broken, &[]).is_err());
        assert_eq!(std::fs::read(&exr).expect("read back"), old);

        assert_eq!(entries(dir.path()), vec![exr, path]);
    }

    #[test]
    fn write_into_missing_directory_fails_cleanly() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("missing").join("out.png");
        let image = gradient(2, 2);
        let err = write_image(&path, &image, &image.to_display_rgba8(true)).expect_err("no dir");
        assert!(err.to_string().contains("missing"), "{err}");
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn failed_rename_leaves_no_temporary() {
        // The target is a non-empty directory: the rename over it fails after the
        // temporary file was fully written.
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("taken.png");
        std::fs::create_dir(&path).expect("mkdir");
        std::fs::write(path.join("inside"), b"x").expect("fill dir");
        let image = gradient(2, 2);
        let err = write_image(&path, &image, &image.to_display_rgba8(true)).expect_err("dir");
        assert!(matches!(err, OutputError::Io { .. }), "{err}");
        assert!(err.to_string().contains("taken.png"), "{err}");
        assert_eq!(entries(dir.path()), vec![path.clone()]);
        assert_eq!(entries(&path), vec![path.join("inside")]);
    }

    #[test]
    fn overwrites_an_existing_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.png");
        std::fs::write(&path, b"old").expect("seed");
        let image = gradient(3, 2);
        let display = image.to_display_rgba8(false);
        write_image(&path, &image, &display).expect("overwrite");
        let read = image::open(&path).expect("open").to_rgba8();
        assert_eq!(read.into_raw(), display);
    }
}
