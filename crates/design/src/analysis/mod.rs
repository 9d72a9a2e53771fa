//! Surface analysis: differential geometry from exact partials (book §1.4.1.1) and the integrals
//! of chapter 7 — area, enclosed volume, `∫H dA`, `∫H² dA`, `∫K dA` and the energies built from
//! them (bending energy `∫(κ₁² + κ₂²) dA` of §7.5, the Willmore energy, the Canham–Helfrich
//! vesicle energy of §7.5.2 with its reduced volume `ν` and reduced spontaneous curvature `c₀`).
//!
//! Quadrature: composite Gauss–Legendre in `u` (and in an interval `v`), the trapezoid rule in a
//! periodic `v`; both converge fast on smooth integrands, and [`Quadrature`] refines until two
//! successive levels agree to a tolerance. `u` runs over the surface's `u` range
//! ([`Surface::u_range`]). Gauss nodes are interior, so a pole at either end of it (where
//! `X_u × X_v = 0`) is never evaluated.

mod design;
mod geometry;
mod quadrature;
mod sensitivity;
mod trimmed;

pub use design::{
    integrate_design, integrate_design_keeping, integrate_surfaces, Cap, DesignIntegrals,
    NodePartials,
};
pub use geometry::{curvature, curvature_at, Curvature, FundamentalForms};
#[cfg(test)]
pub(crate) use quadrature::gauss_legendre;
pub use sensitivity::{
    integrals_derivative, integrals_derivatives, integrals_derivatives_at, PatchTangent,
};
pub use trimmed::{integrate_trimmed, integrate_trimmed_design, TrimmedIntegrals};

use crate::surface::{Interval, Partials, Surface, VDomain};
use crate::{Error, Result, Vec3};
use quadrature::{composite_gauss, periodic_trapezoid, Rule};
use rayon::prelude::*;

/// The integrals of a surface (or of a whole design), all over the area element
/// `dA = |X_u × X_v| du dv`, with `H` taken with respect to the surface's normal (see
/// [`curvature`] for the sign convention; for a design, the outward normal).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integrals {
    /// `A = ∫ dA`.
    pub area: f64,
    /// `(1/3) ∫ X·n dA`: this surface's share of the enclosed volume by the divergence theorem
    /// (`V = (1/3)∮ X·n dA` over a closed surface with outward `n`). For a design's total,
    /// the enclosed volume (open boundaries closed by caps, see [`integrate_design`]).
    pub volume: f64,
    /// `∫ H dA`.
    pub mean: f64,
    /// `∫ H² dA`.
    pub mean_sq: f64,
    /// `∫ K dA` (`2πχ` for a closed surface, by Gauss–Bonnet).
    pub gauss: f64,
}

impl Integrals {
    /// The bending energy `∫(κ₁² + κ₂²) dA = ∫(4H² − 2K) dA` (§7.5).
    pub fn bending_energy(&self) -> f64 {
        4.0 * self.mean_sq - 2.0 * self.gauss
    }

    /// The Willmore energy `∫(2H)² dA = ∫(κ₁ + κ₂)² dA` (`16π` for every sphere).
    pub fn willmore(&self) -> f64 {
        4.0 * self.mean_sq
    }

    /// The Canham–Helfrich bending energy `∫(C₁ + C₂ − C₀)² dA` (the corrected Eq. 7.8: the
    /// printed equation lost the square). The membrane curvatures `C₁, C₂` are positive for a
    /// sphere: with the outward normal of a design, `C₁ + C₂ = −2H` (see [`curvature`]), so the
    /// value is `∫(2H + C₀)² dA = 4∫H² + 4C₀∫H + C₀²A`. It vanishes for a sphere of radius
    /// `2/C₀`; for `C₀ = 0` it is [`Self::willmore`].
    pub fn helfrich(&self, c0: f64) -> f64 {
        4.0 * self.mean_sq + 4.0 * c0 * self.mean + c0 * c0 * self.area
    }

