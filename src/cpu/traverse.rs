//! The scene queries over the BVH: the CPU twin of `shaders/traverse.wgsl` (same
//! function names, the same nodes, the same rules, in `f64`).
//!
//! Both queries test the planes first, then descend the tree nearest child first with
//! a stack of [`MAX_BVH_DEPTH`] entries, one function for both as in WGSL. Of two hits at exactly the same distance the
//! smaller [`PrimRef`] wins, so the nearest hit does not depend on the visiting order
//! and equals [`closest_hit_brute_force`], which tests every primitive.

use glam::DVec3;

use super::intersect::{Hit, Ray, hit_record, intersect_prim, shear_ray};
use crate::accel::{BvhNode, MAX_BVH_DEPTH, PrimKind, PrimRef, SceneGeometry};

/// Direction components smaller than this in magnitude are replaced by it (with their
/// sign) before the slab test divides by them: an exactly parallel ray then gets huge
/// but finite slab distances, never the NaN of `0 · ∞` (twin: `shaders/traverse.wgsl`).
pub const MIN_DIRECTION_COMPONENT: f64 = 1e-20;

/// `1 + 2γ₃` for `f64` (γₙ = nε/(1 - nε), ε = 2^-53): the factor by which the far slab
/// distance is enlarged so that rounding can never make a ray miss a box it enters
/// (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013). The GPU uses the `f32` value.
pub const FAR_SLAB_SCALE: f64 =
    1.0 + 2.0 * (3.0 * f64::EPSILON / 2.0) / (1.0 - 3.0 * f64::EPSILON / 2.0);

/// Work one query did: nodes visited and primitives tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TraversalCounts {
    /// BVH nodes visited (inner and leaf).
    pub nodes: u64,
    /// Primitive intersection tests (planes included).
    pub primitives: u64,
}

/// A ray prepared for slab tests.
struct SlabRay {
    origin: DVec3,
    inverse_direction: DVec3,
}

impl SlabRay {
    fn new(ray: &Ray) -> Self {
        // -0 counts as positive, as in the WGSL twin's `select`.
        let safe = |d: f64| {
            if d.abs() >= MIN_DIRECTION_COMPONENT {
                d
            } else if d < 0.0 {
                -MIN_DIRECTION_COMPONENT
            } else {
                MIN_DIRECTION_COMPONENT
            }
        };
        let d = ray.direction;
        Self {
            origin: ray.origin,
            inverse_direction: DVec3::new(1.0 / safe(d.x), 1.0 / safe(d.y), 1.0 / safe(d.z)),
        }
    }

    /// The distance at which the ray enters `node`'s box, if it does so in
    /// [0, `t_max`] (the slab test of Kay and Kajiya, with Ize's robust far distance).
    fn enter(&self, node: &BvhNode, t_max: f64) -> Option<f64> {
        let lo =
            (DVec3::from_array(node.min.map(f64::from)) - self.origin) * self.inverse_direction;
        let hi =
            (DVec3::from_array(node.max.map(f64::from)) - self.origin) * self.inverse_direction;
        let near = lo.min(hi).max_element().max(0.0);
        let far = lo.max(hi).min_element().min(t_max) * FAR_SLAB_SCALE;
        (near <= far).then_some(near)
    }
}

/// The exclusive distance limit for testing `prim` against the best hit so far: the
/// best distance, or just beyond it for a smaller reference, which wins exact ties.
/// Without a hit yet, the query's own exclusive `t_max`.
fn limit_for(prim: PrimRef, best_t: f64, best: Option<PrimRef>) -> f64 {
    match best {
        Some(b) if prim < b && best_t.is_finite() => best_t.next_up(),
        _ => best_t,
    }
}

