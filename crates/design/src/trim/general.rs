//! The general re-meshing: kept grid cells, and a constrained Delaunay triangulation of the band
//! between them and the holes.
//!
//! In grid cells (`s = (u − u₀)/Δu`, `t = (v − v₀)/Δv`): a grid vertex is *near* a hole if it is
//! inside it or within 1 of its sampled boundary, and *dropped* if inside or within ½ (vertices
//! on the domain's boundary are never dropped). A cell with a near corner is removed; the others
//! are kept with the grid's two triangles. The band (removed cells minus holes) is triangulated
//! from its remaining grid vertices and the curve samples, with the sides between removed and
//! kept cells (or the domain's boundary) and the chords of every curve as constraint edges. Every
//! triangle of the triangulation lies inside one region bounded by constraints; it is kept when
//! its centroid is in a removed cell and it is not inside a hole (the triangles on the left of a
//! hole's chords, the curves running counter-clockwise, and those reached from them without
//! crossing a constraint).

use super::{Frame, Loop, Loops, OnTrim, ParamMesh, Scratch};
use crate::{Error, Result};
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

const NEAR: u8 = 1;
const DROP: u8 = 2;

/// The shear of the triangulation's plane: a point `(s, t)` (in grid cells) is placed at
/// `(s, t + SHEAR·s)`. The band's grid vertices make squares, whose four corners lie on one
/// circle: every in-circle test of such a square is exactly zero, which the exact predicates
/// settle only by their slowest, exact stage. Sheared by 2⁻²⁰ the squares are parallelograms,
/// not cyclic, and the tests are decided by their first, floating-point stage. The shear is
/// exact on grid vertices (`t + s·2⁻²⁰` of integers below 2³² is representable), keeps grid
/// lines straight and every orientation, and moves a triangle's angles by about 2⁻²⁰ rad: the
/// triangulation is a Delaunay triangulation of the unsheared points up to that (a square's
/// diagonal, a tie there, is now always the one from `(s + 1, t)` to `(s, t + 1)`).
const SHEAR: f64 = 1.0 / (1u64 << 20) as f64;

#[derive(Clone, Copy)]
struct Vertex {
    /// The point in grid cells.
    st: [f64; 2],
    id: u32,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        Point2::new(self.st[0], self.st[1] + SHEAR * self.st[0])
    }
}

/// The squared distance from `p` to the segment `ab`.
fn dist2_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let f = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (x, y) = (p[0] - a[0] - f * dx, p[1] - a[1] - f * dy);
    x * x + y * y
}

