//! Local edits of a curve (book §6.2): a B-spline perturbation between two points.

use super::{reduce_periodic, Curve, Domain, SharedCurve};
use crate::{Error, Result, Vec3};

/// A curve changed only between the parameters `v₁ < v₂` (book §6.2, Eqs. 6.1–6.2):
/// `C̃(v) = C(v) + δ(v)` for `v₁ < v < v₂` and `C̃(v) = C(v)`, the very same values, elsewhere.
///
/// The perturbation is one cubic B-spline, `δ(v) = d · N(v)/N(v₃)`, where `N` is the cubic
/// B-spline basis function on the five simple knots `v₁, (v₁ + v₃)/2, v₃, (v₃ + v₂)/2, v₂` and
/// `v₃ ∈ (v₁, v₂)` the parameter of the handle `X₃ = C(v₃)`: the handle moves by exactly `d`,
/// and `N` is C² at every knot, so the edited curve joins the original at `X₁ = C(v₁)` and
/// `X₂ = C(v₂)` with equal position, tangent and second derivative (C², wherever the original
/// curve is C²). The book's construction (triple control points at the neighbours of `X₁`, `X₂`)
/// reaches C¹ only.
///
/// The displacement is given in the frame of the three points (the book moves `X₃` in the plane
/// of `X₁X₂X₃` or perpendicular to it): `d = along·e₁ + across·e₂ + normal·e₃` with
/// `e₁ = (X₂ − X₁)/|X₂ − X₁|`, `e₃ = e₁ × (X₃ − X₁)` normalised, `e₂ = e₃ × e₁` (towards `X₃`).
///
/// On a periodic curve `v₂ < v₁` means the interval that crosses `v = 0` (`v₂ + 2π`).
#[derive(Clone, Debug)]
pub struct LocalEdit {
    base: SharedCurve,
    /// `v₁`, and the knots relative to it (`t₀ = 0 < t₁ < t₂ < t₃ < t₄ = v₂ − v₁`).
    v1: f64,
    knots: [f64; 5],
    /// `1/ω'(tᵢ) = 1/Π_{j≠i}(tᵢ − tⱼ)`, times `t₄ − t₀` and the scale of `d / N(v₃)`.
    weights: [f64; 5],
    offset: Vec3,
    periodic: bool,
}

/// The points of a local edit and the frame its handle moves in (book §6.2): `X₁ = C(v₁)`,
/// `X₂ = C(v₂)`, the handle `X₃ = C(v₃)`, and the axes `e₁ = (X₂ − X₁)/|X₂ − X₁|`,
/// `e₃ = e₁ × (X₃ − X₁)` normalised, `e₂ = e₃ × e₁` in which [`LocalEdit`] takes the handle's
/// displacement `[along, across, normal]`. An interactive caller moves `X₃` in the plane through
/// it spanned by `e₁, e₂` or along `e₃`, and hands the displacement's components to the edit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFrame {
    /// `v₁` (reduced to `[0, 2π)` on a periodic curve), the length `v₂ − v₁` and `v₃ − v₁`.
    v1: f64,
    len: f64,
    t3: f64,
    /// `X₁ = C(v₁)`, where the edit starts.
    pub x1: Vec3,
    /// `X₂ = C(v₂)`, where the edit ends.
    pub x2: Vec3,
    /// The handle `X₃ = C(v₃)`.
    pub x3: Vec3,
    /// The unit axis `e₁ = (X₂ − X₁)/|X₂ − X₁|` (the `along` direction of a displacement).
    pub e1: Vec3,
    /// `(e₂, e₃)`; `None` when `X₁`, `X₂`, `X₃` are collinear (no plane).
    pub plane: Option<(Vec3, Vec3)>,
}

