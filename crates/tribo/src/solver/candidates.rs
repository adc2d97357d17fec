//! The solver's view of the step's touching contacts, the same for every build of the
//! wide solver (`lanes4`, `lanes8`, `lanes8_avx512`): each contact's [`Candidate`] (what building its
//! constraint reads) and [`ColourKey`] (what the colouring reads), and the flags of a
//! constraint's colour byte.

use super::contact_solver::{ConstraintBodies, ContactInput, MASS_RATIO_GROUP};
use super::SolverBody;
use crate::collision::contact::Contact;

/// One touching contact to solve this step: what building its constraint reads.
///
/// `repr(C)`, 16-byte aligned, 160 bytes (contact and bodies, then the solver input). What
/// the colouring reads is a [`ColourKey`], in an array of its own.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct Candidate {
    pub contact: u32,
    pub bodies: ConstraintBodies,
    pub input: ContactInput,
}

impl Candidate {
    /// Writes the candidate of contact `contact` (record `c`, between the bodies of solver
    /// entries `ba` and `bb`) in place, and its colouring key into `key` (`colour`: the
    /// contact's colour last step): the 160-byte candidate built on the stack and then
    /// copied into its slot cost a `memcpy` per touching contact on top of the writes
    /// (large_pyramid: ~2 % of the step). The bodies' part is read from the solver entries
    /// here, not passed in built: a record just written field by field on the stack and
    /// copied by 16-byte loads cannot be forwarded from the store buffer (tumbler: 44 % of
    /// this function's samples waited on that copy).
    pub fn fill(
        &mut self,
        contact: u32,
        colour: u8,
        ba: &SolverBody,
        bb: &SolverBody,
        c: &Contact,
        key: &mut ColourKey,
    ) {
        self.contact = contact;
        self.bodies = ConstraintBodies {
            index_a: ba.index,
            index_b: bb.index,
            inv_mass_a: ba.inv_mass,
            inv_i_a: ba.inv_i,
            inv_mass_b: bb.inv_mass,
            inv_i_b: bb.inv_i,
            center_a: ba.center,
            center_b: bb.center,
        };
        self.input.fill(c);
        let input = &self.input;
        let b = &self.bodies;
        let flag = |on: bool, bit: u8| if on { bit } else { 0 };
        let [moving_a, moving_b] = b.moving();
        *key = ColourKey {
            index_a: b.index_a,
            index_b: b.index_b,
            colour,
            flags: flag(fast_first(input), FAST)
                | flag(input.count < 2, SINGLE)
                | flag(input.may_be_new_resting(), FRESH)
                | flag(moving_a, KEY_DYNAMIC_A)
                | flag(moving_b, KEY_DYNAMIC_B)
                | flag(mass_ratio(b).is_some(), KEY_RATIO)
                | flag(input.restitution > 0.0, KEY_RESTITUTION),
        };
    }

    /// A placeholder for a contact that is not solved this step.
    pub const SKIP: Candidate = Candidate {
        contact: u32::MAX,
        bodies: ConstraintBodies::STATIC,
        input: ContactInput::EMPTY,
    };
}

/// What the colouring pass reads of a candidate: 12 bytes, in an array of its own, so the
/// serial colouring streams these instead of one cache line of each 160-byte candidate
/// (large_pyramid: 15 000 lines a step).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ColourKey {
    pub(crate) index_a: u32,
    pub(crate) index_b: u32,
    /// The colour the contact had when last solved ([`crate::collision::contact::NO_COLOUR`]: none), tried first.
    pub(crate) colour: u8,
    /// [`FAST`], [`FRESH`], [`KEY_DYNAMIC_A`], [`KEY_DYNAMIC_B`], [`KEY_RATIO`].
    pub(crate) flags: u8,
}

impl ColourKey {
    /// The solver slots of the constraint's two bodies (0: a static body).
    #[inline]
    pub fn slots(&self) -> (u32, u32) {
        (self.index_a, self.index_b)
    }

    /// The solver slots of the two bodies when both are awake dynamic bodies (the pairs
    /// that join islands), else None.
    #[inline]
    pub fn dynamic_pair(&self) -> Option<(u32, u32)> {
        let both = KEY_DYNAMIC_A | KEY_DYNAMIC_B;
        (self.flags & both == both).then_some((self.index_a, self.index_b))
    }
}

