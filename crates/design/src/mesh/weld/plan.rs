//! A weld worked out but not built: which vertices join, how every grid is turned, the normals
//! of the weld candidates, and, where the grids' layout gives them, each part's vertices and
//! triangles, read row by row from the grids when they are written. A writer that streams a
//! part at a time (GLB) needs no welded triangle array, no array of normals and no numbering
//! table: about 100 MB fewer fresh pages for two grids of 1024 × 1024.
//!
//! A part's vertices are the welded vertices its triangles use, in increasing welded number:
//! the vertices of earlier grids it shares ([`PlanPart::foreign`]), then every vertex its own
//! grid adds ([`PlanPart::own`]), in the grid's order. The plan stands only where every one of
//! the grid's own vertices is used by one of its triangles (proven from the layout for the
//! vertices that are not weld candidates, checked for the candidates) and every grid's group
//! is consistently oriented; elsewhere [`Plan::parts`] is `None` and the mesh is built.

use super::normals::{avx2, candidate_normals, NormalSource};
use super::{
    bounding_box, box_union, flipped_of, join, part_names, turned, BoundingBox, CellHasher,
    GridTopology, Joined, WeldOptions, EMPTY_BOX,
};
use crate::mesh::GridMesh;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::hash::BuildHasherDefault;
use std::ops::Range;
use std::sync::OnceLock;

/// One grid's part of the welded mesh, as the plan numbers it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanPart {
    /// The grid's name as given to the weld (`patch{k}` for the `k`-th grid without one).
    pub name: String,
    /// The vertices of earlier grids that this part's triangles use, ascending.
    pub foreign: Vec<u32>,
    /// The welded numbers of the vertices this grid adds, all used by its triangles.
    pub own: Range<u32>,
    /// The kept triangles of every quad row.
    pub kept: Vec<usize>,
}

impl PlanPart {
    /// Number of vertices.
    pub fn vertices(&self) -> usize {
        self.foreign.len() + self.own.len()
    }

    /// Number of triangles.
    pub fn triangles(&self) -> usize {
        self.kept.iter().sum()
    }

    /// The part's number of welded vertex `w` (one it uses): its rank among the part's
    /// vertices.
    #[inline(always)]
    pub fn local(&self, w: u32) -> u32 {
        if w >= self.own.start {
            self.foreign.len() as u32 + (w - self.own.start)
        } else {
            self.foreign.partition_point(|&x| x < w) as u32
        }
    }
}

/// The weld of a set of grids without its arrays (see the module documentation).
pub struct Plan<'g> {
    grids: &'g [GridMesh],
    joined: Joined,
    /// Each grid's turn and the normals of the weld candidates, found by [`Plan::prepare`]
    /// (they are not needed for the vertices' positions, which a writer can start with).
    turns: OnceLock<Turns>,
    parts: Option<Vec<PlanPart>>,
    closed: Option<bool>,
    fast: bool,
}

struct Turns {
    flipped: Vec<bool>,
    /// The normals of the weld candidates, by welded number.
    candidates: HashMap<u32, [f32; 3], BuildHasherDefault<CellHasher>>,
}

impl<'g> Plan<'g> {
    /// Plans the weld of `grids` as [`super::weld_mapped`] welds them (same vertices, turns,
    /// normals and triangles), with parts named `names[k]` (or `patch<k>`).
    pub fn new(grids: &'g [GridMesh], names: &[&str], options: WeldOptions) -> Self {
        let joined = join(grids, options);
        // A grid in no group is in one whose patches disagree about their orientation.
        let grouped =
            (0..grids.len()).all(|k| joined.groups.iter().any(|g| g.members.contains(&k)));
        let closed = grouped.then(|| joined.groups.iter().all(|g| g.closed));
        let names = part_names(grids.len(), names);
        let parts: Option<Vec<PlanPart>> = topologies(grids, &joined)
            .par_iter()
            .zip(names)
            .zip(&joined.starts)
            .map(|((t, name), starts)| part_of(t, name, starts))
            .collect();
        Plan {
            grids,
            joined,
            turns: OnceLock::new(),
            parts,
            closed,
            fast: avx2(),
        }
    }

    /// Finds the grids' turns and the candidates' normals, or waits for the thread finding
    /// them. Call it before [`Plan::own_normals`], [`Plan::local_triangles`] and
    /// [`Plan::candidate_normal`], on a thread that is not one of the thread pool's: the pool
    /// is what finds them, so a pool thread waiting here could wait for itself.
    pub fn prepare(&self) {
        self.turns.get_or_init(|| {
            let j = &self.joined;
            let topo = topologies(self.grids, j);
            let turns: Vec<(usize, bool)> = j
                .groups
                .par_iter()
                .map(|g| {
                    let turn = g.turned_over_soon(&topo, &j.positions, &j.relative, j.diag);
                    (g.root, turn)
                })
                .collect();
            let flipped = flipped_of(&j.relative, &turns);
            let candidates = candidate_normals(self.grids, &topo, &j.positions, &flipped);
            Turns {
                flipped,
                candidates,
            }
        });
    }

