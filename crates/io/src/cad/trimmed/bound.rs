//! The 3D edge of a hole with a proven deviation from the net's image `f = N ∘ pc` of its
//! pcurve.
//!
//! # Cells on which `f` is smooth
//!
//! The net `N` is a polynomial on each cell of its knot grid, and the pcurve `pc` a polynomial
//! (degree 1 or 3) on each of its spans, so `f` is `C^∞` on every interval of `s` inside one
//! span whose image stays in one closed knot cell. Each span is written as a Bézier piece and
//! cut into such intervals recursively ([`cells`]): an interval whose control polygon's `u`
//! and `v` ranges lie in one closed knot cell is *smooth* (the curve lies in the hull of its
//! control points); else, if a knot line crosses the ranges and the control values of that
//! coordinate are strictly monotone (so the coordinate is monotone and crosses the line
//! once), the crossing is bracketed by bisection and a *bracket* of width `w` around it
//! becomes a cell of its own, the two remainders cut again; else the interval is halved. An
//! interval no wider than `w` is a bracket. Every piece of a span thus ends up a smooth cell
//! or a bracket.
//!
//! # The bound on a smooth cell
//!
//! On a smooth cell of width `h` the edge is the cubic Hermite interpolant of `f` and `f'`
//! at its ends (the one-sided derivatives of the cell's own polynomials, `N` of the knot cell
//! the cell lies in), and `|f − H f| ≤ h⁴/384 · sup|f⁗|` (`certify`'s module docs). `sup|f⁗|`
//! is bounded by the majorant of the composition ([`crate::majorant`]):
//! `24 · [s⁴] Σ_{a+b≤4} M_ab/(a! b!) Û^a V̂^b`, with
//! - `M_ab ≥ sup|∂_u^a ∂_v^b N|` over the knot cell: the derivative of order `(a, b)` of a
//!   B-spline surface is a B-spline surface of degree `(p − a, q − b)` whose control points
//!   are the divided differences `P^{(a)}_i = (p − a + 1)/(t_{i+p+1} − t_{i+a}) ·
//!   (P^{(a−1)}_{i+1} − P^{(a−1)}_i)` (in `u`, then the same in `v`); on one knot cell its
//!   value is a convex combination (non-negative B-splines summing to one) of the
//!   `(p − a + 1)(q − b + 1)` of them that live there, so the largest of their norms bounds it
//!   (`0` above the degrees) — [`cell_partials`];
//! - `U_k ≥ sup|u^{(k)}|` over the cell: for the cell's Bézier piece of degree `d` with
//!   control values `b_i` the `k`-th derivative is the Bézier piece with control values
//!   `d!/(d − k)! · Δ^k b_i / h^k`, bounded by their largest magnitude; the same for `V_k`.
//!
//! A cell whose bound exceeds the budget is cut into `⌈(bound/budget)^{1/4}⌉` equal pieces
//! (the remainder scales as `h⁴`), each bounded again with its own, smaller `U_k`, `V_k`
//! (its control polygon lies in its parent's hull: the same knot cell).
//!
//! # The bound on a bracket
//!
//! Inside a bracket `f` may cross knot lines (once, or more where the monotone test failed),
//! so it is bounded with a lower-order argument, on the whole net: `G_ab` the largest
//! `M_ab` over all knot cells, `U_k`, `V_k` from the bracket's own Bézier piece.
//! - If `N` is `C¹` (degrees `≥ 2`, every interior knot of multiplicity at most the degree
//!   less one), `f` is `C¹` with `f'` Lipschitz, `|f''| ≤ L₂ = 2 [s²] Σ_{a+b≤2} G_ab/(a! b!)
//!   Û^a V̂^b` off the crossings. With `ℓ` the linear interpolant of `f` on the bracket,
//!   `r = f − ℓ` has `r(s₀) = r(s₁) = 0`, so `|r| ≤ L₂ h²/8`, and `∫ r' = 0`, so
//!   `|r'(s₀)|, |r'(s₁)| ≤ L₂ h/2`; `H` reproduces `ℓ`, so `f − H f = r − H r` with
//!   `H r = h (r'(s₀) H₁₀ + r'(s₁) H₁₁)` and `|H₁₀| + |H₁₁| = t(1 − t) ≤ 1/4`: together
//!   `|f − H f| ≤ L₂ h²/4`.
//! - Otherwise `N` is continuous (a net's knots never exceed that multiplicity inside), `f` is
//!   Lipschitz with `|f'| ≤ L₁ = [s¹] Σ G_ab Û^a V̂^b`, the end slopes of `H f` are bounded by
//!   `L₁` too, and `f − H f = (f − f₀) H₀₀ + (f − f₁) H₀₁ − h (f'₀ H₁₀ + f'₁ H₁₁)` gives
//!   `|f − H f| ≤ L₁ h g(t)`, `g(t) = t H₀₀ + (1 − t) H₀₁ + t(1 − t) = 2t + 2t² − 8t³ + 4t⁴`,
//!   whose largest value on `[0, 1]` is `g(1/2) = 3/4`: `|f − H f| ≤ 3/4 · L₁ h`.
//!
//! The bracket's width `w` is chosen (from the span's `U_k`, `V_k`) so that its bound is at
//! most `1/1024` of the budget. A pcurve whose control polygon leaves the net's domain, or a
//! net of degree 0, gets no proof (the caller falls back to sampling).
//!
//! The figure is the largest cell bound plus a rounding allowance of `ROUNDING` times the
//! size of the net (the nodal data, the Bézier pieces and the control hulls are computed in
//! floating point).

