use tribo::*;
use tribo_scenes::build;
fn main() -> Result<()> {
    let defl: f32 = std::env::var("DEFL").ok().and_then(|s| s.parse().ok()).unwrap_or(0.0002);
    let mut world = World::new(WorldDef { enable_sleep: false, max_contact_deflection: defl, ..Default::default() })?;
    let m = Material::default().friction(0.6, 0.4);
    build::flat_ground(&mut world, 40.0, m)?;
    let light = build::dynamic_box(&mut world, BodyDef::dynamic(Vec2::new(0.0, 0.5)), 0.5, 0.5, m)?;
    let heavy = build::dynamic_box(&mut world, BodyDef::dynamic(Vec2::new(0.0, 1.5)), 0.5, 0.5, m.density(100.0))?;
    for k in 0..600 {
        world.step(1.0 / 60.0)?;
        if k < 10 || k % 60 == 0 {
            let (pl, ph) = (world.body_position(light)?, world.body_position(heavy)?);
            println!("{k} light {:.5},{:.5} a={:.5}  heavy {:.5},{:.5} a={:.5}", pl.x, pl.y, world.body_angle(light)?, ph.x, ph.y, world.body_angle(heavy)?);
            if k < 4 { for c in world.contacts() { println!("   n={:?} {:?}", c.normal, c.points().iter().map(|p| (p.point, p.separation, p.normal_impulse, p.friction_impulse, p.state)).collect::<Vec<_>>()); } }
        }
    }
    Ok(())
}
