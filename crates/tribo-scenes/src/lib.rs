//! The scene library of Tribo: scene builders and the analytic validation experiments.
//!
//! One library shared by the engine's tests, the `tribo` command, the benchmarks and
//! (later) the bindings and the testbed, so each experiment exists once.
//!
//! - [`build`]: small helpers that put grounds, slopes, boxes and disks into a world.
//! - [`validation`]: the textbook friction and contact experiments; each returns
//!   [`validation::Check`]s (formula, expected, measured, tolerance) that tests assert
//!   and the CLI prints.

pub mod build;
pub mod validation;
