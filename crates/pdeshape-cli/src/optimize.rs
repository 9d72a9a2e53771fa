//! `pdeshape optimize DESIGN -o BEST.toml`: search the design parameters of `[optimize]` by
//! simulated annealing and a Nelder–Mead polish (book §7.3–7.5), or with `--method gradient` by
//! SLSQP on the exact sensitivities ([`pdeshape::optimize::Problem::run_gradient`]; the options
//! checked and the search run by [`pdeshape::optimize::Problem::plan`] and `run_search`), then write
//! the optimised design file (the original text with the parameters applied), its mesh
//! (`BEST.obj`), its picture (`BEST.png`) and the log of the search (`BEST.csv`). With the shell measures (`mass`,
//! `max_shear`, `yield`) the progress line shows the best feasible design so far, and the report
//! the count of failed shell analyses (designs counted as infeasible).

use crate::common::{self, CliError, Output};
use pdeshape::design::WriteDesign as _;
use pdeshape::mesh;
use pdeshape::optimize::{Problem, SearchMethod, SearchPlan, SearchRequest, VARIABLES};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The search.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Method {
    /// Simulated annealing and a Nelder–Mead polish (the book's).
    Anneal,
    /// SLSQP with the exact sensitivities, bounds and constraints.
    Gradient,
    /// Annealing, then SLSQP from each chain's best point; the better result.
    Hybrid,
}

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML) with an [optimize] section.
    pub design: PathBuf,
    /// The optimised design file to write (.toml); the mesh (.obj), picture (.png) and search
    /// log (.csv) go beside it with the same stem.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Seed of the random numbers (default from [optimize], else 1).
    #[arg(long)]
    pub seed: Option<u64>,
    /// The search: simulated annealing (default), gradient (SLSQP on exact sensitivities) or
    /// hybrid (annealing, then SLSQP from each chain's best point).
    #[arg(long, value_enum, default_value_t = Method::Anneal)]
    pub method: Method,
    /// Annealing evaluations, all chains together (default from [optimize], else 2000; also
    /// with --method hybrid); with --method gradient, gradient evaluations per start (default
    /// 100).
    #[arg(long)]
    pub evaluations: Option<usize>,
    /// Independent annealing chains (default from [optimize], else 4).
    #[arg(long)]
    pub chains: Option<usize>,
    /// Nelder–Mead polish evaluations (default from [optimize], else 200).
    #[arg(long)]
    pub polish: Option<usize>,
    /// Starts of the gradient search (default 1: the initial values; the others drawn within
    /// the bounds from --seed).
    #[arg(long)]
    pub starts: Option<usize>,
    /// Print one JSON line on stderr: the search's wall time (ms), its evaluations, its
    /// design solves and its batched tangent solves (the gradient's exact parameters).
    #[arg(long)]
    pub timings: bool,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Grid rows of the mesh and picture (default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns of the mesh and picture (default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
}

/// `dir/stem.ext` for the companion files of `-o`.
fn beside(path: &Path, ext: &str) -> PathBuf {
    path.with_extension(ext)
}

fn csv_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else if x > 0.0 {
        "inf".to_string()
    } else if x < 0.0 {
        "-inf".to_string()
    } else {
        "nan".to_string()
    }
}

