//! The mutation campaign through the real binary, one child process per mutant.
//!
//! Every example design (and three meshes for `fit`) is mutated by the seeded mutator of
//! `pdeshape_testkit::mutate` and run through every subcommand that reads it: check, analyze,
//! surface, render, curve, spline, blend, optimize, animate, cad (surface to STEP or IGES),
//! fit, and shell (mutants of the designs with a `[shell]` section). Each mutant is written to its own directory *before* it runs, and the binary runs in that
//! directory under an address-space limit ([`ADDRESS_SPACE_KIB`]) and a CPU-time limit
//! ([`CPU_SECONDS`], `RLIMIT_CPU`: the bound that does not depend on the machine's load), with
//! `PDESHAPE_MAX_MEMORY` = [`BUDGET_BYTES`]. A mutant fails on
//! - a panic (status 1, `internal error`), a crash or an abort by the allocator (a signal),
//! - the CPU bound (SIGXCPU/SIGKILL from the limit) or the wall-clock safety net ([`WALL`]),
//! - a status other than 0 or 2, an error that is not one clear line (`mutate::unclear`),
//! - an output file after an error, or any `.pdeshape-*` temporary left behind.
//!
//! A quarter of the runs also meet an edge of the operating system (`mutate::Edge`, from a
//! stream of its own): the first output an existing FIFO, directory or loop of symbolic links
//! (the run must refuse it and leave it as it was), the second output a link to the first
//! (refused), the input a FIFO without a writer (refused, not waited on), or SIGTERM during the
//! run (the run ends with every output or none, and no temporary). `roundtrip` reads mutants of
//! the STEP and IGES files of `examples/cup.toml` (counts that size allocations: knot
//! multiplicities, control point counts, degrees). The figures are printed per subcommand and
//! per edge.
//!
//! `shell` runs against a stand-in for CalculiX ([`fake_ccx`], named by `PDESHAPE_CCX`) that
//! always fails, so the campaign does not depend on whether CalculiX is installed: mutants the
//! input checks refuse exit with status 2, those that reach the solver must exit with status 1
//! and one clear line, and leave neither an output nor the solver's temporary directory
//! (`TMPDIR` is the mutant's own directory).
//!
//! A mutant that passes has its directory removed; one that fails keeps it (with `why.txt`), so
//! every failure, and the mutants running when the campaign itself is stopped, can be rerun by
//! hand. `PDESHAPE_CAMPAIGN_MUTANTS` (mutants per example and subcommand, default 1),
//! `PDESHAPE_CAMPAIGN_SEED` (default 23), `PDESHAPE_CAMPAIGN_WORKERS` (default 2) and
//! `PDESHAPE_CAMPAIGN_DIR` (default: a temporary directory) and `PDESHAPE_CAMPAIGN_BINARY` (default:
//! the binary cargo built) choose the run; the figures are
//! printed per subcommand (RELIABILITY.md).

use crate::common;
use pdeshape_testkit::mutate;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// CPU time (user + system, all threads) a mutant may use: 30 s.
const CPU_SECONDS: u64 = 30;
/// Address space of a mutant's process: 3 GiB (`ulimit -v`). With the budget below, a request
/// the memory estimates miss by more than 2 GiB makes the allocator abort, which fails here.
const ADDRESS_SPACE_KIB: u64 = 3 << 20;
/// The memory budget of one request inside the campaign (`PDESHAPE_MAX_MEMORY`): 1 GiB.
const BUDGET_BYTES: u64 = 1 << 30;
/// Wall-clock safety net (not the bound: at `nice -n 19` on a loaded machine a run of one CPU
/// second can take minutes of wall clock).
const WALL: Duration = Duration::from_secs(3600);
/// A process whose CPU time does not grow for this long is blocked or asleep: it fails.
const STALL: Duration = Duration::from_secs(120);
/// Partial figures are printed every this many mutants.
const PROGRESS: usize = 500;

/// The subcommands, the extension of their input and their arguments after the input.
const RUNS: &[(&str, &str, &[&str])] = &[
    ("check", "toml", &["check"]),
    ("analyze", "toml", &["analyze"]),
    (
        "surface",
        "toml",
        &["surface", "-o", "out.obj", "--nu", "16", "--nv", "24"],
    ),
    (
        "render",
        "toml",
        &[
            "render", "-o", "out.png", "--size", "64x48", "--nu", "16", "--nv", "24",
        ],
    ),
    ("curve", "toml", &["curve", "-o", "out.csv"]),
    ("spline", "toml", &["spline", "-o", "out.json"]),
    (
        "blend",
        "toml",
        &["blend", "-o", "out.obj", "--nu", "16", "--nv", "24"],
    ),
    (
        "optimize",
        "toml",
        &[
            "optimize",
            "-o",
            "out.toml",
            "--evaluations",
            "24",
            "--chains",
            "4",
            "--polish",
            "8",
            "--nu",
            "12",
            "--nv",
            "16",
        ],
    ),
    (
        "animate",
        "toml",
        &[
            "animate", "-o", "out.glb", "--csv", "out.csv", "--nu", "12", "--nv", "16",
        ],
    ),
    ("cad", "toml", &["surface", "-o", "out.stp"]),
    ("cad", "toml", &["surface", "-o", "out.igs"]),
];

/// The arguments of `shell` mutants after the input (in turns).
const SHELL_RUNS: &[&[&str]] = &[&["shell"], &["shell", "--json", "-o", "out.vtu"]];

