//! Segment–circle contact: a capsule of radius 0 against the circle (see `capsule_circle`).
//! The segment is two-sided; the normal points from the segment towards the circle centre.

use super::capsule_circle::capsule_circle_local;
use super::Manifold;
use crate::geometry::{Circle, Segment};
use crate::math::Transform;

/// Contact between segment `a` (placed by `xf_a`) and circle `b` (placed by `xf_b`).
pub(super) fn collide_segment_circle(
    a: &Segment,
    xf_a: Transform,
    b: &Circle,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let c = xf_a.inv_mul(xf_b).apply(b.center);
    capsule_circle_local(a.point1, a.point2, 0.0, c, b.radius, spec).to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Circle, Segment, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn both_sides() {
        let seg = Shape::Segment(Segment::new(Vec2::new(-5.0, 0.0), Vec2::new(5.0, 0.0)).unwrap());
        let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
        let id = Transform::IDENTITY;
        let m = collide(
            &seg,
            id,
            &ball,
            Transform::new(Vec2::new(1.0, 0.49), 0.0),
            SPECULATIVE_DISTANCE,
        );
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        assert!((m.points[0].separation + 0.01).abs() < 1e-6);
        assert_near_v(m.points[0].point, Vec2::new(1.0, -0.005), 1e-6);
        let m = collide(
            &seg,
            id,
            &ball,
            Transform::new(Vec2::new(1.0, -0.51), 0.0),
            SPECULATIVE_DISTANCE,
        );
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, -1.0), 1e-6);
        assert!((m.points[0].separation - 0.01).abs() < 1e-6);
        assert_eq!(
            collide(
                &seg,
                id,
                &ball,
                Transform::new(Vec2::new(6.0, 0.0), 0.0),
                SPECULATIVE_DISTANCE
            )
            .count,
            0
        );
    }
}
