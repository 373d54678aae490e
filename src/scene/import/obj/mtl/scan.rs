//! The check of every line of an MTL library before `tobj` parses it ([`scan_mtl`]):
//! numbers that must be finite, counts of values, `illum` models and texture statements
//! with a file name, each error naming the library, line and column; the text handed to
//! `tobj` (colours with one number spelled out as three, unsupported forms blanked);
//! and where each material and its texture statements are ([`MtlLines`]), which `tobj`
//! does not keep.

use std::path::Path;

use crate::echo::echo;
use crate::scene::SceneError;
use crate::scene::import::obj::notes::Notes;
use crate::scene::import::obj::syntax::{at, finite, is_integer, strip_comment, words};

/// Colour keywords of MTL (1 or 3 numbers).
const MTL_COLOURS: &[&str] = &["Ka", "Kd", "Ks", "Ke", "Tf"];
/// Scalar keywords of MTL and of its PBR extension.
const MTL_SCALARS: &[&str] = &[
    "Ns",
    "Ni",
    "d",
    "Tr",
    "Pr",
    "Pm",
    "Ps",
    "Pc",
    "Pcr",
    "aniso",
    "anisor",
    "sharpness",
];

/// Where a material of an MTL library is defined: the line of its `newmtl`, and the line
/// Texture statements whose place [`MtlLines`] keeps (the others are not loaded).
const PLACED_MAPS: &[&str] = &[
    "map_Kd", "map_Ke", "map_d", "norm", "bump", "map_Bump", "map_bump", "map_Pr", "map_Pm",
];

/// Where a material of an MTL library is defined: the line of its `newmtl`, and the line
/// and column of each texture statement it loads, when it has them.
pub(super) struct MtlLines {
    /// The line of its `newmtl`.
    pub(super) line: usize,
    /// `map_Kd` line and column.
    pub(super) map_kd_at: Option<(usize, usize)>,
    /// `map_Ke` line and column.
    pub(super) map_ke_at: Option<(usize, usize)>,
    /// `map_d` line and column.
    pub(super) map_d_at: Option<(usize, usize)>,
    /// `norm` line and column.
    pub(super) norm_at: Option<(usize, usize)>,
    /// `bump` (or `map_Bump`, `map_bump`) line and column.
    pub(super) bump_at: Option<(usize, usize)>,
    /// `map_Pr` line and column.
    pub(super) map_pr_at: Option<(usize, usize)>,
    /// `map_Pm` line and column.
    pub(super) map_pm_at: Option<(usize, usize)>,
}

impl MtlLines {
    /// A material whose `newmtl` is on `line`, with no texture statement yet.
    fn new(line: usize) -> Self {
        Self {
            line,
            map_kd_at: None,
            map_ke_at: None,
            map_d_at: None,
            norm_at: None,
            bump_at: None,
            map_pr_at: None,
            map_pm_at: None,
        }
    }

    /// Keeps the place (`at`: line and column) of the texture statement `keyword`, one
    /// of [`PLACED_MAPS`].
    fn place(&mut self, keyword: &str, at: (usize, usize)) {
        let slot = match keyword {
            "map_Kd" => &mut self.map_kd_at,
            "map_Ke" => &mut self.map_ke_at,
            "map_d" => &mut self.map_d_at,
            "norm" => &mut self.norm_at,
            "map_Pr" => &mut self.map_pr_at,
            "map_Pm" => &mut self.map_pm_at,
            _ => &mut self.bump_at,
        };
        *slot = Some(at);
    }
}

