//! Colour: the luminance of linear radiance and the exact piecewise sRGB curve
//! (IEC 61966-2-1), not a 2.2 power. Part of the layer below both tracers: the CPU
//! reference, the light distributions of [`crate::accel`] and the noise estimate use
//! the one [`luminance`]. The GPU twin is `shaders/color.wgsl` (same names).

use glam::DVec3;

/// Luminance weights of linear Rec. 709 / sRGB primaries (ITU-R BT.709-6, item 3.3;
/// IEC 61966-2-1): `Y = 0.2126 R + 0.7152 G + 0.0722 B`. Twin of `LUMINANCE_WEIGHTS` in
/// `shaders/color.wgsl`.
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Relative luminance of a linear Rec. 709 colour: [`LUMINANCE_WEIGHTS`] summed in
/// channel order (the GPU twin sums in the same order).
pub fn luminance(c: DVec3) -> f64 {
    let [r, g, b] = LUMINANCE_WEIGHTS;
    r * c.x + g * c.y + b * c.z
}

/// Clamps to [0, 1], NaN to 0: the inputs of the sRGB curves.
pub fn clamp_unit(x: f64) -> f64 {
    if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }
}

/// Encodes one linear channel in [0, 1] with the sRGB transfer curve (IEC 61966-2-1:
/// `12.92·c` below 0.0031308, `1.055·c^(1/2.4) − 0.055` above). Values outside [0, 1]
/// are clamped first, NaN maps to 0.
pub fn srgb_encode(linear: f64) -> f64 {
    let c = clamp_unit(linear);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB curve extended monotonically above 1 (no clamp at the top), for radiance
/// values such as emission that may exceed 1. Negative and NaN inputs map to 0.
pub fn srgb_encode_extended(linear: f64) -> f64 {
    if linear > 1.0 {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    } else {
        srgb_encode(linear)
    }
}

/// Decodes one sRGB-encoded channel in [0, 1] to linear (the inverse of
/// [`srgb_encode`]: `c/12.92` up to 0.04045, `((c+0.055)/1.055)^2.4` above).
pub fn srgb_decode(encoded: f64) -> f64 {
    let c = clamp_unit(encoded);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Quantises an encoded value in [0, 1] to 8 bits with round-to-nearest, as the GPU's
/// `Rgba8Unorm` store does.
pub fn quantize_unorm8(encoded: f64) -> u8 {
    (encoded.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_and_decode_are_inverse() {
        for i in 0..=1000 {
            let x = i as f64 / 1000.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-12, "at {x}");
        }
    }

    #[test]
    fn curve_matches_published_points() {
        // Linear 0.5 encodes to 0.7353569830524495 (IEC 61966-2-1 formula);
        // linear 0.18 (mid grey) to 0.4613561295004...; the two pieces meet at 0.0031308.
        assert!((srgb_encode(0.5) - 0.735_356_983_052_449_5).abs() < 1e-12);
        assert!((srgb_encode(0.18) - 0.461_356_129_500_4).abs() < 1e-9);
        let below = 12.92 * 0.003_130_8;
        let above = 1.055 * 0.003_130_8_f64.powf(1.0 / 2.4) - 0.055;
        assert!((below - above).abs() < 1e-6);
        assert_eq!(srgb_encode(f64::NAN), 0.0);
        assert!((srgb_encode(7.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn grey_has_its_own_luminance() {
        assert!((luminance(DVec3::splat(0.25)) - 0.25).abs() < 1e-12);
        // The weights the WGSL twin is checked against are the function's.
        for (i, weight) in LUMINANCE_WEIGHTS.iter().enumerate() {
            let mut primary = DVec3::ZERO;
            primary[i] = 1.0;
            assert_eq!(luminance(primary), *weight);
        }
    }
}
