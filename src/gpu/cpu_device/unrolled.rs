//! Unrolled scenes: the closest-hit test of a scene of a few primitives as
//! straight-line WGSL, one call per primitive with its record index as a literal,
//! instead of a walk of the BVH (`shaders/traverse.wgsl`, "Unrolled scenes").
//!
//! On llvmpipe a storage or uniform read at an index that varies per lane costs one
//! scalar load, extract and insert per lane and per 32-bit component (a quarter of
//! the trace's time on `glass.toml`, by `perf` on the JIT code); a read at a constant
//! index is one load for all lanes, and a primitive test whose kind is a constant has
//! no branch on it. The nearest hit, ties to the smaller primitive reference, is the
//! same as the tree's, which only skips primitives whose boxes a ray misses: the image
//! does not change. Chosen at upload, on CPU devices (where it was measured:
//! `BENCHMARKS.md`, "Unrolled scenes"), for scenes without instances and of at most
//! [`MAX_UNROLLED_PRIMITIVES`] primitives, planes included.

use std::fmt::Write as _;

use crate::accel::{MAX_POLYGON_VERTICES, PrimKind, PrimRef};

use crate::gpu::layout::GpuPolygon;

/// The most primitives (bounded ones and planes) a scene may have for its trace module
/// to test them unrolled. Past it the tree is used: the module's code grows with the
/// count and a tree's walk visits a shrinking share of it. On lavapipe a floor under a
/// grid of Lambert, red and glass spheres traced 14%, 9%, 22% and 10% faster unrolled
/// at 8, 16, 32 and 48 primitives (`BENCHMARKS.md`, "Unrolled scenes"); 48 of the
/// largest polygons still fit the budget's margin (below).
pub const MAX_UNROLLED_PRIMITIVES: usize = 48;

/// The most loop iterations an unrolled closest-hit test charges: every primitive,
/// each a polygon of the most vertices. It must fit in the slack the iteration budget
/// leaves past its limit (`crate::gpu::iteration_budget_for`, 2048).
pub const MAX_UNROLLED_ITERATIONS: usize = MAX_UNROLLED_PRIMITIVES * (1 + MAX_POLYGON_VERTICES);

const _: () = assert!(MAX_UNROLLED_ITERATIONS <= 2048);

/// One primitive test of an unrolled closest-hit test: which record, and for a polygon
/// where its projected vertices lie in `polygon_points`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnrolledTest {
    /// Sphere record `index`.
    Sphere(u32),
    /// Plane record `index`.
    Plane(u32),
    /// Polygon record `index`, its `vertex_count` vertices from `first_vertex`.
    Polygon {
        /// The polygon's record.
        index: u32,
        /// Its first vertex in `polygon_points`.
        first_vertex: u32,
        /// Its number of vertices.
        vertex_count: u32,
    },
    /// Triangle record `index`.
    Triangle(u32),
}

/// The primitive tests of an unrolled scene, in the order the module runs them (any
/// order gives the same hit). Part of [`crate::gpu::ShaderFeatures`], so that a trace module
/// is built once per such list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct UnrolledPrimitives {
    tests: [UnrolledTest; MAX_UNROLLED_PRIMITIVES],
    len: usize,
}

impl UnrolledPrimitives {
    /// The tests of a scene whose tree references `bvh_prims` (the scene's own tree,
    /// without instances) and which has `plane_count` planes, with its polygon records;
    /// `None` if the scene has more than [`MAX_UNROLLED_PRIMITIVES`] primitives, an
    /// instance, or a reference to a record that does not exist.
    pub fn for_scene(
        bvh_prims: &[u32],
        plane_count: usize,
        polygons: &[GpuPolygon],
    ) -> Option<Self> {
        if bvh_prims.len() + plane_count > MAX_UNROLLED_PRIMITIVES {
            return None;
        }
        let mut tests = [UnrolledTest::Plane(0); MAX_UNROLLED_PRIMITIVES];
        let mut len = 0;
        for index in 0..plane_count {
            tests[len] = UnrolledTest::Plane(u32::try_from(index).ok()?);
            len += 1;
        }
        for &reference in bvh_prims {
            let prim = PrimRef(reference);
            let index = u32::try_from(prim.index()).ok()?;
            tests[len] = match prim.kind() {
                PrimKind::Sphere => UnrolledTest::Sphere(index),
                PrimKind::Triangle => UnrolledTest::Triangle(index),
                PrimKind::Polygon => {
                    let record = polygons.get(prim.index())?;
                    if record.vertex_count == 0
                        || record.vertex_count as usize > MAX_POLYGON_VERTICES
                    {
                        return None;
                    }
                    UnrolledTest::Polygon {
                        index,
                        first_vertex: record.first_vertex,
                        vertex_count: record.vertex_count,
                    }
                }
                PrimKind::Plane | PrimKind::Instance => return None,
            };
            len += 1;
        }
        Some(Self { tests, len })
    }