/// Writes the stand-in solver into `dir`: a script that prints a CalculiX-like `*ERROR` line and
/// exits with status 1, whatever its input.
fn fake_ccx(dir: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-ccx");
    std::fs::write(
        &path,
        "#!/bin/sh\necho ' *ERROR in fake-ccx: the campaign runs no solver'\nexit 1\n",
    )
    .unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// One mutant run: what it is and how it is run.
struct Job {
    index: usize,
    sub: &'static str,
    example: String,
    ext: String,
    args: &'static [&'static str],
    text: Vec<u8>,
    /// The edge of the operating system the run meets (special files, aliasing outputs, a
    /// signal between outputs).
    edge: mutate::Edge,
    /// Other files the run reads, unmutated (the design of a `roundtrip`).
    extra: Vec<(String, Vec<u8>)>,
}

/// What became of one mutant.
#[derive(Debug, PartialEq)]
enum Outcome {
    Ok,
    CleanError,
    Panic,
    OverBound,
    Leftover,
    Unclear,
    Crash,
}

#[derive(Default)]
struct Tally {
    mutants: usize,
    ok: usize,
    clean: usize,
    panics: usize,
    over: usize,
    leftovers: usize,
    unclear: usize,
    crashes: usize,
}

impl Tally {
    fn add(&mut self, o: &Outcome) {
        self.mutants += 1;
        match o {
            Outcome::Ok => self.ok += 1,
            Outcome::CleanError => self.clean += 1,
            Outcome::Panic => self.panics += 1,
            Outcome::OverBound => self.over += 1,
            Outcome::Leftover => self.leftovers += 1,
            Outcome::Unclear => self.unclear += 1,
            Outcome::Crash => self.crashes += 1,
        }
    }
    /// The sum of several tallies (the "all" row).
    fn total<'a>(tallies: impl IntoIterator<Item = &'a Tally>) -> Tally {
        let mut all = Tally::default();
        for x in tallies {
            all.mutants += x.mutants;
            all.ok += x.ok;
            all.clean += x.clean;
            all.panics += x.panics;
            all.over += x.over;
            all.leftovers += x.leftovers;
            all.unclear += x.unclear;
            all.crashes += x.crashes;
        }
        all
    }

    fn row(&self, name: &str) -> String {
        format!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} |",
            self.mutants,
            self.ok,
            self.clean,
            self.panics,
            self.over,
            self.leftovers,
            self.unclear,
            self.crashes
        )
    }
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

/// Every example design: `examples/`, `examples/spline/` and `examples/anim/`.
fn designs() -> Vec<(String, String)> {
    let mut out = pdeshape_testkit::example_designs();
    out.extend(pdeshape_testkit::designs_in("examples/anim", "anim-"));
    out
}

