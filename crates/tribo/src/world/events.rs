//! Contact events (pulled after each step) and read-only views of contacts.

use super::{BodyId, ShapeId, World};
use crate::collision::contact::{FrictionState, PointSums};
use crate::error::Result;
use crate::math::Vec2;

/// Two shapes started touching (their manifold gained points) during the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactBeginEvent {
    /// First shape (lower index).
    pub shape_a: ShapeId,
    /// Second shape.
    pub shape_b: ShapeId,
    /// Contact normal, from A to B.
    pub normal: Vec2,
    /// First contact point [m].
    pub point: Vec2,
}

/// Two shapes stopped touching, or one of them was destroyed (its id may be stale).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactEndEvent {
    /// First shape.
    pub shape_a: ShapeId,
    /// Second shape.
    pub shape_b: ShapeId,
}

/// The events of the last step, in deterministic order. Cleared when the next step starts.
#[derive(Clone, Debug, Default)]
pub struct ContactEvents {
    /// Contacts that began touching.
    pub begin: Vec<ContactBeginEvent>,
    /// Contacts that stopped touching.
    pub end: Vec<ContactEndEvent>,
}

/// One contact point after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPointInfo {
    /// World position [m].
    pub point: Vec2,
    /// Separation [m] at the start of the step (negative = overlap).
    pub separation: f32,
    /// Normal impulse applied over the whole step [N·s] (divide by dt for the force); zero,
    /// as are `friction_impulse` and `slip_speed`, when the step did not solve the contact
    /// (neither body dynamic and awake). A sleeping body's contacts keep the values of their
    /// last solved step, unless an awake kinematic body moves them (touching, not solved:
    /// zero).
    pub normal_impulse: f32,
    /// Friction impulse applied over the step along the tangent `(n.y, −n.x)` [N·s].
    pub friction_impulse: f32,
    /// Stick or slip, as decided at the end of the step.
    pub state: FrictionState,
    /// Relative tangential speed of the surfaces at the end of the step [m/s]
    /// (conveyor surface speed removed).
    pub slip_speed: f32,
    /// Feature id of the point.
    pub id: u16,
}

/// A touching contact after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactInfo {
    /// First shape.
    pub shape_a: ShapeId,
    /// Second shape.
    pub shape_b: ShapeId,
    /// Body of `shape_a`.
    pub body_a: BodyId,
    /// Body of `shape_b`.
    pub body_b: BodyId,
    /// Unit normal from A to B.
    pub normal: Vec2,
    /// Number of valid entries in `points` (1 or 2).
    pub point_count: usize,
    /// The points.
    pub points: [ContactPointInfo; 2],
}

impl ContactInfo {
    /// The valid points.
    pub fn points(&self) -> &[ContactPointInfo] {
        &self.points[..self.point_count]
    }
}

impl World {
    /// Begin/end events of the last step.
    pub fn contact_events(&self) -> &ContactEvents {
        &self.events
    }

    /// Every touching contact, in contact-record order (deterministic; the order may change
    /// from one step to the next: the world renumbers its contacts in the solver's order).
    pub fn contacts(&self) -> impl Iterator<Item = ContactInfo> + '_ {
        self.contacts
            .iter()
            .enumerate()
            .filter_map(|(ci, c)| c.as_ref().filter(|c| c.touching).map(|c| self.contact_info(ci, c)))
    }

    /// Touching contacts of one body.
    pub fn body_contacts(&self, id: BodyId) -> Result<Vec<ContactInfo>> {
        let b = self.body_ref(id)?;
        let mut idx: Vec<u32> = b.contacts.clone();
        idx.sort_unstable();
        Ok(idx
            .into_iter()
            .filter_map(|ci| {
                let c = self.contacts.get(ci as usize)?.as_ref()?;
                c.touching.then(|| self.contact_info(ci as usize, c))
            })
            .collect())
    }

    /// The report of contact `ci`, whose record is `c`.
    fn contact_info(&self, ci: usize, c: &crate::collision::contact::Contact) -> ContactInfo {
        let body_id = |i: u32| BodyId {
            index: i,
            generation: self.bodies.generation(i),
        };
        let mut points = [ContactPointInfo {
            point: Vec2::ZERO,
            separation: 0.0,
            normal_impulse: 0.0,
            friction_impulse: 0.0,
            state: FrictionState::Stick,
            slip_speed: 0.0,
            id: 0,
        }; 2];
        for (i, p) in points.iter_mut().enumerate().take(c.manifold.count) {
            let mp = &c.manifold.points[i];
            let ps = &c.points[i];
            let sum = self.contact_sums.get(ci).map_or(PointSums::default(), |s| s[i]);
            *p = ContactPointInfo {
                point: mp.point,
                separation: mp.separation,
                normal_impulse: sum.total_normal_impulse,
                friction_impulse: sum.total_tangent_impulse,
                state: ps.state,
                slip_speed: sum.slip_speed,
                id: mp.id,
            };
        }
        ContactInfo {
            shape_a: c.shape_a,
            shape_b: c.shape_b,
            body_a: body_id(c.body_a),
            body_b: body_id(c.body_b),
            normal: c.manifold.normal,
            point_count: c.manifold.count,
            points,
        }
    }
}
