//! The contact constraints of one step, arranged for the solver stages: graph colouring,
//! wide packing, overflow, mass-ratio groups, and the [`ConstraintSet`] stages over them.
//!
//! Build (once per step, from the touching contacts in contact order):
//! 1. colour every constraint (from its [`ColourKey`]): the colour it had last step while
//!    that is still free (so a pile keeps its layout from step to step, as Box2D v3's
//!    persistent graph colours do), else greedy first fit on per-body colour masks:
//!    moving pairs take the lowest free colour, pairs with a static or kinematic side the
//!    highest, so each pass solves them last, as Box2D v3's `constraint_graph.c` does; no
//!    free colour → overflow;
//! 2. lay the colours out as runs of groups of four lanes (six arrays by use:
//!    [`WideHead`], [`WideArms`], [`WideRare`], [`WideContact`], [`WideCold`],
//!    [`WideDerived`]); inside a colour, face contacts whose two points both carried load
//!    go first (they will most likely take the 2×2 block's fast path together);
//! 3. build the groups four lanes at a time ([`contact_wide::build_group`]), or keep a
//!    constraint whole in the overflow list ([`build_constraint`]).
//!
//! Steps 1 and 2 are skipped when the candidates are last step's, unchanged
//! ([`ContactSolver::same_layout`]): a resting pile keeps its colours and layout.
//!
//! Store (after the substeps): each group computes what its lanes write into their
//! contacts ([`contact_wide::store_group`]) and writes it (with threads: each thread
//! the contacts of its own range, see [`ContactSolver::store`]).
//!
//! The physics of a lane and of a scalar constraint are the same ([`contact_wide`] docs);
//! the scalar code still runs wherever it is simpler: overflow, the warm-start estimate of
//! new contacts, the extra sweeps of light bodies under heavy ones and restitution (each
//! rebuilds what it needs of a lane with [`contact_wide::unpack_full`] and writes the
//! lane's state back).
//!
//! With several threads and enough groups per colour (`World::solve_with`), the substeps
//! run as one job on every thread ([`team_loop`]): fixed shares of every colour, spin
//! barriers between colours and stages.
//!
//! [`team_loop`]: ContactSolver::team_loop

use super::contact_wide::{
    self, StoredContact, WideArms, WideCold, WideContact, WideDerived, WideHead, WideRare, COLORS, DYNAMIC_COLORS,
};
use super::wide::{array_of, LANES};
use crate::collision::contact::{Contact, ContactSums, NO_COLOUR};
use crate::math::Vec2;
use crate::solver::candidates::{
    mass_ratio, Candidate, Candidates, ColourKey, COLOUR_FLAGS, FAST, FRESH, KEY_DYNAMIC_A, KEY_DYNAMIC_B, KEY_RATIO,
    KEY_RESTITUTION, ORDER_FLAGS, SINGLE,
};
use crate::solver::contact_solver::{
    build_constraint, end_substep_one, estimate, is_new_resting, record_approach, restitution_one, solve_one,
    store_impulses, warm_start_one, ContactConstraint, StepSoftness, MAX_ESTIMATE_SWEEPS, MAX_LOCAL_SWEEPS,
    ONGOING_ESTIMATE_SWEEPS,
};
use crate::solver::{
    any_load, claim_each, claim_each_share, for_each_chunk_mut, integrate_positions_range, integrate_velocity_one,
    BodySim, ConstraintSet, SharedState, SliceTuple, StateCell, StateRead, StepContext, TeamProgress,
};
use crate::world::Stopwatch;

/// Where a constraint lives during the substeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// Lane `lane` of `wide[group]`.
    Wide { group: u32, lane: u8 },
    /// `overflow[index]`.
    Overflow(u32),
}

/// A light body's constraints, solved again ⌈M/m⌉ times per relax pass.
struct Group {
    members: Vec<(Slot, ContactConstraint)>,
    sweeps: u32,
}

/// All contact constraints of a step (see the module docs).
#[derive(Default)]
pub(crate) struct ContactSolver {
    /// Unit vector against gravity (zero without gravity).
    pub up: Vec2,
    /// The contact softnesses of the step (the lanes pick theirs in the solve).
    soft: StepSoftness,
    /// What every pass reads of each group (parallel to `wide`).
    head: Vec<WideHead>,
    wide: Vec<WideContact>,
    cold: Vec<WideCold>,
    /// Per group: what the passes read ready-made ([`contact_wide::WideDerived::new`]).
    derived: Vec<WideDerived>,
    /// Per group: its points' anchors (what the warm start, restitution and the store read).
    arms: Vec<WideArms>,
    /// Per group: what only groups with restitution, rolling resistance or a surface speed
    /// use ([`WideRare`]).
    rare: Vec<WideRare>,
    /// Constraints that found no colour, whole (solved first in each pass).
    overflow: Vec<ContactConstraint>,
    /// Constraints whose points are all new this step and touching (those the warm-start
    /// estimate may take).
    fresh: Vec<Slot>,
    /// Gravity or a force acts on some body this step ([`crate::solver::any_load`]): the helpers
    /// for carrying loads (estimate, mass-ratio groups) run only then.
    loaded: bool,
    /// Some coloured constraint has restitution (else the restitution pass skips the
    /// groups: reading each group's flag streamed a cache line per group, ~0.2 ms of
    /// many_pyramids' step, which has none).
    any_restitution: bool,
    groups: Vec<Group>,
    /// `wide[ranges[k].0 .. ranges[k].1]`: the groups of the k-th non-empty colour.
    ranges: Vec<(u32, u32)>,
    /// Per entry of `ranges`: the colour's first group of constraints not taken to its
    /// front by [`fast_first`] (a group holding both kinds counts with the front).
    ///
    /// [`fast_first`]: crate::solver::candidates::fast_first
    slow_start: Vec<u32>,
    /// Per entry of `ranges`: the colour's first group of [`SINGLE`] constraints, its back
    /// part (a group holding both kinds counts with the part before).
    single_start: Vec<u32>,
    /// The colour of each group (stored into its contacts, tried first next step).
    group_colour: Vec<u8>,
    /// Candidate index of each lane of each group (`u32::MAX`: empty lane).
    pub(crate) lane_candidates: Vec<[u32; LANES]>,
    /// The contact of each candidate ([`ContactSolver::solved_order`] reads these 4 bytes,
    /// not the candidates' records).
    contact_of: Vec<u32>,
    /// Last step's candidates' keys as the colouring left them (parallel to `contact_of`):
    /// with the colour each was given and without [`FAST`] ([`ContactSolver::same_layout`]).
    last_keys: Vec<ColourKey>,
    /// Last step's layout had no overflow (only then may the next step keep it).
    pub(crate) layout_kept: bool,
    /// Steps that kept the last step's layout (for tests and diagnostics).
    pub(crate) kept_layouts: u64,
    /// Lanes the last store wrote after its runs, on one thread (their contacts lay outside
    /// their run's range; for tests and diagnostics).
    pub(crate) stored_after: usize,
    /// Runs the last store was cut into (for tests and diagnostics).
    pub(crate) store_runs: usize,
    /// Steps whose substeps the worker team ran ([`ContactSolver::team_loop`]; for tests
    /// and diagnostics).
    pub(crate) team_steps: u64,
    /// Where each thread's share of the contact list starts (ascending starts, the first
    /// at 0, each with its thread; empty on one thread or without a team): the contacts of
    /// the groups each thread solved in the last step, for the next narrow phase to hand
    /// each thread the contacts whose lines its core holds.
    pub(crate) contact_owners: Vec<(usize, usize)>,
    /// Builds whose groups were handed to the threads that solve them
    /// ([`ContactSolver::build_shares`]; for tests and diagnostics).
    pub(crate) shared_builds: u64,
    /// Counts the layouts made ([`ContactSolver::colour_and_lay_out`]): while it stands
    /// still, each step's solved order ([`ContactSolver::solved_order`]) is last step's.
    pub(crate) layouts: u64,
    /// Tests: never carry the warm start (the reference the carried one must match).
    #[cfg(test)]
    pub(crate) no_carry: bool,
    /// The team's cuts ([`ContactSolver::team_cuts`]) for (layout, threads, bodies per
    /// thread): a kept layout keeps its groups' bodies, so its cuts too.
    cuts_cache: Option<((u64, usize, usize), TeamCuts)>,
    // Scratch reused every step.
    /// Each candidate's colour (with the [`FAST`] and [`FRESH`] flags) or [`OVERFLOW`].
    colours: Vec<u8>,
    used: Vec<u32>,
    slots: Vec<Slot>,
}

/// A light body gets the mass-ratio sweeps only when the heavier body lies above it:
/// the direction from the light body to the heavy one makes less than 45° with `up`
/// (cosine above this). Stacks and slopes up to 45° qualify; the floor and wall contacts
/// of a heavy container do not (in Box2D's tumbler, with a 0.3 cosine, boxes wedged in the
/// turning drum's corners still drew 12 000 extra constraint solves in some steps; with
/// 0.7, 390 per step on average).
const MIN_CARRY_COSINE: f32 = 0.7;

/// Wide constraints per block of the substep team's work sharing ([`TeamBlock`]). Each
/// block costs three atomic operations per pass (claim, lock, unlock); with the shares cut
/// by bodies little is stolen, and 48 beat 16 (solver passes 6 % faster on two threads in
/// large_pyramid and many_pyramids) while 96 gained nothing more.
const TEAM_BLOCK: usize = 48;

/// Bodies per block of the substep team's integration passes: ~2 µs of work, so a late
/// thread's share is taken over in small pieces.
const TEAM_BODY_BLOCK: usize = 256;

