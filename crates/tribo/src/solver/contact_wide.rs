//! The wide contact solver: graph colouring and four contacts per SIMD lane group (eight
//! in the build for AVX2, `solver::lanes8`: [`LANES`]; "four" below reads as `LANES`, and
//! the byte counts as those of four lanes).
//!
//! The physics is exactly the scalar contact constraint's ([`crate::solver::contact_solver`]: soft
//! normal rows with preload, 2×2 block solve, patch friction with stick/slip and the drift
//! anchor, rolling resistance); this module only changes the order and the layout:
//!
//! * **Graph colouring** (Box2D v3's `constraint_graph.c`, greedy first fit): constraints in
//!   one colour share no moving body, so their order inside the colour does not matter and
//!   four of them can be solved at once. Constraints between two moving bodies take the
//!   lowest free colour; constraints with a static or kinematic side take the highest free
//!   colour, so each pass solves them last (the ground has the last word, as in Box2D).
//!   A constraint that finds no colour goes to the overflow list, solved by the scalar code
//!   before the coloured work of each pass.
//! * **Wide layout**: four constraints as structure-of-arrays ([`FL`] lanes), in six
//!   arrays by use: [`WideHead`] (bodies, normal, masses, impulses: what every pass
//!   reads), [`WideArms`] (the points' anchors: the warm start, restitution and the store),
//!   [`WideContact`] (the rest the solve passes read), [`WideDerived`] (what the solve
//!   passes would derive again in every pass, made once a step), [`WideRare`] (what only
//!   groups with restitution, rolling resistance or a surface speed use, touched by the
//!   passes only there) and [`WideCold`] (what only build, restitution and store read).
//!   The passes are bound by the bytes they stream in large scenes (large_pyramid's groups
//!   are megabytes, beyond L2): each streams only the arrays it reads. Every lane has two
//!   points; a one-point manifold has a second point with zero mass, anchors and
//!   impulses, which then changes nothing. Friction is one
//!   row per lane: the patch row at the middle of a two-point manifold, or the point row
//!   of a one-point manifold (the same row with one point). Empty lanes of the last group
//!   of a colour use the static body (index 0) on both sides and zero masses.
//! * Body velocities are gathered from `BodyState` into lanes and scattered back; only
//!   dynamic bodies are written (no two lanes of a colour share one).
//!
//! A lane computes the same expressions as the scalar code in the same order of
//! operations, so a contact solved wide or scalar gets the same numbers: to the bit for
//! the build, the store, restitution and one-point rows; the scalar 2×2 block rounds its
//! own way (an ulp or a few tens of ulps after a pass), so a two-point lane solved wide
//! agrees with the scalar solve to 1e-4 (`two_point_solve_matches_scalar_solve`). A
//! contact is solved one way for a whole step.

use super::wide::{array_of, lanes_to_rows, rows_to_lanes, unrolled, F4, FL, LANES, ML, VL};
use crate::collision::contact::{Contact, ContactSums, FrictionState, PointState, PointSums};
use crate::math::Vec2;
use crate::solver::contact_solver::{
    fresh_point_sticks, kinetic_energy_of, ConstraintBodies, ConstraintPoint, ContactConstraint, ContactInput,
    StepSoftness, INPUT_FRESH, INPUT_STICK,
};
use crate::solver::{StateCell, StateRead, StepContext};

/// Number of colours (Box2D v3 uses 24, the last for overflow).
pub(crate) const COLORS: usize = 24;
/// Colours open to constraints between two moving bodies (the rest, counted from the top,
/// are for constraints with a static or kinematic side).
pub(crate) const DYNAMIC_COLORS: usize = 20;

/// One point of four constraints: what only the solve passes read (the warm start's part
/// is in [`HeadPoint`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WidePoint {
    pub base_separation: FL,
    pub normal_mass: FL,
    pub preload: FL,
    pub total_normal_impulse: FL,
    pub max_normal_impulse: FL,
}

/// One point of four constraints: what the warm start reads and the solve passes and
/// restitution read and write (its anchors are in [`WideArms`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HeadPoint {
    pub normal_impulse: FL,
}

/// The part of four constraints every pass reads (bodies, normal, masses, impulses), kept
/// in its own array: with [`WideArms`] all the warm start streams but in groups with
/// restitution or rolling resistance (it is bound by memory traffic, not arithmetic), 480
/// bytes a group of eight lanes.
///
/// [`build_group`] writes every field, with no clearing first (as for [`WideContact`]): a
/// field added here must be written there, and poisoned in the test `build_writes_every_field`
/// (which does not compile until it is).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideHead {
    pub index_a: [u32; LANES],
    pub index_b: [u32; LANES],
    /// Whether the lane's body A (B) is dynamic, i.e. written back by the scatter.
    pub write_a: [bool; LANES],
    pub write_b: [bool; LANES],
    pub any_rolling: bool,
    /// Some lane has restitution: only then do the passes record the points' approach
    /// speeds (what restitution reads, in [`WideRare`]).
    pub any_restitution: bool,
    /// Some lane has a surface speed (a conveyor): only then do the passes read it (in
    /// [`WideRare`]; +0.0 in every lane otherwise).
    pub any_surface_speed: bool,
    pub normal: VL,
    pub inv_mass_a: FL,
    pub inv_i_a: FL,
    pub inv_mass_b: FL,
    pub inv_i_b: FL,
    pub split: FL,
    /// `ContactConstraint::shift_cap2` of each lane (`contact_solver::capped_shift`).
    pub shift_cap2: FL,
    pub points: [HeadPoint; 2],
    /// Friction impulse of the row (sum over the points) [N·s].
    pub tangent_impulse: FL,
    /// Lanes with a two-point manifold: the friction row sits at the patch middle and each
    /// point reports half its impulse (one point: the whole).
    pub two_points: ML,
}

/// One point's anchors in four constraints, from the bodies' centres at the step start
/// (r_a, r_b) [m].
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PointArms {
    pub r_a: VL,
    pub r_b: VL,
}

/// The points' anchors of four constraints: what the warm start, restitution and the
/// store read, but not the solve passes (they read the anchors' moments in
/// [`WideDerived`]). In an array of their own, not in [`WideHead`]: the solve and relax
/// passes stream their groups from beyond the L2 cache in large scenes (large_pyramid's
/// 1 873 groups were 3.6 MB with the anchors, 2.6 MB now), and lines they do not read but that lie among those they do
/// are streamed as well (256 unread bytes added to each [`WideContact`] made
/// large_pyramid's solve and relax 9–10 % slower). Written by the build and [`pack`] only.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideArms {
    pub points: [PointArms; 2],
}

/// What only some groups use: restitution's speeds, the rolling resistance row, the
/// surface speed. In an array of its own (as [`WideArms`]): the passes touch a group's
/// only where its flags say the group uses it ([`WideHead::any_restitution`],
/// `any_rolling`, `any_surface_speed`), so the groups without them do not stream these
/// 224 bytes (8 lanes) in every pass. The build and [`pack`] write all of it, the unpacks
/// read all of it, the store reads the approach speeds, the rolling impulse and the
/// surface speed.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideRare {
    /// `ConstraintPoint::approach` of each point, tracked only in groups with restitution
    /// (0 elsewhere: a point without restitution never bounces, whatever its approach).
    pub approach: [FL; 2],
    /// `ConstraintPoint::substep_vn` of each point, recorded only in groups with
    /// restitution.
    pub substep_vn: [FL; 2],
    /// Rolling resistance impulse [N·m·s] (warm start).
    pub rolling_impulse: FL,
    /// Rolling resistance coefficient (`ContactConstraint::rolling_resistance`).
    pub rolling_resistance: FL,
    /// Surface speed along the tangent [m/s] (`ContactConstraint::tangent_speed`).
    pub tangent_speed: FL,
}

/// The rest of four contact constraints, one per lane (see the module docs): what only
/// the solve passes read.
///
/// What costs a few instructions to derive is not stored here (the build writes these
/// records and the store reads them: every step streams them): the softness (from whether
/// a side is static), 1/k11 and 1/k22 (the points' normal masses where the block applies)
/// and the rolling mass (from the inverse inertias) are derived where they are used; K⁻¹,
/// the moments of the friction row's anchors and those of each point's anchors about the
/// normal, which every pass would derive, are in the group's [`WideDerived`]; what only
/// some groups use is in [`WideRare`]. 320 bytes with four lanes (was 400, and 608 before
/// that).
/// [`build_group`] writes every field (see [`WideHead`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideContact {
    /// Friction coefficient of the row this step: μs where it sticks, μd where it slides.
    pub mu: FL,
    pub points: [WidePoint; 2],
    /// Normal-row matrix K (2-point manifolds with `block`, else 0); 1/det K is in
    /// [`WideCold`] (the passes read K⁻¹ in [`WideDerived`]).
    pub k11: FL,
    pub k12: FL,
    pub k22: FL,
    pub block: ML,
    pub tangent_mass: FL,
    pub base_drift: FL,
    pub stick: ML,
    pub total_tangent_impulse: FL,
    pub saturated: ML,
}

/// The parts of four constraints the substeps do not touch (kept apart so the hot
/// [`WideContact`]s stay small): what the scalar code needs to rebuild a lane.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideCold {
    pub contact: [u32; LANES],
    /// 1/det K of each lane (where the block applies, else 0).
    pub inv_det: [f32; LANES],
    pub mu_s: [f32; LANES],
    pub mu_d: [f32; LANES],
    /// Manifold points of each lane (0 for an empty lane).
    pub count: [u8; LANES],
    pub restitution: [f32; LANES],
    pub restitution_threshold: [f32; LANES],
    pub kinetic_energy: [f32; LANES],
    pub height: [f32; LANES],
    pub base_drift: [[f32; LANES]; 2],
    pub stick: [[bool; LANES]; 2],
    pub fresh: [[bool; LANES]; 2],
    /// Some lane has restitution.
    pub any_restitution: bool,
}

/// What every pass of a step would derive again from a group's [`WideHead`], [`WideArms`]
/// and [`WideContact`] (and 1/det K, in [`WideCold`]), made once a step
/// ([`WideDerived::new`]) and kept in an array of its own: the moments of the friction
/// row's anchors and of each point's anchors about the normal, and K⁻¹ = [k22, −k12; −k12,
/// k11] / det K (zero where the block does not apply). Only the passes and restitution read
/// it; the build (or [`pack`]) writes it and the store does not touch it, so the store does
/// not stream it with the groups. (Kept inside [`WideContact`] it made large_pyramid's step
/// 2.5 % faster but many_pyramids' 3 % slower: its build and store streamed the bigger
/// records.)
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WideDerived {
    /// The friction row's anchors' moments about the tangent t = (n.y, −n.x),
    /// (fr_a × t, fr_b × t) [m] (what the passes' [`RowFrame`] needs of them: 32 bytes
    /// instead of the anchors' 64, and two cross products a pass fewer).
    pub fr_moments: (FL, FL),
    /// Each point's anchors' moments about the normal, (r_a × n, r_b × n) [m]: what
    /// [`RowFrame::point`] derived from the anchors in each pass, now read through
    /// [`RowFrame::point_of`] (the arms' four coordinates are not loaded, and two cross
    /// products a point and pass fewer; ±0 for an absent point).
    pub normal_moments: [(FL, FL); 2],
    pub i11: FL,
    pub i12: FL,
    pub i22: FL,
}

impl WideDerived {
    /// From the group's friction anchors ([`friction_arms`]), tangent `t`, its normal (in
    /// `h`), its points' anchors (`arms`), its K (in `w`) and 1/det K (`inv_det`): the
    /// expressions the passes evaluated each time, so the same bits.
    #[inline(always)]
    fn new(friction: (VL, VL), t: VL, h: &WideHead, arms: &WideArms, w: &WideContact, inv_det: FL) -> WideDerived {
        WideDerived {
            fr_moments: moments(friction, t),
            // Spelled out, not `map`ped (see `point_impulse`).
            normal_moments: [
                moments((arms.points[0].r_a, arms.points[0].r_b), h.normal),
                moments((arms.points[1].r_a, arms.points[1].r_b), h.normal),
            ],
            i11: w.k22 * inv_det,
            i12: -w.k12 * inv_det,
            i22: w.k11 * inv_det,
        }
    }
}

// What the hot passes stream per group of four constraints (bytes).
// (In vectors of lanes: 144, 320 and 240 bytes with four lanes, twice that with eight;
// the warm start's anchors 128, the rare part 112.)
const VECTOR: usize = core::mem::size_of::<FL>();
const _: () = assert!(core::mem::size_of::<WideDerived>() == 9 * VECTOR);
const _: () = assert!(core::mem::size_of::<WideContact>() == 20 * VECTOR);
const _: () = assert!(core::mem::size_of::<WideHead>() == 15 * VECTOR);
const _: () = assert!(core::mem::size_of::<WideRare>() == 7 * VECTOR);
const _: () = assert!(core::mem::size_of::<WideArms>() == 8 * VECTOR);

/// Four bodies' velocities and step motion, gathered from `BodyState`s.
#[derive(Clone, Copy, Debug)]
struct WideBody {
    v: VL,
    w: FL,
    touched: FL,
    dp: VL,
    /// sin of the rotation since the step start.
    dq_s: FL,
}

/// Gathers four bodies: each state's two 16-byte halves (v, w, touched; dp, dq) as rows,
/// transposed into lanes.
#[inline(always)]
fn gather<S: StateRead>(states: &[S], idx: &[u32; LANES]) -> WideBody {
    // Lane by lane, written out (`unrolled`): `idx.map(…)` over eight lanes was compiled
    // as a call, and a loop was not always unrolled (the warm start's was left rolled,
    // 0.22 → 0.35 ms in large_pyramid); either way the rows went through the stack.
    let s: [[F4; 2]; LANES] = unrolled(|l| states[idx[l] as usize].rows());
    let [vx, vy, w, touched] = rows_to_lanes(array_of(|l| s[l][0]));
    let [dpx, dpy, _, dq_s] = rows_to_lanes(array_of(|l| s[l][1]));
    WideBody {
        v: VL { x: vx, y: vy },
        w,
        touched,
        dp: VL { x: dpx, y: dpy },
        dq_s,
    }
}

/// Writes the velocities of the lanes' dynamic bodies back (the transpose of [`gather`]'s
/// first half).
#[inline(always)]
fn scatter<S: StateCell>(states: &[S], idx: &[u32; LANES], write: &[bool; LANES], b: &WideBody) {
    let rows = lanes_to_rows([b.v.x, b.v.y, b.w, b.touched]);
    // Every lane's body is dynamic in most groups (all but those against the ground or a
    // kinematic body): one test of all the flags (one word compare), not a branch per lane
    // (a single loop testing `all || write[l]` was not split by the compiler: +2 % solve
    // instructions).
    if *write == [true; LANES] {
        for l in 0..LANES {
            states[idx[l] as usize].set_velocity_row(rows[l]);
        }
        return;
    }
    for l in 0..LANES {
        if write[l] {
            states[idx[l] as usize].set_velocity_row(rows[l]);
        }
    }
}

