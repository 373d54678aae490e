//! The tile file: a scan-line OpenEXR image of one part whose data window is the
//! tile's window and whose display window is the whole image, with the linear image
//! and the display image as channels, and the render it belongs to as attributes.
//!
//! Channels (sorted by name, as OpenEXR wants): `A`, `B`, `G`, `R`, the linear
//! radiance as 32-bit float, and `display.A`, `display.B`, `display.G`,
//! `display.R`, the 8-bit display image as the backend made it (on the GPU its
//! display pass, which may differ from the CPU's encoding by one step at a rounding
//! boundary, `tests/integration/display_pass.rs`), as 32-bit unsigned integers of 0 to 255. The
//! merged PNG is then the whole render's PNG byte for byte. Compression: ZIP of 16
//! rows (lossless).
//!
//! Attributes (besides the standard `dataWindow` and `displayWindow`):
//!
//! | name | type | value |
//! |---|---|---|
//! | `gpuRender.tileFormat` | int | [`TILE_FORMAT_VERSION`] |
//! | `gpuRender.imageSize` | v2i | the whole image's width and height |
//! | `gpuRender.tileIndex`, `gpuRender.tileCount` | int | `--tile I/N`; absent for `--crop` |
//! | `gpuRender.frame` | int | `--frame K`; absent for a still |
//! | `gpuRender.sceneHash` | string | [`Fingerprint::scene`], 16 hex digits |
//! | `gpuRender.settingsHash` | string | [`Fingerprint::settings`], 16 hex digits |
//! | `gpuRender.settings` | string | the settings in words ([`super::describe_settings`]) |
//! | `gpuRender.backend` | string | `cpu`, `gpu`, or `gpu-ray-query` (triangles found by ray queries) |
//! | `gpuRender.device` | string | `CPU reference` or the GPU adapter's name |
//! | `gpuRender.scene` | string | the scene file's name, for people |
//! | `gpuRender.version` | string | the gpu-render version that wrote it, for people |

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, ImageAttributes,
    IntegerBounds, Layer, LayerAttributes, MetaData, ReadChannels, ReadLayers, SmallVec, Text,
    Vec2,
};

use super::{Fingerprint, PixelWindow, TileError};
use crate::film::LinearImage;
use crate::output::{self, OutputError};
use crate::scene::MAX_IMAGE_DIMENSION;

/// The version of the tile format, recorded in every tile; [`read_tile`] refuses
/// others.
pub const TILE_FORMAT_VERSION: i32 = 1;

const FORMAT: &str = "gpuRender.tileFormat";
const IMAGE_SIZE: &str = "gpuRender.imageSize";
const TILE_INDEX: &str = "gpuRender.tileIndex";
const TILE_COUNT: &str = "gpuRender.tileCount";
const FRAME: &str = "gpuRender.frame";
const SCENE_HASH: &str = "gpuRender.sceneHash";
const SETTINGS_HASH: &str = "gpuRender.settingsHash";
const SETTINGS: &str = "gpuRender.settings";
const BACKEND: &str = "gpuRender.backend";
const DEVICE: &str = "gpuRender.device";
const SCENE: &str = "gpuRender.scene";
const VERSION: &str = "gpuRender.version";

/// The linear channels, in the file's (sorted) order, and their index in a pixel.
const LINEAR_CHANNELS: [(&str, usize); 4] = [("A", 3), ("B", 2), ("G", 1), ("R", 0)];
/// The display channels, likewise.
const DISPLAY_CHANNELS: [(&str, usize); 4] = [
    ("display.A", 3),
    ("display.B", 2),
    ("display.G", 1),
    ("display.R", 0),
];

/// What a tile records besides its pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TileInfo {
    /// The whole image's width.
    pub image_width: u32,
    /// The whole image's height.
    pub image_height: u32,
    /// The pixels this tile holds.
    pub window: PixelWindow,
    /// `(index, count)` of `--tile`; `None` for a `--crop`.
    pub tile: Option<(u32, u32)>,
    /// The animation frame, if one was rendered.
    pub frame: Option<u32>,
    /// The hashes of the scene and of the settings.
    pub fingerprint: Fingerprint,
    /// The settings in words.
    pub settings: String,
    /// `cpu` or `gpu`.
    pub backend: String,
    /// The device: `CPU reference` or the adapter's name.
    pub device: String,
    /// The scene file's name.
    pub scene_name: String,
    /// The gpu-render version that wrote it.
    pub version: String,
}

