//! `pdeshape import PART.step|PART.igs -o part.toml [--fill | --fill-g2]`: a CAD part's faces
//! and edges
//! as a design file (faces on planes, cylinders, cones, spheres and tori as `[[parametric]]`
//! surfaces, on (rational) B-spline surfaces as `[[nurbs]]` surfaces, edges as curves), with
//! `--fill` an `[[nsided]]` patch tangent to the faces around every gap (`--fill-g2`: of order
//! 3, curvature-continuous to them).

use crate::common::{self, CliError, Output};
use pdeshape::cad::import;
use pdeshape::format::OutputFormat;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The part: a STEP file (.step, .stp) of faces (ADVANCED_FACE) with their edges, or an
    /// IGES file (.igs, .iges) of a B-rep (entities 186/514/510) or of trimmed surfaces (144).
    pub file: PathBuf,
    /// The design file to write (toml).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also fill every gap of 3 to 8 free edges with an n-sided patch tangent to the faces
    /// beside it.
    #[arg(long)]
    pub fill: bool,
    /// Fill the gaps (as --fill) with patches of order 3, curvature-continuous (G2) to the
    /// faces beside them; `check` reports their G2 residuals.
    #[arg(long)]
    pub fill_g2: bool,
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.file.display().to_string();
    let format = OutputFormat::from_path(&args.file).ok();
    if !matches!(format, Some(OutputFormat::Step | OutputFormat::Iges)) {
        return Err(CliError::input(format!(
            "{shown}: not a STEP or IGES file name (.step, .stp, .igs, .iges)"
        )));
    }
    let out_ext = args.output.extension().and_then(|e| e.to_str());
    if !out_ext.is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        return Err(CliError::input(format!(
            "-o {}: import writes a design file (.toml)",
            args.output.display()
        )));
    }
    let text = crate::cad::read_text(&args.file)?;
    let fill = match (args.fill, args.fill_g2) {
        (_, true) => import::Fill::G2,
        (true, false) => import::Fill::G1,
        (false, false) => import::Fill::None,
    };
    let read = if format == Some(OutputFormat::Iges) {
        import::import_iges
    } else {
        import::import_step
    };
    let imported = read(&text, fill)
        .map_err(|e| CliError::input(format!("{shown}: {}", common::message_of(&e))))?;
    let mut spec = imported.spec.clone();
    spec.title = args
        .file
        .file_stem()
        .map(|s| format!("{} (imported)", s.to_string_lossy()));
    let toml = pdeshape::spec::write_design(&spec)
        .map_err(|e| CliError::input(format!("{shown}: {}", common::message_of(&e))))?;
    let source = args
        .file
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut out = Output::create(&args.output)?;
    out.write_all(imported.header(&source).as_bytes())?;
    out.write_all(toml.as_bytes())?;
    out.commit()?;
    let mut report = String::new();
    let read = imported.faces.iter().filter(|f| f.imported).count();
    let _ = writeln!(
        report,
        "wrote {}: {} of {} faces, {} edges, {} gap(s)",
        common::destination(&args.output),
        read,
        imported.faces.len(),
        spec.curves.len(),
        imported.gaps.len()
    );
    for f in &imported.faces {
        let what = if f.imported {
            ""
        } else {
            " (not read: skipped)"
        };
        let _ = writeln!(
            report,
            "  {} ({}): {}{what}; edges {}",
            f.name,
            f.place,
            f.kind,
            f.edges.join(", ")
        );
    }
    for g in &imported.gaps {
        let to = match (&g.patch, &g.note) {
            (Some(p), _) if fill == import::Fill::G2 => format!("filled by [[nsided]] {p} (G2)"),
            (Some(p), _) => format!("filled by [[nsided]] {p}"),
            (None, Some(n)) => format!("not filled: {n}"),
            (None, None) => "not filled (pass --fill or --fill-g2)".to_string(),
        };
        let _ = writeln!(
            report,
            "  gap of {} edges ({}): {to}",
            g.edges.len(),
            g.edges.join(", ")
        );
    }
    common::report(report.trim_end());
    Ok(())
}