use crate::cad::curve::BCurve;
use crate::majorant::{Majorant, ORDER};
use crate::spline::knots::basis_derivatives;
use crate::spline::BSplineSurface;
use crate::Vec3;

/// Relative rounding allowance (times the size of the net).
const ROUNDING: f64 = 1e-12;
/// The most cells of one edge.
const MAX_CELLS: usize = 1 << 16;
/// A bracket's bound as a fraction of the budget.
const BRACKET_SHARE: f64 = 1.0 / 1024.0;

/// Bounds `M[a][b] ≥ |∂_u^a ∂_v^b N|` (`a + b ≤ 4`).
type Partials = [[f64; ORDER + 1]; ORDER + 1];

/// One polynomial span of the pcurve: its interval of `s` and its Bézier control points.
struct Span {
    s: [f64; 2],
    ctrl: Vec<[f64; 2]>,
}

impl Span {
    /// `s` at the local parameter `t ∈ [0, 1]` (the ends exact).
    fn s_at(&self, t: f64) -> f64 {
        if t >= 1.0 {
            self.s[1]
        } else {
            self.s[0] + (self.s[1] - self.s[0]) * t
        }
    }
}

/// How `f` is bounded on a cell.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// Inside the knot cell with these `u`, `v` spans of the net.
    Smooth([usize; 2]),
    /// A bracket (a lower-order argument).
    Bracket,
}

/// One cell: its span, its local parameters `t₀ < t₁`, its kind and bound.
#[derive(Clone, Copy, Debug)]
struct Cell {
    span: usize,
    t: [f64; 2],
    kind: Kind,
    bound: f64,
}

/// The Bézier pieces of the pcurve's spans (`None` if a knot breaks the curve apart).
fn spans(pc: &BCurve) -> Option<Vec<Span>> {
    let mut c = pc.clamped();
    let p = c.degree;
    let breaks = c.breaks();
    if breaks.len() < 2 {
        return None;
    }
    for &b in &breaks[1..breaks.len() - 1] {
        while c.knots.iter().filter(|&&k| k == b).count() < p {
            c = c.insert(b);
        }
    }
    if c.points.len() != (breaks.len() - 1) * p + 1 {
        return None;
    }
    Some(
        breaks
            .windows(2)
            .enumerate()
            .map(|(i, w)| Span {
                s: [w[0], w[1]],
                ctrl: c.points[i * p..=i * p + p]
                    .iter()
                    .map(|q| [q.x, q.y])
                    .collect(),
            })
            .collect(),
    )
}

