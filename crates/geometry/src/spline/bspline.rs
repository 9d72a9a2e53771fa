//! Tensor-product B-spline surfaces.

use super::knots::{basis_derivatives, elevate, find_span, insert_knot, KnotRule};
use crate::surface::{normal_degenerates, Partials, RowBuf, RowEvaluator, Surface, VDomain};
use crate::{Error, Result, Vec3};

/// Tensor-product B-spline surface
/// `X(u, v) = Σ_{i<n_u} Σ_{j<n_v} N_{i,p}(u) N_{j,q}(v) P_{ij}`
/// with the Cox–de Boor bases of degrees `[p, q]` on the knot vectors `knots_u` (`n_u + p + 1`
/// values) and `knots_v` (`n_v + q + 1` values). Control points are stored row-major: `P_{ij}`
/// at index `i·n_v + j`, `i` along `u`, `j` along `v`.
///
/// The parameter domain is `[u_p, u_{n_u}] × [v_q, v_{n_v}]` of the knot vectors; outside it the
/// first/last polynomial pieces are extended. [`BSplineSurface::derivative`] works in these knot
/// parameters. The [`Surface`] implementation maps `u ∈ [0, 1]` linearly onto `[u_p, u_{n_u}]`
/// (so its `X_u` is `(u_{n_u} − u_p) ∂X/∂u`) and keeps `v` as it is, with
/// `VDomain::Interval(v_q, v_{n_v})`.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineSurface {
    degree: [usize; 2],
    counts: [usize; 2],
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    control: Vec<Vec3>,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for BSplineSurface {}

impl BSplineSurface {
    /// A surface of degrees `[p, q]` (any, `0` included) on the given full knot vectors, with
    /// `n_u = knots_u.len() − p − 1` by `n_v = knots_v.len() − q − 1` control points row-major.
    ///
    /// Requirements (else an error naming the value): at least `p + 1` and `q + 1` control
    /// points per direction, `control.len() = n_u·n_v`, finite control points, finite
    /// non-decreasing knots, a non-empty domain in each direction, no knot value repeated more
    /// than `degree + 1` times, and none strictly inside the domain more than `degree` times
    /// (the surface would break apart).
    pub fn new(
        degree: [usize; 2],
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        control: Vec<Vec3>,
    ) -> Result<Self> {
        let [p, q] = degree;
        for (name, p, knots) in [("knots_u", p, &knots_u), ("knots_v", q, &knots_v)] {
            KnotRule::Open {
                degree: p,
                count: None,
            }
            .check(knots)
            .map_err(|f| f.named(name))?;
        }
        let nu = knots_u.len() - p - 1;
        let nv = knots_v.len() - q - 1;
        if control.len() != nu * nv {
            return Err(Error::invalid(format!(
                "control: the knot vectors ask for {nu} × {nv} = {} control points, got {}",
                nu * nv,
                control.len()
            )));
        }
        check_control(&control, nv)?;
        Ok(BSplineSurface {
            degree,
            counts: [nu, nv],
            knots_u,
            knots_v,
            control,
        })
    }

    /// A surface with uniform clamped knot vectors on `[0, 1]` in both directions (`n − p`
    /// equal spans, end knots repeated `p + 1` times), control points row-major `n_u × n_v`.
    pub fn clamped_uniform(
        degree: [usize; 2],
        counts: [usize; 2],
        control: Vec<Vec3>,
    ) -> Result<Self> {
        let mk = |p: usize, n: usize, name: &str| -> Result<Vec<f64>> {
            if n <= p {
                return Err(Error::invalid(format!(
                    "{name}: degree {p} needs at least {p} + 1 control points, got {n}"
                )));
            }
            let spans = n - p;
            let mut k = vec![0.0; p + 1];
            k.extend((1..spans).map(|i| i as f64 / spans as f64));
            k.extend(std::iter::repeat_n(1.0, p + 1));
            Ok(k)
        };
        let ku = mk(degree[0], counts[0], "counts[0]")?;
        let kv = mk(degree[1], counts[1], "counts[1]")?;
        Self::new(degree, ku, kv, control)
    }

