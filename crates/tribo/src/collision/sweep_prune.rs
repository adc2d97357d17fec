//! Sweep and prune: every overlapping pair of a set of boxes, found by sorting the boxes
//! along one axis and sweeping each box's interval on it (the classic broad phase of
//! Baraff's thesis, 1992, and Bullet's `btAxisSweep3`), here in bands across the sweep
//! axis, and rebuilt each time it is asked, for a pile in motion, where most boxes moved
//! since the last step anyway.
//!
//! Pipeline stage: broad phase (`World::update_pairs`, when at least half the moving
//! tree's proxies moved). Neighbour: [`super::tree`], whose leaves it reads and whose
//! own walk against itself ([`super::tree::FlatTree::self_pairs`]) gives the same pairs and
//! takes over where a sweep would test too many.
//!
//! Why: the tree walk costs a few dozen nanoseconds per overlapping pair found (a
//! descent through two subtrees per pair of leaves, each step a box test and a stack
//! write), where the sweep, once the boxes are sorted, tests each box against the boxes of
//! its band that start inside its interval on the sweep axis, four at a time, one
//! comparison of each bound per candidate, without branches. Tumbler (2 025 boxes, 8 500–10 500
//! overlapping pairs): ~17 tests a box, and the pairs stage 0.556 → 0.27 ms a step.
//!
//! The pairs are exactly the tree's: two boxes overlap when neither lies wholly beyond the
//! other on either axis (the same comparisons as [`crate::math::Aabb::overlaps`], for the
//! finite, not inverted boxes a tree holds), so the pairs a step creates, and so its
//! results, do not depend on which way they were found.

use super::contact::pair_key;
use super::tree::DynamicTree;
use crate::math::wide::{F4, LANES4};

/// A sweep gives up (and the caller walks the tree instead) past this many candidate
/// tests per box on average (a box tested in each band it is listed in, each time
/// counted, in chunks of four): with the boxes crowded on both axes (many boxes spawned
/// on one spot, say) each box's interval in its band holds most of the others, and the
/// tree's walk, which costs per pair found, is then the cheaper. This many tests cost
/// about what the walk costs in a pile; the tumbler's pile needs ~17 a box (~57 before
/// the bands, when a sweep along x met the pile's whole height).
const MAX_TESTS_PER_BOX: usize = 128;

/// The height of a band across the sweep axis, in mean box extents on that axis (see
/// `SweepPrune::moved_pairs`): a box is listed in 1.25 bands on average, and its
/// candidates come from four boxes' height of the pile. (Tumbler's pairs stage,
/// alternated against one band: 0.32 → 0.29 ms; with 8 and 16 extents, not alternated,
/// 0.29–0.31 ms.)
const BAND_BOXES: f32 = 4.0;

/// At most this many bands.
const MAX_BANDS: u32 = 1024;

/// Fewest entries per thread for which the sweep is shared between threads (fewer: one
/// thread sweeps them all).
const MIN_PART_ENTRIES: usize = 2048;

/// The bands across the sweep axis: `of(c)` is the band of cross coordinate `c` [m],
/// non-decreasing in `c` (so a box meets every band from that of its lower bound to that of
/// its upper one).
#[derive(Clone, Copy, Debug)]
struct Bands {
    /// The cross axis' lowest bound [m].
    min: f32,
    /// Bands per metre [1/m] (0: one band).
    per_metre: f32,
    /// The last band.
    last: u32,
}

impl Bands {
    #[inline]
    fn of(self, c: f32) -> u32 {
        // `as` saturates (below `min`: 0); each step is non-decreasing in `c`.
        (((c - self.min) * self.per_metre) as u32).min(self.last)
    }
}

/// The band of a padding entry (see `SweepPrune::moved_pairs`).
const PADDING: u32 = u32::MAX;

/// Boxes tested together, a chunk of the sweep order.
const CHUNK: usize = LANES4;

