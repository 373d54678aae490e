//! Assembling tiles into the whole image.

use std::path::{Path, PathBuf};

use super::file::hex;
use super::{PixelWindow, Tile, TileError, TileInfo, read_tile, read_tile_header};
use crate::echo::echo;
use crate::film::LinearImage;

/// The whole image assembled from its tiles.
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// What the tiles record in common: the first tile's record, with the whole
    /// image as its window and no tile index.
    pub info: TileInfo,
    /// The linear image.
    pub image: LinearImage,
    /// The 8-bit RGBA display image.
    pub display_rgba8: Vec<u8>,
    /// The devices the tiles were rendered on, each once, in the order of the files.
    /// More than one GPU model may round differently in the last bits.
    pub devices: Vec<String>,
}

/// Reads the tiles at `paths` and assembles them into the whole image.
///
/// Every header is read and checked before any pixels: the tiles must record the same
/// image size, frame, backend, settings hash and scene hash as the first; no two may
/// hold the same pixel; together they must hold every pixel.
///
/// Errors: [`TileError::NoTiles`]; the errors of [`read_tile`];
/// [`TileError::Mismatch`] naming both files and what differs;
/// [`TileError::Overlap`] naming both files and the pixels; [`TileError::Gap`] with
/// the uncovered pixels (and the tiles of the split that are missing).
pub fn merge_tiles(paths: &[PathBuf]) -> Result<Merged, TileError> {
    let Some(first_path) = paths.first() else {
        return Err(TileError::NoTiles);
    };
    let headers = paths
        .iter()
        .map(|path| read_tile_header(path))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &headers[0];
    for (path, info) in paths.iter().zip(&headers).skip(1) {
        check_same_render(first_path, first, path, info)?;
    }
    check_no_overlap(paths, &headers)?;
    check_no_gap(&headers)?;

    let (width, height) = (first.image_width, first.image_height);
    let mut image = LinearImage::new(width, height);
    let mut display_rgba8 = vec![0u8; image.pixels.len() * 4];
    let mut devices: Vec<String> = Vec::new();
    for (path, header) in paths.iter().zip(&headers) {
        let tile = read_tile(path)?;
        if tile.info != *header {
            return Err(TileError::NotATile {
                path: path.clone(),
                message: "its header changed while it was being merged".into(),
            });
        }
        place(&tile, &mut image, &mut display_rgba8);
        if !devices.contains(&tile.info.device) {
            devices.push(tile.info.device);
        }
    }
    Ok(Merged {
        info: TileInfo {
            window: PixelWindow::whole(width, height),
            tile: None,
            ..first.clone()
        },
        image,
        display_rgba8,
        devices,
    })
}

/// Copies `tile`'s pixels into the whole image.
fn place(tile: &Tile, image: &mut LinearImage, display_rgba8: &mut [u8]) {
    let window = &tile.info.window;
    let (tile_width, width) = (window.width() as usize, image.width as usize);
    for (row, y) in window.rows.clone().enumerate() {
        let start = y as usize * width + window.columns.start as usize;
        image.pixels[start..start + tile_width]
            .copy_from_slice(&tile.image.pixels[row * tile_width..(row + 1) * tile_width]);
        display_rgba8[start * 4..(start + tile_width) * 4]
            .copy_from_slice(&tile.display_rgba8[row * tile_width * 4..(row + 1) * tile_width * 4]);
    }
}