/// A block of the substep team's work: claimed by one thread per pass. `claimed` holds
/// the number of the last pass that took it, and a thread takes it for pass `p` only if
/// that number is below `p` (`fetch_max`), so a thread late by several passes never takes
/// a block again that another has already taken for a later pass. One per cache line: a
/// claim writes no line another thread's blocks share.
#[repr(align(64))]
struct TeamBlock<T> {
    claimed: core::sync::atomic::AtomicU32,
    work: T,
}

impl<T> TeamBlock<T> {
    fn new(work: T) -> TeamBlock<T> {
        TeamBlock {
            claimed: core::sync::atomic::AtomicU32::new(0),
            work,
        }
    }

    /// Takes the block for pass `stamp`; false if some thread already has.
    #[inline]
    fn claim(&self, stamp: u32) -> bool {
        self.claimed.fetch_max(stamp, core::sync::atomic::Ordering::AcqRel) < stamp
    }
}

/// The substep team's group boundaries: per colour, per part, the groups where each
/// thread's share starts, then the part's end (`ContactSolver::team_cuts`).
type TeamCuts = Vec<Vec<Vec<usize>>>;

/// A colour's block: its groups (the mutex only hands the claiming thread its `&mut`; it
/// is never contended).
type GroupBlock<'a> = TeamBlock<std::sync::Mutex<GroupBlockParts<'a>>>;

/// A colour's block's part of each group array the passes read.
type GroupBlockParts<'a> = (
    &'a mut [WideHead],
    &'a [WideArms],
    &'a mut [WideRare],
    &'a mut [WideContact],
    &'a [WideDerived],
);

/// One part of a pass for the substep team: its blocks, thread `k`'s own ones being
/// `blocks[shares[k] .. shares[k + 1]]` (see `ContactSolver::team_blocks`).
struct TeamPart<B> {
    blocks: Vec<B>,
    shares: Vec<usize>,
}

impl<B> TeamPart<B> {
    /// Thread `k`'s own blocks.
    fn own(&self, k: usize) -> &[B] {
        let (a, b) = (
            self.shares.get(k).copied().unwrap_or(0),
            self.shares.get(k + 1).copied().unwrap_or(0),
        );
        self.blocks.get(a..b).unwrap_or(&[])
    }

    /// The blocks before and after thread `k`'s own.
    fn others(&self, k: usize) -> (&[B], &[B]) {
        let (a, b) = (
            self.shares.get(k).copied().unwrap_or(0),
            self.shares.get(k + 1).copied().unwrap_or(0),
        );
        let (before, rest) = self.blocks.split_at(a.min(self.blocks.len()));
        (before, rest.get(b.saturating_sub(a)..).unwrap_or(&[]))
    }
}

/// The substep team's integration blocks: bodies `1..n` (0 is the static body), thread
/// `k`'s share being its range `k·per_thread ..` (the bodies its colour shares touch
/// most, see `ContactSolver::team_blocks`), cut into [`TEAM_BODY_BLOCK`]s.
fn team_body_blocks(n: usize, threads: usize, per_thread: usize) -> TeamPart<TeamBlock<core::ops::Range<usize>>> {
    let mut part = TeamPart {
        blocks: Vec::new(),
        shares: Vec::with_capacity(threads + 1),
    };
    for k in 0..threads {
        part.shares.push(part.blocks.len());
        let (start, end) = ((k * per_thread).max(1), ((k + 1) * per_thread).min(n));
        let mut at = start;
        while at < end {
            let next = (at + TEAM_BODY_BLOCK).min(end);
            part.blocks.push(TeamBlock::new(at..next));
            at = next;
        }
    }
    part.shares.push(part.blocks.len());
    part
}

/// Bodies per thread of the substep team (thread `k` integrates bodies `k·per_thread ..`),
/// for `bodies` bodies: what its cuts (`ContactSolver::team_cuts`) are made for.
fn team_bodies_per_thread(bodies: usize, threads: usize) -> usize {
    bodies.div_ceil(threads).max(1)
}

/// The group arrays cut into `chunks` (ranges of groups in ascending order, each with the
/// thread that takes it; [`ContactSolver::build_shares`]), thread by thread, each chunk
/// with the index of its first group. Groups outside every chunk are left out.
fn split_shares<S: SliceTuple>(arrays: S, chunks: &BuildChunks, threads: usize) -> Vec<Vec<(usize, S)>> {
    let mut out: Vec<Vec<(usize, S)>> = (0..threads).map(|_| Vec::new()).collect();
    let mut rest = arrays;
    let mut taken = 0usize;
    for (r, k) in chunks {
        let (a, b) = (r.start, r.end);
        if a < taken || b < a || b > taken + rest.len() {
            continue; // not ascending, or out of range: not a cut of these arrays
        }
        let (_, from_a) = rest.split_at(a - taken);
        let (chunk, after) = from_a.split_at(b - a);
        (rest, taken) = (after, b);
        if let Some(share) = out.get_mut(*k) {
            share.push((a, chunk));
        }
    }
    out
}

/// The build's chunks of groups, ascending, each with the thread that takes it
/// ([`ContactSolver::build_shares`]).
type BuildChunks = Vec<(core::ops::Range<usize>, usize)>;

/// A run of groups' six arrays.
type GroupChunk<'a> = (
    &'a mut [WideHead],
    &'a mut [WideArms],
    &'a mut [WideRare],
    &'a mut [WideContact],
    &'a mut [WideCold],
    &'a mut [WideDerived],
);

/// Where one thread of the team is in the job's sequence of passes: the number of the
/// pass (a block is claimed for a pass by stamping it) and the running total of blocks
/// done by its end. Every thread runs the same sequence, so their cursors agree.
#[derive(Default)]
struct TeamCursor {
    pass: u32,
    target: u64,
}

/// Runs thread `k`'s part of the next team pass over `parts` and waits until the whole
/// pass is done: its own share whole, then the others' shares from their far ends back to
/// the first block already taken, as Box2D v3's solver stages steal (the owner works
/// towards it, so the blocks beyond are taken too, or soon will be; trying every block
/// would cost a cache-line transfer per block, the owner's claim). A thread that comes
/// after the pass is done skips it.
fn team_pass<T>(
    parts: &[TeamPart<TeamBlock<T>>],
    k: usize,
    at: &mut TeamCursor,
    progress: &TeamProgress,
    f: impl Fn(&T),
) {
    at.pass += 1;
    at.target += parts.iter().map(|p| p.blocks.len() as u64).sum::<u64>();
    if progress.reached(at.target) {
        return;
    }
    let stamp = at.pass;
    let mut done = 0u64;
    let mut run = |block: &TeamBlock<T>| {
        let mine = block.claim(stamp);
        if mine {
            f(&block.work);
            done += 1;
        }
        mine
    };
    for part in parts {
        part.own(k).iter().for_each(|b| {
            run(b);
        });
    }
    for part in parts {
        let (before, after) = part.others(k);
        let _ = after.iter().rev().all(&mut run);
        let _ = before.iter().rev().all(&mut run);
    }
    progress.finish(done);
    progress.wait_for(at.target);
}