/// The traversal both queries share, twin of `advance_traversal` in
/// `shaders/traverse.wgsl` (without its budget: the CPU never suspends a traversal):
/// the planes, then the tree nearest child first, each leaf's primitives in order,
/// each popped node re-tested against the best hit so far. With `any_hit` the first
/// hit ends it. Returns the best hit, counting the work into `counts`.
fn traverse(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    any_hit: bool,
    counts: &mut TraversalCounts,
) -> Option<(f64, PrimRef)> {
    let sheared = shear_ray(ray);
    let mut best_t = t_max;
    let mut best: Option<PrimRef> = None;
    let mut consider = |prim: PrimRef, best_t: &mut f64, best: &mut Option<PrimRef>| {
        counts.primitives += 1;
        let limit = limit_for(prim, *best_t, *best);
        if let Some(t) = intersect_prim(geometry, prim, ray, &sheared, limit) {
            *best_t = t;
            *best = Some(prim);
        }
    };
    for i in 0..geometry.planes.len() {
        consider(
            PrimRef::new(PrimKind::Plane, i as u32),
            &mut best_t,
            &mut best,
        );
    }
    let nodes = &geometry.bvh.nodes;
    let slab = SlabRay::new(ray);
    let mut stack = [0u32; MAX_BVH_DEPTH as usize];
    let mut stack_len = 0usize;
    let mut current = match nodes.first() {
        Some(root) if slab.enter(root, best_t).is_some() => Some(0u32),
        _ => None,
    };
    loop {
        if any_hit && best.is_some() {
            break;
        }
        let Some(index) = current else {
            // Pop; a node pushed earlier may lie beyond a hit found since.
            if stack_len == 0 {
                break;
            }
            stack_len -= 1;
            let candidate = stack[stack_len];
            current = slab
                .enter(&nodes[candidate as usize], best_t)
                .map(|_| candidate);
            continue;
        };
        counts.nodes += 1;
        let node = &nodes[index as usize];
        current = None;
        if node.is_leaf() {
            for &prim in
                &geometry.bvh.prims[node.first as usize..(node.first + node.count) as usize]
            {
                consider(prim, &mut best_t, &mut best);
                if any_hit && best.is_some() {
                    break;
                }
            }
            continue;
        }
        let (a, b) = (node.first, node.first + 1);
        let enter_a = slab.enter(&nodes[a as usize], best_t);
        let enter_b = slab.enter(&nodes[b as usize], best_t);
        current = match (enter_a, enter_b) {
            (Some(ta), Some(tb)) => {
                // Nearest child first; the other waits on the stack.
                let (near, far) = if tb < ta { (b, a) } else { (a, b) };
                stack[stack_len] = far;
                stack_len += 1;
                Some(near)
            }
            (Some(_), None) => Some(a),
            (None, Some(_)) => Some(b),
            (None, None) => None,
        };
    }
    best.map(|prim| (best_t, prim))
}

/// The nearest primitive along `ray` in (0, `t_max`) and its distance, counting the
/// work into `counts`.
pub fn closest_hit_counted(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    counts: &mut TraversalCounts,
) -> Option<(f64, PrimRef)> {
    traverse(geometry, ray, t_max, false, counts)
}

/// The nearest hit along `ray` in (0, `t_max`), its point re-projected onto the
/// primitive ([`hit_record`]).
pub fn intersect_scene(geometry: &SceneGeometry, ray: &Ray, t_max: f64) -> Option<Hit> {
    let mut counts = TraversalCounts::default();
    closest_hit_counted(geometry, ray, t_max, &mut counts)
        .map(|(t, prim)| hit_record(geometry, prim, ray, t))
}

/// Whether anything lies along `ray` in (0, `t_max`): the shadow-ray query, which
/// stops at the first hit it finds.
pub fn occluded(geometry: &SceneGeometry, ray: &Ray, t_max: f64) -> bool {
    let mut counts = TraversalCounts::default();
    occluded_counted(geometry, ray, t_max, &mut counts)
}

/// [`occluded`], counting the work into `counts`.
pub fn occluded_counted(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    counts: &mut TraversalCounts,
) -> bool {
    traverse(geometry, ray, t_max, true, counts).is_some()
}

/// The nearest hit by testing every primitive, with the same tie rule: the oracle of
/// the traversal tests.
pub fn closest_hit_brute_force(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
) -> Option<(f64, PrimRef)> {
    let mut best_t = t_max;
    let mut best: Option<PrimRef> = None;
    let kinds = [
        (PrimKind::Sphere, geometry.spheres.len()),
        (PrimKind::Plane, geometry.planes.len()),
        (PrimKind::Polygon, geometry.polygons.len()),
        (PrimKind::Triangle, geometry.triangles.len()),
    ];
    let sheared = shear_ray(ray);
    for (kind, count) in kinds {
        for i in 0..count {
            let prim = PrimRef::new(kind, i as u32);
            let limit = limit_for(prim, best_t, best);
            if let Some(t) = intersect_prim(geometry, prim, ray, &sheared, limit) {
                best_t = t;
                best = Some(prim);
            }
        }
    }
    best.map(|prim| (best_t, prim))
}
