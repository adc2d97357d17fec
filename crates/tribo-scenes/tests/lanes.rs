//! The two builds of the wide contact solver in one binary (`tribo::SolverLanes`): eight
//! lanes (AVX2, what `Auto` takes on a CPU with AVX2) and four (SSE2). Every lane computes
//! the same expressions whatever the width, so a world gives bit-identical results with
//! either: this test steps every library scene both ways and compares every body's pose
//! and velocity to the bit (no tolerance: the promise is identity, and any reordering of
//! a sum would show in the last bit within a few steps of a pile). On a CPU without AVX2
//! both worlds run four lanes and the test says so (it then cannot fail on the width).

use tribo::{SolverLanes, World, WorldDef};
use tribo_scenes::scenes::SCENES;

/// Every body's pose and velocity, as raw bits, after `steps` steps (the scene's hook not
/// run: `.ci/run` compares hooked scenes through the CLI), and the world's lane count.
fn run(entry: &tribo_scenes::scenes::SceneEntry, lanes: SolverLanes, steps: u32) -> (Vec<u32>, usize) {
    let built = (entry.build)().build().expect("scene builds");
    let mut world: World = built.world;
    let def = WorldDef {
        solver_lanes: lanes,
        ..*world.def()
    };
    world.set_def(def).expect("lanes accepted");
    for _ in 0..steps {
        world.step(built.dt).expect("step");
    }
    (state_bits(&world, &built.bodies), world.solver_lanes())
}

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

#[test]
fn eight_and_four_lanes_step_every_scene_to_the_same_bits() {
    let auto = tribo::solver_lanes();
    if auto == 4 {
        eprintln!("this CPU has no AVX2: both worlds run four lanes");
    }
    for entry in SCENES {
        // Long enough for piles to settle (new contacts estimated, friction states
        // switching) and for the dynamic scenes to collide; the large benchmark scenes
        // fewer steps (each costs milliseconds).
        let steps = if entry.name.starts_with("scaling_rain") || entry.name == "many_pyramids" {
            40
        } else {
            120
        };
        let (wide, lanes_auto) = run(entry, SolverLanes::Auto, steps);
        let (four, lanes_four) = run(entry, SolverLanes::Four, steps);
        assert_eq!(
            (lanes_auto, lanes_four),
            (auto, 4),
            "{}: the worlds' lane counts",
            entry.name
        );
        let differ = wide.iter().zip(&four).filter(|(a, b)| a != b).count();
        assert!(
            differ == 0 && wide.len() == four.len(),
            "{}: {auto} lanes and 4 lanes differ in {differ} of {} values after {steps} steps",
            entry.name,
            wide.len()
        );
    }
}

/// Changing `WorldDef::solver_lanes` mid-run (a new solver, the contacts' colours kept)
/// changes no result either: a pyramid stepped with eight lanes, then four, then eight
/// again ends where one stepped with four throughout ends.
#[test]
fn switching_lanes_mid_run_changes_no_result() {
    let entry = SCENES.iter().find(|e| e.name == "pyramid").expect("pyramid scene");
    let (steady, _) = run(entry, SolverLanes::Four, 90);
    let built = (entry.build)().build().expect("scene builds");
    let mut world = built.world;
    for (lanes, steps) in [
        (SolverLanes::Auto, 30),
        (SolverLanes::Four, 30),
        (SolverLanes::Auto, 30),
    ] {
        let def = WorldDef {
            solver_lanes: lanes,
            ..*world.def()
        };
        world.set_def(def).expect("lanes accepted");
        for _ in 0..steps {
            world.step(built.dt).expect("step");
        }
    }
    let bits = state_bits(&world, &built.bodies);
    assert!(bits == steady, "switching lanes changed the pyramid's state");
}
