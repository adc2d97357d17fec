//! Contact manifolds: one file per shape pair, one dispatch match.
//!
//! Every pair function works in shape A's local frame (B is brought over once with
//! `xf_a⁻¹ · xf_b`, so large world coordinates cancel before any geometry) and the result is
//! turned into world axes at the end. Conventions (see [`Manifold`]): unit normal from A to B;
//! each point lies midway between the two surfaces; separation is the signed distance between
//! the surfaces including all radii (negative = overlap); points are kept while
//! `separation < speculative_distance`.
//!
//! # Feature ids
//!
//! `id = kind << 8 | feature_a << 4 | feature_b` (features are vertex/edge indices < 16):
//!
//! | kind | meaning | feature_a | feature_b |
//! |---|---|---|---|
//! | 0 | single point between smooth features (circle contacts); id is 0 | 0 | 0 |
//! | 1 | clipped point, reference edge on A | A edge | B incident vertex |
//! | 2 | clipped point, reference edge on B | A incident vertex | B edge |
//! | 3 | closest vertices (separated corners, or clipping fallback) | A vertex | B vertex |
//! | 4 | capsule/segment closest features, one point | A feature | B feature |
//!
//! For kind 4 a feature is 0 / 1 for the first / second end and 2 for the interior.
//! A clipped point is keyed by the reference edge and the incident-edge vertex it comes from
//! (whether or not it was clipped), so a box sliding on a box, or rocking on one corner,
//! keeps its ids; the two points of a clipped manifold come from the two different incident
//! vertices, so ids are distinct. Reversed pairs keep the ids of the dedicated function.

mod capsule_capsule;
mod capsule_circle;
mod chain_segment;
mod circle_circle;
mod polygon_capsule;
mod polygon_circle;
mod polygon_polygon;
mod polygon_segment;
mod segment_capsule;
mod segment_circle;

use super::{Shape, LINEAR_SLOP};
use crate::math::{Transform, Vec2};

/// At most two contact points per manifold in 2D.
pub const MAX_MANIFOLD_POINTS: usize = 2;

/// One contact point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ManifoldPoint {
    /// World position [m]: midway between the two surfaces.
    pub point: Vec2,
    /// `point` relative to the origin of transform A (`point - xf_a.p`), world axes [m].
    pub anchor_a: Vec2,
    /// `point` relative to the origin of transform B (`point - xf_b.p`), world axes [m].
    pub anchor_b: Vec2,
    /// Signed distance between the surfaces along the normal [m]; negative = overlap.
    pub separation: f32,
    /// Feature id: stays the same while the same pair of features (vertex/edge) touches,
    /// so impulses and friction state can carry over between steps.
    pub id: u16,
}

/// The contact between two shapes: a normal and up to two points.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Manifold {
    /// Unit normal in world axes, pointing from shape A to shape B.
    pub normal: Vec2,
    /// The points; only the first `count` are meaningful.
    pub points: [ManifoldPoint; MAX_MANIFOLD_POINTS],
    /// Number of points (0, 1 or 2).
    pub count: usize,
}

impl Manifold {
    /// An empty manifold (no contact).
    pub const EMPTY: Manifold = Manifold {
        normal: Vec2::ZERO,
        points: [ManifoldPoint {
            point: Vec2::ZERO,
            anchor_a: Vec2::ZERO,
            anchor_b: Vec2::ZERO,
            separation: 0.0,
            id: 0,
        }; MAX_MANIFOLD_POINTS],
        count: 0,
    };

    /// The meaningful points (`&points[..count]`).
    pub fn active_points(&self) -> &[ManifoldPoint] {
        &self.points[..self.count.min(MAX_MANIFOLD_POINTS)]
    }
}

/// Computes the contact manifold between `shape_a` placed by `xf_a` and `shape_b` placed by
/// `xf_b` (all ordered pairs of circle, capsule, polygon, segment and chain segment).
///
/// Points whose separation [m] is below `speculative_distance` [m] are kept (pass at least
/// [`super::SPECULATIVE_DISTANCE`]; more for fast bodies). A pair of segments or chain
/// segments always gives an empty manifold: they are zero-mass ground shapes and never move
/// relative to each other through contact. Non-finite input gives an empty manifold or non-finite numbers, never a
/// panic.
pub fn collide(
    shape_a: &Shape,
    xf_a: Transform,
    shape_b: &Shape,
    xf_b: Transform,
    speculative_distance: f32,
) -> Manifold {
    collide_after(shape_a, xf_a, shape_b, xf_b, speculative_distance, &Manifold::EMPTY)
}

