//! A reusable bit per id: "is this body being removed / freshly inserted in this commit?".
//!
//! One bit per id keeps the whole set in cache (12.5 KB for 100k ids) for the passes that ask
//! it once per endpoint or per pair; callers clear the bits they set, so no pass over the whole
//! set is needed between uses.

use super::ProxyId;

/// A set of ids as a bit vector that grows on demand.
#[derive(Debug, Default)]
pub struct IdMarks {
    words: Vec<u64>,
}

impl IdMarks {
    /// Marks an id.
    pub fn set(&mut self, id: ProxyId) {
        let word = (id / 64) as usize;
        if word >= self.words.len() {
            self.words.resize(word + 1, 0);
        }
        self.words[word] |= 1 << (id % 64);
    }

    /// Unmarks an id (no-op when it was never marked).
    pub fn clear(&mut self, id: ProxyId) {
        if let Some(word) = self.words.get_mut((id / 64) as usize) {
            *word &= !(1 << (id % 64));
        }
    }

    /// Whether an id is marked.
    #[inline]
    pub fn get(&self, id: ProxyId) -> bool {
        self.words
            .get((id / 64) as usize)
            .is_some_and(|word| word & (1 << (id % 64)) != 0)
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.words.capacity() * size_of::<u64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_get_clear() {
        let mut marks = IdMarks::default();
        assert!(!marks.get(1000));
        marks.set(1000);
        marks.set(3);
        assert!(marks.get(1000) && marks.get(3) && !marks.get(4));
        marks.clear(1000);
        marks.clear(1 << 20);
        assert!(!marks.get(1000) && marks.get(3));
    }
}
