//! Curves for the designer: control points in world coordinates (through a curve's
//! `transform`), and circles or ellipses turned into B-splines whose control points can be
//! dragged.

use pdeshape::curve::{Affine, Curve, Domain};
use pdeshape::spec::{CurveKind, CurveSpec, TransformStep, V3};
use pdeshape::{Vec3, TAU};

/// Control points of a periodic cubic B-spline made from an ellipse.
pub const BSPLINE_POINTS: usize = 8;

fn v3(p: &V3) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

/// The affine map of a curve's `transform` steps (`None` if a step is invalid: the design
/// layer reports that).
pub fn transform_map(cs: &CurveSpec) -> Option<Affine> {
    let mut map = Affine::identity();
    for step in &cs.transform {
        let next = match step {
            TransformStep::Translate(d) => Affine::translation(v3(d)),
            TransformStep::Rotate { axis, angle, about } => {
                Affine::rotation(v3(axis), angle.to_radians(), v3(about)).ok()?
            }
            TransformStep::Scale { factor, about } => Affine::scaling(*factor, v3(about)).ok()?,
            TransformStep::Dilate { factors, about } => {
                Affine::dilation(v3(factors), v3(about)).ok()?
            }
        };
        map = map.then(&next);
    }
    Some(map)
}

/// The control points of a B-spline, Bézier or samples curve, where they are drawn (after the
/// curve's transform).
pub fn world_control_points(cs: &CurveSpec) -> Option<Vec<V3>> {
    let points = match &cs.kind {
        CurveKind::BSpline { control, .. } | CurveKind::Bezier { control } => control,
        CurveKind::Samples { points, .. } => points,
        _ => return None,
    };
    let map = transform_map(cs)?;
    Some(
        points
            .iter()
            .map(|p| {
                let q = map.apply_point(&v3(p));
                [q.x, q.y, q.z]
            })
            .collect(),
    )
}

/// The control point that the curve's transform carries to `world` (the inverse map); `None`
/// when the map is singular.
pub fn spec_point(cs: &CurveSpec, world: V3) -> Option<V3> {
    let map = transform_map(cs)?;
    let inverse = map.linear.try_inverse()?;
    let p = inverse * (v3(&world) - map.shift);
    p.iter().all(|x| x.is_finite()).then_some([p.x, p.y, p.z])
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
pub fn bspline_from_ellipse(curve: &dyn Curve) -> Option<CurveSpec> {
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

    #[test]
    fn control_points_map_through_the_transform_and_back() {
        let cs = CurveSpec {
            kind: CurveKind::Bezier {
                control: vec![[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]],
            },
            transform: vec![
                TransformStep::Translate([1.0, 0.0, 0.0]),
                TransformStep::Rotate {
                    axis: [0.0, 0.0, 1.0],
                    angle: 90.0,
                    about: [0.0, 0.0, 0.0],
                },
                TransformStep::Scale {
                    factor: 2.0,
                    about: [0.0, 0.0, 0.0],
                },
            ],
            v_origin: 0.0,
            arc_length: false,
        };
        let w = world_control_points(&cs).unwrap();
        // (1,2,3) → (2,2,3) → (−2,2,3) → (−4,4,6).
        for (a, b) in w[0].iter().zip([-4.0, 4.0, 6.0]) {
            assert!((a - b).abs() < 1e-12, "{:?}", w[0]);
        }
        let back = spec_point(&cs, w[0]).unwrap();
        for (a, b) in back.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
    }
}
