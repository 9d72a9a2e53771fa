//! Taylor models of an n-sided surface over a cell of its parameter square, for the CAD
//! export's certified deviation ([`NSidedSurface::taylor_model`]).
//!
//! On a cell `[u_c − h_u, u_c + h_u] × [v_c − h_v, v_c + h_v]`, with the cell's own
//! coordinates `σ = ((u − u_c)/h_u, (v − v_c)/h_v) ∈ [−1, 1]²`, a [`Model`] of a scalar `g`
//! is a polynomial `P(σ) = Σ_{a+b≤4} c_ab σ_u^a σ_v^b` with floating-point coefficients and a
//! radius `r` such that `|g − P| ≤ r` everywhere on the cell. The arithmetic keeps the
//! relation (Makino and Berz's Taylor models):
//!
//! - sums add polynomials and radii;
//! - a product multiplies the polynomials, keeps the terms of degree `≤ 4` and bounds the
//!   others over the square (`|σ_u^a σ_v^b| ≤ 1`) into the radius, with the cross terms
//!   `|P₁| r₂ + |P₂| r₁ + r₁ r₂` (`|P|` the size of a polynomial over the square);
//! - a function `f` of one variable composed with `g` is Taylor's formula about a point `x₀`
//!   of `g`'s range, `f(g) = Σ_{k<m} f⁽ᵏ⁾(x₀)/k! (g − x₀)^k + f⁽ᵐ⁾(ξ)/m! (g − x₀)^m`, the powers
//!   of `g − x₀` taken in the arithmetic and the last term bounded by `sup|f⁽ᵐ⁾| ρ^m / m!`
//!   over `g`'s range (`ρ` the range's reach from `x₀`). `m = 5` where `f⁽⁵⁾` has a proven
//!   bound, else `m = 4`. The derivatives at `x₀` are those of the evaluator itself (the side's
//!   curve, its ribbons, cubics, a neighbour's Chebyshev field, Legendre polynomials), so the
//!   polynomial is `g`'s own Taylor polynomial at the cell's centre to rounding, and the radius
//!   is of the size of the terms of degree five: it falls like `h⁵` with the cell.
//!
//! Unlike interval arithmetic, the polynomial part keeps every cancellation: near a corner the
//! interpolant `Σ B_i R_i` is smooth only because the two ribbons meeting there agree to second
//! order, and a model of `R_a + Σ_{i≠a} B_i (R_i − R_a)` carries the difference as a polynomial
//! with small coefficients. The cell at a corner itself has no model (the blends are `0/0`
//! there): [`NSidedSurface::corner_reach`] bounds it instead.
//!
//! The inputs are exact: the piece's map is bilinear, so the domain point is
//! `x(σ) = x₀ + x_u h_u σ_u + x_v h_v σ_v + x_uv h_u h_v σ_u σ_v` with the map's partials at the
//! cell's centre, and a side's distance is an affine function of it. Floating-point rounding
//! of the coefficients (relative `1e-16` per operation) is not carried: the export's rounding
//! allowance covers it.

use super::side::{BuiltCurvature, BuiltRibbon, BuiltSide, ChebVec};
use super::{NSidedPatch, NSidedSurface};
use crate::curve::SharedCurve;
use crate::elliptic::basis::cheb_diff;
use crate::Vec3;
use std::sync::OnceLock;

/// The degree of the models' polynomials.
pub const MODEL_DEGREE: usize = 4;
/// The number of coefficients of degree `≤ 4`.
pub const MODEL_LEN: usize = 15;
const ORDER: usize = MODEL_DEGREE;
const LEN: usize = MODEL_LEN;

/// The index of the coefficient of `σ_u^a σ_v^b` (`a + b ≤ 4`): by total degree, then `b`.
pub const fn model_index(a: usize, b: usize) -> usize {
    let t = a + b;
    t * (t + 1) / 2 + b
}

/// The exponents `(a, b)` of coefficient `k`.
pub fn model_exponents(k: usize) -> (usize, usize) {
    let mut t = 0;
    while (t + 1) * (t + 2) / 2 <= k {
        t += 1;
    }
    let b = k - t * (t + 1) / 2;
    (t - b, b)
}

/// The products of two coefficients: those kept (`i`, `j`, their product's index) and those of
/// degree above 4 (`i`, `j`, the index `9 a + b` of their monomial).
struct Products {
    kept: Vec<(u8, u8, u8)>,
    high: Vec<(u8, u8, u8)>,
}

fn products() -> &'static Products {
    static P: OnceLock<Products> = OnceLock::new();
    P.get_or_init(|| {
        let (mut kept, mut high) = (Vec::new(), Vec::new());
        for i in 0..LEN {
            let (a1, b1) = model_exponents(i);
            for j in 0..LEN {
                let (a2, b2) = model_exponents(j);
                let (a, b) = (a1 + a2, b1 + b2);
                if a + b <= ORDER {
                    kept.push((i as u8, j as u8, model_index(a, b) as u8));
                } else {
                    high.push((i as u8, j as u8, (9 * a + b) as u8));
                }
            }
        }
        Products { kept, high }
    })
}

/// A scalar's model on a cell (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(super) struct Model {
    c: [f64; LEN],
    r: f64,
}

impl Model {
    fn constant(x: f64) -> Model {
        let mut c = [0.0; LEN];
        c[0] = x;
        Model { c, r: 0.0 }
    }

    /// The range of the polynomial part over the square: each monomial in `[−1, 1]`, or in
    /// `[0, 1]` when both exponents are even.
    fn poly_range(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (self.c[0], self.c[0]);
        for (k, &c) in self.c.iter().enumerate().skip(1) {
            let (a, b) = model_exponents(k);
            if a % 2 == 0 && b % 2 == 0 {
                lo += c.min(0.0);
                hi += c.max(0.0);
            } else {
                lo -= c.abs();
                hi += c.abs();
            }
        }
        (lo, hi)
    }

    /// The range over the square.
    fn range(&self) -> (f64, f64) {
        let (lo, hi) = self.poly_range();
        (lo - self.r, hi + self.r)
    }

    /// `sup|P|` over the square.
    fn poly_size(&self) -> f64 {
        let (lo, hi) = self.poly_range();
        lo.abs().max(hi.abs())
    }

