//! Temporary files of outputs being written: removed on Ctrl-C, and those left behind by a
//! process that no longer runs removed on the next start.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary files being written, removed by the SIGINT/SIGTERM handler.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Exit status of a run stopped by SIGINT or SIGTERM.
pub(super) const INTERRUPTED: i32 = 130;

/// Removes the temporary files of this run when it is stopped by SIGINT (Ctrl-C) or SIGTERM, then
/// exits with status 130. (SIGKILL cannot be caught: its leftovers are removed by the next run
/// that writes into the same directory, see [`Output::create`].)
pub(crate) fn remove_temporaries_on_signals() {
    let _ = ctrlc::set_handler(|| {
        if let Ok(pending) = PENDING.lock() {
            for p in pending.iter() {
                let _ = std::fs::remove_file(p);
            }
        }
        eprintln!("error: interrupted; no output file was written");
        std::process::exit(INTERRUPTED);
    });
}

pub(super) fn pending_add(p: &Path) {
    if let Ok(mut v) = PENDING.lock() {
        v.push(p.to_path_buf());
    }
}

pub(super) fn pending_remove(p: &Path) {
    if let Ok(mut v) = PENDING.lock() {
        v.retain(|q| q != p);
    }
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
