//! Texture coordinates and bilinear image lookups, below both tracers: the CPU
//! reference shades with them, and the light distributions of [`crate::accel`] weigh
//! textured emitters by [`mean_texel`]. The GPU twin is `shaders/texture.wgsl` (same
//! function names, `f64` arithmetic on the same `f32` texels).
//!
//! Conventions (also in `docs/materials.md`): texture coordinates `(u, v)` run from
//! the image's left edge to its right (`u`) and from its top row to its bottom (`v`);
//! texel `(x, y)` has its centre at `((x + ½)/W, (y + ½)/H)`. Albedo textures repeat;
//! BRDF maps are sampled on a corner-aligned grid and clamp.
//!
//! Filtering (`[render] texture_filtering`, docs/scene-format.md): every image has a
//! mip-map chain ([`mip_levels`]); surface textures are looked up trilinearly
//! ([`sample_texture_lod`]) at the level of detail of a ray cone's footprint
//! ([`texture_lod`], [`ConeFootprint`]; Akenine-Möller et al., "Improved Shader and
//! Texture Level of Detail Using Ray Cones", JCGT 10(1), 2021).

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::scene::{Image, Material, TextureMapping, TextureTransform, TextureWrap};

/// The footprint of a ray cone where it meets a surface: what [`texel_footprint`] needs
/// besides the texture. [`ConeFootprint::NONE`] (width 0) looks textures up at level 0,
/// bilinearly, as without filtering. Twin of `ConeFootprint` in
/// `shaders/texture.wgsl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConeFootprint {
    /// The cone's width at the hit, in scene units (0: no filtering).
    pub width: f64,
    /// `|n·d|`, the cosine between the ray and the geometric normal.
    pub cosine: f64,
    /// Texture-coordinate area over world area of the hit mesh triangle, per
    /// coordinate set (0 and 1); 0 where the hit has no such coordinates.
    pub uv_density: [f64; 2],
    /// The surface's unit geometric normal (as the shape defines it): planar
    /// mapping's tangent frame ([`tangent_frame`]).
    pub normal: DVec3,
    /// The unit direction in the surface along which the footprint is long
    /// ([`footprint_axis`]); zero where the ray meets the surface head-on.
    pub axis: DVec3,
    /// The change of the hit mesh triangle's texture coordinates per unit of world
    /// distance along `axis`, per coordinate set
    /// ([`crate::cpu::intersect::Hit::uv_axis`]); zero without such coordinates.
    pub uv_axis: [DVec2; 2],
    /// The most trilinear probes a lookup may take along the long axis: 1 is the
    /// isotropic trilinear lookup (`texture_filtering = "trilinear"`),
    /// [`crate::scene::MAX_TEXTURE_PROBES`] the anisotropic one.
    pub max_probes: u32,
}

impl ConeFootprint {
    /// No footprint: level 0, bilinear.
    pub const NONE: Self = Self {
        width: 0.0,
        cosine: 1.0,
        uv_density: [0.0; 2],
        normal: DVec3::Y,
        axis: DVec3::ZERO,
        uv_axis: [DVec2::ZERO; 2],
        max_probes: 1,
    };

    /// The footprint of a cone `width` wide where a ray along the unit `direction`
    /// meets a surface of unit geometric `normal` (either side), the hit triangle's
    /// [`crate::cpu::intersect::Hit::uv_density`] and
    /// [`crate::cpu::intersect::Hit::uv_axis`] being `uv_density` and `uv_axis`: the
    /// cosine is `|n·d|` (JCGT 10(1), 2021, §3, eq. 13's `|n̂·d̂|`), the long axis
    /// [`footprint_axis`]; isotropic (`max_probes` 1) until
    /// [`ConeFootprint::with_max_probes`]. Twin of `cone_footprint`.
    pub fn new(
        width: f64,
        direction: DVec3,
        normal: DVec3,
        uv_density: [f64; 2],
        uv_axis: [DVec2; 2],
    ) -> Self {
        Self {
            width,
            cosine: direction.dot(normal).abs(),
            uv_density,
            normal,
            axis: footprint_axis(direction, normal),
            uv_axis,
            max_probes: 1,
        }
    }

    /// This footprint looked up with at most `max_probes` probes.
    pub fn with_max_probes(self, max_probes: u32) -> Self {
        Self { max_probes, ..self }
    }
}

/// The unit direction in a surface of unit normal `normal` along which a ray cone
/// travelling along the unit `direction` leaves its longest trace: `d − n(n·d)`
/// normalised, the projection of the ray onto the surface (the major axis of the
/// cone's elliptical footprint; JCGT 10(1), 2021, §4, "anisotropic lookups"). Zero
/// for a ray along the normal, whose footprint is round. `shaders/intersect.wgsl`
/// (`triangle_hit`) and `shaders/texture.wgsl` (`cone_footprint`) compute it inline.
pub fn footprint_axis(direction: DVec3, normal: DVec3) -> DVec3 {
    (direction - normal * direction.dot(normal)).normalize_or_zero()
}

