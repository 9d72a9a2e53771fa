//! Implement `Surface` for a type of your own, then tessellate and analyse it like any
//! surface of the library.
//!
//! A torus is given by its position and exact first and second partials; `v_domain` says that
//! `v` is an angle (period 2π) and `u_periodic` that `u ∈ [0, 1]` closes up too. The library's
//! tessellation, curvature integrals and closest points then work on it. Prints the area,
//! against the exact `4π² R r`, and the total Gaussian curvature (zero for a torus, by
//! Gauss–Bonnet).
//!
//! `cargo run --release -p pdeshape --example custom_surface`

use pdeshape::analysis::{analyze_surface, Quadrature};
use pdeshape::mesh::tessellate;
use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape::{Vec3, TAU};

/// The torus `X(u, v) = ((R + r cos v) cos 2πu, (R + r cos v) sin 2πu, r sin v)`.
struct Torus {
    big: f64,
    small: f64,
}

impl Surface for Torus {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }

    fn u_periodic(&self) -> bool {
        true
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let (su, cu) = (TAU * u).sin_cos();
        let (sv, cv) = v.sin_cos();
        let (big, r) = (self.big, self.small);
        let rho = big + r * cv;
        Partials {
            x: Vec3::new(rho * cu, rho * su, r * sv),
            xu: Vec3::new(-TAU * rho * su, TAU * rho * cu, 0.0),
            xv: Vec3::new(-r * sv * cu, -r * sv * su, r * cv),
            xuu: Vec3::new(-TAU * TAU * rho * cu, -TAU * TAU * rho * su, 0.0),
            xuv: Vec3::new(TAU * r * sv * su, -TAU * r * sv * cu, 0.0),
            xvv: Vec3::new(-r * cv * cu, -r * cv * su, -r * sv),
        }
    }
}

fn main() {
    let torus = Torus {
        big: 2.0,
        small: 0.5,
    };
    let grid = tessellate(&torus, 48, 24).unwrap();
    let analysis = analyze_surface(&torus, &Quadrature::default()).unwrap();
    let exact = TAU * TAU * torus.big * torus.small;
    println!(
        "{} vertices; area {:.10} (exact {exact:.10})",
        grid.positions.len(),
        analysis.integrals.area
    );
    println!("total Gaussian curvature: {:.2e}", analysis.integrals.gauss);
}

#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main();
    }
}