    /// Degrees `[p, q]`.
    pub fn degree(&self) -> [usize; 2] {
        self.degree
    }
    /// Control-point counts `[n_u, n_v]`.
    pub fn counts(&self) -> [usize; 2] {
        self.counts
    }
    /// The full knot vector in `u`.
    pub fn knots_u(&self) -> &[f64] {
        &self.knots_u
    }
    /// The full knot vector in `v`.
    pub fn knots_v(&self) -> &[f64] {
        &self.knots_v
    }
    /// Control points, row-major (`P_{ij}` at `i·n_v + j`).
    pub fn control(&self) -> &[Vec3] {
        &self.control
    }
    /// The domain `[[u_p, u_{n_u}], [v_q, v_{n_v}]]` in knot parameters.
    pub fn domain(&self) -> [[f64; 2]; 2] {
        let [p, q] = self.degree;
        let [nu, nv] = self.counts;
        [
            [self.knots_u[p], self.knots_u[nu]],
            [self.knots_v[q], self.knots_v[nv]],
        ]
    }

    /// `∂^{ku+kv} X / ∂u^{ku} ∂v^{kv}` at the knot parameters `(u, v)`, exact for every order
    /// (zero above the degree): `Σ_{ij} N⁽ᵏᵘ⁾_{i,p}(u) N⁽ᵏᵛ⁾_{j,q}(v) P_{ij}` over the
    /// `(p+1)(q+1)` B-splines alive on the spans of `u` and `v`.
    pub fn derivative(&self, u: f64, v: f64, ku: usize, kv: usize) -> Vec3 {
        let [p, q] = self.degree;
        if ku > p || kv > q {
            return Vec3::zeros();
        }
        let [nu, nv] = self.counts;
        let su = find_span(&self.knots_u, p, nu, &u);
        let sv = find_span(&self.knots_v, q, nv, &v);
        let mut bu = vec![0.0; (ku + 1) * (p + 1)];
        let mut bv = vec![0.0; (kv + 1) * (q + 1)];
        basis_derivatives(&self.knots_u, p, su, &u, ku, &mut bu);
        basis_derivatives(&self.knots_v, q, sv, &v, kv, &mut bv);
        let (bu, bv) = (&bu[ku * (p + 1)..], &bv[kv * (q + 1)..]);
        let mut x = Vec3::zeros();
        for (r, nu_r) in bu.iter().enumerate() {
            let row = (su - p + r) * nv + sv - q;
            let mut acc = Vec3::zeros();
            for (c, nv_c) in bv.iter().enumerate() {
                acc += self.control[row + c] * *nv_c;
            }
            x += acc * *nu_r;
        }
        x
    }

