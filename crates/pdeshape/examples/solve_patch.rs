//! Solve a biharmonic PDE patch from four boundary curves and tessellate it.
//!
//! The patch runs from a unit circle at `u = 0` to a smaller circle one unit higher at `u = 1`;
//! the derivative conditions make it leave the base outwards and upwards and arrive at the rim
//! going straight up, like the side of a cup. Prints the mesh's vertex count and the patch's
//! area.
//!
//! `cargo run --release -p pdeshape --example solve_patch`

use pdeshape::analysis::{integrate_surface, Quadrature};
use pdeshape::curve::{Ellipse, Point, SharedCurve};
use pdeshape::elliptic::{solve, Condition, Operator, SolveOptions};
use pdeshape::{mesh, Vec3};
use std::sync::Arc;

/// A horizontal circle about the z axis. A curve is a function of `v ∈ [0, 2π)`; as a derivative
/// condition its points are the vectors `∂X/∂u` along the boundary.
fn circle(z: f64, r: f64) -> SharedCurve {
    Arc::new(Ellipse::circle(Vec3::new(0.0, 0.0, z), r, Vec3::z()).unwrap())
}

fn main() {
    // The biharmonic operator (N = 2) with smoothing parameter a = 1.5: four conditions, a
    // position and a derivative at each end.
    let operator = Operator::polyharmonic(2, 1.5).unwrap();
    let conditions = vec![
        Condition {
            u: 0.0,
            derivative: 0,
            curve: circle(0.0, 1.0),
        },
        // ∂X/∂u at the base: half a unit outwards, one unit up.
        Condition {
            u: 0.0,
            derivative: 1,
            curve: circle(1.0, 0.5),
        },
        Condition {
            u: 1.0,
            derivative: 0,
            curve: circle(1.0, 0.7),
        },
        // ∂X/∂u at the rim: straight up.
        Condition {
            u: 1.0,
            derivative: 1,
            curve: Arc::new(Point::new(Vec3::z())),
        },
    ];
    let patch = solve(&operator, conditions, &SolveOptions::default()).unwrap();

    // A 32 × 64 grid of positions and normals (f32, as mesh files store them).
    let grid = mesh::tessellate(&patch, 32, 64).unwrap();
    let area = integrate_surface(&patch, &Quadrature::default())
        .unwrap()
        .area;
    println!("vertices: {}", grid.positions.len());
    println!("area: {area:.6}");
}

#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main();
    }
}
