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
//! above. Joints are solved before the contacts of each pass (Box2D solves its overflow
//! constraints first too), in blocks of consecutive joints coloured so that the blocks of
//! one colour write no body in common: colour after colour, each colour's blocks shared
//! between threads, in an order that does not depend on the thread count. Inside a block
//! the passes take them in a colour order made inside small windows of the slot order
//! ([`JointSolver::order_joints`]), so consecutive joints seldom wait for each other's
//! velocities.

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
    /// Prepares a joint for the step. (Inlined into its one caller, the build, which
    /// then writes the constraint in place: called, it returned the 150-byte record
    /// through a copy.)
    #[inline(always)]
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
            // Only the limit and the spring read the angle (an atan2 per joint and step,
            // the fast one as in the passes: `atan2f` here was 2 % of rain's step; the
            // API's `World::revolute_angle` keeps the exact one).
            angle0: if d.enable_limit || d.enable_spring {
                unwind_angle(a.q.inv_mul(b.q).angle_fast() - d.reference_angle)
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

    /// Applies an angular impulse `l` [N·m·s] (on B, −l on A): [`JointConstraint::apply`]
    /// without the point's terms.
    #[inline]
    fn apply_angular(&self, a: &mut Body, b: &mut Body, l: f32) {
        a.w -= self.inv_i_a * l;
        b.w += self.inv_i_b * l;
    }

    /// Re-applies the accumulated impulses at the start of a substep.
    #[inline(always)]
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
        self.angle0 + a.dq.inv_mul(b.dq).angle_fast()
    }

    /// One pass over the joint's rows (see the module docs); `use_bias`: the biased pass.
    #[inline(always)]
    pub fn solve<S: StateCell>(&mut self, states: &[S], ctx: &StepContext, use_bias: bool) {
        let (mut a, mut b) = self.load(states);
        let k = self.axial_mass;
        // The angle reads only the rotations, which the rows do not change: one atan2 for
        // the spring and the limits.
        let spring = self.enable_spring && use_bias && k > 0.0;
        let limit = self.enable_limit && k > 0.0;
        let angle = if spring || limit { self.angle(&a, &b) } else { 0.0 };
        if spring {
            let c = angle;
            let s = self.spring;
            let imp = -s.mass_scale * k * (b.w - a.w + s.bias_rate * c) - s.impulse_scale * self.impulses.spring;
            self.impulses.spring += imp;
            self.apply_angular(&mut a, &mut b, imp);
        }
        if self.enable_motor && k > 0.0 {
            let imp = -k * (b.w - a.w - self.motor_speed);
            let old = self.impulses.motor;
            self.impulses.motor = (old + imp).clamp(-self.max_motor_impulse, self.max_motor_impulse);
            self.apply_angular(&mut a, &mut b, self.impulses.motor - old);
        }
        if limit {
            // Lower: C = θ − lower ≥ 0, pushing ω_B − ω_A up.
            let (bias, ms, is) = self.limit_row(angle - self.lower, ctx, use_bias);
            let old = self.impulses.lower;
            let imp = -k * ms * (b.w - a.w + bias) - is * old;
            self.impulses.lower = (old + imp).max(0.0);
            self.apply_angular(&mut a, &mut b, self.impulses.lower - old);
            // Upper: C = upper − θ ≥ 0, pushing ω_A − ω_B up.
            let (bias, ms, is) = self.limit_row(self.upper - angle, ctx, use_bias);
            let old = self.impulses.upper;
            let imp = -k * ms * (a.w - b.w + bias) - is * old;
            self.impulses.upper = (old + imp).max(0.0);
            self.apply_angular(&mut a, &mut b, -(self.impulses.upper - old));
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

/// Joints per window of the solve order ([`JointSolver::order`]): the colouring reorders
/// joints only inside a window, so the constraints, built in slot order, are read within a
/// few kilobytes of each other (a whole-step colour order read them in strides, and
/// building them in that order cost joint_grid's set-up more than its solve gained).
/// joint_grid's biased solve pass: 1.50 ms in slot order; 1.30, 1.24, 1.27 and 1.29 ms
/// with windows of 8, 16, 32 and 64 joints (two alternated runs each).
const ORDER_WINDOW: usize = 16;
const _: () = assert!(ORDER_WINDOW <= 32); // colours are bits of a u32

/// Joints per block of the threaded passes (a multiple of [`ORDER_WINDOW`], so a block
/// holds whole windows of the solve order): consecutive joints in slot order, coloured so
/// that the blocks of one colour write no body in common ([`JointSolver::colour_blocks`]).
const JOINT_BLOCK: usize = 256;
const _: () = assert!(JOINT_BLOCK.is_multiple_of(ORDER_WINDOW));

/// Fewest joint blocks per thread and colour, on average, for which the step shares its
/// substeps between threads ([`JointSolver::worth_sharing`]).
const MIN_BLOCKS_PER_THREAD: usize = 2;

/// Block colours: 0 … `BLOCK_COLOURS − 2` are shared between threads; a block that finds
/// them all taken by blocks writing its bodies gets the last, whose blocks run one after
/// the other on one thread.
const BLOCK_COLOURS: usize = 32;
const SERIAL_BLOCKS: usize = BLOCK_COLOURS - 1;

/// What a pass over the joints does ([`JointSolver::pass`]).
#[derive(Clone, Copy)]
enum JointPass {
    /// Re-applies the accumulated impulses.
    WarmStart,
    /// Solves the rows; `use_bias`: the biased pass.
    Solve { use_bias: bool },
}

/// The joints of one step, prepared.
#[derive(Default)]
pub(crate) struct JointSolver {
    /// In slot order.
    pub constraints: Vec<JointConstraint>,
    /// The order the passes take the constraints in (indices into `constraints`): window
    /// by window of [`ORDER_WINDOW`] joints, and in each window colour by colour (see
    /// [`JointSolver::order_joints`]).
    order: Vec<u32>,
    /// The solver states each constraint writes (0: none), as `order` was made for.
    order_bodies: Vec<[u32; 2]>,
    /// The same for this step's constraints (filled by [`JointSolver::push`]).
    writes: Vec<[u32; 2]>,
    /// Scratch of the colouring: per solver state, the colours its joints took in the
    /// current window, or its blocks (all zero between colourings).
    used: Vec<u32>,
    /// The blocks of [`JOINT_BLOCK`] constraints colour by colour (in block order within
    /// a colour), and where each colour's blocks end in it.
    block_order: Vec<u32>,
    colour_ends: Vec<usize>,
    /// The index in `colour_ends` of the colour whose blocks run on one thread (see
    /// [`SERIAL_BLOCKS`]); `usize::MAX` when no block has it.
    serial_from: usize,
    /// Passes whose colours were shared between threads (a count for tests).
    pub shared_passes: u64,
}

impl JointSolver {
    /// Starts a step's build: no constraints yet.
    pub fn clear(&mut self) {
        self.constraints.clear();
        self.writes.clear();
    }

    /// Adds a constraint (in slot order) and notes the states it writes (read by
    /// [`JointSolver::order_joints`] while the record is at hand, not in a second pass
    /// over the constraints: joint_grid's 19 800 take 3 MB).
    pub fn push(&mut self, c: JointConstraint) {
        self.writes.push([
            if c.write_a { c.index_a } else { 0 },
            if c.write_b { c.index_b } else { 0 },
        ]);
        self.constraints.push(c);
    }

    /// Makes the solve order unless the constraints write the same states as when it was
    /// last made (a resting or hanging set of joints keeps it from step to step). Within
    /// each window of [`ORDER_WINDOW`] joints, greedily in slot order, a joint takes the
    /// lowest colour in which no joint of the window writes one of its bodies, and the
    /// window's joints then go colour by colour (in slot order within a colour).
    /// Consecutive joints then seldom write the same body, so one joint's rows need not
    /// wait for the previous joint's velocities and the core overlaps them: in slot
    /// order, each chain's or ragdoll's joints formed one chain of dependent solves. Box2D
    /// v3 colours its joints over the whole step, as its contacts. A function of the joints
    /// and their bodies only (the same for any thread count). `states`: the number of
    /// solver states.
    pub fn order_joints(&mut self, states: usize) {
        if self.order.len() == self.constraints.len() && self.writes == self.order_bodies {
            return;
        }
        core::mem::swap(&mut self.order_bodies, &mut self.writes);
        self.order.clear();
        // All zero already (each window clears what it set): only grown.
        if self.used.len() < states {
            self.used.resize(states, 0);
        }
        let used = &mut self.used;
        for (w, window) in self.order_bodies.chunks(ORDER_WINDOW).enumerate() {
            let first = w * ORDER_WINDOW;
            let mut colours = [0u8; ORDER_WINDOW];
            let mut counts = [0u8; ORDER_WINDOW + 1];
            for (k, bodies) in window.iter().enumerate() {
                // State 0 (a static or sleeping side) is never written: no colour taken.
                let busy = bodies
                    .iter()
                    .filter(|&&i| i != 0)
                    .fold(0u32, |m, &i| m | used.get(i as usize).copied().unwrap_or(0));
                // At most ORDER_WINDOW − 1 colours are busy, so one of 0..ORDER_WINDOW is free.
                let colour = (!busy).trailing_zeros().min(ORDER_WINDOW as u32 - 1);
                for &i in bodies.iter().filter(|&&i| i != 0) {
                    if let Some(u) = used.get_mut(i as usize) {
                        *u |= 1 << colour;
                    }
                }
                colours[k] = colour as u8;
                counts[colour as usize + 1] += 1;
            }
            // Counting sort of the window by colour (stable: slot order within a colour).
            for c in 1..counts.len() {
                counts[c] += counts[c - 1];
            }
            let start = self.order.len();
            self.order.resize(start + window.len(), 0);
            for (k, &c) in colours.iter().take(window.len()).enumerate() {
                let place = &mut counts[c as usize];
                if let Some(out) = self.order.get_mut(start + *place as usize) {
                    *out = (first + k) as u32;
                }
                *place += 1;
            }
            // The next window starts with no colour taken.
            for &i in window.iter().flatten() {
                if let Some(u) = used.get_mut(i as usize) {
                    *u = 0;
                }
            }
        }
        self.colour_blocks();
    }

    /// Colours the blocks of [`JOINT_BLOCK`] joints as the windows' joints are coloured
    /// (greedily in block order, the lowest colour in which no block writes one of its
    /// bodies), into `block_order` and `colour_ends`. The passes run colour after colour,
    /// and with threads share out each colour's blocks: blocks of one colour write no body
    /// in common (a joint writes both its bodies unless one is static, kinematic or
    /// asleep, which no joint writes), so they may run in any order and on any thread with
    /// the same result. Up to 256 joints (one block) the order is the windows' alone; so
    /// it is when every block takes colour 0 (blocks that share no body: separate chains
    /// or ragdolls), whose blocks are still shared between threads. Box2D v3 colours its
    /// joints one by one with its contacts; whole blocks keep the windows' order inside,
    /// whose joints are read within a few kilobytes of each other (see [`ORDER_WINDOW`]).
    fn colour_blocks(&mut self) {
        let used = &mut self.used;
        let colours: Vec<u8> = self
            .order_bodies
            .chunks(JOINT_BLOCK)
            .map(|block| {
                let written = || block.iter().flatten().filter(|&&i| i != 0);
                let busy = written().fold(0u32, |m, &i| m | used.get(i as usize).copied().unwrap_or(0));
                let colour = (!busy).trailing_zeros().min(SERIAL_BLOCKS as u32);
                if colour < SERIAL_BLOCKS as u32 {
                    for &i in written() {
                        if let Some(u) = used.get_mut(i as usize) {
                            *u |= 1 << colour;
                        }
                    }
                }
                colour as u8
            })
            .collect();
        for &i in self.order_bodies.iter().flatten() {
            if let Some(u) = used.get_mut(i as usize) {
                *u = 0;
            }
        }
        self.block_order.clear();
        self.colour_ends.clear();
        let top = colours.iter().copied().max().map_or(0, |c| c as usize + 1);
        for c in 0..top {
            let at = self.block_order.len();
            self.block_order.extend(
                colours
                    .iter()
                    .enumerate()
                    .filter(|&(_, &colour)| colour as usize == c)
                    .map(|(b, _)| b as u32),
            );
            if self.block_order.len() > at {
                self.colour_ends.push(self.block_order.len());
            }
        }
        #[cfg(debug_assertions)]
        self.check_block_colours(&colours);
        // (The serial colour, if used, is the last one; its blocks are marked by it.)
        self.serial_from = if colours.iter().any(|&c| c as usize == SERIAL_BLOCKS) {
            self.colour_ends.len() - 1
        } else {
            usize::MAX
        };
    }

    /// Debug builds: no two blocks of one shared colour write the same state (what makes
    /// sharing a colour's blocks between threads race-free).
    #[cfg(debug_assertions)]
    fn check_block_colours(&self, colours: &[u8]) {
        let mut writer = std::collections::HashMap::new();
        for (b, block) in self.order_bodies.chunks(JOINT_BLOCK).enumerate() {
            let Some(&colour) = colours.get(b).filter(|&&c| (c as usize) < SERIAL_BLOCKS) else {
                continue;
            };
            for &i in block.iter().flatten().filter(|&&i| i != 0) {
                let first = *writer.entry((colour, i)).or_insert(b);
                debug_assert_eq!(
                    first, b,
                    "joint blocks {first} and {b} of colour {colour} both write state {i}"
                );
            }
        }
    }

    /// Whether the passes would give each of `threads` threads at least
    /// [`MIN_BLOCKS_PER_THREAD`] blocks of every shared colour, on average.
    pub fn worth_sharing(&self, threads: usize) -> bool {
        let shared = self.colour_ends.len().min(self.serial_from);
        let blocks = self.colour_ends.get(shared.wrapping_sub(1)).copied().unwrap_or(0);
        shared > 0 && blocks >= MIN_BLOCKS_PER_THREAD * threads * shared
    }

    /// Runs `pass` on every constraint, block colour after block colour (see
    /// [`JointSolver::colour_blocks`]); within a block in slot order (the warm start) or in
    /// the solve order. (A pass, not a closure: called through a closure, each joint's
    /// rows were a call of their own.) With shared states (the threaded step), each
    /// colour's blocks are shared between the pool's threads, the serial colour's run on
    /// this thread.
    fn pass<S: StateCell>(&mut self, states: &[S], ctx: &StepContext, pass: JointPass) {
        let order = &self.order;
        let run = |b: usize, block: &mut [JointConstraint], states: &[S]| {
            let base = b * JOINT_BLOCK;
            match pass {
                JointPass::WarmStart => {
                    for j in block.iter() {
                        j.warm_start(states);
                    }
                }
                JointPass::Solve { use_bias } => {
                    for &k in order.get(base..base + block.len()).unwrap_or(&[]) {
                        if let Some(j) = block.get_mut((k as usize).wrapping_sub(base)) {
                            j.solve(states, ctx, use_bias);
                        }
                    }
                }
            }
        };
        // No joints, or one block: here, without the lists below.
        if self.block_order.len() < 2 {
            if let Some(&b) = self.block_order.first() {
                run(b as usize, &mut self.constraints, states);
            }
            return;
        }
        let shared = S::as_shared(states).is_some();
        self.shared_passes += u64::from(shared);
        let mut blocks: Vec<Option<&mut [JointConstraint]>> =
            self.constraints.chunks_mut(JOINT_BLOCK).map(Some).collect();
        let mut start = 0;
        for (c, &end) in self.colour_ends.iter().enumerate() {
            let mut items: Vec<(usize, &mut [JointConstraint])> = self
                .block_order
                .get(start..end)
                .unwrap_or(&[])
                .iter()
                .filter_map(|&b| blocks.get_mut(b as usize)?.take().map(|block| (b as usize, block)))
                .collect();
            start = end;
            if shared && c < self.serial_from {
                S::for_each_mut(states, &mut items, 1, |_, (b, block), states| run(*b, block, states));
            } else {
                // One thread, or the serial colour: its blocks in order, here.
                for (b, block) in items {
                    run(b, block, states);
                }
            }
        }
    }

    /// Re-applies every joint's impulses, block colour after block colour, in slot order
    /// within a block (a short pass that gained nothing from the solve order: joint_grid's
    /// warm start took 0.50 ms in slot order, 0.69 in the solve order).
    pub fn warm_start<S: StateCell>(&mut self, states: &[S], ctx: &StepContext) {
        self.pass(states, ctx, JointPass::WarmStart);
    }

    /// One pass over every joint's rows, in the solve order (see [`JointSolver::pass`]).
    pub fn solve<S: StateCell>(&mut self, states: &[S], ctx: &StepContext, use_bias: bool) {
        self.pass(states, ctx, JointPass::Solve { use_bias });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constraint between solver states `a` and `b` (0: a static or sleeping side, not
    /// written); only what the ordering reads is meaningful.
    fn between(joint: u32, a: u32, b: u32) -> JointConstraint {
        let soft = Softness {
            bias_rate: 0.0,
            mass_scale: 1.0,
            impulse_scale: 0.0,
        };
        JointConstraint {
            joint,
            index_a: a,
            index_b: b,
            write_a: a != 0,
            write_b: b != 0,
            inv_mass_a: 1.0,
            inv_i_a: 1.0,
            inv_mass_b: 1.0,
            inv_i_b: 1.0,
            frame_a: Vec2::ZERO,
            frame_b: Vec2::ZERO,
            delta_center: Vec2::ZERO,
            angle0: 0.0,
            axial_mass: 0.5,
            softness: soft,
            spring: soft,
            enable_spring: false,
            enable_motor: false,
            enable_limit: false,
            lower: 0.0,
            upper: 0.0,
            motor_speed: 0.0,
            max_motor_impulse: 0.0,
            impulses: JointImpulses::default(),
        }
    }

    /// The solve order is a permutation of the constraints that keeps each joint in its
    /// window and runs colour by colour inside it. A chain of 100 links (joint k between
    /// states k and k + 1; state 0 static) takes two colours per window, the even links
    /// and the odd ones, so inside a window a joint writes a body the joint before it
    /// wrote at most once, where the colour changes; in slot order every joint shared a
    /// body with the one before.
    #[test]
    fn the_solve_order_colours_each_window() {
        let mut js = JointSolver::default();
        js.clear();
        for k in 0..100u32 {
            js.push(between(k, k, k + 1));
        }
        js.order_joints(101);
        let mut seen = js.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..100).collect::<Vec<u32>>(), "a permutation");
        for (w, window) in js.order.chunks(ORDER_WINDOW).enumerate() {
            let slots = w * ORDER_WINDOW..(w * ORDER_WINDOW + window.len());
            assert!(
                window.iter().all(|&k| slots.contains(&(k as usize))),
                "joints stay in their window"
            );
            let shared = window
                .windows(2)
                .filter(|p| {
                    let (x, y) = (js.order_bodies[p[0] as usize], js.order_bodies[p[1] as usize]);
                    x.iter().any(|&i| i != 0 && y.contains(&i))
                })
                .count();
            // Only where the colours change can two consecutive joints share a body.
            assert!(
                shared <= 1,
                "window {w}: {shared} consecutive pairs share a body: {window:?}"
            );
            assert_eq!(window[0] as usize, slots.start, "the window's first joint leads");
        }
        // The same writes: the order is kept; other writes: it is made again.
        let before = js.order.clone();
        js.clear();
        for k in 0..100u32 {
            js.push(between(k, k, k + 1));
        }
        js.order.reverse(); // a kept order stays as it is, even a wrong one
        js.order_joints(101);
        assert_eq!(js.order.iter().rev().copied().collect::<Vec<_>>(), before, "kept");
        js.clear();
        for k in 0..100u32 {
            // Every joint to the static state: no joint writes a shared body.
            js.push(between(k, 0, k + 1));
        }
        js.order_joints(101);
        assert_eq!(js.order, (0..100).collect::<Vec<u32>>(), "one colour: slot order");
    }

    /// The blocks' colours: every block once; no two blocks of a shared colour write the
    /// same state; blocks that find every shared colour taken go last, to one thread. A
    /// chain's blocks share one state with the next block, so they alternate between two
    /// colours; 40 blocks that each hold a joint to one hub state take the 31 shared
    /// colours, then the serial one.
    #[test]
    fn blocks_of_one_colour_write_no_state_in_common() {
        let check = |js: &JointSolver| {
            let mut seen = js.block_order.clone();
            seen.sort_unstable();
            let blocks = js.constraints.len().div_ceil(JOINT_BLOCK) as u32;
            assert_eq!(seen, (0..blocks).collect::<Vec<u32>>(), "every block once");
            let mut start = 0;
            for (c, &end) in js.colour_ends.iter().enumerate() {
                let mut writer = std::collections::HashMap::new();
                for &b in &js.block_order[start..end] {
                    let first = b as usize * JOINT_BLOCK;
                    for bodies in js.order_bodies.iter().skip(first).take(JOINT_BLOCK) {
                        for &i in bodies.iter().filter(|&&i| i != 0) {
                            let w = *writer.entry(i).or_insert(b);
                            assert!(
                                w == b || c >= js.serial_from,
                                "colour {c}: blocks {w} and {b} write state {i}"
                            );
                        }
                    }
                }
                start = end;
            }
        };
        let mut js = JointSolver::default();
        for k in 0..1000u32 {
            js.push(between(k, k + 1, k + 2));
        }
        js.order_joints(1002);
        check(&js);
        assert_eq!(js.colour_ends, vec![2, 4], "a chain's blocks alternate");
        assert_eq!(js.block_order, vec![0, 2, 1, 3]);
        assert_eq!(js.serial_from, usize::MAX);
        assert!(js.worth_sharing(1) && !js.worth_sharing(2), "2 blocks a colour");
        let mut hub = JointSolver::default();
        for k in 0..40 * JOINT_BLOCK as u32 {
            // The first joint of each block holds state 1 (the hub); the others, a
            // static side and a state of their own.
            let a = if k as usize % JOINT_BLOCK == 0 { 1 } else { 0 };
            hub.push(between(k, a, k + 2));
        }
        hub.order_joints(40 * JOINT_BLOCK + 2);
        check(&hub);
        assert_eq!(
            hub.colour_ends.len(),
            BLOCK_COLOURS,
            "31 shared colours and the serial one"
        );
        assert_eq!(hub.serial_from, SERIAL_BLOCKS);
        assert_eq!(&hub.block_order[SERIAL_BLOCKS..], &(31..40).collect::<Vec<u32>>()[..]);
        assert!(!hub.worth_sharing(1), "one block a colour");
        assert!(hub.used.iter().all(|&u| u == 0), "the scratch is left clear");
    }

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