    /// The vesicle energy of Eq. 7.8 with the squares restored and a coefficient on the
    /// Gaussian term: `∫(C₁ + C₂ − C₀)² dA + k_G ∫C₁C₂ dA` ([`Self::helfrich`] plus
    /// `k_G ∫K dA`; the book's Eq. 7.8 has `k_G = 1`). The Gaussian term is the topological
    /// constant `4πk_G` for every closed surface of genus 0.
    pub fn vesicle_energy(&self, c0: f64, k_gauss: f64) -> f64 {
        self.helfrich(c0) + k_gauss * self.gauss
    }

    /// The radius of the sphere of the same area, `R₀ = √(A/4π)` (the corrected definition
    /// under Eq. 7.10, which prints `√(4πA)`).
    pub fn equivalent_radius(&self) -> f64 {
        (self.area / (4.0 * std::f64::consts::PI)).sqrt()
    }

    /// The reduced volume `ν = V / ((4π/3) R₀³)` (Eq. 7.9 with `R₀ = √(A/4π)`): 1 for a sphere,
    /// less for every other closed surface.
    pub fn reduced_volume(&self) -> f64 {
        let r0 = self.equivalent_radius();
        self.volume / (4.0 * std::f64::consts::PI / 3.0 * r0 * r0 * r0)
    }

    /// The reduced spontaneous curvature `c₀ = C₀ R₀` (Eq. 7.10).
    pub fn reduced_spontaneous_curvature(&self, c0: f64) -> f64 {
        c0 * self.equivalent_radius()
    }

    /// The same integrals with the normal reversed: `volume` and `mean` change sign.
    pub fn reversed(&self) -> Integrals {
        Integrals {
            volume: -self.volume,
            mean: -self.mean,
            ..*self
        }
    }

    fn add(&mut self, o: &Integrals) {
        self.area += o.area;
        self.volume += o.volume;
        self.mean += o.mean;
        self.mean_sq += o.mean_sq;
        self.gauss += o.gauss;
    }
}

/// How integrals are computed.
///
/// `u` (and an interval `v`) use composite Gauss–Legendre with [`Self::order`] nodes per panel:
/// exact for polynomials of degree `2·order − 1`, so halving the panels divides the error of a
/// smooth integrand by about `2^(2·order)` (`6.6·10⁴` for the default order 8, which reaches
/// `10⁻¹⁰` with few panels without the ill-conditioning of very high orders). A periodic `v` uses
/// the trapezoid rule, which is spectrally accurate there.
///
/// Adaptive (the default): levels `k = 0, 1, …` use `u_panels·2^k` panels and `v_nodes·2^k`
/// periodic nodes (`v_panels·2^k` panels on an interval); refinement stops when every integral
/// changed by at most `tolerance` relative to its scale between two levels (scales: `A` for the
/// area, `max(|V|, A^{3/2})` for the volume, `max(∫(κ₁² + κ₂²) dA, 10⁻⁶)` for `∫H²` and `∫K`,
/// `√(A·max(∫(κ₁²+κ₂²), 10⁻⁶))` for `∫H`), or when the next level would exceed `max_nodes`.
/// The finer level's values are returned; the last change is the reported error estimate (for
/// fast-converging rules it bounds the error of the coarser level, so it is pessimistic).
///
/// Fixed (`adaptive = false`): one level with exactly the given numbers of panels and nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadrature {
    /// Gauss–Legendre nodes per panel, 1 to 64 (default 8).
    pub order: usize,
    /// Panels in `u` at the first level (default 2).
    pub u_panels: usize,
    /// Trapezoid nodes of a periodic `v` at the first level (default 32).
    pub v_nodes: usize,
    /// Panels of an interval `v` at the first level (default 2).
    pub v_panels: usize,
    /// Relative tolerance of the adaptive refinement (default 10⁻¹¹, so that the returned finer
    /// level is accurate to about 10⁻¹⁰ or better).
    pub tolerance: f64,
    /// Refine until converged (default true).
    pub adaptive: bool,
    /// Most quadrature nodes of one level (default 2²²).
    pub max_nodes: usize,
}

