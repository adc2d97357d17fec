//! The revolute joint's constraint rows in the soft step (one joint at a time, scalar).
//!
//! Legend: `v`, `w` linear [m/s] and angular [rad/s] velocity of a body's centre of mass;
//! `r_a`, `r_b` the arms from the centres of mass to the pivot [m], turned by the body's
//! rotation since the step start (`dq`); `m` inverse masses [1/kg], `i` inverse rotational
//! inertias [1/(kg·m²)]; `λ` accumulated impulses.
//!
//! Rows, in the order each pass solves them (the point last: it matters most):
//! * **spring** (biased pass only, soft with the spring's frequency): angular impulse
//!   Δλ = −s_m·k·(ω_B − ω_A + β θ) − s_i·λ, with k = 1/(i_A + i_B) and (β, s_m, s_i) the
//!   soft coefficients of `solver::softness` — an implicit damped spring of that frequency
//!   about θ = 0; it is soft by nature, so the rigid relax pass leaves it out;
//! * **motor** (both passes): Δλ = −k (ω_B − ω_A − ω_target), λ clamped to
//!   ±max_torque·h;
//! * **limits** (both passes): a one-sided row per limit on C = θ − lower (≥ 0) and
//!   C = upper − θ (≥ 0), λ ≥ 0; a limit not yet reached is speculative (bias C/h: the
//!   joint may close exactly the gap), one passed is pulled back softly in the biased pass
//!   and held rigidly in the relax pass, as contacts are;
//! * **point** (both passes): the 2-vector C = (c_B + Δp_B + r_B) − (c_A + Δp_A + r_A);
//!   Ċ = v_B + ω_B × r_B − v_A − ω_A × r_A; P = −s_m K⁻¹(Ċ + β C) − s_i λ with
//!   K = (m_A + m_B) I − i_A [r_A]ₓ² − i_B [r_B]ₓ² (the 2×2 effective-mass matrix of the
//!   point: K11 = m_A + m_B + i_A r_Ay² + i_B r_By², K12 = −i_A r_Ax r_Ay − i_B r_Bx r_By,
//!   K22 = m_A + m_B + i_A r_Ax² + i_B r_Bx²); rigid (s_m 1, s_i 0, no bias) in the relax
//!   pass.
//!
//! This is the structure of Box2D v3's revolute joint (`revolute_joint.c`: spring, motor,
//! limits, point; soft position correction at the joint's own frequency, 60 Hz and ζ 2 by
//! default, clamped to a quarter of the substep rate), written anew from the equations
//! above. Joints are solved one at a time before the contacts of each pass (Box2D solves
//! its overflow constraints first too): they are few next to contacts in most scenes, and
//! the order keeps results independent of the thread count.

use super::{Softness, StateCell, StepContext};
use crate::dynamics::joint::{JointImpulses, JointRecord};
use crate::math::{Rot, Vec2};

/// One revolute joint prepared for a step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct JointConstraint {
    /// Joint slot index.
    pub joint: u32,
    /// Solver state indices (0: the static body).
    pub index_a: u32,
    pub index_b: u32,
    /// Whether the body is dynamic and awake (its state is written).
    pub write_a: bool,
    pub write_b: bool,
    pub inv_mass_a: f32,
    pub inv_i_a: f32,
    pub inv_mass_b: f32,
    pub inv_i_b: f32,
    /// Arms from the centres of mass to the pivot at the step start, world-oriented [m].
    pub frame_a: Vec2,
    pub frame_b: Vec2,
    /// c_B − c_A at the step start [m].
    pub delta_center: Vec2,
    /// Joint angle at the step start [rad].
    pub angle0: f32,
    /// 1 / (i_A + i_B) [kg·m²] (0 when neither body turns).
    pub axial_mass: f32,
    /// Soft position correction of the point and the limits.
    pub softness: Softness,
    pub spring: Softness,
    pub enable_spring: bool,
    pub enable_motor: bool,
    pub enable_limit: bool,
    pub lower: f32,
    pub upper: f32,
    pub motor_speed: f32,
    /// Largest motor impulse per substep [N·m·s] (max torque × h).
    pub max_motor_impulse: f32,
    pub impulses: JointImpulses,
}

/// What a joint's build needs of one body (static and sleeping bodies: index 0, no mass).
#[derive(Clone, Copy, Debug)]
pub(crate) struct JointBody {
    pub index: u32,
    pub dynamic: bool,
    pub inv_mass: f32,
    pub inv_i: f32,
    /// World centre of mass [m] and rotation at the step start.
    pub center: Vec2,
    pub q: Rot,
    /// Centre of mass in the body frame [m].
    pub local_center: Vec2,
}

/// Wraps an angle into [−π, π] [rad].
pub(crate) fn unwind_angle(a: f32) -> f32 {
    use core::f32::consts::PI;
    if a < -PI {
        a + 2.0 * PI * ((PI - a) / (2.0 * PI)).floor()
    } else if a > PI {
        a - 2.0 * PI * ((a + PI) / (2.0 * PI)).floor()
    } else {
        a
    }
}