/// Checks every line of an MTL library and returns the text for `tobj` (colours with one
/// number spelled out as three, unsupported forms blanked) and, per material in order,
/// where it is defined.
pub(super) fn scan_mtl(
    text: &str,
    path: &Path,
    notes: &mut Notes,
) -> Result<(String, Vec<MtlLines>), SceneError> {
    let mut clean = String::with_capacity(text.len());
    let mut lines = Vec::new();
    let mut nameless = false;
    for (index, line) in text.lines().enumerate() {
        let n = index + 1;
        let line = strip_comment(line);
        let words = words(line);
        let Some(&(column, keyword)) = words.first() else {
            clean.push('\n');
            continue;
        };
        let values = &words[1..];
        let mut kept = line.trim().to_string();
        if keyword == "newmtl" {
            // A material no `usemtl` can name (tobj refuses it): skipped to the next.
            nameless = values.is_empty();
            if nameless {
                notes.nameless_materials.note(|| n);
            }
        }
        if nameless {
            clean.push('\n');
            continue;
        }
        if keyword == "newmtl" {
            lines.push(MtlLines::new(n));
        } else if MTL_COLOURS.contains(&keyword) {
            kept = colour(path, n, column, keyword, values, notes)?;
        } else if MTL_SCALARS.contains(&keyword) {
            kept = scalar(path, n, column, keyword, values, notes)?;
        } else if keyword == "illum" {
            check_illum(path, n, column, values)?;
        } else if keyword.starts_with("map_")
            || matches!(keyword, "bump" | "disp" | "decal" | "refl" | "norm")
        {
            if values.is_empty() {
                return Err(at(
                    path,
                    n,
                    column,
                    format!("`{}` needs a file name", echo(keyword)),
                ));
            }
            if PLACED_MAPS.contains(&keyword) {
                match lines.last_mut() {
                    Some(last) => last.place(keyword, (n, column)),
                    None => kept.clear(),
                }
            }
        }
        if lines.is_empty() {
            // Before the first `newmtl`: belongs to no material.
            kept.clear();
        }
        clean.push_str(&kept);
        clean.push('\n');
    }
    Ok((clean, lines))
}

/// Checks the colour statement `keyword` on line `n` (`values`: its words) and returns
/// the line for `tobj`: r g b (one grey value spelled out as three), or nothing for a
/// spectral or CIE XYZ colour, which is not supported.
fn colour(
    path: &Path,
    n: usize,
    column: usize,
    keyword: &str,
    values: &[(usize, &str)],
    notes: &mut Notes,
) -> Result<String, SceneError> {
    if values
        .first()
        .is_some_and(|w| w.1 == "spectral" || w.1 == "xyz")
    {
        // Spectral and CIE XYZ colours are not supported: dropped.
        return Ok(String::new());
    }
    if values.len() != 1 && values.len() != 3 {
        return Err(at(
            path,
            n,
            column,
            format!(
                "`{keyword}` takes r g b (or one grey value), got {} numbers",
                values.len()
            ),
        ));
    }
    let mut rgb = [0.0; 3];
    for (c, word) in values.iter().enumerate() {
        rgb[c] = finite(path, n, *word, keyword, notes)?;
    }
    if values.len() == 1 {
        rgb = [rgb[0]; 3];
    }
    Ok(format!("{keyword} {:?} {:?} {:?}", rgb[0], rgb[1], rgb[2]))
}

/// Checks the scalar statement `keyword` on line `n` (`values`: its words) and returns
/// the line for `tobj`, its number written out.
fn scalar(
    path: &Path,
    n: usize,
    column: usize,
    keyword: &str,
    values: &[(usize, &str)],
    notes: &mut Notes,
) -> Result<String, SceneError> {
    // `d -halo 0.5`: the halo form is read as a plain dissolve.
    let values: Vec<_> = values.iter().filter(|w| w.1 != "-halo").collect();
    if values.len() != 1 {
        return Err(at(
            path,
            n,
            column,
            format!("`{keyword}` takes one number, got {}", values.len()),
        ));
    }
    let value = finite(path, n, *values[0], keyword, notes)?;
    Ok(format!("{keyword} {value:?}"))
}

/// Checks that the `illum` statement on line `n` (`values`: its words) names an
/// illumination model (0 to 10).
fn check_illum(
    path: &Path,
    n: usize,
    column: usize,
    values: &[(usize, &str)],
) -> Result<(), SceneError> {
    let [word] = values else {
        return Err(at(path, n, column, "`illum` takes one number (0 to 10)"));
    };
    let illum: Option<i64> = match word.1.parse() {
        Ok(illum) => Some(illum),
        // An integer of more digits than an i64 holds: no model either.
        Err(_) if is_integer(word.1) => None,
        Err(_) => {
            return Err(at(
                path,
                n,
                word.0,
                format!("illum: `{}` is not an integer", echo(word.1)),
            ));
        }
    };
    if !illum.is_some_and(|illum| (0..=10).contains(&illum)) {
        return Err(at(
            path,
            n,
            word.0,
            format!(
                "illum {} is not an illumination model (0 to 10)",
                echo(word.1)
            ),
        ));
    }
    Ok(())
}
