//! The orientation and normal pass of [`super::FrameWeld`] over the grids' layout: the same
//! numbers as [`WeldTopology::finish_into`], bit for bit, from one streaming pass per grid.
//!
//! * **Normals.** A grid vertex that is the only copy of its welded vertex and has a neighbour on
//!   every side (rows `1..nu−1`; every column of a periodic grid of at least three columns, the
//!   inner columns otherwise) is in exactly the six triangles of the four quads around it,
//!   all of its own grid (some collapsed by welding: they are left out). Its normal is computed
//!   from its copy and those six facets, summed in the mesh's order, row by row with the facets
//!   of two quad rows at hand. Every other welded vertex (the weld candidates: end rows and
//!   columns, collapsed rows, every vertex of a tiny grid) is done one by one from lists of its
//!   copies and triangles made once per topology.
//! * **Orientation.** The facets depend on the turn of their grid, which depends on the group
//!   volumes of this very frame. The pass takes the turns of the last frame and sums the group
//!   volumes on the way, from the same per-triangle terms as
//!   [`WeldTopology::turns_over`] but in another order; their sum is then within a rounding bound
//!   of the reference order's, and where the decision (the sign, or the comparison with the open
//!   group's threshold) is farther from the boundary than that bound it is the reference's.
//!   Otherwise the group is decided by `turns_over` itself; when a group turns, or any number is
//!   not finite, the caller redoes the frame by the reference pass.
//!
//! Sums of f64 here start from `+0.0` as the reference's do. A sum that starts from `+0.0` is
//! never `−0.0` (round to nearest: `x + y` is `−0.0` only when both are), so adding `+0.0` for a
//! triangle that welding collapsed is the same as leaving it out.

use super::super::normals::{facet_mean, settle, unit};
use super::super::{facet_cross, WeldTopology, OPEN_VOLUME_FRACTION};
use crate::mesh::{GridMesh, TriMesh};

/// What the pass knows of one grid.
#[derive(Clone, Debug, Default)]
struct GridPlan {
    nu: usize,
    nv: usize,
    periodic: bool,
    /// Columns of quads.
    cols: usize,
    /// Columns of the vertices the row pass does: `lo..hi` (empty when it does none).
    lo: usize,
    hi: usize,
    /// Per quad row: the index in `kept` of its kept triangles, when welding collapsed one.
    collapsed: Vec<Option<u32>>,
    /// Per quad: whether its two triangles are kept.
    kept: Vec<Vec<[bool; 2]>>,
    /// The volume group this grid adds to (index in `WeldTopology::groups`).
    group: Option<usize>,
    /// Per row: every vertex is the first copy of its welded vertex (the welded positions are
    /// the grid's own).
    own: Vec<bool>,
    /// Per row: the welded number of vertex `lo` when those of `lo..hi` are consecutive.
    run: Vec<Option<u32>>,
}

/// Welded positions of one grid row as columns of f64, the first column repeated after the last
/// of a periodic row; and the same less the apex of the grid's group.
#[derive(Clone, Debug, Default)]
struct Row {
    p: [Vec<f64>; 3],
    rel: [Vec<f64>; 3],
}

/// Facets of one quad row: first and second triangle of every quad.
#[derive(Clone, Debug, Default)]
struct Facets {
    t1: [Vec<f64>; 3],
    t2: [Vec<f64>; 3],
}

/// Buffers of the pass, kept between frames.
#[derive(Clone, Debug, Default)]
struct Buffers {
    lo: Row,
    hi: Row,
    prev: Facets,
    cur: Facets,
    terms: [Vec<f64>; 2],
    acc: [Vec<f64>; 3],
    unit: Vec<[f32; 3]>,
    dot: Vec<f64>,
}

/// A grid's volume sum: the terms' sum (in the pass's order), the sum of their magnitudes and
/// their number.
#[derive(Clone, Copy, Debug, Default)]
struct Volume {
    sum: f64,
    magnitude: f64,
    terms: usize,
}