/// The joint angle [rad] of bodies turned by `q_a`, `q_b`: B's rotation relative to A
/// minus the reference angle, in [−π, π].
pub(crate) fn joint_angle(q_a: Rot, q_b: Rot, reference: f32) -> f32 {
    unwind_angle(q_a.inv_mul(q_b).angle() - reference)
}

impl JointConstraint {
    /// Prepares a joint for the step.
    pub fn new(slot: u32, j: &JointRecord, a: &JointBody, b: &JointBody, ctx: &StepContext) -> JointConstraint {
        let d = &j.def;
        let hertz = d.constraint_hertz.min(0.25 * ctx.inv_h);
        let k = a.inv_i + b.inv_i;
        let warm = ctx.warm_starting;
        JointConstraint {
            joint: slot,
            index_a: a.index,
            index_b: b.index,
            write_a: a.dynamic && a.index != 0,
            write_b: b.dynamic && b.index != 0,
            inv_mass_a: a.inv_mass,
            inv_i_a: a.inv_i,
            inv_mass_b: b.inv_mass,
            inv_i_b: b.inv_i,
            frame_a: a.q.rotate(d.local_anchor_a - a.local_center),
            frame_b: b.q.rotate(d.local_anchor_b - b.local_center),
            delta_center: b.center - a.center,
            // Only the limit and the spring read the angle (an atan2 per joint and step).
            angle0: if d.enable_limit || d.enable_spring {
                joint_angle(a.q, b.q, d.reference_angle)
            } else {
                0.0
            },
            axial_mass: if k > 0.0 { 1.0 / k } else { 0.0 },
            softness: Softness::new(hertz, d.constraint_damping_ratio, ctx.h),
            spring: Softness::new(d.spring_hertz, d.spring_damping_ratio, ctx.h),
            enable_spring: d.enable_spring,
            enable_motor: d.enable_motor,
            enable_limit: d.enable_limit,
            lower: d.lower_angle,
            upper: d.upper_angle,
            motor_speed: d.motor_speed,
            max_motor_impulse: d.max_motor_torque * ctx.h,
            impulses: if warm { j.impulses } else { JointImpulses::default() },
        }
    }

    /// Loads both bodies' velocities and current arms.
    #[inline]
    fn load<S: StateCell>(&self, states: &[S]) -> (Body, Body) {
        let (sa, sb) = (states[self.index_a as usize].get(), states[self.index_b as usize].get());
        (
            Body {
                v: sa.v,
                w: sa.w,
                dp: sa.dp,
                dq: sa.dq,
                r: sa.dq.rotate(self.frame_a),
            },
            Body {
                v: sb.v,
                w: sb.w,
                dp: sb.dp,
                dq: sb.dq,
                r: sb.dq.rotate(self.frame_b),
            },
        )
    }

    /// Writes the velocities of the bodies this joint moves (and marks them pushed, so
    /// their position update is not the ballistic one).
    #[inline]
    fn save<S: StateCell>(&self, states: &[S], a: &Body, b: &Body) {
        if self.write_a {
            states[self.index_a as usize].set_velocity(a.v, a.w, 1.0);
        }
        if self.write_b {
            states[self.index_b as usize].set_velocity(b.v, b.w, 1.0);
        }
    }

    /// Applies a point impulse `p` [N·s] (on B, −p on A) and an angular impulse `l`
    /// [N·m·s] (on B, −l on A).
    #[inline]
    fn apply(&self, a: &mut Body, b: &mut Body, p: Vec2, l: f32) {
        a.v -= self.inv_mass_a * p;
        a.w -= self.inv_i_a * (a.r.cross(p) + l);
        b.v += self.inv_mass_b * p;
        b.w += self.inv_i_b * (b.r.cross(p) + l);
    }

    /// Re-applies the accumulated impulses at the start of a substep.
    pub fn warm_start<S: StateCell>(&self, states: &[S]) {
        let (mut a, mut b) = self.load(states);
        let j = &self.impulses;
        let axial = j.spring + j.motor + j.lower - j.upper;
        self.apply(&mut a, &mut b, j.linear, axial);
        self.save(states, &a, &b);
    }

    /// The joint angle now [rad] (step-start angle plus the relative turn since).
    #[inline]
    fn angle(&self, a: &Body, b: &Body) -> f32 {
        self.angle0 + a.dq.inv_mul(b.dq).angle()
    }

