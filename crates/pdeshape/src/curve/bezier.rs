use super::{Curve, Domain};
use crate::{Result, Vec3};

/// Bézier curve of any degree on `[0, 1]`.
#[derive(Clone, Debug)]
pub struct Bezier {}

impl Bezier {
    /// At least two control points.
    pub fn new(control: Vec<Vec3>) -> Result<Self> {
        let _ = control;
        todo!("curve kinds")
    }
}

impl Curve for Bezier {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
