//! Curves for the designer: circles or ellipses turned into B-splines whose control points can
//! be dragged. (Control points through a curve's `transform`: `pdeshape::design::
//! world_control_points` and `spec_point`.)

use pdeshape::curve::{Curve, Domain};
use pdeshape::spec::{CurveKind, CurveSpec, V3};
use pdeshape::TAU;

/// Control points of a periodic cubic B-spline made from an ellipse.
pub(super) const BSPLINE_POINTS: usize = 8;

#[cfg(test)]
fn v3(p: &V3) -> pdeshape::Vec3 {
    pdeshape::Vec3::new(p[0], p[1], p[2])
}

/// A periodic cubic B-spline of [`BSPLINE_POINTS`] control points approximating the ellipse
/// `curve` (a built circle or ellipse, transforms included): `c + cos v a₁ + sin v a₂` with
/// `c = (C(0) + C(π))/2`, `a₁ = C(0) − c`, `a₂ = C(π/2) − c`.
///
/// The uniform periodic cubic passes through `(P_{k−1} + 4P_k + P_{k+1})/6` at its knot `t_k`
/// (on `[t_j, t_{j+1}]` it uses `P_j … P_{j+3}`, so knot 0 sits at `P_1`); with
/// `P_k = c + ρ (cos θ_k a₁ + sin θ_k a₂)`, `θ_k = (k − 1)h`, `h = 2π/n`, that point is
/// `c + ρ (2 + cos h)/3 (cos θ a₁ + sin θ a₂)`. So `ρ = 3/(2 + cos h)` puts every knot on the
/// ellipse, knot 0 at `C(0)`: `v = 0` stays where it was and the direction of `v` is kept.
/// (Between knots the radius dips by at most 0.2 % for n = 8.) The result has no transform:
/// its control points are where they are drawn.
pub(super) fn bspline_from_ellipse(curve: &dyn Curve) -> Option<CurveSpec> {
    if curve.domain() != Domain::Periodic {
        return None;
    }
    let c = (curve.point(0.0) + curve.point(std::f64::consts::PI)) / 2.0;
    let a1 = curve.point(0.0) - c;
    let a2 = curve.point(std::f64::consts::FRAC_PI_2) - c;
    let n = BSPLINE_POINTS;
    let h = TAU / n as f64;
    let rho = 3.0 / (2.0 + h.cos());
    let control: Vec<V3> = (0..n)
        .map(|k| {
            let t = (k as f64 - 1.0) * h;
            let p = c + (a1 * t.cos() + a2 * t.sin()) * rho;
            [p.x, p.y, p.z]
        })
        .collect();
    if control.iter().flatten().any(|x| !x.is_finite()) {
        return None;
    }
    Some(CurveSpec {
        kind: CurveKind::BSpline {
            degree: 3,
            control,
            knots: None,
            periodic: true,
            weights: None,
        },
        transform: Vec::new(),
        v_origin: 0.0,
        arc_length: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdeshape::curve::{BSpline, Ellipse};
    use pdeshape::Vec3;

    /// The B-spline meets the circle at every knot (exactly, to rounding), keeps v = 0 and the
    /// direction of v, and stays within the analysed 0.2 % between knots.
    #[test]
    fn bspline_from_circle_meets_it_at_the_knots() {
        let circle =
            Ellipse::circle(Vec3::new(0.3, -0.2, 1.0), 1.5, Vec3::new(0.2, 0.1, 1.0)).unwrap();
        let spec = bspline_from_ellipse(&circle).unwrap();
        let CurveKind::BSpline { control, .. } = &spec.kind else {
            panic!("not a B-spline");
        };
        let b = BSpline::periodic(3, control.iter().map(v3).collect(), None).unwrap();
        let h = TAU / BSPLINE_POINTS as f64;
        for k in 0..BSPLINE_POINTS {
            let t = k as f64 * h;
            let d = (b.point(t) - circle.point(t)).norm();
            assert!(d < 1e-12, "knot {k}: {d}");
        }
        let mut worst: f64 = 0.0;
        for k in 0..512 {
            let t = TAU * k as f64 / 512.0;
            worst = worst.max((b.point(t) - circle.point(t)).norm());
        }
        assert!(worst < 0.002 * 1.5, "worst {worst}");
        // Same direction of travel at v = 0.
        assert!(b.derivative(0.0, 1).dot(&circle.derivative(0.0, 1)) > 0.0);
    }
}
