//! Determinism across thread counts and solver builds: a step split between worker threads
//! must give bit-identical results to the single-threaded step (WorldDef::workers'
//! promise), and the wide solver's eight-lane builds (AVX2, and AVX2 with AVX-512VL, what
//! `SolverLanes::Auto` takes on a CPU with those) the same results as its four-lane one
//! (WorldDef::solver_lanes' promise). The scenes mix resting stacks (many graph colours, new contacts estimated on
//! the first step), sliding, rolling, bouncing and a kinematic body, so every parallel
//! stage runs.

use tribo::{SolverLanes, World, WorldDef};
use tribo_scenes::scenes::{self, SCENES};

/// Every body's pose and velocity, as raw bits.
fn state_bits(world: &World, bodies: &[tribo::BodyId]) -> Vec<u32> {
    let mut bits = Vec::new();
    for &id in bodies {
        let p = world.body_position(id).unwrap();
        let v = world.body_linear_velocity(id).unwrap();
        bits.extend(
            [
                p.x,
                p.y,
                world.body_angle(id).unwrap(),
                v.x,
                v.y,
                world.body_angular_velocity(id).unwrap(),
            ]
            .map(f32::to_bits),
        );
    }
    bits
}

/// The world's settings with `workers` threads and `lanes`.
fn with(world: &mut World, workers: u32, lanes: SolverLanes) {
    let def = WorldDef {
        workers,
        solver_lanes: lanes,
        ..*world.def()
    };
    world.set_def(def).expect("settings accepted");
}

/// [`state_bits`] after `steps` steps with `workers` threads and `lanes` (the scene's step
/// hook not run: `.ci/run` compares hooked scenes through the CLI), the world's lane count
/// and the instructions its solver build is compiled for.
fn run_with(
    build: fn() -> tribo_scenes::format::SceneFile,
    workers: u32,
    lanes: SolverLanes,
    steps: u32,
) -> (Vec<u32>, usize, &'static str) {
    let built = build().build().expect("scene builds");
    let mut world: World = built.world;
    with(&mut world, workers, lanes);
    for _ in 0..steps {
        world.step(built.dt).expect("step");
    }
    (
        state_bits(&world, &built.bodies),
        world.solver_lanes(),
        world.solver_instructions(),
    )
}

/// [`state_bits`] after `steps` steps with `workers` threads.
fn run(build: fn() -> tribo_scenes::format::SceneFile, workers: u32, steps: u32) -> Vec<u32> {
    run_with(build, workers, SolverLanes::Auto, steps).0
}

#[test]
fn two_and_three_workers_match_one_bit_for_bit() {
    // (scene, steps): long enough for contacts to begin, end, slide and sleep.
    // (large_pyramid: enough groups per colour for the solver's worker team on two
    // threads, which the smaller scenes, and it on three, leave to one thread;
    // joint_grid: enough blocks of joints per colour to share its joint passes.)
    let cases: [(fn() -> tribo_scenes::format::SceneFile, u32); 7] = [
        (scenes::large_pyramid, 40),
        (scenes::joint_grid, 20),
        (scenes::pyramid, 120),
        (scenes::dominoes, 150),
        (scenes::tumbler, 150),
        (scenes::bounce, 150),
        (scenes::card_house, 90),
    ];
    for (build, steps) in cases {
        let one = run(build, 1, steps);
        for (workers, lanes) in [
            (2, SolverLanes::Auto),
            (3, SolverLanes::Auto),
            (2, SolverLanes::Eight),
            (2, SolverLanes::Four),
        ] {
            // (Eight and four lanes on two threads: on a CPU with AVX-512 the default runs
            // that build, and the others' team loops would go untested.)
            let (many, _, _) = run_with(build, workers, lanes, steps);
            assert!(
                one == many,
                "{workers} workers ({lanes:?} lanes) differ from 1 worker in {} of {} values",
                one.iter().zip(&many).filter(|(a, b)| a != b).count(),
                one.len()
            );
        }
        // The scene really moved (a test that cannot fail would prove nothing).
        let start = run(build, 1, 0);
        assert_ne!(start, one, "scene did not change in {steps} steps");
    }
}

#[test]
fn workers_out_of_range_are_rejected_and_change_nothing() {
    let mut world = World::new(WorldDef::default()).unwrap();
    for bad in [0, 257] {
        let err = world
            .set_def(WorldDef {
                workers: bad,
                ..WorldDef::default()
            })
            .unwrap_err();
        assert!(err.to_string().contains("workers"), "{err}");
        assert_eq!(world.def().workers, 1);
    }
    assert!(World::new(WorldDef {
        workers: 0,
        ..WorldDef::default()
    })
    .is_err());
}

