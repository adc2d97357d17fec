//! Broad phase: two dynamic AABB trees (static shapes; kinematic and dynamic shapes) of fat
//! boxes, and pair finding for the proxies that moved.
//!
//! Incremental: only shapes whose box left its fat box are re-inserted and queried, so a
//! step costs O(m log n) for m moved shapes among n. Pairs live as contacts until their
//! fat boxes stop overlapping (checked in the narrow phase).

use super::sweep_prune::SweepPrune;
use super::tree::{DynamicTree, FlatTree};
use crate::geometry::{Shape, SPECULATIVE_DISTANCE};
use crate::math::Aabb;
use std::collections::HashMap;

/// Which tree a proxy lives in.
pub(crate) const STATIC_TREE: u8 = 0;
/// Tree of kinematic and dynamic shapes.
pub(crate) const MOVING_TREE: u8 = 1;

/// Largest extra room [m] added around a moving shape's box when it is (re)inserted, so
/// small motions do not touch the tree.
pub(crate) const MAX_AABB_MARGIN: f32 = 0.05;

/// The room [m] around a shape's box in the tree: for moving shapes 1/8 of the shape's
/// reach from its centroid, at most [`MAX_AABB_MARGIN`]; for static shapes, which do not
/// move, the speculative distance. A larger margin moves fewer proxies but makes more
/// pairs of bodies that never touch (Box2D v3.2's `b2ComputeShapeMargin`, same values).
pub(crate) fn aabb_margin(geometry: &Shape, is_static: bool) -> f32 {
    if is_static {
        SPECULATIVE_DISTANCE
    } else {
        (0.125 * geometry.max_extent(geometry.centroid())).min(MAX_AABB_MARGIN)
    }
}

/// How far [m] a shape may move in one step before its box in the tree is swept along the
/// motion: the larger of the speculative distance and half the shape's thickness
/// ([`Shape::min_extent`]). Only the boxes of a body that touched nothing this step, or of
/// a bullet ([`crate::BodyDef::bullet`]), are swept (`World::finalize`).
///
/// Why sweep at all: the speculative margin of the narrow phase grows with the pair's
/// relative motion, but only for pairs that exist, so a body moving further than its boxes'
/// room in one step could meet another body before their pair exists (a step of overlap),
/// or pass a thin one. Static shapes are covered either way: a body that left its fat box is
/// stopped where it first touches one (continuous collision, `World::stop_at_static_shapes`).
/// Half the thickness is Box2D's line for continuous collision (a body is "fast" when it
/// moves more than `safetyFactor` 0.5 × its smallest extent per step).
///
/// Why not sweep a body that touches something: a box swept along the body's own velocity
/// is long for every body of a pile that moves as a whole, although its bodies barely move
/// relative to each other, and every such box makes pairs that never touch (Box2D sweeps
/// none: its boxes grow by a fixed margin). Pairs at the end of Box2D's spinner, whose
/// 6 076 bodies ride round the ring at ~95 m/s: 65.6 k with every fast box swept, 24.0 k
/// with none (Box2D: 22.4 k). A body in free flight touches nothing: a falling ragdoll, a
/// projectile before its impact keep their swept boxes.
pub(crate) fn sweep_free(geometry: &Shape) -> f32 {
    SPECULATIVE_DISTANCE.max(SWEEP_FREE_FRACTION * geometry.min_extent())
}

/// Fraction of a shape's thickness it may move per step unswept ([`sweep_free`]).
const SWEEP_FREE_FRACTION: f32 = 0.5;

