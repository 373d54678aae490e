// The pinhole camera (with an optional thin lens) and the pixel sample pattern. CPU
// twin: src/camera.rs (sobol_second, owen_scramble, sample_seed, sample_offset,
// lens_sample, CameraFrame::camera_ray, CameraFrame::ray_direction ->
// camera_ray_direction); the hash is sample.wgsl's.

#import types
#import bindings
#import sample
#import intersect

// The second coordinate of Sobol's (0,2)-sequence as 32 fraction bits: the XOR of the
// direction numbers v_k of the set bits of `index`, v_0 = 1/2, v_k = v_{k-1} ^
// (v_{k-1} >> 1) (Sobol, USSR Comp. Math. 1967; the first coordinate is van der
// Corput's, reverseBits). Twin of sobol_second.
fn sobol_second(index: u32) -> u32 {
    var bits = 0u;
    var direction = 0x80000000u;
    var rest = index;
    while rest != 0u {
        if (rest & 1u) == 1u {
            bits ^= direction;
        }
        direction ^= direction >> 1u;
        rest >>= 1u;
    }
    return bits;
}

// Nested uniform (Owen) scramble of 32 fraction bits: Laine and Karras's hash on the
// reversed bits, the constants of Burley, "Practical Hash-based Owen Scrambling",
// JCGT 9(4), 2020, listing 3. Twin of owen_scramble.
fn owen_scramble(bits: u32, seed: u32) -> u32 {
    var x = reverseBits(bits) + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverseBits(x);
}

// The hash of sample `index` of a pixel that seeds its lens point: the pattern's
// samples hash pixel_index * spp + index; later rounds (index >= spp) hash that seed
// again mixed with the round. Twin of sample_seed (src/camera.rs).
fn sample_seed(pixel_index: u32, spp: u32, index: u32) -> u32 {
    let round = index / spp;
    let first = pcg_hash(pixel_index * spp + index % spp);
    if round == 0u {
        return first;
    }
    return pcg_hash(first ^ pcg_hash(round));
}

// Offset in [0, 1)^2 of sample `index` inside pixel (px, py): the pixel centre for one
// sample; otherwise point `index` of Sobol's (0,2)-sequence, each coordinate
// Owen-scrambled by a hash of the pixel (pbrt-v4's ZSobolSampler construction, §8.7).
// Twin of sample_offset.
fn sample_offset(px: u32, py: u32, index: u32) -> vec2<f32> {
    if frame.samples_per_pixel <= 1u {
        return vec2<f32>(0.5, 0.5);
    }
    let seed_x = pcg_hash(py * frame.width + px);
    let seed_y = pcg_hash(seed_x);
    return vec2<f32>(
        unit_from_hash(owen_scramble(reverseBits(index), seed_x)),
        unit_from_hash(owen_scramble(sobol_second(index), seed_y)),
    );
}

// The 32-bit golden ratio, XORed into a sample's seed for its lens point.
// CPU twin: LENS_SALT.
const LENS_SALT: u32 = 0x9e3779b9u;

// The point of the unit square that picks the lens point of sample `index` of pixel
// `pixel_index`: a hash of its sample seed, salted apart.
fn lens_sample(pixel_index: u32, spp: u32, index: u32) -> vec2<f32> {
    let seed = pcg_hash(sample_seed(pixel_index, max(spp, 1u), index) ^ LENS_SALT);
    return vec2<f32>(unit_from_hash(seed), unit_from_hash(pcg_hash(seed)));
}

// The camera ray of sample `index` of pixel (px, py) at `offset` inside it: the
// pinhole's (camera_ray_origin, camera_ray_direction), or through a thin lens
// (frame.lens_radius > 0; pbrt-v4 §5.2.3) from the lens point lens_sample picks
// towards where the pinhole ray meets the plane in focus.
fn camera_ray(px: u32, py: u32, index: u32, offset: vec2<f32>) -> Ray {
    let x = f32(px) + offset.x;
    let y = f32(py) + offset.y;
    let direction = camera_ray_direction(x, y);
    let origin = camera_ray_origin(x, y);
    if frame.lens_radius <= 0.0 {
        return Ray(origin, direction);
    }
    let focus = frame.eye + direction * (frame.focus_distance / dot(direction, frame.forward));
    let lens = lens_sample(py * frame.width + px, frame.samples_per_pixel, index);
    let disk = sample_concentric_disk(lens) * frame.lens_radius;
    let lens_point = frame.eye + frame.right * disk.x + frame.up * disk.y;
    return Ray(lens_point, normalize(focus - lens_point));
}

// Unit direction through image position (x, y) in pixels from the top-left corner: the
// view direction for an orthographic camera.
fn camera_ray_direction(x: f32, y: f32) -> vec3<f32> {
    if (frame.flags & FLAG_ORTHOGRAPHIC) != 0u {
        return frame.forward;
    }
    let ndc_x = 2.0 * x / f32(frame.width) - 1.0;
    let ndc_y = 1.0 - 2.0 * y / f32(frame.height);
    return normalize(frame.forward
        + frame.right * (ndc_x * frame.aspect * frame.tan_half_fov_y)
        + frame.up * (ndc_y * frame.tan_half_fov_y));
}

// Where the ray through image position (x, y) starts: the eye, or for an orthographic
// camera (frame.tan_half_fov_y then holds the half view height) the point of the view
// plane the position maps to. CPU twin: CameraFrame::ray_origin.
fn camera_ray_origin(x: f32, y: f32) -> vec3<f32> {
    if (frame.flags & FLAG_ORTHOGRAPHIC) == 0u {
        return frame.eye;
    }
    let ndc_x = 2.0 * x / f32(frame.width) - 1.0;
    let ndc_y = 1.0 - 2.0 * y / f32(frame.height);
    return frame.eye + frame.right * (ndc_x * frame.aspect * frame.tan_half_fov_y)
        + frame.up * (ndc_y * frame.tan_half_fov_y);
}