/// A closed ellipsoid of revolution (semi-axes 1, 1, 1.5): `rings` latitude rings of `around`
/// vertices and two poles, as positions and triangles.
fn ellipsoid(rings: usize, around: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut p = vec![[0.0, 0.0, -1.5]];
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..around {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / around as f64;
            p.push([t.sin() * phi.cos(), t.sin() * phi.sin(), -1.5 * t.cos()]);
        }
    }
    p.push([0.0, 0.0, 1.5]);
    let top = p.len() - 1;
    let at = |i: usize, j: usize| 1 + (i - 1) * around + j % around;
    let mut t = Vec::new();
    for j in 0..around {
        t.push([0, at(1, j + 1), at(1, j)]);
        t.push([top, at(rings - 1, j), at(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..around {
            t.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    (p, t)
}

/// The ellipsoid as OBJ, ASCII PLY and ASCII STL texts: the inputs `fit` mutants start from.
fn meshes() -> Vec<(String, String)> {
    let (p, t) = ellipsoid(16, 20);
    let mut obj = String::from("# ellipsoid\n");
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        p.len(),
        t.len()
    );
    let mut stl = String::from("solid ellipsoid\n");
    for v in &p {
        obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        ply += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    for f in &t {
        obj += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
        ply += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
        stl += "facet normal 0 0 0\nouter loop\n";
        for &k in f {
            stl += &format!("vertex {} {} {}\n", p[k][0], p[k][1], p[k][2]);
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid ellipsoid\n";
    vec![
        ("ellipsoid.obj".into(), obj),
        ("ellipsoid.ply".into(), ply),
        ("ellipsoid.stl".into(), stl),
    ]
}

/// Every job of a campaign of `per` mutants per example and subcommand, in rounds (mutant k of
/// every example and subcommand before mutant k + 1) so that partial figures cover them all.
fn jobs(per: usize, seed: u64, cad: &[(String, String, Vec<u8>)]) -> Vec<Job> {
    let designs = designs();
    let meshes = meshes();
    // The edges come from a stream of their own, so the mutants are those of the same seed
    // without them.
    let mut edges = ChaCha8Rng::seed_from_u64(seed ^ 0xed_9e00);
    let mut cad_streams: Vec<ChaCha8Rng> = (0..cad.len())
        .map(|e| ChaCha8Rng::seed_from_u64(seed ^ 0xcad_000 ^ ((e as u64) << 32)))
        .collect();
    let mut streams: Vec<ChaCha8Rng> = (0..designs.len())
        .map(|e| ChaCha8Rng::seed_from_u64(seed ^ 0xc4_0000 ^ ((e as u64) << 32)))
        .collect();
    let mut mesh_streams: Vec<ChaCha8Rng> = (0..meshes.len())
        .map(|e| ChaCha8Rng::seed_from_u64(seed ^ 0xf1_7000 ^ ((e as u64) << 32)))
        .collect();
    // `fit` gets as many mutants per round as a design subcommand has; so does `shell`, over
    // the designs with a `[shell]` section.
    let fit_per_mesh = designs.len().div_ceil(meshes.len());
    let shelled: Vec<&(String, String)> = designs
        .iter()
        .filter(|(_, t)| t.lines().any(|l| l.trim() == "[shell]"))
        .collect();
    let shell_per_design = designs.len().div_ceil(shelled.len().max(1));
    let mut shell_streams: Vec<ChaCha8Rng> = (0..shelled.len())
        .map(|e| ChaCha8Rng::seed_from_u64(seed ^ 0x5e_1100 ^ ((e as u64) << 32)))
        .collect();
    let mut out = Vec::new();
    for k in 0..per {
        for (e, (name, text)) in designs.iter().enumerate() {
            let m = mutate::mutate(text, &mut streams[e]);
            for (r, &(sub, ext, args)) in RUNS.iter().enumerate() {
                // The two `cad` rows take turns.
                if sub == "cad" && (k + e + r) % 2 == 0 {
                    continue;
                }
                out.push(Job {
                    index: out.len(),
                    sub,
                    example: name.clone(),
                    ext: ext.to_string(),
                    args,
                    text: m.clone().into_bytes(),
                    edge: mutate::edge(&mut edges),
                    extra: Vec::new(),
                });
            }
        }
        for (e, (name, text)) in meshes.iter().enumerate() {
            for _ in 0..fit_per_mesh {
                let m = mutate::mutate(text, &mut mesh_streams[e]);
                out.push(Job {
                    index: out.len(),
                    sub: "fit",
                    example: name.clone(),
                    ext: name.rsplit('.').next().unwrap().to_string(),
                    args: &["fit", "-o", "out.toml"],
                    text: m.into_bytes(),
                    edge: mutate::edge(&mut edges),
                    extra: Vec::new(),
                });
            }
        }
        for (e, (name, text)) in shelled.iter().enumerate() {
            for i in 0..shell_per_design {
                let m = mutate::mutate(text, &mut shell_streams[e]);
                out.push(Job {
                    index: out.len(),
                    sub: "shell",
                    example: name.clone(),
                    ext: "toml".into(),
                    args: SHELL_RUNS[(k + i) % SHELL_RUNS.len()],
                    text: m.into_bytes(),
                    edge: mutate::edge(&mut edges),
                    extra: Vec::new(),
                });
            }
        }
        // STEP and IGES files read back by `roundtrip`, mutated (counts that size allocations:
        // knot multiplicities, control point counts, degrees), beside their unmutated design.
        // As many per round as a design subcommand has.
        let per_cad = designs.len().div_ceil(cad.len().max(1));
        for (e, (name, design, bytes)) in cad.iter().enumerate() {
            for _ in 0..per_cad {
                let text = String::from_utf8_lossy(bytes);
                let m = mutate::mutate(&text, &mut cad_streams[e]);
                out.push(Job {
                    index: out.len(),
                    sub: "roundtrip",
                    example: name.clone(),
                    ext: name.rsplit('.').next().unwrap().to_string(),
                    args: &["roundtrip", "design.toml"],
                    text: m.into_bytes(),
                    edge: mutate::Edge::Plain,
                    extra: vec![("design.toml".into(), design.clone().into_bytes())],
                });
            }
        }
    }
    out
}

/// The binary under test: `PDESHAPE_CAMPAIGN_BINARY` (a copy, so that a long run is not changed
/// by a rebuild) or the one cargo built.
fn binary() -> String {
    std::env::var("PDESHAPE_CAMPAIGN_BINARY")
        .unwrap_or_else(|_| env!("CARGO_BIN_EXE_pdeshape").to_string())
}

/// Runs the binary on `args` in `dir` under the campaign's limits, with `dir` as `TMPDIR` and
/// `ccx` (if given) as the solver; `None` past [`WALL`].
fn run_limited(
    dir: &Path,
    args: &[String],
    ccx: Option<&Path>,
    signal_after: Option<Duration>,
) -> Option<std::process::Output> {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && ulimit -t {CPU_SECONDS} && exec \"$0\" \"$@\""
        ))
        .arg(binary())
        .args(args)
        .current_dir(dir)
        .env("PDESHAPE_MAX_MEMORY", BUDGET_BYTES.to_string())
        .env("TMPDIR", dir)
        .envs(ccx.map(|c| ("PDESHAPE_CCX", c)))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Drain the pipes on threads so a chatty child cannot block on a full pipe.
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let ho = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = std::io::Read::read_to_end(&mut so, &mut b);
        b
    });
    let he = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = std::io::Read::read_to_end(&mut se, &mut b);
        b
    });
    // The bound is the CPU limit; the wall clock only catches a process that stops using CPU
    // (blocked or asleep) for [`STALL`], or runs past [`WALL`] whatever the load.
    let start = Instant::now();
    let mut last = (Instant::now(), cpu_seconds(child.id()).unwrap_or(0.0));
    let mut looked = Instant::now();
    let mut signal_after = signal_after;
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break Some(st);
        }
        if signal_after.is_some_and(|d| start.elapsed() >= d) {
            signal_after = None;
            let _ = Command::new("kill")
                .args(["-TERM", &child.id().to_string()])
                .status();
        }
        let now = Instant::now();
        if now - looked > Duration::from_secs(1) {
            looked = now;
            if let Some(c) = cpu_seconds(child.id()).filter(|&c| c > last.1) {
                last = (now, c);
            }
        }
        if start.elapsed() > WALL || now - last.0 > STALL {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stdout = ho.join().unwrap();
    let stderr = he.join().unwrap();
    status.map(|status| std::process::Output {
        status,
        stdout,
        stderr,
    })
}

