//! Public-API behaviour: bad input is rejected with an error and changes nothing, stale ids
//! are caught, events and queries report what happened, sleeping works, runs are
//! deterministic.

use tribo::{
    Aabb, BodyDef, BodyType, Capsule, Circle, Error, Filter, Material, Polygon, QueryFilter, Segment, Shape, ShapeDef,
    Vec2, World, WorldDef,
};

const DT: f32 = 1.0 / 60.0;

fn ground(world: &mut World) -> tribo::BodyId {
    let g = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
    world
        .create_shape(
            g,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(50.0, 1.0).unwrap()),
        )
        .unwrap();
    g
}

fn unit_box() -> Shape {
    Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap())
}

/// A snapshot of every body's state, for "nothing changed" and determinism checks.
fn snapshot(world: &World) -> Vec<[u32; 6]> {
    world
        .body_ids()
        .into_iter()
        .map(|b| {
            let p = world.body_position(b).unwrap();
            let v = world.body_linear_velocity(b).unwrap();
            [
                p.x.to_bits(),
                p.y.to_bits(),
                world.body_angle(b).unwrap().to_bits(),
                v.x.to_bits(),
                v.y.to_bits(),
                world.body_angular_velocity(b).unwrap().to_bits(),
            ]
        })
        .collect()
}

fn busy_world() -> (World, tribo::BodyId) {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5))).unwrap();
    world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    (world, b)
}

#[test]
fn non_finite_and_out_of_range_input_is_rejected_and_changes_nothing() {
    let (mut world, b) = busy_world();
    let before = snapshot(&world);
    let (bodies, shapes) = (world.body_count(), world.shape_count());
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let bad_vec = [Vec2::new(nan, 0.0), Vec2::new(0.0, inf), Vec2::new(-inf, 1.0)];

    for v in bad_vec {
        assert!(world.create_body(&BodyDef::dynamic(v)).is_err());
        assert!(world.set_body_transform(b, v, 0.0).is_err());
        assert!(world.set_body_linear_velocity(b, v).is_err());
        assert!(world.apply_force(b, v, Vec2::ZERO, true).is_err());
        assert!(world.apply_force(b, Vec2::X, v, true).is_err());
        assert!(world.apply_linear_impulse(b, v, Vec2::ZERO, true).is_err());
        assert!(world.apply_linear_impulse_to_center(b, v, true).is_err());
        assert!(world.apply_force_to_center(b, v, true).is_err());
        assert!(world.set_body_constant_force(b, v).is_err());
        assert!(world.set_gravity(v).is_err());
        assert!(world.cast_ray_closest(v, Vec2::X, QueryFilter::default()).is_err());
        assert!(world.body_velocity_at_point(b, v).is_err());
    }
    for x in [nan, inf, -inf] {
        assert!(world.set_body_transform(b, Vec2::ZERO, x).is_err());
        assert!(world.set_body_angular_velocity(b, x).is_err());
        assert!(world.apply_torque(b, x, true).is_err());
        assert!(world.apply_angular_impulse(b, x, true).is_err());
        assert!(world.set_body_gravity_scale(b, x).is_err());
        assert!(world.set_body_constant_torque(b, x).is_err());
        assert!(world.step(x).is_err());
        let def = BodyDef {
            angle: x,
            ..BodyDef::dynamic(Vec2::ZERO)
        };
        assert!(world.create_body(&def).is_err());
        // Materials
        for m in [
            Material::default().density(x),
            Material::default().friction(x, 0.1),
            Material::default().restitution(x),
            Material {
                tangent_speed: x,
                ..Material::default()
            },
        ] {
            assert!(world.create_shape(b, &ShapeDef::with_material(m), &unit_box()).is_err());
        }
        // Geometry constructors
        assert!(Circle::new(Vec2::ZERO, x).is_err());
        assert!(Polygon::new_box(x, 1.0).is_err());
        assert!(Capsule::new(Vec2::ZERO, Vec2::new(x, 0.0), 0.1).is_err());
        assert!(Segment::new(Vec2::ZERO, Vec2::new(0.0, x)).is_err());
        assert!(Polygon::from_points(&[Vec2::ZERO, Vec2::X, Vec2::new(x, 1.0)], 0.0).is_err());
    }
    assert!(world.step(-1.0).is_err());
    assert!(world.set_body_damping(b, -1.0, 0.0).is_err());
    assert!(world
        .overlap_aabb(Aabb::new(Vec2::new(1.0, 1.0), Vec2::ZERO), QueryFilter::default())
        .is_err());
    // Negative and zero sizes.
    assert!(Circle::new(Vec2::ZERO, -1.0).is_err());
    assert!(Circle::new(Vec2::ZERO, 0.0).is_err());
    assert!(Polygon::new_box(-1.0, 1.0).is_err());
    assert!(Polygon::new_box(1.0, 0.0).is_err());
    assert!(Capsule::new(Vec2::ZERO, Vec2::X, -0.5).is_err());
    // A hand-built shape with a bad radius is caught by create_shape.
    let bad = Shape::Circle(Circle {
        center: Vec2::ZERO,
        radius: -2.0,
    });
    assert!(world.create_shape(b, &ShapeDef::default(), &bad).is_err());
    // μs < μd, e > 1, negative density.
    for m in [
        Material::default().friction(0.2, 0.5),
        Material::default().restitution(1.2),
        Material::default().density(-1.0),
    ] {
        let err = world
            .create_shape(b, &ShapeDef::with_material(m), &unit_box())
            .unwrap_err();
        assert!(!err.to_string().is_empty());
    }
    // World settings.
    assert!(World::new(WorldDef {
        substeps: 0,
        ..WorldDef::default()
    })
    .is_err());
    assert!(world
        .set_def(WorldDef {
            contact_hertz: nan,
            ..WorldDef::default()
        })
        .is_err());

    assert_eq!(snapshot(&world), before, "a rejected call changed the world");
    assert_eq!((world.body_count(), world.shape_count()), (bodies, shapes));
}

