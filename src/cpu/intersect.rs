//! Ray/primitive intersection, the CPU twin of `shaders/intersect.wgsl` (same function
//! names, `f64`): the primitive tests, the hit record of a primitive, and the
//! self-intersection offset. The scene-level queries (`intersect_scene`, `occluded`)
//! traverse the BVH in [`super::traverse`].

use glam::{DVec2, DVec3, DVec4};

use crate::accel::{
    HitKey, InstanceId, PrimKind, PrimRef, SceneGeometry, TriangleAttributes, TriangleShape,
};
use crate::scene::PolygonPlane;
pub use crate::scene::project_to_plane;
use crate::texture::{ConeFootprint, footprint_axis};

/// A ray `origin + t · direction`, `direction` of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.direction * t
    }
}

/// The nearest intersection of a ray with the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (distance, since directions are unit).
    pub t: f64,
    /// Unit geometric normal as the shape defines it (outward for spheres, the plane
    /// normal, the winding normal of polygons and triangles); not yet flipped to face
    /// the ray.
    pub normal: DVec3,
    /// Material index.
    pub material: u32,
    /// The hit point, re-projected onto the surface (see [`hit_record`]).
    pub position: DVec3,
    /// The primitive that was hit.
    pub prim: PrimRef,
    /// Unit shading normal, on the same side as `normal`: a mesh triangle's vertex
    /// normals interpolated at the hit (smooth shading), else `normal`.
    pub shading_normal: DVec3,
    /// Texture coordinates: a mesh triangle's vertex coordinates interpolated at the
    /// hit, else `(0, 0)`.
    pub uv: DVec2,
    /// The second set of texture coordinates, likewise.
    pub uv1: DVec2,
    /// A mesh triangle's vertex colours (RGBA) interpolated at the hit, else opaque
    /// white (1, 1, 1, 1).
    pub color: DVec4,
    /// A mesh triangle's vertex tangents interpolated at the hit (`w`: the bitangent's
    /// handedness, interpolated too; its sign is used), else zero (no normal map).
    pub tangent: DVec4,
    /// Barycentric coordinates of the hit in a triangle (weights of its three
    /// corners), else `(1, 0, 0)`.
    pub barycentrics: DVec3,
    /// The instance of an instanced mesh's triangle (then `prim` indexes its mesh's
    /// triangles), else `None`.
    pub instance: InstanceId,
    /// A mesh triangle's texture-coordinate area over its world area, per coordinate
    /// set (`[uv, uv1]`), for the texture level of detail
    /// ([`crate::texture::ConeFootprint::uv_density`]); 0 without such coordinates.
    pub uv_density: [f64; 2],
    /// The change of a mesh triangle's texture coordinates per unit of world distance
    /// along the footprint's long axis ([`crate::texture::footprint_axis`] of the ray
    /// and the geometric normal), per coordinate set (`[uv, uv1]`;
    /// [`triangle_uv_axis`]): the anisotropic texture lookup's direction; zero
    /// without such coordinates.
    pub uv_axis: [DVec2; 2],
}

impl Hit {
    /// The texture footprint here of a ray cone `cone_width` wide at the hit, met
    /// along `direction` ([`ConeFootprint::new`] with the hit's normal and texture
    /// coordinate density and axis).
    pub fn footprint(&self, cone_width: f64, direction: DVec3) -> ConeFootprint {
        ConeFootprint::new(
            cone_width,
            direction,
            self.normal,
            self.uv_density,
            self.uv_axis,
        )
    }

    /// The surface that was hit: its primitive and instance.
    pub fn key(&self) -> HitKey {
        HitKey {
            prim: self.prim,
            instance: self.instance,
        }
    }
}

/// A triangle as it stands in world space, with its world-space attributes: one of
/// the scene's own, or an instanced mesh's moved by its instance
/// ([`crate::accel::Instance::world_triangle`]). `None` for other primitives.
pub fn world_triangle(
    geometry: &SceneGeometry,
    key: HitKey,
) -> Option<(TriangleShape, Option<TriangleAttributes>)> {
    if key.prim.kind() != PrimKind::Triangle {
        return None;
    }
    match key.instance {
        None => {
            let triangle = geometry.triangles[key.prim.index()];
            let attributes = triangle
                .attributes
                .map(|a| geometry.triangle_attributes[a as usize]);
            Some((triangle, attributes))
        }
        Some(i) => {
            let instance = &geometry.instances[i as usize];
            let mesh = &geometry.instanced_meshes[instance.mesh as usize];
            Some(instance.world_triangle(mesh, key.prim.index()))
        }
    }
}

/// The exclusive distance limit for testing the surface `key` against the best hit so
/// far: the best distance, or just beyond it for a smaller key, which wins exact ties
/// (so that the nearest hit does not depend on the order of the tests). Without a hit
/// yet, the query's own exclusive `t_max`.
pub fn limit_for(key: HitKey, best_t: f64, best: Option<HitKey>) -> f64 {
    match best {
        Some(b) if key < b && best_t.is_finite() => best_t.next_up(),
        _ => best_t,
    }
}

/// The ray parameter of `prim`'s nearest hit along `ray` in (0, `t_max`); `sheared`
/// is [`shear_ray`] of `ray`, for triangles.
pub fn intersect_prim(
    geometry: &SceneGeometry,
    prim: PrimRef,
    ray: &Ray,
    sheared: &ShearedRay,
    t_max: f64,
) -> Option<f64> {
    let i = prim.index();
    match prim.kind() {
        PrimKind::Sphere => {
            let s = &geometry.spheres[i];
            intersect_sphere(ray, s.anchor, s.anchor_normal, s.radius, t_max)
        }
        PrimKind::Polygon => {
            let p = &geometry.polygons[i];
            intersect_polygon(ray, &p.plane, &p.vertices, t_max)
        }
        PrimKind::Triangle => intersect_triangle(sheared, &geometry.triangles[i].vertices, t_max),
        PrimKind::Plane => {
            let p = &geometry.planes[i];
            intersect_plane(ray, p.normal, p.offset, t_max)
        }
        // The traversal enters instances; they are never hit themselves.
        PrimKind::Instance => None,
    }
}

