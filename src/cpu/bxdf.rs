//! Reflection models and the laws of reflection and refraction, the CPU twin of
//! `shaders/bxdf.wgsl` (same function names, `f64`).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use crate::scene::{FresnelModel, Image, Material, MaterialKind, MicrofacetDistribution};
use crate::texture::sample_brdf_map;

/// Smallest microfacet `alpha`: roughness 0 is clamped here so that the distribution's
/// peak `1/(π α²)` stays finite (≈ 3.2e5, far inside `f32`) instead of becoming a
/// delta function that a point light can never hit.
pub const MIN_ALPHA: f64 = 1e-3;

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

/// The distribution's `alpha` for a perceptual roughness in [0, 1]:
/// `alpha = roughness²` (Burley 2012, "Physically-Based Shading at Disney", §5.4; the
/// glTF 2.0 convention), clamped below at [`MIN_ALPHA`].
pub fn microfacet_alpha(roughness: f64) -> f64 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// `sin²` of the angle between the unit vectors `n` and `h`, as `|n × h|²`: exact to
/// the rounding of the components even where the angle is tiny, where `1 - (n·h)²`
/// cancels (at `α = 10⁻³` the GPU's `f32` cosine leaves `1 - cos²` about 10% wrong).
pub fn sin2_between(n: DVec3, h: DVec3) -> f64 {
    n.cross(h).length_squared()
}

/// Trowbridge-Reitz (GGX) normal distribution for a microfacet normal at `cos_h = n·h`,
/// `sin2_h = 1 - (n·h)²` from the normal: `D = α² / (π ((n·h)²(α² - 1) + 1)²)` (Walter
/// et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq. 33),
/// its denominator written `sin²θh + α² cos²θh`, which has no cancellation near the
/// peak. Zero for `cos_h ≤ 0`.
pub fn distribution_ggx(cos_h: f64, sin2_h: f64, alpha: f64) -> f64 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = sin2_h + cos_h * cos_h * a2;
    a2 / (PI * d * d)
}

/// Beckmann normal distribution: `D = exp(-tan²θh/α²) / (π α² cos⁴θh)` (Walter et al.
/// 2007, eq. 25), `tan²θh = sin2_h / cos²θh`. Zero for `cos_h ≤ 0`.
pub fn distribution_beckmann(cos_h: f64, sin2_h: f64, alpha: f64) -> f64 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let c2 = cos_h * cos_h;
    let a2 = alpha * alpha;
    let tan2 = sin2_h / c2;
    (-tan2 / a2).exp() / (PI * a2 * c2 * c2)
}

