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
                while top - q[1] > std::f64::consts::PI {
                    q[1] += TAU;
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
    /// `dropped` (by grid index, in grid order) and two triangles per cell that is not `removed`
    /// (cells indexed `i·cols + j`), written into `pm` (emptied first, its buffers reused); `id`
    /// becomes each grid vertex's index in it (`u32::MAX` for a dropped one).
    pub(crate) fn kept_grid(
        &self,
        dropped: impl Fn(usize) -> bool + Sync,
        removed: &[bool],
        pm: &mut ParamMesh,
        id: &mut Vec<u32>,
    ) {
        let (nu, nv, cols) = (self.nu, self.nv, self.cols());
        // Rows are independent once every row knows where its vertices and triangles start:
        // count per row, take prefix sums, then fill the rows in parallel.
        let kept_per_row: Vec<usize> = (0..nu)
            .into_par_iter()
            .map(|i| (0..nv).filter(|&j| !dropped(i * nv + j)).count())
            .collect();
        let cells_per_row: Vec<usize> = (0..nu - 1)
            .into_par_iter()
            .map(|i| {
                removed[i * cols..(i + 1) * cols]
                    .iter()
                    .filter(|&&r| !r)
                    .count()
            })
            .collect();
        let n_kept: usize = kept_per_row.iter().sum();
        let n_cells: usize = cells_per_row.iter().sum();
        pm.on_trim.clear();
        pm.uv.clear();
        pm.grid_source.clear();
        pm.triangles.clear();
        id.clear();
        id.resize(nu * nv, u32::MAX);
        pm.uv.resize(n_kept, [0.0; 2]);
        pm.grid_source.resize(n_kept, 0);
        {
            let mut rows = Vec::with_capacity(nu);
            let (mut uv_rest, mut src_rest) = (&mut pm.uv[..], &mut pm.grid_source[..]);
            let mut first = 0;
            for (i, id_row) in id.chunks_mut(nv).enumerate() {
                let (a, b) = std::mem::take(&mut uv_rest).split_at_mut(kept_per_row[i]);
                let (c, d) = std::mem::take(&mut src_rest).split_at_mut(kept_per_row[i]);
                rows.push((i, first, id_row, a, c));
                first += kept_per_row[i];
                (uv_rest, src_rest) = (b, d);
            }
            rows.into_par_iter()
                .for_each(|(i, first, id_row, uv_row, src_row)| {
                    let mut k = 0;
                    for (j, slot) in id_row.iter_mut().enumerate() {
                        if !dropped(i * nv + j) {
                            *slot = (first + k) as u32;
                            uv_row[k] = [self.u[i], self.v[j]];
                            src_row[k] = (i * nv + j) as u32;
                            k += 1;
                        }
                    }
                });
        }
        // Room for the re-meshed band as well, so the vector does not grow (and copy) later.
        pm.triangles.reserve(2 * n_cells + 4 * (nu + nv));
        pm.triangles.resize(2 * n_cells, [0u32; 3]);
        {
            let mut rows = Vec::with_capacity(nu - 1);
            let mut rest = &mut pm.triangles[..];
            for (i, &n) in cells_per_row.iter().enumerate() {
                let (a, b) = std::mem::take(&mut rest).split_at_mut(2 * n);
                rows.push((i, a));
                rest = b;
            }
            let id = &id[..];
            rows.into_par_iter().for_each(|(i, out)| {
                let mut k = 0;
                for j in 0..cols {
                    if removed[i * cols + j] {
                        continue;
                    }
                    let j1 = (j + 1) % nv;
                    let [a, b, c, d] = [
                        id[i * nv + j],
                        id[(i + 1) * nv + j],
                        id[(i + 1) * nv + j1],
                        id[i * nv + j1],
                    ];
                    out[k] = [a, b, c];
                    out[k + 1] = [a, c, d];
                    k += 2;
                }
            });
        }
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
    pub fn cols(&self) -> usize {
        if self.periodic {
            self.nv
        } else {
            self.nv - 1
        }
    }

    /// `(u, v)` in grid cells: `((u − u₀)/Δu, (v − v₀)/Δv)`.
    pub fn scaled(&self, p: [f64; 2]) -> [f64; 2] {
        [(p[0] - self.u0) / self.du, (p[1] - self.v0) / self.dv]
    }

    /// Grid column of an unwrapped column number.
    pub fn col(&self, j: i64) -> usize {
        j.rem_euclid(self.nv as i64) as usize
    }

    /// True for a corner on the domain's boundary (`u` ends, and `v` ends unless periodic).
    pub fn on_boundary(&self, i: usize, j: usize) -> bool {
        i == 0 || i + 1 == self.nu || (!self.periodic && (j == 0 || j + 1 == self.nv))
    }
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
    /// Per grid vertex: its index in the band's triangulation (general method).
    pub band: Vec<u32>,
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
        |(us, vs)| {
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
        },
    );
    if result.is_err() {
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
    let nv = vs.len();
    let (n, g) = (pm.uv.len(), pm.grid_source.len());
    let periodic = surface.v_domain().is_periodic();
    out.positions.clear();
    out.normals.clear();
    out.positions.resize(n, [0.0; 3]);
    out.normals.resize(n, [0.0; 3]);
    {
        let (grid_p, off_p) = out.positions.split_at_mut(g);
        let (grid_n, off_n) = out.normals.split_at_mut(g);
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
        let eval = surface.row_evaluator(vs);
        let eval = &*eval;
        rows.into_par_iter().with_min_len(4).for_each_init(
            || RowBuf::new(nv),
            |row, (first, u, p, q, s)| {
                eval.eval_row(u, row);
                for ((p, q), &s) in p.iter_mut().zip(q.iter_mut()).zip(s) {
                    let j = s as usize - first;
                    *p = [row.x[j] as f32, row.y[j] as f32, row.z[j] as f32];
                    *q = [row.nx[j] as f32, row.ny[j] as f32, row.nz[j] as f32];
                }
            },
        );
        off_p
            .par_iter_mut()
            .zip(off_n.par_iter_mut())
            .zip(pm.uv[g..].par_iter())
            .for_each(|((p, q), &[u, v])| {
                let v = if periodic { v.rem_euclid(TAU) } else { v };
                let d = surface.partials(u, v);
                let nn = d.normal();
                *p = [d.x.x as f32, d.x.y as f32, d.x.z as f32];
                *q = [nn.x as f32, nn.y as f32, nn.z as f32];
            });
    }
    out.uv.clear();
    out.uv
        .par_extend(pm.uv.par_iter().map(|p| [p[0] as f32, p[1] as f32]));
    out.triangles.clear();
    out.triangles.extend_from_slice(&pm.triangles);
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