    fn add(&self, o: &Model) -> Model {
        Model {
            c: std::array::from_fn(|k| self.c[k] + o.c[k]),
            r: self.r + o.r,
        }
    }

    fn sub(&self, o: &Model) -> Model {
        Model {
            c: std::array::from_fn(|k| self.c[k] - o.c[k]),
            r: self.r + o.r,
        }
    }

    fn scale(&self, s: f64) -> Model {
        Model {
            c: self.c.map(|x| x * s),
            r: self.r * s.abs(),
        }
    }

    fn mul(&self, o: &Model) -> Model {
        let p = products();
        let mut c = [0.0; LEN];
        for &(i, j, k) in &p.kept {
            c[k as usize] += self.c[i as usize] * o.c[j as usize];
        }
        let mut high = [0.0; 81];
        for &(i, j, k) in &p.high {
            high[k as usize] += self.c[i as usize] * o.c[j as usize];
        }
        let dropped: f64 = high.iter().map(|x| x.abs()).sum();
        let r = dropped + self.poly_size() * o.r + o.poly_size() * self.r + self.r * o.r;
        Model { c, r }
    }

    fn pow(&self, q: usize) -> Model {
        (0..q).fold(Model::constant(1.0), |acc, _| acc.mul(self))
    }
}

/// The powers `(g − x₀)^k / k!` (`k ≤ 4`) of a model, with `x₀` and the reach
/// `ρ = sup|g − x₀|` over the cell: what every function composed with `g` shares.
struct Powers {
    p: [Model; ORDER + 1],
    x0: f64,
    lo: f64,
    hi: f64,
    reach: f64,
}

impl Powers {
    /// `g`'s range is its model's met with `known` (another enclosure of the same range).
    fn new(g: &Model, known: (f64, f64)) -> Powers {
        let (a, b) = g.range();
        let (lo, hi) = (a.max(known.0), b.min(known.1));
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (a, b) };
        let x0 = g.c[0].clamp(lo, hi);
        let mut d = *g;
        d.c[0] -= x0;
        let mut p = [Model::constant(1.0); ORDER + 1];
        for k in 1..=ORDER {
            p[k] = p[k - 1].mul(&d).scale(1.0 / k as f64);
        }
        let reach = (lo - x0).abs().max((hi - x0).abs());
        Powers {
            p,
            x0,
            lo,
            hi,
            reach,
        }
    }

    /// `f ∘ g` from `f⁽ᵏ⁾(x₀)`, `k < m = jet.len()`, and `bound ≥ sup|f⁽ᵐ⁾|` over the range.
    fn compose(&self, jet: &[f64], bound: f64) -> Model {
        let m = jet.len();
        let mut out = Model::constant(0.0);
        for (k, &j) in jet.iter().enumerate() {
            if j != 0.0 {
                out = out.add(&self.p[k].scale(j));
            }
        }
        let fact: f64 = (1..=m).map(|x| x as f64).product();
        out.r += bound * self.reach.powi(m as i32) / fact;
        out
    }

    /// `f ∘ g` for a vector function, with one bound for every coordinate.
    fn compose_vec(&self, jet: &[Vec3], bound: [f64; 3]) -> VModel {
        VModel(std::array::from_fn(|c| {
            let j: Vec<f64> = jet.iter().map(|x| x[c]).collect();
            self.compose(&j, bound[c])
        }))
    }
}

/// A vector's model, per coordinate.
#[derive(Clone, Copy, Debug)]
struct VModel([Model; 3]);

impl VModel {
    fn zero() -> VModel {
        VModel([Model::constant(0.0); 3])
    }
    fn add(&self, o: &VModel) -> VModel {
        VModel(std::array::from_fn(|c| self.0[c].add(&o.0[c])))
    }
    fn sub(&self, o: &VModel) -> VModel {
        VModel(std::array::from_fn(|c| self.0[c].sub(&o.0[c])))
    }
    fn times(&self, s: &Model) -> VModel {
        VModel(std::array::from_fn(|c| self.0[c].mul(s)))
    }
    fn scale(&self, s: f64) -> VModel {
        VModel(std::array::from_fn(|c| self.0[c].scale(s)))
    }
    fn cross(&self, o: &VModel) -> VModel {
        let (a, b) = (&self.0, &o.0);
        VModel([
            a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
            a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
            a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
        ])
    }
    fn dot(&self, o: &VModel) -> Model {
        (0..3).fold(Model::constant(0.0), |acc, c| {
            acc.add(&self.0[c].mul(&o.0[c]))
        })
    }
}

/// A surface's model on a cell: `|X(u, v) − Σ_k coeffs[k] σ_u^a σ_v^b| ≤ radius[c]` in every
/// coordinate `c`, `σ = ((u − centre_u)/half_u, (v − centre_v)/half_v)`, `(a, b)` the exponents
/// of `k` ([`model_exponents`]).
#[derive(Clone, Debug)]
pub struct CellModel {
    /// The cell's centre `(u_c, v_c)`.
    pub centre: [f64; 2],
    /// The cell's half widths `(h_u, h_v)`.
    pub half: [f64; 2],
    /// The polynomial's coefficients in `σ`, by [`model_index`].
    pub coeffs: [Vec3; MODEL_LEN],
    /// The radius in each coordinate.
    pub radius: [f64; 3],
}

impl CellModel {
    /// The polynomial part at `(u, v)`.
    pub fn polynomial(&self, u: f64, v: f64) -> Vec3 {
        let (su, sv) = (
            (u - self.centre[0]) / self.half[0],
            (v - self.centre[1]) / self.half[1],
        );
        self.coeffs
            .iter()
            .enumerate()
            .fold(Vec3::zeros(), |acc, (k, c)| {
                let (a, b) = model_exponents(k);
                acc + c * (su.powi(a as i32) * sv.powi(b as i32))
            })
    }
}

