//! Windows of an image, and the split of an image into tiles.
//!
//! Tile `index` of `count` (0-based) is a band of whole rows: rows
//! `floor(index · height / count)` to `floor((index + 1) · height / count)`, every
//! column. The bands cover every row once, in order, and differ in height by at most
//! one row, so they hold the same number of pixels within one row's worth. Their cost
//! is as similar as their content: a band of sky costs less than a band of glass
//! (`gpu-render estimate` shows the expected time of each band; more tiles than
//! workers evens the load out, as any scheduler hands the next tile to the first free
//! worker). The split depends on nothing but the four numbers, so every process of a
//! job array computes the same bands.

use std::fmt;
use std::ops::Range;

/// A rectangle of image pixels: `columns × rows`, each range half-open, in the pixel
/// coordinates of the whole image (column 0 on the left, row 0 at the top).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct PixelWindow {
    /// The columns, `x0..x1`.
    pub columns: Range<u32>,
    /// The rows, `y0..y1`.
    pub rows: Range<u32>,
}

impl PixelWindow {
    /// The whole image of `width × height`.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            columns: 0..width,
            rows: 0..height,
        }
    }

    /// Columns in the window (0 if the range is reversed).
    pub fn width(&self) -> u32 {
        self.columns.end.saturating_sub(self.columns.start)
    }

    /// Rows in the window (0 if the range is reversed).
    pub fn height(&self) -> u32 {
        self.rows.end.saturating_sub(self.rows.start)
    }

    /// Pixels in the window.
    pub fn pixels(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }

    /// Whether the window holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.pixels() == 0
    }

    /// Whether the window is not empty and lies inside an image of `width × height`.
    pub fn fits(&self, width: u32, height: u32) -> bool {
        !self.is_empty() && self.columns.end <= width && self.rows.end <= height
    }

    /// The pixels both windows hold, if any.
    pub fn intersection(&self, other: &PixelWindow) -> Option<PixelWindow> {
        let window = PixelWindow {
            columns: self.columns.start.max(other.columns.start)
                ..self.columns.end.min(other.columns.end),
            rows: self.rows.start.max(other.rows.start)..self.rows.end.min(other.rows.end),
        };
        (!window.is_empty()).then_some(window)
    }
}

impl fmt::Display for PixelWindow {
    /// `x 0..640, y 120..240 (640x120)`: the half-open ranges and the size.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "x {}..{}, y {}..{} ({}x{})",
            self.columns.start,
            self.columns.end,
            self.rows.start,
            self.rows.end,
            self.width(),
            self.height()
        )
    }
}

/// Why a tile cannot be cut from an image.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SplitError {
    /// The tile count is 0.
    #[error("the tile count must be at least 1")]
    NoTiles,
    /// The index is not below the count.
    #[error("tile index {index} is not below the tile count {count} (tiles are numbered 0 to {last})", last = .count - 1)]
    IndexOutOfRange {
        /// The index asked for.
        index: u32,
        /// The tile count.
        count: u32,
    },
    /// More tiles than rows: some bands would be empty.
    #[error("{count} tiles of whole rows need at least {count} rows, but the image has {height}")]
    MoreTilesThanRows {
        /// The tile count.
        count: u32,
        /// The image's height.
        height: u32,
    },
}

/// The window of tile `index` of `count` of a `width × height` image: the band of
/// rows `floor(index · height / count) .. floor((index + 1) · height / count)`, every
/// column (see the module's documentation).
///
/// ```
/// use gpu_render::tiles::tile_window;
/// let band = tile_window(1, 4, 640, 481).expect("a valid tile");
/// assert_eq!((band.columns, band.rows), (0..640, 120..240));
/// ```
pub fn tile_window(
    index: u32,
    count: u32,
    width: u32,
    height: u32,
) -> Result<PixelWindow, SplitError> {
    if count == 0 {
        return Err(SplitError::NoTiles);
    }
    if index >= count {
        return Err(SplitError::IndexOutOfRange { index, count });
    }
    if count > height {
        return Err(SplitError::MoreTilesThanRows { count, height });
    }
    let row = |i: u32| (u64::from(i) * u64::from(height) / u64::from(count)) as u32;
    Ok(PixelWindow {
        columns: 0..width,
        rows: row(index)..row(index + 1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once_and_differ_by_at_most_one_row() {
        for &(height, count) in &[(1, 1), (7, 7), (480, 4), (481, 4), (1000, 7), (3, 2)] {
            let mut next = 0;
            let mut heights = Vec::new();
            for index in 0..count {
                let band = tile_window(index, count, 5, height).expect("valid");
                assert_eq!(band.columns, 0..5);
                assert_eq!(band.rows.start, next, "{height} rows in {count}");
                next = band.rows.end;
                heights.push(band.height());
            }
            assert_eq!(next, height);
            let (low, high) = (heights.iter().min(), heights.iter().max());
            assert!(
                high.zip(low).is_some_and(|(h, l)| h - l <= 1),
                "{heights:?}"
            );
        }
    }

    #[test]
    fn the_largest_image_splits_without_overflow() {
        let last = tile_window(u32::MAX - 1, u32::MAX, 1, u32::MAX).expect("valid");
        assert_eq!(last.rows.end, u32::MAX);
    }

    #[test]
    fn bad_splits_say_why() {
        assert_eq!(tile_window(0, 0, 4, 4), Err(SplitError::NoTiles));
        let err = tile_window(4, 4, 4, 4).expect_err("index = count");
        assert!(err.to_string().contains("0 to 3"), "{err}");
        let err = tile_window(0, 5, 4, 4).expect_err("more tiles than rows");
        assert!(err.to_string().contains("the image has 4"), "{err}");
    }

    #[test]
    fn windows_intersect_and_fit() {
        let a = PixelWindow {
            columns: 0..10,
            rows: 0..10,
        };
        let b = PixelWindow {
            columns: 5..20,
            rows: 8..9,
        };
        assert_eq!(
            a.intersection(&b),
            Some(PixelWindow {
                columns: 5..10,
                rows: 8..9
            })
        );
        let c = PixelWindow {
            columns: 10..12,
            rows: 0..1,
        };
        assert_eq!(a.intersection(&c), None);
        assert!(a.fits(10, 10));
        assert!(!a.fits(9, 10));
        let empty = PixelWindow {
            columns: 3..3,
            rows: 0..1,
        };
        assert!(!empty.fits(10, 10));
        assert_eq!(b.to_string(), "x 5..20, y 8..9 (15x1)");
    }
}