/// Every build of the wide solver steps every library scene to the same bits: eight lanes
/// for AVX-512VL (`Auto` on a CPU with it), eight for AVX2 (`Eight`) and four (`Four`).
/// Every lane computes the same expressions whatever the width and the instructions (no
/// tolerance: the promise is identity, and any reordering of a sum would show in the last
/// bit within a few steps of a pile). On a CPU without AVX-512 `Auto` and `Eight` run the
/// same build, and without AVX2 all three run four lanes; the test says so (it then cannot
/// fail on what the CPU lacks). Checked by mutation: with the eight-lane subtraction made
/// an addition it fails on the first scene.
#[test]
fn every_solver_build_steps_every_scene_to_the_same_bits() {
    let (auto, instructions) = (tribo::solver_lanes(), tribo::solver_instructions());
    // `Auto` takes eight lanes exactly where the CPU has AVX2, compiled for AVX-512VL
    // exactly where it also has AVX-512F and VL, what the compiler takes those to imply
    // (FMA, F16C), and AVX-512 VBMI2 (Ice Lake's generation or later).
    #[cfg(target_arch = "x86_64")]
    {
        let avx2 = std::is_x86_feature_detected!("avx2");
        let avx512 = avx2
            && std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512vl")
            && std::is_x86_feature_detected!("fma")
            && std::is_x86_feature_detected!("f16c")
            && std::is_x86_feature_detected!("avx512vbmi2");
        assert_eq!(auto == 8, avx2, "lanes taken: {auto}");
        assert_eq!(instructions == "AVX-512VL", avx512, "build taken: {instructions}");
    }
    if auto == 4 {
        eprintln!("this CPU has no AVX2: all the worlds run four lanes");
    } else if instructions != "AVX-512VL" {
        eprintln!("this CPU has no AVX-512VL: `Auto` and `Eight` run the same build");
    }
    for entry in SCENES {
        // Long enough for piles to settle (new contacts estimated, friction states
        // switching) and for the dynamic scenes to collide; the largest scenes fewer steps
        // (each costs milliseconds).
        let steps = if entry.name.starts_with("scaling_rain") || entry.name == "many_pyramids" {
            40
        } else {
            120
        };
        let (wide, lanes_auto, built_auto) = run_with(entry.build, 1, SolverLanes::Auto, steps);
        let (eight, lanes_eight, built_eight) = run_with(entry.build, 1, SolverLanes::Eight, steps);
        let (four, lanes_four, built_four) = run_with(entry.build, 1, SolverLanes::Four, steps);
        // `Eight` takes the AVX2 build wherever there are eight lanes, whatever `Auto` takes.
        let eight_build = if auto == 8 { "AVX2" } else { built_four };
        assert_eq!(
            (lanes_auto, lanes_eight, lanes_four, built_auto, built_eight),
            (auto, auto, 4, instructions, eight_build),
            "{}: the worlds' lane counts and builds",
            entry.name
        );
        // The scene really moved (else the comparison would prove nothing), but for one
        // whose moving bodies all come from its step hook (rain: only its static shelves
        // are the scene's own; `.ci/run` compares it through the CLI, hook and all).
        let (start, _, _) = run_with(entry.build, 1, SolverLanes::Four, 0);
        assert!(
            start != four || entry.name == "rain",
            "{}: nothing moved in {steps} steps",
            entry.name
        );
        for (build, state) in [(instructions, &wide), ("Eight (AVX2)", &eight)] {
            let differ = state.iter().zip(&four).filter(|(a, b)| a != b).count();
            assert!(
                differ == 0 && state.len() == four.len(),
                "{}: {auto} lanes ({build}) and 4 lanes differ in {differ} of {} values after {steps} steps",
                entry.name,
                state.len()
            );
        }
    }
}

/// Changing `WorldDef::solver_lanes` mid-run (a new solver; the contacts keep their colours)
/// changes no result either: the tumbler (its turning drum keeps every box awake and
/// moving), once its boxes pile up in the drum, stepped with `Auto`'s build, then four lanes
/// (on two threads), then eight for AVX2, then `Auto`'s again, ends where one stepped with
/// four throughout ends.
#[test]
fn switching_lanes_mid_run_changes_no_result() {
    let (steady, _, _) = run_with(scenes::tumbler, 1, SolverLanes::Four, 150);
    let built = scenes::tumbler().build().expect("scene builds");
    let mut world = built.world;
    let (auto, instructions) = (tribo::solver_lanes(), tribo::solver_instructions());
    let four = if cfg!(target_arch = "x86_64") {
        "SSE2"
    } else {
        "portable"
    };
    let eight = if auto == 8 { "AVX2" } else { four };
    for (steps, workers, lanes, expected) in [
        (90, 1, SolverLanes::Auto, (auto, instructions)),
        (30, 2, SolverLanes::Four, (4, four)),
        (20, 1, SolverLanes::Eight, (auto, eight)),
        (10, 1, SolverLanes::Auto, (auto, instructions)),
    ] {
        with(&mut world, workers, lanes);
        assert_eq!(
            (world.solver_lanes(), world.solver_instructions()),
            expected,
            "the switch to {lanes:?} took"
        );
        let before = state_bits(&world, &built.bodies);
        for _ in 0..steps {
            world.step(built.dt).expect("step");
        }
        assert_ne!(before, state_bits(&world, &built.bodies), "the tumbler stood still");
        // Contacts carried across the switch (the boxes reach the drum's floor by ~60 steps).
        assert!(world.contacts().count() > 100, "{} contacts", world.contacts().count());
    }
    assert!(
        state_bits(&world, &built.bodies) == steady,
        "switching lanes changed the tumbler's state"
    );
}
