//! Text and numbers read from files, as messages show them.
//!
//! A name, a keyword or a number that a message quotes back from a file (an OBJ
//! statement, an MTL material, a TOML key, a tile's attribute) may hold anything: NUL
//! bytes, newlines, a terminal's escape sequences, ten thousand characters, or a
//! number whose decimal expansion runs to 300 digits. [`echo`] shows such text on one
//! line, its control characters (and the invisible characters that reorder a line)
//! escaped as Rust writes them (`\0`, `\n`, `\u{1b}`), cut after [`MAX_ECHO_CHARS`]
//! characters with `…`; [`short`] shows a number in at most about 24 characters.
//! [`escape_controls`] escapes without cutting, for whole messages.
//!
//! ```
//! use gpu_render::low_level::echo::{echo, short};
//! assert_eq!(echo("a\0b\nc").to_string(), r"a\0b\nc");
//! assert_eq!(short(1e300).to_string(), "1e300");
//! assert_eq!(short(0.25).to_string(), "0.25");
//! ```

use std::borrow::Cow;
use std::fmt::{self, Write as _};
use std::path::Path;

/// The most characters [`echo`] shows (after escaping) before it cuts the text with
/// `…`.
pub const MAX_ECHO_CHARS: usize = 80;

/// The most characters [`echo_path`] shows: a path is longer than a name, and its
/// end (the file's name) matters.
pub const MAX_ECHO_PATH_CHARS: usize = 240;

/// `text` as a message quotes it: one line, control characters escaped, at most
/// [`MAX_ECHO_CHARS`] characters and then `…`.
pub fn echo(text: &str) -> Echo<'_> {
    Echo {
        text: Cow::Borrowed(text),
        limit: MAX_ECHO_CHARS,
    }
}

/// A path that a file names (a texture, a library), as a message quotes it: as
/// [`echo`], cut after [`MAX_ECHO_PATH_CHARS`].
pub fn echo_path(path: &Path) -> Echo<'_> {
    Echo {
        text: path.to_string_lossy(),
        limit: MAX_ECHO_PATH_CHARS,
    }
}

/// `text` with its control characters escaped (as [`echo`] does), whatever its length:
/// for a whole message that may quote a file.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(needs_escape) {
        return Cow::Borrowed(text);
    }
    Cow::Owned(
        Echo {
            text: Cow::Borrowed(text),
            limit: usize::MAX,
        }
        .to_string(),
    )
}

/// `value` in a short form (see [`Short`]).
pub fn short<T: Number>(value: T) -> Short<T> {
    Short(value)
}

/// A floating-point number that [`short`] shows: `f64`, or `f32` (a texel), each with
/// the shortest digits of its own precision.
pub trait Number: fmt::Display + fmt::LowerExp + Copy {
    /// The value, for its magnitude.
    fn to_f64(self) -> f64;
}

impl Number for f64 {
    fn to_f64(self) -> f64 {
        self
    }
}

impl Number for f32 {
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

/// Text shown by [`echo`] or [`echo_path`].
#[derive(Debug, Clone)]
pub struct Echo<'a> {
    text: Cow<'a, str>,
    /// The most characters written before `…`.
    limit: usize,
}

impl fmt::Display for Echo<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut written = 0;
        let mut piece = String::new();
        for c in self.text.chars() {
            piece.clear();
            escape(c, &mut piece);
            let width = piece.chars().count();
            if written + width > self.limit {
                return f.write_char('…');
            }
            f.write_str(&piece)?;
            written += width;
        }
        Ok(())
    }
}

/// Whether `c` is shown escaped: the control characters (C0, DEL, C1) and the
/// characters that change the order or the lines of the text around them without
/// showing (the bidirectional marks and overrides, the line and paragraph
/// separators), which could make a message read other than it is.
fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{2028}'..='\u{202e}' | '\u{2066}'..='\u{2069}'
        )
}

/// Appends `c`, escaped if [`needs_escape`] says so.
fn escape(c: char, out: &mut String) {
    if !needs_escape(c) {
        out.push(c);
        return;
    }
    match c {
        '\0' => out.push_str("\\0"),
        '\n' => out.push_str("\\n"),
        '\r' => out.push_str("\\r"),
        '\t' => out.push_str("\\t"),
        _ => {
            // Writing into a `String` cannot fail.
            let _ = write!(out, "\\u{{{:x}}}", u32::from(c));
        }
    }
}

/// A number as a message shows it: as Rust prints it (the shortest digits that read
/// back to the same value) between 1e-5 and 1e16 in magnitude, in scientific notation
/// (`1e300`, `2.5e-8`) outside that range, where the plain form would run to hundreds
/// of digits; `NaN`, `inf` and `-inf` as they are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Short<T = f64>(pub T);

impl<T: Number> fmt::Display for Short<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let magnitude = self.0.to_f64().abs();
        if magnitude == 0.0 || !magnitude.is_finite() || (1e-5..1e16).contains(&magnitude) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// Three numbers as a message shows a colour or a vector: `[0.5, 1e300, 0]`.
