//! Welding the frames of an animation on the first frame's [`WeldTopology`]: the merge of
//! coincident vertices is not redone, only checked, and every buffer is reused from frame to
//! frame.
//!
//! What welding decides, and what of it may change from frame to frame:
//!
//! * **Which vertices join.** [`WeldTopology::weld`]'s full path merges the grids again and
//!   compares the vertex map. Here a frame keeps the first frame's map when (a) every copy of a
//!   joined vertex is a weld candidate of this frame (a boundary row or column, or a row that
//!   collapsed to one point, decided exactly as the merge decides it) and lies within the
//!   tolerance of its representative (the first copy) with a margin that keeps it inside the
//!   merge's search cells, and (b) no candidate lies within the tolerance of the representative
//!   of another welded vertex of its group. Then the merge finds, for every candidate, its own
//!   representative and no other, so it builds the same map; when the check fails the full path
//!   decides (it may still find the same map).
//! * **The orientation of each group** (its volume's sign, and for an open group whether the
//!   capped volume exceeds [`super::OPEN_VOLUME_FRACTION`]): decided every frame, since a morph
//!   may turn a surface inside out. From the second frame on, the streaming pass of
//!   `weld_frame_pass.rs` sums the volumes on its way in its own order and takes the decision
//!   where the rounding of the two orders cannot change it (otherwise the reference sum
//!   decides); when a group turns, the frame is finished by the reference pass
//!   ([`WeldTopology::finish_into`]).
//! * **Where the vertex normal falls back to the facet normals** (the mean of the copies
//!   vanishes or points against the triangles around the vertex): every frame, as the full path.
//!
//! The positions are gathered from the representatives, the normals summed over the copies and
//! the facets in the order of the full path, so a frame equals the full path's weld bit for bit.

use super::WELD_TOLERANCE;
use super::{facet_cross, WeldTopology, Welded};
use crate::mesh::{GridMesh, Part, TriMesh};

mod pass;
use pass::Pass;

/// Buffers of the orientation and normal pass, kept between frames.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    sums: Vec<[f64; 3]>,
    acc: Vec<[f64; 3]>,
    group_flip: Vec<bool>,
    /// The turns of the grids the triangles of the last mesh were built with.
    flipped: Vec<bool>,
}

/// A weld candidate of the current frame: its position, welded vertex and merge group.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    p: [f32; 3],
    w: u32,
    group: u32,
}

/// What the checks and the gather need of a topology, worked out once, and the buffers they
/// reuse.
#[derive(Clone, Debug, Default)]
struct Plan {
    /// Copies of every welded vertex.
    copies: Vec<u32>,
    /// The first copy of every welded vertex `(grid, index)`: its position is the vertex's.
    first: Vec<(u32, u32)>,
    /// `first` as runs `(grid, first index, length)` of consecutive indices of one grid, in the
    /// order of the welded vertices.
    runs: Vec<(u32, u32, u32)>,
    /// How many grid vertices belong to welded vertices with more than one copy.
    joined_copies: usize,
    /// Every welded vertex has a copy (always, for a topology `WeldTopology::new` made).
    complete: bool,
    candidates: Vec<Candidate>,
    /// Representatives (candidates that are the first copy of their vertex), sorted by `x`:
    /// `(x, index into candidates)`.
    reps: Vec<(f64, u32)>,
    scratch: Scratch,
    /// The layout of the streaming orientation and normal pass (made at the second frame).
    pass: Option<Pass>,
    /// Frames finished by that pass (the others by [`WeldTopology::finish_into`]).
    by_pass: usize,
}

/// A [`WeldTopology`] with what welding further frames on it reuses: see the module
/// documentation. Built once per animation (per worker), then [`FrameWeld::weld`] per frame.
#[derive(Clone, Debug)]
pub struct FrameWeld {
    topology: WeldTopology,
    plan: Plan,
    mesh: TriMesh,
    flipped: Vec<bool>,
}

impl FrameWeld {
    /// Prepares welding frames on `topology`.
    pub fn new(topology: WeldTopology) -> Self {
        let plan = Plan::new(&topology);
        FrameWeld {
            topology,
            plan,
            mesh: TriMesh::default(),
            flipped: Vec::new(),
        }
    }

    /// [`FrameWeld::new`] for the frames after a first one, welded as `first` by
    /// [`WeldTopology::new`] from `grids`: the streaming pass is made ready, and takes the first
    /// frame's turns as those of the next.
    pub fn after(topology: WeldTopology, first: &Welded, grids: &[GridMesh]) -> Self {
        let mut w = FrameWeld::new(topology);
        if first.flipped.len() == w.topology.relative.len() {
            w.plan.scratch.flipped = first.flipped.clone();
            let periodic = grids.iter().map(|g| g.periodic_v).collect();
            w.plan.pass = Some(Pass::new(&w.topology, periodic));
        }
        w
    }

