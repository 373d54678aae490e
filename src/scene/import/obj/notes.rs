//! Problems that do not stop an OBJ or MTL import ([`Notes`]): each kind is counted
//! while the lines are read and reported once per file, at its first place and with
//! how often it occurs, however many lines have it.

use std::collections::HashSet;
use std::path::Path;

use crate::echo::{echo, short};

/// How many kinds of unsupported statement are named one by one in the warnings; the
/// rest are counted together.
const MAX_NAMED_STATEMENTS: usize = 16;

/// `""` for one, `"s"` for any other count.
pub(super) fn plural(count: usize) -> &'static str {
    if count == 1 { "" } else { "s" }
}

/// Problems that do not stop the import, each kind reported once per file, at its
/// first place and with how often it occurs, however many lines have it.
#[derive(Default)]
pub(super) struct Notes {
    /// Words read by their leading number: line, column, the word, the number.
    pub(super) partial_numbers: Counted<(usize, usize, String, f64)>,
    /// Faces of fewer than three corners (skipped).
    pub(super) short_faces: Counted<usize>,
    /// Faces that ear clipping could not cut (fanned instead).
    pub(super) fanned_faces: Counted<usize>,
    /// Faces whose normal indices were dropped: no `vn` before them.
    pub(super) normals_without_vn: Counted<usize>,
    /// `usemtl` statements without a name.
    pub(super) empty_usemtl: Counted<usize>,
    /// `mtllib` statements without a file name.
    pub(super) empty_mtllib: Counted<usize>,
    /// MTL `newmtl` statements without a name.
    pub(super) nameless_materials: Counted<usize>,
    /// Statements that are not read, by keyword: the first line, in order of first use
    /// (at most [`MAX_NAMED_STATEMENTS`]).
    ignored: Vec<(String, usize)>,
    /// The keywords in `ignored`.
    ignored_kinds: HashSet<String>,
    /// Lines with further kinds of unsupported statement, and the first of them.
    ignored_others: Counted<usize>,
}

/// The first occurrence of something and how many there are.
pub(super) struct Counted<T> {
    /// The first occurrence (its place), once there is one.
    first: Option<T>,
    /// How many there are.
    count: usize,
}

impl<T> Default for Counted<T> {
    /// None yet.
    fn default() -> Self {
        Self {
            first: None,
            count: 0,
        }
    }
}

impl<T> Counted<T> {
    /// Counts one more occurrence; `first` gives its place when it is the first.
    pub(super) fn note(&mut self, first: impl FnOnce() -> T) {
        if self.first.is_none() {
            self.first = Some(first());
        }
        self.count += 1;
    }
}

impl Notes {
    /// Notes a statement of `keyword` on `line` that is not read: by its keyword for
    /// the first [`MAX_NAMED_STATEMENTS`] kinds, counted together beyond them.
    pub(super) fn ignore(&mut self, keyword: &str, line: usize) {
        if self.ignored_kinds.contains(keyword) {
            return;
        }
        if self.ignored_kinds.len() < MAX_NAMED_STATEMENTS {
            self.ignored_kinds.insert(keyword.to_string());
            self.ignored.push((keyword.to_string(), line));
        } else {
            self.ignored_others.note(|| line);
        }
    }

    /// Adds one warning per kind of problem noted to `warnings`.
    pub(super) fn report(self, path: &Path, warnings: &mut Vec<String>) {
        let file = path.display();
        let times = |count: usize| match count {
            1 => String::new(),
            _ => format!(" ({count} times)"),
        };
        if let Some((line, column, word, value)) = self.partial_numbers.first {
            let more = match self.partial_numbers.count - 1 {
                0 => String::new(),
                more => format!(" ({more} more such number{})", plural(more)),
            };
            warnings.push(format!(
                "{file}:{line}:{column}: `{}` is read as {}, the number it starts with, as tinyobjloader and assimp read it{more}",
                echo(&word),
                short(value)
            ));
        }
        if let Some(line) = self.short_faces.first {
            let count = self.short_faces.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} of fewer than 3 vertices skipped",
                plural(count)
            ));
        }
        if let Some(line) = self.fanned_faces.first {
            let count = self.fanned_faces.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} could not be ear-clipped (the outline crosses itself in the face's plane); fanned from the first corner, so triangles may overlap",
                plural(count)
            ));
        }
        if let Some(line) = self.normals_without_vn.first {
            let count = self.normals_without_vn.count;
            warnings.push(format!(
                "{file}:{line}: {count} face{} give normal indices, but no `vn` is defined before them; the indices are ignored (flat shading)",
                plural(count)
            ));
        }
        if let Some(line) = self.empty_usemtl.first {
            warnings.push(format!(
                "{file}:{line}: `usemtl` without a material name{}; the default material is used",
                times(self.empty_usemtl.count)
            ));
        }
        if let Some(line) = self.empty_mtllib.first {
            warnings.push(format!(
                "{file}:{line}: `mtllib` without a file name{}; ignored",
                times(self.empty_mtllib.count)
            ));
        }
        if let Some(line) = self.nameless_materials.first {
            warnings.push(format!(
                "{file}:{line}: `newmtl` without a material name{}; the material is skipped",
                times(self.nameless_materials.count)
            ));
        }
        for (keyword, line) in &self.ignored {
            let what = match keyword.as_str() {
                "l" => "lines are not rendered",
                "p" => "points are not rendered",
                "cstype" | "curv" | "curv2" | "surf" | "deg" | "bmat" | "step" | "parm"
                | "trim" | "hole" | "scrv" | "sp" | "end" => {
                    "free-form curves and surfaces are not supported"
                }
                _ => "not supported",
            };
            warnings.push(format!(
                "{file}:{line}: `{}`: {what}; ignored (here and on any later line)",
                echo(keyword)
            ));
        }
        if let Some(line) = self.ignored_others.first {
            let count = self.ignored_others.count;
            warnings.push(format!(
                "{file}:{line}: {count} more line{} of other unknown statements ignored",
                plural(count)
            ));
        }
    }
}