/// One [`team_pass`] per colour, calling `f` on each group of the blocks this thread
/// takes. Generic over `f`, so the group's pass is compiled into the block's loop rather
/// than called through a `&dyn Fn` per group (in instrumented runs of large_pyramid, not
/// alternated, the threads' solve and relax work fell 6 % and 11 %; the step's wall time
/// showed no change of its own).
#[super::lane_fn]
fn team_colours<F>(
    colours: &[Vec<TeamPart<GroupBlock<'_>>>],
    k: usize,
    at: &mut TeamCursor,
    progress: &TeamProgress,
    f: F,
) where
    F: Fn(&mut WideHead, &WideArms, &mut WideRare, &mut WideContact, &WideDerived),
{
    for parts in colours {
        team_pass(parts, k, at, progress, |part| {
            let mut guard = part.lock().unwrap_or_else(|e| e.into_inner());
            let (heads, arms, rares, wides, derived) = &mut *guard;
            let groups = heads
                .iter_mut()
                .zip(arms.iter())
                .zip(rares.iter_mut())
                .zip(wides.iter_mut())
                .zip(derived.iter());
            for ((((h, r), rare), w), dv) in groups {
                f(h, r, rare, w, dv);
            }
        });
    }
}

/// Wide constraints per parallel chunk of a colour.
const GROUP_CHUNK: usize = 32;

/// Candidates per parallel chunk of the kept-layout check.
const LAYOUT_CHUNK: usize = 2048;

/// How many groups ahead the build asks for its candidates' cache lines.
const PREFETCH_GROUPS: usize = 4;

/// Fewest groups per thread of the impulse store (fewer: one thread stores them all).
const STORE_MIN_GROUPS: usize = 256;

/// Colours open to constraints between two moving bodies, as bits (0 … DYNAMIC_COLORS − 1).
const DYNAMIC_COLOR_BITS: u32 = (1 << DYNAMIC_COLORS) - 1;
/// Colours open to constraints with a static or kinematic side, as bits (1 … COLORS − 1).
const STATIC_COLOR_BITS: u32 = ((1 << COLORS) - 1) & !1;
const _: () = assert!(COLORS <= 32);

/// No colour: the constraint goes to the overflow list.
const OVERFLOW: u8 = u8::MAX;
const _: () = assert!(COLORS <= FRESH as usize);
// No coloured constraint's byte reads as OVERFLOW.
const _: () = assert!((COLORS as u8 - 1) | COLOUR_FLAGS != OVERFLOW);

impl ContactSolver {
    /// Builds the step's constraints from `candidates` (in contact order, each carrying its
    /// contact's solver input); `states` and `sims` are the awake bodies' solver states and
    /// step data, `loaded` whether any of them [`crate::solver::loads`] (found while they were made).
    #[super::lane_fn]
    pub fn build<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        sims: &[BodySim],
        candidates: Candidates<'_>,
        loaded: bool,
    ) {
        debug_assert_eq!(loaded, any_load(sims));
        self.overflow.clear();
        self.groups.clear();
        self.soft = StepSoftness::new(ctx);
        let mut light: Vec<(u32, u32)> = Vec::new(); // (light body state, sweeps)
        if self.same_layout(ctx.parallel, candidates, sims, &mut light) {
            self.kept_layouts += 1;
        } else {
            self.colour_and_lay_out(ctx, states, sims, candidates, &mut light);
        }
        // 4. Build and pack the coloured constraints, four lanes per task.
        let up = self.up;
        // With threads and a layout whose team cuts are known (kept from the last step),
        // each thread builds the groups it will solve (see `build_shares`).
        let shares = self.build_shares(ctx, sims.len());
        let lane_candidates = &self.lane_candidates;
        let build_chunk = |first: usize, (heads, arms, rares, wides, colds, derived): GroupChunk<'_>| {
            for k in 0..heads.len() {
                let g = first + k;
                if let Some(ahead) = lane_candidates.get(g + PREFETCH_GROUPS) {
                    for &i in ahead {
                        if let Some(cand) = candidates.get(i as usize) {
                            crate::solver::prefetch(cand);
                        }
                    }
                }
                // The group's output lines too: read for ownership now, they are written
                // without waiting (a line only this core holds is then written in place).
                if let (Some(h), Some(w), Some(c), Some(d)) = (
                    heads.get(k + PREFETCH_GROUPS),
                    wides.get(k + PREFETCH_GROUPS),
                    colds.get(k + PREFETCH_GROUPS),
                    derived.get(k + PREFETCH_GROUPS),
                ) {
                    crate::solver::prefetch(h);
                    crate::solver::prefetch(w);
                    crate::solver::prefetch(c);
                    crate::solver::prefetch(d);
                }
                if let (Some(r), Some(rare)) = (arms.get(k + PREFETCH_GROUPS), rares.get(k + PREFETCH_GROUPS)) {
                    crate::solver::prefetch(r);
                    crate::solver::prefetch(rare);
                }
                let lanes = array_of(|l| {
                    candidates
                        .get(lane_candidates[g][l] as usize)
                        .map(|cand| (cand.contact, &cand.input, &cand.bodies))
                });
                if let (Some(h), Some(r), Some(rare), Some(w), Some(cold), Some(dv)) = (
                    heads.get_mut(k),
                    arms.get_mut(k),
                    rares.get_mut(k),
                    wides.get_mut(k),
                    colds.get_mut(k),
                    derived.get_mut(k),
                ) {
                    contact_wide::build_group(h, r, rare, w, cold, dv, lanes, up, ctx, states);
                }
            }
        };
        let arrays = (
            &mut self.head[..],
            &mut self.arms[..],
            &mut self.rare[..],
            &mut self.wide[..],
            &mut self.cold[..],
            &mut self.derived[..],
        );
        match shares {
            Some((chunks, threads)) => {
                self.shared_builds += 1;
                let items = split_shares(arrays, &chunks, threads);
                claim_each_share(true, items, |(first, chunk)| build_chunk(first, chunk));
            }
            None => for_each_chunk_mut(ctx.parallel, arrays, GROUP_CHUNK, build_chunk),
        }
        self.loaded = loaded;
        if self.loaded {
            self.build_groups(light, candidates);
        }
        #[cfg(debug_assertions)]
        self.check_colours(states.len());
    }

    /// Steps 1–3 of the build: colours, layout, slots (and the overflow constraints, built
    /// whole); `light` gets the light bodies under heavy ones.
    #[super::lane_fn]
    fn colour_and_lay_out<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        sims: &[BodySim],
        candidates: Candidates<'_>,
        light: &mut Vec<(u32, u32)>,
    ) {
        self.layouts += 1;
        self.fresh.clear();
        // 1. Colours. The lists it fills are taken out of `self` for the loop: as locals
        // their lengths stay in registers (as fields, each push reloaded and stored its
        // vector's length: junkyard's pushes were ~50 instructions a contact).
        let n = candidates.list.len();
        let (mut used, mut colours) = (core::mem::take(&mut self.used), core::mem::take(&mut self.colours));
        let (mut contact_of, mut last_keys) = (
            core::mem::take(&mut self.contact_of),
            core::mem::take(&mut self.last_keys),
        );
        used.clear();
        used.resize(states.len(), 0);
        colours.clear();
        colours.reserve(n);
        contact_of.clear();
        contact_of.reserve(n);
        last_keys.clear();
        last_keys.reserve(n);
        let mut counts = [0u32; COLORS];
        // Constraints likely to take the solver's fast path, per colour (see `fast_first`).
        let mut fast_counts = [0u32; COLORS];
        // Constraints of one point or none, per colour (see [`SINGLE`]).
        let mut single_counts = [0u32; COLORS];
        let mut any_restitution = false;
        let mut overflow = false;
        // Every listed contact has its key (the keys are kept for every contact slot), so
        // the contacts are the list itself: copied whole, not pushed one by one.
        contact_of.extend_from_slice(candidates.list);
        for (i, (_, key)) in candidates.keys().enumerate() {
            if key.flags & KEY_RATIO != 0 {
                light.extend(candidates.get(i).and_then(|cand| self.light_body(cand, sims)));
            }
            let (da, db) = (key.flags & KEY_DYNAMIC_A != 0, key.flags & KEY_DYNAMIC_B != 0);
            let busy =
                (if da { used[key.index_a as usize] } else { 0 }) | (if db { used[key.index_b as usize] } else { 0 });
            // The colour of the last step when it is still free (a pile keeps its layout:
            // `World::reorder_contacts`), else the lowest free colour below DYNAMIC_COLORS, or the
            // highest free one from 1 up (bit scans of the free colours).
            let open = if da && db {
                DYNAMIC_COLOR_BITS
            } else {
                STATIC_COLOR_BITS
            };
            let kept = 1u32.checked_shl(key.colour as u32).unwrap_or(0) & open & !busy;
            let colour = if kept != 0 {
                Some(key.colour as usize)
            } else if da && db {
                let free = !busy & DYNAMIC_COLOR_BITS;
                (free != 0).then(|| free.trailing_zeros() as usize)
            } else {
                let free = !busy & STATIC_COLOR_BITS;
                (free != 0).then(|| 31 - free.leading_zeros() as usize)
            };
            match colour {
                Some(k) => {
                    if da {
                        used[key.index_a as usize] |= 1 << k;
                    }
                    if db {
                        used[key.index_b as usize] |= 1 << k;
                    }
                    counts[k] += 1;
                    fast_counts[k] += (key.flags & FAST != 0) as u32;
                    single_counts[k] += (key.flags & SINGLE != 0) as u32;
                    any_restitution |= key.flags & KEY_RESTITUTION != 0;
                    colours.push(k as u8 | (key.flags & COLOUR_FLAGS));
                    last_keys.push(ColourKey {
                        colour: k as u8,
                        flags: key.flags & !ORDER_FLAGS,
                        ..*key
                    });
                }
                None => {
                    colours.push(OVERFLOW);
                    overflow = true;
                }
            }
        }
        self.layout_kept = !overflow;
        (self.used, self.colours, self.contact_of, self.last_keys) = (used, colours, contact_of, last_keys);
        self.any_restitution = any_restitution;
        // 2. Layout: colour k fills lanes from `next[k]` on (in lanes, not groups).
        let mut next = [0u32; COLORS];
        let mut next_slow = [0u32; COLORS];
        let mut next_single = [0u32; COLORS];
        let mut groups = 0u32;
        self.ranges.clear();
        self.slow_start.clear();
        self.single_start.clear();
        self.group_colour.clear();
        for k in 0..COLORS {
            next[k] = groups * LANES as u32;
            next_slow[k] = next[k] + fast_counts[k];
            next_single[k] = next[k] + counts[k] - single_counts[k];
            let start = groups;
            groups += counts[k].div_ceil(LANES as u32);
            if groups > start {
                self.ranges.push((start, groups));
                let slow = next_slow[k].div_ceil(LANES as u32).clamp(start, groups);
                self.slow_start.push(slow);
                self.single_start
                    .push(next_single[k].div_ceil(LANES as u32).clamp(slow, groups));
                self.group_colour.resize(groups as usize, k as u8);
            }
        }
        // Every lane is written whole below (built, empty lanes too, or packed): no memset.
        self.head.resize(groups as usize, WideHead::default());
        self.head.truncate(groups as usize);
        self.wide.resize(groups as usize, WideContact::default());
        self.cold.resize(groups as usize, WideCold::default());
        self.wide.truncate(groups as usize);
        self.cold.truncate(groups as usize);
        self.derived.resize(groups as usize, WideDerived::default());
        self.derived.truncate(groups as usize);
        self.arms.resize(groups as usize, WideArms::default());
        self.arms.truncate(groups as usize);
        self.rare.resize(groups as usize, WideRare::default());
        self.rare.truncate(groups as usize);
        // 3. Slots: overflow constraints are built here, coloured ones below.
        let soft = self.soft;
        // Locals again for the loop (see step 1).
        let (mut slots, mut lane_candidates) = (
            core::mem::take(&mut self.slots),
            core::mem::take(&mut self.lane_candidates),
        );
        slots.clear();
        slots.reserve(n);
        lane_candidates.clear();
        lane_candidates.resize(groups as usize, [u32::MAX; LANES]);
        // Reads only the colour bytes (and the rare overflow candidates), not the candidates.
        for (i, &colour) in self.colours.iter().enumerate() {
            let slot = if colour == OVERFLOW {
                let Some(cand) = candidates.get(i) else { continue };
                let b = &cand.bodies;
                let cc = build_constraint(cand.contact, &cand.input, b, self.up, &soft, ctx, states);
                if cand.input.may_be_new_resting() {
                    self.fresh.push(Slot::Overflow(self.overflow.len() as u32));
                }
                self.overflow.push(cc);
                Slot::Overflow(self.overflow.len() as u32 - 1)
            } else {
                let k = (colour & !COLOUR_FLAGS) as usize;
                let next = if colour & FAST != 0 {
                    &mut next[k]
                } else if colour & SINGLE != 0 {
                    &mut next_single[k]
                } else {
                    &mut next_slow[k]
                };
                let at = *next;
                *next += 1;
                let (group, lane) = (at / LANES as u32, at % LANES as u32);
                debug_assert!((group as usize) < lane_candidates.len(), "lane {at} past the layout");
                if let Some(lanes) = lane_candidates.get_mut(group as usize) {
                    lanes[lane as usize] = i as u32;
                }
                let slot = Slot::Wide {
                    group,
                    lane: lane as u8,
                };
                if colour & FRESH != 0 {
                    self.fresh.push(slot);
                }
                slot
            };
            slots.push(slot);
        }
        (self.slots, self.lane_candidates) = (slots, lane_candidates);
    }

    /// Whether last step's colours and layout hold for `candidates` unchanged: the same
    /// contacts in the same order, with the same bodies, last colours and flags, and no
    /// overflow then. Each contact then keeps its colour (a valid colouring last step, of
    /// the same pairs), so the full colouring would give the same colours and the same
    /// layout, up to the order of [`FAST`] constraints inside a colour, which changes no
    /// result (its flag is not compared: it follows each step's loads, and would otherwise
    /// force a new layout in nearly every step of a resting pile). In large_pyramid and
    /// many_pyramids all but the first steps keep their layout; a pile in motion (tumbler)
    /// fails at once. `light` gets the light bodies under heavy ones, as the colouring
    /// collects them.
    #[super::lane_fn]
    fn same_layout(
        &self,
        parallel: bool,
        candidates: Candidates<'_>,
        sims: &[BodySim],
        light: &mut Vec<(u32, u32)>,
    ) -> bool {
        let n = candidates.list.len();
        if !self.layout_kept || self.last_keys.len() != n || self.contact_of.len() != n {
            return false;
        }
        // Whether the candidates in `range` are laid out as last step; their light bodies
        // into `out`.
        let check = |range: core::ops::Range<usize>, out: &mut Vec<(u32, u32)>| {
            // The three lists side by side over `range` (one bounds check each, not three
            // per candidate).
            let (Some(list), Some(contact_of), Some(last_keys)) = (
                candidates.list.get(range.clone()),
                self.contact_of.get(range.clone()),
                self.last_keys.get(range.clone()),
            ) else {
                return false;
            };
            for (i, ((&contact, &last_contact), last)) in list.iter().zip(contact_of).zip(last_keys).enumerate() {
                let Some(key) = candidates.keys.get(contact as usize) else {
                    return false;
                };
                if contact != last_contact
                    || key.index_a != last.index_a
                    || key.index_b != last.index_b
                    || key.colour != last.colour
                    || key.flags & !ORDER_FLAGS != last.flags
                {
                    return false;
                }
                if key.flags & KEY_RATIO != 0 {
                    out.extend(
                        candidates
                            .get(range.start + i)
                            .and_then(|cand| self.light_body(cand, sims)),
                    );
                }
            }
            true
        };
        let same = if parallel && n >= 2 * LAYOUT_CHUNK {
            // In chunks on the pool's threads (a serial 23-29 µs of large_pyramid's
            // two-thread step, 160 µs of many_pyramids'), the light bodies in order.
            // Per chunk: whether it is as last step, its light bodies.
            type Part = std::sync::Mutex<(bool, Vec<(u32, u32)>)>;
            let parts: Vec<Part> = (0..n.div_ceil(LAYOUT_CHUNK)).map(|_| Default::default()).collect();
            claim_each(true, 0..parts.len(), |k| {
                if let Some(part) = parts.get(k) {
                    let mut part = part.lock().unwrap_or_else(|e| e.into_inner());
                    let (same, out) = &mut *part;
                    *same = check(k * LAYOUT_CHUNK..((k + 1) * LAYOUT_CHUNK).min(n), out);
                }
            });
            let parts: Vec<_> = parts
                .into_iter()
                .map(|p| p.into_inner().unwrap_or_else(|e| e.into_inner()))
                .collect();
            let same = parts.iter().all(|(same, _)| *same);
            if same {
                for (_, out) in parts {
                    light.extend(out);
                }
            }
            same
        } else {
            check(0..n, light)
        };
        if !same {
            light.clear();
        }
        same
    }

    /// A candidate between a light body and one more than [`MASS_RATIO_GROUP`] times
    /// heavier that rests on it: (light body state, its sweeps).
    ///
    /// [`MASS_RATIO_GROUP`]: crate::solver::contact_solver::MASS_RATIO_GROUP
    #[super::lane_fn]
    fn light_body(&self, cand: &Candidate, sims: &[BodySim]) -> Option<(u32, u32)> {
        // Only where the heavy body rests on the light one: it lies above it against
        // gravity (a heavy container holding light bodies, Box2D's tumbler drum at 64 000
        // times its boxes' mass, carries them; they do not carry it), and it has no joint (a
        // motor may press it on the light body with any torque: Box2D's spinner rotor,
        // squeezing bodies against the wall with unbounded torque, made the extra sweeps pile
        // up impulses without bound until the states overflowed). The candidate (masses,
        // normal) is read only for such a pair.
        let (ratio, body, heavy, a_is_light) = mass_ratio(&cand.bodies)?;
        let n = cand.input.normal;
        let to_heavy = if a_is_light { n } else { -n };
        let carries = self.up == Vec2::ZERO || to_heavy.dot(self.up) > MIN_CARRY_COSINE;
        let free = sims.get(heavy as usize).is_some_and(|s| !s.jointed);
        (carries && free).then(|| (body, (ratio.ceil() as u32).min(MAX_LOCAL_SWEEPS)))
    }

    /// The contacts solved in the last step in the order the solver laid them out (group
    /// by group, lane by lane, then the overflow list), into `out`; returns how many of
    /// them do not follow the one before in contact order (few: the contacts already lie
    /// in the layout's order). Read only when a renumbering may follow, not every step.
    /// Any list is safe to renumber by (each live contact is placed once); a stale one
    /// only orders them less well.
    pub fn solved_order(&self, out: &mut Vec<u32>) -> usize {
        out.clear();
        let contact_of = &self.contact_of;
        let lanes = self
            .lane_candidates
            .iter()
            .flatten()
            .filter_map(|&cand| contact_of.get(cand as usize).copied());
        let mut breaks = 0;
        let mut last = u32::MAX;
        for contact in lanes.chain(self.overflow.iter().map(|oc| oc.contact)) {
            breaks += (contact != last.wrapping_add(1)) as usize;
            last = contact;
            out.push(contact);
        }
        breaks
    }

    /// Debug builds: no moving body appears twice in one colour (the threads' shared
    /// states rely on it, see [`SharedState`]).
    #[cfg(debug_assertions)]
    #[super::lane_fn]
    fn check_colours(&self, bodies: usize) {
        // The passes find a group's ready-made part by its index.
        debug_assert_eq!(self.derived.len(), self.head.len());
        let mut seen = vec![u32::MAX; bodies];
        for (k, &(start, end)) in self.ranges.iter().enumerate() {
            for h in &self.head[start as usize..end as usize] {
                for l in 0..LANES {
                    for (write, index) in [(h.write_a[l], h.index_a[l]), (h.write_b[l], h.index_b[l])] {
                        if write {
                            assert_ne!(seen[index as usize], k as u32, "body {index} twice in colour {k}");
                            seen[index as usize] = k as u32;
                        }
                    }
                }
            }
        }
    }

    /// Mass-ratio groups: each light body touching a moving body more than
    /// [`MASS_RATIO_GROUP`]× heavier gets its constraints swept ⌈M/m⌉ (at most
    /// [`MAX_LOCAL_SWEEPS`]) extra times per relax pass. Sequential impulses move momentum
    /// through a light body between a heavy one and the ground only at a rate of about m/M
    /// per sweep, so a 100:1 stack needs ~100 sweeps where one is enough for equal masses.
    /// Only when some body is loaded ([`crate::solver::any_load`]).
    ///
    /// [`MASS_RATIO_GROUP`]: crate::solver::contact_solver::MASS_RATIO_GROUP
    #[super::lane_fn]
    fn build_groups(&mut self, mut light: Vec<(u32, u32)>, candidates: Candidates<'_>) {
        if light.is_empty() {
            return;
        }
        light.sort_unstable();
        light.dedup_by(|x, y| {
            if x.0 == y.0 {
                y.1 = y.1.max(x.1);
                true
            } else {
                false
            }
        });
        for &(body, sweeps) in &light {
            let mut members = Vec::new();
            for (cand, &slot) in candidates.iter().zip(&self.slots) {
                if cand.bodies.index_a == body || cand.bodies.index_b == body {
                    members.push((slot, self.get(slot)));
                }
            }
            self.groups.push(Group { members, sweeps });
        }
    }

    /// The scalar constraint at a slot, with its current state.
    #[super::lane_fn]
    fn get(&self, slot: Slot) -> ContactConstraint {
        match slot {
            Slot::Wide { group, lane } => {
                let g = group as usize;
                contact_wide::unpack_full(
                    &self.head[g],
                    &self.arms[g],
                    &self.rare[g],
                    &self.wide[g],
                    &self.cold[g],
                    &self.soft,
                    lane as usize,
                )
            }
            Slot::Overflow(i) => self.overflow[i as usize],
        }
    }

    /// Writes a scalar constraint's state back to its slot (`full`: geometry and preload
    /// too, after the estimate).
    #[super::lane_fn]
    fn put(&mut self, slot: Slot, cc: &ContactConstraint, full: bool) {
        match slot {
            Slot::Wide { group, lane } => {
                let g = group as usize;
                let (h, w) = (&mut self.head[g], &mut self.wide[g]);
                if full {
                    let (da, db) = (h.write_a[lane as usize], h.write_b[lane as usize]);
                    // (The lane's geometry comes back as it was unpacked, so the group's
                    // derived part is made again with the same bits.)
                    let (arms, rare) = (&mut self.arms[g], &mut self.rare[g]);
                    let (cold, dv) = (&mut self.cold[g], &mut self.derived[g]);
                    contact_wide::pack(h, arms, rare, w, cold, dv, lane as usize, cc, da, db);
                } else {
                    contact_wide::pack_state(h, &mut self.rare[g], w, lane as usize, cc);
                }
            }
            Slot::Overflow(i) => self.overflow[i as usize] = *cc,
        }
    }

    /// Writes every constraint's impulses and friction state back into its contact
    /// (`contacts` is the world's contact list) and its reported sums into `sums` (the
    /// world's `contact_sums`, one per contact slot): each group computes what its lanes
    /// store and writes it straight into their contacts (their first cache line asked for a
    /// few groups ahead), then the overflow constraints store theirs. After a step the
    /// worker team solved, it also notes where each thread's share of the contacts starts
    /// for the next narrow phase (`contact_owners`).
    ///
    /// With threads, the groups are cut into runs (below: after a step the team solved,
    /// what each thread solved of each colour part, neighbours of one thread merged; else
    /// one run per thread by group count), and the contact list at the contact of each
    /// run's first lane: the contacts follow the solver's layout (`World::reorder_contacts`),
    /// so nearly every lane's contact falls in its own run's range, and each task writes its
    /// range directly; the few that do not (contacts made since the last renumbering) are
    /// kept aside and written after, on one thread. Each contact is written once, with the
    /// same values whatever the split. (Computing every lane's values into a buffer first
    /// and copying them in contact order, as this did before, streamed the buffer twice:
    /// large_pyramid's store took 0.64 ms on two threads against 0.81 on one.) Runs cut by
    /// count into more pieces than threads cost more than they saved (eight runs: 1 509
    /// contacts a step of large_pyramid to write after, serially, against 85 with two; the
    /// contacts follow the layout only roughly, `World::reorder_contacts` allows one break in
    /// three); the team's runs are cut where the layout's own order is, so they keep the
    /// strays as few (under 2 %, `the_threaded_store_writes_nearly_every_contact_in_place`).
    #[super::lane_fn]
    pub fn store<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        contacts: &mut [Option<Contact>],
        sums: &mut [ContactSums],
    ) {
        let groups = self.head.len();
        let threads = if ctx.parallel { rayon::current_num_threads() } else { 1 };
        let tasks = threads.min(groups / STORE_MIN_GROUPS).max(1);
        // The runs, each a list of group ranges for one thread and the contacts from its
        // first (the first run's from 0) to the next run's first. With the team's cuts of
        // this layout, a run is what one thread solved of a colour part (`team_shares`; a
        // colour's parts' contacts interleave, and one thread's runs that follow one
        // another in contact order are merged), so each thread reads the group
        // records its cache holds and writes the contacts its next narrow phase visits
        // (`contact_owners`); cut instead into `tasks` runs of as many groups, each held
        // whole colours, half of them solved on the other core (large_pyramid's store
        // scaled ×1.6 on two threads, its collide ×1.8). The contacts follow the solver's
        // order (`World::reorder_contacts`), so few lanes' contacts lie outside their run:
        // those are written after, on one thread.
        let team = self.team_shares(threads);
        let cuts: BuildChunks = match team.as_ref().filter(|_| tasks > 1) {
            Some(shares) => shares.clone(),
            None => (0..tasks)
                .map(|k| (k * groups / tasks..(k + 1) * groups / tasks, k))
                .collect(),
        };
        let mut chunks: Vec<(core::ops::Range<usize>, usize, usize)> = cuts
            .into_iter()
            .map(|(r, k)| (r.clone(), self.first_contact(r.start).unwrap_or(0), k))
            .collect();
        chunks.sort_by_key(|c| c.1);
        type Run = (Vec<core::ops::Range<usize>>, usize, usize);
        let mut runs: Vec<Run> = Vec::new();
        for (r, first, k) in chunks {
            match runs.last_mut() {
                // The same thread, or not past the last run's first contact: one run.
                Some(last) if last.2 == k || first <= last.1 || first >= contacts.len() => last.0.push(r),
                _ => runs.push((vec![r], if runs.is_empty() { 0 } else { first }, k)),
            }
        }
        // Who visits which contacts in the next narrow phase.
        let mut owners = core::mem::take(&mut self.contact_owners);
        self.find_contact_owners(team.as_ref(), contacts.len(), &mut owners);
        self.contact_owners = owners;
        debug_assert_eq!(contacts.len(), sums.len(), "a sum per contact slot");
        self.store_runs = runs.len();
        let mut strays = Vec::new();
        if runs.len() <= 1 {
            self.store_groups(ctx, states, 0..groups, (contacts, sums), 0, &mut strays);
        } else {
            let mut kept: Vec<Vec<(u32, u8, StoredContact)>> = vec![Vec::new(); runs.len()];
            let mut shares: Vec<Vec<_>> = (0..threads).map(|_| Vec::new()).collect();
            let mut rest: &mut [Option<Contact>] = &mut *contacts;
            let mut rest_sums: &mut [ContactSums] = &mut *sums;
            let ends: Vec<usize> = runs.iter().skip(1).map(|r| r.1).chain([usize::MAX]).collect();
            for (((ranges, at, k), end_at), out) in runs.into_iter().zip(ends).zip(kept.iter_mut()) {
                // (`contacts` and `sums` have the same length.)
                let len = end_at.saturating_sub(at).min(rest.len()).min(rest_sums.len());
                let (mine, tail) = core::mem::take(&mut rest).split_at_mut(len);
                let (mine_sums, tail_sums) = core::mem::take(&mut rest_sums).split_at_mut(len);
                let k = if k < shares.len() { k } else { 0 };
                if let Some(share) = shares.get_mut(k) {
                    share.push((ranges, at, (mine, mine_sums), out));
                }
                rest = tail;
                rest_sums = tail_sums;
            }
            let this = &*self;
            claim_each_share(true, shares, |(ranges, base, (mine, mine_sums), out)| {
                for range in ranges {
                    this.store_groups(ctx, states, range, (&mut *mine, &mut *mine_sums), base, out);
                }
            });
            strays.extend(kept.into_iter().flatten());
        }
        self.stored_after = strays.len();
        for (contact, colour, stored) in strays {
            if let (Some(Some(c)), Some(sum)) = (contacts.get_mut(contact as usize), sums.get_mut(contact as usize)) {
                stored.write_into(c, sum);
                c.colour = colour;
            }
        }
        for oc in &self.overflow {
            let at = oc.contact as usize;
            if let (Some(Some(c)), Some(sum)) = (contacts.get_mut(at), sums.get_mut(at)) {
                store_impulses(oc, c, sum, states, ctx);
                c.colour = NO_COLOUR;
            }
        }
    }
}

