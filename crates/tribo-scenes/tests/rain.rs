//! Box2D's rain benchmark as Tribo runs it: ragdolls (11 capsule bodies on 10 limited,
//! sprung, frictional revolute joints) dropped 40 m onto static shelves.

use tribo::{BodyId, World};
use tribo_scenes::format::{JointSpec, SceneFile};
use tribo_scenes::scenes::{
    ragdoll_rain, ragdoll_rain_action, ragdoll_rain_column, ragdoll_rain_shelf_top, RAGDOLL_BODIES,
    RAGDOLL_RAIN_COLUMNS, RAGDOLL_RAIN_PER_GROUP, RAGDOLL_RAIN_ROWS,
};

/// Box2D's `StepRain` schedule over its 1 000 steps: 125 actions (one every 8 steps from
/// step 0), the 40 columns all present from step 312 on, the first re-creation (of column
/// 0) at step 320, and every column re-created in turn afterwards.
#[test]
fn the_hook_schedule_is_box2d_s() {
    let actions: Vec<(u32, usize, bool)> = (0..1000)
        .filter_map(|n| ragdoll_rain_action(n).map(|(c, e)| (n, c, e)))
        .collect();
    assert_eq!(actions.len(), 125);
    let created = actions.iter().filter(|a| !a.2).count();
    assert_eq!(created, RAGDOLL_RAIN_COLUMNS);
    assert_eq!(actions[RAGDOLL_RAIN_COLUMNS - 1], (312, 39, false));
    assert_eq!(actions[RAGDOLL_RAIN_COLUMNS], (320, 0, true));
    assert_eq!(actions[124], (992, 124 % 40, true));
}

/// A column: 5 rows × 5 ragdolls × 11 bodies = 275 bodies and 250 joints; with the
/// ground, all 40 columns make Box2D's end-of-run 11 001 bodies and 10 000 joints.
#[test]
fn a_column_has_box2d_s_counts() {
    let c = ragdoll_rain_column(7);
    assert!(c.validate().is_ok());
    let per_column = RAGDOLL_RAIN_ROWS * RAGDOLL_RAIN_PER_GROUP;
    assert_eq!(c.bodies.len(), per_column * RAGDOLL_BODIES);
    assert_eq!(c.joints.len(), per_column * (RAGDOLL_BODIES - 1));
    assert_eq!(1 + 40 * c.bodies.len(), 11_001);
    assert_eq!(40 * c.joints.len(), 10_000);
    let ground = ragdoll_rain();
    assert_eq!(ground.bodies.len(), 1);
    assert_eq!(ground.bodies[0].shapes.len(), 5 * 501);
}

/// A joint's `reference_angle` sets where its angle is 0: two bodies at the same rotation
/// with reference 0.25π start at joint angle −0.25π; without it, at 0.
#[test]
fn the_reference_angle_is_where_the_joint_angle_is_zero() {
    let mut scene = ragdoll_rain_column(0);
    scene.bodies.truncate(RAGDOLL_BODIES);
    scene.joints.truncate(RAGDOLL_BODIES - 1);
    let mut world = World::new(Default::default()).unwrap();
    scene.add_to(&mut world).unwrap();
    let ids = world.joint_ids();
    // Joints 7 and 9 are the forearms' (Box2D turns their frame A by 0.25π).
    for (k, &id) in ids.iter().enumerate() {
        let angle = world.revolute_angle(id).unwrap();
        let expected = if k == 7 || k == 9 {
            -0.25 * core::f32::consts::PI
        } else {
            0.0
        };
        assert!((angle - expected).abs() < 1e-6, "joint {k}: {angle} vs {expected}");
    }
    // A bad reference angle is refused with its path, and nothing is added.
    let mut bad = SceneFile {
        joints: vec![JointSpec {
            reference_angle: Some(f32::NAN),
            ..scene.joints[0].clone()
        }],
        ..scene.clone()
    };
    bad.joints.truncate(1);
    let before = world.body_count();
    let err = bad.add_to(&mut world).unwrap_err();
    assert_eq!(err.path, "joints[0].reference_angle", "{err}");
    assert_eq!(world.body_count(), before);
}

