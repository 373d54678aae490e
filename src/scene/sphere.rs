//! Spheres relative to their anchor, and how precisely each backend can place one.
//!
//! A sphere far larger than the scene, such as a "ground" sphere of radius 1e10 resting
//! on the origin, cannot be intersected relative to its centre: the centre is 1e10 away,
//! where an `f32` has a spacing of 1024 units (and an `f64` one of 2e-6), so
//! `|o - c|² - r²` loses every digit that says where the surface near the camera is.
//! Both tracers therefore intersect a sphere relative to its **anchor**, its point
//! nearest the world origin, with the outward normal there, in units of its radius
//! (Haines, Günther and Akenine-Möller, "Precision Improvements for Ray/Sphere
//! Intersection", Ray Tracing Gems, ch. 7, §7.3 and 7.4, carried to a better-conditioned
//! point): with `y = (p - a)/r`, the sphere is `|y + n|² = 1`, that is
//! `y·(y + 2n) = 0`, a form whose terms are as small as the distance from the anchor.
//! The anchor is computed once, in `f64`, from the centre and the radius.
//!
//! What still limits a sphere is how precisely its anchor is known: the anchor is
//! `c + r·n`, rounded in `f64` to about `2.2e-16·max(|c|, r)` (exact when the centre and
//! radius are, as `(0, -1e20, 0)` and `1e20` are), and the GPU then rounds it to `f32`,
//! about `1.2e-7·|a|`. [`sphere_precision`] gives both, relative to the distance from the
//! camera, and the loader warns when either exceeds [`SPHERE_PRECISION_LIMIT`].

use glam::DVec3;

/// A sphere's anchor: its point nearest the world origin and the unit outward normal
/// there (`normalize(-c)`; `+y` for a sphere centred on the origin).
pub fn sphere_anchor(center: DVec3, radius: f64) -> (DVec3, DVec3) {
    let normal = (-center).try_normalize().unwrap_or(DVec3::Y);
    (center + normal * radius, normal)
}

/// `(|p - c|² - r²) / r²` for the sphere of radius `radius` through `anchor` with outward
/// normal `normal` there, computed as `y·(y + 2n)` with `y = (p - anchor)/r`: negative
/// inside the sphere, zero on it, positive outside, and as precise as `p - anchor`.
pub fn sphere_level(point: DVec3, anchor: DVec3, normal: DVec3, radius: f64) -> f64 {
    let y = (point - anchor) / radius;
    y.dot(y + 2.0 * normal)
}

/// Relative precision above which the loader warns about a sphere: the error of its
/// surface on a backend as a fraction of its distance from the camera. A pixel of a
/// 1000-pixel-high image with a 45° field of view is 8e-4 of the distance.
pub const SPHERE_PRECISION_LIMIT: f64 = 1e-4;

/// How precisely each backend places a surface (a sphere's, [`sphere_precision`], or a
/// flat shape's, [`crate::scene::flat_precision`]), as seen from a camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePrecision {
    /// Distance from the camera to the sphere's surface (scene units).
    pub distance: f64,
    /// About how far the CPU reference (`f64`) may misplace the surface near its
    /// anchor: the rounding of the anchor, `2.2e-16·max(|c|∞, r)`.
    pub cpu: f64,
    /// The same for the GPU (`f32`): the CPU's error plus the `f32` rounding of the
    /// anchor, `1.2e-7·|a|∞`.
    pub gpu: f64,
}

impl SurfacePrecision {
    /// The CPU's error as a fraction of the distance (infinite for a camera on the
    /// surface).
    pub fn cpu_relative(&self) -> f64 {
        self.cpu / self.distance
    }

    /// The GPU's error as a fraction of the distance.
    pub fn gpu_relative(&self) -> f64 {
        self.gpu / self.distance
    }

    /// Whether the CPU reference cannot place the sphere to [`SPHERE_PRECISION_LIMIT`].
    pub fn cpu_hopeless(&self) -> bool {
        beyond_the_limit(self.cpu_relative())
    }

