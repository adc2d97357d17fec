//! Polygon–segment contact: the segment is a 2-vertex polygon of radius 0 (see
//! `polygon_polygon`); two-sided.

use super::polygon_polygon::{collide_polygons_local, LocalPoly};
use super::Manifold;
use crate::geometry::{Polygon, Segment};
use crate::math::Transform;

/// Contact between polygon `a` (placed by `xf_a`) and segment `b` (placed by `xf_b`).
pub(super) fn collide_polygon_segment(
    a: &Polygon,
    xf_a: Transform,
    b: &Segment,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    let pa = LocalPoly::of_polygon(a);
    let pb = LocalPoly::from_segment(rel.apply(b.point1), rel.apply(b.point2), 0.0);
    collide_polygons_local(&pa, &pb, spec, None).to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Polygon, Segment, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    #[test]
    fn box_on_ground_segment() {
        let ground = Shape::Segment(Segment::new(Vec2::new(-20.0, 0.0), Vec2::new(20.0, 0.0)).unwrap());
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let xb = Transform::new(Vec2::new(3.0, 0.499), 0.0);
        let m = collide(&ground, Transform::IDENTITY, &b, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let mut x: Vec<f32> = m.active_points().iter().map(|p| p.point.x).collect();
        x.sort_by(f32::total_cmp);
        assert!((x[0] - 2.5).abs() < 1e-5 && (x[1] - 3.5).abs() < 1e-5, "{x:?}");
        for p in m.active_points() {
            assert!((p.separation + 0.001).abs() < 1e-5);
        }
        check_manifold(&m, Transform::IDENTITY, xb);
        // Polygon as A: normal points down to the segment.
        let m = collide(&b, xb, &ground, Transform::IDENTITY, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, -1.0), 1e-6);
        // Box beyond the end of a short segment, within speculative range of its end point.
        let short = Shape::Segment(Segment::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0)).unwrap());
        let xb = Transform::new(Vec2::new(1.51, 0.3), 0.0);
        let m = collide(&short, Transform::IDENTITY, &b, xb, SPECULATIVE_DISTANCE);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(1.0, 0.0), 1e-5);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
    }
}
