//! Attached patches (§5.2.1): condition curves that lie on another patch of the design.
//!
//! An `on_patch` curve is the image `C(s) = X_h(u(s), v(s))` on a host patch `X_h` of a closed
//! curve `c(t) = (u, v)(t)` of that patch's parameter plane, `t = s/2π` (so the attached patch's
//! `v` is `s`). A `tangent_field` curve is the derivative condition that goes with it: the unit
//! vector of the host's tangent plane across the curve, `D = −σ·scale·(C' × N)/|C' × N|` with
//! `N = X_u × X_v` of the host and `σ = ±1` the orientation of `c` in the `(u, v)` plane, which
//! points into the trimmed hole (the host continued across the curve). A patch with the position
//! `C` and the derivative `D` at one end meets the host with a common tangent plane (G1).
//!
//! Host patches are solved first, then the curves on them, then the patches that use those
//! curves ([`patch_levels`]; a cycle is refused). The host is trimmed inside every `on_patch`
//! curve with `trim = true` ([`add_attachment_trims`]), and [`SolvedDesign::attachment_reports`]
//! measures G0/G1 along every attachment independently of this construction: the attached
//! patch's end is projected onto the host by the closest-point search.

use super::solved::{DesignSurface, SolvedDesign, SurfaceKind};
use super::trim::{trim_curve, SurfaceTrim, TrimChecks};
use super::validate::{curve_place, plan, references};
use crate::curve::{Curve, Domain};
use crate::spec::{CurveKind, CurveRef, CurveSpec, DesignSpec};
use crate::surface::{ClosestOptions, ClosestPointIndex, Partials, Surface};
use crate::trim::{TrimCurve, TrimMethod};
use crate::{Error, Result, Vec3, TAU};
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

mod bounds;

/// `ds/dt` of the attached patch's `v = s = 2π t`.
const W: f64 = TAU;

/// The host's partials at a point of the `(u, v)` curve (`v` reduced to `[0, 2π)` on a periodic
/// host) and the curve's derivatives in `s`.
fn host_jet(host: &dyn Surface, path: &TrimCurve, s: f64) -> (Partials, [f64; 2], [f64; 2]) {
    let t = s / W;
    let [p, d1, d2] = path.jet(t);
    let pt = host.partials(p[0], host_v(host, p[1]));
    (
        pt,
        [d1[0] / W, d1[1] / W],
        [d2[0] / (W * W), d2[1] / (W * W)],
    )
}

/// The point of the image curve at `s` ([`host_jet`]'s position: the path's point is its jet's
/// first entry).
fn host_point(host: &dyn Surface, path: &TrimCurve, s: f64) -> Vec3 {
    let [u, v] = path.point(s / W);
    host.point(u, host_v(host, v))
}

/// `v` as the host takes it: in `[0, 2π)` on a periodic host.
fn host_v(host: &dyn Surface, v: f64) -> f64 {
    if host.v_domain().is_periodic() {
        v.rem_euclid(TAU)
    } else {
        v
    }
}

/// `C'` and `C''` of the image curve from the host's partials and the `(u, v)` derivatives.
fn image_derivatives(p: &Partials, d1: [f64; 2], d2: [f64; 2]) -> (Vec3, Vec3) {
    let c1 = p.xu * d1[0] + p.xv * d1[1];
    let c2 = p.xuu * (d1[0] * d1[0])
        + p.xuv * (2.0 * d1[0] * d1[1])
        + p.xvv * (d1[1] * d1[1])
        + p.xu * d2[0]
        + p.xv * d2[1];
    (c1, c2)
}

/// Derivatives of order `exact + 1 ..` by central differences of the exact derivative of order
/// `exact` (`f`), step `h`: `Σ_j (−1)^j C(n, j) f(s + (n/2 − j) h) / hⁿ` for `n = order − exact`.
fn differenced(f: &dyn Fn(f64) -> Vec3, s: f64, exact: usize, out: &mut [Vec3]) {
    for (order, o) in out.iter_mut().enumerate().skip(exact + 1) {
        let n = order - exact;
        let h = 1e-3 * n as f64;
        let mut acc = Vec3::zeros();
        let mut binom = 1.0;
        for j in 0..=n {
            let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
            acc += f(s + (n as f64 / 2.0 - j as f64) * h) * (sign * binom);
            binom = binom * (n - j) as f64 / (j + 1) as f64;
        }
        *o = acc / h.powi(n as i32);
    }
}

/// The host's jet at `s` of a path: its partials and the path's `(u, v)` derivatives in `s`.
type HostJet = (Partials, [f64; 2], [f64; 2]);

/// Most jets a [`PathOnHost`] keeps (a frame asks for a few hundred, at the same `s` again and
/// again: the Fourier samples, the mesh columns, the drawn points).
const MAX_KEPT_JETS: usize = 4096;