/// Lever arms of a pass (the anchors moved to their common point, see
/// `contact_solver::lever_arms`).
#[inline(always)]
fn lever_arms(c: &WideHead, d: VL, r_a: VL, r_b: VL) -> (VL, VL) {
    let one = FL::splat(1.0);
    (r_a + d.scale(c.split), r_b - d.scale(one - c.split))
}

/// The relative displacement the lever arms follow (`contact_solver::capped_shift`, lane
/// by lane; the square root only when some lane is over its cap).
#[inline(always)]
fn capped_shift(c: &WideHead, d: VL) -> VL {
    let d2 = d.x * d.x + d.y * d.y;
    let over = d2.gt(c.shift_cap2);
    if !over.any() {
        return d;
    }
    d.scale(over.select((c.shift_cap2 / d2).sqrt(), FL::splat(1.0)))
}

#[inline(always)]
fn relative_velocity(a: &WideBody, b: &WideBody, r_a: VL, r_b: VL) -> VL {
    let vb = VL {
        x: b.v.x - b.w * r_b.y,
        y: b.v.y + b.w * r_b.x,
    };
    let va = VL {
        x: a.v.x - a.w * r_a.y,
        y: a.v.y + a.w * r_a.x,
    };
    vb - va
}

#[inline(always)]
fn apply(c: &WideHead, a: &mut WideBody, b: &mut WideBody, r_a: VL, r_b: VL, p: VL) {
    a.v = a.v - p.scale(c.inv_mass_a);
    a.w -= c.inv_i_a * r_a.cross(p);
    b.v = b.v + p.scale(c.inv_mass_b);
    b.w += c.inv_i_b * r_b.cross(p);
}

/// The arms' moments about a row direction `u`: (r_a × u, r_b × u).
#[inline(always)]
fn moments((r_a, r_b): (VL, VL), u: VL) -> (FL, FL) {
    (r_a.cross(u), r_b.cross(u))
}

/// A row direction's part of a pass that the points share: the displacement d·u
/// [m] and the moments the shift adds to the arms (`lever_arms`: r_a + σ s and
/// r_b − (1 − σ) s give r_a × u + σ (s × u) and r_b × u − (1 − σ)(s × u)).
#[derive(Clone, Copy)]
struct RowFrame {
    u: VL,
    along: FL,
    shift_a: FL,
    shift_b: FL,
}

impl RowFrame {
    #[inline(always)]
    fn new(h: &WideHead, d: VL, shift: VL, u: VL) -> RowFrame {
        let su = shift.cross(u);
        RowFrame {
            u,
            along: d.dot(u),
            shift_a: h.split * su,
            shift_b: (FL::splat(1.0) - h.split) * su,
        }
    }

    /// The moments of a point's lever arms (anchors `r_a`, `r_b` at the step start) and
    /// the first-order displacement of its material points along `u` [m]
    /// (`contact_solver::RowFrame::point`: d·u + sin Δθ_b (r_b × u) − sin Δθ_a (r_a × u)).
    #[inline(always)]
    fn point(&self, a: &WideBody, b: &WideBody, r_a: VL, r_b: VL) -> ((FL, FL), FL) {
        self.point_of(a, b, moments((r_a, r_b), self.u))
    }

    /// [`RowFrame::point`] from the anchors' moments about `u`, (r_a × u, r_b × u).
    #[inline(always)]
    fn point_of(&self, a: &WideBody, b: &WideBody, (ma, mb): (FL, FL)) -> ((FL, FL), FL) {
        let disp = self.along + b.dq_s * mb - a.dq_s * ma;
        ((ma + self.shift_a, mb - self.shift_b), disp)
    }
}

/// The relative velocity along a row direction `u` at arms of moments `m` (`moments`):
/// u·(v_b − v_a) + ω_b (r_b × u) − ω_a (r_a × u), what `relative_velocity(..).dot(u)`
/// is with fewer operations and two registers per point instead of four
/// (`contact_solver::row_speed`, the same expression).
#[inline(always)]
fn row_speed(a: &WideBody, b: &WideBody, u: VL, m: (FL, FL)) -> FL {
    (b.v - a.v).dot(u) + b.w * m.1 - a.w * m.0
}

/// Applies the impulse `lambda` along a row direction `u` at arms of moments `m`:
/// −u·λ to A, +u·λ to B (`contact_solver::apply_row`, the same expression).
#[inline(always)]
fn apply_row(c: &WideHead, a: &mut WideBody, b: &mut WideBody, u: VL, m: (FL, FL), lambda: FL) {
    a.v = a.v - u.scale(c.inv_mass_a * lambda);
    a.w -= c.inv_i_a * (m.0 * lambda);
    b.v = b.v + u.scale(c.inv_mass_b * lambda);
    b.w += c.inv_i_b * (m.1 * lambda);
}

/// The friction row's anchors: the middle of a two-point patch, else the single point
/// (`contact_solver::build_constraint`'s patch row; the same expression).
#[inline(always)]
fn friction_arms(h: &WideHead, arms: &WideArms) -> (VL, VL) {
    let [p0, p1] = &arms.points;
    (
        patch_anchor(h.two_points, p0.r_a, p1.r_a),
        patch_anchor(h.two_points, p0.r_b, p1.r_b),
    )
}

/// The middle of `p` and `q` where `two` (a two-point patch), else `p` (a function, not a
/// closure: see [`point_impulse`]).
#[inline(always)]
fn patch_anchor(two: ML, p: VL, q: VL) -> VL {
    let mid = (p + q).scale(FL::splat(0.5));
    VL {
        x: two.select(mid.x, p.x),
        y: two.select(mid.y, p.y),
    }
}

/// The share of the row's friction impulse point `i` carries (½ each of two points, all of
/// one; an empty lane's impulse is zero, whatever its share).
#[inline(always)]
fn tangent_share(h: &WideHead, i: usize) -> FL {
    let half = FL::splat(0.5);
    if i == 0 {
        h.two_points.select(half, FL::splat(1.0))
    } else {
        h.two_points.select(half, FL::ZERO)
    }
}

/// Lanes with a static side (index 0): their contacts are twice as stiff (Box2D v3's
/// static softness, `contact_solver::build_constraint`).
#[inline(always)]
fn static_lanes(h: &WideHead) -> ML {
    ML::either_zero(h.index_a, h.index_b)
}

/// The softness of each lane: (bias rate, mass scale, impulse scale).
#[inline(always)]
fn lane_softness(h: &WideHead, soft: &StepSoftness) -> (FL, FL, FL) {
    let fixed = static_lanes(h);
    let (s, c) = (&soft.static_contact, &soft.contact);
    // (Spelled out, not a closure: see `point_impulse`.)
    (
        fixed.select(FL::splat(s.bias_rate), FL::splat(c.bias_rate)),
        fixed.select(FL::splat(s.mass_scale), FL::splat(c.mass_scale)),
        fixed.select(FL::splat(s.impulse_scale), FL::splat(c.impulse_scale)),
    )
}

/// Point `i`'s impulse λn_i n + λt_i t ([`warm_start`]). A function, not a closure: in the
/// eight-lane build only functions marked `lane_fn` and what is always inlined into them
/// are compiled for AVX2; a closure inside an always-inlined function is not, and may stay
/// out of line (as may one given to `array::map`).
#[inline(always)]
fn point_impulse(c: &WideHead, n: VL, t: VL, i: usize) -> VL {
    n.scale(c.points[i].normal_impulse) + t.scale(c.tangent_impulse * tangent_share(c, i))
}

/// Re-applies the accumulated impulses at the start of a substep and, in a group with
/// restitution, records each point's normal velocity before them (restitution's impact
/// speed; the only reader, so a group without restitution skips it: large_pyramid's warm
/// start went from 0.305 to 0.279 ms per step).
#[super::lane_inline]
pub(crate) fn warm_start<S: StateCell>(c: &WideHead, arms: &WideArms, rare: &mut WideRare, states: &[S]) {
    let n = c.normal;
    let t = n.right_perp();
    // Both points' impulses P_i = λn_i n + λt_i t at once: the bodies take their sum P and
    // its moments Σ r_i × P_i, the shifted arms' r_a + σ s and r_b − (1 − σ) s
    // (`lever_arms`) adding σ (s × P) and −(1 − σ)(s × P); the arms themselves are never
    // formed (large_pyramid: 274 → 256 instructions a group and substep, warm start
    // 0.183 → 0.169 ms a step). What does not depend on the bodies is made before they are
    // gathered: the head's loads then overlap the gather's instead of waiting behind it
    // (warm start −6 % in large_pyramid and tumbler, the same instructions).
    let (p0, p1) = (point_impulse(c, n, t, 0), point_impulse(c, n, t, 1));
    let total = p0 + p1;
    let [r0, r1] = &arms.points;
    let arms_a = r0.r_a.cross(p0) + r1.r_a.cross(p1);
    let arms_b = r0.r_b.cross(p0) + r1.r_b.cross(p1);
    let mut a = gather(states, &c.index_a);
    let mut b = gather(states, &c.index_b);
    let shift = capped_shift(c, b.dp - a.dp);
    if c.any_restitution {
        for i in 0..2 {
            let p = &arms.points[i];
            let (r_a, r_b) = lever_arms(c, shift, p.r_a, p.r_b);
            rare.substep_vn[i] = relative_velocity(&a, &b, r_a, r_b).dot(n);
        }
    }
    let turn = shift.cross(total);
    let moment_a = arms_a + c.split * turn;
    let moment_b = arms_b - (FL::splat(1.0) - c.split) * turn;
    a.v = a.v - total.scale(c.inv_mass_a);
    a.w -= c.inv_i_a * moment_a;
    b.v = b.v + total.scale(c.inv_mass_b);
    b.w += c.inv_i_b * moment_b;
    if c.any_rolling {
        a.w -= c.inv_i_a * rare.rolling_impulse;
        b.w += c.inv_i_b * rare.rolling_impulse;
    }
    scatter(states, &c.index_a, &c.write_a, &a);
    scatter(states, &c.index_b, &c.write_b, &b);
}

/// Restitution for four constraints after the substeps: `contact_solver::restitution_one`
/// in every lane at once, with its arithmetic and its order (the face block where both
/// points of a two-point lane bounce and the block has a solution, else the bouncing
/// points in turn, each capped so the pair gains no kinetic energy); lanes and points
/// that do not bounce keep their impulses and velocities bit for bit. Unpacking each
/// bouncing lane into a scalar constraint cost 1.4 ms of a 24 ms step in Box2D's spinner,
/// where half the lanes bounce.
#[super::lane_fn]
pub(crate) fn restitution<S: StateCell>(
    h: &mut WideHead,
    anchors: &WideArms,
    rare: &WideRare,
    w: &mut WideContact,
    dv: &WideDerived,
    cold: &WideCold,
    states: &[S],
) {
    let zero = FL::ZERO;
    let e = FL::new(cold.restitution);
    let minus_threshold = -FL::new(cold.restitution_threshold);
    // `contact_solver::bounces` of each point (absent points never bounce).
    let bounces: [ML; 2] = array_of(|i| {
        let p = &w.points[i];
        ML::from_bools(array_of(|l| cold.count[l] as usize > i))
            & e.gt(zero)
            & minus_threshold.ge(rare.approach[i])
            & p.max_normal_impulse.gt(zero)
    });
    if !(bounces[0] | bounces[1]).any() {
        return;
    }
    let mut a = gather(states, &h.index_a);
    let mut b = gather(states, &h.index_b);
    // The bodies' displacements do not change here: nor do the lever arms.
    let shift = capped_shift(h, b.dp - a.dp);
    let arms: [(VL, VL); 2] = array_of(|i| lever_arms(h, shift, anchors.points[i].r_a, anchors.points[i].r_b));
    let n = h.normal;
    let normal_velocity = |a: &WideBody, b: &WideBody, i: usize| relative_velocity(a, b, arms[i].0, arms[i].1).dot(n);
    // Point `i` takes the impulse `new` in the lanes of `m` (elsewhere not even a zero's
    // sign changes).
    let commit =
        |h: &mut WideHead, w: &mut WideContact, m: ML, i: usize, new: FL, a: &mut WideBody, b: &mut WideBody| {
            let lam = h.points[i].normal_impulse;
            let delta = new - lam;
            let (mut a2, mut b2) = (*a, *b);
            apply(h, &mut a2, &mut b2, arms[i].0, arms[i].1, n.scale(delta));
            *a = select_velocity(m, &a2, a);
            *b = select_velocity(m, &b2, b);
            let wp = &mut w.points[i];
            wp.total_normal_impulse = m.select(wp.total_normal_impulse + delta, wp.total_normal_impulse);
            wp.max_normal_impulse = m.select(wp.max_normal_impulse.max(new), wp.max_normal_impulse);
            h.points[i].normal_impulse = m.select(new, lam);
        };
    // Both points of a face bounce: the 2×2 block (`contact_solver::solve_block` with
    // mass scale 1 and impulse scale 0), where it has a solution.
    let face = bounces[0] & bounces[1] & w.block;
    let mut solved = ML::default();
    if face.any() {
        let (lam0, lam1) = (h.points[0].normal_impulse, h.points[1].normal_impulse);
        let (pre0, pre1) = (w.points[0].preload, w.points[1].preload);
        let rhs0 = normal_velocity(&a, &b, 0) + e * rare.approach[0];
        let rhs1 = normal_velocity(&a, &b, 1) + e * rare.approach[1];
        let (k11, k12, k22) = (w.k11, w.k12, w.k22);
        let (i11, i12, i22) = (dv.i11, dv.i12, dv.i22);
        let (one, none) = (FL::splat(1.0), FL::ZERO);
        let soft0 = |rd: FL| lam0 + one * rd - none * (lam0 - pre0);
        let soft1 = |rd: FL| lam1 + one * rd - none * (lam1 - pre1);
        let xa0 = soft0(-(i11 * rhs0 + i12 * rhs1));
        let xa1 = soft1(-(i12 * rhs0 + i22 * rhs1));
        let ok_a = xa0.ge(zero) & xa1.ge(zero);
        let r0 = rhs0 - k12 * lam1;
        let xb0 = soft0(-r0 / k11);
        let wb1 = rhs1 + k12 * (xb0 - lam0) - k22 * lam1;
        let ok_b = xb0.ge(zero) & wb1.ge(zero);
        let r1 = rhs1 - k12 * lam0;
        let xc1 = soft1(-r1 / k22);
        let wc0 = rhs0 + k12 * (xc1 - lam1) - k11 * lam0;
        let ok_c = xc1.ge(zero) & wc0.ge(zero);
        let wd0 = rhs0 - k11 * lam0 - k12 * lam1;
        let wd1 = rhs1 - k12 * lam0 - k22 * lam1;
        let ok_d = wd0.ge(zero) & wd1.ge(zero);
        let x0 = ok_a.select(xa0, ok_b.select(xb0, zero));
        let x1 = ok_a.select(xa1, (!ok_b & ok_c).select(xc1, zero));
        solved = face & (ok_a | ok_b | ok_c | ok_d);
        commit(h, w, solved, 0, x0, &mut a, &mut b);
        commit(h, w, solved, 1, x1, &mut a, &mut b);
    }
    // Elsewhere the bouncing points in turn.
    for (i, &bounce) in bounces.iter().enumerate() {
        let m = bounce & !solved;
        if !m.any() {
            continue;
        }
        let vn = normal_velocity(&a, &b, i);
        let (r_a, r_b) = arms[i];
        let (ra, rb) = (r_a.cross(n), r_b.cross(n));
        let k = h.inv_mass_a + h.inv_mass_b + h.inv_i_a * ra * ra + h.inv_i_b * rb * rb;
        let normal_mass = k.gt(zero).select(FL::splat(1.0) / k, zero);
        let mut impulse = -normal_mass * (vn + e * rare.approach[i]);
        // The energy cap: λ ≤ m_n (−vn + √(vn² + 2 room / m_n)), room = KE₀ − KE.
        let capped = impulse.gt(zero) & normal_mass.gt(zero);
        if (capped & m).any() {
            let room = FL::new(cold.kinetic_energy) - kinetic_energy(h, &a, &b);
            let disc = vn * vn + FL::splat(2.0) * room / normal_mass;
            let max = disc.gt(zero).select(normal_mass * (-vn + disc.sqrt()), zero);
            impulse = capped.select(impulse.min(max.max(zero)), impulse);
        }
        let new = (h.points[i].normal_impulse + impulse).max(zero);
        commit(h, w, m, i, new, &mut a, &mut b);
    }
    scatter(states, &h.index_a, &h.write_a, &a);
    scatter(states, &h.index_b, &h.write_b, &b);
}

