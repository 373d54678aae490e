//! The Whitted tracer with an explicit bounce stack: the CPU twin of
//! `shaders/trace.wgsl` (same function names) and of the slots of
//! `shaders/wavefront.wgsl` (the same stack discipline, so the two agree even when a
//! small stack drops branches).

use glam::DVec3;

use super::bxdf::{eval_brdf, has_base_brdf, reflect_direction, surface_response};
use super::coverage::BlendRule;
use super::intersect::{
    Hit, MAX_PASS_THROUGHS, Ray, culls_back_face, offset_ray_origin, shadow_terminator_point,
};
use super::path::path_radiance;
use super::traverse::{intersect_scene, transmittance};
use crate::accel::SceneGeometry;
use crate::accel::{AreaLights, BrdfMapCdfs, EnvironmentLight};
use crate::camera::{CameraFrame, PixelCone, SamplePattern, lens_sample};
use crate::noise::luminance_m2_step;
pub use crate::scene::MediumStack;
use crate::scene::{AlphaMode, Image, Integrator, Light, Material, RenderSettings, Scene};
use crate::texture::{
    ConeFootprint, TextureLookup, mapped_normal, mip_levels, shading_alpha, shading_material,
};

/// The scene in the form the tracer reads: colours in the lighting space, the geometry
/// with its BVH, the camera basis.
#[derive(Debug, Clone)]
pub struct PreparedScene {
    /// Sampling and depth settings.
    pub settings: RenderSettings,
    /// The camera basis.
    pub camera: CameraFrame,
    /// Where each sample lies in its pixel.
    pub samples: SamplePattern,
    /// Radiance of escaping rays without an environment map.
    pub background: DVec3,
    /// The environment map, with its sampling distribution for the path integrator:
    /// the radiance of escaping rays by direction.
    pub environment: Option<EnvironmentLight>,
    /// Whitted ambient radiance.
    pub ambient: DVec3,
    /// Materials in the lighting space.
    pub materials: Vec<Material>,
    /// Lights.
    pub lights: Vec<Light>,
    /// The primitives and the BVH over them (shared with the GPU backend).
    pub geometry: SceneGeometry,
    /// The dielectrics around the camera ([`Scene::camera_medium`]).
    pub camera_medium: MediumStack,
    /// Albedo textures and BRDF maps.
    pub images: Vec<Image>,
    /// The mip-map levels beyond 0 of every image ([`mip_levels`]), parallel to
    /// `images`; empty without texture filtering.
    pub image_levels: Vec<Vec<Image>>,
    /// A camera ray's cone ([`CameraFrame::pixel_cone`]); zero (no footprint, level 0
    /// lookups) without texture filtering.
    pub cone: PixelCone,
    /// The emissive shapes the path integrator samples.
    pub area_lights: AreaLights,
    /// The inverse-CDF tables of the BRDF maps, which the path integrator samples
    /// tabulated materials by.
    pub brdf_map_cdfs: BrdfMapCdfs,
}

impl PreparedScene {
    /// Prepares a validated scene, building its geometry and BVH.
    pub fn new(scene: &Scene) -> Self {
        Self::with_geometry(scene, SceneGeometry::new(scene))
    }

    /// Prepares a validated scene with geometry already built from it (for example
    /// the one the GPU backend uploaded, so both trace the same tree).
    pub fn with_geometry(scene: &Scene, geometry: SceneGeometry) -> Self {
        let scene = scene.in_lighting_space();
        let (area_lights, brdf_map_cdfs) = match scene.render.integrator {
            Integrator::Path => (
                AreaLights::new(&geometry, &scene.materials, &scene.images),
                BrdfMapCdfs::new(&scene.images, &scene.materials),
            ),
            Integrator::Whitted => (AreaLights::default(), BrdfMapCdfs::default()),
        };
        let camera = CameraFrame::new(&scene.camera, scene.render.width, scene.render.height);
        let (image_levels, cone) = if scene.render.texture_filtering.filters() {
            (
                scene.images.iter().map(mip_levels).collect(),
                camera.pixel_cone(scene.render.height, scene.render.samples_per_pixel),
            )
        } else {
            (Vec::new(), PixelCone::default())
        };
        let mut prepared = Self {
            settings: scene.render,
            camera,
            samples: SamplePattern::new(&scene.render),
            background: scene.environment.background,
            environment: scene
                .environment
                .map
                .clone()
                .map(|map| EnvironmentLight::new(map, !area_lights.is_empty())),
            ambient: scene.environment.ambient,
            materials: scene.materials.clone(),
            lights: scene.lights.clone(),
            geometry,
            camera_medium: MediumStack::from_outermost_first(&scene.camera_medium()),
            images: Vec::new(),
            image_levels,
            cone,
            area_lights,
            brdf_map_cdfs,
        };
        // The lighting space's own copy of the images is moved, not copied again.
        prepared.images = match scene {
            std::borrow::Cow::Owned(scene) => scene.images,
            std::borrow::Cow::Borrowed(scene) => scene.images.clone(),
        };
        prepared
    }