/// The hit record of `prim` at parameter `t` along `ray`: its unit geometric normal as
/// the shape defines it (outward for spheres, the plane normal, the winding normal of
/// polygons and triangles), its material, and the hit point moved back onto the
/// surface, as Wächter and Binder recommend before offsetting a new ray origin ("A
/// Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6,
/// §6.2.1): `ray.at(t)` is off the surface by the rounding error of `t` times the ray
/// length, which grows with the distance from the ray origin, while the re-projected
/// point's error is relative to its own magnitude, which is what the ulp-scaled offset
/// assumes. A sphere point becomes `c + r·normalize(p - c)`; a point of a plane,
/// polygon or triangle is projected orthogonally onto its plane, `p - (N·p - d)·N`.
pub fn hit_record(geometry: &SceneGeometry, prim: PrimRef, ray: &Ray, t: f64) -> Hit {
    hit_record_keyed(geometry, HitKey::world(prim), ray, t)
}

/// [`hit_record`] of the surface `key`, which may be an instanced mesh's triangle: the
/// record is then made from the triangle moved to world space
/// ([`world_triangle`]), at the world point `ray.at(t)`.
pub fn hit_record_keyed(geometry: &SceneGeometry, key: HitKey, ray: &Ray, t: f64) -> Hit {
    if key.instance.is_some()
        && let Some((triangle, attributes)) = world_triangle(geometry, key)
    {
        return triangle_hit(&triangle, attributes.as_ref(), key, ray, t);
    }
    let prim = key.prim;
    let point = ray.at(t);
    let i = prim.index();
    if prim.kind() == PrimKind::Triangle {
        let triangle = &geometry.triangles[i];
        let attributes = triangle
            .attributes
            .map(|a| &geometry.triangle_attributes[a as usize]);
        return triangle_hit(triangle, attributes, key, ray, t);
    }
    let (normal, position) = match prim.kind() {
        PrimKind::Sphere => {
            let s = &geometry.spheres[i];
            (
                sphere_normal(point, s.anchor, s.anchor_normal, s.radius),
                project_onto_sphere(point, s.anchor, s.anchor_normal, s.radius),
            )
        }
        PrimKind::Polygon => {
            let plane = &geometry.polygons[i].plane;
            (
                plane.normal,
                project_onto_plane(point, plane.normal, plane.offset),
            )
        }
        PrimKind::Plane => {
            let p = &geometry.planes[i];
            (p.normal, project_onto_plane(point, p.normal, p.offset))
        }
        // Triangles are handled above; an instance is never a hit.
        PrimKind::Triangle | PrimKind::Instance => (DVec3::Z, point),
    };
    flat_hit(prim, t, normal, geometry.material(prim), position)
}

/// A hit without vertex attributes: its shading normal is its geometric normal, its
/// texture coordinates `(0, 0)`, its colour opaque white, its barycentric coordinates
/// `(1, 0, 0)`.
pub fn flat_hit(prim: PrimRef, t: f64, normal: DVec3, material: u32, position: DVec3) -> Hit {
    Hit {
        t,
        normal,
        material,
        position,
        prim,
        shading_normal: normal,
        uv: DVec2::ZERO,
        uv1: DVec2::ZERO,
        color: DVec4::ONE,
        tangent: DVec4::ZERO,
        barycentrics: DVec3::X,
        instance: None,
        uv_density: [0.0; 2],
        uv_axis: [DVec2::ZERO; 2],
    }
}

/// The hit record of a world-space `triangle` (with its world-space `attributes`) at
/// `ray.at(t)`: the winding normal, the point projected onto its plane, its
/// barycentric coordinates, the interpolated shading normal and texture coordinates,
/// and the coordinates' density and change along the ray's footprint.
fn triangle_hit(
    triangle: &TriangleShape,
    attributes: Option<&TriangleAttributes>,
    key: HitKey,
    ray: &Ray,
    t: f64,
) -> Hit {
    let point = ray.at(t);
    let vertices = &triangle.vertices;
    let normal = triangle_normal(vertices);
    let position = project_onto_plane(point, normal, normal.dot(vertices[0]));
    let mut hit = flat_hit(key.prim, t, normal, triangle.material, position);
    hit.instance = key.instance;
    hit.barycentrics = triangle_barycentrics(position, vertices);
    if let Some(attributes) = attributes {
        apply_triangle_attributes(&mut hit, attributes);
        hit.uv_density = [
            attributes
                .uvs
                .map_or(0.0, |uv| triangle_uv_density(vertices, &uv)),
            attributes
                .uvs1
                .map_or(0.0, |uv| triangle_uv_density(vertices, &uv)),
        ];
        let axis = footprint_axis(ray.direction, normal);
        hit.uv_axis = [attributes.uvs, attributes.uvs1]
            .map(|uv| uv.map_or(DVec2::ZERO, |uv| triangle_uv_axis(vertices, &uv, axis)));
    }
    hit
}

