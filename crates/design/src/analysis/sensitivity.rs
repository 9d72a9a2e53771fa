//! Directional derivatives of a design's integrals: the exact derivative of the *discrete*
//! integrals (the same quadrature nodes and weights, the same orientation and caps) along a
//! tangent surface `Ẋ`, by the chain rule through every integrand.
//!
//! At one node, with `N = X_u × X_v`, `J = |N|`, `n = N/J` and dots for the derivative along the
//! tangent (`Ẋ`, `Ẋ_u`, … are the tangent surface's partials at the node):
//!
//! ```text
//! Ṅ = Ẋ_u × X_v + X_u × Ẋ_v      J̇ = n·Ṅ      ṅ = (Ṅ − n (n·Ṅ)) / J
//! Ė = 2 X_u·Ẋ_u   Ḟ = Ẋ_u·X_v + X_u·Ẋ_v   Ġ = 2 X_v·Ẋ_v
//! L̇ = Ẋ_uu·n + X_uu·ṅ   (M, N alike)       W = J², Ẇ = 2 J J̇
//! K̇ = (L̇N + LṄ − 2MṀ)/W − K Ẇ/W
//! Ḣ = (ĖN + EṄ − 2ḞM − 2FṀ + ĠL + GL̇)/(2W) − H Ẇ/W
//! (J)˙ = J̇   (HJ)˙ = ḢJ + HJ̇   (H²J)˙ = 2HḢJ + H²J̇   (KJ)˙ = K̇J + KJ̇   ((1/3)X·N)˙ = (1/3)(Ẋ·N + X·Ṅ)
//! ```
//!
//! and a cap's `(1/3) c·S` (see [`super::Cap`]) differentiates to `(1/3)(ċ·S + c·Ṡ)` with
//! `ċ` the mean of `Ċ` and `Ṡ = (1/2)∮ (Ċ − ċ) × C' + (C − c) × Ċ' dv`. Degenerate nodes (poles)
//! add to no curvature integral, as in [`super::integrate_design`]; the orientation of each patch
//! and which boundaries have caps are those of the base design (locally constant).

use super::design::{cap_derivative, CURVE_NODES};
use super::quadrature::{periodic_trapezoid, Rule};
use super::{DesignIntegrals, Integrals, NodePartials, Quadrature};
use crate::design::{SolvedDesign, SurfaceKind};
use crate::elliptic::{AdjointTangent, Partial, PdePatch, NODE_WEIGHTS};
use crate::surface::{normal_degenerates, Partials, Surface};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;

/// Node weights per integrand: 18 ([`NODE_WEIGHTS`]) per integral, five integrals.
const NODE: usize = 5 * NODE_WEIGHTS;

/// The derivative of the integrals `at` of `base` (from [`super::integrate_design`] with the
/// quadrature `q`) along the tangent surface `Ẋ = Σ c_k X_k` given as `(c_k, design_k)` pairs:
/// designs with the same patches as `base` (e.g. `[(1/h, X(p + h)), (−1/h, X(p))]`). The
/// partials of every design are evaluated at the base's quadrature nodes. `area`, `volume`
/// (caps included), `mean`, `mean_sq` and `gauss` of the result are the derivatives of those of
/// `at.total`.
pub fn integrals_derivative(
    base: &SolvedDesign,
    at: &DesignIntegrals,
    tangent: &[(f64, &SolvedDesign)],
    q: &Quadrature,
) -> Result<Integrals> {
    let n = base.surfaces.len();
    if at.patches.len() != n {
        return Err(Error::invalid(format!(
            "the integrals are of {} patches, the design has {n}",
            at.patches.len()
        )));
    }
    for (_, d) in tangent {
        if d.surfaces.len() != n {
            return Err(Error::invalid(format!(
                "a tangent design has {} patches, the base design {n}",
                d.surfaces.len()
            )));
        }
    }
    let mut total = Integrals::default();
    for i in 0..n {
        let s = base.surfaces[i].surface();
        let others: Vec<(f64, &dyn Surface)> = tangent
            .iter()
            .map(|(c, d)| (*c, d.surfaces[i].surface()))
            .collect();
        let (ru, rv) = rules_of(s, q, at.analyses[i].u_nodes, at.analyses[i].v_nodes)?;
        let d = patch_derivative(s, &others, &ru, &rv);
        add_patch_derivative(&mut total, &d, at.orientation[i], &base.surfaces[i].name)?;
    }
    let rule = periodic_trapezoid(CURVE_NODES);
    for cap in &at.caps {
        let i = cap.patch;
        let row = |s: &dyn Surface| cap_row(s, &rule.nodes, cap.u);
        let b = row(base.surfaces[i].surface());
        let mut t = vec![Partials::default(); b.len()];
        for (c, d) in tangent {
            for (tp, p) in t.iter_mut().zip(row(d.surfaces[i].surface())) {
                tp.x += *c * p.x;
                tp.xv += *c * p.xv;
            }
        }
        let rows: Vec<_> = b
            .iter()
            .zip(&t)
            .map(|(p, d)| (p.x, p.xv, d.x, d.xv))
            .collect();
        let s = if cap.u == 1.0 { -1.0 } else { 1.0 };
        total.volume += s * at.orientation[i] * cap_derivative(&rows, &rule.weights);
    }
    Ok(total)
}

