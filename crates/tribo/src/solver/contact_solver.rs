//! The contact constraint: a normal row per point (soft, non-penetration) and a friction
//! row per point with Coulomb's static/dynamic law and a stick/slip state machine.
//!
//! Legend (solver kernels only): `v`, `w` linear and angular velocity; `r_a`, `r_b` contact
//! point relative to each centre of mass; `n` normal (A→B); `t = right_perp(n)` tangent;
//! `λ` (lambda) accumulated impulse of the current substep [N·s]; `h` substep [s].
//!
//! ## Effective masses
//! For a row with direction d at the point, the relative velocity is
//! `v_rel = d·((v_b + ω_b × r_b) − (v_a + ω_a × r_a))` and the impulse P = λd changes it by
//! `λ·k` with `k = m_a⁻¹ + m_b⁻¹ + I_a⁻¹ (r_a × d)² + I_b⁻¹ (r_b × d)²`; the row's effective
//! mass is `1/k` (for the tangent row use d = t, not n: ImpulseEngine#14's bug).
//!
//! ## Friction: stick and slip
//! Each point is in one of two states, kept across steps by feature id:
//! * **Stick**: the friction impulse may reach `μs·λn` and aims at zero relative tangential
//!   velocity *and* zero accumulated slip (`drift`, the static-friction anchor: the
//!   tangential slip integrated since the point began to stick). The biased pass drives
//!   the drift back to zero at the contact's bias rate, so the iteration error of a
//!   one-iteration solver cannot add up to creep. Because the drift is measured at the
//!   current contact point (not a material anchor), rolling contacts are not held back.
//! * **Slip**: the friction impulse is clamped to `μd·λn` (exactly that while slipping,
//!   less only if less stops the slip), and no anchor is kept (so sliding stores no
//!   energy: avbd-metal PR #9's lesson).
//!
//! Transitions are decided once per step, after the solve: a sticking point whose
//! friction saturated at `μs·λn` in the last relax pass and that still slips faster than
//! the stick speed turns to Slip; a slipping point whose slip speed fell below the stick
//! speed turns to Stick. Points that carried no normal impulse keep their state. A new
//! point starts sliding if it is already in contact and slipping faster than the stick
//! speed, otherwise sticking (so a body dropped onto a slope it can grip is held by μs).
//!
//! ## Preloaded soft contacts (no sinking under load)
//! A soft contact settles at the deflection `F / (m ω²)` under a load F (see
//! [`super::softness`]); with m the *light* body's effective mass this is how a heavy box
//! sinks centimetres into a light one in soft-step engines, and how a tall stack
//! compresses. Here the soft row relaxes towards a *preload* `λ_pre` instead of towards 0:
//! `Δλ = −m·s_m·(v + β·C) − s_i·(λ − λ_pre)`. The preload is seeded once, when a point
//! begins — by the warm-start estimate of a new resting contact, or by the load the point
//! takes in its first step — and then kept while the point keeps at least half that load
//! (a step with less clears it, [`next_preload`]), so a steady load needs no deflection while impacts and later load
//! changes still meet the damped spring (a load added on top deflects it as in Box2D). It is deliberately not tracked afterwards: a preload that followed the load
//! (even at 0.2 % of the gap per step) is an integrator around the chain of springs of a
//! stack, and it kept the 100-row benchmark pyramid swaying at 0.05–0.25 m/s. Each point has
//! its own preload, so a box on a slope does not tilt into the ground either. (With one sweep per
//! point a per-point preload let tall towers rock; the 2×2 block normal solve below removed
//! that coupling.)
//!
//! ## Mass ratios
//! Sequential impulses move momentum through a light body squeezed between a heavy one and
//! the ground at a rate of about m/M per sweep. Each light body that touches a moving body
//! more than 4× heavier gets ⌈M/m⌉ (at most 64) extra sweeps over its own contacts in the
//! relax pass (rigid rows, so repeated sweeps converge instead of softening).
//!
//! ## Block normal solve
//! The two normal rows of a 2-point manifold are solved together (a 2×2 LCP, Box2D v2.4's
//! block solver in soft form), so one iteration is exact within the manifold.

use super::{BodyState, Softness, StateCell, StateRead, StepContext};
use crate::collision::contact::{Contact, ContactSums, FrictionState};
use crate::math::Vec2;

/// Solver data of one manifold point.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ConstraintPoint {
    pub r_a: Vec2,
    pub r_b: Vec2,
    /// Separation at the step start [m].
    pub base_separation: f32,
    /// Stick drift at the step start [m].
    pub base_drift: f32,
    pub normal_impulse: f32,
    /// Normal impulse the step started with: the soft row relaxes towards it, not 0.
    pub preload: f32,
    pub tangent_impulse: f32,
    pub total_normal_impulse: f32,
    pub total_tangent_impulse: f32,
    pub max_normal_impulse: f32,
    pub normal_mass: f32,
    pub tangent_mass: f32,
    /// Most negative normal velocity seen at the moment the point took load [m/s].
    pub approach: f32,
    /// Normal velocity at the start of the current substep, before warm starting [m/s].
    pub substep_vn: f32,
    pub soft: Softness,
    pub stick: bool,
    /// The point is new this step (its friction state is decided in prepare).
    pub fresh: bool,
    /// Friction hit its clamp in the last relax pass.
    pub saturated: bool,
}

/// Solver data of one contact.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ContactConstraint {
    pub index_a: u32,
    pub index_b: u32,
    pub contact: u32,
    pub normal: Vec2,
    pub inv_mass_a: f32,
    pub inv_i_a: f32,
    pub inv_mass_b: f32,
    pub inv_i_b: f32,
    pub mu_s: f32,
    pub mu_d: f32,
    pub restitution: f32,
    pub restitution_threshold: f32,
    pub rolling_resistance: f32,
    pub rolling_mass: f32,
    pub rolling_impulse: f32,
    pub tangent_speed: f32,
    /// Normal-row matrix K of a 2-point manifold: [k11, k12, k22] [1/kg].
    pub k: [f32; 3],
    /// 1/det K [kg²]: K⁻¹ = [k22, −k12; −k12, k11] / det K.
    pub inv_det: f32,
    /// The 2×2 block solver applies (two points, well conditioned).
    pub block: bool,
    /// Where impulses act between the two bodies' anchors as they move apart within a step:
    /// `m_a⁻¹ / (m_a⁻¹ + m_b⁻¹)` (see [`lever_arms`]).
    pub split: f32,
    /// Square of the longest relative displacement [m²] the lever arms follow in full
    /// ([`shift_cap2`], see [`capped_shift`]).
    pub shift_cap2: f32,
    /// Kinetic energy of the two bodies at the start of the step [J] (restitution cap).
    pub kinetic_energy: f32,
    /// Height of the first contact point along "up" (against gravity) [m].
    pub height: f32,
    /// Effective mass of the patch friction row at the middle of two points [kg].
    pub patch_tangent_mass: f32,
    pub count: usize,
    pub points: [ConstraintPoint; 2],
}

/// Everything the prepare stage needs about the two bodies of a contact (`repr(C)`: the
/// indices and inverse masses first, what the colouring reads).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub(crate) struct ConstraintBodies {
    pub index_a: u32,
    pub index_b: u32,
    pub inv_mass_a: f32,
    pub inv_i_a: f32,
    pub inv_mass_b: f32,
    pub inv_i_b: f32,
    pub center_a: Vec2,
    pub center_b: Vec2,
}

impl ConstraintBodies {
    /// Two static bodies (slot 0, no mass): an unused slot's bodies. The wide build reads
    /// these for an empty lane, so every field must stay zero.
    pub const STATIC: ConstraintBodies = ConstraintBodies {
        index_a: 0,
        index_b: 0,
        inv_mass_a: 0.0,
        inv_i_a: 0.0,
        inv_mass_b: 0.0,
        inv_i_b: 0.0,
        center_a: Vec2::ZERO,
        center_b: Vec2::ZERO,
    };

    /// Whether side A and side B are moving bodies, the ones the solver writes back: a
    /// body with mass or inertia, not the static slot 0 (the colouring's keys and the wide
    /// build's write flags).
    #[inline(always)]
    pub fn moving(&self) -> [bool; 2] {
        let side = |index: u32, inv_mass: f32, inv_i: f32| (inv_mass > 0.0 || inv_i > 0.0) && index != 0;
        [
            side(self.index_a, self.inv_mass_a, self.inv_i_a),
            side(self.index_b, self.inv_mass_b, self.inv_i_b),
        ]
    }

    /// The inverse masses and inertias (A's, then B's), side by side in the record: one
    /// row of the wide build's transpose.
    #[inline(always)]
    pub fn mass_row(&self) -> [f32; 4] {
        [self.inv_mass_a, self.inv_i_a, self.inv_mass_b, self.inv_i_b]
    }

    /// The two centres of mass [m], side by side in the record.
    #[inline(always)]
    pub fn centre_row(&self) -> [f32; 4] {
        [self.center_a.x, self.center_a.y, self.center_b.x, self.center_b.y]
    }
}

/// What building a constraint reads of a contact, copied out in contact order (compact
/// and contiguous, so the build in colour order does not chase 400-byte contact records
/// across memory).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ContactInput {
    pub normal: Vec2,
    pub count: usize,
    pub points: [InputPoint; 2],
    pub mu_s: f32,
    pub mu_d: f32,
    pub restitution: f32,
    pub restitution_threshold: f32,
    /// Rolling resistance × rolling radius [m].
    pub rolling_resistance: f32,
    pub tangent_speed: f32,
    pub rolling_impulse: f32,
}

/// One manifold point and its carried-over state (see [`ContactInput`]). Laid out as two
/// rows of four words, each one row of the wide build's transposes ([`InputPoint::row`],
/// [`InputPoint::state_row`]).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub(crate) struct InputPoint {
    pub point: Vec2,
    pub separation: f32,
    pub normal_impulse: f32,
    pub tangent_impulse: f32,
    pub preload: f32,
    pub drift: f32,
    /// [`INPUT_STICK`] and [`INPUT_FRESH`]: one word, so that the wide build reads four
    /// lanes' flags in the transpose of their state rows and tests them four lanes at a
    /// time, instead of assembling masks from single bytes.
    pub flags: u32,
}