/// Marks grid vertices near each hole (inside, or within 1 of its boundary) and those dropped,
/// into `flags` (one per grid vertex).
fn mark(frame: &Frame, loops: &[Loop], flags: &mut Vec<u8>) {
    let (nu, nv) = (frame.nu, frame.nv);
    flags.clear();
    flags.resize(nu * nv, 0);
    let jmax = if frame.periodic {
        i64::MAX
    } else {
        nv as i64 - 1
    };
    for l in loops {
        let n = l.st.len();
        // Inside: crossings of each grid row s = i with the polygon.
        let (lo, hi) = super::curve::bbox(&l.st);
        let mut xs = Vec::new();
        for i in (lo[0].ceil().max(0.0) as usize)..=(hi[0].floor() as usize).min(nu - 1) {
            let s = i as f64;
            xs.clear();
            for k in 0..n {
                let (a, b) = (l.st[k], l.st[(k + 1) % n]);
                if (a[0] > s) != (b[0] > s) {
                    xs.push(a[1] + (s - a[0]) * (b[1] - a[1]) / (b[0] - a[0]));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                let (j0, j1) = (pair[0].floor() as i64 + 1, pair[1].ceil() as i64 - 1);
                for j in j0..=j1 {
                    flags[i * nv + frame.col(j)] |= NEAR | DROP;
                }
            }
        }
        // Near the boundary.
        for k in 0..n {
            let (a, b) = (l.st[k], l.st[(k + 1) % n]);
            let i0 = (a[0].min(b[0]) - 1.0).floor().max(0.0) as usize;
            let i1 = ((a[0].max(b[0]) + 1.0).ceil() as usize).min(nu - 1);
            let j0 = ((a[1].min(b[1]) - 1.0).floor() as i64).max(0);
            let j1 = ((a[1].max(b[1]) + 1.0).ceil() as i64).min(jmax);
            for i in i0..=i1 {
                for j in j0..=j1 {
                    let d2 = dist2_to_segment([i as f64, j as f64], a, b);
                    if d2 < 1.0 {
                        let jc = frame.col(j);
                        let f = &mut flags[i * nv + jc];
                        *f |= NEAR;
                        if d2 < 0.25 && !frame.on_boundary(i, jc) {
                            *f |= DROP;
                        }
                    }
                }
            }
        }
    }
}

/// The re-meshed domain (see the module's documentation), into `pm` (its buffers and those of
/// `scratch` reused): [`grid`], then [`band`] appended.
pub(super) fn mesh(
    frame: &Frame,
    loops: &Loops,
    pm: &mut ParamMesh,
    scratch: &mut Scratch,
) -> Result<()> {
    let cells = grid(frame, loops, pm, scratch);
    let b = band(frame, loops, &cells, scratch, pm.uv.len() as u32)?;
    b.append_to(pm);
    Ok(())
}

/// The vertices and triangles the band adds to the grid part: its curve samples (numbered from
/// the grid part's vertex count on) and its triangles.
#[derive(Default)]
pub(super) struct Band {
    uv: Vec<[f64; 2]>,
    on_trim: Vec<OnTrim>,
    triangles: Vec<[u32; 3]>,
}

impl Band {
    /// Appends the band to the grid part it was made for.
    pub(super) fn append_to(self, pm: &mut ParamMesh) {
        pm.uv.extend_from_slice(&self.uv);
        pm.on_trim.extend_from_slice(&self.on_trim);
        pm.triangles.extend_from_slice(&self.triangles);
    }

    /// How many vertices it adds.
    pub(super) fn vertices(loops: &Loops) -> usize {
        loops.loops.iter().map(|l| l.st.len()).sum()
    }
}

/// The grid part of the general method into `pm`: marks the grid vertices near the holes (into
/// `scratch.flags`), removes the cells with a near corner (`scratch.removed`), and keeps the
/// rest of the grid ([`Frame::kept_grid`], `scratch.id`). Returns the removed cells, sorted.
pub(super) fn grid(
    frame: &Frame,
    loops: &Loops,
    pm: &mut ParamMesh,
    scratch: &mut Scratch,
) -> Vec<u32> {
    let (nu, nv, cols) = (frame.nu, frame.nv, frame.cols());
    let Scratch {
        flags, removed, id, ..
    } = scratch;
    mark(frame, &loops.loops, flags);
    let flags = &flags[..];
    // Removed cells: those with a near corner. The near vertices are few: scan the flags eight
    // at a time, and list the removed cells (sorted, they are in grid order).
    removed.clear();
    removed.resize((nu - 1) * cols, false);
    let mut cells: Vec<u32> = Vec::new();
    let mut remove_around = |g: usize| {
        let (i, j) = (g / nv, g % nv);
        for ci in [i.wrapping_sub(1), i] {
            if ci >= nu - 1 {
                continue;
            }
            for cj in [j as i64 - 1, j as i64] {
                if !frame.periodic && (cj < 0 || cj >= cols as i64) {
                    continue;
                }
                let c = ci * cols + frame.col(cj);
                if !removed[c] {
                    removed[c] = true;
                    cells.push(c as u32);
                }
            }
        }
    };
    const NEAR8: u64 = u64::from_ne_bytes([NEAR; 8]);
    for (b, chunk) in flags.chunks(8).enumerate() {
        let word = match <[u8; 8]>::try_from(chunk) {
            Ok(w) => u64::from_ne_bytes(w) & NEAR8,
            Err(_) => 1,
        };
        if word == 0 {
            continue;
        }
        for (k, &f) in chunk.iter().enumerate() {
            if f & NEAR != 0 {
                remove_around(8 * b + k);
            }
        }
    }
    cells.sort_unstable();
    // Vertices: grid vertices not dropped, then the curve samples; the band's triangles are
    // fewer than twice its vertices.
    let samples = Band::vertices(loops);
    let extra = [samples, 2 * (4 * cells.len() + samples)];
    frame.kept_grid(flags, DROP, removed, extra, pm, id);
    cells
}

/// The band of [`grid`]'s removed `cells` (its flags, removed cells and vertex indices in
/// `scratch`), triangulated; its first new vertex is `first_vertex` (the grid part's vertex
/// count).
pub(super) fn band(
    frame: &Frame,
    loops: &Loops,
    cells: &[u32],
    scratch: &mut Scratch,
    first_vertex: u32,
) -> Result<Band> {
    let (nu, nv, cols) = (frame.nu, frame.nv, frame.cols());
    let mut out = Band::default();
    if loops.loops.is_empty() {
        return Ok(out);
    }
    let Scratch {
        removed,
        id,
        band: cdt_index,
        ..
    } = scratch;
    let (removed, id) = (&removed[..], &id[..]);
    // Unwrapped column of a grid column: every band column lies in (cut, cut + nv).
    let cut = loops.cut;
    let unwrap = |j: usize| -> i64 {
        if frame.periodic {
            let j = j as i64;
            cut + (j - cut).rem_euclid(nv as i64)
        } else {
            j as i64
        }
    };
    // The band's grid vertices (the kept corners of removed cells, in the order the cells
    // list them) and each one's index in the triangulation, by grid index.
    let mut verts: Vec<Vertex> = Vec::new();
    cdt_index.clear();
    cdt_index.reserve(4 * cells.len());
    for &c in cells {
        let (i, j) = (c as usize / cols, c as usize % cols);
        for (ci, cj) in [(i, j), (i + 1, j), (i + 1, (j + 1) % nv), (i, (j + 1) % nv)] {
            let g = ci * nv + cj;
            if id[g] != u32::MAX {
                cdt_index.entry(g as u32).or_insert_with(|| {
                    verts.push(Vertex {
                        st: [ci as f64, unwrap(cj) as f64],
                        id: id[g],
                    });
                    verts.len() as u32 - 1
                });
            }
        }
    }
    let mut edges: Vec<[usize; 2]> = Vec::new();
    let cell_removed = |ci: i64, cj: i64| -> bool {
        if ci < 0 || ci >= nu as i64 - 1 {
            return false;
        }
        if !frame.periodic && (cj < 0 || cj >= cols as i64) {
            return false;
        }
        removed[ci as usize * cols + frame.col(cj)]
    };
    for &cell in cells {
        let (i, j) = (cell as usize / cols, cell as usize % cols);
        let (ii, jj) = (i as i64, j as i64);
        let c = |a: usize, b: usize| cdt_index[&((a * nv + b % nv) as u32)] as usize;
        if !cell_removed(ii - 1, jj) {
            edges.push([c(i, j), c(i, j + 1)]);
        }
        if !cell_removed(ii + 1, jj) {
            edges.push([c(i + 1, j), c(i + 1, j + 1)]);
        }
        if !cell_removed(ii, jj - 1) {
            edges.push([c(i, j), c(i + 1, j)]);
        }
        if !cell_removed(ii, jj + 1) {
            edges.push([c(i, j + 1), c(i + 1, j + 1)]);
        }
    }
    // Curve samples: vertices and chords.
    let mut sample_base = Vec::with_capacity(loops.loops.len());
    for l in &loops.loops {
        let first = verts.len();
        sample_base.push(first);
        for (k, (&p, (&t, &uv))) in l.st.iter().zip(l.t.iter().zip(&l.uv)).enumerate() {
            let vid = first_vertex + out.uv.len() as u32;
            out.uv.push(uv);
            out.on_trim.push(OnTrim {
                vertex: vid,
                curve: l.curve,
                t,
            });
            verts.push(Vertex { st: p, id: vid });
            let next = first + (k + 1) % l.st.len();
            edges.push([first + k, next]);
        }
    }
    let n_verts = verts.len();
    let mut conflict = None;
    let cdt = ConstrainedDelaunayTriangulation::<Vertex>::try_bulk_load_cdt(verts, edges, |e| {
        conflict.get_or_insert(e);
    })
    .map_err(|e| Error::invalid(format!("the trim curves cannot be triangulated: {e}")))?;
    if cdt.num_vertices() != n_verts || conflict.is_some() {
        return Err(Error::invalid(
            "the trim curves cross themselves or each other (or come closer than the grid \
             resolves); trims must be simple closed curves that do not meet",
        )
        .at("curves"));
    }
    // The faces inside the holes: to the left of every chord (the loops run counter-clockwise;
    // a directed edge's face is the one on its left), and those reached from them without
    // crossing a constraint edge (no vertex lies inside a hole, so these are bounded by chords).
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for (l, &first) in loops.loops.iter().zip(&sample_base) {
        let n = l.st.len();
        for k in 0..n {
            let (a, b) = (first + k, first + (k + 1) % n);
            let e = cdt.get_edge_from_neighbors(
                FixedVertexHandle::from_index(a),
                FixedVertexHandle::from_index(b),
            );
            if let Some(f) = e.and_then(|e| e.face().as_inner()) {
                if !std::mem::replace(&mut inside[f.fix().index()], true) {
                    stack.push(f);
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        for e in f.adjacent_edges() {
            if e.as_undirected().is_constraint_edge() {
                continue;
            }
            if let Some(g) = e.rev().face().as_inner() {
                if !std::mem::replace(&mut inside[g.fix().index()], true) {
                    stack.push(g);
                }
            }
        }
    }
    for f in cdt.inner_faces() {
        if inside[f.fix().index()] {
            continue;
        }
        let vs = f.vertices();
        let p = vs.map(|v| v.data().st);
        let c = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ];
        if !cell_removed(c[0].floor() as i64, c[1].floor() as i64) {
            continue;
        }
        out.triangles.push(vs.map(|v| v.data().id));
    }
    Ok(out)
}