/// [`collide`] for a pair whose manifold of the last step was `last`: two polygons keep
/// the reference face they clipped against while the other face is not clearly better
/// (see `polygon_polygon`), so the feature ids, and with them warm starting, friction
/// state and preload, survive the sway of loaded stacks.
pub fn collide_after(
    shape_a: &Shape,
    xf_a: Transform,
    shape_b: &Shape,
    xf_b: Transform,
    speculative_distance: f32,
    last: &Manifold,
) -> Manifold {
    collide_bounded(shape_a, xf_a, shape_b, xf_b, speculative_distance, last).0
}

/// [`collide_after`], and for an empty manifold of shapes too far apart a lower bound [m]
/// on the distance between their surfaces (0 when there is none: touching, or a pair whose
/// bound is not computed). Every point a manifold can have lies at a separation no smaller
/// than the distance between the surfaces (a clipped point is measured along the reference
/// normal inside the reference face's slab, a vertex pair by its distance), so while the
/// shapes stay farther apart than the speculative distance the manifold stays empty: the
/// narrow phase then skips pairs until their relative motion could have used the bound up.
/// The bound is the separating-axis separation that rejected the pair (pairs of polygons,
/// capsules and segments through `polygon_polygon`, polygon–circle) or the exact distance
/// (circle, capsule and segment pairs by their closest points).
pub(crate) fn collide_bounded(
    shape_a: &Shape,
    xf_a: Transform,
    shape_b: &Shape,
    xf_b: Transform,
    speculative_distance: f32,
    last: &Manifold,
) -> (Manifold, f32) {
    let mut m = Manifold::EMPTY;
    let bound = collide_bounded_into(shape_a, xf_a, shape_b, xf_b, speculative_distance, last, &mut m);
    (m, bound)
}

/// [`collide_bounded`] with the manifold written into `out` (the contact's own); returns
/// the bound. The one dispatch over shape pairs: two polygons write theirs in place (see
/// [`LocalManifold::write_world`]), the other pairs' manifolds are copied in.
pub(crate) fn collide_bounded_into(
    shape_a: &Shape,
    xf_a: Transform,
    shape_b: &Shape,
    xf_b: Transform,
    speculative_distance: f32,
    last: &Manifold,
    out: &mut Manifold,
) -> f32 {
    let spec = speculative_distance;
    // A chain piece keeps holding a shape it had a manifold with (chain_segment, step 1).
    let held = last.count > 0;
    let (m, bound) = match (shape_a, shape_b) {
        (Shape::Circle(a), Shape::Circle(b)) => circle_circle::collide_circles(a, xf_a, b, xf_b, spec),
        (Shape::Circle(a), Shape::Capsule(b)) => flip(capsule_circle::collide_capsule_circle(b, xf_b, a, xf_a, spec)),
        (Shape::Circle(a), Shape::Polygon(b)) => flip(polygon_circle::collide_polygon_circle(b, xf_b, a, xf_a, spec)),
        (Shape::Circle(a), Shape::Segment(b)) => flip(segment_circle::collide_segment_circle(b, xf_b, a, xf_a, spec)),

        (Shape::Capsule(a), Shape::Circle(b)) => capsule_circle::collide_capsule_circle(a, xf_a, b, xf_b, spec),
        (Shape::Capsule(a), Shape::Capsule(b)) => capsule_capsule::collide_capsules(a, xf_a, b, xf_b, spec),
        (Shape::Capsule(a), Shape::Polygon(b)) => {
            flip(polygon_capsule::collide_polygon_capsule(b, xf_b, a, xf_a, spec))
        }
        (Shape::Capsule(a), Shape::Segment(b)) => {
            flip(segment_capsule::collide_segment_capsule(b, xf_b, a, xf_a, spec))
        }

        (Shape::Polygon(a), Shape::Circle(b)) => polygon_circle::collide_polygon_circle(a, xf_a, b, xf_b, spec),
        (Shape::Polygon(a), Shape::Capsule(b)) => polygon_capsule::collide_polygon_capsule(a, xf_a, b, xf_b, spec),
        (Shape::Polygon(a), Shape::Polygon(b)) => {
            return polygon_polygon::collide_polygons_into(a, xf_a, b, xf_b, spec, last_reference_b(last), out)
        }
        (Shape::Polygon(a), Shape::Segment(b)) => polygon_segment::collide_polygon_segment(a, xf_a, b, xf_b, spec),

        (Shape::Segment(a), Shape::Circle(b)) => segment_circle::collide_segment_circle(a, xf_a, b, xf_b, spec),
        (Shape::Segment(a), Shape::Capsule(b)) => segment_capsule::collide_segment_capsule(a, xf_a, b, xf_b, spec),
        (Shape::Segment(a), Shape::Polygon(b)) => {
            flip(polygon_segment::collide_polygon_segment(b, xf_b, a, xf_a, spec))
        }

        (Shape::ChainSegment(a), Shape::Circle(b)) => chain_segment::collide_chain_circle(a, xf_a, b, xf_b, spec, held),
        (Shape::ChainSegment(a), Shape::Capsule(b)) => {
            chain_segment::collide_chain_capsule(a, xf_a, b, xf_b, spec, held)
        }
        (Shape::ChainSegment(a), Shape::Polygon(b)) => {
            chain_segment::collide_chain_polygon(a, xf_a, b, xf_b, spec, last_reference_b(last), held)
        }
        (Shape::Circle(a), Shape::ChainSegment(b)) => {
            flip(chain_segment::collide_chain_circle(b, xf_b, a, xf_a, spec, held))
        }
        (Shape::Capsule(a), Shape::ChainSegment(b)) => {
            flip(chain_segment::collide_chain_capsule(b, xf_b, a, xf_a, spec, held))
        }
        (Shape::Polygon(a), Shape::ChainSegment(b)) => flip(chain_segment::collide_chain_polygon(
            b,
            xf_b,
            a,
            xf_a,
            spec,
            last_reference_b(last),
            held,
        )),

        // Zero-mass ground shapes never push each other.
        (Shape::Segment(_) | Shape::ChainSegment(_), Shape::Segment(_) | Shape::ChainSegment(_)) => {
            (Manifold::EMPTY, 0.0)
        }
    };
    *out = m;
    bound
}

