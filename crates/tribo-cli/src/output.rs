//! What `tribo run` writes: trajectories (CSV, JSON lines), contact points (CSV) and
//! pictures (PNG, SVG, GIF), plus the progress bar. Files are written to a temporary name
//! and renamed when complete, so a failed run leaves no partial output.

use crate::frame::{DrawContact, DrawKind, DrawShape, Frame};
use crate::render;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tribo::{BodyType, FrictionState, Shape};
use tribo_scenes::format::{BuiltScene, MaterialRef, SceneFile};
use tribo_scenes::scenes::{HookAction, StepHook};

/// Writes `bytes` to `path` through a temporary file in the same folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = tmp_path(path);
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

fn tmp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".tmp");
    path.with_file_name(name)
}

/// Trajectory file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrajectoryFormat {
    /// Comma-separated values with a header row.
    Csv,
    /// One JSON object per line.
    JsonLines,
}

impl TrajectoryFormat {
    /// The format named by a file's extension.
    pub fn from_path(p: &Path) -> Result<TrajectoryFormat, String> {
        match p.extension().and_then(|e| e.to_str()) {
            Some("csv") => Ok(TrajectoryFormat::Csv),
            Some("jsonl") => Ok(TrajectoryFormat::JsonLines),
            _ => Err(format!("--out {}: must end in .csv or .jsonl", p.display())),
        }
    }
}

/// Picture formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PictureFormat {
    /// Last frame as PNG.
    Png,
    /// Last frame as SVG.
    Svg,
    /// The whole run as an animated GIF.
    Gif,
}

impl PictureFormat {
    /// The format named by a file's extension.
    pub fn from_path(p: &Path) -> Result<PictureFormat, String> {
        match p.extension().and_then(|e| e.to_str()) {
            Some("png") => Ok(PictureFormat::Png),
            Some("svg") => Ok(PictureFormat::Svg),
            Some("gif") => Ok(PictureFormat::Gif),
            _ => Err(format!("--render {}: must end in .png, .svg or .gif", p.display())),
        }
    }
}

/// A running scene: the world, body names and material colours, and the bodies its step
/// hook created.
pub struct Simulation {
    /// The built world.
    pub built: BuiltScene,
    names: Vec<String>,
    /// Fill colour of each (body, shape) by the shape's material.
    colors: Vec<Vec<[u8; 3]>>,
    /// Palette index of each material seen (in order of first use).
    keys: HashMap<String, usize>,
    /// The scene's step hook, if any.
    hook: Option<StepHook>,
    /// Bodies the hook created, by tag: id and shape colours.
    spawned: BTreeMap<usize, Vec<(tribo::BodyId, Vec<[u8; 3]>)>>,
    /// Name of each body the hook created ("TAG.K": the K-th body of batch TAG).
    spawned_names: HashMap<tribo::BodyId, String>,
    time: f64,
    steps_done: u32,
}

/// Colours for materials in order of first use.
const PALETTE: [[u8; 3]; 8] = [
    [222, 164, 94],  // wood
    [109, 168, 205], // blue
    [143, 188, 111], // green
    [214, 120, 134], // rose
    [176, 144, 204], // violet
    [232, 201, 97],  // yellow
    [120, 190, 180], // teal
    [196, 160, 140], // tan
];

/// Fill colours of a scene's engine shapes (a chain's pieces each) by material, palette
/// indices shared through `keys`.
fn shape_colors(scene: &SceneFile, keys: &mut HashMap<String, usize>) -> Vec<Vec<[u8; 3]>> {
    scene
        .bodies
        .iter()
        .map(|b| {
            b.shapes
                .iter()
                .flat_map(|s| {
                    let key = match &s.material {
                        None => "default".to_string(),
                        Some(MaterialRef::Named(n)) => n.clone(),
                        Some(MaterialRef::Inline(m)) => format!("{m:?}"),
                    };
                    let n = keys.len();
                    let idx = *keys.entry(key).or_insert(n);
                    let pieces = match (s.kind.as_str(), &s.points) {
                        ("chain", Some(p)) => tribo::ChainSegment::piece_count(p.len(), s.closed == Some(true)),
                        _ => 1,
                    };
                    std::iter::repeat_n(PALETTE[idx % PALETTE.len()], pieces)
                })
                .collect()
        })
        .collect()
}

