//! The sides of an n-sided patch: a curve run over a parameter interval, and the ribbon that
//! gives the cross-boundary derivative for G1.

use crate::curve::hermite::hermite_basis;
use crate::curve::SharedCurve;
use crate::elliptic::basis::{cheb_diff, clenshaw_lanes};
use crate::Vec3;
use std::sync::{Arc, Mutex, OnceLock};

/// A unit normal field along a side, as a function of the side's parameter `s ∈ [0, 1]`.
pub type NormalField = Arc<dyn Fn(f64) -> Vec3 + Send + Sync>;

/// A neighbour's second fundamental form along a side, as a function of the side's parameter
/// `s ∈ [0, 1]`: the symmetric tensor `S(s)` with `II(u, w) = uᵀ S w` for vectors `u`, `w` in
/// the neighbour's tangent plane, taken against the orientation of the [`NormalField`] it comes
/// with (for a surface `X(u, v)` with unit normal `N`: `S = J I⁻¹ II I⁻¹ Jᵀ`, `J = [X_u X_v]`,
/// `I`, `II` its first and second fundamental forms in `(u, v)`).
pub type ShapeField = Arc<dyn Fn(f64) -> nalgebra::Matrix3<f64> + Send + Sync>;

/// What a side asks of the patch across it, beyond its position.
#[derive(Clone)]
pub enum Ribbon {
    /// Position only (G0): the cross-boundary derivative is left to the PDE (natural
    /// condition).
    Position,
    /// The cross-boundary derivative given explicitly: `∂X/∂t (s)` with `t` the distance from
    /// the side measured in side lengths of the domain (so `∂X/∂t` has the scale of the side's
    /// own `∂X/∂s`). The curve is run over `[t0, t1]` like the side's position curve.
    Derivative {
        /// The curve `∂X/∂t (s)`, run like the side's position curve.
        curve: SharedCurve,
        /// The curve's parameter at `s = 0`.
        t0: f64,
        /// The curve's parameter at `s = 1` (finite, not `t0`; inside the curve's domain).
        t1: f64,
    },
    /// Tangent to a neighbour whose unit normal along the side is given (any orientation): the
    /// patch's tangent plane along the side is the neighbour's (G1). The cross-boundary
    /// derivative lies in that plane; its size and slant are fixed at the corners by
    /// compatibility with the adjacent sides and interpolated linearly in between.
    TangentPlane(NormalField),
    /// G2 to a neighbour: tangent to it as [`Ribbon::TangentPlane`], and with its normal
    /// curvature across the side: the patch's second cross derivative has the normal component
    /// `II(D, D)` for the cross derivative `D` (its tangential part, free, is the
    /// interpolant's choice). Needs order 3.
    Curvature {
        /// The neighbour's unit normal along the side (any orientation).
        normal: NormalField,
        /// The neighbour's second fundamental form along the side, against `normal`.
        shape: ShapeField,
    },
    /// G1 and G2 given explicitly: the cross derivative `∂X/∂t` (as
    /// [`Ribbon::Derivative`]) and the second cross derivative `∂²X/∂t²`, both run over
    /// `[t0, t1]`: the patch meets the surface `P(s) + t D(s) + t²/2 W(s)` to second order along
    /// the side. Needs order 3.
    Derivatives {
        /// The curve `∂X/∂t (s)`.
        first: SharedCurve,
        /// The curve `∂²X/∂t² (s)`.
        second: SharedCurve,
        /// The curves' parameter at `s = 0`.
        t0: f64,
        /// The curves' parameter at `s = 1`.
        t1: f64,
    },
}

impl Ribbon {
    /// The number of conditions the side carries: 1 (position), 2 (G1) or 3 (G2).
    pub fn multiplicity(&self) -> usize {
        match self {
            Ribbon::Position => 1,
            Ribbon::Derivative { .. } | Ribbon::TangentPlane(_) => 2,
            Ribbon::Curvature { .. } | Ribbon::Derivatives { .. } => 3,
        }
    }
}

impl std::fmt::Debug for Ribbon {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ribbon::Position => f.write_str("Position"),
            Ribbon::Derivative { curve, t0, t1 } => f
                .debug_struct("Derivative")
                .field("curve", curve)
                .field("t0", t0)
                .field("t1", t1)
                .finish(),
            Ribbon::TangentPlane(_) => f.write_str("TangentPlane"),
            Ribbon::Curvature { .. } => f.write_str("Curvature"),
            Ribbon::Derivatives {
                first,
                second,
                t0,
                t1,
            } => f
                .debug_struct("Derivatives")
                .field("first", first)
                .field("second", second)
                .field("t0", t0)
                .field("t1", t1)
                .finish(),
        }
    }
}

/// One side of an n-sided patch: `curve` run from parameter `t0` to `t1` (`t1 < t0` runs it
/// backwards), and its ribbon. Consecutive sides meet end to start.
#[derive(Clone, Debug)]
pub struct Side {
    /// The boundary curve.
    pub curve: SharedCurve,
    /// The curve's parameter at the side's start (`s = 0`).
    pub t0: f64,
    /// The curve's parameter at the side's end (`s = 1`; finite, not `t0`, inside the curve's
    /// domain).
    pub t1: f64,
    /// What the side asks of the patch across it: position only, a cross-boundary derivative or a
    /// tangent plane.
    pub ribbon: Ribbon,
}

impl Side {
    /// A side carrying its position only.
    pub fn position(curve: SharedCurve, t0: f64, t1: f64) -> Side {
        Side {
            curve,
            t0,
            t1,
            ribbon: Ribbon::Position,
        }
    }