/// `x`'s velocities in the lanes of `m`, `y`'s elsewhere.
#[inline(always)]
fn select_velocity(m: ML, x: &WideBody, y: &WideBody) -> WideBody {
    WideBody {
        v: VL {
            x: m.select(x.v.x, y.v.x),
            y: m.select(x.v.y, y.v.y),
        },
        w: m.select(x.w, y.w),
        ..*y
    }
}

/// The pair's kinetic energy [J] in each lane (`contact_solver::kinetic_energy_of`, the
/// same expression).
#[inline(always)]
fn kinetic_energy(h: &WideHead, a: &WideBody, b: &WideBody) -> FL {
    kinetic_part(h.inv_mass_a, h.inv_i_a, a) + kinetic_part(h.inv_mass_b, h.inv_i_b, b)
}

/// One body's part of [`kinetic_energy`] (a function, not a closure: see
/// [`point_impulse`]).
#[inline(always)]
fn kinetic_part(inv_m: FL, inv_i: FL, s: &WideBody) -> FL {
    let (zero, half) = (FL::ZERO, FL::splat(0.5));
    let lin = inv_m
        .gt(zero)
        .select(half * (s.v.x * s.v.x + s.v.y * s.v.y) / inv_m, zero);
    let ang = inv_i.gt(zero).select(half * s.w * s.w / inv_i, zero);
    lin + ang
}

/// A point's sequential normal row (`contact_solver::normal_row`): from impulse `lam`, with
/// normal mass `mass`, right-hand side `rhs` and its softness (`ms`, `is`, preload `pre`),
/// clamped at zero. (Functions, not closures: see [`point_impulse`].)
#[inline(always)]
fn sequential_row(lam: FL, mass: FL, ms: FL, rhs: FL, is: FL, pre: FL) -> FL {
    (lam + (-(mass * ms * rhs) - is * (lam - pre))).max(FL::ZERO)
}

/// A point's impulse in the 2×2 block (`contact_solver::solve_block`'s soft form): from
/// impulse `lam` and the block's rigid solution's change `rd`.
#[inline(always)]
fn soft_row(lam: FL, ms: FL, is: FL, pre: FL, rd: FL) -> FL {
    lam + ms * rd - is * (lam - pre)
}

/// The normal rows of one pass over four constraints (contact_solver::normal_row): bias
/// and softness per point, then the 2×2 block or the points in turn; returns the points'
/// new impulses. `POINTS` = 1 for a group with no second point in any lane (see
/// `contact_set::SINGLE`): only the first point's row, what the general path computes for
/// such lanes (the sequential row), with the second point's impulse +0 (its mass, impulse
/// and preload are zero, so that row gives +0). A constant, so each form's loops unroll.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn normal_rows<const USE_BIAS: bool, const POINTS: usize>(
    h: &mut WideHead,
    rare: &mut WideRare,
    c: &mut WideContact,
    dv: &WideDerived,
    a: &mut WideBody,
    b: &mut WideBody,
    d: VL,
    shift: VL,
    ctx: &StepContext,
    (bias_rate, mass_scale, impulse_scale): (FL, FL, FL),
) -> ((FL, FL), [(FL, FL); 2]) {
    let n = h.normal;
    let zero = FL::ZERO;
    let one = FL::splat(1.0);
    let push = FL::splat(ctx.push_speed);
    let frame = RowFrame::new(h, d, shift, n);
    // Each point's arm moments about the normal (`WideDerived::normal_moments`, through
    // `RowFrame::point_of`).
    let mut rn = [(zero, zero); 2];
    let mut vn = [zero; 2];
    let mut bias = [zero; 2];
    let mut ms = [zero; 2];
    let mut is = [zero; 2];
    for i in 0..POINTS {
        let p = &c.points[i];
        let (m, disp) = frame.point_of(a, b, dv.normal_moments[i]);
        rn[i] = m;
        let s = disp + p.base_separation;
        let speculative = s.gt(zero);
        let (soft_bias, soft_ms, soft_is) = if USE_BIAS {
            ((bias_rate * s).max(-push), mass_scale, impulse_scale)
        } else {
            (zero, one, zero)
        };
        bias[i] = speculative.select(s * FL::splat(ctx.inv_h), soft_bias);
        ms[i] = speculative.select(one, soft_ms);
        is[i] = speculative.select(zero, soft_is);
        vn[i] = row_speed(a, b, n, rn[i]);
    }
    let [p0, p1] = &c.points;
    let (lam0, lam1) = (h.points[0].normal_impulse, h.points[1].normal_impulse);
    let (pre0, pre1) = (p0.preload, p1.preload);
    let rhs0 = vn[0] + bias[0];
    let (new0, new1) = if POINTS == 1 {
        // The sequential row of the first point (the general path's `seq0`).
        let seq0 = sequential_row(lam0, p0.normal_mass, ms[0], rhs0, is[0], pre0);
        apply_row(h, a, b, n, rn[0], seq0 - lam0);
        (seq0, zero)
    } else {
        // The 2×2 block LCP (contact_solver::solve_block), all four cases in every lane.
        let rhs1 = vn[1] + bias[1];
        // K⁻¹ (zero where the block does not apply).
        let (i11, i12, i22) = (dv.i11, dv.i12, dv.i22);
        let xa0 = soft_row(lam0, ms[0], is[0], pre0, -(i11 * rhs0 + i12 * rhs1));
        let xa1 = soft_row(lam1, ms[1], is[1], pre1, -(i12 * rhs0 + i22 * rhs1));
        let ok_a = xa0.ge(zero) & xa1.ge(zero);
        if (ok_a & c.block).all() {
            // Common case (a resting face): both points active in every lane.
            apply_row(h, a, b, n, rn[0], xa0 - lam0);
            apply_row(h, a, b, n, rn[1], xa1 - lam1);
            (xa0, xa1)
        } else {
            let r0 = rhs0 - c.k12 * lam1;
            // 1/k11 and 1/k22: the points' normal masses (where the block applies).
            let xb0 = soft_row(lam0, ms[0], is[0], pre0, -(r0 * p0.normal_mass));
            let wb1 = rhs1 + c.k12 * (xb0 - lam0) - c.k22 * lam1;
            let ok_b = xb0.ge(zero) & wb1.ge(zero);
            let r1 = rhs1 - c.k12 * lam0;
            let xc1 = soft_row(lam1, ms[1], is[1], pre1, -(r1 * p1.normal_mass));
            let wc0 = rhs0 + c.k12 * (xc1 - lam1) - c.k11 * lam0;
            let ok_c = xc1.ge(zero) & wc0.ge(zero);
            let wd0 = rhs0 - c.k11 * lam0 - c.k12 * lam1;
            let wd1 = rhs1 - c.k12 * lam0 - c.k22 * lam1;
            let ok_d = wd0.ge(zero) & wd1.ge(zero);
            let block0 = ok_a.select(xa0, ok_b.select(xb0, zero));
            let block1 = ok_a.select(xa1, (!ok_b & ok_c).select(xc1, zero));
            let found = c.block & (ok_a | ok_b | ok_c | ok_d);
            if found.all() {
                // Every lane solved as a block: no sequential rows needed.
                apply_row(h, a, b, n, rn[0], block0 - lam0);
                apply_row(h, a, b, n, rn[1], block1 - lam1);
                (block0, block1)
            } else {
                // Sequential rows where the block solve does not apply.
                let seq0 = sequential_row(lam0, p0.normal_mass, ms[0], rhs0, is[0], pre0);
                let new0 = found.select(block0, seq0);
                apply_row(h, a, b, n, rn[0], new0 - lam0);
                let vn1 = row_speed(a, b, n, rn[1]);
                let seq1 = sequential_row(lam1, p1.normal_mass, ms[1], vn1 + bias[1], is[1], pre1);
                let new1 = found.select(block1, seq1);
                apply_row(h, a, b, n, rn[1], new1 - lam1);
                (new0, new1)
            }
        }
    };
    for ((p, hp), new) in c
        .points
        .iter_mut()
        .zip(h.points.iter_mut())
        .zip([new0, new1])
        .take(POINTS)
    {
        hp.normal_impulse = new;
        p.max_normal_impulse = p.max_normal_impulse.max(new);
    }
    if h.any_restitution {
        for (i, new) in [new0, new1].into_iter().enumerate().take(POINTS) {
            let (vn, approach) = (rare.substep_vn[i], rare.approach[i]);
            let lower = new.gt(zero) & vn.lt(approach);
            rare.approach[i] = lower.select(vn, approach);
        }
    }
    ((new0, new1), rn)
}

/// One pass over four constraints: normal rows (block or sequential), the friction row,
/// rolling resistance in the relax pass. Inlined into the colour loops: called once per
/// group, it re-broadcast the loop's invariants (context, softness, elapsed time) and
/// spilled them every group (solve 0.69 → 0.66 ms, relax 0.64 → 0.61 in large_pyramid;
/// the warm start is better left a call with four lanes, and inlined with eight).
///
/// Each row works in moment form ([`RowFrame`], [`row_speed`], [`apply_row`]): a point
/// keeps the two moments of its lever arms about the row direction, not the arms' four
/// coordinates, and the displacement along the row is shared by the points. The arm
/// form (the relative velocity dotted with the row, the impulse vector crossed with each
/// arm) needed more operations and more registers than SSE's sixteen hold: large_pyramid
/// ran 4 % fewer instructions, and its solve and relax took 8 % and 10 % less time.
///
/// With `carry` (a relax pass, `USE_BIAS` false; ignored in the biased pass), the group's
/// next warm start is added to its bodies' carry entries ([`carry_warm_start`]); `carry`
/// must have an entry for every state the lanes index.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn solve<const USE_BIAS: bool, S: StateCell>(
    h: &mut WideHead,
    rare: &mut WideRare,
    c: &mut WideContact,
    dv: &WideDerived,
    states: &[S],
    ctx: &StepContext,
    soft: &StepSoftness,
    elapsed: f32,
    carry: Option<&[S]>,
) {
    let mut a = gather(states, &h.index_a);
    let mut b = gather(states, &h.index_b);
    let d = b.dp - a.dp;
    let shift = capped_shift(h, d);
    let n = h.normal;
    let zero = FL::ZERO;
    let one = FL::splat(1.0);
    let push = FL::splat(ctx.push_speed);
    // (bias rate, mass scale, impulse scale); the friction row's bias reads the rate.
    let rows = if USE_BIAS {
        lane_softness(h, soft)
    } else {
        (zero, one, zero)
    };
    let bias_rate = rows.0;
    // The friction row's frame: its arms' moments and the displacement along the tangent
    // read only the step motion (d, the shift, sin Δθ), which the normal rows do not change.
    // Made before them, so what it needs of the step motion is dead across them.
    let t = n.right_perp();
    let (m, disp) = RowFrame::new(h, d, shift, t).point_of(&a, &b, dv.fr_moments);

    // Normal rows; groups of single points skip the second point and the block.
    let ((new0, new1), rn) = if h.two_points.any() {
        normal_rows::<USE_BIAS, 2>(h, rare, c, dv, &mut a, &mut b, d, shift, ctx, rows)
    } else {
        normal_rows::<USE_BIAS, 1>(h, rare, c, dv, &mut a, &mut b, d, shift, ctx, rows)
    };
    if USE_BIAS {
        let pushed = (new0.gt(zero) | new1.gt(zero)).to_unit();
        a.touched = a.touched.max(pushed);
        b.touched = b.touched.max(pushed);
    } else {
        // Only the substep's positions read `touched` (integrate_positions, between the
        // solve and the relax; integrate_velocities clears it): after the relax it is
        // dead, so the relax writes 0 and keeps no register for it.
        a.touched = zero;
        b.touched = zero;
    }

    // Friction row (contact_solver::solve_friction).
    let limit = c.mu * (new0 + new1);
    // +0.0 in every lane of a group without a surface speed (the flag is set by any other
    // bits), so x − 0.0 and 0.0 · elapsed change no bits.
    let tangent_speed = if h.any_surface_speed { rare.tangent_speed } else { zero };
    let vt = row_speed(&a, &b, t, m) - tangent_speed;
    let fbias = if USE_BIAS {
        let drift = disp + c.base_drift - tangent_speed * FL::splat(elapsed);
        let rate = bias_rate * drift;
        (c.stick & limit.gt(zero)).select(rate.clamp(-push, push), zero)
    } else {
        zero
    };
    let old = h.tangent_impulse;
    let unclamped = old + -(c.tangent_mass * (vt + fbias));
    let new = unclamped.clamp(-limit, limit);
    apply_row(h, &mut a, &mut b, t, m, new - old);
    h.tangent_impulse = new;
    if !USE_BIAS {
        // The relax pass ends the substep: add its impulses to the step totals.
        c.points[0].total_normal_impulse += new0;
        c.points[1].total_normal_impulse += new1;
        c.total_tangent_impulse += new;
        c.saturated = limit.gt(zero) & unclamped.abs().gt(limit);
        if h.any_rolling {
            let rlimit = rare.rolling_resistance * (new0 + new1);
            let k_roll = h.inv_i_a + h.inv_i_b;
            let rolling_mass = k_roll.gt(zero).select(one / k_roll, zero);
            let imp = -(rolling_mass * (b.w - a.w));
            let rnew = (rare.rolling_impulse + imp).clamp(-rlimit, rlimit);
            let delta = rnew - rare.rolling_impulse;
            rare.rolling_impulse = rnew;
            a.w -= h.inv_i_a * delta;
            b.w += h.inv_i_b * delta;
        }
    }
    scatter(states, &h.index_a, &h.write_a, &a);
    scatter(states, &h.index_b, &h.write_b, &b);
    if let (false, Some(carry)) = (USE_BIAS, carry) {
        let moments = [rn[0], rn[1], m];
        carry_warm_start(h, rare, carry, t, moments, [new0, new1, new]);
    }
}

