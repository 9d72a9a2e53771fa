//! One designer session: the compiled design, its undo and redo stacks, and the directory the
//! server was started in (the only place files are read from and written to). Everything here
//! is synchronous; the HTTP layer runs it on a blocking thread behind one lock.

use super::error::ApiError;
use super::files;
use super::gestures::{self, LocalDrag, LocalRequest};
use super::timeline::Timeline;
use super::trimmed::{self, TrimmedMeshes};
use crate::common;
use pdeshape::design::WriteDesign as _;
use pdeshape::design::{self, CompiledDesign, Edit};
use pdeshape::mesh::{Format, GridMesh};
use pdeshape::spec::{self, DesignSpec};
use std::path::PathBuf;

/// The largest grid the designer draws (per patch); [`design::grid`] also bounds all patches
/// together.
pub(super) const MAX_NU: usize = 512;
pub(super) const MAX_NV: usize = 1024;
/// Undo entries kept (the oldest are forgotten beyond this).
const MAX_UNDO: usize = 1000;

/// An entry of the undo stack: the edit that undoes it, and the drag (or slider) group it
/// belongs to with the target it changed, so that a whole drag undoes in one step.
struct UndoEntry {
    undo: Edit,
    group: Option<(u64, String)>,
}

/// What surface colouring a frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Coloring {
    Shaded,
    Gauss,
    Mean,
    /// Absolute curvature `|κ₁| + |κ₂|`.
    Absolute,
}

/// Percentiles of the colour range of a curvature map, by surface area (so that a small patch
/// of high curvature, such as a handle, does not take the whole range from a large body).
pub(super) const COLOR_PERCENTILES: (f64, f64) = (0.02, 0.98);

/// The curvature colouring of a frame: per-vertex colours, the range they span and the values'
/// true range.
pub(super) struct Colors {
    pub colors: pdeshape::analysis_report::MeshColors,
    pub range: (f64, f64),
    pub full: (f64, f64),
}

/// Area-weighted quantiles `q` of `values` (weights `w`), or `None` when no value is finite.
fn weighted_quantiles(values: &[f64], w: &[f64], qs: (f64, f64)) -> Option<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = values
        .iter()
        .zip(w)
        .filter(|(x, w)| x.is_finite() && w.is_finite())
        .map(|(x, w)| (*x, *w))
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = v.iter().map(|p| p.1).sum();
    let at = |q: f64| {
        if total <= 0.0 {
            return v[((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)].0;
        }
        let mut acc = 0.0;
        for (x, w) in &v {
            acc += w;
            if acc >= q * total {
                return *x;
            }
        }
        v[v.len() - 1].0
    };
    Some((at(qs.0), at(qs.1)))
}

/// The area around each vertex of a grid mesh: a third of the areas of its triangles.
fn vertex_areas(m: &GridMesh) -> Vec<f64> {
    let (nu, nv) = (m.nu, m.nv);
    let mut w = vec![0.0; m.positions.len()];
    if nu < 2 || nv < 2 || w.len() != nu * nv {
        return vec![1.0; m.positions.len()];
    }
    let p = |i: usize| {
        let q = m.positions[i];
        pdeshape::Vec3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2]))
    };
    let cols = if m.periodic_v { nv } else { nv - 1 };
    for i in 0..nu - 1 {
        for j in 0..cols {
            let j1 = (j + 1) % nv;
            let (a, b, c, d) = (i * nv + j, (i + 1) * nv + j, (i + 1) * nv + j1, i * nv + j1);
            for (x, y, z) in [(a, b, c), (a, c, d)] {
                let area = (p(y) - p(x)).cross(&(p(z) - p(x))).norm() / 2.0;
                if area.is_finite() {
                    for k in [x, y, z] {
                        w[k] += area / 3.0;
                    }
                }
            }
        }
    }
    w
}

pub(super) struct Session {
    root: PathBuf,
    file: String,
    design: CompiledDesign,
    undo: Vec<UndoEntry>,
    redo: Vec<Edit>,
    version: u64,
    /// The animation of a time-dependent design, until the first edit makes it a still design.
    timeline: Option<Timeline>,
    /// The time at which an edit made a time-dependent design a still one.
    frozen_at: Option<f64>,
    /// The trimmed surfaces' triangle meshes, and the grid they were made for (`None` once the
    /// design changed).
    trimmed: TrimmedMeshes,
    trimmed_for: Option<(usize, usize)>,
    /// The local-edit drag under way.
    local: Option<LocalDrag>,
}

