use super::{check_finite, Curve, Domain, FourierSeries, SharedCurve, MAX_ORDER};
use crate::{Error, Result, Vec3};

/// An affine map `x ↦ M x + t` of R³: the design parameters of §6.1 (translate, rotate about an
/// axis through a point, scale about a point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    /// The matrix `M`.
    pub linear: nalgebra::Matrix3<f64>,
    /// The translation `t`.
    pub shift: Vec3,
}

impl Affine {
    /// The identity map (`M = I`, `t = 0`).
    pub fn identity() -> Self {
        Affine {
            linear: nalgebra::Matrix3::identity(),
            shift: Vec3::zeros(),
        }
    }
    /// The translation `x ↦ x + d`.
    pub fn translation(d: Vec3) -> Self {
        Affine {
            linear: nalgebra::Matrix3::identity(),
            shift: d,
        }
    }
    /// Rotation by `angle` radians (right-handed) about the line through `about` along `axis`:
    /// Rodrigues' formula `R = cos θ I + sin θ [k]ₓ + (1 − cos θ) k kᵀ` with `k = axis/|axis|`,
    /// and `x ↦ R (x − about) + about`. The axis must be finite and non-zero, the angle finite.
    pub fn rotation(axis: Vec3, angle: f64, about: Vec3) -> Result<Self> {
        check_finite("axis", &axis)?;
        check_finite("about", &about)?;
        if !angle.is_finite() {
            return Err(Error::invalid(format!("angle = {angle} is not finite")));
        }
        let big = axis.amax();
        if big == 0.0 {
            return Err(Error::invalid(format!(
                "axis = ({}, {}, {}) must be a non-zero vector",
                axis.x, axis.y, axis.z
            )));
        }
        let k = (axis / big).normalize();
        let (s, c) = angle.sin_cos();
        let cross = nalgebra::Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
        let linear = nalgebra::Matrix3::identity() * c + cross * s + k * k.transpose() * (1.0 - c);
        Ok(Affine {
            linear,
            shift: about - linear * about,
        })
    }
    /// Uniform scaling by `factor ≠ 0` about the point `about`: `x ↦ f (x − about) + about`.
    pub fn scaling(factor: f64, about: Vec3) -> Result<Self> {
        check_finite("about", &about)?;
        if !factor.is_finite() || factor == 0.0 {
            return Err(Error::invalid(format!(
                "factor = {factor} must be a finite non-zero number"
            )));
        }
        Ok(Affine {
            linear: nalgebra::Matrix3::identity() * factor,
            shift: about * (1.0 - factor),
        })
    }
    /// Scaling by `factors = (f_x, f_y, f_z)`, each finite and non-zero, along the coordinate
    /// axes about the point `about`: `x ↦ diag(f) (x − about) + about`.
    pub fn dilation(factors: Vec3, about: Vec3) -> Result<Self> {
        check_finite("about", &about)?;
        if factors.iter().any(|f| !f.is_finite() || *f == 0.0) {
            return Err(Error::invalid(format!(
                "factors = ({}, {}, {}) must be finite and non-zero",
                factors.x, factors.y, factors.z
            )));
        }
        let linear = nalgebra::Matrix3::from_diagonal(&factors);
        Ok(Affine {
            linear,
            shift: about - linear * about,
        })
    }
    /// `self` followed by `next`.
    pub fn then(&self, next: &Affine) -> Affine {
        Affine {
            linear: next.linear * self.linear,
            shift: next.linear * self.shift + next.shift,
        }
    }
    /// The image `M p + t` of a point.
    pub fn apply_point(&self, p: &Vec3) -> Vec3 {
        self.linear * p + self.shift
    }
    /// The image `M d` of a vector (a difference of points or a derivative: the translation does
    /// not act).
    pub fn apply_vector(&self, d: &Vec3) -> Vec3 {
        self.linear * d
    }
}

/// An affine image of a curve.
#[derive(Clone, Debug)]
pub struct Transformed {
    /// The curve that is mapped.
    pub inner: SharedCurve,
    /// The map applied to it.
    pub map: Affine,
}

impl Transformed {
    /// The image of `inner` under `map`.
    pub fn new(inner: SharedCurve, map: Affine) -> Self {
        Transformed { inner, map }
    }
}

