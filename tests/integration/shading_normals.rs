//! The shading-normal rules of smooth meshes (src/cpu/trace.rs, twinned in
//! shaders/trace.wgsl): the shading frame and the bent secondary rays are continuous
//! (no facet edge can show where a rule switches on), keep every secondary ray on its
//! side of the real surface, and change nothing where the shading normal is the
//! geometric one.

use glam::DVec3;
use gpu_render::low_level::cpu::trace::{MIN_SECONDARY_COSINE, keep_on_side, shading_frame_normal};

/// Unit directions over the sphere (a Fibonacci lattice).
fn directions(count: usize) -> impl Iterator<Item = DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count).map(move |i| {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

#[test]
fn bent_rays_stay_on_their_side_and_unbent_rays_are_untouched() {
    let side = DVec3::new(0.3, 0.9, -0.2).normalize();
    for d in directions(4000) {
        let kept = keep_on_side(d, side);
        assert!(
            (kept.length() - 1.0).abs() < 1e-12,
            "{d} -> {kept} is not unit"
        );
        assert!(kept.dot(side) > 0.0, "{d} -> {kept} is not on the side");
        if d.dot(side) >= MIN_SECONDARY_COSINE {
            assert_eq!(kept, d, "a ray already on its side was bent");
        }
    }
}

#[test]
fn bending_is_continuous_across_the_threshold() {
    let side = DVec3::Y;
    // Directions sweeping from above the surface to below it: each step is small, so
    // each bent step must be small too (no jump where bending starts).
    let steps = 20_000;
    let mut previous = keep_on_side(DVec3::new(1.0, 0.2, 0.0).normalize(), side);
    for i in 1..=steps {
        let y = 0.2 - 0.6 * i as f64 / steps as f64;
        let kept = keep_on_side(DVec3::new(1.0, y, 0.0).normalize(), side);
        assert!(
            kept.distance(previous) < 1e-3,
            "a jump of {} at y = {y}",
            kept.distance(previous)
        );
        previous = kept;
    }
}

#[test]
fn the_shading_frame_faces_the_viewer_and_is_continuous() {
    let ng = DVec3::Y;
    let ns = DVec3::new(0.35, 1.0, 0.0).normalize();
    assert_eq!(
        shading_frame_normal(DVec3::NEG_Y, ng, ng),
        ng,
        "flat: ng itself"
    );
    let mut previous: Option<DVec3> = None;
    // Viewers sweeping from overhead to grazing on the side ns leans away from; the
    // rays all arrive on ng's front side.
    for i in 0..=20_000 {
        let angle = 1.55 * i as f64 / 20_000.0;
        let wo = DVec3::new(-angle.sin(), angle.cos(), 0.0);
        let n = shading_frame_normal(-wo, ng, ns);
        assert!((n.length() - 1.0).abs() < 1e-12);
        assert!(
            wo.dot(n) > 0.0,
            "the viewer {wo} is behind the shading normal {n}"
        );
        if wo.dot(ns) >= MIN_SECONDARY_COSINE {
            assert_eq!(n, ns, "tilted although the viewer is in front of ns");
        }
        if let Some(p) = previous {
            assert!(n.distance(p) < 1e-3, "a jump at angle {angle}");
        }
        previous = Some(n);
    }
}
