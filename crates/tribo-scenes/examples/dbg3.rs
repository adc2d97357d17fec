use tribo::*;
use tribo_scenes::build;
fn main() -> Result<()> {
    let m = Material::default().friction(0.5, 0.3);
    let mut world = build::world_no_sleep(9.81)?;
    build::flat_ground(&mut world, 50.0, m)?;
    let mut def = BodyDef::dynamic(Vec2::new(0.0, 0.5));
    def.linear_velocity = Vec2::new(4.0, 0.0);
    let disk = build::dynamic_disk(&mut world, def, 0.5, m)?;
    let mass = world.body_mass(disk)?;
    for k in 0..6 {
        world.step(1.0/60.0)?;
        let v = world.body_linear_velocity(disk)?;
        let c = world.body_contacts(disk)?;
        let p = c[0].points()[0];
        println!("{k} v={:.5} dv_expected={:.5} ni={:.5} (mg dt={:.5}) fi={:.5} {:?}", v.x, 4.0 - 0.3*9.81*(k+1) as f32/60.0, p.normal_impulse, mass*9.81/60.0, p.friction_impulse, p.state);
    }
    // restitution
    let m = Material::default().restitution(1.0);
    let mut world = build::world_no_sleep(9.81)?;
    build::flat_ground(&mut world, 10.0, m)?;
    let ball = build::dynamic_disk(&mut world, BodyDef::dynamic(Vec2::new(0.0, 1.25)), 0.25, m)?;
    for k in 0..80 { world.step(1.0/60.0)?; let p = world.body_position(ball)?; let v = world.body_linear_velocity(ball)?; if k > 20 && k < 40 || k%10==0 { println!("{k} y={:.5} vy={:.5}", p.y, v.y); } }
    Ok(())
}
