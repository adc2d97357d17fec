//! The solver: sub-stepped soft sequential impulses (Box2D v3's "soft step", read from its
//! source and the Solver2D write-up, implemented anew).
//!
//! Pipeline stage: after the narrow phase, before finalize. The stage order of one step:
//!
//! 1. prepare constraints (anchors, effective masses, softness, warm-start impulses, graph
//!    colouring; built by the world from the touching contacts, see `contact_set` in
//!    [`lanes4`] and [`lanes8`]);
//!    estimate the impulses of new resting contacts
//! 2. for each of the `substeps` substeps of length `h = dt / substeps`:
//!    1. integrate velocities (gravity, forces, damping)
//!    2. warm start (re-apply the accumulated impulses)
//!    3. solve with bias (soft position correction, static-friction anchors)
//!    4. integrate positions (accumulate Δp, Δq)
//!    5. relax (solve again without bias, removing the correction velocity)
//! 3. restitution (one pass, from the recorded impact velocities)
//! 4. store impulses and friction states back into the contacts
//!
//! Constraints join the solver through [`ConstraintSet`]: [`StepConstraints`] holds the
//! step's joints ([`joint_solver`], solved first in each pass, block colour by block
//! colour) and contacts
//! (`contact_set`, coloured and wide, in the build of the wide solver the world runs:
//! [`Contacts`]).

pub(crate) mod candidates;
pub(crate) mod contact_solver;
pub(crate) mod joint_solver;
pub(crate) mod lanes4;
#[cfg(target_arch = "x86_64")]
pub(crate) mod lanes8;
#[cfg(target_arch = "x86_64")]
pub(crate) mod lanes8_avx512;
pub(crate) mod softness;
pub(crate) use crate::math::wide;

use crate::collision::contact::{Contact, ContactSums};
use crate::math::{Rot, Vec2};
use crate::world::{Profile, Stopwatch};
pub(crate) use softness::Softness;

/// Velocity and accumulated motion of one awake body during a step (32 bytes, hot; aligned
/// to 32 so a state never straddles two cache lines).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct BodyState {
    /// Linear velocity of the centre of mass [m/s].
    pub v: Vec2,
    /// Angular velocity [rad/s].
    pub w: f32,
    /// 1 when a contact pushed the body (or a joint acted on it) in the current substep's
    /// biased pass, else 0: set there, read by the positions' integration that follows,
    /// cleared by `integrate_velocities`. The relax writes 0 (dead until then). Keeps the
    /// 32-byte layout; a float so the struct stays plain data.
    pub touched: f32,
    /// Translation of the centre of mass since the start of the step [m].
    pub dp: Vec2,
    /// Rotation since the start of the step.
    pub dq: Rot,
}

/// A body's [`BodyState`] shared by the worker threads of a step: plain memory, read and
/// written without atomics (one of the crate's nine `unsafe` sites; the others are
/// [`SharedState::from_mut_slice`], [`prefetch`], the SSE intrinsics of [`wide`], the lanes
/// of a [`wide`] register read as an array (its `Deref`), the row access of [`rows_at`]
/// and [`write_velocity_row`], `math::wide8`'s AVX intrinsics and lanes, and the calls into
/// the eight-lane solvers compiled for AVX2 (and for AVX2 with AVX-512F/VL) in
/// `contact_set`'s `ConstraintSet` and [`WideContacts`] impls).
///
/// Why it is race-free — the contract every user of [`StateCell`] for `SharedState` keeps:
/// - a constraint pass runs colour by colour, and the constraints of one colour share no
///   moving body (the graph colouring; checked by `debug_assert`s in
///   `ContactSolver::build`), so while a colour runs each dynamic body's state is touched
///   by at most one thread; the static body (index 0) and kinematic bodies are only read
///   by constraints (their lanes' write flags are off);
/// - the joint passes run block colour by block colour, and the blocks of one colour
///   write no body in common (`JointSolver::colour_blocks`; checked by a `debug_assert`);
///   the blocks that found no free colour run one after another on one thread, after the
///   others;
/// - body integration splits the bodies into disjoint ranges, one per task or block;
/// - the warm-start carry ([`solve_step`]'s `carry`, `SharedState`s too) follows the
///   states: a relax pass writes the carry entries of the bodies its lanes write (the same
///   flags, colour by colour), and body integration reads and clears those of its range;
/// - between colours and stages the threads meet at the end of a rayon scope
///   ([`claim_each`]) or wait until every block of the pass is done ([`TeamProgress`]),
///   both Release/Acquire, which orders one colour's writes before the next colour's
///   reads.
///
/// Relaxed atomics did the same safely but cost 40 % of the substep loop: each 64-bit
/// word had to be moved through an integer register and split into two floats, and loads
/// the pass did not need could not be dropped (large_pyramid, one thread on the shared
/// path: warm start + solve + relax 3.8 ms vs 2.7 ms on plain states).
///
/// 32 bytes, two states per cache line, as Box2D's `b2BodyState` array: padding each to its
/// own 64-byte line (so two threads writing neighbouring bodies never share a line) doubled
/// the states' memory past the L2 cache and cost more than the sharing (many_pyramids on
/// two threads: 14.7 / 15.7 → 12.2 / 12.5 ms per step).
///
/// The threads work on the world's states in place ([`SharedState::from_mut_slice`], as
/// [`Cell::from_mut`] does for one thread): copying them into a shared array and back
/// cost two passes over the states per step.
#[derive(Debug, Default)]
#[repr(transparent)]
pub(crate) struct SharedState(core::cell::UnsafeCell<BodyState>);

// SAFETY: see the contract above: no two threads access one state at the same time
// unless both only read, and the barriers between stages order every write before the
// next reads.
#[allow(unsafe_code)]
unsafe impl Sync for SharedState {}

/// How the solver reads and writes body states, and how it splits work: one
/// implementation per step mode, so a single-threaded step works on plain states
/// ([`Cell`]s over the world's `BodyState`s, no atomics; also a threaded step whose layout
/// is too small to share, see `World::solve_with`) and a multi-threaded one on
/// [`SharedState`]s (plain memory under the contract in its doc, work split between the
/// pool's threads). The solver
/// code is generic over it: the physics is written once.
pub(crate) trait StateRead {
    fn get(&self) -> BodyState;
    /// The state as two rows of four lanes: (v.x, v.y, w, touched), (dp.x, dp.y, dq.c, dq.s).
    fn rows(&self) -> [wide::F4; 2];
}

/// The rows of [`StateRead::rows`] read straight from a state's memory (two 16-byte loads).
///
/// The wide solver gathers four bodies by loading these rows and transposing them
/// (Box2D v3's `b2GatherBodies` does the same): built field by field from a copied
/// state, LLVM turned the transpose back into 28 single-lane loads and inserts per
/// gather, and writing the velocity row as an `F4` became four scalar stores, which the
/// next 16-byte load of that body could not forward from (large_pyramid: 6.3 → 6.09 G
/// instructions in 100 steps, ~5 % per step in six alternations).
#[inline(always)]
#[allow(unsafe_code)]
fn rows_at(p: *const BodyState) -> [wide::F4; 2] {
    // SAFETY: `p` points to a live, aligned BodyState no thread writes now (every caller
    // passes its own reference's address); BodyState is repr(C), 16-aligned and is eight
    // f32 in the order of the rows (checked below), so it reads as two F4.
    unsafe { *(p as *const [wide::F4; 2]) }
}