/// The scene's images with their mip-map chains and the footprint of the hit being
/// shaded: what the shading functions of this module read textures through.
#[derive(Debug, Clone, Copy)]
pub struct TextureLookup<'a> {
    /// Level 0 of every image (the scene's images).
    pub images: &'a [Image],
    /// Levels 1 and up of every image ([`mip_levels`]), parallel to `images`; empty
    /// (or shorter) means no levels beyond 0.
    pub levels: &'a [Vec<Image>],
    /// The ray cone's footprint at the hit.
    pub footprint: ConeFootprint,
}

impl<'a> TextureLookup<'a> {
    /// Level 0 only, no footprint: the bilinear lookups of an unfiltered render.
    pub fn unfiltered(images: &'a [Image]) -> Self {
        Self {
            images,
            levels: &[],
            footprint: ConeFootprint::NONE,
        }
    }

    /// Filtered lookup of image `index` at `(u, v)` for the texture whose coordinates
    /// `transform` makes ([`texel_footprint`], [`sample_texture_footprint`]).
    fn sample(
        &self,
        material: &Material,
        transform: &TextureTransform,
        index: u32,
        (u, v): (f64, f64),
        wrap: [TextureWrap; 2],
    ) -> DVec3 {
        let image = &self.images[index as usize];
        let levels = self
            .levels
            .get(index as usize)
            .map_or(&[][..], Vec::as_slice);
        let footprint = texel_footprint(material, transform, image, levels.len(), &self.footprint);
        sample_texture_footprint(image, levels, u, v, wrap, &footprint)
    }
}

/// The mip-map chain of `image` beyond level 0: level `k` is `max(1, ⌊w/2^k⌋) ×
/// max(1, ⌊h/2^k⌋)` (the sizes of OpenGL 4.6 §8.14.3 and of a wgpu texture's mip
/// levels, so that every image's level `k` fits in the GPU texture array's level `k`),
/// down to 1×1; `⌊log2(max(w, h))⌋` levels. Each level is the box filter of the one
/// above in linear float (all four channels): output texel `i` of an axis of `n → m`
/// texels averages the source interval `[i·n/m, (i+1)·n/m)`, texels weighted by their
/// overlap: the 2×2 box of Williams's pyramid ("Pyramidal Parametrics", SIGGRAPH
/// 1983) for even sizes; across an odd size `2m + 1` each output texel spans 2 + 1/m
/// source texels, the border ones in part, so no texel is dropped and the mean is
/// kept. Separable: columns first, then rows.
pub fn mip_levels(image: &Image) -> Vec<Image> {
    let mut levels: Vec<Image> = Vec::new();
    let mut current = image;
    while current.width > 1 || current.height > 1 {
        let next = downsample(current);
        levels.push(next);
        current = levels.last().expect("just pushed");
    }
    levels
}

/// The number of texels of an image of `width × height` with its mip-map chain
/// ([`mip_levels`]): about 4/3 of level 0.
pub fn mip_chain_texels(width: u32, height: u32) -> u64 {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let mut total = u64::from(w) * u64::from(h);
    while w > 1 || h > 1 {
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
        total += u64::from(w) * u64::from(h);
    }
    total
}

/// The overlap weights of source texels over output texel `i` of an axis of `n → m`
/// texels (see [`mip_levels`]): `(first source texel, weights)`, the weights summing
/// to 1.
fn box_weights(i: u32, n: u32, m: u32) -> (u32, Vec<f64>) {
    let scale = f64::from(n) / f64::from(m);
    let (start, end) = (f64::from(i) * scale, f64::from(i + 1) * scale);
    let first = start.floor() as u32;
    let last = (end.ceil() as u32).min(n);
    let weights = (first..last)
        .map(|j| {
            let overlap = end.min(f64::from(j + 1)) - start.max(f64::from(j));
            overlap.max(0.0) / scale
        })
        .collect();
    (first, weights)
}

