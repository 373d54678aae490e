// Reflection models and the laws of reflection and refraction.
// CPU twin: src/cpu/bxdf.rs (same function names).

const PI: f32 = 3.14159265358979323846;

// Mirror reflection of the incident direction u about the unit normal n
// (lecture: R = u - 2(u·N)N).
fn reflect_direction(u: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return u - n * (2.0 * dot(u, n));
}

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

// The base layer's BRDF for light from wi leaving towards wo (both on n's side).
fn eval_brdf(material: Material, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    switch material.kind {
        case MATERIAL_LAMBERT: { return brdf_lambert(material.diffuse); }
        case MATERIAL_BLINN_PHONG: { return brdf_blinn_phong(material, n, wi, wo); }
        default: { return vec3<f32>(0.0); }
    }
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
        case MATERIAL_LAMBERT, MATERIAL_BLINN_PHONG: {
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
        default: {}
    }
    return response;
}