/// Writes the first row of [`StateRead::rows`] into a state's memory (one 16-byte store).
#[inline(always)]
#[allow(unsafe_code)]
fn write_velocity_row(p: *mut BodyState, row: wide::F4) {
    // SAFETY: `p` points to a live, aligned BodyState only this thread touches now (the
    // caller's own cell, see [`SharedState`]'s contract); its first 16 bytes are v, w and
    // touched as f32 (checked below).
    // One vector store on x86-64 (an `F4` is a register there).
    unsafe {
        *(p as *mut wide::F4) = row;
    }
}
const _: () = {
    assert!(core::mem::size_of::<BodyState>() == 32);
    assert!(core::mem::offset_of!(BodyState, v) == 0);
    assert!(core::mem::offset_of!(BodyState, w) == 8);
    assert!(core::mem::offset_of!(BodyState, touched) == 12);
    assert!(core::mem::offset_of!(BodyState, dp) == 16);
    assert!(core::mem::offset_of!(BodyState, dq) == 24);
    // The fields inside (Rust may order a plain struct's fields as it likes).
    assert!(core::mem::offset_of!(Vec2, x) == 0 && core::mem::offset_of!(Vec2, y) == 4);
    assert!(core::mem::offset_of!(Rot, c) == 0 && core::mem::offset_of!(Rot, s) == 4);
};

impl StateRead for BodyState {
    #[inline(always)]
    fn get(&self) -> BodyState {
        *self
    }
    #[inline(always)]
    fn rows(&self) -> [wide::F4; 2] {
        rows_at(self)
    }
}

impl StateRead for core::cell::Cell<BodyState> {
    #[inline(always)]
    fn get(&self) -> BodyState {
        core::cell::Cell::get(self)
    }
    #[inline(always)]
    fn rows(&self) -> [wide::F4; 2] {
        rows_at(self.as_ptr())
    }
}

impl StateRead for SharedState {
    #[inline(always)]
    fn get(&self) -> BodyState {
        self.load()
    }
    #[inline(always)]
    fn rows(&self) -> [wide::F4; 2] {
        rows_at(self.0.get())
    }
}

/// [`StateRead`] plus writing, and the work split that goes with the storage.
pub(crate) trait StateCell: StateRead + Clone + Send {
    fn set(&self, s: BodyState);
    /// Writes only what a constraint pass changes.
    fn set_velocity(&self, v: Vec2, w: f32, touched: f32);
    /// [`StateCell::set_velocity`] from the first row of [`StateRead::rows`] (v.x, v.y, w,
    /// touched): one 16-byte store.
    fn set_velocity_row(&self, row: wide::F4);
    /// Calls `f(i, &mut items[i], states)` for every item; split between threads for
    /// shared states (chunks of at least `min_len`). `f` may only write its item and the
    /// states of bodies no other item touches.
    fn for_each_mut<T: Send>(
        states: &[Self],
        items: &mut [T],
        min_len: usize,
        f: impl Fn(usize, &mut T, &[Self]) + Sync + Send,
    );
    /// [`StateCell::for_each_mut`] over three slices of the same length, with a second
    /// set of states (`carry`, handed to `f` as the last argument, under the same rule).
    fn for_each_mut3<T: Send, U: Send, V: Send>(
        states: &[Self],
        carry: &[Self],
        slices: (&mut [T], &mut [U], &mut [V]),
        min_len: usize,
        f: impl Fn(usize, &mut T, &mut U, &mut V, &[Self], &[Self]) + Sync + Send,
    );
    /// Calls `f(i, states, carry)` for `i` in `0..n` (split between threads for shared
    /// states).
    fn for_each_index(
        states: &[Self],
        carry: &[Self],
        n: usize,
        min_len: usize,
        f: impl Fn(usize, &[Self], &[Self]) + Sync + Send,
    );
    /// The states as shared states, when they are (the worker-team path).
    fn as_shared(states: &[Self]) -> Option<&[SharedState]>;
}

impl StateCell for core::cell::Cell<BodyState> {
    #[inline(always)]
    fn set(&self, s: BodyState) {
        core::cell::Cell::set(self, s);
    }
    #[inline(always)]
    fn set_velocity(&self, v: Vec2, w: f32, touched: f32) {
        let mut s = core::cell::Cell::get(self);
        s.v = v;
        s.w = w;
        s.touched = touched;
        core::cell::Cell::set(self, s);
    }
    #[inline(always)]
    fn set_velocity_row(&self, row: wide::F4) {
        write_velocity_row(self.as_ptr(), row);
    }
    fn for_each_mut<T: Send>(
        states: &[Self],
        items: &mut [T],
        _min_len: usize,
        f: impl Fn(usize, &mut T, &[Self]) + Sync + Send,
    ) {
        for (i, x) in items.iter_mut().enumerate() {
            f(i, x, states);
        }
    }
    fn for_each_mut3<T: Send, U: Send, V: Send>(
        states: &[Self],
        carry: &[Self],
        (a, b, c): (&mut [T], &mut [U], &mut [V]),
        _min_len: usize,
        f: impl Fn(usize, &mut T, &mut U, &mut V, &[Self], &[Self]) + Sync + Send,
    ) {
        for (i, ((x, y), z)) in a.iter_mut().zip(b.iter_mut()).zip(c.iter_mut()).enumerate() {
            f(i, x, y, z, states, carry);
        }
    }
    fn for_each_index(
        states: &[Self],
        carry: &[Self],
        n: usize,
        _min_len: usize,
        f: impl Fn(usize, &[Self], &[Self]) + Sync + Send,
    ) {
        for i in 0..n {
            f(i, states, carry);
        }
    }
    fn as_shared(_: &[Self]) -> Option<&[SharedState]> {
        None
    }
}

impl StateCell for SharedState {
    #[inline(always)]
    fn set(&self, s: BodyState) {
        self.store(s);
    }
    #[inline(always)]
    fn set_velocity(&self, v: Vec2, w: f32, touched: f32) {
        self.store_velocity(v, w, touched);
    }
    #[inline(always)]
    fn set_velocity_row(&self, row: wide::F4) {
        write_velocity_row(self.0.get(), row);
    }
    fn for_each_mut<T: Send>(
        states: &[Self],
        items: &mut [T],
        min_len: usize,
        f: impl Fn(usize, &mut T, &[Self]) + Sync + Send,
    ) {
        for_each_mut(true, items, min_len, |i, x| f(i, x, states));
    }
    fn for_each_mut3<T: Send, U: Send, V: Send>(
        states: &[Self],
        carry: &[Self],
        (a, b, c): (&mut [T], &mut [U], &mut [V]),
        min_len: usize,
        f: impl Fn(usize, &mut T, &mut U, &mut V, &[Self], &[Self]) + Sync + Send,
    ) {
        let n = min_len.max(1);
        let chunks = a.chunks_mut(n).zip(b.chunks_mut(n)).zip(c.chunks_mut(n)).enumerate();
        claim_each(true, chunks, |(k, ((xs, ys), zs))| {
            for (j, ((x, y), z)) in xs.iter_mut().zip(ys.iter_mut()).zip(zs.iter_mut()).enumerate() {
                f(k * n + j, x, y, z, states, carry);
            }
        });
    }
    fn for_each_index(
        states: &[Self],
        carry: &[Self],
        n: usize,
        min_len: usize,
        f: impl Fn(usize, &[Self], &[Self]) + Sync + Send,
    ) {
        let len = min_len.max(1);
        let blocks = (0..n.div_ceil(len)).map(|k| k * len..((k + 1) * len).min(n));
        claim_each(true, blocks, |range| range.for_each(|i| f(i, states, carry)));
    }
    fn as_shared(states: &[Self]) -> Option<&[SharedState]> {
        Some(states)
    }
}

