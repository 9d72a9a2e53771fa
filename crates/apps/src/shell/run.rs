//! Running CalculiX (`ccx`) on a deck in a temporary directory with a time limit.

use crate::{Error, Result};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How to install the solver, for the message when it is missing.
pub(crate) const INSTALL_HINT: &str =
    "install CalculiX (Debian/Ubuntu: `apt-get install calculix-ccx`; \
     other systems: https://www.calculix.de) or name the binary with PDESHAPE_CCX";

/// How to run the solver.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// The solver binary: `PDESHAPE_CCX` if set, else `ccx` on the `PATH`.
    pub program: PathBuf,
    /// Wall-clock limit of one run; the process is killed after it.
    pub time_limit: Duration,
    /// Threads the solver may use (`OMP_NUM_THREADS`, `CCX_NPROC_EQUATION_SOLVER`).
    pub threads: usize,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            program: std::env::var_os("PDESHAPE_CCX")
                .map(PathBuf::from)
                .unwrap_or_else(|| PathBuf::from("ccx")),
            time_limit: Duration::from_secs(300),
            threads: 1,
        }
    }
}

/// What one run left behind: the `.frd` result file's text and the solver's wall time.
#[derive(Clone, Debug)]
pub struct RunOutput {
    /// The text of the `.frd` result file.
    pub frd: String,
    /// The solver's wall time, in seconds.
    pub seconds: f64,
}

/// Writes `deck` as `job.inp` in a fresh temporary directory, runs `program -i job` there, and
/// returns `job.frd`. The directory is removed whatever happens (it is dropped on every path).
pub fn run_ccx(deck: &str, options: &RunOptions) -> Result<RunOutput> {
    let dir = tempfile::Builder::new()
        .prefix("pdeshape-ccx-")
        .tempdir()
        .map_err(|e| Error::io(format!("cannot create a temporary directory: {e}")))?;
    let inp = dir.path().join("job.inp");
    std::fs::write(&inp, deck)
        .map_err(|e| Error::io(format!("cannot write {}: {e}", inp.display())))?;
    let log = std::fs::File::create(dir.path().join("job.log"))
        .map_err(|e| Error::io(format!("cannot write the solver log: {e}")))?;
    let log2 = log
        .try_clone()
        .map_err(|e| Error::io(format!("cannot write the solver log: {e}")))?;
    let threads = options.threads.max(1).to_string();
    let start = Instant::now();
    let mut child = Command::new(&options.program)
        .arg("-i")
        .arg("job")
        .current_dir(dir.path())
        .env("OMP_NUM_THREADS", &threads)
        .env("CCX_NPROC_EQUATION_SOLVER", &threads)
        .env("CCX_NPROC_RESULTS", &threads)
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(log2)
        .spawn()
        .map_err(|e| {
            if e.kind() == std::io::ErrorKind::NotFound {
                Error::io(format!(
                    "the CalculiX solver '{}' was not found: {INSTALL_HINT}",
                    options.program.display()
                ))
            } else {
                Error::io(format!(
                    "cannot start the CalculiX solver '{}': {e}",
                    options.program.display()
                ))
            }
        })?;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() >= options.time_limit => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(Error::io(format!(
                    "the CalculiX solver did not finish within {} s (killed)",
                    options.time_limit.as_secs_f64()
                )));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(5)),
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(Error::io(format!("waiting for the CalculiX solver: {e}")));
            }
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let log_text = std::fs::read_to_string(dir.path().join("job.log")).unwrap_or_default();
    // ccx exits with status 0 even after some errors; its "*ERROR" lines tell.
    let error_line = log_text
        .lines()
        .find(|l| l.contains("*ERROR"))
        .map(|l| l.trim().to_string());
    if !status.success() || error_line.is_some() {
        return Err(Error::io(format!(
            "the CalculiX solver failed ({}){}",
            status,
            error_line.map(|l| format!(": {l}")).unwrap_or_default()
        )));
    }
    let frd = std::fs::read_to_string(dir.path().join("job.frd")).map_err(|e| {
        Error::io(format!(
            "the CalculiX solver wrote no result file job.frd: {e}"
        ))
    })?;
    Ok(RunOutput { frd, seconds })
}