impl ContactSolver {
    /// The store of the groups in `range`, into `contacts` and `sums`, the parts of the
    /// contact list and of the sums from contact `base` on (of the same length); a lane
    /// whose contact lies outside them goes to `strays` (contact, colour, what it stores).
    #[super::lane_fn]
    fn store_groups<S: StateRead>(
        &self,
        ctx: &StepContext,
        states: &[S],
        range: core::ops::Range<usize>,
        (contacts, sums): (&mut [Option<Contact>], &mut [ContactSums]),
        base: usize,
        strays: &mut Vec<(u32, u8, StoredContact)>,
    ) {
        let at = |contact: u32| (contact as usize).wrapping_sub(base);
        for g in range.clone() {
            let (Some(h), Some(arms), Some(rare), Some(w), Some(cold)) = (
                self.head.get(g),
                self.arms.get(g),
                self.rare.get(g),
                self.wide.get(g),
                self.cold.get(g),
            ) else {
                continue;
            };
            if let (Some(ahead), Some(ahead_cold)) = (
                self.lane_candidates
                    .get(g + PREFETCH_GROUPS)
                    .filter(|_| g + PREFETCH_GROUPS < range.end),
                self.cold.get(g + PREFETCH_GROUPS),
            ) {
                for (&cand, &contact) in ahead.iter().zip(&ahead_cold.contact) {
                    if cand != u32::MAX {
                        if let Some(c) = contacts.get(at(contact)) {
                            crate::solver::prefetch_lines(c, 1);
                        }
                        // (The sums follow the contacts' order, but only as closely as
                        // the contacts follow the layout: spinner's are scattered.)
                        if let Some(sum) = sums.get(at(contact)) {
                            crate::solver::prefetch(sum);
                        }
                    }
                }
            }
            let out = contact_wide::store_group(h, arms, rare, w, cold, states, ctx);
            let (Some(lanes), Some(&colour)) = (self.lane_candidates.get(g), self.group_colour.get(g)) else {
                continue;
            };
            for (l, (&cand, &contact)) in lanes.iter().zip(&cold.contact).enumerate() {
                if cand == u32::MAX {
                    continue; // an empty lane
                }
                match (contacts.get_mut(at(contact)), sums.get_mut(at(contact))) {
                    (Some(Some(c)), Some(sum)) => {
                        out.write_into(l, c, sum);
                        c.colour = colour;
                    }
                    (Some(None), _) => {}
                    _ => strays.push((contact, colour, out.lane(l))),
                }
            }
        }
    }
}

