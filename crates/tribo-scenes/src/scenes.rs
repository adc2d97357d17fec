//! Built-in scenes. Each is one function returning a [`SceneFile`], the engine-neutral
//! description that the CLI runs and renders, `tribo export` writes, and the benchmarks
//! build for every engine.

use crate::format::{
    BodyKind, BodySpec, FilterSpec, JointSpec, MaterialRef, MaterialSpec, MotorSpec, SceneFile, ShapeSpec, SpringSpec,
};
use std::collections::BTreeMap;

/// A built-in scene: name, one line of description, builder.
pub struct SceneEntry {
    /// Name used on the command line.
    pub name: &'static str,
    /// What it shows.
    pub about: &'static str,
    /// Builds the scene.
    pub build: fn() -> SceneFile,
    /// What the scene does before each step, if anything (Box2D's `Step…` functions).
    pub hook: Option<StepHook>,
}

/// Every built-in scene, in the order `tribo scenes` lists them.
pub const SCENES: &[SceneEntry] = &[
    SceneEntry {
        name: "incline",
        about: "μd < tan θ < μs: a block released at rest sticks, a pushed one keeps sliding, a one-μ block slides",
        build: incline,
        hook: None,
    },
    SceneEntry {
        name: "friction_ramp",
        about: "Box2D's friction sample: five boxes of μ 0.75…0 on ramps of 0.25 rad; the first three hold",
        build: friction_ramp,
        hook: None,
    },
    SceneEntry {
        name: "pyramid",
        about: "a 20-row pyramid of unit boxes standing still",
        build: pyramid,
        hook: None,
    },
    SceneEntry {
        name: "card_house",
        about: "a two-storey house of leaning cards that stands only through static friction",
        build: card_house,
        hook: None,
    },
    SceneEntry {
        name: "dominoes",
        about: "a row of 24 dominoes toppled by a push on the first",
        build: dominoes,
        hook: None,
    },
    SceneEntry {
        name: "rolling",
        about: "disks launched sliding without spin start to roll at 2/3 of their speed",
        build: rolling,
        hook: None,
    },
    SceneEntry {
        name: "bounce",
        about: "a row of balls with restitution 0 to 1 dropped from 3 m",
        build: bounce,
        hook: None,
    },
    SceneEntry {
        name: "conveyor",
        about: "boxes dropped on a belt moving at 2 m/s are carried along",
        build: conveyor,
        hook: None,
    },
    SceneEntry {
        name: "tumbler",
        about: "a kinematic rotating box full of boxes and disks",
        build: tumbler,
        hook: None,
    },
    SceneEntry {
        name: "tumbler_benchmark",
        about: "Box2D v3 benchmark tumbler: 2 025 small boxes in a 20 m drum driven at 25°/s by a revolute motor, 750 steps",
        build: tumbler_benchmark,
        hook: None,
    },
    SceneEntry {
        name: "joint_grid",
        about: "Box2D v3 benchmark: a 100 × 100 grid of circles hanging on 19 800 revolute joints, 500 steps",
        build: joint_grid,
        hook: None,
    },
    SceneEntry {
        name: "spinner",
        about: "Box2D v3 benchmark: a rotor on a revolute motor stirring 6 076 bodies in a 40 m ring, 500 steps",
        build: spinner,
        hook: None,
    },
    SceneEntry {
        name: "ragdolls",
        about: "Box2D's ragdoll (its rain benchmark's): 10 of them dropped 5 m onto a shelf, on limited, sprung, frictional joints",
        build: ragdolls,
        hook: None,
    },
    SceneEntry {
        name: "rain",
        about: "Box2D v3 benchmark rain: 1 000 ragdolls arrive in columns every 8 steps and fall onto five shelves, 1 000 steps",
        build: ragdoll_rain,
        hook: Some(ragdoll_rain_hook),
    },
    SceneEntry {
        name: "scaling_rain_1k",
        about: "1 000 boxes and disks raining into a 50 m wide container (the smallest benchmark scaling scene)",
        build: scaling_rain_1k,
        hook: None,
    },
    SceneEntry {
        name: "large_pyramid",
        about: "Box2D v3 benchmark: a 100-row pyramid of 5 050 boxes, sleep off, 500 steps",
        build: large_pyramid,
        hook: None,
    },
    SceneEntry {
        name: "compounds",
        about: "Box2D v3 benchmark: 3 000 bodies of two triangles fall into a container of boxes, 500 steps",
        build: compounds,
        hook: None,
    },
    SceneEntry {
        name: "washer",
        about: "Box2D v3 benchmark: 8 100 small boxes tumbled by a kinematic ring turning at 25°/s, 500 steps",
        build: washer,
        hook: None,
    },
    SceneEntry {
        name: "junkyard",
        about: "Box2D v3 benchmark: 8 000 pentagons in a container stirred by a kinematic pusher swinging ±60 m, 800 steps",
        build: junkyard,
        hook: Some(junkyard_hook),
    },
    SceneEntry {
        name: "many_pyramids",
        about: "Box2D v3 benchmark: 20 × 20 pyramids of 55 boxes (22 000 boxes), sleep off, 200 steps",
        build: many_pyramids,
        hook: None,
    },
];

/// One thing a scene's step hook does before a step: the benchmark does it to every
/// engine, the CLI to its Tribo world.
#[derive(Clone, Copy, Debug)]
pub enum HookAction {
    /// Set the velocity [m/s] of the centre of mass and the angular velocity [rad/s] of
    /// scene body `body` (an index into the scene's bodies).
    SetVelocity {
        /// Scene body index.
        body: usize,
        /// Linear velocity [m/s].
        velocity: [f32; 2],
        /// Angular velocity [rad/s].
        angular_velocity: f32,
    },
    /// Destroy the bodies (with their shapes and joints) created under `tag`.
    Despawn {
        /// The batch's tag.
        tag: usize,
    },
    /// Add the bodies and joints of `batch` (its joints refer to its own bodies; its world
    /// settings are not used) under `tag`.
    Spawn {
        /// The batch's tag.
        tag: usize,
        /// What to add.
        batch: &'static SceneFile,
    },
}

/// A scene's step hook: given the index `n` of the step about to run (0 = the first), the
/// step length `dt` [s] and a way to read a scene body's origin [m], what to do before
/// the step, in order.
pub type StepHook = fn(n: u32, dt: f32, position: &mut dyn FnMut(usize) -> [f32; 2]) -> Vec<HookAction>;

