//! Chain-segment contacts: a one-sided segment whose ghost vertices keep shapes from catching
//! on the internal vertices of a chain.
//!
//! Method (the Gauss-map rule of E. Catto, "Ghost collisions", box2d.org, 2020, as Box2D v3
//! applies it to chains; written here on top of this module's two-sided pair functions):
//! 1. One-sided: a shape whose centre (circle) or centroid (polygon, capsule) lies behind the
//!    piece, and behind each convex neighbour, touches nothing, unless the pair had a
//!    manifold last step: a shape the piece was holding that a squeeze pushed past its line
//!    (a capsule at the bottom of a spinning pile of 6 000 bodies, pressed by 20 N·s per
//!    step) is pushed back out along the piece's normal instead of being let go. A shape
//!    coming from behind has no manifold and passes, as in Box2D (which lets go of both).
//! 2. The two-sided manifold of the piece and the shape is computed as for a segment.
//! 3. Circle: a centre beyond an end of the piece that lies in the neighbour's region (it
//!    projects onto the neighbour's interior) is left to the neighbour.
//! 4. Polygon and capsule: the manifold's normal is classified against the cone of
//!    directions the piece may push in. The piece's own normal is always admitted. A normal
//!    that leans towards an end is admitted at a convex vertex while it stays within the
//!    neighbour's normal (beyond it, the neighbour owns the contact: skipped), and snapped to
//!    the piece's normal at a concave vertex (there, leaning normals can only come from the
//!    internal vertex, which is no surface). Snapping clips the shape's incident edge against
//!    the piece's face, as a reference face.
//!
//! Angular tolerances are Box2D's: a vertex is convex when the sine of its turn is at least
//! 0.01, and a normal may lean past the neighbour's by a sine of 0.01.

use super::capsule_circle::capsule_circle_local;
use super::polygon_polygon::{collide_polygons_local, incident_edge, LocalPoly};
use super::{clip_incident_edge, closest_on_segment, feature_id, LocalManifold, Manifold, KIND_CLIP_REF_A};
use crate::geometry::{Capsule, ChainSegment, Circle, Polygon};
use crate::math::{Transform, Vec2};

/// A vertex is convex (seen from the colliding side) when the chain turns away from that
/// side by a sine of at least this [-].
const CONVEX_SIN: f32 = 0.01;

/// A normal may lean past a convex neighbour's normal by this sine [-] and still be admitted.
const LEAN_SIN: f32 = 0.01;

/// Contact between chain piece `a` (placed by `xf_a`) and circle `b` (placed by `xf_b`).
pub(super) fn collide_chain_circle(
    a: &ChainSegment,
    xf_a: Transform,
    b: &Circle,
    xf_b: Transform,
    spec: f32,
    held: bool,
) -> (Manifold, f32) {
    let c = xf_a.inv_mul(xf_b).apply(b.center);
    let (p1, p2) = (a.segment.point1, a.segment.point2);
    let e = p2 - p1;
    let offset = e.right_perp().dot(c - p1);
    if offset < 0.0 {
        if !held {
            return (Manifold::EMPTY, 0.0);
        }
        // Pushed past the line while held: back out along the piece's normal.
        let n = a.normal();
        let (q, _) = closest_on_segment(c, p1, p2);
        let depth = offset * (1.0 / e.length().max(f32::MIN_POSITIVE));
        let mut m = LocalManifold::new(n);
        m.push((q + c - n * b.radius) * 0.5, depth - b.radius, 0, spec);
        return m.to_world(xf_a, xf_b);
    }
    let along = e.dot(c - p1);
    // Beyond an end, in the region of the neighbour's interior: the neighbour's contact.
    // The inequalities give a centre exactly over a shared vertex to one piece only.
    let neighbours = if along <= 0.0 {
        (p1 - a.ghost1).dot(c - p1) <= 0.0
    } else if along >= e.length_squared() {
        (a.ghost2 - p2).dot(c - p2) > 0.0
    } else {
        false
    };
    if neighbours {
        return (Manifold::EMPTY, 0.0);
    }
    capsule_circle_local(p1, p2, 0.0, c, b.radius, spec).to_world(xf_a, xf_b)
}