/// A closed `(u, v)` path on a solved host, shared by the `on_patch` curve on it and the
/// `tangent_field` across it: both evaluate the host at the same points of the path (the
/// solve's Fourier samples, the mesh columns, the drawn points all fall on `s = 2πk/2^m`), so
/// the host's jets are kept by `s` and computed once, for as long as the host is the same
/// solved surface (a rebuild that keeps the host keeps its paths). A kept jet is the value a
/// fresh evaluation gives; a point taken from it is the host's partials' position, the same
/// bits as its point for analytic patches (whose point and partials share their arithmetic)
/// and the same to rounding for others.
pub struct PathOnHost {
    host: SurfaceKind,
    path: TrimCurve,
    jets: Mutex<HashMap<u64, HostJet>>,
    /// A [`TangentField`] lies across the path: it will ask for the jets wherever the curve
    /// asks for points, so a point is computed as a jet and kept.
    crossed: AtomicBool,
    /// The host's bounds for [`Curve::derivative_bounds`], made on first use.
    bounds: OnceLock<Option<Arc<bounds::Host>>>,
}

impl PathOnHost {
    /// The closed `(u, v)` curve `path` on `host`.
    pub fn new(host: SurfaceKind, path: TrimCurve) -> Arc<Self> {
        Arc::new(PathOnHost {
            host,
            path,
            jets: Mutex::new(HashMap::new()),
            crossed: AtomicBool::new(false),
            bounds: OnceLock::new(),
        })
    }

    /// [`host_jet`] at `s`, kept.
    fn jet(&self, s: f64) -> HostJet {
        let key = s.to_bits();
        let kept = |j: &HashMap<u64, HostJet>| j.get(&key).copied();
        if let Some(j) = self.jets.lock().ok().and_then(|j| kept(&j)) {
            return j;
        }
        let jet = host_jet(self.host.surface(), &self.path, s);
        if let Ok(mut jets) = self.jets.lock() {
            if jets.len() < MAX_KEPT_JETS {
                jets.insert(key, jet);
            }
        }
        jet
    }

    /// The image's point at `s`: a kept jet's position; else, on a path a tangent field
    /// crosses, the jet (kept); else the host's point alone (a position is cheaper than a jet).
    fn point(&self, s: f64) -> Vec3 {
        if let Some(p) = self.kept_point(s) {
            return p;
        }
        if self.crossed.load(Ordering::Relaxed) {
            return self.jet(s).0.x;
        }
        host_point(self.host.surface(), &self.path, s)
    }

    /// The position of the jet kept at `s`, if one is.
    fn kept_point(&self, s: f64) -> Option<Vec3> {
        let jets = self.jets.lock().ok()?;
        jets.get(&s.to_bits()).map(|(p, _, _)| p.x)
    }

    /// The image's point at the path's parameter `t` (`s = 2π t`): a kept jet's position, or
    /// the host's point at the path's point at `t`.
    pub(crate) fn point_at(&self, t: f64) -> Vec3 {
        self.kept_point(W * t).unwrap_or_else(|| {
            let host = self.host.surface();
            let [u, v] = self.path.point(t);
            host.point(u, host_v(host, v))
        })
    }

    /// The host, the path and how many jets are kept (for tests).
    #[cfg(test)]
    pub(crate) fn parts(&self) -> (&SurfaceKind, &TrimCurve, usize) {
        let kept = self.jets.lock().map_or(0, |j| j.len());
        (&self.host, &self.path, kept)
    }

    /// True when this is the path `path` on `host` (the same solved surface).
    pub(crate) fn lies_on(&self, host: &SurfaceKind, path: &TrimCurve) -> bool {
        self.host.id() == host.id() && self.path == *path
    }

    fn host_bounds(&self) -> Option<&bounds::Host> {
        self.bounds
            .get_or_init(|| bounds::Host::new(&self.host, &self.path))
            .as_deref()
    }
}

/// A curve on a surface: `C(s) = X(u(s), v(s))` for a closed `(u, v)` curve, `s ∈ [0, 2π)`.
/// Value and first two derivatives exact (chain rule with the surface's exact partials); higher
/// derivatives (used by nothing in the solvers) by central differences of the second.
#[derive(Clone)]
pub struct CurveOnSurface {
    on: Arc<PathOnHost>,
}

impl CurveOnSurface {
    /// The image on `host` of the closed `(u, v)` curve `path`.
    pub fn new(host: SurfaceKind, path: TrimCurve) -> Self {
        Self::on(PathOnHost::new(host, path))
    }

    /// The image of a path on its host (shared with the path's [`TangentField`]).
    pub fn on(on: Arc<PathOnHost>) -> Self {
        CurveOnSurface { on }
    }

