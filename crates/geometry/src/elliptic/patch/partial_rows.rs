//! Rows of second partials of a [`PdePatch`] for quadrature: per-column tables of `cos nv_j`,
//! `sin nv_j` and of the remainder's `Δ_i(v_j)` and its first two derivatives, so a row is a
//! few multiply–adds per mode and quantity.

use super::PdePatch;
use crate::surface::{Partials, PartialsRows};
use crate::Vec3;
use std::borrow::Cow;

/// Quantities per vertex: `X, X_u, X_v, X_uu, X_uv, X_vv` (x, y, z each).
const Q: usize = 18;
/// Columns per block (the block's accumulators stay in L1).
const BLOCK: usize = 32;

/// The tables of `cos n v_j`, `sin n v_j` (`n = 1..=modes`) on the nodes `v_j` of a row, which
/// depend on the nodes only: patches evaluated on the same nodes (a patch and its tangents)
/// can share them ([`PdePatch::partials_rows_sharing`]), with the same values as their own.
#[derive(Clone, Debug)]
pub struct RowTables {
    vs: Vec<f64>,
    modes: usize,
    /// On the standard periodic grid `v_j = 2πj/nv` with `4 | nv` the tables cover the columns
    /// `0..=nv/4` only: with the sums split by the parity of `n`, `cos n(π ∓ v) = (−1)ⁿ cos nv`,
    /// `sin n(π ∓ v) = ∓(−1)ⁿ sin nv` and `v ↦ 2π − v` give the columns `nv/2 ∓ j` and `nv − j`
    /// from the even and odd cosine and sine sums of column `j`.
    symmetric: bool,
    /// Columns of the tables.
    cols: usize,
    /// `cos[(n−1)·cols + j] = cos(n v_j)`, likewise `sin`.
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl RowTables {
    /// The tables of modes `1..=modes` on the nodes `vs`.
    pub fn new(vs: &[f64], modes: usize) -> Self {
        let nv = vs.len();
        let symmetric = nv >= 8
            && nv.is_multiple_of(4)
            && vs
                .iter()
                .enumerate()
                .all(|(j, &v)| v == crate::TAU * j as f64 / nv as f64);
        let cols = if symmetric { nv / 4 + 1 } else { nv };
        let mut cos = vec![0.0; modes * cols];
        let mut sin = vec![0.0; modes * cols];
        for n in 1..=modes {
            for (j, &v) in vs.iter().take(cols).enumerate() {
                let (s, c) = (n as f64 * v).sin_cos();
                cos[(n - 1) * cols + j] = c;
                sin[(n - 1) * cols + j] = s;
            }
        }
        RowTables {
            vs: vs.to_vec(),
            modes,
            symmetric,
            cols,
            cos,
            sin,
        }
    }

    /// Whether the tables serve a patch of `modes` modes on the nodes `vs`.
    fn serve(&self, vs: &[f64], modes: usize) -> bool {
        self.modes >= modes && self.vs == vs
    }
}

pub(super) struct PdePartialRows<'a> {
    patch: &'a PdePatch,
    nv: usize,
    /// Whether the tables cover a quarter of the standard periodic grid (see [`RowTables`]).
    symmetric: bool,
    /// Columns of the tables.
    cols: usize,
    /// The patch's own tables, or shared ones of at least as many modes on the same nodes.
    tables: Cow<'a, RowTables>,
    /// `delta[i·nv + j] = [Δ_i, Δ_i', Δ_i''](v_j)`.
    delta: Vec<[Vec3; 3]>,
}

impl<'a> PdePartialRows<'a> {
    pub(super) fn new(patch: &'a PdePatch, vs: &[f64]) -> Self {
        Self::with_tables(patch, vs, None)
    }

    /// With `shared` tables when they serve the patch on `vs`, else its own.
    pub(super) fn with_tables(
        patch: &'a PdePatch,
        vs: &[f64],
        shared: Option<&'a RowTables>,
    ) -> Self {
        let m = patch.modes();
        let nv = vs.len();
        let tables = match shared {
            Some(t) if t.serve(vs, m) => Cow::Borrowed(t),
            _ => Cow::Owned(RowTables::new(vs, m)),
        };
        let (symmetric, cols) = (tables.symmetric, tables.cols);
        let mut delta = Vec::new();
        if let Some(r) = &patch.remainder {
            let k = patch.conditions.len();
            delta = Vec::with_capacity(k * nv);
            for i in 0..k {
                for &v in vs {
                    delta.push(r.delta(&patch.conditions, i, v, 2));
                }
            }
        }
        PdePartialRows {
            patch,
            nv,
            symmetric,
            cols,
            tables,
            delta,
        }
    }

    /// Cosine and sine coefficients of the 18 quantities of mode `n` at `u`: with
    /// `Aₙ⁽ᵈ⁾, Bₙ⁽ᵈ⁾` the d-th u-derivatives, `X = A cos + B sin`, `X_v = n(B cos − A sin)`,
    /// `X_vv = −n²(A cos + B sin)`.
    fn coefficients(&self, u: f64, alpha: &mut [f64], beta: &mut [f64]) {
        let mut o = [[0.0; 6]; 3];
        for (n, mode) in self.patch.modes.iter().enumerate() {
            for (d, od) in o.iter_mut().enumerate() {
                mode.eval(u, d, od);
            }
            let nf = n as f64;
            let (a, b) = (
                &mut alpha[n * Q..(n + 1) * Q],
                &mut beta[n * Q..(n + 1) * Q],
            );
            for k in 0..3 {
                let (a0, b0) = (o[0][k], o[0][3 + k]);
                let (a1, b1) = (o[1][k], o[1][3 + k]);
                let (a2, b2) = (o[2][k], o[2][3 + k]);
                a[k] = a0;
                b[k] = b0;
                a[3 + k] = a1;
                b[3 + k] = b1;
                a[6 + k] = nf * b0;
                b[6 + k] = -nf * a0;
                a[9 + k] = a2;
                b[9 + k] = b2;
                a[12 + k] = nf * b1;
                b[12 + k] = -nf * a1;
                a[15 + k] = -nf * nf * a0;
                b[15 + k] = -nf * nf * b0;
            }
        }
    }
}