    /// The side's point at `s ∈ [0, 1]`.
    pub fn point(&self, s: f64) -> Vec3 {
        let mut c = [Vec3::zeros(); 1];
        self.jet(s, &mut c);
        c[0]
    }

    /// `C(s), C'(s), …` with respect to the side parameter `s ∈ [0, 1]` (`out.len() ≤ 9`).
    pub(crate) fn jet(&self, s: f64, out: &mut [Vec3]) {
        curve_jet(&self.curve, self.t0, self.t1, s, out);
    }
}

/// A curve run over `[t0, t1]` as a function of `s ∈ [0, 1]`, with derivatives in `s`.
pub(crate) fn curve_jet(curve: &SharedCurve, t0: f64, t1: f64, s: f64, out: &mut [Vec3]) {
    let dt = t1 - t0;
    curve.jet(t0 + s * dt, out);
    let mut f = 1.0;
    for o in out.iter_mut().skip(1) {
        f *= dt;
        *o *= f;
    }
}

/// A vector function on `[0, 1]` as a Chebyshev series with three derivatives. A long series
/// (a field that is not smooth enough to converge in 64 terms) is evaluated from a table on a
/// uniform grid by quintic Hermite interpolation, so an evaluation costs the same whatever its
/// length (the table's error, `O(h⁶)` with `h = 1/256`, is far below the series').
#[derive(Clone, Debug)]
pub(crate) struct ChebVec {
    /// Series of the value and its first three derivatives, per coordinate, in `x = 2s − 1`.
    series: [[Vec<f64>; 3]; 4],
    /// `[f, f', f'']` at `s = j / TABLE`, `j = 0 ..= TABLE`.
    table: Vec<[Vec3; 3]>,
    /// The largest difference seen between the series and the function at the check points.
    pub fit_error: f64,
    /// The field is the unit vector `v/|v|` of the field `v` the series hold (never
    /// tabulated): see [`ChebVec::fit_unit`].
    unit: bool,
}

/// Intervals of the table of a [`ChebVec`].
const TABLE: usize = 256;

/// The longest series a [`ChebVec`] evaluates directly.
const SHORT: usize = 65;

/// The quintic Hermite basis on `[0, 1]` (value, slope and second derivative at 0, then at 1)
/// with its first three derivatives.
fn quintic(x: f64) -> [[f64; 6]; 4] {
    let (x2, x3, x4, x5) = (x * x, x * x * x, x * x * x * x, x * x * x * x * x);
    [
        [
            1.0 - 10.0 * x3 + 15.0 * x4 - 6.0 * x5,
            x - 6.0 * x3 + 8.0 * x4 - 3.0 * x5,
            0.5 * x2 - 1.5 * x3 + 1.5 * x4 - 0.5 * x5,
            10.0 * x3 - 15.0 * x4 + 6.0 * x5,
            -4.0 * x3 + 7.0 * x4 - 3.0 * x5,
            0.5 * x3 - x4 + 0.5 * x5,
        ],
        [
            -30.0 * x2 + 60.0 * x3 - 30.0 * x4,
            1.0 - 18.0 * x2 + 32.0 * x3 - 15.0 * x4,
            x - 4.5 * x2 + 6.0 * x3 - 2.5 * x4,
            30.0 * x2 - 60.0 * x3 + 30.0 * x4,
            -12.0 * x2 + 28.0 * x3 - 15.0 * x4,
            1.5 * x2 - 4.0 * x3 + 2.5 * x4,
        ],
        [
            -60.0 * x + 180.0 * x2 - 120.0 * x3,
            -36.0 * x + 96.0 * x2 - 60.0 * x3,
            1.0 - 9.0 * x + 18.0 * x2 - 10.0 * x3,
            60.0 * x - 180.0 * x2 + 120.0 * x3,
            -24.0 * x + 84.0 * x2 - 60.0 * x3,
            3.0 * x - 12.0 * x2 + 10.0 * x3,
        ],
        [
            -60.0 + 360.0 * x - 360.0 * x2,
            -36.0 + 192.0 * x - 180.0 * x2,
            -9.0 + 36.0 * x - 30.0 * x2,
            60.0 - 360.0 * x + 360.0 * x2,
            -24.0 + 168.0 * x - 180.0 * x2,
            3.0 - 24.0 * x + 30.0 * x2,
        ],
    ]
}

impl ChebVec {
    /// Interpolates `f` at Chebyshev–Lobatto points, doubling their number (16 … 128) until
    /// the series and `f` agree at the midpoints between nodes to `1e-14` of the function's
    /// size. A field that needs more (a spline through sampled normals, say) keeps 128 points
    /// and reports its [`ChebVec::fit_error`]: every evaluation of the patch pays for the
    /// length of the series. The midpoints of one level are the new nodes of the next, so `f`
    /// is called once per node of the last level.
    pub(crate) fn fit(f: &dyn Fn(f64) -> Vec3) -> ChebVec {
        let node =
            |j: usize, n: usize| 0.5 * ((std::f64::consts::PI * j as f64 / n as f64).cos() + 1.0);
        let mut n = 16;
        let mut vals: Vec<Vec3> = (0..=n).map(|j| f(node(j, n))).collect();
        loop {
            let series = derivative_series(&cheb_coefficients(&vals));
            let mut c = ChebVec {
                series,
                table: Vec::new(),
                fit_error: 0.0,
                unit: false,
            };
            // The midpoints: the odd nodes of the next level.
            let odd: Vec<Vec3> = (0..n).map(|j| f(node(2 * j + 1, 2 * n))).collect();
            let mut err: f64 = 0.0;
            let mut size = vals.iter().fold(0.0f64, |m, v| m.max(v.amax()));
            for (j, want) in odd.iter().enumerate() {
                size = size.max(want.amax());
                err = err.max((c.value(node(2 * j + 1, 2 * n)) - want).amax());
            }
            c.fit_error = err;
            if err <= 1e-14 * size.max(1e-300) || n >= 128 {
                if c.series[0][0].len() > SHORT {
                    c.table = c.tabulate();
                }
                return c;
            }
            let mut next = Vec::with_capacity(2 * n + 1);
            for j in 0..n {
                next.push(vals[j]);
                next.push(odd[j]);
            }
            next.push(vals[n]);
            vals = next;
            n *= 2;
        }
    }