/// One mip level below `image` ([`mip_levels`]).
fn downsample(image: &Image) -> Image {
    let (w, h) = (image.width, image.height);
    let (mw, mh) = ((w / 2).max(1), (h / 2).max(1));
    // Columns first: w × h → mw × h, in f64.
    let mut columns = vec![[0.0f64; 4]; mw as usize * h as usize];
    for x in 0..mw {
        let (first, weights) = box_weights(x, w, mw);
        for y in 0..h {
            let out = &mut columns[(y * mw + x) as usize];
            for (k, weight) in weights.iter().enumerate() {
                let t = image.texel(first + k as u32, y);
                for c in 0..4 {
                    out[c] += weight * f64::from(t[c]);
                }
            }
        }
    }
    let mut texels = vec![[0.0f32; 4]; mw as usize * mh as usize];
    for y in 0..mh {
        let (first, weights) = box_weights(y, h, mh);
        for x in 0..mw {
            let mut sum = [0.0f64; 4];
            for (k, weight) in weights.iter().enumerate() {
                let t = columns[((first + k as u32) * mw + x) as usize];
                for c in 0..4 {
                    sum[c] += weight * t[c];
                }
            }
            texels[(y * mw + x) as usize] = sum.map(|c| c as f32);
        }
    }
    Image {
        path: image.path.clone(),
        width: mw,
        height: mh,
        texels,
    }
}

/// The level of detail `λ` of a lookup of `image` (with `last_level` levels beyond
/// 0) for the texture whose coordinates `transform` makes, at a hit with `footprint`:
/// `λ = log2(w / |n·d|) + ½·log2(W·H·ρ)` (Akenine-Möller et al., JCGT 10(1), 2021,
/// §3, eqs. 13-14 with `Δ = ½·log2(t_a/p_a)` of Ray Tracing Gems ch. 20, eq. 34), `w`
/// the cone's width at the hit, `W × H` the image's size and `ρ` the texture-coordinate
/// area per world area: a mesh triangle's `|uv area| / |world area|` for UV mapping,
/// `1/scale²` for planar mapping, times `|det|` of the transform's linear part.
/// Spherical mapping, UV mapping off a mesh triangle and a zero width give level 0
/// (no filtering). Clamped to `[0, last_level]`; NaN gives 0. Twin of `texture_lod`
/// in `shaders/texture.wgsl`.
pub fn texture_lod(
    material: &Material,
    transform: &TextureTransform,
    image: &Image,
    last_level: usize,
    footprint: &ConeFootprint,
) -> f64 {
    if footprint.width <= 0.0 || last_level == 0 {
        return 0.0;
    }
    let mapping = match material.texture_mapping {
        TextureMapping::Uv => footprint.uv_density[(transform.set == 1) as usize],
        TextureMapping::Planar => 1.0 / (material.texture_scale * material.texture_scale),
        TextureMapping::Spherical => 0.0,
    };
    let [r0, r1] = transform.rows;
    let density = mapping * (r0.x * r1.y - r0.y * r1.x).abs();
    // Also catches a NaN density.
    if density.is_nan() || density <= 0.0 {
        return 0.0;
    }
    let texels = f64::from(image.width) * f64::from(image.height);
    let lambda = (footprint.width / footprint.cosine).log2() + 0.5 * (texels * density).log2();
    if lambda > 0.0 {
        lambda.min(last_level as f64)
    } else {
        0.0
    }
}

/// How a lookup covers a footprint in a texture ([`texel_footprint`]): `probes`
/// trilinear lookups at level of detail `lod`, spread evenly along `axis` (in texture
/// coordinates: the span of the probes, [`PROBE_SPAN`] times the footprint's long
/// axis) and centred on the looked-up point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexelFootprint {
    /// The level of detail of every probe, in `[0, last_level]`.
    pub lod: f64,
    /// The span of the probes in texture coordinates, [`PROBE_SPAN`] times the
    /// footprint's long axis (zero for one probe).
    pub axis: DVec2,
    /// How many probes, in `[1, max_probes]`.
    pub probes: u32,
}

