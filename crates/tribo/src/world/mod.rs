//! The world: owns bodies, shapes and contacts; steps them; answers queries.
//!
//! Pipeline stage: all of them — [`World::step`] (in `step.rs`) reads as the table of
//! contents of a step. This file holds the definition and the public API for creating,
//! destroying, reading and changing bodies and shapes.

mod events;
mod ids;
mod joints;
mod profile;
mod query;
mod step;
mod sweep;

pub use events::{ContactBeginEvent, ContactEndEvent, ContactEvents, ContactInfo, ContactPointInfo};
pub use ids::{BodyId, JointId, ShapeId};
pub use profile::Profile;
pub(crate) use profile::Stopwatch;
pub use query::{QueryFilter, RayResult};

pub(crate) use ids::Arena;

use crate::collision::broad_phase::{aabb_margin, sweep_free, BroadPhase, MOVING_TREE, STATIC_TREE};
use crate::collision::contact::{Contact, ContactSums, NarrowOutcome};
use crate::dynamics::body::Body;
use crate::dynamics::shape::ShapeRecord;
use crate::dynamics::{BodyDef, BodyType, Filter, Material, ShapeDef};
use crate::error::{check_finite, check_non_negative, check_positive, check_vec, Error, Result};
use crate::geometry::{Shape, LINEAR_SLOP, SPECULATIVE_DISTANCE};
use crate::math::{Aabb, Transform, Vec2};
use crate::solver::candidates::{Candidate, ColourKey};
use crate::solver::Contacts;
use crate::solver::{BodySim, BodyState};
use step::ChunkOutcomes;

/// World settings. Every field has a default (listed on the field) that matches Box2D v3
/// where Box2D has the same setting, so scenes port.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldDef {
    /// Gravity [m/s²]. Default (0, −9.81).
    pub gravity: Vec2,
    /// Substeps per step, ≥ 1. Default 4.
    pub substeps: u32,
    /// Contact stiffness [Hz] between moving bodies; contacts with static bodies use twice
    /// this. Clamped to at most 1/8 of the substep rate (30 Hz at 60 Hz × 4). Default 30.
    pub contact_hertz: f32,
    /// Contact damping ratio (dimensionless). Default 10 (heavily damped, no bounce).
    pub contact_damping_ratio: f32,
    /// Largest speed at which overlapping shapes are pushed apart [m/s]. Default 3.
    pub contact_push_speed: f32,
    /// Slip speed [m/s] below which a sliding contact point sticks again. Default 0.01.
    pub stick_speed: f32,
    /// Largest linear speed of any body [m/s]. Default 400.
    pub max_linear_speed: f32,
    /// Whether bodies may fall asleep. Default true.
    pub enable_sleep: bool,
    /// Time [s] an island must rest before it sleeps. Default 0.5. Islands are looked for
    /// every fourth step, so one falls asleep up to three steps (50 ms at 60 Hz) after its
    /// least rested body has rested this long.
    pub time_to_sleep: f32,
    /// Whether impulses carry over between steps. Default true.
    pub warm_starting: bool,
    /// Threads that work on a step, 1..=256. Default 1 (the calling thread only). With more,
    /// the world owns a pool of that many threads; the narrow phase, the constraint set-up,
    /// the impulse store and the finalize are split between them, and so is every colour
    /// of the solver when the step has enough constraints for each thread (on average 100
    /// groups of four or eight per colour and thread; fewer are solved on one). Results
    /// are bit-identical for every count: the work is split only where the parts cannot
    /// affect each other (constraints of one graph colour share no moving body) and
    /// gathered back in a fixed order.
    pub workers: u32,
    /// How many contact constraints the wide solver handles at once, and which build of it
    /// runs. Default [`SolverLanes::Auto`]: eight (AVX2, with AVX-512VL where the CPU has
    /// it) on an x86-64 CPU that has AVX2, else four. Results are bit-identical every way
    /// ([`crate::solver_lanes`]); only the speed differs.
    pub solver_lanes: SolverLanes,
}

/// Which build of the wide contact solver a world runs ([`WorldDef::solver_lanes`]). The
/// solver is compiled three ways into every x86-64 binary (four lanes for SSE2, eight for
/// AVX2, eight for AVX2 with AVX-512F/VL); the world picks one when it is made (or given
/// new settings), and [`World::solver_instructions`] says which.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum SolverLanes {
    /// The fastest this CPU runs: eight lanes compiled for AVX-512VL if the CPU has
    /// AVX-512F and AVX-512VL and is of Ice Lake's generation or later (it has AVX-512
    /// VBMI2; the same 256-bit vectors as AVX2, with 32 registers instead of 16), else
    /// eight compiled for AVX2 if it has AVX2, else four. The default.
    #[default]
    Auto,
    /// Eight lanes compiled for AVX2 only, even on a CPU with AVX-512 (four without AVX2),
    /// e.g. to compare or to test that build.
    Eight,
    /// Four lanes (SSE2 on x86-64, the baseline every x86-64 CPU has), e.g. to compare.
    Four,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: Vec2::new(0.0, -9.81),
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            contact_push_speed: 3.0,
            stick_speed: 0.01,
            max_linear_speed: 400.0,
            enable_sleep: true,
            time_to_sleep: 0.5,
            warm_starting: true,
            workers: 1,
            solver_lanes: SolverLanes::Auto,
        }
    }
}

impl WorldDef {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        check_vec("WorldDef::gravity", self.gravity)?;
        if self.substeps == 0 || self.substeps > 64 {
            return Err(Error::arg(
                "WorldDef::substeps",
                format!("must be in 1..=64 (got {})", self.substeps),
            ));
        }
        check_non_negative("WorldDef::contact_hertz", self.contact_hertz)?;
        check_non_negative("WorldDef::contact_damping_ratio", self.contact_damping_ratio)?;
        check_positive("WorldDef::contact_push_speed", self.contact_push_speed)?;
        check_non_negative("WorldDef::stick_speed", self.stick_speed)?;
        check_positive("WorldDef::max_linear_speed", self.max_linear_speed)?;
        check_non_negative("WorldDef::time_to_sleep", self.time_to_sleep)?;
        if self.workers == 0 || self.workers > 256 {
            return Err(Error::arg(
                "WorldDef::workers",
                format!("must be in 1..=256 (got {})", self.workers),
            ));
        }
        Ok(())
    }
}

/// [`World::reorder_contacts`] renumbers the contacts only when the solver took at least
/// this many (a smaller array stays in the caches whatever its order)…
const REORDER_MIN_CONTACTS: usize = 4096;
/// … and when at least 1 in this many of them did not follow the one before (a pile at
/// rest changes a quarter of its layout once, when most of its contacts start to carry
/// load on both points and move to the front of their colours).
const REORDER_BREAKS: usize = 3;
/// … and at most once in this many steps (a pile in motion changes a quarter of its layout
/// in a few steps: renumbering then costs more than the order saves).
const REORDER_INTERVAL: u64 = 32;

/// What the narrow phase tests of a shape before it reads its geometry: copies of the
/// record's boxes and filter (kept in step with them: [`World::sync_shape_bounds`] after
/// every write), one cache line per shape slot in a compact array. The contacts come in
/// the solver's colour order ([`World::reorder_contacts`]), not their shapes' order: each
/// pair then reads one line per shape, not two or three of a 288-byte arena slot.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct ShapeBounds {
    /// [`ShapeRecord::fat_aabb`].
    pub fat_aabb: Aabb,
    /// [`ShapeRecord::aabb`].
    pub aabb: Aabb,
    pub filter: Filter,
    /// The shape's generation; [`ShapeBounds::NONE`]'s for a free slot.
    pub generation: u32,
}

impl ShapeBounds {
    /// A free slot: no contact's shape id has this generation.
    const NONE: ShapeBounds = ShapeBounds {
        fat_aabb: Aabb {
            min: Vec2::ZERO,
            max: Vec2::ZERO,
        },
        aabb: Aabb {
            min: Vec2::ZERO,
            max: Vec2::ZERO,
        },
        filter: Filter {
            category: 0,
            mask: 0,
            group: 0,
        },
        generation: u32::MAX,
    };
}

const _: () = assert!(core::mem::size_of::<ShapeBounds>() == 64);

/// After a shape's boxes changed: copies them into its [`ShapeBounds`] (filter and
/// generation unchanged; [`World::sync_shape_bounds`] copies everything).
pub(crate) fn copy_boxes(bounds: &mut [ShapeBounds], index: u32, s: &ShapeRecord) {
    if let Some(b) = bounds.get_mut(index as usize) {
        (b.aabb, b.fat_aabb) = (s.aabb, s.fat_aabb);
    }
}

/// A 2D physics world.
pub struct World {
    pub(crate) def: WorldDef,
    pub(crate) bodies: Arena<Body>,
    pub(crate) shapes: Arena<ShapeRecord>,
    /// Per shape slot, what the narrow phase tests first ([`ShapeBounds`]).
    pub(crate) shape_bounds: Vec<ShapeBounds>,
    pub(crate) contacts: Vec<Option<Contact>>,
    /// What the last solved step did at each contact slot's points, for reports
    /// ([`PointSums`]: apart from the records, so the impulse store writes one line of
    /// each); as long as `contacts`, in the same order (a slot's sums are zeroed when a new
    /// contact takes it, and move with it when the contacts are renumbered).
    ///
    /// [`PointSums`]: crate::collision::contact::PointSums
    pub(crate) contact_sums: Vec<ContactSums>,
    pub(crate) contact_free: Vec<u32>,
    pub(crate) joints: Arena<crate::dynamics::joint::JointRecord>,
    pub(crate) broad_phase: BroadPhase,
    pub(crate) events: ContactEvents,
    /// Bodies of each sleeping island (slot = island id); `None` = free slot.
    pub(crate) sleep_islands: Vec<Option<Vec<u32>>>,
    pub(crate) island_free: Vec<u32>,
    /// Bodies whose state became non-finite in the last step (frozen and reported).
    pub(crate) non_finite: Vec<BodyId>,
    // Scratch buffers reused every step (no per-step allocation once warm).
    pub(crate) states: Vec<BodyState>,
    /// The warm start each relax pass carries to the next substep, one entry per state
    /// (velocities only; all zero between steps, see `solver::solve_step`).
    pub(crate) carry: Vec<BodyState>,
    /// A step's solve is under way (set before it, cleared after): still set when the next
    /// one starts, the last one was cut short by a panic the caller caught, and the carry
    /// may hold what its relax passes left; it is cleared then.
    pub(crate) carry_in_use: bool,
    /// Scratch states of the warm-start estimate of new contacts (see `solver::solve_step`).
    pub(crate) trial: Vec<BodyState>,
    pub(crate) sims: Vec<BodySim>,
    pub(crate) contact_solver: Contacts,
    pub(crate) joint_solver: crate::solver::joint_solver::JointSolver,
    /// The solver's input of each contact slot, written by the narrow phase for the
    /// touching contacts with an awake dynamic side (`solver_contacts` lists them).
    pub(crate) candidates: Vec<Candidate>,
    /// What the colouring reads of each candidate (indexed by contact, like `candidates`).
    pub(crate) colour_keys: Vec<ColourKey>,
    /// The narrow phase's verdict on each contact slot it visited this step, and whether
    /// the contact has a candidate (dense: written by the narrow phase's loop, filed into
    /// the chunks' lists after it).
    pub(crate) outcomes: Vec<(NarrowOutcome, bool)>,
    /// What each chunk of the narrow phase found, one entry per chunk of contacts (see
    /// `World::collide`).
    pub(crate) chunk_outcomes: Vec<std::sync::Mutex<ChunkOutcomes>>,
    /// The touching contacts the solver takes this step, in contact order.
    pub(crate) solver_contacts: Vec<u32>,
    /// Whether a force acts on some awake body this step (`solver::any_load` of `sims`,
    /// found by `World::prepare_bodies` while it makes them).
    pub(crate) any_load: bool,
    /// Contacts the narrow phase of the current step listed: those with an awake moving
    /// body, sorted, each once (each chunk of the narrow phase visits its share); none
    /// when most bodies are awake (each contact then tests its bodies).
    pub(crate) active_contacts: Vec<u32>,
    /// The touching contacts the narrow phase visited that the solver does not take (no
    /// awake dynamic side), in contact order: with `solver_contacts`, every touching one.
    pub(crate) unsolved_contacts: Vec<u32>,
    pub(crate) scratch_u32: Vec<u32>,
    pub(crate) scratch_f32: Vec<f32>,
    /// At least 1 in 8 of the contacts the last narrow phase visited were collided in
    /// full (not recycled): the next one asks for the shapes' geometry ahead too.
    pub(crate) collided_many: bool,
    /// One flag per body slot: awake and not static (set by `prepare_bodies`, read by
    /// the narrow phase's `collect_active_contacts`).
    pub(crate) scratch_flags: Vec<bool>,
    /// More than half the bodies are awake and not static (set by `prepare_bodies`).
    pub(crate) mostly_awake: bool,
    /// Scratch of a parallel finalize: per solver slot, whether its body's one shape got
    /// its next box (inside the fat box) in the parallel pass (see `World::finalize`).
    pub(crate) scratch_fitted: Vec<core::sync::atomic::AtomicBool>,
    /// The last parallel finalize left more than half its bodies to its serial pass
    /// (boxes that left their fat boxes; bodies of several shapes, or none): the next ones
    /// run on one thread, the parallel one tried again every 16 steps (see
    /// `World::finalize`).
    pub(crate) finalize_alone: bool,
    /// Finalizes of a threaded world run on one thread (`finalize_alone`; for tests).
    pub(crate) alone_finalizes: u64,
    /// Per solver slot: touched something this step (`finalize`'s sweep rule).
    pub(crate) scratch_touched: Vec<bool>,
    /// Solved bodies per chunk of body slots in the last parallel body pass (its guess
    /// for this step; see `World::prepare_bodies_parallel`).
    pub(crate) scratch_chunk_counts: Vec<usize>,
    /// Parallel body passes run again because a chunk's count changed (for tests).
    pub(crate) body_pass_retries: u64,
    /// Left by a finalize that wrote the next step's solver entries, states and step data
    /// of every solved body (one thread: all three; with threads: the entries' poses and
    /// the states, when no force acted, so the step data hold): the bodies' write count
    /// then, the gravity, and how many solved bodies are loaded. While the count and
    /// gravity are the same, the next body pass is not needed (see
    /// `World::prepare_bodies`).
    pub(crate) next_entries: Option<(u64, Vec2, usize)>,
    /// Some solved dynamic body ended the last finalize with its sleep timer at the time to
    /// sleep: only then may an island fall asleep (`World::update_sleep`).
    pub(crate) any_rested: bool,
    /// Bodies the API wrote through `body_mut` since the last body pass (slot indices, in
    /// call order, repeats kept): not counted by the bodies' write count, but remade one by
    /// one when the pass is skipped.
    pub(crate) written_bodies: Vec<u32>,
    /// How many solved bodies gravity or a force loads (`solver::loads`); `any_load` is
    /// whether any is. A count, so that remaking one body's entries keeps it exact.
    pub(crate) loaded_bodies: usize,
    /// Body passes skipped because finalize had made their entries (for tests).
    pub(crate) body_pass_skips: u64,
    /// The last entries finalize made were not used (a body was written before the next
    /// step, as a scene's per-step hook does): finalize then makes them only every
    /// [`step::ENTRIES_RETRY`] steps, not in every step for nothing.
    pub(crate) entries_unused: bool,
    /// The bodies' write count when this step's solver entries were made (by the body
    /// pass or, before the step, by finalize): finalize brings them up to date only when
    /// no body was written since.
    pub(crate) entries_writes: u64,
    /// Static shapes found by the continuous check (`stop_at_static_shapes`).
    pub(crate) scratch_found: Vec<u32>,
    /// Per body slot, what the solver's constraints need of it (rebuilt every step).
    pub(crate) solver_bodies: Vec<crate::solver::SolverBody>,
    pub(crate) step_count: u64,
    /// The step count when the contacts were last renumbered ([`World::reorder_contacts`]).
    pub(crate) reordered_at: Option<u64>,
    /// The solver layout (`ContactSolver::layouts`, through `solver::Contacts::layouts`) [`World::reorder_contacts`] last
    /// found in good enough order: a kept layout is not walked again (it was walked in
    /// every step of a resting pile, 0.7 % of large_pyramid's step).
    pub(crate) order_checked: Option<u64>,
    pub(crate) profile: Profile,
    /// Worker threads when `def.workers > 1`.
    pub(crate) pool: Option<rayon::ThreadPool>,
}

