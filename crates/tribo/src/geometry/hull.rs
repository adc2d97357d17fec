//! Convex hull of a point cloud.
//!
//! Algorithm: Andrew's monotone chain (A. M. Andrew, "Another efficient algorithm for convex
//! hulls in two dimensions", 1979): sort the points by (x, y), build the lower chain left to
//! right and the upper chain right to left, popping every point that does not make a strict
//! left turn. O(n log n), exact for exactly collinear and duplicate points.
//!
//! Then, on the hull only (interior points never matter):
//! 1. welding: consecutive hull vertices closer than [`LINEAR_SLOP`] are merged (the first one
//!    in counter-clockwise order from the start vertex is kept);
//! 2. collinear removal: a vertex whose outward distance from the line through its two
//!    neighbours is below `0.5 · LINEAR_SLOP` is dropped (the smallest such distance first,
//!    repeated until none is left), which also removes any reflex vertex welding created.
//!
//! The result is counter-clockwise and starts at the lowest-x (then lowest-y) vertex, so the
//! same input always gives the same output, and the four corners of an axis-aligned box come
//! out as (-hx,-hy), (hx,-hy), (hx,hy), (-hx,hy).

use super::{GeometryError, LINEAR_SLOP};
use crate::math::Vec2;

/// Hull vertices closer than this are merged [m].
const WELD_DISTANCE: f32 = LINEAR_SLOP;

/// A hull vertex closer than this to the line through its neighbours is removed [m].
const COLLINEAR_DISTANCE: f32 = 0.5 * LINEAR_SLOP;

/// Counter-clockwise convex hull of `points` [m].
///
/// Points closer than [`LINEAR_SLOP`] (5 mm) are welded and hull vertices within
/// `0.5 · LINEAR_SLOP` of the line through their neighbours are removed. The first returned
/// vertex is the one with the lowest x (ties: lowest y). The hull may have any number of
/// vertices; [`super::Polygon::from_points`] enforces the polygon limit.
///
/// Errors: [`GeometryError::NonFinite`]`("points")` if a coordinate is NaN or infinite;
/// [`GeometryError::DegeneratePolygon`] if fewer than 3 distinct points remain after welding
/// or all points lie on one line (within tolerance).
pub fn convex_hull(points: &[Vec2]) -> Result<Vec<Vec2>, GeometryError> {
    if points.iter().any(|p| !p.is_finite()) {
        return Err(GeometryError::NonFinite("points"));
    }

    let mut sorted: Vec<Vec2> = points.to_vec();
    sorted.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));

    let mut hull = monotone_chain(&sorted);
    weld(&mut hull);
    remove_collinear(&mut hull);

    if hull.len() < 3 {
        return Err(degenerate_reason(points, &hull));
    }

    // Rotate so the lowest-x, then lowest-y vertex comes first (it may have been welded away
    // or removed as collinear).
    let mut start = 0;
    for (i, v) in hull.iter().enumerate() {
        let s = hull[start];
        if v.x < s.x || (v.x == s.x && v.y < s.y) {
            start = i;
        }
    }
    hull.rotate_left(start);
    Ok(hull)
}

/// `(a - o) × (b - o)`: positive when o → a → b turns left (counter-clockwise).
fn turn(o: Vec2, a: Vec2, b: Vec2) -> f32 {
    (a - o).cross(b - o)
}

