use super::{Curve, Domain, FourierSeries};
use crate::check::{finite3, nonzero_vector, positive};
use crate::{Error, Result, Vec3};

/// A constant curve: the degenerate "curve" that closes a surface to a pole.
#[derive(Clone, Debug)]
pub struct Point {
    /// The point the curve stays at.
    pub p: Vec3,
}

impl Point {
    /// The constant curve at `p` (not checked; see [`Point::try_new`]).
    pub fn new(p: Vec3) -> Self {
        Point { p }
    }

    /// [`Point::new`], refusing a point that is not finite (place `at[c]`, as in the design
    /// file's `point` table).
    pub fn try_new(p: Vec3) -> Result<Self> {
        finite3(&p, "at")?;
        Ok(Point { p })
    }
}

impl Curve for Point {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, _t: f64, out: &mut [Vec3]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = if k == 0 { self.p } else { Vec3::zeros() };
        }
    }
    /// `|C| = |p|`, every derivative zero.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        for (k, o) in out.iter_mut().enumerate() {
            *o = if k == 0 { self.p.norm() } else { 0.0 };
        }
        t0 < t1 && out.iter().all(|o| o.is_finite())
    }
    /// The series with `a₀ = p` and no modes.
    fn fourier(&self) -> Option<FourierSeries> {
        Some(FourierSeries {
            a0: self.p,
            cos: Vec::new(),
            sin: Vec::new(),
        })
    }
}

/// `C(v) = c + cos v · a₁ + sin v · a₂` on `[0, 2π)`: circles and ellipses.
#[derive(Clone, Debug)]
pub struct Ellipse {
    /// Centre `c`.
    pub center: Vec3,
    /// Semi-axis vector `a₁`: `C(0) = c + a₁`.
    pub axis1: Vec3,
    /// Semi-axis vector `a₂`: `C(π/2) = c + a₂`.
    pub axis2: Vec3,
}

/// Relative tolerance below which two axes count as dependent: `|a₁ × a₂| ≤ tol·|a₁||a₂|`.
const DEPENDENT_TOL: f64 = 1e-12;

/// The unit start direction of a circle about `normal`: the projection of +x on the plane normal
/// to `normal`, or of +y when `normal` is along x. `normal` must be a unit vector.
fn start_direction(n: &Vec3) -> Vec3 {
    let project = |e: Vec3| e - n * n.dot(&e);
    let px = project(Vec3::x());
    if px.norm() > 1e-12 {
        px.normalize()
    } else {
        project(Vec3::y()).normalize()
    }
}

/// `normal` scaled to unit length; checked as in the design file (place `normal`).
fn unit_normal(normal: &Vec3) -> Result<Vec3> {
    nonzero_vector(normal, "normal")?;
    // Scale first so that huge or tiny normals neither overflow nor underflow.
    Ok((normal / normal.amax()).normalize())
}

impl Ellipse {
    /// General ellipse from its two (conjugate) semi-axis vectors; they must be finite, non-zero
    /// and independent (`|a₁ × a₂| > 10⁻¹² |a₁||a₂|`). Errors are placed as in an `ellipse`
    /// table of the design file: `center[c]`, `axis1`, `axis2`.
    pub fn new(center: Vec3, axis1: Vec3, axis2: Vec3) -> Result<Self> {
        finite3(&center, "center")?;
        nonzero_vector(&axis1, "axis1")?;
        nonzero_vector(&axis2, "axis2")?;
        // Scaled first, so that huge axes (1e300) neither overflow nor pass as parallel.
        let (a, b) = (axis1 / axis1.amax(), axis2 / axis2.amax());
        if a.cross(&b).norm() <= DEPENDENT_TOL * a.norm() * b.norm() {
            return Err(
                Error::invalid("axis1 and axis2 are parallel: the ellipse is degenerate")
                    .at("axis2"),
            );
        }
        Ok(Ellipse {
            center,
            axis1,
            axis2,
        })
    }
    /// Circle of `radius > 0` about `center` in the plane normal to `normal`, starting (v = 0)
    /// along the projection of +x on that plane (+y if the normal is along x). With that unit
    /// start direction `e`: `a₁ = r e`, `a₂ = r n̂ × e`, so the circle runs counter-clockwise
    /// about the normal. Errors are placed as in a `circle` table: `center[c]`, `radius`,
    /// `normal`.
    pub fn circle(center: Vec3, radius: f64, normal: Vec3) -> Result<Self> {
        finite3(&center, "center")?;
        positive(radius, "radius")?;
        Self::with_radii(center, radius, radius, normal)
    }
    /// Axis-aligned ellipse with semi-axes `rx` (along the circle's start direction) and `ry`.
    /// Errors are placed as in an `ellipse` table: `center[c]`, `rx`, `ry`, `normal`.
    pub fn with_radii(center: Vec3, rx: f64, ry: f64, normal: Vec3) -> Result<Self> {
        finite3(&center, "center")?;
        positive(rx, "rx")?;
        positive(ry, "ry")?;
        let n = unit_normal(&normal)?;
        let e = start_direction(&n);
        Ok(Ellipse {
            center,
            axis1: e * rx,
            axis2: n.cross(&e) * ry,
        })
    }
}

