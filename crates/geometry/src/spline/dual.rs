//! The difference-equation theorem and the dual bases of Bézier patches on boxes and simplices
//! (seed 001: Feng, Tong, Chen, "The solution of difference equations and its applications in
//! CAGD").
//!
//! Values attached to a multi-index set (an [`IndexSet`]) are flat arrays: `dim` coordinates
//! per member, members in the set's storage order.

use super::scalar::{binomial, falling, IndexSet, Scalar};
use crate::{Error, Result};

fn check_len<T>(set: &IndexSet, dim: usize, values: &[T], name: &str) -> Result<()> {
    if dim == 0 {
        return Err(Error::invalid("dim: values need at least one coordinate"));
    }
    if values.len() != set.len() * dim {
        return Err(Error::invalid(format!(
            "{name}: {} members × {dim} coordinates = {} values expected, got {}",
            set.len(),
            set.len() * dim,
            values.len()
        )));
    }
    Ok(())
}

/// Theorem 1, Eq. (1): `a_α = Δ^α b_0 = (E − I)^α b_0 = Σ_{σ≤α} (−1)^{|α−σ|} C(α, σ) b_σ` for
/// every member `α` of `set` (a box `{α ≤ d}` or a simplex `{|α| ≤ n}`: both are
/// downward closed, so every `b_σ` needed is there). Computed axis by axis with the in-place
/// difference table `x_k ← x_k − x_{k−1}` (`k` descending, repeated), `O(|set|·Σd_j)`.
pub fn forward_differences<T: Scalar>(set: &IndexSet, dim: usize, b: &[T]) -> Result<Vec<T>> {
    check_len(set, dim, b, "b")?;
    let mut x = b.to_vec();
    let idx = set.indices();
    let mut below = vec![0; set.vars()];
    for j in 0..set.vars() {
        let maxd = idx.iter().map(|a| a[j]).max().unwrap_or(0);
        for r in 1..=maxd {
            for (pos, a) in idx.iter().enumerate().rev() {
                if a[j] >= r {
                    below.copy_from_slice(a);
                    below[j] -= 1;
                    let q = set.position(&below).expect("downward closed");
                    for c in 0..dim {
                        let v = x[pos * dim + c].clone() - x[q * dim + c].clone();
                        x[pos * dim + c] = v;
                    }
                }
            }
        }
    }
    Ok(x)
}

/// Theorem 1, Eq. (2): `b_α = (E + I)^α a_0 = Σ_{σ≤α} C(α, σ) a_σ` for every member `α` (the
/// shift `E` acting on the `a`), the inverse of [`forward_differences`]: the same table run
/// backwards, `x_k ← x_k + x_{k−1}` (`k` ascending).
pub fn binomial_sums<T: Scalar>(set: &IndexSet, dim: usize, a: &[T]) -> Result<Vec<T>> {
    check_len(set, dim, a, "a")?;
    let mut x = a.to_vec();
    let idx = set.indices();
    let mut below = vec![0; set.vars()];
    for j in (0..set.vars()).rev() {
        let maxd = idx.iter().map(|a| a[j]).max().unwrap_or(0);
        for r in (1..=maxd).rev() {
            for (pos, a) in idx.iter().enumerate() {
                if a[j] >= r {
                    below.copy_from_slice(a);
                    below[j] -= 1;
                    let q = set.position(&below).expect("downward closed");
                    for c in 0..dim {
                        let v = x[pos * dim + c].clone() + x[q * dim + c].clone();
                        x[pos * dim + c] = v;
                    }
                }
            }
        }
    }
    Ok(x)
}

/// The dual functional of Theorem 2 (box, Corollary 2.1 for `m = 2`):
/// `Λ_α f = Σ_{σ≤α} C(α, σ) (d−σ)!/d! ∂^{|σ|} f/∂x^σ (0)`, with
/// `(d−σ)!/d! = Π_j (d_j − σ_j)!/d_j!`. Applied to the tensor Bézier patch of degree `d` on
/// `[0, 1]^m` it returns the control point `P_α`. `derivative(σ)` must return
/// `∂^σ f(0)` (`dim` coordinates); it is called for every `σ ≤ α`.
pub fn box_dual<T: Scalar>(
    degree: &[usize],
    alpha: &[usize],
    mut derivative: impl FnMut(&[usize]) -> Vec<T>,
) -> Result<Vec<T>> {
    check_alpha(degree.len(), alpha)?;
    for (j, (a, d)) in alpha.iter().zip(degree).enumerate() {
        if a > d {
            return Err(Error::invalid(format!(
                "alpha[{j}] = {a} exceeds the degree {d}"
            )));
        }
    }
    let set = IndexSet::boxed(alpha)?;
    let mut out: Option<Vec<T>> = None;
    for sigma in set.indices() {
        let mut w = T::one();
        for j in 0..alpha.len() {
            w = w * binomial::<T>(alpha[j], sigma[j]) / falling::<T>(degree[j], sigma[j]);
        }
        accumulate(&mut out, derivative(sigma), w)?;
    }
    Ok(out.unwrap_or_default())
}

