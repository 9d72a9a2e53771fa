//! Banded LU factorisation with partial pivoting (the scheme of LAPACK's `gbtrf`/`gbtrs`, written
//! out for the small bandwidths of the dynamic-curve scheme).
//!
//! A matrix with `kl` sub-diagonals and `ku` super-diagonals is stored row by row; row `i` keeps
//! the columns `i − kl ..= i + ku + kl`: the extra `kl` columns on the right receive the fill-in
//! that row interchanges create. Factorisation and solve cost `O(n·kl·(kl + ku))`, i.e. `O(n)` for
//! the pentadiagonal systems (`kl = ku = 2`) of scheme (6).

use crate::{Error, Result};

/// A banded matrix being assembled, then factorised in place.
#[derive(Debug, Clone)]
pub struct BandMatrix {
    n: usize,
    kl: usize,
    ku: usize,
    width: usize,
    data: Vec<f64>,
    pivots: Vec<usize>,
}

impl BandMatrix {
    /// A zero `n × n` matrix with `kl` sub- and `ku` super-diagonals.
    pub fn zeros(n: usize, kl: usize, ku: usize) -> Self {
        let width = 2 * kl + ku + 1;
        BandMatrix {
            n,
            kl,
            ku,
            width,
            data: vec![0.0; n * width],
            pivots: vec![0; n],
        }
    }

    #[inline]
    fn index(&self, i: usize, c: usize) -> usize {
        debug_assert!(c + self.kl >= i && c <= i + self.ku + self.kl);
        i * self.width + (c + self.kl - i)
    }

    /// Sets the entry `(i, c)`; `c` must lie in the band `i − kl ..= i + ku`.
    pub fn set(&mut self, i: usize, c: usize, value: f64) {
        assert!(
            i < self.n && c < self.n && c + self.kl >= i && c <= i + self.ku,
            "entry ({i}, {c}) outside the band"
        );
        let k = self.index(i, c);
        self.data[k] = value;
    }

