//! Dynamics: bodies, the shapes attached to them, materials with their combine rules, and
//! joints.
//!
//! Pipeline stage: data of the step (integration happens in [`crate::solver`]).

pub(crate) mod body;
pub(crate) mod joint;
pub(crate) mod material;
pub(crate) mod shape;

pub use body::{BodyDef, BodyType};
pub use joint::RevoluteJointDef;
pub use material::{mix, CombineRule, Material, MixedMaterial};
pub use shape::{Filter, ShapeDef};
