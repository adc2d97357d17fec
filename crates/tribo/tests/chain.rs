//! Chains (one-sided segments smoothed by ghost vertices) in a running world.

use tribo::{BodyDef, ChainSegment, Circle, Material, Polygon, Shape, ShapeDef, Vec2, World, WorldDef};

const DT: f32 = 1.0 / 60.0;

/// Flat ground y = 0 from x = 10 to x = −10 as a chain of `pieces` pieces (points right to
/// left: the pieces face up), with friction `mu`.
fn chain_ground(world: &mut World, pieces: usize, mu: f32) {
    let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let points: Vec<Vec2> = (0..=pieces)
        .map(|i| Vec2::new(10.0 - 20.0 * i as f32 / pieces as f32, 0.0))
        .collect();
    let def = ShapeDef {
        material: Material::with_friction(mu),
        ..ShapeDef::default()
    };
    for piece in ChainSegment::chain(&points, false).unwrap() {
        world.create_shape(g, &def, &Shape::ChainSegment(piece)).unwrap();
    }
}

/// A box sliding over 200 pieces of 10 cm stops where Coulomb friction puts it,
/// d = v0² / (2 μ g) = 4² / (2 · 0.3 · 9.81) = 2.718 m, within 2 % (the step's
/// semi-implicit integration is off by about v0·dt/2 = 3 cm, 1.2 %), and crosses the 27
/// joints on its way without a bump: its vertical speed stays under 2 cm/s and its turn
/// rate under 0.05 rad/s at every step (a catch on a joint's vertex would show as a jump
/// in both, or as an early stop).
#[test]
fn a_box_slides_over_many_pieces_to_the_coulomb_distance() {
    let mut world = World::new(WorldDef::default()).unwrap();
    chain_ground(&mut world, 200, 0.3);
    let b = world
        .create_body(&BodyDef {
            linear_velocity: Vec2::new(4.0, 0.0),
            ..BodyDef::dynamic(Vec2::new(-8.05, 0.2))
        })
        .unwrap();
    let def = ShapeDef {
        material: Material::with_friction(0.3),
        ..ShapeDef::default()
    };
    world
        .create_shape(b, &def, &Shape::Polygon(Polygon::new_box(0.3, 0.2).unwrap()))
        .unwrap();
    let x0 = world.body_position(b).unwrap().x;
    for step in 0..150 {
        world.step(DT).unwrap();
        let v = world.body_linear_velocity(b).unwrap();
        let w = world.body_angular_velocity(b).unwrap();
        assert!(v.y.abs() < 0.02 && w.abs() < 0.05, "step {step}: v {v:?}, ω {w}");
    }
    let d = world.body_position(b).unwrap().x - x0;
    let expected = 4.0f32 * 4.0 / (2.0 * 0.3 * 9.81);
    assert!(
        (d - expected).abs() < 0.02 * expected,
        "slid {d} m, expected {expected} m"
    );
    assert!(world.body_linear_velocity(b).unwrap().length() < 1e-3, "at rest");
}

/// One-sided: a ball thrown up at 8 m/s from 1 m below the chain passes through it
/// (reaching about −1 + 8²/(2g) = 2.26 m), falls back onto its front side and rests there,
/// its centre one radius (0.25 m) above the chain within 1 cm.
#[test]
fn a_ball_passes_a_chain_from_behind_and_lands_on_its_front() {
    let mut world = World::new(WorldDef::default()).unwrap();
    chain_ground(&mut world, 40, 0.6);
    let b = world
        .create_body(&BodyDef {
            linear_velocity: Vec2::new(0.0, 8.0),
            ..BodyDef::dynamic(Vec2::new(0.3, -1.0))
        })
        .unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            &Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap()),
        )
        .unwrap();
    let mut top = f32::MIN;
    for _ in 0..240 {
        world.step(DT).unwrap();
        top = top.max(world.body_position(b).unwrap().y);
    }
    assert!(top > 2.0, "reached only {top} m");
    let y = world.body_position(b).unwrap().y;
    assert!((y - 0.25).abs() < 0.01, "rests at y {y} m");
}
