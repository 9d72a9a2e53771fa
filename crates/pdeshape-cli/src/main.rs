//! The `pdeshape` command-line tool: design files (TOML) in, meshes, samples, pictures and
//! reports out. Every failure prints one line `error: …` on stderr; bad input exits with status 2.

mod analyze;
mod animate;
mod blend;
mod cad;
mod check;
mod common;
mod curve;
mod fill;
mod fit;
mod import;
mod optimize;
mod render;
mod schema;
mod serve;
mod shell;
mod spline;
mod surface;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Geometric design with partial differential equations (Bloor–Wilson PDE surfaces).
#[derive(Parser, Debug)]
#[command(name = "pdeshape", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print no "wrote …" lines, notes or progress bars (reports and errors still print).
    #[arg(long, short, global = true)]
    quiet: bool,
    /// Replace output files even when they are read-only.
    #[arg(long, global = true)]
    force: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve a design and write its surface (obj, stl, ply, glb or csv, chosen by extension).
    Surface(surface::Args),
    /// Solve a design and render it with its boundary curves and spine to a PNG picture.
    Render(render::Args),
    /// Validate and solve a design and print a report (modes, condition errors, shared edges)
    /// led by its verdict: OK, ATTENTION (warnings, gaps, small creases; both exit with status
    /// 0) or FAIL (a shared edge creased beyond --g1-tolerance, or curved unlike its
    /// neighbour beyond --g2-tolerance if given; status 1); a refused design exits with 2.
    Check(check::Args),
    /// Run the [dynamic] section of a design (a dynamic PDE curve) and write the final curve
    /// (csv), optionally its frames (csv) and a picture (svg).
    Curve(curve::Args),
    /// Search the design parameters of [optimize] (simulated annealing, then Nelder–Mead) and
    /// write the optimised design file, its mesh, picture and the search log.
    Optimize(optimize::Args),
    /// Print the JSON schema of the design file (or of a morph file or a fit template, with
    /// --kind), for editors.
    Schema(schema::Args),
    /// Solve a [blend] design (a smoothing PDE spline joining two surfaces) and write it (obj,
    /// stl, ply, glb, csv, or json for the control net), reporting the G0/G1 mismatch.
    Blend(blend::Args),
    /// Area, enclosed volume, curvature integrals and bending energies, per patch and in total.
    Analyze(analyze::Args),
    /// Solve the [spline] section (B-spline/Bézier surface of a linear PDE) and write its net
    /// (json), an IGES surface (igs) or a mesh; prints rank and free control points.
    Spline(spline::Args),
    /// Start the browser designer on a local web server and print its URL (with a per-launch
    /// token): drag curves and watch the surface re-solve.
    Serve(serve::Args),
    /// Fit PDE patches to a triangle mesh (obj, stl, ply, off, glb, gltf) and write the design
    /// (toml), with the two-sided distances and the compression ratio.
    Fit(fit::Args),
    /// Fill the holes of a triangle mesh (obj, stl, ply, off, glb, gltf) with PDE patches G1 to
    /// the mesh and weld them in; write the mesh (obj, stl, ply or glb), watertight if it had
    /// only holes.
    Fill(fill::Args),
    /// Read a CAD part's faces and edges from a STEP or IGES file into a design file (toml);
    /// with --fill, an n-sided patch tangent to the faces around every gap.
    Import(import::Args),
    /// Read a STEP or IGES file written by `surface` back and measure its surfaces against the
    /// design's (the largest deviation per surface).
    Roundtrip(cad::RoundtripArgs),
    /// Solve a time-dependent design ([time] with formulas in t, or a [morph] file) at every
    /// frame and write a glTF animation, with per-frame measures (csv, svg) and pictures (png).
    Animate(animate::Args),
    /// Thin-shell strength analysis with CalculiX ([shell], or the book's set-up): largest
    /// shear stress and where, ratio to yield, mass; the stress field as vtu or csv.
    Shell(shell::Args),
}

