//! Generated geometry for the traversal tests: mixed random shapes, closed meshes and
//! the rays that test them.

use glam::{DVec2, DVec3};
use gpu_render::low_level::cpu::intersect::Ray;
use gpu_render::scene::{Mesh, Shape};

/// A small deterministic generator (SplitMix64), so the tests need no crate.
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next value in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A point uniformly in the cube [-s, s]³.
    pub fn point(&mut self, s: f64) -> DVec3 {
        DVec3::new(self.next_f64(), self.next_f64(), self.next_f64()) * (2.0 * s) - s
    }

    /// A unit vector, uniform over the sphere.
    pub fn direction(&mut self) -> DVec3 {
        loop {
            let v = self.point(1.0);
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// The 12 triangles of the cube `center ± scale`, wound outwards.
pub fn cube_triangles(center: DVec3, scale: f64, material: u32) -> Vec<Shape> {
    let corner = |i: usize| {
        center
            + DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            ) * scale
    };
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
                Shape::Triangle {
                    vertices: [corner(f[0]), corner(f[1]), corner(f[2])],
                    material,
                },
                Shape::Triangle {
                    vertices: [corner(f[0]), corner(f[2]), corner(f[3])],
                    material,
                },
            ]
        })
        .collect()
}

/// A UV sphere of `rings × segments` quads (two triangles each), wound outwards.
pub fn uv_sphere(center: DVec3, radius: f64, rings: usize, segments: usize) -> Vec<Shape> {
    let point = |ring: usize, segment: usize| {
        if ring == 0 || ring == rings {
            // One exact vertex per pole: sin(π) is not 0 in floating point, and poles
            // that differ by 1e-17 would leave cracks.
            return center + DVec3::Y * if ring == 0 { radius } else { -radius };
        }
        let theta = std::f64::consts::PI * ring as f64 / rings as f64;
        let phi = std::f64::consts::TAU * (segment % segments) as f64 / segments as f64;
        center
            + DVec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ) * radius
    };
    let mut shapes = Vec::new();
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b) = (point(ring, segment), point(ring, segment + 1));
            let (c, d) = (point(ring + 1, segment + 1), point(ring + 1, segment));
            if ring > 0 {
                shapes.push(Shape::Triangle {
                    vertices: [a, b, d],
                    material: 0,
                });
            }
            if ring + 1 < rings {
                shapes.push(Shape::Triangle {
                    vertices: [b, c, d],
                    material: 0,
                });
            }
        }
    }
    shapes
}

/// Spheres, triangles, small and large polygons, a closed cube, a tessellated sphere,
/// a duplicated triangle (an exact tie) and two planes, from `seed`.
pub fn mixed_shapes(seed: u64) -> Vec<Shape> {
    let mut rng = SplitMix(seed);
    let mut shapes = Vec::new();
    for _ in 0..300 {
        shapes.push(Shape::Sphere {
            center: rng.point(4.0),
            radius: 0.02 + 0.2 * rng.next_f64(),
            material: 0,
        });
    }
    for _ in 0..600 {
        let a = rng.point(4.0);
        shapes.push(Shape::Triangle {
            vertices: [a, a + rng.point(0.4), a + rng.point(0.4)],
            material: 0,
        });
    }
    for i in 0..40 {
        // Regular polygons of 3..80 vertices in random planes.
        let n = 3 + (i * 2) % 78;
        let center = rng.point(4.0);
        let normal = rng.direction();
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let radius = 0.1 + 0.3 * rng.next_f64();
        let vertices = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                center + (u * a.cos() + v * a.sin()) * radius
            })
            .collect();
        shapes.push(Shape::Polygon {
            vertices,
            material: 0,
        });
    }
    shapes.extend(cube_triangles(DVec3::new(1.0, 1.0, -1.0), 0.7, 0));
    shapes.extend(uv_sphere(DVec3::new(-1.5, 0.5, 1.0), 0.8, 12, 24));
    let tie = [
        DVec3::new(0.0, -1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.3),
        DVec3::new(0.0, -0.2, 0.5),
    ];
    for _ in 0..2 {
        shapes.push(Shape::Triangle {
            vertices: tie,
            material: 0,
        });
    }
    shapes.push(Shape::Plane {
        normal: DVec3::Y,
        offset: -4.5,
        material: 0,
    });
    shapes.push(Shape::Plane {
        normal: DVec3::new(1.0, 0.0, 1.0).normalize(),
        offset: 6.0,
        material: 0,
    });
    shapes
}

/// `count` rays from random points towards random directions, and some towards the
/// duplicated triangle of [`mixed_shapes`].
pub fn random_rays(count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix(seed);
    (0..count)
        .map(|i| {
            let origin = rng.point(6.0);
            let direction = if i % 10 == 0 {
                (DVec3::new(0.3, -0.8, 0.25) - origin).normalize()
            } else {
                rng.direction()
            };
            Ray { origin, direction }
        })
        .collect()
}