#[test]
fn errors_say_what_is_wrong() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let err = world
        .create_body(&BodyDef::dynamic(Vec2::new(f32::NAN, 0.0)))
        .unwrap_err();
    assert!(err.to_string().contains("BodyDef::position"), "{err}");
    let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let err = world
        .create_shape(
            b,
            &ShapeDef::with_material(Material::default().friction(0.2, 0.5)),
            &unit_box(),
        )
        .unwrap_err();
    assert!(err.to_string().contains("static friction"), "{err}");
    let err = Polygon::from_points(&[Vec2::ZERO, Vec2::X, Vec2::new(2.0, 0.0)], 0.0).unwrap_err();
    assert!(
        err.to_string().contains("collinear") || err.to_string().contains("degenerate"),
        "{err}"
    );
}

#[test]
fn stale_ids_give_errors_never_another_body() {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let a = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.0))).unwrap();
    let sa = world.create_shape(a, &ShapeDef::default(), &unit_box()).unwrap();
    world.step(DT).unwrap();
    world.destroy_body(a).unwrap();
    // The slot is reused by a new body; the old id must not reach it.
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(5.0, 2.0))).unwrap();
    assert_eq!(a.index, b.index);
    assert_eq!(world.body_position(a), Err(Error::InvalidBody(a)));
    assert_eq!(world.destroy_body(a), Err(Error::InvalidBody(a)));
    assert!(world.set_body_linear_velocity(a, Vec2::X).is_err());
    assert!(world.apply_force_to_center(a, Vec2::X, true).is_err());
    assert!(world.create_shape(a, &ShapeDef::default(), &unit_box()).is_err());
    assert_eq!(world.shape_body(sa), Err(Error::InvalidShape(sa)));
    assert!(world.destroy_shape(sa).is_err());
    assert_eq!(world.body_position(b).unwrap(), Vec2::new(5.0, 2.0));
    world.step(DT).unwrap();
}

