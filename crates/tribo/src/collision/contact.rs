//! Contact records: one per pair of shapes whose fat boxes overlap, holding the manifold
//! and, per point, the impulses and the stick/slip state that persist across steps.
//!
//! Pipeline stage: narrow phase. Neighbours: created by [`super::broad_phase`], read and
//! written back by [`crate::solver`].

use crate::dynamics::MixedMaterial;
use crate::geometry::{collide_bounded_into, Manifold, Shape, MAX_MANIFOLD_POINTS};
use crate::geometry::{LINEAR_SLOP, SPECULATIVE_DISTANCE};
use crate::math::wide::{apply_lanes, split_xy, F4, M4};
use crate::math::{Rot, Transform, Vec2};
use crate::world::ShapeId;

/// Friction state of one contact point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrictionState {
    /// The point holds: its friction may reach μs times its normal impulse.
    #[default]
    Stick,
    /// The point slides: its friction is μd times its normal impulse, against the slip.
    Slip,
}

/// What persists for one manifold point between steps (matched by feature id).
///
/// `repr(C)`, the four floats first in the order of [`PointState::set_stored`]: the
/// impulse store writes them as one 16-byte row per point, straight from the transpose of
/// its lanes; they are what the next step's solver input reads (`ContactInput::fill`).
/// What the step applied (its sums, the slip speed) is reported, never read back: it lives
/// apart, in [`PointSums`], so the store writes one cache line of each contact record.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct PointState {
    /// Normal impulse of the last substep [N·s] (warm start).
    pub normal_impulse: f32,
    /// Friction impulse of the last substep [N·s] (warm start), along the tangent.
    pub tangent_impulse: f32,
    /// Tangential slip [m] accumulated while sticking (the static-friction anchor): the
    /// solver drives it back to zero, so a sticking body cannot creep.
    pub drift: f32,
    /// Normal impulse per substep [N·s] the soft contact relaxes towards (a slowly
    /// tracking average of the manifold's load, so a steady load needs no deflection).
    pub preload: f32,
    /// Stick or slip.
    pub state: FrictionState,
    /// True until the point has been through one solver step.
    pub fresh: bool,
}

impl PointState {
    /// A point with no history: sticking, no impulses (the `Default`).
    pub const BLANK: PointState = PointState {
        normal_impulse: 0.0,
        tangent_impulse: 0.0,
        drift: 0.0,
        preload: 0.0,
        state: FrictionState::Stick,
        fresh: false,
    };

    /// Sets what the impulse store writes: `carried` = (normal [N·s], tangent [N·s], drift
    /// [m], preload [N·s]), the friction state, and `fresh` off. Field by field in layout
    /// order, so the row compiles to one 16-byte store.
    #[inline(always)]
    pub fn set_stored(&mut self, carried: [f32; 4], state: FrictionState) {
        let [normal, tangent, drift, preload] = carried;
        self.normal_impulse = normal;
        self.tangent_impulse = tangent;
        self.drift = drift;
        self.preload = preload;
        self.state = state;
        self.fresh = false;
    }
}

/// What the last solved step did at one manifold point, for contact reports
/// (`World::contacts`; the solver never reads it back). Kept per contact slot in
/// `World::contact_sums`, apart from the [`Contact`] records: the impulse store writes it
/// in the solver's layout order (the order of the contact slots), a dense stream the
/// hardware prefetches, and one cache line of each record rather than two (large_pyramid:
/// the store's time had gone into waiting for the records' second lines). The store writes
/// a solved contact's sums; a touching contact the solver did not take gets zeros; a
/// sleeping one keeps those of its last solved step.
///
/// `repr(C)`, the order of the store's second row per point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct PointSums {
    /// Sum over the step's substeps of the normal impulse [N·s] (what the step applied).
    pub total_normal_impulse: f32,
    /// Sum over the step's substeps of the friction impulse [N·s].
    pub total_tangent_impulse: f32,
    /// Largest normal impulse of any substep [N·s]; > 0 means the point carried load.
    pub max_normal_impulse: f32,
    /// Relative tangential speed at the end of the step [m/s] (surface speed removed).
    pub slip_speed: f32,
}

impl PointSums {
    /// The sums from the store's row (total normal [N·s], total tangent [N·s], max normal
    /// [N·s], slip speed [m/s]).
    #[inline(always)]
    pub fn from_row(row: [f32; 4]) -> PointSums {
        let [total_normal_impulse, total_tangent_impulse, max_normal_impulse, slip_speed] = row;
        PointSums {
            total_normal_impulse,
            total_tangent_impulse,
            max_normal_impulse,
            slip_speed,
        }
    }
}

/// A contact's [`PointSums`], one per manifold point.
pub(crate) type ContactSums = [PointSums; MAX_MANIFOLD_POINTS];

/// [`Contact::colour`] of a contact not yet solved, or solved in the overflow list.
pub(crate) const NO_COLOUR: u8 = u8::MAX;

/// A contact between two shapes (internal record).
///
/// Laid out by use (`repr(C)`, whole cache lines): the passes in contact order that touch
/// only a little of each record — the awake test before the narrow phase, the impulse
/// store — find what they need (the liveness flag, `touching`, the bodies, the point
/// states) in the first line; the recycling basis and the shape ids, read only by the
/// narrow phase and events, come last.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(crate) struct Contact {
    /// Whether the manifold has points.
    pub touching: bool,
    /// The solver colour the contact had when last solved ([`NO_COLOUR`]: none), which
    /// the colouring tries first (see `solver::contact_set`).
    pub colour: u8,
    /// Body slot indices.
    pub body_a: u32,
    pub body_b: u32,
    /// Rolling resistance impulse [N·m·s] of the last substep (warm start).
    pub rolling_impulse: f32,
    /// Rolling lever arm [m]: the larger rolling radius of the two shapes.
    pub rolling_radius: f32,
    pub points: [PointState; MAX_MANIFOLD_POINTS],
    pub manifold: Manifold,
    pub material: MixedMaterial,
    pub shape_a: ShapeId,
    pub shape_b: ShapeId,
    /// What the last full collision left for the next steps to skip one.
    pub memo: Memo,
    /// This contact's place in body A's and body B's contact lists (`Body::contacts`), so
    /// that destroying it takes it out of each list in one step: a static body holds
    /// thousands (the spinner's ring, the washer's drum), and finding the contact by a
    /// search was 3.5 % of the spinner's instructions.
    pub list_pos: [u32; 2],
}

