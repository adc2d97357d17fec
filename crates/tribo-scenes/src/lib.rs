//! The scene library of Tribo: scene builders and the analytic validation experiments.
//!
//! One library shared by the engine's tests, the `tribo` command, the benchmarks and
//! (later) the bindings and the testbed, so each experiment exists once.
//!
//! - [`build`]: small helpers that put grounds, slopes, boxes and disks into a world.
//! - [`format`]: the JSON scene format (parse with error locations, validate, build).
//! - [`scenes`]: the built-in scenes, each a [`format::SceneFile`].
//! - [`validation`]: the textbook friction and contact experiments; each returns
//!   [`validation::Check`]s (formula, expected, measured, tolerance) that tests assert
//!   and the CLI prints.

pub mod build;
pub mod format;
mod locate;
pub mod scenes;
pub mod validation;
