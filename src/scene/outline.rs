//! Whether a polygon's outline crosses itself: the one case where the ways the tracers
//! fill polygons could disagree. A polygon of at most
//! [`MAX_POLYGON_VERTICES`] vertices is filled by the crossing-number
//! (even-odd) test of the lecture's inside-outside rule; a larger one is ear-clipped into
//! triangles, and an emitter is sampled by the triangles of its outline, both of which
//! equal the even-odd fill only for a simple outline (`docs/scene-format.md`).

use std::collections::HashMap;

/// Polygons with more vertices than this are triangulated when the geometry is built
/// (with earcut), so that no single primitive test runs more than this many loop
/// iterations on the GPU (see `docs/model.md`, "Bounded work"); smaller ones are
/// tested whole by the even-odd crossing test.
pub const MAX_POLYGON_VERTICES: usize = 32;

use glam::{DVec2, DVec3};

/// A pair of edges `(i, j)`, `i < j`, of the closed outline `vertices` (edge
/// `k` runs from vertex `k` to vertex `k + 1`, the last back to vertex 0) that cross or
/// touch, adjacent edges only where they overlap; `None` for a simple outline. The
/// outline is projected onto the plane perpendicular to `normal`'s dominant axis.
/// Edges are bucketed in a uniform grid so that outlines of tens of thousands of
/// vertices are checked in about linear time.
pub fn self_crossing(vertices: &[DVec3], normal: DVec3) -> Option<(usize, usize)> {
    let n = vertices.len();
    if n < 4 {
        return None;
    }
    let axis = normal.abs().max_position();
    let points: Vec<DVec2> = vertices
        .iter()
        .map(|v| match axis {
            0 => DVec2::new(v.y, v.z),
            1 => DVec2::new(v.z, v.x),
            _ => DVec2::new(v.x, v.y),
        })
        .collect();
    let edge = |k: usize| (points[k], points[(k + 1) % n]);
    let (lo, hi) = points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let side = (n as f64).sqrt().ceil().max(1.0);
    let size = ((hi - lo) / side).max(DVec2::splat(f64::MIN_POSITIVE));
    let cell = |p: DVec2| {
        let c = ((p - lo) / size).floor();
        (
            (c.x.clamp(0.0, side - 1.0)) as i64,
            (c.y.clamp(0.0, side - 1.0)) as i64,
        )
    };
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for k in 0..n {
        let (a, b) = edge(k);
        let (c0, c1) = (cell(a.min(b)), cell(a.max(b)));
        for cx in c0.0..=c1.0 {
            for cy in c0.1..=c1.1 {
                let bucket = grid.entry((cx, cy)).or_default();
                if let Some(&other) = bucket
                    .iter()
                    .find(|&&other| edges_meet(k, other, n, edge(k), edge(other)))
                {
                    return Some((other, k));
                }
                bucket.push(k);
            }
        }
    }
    None
}

/// Whether edges `i` and `j` of an outline of `n` edges meet where they should not:
/// anywhere for edges that share no vertex, along a stretch for adjacent ones.
fn edges_meet(
    i: usize,
    j: usize,
    n: usize,
    (a, b): (DVec2, DVec2),
    (c, d): (DVec2, DVec2),
) -> bool {
    let adjacent = (i + 1) % n == j || (j + 1) % n == i;
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if adjacent {
        // Sharing a vertex is their design; overlapping along a line is a fold back.
        return d1 == 0.0 && d2 == 0.0 && collinear_overlap(a, b, c, d);
    }
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on_segment(c, d, a))
        || (d2 == 0.0 && on_segment(c, d, b))
        || (d3 == 0.0 && on_segment(a, b, c))
        || (d4 == 0.0 && on_segment(a, b, d))
}

/// Twice the signed area of triangle (p, q, r): positive counter-clockwise.
fn orient(p: DVec2, q: DVec2, r: DVec2) -> f64 {
    (q - p).perp_dot(r - p)
}

/// Whether `r`, collinear with segment p–q, lies on it.
fn on_segment(p: DVec2, q: DVec2, r: DVec2) -> bool {
    r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
}

/// Whether collinear segments a–b and c–d (sharing an end) overlap beyond that end.
fn collinear_overlap(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let direction = b - a;
    let t = |p: DVec2| (p - a).dot(direction);
    let (lo, hi) = (0.0, direction.length_squared());
    let (s0, s1) = (t(c).min(t(d)), t(c).max(t(d)));
    s1.min(hi) - s0.max(lo) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outline(points: &[(f64, f64)]) -> Vec<DVec3> {
        points.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
    }

    #[test]
    fn simple_outlines_have_no_crossing() {
        let square = outline(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
        assert_eq!(self_crossing(&square, DVec3::Z), None);
        // A concave star of 10 corners.
        let star: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let a = f64::from(i) * std::f64::consts::TAU / 10.0;
                let r = if i % 2 == 0 { 1.0 } else { 0.4 };
                (r * a.cos(), r * a.sin())
            })
            .collect();
        assert_eq!(self_crossing(&outline(&star), DVec3::Z), None);
        // A wavy outline of 70,000 corners (tests/integration/stress_scenes.rs).
        let rug: Vec<DVec3> = (0..70_000)
            .map(|i| {
                let a = f64::from(i) / 70_000.0 * std::f64::consts::TAU;
                let r = 1.5 + 0.3 * (12.0 * a).sin();
                DVec3::new(r * a.cos(), 0.01, -r * a.sin())
            })
            .collect();
        assert_eq!(self_crossing(&rug, DVec3::Y), None);
    }

    #[test]
    fn crossings_and_touches_are_found() {
        // A bow tie: edges 0 and 2 cross.
        let bow = outline(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]);
        assert_eq!(self_crossing(&bow, DVec3::Z), Some((0, 2)));
        // A pentagram {5/2}: every edge crosses two others.
        let pentagram: Vec<(f64, f64)> = (0..5)
            .map(|i| {
                let a = f64::from(2 * i) * std::f64::consts::TAU / 5.0;
                (a.cos(), a.sin())
            })
            .collect();
        assert!(self_crossing(&outline(&pentagram), DVec3::Z).is_some());
        // A vertex touching another edge.
        let touch = outline(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 0.0), (0.0, 2.0)]);
        assert!(self_crossing(&touch, DVec3::Z).is_some());
        // Folding back along an edge.
        let fold = outline(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)]);
        assert!(self_crossing(&fold, DVec3::Z).is_some());
    }
}
