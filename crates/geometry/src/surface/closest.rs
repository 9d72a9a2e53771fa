//! The closest point of a surface to a point in space.
//!
//! The search minimises `f(u, v) = |X(u, v) − p|²` over the parameter domain
//! ([`Surface::parameter_domain`]) in two stages:
//!
//! 1. **Coarse samples.** `X` on a grid of the domain (both ends of a bounded parameter, one
//!    period of a periodic one) gives the nearest sample, the start of the first run. Other
//!    starts are the samples that are discrete local minima of the distance and could still hide
//!    a closer point: a sample `s` at distance `d_s` whose grid neighbours lie within `R_s` of it
//!    is tried only while `d_s − R_s` is below the best distance found (a heuristic bound: the
//!    surface between the samples is taken to stay within that neighbourhood).
//! 2. **Projected Newton.** From each start, the first-order conditions
//!    `g = (r·X_u, r·X_v) = 0` with `r = X − p` are solved with the exact Hessian
//!    `H = [[X_u·X_u + r·X_uu, X_u·X_v + r·X_uv], [·, X_v·X_v + r·X_vv]]`. Where `H` is not
//!    positive definite (beyond a focal point, near a pole), the Gauss–Newton step
//!    `−I⁻¹ g` with the first fundamental form `I` (the projection of `−r` on the tangent plane,
//!    always a descent direction) is taken instead. Steps are limited to half the surface's size,
//!    backtracked until `f` decreases, clamped to a bounded parameter's range and wrapped for a
//!    periodic one. A parameter at a bound whose gradient points outward is held there (the
//!    projected first-order conditions of a boundary minimum).
//!
//! **Poles.** Where `X_v` vanishes (a position curve shrunk to a point) `v` is arbitrary and is
//! held; a run that stops on such a row tries sixteen `v` for a direction in `u` that still
//! descends, and continues from the best (likewise for `X_u = 0`).
//!
//! The result is the best over the runs. It is a local minimum that satisfies the first-order
//! conditions ([`Closest::converged`]); the sampling makes it the global one for every surface
//! whose features the sample grid resolves, but no certificate is given.

use super::{Interval, ParameterDomain, Partials, RowBuf, Surface};
use crate::Vec3;

/// Settings of the closest-point search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestOptions {
    /// Sample rows in `u` of the coarse grid (at least 2; 3 if `u` is periodic).
    pub samples_u: usize,
    /// Sample columns in `v` of the coarse grid (at least 3).
    pub samples_v: usize,
    /// Most Newton runs per query (at least 1).
    pub max_starts: usize,
    /// Most iterations per run.
    pub max_iterations: usize,
    /// A run stops when the tangential part of `X − p` (its projection on the tangent plane of
    /// the free parameters) is below `tolerance × (size + distance)`, `size` being the diagonal
    /// of the samples' bounding box. Newton converges quadratically, so the last step taken makes
    /// the result far more accurate than this.
    pub tolerance: f64,
}

impl Default for ClosestOptions {
    /// A 16 × 32 sample grid, up to 4 starts of up to 50 iterations, tolerance `10⁻¹³`.
    fn default() -> Self {
        ClosestOptions {
            samples_u: 16,
            samples_v: 32,
            max_starts: 4,
            max_iterations: 50,
            tolerance: 1e-13,
        }
    }
}

/// The closest point found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// `u` of the foot point, in the surface's `u` range (`[start, end)` if periodic).
    pub u: f64,
    /// `v` of the foot point, in the surface's `v` interval (`[0, 2π)` if periodic).
    pub v: f64,
    /// `X(u, v)`.
    pub point: Vec3,
    /// `|X(u, v) − p|`.
    pub distance: f64,
    /// True if the first-order conditions hold at the result: the tangential part of
    /// `X − p` over the free parameters (those not held at a bound by an outward gradient, nor
    /// arbitrary at a pole) is within a thousand times the stopping tolerance.
    pub converged: bool,
}

/// The ability to find the closest point to a point in space. The default is the general
/// search [`closest_point`]; surfaces with a closed form override it.
pub trait SurfaceNearest: Surface {
    /// The closest point of the surface to `p`; `None` if `p` is not finite or the surface has
    /// no finite sample.
    fn nearest(&self, p: Vec3, opts: &ClosestOptions) -> Option<Closest> {
        closest_point(self, p, opts)
    }
}

