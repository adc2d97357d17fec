//! The public API for joints: create, destroy, read and drive them.
//!
//! A joint links two bodies' islands (they sleep and wake together) and, unless
//! `collide_connected`, stops contacts between its two bodies.

use super::{JointId, World};
use crate::dynamics::joint::{JointImpulses, JointRecord, RevoluteJointDef};
use crate::error::{check_finite, check_non_negative, check_vec, Error, Result};
use crate::math::Vec2;
use crate::solver::joint_solver::joint_angle;
use crate::world::BodyId;

impl RevoluteJointDef {
    /// A joint pivoting about the world point `anchor` [m] with the bodies where they are
    /// now: the local anchors are `anchor` in each body's frame and the reference angle
    /// is the bodies' current relative rotation (so the joint angle starts at 0).
    pub fn at(world: &World, body_a: BodyId, body_b: BodyId, anchor: Vec2) -> Result<RevoluteJointDef> {
        check_vec("anchor", anchor)?;
        let (xa, xb) = (world.body_transform(body_a)?, world.body_transform(body_b)?);
        let mut def = RevoluteJointDef::new(body_a, body_b, xa.inv_apply(anchor), xb.inv_apply(anchor));
        def.reference_angle = xa.q.inv_mul(xb.q).angle();
        Ok(def)
    }
}

impl World {
    /// Creates a revolute joint; wakes both bodies and, unless `collide_connected`, ends
    /// the contacts between them. A joint between two bodies that are not dynamic is
    /// allowed and does nothing (Box2D's joint grid links its static anchors too).
    pub fn create_revolute_joint(&mut self, def: &RevoluteJointDef) -> Result<JointId> {
        def.validate()?;
        self.body_ref(def.body_a)?;
        self.body_ref(def.body_b)?;
        let record = JointRecord {
            def: *def,
            body_a: def.body_a.index,
            body_b: def.body_b.index,
            impulses: JointImpulses::default(),
            inv_h: 0.0,
        };
        let (index, generation) = self.joints.insert(record);
        for bi in [def.body_a.index, def.body_b.index] {
            if let Some(body) = self.bodies.at_mut(bi) {
                body.joints.push(index);
            }
            self.wake_body(bi);
        }
        if !def.collide_connected {
            self.destroy_contacts_between(def.body_a.index, def.body_b.index);
        }
        Ok(JointId { index, generation })
    }

    /// Destroys a joint and wakes its bodies.
    pub fn destroy_joint(&mut self, id: JointId) -> Result<()> {
        self.joint_ref(id)?;
        self.remove_joint_internal(id.index);
        Ok(())
    }

    /// Removes a joint by slot, unlinks it from its bodies and wakes them.
    pub(crate) fn remove_joint_internal(&mut self, index: u32) {
        let generation = self.joints.generation(index);
        let Some(j) = self.joints.remove(index, generation) else {
            return;
        };
        for bi in [j.body_a, j.body_b] {
            if let Some(b) = self.bodies.at_mut(bi) {
                b.joints.retain(|&x| x != index);
            }
            self.wake_body(bi);
        }
        // Pairs the joint kept apart may collide again: their shapes look for pairs anew.
        if !j.def.collide_connected {
            for bi in [j.body_a, j.body_b] {
                let shapes = self.bodies.at(bi).map(|b| b.shapes.clone()).unwrap_or_default();
                for s in shapes {
                    if let Some(rec) = self.shapes.get(s.index, s.generation) {
                        let (tree, proxy, fat) = (rec.tree, rec.proxy, rec.fat_aabb);
                        self.broad_phase.move_proxy(tree, proxy, fat, s.index);
                    }
                }
            }
        }
    }