/// Junkyard's pusher (the last body): before step `n` its velocity is set so that it
/// reaches [`junkyard_pusher_x`] at the end of the step, as Box2D's
/// `b2Body_SetTargetTransform` does (y stays 0, no rotation).
pub fn junkyard_hook(n: u32, dt: f32, position: &mut dyn FnMut(usize) -> [f32; 2]) -> Vec<HookAction> {
    let pusher = JUNKYARD_PUSHER;
    let x = position(pusher)[0];
    vec![HookAction::SetVelocity {
        body: pusher,
        velocity: [(junkyard_pusher_x(n) - x) / dt, 0.0],
        angular_velocity: 0.0,
    }]
}

/// The ragdoll columns of the rain, built once (hooks run inside the benchmark's timed
/// loop: what it times is the engines' creation and destruction, as in Box2D's driver,
/// not the making of the descriptions).
pub fn ragdoll_rain_columns() -> &'static [SceneFile] {
    static COLUMNS: std::sync::OnceLock<Vec<SceneFile>> = std::sync::OnceLock::new();
    COLUMNS.get_or_init(|| (0..RAGDOLL_RAIN_COLUMNS).map(ragdoll_rain_column).collect())
}

/// Box2D's `StepRain` ([`ragdoll_rain_action`]): before step `n`, the next column of
/// ragdolls (tag: its column) is created, or the oldest destroyed and created again.
pub fn ragdoll_rain_hook(n: u32, _dt: f32, _position: &mut dyn FnMut(usize) -> [f32; 2]) -> Vec<HookAction> {
    let Some((column, exists)) = ragdoll_rain_action(n) else {
        return Vec::new();
    };
    let batch = &ragdoll_rain_columns()[column];
    if exists {
        vec![
            HookAction::Despawn { tag: column },
            HookAction::Spawn { tag: column, batch },
        ]
    } else {
        vec![HookAction::Spawn { tag: column, batch }]
    }
}

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
        joints: Vec::new(),
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

/// The four walls of a 20 m square drum (Box2D's tumbler): boxes half (0.5, 10) m at
/// (±10, 0) and half (10, 0.5) m at (0, ±10) in the drum's frame.
fn drum_walls(material: Option<MaterialRef>) -> Vec<ShapeSpec> {
    [
        ([10.0f32, 0.0f32], [0.5f32, 10.0f32]),
        ([-10.0, 0.0], [0.5, 10.0]),
        ([0.0, 10.0], [10.0, 0.5]),
        ([0.0, -10.0], [10.0, 0.5]),
    ]
    .into_iter()
    .map(|(center, half)| ShapeSpec {
        center: Some(center),
        ..box_shape(half[0], half[1], material.clone())
    })
    .collect()
}

/// A kinematic rotating box full of shapes.
pub fn tumbler() -> SceneFile {
    let mut s = scene("a kinematic box turning at 25°/s full of boxes and disks", 600);
    let mut drum = body(Some("drum".into()), BodyKind::Kinematic, [0.0, 10.0], 0.0, Vec::new());
    drum.angular_velocity = 25f32.to_radians();
    drum.shapes = drum_walls(None);
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

/// Angular velocity of the tumbler benchmark's drum [rad/s]: 25°/s ≈ 0.436 rad/s.
pub const TUMBLER_DRUM_SPEED: f32 = 25.0 * core::f32::consts::PI / 180.0;

/// Centre of the tumbler benchmark's drum [m].
pub const TUMBLER_DRUM_CENTER: [f32; 2] = [0.0, 10.0];

/// Largest torque of the tumbler benchmark's drum motor [N·m] (Box2D's scene: 1e8).
pub const TUMBLER_MOTOR_TORQUE: f32 = 1.0e8;

/// Box2D v3's tumbler benchmark scene (SCENES.md §2, `CreateTumbler`).
///
/// Body 0: a static ground body at the origin without shapes. Body 1, "drum": a dynamic
/// body at (0, 10) m of four boxes, half (0.5, 10) m at (±10, 0) m and half (10, 0.5) m
/// at (0, ±10) m in its frame (inside 19 m × 19 m), density 50 kg/m², hinged to the
/// ground at its centre by a revolute joint whose motor turns it at 25°/s
/// ([`TUMBLER_DRUM_SPEED`], ≈ 0.436 rad/s, counter-clockwise) with at most
/// [`TUMBLER_MOTOR_TORQUE`]. Contents: 45 × 45 = 2 025 dynamic boxes, half 0.125 m,
/// density 1 kg/m², friction 0.6, at x = −9 + 0.4 j, y = 1 + 0.4 i m (row i, column j).
/// Gravity (0, −10) m/s², 60 Hz, 4 substeps, sleep on, 750 steps (12.5 s, 312.5° of drum
/// rotation).
pub fn tumbler_benchmark() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark tumbler: a dynamic drum on a revolute motor at 25°/s, 2 025 boxes",
        750,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = true;
    s.materials.insert(
        "drum".into(),
        MaterialSpec {
            density: Some(50.0),
            friction: Some(0.6),
            ..MaterialSpec::default()
        },
    );
    s.materials.insert(
        "box".into(),
        MaterialSpec {
            density: Some(1.0),
            friction: Some(0.6),
            ..MaterialSpec::default()
        },
    );
    s.bodies.push(body(
        Some("ground".into()),
        BodyKind::Static,
        [0.0, 0.0],
        0.0,
        Vec::new(),
    ));
    let mut drum = body(
        Some("drum".into()),
        BodyKind::Dynamic,
        TUMBLER_DRUM_CENTER,
        0.0,
        Vec::new(),
    );
    drum.shapes = drum_walls(named("drum"));
    s.bodies.push(drum);
    s.joints.push(JointSpec {
        motor: Some(MotorSpec {
            speed: TUMBLER_DRUM_SPEED,
            max_torque: TUMBLER_MOTOR_TORQUE,
        }),
        ..JointSpec::revolute(0, 1, TUMBLER_DRUM_CENTER)
    });
    for i in 0..45 {
        for j in 0..45 {
            let p = [-9.0 + 0.4 * j as f32, 1.0 + 0.4 * i as f32];
            s.bodies.push(body(
                None,
                BodyKind::Dynamic,
                p,
                0.0,
                vec![box_shape(0.125, 0.125, named("box"))],
            ));
        }
    }
    s
}

/// Side of Box2D's joint grid [bodies].
pub const JOINT_GRID_N: usize = 100;

