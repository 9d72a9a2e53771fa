//! The output's format (`--format` or the extension) and the refusal of flags that do not apply
//! to an output (`--nu`/`--nv` without a grid, …).

use super::load::message_of;
use super::output::Output;
use super::{shorten, CliError};
use pdeshape::format::OutputFormat;
use std::path::{Path, PathBuf};

/// The path whose extension picks the output format: `--format` when given (it wins over the
/// extension), else `-o`'s own; `-o -` (standard output) needs `--format`.
pub(crate) fn format_path(
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
pub(crate) fn output_format(
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