/// Contact between chain piece `a` (placed by `xf_a`) and polygon `b` (placed by `xf_b`);
/// `last_reference_b` as in `collide_polygons_local` (the sticky reference face).
pub(super) fn collide_chain_polygon(
    a: &ChainSegment,
    xf_a: Transform,
    b: &Polygon,
    xf_b: Transform,
    spec: f32,
    last_reference_b: Option<bool>,
    held: bool,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    let pb = LocalPoly::from_polygon(b, rel);
    chain_local(a, &pb, rel.apply(b.centroid()), spec, last_reference_b, held).to_world(xf_a, xf_b)
}

/// Contact between chain piece `a` (placed by `xf_a`) and capsule `b` (placed by `xf_b`):
/// the capsule is a 2-vertex polygon with its radius.
pub(super) fn collide_chain_capsule(
    a: &ChainSegment,
    xf_a: Transform,
    b: &Capsule,
    xf_b: Transform,
    spec: f32,
    held: bool,
) -> (Manifold, f32) {
    let rel = xf_a.inv_mul(xf_b);
    let (c1, c2) = (rel.apply(b.center1), rel.apply(b.center2));
    let pb = LocalPoly::from_segment(c1, c2, b.radius);
    chain_local(a, &pb, c1.lerp(c2, 0.5), spec, None, held).to_world(xf_a, xf_b)
}

/// What a two-sided normal becomes on a chain piece (step 4 of the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lean {
    Admit,
    Skip,
    Snap,
}

/// The piece's geometry in its frame: unit edge directions and normals of the piece and its
/// neighbours, and the convexity of its two vertices.
struct Piece {
    p1: Vec2,
    p2: Vec2,
    edge1: Vec2,
    normal0: Vec2,
    normal1: Vec2,
    normal2: Vec2,
    convex1: bool,
    convex2: bool,
}

impl Piece {
    fn new(a: &ChainSegment) -> Piece {
        let (p1, p2) = (a.segment.point1, a.segment.point2);
        let edge0 = (p1 - a.ghost1).normalize_or_zero();
        let edge1 = (p2 - p1).normalize_or_zero();
        let edge2 = (a.ghost2 - p2).normalize_or_zero();
        Piece {
            p1,
            p2,
            edge1,
            normal0: edge0.right_perp(),
            normal1: edge1.right_perp(),
            normal2: edge2.right_perp(),
            convex1: edge0.cross(edge1) >= CONVEX_SIN,
            convex2: edge1.cross(edge2) >= CONVEX_SIN,
        }
    }

    /// Whether `point` is behind the piece and behind each convex neighbour.
    fn behind(&self, point: Vec2) -> bool {
        let behind1 = self.normal1.dot(point - self.p1) < 0.0;
        let behind0 = !self.convex1 || self.normal0.dot(point - self.p1) < 0.0;
        let behind2 = !self.convex2 || self.normal2.dot(point - self.p2) < 0.0;
        behind1 && behind0 && behind2
    }

    /// Classifies the unit normal `n` (from the piece towards the shape).
    fn lean(&self, n: Vec2) -> Lean {
        // The piece's own normal (to a sine of LEAN_SIN): always a surface normal.
        if n.dot(self.normal1) > 0.0 && n.cross(self.normal1).abs() <= LEAN_SIN {
            return Lean::Admit;
        }
        if n.dot(self.normal1) < 0.0 {
            // Pushing to the back side: only the piece's face may hold the shape.
            return Lean::Snap;
        }
        if n.dot(self.edge1) <= 0.0 {
            // Leaning towards point1: admitted up to the previous piece's normal, which is
            // clockwise of normal1 at a convex vertex.
            match self.convex1 {
                true if n.cross(self.normal0) > LEAN_SIN => Lean::Skip,
                true => Lean::Admit,
                false => Lean::Snap,
            }
        } else {
            match self.convex2 {
                true if self.normal2.cross(n) > LEAN_SIN => Lean::Skip,
                true => Lean::Admit,
                false => Lean::Snap,
            }
        }
    }
}