/// How many sweeps after one that gave up go straight to the tree walk (the boxes'
/// arrangement changes slowly: a pile that lined up stays so for a while).
const BACK_OFF_SWEEPS: u32 = 32;

/// The sweep's buffers, kept between steps (no allocation once warmed up), and its
/// back-off after a sweep that gave up.
#[derive(Default, Clone, Debug)]
pub(crate) struct SweepPrune {
    /// Sort keys, band after band: the box's lower bound on the sweep axis as
    /// order-preserving bits, then its place in `boxes`.
    keys: Vec<u64>,
    /// Where each band's entries start in `keys` (and the end), and the next free place
    /// of each band while they are filled.
    starts: Vec<u32>,
    fill: Vec<u32>,
    /// The boxes as gathered: (min x, min y, max x, max y) [m], user data, moved.
    boxes: Vec<([f32; 4], u32, bool)>,
    /// In sweep order, band after band (each band's entries followed by a chunk of
    /// padding): the lower and upper bounds on the sweep axis and the cross axis [m], the
    /// user data, whether the box moved, the band.
    lo: Vec<f32>,
    hi: Vec<f32>,
    cross_lo: Vec<f32>,
    cross_hi: Vec<f32>,
    data: Vec<u32>,
    moved: Vec<bool>,
    band: Vec<u32>,
    /// In sweep order: the first band of the entry's box.
    first: Vec<u32>,
    /// Each box's first and last band.
    spans: Vec<(u32, u32)>,
    /// The sweep's scratch: one box's hits.
    hits: Vec<u32>,
    /// Sweeps left to skip after one gave up.
    back_off: u32,
    /// Sweeps made, sweeps that gave up, the most bands a sweep cut, and sweeps shared
    /// between threads (tests read these).
    pub sweeps: u64,
    pub gave_up: u64,
    pub most_bands: u32,
    pub shared_sweeps: u64,
    /// The tests' [`MIN_PART_ENTRIES`] (0: that one), so that small sets are shared too.
    #[cfg(test)]
    min_part: usize,
}

