//! `tribo`: run a scene, write its trajectory, contacts and pictures; list and export the
//! built-in scenes; run the validation experiments.

mod frame;
mod output;
mod render;
mod report;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use tribo_scenes::format::{self, SceneFile};
use tribo_scenes::scenes;

/// The crate version and the wide solver this CPU runs (`tribo::build_info`).
static VERSION: std::sync::LazyLock<String> = std::sync::LazyLock::new(tribo::build_info);

#[derive(Parser)]
#[command(
    name = "tribo",
    version = VERSION.as_str(),
    about = "Tribo: 2D rigid bodies with static and dynamic friction"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// `--solver-lanes` (`tribo::SolverLanes`).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Lanes {
    /// Eight lanes if the CPU has AVX2 (compiled for AVX-512VL if it has that too), else four.
    Auto,
    /// Eight lanes compiled for AVX2 only, even on a CPU with AVX-512 (four without AVX2).
    #[value(name = "8")]
    Eight,
    /// Four lanes (SSE2 on x86-64).
    #[value(name = "4")]
    Four,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (a JSON file or a built-in scene's name).
    Run(RunArgs),
    /// List the built-in scenes.
    Scenes,
    /// Write a built-in scene as a scene file.
    Export {
        /// Built-in scene name (see `tribo scenes`).
        name: String,
        /// Output JSON file.
        file: PathBuf,
    },
    /// Run the analytic friction and contact experiments and print the table.
    Validate {
        /// Also write a self-contained HTML report with plots and pictures into this folder.
        #[arg(long)]
        report: Option<PathBuf>,
    },
}

