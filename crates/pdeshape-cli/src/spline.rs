//! `pdeshape spline DESIGN -o OUT`: solve the `[spline]` section (a B-spline or Bézier surface
//! solving a linear PDE from fixed control points), report rank and free points, and write the
//! control net (json), the surface as IGES 5.3 (igs, iges), or a mesh/samples (obj, stl, ply,
//! glb, csv).

use crate::common::{self, CliError, Output};
use pdeshape::design::solve_spec;
use pdeshape::format::OutputFormat;
use pdeshape::mesh::{self, Format};
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

/// What `-o`/`--format` asks for: the control net (`json`), IGES, or a mesh or sample format.
fn kind(request: &common::FormatRequest) -> Result<Kind, CliError> {
    let found = if request.names("json") {
        Some(Kind::Json)
    } else {
        match request.output_format() {
            Ok(OutputFormat::Iges) => Some(Kind::Iges),
            Ok(f) => f.mesh().ok().map(Kind::Grid),
            Err(_) => None,
        }
    };
    found.ok_or_else(|| {
        let shown = &request.shown;
        CliError::input(match (request.flag, &request.name) {
            ("--format", _) => format!(
                "--format {}: unknown format: use json, igs, iges, obj, stl, ply, glb or csv",
                common::shorten(shown, 40)
            ),
            (_, None) => format!(
                "-o {shown}: no extension: use .json, .igs, .iges, .obj, .stl, .ply, .glb or .csv"
            ),
            _ => format!(
                "-o {shown}: unknown output extension: use .json, .igs, .iges, .obj, .stl, .ply, .glb or .csv"
            ),
        })
    })
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    let kind = kind(&common::format_request(
        &args.output,
        args.format.as_deref(),
        "json, igs, iges, obj, stl, ply, glb or csv",
    )?)?;
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
            let name = args
                .output
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            let text = pdeshape::format::write_spline_iges(
                &solved.to_f64(),
                design.spec.units.unwrap_or_default(),
                &name,
                pdeshape::format::export_timestamp(),
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
