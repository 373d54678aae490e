//! How precisely each backend places a flat shape (a triangle or a polygon) seen from
//! the camera, and how precisely it aims the camera's rays.
//!
//! Both tracers intersect a triangle with the watertight test of Woop, Benthin and Wald
//! (JCGT 2(1), 2013) in coordinates relative to the ray's origin: the distance is the
//! corners' depths weighted by their edge functions, `t = Σ wᵢ zᵢ` with `Σ wᵢ = 1`.
//! Where the corners are much farther from the camera than the point the ray hits (a
//! ground triangle of corners ±2.2e9 seen from 3 units), the sum cancels, and its error
//! is the rounding of the largest corner, `ε·max|vᵢ - e|`, not of the distance: on the
//! GPU (`f32`, `ε = 1.2e-7`) about 260 units for that floor, which then vanishes. Add
//! the rounding of the corners themselves to the precision of their type (`ε·|v|∞`)
//! and compare with the distance from the camera to the shape's nearest point: the
//! loader warns, as for spheres, when the GPU's or the CPU's error exceeds
//! [`SPHERE_PRECISION_LIMIT`] of it, and `--backend auto` renders on the CPU where only
//! the GPU fails.
//!
//! The camera's rays are aimed in `f32` on the GPU: a direction is good to about
//! `1.2e-7`, and neighbouring pixels' rays differ by `2·tan(fov/2)/height`. With a
//! field of view of 1e-6° every pixel's ray rounds to the same direction; the loader
//! warns when the rounding exceeds [`CAMERA_PRECISION_LIMIT`] of a pixel.
//!
//! Beyond precision, the GPU's edge functions are products of two coordinates: past
//! about 1.8e19 from the camera they overflow `f32`, and edges shorter than about 1e-18
//! underflow it. Such shapes get an infinite GPU error.

use glam::DVec3;

use super::{Camera, Mesh, SPHERE_PRECISION_LIMIT, Scene, Shape, SurfacePrecision};

/// The largest coordinate, relative to the camera, whose products of two the GPU's
/// `f32` edge functions can form (the square root of `f32::MAX`, with margin).
const GPU_LARGEST_RELATIVE: f64 = 1e18;
/// The shortest edge whose products of two the GPU's edge functions keep above the
/// smallest normal `f32` (about 1.2e-38), with margin.
const GPU_SHORTEST_EDGE: f64 = 1e-18;

/// How precisely the CPU reference and the GPU place the flat shape of `corners` (a
/// triangle, or a planar polygon's vertices in order) seen from `eye`; see the module
/// documentation.
pub fn flat_precision(corners: &[DVec3], eye: DVec3) -> SurfacePrecision {
    let distance = distance_to_polygon(corners, eye);
    let reach = corners
        .iter()
        .map(|&v| (v - eye).abs().max_element().max(v.abs().max_element()))
        .fold(0.0, f64::max);
    let longest_edge = corners
        .iter()
        .zip(corners.iter().cycle().skip(1))
        .map(|(&a, &b)| (b - a).abs().max_element())
        .fold(0.0, f64::max);
    let cpu = f64::EPSILON * reach;
    let gpu = if reach > GPU_LARGEST_RELATIVE || longest_edge < GPU_SHORTEST_EDGE {
        f64::INFINITY
    } else {
        cpu + f64::from(f32::EPSILON) * reach
    };
    SurfacePrecision { distance, cpu, gpu }
}

/// The fraction of a pixel above which the loader warns that the GPU's `f32` camera
/// rays are aimed too coarsely: an edge pixel then lands on the other side of a
/// silhouette on one backend, and at whole pixels every ray of a row is the same.
pub const CAMERA_PRECISION_LIMIT: f64 = 1e-2;

/// The GPU's rounding of a camera ray's direction (`f32`, 1.2e-7) as a fraction of the
/// angle between neighbouring pixels' rays, `2·tan(fov_y/2)/height`; the CPU's (`f64`)
/// is 2^29 times smaller. Above [`CAMERA_PRECISION_LIMIT`] the GPU's image differs.
pub fn camera_pixel_precision(camera: &Camera, height: u32) -> f64 {
    let pixel = 2.0 * (camera.fov_y_degrees.to_radians() * 0.5).tan() / f64::from(height.max(1));
    f64::from(f32::EPSILON) / pixel
}

/// The fraction of the largest `f32` above which a point light's irradiance on a
/// surface, `I/r²`, counts as beyond the GPU: the GPU forms it before the BRDF and the
/// cosine scale it down, and an infinite irradiance makes the pixel 0 there (the CPU's
/// `f64` gave 1.85e38 for a light of 1e30 7.2e-5 off a white sphere).
const IRRADIANCE_LIMIT: f64 = f32::MAX as f64 / 16.0;

