//! Trimmed patches (§5.2): closed curves in a patch's `(u, v)` parameter plane whose insides are
//! removed, and the re-meshing of what remains into an indexed triangle mesh.
//!
//! Three methods share one frame (the tessellation grid `nu × nv` of the untrimmed patch) and one
//! sampling of the trim curves (samples one grid cell apart, exactly on the curves):
//! - [`TrimMethod::Cdt`] (the default, any number of holes, concave curves): grid cells near a
//!   hole are removed and the band between the kept cells and the hole is triangulated by a
//!   constrained Delaunay triangulation (`spade`) of the band's grid vertices and the curve
//!   samples, the kept cells' sides and the curve's chords as constraints.
//! - [`TrimMethod::Bilinear`] (the book's first method, convex curves): the grid cells inside a
//!   bounding rectangle (on grid lines, one cell of margin) are removed and the region between the
//!   rectangle and the curve is split by the rays from the curve's centroid to the rectangle's
//!   corners into four regions, each meshed by linear interpolation between the rectangle's side
//!   and the curve's arc.
//! - [`TrimMethod::Laplace`] (the book's Eq. 5.3): the same boundary correspondence, with the
//!   interior points `M(s, θ)` solving `(∂²/∂s² + ∂²/∂θ²) M = 0` between the curve (`s = 0`) and
//!   the rectangle (`s = 1`), periodic in `θ`, solved mode by mode in closed form.
//!
//! Periodic `v`: a trim curve may cross the seam (its `v` values below 0 or above 2π); the
//! re-meshing runs in an unwrapped window whose cut avoids every hole.

mod book;
mod curve;
mod general;
mod quality;

pub use curve::{TrimCurve, MAX_DEGREE};
pub use quality::{quality, MeshQuality};

use crate::mesh::{self, GridMesh, Part, TriMesh};
use crate::surface::{ParameterDomain, RowBuf, Surface};
use crate::{Error, Result, TAU};
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// How the region around the holes is re-meshed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TrimMethod {
    /// Constrained Delaunay triangulation of the band around the holes (any curves).
    #[default]
    Cdt,
    /// The book's bilinear four-region mesh (convex curves, §5.2).
    Bilinear,
    /// The book's Laplace mapping of the annulus (Eq. 5.3; convex curves).
    Laplace,
}

impl TrimMethod {
    /// The name used in the design file.
    pub fn word(self) -> &'static str {
        match self {
            TrimMethod::Cdt => "cdt",
            TrimMethod::Bilinear => "bilinear",
            TrimMethod::Laplace => "laplace",
        }
    }
}

/// A vertex that lies on a trim curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnTrim {
    /// The vertex.
    pub vertex: u32,
    /// Index of the trim curve.
    pub curve: usize,
    /// Its parameter: the vertex's `(u, v)` is `curve.point(t)` exactly.
    pub t: f64,
}

/// The re-meshed parameter domain of a trimmed patch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamMesh {
    /// `(u, v)` of every vertex. The first `grid_source.len()` vertices are grid vertices.
    pub uv: Vec<[f64; 2]>,
    /// Grid index `i·nv + j` of each of the leading grid vertices.
    pub grid_source: Vec<u32>,
    /// Triangles, counter-clockwise in `(u, v)`: the kept grid cells' triangles first
    /// (`grid_triangles` of them), then the re-meshed ones.
    pub triangles: Vec<[u32; 3]>,
    /// Number of leading `triangles` taken unchanged from the kept grid cells.
    pub grid_triangles: usize,
    /// Every vertex on a trim curve.
    pub on_trim: Vec<OnTrim>,
}

impl ParamMesh {
    /// The re-meshed triangles (those not taken unchanged from the grid).
    pub fn remeshed(&self) -> &[[u32; 3]] {
        &self.triangles[self.grid_triangles..]
    }

    /// The `(u, v)` corners of triangle `k`; for a `periodic` `v`, corners more than π below
    /// the triangle's largest `v` are moved up by 2π so the triangle is the small one across
    /// the seam.
    pub fn triangle_uv(&self, k: usize, periodic: bool) -> [[f64; 2]; 3] {
        let mut p = self.triangles[k].map(|i| self.uv[i as usize]);
        if periodic {
            let top = p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max);
            for q in &mut p {
                // The number of turns up in one step (a loop of single turns takes forever for
                // a corner at v = 1e11, and never ends where 2π is below the spacing of floats).
                let turns = ((top - q[1] - std::f64::consts::PI) / TAU).ceil();
                if turns > 0.0 {
                    q[1] += turns * TAU;
                }
            }
        }
        p
    }
}

