//! N-sided surfaces certified cell by cell (see the module documentation, "The bound for
//! n-sided patches"): the bicubic Hermite interpolant's deviation on each cell bounded from a
//! Taylor model of the surface, boxes of the cell split where the model is too wide, the corner
//! box bounded by its reach, and rows and columns of cells cut until every cell meets the
//! tolerance.

use super::formula::{net_size_of, subdivide};
use super::sampled::approximate_sampled;
use super::{Approximation, Certificate, MAX_CELLS, ROUNDING};
use crate::cad::hermite::{hermite_interpolant, uniform_nodes};
use crate::nsided::{model_exponents, CellModel, NSidedSurface, MODEL_LEN};
use crate::surface::Surface;
use crate::{Error, Result, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

/// The most halvings of a cell without a bound (its side parameters reach a break of a side's
/// curve) before the surface is sampled instead.
const MAX_DEPTH: u32 = 10;

/// How often a box of a cell is split in four before the cell itself is cut: deep enough for
/// a corner box's reach (`~ tolerance / |∇X|`) from a cell of a coarse grid.
const SPLITS: u32 = 14;

/// The most boxes one cell's check may use before the cell is cut instead.
const MAX_BOXES: usize = 4096;

/// The cubic Bernstein polynomials' power coefficients: `b_i(t) = Σ_k BEZIER[i][k] t^k`.
const BEZIER: [[f64; 4]; 4] = [
    [1.0, -3.0, 3.0, -1.0],
    [0.0, 3.0, -6.0, 3.0],
    [0.0, 0.0, 3.0, -3.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// The bicubic Hermite interpolant on one cell, as power coefficients in the cell's own
/// `t ∈ [0, 1]²`: `H = Σ a[k][l] t_u^k t_v^l`.
struct CellCubic {
    u: [f64; 2],
    v: [f64; 2],
    a: [[Vec3; 4]; 4],
}

impl CellCubic {
    fn new(s: &NSidedSurface, u: [f64; 2], v: [f64; 2]) -> CellCubic {
        let (hu, hv) = (u[1] - u[0], v[1] - v[0]);
        // The Bézier points from the corners' X, X_u, X_v, X_uv.
        let mut b = [[Vec3::zeros(); 4]; 4];
        for (i, &uu) in u.iter().enumerate() {
            for (j, &vv) in v.iter().enumerate() {
                let p = s.partials(uu, vv);
                let (su, sv) = ([1.0, -1.0][i] * hu / 3.0, [1.0, -1.0][j] * hv / 3.0);
                let (bi, bj) = (3 * i, 3 * j);
                let (ni, nj) = ([1, 2][i], [1, 2][j]);
                b[bi][bj] = p.x;
                b[ni][bj] = p.x + p.xu * su;
                b[bi][nj] = p.x + p.xv * sv;
                b[ni][nj] = p.x + p.xu * su + p.xv * sv + p.xuv * (su * sv);
            }
        }
        let mut a = [[Vec3::zeros(); 4]; 4];
        for (i, bi) in b.iter().enumerate() {
            for (j, bij) in bi.iter().enumerate() {
                for (k, ak) in a.iter_mut().enumerate() {
                    for (l, akl) in ak.iter_mut().enumerate() {
                        *akl += bij * (BEZIER[i][k] * BEZIER[j][l]);
                    }
                }
            }
        }
        CellCubic { u, v, a }
    }

    /// The power coefficients in the box's `σ ∈ [−1, 1]²` (`u = c_u + h_u σ_u`, likewise `v`).
    fn on_box(&self, c: [f64; 2], h: [f64; 2]) -> [[Vec3; 5]; 5] {
        let (wu, wv) = (self.u[1] - self.u[0], self.v[1] - self.v[0]);
        // t = (c − u0)/w + (h/w) σ.
        let su = shift_scale((c[0] - self.u[0]) / wu, h[0] / wu);
        let sv = shift_scale((c[1] - self.v[0]) / wv, h[1] / wv);
        let mut out = [[Vec3::zeros(); 5]; 5];
        for (k, ak) in self.a.iter().enumerate() {
            for (l, akl) in ak.iter().enumerate() {
                for m in 0..=k {
                    for n in 0..=l {
                        out[m][n] += akl * (su[k][m] * sv[l][n]);
                    }
                }
            }
        }
        out
    }
}

/// `(c + h σ)^k = Σ_m out[k][m] σ^m`, `k ≤ 3`.
fn shift_scale(c: f64, h: f64) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    out[0][0] = 1.0;
    for k in 1..4 {
        for m in 0..=k {
            let prev_same = out[k - 1][m] * c;
            let prev_lower = if m > 0 { out[k - 1][m - 1] * h } else { 0.0 };
            out[k][m] = prev_same + prev_lower;
        }
    }
    out
}

/// The matrix taking power coefficients in `σ ∈ [−1, 1]` (degree ≤ 4) to Bernstein
/// coefficients of degree 4 on the same interval (`σ = 2x − 1`, then `x^k` in the Bernstein
/// basis: `x^k = Σ_{i≥k} C(i, k)/C(4, k) b_i`).
fn to_bernstein() -> [[f64; 5]; 5] {
    let binom = |n: usize, k: usize| -> f64 {
        (0..k).fold(1.0, |acc, j| acc * (n - j) as f64 / (j + 1) as f64)
    };
    // σ^k = (2x − 1)^k = Σ_j C(k, j) 2^j (−1)^{k−j} x^j.
    let mut out = [[0.0; 5]; 5];
    for k in 0..5 {
        for j in 0..=k {
            let xj = binom(k, j) * 2f64.powi(j as i32) * if (k - j) % 2 == 0 { 1.0 } else { -1.0 };
            for (i, row) in out.iter_mut().enumerate().skip(j) {
                row[k] += xj * binom(i, j) / binom(4, j);
            }
        }
    }
    out
}

/// `sup|p|` over `[−1, 1]²` of each coordinate of `p = Σ c[k][l] σ_u^k σ_v^l` (degree ≤ 4 in
/// each variable), by the largest Bernstein coefficient (the convex hull property), and the
/// Bernstein points themselves.
fn bernstein(c: &[[Vec3; 5]; 5]) -> [[Vec3; 5]; 5] {
    let m = to_bernstein();
    let mut half = [[Vec3::zeros(); 5]; 5];
    for (i, mi) in m.iter().enumerate() {
        for (k, &mik) in mi.iter().enumerate() {
            if mik != 0.0 {
                for l in 0..5 {
                    half[i][l] += c[k][l] * mik;
                }
            }
        }
    }
    let mut out = [[Vec3::zeros(); 5]; 5];
    for i in 0..5 {
        for (j, mj) in m.iter().enumerate() {
            for (l, &mjl) in mj.iter().enumerate() {
                if mjl != 0.0 {
                    out[i][j] += half[i][l] * mjl;
                }
            }
        }
    }
    out
}

/// The bound of `|X − H|` on a box from the surface's model there.
fn model_bound(m: &CellModel, h: &[[Vec3; 5]; 5]) -> f64 {
    let mut diff = *h;
    for row in diff.iter_mut() {
        for x in row.iter_mut() {
            *x = -*x;
        }
    }
    for (k, c) in m.coeffs.iter().enumerate().take(MODEL_LEN) {
        let (a, b) = model_exponents(k);
        diff[a][b] += c;
    }
    let bern = bernstein(&diff);
    let mut size = [0.0f64; 3];
    for x in bern.iter().flatten() {
        for c in 0..3 {
            size[c] = size[c].max(x[c].abs());
        }
    }
    (0..3)
        .map(|c| (size[c] + m.radius[c]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// What one cell's check found.
#[derive(Clone, Copy, Debug)]
enum Cell {
    /// The bound holds: its value and the number of boxes it took.
    Holds(f64, usize),
    /// The bound fails: cut the cell's row (`[true, _]`) and column (`[_, true]`).
    Cut([bool; 2]),
    /// No model anywhere in the box (a break of a side's curve inside it).
    Unbounded,
}

/// The bound of `|X − H|` over the box `[u0, u1] × [v0, v1]` of the cell, splitting the box
/// into quarters while it exceeds `budget` (up to `depth` times, and while `left` boxes
/// remain: then the bound is infinite); `None` where a box has neither a model nor a corner
/// reach. Returns the bound and the number of boxes.
fn box_bound(
    s: &NSidedSurface,
    cubic: &CellCubic,
    u: [f64; 2],
    v: [f64; 2],
    budget: f64,
    depth: u32,
    left: &mut usize,
) -> Option<(f64, usize)> {
    if *left == 0 {
        return Some((f64::INFINITY, 0));
    }
    *left -= 1;
    let c = [0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1])];
    let h = [0.5 * (u[1] - u[0]), 0.5 * (v[1] - v[0])];
    let hpow = cubic.on_box(c, h);
    let own = if let Some((corner, reach)) = s.corner_reach(u, v) {
        // |X − H| ≤ |X − X(c)| + |H − X(c)|, and H lies in the hull of its Bernstein points.
        let mut shifted = hpow;
        shifted[0][0] -= corner;
        let hull = bernstein(&shifted)
            .iter()
            .flatten()
            .map(|x| x.norm())
            .fold(0.0, f64::max);
        Some(reach + hull)
    } else {
        s.taylor_model(u, v).map(|m| model_bound(&m, &hpow))
    };
    if let Some(b) = own {
        if b <= budget || depth == 0 {
            return Some((b, 1));
        }
    } else if depth == 0 {
        return None;
    }
    let mut worst = 0.0f64;
    let mut boxes = 1;
    for a in [[u[0], c[0]], [c[0], u[1]]] {
        for b in [[v[0], c[1]], [c[1], v[1]]] {
            let (w, n) = box_bound(s, cubic, a, b, budget, depth - 1, left)?;
            boxes += n;
            worst = worst.max(w);
            if worst > budget {
                // The cell fails whatever its other quarters give.
                return Some((own.map_or(worst, |o| o.min(worst)), boxes));
            }
        }
    }
    Some((own.map_or(worst, |o| o.min(worst)), boxes))
}

/// The check of one grid cell: a sampled look first (a cell whose sampled deviation already
/// exceeds the budget is cut without models), then the boxes' bounds.
fn check_cell(s: &NSidedSurface, u: [f64; 2], v: [f64; 2], budget: f64) -> Cell {
    let cubic = CellCubic::new(s, u, v);
    // Which direction to cut: the model's quartic terms on the whole cell (the Hermite
    // interpolant's error is about |c₄₀| in u and |c₀₄| in v); both where there is none.
    let directions = || -> [bool; 2] {
        match s.taylor_model(u, v) {
            Some(m) => {
                let (cu, cv) = (m.coeffs[10].norm(), m.coeffs[14].norm());
                [cu * 3.0 >= cv, cv * 3.0 >= cu]
            }
            None => [true, true],
        }
    };
    let sample = 5;
    let mut seen = 0.0f64;
    let hpow = cubic.on_box(
        [0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1])],
        [0.5 * (u[1] - u[0]), 0.5 * (v[1] - v[0])],
    );
    for i in 0..sample {
        for j in 0..sample {
            let (x, y) = (
                -1.0 + 2.0 * (i as f64 + 0.5) / sample as f64,
                -1.0 + 2.0 * (j as f64 + 0.5) / sample as f64,
            );
            let (uu, vv) = (
                0.5 * (u[0] + u[1]) + 0.5 * (u[1] - u[0]) * x,
                0.5 * (v[0] + v[1]) + 0.5 * (v[1] - v[0]) * y,
            );
            let mut hx = Vec3::zeros();
            for (k, row) in hpow.iter().enumerate() {
                for (l, c) in row.iter().enumerate() {
                    hx += c * (x.powi(k as i32) * y.powi(l as i32));
                }
            }
            seen = seen.max((s.partials(uu, vv).x - hx).norm());
        }
    }
    // Near the budget the boxes' bounds would need many splits to prove it: such a cell is cut.
    if seen > 0.9 * budget {
        return Cell::Cut(directions());
    }
    match box_bound(s, &cubic, u, v, budget, SPLITS, &mut { MAX_BOXES }) {
        Some((b, n)) if b <= budget => Cell::Holds(b, n),
        Some(_) => Cell::Cut(directions()),
        None => Cell::Unbounded,
    }
}

/// An n-sided surface interpolated on a tensor grid whose rows and columns of cells are cut
/// until every cell's bound meets the tolerance ([`Certificate::Models`]); where a cell has no
/// bound after [`MAX_DEPTH`] halvings, or the grid would exceed [`MAX_CELLS`], the surface is
/// sampled and the reason kept in [`Approximation::note`].
pub fn approximate_nsided(
    s: &NSidedSurface,
    tolerance: f64,
    min_v: usize,
) -> Result<Approximation> {
    let sampled = |why: String| -> Result<Approximation> {
        let mut a = approximate_sampled(s, tolerance, min_v)?;
        a.note = Some(why);
        Ok(a)
    };
    if let Some(why) = s.bounds_unavailable() {
        return sampled(format!("no derivative bounds: {why}"));
    }
    // The sampled export's first grid: the surface is smooth inside a piece (its breaks, graded
    // towards the corners, serve the quadratures), and the corner's box is split, not the grid.
    let (mut us, mut vs) = (uniform_nodes(0.0, 1.0, 8), uniform_nodes(0.0, 1.0, 8));
    let min_h = 1.0 / 8.0 / f64::from(1u32 << MAX_DEPTH);
    // A cell's check depends only on its corners: cells of rows and columns not cut keep it.
    let mut known: HashMap<[u64; 4], Cell> = HashMap::new();
    let key = |u: [f64; 2], v: [f64; 2]| [u[0], u[1], v[0], v[1]].map(f64::to_bits);
    loop {
        let (mu, mv) = (us.len() - 1, vs.len() - 1);
        if mu * mv > MAX_CELLS {
            return sampled(format!(
                "the n-sided bounds would need more than {MAX_CELLS} grid cells"
            ));
        }
        let size = net_size_of(s, &us, &vs);
        let budget = tolerance - ROUNDING * size;
        if budget <= 0.0 {
            return Err(Error::invalid(format!(
                "the tolerance {tolerance:e} is below the rounding allowance of the surface"
            ))
            .at("tolerance"));
        }
        let fresh: Vec<(usize, Cell)> = (0..mu * mv)
            .into_par_iter()
            .filter_map(|k| {
                let (i, j) = (k / mv, k % mv);
                let (u, v) = ([us[i], us[i + 1]], [vs[j], vs[j + 1]]);
                (!known.contains_key(&key(u, v))).then(|| (k, check_cell(s, u, v, budget)))
            })
            .collect();
        for (k, c) in fresh {
            let (i, j) = (k / mv, k % mv);
            known.insert(key([us[i], us[i + 1]], [vs[j], vs[j + 1]]), c);
        }
        let (mut cut_u, mut cut_v) = (vec![1usize; mu], vec![1usize; mv]);
        let (mut worst, mut boxes) = (0.0f64, 0usize);
        for k in 0..mu * mv {
            let (i, j) = (k / mv, k % mv);
            let (u, v) = ([us[i], us[i + 1]], [vs[j], vs[j + 1]]);
            match known[&key(u, v)] {
                Cell::Holds(b, n) => {
                    worst = worst.max(b);
                    boxes += n;
                }
                Cell::Cut([a, b]) => {
                    if a {
                        cut_u[i] = 2;
                    }
                    if b {
                        cut_v[j] = 2;
                    }
                }
                Cell::Unbounded => {
                    if u[1] - u[0] <= min_h && v[1] - v[0] <= min_h {
                        return sampled(format!(
                            "no derivative bounds on the cell [{:.6}, {:.6}] × [{:.6}, {:.6}] \
                             (a side's curve has a break there, or no bounds)",
                            u[0], u[1], v[0], v[1]
                        ));
                    }
                    cut_u[i] = 2;
                    cut_v[j] = 2;
                }
            }
        }
        if cut_u.iter().chain(&cut_v).all(|&c| c == 1) {
            let net = hermite_interpolant(s, &us, &vs, [false, false])?;
            return Ok(Approximation {
                net,
                closed: [false, false],
                deviation: worst + ROUNDING * size,
                certificate: Certificate::Models {
                    cells: mu * mv,
                    boxes,
                },
                note: None,
            });
        }
        us = subdivide(&us, &cut_u);
        vs = subdivide(&vs, &cut_v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Bernstein conversion reproduces a polynomial's values (the end coefficients are its
    /// values at the square's corners) and bounds it.
    #[test]
    fn bernstein_coefficients_bound_polynomials() {
        let mut c = [[Vec3::zeros(); 5]; 5];
        c[0][0] = Vec3::new(0.3, 0.0, 0.0);
        c[1][0] = Vec3::new(-0.2, 0.0, 0.0);
        c[2][1] = Vec3::new(0.7, 0.0, 0.0);
        c[4][0] = Vec3::new(1.1, 0.0, 0.0);
        c[0][4] = Vec3::new(-0.4, 0.0, 0.0);
        let p =
            |x: f64, y: f64| 0.3 - 0.2 * x + 0.7 * x * x * y + 1.1 * x.powi(4) - 0.4 * y.powi(4);
        let b = bernstein(&c);
        for (i, x) in [(0, -1.0), (4, 1.0)] {
            for (j, y) in [(0, -1.0), (4, 1.0)] {
                assert!((b[i][j][0] - p(x, y)).abs() < 1e-14, "{i} {j}");
            }
        }
        let top = b.iter().flatten().map(|x| x[0].abs()).fold(0.0, f64::max);
        let mut seen = 0.0f64;
        for i in 0..=40 {
            for j in 0..=40 {
                seen = seen.max(p(-1.0 + i as f64 / 20.0, -1.0 + j as f64 / 20.0).abs());
            }
        }
        assert!(seen <= top + 1e-15 && top <= 3.0 * seen, "{seen} {top}");
    }
}

#[cfg(test)]
mod design_tests {
    use super::*;
    use crate::cad::tests::{solve, true_max_deviation};
    use crate::cad::{approximate_design, design_size};
    use crate::design::SurfaceKind;

    /// Every n-sided piece of the pentagon, the vertex blend (tangent-plane ribbons from the
    /// fillets) and the network dome is certified, and its bound holds: at or above the true
    /// largest deviation found by local maximisation from a lattice of every knot cell, and
    /// within the tolerance. A grid that had to be cut beyond the sampled one's would show as
    /// many more cells than the sampled grid's, which the test reports.
    #[test]
    fn nsided_exports_are_certified_and_the_bound_holds() {
        for (name, text) in [
            (
                "pentagon",
                include_str!("../../../../../examples/nsided_pentagon.toml"),
            ),
            (
                "vertex blend",
                include_str!("../../../../../examples/nsided_vertex_blend.toml"),
            ),
            (
                "dome",
                include_str!("../../../../../examples/network_dome.toml"),
            ),
            (
                "G2 octant",
                include_str!("../../../../../examples/nsided_g2_octant.toml"),
            ),
            (
                "STEP corner fill",
                include_str!("../../../../../examples/step_corner_fill.toml"),
            ),
            (
                "STEP NURBS corner fill",
                include_str!("../../../../../examples/step_nurbs_corner_fill.toml"),
            ),
        ] {
            let design = solve(text);
            let tolerance = 1e-4 * design_size(&design);
            let model = approximate_design(&design, tolerance).unwrap();
            let mut pieces = 0;
            for (s, cad) in design.surfaces.iter().zip(&model.surfaces) {
                let SurfaceKind::NSided(surface) = &s.kind else {
                    continue;
                };
                pieces += 1;
                let a = &cad.approx;
                assert!(
                    matches!(a.certificate, Certificate::Models { .. }),
                    "{name} {}: {:?} {:?}",
                    s.name,
                    a.certificate,
                    a.note
                );
                assert!(a.deviation <= tolerance, "{name} {}", s.name);
                let truth = true_max_deviation(&a.net, &|u, v| surface.point(u, v));
                eprintln!(
                    "{name} {}: {:?} bound {:.3e}, true {truth:.3e}, {:?} control points",
                    s.name,
                    a.certificate,
                    a.deviation,
                    a.net.counts()
                );
                assert!(
                    truth <= a.deviation,
                    "{name} {}: {truth:e} > {:e}",
                    s.name,
                    a.deviation
                );
            }
            assert!(pieces > 0, "{name} has n-sided surfaces");
        }
    }

    /// The pentagon with sides whose B-splines have inner knots: a simple knot (the curve `C²`
    /// there) on side 0, a double one (`C¹`) on side 2. The surface is only as smooth across
    /// the knots' images in the domain; the models carry remainders of order 3 and 2 there,
    /// and every piece is still certified, with a bound above the true deviation.
    #[test]
    fn sides_with_breaks_are_certified() {
        let text = include_str!("../../../../../examples/nsided_pentagon.toml")
            .replace(
                "[-0.387553, 0.866754, 0.15], [-0.704572, 0.636427, 0.15]",
                "[-0.387553, 0.866754, 0.15], [-0.55, 0.75, 0.2], [-0.704572, 0.636427, 0.15]",
            )
            .replace(
                "[-0.195928, -0.929017, 0.15], [0.195928, -0.929017, 0.15], ",
                "[-0.195928, -0.929017, 0.15], [-0.1, -0.97, 0.25], [0.1, -0.97, 0.25], \
                 [0.195928, -0.929017, 0.15], ",
            )
            .replace(
                "[curves.side2]\n",
                "[curves.side2]\nknots = [0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1]\n",
            );
        let design = solve(&text);
        let curve = |name: &str| {
            let c = design.curves.iter().find(|c| c.name == name).unwrap();
            c.curve.clone()
        };
        assert_eq!(
            (curve("side0").breaks(), curve("side0").continuity()),
            (vec![0.5], 2)
        );
        assert_eq!(
            (curve("side2").breaks(), curve("side2").continuity()),
            (vec![0.5], 1)
        );
        let tolerance = 1e-4 * design_size(&design);
        let model = approximate_design(&design, tolerance).unwrap();
        for (s, cad) in design.surfaces.iter().zip(&model.surfaces) {
            let SurfaceKind::NSided(surface) = &s.kind else {
                continue;
            };
            let a = &cad.approx;
            assert!(
                matches!(a.certificate, Certificate::Models { .. }),
                "{}: {:?} {:?}",
                s.name,
                a.certificate,
                a.note
            );
            let truth = true_max_deviation(&a.net, &|u, v| surface.point(u, v));
            eprintln!(
                "{}: {:?} bound {:.3e}, true {truth:.3e}, {:?} control points",
                s.name,
                a.certificate,
                a.deviation,
                a.net.counts()
            );
            assert!(
                truth <= a.deviation && a.deviation <= tolerance,
                "{}",
                s.name
            );
        }
    }

    /// A side on a polyline (a B-spline of degree 1 with an inner knot: only `C⁰` there) has
    /// no models of any use: the export says so and samples the pieces that reach it (at a
    /// coarse tolerance: the surface's crease across the domain costs the sampled grid 1026²
    /// control points at 10⁻⁴).
    #[test]
    fn c0_sides_are_sampled_with_the_reason() {
        let text = include_str!("../../../../../examples/nsided_pentagon.toml").replace(
            "degree = 3\nperiodic = false\ncontrol = [[6.123233995736766e-17, 1.0, 0.0], \
             [-0.387553, 0.866754, 0.15], [-0.704572, 0.636427, 0.15], ",
            "degree = 1\nperiodic = false\ncontrol = [[6.123233995736766e-17, 1.0, 0.0], \
             [-0.55, 0.75, 0.2], ",
        );
        let design = solve(&text);
        let side0 = design.curves.iter().find(|c| c.name == "side0").unwrap();
        assert_eq!(side0.curve.continuity(), 0);
        let tolerance = 1e-2 * design_size(&design);
        let model = approximate_design(&design, tolerance).unwrap();
        let notes: Vec<_> = model
            .surfaces
            .iter()
            .filter(|c| c.approx.certificate == Certificate::Sampled)
            .filter_map(|c| c.approx.note.clone())
            .collect();
        assert!(!notes.is_empty());
        assert!(
            notes
                .iter()
                .all(|n| n.contains("side 0's curve is only C0 at its break t = 0.5")),
            "{notes:?}"
        );
    }
}
