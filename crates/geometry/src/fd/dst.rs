//! The orthonormal discrete sine transform of type I and the 2-D transform built from it: the
//! eigenvector basis of the second difference with zero Dirichlet values.
//!
//! For `n` interior nodes `x_1 … x_n` of a line of `n + 1` intervals, `δ²` with `x_0 = x_{n+1} = 0`
//! has the eigenvectors `sin(π j k / (n + 1))`, `k = 1 … n`, with eigenvalues
//! `−4 sin²(π k / (2(n + 1)))`. The matrix `S_{jk} = √(2/(n+1)) sin(π j k / (n + 1))` is symmetric
//! and orthogonal (`S² = I`), so the same transform goes both ways. It is computed by a real FFT
//! of length `2(n + 1)` of the odd extension `(0, x_1 … x_n, 0, −x_n … −x_1)`, whose transform is
//! `−2i Σ_j x_j sin(π j k / (n + 1))`.

use realfft::num_complex::Complex64;
use realfft::{RealFftPlanner, RealToComplex};
use std::sync::Arc;

/// The DST-I of length `n`.
pub(super) struct Dst {
    n: usize,
    fft: Arc<dyn RealToComplex<f64>>,
}

impl Dst {
    pub(super) fn new(n: usize, planner: &mut RealFftPlanner<f64>) -> Self {
        Dst {
            n,
            fft: planner.plan_fft_forward(2 * (n + 1)),
        }
    }

    #[cfg(test)]
    /// `S_{jk}` for `j, k` in `0 … n−1` (nodes and modes `1 … n`).
    pub(super) fn matrix(&self) -> Vec<f64> {
        let n = self.n;
        let s = (2.0 / (n + 1) as f64).sqrt();
        let w = std::f64::consts::PI / (n + 1) as f64;
        let mut m = vec![0.0; n * n];
        for j in 0..n {
            for k in 0..n {
                // (j + 1)(k + 1) reduced modulo 2(n + 1) keeps the argument small.
                let p = ((j + 1) * (k + 1)) % (2 * (n + 1));
                m[j * n + k] = s * (w * p as f64).sin();
            }
        }
        m
    }

    /// Transforms every row (consecutive chunk of `n` values) of `data` in place.
    pub(super) fn rows(&self, data: &mut [f64]) {
        let n = self.n;
        debug_assert_eq!(data.len() % n, 0);
        let len = 2 * (n + 1);
        let mut ext = vec![0.0; len];
        let mut spec = vec![Complex64::new(0.0, 0.0); n + 2];
        let mut scratch = self.fft.make_scratch_vec();
        let scale = -1.0 / ((2 * (n + 1)) as f64).sqrt();
        for row in data.chunks_exact_mut(n) {
            ext[0] = 0.0;
            ext[n + 1] = 0.0;
            for (j, &x) in row.iter().enumerate() {
                ext[j + 1] = x;
                ext[len - 1 - j] = -x;
            }
            self.fft
                .process_with_scratch(&mut ext, &mut spec, &mut scratch)
                .expect("buffer lengths match the plan");
            for (y, z) in row.iter_mut().zip(&spec[1..=n]) {
                *y = scale * z.im;
            }
        }
    }
}

/// `out[c][r] = a[r][c]` for `a` with `rows × cols` entries (row-major).
pub(super) fn transpose(a: &[f64], rows: usize, cols: usize, out: &mut [f64]) {
    const B: usize = 32;
    for r0 in (0..rows).step_by(B) {
        for c0 in (0..cols).step_by(B) {
            for r in r0..(r0 + B).min(rows) {
                for c in c0..(c0 + B).min(cols) {
                    out[c * rows + r] = a[r * cols + c];
                }
            }
        }
    }
}

/// The 2-D transform `S_first ⊗ S_second` of a `rows × cols` array `a` (row-major; rows of length
/// `cols = second.n`, `rows = first.n`): the rows by `second`, then the columns by `first`. The
/// result is written transposed (`cols × rows`) into `out`; `a` is overwritten.
pub(super) fn transform_2d(first: &Dst, second: &Dst, a: &mut [f64], out: &mut [f64]) {
    let (rows, cols) = (first.n, second.n);
    second.rows(a);
    transpose(a, rows, cols, out);
    first.rows(out);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FFT-based transform equals the dense sine matrix, and applying it twice is the
    /// identity (`S² = I`), for odd and even lengths.
    #[test]
    fn sine_transform_matches_its_matrix_and_is_an_involution() {
        let mut planner = RealFftPlanner::new();
        for n in [1, 2, 7, 16, 31] {
            let d = Dst::new(n, &mut planner);
            let s = d.matrix();
            let x: Vec<f64> = (0..2 * n).map(|i| ((i * 7 + 3) as f64).sin()).collect();
            let mut y = x.clone();
            d.rows(&mut y);
            for r in 0..2 {
                for k in 0..n {
                    let want: f64 = (0..n).map(|j| s[k * n + j] * x[r * n + j]).sum();
                    assert!((y[r * n + k] - want).abs() < 1e-14, "n = {n}");
                }
            }
            d.rows(&mut y);
            for (a, b) in x.iter().zip(&y) {
                assert!((a - b).abs() < 1e-14, "n = {n}");
            }
        }
    }

    #[test]
    fn sine_vectors_are_eigenvectors_of_the_dirichlet_second_difference() {
        let mut planner = RealFftPlanner::new();
        let n = 9;
        let s = Dst::new(n, &mut planner).matrix();
        for k in 0..n {
            let lam = -4.0
                * (std::f64::consts::PI * (k + 1) as f64 / (2 * (n + 1)) as f64)
                    .sin()
                    .powi(2);
            for j in 0..n {
                let at = |jj: isize| {
                    if (0..n as isize).contains(&jj) {
                        s[jj as usize * n + k]
                    } else {
                        0.0
                    }
                };
                let d2 = at(j as isize - 1) - 2.0 * at(j as isize) + at(j as isize + 1);
                assert!((d2 - lam * s[j * n + k]).abs() < 1e-14);
            }
        }
    }
}