/// The values and derivatives of the cubic `Σ a_m s^m` at `s`, orders `0 ..= 4` (exact: the
/// fifth derivative is zero).
fn cubic_jet(a: &[Vec3; 4], s: f64) -> [Vec3; ORDER + 1] {
    let mut jet = [Vec3::zeros(); ORDER + 1];
    for (k, j) in jet.iter_mut().enumerate().take(4) {
        for (m, am) in a.iter().enumerate().skip(k) {
            *j += am * (falling(m, k) as f64 * s.powi((m - k) as i32));
        }
    }
    jet
}

/// `m! / (m − k)!` (`1` for `k = 0`, `0` for `k > m`).
fn falling(m: usize, k: usize) -> usize {
    if k > m {
        0
    } else {
        (m + 1 - k..=m).product()
    }
}

/// The monomial coefficients of the cubic Hermite `[v0, m0, v1, m1]` on `[0, 1]`.
fn hermite_monomials(c: [Vec3; 4]) -> [Vec3; 4] {
    let [v0, m0, v1, m1] = c;
    [
        v0,
        m0,
        v0 * -3.0 - m0 * 2.0 + v1 * 3.0 - m1,
        v0 * 2.0 + m0 - v1 * 2.0 + m1,
    ]
}

fn scalar_cubic(c: &[f64; 4]) -> [Vec3; 4] {
    let v = |x: f64| Vec3::new(x, 0.0, 0.0);
    hermite_monomials([v(c[0]), v(c[1]), v(c[2]), v(c[3])])
}

/// The order of the Taylor remainder of `curve`'s derivative of order `shift` over a range of
/// its parameter that holds a break (`broken`), or any range: 5, or less where the curve is only
/// `C^c` at a break or its jet is exact only to order `e` ([`Curve::exact_order`]). Taylor's
/// formula with the integral remainder of order `m` needs the function's derivative of order
/// `m − 1` continuous and the one of order `m` bounded on the pieces, so `m ≤ c + 1 − shift`;
/// its polynomial takes the curve's derivatives of orders `shift ..= m − 1 + shift` from the
/// jet, so `m ≤ e + 1 − shift`. `None` where that is below 1.
///
/// [`Curve::exact_order`]: crate::curve::Curve::exact_order
pub(super) fn remainder_order(curve: &SharedCurve, broken: bool, shift: usize) -> Option<usize> {
    let smooth = if broken {
        curve.continuity().saturating_add(1)
    } else {
        usize::MAX
    };
    smooth
        .min(curve.exact_order().saturating_add(1))
        .checked_sub(shift)
        .filter(|&m| m >= 1)
        .map(|m| m.min(ORDER + 1))
}

/// `s ↦ curve(t0 + s (t1 − t0))` composed with `s` (shifted by `shift` derivatives), or `None`
/// where the curve has no bounds of order 4 + shift (of the order [`remainder_order`] allows
/// where a break lies inside the range).
fn curve_model(curve: &SharedCurve, t0: f64, t1: f64, s: &Powers, shift: usize) -> Option<VModel> {
    let dt = t1 - t0;
    let (ta, tb) = (t0 + s.lo * dt, t0 + s.hi * dt);
    let (lo, hi) = (ta.min(tb), ta.max(tb));
    let tau = std::f64::consts::TAU;
    let inside = |x: f64| [x - tau, x, x + tau].iter().any(|&y| lo < y && y < hi);
    let broken = curve.breaks().into_iter().any(inside);
    let hi = if hi > lo {
        hi
    } else {
        lo + f64::EPSILON * lo.abs().max(1.0)
    };
    // Order-5 bounds where the kind has them (the curve's sixth where the tangent is wanted),
    // else order 4; lower across a break where the curve is less smooth.
    let mut bound = [0.0; ORDER + 3];
    let mut m = remainder_order(curve, broken, shift)?;
    if !curve.derivative_bounds(lo, hi, &mut bound[..m + shift + 1]) {
        m = m.min(ORDER);
        if !curve.derivative_bounds(lo, hi, &mut bound[..m + shift + 1]) {
            return None;
        }
    }
    let mut jet = [Vec3::zeros(); ORDER + 2];
    curve.jet(t0 + s.x0 * dt, &mut jet[..m + shift]);
    let mut f = 1.0;
    for j in jet.iter_mut() {
        *j *= f;
        f *= dt;
    }
    let top = bound[m + shift] * dt.abs().powi((m + shift) as i32) * (1.0 + 1e-15);
    Some(s.compose_vec(&jet[shift..m + shift], [top; 3]))
}

/// A cubic (monomial coefficients) composed with `s`: exact.
fn cubic_model(a: [Vec3; 4], s: &Powers) -> VModel {
    s.compose_vec(&cubic_jet(&a, s.x0), [0.0; 3])
}

/// `Σ c_n T_n(2s − 1)` and its derivatives `0 ..= 4` at `s`.
fn chebyshev_jet(c: &[f64], s: f64) -> [f64; ORDER + 1] {
    let x = 2.0 * s - 1.0;
    let mut series = c.to_vec();
    let mut out = [0.0; ORDER + 1];
    let mut scale = 1.0;
    for o in out.iter_mut() {
        // Clenshaw.
        let (mut b1, mut b2) = (0.0, 0.0);
        for &ck in series.iter().skip(1).rev() {
            (b1, b2) = (2.0 * x * b1 - b2 + ck, b1);
        }
        *o = (x * b1 - b2 + series.first().copied().unwrap_or(0.0)) * scale;
        series = cheb_diff(&series);
        scale *= 2.0;
    }
    out
}

/// Bounds of `Σ c_n T_n(2s − 1)`'s derivative of order 5 in `s` on `[0, 1]`:
/// `|T_n^{(k)}| ≤ T_n^{(k)}(1) = Π_{j<k} (n² − j²)/(2j + 1)`, times `2^k`.
fn chebyshev_fifth(c: &[f64]) -> f64 {
    let mut out = 0.0;
    for (n, cn) in c.iter().enumerate() {
        let n2 = (n * n) as f64;
        let t: f64 = (0..=ORDER)
            .map(|j| {
                let j = j as f64;
                (n2 - j * j).max(0.0) / (2.0 * j + 1.0) * 2.0
            })
            .product();
        out += cn.abs() * t;
    }
    out * (1.0 + 1e-14)
}

