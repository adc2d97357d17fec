//! Polygon–circle contact, including the polygon's rounding radius.
//!
//! With the circle centre `c` in the polygon's frame, let `s = max_i n_i·(c − v_i)` (edge `k`).
//! * `s ≤ 0`: the centre is inside the core; the normal is `n_k` and the core distance `s`.
//! * `s > 0`: the closest core point `q` is found over all edges (exact for a convex polygon);
//!   the normal is `(c − q)/|c − q|` and the core distance `|c − q|`. Since `s` is a lower
//!   bound of that distance, `s > spec + radii` exits early.
//!
//! Separation = core distance − `r_poly − r_circle`; the point is midway between
//! `q + r_poly n` and `c − r_circle n`. One point, id 0.

use super::{closest_on_segment, LocalManifold, Manifold};
use crate::geometry::{Circle, Polygon};
use crate::math::Transform;

/// Contact between polygon `a` (placed by `xf_a`) and circle `b` (placed by `xf_b`), and
/// the separation bound of an empty manifold (see `collide_bounded`): `s − radii` when `s`
/// rejected the pair.
pub(super) fn collide_polygon_circle(
    a: &Polygon,
    xf_a: Transform,
    b: &Circle,
    xf_b: Transform,
    spec: f32,
) -> (Manifold, f32) {
    let c = xf_a.inv_mul(xf_b).apply(b.center);
    let verts = a.vertices();
    let normals = a.normals();
    let n = verts.len();
    if n < 2 {
        return (Manifold::EMPTY, 0.0);
    }
    let radius = a.radius() + b.radius;

    let mut best = f32::MIN;
    let mut edge = 0;
    for i in 0..n {
        let s = normals[i].dot(c - verts[i]);
        if s > best {
            best = s;
            edge = i;
        }
    }
    if !(best - radius < spec) {
        let bound = best - radius;
        return (Manifold::EMPTY, if bound > 0.0 { bound } else { 0.0 });
    }

    let (normal, q, core_distance) = if best <= 0.0 {
        (normals[edge], c - normals[edge] * best, best)
    } else {
        let mut q = verts[0];
        let mut d2 = f32::MAX;
        for i in 0..n {
            let (p, _) = closest_on_segment(c, verts[i], verts[(i + 1) % n]);
            let dd = (c - p).length_squared();
            if dd < d2 {
                d2 = dd;
                q = p;
            }
        }
        let (dist, dir) = (c - q).length_and_normalize();
        if dist > 0.0 {
            (dir, q, dist)
        } else {
            (normals[edge], q, best)
        }
    };

    let mut m = LocalManifold::new(normal);
    let point = (q + normal * a.radius() + c - normal * b.radius) * 0.5;
    m.push(point, core_distance - radius, 0, spec);
    m.to_world(xf_a, xf_b)
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Circle, Polygon, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    const SPEC: f32 = SPECULATIVE_DISTANCE;

    #[test]
    fn circle_on_box_face() {
        let b = Shape::Polygon(Polygon::new_box(2.0, 0.5).unwrap());
        let c = Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap());
        let xa = Transform::new(Vec2::new(0.0, -0.5), 0.0);
        let xb = Transform::new(Vec2::new(0.7, 0.249), 0.0);
        let m = collide(&b, xa, &c, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        assert!((m.points[0].separation + 0.001).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(0.7, -0.0005), 1e-5);
        check_manifold(&m, xa, xb);
        // Rotated box: face normal rotates.
        let xa = Transform::new(Vec2::ZERO, 0.3);
        let up = xa.q.rotate(Vec2::new(0.0, 1.0));
        let xb = Transform::new(xa.apply(Vec2::new(0.5, 0.5)) + up * 0.26, 0.0);
        let m = collide(&b, xa, &c, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, up, 1e-5);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
    }

    #[test]
    fn circle_on_box_corner() {
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let c = Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap());
        let d = Vec2::new(0.6, 0.8);
        let xb = Transform::new(Vec2::new(0.5, 0.5) + d * 0.255, 0.0);
        let m = collide(&b, Transform::IDENTITY, &c, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, d, 1e-5);
        assert!((m.points[0].separation - 0.005).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(0.5, 0.5) + d * 0.0025, 1e-5);
        // 0.283 m from the corner (separation 0.033) although each face plane is only
        // 0.2 m away (the face bound alone would accept it).
        let xb = Transform::new(Vec2::new(0.5, 0.5) + Vec2::new(0.2, 0.2), 0.0);
        assert_eq!(collide(&b, Transform::IDENTITY, &c, xb, SPEC).count, 0);
    }

    #[test]
    fn rounded_polygon_and_deep_centre() {
        let b = Shape::Polygon(Polygon::new_rounded_box(0.5, 0.5, 0.1).unwrap());
        let c = Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap());
        let xb = Transform::new(Vec2::new(0.2, 0.84), 0.0);
        let m = collide(&b, Transform::IDENTITY, &c, xb, SPEC);
        assert_eq!(m.count, 1);
        assert!((m.points[0].separation + 0.01).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(0.2, 0.595), 1e-5);
        // Centre inside the core, nearest the right face.
        let xb = Transform::new(Vec2::new(0.4, 0.1), 0.0);
        let m = collide(&b, Transform::IDENTITY, &c, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(1.0, 0.0), 1e-6);
        assert!((m.points[0].separation + 0.45).abs() < 1e-5);
    }
}
