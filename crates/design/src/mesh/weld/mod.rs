//! The patches of a design as one welded, consistently oriented triangle mesh.
//!
//! A design's grids repeat points: a pole row collapses to one point, the seam of a surface that
//! closes on itself appears twice (the `[blend]` surface's first and last columns), and two
//! patches that share a position curve both carry its points. [`weld`] joins every such pair of
//! boundary vertices (rows `0` and `nu−1`, the end columns of a non-periodic grid, and any row
//! that collapsed to one point) that lie within `10⁻⁶` of the design's bounding-box diagonal of
//! each other, drops the triangles that welding left with two equal corners (the pole fans keep
//! one vertex per pole), and orients the result:
//!
//! * patches that share an edge are turned to agree along it (a patch is flipped as a whole);
//! * a closed group of patches (every edge shared by two triangles) is turned outward: its
//!   signed volume is positive;
//! * an open group that encloses a volume once its boundary is closed by a cone from the
//!   centroid of its boundary vertices (a cup, a glass: [`OPEN_VOLUME_FRACTION`]) is turned so
//!   that this capped volume is positive, the normals pointing away from the inside;
//! * any other open group (a sheet) keeps the side its first patch's normals `X_u × X_v` point
//!   to.
//!
//! Only boundary vertices are welded, so the interior of a self-intersecting surface (the Klein
//! bottle) is never stitched to itself. Vertex normals are the exact surface normals (the
//! normalised mean of the welded copies, after the flips), except where that mean vanishes or
//! points against the triangles around the vertex, where the mean of their facet normals is
//! taken; texture coordinates are dropped, since a welded vertex has several.

use super::{GridMesh, Part, TriMesh};
use rayon::prelude::*;
use std::collections::HashMap;

mod frame;
mod normals;
mod plan;
pub use frame::FrameWeld;
pub use plan::{Plan, PlanPart};
use std::hash::BuildHasherDefault;
use std::mem::MaybeUninit;

/// A fast hasher for the merge's grid-cell keys (multiply–rotate over 8-byte words, as in
/// rustc's FxHash): the keys are cells of the mesh's own vertices, so SipHash's protection
/// against chosen keys buys nothing, and it was a tenth of an animation frame's time.
#[derive(Default, Clone, Copy)]
struct CellHasher(u64);

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
struct Edge(u64);

impl Edge {
    fn new(a: u32, b: u32) -> Self {
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
fn edge_map<V>(triangles: usize) -> HashMap<Edge, V, BuildHasherDefault<CellHasher>> {
    HashMap::with_capacity_and_hasher(triangles * 3 / 2 + 64, Default::default())
}

/// Relative weld tolerance: a fraction of the bounding-box diagonal (far above `f32` rounding of
/// the same point, far below any grid spacing).
pub const WELD_TOLERANCE: f64 = 1e-6;

/// An open group of patches is turned to a positive capped volume only when that volume exceeds
/// this fraction of the cube of the bounding-box diagonal; below it the group is a sheet and
/// keeps the side of its first patch.
pub const OPEN_VOLUME_FRACTION: f64 = 1e-3;

/// How [`weld`] joins the patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WeldOptions {
    /// Join patches that share an edge into one connected mesh (the default). When false, every
    /// patch is welded (poles, seams) and oriented on its own and shares no vertex with another.
    pub join_patches: bool,
}

impl Default for WeldOptions {
    fn default() -> Self {
        WeldOptions { join_patches: true }
    }
}

/// Union–find with the parity of a patch's orientation relative to its group's root.
struct Parity {
    parent: Vec<usize>,
    flip: Vec<bool>,
    conflict: Vec<bool>,
}

impl Parity {
    fn new(n: usize) -> Self {
        Parity {
            parent: (0..n).collect(),
            flip: vec![false; n],
            conflict: vec![false; n],
        }
    }

    /// Root of `a` and the parity of `a` relative to it.
    fn find(&mut self, a: usize) -> (usize, bool) {
        let mut parity = false;
        let mut x = a;
        while self.parent[x] != x {
            parity ^= self.flip[x];
            x = self.parent[x];
        }
        (x, parity)
    }