/// The closest point of `surface` to `p` (see the module documentation for the method); `None`
/// if `p` is not finite, the parameter domain is not a finite box, or no sample of the surface
/// is finite. Builds a [`ClosestPointIndex`] and queries it once: for many queries on one
/// surface build the index once instead.
pub fn closest_point<S: Surface + ?Sized>(
    surface: &S,
    p: Vec3,
    opts: &ClosestOptions,
) -> Option<Closest> {
    ClosestPointIndex::new(surface, opts).closest(p)
}

/// The coarse samples of a surface, computed once, for many closest-point queries.
pub struct ClosestPointIndex<'s, S: Surface + ?Sized> {
    surface: &'s S,
    opts: ClosestOptions,
    domain: ParameterDomain,
    us: Vec<f64>,
    vs: Vec<f64>,
    /// Sample positions, row-major (`i · nv + j`), one coordinate per vector.
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    /// Per sample: the largest distance to a grid neighbour (NaN for a sample that is not
    /// finite).
    radius: Vec<f64>,
    /// Rows (resp. columns) whose samples all coincide: poles.
    collapsed_row: Vec<bool>,
    collapsed_col: Vec<bool>,
    /// Diagonal of the samples' bounding box.
    size: f64,
    /// Largest sample coordinate norm (for rounding floors).
    reach: f64,
}

/// `f64` machine epsilon.
const EPS: f64 = f64::EPSILON;

/// `|X_v|² ≤ DEGENERATE · |X_u|²` marks a pole row (and vice versa).
const DEGENERATE: f64 = 1e-20;

/// Sample values of `n` points over an interval: one period if periodic, else both ends.
fn samples(i: Interval, periodic: bool, n: usize) -> Vec<f64> {
    if periodic {
        (0..n).map(|k| i.lerp(k as f64 / n as f64)).collect()
    } else {
        (0..n)
            .map(|k| {
                if k + 1 == n {
                    i.end
                } else {
                    i.lerp(k as f64 / (n - 1) as f64)
                }
            })
            .collect()
    }
}

/// Neighbour index `k + d` in `0..n`, wrapping if periodic.
fn step(k: usize, d: isize, n: usize, periodic: bool) -> Option<usize> {
    let t = k as isize + d;
    if periodic {
        Some(t.rem_euclid(n as isize) as usize)
    } else if t < 0 || t >= n as isize {
        None
    } else {
        Some(t as usize)
    }
}