impl Simulation {
    /// Wraps a built scene (and its step hook, run before every step).
    pub fn new(scene: &SceneFile, built: BuiltScene, hook: Option<StepHook>) -> Simulation {
        let mut keys = HashMap::new();
        let colors = shape_colors(scene, &mut keys);
        let names = (0..scene.bodies.len()).map(|i| scene.body_name(i)).collect();
        Simulation {
            built,
            names,
            colors,
            keys,
            hook,
            spawned: BTreeMap::new(),
            spawned_names: HashMap::new(),
            time: 0.0,
            steps_done: 0,
        }
    }

    /// Runs the hook (if any), then advances one step.
    pub fn step(&mut self) -> Result<(), String> {
        if let Some(hook) = self.hook {
            let (world, bodies) = (&self.built.world, &self.built.bodies);
            let mut position = |i: usize| {
                bodies
                    .get(i)
                    .and_then(|&id| world.body_position(id).ok())
                    .map_or([f32::NAN; 2], |p| [p.x, p.y])
            };
            for action in hook(self.steps_done, self.built.dt, &mut position) {
                self.apply(action).map_err(|e| format!("the scene's step hook: {e}"))?;
            }
        }
        self.built.world.step(self.built.dt).map_err(|e| e.to_string())?;
        self.time += f64::from(self.built.dt);
        self.steps_done += 1;
        Ok(())
    }

    /// Does one thing the hook asked.
    fn apply(&mut self, action: HookAction) -> Result<(), String> {
        let world = &mut self.built.world;
        match action {
            HookAction::SetVelocity {
                body,
                velocity,
                angular_velocity,
            } => {
                if let Some(&id) = self.built.bodies.get(body) {
                    world
                        .set_body_linear_velocity(id, tribo::Vec2::new(velocity[0], velocity[1]))
                        .map_err(|e| e.to_string())?;
                    world
                        .set_body_angular_velocity(id, angular_velocity)
                        .map_err(|e| e.to_string())?;
                }
            }
            HookAction::Despawn { tag } => {
                for (id, _) in self.spawned.remove(&tag).unwrap_or_default() {
                    self.spawned_names.remove(&id);
                    world.destroy_body(id).map_err(|e| e.to_string())?;
                }
            }
            HookAction::Spawn { tag, batch } => {
                let ids = batch.add_to(world).map_err(|e| e.to_string())?;
                let colors = shape_colors(batch, &mut self.keys);
                let list = self.spawned.entry(tag).or_default();
                for (id, row) in ids.into_iter().zip(colors) {
                    self.spawned_names.insert(id, format!("{tag}.{}", list.len()));
                    list.push((id, row));
                }
            }
        }
        Ok(())
    }

