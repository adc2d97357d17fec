//! Capsule–circle contact (segment–circle uses it with a zero radius).
//!
//! The circle centre `c` (in A's frame) is projected onto the core segment (clamped); with `q`
//! that closest point and `d = |c − q|`: normal `(c − q)/d`, separation `d − r_cap − r_circ`,
//! point midway between the surfaces. A centre exactly on the core uses the segment's
//! clockwise perpendicular. One point, id 0.

use super::{closest_on_segment, LocalManifold, Manifold};
use crate::geometry::{Capsule, Circle};
use crate::math::{Transform, Vec2};

/// Segment `p1`–`p2` grown by `ra` against the circle (`c`, `rb`), in A's frame.
pub(super) fn capsule_circle_local(p1: Vec2, p2: Vec2, ra: f32, c: Vec2, rb: f32, spec: f32) -> LocalManifold {
    let (q, _) = closest_on_segment(c, p1, p2);
    let (dist, normal) = (c - q).length_and_normalize();
    let normal = if dist > 0.0 {
        normal
    } else {
        (p2 - p1).right_perp().try_normalize().unwrap_or(Vec2::Y)
    };
    let mut m = LocalManifold::new(normal);
    let point = (q + normal * ra + c - normal * rb) * 0.5;
    m.push_or_bound(point, dist - ra - rb, 0, spec);
    m
}

/// Contact between capsule `a` (placed by `xf_a`) and circle `b` (placed by `xf_b`).
pub(super) fn collide_capsule_circle(
    a: &Capsule,
    xf_a: Transform,
    b: &Circle,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let c = xf_a.inv_mul(xf_b).apply(b.center);
    capsule_circle_local(a.center1, a.center2, a.radius, c, b.radius, spec).to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Capsule, Circle, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn side_and_end() {
        let cap = Shape::Capsule(Capsule::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0), 0.25).unwrap());
        let circ = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
        let xa = Transform::new(Vec2::new(2.0, 1.0), 0.0);
        // Resting on the side, 1 mm overlap.
        let xb = Transform::new(Vec2::new(2.3, 1.749), 0.0);
        let m = collide(&cap, xa, &circ, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        assert!((m.points[0].separation + 0.001).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(2.3, 1.2495), 1e-5);
        check_manifold(&m, xa, xb);
        // Beyond the rounded end, on a diagonal.
        let d = Vec2::new(1.0, 1.0).normalize_or_zero();
        let xb = Transform::new(Vec2::new(3.0, 1.0) + d * 0.76, 0.0);
        let m = collide(&cap, xa, &circ, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, d, 1e-5);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
        // Far away.
        let xb = Transform::new(Vec2::new(2.0, 2.0), 0.0);
        assert_eq!(collide(&cap, xa, &circ, xb, SPECULATIVE_DISTANCE).count, 0);
    }
}