/// Runs one job in `dir` (which holds only its input) and judges it; `ccx` is the solver of
/// `shell` jobs.
fn judge(job: &Job, dir: &Path, input: &str, ccx: Option<&Path>) -> (Outcome, String) {
    let mut args: Vec<String> = vec![job.args[0].to_string()];
    if job.sub == "roundtrip" {
        // `roundtrip DESIGN FILE`: the mutated file is the second.
        args.extend(job.args[1..].iter().map(|a| a.to_string()));
        args.push(input.to_string());
    } else {
        args.push(input.to_string());
        args.extend(job.args[1..].iter().map(|a| a.to_string()));
    }
    let (edge, made) = make_edge(job, dir, input);
    let signal_after = match edge {
        mutate::Edge::Signal(ms) => Some(Duration::from_millis(ms)),
        _ => None,
    };
    let Some(out) = run_limited(dir, &args, ccx, signal_after) else {
        return (
            Outcome::OverBound,
            format!("no CPU used for {STALL:?}, or still running after {WALL:?}"),
        );
    };
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let left: Vec<String> = common::files(dir)
        .into_iter()
        .filter(|f| f != input && !job.extra.iter().any(|(n, _)| n == f))
        .filter(|f| !made.iter().any(|(n, _)| n == f))
        .collect();
    // A special file or link made as an output is left exactly as it was.
    for (name, before) in &made {
        let now = file_type(&dir.join(name));
        if now != *before {
            return (
                Outcome::Leftover,
                format!("{edge:?}: {name} was {before}, is {now} after the run"),
            );
        }
    }
    let temporaries: Vec<&String> = left
        .iter()
        .filter(|f| f.contains(".pdeshape-") || f.starts_with("pdeshape-ccx-"))
        .collect();
    if let mutate::Edge::Signal(_) = edge {
        let temporaries = !temporaries.is_empty();
        return match (out.status.code(), out.status.signal()) {
            _ if temporaries => (Outcome::Leftover, format!("left {left:?} after SIGTERM")),
            // Stopped before its handler was installed, or by it: nothing may be left, unless
            // the outputs were already all in place (and the message says so).
            (None, Some(15)) | (Some(130), _)
                if !left.is_empty() && !stderr.contains("after the outputs were written") =>
            {
                (
                    Outcome::Leftover,
                    format!("left {left:?} after SIGTERM: {}", first(&stderr)),
                )
            }
            (None, Some(15)) | (Some(130), _) => (Outcome::CleanError, String::new()),
            // Ended before the signal: judged as any run.
            _ => judge_status(job, &out, &stderr, &left, &temporaries_of(&left)),
        };
    }
    if matches!(
        edge,
        mutate::Edge::OutputFifo
            | mutate::Edge::OutputDirectory
            | mutate::Edge::OutputLoop
            | mutate::Edge::OutputsAlias
    ) && out.status.success()
    {
        return (
            Outcome::Leftover,
            format!("{edge:?}: the run succeeded instead of refusing the output"),
        );
    }
    judge_status(job, &out, &stderr, &left, &temporaries)
}

/// The temporaries among the files `left`.
fn temporaries_of(left: &[String]) -> Vec<&String> {
    left.iter()
        .filter(|f| f.contains(".pdeshape-") || f.starts_with("pdeshape-ccx-"))
        .collect()
}

/// What a file is now (its type, or that it does not exist), to compare before and after.
fn file_type(p: &Path) -> String {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.file_type().is_symlink() => {
            format!("a link to {:?}", std::fs::read_link(p).ok())
        }
        Ok(m) => format!("{:?}", m.file_type()),
        Err(_) => "missing".into(),
    }
}

/// The outputs a job's arguments name (`out.*`).
fn outputs(job: &Job) -> Vec<&'static str> {
    job.args
        .iter()
        .copied()
        .filter(|a| a.starts_with("out."))
        .collect()
}

/// Makes the job's edge in `dir` (a FIFO, a directory, a loop of links at the first output; a
/// link from the second output to the first; a FIFO as the input) and returns the edge that
/// applies (plain when the job has no such output) with the names made and what they are.
fn make_edge(job: &Job, dir: &Path, input: &str) -> (mutate::Edge, Vec<(String, String)>) {
    use mutate::Edge;
    let outs = outputs(job);
    let mkfifo = |p: &Path| {
        let _ = std::fs::remove_file(p);
        Command::new("mkfifo")
            .arg(p)
            .status()
            .is_ok_and(|s| s.success())
    };
    let edge = match job.edge {
        Edge::OutputFifo | Edge::OutputDirectory | Edge::OutputLoop if outs.is_empty() => {
            Edge::Plain
        }
        Edge::OutputsAlias if outs.len() < 2 => Edge::Plain,
        e => e,
    };
    let mut made = Vec::new();
    match edge {
        Edge::OutputFifo => {
            if mkfifo(&dir.join(outs[0])) {
                made.push(outs[0].to_string());
            }
        }
        Edge::OutputDirectory => {
            std::fs::create_dir(dir.join(outs[0])).unwrap();
            made.push(outs[0].to_string());
        }
        Edge::OutputLoop => {
            let other = format!("{}.loop", outs[0]);
            std::os::unix::fs::symlink(&other, dir.join(outs[0])).unwrap();
            std::os::unix::fs::symlink(outs[0], dir.join(&other)).unwrap();
            made.push(outs[0].to_string());
            made.push(other);
        }
        Edge::OutputsAlias => {
            std::os::unix::fs::symlink(outs[0], dir.join(outs[1])).unwrap();
            made.push(outs[1].to_string());
        }
        Edge::InputFifo => {
            if mkfifo(&dir.join(input)) {
                made.push(input.to_string());
            }
        }
        Edge::Plain | Edge::Signal(_) => {}
    }
    let made = made
        .into_iter()
        .map(|n| {
            let t = file_type(&dir.join(&n));
            (n, t)
        })
        .collect();
    (edge, made)
}