#[test]
fn create_and_destroy_between_steps() {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let mut live = Vec::new();
    for i in 0..200 {
        if i % 3 == 0 && !live.is_empty() {
            let b = live.remove((i * 7) % live.len());
            world.destroy_body(b).unwrap();
        }
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new((i % 10) as f32, 1.0 + (i % 5) as f32)))
            .unwrap();
        let shape = match i % 4 {
            0 => unit_box(),
            1 => Shape::Circle(Circle::new(Vec2::ZERO, 0.3).unwrap()),
            2 => Shape::Capsule(Capsule::new(Vec2::new(-0.3, 0.0), Vec2::new(0.3, 0.0), 0.2).unwrap()),
            _ => Shape::Polygon(
                Polygon::from_points(&[Vec2::new(0.0, 0.0), Vec2::new(0.6, 0.1), Vec2::new(0.2, 0.5)], 0.02).unwrap(),
            ),
        };
        let s = world.create_shape(b, &ShapeDef::default(), &shape).unwrap();
        if i % 5 == 0 {
            world.destroy_shape(s).unwrap();
            world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
        }
        live.push(b);
        world.step(DT).unwrap();
    }
    for &b in &live {
        assert!(world.body_position(b).unwrap().is_finite());
        assert!(world.body_position(b).unwrap().y > -0.1, "body fell through the ground");
    }
    assert_eq!(world.body_count(), live.len() + 1);
}

#[test]
fn mass_properties_come_from_shapes() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let m = Material::default().density(2.0);
    // Box 2 × 1 at density 2: m = 4 kg, I = m (w² + h²) / 12 = 4·5/12.
    world
        .create_shape(
            b,
            &ShapeDef::with_material(m),
            &Shape::Polygon(Polygon::new_box(1.0, 0.5).unwrap()),
        )
        .unwrap();
    assert!((world.body_mass(b).unwrap() - 4.0).abs() < 1e-5);
    assert!((world.body_rotational_inertia(b).unwrap() - 4.0 * 5.0 / 12.0).abs() < 1e-4);
    // Add a disk of radius 0.5 at (2, 0): centre of mass moves toward it.
    world
        .create_shape(
            b,
            &ShapeDef::with_material(m),
            &Shape::Circle(Circle::new(Vec2::new(2.0, 0.0), 0.5).unwrap()),
        )
        .unwrap();
    let md = 2.0 * core::f32::consts::PI * 0.25;
    let expected_cx = md * 2.0 / (4.0 + md);
    assert!((world.body_local_center_of_mass(b).unwrap().x - expected_cx).abs() < 1e-4);
    world.set_body_fixed_rotation(b, true).unwrap();
    assert_eq!(world.body_rotational_inertia(b).unwrap(), 0.0);
}

#[test]
fn begin_and_end_events() {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
    let mut began = 0;
    for _ in 0..60 {
        world.step(DT).unwrap();
        began += world.contact_events().begin.len();
    }
    assert_eq!(began, 1);
    assert_eq!(world.body_contacts(b).unwrap().len(), 1);
    // Throw it upward: the contact ends.
    world.set_body_linear_velocity(b, Vec2::new(0.0, 8.0)).unwrap();
    let mut ended = 0;
    for _ in 0..10 {
        world.step(DT).unwrap();
        ended += world.contact_events().end.len();
    }
    assert_eq!(ended, 1);
}

#[test]
fn ray_cast_and_overlap_queries() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let g = ground(&mut world);
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(3.0, 0.5))).unwrap();
    let sb = world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
    // Straight down onto the box top at y = 1.
    let hit = world
        .cast_ray_closest(Vec2::new(3.0, 5.0), Vec2::new(0.0, -10.0), QueryFilter::default())
        .unwrap()
        .expect("hit");
    assert_eq!(hit.shape, sb);
    assert!((hit.point.y - 1.0).abs() < 1e-4);
    assert!((hit.fraction - 0.4).abs() < 1e-4);
    assert!((hit.normal - Vec2::Y).length() < 1e-4);
    // Beside the box: the ground (top at y = 0).
    let hit = world
        .cast_ray_closest(Vec2::new(-3.0, 5.0), Vec2::new(0.0, -10.0), QueryFilter::default())
        .unwrap()
        .expect("hit");
    assert_eq!(hit.body, g);
    assert!(hit.point.y.abs() < 1e-4);
    // Filter out the ground's category.
    let none = world
        .cast_ray_closest(
            Vec2::new(-3.0, 5.0),
            Vec2::new(0.0, -10.0),
            QueryFilter { category: 1, mask: 0 },
        )
        .unwrap();
    assert!(none.is_none());
    let found = world
        .overlap_aabb(
            Aabb::new(Vec2::new(2.9, 0.9), Vec2::new(3.1, 1.1)),
            QueryFilter::default(),
        )
        .unwrap();
    assert!(found.contains(&sb));
}