impl Curve for Transformed {
    fn domain(&self) -> Domain {
        self.inner.domain()
    }
    /// `(M C + t)⁽ᵏ⁾ = M C⁽ᵏ⁾` for `k ≥ 1`.
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        self.inner.jet(t, out);
        for (k, o) in out.iter_mut().enumerate() {
            *o = if k == 0 {
                self.map.apply_point(o)
            } else {
                self.map.apply_vector(o)
            };
        }
    }
    fn breaks(&self) -> Vec<f64> {
        self.inner.breaks()
    }
    fn continuity(&self) -> usize {
        self.inner.continuity()
    }
    fn exact_order(&self) -> usize {
        self.inner.exact_order()
    }
    /// `|M C⁽ᵏ⁾| ≤ ‖M‖₂ |C⁽ᵏ⁾|` (the spectral norm, from the eigenvalues of `MᵀM`), plus `|t|`
    /// for `k = 0`.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        if !self.inner.derivative_bounds(t0, t1, out) {
            return false;
        }
        let norm = spectral_norm(&self.map.linear) * (1.0 + super::BOUND_ROUNDING);
        for (k, o) in out.iter_mut().enumerate() {
            *o *= norm;
            if k == 0 {
                *o += self.map.shift.norm() * (1.0 + super::BOUND_ROUNDING);
            }
        }
        out.iter().all(|o| o.is_finite())
    }
    /// The inner exact series mapped: `a₀ ↦ M a₀ + t`, `aₙ ↦ M aₙ`, `bₙ ↦ M bₙ`.
    fn fourier(&self) -> Option<FourierSeries> {
        let f = self.inner.fourier()?;
        Some(FourierSeries {
            a0: self.map.apply_point(&f.a0),
            cos: f.cos.iter().map(|c| self.map.apply_vector(c)).collect(),
            sin: f.sin.iter().map(|c| self.map.apply_vector(c)).collect(),
        })
    }
}

/// The largest singular value of a 3 × 3 matrix, `(λ_max(MᵀM))^{1/2}`, rounded up a little
/// (the eigenvalues of the symmetric `MᵀM` are computed to a few ε of its norm; a relative
/// allowance of `10⁻¹²` of the Frobenius norm covers that). Not finite for a matrix that is not.
fn spectral_norm(m: &nalgebra::Matrix3<f64>) -> f64 {
    let frob = m.norm();
    if !frob.is_finite() || frob == 0.0 {
        return frob;
    }
    let s = m / frob;
    let eig = (s.transpose() * s).symmetric_eigenvalues();
    let top = eig.iter().copied().fold(0.0, f64::max);
    ((top + 1e-12).sqrt() * frob).min(frob)
}

/// Moves the `v = 0` point of a periodic curve (§6.4): `C̃(v) = C(v + shift)`.
#[derive(Clone, Debug)]
pub struct OriginShift {
    /// The periodic curve whose origin moves.
    pub inner: SharedCurve,
    /// The parameter shift `s` in radians: `C̃(v) = C(v + s)`.
    pub shift: f64,
}

impl OriginShift {
    /// The inner curve must be periodic and the shift finite.
    pub fn new(inner: SharedCurve, shift: f64) -> Result<Self> {
        if !shift.is_finite() {
            return Err(Error::invalid(format!("shift = {shift} is not finite")));
        }
        if let Domain::Interval(a, b) = inner.domain() {
            return Err(Error::invalid(format!(
                "the origin of a curve on the interval [{a}, {b}] cannot move; it must be periodic"
            )));
        }
        Ok(OriginShift { inner, shift })
    }
}

