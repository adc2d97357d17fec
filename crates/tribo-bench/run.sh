#!/usr/bin/env bash
# Runs the Tribo / Box2D v3 / Rapier benchmark.
#
# Box2D is compiled by boxdd-sys (cc crate) with -O2 and without NDEBUG by default; the cc
# crate appends $CFLAGS after its own flags, so CFLAGS="-O3 -DNDEBUG" gives a Release build
# of Box2D (asserts off). A crates/tribo-bench/.cargo/config.toml would not be read when
# cargo is run from /work/main, hence the variable here.
#
# It builds into its own target directory: the CFLAGS change Box2D's build, and a separate
# directory keeps that build apart from the workspace's (and from the tests' smoke build).
#
# Usage: crates/tribo-bench/run.sh [SCENE|all] [--runs R] [--steps N] [--threads T] [--json FILE] [--profile]
#        crates/tribo-bench/run.sh scaling [--sizes 1000,4000,16000,64000] [--runs R] [--large-runs R64] [--steps N] [--json FILE]
# (SCENE: large_pyramid, many_pyramids, smash, tumbler, scaling_rain_<n>; every argument is passed to the program.)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
export CFLAGS="${CFLAGS:--O3 -DNDEBUG}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$here/../../target/bench}"
exec cargo run --release -p tribo-bench --manifest-path "$here/../../Cargo.toml" -- "$@"
