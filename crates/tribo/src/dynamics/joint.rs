//! Joints: definitions (user input) and simulation records.
//!
//! Pipeline stage: data of the step; the constraint rows are in
//! [`crate::solver::joint_solver`]. One joint kind today, the revolute joint (a hinge: the
//! two bodies share one point and turn about it), with Box2D v3's options: an angle
//! limit, a motor (which, at speed 0 with a small torque, is also joint friction) and an
//! angular spring.

use crate::error::{check_finite, check_non_negative, check_vec, Error, Result};
use crate::math::Vec2;
use crate::world::BodyId;

/// A revolute joint: body A's point `local_anchor_a` and body B's point `local_anchor_b`
/// are held together, and the bodies turn freely about it (up to the limit, against the
/// motor and the spring when those are on).
///
/// The joint angle is B's rotation relative to A minus `reference_angle`, counter-clockwise
/// [rad]: zero in the pose the joint was made in when made with [`RevoluteJointDef::at`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RevoluteJointDef {
    /// The first body.
    pub body_a: BodyId,
    /// The second body.
    pub body_b: BodyId,
    /// The pivot in body A's frame (relative to its origin) [m].
    pub local_anchor_a: Vec2,
    /// The pivot in body B's frame [m].
    pub local_anchor_b: Vec2,
    /// B's rotation relative to A at which the joint angle is zero [rad].
    pub reference_angle: f32,
    /// Keep the joint angle within `[lower_angle, upper_angle]`.
    pub enable_limit: bool,
    /// Lower angle limit [rad], ≤ `upper_angle`.
    pub lower_angle: f32,
    /// Upper angle limit [rad].
    pub upper_angle: f32,
    /// Drive the relative angular speed towards `motor_speed` with at most
    /// `max_motor_torque`.
    pub enable_motor: bool,
    /// Target relative angular speed ω_B − ω_A [rad/s].
    pub motor_speed: f32,
    /// Largest torque the motor applies [N·m], ≥ 0. With `motor_speed` 0 this is joint
    /// friction: the joint holds until the load exceeds it.
    pub max_motor_torque: f32,
    /// An angular spring pulls the joint angle towards 0.
    pub enable_spring: bool,
    /// Spring frequency [Hz], > 0 when the spring is on (the natural frequency the two
    /// bodies would oscillate at about the joint). The spring is integrated implicitly,
    /// as Box2D's soft springs: stable at any stiffness, but even undamped it loses
    /// amplitude by a factor (1 + (2π f h)²)^(−½) per substep h (about 15 % per cycle at
    /// 2 Hz with 4 substeps at 60 Hz).
    pub spring_hertz: f32,
    /// Spring damping ratio (dimensionless, 0 = undamped, 1 = critical), ≥ 0.
    pub spring_damping_ratio: f32,
    /// Stiffness of the soft position correction that pulls the anchors back together
    /// [Hz], usually 60 (Box2D v3's default); clamped to a quarter of the substep rate.
    /// Under a steady load F the anchors part by F / (m ω²), ω = 2π × this, m the
    /// pivot's effective mass (0.7 mm for a 1 kg body hanging from a static pivot).
    pub constraint_hertz: f32,
    /// Damping ratio of that correction (dimensionless), usually 2 (Box2D v3's default).
    pub constraint_damping_ratio: f32,
    /// Whether the two bodies' shapes still collide with each other (default false).
    pub collide_connected: bool,
    /// Free for the user.
    pub user_data: u64,
}

impl RevoluteJointDef {
    /// A joint between two bodies at given anchors in their own frames [m], with no limit,
    /// motor or spring, reference angle 0 and Box2D's default softness (60 Hz, ζ 2).
    pub fn new(body_a: BodyId, body_b: BodyId, local_anchor_a: Vec2, local_anchor_b: Vec2) -> RevoluteJointDef {
        RevoluteJointDef {
            body_a,
            body_b,
            local_anchor_a,
            local_anchor_b,
            reference_angle: 0.0,
            enable_limit: false,
            lower_angle: 0.0,
            upper_angle: 0.0,
            enable_motor: false,
            motor_speed: 0.0,
            max_motor_torque: 0.0,
            enable_spring: false,
            spring_hertz: 0.0,
            spring_damping_ratio: 0.0,
            constraint_hertz: DEFAULT_CONSTRAINT_HERTZ,
            constraint_damping_ratio: DEFAULT_CONSTRAINT_DAMPING_RATIO,
            collide_connected: false,
            user_data: 0,
        }
    }

