//! First contact along a step's motion.
//!
//! The broad phase pairs shapes from where a body was at the start of a step and how fast
//! it was moving then. An impulse inside the step (a motor-driven rotor, an explosion of
//! contacts) can send a body much further, past shapes it has no pair with: nothing stops
//! it, and a body that ends deep inside a wall made of several pieces can be pushed out
//! through the seam between two of them. Box2D v3 answers with continuous collision against
//! static shapes after the solve (conservative advancement); here the same question — when
//! along its motion does the body first touch a static shape? — is answered with the
//! manifold code already at hand: the motion is sampled at steps shorter than half the
//! moving shape's thickness (so no shape at least that thick is passed between two
//! samples), and the first overlapping sample is bisected against the last free one.

use super::manifold::collide;
use super::Shape;
use crate::math::{Rot, Transform, Vec2};

/// A body's motion over a step: its centre of mass moves in a straight line and it turns
/// about that centre, both in proportion to the fraction `t` of the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// Centre of mass in the body frame [m].
    pub local_center: Vec2,
    /// Centre of mass at the start and at the end of the step [m].
    pub c0: Vec2,
    pub c1: Vec2,
    /// Rotation at the start and at the end of the step.
    pub q0: Rot,
    pub q1: Rot,
}

impl Sweep {
    /// The body's pose at fraction `t` ∈ [0, 1] of the step (the rotation interpolated
    /// linearly and normalised: exact at both ends, within 0.1 % of the angle for turns
    /// up to 0.25π per step, Box2D's limit).
    pub fn at(&self, t: f32) -> Transform {
        let c = self.c0 + t * (self.c1 - self.c0);
        let (qc, qs) = (
            self.q0.c + t * (self.q1.c - self.q0.c),
            self.q0.s + t * (self.q1.s - self.q0.s),
        );
        let mag = (qc * qc + qs * qs).sqrt();
        let q = if mag > 0.0 {
            Rot {
                c: qc / mag,
                s: qs / mag,
            }
        } else {
            self.q1
        };
        Transform {
            p: c - q.rotate(self.local_center),
            q,
        }
    }

    /// The most any point at distance `reach` [m] from the centre of mass moves over the
    /// step [m] (straight motion plus the chord of the turn, 2·reach·sin(Δθ/2) =
    /// reach·|q1 − q0|).
    pub fn travel(&self, reach: f32) -> f32 {
        (self.c1 - self.c0).length() + self.chord(reach)
    }

    /// The chord [m] of the turn of a point at distance `reach` from the centre of mass,
    /// 2·reach·sin(Δθ/2) = reach·|q1 − q0|.
    pub fn chord(&self, reach: f32) -> f32 {
        reach * Vec2::new(self.q1.c - self.q0.c, self.q1.s - self.q0.s).length()
    }
}

/// Bisection steps after the sampling: the contact time is found to 1/1024 of a sample
/// interval.
const BISECTIONS: u32 = 10;

/// Most samples along one motion (a body that moves more than 64 half-thicknesses in a
/// step is sampled more coarsely; the speed limit bounds how far that can be).
const MAX_SAMPLES: u32 = 64;

/// Whether the two shapes overlap by more than the linear slop (some manifold point with a
/// separation below −[`LINEAR_SLOP`](super::LINEAR_SLOP): an overlap a contact would not
/// leave).
fn overlap(fixed: &Shape, xf_fixed: Transform, moving: &Shape, xf: Transform) -> bool {
    let m = collide(fixed, xf_fixed, moving, xf, 0.0);
    m.points[..m.count].iter().any(|p| p.separation < -super::LINEAR_SLOP)
}

