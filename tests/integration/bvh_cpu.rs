//! The CPU traversal of the BVH returns exactly what a brute-force loop over every
//! primitive returns (same distance, same primitive), for random rays and for rays
//! aimed at the shared edges and vertices of closed meshes, with both builders.

use crate::support::geometry::{mixed_shapes, random_rays, rays_through_mesh_edges};
use gpu_render::low_level::accel::{BuildMethod, SceneGeometry};
use gpu_render::low_level::cpu::traverse::{
    TraversalCounts, closest_hit_brute_force, closest_hit_counted, occluded,
};

#[test]
fn traversal_equals_brute_force_for_random_rays() {
    let shapes = mixed_shapes(0x5eed);
    for method in [BuildMethod::Sah, BuildMethod::MedianSplit] {
        let geometry = SceneGeometry::from_shapes(&shapes, method);
        assert!(geometry.bvh.nodes.len() > 100, "a real tree");
        let mut counts = TraversalCounts::default();
        let rays = random_rays(20_000, 7);
        let mut hits = 0;
        for ray in &rays {
            let expected = closest_hit_brute_force(&geometry, ray, f64::INFINITY);
            let actual = closest_hit_counted(&geometry, ray, f64::INFINITY, &mut counts);
            assert_eq!(actual, expected, "{method:?}: ray {ray:?}");
            hits += usize::from(expected.is_some());
            // The shadow query agrees at every distance limit.
            for limit in [0.5, 3.0, f64::INFINITY] {
                let blocked = closest_hit_brute_force(&geometry, ray, limit).is_some();
                assert_eq!(
                    occluded(&geometry, ray, limit),
                    blocked,
                    "{method:?}: {ray:?}"
                );
            }
        }
        assert!(
            hits > rays.len() / 4,
            "{hits} hits: the rays must hit something"
        );
        // The tree prunes: far fewer primitive tests than brute force.
        let brute = (geometry.bounded_count() + geometry.planes.len()) as u64 * rays.len() as u64;
        assert!(
            counts.primitives * 10 < brute,
            "{method:?}: {} tests against {brute}",
            counts.primitives
        );
    }
}

#[test]
fn rays_through_shared_edges_find_the_same_hit_as_brute_force() {
    let (shapes, rays) = rays_through_mesh_edges();
    let geometry = SceneGeometry::from_shapes(&shapes, BuildMethod::Sah);
    let mut missed = 0;
    for ray in &rays {
        let expected = closest_hit_brute_force(&geometry, ray, f64::INFINITY);
        let mut counts = TraversalCounts::default();
        let actual = closest_hit_counted(&geometry, ray, f64::INFINITY, &mut counts);
        assert_eq!(actual, expected, "ray {ray:?}");
        missed += usize::from(expected.is_none());
    }
    // Every ray starts inside a closed mesh: none may slip through (watertightness).
    assert_eq!(missed, 0, "rays slipped between triangles");
}
