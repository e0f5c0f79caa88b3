//! Nested media: the solids a ray is inside, as a small fixed-size stack carried by each ray
//! (Schmidt & Budge 2002, "Simple Nested Dielectrics in Ray Traced Images").
//!
//! Where solids overlap, the medium with the highest rank fills the overlap; of equal
//! ranks, the one entered last. A material's rank is its `priority`, except that priority
//! 0 (plain, the default) ranks above every other: a plain solid is always a real surface
//! and its own medium applies inside it. A surface whose crossing leaves the current medium
//! unchanged (a lower-ranked solid's surface inside a higher-ranked one) is no interface at
//! all: a "false hit" the ray passes through.
//!
//! The stack holds [`MediumStack::CAPACITY`] entries inline (no allocation per ray). Inside
//! more solids than that at once, entering another forgets the outermost (the first
//! entered): the innermost media are the ones rays meet next.

/// One solid a ray is inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Medium {
    /// The IR index of the top-level object (the shape, or the CSG root): one medium.
    pub object: u32,
    /// The index of the material the ray entered it through (its ior and absorption).
    pub material: u32,
    /// The material's rank (see the module documentation).
    pub rank: u32,
}

const NO_MEDIUM: Medium = Medium {
    object: u32::MAX,
    material: 0,
    rank: 0,
};

/// The solids a ray is inside, oldest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MediumStack {
    len: u8,
    entries: [Medium; MediumStack::CAPACITY],
}

impl Default for MediumStack {
    fn default() -> Self {
        MediumStack::EMPTY
    }
}

impl MediumStack {
    /// How many nested solids a ray keeps track of.
    pub const CAPACITY: usize = 8;

    /// In no solid: in the air (ior 1, no absorption).
    pub const EMPTY: MediumStack = MediumStack {
        len: 0,
        entries: [NO_MEDIUM; MediumStack::CAPACITY],
    };

    pub fn as_slice(&self) -> &[Medium] {
        &self.entries[..self.len as usize]
    }

    /// The medium the ray travels in: the highest rank, the last entered among equals;
    /// `None` in the air.
    #[inline]
    pub fn current(&self) -> Option<Medium> {
        let mut best: Option<Medium> = None;
        for &entry in self.as_slice() {
            if best.is_none_or(|b| entry.rank >= b.rank) {
                best = Some(entry);
            }
        }
        best
    }

    /// The medium that would be current once the most recent entry of `object` is gone.
    #[inline]
    pub fn current_without(&self, object: u32) -> Option<Medium> {
        let entries = self.as_slice();
        let skip = entries.iter().rposition(|m| m.object == object);
        let mut best: Option<Medium> = None;
        for (i, &entry) in entries.iter().enumerate() {
            if Some(i) != skip && best.is_none_or(|b| entry.rank >= b.rank) {
                best = Some(entry);
            }
        }
        best
    }

    pub fn contains(&self, object: u32) -> bool {
        self.as_slice().iter().any(|m| m.object == object)
    }

    /// The ray enters a solid. When the stack is full the outermost entry is forgotten.
    #[inline]
    pub fn enter(&mut self, medium: Medium) {
        if self.len as usize == Self::CAPACITY {
            self.entries.copy_within(1.., 0);
            self.len -= 1;
        }
        self.entries[self.len as usize] = medium;
        self.len += 1;
    }

    /// The ray leaves a solid: its most recent entry goes. Returns whether it was there.
    #[inline]
    pub fn leave(&mut self, object: u32) -> bool {
        let len = self.len as usize;
        let Some(index) = self.entries[..len].iter().rposition(|m| m.object == object) else {
            return false;
        };
        self.entries.copy_within(index + 1..len, index);
        self.len -= 1;
        true
    }

    /// A ray leaving a solid it was not known to be inside (it started inside, or the
    /// solid was forgotten) was inside it all along, outside everything else it is in:
    /// the solid goes to the bottom of the stack. Ignored when the stack is full.
    pub fn insert_outermost(&mut self, medium: Medium) {
        let len = self.len as usize;
        if len == Self::CAPACITY {
            return;
        }
        self.entries.copy_within(0..len, 1);
        self.entries[0] = medium;
        self.len += 1;
    }
}

/// Whether two "current media" are the same (both air, or the same solid): crossing from
/// one to the other is no interface.
#[inline]
pub fn same_medium(a: Option<Medium>, b: Option<Medium>) -> bool {
    a.map(|m| m.object) == b.map(|m| m.object)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn medium(object: u32, rank: u32) -> Medium {
        Medium {
            object,
            material: object,
            rank,
        }
    }

    #[test]
    fn the_highest_rank_and_then_the_latest_is_current() {
        let mut stack = MediumStack::EMPTY;
        assert_eq!(stack.current(), None);
        stack.enter(medium(1, 2));
        stack.enter(medium(2, 1));
        // Water (rank 1) entered inside glass (rank 2): the glass still fills the overlap.
        assert_eq!(stack.current(), Some(medium(1, 2)));
        assert!(stack.leave(1));
        assert_eq!(stack.current(), Some(medium(2, 1)));
        // Equal ranks: the last entered.
        stack.enter(medium(3, 1));
        assert_eq!(stack.current(), Some(medium(3, 1)));
        assert!(!stack.leave(7));
        assert!(stack.leave(3) && stack.leave(2));
        assert!(stack.as_slice().is_empty());
    }

    #[test]
    fn a_full_stack_forgets_the_outermost_solid() {
        let mut stack = MediumStack::EMPTY;
        for object in 0..MediumStack::CAPACITY as u32 + 2 {
            stack.enter(medium(object, 1));
        }
        assert_eq!(stack.as_slice().len(), MediumStack::CAPACITY);
        assert!(!stack.contains(0) && !stack.contains(1) && stack.contains(2));
        assert_eq!(stack.current().map(|m| m.object), Some(9));
        // Leaving a forgotten solid changes nothing.
        assert!(!stack.leave(0));
        assert_eq!(stack.as_slice().len(), MediumStack::CAPACITY);
    }

    #[test]
    fn leaving_an_unknown_solid_puts_it_outermost_first() {
        let mut stack = MediumStack::EMPTY;
        stack.enter(medium(5, u32::MAX));
        stack.insert_outermost(medium(4, u32::MAX));
        assert_eq!(stack.as_slice()[0], medium(4, u32::MAX));
        assert_eq!(stack.current(), Some(medium(5, u32::MAX)));
        assert!(same_medium(None, None));
        assert!(!same_medium(None, Some(medium(4, 1))));
    }
}
