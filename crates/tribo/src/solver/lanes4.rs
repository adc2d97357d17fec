//! The wide contact solver with four lanes: SSE2 on x86-64 (the baseline every x86-64 CPU
//! has), arrays elsewhere. The same source as [`super::lanes8`]'s (`contact_set.rs`,
//! `contact_wide.rs`), compiled with the four-lane types and without extra target
//! features.

/// The lane types of this build ([`crate::math::wide`]'s four-lane ones).
pub(crate) mod wide {
    pub(crate) use crate::math::wide::*;
    pub(crate) use crate::math::wide::{transpose as rows_to_lanes, transpose as lanes_to_rows};
    pub(crate) use crate::math::wide::{F4 as FL, M4 as ML, V4 as VL};
    /// Lanes per wide constraint.
    pub(crate) const LANES: usize = 4;
}

// The source's per-build attributes: here every item stays as written.
#[cfg(test)]
pub(crate) use tribo_lanes::keep as lane_tests;
pub(crate) use tribo_lanes::{keep as lane_fn, keep as lane_inline};

#[path = "contact_wide.rs"]
pub(crate) mod contact_wide;

#[path = "contact_set.rs"]
pub(crate) mod contact_set;
