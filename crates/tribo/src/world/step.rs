//! `World::step`: the table of contents of a step, and its phases.
//!
//! 1. [`World::update_pairs`]: broad phase; moved proxies find new pairs → contacts.
//! 2. [`World::collide`]: narrow phase; manifolds, begin/end events, waking.
//! 3. [`World::solve`]: solver stages (see [`crate::solver`]), impulses stored back.
//! 4. [`World::finalize`]: poses from the solver, swept fat boxes, sleep timers.
//! 5. [`World::update_sleep`]: islands that rested long enough fall asleep.

use super::{ContactBeginEvent, ContactEndEvent, ShapeBounds, Stopwatch, World};
use crate::collision::broad_phase::{MOVING_TREE, STATIC_TREE};
use crate::collision::contact::{pair_key, Contact, ContactSums, Memo, NarrowOutcome};
use crate::dynamics::body::Body;
use crate::dynamics::shape::ShapeRecord;
use crate::dynamics::{mix, BodyType};
use crate::error::{Error, Result};
use crate::geometry::{Shape, SPECULATIVE_DISTANCE};
use crate::math::{Rot, Vec2};
use crate::solver::candidates::{Candidate, Candidates, ColourKey};
use crate::solver::WideContacts;
use crate::solver::{
    claim_each, claim_into, for_each_chunk_mut, for_each_mut, loads, solve_step, BodySim, BodyState, SharedState,
    SolverBody, StepConstraints, StepContext,
};
use crate::world::Arena;
use crate::world::{box_velocity, exceeds, next_box, Moved};
use crate::world::{BodyId, ShapeId};

impl World {
    /// Advances the world by `dt` [s] (usually 1/60) in `WorldDef::substeps` substeps.
    /// `dt = 0` does nothing. Contact events of the step are read afterwards with
    /// [`World::contact_events`].
    pub fn step(&mut self, dt: f32) -> Result<()> {
        if !dt.is_finite() || dt < 0.0 {
            return Err(Error::arg("dt", format!("must be finite and ≥ 0 (got {dt})")));
        }
        self.events.begin.clear();
        self.events.end.clear();
        self.non_finite.clear();
        if dt == 0.0 {
            return Ok(());
        }
        match self.pool.take() {
            Some(pool) => {
                // Inside the pool the parallel stages split their work between its threads.
                pool.install(|| {
                    let _awake = crate::solver::awake::Step::start();
                    self.run_step(dt, true)
                });
                self.pool = Some(pool);
            }
            None => self.run_step(dt, false),
        }
        Ok(())
    }

    /// The stages of one step; `parallel`: running inside the world's thread pool.
    fn run_step(&mut self, dt: f32, parallel: bool) {
        let mut total = Stopwatch::start();
        let mut lap = Stopwatch::start();
        // (No refit is pending here, unless a step was cut short: see finalize below.)
        self.broad_phase.refit();
        self.reorder_contacts();
        self.update_pairs(parallel);
        self.profile.pairs = lap.lap();
        self.prepare_bodies(parallel);
        let bodies_ms = lap.lap();
        self.collide(dt, parallel);
        self.profile.collide = lap.lap();
        let ctx = self.step_context(dt, parallel);
        self.solve(&ctx, bodies_ms);
        lap.lap();
        // The trees are refitted once after all the moves (see `BroadPhase::defer_refits`).
        self.broad_phase.defer_refits = true;
        self.finalize(dt, parallel);
        self.broad_phase.refit();
        self.profile.finalize = lap.lap();
        self.update_sleep(dt);
        self.profile.sleep = lap.lap();
        self.profile.step = total.lap();
        self.step_count += 1;
    }

    fn step_context(&self, dt: f32, parallel: bool) -> StepContext {
        let substeps = self.def.substeps.max(1);
        let h = dt / substeps as f32;
        // Box2D v3 clamps the contact frequency to 1/8 of the substep rate.
        let hertz = self.def.contact_hertz.min(0.125 / h);
        let zeta = self.def.contact_damping_ratio;
        StepContext {
            dt,
            h,
            inv_h: 1.0 / h,
            substeps,
            contact_hertz: hertz,
            contact_damping_ratio: zeta,
            push_speed: self.def.contact_push_speed,
            stick_speed: self.def.stick_speed,
            max_linear_speed: self.def.max_linear_speed,
            warm_starting: self.def.warm_starting,
            parallel,
        }
    }

    /// Broad phase: query the trees with every moved proxy and create contacts for new
    /// pairs, in sorted pair order (deterministic).
    fn update_pairs(&mut self, parallel: bool) {
        let mut moved = core::mem::take(&mut self.broad_phase.moved);
        moved.sort_unstable();
        moved.dedup();
        for &si in &moved {
            if let Some(s) = self.shapes.at_mut(si) {
                s.moved = true;
            }
        }
        // When most of the moving tree moved (a pile in motion), its pairs are found all at
        // once instead of by a query per moved shape: by sweep and prune over its boxes, or
        // where that would test too many, by one walk of the tree against itself (see
        // `moving_tree_pairs`). Each overlapping pair is met once, not once from each side.
        // The moved shapes then query only the static tree.
        let moving = MOVING_TREE as usize;
        let count = self.broad_phase.trees[moving].proxy_count();
        let walk = count > 0 && WALK_SHARE * moved.len() >= count;
        #[cfg(test)]
        let walk = walk && !self.broad_phase.no_walk;
        let mut new_pairs: Vec<u64> = Vec::new();
        if walk {
            self.moving_tree_pairs(&moved, parallel, &mut new_pairs);
        }
        // (With the moving tree's pairs found, only moved static shapes query it: no copy.)
        let use_flat = self.broad_phase.prepare_queries(moved.len(), [false, walk]);
        // With the moving tree's pairs found (swept or walked), the moved shapes only have
        // the static tree left to query.
        let queries: &[u32] = if walk && self.broad_phase.trees[STATIC_TREE as usize].proxy_count() == 0 {
            &[]
        } else {
            &moved
        };
        // On threads, in chunks of moved shapes, each chunk's pairs in a list of its own
        // (read-only queries: sorted below, the pairs are the same whatever the split).
        if parallel && queries.len() >= 2 * PAIR_CHUNK {
            let this = &*self;
            claim_into(queries.chunks(PAIR_CHUNK), &mut new_pairs, |chunk, out| {
                this.query_pairs(chunk, walk, use_flat, out)
            });
        } else {
            self.query_pairs(queries, walk, use_flat, &mut new_pairs);
        }
        for &si in &moved {
            if let Some(s) = self.shapes.at_mut(si) {
                s.moved = false;
            }
        }
        moved.clear();
        self.broad_phase.moved = moved;
        new_pairs.sort_unstable();
        new_pairs.dedup();
        for key in new_pairs {
            self.create_contact((key >> 32) as u32, key as u32);
        }
    }

    /// The new pairs of the moved shapes of `queries` with the trees' other shapes, into
    /// `out` (see [`World::update_pairs`]): each queries the static tree, and the moving
    /// one too unless its pairs were found at once (`walk`); `use_flat`: which trees'
    /// [`FlatTree`] copies are current. Reads only.
    fn query_pairs(&self, queries: &[u32], walk: bool, use_flat: [bool; 2], out: &mut Vec<u64>) {
        let mut hits: Vec<u32> = Vec::new();
        for (j, &si) in queries.iter().enumerate() {
            // The moved shapes' records, their bodies and the bodies' key lists are asked
            // for a few shapes ahead (each needs the one before it: a chain of misses).
            self.prefetch_pair_data(queries, j);
            let Some(s) = self.shapes.at(si) else { continue };
            let Some(body) = self.bodies.at(s.body.index) else {
                continue;
            };
            let trees: &[u8] = if s.tree == STATIC_TREE {
                &[MOVING_TREE]
            } else if walk {
                &[STATIC_TREE]
            } else {
                &[MOVING_TREE, STATIC_TREE]
            };
            // Most boxes a moved shape overlaps already have their contact: the cheap
            // tests come first, the bodies (for their types) only for a new pair.
            // The overlaps first (a small callback the walk inlines), then the pair tests.
            hits.clear();
            for &tree in trees {
                let t = tree as usize;
                let found = |_, data| {
                    hits.push(data as u32);
                    true
                };
                if use_flat[t] {
                    self.broad_phase.flat[t].query(s.fat_aabb, s.filter.mask, found);
                } else {
                    self.broad_phase.trees[t].query(s.fat_aabb, s.filter.mask, found);
                }
            }
            for &other in &hits {
                // An existing pair is found in the moved body's short key list before
                // the other shape's record is read (most overlaps are existing pairs).
                if other == si || self.pair_exists(body, pair_key(si, other)) {
                    continue;
                }
                let Some(o) = self.shapes.at(other) else { continue };
                // When both moved, the lower index reports the pair.
                if !(o.moved && other < si) && self.may_pair(s, body, o) {
                    out.push(pair_key(si, other));
                }
            }
        }
    }

