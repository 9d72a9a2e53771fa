//! `pdeshape check DESIGN`: validate, solve and report.
//!
//! The report starts with the library's verdict: `OK`, `ATTENTION` or `FAIL`, followed by the
//! `fail:`, `warning:` and `attention:` lines that explain it. A shared edge (seam) creased by
//! more than `--g1-tolerance`, or (when `--g2-tolerance` is given) whose normal curvature jumps
//! across it by more than that, fails the check: `FAIL`, an `error:` line naming the seams on
//! stderr and exit status 1. `OK` and `ATTENTION` exit with status 0 (the design solved); a
//! refused design exits with status 2.

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
    /// The seam tolerance in radians: a shared edge whose tangent planes meet at a larger angle
    /// (G1) fails the check (exit status 1). The default is one degree; an intended crease (a
    /// lid, a flange) passes with a tolerance above its angle, e.g. `--g1-tolerance 1.6`.
    #[arg(long, value_name = "RAD", default_value_t = diagnostics::SEAM_G1_TOLERANCE)]
    pub g1_tolerance: f64,
    /// The curvature tolerance (1/length): a shared edge across which the two patches' normal
    /// curvatures differ by more (its G2 figure) fails the check (exit status 1). Not judged
    /// unless given: patches that share a derivative curve meet G1, not G2, so a default
    /// would fail designs that are as intended.
    #[arg(long, value_name = "1/LENGTH")]
    pub g2_tolerance: Option<f64>,
}

/// The diagnostics of a solved design, its seams judged by `--g1-tolerance`.
fn judged(args: &Args, design: &Loaded, built: &SolvedDesign) -> diagnostics::Diagnostics {
    let mut d = diagnostics::diagnose(&design.spec, built);
    d.judge_seams(args.g1_tolerance);
    if let Some(t) = args.g2_tolerance {
        d.judge_curvature(t);
    }
    d
}

/// `--g1-tolerance` and `--g2-tolerance` checked before the design is read: finite, at least 0.
fn check_tolerance(args: &Args) -> Result<(), CliError> {
    let t = args.g1_tolerance;
    if !(t.is_finite() && t >= 0.0) {
        return Err(CliError::input(format!(
            "--g1-tolerance: expected an angle in radians, at least 0 (got {t})"
        )));
    }
    match args.g2_tolerance {
        Some(t) if !(t.is_finite() && t >= 0.0) => Err(CliError::input(format!(
            "--g2-tolerance: expected a curvature (1/length), at least 0 (got {t})"
        ))),
        _ => Ok(()),
    }
}

/// Exit status 1 with the failing seams named, when the verdict is `FAIL`.
fn verdict_status(design: &Loaded, d: &diagnostics::Diagnostics) -> Result<(), CliError> {
    if d.verdict != diagnostics::Verdict::Fail {
        return Ok(());
    }
    let n = |x: f64| pdeshape::number::sig(x, pdeshape::number::DIGITS);
    let list = |seams: Vec<String>, what: &str, tolerance: String| {
        format!(
            "{} {}: {}",
            if seams.len() == 1 {
                "a shared edge is".to_string()
            } else {
                format!("{} shared edges are", seams.len())
            },
            format_args!("{what} {tolerance}"),
            seams.join(", ")
        )
    };
    let creased: Vec<String> = d
        .failed_seams()
        .filter(|e| e.g1_failed)
        .map(|e| {
            format!(
                "'{}' | '{}' along '{}' (G1 = {} rad)",
                e.a,
                e.b,
                e.curve,
                n(e.g1)
            )
        })
        .collect();
    let jumps: Vec<String> = d
        .failed_seams()
        .filter(|e| e.g2_failed)
        .map(|e| {
            format!(
                "'{}' | '{}' along '{}' (G2 = {})",
                e.a,
                e.b,
                e.curve,
                n(e.g2)
            )
        })
        .collect();
    let mut parts = Vec::new();
    if !creased.is_empty() {
        let t = n(d.g1_tolerance.unwrap_or(diagnostics::SEAM_G1_TOLERANCE));
        parts.push(list(
            creased,
            "creased beyond the G1 tolerance",
            format!("{t} rad"),
        ));
    }
    if !jumps.is_empty() {
        let t = n(d.g2_tolerance.unwrap_or(f64::NAN));
        parts.push(list(
            jumps,
            "curved unlike its neighbour beyond the G2 tolerance",
            t,
        ));
    }
    Err(CliError {
        message: format!("{}: {}", design.file, parts.join("; ")),
        status: 1,
    })
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
    check_tolerance(args)?;
    if args.json {
        // The report as JSON: per surface its kind, operator, modes and condition errors;
        // shared edges; warnings; the verdict; and the text report.
        let result = common::load(&args.design).and_then(|mut design| {
            common::apply_sets(&mut design, &args.set)?;
            let built = design.build()?;
            check_sections(&design, &built)?;
            let d = judged(args, &design, &built);
            let v = diagnostics::check_json(&design.file, &design.spec, &built, &d);
            Ok((v, verdict_status(&design, &d)))
        });
        return match result {
            Ok((v, status)) => {
                common::print_stdout(&format!("{v}\n"));
                status
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
    // The verdict and its reasons first, then the details.
    let d = judged(args, &design, &built);
    common::print_stdout(&diagnostics::check_text(
        &design.file,
        &design.spec,
        &built,
        &d,
    ));
    verdict_status(&design, &d)
}
