//! What the subcommands share: loading a design with located errors, choosing the grid, and
//! writing an output file atomically.

use pdeshape::design::{self, SolvedDesign};
use pdeshape::format::OutputFormat;
use pdeshape::spec::{self, DesignSpec};
use pdeshape::Error;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// A failure: one line for stderr and the exit status.
#[derive(Debug)]
pub struct CliError {
    pub message: String,
    pub status: u8,
}

impl CliError {
    /// Bad input (design, arguments, output path): exit status 2.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            status: 2,
        }
    }
}

/// A design file read and parsed.
pub struct Loaded {
    pub file: String,
    pub text: String,
    pub spec: DesignSpec,
}

impl Loaded {
    /// `file:line:col: place: message` for an error about this file.
    pub fn error(&self, e: &Error) -> CliError {
        CliError::input(spec::describe_error(&self.file, &self.text, e))
    }

    /// Compiles and solves the design (every kind, with the solver it asks for).
    pub fn build(&self) -> Result<SolvedDesign, CliError> {
        design::solve_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// Validates the design without solving it.
    pub fn validate(&self) -> Result<(), CliError> {
        design::validate_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// The grid ([`design::grid`]): the command line's `--nu`/`--nv`, else `[output]`, else
    /// 64 × 128, refused before anything is solved or allocated beyond the grid limits.
    pub fn grid(&self, nu: Option<usize>, nv: Option<usize>) -> Result<(usize, usize), CliError> {
        design::grid(&self.spec, nu, nv).map_err(|e| {
            if e.place().starts_with("output") {
                self.error(&e)
            } else {
                let place = match e.place() {
                    "nu" => "--nu".to_string(),
                    "nv" => "--nv".to_string(),
                    _ => "--nu × --nv".to_string(),
                };
                CliError::input(format!("{place}: {}", message_of(&e)))
            }
        })
    }
}

/// `--set NAME=VALUE` (repeatable): the values of the design's `[[parameters]]` entries,
/// each checked against the entry's bounds; errors name the flag and the parameter.
pub fn apply_sets(design: &mut Loaded, sets: &[String]) -> Result<(), CliError> {
    for s in sets {
        let Some((name, value)) = s.split_once('=') else {
            return Err(CliError::input(format!(
                "--set {s}: expected NAME=VALUE, e.g. --set theta=0.3"
            )));
        };
        let (name, value) = (name.trim(), value.trim());
        let v: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                CliError::input(format!(
                    "--set {s}: the value '{value}' of '{name}' is not a finite number"
                ))
            })?;
        design::set_parameter(&mut design.spec, name, Some(v))
            .map_err(|e| CliError::input(format!("--set {s}: {}", message_of(&e))))?;
    }
    Ok(())
}

/// The message of an error without its place.
pub fn message_of(e: &Error) -> String {
    e.message()
}

/// Reads and parses a design file (the library's [`pdeshape::open`]: one size limit, one
/// treatment of directories, FIFOs and symlinks; a timed design at its start time).
pub fn load(path: &Path) -> Result<Loaded, CliError> {
    let f = pdeshape::open::DesignFile::read(path).map_err(opened)?;
    let spec = f.parse_still().map_err(opened)?;
    Ok(Loaded {
        file: f.file,
        text: f.text,
        spec,
    })
}

/// A file that could not be opened: its one line.
pub fn opened(e: pdeshape::open::OpenError) -> CliError {
    CliError::input(e.message)
}

/// `--quiet`: no "wrote …" lines and no progress bars.
static QUIET: AtomicBool = AtomicBool::new(false);
/// `--force`: replace read-only output files.
static FORCE: AtomicBool = AtomicBool::new(false);
/// Some output went to standard output (`-o -`), so reports go to stderr.
static STDOUT_USED: AtomicBool = AtomicBool::new(false);
/// The temporary files being written, removed by the SIGINT/SIGTERM handler.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Exit status of a run stopped by SIGINT or SIGTERM.
pub const INTERRUPTED: i32 = 130;

