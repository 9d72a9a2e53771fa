use super::{Curve, Domain};
use crate::check::finite_points;
use crate::spline::knots::{find_span, KnotRule};
use crate::{Error, Result, Vec3, TAU};

/// B-spline curve of any degree: clamped/open on a knot vector, or periodic on `[0, 2π)`.
///
/// `C(t) = Σ_i N_{i,p}(t) P_i` (book Eq. 4.19/5.1, any degree) with the Cox–de Boor basis of
/// degree `p` on the knots `t_0 ≤ t_1 ≤ …`.
/// Values come from de Boor's algorithm; the `k`-th derivative is the B-spline of degree `p − k`
/// with the derivative control points `P⁽ᵏ⁾_i = (p − k + 1)/(t_{i+p+1} − t_{i+k}) (P⁽ᵏ⁻¹⁾_{i+1} −
/// P⁽ᵏ⁻¹⁾_i)`; derivatives beyond the degree are zero. Outside the domain the first/last
/// polynomial piece is extended.
#[derive(Clone, Debug)]
pub struct BSpline {
    degree: usize,
    /// Control points of the equivalent open spline (periodic: the `n` given ones followed by the
    /// first `p` again).
    control: Vec<Vec3>,
    /// Full knot vector, `control.len() + degree + 1` values.
    knots: Vec<f64>,
    periodic: bool,
}

/// Highest degree accepted.
pub(super) const MAX_DEGREE: usize = 30;

impl BSpline {
    /// Open B-spline with the full knot vector (`control.len() + degree + 1` non-decreasing knots);
    /// `None` gives the uniform clamped knot vector on `[0, 1]`. Domain `[t_p, t_n]`.
    ///
    /// Requirements: `1 ≤ degree ≤ MAX_DEGREE` (30); at least `degree + 1` finite control points;
    /// finite, non-decreasing knots; `t_p < t_n`; no knot value repeated more than `degree + 1`
    /// times, and none strictly inside `(t_p, t_n)` more than `degree` times (which would make
    /// the curve discontinuous). Knots need not be clamped (unclamped open knot vectors are
    /// fine). Errors are placed as in a curve table of the design file: `degree`, `control`,
    /// `control[i][c]`, `knots`, `knots[i]`.
    pub fn clamped(degree: usize, control: Vec<Vec3>, knots: Option<Vec<f64>>) -> Result<Self> {
        check_degree_and_control(degree, &control)?;
        let n = control.len();
        let p = degree;
        let knots = match knots {
            None => {
                let spans = n - p;
                let mut k = vec![0.0; p + 1];
                k.extend((1..spans).map(|i| i as f64 / spans as f64));
                k.extend(std::iter::repeat_n(1.0, p + 1));
                k
            }
            Some(k) => k,
        };
        KnotRule::Open {
            degree,
            count: Some(n),
        }
        .check(&knots)
        .map_err(|f| f.at_place("knots"))?;
        check_max_degree(degree)?;
        Ok(BSpline {
            degree,
            control,
            knots,
            periodic: false,
        })
    }

