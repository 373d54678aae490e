// Ray/primitive intersection. CPU twin: src/cpu/intersect.rs (same function names).
// Every routine returns the ray parameter of the nearest hit in (0, t_max), or NO_HIT.

#import types
#import records
#import bindings
#import budget
#import math
#import instance

const NO_HIT: f32 = -1.0;

struct Ray {
    origin: vec3<f32>,
    direction: vec3<f32>,
}

struct Hit {
    t: f32,
    // Unit geometric normal as the shape defines it, not yet flipped towards the ray.
    normal: vec3<f32>,
    material: u32,
    found: bool,
    // The hit point re-projected onto the surface (Ray Tracing Gems, ch. 6, §6.2.1).
    position: vec3<f32>,
    // The primitive hit (a PrimRef).
    prim: u32,
    // Unit shading normal on the side of `normal`: a mesh triangle's interpolated
    // vertex normals, else `normal`.
    shading_normal: vec3<f32>,
    // A mesh triangle's interpolated texture coordinates, else (0, 0).
    uv: vec2<f32>,
    // The second set of texture coordinates, likewise.
    uv1: vec2<f32>,
    // A mesh triangle's interpolated vertex colour (RGBA), else opaque white.
    color: vec4<f32>,
    // A mesh triangle's interpolated tangent (w: the bitangent's handedness), else 0.
    tangent: vec4<f32>,
    // Barycentric coordinates in a triangle, else (1, 0, 0).
    barycentrics: vec3<f32>,
    // The instance of an instanced mesh's triangle (its record's node index; `prim`
    // then names the mesh's triangle), else NO_INSTANCE.
    instance: u32,
    // A mesh triangle's texture-coordinate area per world area, sets 0 and 1 (uv_density),
    // else 0: the texture level of detail's density term.
    uv_density: vec2<f32>,
    // The change of a mesh triangle's texture coordinates per unit of world distance
    // along the footprint's long axis (the ray projected onto the surface), sets 0 (xy)
    // and 1 (zw), else 0: the anisotropic texture lookup's direction (triangle_uv_axis).
    uv_axis: vec4<f32>,
}

// A hit without vertex attributes: shading normal = geometric normal, texture
// coordinates (0, 0), colour opaque white.
fn flat_hit(prim: u32, t: f32, normal: vec3<f32>, material: u32, position: vec3<f32>) -> Hit {
    return Hit(t, normal, material, true, position, prim, normal, vec2<f32>(0.0),
               vec2<f32>(0.0), vec4<f32>(1.0), vec4<f32>(0.0), vec3<f32>(1.0, 0.0, 0.0), NO_INSTANCE,
               vec2<f32>(0.0), vec4<f32>(0.0));
}

//#if MESH_ATTRIBUTES
// The triangle a hit is on, in world space: the scene's own, or an instanced mesh's
// moved by its instance.
fn world_triangle(prim: u32, instance: u32) -> Triangle {
    //#if INSTANCES
    if instance != NO_INSTANCE {
        return instance_world_triangle(prim_index(prim), instance);
    }
    //#endif
    return triangles[prim_index(prim)];
}

