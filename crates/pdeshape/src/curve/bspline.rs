use super::{Curve, Domain};
use crate::{Result, Vec3};

/// B-spline curve of any degree: clamped/open on a knot vector, or periodic on `[0, 2π)`.
#[derive(Clone, Debug)]
pub struct BSpline {}

impl BSpline {
    /// Open B-spline with the full knot vector (`control.len() + degree + 1` non-decreasing knots);
    /// `None` gives the uniform clamped knot vector on `[0, 1]`. Domain `[t_p, t_n]`.
    pub fn clamped(degree: usize, control: Vec<Vec3>, knots: Option<Vec<f64>>) -> Result<Self> {
        let _ = (degree, control, knots);
        todo!("curve kinds")
    }
    /// Periodic (closed) B-spline; `breakpoints` (`control.len() + 1` increasing values, mapped
    /// linearly onto `[0, 2π]`) default to uniform.
    pub fn periodic(
        degree: usize,
        control: Vec<Vec3>,
        breakpoints: Option<Vec<f64>>,
    ) -> Result<Self> {
        let _ = (degree, control, breakpoints);
        todo!("curve kinds")
    }
}

impl Curve for BSpline {
    fn domain(&self) -> Domain {
        todo!("curve kinds")
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