    /// Periodic (closed) B-spline; `knots` are the breakpoints (`control.len() + 1` increasing
    /// values, mapped linearly onto `[0, 2π]`), uniform by default.
    ///
    /// With the breakpoints `u_0 = 0 < u_1 < … < u_n = 2π` (n = `control.len()` ≥ degree + 1),
    /// the knots are extended periodically (`u_{j+n} = u_j + 2π`) and the control points wrapped
    /// (`P_{j+n} = P_j`); the curve is `C^{p−1}` everywhere, including across `v = 0`. On
    /// `[u_j, u_{j+1}]` the curve depends on `P_j … P_{j+p}` (indices modulo n). Errors are
    /// placed as in a curve table of the design file: `degree`, `control`, `control[i][c]`,
    /// `knots`, `knots[i]`.
    pub fn periodic(degree: usize, control: Vec<Vec3>, knots: Option<Vec<f64>>) -> Result<Self> {
        check_degree_and_control(degree, &control)?;
        let n = control.len();
        let p = degree;
        if let Some(b) = &knots {
            KnotRule::Breakpoints { degree, count: n }
                .check(b)
                .map_err(|f| f.at_place("knots"))?;
        }
        check_max_degree(degree)?;
        let u: Vec<f64> = match knots {
            None => (0..=n).map(|i| TAU * i as f64 / n as f64).collect(),
            Some(b) => {
                let (b0, bn) = (b[0], b[n]);
                let mut u: Vec<f64> = b.iter().map(|x| TAU * (x - b0) / (bn - b0)).collect();
                u[0] = 0.0;
                u[n] = TAU;
                for i in 1..=n {
                    if u[i] <= u[i - 1] {
                        return Err(Error::invalid(format!(
                            "is too close to knots[{}] = {} (the breakpoints are scaled to \
                             [0, 2π])",
                            i - 1,
                            b[i - 1]
                        ))
                        .at(&format!("knots[{i}]")));
                    }
                }
                u
            }
        };
        // Equivalent open spline: knots T_i = ext(i − p), i = 0..n + 2p; control P_0..P_{n−1},
        // P_0..P_{p−1}; domain [T_p, T_{n+p}] = [0, 2π].
        let ext = |j: isize| -> f64 {
            let nn = n as isize;
            let q = j.div_euclid(nn);
            let r = j.rem_euclid(nn) as usize;
            u[r] + q as f64 * TAU
        };
        let knots: Vec<f64> = (0..=(n + 2 * p))
            .map(|i| ext(i as isize - p as isize))
            .collect();
        let mut ctrl = control.clone();
        ctrl.extend_from_slice(&control[..p]);
        Ok(BSpline {
            degree,
            control: ctrl,
            knots,
            periodic: true,
        })
    }

    /// Degree `p`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The control points as given (periodic: without the wrapped copies).
    pub fn control_points(&self) -> &[Vec3] {
        let n = self.control.len();
        if self.periodic {
            &self.control[..n - self.degree]
        } else {
            &self.control
        }
    }

    /// The knot vector of the equivalent open spline (periodic: extended periodically).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The distinct knots inside the domain, ends included (where derivatives of order `≥ p`
    /// may jump).
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.bounds();
        let mut v: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|&k| k >= a && k <= b)
            .collect();
        v.dedup();
        v
    }

    fn bounds(&self) -> (f64, f64) {
        let n = self.control.len();
        (self.knots[self.degree], self.knots[n])
    }
}

/// The checks of a B-spline table of the design file, in its order: the degree is at least 1,
/// the control points are finite, and there are at least `degree + 1` of them.
fn check_degree_and_control(degree: usize, control: &[Vec3]) -> Result<()> {
    if degree < 1 {
        return Err(Error::invalid(format!("must be at least 1 (got {degree})")).at("degree"));
    }
    finite_points(control, "control")?;
    if control.len() < degree + 1 {
        return Err(Error::invalid(format!(
            "a degree-{degree} B-spline needs at least {} control points (got {})",
            degree + 1,
            control.len()
        ))
        .at("control"));
    }
    Ok(())
}

fn check_max_degree(degree: usize) -> Result<()> {
    if degree > MAX_DEGREE {
        return Err(
            Error::invalid(format!("must be at most {MAX_DEGREE} (got {degree})")).at("degree"),
        );
    }
    Ok(())
}