/// The derivative of one PDE patch of a design along one direction: `patch + stretch · u X_u`,
/// with `X` the design's patch at the point. `patch` is a tangent solve with the point's
/// operator and condition places (such as [`crate::design::tangent_patches`]' patches); the
/// stretch is non-zero only along the smoothing parameter `a`
/// ([`crate::elliptic::PdePatch::smoothing_tangent_curves`]).
#[derive(Clone, Debug)]
pub struct PatchTangent {
    /// The tangent solve.
    pub patch: std::sync::Arc<PdePatch>,
    /// The factor of `u X_u`.
    pub stretch: f64,
}

/// The derivatives of the integrals `at` of `base` (as in [`integrals_derivative`]) along `K`
/// directions at once: `tangents[k][i]` is the derivative of patch `i` along direction `k`.
/// Every surface of `base` must be a PDE patch of the analytic solver. The chain rule at a node
/// is linear in the tangent's partials, and those are linear in the tangent's mode
/// coefficients, so the weights that map a direction's coefficients to each integral's
/// derivative are gathered in one pass over the quadrature nodes whatever `K`
/// ([`crate::elliptic::PdePatch::quadrature_adjoint`], with the node weights of
/// [`node_gradient`]) and applied to each direction's coefficients: the same derivatives as
/// [`integrals_derivative`]'s node-by-node chain rule up to the rounding of the sums.
pub fn integrals_derivatives(
    base: &SolvedDesign,
    at: &DesignIntegrals,
    tangents: &[Vec<PatchTangent>],
    q: &Quadrature,
) -> Result<Vec<Integrals>> {
    integrals_derivatives_at(base, at, None, tangents, q)
}

