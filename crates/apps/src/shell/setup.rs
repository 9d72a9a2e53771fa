//! The shell analysis a design asks for: its `[shell]` section (or the book's set-up of §7.5.1
//! without one) checked against the design's patches, and turned into a [`ShellModel`] of its
//! solved surfaces in metres.

use super::{LineLoad, Material, RunOptions, ShellMesh, ShellModel, Side, MAX_NODES};
use crate::design::SolvedDesign;
use crate::spec::{DesignSpec, ShellSpec, SideSpec, Units};
use crate::{Error, Result};
use std::time::Duration;

/// Default wall thickness (m): half a millimetre, a thermoformed cup's wall.
pub const DEFAULT_THICKNESS: f64 = 0.5e-3;
/// Default element grid cells per patch `(nu, nv)`.
pub const DEFAULT_ELEMENTS: (usize, usize) = (8, 32);
/// The book's rim load (§7.5.1): 15 N/m, the weight of about 30 containers on the top seal.
pub const BOOK_LINE_LOAD: f64 = 15.0;
/// Most cells along `u` and around `v` per patch.
pub const MAX_ELEMENTS: (usize, usize) = (400, 1000);
/// Bytes per shell node of a solver run, a generous round figure: CalculiX expands each node
/// into three 3-D nodes (9 unknowns), and the sparse factorisation's fill and the result buffers
/// cost a few kilobytes per unknown.
pub(crate) const BYTES_PER_SHELL_NODE: u64 = 8 * 1024;

/// A line load of the setup, its direction resolved when the model is built.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadSetup {
    /// Index of the patch whose edge is loaded.
    pub patch: usize,
    /// The loaded edge.
    pub side: Side,
    /// N/m.
    pub force: f64,
    /// Unit direction, or `None` for "towards the first clamped edge".
    pub direction: Option<[f64; 3]>,
}

/// A checked shell analysis of a design.
#[derive(Clone, Debug, PartialEq)]
pub struct ShellSetup {
    /// Wall thickness (m).
    pub thickness: f64,
    /// The shell's material.
    pub material: Material,
    /// Element grid cells per patch.
    pub elements: (usize, usize),
    /// Edges `(patch, side)` with every displacement and rotation fixed.
    pub clamped: Vec<(usize, Side)>,
    /// Loads along patch edges.
    pub loads: Vec<LoadSetup>,
    /// Pa.
    pub pressure: f64,
    /// Longest a CalculiX run may take (default 300 s).
    pub time_limit: Duration,
    /// Metres per unit of the design's coordinates.
    pub metres: f64,
}

fn side(s: SideSpec) -> Side {
    match s {
        SideSpec::U0 => Side::U0,
        SideSpec::U1 => Side::U1,
    }
}

fn positive(x: f64, max: f64, place: &str) -> Result<f64> {
    if x > 0.0 && x <= max && x.is_finite() {
        Ok(x)
    } else if x > max && x.is_finite() {
        Err(Error::invalid(format!("must be at most {max} (got {x})")).at(place))
    } else {
        Err(Error::invalid(format!("must be positive (got {x})")).at(place))
    }
}

