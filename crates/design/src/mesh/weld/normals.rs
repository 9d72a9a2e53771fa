//! The vertex normals of a welded mesh: the normalised mean of the welded copies' normals, each
//! turned with its patch; where that vanishes or points against the triangles around the vertex
//! (a crease turned back on itself; the limit normal at a pole closing a patch at its end u,
//! whose sign is that of the other end's), the mean of the facet normals around the vertex.
//!
//! Sums are taken in the order of the grids' vertices (copies) and of the mesh's triangles
//! (facets), as one pass over each would (the frame weld's definition, `weld_frame.rs`).
//! Vertices that are not weld candidates have one copy and six triangles of their own grid,
//! known from its layout: they are done row by row in parallel, each quad row's facets computed
//! once per block of rows into columns of `f64` (away from the candidates straight from the
//! grid's positions, which are the welded ones there), then the six facets of every vertex
//! summed in the mesh's order. The candidates (a few rows and columns) are summed in maps.

use super::{candidate_rows, facet_cross, turned, CellHasher, GridTopology, SharedSlice};
use crate::mesh::GridMesh;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// `s / |s|` in f32, or zero where `|s| ≤ 10⁻³` (the copies' normals cancel).
#[inline(always)]
pub(super) fn unit(s: [f64; 3]) -> [f32; 3] {
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    if len > 1e-3 {
        s.map(|c| (c / len) as f32)
    } else {
        [0.0; 3]
    }
}

/// The normalised facet sum `a`, if it has a length; `None` for a zero sum.
#[inline(always)]
pub(super) fn facet_mean(a: [f64; 3]) -> Option<[f32; 3]> {
    let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    (len > 0.0).then(|| a.map(|c| (c / len) as f32))
}

/// `n`, unless it points against the facet sum `a` (or is zero): then `a` normalised.
#[inline(always)]
pub(super) fn settle(n: [f32; 3], a: [f64; 3]) -> [f32; 3] {
    let dot: f64 = (0..3).map(|c| n[c] as f64 * a[c]).sum();
    if dot <= 0.0 {
        facet_mean(a).unwrap_or(n)
    } else {
        n
    }
}

#[inline(always)]
fn add(s: &mut [f64; 3], x: [f64; 3]) {
    for c in 0..3 {
        s[c] += x[c];
    }
}

/// Rows of quads per parallel task.
const BLOCK: usize = 16;

/// The facets of the two triangles of every quad of a row, by column: `f[0..3]` (x, y, z) of
/// the first triangle, `f[3..6]` of the second; zero where welding collapsed the triangle
/// (adding a zero to a sum that starts at `+0` and never becomes `−0` changes nothing, so that
/// is the sum without it).
#[derive(Default)]
struct Facets {
    f: [Vec<f64>; 6],
}

/// Two rows of grid positions as `f64` columns, with the first column repeated at the end.
#[derive(Default)]
struct RowPair {
    c: [Vec<f64>; 6],
}

/// `(b − a) × (c − a)`, as [`facet_cross`] computes it.
#[inline(always)]
fn cross(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
}

/// Facets of quads `lo..hi` of a row from its two vertex rows `p` (grid positions), the
/// triangles `[a, b, c]`, `[a, c, d]` of quad `(a, b, c, d)` turned when `FLIP`.
#[inline(always)]
fn grid_facets<const FLIP: bool>(p: &RowPair, lo: usize, hi: usize, out: &mut Facets) {
    let [x0, y0, z0, x1, y1, z1] = &p.c;
    let [f0, f1, f2, f3, f4, f5] = &mut out.f;
    for j in lo..hi {
        let a = [x0[j], y0[j], z0[j]];
        let b = [x1[j], y1[j], z1[j]];
        let c = [x1[j + 1], y1[j + 1], z1[j + 1]];
        let d = [x0[j + 1], y0[j + 1], z0[j + 1]];
        let (t0, t1) = if FLIP {
            (cross(a, c, b), cross(a, d, c))
        } else {
            (cross(a, b, c), cross(a, c, d))
        };
        (f0[j], f1[j], f2[j]) = (t0[0], t0[1], t0[2]);
        (f3[j], f4[j], f5[j]) = (t1[0], t1[1], t1[2]);
    }
}

