//! Shape types. All coordinates are in the body's local frame [m].

use super::{GeometryError, LINEAR_SLOP};
use crate::math::wide::{apply_lanes, bounds_of_points, split_xy, F4};
use crate::math::{Aabb, Transform, Vec2};

/// Most vertices a polygon may have (Box2D v3 uses 8).
pub const MAX_POLYGON_VERTICES: usize = 8;

/// A solid circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre in the body frame [m].
    pub center: Vec2,
    /// Radius [m], > 0.
    pub radius: f32,
}

/// A capsule: the set of points within `radius` of the segment `center1`–`center2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// First end of the core segment [m].
    pub center1: Vec2,
    /// Second end of the core segment [m].
    pub center2: Vec2,
    /// Radius [m], > 0.
    pub radius: f32,
}

/// A two-sided line segment with no thickness, meant for static ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// First end [m].
    pub point1: Vec2,
    /// Second end [m].
    pub point2: Vec2,
}

/// One piece of a chain: a segment that collides on its right side only (the side of
/// `right_perp(point2 − point1)`), smoothed against its neighbours by two ghost vertices.
///
/// As in Box2D v3 (`b2ChainSegment`): a counter-clockwise loop faces outwards, a clockwise
/// loop inwards. The ghost vertices are the far ends of the neighbouring pieces
/// (`ghost1 → point1` before, `point2 → ghost2` after); contacts use them to drop the normals
/// that would catch on an internal vertex (E. Catto, "Ghost collisions", box2d.org 2020: a
/// normal is kept only inside the cone the two pieces' normals span at a convex vertex, and
/// snapped to the segment's own normal at a concave one). Build them with
/// [`ChainSegment::chain`]; zero mass, for static and kinematic bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainSegment {
    /// End of the previous piece [m, body frame].
    pub ghost1: Vec2,
    /// The piece itself [m, body frame].
    pub segment: Segment,
    /// End of the next piece [m, body frame].
    pub ghost2: Vec2,
}

/// A convex polygon with up to [`MAX_POLYGON_VERTICES`] counter-clockwise vertices and an
/// optional rounding radius (the solid is the polygon grown by `radius`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polygon {
    pub(crate) vertices: [Vec2; MAX_POLYGON_VERTICES],
    pub(crate) normals: [Vec2; MAX_POLYGON_VERTICES],
    pub(crate) count: usize,
    pub(crate) radius: f32,
    pub(crate) centroid: Vec2,
}

/// Any collision shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A circle.
    Circle(Circle),
    /// A capsule.
    Capsule(Capsule),
    /// A convex polygon (boxes included).
    Polygon(Polygon),
    /// A segment (zero thickness, zero mass).
    Segment(Segment),
    /// A one-sided piece of a chain (zero thickness, zero mass).
    ChainSegment(ChainSegment),
}

/// Fails with `NonFinite(what)` unless both coordinates are finite.
fn check_point(what: &'static str, p: Vec2) -> Result<(), GeometryError> {
    if p.is_finite() {
        Ok(())
    } else {
        Err(GeometryError::NonFinite(what))
    }
}

/// Fails unless `value` is finite and strictly positive.
fn check_positive(what: &'static str, value: f32) -> Result<(), GeometryError> {
    if !value.is_finite() {
        Err(GeometryError::NonFinite(what))
    } else if value <= 0.0 {
        Err(GeometryError::NonPositive(what, value))
    } else {
        Ok(())
    }
}

/// Fails unless `value` is finite and not negative.
fn check_non_negative(what: &'static str, value: f32) -> Result<(), GeometryError> {
    if !value.is_finite() {
        Err(GeometryError::NonFinite(what))
    } else if value < 0.0 {
        Err(GeometryError::Negative(what, value))
    } else {
        Ok(())
    }
}

impl Circle {
    /// A circle centred at `center` [m, body frame] with `radius` [m].
    ///
    /// Errors: `NonFinite("center" | "radius")`, `NonPositive("radius", r)`.
    pub fn new(center: Vec2, radius: f32) -> Result<Circle, GeometryError> {
        check_point("center", center)?;
        check_positive("radius", radius)?;
        Ok(Circle { center, radius })
    }
}

