//! Polygon–polygon contact (also used for polygon–capsule and polygon–segment, with the
//! capsule or segment as a 2-vertex polygon).
//!
//! Method (separating-axis theorem + reference-face clipping):
//! 1. For each edge normal of A, the separation of B is `min_j n·(b_j − a_i)`; the largest over
//!    A's edges is `sep_a` (likewise `sep_b`). For convex polygons the larger of the two is the
//!    core separation when the closest features are a vertex and an edge, and a lower bound on
//!    the core distance otherwise, so `max > spec + r_a + r_b` means no contact.
//! 2. The reference face is A's best edge unless B's is better by more than
//!    `0.1 · LINEAR_SLOP`; for a pair whose last manifold clipped against one of two nearly
//!    parallel faces, that face stays unless the other is better by more than
//!    `LINEAR_SLOP` (so a box resting on a swaying box keeps its face, and its ids).
//!    The incident edge is the edge of the other polygon whose normal is most anti-parallel to
//!    the reference normal.
//! 3. If the cores are apart (`max(sep) > 0.1 · LINEAR_SLOP`) and the closest points of the
//!    reference and incident edges are a vertex of each, the contact is that vertex pair
//!    (normal along the vertex–vertex direction, separation = distance − radii); this gives
//!    sane speculative contacts near corners and the exact rounded-corner contact.
//! 4. Otherwise the incident edge is clipped to the reference edge's side planes and each end
//!    closer than `spec` becomes a point (see `clip_incident_edge`). If the incident edge lies
//!    wholly outside the side planes (possible only for 2-vertex polygons), the closest points
//!    of the two edges give one point instead.

use super::{
    clip_incident_edge, feature_id, segment_closest, LocalManifold, Manifold, CORE_TOUCH, KIND_CLIP_REF_A,
    KIND_CLIP_REF_B, KIND_VERTEX_VERTEX,
};
use crate::geometry::{Polygon, LINEAR_SLOP, MAX_POLYGON_VERTICES};
use crate::math::wide::{apply_lanes, join_xy, split_xy, transpose, F4};
use crate::math::{Transform, Vec2};

/// How much better [m] the other face must be before a pair whose last manifold clipped
/// against one face changes to the other. Two loaded boxes sway by a few mrad, which over
/// half a metre changes which face separates more by over a millimetre; each swap changes
/// every feature id, and the points lose their warm start, friction state and preload
/// (in the 100-row benchmark pyramid, ~220 contacts per step with the 0.1·slop rule alone).
const STICKY_REFERENCE: f32 = LINEAR_SLOP;

/// Faces count as parallel for [`STICKY_REFERENCE`] within about 2.6° (cos = 0.999).
const STICKY_PARALLEL_COS: f32 = 0.999;

/// A polygon (or 2-vertex "polygon" for a capsule/segment) expressed in A's frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct LocalPoly {
    pub v: [Vec2; MAX_POLYGON_VERTICES],
    pub n: [Vec2; MAX_POLYGON_VERTICES],
    pub count: usize,
    pub radius: f32,
}

impl LocalPoly {
    /// `p` moved by `xf`. The fixed arrays are transformed four slots at a time (lanes of
    /// x and of y, each lane the scalar expression in its order, so the scalar bits):
    /// all eight slots of a polygon of more than four vertices, the first four of a
    /// smaller one (the others left zero, half the work for every box). No result depends
    /// on a slot past `count`: [`max_separation`] pads with vertex 0 or drops the
    /// separations of edges past the count, and the other users index below it.
    ///
    /// The slots are read from the polygon itself and written whole: transforming a copy
    /// just written (`of_polygon` then a loop over `count`) loaded 16 bytes across two
    /// 8-byte stores still in flight, a store-forwarding stall that took 58 % of this
    /// function's samples (tumbler: 1.2 % of the step). One slot at a time, the transform
    /// was 60-110 instructions a pair of polygons more (tumbler, 200 steps: collide
    /// −3.5 %, 4 interleaved pairs).
    #[inline(always)]
    pub fn from_polygon(p: &Polygon, xf: Transform) -> LocalPoly {
        let count = p.count();
        let (c, s) = (F4::splat(xf.q.c), F4::splat(xf.q.s));
        let t = (F4::splat(xf.p.x), F4::splat(xf.p.y));
        // Four slots at a time, each lane `Transform::apply` (vertices, `apply_lanes`) or
        // `Rot::rotate` (normals) in its order: the scalar bits. (`first` is 0 or 4; the
        // modulo only spares the bounds checks.)
        let moved = |q: &[Vec2; MAX_POLYGON_VERTICES], first: usize, shift: bool| {
            let (x, y) = split_xy(core::array::from_fn(|k| q[(first + k) % MAX_POLYGON_VERTICES]));
            let (mx, my) = if shift {
                apply_lanes((c, s), t, (x, y))
            } else {
                (c * x - s * y, s * x + c * y)
            };
            join_xy(mx, my)
        };
        let (v, n) = (&p.vertices, &p.normals);
        let z = [Vec2::ZERO; 4];
        let (v_hi, n_hi) = if count <= 4 {
            (z, z)
        } else {
            (moved(v, 4, true), moved(n, 4, false))
        };
        let (v_lo, n_lo) = (moved(v, 0, true), moved(n, 0, false));
        let join = |lo: [Vec2; 4], hi: [Vec2; 4]| core::array::from_fn(|k| if k < 4 { lo[k] } else { hi[k - 4] });
        LocalPoly {
            v: join(v_lo, v_hi),
            n: join(n_lo, n_hi),
            count,
            radius: p.radius(),
        }
    }

