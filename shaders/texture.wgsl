// Texture coordinates and bilinear image lookups. CPU twin: src/texture.rs (same
// function names and conventions, documented there and in docs/materials.md).
// Every image of the scene (albedo textures and BRDF maps) is one layer of `images`,
// in the layer's top-left corner; texels are read with textureLoad (Rgba32Float is not
// filterable without an optional feature) and filtered here. Level k of the array's
// mip chain holds level k of every image (max(1, w >> k) × max(1, h >> k), mip_levels
// in src/texture.rs), read by the trilinear lookups at a ray cone's footprint
// (texture_lod, sample_texture_lod).

#import types
#import math
#import bindings

@group(0) @binding(11) var images: texture_2d_array<f32>;

fn image_texel(layer: u32, x: u32, y: u32) -> vec3<f32> {
    return textureLoad(images, vec2<u32>(x, y), layer, 0).rgb;
}

// The most trilinear probes of an anisotropic lookup (MAX_TEXTURE_PROBES in
// src/scene/model.rs).
const MAX_TEXTURE_PROBES: u32 = 16u;

// The footprint of a ray cone at a hit (twin of ConeFootprint in src/texture.rs): its
// width there (0: no filtering, level 0), |n·d|, the hit triangle's texture-
// coordinate area per world area for sets 0 and 1 (0 without them), the geometric
// normal, the unit direction of the footprint's long axis in the surface, the
// triangle's texture-coordinate change along it (sets 0: xy, 1: zw) and the most
// probes a lookup takes.
struct ConeFootprint {
    width: f32,
    cosine: f32,
    uv_density: vec2<f32>,
    normal: vec3<f32>,
    axis: vec3<f32>,
    uv_axis: vec4<f32>,
    max_probes: u32,
}

// The footprint of a cone `width` wide where a ray along the unit `direction` meets a
// surface of unit geometric `normal`, the hit triangle's uv_density and uv_axis being
// `uv_density` and `uv_axis`: the cosine is |n·d| (JCGT 10(1), 2021, §3, eq. 13), the
// long axis d − n(n·d) normalised (footprint_axis in src/texture.rs), the probe limit
// MAX_TEXTURE_PROBES with FLAG_ANISOTROPIC_TEXTURES, else 1. Twin of
// ConeFootprint::new with ConeFootprint::with_max_probes.
fn cone_footprint(width: f32, direction: vec3<f32>, normal: vec3<f32>, uv_density: vec2<f32>, uv_axis: vec4<f32>) -> ConeFootprint {
    let axis = normalize_or_zero(direction - normal * dot(direction, normal));
    let max_probes = select(1u, MAX_TEXTURE_PROBES, (frame.flags & FLAG_ANISOTROPIC_TEXTURES) != 0u);
    return ConeFootprint(width, abs(dot(direction, normal)), uv_density, normal, axis, uv_axis, max_probes);
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
    return sample_texture_level(layer, 0u, width, height, uv, wrap);
}

// sample_texture of mip level `level` of an image of width × height at level 0: its
// size there is max(1, width >> level) × max(1, height >> level) (mip_levels).
fn sample_texture_level(layer: u32, level: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>) -> vec3<f32> {
    let w = max(width >> level, 1u);
    let h = max(height >> level, 1u);
    let p = uv * vec2<f32>(f32(w), f32(h)) - 0.5;
    let p0 = floor(p);
    let xs = vec2<u32>(wrap_index(p0.x, w, wrap.x), wrap_index(p0.x + 1.0, w, wrap.x));
    let ys = vec2<u32>(wrap_index(p0.y, h, wrap.y), wrap_index(p0.y + 1.0, h, wrap.y));
    let f = p - p0;
    let i = i32(level);
    let top = textureLoad(images, vec2<u32>(xs.x, ys.x), layer, i).rgb * (1.0 - f.x)
        + textureLoad(images, vec2<u32>(xs.y, ys.x), layer, i).rgb * f.x;
    let bottom = textureLoad(images, vec2<u32>(xs.x, ys.y), layer, i).rgb * (1.0 - f.x)
        + textureLoad(images, vec2<u32>(xs.y, ys.y), layer, i).rgb * f.x;
    return top * (1.0 - f.y) + bottom * f.y;
}

