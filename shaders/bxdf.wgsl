// Reflection models and the laws of reflection and refraction.
// CPU twin: src/cpu/bxdf.rs (same function names).

#import types
#import math
#import texture

// Mirror reflection of the incident direction u about the unit normal n
// (lecture: R = u - 2(u·N)N).
fn reflect_direction(u: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return u - n * (2.0 * dot(u, n));
}

//#if REFRACTION
// Refraction with k = eta_i / eta_t, n facing the incident side (lecture, Snell's law):
// T = k·u + (k·cos θi - sqrt(1 - k²(1 - cos² θi)))·N, cos θi = N·(-u).
// Returns the zero vector under total internal reflection, and u itself at an
// index-matched interface (k = 1), so such a dielectric vanishes exactly.
fn refract_direction(u: vec3<f32>, n: vec3<f32>, k: f32) -> vec3<f32> {
    if k == 1.0 {
        return u;
    }
    let cos_i = clamp(-dot(u, n), -1.0, 1.0);
    let radicand = 1.0 - k * k * (1.0 - cos_i * cos_i);
    if radicand < 0.0 {
        return vec3<f32>(0.0);
    }
    return u * k + n * (k * cos_i - sqrt(radicand));
}
//#endif

// Fresnel reflectances (R_s, R_p) at a smooth dielectric interface (Fresnel equations;
// Hecht, "Optics", §4.6.2; pbrt-v4 §9.3.4). Both are 1 beyond the critical angle and
// exactly 0 at an index-matched interface (eta_i = eta_t).
fn fresnel_dielectric_polarized(cos_i_in: f32, eta_i: f32, eta_t: f32) -> vec2<f32> {
    if eta_i == eta_t {
        return vec2<f32>(0.0, 0.0);
    }
    let cos_i = clamp(cos_i_in, 0.0, 1.0);
    let ratio = eta_i / eta_t;
    let sin_t_squared = ratio * ratio * (1.0 - cos_i * cos_i);
    if sin_t_squared >= 1.0 {
        return vec2<f32>(1.0, 1.0);
    }
    let cos_t = sqrt(1.0 - sin_t_squared);
    let r_s = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let r_p = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    return vec2<f32>(r_s * r_s, r_p * r_p);
}

// Fresnel reflectance of unpolarised light: the mean of R_s and R_p.
fn fresnel_dielectric(cos_i: f32, eta_i: f32, eta_t: f32) -> f32 {
    let r = fresnel_dielectric_polarized(cos_i, eta_i, eta_t);
    return 0.5 * (r.x + r.y);
}

// Lambertian BRDF albedo / π.
fn brdf_lambert(albedo: vec3<f32>) -> vec3<f32> {
    return albedo / PI;
}

//#if BLINN_PHONG
// Normalized Blinn-Phong kd/π + ks·(n+8)/(8π)·(N·H)^n (Real-Time Rendering, 3rd ed.,
// §7.6, eq. 7.49). Zero where N·H ≤ 0, which keeps pow(0, 0) (undefined in WGSL) away.
fn brdf_blinn_phong(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let half_sum = wi + wo;
    let length_squared = dot(half_sum, half_sum);
    var lobe = 0.0;
    if length_squared > 0.0 {
        let cos_h = clamp(dot(n, half_sum * inverseSqrt(length_squared)), -1.0, 1.0);
        if cos_h > 0.0 {
            lobe = (material.shininess + 8.0) / (8.0 * PI) * pow(cos_h, material.shininess);
        }
    }
    return material.diffuse / PI + material.specular * lobe;
}
//#endif

// Smallest microfacet alpha, so that D's peak 1/(π α²) stays finite (≈ 3.2e5).
const MIN_ALPHA: f32 = 1e-3;

//#if COOK_TORRANCE || PBR
// alpha = roughness² (Burley 2012, §5.4; glTF), clamped below at MIN_ALPHA.
fn microfacet_alpha(roughness: f32) -> f32 {
    return max(roughness * roughness, MIN_ALPHA);
}
//#endif