    /// The new pairs of two shapes of the moving tree, one of which moved, into
    /// `new_pairs` (see [`World::update_pairs`]): the overlapping pairs from a sweep and
    /// prune over the tree's boxes (`SweepPrune`: sorted along one axis in bands across
    /// it, each box tested against those of its bands starting inside its interval;
    /// tumbler's pairs stage 0.556 → 0.27 ms), or, where the boxes are crowded on both
    /// axes so that the sweep would test too many, from one walk of the tree's
    /// [`FlatTree`] copy against itself; the same pairs either way. A pair with a contact
    /// is found in the pair table without reading either shape's record.
    fn moving_tree_pairs(&mut self, moved: &[u32], parallel: bool, new_pairs: &mut Vec<u64>) {
        let mut mark = core::mem::take(&mut self.broad_phase.moved_mark);
        mark.clear();
        mark.resize(self.shapes.capacity(), false);
        for &si in moved {
            if let Some(m) = mark.get_mut(si as usize) {
                *m = true;
            }
        }
        let mut keys = core::mem::take(&mut self.broad_phase.scratch_keys);
        keys.clear();
        let moving = MOVING_TREE as usize;
        let bp = &mut self.broad_phase;
        #[cfg(test)]
        let try_sweep = !bp.no_sweep;
        #[cfg(not(test))]
        let try_sweep = true;
        let threads = if parallel { rayon::current_num_threads() } else { 1 };
        let swept = try_sweep && bp.sweep.moved_pairs(&bp.trees[moving], &mark, threads, &mut keys);
        if !swept {
            keys.clear();
            bp.walks += 1;
            bp.make_flat(moving);
            bp.flat[moving].self_pairs(|a, b| {
                let moved = |s: u64| mark.get(s as usize).copied().unwrap_or(false);
                if moved(a) || moved(b) {
                    keys.push(pair_key(a as u32, b as u32));
                }
            });
        }
        // The keys are looked up after the walk, in a loop of lookups whose cache misses
        // overlap: inside the walk, among its branches, each waited alone (5 % of smash's
        // step at one instruction; pairs stage 1.54 → 1.44 ms in smash, 2.26 → 2.14 in
        // rain, 0.504 → 0.490 in tumbler).
        // On threads, in chunks of keys, each chunk's new pairs in a list of its own
        // (lookups only; sorted by the caller, the pairs are the same whatever the split).
        if parallel && keys.len() >= 2 * KEY_CHUNK {
            let this = &*self;
            claim_into(keys.chunks_mut(KEY_CHUNK), new_pairs, |chunk, out| {
                this.new_pairs_of(chunk, out)
            });
        } else {
            self.new_pairs_of(&mut keys, new_pairs);
        }
        self.broad_phase.scratch_keys = keys;
        self.broad_phase.moved_mark = mark;
    }

    /// The pairs of `keys` (overlapping boxes) that have no contact and may pair, into
    /// `out`; `keys` is scratch (reordered, its tail overwritten).
    fn new_pairs_of(&self, keys: &mut [u64], out: &mut Vec<u64>) {
        let pairs = &self.broad_phase.pairs;
        // The pairs without a contact moved to the front, in order (a `retain` in place).
        let mut kept = 0;
        for k in 0..keys.len() {
            let Some(&key) = keys.get(k) else { break };
            if !pairs.contains_key(&key) {
                if let Some(slot) = keys.get_mut(kept) {
                    *slot = key;
                }
                kept += 1;
            }
        }
        for &key in keys.get(..kept).unwrap_or(&[]) {
            let (sa, sb) = ((key >> 32) as u32, key as u32);
            let (Some(s), Some(o)) = (self.shapes.at(sa), self.shapes.at(sb)) else {
                continue;
            };
            if self
                .bodies
                .at(s.body.index)
                .is_some_and(|body| self.may_pair(s, body, o))
            {
                out.push(key);
            }
        }
    }

    /// Whether shapes `s` (of `body`) and `o`, whose boxes overlap and which have no
    /// contact, make a new pair: other bodies, filters that let them collide, a dynamic
    /// side, and no joint between the bodies that turns their collision off.
    #[inline]
    fn may_pair(&self, s: &ShapeRecord, body: &Body, o: &ShapeRecord) -> bool {
        if o.body == s.body || !s.filter.should_collide(&o.filter) {
            return false;
        }
        let dynamic = body.is_dynamic() || self.bodies.at(o.body.index).is_some_and(|b| b.is_dynamic());
        dynamic && (body.joints.is_empty() || !self.joint_blocks_pair(s.body.index, o.body.index))
    }

    /// [`World::update_pairs`]' prefetch at the `j`-th moved shape: the shape record
    /// [`PAIR_PREFETCH`] ahead, the body of the one half as far ahead (its shape is then
    /// cached), the key list of the next one's body.
    #[inline]
    fn prefetch_pair_data(&self, moved: &[u32], j: usize) {
        if let Some(&far) = moved.get(j + PAIR_PREFETCH) {
            self.shapes.prefetch(far);
        }
        if let Some(s) = moved.get(j + PAIR_PREFETCH / 2).and_then(|&mid| self.shapes.at(mid)) {
            self.bodies.prefetch(s.body.index);
        }
        let near = moved.get(j + 1).and_then(|&near| self.shapes.at(near));
        if let Some(key) = near
            .and_then(|s| self.bodies.at(s.body.index))
            .and_then(|b| b.contact_keys.first())
        {
            crate::solver::prefetch(key);
        }
    }

    /// Whether the pair with `key` has a contact, `body` being one of its bodies: found in
    /// the body's short key list before the world's pair table (every key compared, no
    /// early exit: where the match sits is unpredictable, a branch per key mispredicted).
    #[inline]
    pub(crate) fn pair_exists(&self, body: &Body, key: u64) -> bool {
        if body.contact_keys.len() <= SHORT_CONTACT_LIST {
            body.contact_keys.iter().fold(false, |found, &k| found | (k == key))
        } else {
            self.broad_phase.pairs.contains_key(&key)
        }
    }

    /// Whether the pair with `key` has a contact with manifold points this step, `body`
    /// being one of its bodies (its key list rules most pairs out before the pair table).
    pub(crate) fn pair_has_points(&self, body: &Body, key: u64) -> bool {
        if !self.pair_exists(body, key) {
            return false;
        }
        let contact = self
            .broad_phase
            .pairs
            .get(&key)
            .and_then(|&ci| self.contacts.get(ci as usize));
        // `touching` (the record's first line, which the store just wrote for a solved
        // contact) rather than the manifold's count (its third line, last read by the
        // narrow phase): the same fact (`Contact::update`, `clear_manifold`), and in the
        // spinner's finalize, which asks it for every fast body's static neighbours, the
        // count's line was a cache miss.
        matches!(contact, Some(Some(c)) if c.touching)
    }

    fn create_contact(&mut self, sa: u32, sb: u32) {
        let (Some(a), Some(b)) = (self.shapes.at(sa), self.shapes.at(sb)) else {
            return;
        };
        let (body_a, body_b) = (a.body.index, b.body.index);
        let list_pos = [body_a, body_b].map(|bi| self.bodies.at(bi).map_or(0, |b| b.contacts.len() as u32));
        let (shape_a, shape_b) = (
            super::ShapeId {
                index: sa,
                generation: self.shapes.generation(sa),
            },
            super::ShapeId {
                index: sb,
                generation: self.shapes.generation(sb),
            },
        );
        let ci = match self.contact_free.pop() {
            Some(i) => {
                if let Some(sums) = self.contact_sums.get_mut(i as usize) {
                    *sums = ContactSums::default();
                }
                i
            }
            None => {
                self.contacts.push(None);
                self.contact_sums.resize(self.contacts.len(), ContactSums::default());
                (self.contacts.len() - 1) as u32
            }
        };
        // Written in place over a blank record, field by field: the 320-byte record built
        // on the stack and then copied into its slot had its 16-byte loads wait on the
        // narrower stores that made it, which cannot be forwarded (that copy and `mix`'s,
        // see there, were together a fifth of the samples of `run_step`'s own code in the
        // tumbler, which makes contacts every step).
        let Some(slot) = self.contacts.get_mut(ci as usize) else {
            // (Unreachable: the slot was just pushed, or came from the free list, which
            // only holds slots of the list and is cleared when the list is cut.)
            debug_assert!(false, "contact slot {ci} out of range");
            return;
        };
        let c = slot.insert(Contact::BLANK);
        (c.shape_a, c.shape_b) = (shape_a, shape_b);
        (c.body_a, c.body_b) = (body_a, body_b);
        // (Mixed straight into the record: `mix` is inlined, see there.)
        c.material = mix(&a.material, &b.material);
        c.rolling_radius = rolling_radius(&a.geometry).max(rolling_radius(&b.geometry));
        c.list_pos = list_pos;
        self.broad_phase.pairs.insert(pair_key(sa, sb), ci);
        for bi in [body_a, body_b] {
            // Only the contact lists, which no solver entry reads: not a write the body
            // pass's skip needs to see (`World::next_entries`).
            if let Some(b) = self.bodies.at_mut_quiet(bi) {
                b.contacts.push(ci);
                b.contact_keys.push(pair_key(sa, sb));
            }
        }
    }