    /// Ends every contact between two bodies (no wake-up).
    fn destroy_contacts_between(&mut self, a: u32, b: u32) {
        let Some(body) = self.bodies.at(a) else { return };
        let between: Vec<u32> = body
            .contacts
            .iter()
            .copied()
            .filter(|&ci| {
                self.contacts
                    .get(ci as usize)
                    .and_then(|c| c.as_ref())
                    .is_some_and(|c| (c.body_a == a && c.body_b == b) || (c.body_a == b && c.body_b == a))
            })
            .collect();
        for ci in between {
            self.destroy_contact(ci, false);
        }
    }

    /// Whether a joint between these two body slots keeps their shapes from colliding.
    pub(crate) fn joint_blocks_pair(&self, a: u32, b: u32) -> bool {
        let Some(body) = self.bodies.at(a) else { return false };
        body.joints.iter().any(|&ji| {
            self.joints.at(ji).is_some_and(|j| {
                !j.def.collide_connected && ((j.body_a == a && j.body_b == b) || (j.body_a == b && j.body_b == a))
            })
        })
    }

    fn joint_ref(&self, id: JointId) -> Result<&JointRecord> {
        self.joints.get(id.index, id.generation).ok_or(Error::InvalidJoint(id))
    }

    fn joint_mut(&mut self, id: JointId) -> Result<&mut JointRecord> {
        self.joints
            .get_mut(id.index, id.generation)
            .ok_or(Error::InvalidJoint(id))
    }

    /// Number of live joints.
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// Ids of all live joints in creation-slot order.
    pub fn joint_ids(&self) -> Vec<JointId> {
        self.joints
            .iter()
            .map(|(i, _)| JointId {
                index: i,
                generation: self.joints.generation(i),
            })
            .collect()
    }

    /// Whether the id refers to a live joint.
    pub fn contains_joint(&self, id: JointId) -> bool {
        self.joints.get(id.index, id.generation).is_some()
    }

    /// The joint's definition as it is now (motor, limit and spring settings included).
    pub fn revolute_joint_def(&self, id: JointId) -> Result<RevoluteJointDef> {
        Ok(self.joint_ref(id)?.def)
    }

    /// The pivot as each body holds it, in world coordinates [m] (the two coincide but
    /// for the joint's soft give).
    pub fn joint_world_anchors(&self, id: JointId) -> Result<(Vec2, Vec2)> {
        let j = self.joint_ref(id)?;
        let (a, b) = (self.body_ref(j.def.body_a)?, self.body_ref(j.def.body_b)?);
        Ok((a.xf.apply(j.def.local_anchor_a), b.xf.apply(j.def.local_anchor_b)))
    }

    /// The joint angle [rad] in [−π, π]: B's rotation relative to A minus the reference
    /// angle.
    pub fn revolute_angle(&self, id: JointId) -> Result<f32> {
        let j = self.joint_ref(id)?;
        let (a, b) = (self.body_ref(j.def.body_a)?, self.body_ref(j.def.body_b)?);
        Ok(joint_angle(a.xf.q, b.xf.q, j.def.reference_angle))
    }

    /// The relative angular speed ω_B − ω_A [rad/s].
    pub fn revolute_speed(&self, id: JointId) -> Result<f32> {
        let j = self.joint_ref(id)?;
        let (a, b) = (self.body_ref(j.def.body_a)?, self.body_ref(j.def.body_b)?);
        Ok(b.w - a.w)
    }

    /// The force [N] the joint applied to body B in the last substep of the last step
    /// (body A got the opposite): what holds the pivot together.
    pub fn joint_reaction_force(&self, id: JointId) -> Result<Vec2> {
        let j = self.joint_ref(id)?;
        Ok(j.impulses.linear * j.inv_h)
    }

    /// The torque [N·m] the motor applied to body B in the last substep of the last step.
    pub fn revolute_motor_torque(&self, id: JointId) -> Result<f32> {
        let j = self.joint_ref(id)?;
        Ok(j.impulses.motor * j.inv_h)
    }