/// Flag of an [`InputPoint`]: it sticks ([`FrictionState::Stick`]).
pub(crate) const INPUT_STICK: u32 = 1;
/// Flag of an [`InputPoint`]: it is new this step
/// ([`PointState::fresh`](crate::collision::contact::PointState::fresh)).
pub(crate) const INPUT_FRESH: u32 = 2;

impl InputPoint {
    /// The point [m], its separation [m] and normal impulse [N·s], side by side in the
    /// record: one row of the wide build's transpose.
    #[inline(always)]
    pub fn row(&self) -> [f32; 4] {
        [self.point.x, self.point.y, self.separation, self.normal_impulse]
    }

    /// The friction impulse [N·s], preload [N·s], drift [m] and the flags word (its bits
    /// as a float's), side by side in the record: the other row.
    #[inline(always)]
    pub fn state_row(&self) -> [f32; 4] {
        [
            self.tangent_impulse,
            self.preload,
            self.drift,
            f32::from_bits(self.flags),
        ]
    }

    /// The flags word of a point that sticks or slides, new or not.
    #[inline(always)]
    pub fn flags_of(stick: bool, fresh: bool) -> u32 {
        (if stick { INPUT_STICK } else { 0 }) | (if fresh { INPUT_FRESH } else { 0 })
    }

    /// Whether the point sticks.
    #[inline(always)]
    pub fn stick(&self) -> bool {
        self.flags & INPUT_STICK != 0
    }

    /// Whether the point is new this step.
    #[inline(always)]
    pub fn fresh(&self) -> bool {
        self.flags & INPUT_FRESH != 0
    }
}

impl ContactInput {
    /// μs, μd, restitution and its threshold [m/s], side by side in the record: one row of
    /// the wide build's transpose.
    #[inline(always)]
    pub fn material_row(&self) -> [f32; 4] {
        [self.mu_s, self.mu_d, self.restitution, self.restitution_threshold]
    }

    /// Rolling resistance [m], surface speed [m/s], rolling impulse [N·m·s] (and a 0).
    #[inline(always)]
    pub fn surface_row(&self) -> [f32; 4] {
        [self.rolling_resistance, self.tangent_speed, self.rolling_impulse, 0.0]
    }

    /// No points, no material. The wide build reads it for an empty lane
    /// (`contact_wide::build_group`), so every float must stay +0.0.
    pub const EMPTY: ContactInput = ContactInput {
        normal: Vec2::ZERO,
        count: 0,
        points: [InputPoint {
            point: Vec2::ZERO,
            separation: 0.0,
            normal_impulse: 0.0,
            tangent_impulse: 0.0,
            preload: 0.0,
            drift: 0.0,
            flags: 0,
        }; 2],
        mu_s: 0.0,
        mu_d: 0.0,
        restitution: 0.0,
        restitution_threshold: 0.0,
        rolling_resistance: 0.0,
        tangent_speed: 0.0,
        rolling_impulse: 0.0,
    };

    /// Whether the contact may be new and resting ([`is_new_resting`], which also needs the
    /// approach speed): every point new this step and touching. Only these constraints are
    /// handed to the warm-start estimate; a contact with one new point beside an old one,
    /// or a speculative one, is not (tumbler: most of its new points are such).
    pub fn may_be_new_resting(&self) -> bool {
        let points = &self.points[..self.count.min(2)];
        !points.is_empty() && points.iter().all(|p| fresh_touching(p.fresh(), p.separation))
    }

    /// Writes what building a constraint reads of contact `c` in place (no copy).
    #[inline(always)]
    pub fn fill(&mut self, c: &Contact) {
        self.normal = c.manifold.normal;
        self.count = c.manifold.count.min(2);
        self.mu_s = c.material.friction_static;
        self.mu_d = c.material.friction_dynamic;
        self.restitution = c.material.restitution;
        self.restitution_threshold = c.material.restitution_threshold;
        self.rolling_resistance = c.material.rolling_resistance * c.rolling_radius;
        self.tangent_speed = c.material.tangent_speed;
        self.rolling_impulse = c.rolling_impulse;
        for (i, out) in self.points.iter_mut().enumerate() {
            *out = match (c.manifold.points.get(i), c.points.get(i)) {
                (Some(mp), Some(ps)) if i < self.count => InputPoint {
                    point: mp.point,
                    separation: mp.separation,
                    normal_impulse: ps.normal_impulse,
                    tangent_impulse: ps.tangent_impulse,
                    preload: ps.preload,
                    drift: ps.drift,
                    flags: InputPoint::flags_of(ps.state == FrictionState::Stick, ps.fresh),
                },
                _ => InputPoint::default(),
            };
        }
    }
}

/// Builds the scalar constraint of one touching contact: anchors, masses, the 2×2 block,
/// softness, and the friction state of new points (which needs the body velocities).
pub(crate) fn build_constraint<S: StateRead>(
    contact_index: u32,
    c: &ContactInput,
    bodies: &ConstraintBodies,
    up: Vec2,
    soft: &StepSoftness,
    ctx: &StepContext,
    states: &[S],
) -> ContactConstraint {
    let mut cc = ContactConstraint {
        index_a: bodies.index_a,
        index_b: bodies.index_b,
        contact: contact_index,
        normal: c.normal,
        inv_mass_a: bodies.inv_mass_a,
        inv_i_a: bodies.inv_i_a,
        inv_mass_b: bodies.inv_mass_b,
        inv_i_b: bodies.inv_i_b,
        mu_s: c.mu_s,
        mu_d: c.mu_d,
        restitution: c.restitution,
        restitution_threshold: c.restitution_threshold,
        rolling_resistance: c.rolling_resistance,
        rolling_mass: 0.0,
        rolling_impulse: if ctx.warm_starting { c.rolling_impulse } else { 0.0 },
        tangent_speed: c.tangent_speed,
        k: [0.0; 3],
        inv_det: 0.0,
        block: false,
        patch_tangent_mass: 0.0,
        kinetic_energy: 0.0,
        height: if c.count > 0 { c.points[0].point.dot(up) } else { 0.0 },
        split: {
            let sum = bodies.inv_mass_a + bodies.inv_mass_b;
            if sum > 0.0 {
                bodies.inv_mass_b / sum
            } else {
                0.5
            }
        },
        shift_cap2: shift_cap2(bodies.inv_mass_a, bodies.inv_i_a, bodies.inv_mass_b, bodies.inv_i_b),
        count: c.count,
        points: [ConstraintPoint::default(); 2],
    };
    let k_roll = bodies.inv_i_a + bodies.inv_i_b;
    cc.rolling_mass = if k_roll > 0.0 { 1.0 / k_roll } else { 0.0 };
    let n = cc.normal;
    let t = n.right_perp();
    let masses = cc_masses(bodies);
    let (sa, sb) = load(states, cc.index_a, cc.index_b);
    if cc.restitution > 0.0 {
        cc.kinetic_energy = pair_kinetic_energy(&cc, &sa, &sb);
    }
    // Contacts with static bodies are twice as stiff (Box2D v3's static softness).
    let point_soft = if cc.index_a == 0 || cc.index_b == 0 {
        soft.static_contact
    } else {
        soft.contact
    };
    for i in 0..cc.count {
        let ps = &c.points[i];
        let r_a = ps.point - bodies.center_a;
        let r_b = ps.point - bodies.center_b;
        let cp = &mut cc.points[i];
        cp.r_a = r_a;
        cp.r_b = r_b;
        cp.base_separation = ps.separation;
        cp.base_drift = if ps.stick() && !ps.fresh() { ps.drift } else { 0.0 };
        cp.normal_mass = inv_or_zero(effective_mass_inv(&masses, r_a, r_b, n));
        cp.tangent_mass = inv_or_zero(effective_mass_inv(&masses, r_a, r_b, t));
        if ctx.warm_starting {
            cp.normal_impulse = ps.normal_impulse;
            cp.tangent_impulse = ps.tangent_impulse;
            cp.preload = ps.preload;
        }
        cp.stick = ps.stick();
        cp.fresh = ps.fresh();
        cp.soft = point_soft;
        if cp.fresh {
            cp.stick = fresh_point_sticks(&sa, &sb, r_a, r_b, t, cc.tangent_speed, cp.base_separation, ctx);
        }
    }
    if cc.count == 2 {
        let (p0, p1) = (&cc.points[0], &cc.points[1]);
        let (rc_a, rc_b) = (0.5 * (p0.r_a + p1.r_a), 0.5 * (p0.r_b + p1.r_b));
        cc.patch_tangent_mass = inv_or_zero(effective_mass_inv(&masses, rc_a, rc_b, t));
        let (ra0, rb0, ra1, rb1) = (p0.r_a.cross(n), p0.r_b.cross(n), p1.r_a.cross(n), p1.r_b.cross(n));
        let m = masses.ma + masses.mb;
        let k11 = m + masses.ia * ra0 * ra0 + masses.ib * rb0 * rb0;
        let k22 = m + masses.ia * ra1 * ra1 + masses.ib * rb1 * rb1;
        let k12 = m + masses.ia * ra0 * ra1 + masses.ib * rb0 * rb1;
        let det = k11 * k22 - k12 * k12;
        // Box2D v2.4's guard: skip the block solve when K is near singular.
        if k11 * k11 < 1000.0 * det && det > 0.0 {
            let inv = 1.0 / det;
            cc.k = [k11, k12, k22];
            cc.inv_det = inv;
            cc.block = true;
        }
    }
    cc
}