    /// Narrow phase: update the manifold of every contact with an awake moving body (split
    /// between the worker threads: each contact only writes itself, its outcome and its
    /// solver candidate); then, in contact order, destroy contacts whose fat boxes
    /// separated, report begin/end, wake sleepers.
    ///
    /// The solver's input of each touching contact ([`Candidate`]) is made here, while the
    /// contact's record is in cache from its update, instead of in a second pass over the
    /// records (they are several cache lines each; 58 000 of them in many_pyramids). It
    /// needs the awake bodies' solver entries, made by [`World::prepare_bodies`] before; a
    /// step that wakes a sleeping island makes them and the candidates again.
    fn collide(&mut self, dt: f32, parallel: bool) {
        let mut active = core::mem::take(&mut self.active_contacts);
        let flags = core::mem::take(&mut self.scratch_flags);
        let mut candidates = core::mem::take(&mut self.candidates);
        let mut keys = core::mem::take(&mut self.colour_keys);
        let mut outcomes = core::mem::take(&mut self.outcomes);
        let mut lists = core::mem::take(&mut self.chunk_outcomes);
        // Slots are written before they are read (every visited contact gets an outcome, a
        // solvable one its candidate and colouring key): no clearing.
        outcomes.resize(self.contacts.len(), (NarrowOutcome::Skipped, false));
        candidates.resize(self.contacts.len(), Candidate::SKIP);
        keys.resize(self.contacts.len(), ColourKey::default());
        // One list per chunk of the parallel pass (one for the whole pass on one thread).
        let chunks = if parallel {
            self.contacts.len().div_ceil(CONTACT_CHUNK).max(1)
        } else {
            1
        };
        lists.resize_with(chunks, Default::default);
        for list in &mut lists {
            list.get_mut().unwrap_or_else(|e| e.into_inner()).clear();
        }
        let (shapes, solver_bodies, bounds) = (
            &self.shapes,
            self.solver_bodies.as_slice(),
            self.shape_bounds.as_slice(),
        );
        // Updates one contact, writes its outcome and, if it is touching with an awake
        // dynamic side, its candidate.
        let update = |ci: usize,
                      c: &mut Contact,
                      cand: &mut Candidate,
                      key: &mut ColourKey,
                      out: &mut (NarrowOutcome, bool),
                      collided: &mut u32| {
            let outcome = narrow_phase(c, solver_bodies, bounds, shapes, dt, collided);
            let solvable = matches!(outcome, NarrowOutcome::Updated { touching: true, .. })
                && candidate(ci as u32, c, solver_bodies, cand, key);
            *out = (outcome, solvable);
        };
        let mostly_awake = self.mostly_awake;
        if mostly_awake {
            // Mostly awake: each contact tests its two bodies' flags itself, in the parallel
            // pass (no serial pass to list the active contacts first, and none to go
            // through them after: each chunk files its own verdicts).
            active.clear();
        } else {
            // Otherwise the active contacts are listed through the awake bodies (in contact
            // order), and each chunk visits its share of the list, not its slots: a sleeping
            // contact costs nothing. (Visiting every slot and testing a mark cost 28
            // instructions a slot: smash's 37 800 contacts while the block sleeps, 1.06 M
            // instructions and 53 µs a step, against Box2D's 3 µs.)
            self.collect_active_contacts(&mut active, &flags, false, false);
        }
        let (flags_ref, active_ref, lists_ref) = (flags.as_slice(), active.as_slice(), lists.as_slice());
        let flag = |bi: u32| flags_ref.get(bi as usize).copied().unwrap_or(false);
        // The shapes' records (their geometry) are asked for too when at least 1 in 8 of the
        // pairs were collided in full last step (a pile in motion: tumbler 15-38 %, smash
        // 12-70 %; collide / solver passes -7 %, and -8 % in smash); when the manifolds are
        // recycled (a resting pile: large_pyramid 0 %) those lines would be loaded for
        // nothing (its collide +13 %).
        let geometry_ahead = self.collided_many;
        // The contact ahead's bodies and shape bounds are asked for whatever the size of
        // their arrays: the contact records stream through the core's L2 and push them out
        // of it. (Until 2026-12 only above 768 KiB of bodies and bounds, three quarters of
        // the L2 of the AMD EPYC the benchmark then ran on, where below it the prefetches
        // were just instructions, two dozen a contact (tumbler, 0.26 MiB: collide +2.4 %
        // with them). On the Intel Xeon since (2 MiB of L2 a core), with them at every
        // size, alternated rounds: tumbler's collide −4 %, compounds' (0.57 MiB) −7 %,
        // large_pyramid's (0.62 MiB) unchanged.)
        let collided_total = core::sync::atomic::AtomicU32::new(0);
        // On threads, after a step the worker team solved, each visits the contacts of the
        // groups it solved (the contacts follow the solver's layout): the candidate and key
        // slots it writes here are those its own core read in last step's build
        // (`ContactSolver::build_shares`), rather than lines the other core holds. Cut by
        // count instead (as after a step without the team), large_pyramid's two-thread
        // collide took 0.29-0.32 ms against 0.25-0.27 (its set-up unchanged).
        let owners = if parallel {
            crate::solver::with_contacts!(&self.contact_solver, s => grid_owners(&s.contact_owners, CONTACT_CHUNK))
        } else {
            Vec::new()
        };
        // (On the chunks' grid, so that each chunk files into its own list below.)
        debug_assert!(owners.iter().all(|o| o.0 % CONTACT_CHUNK == 0));
        let slices = (
            self.contacts.as_mut_slice(),
            candidates.as_mut_slice(),
            keys.as_mut_slice(),
            outcomes.as_mut_slice(),
        );
        type Chunk<'c> = (
            &'c mut [Option<Contact>],
            &'c mut [Candidate],
            &'c mut [ColourKey],
            &'c mut [(NarrowOutcome, bool)],
        );
        let run = |first: usize, (slots, cands, keys, outs): Chunk<'_>| {
            let mut collided = 0u32;
            let len = slots.len();
            // The active contacts of this chunk (all its slots when mostly awake).
            // A listed contact's slot in this chunk (the list's share below holds only
            // contacts from `first` on).
            let local = |ci: u32| (ci as usize).wrapping_sub(first);
            let mine = if mostly_awake {
                &[][..]
            } else {
                let lo = active_ref.partition_point(|&ci| (ci as usize) < first);
                let hi = active_ref.partition_point(|&ci| (ci as usize) < first + len);
                active_ref.get(lo..hi).unwrap_or(&[])
            };
            // Visits slot `k`; `record` and `near`: the slots of the contacts whose
            // record, and whose bodies and bounds, are asked for ahead.
            // (A macro, not a closure: called from two loops, a closure was not inlined,
            // and the mostly-awake loop ran 29 % more instructions.)
            macro_rules! visit {
                ($k:expr, $record:expr, $near:expr) => {{
                    let (k, record, near): (usize, Option<usize>, Option<usize>) = ($k, $record, $near);
                    // The record of a contact further ahead, all five lines: the hardware
                    // prefetcher does not keep far enough ahead of this stream
                    // (many_pyramids, 58 000 recycled contacts, 18.5 MB a step: the wait
                    // for the record read four ahead below was three quarters of this
                    // loop's samples, and collide fell from 1.27-1.53 to 0.79-0.89
                    // relax units with it).
                    if let Some(far) = record.and_then(|r| slots.get(r)) {
                        crate::solver::prefetch(far);
                    }
                    // The bodies and shape bounds of a contact a few ahead: loads that
                    // miss (contacts come in solver order, not body order) and that the
                    // narrow phase needs before anything else.
                    if let Some(Some(ahead)) = near.and_then(|r| slots.get(r)) {
                        for bi in [ahead.body_a, ahead.body_b] {
                            if let Some(sb) = solver_bodies.get(bi as usize) {
                                crate::solver::prefetch(sb);
                            }
                        }
                        for id in [ahead.shape_a, ahead.shape_b] {
                            if let Some(sb) = bounds.get(id.index as usize) {
                                crate::solver::prefetch(sb);
                            }
                            if geometry_ahead {
                                shapes.prefetch_n(id.index, 3);
                            }
                        }
                    }
                    let (Some(slot), Some(cand), Some(key), Some(out)) = (
                        slots.get_mut(k),
                        cands.get_mut(k),
                        keys.get_mut(k),
                        outs.get_mut(k),
                    ) else {
                        continue;
                    };
                    match slot.as_mut() {
                        Some(c) if !mostly_awake || flag(c.body_a) || flag(c.body_b) => {
                            update(first + k, c, cand, key, out, &mut collided)
                        }
                        _ => *out = (NarrowOutcome::Skipped, false),
                    }
                }};
            }
            if mostly_awake {
                for k in 0..len {
                    visit!(k, Some(k + RECORD_PREFETCH), Some(k + NARROW_PREFETCH));
                }
            } else {
                let slot_of = |j: usize| mine.get(j).map(|&ci| local(ci));
                for (j, &ci) in mine.iter().enumerate() {
                    visit!(local(ci), slot_of(j + RECORD_PREFETCH), slot_of(j + NARROW_PREFETCH));
                }
            }
            // The chunk's verdicts filed in its lists, from the dense outcomes just
            // written (kept out of the loop above, whose pushes slowed it).
            if let Some(list) = lists_ref.get(first / CONTACT_CHUNK) {
                let mut list = list.lock().unwrap_or_else(|e| e.into_inner());
                if mostly_awake {
                    for (k, &(outcome, solvable)) in outs.iter().enumerate() {
                        list.note((first + k) as u32, outcome, solvable);
                    }
                } else {
                    for &ci in mine {
                        if let Some(&(outcome, solvable)) = outs.get(local(ci)) {
                            list.note(ci, outcome, solvable);
                        }
                    }
                }
            }
            collided_total.fetch_add(collided, core::sync::atomic::Ordering::Relaxed);
        };
        if owners.len() > 1 {
            crate::solver::for_each_chunk_mut_owned(slices, &owners, CONTACT_CHUNK, run);
        } else {
            for_each_chunk_mut(parallel, slices, CONTACT_CHUNK, run);
        }
        // Of the contacts visited: every slot when mostly awake, else the listed ones.
        let visited = if mostly_awake {
            self.contacts.len()
        } else {
            active.len()
        };
        self.collided_many = 8 * collided_total.into_inner() as usize >= visited;
        self.scratch_flags = flags;
        let mut to_destroy = Vec::new();
        let mut to_wake = Vec::new();
        let mut unsolved = core::mem::take(&mut self.unsolved_contacts);
        let mut solvable = core::mem::take(&mut self.solver_contacts);
        unsolved.clear();
        solvable.clear();
        // The chunks' lists in contact order; a contact's record is read only when its
        // touching changed.
        for list in &mut lists {
            let list = list.get_mut().unwrap_or_else(|e| e.into_inner());
            solvable.extend_from_slice(&list.solvable);
            unsolved.extend_from_slice(&list.unsolved);
            for &(ci, outcome) in &list.special {
                let NarrowOutcome::Updated { touching: now, .. } = outcome else {
                    to_destroy.push(ci);
                    continue;
                };
                let Some(Some(c)) = self.contacts.get(ci as usize) else {
                    continue;
                };
                if now {
                    self.events.begin.push(ContactBeginEvent {
                        shape_a: c.shape_a,
                        shape_b: c.shape_b,
                        normal: c.manifold.normal,
                        point: c.manifold.points[0].point,
                    });
                    for bi in [c.body_a, c.body_b] {
                        if self.bodies.at(bi).is_some_and(|b| !b.awake) {
                            to_wake.push(bi);
                        }
                    }
                } else {
                    self.events.end.push(ContactEndEvent {
                        shape_a: c.shape_a,
                        shape_b: c.shape_b,
                    });
                }
            }
        }
        self.active_contacts = active;
        self.outcomes = outcomes;
        self.chunk_outcomes = lists;
        for ci in to_destroy {
            self.destroy_contact(ci, false);
        }
        if !to_wake.is_empty() {
            for bi in to_wake {
                self.wake_body(bi);
            }
            // The woken islands' bodies get solver entries (every awake body's index can
            // change) and their contacts join the solve with their last manifolds: the
            // entries and every touching contact's candidate are made again.
            self.prepare_bodies(parallel);
            let flags = core::mem::take(&mut self.scratch_flags);
            let mut touching = Vec::new();
            self.collect_active_contacts(&mut touching, &flags, self.mostly_awake, true);
            self.scratch_flags = flags;
            solvable.clear();
            unsolved.clear();
            for &ci in &touching {
                if let Some(Some(c)) = self.contacts.get(ci as usize) {
                    if let (Some(slot), Some(key)) = (candidates.get_mut(ci as usize), keys.get_mut(ci as usize)) {
                        if candidate(ci, c, &self.solver_bodies, slot, key) {
                            solvable.push(ci);
                        } else {
                            unsolved.push(ci);
                        }
                    }
                }
            }
        }
        self.unsolved_contacts = unsolved;
        self.solver_contacts = solvable;
        self.candidates = candidates;
        self.colour_keys = keys;
    }

    /// The contacts with an awake moving body (only touching ones if `touching_only`), in
    /// contact order, each once (sorted, no repeats: the narrow phase's chunks find their
    /// share of the list by binary search, and a repeat would collide a contact twice):
    /// found through the awake bodies' contact lists, so sleeping islands cost nothing.
    /// `flags` and `mostly_awake`: [`World::scratch_flags`] and [`World::mostly_awake`], as
    /// [`World::prepare_bodies`] left them; the awake bodies are read from the step data
    /// (`sims`) it left, which hold exactly the bodies it flagged.
    fn collect_active_contacts(&self, out: &mut Vec<u32>, flags: &[bool], mostly_awake: bool, touching_only: bool) {
        out.clear();
        let active = |bi: u32| flags.get(bi as usize).copied().unwrap_or(false);
        if mostly_awake {
            // Mostly awake: one pass in memory order beats chasing the bodies' lists.
            for (ci, c) in self.contacts.iter().enumerate() {
                let Some(c) = c else { continue };
                if (!touching_only || c.touching) && (active(c.body_a) || active(c.body_b)) {
                    out.push(ci as u32);
                }
            }
            return;
        }
        // The awake moving bodies are those with a solver state (`solved`, which set
        // `flags` too, in the body pass, or its reuse, which keeps the solved set, as
        // `prepare_bodies` left them): found through the step data, not a scan of every
        // body slot (9 600 in smash while its block sleeps: 190 000 instructions a step).
        // A body not flagged is skipped (the rule below that takes a contact between two
        // active bodies from its body A relies on the flags).
        for sim in self.sims.iter().skip(1) {
            let bi = sim.body;
            let Some(b) = self.bodies.at(bi) else { continue };
            if !active(bi) {
                debug_assert!(false, "body {bi} has a solver state but is not flagged");
                continue;
            }
            debug_assert!(solved(b), "body {bi} has a solver state but is not solved");
            for &ci in &b.contacts {
                let Some(Some(c)) = self.contacts.get(ci as usize) else {
                    continue;
                };
                if touching_only && !c.touching {
                    continue;
                }
                // A contact between two active bodies is taken from its body A.
                let other = if c.body_a == bi { c.body_b } else { c.body_a };
                if c.body_a == bi || !active(other) {
                    out.push(ci);
                }
            }
        }
        out.sort_unstable();
        debug_assert!(out.windows(2).all(|w| w[0] < w[1]), "an active contact listed twice");
    }

    /// The awake bodies' solver states and step data, and one [`SolverBody`] per body slot
    /// (index 0 of the states: every static body). Made before the narrow phase, which
    /// makes the solver's candidates from them.
    fn prepare_bodies(&mut self, parallel: bool) {
        let g = self.def.gravity;
        let capacity = self.bodies.capacity();
        let reused = self.reuse_entries(g, capacity);
        self.entries_writes = self.bodies.writes();
        if reused {
            return;
        }
        // Every entry is written below (an empty slot's too), so the arrays are only
        // resized, not cleared first: many_pyramids' 22 000 entries are 1.4 MB.
        self.solver_bodies.resize(capacity, SolverBody::default());
        self.solver_bodies.truncate(capacity);
        self.scratch_flags.resize(capacity, false);
        self.scratch_flags.truncate(capacity);
        if parallel && capacity > BODY_CHUNK {
            self.prepare_bodies_parallel(g);
        } else {
            self.states.clear();
            self.sims.clear();
            self.states.push(BodyState::default()); // index 0: every static body
            self.sims.push(BodySim::default());
            let mut loaded = 0;
            for (bi, (sb, flag)) in self
                .solver_bodies
                .iter_mut()
                .zip(self.scratch_flags.iter_mut())
                .enumerate()
            {
                if let Some(b) = prepare_slot(self.bodies.at(bi as u32), self.states.len() as u32, sb, flag) {
                    let sim = body_sim(b, bi as u32, g);
                    loaded += usize::from(loads(&sim));
                    self.states.push(body_state(b));
                    self.sims.push(sim);
                }
            }
            self.loaded_bodies = loaded;
        }
        self.any_load = self.loaded_bodies > 0;
        // Bodies whose contacts the narrow phase visits (awake and not static): most of
        // them, or few (see `World::collide`).
        self.mostly_awake = 2 * (self.states.len() - 1) > self.bodies.len();
    }

    /// Whether the entries the last finalize made stand for this step's body pass: no body
    /// written since but through the API's `body_mut` (those are remade alone, unless one
    /// changed whether it is solved: then the solver order changes) and the same gravity.
    /// A read of every body record saved: large_pyramid's pass took 60 µs of a 3.3 ms step
    /// on one thread, 30 µs of 2 ms on two. Clears the API's list of written bodies.
    fn reuse_entries(&mut self, g: Vec2, capacity: usize) -> bool {
        let made = self.next_entries.take();
        let mut written = core::mem::take(&mut self.written_bodies);
        written.sort_unstable();
        written.dedup();
        let loaded = made
            .filter(|&(writes, gravity, _)| {
                writes == self.bodies.writes() && gravity == g && self.solver_bodies.len() == capacity
            })
            .and_then(|(_, _, loaded)| self.remake_entries(&written, loaded, g));
        written.clear();
        self.written_bodies = written;
        let Some(loaded) = loaded else {
            // Entries made for nothing (with none made, the last verdict stands).
            self.entries_unused |= made.is_some();
            return false;
        };
        self.any_load = loaded > 0;
        self.loaded_bodies = loaded;
        self.body_pass_skips += 1;
        self.entries_unused = false;
        true
    }

    /// What the body pass writes for the bodies in `written` (slot indices, sorted, no
    /// repeats), in place: their solver entries, and their states and step data when they
    /// are solved; `loaded`: the loaded bodies' count before. Returns the count after, or
    /// `None` (nothing written) when some body's being solved changed, which moves the
    /// solver indices of every body after it.
    fn remake_entries(&mut self, written: &[u32], mut loaded: usize, g: Vec2) -> Option<usize> {
        let solved_before = |bi: u32| self.scratch_flags.get(bi as usize).copied();
        if written
            .iter()
            .any(|&bi| solved_before(bi) != Some(self.bodies.at(bi).is_some_and(solved)))
        {
            return None;
        }
        for &bi in written {
            let (Some(b), Some(sb)) = (self.bodies.at(bi), self.solver_bodies.get_mut(bi as usize)) else {
                continue;
            };
            let k = sb.index;
            *sb = solver_body(Some(b), k);
            if let (true, Some(state), Some(sim)) =
                (k != 0, self.states.get_mut(k as usize), self.sims.get_mut(k as usize))
            {
                let new = body_sim(b, bi, g);
                loaded = loaded - usize::from(loads(sim)) + usize::from(loads(&new));
                (*state, *sim) = (body_state(b), new);
            }
        }
        Some(loaded)
    }

    /// [`World::prepare_bodies`] on the pool's threads, with the same result: each chunk
    /// of [`BODY_CHUNK`] slots writes its solved bodies' entries, states and step data from
    /// the solver index where the chunks before it end (solver order stays slot order).
    /// Those ends come from the chunks' solved counts of the last step, checked as the
    /// chunks go: when a body woke, slept, came or went and a count changed, the pass runs
    /// again with the counts it found (what a chunk finds does not depend on the guess, so
    /// the second run is the last). Done serially this pass was a tenth of
    /// large_pyramid's two-thread set-up; with a counting pass of its own first (a read of
    /// every body record) it took as long on two threads as on one (60 µs).
    fn prepare_bodies_parallel(&mut self, g: Vec2) {
        let chunks = self.solver_bodies.len().div_ceil(BODY_CHUNK);
        let mut counts = core::mem::take(&mut self.scratch_chunk_counts);
        if counts.len() != chunks {
            counts.clear();
            counts.resize(chunks, BODY_CHUNK);
        }
        let found = self.prepare_chunks(g, &counts);
        if found != counts {
            self.body_pass_retries += 1;
            let again = self.prepare_chunks(g, &found);
            debug_assert_eq!(again, found, "a chunk's count does not depend on the guess");
            counts = found;
        }
        self.scratch_chunk_counts = counts;
    }

    /// One try of [`World::prepare_bodies_parallel`] with `counts[c]` solved bodies
    /// assumed in chunk `c`; returns the counts found. Every entry is written; the states
    /// and step data are right when the counts found are the ones assumed.
    fn prepare_chunks(&mut self, g: Vec2, counts: &[usize]) -> Vec<usize> {
        let bodies = &self.bodies;
        let total: usize = counts.iter().sum();
        // Every entry past index 0 (every static body) is written below, so last step's
        // are kept and only the length changes: cleared and refilled, these arrays took a
        // serial 22 µs of large_pyramid's two-thread step and 90 µs of many_pyramids'.
        self.states.resize(total + 1, BodyState::default());
        self.sims.resize(total + 1, BodySim::default());
        if let (Some(s), Some(sim)) = (self.states.first_mut(), self.sims.first_mut()) {
            (*s, *sim) = (BodyState::default(), BodySim::default());
        }
        // Each chunk's share of the states and step data, and its first solver index.
        let mut shares = Vec::with_capacity(counts.len());
        let (mut states, mut sims, mut first) = (&mut self.states[1..], &mut self.sims[1..], 1usize);
        for &n in counts {
            let (st, st_rest) = core::mem::take(&mut states).split_at_mut(n);
            let (si, si_rest) = core::mem::take(&mut sims).split_at_mut(n);
            shares.push((first, st, si));
            (states, sims, first) = (st_rest, si_rest, first + n);
        }
        let mut found = vec![0usize; counts.len()];
        let chunks = self
            .solver_bodies
            .chunks_mut(BODY_CHUNK)
            .zip(self.scratch_flags.chunks_mut(BODY_CHUNK))
            .zip(shares)
            .zip(found.iter_mut())
            .enumerate();
        let loaded = core::sync::atomic::AtomicUsize::new(0);
        claim_each(
            true,
            chunks,
            |(c, (((entries, flags), (first, states, sims)), found))| {
                let (mut next, mut any) = (0usize, 0usize);
                for (k, (sb, flag)) in entries.iter_mut().zip(flags.iter_mut()).enumerate() {
                    let bi = c * BODY_CHUNK + k;
                    if let Some(b) = prepare_slot(bodies.at(bi as u32), (first + next) as u32, sb, flag) {
                        if let (Some(state), Some(sim)) = (states.get_mut(next), sims.get_mut(next)) {
                            *state = body_state(b);
                            *sim = body_sim(b, bi as u32, g);
                            any += usize::from(loads(sim));
                        }
                        next += 1;
                    }
                }
                *found = next;
                // A sum: the same whatever the order the chunks finish in.
                loaded.fetch_add(any, core::sync::atomic::Ordering::Relaxed);
            },
        );
        self.loaded_bodies = loaded.into_inner();
        found
    }

    /// Builds the solver's constraints from the candidates the narrow phase made, runs the
    /// solver stages and stores impulses back into the contacts. `bodies_ms`: the time
    /// [`World::prepare_bodies`] took (part of the solver set-up).
    fn solve(&mut self, ctx: &StepContext, bodies_ms: f32) {
        let mut contacts = core::mem::take(&mut self.contact_solver);
        crate::solver::with_contacts!(&mut contacts, solver => self.solve_with(ctx, bodies_ms, solver));
        self.contact_solver = contacts;
    }

    /// [`World::solve`] with the world's build of the wide solver.
    fn solve_with<C: WideContacts>(&mut self, ctx: &StepContext, bodies_ms: f32, solver: &mut C) {
        let mut lap = Stopwatch::start();
        let g = self.def.gravity;
        let candidates = Candidates::new(&self.candidates, &self.colour_keys, &self.solver_contacts);
        solver.build_step(
            ctx,
            &self.states,
            &self.sims,
            candidates,
            self.any_load,
            (-g).normalize_or_zero(),
        );
        self.build_joints(ctx);
        self.profile.solver_setup = bodies_ms + lap.lap();
        let mut joints = core::mem::take(&mut self.joint_solver);
        let mut set = StepConstraints {
            joints: &mut joints,
            contacts: solver,
        };
        // The threads share the substeps only when each colour gives each enough groups:
        // below that the waits after each colour, and the states that cross between the
        // cores when the bodies move, cost more than the halved work (on two threads, the
        // tumbler's 34 groups a colour ran its step at ×0.85–0.87 of the one-thread speed
        // with the team and ×1.03 without; junkyard's 151 at ×0.98 and ×1.10, washer's 173
        // at ×1.09 and ×1.14; large_pyramid's 268 at ×1.58 with it and ×1.13 without).
        // Joints share their passes when their blocks give each thread two a colour
        // (`JointSolver::worth_sharing`; joint_grid's two-thread step 4.54 -> 3.43 ms).
        // Either way the results are the same to the bit.
        let (groups, colours) = set.contacts.layout_size();
        let threads = rayon::current_num_threads();
        // All zero between steps (each substep's velocity pass clears what the relax before
        // it carried, and the last relax carries nothing); only its length follows the states.
        if self.carry_in_use {
            self.carry.fill(BodyState::default());
        }
        debug_assert!(self.carry.iter().all(|c| c.v == Vec2::ZERO && c.w == 0.0));
        self.carry.resize(self.states.len(), BodyState::default());
        self.carry_in_use = true;
        if ctx.parallel
            && (groups >= TEAM_MIN_GROUPS_PER_THREAD * threads * colours || set.joints.worth_sharing(threads))
        {
            // Threads share the states in place (`SharedState`, 32 bytes each).
            let shared = SharedState::from_mut_slice(&mut self.states);
            let carry = SharedState::from_mut_slice(&mut self.carry);
            solve_step(
                ctx,
                &self.sims,
                shared,
                carry,
                &mut self.trial,
                &mut set,
                &mut self.profile,
            );
        } else {
            let cells = core::cell::Cell::from_mut(&mut self.states[..]).as_slice_of_cells();
            let carry = core::cell::Cell::from_mut(&mut self.carry[..]).as_slice_of_cells();
            solve_step(
                ctx,
                &self.sims,
                cells,
                carry,
                &mut self.trial,
                &mut set,
                &mut self.profile,
            );
        }
        self.carry_in_use = false;
        lap.lap();
        solver.store_step(ctx, &self.states, &mut self.contacts, &mut self.contact_sums);
        // The touching contacts the solver did not take report nothing applied.
        for &ci in &self.unsolved_contacts {
            if let Some(sums) = self.contact_sums.get_mut(ci as usize) {
                *sums = ContactSums::default();
            }
        }
        self.joint_solver = joints;
        self.store_joints(ctx);
        self.profile.store = lap.lap();
    }

    /// [`World::finalize`]'s prefetch at solver slot `k`: the body record
    /// [`FINALIZE_PREFETCH`] slots ahead, the first shape of the body half as far ahead.
    #[inline]
    fn prefetch_finalize(&self, k: usize) {
        if let Some(far) = self.sims.get(k + FINALIZE_PREFETCH) {
            self.bodies.prefetch_n(far.body, 4);
            if let Some(sb) = self.solver_bodies.get(far.body as usize) {
                crate::solver::prefetch_lines(sb, 1);
            }
        }
        if let Some(mid) = self.sims.get(k + FINALIZE_PREFETCH / 2) {
            self.shapes.prefetch_n(mid.shape, 4);
        }
    }

    /// Writes the solver's motion back to the bodies, refreshes fat boxes and sleep timers.
    ///
    /// Per body, in solver order: its pose and sleep timer ([`advance_body`]), then its
    /// boxes in the trees ([`World::refresh_body_proxies`]; the trees are shared, so this
    /// part is serial and in that order). A box is swept only when the body moved, or will
    /// move, more than the speculative distance ([`boxes_care`]) and touched nothing, so
    /// which bodies touched something is found only when some body is that fast.
    ///
    /// With threads, when the last parallel finalize left more than half its bodies to the
    /// serial pass (bodies whose boxes leave their fat boxes every step, or of several
    /// shapes or none), the finalize runs on one thread, trying the parallel one again
    /// every [`FINALIZE_RETRY`] steps: the serial pass then read again, on the stepping
    /// thread, every record the other thread had just written (joint_grid's falling grid:
    /// 0.79 ms on two threads against 0.60 on one; large_pyramid's, whose boxes stay put,
    /// 0.11 against 0.20). Same results.
    fn finalize(&mut self, dt: f32, parallel: bool) {
        if !parallel || (self.finalize_alone && !self.step_count.is_multiple_of(FINALIZE_RETRY)) {
            if parallel {
                self.alone_finalizes += 1;
            }
            self.finalize_one_thread(dt);
            return;
        }
        // Poses and sleep timers in parallel: each body writes itself and the pose and
        // velocity in its solver entry (as the one-thread finalize, see there: with the
        // states reset below, the next step's entries when no body is written before it).
        use core::sync::atomic::{AtomicBool, Ordering::Relaxed};
        let fresh = self.make_entries();
        let (states, sleep_on) = (&self.states, self.def.enable_sleep);
        let limit = self.def.max_linear_speed;
        let tts = self.def.time_to_sleep;
        let (any_fast, forced, rested) = (AtomicBool::new(false), AtomicBool::new(false), AtomicBool::new(false));
        self.bodies
            .for_each_live_mut_with(parallel, BODY_CHUNK, &mut self.solver_bodies, |_, b, sb| {
                let index = sb.index;
                if let Some(&s) = states.get(index as usize).filter(|_| index != 0) {
                    // A force this step: the step data change (`body_sim`), and are not made here.
                    if b.force != Vec2::ZERO || b.torque != 0.0 {
                        forced.store(true, Relaxed);
                    }
                    if advance_body(b, s, dt, sleep_on) && boxes_care(b, dt, limit) {
                        any_fast.store(true, Relaxed);
                    }
                    sb.rest = b.sleep_time;
                    if rests(b, tts) {
                        rested.store(true, Relaxed);
                    }
                    if fresh {
                        move_entry(sb, b);
                    }
                }
            });
        self.any_rested = rested.into_inner();
        // This pass's own writes are in the entries; any later one is not.
        let writes = self.bodies.writes();
        if fresh && !forced.into_inner() {
            // Each state as `body_state` makes it from its body, whose velocity is now the
            // state's (a non-finite one is reported below: a write, so no skip).
            for_each_mut(parallel, &mut self.states[1..], BODY_CHUNK, |_, s| *s = next_state(s));
            self.next_entries = Some((writes, self.def.gravity, self.loaded_bodies));
        }
        let mut touched = core::mem::take(&mut self.scratch_touched);
        self.touched_slots(any_fast.into_inner(), &mut touched);
        // The boxes of one-shape bodies are computed shape by shape in parallel; a box that
        // stays inside its fat box is stored there (a shape writes only itself and its
        // bounds) and its body flagged. Only the other bodies go through the serial pass
        // below, which moves tree proxies (it used to store every box: many_pyramids'
        // finalize took as long on two threads as on one).
        let mut fitted = core::mem::take(&mut self.scratch_fitted);
        fitted.clear();
        if dt > 0.0 {
            use core::sync::atomic::{AtomicBool, Ordering::Relaxed};
            fitted.resize_with(self.states.len(), || AtomicBool::new(false));
            let (bodies, solver_bodies) = (&self.bodies, &self.solver_bodies);
            let (touched, flags) = (&touched, &fitted);
            self.shapes
                .for_each_live_mut_with(parallel, BODY_CHUNK, &mut self.shape_bounds, |_, s, bounds| {
                    let bi = s.body.index;
                    let k = solver_bodies.get(bi as usize).map_or(0, |sb| sb.index as usize);
                    let Some(b) = bodies.at(bi).filter(|_| k != 0) else {
                        return;
                    };
                    // One shape (this one), a finite state.
                    if b.shapes.len() != 1 || b.non_finite {
                        return;
                    }
                    let check = b.body_type == BodyType::Dynamic;
                    let sweep = b.bullet || !touched[k];
                    let moved = Moved(b.center - b.center0);
                    let next = next_box(
                        s,
                        s.geometry.aabb(b.xf),
                        box_velocity(b, limit),
                        dt,
                        check,
                        sweep,
                        moved,
                    );
                    if let Some(aabb) = next.filter(|aabb| s.fat_aabb.contains(*aabb)) {
                        s.aabb = aabb;
                        (bounds.aabb, bounds.fat_aabb) = (aabb, s.fat_aabb);
                        if let Some(f) = flags.get(k) {
                            f.store(true, Relaxed);
                        }
                    }
                });
        }
        // The other bodies' fat boxes and the trees, in solver order.
        let mut unfitted = 0usize;
        for k in 1..self.states.len() {
            if fitted.get_mut(k).is_some_and(|f| *f.get_mut()) {
                continue; // fitted above
            }
            unfitted += 1;
            self.prefetch_finalize(k);
            let bi = self.sims[k].body;
            if let Some(bullet) = self.finite_or_reported(bi) {
                self.refresh_body_proxies(bi, dt, bullet || !touched[k]);
            }
        }
        self.scratch_fitted = fitted;
        self.scratch_touched = touched;
        self.finalize_alone = 2 * unfitted > self.states.len().saturating_sub(1);
    }

    /// [`World::finalize`] on one thread: each body's pose and then at once its boxes, while
    /// its record is in cache (two passes over the bodies had cost large_pyramid's finalize
    /// a second read of 5 000 records), in solver order as with threads. Which bodies
    /// touched something is found when the first body whose boxes care comes.
    fn finalize_one_thread(&mut self, dt: f32) {
        let (sleep_on, limit, g) = (self.def.enable_sleep, self.def.max_linear_speed, self.def.gravity);
        // Filled when the first body whose boxes care comes; read only for such bodies.
        let mut touched = core::mem::take(&mut self.scratch_touched);
        let mut found = false;
        // The poses are written without advancing the bodies' write count: each body's
        // next solver entry, state and step data are made from its new record right here,
        // as the next body pass would make them. Any other write to a body from here on
        // (a sweep moving one back, a report, sleep, the API) advances the count, and the
        // next step then runs its body pass.
        let writes = self.bodies.writes();
        let fresh = self.make_entries();
        let (mut loaded, mut rested, tts) = (0, false, self.def.time_to_sleep);
        for k in 1..self.states.len() {
            self.prefetch_finalize(k);
            let (bi, s) = (self.sims[k].body, self.states[k]);
            let Some(b) = self.bodies.at_mut_quiet(bi) else {
                continue;
            };
            let care = advance_body(b, s, dt, sleep_on) && boxes_care(b, dt, limit);
            rested |= rests(b, tts);
            if let Some(sb) = self.solver_bodies.get_mut(bi as usize) {
                sb.rest = b.sleep_time;
                if let (true, Some(state), Some(sim)) = (fresh, self.states.get_mut(k), self.sims.get_mut(k)) {
                    *state = body_state(b);
                    *sim = body_sim(b, bi, g);
                    move_entry(sb, b);
                    loaded += usize::from(loads(sim));
                }
            }
            let Some(bullet) = self.finite_or_reported(bi) else {
                continue;
            };
            if care && !found {
                self.touched_slots(true, &mut touched);
                found = true;
            }
            // A body whose boxes do not care is not swept either way.
            let sweep = bullet || !(care && touched[k]);
            self.refresh_body_proxies(bi, dt, sweep);
        }
        self.scratch_touched = touched;
        self.any_rested = rested;
        self.next_entries = fresh.then_some((writes, g, loaded));
    }

    /// Whether finalize makes the next step's entries (see [`World::finalize_one_thread`]):
    /// only when no body was written since this step's entries were made (then only what
    /// finalize writes, pose, velocity and the forces it clears, changes in them), and not
    /// while the last ones went unused, but every [`ENTRIES_RETRY`] steps (whether they
    /// are used changes no result, only the time).
    fn make_entries(&self) -> bool {
        self.bodies.writes() == self.entries_writes
            && self.written_bodies.is_empty()
            && (!self.entries_unused || self.step_count.is_multiple_of(ENTRIES_RETRY))
    }

    /// Whether body `bi` is a bullet, or `None` when its state went non-finite in this
    /// step's solve: it is then reported (`World::non_finite`) and keeps its boxes.
    fn finite_or_reported(&mut self, bi: u32) -> Option<bool> {
        // Read first: a write (which the body pass's skip counts) only to clear the flag.
        let b = self.bodies.at(bi)?;
        if !b.non_finite {
            return Some(b.bullet);
        }
        if let Some(b) = self.bodies.at_mut(bi) {
            b.non_finite = false;
        }
        let id = BodyId {
            index: bi,
            generation: self.bodies.generation(bi),
        };
        self.non_finite.push(id);
        None
    }

    /// Which solver slots touched something this step (when `any`; else none): their boxes
    /// are not swept (broad_phase::sweep_free), unless the body is a bullet.
    fn touched_slots(&self, any: bool, touched: &mut Vec<bool>) {
        touched.clear();
        touched.resize(self.states.len(), false);
        if !any {
            return;
        }
        // The solved contacts' slots are in their colouring keys (12 bytes each, not the
        // contact records' lines: tumbler's loop stalled on those); the records are read
        // only for the touching contacts without an awake dynamic side.
        let keyed = self
            .solver_contacts
            .iter()
            .filter_map(|&ci| self.colour_keys.get(ci as usize))
            .map(|k| k.slots());
        let unsolved = self.unsolved_contacts.iter().filter_map(|&ci| {
            self.contacts.get(ci as usize).and_then(Option::as_ref).map(|c| {
                let slot = |body: u32| self.solver_bodies.get(body as usize).map_or(0, |sb| sb.index);
                (slot(c.body_a), slot(c.body_b))
            })
        });
        for (a, b) in keyed.chain(unsolved) {
            for slot in [a, b] {
                if let Some(t) = touched.get_mut(slot as usize) {
                    *t = true;
                }
            }
        }
    }

    /// Islands (awake dynamic bodies linked by touching contacts) whose every body has
    /// rested for `time_to_sleep` fall asleep together.
    fn update_sleep(&mut self, _dt: f32) {
        if !self.def.enable_sleep {
            return;
        }
        // An island falls asleep when its least rested body has rested `time_to_sleep`: while
        // no awake body has, no island can, and the islands need not be built (finalize
        // finds whether one has while it writes the timers: a pile that keeps moving, like
        // the tumbler's, pays nothing here).
        let tts = self.def.time_to_sleep;
        // And only every `SLEEP_CHECK_STEPS` steps.
        if !self.any_rested || !self.step_count.is_multiple_of(SLEEP_CHECK_STEPS) {
            return;
        }
        // Islands over the solver slots of the awake bodies (solver order is slot order, so
        // an island's smallest solver slot belongs to its smallest body slot, and the
        // islands come out in the same order as over body slots).
        let n = self.states.len();
        let mut parent = core::mem::take(&mut self.scratch_u32);
        parent.clear();
        parent.extend(0..n as u32);
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                let gp = p[p[x as usize] as usize];
                p[x as usize] = gp;
                x = gp;
            }
            x
        }
        fn union(p: &mut [u32], a: u32, b: u32) {
            let (ra, rb) = (find(p, a), find(p, b));
            if ra != rb {
                // Union by smaller index: each island's root is its smallest slot.
                let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                p[hi as usize] = lo;
            }
        }
        // Touching contacts between two awake dynamic bodies link them: those are solved
        // contacts, whose colouring keys hold both slots (12 bytes each; reading the
        // contact records and both bodies' records for every touching contact was most of
        // this pass in junkyard).
        for &ci in &self.solver_contacts {
            if let Some((a, b)) = self.colour_keys.get(ci as usize).and_then(|k| k.dynamic_pair()) {
                if (a as usize) < n && (b as usize) < n {
                    union(&mut parent, a, b);
                }
            }
        }
        // The bodies' entries say which are awake and dynamic (as their records do: the
        // entries are made again when collide wakes a body, and nothing after it wakes or
        // puts one to sleep) and hold their timers as finalize left them: one line per body
        // slot is read, not the records (the joints' bodies at random, then every body
        // twice: most of this pass in rain's 11 000 ragdoll bodies).
        let entries = &self.solver_bodies;
        let awake_dynamic = |bi: u32| entries.get(bi as usize).filter(|sb| sb.awake_dynamic);
        // Joints between awake dynamic bodies.
        for (_, j) in self.joints.iter() {
            if let (Some(a), Some(b)) = (awake_dynamic(j.body_a), awake_dynamic(j.body_b)) {
                let (sa, sb) = (a.index, b.index);
                if sa != 0 && sb != 0 && (sa as usize) < n && (sb as usize) < n {
                    union(&mut parent, sa, sb);
                }
            }
        }
        let mut min_time = core::mem::take(&mut self.scratch_f32);
        min_time.clear();
        min_time.resize(n, f32::INFINITY);
        let mut any = false;
        // Body slot order (the records' order before).
        let solved = || entries.iter().enumerate().filter(|(_, sb)| sb.awake_dynamic);
        for (_, sb) in solved() {
            let r = find(&mut parent, sb.index) as usize;
            min_time[r] = min_time[r].min(sb.rest);
            any = true;
        }
        if any {
            let mut islands: Vec<(u32, Vec<u32>)> = Vec::new();
            let mut members_of_root: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
            for (bi, sb) in solved() {
                let r = find(&mut parent, sb.index);
                if min_time[r as usize] >= tts {
                    members_of_root.entry(r).or_default().push(bi as u32);
                }
            }
            islands.extend(members_of_root);
            for (_, members) in islands {
                self.put_to_sleep(&members);
            }
        }
        self.scratch_u32 = parent;
        self.scratch_f32 = min_time;
    }

    /// Bodies frozen in the last step because their state became non-finite.
    pub fn non_finite_bodies(&self) -> &[BodyId] {
        &self.non_finite
    }
}