/// Makes the thread pool for `workers` threads (none for 1).
fn make_pool(workers: u32) -> Result<Option<rayon::ThreadPool>> {
    if workers <= 1 {
        return Ok(None);
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(workers as usize)
        .thread_name(|i| format!("tribo-worker-{i}"))
        .build()
        .map(Some)
        .map_err(|e| Error::arg("WorldDef::workers", format!("cannot start {workers} threads: {e}")))
}

impl World {
    /// Makes an empty world; errors if a setting is out of range.
    pub fn new(def: WorldDef) -> Result<World> {
        def.validate()?;
        Ok(World {
            def,
            bodies: Arena::default(),
            shapes: Arena::default(),
            shape_bounds: Vec::new(),
            contacts: Vec::new(),
            contact_sums: Vec::new(),
            contact_free: Vec::new(),
            joints: Arena::default(),
            broad_phase: BroadPhase::default(),
            events: ContactEvents::default(),
            sleep_islands: Vec::new(),
            island_free: Vec::new(),
            non_finite: Vec::new(),
            states: Vec::new(),
            carry: Vec::new(),
            carry_in_use: false,
            trial: Vec::new(),
            sims: Vec::new(),
            contact_solver: Contacts::new(def.solver_lanes),
            joint_solver: Default::default(),
            candidates: Vec::new(),
            colour_keys: Vec::new(),
            outcomes: Vec::new(),
            chunk_outcomes: Vec::new(),
            solver_contacts: Vec::new(),
            any_load: false,
            active_contacts: Vec::new(),
            unsolved_contacts: Vec::new(),
            scratch_u32: Vec::new(),
            scratch_f32: Vec::new(),
            collided_many: false,
            scratch_flags: Vec::new(),
            mostly_awake: false,
            scratch_fitted: Vec::new(),
            finalize_alone: false,
            alone_finalizes: 0,
            scratch_touched: Vec::new(),
            scratch_chunk_counts: Vec::new(),
            body_pass_retries: 0,
            next_entries: None,
            any_rested: false,
            written_bodies: Vec::new(),
            loaded_bodies: 0,
            body_pass_skips: 0,
            entries_unused: false,
            entries_writes: 0,
            scratch_found: Vec::new(),
            solver_bodies: Vec::new(),
            step_count: 0,
            reordered_at: None,
            order_checked: None,
            profile: Profile::default(),
            pool: make_pool(def.workers)?,
        })
    }

    /// Contact constraints the wide solver handles at once in this world: 8 or 4 (see
    /// [`WorldDef::solver_lanes`]).
    pub fn solver_lanes(&self) -> usize {
        self.contact_solver.lanes()
    }

    /// The instructions the wide solver of this world is compiled for: "AVX-512VL" (eight
    /// lanes, with AVX2), "AVX2" (eight lanes), "SSE2" (four lanes, on x86-64) or
    /// "portable" (four lanes, elsewhere). See [`WorldDef::solver_lanes`].
    pub fn solver_instructions(&self) -> &'static str {
        self.contact_solver.instructions()
    }

    /// Per-stage wall-clock times of the last step.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// The settings in force.
    pub fn def(&self) -> &WorldDef {
        &self.def
    }

    /// Replaces the settings (validated first; on error nothing changes).
    pub fn set_def(&mut self, def: WorldDef) -> Result<()> {
        def.validate()?;
        if def.workers != self.def.workers {
            self.pool = make_pool(def.workers)?;
        }
        if def.solver_lanes != self.def.solver_lanes {
            // Each contact keeps its colour, which the new solver tries first.
            self.contact_solver = Contacts::new(def.solver_lanes);
            self.order_checked = None;
        }
        self.def = def;
        Ok(())
    }

    /// Gravity [m/s²].
    pub fn gravity(&self) -> Vec2 {
        self.def.gravity
    }

    /// Sets gravity [m/s²] and wakes every body.
    pub fn set_gravity(&mut self, gravity: Vec2) -> Result<()> {
        check_vec("gravity", gravity)?;
        self.def.gravity = gravity;
        self.wake_all();
        Ok(())
    }

    /// Number of live bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Number of live shapes.
    pub fn shape_count(&self) -> usize {
        self.shapes.len()
    }

    /// Number of contact records (pairs whose fat boxes overlap, touching or not).
    pub fn contact_count(&self) -> usize {
        self.contacts.len() - self.contact_free.len()
    }

    /// Number of steps taken.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Ids of all live bodies in creation-slot order.
    pub fn body_ids(&self) -> Vec<BodyId> {
        self.bodies
            .iter()
            .map(|(i, _)| BodyId {
                index: i,
                generation: self.bodies.generation(i),
            })
            .collect()
    }

    // ----------------------------------------------------------------------------------
    // Bodies
    // ----------------------------------------------------------------------------------

    /// Creates a body. It has no shapes yet: a dynamic body without shapes gets a mass of
    /// 1 kg at its origin.
    pub fn create_body(&mut self, def: &BodyDef) -> Result<BodyId> {
        def.validate()?;
        let mut body = Body::new(def);
        if body.body_type == BodyType::Dynamic {
            body.mass = 1.0;
            body.inv_mass = 1.0;
        }
        let (index, generation) = self.bodies.insert(body);
        let id = BodyId { index, generation };
        if !def.awake && def.body_type != BodyType::Static {
            self.put_to_sleep(&[index]);
        }
        Ok(id)
    }

    /// Destroys a body, its shapes, its contacts (end-touch events are reported) and its
    /// joints.
    pub fn destroy_body(&mut self, id: BodyId) -> Result<()> {
        let b = self.body_ref(id)?;
        let (shapes, joints) = (b.shapes.clone(), b.joints.clone());
        self.wake_body(id.index);
        for j in joints {
            self.remove_joint_internal(j);
        }
        for s in shapes {
            self.remove_shape_internal(s);
        }
        self.bodies.remove(id.index, id.generation);
        Ok(())
    }

    pub(crate) fn body_ref(&self, id: BodyId) -> Result<&Body> {
        self.bodies.get(id.index, id.generation).ok_or(Error::InvalidBody(id))
    }

    /// A body for the API to write: recorded in [`World::written_bodies`], whose solver
    /// entries the next step remakes alone when nothing else was written (a game setting
    /// a player's velocity every frame keeps the skipped body pass).
    pub(crate) fn body_mut(&mut self, id: BodyId) -> Result<&mut Body> {
        let b = self
            .bodies
            .get_mut_quiet(id.index, id.generation)
            .ok_or(Error::InvalidBody(id))?;
        self.written_bodies.push(id.index);
        Ok(b)
    }

    /// Whether the id refers to a live body.
    pub fn contains_body(&self, id: BodyId) -> bool {
        self.bodies.get(id.index, id.generation).is_some()
    }

    /// Body type.
    pub fn body_type(&self, id: BodyId) -> Result<BodyType> {
        Ok(self.body_ref(id)?.body_type)
    }

    /// Position of the body origin [m].
    pub fn body_position(&self, id: BodyId) -> Result<Vec2> {
        Ok(self.body_ref(id)?.xf.p)
    }

    /// Rotation angle [rad] in (−π, π].
    pub fn body_angle(&self, id: BodyId) -> Result<f32> {
        Ok(self.body_ref(id)?.xf.q.angle())
    }

    /// Pose of the body origin.
    pub fn body_transform(&self, id: BodyId) -> Result<Transform> {
        Ok(self.body_ref(id)?.xf)
    }

    /// World position of the centre of mass [m].
    pub fn body_center_of_mass(&self, id: BodyId) -> Result<Vec2> {
        Ok(self.body_ref(id)?.center)
    }

    /// Centre of mass in the body frame [m].
    pub fn body_local_center_of_mass(&self, id: BodyId) -> Result<Vec2> {
        Ok(self.body_ref(id)?.local_center)
    }

    /// Velocity of the centre of mass [m/s].
    pub fn body_linear_velocity(&self, id: BodyId) -> Result<Vec2> {
        Ok(self.body_ref(id)?.v)
    }

    /// Angular velocity [rad/s].
    pub fn body_angular_velocity(&self, id: BodyId) -> Result<f32> {
        Ok(self.body_ref(id)?.w)
    }

    /// Velocity [m/s] of the body's material point at a world point [m].
    pub fn body_velocity_at_point(&self, id: BodyId, world_point: Vec2) -> Result<Vec2> {
        check_vec("world_point", world_point)?;
        let b = self.body_ref(id)?;
        Ok(b.v + Vec2::cross_sv(b.w, world_point - b.center))
    }

    /// Mass [kg] (0 for static and kinematic bodies).
    pub fn body_mass(&self, id: BodyId) -> Result<f32> {
        Ok(self.body_ref(id)?.mass)
    }

    /// Rotational inertia about the centre of mass [kg·m²] (0 if rotation is fixed).
    pub fn body_rotational_inertia(&self, id: BodyId) -> Result<f32> {
        Ok(self.body_ref(id)?.inertia)
    }

    /// Whether the body is awake (static bodies count as awake).
    pub fn body_is_awake(&self, id: BodyId) -> Result<bool> {
        Ok(self.body_ref(id)?.awake)
    }

    /// The user data given at creation.
    pub fn body_user_data(&self, id: BodyId) -> Result<u64> {
        Ok(self.body_ref(id)?.user_data)
    }

    /// The body's shapes in attachment order.
    pub fn body_shapes(&self, id: BodyId) -> Result<Vec<ShapeId>> {
        Ok(self.body_ref(id)?.shapes.clone())
    }

    /// Moves the body origin to `position` [m] with rotation `angle` [rad] (teleport: no
    /// velocity change) and wakes it.
    pub fn set_body_transform(&mut self, id: BodyId, position: Vec2, angle: f32) -> Result<()> {
        check_vec("position", position)?;
        check_finite("angle", angle)?;
        let b = self.body_mut(id)?;
        b.xf = Transform::new(position, angle);
        b.center = b.xf.apply(b.local_center);
        b.center0 = b.center;
        b.q0 = b.xf.q;
        self.wake_body(id.index);
        self.refresh_body_proxies(id.index, 0.0, false);
        Ok(())
    }

    /// Sets the velocity of the centre of mass [m/s] and wakes the body (ignored for
    /// static bodies).
    pub fn set_body_linear_velocity(&mut self, id: BodyId, v: Vec2) -> Result<()> {
        check_vec("linear_velocity", v)?;
        let b = self.body_mut(id)?;
        if b.body_type != BodyType::Static {
            b.v = v;
            self.wake_body(id.index);
        }
        Ok(())
    }

    /// Sets the angular velocity [rad/s] and wakes the body (ignored for static bodies and
    /// for dynamic bodies with fixed rotation).
    pub fn set_body_angular_velocity(&mut self, id: BodyId, w: f32) -> Result<()> {
        check_finite("angular_velocity", w)?;
        let b = self.body_mut(id)?;
        if b.body_type != BodyType::Static && !(b.fixed_rotation && b.is_dynamic()) {
            b.w = w;
            self.wake_body(id.index);
        }
        Ok(())
    }

    /// Applies a force [N] at a world point [m] during the next step (then cleared).
    /// Wakes the body when `wake` is true; a sleeping body not woken ignores the force.
    pub fn apply_force(&mut self, id: BodyId, force: Vec2, world_point: Vec2, wake: bool) -> Result<()> {
        check_vec("force", force)?;
        check_vec("world_point", world_point)?;
        self.push_awake_dynamic(id, wake, |b| {
            b.force += force;
            b.torque += (world_point - b.center).cross(force);
        })
    }

    /// Shared tail of the force and impulse calls: wakes the body if asked, then changes
    /// it if it is dynamic and awake (a sleeping body not woken ignores the push).
    fn push_awake_dynamic(&mut self, id: BodyId, wake: bool, change: impl FnOnce(&mut Body)) -> Result<()> {
        self.body_ref(id)?;
        if wake {
            self.wake_body(id.index);
        }
        let b = self.body_mut(id)?;
        if b.is_dynamic() && b.awake {
            change(b);
        }
        Ok(())
    }

    /// Applies a force [N] at the centre of mass during the next step.
    pub fn apply_force_to_center(&mut self, id: BodyId, force: Vec2, wake: bool) -> Result<()> {
        let c = self.body_ref(id)?.center;
        self.apply_force(id, force, c, wake)
    }

    /// Applies a torque [N·m] during the next step.
    pub fn apply_torque(&mut self, id: BodyId, torque: f32, wake: bool) -> Result<()> {
        check_finite("torque", torque)?;
        self.push_awake_dynamic(id, wake, |b| {
            b.torque += torque;
        })
    }

    /// Applies an impulse [N·s] at a world point [m]: changes the velocity at once.
    pub fn apply_linear_impulse(&mut self, id: BodyId, impulse: Vec2, world_point: Vec2, wake: bool) -> Result<()> {
        check_vec("impulse", impulse)?;
        check_vec("world_point", world_point)?;
        self.push_awake_dynamic(id, wake, |b| {
            b.v += b.inv_mass * impulse;
            b.w += b.inv_inertia * (world_point - b.center).cross(impulse);
        })
    }

    /// Applies an impulse [N·s] at the centre of mass.
    pub fn apply_linear_impulse_to_center(&mut self, id: BodyId, impulse: Vec2, wake: bool) -> Result<()> {
        let c = self.body_ref(id)?.center;
        self.apply_linear_impulse(id, impulse, c, wake)
    }

    /// Applies an angular impulse [N·m·s].
    pub fn apply_angular_impulse(&mut self, id: BodyId, impulse: f32, wake: bool) -> Result<()> {
        check_finite("impulse", impulse)?;
        self.push_awake_dynamic(id, wake, |b| {
            b.w += b.inv_inertia * impulse;
        })
    }

    /// Sets the constant force [N] applied at the centre of mass every step; wakes the body.
    pub fn set_body_constant_force(&mut self, id: BodyId, force: Vec2) -> Result<()> {
        check_vec("constant_force", force)?;
        self.body_mut(id)?.constant_force = force;
        self.wake_body(id.index);
        Ok(())
    }

    /// Sets the constant torque [N·m] applied every step; wakes the body.
    pub fn set_body_constant_torque(&mut self, id: BodyId, torque: f32) -> Result<()> {
        check_finite("constant_torque", torque)?;
        self.body_mut(id)?.constant_torque = torque;
        self.wake_body(id.index);
        Ok(())
    }

    /// Sets the gravity scale (dimensionless); wakes the body.
    pub fn set_body_gravity_scale(&mut self, id: BodyId, scale: f32) -> Result<()> {
        check_finite("gravity_scale", scale)?;
        self.body_mut(id)?.gravity_scale = scale;
        self.wake_body(id.index);
        Ok(())
    }

    /// Sets linear and angular damping [1/s].
    pub fn set_body_damping(&mut self, id: BodyId, linear: f32, angular: f32) -> Result<()> {
        check_non_negative("linear_damping", linear)?;
        check_non_negative("angular_damping", angular)?;
        let b = self.body_mut(id)?;
        b.linear_damping = linear;
        b.angular_damping = angular;
        Ok(())
    }

    /// Makes a body a bullet or not ([`BodyDef::bullet`]), from its next step on.
    pub fn set_body_bullet(&mut self, id: BodyId, bullet: bool) -> Result<()> {
        self.body_mut(id)?.bullet = bullet;
        Ok(())
    }

    /// Fixes or frees the rotation of a body; recomputes its mass data.
    pub fn set_body_fixed_rotation(&mut self, id: BodyId, fixed: bool) -> Result<()> {
        let b = self.body_mut(id)?;
        b.fixed_rotation = fixed;
        if fixed {
            b.w = 0.0;
        }
        self.update_mass(id.index);
        self.wake_body(id.index);
        Ok(())
    }

    /// Wakes (`true`) or puts to sleep (`false`, with its whole island) a body.
    pub fn set_body_awake(&mut self, id: BodyId, awake: bool) -> Result<()> {
        let b = self.body_ref(id)?;
        if b.body_type == BodyType::Static {
            return Ok(());
        }
        if awake {
            self.wake_body(id.index);
        } else if b.awake {
            let island = self.island_of(id.index);
            self.put_to_sleep(&island);
        }
        Ok(())
    }

    // ----------------------------------------------------------------------------------
    // Shapes
    // ----------------------------------------------------------------------------------

    /// Attaches a shape to a body and updates the body's mass, centre of mass and inertia.
    /// Segments are meant for static ground: on a dynamic body they add no mass.
    pub fn create_shape(&mut self, body: BodyId, def: &ShapeDef, geometry: &Shape) -> Result<ShapeId> {
        def.material.validate()?;
        validate_geometry(geometry)?;
        let b = self.body_ref(body)?;
        let tree = if b.body_type == BodyType::Static {
            STATIC_TREE
        } else {
            MOVING_TREE
        };
        let xf = b.xf;
        let v = b.v;
        let margin = aabb_margin(geometry, tree == STATIC_TREE);
        let record = ShapeRecord {
            body,
            geometry: *geometry,
            material: def.material,
            filter: def.filter,
            user_data: def.user_data,
            proxy: u32::MAX,
            tree,
            fat_aabb: Aabb::new(Vec2::ZERO, Vec2::ZERO),
            aabb: Aabb::new(Vec2::ZERO, Vec2::ZERO),
            margin,
            sweep_free: sweep_free(geometry),
            moved: false,
        };
        let (index, generation) = self.shapes.insert(record);
        let id = ShapeId { index, generation };
        let aabb = shape_box(geometry, xf, v, 0.0, 0.0);
        let fat = aabb.expand(margin);
        let proxy = self.broad_phase.create_proxy(tree, fat, def.filter.category, index);
        if let Some(s) = self.shapes.at_mut(index) {
            s.proxy = proxy;
            s.fat_aabb = fat;
            s.aabb = aabb;
        }
        self.sync_shape_bounds(index);
        if let Some(b) = self.bodies.at_mut(body.index) {
            b.shapes.push(id);
            b.shapes_changed();
        }
        self.update_mass(body.index);
        self.wake_body(body.index);
        Ok(id)
    }

    /// Detaches and destroys a shape (its contacts end; the body's mass is recomputed).
    pub fn destroy_shape(&mut self, id: ShapeId) -> Result<()> {
        let body = self.shape_ref(id)?.body;
        self.wake_body(body.index);
        self.remove_shape_internal(id);
        if let Some(b) = self.bodies.at_mut(body.index) {
            b.shapes.retain(|s| *s != id);
            b.shapes_changed();
        }
        self.update_mass(body.index);
        Ok(())
    }

    pub(crate) fn shape_ref(&self, id: ShapeId) -> Result<&ShapeRecord> {
        self.shapes.get(id.index, id.generation).ok_or(Error::InvalidShape(id))
    }

    /// Whether the id refers to a live shape.
    pub fn contains_shape(&self, id: ShapeId) -> bool {
        self.shapes.get(id.index, id.generation).is_some()
    }

    /// The body a shape is attached to.
    pub fn shape_body(&self, id: ShapeId) -> Result<BodyId> {
        Ok(self.shape_ref(id)?.body)
    }

    /// A shape's geometry (in its body's frame).
    pub fn shape_geometry(&self, id: ShapeId) -> Result<Shape> {
        Ok(self.shape_ref(id)?.geometry)
    }

    /// A shape's material.
    pub fn shape_material(&self, id: ShapeId) -> Result<Material> {
        Ok(self.shape_ref(id)?.material)
    }

    /// A shape's filter.
    pub fn shape_filter(&self, id: ShapeId) -> Result<Filter> {
        Ok(self.shape_ref(id)?.filter)
    }

    /// A shape's user data.
    pub fn shape_user_data(&self, id: ShapeId) -> Result<u64> {
        Ok(self.shape_ref(id)?.user_data)
    }

    /// Tight world bounding box of a shape [m].
    pub fn shape_aabb(&self, id: ShapeId) -> Result<Aabb> {
        let s = self.shape_ref(id)?;
        let xf = self.body_ref(s.body)?.xf;
        Ok(s.geometry.aabb(xf))
    }

    /// Replaces a shape's material (validated first). Existing contacts pick the new
    /// coefficients up at once; the body's mass is recomputed if the density changed.
    pub fn set_shape_material(&mut self, id: ShapeId, material: Material) -> Result<()> {
        material.validate()?;
        let s = self
            .shapes
            .get_mut(id.index, id.generation)
            .ok_or(Error::InvalidShape(id))?;
        let density_changed = s.material.density != material.density;
        s.material = material;
        let body = s.body;
        self.remix_contacts(body.index);
        if density_changed {
            self.update_mass(body.index);
        }
        self.wake_body(body.index);
        Ok(())
    }

    /// Replaces a shape's collision filter. Pairs that the new filter forbids end at the
    /// next step; pairs it allows begin as the broad phase finds them.
    pub fn set_shape_filter(&mut self, id: ShapeId, filter: Filter) -> Result<()> {
        let s = self
            .shapes
            .get_mut(id.index, id.generation)
            .ok_or(Error::InvalidShape(id))?;
        s.filter = filter;
        let (tree, proxy, fat, body) = (s.tree, s.proxy, s.fat_aabb, s.body);
        self.sync_shape_bounds(id.index);
        // Re-insert so the tree's category bits and the pair search see the new filter.
        self.broad_phase.destroy_proxy(tree, proxy);
        let new_proxy = self.broad_phase.create_proxy(tree, fat, filter.category, id.index);
        if let Some(s) = self.shapes.at_mut(id.index) {
            s.proxy = new_proxy;
        }
        self.wake_body(body.index);
        Ok(())
    }

    // ----------------------------------------------------------------------------------
    // Internals shared by the API and the step
    // ----------------------------------------------------------------------------------

    /// Recomputes mass, centre of mass, inertia and extent from the body's shapes.
    /// Keeps the origin fixed; the centre-of-mass velocity follows the moved centre.
    pub(crate) fn update_mass(&mut self, body_index: u32) {
        let Some(b) = self.bodies.at(body_index) else { return };
        let shapes: Vec<(Shape, f32)> = b
            .shapes
            .iter()
            .filter_map(|s| self.shapes.get(s.index, s.generation))
            .map(|r| (r.geometry, r.material.density))
            .collect();
        let Some(b) = self.bodies.at_mut(body_index) else {
            return;
        };
        let old_center = b.center;
        let (mut mass, mut moment, mut weighted) = (0.0f32, 0.0f32, Vec2::ZERO);
        if b.body_type == BodyType::Dynamic {
            for (g, rho) in &shapes {
                let md = g.mass(*rho);
                mass += md.mass;
                weighted += md.mass * md.center;
                // inertia about the body origin: I_c + m |c|²
                moment += md.rotational_inertia + md.mass * md.center.length_squared();
            }
        }
        if b.body_type == BodyType::Dynamic && mass > 0.0 {
            let local_center = weighted * (1.0 / mass);
            b.mass = mass;
            b.inv_mass = 1.0 / mass;
            b.local_center = local_center;
            let inertia = moment - mass * local_center.length_squared();
            if inertia > 0.0 && !b.fixed_rotation {
                b.inertia = inertia;
                b.inv_inertia = 1.0 / inertia;
            } else {
                b.inertia = 0.0;
                b.inv_inertia = 0.0;
            }
        } else if b.body_type == BodyType::Dynamic {
            // No mass from shapes: 1 kg at the origin, Box2D's choice.
            b.mass = 1.0;
            b.inv_mass = 1.0;
            b.local_center = Vec2::ZERO;
            b.inertia = 0.0;
            b.inv_inertia = 0.0;
        } else {
            b.mass = 0.0;
            b.inv_mass = 0.0;
            b.inertia = 0.0;
            b.inv_inertia = 0.0;
            b.local_center = Vec2::ZERO;
        }
        if b.fixed_rotation && b.is_dynamic() {
            b.w = 0.0;
        }
        b.center = b.xf.apply(b.local_center);
        b.center0 = b.center;
        // Velocity of the new centre of mass: v + ω × (c_new − c_old).
        b.v += Vec2::cross_sv(b.w, b.center - old_center);
        let lc = b.local_center;
        b.max_extent = shapes.iter().map(|(g, _)| g.max_extent(lc)).fold(0.0, f32::max);
    }

    /// Re-mixes the materials of every contact of a body.
    fn remix_contacts(&mut self, body_index: u32) {
        let Some(b) = self.bodies.at(body_index) else { return };
        for &ci in &b.contacts {
            if let Some(Some(c)) = self.contacts.get_mut(ci as usize) {
                if let (Some(sa), Some(sb)) = (
                    self.shapes.get(c.shape_a.index, c.shape_a.generation),
                    self.shapes.get(c.shape_b.index, c.shape_b.generation),
                ) {
                    c.material = crate::dynamics::mix(&sa.material, &sb.material);
                }
            }
        }
    }

    /// Removes a shape's proxy and contacts and the shape itself (not its body link).
    fn remove_shape_internal(&mut self, id: ShapeId) {
        let Some(s) = self.shapes.get(id.index, id.generation) else {
            return;
        };
        let (tree, proxy, body) = (s.tree, s.proxy, s.body);
        let contacts: Vec<u32> = self
            .bodies
            .at(body.index)
            .map(|b| b.contacts.clone())
            .unwrap_or_default();
        for ci in contacts {
            let involved =
                matches!(self.contacts.get(ci as usize), Some(Some(c)) if c.shape_a == id || c.shape_b == id);
            if involved {
                self.destroy_contact(ci, true);
            }
        }
        self.broad_phase.destroy_proxy(tree, proxy);
        self.shapes.remove(id.index, id.generation);
        self.sync_shape_bounds(id.index);
    }

    /// Copies a shape slot's boxes, filter and generation into [`World::shape_bounds`]
    /// (after every write of them).
    pub(crate) fn sync_shape_bounds(&mut self, index: u32) {
        let copy = self.shapes.at(index).map_or(ShapeBounds::NONE, |s| ShapeBounds {
            fat_aabb: s.fat_aabb,
            aabb: s.aabb,
            filter: s.filter,
            generation: self.shapes.generation(index),
        });
        let i = index as usize;
        if self.shape_bounds.len() <= i {
            self.shape_bounds.resize(i + 1, ShapeBounds::NONE);
        }
        self.shape_bounds[i] = copy;
    }

    /// Updates the fat boxes of a body's shapes after its pose changed.
    /// `dt` > 0 (a step's finalize) also sweeps the boxes along the body's velocity for the
    /// next step (if `sweep`: a bullet, or a body that touched nothing), and first stops a
    /// dynamic body that moved out of the region its pairs covered, or a fast swept one, at
    /// the first static shape in its way ([`World::stop_at_static_shapes`]).
    pub(crate) fn refresh_body_proxies(&mut self, body_index: u32, dt: f32, sweep: bool) {
        if let Some(escaped) = self.refresh_boxes(body_index, dt, 0, None, true, sweep) {
            // A shape ended the step outside the fat box its pairs were found with. Its box
            // at the new pose serves the check and, if the body stays there, the update
            // (a polygon's box is some 140 instructions; the junkyard's falling pentagons
            // escape by the thousand each step).
            if self.stop_at_static_shapes(body_index, escaped) {
                self.refresh_boxes(body_index, dt, 0, None, false, sweep);
            } else {
                self.refresh_boxes(body_index, dt, escaped.0, Some(escaped.1), false, sweep);
            }
        }
    }

    /// [`World::refresh_body_proxies`]' box update, from the body's `first` shape on. With
    /// `check` (and `dt` > 0, for a dynamic body) it first compares each shape's box at the
    /// body's new pose with the fat box its pairs were found with, and stops at the first
    /// one that left it by more than the speculative distance plus the slop, returning its
    /// position in the body's shape list and its box at the new pose (the shapes before it
    /// are updated); the box is computed once either way. `known`: the `first` shape's box
    /// at the body's pose, when the caller has it.
    fn refresh_boxes(
        &mut self,
        body_index: u32,
        dt: f32,
        first: usize,
        known: Option<Aabb>,
        check: bool,
        sweep: bool,
    ) -> Option<(usize, Aabb)> {
        // Disjoint field borrows: no copy of the shape list in this per-step path.
        let Some(b) = self.bodies.at(body_index) else {
            return None;
        };
        let check = check && dt > 0.0 && b.body_type == BodyType::Dynamic;
        let (xf, v) = (b.xf, box_velocity(b, self.def.max_linear_speed));
        let moved = Moved(b.center - b.center0);
        for k in first..b.shapes.len() {
            // Every listed shape is live.
            let index = b.shape_index(k);
            let Some(s) = self.shapes.at_mut(index) else {
                continue;
            };
            let tight = known.filter(|_| k == first).unwrap_or_else(|| s.geometry.aabb(xf));
            let Some(aabb) = next_box(s, tight, v, dt, check, sweep, moved) else {
                return Some((k, tight));
            };
            s.aabb = aabb;
            if !s.fat_aabb.contains(aabb) || dt == 0.0 {
                let fat = aabb.expand(s.margin);
                s.fat_aabb = fat;
                let (tree, proxy) = (s.tree, s.proxy);
                self.broad_phase.move_proxy(tree, proxy, fat, index);
            }
            copy_boxes(&mut self.shape_bounds, index, s);
        }
        None
    }

    /// Wakes a sleeping body and its whole sleeping island.
    pub(crate) fn wake_body(&mut self, body_index: u32) {
        let Some(b) = self.bodies.at(body_index) else { return };
        if b.body_type == BodyType::Static {
            return;
        }
        if b.awake {
            // Only the sleep timer, which no solver entry reads (`World::next_entries`).
            if let Some(b) = self.bodies.at_mut_quiet(body_index) {
                b.sleep_time = 0.0;
            }
            return;
        }
        let island = b.sleep_island;
        let members = self
            .sleep_islands
            .get_mut(island as usize)
            .and_then(|s| s.take())
            .unwrap_or_else(|| vec![body_index]);
        if (island as usize) < self.sleep_islands.len() {
            self.island_free.push(island);
        }
        for m in members {
            if let Some(b) = self.bodies.at_mut(m) {
                b.awake = true;
                b.sleep_time = 0.0;
                b.sleep_island = u32::MAX;
            }
        }
    }

    fn wake_all(&mut self) {
        let ids: Vec<u32> = self.bodies.iter().map(|(i, _)| i).collect();
        for i in ids {
            self.wake_body(i);
        }
    }

    /// Puts the listed bodies to sleep as one island.
    pub(crate) fn put_to_sleep(&mut self, members: &[u32]) {
        let island = match self.island_free.pop() {
            Some(i) => i,
            None => {
                self.sleep_islands.push(None);
                (self.sleep_islands.len() - 1) as u32
            }
        };
        for &m in members {
            if let Some(b) = self.bodies.at_mut(m) {
                b.awake = false;
                b.sleep_time = 0.0;
                b.v = Vec2::ZERO;
                b.w = 0.0;
                b.sleep_island = island;
            }
        }
        self.sleep_islands[island as usize] = Some(members.to_vec());
    }

    /// The awake dynamic bodies connected to `body_index` through touching contacts and
    /// joints.
    fn island_of(&self, body_index: u32) -> Vec<u32> {
        let mut out = vec![body_index];
        let mut seen = std::collections::BTreeSet::from([body_index]);
        let mut i = 0;
        while i < out.len() {
            if let Some(b) = self.bodies.at(out[i]) {
                for &ji in &b.joints {
                    if let Some(j) = self.joints.at(ji) {
                        let other = if j.body_a == out[i] { j.body_b } else { j.body_a };
                        let dynamic = self.bodies.at(other).is_some_and(|o| o.is_dynamic());
                        if dynamic && seen.insert(other) {
                            out.push(other);
                        }
                    }
                }
                for &ci in &b.contacts {
                    if let Some(Some(c)) = self.contacts.get(ci as usize) {
                        if !c.touching {
                            continue;
                        }
                        let other = if c.body_a == out[i] { c.body_b } else { c.body_a };
                        let dynamic = self.bodies.at(other).is_some_and(|o| o.is_dynamic());
                        if dynamic && seen.insert(other) {
                            out.push(other);
                        }
                    }
                }
            }
            i += 1;
        }
        out.sort_unstable();
        out
    }

    /// Renumbers the contacts in the order the last step's solver laid them out (colour
    /// by colour, group by group; then the contacts it did not solve, in their order),
    /// when at least 1 in 3 of them no longer follows the one before in that order and there
    /// are enough of them to overflow the caches. The colouring keeps each contact's
    /// colour while it can ([`Contact::colour`]), so a pile keeps its layout from step to
    /// step, and the next build then reads its candidates (indexed by contact) and the
    /// store writes its contacts in sequence instead of crossing the whole array once per
    /// colour (many_pyramids: 58 000 contacts of 384 bytes, candidates of 160). Box2D v3
    /// keeps its contacts in per-colour arrays for the same reason. Deterministic: the
    /// order comes from the layout.
    ///
    /// [`Contact::colour`]: crate::collision::contact::Contact::colour
    pub(crate) fn reorder_contacts(&mut self) {
        if self
            .reordered_at
            .is_some_and(|at| self.step_count < at + REORDER_INTERVAL)
        {
            return;
        }
        let layout = self.contact_solver.layouts();
        if self.order_checked == Some(layout) {
            return; // the same order as when it was last found good enough
        }
        let mut order = core::mem::take(&mut self.scratch_u32);
        let breaks = self.contact_solver.solved_order(&mut order);
        if order.len() < REORDER_MIN_CONTACTS || REORDER_BREAKS * breaks < order.len() {
            self.scratch_u32 = order;
            self.order_checked = Some(layout);
            return;
        }
        // Each live contact's new index: the solver's order first, then the others in
        // index order (each placed once).
        let n = self.contacts.len();
        let mut new_of_old = vec![u32::MAX; n];
        let mut live = 0u32;
        let contacts = &self.contacts;
        let mut place = |old: usize| {
            if let (Some(Some(_)), Some(new)) = (contacts.get(old), new_of_old.get_mut(old)) {
                if *new == u32::MAX {
                    *new = live;
                    live += 1;
                }
            }
        };
        for &old in &order {
            place(old as usize);
        }
        for old in 0..n {
            place(old);
        }
        permute_live(&mut self.contacts, &new_of_old, live);
        // The sums follow their contacts (a sleeping contact keeps its last ones).
        self.contact_sums.resize(n, ContactSums::default());
        permute_live(&mut self.contact_sums, &new_of_old, live);
        self.contact_free.clear();
        self.reordered_at = Some(self.step_count);
        // The threads' shares of the contact list were found in the old numbering.
        crate::solver::with_contacts!(&mut self.contact_solver, s => s.contact_owners.clear());
        let renumber = |ci: &mut u32| *ci = new_of_old.get(*ci as usize).copied().unwrap_or(u32::MAX);
        // Every value is replaced independently of the others: the map's order cannot
        // reach the result.
        self.broad_phase.pairs.values_mut().for_each(renumber);
        self.bodies
            .for_each_live_mut(false, usize::MAX, |_, b| b.contacts.iter_mut().for_each(renumber));
        self.scratch_u32 = order;
    }

    /// Removes a contact record; reports an end event if it was touching.
    pub(crate) fn destroy_contact(&mut self, ci: u32, wake: bool) {
        let Some(slot) = self.contacts.get_mut(ci as usize) else {
            return;
        };
        let Some(c) = slot.take() else { return };
        self.contact_free.push(ci);
        self.broad_phase
            .pairs
            .remove(&crate::collision::contact::pair_key(c.shape_a.index, c.shape_b.index));
        for (side, bi) in [(0, c.body_a), (1, c.body_b)] {
            // Only the contact lists, which no solver entry reads (`World::next_entries`).
            let Some(b) = self.bodies.at_mut_quiet(bi) else {
                continue;
            };
            // Where the contact says it is (a search only if the list disagrees).
            let at = c.list_pos[side] as usize;
            let Some(pos) = Some(at).filter(|&at| b.contacts.get(at) == Some(&ci)).or_else(|| {
                debug_assert!(false, "contact {ci} is not where its record says in body {bi}'s list");
                b.contacts.iter().position(|&x| x == ci)
            }) else {
                continue;
            };
            let last = b.contacts.len() - 1;
            b.contacts.swap_remove(pos);
            b.contact_keys.swap_remove(pos);
            // The list's last contact moved into the gap: its record learns its new place.
            if let Some(Some(m)) = b
                .contacts
                .get(pos)
                .and_then(|&moved| self.contacts.get_mut(moved as usize))
            {
                for (k, body) in [m.body_a, m.body_b].into_iter().enumerate() {
                    if body == bi && m.list_pos[k] as usize == last {
                        m.list_pos[k] = pos as u32;
                    }
                }
            }
        }
        if c.touching {
            self.events.end.push(ContactEndEvent {
                shape_a: c.shape_a,
                shape_b: c.shape_b,
            });
            if wake {
                self.wake_body(c.body_a);
                self.wake_body(c.body_b);
            }
        }
    }
}

