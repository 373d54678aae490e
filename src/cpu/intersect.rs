//! Ray/primitive intersection, the CPU twin of `shaders/intersect.wgsl` (same function
//! names, `f64`).

use glam::DVec3;

use crate::scene::{PolygonPlane, Scene, Shape, polygon_plane};

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
}

/// A shape with the per-shape constants the intersection routines need.
#[derive(Debug, Clone, PartialEq)]
pub enum PreparedShape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
        /// Material index.
        material: u32,
    },
    /// An infinite plane.
    Plane {
        /// Unit normal.
        normal: DVec3,
        /// Offset along the normal.
        offset: f64,
        /// Material index.
        material: u32,
    },
    /// A planar polygon.
    Polygon {
        /// Its plane and projection axis.
        plane: PolygonPlane,
        /// Its vertices.
        vertices: Vec<DVec3>,
        /// Material index.
        material: u32,
    },
    /// A triangle.
    Triangle {
        /// Corners.
        vertices: [DVec3; 3],
        /// Material index.
        material: u32,
    },
}

impl PreparedShape {
    /// Precomputes a validated shape. Degenerate polygons (rejected by the scene
    /// loader) get a zero normal and are never hit.
    pub fn new(shape: &Shape) -> Self {
        match shape {
            Shape::Sphere {
                center,
                radius,
                material,
            } => Self::Sphere {
                center: *center,
                radius: *radius,
                material: *material,
            },
            Shape::Plane {
                normal,
                offset,
                material,
            } => Self::Plane {
                normal: *normal,
                offset: *offset,
                material: *material,
            },
            Shape::Polygon { vertices, material } => Self::Polygon {
                plane: polygon_plane(vertices).unwrap_or(PolygonPlane {
                    normal: DVec3::ZERO,
                    offset: 0.0,
                    dropped_axis: 2,
                }),
                vertices: vertices.clone(),
                material: *material,
            },
            Shape::Triangle { vertices, material } => Self::Triangle {
                vertices: *vertices,
                material: *material,
            },
        }
    }

    /// The ray parameter of the nearest hit in (0, `t_max`) and the unit geometric
    /// normal there.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(f64, DVec3)> {
        match self {
            Self::Sphere { center, radius, .. } => {
                let t = intersect_sphere(ray, *center, *radius, t_max)?;
                Some((t, (ray.at(t) - *center) / *radius))
            }
            Self::Plane { normal, offset, .. } => {
                intersect_plane(ray, *normal, *offset, t_max).map(|t| (t, *normal))
            }
            Self::Polygon {
                plane, vertices, ..
            } => intersect_polygon(ray, plane, vertices, t_max).map(|t| (t, plane.normal)),
            Self::Triangle { vertices, .. } => {
                let t = intersect_triangle(ray, vertices, t_max)?;
                let normal = (vertices[1] - vertices[0])
                    .cross(vertices[2] - vertices[0])
                    .normalize();
                Some((t, normal))
            }
        }
    }

    /// The material index.
    pub fn material(&self) -> u32 {
        match self {
            Self::Sphere { material, .. }
            | Self::Plane { material, .. }
            | Self::Polygon { material, .. }
            | Self::Triangle { material, .. } => *material,
        }
    }
}

/// Ray/sphere intersection in the numerically stable form of Haines, Günther and
/// Akenine-Möller, "Precision Improvements for Ray/Sphere Intersection" (Ray Tracing
/// Gems, ch. 7). It solves the lecture's `s = -u·ΔP ± sqrt((u·ΔP)² - |ΔP|² + r²)`, but
/// takes the discriminant from the distance between the centre and the ray's closest
/// point, `r² - |ΔP - (u·ΔP)u|²`, and the smaller root as `c/q`, which avoids the
/// cancellations that make the textbook form fail for small or distant spheres.
pub fn intersect_sphere(ray: &Ray, center: DVec3, radius: f64, t_max: f64) -> Option<f64> {
    let f = ray.origin - center;
    let b = -f.dot(ray.direction);
    let closest = f + ray.direction * b;
    let discriminant = radius * radius - closest.dot(closest);
    if discriminant < 0.0 {
        return None;
    }
    let c = f.dot(f) - radius * radius;
    // sign(b) with sign(0) = +1, as the WGSL twin computes it.
    let sign_b = if b >= 0.0 { 1.0 } else { -1.0 };
    let q = b + sign_b * discriminant.sqrt();
    let (t0, t1) = if q == 0.0 {
        (0.0, 0.0)
    } else {
        let (a, b) = (c / q, q);
        (a.min(b), a.max(b))
    };
    if t0 > 0.0 && t0 < t_max {
        Some(t0)
    } else if t1 > 0.0 && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// Ray/plane intersection from the lecture: with `N · P = d`, `s = (d - N·P0) / (N·u)`.
/// A ray parallel to the plane (`N·u = 0`) misses it.
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

/// The two coordinates that remain when `dropped_axis` is removed.
pub fn project_to_plane(point: DVec3, dropped_axis: u32) -> (f64, f64) {
    match dropped_axis {
        0 => (point.y, point.z),
        1 => (point.z, point.x),
        _ => (point.x, point.y),
    }
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
        if (current.1 > pv) != (previous.1 > pv) {
            let crossing_u =
                current.0 + (pv - current.1) * (previous.0 - current.0) / (previous.1 - current.1);
            if pu < crossing_u {
                inside = !inside;
            }
        }
        previous = current;
    }
    inside
}