/// The tessellation grid in `(u, v)` and the scaling to grid cells.
pub(crate) struct Frame {
    pub nu: usize,
    pub nv: usize,
    pub periodic: bool,
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub u0: f64,
    pub du: f64,
    pub v0: f64,
    pub dv: f64,
}

impl Frame {
    /// The grid part of a trimmed mesh, shared by every method: the grid vertices that are not
    /// dropped (`flags[k] & dropped != 0`, by grid index; kept in grid order) and two triangles
    /// per cell that is not `removed`
    /// (cells indexed `i·cols + j`), written into `pm` (emptied first, its buffers reused, with
    /// room for `extra` more vertices and triangles, `[vertices, triangles]`, that the method
    /// adds); `id` becomes each grid vertex's index in it (`u32::MAX` for a dropped one).
    ///
    /// Rows are independent once every row knows where its vertices and triangles start: count
    /// per row, take prefix sums, then fill the rows in parallel, each straight into the
    /// uninitialised capacity of the buffers (no zero-fill first: a fresh buffer's pages are
    /// first touched once, by the thread that writes them).
    pub(crate) fn kept_grid(
        &self,
        flags: &[u8],
        dropped: u8,
        removed: &[bool],
        extra: [usize; 2],
        pm: &mut ParamMesh,
        id: &mut Vec<u32>,
    ) {
        let (nu, nv, cols) = (self.nu, self.nv, self.cols());
        let mask = dropped;
        let kept_per_row: Vec<usize> = flags
            .par_chunks(nv)
            .map(|row| nv - row.iter().filter(|&&f| f & mask != 0).count())
            .collect();
        let dropped = |k: usize| flags[k] & mask != 0;
        let cells_per_row: Vec<usize> = (0..nu - 1)
            .into_par_iter()
            .map(|i| {
                removed[i * cols..(i + 1) * cols]
                    .iter()
                    .filter(|&&r| !r)
                    .count()
            })
            .collect();
        pm.on_trim.clear();
        // Most rows lose no vertex and no cell: they skip the tests.
        let kept = |i: usize| {
            let all = kept_per_row[i] == nv;
            (0..nv).filter(move |&j| all || !dropped(i * nv + j))
        };
        let kept_per_row = &kept_per_row;
        let first: Vec<usize> = kept_per_row
            .iter()
            .scan(0, |acc, &n| {
                *acc += n;
                Some(*acc - n)
            })
            .collect();
        fill_rows(id, &vec![nv; nu], 0, |i| {
            let mut next = first[i] as u32;
            let all = kept_per_row[i] == nv;
            (0..nv).map(move |j| {
                if !all && dropped(i * nv + j) {
                    u32::MAX
                } else {
                    next += 1;
                    next - 1
                }
            })
        });
        fill_rows(&mut pm.uv, kept_per_row, extra[0], |i| {
            kept(i).map(move |j| [self.u[i], self.v[j]])
        });
        fill_rows(&mut pm.grid_source, kept_per_row, 0, |i| {
            kept(i).map(move |j| (i * nv + j) as u32)
        });
        let tris_per_row: Vec<usize> = cells_per_row.iter().map(|n| 2 * n).collect();
        let tris_per_row = &tris_per_row;
        let id = &id[..];
        fill_rows(&mut pm.triangles, tris_per_row, extra[1], |i| {
            let all = tris_per_row[i] == 2 * cols;
            (0..cols)
                .filter(move |&j| all || !removed[i * cols + j])
                .flat_map(move |j| {
                    let j1 = (j + 1) % nv;
                    let [a, b, c, d] = [
                        id[i * nv + j],
                        id[(i + 1) * nv + j],
                        id[(i + 1) * nv + j1],
                        id[i * nv + j1],
                    ];
                    [[a, b, c], [a, c, d]]
                })
        });
        pm.grid_triangles = pm.triangles.len();
    }