/// The layout of a topology's grids as the pass uses it: see the module documentation.
#[derive(Clone, Debug, Default)]
pub(super) struct Pass {
    /// The grids' `periodic_v`, which the layout was made for.
    periodic: Vec<bool>,
    grids: Vec<GridPlan>,
    /// Welded vertices done one by one, increasing.
    special: Vec<u32>,
    /// Their copies `(grid, index)` in the order of the grids' vertices:
    /// `copies[copy_start[s]..copy_start[s + 1]]`.
    copy_start: Vec<u32>,
    copies: Vec<(u32, u32)>,
    /// Their triangles `(grid, welded triangle before any turn)` in the mesh's order.
    tri_start: Vec<u32>,
    tris: Vec<(u32, [u32; 3])>,
    buffers: Buffers,
    /// Groups whose turn the pass's volume left to [`WeldTopology::turns_over`].
    pub(super) undecided: usize,
}

impl Pass {
    /// The layout of `t` for grids with these `periodic_v`.
    pub(super) fn new(t: &WeldTopology, periodic: Vec<bool>) -> Pass {
        let mut count = vec![0u32; t.vertices];
        for map in &t.source {
            for &w in map {
                count[w as usize] += 1;
            }
        }
        let mut special = vec![false; t.vertices];
        let mut seen = vec![false; t.vertices];
        let mut grids = Vec::with_capacity(t.shapes.len());
        for (k, (&(nu, nv), map)) in t.shapes.iter().zip(&t.source).enumerate() {
            let per = periodic[k];
            let cols = if per { nv } else { nv.saturating_sub(1) };
            let (lo, hi) = if per && nv >= 3 {
                (0, nv)
            } else if !per && nv >= 3 {
                (1, nv - 1)
            } else {
                (0, 0)
            };
            for (idx, &w) in map.iter().enumerate() {
                let (i, j) = (idx / nv, idx % nv);
                let plain = i >= 1 && i + 1 < nu && (lo..hi).contains(&j) && count[w as usize] == 1;
                if !plain {
                    special[w as usize] = true;
                }
            }
            let mut collapsed = vec![None; nu.saturating_sub(1)];
            let mut kept = Vec::new();
            for (i, slot) in collapsed.iter_mut().enumerate() {
                let row: Vec<[bool; 2]> = (0..cols)
                    .map(|j| {
                        let j1 = (j + 1) % nv;
                        let (a, b, c, d) =
                            (i * nv + j, (i + 1) * nv + j, (i + 1) * nv + j1, i * nv + j1);
                        let [a, b, c, d] = [a, b, c, d].map(|x| map[x]);
                        [a != b && b != c && a != c, a != c && c != d && a != d]
                    })
                    .collect();
                if row.iter().any(|q| !(q[0] && q[1])) {
                    *slot = Some(kept.len() as u32);
                    kept.push(row);
                }
            }
            let group = t.groups.iter().position(|g| g.members.contains(&k));
            let mut own = Vec::with_capacity(nu);
            let mut run = Vec::with_capacity(nu);
            for row in map.chunks(nv.max(1)) {
                let mut first = true;
                for &w in row {
                    first &= !seen[w as usize];
                    seen[w as usize] = true;
                }
                own.push(first);
                let inner = row.get(lo..hi).unwrap_or_default();
                let consecutive = inner.windows(2).all(|p| p[1] == p[0].wrapping_add(1));
                run.push(inner.first().copied().filter(|_| consecutive));
            }
            grids.push(GridPlan {
                nu,
                nv,
                periodic: per,
                cols,
                lo,
                hi,
                collapsed,
                kept,
                group,
                own,
                run,
            });
        }
        // Lists of the special vertices: copies in the grids' order, triangles in the mesh's.
        let mut slot = vec![u32::MAX; t.vertices];
        let special: Vec<u32> = (0..t.vertices as u32)
            .filter(|&w| special[w as usize])
            .collect();
        for (s, &w) in special.iter().enumerate() {
            slot[w as usize] = s as u32;
        }
        let mut copy_lists: Vec<Vec<(u32, u32)>> = vec![Vec::new(); special.len()];
        for (k, map) in t.source.iter().enumerate() {
            for (idx, &w) in map.iter().enumerate() {
                if let Some(l) = copy_lists.get_mut(slot[w as usize] as usize) {
                    l.push((k as u32, idx as u32));
                }
            }
        }
        let mut tri_lists: Vec<Vec<(u32, [u32; 3])>> = vec![Vec::new(); special.len()];
        for (k, ts) in t.tris.iter().enumerate() {
            for &tri in ts {
                for &w in &tri {
                    if let Some(l) = tri_lists.get_mut(slot[w as usize] as usize) {
                        l.push((k as u32, tri));
                    }
                }
            }
        }
        let (copy_start, copies) = csr(copy_lists);
        let (tri_start, tris) = csr(tri_lists);
        Pass {
            periodic,
            grids,
            special,
            copy_start,
            copies,
            tri_start,
            tris,
            buffers: Buffers::default(),
            undecided: 0,
        }
    }

