//! `Output`: a file written atomically (a temporary beside it, renamed into place when complete)
//! or standard output.

use super::commit::{add_ready, pending_add, pending_remove, Ready};
use super::report::{quiet, FORCE, STDOUT_USED};
use super::temp::{remove_stale_temporaries, temp_prefix};
use super::{io_words, CliError};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// How a "wrote …" line names an output: its path, or "standard output" for `-o -`.
pub(crate) fn destination(path: &Path) -> String {
    if Output::is_stdout(path) {
        "standard output".to_string()
    } else {
        path.display().to_string()
    }
}

/// Where an output goes.
enum Target {
    /// A temporary file next to the real destination (a symlink's target, resolved).
    File {
        temp: tempfile::NamedTempFile,
        dest: PathBuf,
    },
    /// `-o -`: collected and written to stdout at [`Output::commit`].
    Stdout(Vec<u8>),
}

/// An output file being written: a temporary file next to the target, renamed over it only when
/// every output of the command is complete (`commit.rs`). Dropped without [`Output::commit`], it
/// leaves nothing behind; stopped by SIGINT, SIGTERM or SIGHUP, neither (see
/// [`super::remove_temporaries_on_signals`]). `-o -` writes to stdout. Messages name the user's
/// path, never the temporary one.
pub(crate) struct Output {
    shown: String,
    target: Target,
    /// Which file this is, held in [`LIVE`] while the output is open.
    identity: Option<Identity>,
}

/// Which file a destination is: its directory's canonical path joined with its name, and its
/// device and inode when it exists (so hard links count as the same file too).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Identity {
    path: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    /// The identity of `dest` (already resolved through symlinks) in the directory `dir`.
    fn of(dir: &Path, dest: &Path) -> Option<Identity> {
        let name = dest.file_name()?;
        let path = std::fs::canonicalize(dir).ok()?.join(name);
        #[cfg(unix)]
        let inode = {
            use std::os::unix::fs::MetadataExt;
            std::fs::metadata(&path).ok().map(|m| (m.dev(), m.ino()))
        };
        #[cfg(not(unix))]
        let inode = None;
        Some(Identity { path, inode })
    }

    fn same(&self, other: &Identity) -> bool {
        self.path == other.path || (self.inode.is_some() && self.inode == other.inode)
    }
}

/// The files of the outputs open now: a second output naming one of them is refused.
static LIVE: std::sync::Mutex<Vec<Identity>> = std::sync::Mutex::new(Vec::new());

/// Removes a committed output's file from [`LIVE`] once its run is final or undone.
pub(super) fn release(identity: Option<Identity>) {
    if let Some(id) = identity {
        let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = live.iter().position(|other| *other == id) {
            live.remove(i);
        }
    }
}

/// Why a destination cannot be written, before any work: the CLI and the designer word these
/// their own way ([`Output::create`], the designer's save).
#[derive(Debug)]
pub(crate) enum Refusal {
    /// An existing destination that is not a regular file, in words ("a directory", …).
    NotAFile(&'static str),
    /// The destination's directory does not exist.
    NoDirectory(PathBuf),
    /// Another output of this command names the same file.
    SameFile,
    /// The destination is read-only (and `--force` was not given).
    ReadOnly,
    /// The temporary file could not be created in the directory.
    Create(PathBuf, std::io::Error),
}

/// Whether `a` and `b` name the same file (through symlinks, `..` or hard links). Paths that
/// cannot be resolved are compared as given.
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    let id = |p: &Path| {
        let dest = resolve(p);
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Identity::of(&dir, &dest)
    };
    match (id(a), id(b)) {
        (Some(x), Some(y)) => x.same(&y),
        _ => a == b,
    }
}

/// What an existing destination that is not a regular file is, in words; `None` for a regular
/// file or a path that does not exist (a symlink to nowhere creates its target).
fn not_a_file(dest: &Path) -> Option<&'static str> {
    let t = std::fs::symlink_metadata(dest).ok()?.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_symlink() {
        // `resolve` stops on a chain that does not end: a loop, or more than 40 links.
        return Some("a loop of symbolic links");
    }
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_socket() {
            return Some("a socket");
        }
        if t.is_block_device() || t.is_char_device() {
            return Some("a device");
        }
    }
    Some("not a regular file")
}