    /// Factorises in place (`P A = L U`), with partial pivoting within the band.
    /// Fails if a pivot is zero or not finite (the matrix is singular to working precision).
    pub fn factorize(&mut self) -> Result<()> {
        let n = self.n;
        for k in 0..n {
            let last_row = (k + self.kl).min(n - 1);
            let last_col = (k + self.kl + self.ku).min(n - 1);
            let mut p = k;
            let mut best = self.data[self.index(k, k)].abs();
            for i in k + 1..=last_row {
                let v = self.data[self.index(i, k)].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if best == 0.0 || !best.is_finite() {
                return Err(Error::invalid(format!(
                    "the banded system is singular (pivot {best} in column {k})"
                )));
            }
            self.pivots[k] = p;
            if p != k {
                for c in k..=last_col {
                    let a = self.index(k, c);
                    let b = self.index(p, c);
                    self.data.swap(a, b);
                }
            }
            let pivot = self.data[self.index(k, k)];
            for i in k + 1..=last_row {
                let ik = self.index(i, k);
                let m = self.data[ik] / pivot;
                self.data[ik] = m;
                if m != 0.0 {
                    for c in k + 1..=last_col {
                        let kc = self.data[self.index(k, c)];
                        let ic = self.index(i, c);
                        self.data[ic] -= m * kc;
                    }
                }
            }
        }
        Ok(())
    }

    #[allow(clippy::needless_range_loop)] // band indices, not a plain traversal
    /// Solves `A x = b` in place with the factors of [`BandMatrix::factorize`].
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side of the wrong length");
        for k in 0..n {
            let p = self.pivots[k];
            b.swap(k, p);
            let bk = b[k];
            for i in k + 1..=(k + self.kl).min(n - 1) {
                b[i] -= self.data[self.index(i, k)] * bk;
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for c in i + 1..=(i + self.kl + self.ku).min(n - 1) {
                s -= self.data[self.index(i, c)] * b[c];
            }
            b[i] = s / self.data[self.index(i, i)];
        }
    }
}

/// The pentadiagonal case (`kl = ku = 2`) of [`BandMatrix`], with fixed-width rows so that the
/// inner loops have constant bounds: row `i` keeps the columns `i − 2 ..= i + 4` (offset
/// `c + 2 − i`; the last two receive fill-in). Two zero rows and four zero columns of padding
/// past the end remove every bound test from the loops. Same algorithm as [`BandMatrix`] (LU with
/// partial pivoting within the band), with divisions by the pivots replaced by multiplications
/// with their reciprocals (results agree to rounding).
///
/// For the systems of scheme (6) it also offers a streaming solve: [`Penta::begin`], then one
/// [`Penta::push`] per row in order, then [`Penta::finish`]. Each pushed row is factorised without
/// pivoting and forward-substituted at once, so the caller can assemble the next row while the
/// serial chain of pivots of this one is still in flight (the factorisation's latency hides behind
/// the assembly's arithmetic). The unpivoted factors are accepted when they pass the a-posteriori
/// stability test of [`GROWTH`]; otherwise [`Penta::finish`] solves with partial pivoting. Row `i`
/// of the unpivoted factors depends only on rows `0 ..= i`, so while the pushed rows equal, bit for
/// bit, the rows of the last accepted factorisation, its factors are reused row by row.
#[derive(Debug, Clone)]
pub struct Penta {
    n: usize,
    rows: Vec<[f64; 7]>,
    pivots: Vec<usize>,
    /// `1/U_kk`: one division per row in the factorisation, none in the solve.
    inverse: Vec<f64>,
    scratch: Vec<f64>,
    /// The right-hand side pushed with the rows (kept for the pivoting fallback).
    rhs: Vec<f64>,
    /// The unpivoted factors of `rows`, one entry per row.
    factors: Vec<FactorRow>,
    /// `[U_{i,i+1}/U_ii, U_{i,i+2}/U_ii]`: the rows of the unit upper factor, for the back
    /// substitution.
    unit_upper: Vec<[f64; 2]>,
    /// `y_i/U_ii`, `y` the forward substitution's result.
    scaled: Vec<f64>,
    /// Whether `factors` are the valid unpivoted factors of all of `rows`.
    factored: bool,
    /// Number of solves that needed the pivoting fallback, and that reused every factor row.
    pivoted_solves: usize,
    reused_solves: usize,
}

/// Row `i` of the unpivoted factors `A = L U`.
#[derive(Debug, Clone, Copy, Default)]
struct FactorRow {
    /// `L_{i,i−2}`, `L_{i,i−1}`.
    lower: [f64; 2],
    /// The pivot's pass through the chain: `U_{i,i+1}`, `U_{i,i+2}`, `1/U_ii` and
    /// `|U_ii| + |U_{i,i+1}| + |U_{i,i+2}|`.
    pivot: Pivot,
}

/// What row `i + 1` and `i + 2` of the factorisation need of row `i`.
#[derive(Debug, Clone, Copy, Default)]
struct Pivot {
    upper: [f64; 2],
    inverse: f64,
    norm: f64,
}

/// The state of a streaming solve between two [`Penta::push`]es: the last two rows' pivots and
/// forward-substitution values (zero before the first row), and the flags of the rows so far.
#[derive(Debug, Clone, Copy)]
pub struct Stream {
    pivots: [Pivot; 2],
    y: [f64; 2],
    /// Whether every row so far equals the stored one while the stored factors are valid.
    same: bool,
    /// Whether every row so far passed the stability test.
    stable: bool,
}

/// The bound `γ` of the a-posteriori stability test of the unpivoted LU: the factors are accepted
/// when every row satisfies `Σ_c (|L||U|)_{ic} ≤ γ Σ_c |A_{ic}|` and every pivot is finite and
/// non-zero. Gaussian elimination computes `L̂Û = A + ΔA` with `|ΔA| ≤ γ₃ |L̂||Û|` componentwise
/// (`γ₃ ≈ 3ε`: at most three products per entry of a pentadiagonal row; Higham, *Accuracy and
/// Stability of Numerical Algorithms*, Thm 9.3), so the test gives `‖ΔA‖_∞ ≤ 3εγ‖A‖_∞`: a
/// normwise backward error no worse than partial pivoting's worst case for two sub-diagonals
/// (growth up to `2^{2k_l+k_u−1} = 32`). For the matrices of (6) (`1 + aΔt/2` plus `Δt²/2`
/// times a symmetric positive semi-definite operator in the interior) the ratio stays near 1.
pub const GROWTH: f64 = 16.0;

impl Penta {
    /// A zero `n × n` pentadiagonal matrix.
    pub fn zeros(n: usize) -> Self {
        Penta {
            n,
            rows: vec![[0.0; 7]; n + 2],
            pivots: vec![0; n],
            inverse: vec![0.0; n],
            scratch: vec![0.0; n + 4],
            rhs: vec![0.0; n],
            factors: vec![FactorRow::default(); n],
            unit_upper: vec![[0.0; 2]; n],
            scaled: vec![0.0; n],
            factored: false,
            pivoted_solves: 0,
            reused_solves: 0,
        }
    }