/// A tile: what it records and its pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    /// Where it belongs and what render it is of.
    pub info: TileInfo,
    /// The linear image of the window (`window.width() × window.height()`).
    pub image: LinearImage,
    /// The 8-bit RGBA display image of the window, row-major.
    pub display_rgba8: Vec<u8>,
}

/// Writes `tile` to `path` (see the module's documentation for the format),
/// atomically.
///
/// Errors: [`OutputError::BadImage`] when the images do not have the window's size or
/// the window does not lie inside the image; the write's errors.
pub fn write_tile(path: &Path, tile: &Tile) -> Result<(), OutputError> {
    let info = &tile.info;
    let window = &info.window;
    let pixels = window.pixels() as usize;
    let bad = |message: String| OutputError::BadImage {
        path: path.to_path_buf(),
        message,
    };
    if !window.fits(info.image_width, info.image_height) {
        return Err(bad(format!(
            "the window {window} does not lie inside the {}x{} image",
            info.image_width, info.image_height
        )));
    }
    if (tile.image.width, tile.image.height) != (window.width(), window.height())
        || tile.image.pixels.len() != pixels
        || tile.display_rgba8.len() != pixels * 4
    {
        return Err(bad(format!(
            "the images do not hold the window {window}: the linear image is {}x{} with {} \
             pixels, the display image {} bytes",
            tile.image.width,
            tile.image.height,
            tile.image.pixels.len(),
            tile.display_rgba8.len()
        )));
    }
    let linear = LINEAR_CHANNELS.map(|(name, c)| {
        let samples = tile.image.pixels.iter().map(|p| p[c]).collect();
        AnyChannel::new(name, FlatSamples::F32(samples))
    });
    let display = DISPLAY_CHANNELS.map(|(name, c)| {
        let samples = tile
            .display_rgba8
            .chunks_exact(4)
            .map(|p| u32::from(p[c]))
            .collect();
        AnyChannel::new(name, FlatSamples::U32(samples))
    });
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> =
        linear.into_iter().chain(display).collect();

    let mut attributes = LayerAttributes {
        layer_position: Vec2(window.columns.start as i32, window.rows.start as i32),
        ..LayerAttributes::default()
    };
    let mut put = |name: &str, value: AttributeValue| {
        attributes.other.insert(Text::from(name), value);
    };
    put(FORMAT, AttributeValue::I32(TILE_FORMAT_VERSION));
    put(
        IMAGE_SIZE,
        AttributeValue::IntVec2(Vec2(info.image_width as i32, info.image_height as i32)),
    );
    if let Some((index, count)) = info.tile {
        put(TILE_INDEX, AttributeValue::I32(index as i32));
        put(TILE_COUNT, AttributeValue::I32(count as i32));
    }
    if let Some(frame) = info.frame {
        put(FRAME, AttributeValue::I32(frame as i32));
    }
    for (name, value) in [
        (SCENE_HASH, hex(info.fingerprint.scene)),
        (SETTINGS_HASH, hex(info.fingerprint.settings)),
        (SETTINGS, info.settings.clone()),
        (BACKEND, info.backend.clone()),
        (DEVICE, info.device.clone()),
        (SCENE, info.scene_name.clone()),
        (VERSION, info.version.clone()),
    ] {
        put(name, AttributeValue::Text(text(&value)));
    }
    let layer = Layer::new(
        Vec2(window.width() as usize, window.height() as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let image = Image::new(
        ImageAttributes::new(IntegerBounds::from_dimensions(Vec2(
            info.image_width as usize,
            info.image_height as usize,
        ))),
        layer,
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    let encoded = {
        use exr::prelude::WritableImage;
        image.write().to_buffered(&mut bytes)
    };
    let mut bytes = bytes.into_inner();
    encoded
        .map_err(|e| e.to_string())
        .and_then(|()| sort_header_attributes(&mut bytes))
        .map_err(|message| OutputError::EncodeExr {
            path: path.to_path_buf(),
            message,
        })?;
    output::write_bytes(path, &bytes)
}

/// Puts the attributes of a single-part OpenEXR file's header in name order.
///
/// The `exr` crate writes custom attributes in the order of a `HashMap`, which
/// differs from process to process; sorted, the same tile is the same bytes whoever
/// renders it. The header keeps its length, so the offsets after it stay right.
fn sort_header_attributes(bytes: &mut [u8]) -> Result<(), String> {
    const HEADER_START: usize = 8; // the magic number and the version field
    let malformed = || "the encoder's header could not be read back".to_owned();
    let mut entries: Vec<(usize, usize)> = Vec::new();
    let mut at = HEADER_START;
    loop {
        let name_end = at
            + bytes
                .get(at..)
                .and_then(|b| b.iter().position(|&c| c == 0))
                .ok_or_else(malformed)?;
        if name_end == at {
            break; // the empty name that ends the header
        }
        let type_end = name_end
            + 1
            + bytes
                .get(name_end + 1..)
                .and_then(|b| b.iter().position(|&c| c == 0))
                .ok_or_else(malformed)?;
        let size_bytes: [u8; 4] = bytes
            .get(type_end + 1..type_end + 5)
            .and_then(|b| b.try_into().ok())
            .ok_or_else(malformed)?;
        let size = usize::try_from(i32::from_le_bytes(size_bytes)).map_err(|_| malformed())?;
        let end = type_end + 5 + size;
        if end > bytes.len() {
            return Err(malformed());
        }
        entries.push((at, end));
        at = end;
    }
    let mut sorted: Vec<&[u8]> = entries
        .iter()
        .map(|&(start, end)| &bytes[start..end])
        .collect();
    // By name: an attribute name is unique in a header.
    sorted.sort_unstable_by_key(|entry| entry.split(|&c| c == 0).next().unwrap_or(&[]));
    let header = sorted.concat();
    bytes[HEADER_START..HEADER_START + header.len()].copy_from_slice(&header);
    Ok(())
}

/// Reads what the tile at `path` records, without its pixels (only the header is
/// read): enough to check a set of tiles before reading any pixels.
///
/// Errors: [`TileError::Read`] for a file that cannot be read as OpenEXR,
/// [`TileError::NotATile`] for one without the attributes and channels of a tile.
pub fn read_tile_header(path: &Path) -> Result<TileInfo, TileError> {
    let meta =
        MetaData::read_from_buffered(open_tile(path)?, false).map_err(|e| read_error(path, e))?;
    let [header] = meta.headers.as_slice() else {
        return Err(not_a_tile(
            path,
            format!("it has {} parts; a tile has one", meta.headers.len()),
        ));
    };
    if header.deep {
        return Err(not_a_tile(path, "it holds deep data".into()));
    }
    let attributes: HashMap<&Text, &AttributeValue> = header
        .shared_attributes
        .other
        .iter()
        .chain(&header.own_attributes.other)
        .collect();
    let attributes = Attributes { path, attributes };
    let info = attributes.info(
        header.own_attributes.layer_position,
        header.layer_size,
        header.shared_attributes.display_window,
    )?;
    for (name, _) in LINEAR_CHANNELS.iter().chain(&DISPLAY_CHANNELS) {
        let name = Text::from(*name);
        if header.channels.find_index_of_channel(&name).is_none() {
            return Err(not_a_tile(path, format!("it has no channel `{name}`")));
        }
    }
    Ok(info)
}

/// Reads the tile at `path`: what it records and its pixels.
///
/// Errors: as [`read_tile_header`], and [`TileError::NotATile`] for channels of the
/// wrong type or display values above 255.
pub fn read_tile(path: &Path) -> Result<Tile, TileError> {
    let info = read_tile_header(path)?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(open_tile(path)?)
        .map_err(|e| read_error(path, e))?;
    let layer = image.layer_data;
    let pixels = info.window.pixels() as usize;
    let size = (layer.size.x(), layer.size.y());
    if size != (info.window.width() as usize, info.window.height() as usize) {
        return Err(not_a_tile(
            path,
            format!(
                "its pixels are {}x{}, not its window's size",
                size.0, size.1
            ),
        ));
    }
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|channel| channel.name == *name)
            .map(|channel| &channel.sample_data)
    };
    let mut linear = vec![[0.0f32; 4]; pixels];
    for (name, c) in LINEAR_CHANNELS {
        let Some(FlatSamples::F32(samples)) = channel(name) else {
            return Err(not_a_tile(
                path,
                format!("channel `{name}` is not 32-bit float"),
            ));
        };
        for (pixel, &value) in linear.iter_mut().zip(samples) {
            pixel[c] = value;
        }
    }
    let mut display_rgba8 = vec![0u8; pixels * 4];
    for (name, c) in DISPLAY_CHANNELS {
        let Some(FlatSamples::U32(samples)) = channel(name) else {
            return Err(not_a_tile(
                path,
                format!("channel `{name}` is not 32-bit unsigned integer"),
            ));
        };
        for (i, &value) in samples.iter().enumerate().take(pixels) {
            display_rgba8[i * 4 + c] = u8::try_from(value).map_err(|_| {
                not_a_tile(
                    path,
                    format!(
                        "channel `{name}` holds {value} at pixel ({}, {}); display values are \
                         0 to 255",
                        info.window.columns.start as usize + i % info.window.width() as usize,
                        info.window.rows.start as usize + i / info.window.width() as usize
                    ),
                )
            })?;
        }
    }
    Ok(Tile {
        image: LinearImage {
            width: info.window.width(),
            height: info.window.height(),
            pixels: linear,
        },
        display_rgba8,
        info,
    })
}

/// The attributes of one tile's header, read with messages naming the file.
struct Attributes<'a> {
    path: &'a Path,
    attributes: HashMap<&'a Text, &'a AttributeValue>,
}