// The level of detail of a lookup of the texture in `slot` (UV_SLOT_*) of `material`,
// an image of width × height, at a hit with `footprint`: λ = log2(w/|n·d|) +
// ½·log2(W·H·ρ) (Akenine-Möller et al., "Improved Shader and Texture Level of Detail
// Using Ray Cones", JCGT 10(1), 2021, §3; Δ = ½·log2(t_a/p_a) of Ray Tracing Gems
// ch. 20, eq. 34), ρ the texture-coordinate area per world area (the triangle's for UV
// mapping, 1/scale² for planar, level 0 for spherical) times |det| of the texture
// transform; clamped to [0, ⌊log2(max(W, H))⌋], NaN → 0. Twin of texture_lod.
fn texture_lod(material: Material, slot: u32, width: u32, height: u32, footprint: ConeFootprint) -> f32 {
    let last = firstLeadingBit(max(width, height));
    if !(footprint.width > 0.0) || last == 0u {
        return 0.0;
    }
    var mapping = 0.0;
    if material.texture_mapping == MAPPING_UV {
        mapping = select(footprint.uv_density.x, footprint.uv_density.y, (material.uv_sets & (1u << slot)) != 0u);
    } else if material.texture_mapping != MAPPING_SPHERICAL {
        mapping = 1.0 / (material.texture_scale * material.texture_scale);
    }
    let r0 = material.uv_rows[2u * slot];
    let r1 = material.uv_rows[2u * slot + 1u];
    let density = mapping * abs(r0.x * r1.y - r0.y * r1.x);
    if !(density > 0.0) {
        return 0.0;
    }
    let lambda = log2(footprint.width / footprint.cosine) + 0.5 * log2(f32(width) * f32(height) * density);
    if lambda > 0.0 {
        return min(lambda, f32(last));
    }
    return 0.0;
}

// Trilinear lookup at level of detail `lod` (texture_lod): the bilinear lookups of
// levels ⌊lod⌋ and ⌊lod⌋ + 1 mixed by its fraction (Williams, "Pyramidal
// Parametrics", 1983; LINEAR_MIPMAP_LINEAR). Twin of sample_texture_lod.
fn sample_texture_lod(layer: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>, lod: f32) -> vec3<f32> {
    let last = firstLeadingBit(max(width, height));
    let base = floor(lod);
    let i = min(u32(base), last);
    let fraction = lod - base;
    let lower = sample_texture_level(layer, i, width, height, uv, wrap);
    if fraction > 0.0 && i < last {
        return lower * (1.0 - fraction) + sample_texture_level(layer, i + 1u, width, height, uv, wrap) * fraction;
    }
    return lower;
}

// How a lookup covers a footprint (twin of TexelFootprint in src/texture.rs): `probes`
// trilinear lookups at level `lod`, spread evenly along `axis` (texture coordinates,
// the probes' span: PROBE_SPAN times the footprint's long axis) around the looked-up
// point.
struct TexelFootprint {
    lod: f32,
    axis: vec2<f32>,
    probes: u32,
}

// The lookup of the texture in `slot` of `material`, an image of width × height, that
// covers `footprint`. Isotropic (max_probes 1, or no long axis in texture space): one
// probe at texture_lod. Anisotropic: the footprint is L = w/|n·d| long along
// footprint.axis and w wide; in texels its long axis is a = J·axis·L (J: planar
// mapping's (axis·t, axis·b)/scale or the triangle's uv_axis, then the transform's
// linear part; times W × H) and its width b = w·L·W·H·ρ/|a|; the probes span √2·a
// (PROBE_SPAN), tapered by probe_weight: N = round(√2·|a|/b) probes clamped to [1,
// max_probes], spaced √2·a/N apart, each at level log2(max(√2·|a|/N, b)) clamped to
// [0, last level] (Feline: McCormack et al., "Fast Elliptical Lines for
// Anisotropic Texture Mapping", SIGGRAPH 1999; the ray cone's ellipse from
// Akenine-Möller et al., JCGT 10(1), 2021). Twin of texel_footprint.
fn texel_footprint(material: Material, slot: u32, width: u32, height: u32, footprint: ConeFootprint) -> TexelFootprint {
    let isotropic = TexelFootprint(texture_lod(material, slot, width, height, footprint), vec2<f32>(0.0), 1u);
    let last = firstLeadingBit(max(width, height));
    if footprint.max_probes <= 1u || !(footprint.width > 0.0) || last == 0u {
        return isotropic;
    }
    var mapping = 0.0;
    var along = vec2<f32>(0.0);
    if material.texture_mapping == MAPPING_UV {
        let set1 = (material.uv_sets & (1u << slot)) != 0u;
        mapping = select(footprint.uv_density.x, footprint.uv_density.y, set1);
        along = select(footprint.uv_axis.xy, footprint.uv_axis.zw, set1);
    } else if material.texture_mapping == MAPPING_SPHERICAL {
        return isotropic;
    } else {
        let tangents = tangent_frame(footprint.normal);
        let scale = material.texture_scale;
        mapping = 1.0 / (scale * scale);
        along = vec2<f32>(dot(footprint.axis, tangents.t), dot(footprint.axis, tangents.b)) / scale;
    }
    let r0 = material.uv_rows[2u * slot];
    let r1 = material.uv_rows[2u * slot + 1u];
    let density = mapping * abs(r0.x * r1.y - r0.y * r1.x);
    let length_along = footprint.width / footprint.cosine;
    let axis = vec2<f32>(r0.x * along.x + r0.y * along.y, r1.x * along.x + r1.y * along.y) * length_along;
    let size = vec2<f32>(f32(width), f32(height));
    let major = length(axis * size);
    let minor = footprint.width * length_along * size.x * size.y * density / major;
    let probe_axis = axis * PROBE_SPAN;
    let span = major * PROBE_SPAN;
    // Positive and finite (not NaN), else the isotropic lookup, which clamps such cases.
    if !(span > 0.0 && span <= 3.4028235e38 && minor > 0.0 && minor <= 3.4028235e38) {
        return isotropic;
    }
    let probes = u32(clamp(round(span / minor), 1.0, f32(footprint.max_probes)));
    let lod = log2(max(span / f32(probes), minor));
    return TexelFootprint(clamp(lod, 0.0, f32(last)), select(vec2<f32>(0.0), probe_axis, probes > 1u), probes);
}

