//! `tribo-bench`: times Tribo, Box2D v3 (boxdd) and Rapier side by side, in one process,
//! on Box2D v3's benchmark scenes (shared/SCENES.md §1–§2).
//!
//! Timing loop (SCENES.md §1): build the scene (untimed); one untimed step; time steps
//! 1 … N−1; repeat for R runs. Runs are interleaved (run 1 of every engine, then run 2, …)
//! so background noise spreads over all engines. Reported: ms/step median and min over runs.
//!
//! `tribo-bench scaling` instead runs the scaling scenes (`scaling_rain_<n>`: n bodies
//! raining into a container whose width grows ∝ n) for every n of `--sizes` and prints
//! ms/step and µs/step per body for each n and engine.
//!
//! Build Box2D with release C flags: `CFLAGS="-O3 -DNDEBUG"` (see run.sh).

mod engines;
mod scenes;

use clap::Parser;
use engines::{BoxError, EngineKind, Sim};
use scenes::{BenchScene, CheckKind};
use serde_json::json;
use std::io::Write;
use std::time::Instant;
use tribo_scenes::format::{BodyKind, SceneFile};

#[derive(Parser, Debug)]
#[command(
    name = "tribo-bench",
    about = "Tribo vs Box2D v3 vs Rapier on Box2D's benchmark scenes"
)]
struct Args {
    /// Scene to run: large_pyramid, many_pyramids, smash, tumbler, compounds, junkyard,
    /// joint_grid, spinner, rain, washer, or all (these ten); `scaling` runs the scaling scenes
    /// of `--sizes` instead; `scaling_rain_<n>` runs one.
    #[arg(default_value = "all", value_name = "SCENE")]
    scene_pos: String,
    /// Same as the positional SCENE (overrides it).
    #[arg(long)]
    scene: Option<String>,
    /// Runs per engine and scene (median and min are over these).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Scaling run: body counts n of the `scaling_rain_<n>` scenes, comma separated.
    #[arg(long, default_value = "1000,4000,16000,64000", value_delimiter = ',')]
    sizes: Vec<usize>,
    /// Scaling run: runs for scenes of more than 20 000 bodies (at most `--runs`); one run
    /// of the 64 000-body scene takes about a minute per engine on a 2-core machine.
    #[arg(long, default_value_t = 1)]
    large_runs: usize,
    /// Override the scene's step count N (N−1 steps are timed); for smoke runs.
    #[arg(long)]
    steps: Option<u32>,
    /// Worker threads for Tribo (`WorldDef::workers`), Box2D (workerCount) and Rapier (its
    /// rayon pool, only with the `rapier-parallel` feature). Above 1, Tribo and Box2D are
    /// also timed on one thread in the same interleaved runs, for a thread-scaling table.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Engines to time, comma separated (tribo, box2d, rapier).
    #[arg(long, default_value = "tribo,box2d,rapier", value_delimiter = ',')]
    engines: Vec<String>,
    /// Skip the second table (Tribo with μs = 1.5 μd); the scaling run always skips it.
    #[arg(long)]
    no_friction_table: bool,
    /// Write one JSON line per (scene, engine) to this file ("-" = stdout).
    #[arg(long)]
    json: Option<String>,
    /// Print each engine's per-stage profile (sampling adds a little time to each step).
    #[arg(long)]
    profile: bool,
}

/// Result of the stability check of one run.
#[derive(Clone, Debug)]
struct Check {
    passed: bool,
    text: String,
    json: serde_json::Value,
}

/// One scene's results, for the summary tables.
struct SceneResult {
    name: String,
    /// Dynamic bodies.
    dynamic: usize,
    /// Steps per run (the first untimed).
    steps: u32,
    results: Vec<EngineResult>,
}

/// Everything measured for one (scene, engine).
struct EngineResult {
    kind: EngineKind,
    /// Worker threads asked for (the engine reports what it used in `threads`).
    threads_asked: usize,
    ms: Vec<f64>,
    build_s: Vec<f64>,
    check: Option<Check>,
    all_passed: bool,
    threads: usize,
    contacts: usize,
    profile: String,
}