/// How far the threads of one worker-team job (see `ContactSolver::substeps_team`) have
/// got: the number of blocks of work finished, over all the job's passes so far. A thread
/// that has claimed all it can of a pass waits until the count reaches the pass's end
/// (every block of it done), not until every other thread has arrived, as Box2D v3's
/// solver stages wait for their blocks: a thread that is late (its core taken by another
/// process or by the hypervisor, or still waking) holds up the others only while it holds
/// a claimed block, and finds the passes it missed done when it comes. A barrier that
/// waited for every thread cost about 0.25 ms per colour whenever one vCPU was taken
/// away for a while (large_pyramid on two threads: steps of 23 ms in place of 5).
pub(crate) struct TeamProgress {
    done: core::sync::atomic::AtomicU64,
}

impl TeamProgress {
    pub fn new() -> TeamProgress {
        TeamProgress {
            done: core::sync::atomic::AtomicU64::new(0),
        }
    }

    /// Whether every block up to `target` (a running total of the passes' block counts)
    /// is done.
    #[inline]
    pub fn reached(&self, target: u64) -> bool {
        self.done.load(core::sync::atomic::Ordering::Acquire) >= target
    }

    /// Counts `blocks` more as done (after this thread's writes in them: Release, so a
    /// thread that sees the count reach a pass's end sees every block's writes).
    #[inline]
    pub fn finish(&self, blocks: u64) {
        if blocks > 0 {
            self.done.fetch_add(blocks, core::sync::atomic::Ordering::AcqRel);
        }
    }

    /// Returns when every block up to `target` is done: spins, since a pass lasts
    /// microseconds, and yields after a while so an oversubscribed machine progresses.
    pub fn wait_for(&self, target: u64) {
        let mut spins = 0u32;
        while !self.reached(target) {
            if spins < SPINS_BEFORE_YIELD {
                core::hint::spin_loop();
                spins += 1;
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// Asks the CPU to bring `x`'s cache lines (all of them, from its first byte) towards
/// this core ahead of use: for passes that read records in an order the hardware
/// prefetcher cannot guess (the build reads candidates in colour order). A hint: it never
/// faults and changes no result.
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    prefetch_lines(x, core::mem::size_of::<T>().div_ceil(64));
}

/// [`prefetch`] of only the first `lines` cache lines of `x` (a record whose hot part
/// leads it).
#[inline(always)]
pub(crate) fn prefetch_lines<T>(x: &T, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = (x as *const T).cast::<i8>();
        for line in (0..core::mem::size_of::<T>().min(64 * lines)).step_by(64) {
            // SAFETY: a prefetch reads nothing and cannot fault; the address is inside a
            // live reference. SSE is part of x86_64.
            #[allow(unsafe_code)]
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(line));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (x, lines);
}

/// Spins (≈ a few microseconds) before a waiting thread of a team yields its core.
const SPINS_BEFORE_YIELD: u32 = 4000;

impl SharedState {
    pub fn new(s: BodyState) -> SharedState {
        SharedState(core::cell::UnsafeCell::new(s))
    }

    /// The states of an exclusive borrow as shared ones, for the borrow's lifetime.
    #[allow(unsafe_code)]
    pub fn from_mut_slice(states: &mut [BodyState]) -> &[SharedState] {
        // SAFETY: `SharedState` is `repr(transparent)` over `UnsafeCell<BodyState>`, which
        // has `BodyState`'s layout; the exclusive borrow keeps every other access out while
        // the shared one lives (the same argument as `Cell::from_mut`).
        unsafe { &*(states as *mut [BodyState] as *const [SharedState]) }
    }

    #[inline(always)]
    #[allow(unsafe_code)]
    pub fn load(&self) -> BodyState {
        // SAFETY: no thread writes this state now (the contract in the type's docs).
        unsafe { *self.0.get() }
    }

    #[inline(always)]
    #[allow(unsafe_code)]
    pub fn store(&self, s: BodyState) {
        // SAFETY: this thread is the only one touching this state now (type docs).
        unsafe { *self.0.get() = s }
    }

    /// Writes only what a constraint pass changes.
    #[inline(always)]
    #[allow(unsafe_code)]
    pub fn store_velocity(&self, v: Vec2, w: f32, touched: f32) {
        // SAFETY: as `store`; the reference lives only inside this block.
        let state = unsafe { &mut *self.0.get() };
        state.v = v;
        state.w = w;
        state.touched = touched;
    }
}

impl Clone for SharedState {
    fn clone(&self) -> Self {
        SharedState::new(self.load())
    }
}

/// Per-body constants of a step (cold relative to [`BodyState`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BodySim {
    /// Acceleration from gravity and applied forces [m/s²].
    pub linear_accel: Vec2,
    /// Angular acceleration from applied torques [rad/s²].
    pub angular_accel: f32,
    pub linear_damping: f32,
    pub angular_damping: f32,
    /// Body slot index in the world.
    pub body: u32,
    /// Slot index of the body's first shape (`u32::MAX`: none; `World::finalize` asks
    /// for its record ahead without reading the body's shape list).
    pub shape: u32,
    /// The body has joints (a motor may drive it with any torque: its contacts get no
    /// mass-ratio sweeps, see `contact_set`).
    pub jointed: bool,
}

/// What the narrow phase and the constraint build need of a body, one per body slot
/// (static and sleeping bodies too: their poses meet the awake bodies' shapes and their
/// centres anchor the contacts), in a compact array filled at the start of the step: the
/// per-contact passes read one cache line per body, not the body's record (several lines,
/// its fields where the compiler put them), in whatever order the contacts come.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct SolverBody {
    /// Index of the body's state in the solver arrays (0 = none: static or asleep; a
    /// body with a state is active: its contacts are updated this step).
    pub index: u32,
    /// Awake and dynamic: its contacts are solved this step.
    pub awake_dynamic: bool,
    /// Inverse mass [1/kg] and inverse rotational inertia [1/(kg·m²)] as the solver sees
    /// them (0 for bodies without a state).
    pub inv_mass: f32,
    pub inv_i: f32,
    /// World centre of mass [m].
    pub center: Vec2,
    /// Pose of the body origin at the start of the step.
    pub xf: crate::math::Transform,
    /// Velocity at the start of the step [m/s], [rad/s].
    pub v: Vec2,
    pub w: f32,
    /// Largest distance from the centre of mass to any of the body's shapes' points [m].
    pub max_extent: f32,
    /// Largest distance from the body origin to any of its shapes' points (bounded:
    /// `max_extent` + |local centre|) [m].
    pub reach: f32,
    /// The body's sleep timer [s]: when the entry was made, and after each step's finalize
    /// for a solved body (what the island pass reads, `World::update_sleep`, instead of
    /// the body's record).
    pub rest: f32,
}

const _: () = assert!(core::mem::size_of::<SolverBody>() == 64);

#[cfg(test)]
impl StepContext {
    /// Box2D's defaults at 60 Hz with 4 substeps, one thread (solver unit tests).
    pub(crate) fn for_tests() -> StepContext {
        StepContext {
            dt: 1.0 / 60.0,
            h: 1.0 / 240.0,
            inv_h: 240.0,
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            push_speed: 3.0,
            stick_speed: 0.01,
            max_linear_speed: 400.0,
            warm_starting: true,
            parallel: false,
        }
    }
}

/// Tunable numbers of the solver, fixed for one step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepContext {
    pub dt: f32,
    pub h: f32,
    pub inv_h: f32,
    pub substeps: u32,
    /// Contact frequency [Hz] used for the base softness (after clamping).
    pub contact_hertz: f32,
    pub contact_damping_ratio: f32,
    /// Largest speed at which overlap is pushed apart [m/s].
    pub push_speed: f32,
    /// Slip speed below which a sliding point sticks again [m/s].
    pub stick_speed: f32,
    /// Largest linear speed [m/s].
    pub max_linear_speed: f32,
    pub warm_starting: bool,
    /// The step runs inside the world's thread pool: split the work between its threads.
    pub parallel: bool,
}