impl Capsule {
    /// A capsule around the segment `center1`–`center2` [m, body frame] with `radius` [m].
    ///
    /// Errors: `NonFinite("center1" | "center2" | "radius")`, `NonPositive("radius", r)`,
    /// `DegenerateSegment` when the centres are closer than [`LINEAR_SLOP`] (use a circle).
    pub fn new(center1: Vec2, center2: Vec2, radius: f32) -> Result<Capsule, GeometryError> {
        check_point("center1", center1)?;
        check_point("center2", center2)?;
        check_positive("radius", radius)?;
        if !((center2 - center1).length() >= LINEAR_SLOP) {
            return Err(GeometryError::DegenerateSegment("capsule centers"));
        }
        Ok(Capsule {
            center1,
            center2,
            radius,
        })
    }

    /// Length of the core segment [m].
    pub fn length(&self) -> f32 {
        (self.center2 - self.center1).length()
    }
}

impl Segment {
    /// A segment from `point1` to `point2` [m, body frame].
    ///
    /// Errors: `NonFinite("point1" | "point2")`, `DegenerateSegment` when the points are
    /// closer than [`LINEAR_SLOP`].
    pub fn new(point1: Vec2, point2: Vec2) -> Result<Segment, GeometryError> {
        check_point("point1", point1)?;
        check_point("point2", point2)?;
        if !((point2 - point1).length() >= LINEAR_SLOP) {
            return Err(GeometryError::DegenerateSegment("segment points"));
        }
        Ok(Segment { point1, point2 })
    }

    /// Length [m].
    pub fn length(&self) -> f32 {
        (self.point2 - self.point1).length()
    }
}

impl ChainSegment {
    /// How many pieces [`ChainSegment::chain`] makes of `points` points: `points` for a loop,
    /// `points − 1` for an open chain (0 for none).
    pub fn piece_count(points: usize, closed: bool) -> usize {
        if closed {
            points
        } else {
            points.saturating_sub(1)
        }
    }

    /// The index of the first point that ends a piece shorter than [`LINEAR_SLOP`] (the
    /// closing piece of a loop ends at point 0), or `None`.
    pub fn short_piece(points: &[Vec2], closed: bool) -> Option<usize> {
        let n = points.len();
        (0..ChainSegment::piece_count(n, closed))
            .map(|k| (k + 1) % n)
            .find(|&end| !((points[end] - points[(end + n - 1) % n]).length() >= LINEAR_SLOP))
    }

    /// Unit normal of the colliding side, `right_perp(point2 − point1) / length` [body frame].
    pub fn normal(&self) -> Vec2 {
        (self.segment.point2 - self.segment.point1)
            .right_perp()
            .normalize_or_zero()
    }

    /// The pieces of a chain through `points` [m, body frame]: a closed loop (`closed`,
    /// segment `i` from point `i` to point `i+1 mod n`, n pieces, each smoothed against both
    /// neighbours) or an open chain (n − 1 pieces; the two free ends are convex corners of
    /// 90°, so a shape reaching round an end touches its vertex). Each piece collides on its
    /// right side: wind a loop clockwise to keep shapes inside it (Box2D's convention).
    ///
    /// Unlike Box2D v3, an open chain's first and last points are pieces' ends, not ghost
    /// vertices (Box2D makes n − 3 pieces of n points).
    ///
    /// Errors: `NonFinite("points")`, `TooFewPoints` (a loop needs 3 points, an open chain
    /// 2), `DegenerateSegment("chain points")` when two consecutive points (the last and the
    /// first of a loop included) are closer than [`LINEAR_SLOP`].
    pub fn chain(points: &[Vec2], closed: bool) -> Result<Vec<ChainSegment>, GeometryError> {
        if points.iter().any(|p| !p.is_finite()) {
            return Err(GeometryError::NonFinite("points"));
        }
        let needed = if closed { 3 } else { 2 };
        if points.len() < needed {
            return Err(GeometryError::TooFewPoints {
                needed,
                got: points.len(),
            });
        }
        if ChainSegment::short_piece(points, closed).is_some() {
            return Err(GeometryError::DegenerateSegment("chain points"));
        }
        let n = points.len();
        let pieces = ChainSegment::piece_count(n, closed);
        let at = |i: usize| points[i % n];
        let mut out = Vec::with_capacity(pieces);
        for i in 0..pieces {
            let (p1, p2) = (at(i), at(i + 1));
            // A free end is a right-angled convex corner: its ghost lies behind the piece.
            let behind = -(p2 - p1).right_perp();
            let ghost1 = if closed {
                at(i + n - 1)
            } else if i > 0 {
                at(i - 1)
            } else {
                p1 + behind
            };
            let ghost2 = if closed || i + 2 < n { at(i + 2) } else { p2 + behind };
            out.push(ChainSegment {
                ghost1,
                segment: Segment { point1: p1, point2: p2 },
                ghost2,
            });
        }
        Ok(out)
    }
}