    /// The scene's textures looked up at `footprint` (filtered as the scene's
    /// `texture_filtering` says: [`crate::texture::texel_footprint`] with its probe
    /// limit).
    pub fn textures(&self, footprint: ConeFootprint) -> TextureLookup<'_> {
        TextureLookup {
            images: &self.images,
            levels: &self.image_levels,
            footprint: footprint.with_max_probes(self.settings.texture_filtering.max_probes()),
        }
    }

    /// The width at `hit` of a ray cone `width` wide at the ray's origin: `width +
    /// spread·t` (JCGT 10(1), 2021, §3: a cone's width grows linearly along the ray;
    /// the ray's direction is a unit vector, so `t` is the distance).
    pub fn cone_width_at(&self, width: f64, hit: &Hit) -> f64 {
        width + self.cone.spread * hit.t
    }

    /// The camera ray of sample `index` of pixel (`x`, `y`), at `offset` inside the
    /// pixel ([`SamplePattern::offset`]), through the lens point [`lens_sample`]
    /// picks for it ([`CameraFrame::camera_ray`]).
    pub fn camera_ray(&self, x: u32, y: u32, index: u32, offset: (f64, f64)) -> Ray {
        let (width, height) = (self.settings.width, self.settings.height);
        let lens = lens_sample(
            y.wrapping_mul(width).wrapping_add(x),
            self.settings.samples_per_pixel,
            index,
        );
        let (origin, direction) = self.camera.camera_ray(
            f64::from(x) + offset.0,
            f64::from(y) + offset.1,
            width,
            height,
            lens,
        );
        Ray { origin, direction }
    }
}

/// Squared distances to a point light below this (the smallest normal `f32`, 2^-126)
/// contribute nothing: at zero or denormal distance `I / r²` is infinite or NaN in
/// `f32`, and the light is inside the surface it would light. Both backends use the
/// same threshold.
pub const MIN_LIGHT_DISTANCE_SQUARED: f64 = f32::MIN_POSITIVE as f64;

/// Branch weights (largest channel) at or below this, the smallest normal `f32`
/// (2^-126), are not traced, whatever the cutoff: the GPU's `f32` weights cannot hold
/// less (most GPUs flush such denormals to zero), and such a branch adds nothing any
/// image format can show. Both backends use the same floor, so that deep glass, whose
/// inner reflections shrink a weight by about 0.04 each, traces the same rays on both.
pub const MIN_BRANCH_WEIGHT: f64 = f32::MIN_POSITIVE as f64;

/// Whether a radiance value is finite and stays finite when rounded to `f32`: the
/// final guard of [`trace_radiance`]. A contribution that fails it (an overflowing
/// product, a NaN from some unforeseen 0·∞) is dropped rather than allowed to poison
/// the pixel; the GPU twin `finite_radiance` tests the `f32` exponent bits, which no
/// compiler's fast-math assumptions can fold away.
pub fn finite_radiance(c: DVec3) -> bool {
    // Written per component: a NaN fails each comparison (glam's max_element would
    // skip it).
    let limit = f64::from(f32::MAX);
    c.x.abs() <= limit && c.y.abs() <= limit && c.z.abs() <= limit
}