/// Steps between two searches for islands to put to sleep (every step's rest timers are
/// kept; an island falls asleep at the first search after its least rested body has rested
/// `WorldDef::time_to_sleep`, up to this many steps less one later).
pub(super) const SLEEP_CHECK_STEPS: u64 = 4;

/// Bodies per parallel chunk of finalize and of the step's body pass.
pub(super) const BODY_CHUNK: usize = 256;

/// Steps between finalize's tries to make the next step's solver entries while the last
/// ones went unused ([`World::entries_unused`]).
pub(super) const ENTRIES_RETRY: u64 = 8;

/// Whether the solver gets a state for body `b`: awake and not static.
#[inline]
fn solved(b: &Body) -> bool {
    b.awake && b.body_type != BodyType::Static
}

/// Writes a body slot's solver entry and awake flag (`b`: the slot's body, if any;
/// `index`: its solver index, if it is [`solved`]); returns the body if it is solved (it
/// then takes that index's state and step data).
#[inline]
fn prepare_slot<'b>(b: Option<&'b Body>, index: u32, sb: &mut SolverBody, flag: &mut bool) -> Option<&'b Body> {
    *flag = b.is_some_and(solved);
    *sb = solver_body(b, index);
    b.filter(|b| solved(b))
}

/// Body `b`'s solver entry (`b`: the slot's body, if any); `index`: its solver index, if
/// it is [`solved`].
#[inline]
fn solver_body(b: Option<&Body>, index: u32) -> SolverBody {
    let Some(b) = b else {
        return SolverBody::default();
    };
    let on = solved(b);
    SolverBody {
        index: if on { index } else { 0 },
        awake_dynamic: on && b.is_dynamic(),
        inv_mass: if on { b.inv_mass } else { 0.0 },
        inv_i: if on { b.inv_inertia } else { 0.0 },
        center: b.center,
        xf: b.xf,
        v: b.v,
        w: b.w,
        max_extent: b.max_extent,
        reach: b.max_extent + b.local_center.length(),
        rest: b.sleep_time,
    }
}