/// The lookup of `image` (with `last_level` levels beyond 0) that covers `footprint`
/// for the texture whose coordinates `transform` makes. Isotropic (`max_probes` 1,
/// or no long axis in texture space): one probe at [`texture_lod`]. Anisotropic: the
/// footprint is `L = w/|n·d|` long along [`ConeFootprint::axis`] and `w` wide; in
/// texels its long axis is `a = J·axis·L` (`J` the texture coordinates' change per
/// world distance: planar mapping's `(axis·t, axis·b)/scale`, a mesh triangle's
/// [`ConeFootprint::uv_axis`], then the transform's linear part; times `W × H`) and
/// its width `b = w·L·W·H·ρ / |a|` (the area over the length, `ρ` as in
/// [`texture_lod`]). The probes cover `√2·a` ([`PROBE_SPAN`]), which their Gaussian
/// weights ([`sample_texture_footprint`]) taper: `N = round(√2·|a|/b)` probes, clamped
/// to `[1, max_probes]`, spaced `√2·a/N` apart, each at level `log2(max(√2·|a|/N, b))`
/// (clamped to `[0, last_level]`): probes along the major axis, each filtering its
/// share of it, as Feline does (McCormack et al., "Feline: Fast Elliptical Lines for
/// Anisotropic Texture Mapping", SIGGRAPH 1999; the ray cone's ellipse from
/// Akenine-Möller et al., JCGT 10(1), 2021). Twin of `texel_footprint` in
/// `shaders/texture.wgsl`.
pub fn texel_footprint(
    material: &Material,
    transform: &TextureTransform,
    image: &Image,
    last_level: usize,
    footprint: &ConeFootprint,
) -> TexelFootprint {
    let isotropic = TexelFootprint {
        lod: texture_lod(material, transform, image, last_level, footprint),
        axis: DVec2::ZERO,
        probes: 1,
    };
    if footprint.max_probes <= 1 || footprint.width <= 0.0 || last_level == 0 {
        return isotropic;
    }
    let (mapping, along) = match material.texture_mapping {
        TextureMapping::Uv => {
            let set = (transform.set == 1) as usize;
            (footprint.uv_density[set], footprint.uv_axis[set])
        }
        TextureMapping::Planar => {
            let (t, b) = tangent_frame(footprint.normal);
            let scale = material.texture_scale;
            (
                1.0 / (scale * scale),
                DVec2::new(footprint.axis.dot(t), footprint.axis.dot(b)) / scale,
            )
        }
        TextureMapping::Spherical => return isotropic,
    };
    let [r0, r1] = transform.rows;
    let density = mapping * (r0.x * r1.y - r0.y * r1.x).abs();
    let length = footprint.width / footprint.cosine;
    let axis = DVec2::new(
        r0.x * along.x + r0.y * along.y,
        r1.x * along.x + r1.y * along.y,
    ) * length;
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    let major = DVec2::new(axis.x * w, axis.y * h).length();
    let minor = footprint.width * length * w * h * density / major;
    let (axis, span) = (axis * PROBE_SPAN, major * PROBE_SPAN);
    // Not finite or not positive (a grazing ray, a degenerate mapping, NaN): the
    // isotropic lookup, which clamps such cases.
    if !(span > 0.0 && span.is_finite() && minor > 0.0 && minor.is_finite()) {
        return isotropic;
    }
    let probes = (span / minor)
        .round()
        .clamp(1.0, f64::from(footprint.max_probes)) as u32;
    let lod = (span / f64::from(probes)).max(minor).log2();
    TexelFootprint {
        lod: if lod > 0.0 {
            lod.min(last_level as f64)
        } else {
            0.0
        },
        axis: if probes > 1 { axis } else { DVec2::ZERO },
        probes,
    }
}

/// How far the probes of an anisotropic lookup reach along the footprint's long axis,
/// in footprint lengths: `√2` ([`texel_footprint`]), tapered by the Gaussian of
/// [`probe_weight`]. Measured, not derived: with the probes evenly weighted over the
/// footprint's length (a box along the axis, whose sharp ends alias) the whole-image
/// error of `scenes/bench/horizon-checker.toml` was 0.338 of the unfiltered one; with
/// the Gaussian over `√2·L` it is 0.324, and lower on `horizon-photo.toml` and
/// `horizon-fabric.toml` too (BENCHMARKS.md, "Filtered textures", with the other spans
/// and widths tried).
pub const PROBE_SPAN: f64 = std::f64::consts::SQRT_2;

/// The weight of the probe at `r ∈ (−1, 1)` along the span of an anisotropic lookup
/// (`r = ±1` at its ends): `e^{−2r²}`, the Gaussian of the elliptical weighted average
/// (Heckbert, "Fundamentals of Texture Mapping and Image Warping", 1989, §3.5.8;
/// pbrt-v4's `MIPMap::EWA`, α = 2), which falls to `e^{−2}` at the span's ends: a
/// standard deviation of `√2·L/4 = L/√8` for a footprint `L` long. Twin of
/// `probe_weight`.
pub fn probe_weight(r: f64) -> f64 {
    (-2.0 * r * r).exp()
}

/// The anisotropic lookup of `footprint` ([`texel_footprint`]) at `(u, v)`: its
/// probes' trilinear lookups ([`sample_texture_lod`]) at `(u, v) + axis·r_i/2`, `r_i =
/// 2·((i + ½)/N − ½)` for `i` in `[0, N)`, averaged with the weights
/// [`probe_weight`]`(r_i)`. Twin of `sample_texture_footprint`.
pub fn sample_texture_footprint(
    image: &Image,
    levels: &[Image],
    u: f64,
    v: f64,
    wrap: [TextureWrap; 2],
    footprint: &TexelFootprint,
) -> DVec3 {
    let n = footprint.probes.max(1);
    let (mut sum, mut total) = (DVec3::ZERO, 0.0);
    for i in 0..n {
        let r = 2.0 * ((f64::from(i) + 0.5) / f64::from(n) - 0.5);
        let weight = probe_weight(r);
        let at = DVec2::new(u, v) + footprint.axis * (0.5 * r);
        sum += sample_texture_lod(image, levels, at.x, at.y, wrap, footprint.lod) * weight;
        total += weight;
    }
    sum / total
}

