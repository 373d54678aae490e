//! Hashing and sample warps, below both tracers: the one PCG hash that the camera's
//! sample pattern ([`crate::camera`]) and the path integrator's counter-based random
//! numbers both draw from, and the warps from uniform numbers to directions and points
//! (the cosine hemisphere, the cone of a sphere, a triangle's area) with their
//! densities. The samplers of the BRDF lobes' own distributions are with the BRDFs
//! (`crate::cpu::bxdf`). The GPU twin is `shaders/sample.wgsl` (same names).
//!
//! Every sampler maps uniform numbers `u ∈ [0, 1)²` to a sample and has a density
//! function for the same measure (solid angle for directions, area for points) that
//! `tests/integration/sampler_chi2.rs` checks against the sampler's histogram with a chi-square
//! test, as pbrt-v4 and Mitsuba 3 do. Directions are in a local frame whose `z` is the
//! surface normal ([`ShadingFrame`]).

use glam::{DVec2, DVec3};

/// An orthonormal basis around a unit normal `n` (`z` = `n`), without branches on
/// the normal's direction except its sign (Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    /// First tangent.
    pub x: DVec3,
    /// Second tangent.
    pub y: DVec3,
    /// The normal.
    pub z: DVec3,
}

impl ShadingFrame {
    /// The frame around the unit normal `n`.
    pub fn new(n: DVec3) -> Self {
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Self {
            x: DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            y: DVec3::new(b, sign + n.y * n.y * a, -n.y),
            z: n,
        }
    }