/// Adds a contribution to `radiance` when it is [`finite_radiance`].
pub fn add_contribution(radiance: &mut DVec3, contribution: DVec3) {
    if finite_radiance(contribution) {
        *radiance += contribution;
    }
}

/// The radiance a ray escaping along the unit `direction` sees: the environment map's
/// texel times its scale, or the constant background.
pub fn background_radiance(scene: &PreparedScene, direction: DVec3) -> DVec3 {
    match &scene.environment {
        Some(environment) => environment.map.radiance(direction),
        None => scene.background,
    }
}

/// One pending ray on the bounce stack.
#[derive(Debug, Clone, Copy)]
struct StackEntry {
    ray: Ray,
    /// Product of the weights of the bounces that led here.
    weight: DVec3,
    /// Bounces since the primary ray.
    depth: u32,
    /// The dielectrics the ray travels inside.
    medium: MediumStack,
    /// The ray cone's width at the ray's origin (its spread is the camera's,
    /// [`PreparedScene::cone`]).
    cone_width: f64,
}

/// Radiance and ray count of one pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelResult {
    /// Mean radiance over the pixel's samples.
    pub radiance: DVec3,
    /// Rays traced for this pixel.
    pub rays: u64,
    /// Welford's sum of squared deviations of the samples' luminance
    /// ([`crate::noise::luminance_m2_step`]), for the pixel's noise estimate.
    pub luminance_m2: f64,
}

/// Traces every sample of pixel (`x`, `y`) and averages them (box filter).
pub fn trace_pixel(scene: &PreparedScene, x: u32, y: u32) -> PixelResult {
    let settings = &scene.settings;
    let mut sum = DVec3::ZERO;
    let mut luminance_m2 = 0.0;
    let mut rays = 0;
    for index in 0..settings.samples_per_pixel {
        let (dx, dy) = scene.samples.offset(x, y, index);
        let primary = scene.camera_ray(x, y, index, (dx, dy));
        let (radiance, sample_rays) = match settings.integrator {
            Integrator::Whitted => trace_radiance(scene, primary),
            Integrator::Path => path_radiance(scene, primary, y * settings.width + x, index),
        };
        let before = sum;
        sum += radiance;
        luminance_m2 = luminance_m2_step(
            luminance_m2,
            before,
            sum,
            crate::color::luminance(radiance),
            index,
        );
        rays += sample_rays;
    }
    let radiance = sum / f64::from(settings.samples_per_pixel);
    PixelResult {
        // The sum of finite contributions may still overflow: the pixel is then black
        // (and on both backends alike, since the GPU's f32 overflows first).
        radiance: if finite_radiance(radiance) {
            radiance
        } else {
            DVec3::ZERO
        },
        rays,
        luminance_m2,
    }
}

