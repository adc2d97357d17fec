//! Built-in scenes. Each is one function returning a [`SceneFile`], the engine-neutral
//! description that the CLI runs and renders, `tribo export` writes, and the benchmarks
//! build for every engine.

use crate::format::{BodyKind, BodySpec, MaterialRef, MaterialSpec, SceneFile, ShapeSpec};
use std::collections::BTreeMap;

/// A built-in scene: name, one line of description, builder.
pub struct SceneEntry {
    /// Name used on the command line.
    pub name: &'static str,
    /// What it shows.
    pub about: &'static str,
    /// Builds the scene.
    pub build: fn() -> SceneFile,
}

/// Every built-in scene, in the order `tribo scenes` lists them.
pub const SCENES: &[SceneEntry] = &[
    SceneEntry {
        name: "incline",
        about: "μd < tan θ < μs: a block released at rest sticks, a pushed one keeps sliding, a one-μ block slides",
        build: incline,
    },
    SceneEntry {
        name: "friction_ramp",
        about: "Box2D's friction sample: five boxes of μ 0.75…0 on ramps of 0.25 rad; the first three hold",
        build: friction_ramp,
    },
    SceneEntry {
        name: "pyramid",
        about: "a 20-row pyramid of unit boxes standing still",
        build: pyramid,
    },
    SceneEntry {
        name: "card_house",
        about: "a two-storey house of leaning cards that stands only through static friction",
        build: card_house,
    },
    SceneEntry {
        name: "dominoes",
        about: "a row of 24 dominoes toppled by a push on the first",
        build: dominoes,
    },
    SceneEntry {
        name: "rolling",
        about: "disks launched sliding without spin start to roll at 2/3 of their speed",
        build: rolling,
    },
    SceneEntry {
        name: "bounce",
        about: "a row of balls with restitution 0 to 1 dropped from 3 m",
        build: bounce,
    },
    SceneEntry {
        name: "conveyor",
        about: "boxes dropped on a belt moving at 2 m/s are carried along",
        build: conveyor,
    },
    SceneEntry {
        name: "tumbler",
        about: "a kinematic rotating box full of boxes and disks",
        build: tumbler,
    },
    SceneEntry {
        name: "large_pyramid",
        about: "Box2D v3 benchmark: a 100-row pyramid of 5 050 boxes, sleep off, 500 steps",
        build: large_pyramid,
    },
    SceneEntry {
        name: "many_pyramids",
        about: "Box2D v3 benchmark: 20 × 20 pyramids of 55 boxes (22 000 boxes), sleep off, 200 steps",
        build: many_pyramids,
    },
];

/// The built-in scene of that name.
pub fn find(name: &str) -> Option<&'static SceneEntry> {
    SCENES.iter().find(|s| s.name == name)
}

fn scene(description: &str, steps: u32) -> SceneFile {
    SceneFile {
        description: Some(description.to_string()),
        gravity: [0.0, -9.81],
        dt: 1.0 / 60.0,
        substeps: 4,
        steps,
        enable_sleep: true,
        materials: BTreeMap::new(),
        bodies: Vec::new(),
    }
}

fn mat(friction_static: f32, friction_dynamic: f32) -> MaterialSpec {
    MaterialSpec {
        friction_static: Some(friction_static),
        friction_dynamic: Some(friction_dynamic),
        ..MaterialSpec::default()
    }
}

fn named(name: &str) -> Option<MaterialRef> {
    Some(MaterialRef::Named(name.to_string()))
}

fn box_shape(hx: f32, hy: f32, material: Option<MaterialRef>) -> ShapeSpec {
    ShapeSpec {
        kind: "box".into(),
        half_extents: Some([hx, hy]),
        material,
        ..ShapeSpec::default()
    }
}

fn circle_shape(radius: f32, material: Option<MaterialRef>) -> ShapeSpec {
    ShapeSpec {
        kind: "circle".into(),
        radius: Some(radius),
        material,
        ..ShapeSpec::default()
    }
}