/// Which polygon's face the last manifold of a polygon pair clipped against (`Some(true)`:
/// B's), for the sticky reference face of `polygon_polygon`.
fn last_reference_b(last: &Manifold) -> Option<bool> {
    match last.active_points().first().map(|p| p.id >> 8) {
        Some(KIND_CLIP_REF_A) => Some(false),
        Some(KIND_CLIP_REF_B) => Some(true),
        _ => None,
    }
}

/// Turns the manifold of (B, A) into the manifold of (A, B): the normal is negated, the
/// anchors swap (the old `anchor_a = point − xf_b.p` is the new `anchor_b`), points,
/// separations, ids and the separation bound are unchanged.
fn flip((m, bound): (Manifold, f32)) -> (Manifold, f32) {
    let mut out = m;
    out.normal = -m.normal;
    for p in out.points.iter_mut() {
        core::mem::swap(&mut p.anchor_a, &mut p.anchor_b);
    }
    (out, bound)
}

/// Feature-id kinds (see the module documentation).
const KIND_CLIP_REF_A: u16 = 1;
const KIND_CLIP_REF_B: u16 = 2;
const KIND_VERTEX_VERTEX: u16 = 3;
const KIND_SEGMENT_FEATURES: u16 = 4;

/// Packs a feature id: `kind << 8 | a << 4 | b` (a, b < 16).
fn feature_id(kind: u16, a: usize, b: usize) -> u16 {
    ((kind & 0xFF) << 8) | (((a as u16) & 0xF) << 4) | ((b as u16) & 0xF)
}

/// Below this core distance [m] two cores count as touching and a normal from their closest
/// points is not trusted.
const CORE_TOUCH: f32 = 0.1 * LINEAR_SLOP;

/// One point of a manifold under construction, in A's local frame.
#[derive(Clone, Copy, Debug, Default)]
struct LocalPoint {
    /// Midway point [m, A frame].
    point: Vec2,
    /// Signed surface distance [m].
    separation: f32,
    id: u16,
    /// Always 0: the record's two padding bytes made a field of their own. Without it the
    /// zeroed record was written as two overlapping 8-byte stores (bytes 0–7 and 6–13,
    /// skipping the padding), and the first load of its copy, reading bytes 0–7 from both,
    /// could not be forwarded from the store buffer and waited for both to retire (a
    /// quarter of the polygon collision's samples in tumbler).
    _pad: u16,
}

