//! The one error type of the public API.

use crate::geometry::GeometryError;
use crate::world::{BodyId, JointId, ShapeId};
use core::fmt;

/// Everything that can go wrong in a public call. A call that returns an error changes
/// nothing in the world.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// The body id is stale (the body was destroyed) or was never issued by this world.
    InvalidBody(BodyId),
    /// The shape id is stale (the shape or its body was destroyed) or was never issued.
    InvalidShape(ShapeId),
    /// The joint id is stale (the joint or one of its bodies was destroyed) or was never
    /// issued.
    InvalidJoint(JointId),
    /// An argument is out of range or not finite.
    InvalidArgument {
        /// Which argument or field, e.g. `"BodyDef::position"`.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A shape's geometry is degenerate or not finite.
    Geometry(GeometryError),
}

impl Error {
    /// Shorthand for [`Error::InvalidArgument`].
    pub(crate) fn arg(name: &'static str, reason: impl Into<String>) -> Error {
        Error::InvalidArgument {
            name,
            reason: reason.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidBody(id) => write!(
                f,
                "body id (index {}, generation {}) is stale or was never created",
                id.index, id.generation
            ),
            Error::InvalidShape(id) => write!(
                f,
                "shape id (index {}, generation {}) is stale or was never created",
                id.index, id.generation
            ),
            Error::InvalidJoint(id) => write!(
                f,
                "joint id (index {}, generation {}) is stale or was never created",
                id.index, id.generation
            ),
            Error::InvalidArgument { name, reason } => write!(f, "{name}: {reason}"),
            Error::Geometry(e) => write!(f, "invalid shape geometry: {e}"),
        }
    }
}

impl std::error::Error for Error {}

impl From<GeometryError> for Error {
    fn from(e: GeometryError) -> Self {
        Error::Geometry(e)
    }
}

/// Result alias of the public API.
pub type Result<T> = core::result::Result<T, Error>;

/// Checks that a number is finite.
pub(crate) fn check_finite(name: &'static str, v: f32) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::arg(name, format!("must be finite (got {v})")))
    }
}

/// Checks that a vector is finite.
pub(crate) fn check_vec(name: &'static str, v: crate::math::Vec2) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::arg(name, format!("must be finite (got ({}, {}))", v.x, v.y)))
    }
}

/// Checks that a number is finite and ≥ 0.
pub(crate) fn check_non_negative(name: &'static str, v: f32) -> Result<()> {
    check_finite(name, v)?;
    if v < 0.0 {
        return Err(Error::arg(name, format!("must not be negative (got {v})")));
    }
    Ok(())
}

/// Checks that a number is finite and > 0.
pub(crate) fn check_positive(name: &'static str, v: f32) -> Result<()> {
    check_finite(name, v)?;
    if v <= 0.0 {
        return Err(Error::arg(name, format!("must be positive (got {v})")));
    }
    Ok(())
}