    fn new(domain: ParameterDomain, nu: usize, nv: usize) -> Result<Frame> {
        let (u, v) = mesh::grid_parameters_in(domain.u, domain.v, nu, nv)?;
        let periodic = domain.v.is_periodic();
        let vi = domain.v.interval();
        let dv = if periodic {
            TAU / nv as f64
        } else {
            vi.length() / (nv - 1) as f64
        };
        Ok(Frame {
            nu,
            nv,
            periodic,
            u,
            v,
            u0: domain.u.start,
            du: domain.u.length() / (nu - 1) as f64,
            v0: vi.start,
            dv,
        })
    }

    /// Columns of cells.
    pub(crate) fn cols(&self) -> usize {
        if self.periodic {
            self.nv
        } else {
            self.nv - 1
        }
    }

    /// `(u, v)` in grid cells: `((u − u₀)/Δu, (v − v₀)/Δv)`.
    pub(crate) fn scaled(&self, p: [f64; 2]) -> [f64; 2] {
        [(p[0] - self.u0) / self.du, (p[1] - self.v0) / self.dv]
    }

    /// Grid column of an unwrapped column number.
    pub(crate) fn col(&self, j: i64) -> usize {
        j.rem_euclid(self.nv as i64) as usize
    }

    /// True for a corner on the domain's boundary (`u` ends, and `v` ends unless periodic).
    pub(crate) fn on_boundary(&self, i: usize, j: usize) -> bool {
        i == 0 || i + 1 == self.nu || (!self.periodic && (j == 0 || j + 1 == self.nv))
    }
}

/// Empties `v` and fills it with `rows.iter().sum()` elements: row `i`, `rows[i]` elements,
/// is the first `rows[i]` items of `items(i)`, written straight into `v`'s uninitialised
/// capacity; the rows are written in parallel (no zero-fill first: each page of a fresh buffer
/// is first touched once, by the thread that writes it). An iterator that runs short panics
/// (before any element becomes part of `v`). Room for `extra` more elements is reserved.
fn fill_rows<T: Send, I: Iterator<Item = T>>(
    v: &mut Vec<T>,
    rows: &[usize],
    extra: usize,
    items: impl Fn(usize) -> I + Sync,
) {
    let n: usize = rows.iter().sum();
    v.clear();
    v.reserve(n + extra);
    let mut chunks = Vec::with_capacity(rows.len());
    let mut rest = &mut v.spare_capacity_mut()[..n];
    for (i, &len) in rows.iter().enumerate() {
        let (row, tail) = std::mem::take(&mut rest).split_at_mut(len);
        chunks.push((i, row));
        rest = tail;
    }
    chunks.into_par_iter().with_min_len(4).for_each(|(i, row)| {
        let mut it = items(i);
        for slot in row {
            slot.write(it.next().expect("a row of a trimmed mesh ran short"));
        }
    });
    // SAFETY: the first `n` slots of the capacity are the rows' slots (disjoint, covering
    // `0..n`), and every slot of every row was written above (a short row panicked instead).
    unsafe { v.set_len(n) };
}

/// One trim curve, sampled: parameters, points, and points in grid cells (unwrapped into the
/// window of the cut), counter-clockwise in `(u, v)`.
pub(crate) struct Loop {
    pub curve: usize,
    pub t: Vec<f64>,
    pub uv: Vec<[f64; 2]>,
    pub st: Vec<[f64; 2]>,
}

