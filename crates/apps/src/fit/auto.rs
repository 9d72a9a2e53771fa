//! The tolerance a fit is held to, and the choice of mode with its fallback: what `pdeshape
//! fit` and Python's `fit` both ask for.
//!
//! A fit is accepted when its two-sided Hausdorff distance to the mesh is within the
//! tolerance ([`DEFAULT_TOLERANCE`] of the diagonal unless one is given). The fast modes (tube,
//! sheet, template) refine their sections towards a finer target ([`FAST_TARGET`], or the
//! tolerance when one is given). In the automatic choice, a mesh the fast modes refuse (not a
//! tube, not a sheet: a torus, a mug, a body with limbs) or fit beyond the tolerance is fitted
//! by the general mode ([`super::fit_general`]) instead, and why is kept to be said. A forced
//! mode or a template is measured and returned as it is, so the caller decides what a miss
//! means ([`Fitted::missed`]).

use super::frame::FileFrame;
use super::layout::{fit_general_measured, MEASURE_GRID};
use super::measure::{measure, Measures, MeshSamples, PointDistances};
use super::mesh::InputMesh;
use super::options::{fit_mesh, Fit, FitMode, FitOptions};
use super::template::{fit_template, Template};
use crate::design::solve_design;
use crate::number::sig;
use crate::spec::{DesignSpec, Units};
use crate::{Error, Result, Vec3};

/// The two-sided Hausdorff distance, as a fraction of the mesh's bounding-box diagonal, a fit
/// must meet when no tolerance is given.
pub const DEFAULT_TOLERANCE: f64 = 2e-2;

/// The sample error the tube and sheet modes refine their sections to when no tolerance is
/// given (a tenth of [`DEFAULT_TOLERANCE`]: their patches between sections add to it).
pub const FAST_TARGET: f64 = 2e-3;

/// The samples per patch (`u × v`) at which the fast modes' fits are measured.
const FAST_GRID: (usize, usize) = (48, 96);

/// Which mode fits a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeChoice {
    /// Tube or sheet as the mesh's shape says, the general mode where they refuse it or miss.
    Auto,
    /// The tube mode only.
    Tube,
    /// The sheet mode only.
    Sheet,
    /// The general mode only.
    General,
}

impl ModeChoice {
    /// The names a user gives, in the order of [`ModeChoice::parse`].
    pub const NAMES: [&'static str; 4] = ["auto", "tube", "sheet", "general"];

    /// The choice named `name`, or an error listing the names.
    pub fn parse(name: &str) -> Result<ModeChoice> {
        match name {
            "auto" => Ok(ModeChoice::Auto),
            "tube" => Ok(ModeChoice::Tube),
            "sheet" => Ok(ModeChoice::Sheet),
            "general" => Ok(ModeChoice::General),
            other => Err(Error::invalid(format!(
                "'{other}' is not a mode (one of {})",
                ModeChoice::NAMES.join(", ")
            ))
            .at("mode")),
        }
    }
}

/// What is asked of a fit.
#[derive(Clone, Copy, Debug)]
pub struct Request<'a> {
    /// The mode (ignored when a template is given: the template names its parts' modes).
    pub mode: ModeChoice,
    /// A template of parts, instead of an automatic mode.
    pub template: Option<&'a Template>,
    /// The tolerance (a fraction of the diagonal, in `(0, 1)`); [`DEFAULT_TOLERANCE`] when
    /// `None`.
    pub tolerance: Option<f64>,
    /// A fixed number of patches (tube and sheet) or of first-round layout vertices
    /// (general), instead of the adaptive choice.
    pub patches: Option<usize>,
    /// The length unit of the mesh's coordinates when its file states one
    /// ([`MeshRead::units`](super::MeshRead::units)): the fitted design's `units`.
    pub units: Option<Units>,
    /// The frame of the mesh's file ([`MeshRead::file`](super::MeshRead::file)): points in
    /// messages are named in its coordinates.
    pub file: FileFrame,
}

