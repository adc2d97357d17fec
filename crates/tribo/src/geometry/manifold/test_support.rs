//! Test helpers shared by the pair files, and the all-pairs tests.

use super::{collide, Manifold};
use crate::geometry::{Capsule, Circle, Polygon, Segment, Shape, SPECULATIVE_DISTANCE};
use crate::math::{Transform, Vec2};

/// A reproducible stream of numbers in [0, 1) for randomised fixtures (a linear
/// congruential generator, Numerical Recipes' constants, its top 24 bits).
pub(crate) fn uniform(mut seed: u32) -> impl FnMut() -> f32 {
    move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// Asserts `|a − b| < tol`.
pub(crate) fn assert_near_v(a: Vec2, b: Vec2, tol: f32) {
    assert!((a - b).length() < tol, "{a:?} vs {b:?} (tol {tol})");
}

/// The ids of the active points, in order.
pub(crate) fn ids(m: &Manifold) -> Vec<u16> {
    m.active_points().iter().map(|p| p.id).collect()
}

/// Invariants every manifold must satisfy.
pub(crate) fn check_manifold(m: &Manifold, xf_a: Transform, xf_b: Transform) {
    assert!(m.count <= 2);
    if m.count == 0 {
        return;
    }
    assert!((m.normal.length() - 1.0).abs() < 1e-5, "normal {:?}", m.normal);
    for p in m.active_points() {
        assert_near_v(p.anchor_a, p.point - xf_a.p, 1e-5);
        assert_near_v(p.anchor_b, p.point - xf_b.p, 1e-5);
        assert!(p.separation.is_finite());
    }
    if m.count == 2 {
        assert_ne!(m.points[0].id, m.points[1].id, "duplicate ids in {m:?}");
    }
}

/// One shape of each kind, with off-centre local geometry.
fn zoo() -> Vec<(&'static str, Shape)> {
    vec![
        (
            "circle",
            Shape::Circle(Circle::new(Vec2::new(0.1, -0.05), 0.4).unwrap()),
        ),
        (
            "capsule",
            Shape::Capsule(Capsule::new(Vec2::new(-0.5, 0.1), Vec2::new(0.6, 0.0), 0.2).unwrap()),
        ),
        (
            "polygon",
            Shape::Polygon(
                Polygon::from_points(
                    &[
                        Vec2::new(-0.5, -0.4),
                        Vec2::new(0.6, -0.5),
                        Vec2::new(0.7, 0.3),
                        Vec2::new(0.0, 0.6),
                        Vec2::new(-0.6, 0.2),
                    ],
                    0.0,
                )
                .unwrap(),
            ),
        ),
        (
            "rounded box",
            Shape::Polygon(Polygon::new_rounded_box(0.4, 0.25, 0.1).unwrap()),
        ),
        ("box", Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap())),
        (
            "segment",
            Shape::Segment(Segment::new(Vec2::new(-0.8, 0.0), Vec2::new(0.9, 0.1)).unwrap()),
        ),
    ]
}

/// Smallest separation in a manifold (infinity when empty).
fn min_sep(m: &Manifold) -> f32 {
    m.active_points().iter().fold(f32::INFINITY, |s, p| s.min(p.separation))
}

/// Placements of B around A at which the shapes are near contact: B starts far along a
/// direction and walks in until the manifold's smallest separation drops below `target`.
fn near_contact_placements(a: &Shape, b: &Shape, target: f32) -> Vec<(Transform, Transform)> {
    let mut out = Vec::new();
    let xa = Transform::new(Vec2::new(0.3, -0.2), 0.4);
    for k in 0..7 {
        let dir_angle = 0.3 + k as f32 * 0.9;
        let dir = Vec2::new(dir_angle.cos(), dir_angle.sin());
        let b_angle = -0.7 + 0.37 * k as f32;
        let mut dist = 4.0f32;
        let mut found = None;
        while dist > 0.0 {
            let xb = Transform::new(xa.p + dir * dist, b_angle);
            let m = collide(a, xa, b, xb, 1.0);
            if m.count > 0 && min_sep(&m) < target {
                found = Some(xb);
                break;
            }
            dist -= 0.0005;
        }
        if let Some(xb) = found {
            out.push((xa, xb));
        }
    }
    out
}

