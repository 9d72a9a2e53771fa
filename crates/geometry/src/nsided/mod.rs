//! Patches bounded by a loop of `n = 3 … 8` curves, solving the Bloor–Wilson PDE
//! `(∂²/∂x² + a² ∂²/∂y²)^N X = 0` (`N = 1, 2, 3`) on a regular n-gon, with the boundary met
//! exactly and, on any side, a ribbon (cross-boundary derivative) met exactly for G1 and, for
//! `N = 3`, a curvature ribbon (second cross derivative) met exactly for G2.
//!
//! # Method
//!
//! The surface is `X = C + Σ c_k φ_k` on the regular n-gon `Ω` ([`domain`]):
//! - `C` is a transfinite interpolant of the boundary data (a side-blended patch in the manner
//!   of Kato): each side `i` gives a ribbon `R_i = P_i(s_i) + (d_i / L) D_i(s_i)` in its own
//!   coordinates (`d_i` the distance to the side, `s_i = d_{i−1}/(d_{i−1} + d_{i+1})` the
//!   position along it, `L` the side length), and `C = Σ B_i R_i` with the blends
//!   `B_i = Π_{j≠i} d_j³ / Σ_k Π_{j≠k} d_j³`. On side `i`, `B_i = 1` and every other blend
//!   vanishes with two cross derivatives, so `C = P_i` and `∂C/∂n = D_i/L + P_i' ∂s_i/∂n`:
//!   position and tangent plane are those of the data, exactly.
//! - `φ_k = w · P_a(x) P_b(y)` ([`basis`]) vanish on every side together with as many
//!   cross derivatives as the side has conditions, so they change nothing on the boundary.
//!   Their coefficients minimise the operator's energy `∫_Ω (L X)²` (`N = 2`),
//!   `∫_Ω X_x² + a² X_y²` (`N = 1`) or `∫_Ω (∂_x L X)² + a² (∂_y L X)²` (`N = 3`; its first
//!   variation is `2 ∫ ∇_a(L X) · ∇_a(L φ) = −2 ∫ L²X · Lφ = −2 ∫ L³X · φ` when `φ` vanishes with
//!   two cross derivatives on the sides, so `Lφ = 0` there and no boundary term is left), whose
//!   Euler–Lagrange equation is the PDE: a Galerkin
//!   (Ritz) solve, spectrally convergent in the degree for smooth data. The matrix depends on
//!   the polygon, the sides' multiplicities, the operator and the degree only, so it is
//!   factorised once and cached, with the operator's weights of the sides' data at every
//!   quadrature point (`Weights`): an edit of the curves costs the sides' data at each point
//!   and a back substitution.
//!
//! Sides without a ribbon take the natural condition of the energy (for `N = 2`). A ribbon is
//! explicit ([`Ribbon::Derivative`]) or the tangent plane of a neighbour
//! ([`Ribbon::TangentPlane`]): then `D = a(s) N × P' + b(s) P'` lies in the neighbour's plane,
//! with `a`, `b` fixed at the two corners so that the cross derivative there equals the
//! adjacent side's tangent (the compatibility a surface needs to be `C¹` at a corner), and
//! linear in between. Where that tangent is not in the neighbour's plane, no surface is G1 to
//! both neighbours at the corner; the angle is reported ([`Corner::tangent_mismatch`]) and the
//! ribbon takes its projection. Twists (mixed derivatives at corners) need not agree: the
//! blends absorb them.
//!
//! # Order 3 and curvature ribbons (G2)
//!
//! Every ribbon is `R_i = P_i + t D_i + t² E_i (+ t³ F_i)`; `E_i` is the interpolant's choice
//! on a G0 or G1 side (fixed at the corners so that neighbouring ribbons agree to second
//! order). A curvature ribbon makes it a condition: from a neighbour ([`Ribbon::Curvature`],
//! its normal `N` and second fundamental form `II` along the side), `E = l + N (II(D, D)/2 −
//! N · l)`, so `N · E = II(D, D)/2` (`R_tt = 2E`, and the neighbour's normal curvature in the
//! direction `D` is `II(D, D)`; the other parts of the patch's second fundamental form along
//! the side, `II(P', P') = N · P''` and `II(P', D) = N · D'`, are the neighbour's already once
//! the side lies on it and the tangent planes agree), `l` the free tangential part; or given
//! explicitly ([`Ribbon::Derivatives`], `E = W/2`). The blends of order 3 are `Π_{j≠i} d_j⁴`,
//! so every other blend vanishes with three cross derivatives on side `i` and `C` has `R_i`'s
//! second-order jet there; the correction vanishes with three cross derivatives on a G2 side
//! (multiplicity 3), so the patch is G2 to the ribbon surface to rounding. At the corners the
//! ribbons are matched to third order as well (the cubic terms `t³ F` and the slopes of `E`),
//! so the interpolant is `C³` there when the data allow; where two curvature ribbons disagree
//! at a corner (the next side's curve turns in the patch's normal direction with another
//! curvature than the ribbon asks across it), no surface is G2 to both: the normal part left
//! is reported ([`Corner::curvature_mismatch`]) and the blends absorb it, with ripples of the
//! correction nearby.
//!
//! For `n = 4` the patch is one surface on the square; otherwise it is presented as `n`
//! four-sided pieces around the centre ([`NSidedSurface`]), each the bilinear image of the
//! quadrilateral between a corner, the midpoints of its two sides and the centre, so every
//! consumer of [`Surface`] (meshes, CAD, analysis) takes it; the pieces meet G1 because they
//! are cuts of one smooth function.
//!
//! # Accuracy
//!
//! Positions and ribbons are met to rounding by construction. The neighbouring ribbons are
//! matched to second order at every corner (twists of free and plane ribbons, second cross
//! derivatives), so the interpolant is `C²` there when the data allow; its third derivatives
//! still jump at the corners, so the Ritz error falls algebraically in the degree (about
//! `p^−4` in the maximum norm on the closed-form tests), not spectrally. The magnitude of a
//! plane ribbon's cross derivative is prescribed (corner-compatible, cubic along the side),
//! not optimised by the energy.

mod basis;
mod bounds;
mod domain;
mod jet;
mod model;
mod rows;
mod side;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_g2;

pub use model::{model_exponents, model_index, CellModel, MODEL_DEGREE, MODEL_LEN};
pub use side::{NormalField, Ribbon, ShapeField, Side};

use crate::surface::{
    FirstPartialsRows, Partials, PointwiseFirstPartials, RowEvaluator, Surface, VDomain,
};
use crate::{Error, Result, Vec3};
use basis::Basis;
use domain::Polygon;
use jet::{Jet, VJet};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use side::{BuiltCurvature, BuiltRibbon, BuiltSide, ChebVec};
use std::sync::{Arc, Mutex, OnceLock};

/// Where the quadrature panels of a piece end near a polygon corner (see
/// [`NSidedSurface`]'s `breaks`).
const CORNER_GRADING: [f64; 4] = [1e-4, 1e-3, 1e-2, 1e-1];

/// The smallest turn of the boundary's tangent at a corner (radians, 0.5°).
const MIN_TURN: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The largest number of sides.
pub const MAX_SIDES: usize = 8;

/// Options of an n-sided patch.
#[derive(Clone, Debug, PartialEq)]
pub struct NSidedOptions {
    /// `N`: 1 (Laplace, positions only), 2 (biharmonic type, positions and ribbons) or 3
    /// (triharmonic type, positions, ribbons and curvature ribbons).
    pub order: usize,
    /// The smoothing parameter `a > 0` of `∂²/∂x² + a² ∂²/∂y²` (for `n = 4`, `x` runs along
    /// side 0 and `y` along side 1).
    pub a: f64,
    /// The degree `p` of the correction polynomials (`(p + 1)(p + 2)/2` unknowns per
    /// coordinate), 0 to 24.
    pub degree: usize,
    /// The largest gap allowed where two consecutive sides meet, relative to the size of the
    /// boundary (the diagonal of its bounding box).
    pub gap_tolerance: f64,
}