/// Radiance arriving along `primary`, traced iteratively: every reflected or refracted
/// ray is pushed on a stack of `stack_size` entries and popped until none is left.
/// Returns the radiance and the number of rays traced (camera, shadow and secondary).
/// Each contribution (background or shaded hit, times the path weight) is added only
/// when [`finite_radiance`]; no NaN or infinity reaches the image.
pub fn trace_radiance(scene: &PreparedScene, primary: Ray) -> (DVec3, u64) {
    let capacity = scene.settings.stack_size as usize;
    let cutoff = scene.settings.min_ray_weight.max(MIN_BRANCH_WEIGHT);
    let mut stack: Vec<StackEntry> = Vec::with_capacity(capacity);
    stack.push(StackEntry {
        ray: primary,
        weight: DVec3::ONE,
        depth: 0,
        medium: scene.camera_medium,
        cone_width: scene.cone.width,
    });
    let mut radiance = DVec3::ZERO;
    let mut rays = 0u64;
    let mut passes = 0u32;
    while let Some(entry) = stack.pop() {
        rays += 1;
        let Some(hit) = intersect_scene(&scene.geometry, &entry.ray, f64::INFINITY) else {
            add_contribution(
                &mut radiance,
                entry.weight * background_radiance(scene, entry.ray.direction),
            );
            continue;
        };
        let material = &scene.materials[hit.material as usize];
        // Every ray spawned here (through, reflected, refracted) starts as wide as the
        // cone is here, and keeps the spread: the specular bounces of JCGT 10(1), 2021,
        // §3 without the curvature term.
        let cone_width = scene.cone_width_at(entry.cone_width, &hit);
        if passes < MAX_PASS_THROUGHS
            && culls_back_face(
                material.cull_back_faces,
                entry.depth,
                entry.ray.direction,
                hit.normal,
            )
        {
            passes += 1;
            let origin = offset_ray_origin(hit.position, hit.normal, scene.geometry.offset_scale);
            stack.push(StackEntry {
                ray: Ray {
                    origin,
                    ..entry.ray
                },
                cone_width,
                ..entry
            });
            continue;
        }
        // A blended surface stops the fraction alpha of the light: its shading and
        // branches are weighted by alpha, and the ray goes on through it, unbent,
        // with weight 1 − alpha (one bounce deeper, pushed first so it is traced
        // last).
        let mut entry = entry;
        if material.alpha_mode == AlphaMode::Blend {
            let alpha = blend_alpha(scene, material, &hit);
            if alpha < 1.0 && entry.depth < scene.settings.max_depth {
                let weight = entry.weight * (1.0 - alpha);
                if weight.max_element() > cutoff && stack.len() < capacity {
                    let beyond = if entry.ray.direction.dot(hit.normal) > 0.0 {
                        hit.normal
                    } else {
                        -hit.normal
                    };
                    let origin =
                        offset_ray_origin(hit.position, beyond, scene.geometry.offset_scale);
                    stack.push(StackEntry {
                        ray: Ray {
                            origin,
                            ..entry.ray
                        },
                        weight,
                        depth: entry.depth + 1,
                        medium: entry.medium,
                        cone_width,
                    });
                }
            }
            entry.weight *= alpha;
        }
        let footprint = hit.footprint(cone_width, entry.ray.direction);
        let shaded = shade_hit(scene, &entry.ray, &hit, &entry.medium, footprint);
        add_contribution(&mut radiance, entry.weight * shaded.radiance);
        rays += shaded.shadow_rays;
        if entry.depth >= scene.settings.max_depth {
            continue;
        }
        // Refraction is pushed first so that reflection is traced first; a branch that
        // finds the stack full, or carries no more than the weight cutoff, is dropped
        // (both backends do the same).
        let branches = [
            (shaded.transmitted, shaded.transmitted_medium),
            (shaded.reflected, entry.medium),
        ];
        for ((weight, ray), medium) in branches {
            let weight = entry.weight * weight;
            if weight.max_element() > cutoff && stack.len() < capacity {
                stack.push(StackEntry {
                    ray,
                    weight,
                    depth: entry.depth + 1,
                    medium,
                    cone_width,
                });
            }
        }
    }
    (radiance, rays)
}

/// The alpha of a blended `material` at `hit` ([`shading_alpha`]), clamped to [0, 1]:
/// the fraction of light the surface stops. Twin of `blend_alpha` in
/// `shaders/trace.wgsl`.
pub fn blend_alpha(scene: &PreparedScene, material: &Material, hit: &Hit) -> f64 {
    let texture = material
        .albedo_texture
        .and_then(|i| scene.images.get(i as usize));
    shading_alpha(
        material,
        texture,
        hit.position,
        hit.normal,
        [hit.uv, hit.uv1],
        hit.color.w,
    )
    .clamp(0.0, 1.0)
}

/// What shading one hit produced.
#[derive(Debug, Clone, Copy)]
pub struct ShadedHit {
    /// Emitted plus directly lit (and ambient) radiance leaving the hit towards the eye.
    pub radiance: DVec3,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// Weight and ray of the reflected branch (weight zero when there is none).
    pub reflected: (DVec3, Ray),
    /// Weight and ray of the refracted branch (weight zero when there is none).
    pub transmitted: (DVec3, Ray),
    /// The medium stack of the refracted ray.
    pub transmitted_medium: MediumStack,
}

