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
use super::{DesignIntegrals, Integrals, Quadrature};
use crate::design::SolvedDesign;
use crate::surface::{normal_degenerates, Partials, Surface};
use crate::{Error, Result};
use rayon::prelude::*;

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

/// The derivatives of the integrals `at` of `base` (as in [`integrals_derivative`]) along `K`
/// tangent surfaces at once: `tangents[k][i]` is the derivative of patch `i` along direction
/// `k` (such as [`crate::design::tangent_patches`]' patches). One pass over the quadrature nodes:
/// each row of the base's partials is evaluated once for all directions, and each direction's
/// partials once (not as differences of designs). The same chain rule at the same nodes as
/// [`integrals_derivative`], so the same derivatives to rounding.
pub fn integrals_derivatives(
    base: &SolvedDesign,
    at: &DesignIntegrals,
    tangents: &[Vec<&dyn Surface>],
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
        let s = base.surfaces[i].surface();
        let surfaces: Vec<&dyn Surface> = tangents.iter().map(|t| t[i]).collect();
        let (ru, rv) = rules_of(s, q, at.analyses[i].u_nodes, at.analyses[i].v_nodes)?;
        let d = patch_derivatives(s, &surfaces, &ru, &rv);
        for (total, d) in totals.iter_mut().zip(&d) {
            add_patch_derivative(total, d, at.orientation[i], &base.surfaces[i].name)?;
        }
    }
    let rule = periodic_trapezoid(CURVE_NODES);
    for cap in &at.caps {
        let i = cap.patch;
        let row = |s: &dyn Surface| cap_row(s, &rule.nodes, cap.u);
        let b = row(base.surfaces[i].surface());
        let sign = if cap.u == 1.0 { -1.0 } else { 1.0 };
        for (total, t) in totals.iter_mut().zip(tangents) {
            let rows: Vec<_> = b
                .iter()
                .zip(row(t[i]))
                .map(|(p, d)| (p.x, p.xv, d.x, d.xv))
                .collect();
            total.volume += sign * at.orientation[i] * cap_derivative(&rows, &rule.weights);
        }
    }
    Ok(totals)
}

/// [`patch_derivative`] along each of the tangent surfaces `tangents` (their own partials).
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

fn patch_derivatives(
    s: &dyn Surface,
    tangents: &[&dyn Surface],
    ru: &Rule,
    rv: &Rule,
) -> Vec<[f64; 5]> {
    let kk = tangents.len();
    let base = s.partials_rows(&rv.nodes);
    let evals: Vec<Box<dyn crate::surface::PartialsRows + '_>> = tangents
        .iter()
        .map(|t| t.partials_rows(&rv.nodes))
        .collect();
    let rows: Vec<Vec<[f64; 5]>> = ru
        .nodes
        .par_iter()
        .zip(&ru.weights)
        .map_init(
            || {
                (
                    vec![Partials::default(); rv.nodes.len()],
                    vec![Partials::default(); rv.nodes.len()],
                )
            },
            |(pb, pt), (&u, &wu)| {
                base.eval_row(u, pb);
                evals
                    .iter()
                    .map(|e| {
                        e.eval_row(u, pt);
                        let mut sum = [0.0; 5];
                        for ((p, t), &wv) in pb.iter().zip(pt.iter()).zip(&rv.weights) {
                            let d = node_derivative(p, t);
                            for (s, d) in sum.iter_mut().zip(d) {
                                *s += wu * wv * d;
                            }
                        }
                        sum
                    })
                    .collect()
            },
        )
        .collect();
    let mut total = vec![[0.0; 5]; kk];
    for r in &rows {
        for (t, r) in total.iter_mut().zip(r) {
            for (t, x) in t.iter_mut().zip(r) {
                *t += x;
            }
        }
    }
    total
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::UnitCylinder;
    use crate::Vec3;

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
