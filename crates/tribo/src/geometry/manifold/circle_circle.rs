//! Circle–circle contact.
//!
//! With centres `c_a`, `c_b` (B in A's frame) at distance `d`: normal `(c_b − c_a)/d`,
//! separation `d − r_a − r_b`, point midway between the surface points `c_a + r_a n` and
//! `c_b − r_b n`. Coincident centres use A's local y axis. One point, id 0.

use super::{LocalManifold, Manifold};
use crate::geometry::Circle;
use crate::math::{Transform, Vec2};

/// Circle A (centre `ca`, radius `ra`) against circle B, in A's frame.
pub(super) fn circles_local(ca: Vec2, ra: f32, cb: Vec2, rb: f32, spec: f32) -> LocalManifold {
    let (dist, normal) = (cb - ca).length_and_normalize();
    let normal = if dist > 0.0 { normal } else { Vec2::Y };
    let separation = dist - ra - rb;
    let mut m = LocalManifold::new(normal);
    let point = (ca + normal * ra + cb - normal * rb) * 0.5;
    m.push_or_bound(point, separation, 0, spec);
    m
}

/// Contact between circles `a` (placed by `xf_a`) and `b` (placed by `xf_b`), and the
/// separation bound of an empty manifold: the exact surface distance (see
/// `collide_bounded`).
pub(super) fn collide_circles(a: &Circle, xf_a: Transform, b: &Circle, xf_b: Transform, spec: f32) -> (Manifold, f32) {
    let cb = xf_a.inv_mul(xf_b).apply(b.center);
    circles_local(a.center, a.radius, cb, b.radius, spec).to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Circle, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn overlapping_touching_and_apart() {
        let a = Shape::Circle(Circle::new(Vec2::new(0.5, 0.0), 1.0).unwrap());
        let b = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
        let xa = Transform::new(Vec2::new(-0.5, 0.0), 0.0);
        let xb = Transform::new(Vec2::new(1.4, 0.0), 0.7);
        let m = collide(&a, xa, &b, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(1.0, 0.0), 1e-6);
        assert!((m.points[0].separation + 0.1).abs() < 1e-6);
        assert_near_v(m.points[0].point, Vec2::new(0.95, 0.0), 1e-6);
        check_manifold(&m, xa, xb);
        // 1 cm gap: speculative; 3 cm: none.
        let m = collide(
            &a,
            xa,
            &b,
            Transform::new(Vec2::new(1.51, 0.0), 0.0),
            SPECULATIVE_DISTANCE,
        );
        assert_eq!(m.count, 1);
        assert!((m.points[0].separation - 0.01).abs() < 1e-6);
        let m = collide(
            &a,
            xa,
            &b,
            Transform::new(Vec2::new(1.53, 0.0), 0.0),
            SPECULATIVE_DISTANCE,
        );
        assert_eq!(m.count, 0);
        // Concentric: a unit normal, no NaN.
        let m = collide(&a, xa, &b, Transform::new(Vec2::ZERO, 0.0), SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert!((m.normal.length() - 1.0).abs() < 1e-6);
        assert!((m.points[0].separation + 1.5).abs() < 1e-6);
    }
}