/// A point light of `scene` so near one of its shapes (spheres, planes, polygons,
/// triangles; not mesh triangles) that its irradiance there, `I/r²`, is beyond what
/// the GPU's `f32` forms: `(light index, shape index, distance)` of the first such pair.
pub fn light_beyond_the_gpu(scene: &Scene) -> Option<(usize, usize, f64)> {
    scene.lights.iter().enumerate().find_map(|(i, light)| {
        let super::Light::Point {
            position,
            intensity,
        } = light
        else {
            return None;
        };
        // Nearer than this, I/r² exceeds the limit.
        let nearest = (intensity.max_element() / IRRADIANCE_LIMIT).sqrt();
        if nearest.is_nan() || nearest <= 0.0 {
            return None;
        }
        scene.shapes.iter().enumerate().find_map(|(k, shape)| {
            let distance = distance_to_shape(shape, *position);
            (distance < nearest).then_some((i, k, distance))
        })
    })
}

/// The distance from `point` to the surface of `shape`.
fn distance_to_shape(shape: &Shape, point: DVec3) -> f64 {
    match shape {
        Shape::Sphere { center, radius, .. } => {
            super::sphere_precision(*center, *radius, point).distance
        }
        Shape::Plane { normal, offset, .. } => (normal.dot(point) - offset).abs(),
        Shape::Polygon { vertices, .. } => distance_to_polygon(vertices, point),
        Shape::Triangle { vertices, .. } => distance_to_polygon(vertices, point),
    }
}

/// A flat shape of a scene that only the CPU reference places precisely enough.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatShapeBeyondTheGpu {
    /// `objects[i]`-style name of the shape: `shape i (triangle)`, or `mesh NAME`.
    pub what: String,
    /// How precisely each backend places it.
    pub precision: SurfacePrecision,
}

/// The first triangle or polygon of `scene` (its own shapes, then every placed mesh
/// triangle) that the GPU cannot place to [`SPHERE_PRECISION_LIMIT`] seen from the
/// camera while the CPU reference can. A mesh placement is checked triangle by
/// triangle only where its world box does not already prove it fine.
pub fn flat_shape_beyond_the_gpu(scene: &Scene) -> Option<FlatShapeBeyondTheGpu> {
    let eye = scene.camera.eye;
    for (i, shape) in scene.shapes.iter().enumerate() {
        let (corners, kind): (&[DVec3], _) = match shape {
            Shape::Triangle { vertices, .. } => (vertices, "triangle"),
            Shape::Polygon { vertices, .. } => (vertices, "polygon"),
            _ => continue,
        };
        if let Some(precision) = only_the_cpu_places(corners, eye) {
            return Some(FlatShapeBeyondTheGpu {
                what: format!("objects[{i}] ({kind})"),
                precision,
            });
        }
    }
    mesh_triangle_beyond_the_gpu(&scene.meshes, eye)
}

/// The first placed triangle of `meshes` that the GPU cannot place to
/// [`SPHERE_PRECISION_LIMIT`] seen from `eye` while the CPU reference can (see
/// [`flat_shape_beyond_the_gpu`]).
pub fn mesh_triangle_beyond_the_gpu(meshes: &[Mesh], eye: DVec3) -> Option<FlatShapeBeyondTheGpu> {
    for mesh in meshes {
        let Some((lo, hi)) = bounds(&mesh.positions) else {
            continue;
        };
        for transform in &mesh.instances {
            let corners: Vec<DVec3> = (0..8)
                .map(|k| {
                    let pick = |bit: usize, l: f64, h: f64| if k & bit == 0 { l } else { h };
                    transform.transform_point3(DVec3::new(
                        pick(1, lo.x, hi.x),
                        pick(2, lo.y, hi.y),
                        pick(4, lo.z, hi.z),
                    ))
                })
                .collect();
            if box_is_fine(&corners, eye) {
                continue;
            }
            for triangle in &mesh.triangles {
                let world =
                    triangle.map(|v| transform.transform_point3(mesh.positions[v as usize]));
                if let Some(precision) = only_the_cpu_places(&world, eye) {
                    return Some(FlatShapeBeyondTheGpu {
                        what: format!("mesh {}", mesh.name),
                        precision,
                    });
                }
            }
        }
    }
    None
}

/// The precision of the flat shape of `corners` seen from `eye` when the GPU cannot
/// place it to [`SPHERE_PRECISION_LIMIT`] and the CPU reference can, else `None`.
fn only_the_cpu_places(corners: &[DVec3], eye: DVec3) -> Option<SurfacePrecision> {
    let precision = flat_precision(corners, eye);
    (precision.gpu_hopeless() && !precision.cpu_hopeless()).then_some(precision)
}