/// The next substep's warm start of four constraints, at the end of the relax pass that
/// set their impulses ([`warm_start`]'s impulses, from the relax's row moments instead
/// of the arms: the same arms, shifted by the same motion, since no position moves
/// between the two), added to their bodies' entries in `carry` (see
/// `solver::solve_step`). `moments`: the two points' normal rows' and the friction row's
/// (r_a × u, r_b × u); `lambda`: their impulses.
#[inline(always)]
fn carry_warm_start<S: StateCell>(
    h: &WideHead,
    rare: &WideRare,
    carry: &[S],
    t: VL,
    moments: [(FL, FL); 3],
    lambda: [FL; 3],
) {
    let total = h.normal.scale(lambda[0] + lambda[1]) + t.scale(lambda[2]);
    let mut moment_a = moments[0].0 * lambda[0] + moments[1].0 * lambda[1] + moments[2].0 * lambda[2];
    let mut moment_b = moments[0].1 * lambda[0] + moments[1].1 * lambda[1] + moments[2].1 * lambda[2];
    if h.any_rolling {
        moment_a += rare.rolling_impulse;
        moment_b += rare.rolling_impulse;
    }
    let mut a = gather(carry, &h.index_a);
    let mut b = gather(carry, &h.index_b);
    a.v = a.v - total.scale(h.inv_mass_a);
    a.w -= h.inv_i_a * moment_a;
    b.v = b.v + total.scale(h.inv_mass_b);
    b.w += h.inv_i_b * moment_b;
    scatter(carry, &h.index_a, &h.write_a, &a);
    scatter(carry, &h.index_b, &h.write_b, &b);
}

/// One lane's constraint to build: its contact index, solver input and bodies.
pub(crate) type LaneInput<'a> = Option<(u32, &'a ContactInput, &'a ConstraintBodies)>;

/// Builds four constraints straight into a group: lane by lane the same numbers as
/// `contact_solver::build_constraint` followed by [`pack`] (the same expressions in the
/// same order), but the masses, the 2×2 block and the friction row are computed four lanes
/// at a time and the group is written whole, not field by field per lane. An empty lane
/// has the static body on both sides, no mass and no impulse: solving it changes nothing.
#[allow(clippy::too_many_arguments)]
#[super::lane_fn]
pub(crate) fn build_group<S: StateRead>(
    head: &mut WideHead,
    anchors: &mut WideArms,
    rare: &mut WideRare,
    w: &mut WideContact,
    cold: &mut WideCold,
    derived: &mut WideDerived,
    lanes: [LaneInput<'_>; LANES],
    up: Vec2,
    ctx: &StepContext,
    states: &[S],
) {
    let warm = ctx.warm_starting;
    let zero = FL::ZERO;
    let one = FL::splat(1.0);
    let half = FL::splat(0.5);
    // Written in place (a 1 KiB group built on the stack and copied costs more), every
    // field of `head`, `anchors`, `rare` and `w` once, with no clearing first: clearing them was two
    // `memset` calls a group, 84 instructions of large_pyramid's ~1 200 (the test
    // `build_writes_every_field` builds into a poisoned group). `cold` is cleared.
    *cold = WideCold::default();
    let (hd, out, c) = (head, w, cold);
    // What the four-lane part below reads, assembled from the candidates in registers
    // (zero in empty lanes and absent points). Stored lane by lane and read back as
    // vectors, as it once was, the first vector load could not be forwarded from the four
    // scalar stores it spans and waited for every store before it to drain (the group's
    // clearing, then still done, included): a fifth of the build's samples; the build and
    // its `memset`s went from 11.2 % to 10.7 % of large_pyramid's step.
    //
    // An empty lane reads an empty input and static bodies (all zeros, as if the lane
    // were skipped) instead of being tested at every column: large_pyramid's build ran
    // 8 % fewer instructions (1 298 → 1 195 a group). Only the tangent impulse of an
    // empty input differs (−0.0), so it is masked.
    // (Loops and `array_of`, not `array::map` and `from_fn`: see `array_of`.)
    let mut read: [(&ContactInput, &ConstraintBodies); LANES] =
        [(&ContactInput::EMPTY, &ConstraintBodies::STATIC); LANES];
    for (r, lane) in read.iter_mut().zip(&lanes) {
        if let Some((_, input, b)) = *lane {
            *r = (input, b);
        }
    }
    let present = ML::from_bools(array_of(|l| lanes[l].is_some()));
    // Each lane's bodies (an empty lane: the static body, not written back).
    let (index_a, index_b) = (array_of(|l| read[l].1.index_a), array_of(|l| read[l].1.index_b));
    (hd.index_a, hd.index_b) = (index_a, index_b);
    let each = |f: &dyn Fn(&ContactInput, &ConstraintBodies) -> f32| FL::new(array_of(|l| f(read[l].0, read[l].1)));
    let count_of = |input: &ContactInput| input.count.min(2);
    // Fields that lie side by side in a candidate come as one 16-byte row per lane,
    // transposed into lanes of each (zeros in an empty lane): with four lanes eight
    // shuffles instead of sixteen single-lane loads and inserts per row.
    let columns = |row: &dyn Fn(&ContactInput, &ConstraintBodies) -> [f32; 4]| {
        rows_to_lanes(array_of(|l| F4::new(row(read[l].0, read[l].1))))
    };
    let [cax, cay, cbx, cby] = columns(&|_, b| b.centre_row());
    let (center_a, center_b) = (VL { x: cax, y: cay }, VL { x: cbx, y: cby });
    let [ma, ia, mb, ib] = columns(&|_, b| b.mass_row());
    // Which sides are written back: `ConstraintBodies::moving`, four lanes at once from
    // the masses' columns.
    let moving = |m: FL, i: FL, index: [u32; LANES]| ((m.gt(zero) | i.gt(zero)) & !ML::zero_lanes(index)).to_bools();
    hd.write_a = moving(ma, ia, index_a);
    hd.write_b = moving(mb, ib, index_b);
    // Each point's (x, y, separation, normal impulse); kept where the lane has the point.
    let point_rows: [[FL; 4]; 2] = array_of(|i| columns(&|input, _| input.points[i].row()));
    let counts = array_of(|l| count_of(read[l].0) as u32);
    let has: [ML; 2] = array_of(|i| ML::above(counts, i as u32));
    let point: [VL; 2] = array_of(|i| VL {
        x: has[i].select(point_rows[i][0], zero),
        y: has[i].select(point_rows[i][1], zero),
    });
    // Each point's (friction impulse, preload, drift, flags), and its flags as masks (none
    // where the lane lacks the point): the flags come in the transpose with the floats, one
    // word a lane, instead of masks assembled from each lane's bytes.
    let state_rows: [[FL; 4]; 2] = array_of(|i| columns(&|input, _| input.points[i].state_row()));
    let stick_in: [ML; 2] = array_of(|i| has[i] & state_rows[i][3].bits_set(INPUT_STICK));
    let fresh: [ML; 2] = array_of(|i| has[i] & state_rows[i][3].bits_set(INPUT_FRESH));
    // A sticking point's drift carries over (not a fresh one's). Chosen by masks, not a branch
    // per lane: which points stick is data (the branch had missed 3 100 times a step in
    // tumbler, 6 % of its misses).
    let base_drift: [FL; 2] = array_of(|i| (stick_in[i] & !fresh[i]).select(state_rows[i][2], zero));
    hd.normal = VL {
        x: each(&|input, _| input.normal.x),
        y: each(&|input, _| input.normal.y),
    };
    (hd.inv_mass_a, hd.inv_i_a, hd.inv_mass_b, hd.inv_i_b) = (ma, ia, mb, ib);
    for i in 0..2 {
        let (hp, wp) = (&mut hd.points[i], &mut out.points[i]);
        wp.base_separation = has[i].select(point_rows[i][2], zero);
        hp.normal_impulse = if warm {
            has[i].select(point_rows[i][3], zero)
        } else {
            zero
        };
        // (A mask, not a branch per lane: whether a lane has point `i` is data.)
        wp.preload = if warm {
            has[i].select(state_rows[i][1], zero)
        } else {
            zero
        };
        // The step's sums and what restitution tracks start from zero.
        (wp.total_normal_impulse, wp.max_normal_impulse) = (zero, zero);
    }
    (rare.substep_vn, rare.approach) = ([zero; 2], [zero; 2]);
    (out.total_tangent_impulse, out.saturated) = (zero, ML::default());
    // Summed as `pack_state` sums (`Iterator::sum` of f32 starts at −0.0, and −0.0 + x is
    // x: the same bits, the same sign of a zero sum), without a loop; +0.0 in an empty lane.
    // Four lanes at once (a `match` on each lane's count was a branch per lane).
    let friction_impulse = |i: usize| if warm { state_rows[i][0] } else { zero };
    let (t0, t1) = (friction_impulse(0), friction_impulse(1));
    let summed = has[1].select(t0 + t1, has[0].select(t0, FL::splat(-0.0)));
    hd.tangent_impulse = present.select(summed, zero);
    c.base_drift = [*base_drift[0], *base_drift[1]];
    let [mu_s, mu_d, restitution, threshold] = columns(&|input, _| input.material_row());
    (c.mu_s, c.mu_d, c.restitution, c.restitution_threshold) = (*mu_s, *mu_d, *restitution, *threshold);
    let [rolling_resistance, tangent_speed, rolling_impulse, _] = columns(&|input, _| input.surface_row());
    (rare.rolling_resistance, rare.tangent_speed) = (rolling_resistance, tangent_speed);
    let used_rolling_impulse = if warm { rolling_impulse } else { zero };
    rare.rolling_impulse = used_rolling_impulse;
    // Any lane whose speed is not +0.0 (−0.0 included: the passes then read the speeds).
    hd.any_surface_speed = (tangent_speed.ne(zero) | tangent_speed.bits_set(0x8000_0000)).any();
    // The group's flags and the points' heights, four lanes at once from the columns (an
    // empty lane's zeros set no flag and give the height 0): the scalar tests and the
    // height's `dot`, lane by lane.
    let any_restitution = restitution.gt(zero).any();
    (c.any_restitution, hd.any_restitution) = (any_restitution, any_restitution);
    hd.any_rolling = (rolling_resistance.gt(zero) | used_rolling_impulse.ne(zero)).any();
    let height = point_rows[0][0] * FL::splat(up.x) + point_rows[0][1] * FL::splat(up.y);
    c.height = *has[0].select(height, zero);
    for (l, lane) in lanes.iter().enumerate() {
        let Some((contact, input, b)) = *lane else {
            continue;
        };
        c.contact[l] = contact;
        c.count[l] = count_of(input) as u8;
        if input.restitution > 0.0 {
            let (sa, sb) = (states[b.index_a as usize].get(), states[b.index_b as usize].get());
            c.kinetic_energy[l] = kinetic_energy_of(b.inv_mass_a, b.inv_i_a, b.inv_mass_b, b.inv_i_b, &sa, &sb);
        }
    }
    // Each point's friction state: its own, but a new point's is decided from the bodies'
    // velocities (`fresh_point_sticks`), lane by lane where a lane has one.
    c.fresh = [fresh[0].to_bools(), fresh[1].to_bools()];
    let stick = if (fresh[0] | fresh[1]).any() {
        let mut stick = [stick_in[0].to_bools(), stick_in[1].to_bools()];
        for (l, lane) in lanes.iter().enumerate() {
            let Some((_, input, b)) = *lane else {
                continue;
            };
            if !(c.fresh[0][l] || c.fresh[1][l]) {
                continue;
            }
            let (sa, sb) = (states[b.index_a as usize].get(), states[b.index_b as usize].get());
            let t = input.normal.right_perp();
            for (i, ip) in input.points[..count_of(input)].iter().enumerate() {
                if ip.fresh() {
                    let (r_a, r_b) = (ip.point - b.center_a, ip.point - b.center_b);
                    stick[i][l] = fresh_point_sticks(&sa, &sb, r_a, r_b, t, input.tangent_speed, ip.separation, ctx);
                }
            }
        }
        c.stick = stick;
        [ML::from_stored_bools(stick[0]), ML::from_stored_bools(stick[1])]
    } else {
        c.stick = [stick_in[0].to_bools(), stick_in[1].to_bools()];
        stick_in
    };
    // The row sticks where every point it has sticks (an empty lane: a sticking, empty
    // friction row). μs where the row sticks (an empty lane: 0), μd where it slides.
    out.stick = (!has[0] | stick[0]) & (!has[1] | stick[1]);
    out.mu = out.stick.select(mu_s, mu_d);
    // Four lanes at once (contact_solver::build_constraint and pack).
    let n = hd.normal;
    let t = n.right_perp();
    // k = m_a⁻¹ + m_b⁻¹ + I_a⁻¹ (r_a × d)² + I_b⁻¹ (r_b × d)² (effective_mass_inv).
    let k_of = |r_a: VL, r_b: VL, d: VL| {
        let (ra, rb) = (r_a.cross(d), r_b.cross(d));
        ma + mb + ia * ra * ra + ib * rb * rb
    };
    let inv_or_zero = |k: FL| k.gt(zero).select(one / k, zero);
    let sum = ma + mb;
    hd.split = sum.gt(zero).select(mb / sum, half);
    hd.shift_cap2 = wide_shift_cap2(ma, ia, mb, ib);
    let mut arms = [(VL::default(), VL::default()); 2];
    let mut kn = [zero; 2];
    for i in 0..2 {
        let keep = |v: VL| VL {
            x: has[i].select(v.x, zero),
            y: has[i].select(v.y, zero),
        };
        let (r_a, r_b) = (keep(point[i] - center_a), keep(point[i] - center_b));
        arms[i] = (r_a, r_b);
        kn[i] = k_of(r_a, r_b, n);
        anchors.points[i] = PointArms { r_a, r_b };
        let wp = &mut out.points[i];
        wp.normal_mass = has[i].select(inv_or_zero(kn[i]), zero);
    }
    let ((ra0, rb0), (ra1, rb1)) = (arms[0], arms[1]);
    let two = has[1];
    hd.two_points = two;
    // Friction row: the patch middle of two points, or the single point.
    let (fr_a, fr_b) = friction_arms(hd, anchors);
    out.tangent_mass = has[0].select(inv_or_zero(k_of(fr_a, fr_b, t)), zero);
    let [d0, d1] = base_drift;
    out.base_drift = two.select(half * (d0 + d1), d0);
    // The 2×2 normal block (Box2D v2.4's guard: none when K is near singular).
    let (k11, k22) = (kn[0], kn[1]);
    let (c0, c1) = (ra0.cross(n), ra1.cross(n));
    let (e0, e1) = (rb0.cross(n), rb1.cross(n));
    let k12 = ma + mb + ia * c0 * c1 + ib * e0 * e1;
    let det = k11 * k22 - k12 * k12;
    let block = two & (k11 * k11).lt(FL::splat(1000.0) * det) & det.gt(zero);
    let inv = one / det;
    out.block = block;
    out.k11 = block.select(k11, zero);
    out.k12 = block.select(k12, zero);
    out.k22 = block.select(k22, zero);
    let inv_det = block.select(inv, zero);
    c.inv_det = *inv_det;
    *derived = WideDerived::new((fr_a, fr_b), t, hd, anchors, out, inv_det);
}

/// `contact_solver::shift_cap2` four lanes at once (the same quotients and minimum; the
/// scalar form's two divisions per lane were a fourteenth of the wide build).
#[inline(always)]
fn wide_shift_cap2(ma: FL, ia: FL, mb: FL, ib: FL) -> FL {
    let (zero, max) = (FL::ZERO, FL::splat(f32::MAX));
    // (Spelled out, not a closure: see `point_impulse`.)
    let (side_a, side_b) = (ia.gt(zero).select(ma / ia, max), ib.gt(zero).select(mb / ib, max));
    let rho2 = side_a.min(side_b);
    rho2.lt(max).select(FL::splat(0.25) * rho2, max)
}

/// What the store writes into one contact: its points' persistent states, the rolling
/// impulse and its points' reported sums (`contact_solver::store_impulses`, computed from a
/// lane).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StoredContact {
    pub points: [PointState; 2],
    pub sums: ContactSums,
    pub rolling_impulse: f32,
    /// Points written (the manifold's count).
    pub count: u8,
}

