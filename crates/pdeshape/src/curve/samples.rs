use super::{Curve, Domain};
use crate::{Result, Vec3};

/// How closed point samples are spread over `[0, 2π)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SampleParam {
    /// Equal parameter steps.
    Uniform,
    /// Steps proportional to the chord lengths (default).
    #[default]
    Chord,
    /// Steps proportional to the square roots of the chord lengths.
    Centripetal,
}

/// Closed point samples interpolated by a periodic C² cubic spline.
#[derive(Clone, Debug)]
pub struct PointSamples {}

impl PointSamples {
    /// At least 3 points; consecutive points (and last/first) must differ.
    pub fn closed(points: Vec<Vec3>, param: SampleParam) -> Result<Self> {
        let _ = (points, param);
        todo!("curve kinds")
    }
}

impl Curve for PointSamples {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("curve kinds")
    }
}
