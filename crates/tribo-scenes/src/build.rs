//! Scene-building helpers shared by scenes and experiments.

use tribo::{BodyDef, BodyId, Circle, Material, Polygon, Result, Rot, Shape, ShapeDef, Vec2, World, WorldDef};

/// Standard gravity [m/s²] used by the experiments.
pub const G: f32 = 9.81;
/// Step length of the experiments [s]: 1/60 s.
pub const DT: f32 = 1.0 / 60.0;

/// A world with gravity (0, −g), 4 substeps and sleep off (experiments measure drift, so
/// nothing may hide it by sleeping).
pub fn world_no_sleep(gravity: f32) -> Result<World> {
    World::new(WorldDef {
        gravity: Vec2::new(0.0, -gravity),
        enable_sleep: false,
        ..WorldDef::default()
    })
}

/// A static ground box whose top face is the line y = 0 for |x| ≤ `half_width` [m].
pub fn flat_ground(world: &mut World, half_width: f32, material: Material) -> Result<BodyId> {
    slope_ground(world, 0.0, half_width, material)
}

/// A static ground box 2 m thick whose top face passes through the origin, rotated
/// counter-clockwise by `angle` [rad] (so the slope rises towards +x).
pub fn slope_ground(world: &mut World, angle: f32, half_width: f32, material: Material) -> Result<BodyId> {
    let q = Rot::from_angle(angle);
    let mut def = BodyDef::fixed(q.rotate(Vec2::new(0.0, -1.0)));
    def.angle = angle;
    let body = world.create_body(&def)?;
    world.create_shape(
        body,
        &ShapeDef::with_material(material),
        &Shape::Polygon(Polygon::new_box(half_width, 1.0)?),
    )?;
    Ok(body)
}

/// A dynamic box of half extents (hx, hy) resting on a slope of `angle` through the
/// origin, its centre at distance `along` [m] up the slope.
pub fn box_on_slope(world: &mut World, angle: f32, along: f32, hx: f32, hy: f32, material: Material) -> Result<BodyId> {
    let q = Rot::from_angle(angle);
    let mut def = BodyDef::dynamic(q.rotate(Vec2::new(along, hy)));
    def.angle = angle;
    dynamic_box(world, def, hx, hy, material)
}

/// A dynamic box body from a definition.
pub fn dynamic_box(world: &mut World, def: BodyDef, hx: f32, hy: f32, material: Material) -> Result<BodyId> {
    let body = world.create_body(&def)?;
    world.create_shape(
        body,
        &ShapeDef::with_material(material),
        &Shape::Polygon(Polygon::new_box(hx, hy)?),
    )?;
    Ok(body)
}

/// A dynamic disk body from a definition.
pub fn dynamic_disk(world: &mut World, def: BodyDef, radius: f32, material: Material) -> Result<BodyId> {
    let body = world.create_body(&def)?;
    world.create_shape(
        body,
        &ShapeDef::with_material(material),
        &Shape::Circle(Circle::new(Vec2::ZERO, radius)?),
    )?;
    Ok(body)
}

/// A pyramid of unit boxes (half extent `h`) on the ground y = 0, `rows` boxes at the
/// base, centred on x = `center_x`. Returns the bodies, bottom row first; the last is the
/// top box.
pub fn pyramid(world: &mut World, rows: usize, h: f32, center_x: f32, material: Material) -> Result<Vec<BodyId>> {
    let mut out = Vec::with_capacity(rows * (rows + 1) / 2);
    let size = 2.0 * h;
    for i in 0..rows {
        let count = rows - i;
        let x0 = center_x - 0.5 * size * (count as f32 - 1.0);
        for j in 0..count {
            let p = Vec2::new(x0 + size * j as f32, h + size * i as f32);
            out.push(dynamic_box(world, BodyDef::dynamic(p), h, h, material)?);
        }
    }
    Ok(out)
}
