//! Building a design's curves from their specs, each once, following references; curves whose
//! spec and dependencies did not change since the last build are reused as they are.

use super::attach::{CurveOnSurface, PathOnHost, TangentField};
use super::solved::{NamedCurve, SurfaceKind};
use super::trim::trim_curve;
use super::validate::{
    curve_place, kind_name, reference_names, references, unknown_curve, validate_patches,
};
use crate::curve::{
    ArcLength, BSpline, Bezier, Combination, Domain, Ellipse, Formula, FourierSeries, Hermite,
    LocalEdit, OriginShift, Point, PointSamples, RationalBSpline, SampleParam, SharedCurve,
    Transformed,
};
use crate::spec::*;
use crate::{Error, Result, Vec3};
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// A curve as last built: the spec it came from and the curves it referred to, so that a later
/// build can tell whether it would come out the same.
#[derive(Clone)]
struct Built {
    spec: CurveSpec,
    deps: Vec<SharedCurve>,
    /// The identities of the host surfaces of an `on_patch` or `tangent_field` curve.
    hosts: Vec<usize>,
    curve: SharedCurve,
}

/// A place in the design file, built only when an error names it (or an inline curve is
/// cached under it): building the designs at the steps of a derivative would otherwise
/// format the place of every condition and curve of every design.
type Place<'p> = &'p dyn Fn() -> String;

/// The curves of the last build: named curves by name, inline curves by their place
/// (`patches[2].conditions[1].curve`).
#[derive(Clone, Default)]
pub(crate) struct CurveCache {
    named: HashMap<String, Built>,
    inline: HashMap<String, Built>,
    /// The paths on hosts (host identity, path): kept while their host is unchanged.
    paths: Vec<(usize, TrimCurveSpec, Arc<PathOnHost>)>,
}

/// The address of a shared curve (its identity: equal addresses are the same built curve).
pub(crate) fn curve_id(c: &SharedCurve) -> usize {
    Arc::as_ptr(c) as *const () as usize
}

/// Builds curves by name, each once, following references, reusing the curves of the previous
/// build whose spec and dependencies are unchanged (a reused curve is the very object a fresh
/// build would have recomputed, so results are identical).
pub(crate) struct CurveBuilder<'a> {
    specs: &'a BTreeMap<String, CurveSpec>,
    built: HashMap<String, SharedCurve>,
    previous: &'a CurveCache,
    next: CurveCache,
    /// The solved PDE patches curves may lie on (`on_patch`), by name.
    hosts: HashMap<String, SurfaceKind>,
    /// The paths on hosts built so far (host identity, path): an `on_patch` curve and its
    /// `tangent_field` share one, and with it the host's jets along it.
    paths: Vec<(usize, TrimCurveSpec, Arc<PathOnHost>)>,
}

impl<'a> CurveBuilder<'a> {
    pub(crate) fn new(specs: &'a BTreeMap<String, CurveSpec>, previous: &'a CurveCache) -> Self {
        CurveBuilder {
            specs,
            built: HashMap::new(),
            previous,
            next: CurveCache::default(),
            hosts: HashMap::new(),
            paths: Vec::new(),
        }
    }

    /// Makes a solved patch available to the `on_patch` curves built from now on.
    pub(crate) fn add_host(&mut self, name: &str, kind: SurfaceKind) {
        self.hosts.insert(name.to_string(), kind);
    }

    /// The solved host `name` of an `on_patch` curve (solved before: see
    /// [`super::attach::patch_levels`]).
    fn host(&self, name: &str, place: &str) -> Result<SurfaceKind> {
        self.hosts.get(name).cloned().ok_or_else(|| {
            Error::invalid(format!(
                "the patch '{name}' is not solved before this curve is needed (no PDE patch of that name, or the patches depend on each other)"
            ))
            .at(place)
        })
    }