    #[cfg(test)]
    /// Adds `value` to `A_{i,c}` (`|i − c| ≤ 2`) and forgets the factors.
    pub fn add(&mut self, i: usize, c: usize, value: f64) {
        self.rows[i][c + 2 - i] += value;
        self.factored = false;
    }

    #[cfg(test)]
    /// How many solves fell back to partial pivoting.
    pub fn pivoted_solves(&self) -> usize {
        self.pivoted_solves
    }

    #[cfg(test)]
    /// How many solves reused every row of the factors of the previous one.
    pub fn reused_solves(&self) -> usize {
        self.reused_solves
    }

    /// Starts a streaming solve: rows `0, 1, …, n − 1` follow through [`Penta::push`], which
    /// carries the returned state from row to row.
    pub fn begin(&self) -> Stream {
        Stream {
            pivots: [Pivot::default(); 2],
            y: [0.0; 2],
            same: self.factored,
            stable: true,
        }
    }

    /// Pushes row `i` (the rows come in order `0, 1, …`): `a = [A_{i,i−2}, …, A_{i,i+2}]` (entries
    /// outside the matrix must be zero) and the right-hand side `b_i`. Factorises the row without
    /// pivoting (or reuses its stored factors) and does its step of the forward substitution.
    #[inline(always)]
    pub fn push(&mut self, s: &mut Stream, i: usize, a: [f64; 5], b: f64) {
        self.rhs[i] = b;
        let [p2, p1] = s.pivots;
        let [y2, y1] = s.y;
        let stored = &mut self.rows[i];
        let (pivot, y) = if s.same && stored[..5] == a {
            let f = self.factors[i];
            let y = b - f.lower[0] * y2 - f.lower[1] * y1;
            (f.pivot, y)
        } else {
            s.same = false;
            *stored = [a[0], a[1], a[2], a[3], a[4], 0.0, 0.0];
            let l2 = a[0] * p2.inverse;
            let e1 = a[1] - l2 * p2.upper[0];
            let l1 = e1 * p1.inverse;
            let diag = a[2] - l2 * p2.upper[1] - l1 * p1.upper[0];
            let s1 = a[3] - l1 * p1.upper[1];
            let r = 1.0 / diag;
            let norm = diag.abs() + s1.abs() + a[4].abs();
            let pivot = Pivot {
                upper: [s1, a[4]],
                inverse: r,
                norm,
            };
            self.factors[i] = FactorRow {
                lower: [l2, l1],
                pivot,
            };
            self.unit_upper[i] = [s1 * r, a[4] * r];
            let lu = norm + l1.abs() * p1.norm + l2.abs() * p2.norm;
            let asum = a[0].abs() + a[1].abs() + a[2].abs() + a[3].abs() + a[4].abs();
            s.stable &= (lu <= GROWTH * asum) & (r.abs() < f64::INFINITY) & (r != 0.0);
            (pivot, b - l2 * y2 - l1 * y1)
        };
        self.scaled[i] = y * pivot.inverse;
        s.pivots = [p1, pivot];
        s.y = [y1, y];
    }

