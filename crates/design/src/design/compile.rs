//! Compiling a design: plan, validate once, build curves, dispatch every part to its solver,
//! and collect a [`SolvedDesign`]. A [`CompiledDesign`] keeps what it built, so compiling an
//! edited design re-solves only the parts whose inputs changed; everything else is reused as
//! the very object an earlier compile made, so the result is the same, bit for bit, as
//! compiling the edited design from scratch.

use super::blend::solve_blend_with;
use super::curves::{curve_id, named_curves, CurveBuilder, CurveCache};
use super::dynamic::build_dynamic;
use super::edit::Edit;
use super::parametric::build_parametric;
use super::preview::{self, AffineGrid, Drag, DragKey};
use super::solved::{ConditionInfo, DesignSurface, SolvedDesign, SurfaceKind};
use super::spline::solve_spec;
use super::trim::TrimChecks;
use super::validate::{build_operator, check_solver, kind_name, plan, validate_patches};
use crate::analysis::PatchTangent;
use crate::curve::SharedCurve;
use crate::elliptic::{self, Condition, SolveOptions};
use crate::mesh::{self, GridMesh};
use crate::spec::{
    BlendSpec, CurveRef, DesignSpec, OperatorSpec, ParametricSpec, SolverMethod, SplineSpec,
};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

/// What a PDE patch's solution depends on: equal keys give equal surfaces.
#[derive(Clone, Debug, PartialEq)]
struct PatchKey {
    operator: OperatorSpec,
    method: SolverMethod,
    options: SolveOptions,
    fd_grid: Option<[usize; 2]>,
    /// `(u, derivative order, curve identity)` of every condition, in order.
    conditions: Vec<(u64, usize, usize)>,
}

/// A solved PDE patch with the key it was solved from. (The solved design's conditions keep the
/// key's curves alive, so a curve identity cannot be taken by another curve while the patch is
/// cached.)
#[derive(Clone)]
struct CachedPatch {
    key: PatchKey,
    kind: SurfaceKind,
}

/// A PDE patch of the design with its conditions built, before solving.
struct Planned {
    name: String,
    /// Where its conditions are: `conditions` or `patches[i].conditions`.
    place: String,
    operator: OperatorSpec,
    operator_place: String,
    conditions: Vec<ConditionInfo>,
    key: PatchKey,
}

/// The meshes of the last tessellation and the surfaces they were made from.
#[derive(Default)]
struct MeshCache {
    sources: Vec<SurfaceKind>,
    meshes: Vec<GridMesh>,
}

/// A design compiled and solved, ready to be edited and re-solved incrementally.
pub struct CompiledDesign {
    spec: DesignSpec,
    solved: SolvedDesign,
    curves: CurveCache,
    patches: Vec<CachedPatch>,
    parametric: Vec<(ParametricSpec, Arc<crate::surface::ParametricSurface>)>,
    nurbs: Vec<(crate::spec::NurbsSpec, Arc<super::NurbsSurface>)>,
    blend: Option<(BlendSpec, Vec<usize>, SurfaceKind)>,
    spline: Option<(SplineSpec, SurfaceKind)>,
    /// `[[spine]]` edits with the identity of the patch each was applied to.
    spines: Vec<(crate::spec::SpineSpec, usize, SurfaceKind)>,
    meshes: MeshCache,
    /// The holes cut without error in the last build ([`TrimChecks`]).
    trim_checks: TrimChecks,
    /// The control point being dragged and the affine model of what it moves.
    drag: Drag,
}

impl std::fmt::Debug for CompiledDesign {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledDesign")
            .field("solved", &self.solved)
            .finish_non_exhaustive()
    }
}

/// Compiles and solves a design: validates it once, builds its curves, solves every PDE patch
/// with the solver the design asks for (analytic or finite differences), builds its
/// `[[parametric]]` surfaces, solves its `[blend]` and `[spline]` sections and builds its
/// `[dynamic]` curve. Errors name their place in the design file.
pub fn compile(spec: &DesignSpec) -> Result<CompiledDesign> {
    let mut d = CompiledDesign {
        spec: spec.clone(),
        solved: SolvedDesign::empty(),
        curves: CurveCache::default(),
        patches: Vec::new(),
        parametric: Vec::new(),
        nurbs: Vec::new(),
        blend: None,
        spline: None,
        spines: Vec::new(),
        meshes: MeshCache::default(),
        trim_checks: TrimChecks::default(),
        drag: Drag::default(),
    };
    d.rebuild(spec.clone())?;
    Ok(d)
}

