//! `pdeshape check DESIGN`: validate, solve and report.
//!
//! The report ends with the library's verdict: `OK`, or `ATTENTION` after the `warning:` and
//! `attention:` lines that explain it. Both exit with status 0 (the design solved); a refused
//! design exits with status 2, and a failure that is not the input's (a bug) with 1.

use crate::common::{self, CliError, Loaded};
use pdeshape::design::SolvedDesign;
use pdeshape::diagnostics;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Print the report as one JSON object with the `verdict` (`"ok"` or `"attention"`);
    /// `"ok": false` and the error when the design is refused (the error line still goes to
    /// stderr with exit status 2).
    #[arg(long)]
    pub json: bool,
}

/// The text report of a solved design: the verdict and its reasons first, then the details.
fn report(design: &Loaded, built: &SolvedDesign) -> String {
    let d = diagnostics::diagnose(&design.spec, built);
    diagnostics::check_text(&design.file, &design.spec, built, &d)
}

/// The report as JSON: per surface its kind, operator, modes and condition errors; shared edges;
/// warnings; the verdict; and the text report.
fn report_json(design: &Loaded, built: &SolvedDesign) -> serde_json::Value {
    let d = diagnostics::diagnose(&design.spec, built);
    diagnostics::check_json(&design.file, &design.spec, built, &d)
}

/// The sections other commands act on, checked as those commands would read them, so that
/// `check` refuses what they refuse: `[shell]` (thickness, material, elements, edges, loads).
fn check_sections(design: &Loaded, built: &SolvedDesign) -> Result<(), CliError> {
    if design.spec.shell.is_some() {
        pdeshape::shell::ShellSetup::new(&design.spec, &built.names())
            .map_err(|e| design.error(&e))?;
    }
    Ok(())
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    if args.json {
        let result = common::load(&args.design).and_then(|mut design| {
            common::apply_sets(&mut design, &args.set)?;
            let built = design.build()?;
            check_sections(&design, &built)?;
            Ok(report_json(&design, &built))
        });
        return match result {
            Ok(v) => {
                common::print_stdout(&format!("{v}\n"));
                Ok(())
            }
            Err(e) => {
                let v = serde_json::json!({ "ok": false, "error": e.message });
                common::print_stdout(&format!("{v}\n"));
                Err(e)
            }
        };
    }
    let mut design = common::load(&args.design)?;
    common::apply_sets(&mut design, &args.set)?;
    let built = design.build()?;
    check_sections(&design, &built)?;
    common::print_stdout(&report(&design, &built));
    Ok(())
}