    /// The unit vector field `v/|v|` of `v`: `v` as its own series ([`ChebVec::fit`], the
    /// tail that only rounding put there cut off), each evaluation normalising `v`'s jet. A
    /// side's neighbour normal is often the direction of a polynomial (an interpolant of
    /// sampled normals) whose unit vector is not one: its own series takes 17 to 65 terms to
    /// reach `1e-14` where `v` takes a handful, and every evaluation of the patch pays for the
    /// length. `None` where `v`'s series is long (tabulated), or `|v|` may fall below `1e-6`
    /// of its largest (the normalisation's derivatives would grow with `1/|v|`): the unit
    /// field is then fitted as it is.
    pub(crate) fn fit_unit(v: &dyn Fn(f64) -> Vec3) -> Option<ChebVec> {
        let mut c = ChebVec::fit(v);
        if !c.table.is_empty() {
            return None;
        }
        let len = c.series[0][0].len();
        // |v| at `M + 1` points, and between them at least the nearest one's less
        // `sup|v'| / 2M` (`sup|v'| ≤ 2 Σ|c'ₙ|` per coordinate, the series in `x = 2s − 1`).
        const M: usize = 64;
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for j in 0..=M {
            let x = length(c.value(j as f64 / M as f64));
            lo = lo.min(x);
            hi = hi.max(x);
        }
        let slope = c.series[1]
            .iter()
            .map(|x| 2.0 * x.iter().map(|y| y.abs()).sum::<f64>())
            .fold(0.0, f64::hypot);
        if !(lo - slope / (2 * M) as f64 >= 1e-6 * hi && hi.is_finite()) {
            return None;
        }
        // Trailing coefficients whose sum is below 1e-15 of the series' size: rounding.
        let size = |k: usize| c.series[0].iter().map(|x| x[k].abs()).sum::<f64>();
        let total: f64 = (0..len).map(size).sum();
        let (mut keep, mut cut) = (len, 0.0);
        while keep > 1 && cut + size(keep - 1) <= 1e-15 * total {
            cut += size(keep - 1);
            keep -= 1;
        }
        let kept = c.series[0].clone().map(|mut x| {
            x.truncate(keep);
            x
        });
        c.series = derivative_series(&kept);
        c.unit = true;
        Some(c)
    }

    fn value(&self, s: f64) -> Vec3 {
        self.series_at(0, s)
    }

    /// The series of the three coordinates in `x = 2s − 1`, if the field is evaluated from
    /// them (`None` for a tabulated one, whose third derivative jumps between table points:
    /// see [`ChebVec::piece_taylor`], and for a unit field: see [`ChebVec::unit_series`]).
    pub(crate) fn coordinate_series(&self) -> Option<&[Vec<f64>; 3]> {
        (self.table.is_empty() && !self.unit).then_some(&self.series[0])
    }

    /// For a unit field ([`ChebVec::fit_unit`]), the series of the coordinates of the field
    /// `v` it is the direction of.
    pub(crate) fn unit_series(&self) -> Option<&[Vec<f64>; 3]> {
        self.unit.then_some(&self.series[0])
    }

    /// A bound of `|f|` on `[0, 1]`: 1 for a unit field (to rounding), else the norm of
    /// [`ChebVec::size_bounds`].
    pub(crate) fn norm_bound(&self) -> f64 {
        if self.unit {
            return 1.0 + 1e-14;
        }
        let [x, y, z] = self.size_bounds();
        x.hypot(y).hypot(z)
    }

    /// The table's piece containing `s` (the one [`ChebVec::jet`] evaluates), for a tabulated
    /// field.
    pub(crate) fn piece_of(&self, s: f64) -> usize {
        ((s * TABLE as f64).floor().max(0.0) as usize).min(TABLE - 1)
    }

    /// The interval `[k/TABLE, (k + 1)/TABLE]` of piece `k`.
    pub(crate) fn piece_span(&self, k: usize) -> (f64, f64) {
        let h = 1.0 / TABLE as f64;
        (k as f64 * h, (k + 1) as f64 * h)
    }

