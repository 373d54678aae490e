//! Writing rendered images to disk, atomically.
//!
//! The format follows the file extension: `.png` gets the 8-bit sRGB display image,
//! `.exr` the linear image as 32-bit float RGBA and `.hdr` the linear image as Radiance
//! RGBE. Every file is first written to a temporary file beside the target, flushed and
//! synced, then renamed over the target, so a failed write never leaves a truncated or
//! half-written file where the old one was, and no temporary file stays behind: on
//! Linux the temporary file has no name until it is complete, so that even a process
//! killed with SIGKILL leaves nothing (see `temporary`).
//!
//! A program that handles signals calls [`cancel_pending_writes`] from its handler
//! before it exits: that removes the temporary files of the writes in progress and
//! makes them fail instead of completing (see `docs/reliability.md`).
//!
//! Radiance HDR cannot hold every `f32`: a channel above [`HDR_MAX`] is clamped to it
//! (and counted in [`Written::clamped_pixels`]) rather than written as black.

use std::fmt;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use image::codecs::hdr::HdrEncoder;
use image::codecs::openexr::OpenExrEncoder;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, Rgb};

use crate::film::LinearImage;
use crate::input::{FileIdentity, InputFile};

mod layers;
mod temporary;

pub use layers::{AuxPass, write_exr_with_passes};
use temporary::Temporary;
pub use temporary::cancel_pending_writes;

/// The largest value a Radiance HDR (RGBE) file holds: mantissa 255, exponent 2^127
/// (`255 · 2^119 ≈ 1.69e38`). Larger channels are clamped to it.
pub const HDR_MAX: f32 = 255.0 * (1u128 << 119) as f32;

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
#[non_exhaustive]
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
    /// The output path names an existing directory, or ends with a path separator.
    #[error("{}: is a directory; give a file name ending in .png, .exr or .hdr", .path.display())]
    IsDirectory {
        /// The output path.
        path: PathBuf,
    },
    /// The output path exists and is not a regular file (a FIFO, a device, a socket).
    #[error("{}: exists and is not a regular file ({kind}); give the path of a file", .path.display())]
    NotARegularFile {
        /// The output path.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// The output is one of the render's inputs (the scene file or a texture).
    #[error(
        "{}: is the same file as the {what} {}; writing it would destroy the input",
        .path.display(),
        .input.display()
    )]
    OverwritesInput {
        /// The output path.
        path: PathBuf,
        /// The input it would replace.
        input: PathBuf,
        /// What the input is ("scene file", "texture").
        what: String,
    },
    /// Two outputs of one command name the same file (`-o img.exr` with
    /// `--standard-error ./img.exr`): the second would replace the first.
    #[error(
        "{}: the {what} is the same file as the {other_what} {}; name another file for each",
        .path.display(),
        .other.display()
    )]
    SameOutput {
        /// The later output.
        path: PathBuf,
        /// What it is ("--standard-error").
        what: String,
        /// The earlier output it collides with.
        other: PathBuf,
        /// What that is ("image (-o)").
        other_what: String,
    },
    /// The image and the buffers handed to the writer disagree in size.
    #[error("{}: cannot write the image: {message}", .path.display())]
    BadImage {
        /// The output file.
        path: PathBuf,
        /// Which buffer has the wrong size.
        message: String,
    },
    /// The encoder failed for a reason other than writing (which is [`OutputError::Io`]).
    #[error("{}: cannot encode the image as {format}: {error}", .path.display())]
    Encode {
        /// The output file.
        path: PathBuf,
        /// The format being written.
        format: OutputFormat,
        /// The encoder's error (in the message; not repeated as a source).
        error: image::ImageError,
    },
    /// The OpenEXR encoder of tiles (the `exr` crate, which writes data windows and
    /// custom attributes) failed for a reason other than writing.
    #[error("{}: cannot encode the OpenEXR tile: {message}", .path.display())]
    EncodeExr {
        /// The output file.
        path: PathBuf,
        /// The encoder's words.
        message: String,
    },
    /// Creating, writing, syncing or renaming the file failed.
    #[error("{}: cannot {action}: {error}", .path.display())]
    Io {
        /// The output file.
        path: PathBuf,
        /// What was being done ("create a temporary file in /dir", ...).
        action: String,
        /// The operating system's error (in the message; not repeated as a source).
        error: io::Error,
    },
    /// [`cancel_pending_writes`] was called (a signal arrived): nothing was written.
    #[error("{}: not written: the program was interrupted", .path.display())]
    Cancelled {
        /// The output file.
        path: PathBuf,
    },
}