/// Andrew's monotone chain on points sorted by (x, y). Keeps strict left turns only, so
/// duplicates and exactly collinear points are dropped. Returns fewer than 3 points when all
/// points are on one line.
fn monotone_chain(sorted: &[Vec2]) -> Vec<Vec2> {
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * sorted.len() + 1);
    // Lower chain, left to right.
    for &p in sorted {
        while hull.len() >= 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    // Upper chain, right to left (the last sorted point is already on the hull).
    let lower_len = hull.len() + 1;
    for &p in sorted.iter().rev().skip(1) {
        while hull.len() >= lower_len && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    // The upper chain ends on the first point again.
    if hull.len() > 1 {
        hull.pop();
    }
    hull
}

/// Merges consecutive hull vertices (cyclically) closer than [`WELD_DISTANCE`].
fn weld(hull: &mut Vec<Vec2>) {
    let tol2 = WELD_DISTANCE * WELD_DISTANCE;
    let mut out: Vec<Vec2> = Vec::with_capacity(hull.len());
    for &p in hull.iter() {
        match out.last() {
            Some(&q) if (p - q).length_squared() < tol2 => {}
            _ => out.push(p),
        }
    }
    // Wrap-around: the last kept vertex against the first.
    while out.len() > 1 {
        let first = out[0];
        let last = out[out.len() - 1];
        if (last - first).length_squared() < tol2 {
            out.pop();
        } else {
            break;
        }
    }
    *hull = out;
}

/// Removes vertices that are (nearly) on the line through their neighbours, or reflex.
fn remove_collinear(hull: &mut Vec<Vec2>) {
    while hull.len() >= 3 {
        let n = hull.len();
        let mut worst: Option<(usize, f32)> = None;
        for i in 0..n {
            let prev = hull[(i + n - 1) % n];
            let next = hull[(i + 1) % n];
            let chord = next - prev;
            let len = chord.length();
            // Outward (right of the chord prev → next) distance of the vertex.
            let dist = if len > 0.0 {
                (hull[i] - prev).cross(chord) / len
            } else {
                0.0
            };
            if dist < COLLINEAR_DISTANCE && !matches!(worst, Some((_, d)) if d <= dist) {
                worst = Some((i, dist));
            }
        }
        match worst {
            Some((i, _)) => {
                hull.remove(i);
            }
            None => break,
        }
    }
}

/// Explains why fewer than 3 hull vertices remain.
fn degenerate_reason(points: &[Vec2], hull: &[Vec2]) -> GeometryError {
    // Collinear: the hull collapsed to a line yet some point is distinct from its ends.
    let tol2 = WELD_DISTANCE * WELD_DISTANCE;
    let distinct_from_hull = |p: &Vec2| hull.iter().all(|q| (*p - *q).length_squared() >= tol2);
    let three_distinct = hull.len() == 2 && points.iter().any(distinct_from_hull);
    if three_distinct {
        GeometryError::DegeneratePolygon(format!(
            "all {} points are collinear (within {} m)",
            points.len(),
            COLLINEAR_DISTANCE
        ))
    } else {
        GeometryError::DegeneratePolygon(format!(
            "fewer than 3 distinct points ({} given, {} distinct after merging points closer than {} m)",
            points.len(),
            hull.len(),
            WELD_DISTANCE
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32) -> Vec2 {
        Vec2::new(x, y)
    }

    fn is_ccw_convex(h: &[Vec2]) -> bool {
        let n = h.len();
        (0..n).all(|i| turn(h[i], h[(i + 1) % n], h[(i + 2) % n]) > 0.0)
    }

    #[test]
    fn square_with_interior_points() {
        let pts = [
            v(0.2, 0.3),
            v(1.0, 1.0),
            v(-1.0, 1.0),
            v(0.0, 0.0),
            v(1.0, -1.0),
            v(-0.5, 0.5),
            v(-1.0, -1.0),
        ];
        let h = convex_hull(&pts).unwrap();
        assert_eq!(h, vec![v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0), v(-1.0, 1.0)]);
        assert!(is_ccw_convex(&h));
    }

    #[test]
    fn duplicates_are_welded() {
        let pts = [
            v(0.0, 0.0),
            v(0.0, 0.0),
            v(2.0, 0.0),
            v(2.001, 0.0005),
            v(1.0, 1.5),
            v(1.0, 1.5),
            v(0.0005, -0.001),
        ];
        let h = convex_hull(&pts).unwrap();
        assert_eq!(h.len(), 3, "{h:?}");
        assert!(is_ccw_convex(&h));
        // All-identical points: fewer than 3 distinct.
        let same = [v(1.0, 1.0); 5];
        match convex_hull(&same) {
            Err(GeometryError::DegeneratePolygon(msg)) => assert!(msg.contains("distinct"), "{msg}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn collinear_points_removed_or_rejected() {
        // Mid-edge points are removed.
        let pts = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(2.0, 0.0),
            v(2.0, 2.0),
            v(1.0, 2.001),
            v(0.0, 2.0),
        ];
        let h = convex_hull(&pts).unwrap();
        assert_eq!(h, vec![v(0.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(0.0, 2.0)]);
        // All on one line (one point 1 mm off): rejected as collinear.
        let line = [v(0.0, 0.0), v(1.0, 1.0), v(2.0, 2.0), v(3.0, 3.001)];
        match convex_hull(&line) {
            Err(GeometryError::DegeneratePolygon(msg)) => assert!(msg.contains("collinear"), "{msg}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn too_few_points() {
        for pts in [&[][..], &[v(0.0, 0.0)][..], &[v(0.0, 0.0), v(1.0, 0.0)][..]] {
            match convex_hull(pts) {
                Err(GeometryError::DegeneratePolygon(msg)) => assert!(msg.contains("distinct"), "{msg}"),
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn non_finite_rejected() {
        let pts = [v(0.0, 0.0), v(1.0, 0.0), v(f32::NAN, 1.0)];
        assert_eq!(convex_hull(&pts), Err(GeometryError::NonFinite("points")));
        let pts = [v(0.0, 0.0), v(1.0, 0.0), v(0.0, f32::INFINITY)];
        assert_eq!(convex_hull(&pts), Err(GeometryError::NonFinite("points")));
    }

    #[test]
    fn many_points_on_a_circle() {
        let pts: Vec<Vec2> = (0..12)
            .map(|i| {
                let a = i as f32 * core::f32::consts::TAU / 12.0;
                v(a.cos(), a.sin())
            })
            .collect();
        let h = convex_hull(&pts).unwrap();
        assert_eq!(h.len(), 12);
        assert!(is_ccw_convex(&h));
        // Starts at the lowest-x point, (cos π, sin π).
        assert_eq!(h[0], pts[6]);
        // Deterministic: same input, same output; shuffled input, same output.
        let mut rev = pts.clone();
        rev.reverse();
        assert_eq!(convex_hull(&rev).unwrap(), h);
    }
}