impl EngineResult {
    fn median(&self) -> f64 {
        let mut v = self.ms.clone();
        v.sort_by(|a, b| a.total_cmp(b));
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    fn min(&self) -> f64 {
        self.ms.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), BoxError> {
    let scene_name = args.scene.clone().unwrap_or_else(|| args.scene_pos.clone());
    let scaling = scene_name == "scaling";
    let selected: Vec<BenchScene> = if scaling {
        if args.sizes.is_empty() || args.sizes.contains(&0) {
            return Err("--sizes needs body counts of at least 1".into());
        }
        args.sizes.iter().map(|&n| scenes::scaling_scene(n)).collect()
    } else if scene_name == "all" {
        scenes::scenes()
    } else if let Some(n) = scene_name
        .strip_prefix("scaling_rain_")
        .and_then(|n| n.parse::<usize>().ok())
        .filter(|&n| n > 0)
    {
        vec![scenes::scaling_scene(n)]
    } else {
        let mut all = scenes::scenes();
        let names: Vec<String> = all.iter().map(|s| s.name.clone()).collect();
        let i = all.iter().position(|s| s.name == scene_name).ok_or_else(|| {
            format!(
                "unknown scene {scene_name} (known: {}, all, scaling, scaling_rain_<n>)",
                names.join(", ")
            )
        })?;
        vec![all.swap_remove(i)]
    };
    let mut kinds = Vec::new();
    for e in &args.engines {
        kinds.push(match e.as_str() {
            "tribo" => EngineKind::Tribo,
            "box2d" => EngineKind::Box2d,
            "rapier" => EngineKind::Rapier,
            other => return Err(format!("unknown engine {other} (tribo, box2d, rapier)").into()),
        });
    }
    if !args.no_friction_table && !scaling && kinds.contains(&EngineKind::Tribo) {
        kinds.push(EngineKind::TriboMus15);
    }
    let mut runs_of: Vec<(EngineKind, usize)> = kinds.iter().map(|&k| (k, args.threads)).collect();
    if args.threads > 1 && !scaling {
        // The same engines on one thread, in the same interleaved runs: the speed-up is
        // measured within one invocation, not across runs minutes apart.
        for k in [EngineKind::Tribo, EngineKind::Box2d] {
            if kinds.contains(&k) {
                runs_of.push((k, 1));
            }
        }
    }
    if args.runs == 0 || args.large_runs == 0 {
        return Err("--runs and --large-runs must be at least 1".into());
    }
    if args.threads == 0 {
        return Err("--threads must be at least 1".into());
    }
    let mut json_out: Option<Box<dyn Write>> = match args.json.as_deref() {
        None => None,
        Some("-") => Some(Box::new(std::io::stdout())),
        Some(path) => Some(Box::new(std::fs::File::create(path)?)),
    };

    print_header(args);
    let mut all_results = Vec::new();
    for bench in &selected {
        let mut scene = (bench.build)();
        if let Some(n) = args.steps {
            scene.steps = n.max(2);
        }
        let dynamic = dynamic_count(&scene);
        let runs = if scaling && dynamic > 20_000 {
            args.large_runs.min(args.runs)
        } else {
            args.runs
        };
        let results = run_scene(bench, &scene, &runs_of, args, runs)?;
        print_scene_table(bench, &scene, &results, args);
        if let Some(out) = json_out.as_mut() {
            for r in &results {
                let line = json!({
                    "scene": bench.name,
                    "engine": r.kind.name(),
                    "threads": r.threads,
                    "runs": r.ms.len(),
                    "steps": scene.steps,
                    "timed_steps": scene.steps - 1,
                    "ms_per_step_median": r.median(),
                    "ms_per_step_min": r.min(),
                    "ms_per_step_runs": r.ms,
                    "us_per_step_per_body_median": 1000.0 * r.median() / dynamic as f64,
                    "build_s_median": median(&r.build_s),
                    "check_passed": r.all_passed,
                    "check": r.check.as_ref().map(|c| c.json.clone()),
                    "contacts": r.contacts,
                    "bodies": scene.bodies.len(),
                    "dynamic_bodies": dynamic,
                    // How the engine's wide solver was built (Box2D's AVX2 path is a build
                    // option, `box2d-avx2`).
                    "simd": r.kind.simd(),
                });
                writeln!(out, "{line}")?;
            }
            out.flush()?;
        }
        all_results.push(SceneResult {
            name: bench.name.clone(),
            dynamic,
            steps: scene.steps,
            results,
        });
    }
    if kinds.contains(&EngineKind::TriboMus15) {
        print_friction_table(&all_results, args);
    }
    if args.threads > 1 && !scaling {
        print_thread_table(&all_results, args);
    }
    if scaling {
        print_scaling_table(&all_results, &selected, args);
    }
    Ok(())
}

fn dynamic_count(scene: &SceneFile) -> usize {
    scene.bodies.iter().filter(|b| b.kind == BodyKind::Dynamic).count()
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn print_header(args: &Args) {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0);
    let b2 = boxdd::Foundation::initialize_default()
        .and_then(|_| boxdd::version())
        .map(|v| format!("{}.{}.{}", v.major, v.minor, v.revision));
    println!("tribo-bench: CPU {cpu}, {cores} cores available");
    match engines::tribo_lanes() {
        tribo::SolverLanes::Four => println!(
            "Tribo {} on this CPU; here worlds with SolverLanes::Four: 4 lanes (TRIBO_BENCH_LANES=4)",
            tribo::build_info()
        ),
        tribo::SolverLanes::Eight => println!(
            "Tribo {} on this CPU; here worlds with SolverLanes::Eight: {} (TRIBO_BENCH_LANES=8)",
            tribo::build_info(),
            if tribo::solver_lanes() == 8 {
                "8 lanes, AVX2 only"
            } else {
                "4 lanes (no AVX2 here)"
            }
        ),
        _ => println!("Tribo {}", tribo::build_info()),
    }
    println!(
        "Box2D {} via boxdd 0.6 (C flags from CFLAGS: \"{}\"; SIMD: {}), Rapier 0.36 ({}{}), Rust profile {}",
        b2.unwrap_or_else(|_| "?".into()),
        env!("TRIBO_BENCH_CFLAGS"),
        if cfg!(feature = "box2d-avx2") {
            "AVX2, 8 lanes, boxdd's simd-avx2"
        } else {
            "SSE2, 4 lanes, Box2D's default"
        },
        if cfg!(feature = "rapier-parallel") {
            "parallel feature on"
        } else {
            "serial build"
        },
        if cfg!(target_feature = "avx2") {
            ", compiled for AVX2"
        } else {
            ""
        },
        env!("TRIBO_BENCH_PROFILE"),
    );
    println!(
        "runs {}, threads {}{}",
        args.runs,
        args.threads,
        if args.steps.is_some() {
            ", step count overridden"
        } else {
            ""
        }
    );
    if env!("TRIBO_BENCH_PROFILE") != "release" {
        println!("WARNING: not a release build; timings are meaningless");
    }
    if !env!("TRIBO_BENCH_CFLAGS").contains("NDEBUG") {
        println!("WARNING: Box2D built without -DNDEBUG (asserts on, boxdd-sys default -O2)");
    }
    println!();
}

fn run_scene(
    bench: &BenchScene,
    scene: &SceneFile,
    kinds: &[(EngineKind, usize)],
    args: &Args,
    runs: usize,
) -> Result<Vec<EngineResult>, BoxError> {
    let mut results: Vec<EngineResult> = kinds
        .iter()
        .map(|&(kind, threads_asked)| EngineResult {
            kind,
            threads_asked,
            ms: Vec::new(),
            build_s: Vec::new(),
            check: None,
            all_passed: true,
            threads: 1,
            contacts: 0,
            profile: String::new(),
        })
        .collect();
    let timed = scene.steps - 1;
    for run in 0..runs {
        for r in results.iter_mut() {
            let t_build = Instant::now();
            let mut sim = engines::build(r.kind, scene, r.threads_asked)?;
            let build_s = t_build.elapsed().as_secs_f64();
            let awake_at_build = sim.awake_count();
            if let Some(hook) = bench.hook {
                scenes::run_hook(hook, 0, sim.as_mut(), scene)?;
            }
            sim.step()?; // untimed first step (index 0)
            let awake_after_first = sim.awake_count();
            let t0 = Instant::now();
            // The scene's hook runs inside the timed loop (Box2D's driver does the same).
            for n in 1..=timed {
                if let Some(hook) = bench.hook {
                    scenes::run_hook(hook, n, sim.as_mut(), scene)?;
                }
                sim.step()?;
                if args.profile {
                    sim.profile_sample();
                }
            }
            let ms = t0.elapsed().as_secs_f64() * 1000.0 / timed as f64;
            let check = check(bench, scene, sim.as_mut());
            eprintln!(
                "  {} run {}/{} {:<13} {:>2}t {:>9.3} ms/step (build {:.2} s; awake bodies at build/after step 0/end: {}/{}/{}) {}",
                bench.name,
                run + 1,
                runs,
                r.kind.name(),
                r.threads_asked,
                ms,
                build_s,
                awake_at_build,
                awake_after_first,
                sim.awake_count(),
                if check.passed { "ok" } else { "CHECK FAILED" }
            );
            r.ms.push(ms);
            r.build_s.push(build_s);
            r.all_passed &= check.passed;
            r.threads = sim.threads();
            r.contacts = sim.contact_count();
            if args.profile {
                r.profile = sim.profile_report();
            }
            r.check = Some(check);
        }
    }
    Ok(results)
}

/// Pyramids: the top box(es) — the dynamic bodies of highest initial y (all pyramids'
/// tops in the highest row for many_pyramids) — must drop less than 10 mm per stacked
/// layer (1.0 m for large_pyramid's 100 layers, 0.1 m for many_pyramids' 10: each resting
/// contact of a soft-contact solver may keep up to the 5 mm linear slop as penetration, so
/// a correct engine's top box sinks up to ~5 mm per layer; a collapse drops metres) and
/// drift less than 0.5 m sideways, and the pile must be at rest at the end (mean body
/// speed below [`MAX_END_MEAN_SPEED`]). Smash: the projectile must have hit and ploughed into the block
/// (final x in (30, 180) m, final speed in (1, 39) m/s; 180 m and 40 m/s would mean it
/// passed through untouched) and total linear momentum must be conserved within 1 %
/// (no gravity, no static bodies). Tumbler: every box centre, turned into the drum's frame
/// (the drum's angle is ω t, t = steps · dt: it is kinematic), must be inside the drum,
/// |x|, |y| < 9.5 m (the inner faces of its walls), and the engine's own drum angle must be
/// ω t within 0.01 rad. Scaling rain: every body centre must be inside the container,
/// |x| < its inner half width and y > 0 m (the floor's top). Every dynamic body's position
/// must stay finite.
/// A pyramid at the end of its run must be at rest: mean body speed below this [m/s]
/// (Box2D v3 ends large_pyramid at 0.005 m/s, Rapier at 0.027; a swaying pile is faster).
const MAX_END_MEAN_SPEED: f32 = 0.05;

fn check(bench: &BenchScene, scene: &SceneFile, sim: &mut dyn Sim) -> Check {
    let dynamic: Vec<usize> = (0..scene.bodies.len())
        .filter(|&i| scene.bodies[i].kind == BodyKind::Dynamic)
        .collect();
    let mut finite = true;
    let mut max_disp = 0.0f32;
    let (mut max_speed, mut sum_speed) = (0.0f32, 0.0f32);
    for &i in &dynamic {
        let p = sim.position(i);
        let p0 = scene.bodies[i].position;
        if !(p[0].is_finite() && p[1].is_finite()) {
            finite = false;
        } else {
            max_disp = max_disp.max(((p[0] - p0[0]).powi(2) + (p[1] - p0[1]).powi(2)).sqrt());
        }
        let v = sim.velocity(i);
        let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
        max_speed = max_speed.max(speed);
        sum_speed += speed;
    }
    let mean_speed = sum_speed / dynamic.len().max(1) as f32;
    match bench.check {
        CheckKind::Pyramid { stack_layers } => {
            let max_drop = 0.01 * stack_layers as f32;
            let y_top = dynamic
                .iter()
                .map(|&i| scene.bodies[i].position[1])
                .fold(f32::NEG_INFINITY, f32::max);
            let tops: Vec<usize> = dynamic
                .iter()
                .copied()
                .filter(|&i| scene.bodies[i].position[1] >= y_top - 1e-3)
                .collect();
            let (mut drop, mut drift) = (0.0f32, 0.0f32);
            for &i in &tops {
                let p = sim.position(i);
                let p0 = scene.bodies[i].position;
                let d = p0[1] - p[1];
                if d.abs() > drop.abs() || d.is_nan() {
                    drop = d;
                }
                drift = drift.max((p[0] - p0[0]).abs());
            }
            let passed = finite && drop.abs() < max_drop && drift < 0.5 && mean_speed < MAX_END_MEAN_SPEED;
            Check {
                passed,
                text: format!(
                    "top drop {:.4} m (< {:.2}), drift {:.4} m (< 0.5) ({} top box{}); max |Δp| any box {:.3} m; \
                     speed at the end: max {:.3}, mean {:.4} m/s (< {MAX_END_MEAN_SPEED})",
                    drop,
                    max_drop,
                    drift,
                    tops.len(),
                    if tops.len() == 1 { "" } else { "es" },
                    max_disp,
                    max_speed,
                    mean_speed
                ),
                json: json!({"top_drop_m": drop, "top_drop_limit_m": max_drop, "top_drift_m": drift, "tops": tops.len(),
                             "max_displacement_m": max_disp, "finite": finite,
                             "end_max_speed_m_s": max_speed, "end_mean_speed_m_s": mean_speed}),
            }
        }
        CheckKind::Smash => {
            let proj = scene
                .bodies
                .iter()
                .position(|b| b.name.as_deref() == Some("projectile"))
                .unwrap_or(dynamic[0]);
            let p = sim.position(proj);
            let v = sim.velocity(proj);
            let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
            let (mut p0, mut p1) = ([0.0f64; 2], [0.0f64; 2]);
            for &i in &dynamic {
                let m = sim.mass(i) as f64;
                let v0 = scene.bodies[i].linear_velocity;
                let v1 = sim.velocity(i);
                p0[0] += m * v0[0] as f64;
                p0[1] += m * v0[1] as f64;
                p1[0] += m * v1[0] as f64;
                p1[1] += m * v1[1] as f64;
            }
            let p0n = (p0[0] * p0[0] + p0[1] * p0[1]).sqrt();
            let err = ((p1[0] - p0[0]).powi(2) + (p1[1] - p0[1]).powi(2)).sqrt() / p0n.max(1e-9);
            let passed = finite && p[0] > 30.0 && p[0] < 180.0 && speed > 1.0 && speed < 39.0 && err < 0.01;
            Check {
                passed,
                text: format!(
                    "projectile x {:.2} m, speed {:.2} m/s; momentum error {:.2e}",
                    p[0], speed, err
                ),
                json: json!({"projectile_x_m": p[0], "projectile_speed_m_s": speed,
                             "momentum_rel_error": err, "finite": finite}),
            }
        }
        CheckKind::Tumbler => {
            let drum = named_body(scene, "drum");
            let c = scene.bodies[drum].position;
            let (measured, expected, angle_err) = kinematic_angle(scene, sim, drum);
            let (s, co) = expected.sin_cos();
            let limit = 9.5f32;
            let (mut outside, mut max_abs) = (0usize, 0.0f32);
            let boxes: Vec<usize> = dynamic.iter().copied().filter(|&i| i != drum).collect();
            for &i in &boxes {
                let p = sim.position(i);
                let d = [p[0] - c[0], p[1] - c[1]];
                // Into the drum's frame: rotate by −angle.
                let local = [co * d[0] + s * d[1], -s * d[0] + co * d[1]];
                let m = local[0].abs().max(local[1].abs());
                if m.is_nan() || m >= limit {
                    outside += 1;
                }
                if m.is_finite() {
                    max_abs = max_abs.max(m);
                }
            }
            let passed = finite && outside == 0 && angle_err.abs() < 0.01;
            Check {
                passed,
                text: format!(
                    "{outside} of {} boxes outside the drum (|x|,|y| < {limit} m in its frame; max {max_abs:.3} m); \
                     drum angle {measured:.4} rad vs ω t = {expected:.4} ≡ {:.4} rad (err {angle_err:.1e})",
                    boxes.len(),
                    measured - angle_err
                ),
                json: json!({"boxes_outside": outside, "boxes": boxes.len(), "max_local_abs_m": max_abs,
                             "limit_m": limit, "drum_angle_rad": measured, "drum_angle_expected_rad": expected,
                             "finite": finite}),
            }
        }
        CheckKind::JointGrid { max_link } => {
            let mut longest = 0.0f32;
            for j in &scene.joints {
                let (Ok(a), Ok(b)) = (scene.resolve_body("", &j.body_a), scene.resolve_body("", &j.body_b)) else {
                    continue;
                };
                let (pa, pb) = (sim.position(a), sim.position(b));
                let d = ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2)).sqrt();
                longest = if d.is_nan() { f32::NAN } else { longest.max(d) };
            }
            let lowest = dynamic
                .iter()
                .map(|&i| sim.position(i)[1])
                .fold(f32::INFINITY, f32::min);
            let passed = finite && longest < max_link;
            Check {
                passed,
                text: format!(
                    "longest link {longest:.3} m (< {max_link}; rest length 1 m) over {} joints; lowest body at \
                     y {lowest:.2} m; speed at the end: max {max_speed:.3}, mean {mean_speed:.4} m/s",
                    scene.joints.len()
                ),
                json: json!({"longest_link_m": longest, "limit_m": max_link, "lowest_y_m": lowest,
                             "end_max_speed_m_s": max_speed, "end_mean_speed_m_s": mean_speed, "finite": finite}),
            }
        }
        CheckKind::Spinner { radius } => {
            let rotor = named_body(scene, "rotor");
            let c = tribo_scenes::scenes::SPINNER_CENTER;
            let bodies: Vec<usize> = dynamic.iter().copied().filter(|&i| i != rotor).collect();
            let (escaped, max_r) = outside_circle(sim, &bodies, c, radius);
            let target = tribo_scenes::scenes::SPINNER_MOTOR_SPEED;
            let w = sim.angular_velocity(rotor);
            let passed = finite && escaped == 0 && (w - target).abs() < 0.01 * target;
            Check {
                passed,
                text: format!(
                    "{escaped} of {} bodies out of the ring (centre ≥ {radius} m from the ring's centre; max {max_r:.3} m); \
                     rotor at {w:.4} rad/s (motor {target} rad/s, within 1 %)",
                    dynamic.len() - 1
                ),
                json: json!({"bodies_escaped": escaped, "max_radius_m": max_r, "ring_limit_m": radius,
                             "rotor_speed_rad_s": w, "motor_speed_rad_s": target, "finite": finite}),
            }
        }
        CheckKind::Washer { radius } => {
            let ring = scene
                .bodies
                .iter()
                .position(|b| b.kind == BodyKind::Kinematic)
                .unwrap_or(0);
            let r = &scene.bodies[ring];
            let t = scene.steps as f32 * scene.dt;
            let c = [
                r.position[0] + r.linear_velocity[0] * t,
                r.position[1] + r.linear_velocity[1] * t,
            ];
            let (measured, expected, angle_err) = kinematic_angle(scene, sim, ring);
            let (outside, max_r) = outside_circle(sim, &dynamic, c, radius);
            let passed = finite && outside == 0 && angle_err.abs() < 0.01;
            Check {
                passed,
                text: format!(
                    "{outside} of {} boxes outside the rim (r < {radius} m of the ring centre; max {max_r:.3} m); \
                     ring angle {measured:.4} rad vs ω t ≡ {:.4} rad (err {angle_err:.1e})",
                    dynamic.len(),
                    measured - angle_err
                ),
                json: json!({"boxes_outside": outside, "boxes": dynamic.len(), "max_radius_m": max_r,
                             "limit_m": radius, "ring_angle_rad": measured, "ring_angle_expected_rad": expected,
                             "finite": finite}),
            }
        }
        CheckKind::RagdollRain => {
            let (bodies, below, off, lowest, finite) = scenes::rain_census(sim);
            Check {
                passed: finite && below == 0 && bodies > 0,
                text: format!(
                    "{below} of {bodies} ragdoll bodies below their shelf's top (lowest {lowest:.3} m above it), \
                     {off} off a shelf's end"
                ),
                json: json!({"bodies": bodies, "below_shelf": below, "off_shelf": off,
                             "lowest_above_shelf_m": lowest, "finite": finite}),
            }
        }
        CheckKind::Rain {
            half_width,
            max_outside,
            catch_y,
        } => {
            let (mut outside, mut y_top, mut y_low) = (0usize, f32::NEG_INFINITY, f32::INFINITY);
            for &i in &dynamic {
                let p = sim.position(i);
                if !(p[0].abs() < half_width && p[1] > 0.0) {
                    outside += 1;
                }
                if p[1].is_finite() {
                    y_top = y_top.max(p[1]);
                    y_low = y_low.min(p[1]);
                }
            }
            let passed = finite && outside <= max_outside && (outside == 0 || y_low > catch_y);
            Check {
                passed,
                text: format!(
                    "{outside} of {} bodies outside the container (|x| < {half_width} m, y > 0; at most \
                     {max_outside}{}); body centres at y {y_low:.3} … {y_top:.2} m",
                    dynamic.len(),
                    if max_outside > 0 {
                        format!(", caught above y = {catch_y} m")
                    } else {
                        String::new()
                    }
                ),
                json: json!({"bodies_outside": outside, "bodies": dynamic.len(), "half_width_m": half_width,
                             "lowest_y_m": y_low, "highest_y_m": y_top, "finite": finite}),
            }
        }
    }
}