pub fn short3(value: impl Into<[f64; 3]>) -> Short3 {
    Short3(value.into())
}

/// Three numbers shown by [`short3`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Short3(pub [f64; 3]);

impl fmt::Display for Short3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0.map(Short);
        write!(f, "[{x}, {y}, {z}]")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(echo("plain name").to_string(), "plain name");
        assert_eq!(echo("a\0b").to_string(), r"a\0b");
        assert_eq!(echo("a\nb\r\tc").to_string(), r"a\nb\r\tc");
        assert_eq!(echo("\u{1b}[31mred").to_string(), r"\u{1b}[31mred");
        assert_eq!(echo("\u{7f}\u{85}").to_string(), r"\u{7f}\u{85}");
        assert_eq!(echo("abc\u{202e}cba").to_string(), r"abc\u{202e}cba");
        // Text that is not a control character stays as it is.
        assert_eq!(
            echo(r"C:\tex\wood.png é ü 木").to_string(),
            r"C:\tex\wood.png é ü 木"
        );
    }

    #[test]
    fn long_text_is_cut_after_the_limit() {
        let nuls = "\0".repeat(10_000);
        let shown = echo(&nuls).to_string();
        assert_eq!(shown.chars().count(), MAX_ECHO_CHARS + 1);
        assert!(
            shown.starts_with(r"\0\0") && shown.ends_with('…'),
            "{shown}"
        );
        let exact = "x".repeat(MAX_ECHO_CHARS);
        assert_eq!(echo(&exact).to_string(), exact);
        let over = "x".repeat(MAX_ECHO_CHARS + 1);
        assert_eq!(
            echo(&over).to_string(),
            format!("{}…", "x".repeat(MAX_ECHO_CHARS))
        );
        // An escape is never cut in the middle.
        let shown = echo(&format!("{}\u{1b}", "x".repeat(MAX_ECHO_CHARS - 3))).to_string();
        assert!(shown.ends_with("xxx…"), "{shown}");
    }

    #[test]
    fn paths_are_cut_later_than_names() {
        let long = format!("{}/wood\n.png", "d".repeat(100));
        let shown = echo_path(Path::new(&long)).to_string();
        assert_eq!(shown, format!("{}/wood\\n.png", "d".repeat(100)));
        let longer = "d".repeat(1000);
        let shown = echo_path(Path::new(&longer)).to_string();
        assert_eq!(shown.chars().count(), MAX_ECHO_PATH_CHARS + 1);
    }

    #[test]
    fn escaping_a_whole_message_keeps_its_length() {
        let long = format!("{}\0", "y".repeat(500));
        let escaped = escape_controls(&long);
        assert_eq!(escaped.len(), 502);
        assert!(escaped.ends_with(r"\0"));
        assert!(matches!(escape_controls("fine"), Cow::Borrowed("fine")));
    }

    #[test]
    fn numbers_are_short_at_any_magnitude() {
        for (value, shown) in [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (1e-300, "1e-300"),
            (3.4e38, "3.4e38"),
            (1.5, "1.5"),
            (0.0, "0"),
            (-2.0, "-2"),
            (0.1 + 0.2, "0.30000000000000004"),
            (123_456_789.0, "123456789"),
            (0.000_01, "0.00001"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ] {
            assert_eq!(short(value).to_string(), shown, "{value:e}");
        }
        for exponent in -320..=308 {
            let value = 1.234_567_890_123_456_7 * 10f64.powi(exponent);
            let shown = short(value).to_string();
            assert!(shown.len() <= 24, "{shown}");
            assert_eq!(shown.parse::<f64>().ok(), Some(value), "{shown}");
        }
        assert_eq!(short3([0.5, 1e300, 0.0]).to_string(), "[0.5, 1e300, 0]");
        assert_eq!(short(f32::MAX).to_string(), "3.4028235e38");
        assert_eq!(short(-0.5f32).to_string(), "-0.5");
    }
}

/// A count of bytes as a message shows it: in GiB, MiB or KiB with two decimals,
/// whichever is the largest unit of which there is at least one, else in bytes
/// (`50.00 MiB`, not `0.05 GiB`; `5.12 MiB`, not `0.00 GiB`).
///
/// ```
/// use gpu_render::low_level::echo::bytes;
/// assert_eq!(bytes(3 << 30).to_string(), "3.00 GiB");
/// assert_eq!(bytes(5 << 20).to_string(), "5.00 MiB");
/// assert_eq!(bytes(1536).to_string(), "1.50 KiB");
/// assert_eq!(bytes(12).to_string(), "12 bytes");
/// ```
pub fn bytes(count: u64) -> Bytes {
    Bytes(count)
}

/// A count of bytes, shown by [`bytes`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const UNITS: [(&str, u32); 3] = [("GiB", 30), ("MiB", 20), ("KiB", 10)];
        for (unit, shift) in UNITS {
            if self.0 >= 1 << shift {
                return write!(f, "{:.2} {unit}", self.0 as f64 / (1u64 << shift) as f64);
            }
        }
        write!(f, "{} bytes", self.0)
    }
}