    /// The Taylor coefficients `q⁽ʲ⁾(y)/j!`, `j = 0 ..= 5`, at any `y` of the quintic `q` that
    /// piece `k` of a tabulated field evaluates (extended beyond the piece).
    pub(crate) fn piece_taylor(&self, k: usize, y: f64) -> [Vec3; 6] {
        // The quintic Hermite basis' monomial coefficients (value, slope, second derivative at
        // 0, then at 1): `quintic`'s first row.
        const B: [[f64; 6]; 6] = [
            [1.0, 0.0, 0.0, -10.0, 15.0, -6.0],
            [0.0, 1.0, 0.0, -6.0, 8.0, -3.0],
            [0.0, 0.0, 0.5, -1.5, 1.5, -0.5],
            [0.0, 0.0, 0.0, 10.0, -15.0, 6.0],
            [0.0, 0.0, 0.0, -4.0, 7.0, -3.0],
            [0.0, 0.0, 0.0, 0.5, -1.0, 0.5],
        ];
        let h = 1.0 / TABLE as f64;
        let (a, c) = (&self.table[k], &self.table[k + 1]);
        let data = [
            a[0],
            a[1] * h,
            a[2] * (h * h),
            c[0],
            c[1] * h,
            c[2] * (h * h),
        ];
        let mono: [Vec3; 6] = std::array::from_fn(|m| {
            data.iter()
                .zip(&B)
                .fold(Vec3::zeros(), |acc, (d, b)| acc + d * b[m])
        });
        // About x_y = (y − k h)/h, then per unit of s.
        let x = (y - k as f64 * h) / h;
        std::array::from_fn(|j| {
            let mut sum = Vec3::zeros();
            for (m, cm) in mono.iter().enumerate().skip(j) {
                let binom = (0..j).fold(1.0, |acc, i| acc * (m - i) as f64 / (i + 1) as f64);
                sum += cm * (binom * x.powi((m - j) as i32));
            }
            sum / h.powi(j as i32)
        })
    }

    /// Bounds of each coordinate's size on `[0, 1]`: `Σ |c_n|` of a short series
    /// (`|T_n| ≤ 1`), or the largest over the table's pieces of their Taylor sums about the
    /// piece's middle.
    pub(crate) fn size_bounds(&self) -> [f64; 3] {
        if self.unit {
            return [1.0 + 1e-14; 3];
        }
        if let Some(c) = self.coordinate_series() {
            return [0, 1, 2].map(|i| c[i].iter().map(|x| x.abs()).sum::<f64>() * (1.0 + 1e-14));
        }
        let r = 0.5 / TABLE as f64;
        let mut out = [0.0f64; 3];
        for k in 0..TABLE {
            let (a, b) = self.piece_span(k);
            let t = self.piece_taylor(k, 0.5 * (a + b));
            for (c, o) in out.iter_mut().enumerate() {
                let sum: f64 = t
                    .iter()
                    .enumerate()
                    .map(|(j, x)| x[c].abs() * r.powi(j as i32))
                    .sum();
                *o = o.max(sum * (1.0 + 1e-14));
            }
        }
        out
    }

    /// The `k`-th derivative (`k ≤ 3`) at `s ∈ [0, 1]` (see [`ChebVec::jet`]).
    pub(crate) fn at(&self, k: usize, s: f64) -> Vec3 {
        self.jet::<3>(s)[k]
    }

    /// The value and derivatives up to `O` (`≤ 3`) at `s ∈ [0, 1]`: from a short series
    /// itself (a smooth field stays analytic, so quadratures over the patch converge at their
    /// full order), from the table when the series is long (the third derivative is then the
    /// quintic's, accurate to `O(h³)`). Only the derivatives up to `O` (`≤ 3`) are computed; the higher entries are zero and
    /// cost nothing, and the others do not depend on `O` (the same recurrences, to the bit).
    pub(crate) fn jet<const O: usize>(&self, s: f64) -> [Vec3; 4] {
        if self.unit {
            return normalised::<O>(self.all_at::<O>(s));
        }
        if self.table.is_empty() {
            return self.all_at::<O>(s);
        }
        let h = 1.0 / TABLE as f64;
        let i = ((s * TABLE as f64).floor().max(0.0) as usize).min(TABLE - 1);
        let x = (s - i as f64 * h) / h;
        let basis = quintic(x);
        let (a, c) = (&self.table[i], &self.table[i + 1]);
        let mut scale = 1.0;
        [0, 1, 2, 3].map(|k| {
            if k > O {
                return Vec3::zeros();
            }
            let b = basis[k];
            let v = a[0] * b[0]
                + a[1] * (h * b[1])
                + a[2] * (h * h * b[2])
                + c[0] * b[3]
                + c[1] * (h * b[4])
                + c[2] * (h * h * b[5]);
            let out = v * scale;
            scale /= h;
            out
        })
    }

    /// The `k`-th derivative (`k ≤ 3`) at `s` from the series.
    fn series_at(&self, k: usize, s: f64) -> Vec3 {
        let mut out = [0.0; 3];
        clenshaw_lanes(
            &self.series[k],
            2.0 * s - 1.0,
            [1.0, 2.0, 4.0, 8.0][k],
            &mut out,
        );
        Vec3::from(out)
    }

    /// `[f, f', f'']` at the table's points: the series times the Chebyshev polynomials'
    /// values there (one matrix product; the values come from the three-term recurrence,
    /// bounded by 1 on `[−1, 1]`, so the sums are as accurate as Clenshaw's).
    fn tabulate(&self) -> Vec<[Vec3; 3]> {
        let len = self.series[0][0].len();
        let t = chebyshev_at_table(len);
        let c = nalgebra::DMatrix::from_fn(len, 9, |m, l| self.series[l / 3][l % 3][m]);
        let v = &*t * c;
        (0..=TABLE)
            .map(|j| {
                [0, 1, 2].map(|k| {
                    Vec3::new(v[(j, 3 * k)], v[(j, 3 * k + 1)], v[(j, 3 * k + 2)])
                        * [1.0, 2.0, 4.0][k]
                })
            })
            .collect()
    }

