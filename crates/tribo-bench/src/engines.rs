//! One builder per engine: each makes that engine's world from a [`SceneFile`].
//!
//! Mapping (SCENES.md §1 and §5.13): 60 Hz (the scene's dt), the scene's substep count,
//! gravity, sleep on/off per `enable_sleep`, each body's type, pose, velocities, damping,
//! gravity scale, fixed rotation and awake flag, and each shape's geometry, density,
//! restitution and friction. Box2D and Rapier have one friction coefficient: they get
//! μ = μs of the shape's material, mixed by √(μA μB) (Box2D's default, Rapier's
//! `GeometricMean`); restitution mixes by max in all three. Contact softness and the other
//! solver settings are each engine's defaults, which match Box2D's (see RESULTS.md for
//! what differs in Rapier).

use std::error::Error;
use tribo_scenes::format::{BodyKind, JointSpec, SceneFile, ShapeSpec};

/// Errors from any engine.
pub type BoxError = Box<dyn Error>;

/// The engines, in table order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EngineKind {
    /// Tribo, μs and μd as the scene says.
    Tribo,
    /// Tribo with every shape's μs scaled by 1.5 (μd unchanged): the cost of the
    /// static/dynamic friction model.
    TriboMus15,
    /// Box2D v3 through boxdd.
    Box2d,
    /// Rapier 2D.
    Rapier,
}

impl EngineKind {
    /// Name in the tables and the JSON.
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::Tribo => "tribo",
            EngineKind::TriboMus15 => "tribo_mus1.5",
            EngineKind::Box2d => "box2d",
            EngineKind::Rapier => "rapier",
        }
    }

    /// How the engine's contact solver was built for this run (the JSON's `simd`).
    pub fn simd(self) -> &'static str {
        match self {
            EngineKind::Tribo | EngineKind::TriboMus15 => match (tribo_lanes(), tribo::solver_instructions()) {
                (tribo::SolverLanes::Auto, "AVX-512VL") => "avx512vl-8",
                (tribo::SolverLanes::Auto | tribo::SolverLanes::Eight, "AVX2" | "AVX-512VL") => "avx2-8",
                _ => "sse2-4",
            },
            EngineKind::Box2d if cfg!(feature = "box2d-avx2") => "avx2-8",
            EngineKind::Box2d => "sse2-4",
            // rapier2d's default features (no `simd8`); compiled for AVX2 when the whole
            // build is (`AVX2=1 run.sh`).
            EngineKind::Rapier if cfg!(target_feature = "avx2") => "default-avx2",
            EngineKind::Rapier => "default",
        }
    }
}

/// The wide solver Tribo's worlds run: [`tribo::SolverLanes::Auto`] (eight lanes on a CPU
/// with AVX2, compiled for AVX-512VL where it has that too), eight compiled for AVX2 only
/// with `TRIBO_BENCH_LANES=8`, or four with `TRIBO_BENCH_LANES=4` (to time those builds on
/// such a CPU).
pub fn tribo_lanes() -> tribo::SolverLanes {
    match std::env::var("TRIBO_BENCH_LANES").as_deref() {
        Ok("4") => tribo::SolverLanes::Four,
        Ok("8") => tribo::SolverLanes::Eight,
        Ok("") | Ok("auto") | Err(_) => tribo::SolverLanes::Auto,
        Ok(other) => {
            eprintln!("TRIBO_BENCH_LANES={other:?}: not 4, 8 or auto; taking auto");
            tribo::SolverLanes::Auto
        }
    }
}

