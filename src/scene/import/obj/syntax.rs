//! The syntax of OBJ and MTL lines, read as tinyobjloader and assimp read it: the
//! file's text decoded ([`decode_text`]), comments cut off, words with their columns,
//! numbers (a number followed by junk read by its start, with a note), and OBJ's face
//! corners (`v/vt/vn` index triples). Errors name the file, line and column ([`at`]).

use std::borrow::Cow;
use std::path::Path;

use super::notes::Notes;
use crate::echo::echo;
use crate::scene::SceneError;

/// A corner's missing texture coordinate or normal index.
pub(super) const NONE: u32 = u32::MAX;

/// The text of an OBJ or MTL file: UTF-16 when it starts with a UTF-16 byte-order
/// mark (as assimp reads it), otherwise UTF-8 without its byte-order mark (which would
/// hide the first line's keyword), invalid bytes replaced with a warning.
pub(super) fn decode_text<'a>(
    bytes: &'a [u8],
    path: &Path,
    warnings: &mut Vec<String>,
) -> Cow<'a, str> {
    let utf16 = |rest: &[u8], unit: fn([u8; 2]) -> u16| {
        let units = rest.chunks_exact(2).map(|pair| unit([pair[0], pair[1]]));
        let text: String = char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect();
        Cow::Owned(text)
    };
    match bytes {
        [0xFE, 0xFF, rest @ ..] => return utf16(rest, u16::from_be_bytes),
        [0xFF, 0xFE, rest @ ..] => return utf16(rest, u16::from_le_bytes),
        _ => {}
    }
    let text = String::from_utf8_lossy(bytes);
    if matches!(text, Cow::Owned(_)) {
        warnings.push(format!(
            "{}: not valid UTF-8; the invalid bytes were replaced",
            path.display()
        ));
    }
    match text {
        Cow::Borrowed(text) => Cow::Borrowed(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Cow::Owned(text) => match text.strip_prefix('\u{feff}') {
            Some(rest) => Cow::Owned(rest.to_string()),
            None => Cow::Owned(text),
        },
    }
}

/// `line` without its comment: a `#` that starts a word starts a comment running to the
/// end of the line (inline comments are common, though the specification only has
/// whole-line ones); a `#` inside a word (`mat#1`) is part of it.
pub(super) fn strip_comment(line: &str) -> &str {
    let mut after_space = true;
    for (offset, c) in line.char_indices() {
        if c == '#' && after_space {
            return &line[..offset];
        }
        after_space = c.is_whitespace();
    }
    line
}

/// Reads face corner number `k` (`v`, `v/vt`, `v//vn` or `v/vt/vn`, each index from 1,
/// or negative counting back from the last defined) as 0-based indices, against the
/// counts of positions, texture coordinates and normals defined before the line.
/// Normal indices in a file with no `vn` before the face are dropped (as tinyobjloader
/// does), setting `dropped_normals`.
pub(super) fn corner(
    path: &Path,
    line: usize,
    k: usize,
    (column, word): (usize, &str),
    defined: [usize; 3],
    dropped_normals: &mut bool,
) -> Result<[u32; 3], SceneError> {
    if word.split('/').count() > 3 {
        return Err(at(
            path,
            line,
            column,
            format!(
                "face corner {k} `{}` has more than three indices (v/vt/vn)",
                echo(word)
            ),
        ));
    }
    let kinds = ["position", "texture coordinate", "normal"];
    let mut corner = [NONE; 3];
    for (slot, part) in word.split('/').enumerate() {
        if part.is_empty() {
            if slot == 0 {
                return Err(at(
                    path,
                    line,
                    column,
                    format!("face corner {k} `{}` has no position index", echo(word)),
                ));
            }
            continue;
        }
        let kind = kinds[slot];
        let fail = |message: String| at(path, line, column, format!("face corner {k}: {message}"));
        // `None`: an integer beyond any index (more digits than an i64 holds).
        let index: Option<i64> = match part.parse() {
            Ok(index) => Some(index),
            Err(_) if is_integer(part) => None,
            Err(_) => {
                return Err(fail(format!(
                    "the {kind} index `{}` is not an integer",
                    echo(part)
                )));
            }
        };
        if index == Some(0) {
            return Err(fail(format!("the {kind} index is 0 (OBJ counts from 1)")));
        }
        let count = defined[slot];
        if slot == 2 && count == 0 {
            *dropped_normals = true;
            continue;
        }
        let resolved = index.and_then(|index| {
            if index > 0 {
                index.unsigned_abs().checked_sub(1)
            } else {
                (count as u64).checked_sub(index.unsigned_abs())
            }
        });
        match resolved {
            Some(resolved) if resolved < count as u64 => corner[slot] = resolved as u32,
            _ => {
                return Err(fail(format!(
                    "the {kind} index {} is out of range: {count} {kind}{} defined before this line",
                    echo(part),
                    if count == 1 { " is" } else { "s are" }
                )));
            }
        }
    }
    Ok(corner)
}