impl LocalFrame {
    /// The frame of a local edit of `base` from `v₁ = from` to `v₂ = to` with the handle at
    /// `v₃ = at` (default the midpoint); errors as [`LocalEdit::new`] places them.
    pub fn new(base: &dyn Curve, from: f64, to: f64, at: Option<f64>) -> Result<Self> {
        for (v, name) in [(from, "from"), (to, "to")] {
            crate::check::finite(v, name)?;
        }
        let periodic = base.domain() == Domain::Periodic;
        let (v1, len) = if periodic {
            let (a, b) = (reduce_periodic(from), reduce_periodic(to));
            let len = if b > a { b - a } else { b + crate::TAU - a };
            (a, len)
        } else {
            let Domain::Interval(lo, hi) = base.domain() else {
                unreachable!()
            };
            if !(lo <= from && from < to && to <= hi) {
                return Err(Error::invalid(format!(
                    "needs {lo} ≤ from < to ≤ {hi} (got from = {from}, to = {to})"
                ))
                .at("to"));
            }
            (from, to - from)
        };
        if len.is_nan() || len <= 1e-9 || (periodic && from == to) {
            return Err(Error::invalid("the interval from `from` to `to` is empty").at("to"));
        }
        let t3 = match at {
            None => 0.5 * len,
            Some(v) => {
                crate::check::finite(v, "at")?;
                let s = if periodic {
                    reduce_periodic(v - v1)
                } else {
                    v - v1
                };
                if !(s > 0.0 && s < len) {
                    return Err(Error::invalid(format!(
                        "must lie strictly between from = {from} and to = {to} (got {v})"
                    ))
                    .at("at"));
                }
                s
            }
        };
        let x1 = base.point(v1);
        let x2 = base.point(v1 + len);
        let x3 = base.point(v1 + t3);
        let chord = x2 - x1;
        if chord.norm().is_nan() || chord.norm() <= 0.0 {
            return Err(Error::invalid("the points X1 and X2 coincide: no direction e1").at("to"));
        }
        let e1 = chord.normalize();
        let n = e1.cross(&(x3 - x1));
        let plane = (n.norm() > 1e-12 * (x3 - x1).norm().max(chord.norm())).then(|| {
            let e3 = n.normalize();
            (e3.cross(&e1), e3)
        });
        Ok(LocalFrame {
            v1,
            len,
            t3,
            x1,
            x2,
            x3,
            e1,
            plane,
        })
    }

    /// `v₁` (on a periodic curve reduced to `[0, 2π)`).
    pub fn from(&self) -> f64 {
        self.v1
    }

    /// `v₂` (on a periodic curve it may exceed 2π).
    pub fn to(&self) -> f64 {
        self.v1 + self.len
    }

    /// `v₃`, the handle's parameter.
    pub fn at(&self) -> f64 {
        self.v1 + self.t3
    }
}

impl LocalEdit {
    /// `from = v₁`, `to = v₂`, `at = v₃` (default the midpoint) and the handle's displacement
    /// `[along, across, normal]`. Errors are placed at the keys of a `local` curve table.
    pub fn new(
        base: SharedCurve,
        from: f64,
        to: f64,
        at: Option<f64>,
        displacement: [f64; 3],
    ) -> Result<Self> {
        for (v, name) in [(from, "from"), (to, "to")] {
            crate::check::finite(v, name)?;
        }
        for (v, name) in displacement.iter().zip(["along", "across", "normal"]) {
            crate::check::finite(*v, name)?;
        }
        let frame = LocalFrame::new(&*base, from, to, at)?;
        let (v1, len, t3) = (frame.v1, frame.len, frame.t3);
        let knots = [0.0, 0.5 * t3, t3, 0.5 * (t3 + len), len];
        let mut weights = [0.0; 5];
        for (i, w) in weights.iter_mut().enumerate() {
            let prod: f64 = (0..5)
                .filter(|&j| j != i)
                .map(|j| knots[i] - knots[j])
                .product();
            *w = len / prod;
        }
        let periodic = base.domain() == Domain::Periodic;
        let mut edit = LocalEdit {
            base,
            v1,
            knots,
            weights,
            offset: Vec3::zeros(),
            periodic,
        };
        let [along, across, normal] = displacement;
        let (e2, e3) = match frame.plane {
            Some(p) => p,
            None if across == 0.0 && normal == 0.0 => (Vec3::zeros(), Vec3::zeros()),
            None => {
                return Err(Error::invalid(
                    "X1, X2 and X3 are collinear: no plane for `across` and `normal`",
                )
                .at("at"))
            }
        };
        let peak = edit.bump(t3, 0);
        edit.offset = (frame.e1 * along + e2 * across + e3 * normal) / peak;
        Ok(edit)
    }