/// Chain piece `a` against the convex shape `b` (in the piece's frame; `centroid` its
/// centroid). See the module documentation.
fn chain_local(
    a: &ChainSegment,
    b: &LocalPoly,
    centroid: Vec2,
    spec: f32,
    last_reference_b: Option<bool>,
    held: bool,
) -> LocalManifold {
    let piece = Piece::new(a);
    if piece.behind(centroid) {
        // Pushed past the piece while held: back out along its normal (step 1).
        return if held {
            clip_on_face(&piece, b, spec)
        } else {
            LocalManifold::default()
        };
    }
    let segment = LocalPoly::from_segment(piece.p1, piece.p2, 0.0);
    // An empty two-sided manifold keeps its bound: a one-sided piece touches less.
    let m = collide_polygons_local(&segment, b, spec, last_reference_b);
    if m.count == 0 {
        return m;
    }
    match piece.lean(m.normal) {
        Lean::Admit => m,
        Lean::Skip => LocalManifold::default(),
        Lean::Snap => clip_on_face(&piece, b, spec),
    }
}

/// The piece's face as the reference face against `b`'s incident edge (the edge whose
/// normal is most anti-parallel to the piece's normal), clipped to the piece's ends.
fn clip_on_face(piece: &Piece, b: &LocalPoly, spec: f32) -> LocalManifold {
    let n = piece.normal1;
    let inc = incident_edge(b, n);
    let (i21, i22) = (inc, (inc + 1) % b.count.max(1));
    let mut m = LocalManifold::new(n);
    clip_incident_edge(
        piece.p1,
        piece.p2,
        n,
        0.0,
        b.v[i21],
        b.v[i22],
        i21,
        i22,
        b.radius,
        spec,
        |p| {
            m.push(
                p.point,
                p.separation,
                feature_id(KIND_CLIP_REF_A, 0, p.incident_vertex),
                spec,
            );
        },
    );
    m
}

#[cfg(test)]
mod tests {
    use super::super::collide;
    use super::super::test_support::*;
    use crate::geometry::{Capsule, ChainSegment, Circle, Polygon, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    const SPEC: f32 = SPECULATIVE_DISTANCE;

    fn v(x: f32, y: f32) -> Vec2 {
        Vec2::new(x, y)
    }

    /// Flat ground y = 0 from x = 5 to x = −5 in pieces of 1 m (wound right to left, so the
    /// pieces collide upwards), as an open chain.
    fn flat_ground() -> Vec<Shape> {
        let points: Vec<Vec2> = (0..=10).map(|i| v(5.0 - i as f32, 0.0)).collect();
        ChainSegment::chain(&points, false)
            .unwrap()
            .into_iter()
            .map(Shape::ChainSegment)
            .collect()
    }

    fn all_contacts(ground: &[Shape], shape: &Shape, xf: Transform) -> Vec<super::Manifold> {
        ground
            .iter()
            .map(|g| collide(g, Transform::IDENTITY, shape, xf, SPEC))
            .filter(|m| m.count > 0)
            .collect()
    }

    #[test]
    fn chain_pieces_and_errors() {
        let square = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
        let lp = ChainSegment::chain(&square, true).unwrap();
        assert_eq!(lp.len(), 4);
        // Each piece's ghosts are its neighbours' far ends.
        assert_eq!(lp[0].ghost1, square[3]);
        assert_eq!(lp[0].ghost2, square[2]);
        assert_eq!(lp[3].segment.point2, square[0]);
        // A counter-clockwise loop faces outwards: piece 0 (bottom edge) faces down.
        assert_near_v(lp[0].normal(), v(0.0, -1.0), 1e-6);
        let open = ChainSegment::chain(&square, false).unwrap();
        assert_eq!(open.len(), 3);
        // Free ends: the ghost lies behind the piece (a 90° convex corner).
        assert_near_v(open[0].ghost1, v(0.0, 1.0), 1e-6);
        assert_near_v(open[2].ghost2, v(0.0, 0.0), 1e-6);
        use crate::geometry::GeometryError as E;
        assert_eq!(
            ChainSegment::chain(&square[..2], true),
            Err(E::TooFewPoints { needed: 3, got: 2 })
        );
        assert_eq!(
            ChainSegment::chain(&square[..1], false),
            Err(E::TooFewPoints { needed: 2, got: 1 })
        );
        assert!(matches!(
            ChainSegment::chain(&[v(0.0, 0.0), v(0.001, 0.0), v(1.0, 1.0)], true),
            Err(E::DegenerateSegment(_))
        ));
        // A loop whose last point repeats its first has a zero-length closing piece.
        assert!(matches!(
            ChainSegment::chain(&[v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 0.0)], true),
            Err(E::DegenerateSegment(_))
        ));
        assert_eq!(
            ChainSegment::chain(&[v(0.0, 0.0), v(f32::NAN, 0.0)], false),
            Err(E::NonFinite("points"))
        );
    }