impl Default for Request<'_> {
    fn default() -> Self {
        Request {
            mode: ModeChoice::Auto,
            template: None,
            tolerance: None,
            patches: None,
            units: None,
            file: FileFrame::default(),
        }
    }
}

/// A fit with its measures.
#[derive(Clone, Debug)]
pub struct Fitted {
    /// The fit.
    pub fit: Fit,
    /// Its distances to the mesh and sizes.
    pub measures: Measures,
    /// The per-point distances (for pictures).
    pub distances: PointDistances,
    /// The point, in the mesh's (design) coordinates, farthest from the other surface.
    pub worst: Vec3,
    /// The frame of the mesh's file: [`Fitted::miss`] and [`Fitted::report`] name `worst` in
    /// its coordinates.
    pub file: FileFrame,
    /// The tolerance the fit is held to (a fraction of the diagonal).
    pub tolerance: f64,
    /// The target the fit was refined to: the sections' for tube, sheet and template fits,
    /// the tolerance for the general mode.
    pub target: f64,
    /// Why the automatic choice fell back to the general mode, when it did.
    pub fallback: Option<String>,
    /// Why the automatic choice kept the fast mode's fit after all, when it fell back because
    /// that fit missed the tolerance and the general mode then refused the mesh or did no
    /// better (the fit returned is then the fast mode's, and it misses).
    pub declined: Option<String>,
}

impl Fitted {
    /// True when the fit is farther from the mesh than the tolerance (or its distance is not
    /// a number).
    pub fn missed(&self) -> bool {
        self.measures.hausdorff_relative.is_nan()
            || self.measures.hausdorff_relative > self.tolerance
    }

    /// The fit's design file, titled after the mesh's file name (`fitted to FILE_NAME`), with
    /// the measures' TOML size made that file's (the fit sized its design untitled).
    pub fn design_file(&mut self, file_name: &str) -> Result<String> {
        let mut spec = self.fit.spec.clone();
        spec.title = Some(format!("fitted to {file_name}"));
        let text = crate::spec::write_design(&spec)?;
        self.measures = self.measures.clone().with_toml_bytes(text.len());
        Ok(text)
    }

    /// How the fit misses its tolerance, with the farthest point in the coordinates of the
    /// mesh's file (`None` when it does not); the caller adds what to do about it in its own
    /// words.
    pub fn miss(&self) -> Option<String> {
        let m = &self.measures;
        self.missed().then(|| {
            format!(
                "the fit misses the tolerance {}% of the diagonal: the Hausdorff distance is {} \
                 ({}% of the diagonal) at {}",
                sig(100.0 * self.tolerance, 4),
                sig(m.hausdorff, 6),
                sig(100.0 * m.hausdorff_relative, 4),
                self.worst_shown()
            )
        })
    }

    /// The farthest point, `(x, y, z)` in the coordinates of the mesh's file.
    pub fn worst_shown(&self) -> String {
        self.file.point(self.worst)
    }

    /// The report of `pdeshape fit --json` (and of Python's `fit_mesh`): the mesh's name as
    /// the caller shows it, the fit's mode and sizes, the tolerance and whether it is missed,
    /// why the automatic choice fell back or declined, the measures (distances in `units`, the
    /// mesh's own when its file states none: `null`), and the notes: `input_notes` (what the
    /// reader and the repairs did, [`MeshRead::repaired`](super::MeshRead::repaired)) and the
    /// fit's own.
    pub fn report(&self, mesh: &str, input_notes: &[String]) -> serde_json::Value {
        let f = &self.fit;
        let worst = self.file.to_file(self.worst);
        serde_json::json!({
            "mesh": mesh,
            "mode": f.mode,
            "a": f.a,
            "patches": f.patches,
            "modes": f.modes,
            "sections": f.sections,
            "sections_dropped": f.dropped,
            "sample_error_relative": f.sample_error,
            // The target the fit was refined to (the sections' for tube and sheet).
            "tolerance": self.target,
            "accept_tolerance": self.tolerance,
            "missed": self.missed(),
            "fallback": self.fallback,
            "general_declined": self.declined,
            "units": f.spec.units.map(Units::as_str),
            "measures": self.measures,
            // In the file's coordinates, as the messages name it.
            "worst": [worst.x, worst.y, worst.z],
            "notes": input_notes.iter().chain(&f.notes).collect::<Vec<_>>(),
        })
    }
}