    /// The tests, in order.
    pub fn tests(&self) -> &[UnrolledTest] {
        &self.tests[..self.len]
    }

    /// The WGSL module `unrolled_scene` (see `gpu::shaders`): the function
    /// `unrolled_closest_hit(ray, sheared, best_t, best_prim)` that runs the tests, with
    /// the imports of the helpers it calls (`shaders/unrolled.wgsl`) and of the types of
    /// its arguments.
    pub fn wgsl(&self) -> String {
        let mut body = String::new();
        for test in self.tests() {
            // Writing to a String cannot fail.
            let _ = match *test {
                UnrolledTest::Sphere(i) => {
                    writeln!(body, "    unrolled_sphere({i}u, ray, best_t, best_prim);")
                }
                UnrolledTest::Plane(i) => {
                    writeln!(body, "    unrolled_plane({i}u, ray, best_t, best_prim);")
                }
                UnrolledTest::Polygon {
                    index,
                    first_vertex,
                    vertex_count,
                } => writeln!(
                    body,
                    "    unrolled_polygon({index}u, {first_vertex}u, {vertex_count}u, ray, best_t, best_prim);"
                ),
                UnrolledTest::Triangle(i) => {
                    writeln!(
                        body,
                        "    unrolled_triangle({i}u, sheared, best_t, best_prim);"
                    )
                }
            };
        }
        format!(
            "#import intersect\n#import unrolled\n\
             // The scene's every primitive, unrolled (src/gpu/cpu_device/unrolled.rs).\n\
             fn unrolled_closest_hit(ray: Ray, sheared: ShearedRay, best_t: ptr<function, f32>,\n\
             \x20                       best_prim: ptr<function, u32>) {{\n{body}}}\n"
        )
    }
}

/// Whether traces on `adapter` test small scenes unrolled: on CPU devices, where it was
/// measured faster (`BENCHMARKS.md`, "Unrolled scenes"); elsewhere the tree, unmeasured.
pub fn preferred(adapter: &wgpu::AdapterInfo) -> bool {
    adapter.device_type == wgpu::DeviceType::Cpu
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polygon(first_vertex: u32, vertex_count: u32) -> GpuPolygon {
        GpuPolygon {
            first_vertex,
            vertex_count,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    #[test]
    fn lists_planes_then_the_tree_references_with_polygon_vertices() {
        let prims = [
            PrimRef::new(PrimKind::Polygon, 1).0,
            PrimRef::new(PrimKind::Sphere, 0).0,
            PrimRef::new(PrimKind::Triangle, 2).0,
        ];
        let unrolled =
            UnrolledPrimitives::for_scene(&prims, 1, &[polygon(0, 3), polygon(3, 5)]).unwrap();
        assert_eq!(
            unrolled.tests(),
            &[
                UnrolledTest::Plane(0),
                UnrolledTest::Polygon {
                    index: 1,
                    first_vertex: 3,
                    vertex_count: 5
                },
                UnrolledTest::Sphere(0),
                UnrolledTest::Triangle(2),
            ]
        );
        let source = unrolled.wgsl();
        assert!(source.contains("unrolled_plane(0u, ray, best_t, best_prim);"));
        assert!(source.contains("unrolled_polygon(1u, 3u, 5u, ray, best_t, best_prim);"));
        assert!(source.contains("unrolled_sphere(0u, ray, best_t, best_prim);"));
        assert!(source.contains("unrolled_triangle(2u, sheared, best_t, best_prim);"));
    }

    #[test]
    fn refuses_large_scenes_instances_and_missing_records() {
        let spheres: Vec<u32> = (0..MAX_UNROLLED_PRIMITIVES as u32)
            .map(|i| PrimRef::new(PrimKind::Sphere, i).0)
            .collect();
        assert!(UnrolledPrimitives::for_scene(&spheres, 0, &[]).is_some());
        assert!(UnrolledPrimitives::for_scene(&spheres, 1, &[]).is_none());
        let instance = [PrimRef::new(PrimKind::Instance, 0).0];
        assert!(UnrolledPrimitives::for_scene(&instance, 0, &[]).is_none());
        let missing = [PrimRef::new(PrimKind::Polygon, 4).0];
        assert!(UnrolledPrimitives::for_scene(&missing, 0, &[polygon(0, 3)]).is_none());
        assert!(UnrolledPrimitives::for_scene(&[], 0, &[]).is_some());
    }
}
