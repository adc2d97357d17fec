//! Revolute joints against the mechanics they should reproduce: pendulum periods, a
//! hanging chain's load, motors, joint friction, limits and springs; plus the API's
//! errors, islands and collide_connected.

use tribo::{
    BodyDef, BodyId, Circle, Error, JointId, Polygon, RevoluteJointDef, Shape, ShapeDef, Vec2, World, WorldDef,
};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;

fn world(gravity: Vec2) -> World {
    World::new(WorldDef {
        gravity,
        ..WorldDef::default()
    })
    .unwrap()
}

fn disk(world: &mut World, at: Vec2, radius: f32) -> tribo::BodyId {
    let b = world.create_body(&BodyDef::dynamic(at)).unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            &Shape::Circle(Circle::new(Vec2::ZERO, radius).unwrap()),
        )
        .unwrap();
    b
}

/// A disk of radius r hung at distance l below a static pivot, released at angle θ0.
fn pendulum(l: f32, r: f32, theta0: f32) -> (World, JointId, tribo::BodyId) {
    let mut w = world(Vec2::new(0.0, -G));
    let pivot = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let bob = disk(&mut w, Vec2::new(l * theta0.sin(), -l * theta0.cos()), r);
    let j = w
        .create_revolute_joint(&RevoluteJointDef::at(&w, pivot, bob, Vec2::ZERO).unwrap())
        .unwrap();
    (w, j, bob)
}

/// Times of the downward zero crossings of x(t) [s], linearly interpolated.
fn crossings(xs: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    for k in 1..xs.len() {
        if xs[k - 1] > 0.0 && xs[k] <= 0.0 {
            let f = xs[k - 1] / (xs[k - 1] - xs[k]);
            out.push((k as f32 - 1.0 + f) * DT);
        }
    }
    out
}

#[test]
fn pendulum_swings_with_the_physical_pendulum_period() {
    // T = 2π √(I_pivot / (m g l)) (1 + θ0²/16), I_pivot = m r²/2 + m l² (a disk at l).
    // Measured over 8 periods from interpolated zero crossings; tolerance 0.3 %: the
    // crossing times are read to about 1e-4 s of a 2 s period, and the soft step's
    // integration error is of order (ω h)² ≈ 1e-4.
    for (l, r) in [(1.0f32, 0.05f32), (2.0, 0.3)] {
        let theta0 = 0.1f32;
        let (mut w, _, bob) = pendulum(l, r, theta0);
        let mut xs = Vec::new();
        for _ in 0..(60 * 25) {
            w.step(DT).unwrap();
            xs.push(w.body_position(bob).unwrap().x);
        }
        let c = crossings(&xs);
        assert!(c.len() >= 9, "{} crossings", c.len());
        let measured = (c[8] - c[0]) / 8.0;
        let i_pivot = 0.5 * r * r + l * l; // per unit mass
        let expected = 2.0 * core::f32::consts::PI * (i_pivot / (G * l)).sqrt() * (1.0 + theta0 * theta0 / 16.0);
        let err = (measured - expected).abs() / expected;
        assert!(
            err < 0.003,
            "l {l}: period {measured} s vs {expected} s ({:.3} %)",
            err * 100.0
        );
    }
}

#[test]
fn pendulum_keeps_its_length_and_does_not_gain_energy() {
    // Released horizontally (θ0 = 90°, at the pivot's height): the bob stays on its circle
    // (|p − pivot| = l within 1 mm: the soft correction's give under the swing's load of
    // up to 3 m g) and never climbs above the height it started from (energy conservation
    // bounds each apex by the release height; an impulse solver may lose energy, never
    // make it: 1 mm allowed for that give). Apexes are read where the vertical velocity
    // turns from up to down. Over 10 s (7 swings) it must still reach within 1 cm of the
    // start (it swings, it is not damped away; measured: every apex 1.5 mm below).
    let (l, r) = (1.5f32, 0.1f32);
    let (mut w, _, bob) = pendulum(l, r, core::f32::consts::FRAC_PI_2);
    let (mut worst_len, mut apexes) = (0.0f32, Vec::new());
    let mut last_vy = 0.0f32;
    for _ in 0..600 {
        w.step(DT).unwrap();
        let p = w.body_position(bob).unwrap();
        worst_len = worst_len.max((p.length() - l).abs());
        let vy = w.body_linear_velocity(bob).unwrap().y;
        if last_vy > 0.0 && vy <= 0.0 {
            apexes.push(p.y);
        }
        last_vy = vy;
    }
    assert!(worst_len < 1e-3, "length error {worst_len} m");
    assert!(apexes.len() >= 6, "{} apexes", apexes.len());
    let highest = apexes.iter().copied().fold(f32::MIN, f32::max);
    assert!(highest < 1e-3, "an apex at {highest} m, above the release height 0");
    let last = *apexes.last().unwrap();
    assert!(last > -0.01, "last apex {last} m: the swing died out");
}

