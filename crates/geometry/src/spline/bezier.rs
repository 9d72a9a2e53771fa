//! Tensor-product Bézier surfaces on `[0, 1]²`.

use super::bspline::{check_control, BSplineSurface};
use crate::surface::{Partials, RowEvaluator, Surface, VDomain};
use crate::{Error, Result, Vec3};

/// Tensor-product Bézier patch of degrees `[n, m]` on `[0, 1]²`:
/// `X(u, v) = Σ_{i=0}^{n} Σ_{j=0}^{m} P_{ij} B_i^n(u) B_j^m(v)` with the Bernstein polynomials
/// `B_i^n(u) = C(n, i) uⁱ (1 − u)ⁿ⁻ⁱ`; in operator form (seed 001 Eq. 7)
/// `X = (I + uΔ₁)ⁿ (I + vΔ₂)ᵐ P_{00}`. Control points row-major: `P_{ij}` at `i·(m+1) + j`.
///
/// Evaluation is de Casteljau's algorithm (first along `v` on every row, then along `u`);
/// derivatives are the Bézier patches of the forward differences of the net,
/// `∂^{k+l}X/∂uᵏ∂vˡ = n!/(n−k)! · m!/(m−l)! · Σ_{i≤n−k} Σ_{j≤m−l} Δ₁ᵏΔ₂ˡ P_{ij} B_i^{n−k}(u) B_j^{m−l}(v)`.
/// Outside `[0, 1]²` the polynomial is extended. The [`Surface`] domain is `u ∈ [0, 1]`,
/// `VDomain::Interval(0, 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierSurface {
    degree: [usize; 2],
    control: Vec<Vec3>,
    /// The same patch as a one-span B-spline: `Surface::partials` and the grid rows use its
    /// basis tables (the Cox–de Boor basis on `0^{n+1} 1^{n+1}` is the Bernstein basis).
    spline: BSplineSurface,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for BezierSurface {}

impl BezierSurface {
    /// A patch of degrees `[n, m]` (any, `0` included) with `(n+1)(m+1)` finite control points
    /// row-major.
    pub fn new(degree: [usize; 2], control: Vec<Vec3>) -> Result<Self> {
        let [n, m] = degree;
        let want = n
            .checked_add(1)
            .and_then(|a| m.checked_add(1).and_then(|b| a.checked_mul(b)));
        if want != Some(control.len()) {
            return Err(Error::invalid(format!(
                "control: degrees [{n}, {m}] need ({n} + 1)·({m} + 1) control points, got {}",
                control.len()
            )));
        }
        check_control(&control, m + 1)?;
        Ok(Self::build(degree, control))
    }

    fn build(degree: [usize; 2], control: Vec<Vec3>) -> Self {
        let [n, m] = degree;
        let knots = |d: usize| {
            let mut k = vec![0.0; d + 1];
            k.extend(std::iter::repeat_n(1.0, d + 1));
            k
        };
        let spline = BSplineSurface::new(degree, knots(n), knots(m), control.clone())
            .expect("a valid Bézier net is a valid single-span B-spline net");
        BezierSurface {
            degree,
            control,
            spline,
        }
    }

    /// Degrees `[n, m]`.
    pub fn degree(&self) -> [usize; 2] {
        self.degree
    }

    /// Control points, row-major.
    pub fn control(&self) -> &[Vec3] {
        &self.control
    }

    /// `P_{ij}`.
    pub fn control_point(&self, i: usize, j: usize) -> Vec3 {
        self.control[i * (self.degree[1] + 1) + j]
    }