    /// The path `path` on the host `name`, shared by the curves built on it (and kept from the
    /// last build while the host is the same object).
    fn path_on(
        &mut self,
        name: &str,
        path: &TrimCurveSpec,
        place: &str,
    ) -> Result<Arc<PathOnHost>> {
        let host = self.host(name, place)?;
        let id = host.id();
        let same = |(h, p, _): &&(usize, TrimCurveSpec, Arc<PathOnHost>)| *h == id && p == path;
        if let Some((_, _, on)) = self.paths.iter().find(same) {
            return Ok(on.clone());
        }
        let on = match self.previous.paths.iter().find(same) {
            Some((_, _, on)) => on.clone(),
            None => PathOnHost::new(host, trim_curve(path)),
        };
        self.paths.push((id, path.clone(), on.clone()));
        Ok(on)
    }

    /// The paths on hosts of the curves built so far.
    pub(crate) fn paths(&self) -> Vec<Arc<PathOnHost>> {
        self.paths.iter().map(|(_, _, on)| on.clone()).collect()
    }

    /// The `(host name, (u, v) curve)` of an `on_patch` spec, or of the `on_patch` curve a
    /// `tangent_field` names.
    fn on_patch_of<'s>(&'s self, spec: &'s CurveSpec) -> Option<(&'s str, &'s TrimCurveSpec)> {
        match &spec.kind {
            CurveKind::OnPatch { patch, path, .. } => Some((patch.as_str(), path)),
            CurveKind::TangentField { curve, .. } => match self.specs.get(curve).map(|c| &c.kind) {
                Some(CurveKind::OnPatch { patch, path, .. }) => Some((patch.as_str(), path)),
                _ => None,
            },
            _ => None,
        }
    }

    /// The cache of this build, for the next one.
    pub(crate) fn into_cache(mut self) -> CurveCache {
        self.next.paths = self.paths;
        self.next
    }

    pub(crate) fn named(&mut self, name: &str, place: &str) -> Result<SharedCurve> {
        self.named_at(name, &|| place.to_string())
    }

    /// [`CurveBuilder::named`] with the place of the reference built only if an error names it.
    fn named_at(&mut self, name: &str, place: Place<'_>) -> Result<SharedCurve> {
        if let Some(c) = self.built.get(name) {
            return Ok(c.clone());
        }
        let (specs, previous) = (self.specs, self.previous);
        let Some(spec) = specs.get(name) else {
            return Err(unknown_curve(name, specs, &place()));
        };
        let old = previous.named.get(name);
        let built = self.cached(spec, &|| curve_place(name), old)?;
        self.built.insert(name.to_string(), built.curve.clone());
        self.next.named.insert(name.to_string(), built.clone());
        Ok(built.curve)
    }

    /// A condition's curve: a named curve, or an inline table cached under its place.
    pub(crate) fn reference(&mut self, r: &CurveRef, place: &str) -> Result<SharedCurve> {
        self.reference_at(r, &|| place.to_string())
    }

    /// [`CurveBuilder::reference`] with the place built only when an error names it or an
    /// inline curve is cached under it.
    pub(crate) fn reference_at(&mut self, r: &CurveRef, place: Place<'_>) -> Result<SharedCurve> {
        match r {
            CurveRef::Name(n) => self.named_at(n, place),
            CurveRef::Inline(spec) => {
                let key = place();
                let previous = self.previous;
                let old = previous.inline.get(&key);
                let built = self.cached(spec, &|| key.clone(), old)?;
                self.next.inline.insert(key, built.clone());
                Ok(built.curve)
            }
        }
    }

    /// The curve of `spec`: the previous one if the spec is equal and every curve it refers to
    /// is the same object as last time, else a fresh build.
    fn cached(&mut self, spec: &CurveSpec, place: Place<'_>, old: Option<&Built>) -> Result<Built> {
        let mut names = Vec::new();
        reference_names(spec, &mut names);
        let mut deps = Vec::with_capacity(names.len());
        for (k, n) in names.into_iter().enumerate() {
            // The reference's place, as `references` words it.
            let at = || {
                let mut refs = Vec::new();
                references(spec, &place(), &mut refs);
                refs.into_iter().nth(k).map(|(_, p)| p).unwrap_or_default()
            };
            deps.push(self.named_at(n, &at)?);
        }
        let hosts: Vec<usize> = match self.on_patch_of(spec) {
            Some((h, _)) => vec![self.host(h, &format!("{}.patch", place()))?.id()],
            None => Vec::new(),
        };
        if let Some(old) = old {
            let same_deps = old.hosts == hosts
                && old.deps.len() == deps.len()
                && old
                    .deps
                    .iter()
                    .zip(&deps)
                    .all(|(a, b)| curve_id(a) == curve_id(b));
            if same_deps && old.spec == *spec {
                // The reused curve's path on its host stays this build's (and the next's).
                if let Some((h, path)) = self.on_patch_of(spec) {
                    let (h, path) = (h.to_string(), path.clone());
                    self.path_on(&h, &path, &format!("{}.patch", place()))?;
                }
                return Ok(old.clone());
            }
        }
        let curve = self.build(spec, place)?;
        Ok(Built {
            spec: spec.clone(),
            deps,
            hosts,
            curve,
        })
    }

    /// Builds one curve: its kind, then arc length, `v_origin`, and the transforms in order.
    fn build(&mut self, spec: &CurveSpec, place: Place<'_>) -> Result<SharedCurve> {
        let at = |e: Error| e.at(&place());
        let v3 = |v: &V3| Vec3::new(v[0], v[1], v[2]);
        let pts = |v: &[V3]| v.iter().map(v3).collect::<Vec<_>>();
        let mut curve: SharedCurve = match &spec.kind {
            CurveKind::Circle {
                center,
                radius,
                normal,
            } => Arc::new(Ellipse::circle(v3(center), *radius, v3(normal)).map_err(at)?),
            CurveKind::Ellipse {
                center,
                axis1,
                axis2,
                rx,
                ry,
                normal,
            } => Arc::new(
                match (axis1, axis2, rx, ry) {
                    (Some(a1), Some(a2), _, _) => Ellipse::new(v3(center), v3(a1), v3(a2)),
                    (_, _, Some(rx), Some(ry)) => Ellipse::with_radii(
                        v3(center),
                        *rx,
                        *ry,
                        normal.as_ref().map_or(Vec3::z(), v3),
                    ),
                    _ => Err(Error::invalid("give either axis1 and axis2, or rx and ry")),
                }
                .map_err(at)?,
            ),
            CurveKind::Point { at: p } => Arc::new(Point::try_new(v3(p)).map_err(at)?),
            CurveKind::BSpline {
                degree,
                control,
                knots,
                periodic,
                weights: None,
            } => Arc::new(
                if *periodic {
                    BSpline::periodic(*degree, pts(control), knots.clone())
                } else {
                    BSpline::clamped(*degree, pts(control), knots.clone())
                }
                .map_err(at)?,
            ),
            CurveKind::BSpline {
                degree,
                control,
                knots,
                periodic,
                weights: Some(w),
            } => Arc::new(
                if *periodic {
                    RationalBSpline::periodic(*degree, pts(control), w, knots.clone())
                } else {
                    RationalBSpline::clamped(*degree, pts(control), w, knots.clone())
                }
                .map_err(at)?,
            ),
            CurveKind::Bezier { control } => Arc::new(Bezier::new(pts(control)).map_err(at)?),
            CurveKind::Hermite { p0, p1, d0, d1 } => {
                Arc::new(Hermite::try_new(v3(p0), v3(p1), v3(d0), v3(d1)).map_err(at)?)
            }
            CurveKind::Fourier { a0, cos, sin } => {
                Arc::new(FourierSeries::new(v3(a0), pts(cos), pts(sin)).map_err(at)?)
            }
            CurveKind::Samples { points, param } => {
                let param = match param {
                    ParamSpec::Uniform => SampleParam::Uniform,
                    ParamSpec::Chord => SampleParam::Chord,
                    ParamSpec::Centripetal => SampleParam::Centripetal,
                };
                Arc::new(PointSamples::closed(pts(points), param).map_err(at)?)
            }
            CurveKind::Formula { x, y, z, domain } => {
                let domain = match domain {
                    DomainSpec::Periodic => Domain::Periodic,
                    DomainSpec::Interval([t0, t1]) => Domain::Interval(*t0, *t1),
                };
                Arc::new(Formula::new(x, y, z, domain).map_err(at)?)
            }
            CurveKind::Derivative {
                position,
                direction,
                scale,
            } => {
                let p = self.reference_at(position, &|| format!("{}.position", place()))?;
                let d = self.reference_at(direction, &|| format!("{}.direction", place()))?;
                if p.domain() != d.domain() {
                    return Err(Error::invalid(format!(
                        "position and direction curves have different domains ({:?} and {:?})",
                        p.domain(),
                        d.domain()
                    ))
                    .at(&place()));
                }
                // X_u = s (d − p): points from the position curve towards the direction curve.
                Arc::new(Combination::new(vec![(*scale, d), (-*scale, p)]).map_err(at)?)
            }
            CurveKind::Local {
                curve,
                from,
                to,
                at: handle,
                along,
                across,
                normal,
            } => {
                let base = self.reference_at(curve, &|| format!("{}.curve", place()))?;
                Arc::new(
                    LocalEdit::new(base, *from, *to, *handle, [*along, *across, *normal])
                        .map_err(at)?,
                )
            }
            CurveKind::OnPatch { patch, path, .. } => {
                let on = self.path_on(patch, path, &format!("{}.patch", place()))?;
                Arc::new(CurveOnSurface::on(on))
            }
            CurveKind::TangentField { curve, scale } => {
                let Some((patch, path)) = self.on_patch_of(spec) else {
                    return Err(
                        Error::invalid(format!("'{curve}' is not an on_patch curve"))
                            .at(&format!("{}.curve", place())),
                    );
                };
                let (patch, path) = (patch.to_string(), path.clone());
                let on = self.path_on(&patch, &path, &format!("{}.curve", place()))?;
                Arc::new(TangentField::on(on, *scale))
            }
        };
        if spec.arc_length {
            curve = Arc::new(
                ArcLength::new(curve).map_err(|e| e.at(&format!("{}.arc_length", place())))?,
            );
        }
        if spec.v_origin != 0.0 {
            curve = Arc::new(
                OriginShift::new(curve, spec.v_origin)
                    .map_err(|e| e.at(&format!("{}.v_origin", place())))?,
            );
        }
        if !spec.transform.is_empty() {
            let map = super::transform::transform_map_at(&spec.transform, place)?;
            curve = Arc::new(Transformed::new(curve, map));
        }
        Ok(curve)
    }
}

