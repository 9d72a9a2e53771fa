//! The outputs of one command, committed all or none.
//!
//! Every output is written to a temporary file beside its destination ([`super::Output`]).
//! [`super::Output::commit`] only finishes that temporary (flushed, synced, given its final
//! permissions) and hands it to the journal here; the renames happen together in
//! [`finish_outputs`], after the command has produced every output. A destination that already
//! exists is kept under a hard link (a backup) until all renames succeeded, so when a rename
//! fails, or SIGINT/SIGTERM/SIGHUP arrives while the outputs are being put in place, every
//! output this run already renamed is undone: removed, or its previous file put back. Then the
//! message "no output file was written" is true.
//!
//! The "wrote …" lines a command prints while its outputs wait for [`finish_outputs`] are held
//! and printed after the renames, so they are never printed for files that were not written.

use super::temp::temp_prefix;
use super::CliError;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

/// An output whose temporary is complete, waiting for its rename.
pub(super) struct Ready {
    /// The temporary file (removed when dropped).
    pub(super) temp: tempfile::TempPath,
    /// The real destination (a symlink's target, resolved).
    pub(super) dest: PathBuf,
    /// The name the user gave, as messages show it.
    pub(super) shown: String,
    /// Which file it is, held in the open outputs' list until the run is final.
    pub(super) identity: Option<super::output::Identity>,
}

/// An output renamed into place by this run, not yet final.
struct Renamed {
    dest: PathBuf,
    shown: String,
    /// The destination's previous file, kept under a temporary name until the run is final.
    backup: Option<PathBuf>,
}

/// What this run has written and not yet made final.
struct Journal {
    /// Temporary files being written (outputs still open).
    pending: Vec<PathBuf>,
    /// Outputs committed and waiting for [`finish_outputs`].
    ready: Vec<Ready>,
    /// Outputs renamed into place during [`finish_outputs`].
    renamed: Vec<Renamed>,
    /// Report lines held until the outputs are in place.
    reports: String,
    /// Outputs made final by [`finish_outputs`] (named by the signal handler's message).
    done: Vec<String>,
    /// The run has ended ([`end_run`]): its outputs are final or undone and its last line is
    /// being printed, so a signal changes nothing more.
    ended: bool,
}

static JOURNAL: Mutex<Journal> = Mutex::new(Journal {
    pending: Vec::new(),
    ready: Vec::new(),
    renamed: Vec::new(),
    reports: String::new(),
    done: Vec::new(),
    ended: false,
});

fn journal() -> std::sync::MutexGuard<'static, Journal> {
    JOURNAL.lock().unwrap_or_else(|e| e.into_inner())
}

pub(super) fn pending_add(p: &Path) {
    journal().pending.push(p.to_path_buf());
}

pub(super) fn pending_remove(p: &Path) {
    journal().pending.retain(|q| q != p);
}

/// Hands a complete temporary to the journal: it is renamed by [`finish_outputs`].
pub(super) fn add_ready(ready: Ready) {
    let mut j = journal();
    let path = ready.temp.to_path_buf();
    j.pending.retain(|q| *q != path);
    j.ready.push(ready);
}

/// Holds `text` until the outputs are in place, if some are waiting; `false` (the caller prints
/// it now) otherwise.
pub(super) fn hold_report(text: &str) -> bool {
    let mut j = journal();
    if j.ready.is_empty() {
        return false;
    }
    j.reports.push_str(text);
    true
}

/// Numbers the backups of this process.
static BACKUPS: AtomicU32 = AtomicU32::new(0);

/// Renames `temp` onto `dest`, keeping an existing regular file at `dest` under a backup name in
/// the same directory (a hard link, or the file itself moved aside where links are refused).
/// On failure nothing has changed at `dest`.
fn rename_keeping(temp: tempfile::TempPath, dest: &Path) -> std::io::Result<Option<PathBuf>> {
    let existing = std::fs::symlink_metadata(dest).is_ok_and(|m| m.file_type().is_file());
    let backup = if existing {
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let n = BACKUPS.fetch_add(1, Ordering::Relaxed);
        let b = dir.join(format!("{}b{n}.tmp", temp_prefix(std::process::id())));
        std::fs::hard_link(dest, &b).or_else(|_| std::fs::rename(dest, &b))?;
        Some(b)
    } else {
        None
    };
    match temp.persist(dest) {
        Ok(()) => Ok(backup),
        Err(e) => {
            if let Some(b) = &backup {
                restore(b, dest);
            }
            Err(e.error)
        }
    }
}

/// Puts the previous file `backup` back at `dest` (renaming one hard link of a file onto another
/// of the same file changes nothing, so the backup's name is removed after).
fn restore(backup: &Path, dest: &Path) {
    let _ = std::fs::rename(backup, dest);
    let _ = std::fs::remove_file(backup);
}

/// Undoes what [`finish_outputs`] renamed and removes every temporary: the file system is as
/// the run found it. Returns the outputs undone, in words ("x removed", "y restored").
fn undo(j: &mut Journal) -> Vec<String> {
    let mut words = Vec::new();
    for r in j.renamed.drain(..).rev() {
        match &r.backup {
            Some(b) => {
                restore(b, &r.dest);
                words.push(format!("{} restored", r.shown));
            }
            None => {
                let _ = std::fs::remove_file(&r.dest);
                words.push(format!("{} removed", r.shown));
            }
        }
    }
    for r in j.ready.drain(..) {
        let _ = std::fs::remove_file(&r.temp);
        super::output::release(r.identity);
    }
    for p in j.pending.drain(..) {
        let _ = std::fs::remove_file(p);
    }
    words.reverse();
    words
}