    /// `p` in its own frame (a copy: [`LocalPoly::from_polygon`] with the identity
    /// would still do every multiplication).
    pub fn of_polygon(p: &Polygon) -> LocalPoly {
        LocalPoly {
            v: p.vertices,
            n: p.normals,
            count: p.count(),
            radius: p.radius(),
        }
    }

    /// The segment `p1`–`p2` (already in the target frame) grown by `radius`: vertices
    /// `[p1, p2]`, edge 0 is `p1 → p2` with normal `right_perp`, edge 1 is `p2 → p1`.
    pub fn from_segment(p1: Vec2, p2: Vec2, radius: f32) -> LocalPoly {
        let n = (p2 - p1).right_perp().try_normalize().unwrap_or(Vec2::Y);
        let mut out = LocalPoly {
            v: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            n: [Vec2::ZERO; MAX_POLYGON_VERTICES],
            count: 2,
            radius,
        };
        out.v[0] = p1;
        out.v[1] = p2;
        out.n[0] = n;
        out.n[1] = -n;
        out
    }
}

/// Edge of `p1` with the largest separation of `p2` from it, and that separation [m]:
/// [`max_separation_4x4`] for a box against a polygon of at most four edges, otherwise
/// [`max_separation_rows`] (one edge at a time, `p2`'s vertices as lanes). Both give the
/// bits of the scalar reference `max_separation_of` (each edge's separations from all of
/// `p2`'s vertices, `p2` padded with its first vertex, which changes no minimum, reduced
/// by a tree of plain comparisons; a loop of NaN-aware `f32::min`, five instructions per
/// vertex, had taken 60 % of the polygon collision).
fn max_separation(p1: &LocalPoly, p2: &LocalPoly) -> (usize, f32) {
    if p2.count == 4 && p1.count <= 4 {
        return max_separation_4x4(p1, p2);
    }
    // At most four vertices: four separations per edge (the padded vertex 0 changes no
    // minimum).
    if p2.count <= 4 {
        max_separation_rows::<false>(p1, p2)
    } else {
        max_separation_rows::<true>(p1, p2)
    }
}

/// [`max_separation`] one edge of `p1` at a time, with `p2`'s vertices as lanes: its
/// first four (padded with vertex 0), and with `WIDE` its next four as a second group.
/// Each edge's separations are one or two lane-wise expressions (`n · (p2.v[j] − v)`, as
/// `Vec2::dot`) and its minimum the tree of the scalar reference
/// (`max_separation_of`): the same bits. For the junkyard's pentagons this takes 218
/// instructions a call; the scalar eight-slot path took 335, computing the eight
/// separations of an edge one at a time (junkyard, 300 steps: 17.78 → 17.49 G
/// instructions).
#[inline(always)]
fn max_separation_rows<const WIDE: bool>(p1: &LocalPoly, p2: &LocalPoly) -> (usize, f32) {
    let vertex = |j: usize| p2.v[if j < p2.count { j } else { 0 }];
    let (x0, y0) = split_xy([vertex(0), vertex(1), vertex(2), vertex(3)]);
    let (x1, y1) = if WIDE {
        split_xy([vertex(4), vertex(5), vertex(6), vertex(7)])
    } else {
        (x0, y0)
    };
    let lesser = |a: f32, b: f32| if b < a { b } else { a };
    let mut best_edge = 0;
    let mut best = f32::MIN;
    for i in 0..p1.count.min(MAX_POLYGON_VERTICES) {
        let (n, v) = (p1.n[i], p1.v[i]);
        let (nx, ny, vx, vy) = (F4::splat(n.x), F4::splat(n.y), F4::splat(v.x), F4::splat(v.y));
        let d = nx * (x0 - vx) + ny * (y0 - vy);
        // Lane j: the reference's `lesser(d[j], d[j + 4])` (`lesser(a, b)` is `b.min(a)`).
        let half = if WIDE {
            (nx * (x1 - vx) + ny * (y1 - vy)).min(d)
        } else {
            d
        };
        let si = lesser(lesser(half[0], half[1]), lesser(half[2], half[3]));
        if si > best {
            best = si;
            best_edge = i;
        }
    }
    (best_edge, best)
}

