//! Mass properties: mass, centroid and rotational inertia about the centroid.
//!
//! Densities are areal [kg/m²]. All formulas below are exact for the solid shapes:
//!
//! * circle: `m = ρπr²`, `I = m r²/2` (solid disk);
//! * capsule: a `L × 2r` rectangle plus two half-disks (see [`Capsule::mass`]);
//! * polygon with rounding radius `r`: the core polygon, plus a `L_i × r` rectangle on the
//!   outside of every edge, plus a circular sector of radius `r` at every vertex whose angle is
//!   the turn between the two adjacent edge normals (the sectors add up to a full disk, so the
//!   area is `A + P r + π r²`). Each piece's area, centroid and polar second moment are summed
//!   about a common point and moved to the overall centroid with the parallel-axis theorem
//!   (`J_o = J_c + a |c − o|²`). This is exact, not the vertex push-out approximation;
//! * segment: zero mass.
//!
//! Polygon core: fan of triangles `(o, v_i, v_i+1)` from the vertex average `o` (inside the
//! convex polygon). For a triangle with edges `e1`, `e2` from `o`: area `a = (e1 × e2)/2`,
//! centroid `o + (e1 + e2)/3`, polar second moment of area about `o`
//! `J_o = (e1 × e2)/12 · (e1·e1 + e1·e2 + e2·e2)`.

use super::{Capsule, Circle, Polygon, Segment, Shape};
use crate::math::Vec2;
use core::f32::consts::PI;

/// Mass properties of a shape.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MassData {
    /// Mass [kg].
    pub mass: f32,
    /// Centre of mass in the body frame [m].
    pub center: Vec2,
    /// Rotational inertia about `center` [kg·m²].
    pub rotational_inertia: f32,
}

/// Area, centroid and polar second moment of area of a plane region.
#[derive(Clone, Copy, Debug)]
pub(super) struct AreaProperties {
    /// Area [m²].
    pub area: f32,
    /// Centroid [m].
    pub centroid: Vec2,
    /// Polar second moment of area about the centroid [m⁴].
    pub inertia: f32,
}

/// Running sums of area pieces about a fixed origin `o`.
struct Accumulator {
    o: Vec2,
    area: f32,
    /// Σ a·(c − o) [m³].
    moment: Vec2,
    /// Σ J about `o` [m⁴].
    j_o: f32,
}

impl Accumulator {
    fn new(o: Vec2) -> Accumulator {
        Accumulator {
            o,
            area: 0.0,
            moment: Vec2::ZERO,
            j_o: 0.0,
        }
    }

    /// Adds a piece of area `a`, centroid `c` and polar moment `j_c` about its own centroid.
    fn add(&mut self, a: f32, c: Vec2, j_c: f32) {
        let r = c - self.o;
        self.area += a;
        self.moment += a * r;
        self.j_o += j_c + a * r.length_squared();
    }

    fn finish(&self) -> AreaProperties {
        if !(self.area > 0.0) {
            return AreaProperties {
                area: 0.0,
                centroid: self.o,
                inertia: 0.0,
            };
        }
        let rel = self.moment * (1.0 / self.area);
        AreaProperties {
            area: self.area,
            centroid: self.o + rel,
            inertia: (self.j_o - self.area * rel.length_squared()).max(0.0),
        }
    }
}

/// Exact area properties of a convex counter-clockwise polygon grown by `radius` [m].
/// `normals[i]` is the outward unit normal of edge `i → i+1`.
pub(super) fn polygon_area_properties(vertices: &[Vec2], normals: &[Vec2], radius: f32) -> AreaProperties {
    let n = vertices.len().min(normals.len());
    if n == 0 {
        return AreaProperties {
            area: 0.0,
            centroid: Vec2::ZERO,
            inertia: 0.0,
        };
    }
    let mut o = Vec2::ZERO;
    for &v in &vertices[..n] {
        o += v;
    }
    o *= 1.0 / n as f32;
    let mut acc = Accumulator::new(o);

    // Core polygon: triangle fan from o.
    for i in 0..n {
        let e1 = vertices[i] - o;
        let e2 = vertices[(i + 1) % n] - o;
        let d = e1.cross(e2);
        let a = 0.5 * d;
        let c_rel = (e1 + e2) * (1.0 / 3.0);
        let j_about_o = d / 12.0 * (e1.dot(e1) + e1.dot(e2) + e2.dot(e2));
        // Store as a piece with its own-centroid moment: J_c = J_o − a |c − o|².
        acc.add(a, o + c_rel, j_about_o - a * c_rel.length_squared());
    }

    if radius > 0.0 && n >= 2 {
        let r = radius;
        for i in 0..n {
            let v1 = vertices[i];
            let v2 = vertices[(i + 1) % n];
            let len = (v2 - v1).length();
            // Edge rectangle len × r on the outside of edge i: J_c = a (len² + r²)/12.
            let a = len * r;
            let c = (v1 + v2) * 0.5 + normals[i] * (0.5 * r);
            acc.add(a, c, a * (len * len + r * r) / 12.0);

            // Corner sector at vertex i between normals i-1 and i, angle θ ∈ (0, π].
            let n_prev = normals[(i + n - 1) % n];
            let n_next = normals[i];
            let theta = n_prev.cross(n_next).atan2(n_prev.dot(n_next));
            if theta > 0.0 {
                let a = 0.5 * theta * r * r;
                // Sector centroid: 4 r sin(θ/2) / (3θ) from the apex along the bisector.
                let d = 4.0 * r * (0.5 * theta).sin() / (3.0 * theta);
                let bisector = (n_prev + n_next).try_normalize().unwrap_or_else(|| n_prev.right_perp());
                let c = vertices[i] + bisector * d;
                // Polar moment about the apex: ∫ρ² dA = θ r⁴ / 4.
                let j_apex = 0.25 * theta * r * r * r * r;
                acc.add(a, c, j_apex - a * d * d);
            }
        }
    }
    acc.finish()
}

