//! B-spline basis functions as polynomials on each knot span, and at single points.
//!
//! On a non-empty span `[u_k, u_{k+1})` of a knot vector `U = {u_0, …, u_{n+p+1}}` only
//! `N_{k−p,p}, …, N_{k,p}` are non-zero, and each is a polynomial of degree `p`. We write it in the
//! local variable `s = (u − u_k)/h`, `h = u_{k+1} − u_k`, so that `s ∈ [0, 1]`, and build it with
//! the Cox–de Boor recursion (seed 003 §3)
//! `N_{i,r}(u) = (u − u_i)/(u_{i+r} − u_i) N_{i,r−1}(u) + (u_{i+r+1} − u)/(u_{i+r+1} − u_{i+1}) N_{i+1,r−1}(u)`
//! carried out on polynomial coefficients (a quotient with a zero denominator counts as 0).

use super::scalar::Scalar;
use crate::spline::knots::{basis_derivatives, find_span, KnotRule};
use crate::{Error, Result};

/// Polynomial coefficients `c_0 + c_1 s + …` in a local variable.
pub(super) type Poly<T> = Vec<T>;

/// `d^k/ds^k` of a polynomial.
pub(super) fn poly_derivative<T: Scalar>(p: &[T], k: usize) -> Poly<T> {
    if k >= p.len() {
        return Vec::new();
    }
    (k..p.len())
        .map(|n| {
            // n (n−1) … (n−k+1)
            let f: i64 = ((n - k + 1)..=n).map(|x| x as i64).product();
            p[n].clone() * T::int(f)
        })
        .collect()
}

/// `∫_0^1 p(s) q(s) ds`, exactly as far as the scalar allows.
pub(super) fn poly_inner01<T: Scalar>(p: &[T], q: &[T]) -> T {
    let mut acc = T::zero();
    for (a, pa) in p.iter().enumerate() {
        if pa.is_zero() {
            continue;
        }
        for (b, qb) in q.iter().enumerate() {
            if qb.is_zero() {
                continue;
            }
            acc = acc + pa.clone() * qb.clone() / T::int((a + b + 1) as i64);
        }
    }
    acc
}

/// One direction of a tensor-product spline space: degree and knot vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Direction<T> {
    /// Polynomial degree `p`.
    pub degree: usize,
    /// Knot vector `u_0 ≤ … ≤ u_{n+p+1}` (see [`Direction::check`]).
    pub knots: Vec<T>,
}

/// The basis of one non-empty knot span.
#[derive(Clone, Debug)]
pub struct Span<T> {
    /// Index `k` of the span `[u_k, u_{k+1})`.
    pub k: usize,
    /// `h = u_{k+1} − u_k > 0`.
    pub h: T,
    /// `polys[r]` is `N_{k−p+r,p}` in the local variable `s`.
    pub polys: Vec<Poly<T>>,
}

impl<T: Scalar> Direction<T> {
    /// Number of control points `n + 1 = #knots − p − 1`.
    pub fn count(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// The parameter domain `[u_p, u_{n+1}]`.
    pub fn domain(&self) -> (T, T) {
        (
            self.knots[self.degree].clone(),
            self.knots[self.count()].clone(),
        )
    }

    /// Checks: degree 1 to 20 and the knot vector by the crate's one knot rule
    /// ([`crate::spline::bspline_basis`] checks the same): at least `p + 1` control points,
    /// finite non-decreasing knots, a domain of positive length, no knot repeated more than
    /// `p + 1` times nor more than `p` times inside the domain. `name` is `u` or `v`. Errors
    /// name their place: `degree` or `knots_u`/`knots_v`.
    pub fn check(&self, name: &str) -> Result<()> {
        let p = self.degree;
        if p == 0 || p > 20 {
            return Err(Error::invalid(format!(
                "degree in {name} must be between 1 and 20 (got {p})"
            ))
            .at("degree"));
        }
        KnotRule::Open {
            degree: p,
            count: None,
        }
        .check(&self.knots)
        .map_err(|f| f.named(&format!("knots_{name}")))
    }

    /// The basis polynomials of every non-empty span of the domain.
    pub fn spans(&self) -> Vec<Span<T>> {
        let p = self.degree;
        let u = &self.knots;
        (p..self.count())
            .filter(|&k| u[k] != u[k + 1])
            .map(|k| {
                let h = u[k + 1].clone() - u[k].clone();
                // Degree 0: N_{k,0} = 1 on the span. table[r] = N_{k−d+r, d}, r = 0..=d.
                let mut table: Vec<Poly<T>> = vec![vec![T::one()]];
                for d in 1..=p {
                    let mut next = Vec::with_capacity(d + 1);
                    for r in 0..=d {
                        let i = k + r - d; // N_{i,d}
                        let mut acc: Poly<T> = vec![T::zero(); d + 1];
                        // (u − u_i)/(u_{i+d} − u_i) N_{i,d−1}; N_{i,d−1} = table[r − 1] when r ≥ 1.
                        if r >= 1 {
                            let den = u[i + d].clone() - u[i].clone();
                            if !den.is_zero() {
                                let c0 = (u[k].clone() - u[i].clone()) / den.clone();
                                let c1 = h.clone() / den;
                                add_linear_times(&mut acc, &c0, &c1, &table[r - 1]);
                            }
                        }
                        // (u_{i+d+1} − u)/(u_{i+d+1} − u_{i+1}) N_{i+1,d−1} = table[r] when r < d.
                        if r < d {
                            let den = u[i + d + 1].clone() - u[i + 1].clone();
                            if !den.is_zero() {
                                let c0 = (u[i + d + 1].clone() - u[k].clone()) / den.clone();
                                let c1 = -(h.clone() / den);
                                add_linear_times(&mut acc, &c0, &c1, &table[r]);
                            }
                        }
                        next.push(acc);
                    }
                    table = next;
                }
                Span { k, h, polys: table }
            })
            .collect()
    }

    /// The index `k` of the span holding `u` (the last non-empty span for `u` at the end of the
    /// domain). `u` must lie in the domain.
    pub fn find_span(&self, u: &T) -> usize {
        find_span(&self.knots, self.degree, self.count(), u)
    }

    /// `N_{i,p}^{(d)}(u)` for `i = k−p..=k` and `d = 0..=nd`, by the crate's one B-spline basis
    /// (the Cox–de Boor table and the unrolled derivative formula of
    /// [`crate::spline::bspline_basis`], exact in rationals). Independent of
    /// [`Direction::spans`]. Returns `(k, ders)` with `ders[d][r]` for `N_{k−p+r}`.
    pub fn basis_derivatives_at(&self, u: &T, nd: usize) -> (usize, Vec<Vec<T>>) {
        let w = self.degree + 1;
        let k = self.find_span(u);
        let mut flat = vec![T::zero(); (nd + 1) * w];
        basis_derivatives(&self.knots, self.degree, k, u, nd, &mut flat);
        (k, flat.chunks(w).map(<[T]>::to_vec).collect())
    }
}

/// `acc += (c0 + c1 s) · q`.
fn add_linear_times<T: Scalar>(acc: &mut [T], c0: &T, c1: &T, q: &[T]) {
    for (n, qn) in q.iter().enumerate() {
        if qn.is_zero() {
            continue;
        }
        acc[n] = acc[n].clone() + c0.clone() * qn.clone();
        acc[n + 1] = acc[n + 1].clone() + c1.clone() * qn.clone();
    }
}