    /// Simulation time [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The picture of the current state.
    pub fn frame(&self) -> Frame {
        let world = &self.built.world;
        let mut frame = Frame {
            time: self.time as f32,
            ..Frame::default()
        };
        // Static bodies first so moving ones are drawn over the ground.
        let scene_bodies = self
            .built
            .bodies
            .iter()
            .zip(self.colors.iter().map(Some).chain(std::iter::repeat(None)));
        let spawned = self.spawned.values().flatten().map(|(id, row)| (id, Some(row)));
        let bodies: Vec<(&tribo::BodyId, Option<&Vec<[u8; 3]>>)> = scene_bodies.chain(spawned).collect();
        for pass_static in [true, false] {
            for &(&id, colors) in &bodies {
                let (Ok(xf), Ok(kind), Ok(shapes)) =
                    (world.body_transform(id), world.body_type(id), world.body_shapes(id))
                else {
                    continue;
                };
                let is_static = kind == BodyType::Static;
                if is_static != pass_static {
                    continue;
                }
                let asleep = !world.body_is_awake(id).unwrap_or(true);
                for (j, sid) in shapes.iter().enumerate() {
                    let Ok(geometry) = world.shape_geometry(*sid) else {
                        continue;
                    };
                    let p = |v: tribo::Vec2| {
                        let w = xf.apply(v);
                        [w.x, w.y]
                    };
                    let kind = match geometry {
                        Shape::Circle(c) => DrawKind::Circle {
                            center: p(c.center),
                            radius: c.radius,
                            angle: xf.q.angle(),
                        },
                        Shape::Polygon(poly) => DrawKind::Polygon {
                            points: poly.vertices().iter().map(|&v| p(v)).collect(),
                            radius: poly.radius(),
                        },
                        Shape::Capsule(c) => DrawKind::Capsule {
                            p1: p(c.center1),
                            p2: p(c.center2),
                            radius: c.radius,
                        },
                        Shape::Segment(s) => DrawKind::Segment {
                            p1: p(s.point1),
                            p2: p(s.point2),
                            back: None,
                        },
                        Shape::ChainSegment(c) => {
                            let back = xf.q.rotate(-c.normal());
                            DrawKind::Segment {
                                p1: p(c.segment.point1),
                                p2: p(c.segment.point2),
                                back: Some([back.x, back.y]),
                            }
                        }
                    };
                    let fill = colors.and_then(|row| row.get(j)).copied().unwrap_or(PALETTE[0]);
                    frame.shapes.push(DrawShape {
                        kind,
                        fill,
                        is_static,
                        asleep,
                    });
                }
            }
        }
        for c in world.contacts() {
            for pt in c.points() {
                frame.contacts.push(DrawContact {
                    point: [pt.point.x, pt.point.y],
                    normal: [c.normal.x, c.normal.y],
                    stick: pt.state == FrictionState::Stick,
                });
            }
        }
        for j in world.joint_ids() {
            if let Ok((_, b)) = world.joint_world_anchors(j) {
                frame.joints.push([b.x, b.y]);
            }
        }
        frame
    }

    fn name_of(&self, id: tribo::BodyId) -> String {
        if let Some(name) = self.spawned_names.get(&id) {
            return name.clone();
        }
        self.built
            .world
            .body_user_data(id)
            .ok()
            .and_then(|i| self.names.get(i as usize).cloned())
            .unwrap_or_else(|| format!("{}", id.index))
    }
}

/// The trajectory and contact writers of a run.
pub struct Writers {
    trajectory: Option<(TrajectoryFormat, PathBuf, BufWriter<File>)>,
    contacts: Option<(PathBuf, BufWriter<File>)>,
    error: Option<std::io::Error>,
}

impl Writers {
    /// Opens the outputs (as temporary files).
    pub fn new(format: Option<TrajectoryFormat>, out: Option<&Path>, contacts: Option<&Path>) -> Writers {
        let mut w = Writers {
            trajectory: None,
            contacts: None,
            error: None,
        };
        if let (Some(format), Some(path)) = (format, out) {
            match File::create(tmp_path(path)) {
                Ok(f) => {
                    let mut bw = BufWriter::new(f);
                    if format == TrajectoryFormat::Csv {
                        if let Err(e) = writeln!(bw, "step,time,body,x,y,angle,vx,vy,omega") {
                            w.error = Some(e);
                        }
                    }
                    w.trajectory = Some((format, path.to_path_buf(), bw));
                }
                Err(e) => w.error = Some(e),
            }
        }
        if let Some(path) = contacts {
            match File::create(tmp_path(path)) {
                Ok(f) => {
                    let mut bw = BufWriter::new(f);
                    if let Err(e) = writeln!(
                        bw,
                        "step,time,body_a,body_b,x,y,normal_x,normal_y,normal_impulse,friction_impulse,state,slip_speed"
                    ) {
                        w.error = Some(e);
                    }
                    w.contacts = Some((path.to_path_buf(), bw));
                }
                Err(e) => w.error = Some(e),
            }
        }
        w
    }