/// Möller–Trumbore ray/triangle intersection (Möller and Trumbore, "Fast, Minimum
/// Storage Ray/Triangle Intersection", JGT 1997).
pub fn intersect_triangle(ray: &Ray, vertices: &[DVec3; 3], t_max: f64) -> Option<f64> {
    let edge1 = vertices[1] - vertices[0];
    let edge2 = vertices[2] - vertices[0];
    let p = ray.direction.cross(edge2);
    let determinant = edge1.dot(p);
    if determinant == 0.0 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = ray.origin - vertices[0];
    let u = s.dot(p) * inverse;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(edge1);
    let v = ray.direction.dot(q) * inverse;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = edge2.dot(q) * inverse;
    (t > 0.0 && t < t_max).then_some(t)
}

/// The nearest hit along `ray` in (0, `t_max`) over all shapes.
pub fn intersect_scene(shapes: &[PreparedShape], ray: &Ray, t_max: f64) -> Option<Hit> {
    let mut nearest: Option<Hit> = None;
    let mut limit = t_max;
    for shape in shapes {
        if let Some((t, normal)) = shape.intersect(ray, limit) {
            limit = t;
            nearest = Some(Hit {
                t,
                normal,
                material: shape.material(),
            });
        }
    }
    nearest
}

/// Whether anything lies along `ray` in (0, `t_max`): the shadow-ray query.
pub fn occluded(shapes: &[PreparedShape], ray: &Ray, t_max: f64) -> bool {
    shapes
        .iter()
        .any(|shape| shape.intersect(ray, t_max).is_some())
}

/// Moves a ray origin off a surface so the new ray does not hit that surface again:
/// the method of Wächter and Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection" (Ray Tracing Gems, ch. 6). The point moves along `normal` (which
/// must point to the side the new ray leaves on) by a fixed number of units in the last
/// place of each coordinate, so the offset scales with the point's magnitude; near the
/// origin, where ulps become tiny, a small absolute offset is used instead.
///
/// The GPU applies the constants to `f32` bit patterns; here they apply to `f64` bit
/// patterns, so the CPU offset is the same number of ulps of its own, finer, precision.
pub fn offset_ray_origin(point: DVec3, normal: DVec3) -> DVec3 {
    const ORIGIN: f64 = 1.0 / 32.0;
    const FLOAT_SCALE: f64 = 1.0 / 65_536.0;
    const INT_SCALE: f64 = 256.0;
    let offset_component = |p: f64, n: f64| -> f64 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let ulps = (INT_SCALE * n) as i64;
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

/// All shapes of `scene`, prepared for intersection.
pub fn prepare_shapes(scene: &Scene) -> Vec<PreparedShape> {
    scene.shapes.iter().map(PreparedShape::new).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(origin: DVec3, direction: DVec3) -> Ray {
        Ray {
            origin,
            direction: direction.normalize(),
        }
    }

    #[test]
    fn sphere_hit_from_outside_and_inside() {
        let r = ray(DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
        let t = intersect_sphere(&r, DVec3::ZERO, 1.0, f64::INFINITY).expect("hit");
        assert!((t - 4.0).abs() < 1e-12);
        let inside = ray(DVec3::ZERO, DVec3::X);
        let t = intersect_sphere(&inside, DVec3::ZERO, 2.0, f64::INFINITY).expect("hit");
        assert!((t - 2.0).abs() < 1e-12);
        let miss = ray(DVec3::new(0.0, 1.5, 5.0), DVec3::NEG_Z);
        assert!(intersect_sphere(&miss, DVec3::ZERO, 1.0, f64::INFINITY).is_none());
        // Behind the origin: no hit.
        let away = ray(DVec3::new(0.0, 0.0, 5.0), DVec3::Z);
        assert!(intersect_sphere(&away, DVec3::ZERO, 1.0, f64::INFINITY).is_none());
        // t_max excludes the hit.
        assert!(intersect_sphere(&r, DVec3::ZERO, 1.0, 3.9).is_none());
    }

    #[test]
    fn sphere_far_away_keeps_precision() {
        // A unit sphere 1e6 units away: the textbook form loses most digits here.
        let r = ray(DVec3::new(0.0, 0.0, 1e6), DVec3::NEG_Z);
        let t = intersect_sphere(&r, DVec3::ZERO, 1.0, f64::INFINITY).expect("hit");
        assert!((t - (1e6 - 1.0)).abs() < 1e-8, "t = {t}");
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
        assert_eq!(intersect_triangle(&r, &tri, f64::INFINITY), Some(2.0));
        let outside = ray(DVec3::new(0.75, 0.75, 2.0), DVec3::NEG_Z);
        assert!(intersect_triangle(&outside, &tri, f64::INFINITY).is_none());
    }

    #[test]
    fn offset_moves_off_the_surface_at_every_scale() {
        for scale in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
            let p = DVec3::new(scale, -scale, 0.5 * scale);
            let moved = offset_ray_origin(p, DVec3::Y);
            assert!(moved.y > p.y, "scale {scale}");
            assert_eq!(moved.x, p.x);
            let back = offset_ray_origin(p, DVec3::NEG_Y);
            assert!(back.y < p.y, "scale {scale}");
        }
    }
}