/// `x`'s bits as an unsigned integer in the order of the floats (negative floats' bits
/// inverted, positive ones' sign bit set), so that sorting the integers sorts the floats.
#[inline]
fn ordered_bits(x: f32) -> u32 {
    let b = x.to_bits();
    if b >> 31 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

impl SweepPrune {
    /// Pushes onto `out` the [`pair_key`] of every pair of `tree`'s leaves whose boxes
    /// overlap and at least one of which is marked in `moved` (indexed by the leaves'
    /// user data, a shape index; unmarked when out of range), in no particular order.
    /// Returns false, with `out` as it was, when the sweep is not worth it: it would test
    /// more than [`MAX_TESTS_PER_BOX`] candidates a box (and then for the next
    /// [`BACK_OFF_SWEEPS`] calls); the caller then walks the tree.
    /// With `threads` > 1 (inside the pool that has them), the sweep of step 3 is shared:
    /// the bands cut into one run of whole bands per thread, of about as many entries
    /// each, each run swept into a list of its own; it gives up when the runs' tests add
    /// up to more than the budget, which is when one thread's sweep gives up (its count
    /// only grows): the same pairs, the same give-up and back-off, for any thread count.
    #[inline(never)]
    pub fn moved_pairs(&mut self, tree: &DynamicTree, moved: &[bool], threads: usize, out: &mut Vec<u64>) -> bool {
        if self.back_off > 0 {
            self.back_off -= 1;
            return false;
        }
        self.sweeps += 1;
        // 1. Gather the leaves, and the spread of their centres on each axis.
        self.boxes.clear();
        let (mut sum, mut sum2) = ([0.0f64; 2], [0.0f64; 2]);
        tree.for_each_leaf(|aabb, data| {
            // Finite and not inverted, as the sweep's order assumes: the tree takes no
            // other (`Aabb::is_valid`, checked by every call that sets a proxy's box).
            debug_assert!(aabb.is_valid());
            let b = [aabb.min.x, aabb.min.y, aabb.max.x, aabb.max.y];
            for axis in 0..2 {
                let c = 0.5 * (b[axis] as f64 + b[axis + 2] as f64);
                sum[axis] += c;
                sum2[axis] += c * c;
            }
            let shape = data as u32;
            let m = moved.get(shape as usize).copied().unwrap_or(false);
            self.boxes.push((b, shape, m));
        });
        let n = self.boxes.len();
        if n < 2 {
            return true;
        }
        // 2. Sort along the axis on which the centres spread the most (their variance ×
        // n², compared: the boxes then overlap fewest others along it), in bands across
        // it: the cross axis cut into bands some boxes wide, each box listed in every
        // band its cross interval meets and swept against that band's boxes only, a
        // pair kept only in the band where the pair's cross overlap begins (the band of
        // the larger cross lower bound, which both boxes meet), so once. In a pile, a
        // box's interval on the sweep axis then holds the boxes of a band, not of the
        // pile's whole height (tumbler: ~57 tests a box in one band, ~17 in bands).
        let spread = |axis: usize| n as f64 * sum2[axis] - sum[axis] * sum[axis];
        let axis = if spread(1) > spread(0) { 1 } else { 0 };
        let cross = 1 - axis;
        let (mut c_min, mut c_max, mut extent) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f64);
        for (b, _, _) in &self.boxes {
            c_min = c_min.min(b[cross]);
            c_max = c_max.max(b[cross + 2]);
            extent += f64::from(b[cross + 2] - b[cross]);
        }
        let band_height = BAND_BOXES * (extent / n as f64) as f32;
        // (At most one band per box: a few boxes spread far apart need no more.)
        let most = MAX_BANDS.min(n as u32) as f32;
        let bands = ((c_max - c_min) / band_height).clamp(1.0, most) as u32;
        let bands = Bands {
            min: c_min,
            per_metre: if bands > 1 { bands as f32 / (c_max - c_min) } else { 0.0 },
            last: bands.max(1) - 1,
        };
        self.most_bands = self.most_bands.max(bands.last + 1);
        // The entries placed band by band (a count, then each band's share), and each
        // band's keys sorted on their own: smaller sorts, of plain words.
        let band_count = bands.last as usize + 1;
        self.starts.clear();
        self.starts.resize(band_count + 1, 0);
        self.spans.clear();
        for (b, _, _) in &self.boxes {
            let span = (bands.of(b[cross]), bands.of(b[cross + 2]));
            self.spans.push(span);
            for band in span.0..=span.1 {
                if let Some(c) = self.starts.get_mut(band as usize + 1) {
                    *c += 1;
                }
            }
        }
        for k in 1..self.starts.len() {
            let before = self.starts.get(k - 1).copied().unwrap_or(0);
            if let Some(c) = self.starts.get_mut(k) {
                *c += before;
            }
        }
        let entries = self.starts.last().copied().unwrap_or(0) as usize;
        self.keys.clear();
        self.keys.resize(entries, 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.starts);
        for (i, ((b, _, _), &(first, last))) in self.boxes.iter().zip(&self.spans).enumerate() {
            let key = (u64::from(ordered_bits(b[axis])) << 32) | i as u64;
            for band in first..=last {
                if let Some(at) = self.fill.get_mut(band as usize) {
                    if let Some(slot) = self.keys.get_mut(*at as usize) {
                        *slot = key;
                    }
                    *at += 1;
                }
            }
        }
        self.lo.clear();
        self.hi.clear();
        self.cross_lo.clear();
        self.cross_hi.clear();
        self.data.clear();
        self.moved.clear();
        self.band.clear();
        self.first.clear();
        // Each band's boxes followed by a chunk of padding that no interval holds (its lower
        // bound NaN: no comparison with it is true) and that is not swept itself (band
        // `PADDING`), so the sweep reads whole chunks without a bounds test of its own and
        // stops at the band's end.
        for band in 0..band_count {
            let (Some(&from), Some(&to)) = (self.starts.get(band), self.starts.get(band + 1)) else {
                continue;
            };
            let Some(keys) = self.keys.get_mut(from as usize..to as usize) else {
                continue;
            };
            keys.sort_unstable();
            for &key in keys.iter() {
                let (Some(&(b, d, m)), Some(&(first, _))) =
                    (self.boxes.get(key as u32 as usize), self.spans.get(key as u32 as usize))
                else {
                    continue;
                };
                self.lo.push(b[axis]);
                self.hi.push(b[axis + 2]);
                self.cross_lo.push(b[cross]);
                self.cross_hi.push(b[cross + 2]);
                self.data.push(d);
                self.moved.push(m);
                self.band.push(band as u32);
                self.first.push(first);
            }
            for _ in 0..CHUNK {
                self.lo.push(f32::NAN);
                self.hi.push(f32::NEG_INFINITY);
                self.cross_lo.push(0.0);
                self.cross_hi.push(0.0);
                self.data.push(0);
                self.moved.push(false);
                self.band.push(PADDING);
                self.first.push(PADDING);
            }
        }
        // 3. Sweep ([`sweep_sorted`]), in runs of whole bands on threads.
        let start = out.len();
        let budget = MAX_TESTS_PER_BOX * n;
        let runs = self.runs(threads, entries);
        let tests = if runs.len() < 2 {
            sweep_sorted(
                [&self.lo, &self.hi, &self.cross_lo, &self.cross_hi],
                &self.data,
                &self.moved,
                [&self.band, &self.first],
                budget,
                &mut self.hits,
                out,
            )
        } else {
            self.shared_sweeps += 1;
            let this = &*self;
            let tests = crate::solver::claim_into(&runs, out, |run, pairs| {
                fn part<'a, T>(v: &'a [T], run: &SweepRun) -> &'a [T] {
                    v.get(run.start..run.end).unwrap_or(&[])
                }
                sweep_sorted(
                    [&this.lo, &this.hi, &this.cross_lo, &this.cross_hi].map(|v| part(v, run)),
                    part(&this.data, run),
                    part(&this.moved, run),
                    [part(&this.band, run), part(&this.first, run)],
                    budget,
                    &mut Vec::new(),
                    pairs,
                )
            });
            tests.iter().fold(0usize, |sum, &t| sum.saturating_add(t))
        };
        let swept = tests <= budget;
        if !swept {
            out.truncate(start);
            self.back_off = BACK_OFF_SWEEPS;
            self.gave_up += 1;
        }
        swept
    }
}