impl Default for NSidedOptions {
    fn default() -> Self {
        NSidedOptions {
            order: 2,
            a: 1.0,
            degree: 12,
            gap_tolerance: 1e-9,
        }
    }
}

/// What happens where side `k − 1` ends and side `k` starts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Corner {
    /// The distance between the end of side `k − 1` and the start of side `k`.
    pub gap: f64,
    /// The angle (radians) by which an adjacent side's tangent leaves a ribbon's tangent plane
    /// at this corner: 0 when the patch can be G1 to both neighbours there.
    pub tangent_mismatch: f64,
    /// What is left of the disagreement of the two sides' twists (mixed second derivatives)
    /// after the free parts of the ribbons took what they could, relative to the sides'
    /// tangents: 0 when the patch can be `C²` at the corner. The blends absorb the rest, so the
    /// surface stays G1 but its curvature is not continuous at the corner.
    pub twist_mismatch: f64,
    /// What is left of the disagreement of the two sides' second derivatives across the
    /// corner in the direction of the surface normal, after the free parts of the second
    /// cross derivatives took what they could: a normal curvature (times the boundary's
    /// size). 0 unless a curvature ribbon (G2) meets the corner: then no surface is G2 to
    /// both sides' data there, and the blends absorb the rest.
    pub curvature_mismatch: f64,
}

/// The largest errors of a solved patch along its boundary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NSidedReport {
    /// The diagonal of the boundary's bounding box.
    pub size: f64,
    /// Per side, the largest distance between the patch and the side's curve.
    pub boundary: Vec<f64>,
    /// Per side with a ribbon, the largest angle (radians) between the patch's tangent plane
    /// and the ribbon's (the neighbour's normal for [`Ribbon::TangentPlane`]).
    pub g1: Vec<Option<f64>>,
    /// Per side with a curvature ribbon (G2), the largest difference between the patch's
    /// normal curvature across the side and the ribbon's (the neighbour's for
    /// [`Ribbon::Curvature`], the surface `P + t D + t²/2 W` for [`Ribbon::Derivatives`]),
    /// times the boundary's size.
    pub g2: Vec<Option<f64>>,
    /// Per corner `k` (start of side `k`).
    pub corners: Vec<Corner>,
}

/// A solved n-sided patch.
pub struct NSidedPatch {
    poly: Polygon,
    sides: Vec<BuiltSide>,
    basis: Basis,
    options: NSidedOptions,
    /// The correction's coefficients, in the order of [`Basis::by_a`].
    coeffs: Vec<Vec3>,
    size: f64,
    corners: Vec<Corner>,
    /// The correction's coefficient sums for [`bounds`], made at the first request.
    correction_bounds: OnceLock<Box<bounds::Correction>>,
    /// The correction's columns and bounds for [`model`], made at the first request.
    correction_data: OnceLock<Box<model::CorrectionData>>,
}

impl std::fmt::Debug for NSidedPatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NSidedPatch")
            .field("n", &self.poly.n)
            .field("options", &self.options)
            .finish()
    }
}

/// The Galerkin operator of one polygon, multiplicities, operator and degree: the quadrature,
/// the operator applied to every basis function at every point, and the factorised matrix.
struct Galerkin {
    key: Key,
    points: Vec<([f64; 2], f64)>,
    /// Components of the operator per point and function: `[φ_x, a φ_y]` (`N = 1`),
    /// `[φ_xx + a² φ_yy]` (`N = 2`) or `[∂_x Lφ, a ∂_y Lφ]` (`N = 3`); laid out
    /// `[point][function][component]`.
    g: Vec<f64>,
    comps: usize,
    /// Jacobi scaling `1/√K_kk` and the Cholesky factor of the scaled matrix (or its
    /// eigen-decomposition when rounding made it indefinite).
    scale: Vec<f64>,
    factor: Factor,
    /// The interpolant's operator at every point as weights of the sides' data (see
    /// [`Weights`]); `None` where the table would be large (many sides at order 3).
    weights: Option<Weights>,
}

/// The operator applied to the boundary interpolant `C` at the quadrature points, as weights
/// of the sides' data. `C = Σ_i B_i Σ_m t_i^m f_{i,m}(s_i)` (`f_{i,0} = P_i`, `f_{i,1} = D_i`,
/// `f_{i,2} = E_i`, `f_{i,3} = F_i`), and by the chain rule `f(s(x, y))`'s jet is
/// `Σ_k f^{(k)}(s) · S_k` with `S_k` the jet of `s ↦ e_k` composed with `s` (Faà di Bruno is
/// linear in `f`'s derivatives). So each component `ℓ_c` of the operator is
/// `ℓ_c C = Σ_i Σ_{m,k} α_{c,m,k} f_{i,m}^{(k)}(s_i)` with `α_{c,m,k} = ℓ_c(B_i t_i^m S_k)`,
/// which depend on the polygon, the operator and the point only: a patch pays for its sides'
/// data at each point and a few products, not for the blends' jets.
struct Weights {
    /// `s_i` at point `q`: `s[q · n + i]`.
    s: Vec<f64>,
    /// `α_{c,m,k}` at point `q` and side `i`: `alpha[((q · n + i) · comps + c) · stride + m ·
    /// (O + 1) + k]` (`m` up to the order's terms, `k ≤ O`).
    alpha: Vec<f64>,
    /// The entries of one `(q, i, c)`: the terms `m` times the derivatives `k`.
    stride: usize,
    /// The derivatives `k` of the data taken (`O + 1`).
    derivatives: usize,
}

/// The most `f64` a [`Weights`] table may hold (4 MiB): the operators of many sides at order
/// 3 evaluate their interpolants directly instead.
const MAX_WEIGHTS: usize = 1 << 19;

enum Factor {
    Cholesky(nalgebra::Cholesky<f64, nalgebra::Dyn>),
    Eigen(nalgebra::SymmetricEigen<f64, nalgebra::Dyn>),
}

#[derive(Clone, Debug, PartialEq)]
struct Key {
    n: usize,
    multiplicity: Vec<usize>,
    order: usize,
    a: u64,
    degree: usize,
}

/// The operators built so far (a few: one per kind of patch a design holds).
fn cache() -> &'static Mutex<Vec<Arc<Galerkin>>> {
    static CACHE: OnceLock<Mutex<Vec<Arc<Galerkin>>>> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(Vec::new()))
}

const CACHE_SIZE: usize = 16;

impl Galerkin {
    fn get(poly: &Polygon, basis: &Basis, order: usize, a: f64) -> Arc<Galerkin> {
        let key = Key {
            n: poly.n,
            multiplicity: basis.multiplicity.clone(),
            order,
            a: a.to_bits(),
            degree: basis.degree,
        };
        if let Ok(c) = cache().lock() {
            if let Some(g) = c.iter().find(|g| g.key == key) {
                return g.clone();
            }
        }
        let g = Arc::new(Galerkin::build(key, poly, basis, order, a));
        if let Ok(mut c) = cache().lock() {
            if c.len() >= CACHE_SIZE {
                c.remove(0);
            }
            c.push(g.clone());
        }
        g
    }