    /// Ends a streaming solve: the solution of `A x = b` for the pushed rows into `x` (length
    /// `n`), by back substitution with the unpivoted factors if every row passed the stability
    /// test, else by LU with partial pivoting ([`Penta::factorize`] on a copy, so that the
    /// pushed matrix stays available for the next comparison). Fails on a singular matrix.
    pub fn finish(&mut self, s: Stream, x: &mut [f64]) -> Result<()> {
        assert_eq!(x.len(), self.n, "solution of the wrong length");
        if s.same {
            self.reused_solves += 1;
        }
        if s.stable {
            self.factored = true;
            // U x = y as x_i = y_i/U_ii − (U_{i,i+1}/U_ii) x_{i+1} − (U_{i,i+2}/U_ii) x_{i+2}:
            // one product and one subtraction on the serial chain per row.
            let (mut x1, mut x2) = (0.0, 0.0);
            for ((xi, &yi), u) in x.iter_mut().zip(&self.scaled).zip(&self.unit_upper).rev() {
                let v = yi - u[1] * x2 - u[0] * x1;
                *xi = v;
                x2 = x1;
                x1 = v;
            }
            return Ok(());
        }
        self.factored = false;
        self.pivoted_solves += 1;
        let saved = self.rows.clone();
        let result = self.factorize();
        if result.is_ok() {
            x.copy_from_slice(&self.rhs);
            self.solve_in_place(x);
        }
        self.rows = saved;
        result
    }