/// [`compile`], keeping only the solved design.
pub fn solve_design(spec: &DesignSpec) -> Result<SolvedDesign> {
    compile(spec).map(CompiledDesign::into_solved)
}

impl CompiledDesign {
    /// The design as it stands (after every applied edit).
    pub fn spec(&self) -> &DesignSpec {
        &self.spec
    }

    /// The solved design.
    pub fn solved(&self) -> &SolvedDesign {
        &self.solved
    }

    /// The solved design, without the caches.
    pub fn into_solved(self) -> SolvedDesign {
        self.solved
    }

    /// Replaces the design by `spec` and re-solves what changed. On an error the compiled
    /// design is left as it was.
    pub fn set_spec(&mut self, spec: DesignSpec) -> Result<()> {
        self.rebuild(spec)?;
        self.drag = Drag::default();
        Ok(())
    }

    /// Applies an edit and re-solves what it touched; returns the edit that undoes it. On an
    /// error (an edit that does not apply, or a design that no longer solves) nothing changes.
    /// Ends any drag: the next meshes are tessellated.
    pub fn apply(&mut self, edit: &Edit) -> Result<Edit> {
        let undo = self.edit(edit)?;
        self.drag.note(None);
        Ok(undo)
    }

    /// [`CompiledDesign::apply`] for an edit that continues a gesture (a drag). Moves of one
    /// control point in a row are a drag, whose meshes [`CompiledDesign::meshes`] may predict
    /// from its affine model ([`super::preview`]): the meshes a tessellation gives to a unit in
    /// the last place of their single precision, not always bit for bit. An edit applied with
    /// [`CompiledDesign::apply`] after it is tessellated again.
    pub fn apply_dragging(&mut self, edit: &Edit) -> Result<Edit> {
        let undo = self.edit(edit)?;
        self.drag.note(match edit {
            Edit::MoveControlPoint { name, index, .. } => Some(DragKey {
                curve: name.clone(),
                index: *index,
            }),
            _ => None,
        });
        Ok(undo)
    }

    fn edit(&mut self, edit: &Edit) -> Result<Edit> {
        let mut spec = self.spec.clone();
        let undo = edit.apply(&mut spec)?;
        self.rebuild(spec)?;
        Ok(undo)
    }

    /// The meshes of every surface on an `nu × nv` grid, re-tessellating into the previous
    /// meshes only the surfaces that changed since the last call (or all, for another grid).
    /// While one control point is dragged ([`CompiledDesign::apply_dragging`]), the surfaces
    /// affine in it are predicted from a model made once per drag instead
    /// ([`super::preview`]), each frame checked against the surface.
    pub fn meshes(&mut self, nu: usize, nv: usize) -> Result<&[GridMesh]> {
        if self.drag.frame((nu, nv)) {
            self.drag.model = Some(self.make_model((nu, nv)));
        }
        let predicted = self.predicted((nu, nv));
        let sources = &self.meshes.sources;
        let surfaces = &self.solved.surfaces;
        let fresh = |k: usize| {
            !predicted.iter().any(|(j, _)| *j == k)
                && sources
                    .get(k)
                    .is_none_or(|s| s.id() != surfaces[k].kind.id())
        };
        let mut result = self
            .solved
            .meshes_into(nu, nv, &mut self.meshes.meshes, fresh);
        if result.is_ok() {
            if let Some(Some(model)) = &self.drag.model {
                for (k, d) in &predicted {
                    let Some((_, affine)) = model.surfaces.iter().find(|(j, _)| j == k) else {
                        continue;
                    };
                    let mesh = &mut self.meshes.meshes[*k];
                    affine.fill(self.solved.surfaces[*k].surface(), *d, mesh);
                    self.drag.predicted += 1;
                    result = self.solved.check_finite(*k, mesh);
                    if result.is_err() {
                        break;
                    }
                }
            }
        }
        if let Err(e) = result {
            // Meshes half rewritten: forget them.
            self.meshes = MeshCache::default();
            return Err(e);
        }
        self.meshes.sources = surfaces.iter().map(|s| s.kind.clone()).collect();
        Ok(&self.meshes.meshes)
    }