/// The edge a job meets: its own, or plain when it has no output of the kind the edge needs.
fn effective_edge(job: &Job) -> mutate::Edge {
    use mutate::Edge;
    let outs = outputs(job);
    match job.edge {
        Edge::OutputFifo | Edge::OutputDirectory | Edge::OutputLoop if outs.is_empty() => {
            Edge::Plain
        }
        Edge::OutputsAlias if outs.len() < 2 => Edge::Plain,
        e => e,
    }
}

/// The row of an edge in the campaign's second table.
fn edge_row(edge: mutate::Edge) -> &'static str {
    use mutate::Edge;
    match edge {
        Edge::Plain => "plain files",
        Edge::OutputFifo => "output is a FIFO",
        Edge::OutputDirectory => "output is a directory",
        Edge::OutputLoop => "output is a symlink loop",
        Edge::OutputsAlias => "two outputs alias",
        Edge::InputFifo => "input is a FIFO",
        Edge::Signal(_) => "SIGTERM during the run",
    }
}

/// Judges a run by its status, message and what it left (the rules of every mutant).
fn judge_status(
    job: &Job,
    out: &std::process::Output,
    stderr: &str,
    left: &[String],
    temporaries: &[&String],
) -> (Outcome, String) {
    let stderr = stderr.to_string();
    if let Some(sig) = out.status.signal() {
        // SIGXCPU (24) at the soft CPU limit, SIGKILL (9) at the hard one.
        return if sig == 24 || sig == 9 {
            (
                Outcome::OverBound,
                format!("past {CPU_SECONDS} s of CPU (signal {sig})"),
            )
        } else {
            (
                Outcome::Crash,
                format!("killed by signal {sig}: {}", first(&stderr)),
            )
        };
    }
    match out.status.code() {
        Some(0) => {
            if temporaries.is_empty() {
                (Outcome::Ok, String::new())
            } else {
                (Outcome::Leftover, format!("left {temporaries:?}"))
            }
        }
        // The solver's failure (status 1) is the end of a mutant that passed the checks and
        // reached CalculiX: `shell`, or `optimize` of a design whose formulas use `max_shear`;
        // `roundtrip` and `check` fail their verdicts with status 1 (a deviation above the
        // tolerance, a seam creased beyond the G1 tolerance), and so does `fit` whose fit
        // misses its tolerance (nothing written).
        Some(c)
            if c == 2
                || (c == 1
                    && (job.sub == "shell"
                        || job.sub == "roundtrip"
                        || (job.sub == "check"
                            && stderr.contains("creased beyond the G1 tolerance"))
                        || (job.sub == "fit"
                            && stderr.contains("the fit misses the tolerance")
                            && stderr.contains("nothing written"))
                        || stderr.contains("CalculiX solver failed"))
                    && !stderr.contains("internal error")) =>
        {
            let lines: Vec<&str> = stderr.lines().collect();
            if !left.is_empty() {
                return (Outcome::Leftover, format!("left {left:?} after an error"));
            }
            if lines.len() != 1 || !lines[0].starts_with("error: ") {
                return (
                    Outcome::Unclear,
                    format!("not one error line: {}", first(&stderr)),
                );
            }
            match mutate::unclear(&lines[0]["error: ".len()..]) {
                Some(why) => (
                    Outcome::Unclear,
                    format!("{why} message: {}", first(&stderr)),
                ),
                None => (Outcome::CleanError, String::new()),
            }
        }
        Some(1) if stderr.contains("internal error") => (Outcome::Panic, first(&stderr)),
        other => (
            Outcome::Crash,
            format!("status {other:?}: {}", first(&stderr)),
        ),
    }
}

fn first(s: &str) -> String {
    s.chars().take(300).collect()
}

/// Runs `jobs` with the campaign's workers, writing every mutant into `root` before it runs;
/// returns the tally per subcommand and the failures (sub, example, why, directory).
fn campaign(
    jobs: &[Job],
    root: &Path,
    workers: usize,
) -> (
    BTreeMap<&'static str, Tally>,
    BTreeMap<&'static str, Tally>,
    Vec<String>,
) {
    let by_edge: Mutex<BTreeMap<&'static str, Tally>> = Mutex::new(BTreeMap::new());
    let ccx = &fake_ccx(root);
    let next = AtomicUsize::new(0);
    let tally: Mutex<BTreeMap<&'static str, Tally>> = Mutex::new(BTreeMap::new());
    let failures = Mutex::new(Vec::new());
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(i) else { break };
                let dir = root.join(format!("{:06}-{}-{}", job.index, job.sub, job.example));
                // A directory of its own, fresh (a rerun into the same root starts clean).
                let _ = std::fs::remove_dir_all(&dir);
                std::fs::create_dir_all(&dir).unwrap();
                let input = format!("in.{}", job.ext);
                std::fs::write(dir.join(&input), &job.text).unwrap();
                for (name, bytes) in &job.extra {
                    std::fs::write(dir.join(name), bytes).unwrap();
                }
                let (o, why) = judge(job, &dir, &input, Some(ccx.as_path()));
                if matches!(o, Outcome::Ok | Outcome::CleanError) {
                    let _ = std::fs::remove_dir_all(&dir);
                } else {
                    let line = format!(
                        "{} {} {} ({}): {why}",
                        job.index,
                        job.sub,
                        job.example,
                        dir.display()
                    );
                    let _ = std::fs::write(
                        dir.join("why.txt"),
                        format!("{line}\n{:?} {:?}\n", job.args, job.edge),
                    );
                    failures.lock().unwrap().push(line);
                }
                by_edge
                    .lock()
                    .unwrap()
                    .entry(edge_row(effective_edge(job)))
                    .or_default()
                    .add(&o);
                let mut t = tally.lock().unwrap();
                t.entry(job.sub).or_default().add(&o);
                let done: usize = t.values().map(|t| t.mutants).sum();
                if done.is_multiple_of(PROGRESS) {
                    let all = Tally::total(t.values());
                    let line = format!(
                        "progress {done}/{} after {:.0} s: {}\n",
                        jobs.len(),
                        start.elapsed().as_secs_f64(),
                        all.row("all")
                    );
                    print!("{line}");
                    let _ = std::fs::OpenOptions::new()
                        .create(true)
                        .append(true)
                        .open(root.join("progress.txt"))
                        .and_then(|mut f| std::io::Write::write_all(&mut f, line.as_bytes()));
                }
            });
        }
    });
    (
        tally.into_inner().unwrap(),
        by_edge.into_inner().unwrap(),
        failures.into_inner().unwrap(),
    )
}

