// Texture coordinates and bilinear image lookups. CPU twin: src/texture.rs (same
// function names and conventions, documented there and in docs/materials.md).
// Every image of the scene (albedo textures and BRDF maps) is one layer of `images`,
// in the layer's top-left corner; texels are read with textureLoad (Rgba32Float is not
// filterable without an optional feature) and filtered here.

#import types
#import math

@group(0) @binding(11) var images: texture_2d_array<f32>;

fn image_texel(layer: u32, x: u32, y: u32) -> vec3<f32> {
    return textureLoad(images, vec2<u32>(x, y), layer, 0).rgb;
}

//#if ALPHA
// The alpha of texel (x, y) of layer `layer` (the image's own alpha channel).
fn image_alpha(layer: u32, x: u32, y: u32) -> f32 {
    return textureLoad(images, vec2<u32>(x, y), layer, 0).a;
}
//#endif

//#if TEXTURES
struct TangentFrame {
    t: vec3<f32>,
    b: vec3<f32>,
}
//#endif

//#if TEXTURES
// t = normalize(n × a), b = t × n, with a = z if |n.y| ≥ 0.999 else y.
fn tangent_frame(n: vec3<f32>) -> TangentFrame {
    var a = vec3<f32>(0.0, 1.0, 0.0);
    if abs(n.y) >= 0.999 {
        a = vec3<f32>(0.0, 0.0, 1.0);
    }
    let t = normalize(cross(n, a));
    return TangentFrame(t, cross(t, n));
}
//#endif

//#if TEXTURES
// Spherical: u = ½ - atan2(n.z, n.x)/(2π), v = acos(n.y)/π. Planar: u = p·t/scale,
// v = p·b/scale on the tangent frame of the geometric normal. UV: the mesh's
// interpolated coordinates of the texture's set (`uv`: set 0, `uv1`: set 1). Then the
// texture's affine map, material.uv_rows[2·slot] and [2·slot + 1] (UV_SLOT_*).
fn texture_coordinates(material: Material, slot: u32, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>) -> vec2<f32> {
    var mapped: vec2<f32>;
    if material.texture_mapping == MAPPING_UV {
        mapped = select(uv, uv1, (material.uv_sets & (1u << slot)) != 0u);
    } else if material.texture_mapping == MAPPING_SPHERICAL {
        let y = clamp(normal.y, -1.0, 1.0);
        mapped = vec2<f32>(0.5 - atan2(normal.z, normal.x) / (2.0 * PI), acos(y) / PI);
    } else {
        let tangents = tangent_frame(normal);
        mapped = vec2<f32>(dot(position, tangents.t), dot(position, tangents.b)) / material.texture_scale;
    }
    let p = vec3<f32>(mapped, 1.0);
    return vec2<f32>(dot(material.uv_rows[2u * slot].xyz, p), dot(material.uv_rows[2u * slot + 1u].xyz, p));
}
//#endif

//#if TEXTURES
// The texel index of the integer-valued coordinate i on an axis of n texels under
// `wrap` (glTF 2.0 §3.8.4.4, the OpenGL wrap modes): repeat takes i mod n, mirrored
// repeat folds i mod 2n back, clamp holds the edge texel. The modulo is taken in
// floating point (an integer conversion would saturate at 2^31 far out on an infinite
// plane); the min catches rounding up to the period.
fn wrap_index(i: f32, n: u32, wrap: u32) -> u32 {
    let m = f32(n);
    if wrap == WRAP_CLAMP_TO_EDGE {
        return u32(clamp(i, 0.0, m - 1.0));
    }
    if wrap == WRAP_MIRRORED_REPEAT {
        let period = 2.0 * m;
        let j = min(u32(i - period * floor(i / period)), 2u * n - 1u);
        return select(j, 2u * n - 1u - j, j >= n);
    }
    return min(u32(i - m * floor(i / m)), n - 1u);
}
//#endif