/// Box2D v3's joint_grid benchmark scene (SCENES.md §2, `CreateJointGrid`): a pure joint
/// benchmark. A 100 × 100 grid of bodies, body (k, i) (column k, row i, created k outer,
/// i inner) at (k, −i) m with one circle of radius 0.4 m (density 1 kg/m², friction 0.6,
/// filter category 0x2 and mask ¬0x2, so no two circles ever collide: no contacts), the
/// bodies of row 0 in columns 47 … 53 static (the grid hangs from them), the others
/// dynamic. Revolute joints with Box2D's defaults (no limit, motor or spring; 60 Hz,
/// ζ 2 correction): each body to the one above it at the point 0.5 m above its centre, and
/// to the one on its left at the point 0.5 m to its left: 2 × 100 × 99 = 19 800 joints.
/// Gravity (0, −10) m/s², sleep off, 500 steps.
pub fn joint_grid() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark: a 100 × 100 grid of circles on 19 800 revolute joints",
        500,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = false;
    let n = JOINT_GRID_N;
    let filter = FilterSpec {
        category: 0x2,
        mask: !0x2,
        group: 0,
    };
    s.bodies.reserve(n * n);
    s.joints.reserve(2 * n * (n - 1));
    for k in 0..n {
        for i in 0..n {
            let pinned = i == 0 && (n / 2 - 3..=n / 2 + 3).contains(&k);
            let kind = if pinned { BodyKind::Static } else { BodyKind::Dynamic };
            let (x, y) = (k as f32, -(i as f32));
            let shape = ShapeSpec {
                filter: Some(filter),
                ..circle_shape(0.4, None)
            };
            let index = s.bodies.len();
            s.bodies.push(body(None, kind, [x, y], 0.0, vec![shape]));
            if i > 0 {
                s.joints.push(JointSpec::revolute(index - 1, index, [x, y + 0.5]));
            }
            if k > 0 {
                s.joints.push(JointSpec::revolute(index - n, index, [x - 0.5, y]));
            }
        }
    }
    s
}

/// Centre [m] and radius [m] of the spinner benchmark's circular wall.
pub const SPINNER_CENTER: [f32; 2] = [0.0, 32.0];
/// Radius of the spinner's wall [m].
pub const SPINNER_RADIUS: f32 = 40.0;
/// Speed of the spinner's rotor motor [rad/s].
pub const SPINNER_MOTOR_SPEED: f32 = 5.0;

/// Box2D v3's spinner benchmark scene (SCENES.md §2, `CreateSpinner`, HEAD sizes).
///
/// Body 0: static ground, a chain loop through 360 points on a circle of radius 40 m
/// about (0, 32) m, wound clockwise as Box2D's (its one-sided pieces push inwards),
/// friction 0.1. (Until 2026-12-02 the ring was 360 quads 2.5 m thick: a body driven into
/// it could be held between two quads' side faces.) Body 1,
/// "rotor": a dynamic rounded box half (0.4, 20) m with radius 0.2 m at (0, 12) m,
/// friction 0, density 1 kg/m², hinged to the ground at its centre by a revolute motor at
/// 5 rad/s with unbounded torque (`f32::MAX`, as Box2D HEAD). Then 6 076 dynamic bodies,
/// density 0.25 kg/m², friction 0.1, restitution 0.1, cycling by creation index mod 3
/// through a capsule (±0.25, 0) m radius 0.25 m, a circle of radius 0.35 m and a square of
/// half 0.35 m, placed from (−23, 2) m stepping 0.5 m in x and wrapping to x = −23, y +=
/// 0.5 m when x reaches 23 (92 per row; the rotor overlaps the middle columns at
/// creation, as in Box2D). Gravity (0, −10) m/s², sleep on, 500 steps.
pub fn spinner() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark: a motor-driven rotor stirring 6 076 bodies in a ring",
        500,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = true;
    let wall_material = MaterialSpec {
        friction: Some(0.1),
        ..MaterialSpec::default()
    };
    // Point k of the ring at radius r (clockwise, as Box2D's chain).
    let point = |k: usize, r: f32| {
        let a = -(k as f32) * core::f32::consts::TAU / 360.0;
        [SPINNER_CENTER[0] + r * a.cos(), SPINNER_CENTER[1] + r * a.sin()]
    };
    let ring = ShapeSpec {
        kind: "chain".into(),
        points: Some((0..360).map(|k| point(k, SPINNER_RADIUS)).collect()),
        closed: Some(true),
        material: Some(MaterialRef::Inline(wall_material)),
        ..ShapeSpec::default()
    };
    s.bodies.push(body(
        Some("ground".into()),
        BodyKind::Static,
        [0.0, 0.0],
        0.0,
        vec![ring],
    ));
    let rotor_material = MaterialSpec {
        density: Some(1.0),
        friction: Some(0.0),
        ..MaterialSpec::default()
    };
    let rotor_shape = ShapeSpec {
        radius: Some(0.2),
        ..polygon_shape(
            vec![[-0.4, -20.0], [0.4, -20.0], [0.4, 20.0], [-0.4, 20.0]],
            Some(MaterialRef::Inline(rotor_material)),
        )
    };
    s.bodies.push(body(
        Some("rotor".into()),
        BodyKind::Dynamic,
        [0.0, 12.0],
        0.0,
        vec![rotor_shape],
    ));
    s.joints.push(JointSpec {
        motor: Some(MotorSpec {
            speed: SPINNER_MOTOR_SPEED,
            max_torque: f32::MAX,
        }),
        ..JointSpec::revolute(0, 1, [0.0, 12.0])
    });
    let m = Some(MaterialRef::Inline(MaterialSpec {
        density: Some(0.25),
        friction: Some(0.1),
        restitution: Some(0.1),
        ..MaterialSpec::default()
    }));
    let (mut x, mut y) = (-23.0f32, 2.0f32);
    for k in 0..6076 {
        let shape = match k % 3 {
            0 => ShapeSpec {
                kind: "capsule".into(),
                center1: Some([-0.25, 0.0]),
                center2: Some([0.25, 0.0]),
                radius: Some(0.25),
                material: m.clone(),
                ..ShapeSpec::default()
            },
            1 => circle_shape(0.35, m.clone()),
            _ => box_shape(0.35, 0.35, m.clone()),
        };
        s.bodies.push(body(None, BodyKind::Dynamic, [x, y], 0.0, vec![shape]));
        x += 0.5;
        if x >= 23.0 {
            x = -23.0;
            y += 0.5;
        }
    }
    s
}

/// Rows of bodies in a [`scaling_rain`] scene's starting grid.
pub const RAIN_ROWS: usize = 20;

/// Inner half width [m] of the container of a [`scaling_rain`] scene with `n` bodies:
/// 1 m per column of the starting grid, so the width grows ∝ n and the pile depth stays
/// the same for every n.
pub fn rain_half_width(n: usize) -> f32 {
    0.5 * n.div_ceil(RAIN_ROWS) as f32
}