    /// The value and derivatives up to `O` at `s` from the series: their recurrences (up
    /// to twelve) at once.
    fn all_at<const O: usize>(&self, s: f64) -> [Vec3; 4] {
        let mut lanes: [&[f64]; 12] = [&[]; 12];
        for (l, series) in lanes.iter_mut().zip(self.series.iter().flatten()) {
            *l = series.as_slice();
        }
        let mut out = [0.0; 12];
        let used = 3 * (O.min(3) + 1);
        clenshaw_lanes(&lanes[..used], 2.0 * s - 1.0, 1.0, &mut out[..used]);
        [0, 1, 2, 3].map(|k| {
            Vec3::new(out[3 * k], out[3 * k + 1], out[3 * k + 2]) * [1.0, 2.0, 4.0, 8.0][k]
        })
    }
}

/// `|v|` without over- or underflow in the squares.
fn length(v: Vec3) -> f64 {
    let m = v.amax();
    if m > 0.0 && m.is_finite() {
        m * (v / m).norm()
    } else {
        m
    }
}

/// `n = v/|v|` and its derivatives up to `O` (`≤ 3`; the higher entries zero) from `v`'s.
/// With `g = |v|⁻¹ = w^{−1/2}`, `w = v·v`: `n⁽ᵏ⁾ = Σ_j C(k, j) g⁽ʲ⁾ v⁽ᵏ⁻ʲ⁾`, and `g`'s
/// derivatives by the chain rule, `g' = −½ w^{−3/2} w'`,
/// `g'' = ¾ w^{−5/2} w'² − ½ w^{−3/2} w''`,
/// `g''' = −15/8 w^{−7/2} w'³ + 9/4 w^{−5/2} w' w'' − ½ w^{−3/2} w'''`; written in
/// `aₖ = w⁽ᵏ⁾/w` and `g⁽ʲ⁾/g` so that no power of `|v|` over- or underflows.
fn normalised<const O: usize>(v: [Vec3; 4]) -> [Vec3; 4] {
    let g = 1.0 / length(v[0]);
    let u = v.map(|x| x * g);
    let a1 = 2.0 * u[0].dot(&u[1]);
    let a2 = 2.0 * (u[1].dot(&u[1]) + u[0].dot(&u[2]));
    let a3 = 2.0 * (3.0 * u[1].dot(&u[2]) + u[0].dot(&u[3]));
    let h = [
        1.0,
        -0.5 * a1,
        0.75 * a1 * a1 - 0.5 * a2,
        -1.875 * a1 * a1 * a1 + 2.25 * a1 * a2 - 0.5 * a3,
    ];
    [0, 1, 2, 3].map(|k| {
        if k > O {
            return Vec3::zeros();
        }
        (0..=k).fold(Vec3::zeros(), |acc, j| {
            acc + u[k - j] * (h[j] * BINOM[k][j])
        })
    })
}

/// `T_m(2 s_j − 1)` at the table's points `s_j = j / TABLE`, `m < len` (kept per length).
fn chebyshev_at_table(len: usize) -> Arc<nalgebra::DMatrix<f64>> {
    static KEPT: OnceLock<Mutex<Vec<Arc<nalgebra::DMatrix<f64>>>>> = OnceLock::new();
    let kept = KEPT.get_or_init(|| Mutex::new(Vec::new()));
    if let Some(t) = kept
        .lock()
        .ok()
        .and_then(|k| k.iter().find(|t| t.ncols() == len).cloned())
    {
        return t;
    }
    let t = Arc::new(nalgebra::DMatrix::from_fn(TABLE + 1, len, |j, m| {
        let x = 2.0 * j as f64 / TABLE as f64 - 1.0;
        let (mut a, mut b) = (1.0, x);
        for _ in 0..m {
            (a, b) = (b, 2.0 * x * b - a);
        }
        a
    }));
    if let Ok(mut k) = kept.lock() {
        k.push(t.clone());
    }
    t
}

/// Chebyshev coefficients from the values at `x_j = cos(πj/n)`, `j = 0 … n`.
fn cheb_coefficients(vals: &[Vec3]) -> [Vec<f64>; 3] {
    let n = vals.len() - 1;
    let mut out = [vec![0.0; n + 1], vec![0.0; n + 1], vec![0.0; n + 1]];
    // cos(π m / n) for m = 0 … 2n − 1: every product j k reduces to one of them.
    let cosines: Vec<f64> = (0..2 * n)
        .map(|m| (std::f64::consts::PI * m as f64 / n as f64).cos())
        .collect();
    for k in 0..=n {
        let mut acc = Vec3::zeros();
        for (j, v) in vals.iter().enumerate() {
            let half = if j == 0 || j == n { 0.5 } else { 1.0 };
            acc += v * (half * cosines[(j * k) % (2 * n)]);
        }
        let mut scale = 2.0 / n as f64;
        if k == 0 || k == n {
            scale *= 0.5;
        }
        for (o, a) in out.iter_mut().zip(acc.iter()) {
            o[k] = a * scale;
        }
    }
    out
}

/// The series and its three derivative series, all padded with zeros to the series' length
/// so that they evaluate as lanes of one recurrence (a zero top coefficient changes no bit).
fn derivative_series(c: &[Vec<f64>; 3]) -> [[Vec<f64>; 3]; 4] {
    let d1 = [cheb_diff(&c[0]), cheb_diff(&c[1]), cheb_diff(&c[2])];
    let d2 = [cheb_diff(&d1[0]), cheb_diff(&d1[1]), cheb_diff(&d1[2])];
    let d3 = [cheb_diff(&d2[0]), cheb_diff(&d2[1]), cheb_diff(&d2[2])];
    let len = c[0].len();
    let pad = |mut v: Vec<f64>| {
        v.resize(len, 0.0);
        v
    };
    [c.clone(), d1.map(pad), d2.map(pad), d3.map(pad)]
}

