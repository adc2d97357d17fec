//! Capsule–capsule contact (segment–capsule uses it with a zero radius for the segment).
//!
//! 1. Closest points of the two core segments (exact); if their distance minus the radii is
//!    not below `spec`, no contact.
//! 2. Cores touching or crossing (distance ≤ `0.1 · LINEAR_SLOP`): the closest-point direction
//!    is meaningless, so the capsules are handed to the polygon routine as 2-vertex polygons
//!    (separating axes = the two core perpendiculars, then clipping), which pushes along the
//!    axis of least penetration.
//! 3. Otherwise the normal is the closest-point direction. If it is perpendicular to one core
//!    (the closest point is interior to that core — the "face"), the other core is clipped to
//!    that face's extent (`clip_incident_edge`); when both clipped ends are within `spec` the
//!    manifold has those 2 points and the face normal. This is what keeps a capsule lying flat
//!    on a capsule or segment from rocking. The face is A's unless the normal is closer to
//!    perpendicular to B's core, so both argument orders pick the same face.
//! 4. Else one point at the closest features, midway between the surfaces, id kind 4.

use super::polygon_polygon::{collide_polygons_local, LocalPoly};
use super::{
    clip_incident_edge, feature_id, segment_closest, LocalManifold, Manifold, CORE_TOUCH, KIND_CLIP_REF_A,
    KIND_CLIP_REF_B, KIND_SEGMENT_FEATURES,
};
use crate::geometry::Capsule;
use crate::math::{Transform, Vec2};

/// |normal · core direction| below which the normal counts as perpendicular to the core.
const FACE_TOLERANCE: f32 = 1e-3;

/// Feature code of a segment parameter: 0 / 1 at the ends, 2 inside.
fn feature_code(f: f32) -> usize {
    if f == 0.0 {
        0
    } else if f == 1.0 {
        1
    } else {
        2
    }
}

/// A clipped face point: (midway point, separation, face edge index, incident vertex index).
type FacePoint = (Vec2, f32, usize, usize);

/// The face of core `r1`–`r2` (radius `r_ref`) facing direction `toward`, against the core
/// `i1`–`i2` (radius `r_inc`): up to 2 clipped points `(point, separation, face edge,
/// incident vertex)` and the face's outward normal. `None` unless both ends are kept.
#[allow(clippy::too_many_arguments)]
fn face_contact(
    r1: Vec2,
    r2: Vec2,
    r_ref: f32,
    i1: Vec2,
    i2: Vec2,
    r_inc: f32,
    toward: Vec2,
    spec: f32,
) -> Option<(Vec2, [FacePoint; 2])> {
    let p = (r2 - r1).right_perp().try_normalize()?;
    // Edge 0 runs r1 → r2 with outward normal p; edge 1 runs r2 → r1 with normal −p.
    let (n, v11, v12, edge) = if p.dot(toward) >= 0.0 {
        (p, r1, r2, 0)
    } else {
        (-p, r2, r1, 1)
    };
    let q = (i2 - i1).right_perp();
    let (v21, v22, i21, i22) = if q.dot(n) <= 0.0 {
        (i1, i2, 0, 1)
    } else {
        (i2, i1, 1, 0)
    };
    // (`emit` runs at most twice: `count` ends at most 2.)
    let mut pts = [(Vec2::ZERO, 0.0, edge, 0); 2];
    let mut count = 0;
    let clipped = clip_incident_edge(v11, v12, n, r_ref, v21, v22, i21, i22, r_inc, spec, |p| {
        if let Some(slot) = pts.get_mut(count) {
            *slot = (p.point, p.separation, edge, p.incident_vertex);
        }
        count += 1;
    });
    if !clipped || count < 2 {
        return None;
    }
    Some((n, pts))
}

/// Core `a1`–`a2` with radius `ra` against core `b1`–`b2` with radius `rb`, in A's frame.
pub(super) fn capsules_local(a1: Vec2, a2: Vec2, ra: f32, b1: Vec2, b2: Vec2, rb: f32, spec: f32) -> LocalManifold {
    let radius = ra + rb;
    let c = segment_closest(a1, a2, b1, b2);
    let delta = c.b - c.a;
    let dist = delta.length();
    if !(dist - radius < spec) {
        // The closest points: the exact distance.
        return LocalManifold {
            bound: if dist - radius > 0.0 { dist - radius } else { 0.0 },
            ..LocalManifold::default()
        };
    }
    if !(dist > CORE_TOUCH) {
        let pa = LocalPoly::from_segment(a1, a2, ra);
        let pb = LocalPoly::from_segment(b1, b2, rb);
        return collide_polygons_local(&pa, &pb, spec, None);
    }
    let normal = delta * (1.0 / dist);

    let (len_a, ua) = (a2 - a1).length_and_normalize();
    let (len_b, ub) = (b2 - b1).length_and_normalize();
    let da = if len_a > 0.0 { normal.dot(ua).abs() } else { f32::MAX };
    let db = if len_b > 0.0 { normal.dot(ub).abs() } else { f32::MAX };
    if da.min(db) < FACE_TOLERANCE {
        if da <= db {
            if let Some((n, pts)) = face_contact(a1, a2, ra, b1, b2, rb, normal, spec) {
                let mut m = LocalManifold::new(n);
                for (point, sep, edge, vertex) in pts {
                    m.push(point, sep, feature_id(KIND_CLIP_REF_A, edge, vertex), spec);
                }
                return m;
            }
        } else if let Some((n, pts)) = face_contact(b1, b2, rb, a1, a2, ra, -normal, spec) {
            let mut m = LocalManifold::new(-n);
            for (point, sep, edge, vertex) in pts {
                m.push(point, sep, feature_id(KIND_CLIP_REF_B, vertex, edge), spec);
            }
            return m;
        }
    }

    let mut m = LocalManifold::new(normal);
    let point = (c.a + normal * ra + c.b - normal * rb) * 0.5;
    let id = feature_id(KIND_SEGMENT_FEATURES, feature_code(c.fa), feature_code(c.fb));
    m.push(point, dist - radius, id, spec);
    m
}

