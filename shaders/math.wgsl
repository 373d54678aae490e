// What the CPU reference takes from std and glam (f64::consts::PI, is_nan,
// max_element, normalize_or_zero, indexing a vector), written for WGSL.

const PI: f32 = 3.14159265358979323846;

// True for every NaN bit pattern: exponent all ones and a non-zero mantissa. Tested on
// the bits because `x != x` may be folded away by shader compilers that assume no NaNs.
fn is_nan_f32(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

fn max_component(c: vec3<f32>) -> f32 {
    return max(c.x, max(c.y, c.z));
}

// `v / |v|`, or zero for a zero vector (glam's normalize_or_zero).
fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    if !(length_squared > 0.0) {
        return vec3<f32>(0.0);
    }
    return v / sqrt(length_squared);
}

// Component `k` (0, 1 or 2) of `v`, picked with selects rather than a dynamic index.
fn vector_component(v: vec3<f32>, k: u32) -> f32 {
    return select(select(v.x, v.y, k == 1u), v.z, k == 2u);
}
