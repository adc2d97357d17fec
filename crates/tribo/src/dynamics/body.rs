//! Rigid bodies: their definition (user input) and their simulation record.
//!
//! Pipeline stage: integration and finalize. Neighbours: [`crate::solver`] reads the
//! solver copies of these records; [`crate::world`] owns them.

use crate::error::{check_finite, check_non_negative, check_vec, Result};
use crate::math::{Rot, Transform, Vec2};
use crate::world::ShapeId;

/// How a body moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BodyType {
    /// Never moves; infinite mass. The default (as in Box2D).
    #[default]
    Static,
    /// Moves with its set velocity; infinite mass; pushes dynamic bodies, is not pushed.
    Kinematic,
    /// Moves under forces, gravity and contacts.
    Dynamic,
}

/// Everything needed to create a body. Defaults: static, at the origin, at rest, awake,
/// gravity scale 1, no damping, free rotation, sleep allowed.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDef {
    /// Static, kinematic or dynamic.
    pub body_type: BodyType,
    /// Position of the body origin [m].
    pub position: Vec2,
    /// Rotation [rad], counter-clockwise.
    pub angle: f32,
    /// Linear velocity of the centre of mass [m/s].
    pub linear_velocity: Vec2,
    /// Angular velocity [rad/s].
    pub angular_velocity: f32,
    /// Linear damping [1/s], ≥ 0: velocity decays as v ← v / (1 + h·c) each substep.
    pub linear_damping: f32,
    /// Angular damping [1/s], ≥ 0.
    pub angular_damping: f32,
    /// Multiplies the world gravity for this body (1 = normal, 0 = floats).
    pub gravity_scale: f32,
    /// Prevents rotation (infinite rotational inertia).
    pub fixed_rotation: bool,
    /// A fast, small body that must not pass through other moving bodies (Box2D's
    /// `isBullet`): its shapes' boxes are swept along each step's motion even while it
    /// touches something, so its pairs exist before it gets there and the speculative
    /// contact catches it. Other bodies' boxes are swept only while they touch nothing (in
    /// flight), and every dynamic body is stopped at static shapes by continuous collision;
    /// a bullet in a moving pile costs pairs. Default false.
    pub bullet: bool,
    /// Constant force [N] applied at the centre of mass every step, until changed.
    pub constant_force: Vec2,
    /// Constant torque [N·m] applied every step, until changed.
    pub constant_torque: f32,
    /// Whether the body may fall asleep when at rest.
    pub enable_sleep: bool,
    /// Whether the body starts awake.
    pub awake: bool,
    /// Speed [m/s] below which the body counts as resting for sleep, usually 0.05 m/s.
    pub sleep_threshold: f32,
    /// Free for the user (an index into their own tables, for example).
    pub user_data: u64,
}

impl Default for BodyDef {
    fn default() -> Self {
        BodyDef {
            body_type: BodyType::Static,
            position: Vec2::ZERO,
            angle: 0.0,
            linear_velocity: Vec2::ZERO,
            angular_velocity: 0.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            gravity_scale: 1.0,
            fixed_rotation: false,
            bullet: false,
            constant_force: Vec2::ZERO,
            constant_torque: 0.0,
            enable_sleep: true,
            awake: true,
            sleep_threshold: 0.05,
            user_data: 0,
        }
    }
}

impl BodyDef {
    /// A dynamic body at `position` [m].
    pub fn dynamic(position: Vec2) -> BodyDef {
        BodyDef {
            body_type: BodyType::Dynamic,
            position,
            ..BodyDef::default()
        }
    }

    /// A static body at `position` [m].
    pub fn fixed(position: Vec2) -> BodyDef {
        BodyDef {
            position,
            ..BodyDef::default()
        }
    }

    /// A kinematic body at `position` [m].
    pub fn kinematic(position: Vec2) -> BodyDef {
        BodyDef {
            body_type: BodyType::Kinematic,
            position,
            ..BodyDef::default()
        }
    }

    /// Checks that every number is finite and in range.
    pub fn validate(&self) -> Result<()> {
        check_vec("BodyDef::position", self.position)?;
        check_finite("BodyDef::angle", self.angle)?;
        check_vec("BodyDef::linear_velocity", self.linear_velocity)?;
        check_finite("BodyDef::angular_velocity", self.angular_velocity)?;
        check_non_negative("BodyDef::linear_damping", self.linear_damping)?;
        check_non_negative("BodyDef::angular_damping", self.angular_damping)?;
        check_finite("BodyDef::gravity_scale", self.gravity_scale)?;
        check_vec("BodyDef::constant_force", self.constant_force)?;
        check_finite("BodyDef::constant_torque", self.constant_torque)?;
        check_non_negative("BodyDef::sleep_threshold", self.sleep_threshold)?;
        Ok(())
    }
}