    fn build(key: Key, poly: &Polygon, basis: &Basis, order: usize, a: f64) -> Galerkin {
        // φ has degree Σm + p; the energy's integrand at most 2(Σm + p − N); the collapsed map
        // adds one degree in ξ. A rule with nq points per direction integrates 2nq − 1.
        let nq = (basis.weight_degree() + basis.degree + 2).max(8);
        let points = poly.quadrature(nq);
        let nb = basis.len();
        let comps = if order == 2 { 1 } else { 2 };
        let a2 = a * a;
        let rows: Vec<Vec<f64>> = points
            .par_iter()
            .map(|(p, _)| {
                let mut row = Vec::with_capacity(nb * comps);
                if order == 3 {
                    let mut phi = Vec::<Jet<3>>::with_capacity(nb);
                    basis.eval(poly, *p, &mut phi);
                    for f in &phi {
                        row.push(f.t[0] + a2 * f.t[2]);
                        row.push(a * (f.t[1] + a2 * f.t[3]));
                    }
                } else {
                    let mut phi = Vec::<Jet>::with_capacity(nb);
                    basis.eval(poly, *p, &mut phi);
                    for f in &phi {
                        if order == 1 {
                            row.push(f.d[0]);
                            row.push(a * f.d[1]);
                        } else {
                            row.push(f.h[0] + a2 * f.h[2]);
                        }
                    }
                }
                row
            })
            .collect();
        // K = Σ_q w_q Σ_c g g^T, as Gᵀ G with the rows scaled by √w.
        let mut gm = DMatrix::<f64>::zeros(points.len() * comps, nb);
        for (q, ((_, w), row)) in points.iter().zip(&rows).enumerate() {
            let sw = w.sqrt();
            for k in 0..nb {
                for c in 0..comps {
                    gm[(q * comps + c, k)] = sw * row[k * comps + c];
                }
            }
        }
        let mut k = gm.tr_mul(&gm);
        let scale: Vec<f64> = (0..nb)
            .map(|i| {
                let d = k[(i, i)];
                if d > 0.0 {
                    1.0 / d.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        for i in 0..nb {
            for j in 0..nb {
                k[(i, j)] *= scale[i] * scale[j];
            }
        }
        let factor = match nalgebra::Cholesky::new(k.clone()) {
            Some(c) => Factor::Cholesky(c),
            None => Factor::Eigen(nalgebra::SymmetricEigen::new(k)),
        };
        let (terms, derivatives) = if order == 3 { (4, 4) } else { (3, 3) };
        let weights =
            (points.len() * poly.n * comps * terms * derivatives <= MAX_WEIGHTS).then(|| {
                if order == 3 {
                    Weights::new::<3>(poly, &points, order, a, comps)
                } else {
                    Weights::new::<2>(poly, &points, order, a, comps)
                }
            });
        Galerkin {
            key,
            points,
            g: rows.concat(),
            comps,
            scale,
            factor,
            weights,
        }
    }

    /// The coefficients minimising the energy of `C + Σ c_k φ_k`, given the operator applied
    /// to `C` at every quadrature point (`lc[q · comps + c]`).
    fn solve(&self, lc: &[Vec3]) -> Vec<Vec3> {
        let nb = self.scale.len();
        let mut rhs = DMatrix::<f64>::zeros(nb, 3);
        for (q, (_, w)) in self.points.iter().enumerate() {
            let g = &self.g[q * nb * self.comps..(q + 1) * nb * self.comps];
            for c in 0..self.comps {
                let v = lc[q * self.comps + c] * *w;
                for k in 0..nb {
                    let gk = g[k * self.comps + c];
                    rhs[(k, 0)] -= gk * v.x;
                    rhs[(k, 1)] -= gk * v.y;
                    rhs[(k, 2)] -= gk * v.z;
                }
            }
        }
        for k in 0..nb {
            for c in 0..3 {
                rhs[(k, c)] *= self.scale[k];
            }
        }
        let sol = match &self.factor {
            Factor::Cholesky(ch) => ch.solve(&rhs),
            Factor::Eigen(e) => {
                let top = e.eigenvalues.amax();
                let mut inv = DVector::<f64>::zeros(nb);
                for i in 0..nb {
                    let l = e.eigenvalues[i];
                    if l > 1e-13 * top {
                        inv[i] = 1.0 / l;
                    }
                }
                let y = e.eigenvectors.tr_mul(&rhs);
                let y = DMatrix::from_fn(nb, 3, |i, c| y[(i, c)] * inv[i]);
                &e.eigenvectors * y
            }
        };
        (0..nb)
            .map(|k| Vec3::new(sol[(k, 0)], sol[(k, 1)], sol[(k, 2)]) * self.scale[k])
            .collect()
    }
}

impl Weights {
    fn new<const O: usize>(
        poly: &Polygon,
        points: &[([f64; 2], f64)],
        order: usize,
        a: f64,
        comps: usize,
    ) -> Weights {
        let n = poly.n;
        let a2 = a * a;
        let terms = if order == 3 { 4 } else { 3 };
        let stride = terms * (O + 1);
        let per_point: Vec<(Vec<f64>, Vec<f64>)> = points
            .par_iter()
            .map(|(p, _)| {
                let blends = NSidedPatch::blends::<O>(poly, order, *p);
                let mut s = Vec::with_capacity(n);
                let mut alpha = Vec::with_capacity(n * comps * stride);
                for &(si, ti, wi) in &blends[..n] {
                    s.push(si.v);
                    let mut per = [vec![0.0; stride], vec![0.0; stride]];
                    let mut tm = wi;
                    for m in 0..terms {
                        for k in 0..=O {
                            let mut e = [0.0; 4];
                            e[k] = 1.0;
                            let j = si.compose(e) * tm;
                            let l = match order {
                                1 => [j.d[0], a * j.d[1]],
                                2 => [j.h[0] + a2 * j.h[2], 0.0],
                                _ => [j.t[0] + a2 * j.t[2], a * (j.t[1] + a2 * j.t[3])],
                            };
                            for (c, x) in per.iter_mut().zip(l) {
                                c[m * (O + 1) + k] = x;
                            }
                        }
                        tm = tm * ti;
                    }
                    for c in &per[..comps] {
                        alpha.extend_from_slice(c);
                    }
                }
                (s, alpha)
            })
            .collect();
        let (s, alpha): (Vec<Vec<f64>>, Vec<Vec<f64>>) = per_point.into_iter().unzip();
        Weights {
            s: s.concat(),
            alpha: alpha.concat(),
            stride,
            derivatives: O + 1,
        }
    }
}

/// The angle between two lines with directions `a` and `b` (0 to π/2).
fn line_angle(a: Vec3, b: Vec3) -> f64 {
    a.cross(&b).norm().atan2(a.dot(&b).abs())
}

/// The checks a boundary passes before any n-sided solve, on the sides' curves alone (not
/// their ribbons): every side finite and longer than 10⁻⁹ of the boundary's size (the diagonal
/// of its points' box), the loop closed at every corner within `gap_tolerance` of that size,
/// every corner turning by more than 0.5° and less than 179.5°, and no two sides (nor one
/// with itself) meeting away from their corners. Returns the size and each corner's gap (the
/// distance from the end of side `k − 1` to the start of side `k`). [`NSidedPatch::solve`]
/// runs these first; a caller laying out many patches can run them alone to find the faces no
/// solve would take.
pub fn boundary(sides: &[Side], gap_tolerance: f64) -> Result<(f64, Vec<f64>)> {
    let n = sides.len();
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    let mut lengths = vec![0.0; n];
    for (i, s) in sides.iter().enumerate() {
        let mut prev: Option<Vec3> = None;
        for j in 0..=64 {
            let mut c = [Vec3::zeros(); 1];
            s.jet(j as f64 / 64.0, &mut c);
            let p = c[0];
            if !p.iter().all(|x| x.is_finite()) {
                return Err(Error::invalid("the curve is not finite on the side")
                    .at(&format!("sides[{i}]")));
            }
            lo = lo.inf(&p);
            hi = hi.sup(&p);
            if let Some(q) = prev {
                lengths[i] += (p - q).norm();
            }
            prev = Some(p);
        }
    }
    let size = (hi - lo).norm();
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::invalid(
            "the sides enclose nothing: every point is the same",
        ));
    }
    for (i, l) in lengths.iter().enumerate() {
        if *l <= 1e-9 * size {
            return Err(Error::invalid(format!(
                "the side is degenerate: its length {l:.3e} is nothing next to the boundary's \
                 size {size:.3e}"
            ))
            .at(&format!("sides[{i}]")));
        }
    }
    let jet = |s: &Side, t: f64| {
        let mut c = [Vec3::zeros(); 2];
        s.jet(t, &mut c);
        c
    };
    let mut gaps = vec![0.0; n];
    for (k, gap) in gaps.iter_mut().enumerate() {
        let prev = (k + n - 1) % n;
        let (end, start) = (jet(&sides[prev], 1.0), jet(&sides[k], 0.0));
        *gap = (end[0] - start[0]).norm();
        if *gap > gap_tolerance * size {
            return Err(Error::invalid(format!(
                "the loop does not close at corner {k} (end of side {prev}, start of side {k}): \
                 the gap is {gap:.3e}, more than {gap_tolerance:.1e} of the boundary's size \
                 {size:.3e}"
            )));
        }
        // The domain's corner turns by 2π/n; a side that continues its predecessor (a flat
        // corner) or turns back on it (a cusp) maps that turn singularly.
        let (a, b) = (end[1], start[1]);
        let turn = a.cross(&b).norm().atan2(a.dot(&b));
        if !(MIN_TURN..=std::f64::consts::PI - MIN_TURN).contains(&turn) {
            return Err(Error::invalid(format!(
                "the sides meet without a corner at corner {k} (end of side {prev}, start of \
                 side {k}): the tangent turns by {:.3}°; every corner of an n-sided patch must \
                 turn (by more than {:.1}° and less than {:.1}°): join the two sides into one",
                turn.to_degrees(),
                MIN_TURN.to_degrees(),
                180.0 - MIN_TURN.to_degrees()
            )));
        }
    }
    // Sides that cross or touch each other, or themselves, bound no disk.
    let loop_sides: Vec<_> = sides
        .iter()
        .map(|s| (s.curve.clone(), s.t0, s.t1))
        .collect();
    let largest_gap = gaps.iter().fold(0.0f64, |a, &g| a.max(g));
    let ends = (1e-6 * size).max(4.0 * largest_gap);
    if let Some((i, s, j, t, p)) =
        crate::network::meet::loop_crossing(&loop_sides, 1e-9 * size, ends)
    {
        let what = if i == j {
            format!("side {i} crosses itself (at s = {s:.4} and s = {t:.4})")
        } else {
            format!("side {i} (at s = {s:.4}) meets side {j} (at s = {t:.4})")
        };
        return Err(Error::invalid(format!(
            "{what} at ({:.4e}, {:.4e}, {:.4e}): the sides of an n-sided patch must bound a disk \
             without touching away from their corners",
            p.x, p.y, p.z
        )));
    }
    Ok((size, gaps))
}

impl NSidedPatch {
    /// Solves the patch bounded by `sides` (in loop order, each ending where the next
    /// starts).
    pub fn solve(sides: Vec<Side>, options: &NSidedOptions) -> Result<NSidedPatch> {
        let n = sides.len();
        if !(3..=MAX_SIDES).contains(&n) {
            return Err(Error::invalid(format!(
                "an n-sided patch has 3 to {MAX_SIDES} sides, not {n}"
            )));
        }
        if !(1..=3).contains(&options.order) {
            return Err(Error::invalid(format!(
                "an n-sided patch takes order 1, 2 or 3, not {}",
                options.order
            )));
        }
        if !(options.a.is_finite() && options.a > 0.0) {
            return Err(Error::invalid(format!(
                "the smoothing parameter a must be finite and positive, not {}",
                options.a
            )));
        }
        if options.degree > basis::MAX_DEGREE {
            return Err(Error::invalid(format!(
                "the degree of an n-sided patch is 0 to 24, not {}",
                options.degree
            )));
        }
        if !(options.gap_tolerance.is_finite() && options.gap_tolerance >= 0.0) {
            return Err(Error::invalid("the gap tolerance must be finite and ≥ 0"));
        }
        for (i, s) in sides.iter().enumerate() {
            check_interval(&s.curve, s.t0, s.t1).map_err(|e| e.at(&format!("sides[{i}]")))?;
            if let Ribbon::Derivative { curve, t0, t1 } = &s.ribbon {
                check_interval(curve, *t0, *t1).map_err(|e| e.at(&format!("sides[{i}].ribbon")))?;
            }
            if let Ribbon::Derivatives {
                first,
                second,
                t0,
                t1,
            } = &s.ribbon
            {
                check_interval(first, *t0, *t1)
                    .map_err(|e| e.at(&format!("sides[{i}].ribbon.first")))?;
                check_interval(second, *t0, *t1)
                    .map_err(|e| e.at(&format!("sides[{i}].ribbon.second")))?;
            }
            let m = s.ribbon.multiplicity();
            if options.order == 1 && m > 1 {
                return Err(Error::invalid(
                    "order 1 (Laplace) takes positions only; a ribbon needs order 2",
                )
                .at(&format!("sides[{i}]")));
            }
            if options.order < 3 && m > 2 {
                return Err(Error::invalid(format!(
                    "a curvature ribbon (G2) needs order 3, not {}",
                    options.order
                ))
                .at(&format!("sides[{i}]")));
            }
            if m > 2 {
                check_c2(&s.curve, s.t0, s.t1).map_err(|e| e.at(&format!("sides[{i}].curve")))?;
            }
        }
        if options.order == 3 && sides.iter().all(|s| s.ribbon.multiplicity() == 1) {
            return Err(Error::invalid(
                "order 3 needs a ribbon (G1 or G2) on at least one side: with positions alone \
                 its energy does not fix the patch (use order 1 or 2)",
            ));
        }
        let (size, gaps) = boundary(&sides, options.gap_tolerance)?;
        let built: Vec<BuiltSide> = sides
            .iter()
            .map(|s| BuiltSide {
                side: s.clone(),
                ribbon: BuiltRibbon::Free([Vec3::zeros(); 4]),
                e: [Vec3::zeros(); 2],
                e_slope: [Vec3::zeros(); 2],
                f: [Vec3::zeros(); 2],
                curvature: BuiltCurvature::Free,
            })
            .collect();
        let corners: Vec<Corner> = gaps
            .into_iter()
            .map(|gap| Corner {
                gap,
                ..Corner::default()
            })
            .collect();
        let poly = Polygon::new(n);
        let mut patch = NSidedPatch {
            basis: Basis::new(&poly, vec![1; n], options.degree),
            poly,
            sides: built,
            options: options.clone(),
            coeffs: Vec::new(),
            size,
            corners,
            correction_bounds: OnceLock::new(),
            correction_data: OnceLock::new(),
        };
        patch.build_ribbons()?;
        let multiplicity: Vec<usize> = patch.sides.iter().map(BuiltSide::multiplicity).collect();
        patch.basis = Basis::new(&patch.poly, multiplicity, options.degree);
        patch.solve_coefficients();
        Ok(patch)
    }

