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
//! ## Load-adaptive stiffness
//! A soft contact settles at the deflection `F / (m ω²)` under a load F (see
//! [`super::softness`]); with m the *light* body's effective mass this is how a heavy box
//! sinks into a light one in soft-step engines. Each point's frequency is raised until the
//! deflection under its current (warm-start) load is at most `max_deflection`:
//! `ω = max(ω_base, √(λ / (h · m_n · δ_max)))`.

use super::{BodyState, ConstraintSet, Softness, StepContext};
use crate::collision::contact::{Contact, FrictionState};
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
#[derive(Clone, Copy, Debug)]
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
    /// Frequency multiplier for unequal masses: √(m_heavy / m_light), capped.
    pub stiffening: f32,
    pub count: usize,
    pub points: [ConstraintPoint; 2],
}

/// Everything the prepare stage needs about the two bodies of a contact.
#[derive(Clone, Copy, Debug)]
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

/// All contact constraints of a step, in solve order.
#[derive(Default)]
pub(crate) struct ContactSolver {
    pub constraints: Vec<ContactConstraint>,
}

impl ContactSolver {
    /// Builds the constraint of one touching contact (prepare stage, part 1).
    pub fn push(&mut self, contact_index: u32, c: &Contact, bodies: &ConstraintBodies) {
        let mut cc = ContactConstraint {
            index_a: bodies.index_a,
            index_b: bodies.index_b,
            contact: contact_index,
            normal: c.manifold.normal,
            inv_mass_a: bodies.inv_mass_a,
            inv_i_a: bodies.inv_i_a,
            inv_mass_b: bodies.inv_mass_b,
            inv_i_b: bodies.inv_i_b,
            mu_s: c.material.friction_static,
            mu_d: c.material.friction_dynamic,
            restitution: c.material.restitution,
            restitution_threshold: c.material.restitution_threshold,
            rolling_resistance: c.material.rolling_resistance * c.rolling_radius,
            rolling_mass: 0.0,
            rolling_impulse: c.rolling_impulse,
            tangent_speed: c.material.tangent_speed,
            stiffening: mass_ratio_stiffening(bodies.inv_mass_a, bodies.inv_mass_b),
            count: c.manifold.count,
            points: [ConstraintPoint::default(); 2],
        };
        let k_roll = bodies.inv_i_a + bodies.inv_i_b;
        cc.rolling_mass = if k_roll > 0.0 { 1.0 / k_roll } else { 0.0 };
        let n = cc.normal;
        let t = n.right_perp();
        let masses = cc_masses(bodies);
        for i in 0..cc.count {
            let mp = &c.manifold.points[i];
            let ps = &c.points[i];
            let r_a = mp.point - bodies.center_a;
            let r_b = mp.point - bodies.center_b;
            let cp = &mut cc.points[i];
            cp.r_a = r_a;
            cp.r_b = r_b;
            cp.base_separation = mp.separation;
            let drift = if ps.state == FrictionState::Stick && !ps.fresh {
                ps.drift
            } else {
                0.0
            };
            cp.base_drift = drift;
            cp.normal_mass = inv_or_zero(effective_mass_inv(&masses, r_a, r_b, n));
            cp.tangent_mass = inv_or_zero(effective_mass_inv(&masses, r_a, r_b, t));
            cp.normal_impulse = ps.normal_impulse;
            cp.tangent_impulse = ps.tangent_impulse;
            cp.stick = ps.state == FrictionState::Stick;
            cp.fresh = ps.fresh;
            cp.preload = ps.preload;
            cp.approach = 0.0;
        }
        self.constraints.push(cc);
    }