/// The simulation record of a body (internal).
#[derive(Clone, Debug)]
pub(crate) struct Body {
    pub body_type: BodyType,
    /// Pose of the body origin.
    pub xf: Transform,
    /// World centre of mass [m].
    pub center: Vec2,
    /// Centre of mass in the body frame [m].
    pub local_center: Vec2,
    /// Centre of mass and rotation at the start of the last step (sleep metric; with them
    /// finalize knows the step's motion, for continuous collision).
    pub center0: Vec2,
    pub q0: Rot,
    pub v: Vec2,
    pub w: f32,
    pub mass: f32,
    pub inv_mass: f32,
    /// Rotational inertia about the centre of mass [kg·m²].
    pub inertia: f32,
    pub inv_inertia: f32,
    pub gravity_scale: f32,
    pub linear_damping: f32,
    pub angular_damping: f32,
    pub fixed_rotation: bool,
    /// Boxes swept along the motion ([`BodyDef::bullet`]).
    pub bullet: bool,
    pub constant_force: Vec2,
    pub constant_torque: f32,
    /// Forces applied through `apply_force*` since the last step; cleared by the step.
    pub force: Vec2,
    pub torque: f32,
    pub enable_sleep: bool,
    pub sleep_threshold: f32,
    pub awake: bool,
    /// How long [s] the body has been below its sleep threshold.
    pub sleep_time: f32,
    /// Set by finalize when the solver produced a non-finite state (reported, then cleared).
    pub non_finite: bool,
    /// Largest distance from the centre of mass to any of its shapes' points [m].
    pub max_extent: f32,
    pub shapes: Vec<ShapeId>,
    /// Slot index of `shapes[0]` (`u32::MAX`: none), kept with the list
    /// ([`Body::shapes_changed`]): the step's body pass and finalize read it without
    /// following the list's pointer (a dependent cache miss per body: 20 % of the body
    /// pass, 60 % of finalize's box refresh).
    pub first_shape: u32,
    /// Indices of the contacts this body takes part in.
    pub contacts: Vec<u32>,
    /// The shape-pair key of each of `contacts` (same order): the broad phase checks a
    /// body's short list before the world's pair table.
    pub contact_keys: Vec<u64>,
    /// Slot indices of the joints attached to this body.
    pub joints: Vec<u32>,
    pub user_data: u64,
    /// Sleeping island this body belongs to while asleep (index into the world's list).
    pub sleep_island: u32,
}

impl Body {
    /// Call after `shapes` changed: keeps `first_shape` with the list.
    pub(crate) fn shapes_changed(&mut self) {
        self.first_shape = self.shapes.first().map_or(u32::MAX, |s| s.index);
    }

    /// Slot index of the body's `k`-th shape (`u32::MAX` past the end); the first from
    /// `first_shape`, without reading the list.
    #[inline]
    pub(crate) fn shape_index(&self, k: usize) -> u32 {
        match k {
            0 => self.first_shape,
            _ => self.shapes.get(k).map_or(u32::MAX, |sid| sid.index),
        }
    }

    pub(crate) fn new(def: &BodyDef) -> Body {
        let xf = Transform::new(def.position, def.angle);
        let moving = def.body_type != BodyType::Static;
        Body {
            body_type: def.body_type,
            xf,
            center: def.position,
            local_center: Vec2::ZERO,
            center0: def.position,
            q0: xf.q,
            v: if moving { def.linear_velocity } else { Vec2::ZERO },
            w: if moving { def.angular_velocity } else { 0.0 },
            mass: 0.0,
            inv_mass: 0.0,
            inertia: 0.0,
            inv_inertia: 0.0,
            gravity_scale: def.gravity_scale,
            linear_damping: def.linear_damping,
            angular_damping: def.angular_damping,
            fixed_rotation: def.fixed_rotation,
            bullet: def.bullet,
            constant_force: def.constant_force,
            constant_torque: def.constant_torque,
            force: Vec2::ZERO,
            torque: 0.0,
            enable_sleep: def.enable_sleep,
            sleep_threshold: def.sleep_threshold,
            awake: def.awake || def.body_type == BodyType::Static,
            sleep_time: 0.0,
            max_extent: 0.0,
            non_finite: false,
            shapes: Vec::new(),
            first_shape: u32::MAX,
            contacts: Vec::new(),
            contact_keys: Vec::new(),
            joints: Vec::new(),
            user_data: def.user_data,
            sleep_island: u32::MAX,
        }
    }

    /// True for dynamic bodies.
    #[inline]
    pub fn is_dynamic(&self) -> bool {
        self.body_type == BodyType::Dynamic
    }
}
