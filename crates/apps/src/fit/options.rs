//! What every fitting mode takes and gives, and the automatic choice between the modes.

use super::frame::FileFrame;
use super::mesh::InputMesh;
use super::section::AxisFrame;
use crate::spec::DesignSpec;
use crate::{Error, Result};

/// Options of the automatic modes (and the defaults of a template's parts).
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Largest sample error allowed, as a fraction of the mesh's bounding-box diagonal.
    pub target: f64,
    /// Smoothing parameter `a` of the biharmonic operator; `None` tries a few and keeps the
    /// one that needs the fewest patches.
    pub a: Option<f64>,
    /// Fine sections `N` (the least-squares data and the candidate nodes).
    pub sections: usize,
    /// Samples `S` per section (a power of two).
    pub samples: usize,
    /// Most Fourier modes per curve.
    pub max_modes: usize,
    /// A fixed number of patches (the nodes spread evenly over the fine sections), instead of
    /// the adaptive choice.
    pub patches: Option<usize>,
    /// The frame of the file the mesh was read from: points in messages are named in its
    /// coordinates ([`FileFrame::point`]).
    pub file: FileFrame,
}

/// The options of the tube mode (the same as every mode's).
pub type TubeOptions = FitOptions;

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            target: 1e-3,
            a: None,
            sections: 96,
            samples: 128,
            max_modes: 32,
            patches: None,
            file: FileFrame::default(),
        }
    }
}

impl FitOptions {
    /// Refuses a target or section count out of range, naming the option.
    pub fn check(&self) -> Result<()> {
        if !(self.target > 0.0 && self.target.is_finite()) {
            return Err(
                Error::invalid(format!("must be a positive number (got {})", self.target))
                    .at("tolerance"),
            );
        }
        if self.sections < 8 || self.sections > 4096 {
            return Err(Error::invalid(format!(
                "must be between 8 and 4096 (got {})",
                self.sections
            ))
            .at("sections"));
        }
        if !self.samples.is_power_of_two() || self.samples < 16 || self.samples > 4096 {
            return Err(Error::invalid(format!(
                "must be a power of two between 16 and 4096 (got {})",
                self.samples
            ))
            .at("samples"));
        }
        if let Some(a) = self.a {
            if !(a > 0.0 && a.is_finite()) {
                return Err(Error::invalid(format!("must be a positive number (got {a})")).at("a"));
            }
        }
        Ok(())
    }
}

/// The mode that made a fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FitMode {
    /// A closed body along its main axis, poles at both ends ([`super::fit_tube`]).
    Tube,
    /// An open sheet by profiles across its main axis ([`super::fit_sheet`]).
    Sheet,
    /// Parts sectioned as a template says ([`super::fit_template`]).
    Template,
    /// Any manifold mesh as one layout of n-sided patches ([`super::fit_general`]).
    General,
}

impl FitMode {
    /// The mode's name, as `--mode` and reports spell it.
    pub fn name(self) -> &'static str {
        match self {
            FitMode::Tube => "tube",
            FitMode::Sheet => "sheet",
            FitMode::Template => "template",
            FitMode::General => "general",
        }
    }
}

/// What a fit made.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The fitted design.
    pub spec: DesignSpec,
    /// The mode that made it.
    pub mode: FitMode,
    /// The sections' frame (of the first part, for a template).
    pub frame: AxisFrame,
    /// Fine sections used (some next to the poles may be dropped, see [`Fit::dropped`]).
    pub sections: usize,
    /// Fine sections next to the poles left out because they were degenerate.
    pub dropped: usize,
    /// Fourier modes of the curves (the most of any part).
    pub modes: usize,
    /// Patches of the fitted design (over all parts).
    pub patches: usize,
    /// The smoothing parameter chosen (of the first part, for a template).
    pub a: f64,
    /// Largest distance, along the mesh's normal, between a fine section's samples and the
    /// fitted patch at its `u`, relative to the diagonal.
    pub sample_error: f64,
    /// What the mode changed or left out, in words (the general mode's creased edges, the
    /// components it could not fit); empty for the tube, sheet and template modes.
    pub notes: Vec<String>,
}

/// What the tube mode made (the same as every mode's).
pub type TubeFit = Fit;

/// The automatic choice: a closed mesh is fitted by the tube mode; an open one whose boundary is
/// one or two loops across its main axis at its ends by the tube mode with open ends, any other
/// open one by the sheet mode. Meshes that are not one edge-manifold surface are refused first.
pub fn fit_mesh(mesh: &InputMesh, opts: &FitOptions) -> Result<Fit> {
    opts.check()?;
    let topology = mesh.require_single()?;
    if topology.boundary_edges == 0 {
        return super::fit_tube(mesh, opts);
    }
    if super::tube::open_ends(mesh, opts.target * mesh.diagonal()).is_some() {
        super::tube::fit_open_tube(mesh, opts)
    } else {
        super::fit_sheet(mesh, opts)
    }
}
