//! Isotropic materials for shell models.

/// An isotropic linear-elastic material, SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Short name for reports.
    pub name: &'static str,
    /// Young's modulus `E` (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio `ν`.
    pub poisson_ratio: f64,
    /// Density `ρ` (kg/m³).
    pub density: f64,
    /// Tensile yield stress (Pa).
    pub yield_stress: f64,
}

impl Material {
    /// General-purpose polystyrene, the usual material of thermoformed yoghurt cups.
    ///
    /// Sources: W. D. Callister, D. G. Rethwisch, *Materials Science and Engineering: An
    /// Introduction*, Appendix B, Tables B.1–B.4 (polystyrene: density 1.04–1.05 g/cm³, modulus of
    /// elasticity 2.28–3.28 GPa, Poisson's ratio 0.33, yield strength 25–69 MPa); the values
    /// taken are `E = 3.0 GPa` (the upper half, for oriented thermoformed sheet), `ν = 0.33`,
    /// `ρ = 1050 kg/m³` and a yield stress of 40 MPa (a typical datasheet value for
    /// general-purpose grades, inside Callister's range).
    pub const POLYSTYRENE: Material = Material {
        name: "polystyrene",
        youngs_modulus: 3.0e9,
        poisson_ratio: 0.33,
        density: 1050.0,
        yield_stress: 40.0e6,
    };
}

impl Default for Material {
    fn default() -> Self {
        Material::POLYSTYRENE
    }
}
