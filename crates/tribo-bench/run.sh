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
# Usage: [AVX2=1 | BOX2D_AVX2=1] [TRIBO_BENCH_LANES=4|8] crates/tribo-bench/run.sh [SCENE|all] [--runs R] [--steps N] [--threads T] [--json FILE] [--profile]
#        crates/tribo-bench/run.sh scaling [--sizes 1000,4000,16000,64000] [--runs R] [--large-runs R64] [--steps N] [--json FILE]
# (SCENE: large_pyramid, many_pyramids, smash, tumbler, scaling_rain_<n>; every argument is passed to the program.)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
export CFLAGS="${CFLAGS:--O3 -DNDEBUG}"
# Tribo's wide solver is compiled three ways into every x86-64 binary and runs eight lanes
# on a CPU that has AVX2 (tribo::SolverLanes::Auto), compiled for AVX-512VL where the CPU
# has it (Ice Lake's generation or later), else for AVX2; TRIBO_BENCH_LANES=8 makes its
# worlds run the AVX2 build (like for like against BOX2D_AVX2=1), TRIBO_BENCH_LANES=4 four
# lanes (SSE2), e.g. for the like-for-like run against Box2D's default build.
# BOX2D_AVX2=1 builds Box2D with its eight-lane AVX2 path (BOX2D_AVX2, boxdd's simd-avx2:
# the `box2d-avx2` feature), off by default as in Box2D's CMake build; the binary then
# needs a CPU with AVX2. AVX2=1 does that and compiles the whole Rust build for AVX2 too
# (Rapier included), in a target directory of their own.
features=()
if [[ "${AVX2:-0}" == 1 ]]; then
    # (The whole build: Rapier is compiled for AVX2 too; CARGO_ENCODED_RUSTFLAGS would
    # override RUSTFLAGS.)
    unset CARGO_ENCODED_RUSTFLAGS
    export RUSTFLAGS="${RUSTFLAGS:-} -C target-feature=+avx2"
    features=(--features box2d-avx2)
    export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$here/../../target/bench-avx2-both}"
elif [[ "${BOX2D_AVX2:-0}" == 1 ]]; then
    features=(--features box2d-avx2)
    export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$here/../../target/bench-avx2}"
fi
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$here/../../target/bench}"
exec cargo run --release -p tribo-bench ${features[@]+"${features[@]}"} --manifest-path "$here/../../Cargo.toml" -- "$@"