/// [`integrals_derivatives`] with the point's partials at the quadrature nodes and on the caps'
/// boundary rows taken from `kept` (those its integrals `at` evaluated,
/// [`super::integrate_design_keeping`]) instead of evaluated again: the same partials at the
/// same nodes, so the same derivatives to the bit. A patch whose kept partials do not match
/// the nodes (or `kept` = `None`) is evaluated.
pub fn integrals_derivatives_at(
    base: &SolvedDesign,
    at: &DesignIntegrals,
    kept: Option<&NodePartials>,
    tangents: &[Vec<PatchTangent>],
    q: &Quadrature,
) -> Result<Vec<Integrals>> {
    let n = base.surfaces.len();
    if at.patches.len() != n {
        return Err(Error::invalid(format!(
            "the integrals are of {} patches, the design has {n}",
            at.patches.len()
        )));
    }
    if let Some(t) = tangents.iter().find(|t| t.len() != n) {
        return Err(Error::invalid(format!(
            "a tangent has {} patches, the base design {n}",
            t.len()
        )));
    }
    let kk = tangents.len();
    let mut totals = vec![Integrals::default(); kk];
    for i in 0..n {
        let name = &base.surfaces[i].name;
        let SurfaceKind::Pde(pde) = &base.surfaces[i].kind else {
            return Err(Error::invalid(
                "the batched derivatives need PDE patches of the analytic solver",
            )
            .at(&format!("patch '{name}'")));
        };
        let s = base.surfaces[i].surface();
        let (ru, rv) = rules_of(s, q, at.analyses[i].u_nodes, at.analyses[i].v_nodes)?;
        let nv = rv.nodes.len();
        let grid = kept
            .and_then(|k| k.grids.get(i))
            .filter(|g| g.len() == ru.nodes.len() && g.iter().all(|r| r.len() == nv));
        let rows = grid.is_none().then(|| s.partials_rows(&rv.nodes));
        let weights = |a: usize, out: &mut [f64]| {
            let mut own = Vec::new();
            let row: &[Partials] = match (grid, &rows) {
                (Some(g), _) => &g[a],
                (None, Some(rows)) => {
                    own.resize(nv, Partials::default());
                    rows.eval_row(ru.nodes[a], &mut own);
                    &own
                }
                (None, None) => unreachable!("the rows are made when no grid is kept"),
            };
            let wu = ru.weights[a];
            for ((p, &wv), out) in row.iter().zip(&rv.weights).zip(out.chunks_exact_mut(NODE)) {
                node_gradient(p, wu * wv, out);
            }
        };
        let list = adjoint_tangents(tangents, i);
        let d = pde
            .quadrature_adjoint(&ru.nodes, &rv.nodes, 5, &weights, &list)
            .map_err(|e| e.at(&format!("patch '{name}'")))?;
        for (total, d) in totals.iter_mut().zip(&d) {
            let d: [f64; 5] = std::array::from_fn(|o| d[o]);
            add_patch_derivative(total, &d, at.orientation[i], name)?;
        }
    }
    if at.caps.is_empty() {
        return Ok(totals);
    }
    // The caps: a cap's derivative is linear in the tangent's `Ẋ`, `Ẋ_v` on the boundary row
    // ([`cap_weights`]), so it is one more adjoint, over the rows of the patch's caps with the
    // weights of `X` and `X_v` only.
    let rule = periodic_trapezoid(CURVE_NODES);
    for i in 0..n {
        let caps: Vec<&super::Cap> = at.caps.iter().filter(|c| c.patch == i).collect();
        if caps.is_empty() {
            continue;
        }
        let name = &base.surfaces[i].name;
        let SurfaceKind::Pde(pde) = &base.surfaces[i].kind else {
            continue;
        };
        let s = base.surfaces[i].surface();
        // The point's boundary row of each cap, as its integrals evaluated it where kept.
        let kept_row = |u: f64| {
            let e = usize::from(u == 1.0);
            kept.and_then(|k| k.ends.get(i))
                .and_then(|ends| ends[e].as_ref())
                .filter(|r| (u == 0.0 || u == 1.0) && r.len() == rule.nodes.len())
        };
        let rows = caps
            .iter()
            .any(|c| kept_row(c.u).is_none())
            .then(|| s.partials_rows(&rule.nodes));
        let mut row = vec![Partials::default(); rule.nodes.len()];
        let us: Vec<f64> = caps.iter().map(|c| c.u).collect();
        let cap_rows: Vec<Vec<f64>> = caps
            .iter()
            .map(|cap| {
                let row: &[Partials] = match (kept_row(cap.u), &rows) {
                    (Some(r), _) => r,
                    (None, Some(rows)) => {
                        rows.eval_row(cap.u, &mut row);
                        &row
                    }
                    (None, None) => unreachable!("the rows are made when one is not kept"),
                };
                let sign = if cap.u == 1.0 { -1.0 } else { 1.0 };
                let mut g = vec![0.0; rule.nodes.len() * NODE_WEIGHTS];
                cap_weights(row, &rule.weights, sign * at.orientation[i], &mut g);
                g
            })
            .collect();
        let weights = |a: usize, out: &mut [f64]| out.copy_from_slice(&cap_rows[a]);
        let list = adjoint_tangents(tangents, i);
        let d = pde
            .quadrature_adjoint_using(
                &us,
                &rule.nodes,
                1,
                &[Partial::X, Partial::Xv],
                &weights,
                &list,
            )
            .map_err(|e| e.at(&format!("patch '{name}'")))?;
        for (total, d) in totals.iter_mut().zip(&d) {
            if !d[0].is_finite() {
                return Err(Error::invalid(
                    "the derivative of a cap's volume is not finite at some node",
                )
                .at(&format!("patch '{name}'")));
            }
            total.volume += d[0];
        }
    }
    Ok(totals)
}

/// The weights of a cap's derivative [`cap_derivative`] times `scale` on its boundary row
/// `row` (the point's partials at the trapezoid nodes with weights `w`): `out[b·18 + q]` for the
/// tangent's `Ẋ` (`q` = 0, 1, 2) and `Ẋ_v` (`q` = 6, 7, 8) at node `b`, the others zero, so that
/// `Σ_b out_b · (Ẋ_b, Ẋ_v,b) = scale · cap_derivative`. With `P = Σ w`, `c = Σ w X / P`,
/// `S = ½ Σ w (X − c) × X_v` and `K = ½ Σ w X_v × c`, the derivative
/// `(1/3)(ċ·S + c·Ṡ)` is, since `c·(a × b) = a·(b × c) = b·(c × a)`,
/// Patch `i`'s tangent in every direction, as the adjoint takes them.
fn adjoint_tangents(tangents: &[Vec<PatchTangent>], i: usize) -> Vec<AdjointTangent<'_>> {
    tangents
        .iter()
        .map(|t| AdjointTangent {
            patch: &t[i].patch,
            stretch: t[i].stretch,
        })
        .collect()
}