const _: () = assert!(core::mem::size_of::<Contact>() == 320);

impl Contact {
    /// A new contact's record before its pair is written in (`World::create_contact`):
    /// not touching, no colour, an empty manifold, nothing to reuse, no impulses.
    pub const BLANK: Contact = Contact {
        touching: false,
        colour: NO_COLOUR,
        body_a: 0,
        body_b: 0,
        rolling_impulse: 0.0,
        rolling_radius: 0.0,
        points: [PointState::BLANK; MAX_MANIFOLD_POINTS],
        manifold: Manifold::EMPTY,
        material: MixedMaterial::BLANK,
        shape_a: ShapeId {
            index: 0,
            generation: 0,
        },
        shape_b: ShapeId {
            index: 0,
            generation: 0,
        },
        memo: Memo::None,
        list_pos: [0; 2],
    };
}

// Everything the impulse store writes (colour, rolling impulse, the point states) lies in
// the record's first cache line.
const _: () =
    assert!(core::mem::offset_of!(Contact, points) + core::mem::size_of::<[PointState; MAX_MANIFOLD_POINTS]>() <= 64);

/// What a contact keeps of its last full collision to skip the next: for a touching pair
/// its poses then, which its first recycle turns into the recycling basis, or the distance
/// bound of a pair found apart. A contact is one or the other, never both, so they share
/// their bytes: the record is five cache lines, not six (the narrow phase streams every
/// awake contact each step).
///
/// `repr(u8)`: a tag of one byte leaves fewer spare values than `Contact::touching`, so
/// `Option<Contact>` keeps its `None` in that first byte; with a wider tag the compiler put
/// it here, in the fourth cache line, which every pass that only checks a slot then had to
/// load (the impulse store took twice as long in large_pyramid).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(u8)]
pub(crate) enum Memo {
    /// Nothing to reuse.
    #[default]
    None,
    /// Where the manifold was last computed (touching pairs; [`Contact::recycle`]).
    Basis(RecycleBasis),
    /// A touching pair's poses when its manifold was computed, from which
    /// [`Contact::recycle`] makes the [`Memo::Basis`] the first time it tries to reuse the
    /// manifold, and the manifold's step allowance (see [`RecycleBasis::allowance`]). A
    /// pair moving faster than that is refused before a basis is made, so it never needs
    /// one: in smash, junkyard and the tumbler many full collisions are of pairs that never
    /// recycle, and making the basis each time was a tenth of a full collision's
    /// instructions.
    Posed {
        xf_a: Transform,
        xf_b: Transform,
        allowance: f32,
    },
    /// A pair found apart: a lower bound [m] (> 0) on its surfaces' distance at the poses
    /// `poses` ([`Contact::still_apart`]).
    Far { bound: f32, poses: FarPoses },
}

/// The bodies' poses when a pair's distance bound ([`Memo::Far`]) was computed: in world
/// axes, and B's relative to A's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FarPoses {
    /// Origin of B minus origin of A [m].
    pub d: Vec2,
    pub q_a: Rot,
    pub q_b: Rot,
    /// B's origin in A's frame [m] (`xf_a.inv_mul(xf_b).p`).
    pub rel_p: Vec2,
    /// B's rotation in A's frame (`xf_a.q.inv_mul(xf_b.q)`).
    pub rel_q: Rot,
}

/// The narrow phase's verdict on one contact in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum NarrowOutcome {
    /// Not updated this step (no awake moving body, or a shape is gone).
    #[default]
    Skipped,
    /// The fat boxes separated or the filters now forbid the pair: destroy it.
    Destroy,
    /// Updated; `touching` now, and whether that changed.
    Updated { touching: bool, changed: bool },
}

/// The manifold's points as material points of the two bodies, kept from the last full
/// manifold computation (contact recycling, as Box2D v3 since 2026-03 but with a much
/// tighter distance; see [`Contact::recycle`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RecycleBasis {
    /// Each point's surface point on A, in A's frame [m].
    pub local_a: [Vec2; MAX_MANIFOLD_POINTS],
    /// Each point's surface point on B, in B's frame [m].
    pub local_b: [Vec2; MAX_MANIFOLD_POINTS],
    /// The normal in A's frame.
    pub normal_a: Vec2,
    /// B's surface points seen from A's frame when the basis was made [m].
    pub b_in_a: [Vec2; MAX_MANIFOLD_POINTS],
    /// A's surface points seen from B's frame when the basis was made [m].
    pub a_in_b: [Vec2; MAX_MANIFOLD_POINTS],
    /// Rotation from A's frame to B's frame when the basis was made.
    pub rel_q: Rot,
    /// The largest relative motion in one step [m] (the narrow phase's `dt · rel`) for
    /// which the manifold may be reused: the margin it was computed with less the linear
    /// slop ([`RECYCLE_STEP`] for a pair collided at the speculative distance; more for a
    /// fast pair, whose margin grew with its motion). See [`RECYCLE_DISTANCE`].
    pub allowance: f32,
}

impl RecycleBasis {
    /// The basis of `manifold`, computed with the bodies at `xf_a` and `xf_b`: each point's
    /// surface points (half the separation either side along the normal) in both frames;
    /// `allowance` [m]: see [`RecycleBasis::allowance`] (tests; `Contact::recycle` makes
    /// it in place, [`RecycleBasis::set`]).
    #[cfg(test)]
    fn of(manifold: &Manifold, xf_a: Transform, xf_b: Transform, allowance: f32) -> RecycleBasis {
        let mut basis = RecycleBasis::default();
        basis.set(manifold, xf_a, xf_b, allowance);
        basis
    }