/// [`max_separation`] of two polygons of at most four edges and exactly four vertices
/// (two boxes, the common pair): the sixteen separations as four lane vectors, one per
/// edge of `p1` (`p2`'s coordinates deinterleaved once), transposed so that one tree of
/// three lane-wise `lesser`s gives every edge's minimum at once. Every lane is the
/// scalar path's expression and its tree in its order, so the result is the same bits
/// (tumbler: the scalar path took 166 instructions a call, most of them building the
/// padded vertex arrays and reducing each edge alone).
#[inline(always)]
fn max_separation_4x4(p1: &LocalPoly, p2: &LocalPoly) -> (usize, f32) {
    let (xs, ys) = split_xy([p2.v[0], p2.v[1], p2.v[2], p2.v[3]]);
    let rows: [F4; 4] = core::array::from_fn(|i| {
        let (n, v) = (p1.n[i], p1.v[i]);
        // n · (p2.v[j] − v), the same expression as `Vec2::dot`.
        F4::splat(n.x) * (xs - F4::splat(v.x)) + F4::splat(n.y) * (ys - F4::splat(v.y))
    });
    // Lane i of column j: vertex j's separation from edge i.
    let [d0, d1, d2, d3] = transpose(rows);
    // The scalar `lesser(a, b)` (`b < a ? b : a`) is `b.min(a)`, one `minps`.
    let lesser = |a: F4, b: F4| b.min(a);
    let si = lesser(lesser(d0, d1), lesser(d2, d3));
    let mut best_edge = 0;
    let mut best = f32::MIN;
    for (i, &s) in si.iter().enumerate().take(p1.count) {
        if s > best {
            best = s;
            best_edge = i;
        }
    }
    (best_edge, best)
}

/// [`max_separation`] over the first `N` (4 or 8) vertex slots of `p2`, one edge at a
/// time: the scalar reference the wide paths are tested against.
#[cfg(test)]
fn max_separation_of<const N: usize>(p1: &LocalPoly, p2: &LocalPoly) -> (usize, f32) {
    let vertex = |j: usize| p2.v[if j < p2.count { j } else { 0 }];
    let xs: [f32; N] = core::array::from_fn(|j| vertex(j).x);
    let ys: [f32; N] = core::array::from_fn(|j| vertex(j).y);
    let lesser = |a: f32, b: f32| if b < a { b } else { a };
    let mut best_edge = 0;
    let mut best = f32::MIN;
    for i in 0..p1.count {
        let (n, v) = (p1.n[i], p1.v[i]);
        // n · (p2.v[j] − v), the same expression as `Vec2::dot`.
        let d: [f32; N] = core::array::from_fn(|j| n.x * (xs[j] - v.x) + n.y * (ys[j] - v.y));
        let si = if N == 4 {
            lesser(lesser(d[0], d[1]), lesser(d[2], d[3]))
        } else {
            let half: [f32; 4] = core::array::from_fn(|j| lesser(d[j], d[(j + 4) % N]));
            lesser(lesser(half[0], half[1]), lesser(half[2], half[3]))
        };
        if si > best {
            best = si;
            best_edge = i;
        }
    }
    (best_edge, best)
}

/// The edge of `p` whose normal is most anti-parallel to the reference normal `n` (the
/// incident edge of a reference face with normal `n`).
pub(super) fn incident_edge(p: &LocalPoly, n: Vec2) -> usize {
    let mut edge = 0;
    let mut min_dot = f32::MAX;
    for j in 0..p.count {
        let d = n.dot(p.n[j]);
        if d < min_dot {
            min_dot = d;
            edge = j;
        }
    }
    edge
}

/// Polygon A against polygon B, both in A's frame. See the module documentation;
/// `last_reference_b` is the face the pair's last manifold clipped against (step 2).
pub(super) fn collide_polygons_local(
    a: &LocalPoly,
    b: &LocalPoly,
    spec: f32,
    last_reference_b: Option<bool>,
) -> LocalManifold {
    polygons_local(a, b, spec, last_reference_b)
}