// A triangle's shading attributes in world space: an instanced mesh's normals through
// the normal matrix, normalised (one that vanishes becomes `facing`, the world winding
// normal), corners 1 and 2 (of every attribute) swapped under a mirroring transform. CPU twin:
// Instance::world_triangle.
fn world_attributes(index: u32, instance: u32, facing: vec3<f32>) -> TriangleAttributes {
    var attributes = triangle_attributes[index];
    //#if INSTANCES
    if instance != NO_INSTANCE {
        let placed = load_instance(instance);
        let n0 = instance_normal(placed, attributes.n0);
        let n1 = instance_normal(placed, attributes.n1);
        let n2 = instance_normal(placed, attributes.n2);
        attributes.n0 = select(facing, normalize(n0), dot(n0, n0) > 0.0);
        let m1 = select(facing, normalize(n1), dot(n1, n1) > 0.0);
        let m2 = select(facing, normalize(n2), dot(n2, n2) > 0.0);
        attributes.n1 = select(m1, m2, placed.mirrored);
        attributes.n2 = select(m2, m1, placed.mirrored);
        let uv1 = attributes.uv01.zw;
        attributes.uv01 = vec4<f32>(attributes.uv01.xy, select(uv1, attributes.uv2, placed.mirrored));
        attributes.uv2 = select(attributes.uv2, uv1, placed.mirrored);
        let second1 = attributes.uv1_01.zw;
        attributes.uv1_01 = vec4<f32>(attributes.uv1_01.xy, select(second1, attributes.uv1_2, placed.mirrored));
        attributes.uv1_2 = select(attributes.uv1_2, second1, placed.mirrored);
        let c1 = attributes.c1;
        attributes.c1 = select(c1, attributes.c2, placed.mirrored);
        attributes.c2 = select(attributes.c2, c1, placed.mirrored);
        // Tangents through the linear part, renormalised (zero where they vanish), the
        // handedness flipped under a mirroring transform. CPU twin: world_tangent.
        let t1 = world_tangent(placed, attributes.t1);
        let t2 = world_tangent(placed, attributes.t2);
        attributes.t0 = world_tangent(placed, attributes.t0);
        attributes.t1 = select(t1, t2, placed.mirrored);
        attributes.t2 = select(t2, t1, placed.mirrored);
    }
    //#endif
    return attributes;
}
//#endif