impl Curve for BSpline {
    fn domain(&self) -> Domain {
        if self.periodic {
            Domain::Periodic
        } else {
            let (a, b) = self.bounds();
            Domain::Interval(a, b)
        }
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let t = self.reduce(t);
        let u = &self.knots;
        let mut work = [Vec3::zeros(); MAX_DEGREE + 1];
        self.hodographs(t, out.len(), |k, s, l| {
            // de Boor for degree q = p − k on span s.
            let q = l.len() - 1;
            work[..=q].copy_from_slice(l);
            for r in 1..=q {
                for j in (r..=q).rev() {
                    let lo = u[j + s - q];
                    let hi = u[j + 1 + s - r];
                    let alpha = (t - lo) / (hi - lo);
                    work[j] = work[j - 1] * (1.0 - alpha) + work[j] * alpha;
                }
            }
            out[k] = work[q];
        });
        for o in out.iter_mut().skip(self.degree + 1) {
            *o = Vec3::zeros();
        }
    }
    /// The distinct knots inside the domain (periodic: in `[0, 2π)`; open: strictly inside).
    fn breaks(&self) -> Vec<f64> {
        let (a, b) = self.bounds();
        let mut v: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|&k| {
                if self.periodic {
                    k >= a && k < b
                } else {
                    k > a && k < b
                }
            })
            .collect();
        v.dedup();
        v
    }
    /// `p − m` with `m` the most times a knot inside the domain repeats.
    fn continuity(&self) -> usize {
        let (a, b) = self.bounds();
        let inside = |k: f64| {
            if self.periodic {
                k >= a && k < b
            } else {
                k > a && k < b
            }
        };
        let mut most = 0;
        let mut run = 0;
        let mut last = f64::NAN;
        for &k in self.knots.iter().filter(|&&k| inside(k)) {
            run = if k == last { run + 1 } else { 1 };
            last = k;
            most = most.max(run);
        }
        self.degree.saturating_sub(most)
    }
    /// On a knot span the `k`-th derivative is the B-spline of degree `p − k` with the
    /// derivative control points `L⁽ᵏ⁾` of [`Curve::jet`] (already in the curve's parameter: a
    /// periodic curve's breakpoints are scaled onto `[0, 2π]` before the knots are built, so no
    /// further chain-rule factor enters); its basis functions are non-negative and sum to one
    /// on the span, so `|C⁽ᵏ⁾| ≤ max_r |L⁽ᵏ⁾_r|` there (the hodograph's convex hull). Up to
    /// degree `MAX_ORDER` the smaller Taylor bound about the middle of each piece
    /// ([`super::polynomial_piece_bounds`]) is taken where it is smaller. An open curve has no
    /// bounds outside its domain (its end pieces extended).
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let (a, b) = self.bounds();
        if out.len() > 6 || !(self.periodic || (a <= t0 && t1 <= b)) {
            return false;
        }
        let pieces = super::pieces(&self.breaks(), self.periodic, t0, t1);
        if pieces.is_empty() {
            return false;
        }
        out.iter_mut().for_each(|o| *o = 0.0);
        let mut piece = [0.0f64; 6];
        let kmax = out.len().min(6);
        for &(x0, x1) in &pieces {
            let hull = self.hull_bounds(0.5 * (x0 + x1), &mut piece[..kmax]);
            let mut taylor = [f64::INFINITY; 6];
            let near = self.degree <= super::MAX_ORDER
                && super::polynomial_piece_bounds(
                    self,
                    self.degree,
                    &[(x0, x1)],
                    &mut taylor[..kmax],
                );
            if !(hull || near) {
                return false;
            }
            for k in 0..kmax {
                let h = if hull { piece[k] } else { f64::INFINITY };
                let t = if near { taylor[k] } else { f64::INFINITY };
                out[k] = out[k].max(h.min(t));
            }
        }
        out.iter().all(|o| o.is_finite())
    }
}

impl BSpline {
    /// `t` reduced into the period of a periodic curve.
    fn reduce(&self, t: f64) -> f64 {
        if self.periodic {
            super::reduce_periodic(t)
        } else {
            t
        }
    }

    /// Calls `visit(k, s, L⁽ᵏ⁾)` for `k = 0 ..= min(count − 1, p)` with the knot span `s` of
    /// `t` and the local control points of the `k`-th derivative there,
    /// `L⁽ᵏ⁾_r = (p−k+1)/(u_{s+r+1} − u_{s−p+r+k}) (L⁽ᵏ⁻¹⁾_{r+1} − L⁽ᵏ⁻¹⁾_r)`,
    /// `L⁽⁰⁾_r = P_{s−p+r}` (`r = 0 ..= p − k`).
    #[inline(always)]
    fn hodographs(&self, t: f64, count: usize, mut visit: impl FnMut(usize, usize, &[Vec3])) {
        let p = self.degree;
        let s = find_span(&self.knots, p, self.control.len(), &t);
        let u = &self.knots;
        let mut l = [Vec3::zeros(); MAX_DEGREE + 1];
        l[..=p].copy_from_slice(&self.control[s - p..=s]);
        for k in 0..count.min(p + 1) {
            if k > 0 {
                let f = (p - k + 1) as f64;
                for r in 0..=(p - k) {
                    let den = u[s + r + 1] - u[s - p + r + k];
                    l[r] = (l[r + 1] - l[r]) * (f / den);
                }
            }
            visit(k, s, &l[..=(p - k)]);
        }
    }

