//! MTL material libraries (Alias|Wavefront Advanced Visualizer manual, appendix B2):
//! each line checked ([`scan`]: errors name the library, line and column), then parsed
//! by `tobj`, and each material mapped onto ours ([`material`]: the table in
//! `docs/models.md`) with its texture maps ([`maps`], [`texture_options`],
//! [`derived_textures`]).
//!
//! This module finds and reads the libraries an OBJ file names ([`Libraries`]).

mod derived_textures;
mod maps;
mod material;
mod scan;
mod texture_options;

use std::collections::{HashMap, HashSet};
use std::io::{Cursor, ErrorKind};
use std::path::{Path, PathBuf};

use self::scan::{MtlLines, scan_mtl};
use super::notes::Notes;
use super::syntax::{at, decode_text};
use crate::echo::{echo, echo_path};
use crate::input::{InputError, read_input};
use crate::scene::SceneError;
use crate::scene::import::{MAX_MODEL_FILE_BYTES, error};

pub(super) use self::material::map_material;

/// A material of an MTL library with what `tobj` does not keep: where it was defined.
pub(super) struct SourceMaterial {
    /// The material as `tobj` parsed it.
    material: tobj::Material,
    /// The library file.
    library: PathBuf,
    /// The line of its `newmtl`.
    line: usize,
    /// The line of the OBJ file's `mtllib` that named the library.
    pub(super) mtllib_line: usize,
    /// `map_Kd` line and column, when it has one.
    map_kd_at: Option<(usize, usize)>,
    /// `map_Ke` line and column, when it has one.
    map_ke_at: Option<(usize, usize)>,
    /// `map_d` line and column, when it has one.
    map_d_at: Option<(usize, usize)>,
    /// `norm` line and column, when it has one.
    norm_at: Option<(usize, usize)>,
    /// `bump` (or `map_Bump`, `map_bump`) line and column, when it has one.
    bump_at: Option<(usize, usize)>,
    /// `map_Pr` line and column, when it has one.
    map_pr_at: Option<(usize, usize)>,
    /// `map_Pm` line and column, when it has one.
    map_pm_at: Option<(usize, usize)>,
}

/// The material libraries an OBJ file names.
#[derive(Default)]
pub(super) struct Libraries {
    /// Every material, libraries in `mtllib` order, materials in file order.
    pub(super) materials: Vec<SourceMaterial>,
    /// Material name → index; of two materials of one name the later one wins.
    pub(super) index: HashMap<String, usize>,
    /// Whether a library could not be read (a warning said so).
    pub(super) any_missing: bool,
}

impl Libraries {
    /// Reads the libraries of the OBJ file `obj` named by its `mtllib` statements (the
    /// text after the keyword, and the line), relative to `directory`, each file once.
    /// A library that does not exist is a warning, one per statement, its materials
    /// replaced by the default one (as tinyobjloader and assimp do); one that exists but
    /// cannot be read (a FIFO, a device, too large), or has a malformed line, is an
    /// error naming the library, line and column.
    pub(super) fn load(
        statements: &[(String, usize)],
        directory: &Path,
        obj: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<Self, SceneError> {
        let mut libraries = Self::default();
        let mut read = HashSet::new();
        for (text, line) in statements {
            let mut unread: Vec<(String, String)> = Vec::new();
            for name in library_names(text, directory) {
                let mut file = directory.join(&name);
                if !file.exists() && name.contains('\\') {
                    file = directory.join(name.replace('\\', "/"));
                }
                if !read.insert(file.clone()) {
                    continue;
                }
                let message = |e: InputError| {
                    format!("cannot read the material library {}: {e}", echo_path(&file))
                };
                match read_input(&file, MAX_MODEL_FILE_BYTES) {
                    Ok(bytes) => libraries.parse(&file, &bytes, *line, warnings)?,
                    Err(InputError::Io(e)) if e.kind() == ErrorKind::NotFound => {
                        unread.push((name, message(InputError::Io(e))));
                    }
                    // A FIFO, a device or a huge file is not a library that went missing
                    // but one that must not be read (src/input.rs).
                    Err(e) => {
                        return Err(at(
                            obj,
                            *line,
                            1,
                            format!("mtllib {}: {}", echo(&name), message(e)),
                        ));
                    }
                }
            }
            if let Some((name, message)) = unread.first() {
                libraries.any_missing = true;
                let others = match unread.len() - 1 {
                    0 => String::new(),
                    _ => format!(
                        " (nor can {}, named on the same line)",
                        unread[1..]
                            .iter()
                            .map(|(name, _)| echo(name).to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                };
                warnings.push(format!(
                    "{}:{line}: mtllib {}: {message}{others}; the materials it would define are replaced by the default material",
                    obj.display(),
                    echo(name)
                ));
            }
        }
        Ok(libraries)
    }

    /// Checks and parses one library's text, named on line `mtllib_line` of the OBJ file.
    fn parse(
        &mut self,
        library: &Path,
        bytes: &[u8],
        mtllib_line: usize,
        warnings: &mut Vec<String>,
    ) -> Result<(), SceneError> {
        let text = decode_text(bytes, library, warnings);
        let mut notes = Notes::default();
        let (clean, lines) = scan_mtl(&text, library, &mut notes)?;
        notes.report(library, warnings);
        let (materials, _) =
            tobj::load_mtl_buf(&mut Cursor::new(clean.as_bytes())).map_err(|e| {
                error(
                    library,
                    format!("the material library could not be read: {e}"),
                )
            })?;
        for (
            material,
            MtlLines {
                line,
                map_kd_at,
                map_ke_at,
                map_d_at,
                norm_at,
                bump_at,
                map_pr_at,
                map_pm_at,
            },
        ) in materials.into_iter().zip(lines)
        {
            self.index
                .insert(material.name.clone(), self.materials.len());
            self.materials.push(SourceMaterial {
                material,
                library: library.to_path_buf(),
                line,
                mtllib_line,
                map_kd_at,
                map_ke_at,
                map_d_at,
                norm_at,
                bump_at,
                map_pr_at,
                map_pm_at,
            });
        }
        Ok(())
    }
}

/// The file names a `mtllib` statement gives: the whole text when a file has that name
/// (names with spaces are common; tobj reads them so), otherwise its words, `\ ` within
/// a word standing for a space (several libraries on one line, as the specification
/// and tinyobjloader read it).
fn library_names(text: &str, directory: &Path) -> Vec<String> {
    if !text.contains(char::is_whitespace) || directory.join(text).is_file() {
        return vec![text.to_string()];
    }
    let mut names = Vec::new();
    let mut name = String::new();
    let mut characters = text.chars().peekable();
    while let Some(c) = characters.next() {
        if c == '\\' && characters.peek().is_some_and(|next| next.is_whitespace()) {
            name.extend(characters.next());
        } else if c.is_whitespace() {
            if !name.is_empty() {
                names.push(std::mem::take(&mut name));
            }
        } else {
            name.push(c);
        }
    }
    if !name.is_empty() {
        names.push(name);
    }
    names
}