/// Refuses a tile of another render than the first. The hashes are compared, not the
/// words beside them: the scene file's name is recorded for people, and tiles of the
/// same scene rendered from files of other names (or folders) belong together.
fn check_same_render(
    first_path: &Path,
    first: &TileInfo,
    path: &Path,
    info: &TileInfo,
) -> Result<(), TileError> {
    fn size(info: &TileInfo) -> String {
        format!("{}x{}", info.image_width, info.image_height)
    }
    fn frame(info: &TileInfo) -> String {
        info.frame
            .map_or("none (a still)".to_owned(), |f| f.to_string())
    }
    // The words a tile records are quoted as text from a file.
    fn backend(info: &TileInfo) -> String {
        echo(&info.backend).to_string()
    }
    fn settings(info: &TileInfo) -> String {
        format!(
            "{} (hash {})",
            echo(&info.settings),
            hex(info.fingerprint.settings)
        )
    }
    fn scene(info: &TileInfo) -> String {
        match info.scene_name.as_str() {
            "" => format!("hash {}", hex(info.fingerprint.scene)),
            name => format!("hash {} (of {})", hex(info.fingerprint.scene), echo(name)),
        }
    }
    // What differs, and how each tile shows it.
    type Check = (&'static str, bool, fn(&TileInfo) -> String);
    let checks: [Check; 5] = [
        (
            "image size",
            (info.image_width, info.image_height) != (first.image_width, first.image_height),
            size,
        ),
        ("frame", info.frame != first.frame, frame),
        ("backend", info.backend != first.backend, backend),
        (
            "render settings",
            info.fingerprint.settings != first.fingerprint.settings,
            settings,
        ),
        (
            "scene",
            info.fingerprint.scene != first.fingerprint.scene,
            scene,
        ),
    ];
    match checks.into_iter().find(|(_, differs, _)| *differs) {
        Some((what, _, show)) => Err(TileError::Mismatch {
            path: path.to_path_buf(),
            first_path: first_path.to_path_buf(),
            what,
            this: show(info),
            first: show(first),
        }),
        None => Ok(()),
    }
}

/// Refuses two tiles that hold a pixel in common.
fn check_no_overlap(paths: &[PathBuf], headers: &[TileInfo]) -> Result<(), TileError> {
    for (i, a) in headers.iter().enumerate() {
        for (j, b) in headers.iter().enumerate().skip(i + 1) {
            if let Some(window) = a.window.intersection(&b.window) {
                return Err(TileError::Overlap {
                    first: paths[i].clone(),
                    second: paths[j].clone(),
                    window,
                });
            }
        }
    }
    Ok(())
}

/// Refuses tiles (already known not to overlap) that leave pixels uncovered, naming
/// the smallest window around those pixels and, for tiles of a split, the missing
/// tiles.
fn check_no_gap(headers: &[TileInfo]) -> Result<(), TileError> {
    let (width, height) = (headers[0].image_width, headers[0].image_height);
    let covered: u64 = headers.iter().map(|h| h.window.pixels()).sum();
    let whole = u64::from(width) * u64::from(height);
    if covered == whole {
        return Ok(());
    }
    // Row by row: the spans of the tiles crossing the row, in column order.
    let mut bounds: Option<PixelWindow> = None;
    for y in 0..height {
        let mut spans: Vec<_> = headers
            .iter()
            .filter(|h| h.window.rows.contains(&y))
            .map(|h| h.window.columns.clone())
            .collect();
        spans.sort_by_key(|span| span.start);
        let mut x = 0;
        let mut note = |from: u32, to: u32| {
            let gap = PixelWindow {
                columns: from..to,
                rows: y..y + 1,
            };
            bounds = Some(match bounds.take() {
                None => gap,
                Some(b) => PixelWindow {
                    columns: b.columns.start.min(from)..b.columns.end.max(to),
                    rows: b.rows.start..y + 1,
                },
            });
        };
        for span in spans {
            if span.start > x {
                note(x, span.start);
            }
            x = x.max(span.end);
        }
        if x < width {
            note(x, width);
        }
    }
    let mut missing_tiles = Vec::new();
    let counts: Vec<u32> = headers
        .iter()
        .filter_map(|h| h.tile.map(|(_, count)| count))
        .collect();
    if let Some(&count) = counts.first()
        && counts.len() == headers.len()
        && counts.iter().all(|&c| c == count)
    {
        missing_tiles = (0..count)
            .filter(|&index| !headers.iter().any(|h| h.tile == Some((index, count))))
            .map(|index| (index, count))
            .collect();
    }
    Err(TileError::Gap {
        missing: whole - covered,
        window: bounds.unwrap_or_else(|| PixelWindow::whole(width, height)),
        width,
        height,
        missing_tiles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tiles::{Fingerprint, tile_window, write_tile};

    fn info(window: PixelWindow, tile: Option<(u32, u32)>) -> TileInfo {
        TileInfo {
            image_width: 6,
            image_height: 4,
            window,
            tile,
            frame: None,
            fingerprint: Fingerprint {
                scene: 1,
                settings: 2,
            },
            settings: "6x4, 1 spp".into(),
            backend: "cpu".into(),
            device: "CPU reference".into(),
            scene_name: "s.toml".into(),
            version: "0".into(),
        }
    }

    /// Writes tile `index` of `count` of a 6x4 image whose pixel (x, y) is x + 10 y.
    fn write(dir: &Path, name: &str, info: TileInfo) -> PathBuf {
        let window = info.window.clone();
        let mut pixels = Vec::new();
        let mut display = Vec::new();
        for y in window.rows.clone() {
            for x in window.columns.clone() {
                let v = (x + 10 * y) as f32;
                pixels.push([v, v, v, 1.0]);
                display.extend_from_slice(&[x as u8, y as u8, 7, 255]);
            }
        }
        let path = dir.join(name);
        let tile = Tile {
            image: LinearImage {
                width: window.width(),
                height: window.height(),
                pixels,
            },
            display_rgba8: display,
            info,
        };
        write_tile(&path, &tile).expect("write tile");
        path
    }

    fn band(index: u32, count: u32) -> TileInfo {
        info(
            tile_window(index, count, 6, 4).expect("valid"),
            Some((index, count)),
        )
    }

    #[test]
    fn tiles_in_any_order_assemble_the_image() {
        let dir = tempfile::tempdir().expect("tempdir");
        let paths: Vec<_> = [2, 0, 1]
            .iter()
            .map(|&i| write(dir.path(), &format!("t{i}.exr"), band(i, 3)))
            .collect();
        let merged = merge_tiles(&paths).expect("merge");
        for y in 0..4 {
            for x in 0..6 {
                assert_eq!(merged.image.pixel(x, y)[0], (x + 10 * y) as f32);
                let i = (y * 6 + x) as usize * 4;
                assert_eq!(&merged.display_rgba8[i..i + 4], &[x as u8, y as u8, 7, 255]);
            }
        }
        assert_eq!(merged.info.window, PixelWindow::whole(6, 4));
        assert_eq!(merged.devices, vec!["CPU reference".to_owned()]);
    }

    #[test]
    fn a_missing_tile_is_named_with_its_pixels() {
        let dir = tempfile::tempdir().expect("tempdir");
        let paths = vec![
            write(dir.path(), "a.exr", band(0, 4)),
            write(dir.path(), "c.exr", band(2, 4)),
            write(dir.path(), "d.exr", band(3, 4)),
        ];
        let err = merge_tiles(&paths).expect_err("gap");
        assert_eq!(
            err.to_string(),
            "the tiles leave 6 of the 6x4 pixels uncovered, within x 0..6, y 1..2 (6x1); \
             missing: tile 1/4"
        );
    }

    #[test]
    fn a_hole_inside_crops_is_bounded() {
        let dir = tempfile::tempdir().expect("tempdir");
        let crop = |columns, rows| info(PixelWindow { columns, rows }, None);
        let paths = vec![
            write(dir.path(), "top.exr", crop(0..6, 0..1)),
            write(dir.path(), "left.exr", crop(0..2, 1..4)),
            write(dir.path(), "right.exr", crop(4..6, 1..4)),
            write(dir.path(), "mid.exr", crop(2..4, 1..3)),
        ];
        let err = merge_tiles(&paths).expect_err("gap");
        assert!(
            err.to_string()
                .contains("2 of the 6x4 pixels uncovered, within x 2..4, y 3..4"),
            "{err}"
        );
    }

    #[test]
    fn overlapping_tiles_are_refused_with_both_names() {
        let dir = tempfile::tempdir().expect("tempdir");
        let paths = vec![
            write(dir.path(), "half.exr", band(0, 2)),
            write(dir.path(), "third.exr", band(1, 3)),
            write(dir.path(), "rest.exr", band(2, 3)),
        ];
        let err = merge_tiles(&paths).expect_err("overlap");
        let message = err.to_string();
        assert!(
            message.contains("half.exr and ") && message.contains("third.exr overlap"),
            "{message}"
        );
        assert!(message.contains("x 0..6, y 1..2"), "{message}");
    }

    #[test]
    fn a_tile_of_another_scene_or_setting_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let a = write(dir.path(), "a.exr", band(0, 2));
        let mut other = band(1, 2);
        other.fingerprint.scene = 99;
        other.scene_name = "other.toml".into();
        let b = write(dir.path(), "b.exr", other);
        let err = merge_tiles(&[a.clone(), b]).expect_err("mismatch");
        let message = err.to_string();
        assert!(
            message.contains("b.exr: not the same scene as "),
            "{message}"
        );
        assert!(message.contains("a.exr"), "{message}");
        assert!(
            message.contains(
                "hash 0000000000000063 (of other.toml) here, hash 0000000000000001 (of s.toml) \
                 there"
            ),
            "{message}"
        );

        let mut samples = band(1, 2);
        samples.fingerprint.settings = 3;
        samples.settings = "6x4, 2 spp".into();
        let c = write(dir.path(), "c.exr", samples);
        let err = merge_tiles(&[a.clone(), c]).expect_err("mismatch");
        assert!(
            err.to_string().contains("not the same render settings as"),
            "{err}"
        );
        assert!(err.to_string().contains("6x4, 2 spp (hash"), "{err}");

        let mut frame = band(1, 2);
        frame.frame = Some(3);
        let d = write(dir.path(), "d.exr", frame);
        let err = merge_tiles(&[a, d]).expect_err("mismatch");
        assert!(err.to_string().contains("not the same frame as"), "{err}");
        assert!(matches!(merge_tiles(&[]), Err(TileError::NoTiles)));
    }

    #[test]
    fn tiles_of_one_scene_from_files_of_other_names_merge() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut renamed = band(1, 2);
        renamed.scene_name = "copy of s.toml".into();
        let paths = vec![
            write(dir.path(), "a.exr", band(0, 2)),
            write(dir.path(), "b.exr", renamed),
        ];
        let merged = merge_tiles(&paths).expect("the same scene hash merges");
        assert_eq!(merged.info.scene_name, "s.toml");
    }

    #[test]
    fn the_words_a_tile_records_are_quoted_escaped() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut odd = band(1, 2);
        odd.fingerprint.scene = 7;
        odd.scene_name = "two\nlines\u{1b}[2J.toml".into();
        let paths = vec![
            write(dir.path(), "a.exr", band(0, 2)),
            write(dir.path(), "b.exr", odd),
        ];
        let message = merge_tiles(&paths).expect_err("mismatch").to_string();
        assert!(!message.contains(char::is_control), "{message:?}");
        assert!(
            message.contains(r"(of two\nlines\u{1b}[2J.toml) here"),
            "{message}"
        );
    }

    #[test]
    fn settings_words_do_not_count_but_their_hash_does() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut reworded = band(1, 2);
        reworded.settings = "6x4, 1 spp, as an older version put it".into();
        let paths = vec![
            write(dir.path(), "a.exr", band(0, 2)),
            write(dir.path(), "b.exr", reworded),
        ];
        merge_tiles(&paths).expect("the same settings hash merges");
    }
}