    /// The surfaces whose meshes on `grid` the drag's model gives this time, with the point's
    /// move since the model was made: those that changed since the last meshes, whose mesh on
    /// this grid is at hand, and that agree with the model at its probes (a surface that does
    /// not is dropped from the model).
    fn predicted(&mut self, grid: (usize, usize)) -> Vec<(usize, Vec3)> {
        let Some(Some(model)) = &mut self.drag.model else {
            return Vec::new();
        };
        let Some(point) = self
            .drag
            .key
            .as_ref()
            .and_then(|key| preview::control_point(&self.spec, key))
        else {
            return Vec::new();
        };
        if model.grid != grid {
            return Vec::new();
        }
        let d = point - model.origin;
        let (meshes, sources, surfaces) = (
            &self.meshes.meshes,
            &self.meshes.sources,
            &self.solved.surfaces,
        );
        let mut out = Vec::new();
        model.surfaces.retain(|(k, affine)| {
            let k = *k;
            let (Some(mesh), Some(source), Some(s)) =
                (meshes.get(k), sources.get(k), surfaces.get(k))
            else {
                return true;
            };
            if source.id() == s.kind.id() || (mesh.nu, mesh.nv) != grid {
                return true;
            }
            let agrees = affine.probe(s.surface(), d);
            if agrees {
                out.push((k, d));
            }
            agrees
        });
        out
    }

    /// The affine model of the surfaces the dragged point moves, on `grid` (`None` if no
    /// surface is affine in it, or the design does not solve at the steps).
    fn make_model(&self, grid: (usize, usize)) -> Option<preview::Model> {
        let key = self.drag.key.as_ref()?;
        let origin = preview::control_point(&self.spec, key)?;
        let h = preview::step(&self.spec, key)?;
        let mut scratch = self.scratch();
        let mut solve = |d: Vec3| -> Option<Vec<SurfaceKind>> {
            let p = origin + d;
            scratch
                .edit(&Edit::MoveControlPoint {
                    name: key.curve.clone(),
                    index: key.index,
                    point: [p.x, p.y, p.z],
                })
                .ok()?;
            Some(
                scratch
                    .solved
                    .surfaces
                    .iter()
                    .map(|s| s.kind.clone())
                    .collect(),
            )
        };
        let check = Vec3::new(0.5, -0.75, 0.3) * h;
        let axes = [Vec3::x(), Vec3::y(), Vec3::z()].map(|e| solve(e * h));
        let checked = solve(check)?;
        let [Some(ax), Some(ay), Some(az)] = axes else {
            return None;
        };
        let base = &self.solved.surfaces;
        if [&ax, &ay, &az, &checked]
            .iter()
            .any(|s| s.len() != base.len())
        {
            return None;
        }
        let moved = |k: usize| {
            [&ax, &ay, &az, &checked]
                .iter()
                .any(|s| s[k].id() != base[k].kind.id())
        };
        if (0..base.len()).filter(|&k| moved(k)).count() * grid.0 * grid.1
            > preview::MAX_MODEL_VERTICES
        {
            return None;
        }
        let mut surfaces = Vec::new();
        for k in 0..base.len() {
            if !moved(k) {
                continue;
            }
            let s = base[k].surface();
            let Ok((us, vs)) = mesh::grid_parameters_in(s.u_range(), s.v_domain(), grid.0, grid.1)
            else {
                continue;
            };
            let jets = |kind: &SurfaceKind| preview::jets(kind.surface(), &us, &vs);
            let model = AffineGrid::new(
                (us.clone(), vs.clone()),
                preview::jets(s, &us, &vs),
                [jets(&ax[k]), jets(&ay[k]), jets(&az[k])],
                h,
                (&jets(&checked[k]), check),
            );
            if let Some(m) = model {
                surfaces.push((k, m));
            }
        }
        Some(preview::Model {
            grid,
            origin,
            surfaces,
        })
    }