    /// Factorises in place (`P A = L U`); fails on a zero or non-finite pivot.
    pub fn factorize(&mut self) -> Result<()> {
        let rows = &mut self.rows;
        for k in 0..self.n {
            let cand = [rows[k][2].abs(), rows[k + 1][1].abs(), rows[k + 2][0].abs()];
            let mut p = 0;
            if cand[1] > cand[p] {
                p = 1;
            }
            if cand[2] > cand[p] {
                p = 2;
            }
            let best = cand[p];
            if best == 0.0 || !best.is_finite() {
                return Err(Error::invalid(format!(
                    "the banded system is singular (pivot {best} in column {k})"
                )));
            }
            self.pivots[k] = k + p;
            if p != 0 {
                // Columns k ..= k + 4: offset c + 2 in row k, c + 2 − p in row k + p.
                let (head, tail) = rows.split_at_mut(k + p);
                let (rk, rp) = (&mut head[k], &mut tail[0]);
                for c in 0..5 {
                    std::mem::swap(&mut rk[c + 2], &mut rp[c + 2 - p]);
                }
            }
            let pivot_row = rows[k];
            let inv = 1.0 / pivot_row[2];
            self.inverse[k] = inv;
            for i in 1..3 {
                let r = &mut rows[k + i];
                let m = r[2 - i] * inv;
                r[2 - i] = m;
                if m != 0.0 {
                    for c in 1..5 {
                        r[c + 2 - i] -= m * pivot_row[c + 2];
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the factors of [`Penta::factorize`].
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let n = self.n;
        assert_eq!(b.len(), n, "right-hand side of the wrong length");
        let x = &mut self.scratch;
        x[..n].copy_from_slice(b);
        x[n..].iter_mut().for_each(|v| *v = 0.0);
        for k in 0..n {
            x.swap(k, self.pivots[k]);
            let xk = x[k];
            x[k + 1] -= self.rows[k + 1][1] * xk;
            x[k + 2] -= self.rows[k + 2][0] * xk;
        }
        // The padding rows' multipliers are zero, so x[n], x[n + 1] stay 0.
        x[n] = 0.0;
        x[n + 1] = 0.0;
        for i in (0..n).rev() {
            let r = &self.rows[i];
            let s = x[i] - r[3] * x[i + 1] - r[4] * x[i + 2] - r[5] * x[i + 3] - r[6] * x[i + 4];
            x[i] = s * self.inverse[i];
        }
        b.copy_from_slice(&x[..n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dense reference: the banded solve against nalgebra's dense LU on a random banded matrix
    /// that needs pivoting (small diagonal).
    #[test]
    fn matches_dense_lu() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for &(n, kl, ku) in &[(1, 2, 2), (5, 2, 2), (17, 2, 2), (12, 1, 3), (9, 3, 1)] {
            let mut band = BandMatrix::zeros(n, kl, ku);
            let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                for c in i.saturating_sub(kl)..=(i + ku).min(n - 1) {
                    let v: f64 = if c == i {
                        rng.gen_range(-0.1..0.1)
                    } else {
                        rng.gen_range(-1.0..1.0)
                    };
                    band.set(i, c, v);
                    dense[(i, c)] = v;
                }
            }
            let b: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let mut x = b.clone();
            band.factorize().unwrap();
            band.solve_in_place(&mut x);
            let reference = dense
                .clone()
                .lu()
                .solve(&nalgebra::DVector::from_vec(b.clone()))
                .unwrap();
            let scale = reference.amax().max(1.0);
            for i in 0..n {
                assert!(
                    (x[i] - reference[i]).abs() <= 1e-12 * scale,
                    "n={n} i={i}: {} vs {}",
                    x[i],
                    reference[i]
                );
            }
            // Residual of the original system.
            let xv = nalgebra::DVector::from_vec(x);
            let r = &dense * &xv - nalgebra::DVector::from_vec(b);
            assert!(r.amax() <= 1e-12 * scale * (n as f64));
        }
    }

    #[test]
    fn singular_matrix_is_an_error() {
        let mut band = BandMatrix::zeros(3, 2, 2);
        band.set(0, 0, 1.0);
        band.set(1, 0, 1.0);
        // Column 1 and row 2 stay zero.
        band.set(2, 0, 1.0);
        assert!(band.factorize().is_err());
    }

    /// The pentadiagonal solver agrees with the general band solver to rounding (the same
    /// operations, with reciprocals of the pivots) on matrices that need pivoting.
    #[test]
    fn penta_matches_band() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        for n in [1usize, 2, 3, 5, 9, 40] {
            let mut band = BandMatrix::zeros(n, 2, 2);
            let mut penta = Penta::zeros(n);
            for i in 0..n {
                for c in i.saturating_sub(2)..=(i + 2).min(n - 1) {
                    let v: f64 = if c == i {
                        rng.gen_range(-0.1..0.1)
                    } else {
                        rng.gen_range(-1.0..1.0)
                    };
                    band.set(i, c, v);
                    penta.add(i, c, v);
                }
            }
            let b: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let (mut x, mut y) = (b.clone(), b.clone());
            band.factorize().unwrap();
            band.solve_in_place(&mut x);
            penta.factorize().unwrap();
            penta.solve_in_place(&mut y);
            let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for (a, b) in x.iter().zip(&y) {
                assert!((a - b).abs() <= 1e-13 * scale, "n = {n}: {a} vs {b}");
            }
        }
        let mut p = Penta::zeros(3);
        let mut st = p.begin();
        for (i, row) in [
            [0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0, 0.0],
        ]
        .into_iter()
        .enumerate()
        {
            p.push(&mut st, i, row, 1.0);
        }
        assert!(p.finish(st, &mut [0.0; 3]).is_err());
        let mut p = Penta::zeros(3);
        p.add(0, 0, 1.0);
        p.add(1, 0, 1.0);
        p.add(2, 0, 1.0);
        assert!(p.factorize().is_err());
    }

    /// `solve_system` against the general band solver: on symmetric positive definite matrices
    /// of the form `I + K` (`K` the pentadiagonal `[1, −4, 6, −4, 1]` operator times a large
    /// random positive weight, as in scheme (6)) it takes the unpivoted path and agrees to
    /// rounding; on matrices with small diagonals it falls back to pivoting and agrees to
    /// rounding; an unchanged matrix reuses its factors and a changed one does not.
    #[test]
    fn solve_system_paths_match_band() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        for (case, n) in [
            (0, 1usize),
            (0, 2),
            (0, 7),
            (0, 60),
            (1, 3),
            (1, 9),
            (1, 40),
        ] {
            let mut band = BandMatrix::zeros(n, 2, 2);
            let mut penta = Penta::zeros(n);
            let mut entries = vec![[0.0f64; 5]; n];
            if case == 0 {
                let weight: Vec<f64> = (0..n).map(|_| rng.gen_range(1e3..1e6)).collect();
                for (i, w) in weight.iter().enumerate() {
                    // K = Σ_i w_i D_iᵀ D_i, D_i the second difference (1, −2, 1) on columns
                    // i − 1 ..= i + 1 (cut at the ends): symmetric positive semi-definite.
                    let cols = [i as isize - 1, i as isize, i as isize + 1];
                    let dv = [1.0, -2.0, 1.0];
                    for (p, &cp) in cols.iter().enumerate() {
                        for (q, &cq) in cols.iter().enumerate() {
                            if cp >= 0 && cq >= 0 && (cp as usize) < n && (cq as usize) < n {
                                let (r, c) = (cp as usize, cq as usize);
                                entries[r][c + 2 - r] += w * dv[p] * dv[q];
                            }
                        }
                    }
                }
                for e in entries.iter_mut() {
                    e[2] += 1.0 + rng.gen_range(0.0..0.5);
                }
            } else {
                for (i, e) in entries.iter_mut().enumerate() {
                    for (k, v) in e.iter_mut().enumerate() {
                        let c = i as isize + k as isize - 2;
                        if c >= 0 && (c as usize) < n {
                            *v = if k == 2 {
                                rng.gen_range(-0.1..0.1)
                            } else {
                                rng.gen_range(-1.0..1.0)
                            };
                        }
                    }
                }
            }
            for (i, e) in entries.iter().enumerate() {
                for (k, &v) in e.iter().enumerate() {
                    let c = i as isize + k as isize - 2;
                    if c >= 0 && (c as usize) < n {
                        band.set(i, c as usize, v);
                    }
                }
            }
            band.factorize().unwrap();
            let stream = |penta: &mut Penta, entries: &[[f64; 5]], b: &[f64]| {
                let mut st = penta.begin();
                for (i, (e, &bi)) in entries.iter().zip(b).enumerate() {
                    penta.push(&mut st, i, *e, bi);
                }
                let mut x = vec![0.0; b.len()];
                penta.finish(st, &mut x).map(|_| x)
            };
            for round in 0..2 {
                let b: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
                let mut x = b.clone();
                band.solve_in_place(&mut x);
                let y = stream(&mut penta, &entries, &b).unwrap();
                if case == 1 {
                    // The same pivoted algorithm: equal to rounding.
                    let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                    for (a, b) in x.iter().zip(&y) {
                        assert!((a - b).abs() <= 1e-12 * scale, "n = {n}: {a} vs {b}");
                    }
                }
                // Both are backward stable: normwise backward error
                // ‖b − A y‖∞ / (‖A‖∞ ‖y‖∞) within a small multiple of ε (3γ + 8 for the
                // factorisation test of GROWTH and the two substitutions). The solutions
                // themselves differ by up to κ(A) ε, and κ(A) reaches 1e7 here.
                let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let a_norm = entries
                    .iter()
                    .map(|e| e.iter().map(|v| v.abs()).sum::<f64>())
                    .fold(0.0f64, f64::max);
                for sol in [&x, &y] {
                    let residual: Vec<f64> = (0..n)
                        .map(|i| {
                            let mut r = b[i];
                            for (k, v) in entries[i].iter().enumerate() {
                                let c = i as isize + k as isize - 2;
                                if c >= 0 && (c as usize) < n {
                                    r -= v * sol[c as usize];
                                }
                            }
                            r
                        })
                        .collect();
                    let eta = norm(&residual) / (a_norm * norm(sol));
                    assert!(
                        eta <= (3.0 * GROWTH + 8.0) * f64::EPSILON,
                        "case {case}, n = {n}: backward error {eta:e}"
                    );
                }
                assert_eq!(
                    penta.pivoted_solves(),
                    if case == 0 { 0 } else { round + 1 }
                );
                // The same matrix again in the next round: the factors stay valid.
                assert_eq!(penta.reused_solves(), if case == 0 { round } else { 0 });
            }
            if case == 0 {
                // A matrix changed in its last row keeps the factors of the rows before it and
                // solves correctly; one changed in its first row is factorised anew.
                for (shift, changed) in [(1.0, n - 1), (2.0, 0)] {
                    let mut other = entries.clone();
                    other[changed][2] += shift;
                    let b = vec![1.0; n];
                    let y = stream(&mut penta, &other, &b).unwrap();
                    let mut fresh = Penta::zeros(n);
                    let z = stream(&mut fresh, &other, &b).unwrap();
                    assert_eq!(y, z, "n = {n}, row {changed} changed");
                    assert_eq!(penta.reused_solves(), 1);
                }
            }
        }
    }
}