/// `(1/3) Σ_b w_b [Ẋ_b · ((S − K)/P + ½ X_v,b × c) + Ẋ_v,b · ½ c × (X_b − c)]`.
pub(crate) fn cap_weights(row: &[Partials], w: &[f64], scale: f64, out: &mut [f64]) {
    out.fill(0.0);
    let period: f64 = w.iter().sum();
    let c = row.iter().zip(w).map(|(p, w)| p.x * *w).sum::<Vec3>() / period;
    let (mut s, mut k) = (Vec3::zeros(), Vec3::zeros());
    for (p, w) in row.iter().zip(w) {
        s += (p.x - c).cross(&p.xv) * (0.5 * w);
        k += p.xv.cross(&c) * (0.5 * w);
    }
    let mean = (s - k) / period;
    for ((p, &w), out) in row.iter().zip(w).zip(out.chunks_exact_mut(NODE_WEIGHTS)) {
        let gx = (mean + p.xv.cross(&c) * 0.5) * (scale * w / 3.0);
        let gv = c.cross(&(p.x - c)) * (scale * w / 6.0);
        out[..3].copy_from_slice(gx.as_slice());
        out[6..9].copy_from_slice(gv.as_slice());
    }
}

/// The partials of `s` along its parameter line `u` at the nodes `v` (a cap's boundary row).
fn cap_row(s: &dyn Surface, v: &[f64], u: f64) -> Vec<Partials> {
    let mut buf = vec![Partials::default(); v.len()];
    s.partials_rows(v).eval_row(u, &mut buf);
    buf
}

/// Adds one patch's derivative of (area, volume, mean, mean², Gauss) to `total`, the signed
/// ones turned by the patch's orientation `sign`; a non-finite value is an error naming the patch.
fn add_patch_derivative(total: &mut Integrals, d: &[f64; 5], sign: f64, patch: &str) -> Result<()> {
    if d.iter().any(|x| !x.is_finite()) {
        return Err(Error::invalid(
            "the derivative of the integrals is not finite at some quadrature node",
        )
        .at(&format!("patch '{patch}'")));
    }
    total.area += d[0];
    total.volume += sign * d[1];
    total.mean += sign * d[2];
    total.mean_sq += d[3];
    total.gauss += d[4];
    Ok(())
}

/// The rules of the level of `q` that has `nu × nv` nodes on `s` (the level the analysis ended
/// at).
fn rules_of(s: &dyn Surface, q: &Quadrature, nu: usize, nv: usize) -> Result<(Rule, Rule)> {
    let breaks = s.breaks();
    for k in 0..40 {
        let (ru, rv) = q.rules(s.u_range(), s.v_domain(), &breaks, k);
        if ru.nodes.len() == nu && rv.nodes.len() == nv {
            return Ok((ru, rv));
        }
        if ru.nodes.len() > nu || !q.adaptive {
            break;
        }
    }
    Err(Error::invalid(format!(
        "no level of the quadrature has the analysis's {nu} × {nv} nodes"
    )))
}

