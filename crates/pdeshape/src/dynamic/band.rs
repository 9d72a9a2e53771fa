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
/// For the systems of scheme (6) it also offers [`Penta::solve_system`]: the matrix is assembled
/// into a second buffer ([`Penta::next_row`], [`Penta::add_next`], [`Penta::commit`]), factorised
/// without pivoting when that is provably backward stable (see [`GROWTH`]) and otherwise with
/// partial pivoting, and the factors are kept while the assembled matrix stays bit-for-bit the same.
#[derive(Debug, Clone)]
pub struct Penta {
    n: usize,
    rows: Vec<[f64; 7]>,
    pivots: Vec<usize>,
    /// `1/U_kk`: one division per row in the factorisation, none in the solve.
    inverse: Vec<f64>,
    scratch: Vec<f64>,
    /// The matrix being assembled for the next solve (same layout as `rows`).
    next: Vec<[f64; 7]>,
    /// Unpivoted factors of `rows`, row `i` at index `i + 2` (two zero rows in front):
    /// `[L_{i,i−2}, L_{i,i−1}, U_{i,i+1}, U_{i,i+2}]`.
    factors: Vec<[f64; 4]>,
    /// `1/U_ii` of the unpivoted factors, at index `i + 2` (zeros in front).
    factor_inverse: Vec<f64>,
    /// Whether `factors`/`factor_inverse` are the valid unpivoted factors of `rows`.
    factored: bool,
    /// Number of solves that needed the pivoting fallback, and that reused the factors.
    pivoted_solves: usize,
    reused_solves: usize,
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
            next: vec![[0.0; 7]; n + 2],
            factors: vec![[0.0; 4]; n + 2],
            factor_inverse: vec![0.0; n + 2],
            factored: false,
            pivoted_solves: 0,
            reused_solves: 0,
        }
    }

    /// Row `i < n` of the matrix being assembled: `[A_{i,i−2}, …, A_{i,i+2}, 0, 0]` (entries
    /// outside the matrix must stay zero).
    #[inline]
    pub fn next_row(&mut self, i: usize) -> &mut [f64; 7] {
        &mut self.next[i]
    }

    /// Adds `value` to the entry `(i, c)`, `|c − i| ≤ 2`, both `< n`, of the matrix being
    /// assembled.
    #[inline]
    pub fn add_next(&mut self, i: usize, c: usize, value: f64) {
        debug_assert!(i < self.n && c < self.n && c + 2 >= i && c <= i + 2);
        self.next[i][c + 2 - i] += value;
    }

    /// Makes the assembled matrix the current one. If it equals the current matrix bit for bit
    /// (compared as numbers), the factors already computed remain valid and are kept.
    pub fn commit(&mut self) {
        if self.next[..self.n] != self.rows[..self.n] {
            std::mem::swap(&mut self.next, &mut self.rows);
            self.factored = false;
        }
    }

    #[cfg(test)]
    /// How many solves of [`Penta::solve_system`] fell back to partial pivoting.
    pub fn pivoted_solves(&self) -> usize {
        self.pivoted_solves
    }

    #[cfg(test)]
    /// How many solves of [`Penta::solve_system`] reused the factors of the previous one.
    pub fn reused_solves(&self) -> usize {
        self.reused_solves
    }

    /// LU factorisation of the current matrix without pivoting, fused with the forward
    /// substitution `L y = b` (`y` into `scratch[2..n+2]`). Returns whether the factors pass the
    /// stability test of [`GROWTH`]; `rows` is not modified.
    fn factor_unpivoted(&mut self, b: &[f64]) -> bool {
        let n = self.n;
        let rows = &self.rows[..n];
        let fac = &mut self.factors[..n + 2];
        let inv = &mut self.factor_inverse[..n + 2];
        let y = &mut self.scratch[..n + 2];
        fac[0] = [0.0; 4];
        fac[1] = [0.0; 4];
        inv[0] = 0.0;
        inv[1] = 0.0;
        y[0] = 0.0;
        y[1] = 0.0;
        // 1-norms of the rows of U (zero for the two padding rows).
        let (mut norm2, mut norm1) = (0.0f64, 0.0f64);
        let mut ok = true;
        for (i, (a, &bi)) in rows.iter().zip(b).enumerate() {
            let k = i + 2;
            let (f2, f1) = (fac[k - 2], fac[k - 1]);
            let l2 = a[0] * inv[k - 2];
            let e1 = a[1] - l2 * f2[2];
            let l1 = e1 * inv[k - 1];
            let diag = a[2] - l2 * f2[3] - l1 * f1[2];
            let s1 = a[3] - l1 * f1[3];
            let s2 = a[4];
            let r = 1.0 / diag;
            fac[k] = [l2, l1, s1, s2];
            inv[k] = r;
            y[k] = bi - l2 * y[k - 2] - l1 * y[k - 1];
            let norm = diag.abs() + s1.abs() + s2.abs();
            let lu = norm + l1.abs() * norm1 + l2.abs() * norm2;
            let asum = a[0].abs() + a[1].abs() + a[2].abs() + a[3].abs() + a[4].abs();
            ok &= (lu <= GROWTH * asum) & (r.abs() < f64::INFINITY) & (r != 0.0);
            norm2 = norm1;
            norm1 = norm;
        }
        ok
    }

    /// Forward substitution `L y = b` with the stored unpivoted factors.
    fn forward_unpivoted(&mut self, b: &[f64]) {
        let n = self.n;
        let fac = &self.factors[2..n + 2];
        let y = &mut self.scratch[..n + 2];
        y[0] = 0.0;
        y[1] = 0.0;
        let (mut y2, mut y1) = (0.0, 0.0);
        for (i, (f, &bi)) in fac.iter().zip(b).enumerate() {
            let v = bi - f[0] * y2 - f[1] * y1;
            y[i + 2] = v;
            y2 = y1;
            y1 = v;
        }
    }

    /// Back substitution `U x = y` with the unpivoted factors, `y` in `scratch[2..n+2]`.
    fn back_unpivoted(&self, x: &mut [f64]) {
        let n = self.n;
        let fac = &self.factors[2..n + 2];
        let inv = &self.factor_inverse[2..n + 2];
        let y = &self.scratch[2..n + 2];
        let (mut x1, mut x2) = (0.0, 0.0);
        for i in (0..n).rev() {
            let f = &fac[i];
            let v = (y[i] - f[2] * x1 - f[3] * x2) * inv[i];
            x[i] = v;
            x2 = x1;
            x1 = v;
        }
    }

    /// Solves `A x = b` in place for the matrix made current by [`Penta::commit`]: with the kept
    /// factors if the matrix did not change, else by LU without pivoting if it passes the
    /// stability test of [`GROWTH`], else by LU with partial pivoting ([`Penta::factorize`], on a
    /// copy, so that the matrix stays available for comparison). Fails on a singular matrix.
    pub fn solve_system(&mut self, b: &mut [f64]) -> Result<()> {
        assert_eq!(b.len(), self.n, "right-hand side of the wrong length");
        if self.factored {
            self.reused_solves += 1;
            self.forward_unpivoted(b);
            self.back_unpivoted(b);
            return Ok(());
        }
        if self.factor_unpivoted(b) {
            self.factored = true;
            self.back_unpivoted(b);
            return Ok(());
        }
        self.pivoted_solves += 1;
        let saved = self.rows.clone();
        let result = self.factorize();
        if result.is_ok() {
            self.solve_in_place(b);
        }
        self.rows = saved;
        result
    }

    #[cfg(test)]
    /// Adds `value` to the entry `(i, c)`, `|c − i| ≤ 2`, both `< n`.
    #[inline]
    pub fn add(&mut self, i: usize, c: usize, value: f64) {
        debug_assert!(i < self.n && c < self.n && c + 2 >= i && c <= i + 2);
        self.rows[i][c + 2 - i] += value;
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
        p.add_next(0, 0, 1.0);
        p.add_next(1, 0, 1.0);
        p.add_next(2, 0, 1.0);
        p.commit();
        assert!(p.solve_system(&mut [1.0, 2.0, 3.0]).is_err());
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
                        penta.add_next(i, c as usize, v);
                    }
                }
            }
            penta.commit();
            band.factorize().unwrap();
            for round in 0..2 {
                let b: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
                let (mut x, mut y) = (b.clone(), b.clone());
                band.solve_in_place(&mut x);
                penta.solve_system(&mut y).unwrap();
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
                assert_eq!(penta.reused_solves(), if case == 0 { round } else { 0 });
                // The same matrix again (the factors stay valid).
                for (i, e) in entries.iter().enumerate() {
                    *penta.next_row(i) = [e[0], e[1], e[2], e[3], e[4], 0.0, 0.0];
                }
                penta.commit();
            }
            if case == 0 {
                // A changed matrix is factorised anew.
                penta.next_row(0)[2] += 1.0;
                penta.commit();
                let mut y = vec![1.0; n];
                penta.solve_system(&mut y).unwrap();
                assert_eq!(penta.reused_solves(), 1);
            }
        }
    }
}