/// A run of whole bands of the sweep arrays: their places, padding included
/// ([`SweepPrune::runs`]).
struct SweepRun {
    start: usize,
    end: usize,
}

impl SweepPrune {
    /// The bands cut into `threads` runs of consecutive whole bands of about equal
    /// entries (each band's entries followed by its padding, as laid out), or one run
    /// when there are fewer than [`MIN_PART_ENTRIES`] entries a thread (`entries` in all).
    fn runs(&self, threads: usize, entries: usize) -> Vec<SweepRun> {
        #[cfg(test)]
        let min_part = if self.min_part > 0 {
            self.min_part
        } else {
            MIN_PART_ENTRIES
        };
        #[cfg(not(test))]
        let min_part = MIN_PART_ENTRIES;
        let bands = self.starts.len().saturating_sub(1);
        // Band k's entries start at place starts[k] + k · CHUNK (the padding before it).
        let place = |k: usize| self.starts.get(k).map_or(0, |&s| s as usize) + k * CHUNK;
        let count = |k: usize| self.starts.get(k).map_or(0, |&s| s as usize);
        let parts = threads.min(entries / min_part.max(1)).min(bands);
        if parts < 2 {
            return Vec::new();
        }
        let mut runs = Vec::with_capacity(parts);
        let mut from = 0usize;
        for p in 1..=parts {
            // The first band at or past this run's share of the entries (the last run: all).
            let target = p * entries / parts;
            let mut to = from + 1;
            while to < bands && (count(to) < target || p == parts) {
                to += 1;
            }
            runs.push(SweepRun {
                start: place(from),
                end: place(to),
            });
            from = to;
            if from >= bands {
                break;
            }
        }
        runs
    }
}

