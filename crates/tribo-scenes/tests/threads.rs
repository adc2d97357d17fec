//! Determinism across thread counts: a step split between worker threads must give
//! bit-identical results to the single-threaded step (WorldDef::workers' promise). The
//! scenes mix resting stacks (many graph colours, new contacts estimated on the first
//! step), sliding, rolling, bouncing and a kinematic body, so every parallel stage runs.

use tribo::{World, WorldDef};
use tribo_scenes::scenes;

/// Every body's pose and velocity, as raw bits, after `steps` steps with `workers` threads.
fn run(build: fn() -> tribo_scenes::format::SceneFile, workers: u32, steps: u32) -> Vec<u32> {
    let built = build().build().expect("scene builds");
    let mut world: World = built.world;
    let def = WorldDef {
        workers,
        ..*world.def()
    };
    world.set_def(def).expect("workers accepted");
    for _ in 0..steps {
        world.step(built.dt).expect("step");
    }
    let mut bits = Vec::new();
    for &id in &built.bodies {
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

#[test]
fn two_and_three_workers_match_one_bit_for_bit() {
    // (scene, steps): long enough for contacts to begin, end, slide and sleep.
    let cases: [(fn() -> tribo_scenes::format::SceneFile, u32); 5] = [
        (scenes::pyramid, 120),
        (scenes::dominoes, 150),
        (scenes::tumbler, 150),
        (scenes::bounce, 150),
        (scenes::card_house, 90),
    ];
    for (build, steps) in cases {
        let one = run(build, 1, steps);
        for workers in [2, 3] {
            let many = run(build, workers, steps);
            assert!(
                one == many,
                "{workers} workers differ from 1 worker in {} of {} values",
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