/// What a successful write did besides writing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Written {
    /// Pixels with a channel above what the format holds, clamped to its largest value
    /// ([`HDR_MAX`] for `.hdr`; always 0 for `.png`, which clamps to [0, 1] by design,
    /// and `.exr`, which holds every `f32`).
    pub clamped_pixels: u64,
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

/// Checks, before any rendering, that `path` can take an image: it does not name a
/// directory (nor end with a path separator), it is not an existing FIFO, device or
/// other non-regular file, its extension names a supported format, and its directory
/// exists and takes a new file (a temporary file is created there and removed).
/// Returns the format.
pub fn check_output_path(path: &Path) -> Result<OutputFormat, OutputError> {
    if path.is_dir() || ends_with_separator(path) {
        return Err(OutputError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    if let Ok(metadata) = std::fs::metadata(path)
        && !metadata.is_file()
    {
        return Err(OutputError::NotARegularFile {
            path: path.to_path_buf(),
            kind: file_kind(&metadata),
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
    // The probe proves the directory takes new files.
    Temporary::create(path, dir)?.discard();
    Ok(format)
}

/// Whether `path` is spelled with a trailing separator (`out.png/`), which names a
/// directory even though `Path` ignores it.
fn ends_with_separator(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    text.last()
        .is_some_and(|&last| std::path::is_separator(char::from(last)))
}

/// A short name of what a non-regular file is.
fn file_kind(metadata: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if metadata.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Refuses an output path that is the same file as one of `inputs` (compared by device
/// and inode, so symbolic and hard links to an input count): rendering a scene file
/// `scene.png` to `-o scene.png`, or over one of its textures, would destroy the input.
/// `inputs` pairs each path with what it is ("scene file", "texture"). An output that
/// does not exist yet is no input.
pub fn check_not_an_input<'a, 'b>(
    path: &Path,
    inputs: impl IntoIterator<Item = (&'a Path, &'b str)>,
) -> Result<(), OutputError> {
    let Some(output) = FileIdentity::at(path) else {
        return Ok(());
    };
    for (input, what) in inputs {
        if FileIdentity::at(input).as_ref() == Some(&output) {
            return Err(OutputError::OverwritesInput {
                path: path.to_path_buf(),
                input: input.to_path_buf(),
                what: what.to_owned(),
            });
        }
    }
    Ok(())
}

/// Refuses an output path that is one of the files a load read
/// ([`crate::input::record_inputs`]): the file it names now is compared with each
/// input's identity when it was read, and with what the input's path reaches now, so
/// that neither a link nor another spelling of the name gets past.
pub fn check_not_read(path: &Path, inputs: &[InputFile]) -> Result<(), OutputError> {
    let Some(output) = FileIdentity::at(path) else {
        return Ok(());
    };
    for input in inputs {
        if input.identity == output || FileIdentity::at(&input.path).as_ref() == Some(&output) {
            return Err(OutputError::OverwritesInput {
                path: path.to_path_buf(),
                input: input.path.clone(),
                what: "input".to_owned(),
            });
        }
    }
    Ok(())
}

/// Refuses two outputs of one command that would land in the same file: `outputs` pairs
/// each path with what it is ("image (-o)", "--standard-error"). Paths are compared as
/// files, not as text: an existing file by device and inode (so links count), a new one
/// by its resolved folder and name (`./img.exr` and `img.exr` are one file). Each
/// path's folder must exist ([`check_output_path`] checks that first).
pub fn check_distinct_outputs(outputs: &[(&Path, &str)]) -> Result<(), OutputError> {
    for (i, &(first, first_what)) in outputs.iter().enumerate() {
        for &(second, second_what) in &outputs[i + 1..] {
            if same_destination(first, second) {
                return Err(OutputError::SameOutput {
                    path: second.to_path_buf(),
                    what: second_what.to_owned(),
                    other: first.to_path_buf(),
                    other_what: first_what.to_owned(),
                });
            }
        }
    }
    Ok(())
}

/// Whether writing `a` and writing `b` would replace the same file.
fn same_destination(a: &Path, b: &Path) -> bool {
    if let (Some(a), Some(b)) = (FileIdentity::at(a), FileIdentity::at(b)) {
        return a == b;
    }
    let resolved = |path: &Path| {
        let dir = parent_dir(path).canonicalize().ok()?;
        Some((dir, path.file_name()?.to_owned()))
    };
    match (resolved(a), resolved(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}

/// Writes `image` to `path`, choosing the format from the extension: `.png` gets the
/// 8-bit display image `display_rgba8` (`width * height * 4` bytes, top row first),
/// `.exr` and `.hdr` the linear float image. A `.hdr` channel above [`HDR_MAX`] is
/// clamped to it; the returned [`Written`] counts those pixels, so a program can warn.
///
/// The write is atomic: the file is written to a temporary file in the same directory
/// and renamed over `path` only once it is complete and synced. On any error an
/// existing file at `path` is left untouched and the temporary file is removed.
/// The buffers are encoded in place (only `.hdr` makes a copy, of RGB without alpha).
pub fn write_image(
    path: &Path,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<Written, OutputError> {
    let format = OutputFormat::from_path(path)?;
    check_buffers(path, format, image, display_rgba8)?;
    let mut clamped_pixels = 0;
    write_atomically(path, |writer| {
        clamped_pixels = encode_image(writer, format, image, display_rgba8)?;
        Ok(())
    })?;
    Ok(Written { clamped_pixels })
}

/// Encodes the buffers `format` needs (checked by [`check_buffers`]) into `writer`;
/// returns the number of pixels clamped to the format's range.
fn encode_image(
    writer: &mut EncodeWriter<'_>,
    format: OutputFormat,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<u64, EncodeFailure> {
    let (width, height) = (image.width, image.height);
    let mut clamped_pixels = 0;
    let encoded = match format {
        OutputFormat::Png => PngEncoder::new(writer).write_image(
            display_rgba8,
            width,
            height,
            ExtendedColorType::Rgba8,
        ),
        OutputFormat::Exr => OpenExrEncoder::new(writer).write_image(
            bytemuck::cast_slice(&image.pixels),
            width,
            height,
            ExtendedColorType::Rgba32F,
        ),
        OutputFormat::Hdr => {
            let (rgb, clamped) = hdr_pixels(image);
            clamped_pixels = clamped;
            HdrEncoder::new(writer).encode(&rgb, width as usize, height as usize)
        }
    };
    encoded.map_err(|error| EncodeFailure::Image(format, error))?;
    Ok(clamped_pixels)
}

/// The RGB of `image` with every channel clamped to [`HDR_MAX`], and how many pixels
/// had a channel clamped.
fn hdr_pixels(image: &LinearImage) -> (Vec<Rgb<f32>>, u64) {
    let mut clamped = 0;
    let rgb = image
        .pixels
        .iter()
        .map(|p| {
            if p[..3].iter().any(|&c| c > HDR_MAX) {
                clamped += 1;
            }
            Rgb([p[0].min(HDR_MAX), p[1].min(HDR_MAX), p[2].min(HDR_MAX)])
        })
        .collect();
    (rgb, clamped)
}

/// Writes an 8-bit RGBA image (a plot, say) to the PNG file `path`, atomically.
pub fn write_png_rgba8(
    path: &Path,
    width: u32,
    height: u32,
    rgba8: Vec<u8>,
) -> Result<(), OutputError> {
    let expected = width as usize * height as usize * 4;
    if width == 0 || height == 0 || rgba8.len() != expected {
        return Err(OutputError::BadImage {
            path: path.to_path_buf(),
            message: format!("the buffer does not hold a {width}x{height} RGBA8 image"),
        });
    }
    write_atomically(path, |writer| {
        PngEncoder::new(writer)
            .write_image(&rgba8, width, height, ExtendedColorType::Rgba8)
            .map_err(|error| EncodeFailure::Image(OutputFormat::Png, error))
    })
}

/// Writes `bytes` (a file encoded in memory: a tile, a cache) to `path`, atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomically(path, |writer| {
        writer.write_all(bytes).map_err(EncodeFailure::Io)
    })
}

/// Writes `text` to `path` atomically (a CSV table, say).
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomically(path, |writer| {
        writer.write_all(text.as_bytes()).map_err(EncodeFailure::Io)
    })
}

/// Checks that the buffers the format needs have the image's size.
fn check_buffers(
    path: &Path,
    format: OutputFormat,
    image: &LinearImage,
    display_rgba8: &[u8],
) -> Result<(), OutputError> {
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
        OutputFormat::Png if display_rgba8.len() != pixels * 4 => Err(bad(format!(
            "the display buffer has {} bytes, but a {width}x{height} RGBA8 image needs {}",
            display_rgba8.len(),
            pixels * 4
        ))),
        OutputFormat::Exr | OutputFormat::Hdr if image.pixels.len() != pixels => Err(bad(format!(
            "the linear image has {} pixels, but {width}x{height} needs {pixels}",
            image.pixels.len()
        ))),
        _ => Ok(()),
    }
}

/// Why an encoder stopped.
enum EncodeFailure {
    /// The image encoder's error, while writing this format.
    Image(OutputFormat, image::ImageError),
    /// A plain write failed.
    Io(io::Error),
}

/// A writer that keeps the first I/O error it returned, so that a failed encode is
/// reported as the write error it was (disk full), not as whatever the encoder calls
/// it (the OpenEXR encoder calls every error a decoding error).
struct RecordingWriter<W> {
    inner: W,
    error: Option<io::Error>,
}

impl<W> RecordingWriter<W> {
    fn record<T>(&mut self, result: io::Result<T>) -> io::Result<T> {
        if let Err(e) = &result
            && self.error.is_none()
        {
            self.error = Some(match e.raw_os_error() {
                Some(code) => io::Error::from_raw_os_error(code),
                None => io::Error::new(e.kind(), e.to_string()),
            });
        }
        result
    }
}

impl<W: Write> Write for RecordingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let result = self.inner.write(buf);
        self.record(result)
    }

    fn flush(&mut self) -> io::Result<()> {
        let result = self.inner.flush();
        self.record(result)
    }
}

impl<W: Seek> Seek for RecordingWriter<W> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        let result = self.inner.seek(pos);
        self.record(result)
    }
}

/// What an encoder writes into: a file, or in tests anything seekable.
trait WriteSeek: Write + Seek {}

impl<T: Write + Seek> WriteSeek for T {}

/// The writer an encoder gets: buffered, over the temporary file, recording errors.
type EncodeWriter<'a> = BufWriter<RecordingWriter<&'a mut dyn WriteSeek>>;

/// Runs `encode` into `inner` and flushes it. An I/O error of `inner` is reported as
/// what it is ([`OutputError::Io`], "cannot write the file: No space left on device")
/// whatever the encoder turned it into.
fn encode_to(
    path: &Path,
    inner: &mut dyn WriteSeek,
    encode: impl FnOnce(&mut EncodeWriter<'_>) -> Result<(), EncodeFailure>,
) -> Result<(), OutputError> {
    let write_error = |error| OutputError::Io {
        path: path.to_path_buf(),
        action: "write the file".to_owned(),
        error,
    };
    let mut writer = BufWriter::new(RecordingWriter { inner, error: None });
    let encoded = encode(&mut writer);
    let flushed = writer.flush();
    match (encoded, writer.get_mut().error.take()) {
        (_, Some(error)) | (Err(EncodeFailure::Io(error)), None) => Err(write_error(error)),
        (Err(EncodeFailure::Image(format, error)), None) => Err(OutputError::Encode {
            path: path.to_path_buf(),
            format,
            error,
        }),
        (Ok(()), None) => flushed.map_err(write_error),
    }
}

/// Runs `encode` on a temporary file beside `path`, syncs it and renames it over `path`.
/// The temporary file is deleted on every error path, and is known to
/// [`cancel_pending_writes`] while it exists.
fn write_atomically(
    path: &Path,
    encode: impl FnOnce(&mut EncodeWriter<'_>) -> Result<(), EncodeFailure>,
) -> Result<(), OutputError> {
    let io_error = |action: &str| {
        let path = path.to_path_buf();
        let action = action.to_owned();
        move |error: io::Error| OutputError::Io {
            path,
            action,
            error,
        }
    };
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    let mut temp = Temporary::create(path, dir)?;
    let result = encode_to(path, temp.file_mut(), encode).and_then(|()| {
        temp.file()
            .sync_all()
            .map_err(io_error("sync the file to disk"))
    });
    if let Err(error) = result {
        temp.discard();
        return Err(error);
    }
    temp.persist(path)
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

    #[test]
    fn hdr_clamps_radiance_above_its_largest_value_instead_of_writing_black() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("bright.hdr");
        let mut image = LinearImage::new(4, 1);
        image.pixels = vec![
            [1.0, 2.0, 3.0, 1.0],
            [2e38, 0.0, 0.0, 1.0],
            [f32::MAX, 1e38, 0.5, 1.0],
            [HDR_MAX, HDR_MAX, 0.0, 1.0],
        ];
        let written = write_image(&path, &image, &[]).expect("write hdr");
        assert_eq!(written.clamped_pixels, 2);
        let read = image::open(&path).expect("open hdr").to_rgb32f();
        let pixels: Vec<[f32; 3]> = read.pixels().map(|p| p.0).collect();
        assert_eq!(pixels[1][0], HDR_MAX, "{pixels:?}");
        assert_eq!(pixels[2][0], HDR_MAX, "{pixels:?}");
        assert!((pixels[2][1] - 1e38).abs() <= HDR_MAX / 128.0, "{pixels:?}");
        assert_eq!(pixels[3][..2], [HDR_MAX, HDR_MAX]);
        // A value past HDR_MAX is not representable: RGBE's largest exponent is 2^127.
        assert!(f64::from(HDR_MAX) < 2f64.powi(127));
    }

    #[test]
    fn exr_and_png_report_no_clamping() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut image = gradient(2, 2);
        image.pixels[0] = [3e38, 1.0, 1.0, 1.0];
        let display = image.to_display_rgba8(true);
        for name in ["a.exr", "a.png"] {
            let written = write_image(&dir.path().join(name), &image, &display).expect(name);
            assert_eq!(written.clamped_pixels, 0, "{name}");
        }
        let read = image::open(dir.path().join("a.exr"))
            .expect("exr")
            .to_rgba32f();
        assert_eq!(read.get_pixel(0, 0).0[0], 3e38);
    }

    /// A seekable writer that fails like a full disk after `room` bytes.
    struct DiskFull {
        room: usize,
        written: std::io::Cursor<Vec<u8>>,
    }

    impl Write for DiskFull {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.written.get_ref().len() + buf.len() > self.room {
                return Err(io::Error::from_raw_os_error(28)); // ENOSPC
            }
            self.written.write(buf)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Seek for DiskFull {
        fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
            self.written.seek(pos)
        }
    }

    #[test]
    fn a_full_disk_is_a_write_error_in_every_format() {
        let image = gradient(64, 64);
        let display = image.to_display_rgba8(true);
        for format in OutputFormat::ALL {
            let path = PathBuf::from(format!("full.{}", format.extension()));
            let mut disk = DiskFull {
                room: 1000,
                written: std::io::Cursor::new(Vec::new()),
            };
            let err = encode_to(&path, &mut disk, |writer| {
                encode_image(writer, format, &image, &display).map(|_| ())
            })
            .expect_err("the disk is full");
            let message = err.to_string();
            assert!(matches!(err, OutputError::Io { .. }), "{format}: {message}");
            assert!(
                message.starts_with(path.to_str().unwrap_or("")),
                "{message}"
            );
            assert!(message.contains("cannot write the file"), "{message}");
            assert!(!message.to_lowercase().contains("decod"), "{message}");
            let os = io::Error::from_raw_os_error(28).to_string();
            assert_eq!(message.matches(&os).count(), 1, "{message}");
        }
    }

    #[test]
    fn io_errors_do_not_repeat_themselves_in_the_cause_chain() {
        let err = OutputError::Io {
            path: PathBuf::from("x.png"),
            action: "write the file".into(),
            error: io::Error::from_raw_os_error(13),
        };
        assert!(std::error::Error::source(&err).is_none());
        let shown = format!("{:#}", anyhow::Error::new(err));
        assert_eq!(shown.matches("ermission denied").count(), 1, "{shown}");
    }

    #[test]
    fn check_output_path_refuses_a_trailing_separator() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = PathBuf::from(format!("{}/dir.png/", dir.path().display()));
        let err = check_output_path(&path).expect_err("names a directory");
        assert!(matches!(err, OutputError::IsDirectory { .. }), "{err}");
        assert!(entries(dir.path()).is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn check_output_path_refuses_a_fifo_and_leaves_no_probe() {
        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join("pipe.png");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("run mkfifo");
        assert!(made.success());
        let err = check_output_path(&fifo).expect_err("a FIFO");
        assert!(err.to_string().contains("a FIFO"), "{err}");
        let ok = dir.path().join("fine.png");
        assert_eq!(check_output_path(&ok).ok(), Some(OutputFormat::Png));
        assert_eq!(entries(dir.path()), vec![fifo]);
    }

    #[cfg(unix)]
    #[test]
    fn check_output_path_refuses_a_directory_that_takes_no_files() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("tempdir");
        let locked = dir.path().join("locked");
        std::fs::create_dir(&locked).expect("mkdir");
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        // Root writes anywhere; the check is only meaningful for other users.
        let writable = tempfile::tempfile_in(&locked).is_ok();
        let result = check_output_path(&locked.join("out.png"));
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        if writable {
            assert!(result.is_ok());
        } else {
            let err = result.expect_err("read-only directory");
            let message = err.to_string();
            assert!(message.contains("create a temporary file"), "{message}");
            assert_eq!(message.matches("ermission denied").count(), 1, "{message}");
        }
    }

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let scene = dir.path().join("scene.png");
        let texture = dir.path().join("wood.png");
        std::fs::write(&scene, b"[camera]").expect("scene");
        std::fs::write(&texture, b"texels").expect("texture");
        let inputs = [
            (scene.as_path(), "scene file"),
            (texture.as_path(), "texture"),
        ];
        let err = check_not_an_input(&scene, inputs).expect_err("the scene itself");
        assert!(err.to_string().contains("scene file"), "{err}");
        assert!(check_not_an_input(&texture, inputs).is_err());
        assert!(check_not_an_input(&dir.path().join("new.png"), inputs).is_ok());
        let other = dir.path().join("other.png");
        std::fs::write(&other, b"x").expect("other");
        assert!(check_not_an_input(&other, inputs).is_ok());
        let hard = dir.path().join("hard.png");
        std::fs::hard_link(&texture, &hard).expect("hard link");
        assert!(check_not_an_input(&hard, inputs).is_err());
        #[cfg(unix)]
        {
            let link = dir.path().join("link.png");
            std::os::unix::fs::symlink(&scene, &link).expect("symlink");
            let err = check_not_an_input(&link, inputs).expect_err("a link to the scene");
            assert!(err.to_string().contains("scene.png"), "{err}");
        }
    }
}