impl Circle {
    /// Mass properties for areal `density` [kg/m²]: `m = ρπr²`, `I = m r²/2`.
    pub fn mass(&self, density: f32) -> MassData {
        let m = density * PI * self.radius * self.radius;
        MassData {
            mass: m,
            center: self.center,
            rotational_inertia: 0.5 * m * self.radius * self.radius,
        }
    }
}

impl Capsule {
    /// Mass properties for areal `density` [kg/m²].
    ///
    /// A capsule of core length `L` and radius `r` is a `L × 2r` rectangle
    /// (`I = m_rect (L² + 4r²)/12`) plus two half-disks of total mass `m_c = ρπr²`. A half-disk
    /// has inertia `(m_c/2) r²/2` about its flat side's centre and its centroid lies
    /// `d = 4r/(3π)` from that centre; by the parallel-axis theorem each contributes
    /// `(m_c/2)(r²/2 − d² + (L/2 + d)²)` about the capsule centre, so both together give
    /// `m_c (r²/2 + L²/4 + L d)`.
    pub fn mass(&self, density: f32) -> MassData {
        let r = self.radius;
        let len = (self.center2 - self.center1).length();
        let m_rect = density * 2.0 * r * len;
        let m_circ = density * PI * r * r;
        let d = 4.0 * r / (3.0 * PI);
        let i_rect = m_rect * (len * len + 4.0 * r * r) / 12.0;
        let i_circ = m_circ * (0.5 * r * r + 0.25 * len * len + len * d);
        MassData {
            mass: m_rect + m_circ,
            center: self.center1.lerp(self.center2, 0.5),
            rotational_inertia: i_rect + i_circ,
        }
    }
}

impl Polygon {
    /// Mass properties for areal `density` [kg/m²], exact including the rounding radius
    /// (see the module documentation). `center` equals [`Polygon::centroid`].
    pub fn mass(&self, density: f32) -> MassData {
        let p = polygon_area_properties(self.vertices(), self.normals(), self.radius);
        MassData {
            mass: density * p.area,
            center: p.centroid,
            rotational_inertia: density * p.inertia,
        }
    }
}

impl Segment {
    /// A segment has no area: zero mass and inertia, `center` at the midpoint [m].
    pub fn mass(&self, _density: f32) -> MassData {
        MassData {
            mass: 0.0,
            center: self.point1.lerp(self.point2, 0.5),
            rotational_inertia: 0.0,
        }
    }
}

impl Shape {
    /// Mass properties for areal `density` [kg/m²]; inertia is about the returned centre.
    pub fn mass(&self, density: f32) -> MassData {
        match self {
            Shape::Circle(c) => c.mass(density),
            Shape::Capsule(c) => c.mass(density),
            Shape::Polygon(p) => p.mass(density),
            Shape::Segment(s) | Shape::ChainSegment(super::ChainSegment { segment: s, .. }) => s.mass(density),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;

    fn v(x: f32, y: f32) -> Vec2 {
        Vec2::new(x, y)
    }

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-6)
    }