/// A solved body's state at the start of the step: velocity `v` [m/s], `w` [rad/s], no
/// motion yet.
#[inline]
fn start_state(v: Vec2, w: f32) -> BodyState {
    BodyState {
        v,
        w,
        touched: 0.0,
        dp: Vec2::ZERO,
        dq: Rot::IDENTITY,
    }
}

/// Body `b`'s state at the start of the step.
#[inline]
fn body_state(b: &Body) -> BodyState {
    start_state(b.v, b.w)
}

/// The state of the step after one that ended with state `s` (finalize has written `s`'s
/// velocity into its body: [`body_state`]'s).
#[inline]
fn next_state(s: &BodyState) -> BodyState {
    start_state(s.v, s.w)
}

/// What finalize changes in body `b`'s solver entry: its pose and velocity (the rest
/// changes only with a write the next step sees, see [`World::make_entries`]).
#[inline]
fn move_entry(sb: &mut SolverBody, b: &Body) {
    (sb.center, sb.xf, sb.v, sb.w) = (b.center, b.xf, b.v, b.w);
}

/// A solved body's step data (slot `bi`; `g`: the world's gravity [m/s²]).
#[inline]
fn body_sim(b: &Body, bi: u32, g: Vec2) -> BodySim {
    let dynamic = b.body_type == BodyType::Dynamic;
    let force = b.force + b.constant_force;
    let torque = b.torque + b.constant_torque;
    BodySim {
        linear_accel: if dynamic {
            b.inv_mass * force + b.gravity_scale * g
        } else {
            Vec2::ZERO
        },
        angular_accel: if dynamic { b.inv_inertia * torque } else { 0.0 },
        linear_damping: if dynamic { b.linear_damping } else { 0.0 },
        angular_damping: if dynamic { b.angular_damping } else { 0.0 },
        body: bi,
        shape: b.first_shape,
        jointed: !b.joints.is_empty(),
    }
}