    /// `out[k] = max_r |L⁽ᵏ⁾_r|` on the knot span of `t` (module docs of
    /// [`Curve::derivative_bounds`] for this kind); `false` if a value is not finite.
    fn hull_bounds(&self, t: f64, out: &mut [f64]) -> bool {
        let t = self.reduce(t);
        self.hodographs(t, out.len(), |k, _, l| {
            out[k] = l.iter().map(|x| x.norm()).fold(0.0, f64::max) * (1.0 + super::BOUND_ROUNDING);
        });
        for o in out.iter_mut().skip(self.degree + 1) {
            *o = 0.0;
        }
        out.iter().all(|o| o.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;
    use crate::spline::knots::cox_de_boor;

    fn ctrl(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let x = i as f64;
                Vec3::new(x, (1.3 * x).sin() * 2.0, (0.7 * x).cos() + 0.1 * x * x)
            })
            .collect()
    }

    #[test]
    fn clamped_matches_cox_de_boor_and_interpolates_ends() {
        for p in 1..=5 {
            let c = ctrl(p + 4);
            let knots: Vec<f64> = {
                let mut k = vec![-1.0; p + 1];
                k.extend([-0.5, 0.0, 0.2, 1.5].iter().take(3));
                k.extend(vec![2.0; p + 1]);
                k
            };
            // n + p + 1 = p + 4 + p + 1: interior count 3.
            let s = BSpline::clamped(p, c.clone(), Some(knots.clone())).unwrap();
            assert_eq!(s.domain(), Domain::Interval(-1.0, 2.0));
            assert_close(&s.point(-1.0), &c[0], 1e-14, "start");
            assert_close(&s.point(2.0), &c[c.len() - 1], 1e-13, "end");
            for &t in &[-0.9, -0.3, 0.1, 0.7, 1.99] {
                let mut sum = 0.0;
                let mut want = Vec3::zeros();
                for (i, cp) in c.iter().enumerate() {
                    let b = cox_de_boor(&knots, i, p, t, 2.0);
                    sum += b;
                    want += cp * b;
                }
                assert!((sum - 1.0).abs() < 1e-14, "partition of unity p = {p}");
                assert_close(&s.point(t), &want, 1e-13, "Cox–de Boor");
            }
            // FD away from knots (step 1e-4, knots ≥ 0.1 away).
            check_fd(&s, &[-0.8, -0.2, 0.5, 1.0, 1.8], 1e-4, 5, 10.0);
            // Beyond the degree: zero.
            let j = jet(&s, 0.5);
            for d in &j[p + 1..] {
                assert_eq!(*d, Vec3::zeros());
            }
            // Extrapolation is finite and continuous with the end piece.
            let e = jet(&s, 2.5);
            assert!(e.iter().all(|v| v.iter().all(|c| c.is_finite())));
        }
    }

    #[test]
    fn unclamped_knots_work() {
        // Uniform open knot vector 0..=n+p: domain [p, n], no end interpolation.
        let p = 3;
        let c = ctrl(7);
        let knots: Vec<f64> = (0..=c.len() + p).map(|i| i as f64).collect();
        let s = BSpline::clamped(p, c.clone(), Some(knots.clone())).unwrap();
        assert_eq!(s.domain(), Domain::Interval(3.0, 7.0));
        for &t in &[3.0f64, 3.4, 4.5, 6.9, 7.0] {
            let want = c.iter().enumerate().fold(Vec3::zeros(), |acc, (i, cp)| {
                acc + cp * cox_de_boor(&knots, i, p, t.min(6.999_999_999_999), 7.0)
            });
            assert_close(&s.point(t), &want, 1e-11, "unclamped");
        }
        // Uniform cubic piece formula at the domain start: (P0 + 4P1 + P2)/6.
        assert_close(
            &s.point(3.0),
            &((c[0] + c[1] * 4.0 + c[2]) / 6.0),
            1e-14,
            "start",
        );
        check_fd(&s, &[3.5, 4.5, 5.5, 6.5], 1e-4, 5, 10.0);
    }