//#if TRIANGLES
// The barycentric coordinates of `p` (on the triangle's plane) in the triangle
// (v0, v1, v2), clamped to it and summing to 1 (Ericson, "Real-Time Collision
// Detection", §3.4). CPU twin: triangle_barycentrics.
// The vectors are first scaled by the power of two of scale_to_unit (exact), so that
// the products of four coordinates neither overflow (edges beyond about 4e9) nor
// underflow (edges below about 1e-10).
fn triangle_barycentrics(p: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec3<f32> {
    let exponent = scale_to_unit(max(max_component(abs(v1 - v0)), max_component(abs(v2 - v0))));
    let e1 = ldexp(v1 - v0, vec3<i32>(exponent));
    let e2 = ldexp(v2 - v0, vec3<i32>(exponent));
    let q = ldexp(p - v0, vec3<i32>(exponent));
    let d00 = dot(e1, e1);
    let d01 = dot(e1, e2);
    let d11 = dot(e2, e2);
    let d20 = dot(q, e1);
    let d21 = dot(q, e2);
    let denominator = d00 * d11 - d01 * d01;
    if !(denominator > 0.0) {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    let b = max(vec3<f32>(1.0 - v - w, v, w), vec3<f32>(0.0));
    let sum = b.x + b.y + b.z;
    return select(vec3<f32>(1.0, 0.0, 0.0), b / sum, sum > 0.0);
}
//#endif

// Whether a camera ray (`depth` 0) along `direction` passes through the back face of
// a material that culls back faces (glTF doubleSided false, glTF 2.0 §3.9.5) at a hit
// of geometric normal `normal`. CPU twin: culls_back_face.
fn culls_back_face(cull_back_faces: bool, depth: u32, direction: vec3<f32>, normal: vec3<f32>) -> bool {
    return cull_back_faces && depth == 0u && dot(direction, normal) > 0.0;
}

//#if MESH_ATTRIBUTES
// Fills a mesh triangle hit's shading normal (the interpolated vertex normals, kept
// only where they are not degenerate and face the geometric normal's side), texture
// coordinates and vertex colour from its world-space `attributes`. CPU twin: triangle_hit.
fn apply_triangle_attributes(hit: ptr<function, Hit>, attributes: TriangleAttributes) {
    let b = (*hit).barycentrics;
    if attributes.has_normals != 0u {
        let interpolated = attributes.n0 * b.x + attributes.n1 * b.y + attributes.n2 * b.z;
        let length_squared = dot(interpolated, interpolated);
        if length_squared > 0.0 {
            let shading = interpolated * inverseSqrt(length_squared);
            if dot(shading, (*hit).normal) > 0.0 {
                (*hit).shading_normal = shading;
            }
        }
    }
    if attributes.has_uvs != 0u {
        (*hit).uv = attributes.uv01.xy * b.x + attributes.uv01.zw * b.y + attributes.uv2 * b.z;
    }
    if attributes.has_uvs1 != 0u {
        (*hit).uv1 = attributes.uv1_01.xy * b.x + attributes.uv1_01.zw * b.y + attributes.uv1_2 * b.z;
    }
    if attributes.has_colors != 0u {
        (*hit).color = attributes.c0 * b.x + attributes.c1 * b.y + attributes.c2 * b.z;
    }
    if attributes.has_tangents != 0u {
        (*hit).tangent = attributes.t0 * b.x + attributes.t1 * b.y + attributes.t2 * b.z;
    }
}

// Where the shadow rays of a smooth-shaded mesh hit start: the hit point lifted off its
// flat triangle towards the curved surface of the vertex normals, P' = P -
// Σ bᵢ·min(0, (P - Vᵢ)·nᵢ)·nᵢ with the normals turned to the side of `facing` (Hanika,
// "Hacking the Shadow Terminator", Ray Tracing Gems II, ch. 4). CPU twin:
// shadow_terminator_point.
fn shadow_terminator_point(hit: Hit, facing: vec3<f32>) -> vec3<f32> {
    if prim_kind(hit.prim) != PRIM_TRIANGLE {
        return hit.position;
    }
    let triangle = world_triangle(hit.prim, hit.instance);
    if triangle.attributes == NO_ATTRIBUTES {
        return hit.position;
    }
    let attributes = world_attributes(triangle.attributes, hit.instance, hit.normal);
    if attributes.has_normals == 0u {
        return hit.position;
    }
    let sign = select(1.0, -1.0, dot(facing, hit.normal) < 0.0);
    let p = hit.position;
    let b = hit.barycentrics;
    let n0 = attributes.n0 * sign;
    let n1 = attributes.n1 * sign;
    let n2 = attributes.n2 * sign;
    var lifted = p;
    lifted -= n0 * (min(dot(p - triangle.v0, n0), 0.0) * b.x);
    lifted -= n1 * (min(dot(p - triangle.v1, n1), 0.0) * b.y);
    lifted -= n2 * (min(dot(p - triangle.v2, n2), 0.0) * b.z);
    return lifted;
}
//#endif

fn ray_at(ray: Ray, t: f32) -> vec3<f32> {
    return ray.origin + ray.direction * t;
}

//#if TRIANGLES
// The power of two 2^k (returned as k) that brings `largest` (finite, >= 0) into
// [0.5, 1): scaling by it is exact, and keeps squares and products of a few such
// values inside f32's range. 0 for 0.
fn scale_to_unit(largest: f32) -> i32 {
    return -frexp(largest).exp;
}

// The unit normal (v1 - v0) × (v2 - v0), normalized, with the edges and then the cross
// product scaled by powers of two (scale_to_unit) before their squares are taken: a
// ground triangle of corners ±2.2e9 (|cross|² beyond f32's 3.4e38) and one of size
// 1e-15 (|cross|² below its smallest number) had no normal.
fn triangle_normal(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec3<f32> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let edges = scale_to_unit(max(max_component(abs(e1)), max_component(abs(e2))));
    let c = cross(ldexp(e1, vec3<i32>(edges)), ldexp(e2, vec3<i32>(edges)));
    return normalize(ldexp(c, vec3<i32>(scale_to_unit(max_component(abs(c))))));
}
//#endif

//#if SPHERES
// The unit outward normal at p of the sphere of radius `radius` through `anchor`, whose
// outward normal there is `normal`: (p - c)/r = (p - anchor)/r + normal, normalized.
fn sphere_normal(p: vec3<f32>, anchor: vec3<f32>, normal: vec3<f32>, radius: f32) -> vec3<f32> {
    return normalize((p - anchor) / radius + normal);
}

// A point moved radially onto the sphere, c + r·normalize(p - c) (Wächter and Binder,
// Ray Tracing Gems, ch. 6, §6.2.1): its error is then relative to its own magnitude,
// not to the length of the ray that found it, as the ulp-scaled offset assumes.
// Relative to the anchor: with y = (p - anchor)/r and m = y + n, p - r·(|m| - 1)·m/|m|,
// where |m| - 1 = y·(y + 2n)/(|m| + 1) cancels nothing.
fn project_onto_sphere(p: vec3<f32>, anchor: vec3<f32>, normal: vec3<f32>, radius: f32) -> vec3<f32> {
    let y = (p - anchor) / radius;
    let m = y + normal;
    let len = length(m);
    if len > 0.0 {
        return p - m * (dot(y, y + 2.0 * normal) / (len * (len + 1.0)) * radius);
    }
    return p;
}
//#endif

// A point projected orthogonally onto the plane N·p = d: p - (N·p - d)·N (ibid.).
fn project_onto_plane(p: vec3<f32>, normal: vec3<f32>, offset: f32) -> vec3<f32> {
    return p - normal * (dot(normal, p) - offset);
}

//#if SPHERES
// Picks the nearest root in (0, t_max) of two sorted roots.
fn nearest_root(t0: f32, t1: f32, t_max: f32) -> f32 {
    if t0 > 0.0 && t0 < t_max {
        return t0;
    }
    if t1 > 0.0 && t1 < t_max {
        return t1;
    }
    return NO_HIT;
}
//#endif

//#if SPHERES
// Ray/sphere in the stable form of Haines, Günther and Akenine-Möller, "Precision
// Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7): the lecture's
// s = -u·ΔP ± sqrt((u·ΔP)² - |ΔP|² + r²), with the discriminant taken from the ray's
// closest approach and the smaller root as c/q, solved relative to the sphere's anchor
// (its point nearest the origin, outward normal n there) in units of its radius, so that
// no term is the square of the distance to a centre that may be 1e10 away: with
// g = (o - anchor)/r, b = -(g·u + n·u), discriminant (n·u)² - g⊥·(g⊥ + 2n) with
// g⊥ = g - (g·u)u, and c = g·(g + 2n).
fn intersect_sphere(ray: Ray, anchor: vec3<f32>, normal: vec3<f32>, radius: f32, t_max: f32) -> f32 {
    let u = ray.direction;
    let g = (ray.origin - anchor) / radius;
    let g_along = dot(g, u);
    let n_along = dot(normal, u);
    let b = -(g_along + n_along);
    let g_perp = g - u * g_along;
    let discriminant = n_along * n_along - dot(g_perp, g_perp + 2.0 * normal);
    if !(discriminant >= 0.0) {
        return NO_HIT;
    }
    let c = dot(g, g + 2.0 * normal);
    let sign_b = select(-1.0, 1.0, b >= 0.0);
    let q = b + sign_b * sqrt(discriminant);
    if q == 0.0 {
        return NO_HIT;
    }
    let r0 = c / q * radius;
    let r1 = q * radius;
    return nearest_root(min(r0, r1), max(r0, r1), t_max);
}
//#endif

//#if PLANES || POLYGONS
// Ray/plane from the lecture: with N·P = d, s = (d - N·P0) / (N·u); parallel rays miss,
// and a nearly parallel ray whose s overflows fails the range test 0 < s < t_max.
fn intersect_plane(ray: Ray, normal: vec3<f32>, offset: f32, t_max: f32) -> f32 {
    let denominator = dot(normal, ray.direction);
    if denominator == 0.0 {
        return NO_HIT;
    }
    let t = (offset - dot(normal, ray.origin)) / denominator;
    if t > 0.0 && t < t_max {
        return t;
    }
    return NO_HIT;
}
//#endif

//#if POLYGONS
// The two coordinates left when `dropped_axis` (0 = x, 1 = y, 2 = z) is removed: (y, z),
// (z, x) or (x, y), picked with selects (lanes testing different polygons agree on the
// code path).
fn project_to_plane(p: vec3<f32>, dropped_axis: u32) -> vec2<f32> {
    // (dropped_axis + 1) mod 3 and (dropped_axis + 2) mod 3 without an integer division
    // (per lane on CPU devices).
    let u_axis = select(dropped_axis + 1u, 0u, dropped_axis == 2u);
    let v_axis = select(2u, dropped_axis - 1u, dropped_axis > 0u);
    return vec2<f32>(vector_component(p, u_axis), vector_component(p, v_axis));
}
//#endif

//#if POLYGONS
// Whether the edge from `previous` to `current` crosses the ray from `point` along +u:
// one step of the even-odd (crossing number) rule (Haines, "Point in Polygon
// Strategies", Graphics Gems IV). Branch-free, so an unrolled test stays straight-line
// code; an edge that does not straddle the point's v (a horizontal one included, whose
// crossing is a division by zero) never counts.
fn edge_crosses(point: vec2<f32>, previous: vec2<f32>, current: vec2<f32>) -> bool {
    let straddles = (current.y > point.y) != (previous.y > point.y);
    // point.x < current.x + (point.y - current.y) (previous.x - current.x) / dy, with
    // both sides multiplied by dy (whose sign flips the comparison): no division.
    let dy = previous.y - current.y;
    let left = (point.x - current.x) * dy;
    let right = (point.y - current.y) * (previous.x - current.x);
    return straddles & select((right < left), (left < right), (dy > 0.0));
}
//#endif

//#if POLYGONS
// Even-odd inside test in the projection that drops the polygon's dominant axis (Haines,
// as above). The vertices come projected already (`polygon_points`, the same f32
// coordinates). Triangles and quads, the common case, take a loop-free path: four edges
// over the vertices with indices clamped to the last one, so a triangle's fourth edge
// joins its last vertex to itself and cannot cross (the even-odd count is unchanged).
fn point_in_polygon(p: vec3<f32>, polygon: Polygon) -> bool {
    // Its edges count against the invocation's budget (budget.wgsl).
    iterations += polygon.vertex_count;
    return inside_polygon_points(project_to_plane(p, polygon.dropped_axis), polygon.first_vertex,
                                 polygon.vertex_count);
}

// The even-odd test of point_in_polygon for `point`, already projected, against the
// `count` projected vertices from `first` in polygon_points.
fn inside_polygon_points(point: vec2<f32>, first: u32, count: u32) -> bool {
    let last = first + count - 1u;
    if count <= 4u {
        let p0 = polygon_point(first);
        let p1 = polygon_point(min(first + 1u, last));
        let p2 = polygon_point(min(first + 2u, last));
        let p3 = polygon_point(last);
        return (edge_crosses(point, p3, p0) != edge_crosses(point, p0, p1))
            != (edge_crosses(point, p1, p2) != edge_crosses(point, p2, p3));
    }
    var inside = false;
    var previous = polygon_point(last);
    for (var i = 0u; i < count; i += 1u) {
        let current = polygon_point(first + i);
        inside = inside != edge_crosses(point, previous, current);
        previous = current;
    }
    return inside;
}
//#endif

//#if POLYGONS
// Ray/polygon as in the lecture: the plane first, then the inside test.
fn intersect_polygon(ray: Ray, polygon: Polygon, t_max: f32) -> f32 {
    let t = intersect_plane(ray, polygon.normal, polygon.offset, t_max);
    if t == NO_HIT || !point_in_polygon(ray_at(ray, t), polygon) {
        return NO_HIT;
    }
    return t;
}
//#endif

// The per-ray part of the watertight ray/triangle test (Woop, Benthin and Wald 2013,
// Listing 1, "calculate dimension where the ray direction is maximal" and "calculate
// shear constants"): the permutation that makes the largest direction component z
// (x and y follow it cyclically, swapped when it is negative to keep the winding), and
// the shear. Computed once per traversal; every triangle test of the ray reuses it.
struct ShearedRay {
    origin: vec3<f32>,
    // The permutation kx, ky, kz as the component index of each of x, y, z.
    axes: vec3<u32>,
    // shear_x, shear_y, shear_z.
    shear: vec3<f32>,
}

// `v` with its components reordered to (kx, ky, kz).
fn permute(v: vec3<f32>, axes: vec3<u32>) -> vec3<f32> {
    return vec3<f32>(vector_component(v, axes.x), vector_component(v, axes.y),
                     vector_component(v, axes.z));
}

fn shear_ray(ray: Ray) -> ShearedRay {
    let d = ray.direction;
    let m = abs(d);
    var kz = 2u;
    if m.x > m.y {
        if m.x > m.z {
            kz = 0u;
        }
    } else if m.y > m.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    let dz = vector_component(d, kz);
    if dz < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let axes = vec3<u32>(kx, ky, kz);
    let p = permute(d, axes);
    return ShearedRay(ray.origin, axes, vec3<f32>(p.x / p.z, p.y / p.z, 1.0 / p.z));
}

//#if TRIANGLES
// Watertight ray/triangle of Woop, Benthin and Wald, "Watertight Ray/Triangle
// Intersection" (JCGT 2(1), 2013), Listing 1: shear the triangle so the ray becomes
// the +z axis of a permuted frame (`ray`, from shear_ray), then test the signs of the
// 2D edge functions U, V, W. Triangles sharing an edge get exactly opposite values for
// it, and 0 counts as inside, so no ray slips between them. The paper's
// double-precision re-test of zero edge functions is left out (WGSL has no f64); see
// the CPU twin's notes.
fn intersect_triangle(ray: ShearedRay, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_max: f32) -> f32 {
    let a = permute(v0 - ray.origin, ray.axes);
    let b = permute(v1 - ray.origin, ray.axes);
    let c = permute(v2 - ray.origin, ray.axes);
    let ax = a.x - ray.shear.x * a.z;
    let ay = a.y - ray.shear.y * a.z;
    let bx = b.x - ray.shear.x * b.z;
    let by = b.y - ray.shear.y * b.z;
    let cx = c.x - ray.shear.x * c.z;
    let cy = c.y - ray.shear.y * c.z;
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return NO_HIT;
    }
    let determinant = u + v + w;
    if determinant == 0.0 {
        return NO_HIT;
    }
    // Normalised weights first: u·a.z is a product of three coordinates, which
    // overflowed f32 for triangles beyond about 7e12 from the ray origin.
    let inverse = 1.0 / determinant;
    let t = ray.shear.z * ((u * inverse) * a.z + (v * inverse) * b.z + (w * inverse) * c.z);
    if t > 0.0 && t < t_max {
        return t;
    }
    return NO_HIT;
}
//#endif

fn prim_kind(prim: u32) -> u32 {
    return prim >> PRIM_KIND_SHIFT;
}

fn prim_index(prim: u32) -> u32 {
    return prim & PRIM_INDEX_MASK;
}

// The ray parameter of primitive `prim`'s nearest hit in (0, t_max), or NO_HIT.
// `sheared` is shear_ray(ray) (used by triangles; ignored without them).
fn intersect_prim(prim: u32, ray: Ray, sheared: ShearedRay, t_max: f32) -> f32 {
    let i = prim_index(prim);
    switch prim_kind(prim) {
        //#if SPHERES
        case PRIM_SPHERE: {
            let sphere = spheres[i];
            return intersect_sphere(ray, sphere.anchor, sphere.normal, sphere.radius, t_max);
        }
        //#endif
        //#if PLANES
        case PRIM_PLANE: {
            let plane = planes[i];
            return intersect_plane(ray, plane.normal, plane.offset, t_max);
        }
        //#endif
        //#if POLYGONS
        case PRIM_POLYGON: {
            return intersect_polygon(ray, polygons[i], t_max);
        }
        //#endif
        //#if TRIANGLES
        case PRIM_TRIANGLE: {
            let triangle = triangles[i];
            return intersect_triangle(sheared, triangle.v0, triangle.v1, triangle.v2, t_max);
        }
        //#endif
        default: {
            return NO_HIT;
        }
    }
}

//#if TRIANGLES
// The hit record of the world-space `triangle` (primitive `prim` of `instance`) at
// the point p = ray_at(ray, t): its winding normal, p projected onto its plane, its
// barycentric coordinates, its interpolated attributes and its texture coordinates'
// density and change along the ray's footprint. CPU twin: triangle_hit.
fn triangle_hit(prim: u32, instance: u32, triangle: Triangle, ray: Ray, t: f32) -> Hit {
    let p = ray_at(ray, t);
    let normal = triangle_normal(triangle.v0, triangle.v1, triangle.v2);
    var hit = flat_hit(prim, t, normal, triangle.material,
                       project_onto_plane(p, normal, dot(normal, triangle.v0)));
    hit.instance = instance;
    hit.barycentrics = triangle_barycentrics(hit.position, triangle.v0, triangle.v1, triangle.v2);
    //#if MESH_ATTRIBUTES
    if triangle.attributes != NO_ATTRIBUTES {
        let attributes = world_attributes(triangle.attributes, instance, normal);
        apply_triangle_attributes(&hit, attributes);
        let world_area = length(cross(triangle.v1 - triangle.v0, triangle.v2 - triangle.v0));
        // The footprint's long axis (footprint_axis in src/texture.rs).
        let axis = normalize_or_zero(ray.direction - normal * dot(ray.direction, normal));
        if attributes.has_uvs != 0u {
            hit.uv_density.x = triangle_uv_density(world_area, attributes.uv01.xy, attributes.uv01.zw, attributes.uv2);
            hit.uv_axis = vec4<f32>(triangle_uv_axis(triangle.v0, triangle.v1, triangle.v2, attributes.uv01.xy,
                                                     attributes.uv01.zw, attributes.uv2, axis), hit.uv_axis.zw);
        }
        if attributes.has_uvs1 != 0u {
            hit.uv_density.y = triangle_uv_density(world_area, attributes.uv1_01.xy, attributes.uv1_01.zw, attributes.uv1_2);
            hit.uv_axis = vec4<f32>(hit.uv_axis.xy, triangle_uv_axis(triangle.v0, triangle.v1, triangle.v2,
                                                                      attributes.uv1_01.xy, attributes.uv1_01.zw,
                                                                      attributes.uv1_2, axis));
        }
    }
    //#endif
    return hit;
}

//#if MESH_ATTRIBUTES
// A triangle's texture-coordinate area over its world area (`world_area` = |(v1 − v0) ×
// (v2 − v0)|, twice its area, as the uv term is): t_a/p_a of Ray Tracing Gems ch. 20,
// eq. 34, without the texture's size; 0 when not finite. CPU twin: triangle_uv_density.
fn triangle_uv_density(world_area: f32, uv0: vec2<f32>, uv1: vec2<f32>, uv2: vec2<f32>) -> f32 {
    let e1 = uv1 - uv0;
    let e2 = uv2 - uv0;
    let density = abs(e1.x * e2.y - e1.y * e2.x) / world_area;
    // Finite and not NaN: |density| below the largest f32.
    if abs(density) <= 3.4028235e38 {
        return density;
    }
    return 0.0;
}

// The change of texture coordinates (corner coordinates uv0, uv1, uv2) per unit of
// world distance along `axis`, a unit vector in the plane of the triangle v0 v1 v2:
// axis = β1·e1 + β2·e2 over its edges e1 = v1 − v0, e2 = v2 − v0, by Cramer's rule in
// the plane (β1 = (axis × e2)·n / |e1 × e2|, β2 = (e1 × axis)·n / |e1 × e2|, n the unit
// winding normal), gives β1·(uv1 − uv0) + β2·(uv2 − uv0); 0 when not finite. CPU twin:
// triangle_uv_axis.
fn triangle_uv_axis(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, uv0: vec2<f32>, uv1: vec2<f32>, uv2: vec2<f32>, axis: vec3<f32>) -> vec2<f32> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let c = cross(e1, e2);
    let area = length(c);
    let n = c / area;
    let b1 = dot(cross(axis, e2), n) / area;
    let b2 = dot(cross(e1, axis), n) / area;
    let change = (uv1 - uv0) * b1 + (uv2 - uv0) * b2;
    // Finite and not NaN in both components.
    if abs(change.x) <= 3.4028235e38 && abs(change.y) <= 3.4028235e38 {
        return change;
    }
    return vec2<f32>(0.0);
}
//#endif
//#endif

