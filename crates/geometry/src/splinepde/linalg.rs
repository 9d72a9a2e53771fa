//! Dense linear algebra for the constraint systems: the affine solution set `x0 + N y` of
//! `A x = B`, rank-revealing in `f64` (SVD of the row-scaled system) and exact over the
//! rationals (Gauss–Jordan).

use super::scalar::Scalar;
use crate::{Error, Result};
use num_rational::BigRational;
use num_traits::{One, Zero};

/// A dense row-major matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Mat<T> {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Entries row by row: `(i, j)` at `i·cols + j`.
    pub data: Vec<T>,
}

impl<T: Scalar> Mat<T> {
    /// The zero matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Mat {
            rows,
            cols,
            data: vec![T::zero(); rows * cols],
        }
    }
    /// Entry `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> &T {
        &self.data[i * self.cols + j]
    }
    /// Mutable entry `(i, j)`.
    pub fn at_mut(&mut self, i: usize, j: usize) -> &mut T {
        &mut self.data[i * self.cols + j]
    }
    /// `self · other`, skipping exact zeros of `self`.
    pub fn mul(&self, other: &Mat<T>) -> Mat<T> {
        let mut out: Mat<T> = Mat::zeros(self.rows, other.cols);
        for i in 0..self.rows {
            for k in 0..self.cols {
                let a = self.at(i, k);
                if a.is_zero() {
                    continue;
                }
                for j in 0..other.cols {
                    let b = other.at(k, j);
                    if b.is_zero() {
                        continue;
                    }
                    let s = out.at(i, j).clone() + a.clone() * b.clone();
                    *out.at_mut(i, j) = s;
                }
            }
        }
        out
    }
    /// The transpose.
    pub fn transpose(&self) -> Mat<T> {
        let mut out = Mat::zeros(self.cols, self.rows);
        for i in 0..self.rows {
            for j in 0..self.cols {
                *out.at_mut(j, i) = self.at(i, j).clone();
            }
        }
        out
    }
}

/// The solution set `{x0 + N y}` of `A x = B` (one column of `x0` per column of `B`).
#[derive(Clone, Debug)]
pub struct Affine<T> {
    pub x0: Mat<T>,
    /// Columns span the null space of `A`.
    pub null: Mat<T>,
    pub rank: usize,
    /// Rows of `A x = B` that contradict the others (empty when consistent).
    pub inconsistent: Vec<usize>,
}