impl<'s, S: Surface + ?Sized> ClosestPointIndex<'s, S> {
    /// Samples `surface` on the grid of `opts` (through the surface's row evaluator).
    pub fn new(surface: &'s S, opts: &ClosestOptions) -> Self {
        let domain = surface.parameter_domain();
        let (ui, vi) = (domain.u, domain.v_interval());
        let nu = opts.samples_u.max(if domain.u_periodic { 3 } else { 2 });
        let nv = opts.samples_v.max(3);
        let valid = ui.is_valid() && vi.is_valid();
        let (us, vs) = if valid {
            (
                samples(ui, domain.u_periodic, nu),
                samples(vi, domain.v_periodic(), nv),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let n = us.len() * vs.len();
        let (mut x, mut y, mut z) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        if n > 0 {
            let rows = surface.row_evaluator(&vs);
            let mut row = RowBuf::new(vs.len());
            for &u in &us {
                rows.eval_row(u, &mut row);
                x.extend_from_slice(&row.x);
                y.extend_from_slice(&row.y);
                z.extend_from_slice(&row.z);
            }
        }
        let mut index = ClosestPointIndex {
            surface,
            opts: *opts,
            domain,
            us,
            vs,
            x,
            y,
            z,
            radius: Vec::new(),
            collapsed_row: Vec::new(),
            collapsed_col: Vec::new(),
            size: 0.0,
            reach: 0.0,
        };
        index.measure();
        index
    }

    fn sample(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }

    /// Bounding box, neighbourhood radii and collapsed rows and columns.
    fn measure(&mut self) {
        let (nu, nv) = (self.us.len(), self.vs.len());
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        let mut reach = 0.0f64;
        let finite: Vec<bool> = (0..nu * nv)
            .map(|k| self.sample(k).iter().all(|c| c.is_finite()))
            .collect();
        for k in (0..nu * nv).filter(|&k| finite[k]) {
            let s = self.sample(k);
            lo = lo.inf(&s);
            hi = hi.sup(&s);
            reach = reach.max(s.norm());
        }
        let size = if lo.x <= hi.x { (hi - lo).norm() } else { 0.0 };
        self.reach = reach;
        self.size = if size > 0.0 && size.is_finite() {
            size
        } else if reach > 0.0 {
            reach
        } else {
            1.0
        };
        let (up, vp) = (self.domain.u_periodic, self.domain.v_periodic());
        self.radius = vec![f64::NAN; nu * nv];
        for i in 0..nu {
            for j in 0..nv {
                let k = i * nv + j;
                if !finite[k] {
                    continue;
                }
                let s = self.sample(k);
                let mut r = 0.0f64;
                for di in -1..=1 {
                    for dj in -1..=1 {
                        if let (Some(a), Some(b)) = (step(i, di, nu, up), step(j, dj, nv, vp)) {
                            let m = a * nv + b;
                            if finite[m] {
                                r = r.max((self.sample(m) - s).norm());
                            }
                        }
                    }
                }
                self.radius[k] = r;
            }
        }
        let same = 1e-12 * self.reach.max(self.size);
        let collapsed = |ks: &mut dyn Iterator<Item = usize>| {
            let mut first: Option<Vec3> = None;
            for k in ks {
                if !finite[k] {
                    return false;
                }
                let s = self.sample(k);
                match first {
                    None => first = Some(s),
                    Some(f) if (s - f).norm() > same => return false,
                    _ => {}
                }
            }
            true
        };
        let rows = (0..nu)
            .map(|i| collapsed(&mut (0..nv).map(|j| i * nv + j)))
            .collect();
        let cols = (0..nv)
            .map(|j| collapsed(&mut (0..nu).map(|i| i * nv + j)))
            .collect();
        (self.collapsed_row, self.collapsed_col) = (rows, cols);
    }

    /// The surface this index samples.
    pub fn surface(&self) -> &'s S {
        self.surface
    }

    /// The closest point of the surface to `p`: the best of the Newton runs from the sample
    /// starts (module documentation). `None` if `p` is not finite or no sample is.
    pub fn closest(&self, p: Vec3) -> Option<Closest> {
        if !p.iter().all(|c| c.is_finite()) {
            return None;
        }
        let nv = self.vs.len();
        let (px, py, pz) = (p.x, p.y, p.z);
        let d2 = |k: usize| {
            let (a, b, c) = (self.x[k] - px, self.y[k] - py, self.z[k] - pz);
            a * a + b * b + c * c
        };
        let mut best_k = usize::MAX;
        let mut best_d2 = f64::INFINITY;
        for k in 0..self.x.len() {
            let d = d2(k);
            if d < best_d2 {
                (best_k, best_d2) = (k, d);
            }
        }
        if best_k == usize::MAX {
            return None;
        }
        let start = |k: usize| self.start(k, p);
        let (u0, v0) = start(best_k);
        let mut best = self.run(p, u0, v0);
        if self.opts.max_starts <= 1 {
            return Some(best);
        }
        let mut found = vec![(best.u, best.v)];
        // Other starts: discrete local minima that could hide a closer point.
        let mut cands: Vec<(f64, usize)> = Vec::new();
        let (nu, up, vp) = (
            self.us.len(),
            self.domain.u_periodic,
            self.domain.v_periodic(),
        );
        for k in 0..self.x.len() {
            let reach = best.distance + self.radius[k];
            let d = d2(k);
            let may_hide = d < reach * reach;
            if k == best_k || !may_hide {
                continue;
            }
            let (i, j) = (k / nv, k % nv);
            // One start per pole.
            if (self.collapsed_row[i] && j != 0) || (self.collapsed_col[j] && i != 0) {
                continue;
            }
            let mut local_min = true;
            'n: for di in -1..=1 {
                for dj in -1..=1 {
                    if let (Some(a), Some(b)) = (step(i, di, nu, up), step(j, dj, nv, vp)) {
                        if d2(a * nv + b) < d {
                            local_min = false;
                            break 'n;
                        }
                    }
                }
            }
            if local_min {
                cands.push((d, k));
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut runs = 1;
        for &(d, k) in &cands {
            if runs >= self.opts.max_starts {
                break;
            }
            let reach = best.distance + self.radius[k];
            let may_hide = d < reach * reach;
            if !may_hide {
                continue;
            }
            let (u, v) = start(k);
            if found
                .iter()
                .any(|&(fu, fv)| self.near_in_grid(fu, fv, u, v))
            {
                continue;
            }
            let c = self.run(p, u, v);
            runs += 1;
            found.push((c.u, c.v));
            if c.distance < best.distance || (c.distance == best.distance && !best.converged) {
                best = c;
            }
        }
        Some(best)
    }

    /// The start for sample `k`: its parameters moved by one Gauss–Newton step towards `p` on
    /// the tangent plane of central differences of the neighbouring samples (limited to one grid
    /// step), which leaves an error of the order of the squared grid step instead of the step.
    /// The sample's own parameters where the differences are degenerate (poles).
    fn start(&self, k: usize, p: Vec3) -> (f64, f64) {
        let (nu, nv) = (self.us.len(), self.vs.len());
        let (i, j) = (k / nv, k % nv);
        let (u, v) = (self.us[i], self.vs[j]);
        let dom = &self.domain;
        // Central (one-sided at an end) difference between samples `a` and `b`, `steps` grid
        // steps of length `h` apart.
        let diff = |a: usize, b: usize, h: f64, steps: f64| -> Option<Vec3> {
            let t = (self.sample(b) - self.sample(a)) / (h * steps);
            t.iter().all(|c| c.is_finite()).then_some(t)
        };
        let hu = dom.u.length() / if dom.u_periodic { nu } else { nu - 1 } as f64;
        let vi = dom.v_interval();
        let hv = vi.length() / if dom.v_periodic() { nv } else { nv - 1 } as f64;
        let pick = |k: usize, n: usize, periodic: bool| {
            let lo = step(k, -1, n, periodic).unwrap_or(k);
            let hi = step(k, 1, n, periodic).unwrap_or(k);
            let steps = if lo == k || hi == k { 1.0 } else { 2.0 };
            (lo, hi, steps)
        };
        let (ilo, ihi, su) = pick(i, nu, dom.u_periodic);
        let (jlo, jhi, sv) = pick(j, nv, dom.v_periodic());
        let tu = diff(ilo * nv + j, ihi * nv + j, hu, su);
        let tv = diff(i * nv + jlo, i * nv + jhi, hv, sv);
        let (Some(tu), Some(tv)) = (tu, tv) else {
            return (u, v);
        };
        let r = p - self.sample(k);
        let (a, b, c) = (tu.norm_squared(), tu.dot(&tv), tv.norm_squared());
        let det = a * c - b * b;
        if !(det > 1e-12 * a * c && det.is_finite()) {
            return (u, v);
        }
        let (gu, gv) = (r.dot(&tu), r.dot(&tv));
        let du = ((c * gu - b * gv) / det).clamp(-hu, hu);
        let dv = ((a * gv - b * gu) / det).clamp(-hv, hv);
        dom.normalize(u + du, v + dv)
    }

    /// One Newton run from `(u, v)` (no sampling): for tracking a point that moves a little
    /// between queries, from the previous answer. `None` if `p` or the start is not finite.
    pub fn refine(&self, p: Vec3, u: f64, v: f64) -> Option<Closest> {
        if !p.iter().all(|c| c.is_finite()) || !u.is_finite() || !v.is_finite() {
            return None;
        }
        let c = self.run(p, u, v);
        c.distance.is_finite().then_some(c)
    }

    /// True if `(a, b)` is within one grid step of `(u, v)` in both parameters.
    fn near_in_grid(&self, a: f64, b: f64, u: f64, v: f64) -> bool {
        let gap = |x: f64, y: f64, i: Interval, periodic: bool, n: usize| {
            let mut d = (x - y).abs();
            if periodic {
                d = d.min(i.length() - d);
            }
            let h = i.length() / if periodic { n } else { n - 1 } as f64;
            d <= h * 1.0001
        };
        gap(a, u, self.domain.u, self.domain.u_periodic, self.us.len())
            && gap(
                b,
                v,
                self.domain.v_interval(),
                self.domain.v_periodic(),
                self.vs.len(),
            )
    }

    /// Projected Newton / Gauss–Newton from `(u, v)`.
    fn run(&self, p: Vec3, u: f64, v: f64) -> Closest {
        let dom = &self.domain;
        let floor = 16.0 * EPS * (self.reach + p.norm());
        let tol = self.opts.tolerance.max(0.0);
        let thr = |dist: f64| (tol * (self.size + dist)).max(floor);
        let max_step = 0.5 * self.size;
        let (mut u, mut v) = dom.normalize(u, v);
        let mut pt = self.surface.partials(u, v);
        let mut r = pt.x - p;
        let mut f = r.norm_squared();
        if !f.is_finite() {
            return Closest {
                u,
                v,
                point: pt.x,
                distance: f64::INFINITY,
                converged: false,
            };
        }
        let mut escaped = false;
        let mut stopped = false;
        for _ in 0..self.opts.max_iterations {
            let loc = Local::new(&pt, r, u, v, dom);
            let rt = loc.tangential();
            if !rt.is_finite() {
                break;
            }
            if rt <= thr(f.sqrt()) {
                if !escaped && loc.degenerate[0] != loc.degenerate[1] {
                    escaped = true;
                    if let Some((a, b)) = self.escape(&loc, r, u, v, thr(f.sqrt())) {
                        (u, v) = (a, b);
                        pt = self.surface.partials(u, v);
                        r = pt.x - p;
                        f = r.norm_squared();
                        continue;
                    }
                }
                stopped = true;
                break;
            }
            let mut d = loc.newton().unwrap_or_else(|| loc.gauss_newton());
            let len = loc.length(d);
            if len > max_step {
                d = [d[0] * max_step / len, d[1] * max_step / len];
            }
            // Backtracking on the projected step. Close to the answer the change of `f` drowns
            // in the rounding of `X` (about `ε|X|` normal to the surface, times `|r|`), while the
            // gradient stays accurate: there a step that does not raise `f` beyond that noise
            // and shrinks the tangential residual is taken too.
            let noise = 64.0 * EPS * f.sqrt() * (pt.x.norm() + p.norm());
            let mut alpha = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let (a, b) = dom.normalize(u + alpha * d[0], v + alpha * d[1]);
                let q = self.surface.partials(a, b);
                let rq = q.x - p;
                let fq = rq.norm_squared();
                let better =
                    fq < f || (fq <= f + noise && Local::new(&q, rq, a, b, dom).tangential() < rt);
                if better {
                    (u, v, pt, r, f) = (a, b, q, rq, fq);
                    accepted = true;
                    break;
                }
                if (q.x - pt.x).norm() <= floor {
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        let rt = Local::new(&pt, r, u, v, dom).tangential();
        let dist = f.sqrt();
        let converged = rt.is_finite() && (stopped || rt <= 1e3 * thr(dist));
        Closest {
            u,
            v,
            point: pt.x,
            distance: dist,
            converged,
        }
    }

    /// At a pole (one parameter degenerate), the value of the degenerate parameter among
    /// sixteen that gives the steepest feasible descent along the other, if that descends by
    /// more than `thr` (in space).
    fn escape(&self, loc: &Local, r: Vec3, u: f64, v: f64, thr: f64) -> Option<(f64, f64)> {
        let dom = &self.domain;
        // k: the parameter that can move; the other one is sampled.
        let k = if loc.degenerate[1] { 0 } else { 1 };
        let (moving, mi, mp) = if k == 0 {
            (u, dom.u, dom.u_periodic)
        } else {
            (v, dom.v_interval(), dom.v_periodic())
        };
        let (si, sp) = if k == 0 {
            (dom.v_interval(), dom.v_periodic())
        } else {
            (dom.u, dom.u_periodic)
        };
        let up_ok = mp || moving < mi.end;
        let down_ok = mp || moving > mi.start;
        let mut best: Option<(f64, f64)> = None;
        for t in samples(si, sp, 16) {
            let (a, b) = if k == 0 { (u, t) } else { (t, v) };
            let q = self.surface.partials(a, b);
            let tangent = if k == 0 { q.xu } else { q.xv };
            let n = tangent.norm();
            if !(n > 0.0 && n.is_finite()) {
                continue;
            }
            let g = r.dot(&tangent) / n;
            let mut phi = f64::INFINITY;
            if up_ok {
                phi = phi.min(g);
            }
            if down_ok {
                phi = phi.min(-g);
            }
            if phi < -thr && best.is_none_or(|(b, _)| phi < b) {
                best = Some((phi, t));
            }
        }
        best.map(|(_, t)| if k == 0 { (u, t) } else { (t, v) })
    }
}

/// The local quadratic model at one iterate, restricted to the free parameters.
struct Local {
    g: [f64; 2],
    h: [[f64; 2]; 2],
    /// First fundamental form (slightly regularised).
    m: [[f64; 2]; 2],
    free: [bool; 2],
    degenerate: [bool; 2],
}

impl Local {
    fn new(pt: &Partials, r: Vec3, u: f64, v: f64, dom: &ParameterDomain) -> Self {
        let (e, g2, fm) = (
            pt.xu.norm_squared(),
            pt.xv.norm_squared(),
            pt.xu.dot(&pt.xv),
        );
        let g = [r.dot(&pt.xu), r.dot(&pt.xv)];
        let h12 = fm + r.dot(&pt.xuv);
        let h = [[e + r.dot(&pt.xuu), h12], [h12, g2 + r.dot(&pt.xvv)]];
        let reg = 1e-12 * (e + g2);
        let m = [[e + reg, fm], [fm, g2 + reg]];
        let (moves_u, moves_v) = (e > DEGENERATE * g2, g2 > DEGENERATE * e);
        let degenerate = [!moves_u, !moves_v];
        let held = |t: f64, i: Interval, periodic: bool, grad: f64| {
            !periodic && ((t <= i.start && grad > 0.0) || (t >= i.end && grad < 0.0))
        };
        let free = [
            !degenerate[0] && !held(u, dom.u, dom.u_periodic, g[0]),
            !degenerate[1] && !held(v, dom.v_interval(), dom.v_periodic(), g[1]),
        ];
        Local {
            g,
            h,
            m,
            free,
            degenerate,
        }
    }

    /// `−A⁻¹ g` over the free parameters for the symmetric `A` (zero for the held ones);
    /// `None` unless `A` is positive definite relative to `I` (smallest generalised eigenvalue
    /// above `min`).
    fn solve(&self, a: &[[f64; 2]; 2], min: f64) -> Option<[f64; 2]> {
        let m = &self.m;
        match self.free {
            [true, true] => {
                let (a11, a12, a22) = (
                    a[0][0] - min * m[0][0],
                    a[0][1] - min * m[0][1],
                    a[1][1] - min * m[1][1],
                );
                if !(a11 > 0.0 && a11 * a22 - a12 * a12 > 0.0) {
                    return None;
                }
                let det = a[0][0] * a[1][1] - a[0][1] * a[0][1];
                if !(det.is_finite() && det != 0.0) {
                    return None;
                }
                Some([
                    -(a[1][1] * self.g[0] - a[0][1] * self.g[1]) / det,
                    -(a[0][0] * self.g[1] - a[0][1] * self.g[0]) / det,
                ])
            }
            [true, false] => (a[0][0] - min * m[0][0] > 0.0).then(|| [-self.g[0] / a[0][0], 0.0]),
            [false, true] => (a[1][1] - min * m[1][1] > 0.0).then(|| [0.0, -self.g[1] / a[1][1]]),
            [false, false] => Some([0.0, 0.0]),
        }
    }

    /// The Newton step, if the Hessian is positive definite on the free parameters.
    fn newton(&self) -> Option<[f64; 2]> {
        self.solve(&self.h, 1e-9)
    }

    /// The Gauss–Newton step `−I⁻¹ g` (zero if even `I` is singular).
    fn gauss_newton(&self) -> [f64; 2] {
        self.solve(&self.m, 0.0).unwrap_or([0.0, 0.0])
    }

    /// Length in space of the parameter step `d`: `√(dᵀ I d)`.
    fn length(&self, d: [f64; 2]) -> f64 {
        let m = &self.m;
        (m[0][0] * d[0] * d[0] + 2.0 * m[0][1] * d[0] * d[1] + m[1][1] * d[1] * d[1])
            .max(0.0)
            .sqrt()
    }

    /// The tangential part of `r` over the free parameters: `√(gᵀ I⁻¹ g)` (NaN if the model is
    /// not finite).
    fn tangential(&self) -> f64 {
        let finite = self.g.iter().all(|x| x.is_finite())
            && self.h.iter().flatten().all(|x| x.is_finite())
            && self.m.iter().flatten().all(|x| x.is_finite());
        if !finite {
            return f64::NAN;
        }
        let d = self.gauss_newton();
        (-(d[0] * self.g[0] + d[1] * self.g[1])).max(0.0).sqrt()
    }
}

// The general search for the parametric surface (the solvers' surfaces say so beside their types).
impl SurfaceNearest for super::ParametricSurface {}