impl StoredContact {
    /// Writes what it holds into its contact and its sums (the manifold's points and the
    /// rolling impulse).
    #[inline]
    #[super::lane_fn]
    pub(crate) fn write_into(&self, c: &mut Contact, sums: &mut ContactSums) {
        write_stored(c, sums, self.count, self.rolling_impulse, |i, ps, sum| {
            (*ps, *sum) = (self.points[i], self.sums[i])
        });
    }
}

/// Writes a contact's stored states: `set(i, point, sums)` sets point `i` and its sums in
/// place for each of its `count` points (fixed-size writes: a slice copy of variable length
/// is a `memcpy` call), then its rolling impulse.
#[inline(always)]
fn write_stored(
    c: &mut Contact,
    sums: &mut ContactSums,
    count: u8,
    rolling_impulse: f32,
    set: impl Fn(usize, &mut PointState, &mut PointSums),
) {
    if count >= 1 {
        set(0, &mut c.points[0], &mut sums[0]);
    }
    if count >= 2 {
        set(1, &mut c.points[1], &mut sums[1]);
    }
    c.rolling_impulse = rolling_impulse;
}

/// The store stage for four constraints, in group order: exactly what
/// `contact_solver::store_impulses` computes for each lane (the end-of-step slip velocity
/// and the displacement along the tangent four lanes at a time, the sums and the stick/slip
/// transitions lane by lane), transposed into each lane's rows for the contacts to take in
/// contact order ([`StoredGroup::write_into`]).
#[super::lane_fn]
pub(crate) fn store_group<S: StateRead>(
    h: &WideHead,
    arms: &WideArms,
    rare: &WideRare,
    w: &WideContact,
    cold: &WideCold,
    states: &[S],
    ctx: &StepContext,
) -> StoredGroup {
    let a = gather(states, &h.index_a);
    let b = gather(states, &h.index_b);
    let d = b.dp - a.dp;
    let shift = capped_shift(h, d);
    let n = h.normal;
    let t = n.right_perp();
    let frame = RowFrame::new(h, d, shift, t);
    let mut vt = [FL::ZERO; 2];
    let mut disp = [FL::ZERO; 2];
    for i in 0..2 {
        let p = &arms.points[i];
        let (m, along) = frame.point(&a, &b, p.r_a, p.r_b);
        (vt[i], disp[i]) = (row_speed(&a, &b, t, m) - rare.tangent_speed, along);
    }
    // Four lanes at once; every expression is the scalar store's, in its order.
    let zero = FL::ZERO;
    let has0 = ML::from_nonzero_bytes(cold.count);
    let (two, share) = (h.two_points, tangent_share(h, 0));
    let (tangent, total_tangent) = (share * h.tangent_impulse, share * w.total_tangent_impulse);
    // Sums over the points from 0.0 (the scalar loop's start).
    let sum_over = |x0: FL, x1: FL| {
        let first = zero + x0;
        two.select(first + x1, has0.select(first, zero))
    };
    let (n0, n1) = (h.points[0].normal_impulse, h.points[1].normal_impulse);
    let (sum_t, sum_n) = (sum_over(tangent, tangent), sum_over(n0, n1));
    let patch_saturated = sum_t.abs().ge(FL::splat(0.999) * FL::new(cold.mu_s) * sum_n) & has0 & w.saturated;
    // Only read where there are two points (`Sum` from −0.0: the plain sum of the two).
    let sum_total_t = total_tangent + total_tangent;
    let (tn0, tn1) = (w.points[0].total_normal_impulse, w.points[1].total_normal_impulse);
    let sum_total_n = tn0 + tn1;
    let stick_speed = FL::splat(ctx.stick_speed);
    let restitution = FL::new(cold.restitution);
    let threshold = -FL::new(cold.restitution_threshold);
    // Each point's states, four lanes; `StoredGroup::new` transposes them into each
    // lane's two rows, which are written straight into the contact's record and its sums
    // (`PointSums`), not into a `PointState` built on the stack first and copied (filling
    // a default-made array field by field had stalled on store forwarding: the default's
    // unaligned copies were still in flight when its 8-byte words were read back).
    let point = |i: usize| {
        let (wp, normal) = (&w.points[i], h.points[i].normal_impulse);
        let (total_normal, max) = (wp.total_normal_impulse, wp.max_normal_impulse);
        let (was_stick, fresh) = (
            ML::from_stored_bools(cold.stick[i]),
            ML::from_stored_bools(cold.fresh[i]),
        );
        let slip_speed = vt[i].abs();
        let loaded = max.gt(zero);
        // Loaded points change state: a sticking one slips when the patch is saturated and
        // it moves; a sliding one sticks when it has stopped.
        let stays = !(patch_saturated & slip_speed.gt(stick_speed));
        let stick =
            (loaded & ((was_stick & stays) | (!was_stick & slip_speed.lt(stick_speed)))) | (!loaded & was_stick);
        let total_tangent_out =
            (two & sum_total_n.gt(zero)).select(sum_total_t * total_normal / sum_total_n, total_tangent);
        let drift = (stick & was_stick & loaded).select(
            disp[i] + FL::new(cold.base_drift[i]) - rare.tangent_speed * FL::splat(ctx.dt),
            zero,
        );
        // next_preload, with `bounces` of the restitution pass.
        let approach = rare.approach[i];
        let bounced = restitution.gt(zero) & threshold.ge(approach) & max.gt(zero);
        let released = zero.ge(max) | (fresh & bounced);
        let kept = normal.lt(FL::splat(0.5) * wp.preload).select(zero, wp.preload);
        let preload = released.select(zero, fresh.select(normal, kept));
        StoredPoint {
            normal,
            total_normal,
            total_tangent: total_tangent_out,
            max,
            stick,
            drift,
            slip_speed,
            preload,
        }
    };
    StoredGroup::new([point(0), point(1)], tangent, rare.rolling_impulse, cold.count)
}

/// One point's stored states in the four lanes of a group ([`store_group`]).
pub(crate) struct StoredPoint {
    normal: FL,
    total_normal: FL,
    total_tangent: FL,
    max: FL,
    stick: ML,
    drift: FL,
    slip_speed: FL,
    preload: FL,
}

impl StoredPoint {
    /// The point's states as rows, lane by lane ([`StoredGroup::rows`]); `tangent`: its
    /// friction impulse. (A method, not a closure: see [`point_impulse`].)
    #[inline(always)]
    fn rows(&self, tangent: FL) -> ([F4; LANES], [F4; LANES]) {
        (
            lanes_to_rows([self.normal, tangent, self.drift, self.preload]),
            lanes_to_rows([self.total_normal, self.total_tangent, self.max, self.slip_speed]),
        )
    }
}

/// What the store writes into a group's four contacts ([`store_group`]), lane by lane:
/// each point's eight floats transposed into two rows, in [`PointState`]'s and
/// [`PointSums`]' field order, which [`StoredGroup::write_into`] writes as one 16-byte
/// store each (before: eight single-lane extracts and eight scalar stores per point;
/// large_pyramid's writes into the contacts ran 369 instructions a group, now 282, and the
/// transposes, two shuffles a row, add 62 to `store_group`).
pub(crate) struct StoredGroup {
    /// `rows[l][i]`: point `i` of lane `l`, (normal, tangent, drift, preload) and (total
    /// normal, total tangent, max normal, slip speed).
    rows: [[[F4; 2]; 2]; LANES],
    /// Each point's friction state, lane by lane (true: stick; as booleans, not masks: the
    /// writes read one lane at a time, and a mask's lane was copied out of it through the
    /// stack at every read).
    stick: [[bool; LANES]; 2],
    rolling_impulse: FL,
    /// The manifolds' point counts.
    count: [u8; LANES],
}

impl StoredGroup {
    /// The lanes of `points` as rows ([`StoredGroup::rows`]); `tangent` is each point's
    /// friction impulse (the row's, shared by the points).
    #[inline(always)]
    fn new(points: [StoredPoint; 2], tangent: FL, rolling_impulse: FL, count: [u8; LANES]) -> StoredGroup {
        let (a0, b0) = points[0].rows(tangent);
        let (a1, b1) = points[1].rows(tangent);
        StoredGroup {
            rows: array_of(|l| [[a0[l], b0[l]], [a1[l], b1[l]]]),
            stick: [points[0].stick.to_bools(), points[1].stick.to_bools()],
            rolling_impulse,
            count,
        }
    }

    /// Sets `ps` to point `i`'s state in lane `l`, and `sum` to its sums.
    #[inline(always)]
    fn set_point(&self, i: usize, l: usize, ps: &mut PointState, sum: &mut PointSums) {
        let [a, b] = &self.rows[l][i];
        let state = if self.stick[i][l] {
            FrictionState::Stick
        } else {
            FrictionState::Slip
        };
        ps.set_stored([a[0], a[1], a[2], a[3]], state);
        *sum = PointSums::from_row([b[0], b[1], b[2], b[3]]);
    }

    /// Point `i`'s state in lane `l`, and its sums.
    #[inline(always)]
    fn point(&self, i: usize, l: usize) -> (PointState, PointSums) {
        let (mut ps, mut sum) = (PointState::default(), PointSums::default());
        self.set_point(i, l, &mut ps, &mut sum);
        (ps, sum)
    }

    /// Writes lane `l` into its contact and its sums (the manifold's points and the rolling
    /// impulse).
    #[inline(always)]
    pub(crate) fn write_into(&self, l: usize, c: &mut Contact, sums: &mut ContactSums) {
        write_stored(c, sums, self.count[l], self.rolling_impulse[l], |i, ps, sum| {
            self.set_point(i, l, ps, sum)
        });
    }

    /// Lane `l` as a record of its own (for a contact written later, on one thread).
    #[super::lane_fn]
    pub(crate) fn lane(&self, l: usize) -> StoredContact {
        let ((p0, s0), (p1, s1)) = (self.point(0, l), self.point(1, l));
        StoredContact {
            points: [p0, p1],
            sums: [s0, s1],
            rolling_impulse: self.rolling_impulse[l],
            count: self.count[l].min(2),
        }
    }
}

/// Copies a scalar constraint into lane `l` (everything: geometry, masses, state) and
/// makes the group's `derived` part again.
#[allow(clippy::too_many_arguments)]
#[super::lane_fn]
pub(crate) fn pack(
    h: &mut WideHead,
    arms: &mut WideArms,
    rare: &mut WideRare,
    w: &mut WideContact,
    cold: &mut WideCold,
    derived: &mut WideDerived,
    l: usize,
    cc: &ContactConstraint,
    dynamic_a: bool,
    dynamic_b: bool,
) {
    cold.contact[l] = cc.contact;
    cold.count[l] = cc.count as u8;
    cold.restitution[l] = cc.restitution;
    cold.restitution_threshold[l] = cc.restitution_threshold;
    cold.kinetic_energy[l] = cc.kinetic_energy;
    cold.height[l] = cc.height;
    cold.any_restitution |= cc.restitution > 0.0;
    h.any_restitution |= cc.restitution > 0.0;
    for i in 0..2 {
        let real = i < cc.count;
        cold.base_drift[i][l] = if real { cc.points[i].base_drift } else { 0.0 };
        cold.stick[i][l] = real && cc.points[i].stick;
        cold.fresh[i][l] = real && cc.points[i].fresh;
    }
    h.index_a[l] = cc.index_a;
    h.index_b[l] = cc.index_b;
    h.write_a[l] = dynamic_a && cc.index_a != 0;
    h.write_b[l] = dynamic_b && cc.index_b != 0;
    h.normal.x[l] = cc.normal.x;
    h.normal.y[l] = cc.normal.y;
    h.inv_mass_a[l] = cc.inv_mass_a;
    h.inv_i_a[l] = cc.inv_i_a;
    h.inv_mass_b[l] = cc.inv_mass_b;
    h.inv_i_b[l] = cc.inv_i_b;
    h.split[l] = cc.split;
    h.shift_cap2[l] = cc.shift_cap2;
    cold.mu_s[l] = cc.mu_s;
    cold.mu_d[l] = cc.mu_d;
    rare.tangent_speed[l] = cc.tangent_speed;
    h.any_surface_speed |= cc.tangent_speed.to_bits() != 0;
    rare.rolling_resistance[l] = cc.rolling_resistance;
    h.any_rolling |= cc.rolling_resistance > 0.0 || cc.rolling_impulse != 0.0;
    for i in 0..2 {
        let (hp, wp) = (&mut arms.points[i], &mut w.points[i]);
        if i < cc.count {
            let cp = &cc.points[i];
            hp.r_a.x[l] = cp.r_a.x;
            hp.r_a.y[l] = cp.r_a.y;
            hp.r_b.x[l] = cp.r_b.x;
            hp.r_b.y[l] = cp.r_b.y;
            wp.base_separation[l] = cp.base_separation;
            wp.normal_mass[l] = cp.normal_mass;
            wp.preload[l] = cp.preload;
        } else {
            // A point that does nothing: no mass, no anchors, no impulse (every product
            // with its zero mass stays finite and zero).
            for f in [
                &mut hp.r_a.x,
                &mut hp.r_a.y,
                &mut hp.r_b.x,
                &mut hp.r_b.y,
                &mut wp.normal_mass,
                &mut wp.preload,
                &mut wp.base_separation,
            ] {
                f[l] = 0.0;
            }
        }
    }
    let block = cc.count == 2 && cc.block;
    let k = if block { cc.k } else { [0.0; 3] };
    w.k11[l] = k[0];
    w.k12[l] = k[1];
    w.k22[l] = k[2];
    cold.inv_det[l] = if block { cc.inv_det } else { 0.0 };
    w.block[l] = if block { u32::MAX } else { 0 };
    let (p0, p1) = (&cc.points[0], &cc.points[1]);
    // The friction row's anchors follow from the points' (`friction_arms`).
    let (tm, drift, stick) = match cc.count {
        2 => (
            cc.patch_tangent_mass,
            0.5 * (p0.base_drift + p1.base_drift),
            p0.stick && p1.stick,
        ),
        1 => (p0.tangent_mass, p0.base_drift, p0.stick),
        _ => (0.0, 0.0, true),
    };
    w.tangent_mass[l] = tm;
    w.base_drift[l] = drift;
    w.stick[l] = if stick { u32::MAX } else { 0 };
    w.mu[l] = if stick { cc.mu_s } else { cc.mu_d };
    h.two_points[l] = if cc.count == 2 { u32::MAX } else { 0 };
    pack_state(h, rare, w, l, cc);
    *derived = WideDerived::new(
        friction_arms(h, arms),
        h.normal.right_perp(),
        h,
        arms,
        w,
        FL::new(cold.inv_det),
    );
}

