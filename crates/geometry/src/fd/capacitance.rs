//! The four-sided problem for `N = 1, 2` by sine transforms and a capacitance matrix.
//!
//! The boundary values are known and each ghost node is fixed by its derivative condition in
//! terms of the interior node it mirrors: `(X₁ − X₋₁)/2 = h X_n` gives `X₋₁ = X₁ − 2h X_n`.
//! Eliminating both leaves a system `A x = b` in the `(nu − 1)(nv − 1)` interior nodes, where `b`
//! is the scaled source minus the stencil applied to the known parts (boundary values and the
//! `∓2h X_n` parts of the ghosts). `A` is the stencil restricted to the interior plus, at every
//! interior node next to the boundary, the mirrored ghost's coefficient on its diagonal.
//!
//! With `L_D = δ²_u + r δ²_v` (`r = (a h_u/h_v)²`) the 5-point operator with zero boundary
//! values, the 13-point stencil `(δ²_u + r δ²_v)²` restricted to the interior is
//! `L_D² + Σ_q L[·, q] L[q, ·]` over the boundary nodes `q`: a node `q = (0, j)` couples only to
//! `(1, j)`, with weight `1 · 1`, and `q = (i, 0)` only to `(i, 1)`, with `r · r`. The ghost
//! `(−1, j)` enters the row of `(1, j)` with the weight `1` of `δ⁴_u`, and `(i, −1)` that of
//! `(i, 1)` with `r²`. So
//!
//! `A = L_D² + P D Pᵀ`, with `D = 2` on the lines `i = 1, nu − 1` and `D = 2r²` on the lines
//! `j = 1, nv − 1` (a corner-adjacent node is on two lines and gets both):
//!
//! symmetric positive definite (`L_D²` is, `P D Pᵀ` is semi-definite). For `N = 1` there are no
//! ghosts and `A = L_D`. `L_D` is diagonalised by the 2-D sine transform `S = S_u ⊗ S_v`
//! (module `dst`), with eigenvalues `λ_kl = −4 sin²(πk/2nu) − 4r sin²(πl/2nv)`, so `M = L_D^N`
//! is inverted by two transforms. The low-rank term is handled by the Sherman–Morrison–Woodbury
//! identity: with `t = D Pᵀ x`, `A x = b` reads `M x = b − P t`, and `t` solves the capacitance
//! system `(D⁻¹ + Pᵀ M⁻¹ P) t = Pᵀ M⁻¹ b` of size `2(nu − 1) + 2(nv − 1)` (one unknown per node of
//! the four lines, a corner-adjacent node twice), symmetric positive definite. In the sine basis
//! along each line its blocks are known in closed form, and sums and differences of opposite
//! lines split it by parity into four independent blocks of about a quarter of its size (see
//! [`Capacitance`]), each factorised by dense Cholesky.
//!
//! One step of iterative refinement against `A` (the residual from the stencil itself) brings the
//! solution to the accuracy of a backward-stable solve of the assembled system; the result is the
//! sparse solver's discrete solution to rounding (`fd::tests::fast_four_sided_solver_equals_the_sparse_one`).

use super::dst::{transform_2d, Dst};
use super::{BoundaryCondition, FourSided, FourSidedNode, FourSidedProblem, SystemStats};
use crate::{Error, Result, Vec3};
use faer::linalg::solvers::Llt;
use faer::prelude::*;
use faer::Side;
use realfft::RealFftPlanner;