/// collide(a, b) and collide(b, a) must describe the same contact.
pub(crate) fn assert_symmetric(a: &Shape, xa: Transform, b: &Shape, xb: Transform, what: &str) {
    let spec = SPECULATIVE_DISTANCE;
    let m1 = collide(a, xa, b, xb, spec);
    let m2 = collide(b, xb, a, xa, spec);
    check_manifold(&m1, xa, xb);
    check_manifold(&m2, xb, xa);
    assert_eq!(m1.count, m2.count, "{what}: {m1:?} vs {m2:?}");
    if m1.count == 0 {
        return;
    }
    assert_near_v(m1.normal, -m2.normal, 1e-4);
    for p in m1.active_points() {
        let q = m2
            .active_points()
            .iter()
            .min_by(|x, y| (x.point - p.point).length().total_cmp(&(y.point - p.point).length()));
        let q = q.unwrap();
        assert!((p.point - q.point).length() < 1e-4, "{what}: points {m1:?} vs {m2:?}");
        assert!(
            (p.separation - q.separation).abs() < 1e-5,
            "{what}: separations {m1:?} vs {m2:?}"
        );
    }
}

#[test]
fn all_pairs_are_symmetric() {
    let shapes = zoo();
    let mut tested = 0;
    for (na, a) in &shapes {
        for (nb, b) in &shapes {
            if matches!((a, b), (Shape::Segment(_), Shape::Segment(_))) {
                let m = collide(a, Transform::IDENTITY, b, Transform::IDENTITY, 1.0);
                assert_eq!(m.count, 0);
                continue;
            }
            for target in [0.015, -0.01, -0.05] {
                let placements = near_contact_placements(a, b, target);
                assert!(
                    placements.len() >= 5,
                    "{na} vs {nb}: only {} placements",
                    placements.len()
                );
                for (xa, xb) in placements {
                    let what = format!("{na} vs {nb} at {xb:?} (target {target})");
                    assert_symmetric(a, xa, b, xb, &what);
                    tested += 1;
                }
            }
        }
    }
    assert!(tested > 300, "{tested}");
}

#[test]
fn speculative_threshold_for_every_pair() {
    // Far apart → empty; a 1 cm gap → points with separation ≈ 0.01 > 0.
    for (na, a) in &zoo() {
        for (nb, b) in &zoo() {
            if matches!((a, b), (Shape::Segment(_), Shape::Segment(_))) {
                continue;
            }
            let xa = Transform::IDENTITY;
            let far = Transform::new(Vec2::new(0.0, 5.0), 0.0);
            assert_eq!(collide(a, xa, b, far, SPECULATIVE_DISTANCE).count, 0, "{na} vs {nb}");
            for (xa, xb) in near_contact_placements(a, b, 0.0105) {
                let m = collide(a, xa, b, xb, SPECULATIVE_DISTANCE);
                assert!(m.count > 0, "{na} vs {nb}");
                for p in m.active_points() {
                    assert!(
                        p.separation > 0.0 && p.separation < SPECULATIVE_DISTANCE,
                        "{na} vs {nb}: {m:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn ids_distinct_and_normals_unit_everywhere() {
    for (_, a) in &zoo() {
        for (_, b) in &zoo() {
            for (xa, xb) in near_contact_placements(a, b, -0.03) {
                check_manifold(&collide(a, xa, b, xb, SPECULATIVE_DISTANCE), xa, xb);
            }
        }
    }
}

#[test]
fn non_finite_transforms_do_not_panic() {
    let bad = [
        Transform::new(Vec2::new(f32::NAN, 0.0), 0.0),
        Transform::new(Vec2::new(0.0, f32::INFINITY), 0.0),
        Transform::new(Vec2::ZERO, f32::NAN),
    ];
    for (_, a) in &zoo() {
        for (_, b) in &zoo() {
            for xb in bad {
                let m = collide(a, Transform::IDENTITY, b, xb, SPECULATIVE_DISTANCE);
                assert!(m.count <= 2);
                let m = collide(a, xb, b, Transform::IDENTITY, f32::NAN);
                assert!(m.count <= 2);
            }
        }
    }
}
