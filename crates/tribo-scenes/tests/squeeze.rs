//! Regression: bodies squeezed by a motor of unbounded torque must not blow the pile up.
//!
//! Box2D v3's spinner (a 40 m rotor on a revolute motor at 5 rad/s with `f32::MAX` torque,
//! 6 076 bodies in a ring) with every μs raised to 1.5 μd: bodies the rotor pressed into
//! the wall kept the preload of that squeeze after it ended (40–50 N·s on 0.1 kg bodies),
//! which kept pushing them apart at tens of m/s; at step 335 one body reached 4·10⁵ m/s and
//! the next step every state overflowed (the rotor frozen, ~1 000 bodies reported
//! non-finite). A preload is now dropped once its point carries less than half of it.
//!
//! Then (the wall then made of quads 1 m thick) impacts seeded the next preloads with their bounce
//! impulses: a chain reaction that overflowed every state by step 71. A point that bounced
//! now seeds no preload.
//!
//! Checked over 360 steps (the first blow-up came at 335): no body ever reported
//! non-finite, every body centre within 40.5 m of the ring centre at the end (the ring, a
//! one-sided chain, plus the margin of the benchmark's spinner check: a body whose centre
//! crossed the chain falls out of the world), and the rotor turning at its motor's 5 rad/s
//! within 1 %.

use tribo::Vec2;
use tribo_scenes::format::MaterialRef;
use tribo_scenes::scenes;

#[test]
fn spinner_with_static_friction_above_dynamic_does_not_blow_up() {
    let mut scene = scenes::spinner();
    for b in &mut scene.bodies {
        for s in &mut b.shapes {
            if let Some(MaterialRef::Inline(m)) = &mut s.material {
                let mu = m.friction.take().unwrap_or(0.6);
                m.friction_static = Some(1.5 * mu);
                m.friction_dynamic = Some(mu);
            }
        }
    }
    let built = scene.build().expect("scene builds");
    let mut world = built.world;
    for step in 0..360 {
        world.step(built.dt).expect("step");
        assert!(
            world.non_finite_bodies().is_empty(),
            "step {step}: {} bodies non-finite",
            world.non_finite_bodies().len()
        );
    }
    let c = Vec2::new(scenes::SPINNER_CENTER[0], scenes::SPINNER_CENTER[1]);
    let outside = built.bodies[2..]
        .iter()
        .filter(|&&id| (world.body_position(id).unwrap() - c).length() >= scenes::SPINNER_RADIUS + 0.5)
        .count();
    assert_eq!(outside, 0, "bodies out of the ring");
    let w = world.body_angular_velocity(built.bodies[1]).unwrap();
    assert!(
        (w - scenes::SPINNER_MOTOR_SPEED).abs() < 0.01 * scenes::SPINNER_MOTOR_SPEED,
        "rotor at {w} rad/s"
    );
}
