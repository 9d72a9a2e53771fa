//! `pdeshape spline DESIGN -o OUT`: solve the `[spline]` section (a B-spline or Bézier surface
//! solving a linear PDE from fixed control points), report rank and free points, and write the
//! control net (json), the surface as IGES 5.3 (igs, iges), or a mesh/samples (obj, stl, ply,
//! glb, csv).

use crate::common::{self, CliError, Output};
use pdeshape::design::solve_spec;
use pdeshape::mesh::{self, Format};
use pdeshape::splinepde::export::{iges_timestamp, to_iges_in, IgesOptions, IgesUnit};
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML) with a [spline] section.
    pub design: PathBuf,
    /// Output file; the extension picks the format: json (control net and report), igs or iges
    /// (IGES 5.3 B-spline surface), obj, stl, ply, glb or csv (grid of the surface).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The format (json, igs, obj, stl, ply, glb or csv), when -o has no extension or is `-`
    /// (standard output).
    #[arg(long)]
    pub format: Option<String>,
    /// Grid rows for meshes (values of u; default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns for meshes (values of v; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
}

enum Kind {
    Json,
    Iges,
    Grid(Format),
}

fn kind(path: &std::path::Path) -> Result<Kind, CliError> {
    let shown = path.display();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("json") => Ok(Kind::Json),
        Some("igs") | Some("iges") => Ok(Kind::Iges),
        Some(_) => Format::from_path(path).map(Kind::Grid).map_err(|_| {
            CliError::input(format!(
                "-o {shown}: unknown output extension: use .json, .igs, .iges, .obj, .stl, .ply, .glb or .csv"
            ))
        }),
        None => Err(CliError::input(format!(
            "-o {shown}: no extension: use .json, .igs, .iges, .obj, .stl, .ply, .glb or .csv"
        ))),
    }
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    let fpath = common::format_path(
        &args.output,
        args.format.as_deref(),
        "json, igs, iges, obj, stl, ply, glb or csv",
    )?;
    let kind = kind(&fpath).map_err(|e| match &args.format {
        Some(f) => CliError::input(format!(
            "--format {}: unknown format: use json, igs, iges, obj, stl, ply, glb or csv",
            common::shorten(f, 40)
        )),
        None => e,
    })?;
    match kind {
        Kind::Json => common::refuse_grid_flags(args.nu, args.nv, "a .json control net")?,
        Kind::Iges => common::refuse_grid_flags(args.nu, args.nv, "an IGES surface")?,
        Kind::Grid(_) => {}
    }
    let design = common::load(&args.design)?;
    let Some(spec) = design.spec.spline.as_ref() else {
        return Err(CliError::input(format!(
            "{}: the design has no [spline] section (pdeshape spline solves a B-spline/Bézier PDE surface; use pdeshape surface for conditions)",
            design.file
        )));
    };
    let grid = match kind {
        Kind::Grid(_) => Some(design.grid(args.nu, args.nv)?),
        _ => None,
    };
    let mut out = Output::create(&args.output)?;
    let solved = solve_spec(spec).map_err(|e| design.error(&e))?;
    let io = |e: std::io::Error| CliError::input(format!("-o {shown}: {e}"));
    match kind {
        Kind::Json => {
            let text = serde_json::to_string_pretty(&solved.to_json())
                .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
            out.write_all(text.as_bytes())?;
            out.write_all(b"\n")?;
        }
        Kind::Iges => {
            let seconds = pdeshape::format::export_timestamp();
            let name = args
                .output
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            let name: String = name
                .chars()
                .map(|c| if c.is_ascii_graphic() { c } else { '_' })
                .collect();
            let text = to_iges_in(
                &solved.to_f64(),
                &IgesOptions {
                    file_name: name,
                    timestamp: iges_timestamp(seconds),
                },
                IgesUnit::from(design.spec.units.unwrap_or_default()),
            )
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
            out.write_all(text.as_bytes())?;
        }
        Kind::Grid(format) => {
            let (nu, nv) =
                grid.unwrap_or((pdeshape::design::DEFAULT_NU, pdeshape::design::DEFAULT_NV));
            let surface = solved
                .to_f64()
                .to_bspline()
                .map_err(|e| design.error(&e.at("spline")))?;
            let err = |e: pdeshape::Error| CliError::input(format!("-o {shown}: {e}"));
            let mut w = out.writer();
            if format == Format::Csv {
                let mut s = mesh::sample(&surface, nu, nv).map_err(err)?;
                // One convention for both columns: u and v in the knot domain of their knot
                // vectors (the surface is evaluated with u normalised to [0, 1]).
                let [[a, b], _] = surface.domain();
                for u in &mut s.u {
                    *u = a + (b - a) * *u;
                }
                mesh::write_csv(&[s], &mut w).map_err(err)?;
            } else {
                let m = mesh::tessellate(&surface, nu, nv).map_err(err)?;
                mesh::write(format, &[m], &mut w).map_err(err)?;
            }
            w.flush().map_err(io)?;
        }
    }
    out.commit()?;
    common::report(&format!(
        "{}wrote {}\n",
        pdeshape::diagnostics::spline_report(&solved),
        common::destination(&args.output)
    ));
    Ok(())
}