//#if COOK_TORRANCE || PBR
// sin² of the angle between unit n and h as |n × h|², exact where 1 - (n·h)² cancels:
// at α = 1e-3 an f32 cosine leaves 1 - cos² about 10% wrong, a bias of the near-mirror
// lobes against the f64 twin.
fn sin2_between(n: vec3<f32>, h: vec3<f32>) -> f32 {
    let c = cross(n, h);
    return dot(c, c);
}
//#endif

//#if COOK_TORRANCE || PBR
// GGX: D = α² / (π ((n·h)²(α² - 1) + 1)²) (Walter et al. 2007, eq. 33), the
// denominator written sin²θh + α² cos²θh, which does not cancel near the peak.
fn distribution_ggx(cos_h: f32, sin2_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = sin2_h + cos_h * cos_h * a2;
    return a2 / (PI * d * d);
}
//#endif

//#if COOK_TORRANCE || PBR
// Beckmann: D = exp(-tan²θh/α²) / (π α² cos⁴θh) (Walter et al. 2007, eq. 25),
// tan²θh = sin²θh / cos²θh.
fn distribution_beckmann(cos_h: f32, sin2_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let c2 = cos_h * cos_h;
    let a2 = alpha * alpha;
    let tan2 = sin2_h / c2;
    return exp(-tan2 / a2) / (PI * a2 * c2 * c2);
}
//#endif

//#if COOK_TORRANCE || PBR
// Smith Λ for GGX: (-1 + sqrt(1 + α² tan²θ)) / 2 (Heitz 2014, eq. 86).
fn smith_lambda_ggx(cos: f32, alpha: f32) -> f32 {
    let c2 = cos * cos;
    let tan2 = max(1.0 - c2, 0.0) / c2;
    return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * tan2));
}
//#endif

//#if COOK_TORRANCE || PBR
// Smith Λ for Beckmann, Walter et al.'s rational approximation (2007, eq. 27).
fn smith_lambda_beckmann(cos: f32, alpha: f32) -> f32 {
    let c2 = cos * cos;
    let tan = sqrt(max(1.0 - c2, 0.0) / c2);
    if tan == 0.0 {
        return 0.0;
    }
    let a = 1.0 / (alpha * tan);
    if a >= 1.6 {
        return 0.0;
    }
    return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}
//#endif

//#if COOK_TORRANCE || PBR
// Height-correlated Smith G2 = 1 / (1 + Λ(ωo) + Λ(ωi)) (Heitz 2014, eq. 99).
fn smith_g2_height_correlated(cos_i: f32, cos_o: f32, alpha: f32, distribution: u32) -> f32 {
    if distribution == DISTRIBUTION_BECKMANN {
        return 1.0 / (1.0 + smith_lambda_beckmann(cos_i, alpha) + smith_lambda_beckmann(cos_o, alpha));
    }
    return 1.0 / (1.0 + smith_lambda_ggx(cos_i, alpha) + smith_lambda_ggx(cos_o, alpha));
}
//#endif

//#if COOK_TORRANCE || PBR
fn microfacet_distribution(cos_h: f32, sin2_h: f32, alpha: f32, distribution: u32) -> f32 {
    if distribution == DISTRIBUTION_BECKMANN {
        return distribution_beckmann(cos_h, sin2_h, alpha);
    }
    return distribution_ggx(cos_h, sin2_h, alpha);
}
//#endif

//#if COOK_TORRANCE
// Complex numbers as vec2 (re, im), for the conductor Fresnel equations.
fn complex_mul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}
//#endif

//#if COOK_TORRANCE
fn complex_div(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let d = b.x * b.x + b.y * b.y;
    return vec2<f32>(a.x * b.x + a.y * b.y, a.y * b.x - a.x * b.y) / d;
}
//#endif

//#if COOK_TORRANCE
fn complex_norm(a: vec2<f32>) -> f32 {
    return a.x * a.x + a.y * a.y;
}
//#endif