/// Sets `--quiet` and `--force` for the whole run.
pub fn set_flags(quiet: bool, force: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
    FORCE.store(force, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Removes the temporary files of this run when it is stopped by SIGINT (Ctrl-C) or SIGTERM, then
/// exits with status 130. (SIGKILL cannot be caught: its leftovers are removed by the next run
/// that writes into the same directory, see [`Output::create`].)
pub fn remove_temporaries_on_signals() {
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

fn pending_add(p: &Path) {
    if let Ok(mut v) = PENDING.lock() {
        v.push(p.to_path_buf());
    }
}

fn pending_remove(p: &Path) {
    if let Ok(mut v) = PENDING.lock() {
        v.retain(|q| q != p);
    }
}

/// How a "wrote …" line names an output: its path, or "standard output" for `-o -`.
pub fn destination(path: &Path) -> String {
    if Output::is_stdout(path) {
        "standard output".to_string()
    } else {
        path.display().to_string()
    }
}

/// A report line ("wrote …"): on stdout, or on stderr when stdout carries an output; nothing
/// with `--quiet`.
pub fn report(text: &str) {
    if quiet() {
        return;
    }
    if STDOUT_USED.load(Ordering::Relaxed) {
        let _ = std::io::stderr().write_all(text.as_bytes());
    } else {
        print_stdout(text);
    }
}

/// The prefix of this process's temporary files: `.pdeshape-<pid>-`.
fn temp_prefix(pid: u32) -> String {
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
pub fn remove_stale_temporaries(dir: &Path) -> Vec<String> {
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
/// everything succeeded. Dropped without [`Output::commit`], it leaves nothing behind; stopped by
/// SIGINT or SIGTERM, neither (see [`remove_temporaries_on_signals`]). `-o -` writes to stdout.
/// Messages name the user's path, never the temporary one.
pub struct Output {
    shown: String,
    target: Target,
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
    pub fn is_stdout(path: &Path) -> bool {
        path.as_os_str() == "-"
    }

    /// Creates the temporary file in the destination's directory (so the final rename is atomic),
    /// after checking the destination: not a directory, in an existing directory, not read-only
    /// (unless `--force`). Removes stale temporaries of killed runs in that directory.
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let shown = path.display().to_string();
        if Self::is_stdout(path) {
            STDOUT_USED.store(true, Ordering::Relaxed);
            return Ok(Output {
                shown: "standard output".to_string(),
                target: Target::Stdout(Vec::new()),
            });
        }
        let dest = resolve(path);
        if dest.is_dir() {
            return Err(CliError::input(format!("-o {shown}: is a directory")));
        }
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            return Err(CliError::input(format!(
                "-o {shown}: the directory '{}' does not exist",
                dir.display()
            )));
        }
        if let Ok(m) = std::fs::metadata(&dest) {
            if m.permissions().readonly() && !FORCE.load(Ordering::Relaxed) {
                return Err(CliError::input(format!(
                    "-o {shown}: the file is read-only; pass --force to replace it"
                )));
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
            .map_err(|e| {
                CliError::input(format!(
                    "-o {shown}: cannot create a file in '{}': {}",
                    dir.display(),
                    io_words(&e)
                ))
            })?;
        pending_add(temp.path());
        Ok(Output {
            shown,
            target: Target::File { temp, dest },
        })
    }

    /// A buffered writer on the output.
    pub fn writer(&mut self) -> std::io::BufWriter<OutputWriter<'_>> {
        std::io::BufWriter::new(match &mut self.target {
            Target::File { temp, .. } => OutputWriter::File {
                file: temp.as_file_mut(),
                unsent: 0,
            },
            Target::Stdout(buf) => OutputWriter::Stdout(buf),
        })
    }

    /// Writes `bytes` to the output.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), CliError> {
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

    /// Flushes and renames the temporary file onto the destination (through a symlink, onto the
    /// file it points to), or writes the collected bytes to stdout.
    pub fn commit(mut self) -> Result<(), CliError> {
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
                temp.as_file().sync_all().map_err(|e| err(&e))?;
                let r = temp.persist(&dest);
                pending_remove(&tpath);
                r.map_err(|e| err(&e.error))?;
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
pub enum OutputWriter<'a> {
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
    }
}

/// An I/O error in words, without the "(os error N)" suffix.
pub use pdeshape::open::io_words;

/// The path whose extension picks the output format: `--format` when given (it wins over the
/// extension), else `-o`'s own; `-o -` (standard output) needs `--format`.
pub fn format_path(
    output: &Path,
    format: Option<&str>,
    formats: &str,
) -> Result<PathBuf, CliError> {
    match format {
        Some(f) => {
            let f = f.trim_start_matches('.');
            if f.is_empty() || !f.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(CliError::input(format!(
                    "--format: '{}' is not a format: use {formats}",
                    shorten(f, 40)
                )));
            }
            Ok(PathBuf::from(format!("output.{f}")))
        }
        None if Output::is_stdout(output) => Err(CliError::input(format!(
            "-o -: writing to standard output needs --format ({formats})"
        ))),
        None => Ok(output.to_path_buf()),
    }
}

/// The mesh or sample format of an output: `--format` when given (it wins over the
/// extension), else `-o`'s extension ([`OutputFormat`]); `-o -` (standard output) needs
/// `--format`. Errors name the flag.
pub fn output_format(
    output: &Path,
    format: Option<&str>,
    formats: &str,
) -> Result<pdeshape::mesh::Format, CliError> {
    let (flag, shown, parsed) = match format {
        Some(f) => {
            let name = f.trim_start_matches('.');
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(CliError::input(format!(
                    "--format: '{}' is not a format: use {formats}",
                    shorten(name, 40)
                )));
            }
            ("--format", f.to_string(), name.parse::<OutputFormat>())
        }
        None if Output::is_stdout(output) => {
            return Err(CliError::input(format!(
                "-o -: writing to standard output needs --format ({formats})"
            )))
        }
        None => (
            "-o",
            output.display().to_string(),
            OutputFormat::from_path(output),
        ),
    };
    parsed
        .and_then(OutputFormat::mesh)
        .map_err(|e| CliError::input(format!("{flag} {shown}: {}", message_of(&e))))
}

/// Refuses an output path of `flag` that does not end in `.ext` (any case).
pub fn check_extension(path: &Path, flag: &str, ext: &str) -> Result<(), CliError> {
    if pdeshape::format::has_extension(path, ext) {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "{flag} {}: must end in .{ext}",
            path.display()
        )))
    }
}