    /// Makes this the basis of `manifold`, computed with the bodies at `xf_a` and `xf_b`
    /// (each point's surface points, half the separation either side along the normal, in
    /// both frames; `allowance` [m]: see [`RecycleBasis::allowance`]), in place: every
    /// field written, an unused point's slots zero.
    #[inline(always)]
    fn set(&mut self, manifold: &Manifold, xf_a: Transform, xf_b: Transform, allowance: f32) {
        // Field by field, no record built whole: a record built on the stack and copied in
        // reads its 16-byte halves over the narrower stores that made them (no store
        // forwarding: a quarter of `recycle`'s samples in the tumbler waited on that copy).
        let n = manifold.normal;
        let count = manifold.count.min(MAX_MANIFOLD_POINTS);
        for i in 0..MAX_MANIFOLD_POINTS {
            let (la, lb, ba, ab) = match manifold.points.get(i).filter(|_| i < count) {
                Some(mp) => {
                    let half = 0.5 * mp.separation * n;
                    let (surface_a, surface_b) = (mp.point - half, mp.point + half);
                    (
                        xf_a.inv_apply(surface_a),
                        xf_b.inv_apply(surface_b),
                        xf_a.inv_apply(surface_b),
                        xf_b.inv_apply(surface_a),
                    )
                }
                None => (Vec2::ZERO, Vec2::ZERO, Vec2::ZERO, Vec2::ZERO),
            };
            self.local_a[i] = la;
            self.local_b[i] = lb;
            self.b_in_a[i] = ba;
            self.a_in_b[i] = ab;
        }
        self.rel_q = xf_a.q.inv_mul(xf_b.q);
        self.normal_a = xf_a.q.inv_rotate(n);
        self.allowance = allowance;
    }
}

/// Largest relative motion [m] of a pair since its manifold was computed for which the
/// manifold is reused: three times the linear slop (1.5 cm), counted as the largest motion
/// of a manifold point (each side's surface points seen from the other body) plus the turn
/// times the reach of the smaller body's features, which together bound how far any
/// feature of the pair has moved towards the other. A manifold's points are material points
/// of the two bodies, so the separations are refreshed from the points instead of colliding
/// the shapes again.
///
/// What reuse costs in accuracy, within it: a vertex sliding on a face (the common point of
/// polygon contacts) keeps its exact separation, the face being flat; a point clipped at a
/// face's end may ride up to 1.5 cm past it; a tipping box is caught by its turn; pairs
/// with a rounded shape, whose contact points roll, keep a tighter limit
/// ([`ROUND_RECYCLE_DISTANCE`]). A feature the manifold lacks was further than the margin
/// m the manifold was computed with (the speculative distance, grown by the pair's motion
/// then), has moved by at most this distance since, and closes by at most the pair's
/// `dt · rel` in the step, which recycling allows up to m less the linear slop
/// ([`RecycleBasis::allowance`]; [`RECYCLE_STEP`] for m = the speculative distance), so it
/// can overlap by at most 1.5 cm + (m − 0.5 cm) − m = 1 cm: the bound of the earlier limits
/// (5 mm of point motion and 5 mm of turn, tested apart, and 2 cm a step). Box2D v3 reuses manifolds up to 10 × linear
/// slop (5 cm, also motion plus turn times extent), keeping the anchors as they were.
/// History: 1 mm (resting pairs only) until 2026-12; then 5 mm, which cut the manifolds
/// computed per step by 42 % in Box2D's washer, 36 % in its tumbler, 34 % in junkyard and
/// 17 % in smash; then this (instructions over 300 steps against 5 mm: junkyard −1.6 %,
/// tumbler −2.4 %, smash −2.7 %; most of the slow pairs that still failed the 5 mm tests
/// had moved 5–15 mm). Tried and dropped: 1 cm of point motion and 1 cm of turn tested
/// apart (as fast, but a missed feature could overlap by 1.5 cm); 1 cm combined with 2 cm a
/// step (a 1 cm bound too, but fewer pairs reused); a manifold made 5 mm wider instead of a
/// step limit (more speculative points to carry).
pub(crate) const RECYCLE_DISTANCE: f32 = 3.0 * LINEAR_SLOP;

/// [`RECYCLE_DISTANCE`] for a pair with a rounded shape (circle, capsule, rounded polygon:
/// `Contact::rolling_radius` > 0): the linear slop (5 mm). Its contact point rolls over the
/// round feature instead of staying a material point, so reuse errs by R (1 − cos θ) for a
/// turn θ: 6 µm for a disk of R = 0.5 m rolling on a larger body. With the 1.5 cm of
/// polygon pairs, the rolling-resistance validation case's stopping-distance error went
/// from 0.06 % to 0.58 % (of a ±2 % tolerance); this keeps it at its earlier value.
pub(crate) const ROUND_RECYCLE_DISTANCE: f32 = LINEAR_SLOP;

/// Largest relative motion per step [m] (the narrow phase's `dt · rel`) of a pair whose
/// manifold, computed at the speculative distance, is recycled: the speculative distance
/// less the linear slop (1.5 cm); faster pairs are collided again. A manifold computed with
/// a margin grown by the pair's motion allows that growth more
/// ([`RecycleBasis::allowance`]; Box2D's fast bodies bypass recycling instead: tumbler,
/// 1 283 of 9 237 pairs a step were too fast for 1.5 cm, 453 of them recyclable by their
/// own margin). See [`RECYCLE_DISTANCE`] for the bound it keeps.
pub(crate) const RECYCLE_STEP: f32 = SPECULATIVE_DISTANCE - LINEAR_SLOP;