#[test]
fn collision_filtering() {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let ghost = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.0))).unwrap();
    let def = ShapeDef {
        filter: Filter {
            category: 2,
            mask: !1,
            group: 0,
        },
        ..ShapeDef::default()
    };
    world.create_shape(ghost, &def, &unit_box()).unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(
        world.body_position(ghost).unwrap().y < -1.0,
        "masked body should fall through the ground"
    );
    // Negative group: two boxes of group -1 pass through each other.
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let def = ShapeDef {
        filter: Filter {
            group: -1,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    let a = world.create_body(&BodyDef::dynamic(Vec2::new(-2.0, 0.0))).unwrap();
    world.create_shape(a, &def, &unit_box()).unwrap();
    world.set_body_linear_velocity(a, Vec2::new(4.0, 0.0)).unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(2.0, 0.0))).unwrap();
    world.create_shape(b, &def, &unit_box()).unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(world.body_position(a).unwrap().x > 1.5);
}

#[test]
fn bodies_sleep_at_rest_and_wake_when_touched() {
    let mut world = World::new(WorldDef::default()).unwrap();
    ground(&mut world);
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5))).unwrap();
    world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert!(!world.body_is_awake(b).unwrap(), "resting box should sleep after 0.5 s");
    let y_sleep = world.body_position(b).unwrap().y;
    // Drop a box on it: it wakes.
    let c = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0))).unwrap();
    world.create_shape(c, &ShapeDef::default(), &unit_box()).unwrap();
    let mut woke = false;
    for _ in 0..60 {
        world.step(DT).unwrap();
        woke |= world.body_is_awake(b).unwrap();
    }
    assert!(woke, "sleeping box should wake when hit");
    assert!((world.body_position(c).unwrap().y - 1.5).abs() < 0.02);
    assert!((world.body_position(b).unwrap().y - y_sleep).abs() < 0.01);
    // Applying an impulse wakes a sleeper.
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert!(!world.body_is_awake(c).unwrap());
    world
        .apply_linear_impulse_to_center(c, Vec2::new(0.0, 1.0), true)
        .unwrap();
    assert!(world.body_is_awake(c).unwrap());
}

#[test]
fn kinematic_bodies_move_with_their_velocity_and_carry_others() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let mut def = BodyDef::kinematic(Vec2::new(0.0, 0.0));
    def.linear_velocity = Vec2::new(1.0, 0.0);
    let k = world.create_body(&def).unwrap();
    world
        .create_shape(
            k,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(5.0, 0.25).unwrap()),
        )
        .unwrap();
    let rider = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.75))).unwrap();
    world.create_shape(rider, &ShapeDef::default(), &unit_box()).unwrap();
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert!((world.body_position(k).unwrap().x - 2.0).abs() < 1e-3);
    assert_eq!(world.body_type(k).unwrap(), BodyType::Kinematic);
    // Static friction carries the rider with the platform.
    assert!((world.body_linear_velocity(rider).unwrap().x - 1.0).abs() < 0.01);
}

#[test]
fn fast_body_does_not_tunnel_through_thin_ground() {
    // A segment ground and a small box falling at 30 m/s: 0.5 m per step, 2.5× its size.
    let mut world = World::new(WorldDef::default()).unwrap();
    let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    world
        .create_shape(
            g,
            &ShapeDef::default(),
            &Shape::Segment(Segment::new(Vec2::new(-20.0, 0.0), Vec2::new(20.0, 0.0)).unwrap()),
        )
        .unwrap();
    let mut def = BodyDef::dynamic(Vec2::new(0.0, 5.0));
    def.linear_velocity = Vec2::new(0.0, -30.0);
    let b = world.create_body(&def).unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(0.1, 0.1).unwrap()),
        )
        .unwrap();
    let ball = world
        .create_body(&BodyDef {
            linear_velocity: Vec2::new(3.0, -25.0),
            ..BodyDef::dynamic(Vec2::new(2.0, 4.0))
        })
        .unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default(),
            &Shape::Circle(Circle::new(Vec2::ZERO, 0.05).unwrap()),
        )
        .unwrap();
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert!(
        world.body_position(b).unwrap().y > 0.0,
        "box tunnelled: {:?}",
        world.body_position(b)
    );
    assert!(world.body_position(ball).unwrap().y > 0.0, "ball tunnelled");
}