/// Refuses a flag that was given for an output it does not apply to.
pub fn refuse_flag(given: bool, flag: &str, output: &str) -> Result<(), CliError> {
    if given {
        return Err(CliError::input(format!(
            "{flag}: does not apply to {output}"
        )));
    }
    Ok(())
}

/// Refuses `--nu`/`--nv` for an output they do not apply to.
pub fn refuse_grid_flags(
    nu: Option<usize>,
    nv: Option<usize>,
    output: &str,
) -> Result<(), CliError> {
    for (flag, v) in [("--nu", nu), ("--nv", nv)] {
        if v.is_some() {
            return Err(CliError::input(format!(
                "{flag}: does not apply to {output} (it has no grid)"
            )));
        }
    }
    Ok(())
}

/// `s` cut to at most `max` characters, with an ellipsis when cut.
pub fn shorten(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        let head: String = s.chars().take(max).collect();
        format!("{head}…")
    }
}

/// Writes to stdout, ignoring a closed pipe (`pdeshape schema | head` is fine).
pub fn print_stdout(text: &str) {
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    let _ = out.flush();
}

/// When the process's `main` started ([`mark_start`]).
static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();

/// Records the start of the process (called first thing in `main`).
pub fn mark_start() {
    START.get_or_init(std::time::Instant::now);
}

/// Milliseconds since [`mark_start`] (since the first call, if it was not called).
pub fn since_start_ms() -> f64 {
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
        * 1e3
}
