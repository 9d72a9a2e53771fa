//! A solved design written as STEP or IGES text: the format by name, the default tolerance and
//! unit, the approximation and the writer, the same for every shell.

use super::{approximate_design, design_size, step, to_iges, CadModel};
use crate::design::SolvedDesign;
use crate::{Error, Result};
use std::path::Path;

/// The CAD formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CadFormat {
    Step,
    Iges,
}

impl CadFormat {
    /// `step`/`stp` or `igs`/`iges` (any case); `None` for anything else.
    pub fn from_name(name: &str) -> Option<CadFormat> {
        match name.to_ascii_lowercase().as_str() {
            "step" | "stp" => Some(CadFormat::Step),
            "igs" | "iges" => Some(CadFormat::Iges),
            _ => None,
        }
    }

    /// The format of a path's extension ([`CadFormat::from_name`]).
    pub fn from_path(path: &Path) -> Option<CadFormat> {
        CadFormat::from_name(path.extension()?.to_str()?)
    }
}

/// The tolerance used when none is given: `1e-4` of the design's size ([`design_size`]).
pub fn default_tolerance(design: &SolvedDesign) -> f64 {
    1e-4 * design_size(design)
}

/// The length unit of the design's `units` (errors placed at `units`).
pub fn design_unit(design: &SolvedDesign) -> Result<step::LengthUnit> {
    step::LengthUnit::parse(design.units.as_str()).map_err(|e| e.at("units"))
}

/// Refuses a design without surfaces (only a `[dynamic]` curve).
pub fn require_surfaces(design: &SolvedDesign) -> Result<()> {
    if design.surfaces.is_empty() {
        return Err(Error::invalid(
            "the design has no surface (only a [dynamic] curve: `pdeshape curve` runs it)",
        ));
    }
    Ok(())
}

/// The text of `model` in `format`: STEP AP214 or IGES 5.3, in `unit`, with `file_name` and
/// the date of `unix_seconds` in the header.
pub fn model_text(
    model: &CadModel,
    format: CadFormat,
    unit: step::LengthUnit,
    file_name: &str,
    unix_seconds: u64,
) -> Result<String> {
    match format {
        CadFormat::Step => step::to_step(
            model,
            &step::StepOptions {
                unit,
                file_name: file_name.to_string(),
                timestamp: step::step_timestamp(unix_seconds),
            },
        ),
        CadFormat::Iges => to_iges(model, unit, file_name, unix_seconds),
    }
}

/// What [`export_design`] made: the model, its text, and the tolerance and unit used.
pub struct CadExport {
    pub model: CadModel,
    pub text: String,
    pub tolerance: f64,
    pub unit: step::LengthUnit,
}

/// Where [`export_design`] failed, so that each shell can name its own argument.
#[derive(Debug)]
pub enum CadExportError {
    /// The design has no surface, or its `units` are not a length unit (a design error).
    Design(Error),
    /// The approximation failed: with an empty place or `tolerance`, the tolerance is to blame
    /// (too small for the net sizes allowed); otherwise the design at that place.
    Approximation(Error),
    /// The writer refused the model.
    Write(Error),
}

/// The design's surfaces as STEP or IGES text: `tolerance` (default [`default_tolerance`]) and
/// `unit` (default the design's `units`), approximated by [`approximate_design`] and written by
/// [`model_text`].
pub fn export_design(
    design: &SolvedDesign,
    format: CadFormat,
    tolerance: Option<f64>,
    unit: Option<step::LengthUnit>,
    file_name: &str,
    unix_seconds: u64,
) -> std::result::Result<CadExport, CadExportError> {
    require_surfaces(design).map_err(CadExportError::Design)?;
    let unit = match unit {
        Some(u) => u,
        None => design_unit(design).map_err(CadExportError::Design)?,
    };
    let tolerance = tolerance.unwrap_or_else(|| default_tolerance(design));
    let model = approximate_design(design, tolerance).map_err(CadExportError::Approximation)?;
    let text =
        model_text(&model, format, unit, file_name, unix_seconds).map_err(CadExportError::Write)?;
    Ok(CadExport {
        model,
        text,
        tolerance,
        unit,
    })
}