    /// Writes the state after `step`.
    pub fn record(&mut self, sim: &Simulation, step: u32) -> std::io::Result<()> {
        if let Some(e) = self.error.take() {
            self.discard();
            return Err(e);
        }
        let r = self.record_inner(sim, step);
        if r.is_err() {
            self.discard();
        }
        r
    }

    fn record_inner(&mut self, sim: &Simulation, step: u32) -> std::io::Result<()> {
        let world = &sim.built.world;
        let t = sim.time();
        if let Some((format, _, w)) = &mut self.trajectory {
            for (i, &id) in sim.built.bodies.iter().enumerate() {
                let (Ok(p), Ok(a), Ok(v), Ok(om)) = (
                    world.body_position(id),
                    world.body_angle(id),
                    world.body_linear_velocity(id),
                    world.body_angular_velocity(id),
                ) else {
                    continue;
                };
                let name = &sim.names[i];
                match format {
                    TrajectoryFormat::Csv => writeln!(
                        w,
                        "{step},{t:.6},{},{},{},{},{},{},{}",
                        csv_field(name),
                        p.x,
                        p.y,
                        a,
                        v.x,
                        v.y,
                        om
                    )?,
                    TrajectoryFormat::JsonLines => {
                        let rec = serde_json::json!({
                            "step": step, "time": t, "body": name, "x": p.x, "y": p.y, "angle": a,
                            "vx": v.x, "vy": v.y, "omega": om
                        });
                        writeln!(w, "{rec}")?
                    }
                }
            }
        }
        if let Some((_, w)) = &mut self.contacts {
            for c in world.contacts() {
                let (a, b) = (sim.name_of(c.body_a), sim.name_of(c.body_b));
                for p in c.points() {
                    let state = match p.state {
                        FrictionState::Stick => "stick",
                        FrictionState::Slip => "slip",
                    };
                    writeln!(
                        w,
                        "{step},{t:.6},{},{},{},{},{},{},{},{},{state},{}",
                        csv_field(&a),
                        csv_field(&b),
                        p.point.x,
                        p.point.y,
                        c.normal.x,
                        c.normal.y,
                        p.normal_impulse,
                        p.friction_impulse,
                        p.slip_speed
                    )?;
                }
            }
        }
        Ok(())
    }

    /// Flushes and renames the outputs into place.
    pub fn finish(mut self) -> std::io::Result<()> {
        if let Some(e) = self.error.take() {
            self.discard();
            return Err(e);
        }
        if let Some((_, path, mut w)) = self.trajectory.take() {
            w.flush()?;
            std::fs::rename(tmp_path(&path), &path)?;
        }
        if let Some((path, mut w)) = self.contacts.take() {
            w.flush()?;
            std::fs::rename(tmp_path(&path), &path)?;
        }
        Ok(())
    }

    fn discard(&mut self) {
        if let Some((_, path, _)) = self.trajectory.take() {
            let _ = std::fs::remove_file(tmp_path(&path));
        }
        if let Some((path, _)) = self.contacts.take() {
            let _ = std::fs::remove_file(tmp_path(&path));
        }
    }
}

impl Drop for Writers {
    fn drop(&mut self) {
        // Outputs not finished (an error ended the run) leave no files behind.
        self.discard();
    }
}

/// Quotes a CSV field if it needs it.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Collects frames for the picture: the last one for PNG/SVG, a sampled sequence for GIF.
pub struct FrameRecorder {
    kind: Option<PictureFormat>,
    every: u32,
    frames: Vec<Frame>,
    delay_cs: u16,
}

