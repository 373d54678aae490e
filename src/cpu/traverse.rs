//! The scene queries over the BVH: the CPU twin of `shaders/traverse.wgsl` (same
//! function names, the same nodes, the same rules, in `f64`).
//!
//! Both queries test the planes first, then descend the wide tree ([`crate::accel::wide`])
//! nearest child first with a stack of [`MAX_TRAVERSAL_STACK`] entries, one function
//! for both as in WGSL. Of two hits at exactly the same distance the
//! smaller [`PrimRef`] wins, so the nearest hit does not depend on the visiting order
//! and equals [`closest_hit_brute_force`], which tests every primitive.

use glam::DVec3;

use super::coverage::{BlendRule, hit_coverage, stops_ray};
use super::intersect::{
    Hit, Ray, ShearedRay, hit_record_keyed, intersect_prim, intersect_triangle, limit_for,
    shear_ray,
};
use crate::accel::bvh::Aabb32;
use crate::accel::{
    Bvh, EMPTY_CHILD, HitKey, Instance, MAX_TRAVERSAL_STACK, PrimKind, PrimRef, SceneGeometry,
    WIDTH, WideChild, WideNode,
};

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
    /// Wide BVH nodes visited (each tests its children's boxes).
    pub nodes: u64,
    /// Primitive intersection tests (planes included).
    pub primitives: u64,
}

/// A ray prepared for slab tests.
struct SlabRay {
    origin: DVec3,
    inverse_direction: DVec3,
}

/// `1 / d` per component, a component smaller than [`MIN_DIRECTION_COMPONENT`] in
/// magnitude replaced by it with its sign first.
fn inverse_direction(d: DVec3) -> DVec3 {
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
    DVec3::new(1.0 / safe(d.x), 1.0 / safe(d.y), 1.0 / safe(d.z))
}

impl SlabRay {
    fn new(ray: &Ray) -> Self {
        Self {
            origin: ray.origin,
            inverse_direction: inverse_direction(ray.direction),
        }
    }

    /// The distance at which the ray enters `aabb`, if it does so in [0, `t_max`] (the
    /// slab test of Kay and Kajiya, with Ize's robust far distance).
    fn enter(&self, aabb: &Aabb32, t_max: f64) -> Option<f64> {
        let lo =
            (DVec3::from_array(aabb.min.map(f64::from)) - self.origin) * self.inverse_direction;
        let hi =
            (DVec3::from_array(aabb.max.map(f64::from)) - self.origin) * self.inverse_direction;
        let near = lo.min(hi).max_element().max(0.0);
        let far = lo.max(hi).min_element().min(t_max) * FAR_SLAB_SCALE;
        (near <= far).then_some(near)
    }
}

/// The children of `node` the ray enters in [0, `t_max`], with their child words
/// and entry distances, nearest first, and their number (twin of `child_entries` in
/// `shaders/traverse.wgsl`, which marks the others missed instead).
fn child_entries(slab: &SlabRay, node: &WideNode, t_max: f64) -> ([(u32, f64); WIDTH], usize) {
    let mut entered = [(EMPTY_CHILD, f64::INFINITY); WIDTH];
    let mut count = 0;
    for (slot, &word) in node.children.iter().enumerate() {
        if word == EMPTY_CHILD {
            continue;
        }
        if let Some(t) = slab.enter(&node.child_box(slot), t_max) {
            // Insertion by entry distance: the nearest first.
            let mut at = count;
            while at > 0 && t < entered[at - 1].1 {
                entered[at] = entered[at - 1];
                at -= 1;
            }
            entered[at] = (word, t);
            count += 1;
        }
    }
    (entered, count)
}

/// One query's state: the best hit so far and the work done.
struct Query<'a> {
    geometry: &'a SceneGeometry,
    any_hit: bool,
    blend: BlendRule,
    /// The product of `1 − alpha` of the blended surfaces a [`BlendRule::Transmit`]
    /// query crossed.
    transmittance: f64,
    best_t: f64,
    best: Option<HitKey>,
    counts: &'a mut TraversalCounts,
}

