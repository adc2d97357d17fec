//! The analytic validation experiments (formulas from the team's PHYSICS.md §3).
//!
//! Every experiment runs at dt = 1/60 s with 4 substeps unless it says otherwise and
//! returns [`Check`]s: what was measured, what the formula predicts, and the tolerance with
//! the reason for it. The engine's tests assert them; `tribo validate` prints them.

use crate::build::{self, DT, G};
use tribo::{mix, BodyDef, BodyId, CombineRule, FrictionState, Material, Result, Rot, Vec2, World};

/// How a measured value is compared with the expected one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// |measured − expected| ≤ value × |expected|.
    Relative(f64),
    /// |measured − expected| ≤ value.
    Absolute(f64),
    /// measured ≤ value (the expected value is the ideal, usually 0).
    AtMost(f64),
    /// measured ≥ value.
    AtLeast(f64),
}

/// One measured quantity of an experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// Experiment name, e.g. `incline_stick`.
    pub experiment: String,
    /// What is measured and the formula it is checked against.
    pub formula: String,
    /// The formula's value.
    pub expected: f64,
    /// What the engine did.
    pub measured: f64,
    /// Allowed deviation.
    pub tolerance: Tolerance,
    /// Unit of expected and measured.
    pub unit: &'static str,
    /// Sampled curves (time [s], measured, analytic) for plots; may be empty.
    pub series: Vec<(f64, f64, f64)>,
}

impl Check {
    fn new(
        experiment: &str,
        formula: impl Into<String>,
        expected: f64,
        measured: f64,
        tolerance: Tolerance,
        unit: &'static str,
    ) -> Check {
        Check {
            experiment: experiment.to_string(),
            formula: formula.into(),
            expected,
            measured,
            tolerance,
            unit,
            series: Vec::new(),
        }
    }

    fn with_series(mut self, series: Vec<(f64, f64, f64)>) -> Check {
        self.series = series;
        self
    }

    /// The deviation in the tolerance's terms (relative for `Relative`, else absolute).
    pub fn error(&self) -> f64 {
        match self.tolerance {
            Tolerance::Relative(_) => {
                if self.expected == 0.0 {
                    (self.measured - self.expected).abs()
                } else {
                    ((self.measured - self.expected) / self.expected).abs()
                }
            }
            _ => (self.measured - self.expected).abs(),
        }
    }

    /// Whether the measurement is within tolerance (NaN never passes).
    pub fn passed(&self) -> bool {
        if !self.measured.is_finite() {
            return false;
        }
        match self.tolerance {
            Tolerance::Relative(r) => self.error() <= r,
            Tolerance::Absolute(a) => self.error() <= a,
            Tolerance::AtMost(m) => self.measured <= m,
            Tolerance::AtLeast(m) => self.measured >= m,
        }
    }
}

/// Every experiment, in the order of the report.
pub fn all() -> Result<Vec<Check>> {
    let mut out = Vec::new();
    for f in EXPERIMENTS {
        out.extend((f.1)()?);
    }
    Ok(out)
}