/// What an edit changes, for merging the edits of one drag into one undo step: edits of the
/// same target in one group are undone together by the first one's undo edit (each of these
/// undo edits restores the whole target).
fn target(edit: &Edit) -> Option<String> {
    match edit {
        Edit::MoveControlPoint { name, index, .. } => Some(format!("point {name} {index}")),
        Edit::SetCurve { name, .. } | Edit::Transform { name, .. } => Some(format!("curve {name}")),
        Edit::SetSmoothing { patch, .. } | Edit::SetOrder { patch, .. } => {
            Some(format!("operator {patch:?}"))
        }
        Edit::SetModes { .. } => Some("modes".to_string()),
        Edit::SetParameter { name, .. } => Some(format!("parameter {name}")),
        // A local edit replaces the curve's table, as the later positions of its drag do.
        Edit::LocalEdit { name, .. } | Edit::MoveAttachment { name, .. } => {
            Some(format!("curve {name}"))
        }
        Edit::SetSpine { patch, .. } => Some(format!("spine {patch:?}")),
        Edit::SetTrim { index, .. } | Edit::MoveTrimCurve { index, .. } => {
            Some(format!("trim {index}"))
        }
        _ => None,
    }
}

impl Session {
    /// A session on the design file `rel` (inside `root`), or on the built-in starting design.
    pub(super) fn open(root: PathBuf, rel: Option<&str>) -> Result<Session, ApiError> {
        let root = root
            .canonicalize()
            .map_err(|e| ApiError::internal(format!("{}: {e}", root.display())))?;
        let opened = match rel {
            Some(rel) => files::open_design(&root, rel)?,
            None => files::Opened {
                file: "untitled.toml".to_string(),
                spec: starting_design().map_err(|e| ApiError::internal(e.to_string()))?,
                animation: None,
            },
        };
        let (file, design, timeline) = compile_opened(opened)?;
        Ok(Session {
            root,
            file,
            design,
            undo: Vec::new(),
            redo: Vec::new(),
            version: 0,
            timeline,
            frozen_at: None,
            trimmed: TrimmedMeshes::default(),
            trimmed_for: None,
            local: None,
        })
    }