impl Default for Quadrature {
    fn default() -> Self {
        Quadrature {
            order: 8,
            u_panels: 2,
            v_nodes: 32,
            v_panels: 2,
            tolerance: 1e-11,
            adaptive: true,
            max_nodes: 1 << 22,
        }
    }
}

impl Quadrature {
    /// One fixed level: `u_nodes` Gauss nodes in `u` (a multiple of `order` = 8) and `v_nodes`
    /// nodes in `v` (trapezoid when periodic; Gauss panels of 8 on an interval).
    pub fn fixed(u_nodes: usize, v_nodes: usize) -> Self {
        Quadrature {
            u_panels: u_nodes.div_ceil(8).max(1),
            v_nodes: v_nodes.max(1),
            v_panels: v_nodes.div_ceil(8).max(1),
            adaptive: false,
            ..Default::default()
        }
    }

    fn check(&self) -> Result<()> {
        if !(1..=64).contains(&self.order) {
            return Err(
                Error::invalid(format!("must be between 1 and 64 (got {})", self.order))
                    .at("quadrature.order"),
            );
        }
        for (name, n) in [
            ("u_panels", self.u_panels),
            ("v_nodes", self.v_nodes),
            ("v_panels", self.v_panels),
        ] {
            if n == 0 {
                return Err(Error::invalid("must be at least 1").at(&format!("quadrature.{name}")));
            }
        }
        if !(self.tolerance > 0.0 && self.tolerance.is_finite()) {
            return Err(Error::invalid(format!(
                "must be positive and finite (got {})",
                self.tolerance
            ))
            .at("quadrature.tolerance"));
        }
        Ok(())
    }

    /// The rules of level `k` over the `u` range and the `v` domain. Where the surface has
    /// breaks ([`Surface::breaks`]), the panels are shared out among the smooth pieces
    /// between them (at least one each) so that no panel straddles a break.
    fn rules(
        &self,
        u: Interval,
        domain: VDomain,
        breaks: &(Vec<f64>, Vec<f64>),
        k: u32,
    ) -> (Rule, Rule) {
        let f = 1usize << k;
        let ru = pieces_gauss(u.start, u.end, &breaks.0, self.u_panels * f, self.order);
        let rv = match domain {
            VDomain::Periodic => periodic_trapezoid(self.v_nodes * f),
            VDomain::Interval(a, b) => pieces_gauss(a, b, &breaks.1, self.v_panels * f, self.order),
        };
        (ru, rv)
    }
}

/// Composite Gauss–Legendre on `[a, b]`: `panels` equal panels if no break lies inside,
/// otherwise `⌈panels / pieces⌉` equal panels on each piece between consecutive breaks.
fn pieces_gauss(a: f64, b: f64, breaks: &[f64], panels: usize, order: usize) -> Rule {
    let mut cuts: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|&x| x.is_finite() && x > a && x < b)
        .collect();
    if cuts.is_empty() {
        return composite_gauss(a, b, panels, order);
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let per_piece = panels.div_ceil(cuts.len() + 1).max(1);
    let ends: Vec<f64> = std::iter::once(a)
        .chain(cuts)
        .chain(std::iter::once(b))
        .collect();
    let mut rule = Rule {
        nodes: Vec::new(),
        weights: Vec::new(),
    };
    for w in ends.windows(2) {
        let r = composite_gauss(w[0], w[1], per_piece, order);
        rule.nodes.extend(r.nodes);
        rule.weights.extend(r.weights);
    }
    rule
}

