//! The constraint engine: a tensor-product B-spline surface with unknown control points is
//! substituted into a linear constant-coefficient PDE; on every knot span the residual is a
//! polynomial, and every one of its coefficients must vanish (seed 003 Lemmas 1–2, Algorithms
//! 1–2). The control points the user fixes move to the right-hand side; the rest is solved for.
//! Where freedom remains, the net minimising the operator's quadratic functional (seed 003 Eq. 1
//! and §2) is chosen.

use super::basis::{poly_derivative, poly_inner01, Direction, Span};
use super::linalg::{Affine, Mat, Solve};
use super::operator::{InnerTerm, Operator};
use super::scalar::Scalar;
use crate::{Error, Result, Vec3};

/// A control point in the engine's scalar.
pub type Point<T> = [T; 3];

/// The problem: spline space, operator and fixed control points.
#[derive(Clone, Debug)]
pub struct SplineProblem<T> {
    /// The spline space in `u`.
    pub u: Direction<T>,
    /// The spline space in `v`.
    pub v: Direction<T>,
    /// The PDE every span must satisfy.
    pub operator: Operator,
    /// `([i, j], P_ij)`: control point `i` along u, `j` along v, fixed by the user.
    pub fixed: Vec<([usize; 2], Point<T>)>,
}

/// Which coefficient of the residual an equation is: the coefficient of `s^a t^b` on the span
/// `[u_k, u_{k+1}] × [v_l, v_{l+1}]`, with local variables `s = (u − u_k)/h_u`,
/// `t = (v − v_l)/h_v`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EquationLabel {
    /// Knot span indices `[k, l]`: the span `[u_k, u_{k+1}] × [v_l, v_{l+1}]`.
    pub span: [usize; 2],
    /// Exponents `[a, b]` of the monomial `s^a t^b`.
    pub monomial: [usize; 2],
}

/// What the solve found.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveReport {
    /// Control points along u and v.
    pub counts: [usize; 2],
    /// Equations (non-zero residual coefficients over all spans).
    pub equations: usize,
    /// Rank of the equations in the unknown control points (per coordinate).
    pub rank: usize,
    /// Rank of the equations in all control points (the PDE alone).
    pub pde_rank: usize,
    /// Control points solved for.
    pub unknowns: usize,
    /// Fixed by the user.
    pub fixed: Vec<[usize; 2]>,
    /// Unknowns the PDE and the fixed points determine uniquely.
    pub determined: Vec<[usize; 2]>,
    /// Unknowns that stay free (chosen by the functional).
    pub free: Vec<[usize; 2]>,
    /// Dimension of the set of nets satisfying the PDE and the fixed points (per coordinate).
    pub freedom: usize,
    /// How the free part was chosen, one entry per stage used.
    pub chosen_by: Vec<String>,
}