    /// Midpoint-rule integration of a membership test over `[lo, hi]` with `n × n` cells, in
    /// f64: (area, centroid, polar moment about centroid).
    fn integrate(
        inside: impl Fn(f64, f64) -> bool,
        lo: (f64, f64),
        hi: (f64, f64),
        n: usize,
    ) -> (f64, (f64, f64), f64) {
        let dx = (hi.0 - lo.0) / n as f64;
        let dy = (hi.1 - lo.1) / n as f64;
        let (mut a, mut sx, mut sy, mut sxx) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            let x = lo.0 + (i as f64 + 0.5) * dx;
            for j in 0..n {
                let y = lo.1 + (j as f64 + 0.5) * dy;
                if inside(x, y) {
                    a += 1.0;
                    sx += x;
                    sy += y;
                    sxx += x * x + y * y;
                }
            }
        }
        let cell = dx * dy;
        let (cx, cy) = (sx / a, sy / a);
        let j = sxx * cell - a * cell * (cx * cx + cy * cy);
        (a * cell, (cx, cy), j)
    }

    fn seg_dist(px: f64, py: f64, a: (f64, f64), b: (f64, f64)) -> f64 {
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let t = (((px - a.0) * ex + (py - a.1) * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
        let (qx, qy) = (a.0 + t * ex - px, a.1 + t * ey - py);
        (qx * qx + qy * qy).sqrt()
    }

    #[test]
    fn box_mass() {
        let (hx, hy, rho) = (0.75f32, 0.5f32, 3.0f32);
        let md = Polygon::new_box(hx, hy).unwrap().mass(rho);
        let m = 4.0 * hx * hy * rho;
        assert!(close(md.mass, m, 1e-6));
        let (w, h) = (2.0 * hx, 2.0 * hy);
        assert!(close(md.rotational_inertia, m * (w * w + h * h) / 12.0, 1e-5));
        assert!(md.center.length() < 1e-6);
    }

    #[test]
    fn offset_box_centroid() {
        let p = Polygon::new_offset_box(0.5, 0.25, v(2.0, -1.0), 0.3).unwrap();
        let md = p.mass(2.0);
        assert!((md.center - v(2.0, -1.0)).length() < 1e-5, "{md:?}");
        assert!(close(md.mass, 1.0, 1e-5));
        assert!(close(md.rotational_inertia, (1.0 + 0.25) / 12.0, 1e-4));
        // A non-symmetric polygon: triangle centroid is the vertex average.
        let t = Polygon::from_points(&[v(1.0, 1.0), v(4.0, 1.0), v(1.0, 4.0)], 0.0).unwrap();
        let md = t.mass(1.0);
        assert!((md.center - v(2.0, 2.0)).length() < 1e-5);
        assert!(close(md.mass, 4.5, 1e-6));
        // Right triangle with legs a: J_centroid = a⁴/18 (I_x + I_y = 2 · a⁴/36).
        assert!(close(md.rotational_inertia, 81.0 / 18.0, 1e-4), "{md:?}");
    }

    #[test]
    fn circle_mass() {
        let c = Circle::new(v(1.0, 2.0), 0.5).unwrap();
        let md = c.mass(2.0);
        assert!(close(md.mass, 2.0 * PI * 0.25, 1e-6));
        assert!(close(md.rotational_inertia, 0.5 * md.mass * 0.25, 1e-6));
        assert_eq!(md.center, v(1.0, 2.0));
    }

    #[test]
    fn capsule_matches_numeric_integration() {
        let (a, b, r) = ((-0.6, 0.2), (0.9, -0.3), 0.35);
        let cap = Capsule::new(v(a.0 as f32, a.1 as f32), v(b.0 as f32, b.1 as f32), r as f32).unwrap();
        let md = cap.mass(1.0);
        let (area, c, j) = integrate(|x, y| seg_dist(x, y, a, b) <= r, (-1.0, -0.7), (1.3, 0.7), 3000);
        assert!(close(md.mass, area as f32, 1e-3), "{} vs {area}", md.mass);
        assert!((md.center - v(c.0 as f32, c.1 as f32)).length() < 1e-3);
        assert!(
            close(md.rotational_inertia, j as f32, 1e-3),
            "{} vs {j}",
            md.rotational_inertia
        );
    }

    #[test]
    fn rounded_polygon_matches_numeric_integration() {
        let pts = [v(0.0, 0.0), v(1.2, -0.1), v(1.0, 0.8), v(0.1, 0.6)];
        let r = 0.2;
        let p = Polygon::from_points(&pts, r).unwrap();
        let md = p.mass(1.0);
        let verts: Vec<(f64, f64)> = p.vertices().iter().map(|w| (w.x as f64, w.y as f64)).collect();
        let inside = |x: f64, y: f64| {
            let n = verts.len();
            let in_core = (0..n).all(|i| {
                let (a, b) = (verts[i], verts[(i + 1) % n]);
                (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0) >= 0.0
            });
            in_core || (0..n).any(|i| seg_dist(x, y, verts[i], verts[(i + 1) % n]) <= r as f64)
        };
        let (area, c, j) = integrate(inside, (-0.3, -0.4), (1.5, 1.1), 3000);
        assert!(close(md.mass, area as f32, 1e-3), "{} vs {area}", md.mass);
        assert!((md.center - v(c.0 as f32, c.1 as f32)).length() < 1e-3);
        assert!((p.centroid() - md.center).length() < 1e-6);
        assert!(
            close(md.rotational_inertia, j as f32, 1e-3),
            "{} vs {j}",
            md.rotational_inertia
        );
    }

    #[test]
    fn rounded_box_area() {
        let (hx, hy, r) = (0.5f32, 0.25f32, 0.1f32);
        let md = Polygon::new_rounded_box(hx, hy, r).unwrap().mass(1.0);
        let area = 4.0 * hx * hy + 2.0 * (2.0 * hx + 2.0 * hy) * r + PI * r * r;
        assert!(close(md.mass, area, 1e-5));
        assert!(md.center.length() < 1e-6);
    }

    #[test]
    fn segment_has_no_mass() {
        let s = Shape::Segment(Segment::new(v(0.0, 0.0), v(2.0, 0.0)).unwrap());
        let md = s.mass(5.0);
        assert_eq!(md.mass, 0.0);
        assert_eq!(md.rotational_inertia, 0.0);
        assert_eq!(md.center, v(1.0, 0.0));
    }
}
