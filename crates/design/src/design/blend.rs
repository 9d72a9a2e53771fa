//! `[blend]` designs: the section checked and turned into a [`BlendProblem`] for the BFS solver.

use crate::bfs::{
    blend, Blend, BlendProblem, Cylinder, Energy, Join, Plane, MAX_ELEMENTS_PER_SIDE,
};
use crate::spec::{BlendSpec, EnergySpec, JoinSpec, SurfaceSpec};
use crate::surface::Surface;
use crate::{Error, Result, Vec3};

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Finds a surface of the design by name: its identity and the surface.
pub(crate) type Lookup<'a> = dyn Fn(&str) -> Option<(usize, &'a dyn Surface)> + 'a;

/// A primary surface: built from its table, or a surface of the design.
enum Primary<'a> {
    Own(Box<dyn Surface>),
    Design(&'a dyn Surface),
}

impl Primary<'_> {
    fn surface(&self) -> &dyn Surface {
        match self {
            Primary::Own(s) => s.as_ref(),
            Primary::Design(s) => *s,
        }
    }
}

/// Where a primary surface that is a design surface is missing: the error at its `name`.
fn unknown_surface(name: &str) -> Error {
    Error::invalid(format!(
        "the design has no surface named '{name}' (a patch or a [[parametric]] surface)"
    ))
    .at("name")
}

fn build_surface<'a>(s: &SurfaceSpec, lookup: Option<&Lookup<'a>>) -> Result<Primary<'a>> {
    Ok(match s {
        SurfaceSpec::Patch { name } => match lookup {
            Some(find) => Primary::Design(find(name).ok_or_else(|| unknown_surface(name))?.1),
            // Checked without the design's surfaces: a stand-in (names are checked when the
            // design is compiled).
            None => Primary::Own(Box::new(Plane::new(Vec3::zeros(), Vec3::x(), Vec3::y())?)),
        },
        SurfaceSpec::Cylinder { base, axis, radius } => {
            Primary::Own(Box::new(Cylinder::new(v3(*base), v3(*axis), *radius)?))
        }
        SurfaceSpec::Plane { origin, du, dv } => {
            Primary::Own(Box::new(Plane::new(v3(*origin), v3(*du), v3(*dv))?))
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
    checked(spec, None).map(|_| ())
}

/// The identities of the design surfaces a blend joins (`type = "patch"`), in order; errors at
/// `blend.start.surface.name` for an unknown name.
pub(crate) fn design_sources(spec: &BlendSpec, lookup: &Lookup<'_>) -> Result<Vec<usize>> {
    let mut ids = Vec::new();
    for (end, j) in [("start", &spec.start), ("end", &spec.end)] {
        if let SurfaceSpec::Patch { name } = &j.surface {
            let (id, _) = lookup(name)
                .ok_or_else(|| unknown_surface(name).at(&format!("blend.{end}.surface")))?;
            ids.push(id);
        }
    }
    Ok(ids)
}

/// The validated parts of a blend: energy and the two primary surfaces.
type Checked<'a> = (Energy, Primary<'a>, Primary<'a>);

fn checked<'a>(spec: &BlendSpec, lookup: Option<&Lookup<'a>>) -> Result<Checked<'a>> {
    let [nx, ny] = spec.elements;
    for (n, k) in [(nx, 0), (ny, 1)] {
        if n == 0 || n > MAX_ELEMENTS_PER_SIDE {
            return Err(Error::invalid(format!(
                "must be between 1 and {} (got {n})",
                MAX_ELEMENTS_PER_SIDE
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
    let start =
        build_surface(&spec.start.surface, lookup).map_err(|e| e.at("blend.start.surface"))?;
    let end = build_surface(&spec.end.surface, lookup).map_err(|e| e.at("blend.end.surface"))?;
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

/// Builds and solves the blend of a `[blend]` section whose primary surfaces are built-in
/// (cylinders and planes). Errors carry their place in the file (`blend.start.surface.radius`,
/// `blend.points[2]`, `blend.energy`, …).
pub fn solve_blend(spec: &BlendSpec) -> Result<Blend> {
    solve_blend_with(spec, &|_| None)
}

/// [`solve_blend`] with the design's surfaces found by `lookup` (for `type = "patch"`).
pub(crate) fn solve_blend_with(spec: &BlendSpec, lookup: &Lookup<'_>) -> Result<Blend> {
    let (energy, start, end) = checked(spec, Some(lookup))?;
    let [nx, ny] = spec.elements;
    let problem = BlendProblem {
        start: join(start.surface(), &spec.start),
        end: join(end.surface(), &spec.end),
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

/// The join of a blend edge with `surface` as the design file states it.
fn join<'a>(surface: &'a dyn Surface, j: &JoinSpec) -> Join<'a> {
    Join {
        surface,
        from: j.from,
        to: j.to,
        cross: j.cross,
    }
}