    /// The ghost-collision case: a box sliding over the joint of two collinear pieces, sunk
    /// 2 mm (resting contacts run a little below the slop). Against separate segments the
    /// next segment's end vertex can give a sideways normal that stops the box; on a chain
    /// every contact normal must be the ground's (0, 1), to 1e-4 (f32 rounding of the clip).
    #[test]
    fn a_box_crossing_a_joint_sees_only_the_ground_normal() {
        let ground = flat_ground();
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        for k in 0..41 {
            // Box corners pass x = 0, a joint, at a range of offsets and tiny tilts.
            let x = -1.0 + 0.05 * k as f32;
            let tilt = 0.002 * ((k % 5) as f32 - 2.0);
            let xf = Transform::new(v(x, 0.498), tilt);
            let ms = all_contacts(&ground, &b, xf);
            assert!(!ms.is_empty(), "no contact at x {x}");
            for m in &ms {
                assert!(m.normal.y > 0.9999, "normal {:?} at x {x}, tilt {tilt}", m.normal);
                check_manifold(m, Transform::IDENTITY, xf);
            }
        }
        // The two-sided reference: separate segments give a sideways normal for a box whose
        // corner has sunk below the next segment's end (that is what the chain removes).
        let s1 = Shape::Segment(crate::geometry::Segment::new(v(1.0, 0.0), v(0.0, 0.0)).unwrap());
        let xf = Transform::new(v(1.5 - 0.002, 0.497), 0.0);
        let m = collide(&s1, Transform::IDENTITY, &b, xf, SPEC);
        assert!(m.count > 0 && m.normal.y < 0.5, "segment normal {:?}", m.normal);
    }

    #[test]
    fn one_sided() {
        let ground = flat_ground();
        let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let cap = Shape::Capsule(Capsule::new(v(-0.5, 0.0), v(0.5, 0.0), 0.25).unwrap());
        for s in [&ball, &b, &cap] {
            // Above, overlapping by 1 cm: contact pushing up.
            let above = Transform::new(v(0.3, if matches!(s, Shape::Capsule(_)) { 0.24 } else { 0.49 }), 0.0);
            let ms = all_contacts(&ground, s, above);
            assert!(!ms.is_empty());
            for m in &ms {
                assert_near_v(m.normal, v(0.0, 1.0), 1e-5);
                for p in m.active_points() {
                    assert!((p.separation + 0.01).abs() < 1e-4, "{}", p.separation);
                }
            }
            // The same overlap from below: the chain lets it through.
            let below = Transform::new(v(0.3, -above.p.y), 0.0);
            assert!(all_contacts(&ground, s, below).is_empty());
        }
    }

    /// Box2D's convention of one contact per convex region: a ball over a shared vertex is
    /// the contact of one piece only; a ball past a convex corner (a step down) is held by
    /// the corner vertex along the centre direction.
    #[test]
    fn circle_regions() {
        let ground = flat_ground();
        let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
        // Over shared vertices (x = −1, 0, 2) and next to one: one contact each time.
        for x in [-1.0, 0.0, 2.0, 0.999, 1.001] {
            let ms = all_contacts(&ground, &ball, Transform::new(v(x, 0.495), 0.0));
            assert_eq!(ms.len(), 1, "x {x}");
            assert_near_v(ms[0].normal, v(0.0, 1.0), 1e-6);
        }
        // A step: ground at y = 0 for x ≥ 0 (points right to left), then down to y = −1.
        let step = ChainSegment::chain(&[v(3.0, 0.0), v(0.0, 0.0), v(0.0, -1.0), v(-3.0, -1.0)], false).unwrap();
        let step: Vec<Shape> = step.into_iter().map(Shape::ChainSegment).collect();
        let d = v(-1.0, 1.0).normalize_or_zero();
        let xf = Transform::new(d * 0.49, 0.0);
        let ms = all_contacts(&step, &ball, xf);
        assert_eq!(ms.len(), 2, "the corner vertex is shared by both pieces' regions");
        for m in &ms {
            assert_near_v(m.normal, d, 1e-5);
        }
    }