/// How many of `bodies` have their centre at `radius` [m] or more from `c` (or not
/// finite), and the largest finite distance [m].
fn outside_circle(sim: &mut dyn Sim, bodies: &[usize], c: [f32; 2], radius: f32) -> (usize, f32) {
    let (mut outside, mut max_r) = (0usize, 0.0f32);
    for &i in bodies {
        let p = sim.position(i);
        let d = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt();
        if d.is_nan() || d >= radius {
            outside += 1;
        }
        if d.is_finite() {
            max_r = max_r.max(d);
        }
    }
    (outside, max_r)
}

/// The index of the body with this name (0 if none).
fn named_body(scene: &SceneFile, name: &str) -> usize {
    scene
        .bodies
        .iter()
        .position(|b| b.name.as_deref() == Some(name))
        .unwrap_or(0)
}

/// A driven body's angle after the run: (the engine's, ω t from the scene, their
/// difference wrapped to (−π, π]). ω is the body's own angular velocity for a kinematic
/// body, or the speed of the motor of a joint that holds it to a static body.
fn kinematic_angle(scene: &SceneFile, sim: &mut dyn Sim, body: usize) -> (f32, f32, f32) {
    let b = &scene.bodies[body];
    let motor = scene.joints.iter().find_map(|j| {
        let (a, bb) = (
            scene.resolve_body("", &j.body_a).ok()?,
            scene.resolve_body("", &j.body_b).ok()?,
        );
        if bb == body && scene.bodies[a].kind == BodyKind::Static {
            j.motor.map(|m| m.speed)
        } else {
            None
        }
    });
    let omega = motor.unwrap_or(b.angular_velocity);
    let expected = b.angle + omega * scene.steps as f32 * scene.dt;
    let measured = sim.angle(body);
    let pi = std::f32::consts::PI;
    let err = (measured - expected + pi).rem_euclid(std::f32::consts::TAU) - pi;
    (measured, expected, err)
}