/// Samples every curve about one grid cell apart, orients it counter-clockwise, and places it
/// in the unwrapped window `(cut, cut + nv)` of a periodic `v` (the cut avoids every curve by
/// `margin` cells plus `margin_frac` of its extent in `v`). Refuses curves that leave the `u` range (or an interval `v`), a curve that
/// goes all around a periodic `v`, and curves that lie inside one another.
pub(crate) fn prepare(
    frame: &Frame,
    curves: &[TrimCurve],
    margin: f64,
    margin_frac: f64,
) -> Result<Loops> {
    let mut loops = Vec::with_capacity(curves.len());
    for (k, c) in curves.iter().enumerate() {
        c.validate().map_err(|e| e.at(&format!("curves[{k}]")))?;
        let (mut t, mut uv) = c.sample([frame.du, frame.dv], 1.0);
        let mut st: Vec<[f64; 2]> = uv.iter().map(|&p| frame.scaled(p)).collect();
        if curve::signed_area(&st) < 0.0 {
            t.reverse();
            uv.reverse();
            st.reverse();
        }
        let (lo, hi) = curve::bbox(&st);
        let inside_u = lo[0] > 0.0 && hi[0] < (frame.nu - 1) as f64;
        let inside_v = frame.periodic || (lo[1] > 0.0 && hi[1] < (frame.nv - 1) as f64);
        if !(inside_u && inside_v) {
            let (a, b) = curve::bbox(&uv);
            // Six decimals, or a short exponent form for huge values.
            let f = |x: f64| {
                if x.abs() < 1e9 {
                    format!("{x:.6}")
                } else {
                    format!("{x:.3e}")
                }
            };
            return Err(Error::invalid(format!(
                "the curve spans u ∈ [{}, {}], v ∈ [{}, {}]: it must lie inside the patch's \
                 parameter domain (a trim removes a hole, not an edge)",
                f(a[0]),
                f(b[0]),
                f(a[1]),
                f(b[1])
            ))
            .at(&format!("curves[{k}]")));
        }
        loops.push(Loop {
            curve: k,
            t,
            uv,
            st,
        });
    }
    let mut cut = 0;
    if frame.periodic && !loops.is_empty() {
        let nv = frame.nv as i64;
        let mut forbidden = vec![false; frame.nv];
        for l in &loops {
            let (lo, hi) = curve::bbox(&l.st);
            let margin = margin + margin_frac * (hi[1] - lo[1]);
            if hi[1] - lo[1] + 2.0 * margin + 2.0 >= frame.nv as f64 {
                return Err(Error::invalid(
                    "the curve goes (nearly) all around the periodic v direction: a trim must \
                     leave a hole, not cut the patch in two",
                )
                .at(&format!("curves[{}]", l.curve)));
            }
            let a = (lo[1] - margin - 1.0).floor() as i64;
            let b = (hi[1] + margin + 1.0).ceil() as i64;
            for j in a..=b {
                forbidden[j.rem_euclid(nv) as usize] = true;
            }
        }
        let Some(cut_col) = forbidden.iter().position(|f| !f) else {
            return Err(Error::invalid(
                "the trim curves together cover every v of the periodic patch; leave a strip \
                 of v free of holes",
            )
            .at("curves"));
        };
        cut = cut_col as i64;
        for l in &mut loops {
            let (lo, _) = curve::bbox(&l.st);
            let k = ((cut as f64 - lo[1]) / frame.nv as f64).floor() + 1.0;
            for p in &mut l.st {
                p[1] += k * frame.nv as f64;
            }
        }
    }
    for a in 0..loops.len() {
        for b in 0..loops.len() {
            if a != b && point_in_polygon(loops[a].st[0], &loops[b].st) {
                return Err(Error::invalid(format!(
                    "the curve lies inside curves[{}]: trims must not overlap",
                    loops[b].curve
                ))
                .at(&format!("curves[{}]", loops[a].curve)));
            }
        }
    }
    Ok(Loops { loops, cut })
}

/// The sampled curves and the cut of the unwrapped window (0 unless `v` is periodic).
pub(crate) struct Loops {
    pub loops: Vec<Loop>,
    pub cut: i64,
}

/// Even–odd ray casting along `+t`.
pub(crate) fn point_in_polygon(p: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let n = poly.len();
    let mut inside = false;
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        if (a[0] > p[0]) != (b[0] > p[0]) {
            let t = a[1] + (p[0] - a[0]) * (b[1] - a[1]) / (b[0] - a[0]);
            if t > p[1] {
                inside = !inside;
            }
        }
    }
    inside
}

/// The trimmed parameter domain of a surface with `domain` on the `nu × nv` tessellation grid:
/// the insides of `curves` removed, re-meshed by `method`.
pub fn trim_domain(
    domain: ParameterDomain,
    nu: usize,
    nv: usize,
    curves: &[TrimCurve],
    method: TrimMethod,
) -> Result<ParamMesh> {
    let mut pm = ParamMesh::default();
    trim_domain_into(
        domain,
        nu,
        nv,
        curves,
        method,
        &mut pm,
        &mut Scratch::default(),
    )?;
    Ok(pm)
}