    /// One pass over the joint's rows (see the module docs); `use_bias`: the biased pass.
    pub fn solve<S: StateCell>(&mut self, states: &[S], ctx: &StepContext, use_bias: bool) {
        let (mut a, mut b) = self.load(states);
        let k = self.axial_mass;
        if self.enable_spring && use_bias && k > 0.0 {
            let c = self.angle(&a, &b);
            let s = self.spring;
            let imp = -s.mass_scale * k * (b.w - a.w + s.bias_rate * c) - s.impulse_scale * self.impulses.spring;
            self.impulses.spring += imp;
            self.apply(&mut a, &mut b, Vec2::ZERO, imp);
        }
        if self.enable_motor && k > 0.0 {
            let imp = -k * (b.w - a.w - self.motor_speed);
            let old = self.impulses.motor;
            self.impulses.motor = (old + imp).clamp(-self.max_motor_impulse, self.max_motor_impulse);
            self.apply(&mut a, &mut b, Vec2::ZERO, self.impulses.motor - old);
        }
        if self.enable_limit && k > 0.0 {
            let angle = self.angle(&a, &b);
            // Lower: C = θ − lower ≥ 0, pushing ω_B − ω_A up.
            let (bias, ms, is) = self.limit_row(angle - self.lower, ctx, use_bias);
            let old = self.impulses.lower;
            let imp = -k * ms * (b.w - a.w + bias) - is * old;
            self.impulses.lower = (old + imp).max(0.0);
            self.apply(&mut a, &mut b, Vec2::ZERO, self.impulses.lower - old);
            // Upper: C = upper − θ ≥ 0, pushing ω_A − ω_B up.
            let (bias, ms, is) = self.limit_row(self.upper - angle, ctx, use_bias);
            let old = self.impulses.upper;
            let imp = -k * ms * (a.w - b.w + bias) - is * old;
            self.impulses.upper = (old + imp).max(0.0);
            self.apply(&mut a, &mut b, Vec2::ZERO, -(self.impulses.upper - old));
        }
        // The point.
        let c = self.delta_center + (b.dp - a.dp) + (b.r - a.r);
        let cdot = (b.v + Vec2::cross_sv(b.w, b.r)) - (a.v + Vec2::cross_sv(a.w, a.r));
        let (bias, ms, is) = if use_bias {
            (
                c * self.softness.bias_rate,
                self.softness.mass_scale,
                self.softness.impulse_scale,
            )
        } else {
            (Vec2::ZERO, 1.0, 0.0)
        };
        let (ma, mb, ia, ib) = (self.inv_mass_a, self.inv_mass_b, self.inv_i_a, self.inv_i_b);
        let (ra, rb) = (a.r, b.r);
        let k11 = ma + mb + ia * ra.y * ra.y + ib * rb.y * rb.y;
        let k12 = -ia * ra.x * ra.y - ib * rb.x * rb.y;
        let k22 = ma + mb + ia * ra.x * ra.x + ib * rb.x * rb.x;
        let rhs = cdot + bias;
        let det = k11 * k22 - k12 * k12;
        let inv_det = if det != 0.0 { 1.0 / det } else { 0.0 };
        // K⁻¹ rhs by Cramer's rule.
        let x = Vec2::new(
            inv_det * (k22 * rhs.x - k12 * rhs.y),
            inv_det * (k11 * rhs.y - k12 * rhs.x),
        );
        let p = x * -ms - self.impulses.linear * is;
        self.impulses.linear += p;
        self.apply(&mut a, &mut b, p, 0.0);
        self.save(states, &a, &b);
    }

    /// Bias, mass scale and impulse scale of a one-sided limit row with distance `c` [rad]
    /// to the limit (negative: past it).
    #[inline]
    fn limit_row(&self, c: f32, ctx: &StepContext, use_bias: bool) -> (f32, f32, f32) {
        if c > 0.0 {
            (c * ctx.inv_h, 1.0, 0.0)
        } else if use_bias {
            (
                self.softness.bias_rate * c,
                self.softness.mass_scale,
                self.softness.impulse_scale,
            )
        } else {
            (0.0, 1.0, 0.0)
        }
    }
}

/// A body as a joint pass sees it.
#[derive(Clone, Copy, Debug)]
struct Body {
    v: Vec2,
    w: f32,
    dp: Vec2,
    dq: Rot,
    /// The arm to the pivot, turned by `dq` [m].
    r: Vec2,
}

/// The joints of one step, prepared.
#[derive(Default)]
pub(crate) struct JointSolver {
    pub constraints: Vec<JointConstraint>,
}

impl JointSolver {
    pub fn warm_start<S: StateCell>(&mut self, states: &[S]) {
        for j in &self.constraints {
            j.warm_start(states);
        }
    }

    pub fn solve<S: StateCell>(&mut self, states: &[S], ctx: &StepContext, use_bias: bool) {
        for j in &mut self.constraints {
            j.solve(states, ctx, use_bias);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwind_keeps_angles_in_range_and_equivalent() {
        use core::f32::consts::PI;
        for a in [-10.0f32, -4.0, -PI, -1.0, 0.0, 2.0, PI, 3.5, 7.0, 20.0] {
            let u = unwind_angle(a);
            assert!((-PI - 1e-5..=PI + 1e-5).contains(&u), "{a} -> {u}");
            // Same direction: sin and cos agree.
            assert!(
                (u.sin() - a.sin()).abs() < 1e-4 && (u.cos() - a.cos()).abs() < 1e-4,
                "{a} -> {u}"
            );
        }
    }
}