#[test]
fn boxes_hitting_a_wall_are_stopped_at_its_face() {
    // A box of half size h (thickness h from its centre) slides without gravity into a
    // static wall at speeds below and above the broad phase's sweep threshold (h/2 per
    // step: 30 h m/s at 1/60 s), from 8 start points spread over one step's travel (how late
    // a pair is found depends on where the box stands when its fat box is renewed). Above
    // the threshold the swept box holds the whole step's motion, so the pair exists before
    // the box arrives and the speculative contact stops it at the face; below it the pair
    // may be found late, the box's motion then leaves the region its pairs covered, and it
    // is stopped where it first overlaps the wall by the slop (continuous collision against
    // static shapes; without it a box entered the wall 12.5 mm for a step). Either way the
    // overlap stays within 1 cm (twice the soft contact's 5 mm slop), measured from the
    // box centre's x; no box may end beyond the face.
    for h in [0.1f32, 0.5] {
        let threshold = 30.0 * h;
        for (factor, limit) in [
            (0.5, 0.01),
            (0.97, 0.01),
            (1.03, 0.01),
            (3.0, 0.01),
            (10.0, 0.01),
            (30.0, 0.01),
        ] {
            let speed = factor * threshold;
            let mut deepest = 0.0f32;
            for phase in 0..8 {
                let mut world = World::new(WorldDef {
                    gravity: Vec2::ZERO,
                    ..WorldDef::default()
                })
                .unwrap();
                let wall = world.create_body(&BodyDef::fixed(Vec2::new(10.0, 0.0))).unwrap();
                world
                    .create_shape(
                        wall,
                        &ShapeDef::default(),
                        &Shape::Polygon(Polygon::new_box(1.0, 5.0).unwrap()),
                    )
                    .unwrap();
                let travel = speed * DT;
                let start = 9.0 - h - 0.3 - 2.0 * travel - travel * phase as f32 / 8.0;
                let b = world
                    .create_body(&BodyDef {
                        linear_velocity: Vec2::new(speed, 0.0),
                        fixed_rotation: true,
                        ..BodyDef::dynamic(Vec2::new(start, 0.0))
                    })
                    .unwrap();
                world
                    .create_shape(
                        b,
                        &ShapeDef::default(),
                        &Shape::Polygon(Polygon::new_box(h, h).unwrap()),
                    )
                    .unwrap();
                for _ in 0..60 {
                    world.step(DT).unwrap();
                    let x = world.body_position(b).unwrap().x;
                    deepest = deepest.max(x + h - 9.0);
                }
                assert!(
                    world.body_position(b).unwrap().x + h < 9.0 + limit,
                    "h {h}, {speed} m/s: box beyond the face"
                );
            }
            assert!(
                deepest < limit,
                "h {h}, {speed} m/s: overlap {deepest} m (limit {limit} m)"
            );
        }
    }
}

/// A box at rest 0.3 m in front of a wall is kicked towards it at 60 m/s (1 m per step)
/// through the API: its pairs were found for a box at rest, so nothing in the step's solve
/// stops it. The wall is two static boxes meeting exactly where the box hits (a seam, as
/// between the 360 pieces of Box2D's spinner ring). Continuous collision against static
/// shapes stops the box at the wall's face; it must never get deeper than 1 cm (twice the
/// slop) and must end in front of the wall, not inside or behind it (without the stop it
/// went 1.2 m deep, along the seam, whose side faces push sideways, not out).
#[test]
fn a_box_kicked_into_a_wall_of_pieces_stops_at_its_face() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(10.0, 0.0))).unwrap();
    for y in [-1.0f32, 1.0] {
        let piece = Polygon::new_offset_box(1.0, 1.0, Vec2::new(0.0, y), 0.0).unwrap();
        world
            .create_shape(wall, &ShapeDef::default(), &Shape::Polygon(piece))
            .unwrap();
    }
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(8.45, 0.0))).unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(0.25, 0.25).unwrap()),
        )
        .unwrap();
    world.step(DT).unwrap();
    world.set_body_linear_velocity(b, Vec2::new(60.0, 0.0)).unwrap();
    let mut deepest = f32::MIN;
    for _ in 0..60 {
        world.step(DT).unwrap();
        let p = world.body_position(b).unwrap();
        deepest = deepest.max(p.x + 0.25 - 9.0);
        assert!(p.is_finite() && p.y.abs() < 0.5, "the box left sideways: {p:?}");
    }
    assert!(deepest < 0.01, "the box entered the wall {deepest} m");
    assert!(world.body_position(b).unwrap().x + 0.25 < 9.01);
}