//#if COOK_TORRANCE
// Principal square root (pbrt-v4 pstd::sqrt for complex numbers).
fn complex_sqrt(z: vec2<f32>) -> vec2<f32> {
    let n = sqrt(complex_norm(z));
    if n == 0.0 {
        return vec2<f32>(0.0);
    }
    let t1 = sqrt(0.5 * (n + abs(z.x)));
    let t2 = 0.5 * z.y / t1;
    if z.x >= 0.0 {
        return vec2<f32>(t1, t2);
    }
    return vec2<f32>(abs(t2), select(-t1, t1, z.y >= 0.0));
}
//#endif

//#if COOK_TORRANCE
// Conductor Fresnel reflectance for complex index eta + i·k (pbrt-v4 §9.3.6 FrComplex).
fn fresnel_conductor_channel(cos_i_in: f32, eta_re: f32, k: f32) -> f32 {
    let cos_i = clamp(cos_i_in, 0.0, 1.0);
    let eta = vec2<f32>(eta_re, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = complex_div(vec2<f32>(sin2_i, 0.0), complex_mul(eta, eta));
    let cos_t = complex_sqrt(vec2<f32>(1.0 - sin2_t.x, -sin2_t.y));
    let ci = vec2<f32>(cos_i, 0.0);
    let eta_ci = complex_mul(eta, ci);
    let eta_ct = complex_mul(eta, cos_t);
    let r_parallel = complex_div(eta_ci - cos_t, eta_ci + cos_t);
    let r_perpendicular = complex_div(ci - eta_ct, ci + eta_ct);
    return 0.5 * (complex_norm(r_parallel) + complex_norm(r_perpendicular));
}
//#endif

//#if COOK_TORRANCE
fn fresnel_conductor(cos_i: f32, eta: vec3<f32>, k: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        fresnel_conductor_channel(cos_i, eta.x, k.x),
        fresnel_conductor_channel(cos_i, eta.y, k.y),
        fresnel_conductor_channel(cos_i, eta.z, k.z),
    );
}
//#endif

