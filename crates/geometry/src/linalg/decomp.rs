//! Dense decompositions with an iteration cap. nalgebra's plain `svd`, `singular_values`,
//! `symmetric_eigenvalues` and `complex_eigenvalues` iterate until they converge, which they may
//! never do on matrices with subnormal or wildly scaled entries (a smoothing parameter `a = 1e-320`
//! once made `check` run forever). These wrappers stop after [`max_iterations`] and return `None`,
//! which every caller turns into an error that names its input.

use nalgebra::{Complex, DMatrix, DVector, Schur, SymmetricEigen, SVD};

/// The iteration cap for an `n × n` (or `n`-column) problem: the QR-type iterations behind these
/// decompositions converge in a few sweeps per eigen- or singular value, so `100·n` (at least
/// 1000) sweeps are ample for every matrix that converges at all.
pub(crate) fn max_iterations(n: usize) -> usize {
    #[cfg(test)]
    if let Some(cap) = TEST_CAP.with(|c| c.get()) {
        return cap;
    }
    (100 * n).max(1000)
}

#[cfg(test)]
thread_local! {
    /// A lower cap for the tests of this thread ([`with_cap`]).
    static TEST_CAP: std::cell::Cell<Option<usize>> = const { std::cell::Cell::new(None) };
}

/// Runs `f` with the cap of [`max_iterations`] lowered to `cap` on this thread, so that tests
/// can show what a decomposition that does not converge within its cap turns into.
#[cfg(test)]
pub(crate) fn with_cap<T>(cap: usize, f: impl FnOnce() -> T) -> T {
    TEST_CAP.with(|c| c.set(Some(cap)));
    let out = f();
    TEST_CAP.with(|c| c.set(None));
    out
}

/// Singular values of `a`, or `None` if the SVD did not converge.
pub(crate) fn singular_values(a: DMatrix<f64>) -> Option<DVector<f64>> {
    if a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let n = a.nrows().max(a.ncols());
    SVD::try_new_unordered(a, false, false, f64::EPSILON, max_iterations(n))
        .map(|s| s.singular_values)
}

/// The SVD of `a` with `U` and `Vᵀ`, sorted by decreasing singular value, or `None` if it did not
/// converge.
pub(crate) fn svd(a: DMatrix<f64>) -> Option<SVD<f64, nalgebra::Dyn, nalgebra::Dyn>> {
    if a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let n = a.nrows().max(a.ncols());
    SVD::try_new(a, true, true, f64::EPSILON, max_iterations(n))
}

/// Eigenvalues of the symmetric matrix `a`, or `None` if the iteration did not converge.
pub(crate) fn symmetric_eigenvalues(a: DMatrix<f64>) -> Option<DVector<f64>> {
    if a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let n = a.nrows();
    SymmetricEigen::try_new(a, f64::EPSILON, max_iterations(n)).map(|e| e.eigenvalues)
}

/// Eigenvalues of the square matrix `a` (through its real Schur form), or `None` if the
/// iteration did not converge.
pub(crate) fn complex_eigenvalues(a: DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    if a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let n = a.nrows();
    Schur::try_new(a, f64::EPSILON, max_iterations(n))
        .map(|s| s.complex_eigenvalues().iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agree_with_closed_forms() {
        // diag(3, 1) rotated by 30°: singular values and eigenvalues 3 and 1.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let r = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
        let d = DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 1.0]);
        let a = &r * d * r.transpose();
        let mut sv: Vec<f64> = singular_values(a.clone())
            .unwrap()
            .iter()
            .copied()
            .collect();
        sv.sort_by(f64::total_cmp);
        assert!(
            (sv[0] - 1.0).abs() < 1e-14 && (sv[1] - 3.0).abs() < 1e-14,
            "{sv:?}"
        );
        let mut ev: Vec<f64> = symmetric_eigenvalues(a).unwrap().iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        assert!(
            (ev[0] - 1.0).abs() < 1e-14 && (ev[1] - 3.0).abs() < 1e-14,
            "{ev:?}"
        );
        // The companion matrix of σ² + 1: roots ±i.
        let comp = DMatrix::from_row_slice(2, 2, &[0.0, -1.0, 1.0, 0.0]);
        let z = complex_eigenvalues(comp).unwrap();
        assert!(z
            .iter()
            .all(|z| z.re.abs() < 1e-14 && (z.im.abs() - 1.0).abs() < 1e-14));
        let full = svd(DMatrix::from_row_slice(2, 2, &[0.0, 2.0, 1.0, 0.0])).unwrap();
        let sv = full.singular_values.as_slice();
        assert!(
            (sv[0] - 2.0).abs() < 1e-14 && (sv[1] - 1.0).abs() < 1e-14,
            "{sv:?}"
        );
    }

    /// A symmetric 6 × 6 matrix with distinct, spread eigenvalues: no QR-type iteration
    /// finishes it in one sweep.
    fn hard() -> DMatrix<f64> {
        DMatrix::from_fn(6, 6, |i, j| {
            1.0 / (1.0 + i as f64 + j as f64) + if i == j { i as f64 } else { 0.0 }
        })
    }

    #[test]
    fn decompositions_that_need_more_sweeps_than_the_cap_return_none() {
        with_cap(1, || {
            assert_eq!(max_iterations(6), 1);
            assert!(singular_values(hard()).is_none());
            assert!(svd(hard()).is_none());
            assert!(symmetric_eigenvalues(hard()).is_none());
            assert!(complex_eigenvalues(hard()).is_none());
        });
        // With the cap of every run they converge: the eigenvalues sum to the trace.
        assert_eq!(max_iterations(6), 1000);
        let ev = symmetric_eigenvalues(hard()).unwrap();
        assert!((ev.sum() - hard().trace()).abs() < 1e-12, "{ev}");
        assert!(singular_values(hard()).is_some() && svd(hard()).is_some());
        assert_eq!(complex_eigenvalues(hard()).unwrap().len(), 6);
    }

    #[test]
    fn non_finite_input_is_refused() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, f64::NAN, 0.0, 1.0]);
        assert!(singular_values(a.clone()).is_none());
        assert!(svd(a.clone()).is_none());
        assert!(symmetric_eigenvalues(a.clone()).is_none());
        assert!(complex_eigenvalues(a).is_none());
    }
}
