//! Which grids meet along which edges: `GridTopology` reads a grid's triangles from its layout,
//! only the edges between weld candidates going through a map; `join` merges the vertices and finds
//! the grids' relative orientations and the groups they form.

use super::bounds::diagonal;
use super::hash::{edge_map, Edge};
use super::merge::{merge_rows, Merged};
use super::orient::{Group, Parity};
use super::WeldOptions;
use crate::mesh::GridMesh;
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// A grid's triangles as the weld sees them. Vertices that are not weld candidates keep a
/// welded number of their own, so every triangle around one of them belongs to its grid and is
/// known from the grid's layout: only the edges between two "explicit" vertices (the candidates;
/// every vertex of a grid too small for that reasoning) can meet other patches or be used an
/// unusual number of times, and only those go through the edge map.
pub(super) struct GridTopology<'a> {
    pub(super) nu: usize,
    pub(super) nv: usize,
    pub(super) periodic: bool,
    /// Columns of quads.
    pub(super) cols: usize,
    /// The welded vertex of every grid vertex.
    pub(super) map: &'a [u32],
    /// [`candidate_rows`].
    rows: &'a [bool],
    /// Every vertex explicit (a periodic grid of fewer than 3 columns, whose triangles around
    /// a vertex repeat).
    pub(super) all: bool,
}

impl<'a> GridTopology<'a> {
    pub(super) fn new(g: &GridMesh, map: &'a [u32], rows: &'a [bool]) -> Self {
        let cols = if g.periodic_v {
            g.nv
        } else {
            g.nv.saturating_sub(1)
        };
        GridTopology {
            nu: g.nu,
            nv: g.nv,
            periodic: g.periodic_v,
            cols,
            map,
            rows,
            all: g.periodic_v && g.nv < 3,
        }
    }

    /// Whether a row of vertices is explicit as a whole.
    pub(super) fn row_explicit(&self, i: usize) -> bool {
        self.all || self.rows[i]
    }

    /// Whether grid vertex `idx` is explicit: a weld candidate, or any vertex of a tiny grid.
    pub(super) fn explicit(&self, idx: u32) -> bool {
        let (i, j) = (idx as usize / self.nv, idx as usize % self.nv);
        self.row_explicit(i) || (!self.periodic && (j == 0 || j + 1 == self.nv))
    }

    /// The two triangles of quad `(i, j)` in grid numbers, as [`GridMesh::triangles`] gives them.
    pub(super) fn quad(&self, i: usize, j: usize) -> [[u32; 3]; 2] {
        let nv = self.nv;
        let j1 = (j + 1) % nv;
        let (a, b, c, d) = (i * nv + j, (i + 1) * nv + j, (i + 1) * nv + j1, i * nv + j1);
        let [a, b, c, d] = [a, b, c, d].map(|x| x as u32);
        [[a, b, c], [a, c, d]]
    }

    /// A grid triangle in welded numbers, `None` where welding collapsed it.
    pub(super) fn welded(&self, t: [u32; 3]) -> Option<[u32; 3]> {
        let [a, b, c] = t.map(|i| self.map[i as usize]);
        (a != b && b != c && a != c).then_some([a, b, c])
    }

    /// The quads of row `i` with an explicit corner, in order (all of them, when `all_quads`).
    fn quads_to_visit(&self, i: usize, all_quads: bool) -> impl Iterator<Item = usize> {
        let cols = self.cols;
        let whole = all_quads || self.row_explicit(i) || self.row_explicit(i + 1);
        let (first, second): (std::ops::Range<usize>, std::ops::Range<usize>) = if whole {
            (0..cols, 0..0)
        } else if self.periodic || cols == 0 {
            (0..0, 0..0)
        } else if cols == 1 {
            (0..1, 0..0)
        } else {
            (0..1, cols - 1..cols)
        };
        first.chain(second)
    }

    /// Calls `f(grid triangle, welded triangle)` for every triangle that welding kept in the
    /// quads with an explicit corner (in every quad, when `all_quads`), in the grid's order.
    pub(super) fn for_each_visited(&self, all_quads: bool, mut f: impl FnMut([u32; 3], [u32; 3])) {
        for i in 0..self.nu.saturating_sub(1) {
            for j in self.quads_to_visit(i, all_quads) {
                for t in self.quad(i, j) {
                    if let Some(w) = self.welded(t) {
                        f(t, w);
                    }
                }
            }
        }
    }

    /// Number of triangles of quad row `i` that welding keeps.
    fn kept_in_row(&self, i: usize) -> usize {
        let mut dropped = 0;
        for j in self.quads_to_visit(i, false) {
            dropped += self
                .quad(i, j)
                .iter()
                .filter(|&&t| self.welded(t).is_none())
                .count();
        }
        2 * self.cols - dropped
    }

    /// [`GridTopology::kept_in_row`] of every quad row.
    pub(super) fn kept_per_row(&self) -> Vec<usize> {
        (0..self.nu.saturating_sub(1))
            .map(|i| self.kept_in_row(i))
            .collect()
    }

