//! Polygon–capsule contact: the capsule is a 2-vertex polygon with the capsule's radius (see
//! `polygon_polygon`), so a capsule lying on a box face gets 2 points and one touching a
//! corner gets the exact rounded contact.

use super::polygon_polygon::{collide_polygons_local, LocalPoly};
use super::Manifold;
use crate::geometry::{Capsule, Polygon};
use crate::math::Transform;

/// Contact between polygon `a` (placed by `xf_a`) and capsule `b` (placed by `xf_b`).
pub(super) fn collide_polygon_capsule(
    a: &Polygon,
    xf_a: Transform,
    b: &Capsule,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    let pa = LocalPoly::of_polygon(a);
    let pb = LocalPoly::from_segment(rel.apply(b.center1), rel.apply(b.center2), b.radius);
    collide_polygons_local(&pa, &pb, spec, None).to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Capsule, Polygon, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn capsule_flat_on_box() {
        let b = Shape::Polygon(Polygon::new_box(2.0, 0.5).unwrap());
        let c = Shape::Capsule(Capsule::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), 0.25).unwrap());
        let xb = Transform::new(Vec2::new(0.4, 0.749), 0.0);
        let m = collide(&b, Transform::IDENTITY, &c, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let mut x: Vec<f32> = m.active_points().iter().map(|p| p.point.x).collect();
        x.sort_by(f32::total_cmp);
        assert!((x[0] + 0.1).abs() < 1e-5 && (x[1] - 0.9).abs() < 1e-5, "{x:?}");
        for p in m.active_points() {
            assert!((p.separation + 0.001).abs() < 1e-5);
            assert!((p.point.y - 0.4995).abs() < 1e-5);
        }
        assert_ne!(m.points[0].id, m.points[1].id);
        check_manifold(&m, Transform::IDENTITY, xb);
        // Sliding 1 mm keeps the ids.
        let m2 = collide(
            &b,
            Transform::IDENTITY,
            &c,
            Transform::new(Vec2::new(0.401, 0.749), 0.0),
            SPECULATIVE_DISTANCE,
        );
        assert_eq!(ids(&m), ids(&m2));
    }

    #[test]
    fn capsule_end_near_box_corner() {
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let c = Shape::Capsule(Capsule::new(Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), 0.1).unwrap());
        // Capsule lies along the diagonal away from the corner (0.5, 0.5), its end 0.11 away.
        let d = Vec2::new(1.0, 1.0).normalize_or_zero();
        let xb = Transform::new(Vec2::new(0.5, 0.5) + d * 0.11, core::f32::consts::FRAC_PI_4);
        let m = collide(&b, Transform::IDENTITY, &c, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, d, 1e-4);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
    }
}
