use super::{Curve, Domain};
use crate::Vec3;

/// Cubic Hermite curve on `[0, 1]` from end points and end tangents (book Eq. 5.4).
#[derive(Clone, Debug)]
pub struct Hermite {
    pub p0: Vec3,
    pub p1: Vec3,
    pub d0: Vec3,
    pub d1: Vec3,
}

impl Hermite {
    pub fn new(p0: Vec3, p1: Vec3, d0: Vec3, d1: Vec3) -> Self {
        Hermite { p0, p1, d0, d1 }
    }
}

impl Curve for Hermite {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