/// A manifold under construction, in A's local frame.
#[derive(Clone, Copy, Debug, Default)]
struct LocalManifold {
    /// When the manifold is empty because the shapes are too far apart: a lower bound [m]
    /// on the distance between their surfaces (0 when unknown). See [`collide_bounded`].
    bound: f32,
    /// Unit normal from A to B [A frame].
    normal: Vec2,
    points: [LocalPoint; MAX_MANIFOLD_POINTS],
    count: usize,
}

impl LocalManifold {
    fn new(normal: Vec2) -> LocalManifold {
        LocalManifold {
            normal,
            ..LocalManifold::default()
        }
    }

    /// Adds a point when there is room and it is closer than `spec` (NaN is rejected).
    fn push(&mut self, point: Vec2, separation: f32, id: u16, spec: f32) {
        if self.count < MAX_MANIFOLD_POINTS && separation < spec {
            self.points[self.count] = LocalPoint {
                point,
                separation,
                id,
                _pad: 0,
            };
            self.count += 1;
        }
    }

    /// To world axes: `anchor_a = q_a · p`, `point = xf_a.p + anchor_a`,
    /// `anchor_b = anchor_a + (xf_a.p − xf_b.p)` (no large world coordinate is subtracted
    /// from a nearby one); with the separation bound of an empty manifold.
    fn to_world(self, xf_a: Transform, xf_b: Transform) -> (Manifold, f32) {
        let mut m = Manifold::EMPTY;
        let bound = self.write_world(xf_a, xf_b, &mut m);
        (m, bound)
    }

    /// [`LocalManifold::to_world`] written into `m` in place, field by field (what the
    /// narrow phase's contact update takes: a manifold returned by value was copied out of
    /// the callee's frame by 16-byte loads over the narrower stores that had just made
    /// it, which cannot be forwarded; a third of `Contact::update`'s samples in the
    /// tumbler). Returns the separation bound.
    #[inline(always)]
    fn write_world(&self, xf_a: Transform, xf_b: Transform, m: &mut Manifold) -> f32 {
        let count = self.count.min(MAX_MANIFOLD_POINTS);
        let normal = if count == 0 {
            Vec2::ZERO
        } else {
            xf_a.q.rotate(self.normal)
        };
        m.normal = normal;
        let dp = xf_a.p - xf_b.p;
        for (i, out) in m.points.iter_mut().enumerate() {
            match self.points.get(i).filter(|_| i < count) {
                Some(lp) => {
                    let anchor_a = xf_a.q.rotate(lp.point);
                    out.point = xf_a.p + anchor_a;
                    out.anchor_a = anchor_a;
                    out.anchor_b = anchor_a + dp;
                    out.separation = lp.separation;
                    out.id = lp.id;
                }
                None => *out = ManifoldPoint::default(),
            }
        }
        m.count = count;
        if count == 0 {
            self.bound
        } else {
            0.0
        }
    }

    /// Adds a point as [`LocalManifold::push`] does; when it is too far for the manifold,
    /// its separation is the exact distance and becomes the bound.
    fn push_or_bound(&mut self, point: Vec2, separation: f32, id: u16, spec: f32) {
        let before = self.count;
        self.push(point, separation, id, spec);
        if self.count == before && separation > 0.0 {
            self.bound = separation;
        }
    }
}

/// Closest points between segments `p1`–`q1` and `p2`–`q2`.
#[derive(Clone, Copy, Debug)]
struct Closest {
    /// Point on the first segment [m].
    a: Vec2,
    /// Point on the second segment [m].
    b: Vec2,
    /// Parameter of `a` along the first segment, exactly 0 or 1 at the ends.
    fa: f32,
    /// Parameter of `b` along the second segment, exactly 0 or 1 at the ends.
    fb: f32,
}