/// The STEP and IGES files `roundtrip` mutants start from: `examples/cup.toml` written by the
/// binary under test, with its design text.
fn cad_sources(root: &Path) -> Vec<(String, String, Vec<u8>)> {
    let dir = root.join("cad-sources");
    std::fs::create_dir_all(&dir).unwrap();
    let design = pdeshape_testkit::example("cup.toml");
    std::fs::write(dir.join("cup.toml"), &design).unwrap();
    ["cup.igs", "cup.stp"]
        .iter()
        .map(|name| {
            let st = Command::new(binary())
                .args(["--quiet", "surface", "cup.toml", "-o", name])
                .current_dir(&dir)
                .status()
                .unwrap();
            assert!(st.success(), "cannot write {name}");
            let bytes = std::fs::read(dir.join(name)).unwrap();
            (name.to_string(), design.clone(), bytes)
        })
        .collect()
}

#[test]
fn mutation_campaign_through_the_binary() {
    let per: usize = env_or("PDESHAPE_CAMPAIGN_MUTANTS", 1);
    let seed: u64 = env_or("PDESHAPE_CAMPAIGN_SEED", 23);
    let workers: usize = env_or("PDESHAPE_CAMPAIGN_WORKERS", 2);
    let temp = tempfile::Builder::new()
        .prefix("pdeshape-campaign-")
        .tempdir()
        .unwrap();
    let root = std::env::var("PDESHAPE_CAMPAIGN_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| temp.path().to_path_buf());
    std::fs::create_dir_all(&root).unwrap();
    let jobs = jobs(per, seed, &cad_sources(&root));
    let start = Instant::now();
    let (tally, by_edge, failures) = campaign(&jobs, &root, workers);
    println!(
        "seed {seed}, {per} mutants per example and subcommand, {} runs, {workers} workers, {:.1} s; bounds: {CPU_SECONDS} s CPU, {} GiB address space, budget {} GiB",
        jobs.len(),
        start.elapsed().as_secs_f64(),
        ADDRESS_SPACE_KIB >> 20,
        BUDGET_BYTES >> 30
    );
    println!("| subcommand | mutants | successes | clean errors | panics | past bound | leftovers | unclear | crashes |\n|---|---|---|---|---|---|---|---|---|");
    for (sub, t) in &tally {
        println!("{}", t.row(sub));
    }
    let all = Tally::total(tally.values());
    println!("{}", all.row("all"));
    println!("\nBy the edge of the operating system the run met:\n");
    println!("| edge | mutants | successes | clean errors | panics | past bound | leftovers | unclear | crashes |\n|---|---|---|---|---|---|---|---|---|");
    for (edge, t) in &by_edge {
        println!("{}", t.row(edge));
    }
    assert_eq!(all.mutants, jobs.len());
    assert!(all.ok > 0 && all.clean > 0, "both outcomes must occur");
    if !failures.is_empty() {
        // Keep the failing inputs where they can be read.
        let kept = temp.keep();
        let _ = kept;
    }
    assert!(
        failures.is_empty(),
        "{} failing mutants (each directory holds its input and why.txt):\n{}",
        failures.len(),
        failures
            .iter()
            .take(30)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// Requests of the designer's API the serve campaign mutates: `(method, path and query, body)`.
const API_REQUESTS: &[(&str, &str, &str)] = &[
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"move_control_point","name":"rim","index":1,"point":[1.0,0.5,2.0]},"group":7}"#,
    ),
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"set_smoothing","patch":"body","a":1.5}}"#,
    ),
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"set_order","patch":"body","order":2}}"#,
    ),
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"set_modes","modes":4}}"#,
    ),
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"transform","name":"rim","step":{"translate":[0.0,0.0,0.5]}}}"#,
    ),
    (
        "POST",
        "/api/edit?nu=16&nv=32",
        r#"{"edit":{"edit":"set_curve","name":"rim","curve":{"type":"circle","center":[0.0,0.0,2.0],"radius":1.25}}}"#,
    ),
    ("POST", "/api/convert?nu=16&nv=32", r#"{"name":"rim"}"#),
    ("POST", "/api/load?nu=16&nv=32", r#"{"path":"cup.toml"}"#),
    ("POST", "/api/save", r#"{"path":"saved.toml"}"#),
    ("POST", "/api/undo?nu=16&nv=32", ""),
    ("GET", "/api/frame?nu=16&nv=32&color=mean", ""),
    ("GET", "/api/analyze", ""),
    // The server's save errors: a read-only file, a name longer than a file system takes.
    ("POST", "/api/save", r#"{"path":"locked.toml"}"#),
    ("POST", "/api/save", r#"{"path":"LONGNAME.toml"}"#),
    // A wrong method, and a body the request does not read.
    ("GET", "/api/new", ""),
    ("POST", "/api/new", r#"{"nu":16,"nv":32}"#),
];

/// User and system CPU time of process `pid` so far, in seconds (Linux `/proc/<pid>/stat`).
fn cpu_seconds(pid: u32) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// One HTTP/1.1 request; the status and the body of the answer, `None` past [`WALL`].
fn http(host: &str, token: &str, method: &str, path: &str, body: &[u8]) -> Option<(u16, Vec<u8>)> {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(host).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(600))).ok()?;
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nx-pdeshape-token: {token}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).ok()?;
    s.write_all(body).ok()?;
    let mut answer = Vec::new();
    s.read_to_end(&mut answer).ok()?;
    let text = String::from_utf8_lossy(&answer);
    let status: u16 = text.split_whitespace().nth(1)?.parse().ok()?;
    let at = answer.windows(4).position(|w| w == b"\r\n\r\n")? + 4;
    Some((status, answer[at..].to_vec()))
}

/// The designer's API under mutated requests: `pdeshape serve` runs as a child (under the
/// campaign's address-space limit) and gets mutants of [`API_REQUESTS`] (bodies and queries:
/// `PDESHAPE_CAMPAIGN_MUTANTS` × 40 of them; among them saves to a read-only file and to a
/// 300-character name, a wrong method and a body the request does not read). Every answer must
/// be 200 or a 4xx with a clear one-line JSON message that does not name the server's own
/// directory (a 5xx, a reset, an empty 405 fail), each request within [`CPU_SECONDS`] of the
/// server's CPU time, the server must keep serving, and its directory must hold no temporary
/// file at the end.
#[test]
fn designer_api_campaign() {
    use std::io::BufRead;
    let per: usize = env_or("PDESHAPE_CAMPAIGN_MUTANTS", 1) * 40;
    let seed: u64 = env_or("PDESHAPE_CAMPAIGN_SEED", 23);
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        pdeshape_testkit::repo_root().join("examples/cup.toml"),
        dir.path().join("cup.toml"),
    )
    .unwrap();
    // A read-only design file the saves must refuse with a 4xx naming it, never 500.
    let locked = dir.path().join("locked.toml");
    std::fs::write(&locked, "# locked\n").unwrap();
    let mut perms = std::fs::metadata(&locked).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&locked, perms).unwrap();
    // No answer may name the server's own directory.
    let root_shown = dir
        .path()
        .canonicalize()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(binary())
        .args(["serve", "--port", "0"])
        .current_dir(dir.path())
        .env("PDESHAPE_MAX_MEMORY", BUDGET_BYTES.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id();
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    // pdeshape designer: http://127.0.0.1:PORT/?token=TOKEN
    let url = line.trim().rsplit(' ').next().unwrap().to_string();
    let (host, query) = url
        .strip_prefix("http://")
        .and_then(|r| r.split_once('/'))
        .unwrap_or_else(|| panic!("no URL in {line:?}"));
    let token = query.strip_prefix("?token=").unwrap().to_string();
    let host = host.to_string();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5e_7e00);
    let mut tally = Tally::default();
    let mut failures = Vec::new();
    for i in 0..per {
        let (method, path, body) = API_REQUESTS[i % API_REQUESTS.len()];
        let long = "n".repeat(300);
        let body = &body.replace("LONGNAME", &long);
        // Mostly the body is mutated; one request in four mutates the query instead.
        let (path, body) = if i % 4 == 3 {
            (mutate::mutate(path, &mut rng), body.to_string())
        } else {
            (path.to_string(), mutate::mutate(body, &mut rng))
        };
        // A request target holds only unreserved characters and the delimiters of a path and a
        // query: percent-encode the rest (a raw quote or space is refused by the HTTP layer
        // before the API sees it).
        let path = if path.starts_with('/') {
            path
        } else {
            format!("/{path}")
        };
        let path: String = path
            .bytes()
            .map(|b| {
                if b.is_ascii_alphanumeric() || b"-._~/?&=%".contains(&b) {
                    (b as char).to_string()
                } else {
                    format!("%{b:02X}")
                }
            })
            .collect();
        let before = cpu_seconds(pid).unwrap_or(0.0);
        let answer = http(&host, &token, method, &path, body.as_bytes());
        let used = cpu_seconds(pid).map(|c| c - before);
        let (o, why) = match (answer, used) {
            (_, None) => (Outcome::Crash, "the server stopped".to_string()),
            // A request line over 64 KiB may be cut off by the HTTP layer (a closed connection);
            // the server must only go on serving, which the next request checks.
            (None, _) if path.len() > 1 << 16 => (Outcome::CleanError, String::new()),
            (None, _) => (Outcome::OverBound, "no answer within 600 s".to_string()),
            (_, Some(c)) if c > CPU_SECONDS as f64 => {
                (Outcome::OverBound, format!("{c:.1} s of CPU"))
            }
            (Some((200, _)), _) => (Outcome::Ok, String::new()),
            (Some((status, b)), _) if (400..500).contains(&status) => {
                let message = serde_json::from_slice::<serde_json::Value>(&b)
                    .ok()
                    .and_then(|v| v["error"].as_str().map(str::to_string))
                    .unwrap_or_default();
                // Outside `/api/` (a mutated path) the page's router answers, with a status only.
                match mutate::unclear(&message) {
                    _ if !path.starts_with("/api/") => (Outcome::CleanError, String::new()),
                    _ if message.contains(&*root_shown) => (
                        Outcome::Unclear,
                        format!("{status}: the server's own path: {}", first(&message)),
                    ),
                    _ if message.contains('\n') => (
                        Outcome::Unclear,
                        format!("{status}: several lines: {}", first(&message)),
                    ),
                    Some(w) => (
                        Outcome::Unclear,
                        format!("{status}: {w} message: {}", first(&message)),
                    ),
                    None => (Outcome::CleanError, String::new()),
                }
            }
            (Some((status, b)), _) => (
                if status >= 500 {
                    Outcome::Panic
                } else {
                    Outcome::Crash
                },
                format!("status {status}: {}", first(&String::from_utf8_lossy(&b))),
            ),
        };
        if !matches!(o, Outcome::Ok | Outcome::CleanError) {
            failures.push(format!(
                "{method} {} {:?}: {why}",
                first(&path),
                first(&body)
            ));
        }
        let stopped = o == Outcome::Crash;
        tally.add(&o);
        if stopped {
            break;
        }
    }
    // Still serving, and no temporary left in its directory.
    let files = http(&host, &token, "GET", "/api/files", b"");
    let _ = Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status();
    let _ = child.wait();
    let left: Vec<String> = common::files(dir.path())
        .into_iter()
        .filter(|f| f.contains(".pdeshape-") || f.ends_with(".tmp"))
        .collect();
    println!("designer API: seed {seed}, {per} requests");
    println!("{}", tally.row("serve"));
    assert!(
        matches!(files, Some((200, _))),
        "the server no longer serves"
    );
    assert!(left.is_empty(), "left {left:?}");
    assert!(tally.ok > 0 && tally.clean > 0, "both outcomes must occur");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every input that ever failed a campaign (`pdeshape/tests/regressions/`), through the binary
/// under the campaign's limits: designs (`.toml`) through every design subcommand, meshes
/// (`.obj`, `.ply`, `.stl`) through `fit`.
#[test]
fn regression_corpus_through_the_binary() {
    let dir = pdeshape_testkit::repo_root().join("crates/pdeshape/tests/regressions");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    let mut failures = Vec::new();
    let (mut designs, mut meshes) = (0, 0);
    for p in names {
        let ext = p
            .extension()
            .map(|e| e.to_string_lossy().to_string())
            .unwrap_or_default();
        let runs: Vec<(&'static str, &'static [&'static str])> = match ext.as_str() {
            "toml" => {
                designs += 1;
                RUNS.iter().map(|&(sub, _, args)| (sub, args)).collect()
            }
            "obj" | "ply" | "stl" => {
                meshes += 1;
                vec![("fit", &["fit", "-o", "out.toml"][..])]
            }
            _ => continue,
        };
        for (sub, args) in runs {
            let job = Job {
                index: 0,
                sub,
                example: p.file_name().unwrap().to_string_lossy().to_string(),
                ext: ext.clone(),
                args,
                text: std::fs::read(&p).unwrap(),
                edge: mutate::Edge::Plain,
                extra: Vec::new(),
            };
            let work = tempfile::tempdir().unwrap();
            let input = format!("in.{ext}");
            std::fs::write(work.path().join(&input), &job.text).unwrap();
            let (o, why) = judge(&job, work.path(), &input, None);
            if !matches!(o, Outcome::Ok | Outcome::CleanError) {
                failures.push(format!("{} {sub}: {why}", job.example));
            }
        }
    }
    assert!(
        designs > 0 && meshes > 0,
        "the corpus holds designs and meshes"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The unmutated `[shell]` examples reach the stand-in solver: status 1 with its one-line
/// message, no output and no temporary directory left (the path every `shell` mutant that
/// passes the input checks takes in the campaign).
#[test]
fn shell_designs_reach_the_stand_in_solver_and_leave_nothing() {
    let root = tempfile::tempdir().unwrap();
    let ccx = fake_ccx(root.path());
    let shelled: Vec<(String, String)> = designs()
        .into_iter()
        .filter(|(_, t)| t.lines().any(|l| l.trim() == "[shell]"))
        .collect();
    assert!(
        shelled.iter().any(|(n, _)| n.contains("yoghurt")),
        "yoghurt.toml has a [shell] section"
    );
    for (name, text) in &shelled {
        for args in SHELL_RUNS {
            let work = tempfile::tempdir().unwrap();
            std::fs::write(work.path().join("in.toml"), text).unwrap();
            let mut a: Vec<String> = vec![args[0].into(), "in.toml".into()];
            a.extend(args[1..].iter().map(|s| s.to_string()));
            let out = run_limited(work.path(), &a, Some(ccx.as_path()), None).expect("finishes");
            let stderr = String::from_utf8_lossy(&out.stderr).to_string();
            assert_eq!(out.status.code(), Some(1), "{name} {args:?}: {stderr}");
            assert_eq!(
                stderr,
                "error: the CalculiX solver failed (exit status: 1): *ERROR in fake-ccx: the \
                 campaign runs no solver\n",
                "{name} {args:?}"
            );
            assert_eq!(
                common::files(work.path()),
                vec!["in.toml".to_string()],
                "{name} {args:?}"
            );
            let job = Job {
                index: 0,
                sub: "shell",
                example: name.clone(),
                ext: "toml".into(),
                args,
                text: text.clone().into_bytes(),
                edge: mutate::Edge::Plain,
                extra: Vec::new(),
            };
            let (o, why) = judge(&job, work.path(), "in.toml", Some(ccx.as_path()));
            assert_eq!(o, Outcome::CleanError, "{name} {args:?}: {why}");
        }
    }
}