fn bilinear(layer: u32, xs: vec2<u32>, ys: vec2<u32>, f: vec2<f32>) -> vec3<f32> {
    let top = image_texel(layer, xs.x, ys.x) * (1.0 - f.x) + image_texel(layer, xs.y, ys.x) * f.x;
    let bottom = image_texel(layer, xs.x, ys.y) * (1.0 - f.x) + image_texel(layer, xs.y, ys.y) * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}

//#if TEXTURES
// Bilinear lookup with the wrap modes `wrap` (u, v); texel (x, y) is centred at
// ((x+½)/W, (y+½)/H).
fn sample_texture(layer: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>) -> vec3<f32> {
    let p = uv * vec2<f32>(f32(width), f32(height)) - 0.5;
    let p0 = floor(p);
    let xs = vec2<u32>(wrap_index(p0.x, width, wrap.x), wrap_index(p0.x + 1.0, width, wrap.x));
    let ys = vec2<u32>(wrap_index(p0.y, height, wrap.y), wrap_index(p0.y + 1.0, height, wrap.y));
    return bilinear(layer, xs, ys, p - p0);
}
//#endif

//#if ALPHA
//#if TEXTURES
// sample_texture of the alpha channel: the same four texels and weights. Twin of
// sample_texture_alpha.
fn sample_texture_alpha(layer: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>) -> f32 {
    let p = uv * vec2<f32>(f32(width), f32(height)) - 0.5;
    let p0 = floor(p);
    let xs = vec2<u32>(wrap_index(p0.x, width, wrap.x), wrap_index(p0.x + 1.0, width, wrap.x));
    let ys = vec2<u32>(wrap_index(p0.y, height, wrap.y), wrap_index(p0.y + 1.0, height, wrap.y));
    let f = p - p0;
    let top = image_alpha(layer, xs.x, ys.x) * (1.0 - f.x) + image_alpha(layer, xs.y, ys.x) * f.x;
    let bottom = image_alpha(layer, xs.x, ys.y) * (1.0 - f.x) + image_alpha(layer, xs.y, ys.y) * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}
//#endif
//#endif

//#if ALPHA
// The alpha (coverage) at a hit: material.alpha times the albedo texture's alpha at
// the albedo's coordinates (glTF 2.0 §3.9.4). Twin of shading_alpha (src/texture.rs).
fn shading_alpha(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>) -> f32 {
    //#if TEXTURES
    if material.texture_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_ALBEDO, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.texture_wrap_u, material.texture_wrap_v);
        return material.alpha * sample_texture_alpha(material.texture_layer, material.texture_width,
                                                     material.texture_height, st, wrap);
    }
    //#endif
    return material.alpha;
}
//#endif

//#if TABULATED
// The tabulated BRDF f(θi, θr): texel (x, y) of the N×N map holds π·f at
// θi = x/(N-1)·π/2, θr = y/(N-1)·π/2; bilinear, clamped.
fn sample_brdf_map(layer: u32, size: u32, theta_i: f32, theta_r: f32) -> vec3<f32> {
    let last = f32(size - 1u);
    let p = clamp(vec2<f32>(theta_i, theta_r) / (0.5 * PI), vec2<f32>(0.0), vec2<f32>(1.0)) * last;
    let p0 = min(floor(p), vec2<f32>(last - 1.0));
    let i = vec2<u32>(p0);
    return bilinear(layer, vec2<u32>(i.x, i.x + 1u), vec2<u32>(i.y, i.y + 1u), p - p0) / PI;
}
//#endif