impl Query<'_> {
    fn done(&self) -> bool {
        self.any_hit && self.best.is_some()
    }

    /// Tests the surface `key` with the query's tie rule, `hit` giving its distance
    /// below a limit; a hit is kept as [`stops_ray`] says of its coverage
    /// ([`hit_coverage`], at the world ray `world_ray`).
    fn consider(&mut self, key: HitKey, world_ray: &Ray, hit: impl FnOnce(f64) -> Option<f64>) {
        self.counts.primitives += 1;
        if let Some(t) = hit(limit_for(key, self.best_t, self.best))
            && stops_ray(
                self.blend,
                self.any_hit,
                &mut self.transmittance,
                key,
                hit_coverage(self.geometry, key, world_ray, t),
            )
        {
            self.best_t = t;
            self.best = Some(key);
        }
    }

    /// A primitive of the scene's BVH: tested, or for an instance, entered.
    fn world_prim(&mut self, prim: PrimRef, ray: &Ray, sheared: &ShearedRay) {
        if prim.kind() == PrimKind::Instance {
            self.enter_instance(prim.index(), ray);
        } else {
            let geometry = self.geometry;
            self.consider(HitKey::world(prim), ray, |limit| {
                intersect_prim(geometry, prim, ray, sheared, limit)
            });
        }
    }

    /// Traverses instance `index`'s mesh with `ray` moved to its space (twin of the
    /// instance entry in `shaders/traverse.wgsl`).
    fn enter_instance(&mut self, index: usize, ray: &Ray) {
        let geometry = self.geometry;
        let instance = &geometry.instances[index];
        let mesh = &geometry.instanced_meshes[instance.mesh as usize];
        let local = object_ray(instance, ray);
        let sheared = shear_ray(&local);
        let id = Some(index as u32);
        self.walk(&mesh.bvh, &local, |query, prim| {
            query.consider(HitKey { prim, instance: id }, ray, |limit| {
                intersect_triangle(&sheared, &mesh.triangles[prim.index()].vertices, limit)
            });
        });
    }

    /// Descends `bvh`'s wide nodes nearest child first, each node testing its four
    /// children's boxes and stacking the farther ones it enters with their entry
    /// distance; a popped child is skipped where it begins beyond the best hit found
    /// since. Hands each leaf's primitives in order to `leaf_prim`.
    fn walk(&mut self, bvh: &Bvh, ray: &Ray, mut leaf_prim: impl FnMut(&mut Self, PrimRef)) {
        let nodes = &bvh.wide;
        if nodes.is_empty() {
            return;
        }
        let slab = SlabRay::new(ray);
        let mut stack = [(EMPTY_CHILD, 0.0f64); MAX_TRAVERSAL_STACK as usize];
        let mut stack_len = 0usize;
        let mut current = WideChild::Node(0);
        loop {
            if self.done() {
                break;
            }
            match current {
                WideChild::Empty => {
                    // Pop; a child stacked earlier may begin beyond a hit found since.
                    if stack_len == 0 {
                        break;
                    }
                    stack_len -= 1;
                    let (word, entry) = stack[stack_len];
                    if entry <= self.best_t * FAR_SLAB_SCALE {
                        current = WideChild::from_word(word);
                    }
                }
                WideChild::Leaf { first, count } => {
                    current = WideChild::Empty;
                    for &prim in &bvh.prims[first as usize..(first + count) as usize] {
                        leaf_prim(self, prim);
                        if self.done() {
                            break;
                        }
                    }
                }
                WideChild::Node(index) => {
                    self.counts.nodes += 1;
                    let (entered, count) =
                        child_entries(&slab, &nodes[index as usize], self.best_t);
                    let entered = &entered[..count];
                    // Nearest child first; the others wait on the stack, the
                    // farthest deepest.
                    for &waiting in entered.iter().skip(1).rev() {
                        stack[stack_len] = waiting;
                        stack_len += 1;
                    }
                    current = entered
                        .first()
                        .map_or(WideChild::Empty, |&(word, _)| WideChild::from_word(word));
                }
            }
        }
    }
}

/// `ray` in the space of `instance`'s mesh: origin and direction through its
/// world-to-object transform, the direction not renormalised, so that a point keeps
/// its ray parameter (twin: `object_ray` in `shaders/traverse.wgsl`).
pub fn object_ray(instance: &Instance, ray: &Ray) -> Ray {
    Ray {
        origin: instance.world_to_object.transform_point3(ray.origin),
        direction: instance.world_to_object.transform_vector3(ray.direction),
    }
}

