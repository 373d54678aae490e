//! Texture coordinates and bilinear image lookups, below both tracers: the CPU
//! reference shades with them, and the light distributions of [`crate::accel`] weigh
//! textured emitters by [`mean_texel`]. The GPU twin is `shaders/texture.wgsl` (same
//! function names, `f64` arithmetic on the same `f32` texels).
//!
//! Conventions (also in `docs/materials.md`): texture coordinates `(u, v)` run from
//! the image's left edge to its right (`u`) and from its top row to its bottom (`v`);
//! texel `(x, y)` has its centre at `((x + ½)/W, (y + ½)/H)`. Albedo textures repeat;
//! BRDF maps are sampled on a corner-aligned grid and clamp.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::scene::{Image, Material, TextureMapping, TextureTransform, TextureWrap};

/// Texture coordinates of a hit at `position` with unit geometric normal `normal`
/// (as the shape defines it, not flipped towards the ray) for a texture whose
/// coordinates `transform` describes, then transformed by it
/// ([`TextureTransform::apply`]).
///
/// - Spherical: longitude and latitude of the normal, which on a sphere is the
///   direction from its centre: `u = ½ - atan2(n.z, n.x)/(2π)`, `v = acos(n.y)/π`
///   (`v = 0` at the north pole, the seam `u = 0 = 1` on the −x side).
/// - Planar: the position projected on the tangent frame of the normal
///   ([`tangent_frame`]): `u = p·t / scale`, `v = p·b / scale`; on a floor with
///   `n = +y` that is `u = x / scale`, `v = z / scale`.
/// - UV: the hit's interpolated mesh texture coordinates of the set
///   `transform.set`: `uv` (set 0) or `uv1` (set 1), `(0, 0)` off a mesh.
pub fn texture_coordinates(
    material: &Material,
    transform: &TextureTransform,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> (f64, f64) {
    let mapped = match material.texture_mapping {
        TextureMapping::Uv => uvs[(transform.set == 1) as usize],
        TextureMapping::Spherical => {
            let y = normal.y.clamp(-1.0, 1.0);
            DVec2::new(0.5 - normal.z.atan2(normal.x) / (2.0 * PI), y.acos() / PI)
        }
        TextureMapping::Planar => {
            let (t, b) = tangent_frame(normal);
            DVec2::new(
                position.dot(t) / material.texture_scale,
                position.dot(b) / material.texture_scale,
            )
        }
    };
    transform.apply(mapped).into()
}

/// The tangent `t` and bitangent `b` of the planar mapping for unit normal `n`:
/// `t = normalize(n × a)`, `b = t × n`, with `a = z` if `|n.y| ≥ 0.999` else `y`.
pub fn tangent_frame(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.y.abs() >= 0.999 {
        DVec3::Z
    } else {
        DVec3::Y
    };
    let t = n.cross(a).normalize();
    (t, t.cross(n))
}

/// The texel index for the integer-valued texel coordinate `i` of an axis of `n`
/// texels under `wrap` (glTF 2.0, §3.8.4.4 "Samplers"): repeat takes `i mod n`,
/// mirrored repeat reflects every other period (`i mod 2n`, folded back), clamp holds
/// the edge texel. The modulo is taken in floating point, as the WGSL twin
/// `wrap_index` does (an integer conversion would saturate for huge coordinates); the
/// final clamp catches rounding up to the period.
pub fn wrap_index(i: f64, n: u32, wrap: TextureWrap) -> u32 {
    let m = f64::from(n);
    match wrap {
        TextureWrap::Repeat => ((i - m * (i / m).floor()) as u32).min(n - 1),
        TextureWrap::MirroredRepeat => {
            let period = 2.0 * m;
            let j = ((i - period * (i / period).floor()) as u32).min(2 * n - 1);
            if j >= n { 2 * n - 1 - j } else { j }
        }
        TextureWrap::ClampToEdge => i.clamp(0.0, m - 1.0) as u32,
    }
}

/// Bilinear lookup at texture coordinates `(u, v)` with the wrap modes `wrap` of the
/// two axes.
pub fn sample_texture(image: &Image, u: f64, v: f64, wrap: [TextureWrap; 2]) -> DVec3 {
    let (xs, ys, fx, fy) = footprint(image, u, v, wrap);
    bilinear(image, xs, ys, fx, fy)
}

/// [`sample_texture`] of the alpha channel: the same four texels and weights.
pub fn sample_texture_alpha(image: &Image, u: f64, v: f64, wrap: [TextureWrap; 2]) -> f64 {
    let ([xa, xb], [ya, yb], fx, fy) = footprint(image, u, v, wrap);
    let top = image_alpha(image, xa, ya) * (1.0 - fx) + image_alpha(image, xb, ya) * fx;
    let bottom = image_alpha(image, xa, yb) * (1.0 - fx) + image_alpha(image, xb, yb) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// The four texels a bilinear lookup at `(u, v)` reads (columns, rows) and the
/// weights `(fx, fy)` of the second of each.
fn footprint(
    image: &Image,
    u: f64,
    v: f64,
    wrap: [TextureWrap; 2],
) -> ([u32; 2], [u32; 2], f64, f64) {
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    let x = u * w - 0.5;
    let y = v * h - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xa, xb) = (
        wrap_index(x0, image.width, wrap[0]),
        wrap_index(x0 + 1.0, image.width, wrap[0]),
    );
    let (ya, yb) = (
        wrap_index(y0, image.height, wrap[1]),
        wrap_index(y0 + 1.0, image.height, wrap[1]),
    );
    ([xa, xb], [ya, yb], fx, fy)
}

/// The tabulated BRDF `f(θi, θr)` (per channel, in 1/sr) from a square map whose
/// texel `(x, y)` holds `π·f` at `θi = x/(N-1)·π/2` and `θr = y/(N-1)·π/2`
/// (a corner-aligned grid; bilinear between the four nearest samples, clamped).
/// Storing `π·f` makes a map of constant 1 a white Lambertian surface.
pub fn sample_brdf_map(image: &Image, theta_i: f64, theta_r: f64) -> DVec3 {
    let last = f64::from(image.width - 1);
    let x = (theta_i / FRAC_PI_2).clamp(0.0, 1.0) * last;
    let y = (theta_r / FRAC_PI_2).clamp(0.0, 1.0) * last;
    let (x0, y0) = (x.floor().min(last - 1.0), y.floor().min(last - 1.0));
    let (fx, fy) = (x - x0, y - y0);
    let (xa, ya) = (x0 as u32, y0 as u32);
    bilinear(image, [xa, xa + 1], [ya, ya + 1], fx, fy) / PI
}

/// The colour of texel (`x`, `y`) of `image`.
pub fn image_texel(image: &Image, x: u32, y: u32) -> DVec3 {
    let t = image.texel(x, y);
    DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]))
}