/// One row's vertex normals as [`row_normals`] leaves them, by column.
#[derive(Default)]
struct RowNormals {
    /// The unit normal `s·n / |s·n|` of the vertex's copy.
    units: Vec<[f32; 3]>,
    /// The sum of the six facets around the vertex, in the mesh's order.
    sums: Vec<[f64; 3]>,
    /// The dot product of the unit normal with the facet sum.
    dots: Vec<f64>,
}

impl RowNormals {
    fn new(nv: usize) -> RowNormals {
        RowNormals {
            units: vec![[0.0; 3]; nv],
            sums: vec![[0.0; 3]; nv],
            dots: vec![0.0; nv],
        }
    }
}

/// The unit normals `s·n / |s·n|` of a row's vertices in `columns` and their dot products with
/// the facet sums `a` (six facets each, summed in the mesh's order from quad rows `prev`,
/// `cur`), into `out`. Column 0 of a periodic row (whose quads come in another order) is left to
/// the caller.
#[inline(always)]
fn row_normals(
    normals: &[[f32; 3]],
    s: f64,
    [prev, cur]: [&Facets; 2],
    columns: std::ops::Range<usize>,
    out: &mut RowNormals,
) {
    let (p, c) = (&prev.f, &cur.f);
    for j in columns.start.max(1)..columns.end {
        let jm = j - 1;
        let mut a = [0.0f64; 3];
        for (q, acc) in a.iter_mut().enumerate() {
            // Quad row i − 1, then i, quads by column, each quad's first triangle first.
            *acc += p[q][jm];
            *acc += p[3 + q][jm];
            *acc += p[q][j];
            *acc += c[3 + q][jm];
            *acc += c[q][j];
            *acc += c[3 + q][j];
        }
        let n = normals[j];
        let mut m = [0.0f64; 3];
        add(&mut m, [s * n[0] as f64, s * n[1] as f64, s * n[2] as f64]);
        let u = unit(m);
        out.units[j] = u;
        out.sums[j] = a;
        // Only its sign is used: whether it is ≤ 0 does not depend on the order of the terms'
        // sum beyond the sign of a zero.
        out.dots[j] = u[0] as f64 * a[0] + u[1] as f64 * a[1] + u[2] as f64 * a[2];
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn grid_facets_avx2<const FLIP: bool>(p: &RowPair, lo: usize, hi: usize, out: &mut Facets) {
    grid_facets::<FLIP>(p, lo, hi, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn row_normals_avx2(
    normals: &[[f32; 3]],
    s: f64,
    facets: [&Facets; 2],
    columns: std::ops::Range<usize>,
    out: &mut RowNormals,
) {
    row_normals(normals, s, facets, columns, out)
}

/// Whether the processor has AVX2 (the kernels above are compiled for it where it does; the
/// arithmetic is the same, without fused operations).
pub(super) fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// What the vertex normals of one grid are computed from: the grid, the welded positions,
/// whether the grid's patch is turned, and whether to run the AVX2 kernels ([`avx2`]).
#[derive(Clone, Copy)]
pub(super) struct NormalSource<'a> {
    /// The grid.
    pub(super) grid: &'a GridMesh,
    /// The welded positions.
    pub(super) positions: &'a [[f32; 3]],
    /// Whether the grid's patch is turned over.
    pub(super) flip: bool,
    /// Whether the processor has AVX2.
    pub(super) fast: bool,
}

impl GridTopology<'_> {
    /// The facets of quad row `r` into `out`: from the grid's positions where neither vertex
    /// row is explicit (the welded positions there, no triangle collapsed), else from the
    /// welded triangles.
    fn facet_row(&self, src: NormalSource, r: usize, pair: &mut RowPair, out: &mut Facets) {
        let NormalSource {
            grid: g,
            positions,
            flip,
            fast,
        } = src;
        let (nv, cols) = (self.nv, self.cols);
        for f in &mut out.f {
            f.resize(cols, 0.0);
        }
        let generic = |j: usize, out: &mut Facets| {
            for (t, tri) in self.quad(r, j).into_iter().enumerate() {
                let f = self
                    .welded(tri)
                    .map_or([0.0; 3], |w| facet_cross(positions, turned(w, flip)));
                for (q, x) in f.into_iter().enumerate() {
                    out.f[3 * t + q][j] = x;
                }
            }
        };
        if self.row_explicit(r) || self.row_explicit(r + 1) {
            (0..cols).for_each(|j| generic(j, out));
            return;
        }
        for (h, cs) in pair.c.chunks_exact_mut(3).enumerate() {
            let row = &g.positions[(r + h) * nv..(r + h + 1) * nv];
            let [x, y, z] = cs else { unreachable!() };
            for c in [&mut *x, &mut *y, &mut *z] {
                c.resize(nv + 1, 0.0);
            }
            for (j, p) in row.iter().chain(&row[..1]).enumerate() {
                (x[j], y[j], z[j]) = (p[0] as f64, p[1] as f64, p[2] as f64);
            }
        }
        // A non-periodic grid's end columns are weld candidates.
        let (lo, hi) = if self.periodic {
            (0, cols)
        } else {
            (1.min(cols), cols.saturating_sub(1).max(1.min(cols)))
        };
        match (fast, flip) {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `fast` only where the processor has AVX2.
            (true, false) => unsafe { grid_facets_avx2::<false>(pair, lo, hi, out) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            (true, true) => unsafe { grid_facets_avx2::<true>(pair, lo, hi, out) },
            (_, false) => grid_facets::<false>(pair, lo, hi, out),
            (_, true) => grid_facets::<true>(pair, lo, hi, out),
        }
        if !self.periodic && cols > 0 {
            generic(0, out);
            if cols > 1 {
                generic(cols - 1, out);
            }
        }
    }
}

/// The normals of the welded mesh (see the module documentation): `source[k]` is grid `k`'s
/// vertex map, `flipped[k]` its turn, `positions` the welded vertices.
pub(super) fn vertex_normals(
    grids: &[GridMesh],
    source: &[Vec<u32>],
    positions: &[[f32; 3]],
    flipped: &[bool],
) -> Vec<[f32; 3]> {
    let rows: Vec<Vec<bool>> = grids.par_iter().map(candidate_rows).collect();
    let topo: Vec<GridTopology> = grids
        .iter()
        .zip(source)
        .zip(&rows)
        .map(|((g, map), rows)| GridTopology::new(g, map, rows))
        .collect();
    // Zeroed memory from the system, not touched yet: advised before its first write.
    let mut normals = vec![[0.0f32; 3]; positions.len()];
    super::super::advise_huge_pages(&mut normals);
    for (w, n) in candidate_normals(grids, &topo, positions, flipped) {
        normals[w as usize] = n;
    }

    // The other vertices, blocks of rows in parallel. Each writes the normals of its own
    // vertices (welded numbers no other grid vertex has).
    let out = SharedSlice(normals.as_mut_ptr(), normals.len());
    let out = &out;
    let blocks: Vec<(usize, usize)> = topo
        .iter()
        .enumerate()
        .filter(|(_, t)| !t.all)
        .flat_map(|(k, t)| {
            (1..t.nu.saturating_sub(1))
                .step_by(BLOCK)
                .map(move |i| (k, i))
        })
        .collect();
    let fast = avx2();
    blocks.into_par_iter().for_each(|(k, r0)| {
        let t = &topo[k];
        let r1 = (r0 + BLOCK).min(t.nu - 1);
        let src = NormalSource {
            grid: &grids[k],
            positions,
            flip: flipped[k],
            fast,
        };
        t.inner_normals(src, r0..r1, |i, row| {
            let (lo, hi) = t.inner_columns();
            for (j, &n) in row.iter().enumerate().take(hi).skip(lo) {
                // SAFETY: the vertex is not a weld candidate, so its welded number belongs
                // to it alone: no other task writes this element.
                unsafe { out.write(t.map[i * t.nv + j] as usize, n) };
            }
        });
    });
    normals
}

/// The normals of the weld candidates (see the module documentation), by welded number: the
/// mean of their copies in every grid, settled against the facets around them.
pub(super) fn candidate_normals(
    grids: &[GridMesh],
    topo: &[GridTopology],
    positions: &[[f32; 3]],
    flipped: &[bool],
) -> HashMap<u32, [f32; 3], BuildHasherDefault<CellHasher>> {
    // Candidates: their copies and their triangles, in order.
    let mut sums: HashMap<u32, [f64; 3], BuildHasherDefault<CellHasher>> = HashMap::default();
    let mut facets: HashMap<u32, [f64; 3], BuildHasherDefault<CellHasher>> = HashMap::default();
    for (k, (g, t)) in grids.iter().zip(topo).enumerate() {
        let s = if flipped[k] { -1.0 } else { 1.0 };
        for i in 0..g.nu {
            let cols: Vec<usize> = if t.row_explicit(i) {
                (0..g.nv).collect()
            } else if !g.periodic_v && g.nv > 0 {
                if g.nv > 1 {
                    vec![0, g.nv - 1]
                } else {
                    vec![0]
                }
            } else {
                Vec::new()
            };
            for j in cols {
                let idx = i * g.nv + j;
                let n = g.normals[idx];
                add(
                    sums.entry(t.map[idx]).or_insert([0.0; 3]),
                    [s * n[0] as f64, s * n[1] as f64, s * n[2] as f64],
                );
            }
        }
        t.for_each_visited(false, |gt, wt| {
            let f = facet_cross(positions, turned(wt, flipped[k]));
            for e in 0..3 {
                if t.explicit(gt[e]) {
                    add(facets.entry(wt[e]).or_insert([0.0; 3]), f);
                }
            }
        });
    }
    sums.into_iter()
        .map(|(w, s)| {
            let a = facets.get(&w).copied().unwrap_or([0.0; 3]);
            (w, settle(unit(s), a))
        })
        .collect()
}

impl GridTopology<'_> {
    /// The columns `lo..hi` of a row that are not weld candidates in themselves (the end
    /// columns of a non-periodic grid are).
    pub(super) fn inner_columns(&self) -> (usize, usize) {
        if self.periodic {
            (0, self.nv)
        } else {
            (1, self.nv.saturating_sub(1))
        }
    }

    /// The normals of the vertices that are not weld candidates in rows `rows` (within
    /// `1..nu − 1`; the grid not [`GridTopology::all`]): `f(i, row)` for every row `i` that is
    /// not explicit, in order, with the normals at the row's [`GridTopology::inner_columns`]
    /// (the other entries are meaningless). Facets are computed once per quad row, from the
    /// row before the first.
    pub(super) fn inner_normals(
        &self,
        src: NormalSource,
        rows: std::ops::Range<usize>,
        mut f: impl FnMut(usize, &[[f32; 3]]),
    ) {
        let (r0, r1) = (rows.start, rows.end);
        debug_assert!(r0 >= 1 && r1 < self.nu.max(1) && !self.all);
        if r0 >= r1 {
            return;
        }
        let g = src.grid;
        let s = if src.flip { -1.0 } else { 1.0 };
        let nv = self.nv;
        let mut pair = RowPair::default();
        let (mut prev, mut cur) = (Facets::default(), Facets::default());
        let mut out = RowNormals::new(nv);
        let mut row = vec![[0.0f32; 3]; nv];
        self.facet_row(src, r0 - 1, &mut pair, &mut prev);
        let (lo, hi) = self.inner_columns();
        for i in r0..r1 {
            self.facet_row(src, i, &mut pair, &mut cur);
            if !self.row_explicit(i) {
                let row_normals_of = &g.normals[i * nv..(i + 1) * nv];
                let facets = [&prev, &cur];
                if src.fast {
                    // SAFETY: only where the processor has AVX2.
                    #[cfg(target_arch = "x86_64")]
                    unsafe {
                        row_normals_avx2(row_normals_of, s, facets, lo..hi, &mut out)
                    };
                } else {
                    row_normals(row_normals_of, s, facets, lo..hi, &mut out);
                }
                let RowNormals { units, sums, dots } = &out;
                for j in lo..hi {
                    row[j] = if j == 0 {
                        // Column 0 of a periodic row: quads by column put column 0 first.
                        let jm = nv - 1;
                        let (p, c) = (&prev.f, &cur.f);
                        let mut a = [0.0f64; 3];
                        for (q, acc) in a.iter_mut().enumerate() {
                            *acc += p[q][0];
                            *acc += p[q][jm];
                            *acc += p[3 + q][jm];
                            *acc += c[q][0];
                            *acc += c[3 + q][0];
                            *acc += c[3 + q][jm];
                        }
                        let n = g.normals[i * nv];
                        let mut m = [0.0f64; 3];
                        add(&mut m, [s * n[0] as f64, s * n[1] as f64, s * n[2] as f64]);
                        settle(unit(m), a)
                    } else if dots[j] <= 0.0 {
                        facet_mean(sums[j]).unwrap_or(units[j])
                    } else {
                        units[j]
                    };
                }
                f(i, &row);
            }
            std::mem::swap(&mut prev, &mut cur);
        }
    }
}
