//! The auxiliary passes (AOVs) of a render, from the camera rays' first hits: the
//! albedo, the shading normal and the depth that a denoiser is guided by
//! ([`crate::denoise`], Intel Open Image Denoise) and that `--aov` writes as layers of
//! the output EXR. CPU twin of `shaders/aov.wgsl`.
//!
//! Conventions, those of Open Image Denoise's documentation ("Auxiliary feature
//! images"), averaged over the pixel's samples (the same jittered camera rays as the
//! radiance), each escaped sample counting as zero:
//!
//! - **albedo**: the hit material's reflectance after textures, clamped to [0, 1]: the
//!   diffuse albedo (base colour) of every reflecting model; for perfect specular
//!   surfaces the *specular tint*, as OIDN allows instead of following the path: a
//!   mirror's reflectance colour and a dielectric's transmittance filter. No path is
//!   followed, so the passes cost one camera ray per sample and do not depend on the
//!   integrator.
//! - **normal**: the world-space normal the hit is shaded with
//!   ([`super::trace::shading_frame_normal`]), on the side the camera ray arrives from;
//!   not renormalised after averaging (OIDN does not need unit normals).
//! - **depth**: the distance along the camera ray to the hit (its ray parameter, the
//!   direction being unit); 0 where the ray escapes, the value OIDN and compositing
//!   tools treat as "no surface" and that [`crate::denoise`] reads as escaped.

use glam::DVec3;

use super::coverage::BlendRule;
use super::intersect::{MAX_PASS_THROUGHS, Ray, culls_back_face, offset_ray_origin};
use super::path::bounce_blend;
use super::trace::{PreparedScene, shading_frame_normal};
use super::traverse::intersect_scene_with;
use crate::denoise::GuidePasses;
use crate::scene::{Integrator, Material, MaterialKind, Scene};
use crate::texture::{mapped_normal, shading_material};

/// What a camera ray's first hit contributes to the auxiliary passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstHitAov {
    /// [`aov_albedo`] of the hit's material after textures.
    pub albedo: DVec3,
    /// The shading normal, facing the ray.
    pub normal: DVec3,
    /// Distance along the ray to the hit.
    pub depth: f64,
}

/// The albedo pass's value for a material (textures already applied): its specular
/// tint for perfect specular surfaces (mirror: reflectance; dielectric:
/// transmittance), else its diffuse albedo; clamped to [0, 1].
pub fn aov_albedo(material: &Material) -> DVec3 {
    let albedo = match material.kind {
        MaterialKind::Mirror => material.reflectance,
        MaterialKind::Dielectric => material.transmittance,
        _ => material.diffuse,
    };
    albedo.clamp(DVec3::ZERO, DVec3::ONE)
}

/// The first hit of the camera ray `ray` as the auxiliary passes see it, `None` when
/// the ray escapes.
/// A camera ray passes through the back faces of single-sided materials
/// ([`culls_back_face`]), as the image's does, and the hit is shaded with its vertex
/// colour, both texture-coordinate sets and its normal map, as the image's is, at its
/// ray cone's footprint.
/// Blended surfaces stop it as `blend` says: as they stop the image's camera ray.
pub fn first_hit_aov(scene: &PreparedScene, ray: &Ray, blend: BlendRule) -> Option<FirstHitAov> {
    let mut ray = *ray;
    let mut passes = 0;
    let mut cone_width = scene.cone.width;
    let hit = loop {
        let hit = intersect_scene_with(&scene.geometry, &ray, f64::INFINITY, blend)?;
        cone_width = scene.cone_width_at(cone_width, &hit);
        let record = &scene.materials[hit.material as usize];
        if passes == MAX_PASS_THROUGHS
            || !culls_back_face(record.cull_back_faces, 0, ray.direction, hit.normal)
        {
            break hit;
        }
        passes += 1;
        ray.origin = offset_ray_origin(hit.position, hit.normal, scene.geometry.offset_scale);
    };
    let record = &scene.materials[hit.material as usize];
    let uvs = [hit.uv, hit.uv1];
    let textures = scene.textures(hit.footprint(cone_width, ray.direction));
    let material = shading_material(
        record,
        &textures,
        hit.position,
        hit.normal,
        uvs,
        hit.color.truncate(),
    );
    let mapped = mapped_normal(
        record,
        &textures,
        hit.position,
        hit.normal,
        uvs,
        hit.shading_normal,
        hit.tangent,
    );
    let entering = ray.direction.dot(hit.normal) < 0.0;
    let (ng, ns) = if entering {
        (hit.normal, mapped)
    } else {
        (-hit.normal, -mapped)
    };
    Some(FirstHitAov {
        albedo: aov_albedo(&material),
        normal: shading_frame_normal(ray.direction, ng, ns),
        depth: hit.t,
    })
}

