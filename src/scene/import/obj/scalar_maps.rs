//! OBJ's scalar textures folded into the textures our materials read. The dissolve
//! texture (`map_d`) is coverage: its values become the alpha of the material's albedo
//! texture (our materials read coverage there, as glTF's do), as tinyobjloader
//! (`alpha_texname`), assimp (`aiTextureType_OPACITY`) and three.js's MTLLoader
//! (`alphaMap`) read it. The PBR extension's roughness and metalness textures
//! (`map_Pr`, `map_Pm`, as tinyobjloader reads them) become one metallic/roughness
//! texture laid out as glTF's (green roughness, blue metalness), whose values replace
//! `Pr` and `Pm` (the caller sets those factors to 1).

use crate::scene::Image;

/// Which channel of a scalar map's image holds its values: its `-imfchan` option
/// (MTL: `r`, `g`, `b`, `m` the matte, i.e. alpha, `l` the luminance), or, without one,
/// for `map_d` the alpha where the image has any texel below 1 (an RGBA cut-out) and
/// else the luminance (a grey mask), for the PBR maps the luminance (MTL's default for
/// scalar textures).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum ScalarChannel {
    /// One colour channel: 0 red, 1 green, 2 blue.
    Colour(usize),
    /// The alpha channel (MTL's "matte").
    Matte,
    /// Rec. 709 luminance of the file's values.
    Luminance,
    /// Alpha if the image has any below 1, else luminance.
    Auto,
}

impl ScalarChannel {
    /// The channel `-imfchan` names, `None` for a letter MTL does not define (`z`, the
    /// depth channel, included: our images have none).
    pub(super) fn from_imfchan(letter: &str) -> Option<Self> {
        match letter {
            "r" => Some(Self::Colour(0)),
            "g" => Some(Self::Colour(1)),
            "b" => Some(Self::Colour(2)),
            "m" => Some(Self::Matte),
            "l" => Some(Self::Luminance),
            _ => None,
        }
    }

    /// The coverage of `texel` (file values, not linearised) by this channel, with
    /// `Auto` already resolved by [`ScalarChannel::resolved`], clamped to [0, 1].
    fn of(self, texel: [f32; 4]) -> f32 {
        let value = match self {
            Self::Colour(c) => texel[c],
            Self::Matte => texel[3],
            Self::Luminance | Self::Auto => {
                0.2126 * texel[0] + 0.7152 * texel[1] + 0.0722 * texel[2]
            }
        };
        if value.is_nan() {
            0.0
        } else {
            value.clamp(0.0, 1.0)
        }
    }

    /// `Auto` made definite for `image`.
    fn resolved(self, image: &Image) -> Self {
        match self {
            Self::Auto if image.texels.iter().any(|t| t[3] < 1.0) => Self::Matte,
            Self::Auto => Self::Luminance,
            other => other,
        }
    }
}

/// The size of the albedo texture that carries `mask`'s coverage: `base`'s (the
/// `map_Kd` image) where there is one, else `mask`'s.
pub(super) fn coverage_size(base: Option<&Image>, mask: &Image) -> (u32, u32) {
    base.map_or((mask.width, mask.height), |b| (b.width, b.height))
}

/// The albedo texture of a material with a dissolve texture: `base`'s texels (white
/// without one: `Kd` then gives the colour) with their alpha multiplied by `mask`'s
/// coverage through `channel`. Where the sizes differ, each texel takes the mean
/// coverage of the mask texels whose centres fall in it (the nearest one where none
/// do: a smaller mask).
pub(super) fn with_coverage(base: Option<&Image>, mask: &Image, channel: ScalarChannel) -> Image {
    let channel = channel.resolved(mask);
    let (width, height) = coverage_size(base, mask);
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let coverage = mean_under(mask, channel, (x, y), (width, height));
            let [r, g, b, a] = base.map_or([1.0; 4], |b| b.texel(x, y));
            texels.push([r, g, b, a * coverage]);
        }
    }
    let path = match base {
        Some(base) => format!(
            "{} with the coverage of {}",
            base.path.display(),
            mask.path.display()
        ),
        None => format!("the coverage of {}", mask.path.display()),
    };
    Image {
        path: path.into(),
        width,
        height,
        texels,
    }
}

/// The mean of `image`'s values through `channel` (resolved) over the texels whose
/// centres fall in texel `(x, y)` of a `width × height` grid over the same square (the
/// nearest one where none do: a smaller image).
fn mean_under(
    image: &Image,
    channel: ScalarChannel,
    (x, y): (u32, u32),
    (width, height): (u32, u32),
) -> f32 {
    // Image texels [start, end) along one axis under target texel `i` of `n`.
    let span = |i: u32, n: u32, m: u32| {
        let start = u64::from(i) * u64::from(m) / u64::from(n);
        let end = (u64::from(i + 1) * u64::from(m) / u64::from(n)).max(start + 1);
        (start as u32, (end as u32).min(m))
    };
    let (x0, x1) = span(x, width, image.width);
    let (y0, y1) = span(y, height, image.height);
    let mut sum = 0.0f64;
    for iy in y0..y1 {
        for ix in x0..x1 {
            sum += f64::from(channel.of(image.texel(ix, iy)));
        }
    }
    (sum / f64::from((x1 - x0) * (y1 - y0))) as f32
}

/// The size of [`metallic_roughness`]'s texture: the larger map's (in texels; the
/// roughness map's on a tie), `None` without either.
pub(super) fn metallic_roughness_size(
    roughness: Option<&Image>,
    metallic: Option<&Image>,
) -> Option<(u32, u32)> {
    let texels = |i: &Image| u64::from(i.width) * u64::from(i.height);
    let larger = match (roughness, metallic) {
        (Some(r), Some(m)) if texels(m) > texels(r) => m,
        (Some(only), _) | (None, Some(only)) => only,
        (None, None) => return None,
    };
    Some((larger.width, larger.height))
}

