//! `pdeshape import PART.step -o part.toml [--fill]`: a CAD part's faces and edges as a design
//! file (faces on planes, cylinders, cones, spheres and tori as `[[parametric]]` surfaces, edges
//! as curves), with `--fill` an `[[nsided]]` patch tangent to the faces around every gap.

use crate::common::{self, CliError, Output};
use pdeshape::cad::import;
use pdeshape::format::OutputFormat;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The part: a STEP file (.step, .stp) of faces (ADVANCED_FACE) with their edges.
    pub file: PathBuf,
    /// The design file to write (toml).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also fill every gap of 3 to 8 free edges with an n-sided patch tangent to the faces
    /// beside it.
    #[arg(long)]
    pub fill: bool,
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.file.display().to_string();
    if OutputFormat::from_path(&args.file).ok() != Some(OutputFormat::Step) {
        return Err(CliError::input(format!(
            "{shown}: not a STEP file name (.step, .stp)"
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
    let imported = import::import_step(&text, args.fill)
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
            "  {} (line {}): {}{what}; edges {}",
            f.name,
            f.line,
            f.kind,
            f.edges.join(", ")
        );
    }
    for g in &imported.gaps {
        let to = match (&g.patch, &g.note) {
            (Some(p), _) => format!("filled by [[nsided]] {p}"),
            (None, Some(n)) => format!("not filled: {n}"),
            (None, None) => "not filled (pass --fill)".to_string(),
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