impl ContactSolver {
    // The passes of `ConstraintSet` (the trait's methods below call these).

    /// [`ConstraintSet::estimate_new_contacts`].
    #[super::lane_fn]
    fn estimate_new<S: StateCell, T: StateCell>(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[S],
        trial: &[T],
    ) -> bool {
        let mut subset = Vec::new();
        let mut slots = Vec::new();
        // The trial states of the new constraints' bodies: each one's state after one
        // substep of forces (`integrate_velocity_one`, made again for a body met twice;
        // the static body's as it is). The estimate reads and writes no other body.
        let make = |k: u32| {
            if let (Some(t), Some(s)) = (trial.get(k as usize), states.get(k as usize)) {
                t.set(s.get());
                if let (true, Some(sim)) = (k != 0, sims.get(k as usize)) {
                    integrate_velocity_one(ctx.h, sim, t, None);
                }
            }
        };
        for &slot in &self.fresh {
            let mut cc = self.get(slot);
            make(cc.index_a);
            make(cc.index_b);
            record_approach(&mut cc, trial);
            if is_new_resting(&cc) {
                subset.push(cc);
                slots.push(slot);
            }
        }
        if subset.is_empty() {
            return false;
        }
        // A structure placed at rest (most of the step's contacts new) gets the full sweep
        // budget; contacts joining a pile that already carries its load, fewer.
        let max_sweeps = if 2 * subset.len() >= self.slots.len() {
            MAX_ESTIMATE_SWEEPS
        } else {
            ONGOING_ESTIMATE_SWEEPS
        };
        estimate(&mut subset, self.up, ctx, trial, max_sweeps);
        // `estimate` sorted the subset: find each constraint's slot by its contact.
        let mut by_contact: Vec<(u32, Slot)> = slots.iter().map(|&s| (self.get(s).contact, s)).collect();
        by_contact.sort_unstable_by_key(|x| x.0);
        for cc in &subset {
            if let Ok(k) = by_contact.binary_search_by_key(&cc.contact, |x| x.0) {
                self.put(by_contact[k].1, cc, true);
            }
        }
        true
    }