    /// The corner-compatible cross derivative at the start (`end = false`) or end of side `i`:
    /// `−(L/c) P'_{i−1}(1)` and `(L/c) P'_{i+1}(0)`.
    fn corner_target(&self, i: usize, end: bool) -> Vec3 {
        let n = self.poly.n;
        let f = self.poly.side / self.poly.reach;
        if end {
            self.sides[(i + 1) % n].position(0.0)[1] * f
        } else {
            -self.sides[(i + n - 1) % n].position(1.0)[1] * f
        }
    }

    fn build_ribbons(&mut self) -> Result<()> {
        let n = self.poly.n;
        // The neighbours' normals as series, one side per task: the costly part of a re-solve
        // after an edit.
        type Fits = (Option<Box<ChebVec>>, Option<Box<ChebVec>>);
        let normals: Vec<Fits> = self
            .sides
            .par_iter()
            .enumerate()
            .map(|(i, side)| match &side.side.ribbon {
                Ribbon::TangentPlane(field) => fit_normal(field)
                    .map(|n| (Some(n), None))
                    .map_err(|e| e.at(&format!("sides[{i}].ribbon"))),
                Ribbon::Curvature { normal, shape } => {
                    let n = fit_normal(normal).map_err(|e| e.at(&format!("sides[{i}].ribbon")))?;
                    let k = fit_curvature(&side.side, normal, shape)
                        .map_err(|e| e.at(&format!("sides[{i}].ribbon")))?;
                    Ok((Some(n), Some(k)))
                }
                _ => Ok((None, None)),
            })
            .collect::<Result<_>>()?;
        for (i, (normal, curvature)) in normals.into_iter().enumerate() {
            let (t0, t1) = (self.corner_target(i, false), self.corner_target(i, true));
            self.sides[i].curvature = match (&self.sides[i].side.ribbon, curvature) {
                (_, Some(k)) => BuiltCurvature::Neighbour(k),
                (Ribbon::Derivatives { second, t0, t1, .. }, _) => BuiltCurvature::Explicit {
                    curve: second.clone(),
                    t0: *t0,
                    t1: *t1,
                },
                _ => BuiltCurvature::Free,
            };
            let explicit = match &self.sides[i].side.ribbon {
                Ribbon::Derivative { curve, t0, t1 }
                | Ribbon::Derivatives {
                    first: curve,
                    t0,
                    t1,
                    ..
                } => Some((curve.clone(), *t0, *t1)),
                _ => None,
            };
            let built = match (explicit, normal) {
                (Some((curve, t0, t1)), _) => {
                    for (end, k) in [(false, i), (true, (i + 1) % n)] {
                        let s = if end { 1.0 } else { 0.0 };
                        let mut d = [Vec3::zeros(); 1];
                        side::curve_jet(&curve, t0, t1, s, &mut d);
                        let plane = self.sides[i].position(s)[1].cross(&d[0]);
                        let t = self.corner_target(i, end);
                        let angle = std::f64::consts::FRAC_PI_2 - line_angle(plane, t);
                        let c = &mut self.corners[k];
                        c.tangent_mismatch = c.tangent_mismatch.max(angle.max(0.0));
                    }
                    BuiltRibbon::Derivative { curve, t0, t1 }
                }
                (_, Some(normal)) => {
                    let mut ab = [[0.0; 2]; 2];
                    for (e, (end, k)) in [(false, i), (true, (i + 1) % n)].into_iter().enumerate() {
                        let s = if end { 1.0 } else { 0.0 };
                        let tangent = self.sides[i].position(s)[1];
                        let m = normal.at(0, s).cross(&tangent);
                        let t = self.corner_target(i, end);
                        let a = t.dot(&m) / m.norm_squared();
                        let b = t.dot(&tangent) / tangent.norm_squared();
                        let fit = m * a + tangent * b;
                        let angle = line_angle(fit, t).min((t - fit).norm() / t.norm());
                        let c = &mut self.corners[k];
                        c.tangent_mismatch = c.tangent_mismatch.max(angle);
                        ab[e] = [a, b];
                    }
                    if ab[0][0] * ab[1][0] <= 0.0 || (ab[0][0] * ab[1][0]).is_nan() {
                        return Err(Error::invalid(format!(
                            "the adjacent sides leave the neighbour's tangent plane on \
                             opposite sides of this one at corners {i} and {} (a fold): check \
                             the loop's corners and the ribbon's surface",
                            (i + 1) % n
                        ))
                        .at(&format!("sides[{i}].ribbon")));
                    }
                    let (a0, a1, b0, b1) = (ab[0][0], ab[1][0], ab[0][1], ab[1][1]);
                    BuiltRibbon::Plane {
                        normal,
                        a: [a0, a1 - a0, a1, a1 - a0],
                        b: [b0, b1 - b0, b1, b1 - b0],
                    }
                }
                (_, None) => BuiltRibbon::Free([t0, t1 - t0, t1, t1 - t0]),
            };
            self.sides[i].ribbon = built;
        }
        self.match_corners();
        Ok(())
    }