/// The 18 quantities in the order of [`PdePartialRows::coefficients`] as [`Partials`].
#[inline(always)]
fn to_partials(v: &[f64; Q]) -> Partials {
    let v3 = |q: usize| Vec3::new(v[q], v[q + 1], v[q + 2]);
    Partials {
        x: v3(0),
        xu: v3(3),
        xv: v3(6),
        xuu: v3(9),
        xuv: v3(12),
        xvv: v3(15),
    }
}

impl PartialsRows for PdePartialRows<'_> {
    fn eval_row(&self, u: f64, out: &mut [Partials]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
            {
                // SAFETY: the processor has AVX2 and FMA (checked just above).
                unsafe { self.eval_row_avx2(u, out) };
                return;
            }
        }
        self.eval_row_generic::<false>(u, out);
    }
}

impl PdePartialRows<'_> {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_row_avx2(&self, u: f64, out: &mut [Partials]) {
        self.eval_row_generic::<true>(u, out);
    }

    /// The row: cosine sums `C_q(v_j) = Σₙ αₙ,q cos nv_j` and sine sums `S_q(v_j)` (each split
    /// into even and odd `n`) per block of table columns, then `out[j] = C + S` and, on the
    /// symmetric grid, the three mirrored columns; then the remainder. `FMA` selects fused
    /// multiply–adds where the processor has them.
    #[inline(always)]
    fn eval_row_generic<const FMA: bool>(&self, u: f64, out: &mut [Partials]) {
        let madd = |a: f64, x: f64, acc: f64| if FMA { a.mul_add(x, acc) } else { acc + a * x };
        let m = self.patch.modes();
        let nv = self.nv.min(out.len());
        let mut alpha = vec![0.0; (m + 1) * Q];
        let mut beta = vec![0.0; (m + 1) * Q];
        self.coefficients(u, &mut alpha, &mut beta);
        // [parity][q][column]
        let mut cacc = [[[0.0f64; BLOCK]; Q]; 2];
        let mut sacc = [[[0.0f64; BLOCK]; Q]; 2];
        let symmetric = self.symmetric && nv == self.nv;
        let cols = if symmetric { self.cols } else { nv };
        let quarter = nv / 4;
        let mut j0 = 0;
        while j0 < cols {
            let len = BLOCK.min(cols - j0);
            // Mode 0 (even, constant in v).
            for q in 0..Q {
                cacc[0][q][..len].fill(alpha[q]);
                cacc[1][q][..len].fill(0.0);
                sacc[0][q][..len].fill(0.0);
                sacc[1][q][..len].fill(0.0);
            }
            for n in 1..=m {
                let at = (n - 1) * self.cols + j0;
                let c = &self.tables.cos[at..at + len];
                let s = &self.tables.sin[at..at + len];
                let p = n % 2;
                for q in 0..Q {
                    let (an, bn) = (alpha[n * Q + q], beta[n * Q + q]);
                    for (a, x) in cacc[p][q][..len].iter_mut().zip(c) {
                        *a = madd(an, *x, *a);
                    }
                    for (a, x) in sacc[p][q][..len].iter_mut().zip(s) {
                        *a = madd(bn, *x, *a);
                    }
                }
            }
            for t in 0..len {
                let j = j0 + t;
                // Columns j, nv − j, nv/2 − j, nv/2 + j: Ce ± Co ± Se ± So.
                let mut four = [[0.0f64; Q]; 4];
                for q in 0..Q {
                    let (ce, co) = (cacc[0][q][t], cacc[1][q][t]);
                    let (se, so) = (sacc[0][q][t], sacc[1][q][t]);
                    let (a, b, c, d) = (ce + co, ce - co, se + so, se - so);
                    four[0][q] = a + c;
                    four[1][q] = a - c;
                    four[2][q] = b - d;
                    four[3][q] = b + d;
                }
                out[j] = to_partials(&four[0]);
                if symmetric {
                    if j > 0 {
                        out[nv - j] = to_partials(&four[1]);
                    }
                    if j < quarter {
                        out[nv / 2 - j] = to_partials(&four[2]);
                        if j > 0 {
                            out[nv / 2 + j] = to_partials(&four[3]);
                        }
                    }
                }
            }
            j0 += len;
        }
        if let Some(r) = &self.patch.remainder {
            let k = self.patch.conditions.len();
            let mut w = [vec![0.0; k], vec![0.0; k], vec![0.0; k]];
            for (d, wd) in w.iter_mut().enumerate() {
                r.cardinal.eval(u, d, wd);
            }
            for i in (0..k).filter(|&i| r.active[i]) {
                let (w0, w1, w2) = (w[0][i], w[1][i], w[2][i]);
                for (o, [d0, d1, d2]) in out[..nv].iter_mut().zip(&self.delta[i * self.nv..]) {
                    o.x += d0 * w0;
                    o.xu += d0 * w1;
                    o.xuu += d0 * w2;
                    o.xv += d1 * w0;
                    o.xuv += d1 * w1;
                    o.xvv += d2 * w0;
                }
            }
        }
    }
}