/// The change of texture coordinates (corner coordinates `uv`) per unit of world
/// distance along `axis`, a unit vector in the plane of the triangle with corners
/// `vertices`: `axis = β1·e1 + β2·e2` over its edges `e1 = v1 − v0`, `e2 = v2 − v0`,
/// solved by Cramer's rule in the plane (`β1 = (axis × e2)·n / |e1 × e2|`, `β2 = (e1
/// × axis)·n / |e1 × e2|`, `n` the unit winding normal), gives `β1·(uv1 − uv0) +
/// β2·(uv2 − uv0)`. Zero for a degenerate triangle or a zero axis. Twin of
/// `triangle_uv_axis` in `shaders/intersect.wgsl`.
pub fn triangle_uv_axis(vertices: &[DVec3; 3], uv: &[DVec2; 3], axis: DVec3) -> DVec2 {
    let (e1, e2) = (vertices[1] - vertices[0], vertices[2] - vertices[0]);
    let cross = e1.cross(e2);
    let area = cross.length();
    let normal = cross / area;
    let b1 = axis.cross(e2).dot(normal) / area;
    let b2 = e1.cross(axis).dot(normal) / area;
    let change = (uv[1] - uv[0]) * b1 + (uv[2] - uv[0]) * b2;
    if change.is_finite() {
        change
    } else {
        DVec2::ZERO
    }
}

/// The texture-coordinate area of a triangle with corner coordinates `uv` over its
/// world area (corners `vertices`): `|(uv1 − uv0) × (uv2 − uv0)| / |(v1 − v0) × (v2 −
/// v0)|`, the ratio `t_a / p_a` of Akenine-Möller et al., "Texture Level of Detail
/// Strategies for Real-Time Ray Tracing" (Ray Tracing Gems, ch. 20, 2019, eq. 34),
/// without the texture's size. 0 for a degenerate triangle. Twin of `triangle_uv_density` in
/// `shaders/intersect.wgsl`.
pub fn triangle_uv_density(vertices: &[DVec3; 3], uv: &[DVec2; 3]) -> f64 {
    let uv_area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
    let world_area = (vertices[1] - vertices[0])
        .cross(vertices[2] - vertices[0])
        .length();
    let density = uv_area / world_area;
    if density.is_finite() { density } else { 0.0 }
}

/// Whether a camera ray (`depth` 0) travelling along `direction` passes through the
/// surface it hit, of geometric normal `normal` (as the shape defines it): the back
/// face of a material that culls back faces (glTF's `doubleSided: false`, glTF 2.0
/// §3.9.5: "back-face culling is enabled"). Such a ray goes on from just beyond the
/// surface, without a bounce. Spheres' outsides are their fronts; a plane's front is
/// the side its normal points to.
pub fn culls_back_face(cull_back_faces: bool, depth: u32, direction: DVec3, normal: DVec3) -> bool {
    cull_back_faces && depth == 0 && direction.dot(normal) > 0.0
}

/// The most back faces one camera ray passes through ([`culls_back_face`]); the next
/// is shaded as a front. A mutated model made a camera ray pass through back faces
/// without end (the fuzz test of model import never finished), so the CPU bounds it.
pub const MAX_PASS_THROUGHS: u32 = 256;

/// Fills a triangle hit's shading normal (its vertex normals interpolated at its
/// barycentric coordinates), texture coordinates and vertex colour from its
/// world-space `attributes`.
pub fn apply_triangle_attributes(hit: &mut Hit, attributes: &TriangleAttributes) {
    let b = hit.barycentrics;
    if let Some(n) = attributes.normals {
        let interpolated = n[0] * b.x + n[1] * b.y + n[2] * b.z;
        // Degenerate interpolations and normals facing away from the surface
        // fall back to the geometric normal.
        let shading = interpolated.normalize_or(hit.normal);
        if shading.dot(hit.normal) > 0.0 {
            hit.shading_normal = shading;
        }
    }
    if let Some(uv) = attributes.uvs {
        hit.uv = uv[0] * b.x + uv[1] * b.y + uv[2] * b.z;
    }
    if let Some(uv) = attributes.uvs1 {
        hit.uv1 = uv[0] * b.x + uv[1] * b.y + uv[2] * b.z;
    }
    if let Some(c) = attributes.colors {
        hit.color = c[0] * b.x + c[1] * b.y + c[2] * b.z;
    }
    if let Some(t) = attributes.tangents {
        hit.tangent = t[0] * b.x + t[1] * b.y + t[2] * b.z;
    }
}

/// The barycentric coordinates of `point` (on the triangle's plane) in the triangle
/// `vertices`, clamped to the triangle and summing to 1 (Ericson, "Real-Time Collision
/// Detection", §3.4): the weights of the corners for interpolating their attributes.
pub fn triangle_barycentrics(point: DVec3, vertices: &[DVec3; 3]) -> DVec3 {
    // Scaled by a power of two as the GPU twin, whose f32 products of four coordinates
    // overflow for edges beyond about 4e9.
    let (e1, e2) = (vertices[1] - vertices[0], vertices[2] - vertices[0]);
    let scale = scale_to_unit(e1.abs().max_element().max(e2.abs().max_element()));
    let (e1, e2) = (e1 * scale, e2 * scale);
    let p = (point - vertices[0]) * scale;
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (p.dot(e1), p.dot(e2));
    let denominator = d00 * d11 - d01 * d01;
    if denominator.is_nan() || denominator <= 0.0 {
        return DVec3::X;
    }
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    // A hit found on an edge may lie a rounding error outside: clamp, renormalise.
    let b = DVec3::new(1.0 - v - w, v, w).max(DVec3::ZERO);
    let sum = b.x + b.y + b.z;
    if sum > 0.0 { b / sum } else { DVec3::X }
}