/// Measures `spec` against `mesh` on the samples `fitted` is measured with (a variant of the
/// fit's design, such as its packed form): its mode's grids, the mesh's samples for its
/// tolerance.
pub fn measure_like(
    mesh: &InputMesh,
    fitted: &Fitted,
    spec: &DesignSpec,
) -> Result<(Measures, PointDistances)> {
    let grid = match fitted.fit.mode {
        FitMode::General => (MEASURE_GRID, MEASURE_GRID),
        _ => FAST_GRID,
    };
    let solved = solve_design(spec)
        .map_err(|e| Error::invalid(format!("the design does not solve: {}", e.message())))?;
    let samples = MeshSamples::for_tolerance(mesh, fitted.tolerance);
    measure(mesh, spec, &solved, grid, &samples)
}

/// Fits `mesh` as `request` asks (module documentation) and measures the fit. Errors are the
/// modes' own (a template's are placed at its `parts`); when the automatic choice fell back to
/// the general mode and that mode refuses the mesh too, the error says why the fast mode was
/// left.
pub fn fit_measured(mesh: &InputMesh, request: &Request) -> Result<Fitted> {
    let mut fitted = fit_chosen(mesh, request)?;
    fitted.file = request.file;
    if let Some(units) = request.units {
        fitted.fit.spec.units = Some(units);
    }
    Ok(fitted)
}