/// Contact between capsules `a` (placed by `xf_a`) and `b` (placed by `xf_b`).
pub(super) fn collide_capsules(
    a: &Capsule,
    xf_a: Transform,
    b: &Capsule,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    capsules_local(
        a.center1,
        a.center2,
        a.radius,
        rel.apply(b.center1),
        rel.apply(b.center2),
        b.radius,
        spec,
    )
    .to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Capsule, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    const SPEC: f32 = SPECULATIVE_DISTANCE;

    fn cap(len: f32, r: f32) -> Shape {
        Shape::Capsule(Capsule::new(Vec2::new(-0.5 * len, 0.0), Vec2::new(0.5 * len, 0.0), r).unwrap())
    }

    #[test]
    fn flat_on_flat_gives_two_points() {
        let a = cap(4.0, 0.25);
        let b = cap(1.0, 0.2);
        let xa = Transform::new(Vec2::new(0.0, 0.0), 0.0);
        let xb = Transform::new(Vec2::new(0.3, 0.449), 0.0);
        let m = collide(&a, xa, &b, xb, SPEC);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let mut x: Vec<f32> = m.active_points().iter().map(|p| p.point.x).collect();
        x.sort_by(f32::total_cmp);
        assert!((x[0] + 0.2).abs() < 1e-5 && (x[1] - 0.8).abs() < 1e-5, "{x:?}");
        for p in m.active_points() {
            assert!((p.separation + 0.001).abs() < 1e-5);
            assert!((p.point.y - 0.2495).abs() < 1e-5);
        }
        assert_ne!(m.points[0].id, m.points[1].id);
        check_manifold(&m, xa, xb);
        // Slightly tilted (rocking): still two points.
        let m = collide(&a, xa, &b, Transform::new(Vec2::new(0.3, 0.452), 0.004), SPEC);
        assert_eq!(m.count, 2);
        // Overhanging the end of A: the overlap interval is clipped.
        let m = collide(&a, xa, &b, Transform::new(Vec2::new(2.3, 0.449), 0.0), SPEC);
        assert_eq!(m.count, 2);
        let mut x: Vec<f32> = m.active_points().iter().map(|p| p.point.x).collect();
        x.sort_by(f32::total_cmp);
        assert!((x[0] - 1.8).abs() < 1e-5 && (x[1] - 2.0).abs() < 1e-5, "{x:?}");
    }

    #[test]
    fn tilted_end_gives_one_point() {
        let a = cap(4.0, 0.25);
        let b = cap(1.0, 0.25);
        // B tilted 30°, its lower end resting on A's side.
        let ang = 30f32.to_radians();
        let end = Vec2::new(0.5 * ang.cos(), 0.5 * ang.sin());
        let xb = Transform::new(Vec2::new(0.0, 0.5) + end, ang);
        let m = collide(&a, Transform::IDENTITY, &b, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-5);
        assert!(m.points[0].separation.abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(0.0, 0.25), 1e-5);
    }

    #[test]
    fn end_to_end_and_apart() {
        let a = cap(2.0, 0.25);
        let xb = Transform::new(Vec2::new(2.51, 0.0), 0.0);
        let m = collide(&a, Transform::IDENTITY, &a, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(1.0, 0.0), 1e-6);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(1.255, 0.0), 1e-5);
        let xb = Transform::new(Vec2::new(0.0, 0.6), 0.0);
        assert_eq!(collide(&a, Transform::IDENTITY, &a, xb, SPEC).count, 0);
    }

    #[test]
    fn crossing_cores() {
        let a = cap(2.0, 0.1);
        let xb = Transform::new(Vec2::new(0.0, 0.2), core::f32::consts::FRAC_PI_2);
        let m = collide(&a, Transform::IDENTITY, &a, xb, SPEC);
        assert_eq!(m.count, 1);
        // Least penetration: push B up so its lower end clears A (core 0.8 deep + radii).
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        assert!((m.points[0].separation + 1.0).abs() < 1e-5, "{m:?}");
        for p in m.active_points() {
            assert!(p.separation.is_finite() && p.point.is_finite());
        }
    }
}