/// A neighbour's Chebyshev field composed with `s`. A short series is analytic: its own
/// derivatives at `x₀` and the bound of its fifth. A tabulated field is a quintic on each piece
/// of its table, `C²` across the pieces' ends: the quintic `q` of `x₀`'s piece is composed
/// exactly (its fifth derivative is constant), and `sup|f − q|` over `s`'s range, where the
/// other pieces' quintics `q_k` are the field, is added to the radius: on each piece's part
/// `[a, b]` of the range, `|q_k − q| ≤ Σ_j |(q_k − q)⁽ʲ⁾(m)/j!| ((b − a)/2)^j` about its middle
/// `m` (exact: both are quintics).
/// A unit field ([`ChebVec::fit_unit`]) is its series' field `v` times `(v·v)^{−1/2}`
/// ([`rsqrt`]), as the evaluator computes it (`None` where `v·v`'s range reaches 0).
fn field_model(f: &ChebVec, s: &Powers) -> Option<VModel> {
    let series = |c: &[Vec<f64>; 3]| {
        VModel(std::array::from_fn(|i| {
            s.compose(&chebyshev_jet(&c[i], s.x0), chebyshev_fifth(&c[i]))
        }))
    };
    if let Some(c) = f.unit_series() {
        let v = series(c);
        return Some(v.times(&rsqrt(&v.dot(&v))?));
    }
    if let Some(c) = f.coordinate_series() {
        return Some(series(c));
    }
    let k0 = f.piece_of(s.x0);
    let t0 = f.piece_taylor(k0, s.x0);
    let fact = [1.0, 1.0, 2.0, 6.0, 24.0, 120.0];
    let mut far = [0.0f64; 3];
    for k in f.piece_of(s.lo)..=f.piece_of(s.hi) {
        let (a, b) = f.piece_span(k);
        let (a, b) = (a.max(s.lo), b.min(s.hi));
        if k == k0 || a > b {
            continue;
        }
        let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
        let (tk, tq) = (f.piece_taylor(k, m), f.piece_taylor(k0, m));
        for (c, o) in far.iter_mut().enumerate() {
            let sum: f64 = (0..6)
                .map(|j| (tk[j][c] - tq[j][c]).abs() * r.powi(j as i32))
                .sum();
            *o = o.max(sum);
        }
    }
    Some(VModel(std::array::from_fn(|c| {
        let jet: Vec<f64> = (0..=ORDER).map(|j| t0[j][c] * fact[j]).collect();
        let mut m = s.compose(&jet, (t0[5][c] * fact[5]).abs() * (1.0 + 1e-14));
        m.r += far[c] * (1.0 + 1e-14);
        m
    })))
}

/// Legendre `P_0 … P_p` at `x` with all their derivatives (orders `0 ..= p`; the recurrence
/// `(n + 1) P_{n+1} = (2n + 1) x P_n − n P_{n−1}` differentiated `k` times).
fn legendre_jets(p: usize, x: f64) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; p + 1]; p + 1];
    out[0][0] = 1.0;
    if p >= 1 {
        out[1][0] = x;
        out[1][1] = 1.0;
    }
    for n in 1..p {
        let nf = n as f64;
        for k in 0..=p {
            let prev = if k > 0 { out[n][k - 1] } else { 0.0 };
            out[n + 1][k] = ((2.0 * nf + 1.0) * (x * out[n][k] + k as f64 * prev)
                - nf * out[n - 1][k])
                / (nf + 1.0);
        }
    }
    out
}

/// `sup|f⁽⁵⁾|` over `mid ± r` of a polynomial given by all its derivatives at `mid` (Taylor's
/// polynomial of `f⁽⁵⁾`, exact).
fn fifth_bound(jet: &[f64], r: f64) -> f64 {
    let mut out = 0.0;
    let mut f = 1.0;
    for (j, x) in jet.iter().enumerate().skip(ORDER + 1) {
        if j > ORDER + 1 {
            f *= r / (j - ORDER - 1) as f64;
        }
        out += x.abs() * f;
    }
    out * (1.0 + 1e-14)
}

/// The correction's coefficients by `a`, made once per patch.
pub(super) struct CorrectionData {
    /// `c_ab`, by `a` then `b`.
    columns: Vec<Vec<Vec3>>,
}

impl CorrectionData {
    fn new(patch: &NSidedPatch) -> CorrectionData {
        let deg = patch.basis.degree;
        let mut columns = Vec::with_capacity(deg + 1);
        // Already in the order of `Basis::by_a`.
        let mut rest = patch.coeffs.as_slice();
        for a in 0..=deg {
            let (column, tail) = rest.split_at(deg + 1 - a);
            rest = tail;
            columns.push(column.to_vec());
        }
        CorrectionData { columns }
    }
}

/// The side's `P, D, E, F` composed with its parameter `s`.
fn side_model(side: &BuiltSide, s: &Powers) -> Option<[VModel; 4]> {
    let (curve, t0, t1) = (&side.side.curve, side.side.t0, side.side.t1);
    let p = curve_model(curve, t0, t1, s, 0)?;
    let scalar = |c: &[f64; 4]| cubic_model(scalar_cubic(c), s).0[0];
    let d = match &side.ribbon {
        BuiltRibbon::Free(c) => cubic_model(hermite_monomials(*c), s),
        BuiltRibbon::Derivative { curve, t0, t1 } => curve_model(curve, *t0, *t1, s, 0)?,
        BuiltRibbon::Plane { normal, a, b } => {
            let tangent = curve_model(curve, t0, t1, s, 1)?;
            let nrm = field_model(normal, s)?;
            nrm.cross(&tangent)
                .times(&scalar(a))
                .add(&tangent.times(&scalar(b)))
        }
    };
    // E's free part: e₀ + (e₁ − e₀) s + δ₀ h₁₀(s) + δ₁ h₁₁(s) (h₁₀ = s − 2s² + s³,
    // h₁₁ = −s² + s³).
    let [e0, e1] = side.e;
    let [d0, d1] = side.e_slope;
    let lin = cubic_model([e0, e1 - e0 + d0, d0 * -2.0 - d1, d0 + d1], s);
    let e = match (&side.curvature, &side.ribbon) {
        (BuiltCurvature::Free, _) => lin,
        (BuiltCurvature::Explicit { curve, t0, t1 }, _) => {
            curve_model(curve, *t0, *t1, s, 0)?.scale(0.5)
        }
        (BuiltCurvature::Neighbour(k), BuiltRibbon::Plane { normal, a, b }) => {
            // E = l + N g, g = κ/2 − N·l, κ = a² K₀ + 2ab K₁ + b² K₂.
            let nrm = field_model(normal, s)?;
            let kk = field_model(k, s)?;
            let (a, b) = (scalar(a), scalar(b));
            let kappa = a
                .mul(&a)
                .mul(&kk.0[0])
                .add(&a.mul(&b).mul(&kk.0[1]).scale(2.0))
                .add(&b.mul(&b).mul(&kk.0[2]));
            let g = kappa.scale(0.5).sub(&nrm.dot(&lin));
            lin.add(&nrm.times(&g))
        }
        (BuiltCurvature::Neighbour(_), _) => return None,
    };
    let [f0, f1] = side.f;
    let z = Vec3::zeros();
    let f = cubic_model([f0, f1 - f0, z, z], s);
    Some([p, d, e, f])
}

