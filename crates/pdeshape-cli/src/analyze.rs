//! `pdeshape analyze DESIGN [--json]`: area, enclosed volume, curvature integrals and energies
//! per patch and in total.

use crate::common::{self, CliError};
use pdeshape::analysis::{integrate_design, Quadrature};
use pdeshape::analysis_report::{self, integrals_json, integrals_table, num, Curvature};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
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

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
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
        integrals_json(&built.title, &di)
    } else {
        integrals_table(&built.title, design.spec.units, &di)
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
                use pdeshape::number::{sig, DIGITS};
                text.push_str(&format!(
                    "{:<14}{:>14}{:>14}  (area change {} from {}×{} to {}×{})\n",
                    t.name,
                    sig(t.area, DIGITS),
                    sig(t.volume, DIGITS),
                    sig(t.area_change, 2),
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

/// The coarser of the two grids the trimmed integrals are computed on.
const TRIM_NU: usize = 129;
const TRIM_NV: usize = 256;

pub(crate) use pdeshape::analysis_report::MeshColors;

/// What `pdeshape render --color` colours by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum ColorBy {
    /// Gaussian curvature K.
    Gauss,
    /// Mean curvature H (outward normal).
    Mean,
}

impl ColorBy {
    pub(crate) fn word(self) -> &'static str {
        match self {
            ColorBy::Gauss => "Gaussian",
            ColorBy::Mean => "mean",
        }
    }
}

/// `LO,HI` with finite `LO < HI`.
pub(crate) fn parse_range(s: &str) -> Result<(f64, f64), CliError> {
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

/// Per-vertex colours of every mesh by `K` or `H` and the range used
/// ([`pdeshape::analysis_report::curvature_colors`]).
pub(crate) fn curvature_colors(
    built: &pdeshape::design::SolvedDesign,
    meshes: &[pdeshape::mesh::GridMesh],
    by: ColorBy,
    range: Option<(f64, f64)>,
) -> Result<(MeshColors, f64, f64), CliError> {
    let by = match by {
        ColorBy::Gauss => Curvature::Gauss,
        ColorBy::Mean => Curvature::Mean,
    };
    analysis_report::curvature_colors(built, meshes, by, range)
        .map_err(|e| CliError::input(e.to_string()))
}