    /// What [`Plan::prepare`] found (it never waits: it panics when called too early).
    fn turns(&self) -> &Turns {
        self.turns
            .get()
            .expect("Plan::prepare runs before the normals and triangles")
    }

    /// The grids.
    pub fn grids(&self) -> &'g [GridMesh] {
        self.grids
    }

    /// Every grid's part, or `None` where the layout does not give them (see the module
    /// documentation).
    pub fn parts(&self) -> Option<&[PlanPart]> {
        self.parts.as_deref()
    }

    /// Whether the welded mesh is closed (every edge used by two triangles); `None` where a
    /// group of patches could not be oriented consistently.
    pub fn closed(&self) -> Option<bool> {
        self.closed
    }

    /// The position of welded vertex `w`.
    pub fn position(&self, w: u32) -> [f32; 3] {
        self.joined.positions[w as usize]
    }

    /// The normal of welded vertex `w`, a weld candidate (every foreign vertex is one).
    pub fn candidate_normal(&self, w: u32) -> [f32; 3] {
        self.turns().candidates[&w]
    }

    fn topology(&self, k: usize) -> GridTopology<'_> {
        GridTopology::new(&self.grids[k], &self.joined.source[k], &self.joined.rows[k])
    }

    /// The smallest box `(lo, hi)` around grid `k`'s own vertices (its rows in parallel).
    pub fn own_bounds(&self, k: usize) -> BoundingBox {
        (0..self.grids[k].nu)
            .into_par_iter()
            .with_min_len(16)
            .map(|i| {
                let mut b = EMPTY_BOX;
                self.own_positions(k, i..i + 1, |run| b = box_union(b, bounding_box(run)));
                b
            })
            .reduce(|| EMPTY_BOX, box_union)
    }

    /// `f(run)` for runs of grid `k`'s own vertices' positions, in order, in rows `rows`.
    pub fn own_positions(&self, k: usize, rows: Range<usize>, mut f: impl FnMut(&[[f32; 3]])) {
        let g = &self.grids[k];
        let t = self.topology(k);
        for i in rows {
            let row = &g.positions[i * g.nv..(i + 1) * g.nv];
            self.own_runs(&t, k, i, |run| f(&row[run]));
        }
    }

    /// `f(run)` for runs of grid `k`'s own vertices' normals, in order, in rows `rows`: the
    /// welded mesh's normals, bit for bit.
    pub fn own_normals(&self, k: usize, rows: Range<usize>, mut f: impl FnMut(&[[f32; 3]])) {
        let turns = self.turns();
        let t = self.topology(k);
        let g = &self.grids[k];
        let nv = g.nv;
        let map = &self.joined.source[k];
        // Row `i`'s own vertices, `inner` holding the computed normals of a row that is not
        // explicit (whose runs are its inner columns, or one end column).
        let mut emit = |i: usize, inner: Option<&[[f32; 3]]>| {
            let (lo, hi) = t.inner_columns();
            self.own_runs(&t, k, i, |run| match inner {
                Some(row) if run.start >= lo && run.end <= hi => f(&row[run]),
                _ => {
                    for j in run {
                        f(&[turns.candidates[&map[i * nv + j]]]);
                    }
                }
            });
        };
        let mut next = rows.start;
        let inner = rows.start.max(1)..rows.end.min(g.nu.saturating_sub(1));
        if !inner.is_empty() {
            let src = NormalSource {
                grid: g,
                positions: &self.joined.positions,
                flip: turns.flipped[k],
                fast: self.fast,
            };
            t.inner_normals(src, inner, |i, row| {
                for r in next..i {
                    emit(r, None);
                }
                emit(i, Some(row));
                next = i + 1;
            });
        }
        for r in next..rows.end {
            emit(r, None);
        }
    }

    /// `f(triangle)` in the part's own numbers ([`PlanPart::local`]), turned with the grid,
    /// for grid `k`'s kept triangles of quad rows `rows`, in order. Between two rows that are
    /// not explicit no triangle collapses away from the end columns, and each row's numbers
    /// are looked up once.
    pub fn local_triangles(&self, k: usize, rows: Range<usize>, mut f: impl FnMut([u32; 3])) {
        let t = self.topology(k);
        let flip = self.turns().flipped[k];
        let part = &self.parts.as_ref().expect("parts planned")[k];
        let nv = t.nv;
        let locals = |i: usize, out: &mut Vec<u32>| {
            out.clear();
            out.extend(t.map[i * nv..(i + 1) * nv].iter().map(|&w| part.local(w)));
        };
        let generic = |i: usize, j: usize, f: &mut dyn FnMut([u32; 3])| {
            for tri in t.quad(i, j) {
                if let Some(w) = t.welded(tri) {
                    f(turned(w.map(|w| part.local(w)), flip));
                }
            }
        };
        let (mut top, mut bottom) = (Vec::new(), Vec::new());
        let mut have = usize::MAX;
        for i in rows {
            if t.row_explicit(i) || t.row_explicit(i + 1) {
                for j in 0..t.cols {
                    generic(i, j, &mut f);
                }
                continue;
            }
            if have == i {
                std::mem::swap(&mut top, &mut bottom);
            } else {
                locals(i, &mut top);
            }
            locals(i + 1, &mut bottom);
            have = i + 1;
            // Quads with every corner its own grid's, by the layout: the inner columns'.
            let (lo, hi) = if t.periodic {
                (0, nv - 1)
            } else {
                (1, t.cols - 1)
            };
            for j in 0..lo {
                generic(i, j, &mut f);
            }
            for j in lo..hi {
                let (a, b, c, d) = (top[j], bottom[j], bottom[j + 1], top[j + 1]);
                if flip {
                    f([a, c, b]);
                    f([a, d, c]);
                } else {
                    f([a, b, c]);
                    f([a, c, d]);
                }
            }
            for j in hi..t.cols {
                generic(i, j, &mut f);
            }
        }
    }

    /// `f(columns)` for the runs of row `i` of grid `k` whose vertices are the grid's own
    /// (first met there), in order. A row that is not explicit has one run of inner columns
    /// (every one new) and, in a non-periodic grid, each end column that is new.
    fn own_runs(&self, t: &GridTopology, k: usize, i: usize, mut f: impl FnMut(Range<usize>)) {
        let nv = t.nv;
        let row = &t.map[i * nv..(i + 1) * nv];
        let mut expect = self.joined.starts[k][i];
        if !t.row_explicit(i) && nv > 2 {
            if t.periodic {
                return f(0..nv);
            }
            if row[0] as usize == expect {
                f(0..1);
                expect += 1;
            }
            f(1..nv - 1);
            expect += nv - 2;
            if row[nv - 1] as usize == expect {
                f(nv - 1..nv);
            }
            return;
        }
        let mut j = 0;
        while j < nv {
            let start = j;
            while j < nv && row[j] as usize == expect {
                expect += 1;
                j += 1;
            }
            if j > start {
                f(start..j);
            } else {
                j += 1;
            }
        }
    }
}