/// The range of `s = d_{i−1} / (d_{i−1} + d_{i+1})` (monotone in each distance), within
/// `[0, 1]`.
pub(super) fn side_range(dm: (f64, f64), dp: (f64, f64)) -> (f64, f64) {
    let lo = dm.0 / (dm.0 + dp.1);
    let hi = dm.1 / (dm.1 + dp.0);
    let lo = if lo.is_finite() {
        (lo - 1e-15).max(0.0)
    } else {
        0.0
    };
    let hi = if hi.is_finite() {
        (hi + 1e-15).min(1.0)
    } else {
        1.0
    };
    (lo, hi.max(lo))
}

/// `1 / g` for `g` positive on the cell (`known` another enclosure of its range).
fn recip(g: &Model, known: (f64, f64)) -> Option<Model> {
    let pw = Powers::new(g, known);
    if pw.lo.is_nan() || pw.lo <= 0.0 {
        return None;
    }
    let x = pw.x0;
    // (1/x)^{(k)} = (−1)^k k! / x^{k+1}; the fifth is largest in size at the range's low end.
    let mut jet = [0.0; ORDER + 1];
    let mut fact = 1.0;
    for (k, j) in jet.iter_mut().enumerate() {
        if k > 0 {
            fact *= k as f64;
        }
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        *j = sign * fact / x.powi(k as i32 + 1);
    }
    let fifth = 120.0 / pw.lo.powi(ORDER as i32 + 2);
    let mut out = pw.compose(&jet, fifth);
    // The residual's bound, often far smaller: `|1/g − P| ≤ sup|1 − g P| / inf g`, and
    // `1 − g P` has no terms below degree five but rounding.
    let exact = Model { c: out.c, r: 0.0 };
    let residual = Model::constant(1.0).sub(&g.mul(&exact));
    let (lo, hi) = residual.range();
    out.r = out.r.min(lo.abs().max(hi.abs()) / pw.lo);
    Some(out)
}

/// `g^{−1/2}` for `g` positive on the cell: `(x^{−1/2})⁽ᵏ⁾ = (−1)ᵏ (1·3···(2k − 1))/2ᵏ
/// x^{−1/2−k}`, the fifth largest in size at the range's low end.
fn rsqrt(g: &Model) -> Option<Model> {
    let pw = Powers::new(g, (0.0, f64::INFINITY));
    if pw.lo.is_nan() || pw.lo <= 0.0 {
        return None;
    }
    let x = pw.x0;
    let mut jet = [0.0; ORDER + 1];
    let mut c = 1.0;
    for (k, j) in jet.iter_mut().enumerate() {
        *j = c * x.powf(-0.5 - k as f64);
        c *= -(2.0 * k as f64 + 1.0) / 2.0;
    }
    // c is now the fifth's coefficient, −945/32.
    let fifth = c.abs() * pw.lo.powf(-0.5 - (ORDER + 1) as f64) * (1.0 + 1e-14);
    Some(pw.compose(&jet, fifth))
}