/// Scalars with a solver for [`Affine`] sets.
pub trait Solve: Scalar {
    /// The solution set of `A x = B`; for an inconsistent system `x0` is a least-squares
    /// (or partial) solution and `inconsistent` lists offending rows.
    /// Fails only when a decomposition does not converge within its iteration cap.
    fn affine(a: &Mat<Self>, b: &Mat<Self>) -> Result<Affine<Self>> {
        let norms: Vec<f64> = (0..a.rows)
            .map(|i| {
                (0..a.cols)
                    .map(|j| a.at(i, j).to_f64().powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        Self::affine_scaled(a, b, &norms, 0.0)
    }

    /// [`Solve::affine`] where row `i` has the scale `row_norms[i]` (in `f64`, the norm of the
    /// row before known columns were moved to the right-hand side: entries much smaller than
    /// it are rounding residue), and `value_scale` is the size of the values moved to the
    /// right-hand side (residuals are judged against it too). Exact arithmetic ignores the scales.
    fn affine_scaled(
        a: &Mat<Self>,
        b: &Mat<Self>,
        row_norms: &[f64],
        value_scale: f64,
    ) -> Result<Affine<Self>>;

    /// True when the row `r` of `N` is zero (the unknown is fixed by the constraints).
    fn row_is_zero(null: &Mat<Self>, r: usize) -> bool;
}

impl Solve for BigRational {
    /// Gauss–Jordan elimination of `[A | B]` with row tracking; exact.
    fn affine_scaled(
        a: &Mat<Self>,
        b: &Mat<Self>,
        _row_norms: &[f64],
        _value_scale: f64,
    ) -> Result<Affine<Self>> {
        let (m, n, c) = (a.rows, a.cols, b.cols);
        let w = n + c;
        let mut rows: Vec<Vec<BigRational>> = (0..m)
            .map(|i| {
                let mut r: Vec<BigRational> = a.data[i * n..(i + 1) * n].to_vec();
                r.extend_from_slice(&b.data[i * c..(i + 1) * c]);
                r
            })
            .collect();
        let mut origin: Vec<usize> = (0..m).collect();
        let mut pivots: Vec<usize> = Vec::new();
        let mut r = 0;
        for col in 0..n {
            if r == m {
                break;
            }
            let Some(p) = (r..m).find(|&i| !Zero::is_zero(&rows[i][col])) else {
                continue;
            };
            rows.swap(r, p);
            origin.swap(r, p);
            let inv = BigRational::from_integer(1.into()) / rows[r][col].clone();
            for x in rows[r].iter_mut().skip(col) {
                *x = x.clone() * inv.clone();
            }
            let pivot_row = rows[r].clone();
            for (i, row) in rows.iter_mut().enumerate() {
                if i == r || Zero::is_zero(&row[col]) {
                    continue;
                }
                let f = row[col].clone();
                for j in col..w {
                    if !Zero::is_zero(&pivot_row[j]) {
                        row[j] = row[j].clone() - f.clone() * pivot_row[j].clone();
                    }
                }
            }
            pivots.push(col);
            r += 1;
        }
        let rank = pivots.len();
        let inconsistent: Vec<usize> = (rank..m)
            .filter(|&i| rows[i][n..].iter().any(|x| !Zero::is_zero(x)))
            .map(|i| origin[i])
            .collect();
        let mut x0 = Mat::zeros(n, c);
        for (pr, &pc) in pivots.iter().enumerate() {
            for j in 0..c {
                *x0.at_mut(pc, j) = rows[pr][n + j].clone();
            }
        }
        let free: Vec<usize> = (0..n).filter(|j| !pivots.contains(j)).collect();
        let mut null = Mat::zeros(n, free.len());
        for (k, &f) in free.iter().enumerate() {
            *null.at_mut(f, k) = One::one();
            for (pr, &pc) in pivots.iter().enumerate() {
                *null.at_mut(pc, k) = -rows[pr][f].clone();
            }
        }
        Ok(Affine {
            x0,
            null,
            rank,
            inconsistent,
        })
    }

    fn row_is_zero(null: &Mat<Self>, r: usize) -> bool {
        (0..null.cols).all(|k| Zero::is_zero(null.at(r, k)))
    }
}

/// Relative size below which a singular value of the row-normalised system counts as zero:
/// `max(m, n) · ε`, the usual rank threshold (the entries carry a few rounding errors each).
pub(super) fn rank_tolerance(m: usize, n: usize) -> f64 {
    (m.max(n) as f64) * f64::EPSILON
}

/// A row of `N` (orthonormal columns) smaller than this is zero: the unknown is determined.
pub(super) const DETERMINED_TOL: f64 = 1e-8;

impl Solve for f64 {
    /// Rows divided by their scales, then the SVD (a wide system padded with zero rows); singular values below [`rank_tolerance`] · σ_max
    /// are zero. `x0` is the minimum-norm least-squares solution; rows whose scaled residual
    /// exceeds `1e-8 · max(|B|, |x0|, value_scale)` (scaled `B`; rounding of unit rows is
    /// `κ·ε` times the values, so this leaves room for condition numbers up to 10⁷ and is far
    /// below any real contradiction of data of that size) are reported as inconsistent.
    fn affine_scaled(
        a: &Mat<Self>,
        b: &Mat<Self>,
        row_norms: &[f64],
        value_scale: f64,
    ) -> Result<Affine<Self>> {
        use nalgebra::DMatrix;
        let (m, n, c) = (a.rows, a.cols, b.cols);
        if n == 0 || m == 0 {
            // No unknowns: every row with a right-hand side beyond rounding contradicts. No rows:
            // everything is free.
            let inconsistent = (0..m)
                .filter(|&i| {
                    let s = if row_norms[i] > 0.0 {
                        row_norms[i]
                    } else {
                        1.0
                    };
                    let scale = value_scale.max(bscale(b, row_norms));
                    (0..c).any(|j| (b.at(i, j) / s).abs() > 1e-8 * scale)
                })
                .collect();
            let mut null = Mat::zeros(n, n);
            for i in 0..n {
                *null.at_mut(i, i) = 1.0;
            }
            return Ok(Affine {
                x0: Mat::zeros(n, c),
                null,
                rank: 0,
                inconsistent,
            });
        }
        let mut am = DMatrix::<f64>::zeros(m, n);
        let mut bm = DMatrix::<f64>::zeros(m, c);
        for i in 0..m {
            let norm = row_norms[i];
            let s = if norm > 0.0 { 1.0 / norm } else { 1.0 };
            for j in 0..n {
                am[(i, j)] = a.at(i, j) * s;
            }
            for j in 0..c {
                bm[(i, j)] = b.at(i, j) * s;
            }
        }
        // A tall system is decomposed as it is (its thin SVD has the full V); a wide one is
        // padded with zero rows to n × n so that V is complete.
        let (r, qtb) = if m >= n {
            (am.clone(), bm.clone())
        } else {
            let mut r = DMatrix::<f64>::zeros(n, n);
            r.view_mut((0, 0), (m, n)).copy_from(&am);
            let mut qtb = DMatrix::<f64>::zeros(n, c);
            qtb.view_mut((0, 0), (m, c)).copy_from(&bm);
            (r, qtb)
        };
        // Rows have unit norm, so the capped SVD converges on any finite system; should it not
        // (or should an entry not be finite), the solve fails with an error: there is no
        // uncapped fallback.
        let Some(svd) = crate::linalg::decomp::svd(r) else {
            return Err(Error::invalid(format!(
                "the {m} × {n} linear system of the control points could not be solved: its \
                 SVD did not converge within {} sweeps (or an entry is not finite)",
                crate::linalg::decomp::max_iterations(m.max(n))
            )));
        };
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return Err(Error::invalid(
                "the linear system of the control points could not be solved (SVD without vectors)",
            ));
        };
        let smax = svd.singular_values.iter().cloned().fold(0.0, f64::max);
        let tol = rank_tolerance(m, n) * smax;
        let keep: Vec<usize> = (0..n)
            .filter(|&i| svd.singular_values[i] > tol && smax > 0.0)
            .collect();
        // x = V Σ⁺ Uᵀ b over the kept singular values, then two steps of iterative refinement
        // (x += V Σ⁺ Uᵀ (b − A x)) against the rounding of the decomposition itself.
        let pinv = |rhs: &DMatrix<f64>| {
            let mut x = DMatrix::<f64>::zeros(n, c);
            for &i in &keep {
                let coef = u.column(i).transpose() * rhs / svd.singular_values[i];
                x += vt.row(i).transpose() * coef;
            }
            x
        };
        let mut x = pinv(&qtb);
        for _ in 0..2 {
            let r = if m >= n {
                &bm - &am * &x
            } else {
                let mut r = DMatrix::<f64>::zeros(n, c);
                r.view_mut((0, 0), (m, c)).copy_from(&(&bm - &am * &x));
                r
            };
            x += pinv(&r);
        }
        let nulls: Vec<usize> = (0..n).filter(|i| !keep.contains(i)).collect();
        let mut null = Mat::zeros(n, nulls.len());
        for (k, &i) in nulls.iter().enumerate() {
            for j in 0..n {
                *null.at_mut(j, k) = vt[(i, j)];
            }
        }
        let res = &am * &x - &bm;
        let scale = bm
            .amax()
            .max(x.amax())
            .max(value_scale)
            .max(f64::MIN_POSITIVE);
        let inconsistent = (0..m)
            .filter(|&i| res.row(i).amax() > 1e-8 * scale)
            .collect();
        let mut x0 = Mat::zeros(n, c);
        for i in 0..n {
            for j in 0..c {
                *x0.at_mut(i, j) = x[(i, j)];
            }
        }
        Ok(Affine {
            x0,
            null,
            rank: keep.len(),
            inconsistent,
        })
    }

    fn row_is_zero(null: &Mat<Self>, r: usize) -> bool {
        (0..null.cols)
            .map(|k| null.at(r, k).powi(2))
            .sum::<f64>()
            .sqrt()
            < DETERMINED_TOL
    }
}

/// Largest magnitude in `b` with rows divided by their scales, at least the smallest normal
/// number.
fn bscale(b: &Mat<f64>, row_norms: &[f64]) -> f64 {
    let mut m = f64::MIN_POSITIVE;
    for i in 0..b.rows {
        let s = if row_norms[i] > 0.0 {
            row_norms[i]
        } else {
            1.0
        };
        for j in 0..b.cols {
            m = m.max((b.at(i, j) / s).abs());
        }
    }
    m
}