/// The traversal both queries share, twin of `traverse` in
/// `shaders/traverse.wgsl` (without its budget: the CPU never suspends a traversal):
/// the planes, then the tree nearest child first, each leaf's primitives in order
/// (an instance's mesh traversed in its own space where the leaf names it), each
/// popped node re-tested against the best hit so far. With `any_hit` the first hit
/// ends it; `blend` says how blended surfaces stop the ray. Returns the best hit and
/// the transmittance of the blended surfaces passed ([`BlendRule::Transmit`]),
/// counting the work into `counts`.
fn traverse(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    any_hit: bool,
    blend: BlendRule,
    counts: &mut TraversalCounts,
) -> (Option<(f64, HitKey)>, f64) {
    let sheared = shear_ray(ray);
    let mut query = Query {
        geometry,
        any_hit,
        blend,
        transmittance: 1.0,
        best_t: t_max,
        best: None,
        counts,
    };
    for i in 0..geometry.planes.len() {
        query.world_prim(PrimRef::new(PrimKind::Plane, i as u32), ray, &sheared);
    }
    query.walk(&geometry.bvh, ray, |query, prim| {
        query.world_prim(prim, ray, &sheared);
    });
    (
        query.best.map(|key| (query.best_t, key)),
        query.transmittance,
    )
}

/// The nearest surface along `ray` in (0, `t_max`) and its distance, counting the
/// work into `counts` (blended surfaces hit, [`BlendRule::Hit`]).
pub fn closest_hit_counted(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    counts: &mut TraversalCounts,
) -> Option<(f64, HitKey)> {
    traverse(geometry, ray, t_max, false, BlendRule::Hit, counts).0
}

/// The nearest hit along `ray` in (0, `t_max`), its point re-projected onto the
/// primitive ([`super::intersect::hit_record_keyed`]); blended surfaces are hit
/// ([`BlendRule::Hit`]).
pub fn intersect_scene(geometry: &SceneGeometry, ray: &Ray, t_max: f64) -> Option<Hit> {
    intersect_scene_with(geometry, ray, t_max, BlendRule::Hit)
}

/// [`intersect_scene`] with blended surfaces treated by `blend`.
pub fn intersect_scene_with(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
    blend: BlendRule,
) -> Option<Hit> {
    let mut counts = TraversalCounts::default();
    traverse(geometry, ray, t_max, false, blend, &mut counts)
        .0
        .map(|(t, key)| hit_record_keyed(geometry, key, ray, t))
}

/// Whether anything lies along `ray` in (0, `t_max`): the shadow-ray query, which
/// stops at the first hit it finds (blended surfaces included).
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
    traverse(geometry, ray, t_max, true, BlendRule::Hit, counts)
        .0
        .is_some()
}

/// The fraction of light that passes along `ray` in (0, `t_max`): 0 if an opaque
/// surface (or, for [`BlendRule::Stochastic`], a blended one that the draw says
/// stops it) lies there, else the product of `1 − alpha` of the blended surfaces
/// crossed ([`BlendRule::Transmit`]; 1 for the other rules). The shadow-ray query.
pub fn transmittance(geometry: &SceneGeometry, ray: &Ray, t_max: f64, blend: BlendRule) -> f64 {
    let mut counts = TraversalCounts::default();
    match traverse(geometry, ray, t_max, true, blend, &mut counts) {
        (Some(_), _) => 0.0,
        (None, transmittance) => transmittance,
    }
}

/// The nearest hit by testing every primitive (every instance's every triangle in its
/// own space), with the same tie rule: the oracle of the traversal tests.
pub fn closest_hit_brute_force(
    geometry: &SceneGeometry,
    ray: &Ray,
    t_max: f64,
) -> Option<(f64, HitKey)> {
    let mut best_t = t_max;
    let mut best: Option<HitKey> = None;
    let mut consider = |key: HitKey, hit: &dyn Fn(f64) -> Option<f64>| {
        if let Some(t) = hit(limit_for(key, best_t, best))
            && hit_coverage(geometry, key, ray, t) > 0.0
        {
            best_t = t;
            best = Some(key);
        }
    };
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
            consider(HitKey::world(prim), &|limit| {
                intersect_prim(geometry, prim, ray, &sheared, limit)
            });
        }
    }
    for (i, instance) in geometry.instances.iter().enumerate() {
        let mesh = &geometry.instanced_meshes[instance.mesh as usize];
        let local = object_ray(instance, ray);
        let sheared = shear_ray(&local);
        for (j, triangle) in mesh.triangles.iter().enumerate() {
            let key = HitKey {
                prim: PrimRef::new(PrimKind::Triangle, j as u32),
                instance: Some(i as u32),
            };
            consider(key, &|limit| {
                intersect_triangle(&sheared, &triangle.vertices, limit)
            });
        }
    }
    best.map(|key| (best_t, key))
}