/// Closest points of two segments. Method: minimise `|p1 + s d1 − p2 − t d2|²` over the unit
/// square (Ericson, *Real-Time Collision Detection*, §5.1.9): solve the 2×2 normal equations,
/// clamp `s`, recompute `t`, and when `t` clamps recompute `s`. Parallel segments (determinant
/// ≈ 0) start from `s = 0`. Zero-length segments degrade to point–segment queries.
fn segment_closest(p1: Vec2, q1: Vec2, p2: Vec2, q2: Vec2) -> Closest {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let eps = f32::EPSILON * f32::EPSILON;
    let (s, t);
    if a <= eps && e <= eps {
        s = 0.0;
        t = 0.0;
    } else if a <= eps {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= eps {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > f32::EPSILON * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    // Keep the ends exact so callers can test `f == 0.0 || f == 1.0`.
    let s = if s.is_nan() { 0.0 } else { s };
    let t = if t.is_nan() { 0.0 } else { t };
    Closest {
        a: if s == 1.0 { q1 } else { p1 + d1 * s },
        b: if t == 1.0 { q2 } else { p2 + d2 * t },
        fa: s,
        fb: t,
    }
}

/// Closest point on segment `a`–`b` to `p`, and its parameter in [0, 1].
fn closest_on_segment(p: Vec2, a: Vec2, b: Vec2) -> (Vec2, f32) {
    let e = b - a;
    let ee = e.length_squared();
    if !(ee > 0.0) {
        return (a, 0.0);
    }
    let t = ((p - a).dot(e) / ee).clamp(0.0, 1.0);
    (if t == 1.0 { b } else { a + e * t }, t)
}

/// A point produced by clipping an incident edge against a reference edge.
#[derive(Clone, Copy, Debug)]
struct ClipPoint {
    /// Midway point [m].
    point: Vec2,
    /// Signed surface distance [m] (core distance along the reference normal minus radii).
    separation: f32,
    /// Index of the incident vertex this point comes from.
    incident_vertex: usize,
}

/// The reference edge `v11 → v12` (outward unit normal `n`, radius `r_ref`) against the
/// incident edge `v21 → v22` (vertex indices `i21`, `i22`, radius `r_inc`), which runs roughly
/// opposite to it.
///
/// The incident edge is cut to the slab between the reference edge's two side planes
/// (Sutherland–Hodgman clipping against two half-planes, in the edge's tangent coordinate).
/// The end near `v11` comes from `v22`, the end near `v12` from `v21`. For each end, with `d`
/// its core distance along `n`: separation `d − r_ref − r_inc`; the reference surface is at
/// `r_ref` and the incident surface at `d − r_inc` along `n`, so the midway point is the
/// incident point moved by `(r_ref − r_inc − d)/2` along `n`.
///
/// Returns false when the incident edge lies wholly outside the slab (the caller then falls
/// back to closest features); otherwise gives each of the up-to-2 points closer than `spec`
/// to `emit`, in order (the end near `v11` first), and returns true. Given to the caller's
/// closure, inlined into each caller, rather than returned in an array: the array, made on
/// the stack by narrow stores and copied out by 16-byte loads, waited on store forwarding
/// (a sixth of this function's samples in the tumbler, when it was a function of its own;
/// inlining it alone had not helped, the copy stayed).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn clip_incident_edge(
    v11: Vec2,
    v12: Vec2,
    n: Vec2,
    r_ref: f32,
    v21: Vec2,
    v22: Vec2,
    i21: usize,
    i22: usize,
    r_inc: f32,
    spec: f32,
    mut emit: impl FnMut(ClipPoint),
) -> bool {
    let (len, tangent) = (v12 - v11).length_and_normalize();
    let tangent = if len > 0.0 { tangent } else { n.left_perp() };
    let s21 = tangent.dot(v21 - v11);
    let s22 = tangent.dot(v22 - v11);
    let ds = s21 - s22;
    let (x_upper, x_lower);
    if ds > 0.0 {
        // s(u) = s21 − u·ds along v21 → v22; keep 0 ≤ s ≤ len.
        let u0 = ((s21 - len) / ds).max(0.0);
        let u1 = (s21 / ds).min(1.0);
        if !(u0 <= u1) {
            return false;
        }
        x_upper = v21.lerp(v22, u0);
        x_lower = v21.lerp(v22, u1);
    } else {
        // Incident edge perpendicular to the reference edge (or reversed by round-off): no
        // cut is possible; accept it only when it lies within the slab.
        let s = 0.5 * (s21 + s22);
        if !(s >= 0.0 && s <= len) {
            return false;
        }
        x_upper = v21;
        x_lower = v22;
    }
    for (x, vertex) in [(x_lower, i22), (x_upper, i21)] {
        let d = n.dot(x - v11);
        let separation = d - r_ref - r_inc;
        if separation < spec {
            emit(ClipPoint {
                point: x + n * (0.5 * (r_ref - r_inc - d)),
                separation,
                incident_vertex: vertex,
            });
        }
    }
    true
}

#[cfg(test)]
pub(crate) mod test_support;

#[cfg(test)]
mod bound_tests {
    use super::*;
    use crate::geometry::{Capsule, Circle, Polygon, Segment};

    /// Exact distance between the surfaces of two shapes that do not overlap, by brute
    /// force: every shape here is a convex polygon, a circle (one point with a radius), a
    /// capsule or a segment (two points), so the distance between the cores is the smallest
    /// distance from a vertex of one to an edge of the other.
    fn distance(a: &Shape, xf_a: Transform, b: &Shape, xf_b: Transform) -> f32 {
        fn core(s: &Shape, xf: Transform) -> (Vec<Vec2>, f32) {
            match s {
                Shape::Polygon(p) => (p.vertices().iter().map(|&v| xf.apply(v)).collect(), p.radius()),
                Shape::Circle(c) => (vec![xf.apply(c.center)], c.radius),
                Shape::Capsule(c) => (vec![xf.apply(c.center1), xf.apply(c.center2)], c.radius),
                Shape::Segment(g) | Shape::ChainSegment(crate::geometry::ChainSegment { segment: g, .. }) => {
                    (vec![xf.apply(g.point1), xf.apply(g.point2)], 0.0)
                }
            }
        }
        fn to_edges(p: Vec2, vs: &[Vec2]) -> f32 {
            if vs.len() == 1 {
                return (p - vs[0]).length();
            }
            (0..vs.len())
                .map(|i| (p - closest_on_segment(p, vs[i], vs[(i + 1) % vs.len()]).0).length())
                .fold(f32::MAX, f32::min)
        }
        let ((va, ra), (vb, rb)) = (core(a, xf_a), core(b, xf_b));
        let ab = va.iter().map(|&p| to_edges(p, &vb)).fold(f32::MAX, f32::min);
        let ba = vb.iter().map(|&p| to_edges(p, &va)).fold(f32::MAX, f32::min);
        ab.min(ba) - ra - rb
    }

    #[test]
    fn separation_bound_never_exceeds_the_distance() {
        // A box, a rounded triangle, a circle, a capsule, a segment and a chain piece at many
        // poses around each other (every pair but those of two ground shapes): whenever
        // collide_bounded reports the pair apart with a bound, the bound is at most the
        // true surface distance (to 10 µm of f32 rounding), and the manifold is empty.
        let shapes = [
            Shape::Polygon(Polygon::new_box(0.5, 0.25).unwrap()),
            Shape::Polygon(
                Polygon::from_points(&[Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.2), Vec2::new(0.3, 0.9)], 0.05).unwrap(),
            ),
            Shape::Circle(Circle::new(Vec2::new(0.1, -0.2), 0.4).unwrap()),
            Shape::Capsule(Capsule::new(Vec2::new(-0.4, 0.0), Vec2::new(0.4, 0.1), 0.2).unwrap()),
            Shape::Segment(Segment::new(Vec2::new(-0.6, -0.3), Vec2::new(0.7, 0.2)).unwrap()),
            // A chain piece with a convex vertex behind point1 and a concave one after point2.
            Shape::ChainSegment(crate::geometry::ChainSegment {
                ghost1: Vec2::new(-0.9, -1.0),
                segment: Segment::new(Vec2::new(-0.6, -0.3), Vec2::new(0.7, 0.2)).unwrap(),
                ghost2: Vec2::new(1.0, -0.8),
            }),
        ];
        let mut seen = 0;
        for a in &shapes {
            for b in &shapes {
                let ground = |s: &Shape| matches!(s, Shape::Segment(_) | Shape::ChainSegment(_));
                if ground(a) && ground(b) {
                    continue;
                }
                for k in 0..400 {
                    let t = k as f32;
                    let xf_a = Transform::new(Vec2::new(0.3 * (t * 0.37).sin(), 0.2), 0.1 * t);
                    let r = 0.8 + 1.6 * ((t * 0.61).sin() * 0.5 + 0.5);
                    let dir = Vec2::new((t * 0.23).cos(), (t * 0.23).sin());
                    let xf_b = Transform::new(xf_a.p + dir * r, -0.07 * t);
                    let (m, bound) = collide_bounded(a, xf_a, b, xf_b, 0.02, &Manifold::EMPTY);
                    if bound > 0.0 {
                        seen += 1;
                        assert_eq!(m.count, 0);
                        let d = distance(a, xf_a, b, xf_b);
                        assert!(bound <= d + 1e-5, "bound {bound} > distance {d} at k {k}");
                    }
                }
            }
        }
        assert!(seen > 2000, "only {seen} apart configurations");
    }
}