impl Attributes<'_> {
    fn get(&self, name: &str) -> Option<&AttributeValue> {
        self.attributes.get(&Text::from(name)).copied()
    }

    fn missing(&self, name: &str, what: &str) -> TileError {
        not_a_tile(self.path, format!("attribute `{name}` ({what}) is missing"))
    }

    fn wrong(&self, name: &str, what: &str) -> TileError {
        not_a_tile(self.path, format!("attribute `{name}` is not {what}"))
    }

    fn int(&self, name: &str) -> Result<Option<u32>, TileError> {
        match self.get(name) {
            None => Ok(None),
            Some(AttributeValue::I32(value)) => u32::try_from(*value)
                .map(Some)
                .map_err(|_| self.wrong(name, "a whole number (it is negative)")),
            Some(_) => Err(self.wrong(name, "an int")),
        }
    }

    fn text(&self, name: &str) -> Result<String, TileError> {
        match self.get(name) {
            None => Err(self.missing(name, "a string")),
            Some(AttributeValue::Text(text)) => Ok(text.to_string()),
            Some(_) => Err(self.wrong(name, "a string")),
        }
    }

    fn hash(&self, name: &str) -> Result<u64, TileError> {
        let text = self.text(name)?;
        u64::from_str_radix(&text, 16)
            .ok()
            .filter(|_| text.len() == 16)
            .ok_or_else(|| self.wrong(name, "16 hexadecimal digits"))
    }

    /// The tile's record, with its data window (`position`, `size`) and display
    /// window checked against the image size it records.
    fn info(
        &self,
        position: Vec2<i32>,
        size: Vec2<usize>,
        display: IntegerBounds,
    ) -> Result<TileInfo, TileError> {
        match self.int(FORMAT)? {
            Some(TILE_FORMAT_VERSION_U32) => {}
            Some(other) => {
                return Err(not_a_tile(
                    self.path,
                    format!(
                        "it is of tile format {other}; this gpu-render reads format \
                         {TILE_FORMAT_VERSION}"
                    ),
                ));
            }
            None => return Err(self.missing(FORMAT, "the tile format version")),
        }
        let (image_width, image_height) = match self.get(IMAGE_SIZE) {
            Some(AttributeValue::IntVec2(Vec2(w, h))) => {
                let side = |v: i32| {
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| (1..=MAX_IMAGE_DIMENSION).contains(&v))
                };
                side(*w)
                    .zip(side(*h))
                    .ok_or_else(|| self.wrong(IMAGE_SIZE, "an image size the renderer accepts"))?
            }
            Some(_) => return Err(self.wrong(IMAGE_SIZE, "a v2i")),
            None => return Err(self.missing(IMAGE_SIZE, "the whole image's size")),
        };
        let whole =
            IntegerBounds::from_dimensions(Vec2(image_width as usize, image_height as usize));
        if display != whole {
            return Err(not_a_tile(
                self.path,
                format!(
                    "its display window, {}, is not the {image_width}x{image_height} image its \
                     `{IMAGE_SIZE}` records",
                    pixels_from(display.position, display.size)
                ),
            ));
        }
        let start = |v: i32| u32::try_from(v).ok();
        let window = start(position.x())
            .zip(start(position.y()))
            .and_then(|(x, y)| {
                let w = u32::try_from(size.x()).ok()?;
                let h = u32::try_from(size.y()).ok()?;
                Some(PixelWindow {
                    columns: x..x.checked_add(w)?,
                    rows: y..y.checked_add(h)?,
                })
            })
            .filter(|window| window.fits(image_width, image_height))
            .ok_or_else(|| {
                not_a_tile(
                    self.path,
                    format!(
                        "its data window, {}, does not lie inside the \
                         {image_width}x{image_height} image",
                        pixels_from(position, size)
                    ),
                )
            })?;
        let tile = match (self.int(TILE_INDEX)?, self.int(TILE_COUNT)?) {
            (Some(index), Some(count)) if index < count => Some((index, count)),
            (None, None) => None,
            _ => {
                return Err(not_a_tile(
                    self.path,
                    format!(
                        "attributes `{TILE_INDEX}` and `{TILE_COUNT}` must both be given, with \
                         the index below the count"
                    ),
                ));
            }
        };
        Ok(TileInfo {
            image_width,
            image_height,
            window,
            tile,
            frame: self.int(FRAME)?,
            fingerprint: Fingerprint {
                scene: self.hash(SCENE_HASH)?,
                settings: self.hash(SETTINGS_HASH)?,
            },
            settings: self.text(SETTINGS)?,
            backend: self.text(BACKEND)?,
            device: self.text(DEVICE)?,
            scene_name: self.text(SCENE).unwrap_or_default(),
            version: self.text(VERSION).unwrap_or_default(),
        })
    }
}