/// [`collide_polygons_local`]'s body, inlined into the polygon pair's hot path
/// ([`collide_polygons_into`]), whose manifold is then no longer returned through memory on
/// its way to the contact: returned so, its normal was read back by a 16-byte load over the
/// narrower stores that made it, which cannot be forwarded (a seventh of the samples of
/// `collide_polygons_into` in the tumbler).
#[inline(always)]
fn polygons_local(a: &LocalPoly, b: &LocalPoly, spec: f32, last_reference_b: Option<bool>) -> LocalManifold {
    let empty = LocalManifold::default();
    if a.count < 2 || b.count < 2 || a.count > MAX_POLYGON_VERTICES || b.count > MAX_POLYGON_VERTICES {
        return empty;
    }
    let radius = a.radius + b.radius;
    let (edge_a, sep_a) = max_separation(a, b);
    let (edge_b, sep_b) = max_separation(b, a);
    if !(sep_a <= spec + radius && sep_b <= spec + radius) {
        // A separating axis: the cores are at least this far apart (NaN gives no bound).
        let bound = sep_a.max(sep_b) - radius;
        return LocalManifold {
            bound: if bound > 0.0 { bound } else { 0.0 },
            ..empty
        };
    }

    // Keeping the last reference only makes sense for two nearly parallel faces (either
    // gives the same points); otherwise the better face gives the right normal.
    let parallel = a.n[edge_a].dot(b.n[edge_b]) < -STICKY_PARALLEL_COS;
    let flip = match last_reference_b.filter(|_| parallel) {
        None => sep_b > sep_a + 0.1 * LINEAR_SLOP,
        Some(false) => sep_b > sep_a + STICKY_REFERENCE,
        Some(true) => sep_b + STICKY_REFERENCE >= sep_a,
    };
    let (rf, inc, ref_edge) = if flip { (b, a, edge_b) } else { (a, b, edge_a) };
    let n = rf.n[ref_edge];

    let inc_edge = incident_edge(inc, n);

    let i11 = ref_edge;
    let i12 = (ref_edge + 1) % rf.count;
    let i21 = inc_edge;
    let i22 = (inc_edge + 1) % inc.count;
    let (v11, v12) = (rf.v[i11], rf.v[i12]);
    let (v21, v22) = (inc.v[i21], inc.v[i22]);

    // Normal from A to B given a direction from the reference towards the incident polygon.
    let a_to_b = |d: Vec2| if flip { -d } else { d };
    // Id of a pair (reference vertex or edge index, incident vertex index).
    let pair_id = |kind_ref_a: u16, kind_ref_b: u16, ref_feature: usize, inc_vertex: usize| {
        if flip {
            feature_id(kind_ref_b, inc_vertex, ref_feature)
        } else {
            feature_id(kind_ref_a, ref_feature, inc_vertex)
        }
    };

    let closest_fallback = |only_vertices: bool| -> Option<LocalManifold> {
        let c = segment_closest(v11, v12, v21, v22);
        let at_vertex = |f: f32| f == 0.0 || f == 1.0;
        if only_vertices && !(at_vertex(c.fa) && at_vertex(c.fb)) {
            return None;
        }
        let delta = c.b - c.a;
        let dist = delta.length();
        let (dir, core_sep) = if dist > CORE_TOUCH {
            (delta * (1.0 / dist), dist)
        } else {
            (n, n.dot(delta))
        };
        let mut m = LocalManifold::new(a_to_b(dir));
        let separation = core_sep - radius;
        // Reference surface at c.a + r_ref·dir, incident surface at c.b − r_inc·dir.
        let point = (c.a + dir * rf.radius + c.b - dir * inc.radius) * 0.5;
        let rv = if c.fa < 0.5 { i11 } else { i12 };
        let iv = if c.fb < 0.5 { i21 } else { i22 };
        let id = pair_id(KIND_VERTEX_VERTEX, KIND_VERTEX_VERTEX, rv, iv);
        m.push(point, separation, id, spec);
        Some(m)
    };

    if sep_a.max(sep_b) > CORE_TOUCH {
        if let Some(m) = closest_fallback(true) {
            return m;
        }
    }

    let mut m = LocalManifold::new(a_to_b(n));
    let clipped = clip_incident_edge(v11, v12, n, rf.radius, v21, v22, i21, i22, inc.radius, spec, |p| {
        let id = pair_id(KIND_CLIP_REF_A, KIND_CLIP_REF_B, ref_edge, p.incident_vertex);
        m.push(p.point, p.separation, id, spec);
    });
    if clipped {
        m
    } else {
        closest_fallback(false).unwrap_or(empty)
    }
}