    /// The second-order parts of the corner `k`: `H(R_k) − H(R_{k−1})` at `V_k` in the basis
    /// `g_a g_aᵀ`, `g_b g_bᵀ`, `g_a g_bᵀ + g_b g_aᵀ` (`g_a`, `g_b` the inward normals of sides
    /// `k − 1` and `k`), as `[A, B, M]`.
    fn corner_difference(&self, k: usize) -> [Vec3; 3] {
        let n = self.poly.n;
        let j = (k + n - 1) % n;
        let v = self.poly.verts[k];
        let d: Vec<Jet> = (0..n).map(|i| self.poly.distance_jet(i, v)).collect();
        let ribbon = |i: usize| {
            let (s, t) = Self::along(&self.poly, &d, i);
            self.ribbon_jet(i, s, t)
        };
        let (hk, hj) = (ribbon(k).h, ribbon(j).h);
        let (ga, gb) = (self.poly.normal(j), self.poly.normal(k));
        let m = nalgebra::Matrix3::new(
            ga[0] * ga[0],
            gb[0] * gb[0],
            2.0 * ga[0] * gb[0],
            ga[0] * ga[1],
            gb[0] * gb[1],
            ga[0] * gb[1] + ga[1] * gb[0],
            ga[1] * ga[1],
            gb[1] * gb[1],
            2.0 * ga[1] * gb[1],
        );
        let inv = m.try_inverse().unwrap_or_else(nalgebra::Matrix3::zeros);
        let delta = [hk[0] - hj[0], hk[1] - hj[1], hk[2] - hj[2]];
        [0, 1, 2].map(|r| delta[0] * inv[(r, 0)] + delta[1] * inv[(r, 1)] + delta[2] * inv[(r, 2)])
    }

    /// Makes neighbouring ribbons agree to second order at every corner where the data
    /// allow: the twists of free and plane ribbons take the mixed part (as far as a plane
    /// ribbon can: within its tangent plane), the second cross derivatives `E` the rest. What
    /// remains of the mixed part is the corner's twist mismatch.
    fn match_corners(&mut self) {
        let n = self.poly.n;
        let cl = self.poly.reach * self.poly.side;
        let l2 = self.poly.side * self.poly.side;
        for k in 0..n {
            let j = (k + n - 1) % n;
            let [_, _, m] = self.corner_difference(k);
            let delta = -m * cl;
            let free = |s: &BuiltSide| !matches!(s.ribbon, BuiltRibbon::Derivative { .. });
            let (fk, fj) = (free(&self.sides[k]), free(&self.sides[j]));
            let share = if fk && fj { 0.5 } else { 1.0 };
            if fk {
                self.sides[k].add_twist(false, delta * share);
            }
            if fj {
                self.sides[j].add_twist(true, delta * share);
            }
        }
        // The second cross derivatives: `E_k(0)` moves only the `g_b g_bᵀ` part of corner k
        // (by `2 E / L²`), `E_j(1)` only its `g_a g_aᵀ` part; where `E` carries a curvature
        // ribbon, only its tangential part moves.
        for k in 0..n {
            let j = (k + n - 1) % n;
            let [a, b, _] = self.corner_difference(k);
            self.sides[k].e[0] -= b * (0.5 * l2);
            self.sides[j].e[1] += a * (0.5 * l2);
        }
        for k in 0..n {
            let j = (k + n - 1) % n;
            let [a, b, m] = self.corner_difference(k);
            let (tk, tj) = (
                self.sides[k].position(0.0)[1],
                self.sides[j].position(1.0)[1],
            );
            let scale = tk.norm().max(tj.norm());
            self.corners[k].twist_mismatch = m.norm() * cl / scale;
            // The normal parts left: a normal curvature ≈ (N · A) / |X_d|², with |X_d| ≈ |P'| / L.
            let normal = tj.cross(&tk);
            let normal = normal / normal.norm();
            let left = normal.dot(&a).abs().max(normal.dot(&b).abs());
            self.corners[k].curvature_mismatch = left * l2 / (scale * scale) * self.size;
        }
        if self.options.order == 3 {
            self.match_third_order();
        }
    }

    /// The third-order parts of the corner `k`: the third partials of `R_k − R_{k−1}` at `V_k`
    /// as the coefficients of the cubics `a³, a²b, ab², b³` (`a = g_a · p`, `b = g_b · p`,
    /// `g_a`, `g_b` the inward normals of sides `k − 1` and `k`).
    fn corner_third(&self, k: usize) -> [Vec3; 4] {
        let n = self.poly.n;
        let j = (k + n - 1) % n;
        let v = self.poly.verts[k];
        let d: Vec<Jet<3>> = (0..n).map(|i| self.poly.distance_jet(i, v)).collect();
        let ribbon = |i: usize| {
            let (s, t) = Self::along(&self.poly, &d, i);
            self.ribbon_jet(i, s, t)
        };
        let (tk, tj) = (ribbon(k).t, ribbon(j).t);
        let a = Jet::<3>::affine(0.0, self.poly.normal(j));
        let b = Jet::<3>::affine(0.0, self.poly.normal(k));
        let cubics = [a * a * a, a * a * b, a * b * b, b * b * b];
        let m = nalgebra::Matrix4::from_fn(|r, c| cubics[c].t[r]);
        let inv = m.try_inverse().unwrap_or_else(nalgebra::Matrix4::zeros);
        let delta = [0, 1, 2, 3].map(|r| tk[r] - tj[r]);
        [0, 1, 2, 3].map(|c| (0..4).fold(Vec3::zeros(), |acc, r| acc + delta[r] * inv[(c, r)]))
    }

