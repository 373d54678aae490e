//! An image in pieces: windows of it rendered apart (by separate processes or
//! machines, under any scheduler that hands out an index), written as linear OpenEXR
//! tiles that record where they belong, and merged back into the whole image.
//!
//! - [`split`]: the windows: [`PixelWindow`], and [`tile_window`], the split of an
//!   image into `count` bands of rows;
//! - [`fingerprint`]: the hashes of the scene and of the render settings that a tile
//!   records, so that tiles of different renders are never merged;
//! - [`file`](mod@file): the tile file ([`write_tile`], [`read_tile_header`], [`read_tile`]);
//! - [`merge`]: [`merge_tiles`], which checks that the tiles cover the image exactly
//!   once and agree on what they render.
//!
//! A pixel's samples depend only on the pixel and the sample index, and each pixel is
//! summed in a fixed order on both backends (`docs/model.md`), so a merged image is
//! bit-identical to a whole render of the same scene, settings and backend.
//! `docs/distributed.md` describes the command line and the schedulers' recipes.

mod error;
pub mod file;
pub mod fingerprint;
pub mod merge;
pub mod split;

pub use error::TileError;
pub use file::{TILE_FORMAT_VERSION, Tile, TileInfo, read_tile, read_tile_header, write_tile};
pub use fingerprint::{Fingerprint, describe_settings};
pub use merge::{Merged, merge_tiles};
pub use split::{PixelWindow, SplitError, tile_window};