/// Integrals of one surface with what the quadrature learned on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceAnalysis {
    /// Area, volume share and curvature integrals of the final level.
    pub integrals: Integrals,
    /// `(min, max)` of the Gaussian curvature `K` at the non-degenerate quadrature nodes of
    /// the final level (`(+∞, −∞)` if there is none).
    pub gauss_range: (f64, f64),
    /// `(min, max)` of the mean curvature `H` (with respect to `X_u × X_v`) at the same nodes.
    pub mean_range: (f64, f64),
    /// The estimated relative error (see [`Quadrature`]); 0 for a fixed rule.
    pub error: f64,
    /// The adaptive refinement met the tolerance (always true for a fixed rule).
    pub converged: bool,
    /// Nodes of the final level in `u`.
    pub u_nodes: usize,
    /// Nodes of the final level in `v`.
    pub v_nodes: usize,
    /// Interior nodes where the parametrisation was degenerate (`X_u × X_v ≈ 0`); they add to
    /// no integral.
    pub degenerate_nodes: usize,
}

/// Sums over one grid.
#[derive(Clone, Copy, Debug)]
struct Sums {
    i: Integrals,
    gauss_range: (f64, f64),
    mean_range: (f64, f64),
    degenerate: usize,
    nonfinite: bool,
    /// The bounding box of `X` at the nodes (lower and upper corners): the surface's size, for
    /// the scales of [`relative_change`].
    lo: Vec3,
    hi: Vec3,
    /// Nodes summed.
    nodes: usize,
}

impl Default for Sums {
    fn default() -> Self {
        Sums {
            i: Integrals::default(),
            gauss_range: (f64::INFINITY, f64::NEG_INFINITY),
            mean_range: (f64::INFINITY, f64::NEG_INFINITY),
            degenerate: 0,
            nonfinite: false,
            lo: Vec3::repeat(f64::INFINITY),
            hi: Vec3::repeat(f64::NEG_INFINITY),
            nodes: 0,
        }
    }
}

impl Sums {
    fn merge(&mut self, o: &Sums) {
        self.i.add(&o.i);
        self.gauss_range = (
            self.gauss_range.0.min(o.gauss_range.0),
            self.gauss_range.1.max(o.gauss_range.1),
        );
        self.mean_range = (
            self.mean_range.0.min(o.mean_range.0),
            self.mean_range.1.max(o.mean_range.1),
        );
        self.degenerate += o.degenerate;
        self.nonfinite |= o.nonfinite;
        self.lo = self.lo.inf(&o.lo);
        self.hi = self.hi.sup(&o.hi);
        self.nodes += o.nodes;
    }

    /// The largest side of the bounding box (0 for no node).
    fn extent(&self) -> f64 {
        (self.hi - self.lo).max().max(0.0)
    }

    /// Every node was degenerate (`X_u × X_v ≈ 0`): the surface is a curve or a point.
    fn all_degenerate(&self) -> bool {
        self.nodes > 0 && self.degenerate == self.nodes
    }
}

/// Adds the integrands at one node with weight `w`.
#[inline]
fn accumulate(p: &Partials, w: f64, s: &mut Sums) {
    let cross = p.xu.cross(&p.xv);
    if !(cross.iter().all(|c| c.is_finite()) && p.x.iter().all(|c| c.is_finite())) {
        s.nonfinite = true;
        return;
    }
    s.nodes += 1;
    s.lo = s.lo.inf(&p.x);
    s.hi = s.hi.sup(&p.x);
    // Volume: (1/3) X·(X_u × X_v) du dv, defined even where the normal is not.
    s.i.volume += w * p.x.dot(&cross) / 3.0;
    let Some(c) = geometry::core(p) else {
        s.degenerate += 1;
        return;
    };
    let wa = w * c.jac;
    s.i.area += wa;
    s.i.mean += wa * c.mean;
    s.i.mean_sq += wa * c.mean * c.mean;
    s.i.gauss += wa * c.gauss;
    s.gauss_range = (s.gauss_range.0.min(c.gauss), s.gauss_range.1.max(c.gauss));
    s.mean_range = (s.mean_range.0.min(c.mean), s.mean_range.1.max(c.mean));
}

