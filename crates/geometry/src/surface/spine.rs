//! The spine of a surface periodic in `v`: the centre line `A₀(u)`.

use crate::Vec3;

/// A surface with a spine (book §5.3): the curve `A₀(u) = (1/2π) ∫₀^{2π} X(u, v) dv` of the
/// means of its `v`-circles, the constant term of `X`'s Fourier series in `v`. For a surface
/// of revolution it lies on the axis; for a Bloor–Wilson patch it is the mode-0 solution.
///
/// A `&dyn Surface` gives its spine through [`super::Surface::as_spine`].
pub trait Spine {
    /// `dᵏA₀/duᵏ (u)` for `k = order` (`order = 0`: the point of the centre line at `u`).
    fn spine(&self, u: f64, order: usize) -> Vec3;
}