    /// Order 3: makes neighbouring ribbons agree to third order at every corner, so the
    /// interpolant is `C³` there (its blends `Π d_j⁴` vanish to fourth order): the cubic
    /// terms `t³ F` take the pure parts (`a³` by `F_{k−1}(1)`, `b³` by `F_k(0)`, each entering
    /// its ribbon as `F/L³`), the slopes of the second cross derivatives the mixed ones
    /// (`t_k² E_k(s_k)` has the cubic part `E_k'(0) a b² / (L² ρ)` near `V_k`, `s_k ≈ a/ρ`,
    /// `ρ` the reach; `E_{k−1}` the part `−E'_{k−1}(1) a² b / (L² ρ)`), as far as a curvature
    /// ribbon lets them (tangentially) and an explicit one not at all.
    fn match_third_order(&mut self) {
        let n = self.poly.n;
        let l = self.poly.side;
        let (l3, l2r) = (l * l * l, l * l * self.poly.reach);
        for k in 0..n {
            let j = (k + n - 1) % n;
            let [c0, c1, c2, c3] = self.corner_third(k);
            self.sides[j].f[1] += c0 * l3;
            self.sides[k].f[0] -= c3 * l3;
            if !matches!(self.sides[j].curvature, BuiltCurvature::Explicit { .. }) {
                self.sides[j].e_slope[1] -= c1 * l2r;
            }
            if !matches!(self.sides[k].curvature, BuiltCurvature::Explicit { .. }) {
                self.sides[k].e_slope[0] -= c2 * l2r;
            }
        }
    }

    fn solve_coefficients(&mut self) {
        let galerkin = Galerkin::get(&self.poly, &self.basis, self.options.order, self.options.a);
        let lc = match &galerkin.weights {
            Some(w) => self.operator_by_weights(&galerkin, w),
            None => self.operator_at_points(&galerkin),
        };
        self.coeffs = self.basis.by_a(&galerkin.solve(&lc));
    }

    /// The operator's components applied to the interpolant at the quadrature points of
    /// `galerkin` (`[point][component]`), each point's interpolant evaluated with its blends.
    fn operator_at_points(&self, galerkin: &Galerkin) -> Vec<Vec3> {
        let order = self.options.order;
        let a = self.options.a;
        let a2 = a * a;
        galerkin
            .points
            .par_iter()
            .flat_map_iter(|(p, _)| {
                if order == 3 {
                    let c = self.interpolant::<3>(*p);
                    return vec![c.t[0] + c.t[2] * a2, (c.t[1] + c.t[3] * a2) * a];
                }
                let c = self.interpolant::<2>(*p);
                if order == 1 {
                    vec![c.d[0], c.d[1] * a]
                } else {
                    vec![c.h[0] + c.h[2] * a2]
                }
            })
            .collect()
    }

    /// [`Self::operator_at_points`] from the sides' data and the operator's [`Weights`].
    fn operator_by_weights(&self, galerkin: &Galerkin, w: &Weights) -> Vec<Vec3> {
        let n = self.poly.n;
        let comps = galerkin.comps;
        let order = self.options.order;
        let at = |q: usize| -> [Vec3; 2] {
            let mut out = [Vec3::zeros(); 2];
            for (i, side) in self.sides.iter().enumerate() {
                let s = w.s[q * n + i];
                let data = if order == 3 {
                    side.data::<3>(s)
                } else {
                    side.data::<2>(s)
                };
                for (c, o) in out.iter_mut().enumerate().take(comps) {
                    let at = ((q * n + i) * comps + c) * w.stride;
                    let alpha = &w.alpha[at..at + w.stride];
                    for (f, a) in data.iter().zip(alpha.chunks_exact(w.derivatives)) {
                        for (x, a) in f.iter().zip(a) {
                            *o += x * *a;
                        }
                    }
                }
            }
            out
        };
        let per: Vec<[Vec3; 2]> = (0..galerkin.points.len()).into_par_iter().map(at).collect();
        per.iter()
            .flat_map(|o| o[..comps].iter().copied())
            .collect()
    }

    /// The number of sides.
    pub fn n(&self) -> usize {
        self.poly.n
    }

    /// The options the patch was solved with.
    pub fn options(&self) -> &NSidedOptions {
        &self.options
    }

    /// Per side, true if it carries a curvature ribbon (G2).
    pub fn g2_sides(&self) -> Vec<bool> {
        self.sides.iter().map(BuiltSide::has_curvature).collect()
    }

    /// The sides as given.
    pub fn sides(&self) -> impl Iterator<Item = &Side> {
        self.sides.iter().map(|s| &s.side)
    }

    /// The diagonal of the boundary's bounding box.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Side `i`'s ribbon `R_i = P_i(s_i) + t_i D_i(s_i) + t_i² E_i(s_i)` (`+ t_i³ F_i(s_i)` at
    /// order 3) given the jets of `s_i` and `t_i`, to order `O`.
    #[inline(always)]
    fn ribbon_jet<const O: usize>(&self, i: usize, s: Jet<O>, t: Jet<O>) -> VJet<O> {
        let side = &self.sides[i];
        let [p, r, e, f] = side.data::<O>(s.v);
        let t2 = t * t;
        let x = VJet::compose(s, p) + VJet::compose(s, r).times(t) + VJet::compose(s, e).times(t2);
        if self.options.order == 3 {
            x + VJet::compose(s, f).times(t2 * t)
        } else {
            x
        }
    }

    /// Per side `i` at the domain point `p`: the jets of the position along it
    /// `s_i = d_{i−1} / (d_{i−1} + d_{i+1})`, of the scaled distance `t_i = d_i / L` and of
    /// its blend `B_i = Π_{j≠i} d_j^q / Σ_k Π_{j≠k} d_j^q`. `q = 3` leaves the other blends
    /// vanishing with two cross derivatives on a side (enough up to G1, and the interpolant C²
    /// at the corners); order 3 takes `q = 4` (three cross derivatives for G2, and C³ at the
    /// corners).
    #[inline(always)]
    fn blends<const O: usize>(
        poly: &Polygon,
        order: usize,
        p: [f64; 2],
    ) -> [(Jet<O>, Jet<O>, Jet<O>); MAX_SIDES] {
        // On the stack: this runs at every evaluation.
        let n = poly.n;
        let mut d = [Jet::<O>::default(); MAX_SIDES];
        let mut cube = [Jet::<O>::default(); MAX_SIDES];
        let fourth = order == 3;
        for i in 0..n {
            d[i] = poly.distance_jet(i, p);
            cube[i] = d[i] * d[i] * d[i];
            if fourth {
                cube[i] = cube[i] * d[i];
            }
        }
        let mut pis = [Jet::<O>::constant(1.0); MAX_SIDES];
        for (i, pi) in pis.iter_mut().enumerate().take(n) {
            for (j, c) in cube.iter().enumerate().take(n) {
                if j != i {
                    *pi = *pi * *c;
                }
            }
        }
        let total = pis[..n].iter().fold(Jet::constant(0.0), |acc, x| acc + *x);
        let inv_total = total.recip();
        let mut out = [(
            Jet::<O>::default(),
            Jet::<O>::default(),
            Jet::<O>::default(),
        ); MAX_SIDES];
        for (i, o) in out.iter_mut().enumerate().take(n) {
            let (s, t) = Self::along(poly, &d[..n], i);
            *o = (s, t, pis[i] * inv_total);
        }
        out
    }