/// Node values `(nu + 1) × (nv + 1)` (row-major) and the size of the equivalent sparse system.
pub(super) fn solve(p: &FourSidedProblem<'_>, s: &FourSided) -> Result<(Vec<Vec3>, SystemStats)> {
    let n = p.order;
    debug_assert!(n == 1 || n == 2);
    let layout = &s.layout;
    let (nu, nv) = (p.nu, p.nv);
    let (mi, mj) = (nu - 1, nv - 1);
    // The known part of the extended grid: boundary values and the data parts of the ghosts;
    // the scaled source at the interior nodes.
    let mut known = vec![Vec3::zeros(); layout.len()];
    let mut f = vec![Vec3::zeros(); mi * mj];
    let mut nonzeros = 0;
    let mut unknowns = 0;
    s.walk(p, |i, j, node| {
        unknowns += 1;
        match node {
            FourSidedNode::Pde(v) => {
                nonzeros += s.stencil.len();
                f[(i as usize - 1) * mj + j as usize - 1] = v * s.scale;
            }
            FourSidedNode::Condition(BoundaryCondition {
                b,
                k,
                along_u,
                wide,
                val,
                h,
            }) => match (k, wide) {
                (0, _) => {
                    nonzeros += 1;
                    known[layout.index(i, j)] = val;
                }
                (1, false) => {
                    // (X(b+1) − X(b−1))/2 = h·val: the ghost at b + side is the mirrored node
                    // plus side·2h·val.
                    nonzeros += 2;
                    let side = if along_u { i - b } else { j - b };
                    known[layout.index(i, j)] = val * (2.0 * h * side as f64);
                }
                _ => {
                    return Err(Error::invalid(
                        "internal: the sine-transform solver handles N = 1, 2 only",
                    ))
                }
            },
            FourSidedNode::Unused => nonzeros += 1,
        }
        Ok(())
    })?;
    let stats = SystemStats { unknowns, nonzeros };

    // b = h^{2N} F − (stencil applied to the known part), component by component.
    let offsets: Vec<(isize, f64)> = s
        .stencil
        .iter()
        .map(|&(du, dv, c)| (du * layout.cols() as isize + dv, c))
        .collect();
    let mut b: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; mi * mj]);
    let mut ext = vec![0.0; layout.len()];
    for (c, bc) in b.iter_mut().enumerate() {
        for (e, k) in ext.iter_mut().zip(&known) {
            *e = k[c];
        }
        apply_stencil(
            layout.index(1, 1),
            layout.cols(),
            mi,
            mj,
            &offsets,
            &ext,
            bc,
        );
        for (x, fv) in bc.iter_mut().zip(&f) {
            *x = fv[c] - *x;
        }
    }

    let solver = Solver::new(n, p.a, s.hu, s.hv, nu, nv)?;
    let reduced = Reduced {
        order: n,
        mi,
        mj,
        cols: layout.cols(),
        first: layout.index(1, 1),
        len: layout.len(),
        offsets,
    };
    let mut x = b.clone();
    for xc in x.iter_mut() {
        solver.solve(xc);
    }
    // One step of iterative refinement against the reduced operator itself.
    let mut r = b;
    let mut ax = vec![0.0; mi * mj];
    for (rc, xc) in r.iter_mut().zip(&x) {
        reduced.apply(xc, &mut ax);
        for (ri, ai) in rc.iter_mut().zip(&ax) {
            *ri -= ai;
        }
        solver.solve(rc);
    }

    let mv = nv + 1;
    let mut nodes = vec![Vec3::zeros(); (nu + 1) * mv];
    for i in 0..=nu {
        for j in 0..mv {
            let node = &mut nodes[i * mv + j];
            if (1..nu).contains(&i) && (1..nv).contains(&j) {
                let q = (i - 1) * mj + j - 1;
                for c in 0..3 {
                    node[c] = x[c][q] + r[c][q];
                }
            } else {
                *node = known[layout.index(i as isize, j as isize)];
            }
            if !node.iter().all(|c| c.is_finite()) {
                return Err(Error::invalid(
                    "the difference system gave a non-finite solution (singular system)",
                ));
            }
        }
    }
    Ok((nodes, stats))
}

/// `out[(i−1) mj + j−1] = Σ c · ext[index(i, j) + offset]` over the interior nodes, where
/// `first` is the extended index of node `(1, 1)` and `cols` the extended row length.
fn apply_stencil(
    first: usize,
    cols: usize,
    mi: usize,
    mj: usize,
    offsets: &[(isize, f64)],
    ext: &[f64],
    out: &mut [f64],
) {
    for i in 0..mi {
        let base = first + i * cols;
        let row = &mut out[i * mj..(i + 1) * mj];
        row.fill(0.0);
        for &(off, c) in offsets {
            let start = (base as isize + off) as usize;
            for (o, e) in row.iter_mut().zip(&ext[start..start + mj]) {
                *o += c * e;
            }
        }
    }
}

/// The reduced operator `A` on the interior unknowns: the stencil with zero boundary values and
/// each ghost equal to the interior node it mirrors.
struct Reduced {
    order: usize,
    mi: usize,
    mj: usize,
    cols: usize,
    first: usize,
    len: usize,
    offsets: Vec<(isize, f64)>,
}

