// The environment map: the radiance escaping rays see, by direction, and (for the
// path integrator) a light sampled by a 2D piecewise-constant distribution. Twin of
// EnvironmentMap (src/scene/environment.rs, which documents the direction-to-(u, v)
// mapping, Mitsuba 3's `envmap`) and EnvironmentLight (src/accel/environment.rs:
// pbrt-v4's PiecewiseConstant2D over luminance · sin θ, density per steradian
// p(u, v) / (2π² sin θ)). Imported only by modules with the ENVIRONMENT_MAP feature;
// without it the background is the constant frame.background.

#import path_types
#import math

// The header and data described in src/gpu/environment.rs: texels (rgb), the sampling
// function per texel, the rows' conditional CDFs, the marginal CDF.
struct EnvironmentBuffer {
    header: EnvironmentHeader,
    data: array<f32>,
}

@group(0) @binding(20) var<storage, read> environment: EnvironmentBuffer;

// Whether the scene has a map (the general module also renders scenes without one).
fn environment_present() -> bool {
    return environment.header.width > 0u;
}

// The world direction `d` in the map's frame: turned by -α about +y. Twin of
// EnvironmentMap::to_local.
fn environment_to_local(d: vec3<f32>) -> vec3<f32> {
    let cs = environment.header.rotation;
    return vec3<f32>(cs.x * d.x - cs.y * d.z, d.y, cs.y * d.x + cs.x * d.z);
}

// A direction of the map's frame in the world: turned by α about +y. Twin of
// EnvironmentMap::to_world.
fn environment_to_world(d: vec3<f32>) -> vec3<f32> {
    let cs = environment.header.rotation;
    return vec3<f32>(cs.x * d.x + cs.y * d.z, d.y, -cs.y * d.x + cs.x * d.z);
}

