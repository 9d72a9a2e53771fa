use super::{Curve, Domain};
use crate::{Result, Vec3};

/// A constant curve: the degenerate "curve" that closes a surface to a pole.
#[derive(Clone, Debug)]
pub struct Point {
    pub p: Vec3,
}

impl Point {
    pub fn new(p: Vec3) -> Self {
        Point { p }
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
}

/// `C(v) = c + cos v · a₁ + sin v · a₂` on `[0, 2π)`: circles and ellipses.
#[derive(Clone, Debug)]
pub struct Ellipse {
    pub center: Vec3,
    pub axis1: Vec3,
    pub axis2: Vec3,
}

impl Ellipse {
    /// General ellipse from its two (conjugate) semi-axis vectors; they must be independent.
    pub fn new(center: Vec3, axis1: Vec3, axis2: Vec3) -> Result<Self> {
        Ok(Ellipse {
            center,
            axis1,
            axis2,
        })
    }
    /// Circle of `radius > 0` about `center` in the plane normal to `normal`, starting (v = 0)
    /// along the projection of +x on that plane (+y if the normal is along x).
    pub fn circle(center: Vec3, radius: f64, normal: Vec3) -> Result<Self> {
        let _ = (center, radius, normal);
        todo!("curve kinds")
    }
    /// Axis-aligned ellipse with semi-axes `rx` (along the circle's start direction) and `ry`.
    pub fn with_radii(center: Vec3, rx: f64, ry: f64, normal: Vec3) -> Result<Self> {
        let _ = (center, rx, ry, normal);
        todo!("curve kinds")
    }
}

impl Curve for Ellipse {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let (s, c) = t.sin_cos();
        for (d, o) in out.iter_mut().enumerate() {
            let (cd, sd) = match d % 4 {
                0 => (c, s),
                1 => (-s, c),
                2 => (-c, -s),
                _ => (s, -c),
            };
            *o = self.axis1 * cd
                + self.axis2 * sd
                + if d == 0 { self.center } else { Vec3::zeros() };
        }
    }
    fn fourier(&self) -> Option<crate::fourier::FourierSeries> {
        Some(crate::fourier::FourierSeries {
            a0: self.center,
            cos: vec![self.axis1],
            sin: vec![self.axis2],
        })
    }
}