    /// The topology frames are welded on.
    pub fn topology(&self) -> &WeldTopology {
        &self.topology
    }

    /// Welds `grids` into this welder's mesh ([`FrameWeld::mesh`]); the result equals
    /// [`WeldTopology::weld`]'s bit for bit. Returns false (and leaves the mesh empty) when
    /// the check of the vertex map fails: the grids' vertices may join otherwise, and
    /// [`WeldTopology::weld`] must decide.
    pub fn weld(&mut self, grids: &[GridMesh]) -> bool {
        let ok = self.plan.weld(&self.topology, grids, &mut self.mesh);
        if ok {
            self.flipped.clone_from(&self.plan.scratch.flipped);
        } else {
            self.mesh.positions.clear();
            self.mesh.normals.clear();
        }
        ok
    }

    /// The mesh of the last frame [`FrameWeld::weld`] accepted.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The grids turned over in the last frame.
    pub fn flipped(&self) -> &[bool] {
        &self.flipped
    }
}

impl Plan {
    fn new(t: &WeldTopology) -> Self {
        let mut count = vec![0u32; t.vertices];
        let mut first = vec![(u32::MAX, u32::MAX); t.vertices];
        for (k, map) in t.source.iter().enumerate() {
            for (idx, &w) in map.iter().enumerate() {
                let w = w as usize;
                if count[w] == 0 {
                    first[w] = (k as u32, idx as u32);
                }
                count[w] += 1;
            }
        }
        let joined_copies = count.iter().filter(|&&c| c > 1).map(|&c| c as usize).sum();
        let mut runs: Vec<(u32, u32, u32)> = Vec::new();
        for &(k, idx) in &first {
            match runs.last_mut() {
                Some((rk, from, len)) if *rk == k && *from + *len == idx => *len += 1,
                _ => runs.push((k, idx, 1)),
            }
        }
        Plan {
            runs,
            complete: count.iter().all(|&c| c > 0),
            copies: count,
            first,
            joined_copies,
            ..Plan::default()
        }
    }

    /// The check of the module documentation, the gather and the shared finish.
    fn weld(&mut self, t: &WeldTopology, grids: &[GridMesh], mesh: &mut TriMesh) -> bool {
        let same_shapes = grids.len() == t.shapes.len()
            && grids
                .iter()
                .zip(&t.shapes)
                .all(|(g, &(nu, nv))| g.nu == nu && g.nv == nv && g.positions.len() == nu * nv)
            && grids.iter().all(|g| g.normals.len() == g.positions.len());
        if !same_shapes || !self.complete {
            return false;
        }
        let (lo, hi) = bounds(grids);
        // `diagonal`'s number, from the same box.
        let diag = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt();
        let reach = (0..3).fold(0.0f64, |r, c| r.max(lo[c].abs()).max(hi[c].abs()));
        if !self.same_joins(t, grids, diag, reach) {
            return false;
        }
        mesh.positions.clear();
        for &(k, from, len) in &self.runs {
            let (from, len) = (from as usize, len as usize);
            mesh.positions
                .extend_from_slice(&grids[k as usize].positions[from..from + len]);
        }
        mesh.uv.clear();
        if self.finish_by_pass(t, grids, diag, mesh) {
            self.by_pass += 1;
        } else {
            t.finish_into(grids, diag, mesh, &mut self.scratch);
        }
        true
    }

    /// [`WeldTopology::finish_into`] by the streaming pass of `weld_frame_pass.rs`, taking the
    /// turns of the last frame (or those [`FrameWeld::after`] was given) as this frame's; false
    /// where the reference pass must decide (no turns known yet, a group turned, a number not
    /// finite).
    fn finish_by_pass(
        &mut self,
        t: &WeldTopology,
        grids: &[GridMesh],
        diag: f64,
        mesh: &mut TriMesh,
    ) -> bool {
        let flipped = &self.scratch.flipped;
        if flipped.len() != t.relative.len() {
            return false;
        }
        // The triangles of those turns (kept from the last frame, or made for the first).
        let ready = mesh.parts.len() == t.tris.len()
            && mesh.triangles.len() == t.tris.iter().map(Vec::len).sum::<usize>();
        if !ready {
            t.set_triangles(flipped, mesh);
        }
        if !self.pass.as_ref().is_some_and(|p| p.fits(grids)) {
            let periodic = grids.iter().map(|g| g.periodic_v).collect();
            self.pass = Some(Pass::new(t, periodic));
        }
        let pass = self.pass.as_mut().expect("made above");
        pass.finish(t, grids, diag, flipped, mesh)
    }