/// Moves each live item of `items` to its place in `new_of_old` (the live items' places
/// are 0 .. `live`, each given once; `u32::MAX` for a free slot) and cuts off the free
/// slots. In place, cycle by cycle: each swap puts one item where it goes, the free slots
/// going after the live items. (A new array for the contacts cost a page fault per 4 KiB
/// at every renumbering: smash's first, of 40 000 contacts, took 7.6 ms, most of it
/// faulting in 13 MB; in place, its five renumberings took 12.7 ms instead of 20.7, and
/// tumbler's 22 took 5.8 ms instead of 17.5.)
fn permute_live<T>(items: &mut Vec<T>, new_of_old: &[u32], live: u32) {
    let n = items.len();
    let mut dest = new_of_old.to_vec();
    dest.resize(n, u32::MAX);
    for (free, d) in (live..).zip(dest.iter_mut().filter(|d| **d == u32::MAX)) {
        *d = free;
    }
    for i in 0..n {
        // A place out of range (not a permutation: a caller's bug) ends the cycle.
        while let Some(&j) = dest.get(i).filter(|&&j| j as usize != i && (j as usize) < n) {
            items.swap(i, j as usize);
            dest.swap(i, j as usize);
        }
    }
    items.truncate(live as usize);
}

/// The box a shape needs in the broad phase: its tight box grown by the speculative
/// distance and, when the step's motion `|v|·dt` exceeds `free` [m] ([`sweep_free`]),
/// swept along the motion (so a fast body's pairs exist before it gets there). The growth
/// by the speculative distance already holds the shape along the first
/// `SPECULATIVE_DISTANCE` of the motion, so the sweep is that much shorter and still
/// holds every pose of the step.
pub(crate) fn shape_box(geometry: &Shape, xf: Transform, v: Vec2, dt: f32, free: f32) -> Aabb {
    swept_box(geometry.aabb(xf), v, dt, free)
}

