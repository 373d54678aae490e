//! Reflection models and the laws of reflection and refraction, the CPU twin of
//! `shaders/bxdf.wgsl` (same function names, `f64`).

use std::f64::consts::PI;

use glam::DVec3;

use crate::scene::{Material, MaterialKind};

/// Mirror reflection of the incident direction `u` about the unit normal `n`
/// (lecture: `R = u - 2(u·N)N`).
pub fn reflect_direction(u: DVec3, n: DVec3) -> DVec3 {
    u - n * (2.0 * u.dot(n))
}

/// Refraction of the unit incident direction `u` through a surface with unit normal
/// `n` facing the incident side, with `k = η_i / η_t` (lecture, Snell's law):
/// `T = k·u + (k·cos θ_i - sqrt(1 - k²(1 - cos² θ_i)))·N`, `cos θ_i = N·(-u)`.
/// Returns `None` under total internal reflection (negative radicand). An
/// index-matched interface (`k = 1`) returns `u` exactly, so that a dielectric whose
/// index equals its surroundings' vanishes without a trace of rounding.
pub fn refract_direction(u: DVec3, n: DVec3, k: f64) -> Option<DVec3> {
    if k == 1.0 {
        return Some(u);
    }
    let cos_i = (-u.dot(n)).clamp(-1.0, 1.0);
    let radicand = 1.0 - k * k * (1.0 - cos_i * cos_i);
    if radicand < 0.0 {
        return None;
    }
    Some(u * k + n * (k * cos_i - radicand.sqrt()))
}

/// Fresnel reflectances `(R_s, R_p)` of the s- and p-polarised components at a smooth
/// dielectric interface (the Fresnel equations; e.g. Hecht, "Optics", §4.6.2, or pbrt-v4
/// §9.3.4), for `cos_i` the cosine of the incidence angle on the side of index `eta_i`.
/// Both are 1 beyond the critical angle (total internal reflection), and both are
/// exactly 0 at an index-matched interface (`eta_i = eta_t`), where `cos_t` rounded
/// would leave a reflectance of about 1e-17 instead.
pub fn fresnel_dielectric_polarized(cos_i: f64, eta_i: f64, eta_t: f64) -> (f64, f64) {
    if eta_i == eta_t {
        return (0.0, 0.0);
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t_squared = (eta_i / eta_t).powi(2) * (1.0 - cos_i * cos_i);
    if sin_t_squared >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin_t_squared).sqrt();
    let r_s = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let r_p = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    (r_s * r_s, r_p * r_p)
}

/// Fresnel reflectance of unpolarised light: the mean of `R_s` and `R_p`.
pub fn fresnel_dielectric(cos_i: f64, eta_i: f64, eta_t: f64) -> f64 {
    let (r_s, r_p) = fresnel_dielectric_polarized(cos_i, eta_i, eta_t);
    0.5 * (r_s + r_p)
}

/// Lambertian BRDF `albedo / π`.
pub fn brdf_lambert(albedo: DVec3) -> DVec3 {
    albedo / PI
}

/// Normalized Blinn-Phong BRDF `kd/π + ks·(n+8)/(8π)·(N·H)^n` (Akenine-Möller et al.,
/// "Real-Time Rendering", 3rd ed., §7.6, eq. 7.49). The `(n+8)/(8π)` factor keeps the
/// lobe's energy nearly constant as the exponent changes. The lobe is zero where
/// `N·H ≤ 0`, which also keeps `0^0` out of the GPU's `pow`.
pub fn brdf_blinn_phong(material: &Material, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let h = (wi + wo).normalize_or_zero();
    let cos_h = n.dot(h).clamp(-1.0, 1.0);
    let lobe = if cos_h > 0.0 {
        (material.shininess + 8.0) / (8.0 * PI) * cos_h.powf(material.shininess)
    } else {
        0.0
    };
    material.diffuse / PI + material.specular * lobe
}

/// The BRDF of `material`'s base layer for light arriving from `wi` and leaving
/// towards `wo`, both unit and on the side of the unit normal `n`.
pub fn eval_brdf(material: &Material, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    match material.kind {
        MaterialKind::Lambert => brdf_lambert(material.diffuse),
        MaterialKind::BlinnPhong => brdf_blinn_phong(material, n, wi, wo),
        MaterialKind::Mirror | MaterialKind::Dielectric | MaterialKind::Emissive => DVec3::ZERO,
    }
}

/// How a surface splits the light it returns towards `wo` (Whitted's combination):
///
/// `L = L_e + base·(k_d·L_ambient + Σ_lights f·E·cos θ) + reflect ⊙ L(R) + transmit ⊙ L(T)`
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceResponse {
    /// Weight of the base BRDF's direct and ambient lighting (`1 - F` under a coat).
    pub base: f64,
    /// Weight of the perfectly reflected ray.
    pub reflect: DVec3,
    /// Weight of the refracted ray.
    pub transmit: DVec3,
    /// Direction of the refracted ray, when there is one.
    pub transmit_direction: DVec3,
}