    /// `X` and its partials up to second order in knot parameters.
    fn partials_knot(&self, u: f64, v: f64) -> Partials {
        let [p, q] = self.degree;
        let [nu, nv] = self.counts;
        let su = find_span(&self.knots_u, p, nu, &u);
        let sv = find_span(&self.knots_v, q, nv, &v);
        let (wu, wv) = (p + 1, q + 1);
        let mut bu = vec![0.0; 3 * wu];
        let mut bv = vec![0.0; 3 * wv];
        basis_derivatives(&self.knots_u, p, su, &u, 2, &mut bu);
        basis_derivatives(&self.knots_v, q, sv, &v, 2, &mut bv);
        let mut out = Partials::default();
        for r in 0..wu {
            let row = (su - p + r) * nv + sv - q;
            // Curves in v through the row r: value, first, second derivative.
            let (mut c0, mut c1, mut c2) = (Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
            for c in 0..wv {
                let pt = self.control[row + c];
                c0 += pt * bv[c];
                c1 += pt * bv[wv + c];
                c2 += pt * bv[2 * wv + c];
            }
            let (n0, n1, n2) = (bu[r], bu[wu + r], bu[2 * wu + r]);
            out.x += c0 * n0;
            out.xu += c0 * n1;
            out.xuu += c0 * n2;
            out.xv += c1 * n0;
            out.xuv += c1 * n1;
            out.xvv += c2 * n0;
        }
        out
    }

    /// Boehm's knot insertion of `t` into `knots_u`: the same surface with one more row of
    /// control points. `t` must lie in the `u` domain and must not raise a knot's multiplicity
    /// beyond what [`BSplineSurface::new`] allows.
    pub fn insert_knot_u(&self, t: f64) -> Result<Self> {
        let [p, _] = self.degree;
        let [nu, nv] = self.counts;
        // Each column j is a curve in u with control P_{·j}: treat the nv·3 coordinates of a
        // row as one control value.
        let flat = flatten(&self.control);
        let (knots, ctrl) = insert_knot("knots_u", &self.knots_u, p, nu, &flat, 3 * nv, t)?;
        Self::new(self.degree, knots, self.knots_v.clone(), unflatten(&ctrl))
    }

    /// Boehm's knot insertion of `t` into `knots_v`: one more column of control points.
    pub fn insert_knot_v(&self, t: f64) -> Result<Self> {
        let t_self = self.transposed();
        let r = t_self.insert_knot_u(t).map_err(rename_uv)?;
        Ok(r.transposed())
    }

    /// Exact degree elevation `p → p + 1` in `u`: every distinct knot of the `u` domain gets one
    /// more copy (continuity is kept), and the surface does not change. Fails only if the
    /// result would be too large to index (never for realistic nets).
    pub fn elevate_degree_u(&self) -> Result<Self> {
        let [p, q] = self.degree;
        let [nu, nv] = self.counts;
        let flat = flatten(&self.control);
        let (knots, ctrl) = elevate(&self.knots_u, p, nu, &flat, 3 * nv);
        Self::new([p + 1, q], knots, self.knots_v.clone(), unflatten(&ctrl))
    }

    /// Exact degree elevation `q → q + 1` in `v`.
    pub fn elevate_degree_v(&self) -> Result<Self> {
        Ok(self
            .transposed()
            .elevate_degree_u()
            .map_err(rename_uv)?
            .transposed())
    }

    /// The same surface with `u` and `v` exchanged: `Y(v, u) = X(u, v)`.
    pub fn transposed(&self) -> Self {
        let [nu, nv] = self.counts;
        let mut control = Vec::with_capacity(nu * nv);
        for j in 0..nv {
            for i in 0..nu {
                control.push(self.control[i * nv + j]);
            }
        }
        BSplineSurface {
            degree: [self.degree[1], self.degree[0]],
            counts: [nv, nu],
            knots_u: self.knots_v.clone(),
            knots_v: self.knots_u.clone(),
            control,
        }
    }
}

/// Swaps `knots_u` and `knots_v` in a message produced on the transposed surface.
fn rename_uv(e: Error) -> Error {
    let s = e.to_string();
    let s = s
        .replace("knots_u", "\u{0}")
        .replace("knots_v", "knots_u")
        .replace('\u{0}', "knots_v");
    Error::invalid(s)
}

pub(crate) fn check_control(control: &[Vec3], nv: usize) -> Result<()> {
    for (k, p) in control.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(Error::invalid(format!(
                "control[{k}] (row {}, column {}) = ({}, {}, {}) is not finite",
                k / nv,
                k % nv,
                p.x,
                p.y,
                p.z
            )));
        }
    }
    Ok(())
}