    /// Resolves per-point softness and the state of new points (prepare stage, part 2),
    /// once body velocities are known.
    fn prepare_points(&mut self, ctx: &StepContext, states: &[BodyState]) {
        let base_omega = 2.0 * core::f32::consts::PI * ctx.contact_hertz;
        for cc in self.constraints.iter_mut() {
            let (sa, sb) = (states[cc.index_a as usize], states[cc.index_b as usize]);
            let has_static = cc.index_a == 0 || cc.index_b == 0;
            let omega0 = if has_static { 2.0 * base_omega } else { base_omega };
            let n = cc.normal;
            let t = n.right_perp();
            // Preload: the mean of the manifold's normal impulses (common mode only, so
            // the rocking mode stays a plain damped spring).
            let mean = cc.points[..cc.count].iter().map(|p| p.normal_impulse).sum::<f32>() / cc.count.max(1) as f32;
            for cp in cc.points[..cc.count].iter_mut() {
                if !(ctx.preload && ctx.warm_starting) {
                    cp.preload = 0.0;
                }
                if !ctx.warm_starting {
                    cc.rolling_impulse = 0.0;
                    cp.normal_impulse = 0.0;
                    cp.tangent_impulse = 0.0;
                }
                cp.soft = if omega0 > 0.0 {
                    Softness::from_omega(omega0 * cc.stiffening, ctx.contact_damping_ratio, ctx.h)
                } else {
                    Softness::RIGID
                };
                if cp.fresh {
                    let dv = relative_velocity(&sa, &sb, cp.r_a, cp.r_b);
                    let slip = (dv.dot(t) - cc.tangent_speed).abs();
                    let in_contact = cp.base_separation <= crate::geometry::LINEAR_SLOP;
                    cp.stick = !(in_contact && slip > ctx.stick_speed);
                }
            }
        }
    }
}

fn preload_rate() -> f32 {
    std::env::var("PRATE").ok().and_then(|s| s.parse().ok()).unwrap_or(0.1)
}

fn alpha_up() -> f32 {
    std::env::var("PUP").ok().and_then(|s| s.parse().ok()).unwrap_or(0.05)
}

fn no_drift() -> bool {
    std::env::var("NODRIFT").is_ok()
}

fn bias_cap() -> f32 {
    std::env::var("BIASCAP").ok().and_then(|s| s.parse().ok()).unwrap_or(0.25)
}

/// √(m_heavy / m_light) for two dynamic bodies (1 when one side is static or kinematic),
/// capped at `STIFFENING_CAP`. The soft contact's stiffness is `m_n ω²` with `m_n` close to
/// the light body's mass; scaling ω by this factor makes it close to the heavy body's.
fn mass_ratio_stiffening(inv_mass_a: f32, inv_mass_b: f32) -> f32 {
    if inv_mass_a <= 0.0 || inv_mass_b <= 0.0 {
        return 1.0;
    }
    let ratio = inv_mass_a.max(inv_mass_b) / inv_mass_a.min(inv_mass_b);
    ratio.sqrt().min(stiff_cap())
}

fn stiff_cap() -> f32 {
    std::env::var("STIFFCAP").ok().and_then(|s| s.parse().ok()).unwrap_or(10.0)
}

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