/// The weights of [`SurfaceResponse`] for a ray travelling along `direction` that hits
/// `material` where the unit normal facing the ray is `n`; `entering` tells whether
/// the ray arrives from the outside of the surface (the side its geometric normal
/// points to), and `outside_ior` is the index of refraction of the medium on the
/// surface's outside (1 for air; see `MediumStack` in `trace.rs` for nested
/// dielectrics).
pub fn surface_response(
    material: &Material,
    direction: DVec3,
    n: DVec3,
    entering: bool,
    outside_ior: f64,
) -> SurfaceResponse {
    let cos_o = (-direction.dot(n)).clamp(0.0, 1.0);
    let mut response = SurfaceResponse {
        base: 0.0,
        reflect: DVec3::ZERO,
        transmit: DVec3::ZERO,
        transmit_direction: DVec3::ZERO,
    };
    match material.kind {
        MaterialKind::Lambert | MaterialKind::BlinnPhong => {
            // A clear coat reflects F and lets 1 - F reach the base.
            let coat = if material.coat_ior > 0.0 {
                fresnel_dielectric(cos_o, outside_ior, material.coat_ior)
            } else {
                0.0
            };
            response.base = 1.0 - coat;
            response.reflect = DVec3::splat(coat);
        }
        MaterialKind::Mirror => response.reflect = material.reflectance,
        MaterialKind::Dielectric => {
            let (eta_i, eta_t) = if entering {
                (outside_ior, material.ior)
            } else {
                (material.ior, outside_ior)
            };
            match refract_direction(direction, n, eta_i / eta_t) {
                Some(t) => {
                    let f = fresnel_dielectric(cos_o, eta_i, eta_t);
                    response.reflect = DVec3::splat(f);
                    response.transmit = material.transmittance * (1.0 - f);
                    response.transmit_direction = t.normalize();
                }
                // Total internal reflection: everything is reflected.
                None => response.reflect = DVec3::ONE,
            }
        }
        MaterialKind::Emissive => {}
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glass_reflects_four_percent_at_normal_incidence() {
        // ((1.5 - 1) / (1.5 + 1))² = 0.04.
        assert!((fresnel_dielectric(1.0, 1.0, 1.5) - 0.04).abs() < 1e-15);
        // The same from inside.
        assert!((fresnel_dielectric(1.0, 1.5, 1.0) - 0.04).abs() < 1e-15);
    }

    #[test]
    fn brewster_angle_has_no_p_reflection() {
        let brewster = (1.5f64).atan();
        let (r_s, r_p) = fresnel_dielectric_polarized(brewster.cos(), 1.0, 1.5);
        assert!(r_p < 1e-28, "R_p = {r_p}");
        assert!(r_s > 0.1);
    }

    #[test]
    fn critical_angle_starts_total_internal_reflection() {
        let critical = (1.0f64 / 1.5).asin();
        let just_below = (critical - 1e-6).cos();
        let just_above = (critical + 1e-6).cos();
        assert!(fresnel_dielectric(just_below, 1.5, 1.0) < 1.0);
        assert_eq!(fresnel_dielectric(just_above, 1.5, 1.0), 1.0);
        let incoming = DVec3::new((critical + 1e-6).sin(), -(critical + 1e-6).cos(), 0.0);
        assert!(refract_direction(incoming, DVec3::Y, 1.5).is_none());
        let below = DVec3::new((critical - 1e-6).sin(), -(critical - 1e-6).cos(), 0.0);
        let t = refract_direction(below, DVec3::Y, 1.5).expect("refracts");
        // Just below the critical angle the refracted ray grazes the surface.
        assert!(t.y.abs() < 1e-2 && t.x > 0.99);
    }

    #[test]
    fn refraction_obeys_snell() {
        let theta_i: f64 = 0.6;
        let u = DVec3::new(theta_i.sin(), -theta_i.cos(), 0.0);
        let t = refract_direction(u, DVec3::Y, 1.0 / 1.33).expect("refracts");
        assert!((t.length() - 1.0).abs() < 1e-12);
        let sin_t = t.x;
        assert!((theta_i.sin() - 1.33 * sin_t).abs() < 1e-12);
    }

    #[test]
    fn reflection_mirrors_about_the_normal() {
        let u = DVec3::new(1.0, -1.0, 0.0).normalize();
        let r = reflect_direction(u, DVec3::Y);
        assert!((r - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn fresnel_and_transmission_conserve_energy() {
        let glass = Material {
            ior: 1.5,
            ..Material::blank(MaterialKind::Dielectric)
        };
        for i in 0..=90 {
            let theta = f64::from(i)
                .to_radians()
                .min(std::f64::consts::FRAC_PI_2 - 1e-9);
            let dir = DVec3::new(theta.sin(), -theta.cos(), 0.0);
            for entering in [true, false] {
                let r = surface_response(&glass, dir, DVec3::Y, entering, 1.0);
                let total = r.reflect.x + r.transmit.x;
                assert!((total - 1.0).abs() < 1e-12, "θ={i}° entering={entering}");
            }
        }
    }
}
