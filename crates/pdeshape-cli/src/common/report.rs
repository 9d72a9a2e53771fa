//! What the CLI prints: `--quiet` and `--force`, reports on standard output (standard error once
//! standard output carries a file), and the time since the start.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// `--quiet`: no "wrote …" lines and no progress bars.
static QUIET: AtomicBool = AtomicBool::new(false);
/// `--force`: replace read-only output files.
pub(super) static FORCE: AtomicBool = AtomicBool::new(false);
/// Some output went to standard output (`-o -`), so reports go to stderr.
pub(super) static STDOUT_USED: AtomicBool = AtomicBool::new(false);
/// Sets `--quiet` and `--force` for the whole run.
pub(crate) fn set_flags(quiet: bool, force: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
    FORCE.store(force, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub(crate) fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A report line ("wrote …"): on stdout, or on stderr when stdout carries an output; nothing
/// with `--quiet`. While outputs wait for their rename, the line is held and printed once they
/// are in place (`commit.rs`).
pub(crate) fn report(text: &str) {
    if quiet() || super::commit::hold_report(text) {
        return;
    }
    print_report(text);
}

/// Prints a report line now (see [`report`]).
pub(super) fn print_report(text: &str) {
    if STDOUT_USED.load(Ordering::Relaxed) {
        let _ = std::io::stderr().write_all(text.as_bytes());
    } else {
        print_stdout(text);
    }
}

/// Writes to stdout, ignoring a closed pipe (`pdeshape schema | head` is fine).
pub(crate) fn print_stdout(text: &str) {
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    let _ = out.flush();
}

/// When the process's `main` started ([`mark_start`]).
static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();

/// Records the start of the process (called first thing in `main`).
pub(crate) fn mark_start() {
    START.get_or_init(std::time::Instant::now);
}

/// Milliseconds since [`mark_start`] (since the first call, if it was not called).
pub(crate) fn since_start_ms() -> f64 {
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
        * 1e3
}

/// A note about the input (`note: …` on stderr, nothing with `--quiet`): what the library did
/// beyond reading it, in the library's words.
pub(crate) fn note(text: &str) {
    if !quiet() {
        eprintln!("note: {text}");
    }
}