impl Curve for OriginShift {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let s = super::reduce_periodic(self.shift);
        self.inner.jet(super::reduce_periodic(t) + s, out);
    }
    /// The inner breaks moved by `−shift` (reduced to `[0, 2π)`).
    fn breaks(&self) -> Vec<f64> {
        let s = super::reduce_periodic(self.shift);
        let mut b: Vec<f64> = self
            .inner
            .breaks()
            .into_iter()
            .map(|x| super::reduce_periodic(x - s))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
    fn continuity(&self) -> usize {
        self.inner.continuity()
    }
    fn exact_order(&self) -> usize {
        self.inner.exact_order()
    }
    /// The inner curve's bounds over `(t0 + s, t1 + s)`, cut at `2π` into windows of one period.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let s = super::reduce_periodic(self.shift);
        let windows = super::periodic_windows(t0 + s, t1 + s);
        if windows.is_empty() {
            return false;
        }
        let mut part = vec![0.0; out.len()];
        out.iter_mut().for_each(|o| *o = 0.0);
        for (a, b) in windows {
            if !self.inner.derivative_bounds(a, b, &mut part) {
                return false;
            }
            for (o, p) in out.iter_mut().zip(&part) {
                *o = o.max(*p);
            }
        }
        true
    }
    /// `aₙ cos n(v+s) + bₙ sin n(v+s) = [aₙ cos ns + bₙ sin ns] cos nv + [bₙ cos ns − aₙ sin ns] sin nv`.
    fn fourier(&self) -> Option<FourierSeries> {
        let f = self.inner.fourier()?;
        let s = super::reduce_periodic(self.shift);
        let (cos, sin) = f
            .cos
            .iter()
            .zip(&f.sin)
            .enumerate()
            .map(|(i, (a, b))| {
                let (sn, cn) = ((i + 1) as f64 * s).sin_cos();
                (a * cn + b * sn, b * cn - a * sn)
            })
            .unzip();
        Some(FourierSeries { a0: f.a0, cos, sin })
    }
}

/// `Σ wᵢ Cᵢ(t)` over curves with the same domain. The book's derivative curves (Eq. 5.2) are
/// `s·(d − p)`: `Combination::new(vec![(s, d), (-s, p)])`.
#[derive(Clone, Debug)]
pub struct Combination {
    /// The terms `(wᵢ, Cᵢ)`: weight and curve.
    pub terms: Vec<(f64, SharedCurve)>,
}

impl Combination {
    /// At least one term; finite weights; all domains equal.
    pub fn new(terms: Vec<(f64, SharedCurve)>) -> Result<Self> {
        let Some(first) = terms.first() else {
            return Err(Error::invalid(
                "terms: a combination needs at least one curve",
            ));
        };
        let d0 = first.1.domain();
        for (i, (w, c)) in terms.iter().enumerate() {
            if !w.is_finite() {
                return Err(Error::invalid(format!(
                    "terms[{i}]: weight {w} is not finite"
                )));
            }
            if c.domain() != d0 {
                return Err(Error::invalid(format!(
                    "terms[{i}]: domain {:?} differs from the domain {d0:?} of terms[0]",
                    c.domain()
                )));
            }
        }
        Ok(Combination { terms })
    }
}