    #[test]
    fn default_knots_are_uniform_clamped() {
        let c = ctrl(6);
        let s = BSpline::clamped(3, c.clone(), None).unwrap();
        assert_eq!(
            s.knots(),
            &[0.0, 0.0, 0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0, 1.0, 1.0]
        );
        // Clamped end tangent: p/(t_{p+1} − t_1) (P_1 − P_0).
        assert_close(
            &s.derivative(0.0, 1),
            &((c[1] - c[0]) * 9.0),
            1e-13,
            "end tangent",
        );
        // A degree-n B-spline with n+1 points is the Bézier curve.
        let b = BSpline::clamped(4, ctrl(5), None).unwrap();
        let z = super::super::Bezier::new(ctrl(5)).unwrap();
        for &t in &[0.0, 0.3, 0.77, 1.0] {
            let (jb, jz) = (jet(&b, t), jet(&z, t));
            for k in 0..=5 {
                assert_close(&jb[k], &jz[k], 1e-11, "bezier");
            }
        }
    }

    #[test]
    fn periodic_uniform_cubic_matches_known_formula() {
        let n = 7;
        let c = ctrl(n);
        let s = BSpline::periodic(3, c.clone(), None).unwrap();
        assert_eq!(s.control_points(), &c[..]);
        let h = TAU / n as f64;
        for j in 0..n {
            for &x in &[0.0, 0.25, 0.5, 0.9] {
                let t = (j as f64 + x) * h;
                // On [u_j, u_{j+1}] the curve uses P_j … P_{j+3}.
                let p = |m: isize| c[(j as isize + m + 3).rem_euclid(n as isize) as usize];
                let want = (p(-3) * (1.0 - x).powi(3)
                    + p(-2) * (3.0 * x.powi(3) - 6.0 * x * x + 4.0)
                    + p(-1) * (-3.0 * x.powi(3) + 3.0 * x * x + 3.0 * x + 1.0)
                    + p(0) * x.powi(3))
                    / 6.0;
                assert_close(&s.point(t), &want, 1e-13, "uniform cubic");
                let dwant = (p(-3) * (-3.0 * (1.0 - x).powi(2))
                    + p(-2) * (9.0 * x * x - 12.0 * x)
                    + p(-1) * (-9.0 * x * x + 6.0 * x + 3.0)
                    + p(0) * (3.0 * x * x))
                    / (6.0 * h);
                assert_close(&s.derivative(t, 1), &dwant, 1e-12, "uniform cubic d1");
            }
        }
    }

    #[test]
    fn periodic_is_smooth_across_the_seam_and_knots() {
        for (p, n) in (1..=5).flat_map(|p| [(p, p + 1), (p, p + 3)]) {
            let c = ctrl(n);
            let bp: Vec<f64> = (0..=n).map(|i| (i as f64).powf(1.3)).collect();
            let s = BSpline::periodic(p, c, Some(bp)).unwrap();
            assert_eq!(s.domain(), Domain::Periodic);
            for &k in &s.breakpoints() {
                // One-sided limits through the polynomial pieces on either side.
                let a = piece_jet(&s, k, true);
                let b = piece_jet(&s, k, false);
                for d in 0..p {
                    let scale = a[d].norm().max(1.0);
                    assert_close(&a[d], &b[d], 1e-11 * scale, "continuity");
                }
            }
            // Periodic values: t and t + 2π agree, negative t works.
            for &t in &[0.3, 2.0, 5.0] {
                let (j1, j2, j3) = (jet(&s, t), jet(&s, t + TAU), jet(&s, t - 3.0 * TAU));
                for d in 0..=p {
                    assert_close(&j1[d], &j2[d], 1e-11 * j1[d].norm().max(1.0), "period");
                    assert_close(&j1[d], &j3[d], 1e-11 * j1[d].norm().max(1.0), "period-");
                }
            }
        }
    }

    /// Jet at a knot `k` from the piece on its left (`left`) or right, by evaluating the piece's
    /// polynomial: evaluate slightly inside and Taylor-extrapolate exactly to `k`.
    fn piece_jet(s: &BSpline, k: f64, left: bool) -> [Vec3; 9] {
        let d = 1e-3 * if left { -1.0 } else { 1.0 };
        let j = jet(s, super::super::reduce_periodic(k + d));
        // The piece is a polynomial of degree p: its Taylor series at k+d is exact.
        let mut out = [Vec3::zeros(); 9];
        for (m, o) in out.iter_mut().enumerate() {
            let mut acc = Vec3::zeros();
            let mut f = 1.0;
            for (i, ji) in j.iter().enumerate().skip(m) {
                if i > m {
                    f *= -d / (i - m) as f64;
                }
                acc += ji * f;
            }
            *o = acc;
        }
        out
    }