    /// The welded triangles of the grid, without the collapsed ones, in the grid's order.
    pub(super) fn kept(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        (0..self.nu.saturating_sub(1))
            .flat_map(move |i| (0..self.cols).flat_map(move |j| self.quad(i, j)))
            .filter_map(move |t| self.welded(t))
    }

    /// The welded triangles of the grid, without the collapsed ones, in the grid's order (quad
    /// rows in parallel, each written once into its place).
    pub(super) fn triangles(&self) -> Vec<[u32; 3]> {
        let counts = self.kept_per_row();
        let total: usize = counts.iter().sum();
        let mut out: Vec<[u32; 3]> = Vec::with_capacity(total);
        self.triangles_into(&counts, &mut out.spare_capacity_mut()[..total]);
        // SAFETY: `triangles_into` wrote all `total` elements.
        unsafe { out.set_len(total) };
        out
    }

    /// [`GridTopology::triangles`] into `out`, whose length is the sum of `counts` (the kept
    /// triangles of every quad row). Every element is written (checked).
    pub(super) fn triangles_into(&self, counts: &[usize], out: &mut [MaybeUninit<[u32; 3]>]) {
        let mut rest = out;
        let mut parts = Vec::with_capacity(counts.len());
        for (i, &n) in counts.iter().enumerate() {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(n);
            rest = tail;
            parts.push((i, head));
        }
        assert!(rest.is_empty(), "the rows' counts cover the output");
        parts.into_par_iter().with_min_len(8).for_each(|(i, dst)| {
            let mut k = 0;
            for j in 0..self.cols {
                for t in self.quad(i, j) {
                    if let Some(w) = self.welded(t) {
                        dst[k].write(w);
                        k += 1;
                    }
                }
            }
            assert_eq!(k, dst.len(), "the kept triangles of row {i} counted");
        });
    }

    /// The other corners of the triangles (kept by welding) around a vertex `(i, j)` that is not
    /// explicit, two per triangle: an edge from the vertex is used by as many triangles as
    /// its other end appears here. The six triangles of the four quads around `(i, j)`.
    fn around(&self, i: usize, j: usize) -> ([u32; 12], usize) {
        let nv = self.nv;
        let jm = if j == 0 { nv - 1 } else { j - 1 };
        let jp = if j + 1 == nv { 0 } else { j + 1 };
        let v = |a: usize, b: usize| (a * nv + b) as u32;
        let c = v(i, j);
        let tris = [
            [v(i - 1, jm), v(i, jm), c],
            [v(i - 1, jm), c, v(i - 1, j)],
            [v(i - 1, j), c, v(i, jp)],
            [v(i, jm), v(i + 1, j), c],
            [c, v(i + 1, j), v(i + 1, jp)],
            [c, v(i + 1, jp), v(i, jp)],
        ];
        let w = self.map[c as usize];
        let mut others = [0u32; 12];
        let mut n = 0;
        for t in tris {
            if let Some(t) = self.welded(t) {
                for x in t {
                    if x != w {
                        others[n] = x;
                        n += 1;
                    }
                }
            }
        }
        (others, n)
    }

    /// True when the vertex `(i, j)` (not explicit) has an explicit neighbour.
    fn near_explicit(&self, i: usize, j: usize) -> bool {
        self.row_explicit(i - 1)
            || self.row_explicit(i + 1)
            || (!self.periodic && (j == 1 || j + 2 == self.nv))
    }

