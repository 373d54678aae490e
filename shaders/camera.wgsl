// The pinhole camera (with an optional thin lens) and the pixel sample pattern. CPU
// twin: src/camera.rs (strata_grid, jitter_seed, sample_offset, lens_sample,
// CameraFrame::camera_ray, CameraFrame::ray_direction -> camera_ray_direction); the
// hash is sample.wgsl's. The lattice generator of the
// sample count is computed once on the host (camera::lattice_generator) and arrives in
// frame.lattice_generator.

#import types
#import bindings
#import sample
#import intersect

// n columns and n rows of elementary strata for n samples; sample_offset puts exactly
// one sample in every column and every row.
fn strata_grid(samples_per_pixel: u32) -> vec2<u32> {
    let n = max(samples_per_pixel, 1u);
    return vec2<u32>(n, n);
}

// The hash that jitters sample `index` inside its cell: the pattern's samples hash
// pixel_index * spp + index; later rounds through the same strata (index >= spp)
// hash that seed again mixed with the round. Twin of jitter_seed (src/camera.rs).
fn jitter_seed(pixel_index: u32, spp: u32, index: u32) -> u32 {
    let round = index / spp;
    let first = pcg_hash(pixel_index * spp + index % spp);
    if round == 0u {
        return first;
    }
    return pcg_hash(first ^ pcg_hash(round));
}

// Offset in [0, 1)^2 of sample `index` inside pixel (px, py): the pixel centre for one
// sample; otherwise column `index` and row (index * g + shift) mod n of the n x n strata
// (one sample per column and per row, on a Fibonacci lattice of generator g =
// frame.lattice_generator, shifted by a hash of the pixel), jittered inside the cell by a hash of pixel and sample index.
fn sample_offset(px: u32, py: u32, index: u32) -> vec2<f32> {
    let spp = frame.samples_per_pixel;
    if spp <= 1u {
        return vec2<f32>(0.5, 0.5);
    }
    let grid = strata_grid(spp);
    let pixel_index = py * frame.width + px;
    let shift = pcg_hash(pixel_index) % grid.y;
    let column = index % grid.x;
    // column * g + shift < 65535 * 65535 + 65536 < 2^32: no overflow for n <= 65536.
    let row = (column * frame.lattice_generator + shift) % grid.y;
    let seed = jitter_seed(pixel_index, spp, index);
    let jitter = vec2<f32>(unit_from_hash(seed), unit_from_hash(pcg_hash(seed)));
    let cell = vec2<f32>(f32(column), f32(row));
    return (cell + jitter) / vec2<f32>(grid);
}

// The 32-bit golden ratio, XORed into a sample's jitter seed for its lens point.
// CPU twin: LENS_SALT.
const LENS_SALT: u32 = 0x9e3779b9u;

// The point of the unit square that picks the lens point of sample `index` of pixel
// `pixel_index`: a hash of its jitter seed salted apart from the jitter.
fn lens_sample(pixel_index: u32, spp: u32, index: u32) -> vec2<f32> {
    let seed = pcg_hash(jitter_seed(pixel_index, max(spp, 1u), index) ^ LENS_SALT);
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
