//! The `[blend]` section of the design file: two primary surfaces, the lines where the blend
//! meets them, the partition, ε, the energy and data points. Documented in
//! `docs/design-file.md` ("Blends").

use super::types::deserialize_tagged;
use super::write::{is_false, is_zero, never, serialize_kind, serialize_type};
use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize};

/// `[blend]`: a discrete smoothing PDE spline on `[0, 1]²` whose edge `y = 0` joins `start` and
/// whose edge `y = 1` joins `end`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlendSpec {
    /// `[nx, ny]`: elements along the joins (`x`) and across (`y`), default `[8, 4]`.
    #[serde(default = "default_elements")]
    pub elements: [usize; 2],
    /// Identify the edges `x = 0` and `x = 1` (a closed tube; both joins must be closed lines).
    #[serde(default, skip_serializing_if = "is_false")]
    #[schemars(skip_serializing_if = "never")]
    pub periodic: bool,
    /// The weight ε of the energy in Eq. 6 (default 1).
    #[serde(default = "default_one")]
    pub epsilon: f64,
    /// The energy `(u, v)_L` (default `{ kind = "section6", a = 1 }`).
    #[serde(
        default = "default_energy",
        deserialize_with = "deserialize_energy",
        serialize_with = "serialize_kind"
    )]
    pub energy: EnergySpec,
    /// The join of the edge `y = 0`.
    pub start: JoinSpec,
    /// The join of the edge `y = 1`.
    pub end: JoinSpec,
    /// Data points the blend should pass near (the paper's `A` and `β`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<PointSpec>,
}

fn default_elements() -> [usize; 2] {
    [8, 4]
}
fn default_one() -> f64 {
    1.0
}
fn default_energy() -> EnergySpec {
    EnergySpec::Section6 { a: 1.0 }
}

/// The energy, chosen by `kind`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "kind")]
pub enum EnergySpec {
    /// Seed 004 §6: `∂x⁴ + 2a ∂x²∂y² + a² ∂y⁴` with `(u, v)_L = ∫ u_xx v_xx + 2a u_xy v_xy +
    /// a² u_yy v_yy`, `a > 0`.
    #[serde(rename = "section6")]
    Section6 {
        /// The smoothing parameter a (> 0).
        a: f64,
    },
    /// Seed 003's `L_{a,b,c,d,e}`: `∫ a|u_xx|² + b⟨u_xx, u_xy⟩ + c|u_xy|² + d⟨u_xy, u_yy⟩ +
    /// e|u_yy|²`, operator `a ∂x⁴ + b ∂x³∂y + c ∂x²∂y² + d ∂x∂y³ + e ∂y⁴`; optional `mixed`
    /// weighs `⟨u_xx, u_yy⟩`. Must be positive definite in `(u_xx, u_xy, u_yy)`.
    #[serde(rename = "general")]
    General {
        /// Weight of |u_xx|².
        a: f64,
        /// Weight of ⟨u_xx, u_xy⟩.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        b: f64,
        /// Weight of |u_xy|².
        c: f64,
        /// Weight of ⟨u_xy, u_yy⟩.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        d: f64,
        /// Weight of |u_yy|².
        e: f64,
        /// How the mixed terms are formed.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        mixed: f64,
    },
}

fn deserialize_energy<'de, D: Deserializer<'de>>(d: D) -> Result<EnergySpec, D::Error> {
    let table = toml::Table::deserialize(d)?;
    deserialize_tagged(table, "kind", "")
}

fn deserialize_surface<'de, D: Deserializer<'de>>(d: D) -> Result<SurfaceSpec, D::Error> {
    let table = toml::Table::deserialize(d)?;
    deserialize_tagged(table, "type", "")
}

/// Where the blend meets a primary surface `S`: the blend's edge `x ∈ [0, 1]` runs along the
/// line from `from` to `to` in `S`'s `(u, v)` parameters, and the blend's cross derivative is
/// `S`'s derivative along `cross` (pointing out of `S`, the way the blend continues it).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JoinSpec {
    /// The primary surface.
    #[serde(
        deserialize_with = "deserialize_surface",
        serialize_with = "serialize_type"
    )]
    pub surface: SurfaceSpec,
    /// `(u, v)` on `S` of the blend's `x = 0`.
    pub from: [f64; 2],
    /// `(u, v)` on `S` of the blend's `x = 1`.
    pub to: [f64; 2],
    /// Direction in `S`'s `(u, v)` plane whose derivative becomes the blend's `∂y`.
    pub cross: [f64; 2],
}

/// A primary surface, chosen by `type`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "type")]
pub enum SurfaceSpec {
    /// `base + v·axis + radius (cos 2πu e₁ + sin 2πu e₂)`, `e₁` the projection of `+x` on the
    /// plane normal to `axis` (`+y` if the axis is along `x`), `e₂ = â × e₁`.
    #[serde(rename = "cylinder")]
    Cylinder {
        /// Centre of the cylinder's base circle.
        base: [f64; 3],
        /// Axis vector: v runs from base to base + axis.
        axis: [f64; 3],
        /// Radius (> 0).
        radius: f64,
    },
    /// `origin + u·du + v·dv`.
    #[serde(rename = "plane")]
    Plane {
        /// The point at u = v = 0.
        origin: [f64; 3],
        /// The step along u (u ∈ [0, 1]).
        du: [f64; 3],
        /// The step along v.
        dv: [f64; 3],
    },
    /// A surface of this design by name: a PDE patch (`[[patches]]` name, or the single
    /// patch's name) or a `[[parametric]]` surface, in its own `(u, v)` parameters.
    #[serde(rename = "patch")]
    Patch {
        /// The name of the design's surface.
        name: String,
    },
}

/// A data point: the site `at` in `[0, 1]²` and the point `value` in space.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    /// The site [u, v] in [0, 1]².
    pub at: [f64; 2],
    /// The point [x, y, z] the surface takes there.
    pub value: [f64; 3],
}