/// The alpha of texel (`x`, `y`) of `image` (its own alpha channel: 1 for images
/// without one).
pub fn image_alpha(image: &Image, x: u32, y: u32) -> f64 {
    f64::from(image.texel(x, y)[3])
}

fn bilinear(image: &Image, xs: [u32; 2], ys: [u32; 2], fx: f64, fy: f64) -> DVec3 {
    let texel = |x: u32, y: u32| image_texel(image, x, y);
    let top = texel(xs[0], ys[0]) * (1.0 - fx) + texel(xs[1], ys[0]) * fx;
    let bottom = texel(xs[0], ys[1]) * (1.0 - fx) + texel(xs[1], ys[1]) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// The metalness and perceptual roughness at a hit at `position` with geometric normal
/// `normal` and mesh texture coordinates `uvs` (sets 0 and 1): `material.metallic` and
/// `material.roughness`, times the blue and green channels of the metallic/roughness
/// texture where there is one (glTF 2.0 §3.9.2), at its own coordinates
/// (`metallic_roughness_transform`).
pub fn shading_metallic_roughness(
    material: &Material,
    images: &[Image],
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> (f64, f64) {
    match material.metallic_roughness_texture {
        Some(index) => {
            let transform = &material.metallic_roughness_transform;
            let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
            let image = &images[index as usize];
            let texel = sample_texture(image, u, v, material.metallic_roughness_wrap);
            (material.metallic * texel.z, material.roughness * texel.y)
        }
        None => (material.metallic, material.roughness),
    }
}

/// The material at a hit: [`shading_albedo`] as its albedo,
/// [`shading_metallic_roughness`] as its metalness and roughness, and
/// [`shading_emission`] as its emission. Twin of `shading_material` in
/// `shaders/texture.wgsl`.
pub fn shading_material(
    material: &Material,
    images: &[Image],
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    color: DVec3,
) -> Material {
    let mut shaded = *material;
    shaded.diffuse = shading_albedo(material, images, position, normal, uvs, color);
    (shaded.metallic, shaded.roughness) =
        shading_metallic_roughness(material, images, position, normal, uvs);
    shaded.emission = shading_emission(material, images, position, normal, uvs);
    shaded
}

/// The emitted radiance at a point at `position` with geometric normal `normal` and
/// mesh texture coordinates `uvs` (sets 0 and 1): `material.emission`, times the
/// emission texture where there is one (glTF 2.0 §3.9.3: the emissive colour is
/// `emissiveFactor` times the texel), at its own coordinates (`emission_transform`).
/// Vertex colours do not tint emission (glTF's `COLOR_0` multiplies the base colour
/// only). Every place that evaluates emission calls it: a ray's hit and the point
/// next-event estimation sampled on an emitter. Twin of `shading_emission` in
/// `shaders/texture.wgsl`.
pub fn shading_emission(
    material: &Material,
    images: &[Image],
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> DVec3 {
    match material.emission_texture {
        Some(index) => {
            let transform = &material.emission_transform;
            let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
            let image = &images[index as usize];
            material.emission * sample_texture(image, u, v, material.emission_wrap)
        }
        None => material.emission,
    }
}

/// The shading normal at a hit with a normal map: `shading_normal` (the interpolated
/// vertex normal `N`, unit, on the side of the geometric `normal`) turned by the
/// tangent-space texel of `material.normal_texture` at its own coordinates, `n =
/// normalize(T·x + B·y + N·z)` with `(x, y, z) = (2·texel − 1)·(scale, scale, 1)`
/// (glTF 2.0 §3.9.3, `normalTexture`), `T` the interpolated `tangent` made orthogonal
/// to `N` (Gram-Schmidt) and `B = sign(w)·(N × T)`. `shading_normal` itself without a
/// normal map, without a usable tangent (zero, or along `N`), or where the result
/// vanishes or leaves the geometric normal's side. Twin of `mapped_normal` in
/// `shaders/texture.wgsl`.
pub fn mapped_normal(
    material: &Material,
    images: &[Image],
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    shading_normal: DVec3,
    tangent: glam::DVec4,
) -> DVec3 {
    let Some(index) = material.normal_texture else {
        return shading_normal;
    };
    let along = tangent.truncate();
    let t = along - shading_normal * shading_normal.dot(along);
    let length_squared = t.length_squared();
    if length_squared.is_nan() || length_squared <= 0.0 {
        return shading_normal;
    }
    let t = t / length_squared.sqrt();
    let handedness = if tangent.w < 0.0 { -1.0 } else { 1.0 };
    let b = shading_normal.cross(t) * handedness;
    let transform = &material.normal_transform;
    let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
    let texel = sample_texture(&images[index as usize], u, v, material.normal_wrap);
    let scale = material.normal_scale;
    let m = DVec3::new(
        (2.0 * texel.x - 1.0) * scale,
        (2.0 * texel.y - 1.0) * scale,
        2.0 * texel.z - 1.0,
    );
    let mapped = t * m.x + b * m.y + shading_normal * m.z;
    let length_squared = mapped.length_squared();
    if length_squared.is_nan() || length_squared <= 0.0 {
        return shading_normal;
    }
    let mapped = mapped / length_squared.sqrt();
    if mapped.dot(normal) > 0.0 {
        mapped
    } else {
        shading_normal
    }
}

/// The mean texel of an image (per channel, over every texel): the mean of a texture
/// over its whole area. Next-event estimation picks a textured emitter by its material's
/// emission times this mean ([`crate::accel::AreaLights`]): the power of the emitter if
/// its UVs cover the image once uniformly, and an unbiased choice whatever they are
/// (the sampled point's own texel weights its contribution).
pub fn mean_texel(image: &Image) -> DVec3 {
    let sum = image.texels.iter().fold(DVec3::ZERO, |sum, t| {
        sum + DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]))
    });
    sum / image.texels.len().max(1) as f64
}