fn flatten(c: &[Vec3]) -> Vec<f64> {
    c.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn unflatten(c: &[f64]) -> Vec<Vec3> {
    c.chunks_exact(3)
        .map(|w| Vec3::new(w[0], w[1], w[2]))
        .collect()
}

impl Surface for BSplineSurface {
    fn v_domain(&self) -> VDomain {
        let [_, [a, b]] = self.domain();
        VDomain::Interval(a, b)
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let [[a, b], _] = self.domain();
        let h = b - a;
        let mut p = self.partials_knot(a + h * u, v);
        p.xu *= h;
        p.xuv *= h;
        p.xuu *= h * h;
        p
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(BSplineRows::new(self, vs))
    }
}

/// Grid rows of a [`BSplineSurface`]: per-column tables of the `q + 1` values and first
/// derivatives of the `v` B-splines alive at `v_j` (and the span they start at). A row first
/// collapses the `u` direction, `R_l = Σ_r N_r(u) P_{s−p+r, l}` and `R'_l = Σ_r N'_r(u) P_{…}`
/// for every column of the net, then each vertex is four short sums over `q + 1` entries.
struct BSplineRows<'a> {
    surface: &'a BSplineSurface,
    /// First control column of the `v` span of grid column `j`.
    start: Vec<usize>,
    /// `basis[j·2(q+1) + k(q+1) + c] = N⁽ᵏ⁾_{start_j + c, q}(v_j)`, `k = 0, 1`.
    basis: Vec<f64>,
}

impl<'a> BSplineRows<'a> {
    fn new(surface: &'a BSplineSurface, vs: &'a [f64]) -> Self {
        let q = surface.degree[1];
        let nv = surface.counts[1];
        let w = q + 1;
        let mut start = Vec::with_capacity(vs.len());
        let mut basis = vec![0.0; vs.len() * 2 * w];
        for (j, &v) in vs.iter().enumerate() {
            let s = find_span(&surface.knots_v, q, nv, &v);
            start.push(s - q);
            basis_derivatives(
                &surface.knots_v,
                q,
                s,
                &v,
                1,
                &mut basis[j * 2 * w..(j + 1) * 2 * w],
            );
        }
        BSplineRows {
            surface,
            start,
            basis,
        }
    }
}

impl BSplineRows<'_> {
    /// The vertices of one row from the collapsed row net `r0` (values) and `r1` (`u`
    /// derivatives), `W = q + 1` known at compile time.
    #[inline(always)]
    fn columns<const W: usize>(&self, r0: &[f64], r1: &[f64], row: &mut RowBuf) {
        for j in 0..row.len() {
            let o = 3 * self.start[j];
            let m = &self.basis[j * 2 * W..(j + 1) * 2 * W];
            let (m_0, m_1) = m.split_at(W);
            let c0: &[f64] = &r0[o..o + 3 * W];
            let c1: &[f64] = &r1[o..o + 3 * W];
            let mut acc = [0.0; 12];
            for c in 0..W {
                let (m0, m1) = (m_0[c], m_1[c]);
                for k in 0..3 {
                    let (a, b) = (c0[3 * c + k], c1[3 * c + k]);
                    acc[k] += m0 * a;
                    acc[3 + k] += m0 * b;
                    acc[6 + k] += m1 * a;
                    acc[9 + k] += m1 * b;
                }
            }
            store_vertex(row, j, &acc);
        }
    }

    fn columns_any(&self, w: usize, r0: &[f64], r1: &[f64], row: &mut RowBuf) {
        for j in 0..row.len() {
            let o = 3 * self.start[j];
            let m = &self.basis[j * 2 * w..(j + 1) * 2 * w];
            let mut acc = [0.0; 12];
            for c in 0..w {
                let (m0, m1) = (m[c], m[w + c]);
                for k in 0..3 {
                    let (a, b) = (r0[o + 3 * c + k], r1[o + 3 * c + k]);
                    acc[k] += m0 * a;
                    acc[3 + k] += m0 * b;
                    acc[6 + k] += m1 * a;
                    acc[9 + k] += m1 * b;
                }
            }
            store_vertex(row, j, &acc);
        }
    }
}