    /// Records that `a` and `b` must differ in orientation by `differ`.
    fn join(&mut self, a: usize, b: usize, differ: bool) {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            if pa ^ pb != differ {
                self.conflict[ra] = true;
            }
            return;
        }
        // Attach the larger index's root under the smaller's, so a group's root is its first
        // patch.
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        self.parent[hi] = lo;
        self.flip[hi] = pa ^ pb ^ differ;
        if self.conflict[hi] {
            self.conflict[lo] = true;
        }
    }
}

/// True for the rows whose every vertex may coincide with another: the two end rows and the
/// rows collapsed to one point. The end columns of a non-periodic grid are the other weld
/// candidates ([`GridTopology::explicit`]).
fn candidate_rows(g: &GridMesh) -> Vec<bool> {
    let (nu, nv) = (g.nu, g.nv);
    (0..nu)
        .map(|i| {
            let row = &g.positions[i * nv..(i + 1) * nv];
            i == 0 || i + 1 == nu || row.iter().all(|p| p == &row[0])
        })
        .collect()
}

/// The grids of a design welded into one oriented [`TriMesh`] with one part per grid, named
/// `names[k]` (or `patch<k>` where `names` is short). See the module documentation.
pub fn weld(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> TriMesh {
    weld_mapped(grids, names, options).mesh
}

/// A welded mesh with the way back to its grids.
#[derive(Clone, Debug, PartialEq)]
pub struct Welded {
    /// The mesh [`weld`] returns.
    pub mesh: TriMesh,
    /// `source[k][i]`: the welded vertex of vertex `i` of grid `k`.
    pub source: Vec<Vec<u32>>,
    /// True for the grids whose triangles were turned over (`X_v × X_u` orientation).
    pub flipped: Vec<bool>,
}

/// [`weld`], also returning each grid vertex's welded vertex and each grid's turn (for meshes
/// built on the same vertices with other elements, such as quadratic shell elements).
///
/// The mesh equals [`WeldTopology::new`]'s bit for bit, built without keeping a topology: the
/// groups' volumes are summed over each grid's triangles as its layout gives them (members in
/// parallel, each in the order of its triangles) while the triangles are written once, in
/// place, then turned where a grid is.
pub fn weld_mapped(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> Welded {
    let Joined {
        diag,
        positions,
        source,
        rows,
        relative,
        groups,
        ..
    } = join(grids, options);
    let topo: Vec<GridTopology> = grids
        .iter()
        .zip(&source)
        .zip(&rows)
        .map(|((g, map), rows)| GridTopology::new(g, map, rows))
        .collect();
    // The kept triangles of every quad row, and of every grid.
    let counts: Vec<Vec<usize>> = topo.par_iter().map(GridTopology::kept_per_row).collect();
    let lens: Vec<usize> = counts.iter().map(|c| c.iter().sum()).collect();
    let total: usize = lens.iter().sum();
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(total);
    super::advise_huge_pages(triangles.spare_capacity_mut());
    let (turns, ()) = rayon::join(
        || {
            groups
                .par_iter()
                .map(|g| {
                    (
                        g.root,
                        g.turned_over_soon(&topo, &positions, &relative, diag),
                    )
                })
                .collect::<Vec<(usize, bool)>>()
        },
        || {
            let mut rest = &mut triangles.spare_capacity_mut()[..total];
            let mut jobs = Vec::with_capacity(topo.len());
            for ((t, c), &len) in topo.iter().zip(&counts).zip(&lens) {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                jobs.push((t, c, head));
            }
            jobs.into_par_iter()
                .for_each(|(t, c, dst)| t.triangles_into(c, dst));
        },
    );
    // SAFETY: the grids' slices tile the first `total` elements, each written in full by
    // `triangles_into`.
    unsafe { triangles.set_len(total) };
    let flipped = flipped_of(&relative, &turns);
    let names = part_names(grids.len(), names);
    let mut parts = Vec::with_capacity(grids.len());
    let mut rest = triangles.as_mut_slice();
    let mut start = 0;
    for (k, &len) in lens.iter().enumerate() {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        if flipped[k] {
            head.par_chunks_mut(1 << 15)
                .for_each(|ts| ts.iter_mut().for_each(|t| t.swap(1, 2)));
        }
        parts.push(Part {
            name: names[k].clone(),
            triangles: start..start + len,
        });
        start += len;
    }
    let normals = normals::vertex_normals(grids, &source, &positions, &flipped);
    Welded {
        mesh: TriMesh {
            positions,
            normals,
            uv: Vec::new(),
            triangles,
            parts,
        },
        source,
        flipped,
    }
}

/// Each grid's turn: its orientation relative to its group's root, and the root's `turns`
/// (the groups a volume turned over).
fn flipped_of(relative: &[(usize, bool)], turns: &[(usize, bool)]) -> Vec<bool> {
    relative
        .iter()
        .map(|&(root, rel)| rel ^ turns.iter().any(|&(r, turn)| r == root && turn))
        .collect()
}

/// Part names: `names[k]`, or `patch<k>` where `names` is short.
fn part_names(grids: usize, names: &[&str]) -> Vec<String> {
    (0..grids)
        .map(|k| {
            names
                .get(k)
                .map(|s| s.to_string())
                .unwrap_or_else(|| format!("patch{k}"))
        })
        .collect()
}

/// What welding a set of grids found that depends only on which vertices it joined: the
/// welded triangles of every grid, which grids meet along which edges (their relative
/// orientation), which groups of grids are closed and the rims of the open ones. Grids whose
/// vertices join alike (an animation's frames) are welded again with [`WeldTopology::weld`]
/// without building the edge maps again; the result equals [`weld_mapped`]'s bit for bit.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldTopology {
    options: WeldOptions,
    names: Vec<String>,
    /// The grids' shapes `(nu, nv)`.
    shapes: Vec<(usize, usize)>,
    source: Vec<Vec<u32>>,
    vertices: usize,
    /// Per grid, its triangles re-indexed (before any turn), without the collapsed ones.
    tris: Vec<Vec<[u32; 3]>>,
    /// Per grid, its group's root and its orientation relative to it.
    relative: Vec<(usize, bool)>,
    /// The groups whose orientation is decided by a volume, in the order weld visits them.
    groups: Vec<Group>,
}

#[derive(Clone, Debug, PartialEq)]
struct Group {
    root: usize,
    members: Vec<usize>,
    closed: bool,
    /// The first vertex of every rim edge (used once), in the order of the triangles.
    rim: Vec<u32>,
}

impl Group {
    /// Where the cones closing an open group meet: the centroid of its rim (the origin for a
    /// closed group, whose volume does not depend on it).
    fn apex(&self, positions: &[[f32; 3]]) -> [f64; 3] {
        if self.closed {
            return [0.0; 3];
        }
        let mut sum = [0.0f64; 3];
        for &a in &self.rim {
            let p = positions[a as usize];
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        sum.map(|x| x / self.rim.len().max(1) as f64)
    }

    /// Whether the group is turned over, given the signed volumes of its members' triangles
    /// (as the grids have them, before any turn) about [`Group::apex`], in member order: a
    /// closed group whose enclosed volume is negative, or an open one whose volume closed by a
    /// cone from the centroid of its rim (what `analyze` calls the capped volume) is negative
    /// and not next to nothing (a sheet keeps its first patch's side).
    fn turned_over(
        &self,
        relative: &[(usize, bool)],
        volumes: impl IntoIterator<Item = f64>,
        diag: f64,
    ) -> bool {
        let mut volume = 0.0f64;
        for (&k, v) in self.members.iter().zip(volumes) {
            let sign = if relative[k].1 { -1.0 } else { 1.0 };
            volume += sign * v;
        }
        let encloses = self.closed || volume.abs() > OPEN_VOLUME_FRACTION * diag.powi(3);
        encloses && volume < 0.0
    }

    /// [`Group::turned_over`] with the members' volumes summed over their grids' triangles: in
    /// parallel, in any order, when that cannot change the answer; else in the triangles' order.
    ///
    /// Any order of summing `n` terms lands within `γ·Σ|term|` of their exact sum (`γ = n·2⁻⁵³`,
    /// to first order), so two orders differ by at most twice that, and the group's volume (a
    /// sum of the members' with signs) by at most the sum of those plus its own rounding. When
    /// the volume found in parallel is farther than a generous multiple of that from zero and
    /// from the threshold of [`OPEN_VOLUME_FRACTION`], the triangles' order decides alike.
    fn turned_over_soon(
        &self,
        topo: &[GridTopology],
        positions: &[[f32; 3]],
        relative: &[(usize, bool)],
        diag: f64,
    ) -> bool {
        let apex = self.apex(positions);
        // (sum, sum of absolute values, terms) of each member, quad rows in parallel.
        let sums: Vec<(f64, f64, usize)> = self
            .members
            .par_iter()
            .map(|&k| {
                let t = &topo[k];
                (0..t.nu.saturating_sub(1))
                    .into_par_iter()
                    .with_min_len(16)
                    .map(|i| {
                        let (mut s, mut a, mut n) = (0.0f64, 0.0f64, 0usize);
                        for j in 0..t.cols {
                            for tri in t.quad(i, j) {
                                if let Some(w) = t.welded(tri) {
                                    let v = volume_term(positions, w, apex);
                                    s += v;
                                    a += v.abs();
                                    n += 1;
                                }
                            }
                        }
                        (s, a, n)
                    })
                    .reduce(|| (0.0, 0.0, 0), |x, y| (x.0 + y.0, x.1 + y.1, x.2 + y.2))
            })
            .collect();
        let mut volume = 0.0f64;
        for (&k, &(v, _, _)) in self.members.iter().zip(&sums) {
            volume += if relative[k].1 { -v } else { v };
        }
        let size: f64 = sums.iter().map(|&(v, a, _)| a + v.abs()).sum();
        let terms: usize = sums.iter().map(|&(_, _, n)| n).sum::<usize>() + sums.len();
        let slack = 8.0 * (terms as f64 + 4.0) * f64::EPSILON * size;
        let threshold = OPEN_VOLUME_FRACTION * diag.powi(3);
        let clear = volume.abs() > slack
            && (self.closed || (volume.abs() - threshold).abs() > slack)
            && slack.is_finite();
        if clear {
            self.turned_over(relative, sums.iter().map(|&(v, _, _)| v), diag)
        } else {
            let exact = self.members.iter().map(|&k| {
                topo[k]
                    .kept()
                    .map(|t| volume_term(positions, t, apex))
                    .sum::<f64>()
            });
            self.turned_over(relative, exact, diag)
        }
    }
}

/// A box `(lo, hi)` with sides along the axes.
pub type BoundingBox = ([f32; 3], [f32; 3]);

/// The box around nothing: the identity of [`box_union`].
pub const EMPTY_BOX: BoundingBox = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The smallest box around two boxes (by comparisons, as [`bounding_box`]).
pub fn box_union(a: BoundingBox, b: BoundingBox) -> BoundingBox {
    (
        [0, 1, 2].map(|c| if b.0[c] < a.0[c] { b.0[c] } else { a.0[c] }),
        [0, 1, 2].map(|c| if b.1[c] > a.1[c] { b.1[c] } else { a.1[c] }),
    )
}

/// The smallest box `(lo, hi)` around `points`, by comparisons: a NaN coordinate is passed
/// over (as `f32::min` passes it over), and which sign a zero extreme keeps is not specified.
/// Eight points at a time in 24 lanes, which the compiler turns into vector compares.
pub(crate) fn bounding_box(points: &[[f32; 3]]) -> BoundingBox {
    let flat = points.as_flattened();
    let mut lo = [f32::INFINITY; 24];
    let mut hi = [f32::NEG_INFINITY; 24];
    let mut blocks = flat.chunks_exact(24);
    for b in &mut blocks {
        for k in 0..24 {
            lo[k] = if b[k] < lo[k] { b[k] } else { lo[k] };
            hi[k] = if b[k] > hi[k] { b[k] } else { hi[k] };
        }
    }
    for (k, &x) in blocks.remainder().iter().enumerate() {
        lo[k] = if x < lo[k] { x } else { lo[k] };
        hi[k] = if x > hi[k] { x } else { hi[k] };
    }
    let (mut l, mut h) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for k in 0..24 {
        let c = k % 3;
        l[c] = if lo[k] < l[c] { lo[k] } else { l[c] };
        h[c] = if hi[k] > h[c] { hi[k] } else { h[c] };
    }
    (l, h)
}

/// Bounding-box diagonal of every grid vertex (blocks in parallel: minima and maxima do not
/// depend on the order).
fn diagonal(grids: &[GridMesh]) -> f64 {
    let empty = || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let (lo, hi) = grids
        .par_iter()
        .flat_map(|g| g.positions.par_chunks(1 << 14))
        .map(|block| {
            // In f32 (the extremes convert exactly); the sign of a zero does not change the
            // diagonal.
            let (lo, hi) = bounding_box(block);
            (lo.map(f64::from), hi.map(f64::from))
        })
        .reduce(empty, |(a, b), (c, d)| {
            (
                [a[0].min(c[0]), a[1].min(c[1]), a[2].min(c[2])],
                [b[0].max(d[0]), b[1].max(d[1]), b[2].max(d[2])],
            )
        });
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}

/// Joins the boundary vertices that coincide: the welded positions (first copy) and the welded
/// vertex of every grid vertex.
fn merge(grids: &[GridMesh], options: WeldOptions, diag: f64) -> (Vec<[f32; 3]>, Vec<Vec<u32>>) {
    let m = merge_rows(grids, options, diag);
    (m.positions, m.source)
}

/// What [`merge_rows`] finds.
struct Merged {
    /// The welded positions (each vertex's first copy).
    positions: Vec<[f32; 3]>,
    /// Each grid's welded vertex of every grid vertex.
    source: Vec<Vec<u32>>,
    /// Each grid's [`candidate_rows`].
    rows: Vec<Vec<bool>>,
    /// Each grid's welded number of each row's first new vertex, and one past its last row's:
    /// grid `k`'s own vertices (the ones it adds) are `starts[k][0]..starts[k][nu]`.
    starts: Vec<Vec<usize>>,
}

/// [`merge`], also returning each grid's [`candidate_rows`] and where its rows' new vertices
/// start.
///
/// Welded vertices are numbered in the order of the grids' vertices, a new number for every
/// vertex that is not a candidate or finds no earlier candidate within the tolerance. Only the
/// candidates are visited one by one (in that order, looking through the cells around them);
/// the others take consecutive numbers, so every row's new vertices form one range of welded
/// numbers, and the rows are then filled in parallel.
fn merge_rows(grids: &[GridMesh], options: WeldOptions, diag: f64) -> Merged {
    let tol = if diag.is_finite() && diag > 0.0 {
        WELD_TOLERANCE * diag
    } else {
        f64::MIN_POSITIVE
    };
    let tol2 = tol * tol;
    let cell = |p: [f32; 3]| p.map(|x| (x as f64 / tol).floor() as i64);

    // Candidates' cells: their welded vertex and its position (the first copy's).
    type Buckets = HashMap<([i64; 3], usize), Vec<(u32, [f32; 3])>, BuildHasherDefault<CellHasher>>;
    let mut buckets: Buckets = HashMap::default();
    let mut next = 0usize;
    let mut visit = |p: [f32; 3], group: usize, next: &mut usize| -> u32 {
        let c = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = ([c[0] + dx, c[1] + dy, c[2] + dz], group);
                    if let Some(list) = buckets.get(&key) {
                        for &(w, q) in list {
                            let d2: f64 = (0..3).map(|a| (p[a] as f64 - q[a] as f64).powi(2)).sum();
                            if d2 <= tol2 {
                                return w;
                            }
                        }
                    }
                }
            }
        }
        let w = *next as u32;
        *next += 1;
        buckets.entry((c, group)).or_default().push((w, p));
        w
    };
    let mut sources: Vec<Vec<u32>> = Vec::with_capacity(grids.len());
    let mut all_rows = Vec::with_capacity(grids.len());
    // Per grid, the welded number of each row's first new vertex (and one past the last row).
    let mut starts: Vec<Vec<usize>> = Vec::with_capacity(grids.len());
    for (k, g) in grids.iter().enumerate() {
        let group = if options.join_patches { 0 } else { k };
        let (nu, nv) = (g.nu, g.nv);
        let rows = candidate_rows(g);
        // Zeroed pages are faulted in where they are first written: the candidates here, the
        // rest in parallel below.
        let mut map = vec![0u32; nu * nv];
        super::advise_huge_pages(&mut map);
        let mut start = Vec::with_capacity(nu + 1);
        for (i, &whole) in rows.iter().enumerate() {
            start.push(next);
            let row = i * nv;
            if whole {
                for j in 0..nv {
                    map[row + j] = visit(g.positions[row + j], group, &mut next);
                }
            } else if g.periodic_v {
                next += nv;
            } else if nv > 0 {
                map[row] = visit(g.positions[row], group, &mut next);
                if nv > 1 {
                    next += nv - 2;
                    map[row + nv - 1] = visit(g.positions[row + nv - 1], group, &mut next);
                }
            }
        }
        start.push(next);
        sources.push(map);
        all_rows.push(rows);
        starts.push(start);
    }

    // Every row's new vertices are the welded numbers start[i]..start[i + 1]: the row's
    // non-candidates in order, and each candidate whose number is at least start[i].
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(next);
    super::advise_huge_pages(positions.spare_capacity_mut());
    {
        let mut rest = &mut positions.spare_capacity_mut()[..next];
        let mut tasks = Vec::new();
        for (k, (g, map)) in grids.iter().zip(sources.iter_mut()).enumerate() {
            let nv = g.nv.max(1);
            for (i, src) in map.chunks_mut(nv).enumerate() {
                let len = starts[k][i + 1] - starts[k][i];
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                tasks.push((g, &all_rows[k], i, starts[k][i], src, head));
            }
        }
        tasks
            .into_par_iter()
            .with_min_len(8)
            .for_each(|(g, rows, i, start, src, out)| {
                let nv = src.len();
                let row = &g.positions[i * g.nv..i * g.nv + nv];
                if !rows[i] {
                    // Non-candidates, numbered after the first column if it was new.
                    let (first, lo, hi) = if g.periodic_v {
                        (start, 0, nv)
                    } else {
                        let first = start + (src[0] as usize == start) as usize;
                        (first, 1, nv.saturating_sub(1).max(1))
                    };
                    for (j, s) in src.iter_mut().enumerate().take(hi).skip(lo) {
                        *s = (first + j - lo) as u32;
                    }
                }
                // New vertices take increasing numbers along the row; a candidate joined to an
                // earlier vertex (of this row or before) has a smaller one.
                let mut expect = start;
                for (s, p) in src.iter().zip(row) {
                    if *s as usize == expect {
                        out[expect - start].write(*p);
                        expect += 1;
                    }
                }
                assert_eq!(
                    expect - start,
                    out.len(),
                    "every new vertex of the row written"
                );
            });
    }
    // SAFETY: the welded numbers 0..next are the union of the rows' ranges start[i]..start[i+1],
    // and each row wrote every number of its range (checked by the assertion above).
    unsafe { positions.set_len(next) };
    Merged {
        positions,
        source: sources,
        rows: all_rows,
        starts,
    }
}