    /// `∂^{ku+kv} X / ∂u^{ku} ∂v^{kv}` at `(u, v)`, exact for every order (zero above the
    /// degrees), from the differenced net `n!/(n−k)! m!/(m−l)! Δ₁ᵏΔ₂ˡ P` and de Casteljau.
    pub fn derivative(&self, u: f64, v: f64, ku: usize, kv: usize) -> Vec3 {
        let [n, m] = self.degree;
        if ku > n || kv > m {
            return Vec3::zeros();
        }
        let (rows, cols) = (n + 1 - ku, m + 1 - kv);
        let mut net = vec![Vec3::zeros(); rows * cols];
        let w = m + 1;
        // Δ₂ˡ along rows, then Δ₁ᵏ along columns, on a copy of the net.
        let mut work = self.control.clone();
        for _ in 0..kv {
            for i in 0..=n {
                for j in 0..m {
                    work[i * w + j] = work[i * w + j + 1] - work[i * w + j];
                }
            }
        }
        for _ in 0..ku {
            for i in 0..n {
                for j in 0..cols {
                    work[i * w + j] = work[(i + 1) * w + j] - work[i * w + j];
                }
            }
        }
        for i in 0..rows {
            net[i * cols..(i + 1) * cols].copy_from_slice(&work[i * w..i * w + cols]);
        }
        let f = falling(n, ku) * falling(m, kv);
        tensor_de_casteljau(&net, rows, cols, u, v) * f
    }

    /// `X(u, v)` by de Casteljau.
    pub fn point_at(&self, u: f64, v: f64) -> Vec3 {
        let [n, m] = self.degree;
        tensor_de_casteljau(&self.control, n + 1, m + 1, u, v)
    }

    /// The same patch written with degree `n + 1` in `u`:
    /// `Q_i = i/(n+1) P_{i−1} + (1 − i/(n+1)) P_i`, `i = 0..=n+1`, on every column.
    pub fn elevate_degree_u(&self) -> Self {
        let [n, m] = self.degree;
        let w = m + 1;
        let mut out = vec![Vec3::zeros(); (n + 2) * w];
        let nf = (n + 1) as f64;
        for i in 0..=n + 1 {
            let a = i as f64 / nf;
            for j in 0..w {
                let lo = if i >= 1 {
                    self.control[(i - 1) * w + j]
                } else {
                    Vec3::zeros()
                };
                let hi = if i <= n {
                    self.control[i * w + j]
                } else {
                    Vec3::zeros()
                };
                out[i * w + j] = lo * a + hi * (1.0 - a);
            }
        }
        Self::build([n + 1, m], out)
    }

    /// The same patch written with degree `m + 1` in `v`.
    pub fn elevate_degree_v(&self) -> Self {
        self.transposed().elevate_degree_u().transposed()
    }

    /// The same surface with `u` and `v` exchanged.
    pub fn transposed(&self) -> Self {
        let [n, m] = self.degree;
        let mut control = Vec::with_capacity(self.control.len());
        for j in 0..=m {
            for i in 0..=n {
                control.push(self.control[i * (m + 1) + j]);
            }
        }
        Self::build([m, n], control)
    }

    /// The patch as a B-spline surface with one span: knots `0` and `1` each repeated
    /// `degree + 1` times, the same control net.
    pub fn to_bspline(&self) -> BSplineSurface {
        self.spline.clone()
    }
}

/// `n!/(n−k)!` as a float.
pub(crate) fn falling(n: usize, k: usize) -> f64 {
    (n + 1 - k..=n).map(|x| x as f64).product()
}

/// de Casteljau in `v` along each of the `rows` rows of a `rows × cols` net, then in `u`.
pub(crate) fn tensor_de_casteljau(net: &[Vec3], rows: usize, cols: usize, u: f64, v: f64) -> Vec3 {
    let mut col = Vec::with_capacity(rows);
    let mut w = vec![Vec3::zeros(); cols];
    for i in 0..rows {
        w.copy_from_slice(&net[i * cols..(i + 1) * cols]);
        col.push(de_casteljau(&mut w, v));
    }
    de_casteljau(&mut col, u)
}

/// de Casteljau's algorithm on `w` (overwritten): `b_i ← (1 − t) b_i + t b_{i+1}`, repeated.
pub(crate) fn de_casteljau(w: &mut [Vec3], t: f64) -> Vec3 {
    let n = w.len();
    let s = 1.0 - t;
    for r in 1..n {
        for i in 0..n - r {
            w[i] = w[i] * s + w[i + 1] * t;
        }
    }
    w[0]
}

impl Surface for BezierSurface {
    fn v_domain(&self) -> VDomain {
        VDomain::Interval(0.0, 1.0)
    }

    /// From the Bernstein basis values and derivatives (the one-span B-spline's tables).
    fn partials(&self, u: f64, v: f64) -> Partials {
        self.spline.partials(u, v)
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        self.spline.row_evaluator(vs)
    }
}
