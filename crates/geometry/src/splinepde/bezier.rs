//! Named special cases: Bézier patches (one span, clamped knots), harmonic and biharmonic
//! Bézier surfaces from boundary rows and rings (book §8.3, after Monterde and Ugail), and the
//! control-point masks of Eqs. (8.10)–(8.11) as corrected in `docs/errata.md`.

use super::basis::Direction;
use super::engine::{solve, Point, SplineNet, SplineProblem};
use super::linalg::Solve;
use super::operator::Operator;
use super::scalar::Scalar;
use crate::{Error, Result};

/// The knot vector of a Bézier direction of degree `n`: `0` and `1`, each `n + 1` times.
pub fn bezier_direction<T: Scalar>(n: usize) -> Direction<T> {
    let mut knots = vec![T::zero(); n + 1];
    knots.extend(vec![T::one(); n + 1]);
    Direction { degree: n, knots }
}

/// A clamped uniform knot vector on `[0, 1]`: degree `p`, `spans` equal spans (`p + spans`
/// control points), interior knots `k/spans` (exact in rational mode).
pub fn clamped_uniform<T: Scalar>(p: usize, spans: usize) -> Direction<T> {
    let mut knots = vec![T::zero(); p + 1];
    for k in 1..spans {
        knots.push(T::int(k as i64) / T::int(spans as i64));
    }
    knots.extend(vec![T::one(); p + 1]);
    Direction { degree: p, knots }
}

/// The harmonic Bézier surface (`x_uu + x_vv = 0`) of degree `n × m` whose first and last rows
/// `P_{0,j}` and `P_{n,j}` (`j = 0..=m`) are given (book §8.3). The report says whether they
/// determine the net; where they do not, the Dirichlet functional picks it.
pub fn harmonic_bezier<T: Solve>(
    degree: [usize; 2],
    first_row: &[Point<T>],
    last_row: &[Point<T>],
) -> Result<SplineNet<T>> {
    let [n, m] = degree;
    for (name, row) in [("first_row", first_row), ("last_row", last_row)] {
        if row.len() != m + 1 {
            return Err(Error::invalid(format!(
                "needs m + 1 = {} points for degree {m} in v (got {})",
                m + 1,
                row.len()
            ))
            .at(name));
        }
    }
    let mut fixed = Vec::new();
    for j in 0..=m {
        fixed.push(([0, j], first_row[j].clone()));
        fixed.push(([n, j], last_row[j].clone()));
    }
    solve(&SplineProblem {
        u: bezier_direction(n),
        v: bezier_direction(m),
        operator: Operator::laplace(),
        fixed,
    })
}

/// The indices of the outer `rings` rings of an `(n+1) × (m+1)` net (ring 1: the boundary
/// control points; ring 2 adds the points next to them, which carry the boundary tangents).
pub fn ring_indices(degree: [usize; 2], rings: usize) -> Vec<[usize; 2]> {
    let [n, m] = degree;
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=m {
            let d = i.min(n - i).min(j).min(m - j);
            if d < rings {
                out.push([i, j]);
            }
        }
    }
    out
}

/// The Bézier surface of degree `n × m` solving `op` whose outer `rings` rings of control points
/// are taken from `net` (row-major, `(n+1)(m+1)` points; the inner points of `net` are ignored).
/// With `Operator::biharmonic()` and `rings = 2` these are the biharmonic Bézier surfaces of
/// book §8.3 (boundary curves and the cross-boundary tangents).
pub fn bezier_from_rings<T: Solve>(
    degree: [usize; 2],
    op: Operator,
    rings: usize,
    net: &[Point<T>],
) -> Result<SplineNet<T>> {
    let [n, m] = degree;
    if net.len() != (n + 1) * (m + 1) {
        return Err(Error::invalid(format!(
            "needs (n + 1)(m + 1) = {} points (got {})",
            (n + 1) * (m + 1),
            net.len()
        ))
        .at("net"));
    }
    let fixed = ring_indices(degree, rings)
        .into_iter()
        .map(|[i, j]| ([i, j], net[i * (m + 1) + j].clone()))
        .collect();
    solve(&SplineProblem {
        u: bezier_direction(n),
        v: bezier_direction(m),
        operator: op,
        fixed,
    })
}

/// `a_{n,i,k}` of book §8.3: `(n−i)(n−i−1)`, `2(i+1)(n−i−1)`, `(i+1)(i+2)` for `k = 0, 1, 2` and
/// `i ∈ {0, …, n−2}`; zero otherwise. (Degree elevation of `B^{n−2}_i` to degree `n`, times
/// `n(n−1)`.)
pub fn a_coef(n: usize, i: i64, k: usize) -> i64 {
    let n = n as i64;
    if i < 0 || i > n - 2 {
        return 0;
    }
    match k {
        0 => (n - i) * (n - i - 1),
        1 => 2 * (i + 1) * (n - i - 1),
        2 => (i + 1) * (i + 2),
        _ => 0,
    }
}

/// `b_{n,i,k}` of book §8.3 (`i ∈ {0, …, n−4}`, zero otherwise): degree elevation of
/// `B^{n−4}_i` to degree `n`, times `n(n−1)(n−2)(n−3)`.
pub fn b_coef(n: usize, i: i64, k: usize) -> i64 {
    let n = n as i64;
    if i < 0 || i > n - 4 {
        return 0;
    }
    match k {
        0 => (n - i) * (n - i - 1) * (n - i - 2) * (n - i - 3),
        1 => 4 * (i + 1) * (n - i - 1) * (n - i - 2) * (n - i - 3),
        2 => 6 * (i + 1) * (i + 2) * (n - i - 2) * (n - i - 3),
        3 => 4 * (i + 1) * (i + 2) * (i + 3) * (n - i - 3),
        4 => (i + 1) * (i + 2) * (i + 3) * (i + 4),
        _ => 0,
    }
}