fn run(cli: Cli) -> Result<(), common::CliError> {
    match cli.command {
        Command::Surface(args) => surface::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Curve(args) => curve::run(&args),
        Command::Optimize(args) => optimize::run(&args),
        Command::Schema(args) => schema::run(&args),
        Command::Blend(args) => blend::run(&args),
        Command::Analyze(args) => analyze::run(&args),
        Command::Spline(args) => spline::run(&args),
        Command::Serve(args) => serve::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Fill(args) => fill::run(&args),
        Command::Import(args) => import::run(&args),
        Command::Roundtrip(args) => cad::roundtrip(&args),
        Command::Animate(args) => animate::run(&args),
        Command::Shell(args) => shell::run(&args),
    }
}

/// The suggestion for a misspelt subcommand, flag or value (clap's "tip" paragraph, which the
/// one-line error would otherwise drop), as "; did you mean '…'?": of clap's candidates, the
/// nearest to what was typed by the library's string distance, else clap's best.
fn did_you_mean(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let typed = [
        ContextKind::InvalidSubcommand,
        ContextKind::InvalidArg,
        ContextKind::InvalidValue,
    ]
    .into_iter()
    .find_map(|k| match e.get(k) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    });
    for kind in [
        ContextKind::SuggestedSubcommand,
        ContextKind::SuggestedArg,
        ContextKind::SuggestedValue,
    ] {
        let candidates: Vec<String> = match e.get(kind) {
            Some(ContextValue::String(s)) => vec![s.clone()],
            Some(ContextValue::Strings(v)) => v.clone(),
            _ => continue,
        };
        let best = typed
            .as_deref()
            .and_then(|t| {
                pdeshape::spec::suggest::nearest(t, candidates.iter().map(String::as_str))
            })
            .or(candidates.last().map(String::as_str));
        if let Some(b) = best {
            return format!("; did you mean '{b}'?");
        }
    }
    String::new()
}

fn main() -> ExitCode {
    common::mark_start();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    print!("{e}");
                    ExitCode::SUCCESS
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    use clap::CommandFactory;
                    let names: Vec<String> = Cli::command()
                        .get_subcommands()
                        .filter(|c| !c.is_hide_set())
                        .map(|c| c.get_name().to_string())
                        .collect();
                    let (last, rest) = names.split_last().expect("subcommands");
                    eprintln!(
                        "error: a subcommand is required: {} or {last} (see pdeshape --help)",
                        rest.join(", ")
                    );
                    ExitCode::from(2)
                }
                _ => {
                    // clap's message starts with "error: " and its first paragraph says what
                    // is wrong; print that paragraph on one line.
                    let text = e.render().to_string();
                    let paragraph: Vec<&str> = text
                        .lines()
                        .skip_while(|l| l.trim().is_empty())
                        .take_while(|l| !l.trim().is_empty())
                        .map(str::trim)
                        .collect();
                    let line = paragraph.join(" ");
                    let line = line.strip_prefix("error:").unwrap_or(&line).trim();
                    eprintln!("error: {line}{}", did_you_mean(&e));
                    ExitCode::from(2)
                }
            };
        }
    };
    common::set_flags(cli.quiet, cli.force);
    // The designer's server stops cleanly on its own signal handler (and saves atomically
    // through its own files); every other command removes its temporaries when stopped.
    if !matches!(cli.command, Command::Serve(_)) {
        common::remove_temporaries_on_signals();
    }
    // A panic is a bug; report it on one line like every other failure.
    std::panic::set_hook(Box::new(|_| {}));
    // The outputs of a command are renamed into place together once it succeeded, all or none.
    let result = std::panic::catch_unwind(move || run(cli).and_then(|()| common::finish_outputs()));
    if !matches!(result, Ok(Ok(()))) {
        common::abandon_outputs();
    }
    common::end_run();
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => {
            // One line, whatever a message quotes from the input.
            eprintln!(
                "error: {}",
                e.message.replace('\r', "\\r").replace('\n', "\\n")
            );
            ExitCode::from(e.status)
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            eprintln!(
                "error: internal error: {}",
                what.lines().next().unwrap_or("")
            );
            ExitCode::from(1)
        }
    }
}
