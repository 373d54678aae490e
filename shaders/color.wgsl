// The sRGB transfer curve, WGSL twin of `srgb_encode` in src/color.rs.
//
// IEC 61966-2-1:1999 (sRGB), section 5.2, encoding of linear R, G, B in [0, 1]:
//   c' = 12.92 * c                      for c <= 0.0031308
//   c' = 1.055 * c^(1 / 2.4) - 0.055    for c >  0.0031308
// This is the exact piecewise curve, not a 2.2 power approximation.

// True for every NaN bit pattern: exponent all ones and a non-zero mantissa. Tested on
// the bits because `x != x` may be folded away by shader compilers that assume no NaNs.
fn is_nan_f32(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

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

fn srgb_encode3(linear: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(srgb_encode(linear.x), srgb_encode(linear.y), srgb_encode(linear.z));
}