impl NSidedSurface {
    /// The domain coordinate `c + g · (x, y)` over the cell as a model (exact), with its range
    /// from the cell's corners (a bilinear function takes its extremes there).
    fn affine_model(&self, u: [f64; 2], v: [f64; 2], g: [f64; 2], c: f64) -> (Model, (f64, f64)) {
        let dot = |a: [f64; 2]| g[0] * a[0] + g[1] * a[1];
        let (hu, hv) = (0.5 * (u[1] - u[0]), 0.5 * (v[1] - v[0]));
        let m = self.domain_map(0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1]));
        let mut t = Model::constant(c + dot(m[0]));
        t.c[model_index(1, 0)] = dot(m[1]) * hu;
        t.c[model_index(0, 1)] = dot(m[2]) * hv;
        t.c[model_index(1, 1)] = dot(m[3]) * hu * hv;
        let vals =
            [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(i, j)| c + dot(self.domain_map(u[i], v[j])[0]));
        let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (t, (lo - 1e-15, hi + 1e-15))
    }

    /// The Taylor model of the surface over the cell `[u0, u1] × [v0, v1]` (see the module
    /// documentation), or `None` where the cell touches a corner of the polygon or a side's data
    /// have no bounds there (a break of its curve, a curve kind without bounds).
    pub fn taylor_model(&self, u: [f64; 2], v: [f64; 2]) -> Option<CellModel> {
        let patch = &*self.patch;
        let n = patch.poly.n;
        let (d, known): (Vec<Model>, Vec<(f64, f64)>) = (0..n)
            .map(|i| {
                let c = patch.poly.distance(i, [0.0, 0.0]);
                let (m, (lo, hi)) = self.affine_model(u, v, patch.poly.normal(i), c);
                (m, (lo.max(0.0), hi))
            })
            .unzip();
        let q = if patch.options.order == 3 { 4 } else { 3 };
        let powers: Vec<Model> = d.iter().map(|x| x.pow(q)).collect();
        let pis: Vec<Model> = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| j != i)
                    .fold(Model::constant(1.0), |acc, j| acc.mul(&powers[j]))
            })
            .collect();
        let total = pis[1..].iter().fold(pis[0], |acc, x| acc.add(x));
        // Each π_i is a product of non-negative distances' powers: its range from theirs.
        let product = |i: usize, end: fn(&(f64, f64)) -> f64| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| end(&known[j]).powi(q as i32))
                .product::<f64>()
        };
        let total_known = (
            (0..n).map(|i| product(i, |r| r.0)).sum::<f64>() * (1.0 - 1e-14),
            (0..n).map(|i| product(i, |r| r.1)).sum::<f64>() * (1.0 + 1e-14),
        );
        let inv = recip(&total, total_known)?;
        // The side nearest the cell's centre.
        let a = (0..n)
            .min_by(|&i, &j| d[i].c[0].total_cmp(&d[j].c[0]))
            .unwrap_or(0);
        let mut ribbons = Vec::with_capacity(n);
        for i in 0..n {
            let (im, ip) = ((i + n - 1) % n, (i + 1) % n);
            let sum = d[im].add(&d[ip]);
            let sum_known = (known[im].0 + known[ip].0, known[im].1 + known[ip].1);
            let s = d[im].mul(&recip(&sum, sum_known)?);
            let pw = Powers::new(&s, side_range(known[im], known[ip]));
            let [p, dd, e, f] = side_model(&patch.sides[i], &pw)?;
            let t = d[i].scale(1.0 / patch.poly.side);
            let t2 = t.mul(&t);
            let mut r = p.add(&dd.times(&t)).add(&e.times(&t2));
            if patch.options.order == 3 {
                r = r.add(&f.times(&t2.mul(&t)));
            }
            ribbons.push(r);
        }
        // R_a + Σ B_i (R_i − R_a): the differences are small near the corner where two
        // ribbons meet, and the polynomials keep them so.
        let ra = ribbons[a];
        let mut c = ra;
        for i in (0..n).filter(|&i| i != a) {
            // 0 ≤ B_i ≤ 1 (a partition of unity with non-negative terms): the model met with
            // that range where it is wider (near a corner, where B_i is direction dependent).
            let mut b = pis[i].mul(&inv);
            if b.r > 0.5 {
                b = Model::constant(0.5);
                b.r = 0.5;
            }
            c = c.add(&ribbons[i].sub(&ra).times(&b));
        }
        let corr = self.correction_model(u, v, &d);
        let x = c.add(&corr);
        let out = CellModel {
            centre: [0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1])],
            half: [0.5 * (u[1] - u[0]), 0.5 * (v[1] - v[0])],
            coeffs: std::array::from_fn(|k| Vec3::new(x.0[0].c[k], x.0[1].c[k], x.0[2].c[k])),
            radius: [x.0[0].r, x.0[1].r, x.0[2].r],
        };
        let finite = out.radius.iter().all(|r| r.is_finite())
            && out.coeffs.iter().all(|c| c.iter().all(|x| x.is_finite()));
        finite.then_some(out)
    }

    /// `w · Q` over the cell, `Q = Σ_a P_a(x) S_a(y)`, `w = Π (d_i/ρ)^{m_i}`.
    fn correction_model(&self, u: [f64; 2], v: [f64; 2], d: &[Model]) -> VModel {
        let patch = &*self.patch;
        let data = patch
            .correction_data
            .get_or_init(|| Box::new(CorrectionData::new(patch)));
        let mut w = Model::constant(1.0);
        for (di, &m) in d.iter().zip(&patch.basis.multiplicity) {
            w = w.mul(&di.scale(1.0 / patch.basis.inradius).pow(m));
        }
        let (x, xr) = self.affine_model(u, v, [1.0, 0.0], 0.0);
        let (y, yr) = self.affine_model(u, v, [0.0, 1.0], 0.0);
        let (px, py) = (Powers::new(&x, xr), Powers::new(&y, yr));
        let deg = patch.basis.degree;
        let len = deg.max(ORDER + 1);
        // Derivatives at x₀ (the Taylor coefficients) and at the range's middle (the fifth
        // derivative's bound).
        let (lx0, lxm) = (
            legendre_jets(len, px.x0),
            legendre_jets(len, 0.5 * (px.lo + px.hi)),
        );
        let (ly0, lym) = (
            legendre_jets(len, py.x0),
            legendre_jets(len, 0.5 * (py.lo + py.hi)),
        );
        let (rx, ry) = (0.5 * (px.hi - px.lo), 0.5 * (py.hi - py.lo));
        let mut q = VModel::zero();
        for (a, col) in data.columns.iter().enumerate() {
            let pa = px.compose(&lx0[a][..=ORDER], fifth_bound(&lxm[a], rx));
            // S_a's derivatives, coordinate by coordinate.
            let s_at = |l: &[Vec<f64>], k: usize| {
                col.iter()
                    .zip(l)
                    .fold(Vec3::zeros(), |acc, (c, p)| acc + c * p[k])
            };
            let jet: Vec<Vec3> = (0..=ORDER).map(|k| s_at(&ly0, k)).collect();
            let mid: Vec<Vec3> = (0..=len).map(|k| s_at(&lym, k)).collect();
            let bound: [f64; 3] = std::array::from_fn(|c| {
                fifth_bound(&mid.iter().map(|x| x[c]).collect::<Vec<_>>(), ry)
            });
            let sa = py.compose_vec(&jet, bound);
            q = q.add(&sa.times(&pa));
        }
        q.times(&w)
    }
}

#[cfg(test)]
mod tests {
    use super::super::side::Ribbon;
    use super::super::tests::spherical_polygon;
    use super::*;
    use crate::surface::Surface;
    use std::sync::Arc;