    /// [`ConstraintSet::warm_start`].
    #[super::lane_fn]
    fn warm_start_pass<S: StateCell>(&mut self, states: &[S], carried: bool) {
        for cc in &mut self.overflow {
            warm_start_one(cc, states);
        }
        // The groups' warm start came with the velocities (`solver::solve_step`).
        if carried {
            return;
        }
        for &(start, end) in &self.ranges {
            let range = start as usize..end as usize;
            let (heads, arms) = (&self.head[range.clone()], &self.arms[range.clone()]);
            S::for_each_mut(states, &mut self.rare[range], GROUP_CHUNK, |i, rare, states| {
                if let (Some(h), Some(r)) = (heads.get(i), arms.get(i)) {
                    contact_wide::warm_start(h, r, rare, states)
                }
            });
        }
    }

    /// [`ConstraintSet::solve`].
    #[super::lane_fn]
    fn solve_pass<S: StateCell>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        use_bias: bool,
        elapsed: f32,
        carry: Option<&[S]>,
    ) {
        for cc in &mut self.overflow {
            solve_one(cc, states, ctx, use_bias, elapsed);
        }
        // (A carry has an entry for every state, which the lanes' bodies index.)
        let carry = carry.filter(|c| c.len() >= states.len());
        let soft = &self.soft;
        // Colour after colour; the groups of one colour share no moving body.
        for &(start, end) in &self.ranges {
            let range = start as usize..end as usize;
            let groups = (
                &mut self.head[range.clone()],
                &mut self.rare[range.clone()],
                &mut self.wide[range.clone()],
            );
            let derived = &self.derived[range];
            if use_bias {
                S::for_each_mut3(states, &[], groups, GROUP_CHUNK, |i, h, rare, w, states, _| {
                    if let Some(dv) = derived.get(i) {
                        contact_wide::solve::<true, S>(h, rare, w, dv, states, ctx, soft, elapsed, None)
                    }
                });
            } else {
                S::for_each_mut3(
                    states,
                    carry.unwrap_or(&[]),
                    groups,
                    GROUP_CHUNK,
                    |i, h, rare, w, states, carry| {
                        if let Some(dv) = derived.get(i) {
                            let carry = (!carry.is_empty()).then_some(carry);
                            contact_wide::solve::<false, S>(h, rare, w, dv, states, ctx, soft, elapsed, carry)
                        }
                    },
                );
            }
        }
        // Extra local sweeps where a light body carries a heavy one, in the relax pass only:
        // the soft rows of the biased pass are formulated for exactly one sweep (each
        // sweep relaxes the impulse towards its preload).
        if use_bias {
            return;
        }
        let mut groups = core::mem::take(&mut self.groups);
        for g in &mut groups {
            for _ in 0..g.sweeps {
                for (slot, cc) in g.members.iter_mut() {
                    self.sync_from(*slot, cc);
                    // The relax pass already added this substep's impulses to the totals;
                    // add what the extra sweep changes.
                    let before = cc.points.map(|p| (p.normal_impulse, p.tangent_impulse));
                    solve_one(cc, states, ctx, use_bias, elapsed);
                    if let Slot::Wide { .. } = slot {
                        for (p, (n, t)) in cc.points.iter_mut().zip(before) {
                            p.total_normal_impulse += p.normal_impulse - n;
                            p.total_tangent_impulse += p.tangent_impulse - t;
                        }
                    }
                    self.put(*slot, cc, false);
                }
            }
        }
        self.groups = groups;
    }

    /// [`ConstraintSet::restitution`].
    #[super::lane_fn]
    fn restitution_pass<S: StateCell>(&mut self, states: &[S]) {
        for cc in &mut self.overflow {
            restitution_one(cc, states);
        }
        if !self.any_restitution {
            return;
        }
        // Four lanes at once; a group's lanes share no moving body (one colour), and the
        // groups run in order, as the scalar loop ran.
        let groups = self
            .head
            .iter_mut()
            .zip(&self.arms)
            .zip(&self.rare)
            .zip(self.wide.iter_mut())
            .zip(&self.derived)
            .zip(&self.cold);
        for (((((h, arms), rare), w), dv), cold) in groups {
            if cold.any_restitution {
                contact_wide::restitution(h, arms, rare, w, dv, cold, states);
            }
        }
    }
}

// In the eight-lane builds the passes are compiled for AVX2 (or AVX2 with AVX-512F/VL,
// `#[super::lane_fn]`), and calling one from here is `unsafe`: sound, since that build's
// solver is only ever made on a CPU with those (`solver::Contacts::new`). In the four-lane
// build the blocks are plain calls (`unused_unsafe`).
#[allow(unsafe_code, unused_unsafe)]
impl ConstraintSet for ContactSolver {
    fn has_new_contacts(&self) -> bool {
        self.loaded && !self.fresh.is_empty()
    }

    fn estimate_new_contacts<S: StateCell, T: StateCell>(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[S],
        trial: &[T],
    ) -> bool {
        // SAFETY: see the impl.
        unsafe { self.estimate_new(ctx, sims, states, trial) }
    }

    fn warm_start<S: StateCell>(&mut self, _ctx: &StepContext, states: &[S], carried: bool) {
        // SAFETY: see the impl.
        unsafe { self.warm_start_pass(states, carried) }
    }

    fn solve<S: StateCell>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        use_bias: bool,
        elapsed: f32,
        carry: Option<&[S]>,
    ) {
        // SAFETY: see the impl.
        unsafe { self.solve_pass(ctx, states, use_bias, elapsed, carry) }
    }

    /// The groups carry their warm start unless some constraint has restitution (a
    /// group's warm start records each point's approach speed every substep, and an
    /// overflow constraint's, which runs first, recorded it before the groups' impulses)
    /// or mass-ratio groups run (their extra sweeps change impulses after the relax pass
    /// carried them). The overflow constraints warm start as ever.
    fn carries_warm_start(&self) -> bool {
        #[cfg(test)]
        if self.no_carry {
            return false;
        }
        !self.any_restitution
            && self.overflow.iter().all(|cc| cc.restitution == 0.0)
            && self.groups.is_empty()
            && !self.head.is_empty()
    }

    fn end_substep(&mut self) {
        // Wide lanes added their totals at the end of the relax pass.
        for cc in &mut self.overflow {
            end_substep_one(cc);
        }
    }

    fn substeps_team(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[SharedState],
        carry: &[SharedState],
        times: &mut [f32; 5],
    ) -> bool {
        // SAFETY: see the impl.
        unsafe { self.team_loop(ctx, sims, states, carry, times) }
    }

    fn restitution<S: StateCell>(&mut self, states: &[S]) {
        // SAFETY: see the impl.
        unsafe { self.restitution_pass(states) }
    }
}