/// The friction state a new point starts in: sliding only if it is already in contact
/// (separation ≤ linear slop [m]) and slipping faster than `ctx.stick_speed` [m/s] at the
/// bodies' step-start velocities; otherwise sticking.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn fresh_point_sticks(
    sa: &BodyState,
    sb: &BodyState,
    r_a: Vec2,
    r_b: Vec2,
    t: Vec2,
    tangent_speed: f32,
    separation: f32,
    ctx: &StepContext,
) -> bool {
    let dv = relative_velocity(sa, sb, r_a, r_b);
    let slip = (dv.dot(t) - tangent_speed).abs();
    let in_contact = separation <= crate::geometry::LINEAR_SLOP;
    !(in_contact && slip > ctx.stick_speed)
}

/// The two softness settings of a step's contacts.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StepSoftness {
    /// Between two moving bodies.
    pub contact: Softness,
    /// Against a static body: twice the frequency.
    pub static_contact: Softness,
}

impl StepSoftness {
    pub fn new(ctx: &StepContext) -> StepSoftness {
        StepSoftness {
            contact: Softness::new(ctx.contact_hertz, ctx.contact_damping_ratio, ctx.h),
            static_contact: Softness::new(2.0 * ctx.contact_hertz, ctx.contact_damping_ratio, ctx.h),
        }
    }
}

/// Records each point's normal velocity under `states` (the approach speed of new points).
pub(crate) fn record_approach<S: StateRead>(cc: &mut ContactConstraint, states: &[S]) {
    let (a, b) = load(states, cc.index_a, cc.index_b);
    for i in 0..cc.count {
        let (r_a, r_b) = (cc.points[i].r_a, cc.points[i].r_b);
        cc.points[i].substep_vn = point_velocity(cc, &a, &b, r_a, r_b).dot(cc.normal);
    }
}

/// Whether a point is new this step and touching (separation [m] within the slop): what
/// every point of a new resting contact is ([`ContactInput::may_be_new_resting`] before
/// the build, [`is_new_resting`] after).
#[inline]
fn fresh_touching(fresh: bool, separation: f32) -> bool {
    fresh && separation <= crate::geometry::LINEAR_SLOP
}

/// Whether a constraint is new and resting: every point fresh, touching and not hitting
/// (after [`record_approach`]).
pub(crate) fn is_new_resting(cc: &ContactConstraint) -> bool {
    cc.count > 0
        && cc.points[..cc.count]
            .iter()
            .all(|p| fresh_touching(p.fresh, p.base_separation) && p.substep_vn > -RESTING_SPEED)
}

/// Estimates warm-start impulses for new resting constraints (`subset`) by rigid sweeps
/// against `trial`, the states after one substep of forces: first the top-down statics
/// pass ([`statics_estimate`]), then sequential sweeps from the top down until the
/// normal impulses settle, at most `max_sweeps`. Sets each point's preload to its estimate.
pub(crate) fn estimate<S: StateCell>(
    subset: &mut [ContactConstraint],
    up: Vec2,
    ctx: &StepContext,
    trial: &[S],
    max_sweeps: usize,
) {
    if subset.is_empty() {
        return;
    }
    // Top-down order: a sweep then carries the weight of a whole stack down to the
    // ground at once (sequential impulses pass load one contact per sweep against the
    // order).
    sort_top_down(subset);
    statics_estimate(subset, up, trial);
    // Bound the work (the first step of a large scene pays it): at most
    // ESTIMATE_BUDGET row solves, between 16 and `max_sweeps` sweeps.
    let sweeps = (ESTIMATE_BUDGET / subset.len()).clamp(16, max_sweeps.max(16));
    // Constraints that share no moving body do not act on each other: each group of
    // linked constraints (a component) is swept until it settles by itself, so a few
    // slow groups (a tumbling pile's) no longer hold every other group to their count.
    // Inside a group the order and the sweeps are the ones a sweep of the whole subset
    // makes there.
    let members = components(subset, trial.len());
    let mut start = 0;
    while start < members.len() {
        let group = members[start].0;
        let end = start + members[start..].iter().take_while(|m| m.0 == group).count();
        for _ in 0..sweeps {
            let (mut change, mut largest) = (0.0f32, 0.0f32);
            for &(_, i) in &members[start..end] {
                let Some(cc) = subset.get_mut(i as usize) else { continue };
                // Both rows count: a start from the statics pass can have the normal
                // impulses right while friction (and through it the moments) is still
                // settling.
                let before = cc.points.map(|p| (p.normal_impulse, p.tangent_impulse));
                solve_one(cc, trial, ctx, false, 0.0);
                for (cp, (n, t)) in cc.points[..cc.count].iter().zip(before) {
                    change = change
                        .max((cp.normal_impulse - n).abs())
                        .max((cp.tangent_impulse - t).abs());
                    largest = largest.max(cp.normal_impulse);
                }
            }
            if change <= ESTIMATE_TOLERANCE * largest || change < 1e-9 {
                break;
            }
        }
        start = end;
    }
    for cc in subset.iter_mut() {
        for cp in &mut cc.points[..cc.count] {
            cp.preload = cp.normal_impulse;
            cp.max_normal_impulse = 0.0;
            cp.approach = 0.0;
            cp.saturated = false;
        }
    }
}

/// Sorts `subset` from the top down: height [m] falling, then contact index, then place
/// (the order the stable `sort_by` on height and contact gives). Sorted as a list of keys
/// and the records then moved once each: a sort that moves the records themselves (a
/// few hundred bytes each) spent most of its time in `memcpy` (the spinner's estimate,
/// ~450 new resting contacts a step).
fn sort_top_down(subset: &mut [ContactConstraint]) {
    let mut order: Vec<(f32, u32, u32)> = subset
        .iter()
        .enumerate()
        .map(|(i, cc)| (cc.height, cc.contact, i as u32))
        .collect();
    order.sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let sorted: Vec<ContactConstraint> = order
        .iter()
        .filter_map(|&(_, _, i)| subset.get(i as usize).copied())
        .collect();
    // Always equal (`order` is a permutation of the indices); the `if` keeps
    // `copy_from_slice` from panicking should that ever change.
    debug_assert_eq!(sorted.len(), subset.len());
    if sorted.len() == subset.len() {
        subset.copy_from_slice(&sorted);
    }
}

/// The constraints of `subset` grouped by the moving bodies they share (`n_states`: the
/// number of solver states): `(group, index)` pairs sorted by group, each group numbered
/// by its first constraint and listing its constraints in subset order. A static or
/// kinematic side (no inverse mass or inertia) links nothing: impulses do not move it.
fn components(subset: &[ContactConstraint], n_states: usize) -> Vec<(u32, u32)> {
    let mut parent: Vec<u32> = (0..n_states as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while let Some(&p) = parent.get(x as usize).filter(|&&p| p != x) {
            // Path halving.
            let grand = parent.get(p as usize).copied().unwrap_or(p);
            if let Some(slot) = parent.get_mut(x as usize) {
                *slot = grand;
            }
            x = grand;
        }
        x
    }
    let moving = |index: u32, inv_mass: f32, inv_i: f32| index != 0 && (inv_mass > 0.0 || inv_i > 0.0);
    for cc in subset {
        if moving(cc.index_a, cc.inv_mass_a, cc.inv_i_a) && moving(cc.index_b, cc.inv_mass_b, cc.inv_i_b) {
            let (ra, rb) = (root(&mut parent, cc.index_a), root(&mut parent, cc.index_b));
            // The smaller root wins: the grouping does not depend on the order of unions.
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            if let Some(slot) = parent.get_mut(hi as usize) {
                *slot = lo;
            }
        }
    }
    // A constraint's group: the first constraint with its root (a constraint with no
    // moving side is a group of its own).
    let mut first = vec![u32::MAX; n_states];
    let mut members: Vec<(u32, u32)> = Vec::with_capacity(subset.len());
    for (i, cc) in subset.iter().enumerate() {
        let side = if moving(cc.index_a, cc.inv_mass_a, cc.inv_i_a) {
            Some(cc.index_a)
        } else if moving(cc.index_b, cc.inv_mass_b, cc.inv_i_b) {
            Some(cc.index_b)
        } else {
            None
        };
        let group = match side.map(|b| root(&mut parent, b)) {
            Some(r) => match first.get_mut(r as usize) {
                Some(f) if *f == u32::MAX => {
                    *f = i as u32;
                    i as u32
                }
                Some(f) => *f,
                None => i as u32,
            },
            None => i as u32,
        };
        members.push((group, i as u32));
    }
    members.sort_unstable();
    members
}

