//! Pure geometry: shapes, convex hull, mass properties, bounding boxes, ray casts and
//! contact manifolds. Imports only [`crate::math`]; usable without a world.
//!
//! Pipeline stage: narrow phase (called by [`crate::collision`]). Conventions: polygons are
//! counter-clockwise; a manifold normal points from shape A to shape B; negative separation
//! means overlap.
//!
//! Comparisons are often written negated (`if !(sep < spec) { return }`) on purpose: a NaN
//! then takes the early exit instead of producing a contact.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod hull;
mod manifold;
mod mass;
mod raycast;
mod shapes;
mod sweep;

pub use hull::convex_hull;
pub(crate) use manifold::collide_bounded_into;
pub use manifold::{collide, collide_after, Manifold, ManifoldPoint, MAX_MANIFOLD_POINTS};
pub use mass::MassData;
pub use raycast::{RayCastInput, RayHit};
pub use shapes::{Capsule, ChainSegment, Circle, Polygon, Segment, Shape, MAX_POLYGON_VERTICES};
pub(crate) use sweep::{first_contact, Sweep};

use core::fmt;

/// What is wrong with a shape description.
#[derive(Clone, Debug, PartialEq)]
pub enum GeometryError {
    /// A coordinate or size is NaN or infinite; names the field.
    NonFinite(&'static str),
    /// A size that must be positive is zero or negative; names the field and the value.
    NonPositive(&'static str, f32),
    /// A size that must not be negative is negative; names the field and the value.
    Negative(&'static str, f32),
    /// A polygon needs at least 3 distinct points that are not all on one line.
    DegeneratePolygon(String),
    /// More points than a polygon can hold after hulling.
    TooManyVertices(usize),
    /// Two points that must differ (segment, capsule) coincide.
    DegenerateSegment(&'static str),
    /// A chain needs more points (a loop 3, an open chain 2).
    TooFewPoints {
        /// Points needed.
        needed: usize,
        /// Points given.
        got: usize,
    },
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GeometryError::NonFinite(what) => write!(f, "{what} must be finite (got NaN or infinity)"),
            GeometryError::NonPositive(what, v) => write!(f, "{what} must be positive (got {v})"),
            GeometryError::Negative(what, v) => write!(f, "{what} must not be negative (got {v})"),
            GeometryError::DegeneratePolygon(why) => write!(f, "degenerate polygon: {why}"),
            GeometryError::TooManyVertices(n) => write!(
                f,
                "polygon hull has {n} vertices; at most {MAX_POLYGON_VERTICES} are supported"
            ),
            GeometryError::DegenerateSegment(what) => write!(f, "{what}: the two points coincide"),
            GeometryError::TooFewPoints { needed, got } => {
                write!(f, "a chain needs at least {needed} points (got {got})")
            }
        }
    }
}

impl std::error::Error for GeometryError {}

/// Length below which points are considered the same [m] (Box2D's linear slop, 5 mm).
pub const LINEAR_SLOP: f32 = 0.005;

/// Manifold points are kept while their separation is below this distance [m]
/// (speculative contacts; 4 × [`LINEAR_SLOP`] as in Box2D v3).
pub const SPECULATIVE_DISTANCE: f32 = 4.0 * LINEAR_SLOP;
