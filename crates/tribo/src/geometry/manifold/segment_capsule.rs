//! Segment–capsule contact: the segment is a capsule of radius 0 (see `capsule_capsule`), so a
//! capsule lying on a segment gets 2 points.

use super::capsule_capsule::capsules_local;
use super::Manifold;
use crate::geometry::{Capsule, Segment};
use crate::math::Transform;

/// Contact between segment `a` (placed by `xf_a`) and capsule `b` (placed by `xf_b`).
pub(super) fn collide_segment_capsule(
    a: &Segment,
    xf_a: Transform,
    b: &Capsule,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    capsules_local(
        a.point1,
        a.point2,
        0.0,
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
    use crate::geometry::{Capsule, Segment, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn capsule_lying_on_segment() {
        let seg = Shape::Segment(Segment::new(Vec2::new(-10.0, 0.0), Vec2::new(10.0, 0.0)).unwrap());
        let c = Shape::Capsule(Capsule::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), 0.2).unwrap());
        let xb = Transform::new(Vec2::new(1.0, 0.199), 0.0);
        let m = collide(&seg, Transform::IDENTITY, &c, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        for p in m.active_points() {
            assert!((p.separation + 0.001).abs() < 1e-5);
            assert!((p.point.y + 0.0005).abs() < 1e-5);
        }
        check_manifold(&m, Transform::IDENTITY, xb);
        // Under the segment: normal flips (two-sided).
        let xb = Transform::new(Vec2::new(1.0, -0.21), 0.0);
        let m = collide(&seg, Transform::IDENTITY, &c, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, -1.0), 1e-6);
        // Standing upright on the segment: one point.
        let xb = Transform::new(Vec2::new(1.0, 0.69), core::f32::consts::FRAC_PI_2);
        let m = collide(&seg, Transform::IDENTITY, &c, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert!((m.points[0].separation + 0.01).abs() < 1e-5);
    }
}
