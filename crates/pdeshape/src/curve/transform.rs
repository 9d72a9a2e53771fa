use super::{Curve, Domain, FourierSeries, SharedCurve};
use crate::{Result, Vec3};

/// An affine map `x ↦ M x + t` of R³: the design parameters of §6.1 (translate, rotate about an
/// axis through a point, scale about a point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    pub linear: nalgebra::Matrix3<f64>,
    pub shift: Vec3,
}

impl Affine {
    pub fn identity() -> Self {
        Affine {
            linear: nalgebra::Matrix3::identity(),
            shift: Vec3::zeros(),
        }
    }
    pub fn translation(d: Vec3) -> Self {
        Affine {
            linear: nalgebra::Matrix3::identity(),
            shift: d,
        }
    }
    /// Rotation by `angle` radians (right-handed) about the line through `about` along `axis`.
    pub fn rotation(axis: Vec3, angle: f64, about: Vec3) -> Result<Self> {
        let _ = (axis, angle, about);
        todo!("curve kinds")
    }
    /// Uniform scaling by `factor ≠ 0` about the point `about`.
    pub fn scaling(factor: f64, about: Vec3) -> Result<Self> {
        let _ = (factor, about);
        todo!("curve kinds")
    }
    /// `self` followed by `next`.
    pub fn then(&self, next: &Affine) -> Affine {
        Affine {
            linear: next.linear * self.linear,
            shift: next.linear * self.shift + next.shift,
        }
    }
    pub fn apply_point(&self, p: &Vec3) -> Vec3 {
        self.linear * p + self.shift
    }
    pub fn apply_vector(&self, d: &Vec3) -> Vec3 {
        self.linear * d
    }
}

/// An affine image of a curve.
#[derive(Clone, Debug)]
pub struct Transformed {
    pub inner: SharedCurve,
    pub map: Affine,
}

impl Transformed {
    pub fn new(inner: SharedCurve, map: Affine) -> Self {
        Transformed { inner, map }
    }
}

impl Curve for Transformed {
    fn domain(&self) -> Domain {
        self.inner.domain()
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
    fn fourier(&self) -> Option<FourierSeries> {
        todo!("curve kinds")
    }
}

/// Moves the `v = 0` point of a periodic curve (§6.4): `C̃(v) = C(v + shift)`.
#[derive(Clone, Debug)]
pub struct OriginShift {
    pub inner: SharedCurve,
    pub shift: f64,
}

impl OriginShift {
    /// The inner curve must be periodic.
    pub fn new(inner: SharedCurve, shift: f64) -> Result<Self> {
        let _ = (&inner, shift);
        todo!("curve kinds")
    }
}

impl Curve for OriginShift {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}

/// `Σ wᵢ Cᵢ(t)` over curves with the same domain. The book's derivative curves (Eq. 5.2) are
/// `s·(d − p)`: `Combination::new(vec![(s, d), (-s, p)])`.
#[derive(Clone, Debug)]
pub struct Combination {
    pub terms: Vec<(f64, SharedCurve)>,
}

impl Combination {
    /// At least one term; all domains equal.
    pub fn new(terms: Vec<(f64, SharedCurve)>) -> Result<Self> {
        let _ = &terms;
        todo!("curve kinds")
    }
}

impl Curve for Combination {
    fn domain(&self) -> Domain {
        self.terms[0].1.domain()
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
