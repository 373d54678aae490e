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

/// The value of a `-bm` (bump multiplier) option's argument: a finite number, else
/// `None`.
pub(super) fn bump_multiplier(argument: &str) -> Option<f64> {
    argument.parse::<f64>().ok().filter(|v| v.is_finite())
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
    fn the_bump_multiplier_is_a_finite_number() {
        assert_eq!(bump_multiplier("0.5"), Some(0.5));
        assert_eq!(bump_multiplier("inf"), None);
        assert_eq!(bump_multiplier("strong"), None);
    }
}