/// Where the shadow rays of a smooth-shaded mesh hit start: the hit point lifted off
/// its flat triangle towards the curved surface the vertex normals describe, `P' = P -
/// Σ bᵢ·min(0, (P - Vᵢ)·nᵢ)·nᵢ` with the normals `nᵢ` turned to the side `facing` is on
/// (Hanika, "Hacking the Shadow Terminator", Ray Tracing Gems II, ch. 4, 2021). Without
/// it the neighbouring flat facets shadow a point that its smooth normal says is lit:
/// black, faceted terminators on low-poly meshes. Other shapes keep the hit point.
pub fn shadow_terminator_point(geometry: &SceneGeometry, hit: &Hit, facing: DVec3) -> DVec3 {
    let Some((
        triangle,
        Some(TriangleAttributes {
            normals: Some(normals),
            ..
        }),
    )) = world_triangle(geometry, hit.key())
    else {
        return hit.position;
    };
    let sign = if facing.dot(hit.normal) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let p = hit.position;
    let b = hit.barycentrics.to_array();
    let mut lifted = p;
    for k in 0..3 {
        let n = normals[k] * sign;
        lifted -= n * ((p - triangle.vertices[k]).dot(n).min(0.0) * b[k]);
    }
    lifted
}

/// The unit normal `(v1 - v0) × (v2 - v0)` of a triangle, normalized.
pub fn triangle_normal(vertices: &[DVec3; 3]) -> DVec3 {
    let e1 = vertices[1] - vertices[0];
    let e2 = vertices[2] - vertices[0];
    let edges = scale_to_unit(e1.abs().max_element().max(e2.abs().max_element()));
    let c = (e1 * edges).cross(e2 * edges);
    (c * scale_to_unit(c.abs().max_element())).normalize()
}

/// The power of two that brings `largest` (finite, at least 0) into [0.5, 1), 1 for 0:
/// scaling by it is exact and keeps squares and products of a few such values inside
/// the floating-point range. The GPU twin returns the exponent, for `ldexp` (in `f32` a
/// triangle of corners ±2.2e9 had a squared cross product beyond the largest float).
pub fn scale_to_unit(largest: f64) -> f64 {
    if largest == 0.0 || !largest.is_finite() {
        return 1.0;
    }
    // frexp: largest = m·2^e with m in [0.5, 1).
    let exponent = largest.log2().floor() as i32 + 1;
    let scale = 2f64.powi(-exponent);
    // log2 may round across a power of two: correct by one step either way.
    if largest * scale >= 1.0 {
        scale * 0.5
    } else if largest * scale < 0.5 {
        scale * 2.0
    } else {
        scale
    }
}

/// The unit outward normal at `point` of the sphere of radius `radius` through
/// `anchor`, whose outward normal there is `normal` (see [`crate::scene::sphere_anchor`]):
/// `(p - c)/r = (p - anchor)/r + normal`, normalized, without forming the centre.
pub fn sphere_normal(point: DVec3, anchor: DVec3, normal: DVec3, radius: f64) -> DVec3 {
    ((point - anchor) / radius + normal).normalize()
}

/// `point` moved radially onto the sphere: `c + r·normalize(p - c)` (Ray Tracing
/// Gems, ch. 6, §6.2.1), relative to the anchor: with `m = (p - c)/r = y + n` and
/// `y = (p - anchor)/r`, the point is `p - r·(|m| - 1)·m/|m|`, and `|m| - 1 =
/// y·(y + 2n) / (|m| + 1)` cancels nothing, where `c + r·m/|m|` would round the
/// surface to the precision of a centre far away. A point at the centre (never a hit)
/// is returned unchanged.
pub fn project_onto_sphere(point: DVec3, anchor: DVec3, normal: DVec3, radius: f64) -> DVec3 {
    let y = (point - anchor) / radius;
    let m = y + normal;
    let length = m.length();
    if length > 0.0 {
        point - m * (y.dot(y + 2.0 * normal) / (length * (length + 1.0)) * radius)
    } else {
        point
    }
}

/// `point` projected orthogonally onto the plane `N·p = d`: `p - (N·p - d)·N`
/// (Ray Tracing Gems, ch. 6, §6.2.1).
pub fn project_onto_plane(point: DVec3, normal: DVec3, offset: f64) -> DVec3 {
    point - normal * (normal.dot(point) - offset)
}

/// Ray/sphere intersection in the numerically stable form of Haines, Günther and
/// Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing
/// Gems, ch. 7): the lecture's `s = -u·ΔP ± sqrt((u·ΔP)² - |ΔP|² + r²)` with the
/// discriminant taken from the ray's closest approach and the smaller root as `c/q`,
/// solved relative to the sphere's anchor (its point nearest the origin, with outward
/// normal `normal`; [`crate::scene::sphere_anchor`]) in units of its radius. With
/// `g = (o - anchor)/r`, `ΔP/r = g + n`, and
///
/// - `b = -(g·u + n·u)`,
/// - the discriminant `1 - |(g + n)⊥|² = (n·u)² - g⊥·(g⊥ + 2n)`, `g⊥ = g - (g·u)u`,
/// - `c = |g + n|² - 1 = g·(g + 2n)`,
///
/// none of which is the square of the distance to the centre: a sphere of radius 1e10
/// resting on the origin keeps the precision of the scene around its anchor, where
/// `|ΔP|² - r²` would keep that of a point 1e10 away (ulp 1024 in f32) and lose the
/// surface entirely (`docs/numerics.md`). For a ray that can hit, `|g⊥| <= 2`, so the
/// discriminant's terms are at most 8 and lose at most 3 bits more than Haines's.
pub fn intersect_sphere(
    ray: &Ray,
    anchor: DVec3,
    normal: DVec3,
    radius: f64,
    t_max: f64,
) -> Option<f64> {
    let u = ray.direction;
    let g = (ray.origin - anchor) / radius;
    let g_along = g.dot(u);
    let n_along = normal.dot(u);
    let b = -(g_along + n_along);
    let g_perp = g - u * g_along;
    let discriminant = n_along * n_along - g_perp.dot(g_perp + 2.0 * normal);
    // NaN (from an overflowing square) is a miss, like a negative discriminant.
    if discriminant.is_nan() || discriminant < 0.0 {
        return None;
    }
    let c = g.dot(g + 2.0 * normal);
    // sign(b) with sign(0) = +1, as the WGSL twin computes it.
    let sign_b = if b >= 0.0 { 1.0 } else { -1.0 };
    let q = b + sign_b * discriminant.sqrt();
    if q == 0.0 {
        return None;
    }
    let (r0, r1) = (c / q * radius, q * radius);
    nearest_root(r0.min(r1), r0.max(r1), t_max)
}

