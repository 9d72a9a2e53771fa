//! One designer session: the compiled design, its undo and redo stacks, and the directory the
//! server was started in (the only place files are read from and written to). Everything here
//! is synchronous; the HTTP layer runs it on a blocking thread behind one lock.

use super::error::ApiError;
use super::files;
use crate::common::{self, Loaded};
use pdeshape::design::{self, CompiledDesign, Edit};
use pdeshape::mesh::{Format, GridMesh};
use pdeshape::spec::{self, DesignSpec};
use std::path::PathBuf;

/// The largest grid the designer draws (per patch); [`design::grid`] also bounds all patches
/// together.
pub const MAX_NU: usize = 512;
pub const MAX_NV: usize = 1024;
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
pub enum Coloring {
    Shaded,
    Gauss,
    Mean,
}

pub struct Session {
    root: PathBuf,
    file: String,
    design: CompiledDesign,
    undo: Vec<UndoEntry>,
    redo: Vec<Edit>,
    version: u64,
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
        _ => None,
    }
}

impl Session {
    /// A session on the design file `rel` (inside `root`), or on the built-in starting design.
    pub fn open(root: PathBuf, rel: Option<&str>) -> Result<Session, ApiError> {
        let root = root
            .canonicalize()
            .map_err(|e| ApiError::internal(format!("{}: {e}", root.display())))?;
        let (file, spec) = match rel {
            Some(rel) => {
                let (file, loaded) = files::load_design(&root, rel)?;
                (file, loaded.spec)
            }
            None => (
                "untitled.toml".to_string(),
                starting_design().map_err(|e| ApiError::internal(e.to_string()))?,
            ),
        };
        let design = design::compile(&spec).map_err(|e| ApiError::design(&file, &spec, &e))?;
        Ok(Session {
            root,
            file,
            design,
            undo: Vec::new(),
            redo: Vec::new(),
            version: 0,
        })
    }