/// The cubic Hermite basis with its first three derivatives (the third is constant).
fn hermite_basis3(s: f64) -> [[f64; 4]; 4] {
    let [h0, h1, h2] = hermite_basis(s);
    [h0, h1, h2, [12.0, 6.0, -12.0, 6.0]]
}

/// A cubic on `[0, 1]` from its values and slopes at the ends: `[v0, m0, v1, m1]`.
pub(crate) fn hermite_scalar(c: &[f64; 4], s: f64) -> [f64; 4] {
    let h = hermite_basis3(s);
    [0, 1, 2, 3].map(|k| (0..4).map(|j| h[k][j] * c[j]).sum())
}

/// A cubic curve on `[0, 1]` from its values and slopes at the ends.
pub(crate) fn hermite_vector(c: &[Vec3; 4], s: f64) -> [Vec3; 4] {
    let h = hermite_basis3(s);
    [0, 1, 2, 3].map(|k| (0..4).fold(Vec3::zeros(), |acc, j| acc + c[j] * h[k][j]))
}

/// The product of two functions of one variable given with three derivatives (Leibniz).
fn mul1(f: [f64; 4], g: [f64; 4]) -> [f64; 4] {
    [
        f[0] * g[0],
        f[1] * g[0] + f[0] * g[1],
        f[2] * g[0] + 2.0 * f[1] * g[1] + f[0] * g[2],
        f[3] * g[0] + 3.0 * (f[2] * g[1] + f[1] * g[2]) + f[0] * g[3],
    ]
}

/// A side as the patch uses it: the position curve, its cross-boundary derivative `D(s)` and
/// second cross derivative `E(s)` (the ribbon is `P + t D + t² E`; each with three
/// derivatives), and whether `D` and `E` are conditions (G1, G2) or the interpolant's choice.
#[derive(Clone, Debug)]
pub(crate) struct BuiltSide {
    pub side: Side,
    pub ribbon: BuiltRibbon,
    /// `E` at the two ends (linear in between) where `E` is free, its tangential part where
    /// `E` carries the neighbour's curvature: chosen so that neighbouring sides' ribbons agree
    /// to second order at the corners.
    pub e: [Vec3; 2],
    /// Changes of the slope `E'` at the two ends (a cubic added to the linear `E`, zero at
    /// both ends): chosen, for order 3, so that neighbouring ribbons agree to third order at
    /// the corners.
    pub e_slope: [Vec3; 2],
    /// `F` at the two ends (linear in between), the coefficient of `t³` in the ribbon
    /// (order 3 only; zero otherwise).
    pub f: [Vec3; 2],
    pub curvature: BuiltCurvature,
}

#[derive(Clone, Debug)]
pub(crate) enum BuiltRibbon {
    /// The side's own cross derivative, free (a position-only side): the cubic with the
    /// corner-compatible values and the twists `[D(0), D'(0), D(1), D'(1)]`.
    Free([Vec3; 4]),
    Derivative {
        curve: SharedCurve,
        t0: f64,
        t1: f64,
    },
    /// `D(s) = a(s) (N(s) × C'(s)) + b(s) C'(s)`, `a` and `b` cubics from their values and
    /// slopes at the ends, `N` the Chebyshev series of the neighbour's normal.
    Plane {
        normal: Box<ChebVec>,
        a: [f64; 4],
        b: [f64; 4],
    },
}

/// What fixes the second cross derivative `E` of a side.
#[derive(Clone, Debug)]
pub(crate) enum BuiltCurvature {
    /// Nothing: `E` is linear between its corner values.
    Free,
    /// The neighbour's normal curvature (with a plane ribbon): `N · E = II(D, D) / 2`, with
    /// `II(D, D) = a² K₀ + 2ab K₁ + b² K₂` and `K = [II(m, m), II(m, P'), II(P', P')]`,
    /// `m = N × P'`, as a Chebyshev series; the tangential part of `E` is linear between its
    /// corner values.
    Neighbour(Box<ChebVec>),
    /// `E = W/2` for the given second cross derivative `W`.
    Explicit {
        curve: SharedCurve,
        t0: f64,
        t1: f64,
    },
}

/// Binomial coefficients `C(k, j)`, `k ≤ 3`.
const BINOM: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

impl BuiltSide {
    /// True if the side carries a cross-boundary derivative as a condition (G1).
    pub(crate) fn has_ribbon(&self) -> bool {
        !matches!(self.ribbon, BuiltRibbon::Free(_))
    }

    /// True if the side carries a second cross derivative as a condition (G2).
    pub(crate) fn has_curvature(&self) -> bool {
        !matches!(self.curvature, BuiltCurvature::Free)
    }

    /// The number of conditions the side carries.
    pub(crate) fn multiplicity(&self) -> usize {
        1 + usize::from(self.has_ribbon()) + usize::from(self.has_curvature())
    }

    /// `P(s), P'(s), P''(s)`.
    pub(crate) fn position(&self, s: f64) -> [Vec3; 3] {
        let mut c = [Vec3::zeros(); 3];
        self.side.jet(s, &mut c);
        c
    }

    /// `m = N × P'` and `P'` at `s` for a plane ribbon (the two directions `D` is made of).
    pub(crate) fn plane_frame(&self, s: f64) -> Option<(Vec3, Vec3)> {
        match &self.ribbon {
            BuiltRibbon::Plane { normal, .. } => {
                let t = self.position(s)[1];
                Some((normal.at(0, s).cross(&t), t))
            }
            _ => None,
        }
    }