/// The nearer of two sorted roots `t0 <= t1` that lies in (0, `t_max`).
pub fn nearest_root(t0: f64, t1: f64, t_max: f64) -> Option<f64> {
    if t0 > 0.0 && t0 < t_max {
        Some(t0)
    } else if t1 > 0.0 && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// Ray/plane intersection from the lecture: with `N · P = d`, `s = (d - N·P0) / (N·u)`.
/// A ray parallel to the plane (`N·u = 0`) misses it, and so does a nearly parallel one
/// whose `s` overflows: an infinite or NaN `s` fails the range test `0 < s < t_max`
/// (with `t_max` at most +∞), so no division blow-up becomes a hit.
pub fn intersect_plane(ray: &Ray, normal: DVec3, offset: f64, t_max: f64) -> Option<f64> {
    let denominator = normal.dot(ray.direction);
    if denominator == 0.0 {
        return None;
    }
    let t = (offset - normal.dot(ray.origin)) / denominator;
    (t > 0.0 && t < t_max).then_some(t)
}

/// Ray/polygon intersection as in the lecture: the plane first, then an inside test of
/// the hit point against the polygon projected along its dominant normal axis.
pub fn intersect_polygon(
    ray: &Ray,
    plane: &PolygonPlane,
    vertices: &[DVec3],
    t_max: f64,
) -> Option<f64> {
    let t = intersect_plane(ray, plane.normal, plane.offset, t_max)?;
    let point = ray.at(t);
    point_in_polygon(point, vertices, plane.dropped_axis).then_some(t)
}

/// Even-odd (crossing number) inside test in the projection that drops `dropped_axis`
/// (Haines, "Point in Polygon Strategies", Graphics Gems IV): counts the polygon edges
/// crossed by a ray from the point along +u. Works for convex and concave polygons.
pub fn point_in_polygon(point: DVec3, vertices: &[DVec3], dropped_axis: u32) -> bool {
    let (pu, pv) = project_to_plane(point, dropped_axis);
    let mut inside = false;
    let mut previous = project_to_plane(vertices[vertices.len() - 1], dropped_axis);
    for vertex in vertices {
        let current = project_to_plane(*vertex, dropped_axis);
        if edge_crosses((pu, pv), previous, current) {
            inside = !inside;
        }
        previous = current;
    }
    inside
}

/// Whether the edge from `previous` to `current` (projected, `(u, v)`) crosses the ray
/// from `point` along +u: one step of [`point_in_polygon`]'s even-odd rule. An edge
/// that does not straddle the point's `v` never crosses.
pub fn edge_crosses(point: (f64, f64), previous: (f64, f64), current: (f64, f64)) -> bool {
    let (pu, pv) = point;
    if (current.1 > pv) == (previous.1 > pv) {
        return false;
    }
    let crossing_u =
        current.0 + (pv - current.1) * (previous.0 - current.0) / (previous.1 - current.1);
    pu < crossing_u
}

/// The per-ray part of the watertight ray/triangle test (Woop, Benthin and Wald,
/// "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013, Listing 1): the
/// permutation that makes the largest direction component z (x and y follow it
/// cyclically, swapped when it is negative to keep the winding), and the shear.
/// Computed once per query ([`shear_ray`]) and reused by every triangle test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearedRay {
    /// The ray's origin.
    pub origin: DVec3,
    /// `kx, ky, kz`: the component of the original frame that becomes x, y and z.
    pub axes: [usize; 3],
    /// `shear_x, shear_y, shear_z`.
    pub shear: DVec3,
}

/// The [`ShearedRay`] of `ray`.
pub fn shear_ray(ray: &Ray) -> ShearedRay {
    let d = ray.direction;
    let abs = d.abs();
    let kz = if abs.x > abs.y {
        if abs.x > abs.z { 0 } else { 2 }
    } else if abs.y > abs.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let axes = [kx, ky, kz];
    let p = permute(d, axes);
    ShearedRay {
        origin: ray.origin,
        axes,
        shear: DVec3::new(p.x / p.z, p.y / p.z, 1.0 / p.z),
    }
}

/// `v` with its components reordered to (`kx`, `ky`, `kz`).
pub fn permute(v: DVec3, axes: [usize; 3]) -> DVec3 {
    DVec3::new(v[axes[0]], v[axes[1]], v[axes[2]])
}

