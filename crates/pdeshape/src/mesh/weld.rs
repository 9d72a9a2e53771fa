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

use super::{GridMesh, TriMesh};
use std::collections::HashMap;

#[path = "weld_frame.rs"]
mod weld_frame;
use std::hash::BuildHasherDefault;
pub use weld_frame::FrameWeld;

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
        let mut z = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        state.write_u64(z ^ (z >> 31));
    }
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

/// True for the vertices that may coincide with another: the grid's boundary and its collapsed
/// rows.
fn weld_candidates(g: &GridMesh) -> Vec<bool> {
    let (nu, nv) = (g.nu, g.nv);
    let mut c = vec![false; nu * nv];
    for i in 0..nu {
        let row = &g.positions[i * nv..(i + 1) * nv];
        let collapsed = row.iter().all(|p| p == &row[0]);
        let end_row = i == 0 || i + 1 == nu;
        for j in 0..nv {
            let end_col = !g.periodic_v && (j == 0 || j + 1 == nv);
            c[i * nv + j] = end_row || end_col || collapsed;
        }
    }
    c
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
pub fn weld_mapped(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> Welded {
    WeldTopology::new(grids, names, options).1
}

/// What welding a set of grids found that depends only on which vertices it joined: the
/// welded triangles of every grid, which grids meet along which edges (their relative
/// orientation), which groups of grids are closed and the rims of the open ones. Grids whose
/// vertices join alike (an animation's frames) are welded again with [`WeldTopology::weld`]
/// without building the edge maps again; the result equals [`weld_mapped`]'s bit for bit.
#[derive(Clone, Debug)]
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

#[derive(Clone, Debug)]
struct Group {
    root: usize,
    members: Vec<usize>,
    closed: bool,
    /// The first vertex of every rim edge (used once), in the order of the triangles.
    rim: Vec<u32>,
}

/// Bounding-box diagonal of every grid vertex.
fn diagonal(grids: &[GridMesh]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in grids.iter().flat_map(|g| &g.positions) {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c] as f64);
            hi[c] = hi[c].max(p[c] as f64);
        }
    }
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}

/// Joins the boundary vertices that coincide: the welded positions (first copy) and the welded
/// vertex of every grid vertex.
fn merge(grids: &[GridMesh], options: WeldOptions, diag: f64) -> (Vec<[f32; 3]>, Vec<Vec<u32>>) {
    let tol = if diag.is_finite() && diag > 0.0 {
        WELD_TOLERANCE * diag
    } else {
        f64::MIN_POSITIVE
    };
    let tol2 = tol * tol;
    let cell = |p: [f32; 3]| p.map(|x| (x as f64 / tol).floor() as i64);

    // Welded vertex of every grid vertex; representatives keep the first copy's position.
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut source: Vec<Vec<u32>> = Vec::with_capacity(grids.len());
    let mut buckets: HashMap<([i64; 3], usize), Vec<u32>, BuildHasherDefault<CellHasher>> =
        HashMap::default();
    for (k, g) in grids.iter().enumerate() {
        let group = if options.join_patches { 0 } else { k };
        let cand = weld_candidates(g);
        let mut map = Vec::with_capacity(g.positions.len());
        for (idx, &p) in g.positions.iter().enumerate() {
            if !cand[idx] {
                map.push(positions.len() as u32);
                positions.push(p);
                continue;
            }
            let c = cell(p);
            let mut found = None;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let key = ([c[0] + dx, c[1] + dy, c[2] + dz], group);
                        if let Some(list) = buckets.get(&key) {
                            for &w in list {
                                let q = positions[w as usize];
                                let d2: f64 =
                                    (0..3).map(|a| (p[a] as f64 - q[a] as f64).powi(2)).sum();
                                if d2 <= tol2 {
                                    found = Some(w);
                                    break 'search;
                                }
                            }
                        }
                    }
                }
            }
            let w = match found {
                Some(w) => w,
                None => {
                    let w = positions.len() as u32;
                    positions.push(p);
                    buckets.entry((c, group)).or_default().push(w);
                    w
                }
            };
            map.push(w);
        }
        source.push(map);
    }
    (positions, source)
}