/// Trilinear lookup at `(u, v)` and level of detail `lod` (in `[0, levels.len()]`,
/// [`texture_lod`]): the bilinear lookups ([`sample_texture`]) of levels `⌊lod⌋` and
/// `⌊lod⌋ + 1` mixed by the fraction of `lod` (Williams, "Pyramidal Parametrics",
/// 1983; OpenGL's `LINEAR_MIPMAP_LINEAR`). `lod = 0` is the bilinear lookup of level 0.
/// `levels` are levels 1 and up ([`mip_levels`]). Twin of `sample_texture_lod`.
pub fn sample_texture_lod(
    image: &Image,
    levels: &[Image],
    u: f64,
    v: f64,
    wrap: [TextureWrap; 2],
    lod: f64,
) -> DVec3 {
    let base = lod.floor();
    let i = (base as usize).min(levels.len());
    let fraction = lod - base;
    let lower = sample_texture_level(image, levels, i, u, v, wrap);
    if fraction > 0.0 && i < levels.len() {
        lower * (1.0 - fraction) + sample_texture_level(image, levels, i + 1, u, v, wrap) * fraction
    } else {
        lower
    }
}

/// [`sample_texture`] of mip level `level` (0: `image`; `k`: `levels[k − 1]`, in
/// `[0, levels.len()]`) of an image with its chain beyond level 0 in `levels`
/// ([`mip_levels`]). Twin of `sample_texture_level`.
pub fn sample_texture_level(
    image: &Image,
    levels: &[Image],
    level: usize,
    u: f64,
    v: f64,
    wrap: [TextureWrap; 2],
) -> DVec3 {
    let image = if level == 0 {
        image
    } else {
        &levels[level - 1]
    };
    sample_texture(image, u, v, wrap)
}

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
    textures: &TextureLookup,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> (f64, f64) {
    match material.metallic_roughness_texture {
        Some(index) => {
            let transform = &material.metallic_roughness_transform;
            let uv = texture_coordinates(material, transform, position, normal, uvs);
            let wrap = material.metallic_roughness_wrap;
            let texel = textures.sample(material, transform, index, uv, wrap);
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
    textures: &TextureLookup,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    color: DVec3,
) -> Material {
    let mut shaded = *material;
    shaded.diffuse = shading_albedo(material, textures, position, normal, uvs, color);
    (shaded.metallic, shaded.roughness) =
        shading_metallic_roughness(material, textures, position, normal, uvs);
    shaded.emission = shading_emission(material, textures, position, normal, uvs);
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
    textures: &TextureLookup,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
) -> DVec3 {
    match material.emission_texture {
        Some(index) => {
            let transform = &material.emission_transform;
            let uv = texture_coordinates(material, transform, position, normal, uvs);
            let wrap = material.emission_wrap;
            material.emission * textures.sample(material, transform, index, uv, wrap)
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
    textures: &TextureLookup,
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
    let uv = texture_coordinates(material, transform, position, normal, uvs);
    let texel = textures.sample(material, transform, index, uv, material.normal_wrap);
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
    textures: &TextureLookup,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    color: DVec3,
) -> DVec3 {
    let albedo = material.diffuse * color;
    match material.albedo_texture {
        Some(index) => {
            let transform = &material.texture_transform;
            let uv = texture_coordinates(material, transform, position, normal, uvs);
            let wrap = material.texture_wrap;
            albedo * textures.sample(material, transform, index, uv, wrap)
        }
        None => albedo,
    }
}

/// The alpha (coverage) at a hit at `position` with geometric normal `normal`, mesh
/// texture coordinates `uvs` (sets 0 and 1) and interpolated vertex-colour alpha
/// `vertex_alpha` (1 without vertex colours): `material.alpha` times `vertex_alpha`
/// times the alpha of the albedo texture `texture` (the material's `albedo_texture`,
/// if any) at the albedo's coordinates (glTF 2.0 §3.9.4: the base colour's alpha, of
/// which `COLOR_0` is a factor, §3.7.2.1).
pub fn shading_alpha(
    material: &Material,
    texture: Option<&Image>,
    position: DVec3,
    normal: DVec3,
    uvs: [DVec2; 2],
    vertex_alpha: f64,
) -> f64 {
    let alpha = material.alpha * vertex_alpha;
    match texture {
        Some(image) => {
            let transform = &material.texture_transform;
            let (u, v) = texture_coordinates(material, transform, position, normal, uvs);
            alpha * sample_texture_alpha(image, u, v, material.texture_wrap)
        }
        None => alpha,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MAX_TEXTURE_PROBES;

    /// A `width × height` image whose texel `(x, y)` is `f(x, y)` in every channel.
    fn image(width: u32, height: u32, f: impl Fn(u32, u32) -> f32) -> Image {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| [f(x, y); 4])
            .collect();
        Image {
            path: "<test>".into(),
            width,
            height,
            texels,
        }
    }

    fn mean(image: &Image) -> f64 {
        let sum: f64 = image.texels.iter().map(|t| f64::from(t[0])).sum();
        sum / image.texels.len() as f64
    }

    #[test]
    fn mip_levels_halve_down_to_one_texel_as_wgpu_sizes_them() {
        let sizes = |w, h| -> Vec<(u32, u32)> {
            mip_levels(&image(w, h, |_, _| 0.5))
                .iter()
                .map(|l| (l.width, l.height))
                .collect()
        };
        assert_eq!(sizes(8, 8), [(4, 4), (2, 2), (1, 1)]);
        assert_eq!(sizes(5, 3), [(2, 1), (1, 1)]);
        assert_eq!(sizes(16, 2), [(8, 1), (4, 1), (2, 1), (1, 1)]);
        assert_eq!(sizes(1, 7), [(1, 3), (1, 1)]);
        assert!(sizes(1, 1).is_empty());
        for (w, h) in [(8, 8), (5, 3), (16, 2), (1, 7), (1, 1), (640, 480)] {
            let levels = sizes(w, h);
            // ⌊log2(max(w, h))⌋ levels beyond 0: the count the shaders take.
            assert_eq!(levels.len() as u32, w.max(h).ilog2(), "{w}x{h}");
            // The texel count of the whole chain.
            let texels: u64 = levels.iter().map(|&(w, h)| u64::from(w * h)).sum();
            assert_eq!(mip_chain_texels(w, h), u64::from(w * h) + texels, "{w}x{h}");
        }
    }

    #[test]
    fn mip_levels_average_two_by_two_boxes_of_even_sizes() {
        // A one-texel checker averages to grey at level 1; a ramp to the mean of each
        // pair of columns.
        let checker = mip_levels(&image(4, 4, |x, y| ((x + y) % 2) as f32));
        assert!(checker[0].texels.iter().all(|t| t[0] == 0.5));
        let ramp = mip_levels(&image(4, 2, |x, _| x as f32));
        assert_eq!(ramp[0].texels, vec![[0.5; 4], [2.5; 4]]);
        assert_eq!(ramp[1].texels, vec![[1.5; 4]]);
    }

    #[test]
    fn mip_levels_keep_the_mean_of_odd_sizes_dropping_no_texel() {
        // 3 → 1 averages all three; 5 → 2 weighs each output's texels by their
        // overlap with its 2.5-texel interval (0.4, 0.4, 0.2 and 0.2, 0.4, 0.4).
        let three = mip_levels(&image(3, 1, |x, _| [0.0, 1.0, 4.0][x as usize]));
        assert!((three[0].texels[0][0] - 5.0 / 3.0).abs() < 1e-6);
        let five = mip_levels(&image(5, 1, |x, _| [1.0, 2.0, 4.0, 8.0, 16.0][x as usize]));
        let expected = [0.4 + 0.8 + 0.8, 0.8 + 3.2 + 6.4];
        for (texel, expected) in five[0].texels.iter().zip(expected) {
            assert!(
                (texel[0] - expected).abs() < 1e-5,
                "{texel:?} against {expected}"
            );
        }
        let odd = image(7, 5, |x, y| ((x * 7 + y * 3) % 11) as f32 / 10.0);
        for level in mip_levels(&odd) {
            assert!(
                (mean(&level) - mean(&odd)).abs() < 1e-6,
                "{}x{}",
                level.width,
                level.height
            );
        }
        // A single bright texel anywhere reaches the 1×1 level.
        for x in 0..7 {
            let spot = image(7, 1, |i, _| if i == x { 7.0 } else { 0.0 });
            let last = mip_levels(&spot).pop().expect("levels");
            assert!((last.texels[0][0] - 1.0).abs() < 1e-6, "texel {x}");
        }
    }

    fn planar_material(scale: f64) -> Material {
        Material {
            albedo_texture: Some(0),
            texture_mapping: TextureMapping::Planar,
            texture_scale: scale,
            ..Material::lambert(DVec3::ONE)
        }
    }

    #[test]
    fn texture_lod_is_log2_of_the_footprint_in_texels() {
        let material = planar_material(2.0);
        let transform = TextureTransform::IDENTITY;
        let image = image(64, 64, |_, _| 1.0);
        let lod = |width: f64, cosine: f64| {
            let footprint = ConeFootprint {
                width,
                cosine,
                ..ConeFootprint::NONE
            };
            texture_lod(&material, &transform, &image, 6, &footprint)
        };
        // 64 texels over 2 scene units: a footprint of 2/64·2^k units is level k.
        assert!((lod(2.0 / 64.0 * 4.0, 1.0) - 2.0).abs() < 1e-12);
        assert!((lod(2.0 / 64.0 * 5.0, 1.0) - 5f64.log2()).abs() < 1e-12);
        // At a grazing angle the footprint stretches by 1/cos.
        assert!((lod(2.0 / 64.0 * 4.0, 0.5) - 3.0).abs() < 1e-12);
        // Magnified, no cone or a grazing ray: clamped to [0, last level].
        assert_eq!(lod(2.0 / 64.0 * 0.5, 1.0), 0.0);
        assert_eq!(lod(0.0, 1.0), 0.0);
        assert_eq!(lod(1.0, 0.0), 6.0);
        assert_eq!(lod(1e9, 1.0), 6.0);
        // A UV-mapped texture reads the hit triangle's density, and a scaling
        // transform (4 repeats per unit of UV: 16 times the texels) moves it up 2.
        let uv = Material {
            texture_mapping: TextureMapping::Uv,
            ..material
        };
        let footprint = ConeFootprint {
            width: 1.0 / 64.0,
            cosine: 1.0,
            uv_density: [1.0, 0.0],
            ..ConeFootprint::NONE
        };
        let scaled = TextureTransform {
            set: 0,
            rows: [DVec3::new(4.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0)],
        };
        assert!(texture_lod(&uv, &transform, &image, 6, &footprint).abs() < 1e-12);
        assert!((texture_lod(&uv, &scaled, &image, 6, &footprint) - 2.0).abs() < 1e-12);
        // Set 1 has no coordinates on this hit: level 0.
        let set1 = TextureTransform {
            set: 1,
            ..transform
        };
        assert_eq!(texture_lod(&uv, &set1, &image, 6, &footprint), 0.0);
    }

    #[test]
    fn anisotropic_footprints_probe_along_the_long_axis_at_the_short_axis_level() {
        // A floor (n = +y) under planar mapping, 2 units per 64 texels, looked at
        // along +z at 60° from the normal: the footprint is w long across the view
        // (x) and w/cos = 2w along it (z, which is the mapping's v).
        let material = planar_material(2.0);
        let transform = TextureTransform::IDENTITY;
        let image = image(64, 64, |_, _| 1.0);
        let direction = DVec3::new(0.0, -0.5, 0.75f64.sqrt());
        let texel = 2.0 / 64.0;
        let at = |width: f64, max_probes: u32| {
            let footprint =
                ConeFootprint::new(width, direction, DVec3::Y, [0.0; 2], [DVec2::ZERO; 2])
                    .with_max_probes(max_probes);
            texel_footprint(&material, &transform, &image, 6, &footprint)
        };
        // 4 texels wide, 8 long: the probes span 8√2 = 11.3 texels along v (planar v
        // is p·b with b = t × n = -z... its sign is the frame's), none along u: 3
        // probes (11.3/4 rounded), each at the level of 4 texels (their spacing, 3.8
        // texels, is less).
        let anisotropic = at(4.0 * texel, MAX_TEXTURE_PROBES);
        assert_eq!(anisotropic.probes, 3);
        assert!((anisotropic.lod - 2.0).abs() < 1e-12, "{anisotropic:?}");
        assert!(anisotropic.axis.x.abs() < 1e-12);
        assert!((anisotropic.axis.y.abs() * 64.0 - 8.0 * PROBE_SPAN).abs() < 1e-9);
        // Isotropic: one probe at the long axis's level, as texture_lod says.
        let isotropic = at(4.0 * texel, 1);
        assert_eq!(isotropic.probes, 1);
        assert!((isotropic.lod - 3.0).abs() < 1e-12);
        // Magnified: level 0, still three probes across the footprint's length.
        let magnified = at(0.25 * texel, MAX_TEXTURE_PROBES);
        assert_eq!((magnified.lod, magnified.probes), (0.0, 3));
        // Head-on: round, one probe, the isotropic level.
        let head_on =
            ConeFootprint::new(4.0 * texel, -DVec3::Y, DVec3::Y, [0.0; 2], [DVec2::ZERO; 2])
                .with_max_probes(MAX_TEXTURE_PROBES);
        let round = texel_footprint(&material, &transform, &image, 6, &head_on);
        assert_eq!((round.lod, round.probes, round.axis), (2.0, 1, DVec2::ZERO));
        // Grazing (cos 0.01): 100 to 1, capped at 16 probes whose level covers their
        // share (a 16th of the span, √2 times the length), not the width.
        let grazing_direction = DVec3::new(0.0, -0.01, (1.0f64 - 1e-4).sqrt());
        let grazing = ConeFootprint::new(
            texel,
            grazing_direction,
            DVec3::Y,
            [0.0; 2],
            [DVec2::ZERO; 2],
        )
        .with_max_probes(MAX_TEXTURE_PROBES);
        let capped = texel_footprint(&material, &transform, &image, 6, &grazing);
        assert_eq!(capped.probes, MAX_TEXTURE_PROBES);
        assert!(
            (capped.lod - (100.0 * PROBE_SPAN / 16.0).log2()).abs() < 1e-6,
            "{capped:?}"
        );
    }

    #[test]
    fn anisotropic_probes_are_weighted_by_a_gaussian() {
        // Three probes one texel apart on texel centres of level 0 (r = -2/3, 0, 2/3),
        // only the last texel lit: its probe weighs e^{-2·(2/3)²} against the centre
        // probe's 1 (evenly weighted probes would give a third).
        let row = image(6, 1, |x, _| f32::from(x == 3));
        let levels = mip_levels(&row);
        let footprint = TexelFootprint {
            lod: 0.0,
            axis: DVec2::new(0.5, 0.0),
            probes: 3,
        };
        let wrap = [TextureWrap::Repeat; 2];
        let got = sample_texture_footprint(&row, &levels, 2.5 / 6.0, 0.5, wrap, &footprint).x;
        let outer = (-2.0f64 * 4.0 / 9.0).exp();
        assert!((got - outer / (1.0 + 2.0 * outer)).abs() < 1e-12, "{got}");
        assert_eq!(probe_weight(0.0), 1.0);
        assert!((probe_weight(1.0) - (-2.0f64).exp()).abs() < 1e-15);
        assert_eq!(probe_weight(-0.5), probe_weight(0.5));
    }

    #[test]
    fn trilinear_lookups_mix_the_two_nearest_levels() {
        // A one-texel checker: level 0 at a texel centre is its texel, level 1 grey.
        let checker = image(4, 4, |x, y| ((x + y) % 2) as f32);
        let levels = mip_levels(&checker);
        let wrap = [TextureWrap::Repeat; 2];
        let at = |lod: f64| sample_texture_lod(&checker, &levels, 0.375, 0.125, wrap, lod).x;
        assert_eq!(at(0.0), sample_texture(&checker, 0.375, 0.125, wrap).x);
        assert_eq!(at(0.0), 1.0);
        assert!((at(0.25) - 0.875).abs() < 1e-12);
        assert!((at(1.0) - 0.5).abs() < 1e-12);
        assert!((at(2.0) - 0.5).abs() < 1e-12);
        // Beyond the last level: the last level.
        assert_eq!(at(9.5), at(2.0));
    }

    #[test]
    fn an_unfiltered_lookup_is_the_bilinear_lookup_of_level_0() {
        let picture = image(5, 3, |x, y| (x * 3 + y) as f32 / 15.0);
        let images = [picture.clone()];
        let levels = [mip_levels(&picture)];
        let material = planar_material(1.0);
        let filtered = TextureLookup {
            images: &images,
            levels: &levels,
            footprint: ConeFootprint {
                width: 10.0,
                ..ConeFootprint::NONE
            },
        };
        for i in 0..50 {
            let p = DVec3::new(f64::from(i) * 0.137, 0.0, f64::from(i) * 0.071);
            let (u, v) = texture_coordinates(
                &material,
                &material.texture_transform,
                p,
                DVec3::Y,
                [DVec2::ZERO; 2],
            );
            let bilinear = sample_texture(&picture, u, v, material.texture_wrap);
            let unfiltered = TextureLookup::unfiltered(&images);
            let uvs = [DVec2::ZERO; 2];
            assert_eq!(
                shading_albedo(&material, &unfiltered, p, DVec3::Y, uvs, DVec3::ONE),
                bilinear
            );
            // The same lookup with no cone, levels or not.
            let no_cone = TextureLookup {
                footprint: ConeFootprint::NONE,
                ..filtered
            };
            assert_eq!(
                shading_albedo(&material, &no_cone, p, DVec3::Y, uvs, DVec3::ONE),
                bilinear
            );
            // A wide cone reads the 1×1 level: the mean.
            let far = shading_albedo(&material, &filtered, p, DVec3::Y, uvs, DVec3::ONE);
            let last = levels[0].last().expect("levels");
            assert!((far.x - f64::from(last.texels[0][0])).abs() < 1e-12);
        }
    }
}
