//! Integrals of multi-patch designs: consistent orientation across shared edges, outward
//! orientation from the sign of the enclosed volume, and caps over open boundaries.

use super::quadrature::periodic_trapezoid;
use super::{analyze_surface_keeping, Integrals, NodeRows, Quadrature, SurfaceAnalysis};
use crate::design::SolvedDesign;
use crate::surface::{Partials, Surface, VDomain};
use crate::{Result, Vec3};

/// A cap closing an open boundary curve `C(v) = X(u_b, v)` of a patch.
///
/// The cap is the cone of segments from the curve's mean point `c = (1/2π)∮C dv` to the curve.
/// Its share of the volume, `(1/3)∫X·n dA` over the cone, is exactly `±(1/3) c·S` with the
/// vector area `S = (1/2)∮ C × C' dv` (the cone's apex term vanishes since `X·(X_t × X_v)` is
/// `t c·((C − c) × C')` on `X = c + t(C − c)`). For a planar curve the cone is the flat region
/// the curve bounds, so the cap is the planar cap; for a non-planar curve it is the cone (a
/// ruled surface), and [`Cap::planarity`] says how far the curve is from a plane. `S` and `c` are
/// computed with the periodic trapezoid rule on the curve itself (spectrally accurate).
#[derive(Clone, Debug, PartialEq)]
pub struct Cap {
    /// Index of the patch among the surfaces integrated (for [`integrate_design`], its index in
    /// [`SolvedDesign::surfaces`]).
    pub patch: usize,
    /// The boundary `u` of the patch that the cap closes: 0 or 1.
    pub u: f64,
    /// This cap's share of the enclosed volume (with the design's outward orientation).
    pub volume: f64,
    /// The area of the flat cap, `|S|` (exact for a planar curve).
    pub area: f64,
    /// Largest distance of the curve from the plane through `c` normal to `S`, relative to the
    /// curve's largest distance from `c` (0 for a planar curve).
    pub planarity: f64,
}

/// The integrals of every patch of a design and of the whole design.
#[derive(Clone, Debug, PartialEq)]
pub struct DesignIntegrals {
    /// Per patch (in design order), with the design's orientation: `volume` is the patch's share
    /// `(1/3)∫X·n dA` of the enclosed volume and `mean` uses the outward normal.
    pub patches: Vec<Integrals>,
    /// Sums over the patches; `volume` is the enclosed volume including the caps.
    pub total: Integrals,
    /// Every `u`-boundary of every patch is either shared with another patch or a pole, and
    /// every `v` domain is periodic: the design encloses a volume without caps.
    pub closed: bool,
    /// Patch names.
    pub names: Vec<String>,
    /// Per patch: `+1` if the design's outward normal is `X_u × X_v`, `−1` if it is the reverse.
    pub orientation: Vec<f64>,
    /// The caps over open boundaries (empty for a closed design).
    pub caps: Vec<Cap>,
    /// Per patch: the quadrature's report (integrals with the patch's own normal `X_u × X_v`).
    pub analyses: Vec<SurfaceAnalysis>,
    /// The largest relative error estimate of the patches' quadratures.
    pub error: f64,
}

/// `(C(v_j), C'(v_j))` of a boundary curve at the trapezoid nodes.
type BoundaryRow = Vec<(Vec3, Vec3)>;

/// Trapezoid nodes on boundary curves.
pub(super) const CURVE_NODES: usize = 512;
/// Boundary rows closer than this (relative to the design's size) are the same curve.
const SAME_CURVE: f64 = 1e-8;

/// The integrals of a solved design: [`integrate_surfaces`] of all its surfaces (PDE patches,
/// then `[[parametric]]` surfaces, the blend and the spline surface), in that order.
pub fn integrate_design(d: &SolvedDesign, q: &Quadrature) -> Result<DesignIntegrals> {
    let (surfaces, edges) = design_parts(d);
    integrate_surfaces(&surfaces, &edges, q)
}

/// A design's surfaces by name, and its named shared position curves at `u ∈ {0, 1}` (as
/// [`integrate_surfaces`] takes them).
type DesignParts<'a> = (
    Vec<(&'a str, &'a dyn Surface)>,
    Vec<(usize, f64, usize, f64)>,
);