/// De Casteljau: the control points of the piece on `[0, t]` and on `[t, 1]`.
fn split(ctrl: &[[f64; 2]], t: f64) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let n = ctrl.len();
    let mut work = ctrl.to_vec();
    let mut left = vec![work[0]];
    let mut right = vec![work[n - 1]];
    for r in 1..n {
        for i in 0..n - r {
            let next = work[i + 1];
            for (x, y) in work[i].iter_mut().zip(next) {
                *x = *x * (1.0 - t) + y * t;
            }
        }
        left.push(work[0]);
        right.push(work[n - 1 - r]);
    }
    right.reverse();
    (left, right)
}

/// The control points of the piece on `[t₀, t₁] ⊂ [0, 1]`.
fn sub(ctrl: &[[f64; 2]], t0: f64, t1: f64) -> Vec<[f64; 2]> {
    let left = if t1 < 1.0 {
        split(ctrl, t1).0
    } else {
        ctrl.to_vec()
    };
    if t0 > 0.0 && t1 > 0.0 {
        split(&left, t0 / t1).1
    } else {
        left
    }
}

/// The point of a Bézier piece at `t`.
fn point(ctrl: &[[f64; 2]], t: f64) -> [f64; 2] {
    split(ctrl, t).1[0]
}

/// The derivative in `t` of a Bézier piece at `t`.
fn slope(ctrl: &[[f64; 2]], t: f64) -> [f64; 2] {
    let d = (ctrl.len() - 1) as f64;
    if ctrl.len() < 2 {
        return [0.0; 2];
    }
    let hodo: Vec<[f64; 2]> = ctrl
        .windows(2)
        .map(|w| [d * (w[1][0] - w[0][0]), d * (w[1][1] - w[0][1])])
        .collect();
    point(&hodo, t)
}

/// `[U, V]`: bounds `U_k ≥ |u^{(k)}|`, `V_k ≥ |v^{(k)}|` (`k ≤ 4`) over a Bézier piece spanning
/// `h` in `s`, from its differences.
fn coordinate_bounds(ctrl: &[[f64; 2]], h: f64) -> [[f64; ORDER + 1]; 2] {
    let mut out = [[0.0; ORDER + 1]; 2];
    let d = ctrl.len() - 1;
    for (c, o) in out.iter_mut().enumerate() {
        let mut diff: Vec<f64> = ctrl.iter().map(|q| q[c]).collect();
        let mut factor = 1.0;
        for (k, ok) in o.iter_mut().enumerate() {
            if k > d {
                break;
            }
            if k > 0 {
                diff = diff.windows(2).map(|w| w[1] - w[0]).collect();
                factor *= (d + 1 - k) as f64 / h;
            }
            *ok = factor * diff.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        }
    }
    out
}

/// The majorant of `f = N ∘ pc` on a piece with the net's bounds `m` and the piece's
/// coordinate bounds.
fn composed(m: &Partials, uv: &[[f64; ORDER + 1]; 2]) -> Majorant {
    Majorant::compose2(
        m,
        &Majorant::increment(&uv[0]),
        &Majorant::increment(&uv[1]),
    )
}

/// `M_ab` over the knot cell of spans `(su, sv)` (`knots_u[su] < knots_u[su + 1]`, the same
/// in `v`), from the divided differences of its `(p + 1)(q + 1)` control points.
fn cell_partials(net: &BSplineSurface, su: usize, sv: usize) -> Partials {
    let [p, q] = net.degree();
    let nv = net.counts()[1];
    let (ku, kv, c) = (net.knots_u(), net.knots_v(), net.control());
    let mut m = [[0.0; ORDER + 1]; ORDER + 1];
    // level[i][j]: the u-differences of order a (i = 0..=p − a, global index su − p + i).
    let mut level: Vec<Vec<Vec3>> = (0..=p)
        .map(|i| (0..=q).map(|j| c[(su - p + i) * nv + sv - q + j]).collect())
        .collect();
    for (a, row) in m.iter_mut().enumerate() {
        if a > p {
            break;
        }
        if a > 0 {
            level = (0..level.len() - 1)
                .map(|i| {
                    let g = su - p + i;
                    let f = (p + 1 - a) as f64 / (ku[g + p + 1] - ku[g + a]);
                    (0..=q)
                        .map(|j| (level[i + 1][j] - level[i][j]) * f)
                        .collect()
                })
                .collect();
        }
        let mut cols = level.clone();
        for (b, mab) in row.iter_mut().enumerate().take(ORDER + 1 - a) {
            if b > q {
                break;
            }
            if b > 0 {
                cols = cols
                    .iter()
                    .map(|r| {
                        (0..r.len() - 1)
                            .map(|j| {
                                let g = sv - q + j;
                                let f = (q + 1 - b) as f64 / (kv[g + q + 1] - kv[g + b]);
                                (r[j + 1] - r[j]) * f
                            })
                            .collect()
                    })
                    .collect();
            }
            *mab = cols.iter().flatten().fold(0.0f64, |x, y| x.max(y.norm()));
        }
    }
    m
}

