use tribo::*;
use tribo_scenes::build;
fn main() -> Result<()> {
    let m = Material::default().friction(0.6, 0.4);
    let ratio: f32 = std::env::var("R").ok().and_then(|s| s.parse().ok()).unwrap_or(0.95);
    let angle = (ratio * 0.6f32).atan();
    let mut world = build::world_no_sleep(9.81)?;
    build::slope_ground(&mut world, angle, 20.0, m)?;
    let block = build::box_on_slope(&mut world, angle, 0.0, 0.5, 0.5, m)?;
    let q = Rot::from_angle(angle);
    let s0 = world.body_position(block)?.dot(q.x_axis());
    let n0 = world.body_position(block)?.dot(q.rotate(Vec2::Y));
    for k in 0..1200 {
        world.step(1.0 / 60.0)?;
        if k < 12 || k % 120 == 0 {
            let p = world.body_position(block)?;
            let c = world.body_contacts(block)?;
            println!("{k} ds={:.6}mm dn={:.4}mm ang={:.6} {:?}", (p.dot(q.x_axis()) - s0) * 1000.0, (p.dot(q.rotate(Vec2::Y)) - n0)*1000.0, world.body_angle(block)? - angle,
                c[0].points().iter().map(|p| (p.state, (p.normal_impulse*1000.0).round()/1000.0, (p.friction_impulse*1000.0).round()/1000.0)).collect::<Vec<_>>());
        }
    }
    Ok(())
}