impl ContactSolver {
    /// The worker-team substep loop (see [`ConstraintSet::substeps_team`]): one job per
    /// thread of the pool for all substeps; each integrates blocks of bodies and solves
    /// blocks of every colour (its own share first, then blocks the others have not
    /// started, as Box2D v3's solver stages steal blocks), and after each colour and stage
    /// waits until all of that pass's blocks are done ([`team_pass`]). Each block is solved
    /// exactly once per pass, a colour's constraints share no moving body and each body is
    /// integrated by itself, so the result does not depend on the thread count or on who
    /// solved which block. Only for steps without overflow constraints and mass-ratio
    /// groups (scalar work the team would have to serialise); those run the per-colour
    /// path.
    #[super::lane_fn]
    fn team_loop(
        &mut self,
        ctx: &StepContext,
        sims: &[BodySim],
        states: &[SharedState],
        carry: &[SharedState],
        times: &mut [f32; 5],
    ) -> bool {
        let threads = rayon::current_num_threads();
        if threads < 2 || !self.overflow.is_empty() || !self.groups.is_empty() || self.wide.is_empty() {
            return false;
        }
        self.team_steps += 1;
        let soft = self.soft;
        // (Mass-ratio groups never get here; with restitution the groups warm start each
        // substep. See `solver::solve_step`.)
        let carries = self.carries_warm_start() && carry.len() >= states.len();
        let bodies_per_thread = team_bodies_per_thread(sims.len(), threads);
        let colours = self.team_blocks(threads, bodies_per_thread);
        let bodies = [team_body_blocks(sims.len(), threads, bodies_per_thread)];
        let progress = TeamProgress::new();
        let times_out = std::sync::Mutex::new([0.0f32; 5]);
        let work = |k: usize| {
            let mut lap = Stopwatch::start();
            let mut t = [0.0f32; 5];
            let mut at = TeamCursor::default();
            for i in 0..ctx.substeps {
                let elapsed = i as f32 * ctx.h;
                let carried = carries && i > 0;
                team_pass(&bodies, k, &mut at, &progress, |range| {
                    for b in range.clone() {
                        if let (Some(sim), Some(state)) = (sims.get(b), states.get(b)) {
                            let c = if carried { carry.get(b) } else { None };
                            integrate_velocity_one(ctx.h, sim, state, c);
                        }
                    }
                });
                t[0] += lap.lap();
                if !carried {
                    team_colours(&colours, k, &mut at, &progress, |h, r, rare, _, _| {
                        contact_wide::warm_start(h, r, rare, states)
                    });
                }
                t[1] += lap.lap();
                team_colours(&colours, k, &mut at, &progress, |h, _, rare, w, dv| {
                    contact_wide::solve::<true, SharedState>(h, rare, w, dv, states, ctx, &soft, elapsed, None)
                });
                t[2] += lap.lap();
                team_pass(&bodies, k, &mut at, &progress, |range| {
                    integrate_positions_range(ctx, sims, states, range.clone());
                });
                t[3] += lap.lap();
                let into = (carries && i + 1 < ctx.substeps).then_some(carry);
                team_colours(&colours, k, &mut at, &progress, |h, _, rare, w, dv| {
                    contact_wide::solve::<false, SharedState>(h, rare, w, dv, states, ctx, &soft, elapsed + ctx.h, into)
                });
                t[4] += lap.lap();
            }
            if k == 0 {
                *times_out.lock().unwrap_or_else(|e| e.into_inner()) = t;
            }
        };
        // Thread 0's work on this thread, the others' spawned: a spawned share that no
        // other thread has started when this one is done runs here, and finds every pass
        // done (rayon's scope runs its own pending jobs while it waits), so the step never
        // waits for a thread that is not running.
        crate::solver::awake::stage(threads, || {
            rayon::scope(|s| {
                for k in 1..threads {
                    let work = &work;
                    s.spawn(move |_| work(k));
                }
                work(0);
            })
        });
        *times = times_out.into_inner().unwrap_or_else(|e| e.into_inner());
        true
    }

    /// Which thread builds which groups: with threads, when the team's cuts of this layout
    /// are known (a layout kept from the last step, whose solve cut it), each thread takes
    /// the groups it solves ([`ContactSolver::team_shares`]), in [`GROUP_CHUNK`]s: the
    /// chunks in ascending order, each with its thread, and the thread count; else `None`
    /// (the groups cut into one run per thread by count). Built by the thread that solves
    /// them, a group's lines stay in that core's cache for the first warm start; built by
    /// the other (a run by count crosses the colours' cuts), they were fetched across: on
    /// two threads large_pyramid's `build_group` took 70 % more processor time than on one.
    /// Which thread builds a group changes no result.
    fn build_shares(&self, ctx: &StepContext, bodies: usize) -> Option<(BuildChunks, usize)> {
        if !ctx.parallel {
            return None;
        }
        let threads = rayon::current_num_threads();
        let (at, _) = self.cuts_cache.as_ref()?;
        if at.2 != team_bodies_per_thread(bodies, threads) {
            return None;
        }
        let mut chunks = Vec::new();
        for (r, k) in self.team_shares(threads)? {
            let mut at = r.start;
            while at < r.end {
                let next = (at + GROUP_CHUNK).min(r.end);
                chunks.push((at..next, k));
                at = next;
            }
        }
        Some((chunks, threads))
    }

    /// The groups each thread of a team of `threads` solves, when the team's cuts of this
    /// layout are known: ascending ranges that cover every group, each with its thread (the
    /// groups between cuts, if any, go to the first thread), a thread's neighbouring
    /// ranges merged; else `None`.
    fn team_shares(&self, threads: usize) -> Option<BuildChunks> {
        let (at, cuts) = self.cuts_cache.as_ref()?;
        if threads < 2 || at.0 != self.layouts || at.1 != threads {
            return None;
        }
        let mut shares: BuildChunks = Vec::new();
        let mut push = |k: usize, a: usize, b: usize| {
            if a >= b {
                return;
            }
            match shares.last_mut() {
                Some((r, j)) if *j == k && r.end == a => r.end = b,
                _ => shares.push((a..b, k)),
            }
        };
        let mut done = 0usize;
        for at in cuts.iter().flatten() {
            let Some(&first) = at.first() else { continue };
            if first > done {
                push(0, done, first);
            }
            for (k, w) in at.windows(2).enumerate() {
                push(k, w[0].max(done), w[1].max(done));
            }
            done = done.max(at.last().copied().unwrap_or(done));
        }
        push(0, done, self.head.len());
        Some(shares)
    }

    /// The contact of group `g`'s first lane (`None` for an empty lane or no group).
    fn first_contact(&self, g: usize) -> Option<usize> {
        match (self.lane_candidates.get(g), self.cold.get(g)) {
            (Some(lanes), Some(cold)) if lanes[0] != u32::MAX => Some(cold.contact[0] as usize),
            _ => None,
        }
    }

    /// [`ContactSolver::contact_owners`]: where each thread's share of the team (`shares`,
    /// [`ContactSolver::team_shares`]) starts in the contact list (of `contacts` slots),
    /// into `out`; empty without a team's cuts. A share whose first contact does not lie
    /// after the last start (contacts made since the last renumbering) joins the share
    /// before.
    fn find_contact_owners(&self, shares: Option<&BuildChunks>, contacts: usize, out: &mut Vec<(usize, usize)>) {
        out.clear();
        let Some(shares) = shares else {
            return;
        };
        for &(ref r, k) in shares {
            let Some(first) = self.first_contact(r.start) else {
                continue;
            };
            match out.last_mut() {
                None => out.push((0, k)),
                Some(last) if last.1 == k => {}
                Some(last) => {
                    if first > last.0 && first < contacts {
                        out.push((first, k));
                    }
                }
            }
        }
        if out.len() < 2 {
            out.clear();
        }
    }

    /// The team's blocks: per colour, its front and back parts (see [`fast_first`]), each
    /// cut where its constraints pass from one thread's bodies to the next one's (thread
    /// `k` integrates bodies `k·per_thread ..`; a constraint belongs with its lower dynamic
    /// body) and then into blocks of [`TEAM_BLOCK`] groups. Inside a part the constraints
    /// lie in contact order, which follows the bodies (contacts are renumbered in the
    /// layout's order, and made in shape order), so a thread's share of every colour
    /// touches mostly its own bodies: their states stay in its cache from colour to colour
    /// and stage to stage. Cut by block counts instead, the shares of successive colours
    /// ended at different bodies, and about 15 000 cache lines of states crossed between the
    /// two cores per large_pyramid step. Where a part is not in body order the cuts are only
    /// worse, never wrong: every block is still solved once per pass.
    /// [`ContactSolver::team_blocks`]' group boundaries: per colour, per part, the groups
    /// where each thread's share starts, then the part's end.
    ///
    /// [`fast_first`]: crate::solver::candidates::fast_first
    #[super::lane_fn]
    fn team_cuts(&self, threads: usize, per_thread: usize) -> TeamCuts {
        let owner_key = |h: &WideHead| {
            let (a, b) = (h.index_a[0], h.index_b[0]);
            (if a == 0 || (b != 0 && b < a) { b } else { a }) as usize
        };
        let mut cuts: TeamCuts = Vec::with_capacity(self.ranges.len());
        for ((&(start, end), &slow), &single) in self.ranges.iter().zip(&self.slow_start).zip(&self.single_start) {
            let mut parts = Vec::with_capacity(3);
            let (start, slow, single, end) = (start as usize, slow as usize, single as usize, end as usize);
            for (a, b) in [(start, slow), (slow, single), (single, end)] {
                if a >= b {
                    continue;
                }
                let heads = self.head.get(a..b).unwrap_or(&[]);
                let mut at = vec![a];
                for k in 1..threads {
                    let cut = a + heads.partition_point(|h| owner_key(h) < k * per_thread);
                    at.push(cut.max(at[k - 1]));
                }
                at.push(b);
                parts.push(at);
            }
            cuts.push(parts);
        }
        cuts
    }