impl Contact {
    /// Recomputes the manifold and carries impulses and friction state over to points
    /// with the same feature id. Returns whether the contact is touching now.
    pub fn update(
        &mut self,
        geom_a: &Shape,
        xf_a: Transform,
        geom_b: &Shape,
        xf_b: Transform,
        speculative_distance: f32,
    ) -> bool {
        let old_manifold = self.manifold;
        let old_points = self.points;
        let bound = collide_bounded_into(
            geom_a,
            xf_a,
            geom_b,
            xf_b,
            speculative_distance,
            &old_manifold,
            &mut self.manifold,
        );
        for i in 0..self.manifold.count {
            let id = self.manifold.points[i].id;
            let matched = (0..old_manifold.count).find(|&j| old_manifold.points[j].id == id);
            self.points[i] = match matched {
                Some(j) => old_points[j],
                None => PointState {
                    fresh: true,
                    ..PointState::default()
                },
            };
        }
        for p in self.points.iter_mut().skip(self.manifold.count) {
            *p = PointState::default();
        }
        self.touching = self.manifold.count > 0;
        if !self.touching {
            self.rolling_impulse = 0.0;
            self.memo = if bound > 0.0 {
                Memo::Far {
                    bound,
                    poses: FarPoses {
                        d: xf_b.p - xf_a.p,
                        q_a: xf_a.q,
                        q_b: xf_b.q,
                        rel_p: xf_a.q.inv_rotate(xf_b.p - xf_a.p),
                        rel_q: xf_a.q.inv_mul(xf_b.q),
                    },
                }
            } else {
                Memo::None
            };
            return false;
        }
        // The variant set first and its poses written in place: assigned whole, the
        // compiler built it on the stack and copied it from one byte in, a 16-byte load
        // over a 16-byte store it only half overlapped (no forwarding: a stall per full
        // collision).
        self.memo = Memo::Posed {
            xf_a: Transform::IDENTITY,
            xf_b: Transform::IDENTITY,
            allowance: 0.0,
        };
        if let Memo::Posed {
            xf_a: a,
            xf_b: b,
            allowance,
        } = &mut self.memo
        {
            (*a, *b) = (xf_a, xf_b);
            // The margin's growth over the speculative distance (the pair's motion then)
            // is allowed on top of `RECYCLE_STEP`.
            *allowance = RECYCLE_STEP + (speculative_distance - SPECULATIVE_DISTANCE);
        }
        true
    }

    /// Whether a pair found apart is still too far apart for any manifold point within
    /// `margin` [m], judged without colliding it: its distance bound minus the most its
    /// surfaces can have closed in since. That is the lesser of two bounds on the motion of
    /// any shape point: in world axes, the relative motion of the body origins plus each
    /// body's turn times its reach (a point at distance R from the origin turning by Δθ moves
    /// 2R·sin(Δθ/2) = R·|q − q₀|, exactly); and in A's frame, where the distance is the same
    /// (it depends only on B's pose relative to A's), the motion of B's origin there plus
    /// B's relative turn times its reach (a point x of B moves by Δp + (q − q₀)·x as complex
    /// numbers, at most |Δp| + |q − q₀|·|x|). The second is zero for bodies moving as one
    /// (a pile turning with its drum: the tumbler's neighbours apart by a few centimetres
    /// were collided again every few steps, each time apart), the first is the smaller
    /// for A turning alone. `d`: origin of B minus origin of A now [m]; `reach_a`,
    /// `reach_b`: the bodies' largest distance [m] from their origin to a shape point. When
    /// true, colliding would give the empty manifold the contact already has (see
    /// `geometry::collide_bounded`).
    #[inline(always)]
    pub fn still_apart(&self, d: Vec2, q_a: Rot, q_b: Rot, reach_a: f32, reach_b: f32, margin: f32) -> bool {
        let Memo::Far { bound, poses: f } = &self.memo else {
            return false;
        };
        if self.touching || *bound <= margin {
            return false;
        }
        let turn = |q: Rot, q0: Rot| ((q.c - q0.c) * (q.c - q0.c) + (q.s - q0.s) * (q.s - q0.s)).sqrt();
        // `bound − min(relative, world) > margin`, the second bound computed only when the
        // first does not decide (the same verdict: the subtraction is monotone).
        let relative = (q_a.inv_rotate(d) - f.rel_p).length() + reach_b * turn(q_a.inv_mul(q_b), f.rel_q);
        *bound - relative > margin || {
            let world = (d - f.d).length() + reach_a * turn(q_a, f.q_a) + reach_b * turn(q_b, f.q_b);
            *bound - world > margin
        }
    }

    /// What [`Contact::update`] leaves when the shapes are too far apart for any point:
    /// no points, no carried-over state.
    pub fn clear_manifold(&mut self) {
        self.manifold = Manifold::EMPTY;
        self.points = [PointState::default(); MAX_MANIFOLD_POINTS];
        self.rolling_impulse = 0.0;
        self.touching = false;
        // A distance bound stays true of its poses; a basis has nothing left to recycle.
        if matches!(self.memo, Memo::Basis(_) | Memo::Posed { .. }) {
            self.memo = Memo::None;
        }
    }

