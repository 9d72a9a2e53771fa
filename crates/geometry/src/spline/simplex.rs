//! Bézier patches of degree `n` on a simplex in R^m with values in R^dim, generic over the
//! scalar (seed 001 §3, Theorem 3; triangles are `m = 2`, Corollary 3.1).

use super::dual::{forward_differences, simplex_control_from_derivatives};
use super::scalar::{falling, IndexSet, Scalar};
use crate::{Error, Result};

/// `b_n(λ) = Σ_{|α|≤n} C_α B_α^n(λ) = (λ_1 E_1 + … + λ_m E_m + (1 − |λ|) I)^n C_0` on the simplex
/// `V_m = ⟨V^{(1)}, …, V^{(m+1)}⟩`, in the coordinates `λ = (λ_1, …, λ_m)` of the point
/// `Σ_{i≤m} λ_i V^{(i)} + λ_{m+1} V^{(m+1)}` with `λ_{m+1} = 1 − |λ|`, and
/// `B_α^n(λ) = n!/(α! (n−|α|)!) λ^α (1 − |λ|)^{n−|α|}`. Control points are indexed by
/// `α ∈ Z₊ᵐ`, `|α| ≤ n` (the barycentric index `(α, n − |α|)`), stored in the order of
/// `IndexSet::simplex(m, n)`, `dim` coordinates each.
///
/// Derivatives are in `λ_1 … λ_m` (so `∂/∂λ_i` is the barycentric direction
/// `e_i − e_{m+1}`, i.e. along the edge `V^{(m+1)} → V^{(i)}`): with
/// `Δ_i C_β = C_{β+e_i} − C_β`, `∂^σ b_n/∂λ^σ = n!/(n−|σ|)! Σ_{|β|≤n−|σ|} Δ^σ C_β B_β^{n−|σ|}`.
#[derive(Clone, Debug, PartialEq)]
pub struct SimplexBezier<T: Scalar> {
    n: usize,
    dim: usize,
    set: IndexSet,
    control: Vec<T>,
}

impl<T: Scalar> SimplexBezier<T> {
    /// A patch of degree `n` on a simplex in R^m (`m ≥ 1`) with `C(n+m, m)` control points of
    /// `dim ≥ 1` coordinates.
    pub fn new(m: usize, n: usize, dim: usize, control: Vec<T>) -> Result<Self> {
        let set = IndexSet::simplex(m, n)?;
        if dim == 0 {
            return Err(Error::invalid("dim: values need at least one coordinate"));
        }
        if control.len() != set.len() * dim {
            return Err(Error::invalid(format!(
                "control: degree {n} on a simplex in R^{m} needs {} control points × {dim} \
                 coordinates = {} values, got {}",
                set.len(),
                set.len() * dim,
                control.len()
            )));
        }
        Ok(SimplexBezier {
            n,
            dim,
            set,
            control,
        })
    }

    /// The patch whose derivatives `∂^σ b_n(0)/∂λ^σ` (every `|σ| ≤ n`, storage order) are
    /// `derivs`: Theorem 3 of seed 001 for every `α`.
    pub fn from_corner_derivatives(m: usize, n: usize, dim: usize, derivs: &[T]) -> Result<Self> {
        let control = simplex_control_from_derivatives(m, n, dim, derivs)?;
        Self::new(m, n, dim, control)
    }

    /// Degree `n`.
    pub fn degree(&self) -> usize {
        self.n
    }
    /// Number of variables `m`.
    pub fn vars(&self) -> usize {
        self.set.vars()
    }
    /// Coordinates per value.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// The index set `{|α| ≤ n}` in storage order.
    pub fn index_set(&self) -> &IndexSet {
        &self.set
    }
    /// All control points, flat.
    pub fn control(&self) -> &[T] {
        &self.control
    }
    /// `C_α`, if `|α| ≤ n`.
    pub fn control_point(&self, alpha: &[usize]) -> Option<&[T]> {
        let p = self.set.position(alpha)?;
        Some(&self.control[p * self.dim..(p + 1) * self.dim])
    }

    /// `b_n(λ)` by de Casteljau's algorithm:
    /// `C^{(r)}_β = Σ_{i≤m} λ_i C^{(r−1)}_{β+e_i} + λ_{m+1} C^{(r−1)}_β`, `|β| ≤ n − r`.
    pub fn eval(&self, lambda: &[T]) -> Result<Vec<T>> {
        self.check_lambda(lambda)?;
        Ok(self.casteljau(self.control.clone(), self.n, lambda))
    }