/// The normal a hit is shaded with, on the side the ray came from: the interpolated
/// shading normal `ns` of a smooth mesh, tilted towards the viewer where the ray would
/// arrive behind it (near a coarse mesh's silhouette, where `ns` turns away while the
/// real surface `ng` still faces the ray): `normalize(ns + (c_min - wo·ns)·wo)` with
/// `wo = -direction` and `c_min` = [`MIN_SECONDARY_COSINE`], so that `wo` is just
/// above it. Both steps are continuous, so no facet edge shows where a hard switch to
/// `ng` would draw one; shading normals are not physical (Veach's thesis, 1997, §5.3),
/// and this keeps them plausible. The normal is then turned towards `ng` just enough
/// that the mirror reflection about it leaves the real surface
/// ([`valid_reflection_normal`]), so that a steep normal map on a polished surface
/// reflects its surroundings instead of sending its reflection, and the BRDF samples
/// around it, into the surface. Secondary rays that the result would still send
/// through the real surface are bent back by [`keep_on_side`].
pub fn shading_frame_normal(direction: DVec3, ng: DVec3, ns: DVec3) -> DVec3 {
    if ns == ng {
        return ng;
    }
    let wo = -direction;
    let cosine = wo.dot(ns);
    let n = if cosine >= MIN_SECONDARY_COSINE {
        ns
    } else {
        (ns + wo * (MIN_SECONDARY_COSINE - cosine)).normalize()
    };
    valid_reflection_normal(wo, ng, n)
}

/// The largest height above the geometric surface that [`valid_reflection_normal`]
/// asks of a mirror reflection: a hundredth of the unit direction (about 0.6 degrees),
/// less for grazing views.
pub const MIN_REFLECTION_HEIGHT: f64 = 0.01;

/// The shading normal `n` turned towards the geometric normal `ng` (the side `wo`
/// arrives from, `wo·ng > 0`) by the least angle for which the mirror reflection of
/// `wo` about it, `r = 2(n·wo)n - wo`, rises above the surface: `r·ng >= h` with
/// `h = min(0.9·wo·ng, MIN_REFLECTION_HEIGHT)` (a reflection may always be as shallow
/// as the ray that arrives). `n` itself where its reflection already does. The idea is
/// Blender Cycles' valid specular reflection (`ensure_valid_specular_reflection`,
/// `intern/cycles/kernel/closure/bsdf_util.h`); the solution here is worked out
/// directly: in the plane of `ng` and `n`, with `x` the unit part of `n` across `ng`,
/// `n' = sin θ·x + cos θ·ng` reflects `wo` to a height `a·sin 2θ + b·cos 2θ` with
/// `a = wo·x`, `b = wo·ng`, that is `ρ·cos(2θ - α)` with `ρ = |(a, b)|` and
/// `α = atan2(a, b)`; it is at least `b >= h` at `θ = 0` and below `h` at `n`, so the
/// largest `θ` that reaches `h` is `(α + acos(h/ρ))/2`. GPU twin: valid_reflection_normal.
pub fn valid_reflection_normal(wo: DVec3, ng: DVec3, n: DVec3) -> DVec3 {
    let b = wo.dot(ng);
    let height = (0.9 * b).min(MIN_REFLECTION_HEIGHT);
    let reflected = 2.0 * n.dot(wo) * n - wo;
    if reflected.dot(ng) >= height {
        return n;
    }
    let across = n - n.dot(ng) * ng;
    let length = across.length();
    if length.is_nan() || length <= 0.0 {
        return ng;
    }
    let x = across / length;
    let a = wo.dot(x);
    let rho = (a * a + b * b).sqrt();
    // The angle of `n` from `ng`: the turn never goes past it.
    let theta_n = length.atan2(n.dot(ng));
    let theta = (0.5 * (a.atan2(b) + (height / rho).clamp(-1.0, 1.0).acos())).clamp(0.0, theta_n);
    theta.sin() * x + theta.cos() * ng
}

/// The least cosine to the geometric surface that a bent secondary ray keeps
/// ([`keep_on_side`]): about 0.06 degrees off the surface.
pub const MIN_SECONDARY_COSINE: f64 = 1e-3;