    pub(super) fn root(&self) -> &std::path::Path {
        &self.root
    }
    pub(super) fn file(&self) -> &str {
        &self.file
    }
    pub(super) fn spec(&self) -> &DesignSpec {
        self.design.spec()
    }
    pub(super) fn design(&self) -> &CompiledDesign {
        &self.design
    }
    pub(super) fn version(&self) -> u64 {
        self.version
    }
    pub(super) fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }
    pub(super) fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }
    pub(super) fn timeline(&self) -> Option<&Timeline> {
        self.timeline.as_ref()
    }
    pub(super) fn frozen_at(&self) -> Option<f64> {
        self.frozen_at
    }
    /// Parameter meshes of trimmed surfaces made afresh so far (the others were reused).
    #[cfg(test)]
    pub(super) fn remeshed(&self) -> usize {
        self.trimmed.remeshed
    }

    /// Applies `edit` and re-solves; the meshes on `grid` must come out finite too, else the
    /// edit is taken back. On an error nothing changes. Edits of one `group` (a drag) on the
    /// same target make one undo step.
    pub(super) fn apply(
        &mut self,
        edit: &Edit,
        group: Option<u64>,
        grid: (usize, usize),
    ) -> Result<(), ApiError> {
        let undo = self.apply_checked(edit, grid, group.is_some())?;
        // An edited time-dependent design is the still design at the time shown.
        if let Some(t) = self.timeline.take() {
            self.frozen_at = Some(t.t());
        }
        let tag = group.zip(target(edit));
        let merge = tag.is_some()
            && self
                .undo
                .last()
                .is_some_and(|last| last.group.as_ref() == tag.as_ref());
        if !merge {
            self.undo.push(UndoEntry { undo, group: tag });
            if self.undo.len() > MAX_UNDO {
                self.undo.remove(0);
            }
        }
        self.redo.clear();
        Ok(())
    }

    /// [`CompiledDesign::apply`] (or, for an edit of a gesture, `apply_dragging`, whose
    /// meshes may come from the drag's model), then the meshes on `grid`; a design whose
    /// meshes fail (a surface that is not finite) is put back as it was.
    fn apply_checked(
        &mut self,
        edit: &Edit,
        grid: (usize, usize),
        gesture: bool,
    ) -> Result<Edit, ApiError> {
        let err = |s: &Session, e: &pdeshape::Error| ApiError::edit(s.design.spec(), e);
        let grid = self.checked_grid(grid)?;
        let applied = if gesture {
            self.design.apply_dragging(edit)
        } else {
            self.design.apply(edit)
        };
        let undo = applied.map_err(|e| err(self, &e))?;
        self.trimmed_for = None;
        if let Err(e) = self.refresh(grid) {
            let back = self.design.apply(&undo);
            debug_assert!(back.is_ok());
            self.trimmed_for = None;
            return Err(e);
        }
        self.version += 1;
        Ok(undo)
    }

    /// The grid meshes on `grid` and the trimmed surfaces' triangle meshes (made again when the
    /// design or the grid changed). On an error the trimmed meshes are forgotten.
    fn refresh(&mut self, grid: (usize, usize)) -> Result<(), ApiError> {
        let grid = self.checked_grid(grid)?;
        let failed =
            |e: pdeshape::Error| ApiError::unprocessable(common::message_of(&e), e.place());
        if self.trimmed_for == Some(grid) {
            return self
                .design
                .meshes(grid.0, grid.1)
                .map(|_| ())
                .map_err(failed);
        }
        let jobs = trimmed::jobs(self.design.solved());
        let meshes = self.design.meshes(grid.0, grid.1).map_err(failed)?;
        self.trimmed.update(&jobs, meshes, grid).map_err(failed)?;
        self.trimmed_for = Some(grid);
        Ok(())
    }

    /// The meshes of a frame on `grid`: every surface's grid mesh and the triangle meshes of
    /// the trimmed ones.
    pub(super) fn drawn(
        &mut self,
        grid: (usize, usize),
    ) -> Result<(&[GridMesh], &TrimmedMeshes), ApiError> {
        self.refresh(grid)?;
        let grid = self.checked_grid(grid)?;
        let meshes = self
            .design
            .meshes(grid.0, grid.1)
            .map_err(|e| ApiError::unprocessable(common::message_of(&e), e.place()))?;
        Ok((meshes, &self.trimmed))
    }

    /// Moves a spine control point or sets how the sections follow the spine (§5.3); a drag
    /// (`group`) is one undo step.
    pub(super) fn spine(
        &mut self,
        request: &gestures::SpineRequest,
        grid: (usize, usize),
    ) -> Result<(), ApiError> {
        let edit = gestures::spine_edit(self.spec(), self.design.solved(), request)?;
        self.apply(&edit, request.group, grid)
    }

    /// A local edit of a curve (§6.2); the positions of one drag (`group`) make one local edit
    /// and one undo step.
    pub(super) fn local(
        &mut self,
        request: &LocalRequest,
        grid: (usize, usize),
    ) -> Result<(), ApiError> {
        let (edit, drag) = gestures::local_edit(self.spec(), self.local.as_ref(), request)?;
        self.apply(&edit, request.group, grid)?;
        self.local = drag;
        Ok(())
    }

    /// Shows the time-dependent design at time `t` (re-solved incrementally; not an edit).
    pub(super) fn set_time(&mut self, t: f64, grid: (usize, usize)) -> Result<(), ApiError> {
        let Some(timeline) = &self.timeline else {
            let why = match self.frozen_at {
                Some(t) => format!(
                    "the design was edited at t = {t} and is a still design now (load its file again to play it)"
                ),
                None => "the design does not depend on time (it has no formulas in t, no [rig] and is no morph)".to_string(),
            };
            return Err(ApiError::unprocessable(why, "t"));
        };
        let grid = self.checked_grid(grid)?;
        let spec = timeline.spec_at(t)?;
        let before = self.design.spec().clone();
        self.design
            .set_spec(spec)
            .map_err(|e| ApiError::edit(&before, &e))?;
        self.trimmed_for = None;
        if let Err(e) = self.refresh(grid) {
            let back = self.design.set_spec(before);
            debug_assert!(back.is_ok());
            self.trimmed_for = None;
            return Err(e);
        }
        self.version += 1;
        if let Some(timeline) = &mut self.timeline {
            timeline.set(t);
        }
        Ok(())
    }

    /// Undoes the last edit (or drag); false when there is nothing to undo.
    pub(super) fn undo(&mut self, grid: (usize, usize)) -> Result<bool, ApiError> {
        let Some(entry) = self.undo.pop() else {
            return Ok(false);
        };
        match self.apply_checked(&entry.undo, grid, false) {
            Ok(redo) => {
                self.redo.push(redo);
                Ok(true)
            }
            Err(e) => {
                self.undo.push(entry);
                Err(e)
            }
        }
    }

    /// Redoes the last undone edit; false when there is nothing to redo.
    pub(super) fn redo(&mut self, grid: (usize, usize)) -> Result<bool, ApiError> {
        let Some(edit) = self.redo.pop() else {
            return Ok(false);
        };
        match self.apply_checked(&edit, grid, false) {
            Ok(undo) => {
                self.undo.push(UndoEntry { undo, group: None });
                Ok(true)
            }
            Err(e) => {
                self.redo.push(edit);
                Err(e)
            }
        }
    }

    /// Replaces the design by the file `rel` inside the start directory; the stacks start anew.
    pub(super) fn load(&mut self, rel: &str) -> Result<(), ApiError> {
        let (file, design, timeline) = compile_opened(files::open_design(&self.root, rel)?)?;
        self.design = design;
        self.file = file;
        self.start_anew(timeline);
        Ok(())
    }

    /// A new design in the session: empty stacks, no drag under way.
    fn start_anew(&mut self, timeline: Option<Timeline>) {
        self.undo.clear();
        self.redo.clear();
        self.version += 1;
        self.timeline = timeline;
        self.frozen_at = None;
        self.trimmed.clear();
        self.trimmed_for = None;
        self.local = None;
    }

    /// Replaces the design by the starting design (a new, unsaved design).
    pub(super) fn reset(&mut self) -> Result<(), ApiError> {
        let spec = starting_design().map_err(|e| ApiError::internal(e.to_string()))?;
        self.design = design::compile(&spec).map_err(|e| ApiError::edit(&spec, &e))?;
        self.file = "untitled.toml".to_string();
        self.start_anew(None);
        Ok(())
    }

    /// Writes the design as TOML to `rel` inside the start directory (atomically); returns the
    /// path written, relative to the start directory.
    pub(super) fn save(&mut self, rel: &str) -> Result<String, ApiError> {
        if let Some(t) = &self.timeline {
            if rel == self.file {
                return Err(ApiError::unprocessable(
                    format!(
                        "'{rel}' is a time-dependent design: saving would replace it by its still design at t = {}; save under another name",
                        t.t()
                    ),
                    "path",
                ));
            }
        }
        let text = spec::write_design(self.design.spec())
            .map_err(|e| ApiError::unprocessable(common::message_of(&e), e.place()))?;
        let written = files::save_text(&self.root, rel, &text)?;
        self.file = written.clone();
        Ok(written)
    }

    /// The grid `(nu, nv)` checked against the designer's limits and the library's.
    pub(super) fn checked_grid(
        &self,
        (nu, nv): (usize, usize),
    ) -> Result<(usize, usize), ApiError> {
        if !(2..=MAX_NU).contains(&nu) {
            return Err(ApiError::bad_request(
                format!("must be between 2 and {MAX_NU} (got {nu})"),
                "nu",
            ));
        }
        if !(3..=MAX_NV).contains(&nv) {
            return Err(ApiError::bad_request(
                format!("must be between 3 and {MAX_NV} (got {nv})"),
                "nv",
            ));
        }
        design::grid(self.design.spec(), Some(nu), Some(nv))
            .map_err(|e| ApiError::bad_request(common::message_of(&e), e.place()))
    }

    /// The grid meshes on `grid`.
    pub(super) fn meshes(&mut self, grid: (usize, usize)) -> Result<&[GridMesh], ApiError> {
        Ok(self.drawn(grid)?.0)
    }

    /// The `check` report of the design and its diagnostics (the library's, as `pdeshape
    /// check` prints them), the seams judged by the G1 and (if given) the G2 tolerance.
    pub(super) fn check(
        &self,
        g1_tolerance: f64,
        g2_tolerance: Option<f64>,
    ) -> (String, String, pdeshape::diagnostics::Diagnostics) {
        let spec = self.design.spec();
        let solved = self.design.solved();
        let mut d = pdeshape::diagnostics::diagnose(spec, solved);
        d.judge_seams(g1_tolerance);
        if let Some(t) = g2_tolerance {
            d.judge_curvature(t);
        }
        let report = pdeshape::diagnostics::check_report(&self.file, spec, solved, &d);
        let text = pdeshape::diagnostics::check_text(&self.file, spec, solved, &d);
        (report, text, d)
    }

    /// The `analyze` numbers as JSON (the same as `pdeshape analyze --json`).
    pub(super) fn analyze(&self) -> Result<String, ApiError> {
        pdeshape::analysis_report::design_json(self.design.solved())
            .map_err(|e| ApiError::unprocessable(e.to_string(), ""))
    }

    /// The design's surfaces as STEP or IGES (the library's CAD writer at its default
    /// tolerance), and a summary for the page: the number of surfaces, the largest deviation
    /// from the design, whether every deviation is certified, and the tolerance.
    pub(super) fn cad(
        &self,
        format: pdeshape::format::OutputFormat,
    ) -> Result<(Vec<u8>, String), ApiError> {
        let solved = self.design.solved();
        let name = std::path::Path::new(&self.file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "design".to_string());
        let export = pdeshape::cad::export_design(
            solved,
            format,
            None,
            None,
            &format!("{name}.{}", format.name()),
            pdeshape::format::export_timestamp(),
        )
        .map_err(|e| match e {
            pdeshape::cad::CadExportError::Design(e)
            | pdeshape::cad::CadExportError::Tolerance(e)
            | pdeshape::cad::CadExportError::Write(e) => {
                ApiError::unprocessable(common::message_of(&e), e.place())
            }
        })?;
        let surfaces = &export.model.surfaces;
        let deviation = surfaces
            .iter()
            .map(|s| s.approx.deviation)
            .fold(0.0, f64::max);
        let certified = surfaces.iter().all(|s| s.approx.certificate.is_certified());
        let summary = format!(
            "surfaces={}; deviation={deviation:.3e}; certified={certified}; tolerance={:.3e}",
            surfaces.len(),
            export.tolerance
        );
        Ok((export.text.into_bytes(), summary))
    }

    /// The design's surfaces in a mesh format, written by the library's writers.
    pub(super) fn download(
        &mut self,
        format: Format,
        grid: (usize, usize),
    ) -> Result<Vec<u8>, ApiError> {
        let (nu, nv) = self.checked_grid(grid)?;
        let mut out = Vec::new();
        self.design
            .solved()
            .write(format, nu, nv, &mut out)
            .map_err(|e| ApiError::edit(self.design.spec(), &e))?;
        Ok(out)
    }

    /// A PNG picture (the `render` subcommand's), seen from `view`.
    pub(super) fn picture(
        &mut self,
        grid: (usize, usize),
        size: (u32, u32),
        view: Option<pdeshape::Vec3>,
    ) -> Result<Vec<u8>, ApiError> {
        let options = pdeshape::render::RenderOptions {
            width: size.0,
            height: size.1,
            view,
            ..Default::default()
        };
        let overlays = pdeshape::render::overlay_lines(&self.design.solved().overlays());
        let picture = if self.design.solved().trims.is_empty() {
            let meshes = self.meshes(grid)?.to_vec();
            pdeshape::render::render_png(&meshes, &overlays, &options)
        } else {
            // Holes are drawn as the library's trimmed triangle mesh, as `render` does.
            let (nu, nv) = self.checked_grid(grid)?;
            let solved = self.design.solved();
            let m = solved
                .tri_mesh(nu, nv)
                .map_err(|e| ApiError::edit(self.design.spec(), &e))?;
            pdeshape::render::render_png_tri(&m, &overlays, &options)
        };
        picture.map_err(|e| ApiError::unprocessable(common::message_of(&e), e.place()))
    }

    /// Per-vertex colours of the curvature `by` on the meshes of `grid`: over `range`, else
    /// over the [`COLOR_PERCENTILES`] of the values weighted by area (symmetric about 0 when
    /// they span it, as `render --color`); with the values' true range.
    pub(super) fn colors(
        &mut self,
        grid: (usize, usize),
        by: Coloring,
        range: Option<(f64, f64)>,
    ) -> Result<Option<Colors>, ApiError> {
        if by == Coloring::Shaded {
            return Ok(None);
        }
        let meshes = self.meshes(grid)?.to_vec();
        let solved = self.design.solved();
        let orientation = match by {
            Coloring::Mean => {
                pdeshape::integrate_design(solved, &pdeshape::Quadrature::default())
                    .map_err(|e| ApiError::unprocessable(common::message_of(&e), "color"))?
                    .orientation
            }
            _ => vec![1.0; solved.surfaces.len()],
        };
        let values: Vec<Vec<f64>> = solved
            .surfaces
            .iter()
            .zip(&meshes)
            .zip(&orientation)
            .map(|((s, m), sign)| {
                let (k, h) = pdeshape::analysis::curvature_grid(s.surface(), &m.u, &m.v);
                match by {
                    Coloring::Gauss => k,
                    Coloring::Mean => h.into_iter().map(|x| x * sign).collect(),
                    _ => k
                        .iter()
                        .zip(&h)
                        .map(|(k, h)| {
                            if *k >= 0.0 {
                                2.0 * h.abs()
                            } else {
                                2.0 * (h * h - k).sqrt()
                            }
                        })
                        .collect(),
                }
            })
            .collect();
        let flat: Vec<f64> = values.iter().flatten().copied().collect();
        let weights: Vec<f64> = meshes.iter().flat_map(vertex_areas).collect();
        let finite = flat.iter().copied().filter(|x| x.is_finite());
        let full = finite
            .clone()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        let full = if full.0 <= full.1 { full } else { (-1.0, 1.0) };
        let range = match range {
            Some(r) => r,
            None => match weighted_quantiles(&flat, &weights, COLOR_PERCENTILES) {
                Some((lo, hi)) if lo < 0.0 && hi > 0.0 => {
                    let m = lo.abs().max(hi);
                    (-m, m)
                }
                Some((lo, hi)) if hi - lo > 1e-6 * lo.abs().max(hi.abs()) => (lo, hi),
                Some((lo, hi)) => {
                    let mid = 0.5 * (lo + hi);
                    let d = if mid == 0.0 { 1.0 } else { 0.01 * mid.abs() };
                    (mid - d, mid + d)
                }
                None => (-1.0, 1.0),
            },
        };
        let colors = values
            .iter()
            .map(|v| pdeshape::render::diverging_colors(v, range.0, range.1))
            .collect();
        Ok(Some(Colors {
            colors,
            range,
            full,
        }))
    }
}