// How far the probes of an anisotropic lookup reach along the footprint's long axis, in
// footprint lengths: √2 (twin of PROBE_SPAN in src/texture.rs, which says why).
const PROBE_SPAN: f32 = 1.4142135;

// The weight of the probe at r in (−1, 1) along the probes' span: e^(−2r²), the
// Gaussian of the elliptical weighted average (Heckbert, "Fundamentals of Texture
// Mapping and Image Warping", 1989, §3.5.8; pbrt-v4's MIPMap::EWA, α = 2). Twin of
// probe_weight.
fn probe_weight(r: f32) -> f32 {
    return exp(-2.0 * r * r);
}

// The lookup `footprint` (texel_footprint) at `uv`: its probes' trilinear lookups
// (sample_texture_lod) at uv + axis·r_i/2, r_i = 2·((i + ½)/N − ½) for i in [0, N),
// averaged with the weights probe_weight(r_i). Twin of sample_texture_footprint.
fn sample_texture_footprint(layer: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>, footprint: TexelFootprint) -> vec3<f32> {
    let n = max(footprint.probes, 1u);
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var i = 0u; i < n; i++) {
        let r = 2.0 * ((f32(i) + 0.5) / f32(n) - 0.5);
        let weight = probe_weight(r);
        sum += sample_texture_lod(layer, width, height, uv + footprint.axis * (0.5 * r), wrap, footprint.lod) * weight;
        total += weight;
    }
    return sum / total;
}

// The filtered lookup of the texture in `slot` of `material` at the hit's footprint.
// Twin of TextureLookup::sample (src/texture.rs).
fn texture_lookup_sample(material: Material, slot: u32, layer: u32, width: u32, height: u32, uv: vec2<f32>, wrap: vec2<u32>, footprint: ConeFootprint) -> vec3<f32> {
    let covered = texel_footprint(material, slot, width, height, footprint);
    return sample_texture_footprint(layer, width, height, uv, wrap, covered);
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
// The alpha (coverage) at a hit: material.alpha times the interpolated vertex-colour
// alpha `vertex_alpha` (1 without vertex colours) times the albedo texture's alpha at
// the albedo's coordinates (glTF 2.0 §3.9.4, COLOR_0 a factor of the base colour:
// §3.7.2.1). Twin of shading_alpha (src/texture.rs).
fn shading_alpha(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>,
                 vertex_alpha: f32) -> f32 {
    let alpha = material.alpha * vertex_alpha;
    //#if TEXTURES
    if material.texture_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_ALBEDO, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.texture_wrap_u, material.texture_wrap_v);
        return alpha * sample_texture_alpha(material.texture_layer, material.texture_width,
                                            material.texture_height, st, wrap);
    }
    //#endif
    return alpha;
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

//#if TEXTURES
// A texture of a material (UV_SLOT_*): its image layer (NO_IMAGE: none), size and
// wrap modes.
struct SlotImage {
    layer: u32,
    width: u32,
    height: u32,
    wrap: vec2<u32>,
}

// The texture of `material` in `slot` (UV_SLOT_*): the fields of Material that name
// it (texture_* for the albedo; metallic_roughness_*, emission_* and normal_* with
// their wrap modes packed u | v << 8).
fn slot_image(material: Material, slot: u32) -> SlotImage {
    switch slot {
        case UV_SLOT_ALBEDO: {
            return SlotImage(material.texture_layer, material.texture_width, material.texture_height,
                             vec2<u32>(material.texture_wrap_u, material.texture_wrap_v));
        }
        case UV_SLOT_METALLIC_ROUGHNESS: {
            let wrap = material.metallic_roughness_wrap;
            return SlotImage(material.metallic_roughness_layer, material.metallic_roughness_width,
                             material.metallic_roughness_height, vec2<u32>(wrap & 0xffu, (wrap >> 8u) & 0xffu));
        }
        case UV_SLOT_EMISSION: {
            let wrap = material.emission_wrap;
            return SlotImage(material.emission_layer, material.emission_width, material.emission_height,
                             vec2<u32>(wrap & 0xffu, (wrap >> 8u) & 0xffu));
        }
        default: {
            let wrap = material.normal_wrap;
            return SlotImage(material.normal_layer, material.normal_width, material.normal_height,
                             vec2<u32>(wrap & 0xffu, (wrap >> 8u) & 0xffu));
        }
    }
}
//#endif