/// A secondary ray's unit direction `d`, computed about a shading normal, kept on the
/// side of the geometric surface that `side` (a unit normal) points to: unchanged when
/// it leaves that side at a cosine of at least [`MIN_SECONDARY_COSINE`], otherwise
/// pulled towards `side` until it does, `normalize(d + (c_min - d·side)·side)`. This is
/// the bent reflection of Keller et al., "The Iray Light Transport Simulation and
/// Rendering System" (2017), on shading normals: continuous in `d`, so a smooth-shaded
/// mirror or glass mesh shows no seam where `ns` would have sent the ray inside.
pub fn keep_on_side(d: DVec3, side: DVec3) -> DVec3 {
    let cosine = d.dot(side);
    if cosine >= MIN_SECONDARY_COSINE {
        return d;
    }
    (d + side * (MIN_SECONDARY_COSINE - cosine)).normalize()
}

/// Shades `hit` for a ray travelling along `ray.direction`: emission, ambient and
/// direct light with one shadow ray per light, and the secondary rays, for a ray
/// travelling inside the dielectrics of `medium`. Every new ray starts at the
/// re-projected hit point moved off the surface by [`offset_ray_origin`], to the side
/// the ray leaves on (shadow rays of smooth meshes from [`shadow_terminator_point`]).
/// Which side the ray enters is decided by the geometric normal; the BRDF, the mirror
/// direction and refraction use [`shading_frame_normal`]. Textures are looked up at
/// the ray cone's `footprint` ([`PreparedScene::textures`]).
pub fn shade_hit(
    scene: &PreparedScene,
    ray: &Ray,
    hit: &Hit,
    medium: &MediumStack,
    footprint: ConeFootprint,
) -> ShadedHit {
    let position = hit.position;
    let textures = scene.textures(footprint);
    let material = shading_material(
        &scene.materials[hit.material as usize],
        &textures,
        position,
        hit.normal,
        [hit.uv, hit.uv1],
        hit.color.truncate(),
    );
    let material = &material;
    let entering = ray.direction.dot(hit.normal) < 0.0;
    // Shading happens on the side the ray came from.
    let ng = if entering { hit.normal } else { -hit.normal };
    let outside_ior = medium.medium_outside_ior(entering);
    let mapped = mapped_normal(
        &scene.materials[hit.material as usize],
        &textures,
        position,
        hit.normal,
        [hit.uv, hit.uv1],
        hit.shading_normal,
        hit.tangent,
    );
    let ns = if entering { mapped } else { -mapped };
    let n = shading_frame_normal(ray.direction, ng, ns);
    let wo = -ray.direction;
    let mut response = surface_response(material, ray.direction, n, entering, outside_ior);
    let mut reflect = reflect_direction(ray.direction, n).normalize();
    if n != ng {
        reflect = keep_on_side(reflect, ng);
        response.transmit_direction = keep_on_side(response.transmit_direction, -ng);
    }

    let mut radiance = material.emission;
    let mut shadow_rays = 0;
    if has_base_brdf(material.kind) && response.base > 0.0 {
        let mut direct = material.diffuse * scene.ambient;
        let lifted = shadow_terminator_point(&scene.geometry, hit, ng);
        let shadow_origin = offset_ray_origin(lifted, ng, scene.geometry.offset_scale);
        for light in &scene.lights {
            let (lit, traced) = direct_light(
                scene,
                light,
                material,
                shadow_origin,
                n,
                wo,
                BlendRule::Transmit,
            );
            direct += lit;
            shadow_rays += traced;
        }
        radiance += direct * response.base;
    }

    let reflected = Ray {
        origin: offset_ray_origin(position, ng, scene.geometry.offset_scale),
        direction: reflect,
    };
    let transmitted = Ray {
        origin: offset_ray_origin(position, -ng, scene.geometry.offset_scale),
        direction: response.transmit_direction,
    };
    ShadedHit {
        radiance,
        shadow_rays,
        reflected: (response.reflect, reflected),
        transmitted: (response.transmit, transmitted),
        transmitted_medium: medium.medium_after_refraction(entering, material.ior),
    }
}