    fn second(&self, s: f64) -> Vec3 {
        let (p, d1, d2) = self.on.jet(s);
        image_derivatives(&p, d1, d2).1
    }
}

impl std::fmt::Debug for CurveOnSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CurveOnSurface")
            .field("path", &self.on.path)
            .finish_non_exhaustive()
    }
}

impl Curve for CurveOnSurface {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }

    fn jet(&self, s: f64, out: &mut [Vec3]) {
        if let [o] = out {
            // The position alone: the host's point, without its partials.
            *o = self.on.point(s);
            return;
        }
        let (p, d1, d2) = self.on.jet(s);
        let (c1, c2) = image_derivatives(&p, d1, d2);
        for (k, o) in out.iter_mut().enumerate().take(3) {
            *o = [p.x, c1, c2][k];
        }
        if out.len() > 3 {
            differenced(&|s| self.second(s), s, 2, out);
        }
    }

    /// The breaks of the `(u, v)` curve, `s = 2π t`.
    fn breaks(&self) -> Vec<f64> {
        self.on.path.breaks().into_iter().map(|t| W * t).collect()
    }

    /// Value, tangent and second derivative from the host's partials; higher orders are
    /// differenced.
    fn exact_order(&self) -> usize {
        2
    }

    /// Bounds by the majorant of the composition `X(u(s), v(s))` with the host's partials
    /// bounded near each piece of the curve ([`bounds`]). `false` for hosts other than analytic
    /// PDE patches without an active spectral remainder, or a curve reaching outside
    /// `u ∈ [0, 1]`.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        self.bounds(t0, t1, out)
    }
}

/// The derivative condition of an attachment: `D(s) = −σ·scale·(C' × N)/|C' × N|` along an
/// `on_patch` curve `C` (see the module documentation). Value and first derivative exact; higher
/// derivatives by central differences of the first.
#[derive(Clone)]
pub struct TangentField {
    on: Arc<PathOnHost>,
    /// `−σ·scale`.
    factor: f64,
}

impl TangentField {
    /// The field across the image on `host` of `path`, `scale` long, into the hole.
    pub fn new(host: SurfaceKind, path: TrimCurve, scale: f64) -> Self {
        Self::on(PathOnHost::new(host, path), scale)
    }

    /// The field across a path on its host (shared with the path's [`CurveOnSurface`]).
    pub fn on(on: Arc<PathOnHost>, scale: f64) -> Self {
        on.crossed.store(true, Ordering::Relaxed);
        let sigma = on.path.orientation();
        TangentField {
            on,
            factor: -sigma * scale,
        }
    }

    /// `D` and `D'` at `s`.
    fn value_and_slope(&self, s: f64) -> (Vec3, Vec3) {
        let (p, d1, d2) = self.on.jet(s);
        let (c1, c2) = image_derivatives(&p, d1, d2);
        let n = p.xu.cross(&p.xv);
        let xu1 = p.xuu * d1[0] + p.xuv * d1[1];
        let xv1 = p.xuv * d1[0] + p.xvv * d1[1];
        let n1 = xu1.cross(&p.xv) + p.xu.cross(&xv1);
        let w = c1.cross(&n);
        let w1 = c2.cross(&n) + c1.cross(&n1);
        let len = w.norm();
        let hat = w / len;
        let hat1 = (w1 - hat * hat.dot(&w1)) / len;
        (hat * self.factor, hat1 * self.factor)
    }
}

impl std::fmt::Debug for TangentField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TangentField")
            .field("path", &self.on.path)
            .field("factor", &self.factor)
            .finish_non_exhaustive()
    }
}

impl Curve for TangentField {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }

    fn jet(&self, s: f64, out: &mut [Vec3]) {
        let (d, d1) = self.value_and_slope(s);
        if let Some(o) = out.get_mut(0) {
            *o = d;
        }
        if let Some(o) = out.get_mut(1) {
            *o = d1;
        }
        if out.len() > 2 {
            differenced(&|s| self.value_and_slope(s).1, s, 1, out);
        }
    }

    /// The breaks of the `(u, v)` curve, `s = 2π t`.
    fn breaks(&self) -> Vec<f64> {
        self.on.path.breaks().into_iter().map(|t| W * t).collect()
    }

    /// Value and slope; higher orders are differenced.
    fn exact_order(&self) -> usize {
        1
    }

    /// Bounds through a lower bound of `|C' × N|` on short pieces and the majorant of the
    /// normalisation ([`bounds`]); `false` as for [`CurveOnSurface`], or where `C' × N` comes
    /// too close to zero.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        self.bounds(t0, t1, out)
    }
}

