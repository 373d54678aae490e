//! The options of an MTL texture statement (`map_Kd -clamp on -s 2 2 wood grain.png`):
//! the file name split from its options ([`texture_options`]), and the `-s` and `-o`
//! options read as the map of the texture's coordinates ([`scale_and_offset`]).

use glam::DVec2;

use crate::scene::TextureTransform;
use crate::scene::import::WrapMode;
use crate::scene::import::gltf::MAX_TEXTURE_TRANSFORM;

/// The `-s` (scale) and `-o` (origin offset) options of a texture statement, taken out
/// of `options` (its unsupported ones, as [`texture_options`] lists them), as the map
/// of the texture's coordinates that tinyobjloader reads and three.js's MTLLoader
/// applies (`repeat` and `offset`: `uv · s + o`), in our coordinates, whose `v` runs
/// down (`v = 1 − v_obj`): scale `(s_u, s_v)`, offset `(o_u, 1 − s_v − o_v)`. Missing
/// values are MTL's defaults (scale 1, offset 0); the third (`w`) is ignored. `Err`
/// with the option's text where a value is not a finite number of at most
/// [`MAX_TEXTURE_TRANSFORM`] in size.
pub(super) fn scale_and_offset(options: &mut Vec<String>) -> Result<TextureTransform, String> {
    let mut scale = DVec2::ONE;
    let mut offset = DVec2::ZERO;
    let mut problem = None;
    options.retain(|option| {
        let mut words = option.split_whitespace();
        let target = match words.next() {
            Some("-s") => &mut scale,
            Some("-o") => &mut offset,
            _ => return true,
        };
        for (axis, word) in words.take(2).enumerate() {
            match word.parse::<f64>() {
                Ok(v) if v.is_finite() && v.abs() <= MAX_TEXTURE_TRANSFORM => target[axis] = v,
                _ => problem = Some(option.clone()),
            }
        }
        false
    });
    if let Some(option) = problem {
        return Err(option);
    }
    let offset = DVec2::new(offset.x, 1.0 - scale.y - offset.y);
    Ok(TextureTransform::offset_rotation_scale(
        0, offset, 0.0, scale,
    ))
}

/// Splits a texture statement (`-clamp on -s 2 2 file name.png`) into the file name, the
/// wrap mode (`-clamp on` clamps) and the options that are not supported.
pub(super) fn texture_options(spec: &str) -> (String, WrapMode, Vec<String>) {
    /// Options and how many arguments each takes at most (all but the last are numbers).
    const OPTIONS: &[(&str, usize)] = &[
        ("-blendu", 1),
        ("-blendv", 1),
        ("-bm", 1),
        ("-boost", 1),
        ("-cc", 1),
        ("-clamp", 1),
        ("-colorspace", 1),
        ("-imfchan", 1),
        ("-mm", 2),
        ("-o", 3),
        ("-s", 3),
        ("-t", 3),
        ("-texres", 1),
        ("-type", 1),
    ];
    let words: Vec<&str> = spec.split_whitespace().collect();
    let mut wrap = WrapMode::Repeat;
    if words.is_empty() {
        return (String::new(), wrap, Vec::new());
    }
    let mut ignored = Vec::new();
    // The options from word `i` on, each with at most its count of arguments (all but
    // the last numbers), none past `end`: returns the word after them.
    let mut options = |mut i: usize, end: usize| {
        while i < end {
            let Some(&(option, most)) = OPTIONS.iter().find(|(o, _)| *o == words[i]) else {
                break;
            };
            let mut taken = 0;
            while taken < most
                && i + 1 + taken < end
                && (taken == 0 || words[i + 1 + taken].parse::<f64>().is_ok())
            {
                taken += 1;
            }
            let arguments = &words[i + 1..i + 1 + taken];
            if option == "-clamp" {
                if arguments.first() == Some(&"on") {
                    wrap = WrapMode::ClampToEdge;
                }
            } else {
                ignored.push(
                    format!("{option} {}", arguments.join(" "))
                        .trim()
                        .to_string(),
                );
            }
            i += 1 + taken;
        }
        i
    };
    // Options before the file name (its last word kept for it), the file name (spaces
    // and all) up to the next option word, and options after it, which
    // tinyobjloader reads too (its issue 85: `bump.jpg -bm 1.5`).
    let first = options(0, words.len() - 1);
    let is_option = |word: &str| OPTIONS.iter().any(|(o, _)| *o == word);
    let last = (first + 1..words.len())
        .find(|&j| is_option(words[j]))
        .unwrap_or(words.len());
    let stop = options(last, words.len());
    if stop < words.len() {
        ignored.push(words[stop..].join(" "));
    }
    // The file name as written between its first and last word (runs of spaces kept).
    let offset = |word: &str| word.as_ptr() as usize - spec.as_ptr() as usize;
    let file = match words.get(first..last) {
        Some([start, .., end]) => &spec[offset(start)..offset(end) + end.len()],
        Some([only]) => only,
        _ => "",
    };
    (file.to_string(), wrap, ignored)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_options_are_split_from_the_file_name() {
        assert_eq!(
            texture_options("wood grain.png"),
            ("wood grain.png".into(), WrapMode::Repeat, vec![])
        );
        assert_eq!(
            texture_options("-clamp on -s 2 2 1 a.png"),
            (
                "a.png".into(),
                WrapMode::ClampToEdge,
                vec!["-s 2 2 1".to_string()]
            )
        );
        assert_eq!(
            texture_options("-imfchan r bumpmap2.jpg -bm 1.5"),
            (
                "bumpmap2.jpg".into(),
                WrapMode::Repeat,
                vec!["-imfchan r".to_string(), "-bm 1.5".to_string()]
            )
        );
        assert_eq!(
            texture_options("-o 1 two  spaces.png"),
            (
                "two  spaces.png".into(),
                WrapMode::Repeat,
                vec!["-o 1".to_string()]
            )
        );
        assert_eq!(
            texture_options("-clamp on"),
            ("on".into(), WrapMode::Repeat, vec![])
        );
        assert_eq!(
            texture_options("this dissolve texture has spaces.jpg -clamp on"),
            (
                "this dissolve texture has spaces.jpg".into(),
                WrapMode::ClampToEdge,
                vec![]
            )
        );
        assert_eq!(
            texture_options("-bm 0.5 b.png"),
            (
                "b.png".into(),
                WrapMode::Repeat,
                vec!["-bm 0.5".to_string()]
            )
        );
    }
}