    /// Samples the surface on a `(k + 1)²` lattice of the cell (edges included) and asserts
    /// that it stays within the model's radius of its polynomial in every coordinate (the
    /// polynomial is evaluated in floating point: 1e-14 allowed).
    pub(super) fn assert_model_holds(
        s: &NSidedSurface,
        m: &CellModel,
        u: [f64; 2],
        v: [f64; 2],
        k: usize,
    ) {
        let mut worst = [0.0f64; 3];
        for i in 0..=k {
            for j in 0..=k {
                let (uu, vv) = (
                    u[0] + (u[1] - u[0]) * i as f64 / k as f64,
                    v[0] + (v[1] - v[0]) * j as f64 / k as f64,
                );
                let e = s.partials(uu, vv).x - m.polynomial(uu, vv);
                for c in 0..3 {
                    worst[c] = worst[c].max(e[c].abs());
                }
            }
        }
        eprintln!("{u:?} × {v:?}: radius {:?}, sampled {worst:?}", m.radius);
        for c in 0..3 {
            assert!(
                worst[c] <= m.radius[c] + 1e-14,
                "{u:?} × {v:?}: {:?} {worst:?}",
                m.radius
            );
        }
    }

    /// The models hold: on cells from the middle of a piece to 10⁻³ from a corner, the surface
    /// sampled on a 9 × 9 lattice (edges included) stays within the radius of the polynomial
    /// in every coordinate, and the radius falls at least like `h⁴` when the cell is halved
    /// (the remainder is of degree five, order 4 where a bound of order 5 is missing; the
    /// quarters' radii measured here are 31 to 160 times smaller).
    ///
    /// Both forms of a neighbour's normal: the sphere's points themselves (a short field:
    /// its direction is evaluated, [`ChebVec::fit_unit`]), and the points times
    /// `2 + sin 300s` (too long to be kept: the unit field gets a series of its own).
    #[test]
    fn the_models_hold_on_spherical_polygons() {
        for (n, scaled) in [(3, false), (4, false), (5, false), (6, false), (5, true)] {
            let mut sides = spherical_polygon(n, 0.6);
            if scaled {
                for side in &mut sides {
                    let on = side.curve.clone();
                    side.ribbon = Ribbon::TangentPlane(Arc::new(move |s: f64| {
                        on.point(s) * (2.0 + (300.0 * s).sin())
                    }));
                }
            }
            let patch = Arc::new(NSidedPatch::solve(sides, &Default::default()).unwrap());
            for side in &patch.sides {
                let BuiltRibbon::Plane { normal, .. } = &side.ribbon else {
                    panic!("a plane ribbon");
                };
                assert_eq!(normal.unit_series().is_some(), !scaled);
                assert_eq!(normal.coordinate_series().is_some(), scaled);
            }
            let s = &patch.surfaces()[0];
            for (u, v) in [
                ([0.4, 0.5], [0.4, 0.5]),
                ([0.45, 0.46], [0.45, 0.46]),
                ([0.1, 0.2], [0.4, 0.5]),
                ([0.0, 0.05], [0.4, 0.45]),
                ([0.01, 0.02], [0.01, 0.02]),
                ([0.001, 0.002], [0.001, 0.002]),
                ([0.9, 1.0], [0.8, 0.9]),
            ] {
                let m = s.taylor_model(u, v).expect("a model off the corner");
                assert_model_holds(s, &m, u, v, 8);
                let hu = 0.5 * (u[1] - u[0]);
                let half = s
                    .taylor_model([u[0], u[0] + hu], [v[0], v[0] + 0.5 * (v[1] - v[0])])
                    .expect("a model of the quarter");
                let (r1, r2) = (
                    m.radius.iter().copied().fold(0.0, f64::max),
                    half.radius.iter().copied().fold(0.0, f64::max),
                );
                eprintln!("n = {n}, {u:?} × {v:?}: radius / quarter's {:.1}", r1 / r2);
                assert!(r2 <= r1 / 16.0 + 1e-15, "n = {n}, {u:?}: {r1:e} → {r2:e}");
            }
        }
    }
}

#[cfg(test)]
mod break_tests {
    use super::super::side::Ribbon;
    use super::super::tests::spherical_polygon;
    use super::*;
    use crate::curve::{BSpline, Curve};
    use std::sync::Arc;

    /// A cubic B-spline from `a` to `b` on the clamped knots with `inner` inside, its inner
    /// control points on the great arc between them, every other one lifted off the sphere by
    /// 30 %.
    fn bspline_side(a: Vec3, b: Vec3, inner: &[f64]) -> SharedCurve {
        let knots = [&[0.0; 4][..], inner, &[1.0; 4]].concat();
        let n = knots.len() - 4;
        let control = (0..n)
            .map(|i| {
                let t = i as f64 / (n - 1) as f64;
                match i {
                    0 => a,
                    i if i == n - 1 => b,
                    _ => (a * (1.0 - t) + b * t).normalize() * (1.0 + 0.3 * (i % 2) as f64),
                }
            })
            .collect();
        Arc::new(BSpline::clamped(3, control, Some(knots)).unwrap())
    }

    /// The model of a cubic B-spline (or of its derivative, `shift = 1`) composed with
    /// `s = c + h σ` over ranges that straddle an inner knot holds: sampled at 401 points, the
    /// curve stays within the radius of the polynomial, for a simple (`C²`), a double (`C¹`)
    /// and a triple (`C⁰`) knot. The model of order 5 (the curve's fifth derivative, zero on
    /// every piece) would claim a radius of zero there.
    #[test]
    fn curve_models_hold_across_a_knot() {
        let control: Vec<Vec3> = (0..7)
            .map(|i| {
                let x = i as f64;
                Vec3::new(x, (1.7 * x).sin() * 2.0, (x * x * 0.3).cos())
            })
            .collect();
        let inner = |k: Vec<f64>| [vec![0.0; 4], k, vec![1.0; 4]].concat();
        for (knots, c) in [
            (inner(vec![0.2, 0.5, 0.7]), 2),
            (inner(vec![0.3, 0.5, 0.5]), 1),
            (inner(vec![0.5, 0.5, 0.5]), 0),
        ] {
            let curve: SharedCurve =
                Arc::new(BSpline::clamped(3, control.clone(), Some(knots)).unwrap());
            assert_eq!(curve.continuity(), c);
            for shift in 0..=1 {
                let Some(order) = remainder_order(&curve, true, shift) else {
                    assert!(c < shift);
                    continue;
                };
                assert_eq!(order, c + 1 - shift);
                for (centre, h) in [(0.45, 0.1), (0.5, 0.02), (0.51, 0.03), (0.4, 0.25)] {
                    let mut g = Model::constant(centre);
                    g.c[model_index(1, 0)] = h;
                    let powers = Powers::new(&g, (centre - h, centre + h));
                    let m = curve_model(&curve, 0.0, 1.0, &powers, shift).unwrap();
                    for k in 0..=400 {
                        let x = -1.0 + k as f64 / 200.0;
                        let truth = curve.derivative(centre + h * x, shift);
                        for (d, model) in m.0.iter().enumerate() {
                            let poly: f64 = (0..=ORDER)
                                .map(|a| model.c[model_index(a, 0)] * x.powi(a as i32))
                                .sum();
                            assert!(
                                (truth[d] - poly).abs() <= model.r + 1e-12,
                                "C{c}, shift {shift}, {centre} ± {h}, σ = {x}: {} > {}",
                                (truth[d] - poly).abs(),
                                model.r
                            );
                        }
                    }
                }
            }
        }
    }

