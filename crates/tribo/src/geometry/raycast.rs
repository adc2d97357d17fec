//! Ray casts against single shapes, in the shape's local frame.
//!
//! The ray is `p(t) = origin + t · translation`, `t ∈ [0, max_fraction]`. A hit reports the
//! first point where the ray enters the solid. Convention (as Box2D): a ray whose origin is
//! strictly inside a solid shape (circle, capsule, polygon) reports no hit; an origin exactly
//! on the surface may report a hit at fraction 0. Invalid input (NaN, infinite, negative
//! `max_fraction`, zero translation) reports no hit.

use super::{Capsule, ChainSegment, Circle, Polygon, Segment, Shape};
use crate::math::Vec2;

/// A ray (or a swept point) in a shape's local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCastInput {
    /// Start point [m].
    pub origin: Vec2,
    /// Displacement at fraction 1 [m]; the ray is `origin + t · translation`.
    pub translation: Vec2,
    /// Largest fraction `t` to report (1 for the full translation) [-].
    pub max_fraction: f32,
}

/// Where a ray first enters a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Hit point on the surface [m], same frame as the input.
    pub point: Vec2,
    /// Unit surface normal at the hit, facing the ray origin's side.
    pub normal: Vec2,
    /// Fraction `t` of the translation at the hit, in `[0, max_fraction]` [-].
    pub fraction: f32,
}

/// Checked ray: origin, unit direction, length of `translation` and the largest distance.
struct Ray {
    origin: Vec2,
    dir: Vec2,
    length: f32,
    max_distance: f32,
}

impl Ray {
    fn new(input: &RayCastInput) -> Option<Ray> {
        if !input.origin.is_finite() || !input.translation.is_finite() || !input.max_fraction.is_finite() {
            return None;
        }
        if input.max_fraction < 0.0 {
            return None;
        }
        let (length, dir) = input.translation.length_and_normalize();
        if !(length > 0.0) || !length.is_finite() {
            return None;
        }
        Some(Ray {
            origin: input.origin,
            dir,
            length,
            max_distance: input.max_fraction * length,
        })
    }

    fn hit(&self, distance: f32, normal: Vec2) -> Option<RayHit> {
        if !(distance >= 0.0 && distance <= self.max_distance) {
            return None;
        }
        Some(RayHit {
            point: self.origin + self.dir * distance,
            normal,
            fraction: distance / self.length,
        })
    }
}

/// Distance along `ray` to where it enters the circle (`center`, `radius`), assuming the
/// origin is outside. Closest-approach form for accuracy: with `s = origin − center`,
/// `t* = −s·d`, `h² = r² − |s + t* d|²`, entry at `t* − h`.
fn circle_entry(ray: &Ray, center: Vec2, radius: f32) -> Option<(f32, Vec2)> {
    let s = ray.origin - center;
    let t_closest = -s.dot(ray.dir);
    let closest = s + ray.dir * t_closest;
    let h2 = radius * radius - closest.length_squared();
    if !(h2 >= 0.0) {
        return None;
    }
    let t = t_closest - h2.sqrt();
    if !(t >= 0.0) {
        return None;
    }
    let normal = (s + ray.dir * t).try_normalize().unwrap_or(-ray.dir);
    Some((t, normal))
}

/// Distance to where `ray` enters the capsule `p1`–`p2` with `radius`, assuming the origin is
/// outside. The capsule is the union of a rectangle and two disks, so the entry is the earliest
/// of: a hit on a side line within the core's extent, or a hit on an end disk.
fn capsule_entry(ray: &Ray, p1: Vec2, p2: Vec2, radius: f32) -> Option<(f32, Vec2)> {
    let mut best: Option<(f32, Vec2)> = None;
    let mut consider = |cand: Option<(f32, Vec2)>| {
        if let Some((t, n)) = cand {
            if best.map_or(true, |(bt, _)| t < bt) {
                best = Some((t, n));
            }
        }
    };
    let (len, axis) = (p2 - p1).length_and_normalize();
    if len > 0.0 {
        let side = axis.left_perp();
        for sign in [1.0f32, -1.0] {
            let m = side * sign;
            let denom = m.dot(ray.dir);
            if denom < 0.0 {
                // Plane m·(x − p1) = radius.
                let t = (radius - m.dot(ray.origin - p1)) / denom;
                if t >= 0.0 {
                    let along = axis.dot(ray.origin + ray.dir * t - p1);
                    if (0.0..=len).contains(&along) {
                        consider(Some((t, m)));
                    }
                }
            }
        }
    }
    consider(circle_entry(ray, p1, radius));
    consider(circle_entry(ray, p2, radius));
    best
}