/// The velocity a body's boxes are swept along: the solver never moves a body faster than
/// the world's speed limit; a velocity above it (left by the last pass of a violent step)
/// must not sweep a box across the world, which would pair it with every shape.
pub(crate) fn box_velocity(b: &Body, limit: f32) -> Vec2 {
    // Well under the limit (the common case) without the square root and the division.
    match length_beyond(b.v.length_squared(), || b.v.length(), limit) {
        Some(speed) => b.v * (limit / speed),
        None => b.v,
    }
}

/// Whether a length is beyond `bound` (≥ 0) [m or m/s]: `exact() > bound`, where `exact` is the
/// length as the caller computes it and `squared` its square (what it is computed from,
/// up to roundings). Where the square is under 0.999 `bound`², a margin far wider than
/// those roundings, the length is surely not beyond and is not computed: the finalize
/// asked for six square roots and two divisions a body, whose latency was most of
/// `refresh_boxes`' samples in large_pyramid. Elsewhere the length is computed and
/// compared as it always was, so the answer is the same to the bit.
#[inline(always)]
pub(crate) fn exceeds(squared: f32, exact: impl FnOnce() -> f32, bound: f32) -> bool {
    length_beyond(squared, exact, bound).is_some()
}

/// [`exceeds`], giving the length where it is beyond the bound (for the callers that use it
/// then, without computing it again).
#[inline(always)]
fn length_beyond(squared: f32, exact: impl FnOnce() -> f32, bound: f32) -> Option<f32> {
    debug_assert!(bound >= 0.0 || bound.is_nan(), "a length's bound is not negative");
    // (A NaN square is not surely small: the length is computed and compared. The bound's
    // square is capped at the largest float: an overflowing one would take every finite
    // square for surely small, while a length scaled apart from its square (`swept_box`)
    // may still be just over a bound that large.)
    let surely_small = squared < 0.999 * (bound * bound).min(f32::MAX);
    if surely_small {
        return None;
    }
    Some(exact()).filter(|&length| length > bound)
}