    pub fn root(&self) -> &std::path::Path {
        &self.root
    }
    pub fn file(&self) -> &str {
        &self.file
    }
    pub fn spec(&self) -> &DesignSpec {
        self.design.spec()
    }
    pub fn design(&self) -> &CompiledDesign {
        &self.design
    }
    pub fn version(&self) -> u64 {
        self.version
    }
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Applies `edit` and re-solves; the meshes on `grid` must come out finite too, else the
    /// edit is taken back. On an error nothing changes. Edits of one `group` (a drag) on the
    /// same target make one undo step.
    pub fn apply(
        &mut self,
        edit: &Edit,
        group: Option<u64>,
        grid: (usize, usize),
    ) -> Result<(), ApiError> {
        let undo = self.apply_checked(edit, grid)?;
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

    /// [`CompiledDesign::apply`], then the meshes on `grid`; a design whose meshes fail (a
    /// surface that is not finite) is put back as it was.
    fn apply_checked(&mut self, edit: &Edit, grid: (usize, usize)) -> Result<Edit, ApiError> {
        let err = |s: &Session, e: &pdeshape::Error| ApiError::edit(s.design.spec(), e);
        let undo = self.design.apply(edit).map_err(|e| err(self, &e))?;
        let grid = self.checked_grid(grid)?;
        if let Err(e) = self.design.meshes(grid.0, grid.1) {
            let back = self.design.apply(&undo);
            debug_assert!(back.is_ok());
            return Err(err(self, &e));
        }
        self.version += 1;
        Ok(undo)
    }

    /// Undoes the last edit (or drag); false when there is nothing to undo.
    pub fn undo(&mut self, grid: (usize, usize)) -> Result<bool, ApiError> {
        let Some(entry) = self.undo.pop() else {
            return Ok(false);
        };
        match self.apply_checked(&entry.undo, grid) {
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
    pub fn redo(&mut self, grid: (usize, usize)) -> Result<bool, ApiError> {
        let Some(edit) = self.redo.pop() else {
            return Ok(false);
        };
        match self.apply_checked(&edit, grid) {
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
    pub fn load(&mut self, rel: &str) -> Result<(), ApiError> {
        let (file, loaded) = files::load_design(&self.root, rel)?;
        let design =
            design::compile(&loaded.spec).map_err(|e| ApiError::design(&file, &loaded.spec, &e))?;
        self.design = design;
        self.file = file;
        self.undo.clear();
        self.redo.clear();
        self.version += 1;
        Ok(())
    }

    /// Replaces the design by the starting design (a new, unsaved design).
    pub fn reset(&mut self) -> Result<(), ApiError> {
        let spec = starting_design().map_err(|e| ApiError::internal(e.to_string()))?;
        self.design = design::compile(&spec).map_err(|e| ApiError::edit(&spec, &e))?;
        self.file = "untitled.toml".to_string();
        self.undo.clear();
        self.redo.clear();
        self.version += 1;
        Ok(())
    }

    /// Writes the design as TOML to `rel` inside the start directory (atomically); returns the
    /// path written, relative to the start directory.
    pub fn save(&mut self, rel: &str) -> Result<String, ApiError> {
        let text = spec::write_design(self.design.spec())
            .map_err(|e| ApiError::unprocessable(common::message_of(&e), e.place()))?;
        let written = files::save_text(&self.root, rel, &text)?;
        self.file = written.clone();
        Ok(written)
    }

    /// The grid `(nu, nv)` checked against the designer's limits and the library's.
    pub fn checked_grid(&self, (nu, nv): (usize, usize)) -> Result<(usize, usize), ApiError> {
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

    /// The meshes on `grid`.
    pub fn meshes(&mut self, grid: (usize, usize)) -> Result<&[GridMesh], ApiError> {
        let (nu, nv) = self.checked_grid(grid)?;
        let spec = self.design.spec().clone();
        self.design
            .meshes(nu, nv)
            .map_err(|e| ApiError::edit(&spec, &e))
    }

    /// The `check` report of the design and its warnings.
    pub fn check(&self) -> (String, Vec<String>) {
        let loaded = self.loaded();
        crate::check::report(&loaded, self.design.solved())
    }

    /// The `analyze` numbers as JSON (the same as `pdeshape analyze --json`).
    pub fn analyze(&self) -> Result<String, ApiError> {
        crate::analyze::design_json(self.design.solved())
            .map_err(|e| ApiError::unprocessable(e.message, ""))
    }

    /// The design's surfaces in a mesh format, written by the library's writers.
    pub fn download(&mut self, format: Format, grid: (usize, usize)) -> Result<Vec<u8>, ApiError> {
        let (nu, nv) = self.checked_grid(grid)?;
        let mut out = Vec::new();
        self.design
            .solved()
            .write(format, nu, nv, &mut out)
            .map_err(|e| ApiError::edit(self.design.spec(), &e))?;
        Ok(out)
    }

    /// A PNG picture (the `render` subcommand's), seen from `view`.
    pub fn picture(
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
        let overlays = self.design.solved().overlays();
        let meshes = self.meshes(grid)?.to_vec();
        pdeshape::render::render_png(&meshes, &overlays, &options)
            .map_err(|e| ApiError::unprocessable(common::message_of(&e), e.place()))
    }

    /// Per-vertex colours of the curvature `by` on the meshes of `grid` (as `render --color`).
    pub fn colors(
        &mut self,
        grid: (usize, usize),
        by: Coloring,
    ) -> Result<Option<(crate::analyze::MeshColors, f64, f64)>, ApiError> {
        let by = match by {
            Coloring::Shaded => return Ok(None),
            Coloring::Gauss => crate::analyze::ColorBy::Gauss,
            Coloring::Mean => crate::analyze::ColorBy::Mean,
        };
        let meshes = self.meshes(grid)?.to_vec();
        crate::analyze::curvature_colors(self.design.solved(), &meshes, by, None)
            .map(Some)
            .map_err(|e| ApiError::unprocessable(e.message, "color"))
    }

    /// The design as a loaded file (for the `check` report).
    fn loaded(&self) -> Loaded {
        Loaded {
            file: self.file.clone(),
            text: spec::write_design(self.design.spec()).unwrap_or_default(),
            spec: self.design.spec().clone(),
        }
    }
}

/// The design a session starts from without a file: the book's simplest PDE surface, two
/// circles joined by a biharmonic patch (§4.3), with a B-spline rim to drag.
pub fn starting_design() -> pdeshape::Result<DesignSpec> {
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
