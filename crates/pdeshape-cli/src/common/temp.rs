//! Temporary files of outputs being written: removed on Ctrl-C, and those left behind by a
//! process that no longer runs removed on the next start.

use std::path::Path;

/// Exit status of a run stopped by SIGINT, SIGTERM or SIGHUP.
pub(super) const INTERRUPTED: i32 = 130;

/// When the run is stopped by SIGINT (Ctrl-C), SIGTERM or SIGHUP: removes its temporary files,
/// undoes the outputs it had already renamed into place (`commit.rs`), says so and exits with
/// status 130. (SIGKILL cannot be caught: its temporaries are removed by the next run that
/// writes into the same directory, see [`super::Output::create`].)
pub(crate) fn remove_temporaries_on_signals() {
    let _ = ctrlc::set_handler(super::commit::on_signal);
}

/// The prefix of this process's temporary files: `.pdeshape-<pid>-`.
pub(super) fn temp_prefix(pid: u32) -> String {
    format!(".pdeshape-{pid}-")
}

/// The process id in the name of a temporary file `.pdeshape-<pid>-XXXXXX.tmp`.
fn temp_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(".pdeshape-")?.strip_suffix(".tmp")?;
    let (pid, tail) = rest.split_once('-')?;
    (!tail.is_empty() && tail.chars().all(|c| c.is_ascii_alphanumeric()))
        .then(|| pid.parse().ok())
        .flatten()
}

/// Whether a process is running (Linux: `/proc/<pid>/stat` exists and is not a zombie;
/// elsewhere assumed running, so nothing is removed).
fn process_alive(pid: u32) -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        // The state follows the command name in parentheses: `123 (pdeshape) Z …`.
        Ok(stat) => !stat
            .rsplit_once(") ")
            .is_some_and(|(_, rest)| rest.starts_with('Z') || rest.starts_with('X')),
        Err(_) => false,
    }
}

/// Removes temporary files `.pdeshape-<pid>-XXXXXX.tmp` in `dir` left by runs that were killed
/// (their process no longer exists). Returns the names removed.
pub(super) fn remove_stale_temporaries(dir: &Path) -> Vec<String> {
    let mut removed = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return removed;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let Some(pid) = temp_owner(&name) else {
            continue;
        };
        if pid != std::process::id()
            && !process_alive(pid)
            && e.file_type().is_ok_and(|t| t.is_file())
            && std::fs::remove_file(e.path()).is_ok()
        {
            removed.push(name);
        }
    }
    removed
}
