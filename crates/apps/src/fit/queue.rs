//! A priority queue of at most one entry per key (keys `0..n`, such as a mesh's vertices), whose
//! entry a key replaces or removes in place: the decimation's candidate collapses, one per
//! vertex, each replaced when a collapse nearby changes that vertex's best.
//!
//! A plain binary heap with lazy deletion (push the new entry, skip the stale ones when they
//! come out) holds every entry ever pushed: a decimation of a million triangles pushes about
//! twelve per collapse and pops each again, millions of sift-downs through a heap of millions.
//! Here the heap holds one entry per key, each key knows its entry's place, and a replacement
//! sifts that entry up or down from where it is. The order in which entries come out is that
//! of their `Ord` alone (greatest first, like [`std::collections::BinaryHeap`]), so for items
//! whose order is total across keys it is the order lazy deletion gives.

/// The place of a key with no entry.
const ABSENT: u32 = u32::MAX;

/// A binary max-heap of `(key, item)` with at most one entry per key.
pub(crate) struct KeyedHeap<T> {
    heap: Vec<(u32, T)>,
    /// `at[key]`: the entry's index in `heap`, or [`ABSENT`].
    at: Vec<u32>,
}

impl<T: Ord> KeyedHeap<T> {
    /// The heap of `entries` over the keys `0..keys` (a key given twice keeps its last item).
    ///
    /// # Panics
    /// When a key is not below `keys`, or `keys` does not fit a `u32`.
    pub(crate) fn new(keys: usize, entries: impl IntoIterator<Item = (u32, T)>) -> Self {
        assert!(keys < ABSENT as usize, "{keys} keys");
        let mut h = KeyedHeap {
            heap: Vec::new(),
            at: vec![ABSENT; keys],
        };
        for (key, item) in entries {
            match h.at[key as usize] {
                ABSENT => {
                    h.at[key as usize] = h.heap.len() as u32;
                    h.heap.push((key, item));
                }
                i => h.heap[i as usize].1 = item,
            }
        }
        for i in (0..h.heap.len() / 2).rev() {
            h.down(i);
        }
        h
    }

    /// Whether no key has an entry.
    #[cfg(test)]
    pub(crate) fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// Keys with an entry.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.heap.len()
    }

    /// The greatest entry, taken out.
    pub(crate) fn pop(&mut self) -> Option<(u32, T)> {
        if self.heap.is_empty() {
            return None;
        }
        let last = self.heap.len() - 1;
        self.swap(0, last);
        let (key, item) = self.heap.pop().expect("not empty");
        self.at[key as usize] = ABSENT;
        if !self.heap.is_empty() {
            self.down(0);
        }
        Some((key, item))
    }

    /// Gives `key` the entry `item`, replacing the one it had; `None` removes it.
    pub(crate) fn set(&mut self, key: u32, item: Option<T>) {
        let at = self.at[key as usize];
        match (at, item) {
            (ABSENT, None) => {}
            (ABSENT, Some(item)) => {
                let i = self.heap.len();
                self.at[key as usize] = i as u32;
                self.heap.push((key, item));
                self.up(i);
            }
            (i, Some(item)) => {
                let i = i as usize;
                let rises = item > self.heap[i].1;
                self.heap[i].1 = item;
                if rises {
                    self.up(i);
                } else {
                    self.down(i);
                }
            }
            (i, None) => {
                let (i, last) = (i as usize, self.heap.len() - 1);
                self.swap(i, last);
                self.heap.pop();
                self.at[key as usize] = ABSENT;
                if i < self.heap.len() {
                    // The entry moved into the hole may belong above or below it.
                    self.up(i);
                    self.down(i);
                }
            }
        }
    }

    fn swap(&mut self, i: usize, j: usize) {
        self.heap.swap(i, j);
        self.at[self.heap[i].0 as usize] = i as u32;
        self.at[self.heap[j].0 as usize] = j as u32;
    }

    fn up(&mut self, mut i: usize) {
        while i > 0 {
            let parent = (i - 1) / 2;
            if self.heap[i].1 <= self.heap[parent].1 {
                break;
            }
            self.swap(i, parent);
            i = parent;
        }
    }

    fn down(&mut self, mut i: usize) {
        let n = self.heap.len();
        loop {
            let (l, r) = (2 * i + 1, 2 * i + 2);
            let mut top = i;
            if l < n && self.heap[l].1 > self.heap[top].1 {
                top = l;
            }
            if r < n && self.heap[r].1 > self.heap[top].1 {
                top = r;
            }
            if top == i {
                break;
            }
            self.swap(i, top);
            i = top;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BinaryHeap;

    /// A small deterministic generator (the tests need no statistics, only many orders).
    fn lcg(state: &mut u64) -> u64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *state >> 33
    }

    /// Against a binary heap with lazy deletion (each key's newest item valid, the rest
    /// skipped): the same entries out in the same order through random replacements,
    /// removals and pops.
    #[test]
    fn pops_what_lazy_deletion_pops() {
        let keys = 300u32;
        let mut s = 7u64;
        // Items ordered by (value, key): total across keys, as the decimation's candidates.
        let mut start: Vec<(u32, (u64, u32))> = Vec::new();
        for k in 0..keys {
            if !lcg(&mut s).is_multiple_of(4) {
                start.push((k, (lcg(&mut s) % 50, k)));
            }
        }
        let mut ours = KeyedHeap::new(keys as usize, start.clone());
        let mut version = vec![0u32; keys as usize];
        let mut lazy: BinaryHeap<((u64, u32), u32)> =
            start.iter().map(|&(_, item)| (item, 0)).collect();
        let mut live = vec![false; keys as usize];
        for &(k, _) in &start {
            live[k as usize] = true;
        }
        let mut popped = 0;
        for _ in 0..20_000 {
            match lcg(&mut s) % 3 {
                0 => {
                    let mine = ours.pop();
                    let theirs = loop {
                        match lazy.pop() {
                            None => break None,
                            Some((item, v)) if v == version[item.1 as usize] => {
                                break Some((item.1, item))
                            }
                            Some(_) => {}
                        }
                    };
                    assert_eq!(mine, theirs);
                    if let Some((k, _)) = mine {
                        live[k as usize] = false;
                        version[k as usize] += 1;
                        popped += 1;
                    }
                }
                _ => {
                    let k = (lcg(&mut s) % keys as u64) as u32;
                    version[k as usize] += 1;
                    let item = (!lcg(&mut s).is_multiple_of(8)).then(|| (lcg(&mut s) % 50, k));
                    if let Some(item) = item {
                        lazy.push((item, version[k as usize]));
                    }
                    live[k as usize] = item.is_some();
                    ours.set(k, item);
                }
            }
            assert_eq!(ours.len(), live.iter().filter(|&&l| l).count());
        }
        assert!(popped > 1000, "{popped}");
        // Drained in order.
        let mut last = None;
        while let Some((k, item)) = ours.pop() {
            assert_eq!(k, item.1);
            assert!(last.is_none_or(|l| item <= l));
            last = Some(item);
        }
        assert!(ours.is_empty());
    }

    #[test]
    fn a_key_given_twice_keeps_its_last_item() {
        let mut h = KeyedHeap::new(3, [(0, 5), (1, 9), (0, 1)]);
        assert_eq!(h.pop(), Some((1, 9)));
        assert_eq!(h.pop(), Some((0, 1)));
        assert_eq!(h.pop(), None);
        h.set(2, None);
        h.set(2, Some(4));
        h.set(2, Some(3));
        assert_eq!(h.pop(), Some((2, 3)));
        assert!(h.is_empty());
    }
}