impl Reduced {
    fn apply(&self, x: &[f64], out: &mut [f64]) {
        let (mi, mj, cols, first) = (self.mi, self.mj, self.cols, self.first);
        let mut ext = vec![0.0; self.len];
        for i in 0..mi {
            ext[first + i * cols..first + i * cols + mj].copy_from_slice(&x[i * mj..(i + 1) * mj]);
        }
        if self.order == 2 {
            // Ghost rows i = −1, nu + 1 mirror the rows i = 1, nu − 1; ghost columns likewise.
            let at =
                |i: isize, j: isize| (first as isize + (i - 1) * cols as isize + j - 1) as usize;
            let (nu, nv) = (mi as isize + 1, mj as isize + 1);
            for j in 1..nv {
                ext[at(-1, j)] = ext[at(1, j)];
                ext[at(nu + 1, j)] = ext[at(nu - 1, j)];
            }
            for i in 1..nu {
                ext[at(i, -1)] = ext[at(i, 1)];
                ext[at(i, nv + 1)] = ext[at(i, nv - 1)];
            }
        }
        apply_stencil(first, cols, mi, mj, &self.offsets, &ext, out);
    }
}

/// `A⁻¹` by the sine transforms and (for `N = 2`) the capacitance matrix.
struct Solver {
    du: Dst,
    dv: Dst,
    /// `1/λ_klᴺ` in the transformed layout: row `l` (mode in `v`), column `k` (mode in `u`).
    inv_eig: Vec<f64>,
    capacitance: Option<Capacitance>,
}

/// The capacitance system in the sine basis of the four lines, split by parity into four
/// independent blocks, each with its Cholesky factor.
///
/// Write the unknowns of the lines `i = 1, nu − 1` (`U₀`, `U₁`) in the sine basis in `v`
/// (`τ_a = S_v t_{U_a}`) and those of the lines `j = 1, nv − 1` (`V₀`, `V₁`) in the sine basis in
/// `u`. With `s_k = S_u[1, k]`, `s'_l = S_v[1, l]` and `S_u[nu − 1, k] = (−1)^{k+1} s_k` (modes
/// `k = 1 …`), the blocks of `Pᵀ M⁻¹ P` become: between `U_a` and `U_b` the diagonal
/// `Σ_k (±1) s_k² / λ_klᴺ` in `l`, between `V_a` and `V_b` likewise in `k`, and between `U_a`
/// and `V_b` the matrix `(±1) s_k s'_l / λ_klᴺ` itself (no transform left). In the sums and
/// differences `(U₀ ± U₁)/√2`, `(V₀ ± V₁)/√2` the signs decouple the modes by parity: the `u`-even
/// combination of the `U` lines (`+`) meets only odd `k` (1-based), and so on, so the matrix
/// splits into four blocks `(p, q)`: the `U` combination `p` at the `v` modes `l` of parity `q`
/// with the `V` combination `q` at the `u` modes `k` of parity `p`,
///
/// `[ D_U⁻¹ + diag_l 2 Σ_{k∼p} s_k² / λ_klᴺ     2 s_k s'_l / λ_klᴺ                 ]`
/// `[ (sym.)                                 D_V⁻¹ + diag_k 2 Σ_{l∼q} s'_l² / λ_klᴺ ]`
///
/// each of about a quarter of the size (a sixteenth of the work of one dense factorisation).
struct Capacitance {
    mi: usize,
    mj: usize,
    /// Per block `(p, q)`: the `v` modes (0-based) of its `U` part, the `u` modes of its `V`
    /// part, and the factor.
    blocks: Vec<(Vec<usize>, Vec<usize>, Llt<f64>)>,
}

impl Solver {
    fn new(order: usize, a: f64, hu: f64, hv: f64, nu: usize, nv: usize) -> Result<Self> {
        let (mi, mj) = (nu - 1, nv - 1);
        let mut planner = RealFftPlanner::new();
        let du = Dst::new(mi, &mut planner);
        let dv = Dst::new(mj, &mut planner);
        let r = (a * hu / hv).powi(2);
        let pi = std::f64::consts::PI;
        let eu: Vec<f64> = (1..=mi)
            .map(|k| -4.0 * (pi * k as f64 / (2 * nu) as f64).sin().powi(2))
            .collect();
        let ev: Vec<f64> = (1..=mj)
            .map(|l| -4.0 * r * (pi * l as f64 / (2 * nv) as f64).sin().powi(2))
            .collect();
        let mut inv_eig = vec![0.0; mi * mj];
        for (l, row) in inv_eig.chunks_exact_mut(mi).enumerate() {
            for (k, x) in row.iter_mut().enumerate() {
                *x = 1.0 / (eu[k] + ev[l]).powi(order as i32);
            }
        }
        let capacitance = if order == 2 {
            Some(Capacitance::new(mi, mj, nu, nv, &inv_eig, r)?)
        } else {
            None
        };
        Ok(Solver {
            du,
            dv,
            inv_eig,
            capacitance,
        })
    }