    /// Whether this layout was made for grids with these `periodic_v`.
    pub(super) fn fits(&self, grids: &[GridMesh]) -> bool {
        self.periodic.len() == grids.len()
            && self
                .periodic
                .iter()
                .zip(grids)
                .all(|(&p, g)| p == g.periodic_v)
    }

    /// The orientation and normals of [`WeldTopology::finish_into`] for grids turned as
    /// `flipped` (the last frame's turns) into `mesh.normals` (`mesh.positions` gathered,
    /// `mesh.triangles` those of `flipped`). Returns false, with the normals unfinished, when
    /// a group turns otherwise than `flipped` says, or a number is not finite: the reference
    /// pass then decides.
    pub(super) fn finish(
        &mut self,
        t: &WeldTopology,
        grids: &[GridMesh],
        diag: f64,
        flipped: &[bool],
        mesh: &mut TriMesh,
    ) -> bool {
        let positions = &mesh.positions;
        // Apexes of the volume groups, as `turns_over` takes them.
        let apex: Vec<[f64; 3]> = t
            .groups
            .iter()
            .map(|g| {
                if g.closed {
                    [0.0; 3]
                } else {
                    let mut sum = [0.0f64; 3];
                    for &a in &g.rim {
                        let p = positions[a as usize];
                        for c in 0..3 {
                            sum[c] += p[c] as f64;
                        }
                    }
                    sum.map(|x| x / g.rim.len().max(1) as f64)
                }
            })
            .collect();
        // Every normal is written below (by the row pass or one by one).
        mesh.normals.resize(positions.len(), [0.0; 3]);
        let mut volumes = vec![Volume::default(); grids.len()];
        for (k, g) in grids.iter().enumerate() {
            let plan = &self.grids[k];
            let apex = plan.group.map(|i| apex[i]);
            let input = GridInput {
                plan,
                grid: g,
                map: &t.source[k],
                positions: &mesh.positions,
                apex,
            };
            let ok = grid_pass(
                &input,
                flipped[k],
                &mut self.buffers,
                &mut mesh.normals,
                &mut volumes[k],
            );
            if !ok {
                return false;
            }
        }
        // The turns: certified from the pass's volumes where the rounding cannot change them.
        let mut group_turns = Vec::with_capacity(t.groups.len());
        for g in &t.groups {
            let (mut sum, mut magnitude, mut terms) = (0.0f64, 0.0f64, 0usize);
            for &k in &g.members {
                let sign = if t.relative[k].1 { -1.0 } else { 1.0 };
                sum += sign * volumes[k].sum;
                magnitude += volumes[k].magnitude;
                terms += volumes[k].terms + 1;
            }
            // Both orders' sums lie within γ_n·Σ|term| of the exact sum of the terms (n
            // additions, γ_n = n·u/(1 − n·u), u = ε/2); twice that, generously rounded up.
            let bound = 4.0 * (terms as f64 + 8.0) * f64::EPSILON * magnitude + 1e-300;
            // Turned when the volume is below `edge` (`encloses && volume < 0`).
            let edge = if g.closed {
                0.0
            } else {
                -(OPEN_VOLUME_FRACTION * diag.powi(3))
            };
            if !(sum.is_finite() && bound.is_finite() && edge.is_finite()) {
                return false;
            }
            group_turns.push(if sum + bound < edge {
                true
            } else if sum - bound > edge {
                false
            } else {
                self.undecided += 1;
                t.turns_over(g, &mesh.positions, diag)
            });
        }
        let same = t.relative.iter().zip(flipped).all(|(&(root, rel), &f)| {
            let turns = t
                .groups
                .iter()
                .position(|g| g.root == root)
                .is_some_and(|i| group_turns[i]);
            rel ^ turns == f
        });
        if !same || flipped.len() != t.relative.len() {
            return false;
        }
        // The special vertices, one by one as the reference does them.
        let positions = &mesh.positions;
        for (s, &w) in self.special.iter().enumerate() {
            let mut sum = [0.0f64; 3];
            let copies = &self.copies[self.copy_start[s] as usize..self.copy_start[s + 1] as usize];
            for &(k, idx) in copies {
                let sign = if flipped[k as usize] { -1.0 } else { 1.0 };
                let n = grids[k as usize].normals[idx as usize];
                for c in 0..3 {
                    sum[c] += sign * n[c] as f64;
                }
            }
            let mut acc = [0.0f64; 3];
            let tris = &self.tris[self.tri_start[s] as usize..self.tri_start[s + 1] as usize];
            for &(k, tri) in tris {
                let f = facet_cross(positions, turned(tri, flipped[k as usize]));
                for c in 0..3 {
                    acc[c] += f[c];
                }
            }
            mesh.normals[w as usize] = settle(unit(sum), acc);
        }
        true
    }
}

