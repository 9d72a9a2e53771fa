//! The hashing of the weld's maps: `CellHasher` for the merge's grid cells and the edge maps,
//! `Edge`, an undirected edge as one key.

use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// A fast hasher for the merge's grid-cell keys (multiply–rotate over 8-byte words, as in
/// rustc's FxHash): the keys are cells of the mesh's own vertices, so SipHash's protection
/// against chosen keys buys nothing, and it was a tenth of an animation frame's time.
#[derive(Default, Clone, Copy)]
pub(super) struct CellHasher(u64);

impl CellHasher {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl std::hash::Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            self.add(u64::from_le_bytes(w.try_into().expect("8 bytes")));
        }
        for &b in words.remainder() {
            self.add(b as u64);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }
    fn write_i64(&mut self, x: i64) {
        self.add(x as u64);
    }
    fn write_usize(&mut self, x: usize) {
        self.add(x as u64);
    }
}

/// An undirected edge `(min, max)` of a mesh, as a map key. Its hash is a full 64-bit mix
/// (splitmix64's finaliser) of the two indices, so the table's low bits depend on both ends.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) struct Edge(pub(super) u64);

impl Edge {
    pub(super) fn new(a: u32, b: u32) -> Self {
        Edge(((a.min(b) as u64) << 32) | a.max(b) as u64)
    }
}

impl std::hash::Hash for Edge {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        state.write_u64(mix(self.0));
    }
}

/// splitmix64's finaliser: a bijection of 64-bit words whose every output bit depends on every
/// input bit.
fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A map over a mesh's edges, sized for `triangles` triangles (about 3/2 edges each).
pub(super) fn edge_map<V>(triangles: usize) -> HashMap<Edge, V, BuildHasherDefault<CellHasher>> {
    HashMap::with_capacity_and_hasher(triangles * 3 / 2 + 64, Default::default())
}