/// A chain of `n` disks (radius 0.1 m) 0.3 m apart hanging straight down from a static
/// pivot at the origin, or laid out horizontally (`hanging` false); returns the world, the
/// joints (top first) and the links.
fn chain(n: usize, workers: u32, hanging: bool) -> (World, Vec<JointId>, Vec<BodyId>) {
    let mut w = World::new(WorldDef {
        gravity: Vec2::new(0.0, -G),
        workers,
        ..WorldDef::default()
    })
    .unwrap();
    let pivot = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let (mut joints, mut links) = (Vec::new(), Vec::new());
    let mut above = pivot;
    let dir = if hanging {
        Vec2::new(0.0, -0.3)
    } else {
        Vec2::new(0.3, 0.0)
    };
    for k in 0..n {
        let link = disk(&mut w, dir * (k + 1) as f32, 0.1);
        let anchor = dir * k as f32;
        joints.push(
            w.create_revolute_joint(&RevoluteJointDef::at(&w, above, link, anchor).unwrap())
                .unwrap(),
        );
        links.push(link);
        above = link;
    }
    (w, joints, links)
}

#[test]
fn hanging_chain_carries_its_weight_at_each_joint() {
    // A 10-link chain hanging from a pivot: joint k (from the top) carries the weight of
    // the n − k links below it, (n − k) m g upwards on the link below, within 0.5 % after
    // 2 s (the force is the impulse of the last substep over h). The joint is soft (Box2D
    // v3's 60 Hz, ζ 2 position correction), so under a steady load F its anchors part by
    // the static deflection F / (m_eff ω²), ω = 2π·60 rad/s, m_eff the point's effective
    // mass (m for the top joint to the static pivot, m/2 between two links in a straight
    // vertical chain): checked within 10 %. The chain stays straight (last link within
    // 1 mm of x = 0).
    let n = 10;
    let (mut w, joints, links) = chain(n, 1, true);
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let m = w.body_mass(links[0]).unwrap();
    for (k, &j) in joints.iter().enumerate() {
        let f = w.joint_reaction_force(j).unwrap();
        let load = (n - k) as f32 * m * G;
        assert!(
            (f.y - load).abs() < 5e-3 * load && f.x.abs() < 1e-3 * load,
            "joint {k}: {f:?} vs {load} N"
        );
        let (a, b) = w.joint_world_anchors(j).unwrap();
        let m_eff = if k == 0 { m } else { m / 2.0 };
        let omega = 2.0 * core::f32::consts::PI * 60.0;
        let deflection = load / (m_eff * omega * omega);
        let gap = (a - b).length();
        assert!(
            (gap - deflection).abs() < 0.1 * deflection,
            "joint {k}: anchors {gap} m apart vs {deflection} m"
        );
    }
    let end = w.body_position(*links.last().unwrap()).unwrap();
    assert!(end.x.abs() < 1e-3, "chain end at {end:?}");
}

/// A disk on a static pivot at its centre (a wheel on an axle), no gravity.
fn wheel(radius: f32) -> (World, BodyId, BodyId) {
    let mut w = world(Vec2::ZERO);
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let disk_body = disk(&mut w, Vec2::ZERO, radius);
    (w, ground, disk_body)
}