/// Writes `X` and the unit normal of column `j` from `acc = [X, X_u, X_v, X_uv]`. The normal is
/// `X_u × X_v` normalised where that does not degenerate ([`normal_degenerates`], the rule of
/// [`Partials::normal`]) and its size is safely inside the range of `f64`, else
/// [`Partials::normal`] with its scaling and pole limits.
#[inline(always)]
fn store_vertex(row: &mut RowBuf, j: usize, acc: &[f64; 12]) {
    let (xu, xv) = (&acc[3..6], &acc[6..9]);
    let n = [
        xu[1] * xv[2] - xu[2] * xv[1],
        xu[2] * xv[0] - xu[0] * xv[2],
        xu[0] * xv[1] - xu[1] * xv[0],
    ];
    let s2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    let t = xu[0] * xu[0]
        + xu[1] * xu[1]
        + xu[2] * xu[2]
        + xv[0] * xv[0]
        + xv[1] * xv[1]
        + xv[2] * xv[2];
    (row.x[j], row.y[j], row.z[j]) = (acc[0], acc[1], acc[2]);
    let len = s2.sqrt();
    if !normal_degenerates(len, t) && s2 > 1e-290 && s2 < 1e290 {
        let r = 1.0 / len;
        (row.nx[j], row.ny[j], row.nz[j]) = (n[0] * r, n[1] * r, n[2] * r);
    } else {
        let p = Partials {
            x: Vec3::new(acc[0], acc[1], acc[2]),
            xu: Vec3::new(xu[0], xu[1], xu[2]),
            xv: Vec3::new(xv[0], xv[1], xv[2]),
            xuv: Vec3::new(acc[9], acc[10], acc[11]),
            ..Default::default()
        };
        let nn = p.normal();
        (row.nx[j], row.ny[j], row.nz[j]) = (nn.x, nn.y, nn.z);
    }
}

impl RowEvaluator for BSplineRows<'_> {
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        let s = self.surface;
        let [p, q] = s.degree;
        let [nu, nv] = s.counts;
        let [[a, b], _] = s.domain();
        let h = b - a;
        let t = a + h * u;
        let su = find_span(&s.knots_u, p, nu, &t);
        let mut bu = [0.0; 64];
        let mut bu_heap;
        let bu: &mut [f64] = if 2 * (p + 1) <= bu.len() {
            &mut bu[..2 * (p + 1)]
        } else {
            bu_heap = vec![0.0; 2 * (p + 1)];
            &mut bu_heap
        };
        basis_derivatives(&s.knots_u, p, su, &t, 1, bu);
        // R_l (value) and R'_l (u derivative, already scaled to the [0, 1] parameter).
        let mut scratch = std::mem::take(&mut row.scratch);
        scratch.clear();
        scratch.resize(6 * nv, 0.0);
        let (r0, r1) = scratch.split_at_mut(3 * nv);
        for r in 0..=p {
            let (n0, n1) = (bu[r], bu[p + 1 + r] * h);
            let base = (su - p + r) * nv;
            for (l, pt) in s.control[base..base + nv].iter().enumerate() {
                for c in 0..3 {
                    r0[3 * l + c] += n0 * pt[c];
                    r1[3 * l + c] += n1 * pt[c];
                }
            }
        }
        let (r0, r1) = (&*r0, &*r1);
        match q + 1 {
            1 => self.columns::<1>(r0, r1, row),
            2 => self.columns::<2>(r0, r1, row),
            3 => self.columns::<3>(r0, r1, row),
            4 => self.columns::<4>(r0, r1, row),
            5 => self.columns::<5>(r0, r1, row),
            6 => self.columns::<6>(r0, r1, row),
            w => self.columns_any(w, r0, r1, row),
        }
        row.scratch = scratch;
    }
}