/// Distance from `p` to the segment `a`–`b` [m].
fn point_segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let e = b - a;
    let ee = e.length_squared();
    let t = if ee > 0.0 {
        ((p - a).dot(e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + e * t)).length()
}

impl Circle {
    /// Casts a ray against the solid circle (local frame). `None` when the origin is inside.
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        let ray = Ray::new(input)?;
        if (ray.origin - self.center).length_squared() < self.radius * self.radius {
            return None;
        }
        let (t, n) = circle_entry(&ray, self.center, self.radius)?;
        ray.hit(t, n)
    }
}

impl Capsule {
    /// Casts a ray against the solid capsule (local frame). `None` when the origin is inside.
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        let ray = Ray::new(input)?;
        if point_segment_distance(ray.origin, self.center1, self.center2) < self.radius {
            return None;
        }
        let (t, n) = capsule_entry(&ray, self.center1, self.center2, self.radius)?;
        ray.hit(t, n)
    }
}

impl Polygon {
    /// Casts a ray against the solid polygon (local frame). `None` when the origin is inside.
    ///
    /// Radius 0: Cyrus–Beck clipping of the ray against the edge half-planes (exact).
    /// Radius > 0: the rounded polygon is the union of the core and a capsule around every
    /// edge, so the entry is the earliest capsule entry (exact as well).
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        let ray = Ray::new(input)?;
        let verts = self.vertices();
        let normals = self.normals();
        let n = verts.len();
        if n == 0 {
            return None;
        }
        if self.radius > 0.0 {
            let mut max_sep = f32::MIN;
            let mut min_dist = f32::MAX;
            for i in 0..n {
                max_sep = max_sep.max(normals[i].dot(ray.origin - verts[i]));
                min_dist = min_dist.min(point_segment_distance(ray.origin, verts[i], verts[(i + 1) % n]));
            }
            if max_sep <= 0.0 || min_dist < self.radius {
                return None;
            }
            let mut best: Option<(f32, Vec2)> = None;
            for i in 0..n {
                if let Some((t, nrm)) = capsule_entry(&ray, verts[i], verts[(i + 1) % n], self.radius) {
                    if best.map_or(true, |(bt, _)| t < bt) {
                        best = Some((t, nrm));
                    }
                }
            }
            let (t, nrm) = best?;
            return ray.hit(t, nrm);
        }

        // Half-plane i: normals[i]·(x − verts[i]) ≤ 0. Along the ray, x = origin + t·dir.
        let mut lower = f32::MIN;
        let mut upper = ray.max_distance;
        let mut index = None;
        for i in 0..n {
            let numerator = normals[i].dot(verts[i] - ray.origin);
            let denominator = normals[i].dot(ray.dir);
            if denominator == 0.0 {
                if numerator < 0.0 {
                    return None;
                }
            } else {
                let t = numerator / denominator;
                if denominator < 0.0 {
                    if t > lower {
                        lower = t;
                        index = Some(i);
                    }
                } else if t < upper {
                    upper = t;
                }
            }
            if upper < lower {
                return None;
            }
        }
        let i = index?;
        if !(lower >= 0.0) {
            // The ray starts inside (every entering plane is behind the origin).
            return None;
        }
        ray.hit(lower, normals[i])
    }
}

impl Segment {
    /// Casts a ray against the two-sided segment (local frame). The normal faces the ray
    /// origin. Rays parallel to the segment report no hit.
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        let ray = Ray::new(input)?;
        let e = self.point2 - self.point1;
        let ee = e.length_squared();
        let normal = e.right_perp().try_normalize()?;
        let denom = normal.dot(ray.dir);
        if denom == 0.0 {
            return None;
        }
        let t = normal.dot(self.point1 - ray.origin) / denom;
        if !(t >= 0.0 && t <= ray.max_distance) {
            return None;
        }
        let q = ray.origin + ray.dir * t;
        let s = (q - self.point1).dot(e) / ee;
        if !(0.0..=1.0).contains(&s) {
            return None;
        }
        let facing = if denom > 0.0 { -normal } else { normal };
        ray.hit(t, facing)
    }
}

