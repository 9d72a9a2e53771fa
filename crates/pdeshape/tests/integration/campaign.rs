//! The mutation campaign: a deterministic, seeded mutator over every example design × every
//! subcommand's library pipeline, run in-process. It fails on any panic, any mutant that runs
//! past [`BOUND`], and any unclear message (empty, Rust type names, an over-long line, a
//! temporary path). Every input that ever failed is kept in `tests/regressions/` and replayed.
//!
//! `PDESHAPE_CAMPAIGN_MUTANTS` (default 4 per example and subcommand) and
//! `PDESHAPE_CAMPAIGN_SEED` (default 23) choose the size and the seed; the figures are printed
//! per subcommand (RELIABILITY.md).

use pdeshape::design::{self, DynamicPlan};
use pdeshape::spec;
use pdeshape_testkit::mutate::{mutate, unclear};
use pdeshape_testkit::{example_designs, repo_root};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant};

/// No mutant may take longer than this (in-process, all pipelines, on a loaded 2-core machine).
const BOUND: Duration = Duration::from_secs(60);
/// Worker threads of the campaign (the machine's two cores).
const WORKERS: usize = 2;
/// Partial figures are printed every this many mutants.
const PROGRESS: usize = 1000;

const SUBCOMMANDS: &[&str] = &[
    "check", "surface", "render", "analyze", "curve", "spline", "blend", "optimize",
];

/// What a subcommand does with a design, through the library.
fn pipeline(sub: &str, text: &str) -> Result<(), pdeshape::Error> {
    let spec = spec::parse_design(text)?;
    match sub {
        "check" => {
            design::solve_design(&spec)?;
        }
        "surface" | "render" => {
            let (nu, nv) = design::grid(&spec, Some(16), Some(24))?;
            let solved = design::solve_design(&spec)?;
            let meshes = solved.meshes(nu, nv)?;
            if sub == "surface" {
                let mut buf = Vec::new();
                pdeshape::mesh::write(pdeshape::mesh::Format::Obj, &meshes, &mut buf)?;
            } else {
                let options = pdeshape::render::RenderOptions {
                    width: 64,
                    height: 48,
                    ..Default::default()
                };
                pdeshape::render::render_png(
                    &meshes,
                    &pdeshape::render::overlay_lines(&solved.overlays()),
                    &options,
                )?;
            }
        }
        "analyze" => {
            let solved = design::solve_design(&spec)?;
            pdeshape::analysis::integrate_design(&solved, &Default::default())?;
        }
        "curve" => {
            if let Some(d) = &spec.dynamic {
                let built = design::build_dynamic(d)?;
                if let DynamicPlan::Run(r) = &built.plan {
                    r.curve.solve_observed(
                        r.grid,
                        r.positivity,
                        built.frames_every,
                        &mut |_, _, _| {},
                    )?;
                }
            }
        }
        "spline" => {
            if let Some(s) = &spec.spline {
                design::solve_spec(s)?;
            }
        }
        "blend" => {
            if spec.blend.is_some() {
                design::solve_design(&spec)?;
            }
        }
        "optimize" => {
            if spec.optimize.is_some() {
                let mut p = pdeshape::optimize::Problem::new(&spec)?;
                // The campaign bounds the search itself; the limits are tested in `spec::limits`.
                p.options.evaluations = p.options.evaluations.min(24).max(p.options.chains.min(4));
                p.options.chains = p.options.chains.min(4);
                p.options.polish = p.options.polish.min(8);
                p.run(&|_, _| {})?;
            }
        }
        _ => unreachable!(),
    }
    Ok(())
}

#[derive(Default)]
struct Tally {
    mutants: usize,
    ok: usize,
    clean_errors: usize,
    panics: usize,
    over_time: usize,
    unclear: usize,
}

/// What became of one mutant.
enum Outcome {
    Ok,
    CleanError,
    Panic,
    OverTime,
    Unclear(String),
}

/// Runs one input through one pipeline on a thread with a deadline.
fn outcome(sub: &'static str, text: String) -> Outcome {
    let (tx, rx) = mpsc::channel();
    let t2 = text.clone();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| pipeline(sub, &t2));
        let _ = tx.send(r);
    });
    match rx.recv_timeout(BOUND) {
        Err(_) => Outcome::OverTime,
        Ok(Err(_)) => Outcome::Panic,
        Ok(Ok(Ok(()))) => Outcome::Ok,
        Ok(Ok(Err(e))) => {
            let line = spec::describe_error("m.toml", &text, &e);
            match unclear(&line) {
                Some(why) => Outcome::Unclear(format!("{why} message: {}", truncate(&line))),
                None => Outcome::CleanError,
            }
        }
    }
}

/// [`outcome`] as `Ok(success)` or `Err(what went wrong)`.
fn run_one(sub: &'static str, text: String) -> Result<bool, String> {
    match outcome(sub, text) {
        Outcome::Ok => Ok(true),
        Outcome::CleanError => Ok(false),
        Outcome::Panic => Err("panic".to_string()),
        Outcome::OverTime => Err(format!("ran past {BOUND:?}")),
        Outcome::Unclear(m) => Err(m),
    }
}

fn truncate(s: &str) -> String {
    s.chars().take(300).collect()
}

