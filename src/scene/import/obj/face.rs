//! Cutting an OBJ face (a planar polygon of any number of corners, convex or not) into
//! triangles.
//!
//! A convex face is fanned from its first corner, the triangles every reader makes of
//! it. A fan covers a concave face's notches (a ring drawn as one face, out along the
//! rim and back along the hole, becomes a disc), so any other face is ear-clipped, as
//! tinyobjloader and assimp do: mapbox's earcut in the plane that drops the dominant
//! axis of the face's Newell normal.

use earcut::Earcut;
use glam::{DVec2, DVec3};

/// Twice the area, relative to the squared extent of the face, below which a face or
/// triangle has none (a face scaled to at most 1 across, so this is about the rounding
/// of its coordinates).
const NO_AREA: f64 = 1e-12;

/// How a face was cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Cut {
    /// Fanned from its first corner: a triangle, a convex face, or a face with no area.
    Fan,
    /// Ear-clipped: a concave face.
    Ears,
    /// Fanned because ear clipping could not cover it (it crosses itself, or is not
    /// flat enough to have one outline in its plane): its triangles may overlap.
    FanAfterEarsFailed,
}

/// Buffers reused from face to face.
#[derive(Default)]
pub(super) struct FaceCutter {
    earcut: Earcut<f64>,
    projected: Vec<[f64; 2]>,
    ears: Vec<u32>,
}

impl FaceCutter {
    /// Appends to `out` the triangles of the face whose corners are `corners` (in the
    /// file's order), as indices into `corners`, each wound as the face is (its normal
    /// on the side of the face's Newell normal).
    pub fn cut(&mut self, corners: &[DVec3], out: &mut Vec<[u32; 3]>) -> Cut {
        let n = corners.len();
        let fan = |out: &mut Vec<[u32; 3]>| {
            out.extend((1..n.saturating_sub(1)).map(|i| [0, i as u32, i as u32 + 1]));
        };
        if n <= 3 {
            fan(out);
            return Cut::Fan;
        }
        // Relative to the first corner and scaled to at most 1, so that no product below
        // overflows whatever the coordinates.
        let origin = corners[0];
        let extent = corners
            .iter()
            .map(|p| (*p - origin).abs().max_element())
            .fold(0.0, f64::max);
        if !(extent > 0.0 && extent.is_finite()) {
            fan(out);
            return Cut::Fan;
        }
        let local = |i: usize| (corners[i % n] - origin) / extent;
        // Newell's normal: twice the vector area of the polygon, the best-fitting plane's
        // normal for a face that is not quite flat (Sutherland, Sproull and Schumacker,
        // "A Characterization of Ten Hidden-Surface Algorithms", 1974, appendix).
        let normal: DVec3 = (0..n).map(|i| local(i).cross(local(i + 1))).sum();
        let axis = normal.abs().max_position();
        if normal[axis].abs() <= NO_AREA {
            // No area: a degenerate face (its triangles are dropped later), or one whose
            // outline crosses itself into lobes of opposite turn that cancel.
            let start = out.len();
            fan(out);
            let lobes = out[start..].iter().any(|&[p, q, r]| {
                let [p, q, r] = [p, q, r].map(|i| local(i as usize));
                (q - p).cross(r - p).length() > NO_AREA
            });
            return if lobes {
                Cut::FanAfterEarsFailed
            } else {
                Cut::Fan
            };
        }
        // The other two axes in cyclic order, the second negated when the normal points
        // down the dropped axis, so that the face runs counter-clockwise in the plane.
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let sign = normal[axis].signum();
        self.projected.clear();
        self.projected
            .extend((0..n).map(|i| [local(i)[a], sign * local(i)[b]]));
        if is_convex(&self.projected) {
            fan(out);
            return Cut::Fan;
        }
        self.earcut.earcut(
            self.projected.iter().copied(),
            &[] as &[u32],
            &mut self.ears,
        );
        let point = |i: u32| DVec2::from(self.projected[i as usize]);
        let area = |[p, q, r]: [u32; 3]| (point(q) - point(p)).perp_dot(point(r) - point(p)) / 2.0;
        let outline = outline_area(&self.projected);
        let start = out.len();
        let mut covered = 0.0;
        for ear in self.ears.chunks_exact(3) {
            let mut triangle = [ear[0], ear[1], ear[2]];
            let signed = area(triangle);
            if signed < 0.0 {
                triangle.swap(1, 2);
            }
            covered += signed.abs();
            out.push(triangle);
        }
        // Ear clipping covers a simple polygon exactly once; a face that crosses itself
        // leaves part of its outline uncovered, or covers some twice.
        if outline > 0.0 && (covered - outline).abs() <= 1e-9 * outline.max(1.0) {
            Cut::Ears
        } else {
            out.truncate(start);
            fan(out);
            Cut::FanAfterEarsFailed
        }
    }
}

/// The signed area of a polygon in the plane (positive when counter-clockwise).
fn outline_area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| DVec2::from(points[i]).perp_dot(DVec2::from(points[(i + 1) % n])))
        .sum::<f64>()
        / 2.0
}