/// A solved control net.
#[derive(Clone, Debug)]
pub struct SplineNet<T> {
    /// The spline space in `u`.
    pub u: Direction<T>,
    /// The spline space in `v`.
    pub v: Direction<T>,
    /// The PDE the net satisfies.
    pub operator: Operator,
    /// Row-major: index `i·n_v + j`, `i` along u.
    pub control: Vec<Point<T>>,
    /// What the solve found (ranks, determined and free control points).
    pub report: SolveReport,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for SplineNet<f64> {}

fn coef<T: Scalar>(x: f64) -> T {
    T::from_f64(x).unwrap_or_else(T::zero)
}

/// `(1/h)^k`.
fn inv_pow<T: Scalar>(h: &T, k: usize) -> T {
    let mut r = T::one();
    for _ in 0..k {
        r = r / h.clone();
    }
    r
}

/// The residual equations of the PDE on every span: a matrix over all control points (row-major
/// index `i·n_v + j`), the right-hand sides (one column per coordinate) and the labels. Rows
/// that are identically zero are left out.
pub fn assemble<T: Scalar>(
    u: &Direction<T>,
    v: &Direction<T>,
    op: &Operator,
) -> (Mat<T>, Mat<T>, Vec<EquationLabel>) {
    let (nu, nv) = (u.count(), v.count());
    let (p, q) = (u.degree, v.degree);
    let terms: Vec<(T, [usize; 2])> = op.terms().iter().map(|(w, o)| (coef(*w), *o)).collect();
    let g = op.rhs();
    let g: [T; 3] = [coef(g.x), coef(g.y), coef(g.z)];
    let su = u.spans();
    let sv = v.spans();
    // ders[span][order][r] = D^order of N_{k−p+r} in s, for the orders the terms use.
    let ders = |spans: &[Span<T>], axis: usize| -> Vec<Vec<Vec<Vec<T>>>> {
        let maxo = terms.iter().map(|(_, o)| o[axis]).max().unwrap_or(0);
        spans
            .iter()
            .map(|s| {
                (0..=maxo)
                    .map(|o| s.polys.iter().map(|pl| poly_derivative(pl, o)).collect())
                    .collect()
            })
            .collect()
    };
    let du = ders(&su, 0);
    let dv = ders(&sv, 1);
    let mut data: Vec<T> = Vec::new();
    let mut rhs: Vec<T> = Vec::new();
    let mut labels = Vec::new();
    let zero = T::zero();
    let get = |p: &Vec<T>, a: usize| -> T { p.get(a).cloned().unwrap_or_else(T::zero) };
    for (a_idx, spu) in su.iter().enumerate() {
        for (b_idx, spv) in sv.iter().enumerate() {
            let scales: Vec<T> = terms
                .iter()
                .map(|(w, o)| w.clone() * inv_pow(&spu.h, o[0]) * inv_pow(&spv.h, o[1]))
                .collect();
            for a in 0..=p {
                for b in 0..=q {
                    let mut row = vec![zero.clone(); nu * nv];
                    let mut any = false;
                    for r in 0..=p {
                        for t in 0..=q {
                            let mut acc = T::zero();
                            for ((_, o), sc) in terms.iter().zip(&scales) {
                                let x = get(&du[a_idx][o[0]][r], a);
                                if x.is_zero() {
                                    continue;
                                }
                                let y = get(&dv[b_idx][o[1]][t], b);
                                if y.is_zero() {
                                    continue;
                                }
                                acc = acc + sc.clone() * x * y;
                            }
                            if !acc.is_zero() {
                                any = true;
                                let i = spu.k - p + r;
                                let j = spv.k - q + t;
                                row[i * nv + j] = acc;
                            }
                        }
                    }
                    let rhs_row: [T; 3] = if a == 0 && b == 0 {
                        g.clone()
                    } else {
                        [T::zero(), T::zero(), T::zero()]
                    };
                    if any || rhs_row.iter().any(|x| !x.is_zero()) {
                        data.extend(row);
                        rhs.extend(rhs_row);
                        labels.push(EquationLabel {
                            span: [spu.k, spv.k],
                            monomial: [a, b],
                        });
                    }
                }
            }
        }
    }
    let rows = labels.len();
    (
        Mat {
            rows,
            cols: nu * nv,
            data,
        },
        Mat {
            rows,
            cols: 3,
            data: rhs,
        },
        labels,
    )
}

/// `∫ N_i^{(α)} N_k^{(β)} du` over the whole domain, `n × n`.
fn gram_1d<T: Scalar>(dir: &Direction<T>, spans: &[Span<T>], alpha: usize, beta: usize) -> Mat<T> {
    let n = dir.count();
    let p = dir.degree;
    let mut g: Mat<T> = Mat::zeros(n, n);
    for sp in spans {
        // d/du = (1/h) d/ds and du = h ds.
        let scale = inv_pow(&sp.h, alpha + beta) * sp.h.clone();
        let da: Vec<Vec<T>> = sp
            .polys
            .iter()
            .map(|pl| poly_derivative(pl, alpha))
            .collect();
        let db: Vec<Vec<T>> = sp
            .polys
            .iter()
            .map(|pl| poly_derivative(pl, beta))
            .collect();
        for r in 0..=p {
            for t in 0..=p {
                let x = poly_inner01(&da[r], &db[t]);
                if x.is_zero() {
                    continue;
                }
                let (i, k) = (sp.k - p + r, sp.k - p + t);
                let s = g.at(i, k).clone() + scale.clone() * x;
                *g.at_mut(i, k) = s;
            }
        }
    }
    g
}

/// The symmetric matrix `H` of `Σ w ∫ <∂^left x, ∂^right x>` over all control points (one
/// coordinate): `x^T H x` is the functional.
pub fn functional_matrix<T: Scalar>(
    u: &Direction<T>,
    v: &Direction<T>,
    terms: &[InnerTerm],
) -> Mat<T> {
    let (nu, nv) = (u.count(), v.count());
    let (su, sv) = (u.spans(), v.spans());
    let n = nu * nv;
    let mut h: Mat<T> = Mat::zeros(n, n);
    let half = T::one() / T::int(2);
    for term in terms {
        let w: T = coef::<T>(term.w) * half.clone();
        // Both orders of the inner product, so H is symmetric.
        for (l, r) in [(term.left, term.right), (term.right, term.left)] {
            let gu = gram_1d(u, &su, l[0], r[0]);
            let gv = gram_1d(v, &sv, l[1], r[1]);
            for i in 0..nu {
                for k in 0..nu {
                    let a = gu.at(i, k);
                    if a.is_zero() {
                        continue;
                    }
                    let wa = w.clone() * a.clone();
                    for j in 0..nv {
                        for m in 0..nv {
                            let b = gv.at(j, m);
                            if b.is_zero() {
                                continue;
                            }
                            let (row, col) = (i * nv + j, k * nv + m);
                            let s = h.at(row, col).clone() + wa.clone() * b.clone();
                            *h.at_mut(row, col) = s;
                        }
                    }
                }
            }
        }
    }
    h
}

/// Describes an equation for a message.
fn describe_label<T: Scalar>(u: &Direction<T>, v: &Direction<T>, l: &EquationLabel) -> String {
    let [k, m] = l.span;
    format!(
        "the coefficient of s^{} t^{} on the span u ∈ [{}, {}], v ∈ [{}, {}]",
        l.monomial[0],
        l.monomial[1],
        u.knots[k].to_text(),
        u.knots[k + 1].to_text(),
        v.knots[m].to_text(),
        v.knots[m + 1].to_text()
    )
}

/// Picks, among `x = x0 + N y`, the nets minimising `x^T H x` (with the fixed part `xf`): solves
/// `NᵀH_uu N y = −Nᵀ(H_uu x0 + H_uf xf)` and returns the new `x0` and the null space left.
/// `None` when the functional is not bounded below on the allowed nets; `Err` when a
/// decomposition fails to converge.
fn minimise<T: Solve>(
    h: &Mat<T>,
    unknown: &[usize],
    fixed: &[usize],
    xf: &Mat<T>,
    x0: &Mat<T>,
    null: &Mat<T>,
) -> Result<Option<(Mat<T>, Mat<T>)>> {
    let pick = |rows: &[usize], cols: &[usize]| {
        let mut m = Mat::zeros(rows.len(), cols.len());
        for (a, &r) in rows.iter().enumerate() {
            for (b, &c) in cols.iter().enumerate() {
                *m.at_mut(a, b) = h.at(r, c).clone();
            }
        }
        m
    };
    let huu = pick(unknown, unknown);
    let huf = pick(unknown, fixed);
    let nt = null.transpose();
    let m = nt.mul(&huu).mul(null);
    // Bounded below only if M is positive semidefinite (checked in f64: a sanity check of the
    // functional, not part of the exact arithmetic).
    {
        let k = m.rows;
        let mf = nalgebra::DMatrix::from_fn(k, k, |i, j| m.at(i, j).to_f64());
        let Some(eig) = crate::linalg::decomp::symmetric_eigenvalues(mf) else {
            return Ok(None);
        };
        let max = eig.amax();
        if eig.iter().any(|&l| l < -1e-9 * max) {
            return Ok(None);
        }
    }
    let mut g = huu.mul(x0);
    if !fixed.is_empty() {
        let gf = huf.mul(xf);
        for (a, b) in g.data.iter_mut().zip(gf.data) {
            *a = a.clone() + b;
        }
    }
    let mut r = nt.mul(&g);
    for x in r.data.iter_mut() {
        *x = -x.clone();
    }
    let aff: Affine<T> = T::affine(&m, &r).map_err(|e| e.at("spline"))?;
    let dx = null.mul(&aff.x0);
    let mut x1 = x0.clone();
    for (a, b) in x1.data.iter_mut().zip(dx.data) {
        *a = a.clone() + b;
    }
    Ok(Some((x1, null.mul(&aff.null))))
}

/// Solves the problem: the PDE residual vanishes on every span, the fixed points hold, and the
/// freedom left is spent minimising the operator's functional ([`Operator::functional`]; skipped,
/// and said so in the report, where it is not bounded below on the free nets), then the Dirichlet
/// energy, then the free part is set to the smallest solution (only left for nets with no fixed
/// point, where constants are free).
pub fn solve<T: Solve>(problem: &SplineProblem<T>) -> Result<SplineNet<T>> {
    let (u, v) = (&problem.u, &problem.v);
    u.check("u").map_err(|e| e.at("spline"))?;
    v.check("v").map_err(|e| e.at("spline"))?;
    problem
        .operator
        .check()
        .map_err(|e| e.at("spline.operator"))?;
    let (nu, nv) = (u.count(), v.count());
    let n = nu * nv;
    let mut is_fixed = vec![None; n];
    for (k, (ij, _)) in problem.fixed.iter().enumerate() {
        let [i, j] = *ij;
        if i >= nu || j >= nv {
            return Err(Error::invalid(format!(
                "control point [{i}, {j}] does not exist: the net has {nu} × {nv} points (indices from 0)"
            ))
            .at(&format!("spline.fixed[{k}].index")));
        }
        if let Some(prev) = is_fixed[i * nv + j] {
            return Err(Error::invalid(format!(
                "control point [{i}, {j}] is already fixed by spline.fixed[{prev}]"
            ))
            .at(&format!("spline.fixed[{k}].index")));
        }
        is_fixed[i * nv + j] = Some(k);
    }
    let (a, b, labels) = assemble(u, v, &problem.operator);
    let fixed: Vec<usize> = (0..n).filter(|&c| is_fixed[c].is_some()).collect();
    let unknown: Vec<usize> = (0..n).filter(|&c| is_fixed[c].is_none()).collect();
    let mut xf = Mat::zeros(fixed.len(), 3);
    for (a_i, &c) in fixed.iter().enumerate() {
        let k = is_fixed[c].unwrap_or(0);
        for d in 0..3 {
            *xf.at_mut(a_i, d) = problem.fixed[k].1[d].clone();
        }
    }
    // A_u x_u = B − A_f x_f.
    let mut au = Mat::zeros(a.rows, unknown.len());
    let mut rhs = b.clone();
    for r in 0..a.rows {
        for (col, &c) in unknown.iter().enumerate() {
            *au.at_mut(r, col) = a.at(r, c).clone();
        }
        for (fi, &c) in fixed.iter().enumerate() {
            let x = a.at(r, c);
            if x.is_zero() {
                continue;
            }
            for d in 0..3 {
                let s = rhs.at(r, d).clone() - x.clone() * xf.at(fi, d).clone();
                *rhs.at_mut(r, d) = s;
            }
        }
    }
    let pde_rank = T::affine(&a, &Mat::zeros(a.rows, 0))
        .map_err(|e| e.at("spline"))?
        .rank;
    let norms: Vec<f64> = (0..a.rows)
        .map(|i| {
            (0..a.cols)
                .map(|j| a.at(i, j).to_f64().powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let value_scale = xf.data.iter().fold(0.0f64, |m, x| m.max(x.to_f64().abs()));
    let aff = T::affine_scaled(&au, &rhs, &norms, value_scale).map_err(|e| e.at("spline"))?;
    if !aff.inconsistent.is_empty() {
        let shown: Vec<String> = aff
            .inconsistent
            .iter()
            .take(3)
            .map(|&r| describe_label(u, v, &labels[r]))
            .collect();
        let more = aff.inconsistent.len().saturating_sub(3);
        return Err(Error::invalid(format!(
            "the fixed control points contradict the PDE {}: {} equation(s) cannot hold, e.g. {}{}",
            problem.operator.describe(),
            aff.inconsistent.len(),
            shown.join("; "),
            if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            }
        ))
        .at("spline.fixed"));
    }
    let index = |c: usize| [c / nv, c % nv];
    let determined: Vec<[usize; 2]> = (0..unknown.len())
        .filter(|&r| T::row_is_zero(&aff.null, r))
        .map(|r| index(unknown[r]))
        .collect();
    let free: Vec<[usize; 2]> = (0..unknown.len())
        .filter(|&r| !T::row_is_zero(&aff.null, r))
        .map(|r| index(unknown[r]))
        .collect();
    let freedom = aff.null.cols;
    let (mut x, mut null) = (aff.x0, aff.null);
    let mut chosen_by = Vec::new();
    let stages: [(&str, Vec<InnerTerm>); 2] = [
        ("the operator's functional", problem.operator.functional()),
        (
            "the Dirichlet energy ∫|x_u|² + |x_v|²",
            Operator::dirichlet(),
        ),
    ];
    for (name, terms) in stages {
        if null.cols == 0 || terms.is_empty() {
            continue;
        }
        let h = functional_matrix(u, v, &terms);
        let before = null.cols;
        match minimise(&h, &unknown, &fixed, &xf, &x, &null)? {
            Some((x1, n1)) => {
                x = x1;
                null = n1;
                chosen_by.push(format!(
                    "{name} ({} of {before} free directions fixed)",
                    before - null.cols
                ));
            }
            None => chosen_by.push(format!(
                "{name} skipped: it is not bounded below on the {before} free directions"
            )),
        }
    }
    if null.cols > 0 {
        chosen_by.push(format!(
            "the smallest free part ({} directions left after the energies)",
            null.cols
        ));
    }
    let mut control: Vec<Point<T>> = vec![[T::zero(), T::zero(), T::zero()]; n];
    for (r, &c) in unknown.iter().enumerate() {
        control[c] = [x.at(r, 0).clone(), x.at(r, 1).clone(), x.at(r, 2).clone()];
    }
    for (fi, &c) in fixed.iter().enumerate() {
        control[c] = [
            xf.at(fi, 0).clone(),
            xf.at(fi, 1).clone(),
            xf.at(fi, 2).clone(),
        ];
    }
    Ok(SplineNet {
        u: u.clone(),
        v: v.clone(),
        operator: problem.operator.clone(),
        control,
        report: SolveReport {
            counts: [nu, nv],
            equations: a.rows,
            rank: aff.rank,
            pde_rank,
            unknowns: unknown.len(),
            fixed: fixed.iter().map(|&c| index(c)).collect(),
            determined,
            free,
            freedom,
            chosen_by,
        },
    })
}

impl<T: Scalar> SplineNet<T> {
    /// `∂^{ku+kv} x / ∂u^{ku} ∂v^{kv}` at `(u, v)` in knot parameters, by the pointwise
    /// Cox–de Boor derivative recursion (independent of the per-span polynomials of the solve).
    pub fn derivative(&self, u: &T, v: &T, ku: usize, kv: usize) -> Point<T> {
        let (i0, bu) = self.u.basis_derivatives_at(u, ku);
        let (j0, bv) = self.v.basis_derivatives_at(v, kv);
        let (p, q, nv) = (self.u.degree, self.v.degree, self.v.count());
        let mut out = [T::zero(), T::zero(), T::zero()];
        for r in 0..=p {
            let a = &bu[ku][r];
            if a.is_zero() {
                continue;
            }
            for t in 0..=q {
                let w = a.clone() * bv[kv][t].clone();
                if w.is_zero() {
                    continue;
                }
                let c = &self.control[(i0 - p + r) * nv + (j0 - q + t)];
                for d in 0..3 {
                    out[d] = out[d].clone() + w.clone() * c[d].clone();
                }
            }
        }
        out
    }

    /// The PDE residual `L x − g` at `(u, v)`.
    pub fn residual(&self, u: &T, v: &T) -> Point<T> {
        let g = self.operator.rhs();
        let mut out = [-coef::<T>(g.x), -coef::<T>(g.y), -coef::<T>(g.z)];
        for (w, o) in self.operator.terms() {
            let d = self.derivative(u, v, o[0], o[1]);
            let w: T = coef(w);
            for k in 0..3 {
                out[k] = out[k].clone() + w.clone() * d[k].clone();
            }
        }
        out
    }

    /// The net in `f64`.
    pub fn to_f64(&self) -> SplineNet<f64> {
        let dir = |d: &Direction<T>| Direction {
            degree: d.degree,
            knots: d.knots.iter().map(|x| x.to_f64()).collect(),
        };
        SplineNet {
            u: dir(&self.u),
            v: dir(&self.v),
            operator: self.operator.clone(),
            control: self
                .control
                .iter()
                .map(|p| [p[0].to_f64(), p[1].to_f64(), p[2].to_f64()])
                .collect(),
            report: self.report.clone(),
        }
    }

    /// Control point `(i, j)`.
    pub fn control_point(&self, i: usize, j: usize) -> &Point<T> {
        &self.control[i * self.v.count() + j]
    }
}

impl<T: Scalar> SplineNet<T> {
    /// The solved surface as a [`crate::spline::BSplineSurface`] (control points rounded to
    /// `f64` in exact mode): evaluation, meshes, knot insertion and degree elevation.
    pub fn to_bspline(&self) -> Result<crate::spline::BSplineSurface> {
        let f = self.to_f64();
        crate::spline::BSplineSurface::new(
            [f.u.degree, f.v.degree],
            f.u.knots.clone(),
            f.v.knots.clone(),
            f.control
                .iter()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
        )
    }
}

impl SplineNet<f64> {
    /// Control point `(i, j)` as a vector.
    pub fn vec3(&self, i: usize, j: usize) -> Vec3 {
        let p = self.control_point(i, j);
        Vec3::new(p[0], p[1], p[2])
    }
}