// (u, v) of a unit direction of the map's frame: u = atan2(x, -z) / 2π wrapped into
// [0, 1), v = acos(y) / π (Mitsuba 3's envmap). Twin of direction_to_uv.
fn environment_direction_to_uv(d: vec3<f32>) -> vec2<f32> {
    var u = atan2(d.x, -d.z) * (0.5 / PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = acos(clamp(d.y, -1.0, 1.0)) * (1.0 / PI);
    return vec2<f32>(u, v);
}

// The unit direction of the map's frame at (u, v): θ = πv, φ = 2πu,
// (sin φ sin θ, cos θ, -cos φ sin θ). Twin of uv_to_direction.
fn environment_uv_to_direction(uv: vec2<f32>) -> vec3<f32> {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * uv.x;
    let s = sin(theta);
    return vec3<f32>(sin(phi) * s, cos(theta), -cos(phi) * s);
}

// The index (y·width + x) of the texel (⌊u·width⌋, ⌊v·height⌋), clamped into the
// image. Twin of texel_at.
fn environment_texel_at(uv: vec2<f32>) -> u32 {
    let w = environment.header.width;
    let h = environment.header.height;
    let x = min(u32(max(uv.x * f32(w), 0.0)), w - 1u);
    let y = min(u32(max(uv.y * f32(h), 0.0)), h - 1u);
    return y * w + x;
}

// The radiance of texel `texel` times the scale.
fn environment_texel_radiance(texel: u32) -> vec3<f32> {
    let i = 3u * texel;
    let c = vec3<f32>(environment.data[i], environment.data[i + 1u], environment.data[i + 2u]);
    return c * environment.header.scale;
}

// The radiance at map coordinates `uv`: the map interpolated bilinearly with Mitsuba
// 3's envmap convention (column i's centre at u = (i + 1/2)/width, wrapping around;
// row j at v = j/(height - 1)). Twin of EnvironmentMap::radiance_at and Bilinear::at.
fn environment_radiance_at(uv: vec2<f32>) -> vec3<f32> {
    let w = environment.header.width;
    let h = environment.header.height;
    let shifted = uv.x - 0.5 / f32(w);
    let x = (shifted - floor(shifted)) * f32(w);
    let x0 = min(u32(x), w - 1u);
    let x1 = select(x0 + 1u, 0u, x0 + 1u == w);
    let wx = clamp(x - f32(x0), 0.0, 1.0);
    var y0 = 0u;
    var y1 = 0u;
    var wy = 0.0;
    if h >= 2u {
        let y = clamp(uv.y, 0.0, 1.0) * f32(h - 1u);
        y0 = min(u32(y), h - 2u);
        y1 = y0 + 1u;
        wy = clamp(y - f32(y0), 0.0, 1.0);
    }
    let top = environment_texel_radiance(y0 * w + x0) * (1.0 - wx)
        + environment_texel_radiance(y0 * w + x1) * wx;
    let bottom = environment_texel_radiance(y1 * w + x0) * (1.0 - wx)
        + environment_texel_radiance(y1 * w + x1) * wx;
    return top * (1.0 - wy) + bottom * wy;
}

// The radiance seen looking along the unit world direction `d`. Twin of
// EnvironmentMap::radiance.
fn environment_radiance(d: vec3<f32>) -> vec3<f32> {
    return environment_radiance_at(environment_direction_to_uv(environment_to_local(d)));
}

// Where the sampling function f, the conditional CDFs and the marginal CDF begin in
// environment.data.
fn environment_function_offset() -> u32 {
    return 3u * environment.header.width * environment.header.height;
}

fn environment_conditional_offset() -> u32 {
    return 4u * environment.header.width * environment.header.height;
}

fn environment_marginal_offset() -> u32 {
    return environment_conditional_offset() + environment.header.height * (environment.header.width + 1u);
}

// A cell of the 1D piecewise-constant distribution whose n + 1 cumulative values
// begin at `offset`: the largest i < n with cdf[i] <= u (binary search, at most 32
// steps), and the point (i + du) / n it maps u to. Twin of Distribution1D::sample
// (pbrt-v4's PiecewiseConstant1D::Sample).
struct CellSample {
    cell: u32,
    x: f32,
}

fn distribution_1d_sample(offset: u32, n: u32, u: f32) -> CellSample {
    // The first index of [0, n + 1) whose value exceeds u.
    var low = 0u;
    var high = n + 1u;
    for (var step = 0u; step < 32u && low < high; step += 1u) {
        let middle = (low + high) / 2u;
        if environment.data[offset + middle] <= u {
            low = middle + 1u;
        } else {
            high = middle;
        }
    }
    let cell = min(max(low, 1u) - 1u, n - 1u);
    let below = environment.data[offset + cell];
    let width = environment.data[offset + cell + 1u] - below;
    var du = u - below;
    if width > 0.0 {
        du = du / width;
    }
    return CellSample(cell, (f32(cell) + clamp(du, 0.0, 1.0)) / f32(n));
}

// A direction drawn from the map's distribution (the row by u.y, the texel in it by
// u.x), its density per steradian (selection not included) and the texel's radiance;
// not found at a pole or for a black map. Twin of EnvironmentLight::sample.
struct EnvironmentSample {
    wi: vec3<f32>,
    pdf: f32,
    radiance: vec3<f32>,
    found: bool,
}

fn environment_sample(u: vec2<f32>) -> EnvironmentSample {
    var sample = EnvironmentSample(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), false);
    let integral = environment.header.integral;
    if !(integral > 0.0) {
        return sample;
    }
    let w = environment.header.width;
    let h = environment.header.height;
    let row = distribution_1d_sample(environment_marginal_offset(), h, u.y);
    let column = distribution_1d_sample(environment_conditional_offset() + row.cell * (w + 1u), w, u.x);
    let texel = row.cell * w + column.cell;
    let pdf_uv = environment.data[environment_function_offset() + texel] / integral;
    let sin_theta = sin(PI * row.x);
    if !(sin_theta > 0.0 && pdf_uv > 0.0) {
        return sample;
    }
    sample.wi = environment_to_world(environment_uv_to_direction(vec2<f32>(column.x, row.x)));
    sample.pdf = pdf_uv / (2.0 * PI * PI * sin_theta);
    sample.radiance = environment_radiance_at(vec2<f32>(column.x, row.x));
    sample.found = true;
    return sample;
}

// The density per steradian of environment_sample at the unit world direction `wi`.
// Twin of EnvironmentLight::pdf.
fn environment_pdf(wi: vec3<f32>) -> f32 {
    let integral = environment.header.integral;
    if !(integral > 0.0) {
        return 0.0;
    }
    let local = environment_to_local(wi);
    let sin_theta = sqrt(max(1.0 - local.y * local.y, 0.0));
    if sin_theta == 0.0 {
        return 0.0;
    }
    let texel = environment_texel_at(environment_direction_to_uv(local));
    let f = environment.data[environment_function_offset() + texel];
    return f / integral / (2.0 * PI * PI * sin_theta);
}