/// What one chunk of the narrow phase found, in contact order: the touching contacts the
/// solver takes, those it does not, and those to destroy or whose touching changed
/// (events). The serial pass after the narrow phase joins the chunks' lists instead of
/// reading every contact's verdict (a serial 30-40 µs of large_pyramid's two-thread step).
#[derive(Debug, Default)]
pub(crate) struct ChunkOutcomes {
    solvable: Vec<u32>,
    /// Touching, not taken by the solver (no awake dynamic side).
    unsolved: Vec<u32>,
    special: Vec<(u32, NarrowOutcome)>,
}

impl ChunkOutcomes {
    fn clear(&mut self) {
        self.solvable.clear();
        self.unsolved.clear();
        self.special.clear();
    }

    /// Files contact `ci`'s verdict (inlined into both of the narrow phase's filing loops,
    /// the mostly-awake one and the listed contacts' one).
    #[inline(always)]
    fn note(&mut self, ci: u32, outcome: NarrowOutcome, solvable: bool) {
        match outcome {
            NarrowOutcome::Skipped => {}
            NarrowOutcome::Destroy => self.special.push((ci, outcome)),
            NarrowOutcome::Updated { touching, changed } => {
                if touching {
                    if solvable {
                        self.solvable.push(ci);
                    } else {
                        self.unsolved.push(ci);
                    }
                }
                if changed {
                    self.special.push((ci, outcome));
                }
            }
        }
    }
}

