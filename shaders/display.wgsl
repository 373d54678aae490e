// Display pass: linear Rgba32Float radiance -> 8-bit display values.
// Composed as types.wgsl + color.wgsl + display.wgsl. CPU twin:
// `LinearImage::to_display_rgba8` in src/film.rs (srgb_encode + quantize_unorm8).

@group(0) @binding(0) var<uniform> display: DisplayUniforms;
@group(0) @binding(1) var linear_input: texture_2d<f32>;
@group(0) @binding(2) var display_output: texture_storage_2d<rgba8unorm, write>;

// Rounds to the nearest of the 256 unorm8 levels, halves away from zero, exactly as
// `quantize_unorm8` does. Quantising here instead of relying on the storage format's
// float-to-unorm conversion makes the result independent of the driver's rounding
// mode: the stored value k/255 converts back to k on any conforming implementation.
// (WGSL `round` rounds halves to even, hence floor(x + 0.5).)
fn quantize_unorm8(encoded: f32) -> f32 {
    return floor(clamp_unit(encoded) * 255.0 + 0.5) / 255.0;
}

@compute @workgroup_size(8, 8, 1)
fn encode_display(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(linear_input);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let linear = textureLoad(linear_input, vec2<i32>(id.xy), 0).rgb;
    var encoded: vec3<f32>;
    if (display.encode_srgb == 1u) {
        encoded = srgb_encode3(linear);
    } else {
        // Naive gamma mode: the values already are display values; clamp only.
        encoded = vec3<f32>(clamp_unit(linear.x), clamp_unit(linear.y), clamp_unit(linear.z));
    }
    let q = vec3<f32>(quantize_unorm8(encoded.x), quantize_unorm8(encoded.y), quantize_unorm8(encoded.z));
    textureStore(display_output, vec2<i32>(id.xy), vec4<f32>(q, 1.0));
}
