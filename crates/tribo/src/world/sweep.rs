//! Continuous collision against static shapes for bodies that moved further in a step
//! than their pairs covered, or fast bodies whose boxes were swept (see
//! [`crate::geometry::first_contact`] and `world::next_box`).
//!
//! The pairs a body is solved with come from its fat boxes at the start of the step (swept
//! along its velocity then only for a body in flight or a bullet). A body faster than its
//! boxes' room, or an impulse inside the step, can send it further: in Box2D's spinner a box
//! the rotor's tip hits at 70 m/s is kicked 0.7 m into the ring in one step, where it has
//! no contact points; a wall of quads then held it in the seam between two pieces, a chain
//! let it through. Such a body is stopped where
//! it first touches a static shape along its motion, as Box2D v3 stops fast bodies at
//! their time of impact against static shapes; its velocity is kept, and the next step's
//! pairs and speculative contact take it from there.

use super::World;
use crate::collision::broad_phase::STATIC_TREE;
use crate::collision::contact::pair_key;
use crate::dynamics::body::Body;
use crate::geometry::{first_contact, Sweep};
use crate::math::Aabb;

impl World {
    /// Moves a body back along this step's motion to where it first overlaps, by more than
    /// the linear slop, a static shape it may collide with (filters and joints respected)
    /// and had no contact points with this step. Its velocity is unchanged. Returns whether it moved.
    pub(crate) fn stop_at_static_shapes(&mut self, body_index: u32, known: (usize, Aabb)) -> bool {
        let mut found = core::mem::take(&mut self.scratch_found);
        let first = self.first_static_contact(body_index, known, &mut found);
        self.scratch_found = found;
        match first {
            Some((first, sweep)) if first < 1.0 => {
                let xf = sweep.at(first);
                if let Some(b) = self.bodies.at_mut(body_index) {
                    b.xf = xf;
                    b.center = xf.apply(b.local_center);
                    return true;
                }
                false
            }
            _ => false,
        }
    }

    /// The first fraction of this step's motion at which the body overlaps a static shape
    /// it had no contact points with (1 when none), and the motion; `known`: one shape's
    /// position in the body's list and its box at the body's pose; `found` is scratch.
    fn first_static_contact(
        &self,
        body_index: u32,
        known: (usize, Aabb),
        found: &mut Vec<u32>,
    ) -> Option<(f32, Sweep)> {
        let tree = &self.broad_phase.trees[STATIC_TREE as usize];
        let b = self.bodies.at(body_index)?;
        if tree.proxy_count() == 0 {
            return None;
        }
        let sweep = step_motion(b);
        let bulge = sweep_bulge(&sweep, b.max_extent);
        let mut first = 1.0f32;
        // By slot, the first from `first_shape`: following the list's pointer was a cache
        // miss per body, a quarter of this function's samples in the spinner.
        for k in 0..b.shapes.len() {
            let index = b.shape_index(k);
            // Every listed shape is live.
            let Some(s) = self.shapes.at(index) else {
                continue;
            };
            // Every pose of the motion: the box at the start pose (the shape's box from the
            // last refresh holds it, for the escaped shape and those after it; a shape
            // before it already has its new box there, but it did not escape: see
            // `world::next_box`) and at the end pose, grown by the most a point strays from
            // the chord between its two end positions during the turn (the body's reach
            // bounds each shape's).
            let end = if k == known.0 { known.1 } else { s.geometry.aabb(b.xf) };
            let swept = s.aabb.union(end).expand(bulge);
            found.clear();
            tree.query(swept, s.filter.mask, |_, data| {
                found.push(data as u32);
                true
            });
            for &other in found.iter() {
                // A pair with contact points was in this step's solve, with a speculative
                // margin for the motion the step began with. A pair without points was
                // beyond that margin when the step began: an impulse inside the step (the
                // spinner's rotor tip at 100 m/s) can still carry the body through a thin
                // static shape, a one-sided chain piece above all.
                if self.pair_has_points(b, pair_key(index, other)) {
                    continue;
                }
                let Some(o) = self.shapes.at(other) else { continue };
                if !s.filter.should_collide(&o.filter) {
                    continue;
                }
                if !b.joints.is_empty() && self.joint_blocks_pair(body_index, o.body.index) {
                    continue;
                }
                let Some(ob) = self.bodies.at(o.body.index) else {
                    continue;
                };
                if let Some(t) = first_contact(&o.geometry, ob.xf, &s.geometry, &sweep) {
                    first = first.min(t);
                }
            }
        }
        Some((first, sweep))
    }
}

/// A body's motion over the step just solved (from its start pose `center0`, `q0`).
fn step_motion(b: &Body) -> Sweep {
    Sweep {
        local_center: b.local_center,
        c0: b.center0,
        c1: b.center,
        q0: b.q0,
        q1: b.xf.q,
    }
}

/// How far [m] a point at distance `reach` from the centre of mass strays, during the
/// sweep's turn, from the straight line between its start and end positions: the sagitta
/// of its arc, reach·(1 − cos(Δθ/2)) ≤ ½·reach·|q1 − q0| (the chord).
fn sweep_bulge(sweep: &Sweep, reach: f32) -> f32 {
    0.5 * sweep.chord(reach)
}