    /// True when the merge would join the grids' vertices as in the first frame (sufficient
    /// conditions, see the module documentation).
    /// `reach` is the largest absolute coordinate.
    fn same_joins(&mut self, t: &WeldTopology, grids: &[GridMesh], diag: f64, reach: f64) -> bool {
        if !(diag.is_finite() && diag > 0.0) {
            return false;
        }
        let tol = WELD_TOLERANCE * diag;
        let tol2 = tol * tol;
        // The merge's cells are `floor(x / tol)`: far from the origin their rounding could
        // matter; such designs take the full path.
        if reach.is_nan() || reach > tol * (1u64 << 40) as f64 {
            return false;
        }
        // The candidates of this frame, as `weld_candidates` finds them, and the
        // representatives among them (the first copy of their welded vertex).
        self.candidates.clear();
        self.reps.clear();
        let mut joined = 0usize;
        for (k, g) in grids.iter().enumerate() {
            let group = if t.options.join_patches { 0 } else { k as u32 };
            let map = &t.source[k];
            let (nu, nv) = (g.nu, g.nv);
            let (copies, first) = (&self.copies, &self.first);
            let (candidates, reps) = (&mut self.candidates, &mut self.reps);
            let mut push = |idx: usize| {
                let w = map[idx];
                if copies[w as usize] > 1 {
                    joined += 1;
                }
                let p = g.positions[idx];
                if first[w as usize] == (k as u32, idx as u32) {
                    reps.push((p[0] as f64, candidates.len() as u32));
                }
                candidates.push(Candidate { p, w, group });
            };
            for i in 0..nu {
                let row = &g.positions[i * nv..(i + 1) * nv];
                let end_row = i == 0 || i + 1 == nu;
                if end_row || row.iter().all(|p| p == &row[0]) {
                    (i * nv..(i + 1) * nv).for_each(&mut push);
                } else if !g.periodic_v {
                    push(i * nv);
                    if nv > 1 {
                        push(i * nv + nv - 1);
                    }
                }
            }
        }
        // (a) Every copy of a joined vertex is a candidate (a non-candidate is never joined)...
        if joined != self.joined_copies {
            return false;
        }
        // ... and lies within the tolerance of its representative, with a margin that keeps
        // it in the representative's cell or a neighbouring one.
        let inside = tol2 * (1.0 - 1e-3);
        for c in &self.candidates {
            if self.copies[c.w as usize] > 1 {
                let (k, idx) = self.first[c.w as usize];
                if dist2(c.p, grids[k as usize].positions[idx as usize]) > inside {
                    return false;
                }
            }
        }
        // (b) No candidate within the tolerance of another vertex's representative (of its
        // group): a window of 2·tol in x holds every representative within tol.
        self.reps.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for c in &self.candidates {
            let x = c.p[0] as f64;
            let from = self.reps.partition_point(|r| r.0 < x - 2.0 * tol);
            for &(rx, ri) in &self.reps[from..] {
                if rx > x + 2.0 * tol {
                    break;
                }
                let r = &self.candidates[ri as usize];
                if r.w != c.w && r.group == c.group && dist2(c.p, r.p) <= tol2 {
                    return false;
                }
            }
        }
        true
    }
}

/// The box around every grid vertex (as `diagonal` finds it: a coordinate that is NaN is passed
/// over). In f32, eight vertices a step; the f64 box of the f32 numbers is the same.
fn bounds(grids: &[GridMesh]) -> ([f64; 3], [f64; 3]) {
    const L: usize = 24;
    let mut lo = [f32::INFINITY; L];
    let mut hi = [f32::NEG_INFINITY; L];
    // `x < lo` is false for a NaN `x`: as `f64::min`, the NaN is passed over.
    let mut add = |l: usize, x: f32| {
        lo[l] = if x < lo[l] { x } else { lo[l] };
        hi[l] = if x > hi[l] { x } else { hi[l] };
    };
    for g in grids {
        let (chunks, rest) = g.positions.as_flattened().as_chunks::<L>();
        for ch in chunks {
            for (l, &x) in ch.iter().enumerate() {
                add(l, x);
            }
        }
        // `rest` holds whole vertices: lane `l` is coordinate `l % 3` throughout.
        for (l, &x) in rest.iter().enumerate() {
            add(l, x);
        }
    }
    let mut box_lo = [f64::INFINITY; 3];
    let mut box_hi = [f64::NEG_INFINITY; 3];
    for l in 0..L {
        box_lo[l % 3] = box_lo[l % 3].min(lo[l] as f64);
        box_hi[l % 3] = box_hi[l % 3].max(hi[l] as f64);
    }
    (box_lo, box_hi)
}