/// Whether `word` is an integer in decimal, of any size: an optional sign and digits.
pub(super) fn is_integer(word: &str) -> bool {
    let digits = word.strip_prefix(['+', '-']).unwrap_or(word);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// The words of a line with their 1-based columns (in characters).
pub(super) fn words(line: &str) -> Vec<(usize, &str)> {
    let mut words = Vec::new();
    let mut start = None;
    let mut column = 0;
    let mut start_column = 0;
    for (offset, c) in line.char_indices() {
        column += 1;
        match (c.is_whitespace(), start) {
            (false, None) => {
                start = Some(offset);
                start_column = column;
            }
            (true, Some(s)) => {
                words.push((start_column, &line[s..offset]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        words.push((start_column, &line[s..]));
    }
    words
}

/// An error at `line`:`column` of `path`.
pub(super) fn at(
    path: &Path,
    line: usize,
    column: usize,
    message: impl Into<String>,
) -> SceneError {
    SceneError::invalid(path, Some((line, column)), message)
}

/// Parses `word` as a number, failing with a message that names `what`. A word that
/// starts with a number and goes on with something else (`3.1+e2`) is read as that
/// number, as C's `strtod` (and so tinyobjloader and assimp) read it, with a note.
pub(super) fn number(
    path: &Path,
    line: usize,
    (column, word): (usize, &str),
    what: &str,
    notes: &mut Notes,
) -> Result<f64, SceneError> {
    if let Ok(value) = word.parse::<f64>() {
        return Ok(value);
    }
    match word[..number_prefix(word)].parse::<f64>() {
        Ok(value) => {
            notes
                .partial_numbers
                .note(|| (line, column, word.to_string(), value));
            Ok(value)
        }
        Err(_) => Err(at(
            path,
            line,
            column,
            format!("{what}: `{}` is not a number", echo(word)),
        )),
    }
}

/// The length of the longest start of `word` that is a decimal number: an optional
/// sign, digits with at most one point (at least one digit), and an exponent when it
/// has digits.
fn number_prefix(word: &str) -> usize {
    let bytes = word.as_bytes();
    let digits_from = |mut i: usize| {
        while bytes.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        i
    };
    let start = usize::from(matches!(bytes.first(), Some(b'+' | b'-')));
    let mut end = digits_from(start);
    let mut digits = end - start;
    if bytes.get(end) == Some(&b'.') {
        let fraction = digits_from(end + 1);
        digits += fraction - end - 1;
        end = fraction;
    }
    if digits == 0 {
        return 0;
    }
    if matches!(bytes.get(end), Some(b'e' | b'E')) {
        let sign = end + 1 + usize::from(matches!(bytes.get(end + 1), Some(b'+' | b'-')));
        let exponent = digits_from(sign);
        if exponent > sign {
            end = exponent;
        }
    }
    end
}

/// Parses `word` as a finite number.
pub(super) fn finite(
    path: &Path,
    line: usize,
    word: (usize, &str),
    what: &str,
    notes: &mut Notes,
) -> Result<f64, SceneError> {
    let value = number(path, line, word, what, notes)?;
    if !value.is_finite() {
        return Err(at(
            path,
            line,
            word.0,
            format!("{what} is not a finite number ({})", echo(word.1)),
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_know_their_columns() {
        assert_eq!(words("  v 1\t2"), vec![(3, "v"), (5, "1"), (7, "2")]);
    }

    #[test]
    fn comments_start_at_a_hash_that_starts_a_word() {
        assert_eq!(strip_comment("v 1 2 3 # corner"), "v 1 2 3 ");
        assert_eq!(strip_comment("# whole line"), "");
        assert_eq!(strip_comment("usemtl mat#1"), "usemtl mat#1");
        assert_eq!(strip_comment("v 1 2 3\t#tab"), "v 1 2 3\t");
    }

    #[test]
    fn numbers_followed_by_junk_are_read_by_their_start() {
        for (word, length) in [
            ("3.1+e2", 3),
            ("3.1-e2", 3),
            ("1e+2", 4),
            ("2.e", 2),
            ("-.5x", 3),
            ("+", 0),
            (".", 0),
            ("e5", 0),
            ("12abc", 2),
        ] {
            assert_eq!(number_prefix(word), length, "{word}");
        }
    }
}