/// Closed meshes (a cube and a tessellated sphere) and rays from inside them aimed
/// exactly at their vertices and edges.
pub fn rays_through_mesh_edges() -> (Vec<Shape>, Vec<Ray>) {
    let mut shapes = cube_triangles(DVec3::ZERO, 1.0, 0);
    shapes.extend(uv_sphere(DVec3::new(5.0, 0.0, 0.0), 1.0, 10, 20));
    let mut targets = Vec::new();
    for shape in &shapes {
        if let Shape::Triangle { vertices, .. } = shape {
            for k in 0..3 {
                let (a, b) = (vertices[k], vertices[(k + 1) % 3]);
                targets.push(a);
                for f in [0.5, 0.25, 0.9] {
                    targets.push(a + (b - a) * f);
                }
            }
        }
    }
    let mut rays = Vec::new();
    for target in targets {
        let inside = if target.x > 2.5 {
            [DVec3::new(5.0, 0.0, 0.0), DVec3::new(5.2, -0.3, 0.1)]
        } else {
            [DVec3::ZERO, DVec3::new(0.31, -0.52, 0.13)]
        };
        for origin in inside {
            rays.push(Ray {
                origin,
                direction: (target - origin).normalize(),
            });
        }
    }
    (shapes, rays)
}

/// A closed, bumpy sphere of `rings × segments` quads with smooth normals and texture
/// coordinates, wound counter-clockwise seen from outside, in the unit box.
pub fn blob(rings: usize, segments: usize) -> Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for s in 0..=segments {
            let phi = std::f64::consts::TAU * s as f64 / segments as f64;
            let direction = DVec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            let radius = 0.8 + 0.15 * (3.0 * theta).sin() * (2.0 * phi).cos();
            positions.push(direction * radius);
            normals.push(direction);
            uvs.push(DVec2::new(
                s as f64 / segments as f64,
                r as f64 / rings as f64,
            ));
        }
    }
    let index = |r: usize, s: usize| (r * (segments + 1) + s) as u32;
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (
                index(r, s),
                index(r + 1, s),
                index(r + 1, s + 1),
                index(r, s + 1),
            );
            if r > 0 {
                triangles.push([a, d, c]);
            }
            if r + 1 < rings {
                triangles.push([a, c, b]);
            }
        }
    }
    Mesh {
        name: "blob".into(),
        positions,
        normals: Some(normals),
        uvs: Some(uvs),
        uvs1: None,
        colors: None,
        tangents: None,
        triangles,
        material: 1,
        instances: vec![],
    }
}

/// Triangles, convex quads and concave quads ("darts") given as polygons in random
/// planes, 60 in all, with 40 rays at each aimed at random points of its plane within
/// 1.4 radii of its centre along each of the plane's axes: inside, outside and near its
/// edges. The GPU tests polygons of up to four vertices without a loop
/// (`shaders/intersect.wgsl`).
pub fn small_polygons(seed: u64) -> (Vec<Shape>, Vec<Ray>) {
    // `n` corners at jittered angles, each at a distance in [1 - shrink, 1]: convex.
    let jittered = |rng: &mut SplitMix, n: usize, shrink: f64| -> Vec<DVec2> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + 0.6 * rng.next_f64()) / n as f64;
                DVec2::new(a.cos(), a.sin()) * (1.0 - shrink * rng.next_f64())
            })
            .collect()
    };
    let mut rng = SplitMix(seed);
    let mut shapes = Vec::new();
    let mut rays = Vec::new();
    for i in 0..60 {
        let center = rng.point(4.0);
        let normal = rng.direction();
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let radius = 0.2 + 0.4 * rng.next_f64();
        let corners = match i % 3 {
            0 => jittered(&mut rng, 3, 0.0),
            1 => jittered(&mut rng, 4, 0.4),
            _ => vec![
                DVec2::new(0.0, 1.0),
                DVec2::new(-1.0, -1.0),
                DVec2::new(0.0, -0.2 + 0.6 * rng.next_f64()),
                DVec2::new(1.0, -1.0),
            ],
        };
        let on_plane = |p: DVec2| center + (u * p.x + v * p.y) * radius;
        shapes.push(Shape::Polygon {
            vertices: corners.iter().map(|&p| on_plane(p)).collect(),
            material: 0,
        });
        for _ in 0..40 {
            let target = on_plane(DVec2::new(
                2.8 * rng.next_f64() - 1.4,
                2.8 * rng.next_f64() - 1.4,
            ));
            let side = if rng.next_f64() < 0.5 { 1.0 } else { -1.0 };
            let origin = target + (normal * side + rng.point(0.5)) * 3.0;
            rays.push(Ray {
                origin,
                direction: (target - origin).normalize(),
            });
        }
    }
    (shapes, rays)
}