/// The box of `points`, or `None` for none.
fn bounds(points: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// Whether every triangle inside the box of `corners` (a placed mesh's box, eight
/// world points) is placed precisely enough by the GPU: its error bound over the whole
/// box against the box's distance from `eye`, and the box within the range the GPU's
/// edge functions handle. Boxes around the camera prove nothing.
fn box_is_fine(corners: &[DVec3], eye: DVec3) -> bool {
    let Some((lo, hi)) = bounds(corners) else {
        return true;
    };
    let reach = corners
        .iter()
        .map(|&v| (v - eye).abs().max_element().max(v.abs().max_element()))
        .fold(0.0, f64::max);
    let distance = (lo - eye).max(eye - hi).max(DVec3::ZERO).length();
    let gpu = (f64::EPSILON + f64::from(f32::EPSILON)) * reach;
    reach <= GPU_LARGEST_RELATIVE
        && (hi - lo).max_element() >= GPU_SHORTEST_EDGE
        && distance > 0.0
        && gpu / distance <= SPHERE_PRECISION_LIMIT
}

/// The distance from `point` to the polygon of `corners` (planar, in order): the
/// nearest of its fan triangles'.
fn distance_to_polygon(corners: &[DVec3], point: DVec3) -> f64 {
    match corners {
        [] => f64::INFINITY,
        [only] => (point - *only).length(),
        [first, rest @ ..] => rest
            .windows(2)
            .map(|pair| {
                (closest_point_on_triangle(point, *first, pair[0], pair[1]) - point).length()
            })
            .fold(f64::INFINITY, f64::min)
            .min((point - *first).length()),
    }
}

/// The point of the triangle (`a`, `b`, `c`) nearest `p` (Ericson, "Real-Time Collision
/// Detection", §5.1.5), in coordinates relative to `p` so that corners far from it lose
/// no digits near it.
fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (a, b, c) = (a - p, b - p, c - p);
    let ab = b - a;
    let ac = c - a;
    let ap = -a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return p + a;
    }
    let bp = -b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return p + b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p + a + ab * (d1 / (d1 - d3));
    }
    let cp = -c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return p + c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p + a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p + b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = va + vb + vc;
    if denominator == 0.0 || !denominator.is_finite() {
        // Degenerate: the nearest corner.
        return [a, b, c]
            .into_iter()
            .min_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
            .map_or(p, |v| p + v);
    }
    let v = vb / denominator;
    let w = vc / denominator;
    p + a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_floor_far_larger_than_its_distance_is_beyond_the_gpu_only() {
        let eye = DVec3::new(0.0, 3.0, 3.0);
        let floor = |h: f64| {
            [
                DVec3::new(-h, 0.0, h),
                DVec3::new(h, 0.0, h),
                DVec3::new(h, 0.0, -h),
            ]
        };
        let near = flat_precision(&floor(10.0), eye);
        assert!((near.distance - 3.0).abs() < 1e-12, "{near:?}");
        assert!(!near.gpu_hopeless() && !near.cpu_hopeless());
        let far = flat_precision(&floor(2.2e9), eye);
        assert!(far.gpu_hopeless() && !far.cpu_hopeless(), "{far:?}");
        // The same floor scaled with the camera: as precise as at scale 1.
        let scaled = flat_precision(&floor(10.0).map(|v| v * 1e12), eye * 1e12);
        assert!(!scaled.gpu_hopeless(), "{scaled:?}");
        // Beyond the f32 range of the edge functions, however far the camera.
        let huge = flat_precision(&floor(1e30), eye * 1e30);
        assert!(huge.gpu_hopeless() && !huge.cpu_hopeless(), "{huge:?}");
        let tiny = flat_precision(&floor(1e-20), eye * 1e-20);
        assert!(tiny.gpu_hopeless(), "{tiny:?}");
    }

    #[test]
    fn the_nearest_point_of_a_triangle_is_found_in_every_region() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let cases = [
            (DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, 0.0)),
            (DVec3::new(-1.0, -1.0, 0.0), a),
            (DVec3::new(2.0, -0.5, 0.0), b),
            (DVec3::new(-0.5, 2.0, 0.0), c),
            (DVec3::new(0.5, -1.0, 0.0), DVec3::new(0.5, 0.0, 0.0)),
            (DVec3::new(-1.0, 0.5, 0.0), DVec3::new(0.0, 0.5, 0.0)),
            (DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0)),
        ];
        for (p, expected) in cases {
            let q = closest_point_on_triangle(p, a, b, c);
            assert!(
                (q - expected).length() < 1e-12,
                "{p} -> {q}, not {expected}"
            );
        }
    }
}