    /// `v₁` and `v₂` (on a periodic curve `v₂` may exceed 2π).
    pub fn interval(&self) -> (f64, f64) {
        (self.v1, self.v1 + self.knots[4])
    }

    /// `dᵏN/dsᵏ (s)` (times `t₄ − t₀`) at `s = v − v₁ ∈ (t₀, t₄)`, from the truncated powers on
    /// the nearer side, so the value near either end is a single small term (no cancellation).
    fn bump(&self, s: f64, k: usize) -> f64 {
        if k > 3 {
            return 0.0;
        }
        let fall = [1.0, 3.0, 6.0, 6.0][k];
        let mut sum = 0.0;
        if s < self.knots[2] {
            for i in 0..5 {
                if self.knots[i] < s {
                    sum += self.weights[i] * fall * (s - self.knots[i]).powi(3 - k as i32);
                }
            }
        } else {
            let sign = if k % 2 == 1 { -1.0 } else { 1.0 };
            for i in 0..5 {
                if self.knots[i] > s {
                    sum += sign * self.weights[i] * fall * (self.knots[i] - s).powi(3 - k as i32);
                }
            }
        }
        sum
    }

    /// `v − v₁` if `v` lies strictly inside the edited interval.
    fn inside(&self, t: f64) -> Option<f64> {
        let s = if self.periodic {
            reduce_periodic(t - self.v1)
        } else {
            t - self.v1
        };
        (s > 0.0 && s < self.knots[4]).then_some(s)
    }
}

impl Curve for LocalEdit {
    fn domain(&self) -> Domain {
        self.base.domain()
    }

