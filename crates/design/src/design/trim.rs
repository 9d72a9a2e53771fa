//! `[[trims]]` of a design: which surface loses which holes, checked once at compile time.

use super::solved::DesignSurface;
use super::validate::{DEFAULT_NU, DEFAULT_NV};
use crate::mesh::TriMesh;
use crate::spec::{DesignSpec, TrimCurveSpec, TrimMethodSpec};
use crate::surface::ParameterDomain;
use crate::trim::{to_trimesh, trim_domain, ParamMesh, TrimCurve, TrimMethod};
use crate::{Error, Result};

/// The holes of one surface of a solved design.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceTrim {
    /// Index of the surface in [`super::SolvedDesign::surfaces`].
    pub surface: usize,
    /// Where the trim is in the design file (`trims[2]`).
    pub place: String,
    /// How the region around the holes is re-meshed (the entry's `method`; `cdt` for a hole
    /// that only an `on_patch` curve cuts).
    pub method: TrimMethod,
    /// The closed curves in the surface's `(u, v)` plane whose insides are removed: the
    /// entry's, then the paths of trimming `on_patch` curves on this surface.
    pub curves: Vec<TrimCurve>,
}

/// The library's curve of a design file's trim curve.
pub fn trim_curve(c: &TrimCurveSpec) -> TrimCurve {
    match c {
        TrimCurveSpec::Circle { center, radius } => TrimCurve::circle(*center, *radius),
        TrimCurveSpec::Ellipse {
            center,
            radii,
            angle,
        } => TrimCurve::Ellipse {
            center: *center,
            radii: *radii,
            angle: *angle,
        },
        TrimCurveSpec::Polyline { points } => TrimCurve::Polyline(points.clone()),
        TrimCurveSpec::Bspline { degree, points } => TrimCurve::BSpline {
            degree: *degree,
            points: points.clone(),
        },
    }
}

/// The library's method of a design file's method name.
pub fn trim_method(m: TrimMethodSpec) -> TrimMethod {
    match m {
        TrimMethodSpec::Cdt => TrimMethod::Cdt,
        TrimMethodSpec::Bilinear => TrimMethod::Bilinear,
        TrimMethodSpec::Laplace => TrimMethod::Laplace,
    }
}

/// The holes that were cut on the default grid without error in the last build: a domain,
/// its curves and the method. Cutting depends on nothing else (not on the surface's shape), so a
/// rebuild that keeps them (a drag of the host's curves) need not cut them again.
#[derive(Clone, Debug, Default)]
pub(crate) struct TrimChecks(Vec<(ParameterDomain, Vec<TrimCurve>, TrimMethod)>);

impl TrimChecks {
    /// Checks that `curves` can be cut out of `domain` on the default grid ([`trim_domain`]),
    /// unless `previous` saw them cut; either way `self` notes them for the next build.
    pub(crate) fn check(
        &mut self,
        previous: &TrimChecks,
        domain: ParameterDomain,
        curves: &[TrimCurve],
        method: TrimMethod,
    ) -> Result<()> {
        let same = |(d, c, m): &&(ParameterDomain, Vec<TrimCurve>, TrimMethod)| {
            *d == domain && *m == method && c.as_slice() == curves
        };
        if !previous.0.iter().any(|x| same(&x)) {
            trim_domain(domain, DEFAULT_NU, DEFAULT_NV, curves, method)?;
        }
        self.0.push((domain, curves.to_vec(), method));
        Ok(())
    }
}

