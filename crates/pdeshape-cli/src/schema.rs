//! `pdeshape schema`: the JSON schema of the design file.

use crate::common::CliError;

pub(crate) fn run() -> Result<(), CliError> {
    crate::common::print_stdout(&format!("{}\n", pdeshape::spec::json_schema()));
    Ok(())
}