/// Keeping the pool's other threads awake through the serial parts of a step.
///
/// Between two parallel stages a rayon worker with nothing to do goes to sleep, and on this
/// project's VM a sleeping worker starts a job spawned for it about 20 µs late (measured:
/// 1 400 spawns, seven parallel stages a step), while the spawning thread starts at once.
/// So during a step, after each parallel stage, the other threads are given a job that
/// spins (`hold`) until the next stage is posted (`release`; every spawning site runs its
/// scope through [`awake::stage`], which does both) or a millisecond has passed, as Box2D
/// v3's workers spin between its stages. The spinner changes nothing but who waits:
/// results do not depend on it.
pub(crate) mod awake {
    use core::sync::atomic::{AtomicU64, Ordering};
    use std::cell::RefCell;
    use std::sync::Arc;

    thread_local! {
        /// The epoch of the step this thread is running ([`Step`]), bumped whenever work
        /// is posted and when the step ends: a spinner returns when it moves. None outside
        /// a parallel step (then no spinner starts). Per step, not per process: worlds
        /// stepped side by side do not reach each other's spinners.
        static STEP_EPOCH: RefCell<Option<Arc<AtomicU64>>> = const { RefCell::new(None) };
    }

    /// The longest a spinner waits [µs]: a bound on the time a core is held for nothing.
    const LIMIT_US: u128 = 1000;

    /// Marks this thread as running a parallel step until dropped (which also stops the
    /// step's spinners).
    pub(crate) struct Step(Arc<AtomicU64>);

    impl Step {
        pub(crate) fn start() -> Step {
            let epoch = Arc::new(AtomicU64::new(0));
            STEP_EPOCH.with(|c| *c.borrow_mut() = Some(epoch.clone()));
            Step(epoch)
        }
    }

    impl Drop for Step {
        fn drop(&mut self) {
            STEP_EPOCH.with(|c| *c.borrow_mut() = None);
            self.0.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// Work is about to be posted: the step's running spinners return, so their threads
    /// take it.
    #[inline]
    fn release() {
        STEP_EPOCH.with(|c| {
            if let Some(epoch) = &*c.borrow() {
                epoch.fetch_add(1, Ordering::AcqRel);
            }
        });
    }

    /// Runs `stage` (one parallel stage of `threads` threads: a rayon scope) between
    /// [`release`] and [`hold`], as every spawning site must.
    #[inline]
    pub(crate) fn stage<R>(threads: usize, stage: impl FnOnce() -> R) -> R {
        release();
        let out = stage();
        hold(threads);
        out
    }

    /// After a parallel stage, inside a step: one spinner for each of the pool's other
    /// `threads − 1` threads. Each yields its core every 256 spins, so on a pool larger than
    /// the machine the stepping thread is not kept waiting for a core by spinners.
    fn hold(threads: usize) {
        let Some(epoch) = STEP_EPOCH.with(|c| c.borrow().clone()) else {
            return;
        };
        let at = epoch.load(Ordering::Acquire);
        for _ in 1..threads {
            let epoch = epoch.clone();
            rayon::spawn(move || {
                // A spinner found by the stepping thread itself (in a later wait) or late
                // finds the epoch moved on and returns at once.
                let start = std::time::Instant::now();
                let mut spins = 0u32;
                while epoch.load(Ordering::Acquire) == at {
                    core::hint::spin_loop();
                    spins = spins.wrapping_add(1);
                    if spins.is_multiple_of(256) {
                        if start.elapsed().as_micros() > LIMIT_US {
                            break;
                        }
                        // A thread that needs this core (the stepping thread on a pool
                        // larger than the machine, another process) gets it.
                        std::thread::yield_now();
                    }
                }
            });
        }
    }
}

/// Calls `f` on every item, in order on this thread, or when `parallel` on the pool's
/// threads. The items are cut into one share of consecutive items per thread (as rayon
/// splits a range: thread `k`'s share is the `k`-th part, so a stage that follows the
/// solver's body order touches mostly what the same thread touched in the stage before);
/// each thread claims its own share's items one at a time, then the next items of shares
/// whose threads have not got to them (one counter per share), as the solver's worker team
/// does and as Box2D v3's `b2ParallelFor` hands out blocks. This thread runs the other
/// threads' shares itself when they have not started by the time it is done (rayon's
/// scope runs its own pending jobs while it waits), so a thread that is late or loses its
/// core holds up the step only while it holds one item. Rayon's parallel iterators hand
/// out halves and quarters of the range instead, and a thread that lost its core after
/// taking one held the others for the rest of its time slice: on two threads beside
/// another busy process, large_pyramid's set-up, store and finalize took 2–3 × as long as
/// on one thread.
///
/// `f` must not depend on the order in which items run (each writes only what no other
/// writes), so the results are the same for any thread count.
pub(crate) fn claim_each<T: Send>(parallel: bool, items: impl IntoIterator<Item = T>, f: impl Fn(T) + Sync) {
    let threads = if parallel { rayon::current_num_threads() } else { 1 };
    if threads < 2 {
        items.into_iter().for_each(f);
        return;
    }
    let slots = claim_slots(items);
    let n = slots.len();
    let shares = threads.min(n);
    let ends: Vec<usize> = (0..shares).map(|k| (k + 1) * n / shares).collect();
    claim_shares(threads, slots, &ends, f);
}

/// [`claim_each`] on the pool's threads over `chunks`, each writing what it finds into a
/// list of its own, appended to `out` in chunk order (the same list whatever the thread
/// count, as one thread going through the chunks in order would make it); returns what
/// `f` returned for each chunk, in chunk order.
pub(crate) fn claim_into<C: Send, U: Send, R: Send + Default>(
    chunks: impl IntoIterator<Item = C>,
    out: &mut Vec<U>,
    f: impl Fn(C, &mut Vec<U>) -> R + Sync,
) -> Vec<R> {
    let chunks: Vec<C> = chunks.into_iter().collect();
    let mut found: Vec<(Vec<U>, R)> = chunks.iter().map(|_| (Vec::new(), R::default())).collect();
    claim_each(true, chunks.into_iter().zip(found.iter_mut()), |(chunk, (list, r))| {
        *r = f(chunk, list);
    });
    let mut results = Vec::with_capacity(found.len());
    for (list, r) in found {
        out.extend(list);
        results.push(r);
    }
    results
}

/// The items of a [`claim_each`] in their slots: each sits in its slot until one thread
/// takes it (each slot is locked once).
fn claim_slots<T>(items: impl IntoIterator<Item = T>) -> Vec<std::sync::Mutex<Option<T>>> {
    items.into_iter().map(|x| std::sync::Mutex::new(Some(x))).collect()
}

/// [`claim_each`] with each thread's share given: thread `k` claims the items of
/// `shares[k]` first (one share per thread, so a stage can hand each thread what that
/// thread touched in the stage before, when that is not a run of consecutive items).
pub(crate) fn claim_each_share<T: Send>(parallel: bool, shares: Vec<Vec<T>>, f: impl Fn(T) + Sync) {
    let threads = if parallel { rayon::current_num_threads() } else { 1 };
    if threads < 2 {
        shares.into_iter().flatten().for_each(f);
        return;
    }
    let mut slots = Vec::with_capacity(shares.iter().map(Vec::len).sum());
    let mut ends = Vec::with_capacity(shares.len());
    for share in shares.into_iter().take(threads) {
        slots.extend(claim_slots(share));
        ends.push(slots.len());
    }
    claim_shares(threads, slots, &ends, f);
}

/// Runs `f` on the items in `slots` on `threads` threads, share `k` being
/// `slots[ends[k−1] .. ends[k]]` (from 0 for the first), as [`claim_each`] describes.
fn claim_shares<T: Send>(
    threads: usize,
    slots: Vec<std::sync::Mutex<Option<T>>>,
    ends: &[usize],
    f: impl Fn(T) + Sync,
) {
    use core::sync::atomic::{AtomicUsize, Ordering::Relaxed};
    let shares = ends.len();
    if shares < 2 || slots.len() < 2 {
        // One item (or none): this thread alone, without waking another.
        for slot in slots {
            if let Some(x) = slot.into_inner().unwrap_or_else(|e| e.into_inner()) {
                f(x);
            }
        }
        return;
    }
    let start = |k: usize| {
        if k == 0 {
            0
        } else {
            ends.get(k - 1).copied().unwrap_or(0)
        }
    };
    let end = |k: usize| ends.get(k).copied().unwrap_or(0);
    // The next unclaimed item of each share, each counter on its own cache lines (side by
    // side, every claim by one thread would take the line from the other).
    #[repr(align(128))]
    struct Cursor(AtomicUsize);
    let next: Vec<Cursor> = (0..shares).map(|k| Cursor(AtomicUsize::new(start(k)))).collect();
    let work = |k: usize| {
        for j in 0..shares {
            let share = (k + j) % shares;
            let Some(Cursor(cursor)) = next.get(share) else {
                continue;
            };
            loop {
                let i = cursor.fetch_add(1, Relaxed);
                if i >= end(share) {
                    break;
                }
                let item = slots
                    .get(i)
                    .and_then(|slot| slot.lock().unwrap_or_else(|e| e.into_inner()).take());
                if let Some(x) = item {
                    f(x);
                }
            }
        }
    };
    awake::stage(threads, || {
        rayon::scope(|s| {
            let work = &work;
            for k in 1..shares {
                s.spawn(move |_| work(k));
            }
            work(0);
        })
    });
}

/// Calls `f(i, &mut items[i])` for every item, split between the pool's threads when
/// `parallel` (chunks of `min_len` items, see [`claim_each`]), else in order on this
/// thread. `f` must not depend on the order (each item only writes itself and what no
/// other item writes).
pub(crate) fn for_each_mut<T: Send>(parallel: bool, items: &mut [T], min_len: usize, f: impl Fn(usize, &mut T) + Sync) {
    let n = min_len.max(1);
    claim_each(parallel, items.chunks_mut(n).enumerate(), |(k, chunk)| {
        for (j, x) in chunk.iter_mut().enumerate() {
            f(k * n + j, x);
        }
    });
}

/// Calls `f(i, &mut a[i], &mut b[i])` for every index of both, split between the pool's
/// threads when `parallel` (see [`for_each_mut`]).
pub(crate) fn for_each_mut2<A: Send, B: Send>(
    parallel: bool,
    a: &mut [A],
    b: &mut [B],
    min_len: usize,
    f: impl Fn(usize, &mut A, &mut B) + Sync,
) {
    let n = min_len.max(1);
    let chunks = a.chunks_mut(n).zip(b.chunks_mut(n)).enumerate();
    claim_each(parallel, chunks, |(k, (xs, ys))| {
        for (j, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
            f(k * n + j, x, y);
        }
    });
}

/// Mutable slices cut together into chunks ([`for_each_chunk_mut`]): a tuple of
/// `&mut [T]`, of three to six element types.
pub(crate) trait SliceTuple: Sized + Send {
    /// The shortest slice's length (the slices are meant to have one length).
    fn len(&self) -> usize;
    /// Each slice cut at `at` (at most its length): the parts before and from it.
    fn split_at(self, at: usize) -> (Self, Self);
}

macro_rules! slice_tuple {
    ($($t:ident $v:ident),+) => {
        impl<'a, $($t: Send),+> SliceTuple for ($(&'a mut [$t],)+) {
            fn len(&self) -> usize {
                let ($($v,)+) = self;
                let mut n = usize::MAX;
                $(n = n.min($v.len());)+
                n
            }
            fn split_at(self, at: usize) -> (Self, Self) {
                let ($($v,)+) = self;
                $(let $v = $v.split_at_mut(at.min($v.len()));)+
                (($($v.0,)+), ($($v.1,)+))
            }
        }
    };
}
slice_tuple!(A a, B b, C c);
slice_tuple!(A a, B b, C c, D d);
slice_tuple!(A a, B b, C c, D d, E e);
slice_tuple!(A a, B b, C c, D d, E e, F f);

