//! A solved design written as STEP or IGES text: the default tolerance and unit, the
//! approximation and the writer ([`crate::format::write_cad`]), the same for every shell.

use super::{approximate_design, design_size, CadModel};
use crate::design::SolvedDesign;
use crate::format::{write_cad, OutputFormat};
use crate::spec::Units;
use crate::{Error, Result};

/// The tolerance used when none is given: `1e-4` of the design's size ([`design_size`]).
pub fn default_tolerance(design: &SolvedDesign) -> f64 {
    1e-4 * design_size(design)
}

/// Refuses a design without surfaces (only a `[dynamic]` curve).
pub fn require_surfaces(design: &SolvedDesign) -> Result<()> {
    if design.surfaces.is_empty() {
        return Err(Error::no_surface());
    }
    Ok(())
}

/// What [`export_design`] made: the model, its text, and the tolerance and unit used.
pub struct CadExport {
    /// The design in CAD form: every surface's net, deviation and certificate.
    pub model: CadModel,
    /// The STEP or IGES file.
    pub text: String,
    /// The tolerance used (absolute, design units): the one given or [`default_tolerance`].
    pub tolerance: f64,
    /// The length unit the file declares: the one given or the design's.
    pub unit: Units,
}

/// Where [`export_design`] failed, so that each shell can name its own argument.
#[derive(Debug)]
pub enum CadExportError {
    /// The design has no surface (a design error).
    Design(Error),
    /// The approximation failed: with an empty place or `tolerance`, the tolerance is to blame
    /// (too small for the net sizes allowed); otherwise the design at that place.
    Approximation(Error),
    /// The writer refused the model (or `format` is not a CAD format).
    Write(Error),
}

/// The design's surfaces as STEP or IGES text: `tolerance` (default [`default_tolerance`]) and
/// `unit` (default the design's `units`), approximated by [`approximate_design`] and written by
/// [`write_cad`] with the date of `unix_seconds`.
pub fn export_design(
    design: &SolvedDesign,
    format: OutputFormat,
    tolerance: Option<f64>,
    unit: Option<Units>,
    file_name: &str,
    unix_seconds: u64,
) -> std::result::Result<CadExport, CadExportError> {
    require_surfaces(design).map_err(CadExportError::Design)?;
    let unit = unit.unwrap_or(design.units);
    let tolerance = tolerance.unwrap_or_else(|| default_tolerance(design));
    let model = approximate_design(design, tolerance).map_err(CadExportError::Approximation)?;
    let text =
        write_cad(&model, format, unit, file_name, unix_seconds).map_err(CadExportError::Write)?;
    Ok(CadExport {
        model,
        text,
        tolerance,
        unit,
    })
}