    /// How many meshes [`CompiledDesign::meshes`] took from a drag's model instead of
    /// evaluating the surface (for tests and benchmarks).
    pub fn predicted_meshes(&self) -> usize {
        self.drag.predicted
    }

    /// A copy of the compiled design with its caches but no meshes, to solve variations in.
    fn scratch(&self) -> CompiledDesign {
        CompiledDesign {
            spec: self.spec.clone(),
            solved: SolvedDesign::empty(),
            curves: self.curves.clone(),
            patches: self.patches.clone(),
            parametric: self.parametric.clone(),
            nurbs: self.nurbs.clone(),
            blend: self.blend.clone(),
            spline: self.spline.clone(),
            spines: self.spines.clone(),
            meshes: MeshCache::default(),
            trim_checks: self.trim_checks.clone(),
            drag: Drag::default(),
        }
    }

    /// Builds and solves `spec`, reusing what the caches hold; swaps everything in only when
    /// all of it succeeded.
    fn rebuild(&mut self, file: DesignSpec) -> Result<()> {
        // The design with its `[[parameters]]` applied; `self.spec` keeps the file's form.
        let resolved = super::params::resolve_parameters(&file)?;
        let spec: &DesignSpec = &resolved;
        validate_patches(spec)?;
        let options = check_solver(&spec.solver)?;
        let method = spec.solver.method;
        let fd_grid = (method == SolverMethod::Fd)
            .then(|| spec.solver.grid.unwrap_or(super::fd::DEFAULT_GRID));
        let mut builder = CurveBuilder::new(&spec.curves, &self.curves);

        // PDE patches, level by level: hosts first, then the patches whose conditions lie on
        // them (§5.2.1). In each level the conditions are built, then every patch whose key is
        // new is solved (in parallel; each solve is deterministic, so the order does not
        // matter).
        let levels = super::attach::patch_levels(spec)?;
        let mut done: Vec<Option<(Planned, SurfaceKind)>> = (0..levels.iter().map(Vec::len).sum())
            .map(|_| None)
            .collect();
        for level in &levels {
            let planned = plan_patches(spec, &mut builder, method, &options, fd_grid, &|i| {
                level.contains(&i)
            })?;
            let solved: Vec<Result<SurfaceKind>> = planned
                .par_iter()
                .map(|(_, p)| {
                    if let Some(c) = self.patches.iter().find(|c| c.key == p.key) {
                        return Ok(c.kind.clone());
                    }
                    solve_patch(p, &p.key)
                })
                .collect();
            for ((i, p), kind) in planned.into_iter().zip(solved) {
                let kind = kind?;
                builder.add_host(&p.name, kind.clone());
                done[i] = Some((p, kind));
            }
        }
        let curves = named_curves(&mut builder)?;
        let mut surfaces = Vec::new();
        let mut patches = Vec::new();
        for (p, kind) in done.into_iter().flatten() {
            patches.push(CachedPatch {
                key: p.key,
                kind: kind.clone(),
            });
            let place = match p.place.strip_suffix(".conditions") {
                Some(patch) => patch.to_string(),
                None => p.place,
            };
            surfaces.push(DesignSurface {
                name: p.name,
                place,
                kind,
                operator: Some(p.operator),
                conditions: p.conditions,
            });
        }

        // [[spine]]: edited patches replace their solved ones (before anything refers to them).
        let mut spines = self.spines.clone();
        super::spine::apply_spines(
            &spec.spine,
            &mut surfaces,
            spec.patches.is_none(),
            &mut spines,
        )?;

        // [[parametric]]: rebuilt only if the table changed.
        let mut parametric = Vec::with_capacity(spec.parametric.len());
        for (i, p) in spec.parametric.iter().enumerate() {
            let surface = match self.parametric.iter().find(|(s, _)| s == p) {
                Some((_, built)) => built.clone(),
                None => Arc::new(build_parametric(p, i)?),
            };
            surfaces.push(DesignSurface {
                name: p.name.clone(),
                place: format!("parametric[{i}]"),
                kind: SurfaceKind::Parametric(surface.clone()),
                operator: None,
                conditions: Vec::new(),
            });
            parametric.push((p.clone(), surface));
        }

        // [[nurbs]]: reference surfaces, rebuilt only if the table changed.
        let mut nurbs = Vec::with_capacity(spec.nurbs.len());
        for (i, n) in spec.nurbs.iter().enumerate() {
            let place = format!("nurbs[{i}]");
            let surface = match self.nurbs.iter().find(|(s, _)| s == n) {
                Some((_, built)) => built.clone(),
                None => Arc::new(super::NurbsSurface::from_spec(n, &place)?),
            };
            surfaces.push(DesignSurface {
                name: n.name.clone(),
                place,
                kind: SurfaceKind::Nurbs(surface.clone()),
                operator: None,
                conditions: Vec::new(),
            });
            nurbs.push((n.clone(), surface));
        }

        // [[nsided]]: tangent to any surface before them.
        super::nsided::build_nsided(&spec.nsided, &mut builder, &mut surfaces)?;
        // [[network]]: faces tangent across inner curves, and to any surface before them.
        let mut networks =
            super::network::build_networks(&spec.network, &mut builder, &mut surfaces)?;
        // [[patchwork]]: layouts given corner by corner, checked as networks.
        networks.extend(super::patchwork::build_patchworks(
            &spec.patchwork,
            &mut surfaces,
        )?);
        // [[disk]]: patches through their own samples.
        super::disk::build_disks(&spec.disk, &mut surfaces)?;
        let paths = builder.paths();
        let curve_cache = builder.into_cache();

        // [blend]: its primary surfaces may be surfaces of this design.
        let blend = match &spec.blend {
            None => None,
            Some(b) => {
                let (kind, sources) = {
                    let by_name = |name: &str| {
                        surfaces
                            .iter()
                            .find(|s| s.name == name)
                            .map(|s| (s.kind.id(), s.kind.surface()))
                    };
                    let ids = super::blend::design_sources(b, &by_name)?;
                    match &self.blend {
                        Some((old, old_ids, kind)) if old == b && *old_ids == ids => {
                            (kind.clone(), ids)
                        }
                        _ => (
                            SurfaceKind::Blend(Arc::new(solve_blend_with(b, &by_name)?)),
                            ids,
                        ),
                    }
                };
                surfaces.push(DesignSurface {
                    name: "blend".to_string(),
                    place: "blend".to_string(),
                    kind: kind.clone(),
                    operator: None,
                    conditions: Vec::new(),
                });
                Some((b.clone(), sources, kind))
            }
        };

        // [spline].
        let spline = match &spec.spline {
            None => None,
            Some(s) => {
                let kind = match &self.spline {
                    Some((old, kind)) if old == s => kind.clone(),
                    _ => {
                        let solved = solve_spec(s)?;
                        let net = solved.to_f64();
                        SurfaceKind::Spline(Arc::new(solved), Arc::new(net))
                    }
                };
                surfaces.push(DesignSurface {
                    name: "spline".to_string(),
                    place: "spline".to_string(),
                    kind: kind.clone(),
                    operator: None,
                    conditions: Vec::new(),
                });
                Some((s.clone(), kind))
            }
        };

        // Reference surfaces served as neighbours; they are not part of the output.
        let (references, surfaces): (Vec<DesignSurface>, Vec<DesignSurface>) =
            surfaces.into_iter().partition(|s| {
                matches!(s.kind, SurfaceKind::Nurbs(_))
                    || spec.parametric.iter().any(|p| {
                        p.reference
                            && p.name == s.name
                            && matches!(s.kind, SurfaceKind::Parametric(_))
                    })
            });
        let dynamic = spec.dynamic.as_ref().map(build_dynamic).transpose()?;
        if surfaces.is_empty() && dynamic.is_none() {
            return Err(Error::invalid(
                "the design has no conditions: give `conditions = [...]` or [[patches]]",
            ));
        }

        let mut checks = TrimChecks::default();
        let mut trims = super::trim::build_trims(spec, &surfaces, &self.trim_checks, &mut checks)?;
        super::attach::add_attachment_trims(
            spec,
            &surfaces,
            &mut trims,
            &self.trim_checks,
            &mut checks,
        )?;
        let attachments = super::attach::find_attachments(spec, &surfaces);
        self.solved = SolvedDesign {
            title: spec.title.clone(),
            units: spec.units.unwrap_or_default(),
            surfaces,
            curves,
            options,
            method,
            fd_grid,
            multi_patch: spec.patches.is_some(),
            dynamic,
            trims,
            attachments,
            networks,
            references,
            paths,
            edges: OnceLock::new(),
        };
        self.curves = curve_cache;
        self.trim_checks = checks;
        self.patches = patches;
        self.parametric = parametric;
        self.nurbs = nurbs;
        self.blend = blend;
        self.spline = spline;
        self.spines = spines;
        self.spec = file;
        Ok(())
    }
}