const TILE_FORMAT_VERSION_U32: u32 = TILE_FORMAT_VERSION as u32;

/// A window of a header as people read it: `64x65 pixels from pixel (0, 36)`.
fn pixels_from(position: Vec2<i32>, size: Vec2<usize>) -> String {
    format!(
        "{}x{} pixels from pixel ({}, {})",
        size.x(),
        size.y(),
        position.x(),
        position.y()
    )
}

/// A hash as the 16 hexadecimal digits a tile records.
pub(crate) fn hex(hash: u64) -> String {
    format!("{hash:016x}")
}

/// `value` as an OpenEXR string, which holds bytes of 0 to 255: other characters
/// become `?`.
fn text(value: &str) -> Text {
    let latin1: String = value
        .chars()
        .map(|c| if u32::from(c) < 256 { c } else { '?' })
        .collect();
    Text::new_or_none(&latin1).unwrap_or_else(|| Text::from("?"))
}

/// The tile file at `path`, opened as an input ([`crate::input::open_input`]: a FIFO or
/// a device is refused at once, never read from), buffered.
fn open_tile(path: &Path) -> Result<std::io::BufReader<std::fs::File>, TileError> {
    crate::input::open_input(path)
        .map(std::io::BufReader::new)
        .map_err(|e| TileError::Read {
            path: PathBuf::from(path),
            message: e.to_string(),
        })
}