fn design_parts(d: &SolvedDesign) -> DesignParts<'_> {
    let surfaces = d
        .surfaces
        .iter()
        .map(|s| (s.name.as_str(), s.surface()))
        .collect();
    let edges = d
        .edges()
        .iter()
        .map(|e| (e.report.a, e.report.ua, e.report.b, e.report.ub))
        .collect();
    (surfaces, edges)
}

/// The partials of a design's patches where its integrals evaluated them
/// ([`integrate_design_keeping`]): at every patch's quadrature nodes of the level its
/// quadrature ended at, and along its boundary rows `u = 0` and `u = 1` (periodic patches) at
/// the caps' trapezoid nodes. A derivative's adjoint weighs the same partials at the same
/// nodes, so it takes them from here instead of evaluating the patches again.
#[derive(Clone, Debug, Default)]
pub struct NodePartials {
    /// Per patch: `rows[a][b]` at `(u_a, v_b)`.
    pub(crate) grids: Vec<NodeRows>,
    /// Per patch: the rows at `u = 0` and `u = 1` (none for an interval `v` domain).
    pub(crate) ends: Vec<[Option<Vec<Partials>>; 2]>,
}

/// [`integrate_design`], with the partials its quadratures and caps evaluated
/// ([`NodePartials`]): the same integrals, the same bits.
pub fn integrate_design_keeping(
    d: &SolvedDesign,
    q: &Quadrature,
) -> Result<(DesignIntegrals, NodePartials)> {
    let (surfaces, edges) = design_parts(d);
    let (integrals, kept) = integrate_surfaces_with(&surfaces, &edges, q, true)?;
    Ok((integrals, kept.unwrap_or_default()))
}

/// The integrals of a set of patches forming a design. Orientation: two patches that share a
/// boundary curve with the same `v` parametrisation (named in `edges` as `(a, u_a, b, u_b)`, or
/// found by comparing boundary rows `X(u_b, v)`, `u_b ∈ {0, 1}`, to `10⁻⁸` of the design's
/// size) are oriented consistently: the boundary at `u = 1` runs along `+v` for the normal
/// `X_u × X_v` and the one at `u = 0` along `−v`, so sharing ends `1`–`0` keeps both normals and
/// `0`–`0` or `1`–`1` reverses one. Patches on an interval `v` domain linked to none are one
/// group (the design orients them: n-sided pieces, network and patchwork faces). Each connected
/// group of patches is then turned outward: its enclosed volume (patches plus caps) must be
/// positive. Open `u`-boundaries that are not poles
/// get a [`Cap`]; boundaries in `v` of an interval domain get none (then `volume` is only the
/// patches' `(1/3)∫X·n dA`).
pub fn integrate_surfaces(
    surfaces: &[(&str, &dyn Surface)],
    edges: &[(usize, f64, usize, f64)],
    q: &Quadrature,
) -> Result<DesignIntegrals> {
    integrate_surfaces_with(surfaces, edges, q, false).map(|(d, _)| d)
}

