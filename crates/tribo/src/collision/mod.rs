//! Collision: the broad phase (dynamic AABB trees, pair finding), contact records and the
//! narrow-phase update that fills their manifolds.
//!
//! Pipeline stage: first in the step. Neighbours: [`crate::geometry`] computes manifolds;
//! [`crate::solver`] consumes touching contacts.

pub(crate) mod broad_phase;
pub(crate) mod contact;
pub(crate) mod sweep_prune;
pub(crate) mod tree;

pub use contact::FrictionState;
