//! What the subcommands share: loading a design with located errors, choosing the grid, and
//! writing an output file atomically.

/// An I/O error in words, without the "(os error N)" suffix.
pub(crate) use pdeshape::open::io_words;

mod commit;
mod flags;
mod load;
mod output;
mod report;
mod temp;
pub(crate) use commit::{abandon_outputs, end_run, finish_outputs};
pub(crate) use flags::{
    check_extension, format_request, output_format, refuse_flag, refuse_grid_flags, FormatRequest,
};
pub(crate) use load::{apply_sets, load, message_of, opened, Loaded};
pub(crate) use output::{destination, same_file, Output, Refusal};
pub(crate) use report::{mark_start, note, print_stdout, quiet, report, set_flags, since_start_ms};
pub(crate) use temp::remove_temporaries_on_signals;

/// A failure: one line for stderr and the exit status.
#[derive(Debug)]
pub(crate) struct CliError {
    pub message: String,
    pub status: u8,
}

impl CliError {
    /// Bad input (design, arguments, output path): exit status 2.
    pub(crate) fn input(message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            status: 2,
        }
    }
}

/// `s` cut to at most `max` characters, with an ellipsis when cut.
pub(crate) fn shorten(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        let head: String = s.chars().take(max).collect();
        format!("{head}…")
    }
}
