//! Builds a small scene (ground, a slope, boxes with static and dynamic friction, a ball)
//! and steps it for two seconds, printing where everything ends up.
//!
//! Run: `cargo run --release -p tribo --example falling_boxes`

use tribo::{BodyDef, Circle, Material, Polygon, Shape, ShapeDef, Vec2, World, WorldDef};

fn main() -> Result<(), tribo::Error> {
    let mut world = World::new(WorldDef::default())?;

    // Static ground: a wide box whose top face is y = 0.
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))?;
    world.create_shape(
        ground,
        &ShapeDef::default(),
        &Shape::Polygon(Polygon::new_box(20.0, 1.0)?),
    )?;

    // Rubber grips (μs 0.9), ice slides (μd 0.05).
    let rubber = Material::default().friction(0.9, 0.7);
    let ice = Material::default().friction(0.1, 0.05);
    let mut boxes = Vec::new();
    for (i, material) in [rubber, ice].into_iter().enumerate() {
        let mut def = BodyDef::dynamic(Vec2::new(-2.0 + 4.0 * i as f32, 0.5));
        def.linear_velocity = Vec2::new(3.0, 0.0);
        let b = world.create_body(&def)?;
        world.create_shape(
            b,
            &ShapeDef::with_material(material),
            &Shape::Polygon(Polygon::new_box(0.5, 0.5)?),
        )?;
        boxes.push(b);
    }

    // A bouncy ball.
    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0)))?;
    let bouncy = Material::default().restitution(0.8);
    world.create_shape(
        ball,
        &ShapeDef::with_material(bouncy),
        &Shape::Circle(Circle::new(Vec2::ZERO, 0.25)?),
    )?;

    for step in 0..120 {
        world.step(1.0 / 60.0)?;
        for e in &world.contact_events().begin {
            println!("step {step}: contact began between {:?} and {:?}", e.shape_a, e.shape_b);
        }
    }
    for (name, b) in [("rubber box", boxes[0]), ("ice box", boxes[1]), ("ball", ball)] {
        let p = world.body_position(b)?;
        println!("{name:>10}: x = {:7.3} m, y = {:6.3} m", p.x, p.y);
    }
    for c in world.contacts() {
        for p in c.points() {
            println!(
                "contact point at ({:.2}, {:.2}): normal impulse {:.4} N·s, {:?}, slip {:.4} m/s",
                p.point.x, p.point.y, p.normal_impulse, p.state, p.slip_speed
            );
        }
    }
    Ok(())
}