impl Polygon {
    /// The convex hull of `points` [m, body frame], rounded by `radius` [m] (0 for sharp
    /// corners).
    ///
    /// Points closer than [`LINEAR_SLOP`] are merged and collinear hull points dropped (see
    /// [`super::convex_hull`]). Vertices come out counter-clockwise starting at the lowest-x
    /// (then lowest-y) point; normal `i` is the outward unit normal of edge `i → i+1`.
    ///
    /// Errors: `NonFinite("points" | "radius")`, `Negative("radius", r)`,
    /// `DegeneratePolygon` (fewer than 3 distinct points, or all collinear),
    /// `TooManyVertices(n)` when the hull has more than [`MAX_POLYGON_VERTICES`] vertices.
    pub fn from_points(points: &[Vec2], radius: f32) -> Result<Polygon, GeometryError> {
        check_non_negative("radius", radius)?;
        let hull = super::convex_hull(points)?;
        if hull.len() > MAX_POLYGON_VERTICES {
            return Err(GeometryError::TooManyVertices(hull.len()));
        }
        Ok(Polygon::from_ccw(&hull, radius))
    }

    /// An axis-aligned box centred on the body origin with half extents `hx`, `hy` [m].
    ///
    /// Vertices: (-hx,-hy), (hx,-hy), (hx,hy), (-hx,hy); normals (0,-1), (1,0), (0,1), (-1,0).
    ///
    /// Errors: `NonFinite("hx" | "hy")`, `NonPositive("hx" | "hy", v)`.
    pub fn new_box(hx: f32, hy: f32) -> Result<Polygon, GeometryError> {
        Polygon::new_rounded_box(hx, hy, 0.0)
    }

    /// A box with half extents `hx`, `hy` [m] whose core is rounded by `radius` [m]: the solid
    /// is `(2hx + 2radius) × (2hy + 2radius)` with circular corners. Same vertex order as
    /// [`Polygon::new_box`].
    ///
    /// Errors: as [`Polygon::new_box`], plus `NonFinite("radius")`, `Negative("radius", r)`.
    pub fn new_rounded_box(hx: f32, hy: f32, radius: f32) -> Result<Polygon, GeometryError> {
        check_positive("hx", hx)?;
        check_positive("hy", hy)?;
        check_non_negative("radius", radius)?;
        Ok(Polygon::from_ccw(
            &[
                Vec2::new(-hx, -hy),
                Vec2::new(hx, -hy),
                Vec2::new(hx, hy),
                Vec2::new(-hx, hy),
            ],
            radius,
        ))
    }

    /// A box with half extents `hx`, `hy` [m], centred at `center` [m, body frame] and
    /// rotated by `angle` [rad, counter-clockwise]. Vertex `i` is the rotated and shifted
    /// vertex `i` of [`Polygon::new_box`].
    ///
    /// Errors: as [`Polygon::new_box`], plus `NonFinite("center" | "angle")`.
    pub fn new_offset_box(hx: f32, hy: f32, center: Vec2, angle: f32) -> Result<Polygon, GeometryError> {
        check_point("center", center)?;
        if !angle.is_finite() {
            return Err(GeometryError::NonFinite("angle"));
        }
        let b = Polygon::new_box(hx, hy)?;
        let xf = Transform::new(center, angle);
        let mut out = b;
        for i in 0..b.count {
            out.vertices[i] = xf.apply(b.vertices[i]);
            out.normals[i] = xf.q.rotate(b.normals[i]);
        }
        out.centroid = center;
        Ok(out)
    }