/// The PDE patches of a design with their condition curves built (errors at
/// `conditions[i].curve`), each with the key of its solution.
fn plan_patches(
    spec: &DesignSpec,
    builder: &mut CurveBuilder<'_>,
    method: SolverMethod,
    options: &SolveOptions,
    fd_grid: Option<[usize; 2]>,
    pick: &dyn Fn(usize) -> bool,
) -> Result<Vec<(usize, Planned)>> {
    let mut planned = Vec::new();
    for (index, p) in plan(spec)?.into_iter().enumerate() {
        if !pick(index) {
            continue;
        }
        let mut conditions = Vec::with_capacity(p.conditions.len());
        for (i, c) in p.conditions.iter().enumerate() {
            let curve = builder.reference_at(&c.curve, &|| format!("{}[{i}].curve", p.place))?;
            let (curve_name, kind) = match &c.curve {
                CurveRef::Name(n) => (
                    Some(n.clone()),
                    spec.curves.get(n).map_or("?", |s| kind_name(&s.kind)),
                ),
                CurveRef::Inline(s) => (None, kind_name(&s.kind)),
            };
            conditions.push(ConditionInfo {
                u: c.u,
                derivative: c.derivative,
                curve_name,
                kind,
                curve,
            });
        }
        let key = PatchKey {
            operator: p.operator.clone(),
            method,
            options: options.clone(),
            fd_grid,
            conditions: conditions
                .iter()
                .map(|c| (c.u.to_bits(), c.derivative, curve_id(&c.curve)))
                .collect(),
        };
        planned.push((
            index,
            Planned {
                name: p.name,
                place: p.place,
                operator: p.operator.clone(),
                operator_place: p.operator_place,
                conditions,
                key,
            },
        ));
    }
    Ok(planned)
}