/// The real destination of `path`: itself, or the file a symlink (chain) points to.
fn resolve(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => match std::fs::read_link(&p) {
                Ok(t) if t.is_absolute() => p = t,
                Ok(t) => {
                    p = p.parent().map(|d| d.join(&t)).unwrap_or(t);
                }
                Err(_) => break,
            },
            _ => break,
        }
    }
    p
}

impl Output {
    /// Whether `path` means standard output.
    pub(crate) fn is_stdout(path: &Path) -> bool {
        path.as_os_str() == "-"
    }

    /// Creates the temporary file in the destination's directory (so the final rename is atomic),
    /// after checking the destination: not a directory, in an existing directory, not read-only
    /// (unless `--force`). Removes stale temporaries of killed runs in that directory.
    pub(crate) fn create(path: &Path) -> Result<Self, CliError> {
        let shown = pdeshape::spec::words::user_text(&path.display().to_string());
        Self::open(path, FORCE.load(Ordering::Relaxed)).map_err(|r| {
            CliError::input(match r {
                Refusal::NotAFile("a directory") => format!("-o {shown}: is a directory"),
                Refusal::NotAFile(what) => {
                    format!("-o {shown}: is {what}, not a regular file; refused")
                }
                Refusal::NoDirectory(dir) => format!(
                    "-o {shown}: the directory '{}' does not exist",
                    pdeshape::spec::words::user_text(&dir.display().to_string())
                ),
                Refusal::SameFile => {
                    format!("-o {shown}: names the same file as another output of this command")
                }
                Refusal::ReadOnly => {
                    format!("-o {shown}: the file is read-only; pass --force to replace it")
                }
                Refusal::Create(dir, e) => format!(
                    "-o {shown}: cannot create a file in '{}': {}",
                    pdeshape::spec::words::user_text(&dir.display().to_string()),
                    io_words(&e)
                ),
            })
        })
    }