/// A shape's box for the next step from `tight`, its box at the body's new pose (swept
/// along `v` for `dt` when `sweep`, see [`sweep_free`]), or `None` when `check` finds that
/// the body must first be checked against static shapes ([`World::stop_at_static_shapes`]):
/// - the shape escaped: a static shape the body has no pair with had its fat box (its box
///   grown by the speculative distance) apart from this one's, so a shape poking out of its
///   fat box by less than the speculative distance plus the slop overlaps it by the slop at
///   most: only a shape further out can be where nothing stopped it;
/// - or its boxes are swept and the body moved further this step (`moved` [m]) than the
///   shape may move unswept: the swept box held the motion, but a speculative contact is
///   only as good as the normal it had at the start of the step (a chain piece's, say, far
///   from where the body arrives), so fast bodies are checked as Box2D checks them.
pub(crate) fn next_box(
    s: &ShapeRecord,
    tight: Aabb,
    v: Vec2,
    dt: f32,
    check: bool,
    sweep: bool,
    moved: Moved,
) -> Option<Aabb> {
    if check && !s.fat_aabb.expand(SPECULATIVE_DISTANCE + LINEAR_SLOP).contains(tight) {
        return None;
    }
    if check && sweep && moved.beyond(s.sweep_free) {
        return None;
    }
    Some(swept_box(
        tight,
        v,
        dt,
        if sweep { s.sweep_free } else { f32::INFINITY },
    ))
}

/// The displacement of a body's centre over the step [m] (its length is computed only
/// where it is compared near a bound: [`exceeds`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Moved(pub Vec2);

impl Moved {
    /// Whether the displacement is longer than `bound` [m].
    #[inline(always)]
    pub(crate) fn beyond(self, bound: f32) -> bool {
        exceeds(self.0.length_squared(), || self.0.length(), bound)
    }
}

/// [`shape_box`] from the shape's tight box at its pose.
fn swept_box(tight: Aabb, v: Vec2, dt: f32, free: f32) -> Aabb {
    let aabb = tight.expand(SPECULATIVE_DISTANCE);
    let reach = free.max(SPECULATIVE_DISTANCE);
    let beyond = |dt: f32| length_beyond(v.length_squared() * (dt * dt), || v.length() * dt, reach);
    if let Some(motion) = if dt > 0.0 { beyond(dt) } else { None } {
        let d = v * (dt * (1.0 - SPECULATIVE_DISTANCE / motion));
        aabb.union(Aabb::new(aabb.min + d, aabb.max + d))
    } else {
        aabb
    }
}