/// Velocity of B's point minus A's point.
#[inline]
fn relative_velocity(a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> Vec2 {
    (b.v + Vec2::cross_sv(b.w, r_b)) - (a.v + Vec2::cross_sv(a.w, r_a))
}

/// Applies the impulse `p` at the anchors: −p to A, +p to B.
#[inline]
fn apply(cc: &ContactConstraint, a: &mut BodyState, b: &mut BodyState, r_a: Vec2, r_b: Vec2, p: Vec2) {
    a.v -= cc.inv_mass_a * p;
    a.w -= cc.inv_i_a * r_a.cross(p);
    b.v += cc.inv_mass_b * p;
    b.w += cc.inv_i_b * r_b.cross(p);
}

/// Relative displacement of the contact point's two material points since the step start,
/// to first order in the rotation: `Δp_b − Δp_a + sin(Δθ_b) ẑ×r_b − sin(Δθ_a) ẑ×r_a`.
/// Box2D v3 rotates the anchors fully; the second-order term `(cos Δθ − 1) r` then lifts a
/// spinning disk off the ground (its material point rises although its surface does not),
/// which weakens the contact of a rolling or skidding disk (the "slipping-to-rolling comes
/// late" error of Box2D and Rapier). The first-order form matches the velocity Jacobian.
#[inline]
fn anchor_displacement(a: &BodyState, b: &BodyState, r_a: Vec2, r_b: Vec2) -> Vec2 {
    (b.dp - a.dp) + (b.dq.s * r_b.left_perp() - a.dq.s * r_a.left_perp())
}

/// Reads two body states; index 0 is the shared static body, never written.
#[inline]
fn load(states: &[BodyState], ia: u32, ib: u32) -> (BodyState, BodyState) {
    (states[ia as usize], states[ib as usize])
}

#[inline]
fn store(states: &mut [BodyState], ia: u32, ib: u32, a: BodyState, b: BodyState) {
    if ia != 0 {
        states[ia as usize] = a;
    }
    if ib != 0 {
        states[ib as usize] = b;
    }
}

impl ConstraintSet for ContactSolver {
    fn prepare(&mut self, ctx: &StepContext, states: &[BodyState]) {
        // Geometry and masses were filled by `push`; softness and new points' states
        // need the body velocities.
        self.prepare_points(ctx, states);
    }

    fn warm_start(&mut self, states: &mut [BodyState]) {
        for cc in &mut self.constraints {
            let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
            let n = cc.normal;
            let t = n.right_perp();
            if cc.restitution > 0.0 {
                // Impact speed for restitution: the approach velocity before this
                // substep's impulses, whichever pass then catches the impact.
                for cp in &mut cc.points[..cc.count] {
                    cp.substep_vn = relative_velocity(&a, &b, cp.r_a, cp.r_b).dot(n);
                }
            }
            for cp in &cc.points[..cc.count] {
                let p = cp.normal_impulse * n + cp.tangent_impulse * t;
                apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, p);
            }
            a.w -= cc.inv_i_a * cc.rolling_impulse;
            b.w += cc.inv_i_b * cc.rolling_impulse;
            store(states, cc.index_a, cc.index_b, a, b);
        }
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool, elapsed: f32) {
        for cc in &mut self.constraints {
            let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
            let n = cc.normal;
            let t = n.right_perp();
            let mut total_normal = 0.0;
            // Normal rows.
            for i in 0..cc.count {
                let cp = cc.points[i];
                let d = anchor_displacement(&a, &b, cp.r_a, cp.r_b);
                let s = d.dot(n) + cp.base_separation;
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
                let vn = relative_velocity(&a, &b, cp.r_a, cp.r_b).dot(n);
                let impulse =
                    -cp.normal_mass * mass_scale * (vn + bias) - impulse_scale * (cp.normal_impulse - cp.preload);
                let new = (cp.normal_impulse + impulse).max(0.0);
                let delta = new - cp.normal_impulse;
                apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, delta * n);
                let cp = &mut cc.points[i];
                cp.normal_impulse = new;
                cp.max_normal_impulse = cp.max_normal_impulse.max(new);
                if new > 0.0 && cp.substep_vn < cp.approach {
                    cp.approach = cp.substep_vn;
                }
                total_normal += new;
            }
            // Friction rows, after the normal rows so the clamp uses this pass's λn.
            for i in 0..cc.count {
                let cp = cc.points[i];
                let mu = if cp.stick { cc.mu_s } else { cc.mu_d };
                let limit = mu * cp.normal_impulse;
                let vt = relative_velocity(&a, &b, cp.r_a, cp.r_b).dot(t) - cc.tangent_speed;
                let bias = if use_bias && cp.stick && cp.normal_impulse > 0.0 && !no_drift() {
                    let d = anchor_displacement(&a, &b, cp.r_a, cp.r_b);
                    let drift = d.dot(t) + cp.base_drift - cc.tangent_speed * elapsed;
                    (cp.soft.bias_rate * drift).clamp(-ctx.push_speed, ctx.push_speed)
                } else {
                    0.0
                };
                let impulse = -cp.tangent_mass * (vt + bias);
                let unclamped = cp.tangent_impulse + impulse;
                let new = unclamped.clamp(-limit, limit);
                let delta = new - cp.tangent_impulse;
                apply(cc, &mut a, &mut b, cp.r_a, cp.r_b, delta * t);
                let cp = &mut cc.points[i];
                cp.tangent_impulse = new;
                if !use_bias {
                    cp.saturated = limit > 0.0 && unclamped.abs() > limit;
                }
            }
            // Rolling resistance: an angular row clamped by the manifold's normal impulse.
            if cc.rolling_resistance > 0.0 && !use_bias {
                let limit = cc.rolling_resistance * total_normal;
                let impulse = -cc.rolling_mass * (b.w - a.w);
                let new = (cc.rolling_impulse + impulse).clamp(-limit, limit);
                let delta = new - cc.rolling_impulse;
                cc.rolling_impulse = new;
                a.w -= cc.inv_i_a * delta;
                b.w += cc.inv_i_b * delta;
            }
            store(states, cc.index_a, cc.index_b, a, b);
        }
    }

    fn end_substep(&mut self) {
        for cc in &mut self.constraints {
            for cp in &mut cc.points[..cc.count] {
                cp.total_normal_impulse += cp.normal_impulse;
                cp.total_tangent_impulse += cp.tangent_impulse;
            }
        }
    }

    fn restitution(&mut self, states: &mut [BodyState]) {
        for cc in &mut self.constraints {
            if cc.restitution == 0.0 {
                continue;
            }
            let (mut a, mut b) = load(states, cc.index_a, cc.index_b);
            let n = cc.normal;
            for i in 0..cc.count {
                let cp = cc.points[i];
                if cp.approach > -cc.restitution_threshold || cp.max_normal_impulse == 0.0 {
                    continue;
                }
                let vn = relative_velocity(&a, &b, cp.r_a, cp.r_b).dot(n);
                let impulse = -cp.normal_mass * (vn + cc.restitution * cp.approach);
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
    }
}

/// Writes impulses back into the contact and runs the stick/slip transitions
/// (store stage). `states` are the end-of-step states.
pub(crate) fn store_impulses(cc: &ContactConstraint, contact: &mut Contact, states: &[BodyState], ctx: &StepContext) {
    let (a, b) = load(states, cc.index_a, cc.index_b);
    let t = cc.normal.right_perp();
    contact.rolling_impulse = cc.rolling_impulse;
    let mean = cc.points[..cc.count].iter().map(|p| p.normal_impulse).sum::<f32>() / cc.count.max(1) as f32;
    let alpha = preload_rate();
    for (cp, ps) in cc.points[..cc.count].iter().zip(contact.points.iter_mut()) {
        ps.normal_impulse = cp.normal_impulse;
        ps.tangent_impulse = cp.tangent_impulse;
        ps.total_normal_impulse = cp.total_normal_impulse;
        ps.total_tangent_impulse = cp.total_tangent_impulse;
        ps.max_normal_impulse = cp.max_normal_impulse;
        ps.approach_velocity = cp.approach;
        let rate = if mean > cp.preload { alpha_up() } else { alpha };
        ps.preload = if cp.max_normal_impulse > 0.0 { cp.preload + rate * (mean - cp.preload) } else { 0.0 };
        ps.fresh = false;
        let vt = relative_velocity(&a, &b, cp.r_a, cp.r_b).dot(t) - cc.tangent_speed;
        ps.slip_speed = vt.abs();
        let loaded = cp.max_normal_impulse > 0.0;
        let mut stick = cp.stick;
        if loaded {
            if stick && cp.saturated && ps.slip_speed > ctx.stick_speed {
                stick = false;
            } else if !stick && ps.slip_speed < ctx.stick_speed {
                stick = true;
            }
        }
        ps.drift = if stick && cp.stick && loaded {
            let d = anchor_displacement(&a, &b, cp.r_a, cp.r_b);
            d.dot(t) + cp.base_drift - cc.tangent_speed * ctx.dt
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