/// [`for_each_mut`] over a tuple of slices by chunks of `min_len`: `f(first, chunks)` gets
/// a chunk of each slice (its first element at index `first`), so it can look ahead inside
/// the chunk. One chunk on one thread; on threads, thread `k` claims the `k`-th run of
/// chunks first, as [`claim_each`] shares them out.
pub(crate) fn for_each_chunk_mut<S: SliceTuple>(
    parallel: bool,
    slices: S,
    min_len: usize,
    f: impl Fn(usize, S) + Sync,
) {
    if !parallel {
        f(0, slices);
        return;
    }
    let n = min_len.max(1);
    let chunks = slices.len().div_ceil(n);
    let shares = rayon::current_num_threads().min(chunks).max(1);
    let owners: Vec<(usize, usize)> = (0..shares).map(|k| (k * chunks / shares * n, k)).collect();
    for_each_chunk_mut_owned(slices, &owners, n, f);
}

/// [`for_each_chunk_mut`] on threads, with each thread's share given: `owners` lists
/// where each thread's part of the slices starts (ascending starts, each with its thread;
/// the first from 0), and each part is cut into chunks of at most `min_len` that its
/// thread claims first ([`claim_each_share`]). The slices have one length; without
/// owners, the first thread's share is all of them.
pub(crate) fn for_each_chunk_mut_owned<S: SliceTuple>(
    slices: S,
    owners: &[(usize, usize)],
    min_len: usize,
    f: impl Fn(usize, S) + Sync,
) {
    let threads = rayon::current_num_threads();
    let n = min_len.max(1);
    let len = slices.len();
    let mut rest = slices;
    let mut shares: Vec<Vec<_>> = (0..threads).map(|_| Vec::new()).collect();
    let mut at = 0usize;
    let owners = if owners.is_empty() { &[(0, 0)][..] } else { owners };
    for (i, &(_, k)) in owners.iter().enumerate() {
        let end = owners.get(i + 1).map_or(len, |o| o.0.min(len));
        while at < end {
            let m = (end - at).min(n);
            let (chunk, after) = rest.split_at(m);
            rest = after;
            if let Some(share) = shares.get_mut(k.min(threads - 1)) {
                share.push((at, chunk));
            }
            at += m;
        }
    }
    claim_each_share(true, shares, |(first, chunk)| f(first, chunk));
}

