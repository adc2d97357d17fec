//! The wide contact solver with eight lanes, compiled for AVX2: the same source as
//! [`super::lanes4`]'s (`contact_set.rs`, `contact_wide.rs`), with the eight-lane types of
//! [`crate::math::wide8`], every function marked `#[super::lane_fn]` compiled with
//! `#[target_feature(enable = "avx2")]` (and the closures inside it with it), and the warm
//! start (`#[super::lane_inline]`) inlined into its colour loop, which took many_pyramids'
//! warm start from 1.35–1.41 ms to 1.04–1.10 with eight lanes.
//!
//! A function compiled for AVX2 runs only on a CPU that has it: the world takes this
//! build's [`contact_set::ContactSolver`] only after `is_x86_feature_detected!("avx2")`
//! ([`super::Contacts`]), and every call into it from code not compiled for AVX2 goes
//! through that solver's methods. On a CPU that also has AVX-512F/VL the world takes the
//! same source's third build instead, [`super::lanes8_avx512`] (its lane types are these).

/// The lane types of this build.
pub(crate) mod wide {
    pub(crate) use crate::math::wide::*;
    pub(crate) use crate::math::wide8::{lanes_to_rows8 as lanes_to_rows, rows_to_lanes8 as rows_to_lanes};
    pub(crate) use crate::math::wide8::{F8 as FL, M8 as ML, V8 as VL};
    /// Lanes per wide constraint.
    pub(crate) const LANES: usize = 8;
}

// The source's per-build attributes (see `tribo_lanes`).
#[cfg(test)]
pub(crate) use tribo_lanes::avx2_tests as lane_tests;
pub(crate) use tribo_lanes::{avx2 as lane_fn, avx2_inline as lane_inline};

// The same files as `lanes4`'s and `lanes8_avx512`'s, on purpose (one source, three builds).
#[path = "contact_wide.rs"]
#[allow(clippy::duplicate_mod)]
pub(crate) mod contact_wide;

#[path = "contact_set.rs"]
#[allow(clippy::duplicate_mod)]
pub(crate) mod contact_set;
