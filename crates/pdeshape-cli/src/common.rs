//! What the subcommands share: loading a design with located errors, choosing the grid, and
//! writing an output file atomically.

use pdeshape::design::{self, SolvedDesign};
use pdeshape::spec::{self, DesignSpec};
use pdeshape::Error;
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// The message of an error without its place.
pub fn message_of(e: &Error) -> String {
    match e {
        Error::Invalid { message, .. } | Error::Io { message, .. } => message.clone(),
        Error::NotUnique { .. } => {
            let s = e.to_string();
            let p = e.place();
            s.strip_prefix(&format!("{p}: ")).unwrap_or(&s).to_string()
        }
    }
}

/// Reads and parses a design file.
pub fn load(path: &Path) -> Result<Loaded, CliError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::input(format!("{file}: cannot read the design file: {e}")))?;
    let spec = spec::parse_design(&text)
        .map_err(|e| CliError::input(spec::describe_error(&file, &text, &e)))?;
    Ok(Loaded { file, text, spec })
}

/// An output file being written: a temporary file next to the target, renamed over it only when
/// everything succeeded. Dropped without [`Output::commit`], it leaves nothing behind.
pub struct Output {
    path: PathBuf,
    temp: tempfile::NamedTempFile,
}

impl Output {
    /// Creates the temporary file in the target's directory (so the final rename is atomic).
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let shown = path.display();
        if path.is_dir() {
            return Err(CliError::input(format!("-o {shown}: is a directory")));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let temp = tempfile::Builder::new()
            .prefix(".pdeshape-")
            .suffix(".tmp")
            .tempfile_in(&dir)
            .map_err(|e| {
                CliError::input(format!(
                    "-o {shown}: cannot create a file in '{}': {e}",
                    dir.display()
                ))
            })?;
        Ok(Output {
            path: path.to_path_buf(),
            temp,
        })
    }

    /// A buffered writer on the temporary file.
    pub fn writer(&mut self) -> std::io::BufWriter<&mut std::fs::File> {
        std::io::BufWriter::new(self.temp.as_file_mut())
    }

    /// Writes `bytes` to the temporary file.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let shown = self.path.display().to_string();
        self.temp
            .as_file_mut()
            .write_all(bytes)
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))
    }

    /// Flushes and renames the temporary file onto the target.
    pub fn commit(self) -> Result<(), CliError> {
        let shown = self.path.display().to_string();
        // Temporary files are private (0600); the result gets the usual permissions of a new
        // file (rw-r--r--).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            self.temp
                .as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        }
        self.temp
            .as_file()
            .sync_all()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        self.temp
            .persist(&self.path)
            .map_err(|e| CliError::input(format!("-o {shown}: {}", e.error)))?;
        Ok(())
    }
}

/// Writes to stdout, ignoring a closed pipe (`pdeshape schema | head` is fine).
pub fn print_stdout(text: &str) {
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    let _ = out.flush();
}