#[test]
fn runs_are_bit_identical() {
    fn run() -> Vec<[u32; 6]> {
        let mut world = World::new(WorldDef::default()).unwrap();
        ground(&mut world);
        for i in 0..60 {
            let x = (i % 10) as f32 * 1.1 - 5.0;
            let y = 1.0 + (i / 10) as f32 * 1.2;
            let mut def = BodyDef::dynamic(Vec2::new(x, y));
            def.angle = 0.1 * i as f32;
            def.angular_velocity = 0.5 - 0.01 * i as f32;
            let b = world.create_body(&def).unwrap();
            let m = Material::default().friction(0.7, 0.4).restitution(0.1 * (i % 5) as f32);
            let shape = if i % 2 == 0 {
                unit_box()
            } else {
                Shape::Circle(Circle::new(Vec2::ZERO, 0.45).unwrap())
            };
            world.create_shape(b, &ShapeDef::with_material(m), &shape).unwrap();
        }
        for _ in 0..300 {
            world.step(DT).unwrap();
        }
        snapshot(&world)
    }
    assert_eq!(run(), run());
}

/// A bullet ([`BodyDef::bullet`]) keeps its swept boxes while it touches something: a small
/// box sliding along the ground at 40 m/s (0.67 m per step, over three times its own size)
/// into an upright kinematic plank 5 cm thick (moving bodies are not stopped by the
/// continuous collision against static shapes) hits the plank instead of passing it: after
/// 30 steps it is still on its side (x < the plank's x). A body that touches nothing is
/// swept anyway; one sliding on the ground and not a bullet is not, and passes this plank
/// (measured: x = 18 m after 30 steps; Box2D's behaviour for non-bullets).
#[test]
fn a_bullet_sliding_on_the_ground_does_not_pass_a_thin_plank() {
    let run = |bullet: bool| {
        let mut world = World::new(WorldDef::default()).unwrap();
        ground(&mut world);
        let plank = world.create_body(&BodyDef::kinematic(Vec2::new(5.0, 1.0))).unwrap();
        world
            .create_shape(
                plank,
                &ShapeDef::default(),
                &Shape::Polygon(Polygon::new_box(0.025, 1.0).unwrap()),
            )
            .unwrap();
        let b = world
            .create_body(&BodyDef {
                bullet,
                linear_velocity: Vec2::new(40.0, 0.0),
                ..BodyDef::dynamic(Vec2::new(-2.0, 0.1))
            })
            .unwrap();
        let frictionless = ShapeDef {
            material: Material::with_friction(0.0),
            ..ShapeDef::default()
        };
        world
            .create_shape(b, &frictionless, &Shape::Polygon(Polygon::new_box(0.1, 0.1).unwrap()))
            .unwrap();
        for _ in 0..30 {
            world.step(DT).unwrap();
        }
        (world.body_position(b).unwrap().x, world.body_position(plank).unwrap().x)
    };
    let (x, plank_x) = run(true);
    assert!(x < plank_x, "bullet at x {x} passed the plank at {plank_x}");
}

