//! Generational ids and the arena that issues them.
//!
//! An id is an index plus a generation. Destroying an object bumps its slot's generation,
//! so an old id never reaches the slot's next tenant: it gets an error instead.

/// Handle to a body. Stale handles are detected (see [`crate::Error::InvalidBody`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId {
    /// Slot index.
    pub index: u32,
    /// Slot generation when the id was issued.
    pub generation: u32,
}

/// Handle to a shape. Stale handles are detected (see [`crate::Error::InvalidShape`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ShapeId {
    /// Slot index.
    pub index: u32,
    /// Slot generation when the id was issued.
    pub generation: u32,
}

/// Handle to a joint. Stale handles are detected (see [`crate::Error::InvalidJoint`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId {
    /// Slot index.
    pub index: u32,
    /// Slot generation when the id was issued.
    pub generation: u32,
}

#[derive(Clone, Debug)]
struct Slot<T> {
    generation: u32,
    value: Option<T>,
}

/// Slots with generations and a LIFO free list (deterministic reuse order).
#[derive(Clone, Debug)]
pub(crate) struct Arena<T> {
    slots: Vec<Slot<T>>,
    free: Vec<u32>,
    len: usize,
    /// How many times a value was handed out for writing, inserted or removed
    /// ([`Arena::writes`]).
    writes: u64,
}

impl<T> Default for Arena<T> {
    fn default() -> Self {
        Arena {
            slots: Vec::new(),
            free: Vec::new(),
            len: 0,
            writes: 0,
        }
    }
}

impl<T> Arena<T> {
    /// A count that every write access (`insert`, `remove`, `get_mut`, `at_mut`,
    /// `for_each_live_mut*`) advances, but [`Arena::at_mut_quiet`]: while it stays the same,
    /// no value has changed (what a copy made of the values, like the step's solver
    /// entries of the bodies, needs to know to be kept).
    #[inline]
    pub fn writes(&self) -> u64 {
        self.writes
    }

    /// Inserts a value; returns (index, generation).
    pub fn insert(&mut self, value: T) -> (u32, u32) {
        self.writes += 1;
        self.len += 1;
        if let Some(i) = self.free.pop() {
            let slot = &mut self.slots[i as usize];
            slot.value = Some(value);
            (i, slot.generation)
        } else {
            self.slots.push(Slot {
                generation: 1,
                value: Some(value),
            });
            ((self.slots.len() - 1) as u32, 1)
        }
    }

    /// Removes the value if the generation matches.
    pub fn remove(&mut self, index: u32, generation: u32) -> Option<T> {
        self.writes += 1;
        let slot = self.slots.get_mut(index as usize)?;
        if slot.generation != generation || slot.value.is_none() {
            return None;
        }
        slot.generation = slot.generation.wrapping_add(1).max(1);
        self.free.push(index);
        self.len -= 1;
        slot.value.take()
    }

    /// The value if the id is live.
    #[inline]
    pub fn get(&self, index: u32, generation: u32) -> Option<&T> {
        let slot = self.slots.get(index as usize)?;
        if slot.generation == generation {
            slot.value.as_ref()
        } else {
            None
        }
    }

    /// The value if the id is live.
    #[inline]
    pub fn get_mut(&mut self, index: u32, generation: u32) -> Option<&mut T> {
        self.writes += 1;
        self.get_mut_quiet(index, generation)
    }

    /// [`Arena::get_mut`] without advancing [`Arena::writes`]: for a caller that records
    /// the write itself.
    #[inline]
    pub fn get_mut_quiet(&mut self, index: u32, generation: u32) -> Option<&mut T> {
        let slot = self.slots.get_mut(index as usize)?;
        if slot.generation == generation {
            slot.value.as_mut()
        } else {
            None
        }
    }

    /// Asks for the cache line of a slot's first bytes ahead of its use (a hint: reads
    /// nothing, see [`crate::solver::prefetch_lines`]).
    #[inline]
    pub fn prefetch(&self, index: u32) {
        if let Some(slot) = self.slots.get(index as usize) {
            crate::solver::prefetch_lines(slot, 1);
        }
    }

    /// The first `lines` cache lines of a slot, asked for (see [`Arena::prefetch`]).
    #[inline]
    pub fn prefetch_n(&self, index: u32, lines: usize) {
        if let Some(slot) = self.slots.get(index as usize) {
            crate::solver::prefetch_lines(slot, lines);
        }
    }

    /// The value at a slot index, whatever its generation (internal links).
    #[inline]
    pub fn at(&self, index: u32) -> Option<&T> {
        self.slots.get(index as usize).and_then(|s| s.value.as_ref())
    }

    /// The value at a slot index, whatever its generation (internal links).
    #[inline]
    pub fn at_mut(&mut self, index: u32) -> Option<&mut T> {
        self.writes += 1;
        self.at_mut_quiet(index)
    }

    /// [`Arena::at_mut`] without advancing [`Arena::writes`]: for a caller that keeps the
    /// copies of what it writes up to date itself.
    #[inline]
    pub fn at_mut_quiet(&mut self, index: u32) -> Option<&mut T> {
        self.slots.get_mut(index as usize).and_then(|s| s.value.as_mut())
    }

    /// Calls `f(index, value)` for every live value, split between the pool's threads when
    /// `parallel` (each call may only touch its own value).
    pub fn for_each_live_mut(&mut self, parallel: bool, min_len: usize, f: impl Fn(u32, &mut T) + Sync)
    where
        T: Send,
    {
        self.writes += 1;
        crate::solver::for_each_mut(parallel, &mut self.slots, min_len, |i, slot| {
            if let Some(v) = slot.value.as_mut() {
                f(i as u32, v);
            }
        });
    }

    /// [`Arena::for_each_live_mut`] with each live value's entry of `other` (indexed by
    /// slot; slots past its end are not visited).
    pub fn for_each_live_mut_with<U: Send>(
        &mut self,
        parallel: bool,
        min_len: usize,
        other: &mut [U],
        f: impl Fn(u32, &mut T, &mut U) + Sync,
    ) where
        T: Send,
    {
        self.writes += 1;
        crate::solver::for_each_mut2(parallel, &mut self.slots, other, min_len, |i, slot, u| {
            if let Some(v) = slot.value.as_mut() {
                f(i as u32, v, u);
            }
        });
    }

    /// The generation currently stored at a slot.
    #[inline]
    pub fn generation(&self, index: u32) -> u32 {
        self.slots.get(index as usize).map_or(0, |s| s.generation)
    }

    /// Number of live values.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Number of slots (live or free); indices are below this.
    pub fn capacity(&self) -> usize {
        self.slots.len()
    }

    /// Live values with their slot index, in index order (deterministic).
    pub fn iter(&self) -> impl Iterator<Item = (u32, &T)> {
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.value.as_ref().map(|v| (i as u32, v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_ids_are_rejected() {
        let mut a = Arena::default();
        let (i, g) = a.insert(5);
        assert_eq!(a.get(i, g), Some(&5));
        assert_eq!(a.remove(i, g), Some(5));
        assert_eq!(a.get(i, g), None);
        let (j, h) = a.insert(7);
        assert_eq!(j, i, "slot reused");
        assert_ne!(h, g, "generation bumped");
        assert_eq!(a.get(i, g), None, "old id does not reach the new tenant");
        assert_eq!(a.remove(i, g), None);
        assert_eq!(a.len(), 1);
    }
}
