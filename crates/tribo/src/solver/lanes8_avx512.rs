//! The wide contact solver with eight lanes, compiled for AVX2 and AVX-512F/VL: the same
//! source and lane types as [`super::lanes8`]'s (256-bit vectors), every `#[super::lane_fn]`
//! compiled with `#[target_feature(enable = "avx2,avx512f,avx512vl")]`. With AVX-512VL the
//! compiler has 32 vector registers instead of 16 (the solve passes spilled to the stack
//! with 16) and AVX-512VL's instructions on 256-bit vectors; it computes the same
//! expressions (no fused multiply-adds: Rust does not contract `a * b + c`), so the results
//! are those of the other builds to the bit (tests/threads.rs steps every library scene
//! with each build). On the benchmark machine (an Xeon with AVX-512, 2026-12-06) it took
//! large_pyramid's step from 2.42–2.50 ms to 2.29–2.36 and the tumbler's from 1.50–1.55 to
//! 1.40–1.45 (`tribo-bench SCENE --profile`, alternated).
//!
//! A function compiled for AVX-512 runs only on a CPU that has it: the world takes this
//! build's [`contact_set::ContactSolver`] only after `is_x86_feature_detected!` of AVX2,
//! AVX-512F and AVX-512VL (and what the compiler takes AVX-512F to imply, FMA and F16C;
//! `super::avx512_build_pays`), and every call into it from code not compiled for these
//! goes through that solver's methods. The lanes stay 256 bits wide, but the compiler
//! writes some copies of records and some loops with 512-bit registers (moves mostly, a
//! few multiplications and additions), and the cores before Ice Lake lower their clock
//! for those: `Auto` takes this build only on a CPU with AVX-512 VBMI2 (Ice Lake, Zen 4
//! and later), the AVX2 one elsewhere.

/// The lane types of this build: the eight-lane build's.
pub(crate) use super::lanes8::wide;

// The source's per-build attributes (see `tribo_lanes`).
#[cfg(test)]
pub(crate) use tribo_lanes::avx512_tests as lane_tests;
pub(crate) use tribo_lanes::{avx2_inline as lane_inline, avx512 as lane_fn};

// The same files as `lanes4`'s and `lanes8`'s, on purpose (one source, three builds).
#[path = "contact_wide.rs"]
#[allow(clippy::duplicate_mod)]
pub(crate) mod contact_wide;

#[path = "contact_set.rs"]
#[allow(clippy::duplicate_mod)]
pub(crate) mod contact_set;
