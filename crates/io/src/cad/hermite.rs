//! The bicubic Hermite interpolant of a surface on a grid of nodes, as one tensor B-spline.
//!
//! On every cell `[u_i, u_{i+1}] × [v_j, v_{j+1}]` the interpolant is the bicubic with the
//! surface's `X, X_u, X_v, X_uv` at the four corners. Neighbouring cells share the nodal data, so
//! the whole is C¹ and one bicubic B-spline with every interior knot doubled: in one direction
//! the control points are `X_0`, `X_0 + h_0/3 X'_0`, then per interior node `X_i − h_{i−1}/3 X'_i`,
//! `X_i + h_i/3 X'_i`, and finally `X_m − h_{m−1}/3 X'_m`, `X_m` (the Bézier points of the cells
//! with the shared joints left out: with a double knot the joint is the weighted mean of its two
//! neighbours, which is exactly `X_i`). The tensor product applies this in both directions, the
//! twist `X_uv` entering through the product of the two offsets.
//!
//! A direction that closes (periodic `v`, a tube closed in `u`) takes the data of its last node
//! from its first, so the first and last control rows are the same numbers: no seam gap.

use crate::spline::BSplineSurface;
use crate::surface::{Partials, Surface};
use crate::{Result, Vec3};

/// One control index of a direction: the node it comes from and the offset `±h/3` its
/// derivative is weighted with.
fn combos(nodes: &[f64]) -> Vec<(usize, f64)> {
    let m = nodes.len() - 1;
    let mut out = vec![(0, 0.0), (0, (nodes[1] - nodes[0]) / 3.0)];
    for i in 1..m {
        out.push((i, -(nodes[i] - nodes[i - 1]) / 3.0));
        out.push((i, (nodes[i + 1] - nodes[i]) / 3.0));
    }
    out.push((m, -(nodes[m] - nodes[m - 1]) / 3.0));
    out.push((m, 0.0));
    out
}

/// The clamped knot vector of the interpolant: ends four times, interior nodes twice.
pub(crate) fn hermite_knots(nodes: &[f64]) -> Vec<f64> {
    let m = nodes.len() - 1;
    let mut k = vec![nodes[0]; 4];
    for &x in &nodes[1..m] {
        k.push(x);
        k.push(x);
    }
    k.extend([nodes[m]; 4]);
    k
}

/// The bicubic Hermite interpolant of `surface` on the node grid `us × vs` (each strictly
/// increasing, at least two nodes, in the surface's own parameters). `closed = [u, v]`: the last
/// node of that direction takes the first node's data (the surface must be periodic there).
pub fn hermite_interpolant(
    surface: &dyn Surface,
    us: &[f64],
    vs: &[f64],
    closed: [bool; 2],
) -> Result<BSplineSurface> {
    let (mu, mv) = (us.len(), vs.len());
    // Nodal data [X, X_u, X_v, X_uv], row-major.
    let mut data = vec![[Vec3::zeros(); 4]; mu * mv];
    // Row by row (PDE patches evaluate whole rows from per-column tables); a closed direction's
    // last node takes the first node's data, bit for bit.
    let rows = surface.partials_rows(vs);
    let mut row = vec![Partials::default(); mv];
    for i in 0..mu {
        if closed[0] && i + 1 == mu {
            data.copy_within(0..mv, i * mv);
            continue;
        }
        rows.eval_row(us[i], &mut row);
        for (d, p) in data[i * mv..(i + 1) * mv].iter_mut().zip(&row) {
            *d = [p.x, p.xu, p.xv, p.xuv];
        }
        if closed[1] {
            data[i * mv + mv - 1] = data[i * mv];
        }
    }
    let (cu, cv) = (combos(us), combos(vs));
    let mut control = Vec::with_capacity(cu.len() * cv.len());
    for &(i, a) in &cu {
        for &(j, b) in &cv {
            let [x, xu, xv, xuv] = data[i * mv + j];
            control.push(x + xu * a + xv * b + xuv * (a * b));
        }
    }
    BSplineSurface::new([3, 3], hermite_knots(us), hermite_knots(vs), control)
}

/// `m + 1` equally spaced nodes on `[a, b]` (the last exactly `b`).
pub(crate) fn uniform_nodes(a: f64, b: f64, m: usize) -> Vec<f64> {
    (0..=m)
        .map(|i| {
            if i == m {
                b
            } else {
                a + (b - a) * i as f64 / m as f64
            }
        })
        .collect()
}