    #[super::lane_fn]
    fn team_blocks(&mut self, threads: usize, per_thread: usize) -> Vec<Vec<TeamPart<GroupBlock<'_>>>> {
        // Group boundaries, in order: per colour, per part, per thread. Found by binary
        // searches over the groups' first lanes, lines the build has just written on
        // either thread (a serial 10 µs of large_pyramid's two-thread step), so kept with
        // the layout they were found for.
        let id = (self.layouts, threads, per_thread);
        let cuts = match self.cuts_cache.take() {
            Some((at, cuts)) if at == id => cuts,
            _ => self.team_cuts(threads, per_thread),
        };
        // The arrays the passes write, cut together; those they only read, alongside.
        let mut written = (&mut self.head[..], &mut self.rare[..], &mut self.wide[..]);
        let (mut arms, mut derived): (&[WideArms], &[WideDerived]) = (&self.arms, &self.derived);
        let mut taken = 0usize;
        let mut colours = Vec::with_capacity(cuts.len());
        for parts in &cuts {
            let mut out = Vec::with_capacity(parts.len());
            for at in parts {
                // (`team_cuts` makes ascending cuts from `taken` on.)
                debug_assert!(at[0] >= taken && at.windows(2).all(|w| w[0] <= w[1]));
                let skip = at[0].saturating_sub(taken);
                written = written.split_at(skip).1;
                (arms, derived) = (arms.get(skip..).unwrap_or(&[]), derived.get(skip..).unwrap_or(&[]));
                taken = at[0];
                let mut part = TeamPart {
                    blocks: Vec::new(),
                    shares: Vec::with_capacity(threads + 1),
                };
                for k in 0..threads {
                    part.shares.push(part.blocks.len());
                    let len = at[k + 1].saturating_sub(at[k]);
                    let ((h, x, w), rest) = written.split_at(len);
                    let (r, d) = (arms.get(..len).unwrap_or(arms), derived.get(..len).unwrap_or(derived));
                    written = rest;
                    (arms, derived) = (arms.get(len..).unwrap_or(&[]), derived.get(len..).unwrap_or(&[]));
                    taken = at[k + 1];
                    let blocks = h
                        .chunks_mut(TEAM_BLOCK)
                        .zip(r.chunks(TEAM_BLOCK))
                        .zip(x.chunks_mut(TEAM_BLOCK))
                        .zip(w.chunks_mut(TEAM_BLOCK))
                        .zip(d.chunks(TEAM_BLOCK));
                    for ((((hs, rs), xs), ws), ds) in blocks {
                        part.blocks
                            .push(TeamBlock::new(std::sync::Mutex::new((hs, rs, xs, ws, ds))));
                    }
                }
                part.shares.push(part.blocks.len());
                out.push(part);
            }
            colours.push(out);
        }
        self.cuts_cache = Some((id, cuts));
        colours
    }

    /// Refreshes a copy's state from its slot (the coloured passes changed it).
    #[super::lane_fn]
    fn sync_from(&self, slot: Slot, cc: &mut ContactConstraint) {
        match slot {
            Slot::Wide { group, lane } => {
                let g = group as usize;
                contact_wide::unpack_state(&self.head[g], &self.rare[g], &self.wide[g], lane as usize, cc)
            }
            Slot::Overflow(i) => *cc = self.overflow[i as usize],
        }
    }
}

// The build's entries for the world, `unsafe` for the same reason as the passes above.
#[allow(unsafe_code, unused_unsafe)]
impl crate::solver::WideContacts for ContactSolver {
    fn layout_size(&self) -> (usize, usize) {
        (self.head.len(), self.ranges.len())
    }
    fn build_step<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        sims: &[BodySim],
        candidates: Candidates<'_>,
        loaded: bool,
        up: Vec2,
    ) {
        self.up = up;
        // SAFETY: see `impl ConstraintSet for ContactSolver`.
        unsafe { self.build(ctx, states, sims, candidates, loaded) }
    }

    fn store_step<S: StateRead + Sync>(
        &mut self,
        ctx: &StepContext,
        states: &[S],
        contacts: &mut [Option<Contact>],
        sums: &mut [ContactSums],
    ) {
        // SAFETY: see `impl ConstraintSet for ContactSolver`.
        unsafe { self.store(ctx, states, contacts, sums) }
    }
}

#[cfg(test)]
#[super::lane_tests]
mod tests {
    use super::*;
    use core::sync::atomic::{AtomicBool, AtomicU32, Ordering::Relaxed};

    /// Two threads' shares of `n` blocks, each block counting the passes that ran it.
    fn counting_part(n: usize) -> TeamPart<TeamBlock<AtomicU32>> {
        TeamPart {
            blocks: (0..n).map(|_| TeamBlock::new(AtomicU32::new(0))).collect(),
            shares: vec![0, n / 2, n],
        }
    }

    /// Runs `passes` passes as thread `k`: each block checks that every block ran the pass
    /// before (the pass order a team relies on) and counts itself.
    fn run_passes(
        part: &TeamPart<TeamBlock<AtomicU32>>,
        k: usize,
        passes: u32,
        progress: &TeamProgress,
        ok: &AtomicBool,
    ) {
        let parts = core::slice::from_ref(part);
        let mut at = TeamCursor::default();
        for pass in 1..=passes {
            team_pass(parts, k, &mut at, progress, |count| {
                if part.blocks.iter().any(|b| b.work.load(Relaxed) + 1 < pass) || count.load(Relaxed) != pass - 1 {
                    ok.store(false, Relaxed);
                }
                // A few microseconds of work, so the two threads' passes overlap.
                let mut x = 1.0f32;
                for _ in 0..2000 {
                    x = core::hint::black_box(x * 1.000_1);
                }
                count.fetch_add(1, Relaxed);
            });
        }
    }

    /// A thread of a two-thread team that never comes does not hold up the other: it runs
    /// every block once per pass by itself (a barrier that waits for every thread would
    /// never return), and the late thread, when it comes, finds every pass done.
    #[test]
    fn team_passes_finish_without_the_other_thread() {
        let (part, progress, ok) = (counting_part(7), TeamProgress::new(), AtomicBool::new(true));
        run_passes(&part, 0, 5, &progress, &ok);
        assert!(part.blocks.iter().all(|b| b.work.load(Relaxed) == 5));
        run_passes(&part, 1, 5, &progress, &ok);
        assert!(
            part.blocks.iter().all(|b| b.work.load(Relaxed) == 5),
            "a late thread ran a pass again"
        );
        assert!(ok.load(Relaxed) && progress.reached(35));
    }

    /// Two threads, one starting late: every block runs exactly once per pass, and no
    /// block of a pass runs before every block of the pass before it.
    #[test]
    fn team_passes_run_each_block_once_in_pass_order() {
        let (part, progress, ok) = (counting_part(16), TeamProgress::new(), AtomicBool::new(true));
        std::thread::scope(|s| {
            s.spawn(|| run_passes(&part, 0, 200, &progress, &ok));
            s.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(1));
                run_passes(&part, 1, 200, &progress, &ok)
            });
        });
        assert!(ok.load(Relaxed), "a block ran out of pass order or twice in a pass");
        assert!(part.blocks.iter().all(|b| b.work.load(Relaxed) == 200));
    }

    /// The build's shares cut the group arrays into chunks that each thread owns: every
    /// group lies in exactly one chunk, of the thread whose share holds its range, at its
    /// own index (ranges interleaved between threads, as a colour's cuts are, and a gap).
    #[test]
    fn build_shares_cut_every_group_once_for_its_thread() {
        let n = 40;
        let (mut h, mut w) = (vec![WideHead::default(); n], vec![WideContact::default(); n]);
        let (mut c, mut d) = (vec![WideCold::default(); n], vec![WideDerived::default(); n]);
        for (g, cold) in c.iter_mut().enumerate() {
            cold.contact[0] = g as u32;
        }
        let shares = vec![vec![0..5, 12..20, 30..40], vec![5..12, 20..28]];
        let mut chunks: Vec<_> = (0..2)
            .flat_map(|k| shares[k].iter().map(move |r| (r.clone(), k)))
            .collect();
        chunks.sort_unstable_by_key(|(r, _)| r.start);
        let out = split_shares((&mut h[..], &mut w[..], &mut c[..], &mut d[..]), &chunks, 2);
        let mut owner = vec![None; n];
        for (k, chunks) in out.iter().enumerate() {
            for (first, (hs, ws, cs, ds)) in chunks {
                assert!(hs.len() == ws.len() && ws.len() == cs.len() && cs.len() == ds.len());
                for (j, cold) in cs.iter().enumerate() {
                    assert_eq!(cold.contact[0] as usize, first + j, "a chunk's first index");
                    assert_eq!(owner[first + j], None, "group {} in two chunks", first + j);
                    owner[first + j] = Some(k);
                }
            }
        }
        for (g, o) in owner.iter().enumerate() {
            let want = shares.iter().position(|s| s.iter().any(|r| r.contains(&g)));
            assert_eq!(*o, want, "group {g}");
        }
    }
}