    /// Builds a polygon from counter-clockwise, convex, 2..=8 vertices (already validated).
    fn from_ccw(ccw: &[Vec2], radius: f32) -> Polygon {
        let count = ccw.len().min(MAX_POLYGON_VERTICES);
        let mut vertices = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        let mut normals = [Vec2::ZERO; MAX_POLYGON_VERTICES];
        vertices[..count].copy_from_slice(&ccw[..count]);
        for i in 0..count {
            let edge = vertices[(i + 1) % count] - vertices[i];
            // Outward normal of a counter-clockwise edge is its clockwise perpendicular.
            normals[i] = edge.right_perp().normalize_or_zero();
        }
        let props = super::mass::polygon_area_properties(&vertices[..count], &normals[..count], radius);
        Polygon {
            vertices,
            normals,
            count,
            radius,
            centroid: props.centroid,
        }
    }

    /// The counter-clockwise core vertices [m, body frame].
    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices[..self.count.min(MAX_POLYGON_VERTICES)]
    }

    /// Outward unit edge normals; normal `i` belongs to edge `vertices[i] → vertices[i+1]`.
    pub fn normals(&self) -> &[Vec2] {
        &self.normals[..self.count.min(MAX_POLYGON_VERTICES)]
    }

    /// Rounding radius [m] (0 for a sharp polygon).
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Centroid of the solid (rounded) polygon [m, body frame]; equals the core polygon's
    /// centroid for radius 0 and for symmetric shapes such as boxes.
    pub fn centroid(&self) -> Vec2 {
        self.centroid
    }

    /// Number of vertices (3..=8 for constructed polygons).
    pub fn count(&self) -> usize {
        self.count.min(MAX_POLYGON_VERTICES)
    }
}