/// The derivatives of the PDE patches of `base` (the design `spec`, solved) along directions
/// of its parameters, without solving any other design: direction `k` is `Σ c_j spec_j` over
/// the pairs `(c_j, spec_j)` of `directions[k]`, designs with the same patches and condition
/// places as `spec` (such as `[(1/h, spec(p + h)), (−1/h, spec)]`), whose surfaces are linear
/// in their condition curves. Each design's condition curves are built (its `[[parameters]]`
/// applied) but not solved; the derivative of condition `i` of a patch along direction `k` is
/// `Σ c_j C_ij`, and every patch solves all directions as one block
/// ([`crate::elliptic::PdePatch::solve_tangents`]). The result's `[k][i]` is patch `i`'s
/// derivative along direction `k`. Refused unless every surface of `base` is a PDE patch solved
/// by the analytic solver, with no curve on another patch.
///
/// With `smoothing`, one more direction follows: the derivative with respect to the smoothing
/// parameter `a` of the polyharmonic operators, `(1/a) u X_u` plus the tangent solve of
/// [`elliptic::PdePatch::smoothing_tangent_curves`] in the same block (zero for a patch whose
/// operator has no `a`).
pub fn tangent_patches(
    base: &SolvedDesign,
    spec: &DesignSpec,
    directions: &[Vec<(f64, &DesignSpec)>],
    smoothing: bool,
) -> Result<Vec<Vec<PatchTangent>>> {
    let patches: Vec<&Arc<elliptic::PdePatch>> = base
        .surfaces
        .iter()
        .map(|s| match &s.kind {
            SurfaceKind::Pde(p) => Ok(p),
            _ => Err(Error::invalid(format!(
                "surface '{}' is not a PDE patch of the analytic solver: its derivatives need \
                 solves of the design",
                s.name
            ))),
        })
        .collect::<Result<_>>()?;
    let (options, own) = condition_curves(spec)?;
    // The curves of each distinct design once (a direction's designs are often shared, such as
    // the point itself).
    let mut designs: Vec<&DesignSpec> = Vec::new();
    let index: Vec<Vec<(f64, usize)>> = directions
        .iter()
        .map(|d| {
            d.iter()
                .map(|&(c, s)| {
                    let j = match designs.iter().position(|&t| std::ptr::eq(t, s)) {
                        Some(j) => j,
                        None => {
                            designs.push(s);
                            designs.len() - 1
                        }
                    };
                    (c, j)
                })
                .collect()
        })
        .collect();
    // `spec` is checked above; the other designs differ from it in their parameters' values
    // only (their structure is compared below), so their curves are built unchecked.
    let curves: Vec<Vec<Vec<SharedCurve>>> = designs
        .par_iter()
        .map(|&s| {
            if std::ptr::eq(s, spec) {
                Ok(own.clone())
            } else {
                step_condition_curves(s)
            }
        })
        .collect::<Result<_>>()?;
    for c in &curves {
        if c.len() != patches.len()
            || c.iter()
                .zip(&patches)
                .any(|(c, p)| c.len() != p.conditions().len())
        {
            return Err(Error::invalid(
                "a design of a derivative has other patches or conditions than the point",
            ));
        }
    }
    let per_patch: Vec<Vec<PatchTangent>> = patches
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let mut dirs: Vec<Vec<SharedCurve>> = index
                .iter()
                .map(|d| {
                    (0..p.conditions().len())
                        .map(|c| {
                            elliptic::combination(
                                d.iter()
                                    .map(|&(w, j)| (w, curves[j][i][c].clone()))
                                    .collect(),
                            )
                        })
                        .collect()
                })
                .collect();
            let mut stretch = 0.0;
            if smoothing {
                let curves = match p.smoothing_tangent_curves() {
                    Some((s, curves)) => {
                        stretch = s;
                        curves
                    }
                    None => (0..p.conditions().len())
                        .map(|_| elliptic::combination(Vec::new()))
                        .collect(),
                };
                dirs.push(curves);
            }
            let count = dirs.len();
            Ok(p.solve_tangents(&dirs, &options)?
                .into_iter()
                .enumerate()
                .map(|(k, t)| PatchTangent {
                    patch: Arc::new(t),
                    stretch: if k + 1 == count && smoothing {
                        stretch
                    } else {
                        0.0
                    },
                })
                .collect())
        })
        .collect::<Result<_>>()?;
    let count = directions.len() + usize::from(smoothing);
    Ok((0..count)
        .map(|k| per_patch.iter().map(|p| p[k].clone()).collect())
        .collect())
}

