//! A solved design: its named surfaces behind one interface ([`Surface`]), their conditions,
//! the design's curves, spines, shared edges (measured on demand), and what every front end
//! needs from them: the grid policy, meshes with the diagnosis of non-finite surfaces, picture
//! overlays, and writing in any mesh format.

use super::dynamic::BuiltDynamic;
use super::edges::{edge_mismatch, EdgeReport};
use super::spline::SolvedSpline;
use super::validate::{check_grid, DEFAULT_NU, DEFAULT_NV};
use crate::bfs::Blend;
use crate::curve::{Curve, Domain, SharedCurve};
use crate::elliptic::{PdePatch, SolveOptions};
use crate::fd::FdSurface;
use crate::mesh::{self, GridMesh, Samples, TriMesh, Up, WeldOptions, MAX_VERTICES};
use crate::spec::{DesignSpec, OperatorSpec, SolverMethod, Units};
use crate::splinepde::SplineNet;
use crate::surface::{ParametricSurface, Surface};
use crate::{Error, Result, Vec3, TAU};
use std::sync::{Arc, OnceLock};

/// Samples of `v` used to measure the mismatch along shared edges.
const EDGE_SAMPLES: usize = 512;
/// Points per drawn curve and along a spine.
const CURVE_POINTS: usize = 256;

/// A named curve of the design, built.
#[derive(Clone, Debug)]
pub struct NamedCurve {
    /// Its name in `[curves]`.
    pub name: String,
    /// The curve kind as written in the file (`circle`, `bspline`, …).
    pub kind: &'static str,
    /// The built curve, with its `arc_length`, `v_origin` and `transform` applied.
    pub curve: SharedCurve,
}

/// One condition of a patch as the design file gave it.
#[derive(Clone, Debug)]
pub struct ConditionInfo {
    /// Where the condition holds, `0 ≤ u ≤ 1`.
    pub u: f64,
    /// 0 for a position condition, `d` for the `d`-th u-derivative.
    pub derivative: usize,
    /// The curve's name, `None` for an inline curve table.
    pub curve_name: Option<String>,
    /// The curve kind (`circle`, `derivative`, …).
    pub kind: &'static str,
    /// The built curve the condition imposes (modifiers applied).
    pub curve: SharedCurve,
}

/// An edge shared by two patches: the same named curve is a position condition of both.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedEdge {
    /// The shared curve's name.
    pub curve: String,
    /// Surface indices, the edge's `u` on each, and the G0/G1 mismatch.
    pub report: EdgeReport,
}

/// What solved a surface, with the solver's own object (for reports only that solver gives).
#[derive(Clone)]
pub enum SurfaceKind {
    /// A Bloor–Wilson patch solved mode by mode (`solver = "analytic"`).
    Pde(Arc<PdePatch>),
    /// A patch solved by finite differences (`solver = "fd"`).
    Fd(Arc<FdSurface>),
    /// A `[[parametric]]` formula surface.
    Parametric(Arc<ParametricSurface>),
    /// A `[[nurbs]]` (rational) B-spline reference surface.
    Nurbs(Arc<super::NurbsSurface>),
    /// The `[blend]` surface (BFS smoothing spline).
    Blend(Arc<Blend>),
    /// The `[spline]` net, as solved (maybe exact) and in `f64`.
    Spline(Arc<SolvedSpline>, Arc<SplineNet<f64>>),
    /// An analytic PDE patch whose spine a `[[spine]]` table replaced (§5.3).
    SpineEdited(Arc<super::spine::SpineEdited>),
    /// An `[[nsided]]` patch, or one piece of it.
    NSided(Arc<crate::nsided::NSidedSurface>),
    /// A `[[disk]]` patch.
    Disk(Arc<crate::disk::DiskPatch>),
}

impl SurfaceKind {
    /// The surface behind the one interface.
    pub fn surface(&self) -> &dyn Surface {
        match self {
            SurfaceKind::Pde(s) => &**s,
            SurfaceKind::Fd(s) => &**s,
            SurfaceKind::Parametric(s) => &**s,
            SurfaceKind::Nurbs(s) => &**s,
            SurfaceKind::Blend(b) => &b.surface,
            SurfaceKind::Spline(_, n) => &**n,
            SurfaceKind::SpineEdited(s) => &**s,
            SurfaceKind::NSided(s) => &**s,
            SurfaceKind::Disk(s) => &**s,
        }
    }