/// Every named curve of the design, sorted by name.
pub(crate) fn named_curves(builder: &mut CurveBuilder<'_>) -> Result<Vec<NamedCurve>> {
    let specs = builder.specs;
    let mut curves = Vec::new();
    for (name, c) in specs {
        let curve = builder.named(name, &curve_place(name))?;
        curves.push(NamedCurve {
            name: name.clone(),
            kind: kind_name(&c.kind),
            curve,
        });
    }
    Ok(curves)
}

/// Builds one curve table on its own (a curve that names no other curve or patch), as the
/// design would.
pub fn build_curve(curve: &CurveSpec) -> Result<SharedCurve> {
    let specs = BTreeMap::from([("curve".to_string(), curve.clone())]);
    let cache = CurveCache::default();
    CurveBuilder::new(&specs, &cache).named("curve", "curve")
}

/// Validates the design's patches and builds its named curves (sorted by name, with the
/// `[[parameters]]` applied), without solving: what a viewer needs to draw the design's curves.
///
/// A design with curves on its patches (`on_patch`) is compiled (those curves need their host
/// patches solved).
pub fn build_curves(spec: &DesignSpec) -> Result<Vec<NamedCurve>> {
    let resolved = super::params::resolve_parameters(spec)?;
    let spec: &DesignSpec = &resolved;
    validate_patches(spec)?;
    if super::attach::has_attachments(spec) {
        return super::compile(spec).map(|d| d.into_solved().curves);
    }
    named_curves(&mut CurveBuilder::new(&spec.curves, &CurveCache::default()))
}