/// A small version of Box2D's smash: a block of 24 × 24 boxes created asleep, each touching
/// its neighbours, struck by a heavy box at 40 m/s in zero gravity. While most bodies
/// sleep, the narrow phase visits only the awake bodies' contacts (each chunk its share of
/// their list); the wave then wakes the block column by column.
/// * Determinism: one worker and three (about nine chunks of the contact list, each finding
///   its share) give bit-identical states at every step: a chunk that missed or repeated
///   a contact would make the runs differ.
/// * Momentum: contact impulses come in equal and opposite pairs and nothing else acts, so
///   Σ m v stays the projectile's m v₀ (Newton's third law). Tolerance 1e-4 of it: the
///   velocities are f32 (relative rounding ~6e-8 per operation) and the sum runs over
///   577 bodies and 240 steps of impulses, far below 1e-4; a body put back to sleep has its
///   velocity zeroed (at most 0.05 m/s × 0.16 kg each, but the boxes keep drifting apart in
///   zero gravity). What it catches is a moving body pushing on one the solver treats as
///   fixed (a woken body without a solver entry: a broken wake path).
/// * Waking: after 3 steps some bodies but not half of the block are awake (the sparse
///   path ran; 288 awake would make the world mostly awake), and after 240 steps the middle
///   box of the far column, in the line of the impact, has moved away from where it slept.
#[test]
fn sleeping_block_wakes_from_the_impact_alike_on_any_worker_count() {
    let run = |workers: u32| {
        let mut world = World::new(WorldDef {
            gravity: Vec2::ZERO,
            workers,
            ..WorldDef::default()
        })
        .unwrap();
        let h = 0.2;
        let small = Shape::Polygon(Polygon::new_box(h, h).unwrap());
        let mut block = Vec::new();
        for i in 0..24 {
            for j in 0..24 {
                let at = Vec2::new(2.0 * h * i as f32, 2.0 * h * (j as f32 - 12.0));
                let b = world
                    .create_body(&BodyDef {
                        awake: false,
                        ..BodyDef::dynamic(at)
                    })
                    .unwrap();
                world.create_shape(b, &ShapeDef::default(), &small).unwrap();
                // Asleep alone, as the scene files put a body created asleep.
                world.set_body_awake(b, false).unwrap();
                block.push(b);
            }
        }
        let p = world
            .create_body(&BodyDef {
                linear_velocity: Vec2::new(40.0, 0.0),
                ..BodyDef::dynamic(Vec2::new(-3.0, 0.0))
            })
            .unwrap();
        let heavy = Material {
            density: 8.0,
            ..Material::default()
        };
        world
            .create_shape(
                p,
                &ShapeDef::with_material(heavy),
                &Shape::Polygon(Polygon::new_box(1.0, 1.0).unwrap()),
            )
            .unwrap();
        let p0 = world.body_mass(p).unwrap() * 40.0;
        let mut states = Vec::new();
        let mut awake_at_3 = 0;
        for step in 1..=240 {
            world.step(DT).unwrap();
            if step == 3 {
                awake_at_3 = block.iter().filter(|&&b| world.body_is_awake(b).unwrap()).count();
            }
            states.push(snapshot(&world));
        }
        let mut momentum = Vec2::ZERO;
        for &b in block.iter().chain([&p]) {
            momentum += world.body_linear_velocity(b).unwrap() * world.body_mass(b).unwrap();
        }
        // Column i, row j is block[24 i + j]: the far column's middle box (y = 0).
        let far_x = world.body_position(block[23 * 24 + 12]).unwrap().x;
        (states, awake_at_3, momentum, p0, far_x)
    };
    let (one, awake_at_3, momentum, p0, far_x) = run(1);
    assert!(
        awake_at_3 > 0 && awake_at_3 < 24 * 24 / 2,
        "{awake_at_3} of 576 awake after 3 steps: the impact should have woken some, not most"
    );
    assert!(
        (momentum - Vec2::new(p0, 0.0)).length() < 1e-4 * p0,
        "momentum {momentum:?}, expected ({p0}, 0)"
    );
    assert!(
        far_x > 2.0 * 0.2 * 23.0 + 0.1,
        "far column at x = {far_x}: the wave did not reach it"
    );
    let (three, ..) = run(3);
    assert!(one == three, "three workers differ from one");
}

