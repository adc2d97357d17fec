//! # Tribo: 2D rigid bodies whose contacts get friction right
//!
//! Impulse-based rigid-body dynamics (sequential impulses with accumulated clamping, warm
//! starting and sub-stepped soft contacts) with a true Coulomb friction model: every
//! material has a static coefficient μs and a dynamic coefficient μd. A contact point
//! *sticks* while the friction it needs stays within μs times its normal impulse and
//! *slides* with exactly μd times its normal impulse otherwise.
//!
//! ```
//! use tribo::{BodyDef, Material, Polygon, Shape, ShapeDef, Vec2, World, WorldDef};
//!
//! let mut world = World::new(WorldDef::default())?;
//! let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))?;
//! world.create_shape(ground, &ShapeDef::default(), &Shape::Polygon(Polygon::new_box(50.0, 1.0)?))?;
//! let crate_body = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)))?;
//! let wood = Material::default().friction(0.6, 0.4);
//! world.create_shape(crate_body, &ShapeDef::with_material(wood), &Shape::Polygon(Polygon::new_box(0.5, 0.5)?))?;
//! for _ in 0..60 {
//!     world.step(1.0 / 60.0)?;
//! }
//! let y = world.body_position(crate_body)?.y;
//! assert!((y - 0.5).abs() < 0.01);
//! # Ok::<(), tribo::Error>(())
//! ```
//!
//! ## Table of contents
//! - [`math`]: vectors, rotations, transforms, boxes.
//! - [`geometry`]: pure shapes, hull, mass, ray casts, contact manifolds.
//! - `collision`: dynamic AABB trees, broad phase, contact records (internal).
//! - `dynamics`: bodies, shapes, [`Material`] and [`CombineRule`], joints
//!   ([`RevoluteJointDef`]).
//! - `solver`: the soft step and the contact constraint with stick/slip friction
//!   (internal; its design is documented in `ARCHITECTURE.md`).
//! - [`World`]: creation, the step, events, queries.
//!
//! ## Units & conventions
//! - SI units: metres, kilograms, seconds, radians. 2D densities are kg/m², rotational
//!   inertia kg·m², impulses N·s, torques N·m.
//! - Angles are counter-clockwise; polygons are counter-clockwise.
//! - A contact normal points from shape A to shape B; negative separation means overlap.
//! - The friction tangent of a contact is `(n.y, −n.x)` (the normal turned clockwise).
//! - Every public call that takes user input validates it: NaN, infinity and out-of-range
//!   values return an [`Error`] and change nothing.
//! - Same scene, same build → bit-identical results (no hash-order iteration, no threads
//!   racing, no fused multiply-add).

#![warn(missing_docs)]

mod collision;
mod dynamics;
mod error;
pub mod geometry;
pub mod math;
mod solver;
mod world;

pub use collision::FrictionState;
pub use dynamics::joint::{DEFAULT_CONSTRAINT_DAMPING_RATIO, DEFAULT_CONSTRAINT_HERTZ};
pub use dynamics::{mix, BodyDef, BodyType, CombineRule, Filter, Material, MixedMaterial, RevoluteJointDef, ShapeDef};
pub use error::{Error, Result};
pub use geometry::{Capsule, ChainSegment, Circle, GeometryError, MassData, Polygon, Segment, Shape};
pub use math::{Aabb, Rot, Transform, Vec2};
pub use world::{
    BodyId, ContactBeginEvent, ContactEndEvent, ContactEvents, ContactInfo, ContactPointInfo, JointId, Profile,
    QueryFilter, RayResult, ShapeId, SolverLanes, World, WorldDef,
};

/// Contact constraints the wide solver handles at once in a world made with the default
/// [`SolverLanes::Auto`] on this CPU: 8 on an x86-64 CPU that has AVX2 (the solver is
/// compiled a second time for AVX2, and a third for AVX2 with AVX-512F/VL, into every
/// x86-64 build and chosen at run time, so a binary for the x86-64 baseline still runs
/// eight lanes there; Box2D's counterpart, `BOX2D_AVX2`, is a compile-time option), else 4
/// (SSE2, the x86-64 baseline, or arrays on other targets). [`solver_instructions`] says
/// which build.
///
/// Results do not depend on it: every lane computes the same expressions, and where a
/// group takes one branch for all its lanes (the one-point form of the normal rows, the
/// rolling row) the other branch adds only exact zeros, which can at most turn a velocity
/// of −0.0 into +0.0 (and the velocity integration makes every −0.0 +0.0 anyway, unless an
/// acceleration is −0.0). Worlds with every build step a scene to the same bits (a test
/// steps every library scene every way; `.ci/run` compares CLI trajectories).
pub fn solver_lanes() -> usize {
    solver::Contacts::new(SolverLanes::Auto).lanes()
}

/// The instructions the wide solver of a world made with the default [`SolverLanes::Auto`]
/// is compiled for on this CPU: "AVX-512VL" (eight lanes, with AVX2), "AVX2" (eight
/// lanes), "SSE2" (four lanes, on x86-64) or "portable" (four lanes, elsewhere).
pub fn solver_instructions() -> &'static str {
    solver::Contacts::new(SolverLanes::Auto).instructions()
}

/// The crate version and the wide solver [`solver_lanes`] picks on this CPU, e.g. `0.1.0
/// (solver: 8 lanes, AVX-512VL)`, `0.1.0 (solver: 8 lanes, AVX2)`, `0.1.0 (solver: 4
/// lanes, SSE2)` or, off x86-64, `0.1.0 (solver: 4 lanes, portable)` (what `tribo
/// --version` prints).
pub fn build_info() -> String {
    let solver = solver::Contacts::new(SolverLanes::Auto);
    format!(
        "{} (solver: {} lanes, {})",
        env!("CARGO_PKG_VERSION"),
        solver.lanes(),
        solver.instructions()
    )
}
