//! Per-stage wall-clock times of the last step (like Box2D v3's `b2Profile`).

use std::time::Instant;

/// Wall-clock time [ms] of each stage of the last [`crate::World::step`]. Stages in order;
/// the solver stages are summed over the substeps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Profile {
    /// The whole step [ms].
    pub step: f32,
    /// Broad phase: new pairs from moved proxies; and the contacts' renumbering in a step
    /// that renumbers them [ms].
    pub pairs: f32,
    /// Narrow phase: manifolds, begin/end events [ms].
    pub collide: f32,
    /// Solver set-up: awake body states and contact constraints [ms].
    pub solver_setup: f32,
    /// Prepare: softness, new points' friction state, warm-start estimate, graph colouring
    /// and packing [ms].
    pub prepare: f32,
    /// Integrate velocities (all substeps) [ms].
    pub integrate_velocities: f32,
    /// Warm start (all substeps) [ms].
    pub warm_start: f32,
    /// Biased solve (all substeps) [ms].
    pub solve: f32,
    /// Integrate positions (all substeps) [ms].
    pub integrate_positions: f32,
    /// Relax solve and substep totals (all substeps) [ms].
    pub relax: f32,
    /// Restitution [ms].
    pub restitution: f32,
    /// Impulses and friction states stored into the contacts [ms].
    pub store: f32,
    /// Poses, fat boxes and sleep timers of the bodies [ms].
    pub finalize: f32,
    /// Islands and sleeping [ms].
    pub sleep: f32,
}

/// A running stopwatch: `lap` returns the milliseconds since the previous lap.
pub(crate) struct Stopwatch(Instant);

impl Stopwatch {
    pub fn start() -> Stopwatch {
        Stopwatch(Instant::now())
    }

    /// Milliseconds since the last lap (or the start), and restarts.
    pub fn lap(&mut self) -> f32 {
        let now = Instant::now();
        let ms = (now - self.0).as_secs_f64() * 1e3;
        self.0 = now;
        ms as f32
    }
}