/// A scaling benchmark scene: `n` bodies rain into a wide static container.
///
/// Bodies: 2 of every 3 are boxes of half 0.25 m, every third a disk of radius 0.25 m;
/// density 1 kg/m², friction 0.6, restitution 0. They start at rest in a grid of
/// [`RAIN_ROWS`] rows and ⌈n / 20⌉ columns, 1 m apart (odd rows shifted by 0.5 m), the
/// lowest row 1 m above the floor, each body jittered by up to ±0.15 m sideways and
/// (boxes) turned by up to ±0.5 rad, from a fixed hash of its index (every scene of size n
/// is the same). The rows land one after another and form a pile about 12 bodies
/// (≈ 6 m) deep.
///
/// Container (one static body): floor top at y = 0, inner width 2 · [`rain_half_width`]
/// = ⌈n / 20⌉ m — **∝ n**, so the pile depth, and the contacts per body, do not depend
/// on n — and walls 1 m thick rising to y = 25 m (4 m above the highest start).
/// Gravity (0, −10) m/s², 60 Hz, 4 substeps, **sleep off** (every body is solved every
/// step in every engine, whatever its sleep heuristics), 300 steps (5 s).
pub fn scaling_rain(n: usize) -> SceneFile {
    let mut s = scene(&format!("scaling rain: {n} boxes and disks into a container"), 300);
    s.gravity = [0.0, -10.0];
    s.enable_sleep = false;
    s.materials.insert(
        "grain".into(),
        MaterialSpec {
            density: Some(1.0),
            friction: Some(0.6),
            ..MaterialSpec::default()
        },
    );
    let cols = n.div_ceil(RAIN_ROWS);
    let half_width = rain_half_width(n);
    let wall_top = 25.0f32;
    let mut container = body(Some("container".into()), BodyKind::Static, [0.0, 0.0], 0.0, Vec::new());
    for (center, half) in [
        ([0.0f32, -1.0f32], [half_width + 1.0, 1.0f32]),
        ([-half_width - 0.5, 0.5 * wall_top], [0.5, 0.5 * wall_top]),
        ([half_width + 0.5, 0.5 * wall_top], [0.5, 0.5 * wall_top]),
    ] {
        container.shapes.push(ShapeSpec {
            center: Some(center),
            ..box_shape(half[0], half[1], None)
        });
    }
    s.bodies.push(container);
    // SplitMix64-style hash of the index: a fixed pseudo-random number in [−1, 1).
    let jitter = |k: u64| {
        let mut z = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    for k in 0..n {
        let (row, col) = (k / cols, k % cols);
        let shift = if row % 2 == 1 { 0.5 } else { 0.0 };
        let x = -half_width + 0.25 + shift + col as f32 + 0.15 * jitter(2 * k as u64);
        // Keep a turned box (reach ≤ 0.25 (cos 0.5 + sin 0.5) < 0.34 m) off the walls.
        let x = x.clamp(-half_width + 0.35, half_width - 0.35);
        let y = 1.0 + row as f32;
        let (shape, angle) = if k % 3 == 2 {
            (circle_shape(0.25, named("grain")), 0.0)
        } else {
            (box_shape(0.25, 0.25, named("grain")), 0.5 * jitter(2 * k as u64 + 1))
        };
        s.bodies.push(body(None, BodyKind::Dynamic, [x, y], angle, vec![shape]));
    }
    s
}

/// [`scaling_rain`] with 1 000 bodies (container 50 m wide).
pub fn scaling_rain_1k() -> SceneFile {
    scaling_rain(1000)
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

fn offset_box(hx: f32, hy: f32, center: [f32; 2]) -> ShapeSpec {
    ShapeSpec {
        center: Some(center),
        ..box_shape(hx, hy, None)
    }
}

fn polygon_shape(vertices: Vec<[f32; 2]>, material: Option<MaterialRef>) -> ShapeSpec {
    ShapeSpec {
        kind: "polygon".into(),
        vertices: Some(vertices),
        material,
        ..ShapeSpec::default()
    }
}

/// The static container of Box2D's compounds and junkyard scenes: floor boxes half
/// (0.55, 0.5) at x = −`half_count` … `half_count` step 1, y = 0, and at x = ±`half_count`
/// walls of `wall_boxes` boxes half (0.5, 0.55) at y = 1, 2, …
fn box_container(half_count: i32, wall_boxes: i32) -> BodySpec {
    let mut ground = body(Some("ground".into()), BodyKind::Static, [0.0, 0.0], 0.0, Vec::new());
    for i in -half_count..=half_count {
        ground.shapes.push(offset_box(0.55, 0.5, [i as f32, 0.0]));
    }
    for x in [-half_count as f32, half_count as f32] {
        for j in 1..=wall_boxes {
            ground.shapes.push(offset_box(0.5, 0.55, [x, j as f32]));
        }
    }
    ground
}

/// Inner faces of the compounds container: walls at x = ±40 m (half width 0.5 m) and the
/// ground's top at y = 0.5 m.
pub const COMPOUNDS_INNER_HALF_WIDTH: f32 = 39.5;

/// Box2D v3's compounds benchmark scene (`CreateCompounds`, shared/SCENES.md §2): 3 000
/// bodies of two triangles each fall into a container of static boxes.
pub fn compounds() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark compounds: 3 000 two-triangle bodies fall into a box container",
        500,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = true;
    s.materials.insert(
        "triangle".into(),
        MaterialSpec {
            density: Some(1.0),
            friction: Some(0.5),
            ..MaterialSpec::default()
        },
    );
    let mut ground = box_container(40, 100);
    ground.shapes.push(ShapeSpec {
        kind: "segment".into(),
        point1: Some([-800.0, -80.0]),
        point2: Some([800.0, -80.0]),
        ..ShapeSpec::default()
    });
    s.bodies.push(ground);
    let left = vec![[-1.0, 0.0], [0.5, 1.0], [0.0, 2.0]];
    let right = vec![[1.0, 0.0], [-0.5, 1.0], [0.0, 2.0]];
    let mut shift = 0.25f32;
    for i in 0..20 {
        for j in 0..150 {
            let p = [2.0 * i as f32 - 19.0 + shift, 2.25 * j as f32 + 5.575];
            shift = -shift;
            s.bodies.push(body(
                None,
                BodyKind::Dynamic,
                p,
                0.0,
                vec![
                    polygon_shape(left.clone(), named("triangle")),
                    polygon_shape(right.clone(), named("triangle")),
                ],
            ));
        }
    }
    s
}

/// Centre [m] of the washer's ring at the start.
pub const WASHER_CENTER: [f32; 2] = [0.0, 10.0];

/// Inner radius [m] of the washer's rim (its paddles reach in to 14 m).
pub const WASHER_RIM_INNER: f32 = 16.0;

/// Box2D v3's washer benchmark scene (`CreateWasher`, shared/SCENES.md §2): 8 100 small
/// boxes tumbled by a kinematic ring of 36 rim quads and 4 paddles turning at 25°/s.
/// Box2D's scene enables hit events on the boxes; no engine reports them here.
pub fn washer() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark washer: 8 100 boxes in a kinematic ring turning at 25°/s",
        500,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = true;
    let mut ring = body(Some("ring".into()), BodyKind::Kinematic, WASHER_CENTER, 0.0, Vec::new());
    ring.angular_velocity = 25f32.to_radians();
    ring.linear_velocity = [0.001, -0.002];
    let arc = |r0: f32, r1: f32, a0: f32, a1: f32| {
        let (a0, a1) = (a0.to_radians(), a1.to_radians());
        vec![
            [r0 * a0.cos(), r0 * a0.sin()],
            [r1 * a0.cos(), r1 * a0.sin()],
            [r1 * a1.cos(), r1 * a1.sin()],
            [r0 * a1.cos(), r0 * a1.sin()],
        ]
    };
    for m in 0..36 {
        let a = 10.0 * m as f32;
        ring.shapes
            .push(polygon_shape(arc(WASHER_RIM_INNER, 18.0, a - 1.0, a + 11.0), None));
    }
    for m in [0, 9, 18, 27] {
        let a = 10.0 * m as f32;
        ring.shapes
            .push(polygon_shape(arc(14.0, WASHER_RIM_INNER, a, a + 10.0), None));
    }
    s.bodies.push(ring);
    for i in 0..90 {
        for j in 0..90 {
            let p = [-9.9 + 0.21 * j as f32, 0.1 + 0.21 * i as f32];
            s.bodies
                .push(body(None, BodyKind::Dynamic, p, 0.0, vec![box_shape(0.1, 0.1, None)]));
        }
    }
    s
}