/// [`integrate_surfaces`], with the partials it evaluated kept (`keep`).
fn integrate_surfaces_with(
    surfaces: &[(&str, &dyn Surface)],
    edges: &[(usize, f64, usize, f64)],
    q: &Quadrature,
    keep: bool,
) -> Result<(DesignIntegrals, Option<NodePartials>)> {
    let n = surfaces.len();
    let mut analyses = Vec::with_capacity(n);
    let mut kept = keep.then(NodePartials::default);
    for (name, s) in surfaces {
        let (analysis, grid) =
            analyze_surface_keeping(*s, q, keep).map_err(|e| e.at(&format!("patch '{name}'")))?;
        analyses.push(analysis);
        if let (Some(k), Some(grid)) = (&mut kept, grid) {
            k.grids.push(grid);
        }
    }
    // Boundary curves of periodic patches: rows at u = 0 and u = 1.
    let rule = periodic_trapezoid(CURVE_NODES);
    let mut rows: Vec<[Option<BoundaryRow>; 2]> = Vec::with_capacity(n);
    for (i, (_, s)) in surfaces.iter().enumerate() {
        let mut ends: [Option<BoundaryRow>; 2] = [None, None];
        if let Some(k) = &mut kept {
            k.ends.push([None, None]);
        }
        if let VDomain::Periodic = s.v_domain() {
            // Row by row: the surfaces' row paths are far cheaper than point by point.
            let eval = s.partials_rows(&rule.nodes);
            let mut buf = vec![Partials::default(); rule.nodes.len()];
            for (e, u) in [0.0, 1.0].into_iter().enumerate() {
                eval.eval_row(u, &mut buf);
                ends[e] = Some(buf.iter().map(|p| (p.x, p.xv)).collect());
                if let Some(k) = &mut kept {
                    k.ends[i][e] = Some(buf.clone());
                }
            }
        }
        rows.push(ends);
    }
    // The design's size, for the tolerances.
    let size = rows
        .iter()
        .flatten()
        .flatten()
        .flat_map(|r| r.iter().map(|(x, _)| x.amax()))
        .fold(0.0f64, f64::max)
        .max(
            analyses
                .iter()
                .map(|a| a.integrals.area.sqrt())
                .fold(0.0, f64::max),
        )
        .max(f64::MIN_POSITIVE);
    let end = |u: f64| -> Option<usize> {
        if u == 0.0 {
            Some(0)
        } else if u == 1.0 {
            Some(1)
        } else {
            None
        }
    };
    // Links between boundaries: (a, end a, b, end b).
    let mut links: Vec<(usize, usize, usize, usize)> = Vec::new();
    for &(a, ua, b, ub) in edges {
        if let (Some(ea), Some(eb)) = (end(ua), end(ub)) {
            if a < n && b < n && a != b {
                links.push((a, ea, b, eb));
            }
        }
    }
    for a in 0..n {
        for b in a..n {
            for ea in 0..2 {
                for eb in 0..2 {
                    // Within one patch only u = 0 against u = 1 (a torus, say).
                    if a == b && (ea, eb) != (0, 1) {
                        continue;
                    }
                    let (Some(ra), Some(rb)) = (&rows[a][ea], &rows[b][eb]) else {
                        continue;
                    };
                    let gap = ra
                        .iter()
                        .zip(rb)
                        .map(|(p, q)| (p.0 - q.0).norm())
                        .fold(0.0f64, |m, d| if d.is_nan() { d } else { m.max(d) });
                    if gap <= SAME_CURVE * size && !links.contains(&(a, ea, b, eb)) {
                        links.push((a, ea, b, eb));
                    }
                }
            }
        }
    }
    // Relative orientation by propagation along links: sharing ends e_a, e_b keeps both normals
    // when e_a ≠ e_b.
    let mut sign = vec![0.0f64; n];
    let mut group = vec![usize::MAX; n];
    for start in 0..n {
        if group[start] != usize::MAX {
            continue;
        }
        sign[start] = 1.0;
        group[start] = start;
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            for &(a, ea, b, eb) in &links {
                let (j, same) = if a == i {
                    (b, ea != eb)
                } else if b == i {
                    (a, ea != eb)
                } else {
                    continue;
                };
                if group[j] == usize::MAX {
                    group[j] = start;
                    sign[j] = if same { sign[i] } else { -sign[i] };
                    stack.push(j);
                }
            }
        }
    }
    let shared = |i: usize, e: usize| {
        links
            .iter()
            .any(|&(a, ea, b, eb)| (a == i && ea == e) || (b == i && eb == e))
    };
    // Caps over open periodic boundaries (with each patch's own normal for now).
    let mut closed = true;
    let mut caps = Vec::new();
    for (i, ends) in rows.iter().enumerate() {
        for (e, row) in ends.iter().enumerate() {
            let Some(row) = row else {
                // An interval v domain: not closed, no caps.
                closed = false;
                continue;
            };
            if shared(i, e) {
                continue;
            }
            let cap = cap_of(row, &rule.weights);
            let pole = cap.1 <= SAME_CURVE * size;
            if pole {
                continue;
            }
            closed = false;
            // The cap's boundary runs opposite to the patch's: −(1/3)c·S at u = 1, +(1/3)c·S
            // at u = 0 (for the normal X_u × X_v).
            let s = if e == 1 { -1.0 } else { 1.0 };
            caps.push(Cap {
                patch: i,
                u: e as f64,
                volume: s * cap.0,
                area: cap.2,
                planarity: cap.3,
            });
        }
    }
    // Patches on an interval `v` domain share no boundary rows (n-sided pieces, the faces of a
    // network or patchwork, sheets): their parametrisations are oriented by the design itself
    // (an n-sided patch's pieces alike, a network's faces by their loops), so they are one
    // group, turned outward together. Each turned on its own, a closed patchwork's pieces
    // where `X·n < 0` (the inside of a torus's hole, seen from its centre) would be counted
    // with the wrong sign.
    let loose: Vec<usize> = (0..n)
        .filter(|&i| {
            rows[i][0].is_none() && group[i] == i && !links.iter().any(|l| l.0 == i || l.2 == i)
        })
        .collect();
    if let Some(&first) = loose.first() {
        for &i in &loose {
            group[i] = first;
        }
    }
    // Outward: each group's volume positive.
    for g in 0..n {
        if group[g] != g {
            continue;
        }
        let vol: f64 = (0..n)
            .filter(|&i| group[i] == g)
            .map(|i| sign[i] * analyses[i].integrals.volume)
            .sum::<f64>()
            + caps
                .iter()
                .filter(|c| group[c.patch] == g)
                .map(|c| sign[c.patch] * c.volume)
                .sum::<f64>();
        if vol < 0.0 {
            for i in 0..n {
                if group[i] == g {
                    sign[i] = -sign[i];
                }
            }
        }
    }
    for c in &mut caps {
        c.volume *= sign[c.patch];
    }
    let patches: Vec<Integrals> = (0..n)
        .map(|i| {
            let it = analyses[i].integrals;
            if sign[i] < 0.0 {
                it.reversed()
            } else {
                it
            }
        })
        .collect();
    let mut total = Integrals::default();
    for p in &patches {
        total.add(p);
    }
    total.volume += caps.iter().map(|c| c.volume).sum::<f64>();
    let error = analyses.iter().map(|a| a.error).fold(0.0, f64::max);
    let integrals = DesignIntegrals {
        patches,
        total,
        closed,
        names: surfaces.iter().map(|(s, _)| s.to_string()).collect(),
        orientation: sign,
        caps,
        analyses,
        error,
    };
    Ok((integrals, kept))
}