// The material at a hit: its albedo from shading_albedo, its emission from
// shading_emission, and its metalness and perceptual roughness times the blue and green
// channels of the metallic/roughness texture where there is one (glTF 2.0 §3.9.2),
// looked up at its own coordinates. Twin of shading_material (src/texture.rs).
fn shading_material(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>, color: vec3<f32>) -> Material {
    var shaded = material;
    shaded.diffuse = shading_albedo(material, position, normal, uv, uv1, color);
    shaded.emission = shading_emission(material, position, normal, uv, uv1);
    //#if TEXTURES
    if material.metallic_roughness_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_METALLIC_ROUGHNESS, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.metallic_roughness_wrap & 0xffu,
                             (material.metallic_roughness_wrap >> 8u) & 0xffu);
        let texel = sample_texture(material.metallic_roughness_layer,
                                   material.metallic_roughness_width,
                                   material.metallic_roughness_height, st, wrap);
        shaded.metallic = material.metallic * texel.z;
        shaded.roughness = material.roughness * texel.y;
    }
    //#endif
    return shaded;
}

// The shading normal at a hit with a normal map: `shading_normal` (N) turned by the
// tangent-space texel, normalize(T·x + B·y + N·z) with (x, y, z) = (2·texel - 1)·(scale,
// scale, 1), T the tangent made orthogonal to N, B = sign(w)·(N × T) (glTF 2.0 §3.9.3);
// shading_normal itself without a map or usable tangent, or where the result vanishes
// or leaves the geometric normal's side. Twin of mapped_normal (src/texture.rs).
fn mapped_normal(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>, shading_normal: vec3<f32>, tangent: vec4<f32>) -> vec3<f32> {
    //#if TEXTURES
    if material.normal_layer == NO_IMAGE {
        return shading_normal;
    }
    let along = tangent.xyz;
    let t = along - shading_normal * dot(shading_normal, along);
    let t_squared = dot(t, t);
    if !(t_squared > 0.0) {
        return shading_normal;
    }
    let unit_t = t * inverseSqrt(t_squared);
    let b = cross(shading_normal, unit_t) * select(1.0, -1.0, tangent.w < 0.0);
    let st = texture_coordinates(material, UV_SLOT_NORMAL, position, normal, uv, uv1);
    let wrap = vec2<u32>(material.normal_wrap & 0xffu, (material.normal_wrap >> 8u) & 0xffu);
    let texel = sample_texture(material.normal_layer, material.normal_width, material.normal_height, st, wrap);
    let m = vec3<f32>((2.0 * texel.x - 1.0) * material.normal_scale,
                      (2.0 * texel.y - 1.0) * material.normal_scale, 2.0 * texel.z - 1.0);
    let mapped = unit_t * m.x + b * m.y + shading_normal * m.z;
    let m_squared = dot(mapped, mapped);
    if !(m_squared > 0.0) {
        return shading_normal;
    }
    let unit = mapped * inverseSqrt(m_squared);
    if dot(unit, normal) > 0.0 {
        return unit;
    }
    //#endif
    return shading_normal;
}

// The albedo at a hit at `position` with geometric normal `normal`, mesh texture
// coordinates `uv` and `uv1` (sets 0 and 1) and vertex colour `color` (white off a
// mesh with colours): material.diffuse times `color` (glTF 2.0 §3.9.2), times the
// albedo texture where there is one.
fn shading_albedo(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>, color: vec3<f32>) -> vec3<f32> {
    let albedo = material.diffuse * color;
    //#if TEXTURES
    if material.texture_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_ALBEDO, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.texture_wrap_u, material.texture_wrap_v);
        return albedo * sample_texture(material.texture_layer, material.texture_width, material.texture_height, st, wrap);
    }
    //#endif
    return albedo;
}

// The emitted radiance at a point at `position` with geometric normal `normal` and mesh
// texture coordinates `uv` and `uv1`: material.emission, times the emission texture
// where there is one (glTF 2.0 §3.9.3: emissiveFactor times the texel), at its own
// coordinates; vertex colours do not tint it. Twin of shading_emission
// (src/texture.rs).
fn shading_emission(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>) -> vec3<f32> {
    //#if TEXTURES
    if material.emission_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_EMISSION, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.emission_wrap & 0xffu, (material.emission_wrap >> 8u) & 0xffu);
        return material.emission * sample_texture(material.emission_layer, material.emission_width,
                                                  material.emission_height, st, wrap);
    }
    //#endif
    return material.emission;
}