/// A built world that the harness can step and read.
/// Per-stage profile sums over the sampled steps.
#[derive(Default)]
struct ProfileSum {
    sums: Vec<(&'static str, f64)>,
    steps: usize,
}

impl ProfileSum {
    fn add(&mut self, fields: &[(&'static str, f32)]) {
        if self.sums.is_empty() {
            self.sums = fields.iter().map(|&(n, _)| (n, 0.0)).collect();
        }
        for (sum, &(_, x)) in self.sums.iter_mut().zip(fields) {
            sum.1 += x as f64;
        }
        self.steps += 1;
    }

    fn report(&self, source: &str) -> String {
        if self.steps == 0 {
            return "no steps sampled".into();
        }
        let n = self.steps as f64;
        self.sums
            .iter()
            .map(|(name, sum)| format!("{name} {:.3}", sum / n))
            .collect::<Vec<_>>()
            .join(", ")
            + &format!(" (ms/step, {source})")
    }
}

pub trait Sim {
    /// One step of the scene's dt with the scene's substeps.
    fn step(&mut self) -> Result<(), BoxError>;
    /// Origin of scene body `i`.
    fn position(&mut self, i: usize) -> [f32; 2];
    /// Rotation angle [rad] of scene body `i` (in (−π, π]).
    fn angle(&mut self, i: usize) -> f32;
    /// Centre-of-mass velocity of scene body `i`.
    fn velocity(&mut self, i: usize) -> [f32; 2];
    /// Angular velocity [rad/s] of scene body `i`.
    fn angular_velocity(&mut self, i: usize) -> f32;
    /// Mass of scene body `i` (0 for static bodies).
    fn mass(&mut self, i: usize) -> f32;
    /// The engine's own contact (pair) count; definitions differ between engines.
    fn contact_count(&mut self) -> usize;
    /// Threads the engine actually uses.
    fn threads(&self) -> usize;
    /// Dynamic bodies currently awake.
    fn awake_count(&mut self) -> usize;
    /// Sets a kinematic body's velocity [m/s] and angular velocity [rad/s] (scene hooks).
    fn set_kinematic_velocity(&mut self, i: usize, v: [f32; 2], w: f32) -> Result<(), BoxError>;
    /// Adds the bodies and joints of `batch` (joints refer to the batch's own bodies; its
    /// world settings are not used) under `tag` (scene hooks that create bodies).
    fn spawn(&mut self, tag: usize, batch: &SceneFile) -> Result<(), BoxError>;
    /// Destroys the bodies spawned under `tag`, with their shapes and joints.
    fn despawn(&mut self, tag: usize) -> Result<(), BoxError>;
    /// Origins of the bodies spawned under `tag`, in batch order (empty if none).
    fn spawned_positions(&mut self, tag: usize) -> Vec<[f32; 2]>;
    /// Called after each timed step when `--profile` is on.
    fn profile_sample(&mut self) {}
    /// Per-stage profile of the sampled steps, if the engine has one.
    fn profile_report(&self) -> String;
}

/// Builds `kind`'s world for `scene` with `threads` worker threads where the engine allows.
pub fn build(kind: EngineKind, scene: &SceneFile, threads: usize) -> Result<Box<dyn Sim>, BoxError> {
    Ok(match kind {
        EngineKind::Tribo => Box::new(tribo_sim::TriboSim::build(scene, threads)?),
        EngineKind::TriboMus15 => {
            let scaled = crate::scenes::scale_static_friction(scene, 1.5);
            Box::new(tribo_sim::TriboSim::build(&scaled, threads)?)
        }
        EngineKind::Box2d => Box::new(box2d_sim::Box2dSim::build(scene, threads)?),
        EngineKind::Rapier => Box::new(rapier_sim::RapierSim::build(scene, threads)?),
    })
}

fn shape_field<T: Copy>(v: Option<T>, what: &str, s: &ShapeSpec) -> Result<T, BoxError> {
    v.ok_or_else(|| format!("a {} shape needs \"{what}\"", s.kind).into())
}

/// A scene joint as the peers build it: body indices, the anchor in each body's frame
/// (relative to the body origin) [m], and B's rotation relative to A [rad] at which the
/// joint angle is 0 (the scene's `reference_angle`, by default the initial one).
struct JointGeometry {
    a: usize,
    b: usize,
    local_a: [f32; 2],
    local_b: [f32; 2],
    relative_angle: f32,
}

fn joint_geometry(scene: &SceneFile, j: &JointSpec) -> Result<JointGeometry, BoxError> {
    let a = scene.resolve_body("joint.body_a", &j.body_a).map_err(|e| e.1)?;
    let b = scene.resolve_body("joint.body_b", &j.body_b).map_err(|e| e.1)?;
    let local = |i: usize| {
        let body = &scene.bodies[i];
        let (s, c) = body.angle.sin_cos();
        let d = [j.anchor[0] - body.position[0], j.anchor[1] - body.position[1]];
        [c * d[0] + s * d[1], -s * d[0] + c * d[1]]
    };
    Ok(JointGeometry {
        a,
        b,
        local_a: local(a),
        local_b: local(b),
        relative_angle: j
            .reference_angle
            .unwrap_or(scene.bodies[b].angle - scene.bodies[a].angle),
    })
}

// ---------------------------------------------------------------------------------------
mod tribo_sim {
    use super::*;
    use tribo::{BodyId, Vec2, World};

    pub struct TriboSim {
        world: World,
        bodies: Vec<BodyId>,
        /// Bodies added by hooks, by tag.
        spawned: std::collections::BTreeMap<usize, Vec<BodyId>>,
        dt: f32,
        profile: ProfileSum,
    }

    impl TriboSim {
        pub fn build(scene: &SceneFile, threads: usize) -> Result<Self, BoxError> {
            let mut built = scene.build().map_err(|e| e.to_string())?;
            // tribo-scenes' SceneFile::build sets every moving body's velocity after adding
            // its shapes with World::set_body_linear_velocity, which wakes the body, so bodies
            // the scene creates asleep come out awake. Put them back to sleep (each alone:
            // there are no contacts yet), as the scene says and as Box2D and Rapier have them.
            if std::env::var_os("TRIBO_BENCH_KEEP_BUILD_AWAKE").is_none() {
                for (b, &id) in scene.bodies.iter().zip(&built.bodies) {
                    if !b.awake && b.kind != BodyKind::Static {
                        built.world.set_body_awake(id, false)?;
                    }
                }
            }
            let def = tribo::WorldDef {
                workers: threads as u32,
                solver_lanes: tribo_lanes(),
                ..*built.world.def()
            };
            built.world.set_def(def)?;
            Ok(TriboSim {
                world: built.world,
                bodies: built.bodies,
                spawned: Default::default(),
                dt: built.dt,
                profile: ProfileSum::default(),
            })
        }
    }

    fn arr(v: Vec2) -> [f32; 2] {
        [v.x, v.y]
    }

    impl Sim for TriboSim {
        fn step(&mut self) -> Result<(), BoxError> {
            self.world.step(self.dt)?;
            Ok(())
        }
        fn position(&mut self, i: usize) -> [f32; 2] {
            self.world
                .body_position(self.bodies[i])
                .map(arr)
                .unwrap_or([f32::NAN; 2])
        }
        fn angle(&mut self, i: usize) -> f32 {
            self.world.body_angle(self.bodies[i]).unwrap_or(f32::NAN)
        }
        fn velocity(&mut self, i: usize) -> [f32; 2] {
            self.world
                .body_linear_velocity(self.bodies[i])
                .map(arr)
                .unwrap_or([f32::NAN; 2])
        }
        fn angular_velocity(&mut self, i: usize) -> f32 {
            self.world.body_angular_velocity(self.bodies[i]).unwrap_or(f32::NAN)
        }
        fn mass(&mut self, i: usize) -> f32 {
            self.world.body_mass(self.bodies[i]).unwrap_or(0.0)
        }
        fn contact_count(&mut self) -> usize {
            self.world.contact_count()
        }
        fn threads(&self) -> usize {
            self.world.def().workers as usize
        }
        fn set_kinematic_velocity(&mut self, i: usize, v: [f32; 2], w: f32) -> Result<(), BoxError> {
            let id = self.bodies[i];
            self.world.set_body_linear_velocity(id, Vec2::new(v[0], v[1]))?;
            self.world.set_body_angular_velocity(id, w)?;
            Ok(())
        }
        fn spawn(&mut self, tag: usize, batch: &SceneFile) -> Result<(), BoxError> {
            let ids = batch.add_to(&mut self.world).map_err(|e| e.to_string())?;
            self.spawned.entry(tag).or_default().extend(ids);
            Ok(())
        }
        fn despawn(&mut self, tag: usize) -> Result<(), BoxError> {
            for id in self.spawned.remove(&tag).unwrap_or_default() {
                self.world.destroy_body(id)?;
            }
            Ok(())
        }
        fn spawned_positions(&mut self, tag: usize) -> Vec<[f32; 2]> {
            let ids = self.spawned.get(&tag).map(Vec::as_slice).unwrap_or_default();
            ids.iter()
                .map(|&id| self.world.body_position(id).map(arr).unwrap_or([f32::NAN; 2]))
                .collect()
        }
        fn awake_count(&mut self) -> usize {
            self.bodies
                .iter()
                .chain(self.spawned.values().flatten())
                .filter(|&&id| {
                    self.world
                        .body_type(id)
                        .map(|t| t == tribo::BodyType::Dynamic)
                        .unwrap_or(false)
                        && self.world.body_is_awake(id).unwrap_or(false)
                })
                .count()
        }
        fn profile_sample(&mut self) {
            let p = self.world.profile();
            self.profile.add(&[
                ("step", p.step),
                ("pairs", p.pairs),
                ("collide", p.collide),
                ("solver_setup", p.solver_setup),
                ("prepare", p.prepare),
                ("integrate_velocities", p.integrate_velocities),
                ("warm_start", p.warm_start),
                ("solve", p.solve),
                ("integrate_positions", p.integrate_positions),
                ("relax", p.relax),
                ("restitution", p.restitution),
                ("store", p.store),
                ("finalize", p.finalize),
                ("sleep", p.sleep),
            ]);
        }
        fn profile_report(&self) -> String {
            self.profile.report("Tribo's World::profile")
        }
    }
}

// ---------------------------------------------------------------------------------------
mod box2d_sim {
    use super::*;
    use boxdd::{
        shapes, BodyBuilder, BodyId, BodyType, ChainDef, ConstraintTuning, Filter, Foundation, MotionLocks, Position,
        Profile, RevoluteJointDef, ShapeDef, SurfaceMaterial, Transform, Vec2, WorkerCount, World, WorldBuilder,
    };

    pub struct Box2dSim {
        foundation: &'static Foundation,
        world: World,
        bodies: Vec<BodyId>,
        /// Bodies added by hooks, by tag.
        spawned: std::collections::BTreeMap<usize, Vec<BodyId>>,
        /// Constant forces/torques (Box2D clears applied forces after each step).
        forces: Vec<(BodyId, Vec2, f32)>,
        dt: f32,
        substeps: i32,
        threads: usize,
        profile: ProfileSum,
    }

    fn v(a: [f32; 2]) -> Vec2 {
        Vec2::new(a[0], a[1])
    }

    impl Box2dSim {
        pub fn build(scene: &SceneFile, threads: usize) -> Result<Self, BoxError> {
            let foundation = Foundation::initialize_default()?;
            let def = WorldBuilder::from(foundation.world_def())
                .gravity(v(scene.gravity))
                .enable_sleep(scene.enable_sleep)
                .worker_count(WorkerCount::new(threads as u32)?)
                .build()?;
            let mut world = foundation.create_world(def)?;
            let (bodies, forces) = add_scene(foundation, &mut world, scene)?;
            Ok(Box2dSim {
                foundation,
                world,
                bodies,
                spawned: Default::default(),
                forces,
                dt: scene.dt,
                substeps: scene.substeps as i32,
                threads,
                profile: ProfileSum::default(),
            })
        }
    }

    /// Adds a scene's bodies and joints to a Box2D world: the bodies in scene order, and
    /// the constant forces to apply before every step (Box2D clears applied forces).
    #[allow(clippy::type_complexity)]
    fn add_scene(
        foundation: &Foundation,
        world: &mut World,
        scene: &SceneFile,
    ) -> Result<(Vec<BodyId>, Vec<(BodyId, Vec2, f32)>), BoxError> {
        let mut bodies = Vec::with_capacity(scene.bodies.len());
        let mut forces = Vec::new();
        for b in &scene.bodies {
            let body_type = match b.kind {
                BodyKind::Static => BodyType::Static,
                BodyKind::Kinematic => BodyType::Kinematic,
                BodyKind::Dynamic => BodyType::Dynamic,
            };
            let mut builder = BodyBuilder::from(foundation.body_def())
                .body_type(body_type)
                .position(Position::new(b.position[0], b.position[1]))
                .angle(b.angle)
                .awake(b.awake);
            if b.kind != BodyKind::Static {
                builder = builder
                    .linear_velocity(v(b.linear_velocity))
                    .angular_velocity(b.angular_velocity)
                    .linear_damping(b.linear_damping)
                    .angular_damping(b.angular_damping)
                    .gravity_scale(b.gravity_scale)
                    .motion_locks(MotionLocks::new(false, false, b.fixed_rotation))
                    .bullet(b.bullet);
            }
            let id = world.create_body(builder.build()?)?;
            {
                let mut body = world.body(id)?;
                for s in &b.shapes {
                    let m = scene.shape_material(s);
                    let material = SurfaceMaterial::new()
                        .with_friction(m.friction_static)?
                        .with_restitution(m.restitution)?
                        .with_rolling_resistance(m.rolling_resistance)?
                        .with_tangent_speed(m.tangent_speed)?;
                    let f = s.filter.map(tribo::Filter::from).unwrap_or_default();
                    let filter = Filter {
                        category_bits: f.category,
                        mask_bits: f.mask,
                        group_index: f.group,
                    };
                    let def = ShapeDef::builder()
                        .material(material)
                        .density(m.density)
                        .filter(filter)
                        .build()?;
                    match s.kind.as_str() {
                        "circle" => {
                            let c = s.center.unwrap_or([0.0, 0.0]);
                            let r = shape_field(s.radius, "radius", s)?;
                            body.create_circle(&def, &shapes::circle(v(c), r)?)?;
                        }
                        "box" => {
                            let h = shape_field(s.half_extents, "half_extents", s)?;
                            let c = s.center.unwrap_or([0.0, 0.0]);
                            let a = s.angle.unwrap_or(0.0);
                            let poly = if c == [0.0, 0.0] && a == 0.0 {
                                shapes::box_polygon(h[0], h[1])?
                            } else {
                                shapes::offset_box_polygon(h[0], h[1], Transform::from_pos_angle(v(c), a)?)?
                            };
                            body.create_polygon(&def, &poly)?;
                        }
                        "polygon" => {
                            let pts = s.vertices.as_ref().ok_or("a polygon needs \"vertices\"")?;
                            let poly = shapes::polygon_from_points(pts.iter().map(|&p| v(p)), s.radius.unwrap_or(0.0))?;
                            body.create_polygon(&def, &poly)?;
                        }
                        "capsule" => {
                            let c1 = shape_field(s.center1, "center1", s)?;
                            let c2 = shape_field(s.center2, "center2", s)?;
                            let r = shape_field(s.radius, "radius", s)?;
                            body.create_capsule(&def, &shapes::capsule(v(c1), v(c2), r)?)?;
                        }
                        "segment" => {
                            let p1 = shape_field(s.point1, "point1", s)?;
                            let p2 = shape_field(s.point2, "point2", s)?;
                            body.create_segment(&def, &shapes::segment(v(p1), v(p2))?)?;
                        }
                        "chain" => {
                            let pts = s.points.as_ref().ok_or("a chain needs \"points\"")?;
                            let closed = s.closed.unwrap_or(false);
                            let mut all: Vec<[f32; 2]> = pts.clone();
                            if !closed && pts.len() >= 2 {
                                // Box2D uses an open chain's first and last points as ghost
                                // vertices only; Tribo's free ends are right-angled corners,
                                // so the ghosts go behind the end pieces.
                                let behind = |a: [f32; 2], b: [f32; 2], at: [f32; 2]| {
                                    // −right_perp(b − a) = (−(b−a).y, (b−a).x)
                                    [at[0] - (b[1] - a[1]), at[1] + (b[0] - a[0])]
                                };
                                let n = pts.len();
                                all.insert(0, behind(pts[0], pts[1], pts[0]));
                                all.push(behind(pts[n - 2], pts[n - 1], pts[n - 1]));
                            }
                            let chain = ChainDef::builder()
                                .points(all.iter().map(|&p| v(p)))
                                .is_loop(closed)
                                .single_material(&material)
                                .filter(filter)
                                .build()?;
                            body.create_chain(&chain)?;
                        }
                        other => return Err(format!("unknown shape type {other}").into()),
                    }
                }
            }
            if b.kind == BodyKind::Dynamic && (b.force != [0.0, 0.0] || b.torque != 0.0) {
                forces.push((id, v(b.force), b.torque));
            }
            bodies.push(id);
        }
        for j in &scene.joints {
            let g = joint_geometry(scene, j)?;
            // Box2D's joint angle is that of frame B relative to frame A: frame B turned by
            // −(reference angle: by default the initial relative angle) makes it 0 there, as
            // in the scene.
            let base = world
                .joint_base(bodies[g.a], bodies[g.b])?
                .with_local_frame_components(v(g.local_a), 0.0, v(g.local_b), -g.relative_angle)?
                .with_collide_connected(j.collide_connected)
                .with_constraint_tuning(ConstraintTuning::new(j.constraint_hertz, j.constraint_damping_ratio)?);
            let mut def = RevoluteJointDef::new(base);
            if let Some([lower, upper]) = j.limit {
                def = def.enable_limit(true).lower_angle(lower).upper_angle(upper);
            }
            if let Some(m) = j.motor {
                def = def
                    .enable_motor(true)
                    .motor_speed(m.speed)
                    .max_motor_torque(m.max_torque);
            }
            if let Some(sp) = j.spring {
                def = def.enable_spring(true).hertz(sp.hertz).damping_ratio(sp.damping_ratio);
            }
            world.create_revolute_joint(&def)?;
        }
        Ok((bodies, forces))
    }

    fn profile_fields(p: &Profile) -> [(&'static str, f32); 14] {
        [
            ("step", p.step),
            ("pairs", p.pairs),
            ("collide", p.collide),
            ("solve", p.solve),
            ("solver_setup", p.solver_setup),
            ("prepare_constraints", p.prepare_constraints),
            ("integrate_velocities", p.integrate_velocities),
            ("warm_start", p.warm_start),
            ("solve_impulses", p.solve_impulses),
            ("integrate_positions", p.integrate_positions),
            ("relax_impulses", p.relax_impulses),
            ("store_impulses", p.store_impulses),
            ("split_islands", p.split_islands),
            ("transforms+refit+sleep", p.transforms + p.refit + p.sleep_islands),
        ]
    }

    impl Sim for Box2dSim {
        fn step(&mut self) -> Result<(), BoxError> {
            for &(id, f, t) in &self.forces {
                let mut body = self.world.body(id)?;
                body.apply_force_to_center(f, false)?;
                if t != 0.0 {
                    body.apply_torque(t, false)?;
                }
            }
            let completed = self.world.step(self.dt, self.substeps)?;
            match completed.post_step_error() {
                Some(e) => Err(e.into()),
                None => Ok(()),
            }
        }
        fn spawn(&mut self, tag: usize, batch: &SceneFile) -> Result<(), BoxError> {
            let (ids, forces) = add_scene(self.foundation, &mut self.world, batch)?;
            if !forces.is_empty() {
                return Err("box2d: constant forces on spawned bodies are not mapped".into());
            }
            self.spawned.entry(tag).or_default().extend(ids);
            Ok(())
        }
        fn despawn(&mut self, tag: usize) -> Result<(), BoxError> {
            for id in self.spawned.remove(&tag).unwrap_or_default() {
                self.world.body(id)?.destroy()?;
            }
            Ok(())
        }
        fn spawned_positions(&mut self, tag: usize) -> Vec<[f32; 2]> {
            let ids = self.spawned.get(&tag).cloned().unwrap_or_default();
            ids.iter()
                .map(|&id| match self.world.body(id).and_then(|b| b.position()) {
                    Ok(p) => [p.x, p.y],
                    Err(_) => [f32::NAN; 2],
                })
                .collect()
        }
        fn set_kinematic_velocity(&mut self, i: usize, vel: [f32; 2], w: f32) -> Result<(), BoxError> {
            let mut body = self.world.body(self.bodies[i])?;
            body.set_linear_velocity(v(vel))?;
            body.set_angular_velocity(w)?;
            Ok(())
        }
        fn position(&mut self, i: usize) -> [f32; 2] {
            match self.world.body(self.bodies[i]).and_then(|b| b.position()) {
                Ok(p) => [p.x, p.y],
                Err(_) => [f32::NAN; 2],
            }
        }
        fn angle(&mut self, i: usize) -> f32 {
            match self.world.body(self.bodies[i]).and_then(|b| b.rotation()) {
                Ok(q) => q.angle(),
                Err(_) => f32::NAN,
            }
        }
        fn velocity(&mut self, i: usize) -> [f32; 2] {
            match self.world.body(self.bodies[i]).and_then(|b| b.linear_velocity()) {
                Ok(p) => [p.x, p.y],
                Err(_) => [f32::NAN; 2],
            }
        }
        fn angular_velocity(&mut self, i: usize) -> f32 {
            self.world
                .body(self.bodies[i])
                .and_then(|b| b.angular_velocity())
                .unwrap_or(f32::NAN)
        }
        fn mass(&mut self, i: usize) -> f32 {
            self.world.body(self.bodies[i]).and_then(|b| b.mass()).unwrap_or(0.0)
        }
        fn contact_count(&mut self) -> usize {
            self.world.counters().map(|c| c.contact_count as usize).unwrap_or(0)
        }
        fn threads(&self) -> usize {
            self.threads
        }
        fn awake_count(&mut self) -> usize {
            self.world.awake_body_count().map(|n| n as usize).unwrap_or(0)
        }
        fn profile_sample(&mut self) {
            if let Ok(p) = self.world.profile() {
                self.profile.add(&profile_fields(&p));
            }
        }
        fn profile_report(&self) -> String {
            self.profile.report("Box2D's b2Profile")
        }
    }
}

// ---------------------------------------------------------------------------------------
mod rapier_sim {
    use super::*;
    use rapier2d::prelude::*;

    pub struct RapierSim {
        world: PhysicsWorld,
        bodies: Vec<RigidBodyHandle>,
        /// Bodies added by hooks, by tag.
        spawned: std::collections::BTreeMap<usize, Vec<RigidBodyHandle>>,
        /// Some collider has a filter group ([`GroupHooks`] must run).
        hooks: bool,
        threads: usize,
    }

    /// Box2D's group index, which Rapier's interaction groups do not have: colliders with
    /// a non-zero group carry it in their user data and ask for this contact filter, which
    /// drops the pairs of one negative group. (Rapier tests the interaction groups before
    /// the hook, so a positive group cannot override the masks as in Box2D.)
    struct GroupHooks;

    impl PhysicsHooks for GroupHooks {
        fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
            let group = |h: ColliderHandle| context.colliders.get(h).map_or(0, |c| c.user_data as i32);
            let (a, b) = (group(context.collider1), group(context.collider2));
            if a == b && a < 0 {
                None
            } else {
                Some(SolverFlags::COMPUTE_RIGID_IMPULSES)
            }
        }
    }

    fn v(a: [f32; 2]) -> Vector {
        Vector::new(a[0], a[1])
    }

    /// Damping gain of a Rapier velocity motor [N·m·s/rad]: large, so the drive is as
    /// stiff as Box2D's rigid motor row; the torque bound still limits it.
    const MOTOR_GAIN: f32 = 1.0e9;

    /// A shape's filter as Rapier's interaction groups (32 bits; the group index goes
    /// through [`GroupHooks`]).
    fn groups(s: &ShapeSpec) -> Result<InteractionGroups, BoxError> {
        let f = s.filter.map(tribo::Filter::from).unwrap_or_default();
        if f.group > 0 {
            return Err("rapier: positive filter groups are not mapped (see GroupHooks)".into());
        }
        if f.category > u32::MAX as u64 {
            return Err("rapier: filter categories above bit 31 are not mapped".into());
        }
        Ok(InteractionGroups::new(
            Group::from_bits_truncate(f.category as u32),
            Group::from_bits_truncate(f.mask as u32),
            InteractionTestMode::And,
        ))
    }

    /// Adds a scene's bodies and joints to a Rapier world: the bodies in scene order, and
    /// whether some collider needs [`GroupHooks`].
    fn add_scene(world: &mut PhysicsWorld, scene: &SceneFile) -> Result<(Vec<RigidBodyHandle>, bool), BoxError> {
        let mut hooks = false;
        let mut bodies = Vec::with_capacity(scene.bodies.len());
        for b in &scene.bodies {
            let mut builder = match b.kind {
                BodyKind::Static => RigidBodyBuilder::fixed(),
                BodyKind::Kinematic => RigidBodyBuilder::kinematic_velocity_based(),
                BodyKind::Dynamic => RigidBodyBuilder::dynamic(),
            }
            .translation(v(b.position))
            .rotation(b.angle)
            .can_sleep(scene.enable_sleep);
            if b.kind != BodyKind::Static {
                builder = builder
                    .linvel(v(b.linear_velocity))
                    .angvel(b.angular_velocity)
                    .linear_damping(b.linear_damping)
                    .angular_damping(b.angular_damping)
                    .gravity_scale(b.gravity_scale);
                if b.fixed_rotation {
                    builder = builder.lock_rotations();
                }
                // Rapier's continuous collision is its nearest to a bullet.
                builder = builder.ccd_enabled(b.bullet);
            }
            let handle = world.bodies.insert(builder.build());
            for s in &b.shapes {
                let m = scene.shape_material(s);
                let group = group_of(s);
                let collider = match s.kind.as_str() {
                    "circle" => ColliderBuilder::ball(shape_field(s.radius, "radius", s)?)
                        .translation(v(s.center.unwrap_or([0.0, 0.0]))),
                    "box" => {
                        let h = shape_field(s.half_extents, "half_extents", s)?;
                        ColliderBuilder::cuboid(h[0], h[1])
                            .translation(v(s.center.unwrap_or([0.0, 0.0])))
                            .rotation(s.angle.unwrap_or(0.0))
                    }
                    "polygon" => {
                        let pts: Vec<Vector> = s
                            .vertices
                            .as_ref()
                            .ok_or("a polygon needs \"vertices\"")?
                            .iter()
                            .map(|&p| v(p))
                            .collect();
                        let r = s.radius.unwrap_or(0.0);
                        let c = if r > 0.0 {
                            ColliderBuilder::round_convex_hull(&pts, r)
                        } else {
                            ColliderBuilder::convex_hull(&pts)
                        };
                        c.ok_or("rapier: convex hull failed")?
                    }
                    "capsule" => ColliderBuilder::capsule_from_endpoints(
                        v(shape_field(s.center1, "center1", s)?),
                        v(shape_field(s.center2, "center2", s)?),
                        shape_field(s.radius, "radius", s)?,
                    ),
                    "segment" => ColliderBuilder::segment(
                        v(shape_field(s.point1, "point1", s)?),
                        v(shape_field(s.point2, "point2", s)?),
                    ),
                    // Rapier's one-sided polyline: same winding rule as a Box2D or Tribo chain
                    // (clockwise: the outside is solid), without ghost-vertex smoothing.
                    "chain" => {
                        let pts: Vec<Vector> = s
                            .points
                            .as_ref()
                            .ok_or("a chain needs \"points\"")?
                            .iter()
                            .map(|&p| v(p))
                            .collect();
                        let n = pts.len() as u32;
                        let pieces = if s.closed.unwrap_or(false) {
                            n
                        } else {
                            n.saturating_sub(1)
                        };
                        let indices = (0..pieces).map(|i| [i, (i + 1) % n]).collect();
                        ColliderBuilder::oriented_polyline(pts, Some(indices))
                    }
                    other => return Err(format!("unknown shape type {other}").into()),
                }
                .collision_groups(groups(s)?)
                .user_data(group as u32 as u128)
                .active_hooks(if group != 0 {
                    hooks = true;
                    ActiveHooks::FILTER_CONTACT_PAIRS
                } else {
                    ActiveHooks::empty()
                })
                .density(m.density)
                .friction(m.friction_static)
                .friction_combine_rule(CoefficientCombineRule::GeometricMean)
                .restitution(m.restitution)
                .restitution_combine_rule(CoefficientCombineRule::Max);
                world.colliders.insert_with_parent(collider, handle, &mut world.bodies);
            }
            if b.kind == BodyKind::Dynamic && (b.force != [0.0, 0.0] || b.torque != 0.0) {
                // Rapier keeps user forces until reset_forces.
                let rb = &mut world.bodies[handle];
                rb.add_force(v(b.force), false);
                rb.add_torque(b.torque, false);
            }
            bodies.push(handle);
        }
        for j in &scene.joints {
            let g = joint_geometry(scene, j)?;
            let mut joint = RevoluteJointBuilder::new()
                .local_anchor1(v(g.local_a))
                .local_anchor2(v(g.local_b))
                .contacts_enabled(j.collide_connected)
                .softness(SpringCoefficients::new(j.constraint_hertz, j.constraint_damping_ratio));
            if let Some([lower, upper]) = j.limit {
                joint = joint.limits([lower, upper]);
            }
            if let Some(sp) = j.spring {
                // Rapier's joint has one motor: a spring takes it (acceleration-based, so the
                // stiffness ω² and damping 2ζω do not depend on the masses, as Box2D's
                // spring), and a friction motor beside it is dropped.
                let omega = 2.0 * std::f32::consts::PI * sp.hertz;
                joint = joint.motor_model(MotorModel::AccelerationBased).motor_position(
                    0.0,
                    omega * omega,
                    2.0 * sp.damping_ratio * omega,
                );
            } else if let Some(m) = j.motor {
                // A velocity drive (no stiffness, damping gain MOTOR_GAIN: near rigid) with
                // the torque bound, as Box2D's motor.
                joint = joint
                    .motor_model(MotorModel::ForceBased)
                    .motor_velocity(m.speed, MOTOR_GAIN)
                    .motor_max_force(m.max_torque);
            }
            let mut joint = joint.build();
            // Rapier's joint angle is that of frame 2 relative to frame 1: frame 1 turned by
            // the reference angle makes it 0 there.
            joint.data.local_frame1.rotation = Rotation::new(g.relative_angle);
            world.impulse_joints.insert(bodies[g.a], bodies[g.b], joint, true);
        }
        Ok((bodies, hooks))
    }

    fn group_of(s: &ShapeSpec) -> i32 {
        s.filter.map_or(0, |f| f.group)
    }

    impl RapierSim {
        pub fn build(scene: &SceneFile, threads: usize) -> Result<Self, BoxError> {
            let mut world = PhysicsWorld::new();
            world.gravity = v(scene.gravity);
            let p = &mut world.integration_parameters;
            p.dt = scene.dt;
            // Rapier 0.36's TGS-soft solver: num_solver_iterations is the substep count; one
            // biased PGS sweep and one stabilization (relax) sweep per substep, as Box2D.
            p.num_solver_iterations = scene.substeps as usize;
            p.num_internal_pgs_iterations = 1;
            p.num_internal_stabilization_iterations = 1;
            #[cfg(feature = "rapier-parallel")]
            let threads = {
                world.physics_pipeline.configure_thread_pool(threads)?;
                threads
            };
            #[cfg(not(feature = "rapier-parallel"))]
            let threads = {
                let _ = threads;
                1
            };
            let (bodies, hooks) = add_scene(&mut world, scene)?;
            // Bodies created asleep. Rapier wakes bodies whose contacts start touching, and
            // its sleep test compares each body's pose with the pose of its previous step
            // (a first step counts as motion), so a block of touching sleepers (smash)
            // created with `RigidBodyBuilder::sleeping(true)` wakes on the first step and is
            // solved for 0.5 s; `RigidBody::sleep` after creation leaves the bodies flagged
            // asleep but still solved. What works: prime the contact graph with a
            // zero-length step (collision detection only), then take one 1 µs step (records
            // the poses; nothing moves but the projectile, by 40 µm), then mark the sleepers
            // as having rested `time_until_sleep`: Rapier's own sleep pass then puts their
            // island to sleep at the end of the (untimed) first step, as Box2D has them from
            // the start. All of this is part of the untimed build.
            let sleepers: Vec<RigidBodyHandle> = scene
                .bodies
                .iter()
                .zip(&bodies)
                .filter(|(b, _)| !b.awake && scene.enable_sleep && b.kind == BodyKind::Dynamic)
                .map(|(_, &h)| h)
                .collect();
            if !sleepers.is_empty() {
                let dt = world.integration_parameters.dt;
                world.integration_parameters.dt = 0.0;
                world.step();
                world.integration_parameters.dt = 1e-6;
                world.step();
                world.integration_parameters.dt = dt;
                for h in sleepers {
                    let a = world.bodies[h].activation_mut();
                    a.time_since_can_sleep = a.time_until_sleep;
                }
            }
            Ok(RapierSim {
                world,
                bodies,
                spawned: Default::default(),
                hooks,
                threads,
            })
        }
    }

    impl Sim for RapierSim {
        fn step(&mut self) -> Result<(), BoxError> {
            if self.hooks {
                self.world.step_with_events(&GroupHooks, &());
            } else {
                self.world.step();
            }
            Ok(())
        }
        fn spawn(&mut self, tag: usize, batch: &SceneFile) -> Result<(), BoxError> {
            let (handles, hooks) = add_scene(&mut self.world, batch)?;
            self.hooks |= hooks;
            self.spawned.entry(tag).or_default().extend(handles);
            Ok(())
        }
        fn despawn(&mut self, tag: usize) -> Result<(), BoxError> {
            let w = &mut self.world;
            for h in self.spawned.remove(&tag).unwrap_or_default() {
                w.bodies.remove(
                    h,
                    &mut w.islands,
                    &mut w.colliders,
                    &mut w.impulse_joints,
                    &mut w.multibody_joints,
                    &mut w.soft_bodies,
                    true,
                );
            }
            Ok(())
        }
        fn spawned_positions(&mut self, tag: usize) -> Vec<[f32; 2]> {
            let handles = self.spawned.get(&tag).map(Vec::as_slice).unwrap_or_default();
            handles
                .iter()
                .map(|&h| match self.world.bodies.get(h) {
                    Some(rb) => [rb.translation().x, rb.translation().y],
                    None => [f32::NAN; 2],
                })
                .collect()
        }
        fn set_kinematic_velocity(&mut self, i: usize, vel: [f32; 2], w: f32) -> Result<(), BoxError> {
            let rb = &mut self.world.bodies[self.bodies[i]];
            rb.set_linvel(v(vel), true);
            rb.set_angvel(w, true);
            Ok(())
        }
        fn position(&mut self, i: usize) -> [f32; 2] {
            let t = self.world.bodies[self.bodies[i]].translation();
            [t.x, t.y]
        }
        fn angle(&mut self, i: usize) -> f32 {
            self.world.bodies[self.bodies[i]].rotation().angle()
        }
        fn velocity(&mut self, i: usize) -> [f32; 2] {
            let l = self.world.bodies[self.bodies[i]].linvel();
            [l.x, l.y]
        }
        fn angular_velocity(&mut self, i: usize) -> f32 {
            self.world.bodies[self.bodies[i]].angvel()
        }
        fn mass(&mut self, i: usize) -> f32 {
            let rb = &self.world.bodies[self.bodies[i]];
            if rb.is_dynamic() {
                rb.mass()
            } else {
                0.0
            }
        }
        fn contact_count(&mut self) -> usize {
            self.world.narrow_phase.contact_pairs().count()
        }
        fn threads(&self) -> usize {
            self.threads
        }
        fn awake_count(&mut self) -> usize {
            self.bodies
                .iter()
                .chain(self.spawned.values().flatten())
                .filter(|&&h| {
                    let rb = &self.world.bodies[h];
                    rb.is_dynamic() && !rb.is_sleeping()
                })
                .count()
        }
        fn profile_report(&self) -> String {
            "not collected (Rapier's counters need its `profiler` feature)".into()
        }
    }
}