    /// Whether the GPU cannot place the sphere to [`SPHERE_PRECISION_LIMIT`].
    pub fn gpu_hopeless(&self) -> bool {
        beyond_the_limit(self.gpu_relative())
    }
}

/// Whether a relative error exceeds [`SPHERE_PRECISION_LIMIT`] (NaN counts as exceeding).
fn beyond_the_limit(relative: f64) -> bool {
    relative.is_nan() || relative > SPHERE_PRECISION_LIMIT
}

/// How precisely the CPU reference and the GPU place the surface of the sphere
/// (`center`, `radius`) seen from `eye`; see the module documentation.
pub fn sphere_precision(center: DVec3, radius: f64, eye: DVec3) -> SurfacePrecision {
    let (anchor, normal) = sphere_anchor(center, radius);
    // | |e - c| - r | = |level|·r / (|y + n| + 1), without cancellation.
    let y = (eye - anchor) / radius;
    let distance =
        sphere_level(eye, anchor, normal, radius).abs() * radius / ((y + normal).length() + 1.0);
    let cpu = f64::EPSILON * center.abs().max_element().max(radius);
    let gpu = cpu + f64::from(f32::EPSILON) * anchor.abs().max_element();
    SurfacePrecision { distance, cpu, gpu }
}

/// Fraction of the scene's extent above which the loader warns that the GPU places the
/// far side of a sphere around the camera too coarsely ([`far_wall_precision`]). The
/// pipeline fuzzer's scenes 1e-2 across inside ground spheres (docs/numerics.md, "The
/// far wall of a sphere around the camera") first differ at about 0.2 (radius 1e4)
/// and agree at 0.065 (radius 3e3) and below.
pub const FAR_WALL_PRECISION_LIMIT: f64 = 1e-2;

/// How precisely the GPU places points on the far side of a sphere that contains the
/// camera, against the size of the rest of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FarWallPrecision {
    /// About how far the GPU (`f32`) may misplace a point of the far side, and a ray
    /// that comes back from it: the `f32` spacing of coordinates up to `|a|∞ + 2r`
    /// from the origin, `1.2e-7·(|a|∞ + 2r)`. The CPU's (`f64`) is 2^29 times smaller.
    pub gpu: f64,
    /// The extent of the rest of the scene (see [`far_wall_precision`]).
    pub extent: f64,
}

impl FarWallPrecision {
    /// The GPU's error as a fraction of the scene's extent.
    pub fn relative(&self) -> f64 {
        self.gpu / self.extent
    }

    /// Whether it exceeds [`FAR_WALL_PRECISION_LIMIT`] (NaN counts as exceeding).
    pub fn hopeless(&self) -> bool {
        let relative = self.relative();
        relative.is_nan() || relative > FAR_WALL_PRECISION_LIMIT
    }
}

/// For a sphere (`center`, `radius`) that contains `eye`, how precisely the GPU places
/// its far side, up to `2r` from the camera, against `extent`, the size of the rest of
/// the scene (the largest side of the box around the eye, the point lights and the
/// bounded shapes other than the spheres around the eye); `None` when the eye is not
/// inside the sphere. A path that crosses the sphere and comes back (a shadow ray from
/// the far side to a light in the scene, a reflection that returns) arrives with an
/// error of that size: where it is a sizeable part of the scene the GPU cannot say
/// which small object such a path passes or hits, whatever the intersection tests do
/// (the ray's own direction in `f32` is only known to `6e-8` radians). It is an `f32`
/// limit, not a bug: the CPU reference places the same points 2^29 times better.
pub fn far_wall_precision(
    center: DVec3,
    radius: f64,
    eye: DVec3,
    extent: f64,
) -> Option<FarWallPrecision> {
    let (anchor, normal) = sphere_anchor(center, radius);
    let level = sphere_level(eye, anchor, normal, radius);
    if level.is_nan() || level >= 0.0 {
        return None;
    }
    let gpu = f64::from(f32::EPSILON) * (anchor.abs().max_element() + 2.0 * radius);
    Some(FarWallPrecision { gpu, extent })
}

