//! Alpha coverage (glTF 2.0 §3.9.4, `alphaMode` `MASK` and `BLEND`): the fraction of
//! light a candidate hit stops, and whether it stops a query. The CPU twin of
//! `shaders/coverage.wgsl`, which both GPU traversals use (the software walk and the
//! hardware ray queries' candidate loop); the queries of [`super::traverse`] use it.

use super::intersect::{Ray, hit_record_keyed};
use crate::accel::{HitKey, SceneGeometry};
use crate::sample::{pcg_hash, unit_from_hash};
use crate::scene::AlphaMode;
use crate::texture::shading_alpha;

/// How a query treats the surfaces of [`AlphaMode::Blend`] materials whose alpha lies
/// strictly between 0 and 1 (alpha 0 is never hit, alpha 1 always).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlendRule {
    /// Such a surface is hit like an opaque one: the Whitted integrator's camera and
    /// secondary rays, which branch there (weight alpha shaded, `1 − alpha` on
    /// through it), and the AOV pass.
    Hit,
    /// An any-hit query passes it, multiplying its transmittance by `1 − alpha`: the
    /// Whitted integrator's shadow rays.
    Transmit,
    /// Stochastic transparency: the ray is stopped with probability alpha, by
    /// [`blend_number`] of this seed and the surface: every ray of the path
    /// integrator, whose seed comes from its path's sample ([`blend_seed`]).
    Stochastic(u32),
}

/// The fraction of light the hit of the surface `key` at parameter `t` along the
/// world-space `ray` stops (its coverage): 1 for an opaque material; for a mask
/// (glTF 2.0 §3.9.4: opaque where alpha >= alphaCutoff) 1 where its alpha
/// ([`shading_alpha`], at the hit record's point and texture coordinates) reaches the
/// cutoff and 0 where it is below, so the point does not exist for any ray and the
/// traversal looks on; for a blended material its alpha. Twin of `hit_coverage` in
/// `shaders/coverage.wgsl`.
pub fn hit_coverage(geometry: &SceneGeometry, key: HitKey, ray: &Ray, t: f64) -> f64 {
    if geometry.alpha_masks.is_empty() {
        return 1.0;
    }
    let material = match key.instance {
        Some(i) => geometry.instances[i as usize].material,
        None => geometry.material(key.prim),
    };
    let Some(mask) = geometry.alpha_mask(material) else {
        return 1.0;
    };
    let hit = hit_record_keyed(geometry, key, ray, t);
    let alpha = shading_alpha(
        &mask.material,
        mask.texture.as_ref(),
        hit.position,
        hit.normal,
        [hit.uv, hit.uv1],
        hit.color.w,
    );
    match mask.mode {
        AlphaMode::Mask { cutoff } => {
            if alpha < cutoff {
                0.0
            } else {
                1.0
            }
        }
        _ => alpha,
    }
}

/// Whether a candidate hit of the surface `key` whose coverage is `coverage`
/// ([`hit_coverage`]) stops a query of rule `blend` (an any-hit query if `any_hit`):
/// never at coverage 0 (or NaN), always at 1; between, per [`BlendRule`], a
/// transmitting any-hit query multiplying `transmittance` by `1 − coverage`. Twin of
/// `stops_ray` in `shaders/coverage.wgsl`.
pub fn stops_ray(
    blend: BlendRule,
    any_hit: bool,
    transmittance: &mut f64,
    key: HitKey,
    coverage: f64,
) -> bool {
    // NaN stops nothing.
    if coverage.is_nan() || coverage <= 0.0 {
        return false;
    }
    if coverage >= 1.0 {
        return true;
    }
    match blend {
        BlendRule::Hit => true,
        BlendRule::Transmit => {
            if !any_hit {
                return true;
            }
            *transmittance *= 1.0 - coverage;
            false
        }
        BlendRule::Stochastic(seed) => blend_number(seed, key) < coverage,
    }
}

/// The uniform number in [0, 1) that decides whether a stochastic ray of seed `seed`
/// passes the blended surface `key`: its primitive and instance (`u32::MAX` for the
/// scene's own) hashed with the seed by [`pcg_hash`]. Twin of `blend_number`.
pub fn blend_number(seed: u32, key: HitKey) -> f64 {
    let instance = key.instance.unwrap_or(u32::MAX);
    unit_from_hash(pcg_hash(seed ^ pcg_hash(key.prim.0 ^ pcg_hash(instance))))
}

/// The seed of the stochastic transparency of the rays of sample `sample` of image
/// pixel `pixel` at the path's bounce whose random numbers start at dimension
/// `dimension`: [`crate::sample::random_number`]'s hash, unreduced (`u32::MAX`, which
/// the GPU reads as no seed, made 0). Twin of `blend_seed`.
pub fn blend_seed(pixel: u32, sample: u32, dimension: u32) -> u32 {
    let seed = pcg_hash(pcg_hash(pcg_hash(pixel) ^ sample) ^ dimension);
    // u32::MAX means "none" on the GPU (NO_BLEND_SEED).
    if seed == u32::MAX { 0 } else { seed }
}