/// Reflected radiance due to one light: `f(wi, wo) · E · cos θ_i` (the BRDF and the
/// cosine taken about the shading normal `n`) times the transmittance of the shadow
/// ray from `origin` towards the light, whose blended surfaces `blend` treats
/// ([`transmittance`]: 0 when an opaque surface blocks it). Returns it and the number of shadow rays traced (0 when the
/// light is below the shading normal). A light below a smooth mesh's flat triangle but
/// above its shading normal (`ng·wi < 0 < n·wi`, near the shadow terminator) is lit
/// when its shadow ray, which starts at the lifted point of [`shadow_terminator_point`],
/// reaches it: the mesh itself decides, so the terminator follows the smooth surface
/// instead of the facets (Hanika 2021). It can pass at most as far below `ng` as `n`
/// leans from it.
pub fn direct_light(
    scene: &PreparedScene,
    light: &Light,
    material: &Material,
    origin: DVec3,
    n: DVec3,
    wo: DVec3,
    blend: BlendRule,
) -> (DVec3, u64) {
    let Some(sample) = sample_light(light, origin, n) else {
        return (DVec3::ZERO, 0);
    };
    let shadow = Ray {
        origin,
        direction: sample.wi,
    };
    let passed = transmittance(&scene.geometry, &shadow, sample.distance, blend);
    if passed <= 0.0 {
        return (DVec3::ZERO, 1);
    }
    (
        eval_brdf(material, &scene.images, n, sample.wi, wo)
            * sample.irradiance
            * (sample.cos_i * passed),
        1,
    )
}

/// What a light does at a shading point: the direction to it, its distance, the
/// irradiance it delivers on a surface facing it, and `cos θi` about the shading
/// normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub wi: DVec3,
    /// Distance to the light (infinite for a directional light).
    pub distance: f64,
    /// Irradiance on a surface facing the light.
    pub irradiance: DVec3,
    /// `n · wi`, in (0, 1].
    pub cos_i: f64,
}

/// The fraction of a spot light's intensity that leaves it towards a point in direction
/// `-wi` (`wi`: unit, from the point to the light), for a cone along `direction` with
/// the cosines `cos_inner` and `cos_outer` of its half-angles: 1 inside the inner
/// cone, 0 outside the outer one, and between them `t²` with `t = (cos θ − cos_outer)
/// / max(cos_inner − cos_outer, 0.001)` (KHR_lights_punctual, "Spot", its reference
/// implementation: the square makes the fall-off smooth at the outer edge).
pub fn spot_attenuation(direction: DVec3, wi: DVec3, cos_inner: f64, cos_outer: f64) -> f64 {
    let scale = 1.0 / (cos_inner - cos_outer).max(0.001);
    let t = ((direction.dot(-wi) - cos_outer) * scale).clamp(0.0, 1.0);
    t * t
}

/// The geometry of `light` seen from `origin` with shading normal `n`, or `None` when
/// it contributes nothing and casts no shadow ray: a light below `n`, a point or spot
/// light at a zero, denormal or NaN distance, or a point outside a spot light's cone.
pub fn sample_light(light: &Light, origin: DVec3, n: DVec3) -> Option<LightSample> {
    let point = |position: DVec3, intensity: DVec3| {
        let to_light = position - origin;
        let distance_squared = to_light.length_squared();
        // Zero, denormal or NaN distance: no contribution (see the constant).
        if distance_squared.is_nan() || distance_squared < MIN_LIGHT_DISTANCE_SQUARED {
            return None;
        }
        let distance = distance_squared.sqrt();
        // Inverse-square law: E = I / r² on a surface facing the light.
        Some((to_light / distance, distance, intensity / distance_squared))
    };
    let (wi, distance, irradiance) = match *light {
        Light::Point {
            position,
            intensity,
        } => point(position, intensity)?,
        Light::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        } => {
            let (wi, distance, irradiance) = point(position, intensity)?;
            let attenuation = spot_attenuation(direction, wi, cos_inner, cos_outer);
            // Outside the outer cone: no light and no shadow ray.
            if attenuation <= 0.0 {
                return None;
            }
            (wi, distance, irradiance * attenuation)
        }
        Light::Directional {
            direction,
            irradiance,
        } => (-direction, f64::INFINITY, irradiance),
    };
    let cos_i = n.dot(wi).clamp(-1.0, 1.0);
    (cos_i > 0.0).then_some(LightSample {
        wi,
        distance,
        irradiance,
        cos_i,
    })
}