    /// Side `i`'s coordinates `s_i = d_{i−1} / (d_{i−1} + d_{i+1})` and `t_i = d_i / L` from
    /// the distance jets `d` of a point.
    #[inline(always)]
    fn along<const O: usize>(poly: &Polygon, d: &[Jet<O>], i: usize) -> (Jet<O>, Jet<O>) {
        let n = poly.n;
        let (dm, dp) = (d[(i + n - 1) % n], d[(i + 1) % n]);
        (dm.div(dm + dp), d[i].scale(1.0 / poly.side))
    }

    /// The boundary interpolant `C = Σ_i B_i R_i` at the domain point `p`.
    fn interpolant<const O: usize>(&self, p: [f64; 2]) -> VJet<O> {
        let blends = Self::blends::<O>(&self.poly, self.options.order, p);
        let mut c = VJet::default();
        for (i, &(s, t, b)) in blends[..self.poly.n].iter().enumerate() {
            c = c + self.ribbon_jet(i, s, t).times(b);
        }
        c
    }

    /// `X` and its partials in the domain coordinates at `p` (inside the polygon).
    fn eval_domain(&self, p: [f64; 2]) -> VJet {
        self.eval_domain_to::<2>(p)
    }

    /// `X` and its partials up to order `O ≤ 2` in the domain coordinates at `p` (inside the
    /// polygon): the interpolant plus the correction. Order 1 is what positions and normals
    /// need (the rows of a tessellation); its values are those of order 2's, to rounding.
    fn eval_domain_to<const O: usize>(&self, p: [f64; 2]) -> VJet<O> {
        if let Some(k) = self.poly.vertex_near(p, 1e-10) {
            // The blends are 0/0 at a corner: the position is the corner's; the derivatives
            // are their limits, taken a hair inside.
            let q = [p[0] * (1.0 - 1e-7), p[1] * (1.0 - 1e-7)];
            let mut x = self.eval_domain_to::<O>(q);
            x.v = self.sides[k].position(0.0)[0];
            return x;
        }
        self.interpolant::<O>(p) + self.basis.combine::<O>(&self.poly, p, &self.coeffs)
    }

    /// The surfaces that present the patch: one on the square for `n = 4`, else `n` pieces
    /// around the centre (piece `k` has side `k`'s first half at `v = 0` and side `k − 1`'s
    /// second half at `u = 0`).
    pub fn surfaces(self: &Arc<Self>) -> Vec<NSidedSurface> {
        if self.poly.n == 4 {
            vec![NSidedSurface {
                patch: self.clone(),
                piece: None,
            }]
        } else {
            (0..self.poly.n)
                .map(|k| NSidedSurface {
                    patch: self.clone(),
                    piece: Some(k),
                })
                .collect()
        }
    }

    /// The patch's point and unit normal at parameter `s` of side `i` (`s` inside `(0, 1)`).
    pub fn boundary_normal(&self, i: usize, s: f64) -> (Vec3, Vec3) {
        let x = self.eval_domain(self.poly.side_point(i, s));
        let n = x.d[0].cross(&x.d[1]);
        (x.v, n / n.norm())
    }

    /// The patch at parameter `s` of side `i` (`s` inside `(0, 1)`): its point, unit normal,
    /// the tangent `u` of the domain's line square to the side (the cross direction), and its
    /// normal curvature `N · X'' / |u|²` along that line.
    pub fn boundary_curvature(&self, i: usize, s: f64) -> (Vec3, Vec3, Vec3, f64) {
        let x = self.eval_domain(self.poly.side_point(i, s));
        let g = self.poly.normal(i);
        let u = x.d[0] * g[0] + x.d[1] * g[1];
        let xx = x.h[0] * (g[0] * g[0]) + x.h[1] * (2.0 * g[0] * g[1]) + x.h[2] * (g[1] * g[1]);
        let n = x.d[0].cross(&x.d[1]);
        let n = n / n.norm();
        (x.v, n, u, n.dot(&xx) / u.norm_squared())
    }

    /// Measures the patch along its boundary at `samples` points per side.
    pub fn report(&self, samples: usize) -> NSidedReport {
        let n = self.poly.n;
        let m = samples.max(2);
        let mut boundary = vec![0.0f64; n];
        let mut g1 = vec![None; n];
        let mut g2 = vec![None; n];
        for (i, side) in self.sides.iter().enumerate() {
            let mut worst: f64 = 0.0;
            let mut worst2: f64 = 0.0;
            let g = self.poly.normal(i);
            for j in 0..=m {
                let s = j as f64 / m as f64;
                let x = self.eval_domain(self.poly.side_point(i, s));
                boundary[i] = boundary[i].max((x.v - side.position(s)[0]).norm());
                if j == 0 || j == m || !side.has_ribbon() {
                    continue;
                }
                let normal = x.d[0].cross(&x.d[1]);
                let want = match &side.side.ribbon {
                    Ribbon::TangentPlane(f) => f(s),
                    Ribbon::Curvature { normal, .. } => normal(s),
                    _ => side.position(s)[1].cross(&side.ribbon(s)[0]),
                };
                worst = worst.max(line_angle(normal, want));
                if let Some((nt, shape)) = self.target_shape(i, s) {
                    // Normal curvatures along the domain's line across the side: the patch's
                    // `N · X''/|X'|²` and the target's `uᵀ S u / |u|²` at `u = X'`.
                    let u = x.d[0] * g[0] + x.d[1] * g[1];
                    let xx = x.h[0] * (g[0] * g[0])
                        + x.h[1] * (2.0 * g[0] * g[1])
                        + x.h[2] * (g[1] * g[1]);
                    let unit = normal / normal.norm();
                    let sign = if unit.dot(&nt) < 0.0 { -1.0 } else { 1.0 };
                    let patch = sign * unit.dot(&xx) / u.norm_squared();
                    let target = u.dot(&(shape * u)) / u.norm_squared();
                    worst2 = worst2.max((patch - target).abs() * self.size);
                }
            }
            if side.has_ribbon() {
                g1[i] = Some(worst);
            }
            if side.has_curvature() {
                g2[i] = Some(worst2);
            }
        }
        NSidedReport {
            size: self.size,
            boundary,
            g1,
            g2,
            corners: self.corners.clone(),
        }
    }