impl Shape {
    /// Tight world-space bounding box of the shape placed by `xf` [m], rounding radius
    /// included. A segment gets a zero-thickness box when axis-aligned.
    pub fn aabb(&self, xf: Transform) -> Aabb {
        match self {
            Shape::Circle(c) => {
                let p = xf.apply(c.center);
                Aabb::new(p, p).expand(c.radius)
            }
            Shape::Capsule(c) => {
                let a = xf.apply(c.center1);
                let b = xf.apply(c.center2);
                Aabb::new(a.min(b), a.max(b)).expand(c.radius)
            }
            Shape::Segment(s) | Shape::ChainSegment(ChainSegment { segment: s, .. }) => {
                let a = xf.apply(s.point1);
                let b = xf.apply(s.point2);
                Aabb::new(a.min(b), a.max(b))
            }
            Shape::Polygon(p) if p.count() > 0 => {
                // The vertices as lanes, four a group (slots past the count padded with
                // vertex 0), transformed and folded in the scalar fold's order with its
                // ties (`bounds_of_points`: the same bits as the fold below), for every
                // moving polygon every step: a box took 125 instructions a call as scalar
                // code (large_pyramid), an eight-sided one about 300 (junkyard).
                let (n, v) = (p.count(), &p.vertices);
                let at = |i: usize| if i < n { v[i] } else { v[0] };
                let (rot, t) = (
                    (F4::splat(xf.q.c), F4::splat(xf.q.s)),
                    (F4::splat(xf.p.x), F4::splat(xf.p.y)),
                );
                // Vertices k … k + 3, padded, moved by `xf`.
                let group = |k: usize| apply_lanes(rot, t, split_xy([at(k), at(k + 1), at(k + 2), at(k + 3)]));
                let (lo, hi) = if n == 4 {
                    // Four vertices (every box): no slot to pad, so no `i < n` selects.
                    let (x, y) = apply_lanes(rot, t, split_xy([v[0], v[1], v[2], v[3]]));
                    bounds_of_points([x], [y])
                } else if n < 4 {
                    let (x, y) = group(0);
                    bounds_of_points([x], [y])
                } else {
                    let ((x0, y0), (x1, y1)) = (group(0), group(4));
                    bounds_of_points([x0, x1], [y0, y1])
                };
                Aabb::new(Vec2::new(lo[0], lo[1]), Vec2::new(hi[0], hi[1])).expand(p.radius)
            }
            Shape::Polygon(p) => {
                let verts = p.vertices();
                let first = verts.first().map_or(xf.p, |&v| xf.apply(v));
                let mut lo = first;
                let mut hi = first;
                for &v in verts.iter().skip(1) {
                    let w = xf.apply(v);
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
                Aabb::new(lo, hi).expand(p.radius)
            }
        }
    }

    /// Centroid of the solid [m, body frame] (a segment's midpoint for segments).
    pub fn centroid(&self) -> Vec2 {
        match self {
            Shape::Circle(c) => c.center,
            Shape::Capsule(c) => c.center1.lerp(c.center2, 0.5),
            Shape::Segment(s) | Shape::ChainSegment(ChainSegment { segment: s, .. }) => s.point1.lerp(s.point2, 0.5),
            Shape::Polygon(p) => p.centroid,
        }
    }

    /// Largest distance [m] from `local_center` [m, body frame] to any point of the shape
    /// (radius included). Bounds the speed of surface points: `|v| + |ω| · max_extent`.
    pub fn max_extent(&self, local_center: Vec2) -> f32 {
        match self {
            Shape::Circle(c) => (c.center - local_center).length() + c.radius,
            Shape::Capsule(c) => {
                let a = (c.center1 - local_center).length();
                let b = (c.center2 - local_center).length();
                a.max(b) + c.radius
            }
            Shape::Segment(s) | Shape::ChainSegment(ChainSegment { segment: s, .. }) => {
                let a = (s.point1 - local_center).length();
                let b = (s.point2 - local_center).length();
                a.max(b)
            }
            Shape::Polygon(p) => {
                let far = p
                    .vertices()
                    .iter()
                    .fold(0.0f32, |m, &v| m.max((v - local_center).length()));
                far + p.radius
            }
        }
    }

    /// Rough thickness [m]: how far the shape can move before it could tunnel through
    /// something. Circle and capsule: radius; polygon: smallest distance from the centroid to
    /// an edge line plus the radius; segment: 0.
    pub fn min_extent(&self) -> f32 {
        match self {
            Shape::Circle(c) => c.radius,
            Shape::Capsule(c) => c.radius,
            Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
            Shape::Polygon(p) => {
                let mut min = f32::MAX;
                for (v, n) in p.vertices().iter().zip(p.normals()) {
                    min = min.min(n.dot(*v - p.centroid));
                }
                if min == f32::MAX {
                    min = 0.0;
                }
                min.max(0.0) + p.radius
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::manifold::test_support::uniform;
    use crate::math::Rot;

    fn v(x: f32, y: f32) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn constructors_validate() {
        assert!(Circle::new(v(1.0, 2.0), 0.5).is_ok());
        assert_eq!(
            Circle::new(v(f32::NAN, 0.0), 1.0),
            Err(GeometryError::NonFinite("center"))
        );
        assert_eq!(
            Circle::new(v(0.0, 0.0), f32::INFINITY),
            Err(GeometryError::NonFinite("radius"))
        );
        assert_eq!(
            Circle::new(v(0.0, 0.0), 0.0),
            Err(GeometryError::NonPositive("radius", 0.0))
        );
        assert_eq!(
            Circle::new(v(0.0, 0.0), -1.0),
            Err(GeometryError::NonPositive("radius", -1.0))
        );

        assert!(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.25).is_ok());
        assert!(matches!(
            Capsule::new(v(0.0, 0.0), v(0.001, 0.0), 0.25),
            Err(GeometryError::DegenerateSegment(_))
        ));
        assert_eq!(
            Capsule::new(v(0.0, 0.0), v(1.0, 0.0), 0.0),
            Err(GeometryError::NonPositive("radius", 0.0))
        );
        assert_eq!(
            Capsule::new(v(0.0, f32::NAN), v(1.0, 0.0), 0.1),
            Err(GeometryError::NonFinite("center1"))
        );

        assert!(Segment::new(v(0.0, 0.0), v(1.0, 0.0)).is_ok());
        assert!(matches!(
            Segment::new(v(0.0, 0.0), v(0.0, 0.0)),
            Err(GeometryError::DegenerateSegment(_))
        ));
        assert_eq!(
            Segment::new(v(0.0, 0.0), v(f32::INFINITY, 0.0)),
            Err(GeometryError::NonFinite("point2"))
        );

        assert_eq!(Polygon::new_box(0.0, 1.0), Err(GeometryError::NonPositive("hx", 0.0)));
        assert_eq!(Polygon::new_box(1.0, f32::NAN), Err(GeometryError::NonFinite("hy")));
        assert_eq!(
            Polygon::new_rounded_box(1.0, 1.0, -0.1),
            Err(GeometryError::Negative("radius", -0.1))
        );
        assert_eq!(
            Polygon::new_offset_box(1.0, 1.0, v(0.0, 0.0), f32::NAN),
            Err(GeometryError::NonFinite("angle"))
        );
    }

    #[test]
    fn from_points_errors() {
        let sq = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
        assert_eq!(
            Polygon::from_points(&sq, -0.1),
            Err(GeometryError::Negative("radius", -0.1))
        );
        assert_eq!(
            Polygon::from_points(&sq, f32::NAN),
            Err(GeometryError::NonFinite("radius"))
        );
        assert_eq!(
            Polygon::from_points(&[v(0.0, 0.0), v(1.0, f32::NAN), v(0.0, 1.0)], 0.0),
            Err(GeometryError::NonFinite("points"))
        );
        assert!(matches!(
            Polygon::from_points(&[v(0.0, 0.0), v(1.0, 1.0), v(2.0, 2.0)], 0.0),
            Err(GeometryError::DegeneratePolygon(_))
        ));
        assert!(matches!(
            Polygon::from_points(&[v(0.0, 0.0), v(1.0, 1.0)], 0.0),
            Err(GeometryError::DegeneratePolygon(_))
        ));
        let ten: Vec<Vec2> = (0..10)
            .map(|i| {
                let a = i as f32 * core::f32::consts::TAU / 10.0;
                v(a.cos(), a.sin())
            })
            .collect();
        assert_eq!(Polygon::from_points(&ten, 0.0), Err(GeometryError::TooManyVertices(10)));
        assert!(Polygon::from_points(&ten[..8], 0.0).is_ok());
    }

    #[test]
    fn from_points_matches_box() {
        let b = Polygon::new_box(0.5, 0.25).unwrap();
        let p = Polygon::from_points(
            &[v(0.5, 0.25), v(-0.5, -0.25), v(0.0, 0.0), v(-0.5, 0.25), v(0.5, -0.25)],
            0.0,
        )
        .unwrap();
        assert_eq!(p, b);
        assert_eq!(b.normals(), &[v(0.0, -1.0), v(1.0, 0.0), v(0.0, 1.0), v(-1.0, 0.0)]);
        assert_eq!(b.count(), 4);
        assert_eq!(b.centroid(), Vec2::ZERO);
    }

    #[test]
    fn triangle_normals_and_centroid() {
        let p = Polygon::from_points(&[v(0.0, 0.0), v(3.0, 0.0), v(0.0, 3.0)], 0.0).unwrap();
        assert!((p.centroid() - v(1.0, 1.0)).length() < 1e-6);
        let n = p.normals();
        assert!((n[0] - v(0.0, -1.0)).length() < 1e-6);
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert!((n[1] - v(s, s)).length() < 1e-6);
        assert!((n[2] - v(-1.0, 0.0)).length() < 1e-6);
        for (i, nn) in n.iter().enumerate() {
            // Every vertex lies behind every edge plane.
            for w in p.vertices() {
                assert!(nn.dot(*w - p.vertices()[i]) <= 1e-6);
            }
        }
    }

    #[test]
    fn offset_box() {
        let p = Polygon::new_offset_box(1.0, 0.5, v(2.0, 3.0), core::f32::consts::FRAC_PI_2).unwrap();
        assert!((p.vertices()[0] - v(2.5, 2.0)).length() < 1e-6, "{:?}", p.vertices());
        assert!((p.normals()[0] - v(1.0, 0.0)).length() < 1e-6);
        assert_eq!(p.centroid(), v(2.0, 3.0));
    }

    #[test]
    fn aabbs_and_extents() {
        let xf = Transform::new(v(1.0, 2.0), core::f32::consts::FRAC_PI_2);
        let c = Shape::Circle(Circle::new(v(1.0, 0.0), 0.5).unwrap());
        let bb = c.aabb(xf);
        assert!((bb.min - v(0.5, 2.5)).length() < 1e-6 && (bb.max - v(1.5, 3.5)).length() < 1e-6);
        let b = Shape::Polygon(Polygon::new_rounded_box(1.0, 0.5, 0.1).unwrap());
        let bb = b.aabb(xf);
        assert!((bb.min - v(0.4, 0.9)).length() < 1e-6, "{bb:?}");
        assert!((bb.max - v(1.6, 3.1)).length() < 1e-6, "{bb:?}");
        let s = Shape::Segment(Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap());
        let bb = s.aabb(Transform::IDENTITY);
        assert_eq!(bb, Aabb::new(v(-1.0, 0.0), v(1.0, 0.0)));
        let cap = Shape::Capsule(Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.25).unwrap());
        assert_eq!(cap.aabb(Transform::IDENTITY), Aabb::new(v(-1.25, -0.25), v(1.25, 0.25)));

        assert!((b.max_extent(Vec2::ZERO) - (1.25f32.sqrt() + 0.1)).abs() < 1e-6);
        assert!((b.min_extent() - 0.6).abs() < 1e-6);
        assert!((cap.max_extent(Vec2::ZERO) - 1.25).abs() < 1e-6);
        assert_eq!(cap.min_extent(), 0.25);
        assert_eq!(s.min_extent(), 0.0);
        assert!((c.max_extent(Vec2::ZERO) - 1.5).abs() < 1e-6);
        assert_eq!(cap.centroid(), Vec2::ZERO);
    }

    /// A polygon's box is computed four vertices a lane vector; it must be the scalar
    /// fold's, bit for bit (the broad phase and every trajectory depend on it): the same
    /// sums in the same order, and on a tie the running value kept, down to the sign of a
    /// zero. The reference is the fold over the vertices in order with that tie rule
    /// written out; on x86-64 it is also what the old code's `f32::min`/`f32::max` fold
    /// gives, checked here too. The cases: boxes, polygons of 3 to 8 vertices around the
    /// body origin and away from it (there the slots past the count, zeros, would be
    /// outliers if read), regular ones, and signed-zero ties for every vertex count.
    #[test]
    fn a_polygon_aabb_is_the_scalar_folds_bits() {
        let fold = |p: &Polygon, xf: Transform| {
            let w: Vec<Vec2> = p.vertices().iter().map(|&v| xf.apply(v)).collect();
            let (mut lo, mut hi) = (w[0], w[0]);
            let keep = |acc: f32, q: f32, better: bool| if better { q } else { acc };
            for &q in &w[1..] {
                lo = Vec2::new(keep(lo.x, q.x, q.x < lo.x), keep(lo.y, q.y, q.y < lo.y));
                hi = Vec2::new(keep(hi.x, q.x, q.x > hi.x), keep(hi.y, q.y, q.y > hi.y));
            }
            Aabb::new(lo, hi).expand(p.radius)
        };
        let std_fold = |p: &Polygon, xf: Transform| {
            let w: Vec<Vec2> = p.vertices().iter().map(|&v| xf.apply(v)).collect();
            let (mut lo, mut hi) = (w[0], w[0]);
            for &q in &w[1..] {
                lo = lo.min(q);
                hi = hi.max(q);
            }
            Aabb::new(lo, hi).expand(p.radius)
        };
        let bits = |b: Aabb| [b.min.x, b.min.y, b.max.x, b.max.y].map(f32::to_bits);
        let mut next = uniform(0x2545_f491);
        let mut cases = Vec::new();
        for _ in 0..500 {
            let p = Polygon::new_rounded_box(0.05 + next(), 0.05 + next(), 0.1 * next()).unwrap();
            let xf = Transform::new(v(20.0 * next() - 10.0, 20.0 * next() - 10.0), 7.0 * next() - 3.5);
            cases.push((p, xf));
        }
        let mut sizes = [0usize; MAX_POLYGON_VERTICES + 1];
        for k in 0..1200 {
            // Points spread round a circle about the origin or about (3, 3); every third
            // polygon regular (equal coordinates: ties of equal values).
            let n = 3 + k % (MAX_POLYGON_VERTICES - 2);
            let regular = k % 3 == 0;
            let centre = if k % 2 == 0 { Vec2::ZERO } else { v(3.0, 3.0) };
            let points: Vec<Vec2> = (0..n)
                .map(|i| {
                    let (jitter, r) = if regular {
                        (0.0, 0.5)
                    } else {
                        (0.3 * next(), 0.5 + 0.2 * next())
                    };
                    let a = (i as f32 + jitter) * core::f32::consts::TAU / n as f32;
                    centre + v(a.cos(), a.sin()) * r
                })
                .collect();
            let Ok(p) = Polygon::from_points(&points, 0.05 * next()) else {
                continue;
            };
            sizes[p.count()] += 1;
            let xf = Transform::new(v(20.0 * next() - 10.0, 20.0 * next() - 10.0), 7.0 * next() - 3.5);
            cases.push((p, xf));
            cases.push((p, Transform::IDENTITY));
        }
        assert!(
            sizes[3..].iter().all(|&m| m > 20),
            "every vertex count is covered: {sizes:?}"
        );
        // Ties of signed zeros: a polygon with two vertices on x = 0, its largest x, turned
        // by exactly a half turn (c = −1, s = ±0) and moved by −0: one of those vertices
        // lands on x = −0 and the other on x = +0, both the smallest x (on the largest
        // side the radius added, +0, would make either zero +0). Flipping the sign of s
        // swaps which vertex is −0: the fold keeps the first either way, so the two boxes
        // differ in that sign. For 3 to 8 vertices (the two tied vertices fall in either
        // lane group).
        for n in 3..=MAX_POLYGON_VERTICES {
            let mut points = vec![v(0.0, -1.0), v(0.0, 1.0)];
            points.extend((0..n - 2).map(|i| {
                let a = core::f32::consts::PI * (i as f32 + 1.0) / (n - 1) as f32;
                v(-2.0 * a.sin(), -a.cos())
            }));
            let p = Polygon::from_points(&points, 0.0).unwrap();
            assert_eq!(p.count(), n);
            let mut signs = Vec::new();
            for sign in [1.0, -1.0] {
                let xf = Transform {
                    p: v(-0.0, 0.0),
                    q: Rot { c: -1.0, s: 0.0 * sign },
                };
                cases.push((p, xf));
                let slow = fold(&p, xf);
                assert_eq!(slow.min.x, 0.0);
                signs.push(slow.min.x.is_sign_negative());
            }
            assert_ne!(
                signs[0], signs[1],
                "{n} vertices: the two ties must keep zeros of opposite signs"
            );
        }
        // The box of a box: its own branch.
        let p = Polygon::new_offset_box(1.0, 1.0, v(-1.0, 0.0), 0.0).unwrap();
        for sign in [1.0, -1.0] {
            let xf = Transform {
                p: v(-0.0, 0.0),
                q: Rot { c: -1.0, s: 0.0 * sign },
            };
            cases.push((p, xf));
        }
        for (p, xf) in &cases {
            if cfg!(target_arch = "x86_64") {
                assert_eq!(bits(fold(p, *xf)), bits(std_fold(p, *xf)), "the old fold, {xf:?}");
            }
        }
        for (p, xf) in cases {
            let (fast, slow) = (Shape::Polygon(p).aabb(xf), fold(&p, xf));
            assert_eq!(bits(fast), bits(slow), "{xf:?}: {fast:?} vs {slow:?}");
        }
    }
}