/// The non-empty spans `k` (`knots[k] < knots[k + 1]`) of one direction's domain.
fn live_spans(knots: &[f64], p: usize, n: usize) -> Vec<usize> {
    (p..n).filter(|&k| knots[k] < knots[k + 1]).collect()
}

/// True if every interior knot of the direction has multiplicity at most `p − 1` (`C¹`).
fn is_c1(knots: &[f64], p: usize, n: usize) -> bool {
    let (a, b) = (knots[p], knots[n]);
    p >= 2
        && knots
            .iter()
            .filter(|&&k| k > a && k < b)
            .all(|&k| knots.iter().filter(|&&x| x == k).count() < p)
}

/// `∂_u^{ku} ∂_v^{kv} N` at `(u, v)` from the polynomial of the knot cell `(su, sv)`.
fn piece_derivative(net: &BSplineSurface, cell: [usize; 2], uv: [f64; 2], k: [usize; 2]) -> Vec3 {
    let [p, q] = net.degree();
    let nv = net.counts()[1];
    if k[0] > p || k[1] > q {
        return Vec3::zeros();
    }
    let mut bu = vec![0.0; (k[0] + 1) * (p + 1)];
    let mut bv = vec![0.0; (k[1] + 1) * (q + 1)];
    basis_derivatives(net.knots_u(), p, cell[0], &uv[0], k[0], &mut bu);
    basis_derivatives(net.knots_v(), q, cell[1], &uv[1], k[1], &mut bv);
    let (bu, bv) = (&bu[k[0] * (p + 1)..], &bv[k[1] * (q + 1)..]);
    let mut x = Vec3::zeros();
    for (r, nr) in bu.iter().enumerate() {
        let row = (cell[0] - p + r) * nv + cell[1] - q;
        for (c, nc) in bv.iter().enumerate() {
            x += net.control()[row + c] * (nr * nc);
        }
    }
    x
}

/// The net's knot grid and bounds.
struct Grid<'a> {
    net: &'a BSplineSurface,
    spans: [Vec<usize>; 2],
    /// `G_ab`: the largest `M_ab` over all knot cells.
    global: Partials,
    c1: bool,
    cache: std::collections::HashMap<[usize; 2], Partials>,
}

