//! Contact records: one per pair of shapes whose fat boxes overlap, holding the manifold
//! and, per point, the impulses and the stick/slip state that persist across steps.
//!
//! Pipeline stage: narrow phase. Neighbours: created by [`super::broad_phase`], read and
//! written back by [`crate::solver`].

use crate::dynamics::MixedMaterial;
use crate::geometry::{collide, Manifold, Shape, MAX_MANIFOLD_POINTS};
use crate::math::Transform;
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
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PointState {
    /// Normal impulse of the last substep [N·s] (warm start).
    pub normal_impulse: f32,
    /// Friction impulse of the last substep [N·s] (warm start), along the tangent.
    pub tangent_impulse: f32,
    /// Sum over the step's substeps of the normal impulse [N·s] (what the step applied).
    pub total_normal_impulse: f32,
    /// Sum over the step's substeps of the friction impulse [N·s].
    pub total_tangent_impulse: f32,
    /// Largest normal impulse of any substep [N·s]; > 0 means the point carried load.
    pub max_normal_impulse: f32,
    /// Stick or slip.
    pub state: FrictionState,
    /// True until the point has been through one solver step.
    pub fresh: bool,
    /// Tangential slip [m] accumulated while sticking (the static-friction anchor): the
    /// solver drives it back to zero, so a sticking body cannot creep.
    pub drift: f32,
    /// Relative tangential speed at the end of the step [m/s] (surface speed removed).
    pub slip_speed: f32,
    /// Normal impulse per substep [N·s] the soft contact relaxes towards (a slowly
    /// tracking average of the manifold's load, so a steady load needs no deflection).
    pub preload: f32,
    /// Relative normal velocity at impact [m/s] (negative = approaching).
    pub approach_velocity: f32,
}

/// A contact between two shapes (internal record).
#[derive(Clone, Debug)]
pub(crate) struct Contact {
    pub shape_a: ShapeId,
    pub shape_b: ShapeId,
    /// Body slot indices.
    pub body_a: u32,
    pub body_b: u32,
    pub manifold: Manifold,
    pub points: [PointState; MAX_MANIFOLD_POINTS],
    pub material: MixedMaterial,
    /// Rolling lever arm [m]: the larger rolling radius of the two shapes.
    pub rolling_radius: f32,
    /// Rolling resistance impulse [N·m·s] of the last substep (warm start).
    pub rolling_impulse: f32,
    /// Whether the manifold has points.
    pub touching: bool,
}

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
        self.manifold = collide(geom_a, xf_a, geom_b, xf_b, speculative_distance);
        for i in 0..self.manifold.count {
            let id = self.manifold.points[i].id;
            let matched = (0..old_manifold.count).find(|&j| old_manifold.points[j].id == id);
            self.points[i] = match matched {
                Some(j) => {
                    let mut p = old_points[j];
                    p.total_normal_impulse = 0.0;
                    p.total_tangent_impulse = 0.0;
                    p.max_normal_impulse = 0.0;
                    p
                }
                None => PointState {
                    fresh: true,
                    ..PointState::default()
                },
            };
        }
        for p in self.points.iter_mut().skip(self.manifold.count) {
            *p = PointState::default();
        }
        if self.manifold.count == 0 {
            self.rolling_impulse = 0.0;
        }
        self.touching = self.manifold.count > 0;
        self.touching
    }
}

/// Key of an unordered shape pair: lower shape index in the high half.
#[inline]
pub(crate) fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}