    /// [`Output::create`] with the refusal as a value; `force` replaces read-only files.
    pub(crate) fn open(path: &Path, force: bool) -> Result<Self, Refusal> {
        let shown = pdeshape::spec::words::user_text(&path.display().to_string());
        if Self::is_stdout(path) {
            STDOUT_USED.store(true, Ordering::Relaxed);
            return Ok(Output {
                shown: "standard output".to_string(),
                target: Target::Stdout(Vec::new()),
                identity: None,
            });
        }
        let dest = resolve(path);
        if let Some(what) = not_a_file(&dest) {
            return Err(Refusal::NotAFile(what));
        }
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            return Err(Refusal::NoDirectory(dir));
        }
        let identity = Identity::of(&dir, &dest);
        if let Some(id) = &identity {
            let live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
            if live.iter().any(|other| other.same(id)) {
                return Err(Refusal::SameFile);
            }
        }
        if let Ok(m) = std::fs::metadata(&dest) {
            if m.permissions().readonly() && !force {
                return Err(Refusal::ReadOnly);
            }
        }
        for name in remove_stale_temporaries(&dir) {
            if !quiet() {
                eprintln!(
                    "note: removed '{}', left in '{}' by a run that was killed",
                    name,
                    dir.display()
                );
            }
        }
        let temp = tempfile::Builder::new()
            .prefix(&temp_prefix(std::process::id()))
            .suffix(".tmp")
            .tempfile_in(&dir)
            .map_err(|e| Refusal::Create(dir.clone(), e))?;
        pending_add(temp.path());
        if let Some(id) = &identity {
            LIVE.lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(id.clone());
        }
        Ok(Output {
            shown,
            target: Target::File { temp, dest },
            identity,
        })
    }

    /// A buffered writer on the output.
    pub(crate) fn writer(&mut self) -> std::io::BufWriter<OutputWriter<'_>> {
        std::io::BufWriter::new(match &mut self.target {
            Target::File { temp, .. } => OutputWriter::File {
                file: temp.as_file_mut(),
                unsent: 0,
            },
            Target::Stdout(buf) => OutputWriter::Stdout(buf),
        })
    }

    /// Writes `bytes` to the output.
    pub(crate) fn write_all(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let shown = self.shown.clone();
        let r = match &mut self.target {
            Target::File { temp, .. } => temp.as_file_mut().write_all(bytes),
            Target::Stdout(buf) => {
                buf.extend_from_slice(bytes);
                Ok(())
            }
        };
        r.map_err(|e| CliError::input(format!("-o {shown}: {}", io_words(&e))))
    }

    /// Finishes the output: the temporary file is flushed, synced and given its final
    /// permissions, then waits for the rename onto the destination (through a symlink, onto the
    /// file it points to) that [`super::finish_outputs`] does for every output of the command
    /// together. `-o -`: the collected bytes are written to stdout now.
    pub(crate) fn commit(mut self) -> Result<(), CliError> {
        let shown = self.shown.clone();
        let err = |e: &std::io::Error| CliError::input(format!("-o {shown}: {}", io_words(e)));
        match std::mem::replace(&mut self.target, Target::Stdout(Vec::new())) {
            Target::Stdout(buf) => {
                let mut out = std::io::stdout().lock();
                match out.write_all(&buf).and_then(|_| out.flush()) {
                    Ok(()) => Ok(()),
                    Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                    Err(e) => Err(err(&e)),
                }
            }
            Target::File { temp, dest } => {
                let tpath = temp.path().to_path_buf();
                // Temporary files are private (0600); the result gets the usual permissions of
                // a new file (rw-r--r--).
                #[cfg(unix)]
                {
                    use std::os::unix::fs::PermissionsExt;
                    temp.as_file()
                        .set_permissions(std::fs::Permissions::from_mode(0o644))
                        .map_err(|e| err(&e))?;
                }
                let synced = temp.as_file().sync_all();
                if let Err(e) = synced {
                    pending_remove(&tpath);
                    return Err(err(&e));
                }
                add_ready(Ready {
                    temp: temp.into_temp_path(),
                    dest,
                    shown: self.shown.clone(),
                    // Held until the run is final: a later output naming it is still refused.
                    identity: self.identity.take(),
                });
                Ok(())
            }
        }
    }
}

/// Bytes written to the temporary file after which the kernel is asked to start writing them to
/// the disk ([`OutputWriter`]).
const WRITE_BACK: u64 = 8 << 20;

/// What [`Output::writer`] writes to. On Linux, every [`WRITE_BACK`] bytes written to the file the
/// kernel is asked to start writing its dirty pages to the disk (`sync_file_range`, without
/// waiting), so the disk works while the rest is produced and the fsync of [`Output::commit`]
/// waits for the last few megabytes only. It changes nothing of what is written, nor of when the
/// file counts as written: that is still the fsync before the rename.
pub(crate) enum OutputWriter<'a> {
    File {
        file: &'a mut std::fs::File,
        /// Bytes written since write-back was last started.
        unsent: u64,
    },
    Stdout(&'a mut Vec<u8>),
}

impl Write for OutputWriter<'_> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        match self {
            OutputWriter::File { file, unsent } => {
                let n = file.write(bytes)?;
                *unsent += n as u64;
                if *unsent >= WRITE_BACK {
                    *unsent = 0;
                    #[cfg(target_os = "linux")]
                    {
                        use std::os::fd::AsRawFd;
                        // SAFETY: a descriptor of an open file; the call only starts writing
                        // the file's dirty pages (offset 0, length 0: the whole file) and
                        // touches no memory of ours. Its result is a hint's: not needed.
                        unsafe {
                            libc::sync_file_range(
                                file.as_raw_fd(),
                                0,
                                0,
                                libc::SYNC_FILE_RANGE_WRITE,
                            )
                        };
                    }
                }
                Ok(n)
            }
            OutputWriter::Stdout(buf) => buf.write(bytes),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            OutputWriter::File { file, .. } => file.flush(),
            OutputWriter::Stdout(_) => Ok(()),
        }
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Target::File { temp, .. } = &self.target {
            pending_remove(temp.path());
        }
        release(self.identity.take());
    }
}