/// The albedo at a hit at `position` with geometric normal `normal`, mesh texture
/// coordinates `uvs` (sets 0 and 1) and vertex colour `color` (white off a mesh with
/// colours): `material.diffuse` times `color` (glTF 2.0 §3.9.2: `COLOR_0` multiplies
/// the base colour), times the albedo texture where there is one.
pub fn shading_albedo(
    material: &Material,
    images: &[Image],
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    color: DVec3,
) -> DVec3 {
    let albedo = material.diffuse * color;
    match material.albedo_texture {
        Some(index) => {
            let transform = &material.texture_transform;
            let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
            let image = &images[index as usize];
            albedo * sample_texture(image, u, v, material.texture_wrap)
        }
        None => albedo,
    }
}

/// The alpha (coverage) at a hit at `position` with geometric normal `normal` and mesh
/// texture coordinates `uvs` (sets 0 and 1): `material.alpha` times the alpha of the
/// albedo texture `texture` (the material's `albedo_texture`, if any) at the albedo's
/// coordinates (glTF 2.0 §3.9.4: the base colour's alpha). Vertex colours do not
/// contribute (their alpha is not kept).
pub fn shading_alpha(
    material: &Material,
    texture: Option<&Image>,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> f64 {
    match texture {
        Some(image) => {
            let transform = &material.texture_transform;
            let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
            material.alpha * sample_texture_alpha(image, u, v, material.texture_wrap)
        }
        None => material.alpha,
    }
}