/// A grid's triangles as the weld sees them. Vertices that are not weld candidates keep a
/// welded number of their own, so every triangle around one of them belongs to its grid and is
/// known from the grid's layout: only the edges between two "explicit" vertices (the candidates;
/// every vertex of a grid too small for that reasoning) can meet other patches or be used an
/// unusual number of times, and only those go through the edge map.
struct GridTopology<'a> {
    nu: usize,
    nv: usize,
    periodic: bool,
    /// Columns of quads.
    cols: usize,
    /// The welded vertex of every grid vertex.
    map: &'a [u32],
    /// [`candidate_rows`].
    rows: &'a [bool],
    /// Every vertex explicit (a periodic grid of fewer than 3 columns, whose triangles around
    /// a vertex repeat).
    all: bool,
}

impl<'a> GridTopology<'a> {
    fn new(g: &GridMesh, map: &'a [u32], rows: &'a [bool]) -> Self {
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
    fn row_explicit(&self, i: usize) -> bool {
        self.all || self.rows[i]
    }

    /// Whether grid vertex `idx` is explicit: a weld candidate, or any vertex of a tiny grid.
    fn explicit(&self, idx: u32) -> bool {
        let (i, j) = (idx as usize / self.nv, idx as usize % self.nv);
        self.row_explicit(i) || (!self.periodic && (j == 0 || j + 1 == self.nv))
    }

    /// The two triangles of quad `(i, j)` in grid numbers, as [`GridMesh::triangles`] gives them.
    fn quad(&self, i: usize, j: usize) -> [[u32; 3]; 2] {
        let nv = self.nv;
        let j1 = (j + 1) % nv;
        let (a, b, c, d) = (i * nv + j, (i + 1) * nv + j, (i + 1) * nv + j1, i * nv + j1);
        let [a, b, c, d] = [a, b, c, d].map(|x| x as u32);
        [[a, b, c], [a, c, d]]
    }

    /// A grid triangle in welded numbers, `None` where welding collapsed it.
    fn welded(&self, t: [u32; 3]) -> Option<[u32; 3]> {
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
    fn for_each_visited(&self, all_quads: bool, mut f: impl FnMut([u32; 3], [u32; 3])) {
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
    fn kept_per_row(&self) -> Vec<usize> {
        (0..self.nu.saturating_sub(1))
            .map(|i| self.kept_in_row(i))
            .collect()
    }

    /// The welded triangles of the grid, without the collapsed ones, in the grid's order.
    fn kept(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        (0..self.nu.saturating_sub(1))
            .flat_map(move |i| (0..self.cols).flat_map(move |j| self.quad(i, j)))
            .filter_map(move |t| self.welded(t))
    }

    /// The welded triangles of the grid, without the collapsed ones, in the grid's order (quad
    /// rows in parallel, each written once into its place).
    fn triangles(&self) -> Vec<[u32; 3]> {
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
    fn triangles_into(&self, counts: &[usize], out: &mut [MaybeUninit<[u32; 3]>]) {
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
struct Joined {
    diag: f64,
    positions: Vec<[f32; 3]>,
    source: Vec<Vec<u32>>,
    rows: Vec<Vec<bool>>,
    /// [`Merged::starts`].
    starts: Vec<Vec<usize>>,
    relative: Vec<(usize, bool)>,
    groups: Vec<Group>,
}

/// Merges the grids' vertices and finds which grids meet along which edges, how they are turned
/// relative to each other, and which groups are closed (with the rims of the open ones).
///
/// The edges are counted from the grids' layout (see [`GridTopology`]): only the edges between
/// weld candidates (the grids' boundaries and collapsed rows: a few rows and columns) go through
/// a map; the result is that of counting every edge in one map.
fn join(grids: &[GridMesh], options: WeldOptions) -> Joined {
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

impl WeldTopology {
    /// Welds `grids` (as [`weld_mapped`]) and keeps what the welding found.
    pub fn new(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> (Self, Welded) {
        let Joined {
            diag,
            positions,
            source,
            rows,
            relative,
            groups,
            ..
        } = join(grids, options);
        // Triangles per patch, re-indexed, without the ones welding collapsed.
        let tris: Vec<Vec<[u32; 3]>> = grids
            .iter()
            .zip(&source)
            .zip(&rows)
            .map(|((g, map), rows)| GridTopology::new(g, map, rows).triangles())
            .collect();
        let topology = WeldTopology {
            options,
            names: part_names(grids.len(), names),
            shapes: grids.iter().map(|g| (g.nu, g.nv)).collect(),
            vertices: positions.len(),
            source,
            tris,
            relative,
            groups,
        };
        let welded = topology.finish(grids, positions, diag);
        (topology, welded)
    }

    /// Welds grids of the same shapes as the first; `None` when their vertices join otherwise
    /// (a curve became a point, two patches met or parted), where [`weld_mapped`] must be
    /// called again. The result equals `weld_mapped(grids, …)` bit for bit.
    pub fn weld(&self, grids: &[GridMesh]) -> Option<Welded> {
        // The first frame's vertex map, checked rather than rebuilt (see `weld_frame`);
        // where the check fails, the merge decides.
        if let Some(w) = self.weld_gathered(grids) {
            return Some(w);
        }
        let same_shapes = grids.len() == self.shapes.len()
            && grids
                .iter()
                .zip(&self.shapes)
                .all(|(g, &(nu, nv))| g.nu == nu && g.nv == nv && g.positions.len() == nu * nv);
        if !same_shapes {
            return None;
        }
        let diag = diagonal(grids);
        let (positions, source) = merge(grids, self.options, diag);
        if source != self.source || positions.len() != self.vertices {
            return None;
        }
        Some(self.finish(grids, positions, diag))
    }

    /// Whether group `g` is turned over at these positions ([`Group::turned_over`], the members'
    /// volumes summed over their triangles).
    fn turns_over(&self, g: &Group, positions: &[[f32; 3]], diag: f64) -> bool {
        let apex = g.apex(positions);
        let volumes = g
            .members
            .iter()
            .map(|&k| signed_volume_about(positions, &self.tris[k], apex));
        g.turned_over(&self.relative, volumes, diag)
    }

    /// Orients the groups by their volumes at these positions, then the normals.
    fn finish(&self, grids: &[GridMesh], positions: Vec<[f32; 3]>, diag: f64) -> Welded {
        let mut group_flip: HashMap<usize, bool> = HashMap::new();
        for g in &self.groups {
            group_flip.insert(g.root, self.turns_over(g, &positions, diag));
        }
        let flipped: Vec<bool> = self
            .relative
            .iter()
            .map(|&(root, rel)| rel ^ group_flip.get(&root).copied().unwrap_or(false))
            .collect();

        // The triangles, each patch turned as decided (patches in parallel blocks).
        let total: usize = self.tris.iter().map(Vec::len).sum();
        let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(total);
        let mut parts = Vec::with_capacity(self.tris.len());
        {
            let mut rest = &mut triangles.spare_capacity_mut()[..total];
            let mut blocks = Vec::new();
            let mut start = 0;
            for (k, ts) in self.tris.iter().enumerate() {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(ts.len());
                rest = tail;
                for (src, dst) in ts.chunks(1 << 15).zip(head.chunks_mut(1 << 15)) {
                    blocks.push((flipped[k], src, dst));
                }
                parts.push(Part {
                    name: self.names[k].clone(),
                    triangles: start..start + ts.len(),
                });
                start += ts.len();
            }
            blocks.into_par_iter().for_each(|(flip, src, dst)| {
                for (&[a, b, c], d) in src.iter().zip(dst) {
                    d.write(if flip { [a, c, b] } else { [a, b, c] });
                }
            });
        }
        // SAFETY: the blocks tile the first `total` elements, each written in full.
        unsafe { triangles.set_len(total) };

        let normals = normals::vertex_normals(grids, &self.source, &positions, &flipped);
        Welded {
            mesh: TriMesh {
                positions,
                normals,
                uv: Vec::new(),
                triangles,
                parts,
            },
            source: self.source.clone(),
            flipped,
        }
    }
}

/// A triangle as written: turned over (`[a, c, b]`) when its patch is.
fn turned(t: [u32; 3], flip: bool) -> [u32; 3] {
    if flip {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// A slice written by several threads at distinct indices.
struct SharedSlice<T>(*mut T, usize);

// SAFETY: the pointer is only used through `write`, whose callers write distinct indices.
unsafe impl<T: Send> Sync for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    /// Writes element `i`.
    ///
    /// # Safety
    /// No other thread reads or writes element `i` meanwhile.
    unsafe fn write(&self, i: usize, x: T) {
        assert!(i < self.1, "index {i} within {}", self.1);
        // SAFETY: in bounds (checked); exclusive by the caller's promise.
        unsafe { *self.0.add(i) = x };
    }
}

/// `(b − a) × (c − a)` in f64.
pub fn facet_cross(p: &[[f32; 3]], t: [u32; 3]) -> [f64; 3] {
    // Corner by corner rather than through `t.map`, which the compiler does not always inline
    // in this hot loop (the same arithmetic).
    let at = |i: u32| {
        let q = p[i as usize];
        [q[0] as f64, q[1] as f64, q[2] as f64]
    };
    let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
}

/// `Σ a · (b × c) / 6` over the triangles: the enclosed volume of a closed, outward mesh.
fn signed_volume_of(p: &[[f32; 3]], tris: &[[u32; 3]]) -> f64 {
    signed_volume_about(p, tris, [0.0; 3])
}

/// `Σ (a − o) · ((b − o) × (c − o)) / 6`: the signed volume of the triangles closed by cones to
/// `o` (for a closed mesh, the enclosed volume whatever `o`).
fn signed_volume_about(p: &[[f32; 3]], tris: &[[u32; 3]], o: [f64; 3]) -> f64 {
    tris.iter().map(|&t| volume_term(p, t, o)).sum()
}

/// `(a − o) · ((b − o) × (c − o)) / 6` of one triangle.
#[inline(always)]
fn volume_term(p: &[[f32; 3]], t: [u32; 3], o: [f64; 3]) -> f64 {
    let at = |i: u32| {
        let q = p[i as usize];
        [q[0] as f64 - o[0], q[1] as f64 - o[1], q[2] as f64 - o[2]]
    };
    let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
    let bc = [
        b[1] * c[2] - b[2] * c[1],
        b[2] * c[0] - b[0] * c[2],
        b[0] * c[1] - b[1] * c[0],
    ];
    (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0
}

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

#[cfg(test)]
mod tests;
