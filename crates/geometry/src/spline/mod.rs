//! Bézier and B-spline surfaces, multivariate Bézier patches on boxes and simplices, and their
//! dual bases.
//!
//! - [`BSplineSurface`]: tensor-product B-spline surfaces of any degrees and knot vectors
//!   (Cox–de Boor with derivatives of any order, Boehm knot insertion, exact degree elevation);
//!   [`bspline_basis`] gives the basis functions alive at a parameter, with derivatives.
//! - [`BezierSurface`]: tensor-product Bézier patches on `[0, 1]²` (de Casteljau, exact
//!   derivatives from forward differences of the net, degree elevation).
//! - [`TensorBezier`] and [`SimplexBezier`]: Bézier patches on the box `[0, 1]^m` and on a
//!   simplex in R^m with values in R^dim, generic over the [`Scalar`] (`f64` or exact
//!   [`num_rational::BigRational`]); [`simplex_coordinates`] and [`simplex_direction`] map
//!   points and directions of a simplex in R^m to the patch's coordinates `λ`.
//! - The difference-equation theorem and dual bases of seed 001 (Feng, Tong, Chen):
//!   [`forward_differences`] / [`binomial_sums`] (Theorem 1), [`box_dual`] (Theorem 2,
//!   Corollary 2.1), [`simplex_dual`] (Theorem 3, Corollary 3.1), and the all-at-once
//!   conversions [`box_control_from_derivatives`], [`simplex_control_from_derivatives`].
//!
//! ```
//! use num_rational::BigRational;
//! use pdeshape_geometry::spline::{box_dual, Scalar, TensorBezier};
//! // A biquadratic scalar patch with rational control values; Λ_{1,2} recovers P_{1,2}.
//! let ctrl: Vec<BigRational> = (0..9).map(|k| BigRational::ratio(k * k - 3, 7)).collect();
//! let p = TensorBezier::new(vec![2, 2], 1, ctrl.clone()).unwrap();
//! let zero = [BigRational::int(0), BigRational::int(0)];
//! let got = box_dual(&[2, 2], &[1, 2], |s| p.derivative(&zero, s).unwrap()).unwrap();
//! assert_eq!(got[0], ctrl[1 * 3 + 2]);
//! ```

mod bezier;
mod bspline;
mod dual;
pub mod knots;
mod scalar;
mod simplex;
mod tensor;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_dual;

pub use bezier::BezierSurface;
pub use bspline::BSplineSurface;
pub use dual::{
    binomial_sums, box_control_from_derivatives, box_dual, forward_differences,
    simplex_control_from_derivatives, simplex_dual,
};
pub use knots::bspline_basis;
pub use scalar::{rational_from_f64, IndexSet, Scalar, MAX_INDEX_BOX, MAX_VARS};
pub use simplex::{simplex_coordinates, simplex_direction, SimplexBezier};
pub use tensor::TensorBezier;