fn print_scene_table(bench: &BenchScene, scene: &SceneFile, results: &[EngineResult], args: &Args) {
    let dynamic = scene.bodies.iter().filter(|b| b.kind == BodyKind::Dynamic).count();
    println!(
        "== {}: {} dynamic bodies{}, {} steps ({} timed), {} runs, sleep {}",
        bench.name,
        dynamic,
        if bench.hook.is_some() && dynamic == 0 {
            " at the start (the step hook creates and destroys them)"
        } else {
            ""
        },
        scene.steps,
        scene.steps - 1,
        results.first().map_or(0, |r| r.ms.len()),
        if scene.enable_sleep { "on" } else { "off" }
    );
    if !bench.note.is_empty() {
        println!("   note: {}", bench.note);
    }
    let main_rows = |r: &&EngineResult| r.threads_asked == args.threads;
    let tribo = results.iter().filter(main_rows).find(|r| r.kind == EngineKind::Tribo);
    println!(
        "{:<8} {:>7} {:>14} {:>11} {:>14} {:>11} {:>9}  check (last run)",
        "engine", "threads", "median ms/step", "min ms/step", "Tribo/peer med", "Tribo/peer min", "contacts"
    );
    for r in results
        .iter()
        .filter(main_rows)
        .filter(|r| r.kind != EngineKind::TriboMus15)
    {
        let (rm, rn) = match tribo {
            Some(t) => (
                format!("{:.2}", t.median() / r.median()),
                format!("{:.2}", t.min() / r.min()),
            ),
            None => ("-".into(), "-".into()),
        };
        let check = r.check.as_ref().map_or(String::new(), |c| c.text.clone());
        println!(
            "{:<8} {:>7} {:>14.3} {:>11.3} {:>14} {:>11} {:>9}  {} {}",
            r.kind.name(),
            r.threads,
            r.median(),
            r.min(),
            rm,
            rn,
            r.contacts,
            if r.all_passed { "PASS" } else { "FAIL" },
            check
        );
    }
    if args.profile {
        for r in results {
            println!("  profile {} ({} threads): {}", r.kind.name(), r.threads, r.profile);
        }
    }
    println!();
}