/// The mean of the auxiliary passes over every sample of pixel (`x`, `y`): the sums
/// of [`first_hit_aov`] over the pixel's camera rays (those of
/// [`super::trace_pixel`]) divided by the sample count.
pub fn trace_pixel_aov(scene: &PreparedScene, x: u32, y: u32) -> FirstHitAov {
    let settings = &scene.settings;
    let mut sum = FirstHitAov {
        albedo: DVec3::ZERO,
        normal: DVec3::ZERO,
        depth: 0.0,
    };
    for index in 0..settings.samples_per_pixel {
        let (dx, dy) = scene.samples.offset(x, y, index);
        let ray = scene.camera_ray(x, y, index, (dx, dy));
        // The path integrator's camera ray passes blended surfaces stochastically.
        let blend = match settings.integrator {
            Integrator::Path => bounce_blend(y * settings.width + x, index, 0),
            Integrator::Whitted => BlendRule::Hit,
        };
        if let Some(hit) = first_hit_aov(scene, &ray, blend) {
            sum.albedo += hit.albedo;
            sum.normal += hit.normal;
            sum.depth += hit.depth;
        }
    }
    let samples = f64::from(settings.samples_per_pixel.max(1));
    FirstHitAov {
        albedo: sum.albedo / samples,
        normal: sum.normal / samples,
        depth: sum.depth / samples,
    }
}

/// The auxiliary passes of the whole image of `scene`, on all CPU cores.
///
/// ```
/// # use gpu_render::scene::parse_scene;
/// # fn main() -> Result<(), gpu_render::scene::SceneError> {
/// let scene = parse_scene(
///     "[render]\nwidth = 4\nheight = 3\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
///      [materials.grey]\ntype = \"lambert\"\nalbedo = [0.5, 0.5, 0.5]\n\
///      [[objects]]\ntype = \"plane\"\nnormal = [0, 0, 1]\npoint = [0, 0, 0]\nmaterial = \"grey\"\n",
///     std::path::Path::new("<inline>"),
/// )?;
/// let passes = gpu_render::low_level::cpu::aov::render_aovs(&scene);
/// assert!((passes.depth[0] - 3.0).abs() < 0.5);
/// assert_eq!(passes.normal[5], [0.0, 0.0, 1.0]);
/// # Ok(())
/// # }
/// ```
pub fn render_aovs(scene: &Scene) -> GuidePasses {
    render_aovs_prepared(&PreparedScene::new(scene))
}

/// [`render_aovs`] of a scene already prepared.
pub fn render_aovs_prepared(prepared: &PreparedScene) -> GuidePasses {
    let (width, height) = (prepared.settings.width, prepared.settings.height);
    let pixels = width as usize * height as usize;
    let mut means = vec![
        FirstHitAov {
            albedo: DVec3::ZERO,
            normal: DVec3::ZERO,
            depth: 0.0,
        };
        pixels
    ];
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let rows_per_thread = (height as usize).div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (chunk, rows) in means
            .chunks_mut(rows_per_thread * width as usize)
            .enumerate()
        {
            scope.spawn(move || {
                for (i, mean) in rows.iter_mut().enumerate() {
                    let pixel = chunk * rows_per_thread * width as usize + i;
                    let (x, y) = (pixel as u32 % width, pixel as u32 / width);
                    *mean = trace_pixel_aov(prepared, x, y);
                }
            });
        }
    });
    let f = |v: DVec3| v.as_vec3().to_array();
    GuidePasses {
        width,
        height,
        albedo: means.iter().map(|m| f(m.albedo)).collect(),
        normal: means.iter().map(|m| f(m.normal)).collect(),
        depth: means.iter().map(|m| m.depth as f32).collect(),
    }
}