#[test]
fn motor_spins_up_at_its_torque_limit_then_holds_its_speed() {
    // A wheel of inertia I driven at target speed ω with max torque τ accelerates at
    // α = τ / I, reaches ω at t = I ω / τ and then turns at exactly ω. Checked: the time
    // to reach 99 % of ω within 2 % of 0.99 I ω / τ (the step is 1/60 s of ~1 s), the
    // speed after within 0.1 %, and the reported motor torque τ while accelerating.
    let (mut w, ground, d) = wheel(0.5);
    let inertia = w.body_rotational_inertia(d).unwrap();
    let (omega, tau) = (4.0f32, 0.5f32);
    let def = RevoluteJointDef::new(ground, d, Vec2::ZERO, Vec2::ZERO).motor(omega, tau);
    let j = w.create_revolute_joint(&def).unwrap();
    let expected = 0.99 * inertia * omega / tau;
    let mut reached = None;
    for k in 1..=240 {
        w.step(DT).unwrap();
        if k == 10 {
            let t = w.revolute_motor_torque(j).unwrap();
            assert!((t - tau).abs() < 1e-3 * tau, "motor torque {t} N·m while accelerating");
        }
        if reached.is_none() && w.body_angular_velocity(d).unwrap() >= 0.99 * omega {
            reached = Some(k as f32 * DT);
        }
    }
    let t = reached.expect("never reached the speed");
    assert!(
        (t - expected).abs() < 0.02 * expected,
        "reached at {t} s, expected {expected} s"
    );
    let speed = w.revolute_speed(j).unwrap();
    assert!((speed - omega).abs() < 1e-3 * omega, "speed {speed} rad/s");
    // The pivot stays put (the point row holds the wheel's centre).
    assert!(w.body_position(d).unwrap().length() < 1e-4);
}

#[test]
fn joint_friction_holds_below_its_torque_and_slips_above() {
    // Joint friction = a motor at speed 0 with max torque τ. A horizontal bar of mass m
    // pinned at one end feels the gravity torque m g l/2 about the pin: with τ 10 % above
    // it the bar holds (turns less than 1 mrad in 2 s); with τ 10 % below it the bar
    // falls with α = (m g l/2 − τ)/I_pin, measured from its angular speed between 0.1 s
    // and 0.3 s (angle still under 0.05 rad, so the gravity torque stays within 0.1 % of
    // m g l/2), within 2 %. (The first step's friction builds up over its substeps, as in
    // Box2D: the motor row sees only the rotation the point row leaves it.)
    for (factor, holds) in [(1.1f32, true), (0.9f32, false)] {
        let mut w = world(Vec2::new(0.0, -G));
        let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let (l, h) = (2.0f32, 0.1f32);
        let bar = w.create_body(&BodyDef::dynamic(Vec2::new(l / 2.0, 0.0))).unwrap();
        w.create_shape(
            bar,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(l / 2.0, h / 2.0).unwrap()),
        )
        .unwrap();
        let m = w.body_mass(bar).unwrap();
        let gravity_torque = m * G * l / 2.0;
        let tau = factor * gravity_torque;
        let def = RevoluteJointDef::at(&w, ground, bar, Vec2::ZERO)
            .unwrap()
            .motor(0.0, tau);
        let j = w.create_revolute_joint(&def).unwrap();
        if holds {
            for _ in 0..120 {
                w.step(DT).unwrap();
            }
            let angle = w.revolute_angle(j).unwrap();
            assert!(angle.abs() < 1e-3, "held bar turned {angle} rad");
            continue;
        }
        let mut speeds = Vec::new();
        for _ in 0..18 {
            w.step(DT).unwrap();
            speeds.push(w.revolute_speed(j).unwrap());
        }
        let (w1, w2) = (speeds[5], speeds[17]);
        let measured = -(w2 - w1) / (12.0 * DT);
        let i_pin = w.body_rotational_inertia(bar).unwrap() + m * (l / 2.0) * (l / 2.0);
        let alpha = (gravity_torque - tau) / i_pin;
        assert!(w.revolute_angle(j).unwrap().abs() < 0.05);
        assert!(
            (measured - alpha).abs() < 0.02 * alpha,
            "α {measured} rad/s² vs {alpha} rad/s²"
        );
    }
}

#[test]
fn limit_stops_a_falling_bar_at_its_angle() {
    // A bar pinned at one end, released horizontal, limited to [−0.5, 0.5] rad: it falls
    // to −0.5 rad and rests there (overshoot under 0.02 rad: the soft limit under the
    // impact; at rest within 5 mrad of the limit: the soft correction's static deflection
    // under the bar's weight), where the limit carries the gravity torque.
    let mut w = world(Vec2::new(0.0, -G));
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let bar = w.create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
    w.create_shape(
        bar,
        &ShapeDef::default(),
        &Shape::Polygon(Polygon::new_box(1.0, 0.05).unwrap()),
    )
    .unwrap();
    let def = RevoluteJointDef::at(&w, ground, bar, Vec2::ZERO)
        .unwrap()
        .limit(-0.5, 0.5);
    let j = w.create_revolute_joint(&def).unwrap();
    let mut lowest = 0.0f32;
    for _ in 0..180 {
        w.step(DT).unwrap();
        lowest = lowest.min(w.revolute_angle(j).unwrap());
    }
    assert!(lowest > -0.52, "overshoot to {lowest} rad");
    let angle = w.revolute_angle(j).unwrap();
    assert!((angle + 0.5).abs() < 5e-3, "rests at {angle} rad");
    assert!(w.body_angular_velocity(bar).unwrap().abs() < 1e-3);
}