fn body(name: Option<String>, kind: BodyKind, position: [f32; 2], angle: f32, shapes: Vec<ShapeSpec>) -> BodySpec {
    BodySpec {
        name,
        kind,
        position,
        angle,
        gravity_scale: 1.0,
        awake: true,
        shapes,
        ..BodySpec::default()
    }
}

fn rotate(p: [f32; 2], angle: f32) -> [f32; 2] {
    let (s, c) = angle.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// Ground: a static box whose top face is y = `top` for |x| ≤ `half_width`.
fn ground(name: &str, half_width: f32, top: f32, material: Option<MaterialRef>) -> BodySpec {
    body(
        Some(name.into()),
        BodyKind::Static,
        [0.0, top - 1.0],
        0.0,
        vec![box_shape(half_width, 1.0, material)],
    )
}

/// Three blocks on a slope with μd < tan θ < μs.
pub fn incline() -> SceneFile {
    let mut s = scene("incline: μs = 0.6, μd = 0.4, tan θ = 0.5", 180);
    s.materials.insert("wood".into(), mat(0.6, 0.4));
    s.materials.insert("one_mu".into(), mat(0.4, 0.4));
    let angle = 0.5f32.atan();
    let mut slope = body(
        Some("slope".into()),
        BodyKind::Static,
        rotate([0.0, -1.0], angle),
        angle,
        vec![box_shape(20.0, 1.0, named("wood"))],
    );
    slope.angle = angle;
    s.bodies.push(slope);
    let blocks = [
        ("at_rest", 16.0, 0.0, "wood"),
        ("pushed", 12.0, 1.5, "wood"),
        ("one_mu", -2.0, 0.0, "one_mu"),
    ];
    for (name, along, push, material) in blocks {
        let mut b = body(
            Some(name.into()),
            BodyKind::Dynamic,
            rotate([along, 0.5], angle),
            angle,
            vec![box_shape(0.5, 0.5, named(material))],
        );
        if push != 0.0 {
            let down = rotate([-1.0, 0.0], angle);
            b.linear_velocity = [down[0] * push, down[1] * push];
        }
        s.bodies.push(b);
    }
    s
}

/// Box2D's friction ramp: boxes of μ 0.75, 0.5, 0.35, 0.1, 0 on ramps of 0.25 rad with
/// ground μ 0.2 (geometric mean: 0.39, 0.32, 0.26, 0.14, 0 against tan 0.25 = 0.255).
pub fn friction_ramp() -> SceneFile {
    let mut s = scene("friction ramp: mixed μ 0.39, 0.32, 0.26, 0.14, 0 on tan θ = 0.255", 300);
    s.materials.insert("ramp".into(), mat(0.2, 0.2));
    let angle = 0.25f32;
    for (i, mu) in [0.75f32, 0.5, 0.35, 0.1, 0.0].into_iter().enumerate() {
        let y = 12.0 - 3.0 * i as f32;
        let x = -2.0 + 1.5 * i as f32;
        s.bodies.push(body(
            Some(format!("ramp{i}")),
            BodyKind::Static,
            [x, y],
            angle,
            vec![box_shape(4.0, 0.1, named("ramp"))],
        ));
        let p = rotate([2.5, 0.1 + 0.5], angle);
        s.bodies.push(body(
            Some(format!("box_mu_{mu}")),
            BodyKind::Dynamic,
            [x + p[0], y + p[1]],
            angle,
            vec![box_shape(0.5, 0.5, Some(MaterialRef::Inline(mat(mu, mu))))],
        ));
    }
    s.bodies.push(ground("ground", 20.0, -1.0, named("ramp")));
    s
}

fn pyramid_bodies(s: &mut SceneFile, rows: usize, h: f32, center_x: f32, base_y: f32) {
    let size = 2.0 * h;
    for i in 0..rows {
        let count = rows - i;
        let x0 = center_x - 0.5 * size * (count as f32 - 1.0);
        for j in 0..count {
            s.bodies.push(body(
                None,
                BodyKind::Dynamic,
                [x0 + size * j as f32, base_y + h + size * i as f32],
                0.0,
                vec![box_shape(h, h, None)],
            ));
        }
    }
}

/// A 20-row pyramid.
pub fn pyramid() -> SceneFile {
    let mut s = scene("a 20-row pyramid of unit boxes", 600);
    s.bodies.push(ground("ground", 20.0, 0.0, None));
    pyramid_bodies(&mut s, 20, 0.5, 0.0, 0.0);
    s
}

/// A house of cards: pairs of cards leaning on each other, flat cards as floors.
pub fn card_house() -> SceneFile {
    let mut s = scene("card house: leaning cards held by static friction (μs 0.7)", 600);
    s.materials.insert("card".into(), mat(0.7, 0.5));
    s.bodies.push(ground("table", 10.0, 0.0, named("card")));
    let (half_len, half_thick) = (0.5f32, 0.01f32);
    let lean = 0.32f32; // from vertical [rad]
    let dx = half_len * lean.sin();
    let dy = half_len * lean.cos();
    let card = |name: String, pos: [f32; 2], angle: f32| {
        body(
            Some(name),
            BodyKind::Dynamic,
            pos,
            angle,
            vec![box_shape(half_thick, half_len, named("card"))],
        )
    };
    let mut floor = 0.0f32;
    for (level, pairs) in [3usize, 2, 1].into_iter().enumerate() {
        let width = 4.0 * dx + 0.1;
        let x0 = -0.5 * width * (pairs as f32 - 1.0);
        for k in 0..pairs {
            let cx = x0 + width * k as f32;
            let y = floor + dy + half_thick;
            s.bodies.push(card(format!("l{level}_{k}_left"), [cx - dx, y], -lean));
            s.bodies.push(card(format!("l{level}_{k}_right"), [cx + dx, y], lean));
        }
        floor += 2.0 * dy + 2.0 * half_thick;
        if pairs > 1 {
            for k in 0..pairs - 1 {
                let cx = x0 + width * (k as f32 + 0.5);
                s.bodies.push(body(
                    Some(format!("l{level}_floor{k}")),
                    BodyKind::Dynamic,
                    [cx, floor + half_thick],
                    0.0,
                    vec![box_shape(width * 0.5 + 0.05, half_thick, named("card"))],
                ));
            }
            floor += 2.0 * half_thick;
        }
    }
    s
}

/// A row of dominoes; the first gets a push.
pub fn dominoes() -> SceneFile {
    let mut s = scene("24 dominoes (0.1 × 1 m, 0.5 m apart); the first is pushed", 360);
    s.materials.insert("domino".into(), mat(0.6, 0.4));
    s.bodies.push(ground("table", 15.0, 0.0, named("domino")));
    for i in 0..24 {
        let mut d = body(
            Some(format!("domino{i}")),
            BodyKind::Dynamic,
            [-6.0 + 0.5 * i as f32, 0.5],
            0.0,
            vec![box_shape(0.05, 0.5, named("domino"))],
        );
        if i == 0 {
            d.angular_velocity = -1.5;
        }
        s.bodies.push(d);
    }
    s
}

/// Disks launched sliding without spin.
pub fn rolling() -> SceneFile {
    let mut s = scene(
        "disks launched at 4 m/s without spin: rolling at 2/3 v0 after v0/(3 μd g)",
        240,
    );
    s.bodies
        .push(ground("ground", 30.0, 0.0, Some(MaterialRef::Inline(mat(0.5, 0.3)))));
    for (i, mu) in [0.1f32, 0.3, 0.6].into_iter().enumerate() {
        let mut d = body(
            Some(format!("disk_mu_{mu}")),
            BodyKind::Dynamic,
            [-8.0, 0.5 + 1.2 * i as f32 * 0.0],
            0.0,
            vec![circle_shape(0.5, Some(MaterialRef::Inline(mat(mu, mu))))],
        );
        d.position = [-8.0 + 0.0 * i as f32, 0.5];
        d.linear_velocity = [4.0, 0.0];
        // Separate lanes: each disk rolls on its own ground strip.
        d.position[1] = 0.5 + 3.0 * i as f32;
        s.bodies.push(d);
        if i > 0 {
            s.bodies.push(body(
                Some(format!("lane{i}")),
                BodyKind::Static,
                [6.0, 3.0 * i as f32 - 0.1],
                0.0,
                vec![box_shape(16.0, 0.1, Some(MaterialRef::Inline(mat(0.5, 0.3))))],
            ));
        }
    }
    s
}

/// Balls with restitution 0 … 1.
pub fn bounce() -> SceneFile {
    let mut s = scene("balls with e = 0, 0.25, 0.5, 0.75, 1 dropped from 3 m: apex e² h", 300);
    s.bodies.push(ground("ground", 10.0, 0.0, None));
    for (i, e) in [0.0f32, 0.25, 0.5, 0.75, 1.0].into_iter().enumerate() {
        let m = MaterialSpec {
            restitution: Some(e),
            ..MaterialSpec::default()
        };
        s.bodies.push(body(
            Some(format!("ball_e_{e}")),
            BodyKind::Dynamic,
            [-4.0 + 2.0 * i as f32, 3.25],
            0.0,
            vec![circle_shape(0.25, Some(MaterialRef::Inline(m)))],
        ));
    }
    s
}

/// A conveyor belt.
pub fn conveyor() -> SceneFile {
    let mut s = scene("a belt at 2 m/s: boxes reach the belt speed after u/(μd g)", 300);
    s.materials.insert(
        "belt".into(),
        MaterialSpec {
            tangent_speed: Some(2.0),
            ..mat(0.6, 0.5)
        },
    );
    s.materials.insert("box".into(), mat(0.6, 0.5));
    s.bodies.push(body(
        Some("belt".into()),
        BodyKind::Static,
        [0.0, -0.25],
        0.0,
        vec![box_shape(8.0, 0.25, named("belt"))],
    ));
    s.bodies.push(ground("floor", 30.0, -3.0, None));
    for i in 0..4 {
        s.bodies.push(body(
            Some(format!("box{i}")),
            BodyKind::Dynamic,
            [-7.0 + 1.5 * i as f32, 0.5 + 0.6 * i as f32],
            0.0,
            vec![box_shape(0.4, 0.4, named("box"))],
        ));
    }
    s
}

/// A kinematic rotating box full of shapes.
pub fn tumbler() -> SceneFile {
    let mut s = scene("a kinematic box turning at 25°/s full of boxes and disks", 600);
    let mut drum = body(Some("drum".into()), BodyKind::Kinematic, [0.0, 10.0], 0.0, Vec::new());
    drum.angular_velocity = 25f32.to_radians();
    for (center, half) in [
        ([10.0f32, 0.0f32], [0.5f32, 10.0f32]),
        ([-10.0, 0.0], [0.5, 10.0]),
        ([0.0, 10.0], [10.0, 0.5]),
        ([0.0, -10.0], [10.0, 0.5]),
    ] {
        drum.shapes.push(ShapeSpec {
            center: Some(center),
            ..box_shape(half[0], half[1], None)
        });
    }
    s.bodies.push(drum);
    for i in 0..15 {
        for j in 0..15 {
            let p = [-7.0 + 1.0 * j as f32, 4.0 + 1.0 * i as f32];
            let shape = if (i + j) % 3 == 0 {
                circle_shape(0.3, None)
            } else {
                box_shape(0.3, 0.3, None)
            };
            s.bodies.push(body(None, BodyKind::Dynamic, p, 0.0, vec![shape]));
        }
    }
    s
}

/// Box2D v3's pyramid of unit boxes (SCENES.md §2): `base` boxes in the bottom row; box
/// (i, j), j = i…base−1, at x = 0.5 (i + 1) + (j − i) + `x_offset`, y = i + 0.5 + `base_y`.
fn box2d_pyramid(s: &mut SceneFile, base: usize, x_offset: f32, base_y: f32) {
    for i in 0..base {
        for j in i..base {
            let x = 0.5 * (i + 1) as f32 + (j - i) as f32 + x_offset;
            let y = i as f32 + 0.5 + base_y;
            s.bodies.push(body(
                None,
                BodyKind::Dynamic,
                [x, y],
                0.0,
                vec![box_shape(0.5, 0.5, None)],
            ));
        }
    }
}

/// Box2D v3's large_pyramid benchmark scene.
pub fn large_pyramid() -> SceneFile {
    let mut s = scene("Box2D v3 benchmark large_pyramid", 500);
    s.gravity = [0.0, -10.0];
    s.enable_sleep = false;
    s.bodies.push(body(
        Some("ground".into()),
        BodyKind::Static,
        [0.0, -1.0],
        0.0,
        vec![box_shape(100.0, 1.0, None)],
    ));
    box2d_pyramid(&mut s, 100, -50.0, 0.0);
    s
}

/// Box2D v3's many_pyramids benchmark scene.
pub fn many_pyramids() -> SceneFile {
    let mut s = scene("Box2D v3 benchmark many_pyramids", 200);
    s.gravity = [0.0, -10.0];
    s.enable_sleep = false;
    let mut ground = body(Some("ground".into()), BodyKind::Static, [0.0, 0.0], 0.0, Vec::new());
    for r in 0..20 {
        let y = 11.0 * r as f32;
        ground.shapes.push(ShapeSpec {
            kind: "segment".into(),
            point1: Some([-110.0, y]),
            point2: Some([110.0, y]),
            ..ShapeSpec::default()
        });
    }
    s.bodies.push(ground);
    for r in 0..20 {
        for c in 0..20 {
            let center_x = -110.0 + 11.0 * c as f32 + 1.0;
            let base_y = 11.0 * r as f32;
            box2d_pyramid(&mut s, 10, center_x - 0.5, base_y);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_validates_and_builds() {
        for entry in SCENES {
            let scene = (entry.build)();
            assert!(scene.validate().is_ok(), "{}: {:?}", entry.name, scene.validate());
            if entry.name != "many_pyramids" {
                assert!(scene.build().is_ok(), "{}", entry.name);
            }
        }
    }

    #[test]
    fn export_round_trips() {
        for entry in SCENES.iter().filter(|e| e.name != "many_pyramids") {
            let scene = (entry.build)();
            let text = scene.to_json();
            let back = crate::format::parse(&text).expect("exported scene parses");
            assert_eq!(back, scene, "{}", entry.name);
        }
    }
}

#[cfg(test)]
mod sleep_tests {
    use crate::format::{BodyKind, BodySpec, SceneFile};

    /// A body the scene creates asleep stays asleep after building (regression: setting
    /// its velocity used to wake it).
    #[test]
    fn bodies_created_asleep_stay_asleep() {
        let mut scene = super::bounce();
        scene.bodies.push(BodySpec {
            kind: BodyKind::Dynamic,
            position: [8.0, 5.0],
            awake: false,
            gravity_scale: 1.0,
            shapes: vec![super::box_shape(0.5, 0.5, None)],
            ..BodySpec::default()
        });
        let built = SceneFile::build(&scene).expect("builds");
        let id = *built.bodies.last().expect("body");
        assert!(!built.world.body_is_awake(id).expect("live"));
    }
}