/// The hosts a curve depends on (through `on_patch` curves, directly or through the curves it
/// refers to), each with the place of its `patch` key.
fn hosts_of(
    spec: &CurveSpec,
    place: &str,
    curves: &BTreeMap<String, CurveSpec>,
    depth: usize,
    out: &mut Vec<(String, String)>,
) {
    if depth > curves.len() + 8 {
        return;
    }
    if let CurveKind::OnPatch { patch, .. } = &spec.kind {
        out.push((patch.clone(), format!("{place}.patch")));
    }
    let mut refs = Vec::new();
    references(spec, place, &mut refs);
    for (name, _) in refs {
        if let Some(c) = curves.get(name) {
            hosts_of(c, &curve_place(name), curves, depth + 1, out);
        }
    }
}

/// The hosts of a condition's curve.
fn hosts_of_ref(
    r: &CurveRef,
    place: &str,
    curves: &BTreeMap<String, CurveSpec>,
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    match r {
        CurveRef::Name(n) => {
            if let Some(c) = curves.get(n) {
                hosts_of(c, &curve_place(n), curves, 0, &mut out);
            }
        }
        CurveRef::Inline(c) => hosts_of(c, place, curves, 0, &mut out),
    }
    out
}

/// True if any curve of the design (named or inline in a condition) lies on a patch.
pub(crate) fn has_attachments(spec: &DesignSpec) -> bool {
    let on = |c: &CurveSpec| {
        let mut out = Vec::new();
        hosts_of(c, "", &spec.curves, 0, &mut out);
        !out.is_empty()
    };
    spec.curves.values().any(on)
        || plan(spec).is_ok_and(|plans| {
            plans.iter().any(|p| {
                p.conditions.iter().any(|c| match &c.curve {
                    CurveRef::Inline(s) => on(s),
                    CurveRef::Name(_) => false,
                })
            })
        })
}

/// The order in which the PDE patches are solved: levels of patch indices (in the order of
/// [`plan`]); the patches of a level depend only on patches of earlier levels (their hosts).
/// A host that is not a patch of the design, a patch attached to itself, and patches attached
/// to each other in a cycle are refused with the place of the condition (or `patch` key).
pub(crate) fn patch_levels(spec: &DesignSpec) -> Result<Vec<Vec<usize>>> {
    let plans = plan(spec)?;
    let names: Vec<&str> = plans.iter().map(|p| p.name.as_str()).collect();
    // deps[i]: (host index, place of the condition's curve).
    let mut deps: Vec<Vec<(usize, String)>> = Vec::with_capacity(plans.len());
    for (i, p) in plans.iter().enumerate() {
        let mut d = Vec::new();
        for (j, c) in p.conditions.iter().enumerate() {
            let place = format!("{}[{j}].curve", p.place);
            for (host, host_place) in hosts_of_ref(&c.curve, &place, &spec.curves) {
                let h = names
                    .iter()
                    .position(|n| *n == host)
                    .ok_or_else(|| no_host(&host, &names).at(&host_place))?;
                if h == i {
                    return Err(Error::invalid(format!(
                        "the patch '{}' cannot be attached to itself (its condition lies on it)",
                        p.name
                    ))
                    .at(&place));
                }
                d.push((h, place.clone()));
            }
        }
        deps.push(d);
    }
    let mut level: Vec<Option<usize>> = vec![None; plans.len()];
    let mut levels: Vec<Vec<usize>> = Vec::new();
    loop {
        let ready: Vec<usize> = (0..plans.len())
            .filter(|&i| {
                level[i].is_none()
                    && deps[i]
                        .iter()
                        .all(|(h, _)| level[*h].is_some_and(|l| l < levels.len()))
            })
            .collect();
        if ready.is_empty() {
            break;
        }
        for &i in &ready {
            level[i] = Some(levels.len());
        }
        levels.push(ready);
    }
    if let Some(i) = level.iter().position(Option::is_none) {
        // Follow unsolved hosts from i until a patch repeats: that is the cycle.
        let mut path = vec![i];
        let mut k = i;
        while let Some((h, _)) = deps[k].iter().find(|(h, _)| level[*h].is_none()) {
            if let Some(start) = path.iter().position(|x| x == h) {
                path.drain(..start);
                path.push(*h);
                break;
            }
            path.push(*h);
            k = *h;
        }
        let first = path[0];
        let place = deps[first]
            .iter()
            .find(|(h, _)| level[*h].is_none())
            .map_or_else(|| plans[first].place.clone(), |(_, p)| p.clone());
        let cycle: Vec<&str> = path.iter().map(|&k| names[k]).collect();
        return Err(Error::invalid(format!(
            "patches are attached to each other in a cycle: {} (each must be solved before the next)",
            cycle.join(" → ")
        ))
        .at(&place));
    }
    Ok(levels)
}