/// `[area, volume, mean, mean_sq, gauss]` derivatives of one patch with its own normal.
fn patch_derivative(
    s: &dyn Surface,
    others: &[(f64, &dyn Surface)],
    ru: &Rule,
    rv: &Rule,
) -> [f64; 5] {
    let base = s.partials_rows(&rv.nodes);
    let evals: Vec<(f64, Box<dyn crate::surface::PartialsRows + '_>)> = others
        .iter()
        .map(|(c, o)| (*c, o.partials_rows(&rv.nodes)))
        .collect();
    let rows: Vec<[f64; 5]> = ru
        .nodes
        .par_iter()
        .zip(&ru.weights)
        .map_init(
            || {
                (
                    vec![Partials::default(); rv.nodes.len()],
                    vec![Partials::default(); rv.nodes.len()],
                    vec![Partials::default(); rv.nodes.len()],
                )
            },
            |(pb, pt, po), (&u, &wu)| {
                base.eval_row(u, pb);
                pt.iter_mut().for_each(|p| *p = Partials::default());
                for (c, e) in &evals {
                    e.eval_row(u, po);
                    for (t, o) in pt.iter_mut().zip(po.iter()) {
                        add_scaled(t, *c, o);
                    }
                }
                let mut sum = [0.0; 5];
                for ((p, t), &wv) in pb.iter().zip(pt.iter()).zip(&rv.weights) {
                    let d = node_derivative(p, t);
                    for (s, d) in sum.iter_mut().zip(d) {
                        *s += wu * wv * d;
                    }
                }
                sum
            },
        )
        .collect();
    let mut total = [0.0; 5];
    for r in &rows {
        for (t, x) in total.iter_mut().zip(r) {
            *t += x;
        }
    }
    total
}

fn add_scaled(t: &mut Partials, c: f64, o: &Partials) {
    t.x += c * o.x;
    t.xu += c * o.xu;
    t.xv += c * o.xv;
    t.xuu += c * o.xuu;
    t.xuv += c * o.xuv;
    t.xvv += c * o.xvv;
}

/// The derivatives of the integrands `[J, (1/3)X·N, HJ, H²J, KJ]` at one node along the tangent
/// partials `t` (see the module documentation); the curvature terms are 0 where the node is
/// degenerate, as in the integrals themselves.
pub(crate) fn node_derivative(p: &Partials, t: &Partials) -> [f64; 5] {
    let cross = p.xu.cross(&p.xv);
    let dcross = t.xu.cross(&p.xv) + p.xu.cross(&t.xv);
    let volume = (t.x.dot(&cross) + p.x.dot(&dcross)) / 3.0;
    let jac = cross.norm();
    let size = p.xu.norm_squared() + p.xv.norm_squared();
    if normal_degenerates(jac, size) || !jac.is_finite() {
        return [0.0, volume, 0.0, 0.0, 0.0];
    }
    let n = cross / jac;
    let djac = n.dot(&dcross);
    let dn = (dcross - n * djac) / jac;
    let (e, f, g) = (p.xu.dot(&p.xu), p.xu.dot(&p.xv), p.xv.dot(&p.xv));
    let (de, df, dg) = (
        2.0 * p.xu.dot(&t.xu),
        t.xu.dot(&p.xv) + p.xu.dot(&t.xv),
        2.0 * p.xv.dot(&t.xv),
    );
    let (l, m, nn) = (p.xuu.dot(&n), p.xuv.dot(&n), p.xvv.dot(&n));
    let (dl, dm, dnn) = (
        t.xuu.dot(&n) + p.xuu.dot(&dn),
        t.xuv.dot(&n) + p.xuv.dot(&dn),
        t.xvv.dot(&n) + p.xvv.dot(&dn),
    );
    let w = jac * jac;
    let dw = 2.0 * jac * djac;
    let gauss = (l * nn - m * m) / w;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * w);
    if !gauss.is_finite() || !mean.is_finite() {
        return [0.0, volume, 0.0, 0.0, 0.0];
    }
    let dgauss = (dl * nn + l * dnn - 2.0 * m * dm) / w - gauss * dw / w;
    let dmean = (de * nn + e * dnn - 2.0 * df * m - 2.0 * f * dm + dg * l + g * dl) / (2.0 * w)
        - mean * dw / w;
    [
        djac,
        volume,
        dmean * jac + mean * djac,
        2.0 * mean * dmean * jac + mean * mean * djac,
        dgauss * jac + gauss * djac,
    ]
}