    /// `M⁻¹ = S Λ⁻ᴺ S` in place on an interior array (`mi × mj`, row-major).
    fn apply_inverse(&self, x: &mut [f64], tmp: &mut [f64]) {
        transform_2d(&self.du, &self.dv, x, tmp);
        for (t, e) in tmp.iter_mut().zip(&self.inv_eig) {
            *t *= e;
        }
        transform_2d(&self.dv, &self.du, tmp, x);
    }

    /// `A⁻¹` in place.
    fn solve(&self, b: &mut [f64]) {
        let mut tmp = vec![0.0; b.len()];
        let Some(cap) = &self.capacitance else {
            self.apply_inverse(b, &mut tmp);
            return;
        };
        let mut y = b.to_vec();
        self.apply_inverse(&mut y, &mut tmp);
        cap.correct(&self.du, &self.dv, &y, b);
        self.apply_inverse(b, &mut tmp);
    }
}

impl Capacitance {
    fn new(mi: usize, mj: usize, nu: usize, nv: usize, inv_eig: &[f64], r: f64) -> Result<Self> {
        let pi = std::f64::consts::PI;
        let su: Vec<f64> = (1..=mi)
            .map(|k| (2.0 / nu as f64).sqrt() * (pi * k as f64 / nu as f64).sin())
            .collect();
        let sv: Vec<f64> = (1..=mj)
            .map(|l| (2.0 / nv as f64).sqrt() * (pi * l as f64 / nv as f64).sin())
            .collect();
        let mut blocks = Vec::with_capacity(4);
        for p in 0..2 {
            for q in 0..2 {
                let ls: Vec<usize> = (q..mj).step_by(2).collect();
                let ks: Vec<usize> = (p..mi).step_by(2).collect();
                let (nl, nk) = (ls.len(), ks.len());
                let mut c = Mat::<f64>::zeros(nl + nk, nl + nk);
                for (x, &l) in ls.iter().enumerate() {
                    let row = &inv_eig[l * mi..(l + 1) * mi];
                    let g: f64 = ks.iter().map(|&k| su[k] * su[k] * row[k]).sum();
                    c[(x, x)] = 0.5 + 2.0 * g;
                    for (y, &k) in ks.iter().enumerate() {
                        let b = 2.0 * su[k] * sv[l] * row[k];
                        c[(nl + y, x)] = b;
                        c[(x, nl + y)] = b;
                    }
                }
                for (y, &k) in ks.iter().enumerate() {
                    let h: f64 = ls
                        .iter()
                        .map(|&l| sv[l] * sv[l] * inv_eig[l * mi + k])
                        .sum();
                    c[(nl + y, nl + y)] = 0.5 / (r * r) + 2.0 * h;
                }
                let llt = c.llt(Side::Lower).map_err(|_| {
                    Error::invalid(
                        "the difference system is singular (capacitance matrix not definite)",
                    )
                })?;
                blocks.push((ls, ks, llt));
            }
        }
        Ok(Capacitance { mi, mj, blocks })
    }