/// Shapes built through the public constructors are valid; shapes built by hand (struct
/// literals of the public fields) are checked here.
fn validate_geometry(g: &Shape) -> Result<()> {
    match g {
        Shape::Circle(c) => {
            check_vec("Circle::center", c.center)?;
            check_positive("Circle::radius", c.radius)?;
        }
        Shape::Capsule(c) => {
            check_vec("Capsule::center1", c.center1)?;
            check_vec("Capsule::center2", c.center2)?;
            check_positive("Capsule::radius", c.radius)?;
            if (c.center2 - c.center1).length() < crate::geometry::LINEAR_SLOP {
                return Err(Error::arg("Capsule", "center1 and center2 coincide (use a circle)"));
            }
        }
        Shape::Segment(s) => {
            check_vec("Segment::point1", s.point1)?;
            check_vec("Segment::point2", s.point2)?;
            if (s.point2 - s.point1).length() < crate::geometry::LINEAR_SLOP {
                return Err(Error::arg("Segment", "point1 and point2 coincide"));
            }
        }
        Shape::ChainSegment(c) => {
            check_vec("ChainSegment::ghost1", c.ghost1)?;
            check_vec("ChainSegment::segment.point1", c.segment.point1)?;
            check_vec("ChainSegment::segment.point2", c.segment.point2)?;
            check_vec("ChainSegment::ghost2", c.ghost2)?;
            let slop = crate::geometry::LINEAR_SLOP;
            if (c.segment.point2 - c.segment.point1).length() < slop {
                return Err(Error::arg("ChainSegment", "segment.point1 and segment.point2 coincide"));
            }
            if (c.segment.point1 - c.ghost1).length() < slop || (c.ghost2 - c.segment.point2).length() < slop {
                return Err(Error::arg(
                    "ChainSegment",
                    "a ghost vertex coincides with its end point",
                ));
            }
        }
        // Polygons can only be built through validated constructors (private fields).
        Shape::Polygon(_) => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Polygon;
    use crate::solver::with_contacts;

    /// `exceeds` answers exactly as the plain comparison it stands for (`v.length() > bound`,
    /// and `v.length() * dt > bound` as the finalize scales it), for lengths on both sides of
    /// the bound and within ulps of it (where the squared test must defer to the length), at
    /// zero, for infinite and NaN components, a subnormal step squared and an infinite
    /// bound. Checked by mutation: with the margin 0.999 raised to 1.01 it fails (a length
    /// 0.3 % over the bound would be taken as surely under it); at 1.0 it still passes (the
    /// roundings of these cases stay far inside the margin).
    #[test]
    fn exceeds_agrees_with_the_length_comparison() {
        let bound = 0.02f32;
        let mut lengths = vec![
            0.0f32,
            1e-30,
            0.5 * bound,
            0.9995 * bound,
            1.003 * bound,
            2.0 * bound,
            1e30,
        ];
        // The lengths around the bound, ulp by ulp.
        let mut x = bound;
        for _ in 0..64 {
            x = f32::from_bits(x.to_bits() - 1);
        }
        for _ in 0..128 {
            lengths.push(x);
            x = f32::from_bits(x.to_bits() + 1);
        }
        let mut cases = Vec::new();
        for &len in &lengths {
            // Along an axis and at an angle (the square then carries roundings).
            for dir in [Vec2::new(1.0, 0.0), Vec2::new(0.6, 0.8), Vec2::new(0.28, -0.96)] {
                cases.push(dir * len);
            }
        }
        cases.extend([
            Vec2::new(f32::INFINITY, 0.0),
            Vec2::new(f32::NAN, 1.0),
            Vec2::new(-f32::INFINITY, f32::INFINITY),
        ]);
        let mut near = 0;
        for &v in &cases {
            let plain = v.length() > bound;
            assert_eq!(exceeds(v.length_squared(), || v.length(), bound), plain, "{v:?}");
            assert_eq!(Moved(v).beyond(bound), plain, "{v:?}");
            near += usize::from((v.length() - bound).abs() < 1e-6);
        }
        assert!(near > 100, "the cases reach the bound's ulps ({near})");
        // The forms scaled by the step (`swept_box`, `boxes_care`), where the square and the
        // length are rounded apart: speeds ulp by ulp across bound / dt, for steps of a
        // game, a long one and one whose square is subnormal; and an infinite bound (a box
        // that is not swept) and one whose square overflows.
        let dirs = [Vec2::new(1.0, 0.0), Vec2::new(0.6, 0.8), Vec2::new(0.28, -0.96)];
        let mut flips = 0;
        for (dt, bound) in [
            (1.0f32 / 60.0, bound),
            (1.0 / 240.0, bound),
            (0.37, bound),
            (3e-21, bound),
            (0.5, 3e19),
        ] {
            let mut speed = bound / dt;
            for _ in 0..64 {
                speed = f32::from_bits(speed.to_bits() - 1);
            }
            for _ in 0..128 {
                for dir in dirs {
                    let v = dir * speed;
                    let plain = v.length() * dt > bound;
                    let fast = exceeds(v.length_squared() * (dt * dt), || v.length() * dt, bound);
                    assert_eq!(fast, plain, "{v:?}, dt {dt}, bound {bound}");
                    flips += usize::from(plain);
                }
                speed = f32::from_bits(speed.to_bits() + 1);
            }
        }
        assert!(flips > 0 && flips < 5 * 128 * 3, "both answers occur ({flips})");
        for v in cases {
            let plain = v.length() * 0.5 > f32::INFINITY;
            assert_eq!(
                exceeds(v.length_squared() * 0.25, || v.length() * 0.5, f32::INFINITY),
                plain
            );
        }
    }

    fn square() -> Shape {
        Shape::Polygon(Polygon::new_box(0.1, 0.1).unwrap())
    }

    /// The shape's own (tight) box at `xf` moved by `d`.
    fn moved(g: &Shape, xf: Transform, d: Vec2) -> Aabb {
        g.aabb(Transform { p: xf.p + d, q: xf.q })
    }

    /// A world without sleep, and its ground body (fixed at y = −1 m, no shape yet).
    fn sleepless_with_ground() -> (World, BodyId) {
        sleepless_with_ground_on(1)
    }

    /// [`sleepless_with_ground`] stepped by `workers` threads.
    fn sleepless_with_ground_on(workers: u32) -> (World, BodyId) {
        let mut w = World::new(WorldDef {
            enable_sleep: false,
            workers,
            ..WorldDef::default()
        })
        .unwrap();
        let ground = w.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
        (w, ground)
    }

    /// The shape pairs of a world's contacts, in contact order.
    fn shape_pairs(w: &World) -> Vec<(u32, u32)> {
        w.contacts
            .iter()
            .flatten()
            .map(|c| (c.shape_a.index, c.shape_b.index))
            .collect()
    }

    /// A pyramid of `rows` rows of 1 m boxes on the ground, sleep off.
    fn pyramid(rows: usize) -> World {
        pyramid_on(rows, 1)
    }

    /// [`pyramid`] stepped by `workers` threads.
    fn pyramid_on(rows: usize, workers: u32) -> World {
        let (mut w, ground) = sleepless_with_ground_on(workers);
        let slab = Shape::Polygon(Polygon::new_box(200.0, 1.0).unwrap());
        w.create_shape(ground, &ShapeDef::default(), &slab).unwrap();
        let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        for row in 0..rows {
            let n = rows - row;
            for k in 0..n {
                let x = k as f32 - 0.5 * (n - 1) as f32;
                let b = w
                    .create_body(&BodyDef::dynamic(Vec2::new(x, 0.5 + row as f32)))
                    .unwrap();
                w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
            }
        }
        w
    }

    /// A step whose relax passes carry the warm start (`solver::solve_step`) moves the
    /// bodies as one that warm starts every substep: a 12-row pyramid (78 boxes, resting
    /// contacts carrying up to 11 boxes' weight) and a stack of three boxes resting on a
    /// 20° ramp (μ = 0.6: friction holds them, so every contact, box on box too, carries a
    /// friction load), 20 steps each way, velocities within 5e-4 m/s and positions within
    /// 5e-5 m (the same impulses summed in another order: float rounding, which came to
    /// 4e-5 m/s and 1.3e-6 m; 10 % off one body's friction moment in the carry came to
    /// 3e-2 m/s and 5e-3 m). Carrying must have happened.
    #[test]
    fn carried_warm_start_moves_bodies_as_the_pass_did() {
        let run = |carry: bool| -> (Vec<(Vec2, Vec2, f32)>, u64) {
            let mut w = pyramid(12);
            let angle = 20f32.to_radians();
            let ramp_at = Vec2::new(30.0, 5.0);
            let ramp = w
                .create_body(&BodyDef {
                    angle,
                    ..BodyDef::fixed(ramp_at)
                })
                .unwrap();
            let plank = Shape::Polygon(Polygon::new_box(6.0, 0.5).unwrap());
            w.create_shape(ramp, &ShapeDef::default(), &plank).unwrap();
            let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
            let normal = Vec2::new(-angle.sin(), angle.cos());
            for k in 0..3 {
                let at = ramp_at + normal * (1.0 + k as f32);
                let b = w
                    .create_body(&BodyDef {
                        angle,
                        ..BodyDef::dynamic(at)
                    })
                    .unwrap();
                w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
            }
            crate::solver::with_contacts!(&mut w.contact_solver, s => s.no_carry = !carry);
            let mut carried = 0;
            for _ in 0..20 {
                w.step(1.0 / 60.0).unwrap();
                carried += u64::from(crate::solver::with_contacts!(&w.contact_solver, s => {
                    use crate::solver::ConstraintSet;
                    s.carries_warm_start()
                }));
            }
            let bodies = w
                .body_ids()
                .into_iter()
                .map(|id| {
                    (
                        w.body_position(id).unwrap(),
                        w.body_linear_velocity(id).unwrap(),
                        w.body_angular_velocity(id).unwrap(),
                    )
                })
                .collect();
            (bodies, carried)
        };
        let ((with, carried), (without, none)) = (run(true), run(false));
        assert_eq!((carried, none), (20, 0), "every step carried, or none");
        assert_eq!(with.len(), without.len());
        let (mut dv, mut dp) = (0.0f32, 0.0f32);
        for (a, b) in with.iter().zip(&without) {
            dp = dp.max((a.0 - b.0).length());
            dv = dv.max((a.1 - b.1).length()).max((a.2 - b.2).abs());
        }
        assert!(
            dv <= 5e-4 && dp <= 5e-5,
            "carried vs warm-started: velocity {dv} m/s, position {dp} m"
        );
    }

    /// The in-place renumbering gives what building a new array in the new order gives:
    /// each live item at its new index, the free slots gone, for scattered free slots and
    /// a shuffled order (a fixed-seed linear congruential shuffle).
    #[test]
    fn permuting_in_place_matches_a_new_array() {
        let n = 1000usize;
        let items: Vec<Option<u32>> = (0..n as u32).map(|i| (i % 7 != 3).then_some(i)).collect();
        let mut order: Vec<usize> = (0..n).collect();
        let mut seed = 12345u64;
        for i in (1..n).rev() {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            order.swap(i, (seed >> 33) as usize % (i + 1));
        }
        let mut new_of_old = vec![u32::MAX; n];
        let mut expected = Vec::new();
        for &old in &order {
            if let Some(x) = items[old] {
                new_of_old[old] = expected.len() as u32;
                expected.push(Some(x));
            }
        }
        let mut got = items.clone();
        permute_live(&mut got, &new_of_old, expected.len() as u32);
        assert_eq!(got, expected);
        assert!(expected.len() < n && got.iter().all(Option::is_some));
    }

    /// Asserts that each body's contact list holds exactly its contacts, each where its
    /// record says (`Contact::list_pos`), with the pair key of its shapes beside it.
    fn check_contact_lists(w: &World) {
        let mut count = std::collections::HashMap::new();
        for (ci, c) in w.contacts.iter().enumerate() {
            let Some(c) = c else { continue };
            for (side, bi) in [c.body_a, c.body_b].into_iter().enumerate() {
                let b = w.bodies.at(bi).unwrap();
                let at = c.list_pos[side] as usize;
                assert_eq!(b.contacts.get(at), Some(&(ci as u32)), "contact {ci}, side {side}");
                let key = crate::collision::contact::pair_key(c.shape_a.index, c.shape_b.index);
                assert_eq!(b.contact_keys.get(at), Some(&key), "contact {ci}'s key");
                *count.entry(bi).or_insert(0usize) += 1;
            }
        }
        for (bi, b) in w.bodies.iter() {
            assert_eq!(b.contacts.len(), count.get(&bi).copied().unwrap_or(0), "body {bi}");
            assert_eq!(b.contacts.len(), b.contact_keys.len());
        }
    }

    /// Every contact knows its place in its two bodies' contact lists (`Contact::list_pos`,
    /// which `destroy_contact` takes it out by) while pairs come and go: boxes thrown across
    /// a ground slab and each other, with bodies and shapes destroyed on the way. After every
    /// step each list holds exactly the contacts of its body, each where its record says.
    #[test]
    fn contacts_know_their_place_in_the_body_lists() {
        let (mut w, ground) = sleepless_with_ground();
        let slab = Shape::Polygon(Polygon::new_box(30.0, 1.0).unwrap());
        w.create_shape(ground, &ShapeDef::default(), &slab).unwrap();
        // Spread velocities: 37 k mod 101 walks all of 0 … 100.
        let spread = |k: usize| (k * 37 % 101) as f32 / 101.0;
        let mut boxes = Vec::new();
        for k in 0..150 {
            let def = BodyDef {
                linear_velocity: Vec2::new(12.0 * spread(k) - 6.0, 4.0 * spread(k + 50)),
                ..BodyDef::dynamic(Vec2::new(0.3 * (k % 30) as f32 - 4.5, 0.2 + 0.25 * (k / 30) as f32))
            };
            let b = w.create_body(&def).unwrap();
            let shape = w.create_shape(b, &ShapeDef::default(), &square()).unwrap();
            boxes.push((b, shape));
        }
        let mut destroyed = 0;
        // Ground pairs destroyed (a contact index that left the slab's list, from the
        // middle of the list as often as not), and the longest the list was.
        let (mut left_ground, mut longest) = (0, 0);
        let ground_list = |w: &World| w.bodies.at(ground.index).unwrap().contacts.clone();
        for step in 0..150 {
            let before = ground_list(&w);
            w.step(1.0 / 60.0).unwrap();
            check_contact_lists(&w);
            longest = longest.max(before.len());
            if step % 10 == 5 {
                // A box of the bottom row (the first 30): its pair with the slab goes.
                let (b, shape) = boxes[(step / 10) * 2];
                if step % 20 == 5 {
                    w.destroy_shape(shape).ok();
                } else {
                    w.destroy_body(b).ok();
                }
                destroyed += 1;
                check_contact_lists(&w);
                let after = ground_list(&w);
                left_ground += before.iter().filter(|ci| !after.contains(ci)).count();
            }
        }
        let live = w.contacts.iter().flatten().count();
        assert!(destroyed > 0 && live > 100, "{live} contacts at the end");
        assert!(
            longest >= 30 && left_ground >= 10,
            "slab list up to {longest}, {left_ground} left it"
        );
    }

    /// Renumbering the contacts in the solver's layout order (`World::reorder_contacts`)
    /// changes no result: a pile whose contacts stay the same keeps its colours (greedy
    /// colouring of an unchanged set in any order that keeps each colour's members in
    /// turn gives them back), so the solver does the same arithmetic in the same order and
    /// every pose and velocity is bit for bit that of a world that never renumbers. The
    /// same pairs touch; only their indices differ. And the pyramid stands: its top box
    /// sinks less than 1 cm in 40 steps (the soft contacts' preload carries the load
    /// without deflection; a failing solve would let it sag centimetres).
    #[test]
    fn renumbering_the_contacts_changes_no_result() {
        let rows = 70; // 2 485 boxes, over 7 000 contacts: above REORDER_MIN_CONTACTS
        let (mut a, mut b) = (pyramid(rows), pyramid(rows));
        b.reordered_at = Some(1 << 40); // b never renumbers
        let top = |w: &World| w.bodies.iter().map(|(_, x)| x.xf.p.y).fold(f32::MIN, f32::max);
        let start = top(&a);
        for _ in 0..40 {
            a.step(1.0 / 60.0).unwrap();
            b.step(1.0 / 60.0).unwrap();
        }
        assert!(a.reordered_at.is_some(), "the pyramid's contacts were renumbered");
        let (pa, pb) = (shape_pairs(&a), shape_pairs(&b));
        assert_ne!(pa, pb, "renumbered: the contacts come in another order");
        let sorted = |mut p: Vec<(u32, u32)>| {
            p.sort_unstable();
            p
        };
        assert_eq!(sorted(pa), sorted(pb), "the same pairs");
        for ((_, x), (_, y)) in a.bodies.iter().zip(b.bodies.iter()) {
            assert_eq!((x.xf, x.v, x.w), (y.xf, y.v, y.w));
        }
        assert!(start - top(&a) < 0.01, "top box sank {} m", start - top(&a));
        // The bodies' contact lists follow the renumbering.
        check_contact_lists(&a);
        // So do the reported impulses (kept apart from the records, `World::contact_sums`):
        // renumbering b's contacts between steps leaves every pair reporting what it did.
        let reports = |w: &World| {
            let mut r: Vec<_> = w.contacts().collect();
            r.sort_unstable_by_key(|c| (c.shape_a.index, c.shape_b.index));
            r
        };
        // a renumbered in its steps: the same reports as b, pair by pair.
        assert_eq!(reports(&a), reports(&b));
        let before = (shape_pairs(&b), reports(&b));
        let loaded = before
            .1
            .iter()
            .flat_map(|c| c.points().to_vec())
            .filter(|p| p.normal_impulse > 0.0);
        assert!(loaded.count() > before.1.len(), "the pile's points carry load");
        b.reordered_at = None;
        b.reorder_contacts();
        assert_ne!(shape_pairs(&b), before.0, "b's contacts renumbered");
        assert_eq!(reports(&b), before.1);
    }

    /// A small pile on two threads solves its substeps on one (too few groups per colour
    /// for the team to pay, `World::solve_with`), a large one with the worker team; both
    /// to the same bits as a one-thread world.
    #[test]
    fn only_a_large_pile_shares_its_substeps() {
        let (mut small, mut alone) = (pyramid_on(20, 2), pyramid_on(20, 1));
        for _ in 0..30 {
            small.step(1.0 / 60.0).unwrap();
            alone.step(1.0 / 60.0).unwrap();
        }
        let (groups, colours) = with_contacts!(&small.contact_solver, s => crate::solver::WideContacts::layout_size(s));
        assert!(
            groups > 0 && groups < 200 * colours,
            "{groups} groups in {colours} colours"
        );
        assert!(with_contacts!(&small.contact_solver, s => s.team_steps) == 0, "no team");
        let poses = |w: &World| {
            w.bodies
                .iter()
                .map(|(_, b)| {
                    let (p, q) = (b.xf.p, b.xf.q);
                    [p.x, p.y, q.c, q.s, b.v.x, b.v.y, b.w].map(f32::to_bits)
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(poses(&small), poses(&alone));
        let (mut large, mut large_alone) = (pyramid_on(100, 2), pyramid_on(100, 1));
        for _ in 0..10 {
            large.step(1.0 / 60.0).unwrap();
            large_alone.step(1.0 / 60.0).unwrap();
        }
        assert_eq!(poses(&large), poses(&large_alone));
        let (groups, colours) = with_contacts!(&large.contact_solver, s => crate::solver::WideContacts::layout_size(s));
        assert!(
            with_contacts!(&large.contact_solver, s => s.team_steps) > 0,
            "the team ran ({groups} groups in {colours} colours)"
        );
    }

    /// A hanging grid of 40 columns of 39 disks on 3 081 revolute joints (each column hung
    /// from the ground, as joint_grid's top row is pinned) shares its joint passes between
    /// two threads, block colour by
    /// block colour, and ends to the bit where a one-thread world puts it. The joints hold:
    /// each pivot's two anchors stay within 1 cm (the soft joints give millimetres under a
    /// 39-disk column), and the grid hangs from its pins (its lowest disk 39 m down, the
    /// length of a column, within 0.5 m).
    #[test]
    fn a_hanging_grid_shares_its_joints_between_threads_to_the_same_bits() {
        let grid = |workers: u32| {
            let (mut w, ground) = sleepless_with_ground_on(workers);
            let n = 40;
            let disk = Shape::Circle(crate::geometry::Circle::new(Vec2::ZERO, 0.4).unwrap());
            // Neighbours do not collide (their joints hold them), as in joint_grid.
            let def = ShapeDef {
                filter: Filter {
                    category: 2,
                    mask: !2,
                    group: 0,
                },
                ..ShapeDef::default()
            };
            let mut ids: Vec<BodyId> = Vec::new();
            for k in 0..n {
                for i in 0..n {
                    let at = Vec2::new(k as f32, -(i as f32));
                    let b = if i == 0 {
                        ground
                    } else {
                        let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
                        w.create_shape(b, &def, &disk).unwrap();
                        let up = ids[ids.len() - 1];
                        let joint = crate::dynamics::RevoluteJointDef::at(&w, up, b, at + Vec2::new(0.0, 0.5)).unwrap();
                        w.create_revolute_joint(&joint).unwrap();
                        if k > 0 {
                            let left = ids[ids.len() - n];
                            let joint =
                                crate::dynamics::RevoluteJointDef::at(&w, left, b, at - Vec2::new(0.5, 0.0)).unwrap();
                            w.create_revolute_joint(&joint).unwrap();
                        }
                        b
                    };
                    ids.push(b);
                }
            }
            for _ in 0..30 {
                w.step(1.0 / 60.0).unwrap();
            }
            w
        };
        let (two, one) = (grid(2), grid(1));
        assert!(one.joint_count() > 3000, "{} joints", one.joint_count());
        assert!(two.joint_solver.shared_passes > 0, "the joint passes were shared");
        assert_eq!(one.joint_solver.shared_passes, 0);
        let poses = |w: &World| {
            w.bodies
                .iter()
                .map(|(_, b)| [b.xf.p.x, b.xf.p.y, b.xf.q.c, b.xf.q.s, b.v.x, b.v.y, b.w].map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(poses(&two), poses(&one));
        for id in one.joint_ids() {
            let (a, b) = one.joint_world_anchors(id).unwrap();
            assert!((a - b).length() < 0.01, "joint {id:?}: anchors {a:?} and {b:?} apart");
        }
        let lowest = one.bodies.iter().map(|(_, b)| -b.xf.p.y).fold(0.0f32, f32::max);
        assert!((lowest - 39.0).abs() < 0.5, "the lowest disk hangs {lowest} m down");
    }

    /// On two threads, a cloud of boxes falling fast (each leaves its fat box every step)
    /// is finalized on one thread once a parallel finalize finds that out, and a resting
    /// pyramid in parallel; the falling boxes end where a one-thread world puts them, to
    /// the bit.
    #[test]
    fn a_finalize_that_moves_every_box_runs_on_one_thread() {
        let cloud = |workers: u32| {
            let (mut w, _) = sleepless_with_ground_on(workers);
            let cube = Shape::Polygon(Polygon::new_box(0.25, 0.25).unwrap());
            for i in 0..400 {
                let at = Vec2::new((i % 20) as f32 * 2.0, 500.0 + (i / 20) as f32 * 2.0);
                let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
                w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
            }
            for _ in 0..60 {
                w.step(1.0 / 60.0).unwrap();
            }
            w
        };
        let (two, one) = (cloud(2), cloud(1));
        assert!(two.finalize_alone, "the falling boxes left their fat boxes");
        assert!(
            two.alone_finalizes > 10,
            "{} finalizes on one thread",
            two.alone_finalizes
        );
        let ys = |w: &World| w.bodies.iter().map(|(_, b)| b.xf.p.y.to_bits()).collect::<Vec<_>>();
        assert_eq!(ys(&two), ys(&one));
        // Falling freely for a second: g t = 9.8 m/s down (so they did move).
        let falling = |b: &Body| b.body_type == BodyType::Static || b.v.y < -9.0;
        assert!(one.bodies.iter().all(|(_, b)| falling(b)));
        let mut pile = pyramid_on(20, 2);
        for _ in 0..20 {
            pile.step(1.0 / 60.0).unwrap();
        }
        assert!(!pile.finalize_alone, "a resting pile's boxes stay in their fat boxes");
        assert_eq!(pile.alone_finalizes, 0);
    }

    /// With two threads, the build hands a kept layout's groups to the threads that solve
    /// them (`ContactSolver::build_shares`), and the threaded store writes each run's
    /// contacts in place (`ContactSolver::store`, a run being what one thread solved of a
    /// colour part):
    /// once the contacts are renumbered in the solver's order, nearly every lane's contact
    /// lies in its own run's range, and under 2 % of them are left to be written after, on
    /// one thread. (A wrong cut of the contacts or of their sums between the runs leaves
    /// them all to that serial pass: the results stay right, only slow.)
    #[test]
    fn the_threaded_store_writes_nearly_every_contact_in_place() {
        // Over 14 000 contacts: a threaded store, and enough groups per colour for
        // the substeps to run on both threads (`World::solve_with`).
        let mut w = pyramid_on(100, 2);
        for _ in 0..40 {
            w.step(1.0 / 60.0).unwrap();
        }
        assert!(w.reordered_at.is_some(), "the contacts were renumbered");
        let after = with_contacts!(&w.contact_solver, s => s.stored_after);
        // A run per colour part and thread: the groups each thread solved.
        let runs = with_contacts!(&w.contact_solver, s => s.store_runs);
        assert!(runs >= 2 * 6, "{runs} runs");
        // The kept layout's groups were built by the threads that solve them.
        assert!(with_contacts!(&w.contact_solver, s => s.shared_builds) >= 30);
        // And the next narrow phase hands each thread the contacts of its groups: a share
        // of each thread's at least, ascending from contact 0.
        let owners = with_contacts!(&w.contact_solver, s => s.contact_owners.clone());
        assert_eq!(owners.first().map(|o| o.0), Some(0), "{owners:?}");
        assert!(
            owners.windows(2).all(|o| o[0].0 < o[1].0 && o[0].1 != o[1].1),
            "{owners:?}"
        );
        assert!(owners.iter().any(|o| o.1 == 1), "{owners:?}");
        // And survive the move onto the narrow phase's chunk grid.
        assert!(
            super::step::grid_owners(&owners, super::step::CONTACT_CHUNK).len() >= 2,
            "{owners:?}"
        );
        let solved = w.solver_contacts.len();
        assert!(solved > 7000);
        assert!(
            50 * after < solved,
            "{after} of {solved} contacts stored after the runs"
        );
    }

    /// Keeping last step's colours and layout when the candidates are unchanged
    /// (`ContactSolver::same_layout`) changes no result: a resting pyramid keeps them in
    /// nearly every step, and its poses and velocities are bit for bit those of a world
    /// that colours and lays out its constraints again in every step (the same colours; the
    /// order inside a colour, which follows the loads, differs, and changes no arithmetic).
    #[test]
    fn keeping_the_layout_changes_no_result() {
        let steps = 60;
        let (mut a, mut b) = (pyramid(20), pyramid(20));
        for _ in 0..steps {
            a.step(1.0 / 60.0).unwrap();
            // b colours every step afresh
            with_contacts!(&mut b.contact_solver, s => s.layout_kept = false);
            b.step(1.0 / 60.0).unwrap();
        }
        let kept_layouts = |w: &World| with_contacts!(&w.contact_solver, s => s.kept_layouts);
        assert_eq!(kept_layouts(&b), 0);
        // The loads moved some constraints in or out of the front of their colours, so the
        // two worlds solve them in different orders inside a colour.
        let lanes = |w: &World| with_contacts!(&w.contact_solver, s => s.lane_candidates.concat());
        assert_ne!(lanes(&a), lanes(&b));
        let kept = kept_layouts(&a);
        assert!(kept >= steps - 10, "layout kept in {kept} of {steps} steps");
        for ((_, x), (_, y)) in a.bodies.iter().zip(b.bodies.iter()) {
            assert_eq!((x.xf, x.v, x.w), (y.xf, y.v, y.w));
        }
    }

    /// The parallel body pass (`World::prepare_bodies_parallel`) guesses each chunk's
    /// solved bodies from the last step and runs again when a count changed. Bodies that
    /// fall asleep, wake, come and go change the counts; the two-worker world must stay
    /// bit for bit the one-worker world in every step, and the pass must have run again
    /// (else the test proves nothing about the retry).
    /// A world of `workers` threads with a slab of half-width `slab` [m] and `cols` columns
    /// of `rows` unit boxes, `pitch` [m] apart from x = `x0`; the boxes' ids column by column.
    fn columns_of_boxes(
        workers: u32,
        slab: f32,
        (cols, rows): (usize, usize),
        pitch: f32,
        x0: f32,
    ) -> (World, Vec<BodyId>) {
        let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        let mut w = World::new(WorldDef {
            workers,
            ..WorldDef::default()
        })
        .unwrap();
        let ground = w.create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0))).unwrap();
        let slab = Shape::Polygon(Polygon::new_box(slab, 1.0).unwrap());
        w.create_shape(ground, &ShapeDef::default(), &slab).unwrap();
        let mut ids = Vec::new();
        for col in 0..cols {
            for row in 0..rows {
                let at = Vec2::new(pitch * col as f32 + x0, 0.5 + row as f32);
                let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
                w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
                ids.push(b);
            }
        }
        (w, ids)
    }

    #[test]
    fn the_parallel_body_pass_follows_sleep_and_new_bodies() {
        let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
        // 30 columns of 12 boxes, 2 m apart: 360 bodies in two chunks of slots.
        let make = |workers: u32| columns_of_boxes(workers, 400.0, (30, 12), 2.0, -30.0);
        let ((mut a, ids_a), (mut b, ids_b)) = (make(1), make(2));
        let awake = |w: &World| w.bodies.iter().filter(|(_, x)| x.awake && x.is_dynamic()).count();
        let mut fewest = usize::MAX;
        for step in 0..240 {
            // A column's top box goes at step 120 (its neighbours below wake); at step 160
            // a box drops onto another column (into the freed slot) and 200 more onto the
            // ground beside the columns (a third chunk of slots).
            if step == 120 {
                a.destroy_body(ids_a[11]).unwrap();
                b.destroy_body(ids_b[11]).unwrap();
            }
            if step == 160 {
                for w in [&mut a, &mut b] {
                    let n = w.create_body(&BodyDef::dynamic(Vec2::new(-20.0, 14.0))).unwrap();
                    w.create_shape(n, &ShapeDef::default(), &cube).unwrap();
                    for k in 0..200 {
                        let at = Vec2::new(40.0 + 1.5 * (k % 100) as f32, 1.0 + 2.0 * (k / 100) as f32);
                        let n = w.create_body(&BodyDef::dynamic(at)).unwrap();
                        w.create_shape(n, &ShapeDef::default(), &cube).unwrap();
                    }
                }
                assert_eq!(
                    a.bodies.capacity().div_ceil(step::BODY_CHUNK),
                    3,
                    "a third chunk of body slots"
                );
            }
            a.step(1.0 / 60.0).unwrap();
            b.step(1.0 / 60.0).unwrap();
            fewest = fewest.min(awake(&b));
            for ((_, x), (_, y)) in a.bodies.iter().zip(b.bodies.iter()) {
                assert_eq!((x.xf, x.v, x.w, x.awake), (y.xf, y.v, y.w, y.awake), "step {step}");
            }
        }
        assert!(fewest < 360, "some bodies fell asleep (fewest awake: {fewest})");
        assert!(b.body_pass_retries >= 2, "retries: {}", b.body_pass_retries);
    }

    /// A step skips the body pass when the last finalize made its entries and no body was
    /// written since but through the API's `body_mut`, whose bodies are remade alone
    /// (`World::next_entries`, `World::written_bodies`). A world that always runs the pass
    /// must match it bit for bit through every kind of write between steps: velocity,
    /// force, teleport, gravity scale, gravity, mass (a new shape), bodies created and
    /// destroyed, islands falling asleep and woken. And the skip must happen (else this
    /// proves nothing), but after a write only when awake bodies were written alone.
    #[test]
    fn a_skipped_body_pass_matches_the_pass() {
        skipped_body_pass_matches_the_pass(1);
        skipped_body_pass_matches_the_pass(2);
    }

    /// [`a_skipped_body_pass_matches_the_pass`] with `workers` threads.
    fn skipped_body_pass_matches_the_pass(workers: u32) {
        // 60 columns of 5: 300 bodies, two chunks of body slots for the parallel pass.
        let make = || columns_of_boxes(workers, 100.0, (60, 5), 1.5, -45.0);
        let ((mut a, ids), (mut b, _)) = (make(), make());
        let (mut skips_before, mut skipped_after_write) = (0, Vec::new());
        let mut fewest_awake = usize::MAX;
        for step in 0..400 {
            // The same write to both worlds (ids are the same: built alike).
            let write: Option<&dyn Fn(&mut World)> = match step {
                40 => Some(&|w| w.set_body_linear_velocity(ids[4], Vec2::new(2.0, 3.0)).unwrap()),
                60 => Some(&|w| w.apply_force_to_center(ids[9], Vec2::new(0.0, 400.0), true).unwrap()),
                80 => Some(&|w| w.set_body_transform(ids[14], Vec2::new(-60.0, 3.0), 0.3).unwrap()),
                // Writes to that (awake) body alone: remade one by one, the pass skipped.
                85 => Some(&|w| w.set_body_linear_velocity(ids[14], Vec2::new(1.0, 0.0)).unwrap()),
                90 => Some(&|w| w.set_body_gravity_scale(ids[14], 0.0).unwrap()), // one loaded body fewer
                95 => Some(&|w| w.apply_force_to_center(ids[14], Vec2::new(-30.0, 0.0), false).unwrap()),
                100 => Some(&|w| w.set_gravity(Vec2::new(0.5, -9.0)).unwrap()),
                120 => Some(&|w| {
                    let extra = Shape::Polygon(Polygon::new_offset_box(0.2, 0.2, Vec2::new(0.6, 0.0), 0.0).unwrap());
                    w.create_shape(ids[19], &ShapeDef::default(), &extra).unwrap();
                }),
                140 => Some(&|w| {
                    let n = w.create_body(&BodyDef::dynamic(Vec2::new(-70.0, 2.0))).unwrap();
                    let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
                    w.create_shape(n, &ShapeDef::default(), &cube).unwrap();
                }),
                160 => Some(&|w| w.destroy_body(ids[24]).unwrap()),
                // By step 380 the piles have fallen asleep; this wakes one.
                380 => Some(&|w| w.set_body_awake(ids[1], true).unwrap()),
                _ => None,
            };
            if let Some(f) = write {
                f(&mut a);
                f(&mut b);
            }
            let skips = a.body_pass_skips;
            b.next_entries = None; // `b` always runs its body pass
            a.step(1.0 / 60.0).unwrap();
            b.step(1.0 / 60.0).unwrap();
            if write.is_some() {
                skipped_after_write.push((step, a.body_pass_skips != skips));
            }
            if step < 40 {
                skips_before = a.body_pass_skips;
            }
            if step < 380 {
                let awake = a.bodies.iter().filter(|(_, x)| x.is_dynamic() && x.awake).count();
                fewest_awake = fewest_awake.min(awake);
            }
            for ((_, x), (_, y)) in a.bodies.iter().zip(b.bodies.iter()) {
                assert_eq!(
                    (x.xf, x.v, x.w, x.awake),
                    (y.xf, y.v, y.w, y.awake),
                    "{workers}: step {step}"
                );
            }
            // The loaded bodies' count, kept by the skips and the bodies remade alone,
            // against the full pass's.
            assert_eq!(
                (a.loaded_bodies, a.any_load),
                (b.loaded_bodies, b.any_load),
                "step {step}"
            );
        }
        assert_eq!(b.body_pass_skips, 0);
        // All but step 0, the step after the piles fall asleep (a write) and those
        // until finalize makes the entries again (every `ENTRIES_RETRY` steps once unused):
        // at most 1 + ENTRIES_RETRY of the 40.
        assert!(
            skips_before >= 40 - 1 - super::step::ENTRIES_RETRY,
            "the pass was skipped in {skips_before} of the first 40 steps"
        );
        // Skipped right after a write when the API wrote an awake body alone (85–95: the
        // teleported body, still falling), never after the writes counted as such (gravity,
        // mass, a body created, destroyed or woken from sleep). Steps 40–80 write bodies
        // that may or may not have been woken by then: either is right, and compared above.
        for &(step, skipped) in &skipped_after_write {
            match step {
                85 | 90 | 95 => assert!(skipped, "{workers}: step {step} ran the pass"),
                100 | 120 | 140 | 160 | 380 => assert!(!skipped, "{workers}: step {step} skipped it"),
                _ => {}
            }
        }
        assert!(a.body_pass_skips > 300, "skips: {}", a.body_pass_skips);
        assert!(
            fewest_awake == 0,
            "the piles fell asleep before step 380 (fewest awake: {fewest_awake})"
        );
    }

    /// A shower of spinning boxes thrown down onto a slab between two walls (sleep off).
    fn shower(n: usize) -> World {
        let (mut w, ground) = sleepless_with_ground();
        for (half, at) in [
            ((20.0, 1.0), (0.0, 0.0)),
            ((0.5, 20.0), (-10.0, 20.0)),
            ((0.5, 20.0), (10.0, 20.0)),
        ] {
            let slab = Polygon::new_offset_box(half.0, half.1, Vec2::new(at.0, at.1), 0.0).unwrap();
            w.create_shape(ground, &ShapeDef::default(), &Shape::Polygon(slab))
                .unwrap();
        }
        let cube = Shape::Polygon(Polygon::new_box(0.3, 0.3).unwrap());
        for k in 0..n {
            let (col, row) = ((k % 20) as f32, (k / 20) as f32);
            let def = BodyDef {
                linear_velocity: Vec2::new(0.0, -6.0),
                angular_velocity: if k % 2 == 0 { 3.0 } else { -3.0 },
                ..BodyDef::dynamic(Vec2::new(-8.5 + 0.9 * col, 1.0 + 0.9 * row))
            };
            let b = w.create_body(&def).unwrap();
            w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
        }
        w
    }

    /// When most moving proxies moved, the pair update finds the moving tree's pairs all
    /// at once, by sweep and prune over its boxes (`SweepPrune`) or by a walk of the tree
    /// against itself (`FlatTree::self_pairs`), instead of querying it once per moved
    /// shape: the same new pairs, created in the same (sorted) order, so every contact,
    /// pose and velocity is bit for bit that of a world that always queries.
    #[test]
    fn sweeping_or_walking_the_tree_finds_the_same_pairs() {
        let (mut a, mut b, mut c) = (shower(300), shower(300), shower(300));
        b.broad_phase.no_walk = true;
        c.broad_phase.no_sweep = true;
        for _ in 0..90 {
            for w in [&mut a, &mut b, &mut c] {
                w.step(1.0 / 60.0).unwrap();
            }
        }
        assert_eq!(b.broad_phase.walks + b.broad_phase.sweep.sweeps, 0);
        let (sweeps, walks) = (a.broad_phase.sweep.sweeps, c.broad_phase.walks);
        assert!(sweeps >= 20, "the boxes were swept in {sweeps} of 90 steps");
        assert_eq!(
            (a.broad_phase.walks, a.broad_phase.sweep.gave_up),
            (0, 0),
            "every sweep held"
        );
        assert_eq!(
            (walks, c.broad_phase.sweep.sweeps),
            (sweeps, 0),
            "c walked where a swept"
        );
        let bands = a.broad_phase.sweep.most_bands;
        assert!(bands >= 3, "the shower was swept in bands: at most {bands}");
        let pairs = |w: &World| -> Vec<(u32, u32, bool)> {
            w.contacts
                .iter()
                .flatten()
                .map(|c| (c.shape_a.index, c.shape_b.index, c.touching))
                .collect()
        };
        let (pa, pb, pc) = (pairs(&a), pairs(&b), pairs(&c));
        assert!(pa.iter().filter(|p| p.2).count() > 300, "the boxes have piled up");
        assert_eq!(pa, pb);
        assert_eq!(pa, pc);
        for (((_, x), (_, y)), (_, z)) in a.bodies.iter().zip(b.bodies.iter()).zip(c.bodies.iter()) {
            assert_eq!((x.xf, x.v, x.w), (y.xf, y.v, y.w));
            assert_eq!((x.xf, x.v, x.w), (z.xf, z.v, z.w));
        }
    }

    /// Boxes heaped on one spot (each box's interval holds all the others on both axes):
    /// the sweep gives up, backs off, and the walk finds the pairs instead, the same as a
    /// world that always queries; the tree, refitted after each finalize, answers both.
    #[test]
    fn a_crowded_heap_falls_back_to_the_walk() {
        let heap = || {
            let (mut w, _) = sleepless_with_ground();
            let cube = Shape::Polygon(Polygon::new_box(0.5, 0.5).unwrap());
            for k in 0..300 {
                let at = Vec2::new(0.001 * (k % 20) as f32, 0.001 * (k / 20) as f32);
                let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
                w.create_shape(b, &ShapeDef::default(), &cube).unwrap();
            }
            w
        };
        let (mut a, mut b) = (heap(), heap());
        b.broad_phase.no_walk = true;
        for _ in 0..3 {
            a.step(1.0 / 60.0).unwrap();
            b.step(1.0 / 60.0).unwrap();
        }
        // (300 boxes on one spot need ~45 700 tests, over 128 a box: see
        // `MAX_TESTS_PER_BOX`.) Every step found its pairs all at once, the first by the
        // sweep that gave up, the next two by the walk without sweeping (backing off).
        let sweep = &a.broad_phase.sweep;
        assert_eq!(
            (sweep.sweeps, sweep.gave_up),
            (1, 1),
            "the first sweep gave up, the next backed off"
        );
        assert_eq!(a.broad_phase.walks, 3);
        assert!(shape_pairs(&a).len() > 300 * 299 / 4, "the heap's boxes overlap");
        assert_eq!(shape_pairs(&a), shape_pairs(&b));
        for ((_, x), (_, y)) in a.bodies.iter().zip(b.bodies.iter()) {
            assert_eq!((x.xf, x.v, x.w), (y.xf, y.v, y.w));
        }
    }

    #[test]
    fn a_slow_shape_keeps_its_unswept_box() {
        // half 0.1 m: thickness 0.1 m, free 0.05 m per step (sweep_free); 2 m/s at 1/60 s
        // moves 0.033 m < 0.05 m.
        let (g, xf, dt) = (square(), Transform::new(Vec2::new(1.0, 2.0), 0.3), 1.0 / 60.0);
        let free = sweep_free(&g);
        assert!((free - 0.05).abs() < 1e-6, "{free}");
        let b = shape_box(&g, xf, Vec2::new(2.0, 0.0), dt, free);
        assert_eq!(b, moved(&g, xf, Vec2::ZERO).expand(SPECULATIVE_DISTANCE));
    }

    #[test]
    fn a_fast_shape_box_covers_its_whole_motion() {
        // 30 m/s: 0.5 m per step, more than the free 0.05 m, so the box is swept; the sweep
        // is 2 cm short of the motion, which the growth by the speculative distance makes
        // up: the box holds the shape at every pose of the step (checked at 1/16 steps).
        let (g, xf, dt) = (square(), Transform::new(Vec2::new(0.0, 5.0), 0.7), 1.0 / 60.0);
        let v = Vec2::new(3.0, -30.0);
        let d = v * dt;
        let b = shape_box(&g, xf, v, dt, sweep_free(&g));
        for k in 0..=16 {
            assert!(b.contains(moved(&g, xf, d * (k as f32 / 16.0))), "pose {k}/16 outside");
        }
        // Not more than that: the pose a speculative distance further is outside.
        assert!(!b.contains(moved(&g, xf, d * (1.0 + 1.5 * SPECULATIVE_DISTANCE / d.length()))));
    }
}