fn no_host(name: &str, names: &[&str]) -> Error {
    Error::invalid(format!(
        "no PDE patch named '{name}' (the design's patches: {})",
        names
            .iter()
            .map(|n| format!("'{n}'"))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// Checks every `on_patch` and `tangent_field` curve of the design (named, or inline in a
/// condition) without solving: the host is a PDE patch of the design without a `[[spine]]`
/// edit, the `(u, v)` curve is valid, lies inside `0 < u < 1` and spans less than one period in
/// `v` (crossing the seam `v = 0` is allowed, written with `v < 0`), takes no transform,
/// `v_origin` or `arc_length`; a `tangent_field` names an `on_patch` curve and has a finite,
/// non-zero scale.
pub(crate) fn check_attachment_specs(spec: &DesignSpec) -> Result<()> {
    let plans = plan(spec)?;
    let names: Vec<&str> = plans.iter().map(|p| p.name.as_str()).collect();
    let single = spec.patches.is_none();
    let mut all: Vec<(String, &CurveSpec)> = spec
        .curves
        .iter()
        .map(|(n, c)| (curve_place(n), c))
        .collect();
    for p in &plans {
        for (j, c) in p.conditions.iter().enumerate() {
            if let CurveRef::Inline(s) = &c.curve {
                all.push((format!("{}[{j}].curve", p.place), s));
            }
        }
    }
    for (place, c) in all {
        match &c.kind {
            CurveKind::OnPatch { patch, path, .. } => {
                if !names.contains(&patch.as_str()) {
                    return Err(no_host(patch, &names).at(&format!("{place}.patch")));
                }
                let edited = spec.spine.iter().any(|s| match &s.patch {
                    Some(n) => n == patch,
                    None => single,
                });
                if edited {
                    return Err(Error::invalid(format!(
                        "the patch '{patch}' has a [[spine]] edit: curves on spine-edited patches are not supported"
                    ))
                    .at(&format!("{place}.patch")));
                }
                if !c.transform.is_empty() || c.v_origin != 0.0 || c.arc_length {
                    return Err(Error::invalid(
                        "an on_patch curve lies on its patch: it takes no transform, v_origin or arc_length",
                    )
                    .at(&place));
                }
                check_path(&trim_curve(path)).map_err(|e| e.at(&format!("{place}.path")))?;
            }
            CurveKind::TangentField { curve, scale } => {
                if !(scale.is_finite() && *scale != 0.0) {
                    return Err(
                        Error::invalid(format!("must be finite and not 0 (got {scale})"))
                            .at(&format!("{place}.scale")),
                    );
                }
                match spec.curves.get(curve).map(|c| &c.kind) {
                    Some(CurveKind::OnPatch { .. }) => {}
                    Some(other) => {
                        return Err(Error::invalid(format!(
                            "must name an on_patch curve ('{curve}' is a {} curve)",
                            super::validate::kind_name(other)
                        ))
                        .at(&format!("{place}.curve")))
                    }
                    None => {
                        return Err(super::validate::unknown_curve(
                            curve,
                            &spec.curves,
                            &format!("{place}.curve"),
                        ))
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Samples taken round a `(u, v)` curve to find its extent.
const EXTENT_SAMPLES: usize = 4096;

/// The checks of a `(u, v)` curve that do not need its host (see [`check_attachment_specs`]).
/// When a box holding the curve ([`TrimCurve::bounds`]) meets the conditions on `u` and on the
/// width in `v`, and the curve's first point lies in `0 < v < 2π`, the sampled extent (inside
/// the box, and holding that point) meets them all: the curve passes without its samples (this
/// runs on every edit, every frame of a drag).
fn check_path(c: &TrimCurve) -> Result<()> {
    c.validate()?;
    if box_accepts(c) {
        return Ok(());
    }
    let (lo, hi) = c.sampled_extent(EXTENT_SAMPLES);
    if !(lo[0] > 0.0 && hi[0] < 1.0) {
        return Err(Error::invalid(format!(
            "the curve leaves the patch: its u runs from {:.4} to {:.4}, outside 0 < u < 1",
            lo[0], hi[0]
        )));
    }
    if hi[1] - lo[1] >= TAU || hi[1] <= 0.0 || lo[1] >= TAU {
        return Err(Error::invalid(format!(
            "the curve leaves the patch: its v runs from {:.4} to {:.4}; it must lie in one period and meet 0 ≤ v < 2π (write a curve across the seam with v < 0)",
            lo[1], hi[1]
        )));
    }
    Ok(())
}

/// True when a box holding the curve meets the conditions on `u` and on the width in `v` and
/// the curve's first point lies in `0 < v < 2π` (see [`check_path`]).
fn box_accepts(c: &TrimCurve) -> bool {
    let (lo, hi) = c.bounds();
    let first = c.point(0.0);
    lo[0] > 0.0 && hi[0] < 1.0 && hi[1] - lo[1] < TAU && first[1] > 0.0 && first[1] < TAU
}

/// Every `on_patch` curve with `trim = true` (named, in name order, then inline in conditions)
/// as `(place, host name, (u, v) curve)`.
fn trimming_curves(spec: &DesignSpec) -> Vec<(String, String, TrimCurve)> {
    let mut out = Vec::new();
    let mut push = |place: String, c: &CurveSpec| {
        if let CurveKind::OnPatch {
            patch,
            path,
            trim: true,
        } = &c.kind
        {
            out.push((place, patch.clone(), trim_curve(path)));
        }
    };
    for (n, c) in &spec.curves {
        push(curve_place(n), c);
    }
    if let Ok(plans) = plan(spec) {
        for p in &plans {
            for (j, c) in p.conditions.iter().enumerate() {
                if let CurveRef::Inline(s) = &c.curve {
                    push(format!("{}[{j}].curve", p.place), s);
                }
            }
        }
    }
    out
}

/// Adds to `trims` the hole of every trimming `on_patch` curve: to its host's `[[trims]]` entry
/// if it has one (with that entry's method), else as a new entry placed at the curve (`cdt`).
/// Each addition is checked on the default grid; a curve that crosses or lies in another hole
/// (an attachment on a trimmed-away region) is refused at its `path`.
pub(crate) fn add_attachment_trims(
    spec: &DesignSpec,
    surfaces: &[DesignSurface],
    trims: &mut Vec<SurfaceTrim>,
    previous: &TrimChecks,
    checks: &mut TrimChecks,
) -> Result<()> {
    for (place, host, curve) in trimming_curves(spec) {
        let Some(k) = surfaces.iter().position(|s| s.name == host) else {
            continue; // refused earlier by check_attachment_specs
        };
        let (curves, method, other) = match trims.iter().find(|t| t.surface == k) {
            Some(t) => {
                let mut c = t.curves.clone();
                c.push(curve.clone());
                (c, t.method, Some(t.place.clone()))
            }
            None => (vec![curve.clone()], TrimMethod::Cdt, None),
        };
        let domain = surfaces[k].surface().parameter_domain();
        checks
            .check(previous, domain, &curves, method)
        .map_err(|e| {
            let what = match &other {
                Some(o) => format!(
                    "the attachment cannot be cut out of '{host}' together with the holes of {o} (an attachment on a trimmed-away region?)"
                ),
                None => format!("the attachment cannot be cut out of '{host}'"),
            };
            Error::invalid(format!("{what}: {e}"))
                .at(&format!("{place}.path"))
        })?;
        match trims.iter_mut().find(|t| t.surface == k) {
            Some(t) => t.curves.push(curve),
            None => trims.push(SurfaceTrim {
                surface: k,
                place,
                method: TrimMethod::Cdt,
                curves: vec![curve],
            }),
        }
    }
    Ok(())
}

/// One attachment of a solved design: a position condition of a patch that lies on another.
#[derive(Clone, Debug, PartialEq)]
pub struct Attachment {
    /// Index of the attached patch in [`SolvedDesign::surfaces`].
    pub patch: usize,
    /// The `u` of the condition (the attached end: 0 or 1, or an intermediate curve).
    pub u: f64,
    /// Index of the host in [`SolvedDesign::surfaces`].
    pub host: usize,
    /// The `on_patch` curve's name (`None` for an inline table).
    pub curve: Option<String>,
    /// True if the patch's first u-derivative at `u` is a `tangent_field` of that curve, so the
    /// attachment is meant to be tangent-continuous (G1).
    pub tangent: bool,
}

/// The attachments of a design, from its spec and its surfaces (by name).
pub(crate) fn find_attachments(spec: &DesignSpec, surfaces: &[DesignSurface]) -> Vec<Attachment> {
    let mut out = Vec::new();
    let Ok(plans) = plan(spec) else {
        return out;
    };
    let index = |name: &str| surfaces.iter().position(|s| s.name == name);
    for p in &plans {
        let Some(patch) = index(&p.name) else {
            continue;
        };
        for c in p.conditions.iter().filter(|c| c.derivative == 0) {
            let (name, kind) = match &c.curve {
                CurveRef::Name(n) => match spec.curves.get(n) {
                    Some(s) => (Some(n.clone()), &s.kind),
                    None => continue,
                },
                CurveRef::Inline(s) => (None, &s.kind),
            };
            let CurveKind::OnPatch { patch: host, .. } = kind else {
                continue;
            };
            let Some(host) = index(host) else {
                continue;
            };
            let tangent = name.as_ref().is_some_and(|n| {
                p.conditions.iter().any(|d| {
                    d.derivative == 1
                        && d.u == c.u
                        && match &d.curve {
                            CurveRef::Name(m) => matches!(
                                spec.curves.get(m).map(|s| &s.kind),
                                Some(CurveKind::TangentField { curve, .. }) if curve == n
                            ),
                            CurveRef::Inline(s) => matches!(
                                &s.kind,
                                CurveKind::TangentField { curve, .. } if curve == n
                            ),
                        }
                })
            });
            out.push(Attachment {
                patch,
                u: c.u,
                host,
                curve: name,
                tangent,
            });
        }
    }
    out
}

/// G0/G1 along one attachment, measured independently of the construction.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachmentReport {
    /// The attachment measured.
    pub attachment: Attachment,
    /// Points sampled along the attached patch's end.
    pub samples: usize,
    /// Largest distance from a sample `X_a(u, v_j)` to the host (its closest point).
    pub g0: f64,
    /// Largest angle (radians) between the attached patch's normal at the sample and the host's
    /// normal at that closest point (as lines: the sign of a normal is not compared).
    pub g1: f64,
    /// Samples whose closest-point search did not report convergence.
    pub unconverged: usize,
}

impl SolvedDesign {
    /// G0/G1 along every attachment, on `samples` equally spaced `v` of the attached patch's end
    /// (at least 8): each sample is projected onto the host by the closest-point search
    /// ([`ClosestPointIndex`], not the known `(u, v)` curve); G0 is the largest distance, G1 the
    /// largest angle between the two surfaces' normals there.
    pub fn attachment_reports(&self, samples: usize) -> Vec<AttachmentReport> {
        let samples = samples.max(8);
        let opts = ClosestOptions {
            samples_u: 32,
            samples_v: 64,
            ..ClosestOptions::default()
        };
        self.attachments
            .iter()
            .map(|a| {
                let host = self.surfaces[a.host].surface();
                let patch = self.surfaces[a.patch].surface();
                let index = ClosestPointIndex::new(host, &opts);
                let (mut g0, mut g1, mut unconverged) = (0.0f64, 0.0f64, 0);
                for j in 0..samples {
                    let v = TAU * j as f64 / samples as f64;
                    let p = patch.partials(a.u, v);
                    let Some(c) = index.closest(p.x) else {
                        g0 = f64::NAN;
                        continue;
                    };
                    if !c.converged {
                        unconverged += 1;
                    }
                    let n1 = p.normal();
                    let n2 = host.partials(c.u, c.v).normal();
                    let angle = n1.cross(&n2).norm().atan2(n1.dot(&n2).abs());
                    g0 = g0.max(c.distance);
                    g1 = g1.max(angle);
                    if c.distance.is_nan() || angle.is_nan() {
                        g0 = f64::NAN;
                    }
                }
                AttachmentReport {
                    attachment: a.clone(),
                    samples,
                    g0,
                    g1,
                    unconverged,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::solve_design;
    use crate::spec::parse_design;

    /// The sampled extent check alone (the rule `check_path` decides by when its box does not).
    fn sampled_check(c: &TrimCurve) -> bool {
        let (lo, hi) = c.sampled_extent(EXTENT_SAMPLES);
        lo[0] > 0.0 && hi[0] < 1.0 && hi[1] - lo[1] < TAU && hi[1] > 0.0 && lo[1] < TAU
    }

    /// `check_path` (box first, samples when the box cannot decide) accepts and refuses the
    /// same paths as the samples alone: paths well inside, across each limit, curves whose
    /// control points leave the patch while the curve stays in it, and curves across v = 0.
    #[test]
    fn a_path_s_box_decides_as_its_samples_do() {
        let mut curves = vec![
            TrimCurve::circle([0.5, 1.0], 0.2),
            TrimCurve::circle([0.5, 0.1], 0.2),
            TrimCurve::circle([0.9, 1.0], 0.2),
            TrimCurve::circle([0.5, -0.5], 0.2),
            TrimCurve::Ellipse {
                center: [0.5, 3.0],
                radii: [0.3, 3.2],
                angle: 0.0,
            },
            TrimCurve::Polyline(vec![[0.1, 0.2], [0.9, 0.4], [0.5, 1.7]]),
            TrimCurve::Polyline(vec![[0.0, 0.2], [0.9, 0.4], [0.5, 1.7]]),
        ];
        // A quadratic B-spline whose control points reach u = 1.02 while the curve stays
        // below u = 1 (the curve touches each control polygon edge's midpoint), and the same
        // one moved right until the curve leaves.
        for shift in [0.0, 0.03, 0.06] {
            curves.push(TrimCurve::BSpline {
                degree: 2,
                points: vec![
                    [0.5 + shift, 0.5],
                    [1.02 + shift, 1.0],
                    [0.5 + shift, 1.5],
                    [0.3 + shift, 1.0],
                ],
            });
        }
        let mut boxed = 0;
        for (k, c) in curves.iter().enumerate() {
            assert_eq!(check_path(c).is_ok(), sampled_check(c), "path {k}");
            boxed += usize::from(box_accepts(c));
        }
        // Both branches ran: some paths decided by the box, some by the samples.
        assert!(boxed >= 3 && boxed < curves.len());
        assert!(check_path(&curves[7]).is_ok() && curves[7].bounds().1[0] > 1.0);
    }

    /// The teacup's bowl as a host, with an ellipse, a cubic B-spline and a polyline path near
    /// the handle's ends: on intervals of `s` between the breaks the proven bounds of the curve
    /// on the bowl and of its tangent field are at least the largest derivatives on a dense
    /// sample (orders ≤ 2 resp. ≤ 1 exact, the higher ones by fine central differences of the
    /// highest exact one: a check only).
    #[test]
    #[allow(clippy::approx_constant)] // the teacup's own control points
    fn curves_on_a_patch_have_proven_derivative_bounds() {
        let text = include_str!("../../../../examples/teacup.toml");
        let design = solve_design(&parse_design(text).unwrap()).unwrap();
        let host = design
            .surfaces
            .iter()
            .find(|s| s.name == "bowl")
            .unwrap()
            .kind
            .clone();
        let paths = [
            TrimCurve::circle([0.72, std::f64::consts::PI], 0.1),
            TrimCurve::BSpline {
                degree: 3,
                points: vec![
                    [0.12918, 3.14159],
                    [0.16164, 3.21995],
                    [0.24000, 3.25241],
                    [0.31836, 3.21995],
                    [0.35082, 3.14159],
                    [0.31836, 3.06323],
                    [0.24000, 3.03077],
                    [0.16164, 3.06323],
                ],
            },
            TrimCurve::Polyline(vec![[0.4, 3.0], [0.6, 3.0], [0.6, 3.3], [0.4, 3.3]]),
        ];
        for (k, path) in paths.iter().enumerate() {
            let on = CurveOnSurface::new(host.clone(), path.clone());
            let field = TangentField::new(host.clone(), path.clone(), 0.3);
            assert_eq!((on.exact_order(), field.exact_order()), (2, 1));
            let mut cuts = on.breaks();
            assert_eq!(cuts, field.breaks());
            if cuts.is_empty() {
                cuts.push(0.0);
            }
            cuts.push(cuts[0] + TAU);
            for w in cuts.windows(2) {
                // Four intervals per piece (halved until a bound holds, at most 2⁶ times).
                for (name, curve, min_parts) in
                    [("on", &on as &dyn Curve, 4usize), ("field", &field, 4)]
                {
                    let mut parts = min_parts;
                    let mut bounds = Vec::new();
                    while bounds.is_empty() {
                        assert!(parts <= min_parts << 6, "path {k} {name}: no bound");
                        for i in 0..parts {
                            let a = w[0] + (w[1] - w[0]) * i as f64 / parts as f64;
                            let b = w[0] + (w[1] - w[0]) * (i + 1) as f64 / parts as f64;
                            let mut bound = [0.0; 5];
                            if !curve.derivative_bounds(a, b, &mut bound) {
                                bounds.clear();
                                parts *= 2;
                                break;
                            }
                            bounds.push((a, b, bound));
                        }
                    }
                    for (i, &(a, b, bound)) in bounds.iter().enumerate() {
                        let mut seen = [0.0f64; 5];
                        let mut jet = [Vec3::zeros(); 5];
                        // Away from the ends by more than the differences' reach (0.006).
                        let (a2, b2) = (a + 0.006, b - 0.006);
                        for j in 0..=200 {
                            let s = a2 + (b2 - a2) * j as f64 / 200.0;
                            curve.jet(s, &mut jet);
                            for (x, y) in seen.iter_mut().zip(&jet) {
                                *x = x.max(y.norm());
                            }
                        }
                        for o in 0..5 {
                            assert!(
                                seen[o] <= bound[o] * (1.0 + 1e-6),
                                "path {k} {name} [{a}, {b}] order {o}: {} > {}",
                                seen[o],
                                bound[o]
                            );
                        }
                        if i == 0 && w[0] == cuts[0] {
                            eprintln!(
                                "path {k} {name} ({parts} intervals per piece): bound/sampled {:?}",
                                (0..5).map(|o| bound[o] / seen[o]).collect::<Vec<_>>()
                            );
                        }
                    }
                }
            }
        }
        // Not a PDE host with bounds, or a curve outside u ∈ [0, 1]: no bound.
        let out = CurveOnSurface::new(host.clone(), TrimCurve::circle([0.95, 1.0], 0.1));
        assert!(!out.derivative_bounds(0.0, 1.0, &mut [0.0; 5]));
    }
}