/// Renames every committed output into place, together: all of them, or (on the first failure)
/// none, the ones already renamed undone. The held report lines are printed after. Called by
/// `main` when a command succeeded, and by the designer after a save.
pub(crate) fn finish_outputs() -> Result<(), CliError> {
    let mut j = journal();
    let ready = std::mem::take(&mut j.ready);
    let mut rest = ready.into_iter();
    while let Some(r) = rest.next() {
        let Ready {
            temp,
            dest,
            shown,
            identity,
        } = r;
        super::output::release(identity);
        match rename_keeping(temp, &dest) {
            Ok(backup) => j.renamed.push(Renamed {
                dest,
                shown,
                backup,
            }),
            Err(e) => {
                j.ready.extend(rest);
                let undone = undo(&mut j);
                j.reports.clear();
                let also = if undone.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", undone.join(", "))
                };
                return Err(CliError::input(format!(
                    "-o {shown}: {}; no output file was written{also}",
                    super::io_words(&e)
                )));
            }
        }
    }
    for r in std::mem::take(&mut j.renamed) {
        if let Some(b) = &r.backup {
            let _ = std::fs::remove_file(b);
        }
        j.done.push(r.shown);
    }
    let reports = std::mem::take(&mut j.reports);
    drop(j);
    if !reports.is_empty() {
        super::report::print_report(&reports);
    }
    Ok(())
}

/// Removes the temporaries of a run that failed (nothing of it was renamed: renames happen only
/// in [`finish_outputs`]) and drops its held report lines.
pub(crate) fn abandon_outputs() {
    let mut j = journal();
    let _ = undo(&mut j);
    j.reports.clear();
}

/// Marks the run as ended: called by `main` once the outputs are final (or undone), before it
/// prints its last line and exits with the command's own status. A signal after this does
/// nothing (a second line "interrupted" after the error would not be true).
pub(crate) fn end_run() {
    journal().ended = true;
}

/// What the signal handler does: undo this run's outputs and say what is true. The journal
/// stays locked (the process exits), so no rename can follow. After [`end_run`] it does
/// nothing: the run ends as it was ending.
pub(super) fn on_signal() {
    let mut j = journal();
    if j.ended {
        return;
    }
    let done = std::mem::take(&mut j.done);
    let undone = undo(&mut j);
    let message = if !done.is_empty() {
        format!(
            "error: interrupted after the outputs were written ({})",
            done.join(", ")
        )
    } else if !undone.is_empty() {
        format!(
            "error: interrupted; no output file was written ({})",
            undone.join(", ")
        )
    } else {
        "error: interrupted; no output file was written".to_string()
    };
    eprintln!("{message}");
    std::process::exit(super::temp::INTERRUPTED);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ready(dir: &Path, name: &str, text: &str) -> Ready {
        let mut t = tempfile::Builder::new()
            .prefix(&temp_prefix(std::process::id()))
            .suffix(".tmp")
            .tempfile_in(dir)
            .unwrap();
        std::io::Write::write_all(&mut t, text.as_bytes()).unwrap();
        Ready {
            temp: t.into_temp_path(),
            dest: dir.join(name),
            shown: name.to_string(),
            identity: None,
        }
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// The journal is one per process: the tests that use it run one after another.
    static SERIAL: Mutex<()> = Mutex::new(());

    #[test]
    fn a_failed_rename_undoes_the_renames_before_it() {
        let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.txt"), "old a").unwrap();
        add_ready(ready(dir.path(), "a.txt", "new a"));
        add_ready(ready(dir.path(), "b.txt", "new b"));
        // The third cannot be renamed: its temporary is gone.
        let third = ready(dir.path(), "c.txt", "new c");
        std::fs::remove_file(&third.temp).unwrap();
        add_ready(third);
        assert!(hold_report("wrote a.txt\n"));
        let e = finish_outputs().unwrap_err();
        assert!(
            e.message.starts_with("-o c.txt: ")
                && e.message
                    .ends_with("no output file was written (a.txt restored, b.txt removed)"),
            "{}",
            e.message
        );
        assert_eq!(names(dir.path()), ["a.txt"]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.txt")).unwrap(),
            "old a"
        );
        assert!(journal().reports.is_empty());
    }

    #[test]
    fn all_renames_succeed_together_and_leave_no_backup() {
        let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.txt"), "old a").unwrap();
        add_ready(ready(dir.path(), "a.txt", "new a"));
        add_ready(ready(dir.path(), "b.txt", "new b"));
        // Nothing is in place before the renames.
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.txt")).unwrap(),
            "old a"
        );
        assert!(!dir.path().join("b.txt").exists());
        finish_outputs().unwrap();
        assert_eq!(names(dir.path()), ["a.txt", "b.txt"]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.txt")).unwrap(),
            "new a"
        );
        journal().done.clear();
    }

    #[test]
    fn a_signal_after_the_run_ended_changes_nothing() {
        let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
        // Before `end_run`, this call would undo and exit the test process with status 130.
        end_run();
        on_signal();
        assert!(journal().ended);
    }

    #[test]
    fn an_abandoned_run_leaves_nothing() {
        let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        add_ready(ready(dir.path(), "a.txt", "new a"));
        abandon_outputs();
        assert!(names(dir.path()).is_empty());
    }
}
