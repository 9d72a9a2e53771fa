//! `pdeshape check DESIGN`: validate, solve and report.

use crate::common::{self, CliError, Loaded};
use pdeshape::design::SolvedDesign;
use pdeshape::diagnostics;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Print the report as one JSON object (`"ok": false` and the error when the design is
    /// refused; the error line still goes to stderr with exit status 2).
    #[arg(long)]
    pub json: bool,
}

/// The report for a solved design; the second value lists what deserves a warning.
pub(crate) fn report(design: &Loaded, built: &SolvedDesign) -> (String, Vec<String>) {
    let d = diagnostics::diagnose(&design.spec, built);
    let text = diagnostics::check_report(&design.file, &design.spec, built, &d);
    (text, d.warnings)
}

/// The report as JSON: per surface its kind, operator, modes and condition errors; shared edges;
/// warnings; and the text report.
pub(crate) fn report_json(design: &Loaded, built: &SolvedDesign) -> serde_json::Value {
    let d = diagnostics::diagnose(&design.spec, built);
    let text = diagnostics::check_report(&design.file, &design.spec, built, &d);
    let mut v = d.to_json();
    v["ok"] = serde_json::json!(true);
    v["design"] = serde_json::json!(design.file);
    v["report"] = serde_json::json!(text);
    v
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
    let (text, warnings) = report(&design, &built);
    let mut text = text;
    for w in &warnings {
        let _ = writeln!(text, "warning: {w}");
    }
    text.push_str("OK\n");
    common::print_stdout(&text);
    Ok(())
}
