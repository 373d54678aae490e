// Display pass: linear Rgba32Float radiance -> 8-bit display values.
// CPU twin: `LinearImage::to_display_rgba8` in src/film.rs (srgb_encode + quantize_unorm8).

#import types
#import color

@group(0) @binding(0) var<uniform> display: DisplayUniforms;
@group(0) @binding(1) var linear_input: texture_2d<f32>;
@group(0) @binding(2) var display_output: texture_storage_2d<rgba8unorm, write>;

@compute @workgroup_size(8, 8, 1)
fn encode_display(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(linear_input);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let linear = textureLoad(linear_input, vec2<i32>(id.xy), 0).rgb;
    var encoded: vec3<f32>;
    if (display.encode_srgb == 1u) {
        encoded = vec3<f32>(srgb_encode(linear.x), srgb_encode(linear.y), srgb_encode(linear.z));
    } else {
        // Naive gamma mode: the values already are display values; clamp only.
        encoded = vec3<f32>(clamp_unit(linear.x), clamp_unit(linear.y), clamp_unit(linear.z));
    }
    let q = vec3<f32>(quantize_unorm8(encoded.x), quantize_unorm8(encoded.y), quantize_unorm8(encoded.z));
    textureStore(display_output, vec2<i32>(id.xy), vec4<f32>(q, 1.0));
}