/// Named experiments (name, function).
pub type Experiment = (&'static str, fn() -> Result<Vec<Check>>);

/// The list of experiments.
pub const EXPERIMENTS: &[Experiment] = &[
    ("incline_stick", incline_stick),
    ("incline_slide", incline_slide),
    ("incline_hysteresis", incline_hysteresis),
    ("slide_to_rest", slide_to_rest),
    ("pull", pull),
    ("slip_to_roll", slip_to_roll),
    ("rolling_resistance", rolling_resistance),
    ("restitution", restitution),
    ("conveyor", conveyor),
    ("combine_rules", combine_rules),
    ("stacking", stacking),
    ("mass_ratio", mass_ratio),
    ("mass_ratio_slope", mass_ratio_slope),
    ("conservation", conservation),
];

/// Material of the friction experiments: μs = 0.6, μd = 0.4.
pub fn wood() -> Material {
    Material::default().friction(0.6, 0.4)
}

fn steps(seconds: f32) -> usize {
    (seconds / DT).round() as usize
}

/// Position of a body along a slope of angle θ (uphill positive) [m].
fn along(world: &World, body: BodyId, angle: f32) -> Result<f32> {
    let q = Rot::from_angle(angle);
    Ok(world.body_position(body)?.dot(q.x_axis()))
}

/// Least-squares slope of y over x.
fn fit_slope(xs: &[f64], ys: &[f64]) -> f64 {
    let n = xs.len() as f64;
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// Least-squares line y = a + b x; returns (a, b).
fn fit_line(xs: &[f64], ys: &[f64]) -> (f64, f64) {
    let b = fit_slope(xs, ys);
    let n = xs.len() as f64;
    let a = ys.iter().sum::<f64>() / n - b * xs.iter().sum::<f64>() / n;
    (a, b)
}

/// A block released from rest on a slope with μd < tan θ ≤ μs must not move.
/// tan θ = 0.95 μs: the block sits 5 % below its static limit and 42 % above its dynamic
/// limit, so a one-μ engine (μ = μd) would slide and any creep shows.
pub fn incline_stick() -> Result<Vec<Check>> {
    let m = wood();
    let mut out = Vec::new();
    for ratio in [0.5f32, 0.95] {
        let mixed = mix(&m, &m);
        let angle = (ratio * mixed.friction_static).atan();
        let mut world = build::world_no_sleep(G)?;
        build::slope_ground(&mut world, angle, 20.0, m)?;
        let block = build::box_on_slope(&mut world, angle, 0.0, 0.5, 0.5, m)?;
        let s0 = along(&world, block, angle)?;
        let mut max_disp = 0.0f32;
        for _ in 0..steps(20.0) {
            world.step(DT)?;
            max_disp = max_disp.max((along(&world, block, angle)? - s0).abs());
        }
        out.push(Check::new(
            "incline_stick",
            format!("tan θ = {ratio} μs ≤ μs: block stays; max |displacement| along slope over 20 s"),
            0.0,
            max_disp as f64 * 1000.0,
            // 0.05 mm: the bar; Box2D v3 and Rapier move 0.1–0.25 mm here.
            Tolerance::AtMost(0.05),
            "mm",
        ));
    }
    Ok(out)
}

/// Runs a block on a slope and fits its acceleration along the slope (downhill positive)
/// over [t0, t1]. Returns (acceleration, series of (t, v_measured)).
fn slope_acceleration(angle: f32, v0_down: f32, m: Material, t0: f32, t1: f32) -> Result<(f64, Vec<(f64, f64)>)> {
    let mut world = build::world_no_sleep(G)?;
    build::slope_ground(&mut world, angle, 60.0, m)?;
    let block = build::box_on_slope(&mut world, angle, 40.0, 0.5, 0.5, m)?;
    let q = Rot::from_angle(angle);
    let down = -q.x_axis();
    world.set_body_linear_velocity(block, down * v0_down)?;
    let (mut ts, mut vs, mut series) = (Vec::new(), Vec::new(), Vec::new());
    for k in 1..=steps(t1) {
        world.step(DT)?;
        let t = k as f32 * DT;
        let v = world.body_linear_velocity(block)?.dot(down);
        series.push((t as f64, v as f64));
        if t >= t0 {
            ts.push(t as f64);
            vs.push(v as f64);
        }
    }
    Ok((fit_slope(&ts, &vs), series))
}

/// On a slope steeper than μs the block slides with a = g (sin θ − μd cos θ).
pub fn incline_slide() -> Result<Vec<Check>> {
    let m = wood();
    let mixed = mix(&m, &m);
    let angle = (1.2f32 * mixed.friction_static).atan();
    let expected = G as f64 * ((angle as f64).sin() - mixed.friction_dynamic as f64 * (angle as f64).cos());
    let (a, series) = slope_acceleration(angle, 0.0, m, 0.25, 2.0)?;
    let series = series.into_iter().map(|(t, v)| (t, v, expected * t)).collect();
    Ok(vec![Check::new(
        "incline_slide",
        "tan θ = 1.2 μs: a = g (sin θ − μd cos θ)",
        expected,
        a,
        // 1 %: the bar; the fit over 1.75 s averages out step noise.
        Tolerance::Relative(0.01),
        "m/s²",
    )
    .with_series(series)])
}

/// On a slope with μd < tan θ < μs a pushed block keeps sliding and speeds up at
/// g (sin θ − μd cos θ): the hysteresis a one-μ engine cannot show.
pub fn incline_hysteresis() -> Result<Vec<Check>> {
    let m = wood();
    let mixed = mix(&m, &m);
    let angle = (0.95f32 * mixed.friction_static).atan();
    let expected = G as f64 * ((angle as f64).sin() - mixed.friction_dynamic as f64 * (angle as f64).cos());
    let v0 = 1.0;
    let (a, series) = slope_acceleration(angle, v0, m, 0.1, 2.0)?;
    let series = series
        .into_iter()
        .map(|(t, v)| (t, v, v0 as f64 + expected * t))
        .collect();
    Ok(vec![Check::new(
        "incline_hysteresis",
        "tan θ = 0.95 μs, pushed at 1 m/s: keeps sliding, a = g (sin θ − μd cos θ)",
        expected,
        a,
        Tolerance::Relative(0.01),
        "m/s²",
    )
    .with_series(series)])
}

/// A block sliding on flat ground stops after d = v0² / (2 μd g), then does not creep.
pub fn slide_to_rest() -> Result<Vec<Check>> {
    let m = wood();
    let mixed = mix(&m, &m);
    let v0 = 3.0f32;
    let mut world = build::world_no_sleep(G)?;
    build::flat_ground(&mut world, 50.0, m)?;
    let mut def = BodyDef::dynamic(Vec2::new(0.0, 0.5));
    def.linear_velocity = Vec2::new(v0, 0.0);
    let block = build::dynamic_box(&mut world, def, 0.5, 0.5, m)?;
    let expected = (v0 * v0) as f64 / (2.0 * mixed.friction_dynamic as f64 * G as f64);
    let t_stop = v0 as f64 / (mixed.friction_dynamic as f64 * G as f64);
    let mut series = Vec::new();
    for k in 1..=steps(t_stop as f32 + 1.0) {
        world.step(DT)?;
        let t = k as f64 * DT as f64;
        let tt = t.min(t_stop);
        let analytic = v0 as f64 * tt - 0.5 * mixed.friction_dynamic as f64 * G as f64 * tt * tt;
        series.push((t, world.body_position(block)?.x as f64, analytic));
    }
    let d = world.body_position(block)?.x;
    for _ in 0..steps(5.0) {
        world.step(DT)?;
    }
    let creep = (world.body_position(block)?.x - d).abs();
    Ok(vec![
        Check::new(
            "slide_to_rest",
            "stopping distance d = v0² / (2 μd g), v0 = 3 m/s",
            expected,
            d as f64,
            // 2 %: the bar (the start and the stop each fall inside one step).
            Tolerance::Relative(0.02),
            "m",
        )
        .with_series(series),
        Check::new(
            "slide_to_rest",
            "no creep after stopping: |Δx| over the next 5 s",
            0.0,
            creep as f64 * 1000.0,
            Tolerance::AtMost(0.01),
            "mm",
        ),
    ])
}

/// A constant horizontal force F on a resting block: nothing moves while F ≤ μs m g;
/// above, a = (F − μd m g) / m.
pub fn pull() -> Result<Vec<Check>> {
    let m = wood();
    let mixed = mix(&m, &m);
    let mut out = Vec::new();
    for ratio in [0.95f32, 1.5] {
        let mut world = build::world_no_sleep(G)?;
        build::flat_ground(&mut world, 100.0, m)?;
        let block = build::dynamic_box(&mut world, BodyDef::dynamic(Vec2::new(0.0, 0.5)), 0.5, 0.5, m)?;
        let mass = world.body_mass(block)?;
        let f = ratio * mixed.friction_static * mass * G;
        world.set_body_constant_force(block, Vec2::new(f, 0.0))?;
        let (mut ts, mut vs) = (Vec::new(), Vec::new());
        let mut max_disp = 0.0f32;
        for k in 1..=steps(3.0) {
            world.step(DT)?;
            let t = k as f32 * DT;
            max_disp = max_disp.max(world.body_position(block)?.x.abs());
            if t >= 0.5 {
                ts.push(t as f64);
                vs.push(world.body_linear_velocity(block)?.x as f64);
            }
        }
        if ratio <= 1.0 {
            out.push(Check::new(
                "pull",
                "F = 0.95 μs m g ≤ μs m g: block stays; max |Δx| over 3 s",
                0.0,
                max_disp as f64 * 1000.0,
                Tolerance::AtMost(0.05),
                "mm",
            ));
        } else {
            let expected = (f - mixed.friction_dynamic * mass * G) as f64 / mass as f64;
            out.push(Check::new(
                "pull",
                "F = 1.5 μs m g: a = (F − μd m g) / m",
                expected,
                fit_slope(&ts, &vs),
                Tolerance::Relative(0.02),
                "m/s²",
            ));
        }
    }
    Ok(out)
}

/// A disk launched sliding without spin rolls at v = 2/3 v0 from t = v0 / (3 μd g).
pub fn slip_to_roll() -> Result<Vec<Check>> {
    let m = Material::default().friction(0.5, 0.3);
    let mixed = mix(&m, &m);
    let (v0, r) = (4.0f32, 0.5f32);
    let mut world = build::world_no_sleep(G)?;
    build::flat_ground(&mut world, 50.0, m)?;
    let mut def = BodyDef::dynamic(Vec2::new(0.0, r));
    def.linear_velocity = Vec2::new(v0, 0.0);
    let disk = build::dynamic_disk(&mut world, def, r, m)?;
    let t_expected = v0 as f64 / (3.0 * mixed.friction_dynamic as f64 * G as f64);
    let (mut ts, mut slips, mut series) = (Vec::new(), Vec::new(), Vec::new());
    for k in 1..=steps(t_expected as f32 + 1.0) {
        world.step(DT)?;
        let t = k as f64 * DT as f64;
        let v = world.body_linear_velocity(disk)?.x;
        let w = world.body_angular_velocity(disk)?;
        let slip = (v + w * r) as f64; // contact-point speed; 0 when rolling
        let analytic_v = if t < t_expected {
            v0 as f64 - mixed.friction_dynamic as f64 * G as f64 * t
        } else {
            2.0 / 3.0 * v0 as f64
        };
        series.push((t, v as f64, analytic_v));
        if slip > 0.1 * v0 as f64 {
            ts.push(t);
            slips.push(slip);
        }
    }
    // Slip speed falls linearly while sliding: extrapolate the fitted line to zero for a
    // time resolution finer than one step.
    let (a, b) = fit_line(&ts, &slips);
    let t_roll = -a / b;
    let v_final = world.body_linear_velocity(disk)?.x as f64;
    Ok(vec![
        Check::new(
            "slip_to_roll",
            "final rolling speed v = 2/3 v0 (disk, no initial spin)",
            2.0 / 3.0 * v0 as f64,
            v_final,
            Tolerance::Relative(0.005),
            "m/s",
        )
        .with_series(series),
        Check::new(
            "slip_to_roll",
            "time to roll t = v0 / (3 μd g)",
            t_expected,
            t_roll,
            Tolerance::Relative(0.01),
            "s",
        ),
    ])
}

/// A disk rolling without slip on flat ground under rolling resistance c (Box2D's model:
/// the resisting torque is at most c·R·N) decelerates at a = (2/3)·c·g: from m·a = −f and
/// I·α = f·R − c·R·m·g with a = α·R and I = m·R²/2. It stops after d = v0² / (2a).
pub fn rolling_resistance() -> Result<Vec<Check>> {
    let (v0, r, c) = (2.0f32, 0.5f32, 0.05f32);
    let m = Material {
        rolling_resistance: c,
        ..Material::default().friction(0.8, 0.6)
    };
    let mut world = build::world_no_sleep(G)?;
    build::flat_ground(&mut world, 50.0, Material::default().friction(0.8, 0.6))?;
    let mut def = BodyDef::dynamic(Vec2::new(0.0, r));
    def.linear_velocity = Vec2::new(v0, 0.0);
    def.angular_velocity = -v0 / r;
    let disk = build::dynamic_disk(&mut world, def, r, m)?;
    let a = 2.0 / 3.0 * c as f64 * G as f64;
    let t_stop = v0 as f64 / a;
    let mut series = Vec::new();
    for k in 1..=steps(t_stop as f32 + 1.0) {
        world.step(DT)?;
        let t = k as f64 * DT as f64;
        series.push((
            t,
            world.body_linear_velocity(disk)?.x as f64,
            (v0 as f64 - a * t).max(0.0),
        ));
    }
    let d = world.body_position(disk)?.x as f64;
    Ok(vec![Check::new(
        "rolling_resistance",
        "rolling disk, c = 0.05: stopping distance d = v0² / (2 · (2/3) c g)",
        (v0 as f64).powi(2) / (2.0 * a),
        d,
        // 2 %: as for sliding to rest (start and stop each fall inside one step).
        Tolerance::Relative(0.02),
        "m",
    )
    .with_series(series)])
}

/// Drops a ball of radius 0.25 from a height h (bottom above ground) and returns the
/// successive apex heights of the bottom [m], found by a parabola through the three
/// samples around each maximum.
fn bounce_apexes(h: f32, e: f32, seconds: f32) -> Result<Vec<f64>> {
    let r = 0.25f32;
    let m = Material::default().restitution(e);
    let mut world = build::world_no_sleep(G)?;
    build::flat_ground(&mut world, 10.0, m)?;
    let ball = build::dynamic_disk(&mut world, BodyDef::dynamic(Vec2::new(0.0, r + h)), r, m)?;
    let mut ys = vec![(r + h) as f64];
    for _ in 0..steps(seconds) {
        world.step(DT)?;
        ys.push(world.body_position(ball)?.y as f64);
    }
    let mut apexes = Vec::new();
    for k in 1..ys.len() - 1 {
        let (y0, y1, y2) = (ys[k - 1], ys[k], ys[k + 1]);
        if y1 > y0 && y1 >= y2 && y1 - r as f64 > 1e-3 {
            // Vertex of the parabola through three equally spaced samples.
            let denom = y0 - 2.0 * y1 + y2;
            let apex = if denom < 0.0 {
                y1 - (y2 - y0) * (y2 - y0) / (8.0 * denom)
            } else {
                y1
            };
            apexes.push(apex - r as f64);
        }
    }
    Ok(apexes)
}

/// Bounce apex e² h; no bounce below the restitution threshold; no energy gain at e = 1.
pub fn restitution() -> Result<Vec<Check>> {
    let mut out = Vec::new();
    let (h, e) = (2.0f32, 0.5f32);
    let apexes = bounce_apexes(h, e, 2.5)?;
    out.push(Check::new(
        "restitution",
        "first bounce apex = e² h (e = 0.5, h = 2 m)",
        (e * e * h) as f64,
        apexes.first().copied().unwrap_or(0.0),
        Tolerance::Relative(0.01),
        "m",
    ));
    // Impact speed 0.8 m/s < threshold 1 m/s: must not bounce.
    let h_low = 0.8f32 * 0.8 / (2.0 * G);
    let low = bounce_apexes(h_low, 1.0, 1.0)?;
    out.push(Check::new(
        "restitution",
        "impact 0.8 m/s below the 1 m/s threshold: no bounce (apex count)",
        0.0,
        low.len() as f64,
        Tolerance::AtMost(0.0),
        "bounces",
    ));
    let elastic = bounce_apexes(1.0, 1.0, 20.0)?;
    let mut worst_rise = f64::NEG_INFINITY;
    let mut prev = 1.0f64;
    for &a in elastic.iter().take(20) {
        worst_rise = worst_rise.max(a - prev);
        prev = a;
    }
    out.push(Check::new(
        "restitution",
        "e = 1, h = 1 m: apex never rises over 20 bounces (largest rise)",
        0.0,
        worst_rise * 1000.0,
        // 0.05 mm: one part in 20 000 of the height; float noise, not energy gain.
        Tolerance::AtMost(0.05),
        "mm",
    ));
    out.push(Check::new(
        "restitution",
        "e = 1: bounces counted in 20 s (must be ≥ 20)",
        20.0,
        elastic.len() as f64,
        Tolerance::AtLeast(20.0),
        "bounces",
    ));
    Ok(out)
}

/// A box placed on a belt of surface speed u reaches u after t = u / (μd g).
pub fn conveyor() -> Result<Vec<Check>> {
    let u = 2.0f32;
    let belt = Material {
        tangent_speed: u,
        ..wood()
    };
    let m = wood();
    let mixed = mix(&m, &belt);
    let mut world = build::world_no_sleep(G)?;
    build::flat_ground(&mut world, 50.0, belt)?;
    let block = build::dynamic_box(&mut world, BodyDef::dynamic(Vec2::new(0.0, 0.5)), 0.5, 0.5, m)?;
    let t_expected = u as f64 / (mixed.friction_dynamic as f64 * G as f64);
    let (mut ts, mut vs, mut series) = (Vec::new(), Vec::new(), Vec::new());
    for k in 1..=steps(t_expected as f32 + 1.0) {
        world.step(DT)?;
        let t = k as f64 * DT as f64;
        let v = world.body_linear_velocity(block)?.x as f64;
        series.push((t, v, (mixed.friction_dynamic as f64 * G as f64 * t).min(u as f64)));
        if v < 0.9 * u as f64 && t > 0.05 {
            ts.push(t);
            vs.push(v);
        }
    }
    let (a, b) = fit_line(&ts, &vs);
    let t_reach = (u as f64 - a) / b;
    let v_end = world.body_linear_velocity(block)?.x as f64;
    Ok(vec![
        Check::new(
            "conveyor",
            "time to reach the belt speed t = u / (μd g), u = 2 m/s",
            t_expected,
            t_reach,
            Tolerance::Relative(0.02),
            "s",
        )
        .with_series(series),
        Check::new(
            "conveyor",
            "then rides at u",
            u as f64,
            v_end,
            Tolerance::Relative(0.005),
            "m/s",
        ),
    ])
}

/// Moves a block of material `a` on a slope of material `b` for 3 s; returns the largest
/// displacement along the slope [m].
fn slope_displacement(a: Material, b: Material, tan_theta: f32, seconds: f32) -> Result<f32> {
    let angle = tan_theta.atan();
    let mut world = build::world_no_sleep(G)?;
    build::slope_ground(&mut world, angle, 30.0, b)?;
    let block = build::box_on_slope(&mut world, angle, 0.0, 0.5, 0.5, a)?;
    let s0 = along(&world, block, angle)?;
    let mut max_disp = 0.0f32;
    for _ in 0..steps(seconds) {
        world.step(DT)?;
        max_disp = max_disp.max((along(&world, block, angle)? - s0).abs());
    }
    Ok(max_disp)
}

/// Each combine rule checked through an incline threshold: a block of μ = 0.3 (rule R)
/// on a ground of μ = 0.8 sticks at tan θ = 0.9 μ_R and slides at 1.1 μ_R.
pub fn combine_rules() -> Result<Vec<Check>> {
    let rules = [
        (CombineRule::Average, 0.55f32),
        (CombineRule::GeometricMean, (0.3f32 * 0.8).sqrt()),
        (CombineRule::Min, 0.3),
        (CombineRule::Max, 0.8),
        (CombineRule::Multiply, 0.24),
    ];
    let mut out = Vec::new();
    for (rule, mu) in rules {
        let a = Material {
            friction_combine: Some(rule),
            ..Material::with_friction(0.3)
        };
        let b = Material::with_friction(0.8);
        let stick = slope_displacement(a, b, 0.9 * mu, 3.0)?;
        let slide = slope_displacement(a, b, 1.1 * mu, 3.0)?;
        out.push(Check::new(
            "combine_rules",
            format!("{rule:?}: μ = {mu:.4}; at tan θ = 0.9 μ the block holds (max |Δs| over 3 s)"),
            0.0,
            stick as f64 * 1000.0,
            Tolerance::AtMost(0.05),
            "mm",
        ));
        // Sliding at a = g (sin θ − μ cos θ) covers ≥ 0.5·a·t² minus slack; require 10 cm.
        out.push(Check::new(
            "combine_rules",
            format!("{rule:?}: at tan θ = 1.1 μ the block slides (|Δs| over 3 s, ≥ 0.1 m)"),
            0.1,
            slide as f64,
            Tolerance::AtLeast(0.1),
            "m",
        ));
    }
    Ok(out)
}

/// A 20-row pyramid and a 10-box tower stand 10 s; the top box moves < 1 cm.
pub fn stacking() -> Result<Vec<Check>> {
    let m = Material::default();
    let mut out = Vec::new();
    {
        let mut world = build::world_no_sleep(G)?;
        build::flat_ground(&mut world, 40.0, m)?;
        let boxes = build::pyramid(&mut world, 20, 0.5, 0.0, m)?;
        let top = *boxes.last().unwrap_or(&boxes[0]);
        let p0 = world.body_position(top)?;
        for _ in 0..steps(10.0) {
            world.step(DT)?;
        }
        let moved = (world.body_position(top)? - p0).length();
        out.push(Check::new(
            "stacking",
            "20-row pyramid (210 boxes), 10 s: top box displacement",
            0.0,
            moved as f64 * 100.0,
            Tolerance::AtMost(1.0),
            "cm",
        ));
    }
    {
        let mut world = build::world_no_sleep(G)?;
        build::flat_ground(&mut world, 40.0, m)?;
        let mut top = None;
        for i in 0..10 {
            let def = BodyDef::dynamic(Vec2::new(0.0, 0.5 + i as f32));
            top = Some(build::dynamic_box(&mut world, def, 0.5, 0.5, m)?);
        }
        let top = top.ok_or_else(|| tribo::Error::InvalidArgument {
            name: "tower",
            reason: "no boxes".into(),
        })?;
        let p0 = world.body_position(top)?;
        for _ in 0..steps(10.0) {
            world.step(DT)?;
        }
        let moved = (world.body_position(top)? - p0).length();
        out.push(Check::new(
            "stacking",
            "10-box tower, 10 s: top box displacement",
            0.0,
            moved as f64 * 100.0,
            Tolerance::AtMost(1.0),
            "cm",
        ));
    }
    Ok(out)
}

/// A heavy box (100:1) on a light one, on flat ground and on a slope with tan θ = 0.7 μs:
/// it sinks < 5 mm into the light box and slides < 1 mm over 10 s.
///
/// Both boxes are 2 m wide and 0.5 m tall. (Two stacked unit cubes with the heavy one on
/// top would *tip* at tan θ = 0.42: their common centre of mass sits 1.5 m above the slope
/// and the tipping limit is tan θ = (w/2)/h = 0.33 — toppling there is correct physics,
/// not a solver failure.)
pub fn mass_ratio() -> Result<Vec<Check>> {
    mass_ratio_cases(&[("flat ground", 0.0)])
}

/// [`mass_ratio`] on a slope with tan θ = 0.7 μs.
pub fn mass_ratio_slope() -> Result<Vec<Check>> {
    mass_ratio_cases(&[("slope tan θ = 0.7 μs", 0.7 * mix(&wood(), &wood()).friction_static)])
}

fn mass_ratio_cases(cases: &[(&str, f32)]) -> Result<Vec<Check>> {
    let m = wood();
    let heavy_m = Material { density: 100.0, ..m };
    let (hx, hy) = (1.0f32, 0.25f32);
    let mut out = Vec::new();
    for &(label, tan) in cases {
        let angle = tan.atan();
        let mut world = build::world_no_sleep(G)?;
        build::slope_ground(&mut world, angle, 20.0, m)?;
        let light = build::box_on_slope(&mut world, angle, 0.0, hx, hy, m)?;
        let q = Rot::from_angle(angle);
        let mut def = BodyDef::dynamic(q.rotate(Vec2::new(0.0, 3.0 * hy)));
        def.angle = angle;
        let heavy = build::dynamic_box(&mut world, def, hx, hy, heavy_m)?;
        let s0 = along(&world, heavy, angle)?;
        let normal = q.rotate(Vec2::Y);
        let (mut max_sink, mut max_slide) = (0.0f32, 0.0f32);
        for _ in 0..steps(10.0) {
            world.step(DT)?;
            let gap = (world.body_position(heavy)? - world.body_position(light)?).dot(normal) - 2.0 * hy;
            max_sink = max_sink.max(-gap);
            max_slide = max_slide.max((along(&world, heavy, angle)? - s0).abs());
        }
        out.push(Check::new(
            "mass_ratio",
            format!("100:1 heavy on light, {label}: largest sink into the light box"),
            0.0,
            max_sink as f64 * 1000.0,
            Tolerance::AtMost(5.0),
            "mm",
        ));
        out.push(Check::new(
            "mass_ratio",
            format!("100:1 heavy on light, {label}: largest slide along the surface"),
            0.0,
            max_slide as f64 * 1000.0,
            Tolerance::AtMost(1.0),
            "mm",
        ));
    }
    Ok(out)
}

/// Zero gravity, e = 1, μ = 0: collisions conserve linear and angular momentum and never
/// raise kinetic energy; with e = 0.5, energy never rises either.
pub fn conservation() -> Result<Vec<Check>> {
    let mut out = Vec::new();
    for e in [1.0f32, 0.5] {
        let m = Material {
            restitution: e,
            restitution_threshold: 0.0,
            ..Material::with_friction(0.0)
        };
        let mut world = build::world_no_sleep(0.0)?;
        let mut bodies = Vec::new();
        // A ring of boxes and disks flying at each other with spin, off-centre.
        for i in 0..12 {
            let a = i as f32 * core::f32::consts::TAU / 12.0;
            let p = Vec2::new(a.cos(), a.sin()) * 6.0;
            let mut def = BodyDef::dynamic(p);
            def.linear_velocity = Vec2::new(-p.x + 0.7 * p.y, -p.y - 0.3 * p.x) * 0.8;
            def.angular_velocity = if i % 2 == 0 { 1.5 } else { -0.7 };
            def.angle = 0.3 * i as f32;
            let b = if i % 3 == 0 {
                build::dynamic_disk(&mut world, def, 0.6, m)?
            } else {
                build::dynamic_box(&mut world, def, 0.5, 0.3 + 0.05 * i as f32, m)?
            };
            bodies.push(b);
        }
        let measure = |world: &World| -> Result<(Vec2, f64, f64, f64)> {
            let (mut p, mut l, mut ke, mut scale) = (Vec2::ZERO, 0.0f64, 0.0f64, 0.0f64);
            for &b in &bodies {
                let (mass, inertia) = (world.body_mass(b)?, world.body_rotational_inertia(b)?);
                let (v, w, c) = (
                    world.body_linear_velocity(b)?,
                    world.body_angular_velocity(b)?,
                    world.body_center_of_mass(b)?,
                );
                p += mass * v;
                l += (inertia * w) as f64 + (mass * c.cross(v)) as f64;
                ke += 0.5 * (mass * v.length_squared()) as f64 + 0.5 * (inertia * w * w) as f64;
                scale += (mass * v.length()) as f64;
            }
            Ok((p, l, ke, scale))
        };
        let (p0, l0, ke0, scale) = measure(&world)?;
        let (mut dp, mut dl, mut rise, mut ke_prev) = (0.0f64, 0.0f64, 0.0f64, ke0);
        let mut contacts_seen = 0usize;
        for _ in 0..steps(4.0) {
            world.step(DT)?;
            contacts_seen += world.contact_events().begin.len();
            let (p, l, ke, _) = measure(&world)?;
            dp = dp.max(((p - p0).length() as f64) / scale);
            dl = dl.max((l - l0).abs() / (scale * 6.0));
            rise = rise.max((ke - ke_prev) / ke0);
            ke_prev = ke;
        }
        let tag = format!("e = {e}, μ = 0, no gravity ({contacts_seen} contacts began)");
        out.push(Check::new(
            "conservation",
            format!("{tag}: linear momentum change / Σ|p|"),
            0.0,
            dp,
            Tolerance::AtMost(1e-6),
            "",
        ));
        out.push(Check::new(
            "conservation",
            format!("{tag}: angular momentum change / (Σ|p| · 6 m)"),
            0.0,
            dl,
            Tolerance::AtMost(1e-6),
            "",
        ));
        out.push(Check::new(
            "conservation",
            format!("{tag}: largest kinetic-energy rise in one step / KE0"),
            0.0,
            rise,
            // float noise only: 1e-6 of the total.
            Tolerance::AtMost(1e-6),
            "",
        ));
        if contacts_seen == 0 {
            out.push(Check::new(
                "conservation",
                "collisions happened",
                1.0,
                0.0,
                Tolerance::AtLeast(1.0),
                "contacts",
            ));
        }
    }
    Ok(out)
}

/// Friction state of every contact point of a body (used by tests of the state machine).
pub fn friction_states(world: &World, body: BodyId) -> Result<Vec<FrictionState>> {
    Ok(world
        .body_contacts(body)?
        .iter()
        .flat_map(|c| c.points().iter().map(|p| p.state).collect::<Vec<_>>())
        .collect())
}