/// The dual functional of Theorem 3 (simplex, Corollary 3.1 for triangles):
/// `Λ_α f = Σ_{σ≤α} C(α, σ) (n−|σ|)!/n! ∂^{|σ|} f/∂λ^σ (0)` for `|α| ≤ n`, the derivatives taken
/// in the coordinates `λ_1 … λ_m` with `λ_{m+1} = 1 − |λ|` dependent (at `λ = 0`, the vertex
/// `V^{(m+1)}`). Applied to a Bézier patch of degree `n` on the simplex it returns `C_α`.
pub fn simplex_dual<T: Scalar>(
    n: usize,
    alpha: &[usize],
    mut derivative: impl FnMut(&[usize]) -> Vec<T>,
) -> Result<Vec<T>> {
    check_alpha(alpha.len(), alpha)?;
    let total: usize = alpha.iter().sum();
    if total > n {
        return Err(Error::invalid(format!(
            "alpha = {alpha:?}: |alpha| = {total} exceeds the degree {n}"
        )));
    }
    let set = IndexSet::boxed(alpha)?;
    let mut out: Option<Vec<T>> = None;
    for sigma in set.indices() {
        let mut w = T::one() / falling::<T>(n, sigma.iter().sum());
        for j in 0..alpha.len() {
            w = w * binomial::<T>(alpha[j], sigma[j]);
        }
        accumulate(&mut out, derivative(sigma), w)?;
    }
    Ok(out.unwrap_or_default())
}

fn check_alpha(m: usize, alpha: &[usize]) -> Result<()> {
    if m == 0 || alpha.len() != m {
        return Err(Error::invalid(format!(
            "alpha = {alpha:?}: expected {m} components (m ≥ 1)"
        )));
    }
    Ok(())
}

fn accumulate<T: Scalar>(out: &mut Option<Vec<T>>, d: Vec<T>, w: T) -> Result<()> {
    match out {
        None => *out = Some(d.into_iter().map(|x| x * w.clone()).collect()),
        Some(o) => {
            if o.len() != d.len() {
                return Err(Error::invalid(format!(
                    "derivative: returned {} coordinates, earlier {}",
                    d.len(),
                    o.len()
                )));
            }
            for (a, b) in o.iter_mut().zip(d) {
                *a = a.clone() + b * w.clone();
            }
        }
    }
    Ok(())
}

/// All control points of a tensor Bézier patch of degree `d` on `[0, 1]^m` from its derivatives
/// at the origin corner (Theorem 2 for every `α` at once): `derivs` holds `∂^σ P(0)` for every
/// `σ ≤ d` in the order of `IndexSet::boxed(d)`. With `a_σ = (d−σ)!/d! ∂^σ P(0) = Δ^σ P_0`,
/// `P_α = (E + I)^α a_0` ([`binomial_sums`]).
pub fn box_control_from_derivatives<T: Scalar>(
    degree: &[usize],
    dim: usize,
    derivs: &[T],
) -> Result<Vec<T>> {
    let set = IndexSet::boxed(degree)?;
    check_len(&set, dim, derivs, "derivs")?;
    let mut a = derivs.to_vec();
    for (pos, sigma) in set.indices().iter().enumerate() {
        let mut f = T::one();
        for (d, s) in degree.iter().zip(sigma) {
            f = f * falling::<T>(*d, *s);
        }
        for x in &mut a[pos * dim..(pos + 1) * dim] {
            *x = x.clone() / f.clone();
        }
    }
    binomial_sums(&set, dim, &a)
}

/// All control points of a Bézier patch of degree `n` on a simplex in R^m from its derivatives
/// at `λ = 0` (Theorem 3 for every `α` at once): `derivs` holds `∂^σ b_n(0)/∂λ^σ` for every
/// `|σ| ≤ n` in the order of `IndexSet::simplex(m, n)`.
pub fn simplex_control_from_derivatives<T: Scalar>(
    m: usize,
    n: usize,
    dim: usize,
    derivs: &[T],
) -> Result<Vec<T>> {
    let set = IndexSet::simplex(m, n)?;
    check_len(&set, dim, derivs, "derivs")?;
    let mut a = derivs.to_vec();
    for (pos, sigma) in set.indices().iter().enumerate() {
        let f = falling::<T>(n, sigma.iter().sum());
        for x in &mut a[pos * dim..(pos + 1) * dim] {
            *x = x.clone() / f.clone();
        }
    }
    binomial_sums(&set, dim, &a)
}