/// Options of `tribo run`.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scene file (.json) or built-in scene name.
    pub scene: String,
    /// Number of steps (overrides the scene).
    #[arg(long)]
    pub steps: Option<u32>,
    /// Step length [s] (overrides the scene).
    #[arg(long)]
    pub dt: Option<f32>,
    /// Substeps per step (overrides the scene).
    #[arg(long)]
    pub substeps: Option<u32>,
    /// Worker threads for each step (1..=256; results are identical for every count).
    #[arg(long, default_value_t = 1)]
    pub threads: u32,
    /// Contact constraints the solver handles at once: `auto` (8 with AVX2, compiled for
    /// AVX-512VL where the CPU has it, else 4), `8` (AVX2 only) or `4` (results are
    /// identical every way; `tribo --version` shows what `auto` takes).
    #[arg(long, value_enum, default_value_t = Lanes::Auto)]
    pub solver_lanes: Lanes,
    /// Trajectory output: .csv or .jsonl.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write every K-th step to the outputs (step 0 is always written).
    #[arg(long, default_value_t = 1)]
    pub every: u32,
    /// Contact points output (.csv).
    #[arg(long)]
    pub contacts: Option<PathBuf>,
    /// Picture: .png or .svg (last frame) or .gif (the whole run).
    #[arg(long)]
    pub render: Option<PathBuf>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run(&args),
        Command::Scenes => {
            for s in scenes::SCENES {
                println!("{:<15} {}", s.name, s.about);
            }
            Ok(())
        }
        Command::Export { name, file } => export(&name, &file),
        Command::Validate { report } => validate(report.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("tribo: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Loads a scene file or a built-in scene (with its step hook, if it has one).
fn load_scene(name: &str) -> Result<(SceneFile, Option<scenes::StepHook>), String> {
    let path = Path::new(name);
    if path.extension().is_some_and(|e| e == "json") || path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{name}: cannot read: {e}"))?;
        return format::parse(&text)
            .map(|s| (s, None))
            .map_err(|e| format!("{name}: {e}"));
    }
    match scenes::find(name) {
        Some(entry) => Ok(((entry.build)(), entry.hook)),
        None => {
            let names: Vec<&str> = scenes::SCENES.iter().map(|s| s.name).collect();
            Err(format!(
                "{name}: no such file and no built-in scene of that name (built-in: {})",
                names.join(", ")
            ))
        }
    }
}

fn export(name: &str, file: &Path) -> Result<(), String> {
    let entry = scenes::find(name).ok_or_else(|| {
        let names: Vec<&str> = scenes::SCENES.iter().map(|s| s.name).collect();
        format!(
            "{name}: no built-in scene of that name (built-in: {})",
            names.join(", ")
        )
    })?;
    let text = (entry.build)().to_json();
    output::write_atomic(file, text.as_bytes()).map_err(|e| format!("{}: {e}", file.display()))?;
    eprintln!("wrote {} ({} bytes)", file.display(), text.len());
    if entry.hook.is_some() {
        eprintln!(
            "note: {name} also has a step hook (bodies it moves, creates or destroys before each step), which a \
             scene file cannot hold: `tribo run {name}` runs it, `tribo run {}` does not",
            file.display()
        );
    }
    Ok(())
}

fn run(args: &RunArgs) -> Result<(), String> {
    let (mut scene, hook) = load_scene(&args.scene)?;
    if let Some(steps) = args.steps {
        scene.steps = steps;
    }
    if let Some(dt) = args.dt {
        scene.dt = dt;
    }
    if let Some(substeps) = args.substeps {
        scene.substeps = substeps;
    }
    if args.every == 0 {
        return Err("--every: must be at least 1".into());
    }
    // Validate outputs before any work: a bad extension must not leave files behind.
    let traj_kind = args
        .out
        .as_deref()
        .map(output::TrajectoryFormat::from_path)
        .transpose()?;
    let picture_kind = args
        .render
        .as_deref()
        .map(output::PictureFormat::from_path)
        .transpose()?;
    if let Some(c) = &args.contacts {
        if c.extension().is_none_or(|e| e != "csv") {
            return Err(format!("--contacts {}: must end in .csv", c.display()));
        }
    }
    scene.validate().map_err(|(path, message)| {
        let flag = match path.as_str() {
            "dt" => "--dt",
            "substeps" => "--substeps",
            _ => path.as_str(),
        };
        format!("{flag}: {message}")
    })?;
    let mut built = scene.build().map_err(|e| e.to_string())?;
    let def = tribo::WorldDef {
        workers: args.threads,
        solver_lanes: match args.solver_lanes {
            Lanes::Auto => tribo::SolverLanes::Auto,
            Lanes::Eight => tribo::SolverLanes::Eight,
            Lanes::Four => tribo::SolverLanes::Four,
        },
        ..*built.world.def()
    };
    built.world.set_def(def).map_err(|e| format!("--threads: {e}"))?;
    let mut sim = output::Simulation::new(&scene, built, hook);
    let mut writers = output::Writers::new(traj_kind, args.out.as_deref(), args.contacts.as_deref());
    let mut frames = output::FrameRecorder::new(picture_kind, scene.steps, scene.dt);
    writers.record(&sim, 0).map_err(|e| e.to_string())?;
    frames.record(&sim, 0, scene.steps == 0);
    let progress = output::Progress::new(u64::from(scene.steps));
    let start = Instant::now();
    for step in 1..=scene.steps {
        sim.step().map_err(|e| format!("step {step}: {e}"))?;
        if step % args.every == 0 || step == scene.steps {
            writers.record(&sim, step).map_err(|e| e.to_string())?;
        }
        frames.record(&sim, step, step == scene.steps);
        progress.tick(step, start);
    }
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    writers.finish().map_err(|e| e.to_string())?;
    if let (Some(kind), Some(path)) = (picture_kind, args.render.as_deref()) {
        frames
            .write(kind, path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let per_step = if scene.steps > 0 {
        1000.0 * elapsed / f64::from(scene.steps)
    } else {
        0.0
    };
    eprintln!(
        "{}: {} steps of {:.4} s, {} bodies, {} contacts at the end, {:.3} ms/step ({:.2} s; solver: {} lanes, {})",
        args.scene,
        scene.steps,
        scene.dt,
        sim.built.world.body_count(),
        sim.built.world.contacts().count(),
        per_step,
        elapsed,
        sim.built.world.solver_lanes(),
        sim.built.world.solver_instructions()
    );
    Ok(())
}

fn validate(report_dir: Option<&Path>) -> Result<(), String> {
    let start = Instant::now();
    let checks = tribo_scenes::validation::all().map_err(|e| e.to_string())?;
    println!("{}", report::format_table(&checks));
    let failed = checks.iter().filter(|c| !c.passed()).count();
    if let Some(dir) = report_dir {
        let pictures = output::report_pictures();
        let info = format!(
            "tribo {} — {} checks in {:.1} s",
            env!("CARGO_PKG_VERSION"),
            checks.len(),
            start.elapsed().as_secs_f64()
        );
        let path =
            report::write_report(dir, &checks, &pictures, &info).map_err(|e| format!("{}: {e}", dir.display()))?;
        eprintln!("report: {}", path.display());
    }
    if failed > 0 {
        Err(format!("{failed} of {} checks failed", checks.len()))
    } else {
        Ok(())
    }
}