    /// A curve whose jet is exact only to order 2 (as a curve on a surface, which differences
    /// higher orders) gets models whose polynomial stops there: remainders of order 3 for the
    /// curve and 2 for its tangent, with or without a break.
    #[test]
    fn models_stop_at_the_exact_order_of_the_jet() {
        #[derive(Debug)]
        struct Exact2(BSpline);
        impl Curve for Exact2 {
            fn domain(&self) -> crate::curve::Domain {
                self.0.domain()
            }
            fn jet(&self, t: f64, out: &mut [Vec3]) {
                self.0.jet(t, out)
            }
            fn breaks(&self) -> Vec<f64> {
                self.0.breaks()
            }
            fn continuity(&self) -> usize {
                self.0.continuity()
            }
            fn exact_order(&self) -> usize {
                2
            }
        }
        let quintic = || {
            let control = (0..6).map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
            BSpline::clamped(5, control, None).unwrap()
        };
        let smooth: SharedCurve = Arc::new(quintic());
        assert_eq!(remainder_order(&smooth, false, 0), Some(ORDER + 1));
        let limited: SharedCurve = Arc::new(Exact2(quintic()));
        assert_eq!(remainder_order(&limited, false, 0), Some(3));
        assert_eq!(remainder_order(&limited, false, 1), Some(2));
        assert_eq!(remainder_order(&limited, true, 0), Some(3));
    }

    /// Sides on B-splines with inner knots: a simple knot (`C²`) under a tangent-plane ribbon
    /// (whose model differentiates the curve: a remainder of order 2 across the knot) and a
    /// double knot (`C¹`) under a position-only side (order 2). On every cell of a 24 × 24 grid
    /// of every piece (the knots' images cross the domain, so many cells straddle them) the
    /// surface sampled on a 9 × 9 lattice stays within the model's radius, and the radius
    /// still falls when the cell is halved. (Models of order 5 across the knots fail here.)
    #[test]
    fn the_models_hold_across_breaks() {
        let mut sides = spherical_polygon(4, 0.6);
        let side = |i: usize, inner: &[f64]| {
            let c = &sides[i].curve;
            bspline_side(c.point(0.0), c.point(1.0), inner)
        };
        let (simple, double) = (side(0, &[0.3, 0.6]), side(1, &[0.45, 0.45]));
        assert_eq!((simple.continuity(), double.continuity()), (2, 1));
        let on = simple.clone();
        sides[0].curve = simple;
        sides[0].ribbon = Ribbon::TangentPlane(Arc::new(move |s| on.point(s).normalize()));
        sides[1].curve = double;
        sides[1].ribbon = Ribbon::Position;
        let patch = Arc::new(NSidedPatch::solve(sides, &Default::default()).unwrap());
        let s = &patch.surfaces()[0];
        assert!(s.bounds_unavailable().is_none());
        let k = 24;
        for piece in &patch.surfaces() {
            for i in 0..k {
                for j in 0..k {
                    let u = [i as f64 / k as f64, (i + 1) as f64 / k as f64];
                    let v = [j as f64 / k as f64, (j + 1) as f64 / k as f64];
                    if piece.corner_reach(u, v).is_some() {
                        continue;
                    }
                    let m = piece.taylor_model(u, v).expect("a model off the corner");
                    super::tests::assert_model_holds(piece, &m, u, v, 8);
                    let quarter = piece
                        .taylor_model([u[0], 0.5 * (u[0] + u[1])], [v[0], 0.5 * (v[0] + v[1])])
                        .expect("a model of the quarter");
                    let size = |m: &CellModel| m.radius.iter().copied().fold(0.0, f64::max);
                    assert!(size(&quarter) < size(&m), "{u:?} × {v:?}");
                }
            }
        }
    }
}

#[cfg(test)]
mod table_tests {
    use super::super::side::Ribbon;
    use super::super::tests::spherical_polygon;
    use super::*;
    use std::sync::Arc;

    /// With neighbour normals that need a long series (a sphere's normals with a wobble of
    /// 10⁻⁶ at frequency 300, tabulated as quintic Hermite pieces), the models still hold on
    /// cells across many of the table's pieces, and the surface is certified by them.
    #[test]
    fn the_models_hold_with_tabulated_neighbour_fields() {
        let mut sides = spherical_polygon(4, 0.6);
        for side in &mut sides {
            let curve = side.curve.clone();
            side.ribbon = Ribbon::TangentPlane(Arc::new(move |s: f64| {
                curve.point(s) + Vec3::new((300.0 * s).sin(), (300.0 * s).cos(), 0.0) * 1e-6
            }));
        }
        let patch = Arc::new(NSidedPatch::solve(sides, &Default::default()).unwrap());
        assert!(patch.sides.iter().all(|s| matches!(
            &s.ribbon,
            BuiltRibbon::Plane { normal, .. } if normal.coordinate_series().is_none()
        )));
        let s = &patch.surfaces()[0];
        for (u, v) in [
            ([0.4, 0.5], [0.4, 0.5]),
            ([0.0, 0.125], [0.25, 0.375]),
            ([0.9, 0.95], [0.05, 0.1]),
            ([0.01, 0.02], [0.01, 0.02]),
        ] {
            let m = s.taylor_model(u, v).expect("a model off the corner");
            super::tests::assert_model_holds(s, &m, u, v, 16);
        }
    }
}