    #[test]
    fn periodic_fd() {
        let s = BSpline::periodic(5, ctrl(9), None).unwrap();
        let h = TAU / 9.0;
        let ts: Vec<f64> = (0..9).map(|j| (j as f64 + 0.5) * h).collect();
        check_fd(&s, &ts, 1e-4, 5, 10.0);
    }

    #[test]
    fn bad_input_is_rejected() {
        let c = ctrl(5);
        assert!(BSpline::clamped(0, c.clone(), None).is_err());
        assert!(BSpline::clamped(5, c.clone(), None).is_err());
        assert!(BSpline::clamped(3, c.clone(), Some(vec![0.0; 9])).is_err());
        let e = BSpline::clamped(
            3,
            c.clone(),
            Some(vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.4, 1.0, 1.0, 1.0]),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("knots[5]"), "{e}");
        let e = BSpline::clamped(
            3,
            ctrl(8),
            Some(vec![0., 0., 0., 0., 0.5, 0.5, 0.5, 0.5, 1., 1., 1., 1.]),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("repeated"), "{e}");
        assert!(BSpline::clamped(
            3,
            c.clone(),
            Some(vec![0., 0., 0., 0., f64::NAN, 1., 1., 1., 1.])
        )
        .is_err());
        assert!(BSpline::clamped(1, c.clone(), Some(vec![0.0; 7])).is_err());
        let mut bad = c.clone();
        bad[2].y = f64::INFINITY;
        let e = BSpline::clamped(3, bad.clone(), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("control[2]"), "{e}");
        assert!(BSpline::periodic(3, bad, None).is_err());
        assert!(BSpline::periodic(0, c.clone(), None).is_err());
        assert!(BSpline::periodic(5, c.clone(), None).is_err());
        assert!(BSpline::periodic(3, c.clone(), Some(vec![0.0, 1.0, 2.0])).is_err());
        assert!(BSpline::periodic(3, c.clone(), Some(vec![0., 1., 1., 2., 3., 4.])).is_err());
        assert!(BSpline::periodic(3, c.clone(), Some(vec![0., 1., 2., 3., 4., f64::NAN])).is_err());
        assert!(
            BSpline::periodic(3, c.clone(), Some(vec![0., 1., 2., 3., 4., f64::INFINITY])).is_err()
        );
    }

    #[test]
    fn refusals_are_placed_and_worded_as_in_the_design_file() {
        let k = |v: &[f64]| Some(v.to_vec());
        let mut nan1 = ctrl(5);
        nan1[1].z = f64::NAN;
        let cases = [
            (
                BSpline::clamped(0, ctrl(5), None),
                "degree: must be at least 1 (got 0)",
            ),
            (
                BSpline::periodic(0, ctrl(5), None),
                "degree: must be at least 1 (got 0)",
            ),
            (
                BSpline::clamped(31, ctrl(32), None),
                "degree: must be at most 30 (got 31)",
            ),
            (
                BSpline::clamped(3, ctrl(2), None),
                "control: a degree-3 B-spline needs at least 4 control points (got 2)",
            ),
            (
                BSpline::clamped(3, nan1.clone(), None),
                "control[1][2]: must be finite (got NaN)",
            ),
            // Finite control points are checked before their count, as in the design file.
            (
                BSpline::periodic(3, nan1[..2].to_vec(), None),
                "control[1][2]: must be finite (got NaN)",
            ),
            (
                BSpline::clamped(3, ctrl(5), Some(vec![0.0; 8])),
                "knots: needs 9 non-decreasing knots for 5 control points of degree 3 (got 8)",
            ),
            (
                BSpline::clamped(3, ctrl(5), k(&[0., 0., 0., 0., f64::NAN, 1., 1., 1., 1.])),
                "knots[4]: must be finite (got NaN)",
            ),
            (
                BSpline::clamped(3, ctrl(5), k(&[0., 0., 0., 0., 0.5, 0.4, 1., 1., 1.])),
                "knots[5]: must be non-decreasing (got 0.4 after 0.5)",
            ),
            (
                BSpline::clamped(1, ctrl(2), k(&[0., 1., 1., 2.])),
                "knots: the domain [knots[1], knots[2]] = [1, 1] is empty",
            ),
            (
                BSpline::clamped(
                    3,
                    ctrl(8),
                    k(&[0., 0., 0., 0., 0.5, 0.5, 0.5, 0.5, 1., 1., 1., 1.]),
                ),
                "knots[4]: 0.5 is repeated 4 times; at most 3 allowed inside the domain (the \
                 spline would break apart there)",
            ),
            (
                BSpline::clamped(1, ctrl(3), k(&[0., 0., 0., 1., 1.])),
                "knots[0]: 0 is repeated 3 times; at most 2 allowed at or outside the ends of the \
                 domain",
            ),
            (
                BSpline::periodic(3, ctrl(4), k(&[0., 1., 2.])),
                "knots: needs 5 increasing breakpoints for 4 control points of degree 3 (got 3)",
            ),
            (
                BSpline::periodic(3, ctrl(4), k(&[0., 2., 1., 3., 4.])),
                "knots[2]: must be increasing (got 1 after 2)",
            ),
            (
                BSpline::periodic(3, ctrl(4), k(&[0., 1., 1., 3., 4.])),
                "knots[2]: must be increasing (got 1 after 1)",
            ),
            (
                BSpline::periodic(3, ctrl(4), k(&[0., 1., 2., f64::INFINITY, 4.])),
                "knots[3]: must be finite (got inf)",
            ),
            // Increasing, but the first two coincide once scaled to [0, 2π].
            (
                BSpline::periodic(3, ctrl(4), k(&[0., 5e-324, 1e-323, 1.5e-323, 1e300])),
                "knots[1]: is too close to knots[0] = 0 (the breakpoints are scaled to [0, 2π])",
            ),
        ];
        for (i, (r, want)) in cases.into_iter().enumerate() {
            assert_eq!(r.unwrap_err().to_string(), want, "case {i}");
        }
        // Under a curve table the places get the table's prefix.
        let e = BSpline::periodic(3, ctrl(4), k(&[0., 2., 1., 3., 4.]))
            .unwrap_err()
            .at("curves.rim");
        assert_eq!(e.place(), "curves.rim.knots[2]");
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;

    fn ctrl(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let x = i as f64;
                Vec3::new(
                    (0.9 * x).cos() * 2.0,
                    (1.3 * x).sin() * 2.0,
                    0.3 * (0.7 * x).cos(),
                )
            })
            .collect()
    }

    /// The hodograph bounds hold on random intervals; at `k = p` the derivative is one
    /// control point per span, so the bound is attained (ratio 1); below it, the ratio stays
    /// under 3 on these curves (observed at most ≈ 2: hull plus Taylor, whichever is smaller).
    #[test]
    fn bounds_hold_and_are_tight_at_the_degree() {
        let knots: Vec<f64> = (0..=9).map(|i| (i as f64).powf(1.3)).collect();
        let periodic = BSpline::periodic(3, ctrl(9), Some(knots)).unwrap();
        let r = check_bounds(&periodic, 1, 60, 2.0);
        eprintln!("periodic cubic: {r:?}");
        assert!(r[3] <= 1.0 + 1e-6, "{r:?}");
        assert!(r[..3].iter().all(|&x| x <= 3.0), "{r:?}");
        assert_eq!(r[4], 0.0);
        let open = BSpline::clamped(5, ctrl(9), None).unwrap();
        let r = check_bounds(&open, 2, 60, 0.5);
        eprintln!("open quintic: {r:?}");
        assert!(r.iter().all(|&x| x <= 3.0), "{r:?}");
        let quadratic = BSpline::periodic(2, ctrl(7), None).unwrap();
        let r = check_bounds(&quadratic, 3, 60, 3.0);
        assert!(r[2] <= 1.0 + 1e-6, "{r:?}");
        // Outside an open curve's domain (its end pieces extended) there is no bound.
        assert!(!open.derivative_bounds(-0.5, 0.5, &mut [0.0; 5]));
    }

    /// The breaks are the distinct knots inside the domain (periodic: in [0, 2π)).
    #[test]
    fn breaks_are_the_knots() {
        let s = BSpline::periodic(3, ctrl(8), None).unwrap();
        let b = s.breaks();
        assert_eq!(b.len(), 8);
        assert_eq!(s.continuity(), 2);
        assert_eq!(b[0], 0.0);
        assert!((b[1] - TAU / 8.0).abs() < 1e-15);
        let open = BSpline::clamped(3, ctrl(6), None).unwrap();
        assert_eq!(open.breaks(), vec![1.0 / 3.0, 2.0 / 3.0]);
    }
}