/// The compiled design of an opened file, and its timeline if it depends on time.
fn compile_opened(
    opened: files::Opened,
) -> Result<(String, CompiledDesign, Option<Timeline>), ApiError> {
    let design = design::compile(&opened.spec)
        .map_err(|e| ApiError::design(&opened.file, &opened.spec, &e))?;
    let timeline = opened.animation.map(Timeline::new).transpose()?;
    Ok((opened.file, design, timeline))
}

/// The design a session starts from without a file: the book's simplest PDE surface, two
/// circles joined by a biharmonic patch (§4.3), with a B-spline rim to drag.
pub(super) fn starting_design() -> pdeshape::Result<DesignSpec> {
    const TEXT: &str = r#"title = "A new design: two curves and a biharmonic patch"

[operator]
kind = "polyharmonic"
order = 2
a = 1.0

[curves.base]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.base_up]
type = "circle"
center = [0.0, 0.0, 1.0]
radius = 1.0

[curves.base_tangent]
type = "derivative"
position = "base"
direction = "base_up"
scale = 1.0

[curves.rim]
type = "bspline"
degree = 3
# v = 0 is near the second control point: (P0 + 4 P1 + P2)/6 for a uniform cubic.
control = [[0.78, -0.78, 2.0], [1.1, 0.0, 2.0], [0.78, 0.78, 2.0], [0.0, 1.1, 2.0],
           [-0.78, 0.78, 2.0], [-1.1, 0.0, 2.0], [-0.78, -0.78, 2.0], [0.0, -1.1, 2.0]]

[curves.rim_up]
type = "circle"
center = [0.0, 0.0, 3.0]
radius = 1.0

[curves.rim_tangent]
type = "derivative"
position = "rim"
direction = "rim_up"
scale = 1.0

[[patches]]
name = "body"
conditions = [
  { u = 0.0, curve = "base" },
  { u = 0.0, derivative = 1, curve = "base_tangent" },
  { u = 1.0, curve = "rim" },
  { u = 1.0, derivative = 1, curve = "rim_tangent" },
]
"#;
    spec::parse_design(TEXT)
}