fn print_friction_table(all: &[SceneResult], args: &Args) {
    println!("== Tribo: cost of the static/dynamic friction model (every shape's μs scaled by 1.5, μd unchanged)");
    println!(
        "{:<14} {:>16} {:>18} {:>8} {:>14} {:>16}  check μs = 1.5 μd (last run)",
        "scene", "μs=μd median ms", "μs=1.5μd median ms", "ratio", "μs=μd min ms", "μs=1.5μd min ms"
    );
    for SceneResult { name, results, .. } in all {
        let at = |k: EngineKind| results.iter().find(|r| r.kind == k && r.threads_asked == args.threads);
        let (a, b) = (at(EngineKind::Tribo), at(EngineKind::TriboMus15));
        if let (Some(a), Some(b)) = (a, b) {
            println!(
                "{:<14} {:>16.3} {:>18.3} {:>8.3} {:>14.3} {:>16.3}  {} {}",
                name,
                a.median(),
                b.median(),
                b.median() / a.median(),
                a.min(),
                b.min(),
                if b.all_passed { "PASS" } else { "FAIL" },
                b.check.as_ref().map_or(String::new(), |c| c.text.clone())
            );
        }
    }
    println!("(ratio = μs=1.5μd / μs=μd, medians)");
}

/// Thread scaling measured within the run: each engine's one-thread time over its
/// `--threads` time (median over median, min over min).
fn print_thread_table(all: &[SceneResult], args: &Args) {
    println!(
        "== thread scaling in this run: speed-up = ms/step on 1 thread / ms/step on {} (same interleaved runs)",
        args.threads
    );
    println!(
        "{:<14} {:<8} {:>14} {:>14} {:>12} {:>12} {:>12}",
        "scene",
        "engine",
        "1t median ms",
        format!("{}t median ms", args.threads),
        "speed-up med",
        "speed-up min",
        "threads used"
    );
    for SceneResult { name, results, .. } in all {
        for k in [EngineKind::Tribo, EngineKind::Box2d] {
            let at = |t: usize| results.iter().find(|r| r.kind == k && r.threads_asked == t);
            if let (Some(one), Some(many)) = (at(1), at(args.threads)) {
                println!(
                    "{:<14} {:<8} {:>14.3} {:>14.3} {:>12.2} {:>12.2} {:>12}",
                    name,
                    k.name(),
                    one.median(),
                    many.median(),
                    one.median() / many.median(),
                    one.min() / many.min(),
                    many.threads
                );
            }
        }
    }
    println!();
}