/// One level: rows in parallel, summed in row order (the result does not depend on the
/// number of threads); with `keep`, the partials of every row too, for a pass that needs them
/// again at the same nodes (a derivative's adjoint): `rows[a][b]` at `(u_a, v_b)`.
fn integrate_grid(s: &dyn Surface, ru: &Rule, rv: &Rule, keep: bool) -> (Sums, Option<NodeRows>) {
    let eval = s.partials_rows(&rv.nodes);
    let rows: Vec<(Sums, Option<Vec<Partials>>)> = ru
        .nodes
        .par_iter()
        .zip(&ru.weights)
        .map_init(
            || vec![Partials::default(); rv.nodes.len()],
            |buf, (&u, &wu)| {
                eval.eval_row(u, buf);
                let mut sums = Sums::default();
                for (p, &wv) in buf.iter().zip(&rv.weights) {
                    accumulate(p, wu * wv, &mut sums);
                }
                (sums, keep.then(|| buf.clone()))
            },
        )
        .collect();
    let mut total = Sums::default();
    for (r, _) in &rows {
        total.merge(r);
    }
    let kept = keep.then(|| rows.into_iter().filter_map(|(_, p)| p).collect());
    (total, kept)
}

/// The largest change between two levels relative to each integral's scale (see
/// [`Quadrature`]). `extent` is the surface's size `L` (the largest side of its bounding box):
/// the area's scale is at least `10⁻⁶L²` and the volume's `10⁻⁶L³`, so that a nearly
/// degenerate sliver converges instead of refining its rounding residue to the node budget.
fn relative_change(a: &Integrals, b: &Integrals, extent: f64) -> f64 {
    let l = if extent.is_finite() { extent } else { 0.0 };
    let area = b.area.abs().max(1e-6 * l * l).max(f64::MIN_POSITIVE);
    let energy = (4.0 * b.mean_sq.abs() + 2.0 * b.gauss.abs()).max(1e-6);
    let changes = [
        (a.area - b.area).abs() / area,
        (a.volume - b.volume).abs() / b.volume.abs().max(area.powf(1.5)).max(1e-6 * l * l * l),
        (a.mean - b.mean).abs() / (area * energy).sqrt(),
        (a.mean_sq - b.mean_sq).abs() / energy,
        (a.gauss - b.gauss).abs() / energy,
    ];
    changes
        .into_iter()
        .fold(0.0, |m, c| if c.is_nan() { c } else { m.max(c) })
}

/// The integrals of `s` over its `u` range ([`Surface::u_range`], `[0, 1]` for nearly every
/// surface) and its `v` domain (see [`analyze_surface`]).
pub fn integrate_surface(s: &dyn Surface, q: &Quadrature) -> Result<Integrals> {
    analyze_surface(s, q).map(|a| a.integrals)
}

/// Integrals of `s` with the curvature ranges and the quadrature's error estimate. The normal is
/// `X_u × X_v / |X_u × X_v|`. Fails if the surface gives a non-finite value at a node, or for
/// quadrature settings out of range.
pub fn analyze_surface(s: &dyn Surface, q: &Quadrature) -> Result<SurfaceAnalysis> {
    analyze_surface_keeping(s, q, false).map(|(a, _)| a)
}

/// The partials of a surface at the nodes of its quadrature's last level, row by row
/// (`rows[a][b]` at `(u_a, v_b)`), as the integrals evaluated them.
pub(crate) type NodeRows = Vec<Vec<Partials>>;