impl Curve for Ellipse {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    /// `C⁽ᵏ⁾(v) = cos(v + kπ/2) a₁ + sin(v + kπ/2) a₂` (plus `c` for `k = 0`).
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let (s, c) = super::reduce_periodic(t).sin_cos();
        for (k, o) in out.iter_mut().enumerate() {
            let (ck, sk) = match k % 4 {
                0 => (c, s),
                1 => (-s, c),
                2 => (-c, -s),
                _ => (s, -c),
            };
            *o = self.axis1 * ck + self.axis2 * sk;
            if k == 0 {
                *o += self.center;
            }
        }
    }
    /// `sup_θ |cos θ a₁ + sin θ a₂|` is the largest singular value of `[a₁ a₂]`
    /// ([`crate::fourier::mode_size`]), attained; plus `|c|` for `k = 0`.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let r = crate::fourier::mode_size(&self.axis1, &self.axis2) * (1.0 + super::BOUND_ROUNDING);
        for (k, o) in out.iter_mut().enumerate() {
            *o = if k == 0 {
                self.center.norm() * (1.0 + super::BOUND_ROUNDING) + r
            } else {
                r
            };
        }
        t0 < t1 && out.iter().all(|o| o.is_finite())
    }
    /// Exact: `a₀ = c`, one mode with `a₁`, `b₁` the axes.
    fn fourier(&self) -> Option<FourierSeries> {
        Some(FourierSeries {
            a0: self.center,
            cos: vec![self.axis1],
            sin: vec![self.axis2],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;
    use crate::TAU;

    #[test]
    fn ellipse_jet_matches_closed_form_and_fd() {
        let e = Ellipse::new(
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(2.0, 0.5, 0.0),
            Vec3::new(0.0, 1.0, 1.5),
        )
        .unwrap();
        for &v in &[0.0, 0.3, 2.0, 5.9, -1.0, 100.0] {
            let j = jet(&e, v);
            for (k, d) in j.iter().enumerate() {
                // d^k/dv^k cos v = cos(v + kπ/2).
                let ph = v + k as f64 * std::f64::consts::FRAC_PI_2;
                let mut want = e.axis1 * ph.cos() + e.axis2 * ph.sin();
                if k == 0 {
                    want += e.center;
                }
                assert_close(d, &want, 1e-13, "ellipse derivative");
            }
        }
        check_fd(&e, &[0.1, 1.0, 3.0, 6.2], 1e-4, 5, 3.0);
    }

    #[test]
    fn circle_orientation_and_start() {
        let c = Ellipse::circle(Vec3::zeros(), 2.0, Vec3::new(0.0, 0.0, 3.0)).unwrap();
        assert_close(&c.point(0.0), &Vec3::new(2.0, 0.0, 0.0), 1e-15, "start");
        assert_close(
            &c.point(TAU / 4.0),
            &Vec3::new(0.0, 2.0, 0.0),
            1e-15,
            "quarter",
        );
        // Counter-clockwise about the normal: (C − c) × C' along n.
        let j = jet(&c, 0.7);
        assert!(j[0].cross(&j[1]).dot(&Vec3::z()) > 0.0);
        // Normal along x: start along +y.
        let c = Ellipse::circle(Vec3::zeros(), 1.0, Vec3::new(-2.0, 0.0, 0.0)).unwrap();
        assert_close(&c.point(0.0), &Vec3::y(), 1e-15, "start y");
        assert!(c.axis1.cross(&c.axis2).dot(&Vec3::new(-1.0, 0.0, 0.0)) > 0.0);
        // Oblique normal: start is the normalised projection of +x.
        let n = Vec3::new(1.0, 1.0, 1.0);
        let c = Ellipse::with_radii(Vec3::zeros(), 3.0, 1.0, n).unwrap();
        let want = (Vec3::x() - n * (n.dot(&Vec3::x()) / n.norm_squared())).normalize() * 3.0;
        assert_close(&c.axis1, &want, 4e-15, "oblique start");
        assert!((c.axis2.norm() - 1.0).abs() < 1e-15);
        assert!(c.axis1.dot(&c.axis2).abs() < 1e-15);
        assert!(c.axis1.dot(&n).abs() < 1e-14 && c.axis2.dot(&n).abs() < 1e-14);
    }

    #[test]
    fn fourier_is_exact() {
        let e = Ellipse::with_radii(Vec3::new(0.0, 0.0, 1.0), 2.0, 1.0, Vec3::z()).unwrap();
        let f = e.fourier().unwrap();
        for &v in &[0.0, 1.0, 4.0] {
            assert_close(&f.point(v), &e.point(v), 1e-15, "series");
        }
        let p = Point::new(Vec3::new(1.0, 2.0, 3.0));
        let f = p.fourier().unwrap();
        assert_eq!(f.modes(), 0);
        assert_eq!(f.a0, p.p);
    }

    #[test]
    fn bad_input_is_rejected() {
        let z = Vec3::zeros();
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        let inf = Vec3::new(0.0, f64::INFINITY, 0.0);
        assert!(Ellipse::circle(z, 0.0, Vec3::z()).is_err());
        assert!(Ellipse::circle(z, -1.0, Vec3::z()).is_err());
        assert!(Ellipse::circle(z, f64::NAN, Vec3::z()).is_err());
        assert!(Ellipse::circle(z, f64::INFINITY, Vec3::z()).is_err());
        let e = Ellipse::circle(z, 1.0, z).unwrap_err().to_string();
        assert!(e.contains("normal"), "{e}");
        assert!(Ellipse::circle(z, 1.0, nan).is_err());
        let big = Ellipse::circle(z, 1.0, Vec3::new(0.0, 0.0, 1e300)).unwrap();
        assert_close(&big.axis2, &Vec3::y(), 1e-15, "huge normal");
        let tiny = Ellipse::circle(z, 1.0, Vec3::new(0.0, 0.0, 1e-310)).unwrap();
        assert_close(&tiny.axis2, &Vec3::y(), 1e-15, "tiny normal");
        assert!(Ellipse::circle(nan, 1.0, Vec3::z()).is_err());
        let e = Ellipse::circle(z, -2.0, Vec3::z()).unwrap_err().to_string();
        assert!(e.contains("radius: must be positive (got -2)"), "{e}");
        assert!(Ellipse::with_radii(z, 1.0, 0.0, Vec3::z()).is_err());
        assert!(Ellipse::new(z, Vec3::x(), Vec3::x() * 2.0).is_err());
        assert!(Ellipse::new(z, Vec3::x(), z).is_err());
        assert!(Ellipse::new(z, inf, Vec3::y()).is_err());
        assert!(Ellipse::new(nan, Vec3::x(), Vec3::y()).is_err());
        let e = Ellipse::new(z, Vec3::x(), -Vec3::x())
            .unwrap_err()
            .to_string();
        assert!(e.contains("parallel"), "{e}");
    }

    #[test]
    fn refusals_are_placed_and_worded_as_in_the_design_file() {
        let err = |r: Result<Ellipse>| r.unwrap_err().to_string();
        let (z, x, y) = (Vec3::zeros(), Vec3::x(), Vec3::y());
        let nan = Vec3::new(0.0, f64::NAN, 0.0);
        assert_eq!(
            err(Ellipse::circle(nan, 1.0, Vec3::z())),
            "center[1]: must be finite (got NaN)"
        );
        assert_eq!(
            err(Ellipse::circle(z, -1.0, Vec3::z())),
            "radius: must be positive (got -1)"
        );
        assert_eq!(
            err(Ellipse::circle(z, -1e-300, Vec3::z())),
            "radius: must be positive (got -1e-300)"
        );
        assert_eq!(
            err(Ellipse::circle(z, f64::INFINITY, Vec3::z())),
            "radius: must be finite (got inf)"
        );
        assert_eq!(
            err(Ellipse::circle(z, 1.0, z)),
            "normal: must not be the zero vector"
        );
        assert_eq!(
            err(Ellipse::circle(z, 1.0, nan)),
            "normal[1]: must be finite (got NaN)"
        );
        assert_eq!(
            err(Ellipse::with_radii(z, 0.0, 1.0, Vec3::z())),
            "rx: must be positive (got 0)"
        );
        assert_eq!(
            err(Ellipse::with_radii(z, 1.0, f64::NAN, Vec3::z())),
            "ry: must be finite (got NaN)"
        );
        assert_eq!(
            err(Ellipse::with_radii(z, 1.0, 2.0, z)),
            "normal: must not be the zero vector"
        );
        assert_eq!(
            err(Ellipse::new(nan, x, y)),
            "center[1]: must be finite (got NaN)"
        );
        assert_eq!(
            err(Ellipse::new(z, z, y)),
            "axis1: must not be the zero vector"
        );
        assert_eq!(
            err(Ellipse::new(z, x, nan)),
            "axis2[1]: must be finite (got NaN)"
        );
        assert_eq!(
            err(Ellipse::new(z, x, x * -3.0)),
            "axis2: axis1 and axis2 are parallel: the ellipse is degenerate"
        );
        // Huge axes are independent directions like any other (their products overflow).
        let huge = Vec3::new(1e300, 1e300, 0.0);
        assert!(Ellipse::new(z, huge, Vec3::new(0.0, 0.0, 1e300)).is_ok());
        assert!(Ellipse::new(z, huge, huge * 0.5).is_err());
        let e = Ellipse::new(z, x, x).unwrap_err().at("curves.rim");
        assert_eq!(e.place(), "curves.rim.axis2");
        let e = Point::try_new(Vec3::new(1.0, 2.0, f64::INFINITY)).unwrap_err();
        assert_eq!(e.to_string(), "at[2]: must be finite (got inf)");
        assert_eq!(Point::try_new(x).unwrap().p, x);
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;
    use crate::TAU;

    /// Circles attain the bound of every derivative; ellipses' hold.
    #[test]
    fn bounds_hold_and_circles_attain_them() {
        let c = Ellipse::circle(Vec3::zeros(), 2.0, Vec3::new(0.3, 0.1, 1.0)).unwrap();
        let r = check_bounds(&c, 8, 30, TAU);
        assert!(r.iter().all(|&x| x <= 1.0 + 1e-6), "{r:?}");
        let e = Ellipse::new(
            Vec3::new(1.0, 2.0, 0.5),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.3),
        )
        .unwrap();
        check_bounds(&e, 9, 30, TAU);
        // Over a whole period sup|C⁽ᵏ⁾| (k ≥ 1) is the largest singular value of [a₁ a₂], at
        // least (|a₁|² + |a₂|²)^{1/2}/√2: the bound is within √2.
        let mut b = [0.0; 5];
        assert!(e.derivative_bounds(0.0, TAU, &mut b));
        for (k, bk) in b.iter().enumerate().skip(1) {
            let seen = (0..2000)
                .map(|i| e.derivative(TAU * i as f64 / 2000.0, k).norm())
                .fold(0.0, f64::max);
            assert!(
                seen <= *bk && *bk <= 2f64.sqrt() * seen * (1.0 + 1e-6),
                "{k}: {seen} {bk}"
            );
        }
        let p = Point::new(Vec3::new(1.0, 2.0, 3.0));
        let r = check_bounds(&p, 10, 5, 1.0);
        assert!(r[0] <= 1.0 + 1e-6);
    }
}