#[test]
fn spring_oscillates_at_its_frequency() {
    // A wheel on an axle with an undamped angular spring of frequency f, turned by 0.3 rad
    // and released (no gravity): θ(t) = 0.3 cos(2π f t). Period measured over 5 cycles
    // within 1 % of 1/f (the implicit spring's period error is of order (2π f h)²/3 ≈ 1e-3
    // at 2 Hz, h = 1/240 s). The spring is integrated implicitly (as Box2D's soft
    // springs): unconditionally stable, but even at ζ = 0 each substep scales the
    // amplitude by (1 + (ω h)²)^(−1/2), ω = 2π f; the peak after 5 cycles (t = 2.5 s)
    // must match 0.3 (1 + (ω h)²)^(−t/(2h)) within 5 %.
    let (mut w, ground, d) = wheel(0.5);
    let f = 2.0f32;
    w.set_body_transform(d, Vec2::ZERO, 0.3).unwrap();
    let def = RevoluteJointDef::new(ground, d, Vec2::ZERO, Vec2::ZERO).spring(f, 0.0);
    let j = w.create_revolute_joint(&def).unwrap();
    let mut angles = Vec::new();
    for _ in 0..(60 * 3) {
        w.step(DT).unwrap();
        angles.push(w.revolute_angle(j).unwrap());
    }
    let c = crossings(&angles);
    assert!(c.len() >= 6, "{} crossings", c.len());
    let period = (c[5] - c[0]) / 5.0;
    assert!(
        (period - 1.0 / f).abs() < 0.01 / f,
        "period {period} s vs {} s",
        1.0 / f
    );
    let late = angles[(60.0 * 2.5) as usize - 2..]
        .iter()
        .fold(0.0f32, |m, a| m.max(a.abs()));
    let (omega, h) = (2.0 * core::f32::consts::PI * f, DT / 4.0);
    let expected = 0.3 * (1.0 + omega * omega * h * h).powf(-2.5 / (2.0 * h));
    assert!(
        (late - expected).abs() < 0.05 * expected,
        "amplitude {late} rad vs {expected} rad after 5 cycles"
    );
}

/// A static ground box whose top is at y = 0.
fn ground(w: &mut World) {
    let g = w.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
    w.create_shape(
        g,
        &ShapeDef::default(),
        &Shape::Polygon(Polygon::new_box(20.0, 1.0).unwrap()),
    )
    .unwrap();
}

/// Two boxes overlapping by half, jointed at the overlap's middle, on the ground.
fn overlapping_pair(collide_connected: bool) -> (World, JointId) {
    let mut w = world(Vec2::new(0.0, -G));
    ground(&mut w);
    let a = w.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5))).unwrap();
    let b = w.create_body(&BodyDef::dynamic(Vec2::new(0.5, 0.5))).unwrap();
    for body in [a, b] {
        w.create_shape(
            body,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap()),
        )
        .unwrap();
    }
    let mut def = RevoluteJointDef::at(&w, a, b, Vec2::new(0.25, 0.5)).unwrap();
    def.collide_connected = collide_connected;
    let j = w.create_revolute_joint(&def).unwrap();
    (w, j)
}

#[test]
fn jointed_bodies_do_not_collide_unless_asked() {
    // Without collide_connected the overlapping pair has no contact between its boxes
    // (only the two ground contacts) and stays put; with it, the contact pushes the boxes
    // apart against the joint. Destroying the joint lets the pair collide again.
    let (mut w, j) = overlapping_pair(false);
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    let touching_pairs = w.contacts().filter(|c| !c.points().is_empty()).count();
    assert_eq!(touching_pairs, 2, "only the ground contacts");
    w.destroy_joint(j).unwrap();
    w.step(DT).unwrap();
    w.step(DT).unwrap();
    assert_eq!(w.contacts().filter(|c| !c.points().is_empty()).count(), 3);
    let (mut w2, _) = overlapping_pair(true);
    w2.step(DT).unwrap();
    w2.step(DT).unwrap();
    assert_eq!(w2.contacts().filter(|c| !c.points().is_empty()).count(), 3);
}