impl ShellSetup {
    /// Reads `[shell]` (every key optional) against the design's surface `names` (in design
    /// order); every error names its place (`shell.thickness`, `shell.clamped[0].patch`).
    pub fn new(spec: &DesignSpec, names: &[&str]) -> Result<ShellSetup> {
        let empty = ShellSpec::default();
        let s = spec.shell.as_ref().unwrap_or(&empty);
        if names.is_empty() {
            return Err(Error::invalid("the design has no surface to analyse").at("shell"));
        }
        let thickness = positive(
            s.thickness.unwrap_or(DEFAULT_THICKNESS),
            0.1,
            "shell.thickness",
        )?;
        let mut material = Material::POLYSTYRENE;
        if let Some(m) = &s.material {
            let mut custom = false;
            for (value, slot, key) in [
                (
                    m.youngs_modulus,
                    &mut material.youngs_modulus,
                    "youngs_modulus",
                ),
                (m.density, &mut material.density, "density"),
                (m.yield_stress, &mut material.yield_stress, "yield_stress"),
            ] {
                if let Some(v) = value {
                    *slot = positive(v, f64::MAX, &format!("shell.material.{key}"))?;
                    custom = true;
                }
            }
            if let Some(nu) = m.poisson_ratio {
                if !(nu > -1.0 && nu < 0.5) {
                    return Err(Error::invalid(format!(
                        "must be greater than −1 and less than 0.5 (got {nu})"
                    ))
                    .at("shell.material.poisson_ratio"));
                }
                material.poisson_ratio = nu;
                custom = true;
            }
            if custom {
                material.name = "custom";
            }
        }
        let elements = match s.elements {
            None => DEFAULT_ELEMENTS,
            Some([nu, nv]) => {
                if !(1..=MAX_ELEMENTS.0).contains(&nu) {
                    return Err(Error::invalid(format!(
                        "nu must be between 1 and {} (got {nu})",
                        MAX_ELEMENTS.0
                    ))
                    .at("shell.elements"));
                }
                if !(2..=MAX_ELEMENTS.1).contains(&nv) {
                    return Err(Error::invalid(format!(
                        "nv must be between 2 and {} (got {nv})",
                        MAX_ELEMENTS.1
                    ))
                    .at("shell.elements"));
                }
                (nu, nv)
            }
        };
        let find = |name: &str, place: &str| -> Result<usize> {
            names.iter().position(|n| *n == name).ok_or_else(|| {
                Error::invalid(format!(
                    "no patch named '{name}' (the design has {})",
                    names
                        .iter()
                        .map(|n| format!("'{n}'"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .at(place)
            })
        };
        let clamped = match &s.clamped {
            None => vec![(0, Side::U0)],
            Some(list) => list
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    Ok((
                        find(&e.patch, &format!("shell.clamped[{i}].patch"))?,
                        side(e.side),
                    ))
                })
                .collect::<Result<Vec<_>>>()?,
        };
        let loads = match &s.line_loads {
            None => vec![LoadSetup {
                patch: names.len() - 1,
                side: Side::U1,
                force: BOOK_LINE_LOAD,
                direction: None,
            }],
            Some(list) => {
                let mut out = Vec::with_capacity(list.len());
                for (i, l) in list.iter().enumerate() {
                    let place = format!("shell.line_loads[{i}]");
                    let patch = find(&l.patch, &format!("{place}.patch"))?;
                    if !l.force.is_finite() {
                        return Err(Error::invalid(format!("must be finite (got {})", l.force))
                            .at(&format!("{place}.force")));
                    }
                    let direction = match l.direction {
                        None => None,
                        Some(d) => {
                            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                            if !(n > 0.0 && n.is_finite()) {
                                return Err(Error::invalid(format!(
                                    "must be a non-zero finite vector (got {d:?})"
                                ))
                                .at(&format!("{place}.direction")));
                            }
                            Some(d.map(|x| x / n))
                        }
                    };
                    out.push(LoadSetup {
                        patch,
                        side: side(l.side),
                        force: l.force,
                        direction,
                    });
                }
                out
            }
        };
        if loads.iter().any(|l| l.direction.is_none()) && clamped.is_empty() {
            return Err(Error::invalid(
                "a line load without a direction points towards the first clamped edge, but no \
                 edge is clamped: give the load a direction",
            )
            .at("shell.line_loads"));
        }
        let pressure = s.pressure.unwrap_or(0.0);
        if !pressure.is_finite() {
            return Err(
                Error::invalid(format!("must be finite (got {pressure})")).at("shell.pressure")
            );
        }
        let time_limit = positive(s.time_limit.unwrap_or(300.0), 86400.0, "shell.time_limit")?;
        Ok(ShellSetup {
            thickness,
            material,
            elements,
            clamped,
            loads,
            pressure,
            time_limit: Duration::from_secs_f64(time_limit),
            metres: spec.units.unwrap_or(Units::Millimetre).metres(),
        })
    }

    /// Refuses an element grid whose model would be too large: above [`MAX_NODES`] nodes, or
    /// above the memory budget ([`crate::memory`]) at [`BYTES_PER_SHELL_NODE`]; `place` names
    /// the field or flag.
    pub fn check_size(&self, patches: usize, place: &str) -> Result<()> {
        let (nu, nv) = self.elements;
        let nodes = (patches as u64)
            .saturating_mul(2 * nu as u64 + 1)
            .saturating_mul(2 * nv as u64 + 1);
        if nodes > MAX_NODES as u64 {
            return Err(Error::invalid(format!(
                "{nu} × {nv} cells on {patches} patches make about {nodes} nodes, above the \
                 limit of {MAX_NODES}"
            ))
            .at(place));
        }
        crate::memory::check_items(nodes, BYTES_PER_SHELL_NODE, "the shell model", place)
    }

    /// How to run the solver: `PDESHAPE_CCX` or `ccx` on the `PATH`, with the time limit.
    pub fn run_options(&self) -> RunOptions {
        RunOptions {
            time_limit: self.time_limit,
            ..RunOptions::default()
        }
    }

    /// The shell model of the solved design's surfaces: meshed, scaled to metres, with the
    /// clamped edges and loads (a load without a direction points from its edge's centroid to
    /// the first clamped edge's centroid).
    pub fn model(&self, built: &SolvedDesign) -> Result<ShellModel> {
        self.check_size(built.surfaces.len(), "shell.elements")?;
        let surfaces: Vec<&dyn crate::surface::Surface> =
            built.surfaces.iter().map(|s| s.surface()).collect();
        let names = built.names();
        let mut mesh = ShellMesh::new(&surfaces, &names, self.elements.0, self.elements.1)?;
        for p in &mut mesh.nodes {
            *p = p.map(|x| x * self.metres);
        }
        let centroid = |patch: usize, side: Side| -> [f64; 3] {
            let ids = mesh.edge_nodes(patch, side);
            let mut c = [0.0; 3];
            for &i in &ids {
                for (ck, pk) in c.iter_mut().zip(mesh.nodes[i as usize]) {
                    *ck += pk;
                }
            }
            c.map(|x| x / ids.len().max(1) as f64)
        };
        let mut line_loads = Vec::with_capacity(self.loads.len());
        for (i, l) in self.loads.iter().enumerate() {
            let direction = match l.direction {
                Some(d) => d,
                None => {
                    let (cp, cs) = self.clamped[0];
                    let a = centroid(l.patch, l.side);
                    let b = centroid(cp, cs);
                    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    if n.is_nan() || n <= 1e-9 * self.metres {
                        return Err(Error::invalid(
                            "the loaded edge's centroid is the clamped edge's: the default \
                             direction is undefined; give the load a direction",
                        )
                        .at(&format!("shell.line_loads[{i}].direction")));
                    }
                    d.map(|x| x / n)
                }
            };
            line_loads.push(LineLoad {
                patch: l.patch,
                side: l.side,
                force_per_length: l.force,
                direction,
            });
        }
        Ok(ShellModel {
            mesh,
            thickness: self.thickness,
            material: self.material,
            clamped: self.clamped.clone(),
            line_loads,
            pressure: self.pressure,
        })
    }

    /// The wall's mass (kg): density × thickness × the area of the design's surfaces (exact
    /// quadrature, in square metres).
    pub fn mass(&self, built: &SolvedDesign) -> Result<f64> {
        let q = crate::analysis::Quadrature::fixed(48, 4 * self.elements.1.max(32));
        let area = crate::analysis::integrate_design(built, &q)?.total.area;
        Ok(self.material.density * self.thickness * area * self.metres * self.metres)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(shell: &str) -> Result<DesignSpec> {
        let (top, shell) = match shell.strip_prefix("units = \"cm\"\n") {
            Some(rest) => ("units = \"cm\"\n", rest),
            None => ("", shell),
        };
        crate::spec::parse_design(&format!(
            "{top}[[parametric]]\nname = \"wall\"\nx = \"cos(v)\"\ny = \"sin(v)\"\nz = \"u\"\n\
             [[parametric]]\nname = \"top\"\nx = \"(1+u)*cos(v)\"\ny = \"(1+u)*sin(v)\"\nz = \"1\"\n{shell}"
        ))
    }

    #[test]
    fn defaults_are_the_books_set_up() {
        let s = ShellSetup::new(&spec("").unwrap(), &["wall", "top"]).unwrap();
        assert_eq!(s.clamped, vec![(0, Side::U0)]);
        assert_eq!(
            s.loads,
            vec![LoadSetup {
                patch: 1,
                side: Side::U1,
                force: 15.0,
                direction: None
            }]
        );
        assert_eq!(s.thickness, DEFAULT_THICKNESS);
        assert_eq!(s.material, Material::POLYSTYRENE);
        assert_eq!(s.metres, 1e-3);
    }

    #[test]
    fn bad_values_name_their_place() {
        for (text, place, words) in [
            ("[shell]\nthickness = 0.0", "shell.thickness", "positive"),
            ("[shell]\nthickness = -1e-3", "shell.thickness", "positive"),
            ("[shell]\nthickness = 0.5", "shell.thickness", "at most"),
            ("[shell]\nelements = [0, 8]", "shell.elements", "nu"),
            ("[shell]\nelements = [4, 1]", "shell.elements", "nv"),
            ("[shell.material]\npoisson_ratio = 0.5", "shell.material.poisson_ratio", "0.5"),
            ("[shell.material]\nyoungs_modulus = -3e9", "shell.material.youngs_modulus", "positive"),
            ("[shell]\nclamped = [{ patch = \"lid\", side = \"u0\" }]", "shell.clamped[0].patch", "'lid'"),
            ("[shell]\ntime_limit = 0.0", "shell.time_limit", "positive"),
            (
                "[shell]\nclamped = []\nline_loads = [{ patch = \"top\", side = \"u1\", force = 1.0 }]",
                "shell.line_loads",
                "direction",
            ),
            (
                "[shell]\nline_loads = [{ patch = \"top\", side = \"u1\", force = 1.0, direction = [0.0, 0.0, 0.0] }]",
                "shell.line_loads[0].direction",
                "non-zero",
            ),
        ] {
            let e = ShellSetup::new(&spec(text).unwrap(), &["wall", "top"]).unwrap_err();
            assert_eq!(e.place(), place, "{text}: {e}");
            assert!(e.to_string().contains(words), "{text}: {e}");
        }
        // Unknown keys and wrong sides are refused by the reader.
        assert!(spec("[shell]\nthicknes = 1e-3").is_err());
        assert!(spec("[shell]\nclamped = [{ patch = \"wall\", side = \"v0\" }]").is_err());
    }

    #[test]
    fn too_large_models_are_refused_before_meshing() {
        let s = ShellSetup::new(
            &spec("[shell]\nelements = [400, 1000]").unwrap(),
            &["wall", "top"],
        )
        .unwrap();
        let e = s.check_size(2, "--elements").unwrap_err();
        assert_eq!(e.place(), "--elements");
        assert!(e.to_string().contains("limit"), "{e}");
    }

    #[test]
    fn the_model_is_in_metres_and_the_default_load_points_to_the_base() {
        let spec = spec("units = \"cm\"\n[shell]\nelements = [2, 8]").unwrap();
        let built = crate::design::solve_design(&spec).unwrap();
        let s = ShellSetup::new(&spec, &built.names()).unwrap();
        let m = s.model(&built).unwrap();
        let top = m
            .mesh
            .nodes
            .iter()
            .map(|p| p[2])
            .fold(f64::NEG_INFINITY, f64::max);
        assert!((top - 0.01).abs() < 1e-15, "{top}");
        let d = m.line_loads[0].direction;
        // From the ring u = 1 of "top" (radius 2, z = 1) to the base ring (radius 1, z = 0).
        assert!(d[0].abs() < 1e-12 && d[1].abs() < 1e-12 && (d[2] + 1.0).abs() < 1e-12);
        // Mass: ρ t (area of the wall 2π·1·1 + the annulus π(2² − 1²)) cm².
        let area = (2.0 * std::f64::consts::PI + 3.0 * std::f64::consts::PI) * 1e-4;
        let want = 1050.0 * DEFAULT_THICKNESS * area;
        let mass = s.mass(&built).unwrap();
        assert!((mass - want).abs() < 1e-12 * want.max(1.0), "{mass} {want}");
    }
}