/// The metallic/roughness texture of `roughness` and `metallic` (`map_Pr`, `map_Pm`:
/// each an image and the channel its `-imfchan` names, luminance without one), at the
/// larger one's size (in texels): green the roughness, blue the metalness, 1 where a
/// map is missing (the factor alone), red 0 and alpha 1. `None` without either map.
pub(super) fn metallic_roughness(
    roughness: Option<(&Image, ScalarChannel)>,
    metallic: Option<(&Image, ScalarChannel)>,
) -> Option<Image> {
    let (width, height) =
        metallic_roughness_size(roughness.map(|(i, _)| i), metallic.map(|(i, _)| i))?;
    let value = |map: Option<(&Image, ScalarChannel)>, x, y| match map {
        Some((image, channel)) => {
            let channel = match channel {
                ScalarChannel::Auto => ScalarChannel::Luminance,
                other => other,
            };
            mean_under(image, channel, (x, y), (width, height))
        }
        None => 1.0,
    };
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            texels.push([0.0, value(roughness, x, y), value(metallic, x, y), 1.0]);
        }
    }
    let name = |map: Option<(&Image, ScalarChannel)>| {
        map.map_or("none".to_string(), |(i, _)| i.path.display().to_string())
    };
    Some(Image {
        path: format!(
            "roughness {} and metalness {}",
            name(roughness),
            name(metallic)
        )
        .into(),
        width,
        height,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Image {
        Image {
            path: "mask.png".into(),
            width,
            height,
            texels,
        }
    }

    #[test]
    fn a_grey_mask_becomes_the_alpha_of_the_colour_texture() {
        let base = image(2, 1, vec![[0.5, 0.25, 0.125, 1.0], [1.0, 0.0, 0.0, 0.5]]);
        let mask = image(2, 1, vec![[0.0, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]]);
        let merged = with_coverage(Some(&base), &mask, ScalarChannel::Auto);
        assert_eq!(
            merged.texels,
            vec![[0.5, 0.25, 0.125, 0.0], [1.0, 0.0, 0.0, 0.5]]
        );
        // Without a colour texture: white, the coverage in alpha.
        let alone = with_coverage(None, &mask, ScalarChannel::Auto);
        assert_eq!(alone.texels, vec![[1.0, 1.0, 1.0, 0.0], [1.0; 4]]);
    }

    #[test]
    fn a_cut_out_with_alpha_gives_its_alpha_and_imfchan_picks_a_channel() {
        let mask = image(2, 1, vec![[1.0, 0.2, 0.0, 0.0], [1.0, 0.6, 0.0, 1.0]]);
        let alpha = |channel| {
            with_coverage(None, &mask, channel)
                .texels
                .iter()
                .map(|t| t[3])
                .collect::<Vec<_>>()
        };
        assert_eq!(alpha(ScalarChannel::Auto), vec![0.0, 1.0]);
        assert_eq!(alpha(ScalarChannel::Colour(1)), vec![0.2, 0.6]);
        assert_eq!(alpha(ScalarChannel::Colour(0)), vec![1.0, 1.0]);
        let luminance = alpha(ScalarChannel::Luminance);
        assert!((luminance[0] - (0.2126 + 0.7152 * 0.2)).abs() < 1e-6);
        assert_eq!(ScalarChannel::from_imfchan("m"), Some(ScalarChannel::Matte));
        assert_eq!(ScalarChannel::from_imfchan("z"), None);
    }

    #[test]
    fn roughness_and_metalness_maps_make_one_texture_at_the_larger_size() {
        let rough = image(2, 1, vec![[0.2, 0.2, 0.2, 1.0], [0.8, 0.8, 0.8, 1.0]]);
        let metal = image(1, 1, vec![[0.0, 0.0, 0.5, 1.0]]);
        let both = metallic_roughness(
            Some((&rough, ScalarChannel::Auto)),
            Some((&metal, ScalarChannel::Colour(2))),
        )
        .expect("a texture");
        assert_eq!((both.width, both.height), (2, 1));
        assert_eq!(
            both.texels,
            vec![[0.0, 0.2, 0.5, 1.0], [0.0, 0.8, 0.5, 1.0]]
        );
        let alone =
            metallic_roughness(None, Some((&metal, ScalarChannel::Auto))).expect("a texture");
        let luminance = 0.0722 * 0.5;
        assert!((alone.texels[0][2] - luminance).abs() < 1e-7);
        assert_eq!(
            alone.texels[0][1], 1.0,
            "no roughness map: the factor alone"
        );
        assert!(metallic_roughness(None, None).is_none());
    }

    #[test]
    fn masks_of_another_size_are_averaged_or_taken_nearest() {
        let base = image(2, 1, vec![[1.0; 4]; 2]);
        // Four mask texels across: two under each base texel, averaged.
        let fine = image(4, 1, [0.0, 1.0, 1.0, 1.0].map(|v| [v, v, v, 1.0]).to_vec());
        let merged = with_coverage(Some(&base), &fine, ScalarChannel::Luminance);
        assert!((merged.texels[0][3] - 0.5).abs() < 1e-6);
        assert!((merged.texels[1][3] - 1.0).abs() < 1e-6);
        // One mask texel for a 2 x 1 base: both take it.
        let coarse = image(1, 1, vec![[0.25, 0.25, 0.25, 1.0]]);
        let merged = with_coverage(Some(&base), &coarse, ScalarChannel::Luminance);
        assert_eq!((merged.width, merged.height), (2, 1));
        assert!(merged.texels.iter().all(|t| (t[3] - 0.25).abs() < 1e-6));
    }
}