/// Fewest wide groups per colour and thread, on average, for the solver's substeps to run
/// on the step's threads (fewer: on the stepping thread; see `World::solve_with`).
const TEAM_MIN_GROUPS_PER_THREAD: usize = 100;

/// Steps between tries of the parallel finalize while it runs on one thread (see
/// `World::finalize`).
const FINALIZE_RETRY: u64 = 16;

/// Contacts per parallel chunk of the narrow phase and the impulse store.
pub(super) const CONTACT_CHUNK: usize = 256;

/// `owners` (where each thread's share of a list starts, ascending from 0, each with its
/// thread) with each start moved to the nearest multiple of `grid`, so that chunks of
/// `grid` items cut from the starts stay on the grid; a share left empty is dropped, and
/// so are all when fewer than two remain or the first start does not round to 0.
pub(super) fn grid_owners(owners: &[(usize, usize)], grid: usize) -> Vec<(usize, usize)> {
    let grid = grid.max(1);
    let mut out: Vec<(usize, usize)> = Vec::with_capacity(owners.len());
    for &(at, k) in owners {
        let at = (at + grid / 2) / grid * grid;
        match out.last() {
            None if at != 0 => return Vec::new(),
            Some(&(_, j)) if j == k => {}
            Some(&(a, _)) if a >= at => {}
            _ => out.push((at, k)),
        }
    }
    if out.len() < 2 {
        out.clear();
    }
    out
}

/// How many contacts ahead the narrow phase asks for their bodies and shape bounds.
const NARROW_PREFETCH: usize = 4;