/// The fraction of the step at which `moving`, carried by `sweep`, first overlaps `fixed`
/// (at `xf_fixed`) by more than the linear slop: the last sampled or bisected fraction at
/// which it does not. `None` when they already overlap so at the start or never do along
/// the motion, or when `fixed` is a chain piece the moving shape's centroid starts behind
/// or skims (see the early out in the body).
pub fn first_contact(fixed: &Shape, xf_fixed: Transform, moving: &Shape, sweep: &Sweep) -> Option<f32> {
    // A chain piece lets through what starts behind it, and is not worth a search for a
    // shape that moves along it: Box2D's early out (its continuous query callback), a
    // centroid that approaches by less than a quarter of the shape's thickness and ends
    // more than that in front; any overlap then is shallow and the next step's contact
    // takes it.
    if let Shape::ChainSegment(c) = fixed {
        let (normal, local_centroid) = (c.normal(), moving.centroid());
        let offset = |t: f32| {
            let centroid = xf_fixed.inv_apply(sweep.at(t).apply(local_centroid));
            normal.dot(centroid - c.segment.point1)
        };
        let (start, end) = (offset(0.0), offset(1.0));
        let core = 0.25 * moving.min_extent();
        if start < 0.0 || (start - end < core && end > core) {
            return None;
        }
    }
    if overlap(fixed, xf_fixed, moving, sweep.at(0.0)) {
        return None;
    }
    let travel = sweep.travel(moving.max_extent(sweep.local_center));
    let step = (0.5 * moving.min_extent()).max(super::LINEAR_SLOP);
    let samples = if travel.is_finite() {
        ((travel / step).ceil() as u32).clamp(1, MAX_SAMPLES)
    } else {
        1
    };
    let mut free = 0.0f32;
    for k in 1..=samples {
        let t = k as f32 / samples as f32;
        if !overlap(fixed, xf_fixed, moving, sweep.at(t)) {
            free = t;
            continue;
        }
        let mut hit = t;
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (free + hit);
            if overlap(fixed, xf_fixed, moving, sweep.at(mid)) {
                hit = mid;
            } else {
                free = mid;
            }
        }
        return Some(free);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Polygon, Segment, LINEAR_SLOP};

    fn block() -> Shape {
        Shape::Polygon(Polygon::new_box(0.25, 0.25).unwrap())
    }

    fn straight(c0: Vec2, c1: Vec2) -> Sweep {
        Sweep {
            local_center: Vec2::ZERO,
            c0,
            c1,
            q0: Rot::IDENTITY,
            q1: Rot::IDENTITY,
        }
    }

    /// A box moving 3 m down onto a wall whose top is at y = 0: it first touches when its
    /// bottom (0.25 m below the centre) reaches the top, at t = (2 − 0.25) / 3; the pose
    /// returned is apart and within a bisection step of touching.
    #[test]
    fn a_box_driven_into_a_wall_stops_at_its_surface() {
        let wall = Shape::Polygon(Polygon::new_box(5.0, 1.0).unwrap());
        let xf_wall = Transform::new(Vec2::new(0.0, -1.0), 0.0);
        let sweep = straight(Vec2::new(0.3, 2.0), Vec2::new(0.3, -1.0));
        let t = first_contact(&wall, xf_wall, &block(), &sweep).expect("it hits the wall");
        let expected = (1.75 + LINEAR_SLOP) / 3.0;
        assert!(t <= expected && expected - t < 1e-3, "t = {t}, expected {expected}");
        let gap = sweep.at(t).p.y - 0.25;
        assert!((-LINEAR_SLOP..-LINEAR_SLOP + 3e-3).contains(&gap), "gap {gap} m");
    }

    /// A thin segment crossed at 30 half-thicknesses per step is still found (the samples
    /// are half the box's thickness apart); a motion that stops short of the segment, one
    /// that starts overlapping it and one that misses it sideways give no contact.
    #[test]
    fn thin_walls_are_not_passed_and_misses_are_misses() {
        let seg = Shape::Segment(Segment {
            point1: Vec2::new(-1.0, 0.0),
            point2: Vec2::new(1.0, 0.0),
        });
        let xf = Transform::new(Vec2::ZERO, 0.0);
        let through = straight(Vec2::new(0.0, 4.0), Vec2::new(0.0, -3.5));
        let t = first_contact(&seg, xf, &block(), &through).expect("crosses the segment");
        assert!((t - (3.75 + LINEAR_SLOP) / 7.5).abs() < 1e-3, "t = {t}");
        let short = straight(Vec2::new(0.0, 4.0), Vec2::new(0.0, 0.3));
        assert_eq!(first_contact(&seg, xf, &block(), &short), None);
        let inside = straight(Vec2::new(0.0, 0.1), Vec2::new(0.0, -3.0));
        assert_eq!(first_contact(&seg, xf, &block(), &inside), None);
        let beside = straight(Vec2::new(2.0, 4.0), Vec2::new(2.0, -3.0));
        assert_eq!(first_contact(&seg, xf, &block(), &beside), None);
    }

    /// A plank turning about its centre sweeps its end through a post: the turn alone (no
    /// straight motion) is sampled and the contact found before the overlap.
    #[test]
    fn a_turning_plank_hits_a_post() {
        let plank = Shape::Polygon(Polygon::new_box(2.0, 0.1).unwrap());
        let post = Shape::Polygon(Polygon::new_box(0.1, 0.1).unwrap());
        let xf_post = Transform::new(Vec2::new(1.1, 1.1), 0.0);
        let sweep = Sweep {
            local_center: Vec2::ZERO,
            c0: Vec2::ZERO,
            c1: Vec2::ZERO,
            q0: Rot::IDENTITY,
            q1: Rot::from_angle(1.2),
        };
        let t = first_contact(&post, xf_post, &plank, &sweep).expect("the plank's end meets the post");
        assert!(t > 0.0 && t < 1.0);
        let xf = sweep.at(t);
        let m = collide(&post, xf_post, &plank, xf, 0.01);
        let closest = m.points[..m.count]
            .iter()
            .map(|p| p.separation)
            .fold(f32::MAX, f32::min);
        assert!(
            m.count > 0 && (-LINEAR_SLOP..0.0).contains(&closest),
            "closest {closest}"
        );
    }
}