/// Working buffers of the re-meshing, kept between re-meshes (one per grid vertex or cell).
#[derive(Clone, Debug, Default)]
pub(crate) struct Scratch {
    /// Per grid vertex: near / dropped flags (general method).
    pub flags: Vec<u8>,
    /// Per grid cell: removed.
    pub removed: Vec<bool>,
    /// Per grid vertex: its index in the parameter mesh (`u32::MAX` if dropped).
    pub id: Vec<u32>,
    /// Grid index → index in the band's triangulation, for the band's grid vertices (general
    /// method).
    pub band: HashMap<u32, u32, BuildHasherDefault<GridHasher>>,
}

/// A hasher of grid indices (`u32`s, each hashed once by `write_u32`): Fibonacci hashing, one
/// multiplication. The keys are not chosen by an adversary, and the map holds a few thousand.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct GridHasher(u64);

impl Hasher for GridHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }

    fn write_u32(&mut self, x: u32) {
        self.0 = (self.0 ^ u64::from(x)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

/// [`trim_domain`] into `pm`, reusing its buffers and those of `scratch`. On an error `pm` is
/// left empty.
fn trim_domain_into(
    domain: ParameterDomain,
    nu: usize,
    nv: usize,
    curves: &[TrimCurve],
    method: TrimMethod,
    pm: &mut ParamMesh,
    scratch: &mut Scratch,
) -> Result<()> {
    let result = Frame::new(domain, nu, nv).and_then(|frame| match method {
        TrimMethod::Cdt => general::mesh(&frame, &prepare(&frame, curves, 1.0, 0.0)?, pm, scratch),
        TrimMethod::Bilinear | TrimMethod::Laplace => book::mesh(
            &frame,
            &prepare(&frame, curves, 2.0, book::MARGIN)?,
            curves,
            method,
            pm,
            scratch,
        ),
    });
    if result.is_err() {
        pm.clear();
    }
    result
}

impl ParamMesh {
    /// Empties the mesh, keeping its buffers.
    fn clear(&mut self) {
        self.uv.clear();
        self.grid_source.clear();
        self.triangles.clear();
        self.grid_triangles = 0;
        self.on_trim.clear();
    }
}

/// The trimmed triangle mesh of `surface` on the `nu × nv` grid: [`trim_domain`], with grid
/// vertices taken from the surface's tessellation and the others evaluated exactly, as one part
/// called `name`. Also returns the parameter mesh.
pub fn trimmed_mesh(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
    curves: &[TrimCurve],
    method: TrimMethod,
    name: &str,
) -> Result<(TriMesh, ParamMesh)> {
    let mut out = TrimmedMesh::default();
    trimmed_mesh_into(surface, nu, nv, curves, method, name, &mut out)?;
    Ok((out.mesh, out.param))
}

/// A trimmed triangle mesh and its parameter mesh, with the working buffers of the re-meshing:
/// built again by [`trimmed_mesh_into`] (an edit of the trim curves or of the surface), it
/// writes into memory that is already mapped instead of allocating every vector anew.
#[derive(Clone, Debug, Default)]
pub struct TrimmedMesh {
    /// The triangle mesh (one part).
    pub mesh: TriMesh,
    /// Its parameter mesh: vertex `k` of `mesh` is `param.uv[k]`, the triangles are the same.
    pub param: ParamMesh,
    scratch: Scratch,
}

/// [`trimmed_mesh`] into `out`, reusing its buffers; the result is the same, bit for bit. The
/// mesh is built in place: each grid row is evaluated once (by the surface's row evaluator, as
/// [`mesh::tessellate`] does) and its kept vertices written straight to their places in the
/// triangle mesh; the vertices on the trim curves are evaluated exactly. On an error `out` is
/// left empty.
pub fn trimmed_mesh_into(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
    curves: &[TrimCurve],
    method: TrimMethod,
    name: &str,
    out: &mut TrimmedMesh,
) -> Result<()> {
    let TrimmedMesh {
        mesh,
        param,
        scratch,
    } = out;
    let result = mesh::grid_parameters_in(surface.u_range(), surface.v_domain(), nu, nv).and_then(
        |(us, vs)| match method {
            // The band's triangulation is serial: it runs beside the grid part of the mesh
            // (rows evaluated and written, in parallel), which does not depend on it.
            TrimMethod::Cdt => {
                let frame = Frame::new(surface.parameter_domain(), nu, nv)?;
                let loops = prepare(&frame, curves, 1.0, 0.0)?;
                let cells = general::grid(&frame, &loops, param, scratch);
                let extra = general::Band::vertices(&loops);
                let first = param.uv.len() as u32;
                let (band, ()) = rayon::join(
                    || general::band(&frame, &loops, &cells, scratch, first),
                    || fill_grid(surface, &us, &vs, param, extra, mesh),
                );
                let band = band?;
                let grid_triangles = param.triangles.len();
                band.append_to(param);
                fill_rest(surface, param, grid_triangles, name, mesh);
                Ok(())
            }
            TrimMethod::Bilinear | TrimMethod::Laplace => {
                trim_domain_into(
                    surface.parameter_domain(),
                    nu,
                    nv,
                    curves,
                    method,
                    param,
                    scratch,
                )?;
                fill_mesh(surface, &us, &vs, param, name, mesh);
                Ok(())
            }
        },
    );
    if result.is_err() {
        param.clear();
        mesh.positions.clear();
        mesh.normals.clear();
        mesh.uv.clear();
        mesh.triangles.clear();
        mesh.parts.clear();
    }
    result
}

/// The triangle mesh of `pm` on the grid `us × vs` into `out` (buffers reused): the grid
/// vertices row by row from the surface's row evaluator, the others from `X(u, v)`.
fn fill_mesh(
    surface: &dyn Surface,
    us: &[f64],
    vs: &[f64],
    pm: &ParamMesh,
    name: &str,
    out: &mut TriMesh,
) {
    let g = pm.grid_source.len();
    fill_grid(surface, us, vs, pm, pm.uv.len() - g, out);
    fill_rest(surface, pm, pm.grid_triangles, name, out);
}

/// The grid part of [`fill_mesh`]: `out` (emptied, its buffers reused, with room for `extra`
/// more vertices) gets the positions, normals and `(u, v)` of `pm`'s grid vertices and its
/// first `pm.grid_triangles` triangles. Positions and normals are written straight into the
/// uninitialised capacity, in parallel (no zero-fill first: each page of a fresh buffer is first
/// touched once, by the thread that writes it).
fn fill_grid(
    surface: &dyn Surface,
    us: &[f64],
    vs: &[f64],
    pm: &ParamMesh,
    extra: usize,
    out: &mut TriMesh,
) {
    let nv = vs.len();
    let g = pm.grid_source.len();
    out.positions.clear();
    out.normals.clear();
    out.positions.reserve(g + extra);
    out.normals.reserve(g + extra);
    {
        let grid_p = &mut out.positions.spare_capacity_mut()[..g];
        let grid_n = &mut out.normals.spare_capacity_mut()[..g];
        // The kept grid vertices are in grid order: row i's are those with a grid index in
        // [i·nv, (i+1)·nv).
        let mut rows = Vec::with_capacity(us.len());
        let (mut p_rest, mut n_rest, mut s_rest) = (grid_p, grid_n, &pm.grid_source[..]);
        for (i, &u) in us.iter().enumerate() {
            let end = ((i + 1) * nv) as u32;
            let k = s_rest.partition_point(|&s| s < end);
            let (p, pr) = std::mem::take(&mut p_rest).split_at_mut(k);
            let (q, nr) = std::mem::take(&mut n_rest).split_at_mut(k);
            let (s, sr) = s_rest.split_at(k);
            if k > 0 {
                rows.push((i * nv, u, p, q, s));
            }
            (p_rest, n_rest, s_rest) = (pr, nr, sr);
        }
        // Every grid index is below nu·nv: the rows hold all g slots.
        assert!(p_rest.is_empty() && n_rest.is_empty() && s_rest.is_empty());
        let eval = surface.row_evaluator(vs);
        let eval = &*eval;
        rows.into_par_iter().with_min_len(4).for_each_init(
            || RowBuf::new(nv),
            |row, (first, u, p, q, s)| {
                eval.eval_row(u, row);
                // p, q and s have one length: every slot is written.
                for ((p, q), &s) in p.iter_mut().zip(q.iter_mut()).zip(s) {
                    let j = s as usize - first;
                    p.write([row.x[j] as f32, row.y[j] as f32, row.z[j] as f32]);
                    q.write([row.nx[j] as f32, row.ny[j] as f32, row.nz[j] as f32]);
                }
            },
        );
    }
    // SAFETY: the first g slots of both buffers are the grid rows' slots (all of them, asserted
    // above), each written once (zips of slices of one length).
    unsafe {
        out.positions.set_len(g);
        out.normals.set_len(g);
    }
    out.uv.clear();
    out.uv.reserve(g + extra);
    out.uv
        .par_extend(pm.uv[..g].par_iter().map(|p| [p[0] as f32, p[1] as f32]));
    let t = pm.grid_triangles;
    out.triangles.clear();
    out.triangles.reserve(pm.triangles.capacity().max(t));
    out.triangles
        .par_extend(pm.triangles[..t].par_iter().copied());
}

/// The rest of [`fill_mesh`] after [`fill_grid`]: the vertices of `pm` after its grid vertices
/// (`X(u, v)` and its unit normal, evaluated exactly), the triangles from `from_triangle` on,
/// and the one part called `name`.
fn fill_rest(
    surface: &dyn Surface,
    pm: &ParamMesh,
    from_triangle: usize,
    name: &str,
    out: &mut TriMesh,
) {
    let periodic = surface.v_domain().is_periodic();
    let g = out.positions.len();
    let rest = &pm.uv[g..];
    let m = rest.len();
    out.positions.reserve(m);
    out.normals.reserve(m);
    out.positions.spare_capacity_mut()[..m]
        .par_iter_mut()
        .zip(out.normals.spare_capacity_mut()[..m].par_iter_mut())
        .zip(rest.par_iter())
        .for_each(|((p, q), &[u, v])| {
            let v = if periodic { v.rem_euclid(TAU) } else { v };
            let d = surface.partials(u, v);
            let nn = d.normal();
            p.write([d.x.x as f32, d.x.y as f32, d.x.z as f32]);
            q.write([nn.x as f32, nn.y as f32, nn.z as f32]);
        });
    // SAFETY: the m slots after the first g of both buffers were each written once above (a
    // zip of three slices of length m).
    unsafe {
        out.positions.set_len(g + m);
        out.normals.set_len(g + m);
    }
    out.uv
        .extend(pm.uv[g..].iter().map(|p| [p[0] as f32, p[1] as f32]));
    out.triangles
        .extend_from_slice(&pm.triangles[from_triangle..]);
    out.parts.clear();
    out.parts.push(Part {
        name: name.to_string(),
        triangles: 0..pm.triangles.len(),
    });
}

/// The triangle mesh of a parameter mesh: the grid's positions and normals for grid vertices,
/// `X(u, v)` and its unit normal for the others.
pub fn to_trimesh(surface: &dyn Surface, grid: &GridMesh, pm: &ParamMesh, name: &str) -> TriMesh {
    let g = pm.grid_source.len();
    let periodic = surface.v_domain().is_periodic();
    let (mut positions, mut normals): (Vec<[f32; 3]>, Vec<[f32; 3]>) = pm
        .grid_source
        .par_iter()
        .map(|&k| (grid.positions[k as usize], grid.normals[k as usize]))
        .unzip();
    let (off_p, off_n): (Vec<[f32; 3]>, Vec<[f32; 3]>) = pm.uv[g..]
        .par_iter()
        .map(|&[u, v]| {
            let v = if periodic { v.rem_euclid(TAU) } else { v };
            let p = surface.partials(u, v);
            let nn = p.normal();
            (
                [p.x.x as f32, p.x.y as f32, p.x.z as f32],
                [nn.x as f32, nn.y as f32, nn.z as f32],
            )
        })
        .unzip();
    positions.extend_from_slice(&off_p);
    normals.extend_from_slice(&off_n);
    TriMesh {
        positions,
        normals,
        uv: pm
            .uv
            .par_iter()
            .map(|p| [p[0] as f32, p[1] as f32])
            .collect(),
        triangles: pm.triangles.clone(),
        parts: vec![Part {
            name: name.to_string(),
            triangles: 0..pm.triangles.len(),
        }],
    }
}

#[cfg(test)]
mod tests;