/// A family of constraints solved by the step (contacts now; joints later). The set is
/// built before the step's stages run.
pub(crate) trait ConstraintSet {
    /// Whether any constraint has points new this step that carry a load worth estimating
    /// (none when no body is loaded, see [`any_load`]).
    fn has_new_contacts(&self) -> bool;
    /// Estimates warm-start impulses for constraints that begin at rest (no history):
    /// rigid iterations against trial states, those of `states` after one substep of
    /// forces, made in `trial` (as long as `states`; only the entries of the bodies of new
    /// constraints are made and read, the others are left as they were). Returns whether
    /// any constraint was estimated. The trial velocities are thrown away.
    fn estimate_new_contacts<C: StateCell, T: StateCell>(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[C],
        trial: &[T],
    ) -> bool;
    /// Re-applies the accumulated impulses at the start of a substep. `carried`: the
    /// constraints that carry their warm start ([`ConstraintSet::carries_warm_start`])
    /// skip theirs, which the last relax pass added to the carry and the velocities'
    /// integration to the states.
    fn warm_start<C: StateCell>(&mut self, ctx: &StepContext, states: &[C], carried: bool);
    /// One sequential-impulse pass; `use_bias` adds the soft position correction. With
    /// `carry` (a relax pass followed by another substep, when the set carries its warm
    /// start), each constraint that carries its warm start adds the impulse the next
    /// warm start would apply to its bodies' entries in `carry`.
    fn solve<C: StateCell>(
        &mut self,
        ctx: &StepContext,
        states: &[C],
        use_bias: bool,
        elapsed: f32,
        carry: Option<&[C]>,
    );
    /// Whether this step's constraints (some of them) carry their warm start from each
    /// relax pass to the next substep's velocities (see [`solve_step`]).
    fn carries_warm_start(&self) -> bool {
        false
    }
    /// Accumulates what a substep applied (after its relax pass).
    fn end_substep(&mut self);
    /// Restitution pass after all substeps.
    fn restitution<C: StateCell>(&mut self, states: &[C]);
    /// Runs the whole substep loop with a team of worker threads that stay awake between
    /// stages (one job per step instead of one per colour and pass), when the set supports
    /// it for this step; returns false (having done nothing) otherwise. `times` receives the
    /// stage times of [`solve_step`]'s loop as measured by the first thread.
    fn substeps_team(
        &mut self,
        _ctx: &StepContext,
        _sims: &[BodySim],
        _states: &[SharedState],
        _carry: &[SharedState],
        _times: &mut [f32; 5],
    ) -> bool {
        false
    }
}

/// The constraints of a step: joints, then contacts (of any build of the wide solver),
/// in every pass.
pub(crate) struct StepConstraints<'a, C> {
    pub joints: &'a mut joint_solver::JointSolver,
    pub contacts: &'a mut C,
}

impl<K: ConstraintSet> ConstraintSet for StepConstraints<'_, K> {
    fn has_new_contacts(&self) -> bool {
        self.contacts.has_new_contacts()
    }
    fn estimate_new_contacts<C: StateCell, T: StateCell>(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[C],
        trial: &[T],
    ) -> bool {
        self.contacts.estimate_new_contacts(ctx, sims, states, trial)
    }
    fn warm_start<C: StateCell>(&mut self, ctx: &StepContext, states: &[C], carried: bool) {
        self.joints.warm_start(states, ctx);
        self.contacts.warm_start(ctx, states, carried);
    }
    fn solve<C: StateCell>(
        &mut self,
        ctx: &StepContext,
        states: &[C],
        use_bias: bool,
        elapsed: f32,
        carry: Option<&[C]>,
    ) {
        self.joints.solve(states, ctx, use_bias);
        self.contacts.solve(ctx, states, use_bias, elapsed, carry);
    }
    fn carries_warm_start(&self) -> bool {
        self.contacts.carries_warm_start()
    }
    fn end_substep(&mut self) {
        self.contacts.end_substep();
    }
    fn restitution<C: StateCell>(&mut self, states: &[C]) {
        self.contacts.restitution(states);
    }
    fn substeps_team(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[SharedState],
        carry: &[SharedState],
        times: &mut [f32; 5],
    ) -> bool {
        // The team solves contact colours only; joints run before each pass's colours
        // (their block colours shared between threads), which the per-colour path does.
        self.joints.constraints.is_empty() && self.contacts.substeps_team(ctx, sims, states, carry, times)
    }
}

/// The step's contact constraints in one build of the wide solver ([`lanes4`] or
/// [`lanes8`]): what the world does with them besides the passes of [`ConstraintSet`].
pub(crate) trait WideContacts: ConstraintSet {
    /// Builds the step's constraints from `candidates` (see `ContactSolver::build`); `up`
    /// is the unit vector against gravity (zero without).
    fn build_step<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        sims: &[BodySim],
        candidates: candidates::Candidates<'_>,
        loaded: bool,
        up: Vec2,
    );
    /// Stores the step's impulses and friction states into `contacts`, and the reported
    /// sums into `sums` (one per contact slot; see `ContactSolver::store`).
    fn store_step<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        contacts: &mut [Option<Contact>],
        sums: &mut [ContactSums],
    );
    /// The step's layout: its wide groups and its colours.
    fn layout_size(&self) -> (usize, usize);
}

/// The contact constraints of the world, in the build of the wide solver it runs: on an
/// x86-64 CPU with AVX2 eight lanes ([`lanes8_avx512`] if it also has AVX-512F/VL and is
/// of Ice Lake's generation or later, see `avx512_build_pays`, else [`lanes8`]) unless the world asks for another ([`crate::SolverLanes`]),
/// else four ([`lanes4`], SSE2 on x86-64). All give the same results to the bit (every lane
/// computes the same expressions; see [`crate::solver_lanes`]).
pub(crate) enum Contacts {
    Four(lanes4::contact_set::ContactSolver),
    #[cfg(target_arch = "x86_64")]
    Eight(lanes8::contact_set::ContactSolver),
    #[cfg(target_arch = "x86_64")]
    EightAvx512(lanes8_avx512::contact_set::ContactSolver),
}

impl Default for Contacts {
    fn default() -> Contacts {
        Contacts::Four(Default::default())
    }
}

/// Whether `SolverLanes::Auto` takes the AVX-512 build ([`lanes8_avx512`]) on this CPU: it
/// has AVX-512F and AVX-512VL (what the build is compiled for), FMA and F16C (which the
/// compiler takes AVX-512F to imply), and AVX-512 VBMI2, the mark of the cores from Ice
/// Lake and Zen 4 on. The compiler still writes some copies and loops of that build with
/// 512-bit registers, and the cores before Ice Lake (Skylake-SP, Cascade Lake) lower their
/// clock for 512-bit instructions: there the AVX2 build is taken.
#[cfg(target_arch = "x86_64")]
fn avx512_build_pays() -> bool {
    std::is_x86_feature_detected!("avx512f")
        && std::is_x86_feature_detected!("avx512vl")
        && std::is_x86_feature_detected!("fma")
        && std::is_x86_feature_detected!("f16c")
        && std::is_x86_feature_detected!("avx512vbmi2")
}

/// `$body` with `$s` the world's contact solver of any build (`$c`: a [`Contacts`]).
macro_rules! with_contacts {
    ($c:expr, $s:ident => $body:expr) => {
        match $c {
            $crate::solver::Contacts::Four($s) => $body,
            #[cfg(target_arch = "x86_64")]
            $crate::solver::Contacts::Eight($s) => $body,
            #[cfg(target_arch = "x86_64")]
            $crate::solver::Contacts::EightAvx512($s) => $body,
        }
    };
}
pub(crate) use with_contacts;

impl Contacts {
    /// The solver a world with `lanes` takes on this CPU.
    pub fn new(lanes: crate::SolverLanes) -> Contacts {
        #[cfg(target_arch = "x86_64")]
        if lanes != crate::SolverLanes::Four && std::is_x86_feature_detected!("avx2") {
            if lanes == crate::SolverLanes::Auto && avx512_build_pays() {
                // The only place an AVX-512 solver is made: its passes are compiled for
                // AVX-512F/VL (see `lanes8_avx512`).
                return Contacts::EightAvx512(Default::default());
            }
            // The only place an eight-lane AVX2 solver is made: its passes are compiled for
            // AVX2 (see `lanes8`).
            return Contacts::Eight(Default::default());
        }
        let _ = lanes;
        Contacts::Four(Default::default())
    }

    /// Constraints per wide group: 4 or 8.
    pub fn lanes(&self) -> usize {
        match self {
            Contacts::Four(_) => lanes4::wide::LANES,
            #[cfg(target_arch = "x86_64")]
            Contacts::Eight(_) | Contacts::EightAvx512(_) => lanes8::wide::LANES,
        }
    }