/// The solver options and the condition curves of every PDE patch of `spec` (its
/// `[[parameters]]` applied), in the order of the solved design's surfaces, built without
/// solving. Refused for the finite-difference solver and for curves on other patches.
fn condition_curves(spec: &DesignSpec) -> Result<(SolveOptions, Vec<Vec<SharedCurve>>)> {
    let resolved = super::params::resolve_parameters(spec)?;
    let spec: &DesignSpec = &resolved;
    validate_patches(spec)?;
    let options = check_solver(&spec.solver)?;
    if spec.solver.method != SolverMethod::Analytic {
        return Err(Error::invalid(
            "derivatives by tangent solves need the analytic solver",
        ));
    }
    if super::attach::patch_levels(spec)?.len() > 1 {
        return Err(Error::invalid(
            "derivatives by tangent solves need patches whose curves lie on no other patch",
        ));
    }
    let curves = planned_condition_curves(spec, &options)?;
    Ok((options, curves))
}

/// The condition curves of every PDE patch of `spec` as the patches' plan builds them (no
/// solve), in the order of the solved design's surfaces.
fn planned_condition_curves(
    spec: &DesignSpec,
    options: &SolveOptions,
) -> Result<Vec<Vec<SharedCurve>>> {
    let cache = CurveCache::default();
    let mut builder = CurveBuilder::new(&spec.curves, &cache);
    let planned = plan_patches(
        spec,
        &mut builder,
        spec.solver.method,
        options,
        None,
        &|_| true,
    )?;
    Ok(planned
        .into_iter()
        .map(|(_, p)| p.conditions.into_iter().map(|c| c.curve).collect())
        .collect())
}

