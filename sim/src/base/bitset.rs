//! A fixed-size set of body indices, iterated in ascending order: the
//! physics step's awake, pending and live sets.

/// A set of indices `0 .. len`, one bit each.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct BitSet {
    words: Vec<u64>,
}

impl BitSet {
    /// An empty set for indices below `len`.
    pub fn new(len: usize) -> BitSet {
        BitSet {
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// Adds `i`.
    #[inline]
    pub fn insert(&mut self, i: usize) {
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// Removes `i`.
    #[inline]
    pub fn remove(&mut self, i: usize) {
        self.words[i / 64] &= !(1 << (i % 64));
    }

    /// Whether `i` is in the set.
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        self.words[i / 64] & (1 << (i % 64)) != 0
    }

    /// Removes everything.
    pub fn clear(&mut self) {
        self.words.fill(0);
    }

    /// Makes this set a copy of `other` (same size), without allocating.
    pub(crate) fn copy_from(&mut self, other: &BitSet) {
        self.words.copy_from_slice(&other.words);
    }

    /// The smallest member not below `from`. Members added above `from`
    /// while iterating this way are found; members added below are not.
    #[inline]
    pub(crate) fn next_from(&self, from: usize) -> Option<usize> {
        let mut w = from / 64;
        let mut bits = *self.words.get(w)? & (u64::MAX << (from % 64));
        loop {
            if bits != 0 {
                return Some(w * 64 + bits.trailing_zeros() as usize);
            }
            w += 1;
            bits = *self.words.get(w)?;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iterates_in_order_and_sees_later_insertions() {
        let mut s = BitSet::new(200);
        for i in [3, 64, 130, 199] {
            s.insert(i);
        }
        assert_eq!(s.next_from(0), Some(3));
        assert_eq!(s.next_from(4), Some(64));
        s.insert(100);
        assert_eq!(s.next_from(65), Some(100));
        s.remove(130);
        assert_eq!(s.next_from(101), Some(199));
        assert_eq!(s.next_from(200), None);
        assert!(s.contains(64) && !s.contains(65));
        s.clear();
        assert_eq!(s.next_from(0), None);
    }
}
