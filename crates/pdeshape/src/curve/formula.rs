use super::{Curve, Domain};
use crate::{Result, Vec3};

/// A curve given by three formulas in the parameter `v`, e.g. `x = "2*cos(v)"`. Derivatives are
/// symbolic.
#[derive(Clone, Debug)]
pub struct Formula {}

impl Formula {
    /// Errors name the component (`x`, `y` or `z`) whose formula does not parse, uses a variable
    /// other than `v`, or evaluates to a non-finite number on the domain.
    pub fn new(x: &str, y: &str, z: &str, domain: Domain) -> Result<Self> {
        let _ = (x, y, z, domain);
        todo!("curve kinds")
    }
}

impl Curve for Formula {
    fn domain(&self) -> Domain {
        todo!("curve kinds")
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