    /// Reuses the manifold of a touching contact whose bodies moved less than
    /// [`RECYCLE_DISTANCE`] relative to each other since it was computed — each point's
    /// surface point on B seen from A and on A seen from B (a rolling disk moves its
    /// ground point away at once), and the relative rotation times `extent` [m], the reach
    /// of the smaller body's features from the contact (a tipping box brings other
    /// features near), and whose largest relative motion this step, `step` [m] (`dt ·
    /// rel`), is within the manifold's allowance ([`RecycleBasis::allowance`]): normal,
    /// points and separations are then refreshed from the stored material points (same
    /// feature ids, so impulses and friction states carry over unchanged). Returns false
    /// (and changes nothing but the memo's form) when the contact must be collided again.
    pub fn recycle(&mut self, xf_a: Transform, xf_b: Transform, extent: f32, step: f32) -> bool {
        let count = self.manifold.count;
        if count == 0 {
            return false;
        }
        match self.memo {
            // (Written so that a NaN step or allowance refuses.)
            Memo::Posed { allowance, .. } | Memo::Basis(RecycleBasis { allowance, .. }) if !(step <= allowance) => {
                return false
            }
            Memo::Posed {
                xf_a: then_a,
                xf_b: then_b,
                allowance,
            } => {
                // The manifold is still the one computed at these poses: a recycle first
                // makes the basis, and `update` and `clear_manifold` replace the memo with
                // the manifold. (The variant set first, its basis written in place.)
                self.memo = Memo::Basis(RecycleBasis::default());
                if let Memo::Basis(basis) = &mut self.memo {
                    basis.set(&self.manifold, then_a, then_b, allowance);
                }
            }
            _ => {}
        }
        let Memo::Basis(basis) = &self.memo else {
            return false;
        };
        let rel = xf_a.inv_mul(xf_b);
        let turned = basis.rel_q.inv_mul(rel.q).s.abs() * extent;
        // A rounded shape's contact point is not a material point: it rolls, and its
        // separation's error grows with the turn squared.
        let limit = if self.rolling_radius > 0.0 {
            ROUND_RECYCLE_DISTANCE
        } else {
            RECYCLE_DISTANCE
        };
        if turned > limit {
            return false;
        }
        // Each point may move what the turn leaves of the distance.
        let room = limit - turned;
        let limit2 = room * room;
        let rel_ba = xf_b.inv_mul(xf_a);
        // Four lanes at once: B's points 0 and 1 seen from A's frame, A's points 0 and 1
        // seen from B's frame, each compared with where it was seen when the basis was
        // made. Every lane is the scalar expression (`Transform::apply`, then the
        // difference and its `length_squared`), in its order: the same bits. One pass of
        // four lanes instead of four transforms of two-vector scalar code (large_pyramid:
        // this function was 256 instructions a contact, nearly Box2D's full collision).
        let points = |u: &[Vec2; 2], w: &[Vec2; 2]| split_xy([u[0], u[1], w[0], w[1]]);
        let (lb, la) = (&basis.local_b, &basis.local_a);
        let pair = |u: f32, v: f32| F4::new([u, u, v, v]);
        // The first two lanes moved by (q, p), the last two by (q2, p2).
        let moved = |xy: (F4, F4), (q, p): (Rot, Vec2), (q2, p2): (Rot, Vec2)| {
            apply_lanes(
                (pair(q.c, q2.c), pair(q.s, q2.s)),
                (pair(p.x, p2.x), pair(p.y, p2.y)),
                xy,
            )
        };
        let (mx, my) = moved(points(lb, la), (rel.q, rel.p), (rel_ba.q, rel_ba.p));
        let (bx, by) = points(&basis.b_in_a, &basis.a_in_b);
        let (dx, dy) = (mx - bx, my - by);
        let real = if count >= 2 { ALL_LANES } else { FIRST_OF_EACH };
        if ((dx * dx + dy * dy).gt(F4::splat(limit2)) & real).any() {
            return false;
        }
        let n = xf_a.q.rotate(basis.normal_a);
        self.manifold.normal = n;
        // The surface points in world axes, the same way: A's 0 and 1, B's 0 and 1.
        let (wx, wy) = moved(points(la, lb), (xf_a.q, xf_a.p), (xf_b.q, xf_b.p));
        for i in 0..count.min(MAX_MANIFOLD_POINTS) {
            let surface_a = Vec2::new(wx[i], wy[i]);
            let surface_b = Vec2::new(wx[2 + i], wy[2 + i]);
            let mp = &mut self.manifold.points[i];
            mp.point = 0.5 * (surface_a + surface_b);
            mp.anchor_a = mp.point - xf_a.p;
            mp.anchor_b = mp.point - xf_b.p;
            mp.separation = (surface_b - surface_a).dot(n);
        }
        true
    }
}

/// [`Contact::recycle`]'s lanes when the manifold has two points, and when it has one
/// (lanes 0 and 2: point 0 of each side).
const ALL_LANES: M4 = M4::new([u32::MAX; 4]);
const FIRST_OF_EACH: M4 = M4::new([u32::MAX, 0, u32::MAX, 0]);