/// First guess of the estimate: the loads of a rigid structure at rest, passed from the
/// top down (`subset` sorted by height, highest first). Each body that rests on
/// supports below it (contacts whose normal is within 60° of "up") carries its own
/// weight plus what the bodies above put on it; the total is shared between its
/// outermost supports by the lever rule (the two reactions whose moments about the
/// load's line of action balance: `w_hi = W (c − x_lo) / (x_hi − x_lo)`), evenly between
/// the points of one manifold, and passed on to the supporting bodies. This is exact
/// for stacks and pyramids (statically determinate per body) and a good start for piles;
/// the rigid sweeps that follow correct it. Sequential sweeps alone need on the order of
/// N² sweeps to carry the weight of an N-high stack to the ground.
pub(crate) fn statics_estimate<S: StateCell>(subset: &mut [ContactConstraint], up: Vec2, trial: &[S]) {
    if up == Vec2::ZERO {
        return;
    }
    let lat = up.right_perp();
    let n_states = trial.len();
    // Supports of each upper body, in subset order: (upper state, constraint, upper is B).
    let mut supports: Vec<(u32, usize, bool)> = Vec::new();
    for (i, cc) in subset.iter().enumerate() {
        let up_n = cc.normal.dot(up);
        let (upper, upper_is_b, inv_m) = if up_n > 0.5 {
            (cc.index_b, true, cc.inv_mass_b)
        } else if up_n < -0.5 {
            (cc.index_a, false, cc.inv_mass_a)
        } else {
            continue;
        };
        if upper != 0 && inv_m > 0.0 {
            supports.push((upper, i, upper_is_b));
        }
    }
    if supports.is_empty() {
        return;
    }
    // Order of first appearance (highest support first) for each upper body.
    let mut first = vec![u32::MAX; n_states];
    for (k, s) in supports.iter().enumerate() {
        let f = &mut first[s.0 as usize];
        *f = (*f).min(k as u32);
    }
    supports.sort_by_key(|s| (first[s.0 as usize], s.1));
    let mut carried = vec![0.0f32; n_states];
    let mut moment = vec![0.0f32; n_states];
    let mut start = 0;
    while start < supports.len() {
        let upper = supports[start].0;
        let mut end = start;
        while end < supports.len() && supports[end].0 == upper {
            end += 1;
        }
        let group = &supports[start..end];
        start = end;
        let (i0, b0) = (group[0].1, group[0].2);
        let inv_m = if b0 {
            subset[i0].inv_mass_b
        } else {
            subset[i0].inv_mass_a
        };
        // Own weight: the impulse that stops this substep's fall, acting at the centre.
        let fall = (-trial[upper as usize].get().v.dot(up)).max(0.0);
        let own = fall / inv_m;
        let w_total = own + carried[upper as usize];
        if w_total <= 0.0 {
            continue;
        }
        let c = moment[upper as usize] / w_total;
        // Lateral position of each support (mean of its points) from the upper centre.
        let x_of = |cc: &ContactConstraint, upper_is_b: bool| {
            let sum: f32 = cc.points[..cc.count]
                .iter()
                .map(|p| if upper_is_b { p.r_b } else { p.r_a }.dot(lat))
                .sum();
            sum / cc.count as f32
        };
        let (mut lo, mut hi) = (0usize, 0usize);
        let xs: Vec<f32> = group.iter().map(|s| x_of(&subset[s.1], s.2)).collect();
        for k in 0..xs.len() {
            if xs[k] < xs[lo] {
                lo = k;
            }
            if xs[k] > xs[hi] {
                hi = k;
            }
        }
        let mut shares = vec![0.0f32; group.len()];
        if xs[hi] - xs[lo] < 1e-6 {
            shares.iter_mut().for_each(|s| *s = w_total / group.len() as f32);
        } else {
            let w_hi = (w_total * (c - xs[lo]) / (xs[hi] - xs[lo])).clamp(0.0, w_total);
            shares[hi] = w_hi;
            shares[lo] = w_total - w_hi;
        }
        for (k, &(_, ci, upper_is_b)) in group.iter().enumerate() {
            let w = shares[k];
            let cc = &mut subset[ci];
            let up_n = cc.normal.dot(up).abs();
            let count = cc.count;
            for cp in &mut cc.points[..count] {
                cp.normal_impulse = w / (count as f32 * up_n);
            }
            let lower = if upper_is_b { cc.index_a } else { cc.index_b };
            if lower != 0 {
                // The reaction's lateral position seen from the lower body's centre.
                let x_lower: f32 = cc.points[..count]
                    .iter()
                    .map(|p| if upper_is_b { p.r_a } else { p.r_b }.dot(lat))
                    .sum::<f32>()
                    / count as f32;
                carried[lower as usize] += w;
                moment[lower as usize] += w * x_lower;
            }
        }
    }
    // The trial velocities must carry the impulses the sweeps start from.
    for &(_, ci, _) in &supports {
        let cc = &subset[ci];
        let (mut a, mut b) = load(trial, cc.index_a, cc.index_b);
        for cp in &cc.points[..cc.count] {
            apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, cp.normal_impulse * cc.normal);
        }
        store(trial, cc.index_a, cc.index_b, a, b);
    }
}

/// Bias and softness of one normal row in the current pass, with its current velocity
/// and the moments of its lever arms about the normal ([`RowFrame::point`]).
#[derive(Clone, Copy, Debug, Default)]
struct NormalRow {
    vn: f32,
    m: (f32, f32),
    bias: f32,
    mass_scale: f32,
    impulse_scale: f32,
}

/// Point `cp`'s normal row in this pass; `frame`: the normal's [`RowFrame`] (made once for
/// the constraint's points: the pass does not move the bodies).
#[inline]
fn normal_row(
    frame: &RowFrame,
    cp: &ConstraintPoint,
    a: &BodyState,
    b: &BodyState,
    ctx: &StepContext,
    use_bias: bool,
) -> NormalRow {
    let n = frame.u;
    let (m, disp) = frame.point(a, b, cp.r_a, cp.r_b);
    let s = disp + cp.base_separation;
    let (bias, mass_scale, impulse_scale) = if s > 0.0 {
        // Speculative: allow approach that exactly closes the gap.
        (s * ctx.inv_h, 1.0, 0.0)
    } else if use_bias {
        (
            (cp.soft.bias_rate * s).max(-ctx.push_speed),
            cp.soft.mass_scale,
            cp.soft.impulse_scale,
        )
    } else {
        (0.0, 1.0, 0.0)
    };
    NormalRow {
        vn: row_speed(a, b, n, m),
        m,
        bias,
        mass_scale,
        impulse_scale,
    }
}

/// Solves both normal rows of a 2-point manifold at once (the 2×2 LCP by enumeration of
/// the active set, as in Box2D v2.4's block solver, here in soft form):
/// `x = λ − S·K⁻¹(v + b) − I·(λ − λ_pre)` with S, I the rows' mass and impulse scales.
/// Returns `None` when no case is consistent (the caller then solves the rows in turn).
fn solve_block(cc: &ContactConstraint, rows: &[NormalRow; 2]) -> Option<[f32; 2]> {
    let (p0, p1) = (&cc.points[0], &cc.points[1]);
    let lam = [p0.normal_impulse, p1.normal_impulse];
    let pre = [p0.preload, p1.preload];
    let rhs = [rows[0].vn + rows[0].bias, rows[1].vn + rows[1].bias];
    let [k11, k12, k22] = cc.k;
    let (i11, i12, i22) = (k22 * cc.inv_det, -k12 * cc.inv_det, k11 * cc.inv_det);
    let soft = |i: usize, rigid_delta: f32| {
        lam[i] + rows[i].mass_scale * rigid_delta - rows[i].impulse_scale * (lam[i] - pre[i])
    };
    // Both active.
    let d0 = -(i11 * rhs[0] + i12 * rhs[1]);
    let d1 = -(i12 * rhs[0] + i22 * rhs[1]);
    let x = [soft(0, d0), soft(1, d1)];
    if x[0] >= 0.0 && x[1] >= 0.0 {
        return Some(x);
    }
    // Only point 0 active (point 1 released): v0 changes by k12·(0 − λ1).
    let r0 = rhs[0] - k12 * lam[1];
    let x0 = soft(0, -r0 / k11);
    if x0 >= 0.0 {
        let w1 = rhs[1] + k12 * (x0 - lam[0]) - k22 * lam[1];
        if w1 >= 0.0 {
            return Some([x0, 0.0]);
        }
    }
    // Only point 1 active.
    let r1 = rhs[1] - k12 * lam[0];
    let x1 = soft(1, -r1 / k22);
    if x1 >= 0.0 {
        let w0 = rhs[0] + k12 * (x1 - lam[1]) - k11 * lam[0];
        if w0 >= 0.0 {
            return Some([0.0, x1]);
        }
    }
    // Neither active.
    let w0 = rhs[0] - k11 * lam[0] - k12 * lam[1];
    let w1 = rhs[1] - k12 * lam[0] - k22 * lam[1];
    if w0 >= 0.0 && w1 >= 0.0 {
        return Some([0.0, 0.0]);
    }
    None
}

/// Most rigid sweeps used to estimate the impulses of contacts that begin at rest, when
/// they are most of the step's contacts (a scene or a structure placed at rest).
pub(crate) const MAX_ESTIMATE_SWEEPS: usize = 4096;

/// Most rigid sweeps for the new resting contacts of a step in which they are a minority
/// (bodies settling into a moving pile): the rest of the pile already carries its warm
/// start, and in a tumbling pile (Box2D's washer) a few of these subsets converged only
/// after thousands of sweeps — 8 ms per step, a fifth of the step, for a warm-start guess.
/// Half the subsets there converge within 75 sweeps.
pub(crate) const ONGOING_ESTIMATE_SWEEPS: usize = 128;

/// Constraint solves the estimate may spend in one step (about 0.2 s on a 2.6 GHz core).
const ESTIMATE_BUDGET: usize = 2_000_000;

/// The estimate stops when a sweep changes no normal impulse by more than this fraction of
/// the largest.
const ESTIMATE_TOLERANCE: f32 = 1e-4;

/// Approach speed [m/s] below which a new touching contact counts as resting.
const RESTING_SPEED: f32 = 0.5;

/// The preload a point carries into the next step (module docs): seeded by a new point's
/// load (unless the point bounced: its impulse then holds the restitution kick, not a
/// load), then kept while the point's load stays at least half of it; a step without load,
/// or with less than half, clears it for good (re-seeding contacts whose load flickers,
/// such as the side contacts of a pyramid's rows, kicked the pyramid into swaying).
///
/// Why both guards: a preload the contact does not carry keeps pushing the bodies apart,
/// at about s_i·λ_pre / (s_m·m) per substep once they separate. In Box2D's spinner with
/// μs = 1.5 μd, bodies the rotor had pressed into the wall kept 40–50 N·s preloads after
/// the squeeze (25 m/s of push on a 0.1 kg body); and points that began in an impact were
/// seeded with their bounce impulse, whose push made the next impacts, whose bounces seeded
/// the next preloads: the pile blew up within 70 steps. A steady load stays within a few
/// percent of its preload, so stacks keep theirs.
pub(crate) fn next_preload(preload: f32, normal: f32, max_normal: f32, fresh: bool, bounced: bool) -> f32 {
    if max_normal <= 0.0 || (fresh && bounced) {
        0.0
    } else if fresh {
        normal
    } else if normal < 0.5 * preload {
        0.0
    } else {
        preload
    }
}

/// Whether the restitution pass gave a point a bounce ([`restitution_one`]'s test).
#[inline]
pub(crate) fn bounces(restitution: f32, threshold: f32, approach: f32, max_normal: f32) -> bool {
    restitution > 0.0 && approach <= -threshold && max_normal > 0.0
}