/// The broad phase.
#[derive(Default)]
pub(crate) struct BroadPhase {
    pub trees: [DynamicTree; 2],
    /// Shape indices whose proxies moved (or were created) since the last pair update.
    pub moved: Vec<u32>,
    /// Existing pairs: pair key → contact index. Used for lookups only, never iterated in
    /// an order that matters (the contact renumbering replaces each value on its own), so
    /// hash order cannot leak into the simulation.
    pub pairs: HashMap<u64, u32, BuildPairHasher>,
    /// Query copies of the trees ([`FlatTree`]), made when a step queries many proxies.
    pub flat: [FlatTree; 2],
    /// Scratch of the pair update: the keys of the overlapping pairs with a moved proxy.
    pub scratch_keys: Vec<u64>,
    /// Scratch of the pair update: per shape slot, whether its proxy moved.
    pub moved_mark: Vec<bool>,
    /// Pair updates that walked the moving tree against itself (diagnostics and tests).
    pub walks: u64,
    /// Near moves in the moving tree refit it later, all at once ([`BroadPhase::refit`];
    /// a far move is reinserted at once): on during a step's finalize, which moves most
    /// proxies of a pile in motion and queries only the static tree.
    pub defer_refits: bool,
    /// Sweep and prune over the moving tree's boxes (its buffers and back-off), tried
    /// before that walk.
    pub sweep: SweepPrune,
    /// Tests: never find the moving tree's pairs all at once (no sweep, no walk), query
    /// per moved shape (the reference the sweep and the walk must match).
    #[cfg(test)]
    pub no_walk: bool,
    /// Tests: walk the tree without trying the sweep first.
    #[cfg(test)]
    pub no_sweep: bool,
}

/// A pair update that queries at least 1/`FLAT_QUERY_SHARE` of a tree's proxy count
/// queries a [`FlatTree`] copy of it (made in O(n); it halves the node loads of a query).
const FLAT_QUERY_SHARE: usize = 8;

impl BroadPhase {
    /// Makes the query copies of the trees current where `queries` queries pay for it (a
    /// copy that is still current, as the static tree's mostly is, is kept); returns which
    /// trees to query through their copy. Queries give the same overlaps either way.
    /// `few[k]`: tree `k` takes few queries whatever `queries` says (no copy made for it).
    pub fn prepare_queries(&mut self, queries: usize, few: [bool; 2]) -> [bool; 2] {
        let mut use_flat = [false; 2];
        for k in 0..2 {
            let count = self.trees[k].proxy_count();
            if queries * FLAT_QUERY_SHARE >= count && !few[k] && count > 0 {
                self.make_flat(k);
            }
            use_flat[k] = self.flat[k].is_copy_of(&self.trees[k]);
        }
        use_flat
    }

    /// Makes tree `k`'s [`FlatTree`] copy current (kept when it is).
    pub fn make_flat(&mut self, k: usize) {
        if !self.flat[k].is_copy_of(&self.trees[k]) {
            self.trees[k].flatten_into(&mut self.flat[k]);
        }
    }

    /// Inserts a proxy for a shape; returns its proxy id.
    pub fn create_proxy(&mut self, tree: u8, aabb: Aabb, category: u64, shape_index: u32) -> u32 {
        self.moved.push(shape_index);
        self.trees[tree as usize].create_proxy(aabb, category, shape_index as u64)
    }

    /// Removes a proxy.
    pub fn destroy_proxy(&mut self, tree: u8, proxy: u32) {
        self.trees[tree as usize].destroy_proxy(proxy);
    }

    /// Moves a proxy to a new fat box and marks its shape as moved. While
    /// [`BroadPhase::defer_refits`] is on, a near move in the moving tree leaves the tree's
    /// refit to [`BroadPhase::refit`].
    pub fn move_proxy(&mut self, tree: u8, proxy: u32, aabb: Aabb, shape_index: u32) {
        if self.defer_refits && tree == MOVING_TREE {
            self.trees[tree as usize].move_proxy_deferred(proxy, aabb);
        } else {
            self.trees[tree as usize].move_proxy_near(proxy, aabb);
        }
        self.moved.push(shape_index);
    }

    /// Refits the trees whose moves were deferred, and stops deferring.
    pub fn refit(&mut self) {
        self.defer_refits = false;
        for tree in &mut self.trees {
            tree.refit_all();
        }
    }
}

/// A small, fast, deterministic hasher for pair keys (a multiplicative hash: the keys are
/// already well-spread integers, so SipHash's DoS resistance buys nothing here).
#[derive(Default, Clone, Copy)]
pub(crate) struct BuildPairHasher;

impl std::hash::BuildHasher for BuildPairHasher {
    type Hasher = PairHasher;
    fn build_hasher(&self) -> PairHasher {
        PairHasher(0)
    }
}

/// See [`BuildPairHasher`].
pub(crate) struct PairHasher(u64);

impl std::hash::Hasher for PairHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(5) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, k: u64) {
        self.0 = (k ^ (k >> 29)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}