fn topologies<'a>(grids: &[GridMesh], joined: &'a Joined) -> Vec<GridTopology<'a>> {
    grids
        .iter()
        .zip(&joined.source)
        .zip(&joined.rows)
        .map(|((g, map), rows)| GridTopology::new(g, map, rows))
        .collect()
}

/// A grid's part, when every vertex it adds is used by one of its triangles: proven for the
/// vertices that are not weld candidates (each has a triangle with a neighbour in its own row
/// that is not one either, which welding cannot collapse: a periodic grid of at least three
/// columns, or a non-periodic one of at least four), checked for the candidates.
fn part_of(t: &GridTopology, name: String, starts: &[usize]) -> Option<PlanPart> {
    if t.all || (!t.periodic && t.nv < 4) || t.nu < 2 {
        return None;
    }
    let own = starts[0] as u32..starts[t.nu] as u32;
    let kept = t.kept_per_row();
    if kept.iter().all(|&n| n == 0) {
        return None;
    }
    let mut foreign = HashSet::new();
    let mut used = HashSet::new();
    t.for_each_visited(false, |g, w| {
        for e in 0..3 {
            if t.explicit(g[e]) {
                if w[e] < own.start {
                    foreign.insert(w[e]);
                } else {
                    used.insert(w[e]);
                }
            }
        }
    });
    for i in 0..t.nu {
        let row = &t.map[i * t.nv..(i + 1) * t.nv];
        let ends = [row[0], row[t.nv - 1]];
        let explicit: &[u32] = if t.row_explicit(i) {
            row
        } else if t.periodic {
            &[]
        } else {
            &ends
        };
        if explicit
            .iter()
            .any(|&w| w >= own.start && !used.contains(&w))
        {
            return None;
        }
    }
    let mut foreign: Vec<u32> = foreign.into_iter().collect();
    foreign.sort_unstable();
    Some(PlanPart {
        name,
        foreign,
        own,
        kept,
    })
}