/// Prices the search before it starts ([`pdeshape::memory`]): the log of every evaluation
/// (named by `--evaluations`/`--polish` or `optimize.evaluations`), and the quadrature of the
/// evaluations running at once, one per worker (`optimize.quadrature_u × quadrature_v`).
fn search_memory(
    args: &Args,
    design: &common::Loaded,
    problem: &Problem,
    plan: &SearchPlan,
) -> Result<(), CliError> {
    use pdeshape::memory;
    let o = &problem.options;
    let records = plan.evaluations(problem) as u64;
    let parameters = problem.parameters.list.len() as u64;
    let what = format!(
        "the search log of {} + {} evaluations ({parameters} parameters)",
        o.evaluations, o.polish
    );
    if let Err(e) = memory::check(memory::search_log(records, parameters), &what, "") {
        let message = common::message_of(&e);
        return Err(if args.evaluations.is_some() || args.polish.is_some() {
            CliError::input(format!("--evaluations, --polish: {message}"))
        } else {
            design.error(&e.at("optimize.evaluations"))
        });
    }
    let Some(spec) = design.spec.optimize.as_ref() else {
        return Ok(());
    };
    let workers = args
        .threads
        .unwrap_or_else(rayon::current_num_threads)
        .min(o.chains.max(1)) as u64;
    let (qu, qv) = (spec.quadrature_u as u64, spec.quadrature_v as u64);
    let bytes = memory::quadrature_level(qu, qv, workers).and_then(|b| b.checked_mul(workers));
    memory::check(
        bytes,
        &format!("{workers} evaluations at once on a {qu} × {qv} quadrature"),
        "optimize.quadrature_u",
    )
    .map_err(|e| design.error(&e))
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    if args.output.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(CliError::input(format!(
            "-o {shown}: the optimised design file must end in .toml"
        )));
    }
    let design = common::load(&args.design)?;
    let mut problem = Problem::new(&design.spec).map_err(|e| design.error(&e))?;
    let (nu, nv) = design.grid(args.nu, args.nv)?;
    if args.threads == Some(0) {
        return Err(CliError::input("--threads: must be at least 1 (got 0)"));
    }
    let max_threads = pdeshape::spec::limits::MAX_THREADS;
    if let Some(n) = args.threads.filter(|&n| n > max_threads) {
        return Err(CliError::input(format!(
            "--threads: at most {max_threads} worker threads (got {n})"
        )));
    }
    // What each option means for each method, and which it refuses, is the library's.
    let request = SearchRequest {
        method: match args.method {
            Method::Anneal => SearchMethod::Anneal,
            Method::Gradient => SearchMethod::Gradient,
            Method::Hybrid => SearchMethod::Hybrid,
        },
        seed: args.seed,
        evaluations: args.evaluations,
        chains: args.chains,
        polish: args.polish,
        starts: args.starts,
    };
    let plan = problem.plan(&request).map_err(|e| {
        if e.place() == "optimize" {
            design.error(&e)
        } else {
            CliError::input(format!("--{}: {}", e.place(), common::message_of(&e)))
        }
    })?;
    search_memory(args, &design, &problem, &plan)?;
    let paths = [
        args.output.clone(),
        beside(&args.output, "obj"),
        beside(&args.output, "png"),
        beside(&args.output, "csv"),
    ];
    for p in &paths[1..] {
        if common::same_file(p, &args.design) {
            return Err(CliError::input(format!(
                "-o {shown}: would overwrite the design file {}",
                p.display()
            )));
        }
    }
    if common::same_file(&args.output, &args.design) {
        return Err(CliError::input(format!(
            "-o {shown}: would overwrite the design file"
        )));
    }
    let mut outs = paths
        .iter()
        .map(|p| Output::create(p))
        .collect::<Result<Vec<_>, _>>()?;

    let total = plan.evaluations(&problem) as u64;
    let bar = if common::quiet() {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(total)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} evaluations, {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let strength = problem.shell_setup().is_some();
    let report = |done: usize, best: f64| {
        bar.set_position(done as u64);
        if strength {
            let feasible = problem
                .best_feasible()
                .map_or("none yet".to_string(), |(f, _)| format!("{f:.6}"));
            bar.set_message(format!("best {best:.6}, best feasible {feasible}"));
        } else {
            bar.set_message(format!("best {best:.6}"));
        }
    };
    let clock = std::time::Instant::now();
    let search = || problem.run_search(&plan, &report);
    let outcome = match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| CliError::input(format!("--threads: {e}")))?
            .install(search),
        None => search(),
    };
    let seconds = clock.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let outcome = outcome.map_err(|e| match e {
        // A solver that is missing, fails or times out on the starting design.
        e if e.kind() == pdeshape::ErrorKind::Io => CliError {
            message: common::message_of(&e),
            status: 1,
        },
        e => design.error(&e),
    })?;
    let (best_x, best) = &outcome.best;

    // The optimised design file, then its mesh and picture from the re-read file (so what is
    // written is what `pdeshape surface` will build).
    let text = problem
        .parameters
        .apply_to_text(&design.text, &design.spec, best_x)
        .map_err(|e| design.error(&e))?;
    let reread = pdeshape::spec::parse_design(&text)
        .and_then(|s| pdeshape::design::solve_design(&s))
        .map_err(|e| CliError::input(format!("-o {shown}: the optimised design fails: {e}")))?;
    outs[0].write_all(text.as_bytes())?;
    let meshes = reread
        .meshes(nu, nv)
        .map_err(|e| CliError::input(e.to_string()))?;
    {
        let mut w = outs[1].writer();
        // As `pdeshape surface` writes it: welded, with the design's title, units and names.
        mesh::write_mesh(
            mesh::Format::Obj,
            &reread.weld(&meshes, &Default::default()),
            &reread.mesh_info(&Default::default()),
            &mut w,
        )
        .map_err(|e| CliError::input(format!("-o {}: {e}", paths[1].display())))?;
        w.flush()
            .map_err(|e| CliError::input(format!("-o {}: {e}", paths[1].display())))?;
    }
    let png = pdeshape::render::render_png(
        &meshes,
        &pdeshape::render::overlay_lines(&reread.overlays()),
        &pdeshape::render::RenderOptions::default(),
    )
    .map_err(|e| CliError::input(format!("-o {}: {e}", paths[2].display())))?;
    outs[2].write_all(&png)?;
    {
        let names: Vec<&str> = problem.parameters.names();
        let mut w = outs[3].writer();
        let io = |e: std::io::Error| CliError::input(format!("-o {}: {e}", paths[3].display()));
        writeln!(
            w,
            "phase,chain,level,temperature,value,accepted,best,{}",
            names.join(",")
        )
        .map_err(io)?;
        for r in &outcome.search.log {
            let xs: Vec<String> = r.x.iter().map(|x| csv_number(*x)).collect();
            writeln!(
                w,
                "{},{},{},{},{},{},{},{}",
                r.phase,
                r.chain,
                r.level,
                csv_number(r.temperature),
                csv_number(r.value),
                u8::from(r.accepted),
                csv_number(r.best),
                xs.join(",")
            )
            .map_err(io)?;
        }
        w.flush().map_err(io)?;
    }
    for o in outs {
        o.commit()?;
    }

    let mut report = String::new();
    let start_value = outcome
        .start
        .1
        .as_ref()
        .map_or("failed".to_string(), |e| format!("{:.9}", e.total()));
    report.push_str(&format!(
        "objective {}: start {start_value}, best {:.9} (penalty {:.3e}) after {} {}evaluations \
         ({} solves{})\n",
        problem.objective_text(),
        best.total(),
        best.penalty,
        outcome.search.evaluations,
        if plan.method == SearchMethod::Gradient {
            "gradient "
        } else {
            ""
        },
        outcome.solves,
        if outcome.tangent_solves > 0 {
            format!(", {} batched tangent solves", outcome.tangent_solves)
        } else {
            String::new()
        },
    ));
    report.push_str("parameter        initial          best\n");
    for (p, x) in problem.parameters.list.iter().zip(best_x) {
        report.push_str(&format!("{:<12} {:>12.6} {:>13.6}\n", p.name, p.initial, x));
    }
    // The shell measures are NaN unless the formulas use them.
    let vars: Vec<String> = VARIABLES
        .iter()
        .zip(best.variables)
        .enumerate()
        .filter(|(i, (_, v))| *i < 11 || !v.is_nan())
        .map(|(_, (n, v))| format!("{n} = {v:.9}"))
        .collect();
    report.push_str(&format!("{}\n", vars.join(", ")));
    if let Some(g) = &outcome.gradient {
        let k = &g.kkt;
        let s = &g.starts[g.best_start];
        report.push_str(&format!(
            "gradient search: {} start(s), {} converged; the result from start {} ({}); \
             first-order conditions (scaled): stationarity {:.3e}, dual {:.3e}, primal {:.3e} \
             ({} active constraints, {} parameters at a bound)\n",
            g.starts.len(),
            g.starts.iter().filter(|s| s.converged).count(),
            g.best_start,
            s.status,
            k.stationarity,
            k.dual_infeasibility,
            k.primal_infeasibility,
            k.active_constraints,
            k.active_bounds,
        ));
    }
    if strength {
        // The start's and the result's shell measures (the first line's values include the
        // penalties).
        let measures = |e: &pdeshape::optimize::Evaluation| -> String {
            VARIABLES[11..]
                .iter()
                .zip(&e.variables[11..])
                .filter(|(_, v)| !v.is_nan())
                .map(|(n, v)| format!("{n} = {v:.9}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if let Some(e) = &outcome.start.1 {
            report.push_str(&format!(
                "start: objective {:.9}, {}\n",
                e.objective,
                measures(e)
            ));
        }
        report.push_str(&format!(
            "result: objective {:.9}, {}\n",
            best.objective,
            measures(best)
        ));
        report.push_str(&format!(
            "the result is {}feasible; {} failed shell analyses (counted as infeasible){}\n",
            if best.feasible { "" } else { "NOT " },
            outcome.solver_failures,
            outcome
                .first_failure
                .as_ref()
                .map(|m| format!(", the first: {m}"))
                .unwrap_or_default()
        ));
    }
    let dest = crate::common::destination(&args.output);
    report.push_str(&format!(
        "wrote {dest}, {}, {}, {}\n",
        paths[1].display(),
        paths[2].display(),
        paths[3].display()
    ));
    common::report(&report);
    if args.timings {
        // Not part of the report, which does not depend on the machine.
        eprintln!(
            "{}",
            serde_json::json!({
                "search_ms": seconds * 1e3,
                "evaluations": outcome.search.evaluations,
                "solves": outcome.solves,
                "tangent_solves": outcome.tangent_solves,
            })
        );
    }
    Ok(())
}