/// Most frames in a GIF (keeps files small).
const MAX_GIF_FRAMES: u32 = 150;
/// Highest GIF frame rate [1/s].
const MAX_GIF_FPS: f32 = 25.0;

impl FrameRecorder {
    /// Plans the sampling for `steps` steps of `dt`.
    pub fn new(kind: Option<PictureFormat>, steps: u32, dt: f32) -> FrameRecorder {
        let mut every = ((1.0 / (dt * MAX_GIF_FPS)).ceil() as u32).max(1);
        while steps / every > MAX_GIF_FRAMES {
            every += 1;
        }
        let delay_cs = ((100.0 * dt * every as f32).round() as u16).max(2);
        FrameRecorder {
            kind,
            every,
            frames: Vec::new(),
            delay_cs,
        }
    }

    /// Keeps the frame of `step` if the picture needs it (every sampled step and the
    /// last one; PNG and SVG draw only the last, but the camera fits the whole run).
    pub fn record(&mut self, sim: &Simulation, step: u32, last: bool) {
        if self.kind.is_some() && (step.is_multiple_of(self.every) || last) {
            self.frames.push(sim.frame());
        }
    }

    /// Draws the picture.
    pub fn write(&self, kind: PictureFormat, path: &Path) -> Result<(), render::RenderError> {
        let Some(last) = self.frames.last() else {
            return Ok(());
        };
        let tmp = tmp_path(path);
        let result = match kind {
            PictureFormat::Png => {
                let camera = render::Camera::fit(&self.frames, 960, 600);
                render::write_png(last, &camera, &tmp)
            }
            PictureFormat::Svg => {
                let camera = render::Camera::fit(&self.frames, 960, 600);
                render::write_svg(last, &camera, &tmp)
            }
            PictureFormat::Gif => {
                let camera = render::Camera::fit(&self.frames, 640, 400);
                render::write_gif(&self.frames, &camera, self.delay_cs, &tmp)
            }
        };
        match result {
            Ok(()) => std::fs::rename(&tmp, path).map_err(|source| render::RenderError::Io {
                context: format!("renaming {} into place", tmp.display()),
                source,
            }),
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                Err(e)
            }
        }
    }
}

/// Progress bar on stderr for runs longer than about a second; hidden when stderr is not
/// a terminal (indicatif's stderr target checks).
pub struct Progress {
    bar: ProgressBar,
    shown: std::cell::Cell<bool>,
}

impl Progress {
    /// A bar for `steps` steps, hidden until a second has passed.
    pub fn new(steps: u64) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {per_sec}, eta {eta}") {
            bar.set_style(style);
        }
        Progress {
            bar,
            shown: std::cell::Cell::new(false),
        }
    }

    /// Records progress after `step`.
    pub fn tick(&self, step: u32, start: Instant) {
        if !self.shown.get() && start.elapsed().as_secs_f32() > 1.0 {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown.set(true);
        }
        self.bar.set_position(u64::from(step));
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Pictures for the validation report: the last frames of a few built-in scenes.
pub fn report_pictures() -> Vec<crate::report::Picture> {
    let mut out = Vec::new();
    for name in ["incline", "rolling", "bounce", "card_house"] {
        let Some(entry) = tribo_scenes::scenes::find(name) else {
            continue;
        };
        let scene = (entry.build)();
        let Ok(built) = scene.build() else { continue };
        let mut sim = Simulation::new(&scene, built, None);
        let mut frames = vec![sim.frame()];
        let steps = scene.steps.min(180);
        for _ in 0..steps {
            if sim.step().is_err() {
                break;
            }
        }
        frames.push(sim.frame());
        let camera = render::Camera::fit(&frames, 720, 450);
        if let Some(Ok(png)) = frames.last().map(|last| render::png_bytes(last, &camera)) {
            out.push(crate::report::Picture {
                caption: format!("{name} at t = {:.1} s: {}", sim.time(), entry.about),
                png,
            });
        }
    }
    out
}