// The texels of the four textures of `material` (indexed by UV_SLOT_*) at a hit at
// `position` with geometric normal `normal` and mesh texture coordinates `uv` and
// `uv1`, each looked up at its own coordinates at `footprint`; white where the material
// has no such texture. One loop over the slots, so that the filtered lookup is
// compiled once per call site: lavapipe inlines every call, and four inlined copies of
// the anisotropic lookup made the general kernels compile 1.6 times as long. The CPU
// reference looks each texture up where it is used (shading_material, mapped_normal in
// src/texture.rs), the same lookups.
fn material_texels(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>, footprint: ConeFootprint) -> array<vec3<f32>, 4> {
    var texels = array<vec3<f32>, 4>(vec3<f32>(1.0), vec3<f32>(1.0), vec3<f32>(1.0), vec3<f32>(1.0));
    //#if TEXTURES
    for (var slot = 0u; slot < 4u; slot++) {
        let image = slot_image(material, slot);
        if image.layer != NO_IMAGE {
            let st = texture_coordinates(material, slot, position, normal, uv, uv1);
            texels[slot] = texture_lookup_sample(material, slot, image.layer, image.width, image.height, st,
                                                 image.wrap, footprint);
        }
    }
    //#endif
    return texels;
}

// The material at a hit whose textures read `texels` (material_texels) and whose
// vertex colour is `color` (white off a mesh with colours): its albedo material.diffuse
// times `color` times the albedo texel (glTF 2.0 §3.9.2), its emission times the
// emission texel (§3.9.3; vertex colours do not tint it), and its metalness and
// perceptual roughness times the blue and green channels of the metallic/roughness
// texel where there is such a texture (§3.9.2). Without a texture the texel is white
// and the products exact. Twin of shading_material (src/texture.rs).
fn shading_material(material: Material, color: vec3<f32>, texels: array<vec3<f32>, 4>) -> Material {
    var shaded = material;
    shaded.diffuse = material.diffuse * color * texels[UV_SLOT_ALBEDO];
    shaded.emission = material.emission * texels[UV_SLOT_EMISSION];
    //#if TEXTURES
    if material.metallic_roughness_layer != NO_IMAGE {
        shaded.metallic = material.metallic * texels[UV_SLOT_METALLIC_ROUGHNESS].z;
        shaded.roughness = material.roughness * texels[UV_SLOT_METALLIC_ROUGHNESS].y;
    }
    //#endif
    return shaded;
}

// The shading normal at a hit with a normal map whose texel is `texel`
// (material_texels): `shading_normal` (N) turned by the tangent-space texel,
// normalize(T·x + B·y + N·z) with (x, y, z) = (2·texel - 1)·(scale, scale, 1), T the
// tangent made orthogonal to N, B = sign(w)·(N × T) (glTF 2.0 §3.9.3); shading_normal
// itself without a map or usable tangent, or where the result vanishes or leaves the
// side of the geometric normal `normal`. Twin of mapped_normal (src/texture.rs).
fn mapped_normal(material: Material, normal: vec3<f32>, shading_normal: vec3<f32>, tangent: vec4<f32>, texel: vec3<f32>) -> vec3<f32> {
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

// The emitted radiance at a point at `position` with geometric normal `normal` and mesh
// texture coordinates `uv` and `uv1`: material.emission, times the emission texture
// where there is one (glTF 2.0 §3.9.3: emissiveFactor times the texel), at its own
// coordinates; vertex colours do not tint it. Twin of shading_emission
// (src/texture.rs).
fn shading_emission(material: Material, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, uv1: vec2<f32>, footprint: ConeFootprint) -> vec3<f32> {
    //#if TEXTURES
    if material.emission_layer != NO_IMAGE {
        let st = texture_coordinates(material, UV_SLOT_EMISSION, position, normal, uv, uv1);
        let wrap = vec2<u32>(material.emission_wrap & 0xffu, (material.emission_wrap >> 8u) & 0xffu);
        return material.emission * texture_lookup_sample(material, UV_SLOT_EMISSION, material.emission_layer, material.emission_width,
                                               material.emission_height, st, wrap, footprint);
    }
    //#endif
    return material.emission;
}
