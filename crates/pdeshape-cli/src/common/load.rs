//! Loading a design: the file read and parsed, `--set` values applied, errors as
//! `file:line:col: place: message`.

use super::CliError;
use pdeshape::design::{self, SolvedDesign};
use pdeshape::spec::{self, DesignSpec};
use pdeshape::Error;
use std::path::Path;

/// A design file read and parsed.
pub(crate) struct Loaded {
    pub file: String,
    pub text: String,
    pub spec: DesignSpec,
}

impl Loaded {
    /// `file:line:col: place: message` for an error about this file.
    pub(crate) fn error(&self, e: &Error) -> CliError {
        CliError::input(spec::describe_error(&self.file, &self.text, e))
    }

    /// Compiles and solves the design (every kind, with the solver it asks for).
    pub(crate) fn build(&self) -> Result<SolvedDesign, CliError> {
        design::solve_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// Validates the design without solving it.
    pub(crate) fn validate(&self) -> Result<(), CliError> {
        design::validate_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// The grid ([`design::grid`]): the command line's `--nu`/`--nv`, else `[output]`, else
    /// 64 × 128, refused before anything is solved or allocated beyond the grid limits.
    pub(crate) fn grid(
        &self,
        nu: Option<usize>,
        nv: Option<usize>,
    ) -> Result<(usize, usize), CliError> {
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
pub(crate) fn apply_sets(design: &mut Loaded, sets: &[String]) -> Result<(), CliError> {
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
pub(crate) fn message_of(e: &Error) -> String {
    e.message()
}

/// Reads and parses a design file (the library's [`pdeshape::open`]: one size limit, one
/// treatment of directories, FIFOs and symlinks; a timed design at its start time).
pub(crate) fn load(path: &Path) -> Result<Loaded, CliError> {
    let f = pdeshape::open::DesignFile::read(path).map_err(opened)?;
    let spec = f.parse_still().map_err(opened)?;
    Ok(Loaded {
        file: f.file,
        text: f.text,
        spec,
    })
}

/// A file that could not be opened: its one line.
pub(crate) fn opened(e: pdeshape::open::OpenError) -> CliError {
    CliError::input(e.message)
}