//#if COOK_TORRANCE || PBR
// Schlick 1994, eq. 15: F = F0 + (1 - F0)(1 - cos θ)^5.
fn fresnel_schlick(cos: f32, f0: vec3<f32>) -> vec3<f32> {
    let m = 1.0 - clamp(cos, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
}
//#endif

//#if COOK_TORRANCE
fn microfacet_fresnel_exact(material: Material, cos: f32) -> vec3<f32> {
    if material.conductor != 0u {
        return fresnel_conductor(cos, material.eta, material.k);
    }
    return vec3<f32>(fresnel_dielectric(cos, 1.0, material.ior));
}
//#endif

//#if COOK_TORRANCE
// The Cook-Torrance Fresnel: exact, or Schlick with the exact F0.
fn microfacet_fresnel(material: Material, cos: f32) -> vec3<f32> {
    if material.fresnel == FRESNEL_SCHLICK {
        return fresnel_schlick(cos, microfacet_fresnel_exact(material, 1.0));
    }
    return microfacet_fresnel_exact(material, cos);
}
//#endif

//#if COOK_TORRANCE || PBR
// F·D·G2 / (4 cos θi cos θo) (Cook and Torrance 1982; Walter et al. 2007, eq. 20).
fn microfacet_specular(fresnel: vec3<f32>, alpha: f32, distribution: u32, angles: MicrofacetAngles) -> vec3<f32> {
    let d = microfacet_distribution(angles.cos_h, angles.sin2_h, alpha, distribution);
    let g = smith_g2_height_correlated(angles.cos_i, angles.cos_o, alpha, distribution);
    return fresnel * (d * g / (4.0 * angles.cos_i * angles.cos_o));
}
//#endif

//#if COOK_TORRANCE || PBR
// The angles the microfacet models need, for directions wi, wo and their half vector
// h. Twin of the Rust struct of the same name.
struct MicrofacetAngles {
    cos_i: f32,  // n·wi; 0 when the pair gives no reflection
    cos_o: f32,  // n·wo
    cos_h: f32,  // n·h
    sin2_h: f32, // |n × h|²
    cos_d: f32,  // wi·h, clamped to [0, 1]
}
//#endif

//#if COOK_TORRANCE || PBR
// The MicrofacetAngles of wi and wo about n; cos_i = 0 when the pair gives no
// reflection.
fn microfacet_cosines(n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> MicrofacetAngles {
    let cos_i = dot(n, wi);
    let cos_o = dot(n, wo);
    let half_sum = wi + wo;
    let length_squared = dot(half_sum, half_sum);
    if cos_i <= 0.0 || cos_o <= 0.0 || length_squared == 0.0 {
        return MicrofacetAngles(0.0, 0.0, 0.0, 0.0, 0.0);
    }
    let h = half_sum * inverseSqrt(length_squared);
    return MicrofacetAngles(cos_i, cos_o, dot(n, h), sin2_between(n, h), clamp(dot(wi, h), 0.0, 1.0));
}
//#endif

//#if COOK_TORRANCE
// Cook-Torrance: specular lobe, plus for a dielectric kd/π·(1 - F(θi))(1 - F(θo))
// (Shirley et al. 1997, §4).
fn brdf_cook_torrance(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let angles = microfacet_cosines(n, wi, wo);
    if angles.cos_i == 0.0 {
        return vec3<f32>(0.0);
    }
    let alpha = microfacet_alpha(material.roughness);
    let specular = microfacet_specular(microfacet_fresnel(material, angles.cos_d), alpha, material.distribution, angles);
    if material.conductor != 0u {
        return specular;
    }
    let through = (vec3<f32>(1.0) - microfacet_fresnel(material, angles.cos_i)) * (vec3<f32>(1.0) - microfacet_fresnel(material, angles.cos_o));
    return specular + material.diffuse / PI * through;
}
//#endif

//#if OREN_NAYAR
// Oren and Nayar 1994, eq. 30: A = 1 - 0.5σ²/(σ² + 0.33), B = 0.45σ²/(σ² + 0.09).
fn oren_nayar_coefficients(sigma: f32) -> vec2<f32> {
    let s2 = sigma * sigma;
    return vec2<f32>(1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09));
}
//#endif

//#if OREN_NAYAR
// ρ/π·(A + B·max(0, cos(φi - φo))·sin α·tan β), α = max(θi, θo), β = min(θi, θo).
fn brdf_oren_nayar(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let ab = oren_nayar_coefficients(material.sigma);
    let cos_i = clamp(dot(n, wi), 0.0, 1.0);
    let cos_o = clamp(dot(n, wo), 0.0, 1.0);
    let sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
    let sin_o = sqrt(max(1.0 - cos_o * cos_o, 0.0));
    let projected = dot(wi - n * cos_i, wo - n * cos_o);
    let sines = sin_i * sin_o;
    var cos_phi = 0.0;
    if sines > 1e-6 {
        cos_phi = clamp(projected / sines, -1.0, 1.0);
    }
    var sin_alpha = sin_o;
    var tan_beta = 0.0;
    if cos_i < cos_o {
        sin_alpha = sin_i;
        tan_beta = sin_o / cos_o;
    } else if cos_i > 0.0 {
        tan_beta = sin_i / cos_i;
    }
    return material.diffuse / PI * (ab.x + ab.y * max(cos_phi, 0.0) * sin_alpha * tan_beta);
}
//#endif

//#if TABULATED
// The tabulated BRDF at the angles of wi and wo from the normal (isotropic). The angles
// are atan2(|n × w|, n · w), equal to acos(n · w) for unit vectors but accurate in f32
// on GPUs, whose acos is an approximation (on lavapipe it put the path-traced
// tabulated.toml 2.9e-4 RMSE from the CPU; with atan2, 8e-7). Twin of brdf_tabulated.
fn brdf_tabulated(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if material.brdf_map_layer == NO_IMAGE {
        return vec3<f32>(0.0);
    }
    let theta_i = atan2(length(cross(n, wi)), dot(n, wi));
    let theta_r = atan2(length(cross(n, wo)), dot(n, wo));
    return sample_brdf_map(material.brdf_map_layer, material.brdf_map_size, theta_i, theta_r);
}
//#endif

//#if PBR
// glTF 2.0 Appendix B: F0 = mix(0.04, base, metallic), Schlick F at h·wi, GGX D with
// α = roughness², height-correlated Smith G2, diffuse (1 - F)(1 - metallic)·base/π.
fn brdf_pbr(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let angles = microfacet_cosines(n, wi, wo);
    if angles.cos_i == 0.0 {
        return vec3<f32>(0.0);
    }
    let base = material.diffuse;
    let f0 = mix(vec3<f32>(0.04), base, material.metallic);
    let fresnel = fresnel_schlick(angles.cos_d, f0);
    let alpha = microfacet_alpha(material.roughness);
    let specular = microfacet_specular(fresnel, alpha, DISTRIBUTION_GGX, angles);
    return specular + (vec3<f32>(1.0) - fresnel) * (1.0 - material.metallic) * base / PI;
}
//#endif

// The base layer's BRDF for light from wi leaving towards wo (both on n's side);
// material.diffuse is the (textured) albedo at the hit.
fn eval_brdf(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    switch material.kind {
        case MATERIAL_LAMBERT: { return brdf_lambert(material.diffuse); }
        //#if BLINN_PHONG
        case MATERIAL_BLINN_PHONG: { return brdf_blinn_phong(material, n, wi, wo); }
        //#endif
        //#if COOK_TORRANCE
        case MATERIAL_COOK_TORRANCE: { return brdf_cook_torrance(material, n, wi, wo); }
        //#endif
        //#if OREN_NAYAR
        case MATERIAL_OREN_NAYAR: { return brdf_oren_nayar(material, n, wi, wo); }
        //#endif
        //#if TABULATED
        case MATERIAL_TABULATED: { return brdf_tabulated(material, n, wi, wo); }
        //#endif
        //#if PBR
        case MATERIAL_PBR: { return brdf_pbr(material, n, wi, wo); }
        //#endif
        default: { return vec3<f32>(0.0); }
    }
}

// Whether the kind has a base BRDF lit by the lights (and the ambient term).
fn has_base_brdf(kind: u32) -> bool {
    return kind != MATERIAL_MIRROR && kind != MATERIAL_DIELECTRIC && kind != MATERIAL_EMISSIVE;
}

// Whitted's combination (documented in docs/scene-format.md):
// L = L_e + base·(kd·L_ambient + Σ f·E·cos θ) + reflect ⊙ L(R) + transmit ⊙ L(T).
struct SurfaceResponse {
    base: f32,
    reflect: vec3<f32>,
    transmit: vec3<f32>,
    transmit_direction: vec3<f32>,
}

// The weights for a ray along `direction` hitting `material` where the normal facing
// the ray is n; `entering` tells whether it arrives from the geometric outside, and
// outside_ior is the index of the medium on the surface's outside (1 for air).
fn surface_response(material: Material, direction: vec3<f32>, n: vec3<f32>, entering: bool, outside_ior: f32) -> SurfaceResponse {
    let cos_o = clamp(-dot(direction, n), 0.0, 1.0);
    var response = SurfaceResponse(0.0, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    switch material.kind {
        // The glossy models light only through the base BRDF: no perfect mirror ray.
        case MATERIAL_LAMBERT, MATERIAL_BLINN_PHONG, MATERIAL_COOK_TORRANCE, MATERIAL_OREN_NAYAR, MATERIAL_TABULATED, MATERIAL_PBR: {
            // A clear coat reflects F and lets 1 - F reach the base.
            var coat = 0.0;
            if material.coat_ior > 0.0 {
                coat = fresnel_dielectric(cos_o, outside_ior, material.coat_ior);
            }
            response.base = 1.0 - coat;
            response.reflect = vec3<f32>(coat);
        }
        case MATERIAL_MIRROR: {
            response.reflect = material.reflectance;
        }
        //#if REFRACTION
        case MATERIAL_DIELECTRIC: {
            var eta_i = material.ior;
            var eta_t = outside_ior;
            if entering {
                eta_i = outside_ior;
                eta_t = material.ior;
            }
            let t = refract_direction(direction, n, eta_i / eta_t);
            if all(t == vec3<f32>(0.0)) {
                // Total internal reflection: everything is reflected.
                response.reflect = vec3<f32>(1.0);
            } else {
                let f = fresnel_dielectric(cos_o, eta_i, eta_t);
                response.reflect = vec3<f32>(f);
                response.transmit = material.transmittance * (1.0 - f);
                response.transmit_direction = normalize(t);
            }
        }
        //#endif
        default: {}
    }
    return response;
}

// The importance samplers of the lobes' distributions and their densities, for the
// path integrator.
//#if COOK_TORRANCE || PBR
// A microfacet normal of the isotropic GGX distribution visible from the local `wo`:
// Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018, listing
// 1. Twin of sample_ggx_visible_normal.
fn sample_ggx_visible_normal(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    // The view direction stretched to alpha = 1, and a basis around it (T1 horizontal).
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let length_squared = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if length_squared > 0.0 {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(length_squared);
    }
    let t2 = cross(vh, t1);
    // A point of the projected area: a disk, its far half squeezed by vh.z.
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * r * sin(phi);
    // Onto the hemisphere, and back to the ellipsoid configuration.
    let nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}

// Its density per steradian of normals, D_wo(h) = G1(wo)·max(0, wo·h)·D(h) / wo.z
// (Heitz 2018, eq. 1). Twin of pdf_ggx_visible_normal.
fn pdf_ggx_visible_normal(wo: vec3<f32>, h: vec3<f32>, alpha: f32) -> f32 {
    if wo.z <= 0.0 || h.z <= 0.0 {
        return 0.0;
    }
    let g1 = 1.0 / (1.0 + smith_lambda_ggx(wo.z, alpha));
    return g1 * max(dot(wo, h), 0.0) * distribution_ggx(h.z, h.x * h.x + h.y * h.y, alpha) / wo.z;
}
//#endif

//#if COOK_TORRANCE
// A microfacet normal of the Beckmann distribution with density D(h)·cos θ_h:
// tan² θ_h = -α² ln(1 - u₁), φ = 2π u₂ (Walter et al., "Microfacet Models for
// Refraction through Rough Surfaces", EGSR 2007, eq. 28). Twin of
// sample_beckmann_normal.
fn sample_beckmann_normal(alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let tan_squared = -alpha * alpha * log(1.0 - u.x);
    let cos_theta = 1.0 / sqrt(1.0 + tan_squared);
    // tan θ·cos θ, not sqrt(1 - cos²θ), which cancels near the normal.
    let sin_theta = sqrt(tan_squared) * cos_theta;
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// Its density per steradian of normals. Twin of pdf_beckmann_normal.
fn pdf_beckmann_normal(h: vec3<f32>, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    return distribution_beckmann(h.z, h.x * h.x + h.y * h.y, alpha) * h.z;
}
//#endif

//#if BLINN_PHONG
// A half vector of the normalized Blinn-Phong lobe of exponent n, density
// (n + 2)/(2π)·cos^(n+1) θ_h: cos θ_h = (1 - u₁)^(1/(n+2)), φ = 2π u₂ (inverting its
// CDF in cos θ_h). Twin of sample_blinn_phong_half.
fn sample_blinn_phong_half(n: f32, u: vec2<f32>) -> vec3<f32> {
    let cos_theta = pow(1.0 - u.x, 1.0 / (n + 2.0));
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// Its density per steradian of half vectors. Twin of pdf_blinn_phong_half.
fn pdf_blinn_phong_half(h: vec3<f32>, n: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    return (n + 2.0) / (2.0 * PI) * pow(h.z, n + 1.0);
}
//#endif