/// Copies the parts of a constraint that change during the substeps into lane `l`.
#[super::lane_fn]
pub(crate) fn pack_state(h: &mut WideHead, rare: &mut WideRare, w: &mut WideContact, l: usize, cc: &ContactConstraint) {
    for i in 0..2 {
        let wp = &mut w.points[i];
        let (lam, total, max, approach, vn) = if i < cc.count {
            let cp = &cc.points[i];
            (
                cp.normal_impulse,
                cp.total_normal_impulse,
                cp.max_normal_impulse,
                cp.approach,
                cp.substep_vn,
            )
        } else {
            (0.0, 0.0, 0.0, 0.0, 0.0)
        };
        h.points[i].normal_impulse[l] = lam;
        wp.total_normal_impulse[l] = total;
        wp.max_normal_impulse[l] = max;
        rare.approach[i][l] = approach;
        rare.substep_vn[i][l] = vn;
    }
    let n = cc.count.min(2);
    let sum_t: f32 = cc.points[..n].iter().map(|p| p.tangent_impulse).sum();
    let sum_total_t: f32 = cc.points[..n].iter().map(|p| p.total_tangent_impulse).sum();
    h.tangent_impulse[l] = sum_t;
    w.total_tangent_impulse[l] = sum_total_t;
    w.saturated[l] = if cc.points[0].saturated { u32::MAX } else { 0 };
    rare.rolling_impulse[l] = cc.rolling_impulse;
}

/// Copies lane `l`'s changing parts back into the scalar constraint.
#[super::lane_fn]
pub(crate) fn unpack_state(h: &WideHead, rare: &WideRare, w: &WideContact, l: usize, cc: &mut ContactConstraint) {
    let count = cc.count.min(2);
    let share = if count == 2 { 0.5 } else { 1.0 };
    let saturated = w.saturated.lane(l);
    for i in 0..count {
        let wp = &w.points[i];
        let cp = &mut cc.points[i];
        cp.normal_impulse = h.points[i].normal_impulse[l];
        cp.total_normal_impulse = wp.total_normal_impulse[l];
        cp.max_normal_impulse = wp.max_normal_impulse[l];
        cp.approach = rare.approach[i][l];
        cp.substep_vn = rare.substep_vn[i][l];
        cp.tangent_impulse = share * h.tangent_impulse[l];
        cp.total_tangent_impulse = share * w.total_tangent_impulse[l];
        cp.saturated = saturated;
    }
    cc.rolling_impulse = rare.rolling_impulse[l];
}

/// Rebuilds the scalar constraint of lane `l` (geometry, masses and current state).
#[super::lane_fn]
pub(crate) fn unpack_full(
    h: &WideHead,
    arms: &WideArms,
    rare: &WideRare,
    w: &WideContact,
    cold: &WideCold,
    soft: &StepSoftness,
    l: usize,
) -> ContactConstraint {
    let count = cold.count[l] as usize;
    let block = w.block.lane(l);
    let soft = if h.index_a[l] == 0 || h.index_b[l] == 0 {
        soft.static_contact
    } else {
        soft.contact
    };
    let k_roll = h.inv_i_a[l] + h.inv_i_b[l];
    let mut cc = ContactConstraint {
        index_a: h.index_a[l],
        index_b: h.index_b[l],
        contact: cold.contact[l],
        normal: Vec2::new(h.normal.x[l], h.normal.y[l]),
        inv_mass_a: h.inv_mass_a[l],
        inv_i_a: h.inv_i_a[l],
        inv_mass_b: h.inv_mass_b[l],
        inv_i_b: h.inv_i_b[l],
        mu_s: cold.mu_s[l],
        mu_d: cold.mu_d[l],
        restitution: cold.restitution[l],
        restitution_threshold: cold.restitution_threshold[l],
        rolling_resistance: rare.rolling_resistance[l],
        rolling_mass: if k_roll > 0.0 { 1.0 / k_roll } else { 0.0 },
        rolling_impulse: 0.0,
        tangent_speed: rare.tangent_speed[l],
        k: if block {
            [w.k11[l], w.k12[l], w.k22[l]]
        } else {
            [0.0; 3]
        },
        inv_det: if block { cold.inv_det[l] } else { 0.0 },
        block,
        split: h.split[l],
        shift_cap2: h.shift_cap2[l],
        kinetic_energy: cold.kinetic_energy[l],
        height: cold.height[l],
        patch_tangent_mass: if count == 2 { w.tangent_mass[l] } else { 0.0 },
        count,
        points: [ConstraintPoint::default(); 2],
    };
    for i in 0..count {
        let wp = &w.points[i];
        let cp = &mut cc.points[i];
        let hp = &arms.points[i];
        cp.r_a = Vec2::new(hp.r_a.x[l], hp.r_a.y[l]);
        cp.r_b = Vec2::new(hp.r_b.x[l], hp.r_b.y[l]);
        cp.base_separation = wp.base_separation[l];
        cp.base_drift = cold.base_drift[i][l];
        cp.normal_mass = wp.normal_mass[l];
        cp.tangent_mass = if count == 1 { w.tangent_mass[l] } else { 0.0 };
        cp.preload = wp.preload[l];
        cp.soft = soft;
        cp.stick = cold.stick[i][l];
        cp.fresh = cold.fresh[i][l];
    }
    unpack_state(h, rare, w, l, &mut cc);
    cc
}

#[cfg(test)]
#[super::lane_tests]
mod tests {
    use super::*;

    /// `$call` of a function under test. In the eight-lane builds the functions are
    /// compiled for AVX2 (or for AVX2 with AVX-512F/VL) and their call is `unsafe`: these
    /// tests exist there only in a crate compiled for those as a whole (`lane_tests`), so
    /// the CPU has them. A plain call with four lanes.
    macro_rules! lane_call {
        ($call:expr) => {{
            #[allow(unsafe_code, unused_unsafe)]
            // SAFETY: see above.
            let out = unsafe { $call };
            out
        }};
    }
    use crate::math::Rot;
    use crate::solver::contact_solver::{build_constraint, restitution_one, store_impulses, InputPoint};
    use crate::solver::BodyState;