impl Curve for Combination {
    fn domain(&self) -> Domain {
        self.terms[0].1.domain()
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let n = out.len().min(MAX_ORDER + 1);
        let mut buf = [Vec3::zeros(); MAX_ORDER + 1];
        for o in out.iter_mut() {
            *o = Vec3::zeros();
        }
        for (w, c) in &self.terms {
            c.jet(t, &mut buf[..n]);
            for (o, b) in out.iter_mut().zip(&buf[..n]) {
                *o += b * *w;
            }
        }
    }
    /// The union of the terms' breaks.
    fn breaks(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self.terms.iter().flat_map(|(_, c)| c.breaks()).collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
    /// The least of the terms'.
    fn continuity(&self) -> usize {
        self.terms
            .iter()
            .map(|(_, c)| c.continuity())
            .min()
            .unwrap_or(usize::MAX)
    }
    /// The least of the terms'.
    fn exact_order(&self) -> usize {
        self.terms
            .iter()
            .map(|(_, c)| c.exact_order())
            .min()
            .unwrap_or(MAX_ORDER)
    }
    /// `|Σ wᵢ Cᵢ⁽ᵏ⁾| ≤ Σ |wᵢ| sup|Cᵢ⁽ᵏ⁾|`.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let mut part = vec![0.0; out.len()];
        out.iter_mut().for_each(|o| *o = 0.0);
        for (w, c) in &self.terms {
            if !c.derivative_bounds(t0, t1, &mut part) {
                return false;
            }
            for (o, p) in out.iter_mut().zip(&part) {
                *o += w.abs() * p;
            }
        }
        out.iter().all(|o| o.is_finite())
    }
    /// `Σ wᵢ fᵢ` when every term has an exact series.
    fn fourier(&self) -> Option<FourierSeries> {
        let series: Option<Vec<FourierSeries>> =
            self.terms.iter().map(|(_, c)| c.fourier()).collect();
        let series = series?;
        let m = series.iter().map(|f| f.modes()).max().unwrap_or(0);
        let mut out = FourierSeries {
            a0: Vec3::zeros(),
            cos: vec![Vec3::zeros(); m],
            sin: vec![Vec3::zeros(); m],
        };
        for ((w, _), f) in self.terms.iter().zip(&series) {
            out.a0 += f.a0 * *w;
            for n in 0..f.modes() {
                out.cos[n] += f.cos[n] * *w;
                out.sin[n] += f.sin[n] * *w;
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::super::{BSpline, Ellipse, Hermite};
    use super::*;
    use crate::TAU;
    use std::sync::Arc;

    #[test]
    fn rotation_is_rigid_and_fixes_its_axis() {
        let about = Vec3::new(1.0, -2.0, 0.5);
        let axis = Vec3::new(1.0, 2.0, -0.5);
        let r = Affine::rotation(axis, 0.8, about).unwrap();
        // Orthogonal with determinant 1.
        let m = r.linear;
        assert!((m.transpose() * m - nalgebra::Matrix3::identity()).norm() < 1e-15 * 4.0);
        assert!((m.determinant() - 1.0).abs() < 1e-15 * 4.0);
        // Points on the axis are fixed.
        for s in [0.0, 1.0, -3.0] {
            let p = about + axis * s;
            assert_close(&r.apply_point(&p), &p, 1e-14, "axis point");
        }
        // Distances and angles are preserved.
        let (a, b, c) = (
            Vec3::new(0.3, 1.0, 2.0),
            Vec3::new(-1.0, 0.0, 4.0),
            Vec3::new(2.0, 2.0, -1.0),
        );
        let (ra, rb, rc) = (r.apply_point(&a), r.apply_point(&b), r.apply_point(&c));
        assert!(((ra - rb).norm() - (a - b).norm()).abs() < 1e-14);
        assert!(((rc - rb).dot(&(ra - rb)) - (c - b).dot(&(a - b))).abs() < 1e-13);
        // Right-handed: x about z by π/2 gives y.
        let q = Affine::rotation(Vec3::z() * 5.0, TAU / 4.0, Vec3::zeros()).unwrap();
        assert_close(
            &q.apply_point(&Vec3::x()),
            &Vec3::y(),
            1e-16,
            "quarter turn",
        );
        // The rotation angle: a vector ⟂ axis turns by θ.
        let k = axis.normalize();
        let u = k.cross(&Vec3::x()).normalize();
        let ru = r.apply_vector(&u);
        assert!((ru.dot(&u) - 0.8f64.cos()).abs() < 1e-15 * 4.0);
        assert!((u.cross(&ru).dot(&k) - 0.8f64.sin()).abs() < 1e-15 * 4.0);
    }

    #[test]
    fn scaling_and_composition() {
        let about = Vec3::new(1.0, 1.0, 1.0);
        let s = Affine::scaling(-2.0, about).unwrap();
        assert_close(&s.apply_point(&about), &about, 0.0, "fixed");
        assert_close(
            &s.apply_point(&Vec3::new(2.0, 1.0, 1.0)),
            &Vec3::new(-1.0, 1.0, 1.0),
            0.0,
            "scaled",
        );
        let t = Affine::translation(Vec3::x());
        let st = s.then(&t);
        let p = Vec3::new(0.2, 0.4, -1.0);
        assert_close(
            &st.apply_point(&p),
            &t.apply_point(&s.apply_point(&p)),
            1e-15,
            "then",
        );
    }

    #[test]
    fn bad_input_is_rejected() {
        let z = Vec3::zeros();
        let e = Affine::rotation(z, 1.0, z).unwrap_err().to_string();
        assert!(e.contains("axis"), "{e}");
        assert!(Affine::rotation(Vec3::new(f64::NAN, 0.0, 1.0), 1.0, z).is_err());
        assert!(Affine::rotation(Vec3::z(), f64::INFINITY, z).is_err());
        assert!(Affine::rotation(Vec3::z(), 1.0, Vec3::new(0.0, f64::NAN, 0.0)).is_err());
        assert!(Affine::scaling(0.0, z).is_err());
        assert!(Affine::scaling(f64::NAN, z).is_err());
        assert!(Affine::scaling(f64::NEG_INFINITY, z).is_err());
        assert!(Affine::scaling(2.0, Vec3::new(f64::INFINITY, 0.0, 0.0)).is_err());
        let h: SharedCurve = Arc::new(Hermite::new(z, Vec3::x(), Vec3::y(), Vec3::y()));
        assert!(OriginShift::new(h.clone(), 1.0).is_err());
        let c: SharedCurve = Arc::new(Ellipse::circle(z, 1.0, Vec3::z()).unwrap());
        assert!(OriginShift::new(c.clone(), f64::NAN).is_err());
        assert!(Combination::new(vec![]).is_err());
        let e = Combination::new(vec![(1.0, c.clone()), (1.0, h)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("terms[1]"), "{e}");
        assert!(Combination::new(vec![(f64::NAN, c)]).is_err());
    }

    fn spline() -> SharedCurve {
        let ctrl: Vec<Vec3> = (0..6)
            .map(|i| {
                let a = TAU * i as f64 / 6.0;
                Vec3::new(a.cos() * 2.0, a.sin(), 0.3 * (2.0 * a).cos())
            })
            .collect();
        Arc::new(BSpline::periodic(4, ctrl, None).unwrap())
    }

    #[test]
    fn transformed_and_shifted_jets() {
        let map = Affine::rotation(Vec3::new(0.0, 1.0, 1.0), 0.5, Vec3::x())
            .unwrap()
            .then(&Affine::scaling(1.5, Vec3::y()).unwrap());
        let inner = spline();
        let tc = Transformed::new(inner.clone(), map);
        for &t in &[0.1, 2.0, 4.0] {
            let (a, b) = (jet(&tc, t), jet(inner.as_ref(), t));
            assert_close(&a[0], &map.apply_point(&b[0]), 1e-14, "point");
            for k in 1..=8 {
                assert_close(
                    &a[k],
                    &map.apply_vector(&b[k]),
                    1e-12 * b[k].norm().max(1.0),
                    "derivative",
                );
            }
        }
        check_fd(&tc, &[0.5, 1.5, 3.5], 1e-4, 3, 5.0);
        let os = OriginShift::new(inner.clone(), -1.0).unwrap();
        for &t in &[0.1, 2.0, 6.0] {
            let (a, b) = (jet(&os, t), jet(inner.as_ref(), t - 1.0));
            for k in 0..=8 {
                assert_close(&a[k], &b[k], 1e-11 * b[k].norm().max(1.0), "shift");
            }
        }
        assert!(os.fourier().is_none());
        assert!(tc.fourier().is_none());
    }

    #[test]
    fn exact_series_follow_the_wrappers() {
        let e: SharedCurve = Arc::new(
            Ellipse::new(
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(2.0, 0.0, 0.5),
                Vec3::new(0.0, 1.0, 0.0),
            )
            .unwrap(),
        );
        let f: SharedCurve = Arc::new(FourierSeries {
            a0: Vec3::new(1.0, 0.0, 0.0),
            cos: vec![Vec3::zeros(), Vec3::new(0.0, 0.0, 0.3)],
            sin: vec![Vec3::new(0.1, 0.0, 0.0), Vec3::new(0.0, 0.2, 0.0)],
        });
        let map =
            Affine::rotation(Vec3::new(1.0, 1.0, 0.0), 1.1, Vec3::new(0.0, 0.0, 2.0)).unwrap();
        let curves: Vec<SharedCurve> = vec![
            Arc::new(Transformed::new(e.clone(), map)),
            Arc::new(OriginShift::new(f.clone(), 0.7).unwrap()),
            Arc::new(OriginShift::new(e.clone(), -8.0).unwrap()),
            Arc::new(Combination::new(vec![(2.0, e.clone()), (-0.5, f.clone())]).unwrap()),
        ];
        for c in curves {
            let s = c.fourier().expect("exact series");
            for &v in &[0.0, 0.9, 2.5, 5.0] {
                assert_close(&s.point(v), &c.point(v), 1e-14, "series");
                assert_close(&s.derivative(v, 3), &c.derivative(v, 3), 1e-13, "series d3");
            }
        }
    }

    #[test]
    fn combination_is_the_weighted_sum() {
        let a = spline();
        let b: SharedCurve = Arc::new(Ellipse::circle(Vec3::z(), 1.0, Vec3::z()).unwrap());
        let c = Combination::new(vec![(0.5, a.clone()), (-2.0, b.clone())]).unwrap();
        for &t in &[0.3, 3.3] {
            let (jc, ja, jb) = (jet(&c, t), jet(a.as_ref(), t), jet(b.as_ref(), t));
            for k in 0..=8 {
                assert_close(
                    &jc[k],
                    &(ja[k] * 0.5 - jb[k] * 2.0),
                    1e-12 * ja[k].norm().max(1.0),
                    "sum",
                );
            }
        }
        assert!(c.fourier().is_none());
        assert_eq!(c.domain(), Domain::Periodic);
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::super::{BSpline, Ellipse, PointSamples, SampleParam};
    use super::*;
    use std::sync::Arc;

    fn spline() -> SharedCurve {
        let c: Vec<Vec3> = (0..9)
            .map(|i| {
                let t = crate::TAU * i as f64 / 9.0;
                Vec3::new(t.cos(), t.sin() * 1.3, 0.2 * (2.0 * t).cos())
            })
            .collect();
        Arc::new(BSpline::periodic(3, c, None).unwrap())
    }

    /// Affine images, origin shifts and combinations keep proven bounds, with their breaks
    /// mapped; a rotation keeps the bounds of the derivatives exactly (spectral norm 1).
    #[test]
    fn bounds_hold_through_transforms() {
        let rot = Affine::rotation(Vec3::new(1.0, 1.0, 0.2), 0.7, Vec3::new(0.5, 0.0, 0.0))
            .unwrap()
            .then(&Affine::scaling(1.5, Vec3::zeros()).unwrap());
        let t = Transformed::new(spline(), rot);
        let r = check_bounds(&t, 12, 40, 2.0);
        eprintln!("transformed: {r:?}");
        assert!(r[3] <= 1.0 + 1e-6, "{r:?}");
        let (mut a, mut b) = ([0.0; 5], [0.0; 5]);
        let pure = Transformed::new(
            spline(),
            Affine::rotation(Vec3::z(), 1.1, Vec3::zeros()).unwrap(),
        );
        assert!(pure.derivative_bounds(0.3, 0.6, &mut a));
        assert!(spline().derivative_bounds(0.3, 0.6, &mut b));
        for k in 0..5 {
            // Equal up to the rounding allowances (twice `BOUND_ROUNDING`).
            assert!(
                (a[k] - b[k]).abs() <= 3e-9 * b[k].max(1e-300),
                "{k}: {a:?} {b:?}"
            );
        }
        let shifted = OriginShift::new(spline(), 2.0).unwrap();
        let r = check_bounds(&shifted, 13, 40, 3.0);
        assert!(r[3] <= 1.0 + 1e-6, "{r:?}");
        assert!(shifted
            .breaks()
            .iter()
            .all(|&x| spline().breaks().iter().any(|&y| {
                (crate::curve::reduce_periodic(x + 2.0) - y).abs() < 1e-12
                    || (crate::curve::reduce_periodic(x + 2.0) - y).abs() > crate::TAU - 1e-12
            })));
        let pts: Vec<Vec3> = (0..7)
            .map(|i| {
                let t = crate::TAU * i as f64 / 7.0;
                Vec3::new(t.cos(), t.sin(), 0.0)
            })
            .collect();
        let samples: SharedCurve = Arc::new(PointSamples::closed(pts, SampleParam::Chord).unwrap());
        let circle: SharedCurve = Arc::new(Ellipse::circle(Vec3::zeros(), 1.0, Vec3::z()).unwrap());
        let comb = Combination::new(vec![(2.0, samples), (-2.0, circle), (0.5, spline())]).unwrap();
        check_bounds(&comb, 14, 40, 2.0);
        assert_eq!(comb.breaks().len(), 7 + 9 - 1);
    }
}