    /// `∂^{|σ|} b_n / ∂λ^σ (λ)`, exact (zero for `|σ| > n`).
    pub fn derivative(&self, lambda: &[T], sigma: &[usize]) -> Result<Vec<T>> {
        if sigma.len() != self.vars() {
            return Err(Error::invalid(format!(
                "sigma = {sigma:?}: expected {} components",
                self.vars()
            )));
        }
        if sigma.iter().fold(0usize, |a, s| a.saturating_add(*s)) > self.n {
            self.check_lambda(lambda)?;
            return Ok(vec![T::zero(); self.dim]);
        }
        let mut dirs = Vec::new();
        for (i, &s) in sigma.iter().enumerate() {
            let mut e = vec![T::zero(); self.vars()];
            e[i] = T::one();
            dirs.extend(std::iter::repeat_n(e, s));
        }
        self.directional(lambda, &dirs)
    }

    /// The directional derivative `D_{u_1} ⋯ D_{u_k} b_n(λ)` along the vectors `u_j` given in
    /// λ-coordinates (`m` components each; the barycentric direction is
    /// `(u_1, …, u_m, −Σ u_i)`): `n!/(n−k)!` times the patch of degree `n − k` with control
    /// points `Π_j (Σ_i u_{j,i} Δ_i) C_β` (zero for `k > n`).
    pub fn directional(&self, lambda: &[T], dirs: &[Vec<T>]) -> Result<Vec<T>> {
        self.check_lambda(lambda)?;
        for (j, d) in dirs.iter().enumerate() {
            if d.len() != self.vars() {
                return Err(Error::invalid(format!(
                    "dirs[{j}]: expected {} components, got {}",
                    self.vars(),
                    d.len()
                )));
            }
        }
        let k = dirs.len();
        if k > self.n {
            return Ok(vec![T::zero(); self.dim]);
        }
        let mut data = self.control.clone();
        let (m, dim) = (self.vars(), self.dim);
        let mut up = vec![0; m];
        for (j, d) in dirs.iter().enumerate() {
            // Degree n − j → n − j − 1, in place in ascending order (β + e_i comes later).
            let deg = self.n - j;
            for (pos, beta) in self.set.indices().iter().enumerate() {
                if beta.iter().sum::<usize>() + 1 > deg {
                    continue;
                }
                let mut acc = vec![T::zero(); dim];
                for i in 0..m {
                    if d[i] == T::zero() {
                        continue;
                    }
                    up.copy_from_slice(beta);
                    up[i] += 1;
                    let q = self.set.position(&up).expect("inside the simplex");
                    for c in 0..dim {
                        acc[c] = acc[c].clone()
                            + d[i].clone()
                                * (data[q * dim + c].clone() - data[pos * dim + c].clone());
                    }
                }
                data[pos * dim..(pos + 1) * dim].clone_from_slice(&acc);
            }
        }
        let f = falling::<T>(self.n, k);
        let v = self.casteljau(data, self.n - k, lambda);
        Ok(v.into_iter().map(|c| c * f.clone()).collect())
    }

    /// `∂^σ b_n(0)/∂λ^σ` for every `|σ| ≤ n` in storage order: `n!/(n−|σ|)! Δ^σ C_0`.
    pub fn corner_derivatives(&self) -> Vec<T> {
        let mut a = forward_differences(&self.set, self.dim, &self.control)
            .expect("lengths checked at construction");
        for (pos, sigma) in self.set.indices().iter().enumerate() {
            let f = falling::<T>(self.n, sigma.iter().sum());
            for x in &mut a[pos * self.dim..(pos + 1) * self.dim] {
                *x = x.clone() * f.clone();
            }
        }
        a
    }

    /// de Casteljau on the members `|β| ≤ deg` of `data` (laid out on the full set), in place
    /// in ascending order: `C_β` is overwritten after every `C_{β−e_i}` has read it.
    fn casteljau(&self, mut data: Vec<T>, deg: usize, lambda: &[T]) -> Vec<T> {
        let (m, dim) = (self.vars(), self.dim);
        let last = lambda.iter().fold(T::one(), |acc, l| acc - l.clone());
        let mut up = vec![0; m];
        for r in 1..=deg {
            for (pos, beta) in self.set.indices().iter().enumerate() {
                if beta.iter().sum::<usize>() > deg - r {
                    continue;
                }
                let mut acc: Vec<T> = data[pos * dim..(pos + 1) * dim]
                    .iter()
                    .map(|x| x.clone() * last.clone())
                    .collect();
                for i in 0..m {
                    up.copy_from_slice(beta);
                    up[i] += 1;
                    let q = self.set.position(&up).expect("inside the simplex");
                    for c in 0..dim {
                        acc[c] = acc[c].clone() + lambda[i].clone() * data[q * dim + c].clone();
                    }
                }
                data[pos * dim..(pos + 1) * dim].clone_from_slice(&acc);
            }
        }
        data.truncate(dim);
        data
    }

    fn check_lambda(&self, lambda: &[T]) -> Result<()> {
        if lambda.len() != self.vars() {
            return Err(Error::invalid(format!(
                "lambda: expected {} coordinates, got {}",
                self.vars(),
                lambda.len()
            )));
        }
        Ok(())
    }
}

