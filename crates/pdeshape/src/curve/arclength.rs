use super::{Curve, Domain, SharedCurve};
use crate::{Result, Vec3};

/// Arc-length reparametrisation (§5.1): equal parameter steps cover equal lengths. A periodic
/// curve stays on `[0, 2π)`; an open curve keeps its interval.
#[derive(Clone, Debug)]
pub struct ArcLength {
    pub inner: SharedCurve,
}

impl ArcLength {
    /// Fails for a curve of zero length or with a point where `C'` vanishes.
    pub fn new(inner: SharedCurve) -> Result<Self> {
        let _ = &inner;
        todo!("curve kinds")
    }
    /// Total length.
    pub fn length(&self) -> f64 {
        todo!("curve kinds")
    }
}

impl Curve for ArcLength {
    fn domain(&self) -> Domain {
        self.inner.domain()
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