/// Contact between polygons `a` (placed by `xf_a`) and `b` (placed by `xf_b`), written
/// into `out` in place (see `LocalManifold::write_world`), and the separation bound of an
/// empty manifold (see `collide_bounded`); `last_reference_b` as in
/// [`collide_polygons_local`].
pub(super) fn collide_polygons_into(
    a: &Polygon,
    xf_a: Transform,
    b: &Polygon,
    xf_b: Transform,
    spec: f32,
    last_reference_b: Option<bool>,
    out: &mut Manifold,
) -> f32 {
    let la = LocalPoly::of_polygon(a);
    let lb = LocalPoly::from_polygon(b, xf_a.inv_mul(xf_b));
    polygons_local(&la, &lb, spec, last_reference_b).write_world(xf_a, xf_b, out)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{collide, Manifold};
    use super::{max_separation, max_separation_4x4, max_separation_of, LocalPoly};
    use crate::geometry::MAX_POLYGON_VERTICES;
    use crate::geometry::{Polygon, Shape, SPECULATIVE_DISTANCE};
    use crate::math::{Transform, Vec2};

    const SPEC: f32 = SPECULATIVE_DISTANCE;

    fn boxed(hx: f32, hy: f32) -> Shape {
        Shape::Polygon(Polygon::new_box(hx, hy).unwrap())
    }

    fn xf(x: f32, y: f32, a: f32) -> Transform {
        Transform::new(Vec2::new(x, y), a)
    }

    fn xs(m: &Manifold) -> Vec<f32> {
        let mut v: Vec<f32> = m.active_points().iter().map(|p| p.point.x).collect();
        v.sort_by(f32::total_cmp);
        v
    }

    /// Asserts that `got` is the scalar reference's (edge, separation), bit for bit.
    fn same_separation(got: (usize, f32), p1: &LocalPoly, p2: &LocalPoly, what: &str) {
        let want = max_separation_of::<MAX_POLYGON_VERTICES>(p1, p2);
        assert_eq!(
            (got.0, got.1.to_bits()),
            (want.0, want.1.to_bits()),
            "{what}: {got:?} vs {want:?}"
        );
    }

    /// `max_separation_4x4` gives the bits the eight-wide path gives (the same
    /// expressions and minimum tree, every edge of `p1`): boxes of every size against
    /// boxes, triangles and segments as `p1`, at 200 poses, and an exact tie of two
    /// edges, where the first must win.
    #[test]
    fn four_by_four_separations_match_the_eight_wide_path() {
        let mut next = uniform(12345);
        let tri = Polygon::from_points(&[Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), Vec2::new(0.0, 0.7)], 0.0).unwrap();
        let b = LocalPoly::of_polygon(&Polygon::new_box(0.5, 0.3).unwrap());
        let check = |p1: &LocalPoly, p2: &LocalPoly| {
            same_separation(max_separation_4x4(p1, p2), p1, p2, "4x4");
        };
        for _ in 0..200 {
            let xf = Transform::new(Vec2::new(2.0 * next() - 1.0, 2.0 * next() - 1.0), 6.3 * next());
            let other = Polygon::new_box(0.1 + next(), 0.1 + next()).unwrap();
            let moved = LocalPoly::from_polygon(&other, xf);
            check(&b, &moved);
            check(&moved, &b);
            check(&LocalPoly::from_polygon(&tri, xf), &b);
            check(&LocalPoly::from_segment(xf.p, xf.apply(Vec2::new(1.0, 0.2)), 0.05), &b);
        }
        // A tie: a square off the corner of a box, as far (0.25 m, exactly) from its right
        // face as from its top face; the first of the two edges must win.
        let base = LocalPoly::of_polygon(&Polygon::new_box(0.5, 0.25).unwrap());
        let square = Polygon::new_box(0.25, 0.25).unwrap();
        let corner = LocalPoly::from_polygon(&square, Transform::new(Vec2::new(1.0, 0.75), 0.0));
        let mut tied = Vec::new();
        let mut best = f32::MIN;
        for i in 0..4 {
            let d = (0..4)
                .map(|j| base.n[i].dot(corner.v[j] - base.v[i]))
                .fold(f32::MAX, f32::min);
            if d > best {
                (best, tied) = (d, vec![i]);
            } else if d == best {
                tied.push(i);
            }
        }
        assert_eq!(tied.len(), 2, "the fixture ties two edges");
        check(&base, &corner);
        assert_eq!(max_separation_4x4(&base, &corner).0, tied[0]);
    }

    /// `max_separation` gives the bits of the scalar reference for every pair of vertex
    /// counts it dispatches on (a polygon of 2 to 8 vertices against one of 2 to 8):
    /// random convex polygons (the hull of points on a circle) at random poses.
    #[test]
    fn lane_separations_match_the_scalar_reference() {
        let mut next = uniform(777);
        let polygon = |count: usize, xf: Transform, next: &mut dyn FnMut() -> f32| -> LocalPoly {
            if count == 2 {
                return LocalPoly::from_segment(xf.p, xf.apply(Vec2::new(0.3 + next(), 0.2)), 0.05);
            }
            // Points on one circle, each in its own sector, so the hull keeps them all.
            let radius = 0.2 + next();
            let points: Vec<Vec2> = (0..count)
                .map(|k| {
                    let angle = (k as f32 + 0.2 + 0.6 * next()) * core::f32::consts::TAU / count as f32;
                    Vec2::new(angle.cos(), angle.sin()) * radius
                })
                .collect();
            let p = Polygon::from_points(&points, 0.0).unwrap();
            assert_eq!(p.count(), count, "the fixture keeps every point");
            LocalPoly::from_polygon(&p, xf)
        };
        for _ in 0..40 {
            for c1 in 2..=MAX_POLYGON_VERTICES {
                for c2 in 2..=MAX_POLYGON_VERTICES {
                    let p1 = polygon(c1, Transform::new(Vec2::ZERO, 6.3 * next()), &mut next);
                    let at = Vec2::new(2.0 * next() - 1.0, 2.0 * next() - 1.0);
                    let mut p2 = polygon(c2, Transform::new(at, 6.3 * next()), &mut next);
                    // Slots past the count hold a far corner (each of the four in turn), so
                    // a path that read them instead of padding with vertex 0 would find a
                    // much smaller separation for some edge.
                    for corner in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
                        for slot in &mut p2.v[c2..] {
                            *slot = Vec2::new(corner.0, corner.1) * 1.0e6;
                        }
                        same_separation(max_separation(&p1, &p2), &p1, &p2, &format!("{c1} vs {c2}"));
                    }
                }
            }
        }
    }

    /// `LocalPoly::from_polygon` moves every slot it keeps as `Transform::apply` (vertices)
    /// and `Rot::rotate` (normals) do, bit for bit, and leaves the slots of a polygon of at
    /// most four vertices past four zero.
    #[test]
    fn moved_polygon_has_the_scalar_bits() {
        for count in 3..=MAX_POLYGON_VERTICES {
            let points: Vec<Vec2> = (0..count)
                .map(|k| {
                    let angle = (k as f32 + 0.37) * core::f32::consts::TAU / count as f32;
                    Vec2::new(0.7 * angle.cos() + 0.1, 0.7 * angle.sin() - 0.2)
                })
                .collect();
            let p = Polygon::from_points(&points, 0.01).unwrap();
            let xf = Transform::new(Vec2::new(1.25, -3.5), 0.9 + count as f32);
            let moved = LocalPoly::from_polygon(&p, xf);
            assert_eq!(moved.count, count);
            let kept = if count <= 4 { 4 } else { MAX_POLYGON_VERTICES };
            for k in 0..MAX_POLYGON_VERTICES {
                let (v, n) = if k < kept {
                    (xf.apply(p.vertices[k]), xf.q.rotate(p.normals[k]))
                } else {
                    (Vec2::ZERO, Vec2::ZERO)
                };
                let bits = |w: Vec2| (w.x.to_bits(), w.y.to_bits());
                assert_eq!(
                    (bits(moved.v[k]), bits(moved.n[k])),
                    (bits(v), bits(n)),
                    "{count} slot {k}"
                );
            }
        }
    }

    #[test]
    fn unit_box_on_ground_box() {
        let ground = boxed(50.0, 1.0);
        let b = boxed(0.5, 0.5);
        let m = collide(&ground, xf(0.0, 0.0, 0.0), &b, xf(3.0, 1.5, 0.0), SPEC);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let x = xs(&m);
        assert!((x[0] - 2.5).abs() < 1e-5 && (x[1] - 3.5).abs() < 1e-5, "{x:?}");
        for p in m.active_points() {
            assert!(p.separation.abs() < 1e-5);
            assert!((p.point.y - 1.0).abs() < 1e-5);
        }
        check_manifold(&m, xf(0.0, 0.0, 0.0), xf(3.0, 1.5, 0.0));
        // Same thing with the box as A: normal points down.
        let m = collide(&b, xf(3.0, 1.5, 0.0), &ground, xf(0.0, 0.0, 0.0), SPEC);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, -1.0), 1e-6);
        let x = xs(&m);
        assert!((x[0] - 2.5).abs() < 1e-5 && (x[1] - 3.5).abs() < 1e-5, "{x:?}");
    }

    #[test]
    fn box_on_box_overlap_and_speculative() {
        let a = boxed(0.5, 0.5);
        // 1 cm overlap.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(0.2, 0.99, 0.0), SPEC);
        assert_eq!(m.count, 2);
        for p in m.active_points() {
            assert!((p.separation + 0.01).abs() < 1e-5);
            // Midway between the surfaces y = 0.5 and y = 0.49.
            assert!((p.point.y - 0.495).abs() < 1e-5);
        }
        assert_eq!(xs(&m).len(), 2);
        let x = xs(&m);
        assert!((x[0] + 0.3).abs() < 1e-5 && (x[1] - 0.5).abs() < 1e-5, "{x:?}");
        // 1 cm gap: speculative points with positive separation.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(0.2, 1.01, 0.0), SPEC);
        assert_eq!(m.count, 2);
        for p in m.active_points() {
            assert!((p.separation - 0.01).abs() < 1e-5);
        }
        // Beyond the speculative distance: nothing.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(0.2, 1.0 + 1.5 * SPEC, 0.0), SPEC);
        assert_eq!(m.count, 0);
        // A larger speculative distance keeps them.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(0.2, 1.0 + 1.5 * SPEC, 0.0), 2.0 * SPEC);
        assert_eq!(m.count, 2);
    }

    #[test]
    fn rotated_configuration() {
        // Both bodies rotated by the same angle: the contact rotates with them.
        let ground = boxed(5.0, 0.5);
        let b = boxed(0.5, 0.5);
        let ang = 0.6f32;
        let xa = xf(1.0, -2.0, ang);
        let q = xa.q;
        let xb = Transform {
            p: xa.p + q.rotate(Vec2::new(1.0, 1.0 - 0.002)),
            q,
        };
        let m = collide(&ground, xa, &b, xb, SPEC);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, q.rotate(Vec2::new(0.0, 1.0)), 1e-5);
        for p in m.active_points() {
            assert!((p.separation + 0.002).abs() < 1e-4);
            let local = xa.inv_apply(p.point);
            assert!((local.y - 0.499).abs() < 1e-4, "{local:?}");
            assert!(
                (local.x - 0.5).abs() < 1e-4 || (local.x - 1.5).abs() < 1e-4,
                "{local:?}"
            );
        }
        check_manifold(&m, xa, xb);
    }

    #[test]
    fn box_on_its_corner() {
        let ground = boxed(50.0, 1.0);
        let b = boxed(0.5, 0.5);
        let h = 0.5 * 2.0f32.sqrt();
        let xb = xf(0.3, 1.0 + h - 0.001, core::f32::consts::FRAC_PI_4);
        let m = collide(&ground, xf(0.0, 0.0, 0.0), &b, xb, SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let p = m.points[0];
        assert!((p.separation + 0.001).abs() < 1e-4, "{p:?}");
        assert!((p.point.x - 0.3).abs() < 1e-4);
        // Slight rocking keeps the same id (keyed by the corner vertex).
        let m2 = collide(
            &ground,
            xf(0.0, 0.0, 0.0),
            &b,
            xf(0.3, 1.0 + h - 0.001, core::f32::consts::FRAC_PI_4 + 0.01),
            SPEC,
        );
        let m3 = collide(
            &ground,
            xf(0.0, 0.0, 0.0),
            &b,
            xf(0.3, 1.0 + h - 0.001, core::f32::consts::FRAC_PI_4 - 0.01),
            SPEC,
        );
        assert_eq!(m2.count, 1);
        assert_eq!(m3.count, 1);
        assert_eq!(m2.points[0].id, m3.points[0].id);
    }

    #[test]
    fn very_different_sizes() {
        // Small box on a huge box and a huge box on a small box.
        let small = boxed(0.05, 0.05);
        let big = boxed(10.0, 10.0);
        let m = collide(&big, xf(0.0, 0.0, 0.0), &small, xf(-2.0, 10.05, 0.0), SPEC);
        assert_eq!(m.count, 2);
        let x = xs(&m);
        assert!((x[0] + 2.05).abs() < 1e-4 && (x[1] + 1.95).abs() < 1e-4, "{x:?}");
        let m = collide(&small, xf(0.0, 0.0, 0.0), &big, xf(3.0, 10.05, 0.0), SPEC);
        assert_eq!(m.count, 2);
        assert_near_v(m.normal, Vec2::new(0.0, 1.0), 1e-6);
        let x = xs(&m);
        assert!((x[0] + 0.05).abs() < 1e-4 && (x[1] - 0.05).abs() < 1e-4, "{x:?}");
        for p in m.active_points() {
            assert!(p.separation.abs() < 1e-4);
        }
    }

    #[test]
    fn rounded_boxes() {
        let r = 0.1;
        let a = Shape::Polygon(Polygon::new_rounded_box(0.4, 0.4, r).unwrap());
        // Solid is 1 × 1; rest B's solid 5 mm into A's.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(0.5, 0.995, 0.0), SPEC);
        assert_eq!(m.count, 2);
        for p in m.active_points() {
            assert!((p.separation + 0.005).abs() < 1e-5, "{p:?}");
            assert!((p.point.y - 0.4975).abs() < 1e-5, "{p:?}");
        }
        let x = xs(&m);
        assert!((x[0] - 0.1).abs() < 1e-5 && (x[1] - 0.4).abs() < 1e-5, "{x:?}");
        // Corner against corner, diagonally separated: the rounded corners give one point on
        // the diagonal, separation = centre distance of the arcs − 2r.
        let d = 0.8 + 0.2;
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(d, d, 0.0), SPEC);
        assert_eq!(m.count, 0);
        let d = 0.8 + (2.0 * r + 0.01) / 2.0f32.sqrt();
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(d, d, 0.0), SPEC);
        assert_eq!(m.count, 1);
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert_near_v(m.normal, Vec2::new(s, s), 1e-5);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
        // Midway between the arcs: (0.4 + δ/2) per axis with δ = d − 0.8, i.e. d/2.
        assert_near_v(m.points[0].point, Vec2::new(0.5 * d, 0.5 * d), 1e-5);
    }

    #[test]
    fn sharp_corner_to_corner_speculative() {
        let a = boxed(0.5, 0.5);
        // B's lower-left corner 6 mm right and 8 mm above A's upper-right corner: 1 cm apart.
        let m = collide(&a, xf(0.0, 0.0, 0.0), &a, xf(1.006, 1.008, 0.0), SPEC);
        assert_eq!(m.count, 1);
        assert_near_v(m.normal, Vec2::new(0.6, 0.8), 1e-3);
        assert!((m.points[0].separation - 0.01).abs() < 1e-5);
        assert_near_v(m.points[0].point, Vec2::new(0.503, 0.504), 1e-5);
    }

    #[test]
    fn ids_stable_when_sliding_and_distinct() {
        let ground = boxed(50.0, 1.0);
        let b = boxed(0.5, 0.5);
        let m1 = collide(&ground, xf(0.0, 0.0, 0.0), &b, xf(3.0, 1.499, 0.0), SPEC);
        let m2 = collide(&ground, xf(0.0, 0.0, 0.0), &b, xf(3.001, 1.499, 0.0), SPEC);
        assert_eq!(m1.count, 2);
        assert_eq!(m2.count, 2);
        assert_ne!(m1.points[0].id, m1.points[1].id);
        assert_eq!(m1.points[0].id, m2.points[0].id);
        assert_eq!(m1.points[1].id, m2.points[1].id);
        // Equal boxes, sliding past the edge of the lower one: one end gets clipped, ids stay.
        let m3 = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(0.3, 0.999, 0.0), SPEC);
        let m4 = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(0.301, 0.999, 0.0), SPEC);
        let m5 = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(-0.001, 0.999, 0.0), SPEC);
        assert_eq!(m3.count, 2);
        assert_ne!(m3.points[0].id, m3.points[1].id);
        assert_eq!(ids(&m3), ids(&m4));
        assert_eq!(ids(&m3), ids(&m5));
    }

    #[test]
    fn reference_face_does_not_flip_for_equal_boxes() {
        // Equal boxes: A's and B's faces tie; A stays the reference for tiny tilts.
        let b = boxed(0.5, 0.5);
        let m1 = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(0.1, 0.999, 0.0), SPEC);
        let m2 = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(0.1, 0.999, 1e-5), SPEC);
        assert_eq!(ids(&m1), ids(&m2));
    }

    #[test]
    fn reference_face_sticks_while_the_other_is_not_clearly_better() {
        use super::super::collide_after;
        // Equal boxes offset sideways, B tilted so that its bottom face separates more
        // than A's top face by more than 0.1·slop (the fresh choice takes B's face) but
        // less than a slop (a pair that clipped against A's face keeps it).
        let b = boxed(0.5, 0.5);
        let (xa, xb) = (xf(0.0, 0.0, 0.0), xf(0.3, 0.999, -0.004));
        let fresh = collide(&b, xa, &b, xb, SPEC);
        let kind = |m: &Manifold| m.points[0].id >> 8;
        assert_eq!(fresh.count, 2);
        assert_eq!(kind(&fresh), super::super::KIND_CLIP_REF_B);
        let on_a = collide(&b, xa, &b, xf(0.3, 0.999, 0.0), SPEC);
        assert_eq!(kind(&on_a), super::super::KIND_CLIP_REF_A);
        let kept = collide_after(&b, xa, &b, xb, SPEC, &on_a);
        assert_eq!(kind(&kept), super::super::KIND_CLIP_REF_A);
        assert_eq!(ids(&kept), ids(&on_a));
        // Same contact either way: the normals agree within the tilt, the depths within
        // the sticky margin.
        assert!(kept.normal.dot(fresh.normal) > 0.999);
        for (k, f) in kept.points[..2].iter().zip(&fresh.points[..2]) {
            assert!((k.separation - f.separation).abs() < crate::geometry::LINEAR_SLOP);
        }
        // A clearly better face (tilt 0.02 rad, ~10 mm over the overlap) still wins.
        let steep = collide_after(&b, xa, &b, xf(0.3, 0.999, -0.02), SPEC, &on_a);
        assert_eq!(kind(&steep), super::super::KIND_CLIP_REF_B);
    }

    #[test]
    fn deep_overlap_and_garbage() {
        let b = boxed(0.5, 0.5);
        let m = collide(&b, xf(0.0, 0.0, 0.0), &b, xf(0.0, 0.1, 0.3), SPEC);
        assert!(m.count >= 1);
        for p in m.active_points() {
            assert!(p.separation < 0.0 && p.separation.is_finite());
        }
        let m = collide(&b, xf(f32::NAN, 0.0, 0.0), &b, xf(0.0, 0.1, 0.3), SPEC);
        assert_eq!(m.count, 0);
        let m = collide(&b, xf(0.0, 0.0, f32::INFINITY), &b, xf(0.0, 0.1, 0.3), SPEC);
        assert_eq!(m.count, 0);
    }
}