/// A box held by static friction on a tilted floor (gravity tilted by θ = 20°, μ = 0.8 >
/// tan θ) reports, summed over its contact points, the impulses that hold it each step:
/// normal m·g·cos θ·dt and friction m·g·sin θ·dt (Newton at rest: the contact impulse
/// cancels gravity's). Tolerance 1 %: at rest the box's velocity changes by well under 0.1 %
/// of g·dt per step (the soft contact's residual). Its points stick and slip at under the
/// stick speed. Once the box sleeps its contacts are no longer solved, and they keep
/// reporting the impulses of their last solved step.
#[test]
fn a_resting_box_reports_the_impulses_that_hold_it_also_asleep() {
    let theta = 20f32.to_radians();
    let g = 9.81;
    let mut world = World::new(WorldDef {
        gravity: Vec2::new(g * theta.sin(), -g * theta.cos()),
        ..WorldDef::default()
    })
    .unwrap();
    let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
    let grip = ShapeDef {
        material: Material::with_friction(0.8),
        ..ShapeDef::default()
    };
    world
        .create_shape(floor, &grip, &Shape::Polygon(Polygon::new_box(50.0, 1.0).unwrap()))
        .unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5))).unwrap();
    world.create_shape(b, &grip, &unit_box()).unwrap();
    let m = world.body_mass(b).unwrap();
    let sums = |world: &World| {
        let contacts = world.body_contacts(b).unwrap();
        assert_eq!(contacts.len(), 1, "one contact, with the floor");
        let points = contacts[0].points();
        assert_eq!(points.len(), 2, "a face contact");
        assert!(points
            .iter()
            .all(|p| p.state == tribo::FrictionState::Stick && p.slip_speed < 0.01));
        let n: f32 = points.iter().map(|p| p.normal_impulse).sum();
        let t: f32 = points.iter().map(|p| p.friction_impulse).sum();
        (n, t)
    };
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    let (n, t) = sums(&world);
    let (want_n, want_t) = (m * g * theta.cos() * DT, m * g * theta.sin() * DT);
    assert!((n - want_n).abs() < 0.01 * want_n, "normal {n} N·s, expected {want_n}");
    assert!(
        (t.abs() - want_t).abs() < 0.01 * want_t,
        "friction {t} N·s, expected ±{want_t}"
    );
    let mut steps = 0;
    while world.body_is_awake(b).unwrap() {
        world.step(DT).unwrap();
        steps += 1;
        assert!(steps < 600, "the box falls asleep");
    }
    let asleep = sums(&world);
    world.step(DT).unwrap();
    assert_eq!(
        sums(&world),
        asleep,
        "a sleeping contact keeps its last step's impulses"
    );
    assert!((asleep.0 - want_n).abs() < 0.01 * want_n);
}

/// A touching contact the step does not solve reports nothing applied: a box resting on
/// a moving kinematic platform reports its weight's impulse (m·g·dt, 1 %: at rest) while
/// awake; put to sleep, its contact with the platform (kept up to date, the platform
/// moves) is no longer solved and reports zero impulses and zero slip.
#[test]
fn a_contact_the_step_does_not_solve_reports_zero() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let platform = world.create_body(&BodyDef::kinematic(Vec2::new(0.0, -1.0))).unwrap();
    world
        .create_shape(
            platform,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(50.0, 1.0).unwrap()),
        )
        .unwrap();
    world.set_body_linear_velocity(platform, Vec2::new(0.5, 0.0)).unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5))).unwrap();
    world.create_shape(b, &ShapeDef::default(), &unit_box()).unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    let points = |world: &World| {
        let contacts = world.body_contacts(b).unwrap();
        assert_eq!(contacts.len(), 1, "one contact, with the platform");
        contacts[0].points().to_vec()
    };
    let weight = world.body_mass(b).unwrap() * 9.81 * DT;
    let n: f32 = points(&world).iter().map(|p| p.normal_impulse).sum();
    assert!((n - weight).abs() < 0.01 * weight, "normal {n} N·s, expected {weight}");
    world.set_body_awake(b, false).unwrap();
    world.step(DT).unwrap();
    assert!(!world.body_is_awake(b).unwrap());
    let asleep = points(&world);
    assert_eq!(asleep.len(), 2);
    assert!(asleep
        .iter()
        .all(|p| p.normal_impulse == 0.0 && p.friction_impulse == 0.0 && p.slip_speed == 0.0));
}
