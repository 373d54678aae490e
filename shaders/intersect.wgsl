// Ray/primitive intersection. CPU twin: src/cpu/intersect.rs (same function names).
// Every routine returns the ray parameter of the nearest hit in (0, t_max), or NO_HIT.

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
}

fn ray_at(ray: Ray, t: f32) -> vec3<f32> {
    return ray.origin + ray.direction * t;
}

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

// Ray/sphere in the stable form of Haines, Günther and Akenine-Möller, "Precision
// Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7): the lecture's
// s = -u·ΔP ± sqrt((u·ΔP)² - |ΔP|² + r²), with the discriminant taken from the distance
// between the centre and the ray's closest point, and the smaller root as c/q.
fn intersect_sphere(ray: Ray, center: vec3<f32>, radius: f32, t_max: f32) -> f32 {
    let f = ray.origin - center;
    let b = -dot(f, ray.direction);
    let closest = f + ray.direction * b;
    let discriminant = radius * radius - dot(closest, closest);
    if discriminant < 0.0 {
        return NO_HIT;
    }
    let c = dot(f, f) - radius * radius;
    let sign_b = select(-1.0, 1.0, b >= 0.0);
    let q = b + sign_b * sqrt(discriminant);
    if q == 0.0 {
        return NO_HIT;
    }
    let r0 = c / q;
    return nearest_root(min(r0, q), max(r0, q), t_max);
}

// Ray/plane from the lecture: with N·P = d, s = (d - N·P0) / (N·u); parallel rays miss.
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

// The two coordinates left when `dropped_axis` (0 = x, 1 = y, 2 = z) is removed.
fn project_to_plane(p: vec3<f32>, dropped_axis: u32) -> vec2<f32> {
    switch dropped_axis {
        case 0u: { return p.yz; }
        case 1u: { return p.zx; }
        default: { return p.xy; }
    }
}

// Even-odd (crossing number) inside test in the projection that drops the polygon's
// dominant axis (Haines, "Point in Polygon Strategies", Graphics Gems IV).
fn point_in_polygon(p: vec3<f32>, polygon: Polygon) -> bool {
    let point = project_to_plane(p, polygon.dropped_axis);
    var inside = false;
    let last = polygon.first_vertex + polygon.vertex_count - 1u;
    var previous = project_to_plane(polygon_vertices[last].xyz, polygon.dropped_axis);
    for (var i = 0u; i < polygon.vertex_count; i += 1u) {
        let current = project_to_plane(polygon_vertices[polygon.first_vertex + i].xyz,
                                       polygon.dropped_axis);
        if (current.y > point.y) != (previous.y > point.y) {
            let crossing_u = current.x
                + (point.y - current.y) * (previous.x - current.x) / (previous.y - current.y);
            if point.x < crossing_u {
                inside = !inside;
            }
        }
        previous = current;
    }
    return inside;
}

// Ray/polygon as in the lecture: the plane first, then the inside test.
fn intersect_polygon(ray: Ray, polygon: Polygon, t_max: f32) -> f32 {
    let t = intersect_plane(ray, polygon.normal, polygon.offset, t_max);
    if t == NO_HIT || !point_in_polygon(ray_at(ray, t), polygon) {
        return NO_HIT;
    }
    return t;
}

// Möller–Trumbore ray/triangle ("Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 1997).
fn intersect_triangle(ray: Ray, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_max: f32) -> f32 {
    let edge1 = v1 - v0;
    let edge2 = v2 - v0;
    let p = cross(ray.direction, edge2);
    let determinant = dot(edge1, p);
    if determinant == 0.0 {
        return NO_HIT;
    }
    let inverse = 1.0 / determinant;
    let s = ray.origin - v0;
    let u = dot(s, p) * inverse;
    if u < 0.0 || u > 1.0 {
        return NO_HIT;
    }
    let q = cross(s, edge1);
    let v = dot(ray.direction, q) * inverse;
    if v < 0.0 || u + v > 1.0 {
        return NO_HIT;
    }
    let t = dot(edge2, q) * inverse;
    if t > 0.0 && t < t_max {
        return t;
    }
    return NO_HIT;
}

// The nearest hit along `ray` in (0, t_max) over all shapes. Shapes are visited by
// type, not in file order as on the CPU: only exact ties in t can resolve differently.
fn intersect_scene(ray: Ray, t_max: f32) -> Hit {
    var hit = Hit(t_max, vec3<f32>(0.0), 0u, false);
    for (var i = 0u; i < frame.sphere_count; i += 1u) {
        let sphere = spheres[i];
        let t = intersect_sphere(ray, sphere.center, sphere.radius, hit.t);
        if t != NO_HIT {
            hit = Hit(t, (ray_at(ray, t) - sphere.center) / sphere.radius, sphere.material, true);
        }
    }
    for (var i = 0u; i < frame.plane_count; i += 1u) {
        let plane = planes[i];
        let t = intersect_plane(ray, plane.normal, plane.offset, hit.t);
        if t != NO_HIT {
            hit = Hit(t, plane.normal, plane.material, true);
        }
    }
    for (var i = 0u; i < frame.polygon_count; i += 1u) {
        let polygon = polygons[i];
        let t = intersect_polygon(ray, polygon, hit.t);
        if t != NO_HIT {
            hit = Hit(t, polygon.normal, polygon.material, true);
        }
    }
    for (var i = 0u; i < frame.triangle_count; i += 1u) {
        let triangle = triangles[i];
        let t = intersect_triangle(ray, triangle.v0, triangle.v1, triangle.v2, hit.t);
        if t != NO_HIT {
            let normal = normalize(cross(triangle.v1 - triangle.v0, triangle.v2 - triangle.v0));
            hit = Hit(t, normal, triangle.material, true);
        }
    }
    return hit;
}

// Whether anything lies along `ray` in (0, t_max): the shadow-ray query.
fn occluded(ray: Ray, t_max: f32) -> bool {
    for (var i = 0u; i < frame.sphere_count; i += 1u) {
        if intersect_sphere(ray, spheres[i].center, spheres[i].radius, t_max) != NO_HIT {
            return true;
        }
    }
    for (var i = 0u; i < frame.plane_count; i += 1u) {
        if intersect_plane(ray, planes[i].normal, planes[i].offset, t_max) != NO_HIT {
            return true;
        }
    }
    for (var i = 0u; i < frame.polygon_count; i += 1u) {
        if intersect_polygon(ray, polygons[i], t_max) != NO_HIT {
            return true;
        }
    }
    for (var i = 0u; i < frame.triangle_count; i += 1u) {
        let triangle = triangles[i];
        if intersect_triangle(ray, triangle.v0, triangle.v1, triangle.v2, t_max) != NO_HIT {
            return true;
        }
    }
    return false;
}

// Moves a ray origin off a surface: Wächter and Binder, "A Fast and Robust Method for
// Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6). `n` points to the side the new
// ray leaves on. Each coordinate moves by 256·n units in the last place of its f32 bit
// pattern, so the offset scales with the point's magnitude; within 1/32 of the origin,
// where ulps shrink towards zero, a fixed 1/65536·n is added instead.
fn offset_ray_origin(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let ulps = vec3<i32>(256.0 * n);
    let moved = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(ulps, -ulps, p < vec3<f32>(0.0)));
    return select(moved, p + (1.0 / 65536.0) * n, abs(p) < vec3<f32>(1.0 / 32.0));
}