/// Key of an unordered shape pair: lower shape index in the high half.
#[inline]
pub(crate) fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// A blank contact record between shapes 0 and 1 of bodies 0 and 1 (tests).
#[cfg(test)]
pub(crate) fn blank_contact() -> Contact {
    let mut c = Contact::BLANK;
    c.shape_b.index = 1;
    c.body_b = 1;
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Circle, Polygon};
    use crate::math::Rot;

    fn contact() -> Contact {
        blank_contact()
    }

    /// The blank record a new contact starts from holds what each part's `Default` holds,
    /// which the record built whole before it used (a `Default` changed later would
    /// otherwise part from the blank): compared part by part, as `Contact` has no
    /// equality.
    #[test]
    fn a_blank_contact_is_every_part_default() {
        let c = Contact::BLANK;
        assert_eq!(c.points, [PointState::default(); MAX_MANIFOLD_POINTS]);
        assert_eq!(c.manifold, Manifold::default());
        assert_eq!(c.material, MixedMaterial::default());
        assert_eq!(c.memo, Memo::default());
        assert_eq!((c.touching, c.colour), (false, NO_COLOUR));
        assert_eq!((c.rolling_impulse, c.rolling_radius, c.list_pos), (0.0, 0.0, [0, 0]));
    }

    /// `c` (a ground–block contact) recycled for the block at `moved` and collided afresh
    /// there; both must succeed, and every point of the fresh manifold must come back with
    /// its feature id and its separation to 1e-6 m in the recycled one.
    fn recycled_and_fresh(
        c: &Contact,
        ground: &Shape,
        xf_g: Transform,
        block: &Shape,
        moved: Transform,
    ) -> (Contact, Contact) {
        let mut recycled = c.clone();
        assert!(recycled.recycle(xf_g, moved, 2.0 * 0.71, 0.0));
        let mut fresh = c.clone();
        assert!(fresh.update(ground, xf_g, block, moved, 0.02));
        for i in 0..fresh.manifold.count {
            let (r, f) = (recycled.manifold.points[i], fresh.manifold.points[i]);
            assert_eq!(r.id, f.id);
            assert!(
                (r.separation - f.separation).abs() < 1e-6,
                "{} vs {}",
                r.separation,
                f.separation
            );
        }
        (recycled, fresh)
    }

    /// A box resting on a ground box and nudged by 0.2 mm and 0.01°: the recycled manifold
    /// must match a freshly computed one (same features and normal, separations to 1e-6 m):
    /// the points are material points of the two bodies, so the separations along the
    /// face normal are exact under any small rigid motion.
    #[test]
    fn recycled_manifold_of_a_resting_box_matches_a_fresh_one() {
        let ground = Shape::Polygon(Polygon::new_box(5.0, 0.5).unwrap());
        let block = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let xf_g = Transform::new(Vec2::new(0.0, -0.5), 0.0);
        let xf_b0 = Transform::new(Vec2::new(0.3, 0.499), 0.0);
        let mut c = contact();
        assert!(c.update(&ground, xf_g, &block, xf_b0, 0.02));
        let (shift, turn) = (Vec2::new(0.0002, 0.0001), 0.01f32.to_radians());
        let moved = Transform {
            p: xf_b0.p + shift,
            q: Rot::from_angle(turn),
        };
        // How far a corner of the block (0.71 m from its centre) moved along the ground.
        let slide = shift.x.abs() + 0.71 * turn;
        let (recycled, fresh) = recycled_and_fresh(&c, &ground, xf_g, &block, moved);
        assert_eq!(recycled.manifold.count, fresh.manifold.count);
        assert!((recycled.manifold.normal - fresh.manifold.normal).length() < 1e-6);
        for i in 0..fresh.manifold.count {
            let (r, f) = (recycled.manifold.points[i], fresh.manifold.points[i]);
            // The reference face's point is a material point of the ground, so the midpoint
            // lags by at most half the relative slide (and 1 µm of rounding).
            assert!(
                (r.point - f.point).length() <= 0.5 * slide + 1e-6,
                "{:?} vs {:?}",
                r.point,
                f.point
            );
        }
    }

    /// A box sliding along the ground: within the recycle distance (0.8 of it, no turn) the
    /// recycled manifold keeps the same points and the exact separations of a fresh one (a
    /// vertex on a flat face); beyond it (1.2 of it) the pair is collided again.
    #[test]
    fn a_sliding_box_is_recycled_within_the_recycle_distance_with_exact_separations() {
        let ground = Shape::Polygon(Polygon::new_box(5.0, 0.5).unwrap());
        let block = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let xf_g = Transform::new(Vec2::new(0.0, -0.5), 0.0);
        let mut c = contact();
        assert!(c.update(&ground, xf_g, &block, Transform::new(Vec2::new(0.3, 0.499), 0.0), 0.02));
        let slid = Transform::new(Vec2::new(0.3 + 0.8 * RECYCLE_DISTANCE, 0.4985), 0.0);
        let (recycled, _) = recycled_and_fresh(&c, &ground, xf_g, &block, slid);
        assert_eq!(recycled.manifold.count, 2);
        let beyond = Transform::new(Vec2::new(0.3 + 1.2 * RECYCLE_DISTANCE, 0.499), 0.0);
        assert!(!c.recycle(xf_g, beyond, 2.0 * 0.71, 0.0));
    }

    /// How fast a pair may move in the step of a recycle depends on the margin its
    /// manifold was computed with: a feature the manifold lacks was further than that
    /// margin m, so a step of up to m − slop (plus the 1.5 cm of recycle motion) leaves it
    /// at most 1 cm of overlap. At the speculative distance (2 cm) the allowance is
    /// `RECYCLE_STEP` (1.5 cm); computed with a margin of 5 cm (a pair moving 3 cm a step),
    /// 4.5 cm. Each is refused just past its allowance and accepted just under it, with
    /// the same (unmoved) poses, so only the step decides.
    #[test]
    fn a_manifold_allows_the_step_its_margin_covered() {
        let ground = Shape::Polygon(Polygon::new_box(5.0, 0.5).unwrap());
        let block = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let xf_g = Transform::new(Vec2::new(0.0, -0.5), 0.0);
        let xf_b = Transform::new(Vec2::new(0.3, 0.499), 0.0);
        for (margin, allowance) in [(SPECULATIVE_DISTANCE, RECYCLE_STEP), (0.05, 0.045)] {
            let mut c = contact();
            assert!(c.update(&ground, xf_g, &block, xf_b, margin));
            let Memo::Posed { allowance: kept, .. } = c.memo else {
                panic!("a touching pair keeps its poses")
            };
            assert!((kept - allowance).abs() < 1e-6 && (kept - (margin - LINEAR_SLOP)).abs() < 1e-6);
            // A step that is not a number is refused.
            assert!(!c.clone().recycle(xf_g, xf_b, 2.0 * 0.71, f32::NAN));
            assert!(
                !c.clone().recycle(xf_g, xf_b, 2.0 * 0.71, allowance + 1e-4),
                "margin {margin}"
            );
            // Refused without making the basis: the poses stay for a later try.
            let mut refused = c.clone();
            assert!(!refused.recycle(xf_g, xf_b, 2.0 * 0.71, allowance + 1e-4));
            assert!(matches!(refused.memo, Memo::Posed { .. }));
            assert!(c.recycle(xf_g, xf_b, 2.0 * 0.71, allowance - 1e-4), "margin {margin}");
            // The basis keeps the allowance for the next steps.
            assert!(!c.clone().recycle(xf_g, xf_b, 2.0 * 0.71, allowance + 1e-4));
            assert!(c.recycle(xf_g, xf_b, 2.0 * 0.71, allowance - 1e-4));
        }
    }

    /// A ground box (top face y = 0), a disk of radius 0.5 m and the ground's pose.
    fn disk_and_ground() -> (Shape, Shape, Transform) {
        let ground = Shape::Polygon(Polygon::new_box(5.0, 0.5).unwrap());
        let disk = Shape::Circle(Circle {
            center: Vec2::ZERO,
            radius: 0.5,
        });
        (ground, disk, Transform::new(Vec2::new(0.0, -0.5), 0.0))
    }

    /// The check runs four lanes (two points of each side) whatever the manifold's count,
    /// so a one-point manifold must mask the lanes of its unused slot: even zero there is
    /// a point at a body's origin, which moves as the body turns (and would, unmasked,
    /// refuse recycling by the distance between the origins). A disk resting on the
    /// ground must recycle when it moves within the recycle distance with points metres
    /// away in that slot, and still refuse a move beyond it.
    #[test]
    fn a_one_point_manifold_ignores_the_unused_slot_of_its_basis() {
        let (ground, disk, xf_g) = disk_and_ground();
        let mut c = contact();
        assert!(c.update(&ground, xf_g, &disk, Transform::new(Vec2::new(0.0, 0.499), 0.0), 0.02));
        assert_eq!(c.manifold.count, 1);
        // A touching contact keeps its poses; its first recycle makes the basis from them.
        let Memo::Posed { xf_a, xf_b, allowance } = c.memo else {
            panic!("a touching contact keeps its poses")
        };
        c.memo = Memo::Basis(RecycleBasis::of(&c.manifold, xf_a, xf_b, allowance));
        let Memo::Basis(basis) = &mut c.memo else {
            panic!("a recycling basis")
        };
        // Points that would have moved 15 m since the basis was made, were they read.
        (basis.local_a[1], basis.local_b[1]) = (Vec2::new(7.0, -3.0), Vec2::new(7.0, -3.0));
        (basis.b_in_a[1], basis.a_in_b[1]) = (Vec2::new(-7.0, 3.0), Vec2::new(-7.0, 3.0));
        // Lifted by 1 mm: the material points moved 1 mm < RECYCLE_DISTANCE.
        let lifted = Transform::new(Vec2::new(0.0, 0.5), 0.0);
        let mut recycled = c.clone();
        assert!(recycled.recycle(xf_g, lifted, 2.0 * 0.5, 0.0));
        assert!((recycled.manifold.points[0].separation - (c.manifold.points[0].separation + 1e-3)).abs() < 1e-6);
        // Lifted by 1.2 × RECYCLE_DISTANCE: beyond it, collided again.
        let beyond = Transform::new(Vec2::new(0.0, 0.499 + 1.2 * RECYCLE_DISTANCE), 0.0);
        assert!(!c.clone().recycle(xf_g, beyond, 2.0 * 0.5, 0.0));
    }

    /// A rolling disk's contact point is not a material point, but its material points
    /// barely move as it rolls (0.4 mm after rolling 2 cm without slipping): its turn
    /// refuses it (0.04 rad times a reach of 1 m, 4 cm > [`RECYCLE_DISTANCE`]), and a box
    /// tipped by 0.5° is refused by its turn (12 mm at its reach) and its corners' motion
    /// (6 mm) together, so both manifolds are computed again.
    #[test]
    fn rolling_or_turning_contacts_are_not_recycled() {
        let (ground, disk, xf_g) = disk_and_ground();
        let mut c = contact();
        assert!(c.update(&ground, xf_g, &disk, Transform::new(Vec2::new(0.0, 0.5), 0.0), 0.02));
        let rolled = Transform::new(Vec2::new(0.02, 0.5), -0.04);
        assert!(!c.clone().recycle(xf_g, rolled, 2.0 * 0.5, 0.0));
        // A small roll (0.01 rad: 1 cm at the reach) is within a polygon pair's limit, but
        // not within a rounded shape's (`Contact::rolling_radius` > 0), whose point rolls.
        let small = Transform::new(Vec2::new(0.005, 0.5), -0.01);
        assert!(c.clone().recycle(xf_g, small, 2.0 * 0.5, 0.0));
        let round = Contact {
            rolling_radius: 0.5,
            ..c.clone()
        };
        assert!(!round.clone().recycle(xf_g, small, 2.0 * 0.5, 0.0));
        assert!(round
            .clone()
            .recycle(xf_g, Transform::new(Vec2::new(0.002, 0.5), -0.004), 2.0 * 0.5, 0.0));
        let block = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let mut b = contact();
        assert!(b.update(&ground, xf_g, &block, Transform::new(Vec2::new(0.0, 0.5), 0.0), 0.02));
        let tipped = Transform::new(Vec2::new(0.0, 0.5), 0.5f32.to_radians());
        assert!(!b.clone().recycle(xf_g, tipped, 2.0 * 0.71, 0.0));
        // And the untouched pair is recycled (the test would prove nothing otherwise).
        assert!(b.recycle(xf_g, Transform::new(Vec2::new(0.0, 0.5), 0.0), 2.0 * 0.71, 0.0));
    }

    /// Steps a pair through `poses(k)` (A's, B's) for `steps` steps, as the narrow phase
    /// does: each step the contact is either judged still apart, which a fresh collide at
    /// that pose must confirm (an empty manifold), or collided. Returns (steps judged apart,
    /// of them those the world-axes bound alone would not have judged apart, the step the
    /// pair first touched).
    fn judge_apart(
        a_shape: &Shape,
        b_shape: &Shape,
        steps: usize,
        poses: impl Fn(usize) -> (Transform, Transform),
    ) -> (usize, usize, Option<usize>) {
        use crate::geometry::collide;
        let (reach_a, reach_b) = (a_shape.max_extent(Vec2::ZERO), b_shape.max_extent(Vec2::ZERO));
        let margin = 0.02;
        let mut c = blank_contact();
        let (mut skipped, mut by_relative) = (0, 0);
        for k in 0..steps {
            let (xf_a, xf_b) = poses(k);
            let d = xf_b.p - xf_a.p;
            if c.still_apart(d, xf_a.q, xf_b.q, reach_a, reach_b, margin) {
                skipped += 1;
                assert_eq!(collide(a_shape, xf_a, b_shape, xf_b, margin).count, 0, "step {k}");
                let Memo::Far { bound, poses: f } = c.memo else {
                    unreachable!()
                };
                let turn = |q: Rot, q0: Rot| (Vec2::new(q.c, q.s) - Vec2::new(q0.c, q0.s)).length();
                let world = (d - f.d).length() + reach_a * turn(xf_a.q, f.q_a) + reach_b * turn(xf_b.q, f.q_b);
                by_relative += usize::from(bound - world <= margin);
                continue;
            }
            if c.update(a_shape, xf_a, b_shape, xf_b, margin) {
                return (skipped, by_relative, Some(k));
            }
        }
        (skipped, by_relative, None)
    }

    /// Bodies moving as one are judged apart by B's motion in A's frame, which is zero,
    /// and every such verdict is confirmed by a fresh collide; the skips never hide an
    /// approach. Two boxes 3 cm apart (margin 2 cm) turn as one about a pivot 5 m away,
    /// 0.02 rad a step (10 cm of travel), drifting together by 0.1 mm a step: collided at
    /// the first step, then judged apart (the world-axes bound alone, with the origins'
    /// difference turning by 1 cm a step, would have skipped none of them) until the drift
    /// has used up the centimetre left, and touching (a speculative point) once the gap is
    /// under the margin, at step 100. Then B's box, offset 0.35 m from B's origin, turns
    /// about that origin 0.02 rad a step while the pair turns as above, so B's relative turn
    /// times its reach bounds the closing: again every skip confirmed, and the pair touches
    /// as the box swings round to A's face.
    #[test]
    fn bodies_turning_as_one_stay_apart_without_a_collide() {
        let square = |h: f32, at: Vec2| {
            let corners = [Vec2::new(-h, -h), Vec2::new(h, -h), Vec2::new(h, h), Vec2::new(-h, h)];
            Shape::Polygon(Polygon::from_points(&corners.map(|p| p + at), 0.0).unwrap())
        };
        let pivot = Vec2::new(0.0, -5.0);
        let turned = |k: usize, x: f32, spin: f32| {
            let turn = Rot::from_angle(0.02 * k as f32);
            Transform {
                p: pivot + turn.rotate(Vec2::new(x, 5.0) - pivot),
                q: Rot::from_angle(0.02 * k as f32 + spin),
            }
        };
        let a = square(0.25, Vec2::ZERO);
        let drifting = |k: usize| (turned(k, 0.0, 0.0), turned(k, 0.53 - 1e-4 * k as f32, 0.0));
        let (skipped, by_relative, touched) = judge_apart(&a, &a, 130, drifting);
        // The gap reaches the margin at step 100: judged apart at steps 1-99 (less a step
        // or two of rounding near the boundary).
        assert!((97..=99).contains(&skipped), "judged apart at {skipped} steps");
        assert_eq!(by_relative, skipped);
        // The gap is 3 cm − 0.1 mm · k, under the 2 cm margin from step 101.
        assert!(
            touched.is_some_and(|k| (99..=101).contains(&k)),
            "touched at {touched:?}"
        );
        // B's box offset from its origin, spinning about it.
        let offset = square(0.1, Vec2::new(0.35, 0.0));
        let spinning = |k: usize| (turned(k, 0.0, 0.0), turned(k, 0.7, 0.02 * k as f32));
        let (skipped, by_relative, touched) = judge_apart(&a, &offset, 200, spinning);
        assert!(
            skipped > 50 && by_relative > 0,
            "{skipped} skipped, {by_relative} by the relative bound"
        );
        assert!(touched.is_some(), "the box never reached A");
    }

    #[test]
    fn a_pair_judged_still_apart_has_no_manifold_point() {
        // A box turning and drifting towards another along a wobbly path, 0.5 mm to 3 cm per
        // step: every step the contact either is judged still apart (its bound minus the
        // motion since exceeds the margin) or is collided. Whenever it is judged apart, a
        // fresh collide at that pose must be empty, and the pair must end up collided and
        // touching (the skip never hides the approach).
        use crate::geometry::collide;
        let a_shape = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let b_shape = Shape::Polygon(Polygon::new_box(0.3, 0.2).unwrap());
        let reach_a = a_shape.max_extent(Vec2::ZERO);
        let reach_b = b_shape.max_extent(Vec2::ZERO);
        let mut c = blank_contact();
        let margin = 0.02;
        let (mut skipped, mut touched) = (0, false);
        for k in 0..400 {
            let t = k as f32;
            let xf_a = Transform::new(Vec2::new(0.0, 0.01 * (0.3 * t).sin()), 0.002 * t);
            let gap = 2.0 - 0.005 * t;
            let xf_b = Transform::new(Vec2::new(gap, 0.3 * (0.05 * t).sin()), 0.01 * t);
            let d = xf_b.p - xf_a.p;
            if c.still_apart(d, xf_a.q, xf_b.q, reach_a, reach_b, margin) {
                skipped += 1;
                assert_eq!(collide(&a_shape, xf_a, &b_shape, xf_b, margin).count, 0, "step {k}");
                continue;
            }
            if c.update(&a_shape, xf_a, &b_shape, xf_b, margin) {
                touched = true;
                break;
            }
        }
        assert!(touched, "the boxes never touched");
        assert!(skipped > 100, "only {skipped} steps skipped");
    }
}