// hit_record of the surface (`prim`, `instance`): for an instanced mesh's triangle,
// made from the triangle moved to world space (instance_triangle) at the world point.
// Twin of hit_record_keyed.
fn hit_record_keyed(prim: u32, instance: u32, ray: Ray, t: f32) -> Hit {
    //#if INSTANCES
    //#if TRIANGLES
    if instance != NO_INSTANCE {
        return triangle_hit(prim, instance, instance_world_triangle(prim_index(prim), instance),
                            ray, t);
    }
    //#endif
    //#endif
    return hit_record(prim, ray, t);
}

// The hit record of `prim` at parameter `t` along `ray`: the shape's unit geometric
// normal, its material, and the hit point re-projected onto the surface (Wächter and
// Binder, Ray Tracing Gems, ch. 6, §6.2.1).
fn hit_record(prim: u32, ray: Ray, t: f32) -> Hit {
    let i = prim_index(prim);
    let p = ray_at(ray, t);
    switch prim_kind(prim) {
        //#if SPHERES
        case PRIM_SPHERE: {
            let sphere = spheres[i];
            return flat_hit(prim, t, sphere_normal(p, sphere.anchor, sphere.normal, sphere.radius),
                            sphere.material,
                            project_onto_sphere(p, sphere.anchor, sphere.normal, sphere.radius));
        }
        //#endif
        //#if PLANES
        case PRIM_PLANE: {
            let plane = planes[i];
            return flat_hit(prim, t, plane.normal, plane.material,
                            project_onto_plane(p, plane.normal, plane.offset));
        }
        //#endif
        //#if POLYGONS
        case PRIM_POLYGON: {
            let polygon = polygons[i];
            return flat_hit(prim, t, polygon.normal, polygon.material,
                            project_onto_plane(p, polygon.normal, polygon.offset));
        }
        //#endif
        //#if TRIANGLES
        case PRIM_TRIANGLE: {
            return triangle_hit(prim, NO_INSTANCE, triangles[i], ray, t);
        }
        //#endif
        default: {
            var hit = flat_hit(prim, t, vec3<f32>(0.0), 0u, p);
            hit.found = false;
            return hit;
        }
    }
}