    /// `D(s), D'(s), D''(s), D'''(s)`.
    pub(crate) fn ribbon(&self, s: f64) -> [Vec3; 4] {
        let mut p = [Vec3::zeros(); 5];
        if matches!(self.ribbon, BuiltRibbon::Plane { .. }) {
            self.side.jet(s, &mut p);
        }
        self.ribbon_on::<3>(&p, s)
    }

    /// `E(s)` and its derivatives up to `O` (`≤ 3`; the higher entries are zero).
    pub(crate) fn second<const O: usize>(&self, s: f64) -> [Vec3; 4] {
        // The free part: linear between the ends, plus the cubic `h₁₀ δ₀ + h₁₁ δ₁` (zero at
        // both ends, slopes δ₀ and δ₁ there) of the slope changes.
        let h = hermite_basis3(s);
        let [d0, d1] = self.e_slope;
        let lin: [Vec3; 4] = [0, 1, 2, 3].map(|k| {
            let base = match k {
                0 => self.e[0] + (self.e[1] - self.e[0]) * s,
                1 => self.e[1] - self.e[0],
                _ => Vec3::zeros(),
            };
            base + d0 * h[k][1] + d1 * h[k][3]
        });
        match (&self.curvature, &self.ribbon) {
            (BuiltCurvature::Explicit { curve, t0, t1 }, _) => {
                let mut w = [Vec3::zeros(); 4];
                curve_jet(curve, *t0, *t1, s, &mut w[..=O.min(3)]);
                w.map(|x| x * 0.5)
            }
            (BuiltCurvature::Neighbour(k), BuiltRibbon::Plane { normal, a, b }) => {
                let n = normal.jet::<O>(s);
                let (a, b) = (hermite_scalar(a, s), hermite_scalar(b, s));
                let kk = k.jet::<O>(s);
                let comp = |i: usize| [kk[0][i], kk[1][i], kk[2][i], kk[3][i]];
                // κ = a² K₀ + 2ab K₁ + b² K₂ = II(D, D).
                let (aa, ab, bb) = (mul1(a, a), mul1(a, b), mul1(b, b));
                let (k0, k1, k2) = (mul1(aa, comp(0)), mul1(ab, comp(1)), mul1(bb, comp(2)));
                let kappa: [f64; 4] = [0, 1, 2, 3].map(|j| k0[j] + 2.0 * k1[j] + k2[j]);
                // E = l + N g with g = κ/2 − N·l (l the free part): N·E = κ/2 wherever
                // |N| = 1, and l moves only the tangential part of E.
                let g: [f64; 4] = [0, 1, 2, 3].map(|k| {
                    if k > O {
                        return 0.0;
                    }
                    0.5 * kappa[k]
                        - (0..=k)
                            .map(|j| n[j].dot(&lin[k - j]) * BINOM[k][j])
                            .sum::<f64>()
                });
                let ng: [Vec3; 4] = [0, 1, 2, 3].map(|k| {
                    if k > O {
                        return Vec3::zeros();
                    }
                    (0..=k).fold(Vec3::zeros(), |acc, j| {
                        acc + n[j] * (g[k - j] * BINOM[k][j])
                    })
                });
                [0, 1, 2, 3].map(|k| if k > O { Vec3::zeros() } else { lin[k] + ng[k] })
            }
            _ => [0, 1, 2, 3].map(|k| if k > O { Vec3::zeros() } else { lin[k] }),
        }
    }

    /// `P`, `D`, `E` and `F` at `s`, each with its derivatives up to `O` (`≤ 3`; the
    /// higher entries are zero and cost nothing): the side's curve evaluated once.
    pub(crate) fn data<const O: usize>(&self, s: f64) -> [[Vec3; 4]; 4] {
        let mut p = [Vec3::zeros(); 5];
        // A plane ribbon's `D = a N × P' + b P'` takes one derivative of `P` more.
        let plane = matches!(self.ribbon, BuiltRibbon::Plane { .. });
        self.side
            .jet(s, &mut p[..O.min(3) + 1 + usize::from(plane)]);
        let z = Vec3::zeros();
        let f1 = if O >= 1 { self.f[1] - self.f[0] } else { z };
        [
            [0, 1, 2, 3].map(|k| if k > O { z } else { p[k] }),
            self.ribbon_on::<O>(&p, s),
            self.second::<O>(s),
            [self.f[0] + (self.f[1] - self.f[0]) * s, f1, z, z],
        ]
    }

    /// `m = N × P'` and its derivatives up to `O`, given `N … N'''` and `P … P''''`.
    fn frame_m<const O: usize>(n: &[Vec3; 4], p: &[Vec3; 5]) -> [Vec3; 4] {
        [0, 1, 2, 3].map(|k| {
            if k > O {
                return Vec3::zeros();
            }
            (0..=k).fold(Vec3::zeros(), |acc, j| {
                acc + n[j].cross(&p[1 + k - j]) * BINOM[k][j]
            })
        })
    }