/// [`analyze_surface`], with the partials at the nodes of the level it ends at kept (`keep`).
pub(crate) fn analyze_surface_keeping(
    s: &dyn Surface,
    q: &Quadrature,
    keep: bool,
) -> Result<(SurfaceAnalysis, Option<NodeRows>)> {
    q.check()?;
    let domain = s.v_domain();
    let u_range = s.u_range();
    if !u_range.is_valid() {
        return Err(Error::invalid(format!(
            "the surface's u range [{}, {}] is not a finite interval",
            u_range.start, u_range.end
        )));
    }
    if let VDomain::Interval(a, b) = domain {
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(Error::invalid(format!(
                "the surface's v domain [{a}, {b}] is not a finite interval"
            )));
        }
    }
    let finish = |(sums, kept): (Sums, Option<NodeRows>),
                  ru: &Rule,
                  rv: &Rule,
                  error: f64,
                  converged: bool| {
        if sums.nonfinite {
            return Err(Error::invalid(
                "the surface is not finite at some quadrature node (NaN or infinite partials)",
            ));
        }
        let analysis = SurfaceAnalysis {
            integrals: sums.i,
            gauss_range: sums.gauss_range,
            mean_range: sums.mean_range,
            error,
            converged,
            u_nodes: ru.nodes.len(),
            v_nodes: rv.nodes.len(),
            degenerate_nodes: sums.degenerate,
        };
        Ok((analysis, kept))
    };
    let breaks = s.breaks();
    let (ru, rv) = q.rules(u_range, domain, &breaks, 0);
    level_memory(&ru, &rv)?;
    let mut prev = integrate_grid(s, &ru, &rv, keep);
    let mut prev_rules = (ru, rv);
    if !q.adaptive {
        return finish(prev, &prev_rules.0, &prev_rules.1, 0.0, true);
    }
    if prev.0.nonfinite {
        return finish(prev, &prev_rules.0, &prev_rules.1, f64::NAN, false);
    }
    let mut k = 1;
    loop {
        let (ru, rv) = q.rules(u_range, domain, &breaks, k);
        // A level beyond the memory budget ends the refinement, like the node budget.
        if level_memory(&ru, &rv).is_err() {
            return finish(prev, &prev_rules.0, &prev_rules.1, f64::NAN, false);
        }
        let cur = integrate_grid(s, &ru, &rv, keep);
        // A surface degenerate at every node of two levels (a curve) has no area to refine.
        let flat = prev.0.all_degenerate() && cur.0.all_degenerate();
        let change = if flat {
            0.0
        } else {
            relative_change(&prev.0.i, &cur.0.i, cur.0.extent())
        };
        let converged = change <= q.tolerance;
        let (nu2, nv2) = (2 * ru.nodes.len(), 2 * rv.nodes.len());
        if converged || cur.0.nonfinite || nu2.saturating_mul(nv2) > q.max_nodes {
            return finish(cur, &ru, &rv, change, converged);
        }
        prev = cur;
        prev_rules = (ru, rv);
        k += 1;
    }
}

/// Refuses a quadrature level whose memory ([`crate::memory::quadrature_level`], with the
/// workers of the current thread pool) is above the budget, at the place `quadrature`.
fn level_memory(ru: &Rule, rv: &Rule) -> Result<()> {
    let (nu, nv) = (ru.nodes.len(), rv.nodes.len());
    crate::memory::check(
        crate::memory::quadrature_level(nu as u64, nv as u64, rayon::current_num_threads() as u64),
        &format!("a quadrature of {nu} × {nv} nodes"),
        "quadrature",
    )
}

/// `K` and `H` (with respect to `X_u × X_v`) at every grid point `(u_i, v_j)`, row-major
/// (`i·vs.len() + j`), from the surface's rows of partials; at degenerate points (poles) the
/// limit of [`curvature_at`], NaN where even that fails.
pub fn curvature_grid(s: &dyn Surface, us: &[f64], vs: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let eval = s.partials_rows(vs);
    let rows: Vec<(Vec<f64>, Vec<f64>)> =
        us.par_iter()
            .map(|&u| {
                let mut buf = vec![Partials::default(); vs.len()];
                eval.eval_row(u, &mut buf);
                buf.iter()
                    .zip(vs)
                    .map(|(p, &v)| match geometry::core(p) {
                        Some(c) => (c.gauss, c.mean),
                        None => curvature_at(s, u, v)
                            .map_or((f64::NAN, f64::NAN), |c| (c.gauss, c.mean)),
                    })
                    .unzip()
            })
            .collect();
    let mut k = Vec::with_capacity(us.len() * vs.len());
    let mut h = Vec::with_capacity(us.len() * vs.len());
    for (rk, rh) in rows {
        k.extend(rk);
        h.extend(rh);
    }
    (k, h)
}

#[cfg(test)]
mod tests;