    /// True when every edge with an end that is not explicit is used by exactly two triangles.
    /// Away from explicit vertices that holds by the grid's layout (six distinct neighbours,
    /// each edge in two kept triangles); next to them it is counted.
    fn inner_edges_twice(&self) -> bool {
        if self.all {
            return true;
        }
        let check = |i: usize, j: usize| {
            let (others, n) = self.around(i, j);
            let others = &others[..n];
            others
                .iter()
                .all(|x| others.iter().filter(|&y| y == x).count() == 2)
        };
        for i in 1..self.nu.saturating_sub(1) {
            if self.rows[i] {
                continue;
            }
            let (lo, hi) = if self.periodic {
                (0, self.nv)
            } else {
                (1, self.nv.saturating_sub(1))
            };
            if self.row_explicit(i - 1) || self.row_explicit(i + 1) {
                if !(lo..hi).all(|j| check(i, j)) {
                    return false;
                }
            } else if !self.periodic {
                for j in [lo, hi.saturating_sub(1)] {
                    if j < hi && self.near_explicit(i, j) && !check(i, j) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// How many kept triangles use the edge from grid vertex `a` to welded vertex `x`, where
    /// `a` is not explicit.
    fn uses_at(&self, a: u32, x: u32) -> u32 {
        let (i, j) = (a as usize / self.nv, a as usize % self.nv);
        let (others, n) = self.around(i, j);
        others[..n].iter().filter(|&&y| y == x).count() as u32
    }
}

/// What welding finds before any triangle is written: the welded vertices, each grid's vertex
/// map and [`candidate_rows`], each grid's orientation relative to its group's root, and the
/// groups whose turn a volume decides.
pub(super) struct Joined {
    pub(super) diag: f64,
    pub(super) positions: Vec<[f32; 3]>,
    pub(super) source: Vec<Vec<u32>>,
    pub(super) rows: Vec<Vec<bool>>,
    /// [`Merged::starts`].
    pub(super) starts: Vec<Vec<usize>>,
    pub(super) relative: Vec<(usize, bool)>,
    pub(super) groups: Vec<Group>,
}

/// Merges the grids' vertices and finds which grids meet along which edges, how they are turned
/// relative to each other, and which groups are closed (with the rims of the open ones).
///
/// The edges are counted from the grids' layout (see [`GridTopology`]): only the edges between
/// weld candidates (the grids' boundaries and collapsed rows: a few rows and columns) go through
/// a map; the result is that of counting every edge in one map.
pub(super) fn join(grids: &[GridMesh], options: WeldOptions) -> Joined {
    let diag = diagonal(grids);
    let Merged {
        positions,
        source,
        rows,
        starts,
    } = merge_rows(grids, options, diag);
    let topo: Vec<GridTopology> = grids
        .iter()
        .zip(&source)
        .zip(&rows)
        .map(|((g, map), rows)| GridTopology::new(g, map, rows))
        .collect();

    // Whether each grid's edges away from the explicit vertices are all used twice.
    let inner_twice: Vec<bool> = topo.par_iter().map(|t| t.inner_edges_twice()).collect();

    // Edges between explicit vertices → (first patch, its direction, uses); patches meeting
    // along an edge agree in orientation when they run along it in opposite directions.
    let mut visited = 0;
    for t in &topo {
        t.for_each_visited(false, |_, _| visited += 1);
    }
    let mut edges = edge_map::<(usize, bool, u32)>(visited);
    for (k, t) in topo.iter().enumerate() {
        t.for_each_visited(false, |g, w| {
            for e in 0..3 {
                if t.explicit(g[e]) && t.explicit(g[(e + 1) % 3]) {
                    let (a, b) = (w[e], w[(e + 1) % 3]);
                    edges.entry(Edge::new(a, b)).or_insert((k, a < b, 0)).2 += 1;
                }
            }
        });
    }
    let mut parity = Parity::new(grids.len());
    for (k, t) in topo.iter().enumerate() {
        t.for_each_visited(false, |g, w| {
            for e in 0..3 {
                if t.explicit(g[e]) && t.explicit(g[(e + 1) % 3]) {
                    let (a, b) = (w[e], w[(e + 1) % 3]);
                    if let Some(&(first, forward, 2)) = edges.get(&Edge::new(a, b)) {
                        if first != k {
                            // Same direction along the shared edge: opposite orientations.
                            parity.join(first, k, forward == (a < b));
                        }
                    }
                }
            }
        });
    }
    // Uses of the edge from grid vertex g[e] to g[e + 1] of a kept triangle of grid k.
    let uses = |k: usize, g: [u32; 3], w: [u32; 3], e: usize| -> u32 {
        let t = &topo[k];
        let (ga, gb) = (g[e], g[(e + 1) % 3]);
        let (a, b) = (w[e], w[(e + 1) % 3]);
        if t.explicit(ga) && t.explicit(gb) {
            edges.get(&Edge::new(a, b)).map_or(0, |e| e.2)
        } else if inner_twice[k] {
            2
        } else if !t.explicit(ga) {
            t.uses_at(ga, b)
        } else {
            t.uses_at(gb, a)
        }
    };

    // Orientation of each patch relative to its group's root; the groups whose own turn
    // a volume decides.
    let relative: Vec<(usize, bool)> = (0..grids.len()).map(|k| parity.find(k)).collect();
    let mut groups: Vec<Group> = Vec::new();
    for &(root, _) in &relative {
        if groups.iter().any(|g| g.root == root) || parity.conflict[root] {
            continue;
        }
        let members: Vec<usize> = (0..grids.len())
            .filter(|&k| relative[k].0 == root)
            .collect();
        let closed = members.iter().all(|&k| {
            let mut twice = inner_twice[k];
            if twice {
                topo[k].for_each_visited(false, |g, w| {
                    twice &= (0..3).all(|e| uses(k, g, w, e) == 2);
                });
            }
            twice
        });
        let mut rim = Vec::new();
        if !closed {
            for &k in &members {
                // Edges used once lie among the explicit vertices unless some inner edge
                // is not used twice; then every triangle is looked at.
                topo[k].for_each_visited(!inner_twice[k], |g, w| {
                    for e in 0..3 {
                        if uses(k, g, w, e) == 1 {
                            rim.push(w[e]);
                        }
                    }
                });
            }
        }
        groups.push(Group {
            root,
            members,
            closed,
            rim,
        });
    }
    Joined {
        diag,
        positions,
        source,
        rows,
        starts,
        relative,
        groups,
    }
}