/// Inner faces of the junkyard container: walls at x = ±80 m (half width 0.5 m).
pub const JUNKYARD_INNER_HALF_WIDTH: f32 = 79.5;

/// The junkyard pusher's target x [m] before step `n` (shared/SCENES.md §2
/// `StepJunkyard`): 60 sin(0.2 · n/60), y = 0, no rotation.
pub fn junkyard_pusher_x(n: u32) -> f32 {
    60.0 * (0.2 * n as f32 / 60.0).sin()
}

/// Index of junkyard's pusher among its bodies (the last: after the ground and the 8 000
/// pentagons).
pub const JUNKYARD_PUSHER: usize = 8001;

/// Box2D v3's junkyard benchmark scene (`CreateJunkyard`, shared/SCENES.md §2): 8 000
/// pentagons in a container of static boxes, stirred by a kinematic pusher (the last
/// body, [`JUNKYARD_PUSHER`]) that the step hook [`junkyard_hook`] drives to
/// [`junkyard_pusher_x`]. The scene file alone has the pusher at rest; the benchmark and
/// the CLI run the hook before every step.
pub fn junkyard() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark junkyard: 8 000 pentagons stirred by a kinematic pusher",
        800,
    );
    s.gravity = [0.0, -10.0];
    s.enable_sleep = true;
    s.bodies.push(box_container(80, 50));
    let step = std::f32::consts::PI * (5f32.sqrt() - 1.0);
    let pentagon: Vec<[f32; 2]> = (0..5)
        .map(|n| {
            let (sn, cs) = (n as f32 * step).sin_cos();
            [0.25 * cs, 0.25 * sn]
        })
        .collect();
    let mut shift = -0.1f32;
    for i in 0..200 {
        for j in 0..40 {
            let p = [0.75 * i as f32 - 75.0 + shift, j as f32 + 15.0];
            shift = -shift;
            s.bodies.push(body(
                None,
                BodyKind::Dynamic,
                p,
                0.0,
                vec![polygon_shape(pentagon.clone(), None)],
            ));
        }
    }
    s.bodies.push(body(
        Some("pusher".into()),
        BodyKind::Kinematic,
        [0.0, 0.0],
        0.0,
        vec![offset_box(2.0, 4.0, [0.0, 4.0])],
    ));
    s
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
mod benchmark_scene_tests {
    use super::*;