/// How many contacts ahead the narrow phase asks for the contact record itself (many_pyramids'
/// collide, ms: 6 ahead 2.84-2.94, 12 ahead 2.44-2.63, 20 ahead 2.57-2.72).
const RECORD_PREFETCH: usize = 12;

/// Contact lists up to this long are searched for an existing pair instead of the pair
/// table (a few keys in one cache line beat a hash probe into a large table).
const SHORT_CONTACT_LIST: usize = 16;

/// A pair update where at least 1/`WALK_SHARE` of the moving tree's proxies moved finds
/// that tree's pairs all at once (sweep and prune, or a walk of the tree against itself)
/// rather than querying it once per moved shape ([`World::update_pairs`]).
const WALK_SHARE: usize = 2;

/// How many moved shapes ahead [`World::update_pairs`] asks for their records.
const PAIR_PREFETCH: usize = 8;

/// Moved shapes per parallel chunk of the broad phase's queries.
const PAIR_CHUNK: usize = 256;

/// Pair keys per parallel chunk of the broad phase's lookups of found pairs.
const KEY_CHUNK: usize = 2048;

/// Writes a body's solver state `s` (after a step of `dt` [s]) into its record: velocity,
/// pose from the step's motion, and sleep timer. Returns false, leaving the body at its
/// last good pose and flagged `non_finite`, when the state is not finite.
fn advance_body(b: &mut Body, s: BodyState, dt: f32, sleep_on: bool) -> bool {
    b.force = Vec2::ZERO;
    b.torque = 0.0;
    let finite = s.v.is_finite() && s.w.is_finite() && s.dp.is_finite() && s.dq.c.is_finite() && s.dq.s.is_finite();
    if !finite {
        // NaN born inside the simulation: freeze the body at its last good pose and report
        // it (`World::finalize`) rather than spreading the NaN.
        b.v = Vec2::ZERO;
        b.w = 0.0;
        b.non_finite = true;
        return false;
    }
    b.v = s.v;
    b.w = s.w;
    b.center0 = b.center;
    b.q0 = b.xf.q;
    b.center += s.dp;
    let q = s.dq.mul(b.xf.q);
    // Renormalise against slow drift of |q| over many steps.
    let mag = (q.c * q.c + q.s * q.s).sqrt();
    b.xf.q = Rot {
        c: q.c / mag,
        s: q.s / mag,
    };
    b.xf.p = b.center - b.xf.q.rotate(b.local_center);
    // Sleep timer (Box2D's metric: |v| + |ω|·extent against the threshold).
    if sleep_on && b.enable_sleep && b.body_type == BodyType::Dynamic {
        let speed = b.v.length() + b.w.abs() * b.max_extent;
        if speed > b.sleep_threshold {
            b.sleep_time = 0.0;
        } else {
            b.sleep_time += dt;
        }
    } else {
        b.sleep_time = 0.0;
    }
    true
}

/// Whether a solved body has rested long enough to sleep (`tts`: the world's time to
/// sleep [s]); its island may then fall asleep ([`World::update_sleep`]).
#[inline]
fn rests(b: &Body, tts: f32) -> bool {
    b.is_dynamic() && b.sleep_time >= tts
}

/// Whether a body's boxes depend on the sweep rule: it moved this step, or will move at
/// its speed (capped at `limit` [m/s]), more than the speculative distance. Otherwise its
/// next box is not swept whatever the rule ([`next_box`]: the sweep starts beyond
/// `sweep_free`, which is at least that distance, and so does the check of a swept body).
fn boxes_care(b: &Body, dt: f32, limit: f32) -> bool {
    let v = box_velocity(b, limit);
    exceeds(v.length_squared() * (dt * dt), || v.length() * dt, SPECULATIVE_DISTANCE)
        || Moved(b.center - b.center0).beyond(SPECULATIVE_DISTANCE)
}

/// How many solver slots ahead [`World::finalize`] asks for the body records.
const FINALIZE_PREFETCH: usize = 8;

/// Writes the solver's input and colouring key of a touching contact with an awake dynamic
/// side into `out` and `key`; false (nothing written) otherwise.
fn candidate(ci: u32, c: &Contact, solver_bodies: &[SolverBody], out: &mut Candidate, key: &mut ColourKey) -> bool {
    if !c.touching {
        return false;
    }
    let (Some(ba), Some(bb)) = (
        solver_bodies.get(c.body_a as usize),
        solver_bodies.get(c.body_b as usize),
    ) else {
        return false;
    };
    if !ba.awake_dynamic && !bb.awake_dynamic {
        return false;
    }
    out.fill(ci, c.colour, ba, bb, c, key);
    true
}

/// Updates one contact's manifold (recycled when its bodies barely moved); reads only the
/// bodies' solver entries and the shapes, so contacts can be updated in parallel. Counts
/// the pairs collided in full (not recycled, not ruled out by their boxes or distance
/// bound) in `collided`.
fn narrow_phase(
    c: &mut Contact,
    bodies: &[SolverBody],
    bounds: &[ShapeBounds],
    shapes: &Arena<ShapeRecord>,
    dt: f32,
    collided: &mut u32,
) -> NarrowOutcome {
    let (Some(ba), Some(bb)) = (bodies.get(c.body_a as usize), bodies.get(c.body_b as usize)) else {
        return NarrowOutcome::Skipped;
    };
    if ba.index == 0 && bb.index == 0 {
        return NarrowOutcome::Skipped;
    }
    let shape = |id: ShapeId| bounds.get(id.index as usize).filter(|s| s.generation == id.generation);
    let (Some(sa), Some(sb)) = (shape(c.shape_a), shape(c.shape_b)) else {
        return NarrowOutcome::Skipped;
    };
    #[cfg(debug_assertions)]
    for (id, copy) in [(c.shape_a, sa), (c.shape_b, sb)] {
        let s = shapes.get(id.index, id.generation);
        debug_assert!(
            s.is_some_and(|s| s.fat_aabb == copy.fat_aabb && s.aabb == copy.aabb && s.filter == copy.filter),
            "shape bounds out of step with shape {}",
            id.index
        );
    }
    if !sa.fat_aabb.overlaps(sb.fat_aabb) || !sa.filter.should_collide(&sb.filter) {
        return NarrowOutcome::Destroy;
    }
    // Speculative margin grows with the relative motion of the step, so fast bodies meet
    // thin ground before they can pass it.
    let rel = (bb.v - ba.v).length() + ba.w.abs() * ba.max_extent + bb.w.abs() * bb.max_extent;
    let margin = SPECULATIVE_DISTANCE + dt * rel;
    let was = c.touching;
    if !sa.aabb.expand(dt * rel).overlaps(sb.aabb) {
        // The boxes are further apart than the margin (each grown by the speculative
        // distance, and together by the relative motion): no point could be within it.
        c.clear_manifold();
        return NarrowOutcome::Updated {
            touching: false,
            changed: was,
        };
    }
    // A pair found apart that cannot have closed the gap since: its manifold stays empty.
    let (d, reach_a, reach_b) = (bb.xf.p - ba.xf.p, ba.reach, bb.reach);
    if c.still_apart(d, ba.xf.q, bb.xf.q, reach_a, reach_b, margin) {
        return NarrowOutcome::Updated {
            touching: false,
            changed: false,
        };
    }
    // A recycled manifold keeps its points, not the speculative ones a margin grown by the
    // pair's motion would add (a corner swinging towards a wall), so only a pair no faster
    // than its manifold allows may keep it: a feature it lacks was further than the margin
    // m the manifold was made with, has moved by at most the recycle distance since, and
    // closes by at most dt · rel in the step; with dt · rel ≤ m − slop
    // (`RECYCLE_STEP` when m is the speculative distance) it can overlap by 1 cm at most
    // (`RECYCLE_DISTANCE`). Faster pairs are collided again.
    // A pair without a recycling basis of its own (collided last step, or found apart)
    // asks for both shapes' geometry now, so the two records' lines arrive together and
    // while the recycle is tried, rather than one after the other when it fails.
    if !matches!(c.memo, Memo::Basis(_)) {
        for id in [c.shape_a, c.shape_b] {
            shapes.prefetch_n(id.index, 3);
        }
    }
    let now = c.recycle(ba.xf, bb.xf, 2.0 * ba.max_extent.min(bb.max_extent), dt * rel)
        || match (shapes.at(c.shape_a.index), shapes.at(c.shape_b.index)) {
            (Some(sa), Some(sb)) => {
                *collided += 1;
                c.update(&sa.geometry, ba.xf, &sb.geometry, bb.xf, margin)
            }
            _ => false,
        };
    NarrowOutcome::Updated {
        touching: now,
        changed: now != was,
    }
}

/// Lever arm of rolling resistance [m]: the rounding radius of a shape.
fn rolling_radius(g: &Shape) -> f32 {
    match g {
        Shape::Circle(c) => c.radius,
        Shape::Capsule(c) => c.radius,
        Shape::Polygon(p) => p.radius(),
        Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::grid_owners;

    /// Starts move to the nearest grid line; a share that ends up empty, or whose start
    /// falls on the one before, joins that one; a list whose first start does not round
    /// to 0, or that has fewer than two shares left, gives none.
    #[test]
    fn owners_move_to_the_grid() {
        let owners = [(0, 1), (300, 0), (520, 1), (530, 0), (1000, 1), (1400, 0)];
        assert_eq!(grid_owners(&owners, 256), vec![(0, 1), (256, 0), (512, 1), (1280, 0)]);
        assert_eq!(grid_owners(&[(10, 0), (600, 1)], 256), vec![(0, 0), (512, 1)]);
        assert!(grid_owners(&[(200, 0), (600, 1)], 256).is_empty());
        assert!(grid_owners(&[(0, 0), (100, 1)], 256).is_empty());
    }
}