#[test]
fn a_jointed_chain_sleeps_and_wakes_as_one_island() {
    // A chain resting on the ground: every link falls asleep together (the joints link
    // the island); a push on one end wakes the whole chain, including links that touch
    // nothing but their joints.
    let mut w = world(Vec2::new(0.0, -G));
    ground(&mut w);
    let mut links = Vec::new();
    for k in 0..5 {
        let b = w
            .create_body(&BodyDef::dynamic(Vec2::new(k as f32 * 1.1, 0.25)))
            .unwrap();
        w.create_shape(
            b,
            &ShapeDef::default(),
            &Shape::Polygon(Polygon::new_box(0.5, 0.25).unwrap()),
        )
        .unwrap();
        if let Some(&prev) = links.last() {
            let anchor = Vec2::new(k as f32 * 1.1 - 0.55, 0.25);
            w.create_revolute_joint(&RevoluteJointDef::at(&w, prev, b, anchor).unwrap())
                .unwrap();
        }
        links.push(b);
    }
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    assert!(links.iter().all(|&b| !w.body_is_awake(b).unwrap()), "the chain sleeps");
    w.apply_linear_impulse_to_center(links[0], Vec2::new(0.0, 2.0), true)
        .unwrap();
    w.step(DT).unwrap();
    assert!(
        links.iter().all(|&b| w.body_is_awake(b).unwrap()),
        "the whole chain woke"
    );
}

#[test]
fn bad_joint_input_is_rejected_and_changes_nothing() {
    let (mut w, ground, d) = wheel(0.5);
    let good = RevoluteJointDef::new(ground, d, Vec2::ZERO, Vec2::ZERO);
    let nan = RevoluteJointDef {
        local_anchor_a: Vec2::new(f32::NAN, 0.0),
        ..good
    };
    let cases: Vec<(RevoluteJointDef, &str)> = vec![
        (nan, "local_anchor_a"),
        (good.limit(0.5, -0.5), "lower_angle"),
        (good.motor(1.0, -2.0), "max_motor_torque"),
        (good.motor(f32::INFINITY, 2.0), "motor_speed"),
        (good.spring(0.0, 0.5), "spring_hertz"),
        (RevoluteJointDef::new(d, d, Vec2::ZERO, Vec2::ZERO), "body_b"),
    ];
    for (def, field) in cases {
        match w.create_revolute_joint(&def) {
            Err(Error::InvalidArgument { name, .. }) => assert!(name.contains(field), "{name} for {field}"),
            other => panic!("{field}: {other:?}"),
        }
        assert_eq!(w.joint_count(), 0, "{field}: nothing created");
    }
    let j = w.create_revolute_joint(&good).unwrap();
    assert!(matches!(
        w.set_revolute_limit(j, true, 1.0, -1.0),
        Err(Error::InvalidArgument { .. })
    ));
    assert!(
        !w.revolute_joint_def(j).unwrap().enable_limit,
        "a refused change changes nothing"
    );
    // Stale ids: the joint destroyed, or its body destroyed with it.
    w.destroy_joint(j).unwrap();
    assert_eq!(w.revolute_angle(j), Err(Error::InvalidJoint(j)));
    let j2 = w.create_revolute_joint(&good).unwrap();
    w.destroy_body(d).unwrap();
    assert!(!w.contains_joint(j2) && w.joint_count() == 0);
    assert_eq!(w.destroy_joint(j2), Err(Error::InvalidJoint(j2)));
}

#[test]
fn joints_give_bit_identical_results_on_any_thread_count() {
    // Joints are solved before the coloured contacts of each pass, block colour by block
    // colour (a chain this short is one block; the blocks of large sets are shared between
    // threads: the world's hanging-grid test and tribo-scenes' joint_grid): the results
    // must not depend on the worker count.
    let run = |workers: u32| {
        let (mut w, _, links) = chain(30, workers, false);
        for _ in 0..120 {
            w.step(DT).unwrap();
        }
        links
            .iter()
            .map(|&b| {
                let p = w.body_position(b).unwrap();
                (p.x.to_bits(), p.y.to_bits(), w.body_angle(b).unwrap().to_bits())
            })
            .collect::<Vec<_>>()
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}