    #[test]
    fn tumbler_benchmark_matches_scenes_md() {
        let s = tumbler_benchmark();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (750, [0.0, -10.0], true));
        assert_eq!(s.bodies.len(), 2 + 45 * 45);
        assert_eq!((s.bodies[0].kind, s.bodies[0].shapes.len()), (BodyKind::Static, 0));
        let drum = &s.bodies[1];
        assert_eq!(drum.kind, BodyKind::Dynamic);
        assert_eq!(drum.position, [0.0, 10.0]);
        assert_eq!(drum.shapes.len(), 4);
        assert_eq!(s.shape_material(&drum.shapes[0]).density, 50.0);
        assert_eq!(s.joints.len(), 1);
        let j = &s.joints[0];
        assert_eq!(j.anchor, [0.0, 10.0]);
        let motor = j.motor.expect("motor");
        assert!((motor.speed - 0.436).abs() < 1e-3 && motor.max_torque == 1e8);
        let last = s.bodies.last().expect("boxes");
        assert_eq!(last.kind, BodyKind::Dynamic);
        assert!((last.position[0] - (-9.0 + 0.4 * 44.0)).abs() < 1e-5);
        assert!((last.position[1] - (1.0 + 0.4 * 44.0)).abs() < 1e-5);
        let m = s.shape_material(&last.shapes[0]);
        assert_eq!((m.density, m.friction_static, m.friction_dynamic), (1.0, 0.6, 0.6));
        assert_eq!(last.shapes[0].half_extents, Some([0.125, 0.125]));
    }

    #[test]
    fn joint_grid_matches_scenes_md() {
        let s = joint_grid();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (500, [0.0, -10.0], false));
        assert_eq!(s.bodies.len(), 10_000);
        assert_eq!(s.joints.len(), 19_800);
        let statics: Vec<[f32; 2]> = s
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Static)
            .map(|b| b.position)
            .collect();
        assert_eq!(statics, (47..=53).map(|k| [k as f32, 0.0]).collect::<Vec<_>>());
        // Body (k, i) is index 100 k + i at (k, −i); its vertical joint's anchor is 0.5 m up.
        assert_eq!(s.bodies[100 * 3 + 7].position, [3.0, -7.0]);
        let f = s.bodies[0].shapes[0].filter.expect("filter");
        assert!(f.category & f.mask == 0, "circles never collide with each other");
        // The whole scene builds: no contact at all after a step.
        let mut built = s.build().expect("builds");
        built.world.step(built.dt).expect("steps");
        assert_eq!(built.world.joint_count(), 19_800);
        assert_eq!(built.world.contact_count(), 0);
    }

    #[test]
    fn spinner_matches_scenes_md() {
        let s = spinner();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (500, [0.0, -10.0], true));
        assert_eq!(s.bodies.len(), 2 + 6076);
        assert_eq!(s.bodies[0].shapes.len(), 1);
        assert_eq!(s.bodies[0].shapes[0].kind, "chain");
        assert_eq!(s.bodies[0].shapes[0].closed, Some(true));
        let ring = s.bodies[0].shapes[0].points.as_ref().expect("points");
        assert_eq!(ring.len(), 360);
        // Clockwise: point 1 is at angle −1°.
        let a1 = (ring[1][1] - 32.0).atan2(ring[1][0]);
        assert!((a1 + 1f32.to_radians()).abs() < 1e-5, "{a1}");
        let motor = s.joints[0].motor.expect("motor");
        assert_eq!((motor.speed, s.joints[0].anchor), (5.0, [0.0, 12.0]));
        // 92 bodies per row from (−23, 2): the 93rd starts the second row.
        assert_eq!(s.bodies[2 + 92].position, [-23.0, 2.5]);
        let kinds: Vec<&str> = s.bodies[2..5].iter().map(|b| b.shapes[0].kind.as_str()).collect();
        assert_eq!(kinds, ["capsule", "circle", "box"]);
    }

    #[test]
    fn compounds_matches_scenes_md() {
        let s = compounds();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (500, [0.0, -10.0], true));
        assert_eq!(s.bodies.len(), 1 + 3000);
        let ground = &s.bodies[0];
        assert_eq!(ground.kind, BodyKind::Static);
        // 81 floor boxes, 2 × 100 wall boxes, one catch segment.
        assert_eq!(ground.shapes.len(), 81 + 200 + 1);
        assert_eq!(ground.shapes[0].center, Some([-40.0, 0.0]));
        assert_eq!(ground.shapes[0].half_extents, Some([0.55, 0.5]));
        assert_eq!(ground.shapes[81].center, Some([-40.0, 1.0]));
        assert_eq!(ground.shapes[81].half_extents, Some([0.5, 0.55]));
        assert_eq!(ground.shapes[281].point1, Some([-800.0, -80.0]));
        // Column-major creation; the shift alternates +0.25, -0.25, ... in creation order.
        let (first, second, col1) = (&s.bodies[1], &s.bodies[2], &s.bodies[1 + 150]);
        assert_eq!(first.position, [-19.0 + 0.25, 5.575]);
        assert_eq!(second.position, [-19.0 - 0.25, 2.25 + 5.575]);
        assert_eq!(col1.position, [2.0 - 19.0 + 0.25, 5.575]);
        assert_eq!(first.shapes.len(), 2);
        assert_eq!(
            first.shapes[0].vertices,
            Some(vec![[-1.0, 0.0], [0.5, 1.0], [0.0, 2.0]])
        );
        assert_eq!(
            first.shapes[1].vertices,
            Some(vec![[1.0, 0.0], [-0.5, 1.0], [0.0, 2.0]])
        );
        let m = s.shape_material(&first.shapes[0]);
        assert_eq!((m.density, m.friction_static, m.friction_dynamic), (1.0, 0.5, 0.5));
    }

    #[test]
    fn junkyard_matches_scenes_md() {
        let s = junkyard();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (800, [0.0, -10.0], true));
        assert_eq!(s.bodies.len(), 1 + 8000 + 1);
        let ground = &s.bodies[0];
        assert_eq!(ground.shapes.len(), 161 + 100);
        assert_eq!(ground.shapes[0].center, Some([-80.0, 0.0]));
        assert_eq!(ground.shapes[161].center, Some([-80.0, 1.0]));
        // Column-major; the shift alternates -0.1, +0.1, ... in creation order.
        assert_eq!(s.bodies[1].position, [-75.0 - 0.1, 15.0]);
        assert_eq!(s.bodies[2].position, [-75.0 + 0.1, 16.0]);
        assert_eq!(s.bodies[1 + 40].position, [0.75 - 75.0 - 0.1, 15.0]);
        let v = s.bodies[1].shapes[0].vertices.as_ref().expect("pentagon");
        assert_eq!(v.len(), 5);
        for (n, p) in v.iter().enumerate() {
            let a = n as f32 * std::f32::consts::PI * (5f32.sqrt() - 1.0);
            assert!((p[0] - 0.25 * a.cos()).abs() < 1e-6 && (p[1] - 0.25 * a.sin()).abs() < 1e-6);
        }
        let pusher = s.bodies.last().expect("pusher");
        assert_eq!(s.bodies.len() - 1, JUNKYARD_PUSHER);
        assert_eq!((pusher.kind, pusher.position), (BodyKind::Kinematic, [0.0, 0.0]));
        assert_eq!(pusher.shapes[0].half_extents, Some([2.0, 4.0]));
        assert_eq!(pusher.shapes[0].center, Some([0.0, 4.0]));
        // The hook's target: 60 sin(0.2 n / 60), a full swing of ±60 m every 2π·300 steps.
        assert_eq!(junkyard_pusher_x(0), 0.0);
        assert!((junkyard_pusher_x(300) - 60.0 * 1f32.sin()).abs() < 1e-4);
    }

    #[test]
    fn washer_matches_scenes_md() {
        let s = washer();
        assert_eq!((s.steps, s.gravity, s.enable_sleep), (500, [0.0, -10.0], true));
        assert_eq!(s.bodies.len(), 1 + 90 * 90);
        let ring = &s.bodies[0];
        assert_eq!(ring.kind, BodyKind::Kinematic);
        assert_eq!(ring.position, [0.0, 10.0]);
        assert!((ring.angular_velocity - 25f32.to_radians()).abs() < 1e-6);
        assert_eq!(ring.linear_velocity, [0.001, -0.002]);
        assert_eq!(ring.shapes.len(), 36 + 4);
        // Every rim quad spans radii 16..18 and 12°; every paddle 14..16 and 10°.
        for (k, shape) in ring.shapes.iter().enumerate() {
            let v = shape.vertices.as_ref().expect("polygon");
            let radii: Vec<f32> = v.iter().map(|p| (p[0] * p[0] + p[1] * p[1]).sqrt()).collect();
            let (lo, hi) = if k < 36 { (16.0, 18.0) } else { (14.0, 16.0) };
            for r in radii {
                assert!((r - lo).abs() < 1e-4 || (r - hi).abs() < 1e-4, "shape {k}: radius {r}");
            }
            let a = |p: [f32; 2]| p[1].atan2(p[0]);
            let span = (a(v[2]) - a(v[0])).rem_euclid(std::f32::consts::TAU).to_degrees();
            let want = if k < 36 { 12.0 } else { 10.0 };
            assert!((span - want).abs() < 1e-3, "shape {k}: span {span}°");
        }
        let last = s.bodies.last().expect("boxes");
        assert!((last.position[0] - (-9.9 + 0.21 * 89.0)).abs() < 1e-5);
        assert!((last.position[1] - (0.1 + 0.21 * 89.0)).abs() < 1e-5);
        assert_eq!(last.shapes[0].half_extents, Some([0.1, 0.1]));
        // The boxes start inside the rim (r < 16 m; a box reaches 0.15 m from its centre).
        for b in &s.bodies[1..] {
            let d = ((b.position[0] - 0.0).powi(2) + (b.position[1] - 10.0).powi(2)).sqrt();
            assert!(d + 0.15 < WASHER_RIM_INNER, "box at {:?} starts in the rim", b.position);
        }
    }

    #[test]
    fn scaling_rain_starts_inside_its_container_without_overlaps() {
        for n in [1000, 4000, 1234] {
            let s = scaling_rain(n);
            assert!(s.validate().is_ok());
            assert_eq!(s.bodies.len(), n + 1);
            let hw = rain_half_width(n);
            assert_eq!(hw, 0.5 * n.div_ceil(RAIN_ROWS) as f32);
            let pos: Vec<[f32; 2]> = s.bodies[1..].iter().map(|b| b.position).collect();
            // A body reaches at most 0.25 · (cos 0.5 + sin 0.5) < 0.34 m from its centre.
            for p in &pos {
                assert!(p[0].abs() <= hw - 0.345 && p[1] >= 1.0, "{p:?}");
            }
            for (k, a) in pos.iter().enumerate() {
                for b in &pos[k + 1..] {
                    let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                    assert!(d > 0.68, "{a:?} {b:?}");
                }
            }
        }
        assert_eq!(scaling_rain(1000), scaling_rain_1k());
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

// ---------------------------------------------------------------------------------------
// Box2D v3's rain benchmark (`CreateRain`, `StepRain`, the ragdoll of `shared/human.c`).

/// Columns of ragdoll groups in Box2D's rain benchmark.
pub const RAGDOLL_RAIN_COLUMNS: usize = 40;
/// Rows of ragdoll groups (one static shelf per row).
pub const RAGDOLL_RAIN_ROWS: usize = 5;
/// Ragdolls per group.
pub const RAGDOLL_RAIN_PER_GROUP: usize = 5;
/// Bodies per ragdoll.
pub const RAGDOLL_BODIES: usize = 11;
/// The rain's hook acts every this many steps.
pub const RAGDOLL_RAIN_INTERVAL: u32 = 8;
/// Half extent [m] of the shelves' boxes.
const RAGDOLL_SHELF_HALF: f32 = 0.25;
/// Half the length [m] of a shelf: boxes centred at x = −125 … 125.
pub const RAGDOLL_RAIN_SHELF_HALF_LENGTH: f32 = 125.0 + RAGDOLL_SHELF_HALF;

/// Height [m] of shelf `row`'s box centres (y = 0, 45, 90, 135, 180).
pub fn ragdoll_rain_shelf_y(row: usize) -> f32 {
    45.0 * row as f32
}

/// Top face [m] of shelf `row`.
pub fn ragdoll_rain_shelf_top(row: usize) -> f32 {
    ragdoll_rain_shelf_y(row) + RAGDOLL_SHELF_HALF
}

/// Box2D v3's rain benchmark world (SCENES.md §2, `CreateRain`): one static body with 5
/// shelves (y = 0, 45, …, 180 m) of 501 boxes half 0.25 m each at x = −125 … 125 step 0.5;
/// gravity (0, −10) m/s², sleep on, 1 000 steps. The ragdolls arrive through the step hook:
/// every [`RAGDOLL_RAIN_INTERVAL`] steps one column of [`ragdoll_rain_column`] is created,
/// the oldest destroyed and created again once all 40 exist.
pub fn ragdoll_rain() -> SceneFile {
    let mut s = scene(
        "Box2D v3 benchmark rain: ragdolls falling onto five shelves (the ragdolls come from the step hook)",
        1000,
    );
    s.gravity = [0.0, -10.0];
    let mut ground = body(Some("ground".into()), BodyKind::Static, [0.0, 0.0], 0.0, Vec::new());
    for row in 0..RAGDOLL_RAIN_ROWS {
        add_shelf(&mut ground, 250, ragdoll_rain_shelf_y(row));
    }
    s.bodies.push(ground);
    s
}

/// A shelf of the rain's boxes (half [`RAGDOLL_SHELF_HALF`]) centred at x = −0.5 k … 0.5 k
/// for k = `half_count` (2k + 1 boxes), at height `y` [m].
fn add_shelf(ground: &mut BodySpec, half_count: i32, y: f32) {
    for i in -half_count..=half_count {
        ground
            .shapes
            .push(offset_box(RAGDOLL_SHELF_HALF, RAGDOLL_SHELF_HALF, [0.5 * i as f32, y]));
    }
}

/// Ten of the rain benchmark's ragdolls ([`ragdoll`]) in two groups of five (the five of a
/// group collide with each other; the same slot of the two groups shares a filter group),
/// dropped from 5 m onto a shelf of the rain's boxes 20.5 m long; gravity (0, −10) m/s²,
/// 240 steps.
pub fn ragdolls() -> SceneFile {
    let mut s = scene(
        "Box2D's ragdoll: 10 of them dropped 5 m onto a shelf of boxes (limited, sprung, frictional joints)",
        240,
    );
    s.gravity = [0.0, -10.0];
    let mut ground = body(Some("shelf".into()), BodyKind::Static, [0.0, 0.0], 0.0, Vec::new());
    add_shelf(&mut ground, 20, 0.0);
    s.bodies.push(ground);
    for x in [-3.0, 0.75] {
        for k in 0..RAGDOLL_RAIN_PER_GROUP {
            ragdoll(&mut s, [x + 0.5 * k as f32, 5.0], -(k as i32 + 1));
        }
    }
    s
}

/// What the rain's hook does before step `n`: `None`, or the column to (re)create and
/// whether it exists already (then it is destroyed first). Box2D's `StepRain`: every 8
/// steps (from step 0), the next of the 40 columns while they are not all there, then the
/// oldest in turn.
pub fn ragdoll_rain_action(n: u32) -> Option<(usize, bool)> {
    if !n.is_multiple_of(RAGDOLL_RAIN_INTERVAL) {
        return None;
    }
    let k = (n / RAGDOLL_RAIN_INTERVAL) as usize;
    Some((k % RAGDOLL_RAIN_COLUMNS, k >= RAGDOLL_RAIN_COLUMNS))
}

/// One column of Box2D's rain: for each of the 5 rows a group of 5 ragdolls, 0.5 m apart
/// in x from the group point (−125 + 6.25 (column + ½), 40 + 45 row); ragdoll k of a group
/// has filter group −(k+1), so ragdolls of one slot never collide (nor does a ragdoll with
/// itself), those of different slots do. Bodies in order row, ragdoll, bone
/// ([`ragdoll`]); 275 bodies, 250 joints; joints refer to bodies of this file.
pub fn ragdoll_rain_column(column: usize) -> SceneFile {
    let mut s = scene("one column of ragdolls of Box2D's rain benchmark", 1);
    s.gravity = [0.0, -10.0];
    let x0 = -125.0 + 6.25 * (column as f32 + 0.5);
    for row in 0..RAGDOLL_RAIN_ROWS {
        let y = 40.0 + 45.0 * row as f32;
        for k in 0..RAGDOLL_RAIN_PER_GROUP {
            ragdoll(&mut s, [x0 + 0.5 * k as f32, y], -(k as i32 + 1));
        }
    }
    s
}

/// Box2D's ragdoll (`CreateHuman` at scale 1, friction torque 0.05 N·m, spring 5 Hz,
/// ζ 0.5): 11 capsule bodies (the shins with a rounded foot polygon) on 10 revolute joints
/// with limits, joint friction (a motor at speed 0 with max torque 0.05 N·m × the bone's
/// friction scale) and a spring towards the standing pose, appended to `s` with its
/// origin (between the feet) at `at`. Bodies: sleep threshold 0.1 m/s, density 1 kg/m²,
/// friction 0.2 (feet 0.05), category 0x2, mask 0x1 | 0x2 (feet: 0x1, the ground only),
/// the given filter group; head and forearms have linear damping 0.1 /s. Joint A is the
/// parent bone, B the child; the forearm joints' angle is measured from B turned 0.25π
/// relative to A (Box2D turns joint frame A).
fn ragdoll(s: &mut SceneFile, at: [f32; 2], group: i32) {
    use core::f32::consts::PI;
    let material = |friction: f32| {
        Some(MaterialRef::Inline(MaterialSpec {
            density: Some(1.0),
            friction: Some(friction),
            ..MaterialSpec::default()
        }))
    };
    let filter = |mask: u64| {
        Some(FilterSpec {
            category: 0x2,
            mask,
            group,
        })
    };
    let capsule = |y1: f32, y2: f32, r: f32| ShapeSpec {
        kind: "capsule".into(),
        center1: Some([0.0, y1]),
        center2: Some([0.0, y2]),
        radius: Some(r),
        material: material(0.2),
        filter: filter(0x1 | 0x2),
        ..ShapeSpec::default()
    };
    let foot = ShapeSpec {
        kind: "polygon".into(),
        vertices: Some(vec![[-0.03, -0.185], [0.11, -0.185], [0.11, -0.16], [-0.03, -0.14]]),
        radius: Some(0.015),
        material: material(0.05),
        filter: filter(0x1),
        ..ShapeSpec::default()
    };
    let first = s.bodies.len();
    // (height of the body origin [m], shapes, linear damping [1/s]) per bone, in Box2D's
    // bone order: hip, torso, head, upper/lower left leg, upper/lower right leg, upper/lower
    // left arm, upper/lower right arm.
    let leg_upper = || vec![capsule(-0.125, 0.125, 0.06)];
    let leg_lower = || vec![capsule(-0.155, 0.125, 0.045), foot.clone()];
    let arm_upper = || vec![capsule(-0.125, 0.125, 0.035)];
    let arm_lower = || vec![capsule(-0.125, 0.125, 0.03)];
    let bones: [(f32, Vec<ShapeSpec>, f32); RAGDOLL_BODIES] = [
        (0.95, vec![capsule(-0.02, 0.02, 0.095)], 0.0),
        (1.2, vec![capsule(-0.135, 0.135, 0.09)], 0.0),
        (1.475, vec![capsule(-0.038, 0.039, 0.075)], 0.1),
        (0.775, leg_upper(), 0.0),
        (0.475, leg_lower(), 0.0),
        (0.775, leg_upper(), 0.0),
        (0.475, leg_lower(), 0.0),
        (1.225, arm_upper(), 0.0),
        (0.975, arm_lower(), 0.1),
        (1.225, arm_upper(), 0.0),
        (0.975, arm_lower(), 0.1),
    ];
    for (y, shapes, damping) in bones {
        let mut b = body(None, BodyKind::Dynamic, [at[0], at[1] + y], 0.0, shapes);
        b.linear_damping = damping;
        b.sleep_threshold = Some(0.1);
        s.bodies.push(b);
    }
    // (parent, child, pivot height [m], limits [×π rad], friction scale, reference angle).
    let joints: [(usize, usize, f32, [f32; 2], f32, f32); RAGDOLL_BODIES - 1] = [
        (0, 1, 1.0, [-0.25, 0.0], 0.5, 0.0),
        (1, 2, 1.4, [-0.3, 0.1], 0.25, 0.0),
        (0, 3, 0.9, [-0.05, 0.4], 1.0, 0.0),
        (3, 4, 0.625, [-0.5, -0.02], 0.5, 0.0),
        (0, 5, 0.9, [-0.05, 0.4], 1.0, 0.0),
        (5, 6, 0.625, [-0.5, -0.02], 0.5, 0.0),
        (1, 7, 1.35, [-0.1, 0.8], 0.5, 0.0),
        (7, 8, 1.1, [-0.2, 0.3], 0.1, 0.25 * PI),
        (1, 9, 1.35, [-0.1, 0.8], 0.5, 0.0),
        (9, 10, 1.1, [-0.2, 0.3], 0.1, 0.25 * PI),
    ];
    for (parent, child, y, [lower, upper], friction_scale, reference) in joints {
        s.joints.push(JointSpec {
            limit: Some([lower * PI, upper * PI]),
            motor: Some(MotorSpec {
                speed: 0.0,
                max_torque: 0.05 * friction_scale,
            }),
            spring: Some(SpringSpec {
                hertz: 5.0,
                damping_ratio: 0.5,
            }),
            reference_angle: (reference != 0.0).then_some(reference),
            ..JointSpec::revolute(first + parent, first + child, [at[0], at[1] + y])
        });
    }
}
