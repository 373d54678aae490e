//! Output names with placeholders: `{frame}` and `{tile}`, so that one command line
//! serves every index of a job array (`-o out/frame-{frame}.png`).
//!
//! `{frame}` becomes the frame number, zero-padded to at least 4 digits, or to the
//! digits of the animation's last frame when it has 10,000 frames or more, so that
//! the names sort in frame order. `{tile}` becomes the tile index, zero-padded to the
//! digits of the last index (`N - 1`). Other text, braces included, stays as it is.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// The frame placeholder.
pub const FRAME: &str = "{frame}";
/// The tile placeholder.
pub const TILE: &str = "{tile}";

/// Whether `pattern` contains `placeholder`.
pub fn contains(pattern: &Path, placeholder: &str) -> bool {
    pattern.to_string_lossy().contains(placeholder)
}

/// `pattern` with `{frame}` replaced by `frame` (`frame_count` frames in all) and
/// `{tile}` by `tile` (of `tile_count`). A placeholder without its value is an error
/// naming the flag it needs.
pub fn expand(
    pattern: &Path,
    frame: Option<(u32, u32)>,
    tile: Option<(u32, u32)>,
) -> Result<PathBuf> {
    if !contains(pattern, FRAME) && !contains(pattern, TILE) {
        return Ok(pattern.to_path_buf());
    }
    let Some(mut text) = pattern.to_str().map(str::to_owned) else {
        bail!(
            "{}: the output name is not valid UTF-8; {FRAME} and {TILE} need a UTF-8 name",
            pattern.display()
        );
    };
    for (placeholder, value, flag) in [
        (
            FRAME,
            frame.map(|(k, count)| pad(k, count.saturating_sub(1), 4)),
            "--frame K",
        ),
        (
            TILE,
            tile.map(|(i, count)| pad(i, count.saturating_sub(1), 1)),
            "--tile I/N",
        ),
    ] {
        if !contains(Path::new(&text), placeholder) {
            continue;
        }
        let Some(value) = value else {
            bail!(
                "{}: the output name has {placeholder}, which needs {flag}",
                pattern.display()
            );
        };
        text = text.replace(placeholder, &value);
    }
    Ok(PathBuf::from(text))
}

/// `value` zero-padded to the digits of `largest`, and at least `minimum`.
fn pad(value: u32, largest: u32, minimum: usize) -> String {
    let width = largest.to_string().len().max(minimum);
    format!("{value:0width$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_pad_to_four_digits_or_the_last_frame() {
        let name = |frame, count| {
            expand(Path::new("out/f-{frame}.png"), Some((frame, count)), None)
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        };
        assert_eq!(name(7, 48), "out/f-0007.png");
        assert_eq!(name(12_345, 100_000), "out/f-12345.png");
        assert_eq!(name(3, 100_000), "out/f-00003.png");
    }

    #[test]
    fn tiles_pad_to_the_last_index_and_both_may_appear() {
        let path = expand(
            Path::new("{frame}/t{tile}-{tile}.exr"),
            Some((2, 10)),
            Some((3, 12)),
        )
        .expect("expands");
        assert_eq!(path, PathBuf::from("0002/t03-03.exr"));
        let plain = expand(Path::new("a{b}.exr"), None, None).expect("no placeholder");
        assert_eq!(plain, PathBuf::from("a{b}.exr"));
    }

    #[test]
    fn a_placeholder_without_its_flag_is_refused() {
        let err = expand(Path::new("f-{frame}.png"), None, None).expect_err("no frame");
        assert!(err.to_string().contains("needs --frame K"), "{err}");
        let err = expand(Path::new("t{tile}.exr"), Some((1, 2)), None).expect_err("no tile");
        assert!(err.to_string().contains("needs --tile I/N"), "{err}");
    }
}
