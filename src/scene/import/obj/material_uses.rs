//! The checks of an OBJ file's `usemtl` names against its material libraries: names
//! no library defines, and names used before the `mtllib` that defines them. Both are
//! warnings; neither stops the import.

use std::path::Path;

use super::mtl::Libraries;
use super::notes::plural;
use crate::echo::echo;

/// Warns about `usemtl` names that no library defines (unless a library could not be
/// read: its materials are the likely ones, and its warning says so) and about a
/// `usemtl` before the `mtllib` that defines its material (found anyway, by name, as
/// assimp finds it; tinyobjloader and tobj would use their default material).
pub(super) fn check_material_uses(
    used: &[(String, usize)],
    libraries: &Libraries,
    path: &Path,
    warnings: &mut Vec<String>,
) {
    let undefined: Vec<&(String, usize)> = used
        .iter()
        .filter(|(name, _)| !libraries.index.contains_key(name))
        .collect();
    if let Some((name, line)) = undefined.first().filter(|_| !libraries.any_missing) {
        let others = match undefined.len() - 1 {
            0 => String::new(),
            more => format!(
                " (nor {more} other name{} used later: {})",
                plural(more),
                list(undefined[1..].iter().map(|(name, _)| name.as_str()))
            ),
        };
        warnings.push(format!(
            "{}:{line}: usemtl {}: no material library defines it{others}; the default material is used",
            path.display(),
            echo(name)
        ));
    }
    let early: Vec<(&str, usize, usize)> = used
        .iter()
        .filter_map(|(name, line)| {
            let material = &libraries.materials[*libraries.index.get(name)?];
            (material.mtllib_line > *line).then_some((name.as_str(), *line, material.mtllib_line))
        })
        .collect();
    if let Some(&(name, line, mtllib_line)) = early.first() {
        let others = match early.len() - 1 {
            0 => String::new(),
            more => format!(" (and {more} more material{})", plural(more)),
        };
        warnings.push(format!(
            "{}:{line}: usemtl {} comes before the mtllib on line {mtllib_line} that defines it{others}; it is used, but other readers may show their default material",
            path.display(),
            echo(name)
        ));
    }
}

/// The first few of `names` ([`echo`]ed), comma-separated, with `…` when there are
/// more.
fn list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    const SHOWN: usize = 5;
    let names: Vec<&str> = names.collect();
    let shown: Vec<String> = names[..names.len().min(SHOWN)]
        .iter()
        .map(|name| echo(name).to_string())
        .collect();
    let mut text = shown.join(", ");
    if names.len() > SHOWN {
        text.push_str(", …");
    }
    text
}