/// Net access with zero outside the index range (terms whose coefficient vanishes there).
fn at<T: Scalar>(net: &[Point<T>], m: usize, n: usize, i: i64, j: i64) -> Point<T> {
    if i < 0 || j < 0 || i > n as i64 || j > m as i64 {
        return [T::zero(), T::zero(), T::zero()];
    }
    net[i as usize * (m + 1) + j as usize].clone()
}

fn axpy<T: Scalar>(acc: &mut Point<T>, w: i64, p: &Point<T>) {
    if w == 0 {
        return;
    }
    let w = T::int(w);
    for d in 0..3 {
        acc[d] = acc[d].clone() + w.clone() * p[d].clone();
    }
}

/// The harmonic mask of book Eq. (8.10) at `(i, j)` for a net of degree `n × m` (the book takes
/// `m = n`), with the stray factor `b` removed:
/// `Σ` over the five points of the row mask with `a_{n,·,·}` plus the column mask with
/// `a_{m,·,·}`. It is the coefficient of `B^n_i(u) B^m_j(v)` in `x_uu + x_vv` written in the
/// degree-`(n, m)` Bernstein basis, so the surface is harmonic iff it vanishes for every
/// `i = 0..=n`, `j = 0..=m`.
pub fn harmonic_mask<T: Scalar>(
    degree: [usize; 2],
    net: &[Point<T>],
    i: usize,
    j: usize,
) -> Point<T> {
    let [n, m] = degree;
    let (i, j) = (i as i64, j as i64);
    let p = |a: i64, b: i64| at(net, m, n, a, b);
    let mut acc = [T::zero(), T::zero(), T::zero()];
    let an = |x: i64, k: usize| a_coef(n, x, k);
    let am = |x: i64, k: usize| a_coef(m, x, k);
    axpy(&mut acc, an(i, 0), &p(i + 2, j));
    axpy(&mut acc, an(i - 1, 1) - 2 * an(i, 0), &p(i + 1, j));
    axpy(&mut acc, an(i - 1, 1) - 2 * an(i - 2, 2), &p(i - 1, j));
    axpy(&mut acc, an(i - 2, 2), &p(i - 2, j));
    axpy(&mut acc, am(j, 0), &p(i, j + 2));
    axpy(&mut acc, am(j - 1, 1) - 2 * am(j, 0), &p(i, j + 1));
    axpy(&mut acc, am(j - 1, 1) - 2 * am(j - 2, 2), &p(i, j - 1));
    axpy(&mut acc, am(j - 2, 2), &p(i, j - 2));
    axpy(
        &mut acc,
        an(i, 0) - 2 * an(i - 1, 1) + an(i - 2, 2) + am(j, 0) - 2 * am(j - 1, 1) + am(j - 2, 2),
        &p(i, j),
    );
    acc
}

/// `Δ^{r,s} P_{i,j} = Σ_{a,b} (−1)^{r−a+s−b} C(r,a) C(s,b) P_{i+a,j+b}`.
fn forward_difference<T: Scalar>(
    net: &[Point<T>],
    degree: [usize; 2],
    r: usize,
    s: usize,
    i: i64,
    j: i64,
) -> Point<T> {
    let [n, m] = degree;
    let binom = |n: usize, k: usize| -> i64 {
        (0..k).fold(1i64, |acc, x| acc * (n - x) as i64 / (x + 1) as i64)
    };
    let mut acc = [T::zero(), T::zero(), T::zero()];
    for a in 0..=r {
        for b in 0..=s {
            let sign = if (r - a + s - b).is_multiple_of(2) {
                1
            } else {
                -1
            };
            axpy(
                &mut acc,
                sign * binom(r, a) * binom(s, b),
                &at(net, m, n, i + a as i64, j + b as i64),
            );
        }
    }
    acc
}

/// The biharmonic mask of book Eq. (8.11) at `(i, j)` (the printed expression, with `= 0`
/// understood): `Σ_k b_{n,i−k,k} Δ^{4,0}P_{i−k,j} + 2 Σ_{k,l} a_{n,i−k,k} a_{m,j−l,l}
/// Δ^{2,2}P_{i−k,j−l} + Σ_l b_{m,j−l,l} Δ^{0,4}P_{i,j−l}`: the coefficient of
/// `B^n_i(u) B^m_j(v)` in `x_uuuu + 2 x_uuvv + x_vvvv`, for `i = 0..=n`, `j = 0..=m`.
pub fn biharmonic_mask<T: Scalar>(
    degree: [usize; 2],
    net: &[Point<T>],
    i: usize,
    j: usize,
) -> Point<T> {
    let [n, m] = degree;
    let (i, j) = (i as i64, j as i64);
    let mut acc = [T::zero(), T::zero(), T::zero()];
    for k in 0..=4usize {
        let w = b_coef(n, i - k as i64, k);
        if w != 0 {
            axpy(
                &mut acc,
                w,
                &forward_difference(net, degree, 4, 0, i - k as i64, j),
            );
        }
        let w = b_coef(m, j - k as i64, k);
        if w != 0 {
            axpy(
                &mut acc,
                w,
                &forward_difference(net, degree, 0, 4, i, j - k as i64),
            );
        }
    }
    for k in 0..=2usize {
        for l in 0..=2usize {
            let w = 2 * a_coef(n, i - k as i64, k) * a_coef(m, j - l as i64, l);
            if w != 0 {
                axpy(
                    &mut acc,
                    w,
                    &forward_difference(net, degree, 2, 2, i - k as i64, j - l as i64),
                );
            }
        }
    }
    acc
}
