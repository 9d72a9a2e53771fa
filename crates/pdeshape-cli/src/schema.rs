//! `pdeshape schema [--kind design|morph|template]`: the JSON schema of a file the tool reads.

use crate::common::CliError;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// Which file's schema: a design file (default), a morph file (`[morph]` between two
    /// designs) or a `fit --template` file.
    #[arg(long, value_enum, default_value = "design")]
    pub kind: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Kind {
    Design,
    Morph,
    Template,
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let text = match args.kind {
        Kind::Design => pdeshape::spec::json_schema(),
        Kind::Morph => pdeshape::spec::morph_json_schema(),
        Kind::Template => serde_json::to_string_pretty(&pdeshape::fit::template_schema())
            .map_err(|e| CliError::input(format!("--kind template: {e}")))?,
    };
    crate::common::print_stdout(&format!("{text}\n"));
    Ok(())
}