// Moves a ray origin off a surface: Wächter and Binder, "A Fast and Robust Method for
// Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6). `n` points to the side the new
// ray leaves on. Each coordinate moves by 256·n units in the last place of its f32 bit
// pattern, so the offset scales with the point's magnitude; within scale/32 of the
// origin, where ulps shrink towards zero, a fixed scale/65536·n is added instead, with
// `scale` = frame.offset_scale (ray_offset_scale on the CPU: the scene's size, capped
// at 1, so the offset shrinks with scenes smaller than the unit).
fn offset_ray_origin(p: vec3<f32>, n: vec3<f32>, scale: f32) -> vec3<f32> {
    let ulps = vec3<i32>(256.0 * n);
    let moved = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(ulps, -ulps, p < vec3<f32>(0.0)));
    return select(moved, p + ((1.0 / 65536.0) * scale) * n, abs(p) < vec3<f32>((1.0 / 32.0) * scale));
}

// The exclusive distance limit for testing the surface (`instance`, `prim`) against
// the best hit so far: the best distance, or just beyond it for a smaller key, which
// wins exact ties; the key orders by instance, the scene's own primitives
// (NO_INSTANCE) after every instance, then by prim (HitKey's order). Twin of
// limit_for.
fn limit_for(prim: u32, instance: u32, best_t: f32, best_prim: u32, best_instance: u32) -> f32 {
    let smaller = instance < best_instance || (instance == best_instance && prim < best_prim);
    if best_prim != NO_PRIM && smaller && best_t < bitcast<f32>(0x7f800000u) {
        // The next f32 up: best_t is positive and finite.
        return bitcast<f32>(bitcast<u32>(best_t) + 1u);
    }
    return best_t;
}
