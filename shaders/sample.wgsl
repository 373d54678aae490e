// Hashing and sample warps shared by the camera's sample pattern and the path
// integrator. CPU twin: src/sample.rs (same names; the samplers' densities are
// checked there and in tests/integration/sampler_chi2.rs).

#import math

// PCG hash of one 32-bit word (Jarzynski and Olano, "Hash Functions for GPU Rendering",
// JCGT 2020). u32 arithmetic wraps, as Rust's wrapping_mul/wrapping_add do.
fn pcg_hash(input: u32) -> u32 {
    let state = input * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) from the top 24 bits of a hash: exact in f32.
fn unit_from_hash(hash: u32) -> f32 {
    return f32(hash >> 8u) * (1.0 / 16777216.0);
}

// A uniform number in [0, 1) for dimension `dimension` of sample `sample` of image
// pixel `pixel`: the three counters hashed in turn by PCG's RXS-M-XS permutation
// (Jarzynski and Olano, JCGT 9(3), 2020; pcg_hash), the top
// 24 bits scaled by 2^-24, exact in f32. Twin of random_number (src/sample.rs).
fn random_number(pixel: u32, sample: u32, dimension: u32) -> f32 {
    return unit_from_hash(pcg_hash(pcg_hash(pcg_hash(pixel) ^ sample) ^ dimension));
}

// An orthonormal basis around a unit normal (z = n), without branches on the normal's
// direction except its sign (Duff et al., "Building an Orthonormal Basis, Revisited",
// JCGT 6(1), 2017). Twin of ShadingFrame.
struct ShadingFrame {
    x: vec3<f32>,
    y: vec3<f32>,
    z: vec3<f32>,
}

fn shading_frame(n: vec3<f32>) -> ShadingFrame {
    // copysign(1, n.z), read from the sign bit as Rust's copysign does (-0 gives -1).
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return ShadingFrame(vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
                        vec3<f32>(b, sign + n.y * n.y * a, -n.y), n);
}

fn shading_frame_to_local(f: ShadingFrame, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(v, f.x), dot(v, f.y), dot(v, f.z));
}

fn shading_frame_to_world(f: ShadingFrame, v: vec3<f32>) -> vec3<f32> {
    return f.x * v.x + f.y * v.y + f.z * v.z;
}

// A point of the unit disk, uniform in area, by Shirley and Chiu's concentric map ("A
// Low Distortion Map Between Disk and Square", JGT 2(3), 1997). Twin of
// sample_concentric_disk.
fn sample_concentric_disk(u: vec2<f32>) -> vec2<f32> {
    let p = u * 2.0 - vec2<f32>(1.0);
    if all(p == vec2<f32>(0.0)) {
        return vec2<f32>(0.0);
    }
    let quarter = PI / 4.0;
    var r = p.y;
    var theta = 2.0 * quarter - quarter * (p.x / p.y);
    if abs(p.x) > abs(p.y) {
        r = p.x;
        theta = quarter * (p.y / p.x);
    }
    return vec2<f32>(r * cos(theta), r * sin(theta));
}

// A direction of the upper hemisphere with density cos θ / π (Malley's method: a
// uniform disk point lifted onto the hemisphere). Twin of sample_cosine_hemisphere.
fn sample_cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let d = sample_concentric_disk(u);
    return vec3<f32>(d.x, d.y, sqrt(max(1.0 - dot(d, d), 0.0)));
}

// The density of sample_cosine_hemisphere per steradian. Twin of pdf_cosine_hemisphere.
fn pdf_cosine_hemisphere(w: vec3<f32>) -> f32 {
    return max(w.z, 0.0) * (1.0 / PI);
}

// The direction `wo` reflects into about the half vector `h`. Twin of reflect_about.
fn reflect_about(wo: vec3<f32>, h: vec3<f32>) -> vec3<f32> {
    return h * (2.0 * dot(wo, h)) - wo;
}

// The density of a reflected direction from its half vector's, by the Jacobian
// dω_h/dω_i = 1 / (4 |wo·h|) (Walter et al. 2007, eq. 14). Twin of reflected_pdf.
fn reflected_pdf(pdf_h: f32, wo_dot_h: f32) -> f32 {
    if wo_dot_h == 0.0 {
        return 0.0;
    }
    return pdf_h / (4.0 * abs(wo_dot_h));
}

