// The primitive tests of an unrolled scene (src/gpu/cpu_device/unrolled.rs, which writes one call
// per primitive into unrolled_closest_hit; see traverse.wgsl, "Unrolled scenes"): the
// tree's tests with the record index a literal, charged to the budget as the tree's.

#import types
#import records
#import budget
#import intersect

//#if SPHERES
// Unrolled test of sphere record `i` (a literal) against the best hit so far.
fn unrolled_sphere(i: u32, ray: Ray, best_t: ptr<function, f32>, best_prim: ptr<function, u32>) {
    let prim = (PRIM_SPHERE << PRIM_KIND_SHIFT) | i;
    iterations += 1u;
    let sphere = spheres[i];
    let t = intersect_sphere(ray, sphere.anchor, sphere.normal, sphere.radius,
                             limit_for(prim, NO_INSTANCE, *best_t, *best_prim, NO_INSTANCE));
    if t != NO_HIT {
        *best_t = t;
        *best_prim = prim;
    }
}
//#endif

//#if PLANES
// Unrolled test of plane record `i` (a literal).
fn unrolled_plane(i: u32, ray: Ray, best_t: ptr<function, f32>, best_prim: ptr<function, u32>) {
    let prim = (PRIM_PLANE << PRIM_KIND_SHIFT) | i;
    iterations += 1u;
    let plane = planes[i];
    let t = intersect_plane(ray, plane.normal, plane.offset, limit_for(prim, NO_INSTANCE, *best_t, *best_prim, NO_INSTANCE));
    if t != NO_HIT {
        *best_t = t;
        *best_prim = prim;
    }
}
//#endif

//#if POLYGONS
// Unrolled test of polygon record `i` whose `count` vertices start at `first` in
// polygon_points (literals, as upload wrote them): intersect_polygon with the
// vertices read at constant offsets.
fn unrolled_polygon(i: u32, first: u32, count: u32, ray: Ray, best_t: ptr<function, f32>,
                    best_prim: ptr<function, u32>) {
    let prim = (PRIM_POLYGON << PRIM_KIND_SHIFT) | i;
    iterations += 1u;
    let polygon = polygons[i];
    let t = intersect_plane(ray, polygon.normal, polygon.offset, limit_for(prim, NO_INSTANCE, *best_t, *best_prim, NO_INSTANCE));
    if t == NO_HIT {
        return;
    }
    // The same rule and charge as point_in_polygon (intersect.wgsl).
    iterations += count;
    if inside_polygon_points(project_to_plane(ray_at(ray, t), polygon.dropped_axis), first, count) {
        *best_t = t;
        *best_prim = prim;
    }
}
//#endif

//#if TRIANGLES
// Unrolled test of triangle record `i` (a literal).
fn unrolled_triangle(i: u32, sheared: ShearedRay, best_t: ptr<function, f32>,
                     best_prim: ptr<function, u32>) {
    let prim = (PRIM_TRIANGLE << PRIM_KIND_SHIFT) | i;
    iterations += 1u;
    let triangle = triangles[i];
    let t = intersect_triangle(sheared, triangle.v0, triangle.v1, triangle.v2,
                               limit_for(prim, NO_INSTANCE, *best_t, *best_prim, NO_INSTANCE));
    if t != NO_HIT {
        *best_t = t;
        *best_prim = prim;
    }
}
//#endif