    /// With the angle limit `[lower, upper]` [rad] on.
    pub fn limit(mut self, lower: f32, upper: f32) -> RevoluteJointDef {
        self.enable_limit = true;
        self.lower_angle = lower;
        self.upper_angle = upper;
        self
    }

    /// With the motor on: target speed [rad/s] and largest torque [N·m].
    pub fn motor(mut self, speed: f32, max_torque: f32) -> RevoluteJointDef {
        self.enable_motor = true;
        self.motor_speed = speed;
        self.max_motor_torque = max_torque;
        self
    }

    /// With the angular spring on: frequency [Hz] and damping ratio.
    pub fn spring(mut self, hertz: f32, damping_ratio: f32) -> RevoluteJointDef {
        self.enable_spring = true;
        self.spring_hertz = hertz;
        self.spring_damping_ratio = damping_ratio;
        self
    }

    /// Checks every number (finite, in range) and that the bodies differ.
    pub(crate) fn validate(&self) -> Result<()> {
        check_vec("RevoluteJointDef::local_anchor_a", self.local_anchor_a)?;
        check_vec("RevoluteJointDef::local_anchor_b", self.local_anchor_b)?;
        check_finite("RevoluteJointDef::reference_angle", self.reference_angle)?;
        check_finite("RevoluteJointDef::lower_angle", self.lower_angle)?;
        check_finite("RevoluteJointDef::upper_angle", self.upper_angle)?;
        if self.enable_limit && self.lower_angle > self.upper_angle {
            return Err(Error::arg(
                "RevoluteJointDef::lower_angle",
                format!(
                    "must be ≤ upper_angle (got lower {} > upper {})",
                    self.lower_angle, self.upper_angle
                ),
            ));
        }
        check_finite("RevoluteJointDef::motor_speed", self.motor_speed)?;
        check_non_negative("RevoluteJointDef::max_motor_torque", self.max_motor_torque)?;
        check_non_negative("RevoluteJointDef::spring_hertz", self.spring_hertz)?;
        if self.enable_spring && self.spring_hertz <= 0.0 {
            return Err(Error::arg(
                "RevoluteJointDef::spring_hertz",
                format!("must be positive when the spring is on (got {})", self.spring_hertz),
            ));
        }
        check_non_negative("RevoluteJointDef::spring_damping_ratio", self.spring_damping_ratio)?;
        check_non_negative("RevoluteJointDef::constraint_hertz", self.constraint_hertz)?;
        check_non_negative(
            "RevoluteJointDef::constraint_damping_ratio",
            self.constraint_damping_ratio,
        )?;
        if self.body_a == self.body_b {
            return Err(Error::arg("RevoluteJointDef::body_b", "must differ from body_a"));
        }
        Ok(())
    }
}

/// Box2D v3's default stiffness of a joint's soft position correction [Hz].
pub const DEFAULT_CONSTRAINT_HERTZ: f32 = 60.0;
/// Box2D v3's default damping ratio of a joint's soft position correction.
pub const DEFAULT_CONSTRAINT_DAMPING_RATIO: f32 = 2.0;

/// The accumulated impulses of a revolute joint, kept between steps (warm start).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct JointImpulses {
    /// Point constraint [N·s] (on B; A gets the opposite).
    pub linear: Vec2,
    /// Spring, motor, lower and upper limit [N·m·s] (on B about the pivot).
    pub spring: f32,
    pub motor: f32,
    pub lower: f32,
    pub upper: f32,
}

/// The simulation record of a joint (internal).
#[derive(Clone, Debug)]
pub(crate) struct JointRecord {
    pub def: RevoluteJointDef,
    /// Body slot indices (the ids are in `def`).
    pub body_a: u32,
    pub body_b: u32,
    pub impulses: JointImpulses,
    /// 1 / substep of the last step [1/s]: an accumulated impulse of a substep times this
    /// is the force (or torque) the joint applied.
    pub inv_h: f32,
}