impl WeldTopology {
    /// Welds `grids` (as [`weld_mapped`]) and keeps what the welding found.
    pub fn new(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> (Self, Welded) {
        let diag = diagonal(grids);
        let (positions, source) = merge(grids, options, diag);

        // Triangles per patch, re-indexed, without the ones welding collapsed.
        let tris: Vec<Vec<[u32; 3]>> = grids
            .iter()
            .zip(&source)
            .map(|(g, map)| {
                g.triangles()
                    .map(|t| t.map(|i| map[i as usize]))
                    .filter(|[a, b, c]| a != b && b != c && a != c)
                    .collect()
            })
            .collect();

        // Edges → (first patch, its direction, uses); patches meeting along an edge agree in
        // orientation when they run along it in opposite directions.
        let mut edges = edge_map::<(usize, bool, u32)>(tris.iter().map(Vec::len).sum());
        for (k, ts) in tris.iter().enumerate() {
            for t in ts {
                for e in 0..3 {
                    let (a, b) = (t[e], t[(e + 1) % 3]);
                    edges.entry(Edge::new(a, b)).or_insert((k, a < b, 0)).2 += 1;
                }
            }
        }
        let uses = |a: u32, b: u32| edges.get(&Edge::new(a, b)).map_or(0, |e| e.2);
        let mut parity = Parity::new(grids.len());
        for (k, ts) in tris.iter().enumerate() {
            for t in ts {
                for e in 0..3 {
                    let (a, b) = (t[e], t[(e + 1) % 3]);
                    if let Some(&(first, forward, 2)) = edges.get(&Edge::new(a, b)) {
                        if first != k {
                            // Same direction along the shared edge: opposite orientations.
                            parity.join(first, k, forward == (a < b));
                        }
                    }
                }
            }
        }

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
                tris[k]
                    .iter()
                    .all(|t| (0..3).all(|e| uses(t[e], t[(e + 1) % 3]) == 2))
            });
            let mut rim = Vec::new();
            if !closed {
                for &k in &members {
                    for t in &tris[k] {
                        for e in 0..3 {
                            let (a, b) = (t[e], t[(e + 1) % 3]);
                            if uses(a, b) == 1 {
                                rim.push(a);
                            }
                        }
                    }
                }
            }
            groups.push(Group {
                root,
                members,
                closed,
                rim,
            });
        }
        let topology = WeldTopology {
            options,
            names: (0..grids.len())
                .map(|k| {
                    names
                        .get(k)
                        .map(|s| s.to_string())
                        .unwrap_or_else(|| format!("patch{k}"))
                })
                .collect(),
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

    /// Orients the groups by their volumes at these positions, then the normals.
    fn finish(&self, grids: &[GridMesh], positions: Vec<[f32; 3]>, diag: f64) -> Welded {
        self.finish_new(grids, positions, diag)
    }
}

/// `(b − a) × (c − a)` in f64.
pub(crate) fn facet_cross(p: &[[f32; 3]], t: [u32; 3]) -> [f64; 3] {
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
    tris.iter()
        .map(|t| {
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
        })
        .sum()
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
    let mut uses = edge_map::<(u32, u32)>(mesh.triangles.len());
    let mut degenerate = 0;
    for &t in &mesh.triangles {
        let [a, b, c] = t;
        let f = facet_cross(&mesh.positions, t);
        if a == b || b == c || a == c || f == [0.0; 3] {
            degenerate += 1;
        }
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let entry = uses.entry(Edge::new(a, b)).or_default();
            if a < b {
                entry.0 += 1;
            } else {
                entry.1 += 1;
            }
        }
    }
    let mut r = MeshReport {
        boundary_edges: 0,
        nonmanifold_edges: 0,
        misoriented_edges: 0,
        degenerate_triangles: degenerate,
        signed_volume: signed_volume_of(&mesh.positions, &mesh.triangles),
    };
    for &(f, b) in uses.values() {
        match f + b {
            1 => r.boundary_edges += 1,
            2 if f != 1 => r.misoriented_edges += 1,
            2 => {}
            _ => r.nonmanifold_edges += 1,
        }
    }
    r
}