    /// The unit normal and second fundamental form (as a tensor, see [`ShapeField`]) that a
    /// curvature ribbon asks of the patch at `s` on side `i`, from the data as given (not
    /// their series).
    fn target_shape(&self, i: usize, s: f64) -> Option<(Vec3, nalgebra::Matrix3<f64>)> {
        match &self.sides[i].side.ribbon {
            Ribbon::Curvature { normal, shape } => {
                let n = normal(s);
                Some((n / n.norm(), shape(s)))
            }
            Ribbon::Derivatives {
                first,
                second,
                t0,
                t1,
            } => {
                let mut p = [Vec3::zeros(); 3];
                self.sides[i].side.jet(s, &mut p);
                let (mut d, mut w) = ([Vec3::zeros(); 2], [Vec3::zeros(); 1]);
                side::curve_jet(first, *t0, *t1, s, &mut d);
                side::curve_jet(second, *t0, *t1, s, &mut w);
                shape_tensor(&Partials {
                    x: p[0],
                    xu: p[1],
                    xv: d[0],
                    xuu: p[2],
                    xuv: d[1],
                    xvv: w[0],
                })
            }
            _ => None,
        }
    }
}

/// The unit normal `N = X_u × X_v / |…|` of a surface and its second fundamental form as the
/// symmetric tensor `S = J I⁻¹ II I⁻¹ Jᵀ` (`J = [X_u X_v]`, `I` and `II` the fundamental forms
/// in `(u, v)`, `II` against `N`), so that `II(w, w) = wᵀ S w` for every tangent vector `w`
/// (`w = J α` gives `αᵀ JᵀJ I⁻¹ II I⁻¹ JᵀJ α = αᵀ II α`, as `JᵀJ = I`). `None` where the
/// normal is undefined.
pub fn shape_tensor(p: &Partials) -> Option<(Vec3, nalgebra::Matrix3<f64>)> {
    let n = p.normal_or_none()?;
    let first = nalgebra::Matrix2::new(
        p.xu.dot(&p.xu),
        p.xu.dot(&p.xv),
        p.xu.dot(&p.xv),
        p.xv.dot(&p.xv),
    );
    let second = nalgebra::Matrix2::new(n.dot(&p.xuu), n.dot(&p.xuv), n.dot(&p.xuv), n.dot(&p.xvv));
    let inv = first.try_inverse()?;
    let j = nalgebra::Matrix3x2::from_columns(&[p.xu, p.xv]);
    let s = j * inv * second * inv * j.transpose();
    s.iter().all(|x| x.is_finite()).then_some((n, s))
}

/// `K = [II(m, m), II(m, P'), II(P', P')]` along a side with a curvature ribbon (`m = N × P'`,
/// `N` the unit normal), as a Chebyshev series; an error where the data are not finite.
fn fit_curvature(side: &Side, normal: &NormalField, shape: &ShapeField) -> Result<Box<ChebVec>> {
    let (side, normal, shape) = (side.clone(), normal.clone(), shape.clone());
    let k = move |s: f64| {
        let mut p = [Vec3::zeros(); 2];
        side.jet(s, &mut p);
        let n = normal(s);
        let n = n / n.norm();
        let m = n.cross(&p[1]);
        let sh = shape(s);
        Vec3::new(
            m.dot(&(sh * m)),
            m.dot(&(sh * p[1])),
            p[1].dot(&(sh * p[1])),
        )
    };
    for j in 0..=16 {
        if !k(j as f64 / 16.0).iter().all(|x| x.is_finite()) {
            return Err(Error::invalid(
                "the neighbour's curvature is undefined along the side",
            ));
        }
    }
    Ok(Box::new(ChebVec::fit(&k)))
}

/// An error if the curve's first or second derivative jumps inside `(t0, t1)` (at one of its
/// [`crate::curve::Curve::breaks`]): a curvature ribbon needs a side with a continuous
/// curvature.
fn check_c2(curve: &crate::curve::SharedCurve, t0: f64, t1: f64) -> Result<()> {
    let (lo, hi) = (t0.min(t1), t0.max(t1));
    let span = hi - lo;
    let eps = 1e-9 * span.max(1e-300);
    for b in curve.breaks() {
        if !(b > lo + 2.0 * eps && b < hi - 2.0 * eps) {
            continue;
        }
        let (mut l, mut r) = ([Vec3::zeros(); 3], [Vec3::zeros(); 3]);
        curve.jet(b - eps, &mut l);
        curve.jet(b + eps, &mut r);
        let speed = l[1].norm().max(r[1].norm());
        for k in 1..=2 {
            let jump = (r[k] - l[k]).norm();
            let size = l[k]
                .norm()
                .max(r[k].norm())
                .max(speed / span.powi(k as i32 - 1));
            if jump > 1e-6 * size {
                return Err(Error::invalid(format!(
                    "the curve's {} derivative jumps at t = {b} (a break of its kind): a \
                     curvature ribbon (G2) needs a side whose curve has a continuous second \
                     derivative",
                    if k == 1 { "first" } else { "second" }
                )));
            }
        }
    }
    Ok(())
}

/// The unit normal field of a tangent-plane ribbon as a Chebyshev series, of the field's
/// direction where the field's own series is short ([`ChebVec::fit_unit`]); an error where
/// the field vanishes or is not finite.
fn fit_normal(field: &NormalField) -> Result<Box<ChebVec>> {
    let unit = |s: f64| {
        let v = field(s);
        let l = v.norm();
        if l > 0.0 && l.is_finite() {
            v / l
        } else {
            Vec3::repeat(f64::NAN)
        }
    };
    for j in 0..=16 {
        if !unit(j as f64 / 16.0).iter().all(|x| x.is_finite()) {
            return Err(Error::invalid(
                "the neighbour's normal is undefined along the side",
            ));
        }
    }
    Ok(Box::new(
        ChebVec::fit_unit(&|s| field(s)).unwrap_or_else(|| ChebVec::fit(&unit)),
    ))
}

fn check_interval(curve: &crate::curve::SharedCurve, t0: f64, t1: f64) -> Result<()> {
    if !(t0.is_finite() && t1.is_finite()) || t0 == t1 {
        return Err(Error::invalid(format!(
            "the parameter interval [{t0}, {t1}] must be finite and not empty"
        )));
    }
    if let crate::curve::Domain::Interval(a, b) = curve.domain() {
        let slack = 1e-12 * (b - a).abs().max(1.0);
        for t in [t0, t1] {
            if t < a - slack || t > b + slack {
                return Err(Error::invalid(format!(
                    "the parameter {t} lies outside the curve's domain [{a}, {b}]"
                )));
            }
        }
    }
    Ok(())
}

/// An n-sided patch as a [`Surface`] on `[0, 1]²`: the whole square for `n = 4`, or one of
/// the `n` pieces around the centre.
#[derive(Clone, Debug)]
pub struct NSidedSurface {
    patch: Arc<NSidedPatch>,
    piece: Option<usize>,
}

impl NSidedSurface {
    /// The domain point of `(u, v)` with `∂/∂u`, `∂/∂v` and `∂²/∂u∂v` of the map (see
    /// [`Polygon::piece`]; for `n = 4` the square is `[−r, r]²` scaled from `[0, 1]²`).
    fn domain_map(&self, u: f64, v: f64) -> [[f64; 2]; 4] {
        match self.piece {
            Some(k) => self.patch.poly.piece(k, u, v),
            None => {
                let r = std::f64::consts::FRAC_1_SQRT_2;
                let w = 2.0 * r;
                [[-r + w * u, -r + w * v], [w, 0.0], [0.0, w], [0.0, 0.0]]
            }
        }
    }

    /// The patch this surface presents.
    pub fn patch(&self) -> &Arc<NSidedPatch> {
        &self.patch
    }

    /// The piece (`None`: the whole square of a four-sided patch).
    pub fn piece(&self) -> Option<usize> {
        self.piece
    }
}

impl Surface for NSidedSurface {
    fn v_domain(&self) -> VDomain {
        VDomain::Interval(0.0, 1.0)
    }

    /// Panels graded geometrically towards the polygon's corners (`(0, 0)` of a piece, every
    /// corner of the square): there the blends leave third derivatives that jump, and graded
    /// panels keep the quadratures of area and curvature converging at their full order.
    fn breaks(&self) -> (Vec<f64>, Vec<f64>) {
        let near: Vec<f64> = CORNER_GRADING.to_vec();
        let both: Vec<f64> = CORNER_GRADING
            .iter()
            .copied()
            .chain(CORNER_GRADING.iter().rev().map(|t| 1.0 - t))
            .collect();
        match self.piece {
            Some(_) => (near.clone(), near),
            None => (both.clone(), both),
        }
    }

    /// Positions and normals from first-order jets (see the `rows` module): the rows of a
    /// tessellation pay neither for second derivatives nor for allocations.
    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(rows::Rows::new(self, vs))
    }

    /// From first-order jets (`eval_domain_to::<1>`): the operations of
    /// [`Surface::partials`] without the second-order ones.
    fn first_partials(&self, u: f64, v: f64) -> [Vec3; 3] {
        let [p, pu, pv, _] = self.domain_map(u, v);
        let x = self.patch.eval_domain_to::<1>(p);
        let d = |q: [f64; 2]| x.d[0] * q[0] + x.d[1] * q[1];
        [x.v, d(pu), d(pv)]
    }

    fn first_partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn FirstPartialsRows + 'a> {
        Box::new(PointwiseFirstPartials { surface: self, vs })
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let [p, pu, pv, puv] = self.domain_map(u, v);
        let x = self.patch.eval_domain(p);
        let d = |q: [f64; 2]| x.d[0] * q[0] + x.d[1] * q[1];
        let h = |a: [f64; 2], b: [f64; 2]| {
            x.h[0] * (a[0] * b[0]) + x.h[1] * (a[0] * b[1] + a[1] * b[0]) + x.h[2] * (a[1] * b[1])
        };
        Partials {
            x: x.v,
            xu: d(pu),
            xv: d(pv),
            xuu: h(pu, pu),
            xuv: h(pu, pv) + d(puv),
            xvv: h(pv, pv),
        }
    }
}