    fn jet(&self, t: f64, out: &mut [Vec3]) {
        self.base.jet(t, out);
        if let Some(s) = self.inside(t) {
            for (k, o) in out.iter_mut().enumerate() {
                *o += self.offset * self.bump(s, k);
            }
        }
    }
    /// The base curve's breaks and the five knots of the bump (its ends and the three points
    /// where its cubic pieces join), reduced to `[0, 2π)` on a periodic curve.
    fn breaks(&self) -> Vec<f64> {
        let mut b = self.base.breaks();
        for k in self.knots {
            let x = self.v1 + k;
            if self.periodic {
                b.push(reduce_periodic(x));
            } else if let Domain::Interval(lo, hi) = self.base.domain() {
                if x > lo && x < hi {
                    b.push(x);
                }
            }
        }
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
    /// The base curve's, at most 2 (the bump is a cubic B-spline on simple knots).
    fn continuity(&self) -> usize {
        self.base.continuity().min(2)
    }
    fn exact_order(&self) -> usize {
        self.base.exact_order()
    }
    /// `|C̃⁽ᵏ⁾| ≤ sup|C⁽ᵏ⁾| + |d/N(v₃)| sup|N⁽ᵏ⁾|`: the base curve's bounds, and the bump's, a
    /// cubic on each piece between its knots (zero outside them), by Taylor's formula about the
    /// middle of every piece of `(t0, t1)` between [`Curve::breaks`].
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        // The bump's Taylor sums below stop at order 4.
        if out.len() > 5 || !self.base.derivative_bounds(t0, t1, out) {
            return false;
        }
        let size = self.offset.norm();
        let mut bump = vec![0.0f64; out.len()];
        for (a, b) in super::pieces(&self.breaks(), self.periodic, t0, t1) {
            let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
            let Some(s) = self.inside(m) else { continue };
            for (k, o) in bump.iter_mut().enumerate() {
                let (mut sum, mut f) = (0.0, 1.0);
                for j in 0..4usize.saturating_sub(k) {
                    sum += self.bump(s, k + j).abs() * f;
                    f *= r / (j + 1) as f64;
                }
                *o = o.max(sum);
            }
        }
        for (o, b) in out.iter_mut().zip(&bump) {
            *o += size * b * (1.0 + super::BOUND_ROUNDING);
        }
        out.iter().all(|o| o.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::{BSpline, Ellipse};
    use std::sync::Arc;

    fn rim() -> SharedCurve {
        Arc::new(Ellipse::circle(Vec3::new(0.0, 0.0, 2.0), 1.5, Vec3::z()).unwrap())
    }

    /// A curve without breaks is smooth everywhere; an edit of it is `C²` at the bump's knots;
    /// its image under an affine map and a sum with a smooth curve keep that.
    #[test]
    fn continuity_through_edits_and_wrappers() {
        use crate::curve::{Affine, Combination, Transformed};
        let circle = rim();
        assert!(circle.breaks().is_empty());
        assert_eq!(circle.continuity(), usize::MAX);
        let edit: SharedCurve =
            Arc::new(LocalEdit::new(circle.clone(), 0.5, 1.5, None, [0.0, 0.1, 0.2]).unwrap());
        assert!(!edit.breaks().is_empty());
        assert_eq!(edit.continuity(), 2);
        let moved = Transformed::new(edit.clone(), Affine::translation(Vec3::x()));
        assert_eq!(moved.continuity(), 2);
        let sum = Combination::new(vec![(0.5, edit), (0.5, circle)]).unwrap();
        assert_eq!(sum.continuity(), 2);
    }

    /// Outside `[v₁, v₂]` the edited curve is the original bit for bit; the handle moves by
    /// exactly the displacement; at `X₁` and `X₂` value, tangent and second derivative are
    /// continuous (one-sided limits agree to rounding), the third is not (C², not C³).
    #[test]
    fn local_edit_is_local_and_c2_at_the_ends() {
        let periodic: SharedCurve = Arc::new(
            BSpline::periodic(
                3,
                (0..8)
                    .map(|k| {
                        let a = crate::TAU * k as f64 / 8.0;
                        Vec3::new(
                            a.cos() * (1.0 + 0.2 * (k % 2) as f64),
                            a.sin(),
                            0.1 * k as f64,
                        )
                    })
                    .collect(),
                None,
            )
            .unwrap(),
        );
        // An open curve on an interval (a clamped cubic B-spline on [0, 1]).
        let open: SharedCurve = Arc::new(
            BSpline::clamped(
                3,
                (0..7)
                    .map(|k| Vec3::new(k as f64, (k * k % 5) as f64 * 0.3, 0.2 * k as f64))
                    .collect(),
                None,
            )
            .unwrap(),
        );
        let bits = |c: &dyn Curve, v: f64| {
            let mut j = [Vec3::zeros(); 4];
            c.jet(v, &mut j);
            j.map(|x| [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()])
        };
        // Plain, wrapping across v = 0, with the handle off-centre, and on an interval.
        for (base, from, to, at) in [
            (rim(), 1.0, 2.2, None),
            (rim(), 5.8, 0.7, Some(0.2)),
            (periodic.clone(), 2.0, 3.5, Some(2.4)),
            (open.clone(), 0.3, 0.55, Some(0.4)),
        ] {
            let e = LocalEdit::new(base.clone(), from, to, at, [0.1, 0.3, -0.2]).unwrap();
            let (v1, v2) = e.interval();
            let (lo, hi) = match base.domain() {
                Domain::Interval(a, b) => (a, b),
                Domain::Periodic => (0.0, crate::TAU),
            };
            // Bit for bit outside: the samples outside, and just outside either end.
            let mut outside = 0;
            for k in 0..=4000 {
                let v = lo + (hi - lo) * k as f64 / 4000.0;
                if e.inside(v).is_none() {
                    outside += 1;
                    assert_eq!(bits(&e, v), bits(&*base, v), "v = {v}");
                }
            }
            assert!(outside > 1000, "{outside}");
            for v in [v1 - 1e-9, v2 + 1e-9, from - 1e-9, to + 1e-9] {
                if (lo..=hi).contains(&v) || base.domain() == Domain::Periodic {
                    assert_eq!(bits(&e, v), bits(&*base, v), "at {v}");
                }
            }
            // The handle.
            let v3 = at.unwrap_or(0.5 * (v1 + v2));
            let moved = e.point(v3) - base.point(v3);
            assert!((moved.norm() - (0.1f64 * 0.1 + 0.09 + 0.04).sqrt()).abs() < 1e-14);
            assert!(moved.norm() > 0.3);
            // Continuity at both ends: the jump between one-sided limits at distance h shrinks
            // like h^(3−k) for the k-th derivative.
            for end in [v1, v2] {
                for k in 0..3 {
                    let h = 1e-6;
                    let jump = (e.derivative(end + h, k) - e.derivative(end - h, k)).norm();
                    let base_jump =
                        (base.derivative(end + h, k) - base.derivative(end - h, k)).norm();
                    // |δ⁽ᵏ⁾(h)| ≤ |d/N(v₃)| Σ|wᵢ| 3!/(3−k)! h^(3−k) on the edited side.
                    let w: f64 = e.weights.iter().map(|w| w.abs()).sum();
                    let bound =
                        e.offset.norm() * w * 6.0 * h.powi(3 - k as i32) + base_jump + 1e-12;
                    assert!(jump <= bound, "end {end}, derivative {k}: jump {jump}");
                }
                let h = 1e-6;
                let j3 = (e.derivative(end + h, 3) - e.derivative(end - h, 3)).norm();
                let b3 = (base.derivative(end + h, 3) - base.derivative(end - h, 3)).norm();
                assert!(j3 > b3 + 1e-3, "the third derivative should jump at {end}");
            }
        }
    }

    #[test]
    fn bad_local_edits_are_refused_with_their_place() {
        let e = LocalEdit::new(rim(), 1.0, 2.0, Some(3.0), [0.0, 0.1, 0.0]).unwrap_err();
        assert_eq!(e.place(), "at");
        let e = LocalEdit::new(rim(), 1.0, 1.0, None, [0.0, 0.1, 0.0]).unwrap_err();
        assert_eq!(e.place(), "to");
        let e = LocalEdit::new(rim(), 1.0, f64::NAN, None, [0.0, 0.1, 0.0]).unwrap_err();
        assert_eq!(e.place(), "to");
    }

    /// The frame's handle moved by `d` in its axes is where the edited curve passes at `v₃`,
    /// across `v = 0` too; `from` is reduced and `to` follows it.
    #[test]
    fn the_frame_is_the_one_the_edit_moves_the_handle_in() {
        for (from, to, at) in [(1.0, 2.5, None), (5.8, 0.6, Some(0.2))] {
            let f = LocalFrame::new(&*rim(), from, to, at).unwrap();
            let (e2, e3) = f.plane.unwrap();
            let [along, across, normal] = [0.05, 0.2, -0.1];
            let e = LocalEdit::new(rim(), from, to, at, [along, across, normal]).unwrap();
            let moved = f.x3 + f.e1 * along + e2 * across + e3 * normal;
            assert!((e.point(f.at()) - moved).norm() < 1e-12);
            assert!((f.x1 - rim().point(from)).norm() < 1e-12);
            assert!((f.x2 - rim().point(to)).norm() < 1e-12);
            assert!(f.from() >= 0.0 && f.to() > f.from());
            assert_eq!(e.interval(), (f.from(), f.to()));
        }
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::super::{BSpline, Ellipse};
    use super::*;
    use std::sync::Arc;

    /// An edit adds its bump's knots to the base curve's breaks; the bounds hold on random
    /// intervals, also for an edit across `v = 0` and on a B-spline base, and the bump's
    /// third derivative (constant on each of its pieces) keeps them within a factor 3.
    #[test]
    fn bounds_hold_for_edits() {
        let circle: SharedCurve = Arc::new(Ellipse::circle(Vec3::zeros(), 1.0, Vec3::z()).unwrap());
        let edit = LocalEdit::new(circle.clone(), 5.7, 0.6, None, [0.0, 0.3, 0.1]).unwrap();
        assert_eq!(edit.breaks().len(), 5);
        let r = check_bounds(&edit, 15, 80, 2.0);
        eprintln!("local on a circle: {r:?}");
        let c: Vec<Vec3> = (0..10)
            .map(|i| {
                let t = crate::TAU * i as f64 / 10.0;
                Vec3::new(t.cos(), t.sin(), 0.1 * (3.0 * t).sin())
            })
            .collect();
        let spline: SharedCurve = Arc::new(BSpline::periodic(3, c, None).unwrap());
        let edit = LocalEdit::new(spline, 1.0, 2.5, Some(1.4), [0.1, -0.2, 0.3]).unwrap();
        assert_eq!(edit.breaks().len(), 10 + 5);
        let r = check_bounds(&edit, 16, 80, 1.5);
        eprintln!("local on a spline: {r:?}");
        assert!(r[3] <= 3.0, "{r:?}");
    }
}