/// `((1/3) c·S, radius, |S|, planarity)` of a closed curve given by `(C, C')` at the trapezoid
/// nodes with weights `w`: `c` the mean point, `S = (1/2)∮ C × C' dv`, radius the largest
/// `|C − c|`.
fn cap_of(row: &[(Vec3, Vec3)], w: &[f64]) -> (f64, f64, f64, f64) {
    let period: f64 = w.iter().sum();
    let c = row.iter().zip(w).map(|((x, _), w)| x * *w).sum::<Vec3>() / period;
    // Relative to c, so that S is computed without cancellation far from the origin.
    let s = row
        .iter()
        .zip(w)
        .map(|((x, xv), w)| (x - c).cross(xv) * (0.5 * w))
        .sum::<Vec3>();
    let radius = row.iter().map(|(x, _)| (x - c).norm()).fold(0.0, f64::max);
    let area = s.norm();
    let planarity = if area > 0.0 && radius > 0.0 {
        let nrm = s / area;
        row.iter()
            .map(|(x, _)| (x - c).dot(&nrm).abs())
            .fold(0.0, f64::max)
            / radius
    } else {
        0.0
    };
    (c.dot(&s) / 3.0, radius, area, planarity)
}

/// The derivative of a cap's `(1/3) c·S` (see [`cap_of`]) along a tangent: `rows` holds
/// `(C, C', Ċ, Ċ')` at the trapezoid nodes with weights `w`; the result is
/// `(1/3)(ċ·S + c·Ṡ)`, `ċ` the mean of `Ċ`, `Ṡ = (1/2)∮ (Ċ − ċ) × C' + (C − c) × Ċ' dv`.
pub(super) fn cap_derivative(rows: &[(Vec3, Vec3, Vec3, Vec3)], w: &[f64]) -> f64 {
    let period: f64 = w.iter().sum();
    let c = rows.iter().zip(w).map(|(r, w)| r.0 * *w).sum::<Vec3>() / period;
    let dc = rows.iter().zip(w).map(|(r, w)| r.2 * *w).sum::<Vec3>() / period;
    let (mut s, mut ds) = (Vec3::zeros(), Vec3::zeros());
    for ((x, xv, dx, dxv), w) in rows.iter().zip(w) {
        s += (x - c).cross(xv) * (0.5 * w);
        ds += ((dx - dc).cross(xv) + (x - c).cross(dxv)) * (0.5 * w);
    }
    (dc.dot(&s) + c.dot(&ds)) / 3.0
}
