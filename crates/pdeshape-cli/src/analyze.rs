//! `pdeshape analyze DESIGN [--json]`: area, enclosed volume, curvature integrals and energies
//! per patch and in total.

use crate::common::{self, CliError};
use pdeshape::analysis::{integrate_design, DesignIntegrals, Integrals, Quadrature};
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Relative tolerance of the adaptive quadrature (default 1e-11).
    #[arg(long)]
    pub tolerance: Option<f64>,
}

pub fn run(args: &Args) -> Result<(), CliError> {
    let q = match args.tolerance {
        None => Quadrature::default(),
        Some(t) if t > 0.0 && t.is_finite() && t < 1.0 => Quadrature {
            tolerance: t,
            ..Quadrature::default()
        },
        Some(t) => {
            return Err(CliError::input(format!(
                "--tolerance: must be positive and below 1 (got {t})"
            )))
        }
    };
    let mut design = common::load(&args.design)?;
    common::apply_sets(&mut design, &args.set)?;
    let built = design.build()?;
    let di = integrate_design(&built, &q).map_err(|e| CliError::input(e.to_string()))?;
    let mut text = if args.json {
        json(&built.title, &di)
    } else {
        table(&built.title, &di)
    };
    if !built.trims.is_empty() {
        let trimmed =
            pdeshape::analysis::integrate_trimmed_design(&built, TRIM_NU, TRIM_NV, &di.orientation)
                .map_err(|e| design.error(&e))?;
        if args.json {
            let mut v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
            v["trimmed"] = trimmed
                .iter()
                .map(|t| {
                    serde_json::json!({
                        "name": t.name, "area": num(t.area), "volume": num(t.volume),
                        "area_change": num(t.area_change), "grids": t.grids,
                    })
                })
                .collect();
            text = serde_json::to_string_pretty(&v).unwrap_or_default();
            text.push('\n');
        } else {
            text.push_str("trimmed (what remains after the holes; above: untrimmed):\n");
            for t in &trimmed {
                text.push_str(&format!(
                    "{:<14}{:>17.10e}{:>17.10e}  (area change {:.2e} from {}×{} to {}×{})\n",
                    t.name,
                    t.area,
                    t.volume,
                    t.area_change,
                    t.grids[0][0],
                    t.grids[0][1],
                    t.grids[1][0],
                    t.grids[1][1]
                ));
            }
        }
    }
    common::print_stdout(&text);
    Ok(())
}

/// The `--json` report of a solved design (also the designer's analysis panel).
pub fn design_json(built: &pdeshape::design::SolvedDesign) -> Result<String, CliError> {
    let di = integrate_design(built, &Quadrature::default())
        .map_err(|e| CliError::input(e.to_string()))?;
    Ok(json(&built.title, &di))
}
/// The coarser of the two grids the trimmed integrals are computed on.
const TRIM_NU: usize = 129;
const TRIM_NV: usize = 256;

/// A number for JSON: finite numbers as they are, others as null.
fn num(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

fn integrals_json(i: &Integrals) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    for (k, v) in [
        ("area", i.area),
        ("volume", i.volume),
        ("mean_integral", i.mean),
        ("mean_sq_integral", i.mean_sq),
        ("gauss_integral", i.gauss),
        ("bending_energy", i.bending_energy()),
        ("willmore", i.willmore()),
    ] {
        m.insert(k.to_string(), num(v));
    }
    m
}

fn json(title: &Option<String>, d: &DesignIntegrals) -> String {
    let patches: Vec<serde_json::Value> = d
        .patches
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let a = &d.analyses[k];
            let mut m = integrals_json(i);
            m.insert("name".into(), d.names[k].clone().into());
            m.insert("orientation".into(), num(d.orientation[k]));
            // K does not depend on the orientation; H follows it.
            let s = d.orientation[k];
            let (h0, h1) = (a.mean_range.0 * s, a.mean_range.1 * s);
            m.insert("gauss_min".into(), num(a.gauss_range.0));
            m.insert("gauss_max".into(), num(a.gauss_range.1));
            m.insert("mean_min".into(), num(h0.min(h1)));
            m.insert("mean_max".into(), num(h0.max(h1)));
            m.insert("quadrature_error".into(), num(a.error));
            m.insert("converged".into(), a.converged.into());
            m.insert("nodes".into(), serde_json::json!([a.u_nodes, a.v_nodes]));
            serde_json::Value::Object(m)
        })
        .collect();
    let mut total = integrals_json(&d.total);
    total.insert("reduced_volume".into(), num(d.total.reduced_volume()));
    total.insert("equivalent_radius".into(), num(d.total.equivalent_radius()));
    let caps: Vec<serde_json::Value> = d
        .caps
        .iter()
        .map(|c| {
            serde_json::json!({
                "patch": d.names[c.patch], "u": c.u, "volume": num(c.volume),
                "area": num(c.area), "planarity": num(c.planarity)
            })
        })
        .collect();
    let v = serde_json::json!({
        "title": title,
        "closed": d.closed,
        "patches": patches,
        "total": total,
        "caps": caps,
        "quadrature_error": num(d.error),
    });
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}

