//! Counting a triangle mesh's edges: `MeshReport` (boundary, non-manifold and misoriented edges,
//! volume) and the closedness test the GLB writer uses.

use super::hash::Edge;
use super::orient::{facet_cross, signed_volume_of};
use crate::mesh::TriMesh;
use rayon::prelude::*;

/// Topology and volume of a triangle mesh, as a repair tool would count them.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshReport {
    /// Edges used by one triangle only (holes, or the rim of an open surface).
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges used twice in the same direction (neighbours wound against each other).
    pub misoriented_edges: usize,
    /// Triangles with two equal corner indices or positions, or zero area.
    pub degenerate_triangles: usize,
    /// `Σ a · (b × c) / 6`: the enclosed volume when the mesh is closed and outward.
    pub signed_volume: f64,
}

impl MeshReport {
    /// Every edge shared by exactly two triangles running along it in opposite directions.
    pub fn is_closed_and_oriented(&self) -> bool {
        self.boundary_edges == 0 && self.nonmanifold_edges == 0 && self.misoriented_edges == 0
    }
}

/// Counts the mesh's boundary, non-manifold and misoriented edges and degenerate triangles, and
/// its signed volume.
pub fn report(mesh: &TriMesh) -> MeshReport {
    let degenerate = mesh
        .triangles
        .par_chunks(1 << 14)
        .map(|ts| {
            ts.iter()
                .filter(|&&t| {
                    let [a, b, c] = t;
                    a == b || b == c || a == c || facet_cross(&mesh.positions, t) == [0.0; 3]
                })
                .count()
        })
        .sum();
    let edges = edge_uses(mesh);
    MeshReport {
        boundary_edges: edges.boundary,
        nonmanifold_edges: edges.nonmanifold,
        misoriented_edges: edges.misoriented,
        degenerate_triangles: degenerate,
        signed_volume: signed_volume_of(&mesh.positions, &mesh.triangles),
    }
}

/// Edges by how they are used.
#[derive(Default)]
struct EdgeUses {
    boundary: usize,
    nonmanifold: usize,
    misoriented: usize,
}

/// Counts every edge's uses in each direction, grouped by its lower vertex (counts per vertex,
/// prefix sums, then each vertex's few upper ends sorted): memory in the order of the vertices,
/// no hashing.
fn edge_uses(mesh: &TriMesh) -> EdgeUses {
    let n = mesh.positions.len();
    let mut start = vec![0usize; n + 2];
    for t in &mesh.triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            start[a.min(b) as usize + 2] += 1;
        }
    }
    for i in 2..start.len() {
        start[i] += start[i - 1];
    }
    // start[v + 1] is where vertex v's entries go next; afterwards start[v]..start[v + 1].
    let mut entries = vec![0u64; 3 * mesh.triangles.len()];
    for t in &mesh.triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let slot = &mut start[a.min(b) as usize + 1];
            // The upper end, and whether the edge runs upward.
            entries[*slot] = (a.max(b) as u64) << 1 | (a < b) as u64;
            *slot += 1;
        }
    }
    // Blocks of vertices in parallel, each sorting its vertices' entries in place.
    const BLOCK: usize = 1 << 12;
    let mut blocks = Vec::with_capacity(n / BLOCK + 1);
    let mut rest = entries.as_mut_slice();
    for v0 in (0..n).step_by(BLOCK) {
        let v1 = (v0 + BLOCK).min(n);
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(start[v1] - start[v0]);
        rest = tail;
        blocks.push((v0, v1, head));
    }
    let start = &start;
    blocks
        .into_par_iter()
        .map(|(v0, v1, block)| {
            let mut acc = EdgeUses::default();
            for v in v0..v1 {
                let seg = &mut block[start[v] - start[v0]..start[v + 1] - start[v0]];
                seg.sort_unstable();
                let mut k = 0;
                while k < seg.len() {
                    let hi = seg[k] >> 1;
                    let (mut up, mut down) = (0, 0);
                    while k < seg.len() && seg[k] >> 1 == hi {
                        if seg[k] & 1 == 1 {
                            up += 1;
                        } else {
                            down += 1;
                        }
                        k += 1;
                    }
                    match up + down {
                        1 => acc.boundary += 1,
                        2 if up != 1 => acc.misoriented += 1,
                        2 => {}
                        _ => acc.nonmanifold += 1,
                    }
                }
            }
            acc
        })
        .reduce(EdgeUses::default, |a, b| EdgeUses {
            boundary: a.boundary + b.boundary,
            nonmanifold: a.nonmanifold + b.nonmanifold,
            misoriented: a.misoriented + b.misoriented,
        })
}

/// True when every edge of the mesh is used by exactly two triangles (what a glTF material's
/// `doubleSided` depends on). A mesh with an edge used an odd number of times is told at once:
/// the exclusive-or of a hash of every edge use is then almost surely not zero (an edge used
/// twice cancels); otherwise the edges are counted. (The GLB writer takes the exclusive-or in
/// its own pass over the triangles and calls [`closed_given`].)
#[cfg(test)]
pub(crate) fn is_closed(mesh: &TriMesh) -> bool {
    let mixed = mesh
        .triangles
        .par_chunks(1 << 14)
        .map(|ts| ts.iter().fold(0u64, |x, &t| x ^ edge_bits(t)))
        .reduce(|| 0, |a, b| a ^ b);
    closed_given(mesh, mixed)
}

/// The exclusive-or of a hash of the triangle's three edges (each undirected): over a mesh,
/// zero when every edge is used an even number of times, and almost surely not zero otherwise.
/// (One multiplication and a fold per edge: it only spares the count of [`closed_given`] for
/// open meshes, so it needs to be cheap, not strong.)
#[inline(always)]
pub fn edge_bits(t: [u32; 3]) -> u64 {
    let h = |a: u32, b: u32| {
        let x = Edge::new(a, b).0.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        x ^ (x >> 29)
    };
    h(t[0], t[1]) ^ h(t[1], t[2]) ^ h(t[2], t[0])
}

/// [`is_closed`] given the exclusive-or of [`edge_bits`] over the mesh's triangles.
pub fn closed_given(mesh: &TriMesh, mixed: u64) -> bool {
    if mixed != 0 {
        return false;
    }
    let e = edge_uses(mesh);
    e.boundary == 0 && e.nonmanifold == 0
}