    /// The instructions the build is compiled for: "AVX-512VL" (with AVX2), "AVX2", "SSE2"
    /// (the x86-64 baseline), or "portable" (arrays, on other targets).
    pub fn instructions(&self) -> &'static str {
        match self {
            Contacts::Four(_) if cfg!(target_arch = "x86_64") => "SSE2",
            Contacts::Four(_) => "portable",
            #[cfg(target_arch = "x86_64")]
            Contacts::Eight(_) => "AVX2",
            #[cfg(target_arch = "x86_64")]
            Contacts::EightAvx512(_) => "AVX-512VL",
        }
    }

    /// The number of layouts made so far (`ContactSolver::layouts`).
    pub fn layouts(&self) -> u64 {
        with_contacts!(self, s => s.layouts)
    }

    /// The contacts in solved order (`ContactSolver::solved_order`).
    pub fn solved_order(&self, out: &mut Vec<u32>) -> usize {
        with_contacts!(self, s => s.solved_order(out))
    }
}

/// Runs the stages of one step over the awake bodies and a constraint set, timing each
/// stage into `profile`.
///
/// `carry` (one entry per state, all zero on entry and left so) carries the warm start
/// from each relax pass to the next substep when the set allows it
/// ([`ConstraintSet::carries_warm_start`]): a warm start applies each constraint's
/// accumulated impulses, which the relax pass before it has just set, with the same arms
/// (the bodies do not move between the two; the velocities' integration between them
/// only adds forces), so the relax pass adds each constraint's next warm-start impulse to
/// its bodies' carry entries as it finishes the constraint, and the velocities'
/// integration adds the carry to each body and clears it. The warm start that follows
/// then has only the constraints that do not carry theirs left (joints, overflow). The
/// same sums of the same impulses, rounded in another order: a pass over every group a
/// substep less (large_pyramid's groups are megabytes).
pub(crate) fn solve_step<S: StateCell, C: ConstraintSet>(
    ctx: &StepContext,
    sims: &[BodySim],
    states: &[S],
    carry: &[S],
    trial: &mut Vec<BodyState>,
    constraints: &mut C,
    profile: &mut Profile,
) {
    let mut lap = Stopwatch::start();
    // A contact that begins at rest has no warm start: its first substeps would let the
    // body sag and slide before the load builds up (the settling creep of Box2D and
    // Rapier). Estimate its impulses first on scratch states (`trial`, kept between
    // steps: only the new constraints' bodies are made and read, not a copy of every
    // state made and integrated, which cost the tumbler, a pile in motion with ~140 new
    // contacts a step, 6 µs of its 1.45 ms).
    if constraints.has_new_contacts() {
        trial.resize(states.len(), BodyState::default());
        let trial = core::cell::Cell::from_mut(&mut trial[..]).as_slice_of_cells();
        constraints.estimate_new_contacts(ctx, sims, states, trial);
    }
    profile.prepare = lap.lap();
    let mut t = [0.0f32; 5];
    let team = S::as_shared(states).is_some_and(|shared| {
        S::as_shared(carry).is_some_and(|carry| constraints.substeps_team(ctx, sims, shared, carry, &mut t))
    });
    if team {
        lap.lap();
    }
    let carries = constraints.carries_warm_start() && carry.len() >= states.len();
    for i in 0..if team { 0 } else { ctx.substeps } {
        let carried = carries && i > 0;
        integrate_velocities(ctx, sims, states, carried.then_some(carry));
        t[0] += lap.lap();
        // Always called: it also records approach speeds (impulses are zero when warm
        // starting is off).
        constraints.warm_start(ctx, states, carried);
        t[1] += lap.lap();
        let elapsed = i as f32 * ctx.h;
        constraints.solve(ctx, states, true, elapsed, None);
        t[2] += lap.lap();
        integrate_positions(ctx, sims, states);
        t[3] += lap.lap();
        let into = (carries && i + 1 < ctx.substeps).then_some(carry);
        constraints.solve(ctx, states, false, elapsed + ctx.h, into);
        constraints.end_substep();
        t[4] += lap.lap();
    }
    [
        profile.integrate_velocities,
        profile.warm_start,
        profile.solve,
        profile.integrate_positions,
        profile.relax,
    ] = t;
    constraints.restitution(states);
    profile.restitution = lap.lap();
}

/// Whether gravity or an applied force or torque acts on any awake body. Without, there
/// is no static load to carry through the contacts (the impacts of a zero-gravity scene
/// are the solver's ordinary work), so the helpers for carrying loads — the estimate of
/// new resting contacts and the extra sweeps of light bodies under heavy ones — are off.
pub(crate) fn any_load(sims: &[BodySim]) -> bool {
    sims.iter().any(loads)
}

/// Whether gravity or an applied force or torque acts on a body (see [`any_load`]).
#[inline]
pub(crate) fn loads(s: &BodySim) -> bool {
    s.linear_accel != Vec2::ZERO || s.angular_accel != 0.0
}

/// Bodies per parallel chunk of the integration stages.
const BODY_CHUNK: usize = 512;

/// v ← (v + h·a) / (1 + h·c): explicit forces, Padé damping (Box2D v3); then, with
/// `carry`, the warm start carried from the last relax pass (see [`solve_step`]).
fn integrate_velocities<S: StateCell>(ctx: &StepContext, sims: &[BodySim], states: &[S], carry: Option<&[S]>) {
    let h = ctx.h;
    // Index 0 is the shared static body: it never moves.
    S::for_each_index(
        states,
        carry.unwrap_or(&[]),
        sims.len(),
        BODY_CHUNK,
        |k, states, carry| {
            if k == 0 {
                return;
            }
            if let (Some(sim), Some(state)) = (sims.get(k), states.get(k)) {
                integrate_velocity_one(h, sim, state, carry.get(k));
            }
        },
    );
}

/// [`integrate_velocities`] for one body: with `carry`, the velocity carried from the
/// last relax pass is added and the carry cleared.
#[inline]
pub(crate) fn integrate_velocity_one<S: StateCell>(h: f32, sim: &BodySim, state: &S, carry: Option<&S>) {
    let s = state.get();
    let lin = 1.0 / (1.0 + h * sim.linear_damping);
    let ang = 1.0 / (1.0 + h * sim.angular_damping);
    let mut v = (s.v + h * sim.linear_accel) * lin;
    let mut w = (s.w + h * sim.angular_accel) * ang;
    if let Some(c) = carry {
        let k = c.get();
        v += k.v;
        w += k.w;
        c.set_velocity(Vec2::ZERO, 0.0, 0.0);
    }
    state.set_velocity(v, w, 0.0);
}

/// Accumulates Δp += h·v and Δq ← Δq advanced by h·ω, with speed limits.
///
/// A body no contact pushed in this substep moves ballistically: Δp += h·(v − ½·h·a),
/// the exact displacement under the constant acceleration a of gravity and applied forces
/// (plain symplectic Euler overshoots by ½h²a per substep, which makes a dropped ball hit
/// slower and bounce lower than e²h by about (1 + 1/e)·g·h/v).
fn integrate_positions<S: StateCell>(ctx: &StepContext, sims: &[BodySim], states: &[S]) {
    // Index 0 is the shared static body: it never moves. Blocks of four bodies.
    let n = sims.len();
    S::for_each_index(
        states,
        &[],
        n.div_ceil(wide::LANES4),
        BODY_CHUNK / wide::LANES4,
        |q, states, _| {
            let first = q * wide::LANES4;
            integrate_positions_range(ctx, sims, states, first.max(1)..(first + wide::LANES4).min(n));
        },
    );
}

