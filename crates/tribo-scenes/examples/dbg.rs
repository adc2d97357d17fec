use tribo::*;
use tribo_scenes::build;
fn main() -> Result<()> {
    let defl: f32 = std::env::var("DEFL").ok().and_then(|s| s.parse().ok()).unwrap_or(0.0002);
    let n: usize = std::env::var("N").ok().and_then(|s| s.parse().ok()).unwrap_or(10);
    let mut world = World::new(WorldDef { enable_sleep: false, max_contact_deflection: defl, ..Default::default() })?;
    let m = Material::default();
    build::flat_ground(&mut world, 40.0, m)?;
    let mut bs = vec![];
    for i in 0..n {
        bs.push(build::dynamic_box(&mut world, BodyDef::dynamic(Vec2::new(0.0, 0.5 + i as f32)), 0.5, 0.5, m)?);
    }
    for k in 0..600 {
        world.step(1.0 / 60.0)?;
        if k % 30 == 0 {
        let ys: Vec<String> = bs.iter().map(|&b| { let p = world.body_position(b).unwrap(); format!("{:.4},{:.4}/{:.4}", p.x, p.y, world.body_angle(b).unwrap())}).collect();
        println!("{k} {}", ys[ys.len()-3..].join(" "));
        }
    }
    Ok(())
}