/// Smith's `Λ` for GGX at a direction with `cos θ = cos`:
/// `Λ = (-1 + sqrt(1 + α² tan²θ)) / 2` (Heitz 2014, "Understanding the
/// Masking-Shadowing Function in Microfacet-Based BRDFs", eq. 86).
pub fn smith_lambda_ggx(cos: f64, alpha: f64) -> f64 {
    let c2 = cos * cos;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Smith's `Λ` for Beckmann, with Walter et al.'s rational approximation (2007,
/// eq. 27) of the exact `(erf(a) - 1)/2 + exp(-a²)/(2a√π)`, `a = 1/(α tanθ)`: WGSL has
/// no `erf`, and both backends use the same formula.
pub fn smith_lambda_beckmann(cos: f64, alpha: f64) -> f64 {
    let c2 = cos * cos;
    let tan = ((1.0 - c2).max(0.0) / c2).sqrt();
    if tan == 0.0 {
        return 0.0;
    }
    let a = 1.0 / (alpha * tan);
    if a >= 1.6 {
        return 0.0;
    }
    (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a)
}

/// The height-correlated Smith masking-shadowing function
/// `G2 = 1 / (1 + Λ(ωo) + Λ(ωi))` (Heitz 2014, eq. 99), for both distributions.
pub fn smith_g2_height_correlated(
    cos_i: f64,
    cos_o: f64,
    alpha: f64,
    distribution: MicrofacetDistribution,
) -> f64 {
    let lambda = |c| match distribution {
        MicrofacetDistribution::Ggx => smith_lambda_ggx(c, alpha),
        MicrofacetDistribution::Beckmann => smith_lambda_beckmann(c, alpha),
    };
    1.0 / (1.0 + lambda(cos_i) + lambda(cos_o))
}

/// The normal distribution `D(h)` of `distribution`.
pub fn microfacet_distribution(
    cos_h: f64,
    sin2_h: f64,
    alpha: f64,
    distribution: MicrofacetDistribution,
) -> f64 {
    match distribution {
        MicrofacetDistribution::Ggx => distribution_ggx(cos_h, sin2_h, alpha),
        MicrofacetDistribution::Beckmann => distribution_beckmann(cos_h, sin2_h, alpha),
    }
}

/// Fresnel reflectance of a conductor of complex index `eta + i·k` (light arriving
/// from a medium of index 1) for unpolarised light: pbrt-v4 §9.3.6 `FrComplex`,
/// `r⊥ = (cos_i - η cos_t)/(cos_i + η cos_t)`, `r∥ = (η cos_i - cos_t)/(η cos_i +
/// cos_t)`, `cos_t = sqrt(1 - sin²θi/η²)` in complex arithmetic; `F = (|r⊥|² + |r∥|²)/2`.
pub fn fresnel_conductor_channel(cos_i: f64, eta: f64, k: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = Complex::new(eta, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = Complex::new(sin2_i, 0.0).div(eta.mul(eta));
    let cos_t = Complex::new(1.0 - sin2_t.re, -sin2_t.im).sqrt();
    let ci = Complex::new(cos_i, 0.0);
    let r_parallel = eta.mul(ci).sub(cos_t).div(eta.mul(ci).add(cos_t));
    let r_perpendicular = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    0.5 * (r_parallel.norm() + r_perpendicular.norm())
}

/// [`fresnel_conductor_channel`] per RGB channel.
pub fn fresnel_conductor(cos_i: f64, eta: DVec3, k: DVec3) -> DVec3 {
    DVec3::new(
        fresnel_conductor_channel(cos_i, eta.x, k.x),
        fresnel_conductor_channel(cos_i, eta.y, k.y),
        fresnel_conductor_channel(cos_i, eta.z, k.z),
    )
}

/// Schlick's approximation `F = F0 + (1 - F0)(1 - cos θ)^5` (Schlick 1994, "An
/// Inexpensive BRDF Model for Physically-based Rendering", eq. 15).
pub fn fresnel_schlick(cos: f64, f0: DVec3) -> DVec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (DVec3::ONE - f0) * m
}

/// The Fresnel reflectance a Cook-Torrance material uses at `cos` (conductor or
/// dielectric, exact or Schlick with the exact `F0`).
pub fn microfacet_fresnel(material: &Material, cos: f64) -> DVec3 {
    match material.fresnel {
        FresnelModel::Exact => microfacet_fresnel_exact(material, cos),
        FresnelModel::Schlick => fresnel_schlick(cos, microfacet_fresnel_exact(material, 1.0)),
    }
}

/// The exact Fresnel reflectance of a Cook-Torrance material at `cos`: the
/// conductor's, or the dielectric's from air.
pub fn microfacet_fresnel_exact(material: &Material, cos: f64) -> DVec3 {
    if material.conductor {
        fresnel_conductor(cos, material.eta, material.k)
    } else {
        DVec3::splat(fresnel_dielectric(cos, 1.0, material.ior))
    }
}

/// The specular microfacet lobe `F·D·G2 / (4 cos θi cos θo)` (Cook and Torrance 1982;
/// Walter et al. 2007, eq. 20) with `F = fresnel` already evaluated at `h·wi`.
fn microfacet_specular(
    fresnel: DVec3,
    alpha: f64,
    distribution: MicrofacetDistribution,
    angles: &MicrofacetAngles,
) -> DVec3 {
    let d = microfacet_distribution(angles.cos_h, angles.sin2_h, alpha, distribution);
    let g = smith_g2_height_correlated(angles.cos_i, angles.cos_o, alpha, distribution);
    fresnel * (d * g / (4.0 * angles.cos_i * angles.cos_o))
}

/// The angles the microfacet models need, for a pair of directions and the half
/// vector `h` between them.
struct MicrofacetAngles {
    /// `n·wi`.
    cos_i: f64,
    /// `n·wo`.
    cos_o: f64,
    /// `n·h`.
    cos_h: f64,
    /// `|n × h|²`, see [`sin2_between`].
    sin2_h: f64,
    /// `wi·h`, clamped to [0, 1].
    cos_d: f64,
}

/// The [`MicrofacetAngles`] of `wi` and `wo` about `n`, or `None` when either direction
/// is below the surface or they cancel out.
fn microfacet_cosines(n: DVec3, wi: DVec3, wo: DVec3) -> Option<MicrofacetAngles> {
    let cos_i = n.dot(wi);
    let cos_o = n.dot(wo);
    let h = (wi + wo).normalize_or_zero();
    if cos_i <= 0.0 || cos_o <= 0.0 || h == DVec3::ZERO {
        return None;
    }
    Some(MicrofacetAngles {
        cos_i,
        cos_o,
        cos_h: n.dot(h),
        sin2_h: sin2_between(n, h),
        cos_d: wi.dot(h).clamp(0.0, 1.0),
    })
}

/// Cook-Torrance BRDF: the specular lobe [`microfacet_fresnel`]·D·G2/(4 cos θi cos θo),
/// plus, for a dielectric, a diffuse base `kd/π · (1 - F(θi))(1 - F(θo))` weighted by
/// the light that passes the interface on the way in and out (Shirley et al. 1997,
/// "A Practitioners' Assessment of Light Reflection Models", §4), which keeps the
/// sum reciprocal and near energy conserving. `material.diffuse` is the (textured)
/// albedo.
pub fn brdf_cook_torrance(material: &Material, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let Some(angles) = microfacet_cosines(n, wi, wo) else {
        return DVec3::ZERO;
    };
    let alpha = microfacet_alpha(material.roughness);
    let specular = microfacet_specular(
        microfacet_fresnel(material, angles.cos_d),
        alpha,
        material.distribution,
        &angles,
    );
    if material.conductor {
        return specular;
    }
    let through = (DVec3::ONE - microfacet_fresnel(material, angles.cos_i))
        * (DVec3::ONE - microfacet_fresnel(material, angles.cos_o));
    specular + material.diffuse / PI * through
}

/// Oren-Nayar's `A` and `B` for a facet-slope deviation `sigma` in radians:
/// `A = 1 - 0.5 σ²/(σ² + 0.33)`, `B = 0.45 σ²/(σ² + 0.09)` (Oren and Nayar 1994,
/// "Generalization of Lambert's Reflectance Model", eq. 30, the qualitative model).
pub fn oren_nayar_coefficients(sigma: f64) -> (f64, f64) {
    let s2 = sigma * sigma;
    (1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09))
}

/// Oren-Nayar BRDF `ρ/π · (A + B·max(0, cos(φi - φo))·sin α·tan β)`, `α = max(θi, θo)`,
/// `β = min(θi, θo)` (Oren and Nayar 1994, eq. 30). With σ = 0, `A = 1` and `B = 0`:
/// exactly Lambert.
pub fn brdf_oren_nayar(material: &Material, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let (a, b) = oren_nayar_coefficients(material.sigma);
    let cos_i = n.dot(wi).clamp(0.0, 1.0);
    let cos_o = n.dot(wo).clamp(0.0, 1.0);
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    // cos(φi - φo) from the directions projected on the tangent plane.
    let projected = (wi - n * cos_i).dot(wo - n * cos_o);
    let sines = sin_i * sin_o;
    let cos_phi = if sines > 1e-6 {
        (projected / sines).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    // α is the larger angle (smaller cosine), β the smaller angle (larger cosine).
    let (sin_alpha, tan_beta) = if cos_i < cos_o {
        (sin_i, sin_o / cos_o)
    } else {
        (sin_o, if cos_i > 0.0 { sin_i / cos_i } else { 0.0 })
    };
    material.diffuse / PI * (a + b * cos_phi.max(0.0) * sin_alpha * tan_beta)
}

/// The tabulated BRDF at the angles of `wi` and `wo` from the normal (isotropic,
/// independent of azimuth; see [`sample_brdf_map`]). The angles are `atan2(|n × w|, n ·
/// w)`, which is `acos(n · w)` for unit vectors, as the WGSL twin computes them (GPUs
/// approximate `acos`).
pub fn brdf_tabulated(map: &Image, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let theta_i = n.cross(wi).length().atan2(n.dot(wi));
    let theta_r = n.cross(wo).length().atan2(n.dot(wo));
    sample_brdf_map(map, theta_i, theta_r)
}

/// The glTF 2.0 metal/roughness BRDF (glTF 2.0 specification, Appendix B):
/// `F0 = mix(0.04, base, metallic)`, `F = F0 + (1 - F0)(1 - |h·wi|)^5`,
/// `f = F·D·G2/(4 cos θi cos θo) + (1 - F)(1 - metallic)·base/π` with GGX `D`,
/// `α = roughness²` and height-correlated Smith `G2` (as the Khronos sample viewer;
/// the specification's text writes the separable form). `material.diffuse` is the
/// (textured) base colour.
pub fn brdf_pbr(material: &Material, n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let Some(angles) = microfacet_cosines(n, wi, wo) else {
        return DVec3::ZERO;
    };
    let base = material.diffuse;
    let f0 = DVec3::splat(0.04).lerp(base, material.metallic);
    let fresnel = fresnel_schlick(angles.cos_d, f0);
    let alpha = microfacet_alpha(material.roughness);
    let specular = microfacet_specular(fresnel, alpha, MicrofacetDistribution::Ggx, &angles);
    specular + (DVec3::ONE - fresnel) * (1.0 - material.metallic) * base / PI
}

/// The BRDF of `material`'s base layer for light arriving from `wi` and leaving
/// towards `wo`, both unit and on the side of the unit normal `n`. `images` are the
/// scene's (for tabulated maps); `material.diffuse` is the albedo at the hit (see
/// [`crate::texture::shading_albedo`]).
pub fn eval_brdf(material: &Material, images: &[Image], n: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    match material.kind {
        MaterialKind::Lambert => brdf_lambert(material.diffuse),
        MaterialKind::BlinnPhong => brdf_blinn_phong(material, n, wi, wo),
        MaterialKind::CookTorrance => brdf_cook_torrance(material, n, wi, wo),
        MaterialKind::OrenNayar => brdf_oren_nayar(material, n, wi, wo),
        MaterialKind::Pbr => brdf_pbr(material, n, wi, wo),
        MaterialKind::Tabulated => match material.brdf_map {
            Some(map) => brdf_tabulated(&images[map as usize], n, wi, wo),
            None => DVec3::ZERO,
        },
        MaterialKind::Mirror | MaterialKind::Dielectric | MaterialKind::Emissive => DVec3::ZERO,
    }
}

/// Whether `kind` has a base BRDF lit by the lights (and the ambient term).
pub fn has_base_brdf(kind: MaterialKind) -> bool {
    !matches!(
        kind,
        MaterialKind::Mirror | MaterialKind::Dielectric | MaterialKind::Emissive
    )
}

/// Just enough complex arithmetic for [`fresnel_conductor_channel`].
#[derive(Debug, Clone, Copy)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// `|z|²`.
    fn norm(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// The principal square root (pbrt-v4 `pstd::sqrt` for complex numbers).
    fn sqrt(self) -> Self {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Self::new(0.0, 0.0);
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Self::new(t1, t2)
        } else {
            // sign(im) with sign(-0) = +1, as the WGSL twin's `select` computes it.
            Self::new(t2.abs(), if self.im >= 0.0 { t1 } else { -t1 })
        }
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
        // The glossy models light only through the base BRDF: no perfect mirror ray.
        MaterialKind::Lambert
        | MaterialKind::BlinnPhong
        | MaterialKind::CookTorrance
        | MaterialKind::OrenNayar
        | MaterialKind::Tabulated
        | MaterialKind::Pbr => {
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

// The importance samplers of the lobes' distributions and their densities, for the
// path integrator (`tests/integration/sampler_chi2.rs` checks each against its
// density); the general warps are in `crate::sample`.

/// A microfacet normal of the GGX distribution of roughness `alpha` (isotropic)
/// visible from the local direction `wo` (`wo.z > 0`), with density
/// [`pdf_ggx_visible_normal`]: Heitz, "Sampling the GGX Distribution of Visible
/// Normals", JCGT 7(4), 2018, listing 1.
pub fn sample_ggx_visible_normal(wo: DVec3, alpha: f64, u: DVec2) -> DVec3 {
    // The view direction in the hemisphere configuration (stretched to alpha = 1).
    let vh = DVec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    // An orthonormal basis around it (T1 is horizontal).
    let length_squared = vh.x * vh.x + vh.y * vh.y;
    let t1 = if length_squared > 0.0 {
        DVec3::new(-vh.y, vh.x, 0.0) / length_squared.sqrt()
    } else {
        DVec3::X
    };
    let t2 = vh.cross(t1);
    // A point of the projected area: a disk, its far half squeezed by vh.z.
    let r = u.x.sqrt();
    let phi = 2.0 * std::f64::consts::PI * u.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    // Onto the hemisphere, and back to the ellipsoid configuration.
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    DVec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// The density of [`sample_ggx_visible_normal`] at the microfacet normal `h`, per
/// steradian of normals: `D_wo(h) = G1(wo) · max(0, wo·h) · D(h) / wo.z` (Heitz 2018,
/// eq. 1).
pub fn pdf_ggx_visible_normal(wo: DVec3, h: DVec3, alpha: f64) -> f64 {
    if wo.z <= 0.0 || h.z <= 0.0 {
        return 0.0;
    }
    let g1 = 1.0 / (1.0 + smith_lambda_ggx(wo.z, alpha));
    let sin2_h = h.x * h.x + h.y * h.y;
    g1 * wo.dot(h).max(0.0) * distribution_ggx(h.z, sin2_h, alpha) / wo.z
}

/// A microfacet normal of the Beckmann distribution of roughness `alpha`, with density
/// `D(h) · cos θ_h` ([`pdf_beckmann_normal`]): `tan² θ_h = -α² ln(1 - u₁)`, `φ = 2π u₂`
/// (Walter et al., "Microfacet Models for Refraction through Rough Surfaces", EGSR
/// 2007, eq. 28).
pub fn sample_beckmann_normal(alpha: f64, u: DVec2) -> DVec3 {
    let tan_squared = -alpha * alpha * (1.0 - u.x).ln();
    let cos_theta = 1.0 / (1.0 + tan_squared).sqrt();
    // tan θ·cos θ, not sqrt(1 - cos²θ), which cancels near the normal.
    let sin_theta = tan_squared.sqrt() * cos_theta;
    let phi = 2.0 * std::f64::consts::PI * u.y;
    DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// The density of [`sample_beckmann_normal`] at `h`, per steradian of normals.
pub fn pdf_beckmann_normal(h: DVec3, alpha: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    distribution_beckmann(h.z, h.x * h.x + h.y * h.y, alpha) * h.z
}

/// A half vector of the normalized Blinn-Phong lobe of exponent `n`, with density
/// `(n + 2)/(2π) · cos^(n+1) θ_h` ([`pdf_blinn_phong_half`]), the lobe's
/// distribution `(n + 2)/(2π) cos^n θ_h` times `cos θ_h`: `cos θ_h = u₁^(1/(n+2))`,
/// `φ = 2π u₂` (inverting its CDF in `cos θ_h`).
pub fn sample_blinn_phong_half(n: f64, u: DVec2) -> DVec3 {
    let cos_theta = (1.0 - u.x).powf(1.0 / (n + 2.0));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * u.y;
    DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// The density of [`sample_blinn_phong_half`] at `h`, per steradian of half vectors.
pub fn pdf_blinn_phong_half(h: DVec3, n: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    (n + 2.0) / (2.0 * std::f64::consts::PI) * h.z.powf(n + 1.0)
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