    /// `v` (world) in this frame's coordinates.
    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// `v` (in this frame's coordinates) in world coordinates.
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

/// A point of the unit disk, uniform in area, by Shirley and Chiu's concentric map ("A
/// Low Distortion Map Between Disk and Square", JGT 2(3), 1997), which keeps strata
/// compact.
pub fn sample_concentric_disk(u: DVec2) -> DVec2 {
    let p = u * 2.0 - DVec2::ONE;
    if p == DVec2::ZERO {
        return DVec2::ZERO;
    }
    let quarter = std::f64::consts::FRAC_PI_4;
    let (r, theta) = if p.x.abs() > p.y.abs() {
        (p.x, quarter * (p.y / p.x))
    } else {
        (p.y, 2.0 * quarter - quarter * (p.x / p.y))
    };
    DVec2::new(r * theta.cos(), r * theta.sin())
}

/// A direction of the upper hemisphere (`z > 0`) with density `cos θ / π` (Malley's
/// method: a uniform disk point lifted onto the hemisphere), the ideal sampler of a
/// Lambertian BRDF times the cosine.
pub fn sample_cosine_hemisphere(u: DVec2) -> DVec3 {
    let d = sample_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

/// The density of [`sample_cosine_hemisphere`] at a local direction `w`, per
/// steradian.
pub fn pdf_cosine_hemisphere(w: DVec3) -> f64 {
    w.z.max(0.0) * std::f64::consts::FRAC_1_PI
}

/// The direction `wo` reflects into about the half vector `h`.
pub fn reflect_about(wo: DVec3, h: DVec3) -> DVec3 {
    h * (2.0 * wo.dot(h)) - wo
}

/// The density of a reflected direction, per steradian, from its half vector's
/// density `pdf_h`: the Jacobian `dω_h/dω_i = 1 / (4 |wo·h|)` (Walter et al. 2007,
/// eq. 14).
pub fn reflected_pdf(pdf_h: f64, wo_dot_h: f64) -> f64 {
    if wo_dot_h == 0.0 {
        return 0.0;
    }
    pdf_h / (4.0 * wo_dot_h.abs())
}

/// A direction from `point` towards the sphere of `center` and `radius`, uniform over
/// the cone of directions it subtends, and its density per steradian, `1 / (2π (1 -
/// cos θ_max))`; `None` inside the sphere (Shirley and Wang, "Direct Lighting
/// Calculation by Monte Carlo Integration", EGWR 1991; pbrt-v4 §6.2.4).
pub fn sample_sphere_cone(
    point: DVec3,
    center: DVec3,
    radius: f64,
    u: DVec2,
) -> Option<(DVec3, f64)> {
    let to_center = center - point;
    let distance_squared = to_center.length_squared();
    if distance_squared <= radius * radius {
        return None;
    }
    let sin_squared_max = radius * radius / distance_squared;
    let cos_max = (1.0 - sin_squared_max).max(0.0).sqrt();
    // 1 - cos θ_max, without cancellation for small, far spheres.
    let one_minus_cos_max = sin_squared_max / (1.0 + cos_max);
    let cos_theta = 1.0 - u.x * one_minus_cos_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * u.y;
    let frame = ShadingFrame::new(to_center / distance_squared.sqrt());
    let local = DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
    let pdf = 1.0 / (2.0 * std::f64::consts::PI * one_minus_cos_max);
    Some((frame.to_world(local), pdf))
}

/// The density of [`sample_sphere_cone`] for the direction `w` (unit) from `point`: `1
/// / (2π (1 - cos θ_max))` inside the cone, 0 outside it or inside the sphere.
pub fn pdf_sphere_cone(point: DVec3, center: DVec3, radius: f64, w: DVec3) -> f64 {
    let to_center = center - point;
    let distance_squared = to_center.length_squared();
    if distance_squared <= radius * radius {
        return 0.0;
    }
    let sin_squared_max = radius * radius / distance_squared;
    let cos_max = (1.0 - sin_squared_max).max(0.0).sqrt();
    if w.dot(to_center) < cos_max * distance_squared.sqrt() {
        return 0.0;
    }
    1.0 / (2.0 * std::f64::consts::PI * sin_squared_max / (1.0 + cos_max))
}

/// Barycentric coordinates of a point uniform in area over a triangle: `b₀ = 1 -
/// √u₁`, `b₁ = u₂ √u₁`, `b₂ = 1 - b₀ - b₁` (Turk, "Generating Random Points in
/// Triangles", Graphics Gems, 1990). Its density is `1 / area`.
pub fn sample_triangle_barycentrics(u: DVec2) -> DVec3 {
    let root = u.x.sqrt();
    let b0 = 1.0 - root;
    let b1 = u.y * root;
    DVec3::new(b0, b1, 1.0 - b0 - b1)
}

/// The density per steradian, seen from `point`, of a point `on_light` sampled with
/// density `pdf_area` per unit area on a surface of unit normal `light_normal`:
/// `pdf_area · r² / |cos θ_light|` (pbrt-v4 §4.2.3).
pub fn area_to_solid_angle_pdf(
    pdf_area: f64,
    point: DVec3,
    on_light: DVec3,
    light_normal: DVec3,
) -> f64 {
    let to_light = on_light - point;
    let distance_squared = to_light.length_squared();
    let cos_light = light_normal.dot(to_light).abs() / distance_squared.sqrt();
    if cos_light == 0.0 {
        return 0.0;
    }
    pdf_area * distance_squared / cos_light
}

/// The power heuristic with exponent 2 for a sample of density `pdf_a` from one of
/// two strategies whose other has density `pdf_b` (Veach's thesis, 1997, §9.2.4).
pub fn power_heuristic(pdf_a: f64, pdf_b: f64) -> f64 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a + b == 0.0 {
        return 0.0;
    }
    a / (a + b)
}

/// PCG's RXS-M-XS output permutation of a 32-bit LCG step, as a hash (Jarzynski and
/// Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020): the same bits from the
/// same input on any machine, in WGSL as in Rust.
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A uniform number in [0, 1) from the top 24 bits of a hash: exact in `f32`.
pub fn unit_from_hash(hash: u32) -> f64 {
    f64::from(hash >> 8) * (1.0 / 16_777_216.0)
}

/// A uniform number in `[0, 1)` for dimension `dimension` of sample `sample` of the
/// pixel `pixel` (its index in the image): the three counters hashed in turn, the top
/// 24 bits of the result scaled by 2⁻²⁴, so that f32 represents it exactly.
/// Counter-based: no state, so any pixel's samples can be drawn in any order, on
/// either backend.
pub fn random_number(pixel: u32, sample: u32, dimension: u32) -> f64 {
    unit_from_hash(pcg_hash(pcg_hash(pcg_hash(pixel) ^ sample) ^ dimension))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_for_every_normal() {
        for n in [
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::X,
            DVec3::new(0.3, -0.4, 0.866).normalize(),
            DVec3::new(1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = ShadingFrame::new(n);
            for (a, b) in [(f.x, f.y), (f.y, f.z), (f.x, f.z)] {
                assert!(a.dot(b).abs() < 1e-12, "{n}");
            }
            for v in [f.x, f.y, f.z] {
                assert!((v.length() - 1.0).abs() < 1e-12, "{n}");
            }
            let w = DVec3::new(0.2, -0.7, 0.5);
            assert!(f.to_world(f.to_local(w)).distance(w) < 1e-12);
        }
    }

    #[test]
    fn pcg_hash_matches_reference_values() {
        // Values computed by hand from the published algorithm.
        let state = 747_796_405u32.wrapping_add(2_891_336_453);
        let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
        assert_eq!(pcg_hash(1), (word >> 22) ^ word);
        assert_ne!(pcg_hash(0), pcg_hash(1));
    }

    #[test]
    fn the_hash_matches_the_published_function() {
        // Values of the paper's listing, computed independently (Python integers).
        assert_eq!(pcg_hash(0), 129_708_002);
        assert_eq!(pcg_hash(1), 2_831_084_092);
        assert_eq!(pcg_hash(12_345), 4_099_845_390);
        for i in 0..1000 {
            let x = random_number(i, i / 3, i % 7);
            assert!((0.0..1.0).contains(&x));
        }
    }
}