/// The coordinates `λ = (λ_1, …, λ_m)` of the point `x ∈ R^m` with respect to the simplex
/// `⟨V^{(1)}, …, V^{(m+1)}⟩` (`vertices`, `m + 1` points of `m` coordinates): the solution of
/// `Σ_{i≤m} λ_i (V^{(i)} − V^{(m+1)}) = x − V^{(m+1)}`, so `x = Σ_{i≤m} λ_i V^{(i)} + λ_{m+1} V^{(m+1)}`
/// with `λ_{m+1} = 1 − |λ|`. Gaussian elimination with partial pivoting (exact in rationals).
/// A degenerate simplex is an error (in `f64`: a pivot below `1e-13·m` times the largest edge
/// coordinate).
pub fn simplex_coordinates<T: Scalar>(vertices: &[Vec<T>], x: &[T]) -> Result<Vec<T>> {
    let m = check_vertices(vertices)?;
    if x.len() != m {
        return Err(Error::invalid(format!(
            "x: expected {m} coordinates, got {}",
            x.len()
        )));
    }
    let rhs: Vec<T> = (0..m)
        .map(|r| x[r].clone() - vertices[m][r].clone())
        .collect();
    solve_edges(vertices, rhs)
}

/// The λ-coordinates of a direction `w ∈ R^m`: `Σ_{i≤m} d_i (V^{(i)} − V^{(m+1)}) = w`. The
/// derivative of a patch along `w` in the domain's own coordinates is then
/// [`SimplexBezier::directional`] along `d` (chain rule: `λ` is an affine function of `x`).
pub fn simplex_direction<T: Scalar>(vertices: &[Vec<T>], w: &[T]) -> Result<Vec<T>> {
    let m = check_vertices(vertices)?;
    if w.len() != m {
        return Err(Error::invalid(format!(
            "w: expected {m} coordinates, got {}",
            w.len()
        )));
    }
    solve_edges(vertices, w.to_vec())
}

fn check_vertices<T: Scalar>(vertices: &[Vec<T>]) -> Result<usize> {
    if vertices.len() < 2 {
        return Err(Error::invalid(format!(
            "vertices: a simplex in R^m needs m + 1 ≥ 2 vertices, got {}",
            vertices.len()
        )));
    }
    let m = vertices.len() - 1;
    for (i, v) in vertices.iter().enumerate() {
        if v.len() != m {
            return Err(Error::invalid(format!(
                "vertices[{i}]: expected {m} coordinates, got {}",
                v.len()
            )));
        }
        if v.iter().any(|c| !c.to_f64().is_finite()) {
            return Err(Error::invalid(format!(
                "vertices[{i}] = {v:?} is not finite"
            )));
        }
    }
    Ok(m)
}

/// Solves `A d = rhs` with the columns `A_i = V^{(i)} − V^{(m+1)}`.
fn solve_edges<T: Scalar>(vertices: &[Vec<T>], mut rhs: Vec<T>) -> Result<Vec<T>> {
    let m = vertices.len() - 1;
    // a[r][c] = V^{(c)}_r − V^{(m+1)}_r
    let mut a: Vec<Vec<T>> = (0..m)
        .map(|r| {
            (0..m)
                .map(|c| vertices[c][r].clone() - vertices[m][r].clone())
                .collect()
        })
        .collect();
    let scale = a
        .iter()
        .flatten()
        .map(|x| x.to_f64().abs())
        .fold(0.0, f64::max);
    let degenerate = || {
        Error::invalid(format!(
            "vertices: the simplex is degenerate (its {m} edges from the last vertex are \
             linearly dependent)"
        ))
    };
    for col in 0..m {
        let piv = (col..m)
            .max_by(|&i, &j| {
                a[i][col]
                    .to_f64()
                    .abs()
                    .total_cmp(&a[j][col].to_f64().abs())
            })
            .expect("non-empty range");
        // Exact zero (rationals), or a pivot at the rounding level of the edges (f64).
        if a[piv][col] == T::zero()
            || (!T::EXACT && a[piv][col].to_f64().abs() <= 1e-13 * scale * (m as f64))
        {
            return Err(degenerate());
        }
        a.swap(col, piv);
        rhs.swap(col, piv);
        for r in col + 1..m {
            let f = a[r][col].clone() / a[col][col].clone();
            if f == T::zero() {
                continue;
            }
            let pivot_row = a[col].clone();
            for (x, p) in a[r][col..].iter_mut().zip(&pivot_row[col..]) {
                *x = x.clone() - f.clone() * p.clone();
            }
            let v = rhs[r].clone() - f * rhs[col].clone();
            rhs[r] = v;
        }
    }
    let mut d = vec![T::zero(); m];
    for r in (0..m).rev() {
        let mut acc = rhs[r].clone();
        for c in r + 1..m {
            acc = acc - a[r][c].clone() * d[c].clone();
        }
        d[r] = acc / a[r][r].clone();
    }
    Ok(d)
}