    /// `D` and its derivatives up to `O` (`≤ 3`; the higher entries are zero) given the
    /// side's `P … P^(O + 1)` at `s` (used by plane ribbons only).
    fn ribbon_on<const O: usize>(&self, p: &[Vec3; 5], s: f64) -> [Vec3; 4] {
        match &self.ribbon {
            BuiltRibbon::Free(c) => {
                let d = hermite_vector(c, s);
                [0, 1, 2, 3].map(|k| if k > O { Vec3::zeros() } else { d[k] })
            }
            BuiltRibbon::Derivative { curve, t0, t1 } => {
                let mut c = [Vec3::zeros(); 4];
                curve_jet(curve, *t0, *t1, s, &mut c[..=O.min(3)]);
                c
            }
            BuiltRibbon::Plane { normal, a, b } => {
                let n = normal.jet::<O>(s);
                let a = hermite_scalar(a, s);
                let b = hermite_scalar(b, s);
                let m = Self::frame_m::<O>(&n, p);
                // (a m + b P')^(k) by Leibniz.
                [0, 1, 2, 3].map(|k| {
                    if k > O {
                        return Vec3::zeros();
                    }
                    (0..=k).fold(Vec3::zeros(), |acc, j| {
                        acc + (m[k - j] * a[j] + p[1 + k - j] * b[j]) * BINOM[k][j]
                    })
                })
            }
        }
    }

    /// Adds `delta` to the twist `D'` at the start (`end = false`) or end of the side, as far
    /// as the ribbon allows: all of it for a free ribbon, its part in the neighbour's tangent
    /// plane for a plane ribbon, nothing for an explicit one.
    pub(crate) fn add_twist(&mut self, end: bool, delta: Vec3) {
        let s = if end { 1.0 } else { 0.0 };
        let frame = self.plane_frame(s);
        let slot = if end { 3 } else { 1 };
        match (&mut self.ribbon, frame) {
            (BuiltRibbon::Free(c), _) => c[slot] += delta,
            (BuiltRibbon::Plane { a, b, .. }, Some((m, t))) => {
                a[slot] += delta.dot(&m) / m.norm_squared();
                b[slot] += delta.dot(&t) / t.norm_squared();
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chebyshev_series_fit_smooth_fields_with_their_derivatives() {
        let f = |s: f64| Vec3::new((3.0 * s).sin(), s * s * s, (-s).exp());
        let c = ChebVec::fit(&f);
        assert!(c.fit_error < 1e-14, "{}", c.fit_error);
        for s in [0.0f64, 0.13, 0.5, 0.97, 1.0] {
            let d1 = Vec3::new(3.0 * (3.0 * s).cos(), 3.0 * s * s, -(-s).exp());
            let d2 = Vec3::new(-9.0 * (3.0 * s).sin(), 6.0 * s, (-s).exp());
            assert!((c.at(0, s) - f(s)).amax() < 1e-14);
            assert!(
                (c.at(1, s) - d1).amax() < 1e-12,
                "{}",
                (c.at(1, s) - d1).amax()
            );
            assert!(
                (c.at(2, s) - d2).amax() < 1e-10,
                "{}",
                (c.at(2, s) - d2).amax()
            );
        }
    }

    /// The direction of a quintic (an interpolant of sampled normals), at scales from
    /// `1e-200` to `1e200`: the unit field keeps the quintic's six terms; its value and three
    /// derivatives agree with the unit field fitted as it is (a series of its own, of `N > 16`
    /// terms, differentiated term by term: its value within `1e-14`, and by Markov's inequality
    /// each derivative may multiply that by `N²`), and each derivative with central
    /// differences of the one below (step `1e-4`: truncation about `1e-8` of the next
    /// derivatives' size, rounding `1e-12`).
    #[test]
    fn unit_fields_normalise_the_jets_of_a_short_field() {
        let q = |s: f64| {
            Vec3::new(
                0.6 * s - 0.4 * s.powi(5),
                0.2 - 0.8 * s * s + 0.6 * s.powi(4),
                1.0 + 0.4 * s.powi(3),
            )
        };
        let unit = |s: f64| q(s).normalize();
        let plain = ChebVec::fit(&unit);
        let long = plain.coordinate_series().expect("a series")[0].len();
        assert!(long > 16, "{long}");
        let markov = (long * long) as f64;
        for scale in [1e-200, 1.0, 1e200] {
            let c = ChebVec::fit_unit(&|s| q(s) * scale).expect("a short field");
            assert_eq!(c.unit_series().unwrap()[0].len(), 6);
            assert!(c.coordinate_series().is_none());
            for s in [0.0f64, 0.13, 0.5, 0.77, 1.0] {
                let (a, b) = (c.jet::<3>(s), plain.jet::<3>(s));
                for k in 0..4 {
                    let tol = 1e-14 * markov.powi(k as i32);
                    assert!(
                        (a[k] - b[k]).amax() < tol,
                        "{scale:e} {s} {k}: {:?}",
                        a[k] - b[k]
                    );
                }
                let h = 1e-4;
                let t = s.clamp(h, 1.0 - h);
                let (up, down, here) = (c.jet::<3>(t + h), c.jet::<3>(t - h), c.jet::<3>(t));
                for k in 1..4 {
                    let fd = (up[k - 1] - down[k - 1]) / (2.0 * h);
                    assert!(
                        (here[k] - fd).amax() < 1e-6 * (1.0 + here[k].amax()),
                        "{scale:e} {t} {k}: {:?} against {:?}",
                        here[k],
                        fd
                    );
                }
                assert!((a[0].norm() - 1.0).abs() < 1e-15);
                // Only the asked-for derivatives, the same to the bit.
                let one = c.jet::<1>(s);
                assert_eq!([one[0], one[1]], [a[0], a[1]]);
                assert_eq!([one[2], one[3]], [Vec3::zeros(); 2]);
            }
        }
        // A long field, and one whose length falls to 1e-9 of its largest, are not taken.
        assert!(ChebVec::fit_unit(&|s: f64| Vec3::new((300.0 * s).sin(), 1.0, 0.0)).is_none());
        assert!(ChebVec::fit_unit(&|s: f64| Vec3::new(s - 0.37, 1e-9, 0.0)).is_none());
    }
}