impl<'a> Grid<'a> {
    fn new(net: &'a BSplineSurface) -> Option<Grid<'a>> {
        let [p, q] = net.degree();
        let [nu, nv] = net.counts();
        if p == 0 || q == 0 {
            return None;
        }
        let spans = [
            live_spans(net.knots_u(), p, nu),
            live_spans(net.knots_v(), q, nv),
        ];
        let mut global: Partials = [[0.0; ORDER + 1]; ORDER + 1];
        for &su in &spans[0] {
            for &sv in &spans[1] {
                let m = cell_partials(net, su, sv);
                for a in 0..=ORDER {
                    for b in 0..=ORDER {
                        global[a][b] = global[a][b].max(m[a][b]);
                    }
                }
            }
        }
        let c1 = is_c1(net.knots_u(), p, nu) && is_c1(net.knots_v(), q, nv);
        Some(Grid {
            net,
            spans,
            global,
            c1,
            cache: std::collections::HashMap::new(),
        })
    }

    /// The knot cell `[su, sv]` whose closed box holds the ranges `[lo, hi]` of both
    /// coordinates, if any.
    fn cell_of(&self, lo: [f64; 2], hi: [f64; 2]) -> Option<[usize; 2]> {
        let knots = [self.net.knots_u(), self.net.knots_v()];
        let mut out = [0; 2];
        for c in 0..2 {
            let k = knots[c];
            let spans = &self.spans[c];
            // The first span ending after lo (the last one if lo is the domain's end).
            let i = spans.partition_point(|&s| k[s + 1] <= lo[c]);
            let s = *spans.get(i).or(spans.last())?;
            if !(k[s] <= lo[c] && hi[c] <= k[s + 1]) {
                return None;
            }
            out[c] = s;
        }
        Some(out)
    }

    /// A knot line strictly inside `(lo, hi)` of coordinate `c`.
    fn line_inside(&self, c: usize, lo: f64, hi: f64) -> Option<f64> {
        let k = if c == 0 {
            self.net.knots_u()
        } else {
            self.net.knots_v()
        };
        self.spans[c]
            .iter()
            .map(|&s| k[s])
            .find(|&x| x > lo && x < hi)
    }

    /// The bound of a bracket on a Bézier piece spanning `h`.
    fn bracket_bound(&self, ctrl: &[[f64; 2]], h: f64) -> f64 {
        let m = composed(&self.global, &coordinate_bounds(ctrl, h));
        if self.c1 {
            m.derivative(2) * h * h / 4.0
        } else {
            0.75 * m.derivative(1) * h
        }
    }

    /// The width (in `s`) of a bracket with a bound of at most `budget` on the span.
    fn bracket_width(&self, span: &Span, budget: f64) -> f64 {
        let h = span.s[1] - span.s[0];
        let m = composed(&self.global, &coordinate_bounds(&span.ctrl, h));
        let w = if self.c1 {
            (4.0 * budget / m.derivative(2)).sqrt()
        } else {
            budget / (0.75 * m.derivative(1))
        };
        if w.is_nan() {
            0.0
        } else {
            w.min(h)
        }
    }

    /// The bound on a smooth cell of the knot cell `cell` with the piece `ctrl` spanning `h`.
    fn smooth_bound(&mut self, cell: [usize; 2], ctrl: &[[f64; 2]], h: f64) -> f64 {
        let net = self.net;
        let m = *self
            .cache
            .entry(cell)
            .or_insert_with(|| cell_partials(net, cell[0], cell[1]));
        h.powi(4) / 384.0 * composed(&m, &coordinate_bounds(ctrl, h)).derivative(4)
    }
}

/// The coordinate `c` of a Bézier piece at `t`.
fn coordinate(ctrl: &[[f64; 2]], c: usize, t: f64) -> f64 {
    point(ctrl, t)[c]
}

/// The cells of one span ([`cells`] of the module docs), in order; `w` the bracket width in
/// `s`. `None` if there would be more than [`MAX_CELLS`].
fn cells(grid: &Grid, index: usize, span: &Span, w: f64, out: &mut Vec<Cell>) -> Option<()> {
    let h = span.s[1] - span.s[0];
    let wt = (w / h).max(1e-12);
    // Intervals to cut, and whether one is a bracket already.
    let mut work = vec![([0.0, 1.0], false)];
    let mut done: Vec<Cell> = Vec::new();
    while let Some(([t0, t1], bracket)) = work.pop() {
        if done.len() + work.len() > MAX_CELLS {
            return None;
        }
        if bracket {
            done.push(Cell {
                span: index,
                t: [t0, t1],
                kind: Kind::Bracket,
                bound: 0.0,
            });
            continue;
        }
        let ctrl = sub(&span.ctrl, t0, t1);
        let lo = [0, 1].map(|c| ctrl.iter().fold(f64::INFINITY, |m, q| m.min(q[c])));
        let hi = [0, 1].map(|c| ctrl.iter().fold(f64::NEG_INFINITY, |m, q| m.max(q[c])));
        let mut cell = Cell {
            span: index,
            t: [t0, t1],
            kind: Kind::Bracket,
            bound: 0.0,
        };
        if let Some(k) = grid.cell_of(lo, hi) {
            cell.kind = Kind::Smooth(k);
            done.push(cell);
            continue;
        }
        if t1 - t0 <= wt {
            done.push(cell);
            continue;
        }
        // A line crossed by a monotone coordinate: bracket its crossing.
        let mut crossing = None;
        for c in 0..2 {
            let Some(line) = grid.line_inside(c, lo[c], hi[c]) else {
                continue;
            };
            let d: Vec<f64> = ctrl.windows(2).map(|x| x[1][c] - x[0][c]).collect();
            let up = d.iter().all(|&x| x > 0.0);
            if !(up || d.iter().all(|&x| x < 0.0)) {
                continue;
            }
            let below = |t: f64| (coordinate(&span.ctrl, c, t) < line) == up;
            let (mut a, mut b) = (t0, t1);
            while b - a > 0.25 * wt {
                let mid = 0.5 * (a + b);
                if below(mid) {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            crossing = Some(0.5 * (a + b));
            break;
        }
        match crossing {
            Some(x) => {
                let (a, b) = ((x - 0.5 * wt).max(t0), (x + 0.5 * wt).min(t1));
                // Remainders pushed so that the left one is taken first.
                if b < t1 {
                    work.push(([b, t1], false));
                }
                work.push(([a, b], true));
                if a > t0 {
                    work.push(([t0, a], false));
                }
            }
            None => {
                let mid = 0.5 * (t0 + t1);
                work.push(([mid, t1], false));
                work.push(([t0, mid], false));
            }
        }
    }
    out.extend(done);
    Some(())
}

/// The proven edge of a pcurve on the net, with every cell bound at most `target` less the
/// rounding allowance: the edge and its bound, or `None` if no proof applies (the pcurve
/// leaves the net's domain, the net has degree 0, or the cells would be too many).
pub(super) fn proven_edge(net: &BSplineSurface, pc: &BCurve, target: f64) -> Option<(BCurve, f64)> {
    let mut grid = Grid::new(net)?;
    let spans = spans(pc)?;
    let [[u0, u1], [v0, v1]] = net.domain();
    for sp in &spans {
        if sp
            .ctrl
            .iter()
            .any(|q| !(q[0] >= u0 && q[0] <= u1 && q[1] >= v0 && q[1] <= v1))
        {
            return None;
        }
    }
    let size = net.control().iter().fold(1.0f64, |m, p| m.max(p.amax()));
    let allowance = ROUNDING * size;
    let budget = target - allowance;
    if budget.is_nan() || budget <= 0.0 {
        return None;
    }
    let mut all: Vec<Cell> = Vec::new();
    for (i, sp) in spans.iter().enumerate() {
        let w = grid.bracket_width(sp, BRACKET_SHARE * budget);
        cells(&grid, i, sp, w, &mut all)?;
    }
    // Bound every cell; cut smooth cells over the budget into equal pieces.
    let mut done: Vec<Cell> = Vec::with_capacity(all.len());
    let mut work: Vec<Cell> = all.into_iter().rev().collect();
    while let Some(mut cell) = work.pop() {
        if done.len() + work.len() > MAX_CELLS {
            return None;
        }
        let sp = &spans[cell.span];
        let [t0, t1] = cell.t;
        let ctrl = sub(&sp.ctrl, t0, t1);
        let h = sp.s_at(t1) - sp.s_at(t0);
        cell.bound = match cell.kind {
            Kind::Smooth(k) => grid.smooth_bound(k, &ctrl, h),
            Kind::Bracket => grid.bracket_bound(&ctrl, h),
        };
        if !cell.bound.is_finite() {
            return None;
        }
        if cell.bound <= budget || h <= 0.0 {
            done.push(cell);
            continue;
        }
        if cell.kind == Kind::Bracket {
            return None;
        }
        let m = ((cell.bound / budget).powf(0.25).ceil() as usize).clamp(2, MAX_CELLS);
        for j in (0..m).rev() {
            let a = t0 + (t1 - t0) * j as f64 / m as f64;
            let b = if j + 1 == m {
                t1
            } else {
                t0 + (t1 - t0) * (j + 1) as f64 / m as f64
            };
            work.push(Cell { t: [a, b], ..cell });
        }
    }
    // Nodal data: a cell's own polynomials at its ends.
    let n = done.len();
    let mut s = Vec::with_capacity(n + 1);
    let mut x = Vec::with_capacity(n + 1);
    let mut right = vec![Vec3::zeros(); n + 1];
    let mut left = vec![Vec3::zeros(); n + 1];
    let slope_at = |cell: &Cell, t: f64, at: f64| {
        let sp = &spans[cell.span];
        let q = pc.point(at);
        let d = slope(&sp.ctrl, t);
        let h = sp.s[1] - sp.s[0];
        let uv = [q.x, q.y];
        let (nu, nv) = match cell.kind {
            Kind::Smooth(k) => (
                piece_derivative(net, k, uv, [1, 0]),
                piece_derivative(net, k, uv, [0, 1]),
            ),
            Kind::Bracket => (
                net.derivative(q.x, q.y, 1, 0),
                net.derivative(q.x, q.y, 0, 1),
            ),
        };
        nu * (d[0] / h) + nv * (d[1] / h)
    };
    for (i, cell) in done.iter().enumerate() {
        let sp = &spans[cell.span];
        let (a, b) = (sp.s_at(cell.t[0]), sp.s_at(cell.t[1]));
        s.push(a);
        let q = pc.point(a);
        x.push(net.derivative(q.x, q.y, 0, 0));
        right[i] = slope_at(cell, cell.t[0], a);
        left[i + 1] = slope_at(cell, cell.t[1], b);
    }
    s.push(*pc.breaks().last()?);
    // A closed curve: its end is its start, bit for bit.
    x.push(x[0]);
    if s.windows(2).any(|w| w[1] <= w[0]) {
        return None;
    }
    let edge = BCurve::hermite_chain(&s, &x, &right, &left);
    let worst = done.iter().fold(0.0f64, |m, c| m.max(c.bound));
    Some((edge, worst + allowance))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The divided-difference bounds of a cell hold at a lattice of the cell (against the
    /// net's own derivatives) and are attained within a factor 3 for the first order.
    #[test]
    fn cell_partials_bound_the_net() {
        let ctrl: Vec<Vec3> = (0..6 * 5)
            .map(|k| {
                let (i, j) = ((k / 5) as f64, (k % 5) as f64);
                Vec3::new(
                    i + 0.3 * (j * 1.3).sin(),
                    j + 0.2 * (i * 0.7).cos(),
                    (i * j).sin(),
                )
            })
            .collect();
        let net = BSplineSurface::new(
            [3, 2],
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 1.0, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0],
            ctrl,
        )
        .unwrap();
        let grid = Grid::new(&net).unwrap();
        assert!(grid.c1);
        for &su in &grid.spans[0] {
            for &sv in &grid.spans[1] {
                let m = cell_partials(&net, su, sv);
                let (ku, kv) = (net.knots_u(), net.knots_v());
                let mut seen = [[0.0f64; 5]; 5];
                for i in 0..=20 {
                    for j in 0..=20 {
                        let u = ku[su] + (ku[su + 1] - ku[su]) * i as f64 / 20.0;
                        let v = kv[sv] + (kv[sv + 1] - kv[sv]) * j as f64 / 20.0;
                        for a in 0..=4 {
                            for b in 0..=4 - a {
                                let d = piece_derivative(&net, [su, sv], [u, v], [a, b]).norm();
                                seen[a][b] = seen[a][b].max(d);
                                assert!(d <= m[a][b] * (1.0 + 1e-12) + 1e-12, "{a} {b}");
                            }
                        }
                    }
                }
                assert!(m[1][0] <= 3.0 * seen[1][0] && m[0][1] <= 3.0 * seen[0][1]);
                assert_eq!(m[4][0], 0.0);
                assert_eq!(m[0][3], 0.0);
            }
        }
    }

    #[test]
    fn sub_pieces_and_coordinate_bounds() {
        let ctrl = [[0.0, 1.0], [1.0, 3.0], [3.0, 2.0], [4.0, 0.5]];
        let piece = sub(&ctrl, 0.2, 0.7);
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let a = point(&piece, t);
            let b = point(&ctrl, 0.2 + 0.5 * t);
            assert!((a[0] - b[0]).abs() < 1e-14 && (a[1] - b[1]).abs() < 1e-14);
        }
        // On s ∈ [0, 2]: the first and third derivatives of the coordinates.
        let bounds = coordinate_bounds(&ctrl, 2.0);
        for k in 0..=100 {
            let t = k as f64 / 100.0;
            let d = slope(&ctrl, t);
            assert!(d[0].abs() / 2.0 <= bounds[0][1] + 1e-14);
            assert!(d[1].abs() / 2.0 <= bounds[1][1] + 1e-14);
        }
        // The third derivative of a cubic is constant: 6 Δ³b / h³.
        assert!((bounds[0][3] - 6.0 * 2.0 / 8.0).abs() < 1e-14);
        assert_eq!(bounds[1][4], 0.0);
    }

    /// A net with a triple (`C⁰`) knot line and one with double (`C¹`) knot lines; pcurves
    /// that cross the lines, touch them (a circle tangent to `v = 0.25`), run along one and
    /// have a corner on a crossing of two: the proven bound holds against dense sampling with
    /// local maximisation, on both kinds of bracket.
    #[test]
    fn brackets_and_tangencies_keep_the_bound() {
        use crate::trim::TrimCurve;
        let make = |ku: Vec<f64>| {
            let nu = ku.len() - 4;
            let kv = vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0];
            let nv = kv.len() - 4;
            let ctrl: Vec<Vec3> = (0..nu * nv)
                .map(|k| {
                    let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                    Vec3::new(
                        i,
                        j,
                        0.3 * (3.0 * i).sin() + 0.2 * (2.0 * j).cos() + 0.1 * i * j,
                    )
                })
                .collect();
            BSplineSurface::new([3, 3], ku, kv, ctrl).unwrap()
        };
        let c0 = make(vec![
            0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 0.5, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0,
        ]);
        let c1 = make(vec![
            0.0, 0.0, 0.0, 0.0, 0.3, 0.3, 0.5, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0,
        ]);
        let curves = [
            TrimCurve::circle([0.5, 0.5], 0.25),
            TrimCurve::Polyline(vec![
                [0.2, 0.25],
                [0.5, 0.25],
                [0.5, 0.5],
                [0.7, 0.9],
                [0.1, 0.6],
            ]),
            TrimCurve::BSpline {
                degree: 3,
                points: vec![[0.1, 0.1], [0.9, 0.2], [0.8, 0.9], [0.3, 0.7], [0.2, 0.8]],
            },
        ];
        for (net, c1_expected) in [(&c0, false), (&c1, true)] {
            assert_eq!(Grid::new(net).unwrap().c1, c1_expected);
            for (k, c) in curves.iter().enumerate() {
                let (pc, _, _) = super::super::pcurve(c, 10.0, 1e-6).unwrap();
                for target in [1e-3, 1e-6] {
                    let (edge, bound) = proven_edge(net, &pc, target).unwrap();
                    assert!(bound <= target);
                    let coarse = super::super::edge_deviation(net, &pc, &edge);
                    let [a, b] = pc.domain();
                    let mut dense = 0.0f64;
                    for i in 0..=200_000 {
                        let s = a + (b - a) * i as f64 / 200_000.0;
                        let q = pc.point(s);
                        dense = dense.max((edge.point(s) - net.derivative(q.x, q.y, 0, 0)).norm());
                    }
                    let truth = coarse.max(dense);
                    assert!(truth <= bound, "curve {k}: {truth:e} > {bound:e}");
                    assert!(bound <= 20.0 * truth, "curve {k}: {bound:e} vs {truth:e}");
                }
            }
        }
    }
}