/// The squared distance of two mesh points in f64, computed as the merge computes it.
fn dist2(p: [f32; 3], q: [f32; 3]) -> f64 {
    (0..3).map(|a| (p[a] as f64 - q[a] as f64).powi(2)).sum()
}

impl WeldTopology {
    /// Orients the groups by their volumes at `mesh.positions`, then sets the triangles (kept
    /// from the last call when no grid turned otherwise), parts and normals.
    pub(super) fn finish_into(
        &self,
        grids: &[GridMesh],
        diag: f64,
        mesh: &mut TriMesh,
        sc: &mut Scratch,
    ) {
        let positions = &mesh.positions;
        sc.group_flip.clear();
        for g in &self.groups {
            sc.group_flip.push(self.turns_over(g, positions, diag));
        }
        let flip_of = |root: usize| {
            self.groups
                .iter()
                .position(|g| g.root == root)
                .is_some_and(|i| sc.group_flip[i])
        };
        let unchanged = sc.flipped.len() == self.relative.len()
            && self
                .relative
                .iter()
                .zip(&sc.flipped)
                .all(|(&(root, rel), &f)| rel ^ flip_of(root) == f)
            && mesh.parts.len() == self.tris.len()
            && mesh.triangles.len() == self.tris.iter().map(Vec::len).sum::<usize>();
        if !unchanged {
            let flipped: Vec<bool> = self
                .relative
                .iter()
                .map(|&(root, rel)| rel ^ flip_of(root))
                .collect();
            self.set_triangles(&flipped, mesh);
            sc.flipped = flipped;
        }
        let positions = &mesh.positions;

        // Normals: the mean of the welded copies, each turned with its patch.
        sc.sums.clear();
        sc.sums.resize(positions.len(), [0.0; 3]);
        for (k, g) in grids.iter().enumerate() {
            let s = if sc.flipped[k] { -1.0 } else { 1.0 };
            for (&w, n) in self.source[k].iter().zip(&g.normals) {
                let sum = &mut sc.sums[w as usize];
                for c in 0..3 {
                    sum[c] += s * n[c] as f64;
                }
            }
        }
        mesh.normals.clear();
        mesh.normals.extend(sc.sums.iter().map(|s| {
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            if len > 1e-3 {
                s.map(|c| (c / len) as f32)
            } else {
                [0.0; 3]
            }
        }));
        // Where the copies' normals cancel (a crease turned back on itself) or point against
        // the triangles around the vertex (the limit normal at a pole closing a patch at its end
        // u, whose sign is that of the other end's), the mean of the facet normals around the
        // vertex.
        sc.acc.clear();
        sc.acc.resize(positions.len(), [0.0; 3]);
        for &t in &mesh.triangles {
            let f = facet_cross(positions, t);
            for &i in &t {
                let a = &mut sc.acc[i as usize];
                for c in 0..3 {
                    a[c] += f[c];
                }
            }
        }
        for (n, a) in mesh.normals.iter_mut().zip(&sc.acc) {
            let dot: f64 = (0..3).map(|c| n[c] as f64 * a[c]).sum();
            if dot <= 0.0 {
                let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                if len > 0.0 {
                    *n = a.map(|c| (c / len) as f32);
                }
            }
        }
    }

    /// The triangles and parts of the mesh for grids turned as `flipped`.
    fn set_triangles(&self, flipped: &[bool], mesh: &mut TriMesh) {
        mesh.triangles.clear();
        mesh.parts.clear();
        for (k, ts) in self.tris.iter().enumerate() {
            let start = mesh.triangles.len();
            if flipped[k] {
                mesh.triangles.extend(ts.iter().map(|&[a, b, c]| [a, c, b]));
            } else {
                mesh.triangles.extend_from_slice(ts);
            }
            mesh.parts.push(Part {
                name: self.names[k].clone(),
                triangles: start..mesh.triangles.len(),
            });
        }
    }

    /// [`WeldTopology::weld`] by the check of the vertex map and the gather of this module.
    pub(super) fn weld_gathered(&self, grids: &[GridMesh]) -> Option<Welded> {
        let mut plan = Plan::new(self);
        let mut mesh = TriMesh::default();
        plan.weld(self, grids, &mut mesh).then(|| Welded {
            mesh,
            source: self.source.clone(),
            flipped: plan.scratch.flipped,
        })
    }
}

#[cfg(test)]
mod tests;
