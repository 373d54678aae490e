//! The errors of reading and merging tiles: each names the file (or files), the
//! place (the attribute, the channel, the pixels) and the problem.

use std::fmt;
use std::path::PathBuf;

use super::PixelWindow;

/// A failure to read a tile or to merge tiles.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TileError {
    /// The file could not be opened or decoded as OpenEXR.
    #[error("{}: cannot read the tile: {message}", .path.display())]
    Read {
        /// The tile file.
        path: PathBuf,
        /// What went wrong (the OpenEXR decoder's or the operating system's words).
        message: String,
    },
    /// The file is an OpenEXR image, but not a tile gpu-render wrote, or a damaged
    /// one.
    #[error("{}: not a gpu-render tile: {message}", .path.display())]
    NotATile {
        /// The tile file.
        path: PathBuf,
        /// Which attribute or channel is missing or wrong.
        message: String,
    },
    /// `merge` was given no tiles.
    #[error("no tiles to merge")]
    NoTiles,
    /// A tile belongs to another render than the first tile.
    #[error(
        "{}: not the same {what} as {}: {this} here, {first} there; tiles of one image \
         must come from the same scene, frame, settings and backend",
        .path.display(),
        .first_path.display()
    )]
    Mismatch {
        /// The tile that differs.
        path: PathBuf,
        /// The first tile, which the others are compared with.
        first_path: PathBuf,
        /// What differs (`scene`, `image size`, `render settings`, ...).
        what: &'static str,
        /// Its value in `path`.
        this: String,
        /// Its value in `first_path`.
        first: String,
    },
    /// Two tiles hold some of the same pixels.
    #[error(
        "{} and {} overlap in the pixels {window}; every pixel must come from exactly one tile",
        .first.display(),
        .second.display()
    )]
    Overlap {
        /// One tile.
        first: PathBuf,
        /// The other tile.
        second: PathBuf,
        /// The pixels both hold.
        window: PixelWindow,
    },
    /// Some pixels are in no tile.
    #[error(
        "the tiles leave {missing} of the {width}x{height} pixels uncovered, within {window}{}",
        Tiles(.missing_tiles)
    )]
    Gap {
        /// How many pixels no tile holds.
        missing: u64,
        /// The smallest window holding all of them.
        window: PixelWindow,
        /// The image's width.
        width: u32,
        /// The image's height.
        height: u32,
        /// The tiles of the split (index, count) that no file given is, where the
        /// tiles given say they are of a split.
        missing_tiles: Vec<(u32, u32)>,
    },
}

/// "; missing: tile 2/4, tile 3/4" or nothing.
struct Tiles<'a>(&'a [(u32, u32)]);

impl fmt::Display for Tiles<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (index, count)) in self.0.iter().enumerate() {
            let lead = if i == 0 { "; missing: " } else { ", " };
            write!(f, "{lead}tile {index}/{count}")?;
        }
        Ok(())
    }
}