impl ChainSegment {
    /// Casts a ray against the piece's colliding side only (local frame), as Box2D does for
    /// chains: a ray arriving from behind passes through. The normal is the piece's normal.
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        let hit = self.segment.ray_cast(input)?;
        // The segment's hit faces the ray origin: from the front it is the piece's normal.
        (hit.normal.dot(self.normal()) > 0.0).then_some(hit)
    }
}

impl Shape {
    /// Casts a ray against the shape; `input` is in the shape's local (body) frame and so is
    /// the hit. `None` when there is no hit within `max_fraction` or the origin is inside a
    /// solid shape.
    pub fn ray_cast(&self, input: &RayCastInput) -> Option<RayHit> {
        match self {
            Shape::Circle(c) => c.ray_cast(input),
            Shape::Capsule(c) => c.ray_cast(input),
            Shape::Polygon(p) => p.ray_cast(input),
            Shape::Segment(s) => s.ray_cast(input),
            Shape::ChainSegment(c) => c.ray_cast(input),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32) -> Vec2 {
        Vec2::new(x, y)
    }

    fn ray(o: Vec2, t: Vec2) -> RayCastInput {
        RayCastInput {
            origin: o,
            translation: t,
            max_fraction: 1.0,
        }
    }

    fn near(a: Vec2, b: Vec2) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn circle() {
        let c = Shape::Circle(Circle::new(v(1.0, 0.0), 0.5).unwrap());
        let h = c.ray_cast(&ray(v(-2.0, 0.0), v(4.0, 0.0))).unwrap();
        assert!(near(h.point, v(0.5, 0.0)) && near(h.normal, v(-1.0, 0.0)));
        assert!((h.fraction - 0.625).abs() < 1e-6);
        // Too short, pointing away, missing, inside.
        assert!(c.ray_cast(&ray(v(-2.0, 0.0), v(2.0, 0.0))).is_none());
        assert!(c.ray_cast(&ray(v(-2.0, 0.0), v(-4.0, 0.0))).is_none());
        assert!(c.ray_cast(&ray(v(-2.0, 0.6), v(4.0, 0.0))).is_none());
        assert!(c.ray_cast(&ray(v(1.0, 0.1), v(4.0, 0.0))).is_none());
        // Bad input.
        assert!(c.ray_cast(&ray(v(f32::NAN, 0.0), v(4.0, 0.0))).is_none());
        assert!(c.ray_cast(&ray(v(-2.0, 0.0), v(0.0, 0.0))).is_none());
    }

    #[test]
    fn capsule() {
        let c = Shape::Capsule(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.5).unwrap());
        // Side.
        let h = c.ray_cast(&ray(v(0.3, 2.0), v(0.0, -4.0))).unwrap();
        assert!(near(h.point, v(0.3, 0.5)) && near(h.normal, v(0.0, 1.0)), "{h:?}");
        // End cap.
        let h = c.ray_cast(&ray(v(3.0, 0.0), v(-4.0, 0.0))).unwrap();
        assert!(near(h.point, v(1.5, 0.0)) && near(h.normal, v(1.0, 0.0)));
        // Rounded corner region, diagonal.
        let d = v(-1.0, -1.0).normalize_or_zero();
        let h = c.ray_cast(&ray(v(1.0, 0.0) - d * 3.0, d * 5.0)).unwrap();
        assert!(near(h.point, v(1.0, 0.0) - d * 0.5), "{h:?}");
        assert!(near(h.normal, -d));
        // Inside; miss.
        assert!(c.ray_cast(&ray(v(0.0, 0.2), v(0.0, 4.0))).is_none());
        assert!(c.ray_cast(&ray(v(-3.0, 0.6), v(6.0, 0.0))).is_none());
    }