    /// Turns the motor on or off with a target speed [rad/s] and largest torque [N·m];
    /// wakes the bodies.
    pub fn set_revolute_motor(&mut self, id: JointId, enable: bool, speed: f32, max_torque: f32) -> Result<()> {
        check_finite("speed", speed)?;
        check_non_negative("max_torque", max_torque)?;
        let j = self.joint_mut(id)?;
        j.def.enable_motor = enable;
        j.def.motor_speed = speed;
        j.def.max_motor_torque = max_torque;
        self.wake_joint_bodies(id);
        Ok(())
    }

    /// Turns the angle limit on or off with its bounds [rad] (lower ≤ upper); wakes the
    /// bodies.
    pub fn set_revolute_limit(&mut self, id: JointId, enable: bool, lower: f32, upper: f32) -> Result<()> {
        check_finite("lower", lower)?;
        check_finite("upper", upper)?;
        if lower > upper {
            return Err(Error::arg(
                "lower",
                format!("must be ≤ upper (got lower {lower} > upper {upper})"),
            ));
        }
        let j = self.joint_mut(id)?;
        j.def.enable_limit = enable;
        j.def.lower_angle = lower;
        j.def.upper_angle = upper;
        self.wake_joint_bodies(id);
        Ok(())
    }

    /// Turns the angular spring on or off with its frequency [Hz] (> 0 when on) and damping
    /// ratio; wakes the bodies.
    pub fn set_revolute_spring(&mut self, id: JointId, enable: bool, hertz: f32, damping_ratio: f32) -> Result<()> {
        check_non_negative("hertz", hertz)?;
        check_non_negative("damping_ratio", damping_ratio)?;
        if enable && hertz <= 0.0 {
            return Err(Error::arg(
                "hertz",
                format!("must be positive when the spring is on (got {hertz})"),
            ));
        }
        let j = self.joint_mut(id)?;
        j.def.enable_spring = enable;
        j.def.spring_hertz = hertz;
        j.def.spring_damping_ratio = damping_ratio;
        self.wake_joint_bodies(id);
        Ok(())
    }

    fn wake_joint_bodies(&mut self, id: JointId) {
        if let Some(j) = self.joints.get(id.index, id.generation) {
            let (a, b) = (j.body_a, j.body_b);
            self.wake_body(a);
            self.wake_body(b);
        }
    }

    /// Prepares the step's joint constraints: every joint with an awake dynamic body, in
    /// slot order (a joint between two sleeping or non-dynamic bodies does nothing).
    pub(crate) fn build_joints(&mut self, ctx: &crate::solver::StepContext) {
        use crate::solver::joint_solver::{JointBody, JointConstraint};
        let mut solver = core::mem::take(&mut self.joint_solver);
        solver.clear();
        for (ji, j) in self.joints.iter() {
            let side = |bi: u32| -> Option<JointBody> {
                let b = self.bodies.at(bi)?;
                let sb = self.solver_bodies.get(bi as usize)?;
                Some(JointBody {
                    index: sb.index,
                    dynamic: sb.awake_dynamic,
                    inv_mass: if sb.index == 0 { 0.0 } else { sb.inv_mass },
                    inv_i: if sb.index == 0 { 0.0 } else { sb.inv_i },
                    center: b.center,
                    q: b.xf.q,
                    local_center: b.local_center,
                })
            };
            let (Some(a), Some(b)) = (side(j.body_a), side(j.body_b)) else {
                continue;
            };
            if !a.dynamic && !b.dynamic {
                continue;
            }
            solver.push(JointConstraint::new(ji, j, &a, &b, ctx));
        }
        solver.order_joints(self.states.len());
        self.joint_solver = solver;
    }

    /// Writes the joints' accumulated impulses back into their records.
    pub(crate) fn store_joints(&mut self, ctx: &crate::solver::StepContext) {
        for c in &self.joint_solver.constraints {
            if let Some(j) = self.joints.at_mut(c.joint) {
                j.impulses = c.impulses;
                j.inv_h = ctx.inv_h;
            }
        }
    }
}