    /// A group built from `lanes` (the build's four outputs).
    fn built<S: StateRead>(
        lanes: [LaneInput<'_>; LANES],
        up: Vec2,
        ctx: &StepContext,
        states: &[S],
    ) -> (WideHead, WideArms, WideRare, WideContact, WideCold, WideDerived) {
        let (mut h, mut arms, mut rare, mut w, mut cold, mut dv) = Default::default();
        lane_call!(build_group(
            &mut h, &mut arms, &mut rare, &mut w, &mut cold, &mut dv, lanes, up, ctx, states
        ));
        (h, arms, rare, w, cold, dv)
    }

    fn input(count: usize, fresh: bool, restitution: f32, rolling: f32) -> ContactInput {
        let point = |x: f32, sep: f32| InputPoint {
            point: Vec2::new(x, 0.3),
            separation: sep,
            normal_impulse: 0.7 + x,
            tangent_impulse: -0.2 * x,
            preload: 0.5,
            drift: 1e-3 * x,
            flags: InputPoint::flags_of(x > 0.0, fresh),
        };
        ContactInput {
            normal: Vec2::new(0.6, 0.8),
            count,
            points: [point(0.25, -0.004), point(-0.35, 0.002)],
            mu_s: 0.9,
            mu_d: 0.6,
            restitution,
            restitution_threshold: 1.0,
            rolling_resistance: rolling,
            tangent_speed: 0.1,
            rolling_impulse: 0.01,
        }
    }

    /// A body state with velocity (vx, vy) [m/s], ω = `w` [rad/s], moved by `dp` [m] and
    /// turned by `angle` [rad] so far in the step.
    fn moved_state(vx: f32, vy: f32, w: f32, dp: Vec2, angle: f32) -> BodyState {
        BodyState {
            v: Vec2::new(vx, vy),
            w,
            touched: 0.0,
            dp,
            dq: Rot::from_angle(angle),
        }
    }

    fn bodies(index_a: u32, index_b: u32) -> ConstraintBodies {
        let side = |i: u32, m: f32| if i == 0 { (0.0, 0.0) } else { (1.0 / m, 6.0 / m) };
        let ((inv_mass_a, inv_i_a), (inv_mass_b, inv_i_b)) = (side(index_a, 2.0), side(index_b, 0.5));
        ConstraintBodies {
            index_a,
            index_b,
            inv_mass_a,
            inv_i_a,
            inv_mass_b,
            inv_i_b,
            center_a: Vec2::new(0.1, -0.2),
            center_b: Vec2::new(-0.3, 0.9),
        }
    }

    /// The wide build must give every lane exactly what the scalar build followed by
    /// `pack` gives (the solver's lanes and its scalar paths — overflow, estimate,
    /// mass-ratio sweeps — must agree bit for bit): re-packing each real lane from the
    /// scalar constraint over the wide result changes nothing. Covers two-point and
    /// one-point manifolds, a static side, new points (whose stick/slip state is decided
    /// from the step-start velocities: one in contact and slipping, one not), restitution,
    /// rolling resistance and an empty lane.
    struct Fixture {
        ctx: StepContext,
        soft: StepSoftness,
        states: Vec<BodyState>,
        up: Vec2,
        cases: [(u32, ContactInput, ConstraintBodies); 3],
    }

    impl Fixture {
        fn lanes(&self) -> [LaneInput<'_>; LANES] {
            lanes_of(&self.cases)
        }
    }

    /// Four lanes' values, the lanes after them (with eight lanes) 0.
    fn lanes_from(first: [f32; 4]) -> FL {
        FL::new(core::array::from_fn(|l| first.get(l).copied().unwrap_or(0.0)))
    }

    /// The lanes of `cases` in order, empty after them.
    fn lanes_of(cases: &[(u32, ContactInput, ConstraintBodies)]) -> [LaneInput<'_>; LANES] {
        core::array::from_fn(|l| cases.get(l).map(|(c, i, b)| (*c, i, b)))
    }

    fn fixture() -> Fixture {
        let ctx = StepContext::for_tests();
        let soft = StepSoftness::new(&ctx);
        let state = |vx: f32, w: f32| BodyState {
            v: Vec2::new(vx, -0.5),
            w,
            touched: 0.0,
            dp: Vec2::ZERO,
            dq: Rot::IDENTITY,
        };
        let states = vec![
            BodyState::default(),
            state(0.4, 1.5),
            state(-0.3, -0.7),
            state(2.0, 0.0),
        ];
        let up = Vec2::new(0.0, 1.0);
        let cases = [
            (7u32, input(2, false, 0.0, 0.0), bodies(1, 2)),
            (9, input(1, true, 0.0, 0.0), bodies(0, 3)),
            (12, input(2, true, 0.4, 0.05), bodies(2, 1)),
        ];
        Fixture {
            ctx,
            soft,
            states,
            up,
            cases,
        }
    }

    /// Builds `cases` into a group (an empty lane after them) and asserts that packing each
    /// lane from the scalar build over it changes nothing; returns the group.
    fn built_as_packed(
        f: &Fixture,
        cases: &[(u32, ContactInput, ConstraintBodies)],
    ) -> (WideHead, WideArms, WideRare, WideContact, WideCold, WideDerived) {
        let (ctx, soft, states, up) = (f.ctx, f.soft, &f.states, f.up);
        let (h, arms, rare, w, cold, dv) = built(lanes_of(cases), up, &ctx, states);
        // Packed lane by lane over a copy whose ready-made part is spoilt first: pack must
        // make it again.
        let (mut rh, mut rarms, mut rrare, mut r, mut rcold) = (h, arms, rare, w, cold);
        let mut rdv = WideDerived {
            i12: FL::splat(7.0),
            normal_moments: [(FL::splat(7.0), FL::splat(7.0)); 2],
            ..dv
        };
        for (l, (ci, inp, b)) in cases.iter().enumerate() {
            let cc = build_constraint(*ci, inp, b, up, &soft, &ctx, states);
            let dyn_side = |m: f32, i: f32| m > 0.0 || i > 0.0;
            lane_call!(pack(
                &mut rh,
                &mut rarms,
                &mut rrare,
                &mut r,
                &mut rcold,
                &mut rdv,
                l,
                &cc,
                dyn_side(b.inv_mass_a, b.inv_i_a),
                dyn_side(b.inv_mass_b, b.inv_i_b),
            ));
        }
        assert_eq!(format!("{h:?}"), format!("{rh:?}"));
        assert_eq!(format!("{arms:?}"), format!("{rarms:?}"));
        assert_eq!(format!("{rare:?}"), format!("{rrare:?}"));
        assert_eq!(format!("{w:?}"), format!("{r:?}"));
        assert_eq!(format!("{cold:?}"), format!("{rcold:?}"));
        assert_eq!(format!("{dv:?}"), format!("{rdv:?}"));
        (h, arms, rare, w, cold, dv)
    }

    #[test]
    fn wide_build_equals_scalar_build_and_pack() {
        let f = fixture();
        let (ctx, soft, states, up, cases) = (f.ctx, f.soft, &f.states, f.up, &f.cases);
        let (h, arms, rare, w, cold, dv) = built_as_packed(&f, cases);
        // The ready-made part, lane by lane from the scalar build: the moments of the
        // friction row's anchors, at the middle of two points (at the point of one), K⁻¹
        // from the block's K and 1/det K (zeros, the middle one −0, where the block does
        // not apply), each point's anchors' moments about the normal (zero arms for an
        // absent point), to the bit.
        for (l, (ci, inp, b)) in cases.iter().enumerate() {
            let cc = build_constraint(*ci, inp, b, up, &soft, &ctx, states);
            let [p0, p1] = &cc.points;
            let anchor = |a: Vec2, b: Vec2| if cc.count == 2 { (a + b) * 0.5 } else { a };
            let (fr_a, fr_b) = (anchor(p0.r_a, p1.r_a), anchor(p0.r_b, p1.r_b));
            let t = cc.normal.right_perp();
            let block = cc.count == 2 && cc.block;
            let ([k11, k12, k22], inv) = if block { (cc.k, cc.inv_det) } else { ([0.0; 3], 0.0) };
            let expected = [fr_a.cross(t), fr_b.cross(t), k22 * inv, -k12 * inv, k11 * inv];
            let lane = [dv.fr_moments.0, dv.fr_moments.1, dv.i11, dv.i12, dv.i22].map(|x| x[l]);
            assert_eq!(lane.map(f32::to_bits), expected.map(f32::to_bits), "lane {l}");
            let arm = |i: usize, r: Vec2| if i < cc.count { r } else { Vec2::ZERO };
            let expected: Vec<f32> = (0..2)
                .flat_map(|i| [arm(i, cc.points[i].r_a), arm(i, cc.points[i].r_b)])
                .map(|r| r.cross(cc.normal))
                .collect();
            let lane: Vec<f32> = dv.normal_moments.iter().flat_map(|m| [m.0[l], m.1[l]]).collect();
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&lane), bits(&expected), "lane {l}: moments about the normal");
        }
        // What the lanes derive instead of storing (softness, K⁻¹, rolling mass, friction
        // coefficient) comes back as the scalar build made it.
        for (l, (ci, inp, b)) in cases.iter().enumerate() {
            let cc = build_constraint(*ci, inp, b, up, &soft, &ctx, states);
            let u = lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &soft, l));
            let derived = |c: &ContactConstraint| {
                let soft: Vec<_> = c.points[..c.count].iter().map(|p| p.soft).collect();
                format!("{:?}", (c.mu_s, c.mu_d, c.rolling_mass, c.k, c.inv_det, c.block, soft))
            };
            assert_eq!(derived(&u), derived(&cc), "lane {l}");
        }
        // The cases do what they claim: a carried point sticks, a new one in contact and
        // slipping slides; the empty lane carries no mass.
        assert!(cold.stick[0][0] && !cold.stick[0][1] && cold.fresh[0][1]);
        assert_eq!(
            (h.inv_mass_a[3], h.inv_mass_b[3], w.points[0].normal_mass[3]),
            (0.0, 0.0, 0.0)
        );
        assert!(h.any_rolling && cold.any_restitution && w.block.lane(0));
        // What the empty lane reads from its input and bodies is +0.0 to the bit (an
        // empty input's tangent impulse, a sum over no points, would be −0.0; `split` and
        // `shift_cap2` are derived from the zero masses: 0.5 and f32::MAX).
        let mut empty = vec![
            h.normal.x,
            h.normal.y,
            h.inv_mass_a,
            h.inv_i_a,
            h.inv_mass_b,
            h.inv_i_b,
            h.tangent_impulse,
            rare.rolling_impulse,
            w.mu,
            rare.tangent_speed,
            rare.rolling_resistance,
            w.tangent_mass,
            w.base_drift,
        ];
        for i in 0..2 {
            let (hp, ap, wp) = (&h.points[i], &arms.points[i], &w.points[i]);
            empty.extend([ap.r_a.x, ap.r_a.y, ap.r_b.x, ap.r_b.y, hp.normal_impulse]);
            empty.extend([wp.base_separation, wp.normal_mass, wp.preload]);
        }
        let cold_lane = [cold.mu_s[3], cold.mu_d[3], cold.restitution[3], cold.height[3]];
        assert!(empty.iter().all(|x| x[3].to_bits() == 0), "{empty:?}");
        assert_eq!(cold_lane.map(f32::to_bits), [0; 4]);
    }

    /// A group whose every field holds a value (`k` = 0 or 1: two different ones, the
    /// booleans both ways) that the build must overwrite. A full literal, no `..`: a field
    /// added to any of the four records does not compile here until it is poisoned too.
    fn poisoned(k: usize) -> (WideHead, WideArms, WideRare, WideContact) {
        let (x, flag, index) = ([7.5, -7.5][k], k == 0, [7, 9][k]);
        let x = FL::splat(x);
        let v = VL { x, y: x };
        let m = ML::new([[0x0101_0101, u32::MAX][k]; LANES]);
        let hp = HeadPoint { normal_impulse: x };
        let wp = WidePoint {
            base_separation: x,
            normal_mass: x,
            preload: x,
            total_normal_impulse: x,
            max_normal_impulse: x,
        };
        let head = WideHead {
            index_a: [index; LANES],
            index_b: [index; LANES],
            write_a: [flag; LANES],
            write_b: [flag; LANES],
            any_rolling: flag,
            any_restitution: flag,
            any_surface_speed: flag,
            normal: v,
            inv_mass_a: x,
            inv_i_a: x,
            inv_mass_b: x,
            inv_i_b: x,
            split: x,
            shift_cap2: x,
            points: [hp; 2],
            tangent_impulse: x,
            two_points: m,
        };
        let w = WideContact {
            mu: x,
            points: [wp; 2],
            k11: x,
            k12: x,
            k22: x,
            block: m,
            tangent_mass: x,
            base_drift: x,
            stick: m,
            total_tangent_impulse: x,
            saturated: m,
        };
        let arms = WideArms {
            points: [PointArms { r_a: v, r_b: v }; 2],
        };
        let rare = WideRare {
            approach: [x; 2],
            substep_vn: [x; 2],
            rolling_impulse: x,
            rolling_resistance: x,
            tangent_speed: x,
        };
        (head, arms, rare, w)
    }

    /// The build against the scalar build and pack where no point is new (a resting pile's
    /// path: each point's own stick flag, no velocities read), with flags the build must
    /// ignore on the absent second point of a one-point manifold, and a lane whose side A
    /// is the static slot 0 but has mass (written back only for a non-zero index). (A
    /// lane without points is not a case: only touching contacts are built, and they have
    /// a point; its friction sum would start from +0.0 here, from −0.0 in `pack`.)
    #[test]
    fn wide_build_equals_scalar_build_without_new_points() {
        let f = fixture();
        let mut one = input(1, false, 0.0, 0.0);
        one.points[1].flags = INPUT_STICK | INPUT_FRESH;
        let mut static_with_mass = bodies(0, 3);
        (static_with_mass.inv_mass_a, static_with_mass.inv_i_a) = (0.5, 3.0);
        let cases = [
            (7u32, input(2, false, 0.0, 0.0), bodies(1, 2)),
            (9, one, static_with_mass),
            (12, input(2, false, 0.4, 0.05), bodies(2, 1)),
        ];
        let (h, _, _, _, cold, _) = built_as_packed(&f, &cases);
        // What the cases claim: no point is new; the first point of each lane sticks (it
        // lies at x > 0), the second of a two-point lane slides, the one-point lane's
        // absent point neither; lane 1's side A is not written back, its side B is.
        assert_eq!(cold.fresh, [[false; LANES]; 2]);
        let first: [bool; LANES] = core::array::from_fn(|l| l < 3);
        assert_eq!(cold.stick, [first, [false; LANES]]);
        assert!(!h.write_a[1] && h.write_b[1] && h.write_a[0] && h.write_b[2]);
    }

    /// The build writes every field of the group's `WideHead` and `WideContact` (it does
    /// not clear them first): built over either poisoned group ([`poisoned`]), the group
    /// comes out as built into zeroed ones, with and without warm starting (whose fields
    /// it writes either way). Checked by mutation: without the zero written into `approach`
    /// or the rolling impulse left unwritten without warm starting, it fails.
    #[test]
    fn build_writes_every_field() {
        let f = fixture();
        for (warm, k) in [(true, 0), (true, 1), (false, 0), (false, 1)] {
            let ctx = StepContext {
                warm_starting: warm,
                ..f.ctx
            };
            let clean = built(f.lanes(), f.up, &ctx, &f.states);
            let (_, _, _, _, mut cold, mut dv) = clean;
            let (mut h, mut arms, mut rare, mut w) = poisoned(k);
            lane_call!(build_group(
                &mut h,
                &mut arms,
                &mut rare,
                &mut w,
                &mut cold,
                &mut dv,
                f.lanes(),
                f.up,
                &ctx,
                &f.states
            ));
            assert_eq!(
                format!("{:?}", (clean.0, clean.1, clean.2, clean.3)),
                format!("{:?}", (h, arms, rare, w)),
                "warm {warm}, poison {k}"
            );
        }
    }

    /// The group's flags are set from its lanes' columns: none without restitution or a
    /// rolling row in any lane (the fixture's lanes all have a rolling impulse), each one
    /// by the one lane that has it, wherever that lane is, and a rolling impulse not
    /// without warm starting; the heights are the first points' along `up` (the second
    /// point lies higher), zero in empty lanes.
    #[test]
    fn group_flags_and_heights_come_from_their_lanes() {
        let f = fixture();
        let (id, b) = (f.cases[0].0, &f.cases[0].2);
        let mut plain = f.cases[0].1;
        plain.rolling_impulse = 0.0;
        plain.points[1].point.y = 0.7;
        let (mut rolling, mut bouncy, mut resisting) = (plain, plain, plain);
        rolling.rolling_impulse = 0.01;
        bouncy.restitution = 0.4;
        resisting.rolling_resistance = 0.05;
        // (lane input, its lane, flags expected: restitution, rolling)
        for (input, lane, expected) in [
            (&plain, 0, (false, false)),
            (&rolling, 3, (false, true)),
            (&bouncy, 2, (true, false)),
            (&resisting, 1, (false, true)),
        ] {
            let mut lanes: [LaneInput<'_>; LANES] = [None; LANES];
            lanes[lane] = Some((id, input, b));
            let (h, _, _, _, cold, _) = built(lanes, f.up, &f.ctx, &f.states);
            assert_eq!((h.any_restitution, h.any_rolling), expected, "lane {lane}");
            assert_eq!(cold.any_restitution, expected.0);
            let height = input.points[0].point.dot(f.up);
            let heights: [f32; LANES] = core::array::from_fn(|l| if l == lane { height } else { 0.0 });
            assert_eq!(cold.height, heights);
        }
        // Without warm starting the build drops the rolling impulse: no rolling row.
        let cold_ctx = StepContext {
            warm_starting: false,
            ..f.ctx
        };
        let lanes: [LaneInput<'_>; LANES] = core::array::from_fn(|l| (l == 1).then_some((id, &rolling, b)));
        let (h, ..) = built(lanes, f.up, &cold_ctx, &f.states);
        assert!(!h.any_rolling);
    }

    /// Builds a group of `points`-point lanes (a point between two moving bodies carrying
    /// load, a new one on the static body, one with rolling resistance, and an empty lane;
    /// each lane with its own bodies, as lanes of one colour have) and runs biased and
    /// relax passes on it and, lane after lane, the scalar `solve_one` (the overflow and
    /// mass-ratio paths solve with it) on the same constraints. One-point lanes must come
    /// out with the same bits (impulses and bodies); two-point lanes within `tol` relative:
    /// the scalar 2×2 block rounds its own way (1 ulp in a normal impulse, 34 in a friction
    /// impulse after one pass, already before K⁻¹ and the friction anchors were made once
    /// a step). Returns the group as built.
    fn solve_matches_scalar(points: usize, tol: f32) -> (WideHead, WideContact) {
        let ctx = StepContext::for_tests();
        let soft = StepSoftness::new(&ctx);
        let state = |vx: f32, vy: f32, w: f32| moved_state(vx, vy, w, Vec2::new(1e-3 * vx, -2e-3), 1e-3 * w);
        let states = vec![
            BodyState::default(),
            state(0.4, -0.5, 1.5),
            state(-0.3, -1.2, -0.7),
            state(2.0, -0.8, 0.0),
            state(0.1, 0.3, 0.2),
            state(-0.6, -0.9, 0.4),
            // Slid 0.4 m along the contact face since the step start: the lever arms'
            // shift is capped (√(ρ²/4) ≈ 0.2 m for these bodies, `capped_shift`).
            moved_state(0.3, -0.2, 0.5, Vec2::new(0.4, -2e-3), 1e-2),
            state(-0.2, -0.4, -0.3),
        ];
        let cases = [
            (3u32, input(points, false, 0.0, 0.0), bodies(1, 2)),
            (5, input(points, true, 0.0, 0.0), bodies(0, 3)),
            (8, input(points, false, 0.0, 0.05), bodies(4, 5)),
            (11, input(points, false, 0.0, 0.0), bodies(6, 7)),
        ];
        let lanes: [LaneInput<'_>; LANES] = core::array::from_fn(|l| cases.get(l).map(|c| (c.0, &c.1, &c.2)));
        let (mut h, arms, mut rare, mut w, cold, dv) = built(lanes, Vec2::new(0.0, 1.0), &ctx, &states);
        let d = states[7].dp - states[6].dp;
        assert!(d.length_squared() > h.shift_cap2[3], "lane 3's shift is capped");
        let built = (h, w);
        let mut scalar: Vec<ContactConstraint> = (0..cases.len())
            .map(|l| lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &soft, l)))
            .collect();
        let cells = |s: &[BodyState]| -> Vec<core::cell::Cell<BodyState>> {
            s.iter().map(|&s| core::cell::Cell::new(s)).collect()
        };
        let (wide_states, scalar_states) = (cells(&states), cells(&states));
        let mut loaded = false;
        for pass in 0..6 {
            let (bias, elapsed) = (pass % 2 == 0, (pass / 2) as f32 * ctx.h);
            if bias {
                solve::<true, _>(&mut h, &mut rare, &mut w, &dv, &wide_states, &ctx, &soft, elapsed, None);
            } else {
                solve::<false, _>(&mut h, &mut rare, &mut w, &dv, &wide_states, &ctx, &soft, elapsed, None);
            }
            for cc in &mut scalar {
                crate::solver::contact_solver::solve_one(cc, &scalar_states, &ctx, bias, elapsed);
            }
            for (l, cc) in scalar.iter().enumerate() {
                let lane = lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &soft, l));
                for (i, (p, q)) in cc.points.iter().zip(&lane.points).enumerate().take(points) {
                    let bits = |p: &ConstraintPoint| (p.normal_impulse.to_bits(), p.tangent_impulse.to_bits());
                    if tol == 0.0 {
                        assert_eq!(bits(q), bits(p), "pass {pass} lane {l} point {i}");
                    } else {
                        for (x, y) in [
                            (q.normal_impulse, p.normal_impulse),
                            (q.tangent_impulse, p.tangent_impulse),
                        ] {
                            assert!(
                                (x - y).abs() <= tol * y.abs().max(1e-3),
                                "pass {pass} lane {l} point {i}: {x} vs {y}"
                            );
                        }
                    }
                    loaded |= p.normal_impulse > 0.0;
                }
                if points == 1 {
                    assert_eq!(h.points[1].normal_impulse[l].to_bits(), 0, "no second point");
                }
            }
            if tol == 0.0 {
                let bits =
                    |s: &[core::cell::Cell<BodyState>]| format!("{:?}", s.iter().map(|c| c.get()).collect::<Vec<_>>());
                assert_eq!(bits(&wide_states), bits(&scalar_states), "pass {pass}");
            } else {
                for (k, (x, y)) in wide_states.iter().zip(&scalar_states).enumerate() {
                    let (x, y) = (x.get(), y.get());
                    for (u, v) in [(x.v.x, y.v.x), (x.v.y, y.v.y), (x.w, y.w)] {
                        assert!(
                            (u - v).abs() <= tol * v.abs().max(1.0),
                            "pass {pass} body {k}: {u} vs {v}"
                        );
                    }
                }
            }
        }
        assert!(loaded, "the fixture pushes");
        built
    }

    /// A group whose lanes all have one point takes the solve's one-point path, which skips
    /// the second point and the 2×2 block; it must still match the scalar solve.
    #[test]
    fn one_point_solve_equals_scalar_solve() {
        let (h, _) = solve_matches_scalar(1, 0.0);
        assert!(!h.two_points.any(), "no lane has a second point");
    }

    /// Two-point lanes: the 2×2 block with K⁻¹ and the friction row at the patch middle,
    /// both read ready-made from the group's [`WideDerived`], agree with the scalar solve
    /// to 1e-4 (a K⁻¹ with a wrong sign or the friction row at a point instead of the
    /// middle is off by far more).
    #[test]
    fn two_point_solve_matches_scalar_solve() {
        let (h, w) = solve_matches_scalar(2, 1e-4);
        assert!(
            h.two_points.lane(0) && w.block.lane(0),
            "lane 0 is a face the block solves"
        );
    }

    /// A lane gets the same bits whatever the other lanes of its group: the group-wide
    /// branches (the normal rows' one-point form, the rolling row) give a lane that does
    /// not need them only exact zeros, so a one-point constraint solved alone and solved
    /// beside a two-point face with rolling resistance ends with the same impulses and the
    /// same body states, to the bit (with nonzero velocities: a zero added to −0.0 gives
    /// +0.0). This is why the four- and eight-lane builds step alike
    /// (`crate::solver_lanes`): their groups hold different neighbours.
    #[test]
    fn a_lane_gets_the_same_bits_whatever_its_neighbours() {
        let ctx = StepContext::for_tests();
        let soft = StepSoftness::new(&ctx);
        let states = vec![
            BodyState::default(),
            moved_state(0.4, -0.5, 1.5, Vec2::new(1e-3, -2e-3), 0.01),
            moved_state(-0.3, 0.2, -0.7, Vec2::new(-1e-3, 1e-3), -0.02),
            moved_state(0.7, -0.1, 0.3, Vec2::ZERO, 0.0),
            moved_state(-0.2, 0.6, -1.1, Vec2::ZERO, 0.0),
        ];
        // (No rolling impulse carried over: without rolling resistance the relax leaves none.)
        let single = (
            5u32,
            ContactInput {
                rolling_impulse: 0.0,
                ..input(1, false, 0.0, 0.0)
            },
            bodies(1, 2),
        );
        let face = (6u32, input(2, false, 0.0, 0.05), bodies(3, 4));
        // Warm start, biased and relax passes; then lane 0's impulses and its two bodies.
        let run = |cases: &[(u32, ContactInput, ConstraintBodies)]| {
            let (mut h, arms, mut rare, mut w, _, dv) = built(lanes_of(cases), Vec2::new(0.0, 1.0), &ctx, &states);
            let (two, rolling) = (h.two_points.any(), h.any_rolling);
            let cells: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
            warm_start(&h, &arms, &mut rare, &cells);
            solve::<true, _>(&mut h, &mut rare, &mut w, &dv, &cells, &ctx, &soft, ctx.h, None);
            solve::<false, _>(&mut h, &mut rare, &mut w, &dv, &cells, &ctx, &soft, ctx.h, None);
            // Through `Debug`, which tells −0.0 from +0.0.
            let lane = format!(
                "{:?}",
                (
                    h.points.map(|p| p.normal_impulse[0]),
                    h.tangent_impulse[0],
                    rare.rolling_impulse[0],
                    w.points.map(|p| p.total_normal_impulse[0]),
                    w.total_tangent_impulse[0],
                )
            );
            (lane, format!("{:?}", [cells[1].get(), cells[2].get()]), two, rolling)
        };
        let alone = run(&[single]);
        let beside = run(&[single, face]);
        assert!(!alone.2 && !alone.3, "alone: the one-point form, no rolling row");
        assert!(
            beside.2 && beside.3,
            "beside the face: the two-point form and the rolling row"
        );
        assert_eq!(alone.0, beside.0, "the lane's impulses");
        assert_eq!(alone.1, beside.1, "its bodies' states");
    }

    /// The relax pass's carry is the next warm start (`carry_warm_start`, see
    /// `solver::solve_step`): after a relax pass that carries, each body's carry entry
    /// must equal what [`warm_start`] then adds to its relaxed velocity. Three groups:
    /// two-point, one-point (against the ground) and rolling lanes whose bodies moved and
    /// turned since the step start (shifted arms); one-point lanes only (the rows' one-point
    /// form); and bodies moved apart along the tangent past the shift's cap. The same
    /// impulses on the same arms, summed in another order (moments of the rows instead of
    /// cross products of the arms), so equal to 1e-5 of the largest change: a wrong arm,
    /// sign or missing row is off by far more.
    #[test]
    fn relax_carries_the_next_warm_start() {
        let f = fixture();
        let mixed = [
            (7u32, input(2, false, 0.0, 0.0), bodies(1, 2)),
            (9, input(1, false, 0.0, 0.0), bodies(0, 3)),
            (12, input(2, false, 0.0, 0.05), bodies(4, 5)),
        ];
        let single = [
            (7u32, input(1, false, 0.0, 0.0), bodies(1, 2)),
            (9, input(1, false, 0.0, 0.0), bodies(0, 3)),
        ];
        // Slow bodies (the impulses stay on) that moved and turned a little; the third
        // variant moves each body 0.3 m further along the tangent per index, past the cap.
        let tangent = Vec2::new(0.8, -0.6);
        let moved = |far: bool| -> Vec<BodyState> {
            (0..6)
                .map(|k| BodyState {
                    v: Vec2::new(0.004 * k as f32, -0.003),
                    w: 0.01 * k as f32,
                    touched: 0.0,
                    dp: Vec2::new(1e-3 * k as f32, -2e-3 * k as f32) + tangent * if far { 0.3 * k as f32 } else { 0.0 },
                    dq: Rot::from_angle(2e-3 * k as f32),
                })
                .collect()
        };
        let cells = |s: &[BodyState]| -> Vec<core::cell::Cell<BodyState>> {
            s.iter().map(|&s| core::cell::Cell::new(s)).collect()
        };
        for (name, cases, far) in [
            ("mixed", &mixed[..], false),
            ("one-point", &single[..], false),
            ("capped", &mixed[..], true),
        ] {
            let start = moved(far);
            let (mut h, arms, mut rare, mut w, _, dv) = built(lanes_of(cases), f.up, &f.ctx, &start);
            let d = start[2].dp - start[1].dp;
            assert_eq!(
                far,
                d.length_squared() > h.shift_cap2[0],
                "{name}: lane 0's shift capped"
            );
            assert_eq!(name != "one-point", h.two_points.any(), "{name}: two-point lanes");
            let (states, carry) = (cells(&start), cells(&vec![BodyState::default(); start.len()]));
            solve::<false, _>(
                &mut h,
                &mut rare,
                &mut w,
                &dv,
                &states,
                &f.ctx,
                &f.soft,
                f.ctx.h,
                Some(&carry),
            );
            let relaxed: Vec<BodyState> = states.iter().map(|c| c.get()).collect();
            warm_start(&h, &arms, &mut rare, &states);
            let changes: Vec<(Vec2, f32)> = states
                .iter()
                .zip(&relaxed)
                .map(|(s, r)| (s.get().v - r.v, s.get().w - r.w))
                .collect();
            let largest = changes.iter().fold(0.0f32, |m, (v, w)| m.max(v.length()).max(w.abs()));
            assert!(
                largest > 0.1,
                "{name}: the warm start changes the velocities ({largest})"
            );
            for (k, ((v, w), c)) in changes.iter().zip(&carry).enumerate() {
                let c = c.get();
                let off = (c.v - *v).length().max((c.w - w).abs());
                assert!(
                    off <= 1e-5 * largest,
                    "{name}, body {k}: carry {:?} {} vs warm start {v:?} {w}",
                    c.v,
                    c.w
                );
            }
            assert_eq!(carry[0].get().v, Vec2::ZERO, "{name}: the ground takes no carry");
        }
    }

    /// The store's wide half must write into each contact exactly what the scalar store
    /// writes from the same lane (impulses, totals, the patch's split of the friction
    /// total, preload, slip speed, drift and the stick/slip transition): after a solver
    /// pass has changed the impulses and the bodies have moved, both stores are run from
    /// the same lanes and compared field by field.
    #[test]
    fn wide_store_equals_scalar_store() {
        let f = fixture();
        let (mut h, arms, mut rare, mut w, cold, dv) = built(f.lanes(), f.up, &f.ctx, &f.states);
        let cells: Vec<core::cell::Cell<BodyState>> = f.states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        solve::<false, _>(&mut h, &mut rare, &mut w, &dv, &cells, &f.ctx, &f.soft, f.ctx.h, None);
        let moved: Vec<BodyState> = cells
            .iter()
            .map(|c| {
                let mut s = c.get();
                s.dp = Vec2::new(1e-3 * s.v.x, -2e-3);
                s.dq = Rot::from_angle(1e-3 * s.w);
                s
            })
            .collect();
        let stored = lane_call!(store_group(&h, &arms, &rare, &w, &cold, &moved, &f.ctx));
        let out: [StoredContact; LANES] = core::array::from_fn(|l| lane_call!(stored.lane(l)));
        let (mut slipped, mut pushed) = (false, false);
        for l in 0..3 {
            let cc = lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &f.soft, l));
            let mut c = crate::collision::contact::blank_contact();
            let mut sums = ContactSums::default();
            store_impulses(&cc, &mut c, &mut sums, &moved, &f.ctx);
            let n = cc.count;
            assert_eq!(out[l].count as usize, n);
            // Compared through `Debug`, which tells −0.0 from +0.0 (float `==` does not).
            let bits = |points: &[PointState]| format!("{points:?}");
            let sum_bits = |sums: &[PointSums]| format!("{sums:?}");
            assert_eq!(bits(&out[l].points[..n]), bits(&c.points[..n]), "lane {l}");
            assert_eq!(sum_bits(&out[l].sums[..n]), sum_bits(&sums[..n]), "lane {l} sums");
            assert_eq!(out[l].rolling_impulse.to_bits(), c.rolling_impulse.to_bits());
            // What the store stage calls: the lane written straight into a contact and its
            // sums, its points past the manifold's count left as they were.
            let mut written = crate::collision::contact::blank_contact();
            let mut written_sums = [PointSums {
                slip_speed: 7.0,
                ..PointSums::default()
            }; 2];
            let (blank, blank_sums) = (written.points, written_sums);
            stored.write_into(l, &mut written, &mut written_sums);
            assert_eq!(bits(&written.points[..n]), bits(&c.points[..n]), "lane {l} written");
            assert_eq!(
                sum_bits(&written_sums[..n]),
                sum_bits(&sums[..n]),
                "lane {l} sums written"
            );
            assert_eq!(
                bits(&written.points[n..]),
                bits(&blank[n..]),
                "lane {l}: no point past the count"
            );
            assert_eq!(
                sum_bits(&written_sums[n..]),
                sum_bits(&blank_sums[n..]),
                "lane {l}: no sums past the count"
            );
            assert_eq!(written.rolling_impulse.to_bits(), c.rolling_impulse.to_bits());
            slipped |= c.points[..n].iter().any(|p| p.state == FrictionState::Slip);
            pushed |= c.points[..n]
                .iter()
                .zip(&sums)
                .any(|(p, s)| s.total_normal_impulse > 0.0 && p.drift != 0.0);
        }
        assert!(slipped, "the fixture exercises a sliding point");
        assert!(pushed, "and a loaded sticking point with drift");
    }

    /// The wide restitution pass must leave every lane and body exactly as the scalar
    /// `restitution_one` does, lane after lane: a face whose two points bounce (the 2×2
    /// block), a single point whose rebound the energy cap cuts, a face where only one
    /// point bounces (the points in turn), and an empty lane. Each lane has its own bodies,
    /// as lanes of one colour do.
    #[test]
    fn wide_restitution_equals_scalar_restitution() {
        let ctx = StepContext::for_tests();
        let soft = StepSoftness::new(&ctx);
        let state = |vx: f32, vy: f32, w: f32| moved_state(vx, vy, w, Vec2::new(1e-3, -2e-3), 1e-3);
        let states = vec![
            BodyState::default(),
            state(0.4, 2.5, 1.5),
            state(-0.3, -1.5, -0.7),
            state(-0.6, -0.8, 0.0),
            state(0.1, 1.2, -0.4),
            state(0.2, -0.9, 0.2),
        ];
        let cases = [
            (1u32, input(2, false, 0.5, 0.0), bodies(1, 2)),
            (2, input(1, false, 0.5, 0.0), bodies(0, 3)),
            (3, input(2, false, 0.3, 0.0), bodies(4, 5)),
        ];
        let lanes = lanes_of(&cases);
        let (mut h, arms, mut rare, mut w, mut cold, dv) = built(lanes, Vec2::new(0.0, 1.0), &ctx, &states);
        // Impact speeds and loads as the substeps would leave them: every point bounces but
        // lane 2's second (slower than the 1 m/s threshold); lane 1 had little energy.
        for (i, approach) in [[-3.0, -2.0, -2.5, 0.0], [-2.5, 0.0, -0.5, 0.0]]
            .into_iter()
            .enumerate()
        {
            rare.approach[i] = lanes_from(approach);
            w.points[i].max_normal_impulse = lanes_from([1.0, 1.0, 1.0, 0.0]);
            w.points[i].total_normal_impulse = lanes_from([0.3, 0.2, 0.1, 0.0]);
        }
        cold.kinetic_energy = *lanes_from([50.0, 0.2, 50.0, 0.0]);
        assert!(w.block.lane(0), "lane 0 is a face the block can solve");
        // Scalar: lane by lane, each unpacked, solved and compared.
        let scalar: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        let mut expected = Vec::new();
        for l in 0..3 {
            let mut cc = lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &soft, l));
            restitution_one(&mut cc, &scalar);
            expected.push(cc);
        }
        let wide: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        let before = (h, w);
        lane_call!(restitution(&mut h, &arms, &rare, &mut w, &dv, &cold, &wide));
        let bits = |s: BodyState| [s.v.x, s.v.y, s.w].map(f32::to_bits);
        for (k, (x, y)) in wide.iter().zip(&scalar).enumerate() {
            assert_eq!(bits(x.get()), bits(y.get()), "body {k}");
        }
        for (l, cc) in expected.iter().enumerate() {
            let u = lane_call!(unpack_full(&h, &arms, &rare, &w, &cold, &soft, l));
            for i in 0..cc.count {
                let f = |p: &ConstraintPoint| {
                    [p.normal_impulse, p.total_normal_impulse, p.max_normal_impulse].map(f32::to_bits)
                };
                assert_eq!(f(&u.points[i]), f(&cc.points[i]), "lane {l} point {i}");
            }
        }
        // The cases do what they claim: lane 0's two points and lane 2's first point take
        // new impulses, lane 2's second keeps its own; lane 1's rebound is cut by the cap
        // (it rebounds more when the pair had energy to spare).
        let changed = |l: usize, i: usize| h.points[i].normal_impulse[l] != before.0.points[i].normal_impulse[l];
        assert!(changed(0, 0) && changed(0, 1) && changed(2, 0) && !changed(2, 1) && changed(1, 0));
        let (mut free_h, mut free_w, mut free_cold) = (before.0, before.1, cold);
        free_cold.kinetic_energy[1] = 1e6;
        let fresh: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        lane_call!(restitution(
            &mut free_h,
            &arms,
            &rare,
            &mut free_w,
            &dv,
            &free_cold,
            &fresh
        ));
        let lam = before.0.points[0].normal_impulse[1];
        let (capped, free) = (
            h.points[0].normal_impulse[1] - lam,
            free_h.points[0].normal_impulse[1] - lam,
        );
        assert!(
            0.0 < capped && capped < 0.9 * free,
            "the energy cap acted: {capped} vs {free}"
        );
    }
}