    /// `b −= P t` where `t` solves the capacitance system `C t = Pᵀ y`.
    fn correct(&self, du: &Dst, dv: &Dst, y: &[f64], b: &mut [f64]) {
        let (mi, mj) = (self.mi, self.mj);
        // The lines i = 1, nu − 1 (rows) and j = 1, nv − 1 (columns), in the sine basis along
        // them.
        let mut u = vec![0.0; 2 * mj];
        u[..mj].copy_from_slice(&y[..mj]);
        u[mj..].copy_from_slice(&y[(mi - 1) * mj..]);
        let mut v = vec![0.0; 2 * mi];
        for i in 0..mi {
            v[i] = y[i * mj];
            v[mi + i] = y[i * mj + mj - 1];
        }
        dv.rows(&mut u);
        du.rows(&mut v);
        // Sums and differences: (x₀ ± x₁)/√2, an involution.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mix = |x: &mut [f64], m: usize| {
            for i in 0..m {
                let (a, c) = (x[i], x[m + i]);
                x[i] = (a + c) * h;
                x[m + i] = (a - c) * h;
            }
        };
        mix(&mut u, mj);
        mix(&mut v, mi);
        for (blk, (ls, ks, llt)) in self.blocks.iter().enumerate() {
            let (p, q) = (blk / 2, blk % 2);
            let mut t = Mat::<f64>::zeros(ls.len() + ks.len(), 1);
            for (x, &l) in ls.iter().enumerate() {
                t[(x, 0)] = u[p * mj + l];
            }
            for (x, &k) in ks.iter().enumerate() {
                t[(ls.len() + x, 0)] = v[q * mi + k];
            }
            llt.solve_in_place(t.as_mut());
            for (x, &l) in ls.iter().enumerate() {
                u[p * mj + l] = t[(x, 0)];
            }
            for (x, &k) in ks.iter().enumerate() {
                v[q * mi + k] = t[(ls.len() + x, 0)];
            }
        }
        mix(&mut u, mj);
        mix(&mut v, mi);
        dv.rows(&mut u);
        du.rows(&mut v);
        for j in 0..mj {
            b[j] -= u[j];
            b[(mi - 1) * mj + j] -= u[mj + j];
        }
        for i in 0..mi {
            b[i * mj] -= v[i];
            b[i * mj + mj - 1] -= v[mi + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{stencil, Layout};
    use super::*;

    /// The reduced operator `A` of an `nu × nv` grid as a dense matrix (column by column).
    fn dense(order: usize, a: f64, nu: usize, nv: usize) -> (Mat<f64>, Reduced) {
        let (mi, mj) = (nu - 1, nv - 1);
        let g = order - 1;
        let layout = Layout {
            nu,
            mv: nv + 1,
            gu: g,
            gv: g,
            periodic: false,
        };
        let (hu, hv) = (1.0 / nu as f64, 1.3 / nv as f64);
        let offsets = stencil(order, a, hu, hv)
            .iter()
            .map(|&(du, dv, c)| (du * layout.cols() as isize + dv, c))
            .collect();
        let red = Reduced {
            order,
            mi,
            mj,
            cols: layout.cols(),
            first: layout.index(1, 1),
            len: layout.len(),
            offsets,
        };
        let m = mi * mj;
        let mut out = Mat::<f64>::zeros(m, m);
        let mut e = vec![0.0; m];
        let mut col = vec![0.0; m];
        for q in 0..m {
            e[q] = 1.0;
            red.apply(&e, &mut col);
            for p in 0..m {
                out[(p, q)] = col[p];
            }
            e[q] = 0.0;
        }
        (out, red)
    }

    /// The eliminated system is exactly symmetric, equals `L_D² + P D Pᵀ` (the form the
    /// capacitance method inverts), and is positive definite.
    #[test]
    fn reduced_biharmonic_system_is_symmetric_positive_definite() {
        for (a, nu, nv) in [(1.0, 6, 6), (1.7, 7, 5), (0.4, 5, 9)] {
            let (m, _) = dense(2, a, nu, nv);
            let n = m.nrows();
            for p in 0..n {
                for q in 0..n {
                    assert_eq!(m[(p, q)], m[(q, p)], "a = {a}, {nu} × {nv}: ({p}, {q})");
                }
            }
            // L_D: the 5-point operator with zero boundary values.
            let (ld, _) = dense(1, a, nu, nv);
            let mut want = &ld * &ld;
            let (mi, mj) = (nu - 1, nv - 1);
            let r = (a * (1.0 / nu as f64) / (1.3 / nv as f64)).powi(2);
            for i in 0..mi {
                for j in 0..mj {
                    let mut d = 0.0;
                    if i == 0 || i == mi - 1 {
                        d += 2.0;
                    }
                    if j == 0 || j == mj - 1 {
                        d += 2.0 * r * r;
                    }
                    want[(i * mj + j, i * mj + j)] += d;
                }
            }
            let err = (&m - &want).norm_max();
            assert!(err <= 1e-13 * m.norm_max(), "a = {a}: {err:e}");
            assert!(m.llt(Side::Lower).is_ok(), "a = {a}: not definite");
        }
    }

    /// `Solver::solve` inverts the reduced operator: `A A⁻¹ b = b` to rounding, for `N = 1, 2`.
    #[test]
    fn capacitance_solver_inverts_the_reduced_operator() {
        for (order, a, nu, nv) in [
            (1, 1.0, 9, 7),
            (2, 1.0, 8, 8),
            (2, 1.7, 7, 5),
            (2, 0.4, 6, 11),
        ] {
            let (m, red) = dense(order, a, nu, nv);
            let solver =
                Solver::new(order, a, 1.0 / nu as f64, 1.3 / nv as f64, nu, nv).expect("definite");
            let len = m.nrows();
            let b: Vec<f64> = (0..len).map(|i| ((i * 13 + 5) as f64).sin()).collect();
            let mut x = b.clone();
            solver.solve(&mut x);
            let mut ax = vec![0.0; len];
            red.apply(&x, &mut ax);
            let err = ax
                .iter()
                .zip(&b)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max);
            // κ(A) ≤ (8 + 8r)²/λ_min² ≈ 1e4 here.
            assert!(
                err < 1e-10,
                "N = {order}, a = {a}, {nu} × {nv}: residual {err:e}"
            );
            let xn = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(xn > 1e-3);
        }
    }
}
