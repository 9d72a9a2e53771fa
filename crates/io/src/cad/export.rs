//! A solved design written as STEP or IGES text: the default tolerance and unit, the
//! approximation and the writer ([`crate::format::write_cad`]), the same for every shell.

use super::{approximate_design, design_size, CadModel};
use crate::design::SolvedDesign;
use crate::format::{write_cad, OutputFormat};
use crate::spec::Units;
use crate::{Error, Result};
use std::fmt::Write;

/// The tolerance used when none is given: `1e-4` of the design's size ([`design_size`]).
pub fn default_tolerance(design: &SolvedDesign) -> f64 {
    1e-4 * design_size(design)
}

/// Refuses a design without surfaces (only a `[dynamic]` curve).
pub(crate) fn require_surfaces(design: &SolvedDesign) -> Result<()> {
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
    /// The design's size ([`design_size`]), the scale of the relative tolerance.
    pub size: f64,
}

impl CadExport {
    /// What `pdeshape surface` prints after `wrote FILE: `: the number of surfaces, the
    /// tolerance (absolute and relative to the design's size) and the unit; then per surface
    /// its control points and deviation with its certificate, and per hole of a trimmed
    /// surface its edge's size and deviations.
    pub fn report(&self) -> String {
        let mut report = format!(
            "{} B-spline surface(s), tolerance {:.3e} ({:.1e} of the design size {:.4}), unit {}\n",
            self.model.surfaces.len(),
            self.tolerance,
            self.tolerance / self.size,
            self.size,
            self.unit.as_str()
        );
        for s in &self.model.surfaces {
            let [nu, nv] = s.approx.net.counts();
            let _ = writeln!(
                report,
                "  {}: {nu} × {nv} control points, deviation {} {:.3e} ({}{})",
                s.name,
                s.approx.certificate.relation(),
                s.approx.deviation,
                s.approx.certificate.word(),
                s.approx
                    .note
                    .as_ref()
                    .map(|n| format!(": {n}"))
                    .unwrap_or_default()
            );
            for h in &s.holes {
                let _ = writeln!(
                    report,
                    "    hole {}: edge of {} control points, {:.3e} from the face ({}), {:.3e} from the trim curve's image ({})",
                    h.curve,
                    h.edge.points.len(),
                    h.edge_deviation,
                    if h.edge_certified { "certified" } else { "sampled" },
                    h.deviation,
                    if h.certified { "≤" } else { "≈" }
                );
            }
        }
        report
    }
}

/// Where [`export_design`] failed, so that each shell can name its own argument.
#[derive(Debug)]
pub enum CadExportError {
    /// The design is to blame: it has no surface, or a surface at the error's place could not
    /// be approximated.
    Design(Error),
    /// The tolerance is to blame: not a positive number, or too small for the net sizes
    /// allowed. Shells print the message after their own name of the tolerance argument.
    Tolerance(Error),
    /// The writer refused the model (or `format` is not a CAD format).
    Write(Error),
}

/// The design's surfaces as STEP or IGES text: `tolerance` (default [`default_tolerance`]) and
/// `unit` (default the design's `units`), approximated by [`approximate_design`] and written by
/// [`write_cad`] with the date of `unix_seconds` (see [`crate::format::export_timestamp`]).
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
    let size = design_size(design);
    // `default_tolerance`, from the size computed once.
    let tolerance = tolerance.unwrap_or(1e-4 * size);
    let model = approximate_design(design, tolerance).map_err(|e| {
        if e.place().is_empty() || e.place() == "tolerance" {
            CadExportError::Tolerance(e)
        } else {
            CadExportError::Design(e)
        }
    })?;
    let text =
        write_cad(&model, format, unit, file_name, unix_seconds).map_err(CadExportError::Write)?;
    Ok(CadExport {
        model,
        text,
        tolerance,
        unit,
        size,
    })
}
