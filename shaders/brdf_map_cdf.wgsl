// The inverse-CDF tables of tabulated BRDF maps as the sampler reads them: in the
// alpha channel of each map's own layer of `images`. CPU twin: src/accel/brdf_map_cdf.rs,
// which builds them.

#import math
#import texture

// Texel (x, y) of the inverse-CDF table of the map in `layer`. Twin of
// BrdfMapCdf::value.
fn brdf_map_cdf_value(layer: u32, x: u32, y: u32) -> f32 {
    return textureLoad(images, vec2<u32>(x, y), layer, 0).a;
}

// sin² θ_{b+1} − sin² θ_b of band b of an n-texel axis, the band's projected solid angle
// over π, as sin(θ_{b+1} + θ_b)·sin(θ_{b+1} − θ_b) (no cancellation). Twin of
// band_projected_solid_angle (src/accel/brdf_map_cdf.rs).
fn band_projected_solid_angle(b: u32, n: u32) -> f32 {
    let step = (0.5 * PI) / f32(n - 1u);
    return sin(f32(2u * b + 1u) * step) * sin(step);
}