/// The weights of [`node_derivative`] times `w`: `out[o·18 + q]` is `w` times the derivative of
/// integrand `o` (`J, (1/3)X·N, HJ, H²J, KJ`) with respect to component `q` of the tangent's
/// partials (`Ẋ, Ẋ_u, Ẋ_v, Ẋ_uu, Ẋ_uv, Ẋ_vv`, x, y, z each), so that
/// `Σ_q out[o·18 + q] t_q = w · node_derivative(p, t)[o]` for every tangent `t`.
///
/// [`node_derivative`] is linear in the scalars `J̇ = n·Ṅ`, `Ė, Ḟ, Ġ`, `L̇, Ṁ, Ṅ` (with
/// `L̇ = Ẋ_uu·n + (X_uu − L n)·Ṅ / J`, `Ṁ`, `Ṅ` alike): with `κ` the coefficients of those scalars
/// in integrand `o`, the covector of `Ṅ = Ẋ_u × X_v + X_u × Ẋ_v` is
/// `r = κ_J n + (κ_L (X_uu − L n) + κ_M (X_uv − M n) + κ_N (X_vv − N n)) / J`, and the weights are
/// `Ẋ_u: X_v × r + 2κ_E X_u + κ_F X_v`, `Ẋ_v: r × X_u + κ_F X_u + 2κ_G X_v`,
/// `Ẋ_uu: κ_L n`, `Ẋ_uv: κ_M n`, `Ẋ_vv: κ_N n` (and `(1/3)(Ẋ·N + X·Ṅ)` for the volume). Zero
/// curvature weights at degenerate nodes, as in [`node_derivative`].
pub(crate) fn node_gradient(p: &Partials, w: f64, out: &mut [f64]) {
    out[..NODE].fill(0.0);
    let cross = p.xu.cross(&p.xv);
    let put = |out: &mut [f64], o: usize, q: usize, v: Vec3| {
        let at = o * NODE_WEIGHTS + q;
        out[at] = w * v.x;
        out[at + 1] = w * v.y;
        out[at + 2] = w * v.z;
    };
    // The volume: (1/3)(Ẋ·N + X·Ṅ).
    let r = p.x / 3.0;
    put(out, 1, 0, cross / 3.0);
    put(out, 1, 3, p.xv.cross(&r));
    put(out, 1, 6, r.cross(&p.xu));
    let jac = cross.norm();
    let size = p.xu.norm_squared() + p.xv.norm_squared();
    if normal_degenerates(jac, size) || !jac.is_finite() {
        return;
    }
    let n = cross / jac;
    let (e, f, g) = (p.xu.dot(&p.xu), p.xu.dot(&p.xv), p.xv.dot(&p.xv));
    let (l, m, nn) = (p.xuu.dot(&n), p.xuv.dot(&n), p.xvv.dot(&n));
    let ww = jac * jac;
    let gauss = (l * nn - m * m) / ww;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * ww);
    // The area: J̇ alone.
    let mut kappa = [[0.0f64; 7]; 5];
    kappa[0][0] = 1.0;
    if gauss.is_finite() && mean.is_finite() {
        // Ḣ and K̇ in the scalars [J̇, Ė, Ḟ, Ġ, L̇, Ṁ, Ṅ].
        let dh = [
            -2.0 * mean / jac,
            nn / (2.0 * ww),
            -m / ww,
            l / (2.0 * ww),
            g / (2.0 * ww),
            -f / ww,
            e / (2.0 * ww),
        ];
        let dk = [
            -2.0 * gauss / jac,
            0.0,
            0.0,
            0.0,
            nn / ww,
            -2.0 * m / ww,
            l / ww,
        ];
        for s in 0..7 {
            kappa[2][s] = jac * dh[s];
            kappa[3][s] = 2.0 * mean * jac * dh[s];
            kappa[4][s] = jac * dk[s];
        }
        kappa[2][0] += mean;
        kappa[3][0] += mean * mean;
        kappa[4][0] += gauss;
    }
    let (pl, pm, pn) = (
        (p.xuu - n * l) / jac,
        (p.xuv - n * m) / jac,
        (p.xvv - n * nn) / jac,
    );
    for (o, k) in kappa.iter().enumerate() {
        if o == 1 || k.iter().all(|&x| x == 0.0) {
            continue;
        }
        let r = n * k[0] + pl * k[4] + pm * k[5] + pn * k[6];
        put(
            out,
            o,
            3,
            p.xv.cross(&r) + p.xu * (2.0 * k[1]) + p.xv * k[2],
        );
        put(
            out,
            o,
            6,
            r.cross(&p.xu) + p.xu * k[2] + p.xv * (2.0 * k[3]),
        );
        put(out, o, 9, n * k[4]);
        put(out, o, 12, n * k[5]);
        put(out, o, 15, n * k[6]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::UnitCylinder;
    use crate::Vec3;

    /// The node weights against the node derivative on tangents along each of the 18
    /// components and on a generic one, at generic nodes and at a pole (zero curvature
    /// weights). Both evaluate the same expression with different groupings: a weight is a sum
    /// of at most 8 products of at most 5 rounded factors and the dot product has 18 terms, so
    /// each side is within `γ_40 · Σ_q |w_q t_q|` of the exact value (node_derivative's
    /// groupings are no deeper), about `40ε` of the sum of the magnitudes; the differences are
    /// checked against twice that.
    #[test]
    fn node_weights_are_the_gradient_of_the_node_derivative() {
        let c = UnitCylinder;
        let bend = |p: &mut Partials, s: f64| {
            p.xuu += Vec3::new(0.3 * s, -0.2, 0.5);
            p.xuv += Vec3::new(0.1, 0.4 * s, -0.3);
            p.xvv += Vec3::new(-0.2, 0.1, 0.2 * s);
            p.xu += Vec3::new(0.2 * s, 0.1, 0.0);
        };
        let mut nodes = Vec::new();
        for (k, (u, v)) in [(0.3f64, 0.7f64), (0.9, 2.5), (0.1, 4.0)]
            .into_iter()
            .enumerate()
        {
            let mut p = c.partials(u, v);
            bend(&mut p, k as f64 - 1.0);
            nodes.push(p);
        }
        // A pole: X_v = 0.
        let mut pole = c.partials(0.5, 1.0);
        pole.xv = Vec3::zeros();
        nodes.push(pole);
        let eps = f64::EPSILON;
        let gamma = 40.0 * eps / (1.0 - 40.0 * eps);
        for (i, p) in nodes.iter().enumerate() {
            let w = 0.37;
            let mut g = [0.0; NODE];
            node_gradient(p, w, &mut g);
            let mut tangents: Vec<[f64; NODE_WEIGHTS]> = (0..NODE_WEIGHTS)
                .map(|q| std::array::from_fn(|r| if r == q { 1.0 } else { 0.0 }))
                .collect();
            tangents.push(std::array::from_fn(|r| ((r as f64) * 0.7 + 0.3).sin()));
            for t in &tangents {
                let v3 = |q: usize| Vec3::new(t[q], t[q + 1], t[q + 2]);
                let tp = Partials {
                    x: v3(0),
                    xu: v3(3),
                    xv: v3(6),
                    xuu: v3(9),
                    xuv: v3(12),
                    xvv: v3(15),
                };
                let d = node_derivative(p, &tp);
                for (o, d) in d.iter().enumerate() {
                    let gw = &g[o * NODE_WEIGHTS..(o + 1) * NODE_WEIGHTS];
                    let dot: f64 = gw.iter().zip(t).map(|(a, b)| a * b).sum();
                    let size: f64 = gw.iter().zip(t).map(|(a, b)| (a * b).abs()).sum();
                    let bound = 2.0 * gamma * (size + (w * d).abs());
                    assert!(
                        (dot - w * d).abs() <= bound,
                        "node {i}, integrand {o}: {dot} vs {} (bound {bound:e})",
                        w * d
                    );
                }
            }
            if i == 3 {
                // At the pole only the volume has weights.
                assert!(g[..NODE_WEIGHTS].iter().all(|&x| x == 0.0));
                assert!(g[2 * NODE_WEIGHTS..].iter().all(|&x| x == 0.0));
            }
        }
    }

    /// The cap's weights against [`cap_derivative`] on a boundary row (a closed, non-planar
    /// curve `X`, its `X_v`, and a tangent `Ẋ`, `Ẋ_v`) at the nodes of the caps' rule. The two
    /// are the same expression summed in different orders over `N = 512` nodes: each is a sum
    /// of `N` products whose factors are themselves sums of at most `N` terms (`c`, `S`, `K`,
    /// `ċ`, `Ṡ`), so each is within `γ_{2N+8}` of the sum of the magnitudes of its terms (the
    /// terms bounded by products of norms: `|a·(b × c)| ≤ |a||b||c|`), the weights' own sums
    /// `S`, `K` adding their magnitudes times `Σ w |Ẋ| / P`; the difference is checked against
    /// the sum of these bounds.
    #[test]
    fn cap_weights_are_the_gradient_of_the_cap_derivative() {
        let rule = periodic_trapezoid(CURVE_NODES);
        let nn = rule.nodes.len();
        let curve = |v: f64| {
            Vec3::new(
                1.3 * v.cos() + 0.2 * (2.0 * v).sin(),
                0.4 + 0.3 * (3.0 * v).cos(),
                0.9 * v.sin(),
            )
        };
        let dcurve = |v: f64| {
            Vec3::new(
                -1.3 * v.sin() + 0.4 * (2.0 * v).cos(),
                -0.9 * (3.0 * v).sin(),
                0.9 * v.cos(),
            )
        };
        // A dilation, a shift and a bend.
        let tangent = |v: f64| {
            curve(v) * 0.25 + Vec3::new(0.3 + (2.0 * v).cos(), 0.6 + 0.5 * v.sin(), -0.7 + v.cos())
        };
        let dtangent =
            |v: f64| dcurve(v) * 0.25 + Vec3::new(-2.0 * (2.0 * v).sin(), 0.5 * v.cos(), -v.sin());
        let row: Vec<Partials> = rule
            .nodes
            .iter()
            .map(|&v| Partials {
                x: curve(v),
                xv: dcurve(v),
                ..Partials::default()
            })
            .collect();
        let scale = -0.8;
        let mut g = vec![0.0; nn * NODE_WEIGHTS];
        cap_weights(&row, &rule.weights, scale, &mut g);
        let mut adjoint = 0.0;
        let mut magnitude = 0.0;
        for (b, &v) in rule.nodes.iter().enumerate() {
            let gb = &g[b * NODE_WEIGHTS..(b + 1) * NODE_WEIGHTS];
            assert!(gb[3..6].iter().chain(&gb[9..]).all(|&x| x == 0.0));
            let (t, dt) = (tangent(v), dtangent(v));
            for k in 0..3 {
                adjoint += gb[k] * t[k] + gb[6 + k] * dt[k];
                magnitude += (gb[k] * t[k]).abs() + (gb[6 + k] * dt[k]).abs();
            }
        }
        let rows: Vec<_> = rule
            .nodes
            .iter()
            .zip(&row)
            .map(|(&v, p)| (p.x, p.xv, tangent(v), dtangent(v)))
            .collect();
        let direct = scale * cap_derivative(&rows, &rule.weights);
        // The magnitudes of the direct sums' terms, by norms.
        let period: f64 = rule.weights.iter().sum();
        let w = &rule.weights;
        let c = rows.iter().zip(w).map(|(r, w)| r.0 * *w).sum::<Vec3>() / period;
        let dc = rows.iter().zip(w).map(|(r, w)| r.2 * *w).sum::<Vec3>() / period;
        type Node = (Vec3, Vec3, Vec3, Vec3);
        let norm_sum =
            |f: &dyn Fn(&Node) -> f64| -> f64 { rows.iter().zip(w).map(|(r, w)| w * f(r)).sum() };
        let s_abs = norm_sum(&|r| (r.0 - c).norm() * r.1.norm()) / 2.0;
        let ds_abs =
            norm_sum(&|r| (r.2 - dc).norm() * r.1.norm() + (r.0 - c).norm() * r.3.norm()) / 2.0;
        let dc_abs = norm_sum(&|r| r.2.norm()) / period;
        let direct_magnitude = scale.abs() * (dc_abs * s_abs + c.norm() * ds_abs) / 3.0;
        // The rounding of the weights' own sums `S`, `K`, carried by `Σ w |Ẋ| / P`.
        let k_abs = norm_sum(&|r| r.1.norm()) * c.norm() / 2.0;
        let weight_magnitude = scale.abs() * dc_abs * (s_abs + k_abs) / 3.0;
        let m = (2 * nn + 8) as f64 * f64::EPSILON;
        let gamma = m / (1.0 - m);
        let bound = gamma * (magnitude + direct_magnitude + weight_magnitude);
        assert!(direct.abs() > 0.1, "a tangent that moves the cap: {direct}");
        assert!(
            (adjoint - direct).abs() <= bound,
            "{adjoint} vs {direct} (bound {bound:e})"
        );
    }

    /// The node derivative against central differences of the integrands on a surface moved
    /// along a fixed tangent (`X + s·T` with `T` the partials of a smooth field).
    #[test]
    fn node_derivative_matches_differences_of_the_integrands() {
        let c = UnitCylinder;
        let p = c.partials(0.3, 0.7);
        // A tangent: the partials of (u v², sin v, u² cos v).
        let (u, v) = (0.3f64, 0.7f64);
        let t = Partials {
            x: Vec3::new(u * v * v, v.sin(), u * u * v.cos()),
            xu: Vec3::new(v * v, 0.0, 2.0 * u * v.cos()),
            xv: Vec3::new(2.0 * u * v, v.cos(), -u * u * v.sin()),
            xuu: Vec3::new(0.0, 0.0, 2.0 * v.cos()),
            xuv: Vec3::new(2.0 * v, 0.0, -2.0 * u * v.sin()),
            xvv: Vec3::new(2.0 * u, -v.sin(), -u * u * v.cos()),
        };
        let integrands = |s: f64| {
            let mut q = p;
            add_scaled(&mut q, s, &t);
            let core = super::super::geometry::core(&q).unwrap();
            [
                core.jac,
                q.x.dot(&q.xu.cross(&q.xv)) / 3.0,
                core.mean * core.jac,
                core.mean * core.mean * core.jac,
                core.gauss * core.jac,
            ]
        };
        let d = node_derivative(&p, &t);
        for h in [1e-3, 5e-4] {
            let (a, b) = (integrands(h), integrands(-h));
            for k in 0..5 {
                let fd = (a[k] - b[k]) / (2.0 * h);
                // Central differences: error ~ h² |f'''| (here below 10 h²).
                assert!((fd - d[k]).abs() <= 10.0 * h * h, "{k}: {fd} vs {}", d[k]);
            }
        }
    }
}