    /// In a concave corner (a floor meeting a wall) a box pressed into the corner gets the
    /// floor's and the wall's normals only, never a diagonal one from the internal vertex.
    #[test]
    fn concave_corner_snaps_to_the_faces() {
        // Floor y = 0 from x = 3 to the corner, then the wall x = 0 up: the pieces face up
        // and right, into the quadrant x > 0, y > 0.
        let corner = ChainSegment::chain(&[v(3.0, 0.0), v(0.0, 0.0), v(0.0, 3.0)], false).unwrap();
        assert_near_v(corner[1].normal(), v(1.0, 0.0), 1e-6);
        let corner: Vec<Shape> = corner.into_iter().map(Shape::ChainSegment).collect();
        let b = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        for tilt in [0.0f32, 0.3, 0.7] {
            // Rotated box pushed 1 cm into the corner along the diagonal.
            let reach = 0.5 * (tilt.cos() + tilt.sin());
            let xf = Transform::new(v(reach - 0.01, reach - 0.01), tilt);
            let ms = all_contacts(&corner, &b, xf);
            assert!(!ms.is_empty());
            for m in &ms {
                let axis = m.normal.x.abs() > 0.9999 || m.normal.y.abs() > 0.9999;
                assert!(axis, "normal {:?} at tilt {tilt}", m.normal);
                assert!(m.normal.x >= -1e-6 && m.normal.y >= -1e-6);
            }
        }
    }

    /// Either order of a pair gives the same contact (normal negated, same points and
    /// separations): checked for each shape kind at poses over a piece and its vertices.
    #[test]
    fn both_orders_agree() {
        let ground = flat_ground();
        let shapes = [
            Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()),
            Shape::Polygon(Polygon::new_box(0.5, 0.3).unwrap()),
            Shape::Capsule(Capsule::new(v(-0.5, 0.0), v(0.5, 0.0), 0.25).unwrap()),
        ];
        let mut seen = 0;
        for s in &shapes {
            for k in 0..60 {
                let t = k as f32;
                let xf = Transform::new(v(-1.0 + 0.05 * t, 0.3 + 0.01 * (t * 0.7).sin()), 0.4 * (t * 0.3).sin());
                for g in &ground {
                    if collide(g, Transform::IDENTITY, s, xf, SPEC).count > 0 {
                        seen += 1;
                    }
                    assert_symmetric(g, Transform::IDENTITY, s, xf, &format!("{s:?} at {xf:?}"));
                }
            }
        }
        assert!(seen > 100, "only {seen} contacts");
    }

    /// A shape the piece held last step (its pair had a manifold) whose centroid a squeeze
    /// pushed 2 cm past the piece is pushed back along the piece's normal, with the full
    /// depth as separation (radius + 2 cm, or the box's half height + 2 cm); the same pose
    /// reached from behind (no manifold last step) touches nothing.
    #[test]
    fn a_held_shape_pushed_past_the_line_is_pushed_back() {
        use super::super::collide_after;
        let ground = flat_ground();
        let piece = &ground[5]; // x from 0 to −1
        let held = collide(
            piece,
            Transform::IDENTITY,
            &Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()),
            Transform::new(v(-0.5, 0.49), 0.0),
            SPEC,
        );
        assert_eq!(held.count, 1);
        let shapes = [
            (Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()), 0.5),
            (Shape::Polygon(Polygon::new_box(0.3, 0.2).unwrap()), 0.2),
            (
                Shape::Capsule(Capsule::new(v(-0.3, 0.0), v(0.3, 0.0), 0.25).unwrap()),
                0.25,
            ),
        ];
        for (s, half) in &shapes {
            let xf = Transform::new(v(-0.5, -0.02), 0.0);
            let m = collide_after(piece, Transform::IDENTITY, s, xf, SPEC, &held);
            assert!(m.count > 0, "{s:?}");
            assert_near_v(m.normal, v(0.0, 1.0), 1e-6);
            for p in m.active_points() {
                assert!((p.separation + half + 0.02).abs() < 1e-5, "{s:?}: {}", p.separation);
            }
            assert_eq!(collide(piece, Transform::IDENTITY, s, xf, SPEC).count, 0, "{s:?}");
        }
    }
}
