//! The curve at one level of a dynamic-curve run.

use crate::Vec3;

/// The curve at one level of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveFrame {
    /// The level `n`.
    pub step: usize,
    /// `t_n`.
    pub time: f64,
    /// `C(u_j, t_n)`, `u_j = j/J`.
    pub nodes: Vec<Vec3>,
}
