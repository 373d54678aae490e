//! OBJ normal maps: MTL's `norm` (tinyobjloader's and three.js's keyword for a
//! tangent-space normal map) and `bump` / `map_Bump`, which classic MTL means as a
//! height map but Blender's OBJ exporter writes for its normal maps (with `-bm` the
//! strength). Which one an image is, is read from its texels.

use crate::scene::Image;

/// What a `bump` or `norm` image holds, read from its texels (file values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BumpImage {
    /// A tangent-space normal map: colour, its blue channel (the normal's `z`,
    /// `(z + 1) / 2`) at least 0.5 on average, as normals leave the surface.
    NormalMap,
    /// A height map: grey (red, green and blue within two 8-bit steps everywhere).
    HeightMap,
    /// Neither: colour whose blue averages below 0.5.
    Unclear,
}

/// Reads which kind of map `image` is.
pub(super) fn classify(image: &Image) -> BumpImage {
    const GREY: f32 = 2.0 / 255.0;
    let grey = image
        .texels
        .iter()
        .all(|t| (t[0] - t[1]).abs() <= GREY && (t[1] - t[2]).abs() <= GREY);
    if grey {
        return BumpImage::HeightMap;
    }
    let blue: f64 = image.texels.iter().map(|t| f64::from(t[2])).sum();
    if blue >= 0.5 * image.texels.len() as f64 {
        BumpImage::NormalMap
    } else {
        BumpImage::Unclear
    }
}

/// The `-bm` (bump multiplier) of a texture statement's unsupported options as
/// `texture_options` lists them, if it has one: its number, or `Err` with the text.
pub(super) fn bump_multiplier(options: &[String]) -> Option<Result<f64, String>> {
    let argument = options.iter().find_map(|o| o.strip_prefix("-bm "))?;
    Some(
        argument
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| argument.to_string()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(texels: Vec<[f32; 4]>) -> Image {
        Image {
            path: "map.png".into(),
            width: texels.len() as u32,
            height: 1,
            texels,
        }
    }

    #[test]
    fn grey_images_are_height_maps_and_bluish_ones_normal_maps() {
        let grey = image(vec![[0.2, 0.2, 0.2, 1.0], [0.9, 0.9, 0.9, 1.0]]);
        assert_eq!(classify(&grey), BumpImage::HeightMap);
        let flat = image(vec![[0.5, 0.5, 1.0, 1.0], [0.7, 0.4, 0.9, 1.0]]);
        assert_eq!(classify(&flat), BumpImage::NormalMap);
        let red = image(vec![[1.0, 0.0, 0.0, 1.0], [0.8, 0.1, 0.2, 1.0]]);
        assert_eq!(classify(&red), BumpImage::Unclear);
    }

    #[test]
    fn the_bump_multiplier_is_read_from_the_options() {
        let options = |o: &[&str]| o.iter().map(|s| (*s).to_string()).collect::<Vec<_>>();
        assert_eq!(
            bump_multiplier(&options(&["-s 2 2", "-bm 0.5"])),
            Some(Ok(0.5))
        );
        assert_eq!(bump_multiplier(&options(&["-s 2 2"])), None);
        assert_eq!(
            bump_multiplier(&options(&["-bm inf"])),
            Some(Err("inf".into()))
        );
    }
}