/// Flag of a [`ColourKey`]: side A is a moving body (takes a colour).
pub(crate) const KEY_DYNAMIC_A: u8 = 0x01;
/// Flag of a [`ColourKey`]: side B is a moving body.
pub(crate) const KEY_DYNAMIC_B: u8 = 0x02;
/// Flag of a [`ColourKey`]: one body is more than [`MASS_RATIO_GROUP`] times heavier than
/// the other (the colouring then reads the whole candidate, see [`mass_ratio`]).
pub(crate) const KEY_RATIO: u8 = 0x04;
/// Flag of a [`ColourKey`]: the contact has restitution.
pub(crate) const KEY_RESTITUTION: u8 = 0x08;

/// For two bodies with mass, one more than [`MASS_RATIO_GROUP`] times heavier than the
/// other: (mass ratio, light body, heavy body, whether A is the light one).
#[inline]
pub(crate) fn mass_ratio(b: &ConstraintBodies) -> Option<(f32, u32, u32, bool)> {
    if !(b.inv_mass_a > 0.0 && b.inv_mass_b > 0.0) {
        return None;
    }
    // The light body, and the direction from it to the heavy one (the normal points from A
    // to B).
    let out = if b.inv_mass_a > b.inv_mass_b {
        (b.inv_mass_a / b.inv_mass_b, b.index_a, b.index_b, true)
    } else {
        (b.inv_mass_b / b.inv_mass_a, b.index_b, b.index_a, false)
    };
    (out.0 > MASS_RATIO_GROUP).then_some(out)
}

/// The candidates of a step: `slots` (and their colouring `keys`) indexed by contact,
/// `list` the contacts to solve (in contact order); candidate `i` is `slots[list[i]]`.
#[derive(Clone, Copy)]
pub(crate) struct Candidates<'a> {
    pub(crate) slots: &'a [Candidate],
    pub(crate) keys: &'a [ColourKey],
    pub(crate) list: &'a [u32],
}

impl<'a> Candidates<'a> {
    pub fn new(slots: &'a [Candidate], keys: &'a [ColourKey], list: &'a [u32]) -> Candidates<'a> {
        Candidates { slots, keys, list }
    }

    /// The `i`-th candidate.
    #[inline]
    pub fn get(&self, i: usize) -> Option<&'a Candidate> {
        self.slots.get(*self.list.get(i)? as usize)
    }

    /// The candidates in order.
    pub fn iter(&self) -> impl Iterator<Item = &'a Candidate> + '_ {
        self.list.iter().filter_map(|&ci| self.slots.get(ci as usize))
    }

    /// The candidates' contacts and colouring keys, in order.
    pub(crate) fn keys(&self) -> impl Iterator<Item = (u32, &'a ColourKey)> + '_ {
        self.list
            .iter()
            .filter_map(|&ci| Some((ci, self.keys.get(ci as usize)?)))
    }
}

/// Flag in a constraint's colour byte: it goes to the front of its colour ([`fast_first`]).
pub(crate) const FAST: u8 = 0x40;
/// Flag in a constraint's colour byte: all its points are new this step and touching
/// (`ContactInput::may_be_new_resting`).
pub(crate) const FRESH: u8 = 0x20;
/// Flag in a constraint's colour byte (and a [`ColourKey`]'s): it has one point or none,
/// and goes to the back of its colour, after the two-point constraints the front does not
/// take. Groups of single points then take the wide solver's one-point path, which skips
/// the second point and the 2×2 block, and the two-point groups find a block solution in
/// every lane more often. In tumbler a quarter of the lanes have one point; mixed in with
/// two-point lanes they sent two groups in three to the general path (tumbler's step
/// −3.5 %, junkyard's −8 %). Like [`FAST`], it only orders a colour: a kept layout does not
/// compare it.
pub(crate) const SINGLE: u8 = 0x80;
/// The flags that only order a colour ([`FAST`], [`SINGLE`]): a kept layout does not
/// compare them.
pub(crate) const ORDER_FLAGS: u8 = FAST | SINGLE;
/// Every flag a constraint's colour byte carries beside its colour.
pub(crate) const COLOUR_FLAGS: u8 = ORDER_FLAGS | FRESH;

/// Whether a constraint goes to the front of its colour: a face contact whose two points
/// both carried load last step, which will most likely keep both points pushing and take
/// the wide solver's fast path (the 2×2 block with both points active). The others —
/// faces touching on one corner, speculative pairs not yet touching, and behind those the
/// single points ([`SINGLE`]) — go to the back, so the fast path is not lost to a whole
/// group of four because one lane needs the general case. Constraints of one colour share
/// no moving body, so their order inside the colour does not change any result.
#[inline]
pub(crate) fn fast_first(input: &ContactInput) -> bool {
    input.count == 2 && input.points[0].normal_impulse > 0.0 && input.points[1].normal_impulse > 0.0
}
