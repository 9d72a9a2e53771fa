//! The output's format (`--format` or the extension) and the refusal of flags that do not apply
//! to an output (`--nu`/`--nv` without a grid, …).

use super::load::message_of;
use super::output::Output;
use super::{shorten, CliError};
use pdeshape::format::OutputFormat;
use std::path::{Path, PathBuf};

/// The format an output asks for: the name `--format` gives (it wins over the extension), else
/// `-o`'s extension; with the flag and the value that messages about it name.
pub(crate) struct FormatRequest {
    /// `--format` or `-o`.
    pub flag: &'static str,
    /// The flag's value as given.
    pub shown: String,
    /// The format's name (without a dot), or `None` when `-o` has no extension.
    pub name: Option<String>,
    /// `-o`'s path (for the library's refusal of a path without an extension).
    output: PathBuf,
}

impl FormatRequest {
    /// The library's [`OutputFormat`] of the request: `--format`'s name parsed
    /// ([`str::parse`]), else [`OutputFormat::from_path`] of `-o`.
    pub(crate) fn output_format(&self) -> pdeshape::Result<OutputFormat> {
        match (self.flag, &self.name) {
            ("--format", Some(name)) => name.parse(),
            _ => OutputFormat::from_path(&self.output),
        }
    }

    /// Whether the request names `name` (any case): for the formats of one command, such as
    /// the `json` control nets of `spline` and `blend`.
    pub(crate) fn names(&self, name: &str) -> bool {
        self.name
            .as_deref()
            .is_some_and(|n| n.eq_ignore_ascii_case(name))
    }
}

/// The format an output asks for ([`FormatRequest`]); `--format` must be a name (letters and
/// digits, a leading dot allowed), and `-o -` (standard output) needs `--format`. `formats`
/// lists the command's formats for the messages.
pub(crate) fn format_request(
    output: &Path,
    format: Option<&str>,
    formats: &str,
) -> Result<FormatRequest, CliError> {
    match format {
        Some(f) => {
            let name = f.trim_start_matches('.');
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(CliError::input(format!(
                    "--format: '{}' is not a format: use {formats}",
                    shorten(name, 40)
                )));
            }
            Ok(FormatRequest {
                flag: "--format",
                shown: f.to_string(),
                name: Some(name.to_string()),
                output: output.to_path_buf(),
            })
        }
        None if Output::is_stdout(output) => Err(CliError::input(format!(
            "-o -: writing to standard output needs --format ({formats})"
        ))),
        None => Ok(FormatRequest {
            flag: "-o",
            shown: output.display().to_string(),
            name: output.extension().map(|e| e.to_string_lossy().into_owned()),
            output: output.to_path_buf(),
        }),
    }
}

/// The mesh or sample format of an output: `--format` when given (it wins over the
/// extension), else `-o`'s extension ([`OutputFormat`]); `-o -` (standard output) needs
/// `--format`. Errors name the flag.
pub(crate) fn output_format(
    output: &Path,
    format: Option<&str>,
    formats: &str,
) -> Result<pdeshape::mesh::Format, CliError> {
    let request = format_request(output, format, formats)?;
    request
        .output_format()
        .and_then(OutputFormat::mesh)
        .map_err(|e| {
            CliError::input(format!(
                "{} {}: {}",
                request.flag,
                request.shown,
                message_of(&e)
            ))
        })
}

/// Refuses an output path of `flag` that does not end in `.ext` (any case).
pub(crate) fn check_extension(path: &Path, flag: &str, ext: &str) -> Result<(), CliError> {
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
pub(crate) fn refuse_flag(given: bool, flag: &str, output: &str) -> Result<(), CliError> {
    if given {
        return Err(CliError::input(format!(
            "{flag}: does not apply to {output}"
        )));
    }
    Ok(())
}

/// Refuses `--nu`/`--nv` for an output they do not apply to.
pub(crate) fn refuse_grid_flags(
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