/// Step 3 of [`SweepPrune::moved_pairs`] over its sorted arrays (`[lo, hi, cross_lo,
/// cross_hi]`, each band's entries followed by a chunk of padding that no interval holds):
/// box i against the boxes of its band after it that start inside its interval, a chunk
/// of them at a time, up to the first chunk with one starting past it. Each of those also
/// ends after box i starts (it starts no earlier and a box ends no earlier than it
/// starts), so only the cross axis is left to test, four boxes in one comparison; most
/// candidates miss (tumbler: two in three), so the hits are taken from the comparison's
/// bits. Returns the candidates tested, stopping (with pairs pushed) once they pass
/// `budget`. A function of its own, on slices: inlined into the
/// step, its loop kept its values on the stack (the sweep took 0.24 ms of tumbler's step).
#[inline(never)]
fn sweep_sorted(
    bounds: [&[f32]; 4],
    data: &[u32],
    moved: &[bool],
    [band_of_entry, first_band]: [&[u32]; 2],
    budget: usize,
    hits: &mut Vec<u32>,
    out: &mut Vec<u64>,
) -> usize {
    // The arrays cut to one length, which one test per chunk then covers.
    let len = bounds.iter().map(|b| b.len()).fold(
        data.len()
            .min(moved.len())
            .min(band_of_entry.len())
            .min(first_band.len()),
        usize::min,
    );
    let [lo, hi, cross_lo, cross_hi] = bounds.map(|b| b.get(..len).unwrap_or(&[]));
    let n = len.saturating_sub(CHUNK);
    // A box's hits (places in sweep order), written in the loop, which then calls nothing
    // (a call, even a push's rare growth, made the loop keep its vectors on the stack).
    // (Each place is written before it is read: no clearing.)
    // (Room for a whole chunk past the last hit: each chunk writes all its places.)
    if hits.len() < len + CHUNK {
        hits.resize(len + CHUNK, 0);
    }
    let mut tests = 0usize;
    for i in 0..n {
        let (Some(&end), Some(&c_lo), Some(&c_hi), Some(&d), Some(&m), Some(&band)) = (
            hi.get(i),
            cross_lo.get(i),
            cross_hi.get(i),
            data.get(i),
            moved.get(i),
            band_of_entry.get(i),
        ) else {
            break;
        };
        let first = first_band.get(i).copied().unwrap_or(PADDING);
        if band == PADDING {
            continue;
        }
        let (end4, c_lo4, c_hi4) = (F4::splat(end), F4::splat(c_lo), F4::splat(c_hi));
        let mut j = i + 1;
        let mut count = 0usize;
        while j + CHUNK <= len {
            let (Some(l), Some(cl), Some(ch)) = (
                lo.get(j..j + CHUNK),
                cross_lo.get(j..j + CHUNK),
                cross_hi.get(j..j + CHUNK),
            ) else {
                break;
            };
            let (Ok(l), Ok(cl), Ok(ch)) = (l.try_into(), cl.try_into(), ch.try_into()) else {
                break;
            };
            let inside = end4.ge(F4::new(l));
            let hit = (inside & c_hi4.ge(F4::new(cl)) & F4::new(ch).ge(c_lo4)).bits();
            // Every place written, the count advanced by the hits only (no branch on
            // each hit: which of a chunk's four hit is unpredictable).
            for l in 0..CHUNK {
                if let Some(slot) = hits.get_mut(count) {
                    *slot = (j + l) as u32;
                }
                count += ((hit >> l) & 1) as usize;
            }
            tests += CHUNK;
            if inside.bits() != (1 << CHUNK) - 1 {
                break;
            }
            j += CHUNK;
        }
        for &k in hits.get(..count).unwrap_or(&[]) {
            let k = k as usize;
            // Kept in the band of the larger cross lower bound: the later of the two
            // boxes' first bands (`Bands::of` does not decrease).
            if let (Some(&dk), Some(&mk), Some(&first_k)) = (data.get(k), moved.get(k), first_band.get(k)) {
                if (m | mk) && first.max(first_k) == band {
                    out.push(pair_key(d, dk));
                }
            }
        }
        if tests > budget {
            return tests;
        }
    }
    tests
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Aabb, Vec2};

    /// A small deterministic generator (xorshift), for boxes.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// Every pair of `boxes` (by index) that overlaps with at least one moved, by testing
    /// every pair with `Aabb::overlaps`.
    fn brute(boxes: &[(Aabb, bool)]) -> Vec<u64> {
        let mut out = Vec::new();
        for (i, a) in boxes.iter().enumerate() {
            for (j, b) in boxes.iter().enumerate().skip(i + 1) {
                if a.0.overlaps(b.0) && (a.1 || b.1) {
                    out.push(pair_key(i as u32, j as u32));
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// The sweep's pairs (sorted) and how many bands it cut, or None when it gave up.
    fn swept(boxes: &[(Aabb, bool)]) -> Option<(Vec<u64>, u32)> {
        swept_on(boxes, 1).map(|(pairs, bands, _)| (pairs, bands))
    }

    /// [`swept`] on `threads` threads of a pool of its own, sharing any set of more than
    /// eight entries a thread, and whether it did.
    fn swept_on(boxes: &[(Aabb, bool)], threads: usize) -> Option<(Vec<u64>, u32, bool)> {
        let mut tree = DynamicTree::new();
        for (i, (b, _)) in boxes.iter().enumerate() {
            tree.create_proxy(*b, 1, i as u64);
        }
        let moved: Vec<bool> = boxes.iter().map(|b| b.1).collect();
        let mut sp = SweepPrune {
            min_part: 8,
            ..SweepPrune::default()
        };
        let mut out = vec![7];
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok()?;
        let ok = pool.install(|| sp.moved_pairs(&tree, &moved, threads, &mut out));
        assert_eq!(out.first(), Some(&7), "the sweep keeps what `out` held");
        out.remove(0);
        out.sort_unstable();
        ok.then_some((out, sp.most_bands, sp.shared_sweeps > 0))
    }

    /// The sweep finds exactly the pairs a test of every pair finds: random boxes of
    /// mixed sizes (some sharing bounds, some only touching, so the ≤ comparisons are
    /// checked at equality), with and without moved marks, spread wide in x or in y (so
    /// both sweep axes are taken) about the origin (negative bounds too), over areas many
    /// boxes high across the sweep (so pairs of boxes that share several bands are kept
    /// once; every seventh box is long, across up to a dozen bands); on one thread and
    /// shared between three (runs of whole bands).
    #[test]
    fn sweep_finds_exactly_the_overlapping_pairs() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut most_bands, mut shared_cases) = (0, 0);
        for case in 0..40 {
            let n = 5 + case * 7;
            let (wide_x, wide_y) = [(30.0, 5.0), (5.0, 30.0), (40.0, 25.0), (15.0, 60.0), (80.0, 70.0)][case % 5];
            let mut boxes = Vec::new();
            for k in 0..n {
                let (x, y) = (
                    ((rng.next() - 0.3) * wide_x).round() * 0.5,
                    ((rng.next() - 0.3) * wide_y).round() * 0.5,
                );
                let long = if k % 7 == 3 {
                    1.0 + (rng.next() * 40.0).round()
                } else {
                    1.0
                };
                let (mut w, mut h) = (
                    0.5 + (rng.next() * 4.0).round() * 0.25,
                    0.5 + (rng.next() * 4.0).round() * 0.25,
                );
                if k % 2 == 0 {
                    w *= long;
                } else {
                    h *= long;
                }
                let moved = case % 3 != 0 || k % 4 == 0;
                boxes.push((Aabb::new(Vec2::new(x, y), Vec2::new(x + w, y + h)), moved));
            }
            let want = brute(&boxes);
            assert!(case < 3 || !want.is_empty(), "case {case} has pairs");
            let (got, bands) = swept(&boxes).unwrap_or_default();
            assert_eq!(got, want, "case {case}");
            most_bands = most_bands.max(bands);
            // Shared between three threads, by runs of bands: the same pairs.
            let (got, _, shared) = swept_on(&boxes, 3).unwrap_or_default();
            assert_eq!(got, want, "case {case} on three threads");
            shared_cases += usize::from(shared);
        }
        assert!(most_bands >= 8, "some cases are cut into bands: at most {most_bands}");
        assert!(shared_cases >= 20, "{shared_cases} of 40 cases shared their sweep");
    }

    /// Boxes all on one spot, or points (no extent: the bands' height is zero, and their
    /// count 0 / 0), still give every pair: one band.
    #[test]
    fn sweep_of_boxes_on_one_spot() {
        for half in [0.0f32, 0.5] {
            let boxes: Vec<(Aabb, bool)> = (0..6)
                .map(|_| {
                    (
                        Aabb::new(Vec2::new(2.0 - half, -1.0 - half), Vec2::new(2.0 + half, -1.0 + half)),
                        true,
                    )
                })
                .collect();
            let want = brute(&boxes);
            assert_eq!(want.len(), 15, "every pair touches");
            assert_eq!(swept(&boxes), Some((want, 1)), "half extent {half}");
        }
    }

    /// A column of boxes lined up on both axes (each box's interval holds all the others
    /// on either axis) is too many tests a box: the sweep gives up, leaves `out` as it was,
    /// and skips the next sweeps.
    #[test]
    fn sweep_gives_up_on_boxes_lined_up_on_both_axes() {
        let boxes: Vec<(Aabb, bool)> = (0..400)
            .map(|k| {
                let t = k as f32 * 0.001;
                (Aabb::new(Vec2::new(t, t), Vec2::new(t + 1.0, t + 1.0)), true)
            })
            .collect();
        assert_eq!(brute(&boxes).len(), 400 * 399 / 2, "every pair overlaps");
        assert_eq!(swept(&boxes), None);
        let mut tree = DynamicTree::new();
        tree.create_proxy(Aabb::new(Vec2::ZERO, Vec2::new(1.0, 1.0)), 1, 0);
        tree.create_proxy(Aabb::new(Vec2::ZERO, Vec2::new(1.0, 1.0)), 1, 1);
        let mut sp = SweepPrune {
            back_off: BACK_OFF_SWEEPS,
            ..SweepPrune::default()
        };
        let mut out = Vec::new();
        assert!(!sp.moved_pairs(&tree, &[true, true], 1, &mut out), "backing off");
        assert_eq!(sp.back_off, BACK_OFF_SWEEPS - 1);
    }

    #[test]
    fn ordered_bits_sort_as_the_floats() {
        // Distinct floats in increasing order map to increasing words (−0 just below +0,
        // which compare equal as floats: either order sorts them).
        let xs = [
            f32::MIN,
            -1e30,
            -2.5,
            -1.0,
            -1e-30,
            -0.0,
            0.0,
            1e-30,
            0.5,
            3.0,
            1e30,
            f32::MAX,
        ];
        for w in xs.windows(2) {
            assert!(ordered_bits(w[0]) < ordered_bits(w[1]), "{} {}", w[0], w[1]);
        }
    }
}