fn read_error(path: &Path, error: exr::error::Error) -> TileError {
    TileError::Read {
        path: PathBuf::from(path),
        message: match error {
            exr::error::Error::Io(e) => e.to_string(),
            other => other.to_string(),
        },
    }
}

fn not_a_tile(path: &Path, message: String) -> TileError {
    TileError::NotATile {
        path: path.to_path_buf(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile(window: PixelWindow) -> Tile {
        let pixels = window.pixels() as usize;
        let image = LinearImage {
            width: window.width(),
            height: window.height(),
            pixels: (0..pixels)
                .map(|i| [i as f32 * 0.25, -1.5, f32::MAX, 1.0])
                .collect(),
        };
        let display_rgba8 = (0..pixels * 4).map(|i| (i * 7 % 256) as u8).collect();
        Tile {
            info: TileInfo {
                image_width: 9,
                image_height: 7,
                window,
                tile: Some((1, 3)),
                frame: Some(12),
                fingerprint: Fingerprint {
                    scene: 0x0123_4567_89ab_cdef,
                    settings: u64::MAX,
                },
                settings: "9x7, 1 spp".into(),
                backend: "cpu".into(),
                device: "CPU reference".into(),
                scene_name: "scène.toml".into(),
                version: "0.1.0".into(),
            },
            image,
            display_rgba8,
        }
    }

    #[test]
    fn a_tile_reads_back_exactly() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.exr");
        let written = tile(PixelWindow {
            columns: 2..7,
            rows: 3..5,
        });
        write_tile(&path, &written).expect("write");
        let read = read_tile(&path).expect("read");
        assert_eq!(read.image, written.image);
        assert_eq!(read.display_rgba8, written.display_rgba8);
        // Latin-1 survives; the rest is as written.
        assert_eq!(read.info, written.info);
        assert_eq!(read_tile_header(&path).expect("header"), written.info);
    }

    #[test]
    fn the_same_tile_is_the_same_bytes() {
        let dir = tempfile::tempdir().expect("tempdir");
        let window = PixelWindow {
            columns: 0..9,
            rows: 1..4,
        };
        let mut files = Vec::new();
        for name in ["a.exr", "b.exr", "c.exr"] {
            let path = dir.path().join(name);
            write_tile(&path, &tile(window.clone())).expect("write");
            files.push(std::fs::read(&path).expect("read"));
        }
        assert!(files.windows(2).all(|pair| pair[0] == pair[1]));
    }

    #[test]
    fn a_plain_exr_is_not_a_tile() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("plain.exr");
        let image = LinearImage::new(3, 2);
        output::write_image(&path, &image, &[]).expect("write");
        let err = read_tile(&path).expect_err("no attributes");
        let message = err.to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(message.contains("not a gpu-render tile"), "{message}");
        assert!(message.contains(FORMAT), "{message}");
        let junk = dir.path().join("junk.exr");
        std::fs::write(&junk, b"not an exr").expect("write");
        let err = read_tile(&junk).expect_err("junk");
        assert!(matches!(err, TileError::Read { .. }), "{err}");
        let missing = read_tile(&dir.path().join("none.exr")).expect_err("missing");
        assert!(missing.to_string().contains("none.exr"), "{missing}");
    }

    #[test]
    fn a_window_outside_the_image_is_not_written() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.exr");
        let mut outside = tile(PixelWindow {
            columns: 5..10,
            rows: 0..1,
        });
        outside.info.image_width = 9;
        let err = write_tile(&path, &outside).expect_err("outside");
        assert!(err.to_string().contains("does not lie inside"), "{err}");
        assert!(!path.exists());
    }

    /// The record of the tile `tile(window)` writes, as its header's attributes.
    fn attributes(info: &TileInfo) -> Vec<(Text, AttributeValue)> {
        let mut attributes = vec![
            (Text::from(FORMAT), AttributeValue::I32(TILE_FORMAT_VERSION)),
            (
                Text::from(IMAGE_SIZE),
                AttributeValue::IntVec2(Vec2(info.image_width as i32, info.image_height as i32)),
            ),
        ];
        for (name, value) in [
            (SCENE_HASH, hex(info.fingerprint.scene)),
            (SETTINGS_HASH, hex(info.fingerprint.settings)),
            (SETTINGS, info.settings.clone()),
            (BACKEND, info.backend.clone()),
            (DEVICE, info.device.clone()),
        ] {
            attributes.push((Text::from(name), AttributeValue::Text(text(&value))));
        }
        attributes
    }

    #[test]
    fn windows_outside_the_image_are_named_in_pixels() {
        let info = tile(PixelWindow {
            columns: 0..9,
            rows: 0..7,
        })
        .info;
        let owned = attributes(&info);
        let path = Path::new("t.exr");
        let header = Attributes {
            path,
            attributes: owned.iter().map(|(name, value)| (name, value)).collect(),
        };
        let whole = IntegerBounds::from_dimensions(Vec2(9, 7));
        let err = header
            .info(Vec2(0, 3), Vec2(9, 5), whole)
            .expect_err("rows 3..8 of 7");
        assert_eq!(
            err.to_string(),
            "t.exr: not a gpu-render tile: its data window, 9x5 pixels from pixel (0, 3), does \
             not lie inside the 9x7 image"
        );
        let other = IntegerBounds::new(Vec2(0, 1), Vec2(9, 7));
        let err = header
            .info(Vec2(0, 0), Vec2(9, 7), other)
            .expect_err("another display window");
        assert!(
            err.to_string()
                .contains("its display window, 9x7 pixels from pixel (0, 1), is not the 9x7 image"),
            "{err}"
        );
    }
}