/// Every `[[trims]]` entry resolved to its surface and checked: the surface exists (by name, or
/// the only surface), is trimmed by one entry only, the curves are valid, and the holes can be
/// cut on the default grid (inside the domain, not crossing, not nested).
pub(crate) fn build_trims(
    spec: &DesignSpec,
    surfaces: &[DesignSurface],
    previous: &TrimChecks,
    checks: &mut TrimChecks,
) -> Result<Vec<SurfaceTrim>> {
    let mut out: Vec<SurfaceTrim> = Vec::with_capacity(spec.trims.len());
    for (k, t) in spec.trims.iter().enumerate() {
        let place = format!("trims[{k}]");
        let surface = match &t.surface {
            Some(name) => surfaces
                .iter()
                .position(|s| &s.name == name)
                .ok_or_else(|| {
                    Error::invalid(format!(
                        "no surface named '{name}' (the design has {})",
                        surfaces
                            .iter()
                            .map(|s| format!("'{}'", s.name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                    .at(&format!("{place}.surface"))
                })?,
            None if surfaces.len() == 1 => 0,
            None => {
                return Err(Error::invalid(format!(
                    "the design has {} surfaces: name the one to trim",
                    surfaces.len()
                ))
                .at(&format!("{place}.surface")))
            }
        };
        if let Some(other) = out.iter().find(|o| o.surface == surface) {
            return Err(Error::invalid(format!(
                "the surface '{}' is trimmed by {} already: give all its curves there",
                surfaces[surface].name, other.place
            ))
            .at(&format!("{place}.surface")));
        }
        if t.curves.is_empty() {
            return Err(
                Error::invalid("give at least one trim curve").at(&format!("{place}.curves"))
            );
        }
        let curves: Vec<TrimCurve> = t.curves.iter().map(trim_curve).collect();
        let method = trim_method(t.method);
        let domain = surfaces[surface].surface().parameter_domain();
        checks
            .check(previous, domain, &curves, method)
            .map_err(|e| e.at(&place))?;
        out.push(SurfaceTrim {
            surface,
            place,
            method,
            curves,
        });
    }
    Ok(out)
}

impl super::SolvedDesign {
    /// What trims the design, for messages: the first trim's `[[trims]]` entry, or the
    /// attachment (an `on_patch` curve with `trim = true`) that implies it, with the surface
    /// it cuts. `None` for an untrimmed design.
    pub fn trim_origin(&self) -> Option<String> {
        let t = self.trims.first()?;
        let host = &self.surfaces[t.surface].name;
        Some(if t.place.starts_with("trims[") {
            format!(
                "a design with [[trims]] ({} cuts holes in '{host}')",
                t.place
            )
        } else {
            format!(
                "the on_patch curve {} cuts its hole in '{host}' (an attachment with trim = true)",
                t.place
            )
        })
    }

    /// The trims of surface `k`, if it has any.
    pub fn trim_of(&self, k: usize) -> Option<&SurfaceTrim> {
        self.trims.iter().find(|t| t.surface == k)
    }

    /// The trimmed parameter meshes on the `nu × nv` grid: one per surface, `None` for an
    /// untrimmed surface.
    pub fn param_meshes(&self, nu: usize, nv: usize) -> Result<Vec<Option<ParamMesh>>> {
        (0..self.surfaces.len())
            .map(|k| {
                self.trim_of(k)
                    .map(|t| {
                        let s = self.surfaces[k].surface();
                        trim_domain(s.parameter_domain(), nu, nv, &t.curves, t.method)
                            .map_err(|e| e.at(&t.place))
                    })
                    .transpose()
            })
            .collect()
    }

    /// Every surface as one indexed triangle mesh on the `nu × nv` grid, one part per surface
    /// named after it: trimmed surfaces re-meshed around their holes, the others their grid's
    /// triangles.
    pub fn tri_mesh(&self, nu: usize, nv: usize) -> Result<TriMesh> {
        let grids = self.meshes(nu, nv)?;
        let params = self.param_meshes(nu, nv)?;
        let mut out = TriMesh::default();
        for (k, (g, p)) in grids.iter().zip(&params).enumerate() {
            let s = &self.surfaces[k];
            let g = &snap_poles(g);
            let mut m = match p {
                Some(pm) => to_trimesh(s.surface(), g, pm, &s.name),
                None => TriMesh::from_grid(g, &s.name),
            };
            // A pole's row of grid vertices becomes one vertex, without its flat triangles.
            m.join_coincident();
            out.append(&m);
        }
        Ok(out)
    }

    /// The images on their surfaces of every trim curve (3D polylines for pictures), `points`
    /// points each (256 in pictures).
    pub fn trim_overlays(&self, points: usize) -> Vec<super::Overlay> {
        let mut lines = Vec::new();
        for t in &self.trims {
            let kind = &self.surfaces[t.surface].kind;
            let s = kind.surface();
            let periodic = s.v_domain().is_periodic();
            for c in &t.curves {
                // An attachment's hole: the host's points kept along its path.
                let on = self.paths.iter().find(|p| p.lies_on(kind, c));
                let points = (0..points)
                    .map(|k| {
                        let t = k as f64 / points as f64;
                        if let Some(on) = on {
                            return on.point_at(t);
                        }
                        let [u, v] = c.point(t);
                        let v = if periodic {
                            v.rem_euclid(crate::TAU)
                        } else {
                            v
                        };
                        s.point(u, v)
                    })
                    .collect();
                lines.push(super::Overlay {
                    points,
                    kind: super::OverlayKind::Trim,
                    closed: true,
                });
            }
        }
        lines
    }
}

/// Points along a drawn trim curve in pictures.
pub(crate) const TRIM_POINTS: usize = 256;

/// The grid with each end row that collapses to a point (a pole: every vertex within the weld
/// tolerance of the row's first, relative to the grid's diagonal) set exactly to that point,
/// so that [`TriMesh::join_coincident`] makes it one vertex.
fn snap_poles(g: &crate::mesh::GridMesh) -> crate::mesh::GridMesh {
    let mut g = g.clone();
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &g.positions {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let diag = (0..3)
        .map(|c| (hi[c] as f64 - lo[c] as f64).powi(2))
        .sum::<f64>()
        .sqrt();
    let tol = crate::mesh::weld::WELD_TOLERANCE * diag;
    let nv = g.nv;
    for i in [0, g.nu - 1] {
        let row = &mut g.positions[i * nv..(i + 1) * nv];
        let first = row[0];
        let near = row.iter().all(|p| {
            (0..3)
                .map(|c| (p[c] as f64 - first[c] as f64).powi(2))
                .sum::<f64>()
                .sqrt()
                <= tol
        });
        if near {
            row.fill(first);
        }
    }
    g
}