/// Mass ratio above which a light body's constraints get extra local sweeps.
pub(crate) const MASS_RATIO_GROUP: f32 = 4.0;

/// Most extra local sweeps per pass for one light body.
pub(crate) const MAX_LOCAL_SWEEPS: u32 = 64;

/// Inverse masses of a constraint's bodies.
struct Masses {
    ma: f32,
    ia: f32,
    mb: f32,
    ib: f32,
}

fn cc_masses(b: &ConstraintBodies) -> Masses {
    Masses {
        ma: b.inv_mass_a,
        ia: b.inv_i_a,
        mb: b.inv_mass_b,
        ib: b.inv_i_b,
    }
}

/// k = m_a⁻¹ + m_b⁻¹ + I_a⁻¹ (r_a × d)² + I_b⁻¹ (r_b × d)².
#[inline]
fn effective_mass_inv(m: &Masses, r_a: Vec2, r_b: Vec2, d: Vec2) -> f32 {
    let ra = r_a.cross(d);
    let rb = r_b.cross(d);
    m.ma + m.mb + m.ia * ra * ra + m.ib * rb * rb
}

#[inline]
fn inv_or_zero(k: f32) -> f32 {
    if k > 0.0 {
        1.0 / k
    } else {
        0.0
    }
}

/// Lever arms of an impulse at substep time: the anchors are fixed at the start of the
/// step, but the two bodies move apart within it, so A's anchor and B's anchor drift to
/// different world points. Applying ±P at two different points would add a torque couple
/// (dp_b − dp_a) × P and break conservation of angular momentum. Both arms are therefore
/// moved to one common point, weighted toward the lighter body's anchor (the static side's
/// anchor does not matter):
/// `p = p_a + w (p_b − p_a)` with `w = m_b⁻¹ / (m_a⁻¹ + m_b⁻¹)`.
///
/// The effective masses are those of the anchors at the start of the step; the arms
/// follow the bodies' relative displacement in full only while it is short against the
/// bodies' size ([`capped_shift`]).
#[inline]
fn lever_arms(cc: &ContactConstraint, a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> (Vec2, Vec2) {
    let d = capped_shift(b.dp - a.dp, cc.shift_cap2);
    (r_a + cc.split * d, r_b - (1.0 - cc.split) * d)
}

/// The relative displacement `d` [m] the lever arms follow: `d` itself while
/// |d|² ≤ `cap2`, else `d` shortened to length √cap2.
///
/// Why a cap: the rows' effective masses are computed once per step from the anchors; an
/// arm moved by `s` changes the angular term `I⁻¹ (r × n)²` of the true effective mass, and
/// a sequential-impulse row whose true effective mass is more than twice the one it
/// assumes overshoots by more than it corrects: the error grows every pass. In a jam
/// (Box2D's spinner: a rotor with unbounded torque wedging light bodies against the wall,
/// which slide 0.5 m past each other within a step) a body's angular velocity grew ×12 per
/// relax pass, 10³⁸ within a step. [`shift_cap2`] keeps the arms within half the radius
/// of gyration of the bodies, where the angular term changes by at most about the linear
/// one; below the cap (bodies that move less than that relative to each other in a step,
/// as every resting and almost every moving contact does) nothing changes.
#[inline]
pub(crate) fn capped_shift(d: Vec2, cap2: f32) -> Vec2 {
    let d2 = d.length_squared();
    if d2 > cap2 {
        d * (cap2 / d2).sqrt()
    } else {
        d
    }
}

/// The cap of [`capped_shift`] for a constraint's two bodies (inverse masses [1/kg] and
/// inertias [1/(kg·m²)]): (½ ρ)² with ρ the smaller radius of gyration, √(I/m), of a side
/// that turns (a static or non-rotating side does not constrain it; none at all: no cap).
pub(crate) fn shift_cap2(inv_mass_a: f32, inv_i_a: f32, inv_mass_b: f32, inv_i_b: f32) -> f32 {
    let side = |inv_m: f32, inv_i: f32| if inv_i > 0.0 { inv_m / inv_i } else { f32::MAX };
    let rho2 = side(inv_mass_a, inv_i_a).min(side(inv_mass_b, inv_i_b));
    if rho2 < f32::MAX {
        0.25 * rho2
    } else {
        f32::MAX
    }
}

/// Kinetic energy [J] of a constraint's two bodies (a static side counts zero).
fn pair_kinetic_energy(cc: &ContactConstraint, a: &BodyState, b: &BodyState) -> f32 {
    kinetic_energy_of(cc.inv_mass_a, cc.inv_i_a, cc.inv_mass_b, cc.inv_i_b, a, b)
}

/// [`pair_kinetic_energy`] from the two sides' inverse masses [1/kg] and inertias
/// [1/(kg·m²)].
pub(crate) fn kinetic_energy_of(
    inv_mass_a: f32,
    inv_i_a: f32,
    inv_mass_b: f32,
    inv_i_b: f32,
    a: &BodyState,
    b: &BodyState,
) -> f32 {
    let part = |inv_m: f32, inv_i: f32, s: &BodyState| {
        let lin = if inv_m > 0.0 {
            0.5 * s.v.length_squared() / inv_m
        } else {
            0.0
        };
        let ang = if inv_i > 0.0 { 0.5 * s.w * s.w / inv_i } else { 0.0 };
        lin + ang
    };
    part(inv_mass_a, inv_i_a, a) + part(inv_mass_b, inv_i_b, b)
}

/// A row direction `u`'s part of a solver pass that its points share: the bodies'
/// relative displacement along `u` [m] and the moments the shift of [`lever_arms`] adds
/// to the arms (r_a + σ s and r_b − (1 − σ) s give r_a × u + σ (s × u) and
/// r_b × u − (1 − σ)(s × u)). A row then needs the two moments of its arms, not their four
/// coordinates: its speed and impulse are [`row_speed`] and [`apply_row`]. The wide
/// solver (`contact_wide::RowFrame`) computes the same expressions in the same order.
#[derive(Clone, Copy)]
struct RowFrame {
    u: Vec2,
    along: f32,
    shift_a: f32,
    shift_b: f32,
}

impl RowFrame {
    #[inline]
    fn new(cc: &ContactConstraint, a: &BodyState, b: &BodyState, u: Vec2) -> RowFrame {
        let d = b.dp - a.dp;
        let su = capped_shift(d, cc.shift_cap2).cross(u);
        RowFrame {
            u,
            along: d.dot(u),
            shift_a: cc.split * su,
            shift_b: (1.0 - cc.split) * su,
        }
    }

    /// The moments (r_a × u, r_b × u) [m] of a point's lever arms (anchors `r_a`, `r_b`
    /// at the step start, moved by [`lever_arms`]) and the displacement [m] of its material
    /// points along `u` since the step start, to first order in the rotation:
    /// `(Δp_b − Δp_a + sin(Δθ_b) ẑ×r_b − sin(Δθ_a) ẑ×r_a)·u` =
    /// d·u + sin Δθ_b (r_b × u) − sin Δθ_a (r_a × u).
    ///
    /// Box2D v3 rotates the anchors fully; the second-order term `(cos Δθ − 1) r` then lifts
    /// a spinning disk off the ground (its material point rises although its surface does
    /// not), which weakens the contact of a rolling or skidding disk (the
    /// "slipping-to-rolling comes late" error of Box2D and Rapier). The first-order form
    /// matches the velocity Jacobian.
    #[inline]
    fn point(&self, a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> ((f32, f32), f32) {
        let (ma, mb) = (r_a.cross(self.u), r_b.cross(self.u));
        let disp = self.along + b.dq.s * mb - a.dq.s * ma;
        ((ma + self.shift_a, mb - self.shift_b), disp)
    }
}

/// The relative velocity [m/s] along `u` at arms of moments `m` ([`RowFrame::point`]):
/// u·(v_b − v_a) + ω_b (r_b × u) − ω_a (r_a × u) = [`relative_velocity`]`(..).dot(u)`.
#[inline]
fn row_speed(a: &BodyState, b: &BodyState, u: Vec2, m: (f32, f32)) -> f32 {
    (b.v - a.v).dot(u) + b.w * m.1 - a.w * m.0
}

/// Applies the impulse `lambda` [N·s] along `u` at arms of moments `m`: −u λ to A, +u λ to
/// B ([`apply`] of `lambda * u`).
#[inline]
fn apply_row(cc: &ContactConstraint, a: &mut BodyState, b: &mut BodyState, u: Vec2, m: (f32, f32), lambda: f32) {
    a.v -= (cc.inv_mass_a * lambda) * u;
    a.w -= cc.inv_i_a * (m.0 * lambda);
    b.v += (cc.inv_mass_b * lambda) * u;
    b.w += cc.inv_i_b * (m.1 * lambda);
}

/// Relative velocity at a contact point, measured at the common point of [`lever_arms`].
#[inline]
fn point_velocity(cc: &ContactConstraint, a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> Vec2 {
    let (r_a, r_b) = lever_arms(cc, a, b, r_a, r_b);
    relative_velocity(a, b, r_a, r_b)
}

/// Velocity of B's point minus A's point.
#[inline]
fn relative_velocity(a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> Vec2 {
    (b.v + Vec2::cross_sv(b.w, r_b)) - (a.v + Vec2::cross_sv(a.w, r_a))
}

/// Applies the impulse `p` at the anchors' common point (see [`lever_arms`]): −p to A,
/// +p to B.
#[inline]
fn apply(cc: &ContactConstraint, a: &mut BodyState, b: &mut BodyState, r_a: Vec2, r_b: Vec2, p: Vec2) {
    let (r_a, r_b) = lever_arms(cc, a, b, r_a, r_b);
    a.v -= cc.inv_mass_a * p;
    a.w -= cc.inv_i_a * r_a.cross(p);
    b.v += cc.inv_mass_b * p;
    b.w += cc.inv_i_b * r_b.cross(p);
}

/// Relative displacement of the contact point's two material points since the step start,
/// to first order in the rotation (see [`RowFrame::point`], which the passes use: its
/// projection on a row direction); the reference the moment form is tested against.
#[cfg(test)]
fn anchor_displacement(a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> Vec2 {
    (b.dp - a.dp) + (b.dq.s * r_b.left_perp() - a.dq.s * r_a.left_perp())
}

/// Reads two body states; index 0 is the shared static body, never written.
#[inline]
fn load<S: StateRead>(states: &[S], ia: u32, ib: u32) -> (BodyState, BodyState) {
    (states[ia as usize].get(), states[ib as usize].get())
}

#[inline]
fn store<S: StateCell>(states: &[S], ia: u32, ib: u32, a: BodyState, b: BodyState) {
    if ia != 0 {
        states[ia as usize].set(a);
    }
    if ib != 0 {
        states[ib as usize].set(b);
    }
}

/// Restitution for one constraint (after all substeps): points that approached faster
/// than the threshold and took load bounce with `e` times their approach speed.
pub(crate) fn restitution_one<S: StateCell>(cc: &mut ContactConstraint, states: &[S]) {
    if cc.restitution == 0.0 {
        return;
    }
    let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
    let n = cc.normal;
    let bounces = |p: &ConstraintPoint| {
        bounces(
            cc.restitution,
            cc.restitution_threshold,
            p.approach,
            p.max_normal_impulse,
        )
    };
    if cc.count == 2 && cc.block && bounces(&cc.points[0]) && bounces(&cc.points[1]) {
        // Both points of a face bounce: solve them together, or the second point's
        // impulse would add to the rebound the first already set (energy gain).
        let mut rows = [NormalRow::default(); 2];
        for (row, cp) in rows.iter_mut().zip(&cc.points) {
            *row = NormalRow {
                vn: point_velocity(cc, &a, &b, cp.r_a, cp.r_b).dot(n),
                // Unused: restitution applies its impulses in arm form (`apply`), as the
                // wide restitution does.
                m: (0.0, 0.0),
                bias: cc.restitution * cp.approach,
                mass_scale: 1.0,
                impulse_scale: 0.0,
            };
        }
        if let Some(x) = solve_block(cc, &rows) {
            for (i, &xi) in x.iter().enumerate() {
                let cp = cc.points[i];
                apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, (xi - cp.normal_impulse) * n);
                let cp = &mut cc.points[i];
                cp.total_normal_impulse += xi - cp.normal_impulse;
                cp.normal_impulse = xi;
                cp.max_normal_impulse = cp.max_normal_impulse.max(xi);
            }
            store(states, cc.index_a, cc.index_b, a, b);
            return;
        }
    }
    for i in 0..cc.count {
        let cp = cc.points[i];
        if !bounces(&cp) {
            continue;
        }
        let vn = point_velocity(cc, &a, &b, cp.r_a, cp.r_b).dot(n);
        // Effective mass at the lever arms the impulse will act through now.
        let (r_a, r_b) = lever_arms(cc, &a, &b, cp.r_a, cp.r_b);
        let masses = Masses {
            ma: cc.inv_mass_a,
            ia: cc.inv_i_a,
            mb: cc.inv_mass_b,
            ib: cc.inv_i_b,
        };
        let normal_mass = inv_or_zero(effective_mass_inv(&masses, r_a, r_b, n));
        let mut impulse = -normal_mass * (vn + cc.restitution * cp.approach);
        // Never bounce back with more energy than the pair had before the step:
        // along n the pair's energy is KE + λ·vn + λ²/(2 m_n); keep it ≤ KE₀.
        // (The impact speed and the lever arms are sampled at slightly different
        // moments of the step, which could otherwise add a little energy.)
        if impulse > 0.0 && normal_mass > 0.0 {
            let ke = pair_kinetic_energy(cc, &a, &b);
            let room = cc.kinetic_energy - ke;
            // λ²/(2 m_n) + λ vn − room ≤ 0 → λ ≤ m_n (−vn + √(vn² + 2 room / m_n))
            let disc = vn * vn + 2.0 * room / normal_mass;
            let max = if disc > 0.0 {
                normal_mass * (-vn + disc.sqrt())
            } else {
                0.0
            };
            impulse = impulse.min(max.max(0.0));
        }
        let new = (cp.normal_impulse + impulse).max(0.0);
        let delta = new - cp.normal_impulse;
        apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, delta * n);
        let cp = &mut cc.points[i];
        cp.normal_impulse = new;
        cp.total_normal_impulse += delta;
        cp.max_normal_impulse = cp.max_normal_impulse.max(new);
    }
    store(states, cc.index_a, cc.index_b, a, b);
}

/// Re-applies one constraint's accumulated impulses at the start of a substep, after
/// recording its points' normal velocities (restitution's impact speed).
pub(crate) fn warm_start_one<S: StateCell>(cc: &mut ContactConstraint, states: &[S]) {
    let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
    let n = cc.normal;
    let t = n.right_perp();
    for i in 0..cc.count {
        let (r_a, r_b) = (cc.points[i].r_a, cc.points[i].r_b);
        cc.points[i].substep_vn = point_velocity(cc, &a, &b, r_a, r_b).dot(n);
    }
    for cp in &cc.points[..cc.count] {
        let p = cp.normal_impulse * n + cp.tangent_impulse * t;
        apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, p);
    }
    a.w -= cc.inv_i_a * cc.rolling_impulse;
    b.w += cc.inv_i_b * cc.rolling_impulse;
    store(states, cc.index_a, cc.index_b, a, b);
}

/// One pass over one contact: normal rows, friction rows, rolling resistance.
pub(crate) fn solve_one<S: StateCell>(
    cc: &mut ContactConstraint,
    states: &[S],
    ctx: &StepContext,
    use_bias: bool,
    elapsed: f32,
) {
    let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
    solve_normals(cc, &mut a, &mut b, ctx, use_bias);
    if !use_bias {
        // Dead after the relax (only the substep's positions, integrated between the
        // solve and the relax, read it); 0, as the wide relax writes.
        a.touched = 0.0;
        b.touched = 0.0;
    } else if cc.points[..cc.count].iter().any(|p| p.normal_impulse > 0.0) {
        a.touched = 1.0;
        b.touched = 1.0;
    }
    solve_friction(cc, &mut a, &mut b, ctx, use_bias, elapsed);
    // A rolling impulse left without resistance (none can arise from a scene today) is
    // relaxed to zero, as the wide solver's lanes do, not warm-started every substep.
    if (cc.rolling_resistance > 0.0 || cc.rolling_impulse != 0.0) && !use_bias {
        solve_rolling(cc, &mut a, &mut b);
    }
    store(states, cc.index_a, cc.index_b, a, b);
}

/// Normal rows: the two points of a manifold together when the 2×2 system is well
/// conditioned (exact within the manifold), else one after the other.
fn solve_normals(cc: &mut ContactConstraint, a: &mut BodyState, b: &mut BodyState, ctx: &StepContext, use_bias: bool) {
    let n = cc.normal;
    let frame = RowFrame::new(cc, a, b, n);
    let mut rows = [NormalRow::default(); 2];
    for (row, cp) in rows.iter_mut().zip(&cc.points[..cc.count]) {
        *row = normal_row(&frame, cp, a, b, ctx, use_bias);
    }
    let block = if cc.count == 2 && cc.block {
        solve_block(cc, &rows)
    } else {
        None
    };
    match block {
        Some(x) => {
            for (i, &xi) in x.iter().enumerate() {
                let cp = cc.points[i];
                apply_row(cc, a, b, n, rows[i].m, xi - cp.normal_impulse);
                cc.points[i].normal_impulse = xi;
            }
        }
        None => {
            for i in 0..cc.count {
                let cp = cc.points[i];
                let row = if i == 0 {
                    rows[0]
                } else {
                    normal_row(&frame, &cp, a, b, ctx, use_bias)
                };
                let impulse = -cp.normal_mass * row.mass_scale * (row.vn + row.bias)
                    - row.impulse_scale * (cp.normal_impulse - cp.preload);
                let new = (cp.normal_impulse + impulse).max(0.0);
                apply_row(cc, a, b, n, row.m, new - cp.normal_impulse);
                cc.points[i].normal_impulse = new;
            }
        }
    }
    for cp in &mut cc.points[..cc.count] {
        let new = cp.normal_impulse;
        cp.max_normal_impulse = cp.max_normal_impulse.max(new);
        if new > 0.0 && cp.substep_vn < cp.approach {
            cp.approach = cp.substep_vn;
        }
    }
}

/// Friction, after the normal rows so the clamp uses this pass's λn. The limit is μs·λn
/// while sticking, μd·λn while slipping; a sticking row's biased pass also drives the
/// drift back to zero.
///
/// A 2-point manifold (a face contact) gets one friction row at the middle of its points,
/// clamped by μ times the sum of their normal impulses: the patch grips or slides as a
/// whole (PhysX's patch friction; in 2D there is no twist row). Per-point rows solved in
/// turn put all the friction on whichever point comes first, which then saturates at its
/// own share while the other has room; with a light body between a heavy one and the
/// ground that starves the contact of friction for many steps.
fn solve_friction(
    cc: &mut ContactConstraint,
    a: &mut BodyState,
    b: &mut BodyState,
    ctx: &StepContext,
    use_bias: bool,
    elapsed: f32,
) {
    let t = cc.normal.right_perp();
    if cc.count == 2 {
        let (p0, p1) = (cc.points[0], cc.points[1]);
        let r_a = 0.5 * (p0.r_a + p1.r_a);
        let r_b = 0.5 * (p0.r_b + p1.r_b);
        let stick = p0.stick && p1.stick;
        let mu = if stick { cc.mu_s } else { cc.mu_d };
        let limit = mu * (p0.normal_impulse + p1.normal_impulse);
        let (m, disp) = RowFrame::new(cc, a, b, t).point(a, b, r_a, r_b);
        let vt = row_speed(a, b, t, m) - cc.tangent_speed;
        let bias = if use_bias && stick && limit > 0.0 {
            let drift = disp + 0.5 * (p0.base_drift + p1.base_drift) - cc.tangent_speed * elapsed;
            (p0.soft.bias_rate * drift).clamp(-ctx.push_speed, ctx.push_speed)
        } else {
            0.0
        };
        let old = p0.tangent_impulse + p1.tangent_impulse;
        let impulse = -cc.patch_tangent_mass * (vt + bias);
        let unclamped = old + impulse;
        let new = unclamped.clamp(-limit, limit);
        apply_row(cc, a, b, t, m, new - old);
        for cp in &mut cc.points {
            cp.tangent_impulse = 0.5 * new;
            if !use_bias {
                cp.saturated = limit > 0.0 && unclamped.abs() > limit;
            }
        }
        return;
    }
    let frame = RowFrame::new(cc, a, b, t);
    for i in 0..cc.count {
        let cp = cc.points[i];
        let mu = if cp.stick { cc.mu_s } else { cc.mu_d };
        let limit = mu * cp.normal_impulse;
        let (m, disp) = frame.point(a, b, cp.r_a, cp.r_b);
        let vt = row_speed(a, b, t, m) - cc.tangent_speed;
        let bias = if use_bias && cp.stick && cp.normal_impulse > 0.0 {
            let drift = disp + cp.base_drift - cc.tangent_speed * elapsed;
            (cp.soft.bias_rate * drift).clamp(-ctx.push_speed, ctx.push_speed)
        } else {
            0.0
        };
        let impulse = -cp.tangent_mass * (vt + bias);
        let unclamped = cp.tangent_impulse + impulse;
        let new = unclamped.clamp(-limit, limit);
        apply_row(cc, a, b, t, m, new - cp.tangent_impulse);
        let cp = &mut cc.points[i];
        cp.tangent_impulse = new;
        if !use_bias {
            cp.saturated = limit > 0.0 && unclamped.abs() > limit;
        }
    }
}

/// Rolling resistance: an angular row clamped by the manifold's total normal impulse.
fn solve_rolling(cc: &mut ContactConstraint, a: &mut BodyState, b: &mut BodyState) {
    let total_normal: f32 = cc.points[..cc.count].iter().map(|p| p.normal_impulse).sum();
    let limit = cc.rolling_resistance * total_normal;
    let impulse = -cc.rolling_mass * (b.w - a.w);
    let new = (cc.rolling_impulse + impulse).clamp(-limit, limit);
    let delta = new - cc.rolling_impulse;
    cc.rolling_impulse = new;
    a.w -= cc.inv_i_a * delta;
    b.w += cc.inv_i_b * delta;
}

/// Writes impulses back into the contact and its reported sums (`sums`), and runs the
/// stick/slip transitions (store stage). `states` are the end-of-step states.
pub(crate) fn store_impulses<S: StateRead>(
    cc: &ContactConstraint,
    contact: &mut Contact,
    sums: &mut ContactSums,
    states: &[S],
    ctx: &StepContext,
) {
    let (a, b) = load(states, cc.index_a, cc.index_b);
    let t = cc.normal.right_perp();
    contact.rolling_impulse = cc.rolling_impulse;
    // A face contact slides as a whole: its points turn to Slip only when the manifold's
    // total friction reached μs times its total normal impulse (PhysX's per-patch
    // "broken" flag), not when sequential solving happened to load one point to its
    // share's limit while the other still had room.
    let (sum_t, sum_n) = cc.points[..cc.count].iter().fold((0.0f32, 0.0f32), |(t, n), p| {
        (t + p.tangent_impulse, n + p.normal_impulse)
    });
    let patch_saturated = sum_t.abs() >= 0.999 * cc.mu_s * sum_n && cc.points[..cc.count].iter().any(|p| p.saturated);
    let sum_total_t: f32 = cc.points[..cc.count].iter().map(|p| p.total_tangent_impulse).sum();
    let sum_total_n: f32 = cc.points[..cc.count].iter().map(|p| p.total_normal_impulse).sum();
    let frame = RowFrame::new(cc, &a, &b, t);
    for ((cp, ps), sum) in cc.points[..cc.count]
        .iter()
        .zip(contact.points.iter_mut())
        .zip(sums.iter_mut())
    {
        ps.normal_impulse = cp.normal_impulse;
        ps.tangent_impulse = cp.tangent_impulse;
        sum.total_normal_impulse = cp.total_normal_impulse;
        // A face contact's friction is one patch row (split evenly inside the solver, which
        // is the same as acting at the middle); report it split in proportion to the
        // points' normal impulses, so each point shows |f| ≤ μ·n like the patch does.
        sum.total_tangent_impulse = if cc.count == 2 && sum_total_n > 0.0 {
            sum_total_t * cp.total_normal_impulse / sum_total_n
        } else {
            cp.total_tangent_impulse
        };
        sum.max_normal_impulse = cp.max_normal_impulse;
        let bounced = bounces(
            cc.restitution,
            cc.restitution_threshold,
            cp.approach,
            cp.max_normal_impulse,
        );
        ps.preload = next_preload(cp.preload, cp.normal_impulse, cp.max_normal_impulse, cp.fresh, bounced);
        ps.fresh = false;
        let (m, disp) = frame.point(&a, &b, cp.r_a, cp.r_b);
        let vt = row_speed(&a, &b, t, m) - cc.tangent_speed;
        sum.slip_speed = vt.abs();
        let loaded = cp.max_normal_impulse > 0.0;
        let mut stick = cp.stick;
        if loaded {
            if stick && patch_saturated && sum.slip_speed > ctx.stick_speed {
                stick = false;
            } else if !stick && sum.slip_speed < ctx.stick_speed {
                stick = true;
            }
        }
        ps.drift = if stick && cp.stick && loaded {
            disp + cp.base_drift - cc.tangent_speed * ctx.dt
        } else {
            0.0
        };
        ps.state = if stick {
            FrictionState::Stick
        } else {
            FrictionState::Slip
        };
    }
}

/// Adds a substep's impulses to the step totals.
pub(crate) fn end_substep_one(cc: &mut ContactConstraint) {
    for cp in &mut cc.points[..cc.count] {
        cp.total_normal_impulse += cp.normal_impulse;
        cp.total_tangent_impulse += cp.tangent_impulse;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rot;

    /// A new resting contact between solver states `a` and `b` (index 0: the ground) with
    /// inverse masses `inv_a`, `inv_b` (unit boxes of half 0.5 m, I = m (1² + 1²) / 12),
    /// one point at `point`, normal up (from A to B), μ 0.6.
    fn resting_contact(
        contact: u32,
        (a, inv_a, center_a): (u32, f32, Vec2),
        (b, inv_b, center_b): (u32, f32, Vec2),
        point: Vec2,
        states: &[BodyState],
    ) -> ContactConstraint {
        let ctx = StepContext::for_tests();
        let inv_i = |inv_m: f32| 6.0 * inv_m;
        let bodies = ConstraintBodies {
            index_a: a,
            index_b: b,
            inv_mass_a: inv_a,
            inv_i_a: inv_i(inv_a),
            inv_mass_b: inv_b,
            inv_i_b: inv_i(inv_b),
            center_a,
            center_b,
        };
        let input = ContactInput {
            normal: Vec2::new(0.0, 1.0),
            count: 1,
            mu_s: 0.6,
            mu_d: 0.6,
            points: [
                InputPoint {
                    point,
                    flags: INPUT_FRESH,
                    ..InputPoint::default()
                },
                InputPoint::default(),
            ],
            ..ContactInput::EMPTY
        };
        let soft = StepSoftness::new(&ctx);
        build_constraint(contact, &input, &bodies, Vec2::new(0.0, 1.0), &soft, &ctx, states)
    }

    /// The moment form of a row ([`RowFrame`], [`row_speed`], [`apply_row`]) is the arm
    /// form it replaced in the passes, up to rounding: the same moments as the crossed
    /// [`lever_arms`] (with the shift below and above its cap), the same displacement as
    /// [`anchor_displacement`], the same speed as [`point_velocity`] and the same velocity
    /// change as [`apply`] of `λ u`, for random anchors, directions and states. The
    /// tolerance, 1e-6 of the largest term (anchors and shifts ≤ 3 m, velocities ≤ 10 m/s,
    /// so moments and displacements ≤ 10 m, speeds ≤ 100 m/s), is a few f32 roundings
    /// (ε = 1.2e-7); a wrong sign, side or factor in any term is off by far more (the shift
    /// terms are up to 0.2 m, its cap here, and 0.06 m below it).
    #[test]
    fn moment_form_equals_arm_form() {
        // Uniform in [−scale, scale) from a linear congruential generator.
        let mut seed = 2026u32;
        let mut r = |scale: f32| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (2.0 * ((seed >> 8) as f32 / (1u32 << 24) as f32) - 1.0) * scale
        };
        let close =
            |x: f32, y: f32, scale: f32, what: &str| assert!((x - y).abs() <= 1e-6 * scale, "{what}: {x} vs {y}");
        let mut capped = 0;
        for case in 0..400 {
            // Some cases move B far enough that the shift is capped.
            let far = if case % 4 == 0 { 3.0 } else { 0.02 };
            let state = |r: &mut dyn FnMut(f32) -> f32, far: f32| BodyState {
                v: Vec2::new(r(10.0), r(10.0)),
                w: r(10.0),
                touched: 0.0,
                dp: Vec2::new(r(far), r(far)),
                dq: Rot::from_angle(r(0.3)),
            };
            let states = [BodyState::default(), state(&mut r, far), state(&mut r, far)];
            let mut cc = resting_contact(
                0,
                (1, 1.0, Vec2::ZERO),
                (2, 0.5, Vec2::new(0.0, 1.0)),
                Vec2::new(0.2, 0.5),
                &states,
            );
            cc.split = 0.2 + 0.6 * (r(1.0) * 0.5 + 0.5);
            let (a, b) = (states[1], states[2]);
            let angle = r(3.2);
            let u = Vec2::new(angle.cos(), angle.sin());
            let (r_a, r_b) = (Vec2::new(r(2.0), r(2.0)), Vec2::new(r(2.0), r(2.0)));
            capped += usize::from((b.dp - a.dp).length_squared() > cc.shift_cap2);
            let (m, disp) = RowFrame::new(&cc, &a, &b, u).point(&a, &b, r_a, r_b);
            let (arm_a, arm_b) = lever_arms(&cc, &a, &b, r_a, r_b);
            close(m.0, arm_a.cross(u), 10.0, "moment of A's arm");
            close(m.1, arm_b.cross(u), 10.0, "moment of B's arm");
            close(disp, anchor_displacement(&a, &b, r_a, r_b).dot(u), 10.0, "displacement");
            let speed = point_velocity(&cc, &a, &b, r_a, r_b).dot(u);
            close(row_speed(&a, &b, u, m), speed, 100.0, "speed");
            let lambda = r(1.0);
            let (mut a1, mut b1, mut a2, mut b2) = (a, b, a, b);
            apply_row(&cc, &mut a1, &mut b1, u, m, lambda);
            apply(&cc, &mut a2, &mut b2, r_a, r_b, lambda * u);
            for (x, y) in [(a1, a2), (b1, b2)] {
                close(x.v.x, y.v.x, 10.0, "v.x");
                close(x.v.y, y.v.y, 10.0, "v.y");
                close(x.w, y.w, 10.0, "w");
            }
        }
        assert!(capped > 20 && capped < 380, "both sides of the cap ({capped} capped)");
    }

    /// Groups of the estimate: constraints linked through moving bodies, however late the
    /// link comes in the subset; a kinematic body (no inverse mass) or the ground links
    /// nothing. c0: ground–1, c1: 1–2, c2: ground–3, c3: kinematic 4–5, c4: 4–6,
    /// c5: 6–2 (joins c4's body to c0's group). Groups are named by their first member.
    #[test]
    fn estimate_groups_follow_moving_bodies() {
        let states = [BodyState::default(); 7];
        let at = |y: f32| Vec2::new(0.0, y);
        let (dynamic, kinematic, ground) = (1.0, 0.0, 0.0);
        let subset = [
            resting_contact(0, (0, ground, at(0.0)), (1, dynamic, at(0.5)), at(0.0), &states),
            resting_contact(1, (1, dynamic, at(0.5)), (2, dynamic, at(1.5)), at(1.0), &states),
            resting_contact(2, (0, ground, at(0.0)), (3, dynamic, at(0.5)), at(0.0), &states),
            resting_contact(3, (4, kinematic, at(0.0)), (5, dynamic, at(0.5)), at(0.0), &states),
            resting_contact(4, (4, kinematic, at(0.0)), (6, dynamic, at(0.5)), at(0.0), &states),
            resting_contact(5, (6, dynamic, at(0.5)), (2, dynamic, at(1.5)), at(1.0), &states),
        ];
        assert_eq!(
            components(&subset, states.len()),
            vec![(0, 0), (0, 1), (0, 4), (0, 5), (2, 2), (3, 3)]
        );
    }

    /// The estimate, with each group swept until it settles by itself, still carries a
    /// stack's weight to the ground (the stack is one group; swept contact by contact, the
    /// ground would carry one box and the others none): under box k of an n-box stack of unit boxes (1 kg)
    /// the contact takes the impulse that stops the fall of the n − k boxes from k up in
    /// one substep, (n − k) · m · g · h (rigid rows: exact up to where the sweeps stop,
    /// see the tolerance below). A lone box beside it gets m · g · h, the same
    /// number as when it is estimated alone: a group's sweeps no longer depend on others.
    #[test]
    fn estimate_groups_carry_each_stack_by_itself() {
        let ctx = StepContext::for_tests();
        let (g, n) = (10.0f32, 8usize);
        let fall = BodyState {
            v: Vec2::new(0.0, -g * ctx.h),
            ..BodyState::default()
        };
        let mut states = vec![BodyState::default()];
        states.extend(std::iter::repeat_n(fall, n + 1));
        let cells: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        // States 1..=n: the stack at x = 0; state n + 1: the lone box at x = 5 m.
        let centre = |k: usize| Vec2::new(0.0, 0.5 + k as f32);
        let mut subset: Vec<ContactConstraint> = (0..n)
            .map(|k| {
                let below = if k == 0 {
                    (0, 0.0, Vec2::ZERO)
                } else {
                    (k as u32, 1.0, centre(k - 1))
                };
                resting_contact(
                    k as u32,
                    below,
                    (k as u32 + 1, 1.0, centre(k)),
                    Vec2::new(0.0, k as f32),
                    &states,
                )
            })
            .collect();
        let lone = resting_contact(
            n as u32,
            (0, 0.0, Vec2::ZERO),
            (n as u32 + 1, 1.0, Vec2::new(5.0, 0.5)),
            Vec2::new(5.0, 0.0),
            &states,
        );
        subset.push(lone);
        // No "up": no statics first guess (exact for a stack), so the sweeps alone must
        // carry the load down the stack, one contact further per sweep.
        let up = Vec2::ZERO;
        estimate(&mut subset, up, &ctx, &cells, MAX_ESTIMATE_SWEEPS);
        let weight = g * ctx.h; // m · g · h of one unit box [N·s]
                                // The sweeps stop when one changes no impulse by more than 1e-4 of the largest
                                // (the ground's, n weights); Gauss-Seidel on a chain of n contacts converges by a
                                // factor 1 − O(1/n²) per sweep, so what is left can be ~n² times that: 1 % of the
                                // ground's load. Swept contact by contact, the top contact would miss a whole
                                // weight (12 % of it).
        let tolerance = 1e-2 * n as f32 * weight;
        for cc in subset.iter().filter(|cc| (cc.contact as usize) < n) {
            let above = (n - cc.contact as usize) as f32;
            let p = cc.points[0].normal_impulse;
            assert!(
                (p - above * weight).abs() <= tolerance,
                "contact {}: {p} N·s, expected {} N·s",
                cc.contact,
                above * weight
            );
        }
        // Against fresh trial states: the estimate's sweeps stopped the fall in `cells`.
        let fresh: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        let mut alone = [lone];
        estimate(&mut alone, up, &ctx, &fresh, MAX_ESTIMATE_SWEEPS);
        let with_stack = subset
            .iter()
            .find(|cc| cc.contact == n as u32)
            .map(|cc| cc.points[0].preload);
        assert_eq!(with_stack, Some(alone[0].points[0].preload));
        assert!((alone[0].points[0].preload - weight).abs() <= 1e-3 * weight);
    }

    /// One contact between two light boxes (0.1 kg, half 0.35 m, I = m (w² + h²)/12) whose
    /// bodies have slid 1 m past each other along the contact within the step, approaching
    /// at 1 m/s, with a large warm-started impulse (so the clamp at zero never acts):
    /// repeated relax passes of the normal row must drive the approach speed to zero, each
    /// pass closer, and never raise the kinetic energy. With the lever arms following the
    /// whole 1 m, the row's true effective mass is 2.45 times the one it was built with,
    /// each pass overshoots by 1.45 times the speed it removes and the speed grows
    /// geometrically; [`capped_shift`] keeps the ratio near 1.
    #[test]
    fn relax_passes_converge_when_bodies_slid_far_within_the_step() {
        let ctx = StepContext::for_tests();
        let (m, half) = (0.1f32, 0.35f32);
        let inertia = m * (2.0 * half) * (2.0 * half) * 2.0 / 12.0;
        let bodies = ConstraintBodies {
            index_a: 1,
            index_b: 2,
            inv_mass_a: 1.0 / m,
            inv_i_a: 1.0 / inertia,
            inv_mass_b: 1.0 / m,
            inv_i_b: 1.0 / inertia,
            center_a: Vec2::new(0.0, 0.0),
            center_b: Vec2::new(0.0, 0.7),
        };
        let input = ContactInput {
            normal: Vec2::new(0.0, 1.0),
            count: 1,
            points: [
                InputPoint {
                    point: Vec2::new(0.3, 0.35),
                    separation: 0.0,
                    normal_impulse: 5.0,
                    ..InputPoint::default()
                },
                InputPoint::default(),
            ],
            ..ContactInput::EMPTY
        };
        let state = |v: Vec2, dp: Vec2| BodyState {
            v,
            w: 0.0,
            touched: 0.0,
            dp,
            dq: Rot::IDENTITY,
        };
        let states = [
            BodyState::default(),
            state(Vec2::new(0.0, 0.5), Vec2::ZERO),
            state(Vec2::new(0.0, -0.5), Vec2::new(1.0, 0.0)),
        ];
        let soft = StepSoftness::new(&ctx);
        let mut cc = build_constraint(0, &input, &bodies, Vec2::new(0.0, 1.0), &soft, &ctx, &states);
        let cells: Vec<core::cell::Cell<BodyState>> = states.iter().map(|&s| core::cell::Cell::new(s)).collect();
        let energy = |cells: &[core::cell::Cell<BodyState>]| -> f32 {
            cells[1..]
                .iter()
                .map(|c| {
                    let s = c.get();
                    0.5 * m * s.v.length_squared() + 0.5 * inertia * s.w * s.w
                })
                .sum()
        };
        let approach = |cc: &ContactConstraint, cells: &[core::cell::Cell<BodyState>]| -> f32 {
            let (a, b) = (cells[1].get(), cells[2].get());
            point_velocity(cc, &a, &b, cc.points[0].r_a, cc.points[0].r_b)
                .dot(cc.normal)
                .abs()
        };
        let (mut speed, mut e) = (approach(&cc, &cells), energy(&cells));
        assert!(speed > 0.9, "the bodies approach at {speed} m/s");
        let start = speed;
        for pass in 0..10 {
            solve_one(&mut cc, &cells, &ctx, false, ctx.h);
            let (s, en) = (approach(&cc, &cells), energy(&cells));
            assert!(s <= speed, "pass {pass}: approach speed {s} after {speed}");
            assert!(en <= e * (1.0 + 1e-6), "pass {pass}: kinetic energy rose {e} -> {en}");
            (speed, e) = (s, en);
        }
        assert!(speed < 1e-3 * start, "{speed} m/s left of {start}");
    }
}
