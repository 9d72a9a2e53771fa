//! Bézier and B-spline surfaces, multivariate Bézier patches on boxes and simplices, and their
//! dual bases.
//!
//! - [`BSplineSurface`]: tensor-product B-spline surfaces of any degrees and knot vectors
//!   (Cox–de Boor with derivatives of any order, Boehm knot insertion, exact degree elevation).
//! - [`BezierSurface`]: tensor-product Bézier patches on `[0, 1]²` (de Casteljau, exact
//!   derivatives from forward differences of the net, degree elevation).

mod bezier;
mod bspline;
mod knots;
#[cfg(test)]
mod tests;

pub use bezier::BezierSurface;
pub use bspline::BSplineSurface;