#[test]
fn mutation_campaign() {
    let per: usize = std::env::var("PDESHAPE_CAMPAIGN_MUTANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4);
    let seed: u64 = std::env::var("PDESHAPE_CAMPAIGN_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(23);
    std::panic::set_hook(Box::new(|_| {}));
    let examples = example_designs();
    // Every (subcommand, example, mutant): each example's mutants from its own stream, taken in
    // rounds (mutant k of every example and subcommand, then k + 1) so that partial figures
    // cover them all.
    let mutants: Vec<Vec<String>> = examples
        .iter()
        .enumerate()
        .map(|(e, (_, text))| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ ((e as u64) << 32));
            (0..per).map(|_| mutate(text, &mut rng)).collect()
        })
        .collect();
    let mut jobs: Vec<(&'static str, String, String)> = Vec::new();
    // In rounds (mutant k of every example before mutant k + 1), so partial figures cover every
    // example.
    #[allow(clippy::needless_range_loop)]
    for k in 0..per {
        for (e, (name, _)) in examples.iter().enumerate() {
            for &sub in SUBCOMMANDS {
                jobs.push((sub, name.clone(), mutants[e][k].clone()));
            }
        }
    }
    let next = AtomicUsize::new(0);
    let tally: Mutex<BTreeMap<&str, Tally>> = Mutex::new(BTreeMap::new());
    let failures: Mutex<Vec<(&str, String, String, String)>> = Mutex::new(Vec::new());
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..WORKERS {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some((sub, name, text)) = jobs.get(i) else {
                    break;
                };
                let o = outcome(sub, text.clone());
                let mut tally = tally.lock().unwrap();
                let done = tally.values().map(|t| t.mutants).sum::<usize>() + 1;
                if done % PROGRESS == 0 {
                    // Partial figures of a long run, in case it is stopped.
                    let line: Vec<String> = tally
                        .iter()
                        .map(|(s, t)| {
                            format!(
                                "{s} {}/{}/{}/{}/{}/{}",
                                t.mutants, t.ok, t.clean_errors, t.panics, t.over_time, t.unclear
                            )
                        })
                        .collect();
                    println!(
                        "progress {done}/{} after {:.0} s (mutants/successes/clean/panics/past/unclear): {}",
                        jobs.len(),
                        start.elapsed().as_secs_f64(),
                        line.join(", ")
                    );
                }
                let t = tally.entry(sub).or_default();
                t.mutants += 1;
                let why = match o {
                    Outcome::Ok => {
                        t.ok += 1;
                        continue;
                    }
                    Outcome::CleanError => {
                        t.clean_errors += 1;
                        continue;
                    }
                    Outcome::Panic => {
                        t.panics += 1;
                        "panic".to_string()
                    }
                    Outcome::OverTime => {
                        t.over_time += 1;
                        format!("ran past {BOUND:?}")
                    }
                    Outcome::Unclear(m) => {
                        t.unclear += 1;
                        m
                    }
                };
                drop(tally);
                failures
                    .lock()
                    .unwrap()
                    .push((sub, name.clone(), why, text.clone()));
            });
        }
    });
    let _ = std::panic::take_hook();
    let tally = tally.into_inner().unwrap();
    let failures = failures.into_inner().unwrap();
    println!(
        "seed {seed}, {per} mutants per example and subcommand, {} examples, {WORKERS} workers, {:.1} s",
        examples.len(),
        start.elapsed().as_secs_f64()
    );
    println!(
        "| subcommand | mutants | successes | clean errors | panics | past {}s | unclear |\n|---|---|---|---|---|---|---|",
        BOUND.as_secs()
    );
    let mut total = Tally::default();
    for (sub, t) in &tally {
        println!(
            "| {sub} | {} | {} | {} | {} | {} | {} |",
            t.mutants, t.ok, t.clean_errors, t.panics, t.over_time, t.unclear
        );
        total.mutants += t.mutants;
        total.ok += t.ok;
        total.clean_errors += t.clean_errors;
        total.panics += t.panics;
        total.over_time += t.over_time;
        total.unclear += t.unclear;
    }
    println!(
        "| all | {} | {} | {} | {} | {} | {} |",
        total.mutants, total.ok, total.clean_errors, total.panics, total.over_time, total.unclear
    );
    assert_eq!(total.mutants, jobs.len());
    // Keep every failing input for the regression corpus (written only when the campaign fails).
    if !failures.is_empty() {
        let dir = std::env::temp_dir().join("pdeshape-campaign-failures");
        let _ = std::fs::create_dir_all(&dir);
        for (i, (sub, name, _, text)) in failures.iter().enumerate() {
            let _ = std::fs::write(dir.join(format!("{i:04}-{sub}-{name}")), text);
        }
    }
    let shown: Vec<String> = failures
        .iter()
        .take(20)
        .map(|(sub, name, why, _)| format!("{sub} {name}: {why}"))
        .collect();
    assert!(
        failures.is_empty(),
        "{} failing mutants (inputs in {}):\n{}",
        failures.len(),
        std::env::temp_dir()
            .join("pdeshape-campaign-failures")
            .display(),
        shown.join("\n")
    );
}

/// Every input that ever failed the campaign, replayed through every pipeline.
#[test]
fn regression_corpus() {
    let dir = repo_root().join("crates/pdeshape/tests/regressions");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let text = String::from_utf8_lossy(&std::fs::read(&p).unwrap()).to_string();
        for &sub in SUBCOMMANDS {
            if let Err(why) = run_one(sub, text.clone()) {
                panic!("{}: {sub}: {why}", p.display());
            }
        }
        n += 1;
    }
    assert!(n > 0, "the corpus is empty");
}