/// Two columns dropped 40 m onto their shelves (at about 28 m/s) and left 7 s: no body
/// ends below its shelf's top (a body's origin lies inside its capsule, at least the
/// thinnest capsule's 3 cm radius above a surface it rests on, less the few millimetres a
/// soft contact sinks: a body below the top went through the shelf); the joints hold
/// (anchors within 1 cm: the soft joint lets a 0.05 kg forearm hang F/(m ω²) ≈ 0.1 mm at
/// 60 Hz, so 1 cm is a torn joint); every joint angle within its limits (0.02 rad of
/// slack for the soft limit) measured from its reference; and with the ragdolls' sleep
/// threshold of 0.1 m/s, every body asleep.
#[test]
fn ragdolls_land_on_their_shelves_and_rest_jointed() {
    let built = ragdoll_rain().build().unwrap();
    let mut world = built.world;
    let mut bodies: Vec<BodyId> = Vec::new();
    for column in [3, 20] {
        bodies.extend(ragdoll_rain_column(column).add_to(&mut world).unwrap());
    }
    // The fall takes √(2·40 m / 10 m/s²) = 2.8 s; the piles come to rest and, after the
    // 0.5 s below the threshold sleep needs, all sleep by 6 s (measured): 7 s.
    for _ in 0..420 {
        world.step(built.dt).unwrap();
    }
    let per_row = RAGDOLL_RAIN_PER_GROUP * RAGDOLL_BODIES;
    let per_column = RAGDOLL_RAIN_ROWS * per_row;
    let mut lowest = f32::INFINITY;
    for (k, &id) in bodies.iter().enumerate() {
        let row = (k % per_column) / per_row;
        let p = world.body_position(id).unwrap();
        let above = p.y - ragdoll_rain_shelf_top(row);
        lowest = lowest.min(above);
        assert!(above > 0.0, "body {k} (row {row}) is {above} m below its shelf's top");
        assert!(world.body_is_awake(id) == Ok(false), "body {k} still awake");
    }
    assert!(lowest < 0.2, "nothing rests on a shelf? lowest {lowest}");
    for id in world.joint_ids() {
        let (pa, pb) = world.joint_world_anchors(id).unwrap();
        assert!(
            (pa - pb).length() < 0.01,
            "joint anchors {} m apart",
            (pa - pb).length()
        );
        let def = world.revolute_joint_def(id).unwrap();
        let angle = world.revolute_angle(id).unwrap();
        assert!(
            angle > def.lower_angle - 0.02 && angle < def.upper_angle + 0.02,
            "angle {angle} outside [{}, {}]",
            def.lower_angle,
            def.upper_angle
        );
    }
}

/// Creating and destroying bodies and joints between steps (the rain's churn: slots and
/// ids reused) keeps results bit-identical for any worker count: three columns of
/// ragdolls, the first destroyed and created again after 150 steps, run 220 steps (the
/// other two land on their shelves at ~170) on 1, 2 and 3 workers; every body's pose
/// compared bit for bit.
#[test]
fn churn_is_bit_identical_for_any_worker_count() {
    let run = |workers: u32| {
        let built = ragdoll_rain().build().unwrap();
        let mut world = built.world;
        let def = tribo::WorldDef {
            workers,
            ..*world.def()
        };
        world.set_def(def).unwrap();
        let mut columns: Vec<Vec<BodyId>> = (0..3)
            .map(|c| ragdoll_rain_column(c).add_to(&mut world).unwrap())
            .collect();
        let mut out = Vec::new();
        for step in 0..220 {
            if step == 150 {
                for id in columns[0].drain(..) {
                    world.destroy_body(id).unwrap();
                }
                columns[0] = ragdoll_rain_column(0).add_to(&mut world).unwrap();
            }
            world.step(built.dt).unwrap();
        }
        for id in columns.iter().flatten() {
            let p = world.body_position(*id).unwrap();
            out.push((p.x.to_bits(), p.y.to_bits(), world.body_angle(*id).unwrap().to_bits()));
        }
        out
    };
    let one = run(1);
    assert_eq!(one.len(), 3 * 275);
    assert_eq!(one, run(2), "2 workers differ");
    assert_eq!(one, run(3), "3 workers differ");
}