    #[test]
    fn polygon() {
        let b = Shape::Polygon(Polygon::new_box(1.0, 0.5).unwrap());
        let h = b.ray_cast(&ray(v(-3.0, 0.2), v(4.0, 0.0))).unwrap();
        assert!(near(h.point, v(-1.0, 0.2)) && near(h.normal, v(-1.0, 0.0)));
        assert!((h.fraction - 0.5).abs() < 1e-6);
        let h = b.ray_cast(&ray(v(0.5, 3.0), v(0.0, -5.0))).unwrap();
        assert!(near(h.point, v(0.5, 0.5)) && near(h.normal, v(0.0, 1.0)));
        // Diagonal through a corner region.
        let h = b.ray_cast(&ray(v(2.0, 1.5), v(-2.0, -2.0))).unwrap();
        assert!(near(h.point, v(1.0, 0.5)), "{h:?}");
        // Miss, short, inside.
        assert!(b.ray_cast(&ray(v(-3.0, 0.6), v(6.0, 0.0))).is_none());
        assert!(b.ray_cast(&ray(v(-3.0, 0.0), v(1.0, 0.0))).is_none());
        assert!(b.ray_cast(&ray(v(0.0, 0.0), v(5.0, 0.0))).is_none());
        // max_fraction > 1 extends the ray.
        let long = RayCastInput {
            origin: v(-3.0, 0.0),
            translation: v(1.0, 0.0),
            max_fraction: 3.0,
        };
        let h = b.ray_cast(&long).unwrap();
        assert!((h.fraction - 2.0).abs() < 1e-6);
    }

    #[test]
    fn rounded_polygon() {
        let b = Shape::Polygon(Polygon::new_rounded_box(1.0, 0.5, 0.25).unwrap());
        let h = b.ray_cast(&ray(v(0.2, 3.0), v(0.0, -5.0))).unwrap();
        assert!(near(h.point, v(0.2, 0.75)) && near(h.normal, v(0.0, 1.0)), "{h:?}");
        // Corner arc: ray along the corner diagonal direction.
        let d = v(-1.0, -1.0).normalize_or_zero();
        let h = b.ray_cast(&ray(v(1.0, 0.5) - d * 3.0, d * 5.0)).unwrap();
        assert!(near(h.point, v(1.0, 0.5) - d * 0.25), "{h:?}");
        assert!(near(h.normal, -d));
        // Inside the rounding: no hit.
        assert!(b.ray_cast(&ray(v(1.1, 0.0), v(5.0, 0.0))).is_none());
        // Passing the rounded corner 0.311 m from the arc centre (would hit a sharp
        // 1.25 × 0.75 box at (1.19, 0.75)).
        assert!(b.ray_cast(&ray(v(0.44, 1.5), v(2.0, -2.0))).is_none());
        let sharp = Shape::Polygon(Polygon::new_box(1.25, 0.75).unwrap());
        assert!(sharp.ray_cast(&ray(v(0.44, 1.5), v(2.0, -2.0))).is_some());
    }

    /// A chain piece from (1, 0) to (−1, 0) faces up: a ray from above hits it with normal
    /// (0, 1); the same ray from below passes.
    #[test]
    fn chain_segment_one_sided() {
        let pieces = ChainSegment::chain(&[v(1.0, 0.0), v(-1.0, 0.0)], false).unwrap();
        let s = Shape::ChainSegment(pieces[0]);
        let h = s.ray_cast(&ray(v(0.5, 1.0), v(0.0, -2.0))).unwrap();
        assert!(near(h.point, v(0.5, 0.0)) && near(h.normal, v(0.0, 1.0)), "{h:?}");
        assert!(s.ray_cast(&ray(v(0.5, -1.0), v(0.0, 2.0))).is_none());
    }

    #[test]
    fn segment_two_sided() {
        let s = Shape::Segment(Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap());
        let h = s.ray_cast(&ray(v(0.5, 1.0), v(0.0, -2.0))).unwrap();
        assert!(near(h.point, v(0.5, 0.0)) && near(h.normal, v(0.0, 1.0)));
        let h = s.ray_cast(&ray(v(0.5, -1.0), v(0.0, 2.0))).unwrap();
        assert!(near(h.normal, v(0.0, -1.0)));
        assert!((h.fraction - 0.5).abs() < 1e-6);
        assert!(s.ray_cast(&ray(v(1.5, 1.0), v(0.0, -2.0))).is_none());
        assert!(s.ray_cast(&ray(v(-2.0, 0.0), v(4.0, 0.0))).is_none());
    }
}