//#if SPHERES
// A direction from `point` uniform over the cone a sphere subtends, with density
// 1 / (2π (1 - cos θ_max)); not found inside the sphere (Shirley and Wang, "Direct
// Lighting Calculation by Monte Carlo Integration", EGWR 1991; pbrt-v4 §6.2.4). Twin
// of sample_sphere_cone; sin² θ is computed as a(2 - a) with a = 1 - cos θ, which
// equals the CPU's 1 - cos² θ but keeps f32's precision for small cones.
struct DirectionSample {
    wi: vec3<f32>,
    pdf: f32,
    found: bool,
}

fn sample_sphere_cone(point: vec3<f32>, center: vec3<f32>, radius: f32, u: vec2<f32>) -> DirectionSample {
    var sample = DirectionSample(vec3<f32>(0.0), 0.0, false);
    let to_center = center - point;
    let distance_squared = dot(to_center, to_center);
    if distance_squared <= radius * radius {
        return sample;
    }
    let sin_squared_max = radius * radius / distance_squared;
    let cos_max = sqrt(max(1.0 - sin_squared_max, 0.0));
    // 1 - cos θ_max, without cancellation for small, far spheres.
    let one_minus_cos_max = sin_squared_max / (1.0 + cos_max);
    let a = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - a;
    let sin_theta = sqrt(max(a * (2.0 - a), 0.0));
    let phi = 2.0 * PI * u.y;
    let basis = shading_frame(to_center / sqrt(distance_squared));
    let local = vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
    sample.wi = shading_frame_to_world(basis, local);
    sample.pdf = 1.0 / (2.0 * PI * one_minus_cos_max);
    sample.found = true;
    return sample;
}

// Its density for the unit direction `w`: 0 outside the cone or inside the sphere.
// Twin of pdf_sphere_cone.
fn pdf_sphere_cone(point: vec3<f32>, center: vec3<f32>, radius: f32, w: vec3<f32>) -> f32 {
    let to_center = center - point;
    let distance_squared = dot(to_center, to_center);
    if distance_squared <= radius * radius {
        return 0.0;
    }
    let sin_squared_max = radius * radius / distance_squared;
    let cos_max = sqrt(max(1.0 - sin_squared_max, 0.0));
    if dot(w, to_center) < cos_max * sqrt(distance_squared) {
        return 0.0;
    }
    return 1.0 / (2.0 * PI * sin_squared_max / (1.0 + cos_max));
}
//#endif

// Barycentric coordinates of a point uniform in area over a triangle: b₀ = 1 - √u₁,
// b₁ = u₂ √u₁ (Turk, "Generating Random Points in Triangles", Graphics Gems, 1990).
// Twin of sample_triangle_barycentrics.
fn sample_triangle_barycentrics(u: vec2<f32>) -> vec3<f32> {
    let root = sqrt(u.x);
    let b0 = 1.0 - root;
    let b1 = u.y * root;
    return vec3<f32>(b0, b1, 1.0 - b0 - b1);
}

// The density per steradian, seen from `point`, of a point sampled with density
// `pdf_area` per unit area: pdf_area · r² / |cos θ_light| (pbrt-v4 §4.2.3). Twin of
// area_to_solid_angle_pdf.
fn area_to_solid_angle_pdf(pdf_area: f32, point: vec3<f32>, on_light: vec3<f32>, light_normal: vec3<f32>) -> f32 {
    let to_light = on_light - point;
    let distance_squared = dot(to_light, to_light);
    let cos_light = abs(dot(light_normal, to_light)) / sqrt(distance_squared);
    if cos_light == 0.0 {
        return 0.0;
    }
    return pdf_area * distance_squared / cos_light;
}

// The power heuristic with exponent 2, a² / (a² + b²) (Veach's thesis, 1997, §9.2.4).
// Twin of power_heuristic, written with the ratio of the smaller density to the larger
// so that f32 squares of large densities cannot overflow (equal in exact arithmetic).
fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a == 0.0 && pdf_b == 0.0 {
        return 0.0;
    }
    if pdf_a >= pdf_b {
        let r = pdf_b / pdf_a;
        return 1.0 / (1.0 + r * r);
    }
    let r = pdf_a / pdf_b;
    return r * r / (1.0 + r * r);
}
