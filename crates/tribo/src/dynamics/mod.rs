//! Dynamics: bodies, the shapes attached to them, and materials with their combine rules.
//!
//! Pipeline stage: data of the step (integration happens in [`crate::solver`]).

pub(crate) mod body;
pub(crate) mod material;
pub(crate) mod shape;

pub use body::{BodyDef, BodyType};
pub use material::{mix, CombineRule, Material, MixedMaterial};
pub use shape::{Filter, ShapeDef};