/// Lists as one vector and their starts (and its end).
fn csr<T>(lists: Vec<Vec<T>>) -> (Vec<u32>, Vec<T>) {
    let mut start = vec![0u32];
    let mut all = Vec::new();
    for l in lists {
        all.extend(l);
        start.push(all.len() as u32);
    }
    (start, all)
}

/// A triangle as written: turned over (`[a, c, b]`) when its patch is.
fn turned(t: [u32; 3], flip: bool) -> [u32; 3] {
    if flip {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// What the pass reads of one grid: its plan, its mesh, its welded numbers, the welded
/// positions and the apex of its group's volume (`None`: no volume wanted).
struct GridInput<'a> {
    plan: &'a GridPlan,
    grid: &'a GridMesh,
    map: &'a [u32],
    positions: &'a [[f32; 3]],
    apex: Option<[f64; 3]>,
}

/// One grid: volume terms and facets quad row by quad row, normals of the vertices the row pass
/// does. False when a number is not finite.
fn grid_pass(
    input: &GridInput,
    flip: bool,
    buf: &mut Buffers,
    normals: &mut [[f32; 3]],
    volume: &mut Volume,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports the features the function was compiled for.
        return unsafe {
            if flip {
                grid_pass_avx2::<true>(input, buf, normals, volume)
            } else {
                grid_pass_avx2::<false>(input, buf, normals, volume)
            }
        };
    }
    if flip {
        grid_pass_generic::<true>(input, buf, normals, volume)
    } else {
        grid_pass_generic::<false>(input, buf, normals, volume)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn grid_pass_avx2<const FLIP: bool>(
    input: &GridInput,
    buf: &mut Buffers,
    normals: &mut [[f32; 3]],
    volume: &mut Volume,
) -> bool {
    grid_pass_generic::<FLIP>(input, buf, normals, volume)
}

#[inline(always)]
fn grid_pass_generic<const FLIP: bool>(
    input: &GridInput,
    buf: &mut Buffers,
    normals: &mut [[f32; 3]],
    volume: &mut Volume,
) -> bool {
    let GridInput {
        plan,
        grid: g,
        map,
        positions,
        apex,
    } = *input;
    let (nu, nv, cols) = (plan.nu, plan.nv, plan.cols);
    *volume = Volume::default();
    if nu < 2 || cols == 0 {
        return true;
    }
    let Buffers {
        lo,
        hi,
        prev,
        cur,
        terms: [t1, t2],
        acc,
        unit,
        dot,
    } = buf;
    let width = cols + 1;
    for row in [&mut *lo, &mut *hi] {
        for c in row.p.iter_mut().chain(row.rel.iter_mut()) {
            c.resize(width, 0.0);
        }
    }
    for f in [&mut *prev, &mut *cur] {
        for c in f.t1.iter_mut().chain(f.t2.iter_mut()) {
            c.resize(cols, 0.0);
        }
    }
    t1.resize(cols, 0.0);
    t2.resize(cols, 0.0);
    for c in acc.iter_mut() {
        c.resize(nv, 0.0);
    }
    unit.resize(nv, [0.0; 3]);
    dot.resize(nv, 0.0);
    let o = apex.unwrap_or([0.0; 3]);
    let mut lanes = [0.0f64; 4];
    let mut magnitude = [0.0f64; 4];
    let mut finite = true;
    let welded_row = |i: usize| {
        let own = plan.own[i].then(|| &g.positions[i * nv..(i + 1) * nv]);
        (own, &map[i * nv..(i + 1) * nv])
    };
    load_row(lo, positions, welded_row(0), plan.periodic, o);
    for i in 0..nu - 1 {
        load_row(hi, positions, welded_row(i + 1), plan.periodic, o);
        facets::<FLIP>(lo, hi, cols, cur);
        if apex.is_some() {
            terms(lo, hi, cols, t1, t2);
        }
        if let Some(x) = plan.collapsed[i] {
            // Triangles welding collapsed add nothing (see the module documentation).
            for (j, q) in plan.kept[x as usize].iter().enumerate() {
                for c in 0..3 {
                    if !q[0] {
                        cur.t1[c][j] = 0.0;
                    }
                    if !q[1] {
                        cur.t2[c][j] = 0.0;
                    }
                }
                if !q[0] {
                    t1[j] = 0.0;
                }
                if !q[1] {
                    t2[j] = 0.0;
                }
            }
        }
        if apex.is_some() {
            // Every quad's two terms, in four lanes.
            let (c1, r1) = t1[..cols].as_chunks::<4>();
            let (c2, r2) = t2[..cols].as_chunks::<4>();
            for (a, b) in c1.iter().zip(c2) {
                for l in 0..4 {
                    lanes[l] += a[l] + b[l];
                    magnitude[l] += a[l].abs() + b[l].abs();
                }
            }
            for (l, (a, b)) in r1.iter().zip(r2).enumerate() {
                lanes[l] += a + b;
                magnitude[l] += a.abs() + b.abs();
            }
        }
        if i >= 1 && plan.lo < plan.hi {
            let row_normals = &g.normals[i * nv..(i + 1) * nv];
            let len = plan.hi - plan.lo;
            // Straight into the mesh where the row's welded numbers are consecutive.
            let direct = plan.run[i]
                .map(|w| w as usize)
                .filter(|&w| w + len <= normals.len());
            let out = match direct {
                Some(w) => &mut normals[w..w + len],
                None => &mut unit[..len],
            };
            finite &= vertex_row::<FLIP>(plan, prev, cur, row_normals, acc, out, dot);
            if direct.is_none() {
                let row_map = &map[i * nv + plan.lo..i * nv + plan.hi];
                for (&w, n) in row_map.iter().zip(&unit[..len]) {
                    normals[w as usize] = *n;
                }
            }
        }
        std::mem::swap(lo, hi);
        std::mem::swap(prev, cur);
    }
    *volume = Volume {
        sum: (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]),
        magnitude: (magnitude[0] + magnitude[1]) + (magnitude[2] + magnitude[3]),
        terms: 2 * cols * (nu - 1),
    };
    finite
}

/// `a · (b × c) / 6` as [`super::super::signed_volume_about`] computes it (corners less the
/// apex).
#[inline(always)]
fn term(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let bc = [
        b[1] * c[2] - b[2] * c[1],
        b[2] * c[0] - b[0] * c[2],
        b[0] * c[1] - b[1] * c[0],
    ];
    (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0
}

/// A row's welded positions: the grid's own (`own`) or through `map`; the first repeated at the
/// end of a periodic row.
#[inline(always)]
fn load_row(
    row: &mut Row,
    positions: &[[f32; 3]],
    (own, map): (Option<&[[f32; 3]]>, &[u32]),
    periodic: bool,
    o: [f64; 3],
) {
    let nv = map.len();
    let [x, y, z] = &mut row.p;
    let (x, y, z) = (&mut x[..nv], &mut y[..nv], &mut z[..nv]);
    let put = |p: [f32; 3], ((x, y), z): ((&mut f64, &mut f64), &mut f64)| {
        (*x, *y, *z) = (p[0] as f64, p[1] as f64, p[2] as f64);
    };
    let out = x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut());
    match own {
        Some(own) => own.iter().zip(out).for_each(|(&p, o)| put(p, o)),
        None => map
            .iter()
            .zip(out)
            .for_each(|(&w, o)| put(positions[w as usize], o)),
    }
    if periodic {
        for c in 0..3 {
            row.p[c][nv] = row.p[c][0];
        }
    }
    let width = row.p[0].len();
    for ((src, dst), &oc) in row.p.iter().zip(row.rel.iter_mut()).zip(&o) {
        for (d, &x) in dst[..width].iter_mut().zip(&src[..width]) {
            *d = x - oc;
        }
    }
}

/// The facets of quad row `lo`–`hi` as [`facet_cross`] computes them for the triangles as
/// written: quad `(a, b, c, d)` = `(lo[j], hi[j], hi[j+1], lo[j+1])` gives `[a, b, c]` and
/// `[a, c, d]`, turned `[a, c, b]` and `[a, d, c]`.
#[inline(always)]
fn facets<const FLIP: bool>(lo: &Row, hi: &Row, cols: usize, out: &mut Facets) {
    let (ax, ay, az) = (&lo.p[0][..cols], &lo.p[1][..cols], &lo.p[2][..cols]);
    let (dx, dy, dz) = (&lo.p[0][1..=cols], &lo.p[1][1..=cols], &lo.p[2][1..=cols]);
    let (bx, by, bz) = (&hi.p[0][..cols], &hi.p[1][..cols], &hi.p[2][..cols]);
    let (cx, cy, cz) = (&hi.p[0][1..=cols], &hi.p[1][1..=cols], &hi.p[2][1..=cols]);
    let [f1x, f1y, f1z] = &mut out.t1;
    let [f2x, f2y, f2z] = &mut out.t2;
    let (f1x, f1y, f1z) = (&mut f1x[..cols], &mut f1y[..cols], &mut f1z[..cols]);
    let (f2x, f2y, f2z) = (&mut f2x[..cols], &mut f2y[..cols], &mut f2z[..cols]);
    let cross = |e1: [f64; 3], e2: [f64; 3]| {
        [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ]
    };
    for j in 0..cols {
        let ab = [bx[j] - ax[j], by[j] - ay[j], bz[j] - az[j]];
        let ac = [cx[j] - ax[j], cy[j] - ay[j], cz[j] - az[j]];
        let ad = [dx[j] - ax[j], dy[j] - ay[j], dz[j] - az[j]];
        let (f1, f2) = if FLIP {
            (cross(ac, ab), cross(ad, ac))
        } else {
            (cross(ab, ac), cross(ac, ad))
        };
        (f1x[j], f1y[j], f1z[j]) = (f1[0], f1[1], f1[2]);
        (f2x[j], f2y[j], f2z[j]) = (f2[0], f2[1], f2[2]);
    }
}

/// The volume terms `a·(b×c)/6` and `a·(c×d)/6` of the two triangles of every quad of the row.
#[inline(always)]
fn terms(lo: &Row, hi: &Row, cols: usize, out1: &mut [f64], out2: &mut [f64]) {
    let (ax, ay, az) = (&lo.rel[0][..cols], &lo.rel[1][..cols], &lo.rel[2][..cols]);
    let (dx, dy, dz) = (
        &lo.rel[0][1..=cols],
        &lo.rel[1][1..=cols],
        &lo.rel[2][1..=cols],
    );
    let (bx, by, bz) = (&hi.rel[0][..cols], &hi.rel[1][..cols], &hi.rel[2][..cols]);
    let (cx, cy, cz) = (
        &hi.rel[0][1..=cols],
        &hi.rel[1][1..=cols],
        &hi.rel[2][1..=cols],
    );
    let (out1, out2) = (&mut out1[..cols], &mut out2[..cols]);
    for j in 0..cols {
        let (a, b, c, d) = (
            [ax[j], ay[j], az[j]],
            [bx[j], by[j], bz[j]],
            [cx[j], cy[j], cz[j]],
            [dx[j], dy[j], dz[j]],
        );
        out1[j] = term(a, b, c);
        out2[j] = term(a, c, d);
    }
}

/// Normals of the vertices `plan.lo..plan.hi` of a row between quad rows `prev` and `cur`
/// into `out` (from `plan.lo`): the six facets around each in the mesh's order (quad row
/// `i − 1`, then `i`; quads by column; each quad's first triangle first), the copy's normal
/// turned with the grid. False when a number is not finite.
#[inline(always)]
fn vertex_row<const FLIP: bool>(
    plan: &GridPlan,
    prev: &Facets,
    cur: &Facets,
    normals: &[[f32; 3]],
    acc: &mut [Vec<f64>; 3],
    out: &mut [[f32; 3]],
    dots: &mut [f64],
) -> bool {
    let nv = plan.nv;
    let s = if FLIP { -1.0 } else { 1.0 };
    // Columns j ≥ 1: quads j − 1 and j of both rows.
    for (c, acc) in acc.iter_mut().enumerate() {
        let (p1, p2, c1, c2) = (&prev.t1[c], &prev.t2[c], &cur.t1[c], &cur.t2[c]);
        let n = plan.hi - 1;
        let (p1m, p2m, p1j) = (&p1[..n], &p2[..n], &p1[1..=n]);
        let (c2m, c1j, c2j) = (&c2[..n], &c1[1..=n], &c2[1..=n]);
        let a = &mut acc[1..=n];
        for j in 0..n {
            a[j] = 0.0 + p1m[j] + p2m[j] + p1j[j] + c2m[j] + c1j[j] + c2j[j];
        }
        if plan.periodic {
            let m = nv - 1;
            acc[0] = 0.0 + p1[0] + p1[m] + p2[m] + c1[0] + c2[0] + c2[m];
        }
    }
    let (lo, hi) = (plan.lo, plan.hi);
    let (ax, ay, az) = (&acc[0][lo..hi], &acc[1][lo..hi], &acc[2][lo..hi]);
    let (normals, dots) = (&normals[lo..hi], &mut dots[..hi - lo]);
    let out = &mut out[..hi - lo];
    // Whether some vertex needs a second look (its normal against the facets, or a number not
    // finite).
    let mut look = false;
    for j in 0..hi - lo {
        let n = normals[j];
        let m = [
            0.0 + s * n[0] as f64,
            0.0 + s * n[1] as f64,
            0.0 + s * n[2] as f64,
        ];
        let u = unit(m);
        out[j] = u;
        let dot = u[0] as f64 * ax[j] + u[1] as f64 * ay[j] + u[2] as f64 * az[j];
        dots[j] = dot;
        look |= !(dot > 0.0 && dot < f64::INFINITY);
    }
    let mut finite = true;
    if look {
        for j in 0..hi - lo {
            finite &= dots[j].is_finite();
            if dots[j] <= 0.0 {
                out[j] = facet_mean([ax[j], ay[j], az[j]]).unwrap_or(out[j]);
            }
        }
    }
    finite
}