/// Watertight ray/triangle intersection of Woop, Benthin and Wald, "Watertight
/// Ray/Triangle Intersection" (JCGT 2(1), 2013), Listing 1.
///
/// The triangle is translated to the ray origin and sheared so that the ray becomes
/// the +z axis of a permuted coordinate frame (`ray`, from [`shear_ray`]). The 2D edge
/// functions `U`, `V`, `W` of the sheared vertices then decide the hit. Two triangles
/// sharing an edge evaluate that edge's function from the same sheared vertices with
/// the same operations in swapped order, so they get exactly opposite values: a ray
/// can never pass between them. A value of exactly 0 counts as inside (the test rejects
/// only mixed signs), so a ray through a shared edge or vertex hits every triangle
/// there and the nearest `t` wins. The paper re-evaluates zero edge functions in double
/// precision to learn their true sign; neither backend has a wider type (the CPU
/// already works in `f64`, WGSL has no `f64`), and treating 0 as inside keeps the test
/// watertight without it.
///
/// Returns the ray parameter in (0, `t_max`); a non-finite `t` is a miss.
pub fn intersect_triangle(ray: &ShearedRay, vertices: &[DVec3; 3], t_max: f64) -> Option<f64> {
    let (shear_x, shear_y, shear_z) = (ray.shear.x, ray.shear.y, ray.shear.z);
    let a = permute(vertices[0] - ray.origin, ray.axes);
    let b = permute(vertices[1] - ray.origin, ray.axes);
    let c = permute(vertices[2] - ray.origin, ray.axes);
    let (ax, ay) = (a.x - shear_x * a.z, a.y - shear_y * a.z);
    let (bx, by) = (b.x - shear_x * b.z, b.y - shear_y * b.z);
    let (cx, cy) = (c.x - shear_x * c.z, c.y - shear_y * c.z);
    // Scaled barycentric coordinates (2D edge functions).
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let determinant = u + v + w;
    if determinant == 0.0 {
        return None;
    }
    // Normalised weights first, as the GPU twin (where `u·a.z`, a product of three
    // coordinates, overflowed f32 for triangles beyond about 7e12 from the origin).
    let inverse = 1.0 / determinant;
    let t = shear_z * ((u * inverse) * a.z + (v * inverse) * b.z + (w * inverse) * c.z);
    (t > 0.0 && t < t_max).then_some(t)
}