/// Whether a counter-clockwise polygon is convex: it never turns right, and it goes
/// round once (the edges' `x` and `y` directions each change sign at most twice, which a
/// star that turns left at every corner but winds twice does not).
fn is_convex(points: &[[f64; 2]]) -> bool {
    let n = points.len();
    let edge = |i: usize| DVec2::from(points[(i + 1) % n]) - DVec2::from(points[i % n]);
    if (0..n).any(|i| edge(i).perp_dot(edge(i + 1)) < 0.0) {
        return false;
    }
    let sign_changes = |component: fn(DVec2) -> f64| {
        let mut signs = (0..n)
            .map(|i| component(edge(i)))
            .filter(|c| *c != 0.0)
            .map(f64::signum);
        let Some(first) = signs.next() else {
            return 0;
        };
        let (mut changes, mut previous) = (0, first);
        for sign in signs.chain([first]) {
            changes += usize::from(sign != previous);
            previous = sign;
        }
        changes
    };
    sign_changes(|e| e.x) <= 2 && sign_changes(|e| e.y) <= 2
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cut(corners: &[DVec3]) -> (Vec<[u32; 3]>, Cut) {
        let mut out = Vec::new();
        let how = FaceCutter::default().cut(corners, &mut out);
        (out, how)
    }

    /// The total area of `triangles` of `corners`, and whether each is wound along `normal`.
    fn area_and_winding(corners: &[DVec3], triangles: &[[u32; 3]], normal: DVec3) -> (f64, bool) {
        let mut area = 0.0;
        let mut wound = true;
        for t in triangles {
            let [p, q, r] = t.map(|i| corners[i as usize]);
            let cross = (q - p).cross(r - p);
            area += cross.length() / 2.0;
            wound &= cross.dot(normal) >= 0.0;
        }
        (area, wound)
    }

    #[test]
    fn convex_faces_are_fanned_from_the_first_corner() {
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        assert_eq!(cut(&square), (vec![[0, 1, 2], [0, 2, 3]], Cut::Fan));
        // Collinear corners do not make a face concave.
        let with_midpoint = [
            DVec3::ZERO,
            DVec3::X * 0.5,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
        ];
        assert_eq!(cut(&with_midpoint).1, Cut::Fan);
    }

    #[test]
    fn a_concave_face_is_ear_clipped_to_its_own_area_in_any_plane_and_winding() {
        // An L: fanned from corner 0 (the inner corner's opposite) it would cover the notch.
        let l = [
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 1.0),
        ];
        for (plane, normal) in [
            (
                (|p| DVec3::new(p.x, p.y, 5.0)) as fn(DVec2) -> DVec3,
                DVec3::Z,
            ),
            (|p: DVec2| DVec3::new(5.0, p.x, p.y), DVec3::X),
            (|p: DVec2| DVec3::new(p.y, -3.0, p.x), DVec3::Y),
        ] {
            for reversed in [false, true] {
                let mut corners: Vec<DVec3> = l.iter().map(|p| plane(*p)).collect();
                let mut normal = normal;
                if reversed {
                    corners.reverse();
                    normal = -normal;
                }
                let (triangles, how) = cut(&corners);
                assert_eq!(how, Cut::Ears);
                assert_eq!(triangles.len(), 4);
                let (area, wound) = area_and_winding(&corners, &triangles, normal);
                assert!((area - 3.0).abs() < 1e-12, "area {area}");
                assert!(wound, "{triangles:?}");
            }
        }
    }

    #[test]
    fn a_self_crossing_face_falls_back_to_a_fan() {
        // Bow ties: edges that cross, with lobes of equal area (no net area) and not.
        for corners in [
            [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::X, DVec3::Y],
            [
                DVec3::ZERO,
                DVec3::new(2.0, 2.0, 0.0),
                DVec3::X * 2.0,
                DVec3::Y,
            ],
        ] {
            let (triangles, how) = cut(&corners);
            assert_eq!(how, Cut::FanAfterEarsFailed, "{corners:?}");
            assert_eq!(triangles, vec![[0, 1, 2], [0, 2, 3]]);
        }
    }

    #[test]
    fn a_five_pointed_star_drawn_in_one_stroke_is_not_convex() {
        let star: Vec<[f64; 2]> = (0..5)
            .map(|k| {
                let angle = f64::from(k * 2) * std::f64::consts::TAU / 5.0;
                [angle.cos(), angle.sin()]
            })
            .collect();
        assert!(!is_convex(&star));
        let pentagon: Vec<[f64; 2]> = (0..5)
            .map(|k| {
                let angle = f64::from(k) * std::f64::consts::TAU / 5.0;
                [angle.cos(), angle.sin()]
            })
            .collect();
        assert!(is_convex(&pentagon));
    }

    #[test]
    fn faces_without_area_or_with_huge_coordinates_do_not_fail() {
        let point = [DVec3::ONE; 5];
        assert_eq!(cut(&point).0.len(), 3);
        let huge = [
            DVec3::splat(-1e308),
            DVec3::new(1e308, -1e308, 0.0),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1e308, 1e308, 0.0),
            DVec3::new(-1e308, 1e308, 0.0),
        ];
        assert_eq!(cut(&huge).0.len(), 3);
    }
}
