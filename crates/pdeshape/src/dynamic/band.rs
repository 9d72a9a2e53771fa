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
#[derive(Debug, Clone)]
pub struct Penta {
    n: usize,
    rows: Vec<[f64; 7]>,
    pivots: Vec<usize>,
    /// `1/U_kk`: one division per row in the factorisation, none in the solve.
    inverse: Vec<f64>,
    scratch: Vec<f64>,
}

impl Penta {
    /// A zero `n × n` pentadiagonal matrix.
    pub fn zeros(n: usize) -> Self {
        Penta {
            n,
            rows: vec![[0.0; 7]; n + 2],
            pivots: vec![0; n],
            inverse: vec![0.0; n],
            scratch: vec![0.0; n + 4],
        }
    }

    /// Resets every entry to zero.
    pub fn clear(&mut self) {
        self.rows.iter_mut().for_each(|r| *r = [0.0; 7]);
    }

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
        p.add(0, 0, 1.0);
        p.add(1, 0, 1.0);
        p.add(2, 0, 1.0);
        assert!(p.factorize().is_err());
    }
}