/// How far apart the surfaces of two spheres are where the camera looks at the first,
/// and how finely the GPU can tell them apart there ([`coincident_spheres`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereGap {
    /// The distance from the first sphere's point nearest the camera to the second
    /// sphere's surface.
    pub gap: f64,
    /// About how far the GPU (`f32`) may misplace either surface there: both spheres'
    /// [`SurfacePrecision::gpu`] and the `f32` rounding of a hit at that distance.
    pub gpu: f64,
    /// The same for the CPU reference (`f64`).
    pub cpu: f64,
}

/// Two spheres, each at least 100 times larger than its distance from `eye`, whose
/// surfaces near the camera lie closer together than the GPU can place them
/// (`Some`), or `None`: which of the two is in front is then decided by `f32`
/// rounding, not by the scene (z-fighting). Two ground spheres whose centres differ
/// by 1e-3 are 1e-11 apart near their tops; seen from 5e-3 the GPU places a hit to
/// 6e-10. Large spheres only, so that the gap is about the same across the view (two
/// small spheres touching at a point that happens to face the camera are not
/// reported).
pub fn coincident_spheres(
    first: (DVec3, f64),
    second: (DVec3, f64),
    eye: DVec3,
) -> Option<SphereGap> {
    let (a1, n1) = sphere_anchor(first.0, first.1);
    let (a2, n2) = sphere_anchor(second.0, second.1);
    let p1 = sphere_precision(first.0, first.1, eye);
    let p2 = sphere_precision(second.0, second.1, eye);
    let large = |p: &SurfacePrecision, radius: f64| p.distance * 100.0 <= radius;
    if !(large(&p1, first.1) && large(&p2, second.1)) {
        return None;
    }
    // The first sphere's point nearest the eye: the eye moved radially onto it,
    // relative to the anchor (as `project_onto_sphere` in src/cpu/intersect.rs).
    let y = (eye - a1) / first.1;
    let m = y + n1;
    let length = m.length();
    if length.is_nan() || length <= 0.0 {
        return None;
    }
    let p = eye - m * (y.dot(y + 2.0 * n1) / (length * (length + 1.0)) * first.1);
    let y2 = (p - a2) / second.1;
    let gap = sphere_level(p, a2, n2, second.1).abs() * second.1 / ((y2 + n2).length() + 1.0);
    let distance = p1.distance.max(p2.distance);
    let gpu = p1.gpu.max(p2.gpu) + f64::from(f32::EPSILON) * distance;
    let cpu = p1.cpu.max(p2.cpu) + f64::EPSILON * distance;
    (gap <= gpu).then_some(SphereGap { gap, gpu, cpu })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_anchor_is_the_point_nearest_the_origin() {
        let (anchor, normal) = sphere_anchor(DVec3::new(0.0, -1e10, 0.0), 1e10);
        assert_eq!(anchor, DVec3::ZERO);
        assert_eq!(normal, DVec3::Y);
        let (anchor, normal) = sphere_anchor(DVec3::new(3.0, 0.0, 4.0), 1.0);
        assert!((anchor - DVec3::new(2.4, 0.0, 3.2)).length() < 1e-15);
        assert!((normal - DVec3::new(-0.6, 0.0, -0.8)).length() < 1e-15);
        // Centred on the origin: any direction will do; +y.
        assert_eq!(
            sphere_anchor(DVec3::ZERO, 2.0),
            (DVec3::new(0.0, 2.0, 0.0), DVec3::Y)
        );
    }

    #[test]
    fn the_level_is_exact_far_from_the_centre() {
        let (anchor, normal) = sphere_anchor(DVec3::new(0.0, -1e20, 0.0), 1e20);
        // 3 units above the top of a sphere of radius 1e20: (|p - c|² - r²)/r² =
        // (2·3·r + 9)/r² ≈ 6e-20, which |p - c|² - r² in f64 cannot give at all.
        let level = sphere_level(DVec3::new(0.0, 3.0, 0.0), anchor, normal, 1e20);
        assert!((level - 6e-20).abs() < 1e-33, "{level}");
        assert!(sphere_level(DVec3::new(0.0, -1.0, 0.0), anchor, normal, 1e20) < 0.0);
    }

    #[test]
    fn precision_of_a_ground_sphere_and_a_hopeless_one() {
        let eye = DVec3::new(0.0, 3.0, 4.0);
        let ground = sphere_precision(DVec3::new(0.0, -1000.0, 0.0), 1000.0, eye);
        assert!((ground.distance - 3.0).abs() < 0.01, "{ground:?}");
        assert!(
            !ground.cpu_hopeless() && !ground.gpu_hopeless(),
            "{ground:?}"
        );
        let huge = sphere_precision(DVec3::new(0.0, -1e20, 0.0), 1e20, eye);
        assert!((huge.distance - 3.0).abs() < 1e-9, "{huge:?}");
        assert!(huge.cpu_hopeless() && huge.gpu_hopeless(), "{huge:?}");
        // A unit sphere a million units out, seen from 4 units: f64 is fine, f32 is not.
        let far = sphere_precision(
            DVec3::new(1e6, 0.0, 0.0),
            1.0,
            DVec3::new(1e6 - 5.0, 0.0, 0.0),
        );
        assert!(!far.cpu_hopeless() && far.gpu_hopeless(), "{far:?}");
    }

    #[test]
    fn far_wall_of_a_sphere_around_the_camera() {
        let eye = DVec3::new(0.0, -1e-3, 0.0);
        // Radius 1e5 around a scene 1e-2 across: 2.4e-2 units on the far side.
        let huge = far_wall_precision(DVec3::new(0.0, -1e5, 0.0), 1e5, eye, 1e-2).expect("inside");
        assert!(
            huge.hopeless() && (huge.gpu - 2.4e-2).abs() < 1e-3,
            "{huge:?}"
        );
        // Radius 100 around the same scene: 2.4e-5, 2.4e-3 of it.
        let small = far_wall_precision(DVec3::new(0.0, -100.0, 0.0), 100.0, eye, 1e-2);
        assert!(!small.expect("inside").hopeless());
        // A camera above the sphere is not inside it.
        let above = DVec3::new(0.0, 1e-3, 0.0);
        assert_eq!(
            far_wall_precision(DVec3::new(0.0, -1e5, 0.0), 1e5, above, 1e-2),
            None
        );
    }

    #[test]
    fn coincident_ground_spheres_and_separate_ones() {
        let eye = DVec3::new(0.0, 4e-3, -3e-3);
        let ground = (DVec3::new(0.0, -1e5, 0.0), 1e5);
        // Centres 1.2e-3 apart: 1.5e-11 apart near the camera, far below f32's 5e-10
        // and even below f64's rounding of an anchor 1e5 from the origin (2.2e-11).
        let moved = (DVec3::new(1.2e-3, -1e5, 0.0), 1e5);
        let gap = coincident_spheres(ground, moved, eye).expect("coincident");
        assert!(
            gap.gap < 2e-11 && gap.gpu > 4e-10 && gap.cpu > gap.gap,
            "{gap:?}"
        );
        // One 1e-3 lower: resolved.
        let lower = (DVec3::new(0.0, -1e5 - 1e-3, 0.0), 1e5);
        assert_eq!(coincident_spheres(ground, lower, eye), None);
        // Small tangent spheres seen from afar are not reported (only surfaces that are
        // nearly flat across the view are judged).
        let a = (DVec3::new(0.0, 0.0, 0.0), 1e-3);
        let b = (DVec3::new(0.0, 0.0, 2e-3), 1e-3);
        assert_eq!(coincident_spheres(a, b, DVec3::new(0.5, 0.0, 1e-3)), None);
    }
}
