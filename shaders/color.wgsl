// Colour: luminance and the sRGB transfer curve. CPU twin: src/color.rs (same names).
//
// IEC 61966-2-1:1999 (sRGB), section 5.2, encoding of linear R, G, B in [0, 1]:
//   c' = 12.92 * c                      for c <= 0.0031308
//   c' = 1.055 * c^(1 / 2.4) - 0.055    for c >  0.0031308
// This is the exact piecewise curve, not a 2.2 power approximation.

#import math

// Clamps to [0, 1] with NaN mapped to 0, as src/color.rs does before encoding.
// (WGSL leaves clamp(NaN, lo, hi) implementation-defined, hence the explicit test.)
fn clamp_unit(x: f32) -> f32 {
    if (is_nan_f32(x)) {
        return 0.0;
    }
    return clamp(x, 0.0, 1.0);
}

// Encodes one linear channel with the IEC 61966-2-1 curve above; inputs outside
// [0, 1] are clamped first and NaN maps to 0.
fn srgb_encode(linear: f32) -> f32 {
    let c = clamp_unit(linear);
    if (c <= 0.0031308) {
        return 12.92 * c;
    }
    return 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// Inverse of srgb_encode (IEC 61966-2-1:1999, section 5.2), twin of `srgb_decode` in
// src/color.rs; input in [0, 1].
fn srgb_decode(encoded: f32) -> f32 {
    if (encoded <= 0.04045) {
        return encoded / 12.92;
    }
    return pow((encoded + 0.055) / 1.055, 2.4);
}

// Rounds to the nearest of the 256 unorm8 levels, halves away from zero, exactly as
// `quantize_unorm8` does. Quantising here instead of relying on the storage format's
// float-to-unorm conversion makes the result independent of the driver's rounding
// mode: the stored value k/255 converts back to k on any conforming implementation.
// (WGSL `round` rounds halves to even, hence floor(x + 0.5).)
fn quantize_unorm8(encoded: f32) -> f32 {
    return floor(clamp_unit(encoded) * 255.0 + 0.5) / 255.0;
}

// Luminance weights of linear Rec. 709 / sRGB primaries (ITU-R BT.709-6, item 3.3).
// Twin of LUMINANCE_WEIGHTS.
const LUMINANCE_WEIGHTS: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Relative luminance of a linear Rec. 709 colour, the weights summed in channel order
// as the CPU twin sums them.
fn luminance(c: vec3<f32>) -> f32 {
    return LUMINANCE_WEIGHTS.x * c.x + LUMINANCE_WEIGHTS.y * c.y + LUMINANCE_WEIGHTS.z * c.z;
}
