//! m-variate tensor-product Bézier patches on the box `[0, 1]^m` with values in R^dim, generic
//! over the scalar (seed 001 §3, Eq. 7).

use super::dual::{box_control_from_derivatives, forward_differences};
use super::scalar::{falling, IndexSet, Scalar};
use crate::{Error, Result};

/// `P(x) = Σ_{α≤d} P_α b_α^d(x) = Π_{i=1}^{m} (x_i Δ_i + I)^{d_i} P_0` (seed 001 Eq. 7), with
/// `b_α^d(x) = Π_i C(d_i, α_i) x_i^{α_i} (1 − x_i)^{d_i − α_i}`, on `x ∈ [0, 1]^m` (extended as a
/// polynomial outside). Control points `P_α ∈ R^dim` are stored in the order of
/// `IndexSet::boxed(d)` (lexicographic, last index fastest; for `m = 2` this is the row-major
/// layout of [`super::BezierSurface`]), `dim` coordinates each.
///
/// For a box `Π [a_i, b_i]` substitute `x_i = (y_i − a_i)/(b_i − a_i)`; derivatives in `y` carry
/// the factors `(b_i − a_i)^{−σ_i}`.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorBezier<T: Scalar> {
    degree: Vec<usize>,
    dim: usize,
    set: IndexSet,
    control: Vec<T>,
}

impl<T: Scalar> TensorBezier<T> {
    /// A patch of degrees `d = degree` (`m = degree.len() ≥ 1`) with `Π(d_i + 1)` control points
    /// of `dim ≥ 1` coordinates.
    pub fn new(degree: Vec<usize>, dim: usize, control: Vec<T>) -> Result<Self> {
        let set = IndexSet::boxed(&degree)?;
        if dim == 0 {
            return Err(Error::invalid("dim: values need at least one coordinate"));
        }
        if control.len() != set.len() * dim {
            return Err(Error::invalid(format!(
                "control: degrees {degree:?} need {} control points × {dim} coordinates = {} \
                 values, got {}",
                set.len(),
                set.len() * dim,
                control.len()
            )));
        }
        Ok(TensorBezier {
            degree,
            dim,
            set,
            control,
        })
    }

    /// The patch whose derivatives at the origin corner are `derivs` (`∂^σ P(0)` for every
    /// `σ ≤ d`, in storage order): Theorem 2 of seed 001 for every `α`.
    pub fn from_corner_derivatives(degree: Vec<usize>, dim: usize, derivs: &[T]) -> Result<Self> {
        let control = box_control_from_derivatives(&degree, dim, derivs)?;
        Self::new(degree, dim, control)
    }

    /// Degrees `d`.
    pub fn degree(&self) -> &[usize] {
        &self.degree
    }
    /// Number of variables `m`.
    pub fn vars(&self) -> usize {
        self.degree.len()
    }
    /// Coordinates per value.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// The index set `{α ≤ d}` in storage order.
    pub fn index_set(&self) -> &IndexSet {
        &self.set
    }
    /// All control points, flat.
    pub fn control(&self) -> &[T] {
        &self.control
    }
    /// `P_α`, if `α ≤ d`.
    pub fn control_point(&self, alpha: &[usize]) -> Option<&[T]> {
        let p = self.set.position(alpha)?;
        Some(&self.control[p * self.dim..(p + 1) * self.dim])
    }

    /// `P(x)` by de Casteljau's algorithm, one axis at a time (last axis first).
    pub fn eval(&self, x: &[T]) -> Result<Vec<T>> {
        self.check_x(x)?;
        Ok(contract(
            self.control.clone(),
            self.degree.iter().map(|d| d + 1).collect(),
            self.dim,
            x,
        ))
    }

    /// `∂^{|σ|} P / ∂x^σ (x)`, exact: `Π_i d_i!/(d_i−σ_i)!` times the patch of degree `d − σ`
    /// with the control points `Δ^σ P_β` (zero where some `σ_i > d_i`).
    pub fn derivative(&self, x: &[T], sigma: &[usize]) -> Result<Vec<T>> {
        self.check_x(x)?;
        if sigma.len() != self.vars() {
            return Err(Error::invalid(format!(
                "sigma = {sigma:?}: expected {} components",
                self.vars()
            )));
        }
        if sigma.iter().zip(&self.degree).any(|(s, d)| s > d) {
            return Ok(vec![T::zero(); self.dim]);
        }
        let mut shape: Vec<usize> = self.degree.iter().map(|d| d + 1).collect();
        let mut data = self.control.clone();
        let mut f = T::one();
        for (j, &s) in sigma.iter().enumerate() {
            for _ in 0..s {
                data = diff_axis(&data, &mut shape, self.dim, j);
            }
            f = f * falling::<T>(self.degree[j], s);
        }
        let v = contract(data, shape, self.dim, x);
        Ok(v.into_iter().map(|c| c * f.clone()).collect())
    }

    /// `∂^σ P(0)` for every `σ ≤ d` in storage order: `d!/(d−σ)! Δ^σ P_0` (Theorem 1, Eq. 1,
    /// scaled).
    pub fn corner_derivatives(&self) -> Vec<T> {
        let mut a = forward_differences(&self.set, self.dim, &self.control)
            .expect("lengths checked at construction");
        for (pos, sigma) in self.set.indices().iter().enumerate() {
            let mut f = T::one();
            for (d, s) in self.degree.iter().zip(sigma) {
                f = f * falling::<T>(*d, *s);
            }
            for x in &mut a[pos * self.dim..(pos + 1) * self.dim] {
                *x = x.clone() * f.clone();
            }
        }
        a
    }

    fn check_x(&self, x: &[T]) -> Result<()> {
        if x.len() != self.vars() {
            return Err(Error::invalid(format!(
                "x: expected {} coordinates, got {}",
                self.vars(),
                x.len()
            )));
        }
        Ok(())
    }
}

/// Forward difference along axis `j` of a dense array of the given shape (last axis fastest,
/// `dim` coordinates per entry); `shape[j]` shrinks by one.
fn diff_axis<T: Scalar>(data: &[T], shape: &mut [usize], dim: usize, j: usize) -> Vec<T> {
    let inner: usize = shape[j + 1..].iter().product::<usize>() * dim;
    let outer: usize = shape[..j].iter().product();
    let len = shape[j];
    let mut out = Vec::with_capacity(outer * (len - 1) * inner);
    for o in 0..outer {
        for k in 0..len - 1 {
            let lo = (o * len + k) * inner;
            let hi = (o * len + k + 1) * inner;
            for c in 0..inner {
                out.push(data[hi + c].clone() - data[lo + c].clone());
            }
        }
    }
    shape[j] -= 1;
    out
}

/// de Casteljau along the last axis, then the next, … down to one value of `dim` coordinates.
fn contract<T: Scalar>(mut data: Vec<T>, mut shape: Vec<usize>, dim: usize, x: &[T]) -> Vec<T> {
    while let Some(len) = shape.pop() {
        let t = x[shape.len()].clone();
        let s = T::one() - t.clone();
        let blocks = data.len() / (len * dim);
        let mut out = Vec::with_capacity(blocks * dim);
        for b in 0..blocks {
            let w = &mut data[b * len * dim..(b + 1) * len * dim];
            for r in 1..len {
                for i in 0..len - r {
                    for c in 0..dim {
                        let v = w[i * dim + c].clone() * s.clone()
                            + w[(i + 1) * dim + c].clone() * t.clone();
                        w[i * dim + c] = v;
                    }
                }
            }
            out.extend_from_slice(&w[..dim]);
        }
        data = out;
    }
    data
}
