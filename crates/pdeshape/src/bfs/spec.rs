//! The `[blend]` section of the design file: two primary surfaces, the lines where the blend
//! meets them, the partition, ε, the energy and data points. Documented in
//! `docs/design-file.md` ("Blends").

use super::{blend, Blend, BlendProblem, Cylinder, Energy, Join, Plane};
use crate::spec::deserialize_tagged;
use crate::surface::Surface;
use crate::{Error, Result, Vec3};
use schemars::JsonSchema;
use serde::{Deserialize, Deserializer};

/// `[blend]`: a discrete smoothing PDE spline on `[0, 1]²` whose edge `y = 0` joins `start` and
/// whose edge `y = 1` joins `end`.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlendSpec {
    /// `[nx, ny]`: elements along the joins (`x`) and across (`y`), default `[8, 4]`.
    #[serde(default = "default_elements")]
    pub elements: [usize; 2],
    /// Identify the edges `x = 0` and `x = 1` (a closed tube; both joins must be closed lines).
    #[serde(default)]
    pub periodic: bool,
    /// The weight ε of the energy in Eq. 6 (default 1).
    #[serde(default = "default_one")]
    pub epsilon: f64,
    /// The energy `(u, v)_L` (default `{ kind = "section6", a = 1 }`).
    #[serde(default = "default_energy", deserialize_with = "deserialize_energy")]
    pub energy: EnergySpec,
    /// The join of the edge `y = 0`.
    pub start: JoinSpec,
    /// The join of the edge `y = 1`.
    pub end: JoinSpec,
    /// Data points the blend should pass near (the paper's `A` and `β`).
    #[serde(default)]
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
#[derive(Clone, Debug, PartialEq, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "kind")]
pub enum EnergySpec {
    /// Seed 004 §6: `∂x⁴ + 2a ∂x²∂y² + a² ∂y⁴` with `(u, v)_L = ∫ u_xx v_xx + 2a u_xy v_xy +
    /// a² u_yy v_yy`, `a > 0`.
    #[serde(rename = "section6")]
    Section6 { a: f64 },
    /// Seed 003's `L_{a,b,c,d,e}`: `∫ a|u_xx|² + b⟨u_xx, u_xy⟩ + c|u_xy|² + d⟨u_xy, u_yy⟩ +
    /// e|u_yy|²`, operator `a ∂x⁴ + b ∂x³∂y + c ∂x²∂y² + d ∂x∂y³ + e ∂y⁴`; optional `mixed`
    /// weighs `⟨u_xx, u_yy⟩`. Must be positive definite in `(u_xx, u_xy, u_yy)`.
    #[serde(rename = "general")]
    General {
        a: f64,
        #[serde(default)]
        b: f64,
        c: f64,
        #[serde(default)]
        d: f64,
        e: f64,
        #[serde(default)]
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
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JoinSpec {
    /// The primary surface.
    #[serde(deserialize_with = "deserialize_surface")]
    pub surface: SurfaceSpec,
    /// `(u, v)` on `S` of the blend's `x = 0`.
    pub from: [f64; 2],
    /// `(u, v)` on `S` of the blend's `x = 1`.
    pub to: [f64; 2],
    /// Direction in `S`'s `(u, v)` plane whose derivative becomes the blend's `∂y`.
    pub cross: [f64; 2],
}

/// A primary surface, chosen by `type`.
#[derive(Clone, Debug, PartialEq, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "type")]
pub enum SurfaceSpec {
    /// `base + v·axis + radius (cos 2πu e₁ + sin 2πu e₂)`, `e₁` the projection of `+x` on the
    /// plane normal to `axis` (`+y` if the axis is along `x`), `e₂ = â × e₁`.
    #[serde(rename = "cylinder")]
    Cylinder {
        base: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
    /// `origin + u·du + v·dv`.
    #[serde(rename = "plane")]
    Plane {
        origin: [f64; 3],
        du: [f64; 3],
        dv: [f64; 3],
    },
}

/// A data point: the site `at` in `[0, 1]²` and the point `value` in space.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    pub at: [f64; 2],
    pub value: [f64; 3],
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

fn build_surface(s: &SurfaceSpec) -> Result<Box<dyn Surface>> {
    Ok(match s {
        SurfaceSpec::Cylinder { base, axis, radius } => {
            Box::new(Cylinder::new(v3(*base), v3(*axis), *radius)?)
        }
        SurfaceSpec::Plane { origin, du, dv } => {
            Box::new(Plane::new(v3(*origin), v3(*du), v3(*dv))?)
        }
    })
}

impl EnergySpec {
    /// The energy (errors at this table's keys).
    pub fn build(&self) -> Result<Energy> {
        match *self {
            EnergySpec::Section6 { a } => Energy::section6(a),
            EnergySpec::General {
                a,
                b,
                c,
                d,
                e,
                mixed,
            } => Energy::quadratic(
                [
                    [a, b / 2.0, mixed / 2.0],
                    [b / 2.0, c, d / 2.0],
                    [mixed / 2.0, d / 2.0, e],
                ],
                [[0.0; 2]; 2],
                0.0,
            ),
        }
    }

    /// `L` in words, e.g. `∂x⁴ + 20 ∂x²∂y² + 100 ∂y⁴`.
    pub fn describe(&self) -> String {
        let Ok(e) = self.build() else {
            return "invalid energy".to_string();
        };
        let names = ["∂x⁴", "∂x³∂y", "∂x²∂y²", "∂x∂y³", "∂y⁴"];
        let mut out = String::new();
        for (c, n) in e.operator_coefficients().iter().zip(names) {
            if *c == 0.0 {
                continue;
            }
            if out.is_empty() {
                if *c < 0.0 {
                    out.push('-');
                }
            } else {
                out.push_str(if *c < 0.0 { " - " } else { " + " });
            }
            if c.abs() != 1.0 {
                out.push_str(&format!("{} ", c.abs()));
            }
            out.push_str(n);
        }
        out
    }
}

/// Checks a `[blend]` section without solving: element counts, ε, the energy, the primary
/// surfaces and the data sites. Errors carry their place in the file.
pub fn validate_blend(spec: &BlendSpec) -> Result<()> {
    checked(spec).map(|_| ())
}

/// The validated parts of a blend: energy and the two primary surfaces.
type Checked = (Energy, Box<dyn Surface>, Box<dyn Surface>);

fn checked(spec: &BlendSpec) -> Result<Checked> {
    let [nx, ny] = spec.elements;
    for (n, k) in [(nx, 0), (ny, 1)] {
        if n == 0 || n > super::MAX_ELEMENTS_PER_SIDE {
            return Err(Error::invalid(format!(
                "must be between 1 and {} (got {n})",
                super::MAX_ELEMENTS_PER_SIDE
            ))
            .at(&format!("blend.elements[{k}]")));
        }
    }
    // 4 dofs per node and about 1 kB of assembly map per element: refuse systems beyond
    // 2¹⁷ nodes (half a million unknowns) before allocating.
    if (nx + 1) * (ny + 1) > 1 << 17 {
        return Err(Error::invalid(format!(
            "{nx} × {ny} elements exceed 2¹⁷ nodes; refusing to allocate the system"
        ))
        .at("blend.elements"));
    }
    if !(spec.epsilon.is_finite() && spec.epsilon > 0.0) {
        return Err(Error::invalid(format!(
            "must be positive and finite (got {})",
            spec.epsilon
        ))
        .at("blend.epsilon"));
    }
    let energy = spec.energy.build().map_err(|e| e.at("blend.energy"))?;
    let start = build_surface(&spec.start.surface).map_err(|e| e.at("blend.start.surface"))?;
    let end = build_surface(&spec.end.surface).map_err(|e| e.at("blend.end.surface"))?;
    for (k, p) in spec.points.iter().enumerate() {
        let [x, y] = p.at;
        if !((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)) {
            return Err(
                Error::invalid(format!("must lie in [0, 1]² (got [{x}, {y}])"))
                    .at(&format!("blend.points[{k}].at")),
            );
        }
    }
    Ok((energy, start, end))
}

/// Builds and solves the blend of a `[blend]` section. Errors carry their place in the file
/// (`blend.start.surface.radius`, `blend.points[2]`, `blend.energy`, …).
pub fn solve_blend(spec: &BlendSpec) -> Result<Blend> {
    let (energy, start, end) = checked(spec)?;
    let [nx, ny] = spec.elements;
    let problem = BlendProblem {
        start: Join::new(start.as_ref(), &spec.start),
        end: Join::new(end.as_ref(), &spec.end),
        nx,
        ny,
        periodic: spec.periodic,
        energy,
        epsilon: spec.epsilon,
        sites: spec.points.iter().map(|p| p.at).collect(),
        values: spec.points.iter().map(|p| v3(p.value)).collect(),
    };
    blend(&problem).map_err(|e| e.at("blend"))
}

impl<'a> Join<'a> {
    fn new(surface: &'a dyn Surface, j: &JoinSpec) -> Self {
        Join {
            surface,
            from: j.from,
            to: j.to,
            cross: j.cross,
        }
    }
}