/// The condition curves of every PDE patch of `spec` as [`condition_curves`] builds them, but
/// without validating the design: for the designs at the steps of a derivative, which differ
/// from a validated design in the values of its `[[parameters]]` only. A curve its constructor
/// refuses is still an error.
fn step_condition_curves(spec: &DesignSpec) -> Result<Vec<Vec<SharedCurve>>> {
    let resolved = super::params::resolve_parameters(spec)?;
    let spec: &DesignSpec = &resolved;
    let options = check_solver(&spec.solver)?;
    planned_condition_curves(spec, &options)
}

/// Validates a design without solving anything (but a design with curves on its patches, which
/// is compiled: those curves need their hosts solved): [`validate_patches`] (numbers, references,
/// operators, conditions, solver options, the output grid), the `[dynamic]` and `[blend]`
/// sections, and every curve built (its constructor checks its values), after the
/// `[[parameters]]` are applied.
pub fn validate_design(spec: &DesignSpec) -> Result<()> {
    let resolved = super::params::resolve_parameters(spec)?;
    let spec: &DesignSpec = &resolved;
    if let Some(d) = &spec.dynamic {
        build_dynamic(d)?;
    }
    if let Some(blend) = &spec.blend {
        super::blend::validate_blend(blend)?;
    }
    validate_patches(spec)?;
    let options = check_solver(&spec.solver)?;
    if super::attach::has_attachments(spec) {
        // Curves on patches need their hosts solved.
        return compile(spec).map(|_| ());
    }
    let cache = CurveCache::default();
    let mut builder = CurveBuilder::new(&spec.curves, &cache);
    named_curves(&mut builder)?;
    plan_patches(
        spec,
        &mut builder,
        spec.solver.method,
        &options,
        None,
        &|_| true,
    )
    .map(|_| ())
}

/// Solves one planned PDE patch with the solver its key names; errors name their place in the
/// design file.
fn solve_patch(p: &Planned, key: &PatchKey) -> Result<SurfaceKind> {
    match key.fd_grid {
        Some(grid) => {
            let (order, a) = match p.operator {
                OperatorSpec::Polyharmonic { order, a } => (order, a),
                _ => unreachable!("checked by validate_design"),
            };
            super::fd::solve_patch(order, a, grid, &p.conditions, &p.place)
                .map(|s| SurfaceKind::Fd(Arc::new(s)))
        }
        None => {
            let op = build_operator(&p.operator, &p.operator_place)?;
            let conds = p
                .conditions
                .iter()
                .map(|c| Condition {
                    u: c.u,
                    derivative: c.derivative,
                    curve: c.curve.clone(),
                })
                .collect();
            // The solver places its errors at `conditions[i]…` of the patch: the patch's own
            // place without its `conditions` (each place printed once).
            let patch = p
                .place
                .strip_suffix("conditions")
                .map_or(p.place.as_str(), |s| s.trim_end_matches('.'));
            elliptic::solve(&op, conds, &key.options)
                .map(|s| SurfaceKind::Pde(Arc::new(s)))
                .map_err(|e| {
                    if e.place().starts_with("conditions") {
                        e.at(patch)
                    } else {
                        e.at(&p.place)
                    }
                })
        }
    }
}
