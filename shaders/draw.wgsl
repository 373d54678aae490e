// Draws a film's mean radiance into the caller's colour attachment: one triangle that
// covers the pass's viewport, which the film fills, each framebuffer pixel showing the
// film texel under its centre (nearest texel). A viewport of the film's size shows
// film pixel (x, y) at viewport pixel (x, y); a larger one scales the film up.
// DRAW_MODE is chosen on the host from the
// scene's sRGB rule and the attachment's format (src/gpu/draw.rs, DrawMode):
//   0: clamp only (linear radiance into an *Srgb attachment, which encodes it; or
//      naive-gamma display values into a linear-unorm attachment);
//   1: exact sRGB curve (linear radiance into a linear-unorm attachment);
//   2: sRGB decode (naive-gamma display values into an *Srgb attachment, whose
//      encoding then gives the values back: no double encoding).

#import color

override DRAW_MODE: u32 = 0u;

@group(0) @binding(0) var film_mean: texture_2d<f32>;

// The triangle's corner and where it falls on the film, in [0, 1]² over the viewport
// (u to the right, v down: film row 0 is the top row).
struct DrawVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) film_uv: vec2<f32>,
}

@vertex
fn fullscreen_triangle(@builtin(vertex_index) index: u32) -> DrawVertex {
    // Vertices (-1, -1), (3, -1), (-1, 3): one triangle that covers the viewport.
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    var out: DrawVertex;
    out.position = vec4<f32>(x, y, 0.0, 1.0);
    out.film_uv = vec2<f32>(0.5 * (x + 1.0), 0.5 * (1.0 - y));
    return out;
}

@fragment
fn draw_film(vertex: DrawVertex) -> @location(0) vec4<f32> {
    let size = textureDimensions(film_mean);
    // At a pixel centre film_uv is (i + 1/2)/n of the viewport's n pixels: with n equal
    // to the film's size the texel is i, half a texel from either rounding edge.
    let texel = vec2<u32>(floor(vertex.film_uv * vec2<f32>(size)));
    let xy = min(texel, size - vec2<u32>(1u));
    let value = textureLoad(film_mean, xy, 0).rgb;
    var c = vec3<f32>(clamp_unit(value.x), clamp_unit(value.y), clamp_unit(value.z));
    if (DRAW_MODE == 1u) {
        c = vec3<f32>(srgb_encode(value.x), srgb_encode(value.y), srgb_encode(value.z));
    } else if (DRAW_MODE == 2u) {
        c = vec3<f32>(srgb_decode(c.x), srgb_decode(c.y), srgb_decode(c.z));
    }
    return vec4<f32>(c, 1.0);
}
