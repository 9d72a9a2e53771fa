//! `pdeshape surface DESIGN -o part.step|part.igs [--tolerance T] [--units U]`: every surface
//! as a B-spline with its deviation; `pdeshape roundtrip DESIGN FILE`: read a written STEP or
//! IGES file back and measure it against the design.

use crate::common::{self, CliError, Output};
use pdeshape::cad::{self, read};
use pdeshape::format::{export_timestamp, OutputFormat};
use pdeshape::spec::Units;
use std::path::{Path, PathBuf};

/// Writes the design's surfaces as STEP or IGES ([`cad::export_design`]) and prints its report.
pub(crate) fn write(
    design_path: &Path,
    output: &Path,
    format: OutputFormat,
    tolerance: Option<f64>,
    units: Option<&str>,
) -> Result<(), CliError> {
    let unit = units
        .map(|u| {
            u.parse::<Units>()
                .map_err(|e| CliError::input(format!("--units: {}", common::message_of(&e))))
        })
        .transpose()?;
    if let Some(t) = tolerance {
        if !(t.is_finite() && t > 0.0) {
            return Err(CliError::input(format!(
                "--tolerance: must be a positive number (got {t})"
            )));
        }
    }
    let design = common::load(design_path)?;
    design.validate()?;
    let mut out = Output::create(output)?;
    let solved = design.build()?;
    let shown = output.display().to_string();
    let file_name = output
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let export = cad::export_design(
        &solved,
        format,
        tolerance,
        unit,
        &file_name,
        export_timestamp(),
    )
    .map_err(|e| match e {
        cad::CadExportError::Design(e) => design.error(&e),
        cad::CadExportError::Tolerance(e) => {
            CliError::input(format!("--tolerance: {}", common::message_of(&e)))
        }
        cad::CadExportError::Write(e) => CliError::input(format!("-o {shown}: {e}")),
    })?;
    out.write_all(export.text.as_bytes())?;
    out.commit()?;
    let dest = common::destination(output);
    common::report(&format!("wrote {dest}: {}", export.report()));
    Ok(())
}

#[derive(clap::Args, Debug)]
pub(crate) struct RoundtripArgs {
    /// The design file (TOML).
    pub design: PathBuf,
    /// A STEP (.step, .stp) or IGES (.igs, .iges) file written by `pdeshape surface`.
    pub file: PathBuf,
    /// The largest deviation allowed (default: the certified deviation of each surface at the
    /// tolerance of the file is not known here, so the default is 10⁻⁴ of the design size,
    /// the default of `pdeshape surface`).
    #[arg(long)]
    pub tolerance: Option<f64>,
}

/// A STEP or IGES file's text, read under the library's size limit.
pub(crate) fn read_text(path: &Path) -> Result<String, CliError> {
    let shown = path.display().to_string();
    let bytes = pdeshape::open::read_held(path)
        .map_err(|e| CliError::input(format!("{shown}: {}", e.words())))?;
    String::from_utf8(bytes).map_err(|e| {
        CliError::input(format!(
            "{shown}: not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Reads the file back and compares each surface with the design's (status 1 if any deviates by
/// more than the tolerance).
pub(crate) fn roundtrip(args: &RoundtripArgs) -> Result<(), CliError> {
    if let Some(t) = args.tolerance {
        if !(t.is_finite() && t > 0.0) {
            return Err(CliError::input(format!(
                "--tolerance: must be a positive number (got {t})"
            )));
        }
    }
    let shown = args.file.display().to_string();
    let format = OutputFormat::from_path(&args.file)
        .ok()
        .filter(|f| f.is_cad())
        .ok_or_else(|| {
            CliError::input(format!(
                "{shown}: not a STEP or IGES file name (.step, .stp, .igs, .iges)"
            ))
        })?;
    let text = read_text(&args.file)?;
    let read = match format {
        OutputFormat::Step => read::read_step(&text),
        _ => read::read_iges(&text),
    }
    .map_err(|e| CliError::input(format!("{shown}: {}", common::message_of(&e))))?;
    let design = common::load(&args.design)?;
    let solved = design.build()?;
    if read.len() != solved.surfaces.len() {
        return Err(CliError::input(format!(
            "{shown}: {} surfaces, the design has {}",
            read.len(),
            solved.surfaces.len()
        )));
    }
    let tolerance = args
        .tolerance
        .unwrap_or_else(|| cad::default_tolerance(&solved));
    let mut report = String::new();
    let mut worst = 0.0f64;
    for (r, s) in read.iter().zip(&solved.surfaces) {
        let surface = s.kind.surface();
        if !read::same_domain(surface, &r.net) {
            return Err(CliError::input(format!(
                "{shown}: surface `{}` has a parameter domain other than `{}`'s",
                r.name, s.name
            )));
        }
        let d = read::read_back_deviation(surface, &r.net, 9);
        worst = worst.max(d);
        let [nu, nv] = r.net.counts();
        report.push_str(&format!(
            "  {}: {nu} × {nv} control points, deviation {d:.3e} on a 9 × 9 lattice per knot cell\n",
            s.name
        ));
    }
    let verdict = if worst <= tolerance { "ok" } else { "FAILED" };
    common::print_stdout(&format!(
        "{shown}: {} surface(s) read back, largest deviation {worst:.3e} (tolerance {tolerance:.3e}): {verdict}\n{report}",
        read.len()
    ));
    if worst <= tolerance {
        Ok(())
    } else {
        Err(CliError {
            message: format!(
                "{shown}: read-back deviation {worst:.3e} exceeds the tolerance {tolerance:.3e}"
            ),
            status: 1,
        })
    }
}