/// Moves a ray origin off a surface so the new ray does not hit that surface again:
/// the method of Wächter and Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection" (Ray Tracing Gems, ch. 6). The point moves along `normal` (which
/// must point to the side the new ray leaves on) by a fixed number of units in the last
/// place of each coordinate, so the offset scales with the point's magnitude; near the
/// origin (within `scale/32`), where ulps become tiny, a small absolute offset
/// `scale/65536` is used instead, `scale` being [`crate::accel::ray_offset_scale`] (1 in scenes of
/// unit size and beyond: the published constants).
///
/// The units in the last place are those of the coordinate's `f32` rounding, the GPU's
/// (`offset_ray_origin` in `shaders/intersect.wgsl`): the CPU moves its `f64` point by
/// the same displacement the GPU's bit arithmetic makes, so both backends start every
/// new ray from the same point to within `f32` rounding. An offset of 256 `f64` ulps
/// (2^29 times smaller) made the two trace different rays: after a bounce on the far
/// side of a unit sphere the GPU's ray started 6e-5 away from the CPU's, which moved
/// a later hit near a point light by as much and its `1/d²` by 5%
/// (`campaign-3-39192`, docs/fuzzing.md). A coordinate beyond `f32`'s range (no GPU
/// twin) moves by 256 `f64` ulps.
pub fn offset_ray_origin(point: DVec3, normal: DVec3, scale: f64) -> DVec3 {
    const ORIGIN: f64 = 1.0 / 32.0;
    const FLOAT_SCALE: f64 = 1.0 / 65_536.0;
    const INT_SCALE: f64 = 256.0;
    let offset_component = |p: f64, n: f64| -> f64 {
        if p.abs() < ORIGIN * scale {
            return p + FLOAT_SCALE * scale * n;
        }
        // The GPU's `vec3<i32>(256.0 * n)`: truncated towards zero.
        let ulps = (INT_SCALE * n) as i64;
        let rounded = p as f32;
        if rounded.is_finite() {
            let bits = i64::from(rounded.to_bits() as i32);
            let moved = if rounded < 0.0 {
                bits - ulps
            } else {
                bits + ulps
            };
            let moved = f32::from_bits(moved as i32 as u32);
            if moved.is_finite() {
                return p + (f64::from(moved) - f64::from(rounded));
            }
        }
        let bits = p.to_bits() as i64;
        let moved = if p < 0.0 { bits - ulps } else { bits + ulps };
        f64::from_bits(moved as u64)
    };
    DVec3::new(
        offset_component(point.x, normal.x),
        offset_component(point.y, normal.y),
        offset_component(point.z, normal.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Image, Material, TextureMapping, TextureTransform, polygon_plane};
    use crate::texture;

    fn ray(origin: DVec3, direction: DVec3) -> Ray {
        Ray {
            origin,
            direction: direction.normalize(),
        }
    }

    /// [`intersect_sphere`] of the sphere (`center`, `radius`) through its anchor.
    fn sphere_at(ray: &Ray, center: DVec3, radius: f64, t_max: f64) -> Option<f64> {
        let (anchor, normal) = crate::scene::sphere_anchor(center, radius);
        intersect_sphere(ray, anchor, normal, radius, t_max)
    }

    #[test]
    fn sphere_hit_from_outside_and_inside() {
        let r = ray(DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
        let t = sphere_at(&r, DVec3::ZERO, 1.0, f64::INFINITY).expect("hit");
        assert!((t - 4.0).abs() < 1e-12);
        let inside = ray(DVec3::ZERO, DVec3::X);
        let t = sphere_at(&inside, DVec3::ZERO, 2.0, f64::INFINITY).expect("hit");
        assert!((t - 2.0).abs() < 1e-12);
        let miss = ray(DVec3::new(0.0, 1.5, 5.0), DVec3::NEG_Z);
        assert!(sphere_at(&miss, DVec3::ZERO, 1.0, f64::INFINITY).is_none());
        // Behind the origin: no hit.
        let away = ray(DVec3::new(0.0, 0.0, 5.0), DVec3::Z);
        assert!(sphere_at(&away, DVec3::ZERO, 1.0, f64::INFINITY).is_none());
        // t_max excludes the hit.
        assert!(sphere_at(&r, DVec3::ZERO, 1.0, 3.9).is_none());
    }

    #[test]
    fn sphere_far_away_keeps_precision() {
        // A unit sphere 1e6 units away: the textbook form loses most digits here.
        let r = ray(DVec3::new(0.0, 0.0, 1e6), DVec3::NEG_Z);
        let t = sphere_at(&r, DVec3::ZERO, 1.0, f64::INFINITY).expect("hit");
        assert!((t - (1e6 - 1.0)).abs() < 1e-8, "t = {t}");
    }

    #[test]
    fn huge_sphere_resting_on_the_origin_keeps_precision() {
        // Radius 1e20, centre (0, -1e20, 0): |ΔP|² - r² would be 1e40 ± 1e24 in f64.
        // From (0, 3, 4) towards the origin the hit is the origin itself, t = 5.
        let r = ray(DVec3::new(0.0, 3.0, 4.0), DVec3::new(0.0, -3.0, -4.0));
        let t = sphere_at(&r, DVec3::new(0.0, -1e20, 0.0), 1e20, f64::INFINITY).expect("hit");
        assert!((t - 5.0).abs() < 1e-12, "t = {t}");
        let (anchor, normal) = crate::scene::sphere_anchor(DVec3::new(0.0, -1e20, 0.0), 1e20);
        let n = sphere_normal(r.at(t), anchor, normal, 1e20);
        assert!((n - DVec3::Y).length() < 1e-12, "{n}");
        // A point 1 unit above the surface is projected onto it, not 1e4 away.
        let p = project_onto_sphere(DVec3::new(2.0, 1.0, 0.0), anchor, normal, 1e20);
        assert!((p - DVec3::new(2.0, 0.0, 0.0)).length() < 1e-12, "{p}");
    }

    #[test]
    fn plane_hit_and_parallel_miss() {
        let r = ray(DVec3::new(0.0, 3.0, 0.0), DVec3::new(1.0, -1.0, 0.0));
        let t = intersect_plane(&r, DVec3::Y, 1.0, f64::INFINITY).expect("hit");
        assert!((r.at(t).y - 1.0).abs() < 1e-12);
        assert!((t - 2.0 * 2f64.sqrt()).abs() < 1e-12);
        let parallel = ray(DVec3::new(0.0, 3.0, 0.0), DVec3::X);
        assert!(intersect_plane(&parallel, DVec3::Y, 1.0, f64::INFINITY).is_none());
    }

    #[test]
    fn concave_polygon_inside_test() {
        // An L shape in the z = 0 plane: the notch at (1.5, 1.5) is outside.
        let l_shape = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let plane = polygon_plane(&l_shape).expect("planar");
        assert_eq!(plane.dropped_axis, 2);
        assert!((plane.normal - DVec3::Z).length() < 1e-12);
        let cast = |x: f64, y: f64| {
            let r = ray(DVec3::new(x, y, 1.0), DVec3::NEG_Z);
            intersect_polygon(&r, &plane, &l_shape, f64::INFINITY)
        };
        assert_eq!(cast(0.5, 0.5), Some(1.0));
        assert_eq!(cast(1.5, 0.5), Some(1.0));
        assert_eq!(cast(0.5, 1.5), Some(1.0));
        assert_eq!(cast(1.5, 1.5), None);
        assert_eq!(cast(-0.5, 0.5), None);
    }

    #[test]
    fn triangle_hit_and_edges() {
        let tri = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let r = ray(DVec3::new(0.25, 0.25, 2.0), DVec3::NEG_Z);
        assert_eq!(
            intersect_triangle(&shear_ray(&r), &tri, f64::INFINITY),
            Some(2.0)
        );
        let outside = ray(DVec3::new(0.75, 0.75, 2.0), DVec3::NEG_Z);
        assert!(intersect_triangle(&shear_ray(&outside), &tri, f64::INFINITY).is_none());
    }

    /// The 12 triangles of the cube [-1, 1]³, wound outwards.
    fn cube_triangles(scale: f64) -> Vec<[DVec3; 3]> {
        let corner = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            ) * scale
        };
        // Each face as four corner indices in counter-clockwise order seen from outside.
        let faces = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        faces
            .iter()
            .flat_map(|f| {
                [
                    [corner(f[0]), corner(f[1]), corner(f[2])],
                    [corner(f[0]), corner(f[2]), corner(f[3])],
                ]
            })
            .collect()
    }

    #[test]
    fn triangle_hit_matches_the_exact_parameter() {
        let tri = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(2.0, -1.0, 0.0),
            DVec3::new(-1.0, 2.0, 0.0),
        ];
        for direction in [
            DVec3::NEG_Z,
            DVec3::new(0.3, -0.2, -1.0),
            DVec3::new(-0.2, 0.1, -1.0),
        ] {
            let r = ray(DVec3::new(0.1, 0.2, 3.0), direction);
            let t = intersect_triangle(&shear_ray(&r), &tri, f64::INFINITY).expect("hit");
            assert!(r.at(t).z.abs() < 1e-14, "{direction}");
            // Both windings hit (no back-face culling).
            let flipped = [tri[0], tri[2], tri[1]];
            assert_eq!(
                intersect_triangle(&shear_ray(&r), &flipped, f64::INFINITY),
                Some(t)
            );
        }
        // A ray in the triangle's plane misses; so does one aimed away.
        assert!(
            intersect_triangle(
                &shear_ray(&ray(DVec3::new(-5.0, 0.0, 0.0), DVec3::X)),
                &tri,
                1e9
            )
            .is_none()
        );
        assert!(
            intersect_triangle(
                &shear_ray(&ray(DVec3::new(0.0, 0.0, 3.0), DVec3::Z)),
                &tri,
                1e9
            )
            .is_none()
        );
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_never_slip_through_a_closed_cube() {
        for scale in [1e-4, 1.0, 1e4] {
            let cube = cube_triangles(scale);
            // Targets exactly on edges (midpoints and off-centre points) and vertices.
            let mut targets = Vec::new();
            for i in 0..8usize {
                let c = |bit: usize| if i & bit == 0 { -scale } else { scale };
                targets.push(DVec3::new(c(1), c(2), c(4)));
                for fraction in [0.0, 0.3, -0.7] {
                    targets.push(DVec3::new(fraction * scale, c(2), c(4)));
                    targets.push(DVec3::new(c(1), fraction * scale, c(4)));
                    targets.push(DVec3::new(c(1), c(2), fraction * scale));
                }
            }
            // From inside every ray must hit; from outside, rays come from beyond the
            // target on a line through an interior point, so they enter the cube there
            // (a silhouette edge could be missed legitimately).
            let interior = [
                DVec3::ZERO,
                DVec3::new(0.31, -0.52, 0.13),
                DVec3::new(-0.77, 0.05, 0.6),
            ];
            for inside in interior {
                let inside = inside * scale;
                for target in &targets {
                    for origin in [inside, *target + (*target - inside) * 3.7] {
                        let r = ray(origin, *target - origin);
                        let hit = cube.iter().any(|tri| {
                            intersect_triangle(&shear_ray(&r), tri, f64::INFINITY).is_some()
                        });
                        assert!(
                            hit,
                            "scale {scale}: ray {origin} -> {target} slipped through"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn offset_moves_by_the_gpus_f32_ulps() {
        // The GPU twin's arithmetic on f32 bit patterns, written out.
        let gpu = |p: f32, n: f32| -> f32 {
            let ulps = (256.0 * n) as i32;
            let step = if p < 0.0 { -ulps } else { ulps };
            f32::from_bits((p.to_bits() as i32).wrapping_add(step) as u32)
        };
        let n = DVec3::new(0.48, -0.6, 0.64);
        for p in [
            DVec3::new(1.0, -2.0, 0.75),
            DVec3::new(-0.95, -1.999, 0.3),
            DVec3::new(1e4, 3.5e-2, -7e6),
        ] {
            let moved = offset_ray_origin(p, n, 1.0);
            for k in 0..3 {
                let (p32, n32) = (p[k] as f32, n[k] as f32);
                let expected = f64::from(gpu(p32, n32)) - f64::from(p32);
                assert_eq!(moved[k] - p[k], expected, "{p} component {k}");
            }
        }
        // Beyond f32's range the offset falls back to f64 ulps, still off the surface.
        let far = offset_ray_origin(DVec3::new(1e300, 0.0, 0.0), DVec3::X, 1.0);
        assert!(far.x > 1e300);
    }

    #[test]
    fn offset_moves_off_the_surface_at_every_scale() {
        for scale in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
            let p = DVec3::new(scale, -scale, 0.5 * scale);
            let moved = offset_ray_origin(p, DVec3::Y, 1.0);
            assert!(moved.y > p.y, "scale {scale}");
            assert_eq!(moved.x, p.x);
            let back = offset_ray_origin(p, DVec3::NEG_Y, 1.0);
            assert!(back.y < p.y, "scale {scale}");
        }
    }

    #[test]
    fn a_mesh_footprint_follows_the_triangles_texture_coordinates() {
        // A triangle in the floor whose coordinates run 4 times faster along x than
        // along z (u = 4x, v = z): looked at along +x the long axis is u, along +z v.
        let vertices = [DVec3::ZERO, DVec3::X, DVec3::Z];
        let uv = [DVec2::ZERO, DVec2::new(4.0, 0.0), DVec2::new(0.0, 1.0)];
        let density = triangle_uv_density(&vertices, &uv);
        assert!((density - 4.0).abs() < 1e-12);
        let material = Material {
            albedo_texture: Some(0),
            texture_mapping: TextureMapping::Uv,
            ..Material::lambert(DVec3::ONE)
        };
        let image = Image {
            path: "<test>".into(),
            width: 64,
            height: 64,
            texels: vec![[1.0; 4]; 64 * 64],
        };
        let footprint = |direction: DVec3| {
            let axis = footprint_axis(direction, DVec3::Y);
            let uv_axis = triangle_uv_axis(&vertices, &uv, axis);
            let cone = texture::ConeFootprint::new(
                1.0 / 256.0,
                direction,
                DVec3::Y,
                [density, 0.0],
                [uv_axis, DVec2::ZERO],
            )
            .with_max_probes(crate::scene::MAX_TEXTURE_PROBES);
            texture::texel_footprint(&material, &TextureTransform::IDENTITY, &image, 6, &cone)
        };
        let along = DVec3::new(0.5f64.sqrt(), -0.5f64.sqrt(), 0.0);
        let x = footprint(along);
        // Along x: the long axis √2/256 world units = 4·√2/256 of u = √2 texels, the
        // width 1/256 along z = 1/4 texel... ratio 4√2; the probes span √2 times the
        // long axis (PROBE_SPAN): 2 texels, 8 probes.
        assert!(x.axis.y.abs() < 1e-12 && x.axis.x > 0.0, "{x:?}");
        assert!((x.axis.x * 64.0 - 2.0 * 4.0 * 64.0 / 256.0).abs() < 1e-9);
        assert_eq!(x.probes, 8);
        let z = footprint(DVec3::new(0.0, -0.5f64.sqrt(), 0.5f64.sqrt()));
        // Along z: √2/256 of v (0.35 texel) long, 1 texel wide: the width rules.
        assert_eq!(z.probes, 1);
    }
}