/// The scaling summary: per body count n and engine, ms/step, µs/step per dynamic body and
/// Tribo/peer ratios.
fn print_scaling_table(all: &[SceneResult], selected: &[BenchScene], args: &Args) {
    let steps = all.first().map_or(0, |s| s.steps);
    println!(
        "== scaling: n bodies (2/3 boxes half 0.25 m, 1/3 disks r 0.25 m) rain into a container 1 m wide per 20 bodies"
    );
    println!(
        "   (width ∝ n, so the pile is equally deep for every n), sleep off, {steps} steps ({} timed), threads {}",
        steps.saturating_sub(1),
        args.threads
    );
    println!(
        "{:>7} {:<8} {:>4} {:>14} {:>11} {:>14} {:>11} {:>14} {:>11}  check",
        "bodies",
        "engine",
        "runs",
        "median ms/step",
        "min ms/step",
        "med µs/body",
        "min µs/body",
        "Tribo/peer med",
        "Tribo/peer min"
    );
    for (
        SceneResult {
            dynamic: n, results, ..
        },
        bench,
    ) in all.iter().zip(selected)
    {
        let tribo = results.iter().find(|r| r.kind == EngineKind::Tribo);
        for r in results {
            let (rm, rn) = match tribo {
                Some(t) => (
                    format!("{:.2}", t.median() / r.median()),
                    format!("{:.2}", t.min() / r.min()),
                ),
                None => ("-".into(), "-".into()),
            };
            println!(
                "{:>7} {:<8} {:>4} {:>14.3} {:>11.3} {:>14.3} {:>11.3} {:>14} {:>11}  {}{}",
                n,
                r.kind.name(),
                r.ms.len(),
                r.median(),
                r.min(),
                1000.0 * r.median() / *n as f64,
                1000.0 * r.min() / *n as f64,
                rm,
                rn,
                if r.all_passed { "PASS" } else { "FAIL" },
                match &bench.check {
                    CheckKind::Rain { .. } => r
                        .check
                        .as_ref()
                        .and_then(|c| c.json["bodies_outside"].as_u64())
                        .map_or(String::new(), |k| format!(" ({k} outside)")),
                    _ => String::new(),
                }
            );
        }
    }
    println!("(µs/body = µs per step per dynamic body; Tribo/peer = Tribo's ms/step / the peer's)");
}