/// [`integrate_position_one`] for the bodies of `range`, four at a time where it can: the
/// same expressions, but each rotation's normalisation (a square root and a division, the
/// slowest instructions of the pass: with one body at a time they were most of its time)
/// done for four bodies by one vector square root and one vector division, which round
/// each lane exactly as the scalar ones do.
pub(crate) fn integrate_positions_range<S: StateCell>(
    ctx: &StepContext,
    sims: &[BodySim],
    states: &[S],
    range: core::ops::Range<usize>,
) {
    let h = ctx.h;
    let max_w = max_angular_speed(ctx);
    let mut k = range.start;
    while k + wide::LANES4 <= range.end {
        let (Some(block), Some(block_sims)) = (states.get(k..k + wide::LANES4), sims.get(k..k + wide::LANES4)) else {
            break;
        };
        // The rotation after the turn of the substep, before it is normalised
        // (`Rot::integrate`), from each body's clamped angular velocity.
        let turned: [(f32, f32); wide::LANES4] = core::array::from_fn(|l| {
            let s = block[l].get();
            let da = h * s.w.clamp(-max_w, max_w);
            (s.dq.c - da * s.dq.s, s.dq.s + da * s.dq.c)
        });
        let (c, sn) = (wide::F4::new(turned.map(|t| t.0)), wide::F4::new(turned.map(|t| t.1)));
        let mag = (c * c + sn * sn).sqrt();
        let zero = wide::F4::ZERO;
        let inv = mag.gt(zero).select(wide::F4::splat(1.0) / mag, zero);
        let (qc, qs) = (c * inv, sn * inv);
        for (l, (state, sim)) in block.iter().zip(block_sims).enumerate() {
            let mut s = integrate_translation(ctx, sim, state.get());
            s.dq = crate::math::Rot { c: qc[l], s: qs[l] };
            state.set(s);
        }
        k += wide::LANES4;
    }
    for b in k..range.end {
        if let (Some(sim), Some(state)) = (sims.get(b), states.get(b)) {
            integrate_position_one(ctx, sim, state);
        }
    }
}

/// The largest angular speed [rad/s] a body integrates with: a rotation per substep of at
/// most 0.25π per full step, as in Box2D, so the first-order rotation update stays
/// accurate.
#[inline(always)]
fn max_angular_speed(ctx: &StepContext) -> f32 {
    0.25 * core::f32::consts::PI / ctx.dt
}

/// What [`integrate_position_one`] does but the rotation: the speed limits and Δp.
#[inline(always)]
fn integrate_translation(ctx: &StepContext, sim: &BodySim, mut s: BodyState) -> BodyState {
    let h = ctx.h;
    let max_w = max_angular_speed(ctx);
    let max_v2 = ctx.max_linear_speed * ctx.max_linear_speed;
    if s.v.length_squared() > max_v2 {
        s.v = s.v * (ctx.max_linear_speed / s.v.length());
    }
    s.w = s.w.clamp(-max_w, max_w);
    let ballistic = s.touched == 0.0 && sim.linear_damping == 0.0;
    s.dp += if ballistic {
        h * (s.v - (0.5 * h) * sim.linear_accel)
    } else {
        h * s.v
    };
    s
}

/// [`integrate_positions`] for one body.
#[inline]
pub(crate) fn integrate_position_one<S: StateCell>(ctx: &StepContext, sim: &BodySim, state: &S) {
    // `integrate_translation` clamps ω to `max_angular_speed`.
    let mut s = integrate_translation(ctx, sim, state.get());
    s.dq = s.dq.integrate(ctx.h * s.w);
    state.set(s);
}

#[cfg(test)]
mod claim_tests {
    use super::{claim_each, for_each_chunk_mut, for_each_chunk_mut_owned};
    use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

    /// Every item runs exactly once, on two threads as on one, for counts below, at and
    /// above the thread count (a shared counter per share: an item claimed twice would
    /// count 2, one skipped 0).
    #[test]
    fn every_item_runs_once_on_any_thread_count() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
        for n in [0usize, 1, 2, 3, 17, 1000] {
            for parallel in [false, true] {
                let runs: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(0)).collect();
                pool.install(|| claim_each(parallel, 0..n, |i| _ = runs[i].fetch_add(1, Relaxed)));
                assert!(
                    runs.iter().all(|r| r.load(Relaxed) == 1),
                    "n = {n}, parallel = {parallel}"
                );
            }
        }
    }

    /// The chunked form hands each chunk its own first index: every element is written with
    /// its own index, once, whatever thread wrote it.
    #[test]
    fn chunks_know_their_first_index() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
        let (mut a, mut b, mut c, mut d) = (vec![0usize; 1001], vec![0u8; 1001], vec![0u8; 1001], vec![0u8; 1001]);
        pool.install(|| {
            let slices = (&mut a[..], &mut b[..], &mut c[..], &mut d[..]);
            for_each_chunk_mut(true, slices, 32, |first, (ws, xs, ys, zs)| {
                let rows = ws.iter_mut().zip(xs.iter_mut()).zip(ys.iter_mut()).zip(zs.iter_mut());
                for (k, (((w, x), y), z)) in rows.enumerate() {
                    *w = first + k;
                    *x += 1;
                    *y += 1;
                    *z += 1;
                }
            })
        });
        assert!(a.iter().enumerate().all(|(i, &x)| x == i));
        assert!(b.iter().chain(&c).chain(&d).all(|&y| y == 1));
    }

    /// The form with owners given cuts every share into chunks of at most the chunk length
    /// that never cross a share's start, and still writes every element once with its own
    /// index (shares whose starts are off the chunk grid included).
    #[test]
    fn owned_chunks_stay_inside_their_shares() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
        let n = 1001;
        let owners = [(0usize, 1usize), (96, 0), (300, 1), (301, 0), (900, 1)];
        let (mut a, mut b, mut c, mut d) = (vec![0usize; n], vec![0u8; n], vec![0u8; n], vec![0u8; n]);
        let chunks = std::sync::Mutex::new(Vec::new());
        pool.install(|| {
            for_each_chunk_mut_owned(
                (&mut a[..], &mut b[..], &mut c[..], &mut d[..]),
                &owners,
                32,
                |first, (ws, xs, ys, zs)| {
                    chunks.lock().expect("chunk list").push((first, ws.len()));
                    let rows = ws.iter_mut().zip(xs.iter_mut()).zip(ys.iter_mut()).zip(zs.iter_mut());
                    for (k, (((w, x), y), z)) in rows.enumerate() {
                        *w = first + k;
                        *x += 1;
                        *y += 1;
                        *z += 1;
                    }
                },
            )
        });
        assert!(a.iter().enumerate().all(|(i, &x)| x == i));
        assert!(b.iter().chain(&c).chain(&d).all(|&y| y == 1));
        let chunks = chunks.into_inner().expect("chunk list");
        for (first, len) in chunks {
            assert!((1..=32).contains(&len), "chunk at {first} of {len}");
            let crosses = owners.iter().any(|&(at, _)| first < at && at < first + len);
            assert!(!crosses, "chunk {first}..{} crosses a share's start", first + len);
        }
    }

    /// Inside a step, every stage leaves a spinner on the pool's other thread
    /// (`awake::hold`); the next stage must still hand out every item exactly once, after
    /// serial gaps shorter and longer than nothing, and the step must end (a spinner that
    /// never gave way would leave the scope to run here alone, but one that never returned
    /// would hang this test).
    #[test]
    fn stages_between_spinners_run_every_item_once() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
        let runs: Vec<AtomicU32> = (0..500).map(|_| AtomicU32::new(0)).collect();
        pool.install(|| {
            let _step = super::awake::Step::start();
            for stage in 0..40u32 {
                // A serial gap of 0–390 µs between stages.
                let gap = std::time::Instant::now();
                while gap.elapsed().as_micros() < u128::from(stage * 10) {
                    core::hint::spin_loop();
                }
                claim_each(true, 0..runs.len(), |i| _ = runs[i].fetch_add(1, Relaxed));
            }
        });
        assert!(runs.iter().all(|r| r.load(Relaxed) == 40));
    }
}