    /// The solver's name, for reports.
    pub fn word(&self) -> &'static str {
        match self {
            SurfaceKind::Pde(_) => "PDE patch (analytic)",
            SurfaceKind::Fd(_) => "PDE patch (finite differences)",
            SurfaceKind::Parametric(_) => "parametric surface",
            SurfaceKind::Nurbs(s) if s.is_rational() => "NURBS surface",
            SurfaceKind::Nurbs(_) => "B-spline surface",
            SurfaceKind::Blend(_) => "blend (BFS smoothing spline)",
            SurfaceKind::Spline(..) => "spline PDE surface",
            SurfaceKind::SpineEdited(_) => "PDE patch (analytic) with an edited spine",
            SurfaceKind::NSided(_) => "n-sided PDE patch",
            SurfaceKind::Disk(_) => "PDE patch on the unit disk",
        }
    }

    /// The identity of the solved object: equal for a surface reused from an earlier solve.
    pub fn id(&self) -> usize {
        match self {
            SurfaceKind::Pde(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Fd(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Parametric(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Nurbs(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Blend(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Spline(_, n) => Arc::as_ptr(n) as usize,
            SurfaceKind::SpineEdited(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::NSided(s) => Arc::as_ptr(s) as usize,
            SurfaceKind::Disk(s) => Arc::as_ptr(s) as usize,
        }
    }
}

/// One named surface of a solved design.
#[derive(Clone)]
pub struct DesignSurface {
    /// Unique within the design (a single-patch design's surface is named after the title, or
    /// `surface`).
    pub name: String,
    /// Where it comes from in the design file: `conditions`, `patches[2]`, `parametric[0]`,
    /// `blend` or `spline`.
    pub place: String,
    /// What solved it, holding the solved object.
    pub kind: SurfaceKind,
    /// The operator of a PDE patch.
    pub operator: Option<OperatorSpec>,
    /// The conditions of a PDE patch, in file order (empty for other surfaces).
    pub conditions: Vec<ConditionInfo>,
}

impl DesignSurface {
    /// The surface behind the one interface.
    pub fn surface(&self) -> &dyn Surface {
        self.kind.surface()
    }

    /// The analytic PDE patch, if this is one.
    pub fn pde(&self) -> Option<&PdePatch> {
        match &self.kind {
            SurfaceKind::Pde(p) => Some(p),
            _ => None,
        }
    }

    /// `A₀(u)` (or its `order`-th u-derivative) for surfaces that have a spine
    /// ([`crate::surface::Spine`]: PDE patches, periodic finite-difference patches).
    pub fn spine(&self, u: f64, order: usize) -> Option<Vec3> {
        self.surface().as_spine().map(|s| s.spine(u, order))
    }

    /// True for the surfaces of PDE conditions (analytic or finite differences).
    pub fn is_patch(&self) -> bool {
        matches!(
            self.kind,
            SurfaceKind::Pde(_) | SurfaceKind::Fd(_) | SurfaceKind::SpineEdited(_)
        )
    }
}

/// How a design is exported to a mesh file.
#[derive(Clone, Debug, PartialEq)]
pub struct Export {
    /// Keep every surface apart (welded and oriented on its own) instead of joining surfaces
    /// that share an edge into one mesh.
    pub separate_patches: bool,
    /// A factor applied to every position (finite, positive).
    pub scale: f64,
    /// The up axis of OBJ, STL and PLY files (glTF is always `+Y` up).
    pub up: Up,
}

impl Export {
    /// How the weld treats the design's surfaces under these options.
    pub fn weld_options(&self) -> WeldOptions {
        WeldOptions {
            join_patches: !self.separate_patches,
        }
    }
}

impl Default for Export {
    fn default() -> Self {
        Export {
            separate_patches: false,
            scale: 1.0,
            up: Up::Z,
        }
    }
}

/// A design with every part solved: the result of [`super::compile`].
pub struct SolvedDesign {
    /// The design's `title`, if it has one.
    pub title: Option<String>,
    /// The length unit of the coordinates (`units`, default millimetres).
    pub units: Units,
    /// Every surface: the PDE patches in file order, then the `[[parametric]]` surfaces, the
    /// `[blend]` and the `[spline]` surface.
    pub surfaces: Vec<DesignSurface>,
    /// The named curves, sorted by name.
    pub curves: Vec<NamedCurve>,
    /// The analytic solver's options.
    pub options: SolveOptions,
    /// The solver of the PDE patches.
    pub method: SolverMethod,
    /// The finite-difference grid `[nu, nv]` when `method` is `Fd`.
    pub fd_grid: Option<[usize; 2]>,
    /// The design used `[[patches]]`.
    pub multi_patch: bool,
    /// The `[dynamic]` section, built (a dynamic PDE curve to run).
    pub dynamic: Option<BuiltDynamic>,
    /// The `[[trims]]`: holes cut out of surfaces (see [`super::trim`]).
    pub trims: Vec<super::trim::SurfaceTrim>,
    /// Position conditions that lie on another patch (§5.2.1; see
    /// [`SolvedDesign::attachment_reports`]).
    pub attachments: Vec<super::attach::Attachment>,
    /// The `[[network]]`s: their nodes, pieces, faces (surfaces `name.k`) and joints.
    pub networks: Vec<super::network::SolvedNetwork>,
    /// The `[[parametric]]` surfaces marked `reference` and the `[[nurbs]]` surfaces:
    /// neighbours of n-sided patches and networks, not part of the output.
    pub references: Vec<DesignSurface>,
    /// The `(u, v)` paths of the `on_patch` curves on their hosts, with the host's jets kept
    /// along them (drawn trim lines take their points from there).
    pub(crate) paths: Vec<Arc<super::attach::PathOnHost>>,
    pub(crate) edges: OnceLock<Vec<SharedEdge>>,
}

impl std::fmt::Debug for SolvedDesign {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolvedDesign")
            .field("title", &self.title)
            .field(
                "surfaces",
                &self.surfaces.iter().map(|s| &s.name).collect::<Vec<_>>(),
            )
            .field("curves", &self.curves.len())
            .finish()
    }
}

/// The number of surfaces a design will have (before solving it): PDE patches, parametric
/// surfaces, a blend, a spline, and the pieces that present n-sided patches and patchwork
/// faces (one for four sides, else one per side). A network's faces are found when it is
/// solved; each of its curves is counted as one.
fn surface_count(spec: &DesignSpec) -> usize {
    let patches = match (&spec.patches, &spec.conditions) {
        (Some(p), _) => p.len(),
        (None, Some(_)) => 1,
        (None, None) => 0,
    };
    let pieces = |sides: usize| if sides == 4 { 1 } else { sides };
    patches
        + spec.parametric.len()
        + spec.disk.len()
        + spec.blend.is_some() as usize
        + spec.spline.is_some() as usize
        + spec
            .nsided
            .iter()
            .map(|n| pieces(n.sides.len()))
            .sum::<usize>()
        + spec
            .patchwork
            .iter()
            .flat_map(|p| &p.faces)
            .map(|f| pieces(f.len()))
            .sum::<usize>()
        + spec.network.iter().map(|n| n.curves.len()).sum::<usize>()
}

/// The vertices the default grid may give all of a design's surfaces together: a design of
/// many pieces (a fitted mesh's thousands of faces) gets a coarser square grid per piece,
/// down to [`MIN_DEFAULT_GRID`], instead of the default's 128 × 128 each.
pub(crate) const DEFAULT_GRID_VERTICES: usize = 1 << 22;

/// The coarsest square grid per piece the default grid shrinks to.
pub(crate) const MIN_DEFAULT_GRID: usize = 9;

/// The tessellation grid of a design: the caller's `nu`/`nv`, else the design's `[output]`,
/// else 64 × 128 (square, the larger of the two, for a design with `[[nsided]]` patches,
/// `[[patchwork]]`s or `[[network]]`s; that square made coarser, down to
/// [`MIN_DEFAULT_GRID`], until all surfaces together have at most [`DEFAULT_GRID_VERTICES`]
/// vertices); refused (before anything is solved or allocated) beyond the grid limits of
/// [`check_grid`], or when all surfaces together would exceed [`MAX_VERTICES`] vertices or
/// the memory there is. A refused request has the place `nu`, `nv` or `nu × nv`; a refused
/// `[output]` has its place in the file (`output.nu`, …).
pub fn grid(spec: &DesignSpec, nu: Option<usize>, nv: Option<usize>) -> Result<(usize, usize)> {
    let nu_v = nu.or(spec.output.nu).unwrap_or(DEFAULT_NU);
    let nv_v = nv.or(spec.output.nv).unwrap_or(DEFAULT_NV);
    let surfaces = surface_count(spec).max(1);
    // The pieces of an n-sided patch, and the faces of a network, meet along u-lines of one
    // surface and v-lines of another: square grids make their vertices match, so the weld
    // joins them without T-junctions.
    let (nu_v, nv_v) =
        if spec.nsided.is_empty() && spec.network.is_empty() && spec.patchwork.is_empty() {
            (nu_v, nv_v)
        } else {
            let mut n = nu_v.max(nv_v);
            let defaulted = nu.or(spec.output.nu).is_none() && nv.or(spec.output.nv).is_none();
            if defaulted && n.saturating_mul(n).saturating_mul(surfaces) > DEFAULT_GRID_VERTICES {
                let fits = (DEFAULT_GRID_VERTICES / surfaces) as f64;
                n = (fits.sqrt().floor() as usize).clamp(MIN_DEFAULT_GRID, n);
            }
            (n, n)
        };
    let checked = check_grid(nu_v, nv_v).and_then(|()| {
        match nu_v.checked_mul(nv_v).and_then(|n| n.checked_mul(surfaces)) {
            Some(n) if n <= MAX_VERTICES => crate::memory::check_items(
                n as u64,
                crate::memory::BYTES_PER_GRID_VERTEX,
                &format!("the {nu_v} × {nv_v} grid of {surfaces} patch(es)"),
                "nu × nv",
            ),
            _ => Err(Error::invalid(format!(
                "{surfaces} patches of {nu_v} × {nv_v} vertices exceed {MAX_VERTICES} vertices in all; refusing to allocate them"
            ))
            .at("nu × nv")),
        }
    });
    match checked {
        Ok(()) => Ok((nu_v, nv_v)),
        Err(e) => {
            let requested = match e.place() {
                "nu" => nu.is_some(),
                "nv" => nv.is_some(),
                _ => nu.is_some() || nv.is_some(),
            };
            if requested {
                Err(e)
            } else {
                Err(e.at("output"))
            }
        }
    }
}

/// What an [`Overlay`] shows; a picture chooses its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverlayKind {
    /// A position curve of a patch (or a spine-edited patch's section).
    Curve,
    /// The spine `A₀(u)` of a patch.
    Spine,
    /// The image of a trim curve on its surface.
    Trim,
}

/// A polyline a picture draws over the surfaces: the geometry of a design's curves, spines and
/// trim curves, without colour or width (those are the picture's: `render::overlay_lines`).
#[derive(Clone, Debug, PartialEq)]
pub struct Overlay {
    /// The points in order.
    pub points: Vec<Vec3>,
    /// What the line shows.
    pub kind: OverlayKind,
    /// Join the last point to the first.
    pub closed: bool,
}

/// `CURVE_POINTS` points of a curve: over `[0, 2π)` for a periodic curve (drawn closed), over
/// its whole interval otherwise.
pub fn curve_overlay(curve: &dyn Curve) -> Overlay {
    let (points, closed) = match curve.domain() {
        Domain::Periodic => (
            (0..CURVE_POINTS)
                .map(|k| curve.point(TAU * k as f64 / CURVE_POINTS as f64))
                .collect(),
            true,
        ),
        Domain::Interval(a, b) => (
            (0..CURVE_POINTS)
                .map(|k| curve.point(a + (b - a) * k as f64 / (CURVE_POINTS - 1) as f64))
                .collect(),
            false,
        ),
    };
    Overlay {
        points,
        kind: OverlayKind::Curve,
        closed,
    }
}

impl SolvedDesign {
    /// The surface called `name`, among the output surfaces and then the reference ones.
    pub fn surface_named(&self, name: &str) -> Option<&DesignSurface> {
        self.surfaces
            .iter()
            .chain(&self.references)
            .find(|s| s.name == name)
    }

    /// A design with nothing in it (before the first compile).
    pub(crate) fn empty() -> Self {
        SolvedDesign {
            title: None,
            units: Units::default(),
            surfaces: Vec::new(),
            curves: Vec::new(),
            options: SolveOptions::default(),
            method: SolverMethod::Analytic,
            fd_grid: None,
            multi_patch: false,
            dynamic: None,
            trims: Vec::new(),
            attachments: Vec::new(),
            networks: Vec::new(),
            references: Vec::new(),
            paths: Vec::new(),
            edges: OnceLock::new(),
        }
    }

    /// The surfaces' names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.surfaces.iter().map(|s| s.name.as_str()).collect()
    }

    /// Every pair of patches that share a named position curve, with the G0/G1 mismatch there
    /// (measured on first use).
    pub fn edges(&self) -> &[SharedEdge] {
        self.edges.get_or_init(|| shared_edges(&self.surfaces))
    }

    /// The place of surface `k` for messages about its conditions (`patches[2].` or empty for a
    /// single-patch design).
    fn conditions_place(&self, k: usize) -> String {
        let s = &self.surfaces[k];
        if s.place == "conditions" {
            "conditions".to_string()
        } else {
            format!("{}.conditions", s.place)
        }
    }

    /// Refuses a grid of surface `k` that is not finite somewhere, naming the condition curve
    /// that is not finite there (formula curves are checked at sample points only when they are
    /// read, so a NaN between them shows up here).
    pub(super) fn check_finite<T: Copy + Into<f64> + Sync>(
        &self,
        k: usize,
        g: &mesh::Grid<T>,
    ) -> Result<()> {
        use rayon::prelude::*;
        // Blocks in parallel, each folded without a branch per number (which vectorises); the
        // first number that is not finite is looked for only when there is one.
        let finite = |v: &[[T; 3]]| {
            v.as_flattened()
                .iter()
                .fold(true, |ok, x| ok & (*x).into().is_finite())
        };
        let all = g
            .positions
            .par_chunks(1 << 14)
            .zip(g.normals.par_chunks(1 << 14))
            .all(|(p, n)| finite(p) & finite(n));
        if all && g.positions.len() == g.normals.len() {
            return Ok(());
        }
        let bad = g
            .positions
            .par_iter()
            .zip(&g.normals)
            .with_min_len(1 << 14)
            .position_first(|(a, b)| a.iter().chain(b).any(|x| !(*x).into().is_finite()));
        let Some(at) = bad else {
            return Ok(());
        };
        let s = &self.surfaces[k];
        let (i, j) = (at / g.nv, at % g.nv);
        let (u, v) = (g.u[i], g.v[j]);
        let culprit =
            s.conditions.iter().enumerate().find(|(_, c)| {
                !(0..3).all(|d| c.curve.derivative(v, d).iter().all(|x| x.is_finite()))
            });
        Err(match culprit {
            Some((ci, c)) => Error::invalid(format!(
                "{}not finite at v = {v} (or its derivatives are not)",
                c.curve_name
                    .as_deref()
                    .map(|n| format!("curve '{n}' is "))
                    .unwrap_or_default()
            ))
            .at(&format!("{}[{ci}].curve", self.conditions_place(k))),
            None => Error::invalid(format!(
                "the surface '{}' is not finite at u = {u}, v = {v}",
                s.name
            ))
            .at(&s.place),
        })
    }

    /// f32 meshes of every surface on an `nu × nv` grid (as every mesh format and picture
    /// stores them), each checked finite.
    pub fn meshes(&self, nu: usize, nv: usize) -> Result<Vec<GridMesh>> {
        self.grids(nu, nv)
    }

    /// Full-precision samples of every surface (CSV), each checked finite.
    pub fn samples(&self, nu: usize, nv: usize) -> Result<Vec<Samples>> {
        self.grids(nu, nv)
    }

    /// Every surface's grid, each checked finite (as it is stored; looked through again, for
    /// the message, only when it is not).
    fn grids<T: mesh::GridScalar + Into<f64>>(
        &self,
        nu: usize,
        nv: usize,
    ) -> Result<Vec<mesh::Grid<T>>> {
        let mut out = Vec::with_capacity(self.surfaces.len());
        for (k, s) in self.surfaces.iter().enumerate() {
            let (g, finite) = mesh::evaluate_grid_finite(s.surface(), nu, nv)?;
            if !finite {
                self.check_finite(k, &g)?;
            }
            out.push(g);
        }
        Ok(out)
    }

    /// [`SolvedDesign::meshes`] into existing meshes, re-tessellating only the surfaces for
    /// which `fresh(k)` is true (or whose mesh has another grid).
    pub fn meshes_into(
        &self,
        nu: usize,
        nv: usize,
        meshes: &mut Vec<GridMesh>,
        fresh: impl Fn(usize) -> bool,
    ) -> Result<()> {
        meshes.truncate(self.surfaces.len());
        for (k, s) in self.surfaces.iter().enumerate() {
            if k == meshes.len() {
                let g = mesh::tessellate(s.surface(), nu, nv)?;
                self.check_finite(k, &g)?;
                meshes.push(g);
            } else if fresh(k) || meshes[k].nu != nu || meshes[k].nv != nv {
                mesh::tessellate_into(s.surface(), nu, nv, &mut meshes[k])?;
                self.check_finite(k, &meshes[k])?;
            }
        }
        Ok(())
    }

    /// The design's grids as one [`TriMesh`] (see [`mesh::weld`]), one part per surface named
    /// after it.
    pub fn weld(&self, grids: &[GridMesh], export: &Export) -> TriMesh {
        mesh::weld(grids, &self.names(), export.weld_options())
    }

    /// What a picture draws over the surfaces: the position curves of every patch (each shared
    /// curve once; a spine-edited patch's sections at those `u` instead, where its edit moved
    /// them) and every spine.
    pub fn overlays(&self) -> Vec<Overlay> {
        let mut lines = Vec::new();
        let mut drawn: Vec<&str> = Vec::new();
        for (s, c) in self.surfaces.iter().flat_map(|s| {
            s.conditions
                .iter()
                .filter(|c| c.derivative == 0)
                .map(move |c| (s, c))
        }) {
            if let Some(points) = s.edited_section(c.u, CURVE_POINTS) {
                lines.push(Overlay {
                    points,
                    kind: OverlayKind::Curve,
                    closed: true,
                });
                continue;
            }
            if let Some(name) = &c.curve_name {
                if drawn.contains(&name.as_str()) {
                    continue;
                }
                drawn.push(name);
            }
            lines.push(curve_overlay(&*c.curve));
        }
        for s in &self.surfaces {
            if s.spine(0.0, 0).is_none() {
                continue;
            }
            let points = (0..CURVE_POINTS)
                .filter_map(|k| s.spine(k as f64 / (CURVE_POINTS - 1) as f64, 0))
                .collect();
            lines.push(Overlay {
                points,
                kind: OverlayKind::Spine,
                closed: false,
            });
        }
        lines.extend(self.trim_overlays(super::trim::TRIM_POINTS));
        lines.retain(|l| l.points.iter().all(|p| p.iter().all(|x| x.is_finite())));
        lines
    }
}

/// Every pair of patches that share a named position curve, with the G0/G1 mismatch there.
fn shared_edges(surfaces: &[DesignSurface]) -> Vec<SharedEdge> {
    let mut edges = Vec::new();
    for a in 0..surfaces.len() {
        for b in a + 1..surfaces.len() {
            for ca in surfaces[a].conditions.iter().filter(|c| c.derivative == 0) {
                for cb in surfaces[b].conditions.iter().filter(|c| c.derivative == 0) {
                    let (Some(na), Some(nb)) = (&ca.curve_name, &cb.curve_name) else {
                        continue;
                    };
                    if na != nb {
                        continue;
                    }
                    let (g0, g1) = edge_mismatch(
                        surfaces[a].surface(),
                        ca.u,
                        surfaces[b].surface(),
                        cb.u,
                        EDGE_SAMPLES,
                    );
                    edges.push(SharedEdge {
                        curve: na.clone(),
                        report: EdgeReport {
                            a,
                            ua: ca.u,
                            b,
                            ub: cb.u,
                            g0,
                            g1,
                        },
                    });
                }
            }
        }
    }
    edges
}