fn table(title: &Option<String>, d: &DesignIntegrals) -> String {
    let mut s = String::new();
    if let Some(t) = title {
        let _ = writeln!(s, "design: {t}");
    }
    let _ = writeln!(
        s,
        "{:<14}{:>17}{:>17}{:>17}{:>17}{:>17}{:>17}",
        "patch", "area", "volume", "bending", "willmore", "∫K dA", "∫H dA"
    );
    let row = |s: &mut String, name: &str, i: &Integrals| {
        let _ = writeln!(
            s,
            "{:<14}{:>17.10e}{:>17.10e}{:>17.10e}{:>17.10e}{:>17.10e}{:>17.10e}",
            name,
            i.area,
            i.volume,
            i.bending_energy(),
            i.willmore(),
            i.gauss,
            i.mean
        );
    };
    for (k, i) in d.patches.iter().enumerate() {
        row(&mut s, &d.names[k], i);
    }
    row(&mut s, "total", &d.total);
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<14}{:>17}{:>17}{:>17}{:>17}",
        "patch", "K min", "K max", "H min", "H max"
    );
    for (k, a) in d.analyses.iter().enumerate() {
        let sgn = d.orientation[k];
        let (h0, h1) = (a.mean_range.0 * sgn, a.mean_range.1 * sgn);
        let _ = writeln!(
            s,
            "{:<14}{:>17.10e}{:>17.10e}{:>17.10e}{:>17.10e}",
            d.names[k],
            a.gauss_range.0,
            a.gauss_range.1,
            h0.min(h1),
            h0.max(h1)
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "closed: {}",
        if d.closed {
            "yes".to_string()
        } else if d.caps.is_empty() {
            "no (open in v: volume is the patches' (1/3)∫X·n dA only)".to_string()
        } else {
            let caps: Vec<String> = d
                .caps
                .iter()
                .map(|c| {
                    format!(
                        "'{}' u = {} (planarity {:.1e})",
                        d.names[c.patch], c.u, c.planarity
                    )
                })
                .collect();
            format!("no; volume closed by caps over {}", caps.join(", "))
        }
    );
    let _ = writeln!(
        s,
        "reduced volume ν = {:.10}   (R0 = √(A/4π) = {:.10e})",
        d.total.reduced_volume(),
        d.total.equivalent_radius()
    );
    let _ = writeln!(
        s,
        "quadrature: estimated relative error {:.1e}{}",
        d.error,
        if d.analyses.iter().all(|a| a.converged) {
            ""
        } else {
            " (NOT converged within the node budget)"
        }
    );
    s
}

/// sRGB colours per vertex, one list per mesh.
pub type MeshColors = Vec<Vec<[u8; 3]>>;

/// What `pdeshape render --color` colours by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorBy {
    /// Gaussian curvature K.
    Gauss,
    /// Mean curvature H (outward normal).
    Mean,
}

impl ColorBy {
    pub fn word(self) -> &'static str {
        match self {
            ColorBy::Gauss => "Gaussian",
            ColorBy::Mean => "mean",
        }
    }
}

/// `LO,HI` with finite `LO < HI`.
pub fn parse_range(s: &str) -> Result<(f64, f64), CliError> {
    let bad = || {
        CliError::input(format!(
            "--range: expected two numbers LO,HI with LO < HI (got '{s}')"
        ))
    };
    let (a, b) = s.split_once(',').ok_or_else(bad)?;
    let lo: f64 = a.trim().parse().map_err(|_| bad())?;
    let hi: f64 = b.trim().parse().map_err(|_| bad())?;
    if lo.is_finite() && hi.is_finite() && lo < hi {
        Ok((lo, hi))
    } else {
        Err(bad())
    }
}

/// Per-vertex colours of every mesh (PDE patches, then parametric surfaces, as
/// `common::meshes` orders them) by `K` or `H`, and the range used: `range`, or
/// `render::robust_range` of the values on the grids (1st to 99th percentile, symmetric about 0
/// when it spans 0; `±1` if no value is finite). `H` is taken with the design's outward
/// orientation.
pub fn curvature_colors(
    built: &pdeshape::design::SolvedDesign,
    meshes: &[pdeshape::mesh::GridMesh],
    by: ColorBy,
    range: Option<(f64, f64)>,
) -> Result<(MeshColors, f64, f64), CliError> {
    use pdeshape::surface::Surface;
    let surfaces: Vec<&dyn Surface> = built.surfaces.iter().map(|s| s.surface()).collect();
    let orientation = match by {
        ColorBy::Gauss => vec![1.0; surfaces.len()],
        ColorBy::Mean => {
            integrate_design(built, &Quadrature::default())
                .map_err(|e| CliError::input(e.to_string()))?
                .orientation
        }
    };
    let values: Vec<Vec<f64>> = surfaces
        .iter()
        .zip(meshes)
        .zip(&orientation)
        .map(|((s, m), sign)| {
            let (k, h) = pdeshape::analysis::curvature_grid(*s, &m.u, &m.v);
            match by {
                ColorBy::Gauss => k,
                ColorBy::Mean => h.into_iter().map(|x| x * sign).collect(),
            }
        })
        .collect();
    let (lo, hi) = match range {
        Some(r) => r,
        None => pdeshape::render::robust_range(values.iter().flatten()).unwrap_or((-1.0, 1.0)),
    };
    let colors = values
        .iter()
        .map(|v| pdeshape::render::diverging_colors(v, lo, hi))
        .collect();
    Ok((colors, lo, hi))
}