/// [`fit_measured`] but for the units.
fn fit_chosen(mesh: &InputMesh, request: &Request) -> Result<Fitted> {
    if let Some(t) = request.tolerance {
        if !(t > 0.0 && t < 1.0) {
            return Err(Error::invalid(format!(
                "{t}: must be a number between 0 and 1 (a fraction of the diagonal)"
            ))
            .at("tolerance"));
        }
    }
    let tolerance = request.tolerance.unwrap_or(DEFAULT_TOLERANCE);
    let opts = FitOptions {
        target: request.tolerance.unwrap_or(FAST_TARGET),
        patches: request.patches,
        file: request.file,
        ..FitOptions::default()
    };
    let mut fallback: Option<String> = None;
    let fast = match (request.template, request.mode) {
        (Some(t), _) => Some(fit_template(mesh, t, &opts)?),
        (None, ModeChoice::Tube) => Some(super::fit_tube(mesh, &opts)?),
        (None, ModeChoice::Sheet) => Some(super::fit_sheet(mesh, &opts)?),
        (None, ModeChoice::General) => None,
        (None, ModeChoice::Auto) => match fit_mesh(mesh, &opts) {
            Ok(f) => Some(f),
            Err(e) if matches!(e.place(), "tolerance" | "sections") => return Err(e),
            Err(e) => {
                fallback = Some(e.message());
                None
            }
        },
    };
    // The fast mode's fit when it missed: kept if the general mode refuses the mesh or does
    // no better.
    let mut missed_fast: Option<Fitted> = None;
    // The fast mode's fit when it met the tolerance in more bytes than the mesh has: kept
    // unless the general mode meets it in fewer.
    let mut larger_fast: Option<Fitted> = None;
    if let Some(fit) = fast {
        let solved = solve_design(&fit.spec).map_err(|e| {
            Error::invalid(format!("the fitted design does not solve: {}", e.message()))
        })?;
        let auto = request.mode == ModeChoice::Auto && request.template.is_none();
        // In the automatic choice a fast fit is first measured at its grid and the mesh's
        // vertices: those are points of the two surfaces, so a distance past the tolerance
        // there is a miss already, and the general mode takes over without the dense measure
        // (a tube fitted to a tetrahedron, hundreds of diagonals off, took seconds to
        // measure densely).
        let coarse = if auto {
            let none = MeshSamples::default();
            Some(measure(mesh, &fit.spec, &solved, FAST_GRID, &none)?)
        } else {
            None
        };
        let (measures, distances) = match coarse {
            Some((m, d)) if m.hausdorff_relative.is_nan() || m.hausdorff_relative > tolerance => {
                (m, d)
            }
            _ => {
                let samples = MeshSamples::for_tolerance(mesh, tolerance);
                measure(mesh, &fit.spec, &solved, FAST_GRID, &samples)?
            }
        };
        let (worst, _) = distances.worst(mesh);
        let fitted = Fitted {
            fit,
            measures,
            distances,
            worst,
            file: request.file,
            tolerance,
            target: opts.target,
            fallback: None,
            declined: None,
        };
        if auto && fitted.missed() {
            fallback = Some(format!(
                "the {} mode misses the tolerance ({}% of the diagonal)",
                fitted.fit.mode.name(),
                sig(100.0 * fitted.measures.hausdorff_relative, 4)
            ));
            missed_fast = Some(fitted);
        } else if auto && fitted.measures.design_bytes > fitted.measures.mesh_bytes {
            larger_fast = Some(fitted);
        } else {
            return Ok(fitted);
        }
    }
    let general = FitOptions {
        target: tolerance,
        ..opts
    };
    let attempt = fit_general_measured(mesh, &general);
    // A fast fit within the tolerance but larger than the mesh (a cube as a tube of 30
    // patches, 87 kB for 240 bytes): the general mode's fit takes its place when it is within
    // the tolerance too, in fewer bytes.
    if let Some(f) = larger_fast {
        return Ok(match attempt {
            Ok((fit, measures, distances, _))
                if measures.hausdorff_relative <= tolerance
                    && measures.design_bytes < f.measures.design_bytes =>
            {
                let (worst, _) = distances.worst(mesh);
                Fitted {
                    fallback: Some(format!(
                        "the {} mode's design ({} bytes) is larger than the mesh ({} bytes), the \
                         general mode's within the tolerance in {} bytes",
                        f.fit.mode.name(),
                        f.measures.design_bytes,
                        f.measures.mesh_bytes,
                        measures.design_bytes
                    )),
                    fit,
                    measures,
                    distances,
                    worst,
                    target: tolerance,
                    ..f
                }
            }
            _ => f,
        });
    }
    let (fit, measures, distances) = match (attempt, missed_fast) {
        (Ok((fit, measures, distances, _)), fast) => match fast {
            Some(mut f)
                if measures
                    .hausdorff_relative
                    .partial_cmp(&f.measures.hausdorff_relative)
                    != Some(std::cmp::Ordering::Less) =>
            {
                f.declined = Some(format!(
                    "the general mode did no better ({}% of the diagonal)",
                    sig(100.0 * measures.hausdorff_relative, 4)
                ));
                return Ok(f);
            }
            _ => (fit, measures, distances),
        },
        (Err(e), Some(mut f)) => {
            f.declined = Some(format!(
                "the general mode refused the mesh: {}",
                e.message()
            ));
            return Ok(f);
        }
        (Err(e), None) => {
            return Err(match &fallback {
                Some(why) if !e.message().contains(why.as_str()) => {
                    Error::invalid(format!("{} ({why})", e.message())).at(e.place())
                }
                _ => e,
            })
        }
    };
    let (worst, _) = distances.worst(mesh);
    Ok(Fitted {
        fit,
        measures,
        distances,
        worst,
        file: request.file,
        tolerance,
        target: tolerance,
        fallback,
        declined: None,
    })
}
